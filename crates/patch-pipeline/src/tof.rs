//! Time-of-flight frames as the programs filter them (thesis §2.5.5; `sensor_tof`): a frame
//! read from a 16-bit range and amplitude PNG pair with its JSON sidecar, or from an organised
//! cloud whose intensity is the amplitude, filtered by the AAT (with unwrapping), a plain
//! amplitude threshold, or two-frequency unwrapping.

use anyhow::{Context, Result, bail};
use pointcloud::Real;
use pointcloud::io::ReadOptions;
use sensor_tof::calibrate::Calibration;
use sensor_tof::io::{
    DEFAULT_AAT, FrameMeta, frame_from_cloud, read_json, read_meta, read_png_pair,
    read_png_pair_with_confidence,
};
use sensor_tof::regions::{RegionConfig, RegionUnwrapper};
use sensor_tof::two_freq::{TwoFreqConfig, unwrap_two_frequencies};
use sensor_tof::{
    AatConfig, AatRange, FilterConfig, FilterOutput, NegativeIllumination, TofFilter, TofFrame,
};
use std::path::{Path, PathBuf};

/// The frame to read: a PNG pair, or an organised cloud, with its sidecar.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameSource {
    /// 16-bit range PNG (values × `metres_per_unit` of the sidecar; 0 = no measurement).
    pub range: Option<PathBuf>,
    /// 16-bit amplitude PNG.
    pub amplitude: Option<PathBuf>,
    /// Optional 8- or 16-bit confidence PNG.
    pub confidence: Option<PathBuf>,
    /// JSON sidecar: image size, scales, range kind, intrinsics, modulation frequency, AAT
    /// parameters (or an ifm O3R `frame_meta.json`).
    pub meta: PathBuf,
}

crate::names::named_enum! {
    /// Which filter.
    pub enum Method ("method") {
        /// The adaptive amplitude threshold (Eq 2.4) with the sidecar's illumination model.
        Aat = "aat",
            "The adaptive amplitude threshold (Eq 2.4) with the sidecar's illumination model";
        /// The plain amplitude threshold `--at`.
        At = "at", "The plain amplitude threshold `--at`";
        /// Two frames at two modulation frequencies (`--range2`, `--amplitude2`, `--meta2`).
        TwoFreq = "two-freq",
            "Two frames at two modulation frequencies (`--range2`, `--amplitude2`, `--meta2`)";
        /// Region unwrapping (beyond the thesis): the AAT's evidence judged per smooth region;
        /// unwraps only where the region agrees, drops the ambiguous rest.
        Regions = "regions",
            "Region unwrapping: unwrap only where a smooth region's ranges and amplitudes agree, drop the ambiguous rest";
    }
}

/// How to filter a frame (`patchnav tof filter` without its output options). Error messages
/// name the command line's flags.
#[derive(Clone, Debug, PartialEq)]
pub struct FilterSetup {
    /// The frame.
    pub frame: FrameSource,
    /// An organised cloud whose intensity is the amplitude, instead of the PNG pair (the
    /// sidecar gives the camera).
    pub cloud: Option<PathBuf>,
    /// The filter.
    pub method: Method,
    /// The plain amplitude threshold of `--method at` (the thesis's baselines: 160 and 240).
    pub at: Real,
    /// Override the sidecar's AAT (apparent-reflectivity threshold; the thesis uses 0.2).
    pub aat: Option<Real>,
    /// Take the illumination parabola from a calibration JSON (`patchnav tof calibrate`)
    /// instead of the sidecar.
    pub calibration: Option<PathBuf>,
    /// Unwrap the pixels the AAT flags (one non-ambiguity range further along the beam).
    pub unwrap: bool,
    /// With `--unwrap`: drop instead of unwrapping flagged pixels with amplitude ≤ X (very
    /// dark, probably wrapped more than once); with `--method regions`: drop pixels with
    /// amplitude ≤ X before segmenting (`RegionConfig::low_at`).
    pub low_at: Option<Real>,
    /// Use the radial distance as Eq 2.4's r_p (default: the depth, as the thesis).
    pub radial: bool,
    /// Clamp the illumination model to at least this fraction of its maximum (0.04 if given
    /// without a value), so the image corners where Eq 2.5 goes negative are tested too
    /// (default: they always pass, as Eq 2.4 literally says).
    pub clamp_corners: Option<Real>,
    /// Two-frequency: the second frame's range PNG.
    pub range2: Option<PathBuf>,
    /// Two-frequency: the second frame's amplitude PNG.
    pub amplitude2: Option<PathBuf>,
    /// Two-frequency: the second frame's sidecar (its `modulation_hz` must differ).
    pub meta2: Option<PathBuf>,
    /// Two-frequency: candidates beyond this radial distance are not considered, metres (the
    /// 20 + 5 MHz preset's 29.5 m).
    pub max_range: Real,
    /// Two-frequency: the phase noise, radians (sets the tolerance to 3 σ of the disagreement).
    pub phase_noise: Real,
    /// Two-frequency: both amplitudes must exceed this.
    pub min_amplitude: Option<Real>,
}

impl FilterSetup {
    /// The command line's defaults for `frame` filtered by `method`: AT 160, the sidecar's
    /// AAT and illumination, no unwrapping, depth ranges, corners untested, and the SR-3000's
    /// two-frequency limits (29.5 m, its phase noise) without a second frame.
    pub fn new(frame: FrameSource, method: Method) -> FilterSetup {
        FilterSetup {
            frame,
            cloud: None,
            method,
            at: 160.0,
            aat: None,
            calibration: None,
            unwrap: false,
            low_at: None,
            radial: false,
            clamp_corners: None,
            range2: None,
            amplitude2: None,
            meta2: None,
            max_range: 29.5,
            phase_noise: sensor_tof::two_freq::SR3000_PHASE_NOISE_RAD,
            min_amplitude: None,
        }
    }
}

/// Reads the frame `args` names (PNG pair or `cloud`) and its sidecar.
///
/// # Errors
/// An unreadable frame or sidecar, or no frame named.
pub fn load_frame(args: &FrameSource, cloud: Option<&Path>) -> Result<(TofFrame, FrameMeta)> {
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
pub fn filter_frame(args: &FilterSetup) -> Result<(TofFrame, FilterOutput, String)> {
    let (frame, meta) = load_frame(&args.frame, args.cloud.as_deref())?;
    let (output, name) = filter_loaded(&frame, &meta, args)?;
    Ok((frame, output, name))
}

/// Filters a frame in memory (the Python package's arrays) as `--method` says: the filter's
/// output and the method's name. `args.frame.meta` names the sidecar in messages; the frame's
/// other paths and `args.cloud` are not read (two-frequency unwrapping reads its second frame
/// from `--range2`, `--amplitude2` and `--meta2`).
///
/// # Errors
/// No AAT parameters for `--method aat`, a parameter out of range, or the filter refusing the
/// frame.
pub fn filter_loaded(
    frame: &TofFrame,
    meta: &FrameMeta,
    args: &FilterSetup,
) -> Result<(FilterOutput, String)> {
    let (output, name) = match args.method {
        Method::At => {
            if args.unwrap {
                bail!("--unwrap needs --method aat: a plain AT flags dark pixels at any range");
            }
            let f = TofFilter::new(frame.camera(), frame.kind(), &FilterConfig::at(args.at))?;
            (f.run(frame)?, format!("AT {}", args.at))
        }
        Method::Aat => {
            if args.low_at.is_some() && !args.unwrap {
                bail!("--low-at needs --unwrap with --method aat (or --method regions)");
            }
            let aat = aat_of(args, frame, meta)?;
            let name = format!("AAT {}", aat.threshold);
            let config = if args.unwrap {
                FilterConfig::aat_unwrap(aat, args.low_at)
            } else {
                FilterConfig::aat(aat)
            };
            (TofFilter::new(frame.camera(), frame.kind(), &config)?.run(frame)?, name)
        }
        Method::Regions => {
            if args.unwrap {
                bail!(
                    "--unwrap is for --method aat: --method regions decides what to unwrap itself"
                );
            }
            let aat = aat_of(args, frame, meta)?;
            let name = format!("regions (AAT {})", aat.threshold);
            let config = RegionConfig { low_at: args.low_at, ..RegionConfig::new(aat) };
            let out = RegionUnwrapper::new(frame.camera(), frame.kind(), &config)?.run(frame)?;
            (out, name)
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
            unwrap_two_frequencies(frame, &frame2, &config, &mut out)?;
            let name = format!(
                "two-frequency {} + {} MHz",
                meta.modulation_hz / 1e6,
                meta2.modulation_hz / 1e6
            );
            (out, name)
        }
    };
    Ok((output, name))
}

/// The AAT of `--method aat` and `--method regions`: the calibration's illumination or the
/// sidecar's AAT, with `--aat`, `--radial` and `--clamp-corners` applied.
fn aat_of(args: &FilterSetup, frame: &TofFrame, meta: &FrameMeta) -> Result<AatConfig> {
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
        aat.negative = NegativeIllumination::Clamp((fraction * max).max(Real::MIN_POSITIVE));
    }
    Ok(aat)
}
