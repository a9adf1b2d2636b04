//! `patchnav run CONFIG.toml`: the demo's job (`patchnav demo`) on the user's own data. Reads
//! scans with their poses, a mesh, a map file or a point cloud; builds the map types of thesis
//! Table 6.1 that the input allows in the chosen backends; plans with the chosen planners and
//! seeds from one start to the goals on every map; optionally filters a time-of-flight frame
//! (AAT + unwrapping, thesis §2.5) and classifies a terrain frame (plane Hough transform,
//! Ch. 4); optionally times RRTs against iterations (`[timing]`, Fig 6.4) and compares the
//! volume explored on every map (`[volume]`, Tables 6.2 / 6.4, Fig 6.1); and writes
//! `results.json`, `report.html` (the demo's report; a section without its `[timing]` or
//! `[volume]` reads "not computed") and the 3D files into the output folder, with a summary on
//! standard output.
//!
//! # The configuration file
//!
//! TOML; unknown keys are errors; paths are relative to the configuration file's folder.
//! `docs/run.md` has a complete example.
//!
//! | key | default | meaning |
//! |---|---|---|
//! | `input.scans` | — | scan files in their sensor frames (`.ply .pcd .3d .bin .xyz .png`); exactly one of `scans`, `mesh`, `map`, `cloud` |
//! | `input.poses` | each scan's own pose (PLY/PCD header, 3DTK `.pose`) | a `poses.json` as `patchnav simulate` writes and `patchnav extract --poses` reads, matched by file name |
//! | `input.mesh` | — | an OBJ mesh: coplanar faces become planar patches (faces that make no valid polygon: trimesh patches) |
//! | `input.map` | — | a map file (`.pmap`) of any backend |
//! | `input.cloud` | — | a point cloud in the world frame (the `pc` map) |
//! | `input.name` | the configuration file's stem | the data set's name in the report |
//! | `input.skip_non_finite` | `false` | drop NaN points of unorganised clouds instead of failing |
//! | `maps.types` | all the input allows: scans and mesh `planes hybrid trimesh pc`, map file its own type, cloud `pc` | map types to build |
//! | `maps.backends` | `["trimesh"]` (a map file: its own backend) | backends each patch map is loaded into (`polygon bbox6d trimesh rapier`); one Table 6.1 row and one set of planning runs per backend; the `pc` map is always `pointcloud` |
//! | `maps.sensor` | `"alrf"` | extraction presets for scans: `alrf`, `range-camera`, `exact` |
//! | `maps.spacing` | `0.05` | mesh input: sample spacing of its `pc` map, metres |
//! | `maps.mesh_edge` | none (unsplit) | mesh input: longest triangle edge of its `trimesh` map, metres |
//! | `maps.max_patch_triangles` | `324` | mesh input: most triangles per patch of its `trimesh` map |
//! | `plan.start` | — (required) | `[x, y, z]`, metres; must be free on every map |
//! | `plan.goals` | — (required) | `[[x, y, z], ...]` |
//! | `plan.radius` | `0.3` | robot radius, metres |
//! | `plan.step` | `1.0` | longest RRT edge, metres |
//! | `plan.goal_tolerance` | `0.5` | how close a vertex must come to a goal, metres |
//! | `plan.planners` | `["rrt", "prm"]` | any planner of `patchnav plan` (`rrt ma-rrt evasion-rrt prm ma-prm rrt-connect prm-star lazy-prm rrt-star prm-valid`) |
//! | `plan.seeds` | `[1]` | seeds; every planner runs once per seed on every map |
//! | `plan.max_iterations` | `10000` | iteration budget of a run (it stops once every goal is reached) |
//! | `tof.range`, `tof.amplitude`, `tof.meta` | — (required in `[tof]`) | a 16-bit PNG pair and its JSON sidecar, as `patchnav tof filter` reads |
//! | `tof.confidence` | none | optional confidence PNG |
//! | `tof.method` | `regions` | `regions` (region unwrapping: unwraps only where a region agrees), `aat` (the thesis's adaptive amplitude threshold) or `at` (plain threshold 160) |
//! | `tof.aat` | the sidecar's (thesis: 0.2) | AAT threshold (also the evidence of `regions`) |
//! | `tof.unwrap` | `false` | with `method = "aat"`: unwrap the flagged pixels instead of dropping them |
//! | `tof.low_at` | none | drop pixels with amplitude ≤ this before segmenting (`regions`), or flagged ones instead of unwrapping them (`aat` with `unwrap`) |
//! | `terrain.frame` | — (required in `[terrain]`) | a range frame, as `patchnav terrain` reads |
//! | `terrain.resolution` | `15.0` | Hough angular resolution, degrees |
//! | `terrain.sensor_height` | `0.45` | metres above the floor |
//! | `terrain.pitch` | `0.0` | degrees down from level |
//! | `terrain.axes` | camera for organised frames, lidar otherwise | `camera` or `lidar` |
//! | `terrain.max_range` | none | keep points within this horizontal range, metres |
//! | `terrain.sectors` | `3` | azimuth sectors of the ±45° forward view |
//! | `timing.iterations` | `3000` | iterations of every timed RRT (K of Fig 6.4) |
//! | `timing.checkpoints` | `20` | times recorded per run (every K/N iterations, and at 100, 500, 1000) |
//! | `timing.seeds` | `[1, …, 8]` | seeds; one run per seed from every start on every map |
//! | `timing.starts` | `[plan.start]` | `[[x, y, z], ...]`; each must be free on every map |
//! | `volume.planner` | `"rrt"` | `rrt` (Table 6.2) or `prm` (Table 6.4) |
//! | `volume.iterations`, `volume.seeds`, `volume.starts` | `[timing]`'s, else as in `[timing]` | the runs whose roadmaps fill the grid |
//! | `volume.cells` | `256` | voxels per axis of the grid covering every map (1–1024) |
//! | `output.dir` | `"out/run"` | output folder |
//! | `output.write_3d` | `true` | write the map meshes, roadmaps, paths and the ToF cloud |
//!
//! # Choices
//! * Planning uses `patchnav plan`'s planners ([`roadmap::named_planner_on`]: every planner
//!   tests the direct step to a goal after each vertex, thesis §6.2.3), each map sampled in its
//!   own box (thesis L6460), stopping when every goal is reached or the budget is spent.
//! * Planners that need a patch map (`evasion-rrt`, `ma-prm`, `ma-rrt`, thesis Table 5.2) are
//!   skipped on the `pc` map, with a line in the summary.
//! * `[timing]` and `[volume]` run as the demo's timing and volume stage
//!   ([`crate::demo::explore`]): RRT (Algorithm 13) or PRM (Algorithm 14) without
//!   goals, each map sampled in its own box, one run per start and seed, the explored space
//!   (every edge, every free vertex) rasterised into one grid covering all maps. Their defaults
//!   are the demo's default scale; when `[volume]` asks for the RRT with `[timing]`'s
//!   iterations, seeds and starts (its defaults), the timed runs fill the grid, as in the demo.
//!   The demo starts at the lab's room corners; here the starts are the user's.
//! * A mesh's `trimesh` map is its surfaces as triangles (planar patches triangulated by
//!   constrained Delaunay), split to `maps.mesh_edge` if given and cut into patches of at most
//!   `maps.max_patch_triangles`, as the simulated scenes' trimesh maps
//!   ([`crate::scene_map::SceneSurfaces::patches`]); unsplit it has the planes map's geometry,
//!   so the two differ only in their collision objects. `mesh_edge = 0.1` gives the lab
//!   experiments' triangle size, which stands in for the scan grid of naive trimesh growing.
//! * Without a simulation's truth, the ToF section's wrapped / unwrapped-correctly / wrong
//!   percentages and the terrain's true class are unknown.

mod config;
mod pipeline;

pub use config::{Config, Input, load};

use crate::Progress;
use anyhow::{Context, Result};
use std::fmt::Write as _;

/// Runs the configuration file `path` (`patchnav run`): its stages, then `results.json` and
/// `report.html` in its output folder. Returns the path of the report and the summary lines.
///
/// # Errors
/// A bad configuration (one line naming the key), or a stage failing.
pub fn run(
    path: &std::path::Path,
    progress: &dyn Progress,
) -> Result<(std::path::PathBuf, String)> {
    let config = load(path)?;
    std::fs::create_dir_all(&config.out)
        .with_context(|| format!("output.dir: creating {}", config.out.display()))?;
    let (results, skipped) = pipeline::run(&config, progress)?;
    let json = config.out.join("results.json");
    pointcloud::io::write_bytes_atomically(&json, serde_json::to_string(&results)? + "\n")?;
    let html = config.out.join("report.html");
    crate::report::write(&results, &html)?;
    Ok((html, summary(&config, &results, &skipped)?))
}

/// `n` and `what`, with an `s` unless `n` is 1.
fn plural(n: usize, what: &str) -> String {
    format!("{n} {what}{}", if n == 1 { "" } else { "s" })
}

/// The summary printed on standard output.
fn summary(config: &Config, r: &crate::results::DemoResults, skipped: &[String]) -> Result<String> {
    let mut out = String::new();
    let what = match &config.input {
        Input::Scans { files, poses } => format!(
            "{} scans, {} points, poses {}",
            files.len(),
            r.scene.points,
            poses.as_ref().map_or("from the scans".to_owned(), |p| format!("from {}", p.display()))
        ),
        Input::Mesh(p) => format!("mesh {}", p.display()),
        Input::Map(p) => format!("map file {}", p.display()),
        Input::Cloud(p) => format!("cloud {}, {} points", p.display(), r.scene.points),
    };
    writeln!(out, "{}: {what}", config.name)?;
    if let Some(t) = &r.tof {
        writeln!(
            out,
            "tof: {} on {}×{}: {:.1} % discarded, {:.1} ms",
            t.method, t.width, t.height, t.discarded_percent, t.millis
        )?;
    }
    if let Some(t) = &r.terrain {
        writeln!(
            out,
            "terrain: {} ({}), sectors {}",
            t.class,
            if t.drivable { "drivable" } else { "not drivable" },
            t.sectors.iter().map(|(c, _)| c.as_str()).collect::<Vec<_>>().join(" / ")
        )?;
    }
    writeln!(out, "maps:")?;
    for m in &r.maps {
        let held = if m.points > 0 {
            format!("{} points", m.points)
        } else {
            format!(
                "{} planar + {} trimesh patches, {} triangles",
                m.planar_patches, m.trimesh_patches, m.triangles
            )
        };
        writeln!(
            out,
            "  {:<8} {:<10} {held}, {:.1} MB, built in {:.2} s",
            m.kind,
            m.backend,
            m.memory_bytes as f64 / 1e6,
            m.build_seconds
        )?;
    }
    writeln!(out, "plans (radius {} m, goals: {}):", config.plan.radius, config.plan.goals.len())?;
    for p in &r.plans {
        writeln!(
            out,
            "  {:<8} {:<10} {:<12} seed {:<3} {}  {:.2} m, {} samples, {:.3} s",
            p.map,
            p.backend,
            p.planner,
            p.seed,
            if p.solved { "solved  " } else { "unsolved" },
            p.path_length,
            p.iterations,
            p.seconds
        )?;
    }
    for line in skipped {
        writeln!(out, "  {line}")?;
    }
    if let Some(t) = &config.timing {
        let medians: Vec<String> = r
            .timing
            .iter()
            .filter_map(|c| Some(format!("{} {:.1} ms", c.map, c.median_ms.last()?)))
            .collect();
        writeln!(
            out,
            "rrt timing ({} × {}, median at {} iterations): {}",
            plural(t.starts.len(), "start"),
            plural(t.seeds.len(), "seed"),
            t.iterations,
            medians.join(", ")
        )?;
    }
    if let Some(v) = &r.volume {
        let volumes: Vec<String> =
            v.maps.iter().zip(&v.volumes_m3).map(|(m, x)| format!("{m} {x:.2} m³")).collect();
        writeln!(
            out,
            "explored volume ({}, {} runs per map of {} iterations, cells of {:.3} m): {}",
            v.planner,
            v.runs,
            v.iterations,
            v.cell,
            volumes.join(", ")
        )?;
        if let Some((x, a, b)) = v.largest_difference() {
            writeln!(
                out,
                "  largest difference: {x:.3} % of the {a} map's volume not in the {b} map's"
            )?;
        }
    }
    let stages: Vec<String> =
        r.stages.iter().map(|s| format!("{} {:.2} s", s.stage, s.seconds)).collect();
    writeln!(out, "time: {}", stages.join(", "))?;
    writeln!(
        out,
        "wrote {} files and results.json into {}",
        r.files.len() + 1,
        config.out.display()
    )?;
    Ok(out)
}
