//! The command line of `patchnav experiment office`: arguments that become
//! [`patch_pipeline::experiment::office`]'s settings; the experiment lives there.

use crate::progress::Progress;
use anyhow::Result;
use clap::Args;

use crate::names;
use patch_core::Real;
use patch_map::Backend;
use roadmap::PlannerKind;
use std::path::PathBuf;

use patch_pipeline::experiment::office::{self as lib, OfficeSetup};

/// Arguments of `patchnav experiment office`.
#[derive(Args, Debug)]
pub struct OfficeArgs {
    /// The planning problem JSON (mesh, robot_radius, max_step, bounds, start, four goals,
    /// goal_tolerance; its `iterations` and `seeds` are ignored), relative to the current
    /// directory.
    #[arg(long, default_value = "../shared/bench/floorplan.json")]
    pub problem: PathBuf,
    /// Runs per planner and backend, with seeds 0..N.
    #[arg(long, default_value_t = 50)]
    pub seeds: u64,
    /// Iteration cap of a run; a run that has not reached every ROI by then fails.
    #[arg(long = "max-iterations", default_value_t = 100_000)]
    pub max_iterations: u64,
    /// Only these planners (comma-separated; default: all, in the thesis's order).
    #[arg(long, value_parser = names::all::<PlannerKind>(), value_delimiter = ',')]
    pub planners: Vec<PlannerKind>,
    /// Only these backends (comma-separated; default: all, in the thesis's column order).
    #[arg(long, value_parser = names::all::<Backend>(), value_delimiter = ',')]
    pub backends: Vec<Backend>,
    /// Also write one JSON line per run (the rows of `plan --problem` plus the metrics).
    #[arg(long)]
    pub jsonl: Option<PathBuf>,
    /// Point spacing of the `pointcloud` backend, metres (default: a quarter of the robot
    /// radius).
    #[arg(long = "sample-spacing")]
    pub sample_spacing: Option<Real>,
    /// Seeds run at once (default: one per core; the tables but for the times do not depend on
    /// it). Each run is timed while the others run: use 1 for the cleanest Table 5.3 times.
    #[arg(long)]
    pub threads: Option<std::num::NonZeroUsize>,
}

impl OfficeArgs {
    /// The library's settings.
    pub fn setup(&self) -> OfficeSetup {
        OfficeSetup {
            problem: self.problem.clone(),
            seeds: self.seeds,
            max_iterations: self.max_iterations,
            planners: self.planners.clone(),
            backends: self.backends.clone(),
            jsonl: self.jsonl.clone(),
            sample_spacing: self.sample_spacing,
            threads: self.threads,
        }
    }
}

/// Runs `patchnav experiment office`.
pub fn run(args: &OfficeArgs, progress: &Progress) -> Result<()> {
    lib::run(&args.setup(), progress)
}
