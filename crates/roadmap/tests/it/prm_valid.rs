//! The PRM on valid samples with cycles (`PrmConfig::valid`, planner `prm-valid`): every vertex
//! is free, the roadmap has cycles, paths are no longer than the thesis PRM's on the same
//! samples, and runs are deterministic.

use patch_core::{BruteForceMap, CapsuleStep, Counted, UnspecificStepIntersector};
use petgraph::algo::is_cyclic_undirected;
use roadmap::{MaxIterations, PathMetrics, Planner, PlannerStatus, Prm, PrmConfig, PrmConnections};

use crate::common;
use common::*;

/// Whether the robot's sphere at `p` touches the map.
fn sphere_free(map: &BruteForceMap, p: &patch_core::Point3) -> bool {
    map.is_step_free(&CapsuleStep::new(*p, *p, RADIUS).unwrap())
}

#[test]
fn only_free_samples_become_vertices_and_the_thesis_prm_keeps_colliding_ones() {
    let map = wall_with_door();
    let problem = across(0.3);
    let mut valid = Prm::new(&map, space(0.5), PrmConfig::valid(), 4);
    valid.solve(&problem, &mut MaxIterations(1_500));
    assert_eq!(valid.name(), "prm-valid");
    let g = valid.roadmap();
    assert!(g.node_weights().all(|p| sphere_free(&map, p)), "a colliding sample was added");
    assert!(is_cyclic_undirected(g), "edges to all neighbours close cycles");
    assert_all_free(&map, &valid, 1);
    // Dropped samples still count as iterations.
    let c = valid.counters();
    assert_eq!(c.samples, 1_500);
    assert!(c.vertices < 1_500, "{} vertices from 1500 samples near a wall", c.vertices);

    let mut thesis = Prm::new(&map, space(0.5), PrmConfig::thesis(), 4);
    thesis.solve(&problem, &mut MaxIterations(1_500));
    let colliding = thesis.roadmap().node_weights().filter(|p| !sphere_free(&map, p)).count();
    assert!(colliding > 0, "the thesis PRM adds unchecked samples (spec §4)");
    assert!(!is_cyclic_undirected(thesis.roadmap()));
}

#[test]
fn cycles_alone_shorten_paths_on_the_same_samples() {
    // Without sample checks both PRMs see the same vertices; only the edges differ, so the
    // roadmap with cycles is a supergraph of the forest and its shortest path cannot be longer.
    let map = wall_with_door();
    let problem = across(0.3);
    let mut longer = 0;
    for seed in 0..6 {
        let mut forest = Prm::new(&map, space(0.5), PrmConfig::thesis(), seed);
        let cycles = PrmConfig { connections: PrmConnections::Cycles, ..PrmConfig::thesis() };
        let mut with_cycles = Prm::new(&map, space(0.5), cycles, seed);
        forest.solve(&problem, &mut MaxIterations(800));
        with_cycles.solve(&problem, &mut MaxIterations(800));
        assert!(forest.roadmap().node_weights().eq(with_cycles.roadmap().node_weights()));
        assert!(with_cycles.roadmap().edge_count() >= forest.roadmap().edge_count());
        let (Some(a), Some(b)) = (forest.path_to(0), with_cycles.path_to(0)) else {
            continue;
        };
        let (la, lb) = (PathMetrics::of(&a).length, PathMetrics::of(&b).length);
        assert!(lb <= la + 1e-9, "seed {seed}: {lb} > {la}");
        longer += usize::from(lb < la - 1e-6);
    }
    assert!(longer > 0, "cycles shortened no path in six seeds");
}

#[test]
fn same_seed_same_roadmap_and_solves_the_door() {
    let map = wall_with_door();
    let problem = across(0.3);
    let run = |seed| {
        let counted = Counted::new(&map);
        let mut prm = Prm::new(&counted, space(0.5), PrmConfig::valid(), seed);
        let status = prm.solve(&problem, &mut until_solved(20_000));
        (status, prm.roadmap().clone())
    };
    for seed in 0..3 {
        let (s1, r1) = run(seed);
        let (s2, r2) = run(seed);
        assert_eq!(s1, PlannerStatus::Exact, "seed {seed}");
        assert_eq!(s1, s2);
        assert!(same_roadmap(&r1, &r2), "seed {seed}: roadmaps differ");
    }
}
