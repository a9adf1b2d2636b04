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
    /// Seed of the simulated noise.
    #[arg(long, default_value_t = 7)]
    pub seed: u64,
    /// A real frame to fold: a folder with `radial_distance_u16.png`,
    /// `normalized_amplitude_u16.png`, `radial_distance_noise_u16.png` and `frame_meta.json` (the
    /// ifm O3R frame of the shared real-data folder).
    #[arg(long)]
    pub real: Option<PathBuf>,
    /// The non-ambiguity range to fold the real frame at, metres (its distances are 0.2–2 m,
    /// median 0.51 m).
    #[arg(long, default_value_t = 0.5)]
    pub fold: Real,
    /// The second frequency's non-ambiguity range for two-frequency unwrapping, metres.
    #[arg(long, default_value_t = 0.6)]
    pub second_fold: Real,
    /// Write every result as JSON to this file.
    #[arg(long)]
    pub json: Option<PathBuf>,
}

impl TofArgs {
    /// The library's settings.
    pub fn setup(&self) -> TofSetup {
        TofSetup {
            seed: self.seed,
            real: self.real.clone(),
            fold: self.fold,
            second_fold: self.second_fold,
            json: self.json.clone(),
        }
    }
}

/// Runs `patchnav experiment tof`.
pub fn run(args: &TofArgs, progress: &Progress) -> Result<()> {
    lib::run(&args.setup(), progress)
}
