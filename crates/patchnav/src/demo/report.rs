//! The demo's self-contained HTML report (being written).

use super::model::DemoResults;
use anyhow::Result;
use std::path::Path;

/// Writes `report.html` for `results`.
pub fn write(_results: &DemoResults, path: &Path) -> Result<()> {
    std::fs::write(path, "<!doctype html><title>patchnav demo</title>\n")?;
    Ok(())
}
