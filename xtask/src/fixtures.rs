//! The committed fixtures: small files made by our own simulator, byte-for-byte reproducible.
//!
//! | file | what |
//! |---|---|
//! | `lab-alrf-2deg.ply` | the `lab` scene (seed 1) scanned by the actuated laser range finder at 2° steps (136 × 91 beams), binary PLY, organised, labels = surface ids, sensor pose in the header |
//! | `lab-tof.pcd` | the `lab` scene seen by the range camera (176 × 144, depth), PCD `binary_compressed`, organised |
//! | `lab-tof-depth.png` | the same frame as a 16-bit depth PNG in millimetres |
//! | `lab-tof-depth_intrinsics.json` | its pinhole intrinsics (the sidecar `pointcloud::io::read_cloud` looks for) |
//! | `terrain-ramp-stereo.bin` | a 15° ramp seen by the stereo camera (every fourth row and column), KITTI-style float32 records (unorganised, camera optical frame) |
//! | `lab-alrf-2deg.3d`, `lab-alrf-2deg.pose` | the ALRF scan in 3DTK's format (cm, left-handed) with its pose |
//!
//! Tests read these files, and `fixtures_are_current` regenerates them and compares bytes, so a
//! change to a writer or to the simulator shows up as a stale fixture.

use anyhow::{Context, Result};
use pointcloud::PointCloud;
use pointcloud::io::Precision;
use pointcloud::io::depth_png::write_depth_png;
use pointcloud::io::kitti::write_kitti_bin;
use pointcloud::io::pcd::{PcdEncoding, PcdWriteOptions, write_pcd};
use pointcloud::io::ply::{PlyEncoding, PlyWriteOptions, write_ply};
use pointcloud::io::uos::{write_uos_pose, write_uos_scan};
use scene_sim::{Alrf, AlrfConfig, RangeCamera, RangeSensor, StereoCamera, scene_by_name};
use std::path::Path;

/// One fixture: its file name and its bytes.
type Fixture = (&'static str, Vec<u8>);

const SEED: u64 = 1;
const SENSOR_HEIGHT: f64 = 0.6;

/// Makes every fixture in memory.
pub fn generate() -> Result<Vec<Fixture>> {
    let lab = scene_by_name("lab", SEED)?;
    let body = *lab.scan_poses(1, SENSOR_HEIGHT, SEED).first().context("no pose in the lab")?;

    let alrf = Alrf::new(AlrfConfig::sick_s300_with_step(2f64.to_radians())?)?;
    let alrf_cloud = alrf.scan(&lab, &alrf.mount(&body), SEED).to_cloud()?;
    let mut ply = Vec::new();
    let ply_options =
        PlyWriteOptions { encoding: PlyEncoding::BinaryLittleEndian, precision: Precision::F32 };
    write_ply(&mut ply, &alrf_cloud, &ply_options)?;
    let mut uos = Vec::new();
    write_uos_scan(&mut uos, &alrf_cloud)?;
    let mut uos_pose = Vec::new();
    write_uos_pose(&mut uos_pose, alrf_cloud.sensor_pose().context("scan without pose")?)?;

    let tof = RangeCamera::swissranger_sr3000();
    let tof_scan = tof.scan(&lab, &tof.mount(&body), SEED);
    let mut pcd = Vec::new();
    let pcd_options =
        PcdWriteOptions { encoding: PcdEncoding::BinaryCompressed, precision: Precision::F32 };
    write_pcd(&mut pcd, &tof_scan.to_cloud()?, &pcd_options)?;
    let mut png = Vec::new();
    write_depth_png(&mut png, &tof_scan.image, 0.001)?;
    let k = tof.config().intrinsics();
    let intrinsics = serde_json::json!({
        "fx": k.fx, "fy": k.fy, "cx": k.cx, "cy": k.cy,
        "width": tof_scan.image.width(), "height": tof_scan.image.height(),
        "depth_scale": 0.001,
        "note": "simulated range camera of the lab scene; depth PNG holds z in millimetres, 0 = invalid",
    });
    let json = (serde_json::to_string_pretty(&intrinsics)? + "\n").into_bytes();

    let ramp = scene_by_name("terrain-ramp", SEED)?;
    let stereo = StereoCamera::stoc();
    let origin = pointcloud::SensorPose::from_position_rpy(
        pointcloud::Point3::new(0.0, 0.0, SENSOR_HEIGHT),
        0.0,
        0.0,
        0.0,
    );
    let full = stereo.scan(&ramp, &stereo.mount(&origin), SEED).to_cloud()?;
    let mut stereo_cloud = every_fourth_pixel(&full);
    stereo_cloud.set_grid(None)?;
    let mut bin = Vec::new();
    write_kitti_bin(&mut bin, &stereo_cloud)?;

    Ok(vec![
        ("lab-alrf-2deg.ply", ply),
        ("lab-alrf-2deg.3d", uos),
        ("lab-alrf-2deg.pose", uos_pose),
        ("lab-tof.pcd", pcd),
        ("lab-tof-depth.png", png),
        ("lab-tof-depth_intrinsics.json", json),
        ("terrain-ramp-stereo.bin", bin),
    ])
}

/// The points of every fourth row and column of an organised cloud (a small fixture).
fn every_fourth_pixel(cloud: &PointCloud) -> PointCloud {
    let Some(grid) = cloud.grid() else { return cloud.clone() };
    let mut keep = vec![false; cloud.len()];
    for row in (0..grid.height()).step_by(4) {
        for col in (0..grid.width()).step_by(4) {
            if let Some(i) = grid.point_index(col, row) {
                keep[i] = true;
            }
        }
    }
    cloud.retain_indices(|i| keep[i])
}

/// Writes every fixture into `dir`; returns their names.
pub fn write_all(dir: &Path) -> Result<Vec<&'static str>> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let mut names = Vec::new();
    for (name, bytes) in generate()? {
        let path = dir.join(name);
        pointcloud::io::write_bytes_atomically(&path, bytes)?;
        names.push(name);
    }
    Ok(names)
}

/// The fixtures in `dir` that are missing or differ from what [`generate`] makes.
pub fn check(dir: &Path) -> Result<Vec<&'static str>> {
    Ok(generate()?
        .into_iter()
        .filter(|(name, bytes)| std::fs::read(dir.join(name)).ok().as_ref() != Some(bytes))
        .map(|(name, _)| name)
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use pointcloud::io;

    /// Every fixture must load through the path-level reader.
    fn load_all(dir: &Path) -> Result<Vec<(&'static str, PointCloud)>> {
        let mut out = Vec::new();
        for (name, _) in generate()? {
            if name.ends_with(".json") || name.ends_with(".pose") {
                continue;
            }
            let cloud = io::read_cloud(&dir.join(name), &io::ReadOptions::STRICT)?;
            out.push((name, cloud));
        }
        Ok(out)
    }

    #[test]
    fn fixtures_are_current() {
        let dir = crate::project_root().join("fixtures");
        let stale = check(&dir).unwrap();
        assert!(stale.is_empty(), "stale fixtures {stale:?}: run `cargo xtask fixtures`");
    }

    #[test]
    fn fixtures_load_with_their_content() {
        let dir = crate::project_root().join("fixtures");
        let clouds = load_all(&dir).unwrap();
        assert_eq!(clouds.len(), 5);
        for (name, cloud) in &clouds {
            assert!(cloud.len() > 1000, "{name} has only {} points", cloud.len());
        }
        let get = |n: &str| &clouds.iter().find(|(name, _)| *name == n).unwrap().1;
        let ply = get("lab-alrf-2deg.ply");
        assert_eq!(ply.grid().map(|g| (g.width(), g.height())), Some((136, 91)));
        assert!(ply.labels().is_some() && ply.sensor_pose().is_some());
        let pcd = get("lab-tof.pcd");
        let png = get("lab-tof-depth.png");
        assert_eq!(pcd.grid().map(|g| (g.width(), g.height())), Some((176, 144)));
        assert_eq!(pcd.len(), png.len(), "the PCD and the PNG are the same frame");
        // The 3DTK copy converts back to the same metres within the format's text precision.
        let uos = get("lab-alrf-2deg.3d");
        assert_eq!(uos.len(), ply.len());
        let max_err = uos
            .positions()
            .iter()
            .zip(ply.positions())
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        assert!(max_err < 1e-4, "3DTK copy differs by {max_err} m");
    }
}
