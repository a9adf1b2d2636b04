//! `patchnav tof filter|calibrate`: time-of-flight frames (thesis §2.5.5; `sensor_tof`).
//!
//! ```text
//! patchnav tof filter --range R.png --amplitude A.png --meta M.json --method aat|at|two-freq
//!     [--at 160] [--aat 0.2] [--calibration C.json] [--unwrap] [--low-at X] [--radial]
//!     [--clamp-corners] [--range2 R2.png --amplitude2 A2.png --meta2 M2.json]
//!     --out cloud.ply [--png outcomes.png] [--dense|--safe]
//! patchnav tof filter --cloud F.ply --meta M.json ...
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
use clap::{Args, ValueEnum};
use pointcloud::Real;
use pointcloud::io::ReadOptions;
use sensor_tof::calibrate::{Calibration, CalibrationOptions, fit_parabola, white_wall_table};
use sensor_tof::io::{
    DEFAULT_AAT, FrameMeta, frame_from_cloud, read_json, read_meta, read_png_pair,
    read_png_pair_with_confidence, write_json, write_rgb_png,
};
use sensor_tof::two_freq::{SR3000_PHASE_NOISE_RAD, TwoFreqConfig, unwrap_two_frequencies};
use sensor_tof::{
    AatRange, FilterConfig, FilterOutput, NegativeIllumination, PixelOutcome, TofFilter, TofFrame,
};
use std::path::{Path, PathBuf};

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

/// Which filter.
#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum Method {
    /// The adaptive amplitude threshold (Eq 2.4) with the sidecar's illumination model.
    Aat,
    /// The plain amplitude threshold `--at`.
    At,
    /// Two frames at two modulation frequencies (`--range2`, `--amplitude2`, `--meta2`).
    TwoFreq,
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
    #[arg(long, value_enum, default_value_t = Method::Aat)]
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
    /// With `--unwrap`: drop instead of unwrapping flagged pixels with amplitude ≤ X (very
    /// dark, probably wrapped more than once).
    #[arg(long, requires = "unwrap")]
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
    /// The output cloud (.ply .pcd .xyz ...).
    #[arg(long)]
    pub out: PathBuf,
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

/// Runs a `patchnav tof` subcommand.
pub fn run(command: &TofCommand, progress: &Progress) -> Result<()> {
    match command {
        TofCommand::Filter(args) => filter(args, progress),
        TofCommand::Calibrate(args) => calibrate(args, progress),
        TofCommand::Simulate(args) => crate::tof_sim::run(args, progress),
    }
}

/// Reads the frame the arguments name (PNG pair or `cloud`) and its sidecar.
fn load_frame(args: &FrameArgs, cloud: Option<&Path>) -> Result<(TofFrame, FrameMeta)> {
    let meta = read_meta(&args.meta)?;
    let frame = match (cloud, &args.range, &args.amplitude) {
        (Some(path), _, _) => {
            let cloud = pointcloud::io::read_cloud(path, &ReadOptions::STRICT)?;
            frame_from_cloud(&cloud, &meta.camera()?, meta.range_kind)
                .with_context(|| format!("{}", path.display()))?
        }
        (None, Some(r), Some(a)) => match &args.confidence {
            Some(c) => read_png_pair_with_confidence(r, a, c, &meta)?,
            None => read_png_pair(r, a, &meta)?,
        },
        _ => bail!("no frame: give --range and --amplitude, or a cloud"),
    };
    Ok((frame, meta))
}

/// Reads the frame the arguments name and filters it as `--method` says: the frame, the
/// filter's output and the method's name (e.g. `AAT 0.2`).
///
/// # Errors
/// An unreadable frame or sidecar, no AAT parameters for `--method aat`, a parameter out of
/// range, or the filter refusing the frame.
pub(crate) fn filter_frame(args: &FilterArgs) -> Result<(TofFrame, FilterOutput, String)> {
    let (frame, meta) = load_frame(&args.frame, args.cloud.as_deref())?;
    let (output, name) = match args.method {
        Method::At => {
            if args.unwrap {
                bail!("--unwrap needs --method aat: a plain AT flags dark pixels at any range");
            }
            let f = TofFilter::new(frame.camera(), frame.kind(), &FilterConfig::at(args.at))?;
            (f.run(&frame)?, format!("AT {}", args.at))
        }
        Method::Aat => {
            let mut aat = match &args.calibration {
                Some(path) => {
                    let c: Calibration = read_json(path)?;
                    let (w, h) = (frame.camera().width, frame.camera().height);
                    if (c.width, c.height) != (w, h) {
                        bail!(
                            "{}: calibrated on {} × {} frames, this one is {w} × {h}",
                            path.display(),
                            c.width,
                            c.height
                        );
                    }
                    // The sidecar's threshold (else the thesis's 0.2) with this illumination.
                    let threshold = meta.aat()?.map_or(DEFAULT_AAT, |a| a.threshold);
                    c.aat_config(threshold)
                }
                None => meta.aat()?.with_context(|| {
                    format!(
                        "{}: no AAT parameters (give an `aat` block or a camera preset, or \
                         --calibration)",
                        args.frame.meta.display()
                    )
                })?,
            };
            if let Some(t) = args.aat {
                aat.threshold = t;
            }
            if args.radial {
                aat.range = AatRange::Radial;
            }
            if let Some(fraction) = args.clamp_corners {
                if !(fraction.is_finite() && fraction > 0.0 && fraction <= 1.0) {
                    bail!("--clamp-corners {fraction}: want a fraction in (0, 1]");
                }
                let aw = sensor_tof::filter::illumination_table(&aat.illumination, frame.camera())?;
                let max = aw.iter().copied().fold(Real::NEG_INFINITY, Real::max);
                aat.negative =
                    NegativeIllumination::Clamp((fraction * max).max(Real::MIN_POSITIVE));
            }
            let name = format!("AAT {}", aat.threshold);
            let config = if args.unwrap {
                FilterConfig::aat_unwrap(aat, args.low_at)
            } else {
                FilterConfig::aat(aat)
            };
            (TofFilter::new(frame.camera(), frame.kind(), &config)?.run(&frame)?, name)
        }
        Method::TwoFreq => {
            let (Some(r2), Some(a2), Some(m2)) = (&args.range2, &args.amplitude2, &args.meta2)
            else {
                bail!("--method two-freq needs --range2, --amplitude2 and --meta2");
            };
            let meta2 = read_meta(m2)?;
            let frame2 = read_png_pair(r2, a2, &meta2)?.converted(frame.kind());
            let mut config = TwoFreqConfig::for_pair(
                meta.modulation_hz,
                meta2.modulation_hz,
                args.max_range,
                args.phase_noise,
            )?;
            config.min_amplitude = args.min_amplitude;
            let mut out = FilterOutput::default();
            unwrap_two_frequencies(&frame, &frame2, &config, &mut out)?;
            let name = format!(
                "two-frequency {} + {} MHz",
                meta.modulation_hz / 1e6,
                meta2.modulation_hz / 1e6
            );
            (out, name)
        }
    };
    Ok((frame, output, name))
}

fn filter(args: &FilterArgs, progress: &Progress) -> Result<()> {
    let (frame, output, name) = filter_frame(args)?;
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
    pointcloud::io::write_cloud(&args.out, &cloud)?;
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
        args.out.display()
    ));
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
    let (frame, _) = load_frame(&args.frame, args.white_wall.as_deref())?;
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
