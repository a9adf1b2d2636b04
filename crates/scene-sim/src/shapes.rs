//! Analytic primitives and their exact ray intersections.
//!
//! Every primitive is a set of *surfaces* that rays hit from either side (a box is its six
//! faces, not a solid: a ray starting inside a box hits the face it leaves through). Each shape
//! is validated when it is made, so a shape that exists is finite and not degenerate.
//!
//! | shape | surfaces (part index) | ray test |
//! |---|---|---|
//! | [`PlanarPolygon`] | 1: the polygon (holes are not part of it) | ray–plane, then even–odd point in polygon over outline and holes |
//! | [`Cuboid`] | 6: −x, +x, −y, +y, −z, +z faces of its own frame | slab test in the box frame |
//! | [`Sphere`] | 1 | quadratic |
//! | [`Cylinder`] | 3: side, bottom cap (−z), top cap (+z) | quadratic for the side, ray–plane + disc for the caps |

use crate::SceneError;
use pointcloud::{Aabb, Isometry3, Point3, Real, Vector3};

/// A point in a patch's own 2D frame.
pub type Point2 = nalgebra::Point2<Real>;

/// Hits closer than this along the ray (metres) are ignored, so a ray starting on a surface
/// does not hit that surface again.
pub const RAY_EPSILON: Real = 1e-9;

/// The smallest ring area a polygon accepts, m².
const MIN_RING_AREA: Real = 1e-10;

/// A hit in a primitive before the scene turns it into a [`crate::Hit`].
#[derive(Copy, Clone, Debug)]
pub(crate) struct LocalHit {
    /// Distance along the (unit) ray.
    pub t: Real,
    /// Surface normal in the world, unit length, either orientation.
    pub normal: Vector3,
    /// Which surface of the primitive (see the module table).
    pub part: u32,
}

fn finite3(v: &Vector3) -> bool {
    v.iter().all(|x| x.is_finite())
}

pub(crate) fn check_isometry(what: &'static str, m: &Isometry3) -> Result<(), SceneError> {
    let q = &m.rotation.coords;
    if !finite3(&m.translation.vector) || !q.iter().all(|x| x.is_finite()) {
        return Err(SceneError::NonFinite { what });
    }
    let norm = q.norm();
    if (norm - 1.0).abs() > 1e-6 {
        return Err(SceneError::NonUnitRotation { what, norm });
    }
    Ok(())
}

fn check_positive(what: &'static str, value: Real) -> Result<(), SceneError> {
    if !value.is_finite() {
        return Err(SceneError::NonFinite { what });
    }
    if value <= 0.0 {
        return Err(SceneError::BadParameter { what, value, allowed: "> 0" });
    }
    Ok(())
}

/// A planar polygon with holes: the thesis's planar patch (§5.1), an outline and holes in the
/// patch's own 2D frame plus the rigid transform `world_from_patch` that places the frame's
/// x–y plane in the world (the patch normal is the frame's +z).
///
/// Inside is decided by the even–odd rule over the outline and all holes, so holes may touch
/// the outline (a door reaching the floor is a hole sharing the wall's bottom edge). Rings are
/// not checked for self-intersection, nor holes for lying inside the outline.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanarPolygon {
    world_from_patch: Isometry3,
    /// All rings, outline first, concatenated.
    vertices: Vec<Point2>,
    /// Start index of each ring in `vertices`, plus the total length at the end.
    ring_starts: Vec<usize>,
    lo: Point2,
    hi: Point2,
    origin: Point3,
    axis_u: Vector3,
    axis_v: Vector3,
    normal: Vector3,
    offset: Real,
}

impl PlanarPolygon {
    /// A polygon from its outline and holes in the patch frame, placed by `world_from_patch`.
    ///
    /// Fails on a non-finite or non-unit transform, a ring with fewer than three vertices,
    /// a non-finite vertex, or a ring of (almost) zero area.
    pub fn new(
        world_from_patch: Isometry3,
        outline: Vec<Point2>,
        holes: Vec<Vec<Point2>>,
    ) -> Result<PlanarPolygon, SceneError> {
        check_isometry("polygon transform", &world_from_patch)?;
        let mut vertices = Vec::new();
        let mut ring_starts = Vec::new();
        for (ring, pts) in std::iter::once(outline).chain(holes).enumerate() {
            if pts.len() < 3 {
                return Err(SceneError::TooFewVertices { ring, count: pts.len() });
            }
            if !pts.iter().all(|p| p.x.is_finite() && p.y.is_finite()) {
                return Err(SceneError::NonFinite { what: "polygon vertex" });
            }
            let area = ring_area(&pts).abs();
            if !area.is_finite() {
                return Err(SceneError::NonFinite { what: "polygon area" });
            }
            if area < MIN_RING_AREA {
                return Err(SceneError::DegeneratePolygon { ring, area });
            }
            ring_starts.push(vertices.len());
            vertices.extend(pts);
        }
        ring_starts.push(vertices.len());
        let outline_end = ring_starts[1];
        let mut lo = Point2::new(Real::INFINITY, Real::INFINITY);
        let mut hi = Point2::new(Real::NEG_INFINITY, Real::NEG_INFINITY);
        for p in &vertices[..outline_end] {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        let r = world_from_patch.rotation;
        let normal = r * Vector3::z();
        let origin: Point3 = world_from_patch.translation.vector.into();
        Ok(PlanarPolygon {
            world_from_patch,
            vertices,
            ring_starts,
            lo,
            hi,
            origin,
            axis_u: r * Vector3::x(),
            axis_v: r * Vector3::y(),
            normal,
            offset: normal.dot(&origin.coords),
        })
    }

    /// The axis-aligned rectangle `[min, max]` of the patch frame, with rectangular holes
    /// `(min, max)` (which may touch the outline, like doors).
    pub fn rectangle(
        world_from_patch: Isometry3,
        min: Point2,
        max: Point2,
        holes: &[(Point2, Point2)],
    ) -> Result<PlanarPolygon, SceneError> {
        let rect = |a: Point2, b: Point2| vec![a, Point2::new(b.x, a.y), b, Point2::new(a.x, b.y)];
        PlanarPolygon::new(
            world_from_patch,
            rect(min, max),
            holes.iter().map(|&(a, b)| rect(a, b)).collect(),
        )
    }

    /// The parallelogram `corner + a·edge_u + b·edge_v`, `a, b ∈ [0, 1]`, given in world
    /// coordinates. The patch frame has x along `edge_u` and its normal along
    /// `edge_u × edge_v`. Fails on non-finite input or parallel (or zero) edges.
    pub fn parallelogram(
        corner: Point3,
        edge_u: Vector3,
        edge_v: Vector3,
    ) -> Result<PlanarPolygon, SceneError> {
        if !(finite3(&corner.coords) && finite3(&edge_u) && finite3(&edge_v)) {
            return Err(SceneError::NonFinite { what: "parallelogram" });
        }
        let area = edge_u.cross(&edge_v).norm();
        if area.is_nan() || area < MIN_RING_AREA {
            return Err(SceneError::DegeneratePolygon { ring: 0, area });
        }
        let x = edge_u.normalize();
        let z = edge_u.cross(&edge_v).normalize();
        let y = z.cross(&x);
        let rotation = nalgebra::UnitQuaternion::from_rotation_matrix(
            &nalgebra::Rotation3::from_basis_unchecked(&[x, y, z]),
        );
        let world_from_patch = Isometry3::from_parts(corner.coords.into(), rotation);
        let lu = edge_u.norm();
        let (vx, vy) = (edge_v.dot(&x), edge_v.dot(&y));
        PlanarPolygon::new(
            world_from_patch,
            vec![
                Point2::new(0.0, 0.0),
                Point2::new(lu, 0.0),
                Point2::new(lu + vx, vy),
                Point2::new(vx, vy),
            ],
            Vec::new(),
        )
    }

    /// The transform placing the patch frame in the world.
    pub fn world_from_patch(&self) -> &Isometry3 {
        &self.world_from_patch
    }

    /// The outline in the patch frame.
    pub fn outline(&self) -> &[Point2] {
        &self.vertices[self.ring_starts[0]..self.ring_starts[1]]
    }

    /// The holes in the patch frame.
    pub fn holes(&self) -> impl Iterator<Item = &[Point2]> + '_ {
        self.ring_starts[1..].windows(2).map(|w| &self.vertices[w[0]..w[1]])
    }

    /// The unit normal in the world (the patch frame's +z).
    pub fn normal(&self) -> Vector3 {
        self.normal
    }

    /// The plane offset: world points `p` of the plane satisfy `normal · p = offset`.
    pub fn offset(&self) -> Real {
        self.offset
    }

    /// The area of the outline minus the holes (assuming the holes lie inside and apart).
    pub fn area(&self) -> Real {
        let rings: Vec<Real> = self
            .ring_starts
            .windows(2)
            .map(|w| ring_area(&self.vertices[w[0]..w[1]]).abs())
            .collect();
        rings[0] - rings[1..].iter().sum::<Real>()
    }

    /// Whether the patch-frame point (`x`, `y`) lies inside (even–odd rule).
    pub fn contains_local(&self, x: Real, y: Real) -> bool {
        if x < self.lo.x || x > self.hi.x || y < self.lo.y || y > self.hi.y {
            return false;
        }
        let mut inside = false;
        for w in self.ring_starts.windows(2) {
            let ring = &self.vertices[w[0]..w[1]];
            let mut j = ring.len() - 1;
            for i in 0..ring.len() {
                let (pi, pj) = (ring[i], ring[j]);
                if (pi.y > y) != (pj.y > y) && x < (pj.x - pi.x) * (y - pi.y) / (pj.y - pi.y) + pi.x
                {
                    inside = !inside;
                }
                j = i;
            }
        }
        inside
    }

    fn aabb(&self) -> Aabb {
        Aabb::from_points(
            self.outline()
                .iter()
                .map(|p| self.world_from_patch * Point3::new(p.x, p.y, 0.0))
                .collect::<Vec<_>>()
                .iter(),
        )
    }

    #[inline]
    fn intersect(&self, o: &Point3, d: &Vector3, t_max: Real) -> Option<LocalHit> {
        let denom = self.normal.dot(d);
        if denom.abs() < 1e-15 {
            return None;
        }
        let t = (self.offset - self.normal.dot(&o.coords)) / denom;
        if !(t > RAY_EPSILON && t < t_max) {
            return None;
        }
        let rel = (o + d * t) - self.origin;
        self.contains_local(rel.dot(&self.axis_u), rel.dot(&self.axis_v)).then_some(LocalHit {
            t,
            normal: self.normal,
            part: 0,
        })
    }
}

/// Twice-signed-area halved: the shoelace area of a ring (positive if counter-clockwise).
fn ring_area(ring: &[Point2]) -> Real {
    let mut s = 0.0;
    let mut j = ring.len() - 1;
    for i in 0..ring.len() {
        s += (ring[j].x - ring[i].x) * (ring[j].y + ring[i].y);
        j = i;
    }
    s / 2.0
}

/// A box with half extents along the axes of its own frame, placed by `world_from_box` (the
/// frame's origin is the box centre).
#[derive(Clone, Debug, PartialEq)]
pub struct Cuboid {
    world_from_box: Isometry3,
    half_extents: Vector3,
    box_from_world: nalgebra::Matrix3<Real>,
    world_axes: nalgebra::Matrix3<Real>,
}

impl Cuboid {
    /// A posed box. Fails on a non-finite or non-unit transform or a half extent that is not
    /// positive.
    pub fn new(world_from_box: Isometry3, half_extents: Vector3) -> Result<Cuboid, SceneError> {
        check_isometry("box transform", &world_from_box)?;
        for &h in half_extents.iter() {
            check_positive("box half extent", h)?;
        }
        let world_axes = world_from_box.rotation.to_rotation_matrix().into_inner();
        Ok(Cuboid {
            world_from_box,
            half_extents,
            box_from_world: world_axes.transpose(),
            world_axes,
        })
    }

    /// The axis-aligned box with the given opposite corners.
    pub fn axis_aligned(a: Point3, b: Point3) -> Result<Cuboid, SceneError> {
        if !(finite3(&a.coords) && finite3(&b.coords)) {
            return Err(SceneError::NonFinite { what: "box corner" });
        }
        let (lo, hi) = (a.inf(&b), a.sup(&b));
        Cuboid::new(
            Isometry3::translation((lo.x + hi.x) / 2.0, (lo.y + hi.y) / 2.0, (lo.z + hi.z) / 2.0),
            (hi - lo) / 2.0,
        )
    }

    /// A box of full `size` standing on the plane `z = base_z`, centred at `center_xy` and
    /// turned by `yaw` (radians) about the vertical.
    pub fn standing(
        center_xy: Point2,
        base_z: Real,
        size: Vector3,
        yaw: Real,
    ) -> Result<Cuboid, SceneError> {
        let m = Isometry3::new(
            Vector3::new(center_xy.x, center_xy.y, base_z + size.z / 2.0),
            Vector3::z() * yaw,
        );
        Cuboid::new(m, size / 2.0)
    }

    /// The transform placing the box frame (origin at the centre) in the world.
    pub fn world_from_box(&self) -> &Isometry3 {
        &self.world_from_box
    }

    /// Half the edge lengths along the box frame's axes.
    pub fn half_extents(&self) -> &Vector3 {
        &self.half_extents
    }

    /// The outward unit normal of face `part` (0..6: −x, +x, −y, +y, −z, +z) in the world.
    pub fn face_normal(&self, part: u32) -> Vector3 {
        let axis = (part / 2) as usize % 3;
        let sign = if part.is_multiple_of(2) { -1.0 } else { 1.0 };
        self.world_axes.column(axis) * sign
    }

    /// The centre of face `part` in the world.
    pub fn face_center(&self, part: u32) -> Point3 {
        let axis = (part / 2) as usize % 3;
        self.center() + self.face_normal(part) * self.half_extents[axis]
    }

    fn center(&self) -> Point3 {
        self.world_from_box.translation.vector.into()
    }

    /// Whether the world point lies inside or on the box.
    pub fn contains(&self, p: &Point3) -> bool {
        let l = self.box_from_world * (p - self.center());
        (0..3).all(|i| l[i].abs() <= self.half_extents[i])
    }

    fn aabb(&self) -> Aabb {
        let e = self.world_axes.abs() * self.half_extents;
        let c = self.center();
        Aabb { min: c - e, max: c + e }
    }

    #[inline]
    fn intersect(&self, o: &Point3, d: &Vector3, t_max: Real) -> Option<LocalHit> {
        let lo = self.box_from_world * (o - self.center());
        let ld = self.box_from_world * d;
        let mut t_near = Real::NEG_INFINITY;
        let mut t_far = Real::INFINITY;
        let (mut near_part, mut far_part) = (0u32, 0u32);
        for i in 0..3 {
            let h = self.half_extents[i];
            if ld[i] == 0.0 {
                if lo[i].abs() > h {
                    return None;
                }
                continue;
            }
            let inv = 1.0 / ld[i];
            let t_lo = (-h - lo[i]) * inv;
            let t_hi = (h - lo[i]) * inv;
            // Entering through the −h face when moving in +direction.
            let (a, b, pa, pb) = if inv > 0.0 {
                (t_lo, t_hi, 2 * i as u32, 2 * i as u32 + 1)
            } else {
                (t_hi, t_lo, 2 * i as u32 + 1, 2 * i as u32)
            };
            if a > t_near {
                t_near = a;
                near_part = pa;
            }
            if b < t_far {
                t_far = b;
                far_part = pb;
            }
        }
        if t_near.is_nan() || t_far.is_nan() || t_near > t_far {
            return None;
        }
        let (t, part) = if t_near > RAY_EPSILON {
            (t_near, near_part)
        } else if t_far > RAY_EPSILON {
            (t_far, far_part)
        } else {
            return None;
        };
        (t < t_max).then(|| LocalHit { t, normal: self.face_normal(part), part })
    }
}

/// A sphere.
#[derive(Clone, Debug, PartialEq)]
pub struct Sphere {
    center: Point3,
    radius: Real,
}

impl Sphere {
    /// A sphere; fails on a non-finite centre or a radius that is not positive.
    pub fn new(center: Point3, radius: Real) -> Result<Sphere, SceneError> {
        if !finite3(&center.coords) {
            return Err(SceneError::NonFinite { what: "sphere centre" });
        }
        check_positive("sphere radius", radius)?;
        Ok(Sphere { center, radius })
    }

    /// The centre.
    pub fn center(&self) -> &Point3 {
        &self.center
    }

    /// The radius.
    pub fn radius(&self) -> Real {
        self.radius
    }

    fn aabb(&self) -> Aabb {
        let r = Vector3::repeat(self.radius);
        Aabb { min: self.center - r, max: self.center + r }
    }

    #[inline]
    fn intersect(&self, o: &Point3, d: &Vector3, t_max: Real) -> Option<LocalHit> {
        let oc = o - self.center;
        let b = oc.dot(d);
        let c = oc.norm_squared() - self.radius * self.radius;
        let disc = b * b - c;
        if disc.is_nan() || disc < 0.0 {
            return None;
        }
        let s = disc.sqrt();
        let mut t = -b - s;
        if t <= RAY_EPSILON {
            t = -b + s;
        }
        if !(t > RAY_EPSILON && t < t_max) {
            return None;
        }
        let normal = (oc + d * t) / self.radius;
        Some(LocalHit { t, normal, part: 0 })
    }
}

/// A finite cylinder with caps: radius about its frame's z axis, from `−half_height` to
/// `+half_height` along it, placed by `world_from_cylinder` (origin at the centre).
#[derive(Clone, Debug, PartialEq)]
pub struct Cylinder {
    world_from_cylinder: Isometry3,
    radius: Real,
    half_height: Real,
    cyl_from_world: nalgebra::Matrix3<Real>,
    world_axes: nalgebra::Matrix3<Real>,
}

impl Cylinder {
    /// A posed cylinder. Fails on a non-finite or non-unit transform, or a radius or half height
    /// that is not positive.
    pub fn new(
        world_from_cylinder: Isometry3,
        radius: Real,
        half_height: Real,
    ) -> Result<Cylinder, SceneError> {
        check_isometry("cylinder transform", &world_from_cylinder)?;
        check_positive("cylinder radius", radius)?;
        check_positive("cylinder half height", half_height)?;
        let world_axes = world_from_cylinder.rotation.to_rotation_matrix().into_inner();
        Ok(Cylinder {
            world_from_cylinder,
            radius,
            half_height,
            cyl_from_world: world_axes.transpose(),
            world_axes,
        })
    }

    /// An upright cylinder standing on `base_center` (the centre of its bottom cap).
    pub fn upright(
        base_center: Point3,
        radius: Real,
        height: Real,
    ) -> Result<Cylinder, SceneError> {
        if !finite3(&base_center.coords) {
            return Err(SceneError::NonFinite { what: "cylinder base" });
        }
        check_positive("cylinder height", height)?;
        Cylinder::new(
            Isometry3::translation(base_center.x, base_center.y, base_center.z + height / 2.0),
            radius,
            height / 2.0,
        )
    }

    /// The transform placing the cylinder frame (origin at the centre, axis z) in the world.
    pub fn world_from_cylinder(&self) -> &Isometry3 {
        &self.world_from_cylinder
    }

    /// The radius.
    pub fn radius(&self) -> Real {
        self.radius
    }

    /// Half the height along the axis.
    pub fn half_height(&self) -> Real {
        self.half_height
    }

    /// The unit axis direction in the world.
    pub fn axis(&self) -> Vector3 {
        self.world_axes.column(2).into_owned()
    }

    fn center(&self) -> Point3 {
        self.world_from_cylinder.translation.vector.into()
    }

    /// Whether the world point lies inside or on the cylinder.
    pub fn contains(&self, p: &Point3) -> bool {
        let l = self.cyl_from_world * (p - self.center());
        l.z.abs() <= self.half_height && l.x * l.x + l.y * l.y <= self.radius * self.radius
    }

    fn aabb(&self) -> Aabb {
        let a = self.axis();
        let e = Vector3::from_fn(|i, _| {
            a[i].abs() * self.half_height + self.radius * (1.0 - a[i] * a[i]).max(0.0).sqrt()
        });
        let c = self.center();
        Aabb { min: c - e, max: c + e }
    }

    #[inline]
    fn intersect(&self, o: &Point3, d: &Vector3, t_max: Real) -> Option<LocalHit> {
        let lo = self.cyl_from_world * (o - self.center());
        let ld = self.cyl_from_world * d;
        let (r, h) = (self.radius, self.half_height);
        let mut best: Option<(Real, u32, Vector3)> = None;
        let mut consider = |t: Real, part: u32, n: Vector3| {
            if t > RAY_EPSILON && t < t_max && best.is_none_or(|(bt, _, _)| t < bt) {
                best = Some((t, part, n));
            }
        };
        let a = ld.x * ld.x + ld.y * ld.y;
        if a > 1e-18 {
            let b = lo.x * ld.x + lo.y * ld.y;
            let c = lo.x * lo.x + lo.y * lo.y - r * r;
            let disc = b * b - a * c;
            if disc >= 0.0 {
                let s = disc.sqrt();
                for t in [(-b - s) / a, (-b + s) / a] {
                    let z = lo.z + t * ld.z;
                    if z.abs() <= h {
                        let p = lo + ld * t;
                        consider(t, 0, Vector3::new(p.x / r, p.y / r, 0.0));
                    }
                }
            }
        }
        if ld.z != 0.0 {
            for (z, part, nz) in [(-h, 1, -1.0), (h, 2, 1.0)] {
                let t = (z - lo.z) / ld.z;
                let p = lo + ld * t;
                if p.x * p.x + p.y * p.y <= r * r {
                    consider(t, part, Vector3::new(0.0, 0.0, nz));
                }
            }
        }
        best.map(|(t, part, n)| LocalHit { t, normal: self.world_axes * n, part })
    }
}

/// Any primitive a scene holds.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A planar polygon with holes (1 surface).
    Polygon(PlanarPolygon),
    /// A posed box (6 surfaces).
    Cuboid(Cuboid),
    /// A sphere (1 surface).
    Sphere(Sphere),
    /// A finite capped cylinder (3 surfaces).
    Cylinder(Cylinder),
}

impl From<PlanarPolygon> for Shape {
    fn from(s: PlanarPolygon) -> Shape {
        Shape::Polygon(s)
    }
}
impl From<Cuboid> for Shape {
    fn from(s: Cuboid) -> Shape {
        Shape::Cuboid(s)
    }
}
impl From<Sphere> for Shape {
    fn from(s: Sphere) -> Shape {
        Shape::Sphere(s)
    }
}
impl From<Cylinder> for Shape {
    fn from(s: Cylinder) -> Shape {
        Shape::Cylinder(s)
    }
}

impl Shape {
    /// How many surfaces (and so [`crate::SurfaceId`]s) the shape has.
    pub fn num_surfaces(&self) -> u32 {
        match self {
            Shape::Polygon(_) | Shape::Sphere(_) => 1,
            Shape::Cuboid(_) => 6,
            Shape::Cylinder(_) => 3,
        }
    }

    /// The suffix naming surface `part` ("" for single-surface shapes).
    pub fn part_name(&self, part: u32) -> &'static str {
        match self {
            Shape::Polygon(_) | Shape::Sphere(_) => "",
            Shape::Cuboid(_) => ["/-x", "/+x", "/-y", "/+y", "/-z", "/+z"][part as usize % 6],
            Shape::Cylinder(_) => ["/side", "/bottom", "/top"][part as usize % 3],
        }
    }

    /// The axis-aligned bounding box in the world.
    pub fn aabb(&self) -> Aabb {
        match self {
            Shape::Polygon(s) => s.aabb(),
            Shape::Cuboid(s) => s.aabb(),
            Shape::Sphere(s) => s.aabb(),
            Shape::Cylinder(s) => s.aabb(),
        }
    }

    /// Whether a world point lies inside the solid (boxes, spheres, cylinders) — never for a
    /// polygon, which has no inside.
    pub fn contains(&self, p: &Point3) -> bool {
        match self {
            Shape::Polygon(_) => false,
            Shape::Cuboid(s) => s.contains(p),
            Shape::Sphere(s) => (p - s.center).norm_squared() <= s.radius * s.radius,
            Shape::Cylinder(s) => s.contains(p),
        }
    }

    /// The world plane `(unit normal, offset)` of planar surface `part`, `None` for curved ones.
    /// Box and cap normals point outwards; a polygon's is its frame's +z.
    pub fn plane(&self, part: u32) -> Option<(Vector3, Real)> {
        match self {
            Shape::Polygon(s) => Some((s.normal, s.offset)),
            Shape::Cuboid(s) => {
                let n = s.face_normal(part);
                Some((n, n.dot(&s.face_center(part).coords)))
            }
            Shape::Sphere(_) => None,
            Shape::Cylinder(s) => {
                if part == 0 {
                    return None;
                }
                let n = if part == 1 { -s.axis() } else { s.axis() };
                Some((n, n.dot(&(s.center() + n * s.half_height).coords)))
            }
        }
    }

    #[inline]
    pub(crate) fn intersect(&self, o: &Point3, d: &Vector3, t_max: Real) -> Option<LocalHit> {
        match self {
            Shape::Polygon(s) => s.intersect(o, d, t_max),
            Shape::Cuboid(s) => s.intersect(o, d, t_max),
            Shape::Sphere(s) => s.intersect(o, d, t_max),
            Shape::Cylinder(s) => s.intersect(o, d, t_max),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

    fn ray(o: [Real; 3], d: [Real; 3]) -> (Point3, Vector3) {
        (Point3::new(o[0], o[1], o[2]), Vector3::new(d[0], d[1], d[2]).normalize())
    }

    fn square_with_hole() -> PlanarPolygon {
        // The square [0, 4]² at height z = 1 (normal +z) with the hole [1, 2]².
        PlanarPolygon::rectangle(
            Isometry3::translation(0.0, 0.0, 1.0),
            Point2::new(0.0, 0.0),
            Point2::new(4.0, 4.0),
            &[(Point2::new(1.0, 1.0), Point2::new(2.0, 2.0))],
        )
        .unwrap()
    }

    #[test]
    fn polygon_hits_outside_holes_only() {
        let p = square_with_hole();
        let (o, d) = ray([3.0, 3.0, 5.0], [0.0, 0.0, -1.0]);
        let h = p.intersect(&o, &d, 100.0).unwrap();
        assert!((h.t - 4.0).abs() < 1e-12);
        assert_eq!(h.normal, Vector3::z());
        let (o, d) = ray([1.5, 1.5, 5.0], [0.0, 0.0, -1.0]);
        assert!(p.intersect(&o, &d, 100.0).is_none(), "through the hole");
        let (o, d) = ray([5.0, 3.0, 5.0], [0.0, 0.0, -1.0]);
        assert!(p.intersect(&o, &d, 100.0).is_none(), "beside the outline");
        // From below, slanted: two-sided.
        let (o, d) = ray([0.0, 0.0, 0.0], [3.0, 0.5, 1.0]);
        let h = p.intersect(&o, &d, 100.0).unwrap();
        assert!((h.t - 10.25f64.sqrt()).abs() < 1e-12);
        // Parallel to the plane and beyond max range.
        let (o, d) = ray([3.0, 3.0, 1.0], [1.0, 0.0, 0.0]);
        assert!(p.intersect(&o, &d, 100.0).is_none());
        let (o, d) = ray([3.0, 3.0, 5.0], [0.0, 0.0, -1.0]);
        assert!(p.intersect(&o, &d, 3.9).is_none());
        assert!((p.area() - 15.0).abs() < 1e-12);
    }

    #[test]
    fn hole_touching_the_outline_is_a_door() {
        // A wall 4 × 2.5 with a door 1 × 2 from the bottom edge.
        let wall = PlanarPolygon::rectangle(
            Isometry3::identity(),
            Point2::new(0.0, 0.0),
            Point2::new(4.0, 2.5),
            &[(Point2::new(1.0, 0.0), Point2::new(2.0, 2.0))],
        )
        .unwrap();
        assert!(!wall.contains_local(1.5, 1.0));
        assert!(wall.contains_local(1.5, 2.2));
        assert!(wall.contains_local(0.5, 1.0));
    }

    #[test]
    fn posed_polygon_and_parallelogram() {
        // A vertical square facing −x at x = 2: rotate the patch frame so its +z is −x.
        let m = Isometry3::new(Vector3::new(2.0, 0.0, 0.0), Vector3::y() * -FRAC_PI_2);
        let p = PlanarPolygon::rectangle(m, Point2::new(-1.0, -1.0), Point2::new(1.0, 1.0), &[])
            .unwrap();
        assert!((p.normal() - (-Vector3::x())).norm() < 1e-12);
        let (o, d) = ray([0.0, 0.5, 0.5], [1.0, 0.0, 0.0]);
        assert!((p.intersect(&o, &d, 10.0).unwrap().t - 2.0).abs() < 1e-12);
        let q = PlanarPolygon::parallelogram(
            Point3::new(0.0, 0.0, 0.0),
            Vector3::new(2.0, 0.0, 0.0),
            Vector3::new(1.0, 1.0, 0.0),
        )
        .unwrap();
        assert!((q.normal() - Vector3::z()).norm() < 1e-12);
        assert!((q.area() - 2.0).abs() < 1e-12);
        let (o, d) = ray([2.9, 0.95, 1.0], [0.0, 0.0, -1.0]);
        assert!(q.intersect(&o, &d, 10.0).is_some());
        let (o, d) = ray([0.1, 0.95, 1.0], [0.0, 0.0, -1.0]);
        assert!(q.intersect(&o, &d, 10.0).is_none(), "outside the slanted edge");
    }

    #[test]
    fn bad_polygons_are_refused() {
        let id = Isometry3::identity();
        let pts =
            |v: &[(Real, Real)]| v.iter().map(|&(x, y)| Point2::new(x, y)).collect::<Vec<_>>();
        assert_eq!(
            PlanarPolygon::new(id, pts(&[(0.0, 0.0), (1.0, 0.0)]), vec![]),
            Err(SceneError::TooFewVertices { ring: 0, count: 2 })
        );
        assert!(matches!(
            PlanarPolygon::new(id, pts(&[(0.0, 0.0), (1.0, 0.0), (2.0, 0.0)]), vec![]),
            Err(SceneError::DegeneratePolygon { ring: 0, .. })
        ));
        assert!(matches!(
            PlanarPolygon::new(id, pts(&[(0.0, 0.0), (1.0, 0.0), (Real::NAN, 1.0)]), vec![]),
            Err(SceneError::NonFinite { .. })
        ));
        let square = pts(&[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]);
        assert!(matches!(
            PlanarPolygon::new(id, square.clone(), vec![pts(&[(0.2, 0.2), (0.5, 0.5)])]),
            Err(SceneError::TooFewVertices { ring: 1, count: 2 })
        ));
        let bad = Isometry3::translation(Real::INFINITY, 0.0, 0.0);
        assert!(matches!(
            PlanarPolygon::new(bad, square.clone(), vec![]),
            Err(SceneError::NonFinite { .. })
        ));
        let mut skew = Isometry3::identity();
        skew.rotation =
            nalgebra::UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(2.0, 0.0, 0.0, 0.0));
        assert!(matches!(
            PlanarPolygon::new(skew, square, vec![]),
            Err(SceneError::NonUnitRotation { .. })
        ));
        assert!(matches!(
            PlanarPolygon::parallelogram(Point3::origin(), Vector3::x(), Vector3::x() * 2.0),
            Err(SceneError::DegeneratePolygon { .. })
        ));
    }

    #[test]
    fn box_faces_from_outside_and_inside() {
        let b =
            Cuboid::axis_aligned(Point3::new(1.0, -1.0, -1.0), Point3::new(3.0, 1.0, 1.0)).unwrap();
        let (o, d) = ray([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
        let h = b.intersect(&o, &d, 10.0).unwrap();
        assert_eq!((h.t, h.part), (1.0, 0));
        assert_eq!(h.normal, -Vector3::x());
        let (o, d) = ray([2.0, 0.0, 5.0], [0.0, 0.0, -1.0]);
        let h = b.intersect(&o, &d, 10.0).unwrap();
        assert_eq!((h.t, h.part), (4.0, 5));
        // From inside: the face the ray leaves through.
        let (o, d) = ray([2.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let h = b.intersect(&o, &d, 10.0).unwrap();
        assert_eq!((h.t, h.part), (1.0, 3));
        let (o, d) = ray([0.0, 2.0, 0.0], [1.0, 0.0, 0.0]);
        assert!(b.intersect(&o, &d, 10.0).is_none());
        // Posed: a unit cube turned 45° about z at x = 3 presents an edge at x = 3 − √2/2.
        let c =
            Cuboid::standing(Point2::new(3.0, 0.0), -0.5, Vector3::repeat(1.0), FRAC_PI_4).unwrap();
        let (o, d) = ray([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
        let h = c.intersect(&o, &d, 10.0).unwrap();
        assert!((h.t - (3.0 - FRAC_1_SQRT_2_HALF)).abs() < 1e-12);
        assert!(matches!(
            Cuboid::new(Isometry3::identity(), Vector3::new(1.0, 0.0, 1.0)),
            Err(SceneError::BadParameter { .. })
        ));
    }

    const FRAC_1_SQRT_2_HALF: Real = std::f64::consts::SQRT_2 / 2.0;

    #[test]
    fn sphere_hits() {
        let s = Sphere::new(Point3::new(5.0, 0.0, 0.0), 1.0).unwrap();
        let (o, d) = ray([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
        let h = s.intersect(&o, &d, 10.0).unwrap();
        assert!((h.t - 4.0).abs() < 1e-12);
        assert!((h.normal + Vector3::x()).norm() < 1e-12);
        let (o, d) = ray([5.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
        assert!((s.intersect(&o, &d, 10.0).unwrap().t - 1.0).abs() < 1e-12, "from inside");
        let (o, d) = ray([0.0, 1.01, 0.0], [1.0, 0.0, 0.0]);
        assert!(s.intersect(&o, &d, 10.0).is_none());
        // Slanted: the distance to a sphere along a ray at offset y = 0.6 is 5 − 0.8.
        let (o, d) = ray([0.0, 0.6, 0.0], [1.0, 0.0, 0.0]);
        assert!((s.intersect(&o, &d, 10.0).unwrap().t - 4.2).abs() < 1e-12);
        assert!(Sphere::new(Point3::origin(), 0.0).is_err());
        assert!(Sphere::new(Point3::new(Real::NAN, 0.0, 0.0), 1.0).is_err());
    }

    #[test]
    fn cylinder_side_and_caps() {
        let c = Cylinder::upright(Point3::new(4.0, 0.0, 0.0), 0.5, 2.0).unwrap();
        let (o, d) = ray([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
        let h = c.intersect(&o, &d, 10.0).unwrap();
        assert_eq!(h.part, 0);
        assert!((h.t - 3.5).abs() < 1e-12);
        assert!((h.normal + Vector3::x()).norm() < 1e-12);
        let (o, d) = ray([4.2, 0.1, 5.0], [0.0, 0.0, -1.0]);
        let h = c.intersect(&o, &d, 10.0).unwrap();
        assert_eq!(h.part, 2);
        assert!((h.t - 3.0).abs() < 1e-12);
        let (o, d) = ray([0.0, 0.0, 2.5], [1.0, 0.0, 0.0]);
        assert!(c.intersect(&o, &d, 10.0).is_none(), "above the top");
        // Slanted into the top cap from above-left: enters through the cap at (3.6, 0, 2).
        let (o, d) = ray([2.6, 0.0, 3.0], [1.0, 0.0, -1.0]);
        let h = c.intersect(&o, &d, 10.0).unwrap();
        assert_eq!(h.part, 2);
        assert!((h.t - 2f64.sqrt()).abs() < 1e-12);
        // A lying cylinder (axis along y).
        let m = Isometry3::new(Vector3::new(3.0, 0.0, 0.0), Vector3::x() * FRAC_PI_2);
        let lying = Cylinder::new(m, 1.0, 2.0).unwrap();
        let (o, d) = ray([0.0, 1.5, 0.0], [1.0, 0.0, 0.0]);
        assert!((lying.intersect(&o, &d, 10.0).unwrap().t - 2.0).abs() < 1e-12);
        let (o, d) = ray([3.0, 10.0, 0.5], [0.0, -1.0, 0.0]);
        let h = lying.intersect(&o, &d, 20.0).unwrap();
        assert!((h.t - 8.0).abs() < 1e-12);
        let aabb = Shape::from(lying).aabb();
        assert!((aabb.extents() - Vector3::new(2.0, 4.0, 2.0)).norm() < 1e-9);
        assert!(Cylinder::upright(Point3::origin(), -1.0, 1.0).is_err());
        assert!(Cylinder::upright(Point3::origin(), 1.0, 0.0).is_err());
    }

    /// A hit point nudged into the solid (against the outward normal) is inside it, nudged out
    /// of it is not.
    #[test]
    fn hits_lie_on_the_solid_boundary() {
        let shapes: Vec<Shape> = vec![
            Cuboid::standing(Point2::new(3.0, 0.5), 0.0, Vector3::new(1.0, 2.0, 0.7), 0.4)
                .unwrap()
                .into(),
            Sphere::new(Point3::new(3.0, -0.5, 0.3), 0.8).unwrap().into(),
            Cylinder::new(
                Isometry3::new(Vector3::new(3.0, 0.0, 0.5), Vector3::new(0.3, 0.9, 0.1)),
                0.4,
                0.9,
            )
            .unwrap()
            .into(),
        ];
        let mut hits = 0;
        for s in &shapes {
            for i in 0..400 {
                let a = i as Real * 0.0157;
                let target = [3.0, (a * 7.0).sin(), 0.4 + (a * 3.0).cos()];
                let (o, d) = ray([0.0, 0.0, 0.5], [target[0], target[1], target[2] - 0.5]);
                let Some(h) = s.intersect(&o, &d, 20.0) else { continue };
                hits += 1;
                let p = o + d * h.t;
                // Outward normal: the shape's normal faces away from the inside.
                let n = h.normal;
                let (inside, outside) = (p - n * 1e-6, p + n * 1e-6);
                assert!(s.contains(&inside) && !s.contains(&outside), "{s:?} at {p}");
            }
        }
        assert!(hits > 200, "{hits}");
    }
}
