//! `patchnav experiment tof`: thesis Table 2.4 (the AAT against amplitude thresholds) on the
//! six simulated scenes, with the metrics the thesis had no ground truth for, and the same
//! detection on a real frame folded at a chosen non-ambiguity range.

use crate::Progress;
use anyhow::{Context, Result};
use pointcloud::Real;
use sensor_tof::experiment::{
    Method, evaluate_folded, evaluate_scene, quality_table, table_2_4, tune_on_scenes, yield_table,
};
use sensor_tof::regions::RegionConfig;
use sensor_tof::scenes::all_scenes;
use std::path::PathBuf;

/// The settings of the ToF experiment (`patchnav experiment tof`); [`Default`] is the
/// command line's.
#[derive(Clone, Debug, PartialEq)]
pub struct TofSetup {
    /// Seed of the simulated noise the methods are scored on.
    pub seed: u64,
    /// Seed of the simulated noise region unwrapping is tuned on (must differ from `seed` for
    /// a held-out score).
    pub tune_seed: u64,
    /// A real frame to fold: a folder with `radial_distance_u16.png`,
    /// `normalized_amplitude_u16.png`, `radial_distance_noise_u16.png` and `frame_meta.json` (the
    /// ifm O3R frame of the shared real-data folder).
    pub real: Option<PathBuf>,
    /// The non-ambiguity ranges to fold the real frame at, metres (its distances are 0.2–2 m,
    /// median 0.51 m).
    pub folds: Vec<Real>,
    /// The second frequency's non-ambiguity range for two-frequency unwrapping, as a multiple
    /// of each fold.
    pub second_fold_factor: Real,
    /// Write every result as JSON to this file.
    pub json: Option<PathBuf>,
}

impl Default for TofSetup {
    fn default() -> TofSetup {
        TofSetup {
            seed: 7,
            tune_seed: 1,
            real: None,
            folds: vec![0.5, 0.7],
            second_fold_factor: 1.2,
            json: None,
        }
    }
}

/// Runs the experiment: region unwrapping tuned on the simulated scenes of `tune_seed`, then
/// Table 2.4, the quality table and the yield table on `seed`; then the real frame at each fold
/// when given (tuned on its even rows, scored on its odd rows).
pub fn run(args: &TofSetup, progress: &dyn Progress) -> Result<()> {
    if args.tune_seed == args.seed {
        anyhow::bail!(
            "--tune-seed must differ from --seed (scores on the tuning seed are not held out)"
        );
    }
    let scenes = all_scenes()?;
    let bar = progress.bar(scenes.len() as u64, "scenes");
    let tuned = tune_on_scenes(args.tune_seed)?;
    let mut methods = Method::all();
    methods.push(Method::Regions(Box::new(tuned.config.clone())));
    let mut results = Vec::new();
    for scene in &scenes {
        let mut r = evaluate_scene(scene, &methods, args.seed)?;
        if let Some(m) = r.results.last_mut() {
            m.method = "regions (tuned)".into();
        }
        results.push(r);
        bar.inc(1);
    }
    bar.finish_and_clear();
    progress.report(&table_2_4(&results));
    progress.report(&quality_table(&results));
    progress.report(&format!(
        "region unwrapping tuned on seed {} (training: mean yield {:.1} %, worst wrong {:.2} %): {}",
        args.tune_seed,
        tuned.train_yield_percent,
        tuned.train_max_wrong_percent,
        describe(&tuned.config)
    ));
    progress.report(&format!(
        "wrong % and yield (correct output, % of measured pixels) on seed {}; * = wrong ≤ 1 % and yield ≥ 80 %:",
        args.seed
    ));
    progress.report(&yield_table(&results));
    let mut folded = Vec::new();
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
        for &fold in &args.folds {
            let second = fold * args.second_fold_factor;
            let f = evaluate_folded(&frame, Some(noise.range()), fold, second, args.seed)?;
            progress.report(&format!(
                "real frame folded at {} m (second frequency {} m): {} measured pixels, {:.1} % wrapped; \
                 thresholds tuned on the even rows {:?}; regions tuned on the even rows: {}; scored on the odd rows \
                 (discarded % counts every pixel, also those the camera gave no distance):",
                f.fold_m, f.second_fold_m, f.measured, f.wrapped_percent, f.thresholds,
                describe(&f.regions.config)
            ));
            let as_scene = f.as_scene();
            progress.report(&quality_table(std::slice::from_ref(&as_scene)));
            progress.report(&yield_table(std::slice::from_ref(&as_scene)));
            folded.push(f);
        }
    }
    if let Some(path) = &args.json {
        let value = serde_json::json!({ "scenes": results, "regions": tuned, "folded": folded });
        pointcloud::io::write_bytes_atomically(path, serde_json::to_string_pretty(&value)? + "\n")?;
    }
    Ok(())
}

/// The tuned fields of a region configuration, one line.
pub fn describe(c: &RegionConfig) -> String {
    format!(
        "regions ≥ {} pixels, brightness {}–{} T, amplitude ratio ≤ {}, curvature {}, margin {}, wraps ≤ {}, low AT {}, noise ≤ {}, absorb passes {}, scattering gate {}",
        c.min_region_pixels,
        c.min_brightness,
        c.max_brightness,
        c.max_amplitude_ratio,
        c.join_curvature_m.map_or("off".into(), |t| format!("{} cm", t * 100.0)),
        c.min_margin,
        c.max_wraps,
        c.low_at.map_or("off".into(), |t| format!("{t}")),
        c.max_noise_m.map_or("off".into(), |t| format!("{} cm", t * 100.0)),
        c.absorb_passes,
        c.scattering.map_or("off".into(), |g| format!(
            "{} % over {} px, share ≤ {}",
            g.strength * 100.0,
            g.radius,
            g.max_share
        ))
    )
}
