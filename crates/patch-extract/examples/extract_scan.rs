//! Extracts planar patches from a scan: one simulated actuated-LRF scan of the lab (or a
//! point cloud file given as argument, any format `pointcloud` reads, best an organised scan
//! in its sensor frame with its pose, as the fixtures are), run through `extract` with
//! `PipelineConfig::alrf()`. Prints the planar patches, the points in planes and the time.
//!
//! ```sh
//! cargo run -p patch-extract --example extract_scan
//! cargo run -p patch-extract --example extract_scan -- fixtures/lab-alrf-2deg.ply
//! ```

use patch_extract::projection::{AlrfSideColumns, invalidate_alrf_side_columns};
use patch_extract::{PipelineConfig, extract};
use pointcloud::io::{ReadOptions, read_cloud};
use pointcloud::{BeamModel, PointCloud};
use scene_sim::{Alrf, AlrfConfig, RangeSensor};
use std::path::Path;

/// One scan of the lab at 2° steps from a pose 0.6 m up; the ±90° columns, which the tilting
/// scanner sees edge-on, are dropped first (thesis App. A).
fn lab_scan() -> Result<PointCloud, Box<dyn std::error::Error>> {
    let scene = scene_sim::lab(1)?;
    let robot = scene.scan_poses(1, 0.6, 1)[0];
    let alrf = Alrf::new(AlrfConfig::sick_s300_with_step(2f64.to_radians())?)?;
    let scan = alrf.scan(&scene, &alrf.mount(&robot), 1);
    let BeamModel::ActuatedLrf(model) = scan.image.beams() else {
        return Err("an ALRF scan has an actuated-LRF beam model".into());
    };
    Ok(invalidate_alrf_side_columns(&scan.to_cloud()?, model, &AlrfSideColumns::thesis())?.0)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let scan = match std::env::args().nth(1) {
        Some(path) => read_cloud(Path::new(&path), &ReadOptions::SKIP_NON_FINITE)?,
        None => lab_scan()?,
    };
    let out = extract(std::slice::from_ref(&scan), &PipelineConfig::alrf(), |_| {})?;
    let report = &out.scans[0];
    let planar = out.patches.iter().filter(|p| p.as_planar().is_some()).count();
    println!(
        "{planar} planar patches; {} of {} points in planes ({:.1} %); {:.2} s",
        report.region_points,
        report.points,
        100.0 * report.region_points as f64 / report.points.max(1) as f64,
        out.times.total().as_secs_f64()
    );
    Ok(())
}
