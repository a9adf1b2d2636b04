//! RRT* (Karaman & Frazzoli 2011, "Sampling-based algorithms for optimal motion planning",
//! Algorithm 6): the RRT with choose-parent and rewiring, asymptotically optimal in path
//! length. Not part of the thesis.

use std::time::Instant;

use patch_core::{Point3, Real, UnspecificStepIntersector};
use petgraph::graph::NodeIndex;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::nn::{KdNeighbors, NearestNeighbors};
use crate::planner::{
    self, Checker, GoalStep, Planner, PlannerCounters, PlannerStatus, Roadmap, Solution,
};
use crate::rrt::{self, RrtConfig};
use crate::space::{PlanningSpace, Problem};
use crate::termination::Termination;

/// The choices of an [`RrtStar`]. No `Default`: pick [`RrtStarConfig::standard`] and change
/// fields.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct RrtStarConfig {
    /// The RRT's sampling choices: goal bias, sampler ([`Sampler`](crate::Sampler)) and the
    /// direct goal step of the Lesum variants (a goal centre reached by it becomes an ordinary
    /// tree vertex, later rewired like any other).
    pub rrt: RrtConfig,
    /// The rewiring neighbourhood of the k-nearest RRT* (Karaman & Frazzoli 2011, §3.3 and
    /// Algorithm 6 with `Near` = k-nearest): the `n`-th vertex looks at its
    /// `k(n) = ⌈rewire_factor · ln n⌉` nearest existing vertices
    /// ([`RrtStarConfig::neighbours_for`]). Asymptotic optimality needs
    /// `rewire_factor > e·(1 + 1/d)` (`d = 3`: ≈ 3.62); [`RrtStarConfig::standard`] takes
    /// `2e ≈ 5.44`, which satisfies the bound in every dimension.
    pub rewire_factor: Real,
    /// Only neighbours within this distance are considered; `None`: no limit (the paper's
    /// k-nearest variant). The nearest vertex, the one the new vertex is steered from, is always
    /// a parent candidate. A non-finite or negative radius leaves only that vertex (an RRT).
    pub rewire_radius: Option<Real>,
}

impl RrtStarConfig {
    /// The k-nearest RRT* with `k(n) = ⌈2e · ln n⌉` (Karaman & Frazzoli 2011's `k_RRG = 2e`),
    /// no radius limit, and the sampling of [`RrtConfig::thesis`] (uniform, no goal bias, no
    /// direct goal step).
    pub fn standard() -> RrtStarConfig {
        RrtStarConfig {
            rrt: RrtConfig::thesis(),
            rewire_factor: 2.0 * std::f64::consts::E,
            rewire_radius: None,
        }
    }

    /// How many nearest existing vertices a new vertex considers for its parent and for
    /// rewiring when it becomes the `vertices`-th vertex (counting itself and the start):
    /// `⌈rewire_factor · ln n⌉`, at least 1; 1 for `n ≤ 1` or a factor that is not finite and
    /// positive.
    pub fn neighbours_for(&self, vertices: usize) -> usize {
        if vertices <= 1 || !(self.rewire_factor.is_finite() && self.rewire_factor > 0.0) {
            return 1;
        }
        let k = (self.rewire_factor * (vertices as Real).ln()).ceil();
        (k as usize).max(1)
    }
}

/// RRT* (Karaman & Frazzoli 2011, Algorithm 6, k-nearest variant): a tree from the start whose
/// vertices keep the shortest path found so far; not part of the thesis.
///
/// Each iteration draws a sample `x` as the [`Rrt`](crate::Rrt) does (goal bias, sampler) and
/// steers from the nearest vertex `x_nearest` to
/// `x_new = x_nearest + min(max_step, |x − x_nearest|)·unit`. If that capsule is free,
/// `x_new` is added:
/// 1. **Choose parent**: among `x_nearest` and the `k(n)` nearest vertices
///    ([`RrtStarConfig::neighbours_for`], optionally within
///    [`rewire_radius`](RrtStarConfig::rewire_radius)), the one minimising
///    `cost(v) + |v − x_new|` whose capsule to `x_new` is free. Candidates are tried by
///    increasing cost and only while they beat `x_nearest`, so a capsule is checked only when
///    it could lower the cost.
/// 2. **Rewire**: every other candidate `v` with `cost(x_new) + |x_new − v| < cost(v)` and a
///    free capsule (the result of step 1 is reused, the capsule is symmetric) gets `x_new` as
///    its parent: the old parent edge is removed, so the roadmap stays a tree, and the costs of
///    `v`'s descendants are recomputed from their parents (`cost(child) = cost(parent) + edge
///    length`, exactly the length of the tree path).
///
/// A goal is reached when some vertex lies within its tolerance (or, with the direct goal
/// step, the capsule from a new vertex to an unreached goal centre is free: the centre joins
/// the tree). [`Planner::path_to`] returns the tree path to the cheapest vertex within the
/// goal's tolerance; with [`GoalReached`](crate::GoalReached) the run stops at the first
/// solution like the other planners, with [`MaxIterations`](crate::MaxIterations) it keeps
/// improving it (costs never increase).
///
/// Needs only [`UnspecificStepIntersector`].
///
/// # Complexity
/// Per iteration a nearest and a `k(n)`-nearest [`KdNeighbors`] query (`k(n) = O(log n)`),
/// one capsule check for the steer step plus at most `2·k(n)` more (usually far fewer), and
/// the cost update of the rewired subtrees.
pub struct RrtStar<'m, M: UnspecificStepIntersector + ?Sized> {
    map: &'m M,
    space: PlanningSpace,
    config: RrtStarConfig,
    seed: u64,
    solution: Solution,
    tree: Tree,
}

impl<'m, M: UnspecificStepIntersector + ?Sized> RrtStar<'m, M> {
    /// A planner on `map` in `space`; `seed` fixes the random stream.
    pub fn new(map: &'m M, space: PlanningSpace, config: RrtStarConfig, seed: u64) -> Self {
        RrtStar { map, space, config, seed, solution: Solution::default(), tree: Tree::default() }
    }

    /// The configuration.
    pub fn config(&self) -> &RrtStarConfig {
        &self.config
    }

    /// The space.
    pub fn space(&self) -> &PlanningSpace {
        &self.space
    }

    /// The cost of a roadmap vertex: the length of its tree path from the start (`None` for a
    /// vertex not in the roadmap).
    pub fn cost(&self, vertex: NodeIndex) -> Option<Real> {
        self.tree.cost.get(vertex.index()).copied()
    }

    /// The parent of a roadmap vertex in the tree (`None` for the start and for a vertex not in
    /// the roadmap).
    pub fn parent(&self, vertex: NodeIndex) -> Option<NodeIndex> {
        self.tree.parent.get(vertex.index()).copied().flatten()
    }
}

impl<M: UnspecificStepIntersector + ?Sized> Planner for RrtStar<'_, M> {
    fn name(&self) -> &'static str {
        crate::PlannerKind::RrtStar.name()
    }

    fn solve(&mut self, problem: &Problem, stop: &mut dyn Termination) -> PlannerStatus {
        let (map, space, config) = (self.map, &self.space, &self.config);
        solve_rrt_star(
            map,
            space,
            config,
            self.seed,
            problem,
            stop,
            &mut self.solution,
            &mut self.tree,
        )
    }

    fn roadmap(&self) -> &Roadmap {
        &self.solution.graph
    }

    fn path_to(&self, goal: usize) -> Option<Vec<Point3>> {
        let mut v = (*self.solution.reached.get(goal)?)?;
        let mut path = vec![self.solution.graph[v]];
        while let Some(p) = self.tree.parent[v.index()] {
            path.push(self.solution.graph[p]);
            v = p;
        }
        path.reverse();
        Some(path)
    }

    fn counters(&self) -> PlannerCounters {
        self.solution.counters
    }

    fn clear(&mut self) {
        self.solution = Solution::default();
        self.tree = Tree::default();
    }
}

/// The tree beside the roadmap: parents, children and costs by vertex index, and per goal the
/// vertices within its tolerance.
#[derive(Default)]
struct Tree {
    nn: KdNeighbors,
    parent: Vec<Option<NodeIndex>>,
    children: Vec<Vec<NodeIndex>>,
    cost: Vec<Real>,
    near_goal: Vec<Vec<NodeIndex>>,
    /// Per goal, whether its centre is a vertex (direct goal step).
    goal_vertex: Vec<bool>,
}

impl Tree {
    fn reset(&mut self, goals: usize) {
        *self = Tree {
            near_goal: vec![Vec::new(); goals],
            goal_vertex: vec![false; goals],
            ..Tree::default()
        };
    }

    /// Adds `p` with an edge from `parent` (none for the start).
    fn add(&mut self, solution: &mut Solution, p: Point3, parent: Option<NodeIndex>) -> NodeIndex {
        let v = solution.graph.add_node(p);
        self.nn.add(p);
        let cost = parent.map_or(0.0, |u| {
            let length = (p - solution.graph[u]).norm();
            solution.graph.add_edge(u, v, length);
            self.children[u.index()].push(v);
            self.cost[u.index()] + length
        });
        self.parent.push(parent);
        self.children.push(Vec::new());
        self.cost.push(cost);
        for (g, goal) in solution.goals.iter().enumerate() {
            if (goal.center - p).norm() <= goal.tolerance {
                self.near_goal[g].push(v);
            }
        }
        v
    }

    /// Makes `parent` the parent of `v` (removing the old parent edge) and recomputes the costs
    /// of `v`'s subtree. `v` must not be the start nor an ancestor of `parent`.
    fn reparent(&mut self, solution: &mut Solution, v: NodeIndex, parent: NodeIndex) {
        let graph = &mut solution.graph;
        if let Some(old) = self.parent[v.index()] {
            if let Some(e) = graph.find_edge(old, v) {
                graph.remove_edge(e);
            }
            self.children[old.index()].retain(|&c| c != v);
        }
        let length = (graph[v] - graph[parent]).norm();
        graph.add_edge(parent, v, length);
        self.children[parent.index()].push(v);
        self.parent[v.index()] = Some(parent);
        self.cost[v.index()] = self.cost[parent.index()] + length;
        // Parents before children: each popped vertex's parent is already updated.
        let mut stack = self.children[v.index()].clone();
        while let Some(c) = stack.pop() {
            let p = self.parent[c.index()].expect("a child has a parent");
            self.cost[c.index()] = self.cost[p.index()] + (graph[c] - graph[p]).norm();
            stack.extend_from_slice(&self.children[c.index()]);
        }
    }

    /// Per goal the cheapest vertex within its tolerance (ties: the lower index).
    fn update_reached(&self, solution: &mut Solution) {
        for (g, near) in self.near_goal.iter().enumerate() {
            solution.reached[g] = near.iter().copied().min_by(|a, b| {
                self.cost[a.index()].total_cmp(&self.cost[b.index()]).then(a.cmp(b))
            });
        }
    }
}

/// A parent or rewiring candidate of a new vertex.
struct Candidate {
    vertex: NodeIndex,
    distance: Real,
    /// Whether its capsule to the new vertex is free, once checked.
    free: Option<bool>,
}

#[allow(clippy::too_many_arguments)]
fn solve_rrt_star<M: UnspecificStepIntersector + ?Sized>(
    map: &M,
    space: &PlanningSpace,
    config: &RrtStarConfig,
    seed: u64,
    problem: &Problem,
    stop: &mut dyn Termination,
    solution: &mut Solution,
    tree: &mut Tree,
) -> PlannerStatus {
    let started = Instant::now();
    solution.reset(&problem.goals);
    tree.reset(problem.goals.len());
    let mut checker = Checker::new(map, space.robot_radius());
    if let Some(invalid) = planner::validate(problem, space, &mut checker) {
        solution.finish(0, &checker);
        return invalid;
    }
    let max_dist = match config.rewire_radius {
        None => Real::INFINITY,
        Some(r) if r.is_finite() && r >= 0.0 => r,
        Some(_) => Real::NEG_INFINITY,
    };
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let start = tree.add(solution, problem.start, None);
    direct_goal_steps(solution, tree, &mut checker, config, start);
    tree.update_reached(solution);
    let mut iterations = 0u64;
    while !stop.should_stop(&solution.progress(iterations, started)) {
        iterations += 1;
        let (x, _) = rrt::sample(&mut rng, space, &config.rrt, solution);
        let Some(near) = tree.nn.nearest(&x) else { break };
        if near.distance <= 0.0 {
            continue;
        }
        let nearest = NodeIndex::new(near.index);
        let x_nearest = solution.graph[nearest];
        let length = space.max_step().min(near.distance);
        let x_new = x_nearest + (x - x_nearest) * (length / near.distance);
        if !(space.bounds().contains(&x_new) && checker.free(&x_nearest, &x_new)) {
            continue;
        }
        // Candidates: the k(n) nearest (before adding x_new) and always x_nearest.
        let k = config.neighbours_for(solution.graph.node_count() + 1);
        let mut candidates: Vec<Candidate> = tree
            .nn
            .k_nearest(&x_new, k, max_dist)
            .into_iter()
            .map(|n| Candidate {
                vertex: NodeIndex::new(n.index),
                distance: n.distance,
                free: None,
            })
            .collect();
        match candidates.iter_mut().find(|c| c.vertex == nearest) {
            Some(c) => c.free = Some(true),
            None => candidates.push(Candidate {
                vertex: nearest,
                distance: (x_new - x_nearest).norm(),
                free: Some(true),
            }),
        }
        let via = |c: &Candidate, tree: &Tree| tree.cost[c.vertex.index()] + c.distance;
        // Choose parent: by increasing cost through the candidate; the first free one wins.
        let mut order: Vec<usize> = (0..candidates.len()).collect();
        order.sort_by(|&a, &b| {
            let (ca, cb) = (&candidates[a], &candidates[b]);
            via(ca, tree).total_cmp(&via(cb, tree)).then(ca.vertex.cmp(&cb.vertex))
        });
        let mut parent = nearest;
        let nearest_cost = tree.cost[nearest.index()] + (x_new - x_nearest).norm();
        for i in order {
            let c = &mut candidates[i];
            if c.vertex == nearest || via(c, tree) >= nearest_cost {
                break;
            }
            let free = checker.free(&solution.graph[c.vertex], &x_new);
            c.free = Some(free);
            if free {
                parent = c.vertex;
                break;
            }
        }
        let v = tree.add(solution, x_new, Some(parent));
        // Rewire the other candidates through v where that is shorter.
        for c in &mut candidates {
            if c.vertex == parent
                || tree.cost[v.index()] + c.distance >= tree.cost[c.vertex.index()]
            {
                continue;
            }
            let free =
                *c.free.get_or_insert_with(|| checker.free(&solution.graph[c.vertex], &x_new));
            if free {
                tree.reparent(solution, c.vertex, v);
            }
        }
        direct_goal_steps(solution, tree, &mut checker, config, v);
        tree.update_reached(solution);
    }
    solution.finish(iterations, &checker);
    solution.status(|_| true)
}

/// With the direct goal step: connects `v` to the centre of each unreached goal that has no
/// vertex yet, if the capsule is free.
fn direct_goal_steps<M: UnspecificStepIntersector + ?Sized>(
    solution: &mut Solution,
    tree: &mut Tree,
    checker: &mut Checker<'_, M>,
    config: &RrtStarConfig,
    v: NodeIndex,
) {
    if config.rrt.goal_step == GoalStep::Grown {
        return;
    }
    for g in 0..solution.goals.len() {
        if !tree.near_goal[g].is_empty() || tree.goal_vertex[g] {
            continue;
        }
        let center = solution.goals[g].center;
        if checker.free(&solution.graph[v], &center) {
            tree.add(solution, center, Some(v));
            tree.goal_vertex[g] = true;
        }
    }
}
