//! The Evasion RRT (thesis §5.5.1, Algorithm 11, as repaired by spec §4 [R]).

use patch_core::{Patch, PatchId, Point3, Real, SpecificStepIntersector, UnitVector3, Vector3};

use crate::planner::{
    Checker, Contact, Planner, PlannerCounters, PlannerStatus, Roadmap, Solution,
};
use crate::rrt::{RrtConfig, solve_rrt};
use crate::space::{PlanningSpace, Problem};
use crate::termination::Termination;

/// The choices of an [`EvasionRrt`]. No `Default`: start from [`EvasionRrtConfig::for_space`]
/// and change fields.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct EvasionRrtConfig {
    /// Sampling, goal bias and the direct goal test, exactly as for the RRT.
    pub rrt: RrtConfig,
    /// `l_ev`: how far, in metres, one evasion shifts the candidate vertex sideways. Must be
    /// finite and positive for evasion to happen; otherwise no shift is tried.
    pub evasion_step: Real,
    /// `E`: the most shifts tried for one candidate (0 makes the planner a plain RRT that
    /// asks the specific query).
    pub max_evasions: u32,
}

impl EvasionRrtConfig {
    /// The defaults for `space`. The thesis gives neither `l_ev` nor a bound on the number of
    /// shifts (spec §4, §7.14); these are this crate's choices:
    /// * `rrt`: [`RrtConfig::thesis`] (uniform samples, no goal bias, no direct goal test, as
    ///   in the thesis's benchmark);
    /// * `evasion_step`: the robot radius (a shift moves the capsule end by its own radius,
    ///   fine enough to slip past a patch border without jumping over thin gaps);
    /// * `max_evasions`: 8 (shifts up to 8 radii, a few robot diameters, beside the first
    ///   contact).
    pub fn for_space(space: &PlanningSpace) -> EvasionRrtConfig {
        EvasionRrtConfig {
            rrt: RrtConfig::thesis(),
            evasion_step: space.robot_radius(),
            max_evasions: 8,
        }
    }
}

/// The Evasion RRT (thesis §5.5.1, Algorithm 11): an RRT whose colliding extensions slide
/// sideways along the planar patch they hit, so vertices gather near obstacles.
///
/// The printed algorithm is broken (spec §4, §7.14: `x_new` is never assigned, `p_old` never
/// set, a hit on another patch ends the loop while still colliding, `u × n` vanishes for
/// `u ∥ n`). This is the repair (spec \[R\]): each iteration proposes `x_new` exactly as [`Rrt`]
/// does, with step direction `u = unit(x_new − x_near)`. While the specific capsule check
/// `x_near → x_new` hits, the hit patch `p` is planar, it is the same patch as the first hit,
/// and fewer than `E` shifts were made:
/// `x_new ← x_new + l_ev · unit(u × n_p)` with `n_p` the patch's own plane normal (so the
/// shift lies in the patch's plane, across the motion). If `u ∥ n_p`, `u × a` replaces
/// `u × n_p`, with `a` the coordinate axis least aligned with `n_p` (first of x, y, z on ties).
/// `x_new` is added (edge to `x_near`) only if the last check is free and `x_new` lies in the
/// bounds; a hit on a trimesh patch or on a different patch, a shift out of the bounds, or `E`
/// shifts without success make the iteration Trapped. Goal handling, termination, status and
/// counters are the RRT's; each specific check counts as one collision check.
///
/// The shifts are perpendicular to `u`, so an edge is at most
/// `sqrt(max_step² + (E · l_ev)²)` long.
///
/// Needs [`SpecificStepIntersector`] (thesis Table 5.2); a map with only the
/// unspecific query is rejected at compile time:
///
/// ```
/// use patch_core::{Aabb, BruteForceMap, Point3};
/// use roadmap::{EvasionRrt, EvasionRrtConfig, PlanningSpace};
///
/// let bounds = Aabb::new(Point3::origin(), Point3::new(4.0, 4.0, 2.0));
/// let space = PlanningSpace::new(bounds, 0.2, 0.5).unwrap();
/// let map = BruteForceMap::new(); // has the specific capsule query
/// let _planner = EvasionRrt::new(&map, space, EvasionRrtConfig::for_space(&space), 0);
/// ```
///
/// ```compile_fail
/// use patch_core::{Aabb, CapsuleStep, Point3, UnspecificStepIntersector};
/// use roadmap::{EvasionRrt, EvasionRrtConfig, PlanningSpace};
///
/// struct OnlyUnspecific;
/// impl UnspecificStepIntersector for OnlyUnspecific {
///     fn is_step_free(&self, _: &CapsuleStep) -> bool { true }
/// }
/// let bounds = Aabb::new(Point3::origin(), Point3::new(4.0, 4.0, 2.0));
/// let space = PlanningSpace::new(bounds, 0.2, 0.5).unwrap();
/// let map = OnlyUnspecific; // no `first_hit`: not accepted
/// let _planner = EvasionRrt::new(&map, space, EvasionRrtConfig::for_space(&space), 0);
/// ```
///
/// [`Rrt`]: crate::Rrt
pub struct EvasionRrt<'m, M: SpecificStepIntersector + ?Sized> {
    map: &'m M,
    space: PlanningSpace,
    config: EvasionRrtConfig,
    seed: u64,
    solution: Solution,
    evaded: usize,
}

impl<'m, M: SpecificStepIntersector + ?Sized> EvasionRrt<'m, M> {
    /// A planner on `map` in `space`; `seed` fixes the random stream.
    pub fn new(map: &'m M, space: PlanningSpace, config: EvasionRrtConfig, seed: u64) -> Self {
        EvasionRrt { map, space, config, seed, solution: Solution::default(), evaded: 0 }
    }

    /// The configuration.
    pub fn config(&self) -> &EvasionRrtConfig {
        &self.config
    }

    /// The space.
    pub fn space(&self) -> &PlanningSpace {
        &self.space
    }

    /// How many vertices of the last solve were added after at least one shift.
    pub fn evaded_vertices(&self) -> usize {
        self.evaded
    }
}

impl<M: SpecificStepIntersector + ?Sized> Planner for EvasionRrt<'_, M> {
    fn name(&self) -> &'static str {
        crate::PlannerKind::EvasionRrt.name()
    }

    fn solve(&mut self, problem: &Problem, stop: &mut dyn Termination) -> PlannerStatus {
        let bounds = self.space.bounds();
        let config = self.config;
        let evaded = &mut self.evaded;
        *evaded = 0;
        let extend = |checker: &mut Checker<'_, M>, x_near: &Point3, x_new: &Point3| {
            if !bounds.contains(x_new) {
                return None;
            }
            let u = x_new - x_near;
            let mut x = *x_new;
            let mut first_patch: Option<PatchId> = None;
            let mut shifts = 0u32;
            loop {
                let hit = match checker.first_hit(x_near, &x) {
                    Contact::Free => {
                        *evaded += usize::from(shifts > 0);
                        return Some(x);
                    }
                    Contact::Invalid => return None,
                    Contact::Hit(hit) => hit,
                };
                let can_shift = config.evasion_step.is_finite()
                    && config.evasion_step > 0.0
                    && shifts < config.max_evasions;
                if !can_shift || first_patch.is_some_and(|p| p != hit.patch) {
                    return None;
                }
                let Some(Patch::Planar(patch)) = checker.map().patch(hit.patch) else {
                    return None; // trimesh patches (or an unknown id): stop evading
                };
                first_patch = Some(hit.patch);
                x += evasion_direction(&u, &patch.normal()) * config.evasion_step;
                shifts += 1;
                if !bounds.contains(&x) {
                    return None;
                }
            }
        };
        let solution = &mut self.solution;
        let (map, space, rrt) = (self.map, &self.space, &config.rrt);
        solve_rrt(map, space, rrt, self.seed, problem, stop, solution, Some, extend)
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
        self.evaded = 0;
    }
}

/// `unit(u × n)`, or `unit(u × a)` with `a` the axis least aligned with `n` when `u ∥ n`
/// (or `u = 0`, which the RRT never proposes; then any unit vector in the plane).
fn evasion_direction(u: &Vector3, n: &UnitVector3) -> Vector3 {
    let d = u.cross(n);
    if d.norm() > 1e-9 * u.norm() && d.norm() > 0.0 {
        return d.normalize();
    }
    let axis = (0..3).fold(0, |best, i| if n[i].abs() < n[best].abs() { i } else { best });
    let d = u.cross(&Vector3::ith(axis, 1.0));
    if d.norm() > 0.0 {
        d.normalize()
    } else {
        // u = 0: a unit vector perpendicular to n.
        n.cross(&Vector3::ith(axis, 1.0)).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn evasion_direction_is_perpendicular_and_unit() {
        let z = UnitVector3::new_normalize(Vector3::z());
        let d = evasion_direction(&Vector3::new(2.0, 0.0, 0.0), &z);
        assert!((d - Vector3::new(0.0, -1.0, 0.0)).norm() < 1e-12);
        // u ∥ n: perpendicular to both, deterministic.
        for u in [Vector3::new(0.0, 0.0, 3.0), Vector3::new(0.0, 0.0, -1.0), Vector3::zeros()] {
            let d = evasion_direction(&u, &z);
            assert!((d.norm() - 1.0).abs() < 1e-12);
            assert!(d.dot(&z).abs() < 1e-12 && d.dot(&u).abs() < 1e-12);
            assert_eq!(d, evasion_direction(&u, &z));
        }
        let n = UnitVector3::new_normalize(Vector3::new(1.0, 2.0, 3.0));
        let d = evasion_direction(&(n.into_inner() * 0.5), &n);
        assert!((d.norm() - 1.0).abs() < 1e-12 && d.dot(&n).abs() < 1e-9);
    }
}
