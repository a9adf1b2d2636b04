//! RRT-Connect (Kuffner & LaValle 2000): two trees, one from the start and one from the goal,
//! each extension of one followed by a greedy connection attempt of the other.

use std::time::Instant;

use patch_core::{CapsuleStep, Point3, Real, UnspecificStepIntersector};
use petgraph::graph::NodeIndex;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::nn::{KdNeighbors, NearestNeighbors};
use crate::planner::{self, Checker, Planner, PlannerCounters, PlannerStatus, Roadmap, Solution};
use crate::space::{PlanningSpace, Problem};
use crate::termination::Termination;

/// RRT-Connect (Kuffner & LaValle 2000) for problems with at most one goal; not part of the
/// thesis, a baseline from the literature.
///
/// One tree grows from the start, one from the goal centre. Each iteration draws a uniform
/// sample `x` in the bounds and EXTENDs one tree one step toward it (the RRT's step rule:
/// `min(max_step, |x − x_near|)` along `x − x_near`, added if the capsule is free); if a
/// vertex was added, the other tree CONNECTs to it: it takes such steps toward that vertex
/// until the last (at most `max_step` long) edge joins the two trees or a step collides. Then
/// the trees swap roles. The goal is reached when the trees join (the path ends at the goal
/// centre) or when a vertex of the start tree lies within the goal's tolerance. After that,
/// iterations grow the start tree alone, like the RRT.
///
/// A problem with more than one goal gives [`PlannerStatus::InvalidGoal`]; with no goal only
/// the start tree grows. The roadmap holds both trees (a forest until they join); vertices of
/// the goal tree count as explored (for [`PlannerStatus::Approximate`]) only once joined.
///
/// Needs only [`UnspecificStepIntersector<CapsuleStep>`].
pub struct RrtConnect<'m, M: UnspecificStepIntersector<CapsuleStep> + ?Sized> {
    map: &'m M,
    space: PlanningSpace,
    seed: u64,
    solution: Solution,
}

impl<'m, M: UnspecificStepIntersector<CapsuleStep> + ?Sized> RrtConnect<'m, M> {
    /// A planner on `map` in `space`; `seed` fixes the random stream.
    pub fn new(map: &'m M, space: PlanningSpace, seed: u64) -> Self {
        RrtConnect { map, space, seed, solution: Solution::default() }
    }

    /// The space.
    pub fn space(&self) -> &PlanningSpace {
        &self.space
    }
}

impl<M: UnspecificStepIntersector<CapsuleStep> + ?Sized> Planner for RrtConnect<'_, M> {
    fn name(&self) -> &'static str {
        "rrt-connect"
    }

    fn solve(&mut self, problem: &Problem, stop: &mut dyn Termination) -> PlannerStatus {
        solve_connect(self.map, &self.space, self.seed, problem, stop, &mut self.solution)
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

/// One tree: its vertices (by nearest-neighbour index) and their nearest-neighbour structure.
#[derive(Default)]
struct Tree {
    nn: KdNeighbors,
    nodes: Vec<NodeIndex>,
}

impl Tree {
    fn push(&mut self, v: NodeIndex, p: Point3) {
        self.nn.add(p);
        self.nodes.push(v);
    }

    fn nearest(&self, x: &Point3) -> Option<(NodeIndex, Real)> {
        self.nn.nearest(x).map(|n| (self.nodes[n.index], n.distance))
    }
}

/// The working state: the solution, both trees, which nodes are connected to the start.
struct State<'s> {
    solution: &'s mut Solution,
    trees: [Tree; 2],
    in_start: Vec<bool>,
}

impl State<'_> {
    fn add(&mut self, tree: usize, p: Point3) -> NodeIndex {
        let v = self.solution.graph.add_node(p);
        self.trees[tree].push(v, p);
        self.in_start.push(tree == 0);
        v
    }

    /// Marks the goal reached by `v` if `v` is in the start tree and within tolerance.
    fn test_goal(&mut self, v: NodeIndex) {
        if let (Some(goal), Some(None)) =
            (self.solution.goals.first(), self.solution.reached.first())
            && self.in_start[v.index()]
            && (self.solution.graph[v] - goal.center).norm() <= goal.tolerance
        {
            self.solution.reached[0] = Some(v);
        }
    }
}

/// The outcome of one step toward a target.
enum Step {
    Trapped,
    Advanced(NodeIndex),
}

/// One RRT step of tree `tree` toward `x` (nothing for a zero-length step).
fn extend<M: UnspecificStepIntersector<CapsuleStep> + ?Sized>(
    state: &mut State<'_>,
    checker: &mut Checker<'_, M>,
    space: &PlanningSpace,
    tree: usize,
    x: &Point3,
) -> Step {
    let Some((near, distance)) = state.trees[tree].nearest(x) else { return Step::Trapped };
    if distance <= 0.0 {
        return Step::Trapped;
    }
    let p_near = state.solution.graph[near];
    let length = space.max_step().min(distance);
    let x_new = p_near + (x - p_near) * (length / distance);
    if !space.bounds().contains(&x_new) || !checker.free(&p_near, &x_new) {
        return Step::Trapped;
    }
    let v = state.add(tree, x_new);
    state.solution.graph.add_edge(near, v, (x_new - p_near).norm());
    state.test_goal(v);
    Step::Advanced(v)
}

/// Tree `tree` steps toward vertex `target` of the other tree until it joins it (returns
/// `true`) or a step collides.
fn connect<M: UnspecificStepIntersector<CapsuleStep> + ?Sized>(
    state: &mut State<'_>,
    checker: &mut Checker<'_, M>,
    space: &PlanningSpace,
    tree: usize,
    target: NodeIndex,
) -> bool {
    let x = state.solution.graph[target];
    loop {
        let Some((near, distance)) = state.trees[tree].nearest(&x) else { return false };
        if distance <= space.max_step() {
            let p_near = state.solution.graph[near];
            if !checker.free(&p_near, &x) {
                return false;
            }
            state.solution.graph.add_edge(near, target, distance);
            return true;
        }
        if let Step::Trapped = extend(state, checker, space, tree, &x) {
            return false;
        }
    }
}

fn solve_connect<M: UnspecificStepIntersector<CapsuleStep> + ?Sized>(
    map: &M,
    space: &PlanningSpace,
    seed: u64,
    problem: &Problem,
    stop: &mut dyn Termination,
    solution: &mut Solution,
) -> PlannerStatus {
    let started = Instant::now();
    solution.reset(&problem.goals);
    let mut checker = Checker::new(map, space.robot_radius());
    if problem.goals.len() > 1 {
        solution.finish(0, &checker);
        return PlannerStatus::InvalidGoal;
    }
    if let Some(invalid) = planner::validate(problem, space, &mut checker) {
        solution.finish(0, &checker);
        return invalid;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut state = State { solution, trees: [Tree::default(), Tree::default()], in_start: vec![] };
    let start = state.add(0, problem.start);
    state.test_goal(start);
    let goal_root = match problem.goals.first() {
        Some(goal) if state.solution.reached[0].is_none() => Some(state.add(1, goal.center)),
        _ => None,
    };
    // The tree that extends next (0: start, 1: goal); the other one connects.
    let mut active = 0;
    let mut iterations = 0u64;
    while !stop.should_stop(&state.solution.progress(iterations, started)) {
        iterations += 1;
        let x = planner::uniform(&mut rng, space);
        if state.solution.reached.iter().all(Option::is_some) {
            extend(&mut state, &mut checker, space, 0, &x);
            continue;
        }
        if let Step::Advanced(v) = extend(&mut state, &mut checker, space, active, &x)
            && connect(&mut state, &mut checker, space, 1 - active, v)
        {
            join(&mut state);
            state.solution.reached[0] = goal_root;
        }
        active = 1 - active;
    }
    let State { solution, in_start, .. } = state;
    solution.finish(iterations, &checker);
    solution.status(|v| in_start[v.index()])
}

/// Moves the goal tree into the start tree once they are joined.
fn join(state: &mut State<'_>) {
    let goal_tree = std::mem::take(&mut state.trees[1]);
    for v in goal_tree.nodes {
        let p = state.solution.graph[v];
        state.trees[0].push(v, p);
        state.in_start[v.index()] = true;
    }
}
