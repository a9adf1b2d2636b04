//! The planners of the matrix, built by `roadmap`'s named-planner factory as `patchnav plan`
//! builds them: every planner
//! tests, after each added vertex, whether a goal is directly reachable by one free capsule step
//! (the thesis's §6.2.3 variant), so their results compare; PRM has the thesis's six
//! neighbours (Algorithm 14).

use anyhow::{Result, bail};
use patch_map::AnyMap;
use roadmap::{
    MapCapability, Planner, PlannerKind, PlanningSpace, named_patch_planner, named_planner,
};

/// Every planner of the `roadmap` crate, by the name the matrix uses in its case keys: the
/// thesis's five first (Table 5.3's rows), then the others.
pub(crate) const PLANNERS: [&str; 9] = {
    let mut names = [""; 9];
    let mut i = 0;
    while i < names.len() {
        names[i] = PlannerKind::ALL[i].name();
        i += 1;
    }
    names
};

/// The planner `name` on `map` ([`roadmap::named_planner`]); an error when it cannot run on
/// this map (the point-cloud map answers neither proximity queries nor specific hits: thesis
/// Table 5.2).
pub(crate) fn make_planner<'m>(
    name: &str,
    map: &'m AnyMap,
    space: PlanningSpace,
    seed: u64,
) -> Result<Box<dyn Planner + 'm>> {
    let Ok(kind) = name.parse::<PlannerKind>() else {
        bail!("unknown planner `{name}`; known: {}", PLANNERS.join(", "));
    };
    let Some(needs) = kind.needs() else {
        return Ok(named_planner(kind, map, space, seed)?);
    };
    Ok(match map {
        AnyMap::Polygon(m) => named_patch_planner(kind, m, space, seed),
        AnyMap::BBox6d(m) => named_patch_planner(kind, m, space, seed),
        AnyMap::Trimesh(m) => named_patch_planner(kind, m, space, seed),
        AnyMap::Rapier(m) => named_patch_planner(kind, m, space, seed),
        other => match needs {
            MapCapability::SpecificHits => bail!(
                "evasion-rrt needs specific step hits; a `{}` map cannot report them",
                other.backend()
            ),
            MapCapability::Proximity => bail!(
                "a medial-axis planner needs proximity queries; a `{}` map cannot answer them",
                other.backend()
            ),
        },
    })
}
