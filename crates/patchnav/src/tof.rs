//! `patchnav tof filter|calibrate`: time-of-flight frames (thesis §2.5.5; `sensor_tof`).
//!
//! ```text
//! patchnav tof filter --range R.png --amplitude A.png --meta M.json --method regions|aat|at|two-freq
//!     [--at 160] [--aat 0.2] [--calibration C.json] [--unwrap] [--low-at X] [--radial]
//!     [--clamp-corners] [--range2 R2.png --amplitude2 A2.png --meta2 M2.json]
//!     --out cloud.ply [--png outcomes.png] [--dense|--safe]
//! patchnav tof filter --cloud F.ply --meta M.json ...
//! patchnav tof filter --cloud BAG --topic T --meta M.json ...   (one line per message)
//! patchnav tof calibrate [WHITE_WALL] [--range R.png --amplitude A.png] --meta M.json
//!     [--fixed-curvature] [--radial] [--trim SIGMA] [--table T.json] --out calib.json
//! ```
//!
//! A frame is a 16-bit range PNG and a 16-bit amplitude PNG with a JSON sidecar
//! (`sensor_tof::io`, which also reads the ifm O3R `frame_meta.json`), or an organised cloud
//! whose intensity is the amplitude (any format `pointcloud::io` reads) with a sidecar for the
//! camera.

use crate::progress::Progress;
use anyhow::{Context, Result, bail};
use clap::Args;
use patch_pipeline::tof::{
    FilterSetup, FrameSource, Method, filter_frame, filter_loaded, load_frame,
};
use pointcloud::Real;
use sensor_tof::calibrate::{CalibrationOptions, fit_parabola, white_wall_table};
use sensor_tof::io::{frame_from_cloud, read_meta, write_json, write_rgb_png};
use sensor_tof::two_freq::SR3000_PHASE_NOISE_RAD;
use sensor_tof::{AatRange, FilterOutput, PixelOutcome, TofFrame};
use std::path::PathBuf;

/// Time-of-flight subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum TofCommand {
    /// Filter a frame for wrap-around (AAT, thesis Eq 2.4), a plain amplitude threshold, or
    /// two-frequency unwrapping, and write the output cloud.
    ///
    /// The cloud (PLY or any format by extension) has per point the fields `outcome` (u8:
    /// 0 kept, 1 unwrapped, 2 dropped) and `pixel` (u32, row-major index) and the amplitude as
    /// intensity. `--png` writes an 8-bit RGB image of the outcomes: kept pixels grey (brighter
    /// = nearer), unwrapped pixels blue (brighter = nearer, on the same range scale), dropped
    /// pixels red, pixels without a measurement black.
    Filter(FilterArgs),
    /// Fit the illumination parabola (Eq 2.5 with a curvature) to a frame of a perpendicular
    /// white wall and write it as JSON (a sidecar's `aat.calibration` can name it).
    Calibrate(CalibrateArgs),
    /// Simulate a frame of one of the six test scenes of thesis Table 2.4 (SR-3100, wrap-around,
    /// noise, sunlight, scattering, dark materials) as a PNG pair + sidecar, with the truth.
    Simulate(crate::tof_sim::SimulateArgs),
}

/// The frame to read: a PNG pair, or an organised cloud, with its sidecar.
#[derive(Debug, Args)]
pub struct FrameArgs {
    /// 16-bit range PNG (values × `metres_per_unit` of the sidecar; 0 = no measurement).
    #[arg(long, requires = "amplitude")]
    pub range: Option<PathBuf>,
    /// 16-bit amplitude PNG.
    #[arg(long, requires = "range")]
    pub amplitude: Option<PathBuf>,
    /// Optional 8- or 16-bit confidence PNG.
    #[arg(long, requires = "range")]
    pub confidence: Option<PathBuf>,
    /// JSON sidecar: image size, scales, range kind, intrinsics, modulation frequency, AAT
    /// parameters (or an ifm O3R `frame_meta.json`).
    #[arg(long)]
    pub meta: PathBuf,
}

/// Arguments of `patchnav tof filter`.
#[derive(Debug, Args)]
pub struct FilterArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
    /// An organised cloud whose intensity is the amplitude, instead of the PNG pair (the
    /// sidecar gives the camera).
    #[arg(long, conflicts_with_all = ["range", "amplitude", "confidence"])]
    pub cloud: Option<PathBuf>,
    /// The filter.
    #[arg(long, value_parser = crate::names::all::<Method>(), default_value_t = Method::Regions)]
    pub method: Method,
    /// The plain amplitude threshold of `--method at` (the thesis's baselines: 160 and 240).
    #[arg(long, default_value_t = 160.0)]
    pub at: Real,
    /// Override the sidecar's AAT (apparent-reflectivity threshold; the thesis uses 0.2).
    #[arg(long)]
    pub aat: Option<Real>,
    /// Take the illumination parabola from a calibration JSON (`patchnav tof calibrate`)
    /// instead of the sidecar.
    #[arg(long)]
    pub calibration: Option<PathBuf>,
    /// Unwrap the pixels the AAT flags (one non-ambiguity range further along the beam).
    #[arg(long)]
    pub unwrap: bool,
    /// With `--method aat --unwrap`: drop instead of unwrapping flagged pixels with amplitude
    /// ≤ X (very dark, probably wrapped more than once); with `--method regions`: drop pixels
    /// with amplitude ≤ X before segmenting.
    #[arg(long)]
    pub low_at: Option<Real>,
    /// Use the radial distance as Eq 2.4's r_p (default: the depth, as the thesis).
    #[arg(long)]
    pub radial: bool,
    /// Clamp the illumination model to at least this fraction of its maximum (0.04 if given
    /// without a value), so the image corners where Eq 2.5 goes negative are tested too
    /// (default: they always pass, as Eq 2.4 literally says).
    #[arg(long, num_args = 0..=1, default_missing_value = "0.04", value_name = "FRACTION")]
    pub clamp_corners: Option<Real>,
    /// Two-frequency: the second frame's range PNG.
    #[arg(long, requires_all = ["amplitude2", "meta2"])]
    pub range2: Option<PathBuf>,
    /// Two-frequency: the second frame's amplitude PNG.
    #[arg(long)]
    pub amplitude2: Option<PathBuf>,
    /// Two-frequency: the second frame's sidecar (its `modulation_hz` must differ).
    #[arg(long)]
    pub meta2: Option<PathBuf>,
    /// Two-frequency: candidates beyond this radial distance are not considered, metres (the
    /// 20 + 5 MHz preset's 29.5 m).
    #[arg(long, default_value_t = 29.5)]
    pub max_range: Real,
    /// Two-frequency: the phase noise, radians (sets the tolerance to 3 σ of the disagreement).
    #[arg(long, default_value_t = SR3000_PHASE_NOISE_RAD)]
    pub phase_noise: Real,
    /// Two-frequency: both amplitudes must exceed this.
    #[arg(long)]
    pub min_amplitude: Option<Real>,
    /// With a ROS bag as --cloud: its topic of organised `sensor_msgs/PointCloud2` frames whose
    /// intensity is the amplitude; every message is filtered, one result line each.
    #[arg(long, requires = "cloud", conflicts_with_all = ["out", "png"])]
    pub topic: Option<String>,
    /// The output cloud (.ply .pcd .xyz ...).
    #[arg(long, required_unless_present = "topic")]
    pub out: Option<PathBuf>,
    /// Also write an RGB image of the outcomes.
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Write kept and unwrapped pixels (default).
    #[arg(long, conflicts_with = "safe")]
    pub dense: bool,
    /// Write only the kept pixels (sparse but nearly correct, thesis L2456–2458).
    #[arg(long)]
    pub safe: bool,
}

/// Arguments of `patchnav tof calibrate`.
#[derive(Debug, Args)]
pub struct CalibrateArgs {
    /// A white-wall frame as an organised cloud whose intensity is the amplitude (or give
    /// `--range` and `--amplitude`).
    #[arg(conflicts_with_all = ["range", "amplitude", "confidence"])]
    pub white_wall: Option<PathBuf>,
    #[command(flatten)]
    pub frame: FrameArgs,
    /// Fix the curvature to 1, as Eq 2.5 is printed.
    #[arg(long)]
    pub fixed_curvature: bool,
    /// Normalise the amplitudes with the radial distance (default: the depth, Eq 2.4's r_p).
    #[arg(long)]
    pub radial: bool,
    /// Refit without pixels whose residual exceeds SIGMA RMS residuals.
    #[arg(long)]
    pub trim: Option<Real>,
    /// Refuse walls with fewer measured pixels.
    #[arg(long, default_value_t = 100)]
    pub min_pixels: usize,
    /// Also write the per-pixel white-wall table (JSON; a sidecar's `aat.white_wall_table`).
    #[arg(long)]
    pub table: Option<PathBuf>,
    /// The calibration JSON to write.
    #[arg(long)]
    pub out: PathBuf,
}

impl FrameArgs {
    /// The library's frame source.
    pub fn source(&self) -> FrameSource {
        FrameSource {
            range: self.range.clone(),
            amplitude: self.amplitude.clone(),
            confidence: self.confidence.clone(),
            meta: self.meta.clone(),
        }
    }
}

impl FilterArgs {
    /// The library's settings (without the output options).
    pub fn setup(&self) -> FilterSetup {
        FilterSetup {
            frame: self.frame.source(),
            cloud: self.cloud.clone(),
            method: self.method,
            at: self.at,
            aat: self.aat,
            calibration: self.calibration.clone(),
            unwrap: self.unwrap,
            low_at: self.low_at,
            radial: self.radial,
            clamp_corners: self.clamp_corners,
            range2: self.range2.clone(),
            amplitude2: self.amplitude2.clone(),
            meta2: self.meta2.clone(),
            max_range: self.max_range,
            phase_noise: self.phase_noise,
            min_amplitude: self.min_amplitude,
        }
    }
}

/// Runs a `patchnav tof` subcommand.
pub fn run(command: &TofCommand, progress: &Progress) -> Result<()> {
    match command {
        TofCommand::Filter(args) => filter(args, progress),
        TofCommand::Calibrate(args) => calibrate(args, progress),
        TofCommand::Simulate(args) => crate::tof_sim::run(args, progress),
    }
}

fn filter(args: &FilterArgs, progress: &Progress) -> Result<()> {
    if let Some(topic) = &args.topic {
        return filter_bag(args, topic, progress);
    }
    let Some(out) = &args.out else { bail!("give --out (or a bag with --topic)") };
    if args.cloud.as_deref().is_some_and(crate::extract::is_bag) {
        bail!("a bag as --cloud needs --topic (`patchnav info` lists its topics)");
    }
    let (frame, output, name) = filter_frame(&args.setup())?;
    let mut written = output.clone();
    if args.safe {
        for (o, r) in written.outcomes.iter_mut().zip(written.radial.iter_mut()) {
            if *o == PixelOutcome::Unwrapped {
                *o = PixelOutcome::Dropped;
                *r = 0.0;
            }
        }
    }
    let cloud = written.to_cloud(&frame, false);
    pointcloud::io::write_cloud(out, &cloud)?;
    if let Some(png) = &args.png {
        let rgb = outcome_image(&frame, &output);
        write_rgb_png(png, frame.camera().width, frame.camera().height, &rgb)?;
    }
    let c = output.counts;
    progress.say(format!(
        "{name}: {} pixels, {} measured: {} kept, {} unwrapped, {} dropped ({:.1} % discarded); \
         {} points written to {}",
        c.total(),
        frame.num_measured(),
        c.kept,
        c.unwrapped,
        c.dropped,
        c.discarded_percent(),
        cloud.len(),
        out.display()
    ));
    Ok(())
}

/// `patchnav tof filter --cloud BAG --topic T --meta M`: every organised cloud of the topic (its
/// intensity the amplitude) filtered as one frame of the sidecar's camera, one line each.
fn filter_bag(args: &FilterArgs, topic: &str, progress: &Progress) -> Result<()> {
    let Some(path) = &args.cloud else { bail!("--topic needs a bag as --cloud") };
    if !crate::extract::is_bag(path) {
        bail!("--topic takes a ROS bag (.mcap, a rosbag2 folder, .bag) as --cloud");
    }
    let setup = args.setup();
    let meta = read_meta(&args.frame.meta)?;
    let camera = meta.camera()?;
    let query = ros_bag::ScanQuery { posed: false, ..ros_bag::ScanQuery::all(topic) };
    let bag = ros_bag::Bag::open(path)?;
    let summary = ros_bag::for_each_scan(&bag, &query, |scan| -> Result<()> {
        let at = format!("{} {topic} at {:.3} s", path.display(), scan.time_s);
        let frame =
            frame_from_cloud(&scan.cloud, &camera, meta.range_kind).with_context(|| at.clone())?;
        let (output, name) = filter_loaded(&frame, &meta, &setup).with_context(|| at.clone())?;
        let c = output.counts;
        progress.report(format!(
            "{:>9.3} s  {name}: {} measured: {} kept, {} unwrapped, {} dropped ({:.1} % discarded)",
            scan.time_s,
            frame.num_measured(),
            c.kept,
            c.unwrapped,
            c.dropped,
            c.discarded_percent()
        ));
        Ok(())
    })?;
    let (on_topic, _, kept) = summary.counts;
    progress.say(format!("{kept} of {on_topic} messages on {topic} filtered"));
    Ok(())
}

/// The outcome image (see the `filter` help): grey kept, blue unwrapped (brighter = nearer,
/// one scale up to the farthest output range), red dropped, black unmeasured.
fn outcome_image(frame: &TofFrame, out: &FilterOutput) -> Vec<u8> {
    let far = out
        .outcomes
        .iter()
        .zip(&out.radial)
        .filter(|(o, _)| o.is_output())
        .map(|(_, &r)| r)
        .fold(0.0f32, f32::max)
        .max(1e-6);
    let mut rgb = Vec::with_capacity(out.outcomes.len() * 3);
    for (i, (&o, &r)) in out.outcomes.iter().zip(&out.radial).enumerate() {
        let level = (255.0 - 191.0 * (r / far).clamp(0.0, 1.0)).round() as u8;
        let px = match o {
            PixelOutcome::Kept => [level, level, level],
            PixelOutcome::Unwrapped => [level / 4, level / 2, level],
            PixelOutcome::Dropped if frame.range()[i] > 0.0 => [220, 0, 0],
            PixelOutcome::Dropped => [0, 0, 0],
        };
        rgb.extend_from_slice(&px);
    }
    rgb
}

fn calibrate(args: &CalibrateArgs, progress: &Progress) -> Result<()> {
    let (frame, _) = load_frame(&args.frame.source(), args.white_wall.as_deref())?;
    let options = CalibrationOptions {
        range: if args.radial { AatRange::Radial } else { AatRange::Depth },
        fixed_curvature: args.fixed_curvature,
        min_pixels: args.min_pixels,
        trim_sigma: args.trim,
    };
    let c = fit_parabola(&frame, &options)?;
    write_json(&args.out, &c)?;
    if let Some(path) = &args.table {
        write_json(path, &white_wall_table(&frame, &options)?)?;
    }
    let p = c.parabola;
    progress.report(format!(
        "Â = {:.1}, δx = {:.2}, δy = {:.2}, k = {:.5}, residual RMS = {:.2} ({} pixels, {:.1} % \
         of the frame, {} range{})",
        p.a_hat,
        p.delta_x,
        p.delta_y,
        p.curvature,
        c.residual_rms,
        c.used_pixels,
        100.0 * c.used_fraction,
        if c.range == AatRange::Radial { "radial" } else { "depth" },
        if c.fixed_curvature { ", curvature fixed" } else { "" }
    ));
    Ok(())
}
