//! A scene's exact geometry as patches (`patch-core` types): what a perfect patch extraction
//! (thesis Chapter 5, §5.1) would give for a [`Scene`].
//!
//! Every planar surface becomes a [`PlanarPatch`]: polygons with their holes, the six faces of
//! each box (normals outwards), and the two caps of each cylinder as regular polygons. Every
//! curved surface (a sphere, a cylinder's side) becomes one tessellated [`TrimeshPatch`]: the
//! `hybrid` map of the thesis's Table 6.1 (§6.1) built from ground truth instead of scans.
//!
//! Curved surfaces are tessellated with vertices on the surface (inscribed), so a mesh lies up
//! to `r·(1 − cos(π/n))` inside the true surface for `n` segments around; [`Tessellation`]
//! sets the segment count.
//!
//! ```
//! use scene_sim::patches::{Tessellation, scene_patches};
//! let patches = scene_patches(&scene_sim::lab(0).unwrap(), &Tessellation::default()).unwrap();
//! assert!(patches.iter().any(|p| p.as_trimesh().is_some()));
//! ```

use crate::{Cuboid, Cylinder, PlanarPolygon, Point2, Primitive, Scene, Shape, Sphere};
use patch_core::{
    Isometry3, Patch, PatchError, PlanarPatch, Point3, Polygon, Real, TrimeshPatch, Vector3,
};

/// Why a scene surface could not be turned into a patch.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PatchesError {
    /// A tessellation parameter is out of range.
    #[error("tessellation: {what} is {value}, outside its allowed range {allowed}")]
    BadTessellation {
        /// Which parameter.
        what: &'static str,
        /// Its value.
        value: f64,
        /// The allowed range, in words.
        allowed: &'static str,
    },
    /// A surface of a primitive is not a valid patch (a polygon that stays invalid after its
    /// floor- or ceiling-touching holes became notches, or a degenerate face or mesh).
    #[error("{surface} of `{primitive}`: {source}")]
    Surface {
        /// The primitive's name.
        primitive: String,
        /// Which of its surfaces (`"the polygon"`, `"a box face"`, `"the sphere"`, ...).
        surface: &'static str,
        /// Why `patch-core` refused it.
        #[source]
        source: PatchError,
    },
}

/// How curved surfaces (spheres, cylinder sides and the regular polygons standing in for
/// cylinder caps) are tessellated.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Tessellation {
    /// Longest edge around a curved surface, metres (default 0.1 m, the lab experiment's
    /// choice: the lab's barrel gets 19 segments, its table legs 8). Also the longest edge
    /// along a cylinder's axis.
    pub curved_edge: Real,
    /// Fewest segments around a sphere or cylinder (and vertices of a cap polygon); default 8.
    pub min_segments: usize,
}

impl Default for Tessellation {
    fn default() -> Tessellation {
        Tessellation { curved_edge: 0.1, min_segments: 8 }
    }
}

/// Most segments around one circle (a guard against a tiny `curved_edge`).
const MAX_SEGMENTS: Real = 100_000.0;

impl Tessellation {
    /// Checks the parameters.
    ///
    /// # Errors
    /// [`PatchesError::BadTessellation`] for a curved edge that is not a positive finite
    /// length, or fewer than 3 segments.
    pub fn check(&self) -> Result<(), PatchesError> {
        if !(self.curved_edge.is_finite() && self.curved_edge > 0.0) {
            return Err(PatchesError::BadTessellation {
                what: "the curved edge",
                value: self.curved_edge,
                allowed: "(0, ∞) m",
            });
        }
        if self.min_segments < 3 {
            return Err(PatchesError::BadTessellation {
                what: "the minimum segment count",
                value: self.min_segments as f64,
                allowed: "[3, ∞)",
            });
        }
        Ok(())
    }

    /// Segments around a circle of radius `r`: enough for edges of at most
    /// [`curved_edge`](Tessellation::curved_edge), at least
    /// [`min_segments`](Tessellation::min_segments), at most 100,000.
    pub fn segments(&self, r: Real) -> usize {
        let n = (std::f64::consts::TAU * r / self.curved_edge).ceil();
        (n.min(MAX_SEGMENTS) as usize).max(self.min_segments)
    }
}

/// Every surface of `scene` as a patch, primitive by primitive (see [`primitive_patches`] for
/// the order within one).
///
/// # Errors
/// A bad tessellation, or a surface that is not a valid patch ([`PatchesError::Surface`]).
pub fn scene_patches(scene: &Scene, t: &Tessellation) -> Result<Vec<Patch>, PatchesError> {
    t.check()?;
    let mut out = Vec::new();
    for primitive in scene.primitives() {
        out.extend(primitive_patches(primitive, t)?);
    }
    Ok(out)
}

/// The surfaces of one primitive as patches: a polygon's one planar patch, a box's six faces
/// (in the order of [`Cuboid::face_normal`]'s parts), a sphere's mesh, or a cylinder's side
/// mesh followed by its bottom and top caps.
///
/// # Errors
/// A bad tessellation, or a surface that is not a valid patch ([`PatchesError::Surface`]).
pub fn primitive_patches(
    primitive: &Primitive,
    t: &Tessellation,
) -> Result<Vec<Patch>, PatchesError> {
    t.check()?;
    let name = &primitive.name;
    let tag = |surface: &'static str| {
        move |source: PatchError| PatchesError::Surface { primitive: name.clone(), surface, source }
    };
    Ok(match &primitive.shape {
        Shape::Polygon(p) => vec![Patch::from(polygon_patch(p).map_err(tag("the polygon"))?)],
        Shape::Cuboid(c) => {
            cuboid_faces(c).map_err(tag("a box face"))?.into_iter().map(Patch::from).collect()
        }
        Shape::Sphere(s) => vec![Patch::from(sphere_mesh(s, t).map_err(tag("the sphere"))?)],
        Shape::Cylinder(c) => {
            let (side, [bottom, top]) =
                cylinder_surfaces(c, t).map_err(tag("a cylinder surface"))?;
            vec![Patch::from(side), Patch::from(bottom), Patch::from(top)]
        }
    })
}

/// The patch of a scene polygon, with its holes. A hole touching the outline (a door reaching
/// the floor) is invalid for a patch polygon; for an axis-aligned rectangle with rectangular
/// holes, such holes on the bottom or top edge become notches of the outline (same area).
///
/// # Errors
/// The polygon is not a valid patch polygon, also after notching.
pub fn polygon_patch(p: &PlanarPolygon) -> Result<PlanarPatch, PatchError> {
    let holes: Vec<Vec<Point2>> = p.holes().map(<[Point2]>::to_vec).collect();
    let polygon = match Polygon::new(p.outline().to_vec(), holes.clone()) {
        Ok(polygon) => polygon,
        Err(e) => {
            let Some((outline, holes)) = notched(p.outline(), &holes) else {
                return Err(e);
            };
            Polygon::new(outline, holes)?
        }
    };
    PlanarPatch::new(polygon, *p.world_from_patch())
}

/// The corners `(min, max)` of an axis-aligned rectangle ring, `None` for any other ring.
fn rectangle(ring: &[Point2]) -> Option<(Point2, Point2)> {
    if ring.len() != 4 {
        return None;
    }
    let lo = ring.iter().fold(ring[0], |m, p| m.inf(p));
    let hi = ring.iter().fold(ring[0], |m, p| m.sup(p));
    let on_corner = |q: &Point2| (q.x == lo.x || q.x == hi.x) && (q.y == lo.y || q.y == hi.y);
    ring.iter().all(on_corner).then_some((lo, hi))
}

/// The outline of a rectangle with its bottom- and top-touching rectangular holes cut in as
/// notches, and the other holes; `None` if the rings are not all axis-aligned rectangles or a
/// hole touches a side edge.
fn notched(outline: &[Point2], holes: &[Vec<Point2>]) -> Option<(Vec<Point2>, Vec<Vec<Point2>>)> {
    let (lo, hi) = rectangle(outline)?;
    let boxes: Vec<(Point2, Point2)> = holes.iter().map(|h| rectangle(h)).collect::<Option<_>>()?;
    if boxes.iter().any(|(a, b)| a.x <= lo.x || b.x >= hi.x) {
        return None;
    }
    let mut bottom: Vec<_> = boxes.iter().filter(|(a, _)| a.y <= lo.y).collect();
    let mut top: Vec<_> = boxes.iter().filter(|(a, b)| a.y > lo.y && b.y >= hi.y).collect();
    bottom.sort_by(|p, q| p.0.x.total_cmp(&q.0.x));
    top.sort_by(|p, q| q.0.x.total_cmp(&p.0.x));
    // Counter-clockwise: along the bottom eastwards, up, along the top westwards.
    let mut ring = vec![lo];
    for (a, b) in bottom {
        let up = b.y.min(hi.y);
        ring.extend([Point2::new(a.x, lo.y), Point2::new(a.x, up), Point2::new(b.x, up)]);
        ring.push(Point2::new(b.x, lo.y));
    }
    ring.extend([Point2::new(hi.x, lo.y), hi]);
    for (a, b) in top {
        ring.extend([Point2::new(b.x, hi.y), Point2::new(b.x, a.y), Point2::new(a.x, a.y)]);
        ring.push(Point2::new(a.x, hi.y));
    }
    ring.push(Point2::new(lo.x, hi.y));
    ring.dedup();
    let inner = boxes
        .iter()
        .filter(|(a, b)| a.y > lo.y && b.y < hi.y)
        .map(|(a, b)| vec![*a, Point2::new(b.x, a.y), *b, Point2::new(a.x, b.y)])
        .collect();
    Some((ring, inner))
}

/// A planar patch through world points given counter-clockwise seen from `normal`'s side.
fn world_patch(mut ring: Vec<Point3>, normal: &Vector3) -> Result<PlanarPatch, PatchError> {
    let newell = (0..ring.len()).fold(Vector3::zeros(), |n, i| {
        let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
        n + a.coords.cross(&b.coords)
    });
    if newell.dot(normal) < 0.0 {
        ring.reverse();
    }
    PlanarPatch::from_world_polygon(&ring, &[], 1e-9)
}

/// The six faces of a box as planar patches, normals outwards, in the order of the box's
/// parts ([`Cuboid::face_normal`]).
///
/// # Errors
/// A face `patch-core` refuses (a box too thin for its plane fit).
pub fn cuboid_faces(c: &Cuboid) -> Result<[PlanarPatch; 6], PatchError> {
    let axes = c.world_from_box().rotation.to_rotation_matrix().into_inner();
    let h = *c.half_extents();
    let face = |part: u32| {
        let a = (part / 2) as usize;
        let (i, j) = ((a + 1) % 3, (a + 2) % 3);
        let u: Vector3 = axes.column(i) * h[i];
        let v: Vector3 = axes.column(j) * h[j];
        let centre = c.face_center(part);
        let ring = vec![centre - u - v, centre + u - v, centre + u + v, centre - u + v];
        world_patch(ring, &c.face_normal(part))
    };
    Ok([face(0)?, face(1)?, face(2)?, face(3)?, face(4)?, face(5)?])
}

/// The side of a cylinder as a mesh (`t.segments(r)` around, rings at most
/// `t.curved_edge` apart along the axis) and its bottom and top caps as regular polygons with
/// the same vertices, normals outwards.
///
/// # Errors
/// A mesh or cap `patch-core` refuses.
pub fn cylinder_surfaces(
    c: &Cylinder,
    t: &Tessellation,
) -> Result<(TrimeshPatch, [PlanarPatch; 2]), PatchError> {
    let m: &Isometry3 = c.world_from_cylinder();
    let (r, h) = (c.radius(), c.half_height());
    let n = t.segments(r);
    let rings = ((2.0 * h / t.curved_edge).ceil() as usize).max(1);
    let at = |k: usize, z: Real| {
        let a = std::f64::consts::TAU * k as Real / n as Real;
        m * Point3::new(r * a.cos(), r * a.sin(), z)
    };
    let mut vertices = Vec::with_capacity(n * (rings + 1));
    for j in 0..=rings {
        let z = -h + 2.0 * h * j as Real / rings as Real;
        vertices.extend((0..n).map(|k| at(k, z)));
    }
    let mut triangles = Vec::with_capacity(2 * n * rings);
    for j in 0..rings {
        for k in 0..n {
            let (a, b) = ((j * n + k) as u32, (j * n + (k + 1) % n) as u32);
            let (c2, d) = (a + n as u32, b + n as u32);
            triangles.push([a, b, d]);
            triangles.push([a, d, c2]);
        }
    }
    let side = TrimeshPatch::new(vertices, triangles)?;
    let axis = c.axis();
    let bottom = world_patch((0..n).map(|k| at(k, -h)).collect(), &-axis)?;
    let top = world_patch((0..n).map(|k| at(k, h)).collect(), &axis)?;
    Ok((side, [bottom, top]))
}

/// A sphere as a closed latitude–longitude mesh: `t.segments(r)` meridians, half as many (at
/// least 2) latitude bands, one vertex at each pole.
///
/// # Errors
/// A mesh `patch-core` refuses.
pub fn sphere_mesh(s: &Sphere, t: &Tessellation) -> Result<TrimeshPatch, PatchError> {
    let (centre, r) = (s.center(), s.radius());
    let n = t.segments(r);
    let lat = (n / 2).max(2);
    let mut vertices = vec![centre + Vector3::z() * r, centre - Vector3::z() * r];
    for j in 1..lat {
        let polar = std::f64::consts::PI * j as Real / lat as Real;
        for k in 0..n {
            let a = std::f64::consts::TAU * k as Real / n as Real;
            let d = Vector3::new(polar.sin() * a.cos(), polar.sin() * a.sin(), polar.cos());
            vertices.push(centre + d * r);
        }
    }
    let ring = |j: usize, k: usize| (2 + (j - 1) * n + k % n) as u32;
    let mut triangles = Vec::new();
    for k in 0..n {
        triangles.push([0, ring(1, k), ring(1, k + 1)]);
        triangles.push([1, ring(lat - 1, k + 1), ring(lat - 1, k)]);
        for j in 1..lat - 1 {
            let (a, b) = (ring(j, k), ring(j, k + 1));
            let (c, d) = (ring(j + 1, k), ring(j + 1, k + 1));
            triangles.push([a, c, d]);
            triangles.push([a, d, b]);
        }
    }
    TrimeshPatch::new(vertices, triangles)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Material, SceneBuilder};
    use std::collections::HashMap;

    fn area(patches: &[Patch]) -> Real {
        patches.iter().map(Patch::area).sum()
    }

    #[test]
    fn a_box_gives_six_outward_faces() {
        let c = Cuboid::new(
            Isometry3::new(Vector3::new(1.0, 2.0, 0.5), Vector3::new(0.1, 0.2, 0.7)),
            Vector3::new(0.5, 1.0, 1.5),
        )
        .unwrap();
        let mut b = SceneBuilder::new("one box");
        b.add("box", c, Material::WOOD).unwrap();
        let patches = scene_patches(&b.build().unwrap(), &Tessellation::default()).unwrap();
        assert_eq!(patches.len(), 6);
        // 2·(1·2 + 1·3 + 2·3) = 22 m².
        assert!((area(&patches) - 22.0).abs() < 1e-9, "{}", area(&patches));
        let centre = Point3::new(1.0, 2.0, 0.5);
        for p in &patches {
            let p = p.as_planar().expect("box faces are planar");
            let on = p.to_world(&p.polygon().outer().points()[0]);
            assert!(p.normal().dot(&(on - centre)) > 0.0, "the normal points outwards");
        }
    }

    #[test]
    fn a_door_touching_the_floor_becomes_a_notch() {
        let outline = vec![
            Point2::new(0.0, 0.0),
            Point2::new(6.0, 0.0),
            Point2::new(6.0, 3.0),
            Point2::new(0.0, 3.0),
        ];
        let door = vec![
            Point2::new(2.0, 0.0),
            Point2::new(3.0, 0.0),
            Point2::new(3.0, 2.0),
            Point2::new(2.0, 2.0),
        ];
        let window = vec![
            Point2::new(4.0, 1.0),
            Point2::new(5.0, 1.0),
            Point2::new(5.0, 2.0),
            Point2::new(4.0, 2.0),
        ];
        assert!(
            Polygon::new(outline.clone(), vec![door.clone()]).is_err(),
            "a door hole is no patch polygon"
        );
        let wall = PlanarPolygon::new(Isometry3::identity(), outline, vec![door, window]).unwrap();
        let patch = polygon_patch(&wall).unwrap();
        assert!((patch.area() - (18.0 - 2.0 - 1.0)).abs() < 1e-9, "{}", patch.area());
        assert_eq!(patch.polygon().holes().len(), 1, "the window stays a hole");
        assert_eq!(patch.polygon().outer().points().len(), 8, "the door is a notch of the outline");
        // A hole touching a side edge cannot be notched.
        let side = vec![
            Point2::new(0.0, 1.0),
            Point2::new(1.0, 1.0),
            Point2::new(1.0, 2.0),
            Point2::new(0.0, 2.0),
        ];
        let outline = vec![
            Point2::new(0.0, 0.0),
            Point2::new(6.0, 0.0),
            Point2::new(6.0, 3.0),
            Point2::new(0.0, 3.0),
        ];
        if let Ok(bad) = PlanarPolygon::new(Isometry3::identity(), outline, vec![side]) {
            assert!(polygon_patch(&bad).is_err());
        }
    }

    #[test]
    fn a_cylinder_has_a_side_and_two_outward_caps() {
        let cyl = Cylinder::upright(Point3::new(-3.0, 0.0, 0.0), 0.3, 1.0).unwrap();
        let t = Tessellation { curved_edge: 0.2, min_segments: 8 };
        let n = t.segments(0.3);
        assert_eq!(n, 10, "⌈2π·0.3 / 0.2⌉");
        let (side, [bottom, top]) = cylinder_surfaces(&cyl, &t).unwrap();
        let rings = 5; // ⌈1.0 / 0.2⌉ bands along the axis
        assert_eq!(side.num_triangles(), 2 * n * rings);
        let (z0, z1) = (
            cyl.world_from_cylinder() * Point3::new(0.0, 0.0, -cyl.half_height()),
            cyl.world_from_cylinder() * Point3::new(0.0, 0.0, cyl.half_height()),
        );
        assert!(bottom.normal().dot(&cyl.axis()) < -0.999 && top.normal().dot(&cyl.axis()) > 0.999);
        assert!(
            (bottom.to_world(&bottom.polygon().outer().points()[0]) - z0).dot(&cyl.axis()).abs()
                < 1e-9
        );
        assert!(
            (top.to_world(&top.polygon().outer().points()[0]) - z1).dot(&cyl.axis()).abs() < 1e-9
        );
        // Inscribed regular n-gon caps: (n/2)·r²·sin(2π/n).
        let cap = 0.5 * n as Real * 0.09 * (std::f64::consts::TAU / n as Real).sin();
        assert!((bottom.area() - cap).abs() < 1e-9 && (top.area() - cap).abs() < 1e-9);
        let side_area = n as Real * 2.0 * 0.3 * (std::f64::consts::PI / n as Real).sin() * 1.0;
        assert!((side.area() - side_area).abs() < 1e-9, "{} vs {side_area}", side.area());
    }

    #[test]
    fn a_sphere_mesh_is_closed_and_inscribed() {
        let s = Sphere::new(Point3::new(4.0, 0.0, 1.0), 0.5).unwrap();
        let t = Tessellation { curved_edge: 0.2, min_segments: 8 };
        let mesh = sphere_mesh(&s, &t).unwrap();
        // Closed: every undirected edge is shared by exactly two triangles, once each way.
        let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
        for tri in mesh.triangles() {
            for e in 0..3 {
                let (a, b) = (tri[e], tri[(e + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_default() += if a < b { 1 } else { -1 };
            }
        }
        assert!(edges.values().all(|&v| v == 0), "every edge is used once in each direction");
        let total: usize = edges.len();
        assert_eq!(3 * mesh.num_triangles(), 2 * total);
        for v in mesh.vertices() {
            assert!(((v - s.center()).norm() - 0.5).abs() < 1e-12, "vertices on the sphere");
        }
        let exact = 4.0 * std::f64::consts::PI * 0.25;
        assert!(mesh.area() < exact && mesh.area() > 0.9 * exact, "{}", mesh.area());
    }

    #[test]
    fn the_labs_patches_are_all_valid() {
        let lab = crate::lab(0).unwrap();
        let patches = scene_patches(&lab, &Tessellation::default()).unwrap();
        let planar = patches.iter().filter(|p| p.as_planar().is_some()).count();
        let curved = patches.len() - planar;
        assert!(planar > 40 && curved >= 2, "{planar} planar, {curved} curved");
        assert!(patches.iter().all(|p| p.area().is_finite() && p.area() > 0.0));
        // Polygons keep their area (doors become notches, not lost).
        for primitive in lab.primitives() {
            if let Shape::Polygon(poly) = &primitive.shape {
                let patch = polygon_patch(poly).unwrap();
                assert!((patch.area() - poly.area()).abs() < 1e-9, "{}", primitive.name);
            }
        }
    }

    #[test]
    fn bad_tessellations_are_refused() {
        let lab = crate::lab(0).unwrap();
        for t in [
            Tessellation { curved_edge: 0.0, min_segments: 8 },
            Tessellation { curved_edge: Real::NAN, min_segments: 8 },
            Tessellation { curved_edge: 0.1, min_segments: 2 },
        ] {
            assert!(matches!(scene_patches(&lab, &t), Err(PatchesError::BadTessellation { .. })));
        }
    }
}
