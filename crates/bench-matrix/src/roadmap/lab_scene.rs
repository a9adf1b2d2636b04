//! The lab scene's exact geometry as patches (thesis §6.1's Lab, `scene-sim`'s `lab`): every
//! planar surface as a planar patch (polygons with their holes, the six faces of each box,
//! cylinder caps as regular polygons) and every curved surface (sphere, cylinder side) as one
//! tessellated trimesh patch — the `hybrid` map of the thesis's Table 6.1 as a perfect patch
//! extraction would give it, built by [`scene_sim::patches`] (as `patchnav`'s lab map builder
//! does for `--source scene`); and the corner start shared with the maps built from scans
//! ([`super::lab_maps`]).

use anyhow::{Context, Result};
use patch_core::{CapsuleStep, Patch, Point3, Real, UnspecificStepIntersector as _};
use patch_map::AnyMap;
use pointcloud::Aabb;
use scene_sim::Scene;
use scene_sim::patches::Tessellation;

/// Every surface of `scene` as a patch (planar and tessellated curved), with the lab
/// experiment's tessellation ([`Tessellation::default`]: 0.1 m curved edges, the barrel gets 19
/// segments, table legs 8).
pub(crate) fn scene_patches(scene: &Scene) -> Result<Vec<Patch>> {
    scene_sim::patches::scene_patches(scene, &Tessellation::default())
        .with_context(|| format!("the patches of scene `{}`", scene.name()))
}

/// The start of the lab's RRTs (thesis §6.1: "room corners"): the first point free on every map
/// (and inside `within`, when given) on a small spiral from 0.6 m inside the south-west corner,
/// at 1.0 m height — the first of `patchnav experiment lab-timing`'s four corner starts, by the
/// same rule.
pub(crate) fn corner_start(
    maps: &[&AnyMap],
    radius: Real,
    within: Option<&Aabb>,
) -> Result<Point3> {
    let free = |p: &Point3| {
        within.is_none_or(|b| b.contains(p))
            && maps
                .iter()
                .all(|m| CapsuleStep::sphere(*p, radius).is_ok_and(|s| m.is_step_free(&s)))
    };
    near_corner(Point3::new(0.0, 0.0, 1.0), [1.0, 1.0], free)
        .context("no free start near the lab's south-west corner")
}

/// The first point `free` accepts on a small spiral from 0.6 m inside a room corner at
/// `corner` (its height kept), stepping 0.2 m into the room along `inwards` (±1 per axis):
/// eight rings: the rule of every lab start here, and the one `patchnav experiment lab-timing`
/// follows.
pub(crate) fn near_corner(
    corner: Point3,
    inwards: [Real; 2],
    free: impl Fn(&Point3) -> bool,
) -> Option<Point3> {
    (0..8)
        .flat_map(|ring| {
            let d = 0.6 + 0.2 * Real::from(ring);
            (0..=ring).flat_map(move |k| {
                let e = 0.6 + 0.2 * Real::from(k);
                [(d, e), (e, d)]
            })
        })
        .map(|(dx, dy)| {
            Point3::new(corner.x + inwards[0] * dx, corner.y + inwards[1] * dy, corner.z)
        })
        .find(|p| free(p))
}

#[cfg(test)]
mod tests {
    use super::*;
    use scene_sim::Shape;

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
        let patch = scene_sim::patches::polygon_patch(poly).unwrap();
        assert!((patch.area() - (12.0 * 4.0 - 1.2 * 2.1)).abs() < 1e-9);
        assert!(
            patches.iter().any(|p| p.as_planar() == Some(&patch)),
            "the wall is among the patches"
        );
    }
}
