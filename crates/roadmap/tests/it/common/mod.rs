//! Scenes, problems and checks shared by the planner tests.
#![allow(dead_code)] // each test binary uses a different subset

use patch_core::{
    Aabb, BruteForceMap, CapsuleStep, FromPatches, PlanarPatch, Point3, Real,
    UnspecificStepIntersector,
};
use petgraph::visit::EdgeRef;
use roadmap::{AnyOf, Goal, GoalReached, MaxIterations, Planner, PlanningSpace, Problem, Roadmap};

/// The robot radius of every test.
pub const RADIUS: Real = 0.2;

/// A 6 m × 4 m × 2.5 m box.
pub fn room() -> Aabb {
    Aabb::new(Point3::origin(), Point3::new(6.0, 4.0, 2.5))
}

/// The room as a planning space with the given longest step.
pub fn space(max_step: Real) -> PlanningSpace {
    PlanningSpace::new(room(), RADIUS, max_step).unwrap()
}

/// A wall at x = 3 filling the room's cross-section, with a 1 m × 1.5 m opening off the
/// straight line of [`across`].
pub fn wall_with_door() -> BruteForceMap {
    let x = 3.0;
    let outer = [
        Point3::new(x, 0.0, 0.0),
        Point3::new(x, 4.0, 0.0),
        Point3::new(x, 4.0, 2.5),
        Point3::new(x, 0.0, 2.5),
    ];
    let hole = vec![
        Point3::new(x, 0.5, 0.5),
        Point3::new(x, 1.5, 0.5),
        Point3::new(x, 1.5, 2.0),
        Point3::new(x, 0.5, 2.0),
    ];
    let wall = PlanarPatch::from_world_polygon(&outer, &[hole], 1e-9).unwrap();
    BruteForceMap::from_patches([wall.into()]).unwrap()
}

/// From one side of the room to the other, straight through the wall of [`wall_with_door`].
pub fn across(tolerance: Real) -> Problem {
    Problem {
        start: Point3::new(1.0, 2.0, 1.25),
        goals: vec![Goal { center: Point3::new(5.0, 2.0, 1.25), tolerance }],
    }
}

/// Stop when every goal is reached or after `k` iterations.
pub fn until_solved(k: u64) -> AnyOf<GoalReached, MaxIterations> {
    AnyOf(GoalReached, MaxIterations(k))
}

/// Every roadmap edge and every edge of the paths to the first `goals` goals is free (by the
/// brute-force map), and every edge weight is the edge's length.
pub fn assert_all_free(map: &BruteForceMap, planner: &dyn Planner, goals: usize) {
    let graph = planner.roadmap();
    for e in graph.edge_references() {
        let (a, b) = (graph[e.source()], graph[e.target()]);
        let step = CapsuleStep::new(a, b, RADIUS).unwrap();
        assert!(map.is_step_free(&step), "roadmap edge {a} → {b} collides");
        assert!((e.weight() - (b - a).norm()).abs() < 1e-12, "edge weight is its length");
    }
    for g in 0..goals {
        if let Some(path) = planner.path_to(g) {
            for w in path.windows(2) {
                let step = CapsuleStep::new(w[0], w[1], RADIUS).unwrap();
                assert!(map.is_step_free(&step), "path edge {} → {} collides", w[0], w[1]);
            }
        }
    }
}

/// Whether two roadmaps have the same vertices and edges in the same order.
pub fn same_roadmap(a: &Roadmap, b: &Roadmap) -> bool {
    let nodes = a.node_weights().eq(b.node_weights());
    let edges = a
        .edge_references()
        .map(|e| (e.source(), e.target(), *e.weight()))
        .eq(b.edge_references().map(|e| (e.source(), e.target(), *e.weight())));
    nodes && edges
}

/// The roadmap is one tree: connected, acyclic, `n − 1` edges (or empty).
pub fn assert_tree(graph: &Roadmap) {
    let n = graph.node_count();
    if n == 0 {
        assert_eq!(graph.edge_count(), 0);
        return;
    }
    assert_eq!(graph.edge_count(), n - 1, "a tree has n − 1 edges");
    assert_eq!(petgraph::algo::connected_components(graph), 1, "a tree is connected");
}
