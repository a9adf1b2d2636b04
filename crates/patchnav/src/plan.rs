//! `patchnav plan MAP --start x,y,z --goal x,y,z --planner rrt|prm|prm-valid|prm-star|lazy-prm|rrt-star|rrt-connect|evasion-rrt|ma-prm|ma-rrt ...`: one planning run on a
//! map file, printing the status, the counters and the path, and writing the roadmap and the
//! path as OBJ polylines (`v` and `l` records) that any 3D viewer opens, or the map, roadmap
//! and paths as ROS 2 markers in an MCAP file (`--mcap`, [`patch_pipeline::viewer`]).

use crate::names;
use crate::progress::Progress;
use anyhow::{Context, Result, bail};
use clap::Args;
use patch_core::{Point3, Real};
use patch_pipeline::plan::{PlanSetup, plan_on_map};
use patch_pipeline::polylines::{write_obj_lines, write_obj_roadmap};
use patch_pipeline::viewer::{ViewerContent, viewer_header, write_viewer_mcap};
use roadmap::{PathMetrics, PlannerKind};
use std::fmt::Write as _;
use std::path::PathBuf;

/// Arguments of `patchnav plan`: either one run on a map file (`MAP --start --goal --radius`),
/// or the runs of a shared planning problem (`--problem P.json --backend B --mode M`).
#[derive(Args, Debug)]
pub struct PlanArgs {
    /// A map file written by `patchnav map build` (any backend).
    #[arg(required_unless_present = "problem", conflicts_with = "problem")]
    pub map: Option<PathBuf>,
    /// Start position `x,y,z` in metres.
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true, required_unless_present = "problem", conflicts_with = "problem")]
    pub start: Option<Point3>,
    /// A goal position `x,y,z` (repeat for several regions of interest).
    #[arg(long = "goal", value_parser = parse_point, allow_hyphen_values = true, required_unless_present = "problem", conflicts_with = "problem")]
    pub goals: Vec<Point3>,
    /// How close a vertex must come to a goal, metres.
    #[arg(long, default_value_t = 0.5, conflicts_with = "problem")]
    pub goal_tolerance: Real,
    /// The planner.
    #[arg(long, value_parser = names::all::<PlannerKind>(), default_value_t = PlannerKind::Rrt)]
    pub planner: PlannerKind,
    /// Robot radius (the capsule radius of every step), metres.
    #[arg(long, required_unless_present = "problem", conflicts_with = "problem")]
    pub radius: Option<Real>,
    /// Longest tree edge (RRT), metres.
    #[arg(long, default_value_t = 1.0, conflicts_with = "problem")]
    pub step: Real,
    /// Seed of the planner's random samples.
    #[arg(long, default_value_t = 0, conflicts_with = "problem")]
    pub seed: u64,
    /// Iteration budget.
    #[arg(long, default_value_t = 10_000, conflicts_with = "problem")]
    pub iterations: u64,
    /// Keep growing after every goal is reached (the thesis's fixed-K runs) instead of stopping.
    #[arg(long, conflicts_with = "problem")]
    pub explore: bool,
    /// Write the roadmap as OBJ polylines.
    #[arg(long, conflicts_with = "problem")]
    pub roadmap_out: Option<PathBuf>,
    /// Write the path to the first goal as an OBJ polyline.
    #[arg(long, conflicts_with = "problem")]
    pub path_out: Option<PathBuf>,
    /// Write the map, the roadmap and the paths (one per goal reached) as ROS 2 markers in an
    /// MCAP file that Foxglove or RViz replays (/patchnav/map, /patchnav/roadmap,
    /// /patchnav/path).
    #[arg(long, conflicts_with = "problem")]
    pub mcap: Option<PathBuf>,
    /// With --mcap: the frame the messages are in.
    #[arg(long, default_value = patch_pipeline::viewer::DEFAULT_FRAME_ID, requires = "mcap")]
    pub frame_id: String,
    /// Also shortcut every path (greedy pass and 100 random attempts) and report it.
    #[arg(long, conflicts_with = "problem")]
    pub shortcut: bool,
    #[command(flatten)]
    pub problem: crate::problem::ProblemArgs,
}

fn parse_point(text: &str) -> Result<Point3, String> {
    let v: Vec<Real> = text
        .split(',')
        .map(|s| s.trim().parse::<Real>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("`{text}` is not x,y,z: {e}"))?;
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(Point3::new(x, y, z)),
        _ => Err(format!("`{text}` is not three finite numbers x,y,z")),
    }
}

/// Runs `patchnav plan`.
pub fn run(args: &PlanArgs, progress: &Progress) -> Result<()> {
    if args.problem.problem.is_some() {
        return crate::problem::run(&args.problem, args.planner, progress);
    }
    // clap enforces these when there is no --problem.
    let (Some(map_path), Some(start), Some(radius)) = (&args.map, args.start, args.radius) else {
        bail!("give a MAP with --start, --goal and --radius, or --problem");
    };
    let map = patch_pipeline::files::open_map(map_path)?;
    let setup = PlanSetup {
        start,
        goals: args.goals.clone(),
        goal_tolerance: args.goal_tolerance,
        planner: args.planner,
        radius,
        step: args.step,
        seed: args.seed,
        iterations: args.iterations,
        explore: args.explore,
        shortcut: args.shortcut,
    };
    let spinner = progress.spinner("planning");
    let outcome =
        plan_on_map(&map, &setup).with_context(|| format!("planning on {}", map_path.display()))?;
    spinner.finish_and_clear();
    let c = outcome.counters;
    let mut out = String::new();
    writeln!(out, "planner:          {} on a `{}` map", outcome.planner, map.backend())?;
    writeln!(out, "status:           {:?}", outcome.status)?;
    writeln!(out, "samples:          {}", c.samples)?;
    writeln!(out, "vertices:         {}", c.vertices)?;
    writeln!(out, "edges:            {}", c.edges)?;
    writeln!(
        out,
        "collision checks: {} ({:.3} s)",
        c.collision_checks,
        c.collision_time.as_secs_f64()
    )?;
    for (i, goal) in setup.goals.iter().enumerate() {
        match &outcome.paths[i] {
            Some(path) => {
                let m = PathMetrics::of(path);
                writeln!(
                    out,
                    "goal {i} ({:.2}, {:.2}, {:.2}): reached, path of {} vertices, {:.3} m, \
                     {} turns ({} steep), curviness {:.1}°",
                    goal.x,
                    goal.y,
                    goal.z,
                    path.len(),
                    m.length,
                    m.turns,
                    m.steep_turns,
                    m.curviness.to_degrees()
                )?;
                if let Some(short) = &outcome.shortcuts[i] {
                    let m = PathMetrics::of(short);
                    writeln!(
                        out,
                        "        shortcut: {} vertices, {:.3} m, {} turns ({} steep), curviness {:.1}°",
                        short.len(),
                        m.length,
                        m.turns,
                        m.steep_turns,
                        m.curviness.to_degrees()
                    )?;
                }
            }
            None => writeln!(
                out,
                "goal {i} ({:.2}, {:.2}, {:.2}): not reached",
                goal.x, goal.y, goal.z
            )?,
        }
    }
    if let Some(file) = &args.roadmap_out {
        write_obj_roadmap(file, &outcome.roadmap)?;
    }
    if let Some(file) = &args.path_out {
        let path = outcome.paths[0].clone().unwrap_or_default();
        let line = (!path.is_empty()).then(|| (0..path.len()).collect());
        write_obj_lines(file, &path, line.into_iter())?;
    }
    if let Some(file) = &args.mcap {
        let paths: Vec<Vec<Point3>> =
            outcome.paths.iter().map(|p| p.clone().unwrap_or_default()).collect();
        let content = ViewerContent {
            map: Some(&map),
            roadmap: Some(&outcome.roadmap),
            paths: Some(&paths),
            cloud: None,
        };
        let summary = write_viewer_mcap(file, &content, &viewer_header(Some(&args.frame_id)))?;
        writeln!(out, "{}: {summary}", file.display())?;
    }
    progress.say(out.trim_end());
    Ok(())
}
