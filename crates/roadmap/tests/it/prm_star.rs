//! PRM*: the neighbour count follows `k(n) = ⌈e·(1 + 1/3)·ln n⌉`, every edge is free, and
//! paths are shortest in the roadmap.

use patch_core::conformance::SceneKind;
use patch_core::conformance::strategies;
use patch_core::{BruteForceMap, CapsuleStep, FromPatches, Real, UnspecificStepIntersector};
use petgraph::visit::EdgeRef;
use proptest::prelude::*;
use roadmap::metrics::path_length;
use roadmap::{
    AnyOf, Goal, GoalReached, GoalStep, MaxIterations, Planner, PlannerStatus, PlanningSpace, Prm,
    PrmConfig, PrmConnections, Problem,
};

use crate::common;
use common::*;

fn assert_edges_free(map: &BruteForceMap, prm: &dyn Planner) {
    let graph = prm.roadmap();
    for e in graph.edge_references() {
        let (a, b) = (graph[e.source()], graph[e.target()]);
        assert!(map.is_step_free(&CapsuleStep::new(a, b, RADIUS).unwrap()), "{a} → {b} collides");
        assert!((e.weight() - (b - a).norm()).abs() < 1e-12);
    }
    if let Some(path) = prm.path_to(0) {
        for w in path.windows(2) {
            assert!(map.is_step_free(&CapsuleStep::new(w[0], w[1], RADIUS).unwrap()));
        }
    }
}

#[test]
fn the_neighbour_count_follows_the_formula() {
    let star = PrmConfig::star();
    assert_eq!(star.connections, PrmConnections::Star);
    let formula = |n: usize| (std::f64::consts::E * (4.0 / 3.0) * (n as Real).ln()).ceil() as usize;
    for n in 2..5_000 {
        assert_eq!(star.neighbours_for(n), formula(n), "n = {n}");
    }
    // e·4/3 ≈ 3.6244: k(2) = ⌈2.51⌉, k(10) = ⌈8.35⌉, k(100) = ⌈16.69⌉, k(1000) = ⌈25.04⌉.
    assert_eq!([2, 10, 100, 1000].map(|n| star.neighbours_for(n)), [3, 9, 17, 26]);
    assert_eq!(star.neighbours_for(0), 0);
    assert_eq!(star.neighbours_for(1), 0);
    // Without `star` the count is the fixed `N`.
    let thesis = PrmConfig::thesis();
    assert_eq!(thesis.connections, PrmConnections::Forest);
    assert!([1, 2, 100, 10_000].iter().all(|&n| thesis.neighbours_for(n) == 6));
}

#[test]
fn in_an_empty_room_every_sample_connects_to_k_of_n_neighbours() {
    // No obstacles, no radius limit, no component test: the sample that becomes the n-th
    // vertex adds exactly min(k(n), n − 1) edges.
    let map = BruteForceMap::new();
    let config = PrmConfig::star();
    let samples = 300;
    let mut prm = Prm::new(&map, space(0.5), config, 4);
    prm.solve(&across(0.3), &mut MaxIterations(samples));
    let vertices = prm.roadmap().node_count();
    assert_eq!(vertices, samples as usize + 1);
    let expected: usize = (2..=vertices).map(|n| config.neighbours_for(n).min(n - 1)).sum();
    assert_eq!(prm.roadmap().edge_count(), expected);
    assert_eq!(prm.counters().edges, expected);
    assert_edges_free(&map, &prm);
}

#[test]
fn prm_star_crosses_the_door_with_free_edges_and_a_shortest_path() {
    let map = wall_with_door();
    let mut prm = Prm::new(&map, space(0.5), PrmConfig::star(), 2);
    let status = prm.solve(&across(0.3), &mut AnyOf(GoalReached, MaxIterations(5_000)));
    assert_eq!(status, PlannerStatus::Exact);
    assert_edges_free(&map, &prm);
    let path = prm.path_to(0).unwrap();
    assert_eq!(path[0], across(0.3).start);
    assert!((path.last().unwrap() - across(0.3).goals[0].center).norm() <= 0.3);
    // Deterministic for a seed.
    let mut again = Prm::new(&map, space(0.5), PrmConfig::star(), 2);
    again.solve(&across(0.3), &mut AnyOf(GoalReached, MaxIterations(5_000)));
    assert_eq!(again.path_to(0).unwrap(), path);
}

#[test]
fn paths_are_shortest_in_the_roadmap() {
    // Growing past the goal, PRM*'s roadmap has cycles; the path is Dijkstra's.
    let map = BruteForceMap::new();
    let mut prm = Prm::new(&map, space(0.5), PrmConfig::star(), 8);
    prm.solve(&across(0.3), &mut MaxIterations(400));
    let graph = prm.roadmap();
    assert!(petgraph::algo::is_cyclic_undirected(graph));
    let path = prm.path_to(0).unwrap();
    let end = graph.node_indices().find(|&v| graph[v] == *path.last().unwrap()).unwrap();
    let distances =
        petgraph::algo::dijkstra(graph, petgraph::graph::NodeIndex::new(0), Some(end), |e| {
            *e.weight()
        });
    assert!((path_length(&path) - distances[&end]).abs() < 1e-9);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn prm_star_edges_are_free_on_random_scenes(
        patches in strategies::scene(SceneKind::Mixed, 0..6),
        start in strategies::point3(strategies::scene_bounds()),
        goal in strategies::point3(strategies::scene_bounds()),
        seed in any::<u64>(),
        direct_goal_step in any::<bool>(),
    ) {
        let map = BruteForceMap::from_patches(patches).unwrap();
        let space = PlanningSpace::new(strategies::scene_bounds(), RADIUS, 0.8).unwrap();
        let problem = Problem { start, goals: vec![Goal { center: goal, tolerance: 0.25 }] };
        let goal_step = if direct_goal_step { GoalStep::Direct } else { GoalStep::Grown };
        let config = PrmConfig { goal_step, ..PrmConfig::star() };
        let mut prm = Prm::new(&map, space, config, seed);
        let status = prm.solve(&problem, &mut MaxIterations(80));
        assert_edges_free(&map, &prm);
        prop_assert_eq!(status == PlannerStatus::Exact, prm.path_to(0).is_some());
    }
}
