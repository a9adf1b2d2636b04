//! `cargo xtask compare` (being written).

use anyhow::{Result, bail};

/// Runs `cargo xtask compare ARGS`.
pub fn run(_args: &[String]) -> Result<()> {
    bail!("compare is not built yet")
}
