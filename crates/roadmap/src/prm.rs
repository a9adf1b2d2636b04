//! The probabilistic roadmap (Kavraki et al. 1996; thesis Algorithm 14, §5.5 and §6.1).

use std::time::Instant;

use patch_core::{CapsuleStep, Point3, Real, UnspecificStepIntersector};
use petgraph::graph::NodeIndex;
use petgraph::unionfind::UnionFind;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::nn::{KdNeighbors, NearestNeighbors};
use crate::planner::{self, Checker, Planner, PlannerCounters, PlannerStatus, Roadmap, Solution};
use crate::space::{PlanningSpace, Problem};
use crate::termination::Termination;

/// The choices of a [`Prm`]. No `Default`: pick [`PrmConfig::thesis`] and change fields.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PrmConfig {
    /// How many nearest existing vertices a new sample tries to connect to (the thesis's `N`,
    /// not given there; spec §7.4 recommends at least 6, Fig. 6.9). Ignored with
    /// [`star`](Self::star).
    pub neighbours: usize,
    /// Only vertices within this distance are tried; `None`: no edge-length limit, as in the
    /// thesis (§5.5, §6.1). A non-finite or negative radius connects nothing.
    pub connection_radius: Option<Real>,
    /// After each added vertex, if an unreached goal has no vertex yet, also test the straight
    /// capsule step from the vertex to the goal centre and on success add the centre as a
    /// vertex (the direct goal test of the thesis's Lesum variants, §6.2.3, carried over).
    pub direct_goal_step: bool,
    /// PRM* (Karaman & Frazzoli 2011, the k-nearest variant; not in the thesis): a sample
    /// added as the `n`-th vertex tries its `k(n) = ⌈e·(1 + 1/3)·ln n⌉` nearest existing
    /// vertices (3D; [`PrmConfig::neighbours_for`]) instead of [`neighbours`](Self::neighbours),
    /// and also connects to neighbours already in its component, so the roadmap has cycles and
    /// paths are shortest by length in it. `false`: Algorithm 14's forest.
    pub star: bool,
}

impl PrmConfig {
    /// Algorithm 14 as in the thesis: `N = 6` neighbours, no edge-length limit, no direct
    /// goal test.
    pub fn thesis() -> PrmConfig {
        PrmConfig { neighbours: 6, connection_radius: None, direct_goal_step: false, star: false }
    }

    /// PRM* (Karaman & Frazzoli 2011, k-nearest variant): [`star`](Self::star) set, no
    /// edge-length limit, no direct goal test.
    pub fn star() -> PrmConfig {
        PrmConfig { star: true, ..PrmConfig::thesis() }
    }

    /// How many nearest existing vertices a sample tries when it becomes the `vertices`-th
    /// vertex (counting itself and the start): [`neighbours`](Self::neighbours), or with
    /// [`star`](Self::star) `k(n) = ⌈e·(1 + 1/3)·ln n⌉` (0 for `n ≤ 1`).
    pub fn neighbours_for(&self, vertices: usize) -> usize {
        if !self.star {
            return self.neighbours;
        }
        if vertices <= 1 {
            return 0;
        }
        const DIMENSION: Real = 3.0;
        let k = std::f64::consts::E * (1.0 + 1.0 / DIMENSION) * (vertices as Real).ln();
        k.ceil() as usize
    }
}

/// The PRM (thesis Algorithm 14): a forest of random vertices, components joined by free
/// straight edges.
///
/// The start is vertex 0. Each iteration draws a uniform sample `x`, finds its `N` nearest
/// existing vertices (before adding `x`), adds `x`, and walks those neighbours by increasing
/// distance: it adds the edge if the neighbour is not already in `x`'s component (union–find,
/// the thesis's "associative array node → component", spec §4) and the capsule of the robot
/// radius between them is free. Samples are not checked for validity (spec §4): a colliding
/// sample stays isolated, because every capsule from it includes its sphere. The roadmap is a
/// forest by construction. [`PlanningSpace::max_step`] is not used.
///
/// With [`PrmConfig::star`] (PRM*, [`PrmConfig::star()`]) `N` grows with the vertex count
/// ([`PrmConfig::neighbours_for`]) and the component test is dropped, so every free edge to
/// the `k(n)` nearest vertices is added and the roadmap has cycles; [`Planner::path_to`]
/// returns the shortest path by length in the roadmap.
///
/// A goal is reached once some vertex within its tolerance is in the start's component.
///
/// Needs only [`UnspecificStepIntersector<CapsuleStep>`] (thesis Table 5.2).
///
/// # Complexity
/// Per iteration a [`KdNeighbors`] query for the neighbours plus at most `N` (PRM*: `k(n)`,
/// `O(log n)`) capsule checks (plus one per goal without a vertex, with the direct goal step).
pub struct Prm<'m, M: UnspecificStepIntersector<CapsuleStep> + ?Sized> {
    map: &'m M,
    space: PlanningSpace,
    config: PrmConfig,
    seed: u64,
    solution: Solution,
}

impl<'m, M: UnspecificStepIntersector<CapsuleStep> + ?Sized> Prm<'m, M> {
    /// A planner on `map` in `space`; `seed` fixes the random stream.
    pub fn new(map: &'m M, space: PlanningSpace, config: PrmConfig, seed: u64) -> Self {
        Prm { map, space, config, seed, solution: Solution::default() }
    }

    /// The configuration.
    pub fn config(&self) -> &PrmConfig {
        &self.config
    }

    /// The space.
    pub fn space(&self) -> &PlanningSpace {
        &self.space
    }
}

impl<M: UnspecificStepIntersector<CapsuleStep> + ?Sized> Planner for Prm<'_, M> {
    fn name(&self) -> &'static str {
        "prm"
    }

    fn solve(&mut self, problem: &Problem, stop: &mut dyn Termination) -> PlannerStatus {
        let space = &self.space;
        let sample = |rng: &mut ChaCha8Rng| Some(planner::uniform(rng, space));
        let solution = &mut self.solution;
        solve_prm(self.map, space, &self.config, self.seed, problem, stop, solution, sample)
    }

    fn roadmap(&self) -> &Roadmap {
        &self.solution.graph
    }

    fn path_to(&self, goal: usize) -> Option<Vec<Point3>> {
        self.solution.path_to(goal)
    }

    fn counters(&self) -> PlannerCounters {
        self.solution.counters
    }

    fn clear(&mut self) {
        self.solution = Solution::default();
    }
}

/// The PRM's working state besides the roadmap.
struct Forest {
    nn: KdNeighbors,
    components: UnionFind<usize>,
    /// Per goal, the vertices within its tolerance.
    near_goal: Vec<Vec<NodeIndex>>,
    /// Per goal, whether its centre is a vertex.
    goal_vertex: Vec<bool>,
}

impl Forest {
    fn add(&mut self, solution: &mut Solution, p: Point3) -> NodeIndex {
        let v = solution.graph.add_node(p);
        self.nn.add(p);
        self.components.new_set();
        for (g, goal) in solution.goals.iter().enumerate() {
            if (goal.center - p).norm() <= goal.tolerance {
                self.near_goal[g].push(v);
            }
        }
        v
    }

    fn connect(&mut self, solution: &mut Solution, a: NodeIndex, b: NodeIndex) {
        let length = (solution.graph[a] - solution.graph[b]).norm();
        solution.graph.add_edge(a, b, length);
        self.components.union(a.index(), b.index());
    }
}

/// The PRM loop shared by [`Prm`] and the MA PRM: `sample(rng)` gives the next vertex, or
/// `None` to drop the iteration's sample (it still counts as an iteration).
#[allow(clippy::too_many_arguments)]
pub(crate) fn solve_prm<M: UnspecificStepIntersector<CapsuleStep> + ?Sized>(
    map: &M,
    space: &PlanningSpace,
    config: &PrmConfig,
    seed: u64,
    problem: &Problem,
    stop: &mut dyn Termination,
    solution: &mut Solution,
    mut sample: impl FnMut(&mut ChaCha8Rng) -> Option<Point3>,
) -> PlannerStatus {
    let started = Instant::now();
    solution.reset(&problem.goals);
    let mut checker = Checker::new(map, space.robot_radius());
    if let Some(invalid) = planner::validate(problem, space, &mut checker) {
        solution.finish(0, &checker);
        return invalid;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let goals = problem.goals.len();
    let mut forest = Forest {
        nn: KdNeighbors::new(),
        components: UnionFind::new(0),
        near_goal: vec![Vec::new(); goals],
        goal_vertex: vec![false; goals],
    };
    let max_dist = match config.connection_radius {
        None => Real::INFINITY,
        Some(r) if r.is_finite() && r >= 0.0 => r,
        Some(_) => Real::NEG_INFINITY,
    };
    let start = forest.add(solution, problem.start);
    direct_goal_steps(solution, &mut forest, &mut checker, config, start);
    update_reached(solution, &forest);
    let mut iterations = 0u64;
    while !stop.should_stop(&solution.progress(iterations, started)) {
        iterations += 1;
        let Some(x) = sample(&mut rng) else {
            continue;
        };
        let k = config.neighbours_for(solution.graph.node_count() + 1);
        let near = forest.nn.k_nearest(&x, k, max_dist);
        let v = forest.add(solution, x);
        for n in near {
            let w = NodeIndex::new(n.index);
            if (config.star || !forest.components.equiv(v.index(), w.index()))
                && checker.free(&solution.graph[w], &x)
            {
                forest.connect(solution, w, v);
            }
        }
        direct_goal_steps(solution, &mut forest, &mut checker, config, v);
        update_reached(solution, &forest);
    }
    solution.finish(iterations, &checker);
    let start_root = forest.components.find(start.index());
    solution.status(|v| forest.components.find(v.index()) == start_root)
}

/// With the direct goal step: connects `v` to the centre of each unreached goal that has no
/// vertex yet, if the capsule is free.
fn direct_goal_steps<M: UnspecificStepIntersector<CapsuleStep> + ?Sized>(
    solution: &mut Solution,
    forest: &mut Forest,
    checker: &mut Checker<'_, M>,
    config: &PrmConfig,
    v: NodeIndex,
) {
    if !config.direct_goal_step {
        return;
    }
    for g in 0..solution.goals.len() {
        if solution.reached[g].is_some() || forest.goal_vertex[g] {
            continue;
        }
        let center = solution.goals[g].center;
        if checker.free(&solution.graph[v], &center) {
            let w = forest.add(solution, center);
            forest.connect(solution, v, w);
            forest.goal_vertex[g] = true;
        }
    }
}

/// Marks goals whose nearby vertices joined the start's component.
fn update_reached(solution: &mut Solution, forest: &Forest) {
    for g in 0..solution.goals.len() {
        if solution.reached[g].is_none() {
            solution.reached[g] =
                forest.near_goal[g].iter().copied().find(|w| forest.components.equiv(0, w.index()));
        }
    }
}
