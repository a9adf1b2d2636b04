//! RRT-Connect (Kuffner & LaValle 2000): two trees, one from the start and one from the goal,
//! each extension of one followed by a greedy connection attempt of the other.

use std::time::Instant;

use patch_core::{Point3, Real, UnspecificStepIntersector};
use petgraph::graph::NodeIndex;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::nn::{KdNeighbors, NearestNeighbors};
use crate::planner::{self, Checker, Planner, PlannerStatus, Solution};
use crate::space::{PlanningSpace, Problem};
use crate::termination::Termination;

/// RRT-Connect (Kuffner & LaValle 2000), extended to several goals; not part of the thesis, a
/// baseline from the literature.
///
/// One tree grows from the start and one from each goal centre. Each iteration draws a uniform
/// sample `x` in the bounds and EXTENDs one tree one step toward it (the RRT's step rule:
/// `min(max_step, |x − x_near|)` along `x − x_near`, added if the capsule is free); if a
/// vertex was added, the partner tree CONNECTs to it: it takes such steps toward that vertex
/// until the last (at most `max_step` long) edge joins the two trees or a step collides.
///
/// With one goal this is Kuffner and LaValle's algorithm: the start tree and the goal tree
/// swap roles every iteration. With `k` goals the start tree is paired with the goal trees in
/// turn (round robin over the goals not yet reached): one iteration the start tree extends
/// and the current goal tree connects, the next the goal tree extends and the start tree
/// connects, then the next goal's turn. A goal tree that joins the start tree becomes part of
/// it (so later goals can connect to everything reached so far) and its goal is reached (the
/// path ends at the goal centre); a goal is also reached when a vertex of the start tree lies
/// within its tolerance. Once every goal is reached, iterations grow the start tree alone,
/// like the RRT; with no goal only the start tree grows.
///
/// The roadmap holds every tree (a forest until they join); vertices of a goal tree count as
/// explored (for [`PlannerStatus::Approximate`]) only once joined.
///
/// Needs only [`UnspecificStepIntersector`].
pub struct RrtConnect<'m, M: UnspecificStepIntersector + ?Sized> {
    map: &'m M,
    space: PlanningSpace,
    seed: u64,
    solution: Solution,
}

impl<'m, M: UnspecificStepIntersector + ?Sized> RrtConnect<'m, M> {
    /// A planner on `map` in `space`; `seed` fixes the random stream.
    pub fn new(map: &'m M, space: PlanningSpace, seed: u64) -> Self {
        RrtConnect { map, space, seed, solution: Solution::default() }
    }

    /// The space.
    pub fn space(&self) -> &PlanningSpace {
        &self.space
    }
}

impl<M: UnspecificStepIntersector + ?Sized> Planner for RrtConnect<'_, M> {
    fn name(&self) -> &'static str {
        crate::PlannerKind::RrtConnect.name()
    }

    fn solve(&mut self, problem: &Problem, stop: &mut dyn Termination) -> PlannerStatus {
        solve_connect(self.map, &self.space, self.seed, problem, stop, &mut self.solution)
    }

    planner::solution_accessors!();
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

/// The working state: the solution, the trees (0: the start's, then one per goal with a goal
/// tree), and which tree each vertex belongs to.
struct State<'s> {
    solution: &'s mut Solution,
    trees: Vec<Tree>,
    tree_of: Vec<usize>,
}

impl State<'_> {
    fn add(&mut self, tree: usize, p: Point3) -> NodeIndex {
        let v = self.solution.graph.add_node(p);
        self.trees[tree].push(v, p);
        self.tree_of.push(tree);
        v
    }

    fn in_start(&self, v: NodeIndex) -> bool {
        self.tree_of[v.index()] == 0
    }

    /// Marks every goal reached by `v` if `v` is in the start tree and within tolerance.
    fn test_goal(&mut self, v: NodeIndex) {
        if !self.in_start(v) {
            return;
        }
        let p = self.solution.graph[v];
        for (goal, reached) in self.solution.goals.iter().zip(&mut self.solution.reached) {
            if reached.is_none() && (p - goal.center).norm() <= goal.tolerance {
                *reached = Some(v);
            }
        }
    }
}

/// The outcome of one step toward a target.
enum Step {
    Trapped,
    Advanced(NodeIndex),
}

/// One RRT step of tree `tree` toward `x` (nothing for a zero-length step).
fn extend<M: UnspecificStepIntersector + ?Sized>(
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
fn connect<M: UnspecificStepIntersector + ?Sized>(
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

fn solve_connect<M: UnspecificStepIntersector + ?Sized>(
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
    if let Some(invalid) = planner::validate(problem, space, &mut checker) {
        solution.finish(0, &checker);
        return invalid;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut state = State { solution, trees: vec![Tree::default()], tree_of: vec![] };
    let start = state.add(0, problem.start);
    state.test_goal(start);
    // One tree per goal not reached by the start itself: (goal, its tree, the goal's root).
    let mut open: Vec<(usize, usize, NodeIndex)> = Vec::new();
    for (g, goal) in problem.goals.iter().enumerate() {
        if state.solution.reached[g].is_none() {
            state.trees.push(Tree::default());
            let tree = state.trees.len() - 1;
            open.push((g, tree, state.add(tree, goal.center)));
        }
    }
    // `turn` picks the goal tree paired with the start tree; `start_extends` which of the
    // pair extends (the other connects).
    let mut turn = 0usize;
    let mut start_extends = true;
    let mut iterations = 0u64;
    while !stop.should_stop(&state.solution.progress(iterations, started)) {
        iterations += 1;
        let x = planner::uniform(&mut rng, space);
        // Goals reached by a start-tree vertex within tolerance leave the rotation.
        open.retain(|&(g, _, _)| state.solution.reached[g].is_none());
        if open.is_empty() {
            extend(&mut state, &mut checker, space, 0, &x);
            continue;
        }
        turn %= open.len();
        let (goal, tree, root) = open[turn];
        let (extending, connecting) = if start_extends { (0, tree) } else { (tree, 0) };
        if let Step::Advanced(v) = extend(&mut state, &mut checker, space, extending, &x)
            && connect(&mut state, &mut checker, space, connecting, v)
        {
            join(&mut state, tree);
            if state.solution.reached[goal].is_none() {
                state.solution.reached[goal] = Some(root);
            }
            open.remove(turn);
            start_extends = true;
            continue;
        }
        start_extends = !start_extends;
        if start_extends {
            turn += 1;
        }
    }
    let State { solution, tree_of, .. } = state;
    solution.finish(iterations, &checker);
    solution.status(|v| tree_of[v.index()] == 0)
}

/// Moves goal tree `tree` into the start tree once they are joined.
fn join(state: &mut State<'_>, tree: usize) {
    let goal_tree = std::mem::take(&mut state.trees[tree]);
    for &v in &goal_tree.nodes {
        let p = state.solution.graph[v];
        state.trees[0].push(v, p);
        state.tree_of[v.index()] = 0;
    }
    // Vertices the start tree just took over may lie within other goals' tolerance.
    for v in goal_tree.nodes {
        state.test_goal(v);
    }
}
