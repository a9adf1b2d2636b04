//! Segmentation: PCL's organised multi-plane segmentation + concave hulls (`cmp_segment`)
//! against `patchnav extract --sensor range-camera`, on three sets of organised inputs:
//!
//! * **floor plan**: the shared bench's 640 × 480 depth image `floorplan_scan.ply`, scored
//!   against the floor plan's mesh with the scoring of `cargo xtask peers planes`
//!   ([`crate::peers::Truth`]);
//! * **lab**: [`LAB_FRAMES`] simulated range-camera frames of the lab scene (scene-sim's
//!   SR-3000 model, 176 × 144, seed [`LAB_SEED`], poses from `lab_poses`), written as organised
//!   PLY files with surface labels under `target/compare/segmentation/lab/` and scored by the
//!   same rules against the scene's exact surfaces (`truth::SceneTruth`);
//! * **real**: the organised depth and ToF frames of the real-data folder (see `REAL_FRAMES`),
//!   converted by `patchnav` into organised PLY files under `target/compare/segmentation/real/`
//!   so both sides read the same points. They have no ground truth: the rows give time, planes
//!   and the share of valid points assigned to a plane. A missing folder or frame is skipped
//!   with a printed note.
//!
//! Every input runs `REPS` times per side, alternating; one JSONL row per run and side. The
//! text is a table for the scored inputs, one for the real frames, and an overall table: per set
//! and over all inputs, the median of the per-input ratios ours / theirs of the median times,
//! and the quality of both sides.

use super::{Env, arg, json_lines, median, num, ratio};
use anyhow::{Context, Result, bail};
use pointcloud::io::Precision;
use pointcloud::io::ply::{PlyEncoding, PlyWriteOptions, write_ply};
use scene_sim::{RangeCamera, RangeSensor as _};
use serde_json::{Value, json};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

mod truth;

/// Repetitions per side and input (alternating), for the median time.
const REPS: usize = 3;
/// The shared bench's depth image.
const FLOORPLAN: &str = "floorplan_scan";
/// Simulated range-camera frames of the lab: 6 frames × 3 repetitions × 2 sides take about
/// 15 s, so the whole part stays within about two minutes.
pub const LAB_FRAMES: usize = 6;
/// Seed of the lab scene, its frames' poses and the sensor noise.
pub const LAB_SEED: u64 = 0;
/// Height of the lab frames' camera above the floor, metres (a camera on a robot's mast).
const LAB_HEIGHT: f64 = 1.0;
/// Where the lab frames' cameras look: the middle of the room (x, y), metres.
const LAB_TARGET: [f64; 2] = [6.0, 4.5];
/// How far the lab frames' cameras look down, degrees.
const LAB_PITCH_DEG: f64 = 15.0;
/// The variable naming the real-data folder (as in the project's real-data tests).
const REAL_DATA_VAR: &str = "PATCHNAV_REAL_DATA";

/// Where a real frame comes from, relative to the real-data folder.
enum RealSource {
    /// An organised cloud or depth PNG read by `patchnav convert` (with `--depth-camera` when
    /// given).
    Cloud { file: &'static str, depth_camera: Option<&'static str> },
    /// A ToF frame (range + amplitude PNGs and sidecar) read by `patchnav tof filter` with no
    /// amplitude threshold, so every measured pixel is kept.
    Tof { range: &'static str, amplitude: &'static str, meta: &'static str },
}

/// One real frame of the comparison.
struct RealFrame {
    name: &'static str,
    source: RealSource,
    /// Our extraction preset for the frame's sensor (`patchnav extract --sensor`).
    sensor: &'static str,
}

/// Our preset for depth from disparity (structured light, stereo): noise growing with the
/// square of the range.
const DISPARITY: &str = "structured-light";
/// Our preset for time-of-flight frames (and the synthetic inputs): constant noise.
const TIME_OF_FLIGHT: &str = "range-camera";

/// The real organised frames: every organised depth or ToF frame of the real-data folder but
/// two of the three nearly identical OpenNI box frames (0.25 s apart).
const REAL_FRAMES: [RealFrame; 5] = [
    RealFrame {
        name: "kinect-office",
        source: RealSource::Cloud { file: "pcl_kinect_office/office1.pcd", depth_camera: None },
        sensor: DISPARITY,
    },
    RealFrame {
        name: "tum-desk",
        source: RealSource::Cloud {
            file: "tum_rgbd_kinect_frame/TUM_depth.png",
            depth_camera: Some("tum"),
        },
        sensor: DISPARITY,
    },
    RealFrame {
        name: "openni-boxes",
        source: RealSource::Cloud {
            file: "pcl_openni_grabber_boxes/frame_20121214T142255.814212.pcd",
            depth_camera: None,
        },
        sensor: DISPARITY,
    },
    RealFrame {
        name: "stereo-table-mug",
        source: RealSource::Cloud {
            file: "pcl_stereo_table_mug/table_scene_mug_stereo_textured.pcd",
            depth_camera: None,
        },
        sensor: DISPARITY,
    },
    RealFrame {
        name: "ifm-o3r-tof",
        source: RealSource::Tof {
            range: "ifm_o3r_tof_frame/radial_distance_u16.png",
            amplitude: "ifm_o3r_tof_frame/normalized_amplitude_u16.png",
            meta: "ifm_o3r_tof_frame/frame_meta.json",
        },
        sensor: TIME_OF_FLIGHT,
    },
];

/// What the segmentation part runs on besides the shared bench.
pub struct Options {
    /// Simulated lab frames (1 to 64).
    pub lab_frames: usize,
    /// The real-data folder (skipped with a note when absent).
    pub real_dir: PathBuf,
}

impl Options {
    /// [`LAB_FRAMES`] frames; the real data at `$PATCHNAV_REAL_DATA`, else `shared/data/real`
    /// next to the checkout at `root`.
    pub fn from_env(root: &Path) -> Options {
        let real_dir = std::env::var_os(REAL_DATA_VAR)
            .map(PathBuf::from)
            .unwrap_or_else(|| root.join("../shared/data/real"));
        Options { lab_frames: LAB_FRAMES, real_dir }
    }
}

/// The three sets of inputs.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
enum Set {
    FloorPlan,
    Lab,
    Real,
}

impl Set {
    const ALL: [Set; 3] = [Set::FloorPlan, Set::Lab, Set::Real];

    /// The row's `set` value.
    fn key(self) -> &'static str {
        match self {
            Set::FloorPlan => "floorplan",
            Set::Lab => "lab",
            Set::Real => "real",
        }
    }

    fn title(self) -> &'static str {
        match self {
            Set::FloorPlan => "floor plan (synthetic 640 × 480)",
            Set::Lab => "lab (simulated 176 × 144)",
            Set::Real => "real frames",
        }
    }
}

/// How the runs on one input are scored.
enum Scoring {
    /// Against the floor plan's mesh.
    FloorPlan,
    /// Against the lab's exact surfaces, with these true planes visible.
    Lab(Vec<usize>),
    /// No ground truth: coverage only.
    Coverage,
}

/// One organised cloud both sides run on.
struct Input {
    name: String,
    set: Set,
    cloud: PathBuf,
    scoring: Scoring,
    /// Our extraction preset.
    sensor: &'static str,
}

/// Runs both sides `REPS` times on every input; returns the rows and the tables.
pub fn run_with(env: &Env, options: &Options) -> Result<(Vec<Value>, String)> {
    if !(1..=64).contains(&options.lab_frames) {
        bail!("the lab frames must be between 1 and 64, got {}", options.lab_frames);
    }
    let scan = env.bench.join(format!("{FLOORPLAN}.ply"));
    if !scan.is_file() {
        bail!("missing {} (the shared bench)", scan.display());
    }
    let started = std::time::Instant::now();
    let dir = env.out.join("segmentation");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let mut notes = Vec::new();
    eprintln!("segmentation: ground truth from floorplan.obj");
    let floor_truth = crate::peers::Truth::load(&env.bench)?;
    let mut inputs = vec![Input {
        name: FLOORPLAN.to_owned(),
        set: Set::FloorPlan,
        cloud: scan,
        scoring: Scoring::FloorPlan,
        sensor: TIME_OF_FLIGHT,
    }];
    let (lab_truth, lab) = lab_inputs(options.lab_frames, &dir.join("lab"))?;
    inputs.extend(lab);
    inputs.extend(real_inputs(env, &options.real_dir, &dir.join("real"), &mut notes)?);

    let mut rows = Vec::new();
    for input in &inputs {
        eprintln!("segmentation: {}", input.name);
        for rep in 0..REPS {
            for side in ["pcl", "ours"] {
                let mut row = match run_side(env, &dir, input, side) {
                    Ok((mut row, polygons)) => {
                        let mut quality = match &input.scoring {
                            Scoring::FloorPlan => floor_truth.quality(FLOORPLAN, &polygons),
                            Scoring::Lab(visible) => lab_truth.quality(visible, &polygons),
                            Scoring::Coverage => json!({}),
                        };
                        quality["points_in_planes"] = json!(coverage(&row));
                        row["quality"] = quality;
                        row
                    }
                    Err(e) => {
                        let note = format!("{} ({side}) skipped: {e:#}", input.name);
                        eprintln!("segmentation: {note}");
                        json!({"kind": "planes", "skipped": note})
                    }
                };
                row["side"] = json!(side);
                row["rep"] = json!(rep);
                row["input"] = json!(input.name);
                row["set"] = json!(input.set.key());
                rows.push(row);
            }
        }
    }
    eprintln!("segmentation: {} inputs in {:.0} s", inputs.len(), started.elapsed().as_secs_f64());
    let mut text = tables(&rows);
    for note in &notes {
        writeln!(text, "\nNote: {note}.")?;
    }
    Ok((rows, text))
}

/// One run of one side on `input`: its row and its plane polygons.
fn run_side(env: &Env, dir: &Path, input: &Input, side: &str) -> Result<(Value, Value)> {
    let stem = input.name.replace('/', "-");
    let polygons = dir.join(format!("{stem}.{side}.polygons.json"));
    let _ = std::fs::remove_file(&polygons);
    let row = if side == "pcl" {
        let a = [arg(&input.cloud), "--polygons".into(), arg(&polygons)];
        json_lines(&env.build.join("cmp_segment"), &a)?
            .pop()
            .context("cmp_segment printed no row")?
    } else {
        let jsonl = dir.join(format!("{stem}.ours.jsonl"));
        let _ = std::fs::remove_file(&jsonl);
        let a = [
            "--quiet",
            "extract",
            &arg(&input.cloud),
            "--sensor",
            input.sensor,
            "--jsonl",
            &arg(&jsonl),
            "--polygons",
            &arg(&polygons),
        ]
        .map(str::to_owned);
        json_lines(&env.patchnav, &a)?;
        let text = std::fs::read_to_string(&jsonl)
            .with_context(|| format!("reading {}", jsonl.display()))?;
        let last = text.lines().last().with_context(|| format!("{} is empty", jsonl.display()))?;
        serde_json::from_str(last).with_context(|| format!("{} is not JSON", jsonl.display()))?
    };
    Ok((row, read_json(&polygons)?))
}

/// Simulates `frames` range-camera frames of the lab into `dir` (see [`lab_poses`]); returns
/// the scene's truth and one input per frame with the true planes it shows.
fn lab_inputs(frames: usize, dir: &Path) -> Result<(truth::SceneTruth, Vec<Input>)> {
    if dir.exists() {
        std::fs::remove_dir_all(dir).with_context(|| format!("removing {}", dir.display()))?;
    }
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    eprintln!("segmentation: simulating {frames} range-camera frames of the lab");
    let scene = scene_sim::scene_by_name("lab", LAB_SEED).context("building the lab scene")?;
    let camera = RangeCamera::swissranger_sr3000();
    let poses = lab_poses(&scene, frames);
    if poses.len() < frames {
        bail!("the lab has room for only {} camera poses, {frames} asked", poses.len());
    }
    let options =
        PlyWriteOptions { encoding: PlyEncoding::BinaryLittleEndian, precision: Precision::F32 };
    let mut inputs = Vec::new();
    let mut labels = Vec::new();
    for (i, pose) in poses.iter().enumerate() {
        let seed = scene_sim::sensors::derive_seed(LAB_SEED, i as u64);
        let cloud = camera.scan(&scene, pose, seed).to_cloud().context("building a lab frame")?;
        let path = dir.join(format!("frame{i:03}.ply"));
        pointcloud::io::write_atomically(&path, |w| {
            write_ply(w, &cloud, &options).with_context(|| format!("writing {}", path.display()))
        })?;
        labels.push(cloud.labels().context("a simulated frame without labels")?.to_vec());
        inputs.push(path);
    }
    let truth = truth::SceneTruth::new(scene);
    eprintln!("segmentation: the lab has {} true planes", truth.num_planes());
    let inputs = inputs
        .into_iter()
        .zip(labels)
        .enumerate()
        .map(|(i, (cloud, labels))| Input {
            name: format!("lab/frame{i:03}"),
            set: Set::Lab,
            cloud,
            scoring: Scoring::Lab(truth.visible(&labels)),
            sensor: TIME_OF_FLIGHT,
        })
        .collect();
    Ok((truth, inputs))
}

/// The lab frames' camera poses: the positions of [`scene_sim::Scene::scan_poses`] (seed
/// [`LAB_SEED`], well spread and collision-free) at [`LAB_HEIGHT`], each camera turned towards
/// [`LAB_TARGET`] and tilted down by [`LAB_PITCH_DEG`], so that a frame shows floor, walls
/// and furniture rather than one bare wall (the seeded yaw is kept where the target is under 1 m
/// away).
fn lab_poses(scene: &scene_sim::Scene, frames: usize) -> Vec<pointcloud::SensorPose> {
    scene
        .scan_poses(frames, LAB_HEIGHT, LAB_SEED)
        .iter()
        .map(|body| {
            let p = body.world_from_sensor.translation.vector;
            let (dx, dy) = (LAB_TARGET[0] - p.x, LAB_TARGET[1] - p.y);
            let yaw = if dx.hypot(dy) >= 1.0 {
                dy.atan2(dx)
            } else {
                body.world_from_sensor.rotation.euler_angles().2
            };
            scene_sim::camera_pose_looking(
                pointcloud::Point3::new(p.x, p.y, LAB_HEIGHT),
                yaw,
                -LAB_PITCH_DEG.to_radians(),
            )
        })
        .collect()
}

/// Converts the real frames under `real` to organised PLY files in `dir`; a missing folder or
/// frame, or one that does not convert, becomes a note.
fn real_inputs(env: &Env, real: &Path, dir: &Path, notes: &mut Vec<String>) -> Result<Vec<Input>> {
    let mut note = |n: String| {
        eprintln!("segmentation: {n}");
        notes.push(n);
    };
    if !real.is_dir() {
        note(format!(
            "real frames skipped: {} not found (set {REAL_DATA_VAR} to the real-data folder)",
            real.display()
        ));
        return Ok(Vec::new());
    }
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let mut inputs = Vec::new();
    for frame in &REAL_FRAMES {
        let ply = dir.join(format!("{}.ply", frame.name));
        let (sources, a): (Vec<PathBuf>, Vec<String>) = match frame.source {
            RealSource::Cloud { file, depth_camera } => {
                let src = real.join(file);
                let mut a = vec!["--quiet".into(), "convert".into(), arg(&src), arg(&ply)];
                if let Some(camera) = depth_camera {
                    a.extend(["--depth-camera".into(), camera.into()]);
                }
                (vec![src], a)
            }
            RealSource::Tof { range, amplitude, meta } => {
                let [r, am, m] = [range, amplitude, meta].map(|f| real.join(f));
                let a = ["--quiet", "tof", "filter", "--method", "at", "--at", "0"]
                    .map(str::to_owned)
                    .into_iter()
                    .chain(["--range".into(), arg(&r), "--amplitude".into(), arg(&am)])
                    .chain(["--meta".into(), arg(&m), "--out".into(), arg(&ply)])
                    .collect();
                (vec![r, am, m], a)
            }
        };
        if let Some(missing) = sources.iter().find(|s| !s.is_file()) {
            note(format!("real frame {} skipped: {} not found", frame.name, missing.display()));
            continue;
        }
        if let Err(e) = json_lines(&env.patchnav, &a) {
            note(format!("real frame {} skipped: {e:#}", frame.name));
            continue;
        }
        inputs.push(Input {
            name: format!("real/{}", frame.name),
            set: Set::Real,
            cloud: ply,
            scoring: Scoring::Coverage,
            sensor: frame.sensor,
        });
    }
    Ok(inputs)
}

fn read_json(path: &Path) -> Result<Value> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    serde_json::from_str(&text).with_context(|| format!("{} is not JSON", path.display()))
}

/// The share of a run's valid points assigned to a plane (`inliers / points`).
fn coverage(row: &Value) -> Option<f64> {
    let inliers = row.get("inliers").and_then(Value::as_f64)?;
    let points = row.get("points").and_then(Value::as_f64)?;
    (points > 0.0 && inliers >= 0.0).then(|| inliers / points)
}

/// One side's runs on one input.
#[derive(Clone, Debug, Default)]
struct Side {
    method: String,
    runs: usize,
    time: Option<f64>,
    normals: Option<f64>,
    seg: Option<f64>,
    hull: Option<f64>,
    rss: Option<f64>,
    /// The first run's row (counts and quality do not change between repetitions).
    first: Value,
    skipped: Vec<String>,
}

impl Side {
    fn of(rows: &[&Value]) -> Option<Side> {
        let ok: Vec<&Value> = rows.iter().copied().filter(|r| r.get("skipped").is_none()).collect();
        let skipped: Vec<String> = rows
            .iter()
            .filter_map(|r| r.get("skipped").and_then(Value::as_str).map(str::to_owned))
            .collect();
        if ok.is_empty() && skipped.is_empty() {
            return None;
        }
        let med = |k: &str| median(ok.iter().filter_map(|r| r.get(k).and_then(Value::as_f64)));
        let first = ok.first().map_or(Value::Null, |r| (*r).clone());
        Some(Side {
            method: first["method"].as_str().unwrap_or("?").to_owned(),
            runs: ok.len(),
            time: med("time_s"),
            normals: med("time_normals_s"),
            seg: med("time_seg_s"),
            hull: med("time_hull_s"),
            rss: med("peak_rss_kib"),
            first,
            skipped,
        })
    }

    fn q(&self, key: &str) -> Option<f64> {
        self.first.get("quality").and_then(|q| q.get(key)).and_then(Value::as_f64)
    }

    fn count(&self, key: &str) -> String {
        self.first.get(key).and_then(Value::as_f64).map_or("–".to_owned(), |v| format!("{v:.0}"))
    }

    fn found(&self) -> String {
        match (self.q("true_planes_found"), self.q("true_planes_visible")) {
            (Some(f), Some(v)) => format!("{f:.0}/{v:.0}"),
            _ => "–".to_owned(),
        }
    }
}

/// Both sides on one input, in the order the rows came.
#[derive(Clone, Debug)]
struct PerInput {
    input: String,
    set: String,
    pcl: Option<Side>,
    ours: Option<Side>,
}

impl PerInput {
    /// The ratio ours / theirs of the median times, when both sides ran.
    fn time_ratio(&self) -> Option<f64> {
        let t = |s: &Option<Side>| s.as_ref().and_then(|s| s.time);
        match (t(&self.ours), t(&self.pcl)) {
            (Some(a), Some(b)) if b > 0.0 && a.is_finite() && b.is_finite() => Some(a / b),
            _ => None,
        }
    }
}

fn per_input(rows: &[Value]) -> Vec<PerInput> {
    let mut names: Vec<(&str, &str)> = Vec::new();
    for r in rows {
        let name = r.get("input").and_then(Value::as_str).unwrap_or("?");
        if !names.iter().any(|(n, _)| *n == name) {
            names.push((name, r.get("set").and_then(Value::as_str).unwrap_or("?")));
        }
    }
    names
        .into_iter()
        .map(|(name, set)| {
            let pick = |side: &str| -> Vec<&Value> {
                rows.iter()
                    .filter(|r| r["input"] == json!(name) && r["side"] == json!(side))
                    .collect()
            };
            PerInput {
                input: name.to_owned(),
                set: set.to_owned(),
                pcl: Side::of(&pick("pcl")),
                ours: Side::of(&pick("ours")),
            }
        })
        .collect()
}

/// The tables: scored inputs, real frames, overall.
fn tables(rows: &[Value]) -> String {
    let inputs = per_input(rows);
    let mut out = String::new();
    let mut skipped = Vec::new();
    let scored: Vec<&PerInput> = inputs.iter().filter(|i| i.set != Set::Real.key()).collect();
    if !scored.is_empty() {
        out.push_str(
            "### Inputs with ground truth\n\n\
             | input | side | method | runs | median time s | normals / segmentation / hulls s | planes | polygons | polygon vertices | true planes found | planes off truth | vertices on surface | points in planes | peak RSS KiB | time ours/theirs |\n\
             |---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
        );
        for i in &scored {
            for (label, s) in sides(i, &mut skipped) {
                let _ = writeln!(
                    out,
                    "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                    row_head(i, label, s),
                    s.count("planes"),
                    s.count("polygons"),
                    s.count("polygon_vertices"),
                    s.found(),
                    s.q("planes_off_truth").map_or("–".to_owned(), |v| format!("{v:.0}")),
                    num(s.q("vertices_on_surface")),
                    num(s.q("points_in_planes")),
                    num(s.rss),
                    if label == "ours" { ratio_of(i) } else { String::new() },
                );
            }
        }
    }
    let real: Vec<&PerInput> = inputs.iter().filter(|i| i.set == Set::Real.key()).collect();
    if !real.is_empty() {
        out.push_str(
            "\n### Real frames (no ground truth)\n\n\
             | input | side | method | runs | median time s | normals / segmentation / hulls s | valid points | planes | polygons | polygon vertices | points in planes | peak RSS KiB | time ours/theirs |\n\
             |---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
        );
        for i in &real {
            for (label, s) in sides(i, &mut skipped) {
                let _ = writeln!(
                    out,
                    "| {} | {} | {} | {} | {} | {} | {} | {} |",
                    row_head(i, label, s),
                    s.count("points"),
                    s.count("planes"),
                    s.count("polygons"),
                    s.count("polygon_vertices"),
                    num(s.q("points_in_planes")),
                    num(s.rss),
                    if label == "ours" { ratio_of(i) } else { String::new() },
                );
            }
        }
    }
    out.push_str(&overall(&inputs));
    skipped.sort();
    skipped.dedup();
    for s in skipped {
        let _ = writeln!(out, "\nNote: {s}.");
    }
    out
}

/// The sides of `i` that ran (PCL, then ours), their skipped-run notes added to `skipped`.
fn sides<'a>(i: &'a PerInput, skipped: &mut Vec<String>) -> Vec<(&'static str, &'a Side)> {
    let mut out = Vec::new();
    for (label, side) in [("PCL", &i.pcl), ("ours", &i.ours)] {
        let Some(s) = side else { continue };
        skipped.extend(s.skipped.iter().cloned());
        if s.runs > 0 {
            out.push((label, s));
        }
    }
    out
}

/// The first columns of a side's row: input, side, method, runs, median time, stage times.
fn row_head(i: &PerInput, label: &str, s: &Side) -> String {
    format!(
        "{} | {label} | {} | {} | {} | {} / {} / {}",
        i.input,
        s.method,
        s.runs,
        num(s.time),
        num(s.normals),
        num(s.seg),
        num(s.hull)
    )
}

fn ratio_of(i: &PerInput) -> String {
    ratio(i.ours.as_ref().and_then(|s| s.time), i.pcl.as_ref().and_then(|s| s.time))
}

/// Quality and time of one group of inputs, both sides.
#[derive(Clone, Debug, Default, PartialEq)]
struct Overall {
    /// Inputs where both sides ran.
    inputs: usize,
    /// Median, smallest and largest per-input time ratio ours / theirs.
    ratio: Option<(f64, f64, f64)>,
    /// Per side (PCL, ours): true planes found and visible, summed over the inputs with truth.
    found: [(u64, u64); 2],
    /// Per side: planes off truth, summed.
    off: [u64; 2],
    /// Per side: median over the inputs of the share of vertices on a surface.
    on_surface: [Option<f64>; 2],
    /// Per side: median over the inputs of the share of valid points in planes.
    in_planes: [Option<f64>; 2],
    /// Whether any input of the group has ground truth.
    scored: bool,
}

fn summarise(inputs: &[&PerInput]) -> Overall {
    let both: Vec<&&PerInput> = inputs
        .iter()
        .filter(|i| {
            i.pcl.as_ref().zip(i.ours.as_ref()).is_some_and(|(a, b)| a.runs > 0 && b.runs > 0)
        })
        .collect();
    let ratios: Vec<f64> = both.iter().filter_map(|i| i.time_ratio()).collect();
    let mut o = Overall { inputs: both.len(), ..Overall::default() };
    if let Some(m) = median(ratios.clone()) {
        let lo = ratios.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = ratios.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        o.ratio = Some((m, lo, hi));
    }
    for k in 0..2 {
        let sides: Vec<&Side> = both
            .iter()
            .filter_map(|i| if k == 0 { i.pcl.as_ref() } else { i.ours.as_ref() })
            .collect();
        for s in &sides {
            if let (Some(f), Some(v)) = (s.q("true_planes_found"), s.q("true_planes_visible")) {
                o.found[k].0 += f as u64;
                o.found[k].1 += v as u64;
                o.scored = true;
            }
            o.off[k] += s.q("planes_off_truth").unwrap_or(0.0) as u64;
        }
        o.on_surface[k] = median(sides.iter().filter_map(|s| s.q("vertices_on_surface")));
        o.in_planes[k] = median(sides.iter().filter_map(|s| s.q("points_in_planes")));
    }
    o
}

/// The overall table (per set and over all inputs) and the overall line.
fn overall(inputs: &[PerInput]) -> String {
    let mut out = String::from(
        "\n### Overall\n\n\
         | inputs | count | time ours/theirs: median (min–max) | true planes found PCL | ours | planes off truth PCL | ours | vertices on surface PCL | ours | points in planes PCL | ours |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let groups = Set::ALL
        .iter()
        .map(|s| (s.title(), inputs.iter().filter(|i| i.set == s.key()).collect::<Vec<_>>()))
        .chain(std::iter::once(("all", inputs.iter().collect())));
    let mut all = Overall::default();
    for (title, group) in groups {
        if group.is_empty() {
            continue;
        }
        let o = summarise(&group);
        let r = o.ratio.map_or("–".to_owned(), |(m, lo, hi)| {
            format!("{} ({}–{})", num(Some(m)), num(Some(lo)), num(Some(hi)))
        });
        let found = |k: usize| {
            if o.scored { format!("{}/{}", o.found[k].0, o.found[k].1) } else { "–".into() }
        };
        let off = |k: usize| if o.scored { o.off[k].to_string() } else { "–".into() };
        let _ = writeln!(
            out,
            "| {title} | {} | {r} | {} | {} | {} | {} | {} | {} | {} | {} |",
            o.inputs,
            found(0),
            found(1),
            off(0),
            off(1),
            num(o.on_surface[0]),
            num(o.on_surface[1]),
            num(o.in_planes[0]),
            num(o.in_planes[1]),
        );
        all = o;
    }
    if let Some((m, lo, hi)) = all.ratio {
        let _ = writeln!(
            out,
            "\nOverall: over {} inputs, ours takes a median {} of PCL's time (per input {}–{}); \
             true planes found: PCL {}/{}, ours {}/{}; planes off truth: PCL {}, ours {}; \
             median share of valid points in planes: PCL {}, ours {}.",
            all.inputs,
            num(Some(m)),
            num(Some(lo)),
            num(Some(hi)),
            all.found[0].0,
            all.found[0].1,
            all.found[1].0,
            all.found[1].1,
            all.off[0],
            all.off[1],
            num(all.in_planes[0]),
            num(all.in_planes[1]),
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A row as the runs give it, with a quality object.
    fn row(input: &str, set: &str, side: &str, time: f64, quality: Value) -> Value {
        json!({
            "kind": "planes", "method": if side == "pcl" { "omps+concave-hull" } else { "region-growing" },
            "input": input, "set": set, "side": side, "time_s": time, "time_seg_s": time / 2.0,
            "planes": 4, "polygons": 4, "polygon_vertices": 40, "points": 1000, "inliers": 800,
            "peak_rss_kib": 1000, "quality": quality,
        })
    }

    fn truth_q(found: u64, visible: u64, off: u64, on: f64) -> Value {
        json!({"true_planes_found": found, "true_planes_visible": visible, "planes_off_truth": off,
               "vertices_on_surface": on, "points_in_planes": 0.8})
    }

    fn rows() -> Vec<Value> {
        let mut rows = Vec::new();
        for t in [1.0, 3.0, 2.0] {
            rows.push(row("floorplan_scan", "floorplan", "pcl", t, truth_q(7, 10, 3, 1.0)));
            rows.push(row("floorplan_scan", "floorplan", "ours", t / 4.0, truth_q(9, 10, 1, 1.0)));
            rows.push(row("lab/scan000", "lab", "pcl", t, truth_q(2, 3, 0, 0.9)));
            rows.push(row("lab/scan000", "lab", "ours", t / 2.0, truth_q(3, 3, 1, 0.7)));
            rows.push(row("real/a", "real", "pcl", t, json!({"points_in_planes": 0.4})));
            rows.push(row("real/a", "real", "ours", t, json!({"points_in_planes": 0.9})));
        }
        rows
    }

    #[test]
    fn lab_cameras_stand_apart_and_look_down_into_the_room() {
        let scene = scene_sim::scene_by_name("lab", LAB_SEED).unwrap();
        let poses = lab_poses(&scene, LAB_FRAMES);
        assert_eq!(poses.len(), LAB_FRAMES);
        for (i, pose) in poses.iter().enumerate() {
            let m = &pose.world_from_sensor;
            let p = m.translation.vector;
            assert!((p.z - LAB_HEIGHT).abs() < 1e-9);
            // the optical axis (z) points down by the pitch, towards the target
            let axis = m.rotation * pointcloud::Vector3::z();
            assert!((axis.z + LAB_PITCH_DEG.to_radians().sin()).abs() < 1e-9, "{axis:?}");
            let to_target = pointcloud::Vector3::new(LAB_TARGET[0] - p.x, LAB_TARGET[1] - p.y, 0.0);
            if to_target.norm() >= 1.0 {
                let heading = pointcloud::Vector3::new(axis.x, axis.y, 0.0).normalize();
                assert!(heading.dot(&to_target.normalize()) > 1.0 - 1e-9, "{heading:?}");
            }
            // the image's horizontal axis (x) is level
            assert!((m.rotation * pointcloud::Vector3::x()).z.abs() < 1e-9);
            for q in &poses[..i] {
                assert!((q.world_from_sensor.translation.vector - p).norm() > 0.5);
            }
        }
    }

    #[test]
    fn coverage_is_inliers_over_points() {
        assert_eq!(coverage(&json!({"inliers": 30, "points": 120})), Some(0.25));
        assert_eq!(coverage(&json!({"inliers": 30, "points": 0})), None);
        assert_eq!(coverage(&json!({"points": 10})), None);
        assert_eq!(coverage(&json!({"inliers": null, "points": 10})), None);
    }

    #[test]
    fn per_input_groups_rows_in_order_with_median_times() {
        let inputs = per_input(&rows());
        let names: Vec<&str> = inputs.iter().map(|i| i.input.as_str()).collect();
        assert_eq!(names, ["floorplan_scan", "lab/scan000", "real/a"]);
        let fp = &inputs[0];
        assert_eq!(fp.pcl.as_ref().unwrap().runs, 3);
        assert_eq!(fp.pcl.as_ref().unwrap().time, Some(2.0));
        assert_eq!(fp.ours.as_ref().unwrap().time, Some(0.5));
        assert_eq!(fp.time_ratio(), Some(0.25));
        assert_eq!(inputs[1].time_ratio(), Some(0.5));
        assert_eq!(inputs[2].time_ratio(), Some(1.0));
    }

    #[test]
    fn overall_takes_the_median_ratio_and_sums_planes() {
        let inputs = per_input(&rows());
        let all: Vec<&PerInput> = inputs.iter().collect();
        let o = summarise(&all);
        assert_eq!(o.inputs, 3);
        assert_eq!(o.ratio, Some((0.5, 0.25, 1.0)));
        assert!(o.scored);
        assert_eq!(o.found, [(9, 13), (12, 13)]);
        assert_eq!(o.off, [3, 2]);
        assert_eq!(o.on_surface, [Some(0.95), Some(0.85)]);
        assert_eq!(o.in_planes, [Some(0.8), Some(0.8)]);
        let real: Vec<&PerInput> = inputs.iter().filter(|i| i.set == "real").collect();
        let o = summarise(&real);
        assert!(!o.scored);
        assert_eq!(o.in_planes, [Some(0.4), Some(0.9)]);
    }

    #[test]
    fn a_skipped_side_is_noted_and_left_out_of_the_ratios() {
        let mut rows = rows();
        rows.push(
            json!({"kind": "planes", "skipped": "real/b (pcl) skipped: boom", "input": "real/b",
                         "set": "real", "side": "pcl", "rep": 0}),
        );
        rows.push(row("real/b", "real", "ours", 0.1, json!({"points_in_planes": 0.5})));
        let inputs = per_input(&rows);
        assert_eq!(inputs.len(), 4);
        assert_eq!(inputs[3].time_ratio(), None);
        let all: Vec<&PerInput> = inputs.iter().collect();
        assert_eq!(summarise(&all).inputs, 3);
        let text = tables(&rows);
        assert!(text.contains("Note: real/b (pcl) skipped: boom."), "{text}");
        assert!(text.contains("| real/b | ours |"), "{text}");
        assert!(!text.contains("| real/b | PCL |"), "{text}");
    }

    #[test]
    fn tables_have_one_line_per_input_and_side_and_an_overall_line() {
        let text = tables(&rows());
        for needle in [
            "| floorplan_scan | PCL | omps+concave-hull | 3 | 2.000 |",
            "| floorplan_scan | ours | region-growing | 3 | 0.500 |",
            "| 7/10 | 3 | 1.000 | 0.800 |",
            "| lab/scan000 | ours |",
            "### Real frames (no ground truth)",
            "| real/a | ours | region-growing | 3 | 2.000 | – / 1.000 / – | 1000 | 4 | 4 | 40 | 0.900 |",
            "| all | 3 | 0.500 (0.250–1.000) | 9/13 | 12/13 | 3 | 2 |",
            "| real frames | 1 | 1.000 (1.000–1.000) | – | – | – | – |",
            "Overall: over 3 inputs, ours takes a median 0.500 of PCL's time",
        ] {
            assert!(text.contains(needle), "missing `{needle}` in\n{text}");
        }
        // table rows have as many cells as their header
        for table in text.split("\n\n").filter(|t| t.starts_with('|')) {
            let cells = |l: &str| l.matches('|').count();
            let mut lines = table.lines();
            let header = cells(lines.next().unwrap());
            assert!(lines.all(|l| cells(l) == header), "{table}");
        }
    }
}
