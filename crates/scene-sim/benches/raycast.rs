//! Ray-casting throughput: a full-resolution actuated-LRF scan of the lab (541 × 361 =
//! 195,301 beams, with and without mixed pixels), an SR-3000 range-camera scan and a STOC
//! stereo scan, plus the bare ray casting of the ALRF grid.
//!
//! Run with `cargo bench -p scene-sim -- --warm-up-time 1 --measurement-time 3`.

use criterion::{Criterion, Throughput, criterion_main};
use scene_sim::{
    Alrf, AlrfConfig, RangeCamera, RangeSensor, StereoCamera, camera_pose_from_body, lab,
    trace_image,
};
use std::hint::black_box;

fn scans(c: &mut Criterion) {
    let scene = lab(1).expect("lab scene");
    let body = scene.scan_poses(1, 0.5, 1)[0];
    let camera = camera_pose_from_body(&body);
    let mut g = c.benchmark_group("lab");
    g.sample_size(10);

    let alrf = Alrf::sick_s300();
    let cfg = *alrf.config();
    let beams = u64::from(cfg.columns) * u64::from(cfg.rows);
    g.throughput(Throughput::Elements(beams));
    g.bench_function("alrf_trace_only", |b| {
        b.iter(|| {
            trace_image(&scene, black_box(&body), &cfg.beam_model(), cfg.columns, cfg.rows, 20.0)
        })
    });
    g.bench_function("alrf_sick_s300", |b| b.iter(|| alrf.scan(&scene, black_box(&body), 1)));
    let plain = Alrf::new(AlrfConfig { mixed_pixels: None, ..cfg }).expect("config");
    g.bench_function("alrf_no_mixed_pixels", |b| {
        b.iter(|| plain.scan(&scene, black_box(&body), 1))
    });

    let sr = RangeCamera::swissranger_sr3000();
    let c = sr.config();
    g.throughput(Throughput::Elements(u64::from(c.width) * u64::from(c.height)));
    g.bench_function("range_camera_sr3000", |b| b.iter(|| sr.scan(&scene, black_box(&camera), 1)));

    let stoc = StereoCamera::stoc();
    let c = stoc.config();
    g.throughput(Throughput::Elements(u64::from(c.width) * u64::from(c.height)));
    g.bench_function("stereo_stoc", |b| b.iter(|| stoc.scan(&scene, black_box(&camera), 1)));
    g.finish();
}

/// The criterion group (its generated function has no doc comment of its own).
#[allow(missing_docs)]
mod group {
    criterion::criterion_group!(benches, super::scans);
}

criterion_main!(group::benches);
