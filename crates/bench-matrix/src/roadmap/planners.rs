//! The planners of the matrix, configured as `patchnav plan` configures them: every planner
//! tests, after each added vertex, whether a goal is directly reachable by one free capsule step
//! (the thesis's §6.2.3 variant), so their results compare; PRM has the thesis's six
//! neighbours (Algorithm 14).

use anyhow::{Result, bail};
use patch_map::AnyMap;
use roadmap::{
    EvasionRrt, EvasionRrtConfig, MaPrm, MaPrmConfig, MaRrt, MaRrtConfig, Planner, PlanningSpace,
    Prm, PrmConfig, Rrt, RrtConfig, RrtConnect, RrtStar, RrtStarConfig,
};

/// Every planner of the `roadmap` crate, by the name the matrix uses in its case keys: the
/// thesis's five first (Table 5.3's rows), then the others.
pub(crate) const PLANNERS: [&str; 9] = [
    "rrt",
    "ma-rrt",
    "evasion-rrt",
    "prm",
    "ma-prm",
    "rrt-connect",
    "prm-star",
    "lazy-prm",
    "rrt-star",
];

/// PRM as the thesis configures it (six neighbours), with the direct goal step.
fn prm_config() -> PrmConfig {
    PrmConfig { direct_goal_step: true, ..PrmConfig::thesis() }
}

/// The planner `name` on `map`; an error when it cannot run on this map (the point-cloud map
/// answers neither proximity queries nor specific hits: thesis Table 5.2).
pub(crate) fn make_planner<'m>(
    name: &str,
    map: &'m AnyMap,
    space: PlanningSpace,
    seed: u64,
) -> Result<Box<dyn Planner + 'm>> {
    Ok(match name {
        "rrt" => Box::new(Rrt::new(map, space, RrtConfig::lesum(None), seed)),
        "prm" => Box::new(Prm::new(map, space, prm_config(), seed)),
        "prm-star" => {
            let config = PrmConfig { direct_goal_step: true, ..PrmConfig::star() };
            Box::new(Prm::new(map, space, config, seed))
        }
        "lazy-prm" => Box::new(Prm::lazy(map, space, prm_config(), seed)),
        "rrt-star" => {
            let config = RrtStarConfig { rrt: RrtConfig::lesum(None), ..RrtStarConfig::standard() };
            Box::new(RrtStar::new(map, space, config, seed))
        }
        "rrt-connect" => Box::new(RrtConnect::new(map, space, seed)),
        "evasion-rrt" => evasion_planner(map, space, seed)?,
        "ma-prm" | "ma-rrt" => medial_planner(name == "ma-prm", map, space, seed)?,
        other => bail!("unknown planner `{other}`; known: {}", PLANNERS.join(", ")),
    })
}

/// A medial-axis planner on the concrete backend of `map` (it needs proximity queries).
fn medial_planner<'m>(
    prm: bool,
    map: &'m AnyMap,
    space: PlanningSpace,
    seed: u64,
) -> Result<Box<dyn Planner + 'm>> {
    fn make<'m, M>(prm: bool, m: &'m M, space: PlanningSpace, seed: u64) -> Box<dyn Planner + 'm>
    where
        M: patch_core::ProximityQuery
            + patch_core::UnspecificStepIntersector<patch_core::CapsuleStep>,
    {
        if prm {
            let config = MaPrmConfig { prm: prm_config(), ..MaPrmConfig::for_space(&space) };
            Box::new(MaPrm::new(m, space, config, seed))
        } else {
            let config =
                MaRrtConfig { rrt: RrtConfig::lesum(None), ..MaRrtConfig::for_space(&space) };
            Box::new(MaRrt::new(m, space, config, seed))
        }
    }
    Ok(match map {
        AnyMap::Polygon(m) => make(prm, m, space, seed),
        AnyMap::BBox6d(m) => make(prm, m, space, seed),
        AnyMap::Trimesh(m) => make(prm, m, space, seed),
        AnyMap::Rapier(m) => make(prm, m, space, seed),
        other => bail!(
            "a medial-axis planner needs proximity queries; a `{}` map cannot answer them",
            other.backend()
        ),
    })
}

/// The Evasion RRT on the concrete backend of `map` (it needs specific step hits).
fn evasion_planner<'m>(
    map: &'m AnyMap,
    space: PlanningSpace,
    seed: u64,
) -> Result<Box<dyn Planner + 'm>> {
    let config =
        EvasionRrtConfig { rrt: RrtConfig::lesum(None), ..EvasionRrtConfig::for_space(&space) };
    Ok(match map {
        AnyMap::Polygon(m) => Box::new(EvasionRrt::new(m, space, config, seed)),
        AnyMap::BBox6d(m) => Box::new(EvasionRrt::new(m, space, config, seed)),
        AnyMap::Trimesh(m) => Box::new(EvasionRrt::new(m, space, config, seed)),
        AnyMap::Rapier(m) => Box::new(EvasionRrt::new(m, space, config, seed)),
        other => bail!(
            "evasion-rrt needs specific step hits; a `{}` map cannot report them",
            other.backend()
        ),
    })
}
