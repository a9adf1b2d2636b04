//! Planning on the four map types: RRT and PRM from a room corner to the other three
//! (path metrics, thesis §5.6), RRTs timed against iterations (Fig 6.4, thesis Algorithm 13
//! as run for §6.1) and their explored volumes compared (Table 6.2, Fig 6.1).

use super::explore::{Exploration, Target, explore};
use super::maps::Built;
use super::{Files, GOAL_TOLERANCE, MAX_DRAWN, RADIUS, STEP, Settings, decimate, p3, p3mm};
use crate::Progress;
use crate::experiment::lab::{LAB_ROOM, common_box_of, corner_starts};
use crate::polylines::{write_obj_paths, write_obj_roadmap};
use crate::results::{PlanRun, TimingCurve, VolumeSection};
use crate::scene_map::{BuiltMap, MapKind};
use anyhow::{Context, Result, bail};
use patch_core::Point3;
use patch_map::AnyMap;
use roadmap::metrics::{turn_angles, upper_quartile};
use roadmap::{
    AnyOf, Goal, GoalReached, MaxIterations, PathMetrics, Planner, PlannerKind, PlannerStatus,
    PlanningSpace, Prm, PrmConfig, Problem, Rrt, RrtConfig,
};
use std::time::Instant;

/// The planners run on every map type: goal-biased RRT first, then PRM.
const PLANNERS: [PlannerKind; 2] = [PlannerKind::Rrt, PlannerKind::Prm];

/// Probability that an RRT sample is an unreached goal's centre (LaValle's goal bias; the
/// thesis's Lab runs grow without goals, its office runs test the goal directly instead).
pub const RRT_GOAL_BIAS: f64 = 0.05;

/// The planner `kind` of [`PLANNERS`] on `map`: thesis Algorithm 13 with a goal bias of
/// [`RRT_GOAL_BIAS`], or Algorithm 14 as the thesis configures it (six neighbours, no
/// edge-length limit). Neither tests the direct step to a goal after each vertex (the §6.2.3
/// Lesum variant): in the lab the corners see each other at 1 m height, so that test alone
/// would solve every problem without a roadmap.
fn planner(
    kind: PlannerKind,
    map: &AnyMap,
    space: PlanningSpace,
    seed: u64,
) -> Result<Box<dyn Planner + '_>> {
    Ok(match kind {
        PlannerKind::Rrt => {
            let config = RrtConfig { goal_bias: RRT_GOAL_BIAS, ..RrtConfig::thesis() };
            Box::new(Rrt::new(map, space, config, seed))
        }
        PlannerKind::Prm => Box::new(Prm::new(map, space, PrmConfig::thesis(), seed)),
        other => bail!("the demo plans with rrt and prm, not {other}"),
    })
}

/// The first point free on every map near each of the four room corners, 1 m up (the lab
/// experiments' starts).
pub fn starts(built: &Built) -> Result<Vec<Point3>> {
    let on: Vec<&AnyMap> = built.maps.iter().map(|m| &m.map).collect();
    corner_starts(&on, &common_box_of(&built.maps), RADIUS, LAB_ROOM, 4)
}

/// The demo's planning problem: from the south-west corner start to the south-east and
/// north-east corners and to the open floor in front of the rack's middle (the north-west
/// corner lies behind the rack's end, in a 0.96 m gap that the scans' mixed pixels narrow further:
/// a narrow-passage benchmark, not a demo; the timing runs still start there).
pub fn plan_points(built: &Built, starts: &[Point3]) -> Result<(Point3, Vec<Point3>)> {
    let (start, corners) = starts.split_first().context("no start")?;
    let mut goals: Vec<Point3> = corners.iter().take(2).copied().collect();
    let common = common_box_of(&built.maps);
    let free = |p: &Point3| {
        common.contains(p)
            && built.maps.iter().all(|m| {
                patch_core::CapsuleStep::sphere(*p, RADIUS)
                    .is_ok_and(|s| patch_core::UnspecificStepIntersector::is_step_free(&m.map, &s))
            })
    };
    // A small spiral around (4, 6.4, 1): in front of the rack, between its posts' rows.
    let front = (0..6)
        .flat_map(|ring| {
            let r = 0.2 * f64::from(ring);
            (0..8).map(move |k| {
                let a = std::f64::consts::FRAC_PI_4 * f64::from(k);
                Point3::new(4.0 + r * a.cos(), 6.4 + r * a.sin(), 1.0)
            })
        })
        .find(|p| free(p))
        .context("no free goal in front of the rack")?;
    goals.push(front);
    Ok((*start, goals))
}

/// One finished planning run as the report keeps it ([`PlanRun`]): its paths to the goals it
/// reached with their metrics (thesis §5.6), counters, and ([`drawn`](Self::drawn)) its
/// roadmap's edges for the pictures; optionally the roadmap and paths written as OBJ under
/// `files` (`roadmap-<tag>.obj`, `path-<tag>.obj`). Shared by the demo and `patchnav run`.
pub struct RunRecord<'a> {
    /// The type of the map planned on.
    pub kind: MapKind,
    /// The map planned on.
    pub map: &'a AnyMap,
    /// The planner's name in the report.
    pub name: String,
    /// The run's seed.
    pub seed: u64,
    /// Wall time of `solve`.
    pub seconds: f64,
    /// The start.
    pub start: Point3,
    /// The goal centres.
    pub goals: &'a [Point3],
    /// Keep the roadmap's edges (decimated) for the pictures.
    pub drawn: bool,
    /// Write the roadmap and the paths as OBJ files under this tag.
    pub obj_tag: Option<String>,
}

impl RunRecord<'_> {
    /// The [`PlanRun`] of `run`; writes its OBJ files when [`obj_tag`](Self::obj_tag) is set.
    pub fn record(self, run: &dyn Planner, files: &mut Files) -> Result<PlanRun> {
        let paths: Vec<Vec<Point3>> =
            (0..self.goals.len()).filter_map(|g| run.path_to(g)).collect();
        let metrics: Vec<PathMetrics> = paths.iter().map(|p| PathMetrics::of(p)).collect();
        let angles: Vec<f64> = paths.iter().flat_map(|p| turn_angles(p)).collect();
        let graph = run.roadmap();
        let (kind, name) = (self.kind, &self.name);
        if let Some(tag) = &self.obj_tag {
            let file = format!("roadmap-{tag}.obj");
            write_obj_roadmap(&files.path(&file), graph)?;
            files.add(format!("{name} roadmap on the {kind} map (OBJ polylines)"), &file)?;
            let file = format!("path-{tag}.obj");
            write_obj_paths(&files.path(&file), &paths)?;
            files.add(
                format!("{name} paths on the {kind} map, one polyline per goal (OBJ)"),
                &file,
            )?;
        }
        let edges = if self.drawn {
            let edges: Vec<[[f64; 3]; 2]> = graph
                .edge_indices()
                .filter_map(|e| graph.edge_endpoints(e))
                .map(|(a, b)| [p3mm(&graph[a]), p3mm(&graph[b])])
                .collect();
            decimate(&edges, MAX_DRAWN)
        } else {
            Vec::new()
        };
        let c = run.counters();
        Ok(PlanRun {
            map: kind.name().to_owned(),
            backend: self.map.backend().to_string(),
            planner: self.name,
            seed: self.seed,
            solved: paths.len() == self.goals.len(),
            seconds: self.seconds,
            iterations: c.samples,
            vertices: c.vertices,
            collision_checks: c.collision_checks,
            path_length: metrics.iter().map(|m| m.length).sum(),
            turns: metrics.iter().map(|m| m.turns).sum(),
            steep_turns: metrics.iter().map(|m| m.steep_turns).sum(),
            curviness_deg: upper_quartile(&angles).unwrap_or(0.0).to_degrees(),
            start: p3(&self.start),
            goals: self.goals.iter().map(p3).collect(),
            paths: paths.iter().map(|p| p.iter().map(p3).collect()).collect(),
            edges,
        })
    }
}

/// The planning space of `map`: its own box (thesis L6460).
fn space(map: &BuiltMap) -> Result<PlanningSpace> {
    PlanningSpace::new(map.map.bounds(), RADIUS, STEP)
        .with_context(|| format!("the {} map's planning space", map.kind))
}

/// Runs RRT and PRM from `start` to `goal_points` ([`plan_points`]) on every map, `plan_seeds` seeds
/// each, and writes the first seed's roadmap and paths (`roadmap-MAP-PLANNER.obj`,
/// `path-MAP-PLANNER.obj`). Only the first seed's run carries its (decimated) roadmap edges
/// for the pictures; the other runs have metrics and paths only.
pub fn plan_all(
    built: &Built,
    start: &Point3,
    goal_points: &[Point3],
    seed: u64,
    settings: &Settings,
    progress: &dyn Progress,
    files: &mut Files,
) -> Result<Vec<PlanRun>> {
    let goals: Vec<Goal> =
        goal_points.iter().map(|&center| Goal { center, tolerance: GOAL_TOLERANCE }).collect();
    let problem = Problem { start: *start, goals };
    let bar =
        progress.bar((built.maps.len() * PLANNERS.len()) as u64 * settings.plan_seeds, "planning");
    let mut runs = Vec::new();
    for m in &built.maps {
        let space = space(m)?;
        for kind in PLANNERS {
            for s in 0..settings.plan_seeds {
                let run_seed = seed.wrapping_add(s);
                let mut run = planner(kind, &m.map, space, run_seed)?;
                let t0 = Instant::now();
                let status = run.solve(
                    &problem,
                    &mut AnyOf(GoalReached, MaxIterations(settings.plan_iterations)),
                );
                let seconds = t0.elapsed().as_secs_f64();
                if status == PlannerStatus::InvalidStart {
                    bail!("the start is not free on the {} map", m.kind);
                }
                let name = run.name().to_owned();
                let record = RunRecord {
                    kind: m.kind,
                    map: &m.map,
                    drawn: s == 0,
                    obj_tag: (s == 0).then(|| format!("{}-{name}", m.kind)),
                    name,
                    seed: run_seed,
                    seconds,
                    start: *start,
                    goals: goal_points,
                };
                runs.push(record.record(run.as_ref(), files)?);
                bar.inc(1);
            }
        }
    }
    bar.finish_and_clear();
    Ok(runs)
}

/// Grows RRTs (thesis Algorithm 13, no goal) from the first `timing_starts` corners with
/// `timing_seeds` seeds on every map, timed at checkpoints (Fig 6.4: median and quartiles per
/// map type), and rasterises each map type's explored space (every edge, every free vertex)
/// into one voxel grid covering all maps: the congruence table (Table 6.2) and a horizontal
/// slice at the start height (Fig 6.1). See [`explore`].
pub fn timing_and_volume(
    built: &Built,
    starts: &[Point3],
    seed: u64,
    settings: &Settings,
    progress: &dyn Progress,
) -> Result<(Vec<TimingCurve>, VolumeSection)> {
    let targets: Vec<Target<'_>> =
        built.maps.iter().map(|m| Target { name: m.kind.name().to_owned(), map: &m.map }).collect();
    let seeds: Vec<u64> = (0..settings.timing_seeds).map(|s| seed.wrapping_add(s)).collect();
    let exploration = Exploration {
        planner: PlannerKind::Rrt,
        iterations: settings.iterations,
        starts: &starts[..settings.timing_starts.min(starts.len())],
        seeds: &seeds,
        radius: RADIUS,
        step: STEP,
        checkpoints: Some(settings.checkpoints),
        cells: Some(settings.cells),
    };
    let (curves, volume) = explore(&targets, &exploration, progress)?;
    Ok((curves, volume.context("the demo asks for the explored volume")?))
}
