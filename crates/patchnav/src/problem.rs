//! `patchnav plan --problem P.json --backend B --planner X --mode explore|solve|roi`: the runs
//! of a planning problem in the shared exchange format (its `FORMAT.md`: problem JSON in, one
//! JSON line per run out), so our runs and other tools' runs on the same problem compare
//! directly.
//!
//! * `explore`: grow for exactly `iterations` iterations with no reachable goal;
//! * `solve`: one query start → goal per goal (the line names the goal's index), stopping when
//!   it is reached or after `iterations`;
//! * `roi`: reach every goal from the start with one growing tree or roadmap (the thesis's
//!   preliminary experiment, §5.5.3), stopping when all are reached or after `iterations`.

use crate::names;
use crate::plan::make_planner;
use crate::progress::Progress;
use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use patch_core::{Patch, Point3, Real};
use patch_map::{AnyMap, Backend, MeshToPatchesConfig, planar_patches_from_mesh};
use roadmap::{
    AnyOf, GoalReached, MaxIterations, PathMetrics, Planner, PlannerKind, PlannerStatus, Problem,
};
use serde_json::{Value, json};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What the runs of a problem do.
#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum Mode {
    /// Exactly `iterations` iterations, no goal.
    Explore,
    /// One query per goal.
    Solve,
    /// All goals with one tree or roadmap.
    Roi,
}

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
    #[arg(long, value_enum, default_value_t = Mode::Roi, requires = "problem")]
    pub mode: Mode,
    /// Point spacing when the backend is `pointcloud`, metres (default: a quarter of the robot
    /// radius, well inside the density the point-cloud map assumes).
    #[arg(long = "sample-spacing", requires = "problem")]
    pub sample_spacing: Option<Real>,
}

pub(crate) use roadmap::ProblemFile;

/// Reads a problem JSON ([`ProblemFile::read`]); the mesh path is resolved relative to the file.
pub(crate) fn read_problem(path: &Path) -> Result<ProblemFile> {
    ProblemFile::read(path).with_context(|| format!("problem file {}", path.display()))
}

/// The problem's mesh as planar patches (exact CAD faces).
pub(crate) fn read_patches(p: &ProblemFile) -> Result<Vec<Patch>> {
    let mesh = pointcloud::io::read_mesh(&p.mesh)?;
    Ok(planar_patches_from_mesh(&mesh, &MeshToPatchesConfig::exact_cad()).0)
}

/// The map of `backend` built from `patches`; a point-cloud map samples them every
/// `sample_spacing` metres (default: a quarter of the robot radius).
pub(crate) fn map_from_patches(
    p: &ProblemFile,
    patches: Vec<Patch>,
    backend: Backend,
    sample_spacing: Option<Real>,
) -> Result<AnyMap> {
    let spacing = sample_spacing.unwrap_or(p.robot_radius / 4.0);
    Ok(AnyMap::from_patches(backend, patches, Some(spacing))?)
}

/// One timed `solve`: in `explore` mode exactly `iterations` iterations, otherwise until every
/// goal of `problem` is reached or after `iterations`. Only the `solve` call is timed.
pub(crate) fn solve_timed(
    planner: &mut dyn Planner,
    problem: &Problem,
    mode: Mode,
    iterations: u64,
) -> (PlannerStatus, Real) {
    let t = Instant::now();
    let status = if mode == Mode::Explore {
        planner.solve(problem, &mut MaxIterations(iterations))
    } else {
        planner.solve(problem, &mut AnyOf(GoalReached, MaxIterations(iterations)))
    };
    (status, t.elapsed().as_secs_f64())
}

/// The keys every result row starts with (the results format of `FORMAT.md`).
fn row_head(p: &ProblemFile, planner: &str, backend: Backend, mode: Mode, seed: u64) -> Value {
    json!({
        "kind": "planning",
        "tool": concat!("patchnav-", env!("CARGO_PKG_VERSION")),
        "planner": planner,
        "backend": backend.name(),
        "problem": p.name,
        "mode": mode_name(mode),
        "seed": seed,
    })
}

fn mode_name(mode: Mode) -> String {
    format!("{mode:?}").to_lowercase()
}

/// The row of a run that could not be made (the planner cannot run on the map, or not on
/// this query): recorded with the reason, as the results format asks.
pub(crate) fn skipped_row(
    p: &ProblemFile,
    kind: PlannerKind,
    backend: Backend,
    mode: Mode,
    seed: u64,
    reason: &anyhow::Error,
) -> Value {
    let mut row = row_head(p, kind.name(), backend, mode, seed);
    row["skipped"] = json!(format!("{reason:#}"));
    row
}

/// The row of a finished run: `paths` holds the planner's path to each goal of the query.
pub(crate) fn run_row(
    p: &ProblemFile,
    planner: &dyn Planner,
    backend: Backend,
    mode: Mode,
    seed: u64,
    (status, time_s): (PlannerStatus, Real),
    paths: &[Option<Vec<Point3>>],
) -> Value {
    let solved = mode != Mode::Explore && paths.iter().all(Option::is_some);
    let path_length = solved
        .then(|| paths.iter().flatten().map(|path| PathMetrics::of(path).length).sum::<Real>());
    let c = planner.counters();
    let mut row = row_head(p, planner.name(), backend, mode, seed);
    for (key, value) in [
        ("map", json!(p.mesh.file_name().map(|f| f.to_string_lossy().into_owned()))),
        ("iterations", json!(c.samples)),
        ("vertices", json!(planner.roadmap().node_count())),
        ("time_s", json!(time_s)),
        ("collision_checks", json!(c.collision_checks)),
        ("solved", json!(solved)),
        ("path_length", json!(path_length)),
        ("status", json!(format!("{status:?}"))),
        ("motion", json!("capsule")),
    ] {
        row[key] = value;
    }
    if mode == Mode::Roi {
        row["goals"] = paths
            .iter()
            .map(|path| match path {
                Some(path) => {
                    json!({"solved": true, "path_length": PathMetrics::of(path).length})
                }
                None => json!({"solved": false, "path_length": null}),
            })
            .collect();
    }
    row
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
            let row = match make_planner(kind, &map, space, seed) {
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
