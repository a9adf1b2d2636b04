//! Thesis §6.1 on the simulated lab (Fig 6.4, Tables 6.2 and 6.4).

use crate::progress::Progress;
use anyhow::{Result, bail};
use clap::Args;

/// Arguments of `patchnav experiment lab-timing`.
#[derive(Args, Debug)]
pub struct LabTimingArgs {}

/// Arguments of `patchnav experiment lab-volume`.
#[derive(Args, Debug)]
pub struct LabVolumeArgs {}

/// Runs the timing experiment.
pub fn run_timing(_args: &LabTimingArgs, _progress: &Progress) -> Result<()> {
    bail!("not built yet")
}

/// Runs the explored-volume experiment.
pub fn run_volume(_args: &LabVolumeArgs, _progress: &Progress) -> Result<()> {
    bail!("not built yet")
}
