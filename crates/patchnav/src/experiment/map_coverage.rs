//! The command line of `patchnav experiment map-coverage`: arguments that become
//! [`patch_pipeline::experiment::map_coverage`]'s settings; the experiment lives there.

use crate::progress::Progress;
use anyhow::Result;
use clap::Args;

use patch_core::Real;
use std::path::PathBuf;

use patch_pipeline::experiment::map_coverage::{self as lib, MapCoverageSetup};

/// Arguments of `patchnav experiment map-coverage`.
#[derive(Args, Debug, Clone)]
pub struct MapCoverageArgs {
    /// The real-data folder (each scan's folder holds a SOURCE.md).
    #[arg(long, default_value = "../shared/data/real")]
    pub real_dir: PathBuf,
    /// Covered within this many σ(r) of a patch.
    #[arg(long, default_value_t = 3.0)]
    pub sigmas: Real,
}

impl MapCoverageArgs {
    /// The library's settings.
    pub fn setup(&self) -> MapCoverageSetup {
        MapCoverageSetup { real_dir: self.real_dir.clone(), sigmas: self.sigmas }
    }
}

/// Runs `patchnav experiment map-coverage`.
pub fn run(args: &MapCoverageArgs, progress: &Progress) -> Result<()> {
    lib::run(&args.setup(), progress)
}
