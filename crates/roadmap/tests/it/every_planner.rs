//! Every planner kind on every map backend (thesis Table 5.2): where the backend offers what
//! the planner needs, the planner grows a roadmap whose edges the exact map calls free (patch
//! backends) and the same one again for the same seed; where it does not, the planner is
//! refused with a typed error.

use crate::common::*;
use patch_core::PatchMap as _;
use patch_map::{AnyMap, Backend};
use roadmap::{PlannerKind, named_planner_on};

#[test]
fn every_planner_kind_runs_on_every_backend_that_offers_what_it_needs() {
    let exact = wall_with_door();
    let problem = across(0.3);
    for backend in Backend::ALL {
        let map = AnyMap::from_patches(backend, exact.patches().to_vec(), Some(0.05)).unwrap();
        for kind in PlannerKind::ALL {
            let roadmap_of = |seed| {
                let mut planner = named_planner_on(kind, &map, space(0.5), seed).ok()?;
                planner.solve(&problem, &mut until_solved(1_500));
                Some((planner.roadmap().clone(), planner))
            };
            let Some((first, planner)) = roadmap_of(7) else {
                assert!(!kind.runs_on(&map), "{kind} was refused on {backend}");
                assert!(!backend.holds_patches(), "a patch map offers every capability");
                continue;
            };
            assert!(kind.runs_on(&map), "{kind} ran on {backend}, which lacks what it needs");
            // (The medial-axis planners may grow nothing here: one wall has no medial axis.)
            let (again, _) = roadmap_of(7).unwrap();
            assert!(same_roadmap(&first, &again), "{kind} on {backend}: not deterministic");
            if backend.holds_patches() {
                // The point-cloud backend is exact for its points, not for the wall between
                // them, so only the patch backends are held to the exact map.
                assert_all_free(&exact, planner.as_ref(), 1);
            }
        }
    }
}
