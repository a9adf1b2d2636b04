//! `cargo xtask peers ground`: our per-point ground segmentation (`patchnav terrain
//! --ground-out`, [`hough_terrain`'s `GroundSegmenter`]) beside Patchwork++ (PyPI
//! `pypatchworkpp`, run by `compare/ground/patchworkpp.py`) in one run, both scored by
//! [`score`] against per-point truth.
//!
//! * **SemanticKITTI** (`semantickitti_labelled_scan/000000.{bin,label}`): ground = classes
//!   [`GROUND_CLASSES`] (road, parking, sidewalk, other-ground, lane-marking, terrain), classes 0
//!   and 1 (unlabelled, outlier) not scored. Ours with KITTI's mount (1.73 m, level) and with the
//!   mount estimated from the scan; Patchwork++ with its default parameters and the sensor
//!   height 1.73 m.
//! * **Simulated** ([`SIM_SCENES`] × the SR-3000 range camera and the actuated laser scanner ×
//!   seeds): ground = the points whose beam hit a surface the robot can drive on (the floor, and
//!   the tops of ramps, plateaus and canyons within Rugbot's 0.2 m / 35° limits); ours with the
//!   known mount, Patchwork++ on the same points levelled (z up, sensor at the origin) with its
//!   sensor height given and its other parameters at their defaults (tuned for a car: it takes
//!   nothing within 2.7 m as ground).
//! * **Timing**: each side labels the same scan a first time and then `repeat` times back to
//!   back in one process on one core; the rows give the first call, the best and the median of
//!   the others. Ours times levelling, grid, fits and labels (not reading the file); Patchwork++
//!   times `estimateGround` (the NumPy array already built).

use super::Peers;
use anyhow::{Context, Result, bail, ensure};
use pointcloud::io::{ReadOptions, read_cloud};
use pointcloud::{Point3, PointCloud, SensorPose};
use scene_sim::{Alrf, AlrfConfig, RangeCamera, RangeSensor, Scene, TerrainSpec, lab, terrain};
use serde_json::{Value, json};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

/// SemanticKITTI's ground classes: road, parking, sidewalk, other-ground, lane-marking, terrain.
pub const GROUND_CLASSES: [u32; 6] = [40, 44, 48, 49, 60, 72];
/// SemanticKITTI's classes left out of the score: unlabelled, outlier.
pub const IGNORED_CLASSES: [u32; 2] = [0, 1];
/// KITTI's Velodyne height above the road, metres.
pub const KITTI_HEIGHT: f64 = 1.73;
/// Calls per side after the first.
pub const REPEAT: usize = 5;

/// Precision, recall and F1 of a ground label.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct Score {
    /// Ground points labelled ground.
    pub tp: usize,
    /// Other points labelled ground.
    pub fp: usize,
    /// Ground points not labelled ground.
    pub fn_: usize,
    /// Points scored.
    pub scored: usize,
}

impl Score {
    /// `tp / (tp + fp)` (1 when nothing is labelled ground).
    pub fn precision(&self) -> f64 {
        if self.tp + self.fp == 0 { 1.0 } else { self.tp as f64 / (self.tp + self.fp) as f64 }
    }

    /// `tp / (tp + fn)` (1 when there is no ground).
    pub fn recall(&self) -> f64 {
        if self.tp + self.fn_ == 0 { 1.0 } else { self.tp as f64 / (self.tp + self.fn_) as f64 }
    }

    /// The harmonic mean of precision and recall.
    pub fn f1(&self) -> f64 {
        let (p, r) = (self.precision(), self.recall());
        if p + r == 0.0 { 0.0 } else { 2.0 * p * r / (p + r) }
    }

    /// Adds another score's counts.
    pub fn add(&mut self, o: &Score) {
        self.tp += o.tp;
        self.fp += o.fp;
        self.fn_ += o.fn_;
        self.scored += o.scored;
    }

    fn json(&self) -> Value {
        json!({"tp": self.tp, "fp": self.fp, "fn": self.fn_, "scored": self.scored,
            "precision": self.precision(), "recall": self.recall(), "f1": self.f1()})
    }
}

/// Scores `predicted` ground labels against `truth` (`None`: not scored).
///
/// # Errors
/// Lengths that differ.
pub fn score(predicted: &[bool], truth: &[Option<bool>]) -> Result<Score> {
    ensure!(
        predicted.len() == truth.len(),
        "{} labels for {} points of truth",
        predicted.len(),
        truth.len()
    );
    let mut s = Score::default();
    for (&p, t) in predicted.iter().zip(truth) {
        let Some(t) = *t else { continue };
        s.scored += 1;
        match (p, t) {
            (true, true) => s.tp += 1,
            (true, false) => s.fp += 1,
            (false, true) => s.fn_ += 1,
            (false, false) => {}
        }
    }
    Ok(s)
}

/// SemanticKITTI's truth from a `.label` file: ground for [`GROUND_CLASSES`], `None` for
/// [`IGNORED_CLASSES`] (the class is the lower 16 bits).
///
/// # Errors
/// A length that is not a multiple of 4.
pub fn kitti_truth(label_bytes: &[u8]) -> Result<Vec<Option<bool>>> {
    ensure!(label_bytes.len().is_multiple_of(4), "a .label file holds 4 bytes per point");
    Ok(label_bytes
        .chunks_exact(4)
        .map(|c| {
            let class = u32::from_le_bytes([c[0], c[1], c[2], c[3]]) & 0xffff;
            (!IGNORED_CLASSES.contains(&class)).then(|| GROUND_CLASSES.contains(&class))
        })
        .collect())
}

/// The Patchwork++ side: a Python with `pypatchworkpp` and the driver script.
#[derive(Clone, Debug)]
pub struct Patchwork {
    /// The virtual environment's Python.
    pub python: PathBuf,
    /// `compare/ground/patchworkpp.py`.
    pub script: PathBuf,
}

/// What `cargo xtask peers ground` runs.
#[derive(Clone, Debug)]
pub struct GroundRun {
    /// The folder with `000000.bin`, `000000.label`.
    pub scan_dir: PathBuf,
    /// Patchwork++, or why it is missing (the run fails with that message).
    pub patchwork: Result<Patchwork, String>,
    /// Seeds of the simulated frames.
    pub seeds: Vec<u64>,
}

/// The simulated scenes (terrain scenes of scene-sim and the lab); `sim_scene` says which of
/// their surfaces are drivable ground.
pub const SIM_SCENES: [&str; 9] = [
    "floor",
    "ramp20",
    "ramp40",
    "plateau0.1",
    "plateau0.3",
    "canyon0.3",
    "wall2m",
    "clutter25",
    "lab",
];

/// The scene `name` of [`SIM_SCENES`] and the names of its surfaces that are drivable ground:
/// the floor, a 20° ramp and the platform it leads to, a 0.1 m plateau's top; not a 40° ramp,
/// a 0.3 m plateau or canyon, walls, obstacles, the lab's rack or furniture.
fn sim_scene(name: &str, seed: u64) -> Result<(Scene, &'static [&'static str])> {
    let deg = |d: f64| d.to_radians();
    let t = |spec: TerrainSpec| terrain(&spec, seed).map_err(anyhow::Error::from);
    Ok(match name {
        "floor" => (t(TerrainSpec::Floor)?, &["floor"][..]),
        "ramp20" => (
            t(TerrainSpec::Ramp { pitch: deg(20.0), roll: 0.0, distance: 1.5 })?,
            &["floor", "ramp", "platform/+z"][..],
        ),
        "ramp40" => {
            (t(TerrainSpec::Ramp { pitch: deg(40.0), roll: 0.0, distance: 1.5 })?, &["floor"][..])
        }
        "plateau0.1" => {
            (t(TerrainSpec::Plateau { height: 0.1, distance: 1.5 })?, &["floor", "plateau/+z"][..])
        }
        "plateau0.3" => (t(TerrainSpec::Plateau { height: 0.3, distance: 1.5 })?, &["floor"][..]),
        "canyon0.3" => (t(TerrainSpec::Canyon { depth: 0.3, distance: 1.5 })?, &["floor"][..]),
        "wall2m" => (t(TerrainSpec::Wall { distance: 2.0, height: 2.0 })?, &["floor"][..]),
        "clutter25" => (t(TerrainSpec::Obstacles { count: 25, distance: 1.5 })?, &["floor"][..]),
        "lab" => (lab(seed)?, &["floor"][..]),
        other => bail!("unknown simulated scene {other}"),
    })
}

/// A simulated sensor: name, height (m), pitch (degrees down), axes for `patchnav`.
struct SimSensor {
    name: &'static str,
    height: f64,
    pitch_deg: f64,
    axes: &'static str,
    sensor: Box<dyn RangeSensor>,
}

fn sim_sensors() -> Result<Vec<SimSensor>> {
    Ok(vec![
        SimSensor {
            name: "sr3000",
            height: 0.45,
            pitch_deg: 15.0,
            axes: "camera",
            sensor: Box::new(RangeCamera::swissranger_sr3000()),
        },
        SimSensor {
            name: "alrf-1deg",
            height: 0.5,
            pitch_deg: 0.0,
            axes: "lidar",
            sensor: Box::new(Alrf::new(AlrfConfig::sick_s300_with_step(1f64.to_radians())?)?),
        },
    ])
}

/// A simulated frame with per-point truth.
fn sim_frame(
    scene_name: &str,
    sensor: &SimSensor,
    seed: u64,
) -> Result<(PointCloud, Vec<Option<bool>>)> {
    let (scene, ground_names) = sim_scene(scene_name, seed)?;
    let body = if scene_name == "lab" {
        let pose = scene.scan_poses(1, sensor.height, seed);
        let p = pose.first().context("no scan pose in the lab")?;
        let t = p.world_from_sensor.translation.vector;
        let yaw = p.world_from_sensor.rotation.euler_angles().2;
        SensorPose::from_position_rpy(Point3::new(t.x, t.y, sensor.height), 0.0, 0.0, yaw)
    } else {
        SensorPose::from_position_rpy(Point3::new(0.0, 0.0, sensor.height), 0.0, 0.0, 0.0)
    };
    let body = SensorPose::from_position_rpy(
        Point3::from(body.world_from_sensor.translation.vector),
        0.0,
        sensor.pitch_deg.to_radians(),
        body.world_from_sensor.rotation.euler_angles().2,
    );
    let pose = sensor.sensor.mount(&body);
    let cloud = sensor.sensor.scan(&scene, &pose, seed).to_cloud()?;
    let drivable: Vec<bool> =
        scene.surfaces().iter().map(|s| ground_names.contains(&s.name.as_str())).collect();
    let labels = cloud.labels().context("simulated cloud without surface labels")?;
    let truth =
        labels.iter().map(|&l| Some(drivable.get(l as usize).copied().unwrap_or(false))).collect();
    Ok((cloud, truth))
}

/// Writes `cloud` as a KITTI `.bin` (float32 x, y, z, 0) in a levelled frame for Patchwork++:
/// z up along gravity, the sensor at the origin (the cloud's sensor pose with its x and y
/// removed; the heading does not matter to a ground segmenter).
fn write_levelled_bin(path: &Path, cloud: &PointCloud) -> Result<()> {
    let pose = cloud.sensor_pose().context("a simulated cloud has its sensor pose")?;
    let origin = pose.world_from_sensor.translation.vector;
    let mut bytes = Vec::with_capacity(cloud.len() * 16);
    for p in cloud.positions() {
        let w = pose.world_from_sensor * p;
        for v in [w.x - origin.x, w.y - origin.y, w.z - origin.z, 0.0] {
            bytes.extend_from_slice(&(v as f32).to_le_bytes());
        }
    }
    pointcloud::io::write_bytes_atomically(path, bytes)?;
    Ok(())
}

/// Our side's result for one frame.
struct Ours {
    labels: Vec<bool>,
    json: Value,
}

/// Runs `patchnav terrain FRAME --ground-out` (with `mount_args`) and reads the labels back.
fn ours(
    patchnav: &Path,
    frame: &Path,
    out: &Path,
    mount_args: &[String],
    repeat: usize,
) -> Result<Ours> {
    let mut cmd = Command::new(patchnav);
    cmd.arg("terrain").arg(frame).arg("--ground-out").arg(out).args(mount_args).args([
        "--repeat",
        &repeat.to_string(),
        "--json",
    ]);
    let text = crate::compare::capture(&mut cmd)?;
    let line = text.lines().rev().find(|l| l.starts_with('{')).context("no JSON line")?;
    let json: Value = serde_json::from_str(line)?;
    let cloud = read_cloud(out, &ReadOptions { skip_non_finite: false })?;
    let field = cloud.extra_field("ground").context("no `ground` field in our output")?;
    let labels = (0..field.data.len()).map(|i| field.data.get_f64(i) == Some(1.0)).collect();
    Ok(Ours { labels, json: json["ground"].clone() })
}

fn ms(v: &Value, key: &str) -> f64 {
    v[key].as_f64().unwrap_or(f64::NAN)
}

/// Runs both sides on SemanticKITTI and ours on the simulated frames; returns the rows and
/// the tables (markdown).
///
/// # Errors
/// Missing scan files, Patchwork++ not installed, or a run failing.
pub fn run(env: &Peers, args: &GroundRun) -> Result<(Vec<Value>, String)> {
    let (work, patchnav) = (&env.work, &env.patchnav);
    let bin = args.scan_dir.join("000000.bin");
    let label = args.scan_dir.join("000000.label");
    for f in [&bin, &label] {
        ensure!(f.is_file(), "missing {} (the labelled SemanticKITTI scan)", f.display());
    }
    let pw = args.patchwork.as_ref().map_err(|e| anyhow::anyhow!("Patchwork++: {e}"))?;
    let truth = kitti_truth(&std::fs::read(&label)?)?;
    let mut rows = Vec::new();
    let mut table = String::from(
        "SemanticKITTI 000000 (ground: road, parking, sidewalk, other-ground, lane-marking, terrain)\n\
         | method | mount | precision | recall | F1 | ms best | ms median | ms first | ours / Patchwork++ (best) |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );

    // Patchwork++ and ours, back to back.
    let pw_labels = work.join("kitti.patchworkpp.u8");
    let text = crate::compare::capture(
        Command::new(&pw.python)
            .env("OMP_NUM_THREADS", "1")
            .arg(&pw.script)
            .arg(&bin)
            .arg(&pw_labels)
            .args(["--sensor-height", &KITTI_HEIGHT.to_string(), "--repeat", &REPEAT.to_string()]),
    )?;
    let line = text.lines().rev().find(|l| l.starts_with('{')).context("no JSON line")?;
    let pw_json: Value = serde_json::from_str(line)?;
    let theirs: Vec<bool> = std::fs::read(&pw_labels)?.iter().map(|&b| b == 1).collect();
    let pw_score = score(&theirs, &truth)?;
    let pw_best = ms(&pw_json, "best_ms");

    let given = vec![
        "--axes".to_owned(),
        "lidar".to_owned(),
        "--sensor-height".to_owned(),
        KITTI_HEIGHT.to_string(),
        "--pitch".to_owned(),
        "0".to_owned(),
    ];
    let estimated = vec!["--axes".to_owned(), "lidar".to_owned()];
    let mut sides = Vec::new();
    for (mount, mount_args) in [("1.73 m, level (given)", given), ("estimated", estimated)] {
        let out = work
            .join(format!("kitti.ours.{}.ply", if mount == "estimated" { "est" } else { "given" }));
        let o = ours(patchnav, &bin, &out, &mount_args, REPEAT)?;
        sides.push((mount, score(&o.labels, &truth)?, o.json));
    }
    for (mount, s, j) in &sides {
        rows.push(json!({"frame": "semantickitti-000000", "tool": "patchnav", "method": "ground",
            "mount": mount, "score": s.json(), "time": j}));
        table += &format!(
            "| ours | {mount} | {:.3} | {:.3} | {:.3} | {:.2} | {:.2} | {:.2} | {:.2} |\n",
            s.precision(),
            s.recall(),
            s.f1(),
            ms(j, "best_ms"),
            ms(j, "median_ms"),
            ms(j, "first_ms"),
            ms(j, "best_ms") / pw_best
        );
    }
    rows.push(json!({"frame": "semantickitti-000000", "tool": "patchworkpp", "method": "ground",
        "mount": "1.73 m", "score": pw_score.json(), "time": pw_json}));
    table += &format!(
        "| Patchwork++ {} | 1.73 m | {:.3} | {:.3} | {:.3} | {:.2} | {:.2} | {:.2} | 1 |\n",
        pw_json["package"].as_str().unwrap_or("1.4.1"),
        pw_score.precision(),
        pw_score.recall(),
        pw_score.f1(),
        pw_best,
        ms(&pw_json, "median_ms"),
        ms(&pw_json, "first_ms"),
    );

    // Simulated frames.
    let sensors = sim_sensors()?;
    let mut sim = String::from(
        "\nSimulated frames (ground: the drivable surfaces), ours with the known mount\n| scene | sensor |",
    );
    for seed in &args.seeds {
        write!(sim, " seed {seed} P / R / F1 |")?;
    }
    sim += "\n|---|---|";
    sim += &"---|".repeat(args.seeds.len());
    sim += "\n";
    let mut totals = vec![Score::default(); args.seeds.len()];
    let mut pw_totals = vec![Score::default(); args.seeds.len()];
    let mut pw_sim = String::from(
        "\nPatchwork++ on the same simulated frames (levelled, z up, its sensor height given, default parameters)\n| scene | sensor |",
    );
    for seed in &args.seeds {
        write!(pw_sim, " seed {seed} P / R / F1 |")?;
    }
    pw_sim += "\n|---|---|";
    pw_sim += &"---|".repeat(args.seeds.len());
    pw_sim += "\n";
    for scene in SIM_SCENES {
        for sensor in &sensors {
            write!(sim, "| {scene} | {} |", sensor.name)?;
            write!(pw_sim, "| {scene} | {} |", sensor.name)?;
            for (k, &seed) in args.seeds.iter().enumerate() {
                let (cloud, truth) = sim_frame(scene, sensor, seed)?;
                let frame = work.join(format!("sim-{scene}-{}-{seed}.ply", sensor.name));
                pointcloud::io::write_cloud(&frame, &cloud)?;
                let out = work.join(format!("sim-{scene}-{}-{seed}.ground.ply", sensor.name));
                let mount = vec![
                    "--axes".to_owned(),
                    sensor.axes.to_owned(),
                    "--sensor-height".to_owned(),
                    sensor.height.to_string(),
                    "--pitch".to_owned(),
                    sensor.pitch_deg.to_string(),
                ];
                let o = ours(patchnav, &frame, &out, &mount, 1)?;
                let s = score(&o.labels, &truth)?;
                totals[k].add(&s);
                rows.push(json!({"frame": format!("sim-{scene}"), "sensor": sensor.name, "seed": seed,
                    "tool": "patchnav", "method": "ground", "points": cloud.len(), "score": s.json(), "time": o.json}));
                write!(sim, " {:.3} / {:.3} / {:.3} |", s.precision(), s.recall(), s.f1())?;

                let bin = work.join(format!("sim-{scene}-{}-{seed}.levelled.bin", sensor.name));
                write_levelled_bin(&bin, &cloud)?;
                let lbl = work.join(format!("sim-{scene}-{}-{seed}.patchworkpp.u8", sensor.name));
                let text = crate::compare::capture(
                    Command::new(&pw.python)
                        .env("OMP_NUM_THREADS", "1")
                        .arg(&pw.script)
                        .arg(&bin)
                        .arg(&lbl)
                        .args(["--sensor-height", &sensor.height.to_string(), "--repeat", "1"]),
                )?;
                let line =
                    text.lines().rev().find(|l| l.starts_with('{')).context("no JSON line")?;
                let pw_time: Value = serde_json::from_str(line)?;
                let theirs: Vec<bool> = std::fs::read(&lbl)?.iter().map(|&b| b == 1).collect();
                let t = score(&theirs, &truth)?;
                pw_totals[k].add(&t);
                rows.push(json!({"frame": format!("sim-{scene}"), "sensor": sensor.name, "seed": seed,
                    "tool": "patchworkpp", "method": "ground", "points": cloud.len(), "score": t.json(), "time": pw_time}));
                write!(pw_sim, " {:.3} / {:.3} / {:.3} |", t.precision(), t.recall(), t.f1())?;
            }
            sim += "\n";
            pw_sim += "\n";
        }
    }
    sim += "| all | both |";
    for t in &totals {
        write!(sim, " {:.3} / {:.3} / {:.3} |", t.precision(), t.recall(), t.f1())?;
    }
    sim += "\n";
    pw_sim += "| all | both |";
    for t in &pw_totals {
        write!(pw_sim, " {:.3} / {:.3} / {:.3} |", t.precision(), t.recall(), t.f1())?;
    }
    pw_sim += "\n";
    Ok((rows, table + &sim + &pw_sim))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scores_count_and_skip_ignored_points() {
        let s = score(
            &[true, true, false, false, true],
            &[Some(true), Some(false), Some(true), Some(false), None],
        )
        .unwrap();
        assert_eq!((s.tp, s.fp, s.fn_, s.scored), (1, 1, 1, 4));
        assert_eq!((s.precision(), s.recall(), s.f1()), (0.5, 0.5, 0.5));
        assert!(score(&[true], &[]).is_err());
        let bytes: Vec<u8> = [40u32, 1, 50 | (7 << 16), 72 | (3 << 16)]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        assert_eq!(kitti_truth(&bytes).unwrap(), vec![Some(true), None, Some(false), Some(true)]);
    }

    #[test]
    fn simulated_truth_marks_drivable_surfaces() {
        let sensors = sim_sensors().unwrap();
        let (cloud, truth) = sim_frame("plateau0.3", &sensors[0], 1).unwrap();
        assert_eq!(cloud.len(), truth.len());
        let ground = truth.iter().filter(|t| **t == Some(true)).count();
        assert!(ground > 0 && ground < truth.len(), "{ground} of {}", truth.len());
        let (_, truth) = sim_frame("plateau0.1", &sensors[0], 1).unwrap();
        let more = truth.iter().filter(|t| **t == Some(true)).count();
        assert!(more > ground);
    }
}
