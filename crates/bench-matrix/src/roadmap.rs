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
//!   step 1 m (not given in the thesis for the Lab).
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

mod lab_scene;
mod planners;

use anyhow::{Context, Result, bail};
use patch_core::{FromPatches, Patch, Point3, Real};
use patch_map::{
    AnyMap, BBox6dMap, MeshToPatchesConfig, PointCloudMap, PolygonMap, RapierMap, TrimeshMap,
    planar_patches_from_mesh, sample_patch_points,
};
use pointcloud::Aabb;
use roadmap::metrics::{added_length, turn_angles, upper_quartile};
use roadmap::{
    AnyOf, Goal, GoalReached, MaxIterations, PathMetrics, PlannerStatus, PlanningSpace, Problem,
    Termination,
};
use serde_json::{Value, json};
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

pub(crate) use planners::PLANNERS;

/// The scenes of the matrix.
pub(crate) const SCENES: [&str; 2] = ["office", "lab"];
/// The backends, in the thesis's column order (Simple, BB6D, OPCODE, Bullet), then the
/// point-cloud map.
pub(crate) const BACKENDS: [&str; 5] = ["polygon", "bbox6d", "trimesh", "rapier", "pointcloud"];
/// Iteration cap of an office run (as `patchnav experiment office`); a run that has not
/// reached every ROI by then fails.
pub(crate) const OFFICE_MAX_ITERATIONS: u64 = 100_000;
/// Iterations of a lab run (K; the thesis's Fig 6.4 runs from 100 up).
pub(crate) const LAB_ITERATIONS: u64 = 1000;
/// The checkpoints a lab run is timed at (each below or at [`LAB_ITERATIONS`]).
const LAB_CHECKPOINTS: [u64; 3] = [100, 500, LAB_ITERATIONS];
/// The planners the lab scene runs: RRT (Fig 6.4) and PRM (Table 6.4's roadmaps).
const LAB_PLANNERS: [&str; 2] = ["rrt", "prm"];
/// Robot radius and step of the lab runs, metres (the lab experiment's choices).
const LAB_RADIUS: Real = 0.3;
const LAB_STEP: Real = 1.0;

/// What to run: the options of `bench-matrix roadmap`.
#[derive(Clone, Debug)]
pub(crate) struct MatrixArgs {
    /// Scenes (empty: all).
    pub scenes: Vec<String>,
    /// Backends (empty: all).
    pub backends: Vec<String>,
    /// Planners (empty: all that apply to the scene).
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
        for (what, given, known) in [
            ("scene", &self.scenes, &SCENES[..]),
            ("backend", &self.backends, &BACKENDS[..]),
            ("planner", &self.planners, &PLANNERS[..]),
        ] {
            if let Some(bad) = given.iter().find(|g| !known.contains(&g.as_str())) {
                bail!("unknown {what} `{bad}`; known: {}", known.join(", "));
            }
        }
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

    fn wants<'a>(given: &[String], all: &[&'a str]) -> Vec<&'a str> {
        all.iter().copied().filter(|n| given.is_empty() || given.iter().any(|g| g == n)).collect()
    }
}

/// The case key of one run.
pub(crate) fn case_key(scene: &str, backend: &str, planner: &str, seed: u64) -> String {
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
    maps: Vec<(&'static str, AnyMap)>,
    space: PlanningSpace,
    query: Problem,
    mode: Mode,
    planners: Vec<&'static str>,
}

/// Runs the matrix; `emit` gets every row, the rows of one case together, `solved` last.
pub(crate) fn run(args: &MatrixArgs, emit: &mut dyn FnMut(Value) -> Result<()>) -> Result<()> {
    args.validate()?;
    let backends = MatrixArgs::wants(&args.backends, &BACKENDS);
    for scene in MatrixArgs::wants(&args.scenes, &SCENES) {
        let t0 = Instant::now();
        let setup = match scene {
            "office" => match office_setup(&backends)? {
                Some(s) => s,
                None => continue,
            },
            _ => lab_setup(&backends)?,
        };
        eprintln!(
            "roadmap: {scene}: {} maps built in {:.1} s",
            setup.maps.len(),
            t0.elapsed().as_secs_f64()
        );
        let planners: Vec<&str> = setup
            .planners
            .iter()
            .copied()
            .filter(|p| args.planners.is_empty() || args.planners.iter().any(|g| g == p))
            .collect();
        let mut items = Vec::new();
        let mut skipped = 0;
        for (b, (backend, _)) in setup.maps.iter().enumerate() {
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
    items: &[(usize, &'static str, u64)],
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
                    let (backend, map) = (&setup.maps[b].0, &setup.maps[b].1);
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
            self.seconds.push(progress.elapsed.as_secs_f64());
        }
        self.seconds.len() == self.at.len()
    }
}

/// One run: its rows, or (inner error) why the planner cannot run on this map.
fn run_case(
    setup: &Setup,
    backend: &str,
    map: &AnyMap,
    planner_name: &str,
    seed: u64,
    jobs: usize,
) -> Result<std::result::Result<Vec<Value>, String>> {
    let mut planner = match planners::make_planner(planner_name, map, setup.space, seed) {
        Ok(p) => p,
        Err(e) => return Ok(Err(format!("{e:#}"))),
    };
    let case = case_key(setup.scene, backend, planner_name, seed);
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
                "scene": setup.scene, "backend": backend, "planner": planner_name, "seed": seed,
                "status": status, "mode": mode, "max_iterations": cap, "jobs": jobs,
            })
        })
        .collect()))
}

/// The map of `backend` built from `patches`; the point-cloud map samples them every
/// `spacing` metres.
fn build_map(backend: &str, patches: Vec<Patch>, spacing: Real) -> Result<AnyMap> {
    Ok(match backend {
        "polygon" => AnyMap::Polygon(PolygonMap::from_patches(patches)?),
        "bbox6d" => AnyMap::BBox6d(BBox6dMap::from_patches(patches)?),
        "trimesh" => AnyMap::Trimesh(TrimeshMap::from_patches(patches)?),
        "rapier" => AnyMap::Rapier(RapierMap::from_patches(patches)?),
        "pointcloud" => AnyMap::PointCloud(PointCloudMap::from_points(&sample_patch_points(
            &patches, spacing,
        )?)?),
        other => bail!("unknown backend `{other}`"),
    })
}

fn build_maps(
    backends: &[&'static str],
    patches: &[Patch],
    spacing: Real,
) -> Result<Vec<(&'static str, AnyMap)>> {
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

fn point(v: Option<&Value>, what: &str) -> Result<Point3> {
    let a: Vec<Real> = v
        .and_then(Value::as_array)
        .with_context(|| format!("`{what}` is missing or not an array"))?
        .iter()
        .map(|x| x.as_f64().with_context(|| format!("`{what}` holds a non-number")))
        .collect::<Result<_>>()?;
    match a[..] {
        [x, y, z] if a.iter().all(|c| c.is_finite()) => Ok(Point3::new(x, y, z)),
        _ => bail!("`{what}` is not three finite numbers"),
    }
}

fn number(v: &Value, key: &str) -> Result<Real> {
    v.get(key)
        .and_then(Value::as_f64)
        .with_context(|| format!("`{key}` is missing or not a number"))
}

/// The office scene from the shared floor plan; `None` (with a note) when it is not there.
fn office_setup(backends: &[&'static str]) -> Result<Option<Setup>> {
    let path = bench_dir().join("floorplan.json");
    if !path.is_file() {
        eprintln!(
            "SKIPPED: scene `office` (no shared/bench/floorplan.json next to the checkout; set PATCHNAV_BENCH_DIR)"
        );
        return Ok(None);
    }
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let v: Value =
        serde_json::from_str(&text).with_context(|| format!("{} is not JSON", path.display()))?;
    let mesh = v.get("mesh").and_then(Value::as_str).context("`mesh` is missing")?;
    let mesh = path.parent().unwrap_or(Path::new(".")).join(mesh);
    let bounds = v.get("bounds").context("`bounds` is missing")?;
    let bounds =
        Aabb::new(point(bounds.get("min"), "bounds.min")?, point(bounds.get("max"), "bounds.max")?);
    let radius = number(&v, "robot_radius")?;
    let space = PlanningSpace::new(bounds, radius, number(&v, "max_step")?)
        .context("bounds, robot_radius, max_step")?;
    let tolerance = number(&v, "goal_tolerance")?;
    let goals = v
        .get("goals")
        .and_then(Value::as_array)
        .context("`goals` is missing")?
        .iter()
        .enumerate()
        .map(|(i, g)| Ok(Goal { center: point(Some(g), &format!("goals[{i}]"))?, tolerance }))
        .collect::<Result<Vec<_>>>()?;
    let query = Problem { start: point(v.get("start"), "start")?, goals };
    let patches = planar_patches_from_mesh(
        &pointcloud::io::read_mesh(&mesh)?,
        &MeshToPatchesConfig::exact_cad(),
    )
    .0;
    Ok(Some(Setup {
        scene: "office",
        maps: build_maps(backends, &patches, radius / 4.0)?,
        space,
        query,
        mode: Mode::Roi(OFFICE_MAX_ITERATIONS),
        planners: PLANNERS.to_vec(),
    }))
}

/// The lab scene from its exact geometry.
fn lab_setup(backends: &[&'static str]) -> Result<Setup> {
    let scene = scene_sim::lab(0).context("building the lab scene")?;
    let patches = lab_scene::scene_patches(&scene)?;
    let maps = build_maps(backends, &patches, LAB_RADIUS / 4.0)?;
    let bounds = scene.bounds();
    let space =
        PlanningSpace::new(bounds, LAB_RADIUS, LAB_STEP).context("the lab's planning space")?;
    let start =
        lab_scene::corner_start(&maps.iter().map(|m| &m.1).collect::<Vec<_>>(), LAB_RADIUS)?;
    Ok(Setup {
        scene: "lab",
        maps,
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
            "pointcloud",
            lab_scene::scene_patches(&scene_sim::lab(0).unwrap()).unwrap(),
            0.075,
        )
        .unwrap();
        let space =
            PlanningSpace::new(Aabb::new(Point3::origin(), Point3::new(1.0, 1.0, 1.0)), 0.1, 0.5)
                .unwrap();
        for p in ["ma-rrt", "ma-prm", "evasion-rrt"] {
            assert!(planners::make_planner(p, &map, space, 0).is_err(), "{p}");
        }
        assert!(planners::make_planner("rrt", &map, space, 0).is_ok());
    }
}
