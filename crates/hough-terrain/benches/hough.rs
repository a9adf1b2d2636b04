//! Votes per second and frames per second of Algorithm 2 (+3) at the thesis's resolutions
//! (45°, 15°, 9°) on a full 176 × 144 range-camera frame (25,344 points) and a 72,000-point
//! stereo-like frame: fast serial, fast on 2 threads, and the literal transcription.
//!
//! `cargo bench -p hough-terrain --bench hough -- --quick`

use criterion::{BenchmarkId, Criterion, Throughput, criterion_main};
use hough_terrain::{
    Accumulator, HoughClassifier, HoughConfig, HoughSpace, NormalTable, SensorAxes, SensorMount,
    vote_literal,
};
use nalgebra::Point3;
use pointcloud::SensorPose;
use scene_sim::{RangeCamera, RangeSensor, StereoCamera, TerrainSpec, terrain};
use std::hint::black_box;

const HEIGHT: f64 = 0.45;
const PITCH_DEG: f64 = 25.0;

fn mount() -> SensorMount {
    SensorMount::looking_ahead(HEIGHT, PITCH_DEG.to_radians(), 0.0, SensorAxes::Optical).unwrap()
}

/// Sensor-frame points: the SR-3000 sees a 20° ramp 2 m ahead, every pixel valid; the STOC the
/// same scene, its points thinned to 72,000.
fn frames() -> Vec<(&'static str, Vec<Point3<f64>>)> {
    let scene =
        terrain(&TerrainSpec::Ramp { pitch: 20f64.to_radians(), roll: 0.0, distance: 2.0 }, 1)
            .unwrap();
    let body = SensorPose::from_position_rpy(
        Point3::new(0.0, 0.0, HEIGHT),
        0.0,
        PITCH_DEG.to_radians(),
        0.0,
    );
    let sr = RangeCamera::swissranger_sr3000();
    let sr_points = sr.scan(&scene, &sr.mount(&body), 1).to_cloud().unwrap().positions().to_vec();
    assert_eq!(sr_points.len(), 25_344, "every SR pixel valid");
    let stoc = StereoCamera::stoc();
    let all = stoc.scan(&scene, &stoc.mount(&body), 1).to_cloud().unwrap().positions().to_vec();
    let step = all.len() as f64 / 72_000.0;
    assert!(step >= 1.0, "{} stereo points", all.len());
    let stereo: Vec<_> = (0..72_000).map(|i| all[(i as f64 * step) as usize]).collect();
    vec![("sr-25344", sr_points), ("stereo-72000", stereo)]
}

fn voting(c: &mut Criterion) {
    let m = mount();
    for (name, points) in frames() {
        let levelled: Vec<_> = points.iter().map(|p| m.to_levelled(p)).collect();
        let mut group = c.benchmark_group(format!("vote/{name}"));
        group.sample_size(10);
        for res in [45.0, 15.0, 9.0] {
            let space = HoughSpace::thesis_degrees(res).unwrap();
            let votes = (levelled.len() * space.angle_pairs()) as u64;
            group.throughput(Throughput::Elements(votes));
            let table = NormalTable::new(&space);
            let mut acc = Accumulator::new(space);
            group.bench_with_input(BenchmarkId::new("fast", res), &levelled, |b, pts| {
                b.iter(|| {
                    acc.clear();
                    table.vote(black_box(pts), &mut acc).unwrap();
                })
            });
            let mut partials = Vec::new();
            group.bench_with_input(BenchmarkId::new("fast-2-threads", res), &levelled, |b, pts| {
                b.iter(|| {
                    acc.clear();
                    table.vote_parallel(black_box(pts), &mut acc, &mut partials, 2).unwrap();
                })
            });
            group.bench_with_input(BenchmarkId::new("literal", res), &levelled, |b, pts| {
                b.iter(|| vote_literal(&space, black_box(pts)).unwrap())
            });
        }
        group.finish();
    }
}

fn frames_per_second(c: &mut Criterion) {
    for (name, points) in frames() {
        let mut group = c.benchmark_group(format!("classify/{name}"));
        group.sample_size(10);
        group.throughput(Throughput::Elements(1));
        for res in [45.0f64, 15.0, 9.0] {
            let mut classifier =
                HoughClassifier::new(HoughConfig::thesis(res.to_radians(), mount()).unwrap())
                    .unwrap();
            group.bench_with_input(BenchmarkId::new("serial", res), &points, |b, pts| {
                b.iter(|| classifier.classify(black_box(pts)).unwrap())
            });
        }
        group.finish();
    }
}

/// The criterion group (its generated function has no doc comment of its own).
#[allow(missing_docs)]
mod group {
    criterion::criterion_group!(benches, super::voting, super::frames_per_second);
}
criterion_main!(group::benches);
