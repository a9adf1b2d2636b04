//! `patchnav demo`: the main job on the built-in example. Simulates the lab scanned by the ALRF
//! from several poses (and a time-of-flight frame and a terrain snapshot), filters the ToF frame
//! with the AAT and unwraps it, classifies the terrain, extracts planar and trimesh patches,
//! builds the planes, hybrid, trimesh and point-cloud maps, plans RRT and PRM on each, and writes
//! `report.html` (one self-contained page), `results.json` and the 3D files into the output
//! folder.

pub use patch_pipeline::{demo as pipeline, report, results as model};

use crate::progress::Progress;
use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;

/// Arguments of `patchnav demo`.
#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Output folder.
    #[arg(long, default_value = "out/demo")]
    pub out: PathBuf,
    /// Seed of everything random.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// A few seconds: fewer scans, seeds and iterations.
    #[arg(long, conflicts_with = "full")]
    pub quick: bool,
    /// Several minutes: more scans, seeds and iterations.
    #[arg(long)]
    pub full: bool,
}

impl DemoArgs {
    /// The scale the flags ask for.
    pub fn scale(&self) -> model::Scale {
        match (self.quick, self.full) {
            (true, _) => model::Scale::Quick,
            (_, true) => model::Scale::Full,
            _ => model::Scale::Default,
        }
    }
}

/// Runs `patchnav demo`.
pub fn run(args: &DemoArgs, progress: &Progress) -> Result<()> {
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let results = pipeline::run(args.scale(), args.seed, &args.out, progress)?;
    let json = args.out.join("results.json");
    pointcloud::io::write_bytes_atomically(&json, serde_json::to_string(&results)? + "\n")?;
    let html = args.out.join("report.html");
    report::write(&results, &html)?;
    progress.report(format!("report: {}", html.display()));
    Ok(())
}
