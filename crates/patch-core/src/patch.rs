//! Patches: planar polygons with a pose, and triangle meshes (thesis §5.1).

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::geometry::{
    ClosestPoint, Contact, SegmentDistance, TriangleFrame, closest_point_on_region,
    first_contact_region, segment_region_distance, segment_region_within,
};
use crate::step::Step;
use crate::{
    Aabb, Isometry3, PatchError, Point2, Point3, Polygon, Real, RingId, UnitVector3, Vector3, na,
};

/// Triangles with a smaller area (in m²) are degenerate and rejected by [`TrimeshPatch::new`].
pub const MIN_TRIANGLE_AREA: Real = 1e-12;

/// The kinds of patch a map can hold.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum PatchKind {
    /// [`PlanarPatch`].
    Planar,
    /// [`TrimeshPatch`].
    Trimesh,
}

impl fmt::Display for PatchKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            PatchKind::Planar => "planar",
            PatchKind::Trimesh => "trimesh",
        })
    }
}

/// The frame of a planar patch on the plane through `origin` with normal `normal` (any length
/// but zero): `z` = the unit normal, `x` = the world axis least aligned with the normal (the
/// first of x, y, z on ties) made orthogonal to it, `y = z × x`, origin at `origin`. Every
/// patch built from world coordinates here ([`PlanarPatch::from_world_polygon`], patches from
/// meshes, extraction) uses this rule, so patches of one plane share their axes.
pub fn plane_frame(normal: &Vector3, origin: &Point3) -> Isometry3 {
    let normal = normal.normalize();
    let axis = normal.iamin();
    let mut x = Vector3::zeros();
    x[axis] = 1.0;
    let x = (x - normal * normal[axis]).normalize();
    let y = normal.cross(&x);
    let rotation = na::Rotation3::from_matrix_unchecked(na::Matrix3::from_columns(&[x, y, normal]));
    Isometry3::from_parts(
        na::Translation3::from(origin.coords),
        na::UnitQuaternion::from_rotation_matrix(&rotation),
    )
}

/// A plane `normal · x = offset` in Hessian normal form.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Plane {
    /// The unit normal.
    pub normal: UnitVector3,
    /// The signed distance of the plane from the origin along the normal.
    pub offset: Real,
}

impl Plane {
    /// `normal · p − offset`: positive on the side the normal points to.
    #[inline]
    pub fn signed_distance(&self, p: &Point3) -> Real {
        self.normal.dot(&p.coords) - self.offset
    }
}

/// The uncertainty of a fitted plane: a symmetric 4×4 covariance of `(nx, ny, nz, d)` in the
/// world frame, where `n · x = d` is the plane (thesis App. A: map files keep a per-patch
/// uncertainty; the fit in [Pathak 2010] yields it).
///
/// Validated: finite, symmetric (entries mirrored across the diagonal may differ by at most
/// `1e-9 · max(1, max |entry|)`; the stored matrix is the symmetrised one) and with
/// non-negative variances on the diagonal. Positive semi-definiteness is not checked.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "na::Matrix4<Real>", into = "na::Matrix4<Real>")]
pub struct PlaneCovariance(na::Matrix4<Real>);

impl PlaneCovariance {
    /// Validates and symmetrises a covariance matrix.
    ///
    /// # Errors
    /// [`PatchError::NonFiniteCovariance`], [`PatchError::AsymmetricCovariance`],
    /// [`PatchError::NegativeVariance`], naming the entry.
    pub fn new(matrix: na::Matrix4<Real>) -> Result<PlaneCovariance, PatchError> {
        for row in 0..4 {
            for col in 0..4 {
                if !matrix[(row, col)].is_finite() {
                    return Err(PatchError::NonFiniteCovariance { row, col });
                }
            }
        }
        let scale = matrix.amax().max(1.0);
        for row in 0..4 {
            for col in row + 1..4 {
                if (matrix[(row, col)] - matrix[(col, row)]).abs() > 1e-9 * scale {
                    return Err(PatchError::AsymmetricCovariance { row, col });
                }
            }
        }
        if let Some(index) = (0..4).find(|&i| matrix[(i, i)] < 0.0) {
            return Err(PatchError::NegativeVariance { index });
        }
        Ok(PlaneCovariance((matrix + matrix.transpose()) * 0.5))
    }

    /// The symmetric matrix.
    pub fn matrix(&self) -> &na::Matrix4<Real> {
        &self.0
    }
}

impl TryFrom<na::Matrix4<Real>> for PlaneCovariance {
    type Error = PatchError;
    fn try_from(m: na::Matrix4<Real>) -> Result<Self, Self::Error> {
        PlaneCovariance::new(m)
    }
}

impl From<PlaneCovariance> for na::Matrix4<Real> {
    fn from(c: PlaneCovariance) -> Self {
        c.0
    }
}

/// Checks that an isometry is finite with a unit rotation (norm within 1e-6 of 1); a rotation
/// off by more than 1e-12 is renormalised.
fn validate_isometry(iso: Isometry3) -> Result<Isometry3, PatchError> {
    let q = iso.rotation.into_inner();
    let finite = iso.translation.vector.iter().chain(q.coords.iter()).all(|c| c.is_finite());
    let norm = q.norm();
    if !finite || (norm - 1.0).abs() > 1e-6 {
        return Err(PatchError::InvalidTransform);
    }
    if (norm - 1.0).abs() > 1e-12 {
        let rotation = na::UnitQuaternion::new_normalize(q);
        return Ok(Isometry3::from_parts(iso.translation, rotation));
    }
    Ok(iso)
}

/// A planar patch: a polygon with holes in the xy-plane of its own frame, and the rigid
/// transform `world_from_patch` placing that frame in the world (thesis §5.1, Fig. 5.1).
///
/// The thesis keeps the 2D polygon and one full transform rather than a canonical `(n, d)`
/// plane with canonical in-plane axes, because canonical axes jump when the normal passes a
/// reference direction and because moving a patch within its plane then needs no vertex
/// updates (§5.1). The plane is derived, never stored twice: [`normal`](Self::normal) is the
/// frame's z axis in the world, [`offset`](Self::offset) is `normal · origin`.
///
/// Optionally carries the plane's [`PlaneCovariance`] from the fit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawPlanarPatch", into = "RawPlanarPatch")]
pub struct PlanarPatch {
    polygon: Polygon,
    world_from_patch: Isometry3,
    covariance: Option<PlaneCovariance>,
}

#[derive(Serialize, Deserialize)]
struct RawPlanarPatch {
    polygon: Polygon,
    world_from_patch: Isometry3,
    #[serde(default)]
    covariance: Option<PlaneCovariance>,
}

impl TryFrom<RawPlanarPatch> for PlanarPatch {
    type Error = PatchError;
    fn try_from(raw: RawPlanarPatch) -> Result<Self, Self::Error> {
        let mut patch = PlanarPatch::new(raw.polygon, raw.world_from_patch)?;
        patch.covariance = raw.covariance;
        Ok(patch)
    }
}

impl From<PlanarPatch> for RawPlanarPatch {
    fn from(p: PlanarPatch) -> Self {
        RawPlanarPatch {
            polygon: p.polygon,
            world_from_patch: p.world_from_patch,
            covariance: p.covariance,
        }
    }
}

/// # Construction
impl PlanarPatch {
    /// The patch with this polygon (in the patch frame's xy-plane) and pose.
    ///
    /// # Errors
    /// [`PatchError::InvalidTransform`] if the transform has non-finite entries or a rotation
    /// that is not a unit quaternion.
    pub fn new(polygon: Polygon, world_from_patch: Isometry3) -> Result<PlanarPatch, PatchError> {
        let world_from_patch = validate_isometry(world_from_patch)?;
        Ok(PlanarPatch { polygon, world_from_patch, covariance: None })
    }

    /// The rectangle `[min, max]` (in the patch frame) placed by `world_from_patch`.
    ///
    /// # Errors
    /// As [`Polygon::rectangle`] and [`PlanarPatch::new`].
    pub fn rectangle(
        world_from_patch: Isometry3,
        min: Point2,
        max: Point2,
    ) -> Result<PlanarPatch, PatchError> {
        PlanarPatch::new(Polygon::rectangle(min, max)?, world_from_patch)
    }

    /// The patch through 3D rings: fits a plane and expresses the rings in a frame on it.
    ///
    /// * Plane: orthogonal least squares over all vertices of all rings (the normal is the
    ///   eigenvector of the smallest eigenvalue of the scatter matrix about the centroid).
    /// * Normal sign: the outer ring, seen from the side the normal points to, runs
    ///   counter-clockwise (right-hand rule on its Newell normal). So the caller picks the side
    ///   by the order of the outer ring.
    /// * Frame (the recommendation of the project's patch-map spec, §1): origin = the centroid
    ///   (which lies on the fitted plane, so it is the centroid of the projected points),
    ///   z = normal, x = the world axis least aligned with the normal (first of x, y, z on
    ///   ties) made orthogonal to it, y = z × x.
    ///
    /// # Errors
    /// [`PatchError::InvalidTolerance`] for a negative or non-finite tolerance;
    /// [`PatchError::TooFewVertices`] / [`PatchError::NonFiniteVertex`] for bad rings;
    /// [`PatchError::NotPlanar`] if a vertex is farther than `tolerance` from the fitted
    /// plane; then any polygon error of [`Polygon::new`] (holes given in 3D that cross the
    /// outer ring, …).
    pub fn from_world_polygon(
        outer: &[Point3],
        holes: &[Vec<Point3>],
        tolerance: Real,
    ) -> Result<PlanarPatch, PatchError> {
        if !(tolerance >= 0.0 && tolerance.is_finite()) {
            return Err(PatchError::InvalidTolerance { tolerance });
        }
        let rings: Vec<(RingId, &[Point3])> = std::iter::once((RingId::Outer, outer))
            .chain(holes.iter().enumerate().map(|(k, h)| (RingId::Hole(k), h.as_slice())))
            .collect();
        for (ring, points) in &rings {
            if points.len() < 3 {
                return Err(PatchError::TooFewVertices { ring: *ring, count: points.len() });
            }
            if let Some(vertex) = points.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
                return Err(PatchError::NonFiniteVertex { ring: *ring, vertex });
            }
        }
        let count = rings.iter().map(|(_, p)| p.len()).sum::<usize>() as Real;
        let centroid = Point3::from(
            rings.iter().flat_map(|(_, p)| p.iter()).map(|p| p.coords).sum::<Vector3>() / count,
        );
        let mut scatter = na::Matrix3::<Real>::zeros();
        for p in rings.iter().flat_map(|(_, p)| p.iter()) {
            let v = p - centroid;
            scatter += v * v.transpose();
        }
        let eigen = na::SymmetricEigen::new(scatter);
        let smallest = eigen.eigenvalues.imin();
        let mut normal: Vector3 = eigen.eigenvectors.column(smallest).into_owned();
        let mut newell = Vector3::zeros();
        for i in 0..outer.len() {
            let a = outer[i] - centroid;
            let b = outer[(i + 1) % outer.len()] - centroid;
            newell += a.cross(&b);
        }
        if newell.dot(&normal) < 0.0 {
            normal = -normal;
        }
        let world_from_patch = plane_frame(&normal, &centroid);
        let mut local_rings = Vec::with_capacity(rings.len());
        for (ring, points) in &rings {
            let mut local = Vec::with_capacity(points.len());
            for (vertex, p) in points.iter().enumerate() {
                let q = world_from_patch.inverse_transform_point(p);
                if q.z.abs() > tolerance {
                    return Err(PatchError::NotPlanar {
                        ring: *ring,
                        vertex,
                        distance: q.z.abs(),
                        tolerance,
                    });
                }
                local.push(Point2::new(q.x, q.y));
            }
            local_rings.push(local);
        }
        let outer_local = local_rings.remove(0);
        let polygon = Polygon::new(outer_local, local_rings)?;
        PlanarPatch::new(polygon, world_from_patch)
    }

    /// This patch with a plane covariance attached.
    pub fn with_covariance(mut self, covariance: PlaneCovariance) -> PlanarPatch {
        self.covariance = Some(covariance);
        self
    }
}

/// # Access
impl PlanarPatch {
    /// The polygon in the patch frame.
    pub fn polygon(&self) -> &Polygon {
        &self.polygon
    }

    /// The pose of the patch frame in the world.
    pub fn world_from_patch(&self) -> &Isometry3 {
        &self.world_from_patch
    }

    /// The plane covariance from the fit, if known.
    pub fn covariance(&self) -> Option<&PlaneCovariance> {
        self.covariance.as_ref()
    }

    /// The plane normal in the world: the patch frame's z axis. The polygon runs
    /// counter-clockwise seen from the side it points to.
    pub fn normal(&self) -> UnitVector3 {
        UnitVector3::new_normalize(self.world_from_patch.rotation * Vector3::z())
    }

    /// The plane offset `d` in `normal · x = d`.
    pub fn offset(&self) -> Real {
        self.normal().dot(&self.world_from_patch.translation.vector)
    }

    /// The plane in Hessian normal form.
    pub fn plane(&self) -> Plane {
        Plane { normal: self.normal(), offset: self.offset() }
    }

    /// A point of the patch plane (patch-frame 2D coordinates) in the world.
    pub fn to_world(&self, p: &Point2) -> Point3 {
        self.world_from_patch * Point3::new(p.x, p.y, 0.0)
    }

    /// A world point in the patch frame; its `z` is the signed height above the plane.
    pub fn to_local(&self, p: &Point3) -> Point3 {
        self.world_from_patch.inverse_transform_point(p)
    }

    /// The area of the polygon.
    pub fn area(&self) -> Real {
        self.polygon.area()
    }

    /// The world box of the outer ring's vertices as transformed to the world in floating
    /// point (holes lie inside it).
    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for p in self.polygon.outer().points() {
            b.grow(&self.to_world(p));
        }
        b
    }
}

/// # Queries (world frame)
///
/// Each query is transformed into the patch frame, answered there by the kernels of
/// [`geometry`](crate::geometry), and transformed back.
impl PlanarPatch {
    /// The point of the patch closest to `p` and its distance.
    pub fn closest_point(&self, p: &Point3) -> ClosestPoint {
        let c = closest_point_on_region(&self.polygon, &self.to_local(p));
        ClosestPoint { point: self.world_from_patch * c.point, distance: c.distance }
    }

    /// The closest approach of the segment `a → b` to the patch
    /// ([`segment_region_distance`]).
    pub fn segment_distance(&self, a: &Point3, b: &Point3) -> SegmentDistance {
        let s = segment_region_distance(&self.polygon, &self.to_local(a), &self.to_local(b));
        SegmentDistance { point: self.world_from_patch * s.point, ..s }
    }

    /// Whether the segment `a → b` comes within `radius` of the patch: the answer of
    /// `segment_distance(a, b).distance <= radius`, with early rejects by the plane and the
    /// polygon's bounding rectangle ([`segment_region_within`]).
    pub fn segment_within(&self, a: &Point3, b: &Point3, radius: Real) -> bool {
        segment_region_within(&self.polygon, &self.to_local(a), &self.to_local(b), radius)
    }

    /// The first contact of a sphere of radius `radius` swept from `a` to `b`
    /// ([`first_contact_region`]); the normal is the plane normal, flipped as
    /// [`StepHit`](crate::StepHit) describes.
    pub fn first_contact(&self, a: &Point3, b: &Point3, radius: Real) -> Option<Contact> {
        let c = first_contact_region(&self.polygon, &self.to_local(a), &self.to_local(b), radius)?;
        Some(Contact {
            t: c.t,
            point: self.world_from_patch * c.point,
            normal: UnitVector3::new_normalize(
                self.world_from_patch.rotation * c.normal.into_inner(),
            ),
        })
    }
}

/// A triangle mesh patch (thesis §5.1: the non-planar remainder of hybrid maps, and whole
/// trimesh maps).
///
/// Validated: at least one triangle, finite vertices, indices in range, every triangle of area
/// at least [`MIN_TRIANGLE_AREA`]. Unused vertices are allowed. Triangle orientation carries no
/// meaning (the surface is two-sided).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawTrimeshPatch", into = "RawTrimeshPatch")]
pub struct TrimeshPatch {
    vertices: Vec<Point3>,
    triangles: Vec<[u32; 3]>,
}

#[derive(Serialize, Deserialize)]
struct RawTrimeshPatch {
    vertices: Vec<Point3>,
    triangles: Vec<[u32; 3]>,
}

impl TryFrom<RawTrimeshPatch> for TrimeshPatch {
    type Error = PatchError;
    fn try_from(raw: RawTrimeshPatch) -> Result<Self, Self::Error> {
        TrimeshPatch::new(raw.vertices, raw.triangles)
    }
}

impl From<TrimeshPatch> for RawTrimeshPatch {
    fn from(p: TrimeshPatch) -> Self {
        RawTrimeshPatch { vertices: p.vertices, triangles: p.triangles }
    }
}

impl TrimeshPatch {
    /// The heap bytes this patch owns: its vertex and triangle buffers, by capacity.
    pub fn heap_bytes(&self) -> usize {
        self.vertices.capacity() * std::mem::size_of::<Point3>()
            + self.triangles.capacity() * std::mem::size_of::<[u32; 3]>()
    }

    /// Validates and builds the mesh.
    ///
    /// # Errors
    /// [`PatchError::NoTriangles`], [`PatchError::NonFiniteMeshVertex`],
    /// [`PatchError::IndexOutOfRange`], [`PatchError::DegenerateTriangle`].
    pub fn new(
        vertices: Vec<Point3>,
        triangles: Vec<[u32; 3]>,
    ) -> Result<TrimeshPatch, PatchError> {
        if triangles.is_empty() {
            return Err(PatchError::NoTriangles);
        }
        if let Some(vertex) = vertices.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(PatchError::NonFiniteMeshVertex { vertex });
        }
        for (triangle, tri) in triangles.iter().enumerate() {
            if let Some(&index) = tri.iter().find(|&&i| i as usize >= vertices.len()) {
                return Err(PatchError::IndexOutOfRange {
                    triangle,
                    index,
                    num_vertices: vertices.len(),
                });
            }
            let [a, b, c] = tri.map(|i| vertices[i as usize]);
            let area = 0.5 * (b - a).cross(&(c - a)).norm();
            if area < MIN_TRIANGLE_AREA || TriangleFrame::new(&[a, b, c]).is_none() {
                return Err(PatchError::DegenerateTriangle { triangle, area });
            }
        }
        let (mut vertices, mut triangles) = (vertices, triangles);
        vertices.shrink_to_fit();
        triangles.shrink_to_fit();
        Ok(TrimeshPatch { vertices, triangles })
    }

    /// The vertices.
    pub fn vertices(&self) -> &[Point3] {
        &self.vertices
    }

    /// The triangles, as indices into [`vertices`](Self::vertices).
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The number of triangles (at least 1).
    pub fn num_triangles(&self) -> usize {
        self.triangles.len()
    }

    /// The corners of triangle `i`.
    ///
    /// # Panics
    /// If `i` is not a triangle index.
    pub fn triangle(&self, i: usize) -> [Point3; 3] {
        self.triangles[i].map(|k| self.vertices[k as usize])
    }

    /// The local frame of every triangle, in order ([`TriangleFrame`]).
    pub fn triangle_frames(&self) -> impl Iterator<Item = TriangleFrame> + '_ {
        (0..self.triangles.len())
            .map(|i| TriangleFrame::new(&self.triangle(i)).expect("triangles are validated"))
    }

    /// The total area of the triangles.
    pub fn area(&self) -> Real {
        (0..self.triangles.len())
            .map(|i| {
                let [a, b, c] = self.triangle(i);
                0.5 * (b - a).cross(&(c - a)).norm()
            })
            .sum()
    }

    /// The box of the vertices used by triangles.
    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for tri in &self.triangles {
            for &i in tri {
                b.grow(&self.vertices[i as usize]);
            }
        }
        b
    }
}

/// # Queries (world frame)
///
/// Loops over all triangles. Ties go to the lowest triangle index, except for
/// [`first_contact`](Self::first_contact), where among triangles touched at the same `t` the
/// one nearest to the sphere's centre wins (so the contact point is the mesh's closest point).
impl TrimeshPatch {
    /// The point of the mesh closest to `p` and its distance.
    pub fn closest_point(&self, p: &Point3) -> ClosestPoint {
        let mut best = ClosestPoint { point: self.vertices[0], distance: Real::INFINITY };
        for frame in self.triangle_frames() {
            let c = frame.closest_point(p);
            if c.distance < best.distance {
                best = c;
            }
        }
        best
    }

    /// The closest approach of the segment `a → b` to the mesh.
    pub fn segment_distance(&self, a: &Point3, b: &Point3) -> SegmentDistance {
        let mut best =
            SegmentDistance { distance: Real::INFINITY, t: 0.0, point: self.vertices[0] };
        for frame in self.triangle_frames() {
            let s = frame.segment_distance(a, b);
            if s.distance < best.distance {
                best = s;
                if best.distance == 0.0 {
                    break;
                }
            }
        }
        best
    }

    /// The first contact of a sphere of radius `radius` swept from `a` to `b`; the normal is
    /// the normal of the triangle touched first, flipped as [`StepHit`](crate::StepHit)
    /// describes.
    pub fn first_contact(&self, a: &Point3, b: &Point3, radius: Real) -> Option<Contact> {
        let mut best: Option<(Contact, Real)> = None;
        for frame in self.triangle_frames() {
            if let Some(c) = frame.first_contact(a, b, radius) {
                let gap = (a + (b - a) * c.t - c.point).norm_squared();
                if best.is_none_or(|(b, g)| earlier(c.t, gap, b.t, g)) {
                    best = Some((c, gap));
                }
            }
        }
        best.map(|(c, _)| c)
    }
}

/// Whether a contact at `t` with squared centre distance `gap` comes before one at `t_best`,
/// `gap_best`: earlier, or as early and nearer.
pub(crate) fn earlier(t: Real, gap: Real, t_best: Real, gap_best: Real) -> bool {
    t < t_best || (t == t_best && gap < gap_best)
}

/// A patch of a map: planar or triangle mesh.
// Most patches are planar, and the queries read them in place: boxing the larger variant would
// add a pointer chase to every collision test to save memory on the rarer meshes.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Patch {
    /// A planar polygon with holes and a pose.
    Planar(PlanarPatch),
    /// A triangle mesh.
    Trimesh(TrimeshPatch),
}

impl From<PlanarPatch> for Patch {
    fn from(p: PlanarPatch) -> Self {
        Patch::Planar(p)
    }
}

impl From<TrimeshPatch> for Patch {
    fn from(p: TrimeshPatch) -> Self {
        Patch::Trimesh(p)
    }
}

impl PlanarPatch {
    /// This patch moved rigidly by `motion` (e.g. from a scan's sensor frame to the world by
    /// the scan's pose): the frame becomes `motion · world_from_patch`, and a plane covariance
    /// of `(n, d)` is carried along to first order — exactly, since the map is linear:
    /// `n' = R n`, `d' = d + n'·t`, so `Σ' = J Σ Jᵀ` with `J = [[R, 0], [(Rᵀ t)ᵀ, 1]]`.
    pub fn transformed(&self, motion: &Isometry3) -> PlanarPatch {
        let world_from_patch = motion * self.world_from_patch;
        let covariance = self.covariance.map(|c| {
            let r = motion.rotation.to_rotation_matrix().into_inner();
            let rt_t = r.transpose() * motion.translation.vector;
            let mut j = na::Matrix4::<Real>::zeros();
            j.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
            j[(3, 0)] = rt_t.x;
            j[(3, 1)] = rt_t.y;
            j[(3, 2)] = rt_t.z;
            j[(3, 3)] = 1.0;
            let m = j * c.matrix() * j.transpose();
            // Symmetric up to rounding; re-symmetrise exactly.
            PlaneCovariance((m + m.transpose()) * 0.5)
        });
        PlanarPatch { polygon: self.polygon.clone(), world_from_patch, covariance }
    }
}

impl TrimeshPatch {
    /// This mesh moved rigidly by `motion`.
    pub fn transformed(&self, motion: &Isometry3) -> TrimeshPatch {
        TrimeshPatch {
            vertices: self.vertices.iter().map(|v| motion * v).collect(),
            triangles: self.triangles.clone(),
        }
    }
}

impl Patch {
    /// This patch moved rigidly by `motion` ([`PlanarPatch::transformed`],
    /// [`TrimeshPatch::transformed`]).
    pub fn transformed(&self, motion: &Isometry3) -> Patch {
        match self {
            Patch::Planar(p) => Patch::Planar(p.transformed(motion)),
            Patch::Trimesh(m) => Patch::Trimesh(m.transformed(motion)),
        }
    }

    /// The heap bytes this patch owns (its polygon rings or mesh buffers, by capacity); the
    /// patch value itself is not included.
    pub fn heap_bytes(&self) -> usize {
        match self {
            Patch::Planar(p) => p.polygon().heap_bytes(),
            Patch::Trimesh(m) => m.heap_bytes(),
        }
    }

    /// Which kind of patch this is.
    pub fn kind(&self) -> PatchKind {
        match self {
            Patch::Planar(_) => PatchKind::Planar,
            Patch::Trimesh(_) => PatchKind::Trimesh,
        }
    }

    /// The planar patch, if it is one.
    pub fn as_planar(&self) -> Option<&PlanarPatch> {
        match self {
            Patch::Planar(p) => Some(p),
            Patch::Trimesh(_) => None,
        }
    }

    /// The triangle mesh, if it is one.
    pub fn as_trimesh(&self) -> Option<&TrimeshPatch> {
        match self {
            Patch::Trimesh(m) => Some(m),
            Patch::Planar(_) => None,
        }
    }

    /// The world box of the patch.
    pub fn bounds(&self) -> Aabb {
        match self {
            Patch::Planar(p) => p.bounds(),
            Patch::Trimesh(m) => m.bounds(),
        }
    }

    /// The surface area.
    pub fn area(&self) -> Real {
        match self {
            Patch::Planar(p) => p.area(),
            Patch::Trimesh(m) => m.area(),
        }
    }

    /// How many triangles the patch becomes when triangulated: the mesh's triangle count, or
    /// for a polygon with `n` vertices in all and `h` holes, `n + 2h − 2` (every triangulation
    /// without added vertices has that many). For sizing buffers of triangulating backends.
    pub fn num_triangles_hint(&self) -> usize {
        match self {
            Patch::Planar(p) => p.polygon().num_vertices() + 2 * p.polygon().holes().len() - 2,
            Patch::Trimesh(m) => m.num_triangles(),
        }
    }

    /// The point of the patch closest to `p` and its distance.
    pub fn closest_point(&self, p: &Point3) -> ClosestPoint {
        match self {
            Patch::Planar(q) => q.closest_point(p),
            Patch::Trimesh(m) => m.closest_point(p),
        }
    }

    /// The closest approach of the segment `a → b` to the patch.
    pub fn segment_distance(&self, a: &Point3, b: &Point3) -> SegmentDistance {
        match self {
            Patch::Planar(q) => q.segment_distance(a, b),
            Patch::Trimesh(m) => m.segment_distance(a, b),
        }
    }

    /// The first contact of a sphere of radius `radius` swept from `a` to `b`.
    pub fn first_contact(&self, a: &Point3, b: &Point3, radius: Real) -> Option<Contact> {
        match self {
            Patch::Planar(q) => q.first_contact(a, b, radius),
            Patch::Trimesh(m) => m.first_contact(a, b, radius),
        }
    }

    /// Whether the step collides with this patch: the distance of its core segment is at most
    /// its radius (touching counts). The same answer as `segment_distance(..).distance <=
    /// radius`, found with early exits.
    pub fn collides_with<S: Step>(&self, step: &S) -> bool {
        let (a, b, r) = (step.start(), step.end(), step.radius());
        match self {
            Patch::Planar(q) => q.segment_within(&a, &b, r),
            Patch::Trimesh(m) => m.triangle_frames().any(|f| f.segment_within(&a, &b, r)),
        }
    }

    /// The first contact of the step with this patch ([`Patch::first_contact`]).
    pub fn step_contact<S: Step>(&self, step: &S) -> Option<Contact> {
        self.first_contact(&step.start(), &step.end(), step.radius())
    }
}

#[cfg(test)]
mod tests;
