//! Lazy PRM on the brute-force reference map: only edges checked free enter the roadmap and
//! paths, fewer collision checks than the eager PRM for the same query, determinism.

use patch_core::conformance::SceneKind;
use patch_core::conformance::strategies;
use patch_core::{
    BruteForceMap, CapsuleStep, Counted, FromPatches, Point3, UnspecificStepIntersector,
};
use proptest::prelude::*;
use roadmap::{
    Goal, GoalStep, MaxIterations, Planner, PlannerStatus, PlanningSpace, Prm, PrmConfig, Problem,
};

use crate::common;
use common::*;

#[test]
fn finds_the_door_through_checked_edges() {
    let map = wall_with_door();
    let problem = across(0.3);
    for config in [PrmConfig::thesis(), PrmConfig::star()] {
        for seed in 0..3 {
            let mut p = Prm::lazy(&map, space(0.5), config, seed);
            assert_eq!(p.solve(&problem, &mut until_solved(20_000)), PlannerStatus::Exact);
            assert_all_free(&map, &p, 1);
            let path = p.path_to(0).unwrap();
            assert_eq!(path[0], problem.start);
            assert!((path.last().unwrap() - problem.goals[0].center).norm() <= 0.3);
            assert!(path.iter().any(|q| q.x > 3.0) && path.iter().any(|q| q.x < 3.0));
            // GoalReached stops at the first iteration whose query succeeds.
            let samples = p.counters().samples;
            let status = p.solve(&problem, &mut MaxIterations(samples - 1));
            assert_ne!(status, PlannerStatus::Exact);
            assert!(p.path_to(0).is_none());
        }
    }
}

#[test]
fn lazy_checks_fewer_edges_than_eager() {
    let map = wall_with_door();
    let problem = across(0.3);
    for seed in 0..4 {
        let mut eager = Prm::new(&map, space(0.5), PrmConfig::thesis(), seed);
        let mut lazy = Prm::lazy(&map, space(0.5), PrmConfig::thesis(), seed);
        assert_eq!(eager.solve(&problem, &mut until_solved(20_000)), PlannerStatus::Exact);
        assert_eq!(lazy.solve(&problem, &mut until_solved(20_000)), PlannerStatus::Exact);
        let (e, l) = (eager.counters(), lazy.counters());
        assert!(
            l.collision_checks < e.collision_checks,
            "seed {seed}: lazy {} vs eager {} checks",
            l.collision_checks,
            e.collision_checks
        );
        // Same seed, same samples: the vertices agree as far as both got.
        let n = l.vertices.min(e.vertices);
        assert!(eager.roadmap().node_weights().take(n).eq(lazy.roadmap().node_weights().take(n)));
    }
}

#[test]
fn same_seed_same_roadmap_and_counters_match_a_counted_map() {
    let counted = Counted::new(wall_with_door());
    let problem = across(0.3);
    let mut a = Prm::lazy(&counted, space(0.5), PrmConfig::thesis(), 7);
    a.solve(&problem, &mut MaxIterations(400));
    assert_eq!(a.counters().collision_checks, counted.counts().is_step_free);
    assert_eq!(a.counters().samples, 400);
    assert_eq!(a.counters().vertices, 401);
    assert_eq!(a.counters().edges, a.roadmap().edge_count());
    let first = a.roadmap().clone();
    a.solve(&problem, &mut MaxIterations(400));
    assert!(same_roadmap(&first, a.roadmap()), "a second solve repeats the first");
    let mut b = Prm::lazy(&counted, space(0.5), PrmConfig::thesis(), 7);
    b.solve(&problem, &mut MaxIterations(400));
    assert!(same_roadmap(a.roadmap(), b.roadmap()));
    assert_eq!(a.path_to(0), b.path_to(0));
    let mut c = Prm::lazy(&counted, space(0.5), PrmConfig::thesis(), 8);
    c.solve(&problem, &mut MaxIterations(400));
    assert!(!same_roadmap(a.roadmap(), c.roadmap()));
    assert_eq!(a.name(), "lazy-prm");
    a.clear();
    assert_eq!(a.roadmap().node_count(), 0);
    assert_eq!(a.counters(), Default::default());
}

#[test]
fn an_open_room_needs_only_the_path_edges() {
    // Without obstacles the first query succeeds and checks only its own edges (plus the start
    // and goal checks).
    let map = BruteForceMap::new();
    let problem = across(0.3);
    let mut p = Prm::lazy(&map, space(0.5), PrmConfig::thesis(), 1);
    assert_eq!(p.solve(&problem, &mut until_solved(5_000)), PlannerStatus::Exact);
    let path = p.path_to(0).unwrap();
    assert_eq!(p.counters().collision_checks, 2 + (path.len() as u64 - 1));
    assert_eq!(p.roadmap().edge_count(), path.len() - 1);
}

#[test]
fn invalid_starts_and_goals() {
    let map = wall_with_door();
    let goal = Goal { center: Point3::new(5.0, 2.0, 1.25), tolerance: 0.3 };
    let near_wall = Point3::new(2.9, 3.0, 1.25);
    let mut p = Prm::lazy(&map, space(0.5), PrmConfig::thesis(), 0);
    let problem = Problem { start: near_wall, goals: vec![goal] };
    assert_eq!(p.solve(&problem, &mut MaxIterations(10)), PlannerStatus::InvalidStart);
    let problem = Problem {
        start: Point3::new(1.0, 2.0, 1.25),
        goals: vec![goal, Goal { center: near_wall, tolerance: 0.3 }],
    };
    assert_eq!(p.solve(&problem, &mut MaxIterations(10)), PlannerStatus::InvalidGoal);
    assert_eq!(p.solve(&across(0.3), &mut MaxIterations(0)), PlannerStatus::Timeout);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn every_edge_is_free_on_random_scenes(
        patches in strategies::scene(SceneKind::Mixed, 0..6),
        start in strategies::point3(strategies::scene_bounds()),
        goals in proptest::collection::vec(strategies::point3(strategies::scene_bounds()), 1..3),
        seed in any::<u64>(),
        star in any::<bool>(),
        direct_goal_step in any::<bool>(),
    ) {
        let map = BruteForceMap::from_patches(patches).unwrap();
        let space = PlanningSpace::new(strategies::scene_bounds(), RADIUS, 0.8).unwrap();
        let goals: Vec<Goal> = goals.into_iter().map(|center| Goal { center, tolerance: 0.25 }).collect();
        let problem = Problem { start, goals: goals.clone() };
        let base = if star { PrmConfig::star() } else { PrmConfig::thesis() };
        let goal_step = if direct_goal_step { GoalStep::Direct } else { GoalStep::Grown };
        let config = PrmConfig { goal_step, ..base };
        let mut p = Prm::lazy(&map, space, config, seed);
        let status = p.solve(&problem, &mut MaxIterations(80));
        assert_all_free(&map, &p, goals.len());
        let sphere_free = |q: Point3| map.is_step_free(&CapsuleStep::sphere(q, RADIUS).unwrap());
        prop_assert_eq!(status == PlannerStatus::InvalidStart, !sphere_free(start));
        if status == PlannerStatus::Exact {
            for (g, goal) in goals.iter().enumerate() {
                let path = p.path_to(g).unwrap();
                prop_assert_eq!(path[0], start);
                prop_assert!((path.last().unwrap() - goal.center).norm() <= 0.25 + 1e-12);
            }
        }
        // The eager PRM* on the same seed connects at least what the lazy one found.
        if status == PlannerStatus::Exact && star && !direct_goal_step {
            let mut eager = Prm::new(&map, space, config, seed);
            prop_assert_eq!(eager.solve(&problem, &mut MaxIterations(80)), PlannerStatus::Exact);
        }
    }
}
