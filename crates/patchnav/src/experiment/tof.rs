//! The command line of `patchnav experiment tof`: arguments that become
//! [`patch_pipeline::experiment::tof`]'s settings; the experiment lives there.

use crate::progress::Progress;
use anyhow::Result;
use clap::Args;
use patch_pipeline::experiment::tof::{self as lib, TofSetup};
use pointcloud::Real;
use std::path::PathBuf;

/// Arguments of `patchnav experiment tof`.
#[derive(Debug, Args)]
pub struct TofArgs {
    /// Seed of the simulated noise the methods are scored on.
    #[arg(long, default_value_t = 7)]
    pub seed: u64,
    /// Seed of the simulated noise region unwrapping is tuned on (must differ from --seed).
    #[arg(long, default_value_t = 1)]
    pub tune_seed: u64,
    /// A real frame to fold: a folder with `radial_distance_u16.png`,
    /// `normalized_amplitude_u16.png`, `radial_distance_noise_u16.png` and `frame_meta.json` (the
    /// ifm O3R frame of the shared real-data folder).
    #[arg(long)]
    pub real: Option<PathBuf>,
    /// The non-ambiguity ranges to fold the real frame at, metres, comma-separated (its
    /// distances are 0.2–2 m, median 0.51 m).
    #[arg(long, value_delimiter = ',', default_values_t = [0.5, 0.7])]
    pub fold: Vec<Real>,
    /// The second frequency's non-ambiguity range for two-frequency unwrapping, as a multiple
    /// of each fold.
    #[arg(long, default_value_t = 1.2)]
    pub second_fold_factor: Real,
    /// Write every result as JSON to this file.
    #[arg(long)]
    pub json: Option<PathBuf>,
}

impl TofArgs {
    /// The library's settings.
    pub fn setup(&self) -> TofSetup {
        TofSetup {
            seed: self.seed,
            tune_seed: self.tune_seed,
            real: self.real.clone(),
            folds: self.fold.clone(),
            second_fold_factor: self.second_fold_factor,
            json: self.json.clone(),
        }
    }
}

/// Runs `patchnav experiment tof`.
pub fn run(args: &TofArgs, progress: &Progress) -> Result<()> {
    lib::run(&args.setup(), progress)
}
