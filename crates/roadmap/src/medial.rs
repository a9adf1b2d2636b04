//! The medial-axis planners (thesis §5.5.2, Algorithm 12): samples are retracted onto the
//! medial axis of the patches before they join the roadmap ([`retract_to_medial_axis`],
//! [`MaPrm`], [`MaRrt`]).
//!
//! The medial axis between two patches `P1`, `P2` is the set of points equally far from both
//! (`d_P1(q) = d_P2(q)`); the thesis retracts samples onto it without computing it, which is
//! simpler than the retraction of Wilmarth et al. (1999) because the patches are the border of free space.
//!
//! These planners need [`ProximityQuery`] besides [`UnspecificStepIntersector`]
//! (thesis Table 5.2): a map without closest-patch queries, such as the point-cloud map
//! (`PointCloudMap` of the `patch-map` crate), cannot run them and is rejected at compile time.

use std::cell::Cell;
use std::time::{Duration, Instant};

use patch_core::{Aabb, Point3, Proximity, ProximityQuery, Real, UnspecificStepIntersector};
use rand_chacha::ChaCha8Rng;

use crate::planner::{self, Checker, Planner, PlannerStatus, Solution};
use crate::prm::{PrmConfig, solve_prm};
use crate::rrt::{RrtConfig, solve_rrt};
use crate::space::{PlanningSpace, Problem};
use crate::termination::Termination;

/// Retracts `x` onto the medial axis of the map's patches (the inner step of thesis
/// Algorithm 12), or `None` if the sample is dropped.
///
/// Let `p` be the patch closest to `x` and `c` the closest point on it. The search runs along
/// the ray `x′(s) = x + s·(x − c)`, `s ≥ 0`, away from `p`, for a point whose two closest
/// patches are equally far: a root of `f(s) = d(x′, p) − d(x′, q)`, where `q` is the closest
/// patch other than `p`.
///
/// # Method
/// [`ProximityQuery`] returns only the single closest patch, so `q` and `f` are never
/// computed. Instead, `f` changes sign exactly where the closest patch of `x′` changes from
/// `p` to another patch, so the search brackets and bisects the predicate "the closest patch
/// of `x′` is no longer `p`":
/// 1. Bracket: probe `s = τ/|x − c|` (a first step of length `τ = tolerance`), then double
///    `s` while the closest patch is still `p`; the last probe is clamped to the point where
///    the ray leaves `bounds`. If the closest patch is still `p` there, no root lies inside the
///    bounds and the sample is dropped.
/// 2. Bisect the bracket `[s_lo, s_hi]` (closest patch `p` at `s_lo`, another at `s_hi`)
///    until `|x′(s_hi) − x′(s_lo)| ≤ τ`, and return the midpoint of the final bracket. It lies
///    within `τ/2` of a point where the closest patch changes from `p` to another patch `q`:
///    a point of the medial axis between `p` and `q`, which is what Algorithm 12 needs.
///
/// When `p` is convex (a triangle, a convex polygon without holes), `d(x′, p)` grows at the
/// full rate `|x − c|` along the ray while every other distance grows at most that fast, so
/// `f` is non-decreasing: the closest patch, once changed, never returns to `p`, and the
/// point found is the **first** point along the ray where the closest patch changes. For a
/// non-convex patch the closest patch may change back and forth; the point found is then a
/// change point inside the first bracket of the doubling grid, not necessarily the first one.
///
/// The retracted point is not checked for collision: like a PRM sample it may lie closer to
/// the patches than the robot's radius (a narrow gap), and then no capsule from it is free.
///
/// # Cost
/// `O(log(L/τ))` closest-patch queries, `L` the length of the ray inside `bounds`.
///
/// # Dropped samples
/// `None` if `tolerance` is not finite and positive, `x` is not finite or lies outside
/// `bounds`, the map is empty, `x` lies on a patch (`x == c`), or the ray leaves `bounds`
/// before the closest patch changes (for example with a single patch).
pub fn retract_to_medial_axis<M: ProximityQuery + ?Sized>(
    map: &M,
    x: &Point3,
    bounds: &Aabb,
    tolerance: Real,
) -> Option<Point3> {
    retract(|q| map.closest_patch(q, Real::INFINITY), x, bounds, tolerance)
}

/// [`retract_to_medial_axis`] with the closest-patch query as a function (so the planners
/// can count and time it).
fn retract(
    closest_patch: impl Fn(&Point3) -> Option<Proximity>,
    x: &Point3,
    bounds: &Aabb,
    tolerance: Real,
) -> Option<Point3> {
    let finite = x.iter().all(|c| c.is_finite());
    if !(tolerance.is_finite() && tolerance > 0.0 && finite && bounds.contains(x)) {
        return None;
    }
    let closest = closest_patch(x)?;
    let dir = x - closest.point;
    let len = dir.norm();
    if !(closest.distance > 0.0 && len > 0.0 && len.is_finite()) {
        return None;
    }
    // Where the ray leaves the box.
    let s_max = (0..3)
        .filter(|&i| dir[i] != 0.0)
        .map(|i| {
            let face = if dir[i] > 0.0 { bounds.max[i] } else { bounds.min[i] };
            (face - x[i]) / dir[i]
        })
        .fold(Real::INFINITY, Real::min);
    if !(s_max > 0.0 && s_max.is_finite()) {
        return None;
    }
    let at = |s: Real| (x + dir * s).sup(&bounds.min).inf(&bounds.max);
    let changed = |s: Real| closest_patch(&at(s)).is_some_and(|q| q.patch != closest.patch);
    let mut lo: Real = 0.0;
    let mut hi = (tolerance / len).min(s_max);
    if hi <= 0.0 {
        return None;
    }
    while !changed(hi) {
        if hi >= s_max {
            return None;
        }
        lo = hi;
        hi = (2.0 * hi).min(s_max);
    }
    while (hi - lo) * len > tolerance {
        let mid = 0.5 * (lo + hi);
        if !(lo < mid && mid < hi) {
            break;
        }
        if changed(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(at(0.5 * (lo + hi)))
}

/// Closest-patch queries through the map, counted and timed (for
/// [`PlannerCounters::proximity_queries`](crate::PlannerCounters::proximity_queries)).
struct ProximityCounter<'a, M: ?Sized> {
    map: &'a M,
    queries: Cell<u64>,
    time: Cell<Duration>,
}

impl<'a, M: ProximityQuery + ?Sized> ProximityCounter<'a, M> {
    fn new(map: &'a M) -> Self {
        ProximityCounter { map, queries: Cell::new(0), time: Cell::new(Duration::ZERO) }
    }

    /// [`retract_to_medial_axis`], counting its closest-patch queries.
    fn retract(&self, x: &Point3, bounds: &Aabb, tolerance: Real) -> Option<Point3> {
        let closest_patch = |q: &Point3| {
            let t0 = Instant::now();
            let found = self.map.closest_patch(q, Real::INFINITY);
            self.time.set(self.time.get() + t0.elapsed());
            self.queries.set(self.queries.get() + 1);
            found
        };
        retract(closest_patch, x, bounds, tolerance)
    }

    /// Writes the counts into the solution's counters.
    fn finish(&self, solution: &mut Solution) {
        solution.counters.proximity_queries = self.queries.get();
        solution.counters.proximity_time = self.time.get();
    }
}

/// The retraction tolerance of the `for_space` constructors: 1 % of the robot radius.
fn default_tolerance(space: &PlanningSpace) -> Real {
    0.01 * space.robot_radius()
}

/// The choices of an [`MaPrm`]. No `Default`: pick [`MaPrmConfig::for_space`] and change
/// fields.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct MaPrmConfig {
    /// The PRM's choices (neighbours `N`, connection radius, direct goal step, and
    /// [`PrmConfig::star`], which gives an MA PRM with PRM*'s neighbour count and cycles); the
    /// thesis gives no `N` for the MA PRM either (spec §7.4).
    pub prm: PrmConfig,
    /// The solver tolerance of [`retract_to_medial_axis`] (metres; the length of the final
    /// bisection bracket). Must be finite and positive, otherwise every sample is dropped.
    pub retraction_tolerance: Real,
}

impl MaPrmConfig {
    /// [`PrmConfig::thesis`] (`N = 6`) and a retraction tolerance of 1 % of the robot radius.
    /// The thesis gives neither `N` nor a solver or tolerance for the retraction (§5.5.2);
    /// these values are this crate's choice.
    pub fn for_space(space: &PlanningSpace) -> MaPrmConfig {
        MaPrmConfig { prm: PrmConfig::thesis(), retraction_tolerance: default_tolerance(space) }
    }
}

/// The medial-axis PRM (thesis Algorithm 12): a [`Prm`](crate::Prm) whose samples are first
/// retracted onto the medial axis of the patches.
///
/// Each iteration draws a uniform sample and retracts it with [`retract_to_medial_axis`]; a
/// dropped sample adds nothing but still counts as an iteration (and in
/// [`PlannerCounters::samples`](crate::PlannerCounters::samples)). A retracted sample is connected exactly as in the PRM: its
/// `N` nearest existing vertices (computed before adding it) are tried by increasing
/// distance, skipping those already in its component (union–find), and an edge is added if
/// the robot's capsule is free. The start (vertex 0) and, with the direct goal step, goal
/// centres are not retracted.
///
/// With the same seed, the samples before retraction are those of the [`Prm`](crate::Prm).
/// Closest-patch queries are counted in [`PlannerCounters::proximity_queries`](crate::PlannerCounters::proximity_queries) (not in
/// [`PlannerCounters::collision_checks`](crate::PlannerCounters::collision_checks)).
///
/// Needs [`ProximityQuery`] and [`UnspecificStepIntersector`] (thesis
/// Table 5.2); a map without closest-patch queries (the point-cloud map) is rejected at
/// compile time:
///
/// ```
/// use patch_core::{Aabb, BruteForceMap, Point3};
/// use roadmap::{MaPrm, MaPrmConfig, PlanningSpace};
///
/// let bounds = Aabb::new(Point3::origin(), Point3::new(4.0, 4.0, 2.0));
/// let space = PlanningSpace::new(bounds, 0.2, 0.5).unwrap();
/// let map = BruteForceMap::new(); // has closest-patch queries
/// let _planner = MaPrm::new(&map, space, MaPrmConfig::for_space(&space), 0);
/// ```
///
/// ```compile_fail
/// use patch_core::{Aabb, CapsuleStep, Point3, UnspecificStepIntersector};
/// use roadmap::{MaPrm, MaPrmConfig, PlanningSpace};
///
/// struct OnlyUnspecific;
/// impl UnspecificStepIntersector for OnlyUnspecific {
///     fn is_step_free(&self, _: &CapsuleStep) -> bool { true }
/// }
/// let bounds = Aabb::new(Point3::origin(), Point3::new(4.0, 4.0, 2.0));
/// let space = PlanningSpace::new(bounds, 0.2, 0.5).unwrap();
/// let map = OnlyUnspecific; // no `closest_patch`: not accepted
/// let _planner = MaPrm::new(&map, space, MaPrmConfig::for_space(&space), 0);
/// ```
///
/// # Complexity
/// Per iteration `O(log(L/τ))` closest-patch queries (see [`retract_to_medial_axis`]) plus the
/// PRM's neighbour query and at most `N` capsule checks.
pub struct MaPrm<'m, M: ProximityQuery + UnspecificStepIntersector + ?Sized> {
    map: &'m M,
    space: PlanningSpace,
    config: MaPrmConfig,
    seed: u64,
    solution: Solution,
}

impl<'m, M: ProximityQuery + UnspecificStepIntersector + ?Sized> MaPrm<'m, M> {
    /// A planner on `map` in `space`; `seed` fixes the random stream.
    pub fn new(map: &'m M, space: PlanningSpace, config: MaPrmConfig, seed: u64) -> Self {
        MaPrm { map, space, config, seed, solution: Solution::default() }
    }

    /// The configuration.
    pub fn config(&self) -> &MaPrmConfig {
        &self.config
    }

    /// The space.
    pub fn space(&self) -> &PlanningSpace {
        &self.space
    }
}

impl<M: ProximityQuery + UnspecificStepIntersector + ?Sized> Planner for MaPrm<'_, M> {
    fn name(&self) -> &'static str {
        crate::PlannerKind::MaPrm.name()
    }

    fn solve(&mut self, problem: &Problem, stop: &mut dyn Termination) -> PlannerStatus {
        let (map, space, config) = (self.map, &self.space, &self.config);
        let bounds = space.bounds();
        let tolerance = config.retraction_tolerance;
        let counter = ProximityCounter::new(map);
        let sample = |rng: &mut ChaCha8Rng| {
            counter.retract(&planner::uniform(rng, space), &bounds, tolerance)
        };
        let solution = &mut self.solution;
        let status = solve_prm(map, space, &config.prm, self.seed, problem, stop, solution, sample);
        counter.finish(solution);
        status
    }

    planner::solution_accessors!();
}

/// The choices of an [`MaRrt`]. No `Default`: pick [`MaRrtConfig::for_space`] and change
/// fields.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct MaRrtConfig {
    /// The RRT's choices (goal bias, sampler, direct goal step).
    pub rrt: RrtConfig,
    /// The solver tolerance of [`retract_to_medial_axis`] (metres). Must be finite and
    /// positive, otherwise every sample is dropped.
    pub retraction_tolerance: Real,
}

impl MaRrtConfig {
    /// [`RrtConfig::thesis`] and a retraction tolerance of 1 % of the robot radius. The thesis
    /// gives no pseudo-code, solver or tolerance for the MA RRT (§5.5.2); these values are
    /// this crate's choice.
    pub fn for_space(space: &PlanningSpace) -> MaRrtConfig {
        MaRrtConfig { rrt: RrtConfig::thesis(), retraction_tolerance: default_tolerance(space) }
    }
}

/// The medial-axis RRT: an [`Rrt`](crate::Rrt) that extends toward samples retracted onto
/// the medial axis.
///
/// The thesis gives no pseudo-code (it is "inspired by" Wilmarth et al. and "immediately
/// connects nodes moved to the medial axes", §5.5.2); this is the spec's reading: each sample
/// `x_rand` (except a goal centre chosen by the goal bias) is retracted with
/// [`retract_to_medial_axis`] to `x′` — a dropped sample adds nothing but counts as an
/// iteration — and the tree takes one RRT EXTEND step toward `x′`
/// (`x_new = x_near + min(max_step, |x′ − x_near|)·unit`, added if the capsule is free and
/// `x_new` is inside the bounds). Only `x′` lies on the medial axis; `x_new` does when the
/// step reaches it. Goals are tested as in the RRT.
///
/// Closest-patch queries are counted in [`PlannerCounters::proximity_queries`](crate::PlannerCounters::proximity_queries) (not in
/// [`PlannerCounters::collision_checks`](crate::PlannerCounters::collision_checks)).
///
/// Needs [`ProximityQuery`] and [`UnspecificStepIntersector`] (thesis
/// Table 5.2); a map without closest-patch queries (the point-cloud map) cannot run it.
pub struct MaRrt<'m, M: ProximityQuery + UnspecificStepIntersector + ?Sized> {
    map: &'m M,
    space: PlanningSpace,
    config: MaRrtConfig,
    seed: u64,
    solution: Solution,
}

impl<'m, M: ProximityQuery + UnspecificStepIntersector + ?Sized> MaRrt<'m, M> {
    /// A planner on `map` in `space`; `seed` fixes the random stream.
    pub fn new(map: &'m M, space: PlanningSpace, config: MaRrtConfig, seed: u64) -> Self {
        MaRrt { map, space, config, seed, solution: Solution::default() }
    }

    /// The configuration.
    pub fn config(&self) -> &MaRrtConfig {
        &self.config
    }

    /// The space.
    pub fn space(&self) -> &PlanningSpace {
        &self.space
    }
}

impl<M: ProximityQuery + UnspecificStepIntersector + ?Sized> Planner for MaRrt<'_, M> {
    fn name(&self) -> &'static str {
        crate::PlannerKind::MaRrt.name()
    }

    fn solve(&mut self, problem: &Problem, stop: &mut dyn Termination) -> PlannerStatus {
        let (map, space, config) = (self.map, &self.space, &self.config);
        let bounds = space.bounds();
        let tolerance = config.retraction_tolerance;
        let counter = ProximityCounter::new(map);
        let retract = |x: Point3| counter.retract(&x, &bounds, tolerance);
        let extend = |checker: &mut Checker<'_, M>, x_near: &Point3, x_new: &Point3| {
            (bounds.contains(x_new) && checker.free(x_near, x_new)).then_some(*x_new)
        };
        let solution = &mut self.solution;
        let status =
            solve_rrt(map, space, &config.rrt, self.seed, problem, stop, solution, retract, extend);
        counter.finish(solution);
        status
    }

    planner::solution_accessors!();
}

#[cfg(test)]
mod tests {
    use super::*;
    use patch_core::{BruteForceMap, FromPatches, PlanarPatch};

    const TOL: Real = 1e-4;

    fn quad(corners: [Point3; 4]) -> PlanarPatch {
        PlanarPatch::from_world_polygon(&corners, &[], 1e-9).unwrap()
    }

    /// A horizontal square `[-5, 5]²` at height `z`.
    fn floor_at(z: Real) -> PlanarPatch {
        quad([
            Point3::new(-5.0, -5.0, z),
            Point3::new(5.0, -5.0, z),
            Point3::new(5.0, 5.0, z),
            Point3::new(-5.0, 5.0, z),
        ])
    }

    /// A vertical square in the plane `x = x0`.
    fn wall_at(x0: Real) -> PlanarPatch {
        quad([
            Point3::new(x0, -5.0, -5.0),
            Point3::new(x0, 5.0, -5.0),
            Point3::new(x0, 5.0, 5.0),
            Point3::new(x0, -5.0, 5.0),
        ])
    }

    fn cube(half: Real) -> Aabb {
        Aabb::new(Point3::new(-half, -half, -half), Point3::new(half, half, half))
    }

    fn parallel_walls() -> BruteForceMap {
        BruteForceMap::from_patches([floor_at(0.0).into(), floor_at(2.0).into()]).unwrap()
    }

    #[test]
    fn between_parallel_walls_lands_on_the_mid_plane() {
        let map = parallel_walls();
        let bounds = Aabb::new(Point3::new(-4.0, -4.0, 0.0), Point3::new(4.0, 4.0, 2.0));
        for x in [
            Point3::new(0.5, 0.5, 0.3),
            Point3::new(-1.0, 2.0, 1.9),
            Point3::new(3.0, -3.0, 0.001),
            Point3::new(0.0, 0.0, 0.99999),
        ] {
            let r = retract_to_medial_axis(&map, &x, &bounds, TOL).unwrap();
            assert!((r.z - 1.0).abs() <= TOL, "{x} retracted to {r}");
            // The ray is the normal of the closest wall: x and y are kept.
            assert!((r.x - x.x).abs() < 1e-12 && (r.y - x.y).abs() < 1e-12);
        }
        // A coarser tolerance, still within it.
        let r = retract_to_medial_axis(&map, &Point3::new(0.0, 0.0, 0.2), &bounds, 0.05).unwrap();
        assert!((r.z - 1.0).abs() <= 0.05);
    }

    #[test]
    fn in_a_corner_lands_on_the_bisector() {
        // Floor z = 0 and wall x = 0 meet along the y axis; the medial axis is x = z.
        let map = BruteForceMap::from_patches([floor_at(0.0).into(), wall_at(0.0).into()]).unwrap();
        let bounds = Aabb::new(Point3::new(0.0, -4.0, 0.0), Point3::new(4.0, 4.0, 4.0));
        for x in
            [Point3::new(2.0, 0.0, 0.5), Point3::new(0.1, 1.0, 3.0), Point3::new(3.0, 3.0, 1.0)]
        {
            let r = retract_to_medial_axis(&map, &x, &bounds, TOL).unwrap();
            let (d_floor, d_wall) = (r.z, r.x);
            assert!((d_floor - d_wall).abs() <= 2.0 * TOL, "{x} retracted to {r}");
        }
    }

    #[test]
    fn drops_samples_without_a_root_in_the_bounds() {
        let map = parallel_walls();
        // The mid-plane z = 1 lies outside this box.
        let low = Aabb::new(Point3::new(-4.0, -4.0, 0.0), Point3::new(4.0, 4.0, 0.9));
        assert_eq!(retract_to_medial_axis(&map, &Point3::new(0.0, 0.0, 0.3), &low, TOL), None);
        // A single patch has no medial axis.
        let single = BruteForceMap::from_patches([floor_at(0.0).into()]).unwrap();
        assert_eq!(
            retract_to_medial_axis(&single, &Point3::new(0.0, 0.0, 0.3), &cube(4.0), TOL),
            None
        );
        // An empty map neither.
        let empty = BruteForceMap::new();
        assert_eq!(retract_to_medial_axis(&empty, &Point3::origin(), &cube(4.0), TOL), None);
    }

    #[test]
    fn drops_samples_on_a_patch_and_invalid_input() {
        let map = parallel_walls();
        let bounds = Aabb::new(Point3::new(-4.0, -4.0, 0.0), Point3::new(4.0, 4.0, 2.0));
        let on = Point3::new(1.0, 1.0, 0.0);
        assert_eq!(retract_to_medial_axis(&map, &on, &bounds, TOL), None);
        let x = Point3::new(0.0, 0.0, 0.5);
        for tol in [0.0, -1.0, Real::NAN, Real::INFINITY] {
            assert_eq!(retract_to_medial_axis(&map, &x, &bounds, tol), None);
        }
        let outside = Point3::new(0.0, 0.0, 3.0);
        assert_eq!(retract_to_medial_axis(&map, &outside, &bounds, TOL), None);
        let nan = Point3::new(Real::NAN, 0.0, 0.5);
        assert_eq!(retract_to_medial_axis(&map, &nan, &bounds, TOL), None);
    }

    #[test]
    fn the_first_change_of_closest_patch_is_found() {
        // Walls at z = 0, z = 1 and z = 3: from z = 0.2 the ray meets the medial axis of the
        // first two walls (z = 0.5) before anything else.
        let map = BruteForceMap::from_patches([
            floor_at(0.0).into(),
            floor_at(1.0).into(),
            floor_at(3.0).into(),
        ])
        .unwrap();
        let r = retract_to_medial_axis(&map, &Point3::new(0.0, 0.0, 0.2), &cube(4.0), TOL);
        assert!((r.unwrap().z - 0.5).abs() <= TOL);
        // From z = 1.2 the closest wall is z = 1; moving up, the axis is z = 2.
        let r = retract_to_medial_axis(&map, &Point3::new(0.0, 0.0, 1.2), &cube(4.0), TOL);
        assert!((r.unwrap().z - 2.0).abs() <= TOL);
    }
}
