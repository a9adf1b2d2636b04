//! The runs of a planning problem in the shared exchange format (its `FORMAT.md`: problem JSON
//! in, one JSON line per run out), so our runs and other tools' runs on the same problem
//! compare directly (`patchnav plan --problem`, `patchnav experiment office`).
//!
//! * `explore`: grow for exactly `iterations` iterations with no reachable goal;
//! * `solve`: one query start → goal per goal (the line names the goal's index), stopping when
//!   it is reached or after `iterations`;
//! * `roi`: reach every goal from the start with one growing tree or roadmap (the thesis's
//!   preliminary experiment, §5.5.3), stopping when all are reached or after `iterations`.

use anyhow::{Context, Result};
use patch_core::{Patch, Point3, Real};
use patch_map::{AnyMap, Backend, MeshToPatchesConfig, planar_patches_from_mesh};
use roadmap::{
    AnyOf, GoalReached, MaxIterations, PathMetrics, Planner, PlannerKind, PlannerStatus, Problem,
};
use serde_json::{Value, json};
use std::path::Path;
use std::time::Instant;

crate::names::named_enum! {
    /// What the runs of a problem do.
    pub enum Mode ("mode") {
        /// Exactly `iterations` iterations, no goal.
        Explore = "explore", "Exactly `iterations` iterations, no goal";
        /// One query per goal.
        Solve = "solve", "One query per goal";
        /// All goals with one tree or roadmap.
        Roi = "roi", "All goals with one tree or roadmap";
    }
}

pub use roadmap::ProblemFile;

/// Reads a problem JSON ([`ProblemFile::read`]); the mesh path is resolved relative to the file.
pub fn read_problem(path: &Path) -> Result<ProblemFile> {
    ProblemFile::read(path).with_context(|| format!("problem file {}", path.display()))
}

/// The problem's mesh as planar patches (exact CAD faces).
pub fn read_patches(p: &ProblemFile) -> Result<Vec<Patch>> {
    let mesh = pointcloud::io::read_mesh(&p.mesh)?;
    Ok(planar_patches_from_mesh(&mesh, &MeshToPatchesConfig::exact_cad()).0)
}

/// The map of `backend` built from `patches`; a point-cloud map samples them every
/// `sample_spacing` metres (default: a quarter of the robot radius).
pub fn map_from_patches(
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
pub fn solve_timed(
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
        "mode": mode.name(),
        "seed": seed,
    })
}

/// The row of a run that could not be made (the planner cannot run on the map, or not on
/// this query): recorded with the reason, as the results format asks.
pub fn skipped_row(
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
pub fn run_row(
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
