//! The lab scene's exact geometry as patches (thesis §6.1's Lab, `scene-sim`'s `lab`): every
//! planar surface as a planar patch (polygons with their holes, the six faces of each box,
//! cylinder caps as regular polygons) and every curved surface (sphere, cylinder side) as one
//! tessellated trimesh patch — the `hybrid` map of the thesis's Table 6.1 as a perfect patch
//! extraction would give it. The same construction as `patchnav`'s lab map builder
//! (`--source scene`), kept here so this benchmark depends on library crates only.

use anyhow::{Context, Result};
use patch_core::{
    CapsuleStep, Isometry3, Patch, PlanarPatch, Point2, Point3, Polygon, Real, TrimeshPatch,
    UnspecificStepIntersector as _, Vector3,
};
use patch_map::AnyMap;
use scene_sim::{Cuboid, Cylinder, PlanarPolygon, Scene, Shape};

/// Longest edge of the tessellation of curved surfaces, metres (the lab experiment's 0.1 m: the
/// barrel gets 19 segments, table legs 8).
pub(crate) const CURVED_EDGE: Real = 0.1;
/// Fewest segments around a sphere or cylinder.
const MIN_SEGMENTS: usize = 8;

/// Segments around a circle of radius `r`.
fn segments(r: Real) -> usize {
    let n = (std::f64::consts::TAU * r / CURVED_EDGE).ceil();
    (n.min(100_000.0) as usize).max(MIN_SEGMENTS)
}

/// Every surface of `scene` as a patch (planar and tessellated curved).
pub(crate) fn scene_patches(scene: &Scene) -> Result<Vec<Patch>> {
    let mut out = Vec::new();
    for primitive in scene.primitives() {
        let name = &primitive.name;
        match &primitive.shape {
            Shape::Polygon(p) => {
                out.push(Patch::from(
                    polygon_patch(p).with_context(|| format!("scene polygon `{name}`"))?,
                ));
            }
            Shape::Cuboid(c) => {
                for face in cuboid_faces(c) {
                    out.push(Patch::from(face.with_context(|| format!("a face of box `{name}`"))?));
                }
            }
            Shape::Sphere(s) => out.push(Patch::from(
                sphere_mesh(s.center(), s.radius()).with_context(|| format!("sphere `{name}`"))?,
            )),
            Shape::Cylinder(c) => {
                let (side, caps) =
                    cylinder_surfaces(c).with_context(|| format!("cylinder `{name}`"))?;
                out.push(Patch::from(side));
                out.extend(caps.into_iter().map(Patch::from));
            }
        }
    }
    Ok(out)
}

/// The start of the lab's RRTs (thesis §6.1: "room corners"): the first point free on every map
/// on a small spiral from 0.6 m inside the south-west corner, at 1.0 m height.
pub(crate) fn corner_start(maps: &[&AnyMap], radius: Real) -> Result<Point3> {
    let free = |p: &Point3| {
        maps.iter().all(|m| CapsuleStep::sphere(*p, radius).is_ok_and(|s| m.is_step_free(&s)))
    };
    (0..8)
        .flat_map(|ring| {
            let d = 0.6 + 0.2 * Real::from(ring);
            (0..=ring).flat_map(move |k| {
                let e = 0.6 + 0.2 * Real::from(k);
                [(d, e), (e, d)]
            })
        })
        .map(|(dx, dy)| Point3::new(dx, dy, 1.0))
        .find(|p| free(p))
        .context("no free start near the lab's south-west corner")
}

/// The patch of a scene polygon. A hole touching the outline (a door reaching the floor) is
/// invalid for a patch polygon; for an axis-aligned rectangle with rectangular holes, such
/// holes on the bottom or top edge become notches of the outline.
fn polygon_patch(p: &PlanarPolygon) -> Result<PlanarPatch> {
    let holes: Vec<Vec<Point2>> = p.holes().map(<[Point2]>::to_vec).collect();
    let polygon = match Polygon::new(p.outline().to_vec(), holes.clone()) {
        Ok(polygon) => polygon,
        Err(e) => {
            let Some((outline, holes)) = notched(p.outline(), &holes) else {
                return Err(e.into());
            };
            Polygon::new(outline, holes)?
        }
    };
    Ok(PlanarPatch::new(polygon, *p.world_from_patch())?)
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
fn world_patch(mut ring: Vec<Point3>, normal: &Vector3) -> Result<PlanarPatch> {
    let newell = (0..ring.len()).fold(Vector3::zeros(), |n, i| {
        let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
        n + a.coords.cross(&b.coords)
    });
    if newell.dot(normal) < 0.0 {
        ring.reverse();
    }
    Ok(PlanarPatch::from_world_polygon(&ring, &[], 1e-9)?)
}

/// The six faces of a box as planar patches, normals outwards.
fn cuboid_faces(c: &Cuboid) -> impl Iterator<Item = Result<PlanarPatch>> + '_ {
    let axes = c.world_from_box().rotation.to_rotation_matrix().into_inner();
    let h = *c.half_extents();
    (0..6u32).map(move |part| {
        let a = (part / 2) as usize;
        let (i, j) = ((a + 1) % 3, (a + 2) % 3);
        let u: Vector3 = axes.column(i) * h[i];
        let v: Vector3 = axes.column(j) * h[j];
        let centre = c.face_center(part);
        let ring = vec![centre - u - v, centre + u - v, centre + u + v, centre - u + v];
        world_patch(ring, &c.face_normal(part))
    })
}

/// The side of a cylinder as a mesh and its two caps as regular polygons.
fn cylinder_surfaces(c: &Cylinder) -> Result<(TrimeshPatch, [PlanarPatch; 2])> {
    let m: &Isometry3 = c.world_from_cylinder();
    let (r, h) = (c.radius(), c.half_height());
    let n = segments(r);
    let rings = ((2.0 * h / CURVED_EDGE).ceil() as usize).max(1);
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

/// A sphere as a latitude–longitude mesh.
fn sphere_mesh(centre: &Point3, r: Real) -> Result<TrimeshPatch> {
    let n = segments(r);
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
    Ok(TrimeshPatch::new(vertices, triangles)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lab_surfaces_cover_the_scene_and_the_door_is_a_notch() {
        let lab = scene_sim::lab(0).unwrap();
        let patches = scene_patches(&lab).unwrap();
        let planar = patches.iter().filter(|p| p.as_planar().is_some()).count();
        let curved = patches.len() - planar;
        assert!(planar > 40 && curved >= 2, "{planar} planar, {curved} curved");
        // The south wall (12 × 4 m with a 1.2 × 2.1 m door reaching the floor) keeps its area.
        let south = lab.primitives().iter().find(|p| p.name == "wall-south").unwrap();
        let Shape::Polygon(poly) = &south.shape else { panic!("the south wall is a polygon") };
        let patch = polygon_patch(poly).unwrap();
        assert!((patch.area() - (12.0 * 4.0 - 1.2 * 2.1)).abs() < 1e-9);
    }
}
