//! Every planner of this crate by name, configured alike for comparisons: each tests, after
//! every added vertex, whether a goal is directly reachable by one free capsule step (the
//! thesis's §6.2.3 variant), so their results compare; the RRTs use Lesum's goal bias
//! ([`RrtConfig::lesum`]) and the PRMs the thesis's six neighbours (Algorithm 14).
//!
//! Two planners need more of a map than step tests (thesis Table 5.2): the Evasion RRT needs
//! specific step hits, the medial-axis planners need proximity queries ([`PlannerKind::needs`],
//! the one place that decides it; [`PlannerKind::runs_on`] asks a map chosen at run time).
//! [`named_planner`] builds the others on any map that tests steps; [`named_patch_planner`]
//! builds all ten on a map with every capability.
//!
//! ```
//! use patch_core::{Aabb, BruteForceMap, Point3};
//! use roadmap::{PlannerKind, PlanningSpace, named_patch_planner, named_planner};
//!
//! let map = BruteForceMap::new();
//! let space = PlanningSpace::new(Aabb::new(Point3::origin(), Point3::new(4.0, 4.0, 2.0)), 0.2, 0.5)?;
//! let kind: PlannerKind = "ma-prm".parse()?;
//! assert!(named_planner(kind, &map, space, 7).is_err(), "needs proximity queries");
//! let planner = named_patch_planner(kind, &map, space, 7);
//! # let _ = planner;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::GoalStep;
use crate::{
    EvasionRrt, EvasionRrtConfig, MaPrm, MaPrmConfig, MaRrt, MaRrtConfig, Planner, PlanningSpace,
    Prm, PrmConfig, Rrt, RrtConfig, RrtConnect, RrtStar, RrtStarConfig,
};
use patch_core::{
    MaybePatchMap, PatchMapVisitor, ProximityQuery, SpecificStepIntersector,
    UnspecificStepIntersector,
};
use std::fmt;
use std::str::FromStr;

/// The planners of this crate.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum PlannerKind {
    /// Rapidly-exploring random tree (thesis Algorithm 13).
    Rrt,
    /// Medial-axis RRT (thesis §5.5.2): needs proximity queries.
    MaRrt,
    /// Evasion RRT (thesis Algorithm 11): needs specific step hits.
    EvasionRrt,
    /// Probabilistic roadmap (thesis Algorithm 14), six nearest neighbours.
    Prm,
    /// Medial-axis PRM (thesis Algorithm 12): needs proximity queries.
    MaPrm,
    /// RRT-Connect (Kuffner and LaValle 2000).
    RrtConnect,
    /// PRM* (Karaman and Frazzoli 2011).
    PrmStar,
    /// Lazy PRM (Bohlin and Kavraki 2000), six nearest neighbours.
    LazyPrm,
    /// RRT* (Karaman and Frazzoli 2011).
    RrtStar,
    /// PRM on valid samples with cycles ([`PrmConfig::valid`]): Algorithm 14 with each sample
    /// checked before it is added and edges to all six neighbours, as OMPL's PRM builds its
    /// roadmap; not in the thesis.
    PrmValid,
}

/// A capability of a map beyond step tests that some planners need (thesis Table 5.2).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum MapCapability {
    /// Which patch a step hits ([`SpecificStepIntersector`]).
    SpecificHits,
    /// The closest patch to a point ([`ProximityQuery`]).
    Proximity,
}

/// Why a planner could not be named or built.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum NamedPlannerError {
    /// No planner has this name.
    #[error("unknown planner `{name}`; known: {}", PlannerKind::ALL.map(PlannerKind::name).join(", "))]
    Unknown {
        /// The name given.
        name: String,
    },
    /// The planner needs a capability the map lacks; build it with [`named_patch_planner`].
    #[error("{planner} needs a map with {capability}")]
    NeedsCapability {
        /// The planner.
        planner: PlannerKind,
        /// What it needs.
        capability: MapCapability,
    },
    /// The planner needs a capability the backend of a run-time map lacks
    /// ([`named_planner_on`]).
    #[error("{planner} needs a map with {capability}; a `{backend}` map cannot answer them")]
    BackendLacks {
        /// The planner.
        planner: PlannerKind,
        /// What it needs.
        capability: MapCapability,
        /// The map's backend.
        backend: &'static str,
    },
}

impl PlannerKind {
    /// All ten: the thesis's five first (Table 5.3's rows), then the others.
    pub const ALL: [PlannerKind; 10] = [
        PlannerKind::Rrt,
        PlannerKind::MaRrt,
        PlannerKind::EvasionRrt,
        PlannerKind::Prm,
        PlannerKind::MaPrm,
        PlannerKind::RrtConnect,
        PlannerKind::PrmStar,
        PlannerKind::LazyPrm,
        PlannerKind::RrtStar,
        PlannerKind::PrmValid,
    ];

    /// The lower-case, hyphenated name (`rrt`, `ma-rrt`, `evasion-rrt`, `prm`, `ma-prm`,
    /// `rrt-connect`, `prm-star`, `lazy-prm`, `rrt-star`, `prm-valid`).
    pub const fn name(self) -> &'static str {
        match self {
            PlannerKind::Rrt => "rrt",
            PlannerKind::MaRrt => "ma-rrt",
            PlannerKind::EvasionRrt => "evasion-rrt",
            PlannerKind::Prm => "prm",
            PlannerKind::MaPrm => "ma-prm",
            PlannerKind::RrtConnect => "rrt-connect",
            PlannerKind::PrmStar => "prm-star",
            PlannerKind::LazyPrm => "lazy-prm",
            PlannerKind::RrtStar => "rrt-star",
            PlannerKind::PrmValid => "prm-valid",
        }
    }

    /// One line for help texts.
    pub const fn description(self) -> &'static str {
        match self {
            PlannerKind::Rrt => "Rapidly-exploring random tree (thesis Algorithm 13)",
            PlannerKind::MaRrt => {
                "Medial-axis RRT (thesis §5.5.2): needs proximity queries (a patch map)"
            }
            PlannerKind::EvasionRrt => {
                "Evasion RRT (thesis Algorithm 11, repaired): needs specific step hits (a patch map)"
            }
            PlannerKind::Prm => {
                "Probabilistic roadmap (thesis Algorithm 14), six nearest neighbours"
            }
            PlannerKind::MaPrm => {
                "Medial-axis PRM (thesis Algorithm 12): needs proximity queries (a patch map)"
            }
            PlannerKind::RrtConnect => {
                "RRT-Connect (Kuffner and LaValle 2000), one goal tree per goal joined to the \
                 start tree"
            }
            PlannerKind::PrmStar => {
                "PRM* (Karaman and Frazzoli 2011): ⌈e(1 + 1/3) ln n⌉ nearest neighbours, cycles \
                 kept"
            }
            PlannerKind::LazyPrm => {
                "Lazy PRM (Bohlin and Kavraki 2000): six nearest neighbours, edges checked only \
                 when a shortest path uses them"
            }
            PlannerKind::RrtStar => {
                "RRT* (Karaman and Frazzoli 2011): ⌈2e ln n⌉ nearest candidates for parent and \
                 rewiring"
            }
            PlannerKind::PrmValid => {
                "PRM on valid samples with cycles: Algorithm 14 with each sample checked before \
                 it is added and edges to all six neighbours (as OMPL's PRM); not in the thesis"
            }
        }
    }

    /// The capability beyond step tests this planner needs, if any: the one place that decides
    /// what a map must offer a planner.
    pub const fn needs(self) -> Option<MapCapability> {
        match self {
            PlannerKind::EvasionRrt => Some(MapCapability::SpecificHits),
            PlannerKind::MaRrt | PlannerKind::MaPrm => Some(MapCapability::Proximity),
            PlannerKind::Rrt
            | PlannerKind::Prm
            | PlannerKind::PrmStar
            | PlannerKind::LazyPrm
            | PlannerKind::RrtStar
            | PlannerKind::PrmValid
            | PlannerKind::RrtConnect => None,
        }
    }

    /// Whether `map` offers what this planner [`needs`](Self::needs).
    pub fn runs_on<M: MaybePatchMap + ?Sized>(self, map: &M) -> bool {
        self.needs().is_none_or(|capability| capability.offered_by(map))
    }
}

impl MapCapability {
    /// Whether `map` offers this capability: a map that holds patches offers both
    /// ([`MaybePatchMap::with_patch_map`] runs its visitor on a map with every capability).
    pub fn offered_by<M: MaybePatchMap + ?Sized>(self, map: &M) -> bool {
        map.with_patch_map(Offers).is_ok()
    }
}

/// The visitor of [`MapCapability::offered_by`]: it only has to run.
struct Offers;

impl<'m> PatchMapVisitor<'m> for Offers {
    type Output = ();

    fn visit<M>(self, _map: &'m M) -> Self::Output
    where
        M: ProximityQuery + SpecificStepIntersector,
    {
    }
}

impl fmt::Display for MapCapability {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            MapCapability::SpecificHits => "specific step hits",
            MapCapability::Proximity => "proximity queries",
        })
    }
}

impl fmt::Display for PlannerKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for PlannerKind {
    type Err = NamedPlannerError;

    fn from_str(name: &str) -> Result<PlannerKind, NamedPlannerError> {
        PlannerKind::ALL
            .into_iter()
            .find(|k| k.name() == name)
            .ok_or_else(|| NamedPlannerError::Unknown { name: name.to_owned() })
    }
}

/// PRM with the thesis's six neighbours and the direct goal step.
fn prm_config() -> PrmConfig {
    PrmConfig { goal_step: GoalStep::Direct, ..PrmConfig::thesis() }
}

/// The planner `kind` on any map that tests steps.
///
/// # Errors
/// [`NamedPlannerError::NeedsCapability`] for the Evasion RRT and the medial-axis planners.
pub fn named_planner<'m, M>(
    kind: PlannerKind,
    map: &'m M,
    space: PlanningSpace,
    seed: u64,
) -> Result<Box<dyn Planner + 'm>, NamedPlannerError>
where
    M: UnspecificStepIntersector + ?Sized,
{
    step_test_planner(kind, map, space, seed)
        .map_err(|capability| NamedPlannerError::NeedsCapability { planner: kind, capability })
}

/// The planner `kind` on a map with every capability (a patch map); the planners that need no
/// more than step tests are the same as [`named_planner`]'s.
pub fn named_patch_planner<'m, M>(
    kind: PlannerKind,
    map: &'m M,
    space: PlanningSpace,
    seed: u64,
) -> Box<dyn Planner + 'm>
where
    M: ProximityQuery + SpecificStepIntersector + ?Sized,
{
    match step_test_planner(kind, map, space, seed) {
        Ok(planner) => planner,
        Err(MapCapability::SpecificHits) => {
            let config = EvasionRrtConfig {
                rrt: RrtConfig::lesum(None),
                ..EvasionRrtConfig::for_space(&space)
            };
            Box::new(EvasionRrt::new(map, space, config, seed))
        }
        Err(MapCapability::Proximity) if kind == PlannerKind::MaPrm => {
            let config = MaPrmConfig { prm: prm_config(), ..MaPrmConfig::for_space(&space) };
            Box::new(MaPrm::new(map, space, config, seed))
        }
        Err(MapCapability::Proximity) => {
            let config =
                MaRrtConfig { rrt: RrtConfig::lesum(None), ..MaRrtConfig::for_space(&space) };
            Box::new(MaRrt::new(map, space, config, seed))
        }
    }
}

/// The planner `kind` on a map whose backend is chosen at run time (`patch_map::AnyMap`):
/// the planners that need only step tests on the map as it is ([`named_planner`]), the others
/// on the concrete patch map it holds ([`named_patch_planner`]).
///
/// # Errors
/// [`NamedPlannerError::BackendLacks`] when `kind` needs proximity queries or specific hits and
/// the map holds no patches (a point-cloud map, thesis Table 5.2).
pub fn named_planner_on<'m, M>(
    kind: PlannerKind,
    map: &'m M,
    space: PlanningSpace,
    seed: u64,
) -> Result<Box<dyn Planner + 'm>, NamedPlannerError>
where
    M: MaybePatchMap + UnspecificStepIntersector + ?Sized,
{
    let Some(capability) = kind.needs() else {
        return named_planner(kind, map, space, seed);
    };
    map.with_patch_map(PatchPlanner { kind, space, seed }).map_err(|_| {
        NamedPlannerError::BackendLacks { planner: kind, capability, backend: map.backend_name() }
    })
}

/// [`named_patch_planner`] as a [`PatchMapVisitor`].
struct PatchPlanner {
    kind: PlannerKind,
    space: PlanningSpace,
    seed: u64,
}

impl<'m> PatchMapVisitor<'m> for PatchPlanner {
    type Output = Box<dyn Planner + 'm>;

    fn visit<M>(self, map: &'m M) -> Self::Output
    where
        M: ProximityQuery + SpecificStepIntersector,
    {
        named_patch_planner(self.kind, map, self.space, self.seed)
    }
}

/// The planner `kind` if step tests suffice for it, else the capability it needs.
fn step_test_planner<'m, M>(
    kind: PlannerKind,
    map: &'m M,
    space: PlanningSpace,
    seed: u64,
) -> Result<Box<dyn Planner + 'm>, MapCapability>
where
    M: UnspecificStepIntersector + ?Sized,
{
    Ok(match kind {
        PlannerKind::Rrt => Box::new(Rrt::new(map, space, RrtConfig::lesum(None), seed)),
        PlannerKind::Prm => Box::new(Prm::new(map, space, prm_config(), seed)),
        PlannerKind::PrmStar => {
            let config = PrmConfig { goal_step: GoalStep::Direct, ..PrmConfig::star() };
            Box::new(Prm::new(map, space, config, seed))
        }
        PlannerKind::LazyPrm => Box::new(Prm::lazy(map, space, prm_config(), seed)),
        PlannerKind::PrmValid => {
            let config = PrmConfig { goal_step: GoalStep::Direct, ..PrmConfig::valid() };
            Box::new(Prm::new(map, space, config, seed))
        }
        PlannerKind::RrtStar => {
            let config = RrtStarConfig { rrt: RrtConfig::lesum(None), ..RrtStarConfig::standard() };
            Box::new(RrtStar::new(map, space, config, seed))
        }
        PlannerKind::RrtConnect => Box::new(RrtConnect::new(map, space, seed)),
        PlannerKind::EvasionRrt => return Err(MapCapability::SpecificHits),
        PlannerKind::MaRrt | PlannerKind::MaPrm => return Err(MapCapability::Proximity),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{AnyOf, Goal, GoalReached, MaxIterations, PlannerStatus, Problem};
    use patch_core::{Aabb, BruteForceMap, Point3};
    use patch_core::{MaybePatchMap, PatchMapVisitor};

    fn space() -> PlanningSpace {
        PlanningSpace::new(Aabb::new(Point3::origin(), Point3::new(4.0, 4.0, 2.0)), 0.2, 0.5)
            .unwrap()
    }

    #[test]
    fn names_round_trip_and_unknown_names_are_refused() {
        for kind in PlannerKind::ALL {
            assert_eq!(kind.name().parse::<PlannerKind>(), Ok(kind));
            assert_eq!(kind.to_string(), kind.name());
        }
        let e = "rrt-sharp".parse::<PlannerKind>().unwrap_err();
        assert!(e.to_string().contains("rrt-sharp") && e.to_string().contains("lazy-prm"));
    }

    #[test]
    fn every_name_round_trips_and_unknown_names_list_all_of_them() {
        let mut names: Vec<&str> = PlannerKind::ALL.iter().map(|k| k.name()).collect();
        for kind in PlannerKind::ALL {
            assert_eq!(kind.to_string().parse::<PlannerKind>(), Ok(kind));
            let d = kind.description();
            assert!(!d.is_empty() && !d.contains('\n') && !d.contains("  "), "{kind}: {d}");
            // The help text states the need that `needs` decides.
            assert_eq!(d.contains("needs"), kind.needs().is_some(), "{kind}: {d}");
        }
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), PlannerKind::ALL.len(), "names are distinct");
        for bad in ["", "RRT", "rrt ", "astar", "prm_star"] {
            match bad.parse::<PlannerKind>() {
                Err(e @ NamedPlannerError::Unknown { .. }) => {
                    let text = e.to_string();
                    assert!(text.contains(&format!("`{bad}`")), "{text}");
                    assert!(PlannerKind::ALL.iter().all(|k| text.contains(k.name())), "{text}");
                }
                other => panic!("{bad:?}: {other:?}"),
            }
        }
    }

    #[test]
    fn needy_planners_are_refused_on_plain_maps_and_all_solve_on_patch_maps() {
        let map = BruteForceMap::new();
        let problem = Problem {
            start: Point3::new(0.5, 0.5, 1.0),
            goals: vec![Goal { center: Point3::new(3.5, 3.5, 1.0), tolerance: 0.3 }],
        };
        for kind in PlannerKind::ALL {
            match named_planner(kind, &map, space(), 3) {
                Ok(_) => assert!(kind.needs().is_none(), "{kind}"),
                Err(NamedPlannerError::NeedsCapability { planner, capability }) => {
                    assert_eq!((planner, Some(capability)), (kind, kind.needs()));
                }
                Err(e) => panic!("{kind}: {e}"),
            }
            let mut planner = named_patch_planner(kind, &map, space(), 3);
            let status = planner.solve(&problem, &mut AnyOf(GoalReached, MaxIterations(5_000)));
            assert_eq!(status, PlannerStatus::Exact, "{kind} in free space");
        }
    }

    /// A run-time map: patches (every capability) or "points" (step tests only).
    enum RunTimeMap {
        Patches(BruteForceMap),
        Points(BruteForceMap),
    }

    impl UnspecificStepIntersector for RunTimeMap {
        fn is_step_free(&self, step: &patch_core::CapsuleStep) -> bool {
            match self {
                RunTimeMap::Patches(m) | RunTimeMap::Points(m) => m.is_step_free(step),
            }
        }
    }

    impl MaybePatchMap for RunTimeMap {
        fn with_patch_map<'m, V: PatchMapVisitor<'m>>(&'m self, v: V) -> Result<V::Output, V> {
            match self {
                RunTimeMap::Patches(m) => Ok(v.visit(m)),
                RunTimeMap::Points(_) => Err(v),
            }
        }

        fn backend_name(&self) -> &'static str {
            match self {
                RunTimeMap::Patches(_) => "patches",
                RunTimeMap::Points(_) => "points",
            }
        }
    }

    #[test]
    fn run_time_maps_build_every_planner_they_can_and_name_the_backend_otherwise() {
        let patches = RunTimeMap::Patches(BruteForceMap::new());
        let points = RunTimeMap::Points(BruteForceMap::new());
        for kind in PlannerKind::ALL {
            let planner = named_planner_on(kind, &patches, space(), 3).expect("patch map");
            let expected = if kind == PlannerKind::LazyPrm { "lazy-prm" } else { kind.name() };
            assert_eq!(planner.name(), expected);
            match (named_planner_on(kind, &points, space(), 3), kind.needs()) {
                (Ok(_), None) => {}
                (
                    Err(NamedPlannerError::BackendLacks { planner, capability, backend }),
                    Some(needs),
                ) => {
                    assert_eq!((planner, capability, backend), (kind, needs, "points"));
                    let text =
                        named_planner_on(kind, &points, space(), 3).err().unwrap().to_string();
                    assert!(text.contains(kind.name()) && text.contains("`points`"), "{text}");
                }
                (other, needs) => panic!("{kind}: {:?} with needs {needs:?}", other.err()),
            }
            assert!(kind.runs_on(&patches), "{kind}");
            assert_eq!(kind.runs_on(&points), kind.needs().is_none(), "{kind}");
        }
        for capability in [MapCapability::SpecificHits, MapCapability::Proximity] {
            assert!(capability.offered_by(&patches) && !capability.offered_by(&points));
        }
    }
}
