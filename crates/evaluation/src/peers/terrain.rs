//! `cargo xtask peers terrain`: the time of our Hough terrain classification beside one RANSAC
//! ground-plane fit by PCL (`pcl_planes --method ransac --max-planes 1`) and Open3D
//! (`open3d_planes.py --method segment_plane --max-planes 1`) on the same frames.
//!
//! Frames: simulated SR-3000 frames (176 × 144) of a floor, a 30° ramp, a wall 2 m ahead and a
//! cluttered floor, and the same scenes by the STOC stereo camera cut to 72,000 points, from a
//! level camera 0.45 m above the floor; written as unorganised PLY in the camera's optical
//! frame. Ours: `patchnav terrain --axes camera --sensor-height 0.45 --repeat 20 --json` (the
//! median in-process time of levelling, preprocessing, Algorithms 2 and 3) at 45°, 15° and 9°.
//! Theirs: the in-process segmentation time of one RANSAC plane (1000 iterations, 2 cm), the
//! median of 3 runs. A peer that is not built or installed gives a line saying how to get it.

use anyhow::{Context, Result};
use pointcloud::{Point3, PointCloud, SensorPose};
use scene_sim::{RangeCamera, RangeSensor, StereoCamera, TerrainSpec, terrain};
use serde_json::{Value, json};
use std::process::Command;

/// Camera height above the floor (metres) and the stereo frame's size.
const HEIGHT: f64 = 0.45;
const STEREO_POINTS: usize = 72_000;
const RESOLUTIONS: [&str; 3] = ["45", "15", "9"];

fn frames() -> Result<Vec<(String, PointCloud)>> {
    let body = SensorPose::from_position_rpy(Point3::new(0.0, 0.0, HEIGHT), 0.0, 0.0, 0.0);
    let specs = [
        ("floor", TerrainSpec::Floor),
        ("ramp30", TerrainSpec::Ramp { pitch: 30f64.to_radians(), roll: 0.0, distance: 1.5 }),
        ("wall2m", TerrainSpec::Wall { distance: 2.0, height: 2.0 }),
        ("clutter25", TerrainSpec::Obstacles { count: 25, distance: 1.5 }),
    ];
    let tof = RangeCamera::swissranger_sr3000();
    let stereo = StereoCamera::stoc();
    let mut out = Vec::new();
    for (name, spec) in specs {
        let scene = terrain(&spec, 1)?;
        let t = tof.scan(&scene, &tof.mount(&body), 1).to_cloud()?;
        out.push((format!("tof-{name}"), PointCloud::from_positions(t.positions().to_vec())?));
        let s = stereo.scan(&scene, &stereo.mount(&body), 1).to_cloud()?;
        let p = s.positions();
        let n = p.len().min(STEREO_POINTS);
        let sub: Vec<Point3> = (0..n).map(|i| p[i * p.len() / n]).collect();
        out.push((format!("stereo-{name}"), PointCloud::from_positions(sub)?));
    }
    Ok(out)
}

/// The last JSON line a program printed.
fn json_line(out: &str) -> Result<Value> {
    let line =
        out.lines().rev().find(|l| l.trim_start().starts_with('{')).context("no JSON line")?;
    Ok(serde_json::from_str(line)?)
}

/// Times our Hough terrain classification and one RANSAC plane fit of each peer on the same
/// simulated frames: one row per run and the table (a peer that is not built is skipped with a
/// note on standard error).
pub fn run(env: &super::Peers) -> Result<(Vec<Value>, String)> {
    let (work, patchnav, build_dir, peers) =
        (&env.work, &env.patchnav, &env.build_dir, &env.peers_dir);
    let pcl = build_dir.join("pcl_planes");
    let python = "/usr/bin/python3";
    let open3d_script = peers.join("open3d_planes.py");
    let open3d_ok = open3d_script.is_file()
        && Command::new(python)
            .args(["-c", "import open3d"])
            .output()
            .is_ok_and(|o| o.status.success());
    if !pcl.is_file() {
        eprintln!(
            "SKIPPED: PCL (pcl_planes not built: PEERS_BUILD_DIR={} bash {}/build.sh)",
            build_dir.display(),
            peers.display()
        );
    }
    if !open3d_ok {
        eprintln!(
            "SKIPPED: Open3D ({python} cannot import open3d: apt-get install python3-open3d or pip install open3d)"
        );
    }

    let mut rows = Vec::new();
    let mut table = String::from(
        "Hough terrain classification (ours) vs one RANSAC plane fit, ms per frame (median)\n| frame | points | ours \
         45° | ours 15° | ours 9° | PCL RANSAC | Open3D RANSAC | ours 45° / PCL | ours 45° / Open3D |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for (name, cloud) in frames()? {
        let file = work.join(format!("{name}.ply"));
        pointcloud::io::write_cloud(&file, &cloud)?;
        let f = file.display().to_string();
        let mut ours = Vec::new();
        for res in RESOLUTIONS {
            let o = crate::compare::capture(Command::new(patchnav).args([
                "terrain",
                &f,
                "--axes",
                "camera",
                "--sensor-height",
                "0.45",
                "--resolution",
                res,
                "--repeat",
                "20",
                "--json",
            ]))?;
            let v = json_line(&o)?;
            let ms = v["time_ms"].as_f64().context("time_ms")?;
            rows.push(json!({"frame": name, "tool": "patchnav", "method": format!("hough-{res}deg"),
                "points": cloud.len(), "time_ms": ms, "class": v["class"], "drivable": v["drivable"]}));
            ours.push(ms);
        }
        let mut theirs = |tool: &str, cmd: &mut dyn FnMut() -> Command| -> Result<Option<f64>> {
            let mut times = Vec::new();
            let mut last = Value::Null;
            for _ in 0..3 {
                let v = json_line(&crate::compare::capture(&mut cmd())?)?;
                times.push(v["time_seg_s"].as_f64().context("time_seg_s")? * 1e3);
                last = v;
            }
            let ms = crate::stats::median(times).unwrap_or(f64::NAN);
            rows.push(json!({"frame": name, "tool": last["tool"], "method": "ransac-1-plane", "points": cloud.len(),
                "time_ms": ms, "inliers": last.get("inliers"), "peer": tool}));
            Ok(Some(ms))
        };
        let pcl_ms = if pcl.is_file() {
            theirs("pcl", &mut || {
                let mut c = Command::new(&pcl);
                c.args([
                    &f,
                    "--method",
                    "ransac",
                    "--max-planes",
                    "1",
                    "--dist",
                    "0.02",
                    "--min-inliers",
                    "100",
                ]);
                c
            })?
        } else {
            None
        };
        let o3d_ms = if open3d_ok {
            theirs("open3d", &mut || {
                let mut c = Command::new(python);
                c.arg(&open3d_script).args([
                    &f,
                    "--method",
                    "segment_plane",
                    "--max-planes",
                    "1",
                    "--seed",
                    "0",
                ]);
                c
            })?
        } else {
            None
        };
        let cell = |v: Option<f64>| v.map_or("–".to_owned(), |v| format!("{v:.2}"));
        let ratio = |v: Option<f64>| v.map_or("–".to_owned(), |v| format!("{:.3}", ours[0] / v));
        table += &format!(
            "| {name} | {} | {:.2} | {:.2} | {:.2} | {} | {} | {} | {} |\n",
            cloud.len(),
            ours[0],
            ours[1],
            ours[2],
            cell(pcl_ms),
            cell(o3d_ms),
            ratio(pcl_ms),
            ratio(o3d_ms)
        );
    }
    Ok((rows, table))
}
