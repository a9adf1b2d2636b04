//! Path shortcutting on the brute-force reference map: same ends, only free or original
//! segments, never longer, deterministic.

use patch_core::conformance::SceneKind;
use patch_core::conformance::strategies;
use patch_core::{
    Aabb, BruteForceMap, CapsuleStep, FromPatches, Point3, UnspecificStepIntersector,
};
use proptest::prelude::*;
use roadmap::metrics::path_length;
use roadmap::{
    AnyOf, Goal, GoalReached, MaxIterations, Planner, PlannerStatus, PlanningSpace, Problem, Rrt,
    RrtConfig, ShortcutConfig, shortcut_path,
};

use crate::common;
use common::*;

fn is_free(map: &BruteForceMap, a: Point3, b: Point3) -> bool {
    map.is_step_free(&CapsuleStep::new(a, b, RADIUS).unwrap())
}

/// The result's ends, segments and length, checked against the input.
fn assert_guarantees(map: &BruteForceMap, input: &[Point3], output: &[Point3]) {
    assert_eq!(input.first(), output.first(), "start kept");
    assert_eq!(input.last(), output.last(), "end kept");
    assert!(path_length(output) <= path_length(input), "never longer");
    for w in output.windows(2) {
        let original = input.windows(2).any(|v| v == w);
        assert!(original || is_free(map, w[0], w[1]), "new segment {} → {} collides", w[0], w[1]);
    }
}

#[test]
fn an_empty_room_leaves_the_straight_line() {
    let map = BruteForceMap::new();
    let path = [
        Point3::new(0.5, 0.5, 1.0),
        Point3::new(1.0, 3.0, 1.0),
        Point3::new(2.0, 0.5, 1.5),
        Point3::new(3.0, 3.5, 1.0),
        Point3::new(4.0, 1.0, 1.0),
    ];
    let greedy = ShortcutConfig { greedy: true, random_attempts: 0 };
    let out = shortcut_path(&map, &path, RADIUS, &greedy, 0);
    assert_eq!(out, [path[0], path[4]]);
    let random = ShortcutConfig { greedy: false, random_attempts: 200 };
    let out = shortcut_path(&map, &path, RADIUS, &random, 3);
    assert_guarantees(&map, &path, &out);
    assert!(path_length(&out) < path_length(&path));
}

#[test]
fn short_paths_come_back_unchanged() {
    let map = BruteForceMap::new();
    let config = ShortcutConfig::standard();
    let p = Point3::new(1.0, 2.0, 3.0);
    let q = Point3::new(2.0, 2.0, 3.0);
    assert!(shortcut_path(&map, &[], RADIUS, &config, 1).is_empty());
    assert_eq!(shortcut_path(&map, &[p], RADIUS, &config, 1), [p]);
    assert_eq!(shortcut_path(&map, &[p, q], RADIUS, &config, 1), [p, q]);
    // An invalid radius makes every step collide: nothing changes.
    let path = [p, Point3::new(1.5, 3.0, 3.0), q];
    assert_eq!(shortcut_path(&map, &path, -1.0, &config, 1), path);
}

#[test]
fn a_path_through_the_door_gets_shorter_and_stays_free() {
    let map = wall_with_door();
    // A detour through the door at (3, 1, 1.25).
    let path = [
        Point3::new(1.0, 3.0, 1.25),
        Point3::new(1.0, 1.0, 1.25),
        Point3::new(2.0, 1.0, 1.25),
        Point3::new(3.0, 1.0, 1.25),
        Point3::new(4.0, 1.0, 1.25),
        Point3::new(5.0, 1.0, 1.25),
        Point3::new(5.0, 3.0, 1.25),
    ];
    assert!(path.windows(2).all(|w| is_free(&map, w[0], w[1])));
    let out = shortcut_path(&map, &path, RADIUS, &ShortcutConfig::standard(), 11);
    assert_guarantees(&map, &path, &out);
    assert!(out.windows(2).all(|w| is_free(&map, w[0], w[1])));
    assert!(path_length(&out) < path_length(&path) - 1.0, "corners cut");
    // It still passes the wall through the door.
    assert!(!is_free(&map, path[0], path[6]));
}

#[test]
fn shortcutting_is_deterministic_for_a_seed() {
    let map = wall_with_door();
    let space =
        PlanningSpace::new(Aabb::new(Point3::origin(), Point3::new(6.0, 4.0, 2.5)), RADIUS, 0.5)
            .unwrap();
    let problem = Problem {
        start: Point3::new(1.0, 2.0, 1.25),
        goals: vec![Goal { center: Point3::new(5.0, 2.0, 1.25), tolerance: 0.3 }],
    };
    let mut rrt = Rrt::new(&map, space, RrtConfig::thesis(), 5);
    let status = rrt.solve(&problem, &mut AnyOf(GoalReached, MaxIterations(20_000)));
    assert_eq!(status, PlannerStatus::Exact);
    let path = rrt.path_to(0).unwrap();
    let config = ShortcutConfig::standard();
    let a = shortcut_path(&map, &path, RADIUS, &config, 9);
    let b = shortcut_path(&map, &path, RADIUS, &config, 9);
    assert_eq!(a, b);
    assert_guarantees(&map, &path, &a);
    assert!(a.windows(2).all(|w| is_free(&map, w[0], w[1])));
    assert!(path_length(&a) < path_length(&path));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    /// Arbitrary polylines (free or not): the result keeps the ends, is never longer, and every
    /// segment is either an input segment or free.
    #[test]
    fn random_polylines_keep_the_guarantees(
        patches in strategies::scene(SceneKind::Mixed, 0..6),
        path in proptest::collection::vec(strategies::point3(strategies::scene_bounds()), 0..8),
        seed in any::<u64>(),
        greedy in any::<bool>(),
        random_attempts in 0usize..40,
    ) {
        let map = BruteForceMap::from_patches(patches).unwrap();
        let config = ShortcutConfig { greedy, random_attempts };
        let out = shortcut_path(&map, &path, RADIUS, &config, seed);
        assert_guarantees(&map, &path, &out);
        prop_assert_eq!(&out, &shortcut_path(&map, &path, RADIUS, &config, seed));
    }

    /// Planner paths on random scenes: every segment of the result is free.
    #[test]
    fn planner_paths_stay_free_on_random_scenes(
        patches in strategies::scene(SceneKind::Mixed, 0..6),
        start in strategies::point3(strategies::scene_bounds()),
        goal in strategies::point3(strategies::scene_bounds()),
        seed in any::<u64>(),
    ) {
        let map = BruteForceMap::from_patches(patches).unwrap();
        let space = PlanningSpace::new(strategies::scene_bounds(), RADIUS, 0.8).unwrap();
        let problem = Problem { start, goals: vec![Goal { center: goal, tolerance: 0.25 }] };
        let mut rrt = Rrt::new(&map, space, RrtConfig::lesum(Some(1e4)), seed);
        rrt.solve(&problem, &mut AnyOf(GoalReached, MaxIterations(150)));
        if let Some(path) = rrt.path_to(0) {
            prop_assert!(path.windows(2).all(|w| is_free(&map, w[0], w[1])));
            let out = shortcut_path(&map, &path, RADIUS, &ShortcutConfig::standard(), seed);
            assert_guarantees(&map, &path, &out);
            for w in out.windows(2) {
                prop_assert!(is_free(&map, w[0], w[1]), "segment {} → {} collides", w[0], w[1]);
            }
        }
    }
}
