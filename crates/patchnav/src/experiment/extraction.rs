//! Thesis §5.3 (Figs 5.12–5.14, Table 5.1).

use crate::progress::Progress;
use anyhow::{Result, bail};
use clap::Args;

/// Arguments of `patchnav experiment extraction`.
#[derive(Args, Debug)]
pub struct ExtractionArgs {}

/// Runs the experiment.
pub fn run(_args: &ExtractionArgs, _progress: &Progress) -> Result<()> {
    bail!("not built yet")
}
