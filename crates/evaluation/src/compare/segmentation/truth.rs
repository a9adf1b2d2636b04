//! Ground truth of a simulated scene for the segmentation comparison: the scene's exact planar
//! surfaces as true planes, which of them a labelled frame shows, and the quality of a run's
//! plane polygons against them.
//!
//! The rules are those `cargo xtask peers planes` applies to the floor plan's mesh
//! (`crate::peers::Truth`), with exact geometry in place of a triangle mesh:
//! * **true planes**: the scene's planar surfaces (polygons, box faces, cylinder caps) grouped by
//!   plane (normals within 1°, offsets within 1 cm); curved surfaces are no true plane.
//! * **visible** in a frame: at least [`VISIBLE_POINTS`] measured pixels whose beam hit one of
//!   the plane's surfaces (the frame's `label` property, exact where the mesh rule counts points
//!   within 2 cm).
//! * **found**: a visible true plane that some extracted plane matches: normals within
//!   [`MATCH_ANGLE_DEG`](crate::peers::MATCH_ANGLE_DEG) (either orientation) and the extracted
//!   polygon's vertices on average within [`MATCH_OFFSET`](crate::peers::MATCH_OFFSET) of the
//!   true plane. **Off truth**: an extracted plane matching no true plane at all (visible or
//!   not).
//! * **vertices on surface**: the share of polygon vertices within [`ON_SURFACE`] of any surface
//!   of the scene, curved ones included.

use pointcloud::{Point3, Vector3};
use scene_sim::{Point2, Scene, Shape};
use serde_json::Value;

use crate::peers::{MatchTally, Plane};
pub(crate) use crate::peers::{ON_SURFACE, VISIBLE_POINTS};

/// Surfaces lie on one true plane within these (degrees, metres).
const SAME_PLANE_DEG: f64 = 1.0;
const SAME_PLANE_M: f64 = 0.01;

/// The true planes of a scene and the exact surfaces to measure vertices against.
pub(crate) struct SceneTruth {
    scene: Scene,
    planes: Vec<Plane>,
    /// True plane of each surface (index = surface id), `None` for curved surfaces.
    plane_of_surface: Vec<Option<usize>>,
}

impl SceneTruth {
    /// Groups the scene's planar surfaces into true planes.
    pub(crate) fn new(scene: Scene) -> SceneTruth {
        let mut planes: Vec<Plane> = Vec::new();
        let plane_of_surface = scene
            .surfaces()
            .iter()
            .map(|s| {
                let plane = Plane::new(s.plane?.normal.into_inner(), s.plane?.offset)?;
                let i = planes
                    .iter()
                    .position(|p| p.same(&plane, SAME_PLANE_DEG, SAME_PLANE_M))
                    .unwrap_or_else(|| {
                        planes.push(plane);
                        planes.len() - 1
                    });
                Some(i)
            })
            .collect();
        SceneTruth { scene, planes, plane_of_surface }
    }

    /// How many true planes the scene has.
    pub(crate) fn num_planes(&self) -> usize {
        self.planes.len()
    }

    /// The true planes shown by at least [`VISIBLE_POINTS`] of the measured pixels, given the
    /// surface id each measured pixel's beam hit (ids the scene does not know are ignored).
    pub(crate) fn visible(&self, labels: &[u32]) -> Vec<usize> {
        let mut counts = vec![0usize; self.planes.len()];
        for &l in labels {
            if let Some(Some(i)) = self.plane_of_surface.get(l as usize) {
                counts[*i] += 1;
            }
        }
        (0..counts.len()).filter(|&i| counts[i] >= VISIBLE_POINTS).collect()
    }

    /// Whether `p` lies within [`ON_SURFACE`] of any surface of the scene.
    pub(crate) fn on_surface(&self, p: &Point3) -> bool {
        if !p.coords.iter().all(|c| c.is_finite()) {
            return false;
        }
        self.scene.primitives().iter().any(|prim| {
            let b = prim.shape.aabb();
            let near = (0..3).all(|k| {
                p[k] >= b.min[k] - ON_SURFACE - 1e-9 && p[k] <= b.max[k] + ON_SURFACE + 1e-9
            });
            near && surface_distance(&prim.shape, p) <= ON_SURFACE
        })
    }

    /// The quality of a run's plane polygons with `visible` true planes, as the JSON object
    /// `peers::Truth::quality` gives (the same keys).
    pub(crate) fn quality(&self, visible: &[usize], polygons: &Value) -> Value {
        let tally = MatchTally::of_polygons(polygons, &self.planes, |q| self.on_surface(q));
        tally.report(visible, |i| {
            let t = &self.planes[i];
            format!(
                "n ({:.2} {:.2} {:.2}) · x = {:.2}",
                t.normal.x, t.normal.y, t.normal.z, t.offset
            )
        })
    }
}

/// The distance from `p` to the surface of `shape` (a polygon's area, a solid's boundary).
pub(crate) fn surface_distance(shape: &Shape, p: &Point3) -> f64 {
    match shape {
        Shape::Polygon(s) => {
            let l = s.world_from_patch().inverse_transform_point(p);
            if s.contains_local(l.x, l.y) {
                return l.z.abs();
            }
            let q = Point2::new(l.x, l.y);
            let edge = std::iter::once(s.outline())
                .chain(s.holes())
                .flat_map(|ring| {
                    (0..ring.len()).map(move |i| (ring[i], ring[(i + 1) % ring.len()]))
                })
                .map(|(a, b)| segment_distance(&q, &a, &b))
                .fold(f64::INFINITY, f64::min);
            edge.hypot(l.z)
        }
        Shape::Cuboid(c) => {
            let l = c.world_from_box().inverse_transform_point(p);
            let h = c.half_extents();
            let d = Vector3::new(l.x.abs() - h.x, l.y.abs() - h.y, l.z.abs() - h.z);
            box_distance(&d.iter().copied().collect::<Vec<_>>())
        }
        Shape::Sphere(s) => ((p - s.center()).norm() - s.radius()).abs(),
        Shape::Cylinder(c) => {
            let l = c.world_from_cylinder().inverse_transform_point(p);
            box_distance(&[l.x.hypot(l.y) - c.radius(), l.z.abs() - c.half_height()])
        }
    }
}

/// The distance to the boundary of a box from a point whose per-axis excess over the half
/// extents is `d` (`|x| − h`; all negative inside).
fn box_distance(d: &[f64]) -> f64 {
    let outside = d.iter().map(|x| x.max(0.0).powi(2)).sum::<f64>().sqrt();
    if outside > 0.0 { outside } else { -d.iter().copied().fold(f64::NEG_INFINITY, f64::max) }
}

/// The distance from `q` to the segment `a`–`b`.
fn segment_distance(q: &Point2, a: &Point2, b: &Point2) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 { ((q - a).dot(&ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (q - (a + ab * t)).norm()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::peers::parse_planes;
    use pointcloud::Isometry3;
    use scene_sim::{Cuboid, Cylinder, Material, PlanarPolygon, SceneBuilder, Sphere};
    use serde_json::json;

    /// A floor (10 × 10 m at z = 0), a 1 m box standing on it at (5, 5), a sphere and a
    /// cylinder.
    fn scene() -> Scene {
        let mut b = SceneBuilder::new("test");
        let square = vec![
            Point2::new(0.0, 0.0),
            Point2::new(10.0, 0.0),
            Point2::new(10.0, 10.0),
            Point2::new(0.0, 10.0),
        ];
        let floor = PlanarPolygon::new(Isometry3::identity(), square, Vec::new()).unwrap();
        b.add("floor", floor, Material::CONCRETE).unwrap();
        let cube =
            Cuboid::axis_aligned(Point3::new(4.5, 4.5, 0.0), Point3::new(5.5, 5.5, 1.0)).unwrap();
        b.add("box", cube, Material::WOOD).unwrap();
        b.add("ball", Sphere::new(Point3::new(2.0, 2.0, 1.0), 0.5).unwrap(), Material::WOOD)
            .unwrap();
        let cyl = Cylinder::upright(Point3::new(8.0, 8.0, 0.0), 0.3, 2.0).unwrap();
        b.add("barrel", cyl, Material::WOOD).unwrap();
        b.build().unwrap()
    }

    fn plane_json(normal: [f64; 3], d: f64, ring: &[[f64; 3]]) -> Value {
        json!({"normal": normal, "d": d, "polygons": [ring]})
    }

    #[test]
    fn planar_surfaces_group_into_planes() {
        let t = SceneTruth::new(scene());
        // floor and box bottom share z = 0; box: 5 other faces; cylinder: two caps, the bottom
        // on the floor's plane: floor, 5 box faces, cylinder top = 7.
        assert_eq!(t.num_planes(), 7);
        let surfaces = t.scene.surfaces();
        let floor = surfaces.iter().position(|s| s.name == "floor").unwrap();
        let bottom = surfaces.iter().position(|s| s.name == "box/-z").unwrap();
        assert_eq!(t.plane_of_surface[floor], t.plane_of_surface[bottom]);
        let ball = surfaces.iter().position(|s| s.name == "ball").unwrap();
        assert_eq!(t.plane_of_surface[ball], None);
    }

    #[test]
    fn visibility_counts_labelled_pixels_per_plane() {
        let t = SceneTruth::new(scene());
        let id = |name: &str| t.scene.surfaces().iter().position(|s| s.name == name).unwrap();
        let (floor, top, ball) = (id("floor") as u32, id("box/+z") as u32, id("ball") as u32);
        let mut labels = vec![floor; 300];
        labels.extend(vec![id("box/-z") as u32; 200]); // same plane as the floor: 500 in all
        labels.extend(vec![top; VISIBLE_POINTS - 1]);
        labels.extend(vec![ball; 5000]);
        labels.push(u32::MAX); // unknown id
        let visible = t.visible(&labels);
        assert_eq!(visible, vec![t.plane_of_surface[floor as usize].unwrap()]);
    }

    #[test]
    fn surface_distances_are_exact() {
        let s = scene();
        let shape = |name: &str| &s.primitives().iter().find(|p| p.name == name).unwrap().shape;
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        // the floor: above its inside, and beside its edge
        assert!(close(surface_distance(shape("floor"), &Point3::new(3.0, 3.0, 0.25)), 0.25));
        assert!(close(surface_distance(shape("floor"), &Point3::new(13.0, 14.0, 0.0)), 5.0));
        // the box: inside (nearest face 0.1 m away), outside beyond a corner
        assert!(close(surface_distance(shape("box"), &Point3::new(5.0, 5.0, 0.9)), 0.1));
        let d = surface_distance(shape("box"), &Point3::new(6.5, 6.5, 1.0));
        assert!(close(d, 2f64.sqrt()));
        assert!(close(surface_distance(shape("ball"), &Point3::new(2.0, 2.0, 2.0)), 0.5));
        assert!(close(surface_distance(shape("barrel"), &Point3::new(8.0, 8.0, 1.0)), 0.3));
        assert!(close(surface_distance(shape("barrel"), &Point3::new(8.0, 8.0, 2.5)), 0.5));
        assert!(close(surface_distance(shape("barrel"), &Point3::new(9.0, 8.0, 1.0)), 0.7));
    }

    #[test]
    fn quality_counts_found_off_and_on_surface() {
        let t = SceneTruth::new(scene());
        let id = |name: &str| t.scene.surfaces().iter().position(|s| s.name == name).unwrap();
        let floor = t.plane_of_surface[id("floor")].unwrap();
        let top = t.plane_of_surface[id("box/+z")].unwrap();
        let side = t.plane_of_surface[id("box/+x")].unwrap();
        let visible = [floor, top, side];
        let polygons = json!({"planes": [
            // the floor, normal flipped and 1 cm high: found
            plane_json([0.0, 0.0, -1.0], 0.01, &[[1.0, 1.0, 0.01], [3.0, 1.0, 0.01], [3.0, 3.0, 0.01]]),
            // the box top, 1° tilted: found
            plane_json(
                [1f64.to_radians().sin(), 0.0, 1f64.to_radians().cos()],
                -1.0,
                &[[4.6, 4.6, 1.0], [5.4, 4.6, 1.0], [5.0, 5.4, 1.0]],
            ),
            // a plane at z = 0.5: off truth, its three vertices in the air
            plane_json([0.0, 0.0, 1.0], -0.5, &[[1.0, 1.0, 0.5], [2.0, 1.0, 0.5], [1.0, 2.0, 0.5]]),
            // no normal: off truth; its vertex on the ball counts as on surface
            json!({"d": 0.0, "polygons": [[[2.0, 2.0, 1.5]]]}),
        ]});
        let q = t.quality(&visible, &polygons);
        assert_eq!(q["true_planes_visible"], 3);
        assert_eq!(q["true_planes_found"], 2);
        assert_eq!(q["planes_off_truth"], 2);
        assert_eq!(q["polygon_vertices_checked"], 10);
        assert!((q["vertices_on_surface"].as_f64().unwrap() - 7.0 / 10.0).abs() < 1e-12);
        assert_eq!(q["true_planes_missed"].as_array().unwrap().len(), 1);
        // no planes at all: nothing found, no vertices
        let q = t.quality(&visible, &json!({"planes": []}));
        assert_eq!(
            (q["true_planes_found"].as_u64(), q["planes_off_truth"].as_u64()),
            (Some(0), Some(0))
        );
        assert!(q["vertices_on_surface"].is_null());
    }

    #[test]
    fn parse_planes_tolerates_bad_json() {
        assert!(parse_planes(&json!({})).is_empty());
        assert!(parse_planes(&json!({"planes": 3})).is_empty());
        let p = parse_planes(&json!({"planes": [{"normal": [0, 0, 2], "d": -4,
            "polygons": [[[1, 2, 2], [2, 2, 2], "x"]], "holes": [[[1.5, 2.5, 2]]]}]}));
        assert_eq!(p.len(), 1);
        assert_eq!(p[0].plane, Some(Plane { normal: Vector3::z(), offset: 2.0 }));
        assert_eq!(p[0].corners.len(), 3);
        let p = parse_planes(
            &json!({"planes": [{"normal": [0, 0, 0], "d": 1}, {"normal": [1, 0, 0]}]}),
        );
        assert!(p.iter().all(|e| e.plane.is_none() && e.corners.is_empty()));
    }
}
