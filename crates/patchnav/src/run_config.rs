//! `patchnav run CONFIG.toml`: the demo's job on the user's own data
//! ([`patch_pipeline::run_config`], where the configuration keys are listed; `docs/run.md` has
//! a complete example).

use crate::progress::Progress;
use anyhow::Result;

/// Arguments of `patchnav run`.
#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// The configuration file (TOML; see `docs/run.md`).
    pub config: std::path::PathBuf,
}

/// Runs `patchnav run`.
///
/// # Errors
/// A bad configuration (one line naming the key), or a stage failing.
pub fn run(args: &RunArgs, progress: &Progress) -> Result<()> {
    let (html, summary) = patch_pipeline::run_config::run(&args.config, progress)?;
    progress.say(summary.trim_end());
    progress.report(format!("report: {}", html.display()));
    Ok(())
}
