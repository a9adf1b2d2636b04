//! The object-safe planner face, its outcome and counters, and the machinery the planners
//! share (collision-check counting, start/goal validation, goal bookkeeping, paths).

use std::time::{Duration, Instant};

use patch_core::{
    CapsuleStep, Point3, Real, SpecificStepIntersector, StepHit, UnspecificStepIntersector,
};
use petgraph::graph::{NodeIndex, UnGraph};

use crate::space::{Goal, PlanningSpace, Problem};
use crate::termination::{Progress, Termination};

/// A roadmap: vertices are robot positions, an edge is a straight motion whose capsule of
/// the robot radius was found free; its weight is its length.
pub type Roadmap = UnGraph<Point3, Real>;

/// Whether a tree or roadmap planner also tests the straight step to each unreached goal.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum GoalStep {
    /// Goals are reached only by vertices the planner grows there (thesis Algorithms 13, 14).
    Grown,
    /// After each added vertex, also test the straight capsule step from it to each unreached
    /// goal centre, of any length (spec §7.17), and on success add the centre as a vertex (the
    /// thesis's Lesum variants, §6.2.3).
    Direct,
}

/// How a `solve` ended: an outcome, not an error (OMPL's `PlannerStatus`).
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum PlannerStatus {
    /// Every goal is connected to the start ([`Planner::path_to`] returns a path for each).
    Exact,
    /// The termination stopped the run with some goal unreached; `gap` is the largest, over the
    /// unreached goals, of the distance from the goal centre to the closest vertex connected
    /// to the start.
    Approximate {
        /// That distance, in metres.
        gap: Real,
    },
    /// The termination stopped the run with some goal unreached before any vertex was
    /// connected to the start (nothing was explored).
    Timeout,
    /// The start is not finite, lies outside the space's bounds, or its sphere collides.
    InvalidStart,
    /// Some goal centre is not finite, lies outside the bounds or its sphere collides, or its
    /// tolerance is not a finite non-negative number.
    InvalidGoal,
}

/// What a planner has done in its last `solve` (the thesis counts iterations, vertices and
/// collision checks, Fig. 6.9; OMPL's benchmark records the same).
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct PlannerCounters {
    /// Samples drawn (= iterations).
    pub samples: u64,
    /// Vertices of the roadmap.
    pub vertices: usize,
    /// Edges of the roadmap.
    pub edges: usize,
    /// Capsule checks asked of the map (unspecific or specific), including the start and goal
    /// validity checks.
    pub collision_checks: u64,
    /// Wall-clock time spent inside those checks, estimated from every 16th check (reading
    /// the clock around each would cost as much as a check on a small map).
    pub collision_time: Duration,
    /// Closest-patch queries ([`ProximityQuery::closest_patch`]) asked of the map: those of the
    /// medial-axis retraction of [`MaPrm`](crate::MaPrm) and [`MaRrt`](crate::MaRrt)
    /// (thesis §5.5.2); 0 for the other planners.
    ///
    /// [`ProximityQuery::closest_patch`]: patch_core::ProximityQuery::closest_patch
    pub proximity_queries: u64,
    /// Wall-clock time spent inside those queries (not part of `collision_time`).
    pub proximity_time: Duration,
}

/// A planner behind a trait object (generic inside, `dyn` at the boundary: a benchmark
/// harness holds `Box<dyn Planner + '_>`).
///
/// Every `solve` starts from scratch: the roadmap is cleared and the random stream re-seeded,
/// so solving the same problem twice gives the same roadmap.
pub trait Planner {
    /// A short name for reports (`"rrt"`, `"prm"`).
    fn name(&self) -> &'static str;

    /// Builds a roadmap for `problem` until `stop` says so, and tells how it ended.
    fn solve(&mut self, problem: &Problem, stop: &mut dyn Termination) -> PlannerStatus;

    /// The roadmap of the last `solve` (empty before the first and after
    /// [`clear`](Planner::clear)). Node 0 is the start.
    fn roadmap(&self) -> &Roadmap;

    /// The path from the start to goal number `goal` of the last problem, or `None` if it is
    /// unreached or out of range. It ends at the vertex that reached the goal (within the
    /// goal's tolerance, or the goal centre itself after a direct goal step), and is the
    /// shortest such path by length in the roadmap (the only one in a forest).
    fn path_to(&self, goal: usize) -> Option<Vec<Point3>>;

    /// The counters of the last `solve`.
    fn counters(&self) -> PlannerCounters;

    /// Forgets the roadmap, the goals reached and the counters.
    fn clear(&mut self);
}

/// Every this many checks one is timed; [`PlannerCounters::collision_time`] scales up.
const TIME_EVERY: u64 = 16;

/// Capsule checks through the map, counted, and timed by sampling every
/// [`TIME_EVERY`]th.
pub(crate) struct Checker<'a, M: ?Sized> {
    map: &'a M,
    radius: Real,
    checks: u64,
    /// The summed time of the timed checks.
    time: Duration,
}

impl<M: ?Sized> Checker<'_, M> {
    /// Runs one check on the map, counted, and timed if it is a sampled one.
    fn timed<T>(&mut self, check: impl FnOnce(&M) -> T) -> T {
        let sampled = self.checks.is_multiple_of(TIME_EVERY);
        self.checks += 1;
        if !sampled {
            return check(self.map);
        }
        let t0 = Instant::now();
        let out = check(self.map);
        self.time += t0.elapsed();
        out
    }

    /// The estimated time of all checks: the timed ones scaled to the count.
    fn estimated_time(&self) -> Duration {
        let timed = self.checks.div_ceil(TIME_EVERY);
        if timed == 0 {
            return Duration::ZERO;
        }
        self.time.mul_f64(self.checks as f64 / timed as f64)
    }
}

impl<'a, M: UnspecificStepIntersector + ?Sized> Checker<'a, M> {
    pub(crate) fn new(map: &'a M, radius: Real) -> Self {
        Checker { map, radius, checks: 0, time: Duration::ZERO }
    }

    /// Whether the robot's capsule from `a` to `b` is free. A step that cannot be built
    /// (non-finite points) counts as colliding.
    pub(crate) fn free(&mut self, a: &Point3, b: &Point3) -> bool {
        let Ok(step) = CapsuleStep::new(*a, *b, self.radius) else {
            return false;
        };
        self.timed(|map| map.is_step_free(&step))
    }
}

/// The most iterations [`Solution::reserve_for`] reserves room for (a larger budget grows
/// the roadmap as it goes beyond that).
const MAX_RESERVED: u64 = 1 << 18;

/// What a specific capsule check found.
pub(crate) enum Contact {
    /// The step is free.
    Free,
    /// The step first touches the map here.
    Hit(StepHit),
    /// The step could not be built (non-finite points): treated as colliding.
    Invalid,
}

impl<'a, M: SpecificStepIntersector + ?Sized> Checker<'a, M> {
    /// The first contact of the robot's capsule from `a` to `b`, counted and timed as one
    /// collision check.
    pub(crate) fn first_hit(&mut self, a: &Point3, b: &Point3) -> Contact {
        let Ok(step) = CapsuleStep::new(*a, *b, self.radius) else {
            return Contact::Invalid;
        };
        let hit = self.timed(|map| map.first_hit(&step));
        hit.map_or(Contact::Free, Contact::Hit)
    }

    /// The map (for patch look-ups).
    pub(crate) fn map(&self) -> &'a M {
        self.map
    }
}

/// The start and goal checks every planner makes before sampling.
pub(crate) fn validate<M>(
    problem: &Problem,
    space: &PlanningSpace,
    checker: &mut Checker<'_, M>,
) -> Option<PlannerStatus>
where
    M: UnspecificStepIntersector + ?Sized,
{
    let bounds = space.bounds();
    let valid = |p: &Point3, checker: &mut Checker<'_, M>| {
        p.iter().all(|c| c.is_finite()) && bounds.contains(p) && checker.free(p, p)
    };
    if !valid(&problem.start, checker) {
        return Some(PlannerStatus::InvalidStart);
    }
    for goal in &problem.goals {
        let tolerance_ok = goal.tolerance.is_finite() && goal.tolerance >= 0.0;
        if !(tolerance_ok && valid(&goal.center, checker)) {
            return Some(PlannerStatus::InvalidGoal);
        }
    }
    None
}

/// The [`Planner`] methods of a planner whose state is a `solution: Solution` field:
/// `roadmap`, `path_to`, `counters` and `clear`.
macro_rules! solution_accessors {
    () => {
        fn roadmap(&self) -> &$crate::Roadmap {
            &self.solution.graph
        }

        fn path_to(&self, goal: usize) -> Option<Vec<patch_core::Point3>> {
            self.solution.path_to(goal)
        }

        fn counters(&self) -> $crate::PlannerCounters {
            self.solution.counters
        }

        fn clear(&mut self) {
            self.solution = $crate::planner::Solution::default();
        }
    };
}
pub(crate) use solution_accessors;

/// The shared state of a solve: the roadmap, which vertex reached each goal, the counters.
#[derive(Clone, Debug, Default)]
pub(crate) struct Solution {
    pub(crate) graph: Roadmap,
    pub(crate) goals: Vec<Goal>,
    pub(crate) reached: Vec<Option<NodeIndex>>,
    pub(crate) counters: PlannerCounters,
}

impl Solution {
    pub(crate) fn reset(&mut self, goals: &[Goal]) {
        self.graph.clear();
        self.goals = goals.to_vec();
        self.reached = vec![None; goals.len()];
        self.counters = PlannerCounters::default();
    }

    /// Reserves room for a tree that adds at most one vertex and edge per iteration, for
    /// `budget` iterations (at most [`MAX_RESERVED`] of them), so the roadmap is not copied
    /// as it grows. `None` reserves nothing.
    pub(crate) fn reserve_for(&mut self, budget: Option<u64>) {
        let Some(budget) = budget else { return };
        let room = usize::try_from(budget.min(MAX_RESERVED)).unwrap_or(0);
        self.graph.reserve_nodes((room + 1).saturating_sub(self.graph.node_count()));
        self.graph.reserve_edges(room.saturating_sub(self.graph.edge_count()));
    }

    pub(crate) fn goals_reached(&self) -> usize {
        self.reached.iter().filter(|r| r.is_some()).count()
    }

    pub(crate) fn progress(&self, iterations: u64, started: Instant) -> Progress {
        Progress {
            iterations,
            vertices: self.graph.node_count(),
            goals_reached: self.goals_reached(),
            goals_total: self.goals.len(),
            started,
        }
    }

    pub(crate) fn finish(&mut self, samples: u64, checker: &Checker<'_, impl ?Sized>) {
        self.counters.samples = samples;
        self.counters.vertices = self.graph.node_count();
        self.counters.edges = self.graph.edge_count();
        self.counters.collision_checks = checker.checks;
        self.counters.collision_time = checker.estimated_time();
    }

    /// The final status; `connected(v)` tells whether vertex `v` is connected to the start.
    pub(crate) fn status(&self, connected: impl Fn(NodeIndex) -> bool) -> PlannerStatus {
        if self.reached.iter().all(Option::is_some) {
            return PlannerStatus::Exact;
        }
        let explored: Vec<Point3> =
            self.graph.node_indices().filter(|&v| connected(v)).map(|v| self.graph[v]).collect();
        if explored.len() <= 1 {
            return PlannerStatus::Timeout;
        }
        let gap = self
            .goals
            .iter()
            .zip(&self.reached)
            .filter(|(_, r)| r.is_none())
            .map(|(g, _)| {
                explored.iter().map(|p| (p - g.center).norm()).fold(Real::INFINITY, Real::min)
            })
            .fold(0.0, Real::max);
        PlannerStatus::Approximate { gap }
    }

    /// The path from node 0 to the vertex that reached `goal`: the shortest by edge length
    /// (Dijkstra; in the forests of most planners it is the unique path).
    pub(crate) fn path_to(&self, goal: usize) -> Option<Vec<Point3>> {
        let target = (*self.reached.get(goal)?)?;
        let start = NodeIndex::new(0);
        if start.index() >= self.graph.node_count() {
            return None;
        }
        let (_, nodes) =
            petgraph::algo::astar(&self.graph, start, |v| v == target, |e| *e.weight(), |_| 0.0)?;
        Some(nodes.into_iter().map(|v| self.graph[v]).collect())
    }
}

/// A uniform sample in the box (a flat axis gives its one value).
pub(crate) fn uniform(rng: &mut impl rand::Rng, space: &PlanningSpace) -> Point3 {
    let b = space.bounds();
    Point3::from(std::array::from_fn(|i| b.min[i] + (b.max[i] - b.min[i]) * rng.random::<Real>()))
        .inf(&b.max)
}
