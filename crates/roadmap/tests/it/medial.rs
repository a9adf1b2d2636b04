//! The medial-axis planners on the brute-force reference map: retraction in a corridor,
//! determinism, dropped samples, clearance against the plain PRM, and every edge re-checked
//! free on random scenes.

use patch_core::conformance::SceneKind;
use patch_core::conformance::strategies;
use patch_core::{
    Aabb, BruteForceMap, CapsuleStep, Counted, FromPatches, PlanarPatch, Point3, ProximityQuery,
    Real, UnspecificStepIntersector,
};
use petgraph::algo::is_cyclic_undirected;
use proptest::prelude::*;
use roadmap::{
    Goal, MaPrm, MaPrmConfig, MaRrt, MaRrtConfig, MaxIterations, Planner, PlannerStatus,
    PlanningSpace, Prm, PrmConfig, Problem, Roadmap,
};

use crate::common;
use common::*;

/// The corridor's inside: 10 m long, 2 m wide, 1.5 m high.
fn corridor_box() -> Aabb {
    Aabb::new(Point3::origin(), Point3::new(10.0, 2.0, 1.5))
}

fn space(bounds: Aabb) -> PlanningSpace {
    PlanningSpace::new(bounds, RADIUS, 0.5).unwrap()
}

fn quad(corners: [Point3; 4]) -> PlanarPatch {
    PlanarPatch::from_world_polygon(&corners, &[], 1e-9).unwrap()
}

/// Floor, ceiling and two side walls around [`corridor_box`], open at both ends.
fn corridor() -> BruteForceMap {
    let (x0, x1) = (-1.0, 11.0);
    let p = Point3::new;
    let floor = quad([p(x0, 0.0, 0.0), p(x1, 0.0, 0.0), p(x1, 2.0, 0.0), p(x0, 2.0, 0.0)]);
    let ceiling = quad([p(x0, 0.0, 1.5), p(x1, 0.0, 1.5), p(x1, 2.0, 1.5), p(x0, 2.0, 1.5)]);
    let left = quad([p(x0, 0.0, 0.0), p(x1, 0.0, 0.0), p(x1, 0.0, 1.5), p(x0, 0.0, 1.5)]);
    let right = quad([p(x0, 2.0, 0.0), p(x1, 2.0, 0.0), p(x1, 2.0, 1.5), p(x0, 2.0, 1.5)]);
    BruteForceMap::from_patches([floor.into(), ceiling.into(), left.into(), right.into()]).unwrap()
}

fn along_the_corridor() -> Problem {
    Problem {
        start: Point3::new(0.5, 1.0, 0.75),
        goals: vec![Goal { center: Point3::new(9.5, 1.0, 0.75), tolerance: 0.3 }],
    }
}

/// The corridor's medial axis: equally far from the two closest of its four walls.
fn on_corridor_axis(q: &Point3, tolerance: Real) -> bool {
    let mut d = [q.z, 1.5 - q.z, q.y, 2.0 - q.y];
    d.sort_by(Real::total_cmp);
    d[1] - d[0] <= tolerance
}

#[test]
fn accepts_maps_with_proximity_and_capsule_queries() {
    fn takes<M: ProximityQuery + UnspecificStepIntersector + ?Sized>(
        map: &M,
    ) -> Vec<Box<dyn Planner + '_>> {
        let s = space(corridor_box());
        vec![
            Box::new(MaPrm::new(map, s, MaPrmConfig::for_space(&s), 0)),
            Box::new(MaRrt::new(map, s, MaRrtConfig::for_space(&s), 0)),
        ]
    }
    let map = corridor();
    let counted = Counted::new(corridor());
    let by_ref = &map;
    let mut all = takes(&map);
    all.extend(takes(&counted));
    all.extend(takes(&by_ref));
    for p in &mut all {
        assert_eq!(p.solve(&along_the_corridor(), &mut until_solved(5_000)), PlannerStatus::Exact);
    }
    assert_eq!(all[0].name(), "ma-prm");
    assert_eq!(all[1].name(), "ma-rrt");
}

#[test]
fn ma_prm_vertices_lie_on_the_medial_axis_and_connect_the_corridor() {
    let map = corridor();
    let s = space(corridor_box());
    let config = MaPrmConfig::for_space(&s);
    let problem = along_the_corridor();
    for seed in 0..3 {
        let mut p = MaPrm::new(&map, s, config, seed);
        assert_eq!(p.solve(&problem, &mut until_solved(5_000)), PlannerStatus::Exact);
        assert_all_free(&map, &p, 1);
        let graph = p.roadmap();
        assert!(!is_cyclic_undirected(graph));
        // Every vertex but the start is a retracted sample (no direct goal step).
        for q in graph.node_weights().skip(1) {
            assert!(on_corridor_axis(q, 2.0 * config.retraction_tolerance), "{q} off the axis");
            assert!(s.bounds().contains(q));
        }
        // Samples never leave the corridor through its open ends: none is dropped.
        assert_eq!(p.counters().vertices as u64, p.counters().samples + 1);
    }
}

#[test]
fn ma_rrt_crosses_the_corridor() {
    let map = corridor();
    let s = space(corridor_box());
    for seed in 0..3 {
        let mut p = MaRrt::new(&map, s, MaRrtConfig::for_space(&s), seed);
        assert_eq!(p.solve(&along_the_corridor(), &mut until_solved(5_000)), PlannerStatus::Exact);
        assert_all_free(&map, &p, 1);
        let path = p.path_to(0).unwrap();
        assert_eq!(path[0], along_the_corridor().start);
        assert!(!is_cyclic_undirected(p.roadmap()));
        assert!(p.roadmap().edge_references().all(|e| *e.weight() <= 0.5 + 1e-12));
    }
}

#[test]
fn same_seed_same_roadmap() {
    let map = corridor();
    let s = space(corridor_box());
    let problem = along_the_corridor();
    let mut a = MaPrm::new(&map, s, MaPrmConfig::for_space(&s), 11);
    let mut b = MaPrm::new(&map, s, MaPrmConfig::for_space(&s), 11);
    a.solve(&problem, &mut MaxIterations(300));
    b.solve(&problem, &mut MaxIterations(300));
    assert!(same_roadmap(a.roadmap(), b.roadmap()));
    assert_eq!(a.counters().edges, b.counters().edges);
    let first = a.roadmap().clone();
    a.solve(&problem, &mut MaxIterations(300));
    assert!(same_roadmap(&first, a.roadmap()), "solve starts from the seed again");

    let mut c = MaRrt::new(&map, s, MaRrtConfig::for_space(&s), 11);
    let mut d = MaRrt::new(&map, s, MaRrtConfig::for_space(&s), 11);
    c.solve(&problem, &mut MaxIterations(300));
    d.solve(&problem, &mut MaxIterations(300));
    assert!(same_roadmap(c.roadmap(), d.roadmap()));
    c.clear();
    assert_eq!(c.roadmap().node_count(), 0);
    assert_eq!(c.counters(), Default::default());
}

#[test]
fn dropped_samples_count_as_iterations() {
    // A single floor has no medial axis: every sample is dropped.
    let p = Point3::new;
    let floor =
        quad([p(-1.0, -1.0, 0.0), p(11.0, -1.0, 0.0), p(11.0, 3.0, 0.0), p(-1.0, 3.0, 0.0)]);
    let map = BruteForceMap::from_patches([floor.into()]).unwrap();
    let s = space(corridor_box());
    let problem = along_the_corridor();
    let mut prm = MaPrm::new(&map, s, MaPrmConfig::for_space(&s), 3);
    assert_eq!(prm.solve(&problem, &mut MaxIterations(100)), PlannerStatus::Timeout);
    assert_eq!(prm.counters().samples, 100);
    assert_eq!(prm.counters().vertices, 1);
    let mut rrt = MaRrt::new(&map, s, MaRrtConfig::for_space(&s), 3);
    assert_eq!(rrt.solve(&problem, &mut MaxIterations(100)), PlannerStatus::Timeout);
    assert_eq!((rrt.counters().samples, rrt.counters().vertices), (100, 1));
    // Goal centres chosen by the goal bias are not retracted, so the MA RRT still gets there.
    let mut config = MaRrtConfig::for_space(&s);
    config.rrt.goal_bias = 0.2;
    let mut biased = MaRrt::new(&map, s, config, 3);
    assert_eq!(biased.solve(&problem, &mut until_solved(5_000)), PlannerStatus::Exact);
    assert_all_free(&map, &biased, 1);
}

#[test]
fn ma_prm_vertices_have_more_clearance_than_prm_vertices() {
    let map = corridor();
    let s = space(corridor_box());
    let problem = along_the_corridor();
    let mean_clearance = |graph: &Roadmap| {
        let n = graph.node_count() - 1;
        graph.node_weights().skip(1).map(|q| map.clearance(q, Real::INFINITY)).sum::<Real>()
            / n as Real
    };
    let tolerance = MaPrmConfig::for_space(&s).retraction_tolerance;
    for seed in 0..3 {
        let mut ma = MaPrm::new(&map, s, MaPrmConfig::for_space(&s), seed);
        let mut prm = Prm::new(&map, s, PrmConfig::thesis(), seed);
        ma.solve(&problem, &mut MaxIterations(200));
        prm.solve(&problem, &mut MaxIterations(200));
        // Same seed, same samples before retraction; retraction moves each sample away from
        // its closest wall until another is as close, so its clearance only grows (up to the
        // retraction tolerance: the point returned is within it of the axis).
        for (a, b) in ma.roadmap().node_weights().zip(prm.roadmap().node_weights()) {
            let (ca, cb) = (map.clearance(a, Real::INFINITY), map.clearance(b, Real::INFINITY));
            assert!(ca >= cb - tolerance, "{b} ({cb}) retracted to {a} ({ca})");
        }
        assert!(mean_clearance(ma.roadmap()) > mean_clearance(prm.roadmap()));
    }
}

#[test]
fn closest_patch_queries_are_counted() {
    let counted = Counted::new(corridor());
    let s = space(corridor_box());
    let problem = along_the_corridor();
    let planners: Vec<Box<dyn Planner + '_>> = vec![
        Box::new(MaPrm::new(&counted, s, MaPrmConfig::for_space(&s), 5)),
        Box::new(MaRrt::new(&counted, s, MaRrtConfig::for_space(&s), 5)),
    ];
    for mut p in planners {
        counted.reset_counts();
        p.solve(&problem, &mut MaxIterations(200));
        let (c, seen) = (p.counters(), counted.counts());
        assert_eq!(c.proximity_queries, seen.closest_patch, "{}", p.name());
        assert_eq!(c.collision_checks, seen.is_step_free, "{}", p.name());
        // Each kept sample needs at least the first query, one probe and the bisection.
        assert!(c.proximity_queries >= 3 * (c.vertices as u64 - 1), "{}", p.name());
        assert!(c.proximity_time > std::time::Duration::ZERO);
        // A second solve starts the count again.
        counted.reset_counts();
        p.solve(&problem, &mut MaxIterations(50));
        assert_eq!(p.counters().proximity_queries, counted.counts().closest_patch);
        p.clear();
        assert_eq!(p.counters().proximity_queries, 0);
    }
    // The plain PRM asks none.
    let mut prm = Prm::new(&counted, s, PrmConfig::thesis(), 5);
    prm.solve(&problem, &mut MaxIterations(50));
    assert_eq!(prm.counters().proximity_queries, 0);
}

#[test]
fn invalid_starts_and_goals() {
    let map = corridor();
    let s = space(corridor_box());
    let mut p = MaPrm::new(&map, s, MaPrmConfig::for_space(&s), 0);
    let mut problem = along_the_corridor();
    problem.start.z = 0.1; // the sphere touches the floor
    assert_eq!(p.solve(&problem, &mut MaxIterations(10)), PlannerStatus::InvalidStart);
    let mut problem = along_the_corridor();
    problem.goals[0].center.y = 1.9;
    let mut r = MaRrt::new(&map, s, MaRrtConfig::for_space(&s), 0);
    assert_eq!(r.solve(&problem, &mut MaxIterations(10)), PlannerStatus::InvalidGoal);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn every_edge_is_free_on_random_scenes(
        patches in strategies::scene(SceneKind::Mixed, 0..6),
        start in strategies::point3(strategies::scene_bounds()),
        goal in strategies::point3(strategies::scene_bounds()),
        tolerance in 0.0..0.5f64,
        seed in any::<u64>(),
    ) {
        let map = BruteForceMap::from_patches(patches).unwrap();
        let space = PlanningSpace::new(strategies::scene_bounds(), RADIUS, 0.8).unwrap();
        let problem = Problem { start, goals: vec![Goal { center: goal, tolerance }] };
        let planners: Vec<Box<dyn Planner + '_>> = vec![
            Box::new(MaPrm::new(&map, space, MaPrmConfig::for_space(&space), seed)),
            Box::new(MaRrt::new(&map, space, MaRrtConfig::for_space(&space), seed)),
        ];
        let sphere_free = |q: Point3| map.is_step_free(&CapsuleStep::sphere(q, RADIUS).unwrap());
        for mut p in planners {
            let status = p.solve(&problem, &mut MaxIterations(60));
            assert_all_free(&map, p.as_ref(), 1);
            prop_assert_eq!(status == PlannerStatus::InvalidStart, !sphere_free(start));
            prop_assert_eq!(status == PlannerStatus::Exact, p.path_to(0).is_some());
            if let Some(path) = p.path_to(0) {
                prop_assert_eq!(path[0], start);
                prop_assert!((path.last().unwrap() - goal).norm() <= tolerance + 1e-12);
            }
            let graph = p.roadmap();
            prop_assert!(!is_cyclic_undirected(graph));
            prop_assert!(graph.node_weights().all(|q| space.bounds().contains(q)));
        }
    }
}
