//! RRT-Connect on the brute-force reference map: outcomes, determinism, and every edge
//! re-checked free.

use patch_core::conformance::SceneKind;
use patch_core::conformance::strategies;
use patch_core::{
    BruteForceMap, CapsuleStep, Counted, FromPatches, Point3, Real, UnspecificStepIntersector,
};
use petgraph::algo::is_cyclic_undirected;
use proptest::prelude::*;
use roadmap::{
    Goal, MaxIterations, Planner, PlannerStatus, PlanningSpace, Problem, RrtConnect, Termination,
};

use crate::common;
use common::*;

#[test]
fn joins_the_trees_across_an_empty_room_and_through_the_door() {
    let problem = across(0.0);
    for map in [BruteForceMap::new(), wall_with_door()] {
        for seed in 0..3 {
            let mut p = RrtConnect::new(&map, space(0.5), seed);
            assert_eq!(p.solve(&problem, &mut until_solved(20_000)), PlannerStatus::Exact);
            let path = p.path_to(0).unwrap();
            assert_eq!(path[0], problem.start);
            assert_eq!(path.last(), Some(&problem.goals[0].center));
            assert!(path.windows(2).all(|w| (w[1] - w[0]).norm() <= 0.5 + 1e-12));
            assert_all_free(&map, &p, 1);
            assert!(!is_cyclic_undirected(p.roadmap()));
            assert_eq!(p.roadmap().edge_count(), p.roadmap().node_count() - 1, "one tree");
        }
    }
    // The empty room needs only a few iterations: the first connection attempt succeeds.
    let map = BruteForceMap::new();
    let mut p = RrtConnect::new(&map, space(0.5), 0);
    assert_eq!(p.solve(&problem, &mut until_solved(20_000)), PlannerStatus::Exact);
    assert!(p.counters().samples <= 3, "{} samples", p.counters().samples);
}

#[test]
fn goals_start_and_termination() {
    let map = wall_with_door();
    let problem = across(0.0);
    let mut p = RrtConnect::new(&map, space(0.5), 1);
    assert_eq!(p.name(), "rrt-connect");
    let bad_start = Problem { start: Point3::new(2.9, 3.0, 1.25), ..problem.clone() };
    assert_eq!(p.solve(&bad_start, &mut MaxIterations(10)), PlannerStatus::InvalidStart);
    assert_eq!(p.roadmap().node_count(), 0);
    assert_eq!(p.solve(&problem, &mut MaxIterations(0)), PlannerStatus::Timeout);
    assert_eq!(p.roadmap().node_count(), 2, "the start and the goal root");
    if let PlannerStatus::Approximate { gap } = p.solve(&problem, &mut MaxIterations(5)) {
        let closest = p
            .roadmap()
            .node_weights()
            .skip(2)
            .chain([problem.start].iter())
            .map(|q| (q - problem.goals[0].center).norm())
            .fold(Real::INFINITY, Real::min);
        assert!(gap >= closest && gap <= 4.0);
    }
    // A goal within tolerance of the start: reached before any sample.
    let trivial = Problem {
        start: problem.start,
        goals: vec![Goal {
            center: problem.start + patch_core::Vector3::x() * 0.1,
            tolerance: 0.2,
        }],
    };
    assert_eq!(p.solve(&trivial, &mut until_solved(100)), PlannerStatus::Exact);
    assert_eq!(p.path_to(0).unwrap(), vec![problem.start]);
    // No goal: the start tree grows alone.
    let none = Problem { start: problem.start, goals: vec![] };
    assert_eq!(p.solve(&none, &mut MaxIterations(50)), PlannerStatus::Exact);
    assert_eq!(p.counters().samples, 50);
    assert_eq!(p.roadmap().edge_count(), p.roadmap().node_count() - 1);
    p.clear();
    assert_eq!(p.roadmap().node_count(), 0);
    assert!(p.path_to(0).is_none());
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
fn reaches_several_goals_on_both_sides_of_the_wall() {
    let map = wall_with_door();
    let goal = |x: Real, y: Real| Goal { center: Point3::new(x, y, 1.25), tolerance: 0.0 };
    let problem = Problem {
        start: Point3::new(1.0, 2.0, 1.25),
        goals: vec![goal(5.0, 2.0), goal(0.5, 3.5), goal(5.5, 0.5), goal(4.0, 3.5)],
    };
    for seed in 0..8 {
        let mut p = RrtConnect::new(&map, space(0.5), seed);
        assert_eq!(p.solve(&problem, &mut until_solved(20_000)), PlannerStatus::Exact, "{seed}");
        assert_all_free(&map, &p, problem.goals.len());
        for (i, g) in problem.goals.iter().enumerate() {
            let path = p.path_to(i).unwrap();
            assert_eq!(path[0], problem.start);
            assert_eq!(*path.last().unwrap(), g.center, "goal {i} ends at its centre");
        }
        // Every goal tree joined the start tree: one tree over all vertices.
        assert!(!is_cyclic_undirected(p.roadmap()));
        assert_eq!(p.roadmap().edge_count(), p.roadmap().node_count() - 1);
    }
    // A goal inside the wall is invalid, whichever its position in the list.
    let mut bad = problem.clone();
    bad.goals[2] = goal(3.0, 3.0);
    let mut p = RrtConnect::new(&map, space(0.5), 0);
    assert_eq!(p.solve(&bad, &mut MaxIterations(10)), PlannerStatus::InvalidGoal);
}

#[test]
fn determinism_counters_and_termination() {
    let counted = Counted::new(wall_with_door());
    let problem = across(0.0);
    let run = |seed: u64| {
        counted.reset_counts();
        let mut p = RrtConnect::new(&counted, space(0.5), seed);
        let mut rec = Recorder(Vec::new(), 300);
        p.solve(&problem, &mut rec);
        assert_eq!(rec.0, (0..=300).collect::<Vec<_>>());
        assert_eq!(p.counters().collision_checks, counted.counts().is_step_free);
        assert_eq!(p.counters().samples, 300);
        let first = p.roadmap().clone();
        p.solve(&problem, &mut MaxIterations(300));
        assert!(same_roadmap(&first, p.roadmap()), "a second solve repeats the first");
        first
    };
    let (a, b, c) = (run(5), run(5), run(6));
    assert!(same_roadmap(&a, &b));
    assert!(!same_roadmap(&a, &c));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

    #[test]
    fn every_edge_is_free_on_random_scenes(
        patches in strategies::scene(SceneKind::Mixed, 0..6),
        start in strategies::point3(strategies::scene_bounds()),
        goals in proptest::collection::vec(strategies::point3(strategies::scene_bounds()), 1..4),
        tolerance in 0.0..0.5f64,
        seed in any::<u64>(),
    ) {
        let map = BruteForceMap::from_patches(patches).unwrap();
        let space = PlanningSpace::new(strategies::scene_bounds(), RADIUS, 0.8).unwrap();
        let problem = Problem {
            start,
            goals: goals.iter().map(|&center| Goal { center, tolerance }).collect(),
        };
        let mut p = RrtConnect::new(&map, space, seed);
        let status = p.solve(&problem, &mut MaxIterations(60));
        assert_all_free(&map, &p, goals.len());
        let sphere_free = |q: Point3| map.is_step_free(&CapsuleStep::sphere(q, RADIUS).unwrap());
        prop_assert_eq!(status == PlannerStatus::InvalidStart, !sphere_free(start));
        if sphere_free(start) {
            let all_free = goals.iter().all(|&g| sphere_free(g));
            prop_assert_eq!(status == PlannerStatus::InvalidGoal, !all_free);
        }
        prop_assert_eq!(
            status == PlannerStatus::Exact,
            (0..goals.len()).all(|i| p.path_to(i).is_some())
        );
        for (i, goal) in goals.iter().enumerate() {
            if let Some(path) = p.path_to(i) {
                prop_assert_eq!(path[0], start);
                prop_assert!((path.last().unwrap() - goal).norm() <= tolerance + 1e-12);
            }
        }
        let graph = p.roadmap();
        prop_assert!(!is_cyclic_undirected(graph));
        prop_assert!(graph.edge_references().all(|e| *e.weight() <= 0.8 + 1e-12));
        prop_assert!(graph.node_weights().all(|q| space.bounds().contains(q)));
    }
}
