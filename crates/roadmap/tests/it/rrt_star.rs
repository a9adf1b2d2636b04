//! RRT* on the brute-force reference map: every edge re-checked free, the roadmap stays a
//! tree whose costs are path lengths, paths only get shorter and approach the straight line,
//! determinism and counters.

use patch_core::conformance::SceneKind;
use patch_core::conformance::strategies;
use patch_core::{
    BruteForceMap, CapsuleStep, Counted, FromPatches, Point3, Real, UnspecificStepIntersector,
};
use petgraph::graph::NodeIndex;
use proptest::prelude::*;
use roadmap::metrics::path_length;
use roadmap::{
    Goal, MaxIterations, Planner, PlannerStatus, PlanningSpace, Problem, Rrt, RrtConfig, RrtStar,
    RrtStarConfig,
};

use crate::common;
use common::*;

/// Every vertex's cost is the length of its tree path, and the tree is consistent with the
/// roadmap's edges.
fn assert_costs_are_path_lengths<M: UnspecificStepIntersector + ?Sized>(planner: &RrtStar<'_, M>) {
    let graph = planner.roadmap();
    assert_tree(graph);
    for v in graph.node_indices() {
        let mut length = 0.0;
        let mut u = v;
        while let Some(p) = planner.parent(u) {
            assert!(graph.find_edge(p, u).is_some(), "the parent edge is in the roadmap");
            length += (graph[u] - graph[p]).norm();
            u = p;
        }
        assert_eq!(u, NodeIndex::new(0), "every vertex hangs from the start");
        let cost = planner.cost(v).unwrap();
        assert!((cost - length).abs() <= 1e-9 * (1.0 + length), "cost {cost} ≠ length {length}");
    }
}

#[test]
fn the_rewire_count_follows_the_formula() {
    let config = RrtStarConfig::standard();
    let two_e = 2.0 * std::f64::consts::E;
    assert_eq!(config.rewire_factor, two_e);
    for n in 2..3_000 {
        let k = (two_e * (n as Real).ln()).ceil() as usize;
        assert_eq!(config.neighbours_for(n), k, "n = {n}");
    }
    // 2e ≈ 5.4366: k(2) = ⌈3.77⌉, k(100) = ⌈25.04⌉.
    assert_eq!([0, 1, 2, 100].map(|n| config.neighbours_for(n)), [1, 1, 4, 26]);
    let off = RrtStarConfig { rewire_factor: Real::NAN, ..config };
    assert_eq!(off.neighbours_for(1_000), 1);
}

#[test]
fn crosses_the_door_as_a_tree_with_path_costs() {
    let map = wall_with_door();
    let problem = across(0.3);
    for seed in 0..3 {
        let mut p = RrtStar::new(&map, space(0.5), RrtStarConfig::standard(), seed);
        assert_eq!(p.solve(&problem, &mut until_solved(20_000)), PlannerStatus::Exact);
        assert_all_free(&map, &p, 1);
        assert_costs_are_path_lengths(&p);
        let path = p.path_to(0).unwrap();
        assert_eq!(path[0], problem.start);
        assert!((path.last().unwrap() - problem.goals[0].center).norm() <= 0.3);
        assert!(path.iter().any(|q| q.x > 3.0) && path.iter().any(|q| q.x < 3.0));
        let end = p.roadmap().node_indices().find(|&v| p.roadmap()[v] == *path.last().unwrap());
        assert!((p.cost(end.unwrap()).unwrap() - path_length(&path)).abs() < 1e-9);
        // GoalReached stops at the first solution: one iteration fewer has none.
        let samples = p.counters().samples;
        let status = p.solve(&problem, &mut MaxIterations(samples - 1));
        assert!(matches!(status, PlannerStatus::Approximate { .. }), "{status:?}");
    }
}

#[test]
fn paths_only_get_shorter_and_approach_the_straight_line() {
    // Uniform samples without goal bias: the sample stream does not depend on the tree, so
    // a longer run on the same seed extends a shorter one and the best cost never grows.
    let map = BruteForceMap::new();
    let problem = across(0.25);
    let mut previous = Real::INFINITY;
    let mut last = None;
    for k in [1_000, 2_000, 4_000, 8_000] {
        let mut p = RrtStar::new(&map, space(0.5), RrtStarConfig::standard(), 3);
        assert_eq!(p.solve(&problem, &mut MaxIterations(k)), PlannerStatus::Exact);
        let path = p.path_to(0).unwrap();
        let length = path_length(&path);
        assert!(length <= previous + 1e-12, "{k} iterations: {length} > {previous}");
        previous = length;
        last = Some((p.roadmap().clone(), path));
    }
    let (graph, path) = last.unwrap();
    assert_tree(&graph);
    let straight = (path.last().unwrap() - path[0]).norm();
    assert!(previous <= 1.05 * straight, "{previous} vs straight {straight}");
    // Plain RRT on the same seed and budget is longer.
    let mut rrt = Rrt::new(&map, space(0.5), RrtConfig::thesis(), 3);
    assert_eq!(rrt.solve(&problem, &mut MaxIterations(8_000)), PlannerStatus::Exact);
    assert!(path_length(&rrt.path_to(0).unwrap()) > previous);
}

#[test]
fn same_seed_same_roadmap() {
    let map = wall_with_door();
    let problem = across(0.3);
    let mut config = RrtStarConfig::standard();
    config.rrt = RrtConfig::lesum(Some(4e3));
    config.rrt.goal_bias = 0.1;
    let run = |seed: u64| {
        let mut p = RrtStar::new(&map, space(0.5), config, seed);
        p.solve(&problem, &mut MaxIterations(600));
        let first = p.roadmap().clone();
        p.solve(&problem, &mut MaxIterations(600));
        assert!(same_roadmap(&first, p.roadmap()), "a second solve repeats the first");
        (first, p.path_to(0), p.counters())
    };
    let (a, b, c) = (run(9), run(9), run(10));
    assert!(same_roadmap(&a.0, &b.0));
    assert_eq!((a.1, a.2.edges, a.2.collision_checks), (b.1, b.2.edges, b.2.collision_checks));
    assert!(!same_roadmap(&a.0, &c.0));
}

#[test]
fn counters_match_a_counted_map() {
    let counted = Counted::new(wall_with_door());
    let mut p = RrtStar::new(&counted, space(0.5), RrtStarConfig::standard(), 2);
    p.solve(&across(0.3), &mut MaxIterations(500));
    let c = p.counters();
    assert_eq!(c.collision_checks, counted.counts().is_step_free);
    assert_eq!(c.samples, 500);
    assert_eq!(c.vertices, p.roadmap().node_count());
    assert_eq!(c.edges, c.vertices - 1);
    assert!(c.collision_time > std::time::Duration::ZERO);
    p.clear();
    assert_eq!(p.roadmap().node_count(), 0);
    assert_eq!(p.counters(), Default::default());
    assert!(p.path_to(0).is_none());
}

#[test]
fn direct_goal_step_and_trivial_goals() {
    let map = BruteForceMap::new();
    let problem = across(0.3);
    let config = RrtStarConfig { rrt: RrtConfig::lesum(None), ..RrtStarConfig::standard() };
    let mut p = RrtStar::new(&map, space(0.5), config, 4);
    assert_eq!(p.solve(&problem, &mut until_solved(100)), PlannerStatus::Exact);
    assert_eq!(p.path_to(0).unwrap(), vec![problem.start, problem.goals[0].center]);
    assert_eq!(p.counters().samples, 0);
    // Behind the wall the centre joins the tree later and is rewired like any vertex.
    let map = wall_with_door();
    let mut p = RrtStar::new(&map, space(0.5), config, 4);
    assert_eq!(p.solve(&problem, &mut MaxIterations(1_500)), PlannerStatus::Exact);
    assert_eq!(p.path_to(0).unwrap().last(), Some(&problem.goals[0].center));
    assert_all_free(&map, &p, 1);
    assert_costs_are_path_lengths(&p);
}

#[test]
fn invalid_starts_and_goals() {
    let map = wall_with_door();
    let goal = Goal { center: Point3::new(5.0, 2.0, 1.25), tolerance: 0.3 };
    let near_wall = Point3::new(2.9, 3.0, 1.25);
    let mut p = RrtStar::new(&map, space(0.5), RrtStarConfig::standard(), 0);
    for start in [near_wall, Point3::new(-1.0, 2.0, 1.0), Point3::new(Real::NAN, 2.0, 1.0)] {
        let problem = Problem { start, goals: vec![goal] };
        assert_eq!(p.solve(&problem, &mut MaxIterations(10)), PlannerStatus::InvalidStart);
        assert_eq!(p.roadmap().node_count(), 0);
        assert_eq!(p.counters().samples, 0);
    }
    let problem = Problem {
        start: Point3::new(1.0, 2.0, 1.25),
        goals: vec![goal, Goal { center: near_wall, tolerance: 0.3 }],
    };
    assert_eq!(p.solve(&problem, &mut MaxIterations(10)), PlannerStatus::InvalidGoal);
    assert_eq!(p.name(), "rrt-star");
    assert_eq!(p.solve(&across(0.3), &mut MaxIterations(0)), PlannerStatus::Timeout);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

    #[test]
    fn every_edge_is_free_on_random_scenes(
        patches in strategies::scene(SceneKind::Mixed, 0..6),
        start in strategies::point3(strategies::scene_bounds()),
        goal in strategies::point3(strategies::scene_bounds()),
        seed in any::<u64>(),
        lesum in any::<bool>(),
        radius in proptest::option::of(0.3..3.0f64),
    ) {
        let map = BruteForceMap::from_patches(patches).unwrap();
        let space = PlanningSpace::new(strategies::scene_bounds(), RADIUS, 0.8).unwrap();
        let problem = Problem { start, goals: vec![Goal { center: goal, tolerance: 0.25 }] };
        let rrt = if lesum { RrtConfig::lesum(Some(1e4)) } else { RrtConfig::thesis() };
        let config = RrtStarConfig { rrt, rewire_radius: radius, ..RrtStarConfig::standard() };
        let mut p = RrtStar::new(&map, space, config, seed);
        let status = p.solve(&problem, &mut MaxIterations(150));
        assert_all_free(&map, &p, 1);
        let sphere_free = |q: Point3| map.is_step_free(&CapsuleStep::sphere(q, RADIUS).unwrap());
        prop_assert_eq!(status == PlannerStatus::InvalidStart, !sphere_free(start));
        prop_assert_eq!(status == PlannerStatus::Exact, p.path_to(0).is_some());
        if let Some(path) = p.path_to(0) {
            prop_assert_eq!(path[0], start);
            prop_assert!((path.last().unwrap() - goal).norm() <= 0.25 + 1e-12);
        }
        if !matches!(status, PlannerStatus::InvalidStart | PlannerStatus::InvalidGoal) {
            assert_costs_are_path_lengths(&p);
        }
        prop_assert!(p.roadmap().node_weights().all(|q| space.bounds().contains(q)));
    }
}
