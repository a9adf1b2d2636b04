//! Organised-frame extraction (thesis §5.3): plane segmentation by region growing
//! ([`patch_extract::segment`]) and the whole per-scan pipeline (segmentation, α-shape outlines,
//! Douglas–Peucker), on a simulated 640 × 480 range-camera frame of scene-sim's lab (the
//! SR-3000 model widened to VGA, σ = 1 cm, seen from 1 m above the floor looking at the middle
//! of the room, tilted down 15°).
//!
//! * `segment/threads=k`: [`patch_extract::segment_with_threads`] with
//!   [`SegmentConfig::range_camera`] (the seeds computed on k threads; the result is the same).
//! * `extract/<polygonize>`: one scan through [`patch_extract::extract_with_threads`] on one
//!   thread with [`PipelineConfig::range_camera`] and its outlines thinned on the pixel grid
//!   (`thinned`, the preset) or from every point (`thesis`).
//!
//! Run with `cargo bench -p patch-extract --bench organised -- --warm-up-time 1
//! --measurement-time 5`.

use std::hint::black_box;
use std::num::NonZeroUsize;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_main};
use patch_extract::polygonize::PolygonizeConfig;
use patch_extract::{PipelineConfig, SegmentConfig, extract_with_threads, segment_with_threads};
use pointcloud::PointCloud;
use scene_sim::{RangeCamera, RangeCameraConfig, RangeSensor as _};

/// A 640 × 480 frame of the lab, seed 0.
fn frame() -> PointCloud {
    let scene = scene_sim::scene_by_name("lab", 0).expect("the lab scene");
    let camera = RangeCamera::new(RangeCameraConfig {
        width: 640,
        height: 480,
        ..RangeCameraConfig::swissranger_sr3000()
    })
    .expect("a valid camera");
    let body = scene.scan_poses(1, 1.0, 0).into_iter().next().expect("a scan pose");
    let p = body.world_from_sensor.translation.vector;
    let yaw = (4.5 - p.y).atan2(6.0 - p.x);
    let pose = scene_sim::camera_pose_looking(
        pointcloud::Point3::new(p.x, p.y, 1.0),
        yaw,
        -15f64.to_radians(),
    );
    camera.scan(&scene, &pose, 0).to_cloud().expect("a frame")
}

fn bench(c: &mut Criterion) {
    let cloud = frame();
    let points = cloud.len() as u64;

    let mut group = c.benchmark_group("segment");
    group.throughput(Throughput::Elements(points));
    let config = SegmentConfig::range_camera();
    for threads in [1, 2] {
        let t = NonZeroUsize::new(threads).unwrap_or(NonZeroUsize::MIN);
        group.bench_function(BenchmarkId::new("threads", threads), |b| {
            b.iter(|| segment_with_threads(black_box(&cloud), &config, t).expect("valid config"))
        });
    }
    group.finish();

    let mut group = c.benchmark_group("extract");
    group.throughput(Throughput::Elements(points));
    group.sample_size(20);
    let scans = [cloud.clone()];
    for (name, polygonize) in
        [("thinned", PolygonizeConfig::thinned()), ("thesis", PolygonizeConfig::thesis())]
    {
        let config = PipelineConfig { polygonize, ..PipelineConfig::range_camera() };
        group.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter(|| {
                extract_with_threads(black_box(&scans), &config, NonZeroUsize::MIN, |_| {})
                    .expect("valid config")
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
