//! `patchnav plan --problem P.json --backend B --planner X --mode explore|solve|roi`: the runs
//! of a planning problem in the shared exchange format ([`patch_pipeline::problem`]), one JSON
//! line per run on standard output.
//!
//! * `explore`: grow for exactly `iterations` iterations with no reachable goal;
//! * `solve`: one query start → goal per goal (the line names the goal's index), stopping when
//!   it is reached or after `iterations`;
//! * `roi`: reach every goal from the start with one growing tree or roadmap (the thesis's
//!   preliminary experiment, §5.5.3), stopping when all are reached or after `iterations`.

use crate::names;
use crate::progress::Progress;
use anyhow::{Context, Result};
use clap::Args;
use patch_core::{Point3, Real};
use patch_map::Backend;
use patch_pipeline::problem::{
    Mode, map_from_patches, read_patches, read_problem, run_row, skipped_row, solve_timed,
};
use roadmap::{PlannerKind, named_planner_on};
use serde_json::json;
use std::path::PathBuf;

/// The `--problem` options of `patchnav plan`.
#[derive(Args, Debug)]
pub struct ProblemArgs {
    /// A planning problem JSON (mesh, robot_radius, max_step, bounds, start, goals,
    /// goal_tolerance, iterations, seeds); prints one JSON line per run.
    #[arg(long)]
    pub problem: Option<PathBuf>,
    /// The backend the problem's mesh is loaded into.
    #[arg(long, value_parser = names::all::<Backend>(), default_value_t = Backend::BBox6d, requires = "problem")]
    pub backend: Backend,
    /// What each run does.
    #[arg(long, value_parser = names::all::<Mode>(), default_value_t = Mode::Roi, requires = "problem")]
    pub mode: Mode,
    /// Point spacing when the backend is `pointcloud`, metres (default: a quarter of the robot
    /// radius, well inside the density the point-cloud map assumes).
    #[arg(long = "sample-spacing", requires = "problem")]
    pub sample_spacing: Option<Real>,
}

/// Runs every seed (and in `solve` mode every goal) of the problem; prints one JSON line each.
pub fn run(args: &ProblemArgs, kind: PlannerKind, progress: &Progress) -> Result<()> {
    let path = args.problem.as_ref().context("--problem is missing")?;
    let p = read_problem(path)?;
    let map = map_from_patches(&p, read_patches(&p)?, args.backend, args.sample_spacing)?;
    let space = p.space().with_context(|| path.display().to_string())?;
    let queries: Vec<(Option<usize>, Vec<Point3>)> = match args.mode {
        Mode::Explore => vec![(None, Vec::new())],
        Mode::Roi => vec![(None, p.goals.clone())],
        Mode::Solve => p.goals.iter().enumerate().map(|(i, g)| (Some(i), vec![*g])).collect(),
    };
    let bar = progress.bar((p.seeds.len() * queries.len()) as u64, "runs");
    for &seed in &p.seeds {
        for (goal_index, goals) in &queries {
            let problem = p.query(goals);
            let row = match named_planner_on(kind, &map, space, seed).map_err(anyhow::Error::from) {
                Ok(mut planner) => {
                    let outcome = solve_timed(planner.as_mut(), &problem, args.mode, p.iterations);
                    let paths: Vec<Option<Vec<Point3>>> =
                        (0..goals.len()).map(|i| planner.path_to(i)).collect();
                    let mut row = run_row(
                        &p,
                        planner.as_ref(),
                        map.backend(),
                        args.mode,
                        seed,
                        outcome,
                        &paths,
                    );
                    if let Some(i) = goal_index {
                        row["goal"] = json!(i);
                    }
                    row
                }
                Err(reason) => skipped_row(&p, kind, map.backend(), args.mode, seed, &reason),
            };
            // A closed pipe (`| head`) ends the run quietly instead of panicking in println!.
            let written = bar.suspend(|| {
                use std::io::Write as _;
                let mut out = std::io::stdout().lock();
                writeln!(out, "{row}").and_then(|()| out.flush())
            });
            match written {
                Ok(()) => {}
                Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => return Ok(()),
                Err(e) => return Err(e).context("writing a result row"),
            }
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    Ok(())
}
