//! The roadmap's k-d structure (RRT's hot path): `nearest` and `k_nearest(q, 1, ∞)` on 10,000
//! and 100,000 random vertices in a 12 × 9 × 4 m box (seeded), with random queries, and
//! growing the structure to those sizes (`add`).
//!
//! Run with `cargo bench -p patchnav-roadmap --bench nn -- --warm-up-time 1 --measurement-time 3`.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_main};
use patch_core::{Point3, Real};
use rand::{Rng, SeedableRng};
use roadmap::{KdNeighbors, NearestNeighbors};

/// Queries per measured batch.
const BATCH: usize = 256;

fn points(count: usize, seed: u64) -> Vec<Point3> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    (0..count)
        .map(|_| {
            Point3::new(
                rng.random_range(0.0..12.0),
                rng.random_range(0.0..9.0),
                rng.random_range(0.0..4.0),
            )
        })
        .collect()
}

fn nearest(c: &mut Criterion) {
    let mut group = c.benchmark_group("nearest");
    group.throughput(Throughput::Elements(BATCH as u64));
    for n in [10_000, 100_000] {
        let mut nn = KdNeighbors::new();
        for p in points(n, 1) {
            nn.add(p);
        }
        let queries = points(BATCH, 2);
        group.bench_with_input(BenchmarkId::new("nearest", n), &queries, |b, qs| {
            b.iter(|| {
                qs.iter().map(|q| nn.nearest(black_box(q)).map_or(0, |n| n.index)).sum::<usize>()
            })
        });
        group.bench_with_input(BenchmarkId::new("k_nearest-1", n), &queries, |b, qs| {
            b.iter(|| {
                qs.iter()
                    .map(|q| nn.k_nearest(black_box(q), 1, Real::INFINITY)[0].index)
                    .sum::<usize>()
            })
        });
    }
    group.finish();
    let mut group = c.benchmark_group("add");
    group.sample_size(10);
    for n in [10_000, 100_000] {
        group.throughput(Throughput::Elements(n as u64));
        let all = points(n, 1);
        group.bench_with_input(BenchmarkId::new("add", n), &all, |b, all| {
            b.iter(|| {
                let mut nn = KdNeighbors::new();
                for p in all {
                    nn.add(black_box(*p));
                }
                nn.len()
            })
        });
    }
    group.finish();
}

/// The criterion group (its generated function has no doc comment of its own).
#[allow(missing_docs)]
mod group {
    criterion::criterion_group!(benches, super::nearest);
}

criterion_main!(group::benches);
