//! The `terrain` benchmark (being written).

use anyhow::{Result, bail};
use serde_json::Value;

/// Runs the terrain benchmark.
pub fn run(_seed: u64) -> Result<Vec<Value>> {
    bail!("not built yet")
}
