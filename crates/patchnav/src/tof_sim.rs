//! `patchnav tof simulate`: a simulated time-of-flight frame of one of the six test scenes of
//! thesis Table 2.4, written as the PNG pair and sidecar `patchnav tof filter` reads, with the
//! truth beside it.

use crate::progress::Progress;
use anyhow::{Context, Result};
use clap::Args;
use pointcloud::Real;
use sensor_tof::experiment::aat_for;
use sensor_tof::io::{AatMeta, FrameMeta, write_meta, write_png_pair};
use sensor_tof::scenes::{SCENE_NAMES, tof_scene};
use sensor_tof::sim::TofSimulator;
use sensor_tof::{Illumination, TofFrame};
use std::path::PathBuf;

/// Arguments of `patchnav tof simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// The scene: rack-and-door, corner-window, gates, close-boxes, dark-material, sun (the six
    /// of Table 2.4), or white-wall (a white wall at 1 m, for `tof calibrate`).
    pub scene: String,
    /// Output folder: `range.png`, `amplitude.png`, `meta.json` (with the AAT parameters of the
    /// simulated camera), `truth_radial.png` (true radial distance, same scale; 0 = nothing
    /// within the simulator's casting range) and `truth_wraps.png` (wrap counts, 16-bit).
    #[arg(long)]
    pub out: PathBuf,
    /// Seed of the noise.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Also simulate the view at this second modulation frequency (Hz) into `range2.png`,
    /// `amplitude2.png`, `meta2.json`, for `tof filter --method two-freq`.
    #[arg(long)]
    pub second_frequency: Option<Real>,
}

/// Metres per PNG unit of the written ranges: 0.5 mm covers 32.7 m.
const METRES_PER_UNIT: Real = 0.0005;

/// Runs `patchnav tof simulate`.
pub fn run(args: &SimulateArgs, progress: &Progress) -> Result<()> {
    let scene = tof_scene(&args.scene).with_context(|| {
        format!("unknown scene `{}` (known: {})", args.scene, SCENE_NAMES.join(", "))
    })?;
    let sim = TofSimulator::new(scene.sim.clone())?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let (a, b) = match args.second_frequency {
        Some(hz) => {
            let (a, b) = sim.simulate_two_frequencies(&scene.scene, &scene.pose, hz, args.seed)?;
            (a, Some(b))
        }
        None => (sim.simulate(&scene.scene, &scene.pose, args.seed)?, None),
    };
    let aat = aat_for(&sim);
    let meta_for = |frame: &TofFrame| {
        let mut meta = FrameMeta::for_camera(frame.camera(), frame.kind(), METRES_PER_UNIT);
        if let Illumination::Parabola(p) = &aat.illumination {
            meta.aat = Some(AatMeta {
                threshold: aat.threshold,
                a_hat: Some(p.a_hat),
                delta_x: Some(p.delta_x),
                delta_y: Some(p.delta_y),
                curvature: Some(p.curvature),
                white_wall_table: None,
                calibration: None,
            });
        }
        meta
    };
    let write = |frame: &TofFrame, suffix: &str| -> Result<()> {
        let meta = meta_for(frame);
        write_png_pair(
            frame,
            &args.out.join(format!("range{suffix}.png")),
            &args.out.join(format!("amplitude{suffix}.png")),
            &meta,
        )?;
        write_meta(&args.out.join(format!("meta{suffix}.json")), &meta)?;
        Ok(())
    };
    write(&a.frame, "")?;
    if let Some(b) = &b {
        write(&b.frame, "2")?;
    }
    // The truth as 16-bit PNGs: radial distance at the same scale, and the wrap counts.
    let n = a.truth.radial.len();
    let truth_units: Vec<u16> = a
        .truth
        .radial
        .iter()
        .map(|r| r.map_or(0, |r| (r as Real / METRES_PER_UNIT).round().clamp(1.0, 65535.0) as u16))
        .collect();
    let wraps: Vec<u16> = a.truth.wraps.iter().map(|&w| w as u16).collect();
    let c = a.frame.camera();
    for (name, data) in [("truth_radial.png", &truth_units), ("truth_wraps.png", &wraps)] {
        let path = args.out.join(name);
        write_u16_png(&path, c.width, c.height, data)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    let wrapped = a.truth.wraps.iter().filter(|&&w| w > 0).count();
    progress.report(format!(
        "{}: {} × {} frame at {:.1} MHz ({:.2} m non-ambiguity range), {} measured pixels, {:.1} % wrapped; written to {}",
        scene.name,
        c.width,
        c.height,
        c.modulation_hz / 1e6,
        c.non_ambiguity_range(),
        a.frame.num_measured(),
        100.0 * wrapped as Real / n.max(1) as Real,
        args.out.display()
    ));
    Ok(())
}

/// A 16-bit grayscale PNG (big-endian samples, as PNG stores them).
fn write_u16_png(path: &std::path::Path, width: u32, height: u32, data: &[u16]) -> Result<()> {
    pointcloud::io::write_atomically(path, |out| -> Result<()> {
        let mut encoder = png::Encoder::new(out, width, height);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(png::BitDepth::Sixteen);
        let mut writer = encoder.write_header()?;
        let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_be_bytes()).collect();
        writer.write_image_data(&bytes)?;
        writer.finish()?;
        Ok(())
    })
}
