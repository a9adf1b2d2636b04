//! RRT iterations allocate nothing but the amortised growth of the roadmap and of the
//! nearest-neighbour tree (its own test binary: `allocation-counter` replaces the global
//! allocator, and counts the current thread only).

use roadmap::{MaxIterations, Planner, PlannerStatus, Rrt, RrtConfig};

#[path = "it/common/mod.rs"]
mod common;

#[test]
fn rrt_iterations_allocate_only_to_grow() {
    let map = common::wall_with_door();
    let problem = common::across(0.3);
    let mut rrt = Rrt::new(&map, common::space(0.5), RrtConfig::thesis(), 3);
    let iterations = 20_000u64;
    let mut status = PlannerStatus::Timeout;
    let info = allocation_counter::measure(|| {
        status = rrt.solve(&problem, &mut MaxIterations(iterations));
    });
    assert_eq!(status, PlannerStatus::Exact);
    let vertices = rrt.counters().vertices as u64;
    // Growth: doubling vectors (a few dozen reallocations), and one new leaf per leaf split
    // of the nearest-neighbour tree (a leaf splits every 12 or so added vertices).
    let allowed = 100 + vertices / 8;
    println!(
        "{iterations} iterations, {vertices} vertices: {} allocations ({:.4} per iteration)",
        info.count_total,
        info.count_total as f64 / iterations as f64
    );
    assert!(info.count_total <= allowed, "{} allocations > {allowed}", info.count_total);
}
