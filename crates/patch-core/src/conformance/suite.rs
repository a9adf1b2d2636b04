//! Whole suites, one per capability, for any backend `M: FromPatches`: random scenes from
//! [`strategies`](super::strategies), the backend and a [`BruteForceMap`] built from the same
//! patches, every generated query checked with [`checks`](super::checks).
//!
//! Each suite panics with the seed, the case count and the minimal failing scene and queries
//! (proptest shrinks them) on the first disagreement. Scenes hold 0–6 patches; each case runs
//! up to 16 queries.

use std::fmt::Debug;

use proptest::strategy::Strategy;
use proptest::test_runner::{Config, RngSeed, TestCaseError, TestRunner};

use super::SuiteConfig;
use super::checks::{
    check_clearance_vs_capsule, check_map, check_proximity, check_specific, check_unspecific,
};
use super::strategies::{
    scene, scene_with_capsule_steps, scene_with_line_steps, scene_with_points,
};
use crate::{
    BruteForceMap, FromPatches, LineStep, Patch, PatchId, PatchMap, PatchMapMut, ProximityQuery,
    Real, SpecificStepIntersector, UnspecificStepIntersector,
};

const PATCHES: std::ops::RangeInclusive<usize> = 0..=6;
const QUERIES: std::ops::RangeInclusive<usize> = 1..=16;

fn run<T: Debug>(
    config: &SuiteConfig,
    name: &str,
    strategy: impl Strategy<Value = T>,
    test: impl Fn(T) -> Result<(), TestCaseError>,
) {
    let mut runner = TestRunner::new(Config {
        cases: config.cases,
        rng_seed: RngSeed::Fixed(config.seed),
        failure_persistence: None,
        max_shrink_iters: 4096,
        ..Config::default()
    });
    if let Err(e) = runner.run(&strategy, test) {
        panic!(
            "conformance suite `{name}` failed (seed {}, {} cases, {:?}): {e}",
            config.seed, config.cases, config.tolerance
        );
    }
}

fn build<M: FromPatches>(patches: &[Patch]) -> Result<(M, BruteForceMap), TestCaseError> {
    let map = M::from_patches(patches.to_vec())
        .map_err(|e| TestCaseError::fail(format!("from_patches failed: {e}")))?;
    let reference = BruteForceMap::from_patches(patches.to_vec())
        .map_err(|e| TestCaseError::fail(format!("reference failed: {e}")))?;
    Ok((map, reference))
}

/// [`PatchMap`] after [`FromPatches::from_patches`]: the patches in order, the defaults, the
/// bounds ([`check_map`]).
pub fn map<M: FromPatches + PatchMap>(config: &SuiteConfig) {
    run(config, "map", scene(config.scenes, PATCHES), |patches| {
        let (map, _) = build::<M>(&patches)?;
        check_map(&map, &patches, config.tolerance)
    });
}

/// [`PatchMapMut::add_patch`] on a map built empty: ids `0, 1, …`, then the same checks as
/// [`map`].
pub fn map_mut<M: FromPatches + PatchMapMut>(config: &SuiteConfig) {
    run(config, "map_mut", scene(config.scenes, PATCHES), |patches| {
        let (mut map, _) = build::<M>(&[])?;
        for (i, p) in patches.iter().enumerate() {
            let id = map
                .add_patch(p.clone())
                .map_err(|e| TestCaseError::fail(format!("add_patch failed: {e}")))?;
            if id != PatchId(i as u32) {
                return Err(TestCaseError::fail(format!("add_patch returned {id}, expected {i}")));
            }
        }
        check_map(&map, &patches, config.tolerance)
    });
}

/// [`ProximityQuery`] at random points and points near patches, with `max_dist` infinite, 0.5
/// m and 0 ([`check_proximity`]).
pub fn proximity<M: FromPatches + ProximityQuery>(config: &SuiteConfig) {
    run(
        config,
        "proximity",
        scene_with_points(config.scenes, PATCHES, QUERIES),
        |(patches, points)| {
            let (map, reference) = build::<M>(&patches)?;
            for p in &points {
                for max_dist in [Real::INFINITY, 0.5, 0.0] {
                    check_proximity(&map, &reference, p, max_dist, config.tolerance)?;
                }
            }
            Ok(())
        },
    );
}

/// [`UnspecificStepIntersector<LineStep>`] ([`check_unspecific`]).
pub fn line_unspecific<M: FromPatches + UnspecificStepIntersector<LineStep>>(config: &SuiteConfig) {
    run(
        config,
        "line_unspecific",
        scene_with_line_steps(config.scenes, PATCHES, QUERIES),
        |(patches, steps)| {
            let (map, reference) = build::<M>(&patches)?;
            steps.iter().try_for_each(|s| check_unspecific(&map, &reference, s, config.tolerance))
        },
    );
}

/// [`SpecificStepIntersector<LineStep>`] ([`check_specific`], which also checks the
/// unspecific answer against it).
pub fn line_specific<M: FromPatches + SpecificStepIntersector<LineStep>>(config: &SuiteConfig) {
    run(
        config,
        "line_specific",
        scene_with_line_steps(config.scenes, PATCHES, QUERIES),
        |(patches, steps)| {
            let (map, reference) = build::<M>(&patches)?;
            steps.iter().try_for_each(|s| check_specific(&map, &reference, s, config.tolerance))
        },
    );
}

/// [`UnspecificStepIntersector`] ([`check_unspecific`]).
pub fn capsule_unspecific<M: FromPatches + UnspecificStepIntersector>(config: &SuiteConfig) {
    run(
        config,
        "capsule_unspecific",
        scene_with_capsule_steps(config.scenes, PATCHES, QUERIES),
        |(patches, steps)| {
            let (map, reference) = build::<M>(&patches)?;
            steps.iter().try_for_each(|s| check_unspecific(&map, &reference, s, config.tolerance))
        },
    );
}

/// [`SpecificStepIntersector`] ([`check_specific`]).
pub fn capsule_specific<M: FromPatches + SpecificStepIntersector>(config: &SuiteConfig) {
    run(
        config,
        "capsule_specific",
        scene_with_capsule_steps(config.scenes, PATCHES, QUERIES),
        |(patches, steps)| {
            let (map, reference) = build::<M>(&patches)?;
            steps.iter().try_for_each(|s| check_specific(&map, &reference, s, config.tolerance))
        },
    );
}

/// Clearance against sphere steps ([`check_clearance_vs_capsule`]).
pub fn clearance_vs_capsule<M>(config: &SuiteConfig)
where
    M: FromPatches + ProximityQuery + UnspecificStepIntersector,
{
    run(
        config,
        "clearance_vs_capsule",
        scene_with_points(config.scenes, PATCHES, QUERIES),
        |(patches, points)| {
            let (map, _) = build::<M>(&patches)?;
            points.iter().try_for_each(|p| check_clearance_vs_capsule(&map, p, config.tolerance))
        },
    );
}
