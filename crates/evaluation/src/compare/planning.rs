//! Planning: OMPL + FCL (`cmp_plan`) against `patchnav plan --problem` on the same problems.
//!
//! Problems (written to `target/compare/problems/`, meshes by absolute path):
//! * `floorplan`: the shared bench's office floor plan (226 triangles, four rooms' ROIs);
//! * `lab`: the simulated lab's patch map extracted from `--poses` ALRF scans, exported as a
//!   triangle mesh; start at the south-east, goals in the rack and across the room.
//!
//! Every problem runs in three modes with the same budget on both sides: `explore` (exactly
//! `EXPLORE_ITERATIONS` iterations: time per iteration), `solve` (start → each goal, stop at
//! the goal or after `SOLVE_ITERATIONS`: time to solve, success, path length) and `roi` (all
//! goals with one tree / roadmap, same budget). Ours runs on the polygon, bbox6d and trimesh
//! backends; theirs on FCL's OBBRSS BVH of the same triangles.

use super::{Env, arg, json_lines, median, num, ratio};
use anyhow::{Context, Result};
use patch_map::Backend;
use roadmap::PlannerKind;
use serde_json::{Value, json};
use std::fmt::Write as _;
use std::path::PathBuf;

/// Iterations of an `explore` run.
const EXPLORE_ITERATIONS: u64 = 5000;
/// Iteration budget of a `solve` or `roi` run (both sides stop earlier when done).
const SOLVE_ITERATIONS: u64 = 20_000;
/// Wall-clock cap of one OMPL run, seconds (a safety net; no run should reach it).
const TIME_LIMIT_S: f64 = 30.0;
/// Our backends: two patch maps and the same triangles.
const OUR_BACKENDS: [Backend; 3] = [Backend::Polygon, Backend::BBox6d, Backend::Trimesh];
/// (common planner name, OMPL program's planner name, our planners run against it). The
/// first of ours has the common name; a variant's side is labelled `ours/{backend} {variant}`.
/// PRM runs twice on our side: the thesis's Algorithm 14 (`prm`: unchecked samples, a forest)
/// and `prm-valid` (samples checked, edges to all six neighbours: the roadmap OMPL's PRM builds).
const PLANNERS: [(PlannerKind, &str, &[PlannerKind]); 3] = [
    (PlannerKind::Rrt, "rrt", &[PlannerKind::Rrt]),
    (PlannerKind::RrtConnect, "rrtconnect", &[PlannerKind::RrtConnect]),
    (PlannerKind::Prm, "prm", &[PlannerKind::Prm, PlannerKind::PrmValid]),
];

/// The side label of our planner `variant` of the common planner `common` on `backend`.
fn our_side(backend: Backend, common: PlannerKind, variant: PlannerKind) -> String {
    if variant == common { format!("ours/{backend}") } else { format!("ours/{backend} {variant}") }
}
const MODES: [&str; 3] = ["explore", "solve", "roi"];
/// OMPL as shipped (RRT goal bias 0.05, goal reached within the tolerance).
const STOCK: &str = "ompl+fcl";
/// OMPL with the project's goal test (`cmp_plan --direct-goal`): the reference of the ratios
/// where it exists (RRT and PRM in solve and roi modes), so both sides run the same algorithm.
const DIRECT: &str = "ompl+fcl direct-goal";

/// The lab folder: scans, extracted maps and the exported mesh.
pub fn lab_dir(env: &Env) -> PathBuf {
    env.out.join("lab")
}

/// The lab's scan files, in order.
pub fn lab_scans(env: &Env, poses: usize) -> Vec<PathBuf> {
    (0..poses).map(|i| lab_dir(env).join(format!("scan{i:03}.ply"))).collect()
}

/// Simulates `poses` ALRF scans of the lab (seed 0) and extracts the planar patch map, exported
/// as `lab/lab.obj` for the planning problem.
pub fn lab_inputs(env: &Env, poses: usize) -> Result<()> {
    let dir = lab_dir(env);
    if dir.exists() {
        std::fs::remove_dir_all(&dir).with_context(|| format!("removing {}", dir.display()))?;
    }
    eprintln!("simulating {poses} ALRF scans of the lab");
    let p = &env.patchnav;
    json_lines(
        p,
        &["--quiet", "simulate", "lab", "--sensor", "alrf", "--poses", &poses.to_string(), "--out"]
            .map(str::to_owned)
            .into_iter()
            .chain([arg(&dir)])
            .collect::<Vec<_>>(),
    )?;
    let mut a: Vec<String> = vec!["--quiet".into(), "extract".into()];
    a.extend(lab_scans(env, poses).iter().map(arg));
    a.extend([
        "--out".into(),
        arg(dir.join("planning.pmap")),
        "--export".into(),
        arg(dir.join("lab.obj")),
    ]);
    json_lines(p, &a)?;
    Ok(())
}

/// Writes the problem JSON of `name` for `mode`; returns its path.
fn write_problem(env: &Env, name: &str, mode: &str, seeds: u64) -> Result<PathBuf> {
    let mut v: Value = match name {
        "floorplan" => {
            let path = env.bench.join("floorplan.json");
            let text = std::fs::read_to_string(&path)
                .with_context(|| format!("reading {} (the shared bench)", path.display()))?;
            let mut v: Value = serde_json::from_str(&text)?;
            v["mesh"] = json!(arg(env.bench.join("floorplan.obj").canonicalize()?));
            v
        }
        _ => json!({
            "name": "lab",
            "mesh": arg(lab_dir(env).join("lab.obj")),
            "robot_radius": 0.3,
            "max_step": 1.0,
            "bounds": {"min": [0.0, 0.0, 0.0], "max": [12.0, 9.0, 4.0]},
            "start": [10.0, 1.5, 2.6],
            // two between the rack's boards, one beside the rack, one across the room
            "goals": [[2.0, 8.05, 1.85], [6.0, 8.05, 1.85], [2.0, 8.05, 2.6], [10.0, 7.0, 1.0]],
            "goal_tolerance": 0.5,
        }),
    };
    v["iterations"] = json!(if mode == "explore" { EXPLORE_ITERATIONS } else { SOLVE_ITERATIONS });
    v["seeds"] = json!((0..seeds).collect::<Vec<_>>());
    let dir = env.out.join("problems");
    std::fs::create_dir_all(&dir)?;
    let path = dir.join(format!("{name}-{mode}.json"));
    pointcloud::io::write_bytes_atomically(&path, serde_json::to_string_pretty(&v)?)?;
    Ok(path)
}

/// Runs every problem × mode × planner on both sides; returns the rows and the table.
pub fn run(env: &Env, seeds: u64) -> Result<(Vec<Value>, String)> {
    let omplx = env.build.join("cmp_plan");
    let mut rows = Vec::new();
    for name in ["floorplan", "lab"] {
        for mode in MODES {
            let problem = write_problem(env, name, mode, seeds)?;
            for (ours, theirs, variants) in PLANNERS {
                if mode == "explore" && ours == PlannerKind::RrtConnect {
                    continue; // two trees and a goal: no explore mode
                }
                eprintln!("planning: {name} {mode} {ours}");
                let a = [
                    arg(&problem),
                    "--planner".into(),
                    theirs.into(),
                    "--mode".into(),
                    mode.into(),
                    "--time-limit".into(),
                    TIME_LIMIT_S.to_string(),
                ];
                rows.extend(tagged(json_lines(&omplx, &a), STOCK, name, mode, ours));
                if mode != "explore" && ours != PlannerKind::RrtConnect {
                    let mut a = a.to_vec();
                    a.push("--direct-goal".into());
                    rows.extend(tagged(json_lines(&omplx, &a), DIRECT, name, mode, ours));
                }
                for &variant in variants {
                    for backend in OUR_BACKENDS {
                        let a = [
                            "--quiet",
                            "plan",
                            "--problem",
                            &arg(&problem),
                            "--backend",
                            backend.name(),
                            "--planner",
                            variant.name(),
                            "--mode",
                            mode,
                        ]
                        .map(str::to_owned);
                        let side = our_side(backend, ours, variant);
                        rows.extend(tagged(json_lines(&env.patchnav, &a), &side, name, mode, ours));
                    }
                }
            }
        }
    }
    Ok((rows.clone(), table(&rows)))
}

/// Adds `side`, `problem`, `mode` and the common planner name to each row; a failed process
/// becomes one skipped row.
fn tagged(
    result: Result<Vec<Value>>,
    side: &str,
    problem: &str,
    mode: &str,
    planner: PlannerKind,
) -> Vec<Value> {
    let rows = result.unwrap_or_else(|e| {
        vec![json!({"kind": "planning", "skipped": format!("{e:#}"), "problem": problem, "mode": mode})]
    });
    rows.into_iter()
        .map(|mut r| {
            r["side"] = json!(side);
            r["planner_common"] = json!(planner.name());
            r
        })
        .collect()
}

/// Medians of one (problem, mode, planner, side) group.
#[derive(Default)]
struct Stats {
    runs: usize,
    skipped: usize,
    solved: usize,
    time_s: Option<f64>,
    us_per_iteration: Option<f64>,
    us_per_check: Option<f64>,
    iterations: Option<f64>,
    path_length: Option<f64>,
}

fn stats(rows: &[&Value]) -> Stats {
    let f = |r: &Value, k: &str| r.get(k).and_then(Value::as_f64);
    let done: Vec<&&Value> = rows.iter().filter(|r| r.get("skipped").is_none()).collect();
    let sum = |k: &str| done.iter().filter_map(|r| f(r, k)).sum::<f64>();
    let (t, it, checks) = (sum("time_s"), sum("iterations"), sum("collision_checks"));
    Stats {
        runs: done.len(),
        skipped: rows.len() - done.len(),
        solved: done.iter().filter(|r| r.get("solved") == Some(&json!(true))).count(),
        time_s: median(done.iter().filter_map(|r| f(r, "time_s"))),
        us_per_iteration: (it > 0.0).then(|| 1e6 * t / it),
        us_per_check: (checks > 0.0).then(|| 1e6 * t / checks),
        iterations: median(done.iter().filter_map(|r| f(r, "iterations"))),
        path_length: median(done.iter().filter_map(|r| f(r, "path_length"))),
    }
}

/// The side-by-side table: one line per side, ratios against the OMPL line of the same group.
fn table(rows: &[Value]) -> String {
    let mut out = String::from(
        "| problem | mode | planner | side | runs | solved | median time ms | µs / iteration | µs / check | median iterations | median path m | time ours/theirs | µs/it ours/theirs | path ours/theirs |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for problem in ["floorplan", "lab"] {
        for mode in MODES {
            for (planner, _, variants) in PLANNERS {
                let group = |side: &str| -> Vec<&Value> {
                    rows.iter()
                        .filter(|r| {
                            r["problem"] == json!(problem)
                                && r["mode"] == json!(mode)
                                && r["planner_common"] == json!(planner.name())
                                && r["side"] == json!(side)
                        })
                        .collect()
                };
                let stock = stats(&group(STOCK));
                if stock.runs + stock.skipped == 0 {
                    continue;
                }
                let direct = stats(&group(DIRECT));
                let reference = if direct.runs > 0 { DIRECT } else { STOCK };
                let theirs = if direct.runs > 0 { direct } else { stock };
                let sides =
                    [STOCK, DIRECT]
                        .into_iter()
                        .filter(|s| *s == STOCK || reference == DIRECT)
                        .map(str::to_owned)
                        .chain(variants.iter().flat_map(|&v| {
                            OUR_BACKENDS.iter().map(move |&b| our_side(b, planner, v))
                        }));
                for side in sides {
                    let s = stats(&group(&side));
                    let is_theirs = side.starts_with("ompl");
                    let solved = if mode == "explore" {
                        "–".to_owned()
                    } else {
                        format!("{}/{}", s.solved, s.runs)
                    };
                    let runs = if s.skipped > 0 {
                        format!("{} (+{} skipped)", s.runs, s.skipped)
                    } else {
                        s.runs.to_string()
                    };
                    let r = |a: Option<f64>, b: Option<f64>| {
                        if is_theirs { String::new() } else { ratio(a, b) }
                    };
                    let _ = writeln!(
                        out,
                        "| {problem} | {mode} | {planner} | {side}{} | {runs} | {solved} | {} | {} | {} | {} | {} | {} | {} | {} |",
                        if side == reference { " (ref.)" } else { "" },
                        num(s.time_s.map(|t| t * 1e3)),
                        num(s.us_per_iteration),
                        num(s.us_per_check),
                        num(s.iterations),
                        num(s.path_length),
                        r(s.time_s, theirs.time_s),
                        r(s.us_per_iteration, theirs.us_per_iteration),
                        r(s.path_length, theirs.path_length),
                    );
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_pool_time_over_iterations_and_skip_skipped_rows() {
        let rows = [
            json!({"time_s": 1.0, "iterations": 10.0, "collision_checks": 20.0, "solved": true, "path_length": 3.0}),
            json!({"time_s": 3.0, "iterations": 30.0, "collision_checks": 20.0, "solved": false, "path_length": null}),
            json!({"skipped": "x"}),
        ];
        let s = stats(&rows.iter().collect::<Vec<_>>());
        assert_eq!((s.runs, s.skipped, s.solved), (2, 1, 1));
        assert!((s.us_per_iteration.unwrap() - 1e5).abs() < 1e-6);
        assert!((s.us_per_check.unwrap() - 1e5).abs() < 1e-6);
        assert_eq!(s.time_s, Some(2.0));
        assert_eq!(s.path_length, Some(3.0));
    }

    #[test]
    fn variants_get_their_own_side_and_the_common_planner_keeps_the_plain_label() {
        let (prm, valid) = (PlannerKind::Prm, PlannerKind::PrmValid);
        assert_eq!(our_side(Backend::Trimesh, prm, prm), "ours/trimesh");
        assert_eq!(our_side(Backend::Trimesh, prm, valid), "ours/trimesh prm-valid");
        let rows: Vec<Value> = ["ompl+fcl", "ours/polygon", "ours/polygon prm-valid"]
            .iter()
            .map(|side| {
                json!({"problem": "floorplan", "mode": "solve", "planner_common": "prm",
                       "side": side, "time_s": 0.002, "iterations": 10.0, "solved": true,
                       "path_length": 4.0})
            })
            .collect();
        let t = table(&rows);
        assert!(t.contains("| ours/polygon prm-valid | 1 | 1/1 |"), "{t}");
        assert!(t.contains("| ours/polygon | 1 | 1/1 |"), "{t}");
    }
}
