//! `patchnav simulate SCENE --sensor alrf|tof|stereo --poses N --out DIR`.
//!
//! Writes, into `DIR`:
//! * `scanNNN.ply`: the measured organised cloud in the sensor frame (binary PLY, float
//!   positions), with `comment organized W H` and `comment sensor_to_world …` so any reader of
//!   the shared exchange format can place it; the `label` property is the surface each beam hit;
//! * `scanNNN_truth.ply`: the noise-free organised cloud of every pixel whose beam hit a surface,
//!   with `label` (surface id), `true_range`, `incidence_cos`, `reflectivity` and `mixed_pixel`;
//! * `poses.json`: every scan's `world_from_sensor` (translation, quaternion, 4 × 4 matrix);
//! * `scene.json`: the scene, seed, sensor, bounds and the table of surfaces.

use crate::progress::Progress;
use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use pointcloud::io::ply::{PlyEncoding, PlyWriteOptions, write_ply};
use pointcloud::io::{Precision, write_atomically, write_bytes_atomically};
use pointcloud::{FieldData, PointCloud, RangeImage, ScalarField, SensorPose};
use scene_sim::{
    Alrf, AlrfConfig, RangeCamera, RangeSensor, Scene, SimulatedScan, StereoCamera, scene_by_name,
    scene_names,
};
use serde_json::json;
use std::path::{Path, PathBuf};

/// The sensors `simulate` offers.
#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum SensorChoice {
    /// Actuated laser range finder, SICK S300-like: 541 × 361 beams over 270° × 180°, 0–20 m.
    Alrf,
    /// Time-of-flight range camera, SwissRanger SR-3000-like: 176 × 144 pixels, 47° × 39°.
    Tof,
    /// Stereo camera, STOC-like: 640 × 480 pixels, noise growing with range squared.
    Stereo,
}

/// Arguments of `patchnav simulate`.
#[derive(Args, Debug)]
pub struct SimulateArgs {
    /// The scene: office, lab, or a terrain scene (terrain-floor, terrain-ramp, ...).
    pub scene: String,
    /// The simulated sensor.
    #[arg(long, value_enum)]
    pub sensor: SensorChoice,
    /// How many scans, from well-spread collision-free poses.
    #[arg(long, default_value_t = 3)]
    pub poses: usize,
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Seed of the scene, the poses and the sensor noise.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Height of the sensor above the floor, metres.
    #[arg(long, default_value_t = 0.5)]
    pub height: f64,
    /// Angular step of the actuated laser range finder in degrees (default: the S300's 0.5°).
    #[arg(long)]
    pub step_deg: Option<f64>,
}

/// Upper bound on `--poses`: each scan is written as files, so this guards against typos.
const MAX_POSES: usize = 10_000;

/// Runs `patchnav simulate`.
pub fn run(args: &SimulateArgs, progress: &Progress) -> Result<()> {
    if args.poses == 0 || args.poses > MAX_POSES {
        bail!("--poses must be between 1 and {MAX_POSES}, got {}", args.poses);
    }
    if !(args.height.is_finite() && args.height > 0.0) {
        bail!("--height must be a positive number of metres, got {}", args.height);
    }
    if !scene_names().contains(&args.scene.as_str()) {
        bail!("unknown scene `{}`; choose one of: {}", args.scene, scene_names().join(", "));
    }
    let scene = scene_by_name(&args.scene, args.seed)
        .with_context(|| format!("building scene `{}`", args.scene))?;
    let sensor = make_sensor(args)?;
    let bodies = scene.scan_poses(args.poses, args.height, args.seed);
    if bodies.len() < args.poses {
        bail!(
            "scene `{}` has room for only {} sensor poses at height {} m",
            args.scene,
            bodies.len(),
            args.height
        );
    }
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;

    let bar = progress.bar(bodies.len() as u64, "scanning");
    let mut pose_rows = Vec::new();
    let mut total_points = 0usize;
    for (i, body) in bodies.iter().enumerate() {
        let pose = sensor.mount(body);
        let scan = sensor.scan(&scene, &pose, scene_sim::sensors::derive_seed(args.seed, i as u64));
        let name = format!("scan{i:03}.ply");
        let cloud = scan.to_cloud().context("building the measured cloud")?;
        total_points += cloud.len();
        write_cloud_ply(&args.out.join(&name), &cloud)?;
        let truth = truth_cloud(&scan).context("building the ground-truth cloud")?;
        write_cloud_ply(&args.out.join(format!("scan{i:03}_truth.ply")), &truth)?;
        pose_rows.push(pose_json(&name, &scan.pose));
        bar.inc(1);
    }
    bar.finish_and_clear();

    write_json(&args.out.join("poses.json"), &json!({ "scans": pose_rows }))?;
    write_json(&args.out.join("scene.json"), &scene_json(&scene, args))?;
    progress.say(format!(
        "wrote {} scans of `{}` ({} points) to {}",
        bodies.len(),
        args.scene,
        total_points,
        args.out.display()
    ));
    Ok(())
}

fn make_sensor(args: &SimulateArgs) -> Result<Box<dyn RangeSensor>> {
    Ok(match args.sensor {
        SensorChoice::Alrf => {
            let config = match args.step_deg {
                None => AlrfConfig::sick_s300(),
                Some(step) => AlrfConfig::sick_s300_with_step(step.to_radians())
                    .with_context(|| format!("--step-deg {step}"))?,
            };
            Box::new(Alrf::new(config)?)
        }
        SensorChoice::Tof | SensorChoice::Stereo if args.step_deg.is_some() => {
            bail!("--step-deg applies only to --sensor alrf")
        }
        SensorChoice::Tof => Box::new(RangeCamera::swissranger_sr3000()),
        SensorChoice::Stereo => Box::new(StereoCamera::stoc()),
    })
}

/// The noise-free organised cloud of every pixel whose beam hit a surface, with the truth
/// attributes.
fn truth_cloud(scan: &SimulatedScan) -> Result<PointCloud> {
    let image = &scan.image;
    let truth = &scan.truth;
    let ideal = RangeImage::new(
        image.width(),
        image.height(),
        *image.beams(),
        image.kind(),
        truth.true_range.clone(),
    )?;
    let mut cloud = ideal.to_cloud()?;
    let hit: Vec<usize> =
        (0..truth.true_range.len()).filter(|&i| truth.true_range[i].is_some()).collect();
    let f32s =
        |v: &[Option<f32>]| hit.iter().map(|&i| v[i].unwrap_or(f32::NAN)).collect::<Vec<_>>();
    cloud.set_labels(Some(
        hit.iter().map(|&i| truth.surface[i].map_or(u32::MAX, |s| s.0)).collect(),
    ))?;
    let fields = [
        ("true_range", FieldData::F32(f32s(&truth.true_range))),
        ("incidence_cos", FieldData::F32(f32s(&truth.incidence_cos))),
        ("reflectivity", FieldData::F32(f32s(&truth.reflectivity))),
        (
            "mixed_pixel",
            FieldData::U8(hit.iter().map(|&i| u8::from(truth.mixed_pixel[i])).collect()),
        ),
    ];
    for (name, data) in fields {
        cloud.push_extra_field(ScalarField { name: name.to_owned(), data })?;
    }
    cloud.set_sensor_pose(Some(scan.pose));
    Ok(cloud)
}

fn write_cloud_ply(path: &Path, cloud: &PointCloud) -> Result<()> {
    let options =
        PlyWriteOptions { encoding: PlyEncoding::BinaryLittleEndian, precision: Precision::F32 };
    write_atomically(path, |w| write_ply(w, cloud, &options)).map_err(|e| e.with_path(path))?;
    Ok(())
}

fn pose_json(file: &str, pose: &SensorPose) -> serde_json::Value {
    let m = pose.world_from_sensor.to_homogeneous();
    let t = pose.world_from_sensor.translation.vector;
    let q = pose.world_from_sensor.rotation;
    let rows: Vec<Vec<f64>> = (0..4).map(|r| (0..4).map(|c| m[(r, c)]).collect()).collect();
    json!({
        "file": file,
        "translation": [t.x, t.y, t.z],
        "rotation_xyzw": [q.i, q.j, q.k, q.w],
        "world_from_sensor": rows,
    })
}

fn scene_json(scene: &Scene, args: &SimulateArgs) -> serde_json::Value {
    let b = scene.bounds();
    let surfaces: Vec<_> = scene
        .surfaces()
        .iter()
        .map(|s| {
            json!({
                "id": s.id.0,
                "name": s.name,
                "reflectivity": s.material.reflectivity,
                "textured": s.material.textured,
                "planar": s.plane.is_some(),
            })
        })
        .collect();
    json!({
        "scene": args.scene,
        "seed": args.seed,
        "sensor": format!("{:?}", args.sensor).to_lowercase(),
        "sensor_height_m": args.height,
        "bounds": { "min": [b.min.x, b.min.y, b.min.z], "max": [b.max.x, b.max.y, b.max.z] },
        "surfaces": surfaces,
    })
}

fn write_json(path: &Path, value: &serde_json::Value) -> Result<()> {
    let text = serde_json::to_string_pretty(value)?;
    write_bytes_atomically(path, text + "\n")?;
    Ok(())
}
