//! The rapidly-exploring random tree (LaValle 1998; thesis Algorithm 13, §5.5 and §6.1).

use std::time::Instant;

use patch_core::{Point3, Real, UnspecificStepIntersector};
use petgraph::graph::NodeIndex;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::nn::{KdNeighbors, NearestNeighbors};
use crate::planner::{self, Checker, GoalStep, Planner, PlannerStatus, Solution};
use crate::space::{PlanningSpace, Problem};
use crate::termination::Termination;

/// Where RRT samples come from (besides the goal bias of [`RrtConfig::goal_bias`]).
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Sampler {
    /// Uniform in the space's bounds (thesis §6.1: the box of all patches).
    Uniform,
    /// The goal-directed sampling of the thesis's Lesum variants (§6.2.3): per axis
    /// independently a normal distribution centred on an unreached goal (chosen uniformly),
    /// with standard deviation `σ = sqrt(d_far · factor)`, both in millimetres, where `d_far`
    /// is the distance from the goal to the farther face of the box on that axis.
    ///
    /// The thesis calls `d_far · factor` a "variance" and gives factors 1e3 … 2e5 (Fig. 6.11);
    /// reading it as σ² in mm² is the only reading under which small factors hurt and large
    /// ones approach uniform sampling (spec §7.9). A coordinate outside the box is drawn
    /// again (the thesis leaves this open). Once every goal is reached, samples are uniform.
    GoalGaussian {
        /// The bias factor (mm); must be finite and positive.
        factor: Real,
    },
}

/// The choices of an [`Rrt`]. No `Default`: pick [`RrtConfig::thesis`] or
/// [`RrtConfig::lesum`] and change fields.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct RrtConfig {
    /// The probability with which a sample is the centre of an unreached goal (chosen
    /// uniformly) instead of coming from `sampler`; 0 disables it. Values outside `[0, 1]` are
    /// clamped, NaN counts as 0.
    pub goal_bias: Real,
    /// Where the other samples come from.
    pub sampler: Sampler,
    /// Whether each added vertex also tries the straight step to the unreached goals
    /// ([`GoalStep::Direct`]: the thesis's Lesum variants, §6.2.3).
    pub goal_step: GoalStep,
}

impl RrtConfig {
    /// Algorithm 13 as run for the thesis's roadmaps (§6.1): uniform samples, no goal bias,
    /// no direct goal test.
    pub fn thesis() -> RrtConfig {
        RrtConfig { goal_bias: 0.0, sampler: Sampler::Uniform, goal_step: GoalStep::Grown }
    }

    /// The Lesum variant (§6.2.3): the direct goal test after each vertex, and goal-directed
    /// Gaussian sampling with the given bias factor (`None`: uniform samples, the thesis's
    /// "no bias" runs).
    pub fn lesum(bias_factor: Option<Real>) -> RrtConfig {
        let sampler =
            bias_factor.map_or(Sampler::Uniform, |factor| Sampler::GoalGaussian { factor });
        RrtConfig { goal_bias: 0.0, sampler, goal_step: GoalStep::Direct }
    }
}

/// The RRT (thesis Algorithm 13): a tree from the start, grown toward random samples.
///
/// Each iteration draws a sample `x`, finds the nearest vertex `x_near`, and proposes
/// `x_new = x_near + min(max_step, |x − x_near|) · (x − x_near)/|x − x_near|` (LaValle's rule,
/// spec §7.8). If the capsule of the robot radius from `x_near` to `x_new` is free, `x_new`
/// becomes a vertex with an edge to `x_near`; otherwise the iteration adds nothing (Trapped).
/// A sample equal to `x_near` adds nothing either. After each added vertex every unreached
/// goal is tested: it is reached if the vertex lies within its tolerance, or (with
/// [`RrtConfig::goal_step`]) if the capsule from the vertex to the goal centre is free.
///
/// Needs only [`UnspecificStepIntersector`] (thesis Table 5.2).
///
/// # Complexity
/// Nearest neighbours come from [`KdNeighbors`] (amortised O(log² n) per added vertex,
/// O(log² n) per query) on top of one capsule check per iteration (plus one per unreached
/// goal with the direct goal step).
pub struct Rrt<'m, M: UnspecificStepIntersector + ?Sized> {
    map: &'m M,
    space: PlanningSpace,
    config: RrtConfig,
    seed: u64,
    solution: Solution,
}

impl<'m, M: UnspecificStepIntersector + ?Sized> Rrt<'m, M> {
    /// A planner on `map` in `space`; `seed` fixes the random stream.
    pub fn new(map: &'m M, space: PlanningSpace, config: RrtConfig, seed: u64) -> Self {
        Rrt { map, space, config, seed, solution: Solution::default() }
    }

    /// The configuration.
    pub fn config(&self) -> &RrtConfig {
        &self.config
    }

    /// The space.
    pub fn space(&self) -> &PlanningSpace {
        &self.space
    }
}

impl<M: UnspecificStepIntersector + ?Sized> Planner for Rrt<'_, M> {
    fn name(&self) -> &'static str {
        crate::PlannerKind::Rrt.name()
    }

    fn solve(&mut self, problem: &Problem, stop: &mut dyn Termination) -> PlannerStatus {
        let bounds = self.space.bounds();
        let extend = |checker: &mut Checker<'_, M>, x_near: &Point3, x_new: &Point3| {
            (bounds.contains(x_new) && checker.free(x_near, x_new)).then_some(*x_new)
        };
        let solution = &mut self.solution;
        let (map, space, config) = (self.map, &self.space, &self.config);
        solve_rrt(map, space, config, self.seed, problem, stop, solution, Some, extend)
    }

    planner::solution_accessors!();
}

/// The RRT loop shared by [`Rrt`], the Evasion RRT and the MA RRT: `retract(x)` maps each
/// sample that is not a goal centre chosen by the goal bias to the point to extend toward
/// (`Some(x)` for the plain RRT, the retraction onto the medial axis for the MA RRT), `None`
/// dropping the iteration's sample; `extend(checker, x_near, x_new)` returns the vertex to add
/// with an edge to `x_near` (`x_new` itself for the plain RRT, a shifted point for the Evasion
/// RRT), or `None` if the extension is Trapped.
#[allow(clippy::too_many_arguments)]
pub(crate) fn solve_rrt<'m, M: UnspecificStepIntersector + ?Sized>(
    map: &'m M,
    space: &PlanningSpace,
    config: &RrtConfig,
    seed: u64,
    problem: &Problem,
    stop: &mut dyn Termination,
    solution: &mut Solution,
    mut retract: impl FnMut(Point3) -> Option<Point3>,
    mut extend: impl FnMut(&mut Checker<'m, M>, &Point3, &Point3) -> Option<Point3>,
) -> PlannerStatus {
    let started = Instant::now();
    solution.reset(&problem.goals);
    solution.reserve_for(stop.iteration_budget());
    let mut checker = Checker::new(map, space.robot_radius());
    if let Some(invalid) = planner::validate(problem, space, &mut checker) {
        solution.finish(0, &checker);
        return invalid;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut nn = KdNeighbors::new();
    let start = solution.graph.add_node(problem.start);
    nn.add(problem.start);
    test_goals(solution, &mut nn, &mut checker, config, start);
    let mut iterations = 0u64;
    while !stop.should_stop(&solution.progress(iterations, started)) {
        iterations += 1;
        let (x, goal_centre) = sample(&mut rng, space, config, solution);
        let x = if goal_centre { Some(x) } else { retract(x) };
        let Some(x) = x else {
            continue;
        };
        let Some(near) = nn.nearest(&x) else { break };
        if near.distance <= 0.0 {
            continue;
        }
        let x_near = solution.graph[NodeIndex::new(near.index)];
        let length = space.max_step().min(near.distance);
        let x_new = x_near + (x - x_near) * (length / near.distance);
        let Some(x_new) = extend(&mut checker, &x_near, &x_new) else {
            continue;
        };
        let v = solution.graph.add_node(x_new);
        solution.graph.add_edge(NodeIndex::new(near.index), v, (x_new - x_near).norm());
        nn.add(x_new);
        test_goals(solution, &mut nn, &mut checker, config, v);
    }
    solution.finish(iterations, &checker);
    solution.status(|_| true)
}

/// Tests every unreached goal against the new vertex `v` (all vertices are in the start's tree).
fn test_goals<M: UnspecificStepIntersector + ?Sized>(
    solution: &mut Solution,
    nn: &mut KdNeighbors,
    checker: &mut Checker<'_, M>,
    config: &RrtConfig,
    v: NodeIndex,
) {
    let p = solution.graph[v];
    for g in 0..solution.goals.len() {
        if solution.reached[g].is_some() {
            continue;
        }
        let goal = solution.goals[g];
        let distance = (goal.center - p).norm();
        if distance <= goal.tolerance {
            solution.reached[g] = Some(v);
        } else if config.goal_step == GoalStep::Direct && checker.free(&p, &goal.center) {
            let w = solution.graph.add_node(goal.center);
            solution.graph.add_edge(v, w, distance);
            nn.add(goal.center);
            solution.reached[g] = Some(w);
            // The new goal vertex may lie within the tolerance of other goals.
            for (h, other) in solution.goals.iter().enumerate() {
                if solution.reached[h].is_none()
                    && (other.center - goal.center).norm() <= other.tolerance
                {
                    solution.reached[h] = Some(w);
                }
            }
        }
    }
}

/// The next sample, and whether it is a goal centre chosen by the goal bias (shared with the
/// RRT*).
pub(crate) fn sample(
    rng: &mut ChaCha8Rng,
    space: &PlanningSpace,
    config: &RrtConfig,
    solution: &Solution,
) -> (Point3, bool) {
    // Every goal reached (or none, as when exploring): no list to make.
    if solution.reached.iter().all(Option::is_some) {
        return (planner::uniform(rng, space), false);
    }
    let unreached: Vec<usize> =
        (0..solution.goals.len()).filter(|&g| solution.reached[g].is_none()).collect();
    let bias = if config.goal_bias.is_nan() { 0.0 } else { config.goal_bias.clamp(0.0, 1.0) };
    if bias > 0.0 && rng.random::<Real>() < bias {
        return (solution.goals[unreached[rng.random_range(0..unreached.len())]].center, true);
    }
    let x = match config.sampler {
        Sampler::Uniform => planner::uniform(rng, space),
        Sampler::GoalGaussian { factor } => {
            let center = solution.goals[unreached[rng.random_range(0..unreached.len())]].center;
            gaussian_in_box(rng, space, &center, factor)
        }
    };
    (x, false)
}

/// Per axis: `N(center, σ²)` with `σ = sqrt(d_far[mm] · factor)` mm, redrawn until inside the
/// box. The centre is inside the box, so each draw lands inside with probability ≥ ½.
fn gaussian_in_box(
    rng: &mut ChaCha8Rng,
    space: &PlanningSpace,
    center: &Point3,
    factor: Real,
) -> Point3 {
    let b = space.bounds();
    if !(factor.is_finite() && factor > 0.0) {
        return planner::uniform(rng, space);
    }
    Point3::from(std::array::from_fn(|i| {
        let d_far_mm = (center[i] - b.min[i]).max(b.max[i] - center[i]) * 1000.0;
        let sigma = (d_far_mm * factor).sqrt() / 1000.0;
        if !(sigma.is_finite() && sigma > 0.0) {
            return center[i];
        }
        loop {
            let x = center[i] + sigma * standard_normal(rng);
            if b.min[i] <= x && x <= b.max[i] {
                return x;
            }
        }
    }))
}

/// A standard normal deviate (Box–Muller).
fn standard_normal(rng: &mut ChaCha8Rng) -> Real {
    let u1 = 1.0 - rng.random::<Real>(); // in (0, 1]
    let u2 = rng.random::<Real>();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

#[cfg(test)]
mod tests {
    use super::*;
    use patch_core::Aabb;

    #[test]
    fn gaussian_samples_stay_in_the_box_and_concentrate() {
        let b = Aabb::new(Point3::origin(), Point3::new(100.0, 100.0, 10.0));
        let space = PlanningSpace::new(b, 0.1, 1.0).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let goal = Point3::new(90.0, 10.0, 5.0);
        let near = |factor: Real, rng: &mut ChaCha8Rng| {
            (0..500)
                .map(|_| gaussian_in_box(rng, &space, &goal, factor))
                .inspect(|p| assert!(b.contains(p)))
                .filter(|p| (p - goal).norm() < 10.0)
                .count()
        };
        // σ ≈ sqrt(90 000 · 1) mm = 0.3 m on x: almost all samples near the goal.
        assert!(near(1.0, &mut rng) > 450);
        // σ ≈ 134 m: close to uniform.
        assert!(near(2e5, &mut rng) < 100);
    }
}
