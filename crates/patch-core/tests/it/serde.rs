//! Serialisation round trips of random patches, maps and steps.

use patch_core::conformance::SceneKind;
use patch_core::conformance::strategies;
use patch_core::{BruteForceMap, CapsuleStep, FromPatches, Patch, PatchMap};
use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn patches_round_trip_through_json(patches in strategies::scene(SceneKind::Mixed, 0..=4)) {
        let json = serde_json::to_string(&patches).unwrap();
        let back: Vec<Patch> = serde_json::from_str(&json).unwrap();
        prop_assert_eq!(&back, &patches);
        let map = BruteForceMap::from_patches(patches).unwrap();
        let json = serde_json::to_string(&map).unwrap();
        let back: BruteForceMap = serde_json::from_str(&json).unwrap();
        prop_assert_eq!(back.bounds(), map.bounds());
        prop_assert_eq!(back, map);
    }

    #[test]
    fn steps_round_trip_through_json(step in strategies::capsule_step(strategies::step_bounds())) {
        let json = serde_json::to_string(&step).unwrap();
        prop_assert_eq!(serde_json::from_str::<CapsuleStep>(&json).unwrap(), step);
    }
}
