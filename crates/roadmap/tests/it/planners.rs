//! RRT and PRM on the brute-force reference map: outcomes, determinism, and every edge
//! re-checked free.

use patch_core::conformance::SceneKind;
use patch_core::conformance::strategies;
use patch_core::{
    BruteForceMap, CapsuleStep, Counted, FromPatches, Point3, Real, UnspecificStepIntersector,
};
use petgraph::algo::is_cyclic_undirected;
use petgraph::visit::EdgeRef;
use proptest::prelude::*;
use roadmap::{
    AnyOf, Goal, GoalReached, GoalStep, MaxIterations, Planner, PlannerStatus, PlanningSpace, Prm,
    PrmConfig, Problem, Roadmap, Rrt, RrtConfig, Sampler, Termination,
};

use crate::common;
use common::*;

#[test]
fn rrt_and_prm_cross_an_empty_room() {
    let map = BruteForceMap::new();
    let problem = across(0.3);
    let mut rrt = Rrt::new(&map, space(0.5), RrtConfig::thesis(), 1);
    assert_eq!(rrt.solve(&problem, &mut until_solved(5_000)), PlannerStatus::Exact);
    let path = rrt.path_to(0).unwrap();
    assert_eq!(path[0], problem.start);
    assert!((path.last().unwrap() - problem.goals[0].center).norm() <= 0.3);
    assert_all_free(&map, &rrt, 1);

    let mut prm = Prm::new(&map, space(0.5), PrmConfig::thesis(), 1);
    assert_eq!(prm.solve(&problem, &mut until_solved(5_000)), PlannerStatus::Exact);
    assert!(prm.path_to(0).is_some());
    assert_all_free(&map, &prm, 1);
}

#[test]
fn rrt_and_prm_find_the_door() {
    let map = wall_with_door();
    let problem = across(0.3);
    let straight = CapsuleStep::new(problem.start, problem.goals[0].center, RADIUS).unwrap();
    assert!(!map.is_step_free(&straight));
    for seed in 0..3 {
        let mut rrt = Rrt::new(&map, space(0.5), RrtConfig::thesis(), seed);
        assert_eq!(rrt.solve(&problem, &mut until_solved(20_000)), PlannerStatus::Exact);
        let path = rrt.path_to(0).unwrap();
        assert!(path.iter().any(|p| p.x > 3.0) && path.iter().any(|p| p.x < 3.0));
        assert_all_free(&map, &rrt, 1);

        let mut prm = Prm::new(&map, space(0.5), PrmConfig::thesis(), seed);
        assert_eq!(prm.solve(&problem, &mut until_solved(20_000)), PlannerStatus::Exact);
        assert_all_free(&map, &prm, 1);
        assert!(!is_cyclic_undirected(prm.roadmap()));
    }
}

#[test]
fn lesum_rrt_steps_straight_to_a_visible_goal() {
    let map = BruteForceMap::new();
    let problem = across(0.3);
    let mut rrt = Rrt::new(&map, space(0.5), RrtConfig::lesum(None), 4);
    assert_eq!(rrt.solve(&problem, &mut until_solved(100)), PlannerStatus::Exact);
    assert_eq!(rrt.path_to(0).unwrap(), vec![problem.start, problem.goals[0].center]);
    assert_eq!(rrt.counters().samples, 0);

    // Through the door with goal-directed sampling and goal bias.
    let map = wall_with_door();
    let mut config = RrtConfig::lesum(Some(2e4));
    config.goal_bias = 0.05;
    assert_eq!(config.sampler, Sampler::GoalGaussian { factor: 2e4 });
    let mut rrt = Rrt::new(&map, space(0.5), config, 4);
    assert_eq!(rrt.solve(&problem, &mut until_solved(20_000)), PlannerStatus::Exact);
    assert_eq!(rrt.path_to(0).unwrap().last(), Some(&problem.goals[0].center));
    assert_all_free(&map, &rrt, 1);

    let mut config = PrmConfig::thesis();
    config.goal_step = GoalStep::Direct;
    let mut prm = Prm::new(&map, space(0.5), config, 4);
    assert_eq!(prm.solve(&problem, &mut until_solved(20_000)), PlannerStatus::Exact);
    assert_all_free(&map, &prm, 1);
}

#[test]
fn invalid_starts_and_goals() {
    let map = wall_with_door();
    let goal = Goal { center: Point3::new(5.0, 2.0, 1.25), tolerance: 0.3 };
    let near_wall = Point3::new(2.9, 3.0, 1.25); // 0.1 m from the wall, radius 0.2
    let outside = Point3::new(-1.0, 2.0, 1.0);
    let nan = Point3::new(Real::NAN, 2.0, 1.0);
    for planner in planners(&map, 0) {
        let mut planner = planner;
        for start in [near_wall, outside, nan] {
            let problem = Problem { start, goals: vec![goal] };
            let status = planner.solve(&problem, &mut MaxIterations(10));
            assert_eq!(status, PlannerStatus::InvalidStart, "{}", planner.name());
            assert_eq!(planner.roadmap().node_count(), 0);
            assert_eq!(planner.counters().samples, 0);
        }
        let start = Point3::new(1.0, 2.0, 1.25);
        for bad in [
            Goal { center: near_wall, tolerance: 0.3 },
            Goal { center: outside, tolerance: 0.3 },
            Goal { center: goal.center, tolerance: -0.1 },
            Goal { center: goal.center, tolerance: Real::NAN },
        ] {
            let problem = Problem { start, goals: vec![goal, bad] };
            let status = planner.solve(&problem, &mut MaxIterations(10));
            assert_eq!(status, PlannerStatus::InvalidGoal, "{}", planner.name());
        }
    }
}

fn planners(map: &BruteForceMap, seed: u64) -> Vec<Box<dyn Planner + '_>> {
    vec![
        Box::new(Rrt::new(map, space(0.5), RrtConfig::thesis(), seed)),
        Box::new(Prm::new(map, space(0.5), PrmConfig::thesis(), seed)),
    ]
}

#[test]
fn termination_and_status() {
    let map = wall_with_door();
    let problem = across(0.3);
    for mut planner in planners(&map, 5) {
        assert_eq!(planner.solve(&problem, &mut MaxIterations(0)), PlannerStatus::Timeout);
        let now = roadmap::Deadline(std::time::Instant::now());
        assert_eq!(planner.solve(&problem, &mut AnyOf(now, GoalReached)), PlannerStatus::Timeout);
        assert_eq!(planner.counters().samples, 0);
        assert_eq!(planner.roadmap().node_count(), 1);
        for k in [1, 7, 50] {
            let status = planner.solve(&problem, &mut MaxIterations(k));
            assert_eq!(planner.counters().samples, k, "{}", planner.name());
            if let PlannerStatus::Approximate { gap } = status {
                assert!(gap > 0.0 && gap <= 4.0);
            }
        }
        // A goal within tolerance of the start is reached before any sample.
        let trivial = Problem {
            start: problem.start,
            goals: vec![Goal {
                center: problem.start + patch_core::Vector3::x() * 0.1,
                tolerance: 0.2,
            }],
        };
        assert_eq!(planner.solve(&trivial, &mut until_solved(100)), PlannerStatus::Exact);
        assert_eq!(planner.counters().samples, 0);
        assert_eq!(planner.path_to(0).unwrap(), vec![problem.start]);
        assert!(planner.path_to(1).is_none());
        // No goals: exact at once.
        let none = Problem { start: problem.start, goals: vec![] };
        assert_eq!(planner.solve(&none, &mut GoalReached), PlannerStatus::Exact);
        planner.clear();
        assert_eq!(planner.roadmap().node_count(), 0);
        assert_eq!(planner.counters().collision_checks, 0);
        assert!(planner.path_to(0).is_none());
    }
}

#[test]
fn counters_match_a_counted_map() {
    let counted = Counted::new(wall_with_door());
    let problem = across(0.3);
    let mut rrt = Rrt::new(&counted, space(0.5), RrtConfig::thesis(), 2);
    rrt.solve(&problem, &mut MaxIterations(300));
    let c = rrt.counters();
    assert_eq!(c.collision_checks, counted.counts().is_step_free);
    assert_eq!(c.vertices, rrt.roadmap().node_count());
    assert_eq!(c.edges, c.vertices - 1);
    assert!(c.collision_time > std::time::Duration::ZERO);
    counted.reset_counts();
    let mut prm = Prm::new(&counted, space(0.5), PrmConfig::thesis(), 2);
    prm.solve(&problem, &mut MaxIterations(300));
    assert_eq!(prm.counters().collision_checks, counted.counts().is_step_free);
    assert_eq!(prm.counters().vertices, 301);
    // At most N checks per sample, plus the start and goal checks.
    assert!(prm.counters().collision_checks <= 300 * 6 + 2);
}

#[test]
fn planners_accept_any_capsule_intersector() {
    fn takes<M: UnspecificStepIntersector + ?Sized>(map: &M) -> Vec<Box<dyn Planner + '_>> {
        vec![
            Box::new(Rrt::new(map, space(0.5), RrtConfig::thesis(), 0)),
            Box::new(Prm::new(map, space(0.5), PrmConfig::thesis(), 0)),
        ]
    }
    let map = BruteForceMap::new();
    let counted = Counted::new(BruteForceMap::new());
    let by_ref = &map;
    let dynamic: &dyn UnspecificStepIntersector = &map;
    let problem = across(0.3);
    let mut all = takes(&map);
    all.extend(takes(&counted));
    all.extend(takes(&by_ref));
    all.extend(takes(dynamic));
    for mut p in all {
        assert_eq!(p.solve(&problem, &mut until_solved(5_000)), PlannerStatus::Exact);
    }
}

#[test]
fn same_seed_same_roadmap() {
    let map = wall_with_door();
    let problem = across(0.3);
    let stop = || MaxIterations(400);
    let mut config = RrtConfig::lesum(Some(4e3));
    config.goal_bias = 0.1;
    let runs = |seed: u64| -> Vec<Roadmap> {
        let mut out = Vec::new();
        for mut p in [
            Box::new(Rrt::new(&map, space(0.5), config, seed)) as Box<dyn Planner + '_>,
            Box::new(Rrt::new(&map, space(0.5), RrtConfig::thesis(), seed)),
            Box::new(Prm::new(&map, space(0.5), PrmConfig::thesis(), seed)),
        ] {
            p.solve(&problem, &mut stop());
            let first = p.roadmap().clone();
            p.solve(&problem, &mut stop());
            assert!(same_roadmap(&first, p.roadmap()), "a second solve repeats the first");
            out.push(first);
        }
        out
    };
    let (a, b, c) = (runs(9), runs(9), runs(10));
    for i in 0..a.len() {
        assert!(same_roadmap(&a[i], &b[i]));
        assert!(!same_roadmap(&a[i], &c[i]));
    }
}

/// A termination that records what it was shown.
struct Recorder(Vec<u64>, u64);

impl Termination for Recorder {
    fn should_stop(&mut self, progress: &roadmap::Progress) -> bool {
        self.0.push(progress.iterations);
        progress.iterations >= self.1
    }
}

#[test]
fn termination_is_asked_before_every_iteration() {
    let map = BruteForceMap::new();
    let problem = across(0.3);
    for mut p in planners(&map, 0) {
        let mut rec = Recorder(Vec::new(), 5);
        p.solve(&problem, &mut rec);
        assert_eq!(rec.0, [0, 1, 2, 3, 4, 5]);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

    #[test]
    fn every_edge_is_free_on_random_scenes(
        patches in strategies::scene(SceneKind::Mixed, 0..6),
        start in strategies::point3(strategies::scene_bounds()),
        goal in strategies::point3(strategies::scene_bounds()),
        seed in any::<u64>(),
        lesum in any::<bool>(),
        radius_limit in proptest::option::of(0.5..4.0f64),
    ) {
        let map = BruteForceMap::from_patches(patches).unwrap();
        let space = PlanningSpace::new(strategies::scene_bounds(), RADIUS, 0.8).unwrap();
        let problem = Problem { start, goals: vec![Goal { center: goal, tolerance: 0.25 }] };
        let rrt_config = if lesum { RrtConfig::lesum(Some(1e4)) } else { RrtConfig::thesis() };
        let mut rrt = Rrt::new(&map, space, rrt_config, seed);
        let status = rrt.solve(&problem, &mut MaxIterations(60));
        assert_all_free(&map, &rrt, 1);
        let sphere_free = |p: Point3| map.is_step_free(&CapsuleStep::sphere(p, RADIUS).unwrap());
        prop_assert_eq!(status == PlannerStatus::InvalidStart, !sphere_free(start));
        if sphere_free(start) {
            prop_assert_eq!(status == PlannerStatus::InvalidGoal, !sphere_free(goal));
        }
        if let PlannerStatus::Approximate { gap } = status {
            let closest = rrt.roadmap().node_weights().map(|p| (p - goal).norm()).fold(Real::INFINITY, Real::min);
            prop_assert_eq!(gap, closest);
            prop_assert!(gap > 0.25);
        }
        prop_assert_eq!(status == PlannerStatus::Exact, rrt.path_to(0).is_some());
        let graph = rrt.roadmap();
        for e in graph.edge_references() {
            let goal_edge = lesum && graph[e.target()] == goal;
            prop_assert!(goal_edge || *e.weight() <= 0.8 + 1e-12, "RRT step {} > max_step", e.weight());
        }
        if graph.node_count() > 0 {
            prop_assert_eq!(graph.edge_count(), graph.node_count() - 1);
            prop_assert!(graph.node_weights().all(|p| space.bounds().contains(p)));
        }

        let goal_step = if lesum { GoalStep::Direct } else { GoalStep::Grown };
        let prm_config = PrmConfig { neighbours: 5, connection_radius: radius_limit, goal_step, ..PrmConfig::thesis() };
        let mut prm = Prm::new(&map, space, prm_config, seed);
        let status = prm.solve(&problem, &mut MaxIterations(60));
        assert_all_free(&map, &prm, 1);
        prop_assert_eq!(status == PlannerStatus::InvalidStart, !sphere_free(start));
        if matches!(status, PlannerStatus::Exact | PlannerStatus::Approximate { .. } | PlannerStatus::Timeout) {
            // Every sample is a vertex, plus the start and at most the goal centre.
            let extra = prm.roadmap().node_count() - 61;
            prop_assert!(extra <= usize::from(lesum));
        }
        prop_assert_eq!(status == PlannerStatus::Exact, prm.path_to(0).is_some());
        prop_assert!(!is_cyclic_undirected(prm.roadmap()), "PRM roadmap is a forest");
        if let Some(r) = radius_limit {
            let within = prm
                .roadmap()
                .edge_references()
                .all(|e| *e.weight() <= r || prm_config.goal_step == GoalStep::Direct);
            prop_assert!(within, "PRM edge longer than the connection radius");
        }
    }
}
