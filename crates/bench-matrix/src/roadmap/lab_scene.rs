//! The lab scene's exact geometry as patches (thesis §6.1's Lab, `scene-sim`'s `lab`): every
//! planar surface as a planar patch (polygons with their holes, the six faces of each box,
//! cylinder caps as regular polygons) and every curved surface (sphere, cylinder side) as one
//! tessellated trimesh patch — the `hybrid` map of the thesis's Table 6.1 as a perfect patch
//! extraction would give it, built by [`scene_sim::patches`] (as `patchnav`'s lab map builder
//! does for `--source scene`).

use anyhow::{Context, Result};
use patch_core::Patch;
use scene_sim::Scene;
use scene_sim::patches::Tessellation;

/// Every surface of `scene` as a patch (planar and tessellated curved), with the lab
/// experiment's tessellation ([`Tessellation::default`]: 0.1 m curved edges, the barrel gets 19
/// segments, table legs 8).
pub(crate) fn scene_patches(scene: &Scene) -> Result<Vec<Patch>> {
    scene_sim::patches::scene_patches(scene, &Tessellation::default())
        .with_context(|| format!("the patches of scene `{}`", scene.name()))
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
