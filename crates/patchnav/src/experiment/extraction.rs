//! The command line of `patchnav experiment extraction`: arguments that become
//! [`patch_pipeline::experiment::extraction`]'s settings; the experiment lives there.

use crate::progress::Progress;
use anyhow::Result;
use clap::Args;

use patch_core::Real;
use std::path::PathBuf;

use patch_pipeline::experiment::extraction::{self as lib, ExtractionSetup, RegionSource};

/// Arguments of `patchnav experiment extraction`.
#[derive(Args, Debug)]
pub struct ExtractionArgs {
    /// Scan poses per sensor and noise level.
    #[arg(long, default_value_t = 3)]
    pub poses: usize,
    /// Seed of the lab's furniture, the poses and the sensor noise.
    #[arg(long, default_value_t = 7)]
    pub seed: u64,
    /// Angular step of the simulated ALRF in degrees (the S300: 0.5°; 1° is 4× faster).
    #[arg(long, default_value_t = 0.5)]
    pub alrf_step_deg: Real,
    /// ALRF scans extracted into the planes and hybrid maps for the map-size comparison (the
    /// thesis's Lab: 29).
    #[arg(long, default_value_t = 29)]
    pub map_scans: usize,
    /// Regions of the outlining survey.
    #[arg(long, value_parser = crate::names::all::<RegionSource>(), default_value_t = RegionSource::Segmented)]
    pub regions: RegionSource,
    /// Directory of real scans (see its README.md); skipped with a note when absent.
    #[arg(long, default_value = "../shared/data/real")]
    pub real: PathBuf,
    /// Tiny sizes, for tests.
    #[arg(long)]
    pub quick: bool,
    /// Also write every table row as a JSON object per line to this file.
    #[arg(long)]
    pub jsonl: Option<PathBuf>,
}

impl ExtractionArgs {
    /// The library's settings.
    pub fn setup(&self) -> ExtractionSetup {
        ExtractionSetup {
            poses: self.poses,
            seed: self.seed,
            alrf_step_deg: self.alrf_step_deg,
            map_scans: self.map_scans,
            regions: self.regions,
            real: self.real.clone(),
            quick: self.quick,
            jsonl: self.jsonl.clone(),
        }
    }
}

/// Runs `patchnav experiment extraction`.
pub fn run(args: &ExtractionArgs, progress: &Progress) -> Result<()> {
    lib::run(&args.setup(), progress)
}
