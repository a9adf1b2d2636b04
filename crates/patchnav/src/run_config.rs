//! `patchnav run CONFIG.toml` (being written).

use crate::progress::Progress;
use anyhow::{Result, bail};

/// Arguments of `patchnav run`.
#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// The configuration file.
    pub config: std::path::PathBuf,
}

/// Runs `patchnav run`.
pub fn run(_args: &RunArgs, _progress: &Progress) -> Result<()> {
    bail!("run is not built yet")
}
