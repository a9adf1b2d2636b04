//! Explored volume (thesis §6.1.1): rasterising capsules into the sparse voxel grid, and the
//! set operations of the congruence tables (Table 6.2).
//!
//! Scene: random 1 m capsules of radius 0.3 m (random start in a 12 × 9 × 4 m box, random
//! direction, seeded) in a grid over that box with `N` = 256 (46.9 mm cells, near the
//! thesis's 38.7 mm) and `N` = 1024 (11.7 mm cells); throughput in capsules per second.
//! `count_not_in` and `union_with` run on two grids of 2,000 such capsules each.
//!
//! Run with `cargo bench -p patchnav-roadmap --bench volume -- --warm-up-time 1 --measurement-time 3`.
//! The 10,000-capsule measurement of the issue is the ignored test `rasterise_lab_scale_timing`
//! in `tests/it/volume.rs`.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_main};
use patch_core::{Point3, Real, Vector3};
use rand::{Rng, SeedableRng};
use roadmap::volume::VoxelGrid;

/// The robot radius.
const RADIUS: Real = 0.3;
/// Capsules per measured batch.
const BATCH: usize = 64;

fn capsules(count: usize, seed: u64) -> Vec<(Point3, Point3)> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    (0..count)
        .map(|_| {
            let a = Point3::new(
                rng.random_range(0.0..12.0),
                rng.random_range(0.0..9.0),
                rng.random_range(0.0..4.0),
            );
            let dir = loop {
                let v = Vector3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                );
                if (1e-3..=1.0).contains(&v.norm()) {
                    break v.normalize();
                }
            };
            (a, a + dir)
        })
        .collect()
}

fn grid(n: u32) -> VoxelGrid {
    VoxelGrid::new(Point3::origin(), Point3::new(12.0, 9.0, 4.0), n).unwrap()
}

fn rasterise(c: &mut Criterion) {
    let mut group = c.benchmark_group("volume/add_capsule");
    group.sample_size(10);
    group.throughput(Throughput::Elements(BATCH as u64));
    let batch = capsules(BATCH, 1);
    for n in [256, 1024] {
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |bench, &n| {
            bench.iter_batched(
                || grid(n),
                |mut g| {
                    for (a, b) in &batch {
                        g.add_capsule(*a, *b, RADIUS).unwrap();
                    }
                    g
                },
                criterion::BatchSize::LargeInput,
            );
        });
    }
    group.finish();
}

fn set_operations(c: &mut Criterion) {
    let mut group = c.benchmark_group("volume/sets");
    group.sample_size(10);
    let [a, b] = [2, 3].map(|seed| {
        let mut g = grid(1024);
        for (p, q) in capsules(2_000, seed) {
            g.add_capsule(p, q, RADIUS).unwrap();
        }
        g
    });
    group.bench_function("count_not_in/1024", |bench| {
        bench.iter(|| black_box(a.count_not_in(&b).unwrap()));
    });
    group.bench_function("union_with/1024", |bench| {
        bench.iter_batched(
            || a.clone(),
            |mut u| {
                u.union_with(&b).unwrap();
                u
            },
            criterion::BatchSize::LargeInput,
        );
    });
    group.finish();
}

/// The criterion group (its generated function has no doc comment of its own).
#[allow(missing_docs)]
mod group {
    criterion::criterion_group!(benches, super::rasterise, super::set_operations);
}

criterion_main!(group::benches);
