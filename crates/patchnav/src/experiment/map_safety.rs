//! The command line of `patchnav experiment map-safety`: arguments that become
//! [`patch_pipeline::experiment::map_safety`]'s settings; the experiment lives there.

use crate::progress::Progress;
use anyhow::Result;
use clap::Args;

use patch_core::Real;
use patch_pipeline::MapKind;
use patch_pipeline::experiment::map_safety::{self as lib, MapSafetySetup};

/// Arguments of `patchnav experiment map-safety`.
#[derive(Args, Debug, Clone)]
pub struct MapSafetyArgs {
    /// Scenes, comma-separated (`lab`, `office`).
    #[arg(long, value_delimiter = ',', default_values_t = ["lab".to_owned(), "office".to_owned()])]
    pub scenes: Vec<String>,
    /// Noise levels as multipliers of the S300 model's σ = 3 cm, comma-separated (0 is
    /// noise-free and without mixed pixels).
    #[arg(long, value_delimiter = ',', default_values_t = [0.0, 1.0, 2.0])]
    pub noise: Vec<Real>,
    /// Numbers of scans, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = [8usize, 29])]
    pub scans: Vec<usize>,
    /// The map types, comma-separated.
    #[arg(long, value_parser = crate::names::all::<MapKind>(), value_delimiter = ',', default_values_t = MapKind::ALL)]
    pub maps: Vec<MapKind>,
    /// Random capsule steps per map.
    #[arg(long, default_value_t = 100_000)]
    pub samples: usize,
    /// Seed of the random steps and the planners.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Seed of the scene's furniture, the scan poses and the sensor noise.
    #[arg(long, default_value_t = 0)]
    pub scene_seed: u64,
    /// Robot radius, metres.
    #[arg(long, default_value_t = 0.3)]
    pub radius: Real,
    /// Longest random step, metres.
    #[arg(long, default_value_t = 1.0)]
    pub max_length: Real,
    /// Iterations of each RRT and PRM run in the planner view (0: no planner view).
    #[arg(long, default_value_t = 2000)]
    pub planner_iterations: u64,
    /// Planner runs per planner and map (seeds `seed`, `seed + 1`, ...).
    #[arg(long, default_value_t = 2)]
    pub planner_seeds: u64,
    /// Height of the scanner above the floor, metres.
    #[arg(long, default_value_t = 0.5)]
    pub scan_height: Real,
    /// Angular step of the simulated ALRF in degrees (default: the S300's 0.5°).
    #[arg(long)]
    pub scan_step_deg: Option<Real>,
    /// Also write the rows as JSON to this file.
    #[arg(long)]
    pub json: Option<std::path::PathBuf>,
}

impl MapSafetyArgs {
    /// The library's settings.
    pub fn setup(&self) -> MapSafetySetup {
        MapSafetySetup {
            scenes: self.scenes.clone(),
            noise: self.noise.clone(),
            scans: self.scans.clone(),
            maps: self.maps.clone(),
            samples: self.samples,
            seed: self.seed,
            scene_seed: self.scene_seed,
            radius: self.radius,
            max_length: self.max_length,
            planner_iterations: self.planner_iterations,
            planner_seeds: self.planner_seeds,
            scan_height: self.scan_height,
            scan_step_deg: self.scan_step_deg,
            json: self.json.clone(),
        }
    }
}

/// Runs `patchnav experiment map-safety`.
pub fn run(args: &MapSafetyArgs, progress: &Progress) -> Result<()> {
    lib::run(&args.setup(), progress)
}
