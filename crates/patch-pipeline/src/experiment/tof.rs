//! `patchnav experiment tof`: thesis Table 2.4 (the AAT against amplitude thresholds) on the
//! six simulated scenes, with the metrics the thesis had no ground truth for, and the same
//! detection on a real frame folded at a chosen non-ambiguity range.

use crate::Progress;
use anyhow::{Context, Result};
use pointcloud::Real;
use sensor_tof::experiment::{
    Method, SceneResult, ThesisDiscarded, evaluate_folded, evaluate_scene, quality_table, table_2_4,
};
use sensor_tof::scenes::all_scenes;
use std::path::PathBuf;

/// The settings of the ToF experiment (`patchnav experiment tof`); [`Default`] is the
/// command line's.
#[derive(Clone, Debug, PartialEq)]
pub struct TofSetup {
    /// Seed of the simulated noise.
    pub seed: u64,
    /// A real frame to fold: a folder with `radial_distance_u16.png`,
    /// `normalized_amplitude_u16.png`, `radial_distance_noise_u16.png` and `frame_meta.json` (the
    /// ifm O3R frame of the shared real-data folder).
    pub real: Option<PathBuf>,
    /// The non-ambiguity range to fold the real frame at, metres (its distances are 0.2–2 m,
    /// median 0.51 m).
    pub fold: Real,
    /// The second frequency's non-ambiguity range for two-frequency unwrapping, metres.
    pub second_fold: Real,
    /// Write every result as JSON to this file.
    pub json: Option<PathBuf>,
}

impl Default for TofSetup {
    fn default() -> TofSetup {
        TofSetup { seed: 7, real: None, fold: 0.5, second_fold: 0.6, json: None }
    }
}

/// Runs the experiment: Table 2.4 and the quality table, then the real frame when given.
pub fn run(args: &TofSetup, progress: &dyn Progress) -> Result<()> {
    let scenes = all_scenes()?;
    let bar = progress.bar(scenes.len() as u64, "scenes");
    let mut results = Vec::new();
    for scene in &scenes {
        results.push(evaluate_scene(scene, &Method::all(), args.seed)?);
        bar.inc(1);
    }
    bar.finish_and_clear();
    progress.report(&table_2_4(&results));
    progress.report(&quality_table(&results));
    let mut folded = None;
    if let Some(dir) = &args.real {
        let meta = sensor_tof::io::read_meta(&dir.join("frame_meta.json"))?;
        let amplitude = dir.join("normalized_amplitude_u16.png");
        let frame =
            sensor_tof::io::read_png_pair(&dir.join("radial_distance_u16.png"), &amplitude, &meta)
                .with_context(|| format!("reading the frame in {}", dir.display()))?;
        let noise = sensor_tof::io::read_png_pair(
            &dir.join("radial_distance_noise_u16.png"),
            &amplitude,
            &meta,
        )
        .with_context(|| format!("reading the noise image in {}", dir.display()))?;
        let f =
            evaluate_folded(&frame, Some(noise.range()), args.fold, args.second_fold, args.seed)?;
        progress.report(&format!(
            "real frame folded at {} m (second frequency {} m): {} measured pixels, {:.1} % wrapped; \
             thresholds tuned on the even rows {:?}; scored on the odd rows (discarded % counts every pixel, \
             also those the camera gave no distance):",
            f.fold_m, f.second_fold_m, f.measured, f.wrapped_percent, f.thresholds
        ));
        let as_scene = SceneResult {
            scene: "real-folded".into(),
            wrapped_percent: f.wrapped_percent,
            thesis: ThesisDiscarded { aat: Real::NAN, at160: Real::NAN, at240: None },
            results: f.results.clone(),
        };
        progress.report(&quality_table(std::slice::from_ref(&as_scene)));
        folded = Some(f);
    }
    if let Some(path) = &args.json {
        let value = serde_json::json!({ "scenes": results, "folded": folded });
        pointcloud::io::write_bytes_atomically(path, serde_json::to_string_pretty(&value)? + "\n")?;
    }
    Ok(())
}
