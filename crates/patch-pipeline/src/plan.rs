//! One planning run on a map: what `patchnav plan MAP --start --goal --radius` and the Python
//! package's `plan` do (thesis Ch. 5; the planners of `roadmap`).
//!
//! Every planner tests, after each added vertex, whether the goal is directly reachable by one
//! free capsule step (the thesis's §6.2.3 variant), so their results compare. The same map,
//! settings and seed give the same roadmap and paths, whichever program asks.

use anyhow::{Context, Result, bail, ensure};
use patch_core::{Point3, Real};
use patch_map::AnyMap;
use roadmap::{
    AnyOf, Goal, GoalReached, MaxIterations, PlannerCounters, PlannerKind, PlannerStatus,
    PlanningSpace, Problem, Roadmap, ShortcutConfig, named_planner_on, shortcut_path,
};

/// A planning run's settings. Error messages name the command line's flags.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanSetup {
    /// The robot's start position.
    pub start: Point3,
    /// Goal positions (regions of interest), at least one.
    pub goals: Vec<Point3>,
    /// How close a vertex must come to a goal, metres.
    pub goal_tolerance: Real,
    /// The planner.
    pub planner: PlannerKind,
    /// Robot radius (the capsule radius of every step), metres.
    pub radius: Real,
    /// Longest tree edge (RRT), metres.
    pub step: Real,
    /// Seed of the planner's random samples.
    pub seed: u64,
    /// Iteration budget.
    pub iterations: u64,
    /// Keep growing after every goal is reached (the thesis's fixed-K runs).
    pub explore: bool,
    /// Also shortcut every path (greedy pass and 100 random attempts, seeded by `seed`).
    pub shortcut: bool,
}

impl PlanSetup {
    /// The command line's defaults: RRT, 0.5 m goal tolerance, 1 m steps, seed 0, 10,000
    /// iterations, stop when every goal is reached, no shortcutting.
    pub fn new(start: Point3, goals: Vec<Point3>, radius: Real) -> PlanSetup {
        PlanSetup {
            start,
            goals,
            goal_tolerance: 0.5,
            planner: PlannerKind::Rrt,
            radius,
            step: 1.0,
            seed: 0,
            iterations: 10_000,
            explore: false,
            shortcut: false,
        }
    }
}

/// What a planning run found.
#[derive(Clone, Debug)]
pub struct PlanOutcome {
    /// The planner's short name.
    pub planner: &'static str,
    /// How the run ended.
    pub status: PlannerStatus,
    /// Its counters.
    pub counters: PlannerCounters,
    /// Per goal: the path from the start, or `None` if unreached.
    pub paths: Vec<Option<Vec<Point3>>>,
    /// Per goal: the shortcut path (`None` if unreached or not asked for).
    pub shortcuts: Vec<Option<Vec<Point3>>>,
    /// The roadmap (node 0 is the start).
    pub roadmap: Roadmap,
}

/// Plans on `map` as `setup` says ([`named_planner_on`]).
///
/// # Errors
/// An empty map, no goal, a non-finite position, a radius, step or tolerance that is not a
/// positive number of metres, or a planner the map's backend cannot serve.
pub fn plan_on_map(map: &AnyMap, setup: &PlanSetup) -> Result<PlanOutcome> {
    ensure!(!setup.goals.is_empty(), "give at least one --goal");
    let finite = |p: &Point3| p.iter().all(|c| c.is_finite());
    ensure!(finite(&setup.start), "--start must be three finite numbers");
    ensure!(setup.goals.iter().all(finite), "every --goal must be three finite numbers");
    ensure!(
        setup.goal_tolerance.is_finite() && setup.goal_tolerance > 0.0,
        "--goal-tolerance must be a positive number of metres, not {}",
        setup.goal_tolerance
    );
    let bounds = map.bounds();
    if bounds.is_empty() {
        bail!("the map is empty, so it has no bounds to sample in");
    }
    let space = PlanningSpace::new(bounds, setup.radius, setup.step)
        .context("--radius and --step must be positive numbers of metres")?;
    let problem = Problem {
        start: setup.start,
        goals: setup
            .goals
            .iter()
            .map(|&center| Goal { center, tolerance: setup.goal_tolerance })
            .collect(),
    };
    let mut planner = named_planner_on(setup.planner, map, space, setup.seed)?;
    let status = if setup.explore {
        planner.solve(&problem, &mut MaxIterations(setup.iterations))
    } else {
        planner.solve(&problem, &mut AnyOf(GoalReached, MaxIterations(setup.iterations)))
    };
    let paths: Vec<Option<Vec<Point3>>> =
        (0..problem.goals.len()).map(|i| planner.path_to(i)).collect();
    let shortcuts = paths
        .iter()
        .map(|p| {
            let p = p.as_ref().filter(|_| setup.shortcut)?;
            Some(shortcut_path(map, p, setup.radius, &ShortcutConfig::standard(), setup.seed))
        })
        .collect();
    Ok(PlanOutcome {
        planner: planner.name(),
        status,
        counters: planner.counters(),
        paths,
        shortcuts,
        roadmap: planner.roadmap().clone(),
    })
}
