//! The conformance suite of `patch-core` (feature `conformance`) for every patch-map backend of
//! this crate, one module per backend, each listing every capability the backend implements
//! with the tolerance it declares. Cases and seed come from `PATCHNAV_CONFORMANCE_CASES` and
//! `PATCHNAV_CONFORMANCE_SEED`.
//!
//! The point-cloud map is not a patch map and cannot run the suite; its Algorithm 10 is checked
//! against a brute-force oracle over points in `src/point_cloud.rs`, and here against the
//! reference map on densely sampled patches (`point_cloud_map`).

use patch_core::Tolerance;
use patch_core::conformance::{SceneKind, SuiteConfig};

/// The native polygon map is exact: it runs the reference's own kernels, and its per-patch box
/// test only rejects patches that provably cannot touch the query.
mod polygon_map {
    use super::*;
    patch_core::conformance_tests!(
        patch_map::PolygonMap,
        SuiteConfig::from_env(Tolerance::EXACT, SceneKind::Mixed);
        map, map_mut, proximity, line_unspecific, line_specific,
        capsule_unspecific, capsule_specific, clearance_vs_capsule,
    );
}

/// The 6D box map is exact: its broad phase returns a superset of the patches the kernels can
/// report (query boxes carry a rounding slack), and the narrow phase is the reference's.
mod bbox6d_map {
    use super::*;
    patch_core::conformance_tests!(
        patch_map::BBox6dMap,
        SuiteConfig::from_env(Tolerance::EXACT, SceneKind::Mixed);
        map, map_mut, proximity, line_unspecific, line_specific,
        capsule_unspecific, capsule_specific, clearance_vs_capsule,
    );
}

/// Stronger than the tolerance statements: the native backends give *the same* answers as the
/// reference map, bit for bit, including which patch wins a tie.
mod identical_answers {
    use patch_core::conformance::SceneKind;
    use patch_core::conformance::strategies::{
        scene_with_capsule_steps, scene_with_line_steps, scene_with_points,
    };
    use patch_core::{
        BruteForceMap, FromPatches, PatchMapMut, ProximityQuery, Real, SpecificStepIntersector,
        UnspecificStepIntersector,
    };
    use patch_map::{BBox6dMap, PolygonMap};
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 128, failure_persistence: None, ..ProptestConfig::default() })]

        #[test]
        fn capsule_and_line_steps((patches, steps) in scene_with_capsule_steps(SceneKind::Mixed, 0..=8, 1..=16)) {
            let reference = BruteForceMap::from_patches(patches.clone()).unwrap();
            let polygon = PolygonMap::from_patches(patches.clone()).unwrap();
            // The 6D map grown one patch at a time (the forest's incremental path).
            let mut bbox = BBox6dMap::default();
            for p in &patches {
                bbox.add_patch(p.clone()).unwrap();
            }
            for s in &steps {
                let expected = reference.first_hit(s);
                prop_assert_eq!(polygon.first_hit(s), expected);
                prop_assert_eq!(bbox.first_hit(s), expected);
                prop_assert_eq!(polygon.is_step_free(s), expected.is_none());
                prop_assert_eq!(bbox.is_step_free(s), expected.is_none());
                let line = s.line();
                let expected = reference.first_hit(&line);
                prop_assert_eq!(polygon.first_hit(&line), expected);
                prop_assert_eq!(bbox.first_hit(&line), expected);
                prop_assert_eq!(polygon.is_step_free(&line), expected.is_none());
                prop_assert_eq!(bbox.is_step_free(&line), expected.is_none());
            }
        }

        #[test]
        fn probe_lines((patches, steps) in scene_with_line_steps(SceneKind::Mixed, 0..=8, 1..=16)) {
            let reference = BruteForceMap::from_patches(patches.clone()).unwrap();
            let polygon = PolygonMap::from_patches(patches.clone()).unwrap();
            let bbox = BBox6dMap::from_patches(patches).unwrap();
            for s in &steps {
                let expected = reference.first_hit(s);
                prop_assert_eq!(polygon.first_hit(s), expected);
                prop_assert_eq!(bbox.first_hit(s), expected);
                prop_assert_eq!(bbox.is_step_free(s), expected.is_none());
            }
        }

        #[test]
        fn closest_patches((patches, points) in scene_with_points(SceneKind::Mixed, 0..=8, 1..=16)) {
            let reference = BruteForceMap::from_patches(patches.clone()).unwrap();
            let polygon = PolygonMap::from_patches(patches.clone()).unwrap();
            let bbox = BBox6dMap::from_patches(patches).unwrap();
            for p in &points {
                for max_dist in [Real::INFINITY, 1e12, 2.0, 0.5, 0.0] {
                    let expected = reference.closest_patch(p, max_dist);
                    prop_assert_eq!(polygon.closest_patch(p, max_dist), expected);
                    prop_assert_eq!(bbox.closest_patch(p, max_dist), expected);
                }
            }
        }
    }
}

/// The point-cloud map on points sampled densely on random patches.
///
/// # Density assumption
/// `patch_map::sample_patch_points` puts every surface point within `h` of a sample (its
/// module docs prove it). Hence a step whose exact
/// distance to the patches is `d ≤ r − h` has a sample within `r` of its segment: Algorithm 10
/// must report it colliding. With `h = 0.1 m` and radii from 0.25 m the spacing is below `r/2`,
/// the regime the thesis assumes (L5724). In the other direction every sample lies on a patch,
/// so a step reported colliding comes within `r` of a patch (up to the grazing tolerance of
/// [`PointCloudMap::MIN_ADVANCE`]).
mod point_cloud_map {
    use std::sync::Arc;

    use patch_core::conformance::SceneKind;
    use patch_core::conformance::strategies::{capsule_step_with, probe_step, scene, step_bounds};
    use patch_core::{
        BruteForceMap, CapsuleStep, FromPatches, Patch, Point3, Real, Step,
        UnspecificStepIntersector,
    };
    use patch_map::{PointCloudMap, sample_patch_points};
    use proptest::prelude::*;

    /// The sample spacing, metres.
    const SPACING: Real = 0.1;

    /// Samples every patch with spacing at most [`SPACING`] (the library's sampler).
    fn sample(patches: &[Patch]) -> Vec<Point3> {
        sample_patch_points(patches, SPACING).expect("valid patches triangulate")
    }

    fn scene_with_steps() -> impl Strategy<Value = (Vec<Patch>, Vec<CapsuleStep>)> {
        let radius = || (0.25..1.0).boxed();
        scene(SceneKind::Mixed, 1..=4).prop_flat_map(move |patches| {
            let shared: Arc<[Patch]> = patches.clone().into();
            let step = prop_oneof![
                1 => capsule_step_with(step_bounds(), radius()),
                2 => probe_step(shared, radius()),
            ];
            (Just(patches), prop::collection::vec(step, 1..=12))
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 48, failure_persistence: None, ..ProptestConfig::default() })]

        #[test]
        fn never_frees_a_step_through_a_densely_sampled_surface((patches, steps) in scene_with_steps()) {
            let points = sample(&patches);
            let cloud = PointCloudMap::from_points(&points).unwrap();
            let reference = BruteForceMap::from_patches(patches).unwrap();
            for s in &steps {
                prop_assert!(SPACING < s.radius() / 2.0);
                let d = reference.step_distance(s).map_or(Real::INFINITY, |d| d.distance);
                if cloud.is_step_free(s) {
                    prop_assert!(
                        d > s.radius() - SPACING - 1e-9,
                        "free, but the surface is {} from the segment (radius {}, slack {}): {:?}",
                        d, s.radius(), SPACING, s
                    );
                } else {
                    prop_assert!(
                        d <= s.radius() + 1e-6,
                        "colliding, but the surface is {} from the segment (radius {}): {:?}",
                        d, s.radius(), s
                    );
                }
            }
        }
    }
}

/// The parry trimesh map: one triangle mesh with its BVH, parry's projection, ray–triangle
/// casts and GJK capsule tests. Its declared band (`TrimeshMap::TOLERANCE`) is numeric: GJK
/// decides grazing contacts only to a relative precision of about 5e-8.
mod trimesh_map {
    use super::*;
    patch_core::conformance_tests!(
        patch_map::TrimeshMap,
        SuiteConfig::from_env(patch_map::TrimeshMap::TOLERANCE, SceneKind::Mixed);
        map, map_mut, proximity, line_unspecific, line_specific,
        capsule_unspecific, capsule_specific, clearance_vs_capsule,
    );
}

/// The rapier map: one collider per patch in rapier's broad phase, the trimesh map's per-mesh
/// narrow phase in each collider, hence its tolerance.
#[cfg(feature = "rapier")]
mod rapier_map {
    use super::*;
    patch_core::conformance_tests!(
        patch_map::RapierMap,
        SuiteConfig::from_env(patch_map::RapierMap::TOLERANCE, SceneKind::Mixed);
        map, map_mut, proximity, line_unspecific, line_specific,
        capsule_unspecific, capsule_specific, clearance_vs_capsule,
    );
}
