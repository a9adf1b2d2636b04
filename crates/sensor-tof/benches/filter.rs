//! Frames per second of the per-frame work of the AAT (thesis §2.5.5): the adaptive amplitude
//! threshold, unwrapping and conversion of the output to points, on a 176 × 144 SR-3000 frame
//! and a 640 × 480 frame, beside a plain copy of the frame's range and amplitude images into
//! preallocated buffers (the memory-speed floor: the work's time divided by the copy's says how
//! close to memory speed the filter runs).
//!
//! Run with `cargo bench -p sensor-tof --bench filter -- --warm-up-time 1 --measurement-time 3`.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_main};
use pointcloud::{PinholeIntrinsics, RangeKind};
use rand::{Rng, SeedableRng};
use sensor_tof::{AatConfig, FilterConfig, FilterOutput, Parabola, TofCamera, TofFilter, TofFrame};

/// A frame of `camera`: a random mix of near surfaces and wrapped far ones, amplitudes from the
/// thesis's model `ρ · aw_p / z²` with the SR-3000 parabola stretched to the image.
fn frame(camera: TofCamera, seed: u64) -> TofFrame {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let amb = camera.non_ambiguity_range();
    let p = Parabola {
        delta_x: camera.width as f64 / 2.0,
        delta_y: camera.height as f64 * 61.0 / 144.0,
        curvature: 176.0 * 176.0 / (camera.width as f64).powi(2),
        ..Parabola::sr3000()
    };
    let (mut range, mut amp) = (Vec::new(), Vec::new());
    for row in 0..camera.height {
        for col in 0..camera.width {
            let k = camera.ray(col, row).norm();
            let true_r: f64 = rng.random_range(0.8..14.0);
            let rho: f64 = rng.random_range(0.05..1.0);
            let z = true_r / k;
            range.push((true_r.rem_euclid(amb) / k) as f32);
            amp.push((rho * p.eval(col as f64, row as f64).max(400.0) / (z * z)) as f32);
        }
    }
    TofFrame::new(camera, RangeKind::Depth, range, amp).unwrap()
}

fn bench(c: &mut Criterion) {
    let vga = TofCamera::pinhole(
        640,
        480,
        PinholeIntrinsics::from_fov(640, 480, 60f64.to_radians(), 47f64.to_radians()),
        20e6,
    )
    .unwrap();
    let mut group = c.benchmark_group("aat_unwrap_points");
    for (name, camera) in [("176x144", TofCamera::sr3000()), ("640x480", vga)] {
        let f = frame(camera, 7);
        let n = camera.num_pixels();
        group.throughput(Throughput::Elements(n as u64));
        let filter = TofFilter::new(
            &camera,
            RangeKind::Depth,
            &FilterConfig::aat_unwrap(AatConfig::sr3000(), None),
        )
        .unwrap();
        let mut out = FilterOutput::default();
        let (mut points, mut pixels) = (Vec::with_capacity(n), Vec::with_capacity(n));
        group.bench_function(BenchmarkId::new("filter", name), |b| {
            b.iter(|| {
                filter.apply(black_box(&f), &mut out).unwrap();
                points.clear();
                pixels.clear();
                out.points_into(filter.tables(), &mut points, &mut pixels);
                black_box(points.len())
            })
        });
        let (mut r, mut a) = (vec![0f32; n], vec![0f32; n]);
        group.bench_function(BenchmarkId::new("copy", name), |b| {
            b.iter(|| {
                r.copy_from_slice(black_box(f.range()));
                a.copy_from_slice(black_box(f.amplitude()));
                black_box(r[n - 1] + a[n - 1])
            })
        });
    }
    group.finish();
}

fn benches() {
    let mut c = Criterion::default().configure_from_args();
    bench(&mut c);
}

criterion_main!(benches);
