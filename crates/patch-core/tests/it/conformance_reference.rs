//! The conformance suite run on the reference map itself (self-consistency: contact points,
//! normals, first contacts, the unspecific and specific answers, clearance against spheres)
//! and on the adaptors that forward to it. The reference's distances are checked against
//! sampling oracles in `oracle.rs`.
#![cfg(feature = "conformance")]

use patch_core::conformance::{SceneKind, SuiteConfig};
use patch_core::{BruteForceMap, Counted, Tolerance};

fn config() -> SuiteConfig {
    SuiteConfig::from_env(Tolerance::EXACT, SceneKind::Mixed)
}

mod brute_force {
    use super::*;
    patch_core::conformance_tests!(
        BruteForceMap,
        config();
        map, map_mut, proximity, line_unspecific, line_specific, capsule_unspecific,
        capsule_specific, clearance_vs_capsule,
    );
}

mod counted {
    use super::*;
    patch_core::conformance_tests!(
        Counted<BruteForceMap>,
        config();
        map, map_mut, proximity, capsule_specific,
    );
}

mod by_reference {
    //! The blanket implementations for `&M`, through a newtype that owns a leaked map.
    use super::*;
    use patch_core::{
        CapsuleStep, FromPatches, MapError, Patch, PatchMap, Point3, Proximity, ProximityQuery,
        Real, SpecificStepIntersector, StepHit, UnspecificStepIntersector,
    };

    /// Implements only the required methods, forwarding to `&BruteForceMap`, so the default
    /// methods (`patch`, `len`, `is_empty`, `clearance`) are the ones under test.
    struct Borrowed(&'static BruteForceMap);

    impl FromPatches for Borrowed {
        type Error = MapError;
        fn from_patches(patches: impl IntoIterator<Item = Patch>) -> Result<Self, MapError> {
            Ok(Borrowed(Box::leak(Box::new(BruteForceMap::from_patches(patches)?))))
        }
    }
    impl PatchMap for Borrowed {
        fn patches(&self) -> &[Patch] {
            PatchMap::patches(&self.0)
        }
        fn bounds(&self) -> patch_core::Aabb {
            PatchMap::bounds(&self.0)
        }
        fn tolerance(&self) -> Tolerance {
            PatchMap::tolerance(&self.0)
        }
    }
    impl ProximityQuery for Borrowed {
        fn closest_patch(&self, point: &Point3, max_dist: Real) -> Option<Proximity> {
            ProximityQuery::closest_patch(&self.0, point, max_dist)
        }
    }
    impl UnspecificStepIntersector for Borrowed {
        fn is_step_free(&self, step: &CapsuleStep) -> bool {
            patch_core::is_step_free_via_first_hit(&self.0, step)
        }
    }
    impl SpecificStepIntersector for Borrowed {
        fn first_hit(&self, step: &CapsuleStep) -> Option<StepHit> {
            SpecificStepIntersector::first_hit(&self.0, step)
        }
    }

    patch_core::conformance_tests!(Borrowed, config(); map, proximity, capsule_specific, clearance_vs_capsule);
}
