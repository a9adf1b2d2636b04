//! `patchnav terrain FRAME`: terrain classification (being written).

use crate::progress::Progress;

/// Arguments of `patchnav terrain`.
#[derive(Debug, clap::Args)]
pub struct TerrainArgs {
    /// A range frame or point cloud.
    pub frame: std::path::PathBuf,
}

pub fn run(_args: &TerrainArgs, _progress: &Progress) -> anyhow::Result<()> {
    anyhow::bail!("terrain classification is not built yet")
}
