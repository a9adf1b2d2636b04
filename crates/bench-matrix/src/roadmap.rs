//! `roadmap`: the planning matrix — scenes × backends × planners × seeds, one run per cell and
//! seed, one row per run and metric with the case key `scene/backend/planner/seed`.
//!
//! # Scenes
//! * `office` — the thesis's preliminary experiment (§5.5.3, Tables 5.3–5.11) on the shared
//!   floor plan (`shared/bench/floorplan.json` next to the checkout, or `$PATCHNAV_BENCH_DIR`):
//!   20 × 15 × 2.5 m, 51 planar patches from the mesh, robot radius 0.3 m, step 1 m. A run
//!   reaches all four regions of interest from the central start with one growing tree or
//!   roadmap and stops there, or fails at [`OFFICE_MAX_ITERATIONS`] (the `roi` mode of the
//!   shared results format). Metrics over the four paths as the thesis measures them
//!   (L6119–6121, L6364–6366): added length, steep (> 90°) and total turns summed, curviness =
//!   upper quartile of the turn angles of all four paths pooled.
//! * `lab` — thesis §6.1 (Fig 6.4) on `scene-sim`'s lab (seed 0, 12 × 9 × 4 m): the scene's
//!   exact geometry as patches ([`lab_scene`]: the `hybrid` map a perfect extraction would
//!   give), an RRT (or PRM) grown from a free point near the south-west corner for
//!   [`LAB_ITERATIONS`] iterations with no goal (thesis Algorithm 13 as run for §6.1), timed
//!   at 100, 500 (the thesis's "useful number", L6813–6818) and 1000 iterations. Radius 0.3 m,
//!   step 1 m (not given in the thesis for the Lab). Samples in the scene's box.
//! * `lab-scans-planes`, `lab-scans-hybrid`, `lab-scans-trimesh`, `lab-scans-pc` (`--scene
//!   lab-scans` selects all four) — Fig 6.4 as the thesis ran it: the lab's four map types
//!   built from simulated ALRF scans ([`lab_maps`]; planes, hybrid and trimesh by patch
//!   extraction, pc the raw scan points), read from the folder of map files named by
//!   `$PATCHNAV_LAB_MAPS`, which `cargo xtask bench` builds with `patchnav map build --source
//!   scans` and caches under `target/bench/lab-maps/`. Without it these scenes are skipped with
//!   a note. Runs as `lab` (RRT and PRM, K = 100/500/1000, radius 0.3 m, step 1 m), but each
//!   map samples in its own box (thesis L6460, as `patchnav experiment lab-timing`) and the
//!   start is free on all four maps. The patch maps run on the four patch backends, the pc map
//!   on `pointcloud` only (the thesis's Algorithm 10 for raw clouds); on the trimesh map a run
//!   without `--backend` leaves out polygon and bbox6d (≈ 12 s per run there). Rows carry
//!   `lab_maps`, the name of the folder (its name holds the build parameters).
//!
//! # Case keys
//! `scene/backend/planner/seed`. The map type is part of the scene, so a key names the map and
//! the backend holding it (`lab-scans-trimesh/rapier/rrt/3`: the trimesh map built from scans
//! in rapier), `lab` keeps its exact-geometry rows, and documentation groups the scans rows by
//! the scene prefix `lab-scans-`.
//!
//! # Backends
//! `polygon` (the thesis's Simple), `bbox6d` (BB6D), `trimesh` (one parry BVH, OPCODE's role),
//! `rapier` (Bullet's), `pointcloud` (Algorithm 10 on the patches sampled every quarter robot
//! radius). Each map is built once per scene; only `solve` is timed. Planners that need
//! proximity queries or specific hits (MA RRT, MA PRM, Evasion RRT) cannot run on the
//! point-cloud map (thesis Table 5.2); those cells are reported on standard error and give no
//! rows.
//!
//! # Parallel runs
//! `--jobs N` runs cases on N threads sharing the maps. Each run is timed on its own thread, so
//! the times stay per-run wall times, but runs compete for caches and memory bandwidth: every
//! row records `jobs`, and timing tables should come from `--jobs 1`.

pub(crate) mod lab_maps;
pub(crate) mod lab_scene;
mod planners;

use anyhow::{Context, Result, bail};
use patch_core::{Patch, Point3, Real};
use patch_map::{AnyMap, Backend, MeshToPatchesConfig, planar_patches_from_mesh};
use patch_pipeline::experiment::lab::{LAB_ROOM, corner_starts};
use patch_pipeline::scene_map::MapKind;
use pointcloud::Aabb;
use roadmap::metrics::{added_length, turn_angles, upper_quartile};
use roadmap::{
    AnyOf, GoalReached, MaxIterations, PathMetrics, PlannerKind, PlannerStatus, PlanningSpace,
    Problem, ProblemFile, Termination,
};
use serde_json::{Value, json};
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// The scenes of the matrix.
pub(crate) const SCENES: [&str; 6] =
    ["office", "lab", "lab-scans-planes", "lab-scans-hybrid", "lab-scans-trimesh", "lab-scans-pc"];
/// A `--scene` name selecting every `lab-scans-*` scene.
const LAB_SCANS_GROUP: &str = "lab-scans";
/// Iteration cap of an office run (as `patchnav experiment office`); a run that has not
/// reached every ROI by then fails.
pub(crate) const OFFICE_MAX_ITERATIONS: u64 = 100_000;
/// Iterations of a lab run (K; the thesis's Fig 6.4 runs from 100 up).
pub(crate) const LAB_ITERATIONS: u64 = 1000;
/// The checkpoints a lab run is timed at (each below or at [`LAB_ITERATIONS`]).
const LAB_CHECKPOINTS: [u64; 3] = [100, 500, LAB_ITERATIONS];
/// The planners the lab scene runs: RRT (Fig 6.4) and PRM (Table 6.4's roadmaps).
const LAB_PLANNERS: [PlannerKind; 2] = [PlannerKind::Rrt, PlannerKind::Prm];
/// Robot radius and step of the lab runs, metres (the lab experiment's choices).
const LAB_RADIUS: Real = 0.3;
const LAB_STEP: Real = 1.0;

/// What to run: the options of `bench-matrix roadmap`.
#[derive(Clone, Debug)]
pub(crate) struct MatrixArgs {
    /// Scenes (empty: all).
    pub scenes: Vec<String>,
    /// Backends by name (empty: all, [`Backend::ALL`]).
    pub backends: Vec<String>,
    /// Planners by name (empty: all that apply to the scene).
    pub planners: Vec<String>,
    /// First seed; runs use `seed..seed + seeds`.
    pub seed: u64,
    /// Seeds per cell.
    pub seeds: u64,
    /// Worker threads.
    pub jobs: usize,
    /// Case keys already done (resumed runs skip them).
    pub skip: HashSet<String>,
}

impl MatrixArgs {
    /// Checks the selection against the known names.
    pub(crate) fn validate(&self) -> Result<()> {
        if let Some(bad) =
            self.scenes.iter().find(|g| *g != LAB_SCANS_GROUP && !SCENES.contains(&g.as_str()))
        {
            bail!(
                "unknown scene `{bad}`; known: {}, {LAB_SCANS_GROUP} (all lab-scans-*)",
                SCENES.join(", ")
            );
        }
        self.selected_backends()?;
        self.selected_planners()?;
        if self.seeds == 0 || self.seeds > 1_000_000 {
            bail!("--seeds must be between 1 and 1,000,000, got {}", self.seeds);
        }
        if self.seed.checked_add(self.seeds).is_none() {
            bail!("--seed {} + --seeds {} overflows", self.seed, self.seeds);
        }
        if self.jobs == 0 || self.jobs > 1024 {
            bail!("--jobs must be between 1 and 1024, got {}", self.jobs);
        }
        Ok(())
    }

    /// The backends selected, in [`Backend::ALL`] order.
    fn selected_backends(&self) -> Result<Vec<Backend>> {
        selected(&self.backends, &Backend::ALL)
    }

    /// The planners selected, in [`PlannerKind::ALL`] order.
    fn selected_planners(&self) -> Result<Vec<PlannerKind>> {
        selected(&self.planners, &PlannerKind::ALL)
    }

    /// The scenes to run, in [`SCENES`] order (`lab-scans` stands for every `lab-scans-*`).
    fn scenes(&self) -> Vec<&'static str> {
        SCENES
            .iter()
            .copied()
            .filter(|n| {
                self.scenes.is_empty()
                    || self
                        .scenes
                        .iter()
                        .any(|g| g == n || (g == LAB_SCANS_GROUP && lab_maps::kind_of(n).is_some()))
            })
            .collect()
    }
}

/// The values of `all` named in `given` (all of them when `given` is empty), in `all`'s order.
fn selected<T>(given: &[String], all: &[T]) -> Result<Vec<T>>
where
    T: FromStr + Copy + PartialEq,
    T::Err: std::error::Error + Send + Sync + 'static,
{
    let given: Vec<T> = given.iter().map(|g| g.parse()).collect::<Result<_, _>>()?;
    Ok(all.iter().copied().filter(|v| given.is_empty() || given.contains(v)).collect())
}

/// The case key of one run.
pub(crate) fn case_key(scene: &str, backend: Backend, planner: PlannerKind, seed: u64) -> String {
    format!("{scene}/{backend}/{planner}/{seed}")
}

/// What a run does.
#[derive(Copy, Clone, Debug, PartialEq)]
enum Mode {
    /// Reach every goal with one tree or roadmap, at most this many iterations.
    Roi(u64),
    /// Grow with no goal, timed at [`LAB_CHECKPOINTS`].
    Explore,
}

/// A scene ready to run: its maps, space, query and planners.
struct Setup {
    scene: &'static str,
    /// The folder name of the maps built from scans (`lab-scans-*` scenes), put in every row.
    lab_maps: Option<String>,
    maps: Vec<(Backend, AnyMap)>,
    space: PlanningSpace,
    query: Problem,
    mode: Mode,
    planners: Vec<PlannerKind>,
}

/// Runs the matrix; `emit` gets every row, the rows of one case together, `solved` last. The
/// `lab-scans-*` scenes read their maps from the folder named by `$PATCHNAV_LAB_MAPS`.
pub(crate) fn run(args: &MatrixArgs, emit: &mut dyn FnMut(Value) -> Result<()>) -> Result<()> {
    run_with(args, lab_maps::folder_from_env().as_deref(), emit)
}

/// [`run`] with the folder of the lab's maps built from scans (`None`: those scenes are
/// skipped with a note).
fn run_with(
    args: &MatrixArgs,
    lab_maps_folder: Option<&Path>,
    emit: &mut dyn FnMut(Value) -> Result<()>,
) -> Result<()> {
    args.validate()?;
    let backends = args.selected_backends()?;
    let wanted_planners = args.selected_planners()?;
    let mut scanned: Option<lab_maps::LabMaps> = None;
    for scene in args.scenes() {
        let t0 = Instant::now();
        let setup = match (scene, lab_maps::kind_of(scene)) {
            ("office", _) => match office_setup(&backends)? {
                Some(s) => s,
                None => continue,
            },
            (_, Some(kind)) => {
                let Some(folder) = lab_maps_folder else {
                    eprintln!(
                        "SKIPPED: scene `{scene}` (no maps built from scans: set {} to a folder \
                         of planes/hybrid/trimesh/pc .pmap files, as `cargo xtask bench` does)",
                        lab_maps::LAB_MAPS_ENV
                    );
                    continue;
                };
                if scanned.is_none() {
                    scanned = Some(lab_maps::load(folder, LAB_RADIUS)?);
                }
                let Some(maps) = scanned.as_mut() else { continue };
                let backends = lab_scans_backends(kind, &backends, args.backends.is_empty());
                lab_scans_setup(scene, kind, maps, &backends)?
            }
            _ => lab_setup(&backends)?,
        };
        eprintln!(
            "roadmap: {scene}: {} maps built in {:.1} s",
            setup.maps.len(),
            t0.elapsed().as_secs_f64()
        );
        let planners: Vec<PlannerKind> =
            setup.planners.iter().copied().filter(|p| wanted_planners.contains(p)).collect();
        let mut items = Vec::new();
        let mut skipped = 0;
        for (b, &(backend, _)) in setup.maps.iter().enumerate() {
            for &planner in &planners {
                for seed in args.seed..args.seed + args.seeds {
                    if args.skip.contains(&case_key(scene, backend, planner, seed)) {
                        skipped += 1;
                    } else {
                        items.push((b, planner, seed));
                    }
                }
            }
        }
        eprintln!(
            "roadmap: {scene}: {} runs to make, {skipped} already in the results",
            items.len()
        );
        run_items(&setup, &items, args.jobs, emit)?;
        eprintln!("roadmap: {scene}: done in {:.1} s", t0.elapsed().as_secs_f64());
    }
    Ok(())
}

/// Runs `items` on `jobs` threads sharing the maps; rows go to `emit` from this thread.
fn run_items(
    setup: &Setup,
    items: &[(usize, PlannerKind, u64)],
    jobs: usize,
    emit: &mut dyn FnMut(Value) -> Result<()>,
) -> Result<()> {
    let next = AtomicUsize::new(0);
    let cannot = std::sync::Mutex::new(std::collections::BTreeMap::<String, String>::new());
    std::thread::scope(|s| -> Result<()> {
        let (tx, rx) = std::sync::mpsc::channel::<Result<Vec<Value>>>();
        for _ in 0..jobs.min(items.len().max(1)) {
            let tx = tx.clone();
            let (next, cannot) = (&next, &cannot);
            s.spawn(move || {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&(b, planner, seed)) = items.get(i) else { break };
                    let (backend, map) = (setup.maps[b].0, &setup.maps[b].1);
                    let rows = match run_case(setup, backend, map, planner, seed, jobs) {
                        Ok(Ok(rows)) => rows,
                        Ok(Err(reason)) => {
                            if let Ok(mut c) = cannot.lock() {
                                c.insert(format!("{}/{backend}/{planner}", setup.scene), reason);
                            }
                            Vec::new()
                        }
                        Err(e) => {
                            let _ = tx.send(Err(e));
                            break;
                        }
                    };
                    if tx.send(Ok(rows)).is_err() {
                        break;
                    }
                }
            });
        }
        drop(tx);
        for rows in rx {
            for row in rows? {
                emit(row)?;
            }
        }
        Ok(())
    })?;
    for (cell, reason) in cannot.into_inner().unwrap_or_default() {
        eprintln!("roadmap: {cell}: skipped ({reason})");
    }
    Ok(())
}

/// A [`Termination`] that records the time and vertex count when the iterations reach each
/// checkpoint, and stops at the last.
struct Checkpoints {
    at: &'static [u64],
    seconds: Vec<f64>,
}

impl Termination for Checkpoints {
    fn should_stop(&mut self, progress: &roadmap::Progress) -> bool {
        while let Some(&next) = self.at.get(self.seconds.len()) {
            if progress.iterations < next {
                break;
            }
            self.seconds.push(progress.elapsed().as_secs_f64());
        }
        self.seconds.len() == self.at.len()
    }
}

/// One run: its rows, or (inner error) why the planner cannot run on this map.
fn run_case(
    setup: &Setup,
    backend: Backend,
    map: &AnyMap,
    kind: PlannerKind,
    seed: u64,
    jobs: usize,
) -> Result<std::result::Result<Vec<Value>, String>> {
    let mut planner = match planners::make_planner(kind, map, setup.space, seed) {
        Ok(p) => p,
        Err(e) => return Ok(Err(format!("{e:#}"))),
    };
    let case = case_key(setup.scene, backend, kind, seed);
    let mut metrics: Vec<(&str, Real, &str)> = Vec::new();
    let (status, cap) = match setup.mode {
        Mode::Roi(cap) => {
            let t = Instant::now();
            let status = planner.solve(&setup.query, &mut AnyOf(GoalReached, MaxIterations(cap)));
            metrics.push(("time", t.elapsed().as_secs_f64(), "s"));
            (status, cap)
        }
        Mode::Explore => {
            let mut timer = Checkpoints { at: &LAB_CHECKPOINTS, seconds: Vec::new() };
            let status = planner.solve(&setup.query, &mut timer);
            if status == PlannerStatus::InvalidStart {
                bail!("{case}: the start is not free");
            }
            if timer.seconds.len() != LAB_CHECKPOINTS.len() {
                bail!("{case}: the run stopped before {LAB_ITERATIONS} iterations");
            }
            metrics.push(("time", timer.seconds[2], "s"));
            metrics.push(("time_k100", timer.seconds[0], "s"));
            metrics.push(("time_k500", timer.seconds[1], "s"));
            (status, LAB_ITERATIONS)
        }
    };
    let c = planner.counters();
    metrics.push(("iterations", c.samples as Real, "count"));
    metrics.push(("vertices", planner.roadmap().node_count() as Real, "count"));
    metrics.push(("collision_checks", c.collision_checks as Real, "count"));
    let paths: Option<Vec<Vec<Point3>>> =
        (0..setup.query.goals.len()).map(|g| planner.path_to(g)).collect();
    let solved = matches!(setup.mode, Mode::Roi(_)) && paths.is_some();
    if let (true, Some(paths)) = (solved, &paths) {
        let per_path: Vec<PathMetrics> = paths.iter().map(|p| PathMetrics::of(p)).collect();
        let angles: Vec<Real> = paths.iter().flat_map(|p| turn_angles(p)).collect();
        metrics.push(("path_length", added_length(paths.iter().map(Vec::as_slice)), "m"));
        metrics.push(("turns", per_path.iter().map(|m| m.turns as Real).sum(), "count"));
        metrics.push((
            "steep_turns",
            per_path.iter().map(|m| m.steep_turns as Real).sum(),
            "count",
        ));
        metrics.push(("curviness", upper_quartile(&angles).unwrap_or(0.0).to_degrees(), "deg"));
    }
    metrics.push(("solved", if solved { 1.0 } else { 0.0 }, "bool"));
    let status = match status {
        PlannerStatus::Exact => "exact",
        PlannerStatus::Approximate { .. } => "approximate",
        PlannerStatus::Timeout => "timeout",
        PlannerStatus::InvalidStart => "invalid-start",
        PlannerStatus::InvalidGoal => "invalid-goal",
    };
    let mode = match setup.mode {
        Mode::Roi(_) => "roi",
        Mode::Explore => "explore",
    };
    Ok(Ok(metrics
        .into_iter()
        .map(|(metric, value, unit)| {
            json!({
                "case": case, "metric": metric, "value": value, "unit": unit,
                "scene": setup.scene, "backend": backend.name(), "planner": kind.name(), "seed": seed,
                "status": status, "mode": mode, "max_iterations": cap, "jobs": jobs,
            })
        })
        .map(|mut row| {
            if let (Some(folder), Some(obj)) = (&setup.lab_maps, row.as_object_mut()) {
                obj.insert("lab_maps".into(), folder.clone().into());
            }
            row
        })
        .collect()))
}

/// The map of `backend` built from `patches`; the point-cloud map samples them every
/// `spacing` metres.
fn build_map(backend: Backend, patches: Vec<Patch>, spacing: Real) -> Result<AnyMap> {
    Ok(AnyMap::from_patches(backend, patches, Some(spacing))?)
}

fn build_maps(
    backends: &[Backend],
    patches: &[Patch],
    spacing: Real,
) -> Result<Vec<(Backend, AnyMap)>> {
    backends
        .iter()
        .map(|&b| {
            Ok((
                b,
                build_map(b, patches.to_vec(), spacing)
                    .with_context(|| format!("building the `{b}` map"))?,
            ))
        })
        .collect()
}

/// The shared benchmark folder (`$PATCHNAV_BENCH_DIR`, else `shared/bench` next to the checkout).
fn bench_dir() -> PathBuf {
    match std::env::var_os("PATCHNAV_BENCH_DIR") {
        Some(d) => PathBuf::from(d),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/bench"),
    }
}

/// The office scene from the shared floor plan; `None` (with a note) when it is not there.
fn office_setup(backends: &[Backend]) -> Result<Option<Setup>> {
    let path = bench_dir().join("floorplan.json");
    if !path.is_file() {
        eprintln!(
            "SKIPPED: scene `office` (no shared/bench/floorplan.json next to the checkout; set PATCHNAV_BENCH_DIR)"
        );
        return Ok(None);
    }
    let p = ProblemFile::read(&path)?;
    let space = p.space().with_context(|| path.display().to_string())?;
    let query = p.query(&p.goals);
    let (mesh, radius) = (p.mesh, p.robot_radius);
    let patches = planar_patches_from_mesh(
        &pointcloud::io::read_mesh(&mesh)?,
        &MeshToPatchesConfig::exact_cad(),
    )
    .0;
    Ok(Some(Setup {
        scene: "office",
        lab_maps: None,
        maps: build_maps(backends, &patches, radius / 4.0)?,
        space,
        query,
        mode: Mode::Roi(OFFICE_MAX_ITERATIONS),
        planners: PlannerKind::ALL.to_vec(),
    }))
}

/// The lab scene from its exact geometry.
fn lab_setup(backends: &[Backend]) -> Result<Setup> {
    let scene = scene_sim::lab(0).context("building the lab scene")?;
    let patches = lab_scene::scene_patches(&scene)?;
    let maps = build_maps(backends, &patches, LAB_RADIUS / 4.0)?;
    let bounds = scene.bounds();
    let space =
        PlanningSpace::new(bounds, LAB_RADIUS, LAB_STEP).context("the lab's planning space")?;
    let on: Vec<&AnyMap> = maps.iter().map(|m| &m.1).collect();
    let anywhere =
        Aabb::new(Point3::from([Real::NEG_INFINITY; 3]), Point3::from([Real::INFINITY; 3]));
    let start = corner_starts(&on, &anywhere, LAB_RADIUS, LAB_ROOM, 1)
        .context("no free start near the lab's south-west corner")?[0];
    Ok(Setup {
        scene: "lab",
        lab_maps: None,
        maps,
        space,
        query: Problem { start, goals: Vec::new() },
        mode: Mode::Explore,
        planners: LAB_PLANNERS.to_vec(),
    })
}

/// The lab scene `scene` on the map of `kind` built from scans, in each of `backends` that can
/// hold it; it samples in the map's own box (thesis L6460).
/// Backends without a broad phase worth the name that a default run leaves out on the
/// trimesh map from scans: polygon and bbox6d test each of its ~55,000 patches' boxes per step
/// and take ≈ 12 s per 1000-iteration run (about 3,000× the trimesh backend).
const SLOW_ON_SCANNED_TRIMESH: [Backend; 2] = [Backend::Polygon, Backend::BBox6d];

/// The backends a `lab-scans-*` scene runs: `selected`, less [`SLOW_ON_SCANNED_TRIMESH`] for the
/// trimesh map when the backends were not named (`by_default`; a note says so).
fn lab_scans_backends(kind: MapKind, selected: &[Backend], by_default: bool) -> Vec<Backend> {
    if kind != MapKind::Trimesh || !by_default {
        return selected.to_vec();
    }
    let [a, b] = SLOW_ON_SCANNED_TRIMESH;
    eprintln!(
        "roadmap: lab-scans-trimesh: {a} and {b} left out by default (≈ 12 s per run); name \
         them with --backend to run them"
    );
    selected.iter().copied().filter(|b| !SLOW_ON_SCANNED_TRIMESH.contains(b)).collect()
}

fn lab_scans_setup(
    scene: &'static str,
    kind: MapKind,
    maps: &mut lab_maps::LabMaps,
    backends: &[Backend],
) -> Result<Setup> {
    let bounds = maps.bounds(kind)?;
    let space = PlanningSpace::new(bounds, LAB_RADIUS, LAB_STEP)
        .with_context(|| format!("the planning space of the {kind} map"))?;
    let start = maps.start;
    let built =
        maps.take_maps(kind, backends).with_context(|| format!("loading the {kind} map"))?;
    Ok(Setup {
        scene,
        lab_maps: maps.folder.file_name().map(|n| n.to_string_lossy().into_owned()),
        maps: built,
        space,
        query: Problem { start, goals: Vec::new() },
        mode: Mode::Explore,
        planners: LAB_PLANNERS.to_vec(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args() -> MatrixArgs {
        MatrixArgs {
            scenes: vec!["lab".into()],
            backends: vec!["polygon".into(), "pointcloud".into()],
            planners: vec!["rrt".into()],
            seed: 3,
            seeds: 2,
            jobs: 2,
            skip: HashSet::new(),
        }
    }

    #[test]
    fn the_scanned_trimesh_map_leaves_out_slow_backends_unless_they_are_named() {
        let all: Vec<Backend> = Backend::ALL.to_vec();
        assert_eq!(lab_scans_backends(MapKind::Planes, &all, true), all);
        assert_eq!(lab_scans_backends(MapKind::Trimesh, &all, false), all);
        assert_eq!(
            lab_scans_backends(MapKind::Trimesh, &all, true),
            [Backend::Trimesh, Backend::Rapier, Backend::PointCloud]
        );
    }

    #[test]
    fn bad_selections_are_errors() {
        for bad in [
            MatrixArgs { scenes: vec!["moon".into()], ..args() },
            MatrixArgs { backends: vec!["octree".into()], ..args() },
            MatrixArgs { planners: vec!["a-star".into()], ..args() },
            MatrixArgs { seeds: 0, ..args() },
            MatrixArgs { jobs: 0, ..args() },
            MatrixArgs { seed: u64::MAX, ..args() },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
        assert!(args().validate().is_ok());
    }

    #[test]
    fn lab_runs_give_every_metric_per_case_and_resume_skips() {
        let mut rows = Vec::new();
        run(&args(), &mut |r| {
            rows.push(r);
            Ok(())
        })
        .unwrap();
        let cases: HashSet<&str> = rows.iter().map(|r| r["case"].as_str().unwrap()).collect();
        assert_eq!(cases.len(), 4, "2 backends × 1 planner × 2 seeds: {cases:?}");
        assert!(cases.contains("lab/pointcloud/rrt/4"));
        for case in &cases {
            let metrics: Vec<&str> = rows
                .iter()
                .filter(|r| r["case"] == *case)
                .map(|r| r["metric"].as_str().unwrap())
                .collect();
            assert_eq!(metrics.last(), Some(&"solved"), "{case}: solved comes last");
            let time = |m: &str| {
                rows.iter().find(|r| r["case"] == *case && r["metric"] == m).unwrap()["value"]
                    .as_f64()
                    .unwrap()
            };
            assert!(time("time_k100") <= time("time_k500") && time("time_k500") <= time("time"));
            assert_eq!(time("iterations"), LAB_ITERATIONS as f64);
        }
        // Same seed, same tree on the exact backend whichever thread ran it.
        let vertices = |case: &str| {
            rows.iter().find(|r| r["case"] == case && r["metric"] == "vertices").unwrap()["value"]
                .clone()
        };
        let mut again = Vec::new();
        let skip: HashSet<String> =
            cases.iter().filter(|c| **c != "lab/polygon/rrt/3").map(|c| c.to_string()).collect();
        run(&MatrixArgs { skip, jobs: 1, ..args() }, &mut |r| {
            again.push(r);
            Ok(())
        })
        .unwrap();
        assert!(
            again.iter().all(|r| r["case"] == "lab/polygon/rrt/3"),
            "only the case not yet done runs"
        );
        let v = again.iter().find(|r| r["metric"] == "vertices").unwrap()["value"].clone();
        assert_eq!(v, vertices("lab/polygon/rrt/3"));
    }

    #[test]
    fn lab_scans_scenes_plan_on_the_maps_of_a_folder() {
        let dir = lab_maps::tests::TempDir::new("lab-scans-run");
        lab_maps::tests::write_tiny_maps(&dir.0);
        let a = MatrixArgs {
            scenes: vec!["lab-scans".into()],
            backends: Vec::new(),
            seeds: 1,
            ..args()
        };
        let mut rows = Vec::new();
        run_with(&a, Some(&dir.0), &mut |r| {
            rows.push(r);
            Ok(())
        })
        .unwrap();
        let cases: HashSet<&str> = rows.iter().map(|r| r["case"].as_str().unwrap()).collect();
        // By default the trimesh map leaves out the two slow backends.
        assert_eq!(cases.len(), 2 * 4 + 2 + 1, "planes, hybrid × 4 + trimesh × 2 + pc: {cases:?}");
        for kind in [MapKind::Planes, MapKind::Hybrid, MapKind::Trimesh] {
            for backend in Backend::patch_backends() {
                let slow = kind == MapKind::Trimesh && SLOW_ON_SCANNED_TRIMESH.contains(&backend);
                let case = format!("lab-scans-{kind}/{backend}/rrt/3");
                assert_eq!(cases.contains(case.as_str()), !slow, "{case}");
            }
        }
        assert!(cases.contains("lab-scans-pc/pointcloud/rrt/3"));
        let folder = dir.0.file_name().unwrap().to_str().unwrap();
        assert!(rows.iter().all(|r| r["lab_maps"] == folder && r["mode"] == "explore"));
        // Same seed, same start, same exact map: the planes tree is the same in polygon and
        // bbox6d (both exact).
        let vertices = |case: &str| {
            rows.iter().find(|r| r["case"] == case && r["metric"] == "vertices").unwrap()["value"]
                .clone()
        };
        assert_eq!(
            vertices("lab-scans-planes/polygon/rrt/3"),
            vertices("lab-scans-planes/bbox6d/rrt/3")
        );
        // One scene and backend, resumed; without the folder the scenes are skipped.
        let one = MatrixArgs {
            scenes: vec!["lab-scans-trimesh".into()],
            backends: vec!["rapier".into(), "pointcloud".into()],
            ..a.clone()
        };
        let mut again = Vec::new();
        run_with(&one, Some(&dir.0), &mut |r| {
            again.push(r);
            Ok(())
        })
        .unwrap();
        assert!(!again.is_empty());
        assert!(again.iter().all(|r| r["case"] == "lab-scans-trimesh/rapier/rrt/3"));
        let skip = HashSet::from(["lab-scans-trimesh/rapier/rrt/3".to_owned()]);
        let mut none = Vec::new();
        run_with(&MatrixArgs { skip, ..one.clone() }, Some(&dir.0), &mut |r| {
            none.push(r);
            Ok(())
        })
        .unwrap();
        run_with(&one, None, &mut |r| {
            none.push(r);
            Ok(())
        })
        .unwrap();
        assert!(none.is_empty());
        assert!(MatrixArgs { scenes: vec!["lab-scans-moon".into()], ..a }.validate().is_err());
    }

    #[test]
    fn medial_planners_cannot_run_on_the_point_cloud_map() {
        let mut rows = Vec::new();
        let a = MatrixArgs { planners: vec!["ma-rrt".into()], ..args() };
        // The lab's planner list does not hold ma-rrt: nothing runs.
        run(&a, &mut |r| {
            rows.push(r);
            Ok(())
        })
        .unwrap();
        assert!(rows.is_empty());
        let map = build_map(
            Backend::PointCloud,
            lab_scene::scene_patches(&scene_sim::lab(0).unwrap()).unwrap(),
            0.075,
        )
        .unwrap();
        let space = PlanningSpace::new(
            pointcloud::Aabb::new(Point3::origin(), Point3::new(1.0, 1.0, 1.0)),
            0.1,
            0.5,
        )
        .unwrap();
        for p in [PlannerKind::MaRrt, PlannerKind::MaPrm, PlannerKind::EvasionRrt] {
            assert!(planners::make_planner(p, &map, space, 0).is_err(), "{p}");
        }
        assert!(planners::make_planner(PlannerKind::Rrt, &map, space, 0).is_ok());
    }
}
