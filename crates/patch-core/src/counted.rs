//! An adaptor that counts queries: the collision-check counters of the planners (thesis
//! Fig. 6.9 counts collision checks per iteration; OMPL's motion validator counts valid and
//! invalid checks).

use std::cell::Cell;

use serde::{Deserialize, Serialize};

use crate::capability::{
    FromPatches, PatchId, PatchMap, PatchMapMut, ProximityQuery, SpecificStepIntersector, StepHit,
    UnspecificStepIntersector,
};
use crate::step::Step;
use crate::{Aabb, MapError, Patch, Point3, Proximity, Real};

/// How many queries of each kind a [`Counted`] map has answered.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct QueryCounts {
    /// Calls of [`ProximityQuery::closest_patch`].
    pub closest_patch: u64,
    /// Calls of [`ProximityQuery::clearance`].
    pub clearance: u64,
    /// Calls of [`UnspecificStepIntersector::is_step_free`] (all step types), of which
    pub is_step_free: u64,
    /// … how many answered "free".
    pub free_steps: u64,
    /// Calls of [`SpecificStepIntersector::first_hit`] (all step types).
    pub first_hit: u64,
}

impl QueryCounts {
    /// All step checks: `is_step_free + first_hit`.
    pub fn step_checks(&self) -> u64 {
        self.is_step_free + self.first_hit
    }
}

/// Wraps a map and counts the queries it answers; forwards every capability the inner map
/// has (a decorator, like petgraph's `NodeFiltered`).
///
/// Counts live in a [`Cell`], so queries keep taking `&self`; the adaptor is therefore not
/// `Sync` (planners run single-threaded). Only the outermost call counts: a default method
/// of the inner map calling another query is not counted twice, because the adaptor forwards
/// each method to the inner map's own implementation.
#[derive(Debug, Clone)]
pub struct Counted<M> {
    inner: M,
    counts: Cell<QueryCounts>,
}

impl<M> Counted<M> {
    /// Wraps `inner` with all counts at zero.
    pub fn new(inner: M) -> Counted<M> {
        Counted { inner, counts: Cell::new(QueryCounts::default()) }
    }

    /// The counts so far.
    pub fn counts(&self) -> QueryCounts {
        self.counts.get()
    }

    /// Sets all counts to zero.
    pub fn reset_counts(&self) {
        self.counts.set(QueryCounts::default());
    }

    /// The wrapped map.
    pub fn inner(&self) -> &M {
        &self.inner
    }

    /// Unwraps the map.
    pub fn into_inner(self) -> M {
        self.inner
    }

    fn bump(&self, f: impl FnOnce(&mut QueryCounts)) {
        let mut c = self.counts.get();
        f(&mut c);
        self.counts.set(c);
    }
}

impl<M: PatchMap> PatchMap for Counted<M> {
    fn patches(&self) -> &[Patch] {
        self.inner.patches()
    }
    fn bounds(&self) -> Aabb {
        self.inner.bounds()
    }
    fn tolerance(&self) -> crate::Tolerance {
        self.inner.tolerance()
    }
    fn patch(&self, id: PatchId) -> Option<&Patch> {
        self.inner.patch(id)
    }
    fn len(&self) -> usize {
        self.inner.len()
    }
    fn is_empty(&self) -> bool {
        self.inner.is_empty()
    }
}

impl<M: PatchMapMut> PatchMapMut for Counted<M> {
    fn add_patch(&mut self, patch: Patch) -> Result<PatchId, MapError> {
        self.inner.add_patch(patch)
    }
}

impl<M: FromPatches> FromPatches for Counted<M> {
    type Error = M::Error;
    fn from_patches(patches: impl IntoIterator<Item = Patch>) -> Result<Self, Self::Error> {
        M::from_patches(patches).map(Counted::new)
    }
}

impl<M: ProximityQuery> ProximityQuery for Counted<M> {
    fn closest_patch(&self, point: &Point3, max_dist: Real) -> Option<Proximity> {
        self.bump(|c| c.closest_patch += 1);
        self.inner.closest_patch(point, max_dist)
    }
    fn clearance(&self, point: &Point3, max_dist: Real) -> Real {
        self.bump(|c| c.clearance += 1);
        self.inner.clearance(point, max_dist)
    }
}

impl<M: UnspecificStepIntersector<S>, S: Step> UnspecificStepIntersector<S> for Counted<M> {
    fn is_step_free(&self, step: &S) -> bool {
        let free = self.inner.is_step_free(step);
        self.bump(|c| {
            c.is_step_free += 1;
            c.free_steps += u64::from(free);
        });
        free
    }
}

impl<M: SpecificStepIntersector<S>, S: Step> SpecificStepIntersector<S> for Counted<M> {
    fn first_hit(&self, step: &S) -> Option<StepHit> {
        self.bump(|c| c.first_hit += 1);
        self.inner.first_hit(step)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{BruteForceMap, CapsuleStep, Isometry3, LineStep, PlanarPatch, Point2};

    #[test]
    fn counts_each_query_kind_once() {
        let floor = PlanarPatch::rectangle(
            Isometry3::identity(),
            Point2::new(0.0, 0.0),
            Point2::new(1.0, 1.0),
        )
        .unwrap();
        let mut map = Counted::new(BruteForceMap::new());
        assert_eq!(map.add_patch(floor.into()), Ok(PatchId(0)));
        let free =
            CapsuleStep::new(Point3::new(0.5, 0.5, 1.0), Point3::new(0.5, 0.5, 2.0), 0.1).unwrap();
        let blocked =
            LineStep::new(Point3::new(0.5, 0.5, 1.0), Point3::new(0.5, 0.5, -1.0)).unwrap();
        assert!(map.is_step_free(&free));
        assert!(!map.is_step_free(&blocked));
        assert!(map.first_hit(&blocked).is_some());
        assert_eq!(map.clearance(&Point3::new(0.5, 0.5, 2.0), 10.0), 2.0);
        assert!(map.closest_patch(&Point3::new(0.5, 0.5, 2.0), 1.0).is_none());
        let c = map.counts();
        assert_eq!(
            c,
            QueryCounts {
                closest_patch: 1,
                clearance: 1,
                is_step_free: 2,
                free_steps: 1,
                first_hit: 1
            }
        );
        assert_eq!(c.step_checks(), 3);
        assert_eq!(map.len(), 1);
        assert_eq!(map.bounds(), map.inner().bounds());
        map.reset_counts();
        assert_eq!(map.counts(), QueryCounts::default());
        assert_eq!(map.into_inner().len(), 1);
    }
}
