//! Thesis §5.5.3 (Tables 5.3–5.11).

use crate::progress::Progress;
use anyhow::{Result, bail};
use clap::Args;

/// Arguments of `patchnav experiment office`.
#[derive(Args, Debug)]
pub struct OfficeArgs {}

/// Runs the experiment.
pub fn run(_args: &OfficeArgs, _progress: &Progress) -> Result<()> {
    bail!("not built yet")
}
