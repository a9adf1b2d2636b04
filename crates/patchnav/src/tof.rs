//! `patchnav tof ...`: time-of-flight frames (being written).

use crate::progress::Progress;

/// Time-of-flight subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum TofCommand {}

pub fn run(command: &TofCommand, _progress: &Progress) -> anyhow::Result<()> {
    match *command {}
}
