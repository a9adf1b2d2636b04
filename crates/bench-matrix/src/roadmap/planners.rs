//! The planners of the matrix, built by `roadmap`'s named-planner factory as `patchnav plan`
//! builds them: every planner
//! tests, after each added vertex, whether a goal is directly reachable by one free capsule step
//! (the thesis's §6.2.3 variant), so their results compare; PRM has the thesis's six
//! neighbours (Algorithm 14). The matrix runs every [`PlannerKind`] (the thesis's five first,
//! Table 5.3's rows, then the others), named in its case keys by [`PlannerKind::name`].

use anyhow::Result;
use patch_map::AnyMap;
use roadmap::{Planner, PlannerKind, PlanningSpace, named_planner_on};

/// The planner `kind` on `map` ([`roadmap::named_planner_on`]); an error when it cannot run on
/// this map (the point-cloud map answers neither proximity queries nor specific hits: thesis
/// Table 5.2).
pub(crate) fn make_planner(
    kind: PlannerKind,
    map: &AnyMap,
    space: PlanningSpace,
    seed: u64,
) -> Result<Box<dyn Planner + '_>> {
    Ok(named_planner_on(kind, map, space, seed)?)
}
