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
//! | `lab-alrf.mcap`, `lab-alrf.bag` | a ROS 2 MCAP bag and a ROS 1 bag of three ALRF scans (6° steps) from a moving base: `/tf_static` (base_link → laser), `/tf` (odom → base_link, 100 ms before, at and after each scan), `/points` (organised, float32) and `/points_flat` (the same scans unorganised, float64 in a padded layout) |
//!
//! Tests read these files, and `fixtures_are_current` regenerates them and compares bytes, so a
//! change to a writer or to the simulator shows up as a stale fixture.

use anyhow::{Context, Result};
use pointcloud::io::Precision;
use pointcloud::io::depth_png::write_depth_png;
use pointcloud::io::kitti::write_kitti_bin;
use pointcloud::io::pcd::{PcdEncoding, PcdWriteOptions, write_pcd};
use pointcloud::io::ply::{PlyEncoding, PlyWriteOptions, write_ply};
use pointcloud::io::pointcloud2::{Pc2Layout, encode};
use pointcloud::io::uos::{write_uos_pose, write_uos_scan};
use pointcloud::{Isometry3, PointCloud};
use ros_bag::msgs::{POINT_CLOUD2, TF_MESSAGE};
use ros_bag::{BagFormat, BagWriter, Header, TransformStamped};
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

    let (mcap, bag) = (lab_bag(&lab, BagFormat::Mcap)?, lab_bag(&lab, BagFormat::Ros1)?);

    Ok(vec![
        ("lab-alrf.mcap", mcap),
        ("lab-alrf.bag", bag),
        ("lab-alrf-2deg.ply", ply),
        ("lab-alrf-2deg.3d", uos),
        ("lab-alrf-2deg.pose", uos_pose),
        ("lab-tof.pcd", pcd),
        ("lab-tof-depth.png", png),
        ("lab-tof-depth_intrinsics.json", json),
        ("terrain-ramp-stereo.bin", bin),
    ])
}

/// Three ALRF scans of `lab` from a moving base as a bag (see the module docs).
fn lab_bag(lab: &scene_sim::Scene, format: BagFormat) -> Result<Vec<u8>> {
    let stamped = |stamp_ns, parent: &str, child: &str, m| TransformStamped {
        header: Header { stamp_ns, frame_id: parent.into() },
        child_frame_id: child.into(),
        parent_from_child: m,
    };
    let alrf = Alrf::new(AlrfConfig::sick_s300_with_step(6f64.to_radians())?)?;
    let base_from_laser = Isometry3::translation(0.1, 0.0, 0.5);
    let t0 = 1_700_000_000_000_000_000i64;
    let mut w = BagWriter::new(format)?;
    let tf_static = w.add_topic("/tf_static", TF_MESSAGE)?;
    let tf = w.add_topic("/tf", TF_MESSAGE)?;
    let points = w.add_topic("/points", POINT_CLOUD2)?;
    let flat = w.add_topic("/points_flat", POINT_CLOUD2)?;
    w.write_tf(tf_static, t0 as u64, &[stamped(t0, "base_link", "laser", base_from_laser)])?;
    let padded = Pc2Layout {
        precision: Precision::F64,
        padding: 4,
        row_padding: 0,
        big_endian: false,
        positions_last: false,
    };
    for (k, body) in lab.scan_poses(3, SENSOR_HEIGHT, SEED).into_iter().enumerate() {
        let laser = alrf.mount(&body);
        let mut cloud = alrf.scan(lab, &laser, SEED + k as u64).to_cloud()?;
        cloud.set_sensor_pose(None);
        let odom_from_base = laser.world_from_sensor * base_from_laser.inverse();
        let stamp = t0 + 100_000_000 + k as i64 * 500_000_000;
        for dt in [-100_000_000i64, 0, 100_000_000] {
            let creep = Isometry3::translation(dt as f64 * 0.3e-9, 0.0, 0.0);
            let m = odom_from_base * creep;
            w.write_tf(tf, (stamp + dt) as u64, &[stamped(stamp + dt, "odom", "base_link", m)])?;
            if dt == 0 {
                let header = Header { stamp_ns: stamp, frame_id: "laser".into() };
                w.write_cloud(points, &header, &encode(&cloud, &Pc2Layout::default())?)?;
                cloud.set_grid(None)?;
                w.write_cloud(flat, &header, &encode(&cloud, &padded)?)?;
            }
        }
    }
    Ok(w.finish()?)
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
            if name.ends_with(".json")
                || name.ends_with(".pose")
                || name.ends_with(".mcap")
                || name.ends_with(".bag")
            {
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

    #[test]
    fn bag_fixtures_hold_three_posed_scans() {
        let dir = crate::project_root().join("fixtures");
        for name in ["lab-alrf.mcap", "lab-alrf.bag"] {
            let bag = ros_bag::Bag::open(dir.join(name)).unwrap();
            let found = ros_bag::read_scans(&bag, &ros_bag::ScanQuery::all("/points")).unwrap();
            assert_eq!(found.counts, (3, 3, 3), "{name}");
            assert_eq!(found.fixed_frame.as_deref(), Some("odom"));
            for s in &found.scans {
                assert!(s.cloud.grid().is_some() && s.cloud.len() > 500, "{name}");
            }
            let flat = ros_bag::read_scans(&bag, &ros_bag::ScanQuery::all("/points_flat")).unwrap();
            for (a, b) in found.scans.iter().zip(&flat.scans) {
                assert!(b.cloud.grid().is_none());
                assert_eq!(a.cloud.len(), b.cloud.len());
            }
        }
    }
}
