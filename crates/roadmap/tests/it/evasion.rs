//! The Evasion RRT on the brute-force reference map: outcomes, determinism, evasion, its
//! relation to the RRT, and every edge re-checked free.

use patch_core::conformance::SceneKind;
use patch_core::conformance::strategies;
use patch_core::{
    BruteForceMap, CapsuleStep, Counted, FromPatches, PlanarPatch, Point3, ProximityQuery, Real,
    SpecificStepIntersector, UnspecificStepIntersector,
};
use petgraph::algo::is_cyclic_undirected;
use petgraph::visit::EdgeRef;
use proptest::prelude::*;
use roadmap::{
    EvasionRrt, EvasionRrtConfig, Goal, GoalStep, MaxIterations, Planner, PlannerStatus,
    PlanningSpace, Problem, Roadmap, Rrt, RrtConfig,
};

use crate::common;
use common::*;

fn quad(corners: [Point3; 4], holes: Vec<Vec<Point3>>) -> PlanarPatch {
    PlanarPatch::from_world_polygon(&corners, &holes, 1e-9).unwrap()
}

/// A 1.2 m × 1.2 m plate at x = 3 in the middle of the room, across the straight line.
fn plate() -> BruteForceMap {
    let x = 3.0;
    let outer = [
        Point3::new(x, 1.4, 0.65),
        Point3::new(x, 2.6, 0.65),
        Point3::new(x, 2.6, 1.85),
        Point3::new(x, 1.4, 1.85),
    ];
    BruteForceMap::from_patches([quad(outer, vec![]).into()]).unwrap()
}

fn config(space: &PlanningSpace) -> EvasionRrtConfig {
    EvasionRrtConfig::for_space(space)
}

/// The planner accepts maps with the specific capsule query (the negative case, a map with
/// only the unspecific query, does not compile; see the `EvasionRrt` docs).
#[test]
fn accepts_specific_intersectors() {
    fn assert_impl<M: SpecificStepIntersector + ?Sized>(_: &M) {}
    let map = BruteForceMap::new();
    let counted = Counted::new(BruteForceMap::new());
    assert_impl(&map);
    assert_impl(&counted);
    assert_impl(&&map);
    let dynamic: &dyn SpecificStepIntersector = &map;
    let mut p = EvasionRrt::new(dynamic, space(0.5), config(&space(0.5)), 0);
    assert_eq!(p.solve(&across(0.3), &mut until_solved(5_000)), PlannerStatus::Exact);
    assert_eq!(p.name(), "evasion-rrt");
}

#[test]
fn crosses_the_room_and_finds_the_door() {
    let problem = across(0.3);
    for map in [BruteForceMap::new(), wall_with_door(), plate()] {
        for seed in 0..3 {
            let mut p = EvasionRrt::new(&map, space(0.5), config(&space(0.5)), seed);
            assert_eq!(p.solve(&problem, &mut until_solved(20_000)), PlannerStatus::Exact);
            let path = p.path_to(0).unwrap();
            assert_eq!(path[0], problem.start);
            assert!((path.last().unwrap() - problem.goals[0].center).norm() <= 0.3);
            assert_all_free(&map, &p, 1);
            assert!(!is_cyclic_undirected(p.roadmap()));
        }
    }
}

#[test]
fn same_seed_same_roadmap() {
    let map = plate();
    let problem = across(0.3);
    let run = |seed: u64| {
        let mut p = EvasionRrt::new(&map, space(0.5), config(&space(0.5)), seed);
        p.solve(&problem, &mut MaxIterations(500));
        let first = (p.roadmap().clone(), p.evaded_vertices());
        p.solve(&problem, &mut MaxIterations(500));
        assert!(same_roadmap(&first.0, p.roadmap()), "a second solve repeats the first");
        assert_eq!(first.1, p.evaded_vertices());
        first
    };
    let (a, b, c) = (run(3), run(3), run(4));
    assert!(same_roadmap(&a.0, &b.0) && a.1 == b.1);
    assert!(!same_roadmap(&a.0, &c.0));
}

/// Without shifts the Evasion RRT is the RRT: same seed, same roadmap.
#[test]
fn without_evasion_it_is_the_rrt() {
    let problem = across(0.3);
    for map in [wall_with_door(), plate()] {
        for seed in 0..3 {
            let mut rrt = Rrt::new(&map, space(0.5), RrtConfig::thesis(), seed);
            rrt.solve(&problem, &mut MaxIterations(400));
            for cfg in [
                EvasionRrtConfig { max_evasions: 0, ..config(&space(0.5)) },
                EvasionRrtConfig { evasion_step: 0.0, ..config(&space(0.5)) },
            ] {
                let mut ev = EvasionRrt::new(&map, space(0.5), cfg, seed);
                ev.solve(&problem, &mut MaxIterations(400));
                assert!(same_roadmap(rrt.roadmap(), ev.roadmap()));
                assert_eq!(ev.evaded_vertices(), 0);
                assert_eq!(ev.counters().collision_checks, rrt.counters().collision_checks);
            }
        }
    }
}

#[test]
fn collisions_are_evaded_along_the_plate() {
    let map = plate();
    let problem = across(0.3);
    let cfg = config(&space(0.5));
    let bound = (0.5 as Real).hypot(Real::from(cfg.max_evasions) * cfg.evasion_step) + 1e-9;
    for seed in 0..4 {
        let mut p = EvasionRrt::new(&map, space(0.5), cfg, seed);
        p.solve(&problem, &mut MaxIterations(2_000));
        assert!(p.evaded_vertices() > 0, "seed {seed}: no vertex came from an evasion");
        assert_all_free(&map, &p, 1);
        let graph = p.roadmap();
        let longest = graph.edge_references().map(|e| *e.weight()).fold(0.0, Real::max);
        assert!(longest > 0.5 + 1e-9, "an evaded edge is longer than the step");
        assert!(longest <= bound);
        assert_eq!(graph.edge_count(), graph.node_count() - 1);
    }
}

/// Vertices gather near obstacles (thesis §5.5.1): on the plate scene, the mean clearance of
/// the vertices is lower than the RRT's with the same seed and iterations. The two share the
/// random stream, so most vertices coincide and the difference comes from the evasions; the
/// assertion is per seed for at least 7 of 8 seeds and for the mean over them.
#[test]
fn vertices_gather_near_obstacles() {
    let map = plate();
    let problem = Problem { start: across(0.3).start, goals: vec![] };
    let mean_clearance = |g: &Roadmap| {
        let sum: Real = g.node_weights().map(|p| map.clearance(p, Real::INFINITY)).sum();
        sum / g.node_count() as Real
    };
    let (mut closer, mut rrt_sum, mut ev_sum) = (0, 0.0, 0.0);
    for seed in 0..8 {
        let mut rrt = Rrt::new(&map, space(0.5), RrtConfig::thesis(), seed);
        rrt.solve(&problem, &mut MaxIterations(1_000));
        let mut ev = EvasionRrt::new(&map, space(0.5), config(&space(0.5)), seed);
        ev.solve(&problem, &mut MaxIterations(1_000));
        let (a, b) = (mean_clearance(rrt.roadmap()), mean_clearance(ev.roadmap()));
        closer += usize::from(b < a);
        rrt_sum += a;
        ev_sum += b;
    }
    assert!(closer >= 7, "evasion closer to the plate for only {closer}/8 seeds");
    assert!(ev_sum < rrt_sum);
}

#[test]
fn counters_count_specific_checks() {
    let counted = Counted::new(plate());
    let problem = across(0.3);
    for direct in [false, true] {
        counted.reset_counts();
        let mut cfg = config(&space(0.5));
        cfg.rrt.goal_step = if direct { GoalStep::Direct } else { GoalStep::Grown };
        let mut p = EvasionRrt::new(&counted, space(0.5), cfg, 2);
        p.solve(&problem, &mut MaxIterations(300));
        let c = p.counters();
        let counts = counted.counts();
        assert_eq!(c.collision_checks, counts.step_checks());
        assert!(counts.first_hit >= 300 - 1);
        assert_eq!(c.samples, 300);
        assert_eq!(c.vertices, p.roadmap().node_count());
        assert_eq!(c.edges, c.vertices - 1);
        p.clear();
        assert_eq!(p.roadmap().node_count(), 0);
        assert_eq!((p.counters().collision_checks, p.evaded_vertices()), (0, 0));
    }
}

#[test]
fn invalid_starts_and_goals() {
    let map = wall_with_door();
    let goal = Goal { center: Point3::new(5.0, 2.0, 1.25), tolerance: 0.3 };
    let mut p = EvasionRrt::new(&map, space(0.5), config(&space(0.5)), 0);
    for start in [Point3::new(2.9, 3.0, 1.25), Point3::new(-1.0, 2.0, 1.0)] {
        let problem = Problem { start, goals: vec![goal] };
        assert_eq!(p.solve(&problem, &mut MaxIterations(10)), PlannerStatus::InvalidStart);
        assert_eq!(p.roadmap().node_count(), 0);
    }
    let bad = Goal { center: Point3::new(3.1, 3.0, 1.25), tolerance: 0.3 };
    let problem = Problem { start: across(0.3).start, goals: vec![goal, bad] };
    assert_eq!(p.solve(&problem, &mut MaxIterations(10)), PlannerStatus::InvalidGoal);
    assert_eq!(p.solve(&across(0.3), &mut MaxIterations(0)), PlannerStatus::Timeout);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn every_edge_is_free_on_random_planar_scenes(
        patches in strategies::scene(SceneKind::PlanarOnly, 0..6),
        start in strategies::point3(strategies::scene_bounds()),
        goal in strategies::point3(strategies::scene_bounds()),
        seed in any::<u64>(),
        lesum in any::<bool>(),
        evasion_step in 0.05..0.6f64,
        max_evasions in 0..12u32,
    ) {
        let map = BruteForceMap::from_patches(patches).unwrap();
        let space = PlanningSpace::new(strategies::scene_bounds(), RADIUS, 0.8).unwrap();
        let problem = Problem { start, goals: vec![Goal { center: goal, tolerance: 0.25 }] };
        let rrt = if lesum { RrtConfig::lesum(Some(1e4)) } else { RrtConfig::thesis() };
        let cfg = EvasionRrtConfig { rrt, evasion_step, max_evasions };
        let mut p = EvasionRrt::new(&map, space, cfg, seed);
        let status = p.solve(&problem, &mut MaxIterations(60));
        assert_all_free(&map, &p, 1);
        let sphere_free = |q: Point3| map.is_step_free(&CapsuleStep::sphere(q, RADIUS).unwrap());
        prop_assert_eq!(status == PlannerStatus::InvalidStart, !sphere_free(start));
        prop_assert_eq!(status == PlannerStatus::Exact, p.path_to(0).is_some());
        let graph = p.roadmap();
        let bound = (0.8 as Real).hypot(Real::from(max_evasions) * evasion_step) + 1e-9;
        for e in graph.edge_references() {
            let goal_edge = lesum && graph[e.target()] == goal;
            prop_assert!(goal_edge || *e.weight() <= bound, "edge {} > {}", e.weight(), bound);
        }
        if graph.node_count() > 0 {
            prop_assert_eq!(graph.edge_count(), graph.node_count() - 1);
            prop_assert!(graph.node_weights().all(|q| space.bounds().contains(q)));
        }
        prop_assert!(p.evaded_vertices() <= graph.node_count());
    }

    /// Hits on trimesh patches end the evasion at once: on trimesh-only scenes the Evasion
    /// RRT builds the RRT's roadmap.
    #[test]
    fn trimesh_hits_are_not_evaded(
        patches in strategies::scene(SceneKind::TrimeshOnly, 1..5),
        start in strategies::point3(strategies::scene_bounds()),
        seed in any::<u64>(),
    ) {
        let map = BruteForceMap::from_patches(patches).unwrap();
        let space = PlanningSpace::new(strategies::scene_bounds(), RADIUS, 0.8).unwrap();
        let problem = Problem { start, goals: vec![] };
        let mut rrt = Rrt::new(&map, space, RrtConfig::thesis(), seed);
        rrt.solve(&problem, &mut MaxIterations(60));
        let mut ev = EvasionRrt::new(&map, space, EvasionRrtConfig::for_space(&space), seed);
        ev.solve(&problem, &mut MaxIterations(60));
        prop_assert!(same_roadmap(rrt.roadmap(), ev.roadmap()));
        prop_assert_eq!(ev.evaded_vertices(), 0);
    }
}
