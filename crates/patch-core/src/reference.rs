//! The brute-force reference map: every capability, exactly, by looping over all patches.

use serde::{Deserialize, Serialize};

use crate::capability::{
    FromPatches, PatchId, PatchMap, PatchMapMut, ProximityQuery, SpecificStepIntersector, StepHit,
    UnspecificStepIntersector,
};
use crate::patch::earlier;
use crate::step::Step;
use crate::{Aabb, MapError, Patch, Point3, Proximity, Real};

/// The closest approach of a step's core segment to a map.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StepDistance {
    /// The nearest patch.
    pub patch: PatchId,
    /// The distance between the step's segment and that patch.
    pub distance: Real,
    /// A parameter along the step where the distance is attained.
    pub t: Real,
    /// The point of the patch where it is attained.
    pub point: Point3,
}

/// The reference implementation of every capability (the role of the thesis's
/// SimplePatchMap, §5.4.2, extended to trimesh patches and capsule steps).
///
/// No broad phase: every query runs the exact kernels of [`geometry`](crate::geometry) on
/// every patch. It is the oracle that the conformance suite checks backends against, and a
/// correct (if slow) map for small scenes.
///
/// # Complexity
/// With `P` patches of at most `n` edges or triangles each: every query is O(P·n) time and
/// O(1) extra space; [`add_patch`](PatchMapMut::add_patch) is amortised O(n) (the bounds are
/// grown).
///
/// Serialises as the list of its patches.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "Vec<Patch>", into = "Vec<Patch>")]
pub struct BruteForceMap {
    patches: Vec<Patch>,
    bounds: Aabb,
}

impl Default for BruteForceMap {
    fn default() -> Self {
        BruteForceMap::new()
    }
}

impl BruteForceMap {
    /// The empty map.
    pub fn new() -> BruteForceMap {
        BruteForceMap { patches: Vec::new(), bounds: Aabb::EMPTY }
    }

    /// Gives the patches back.
    pub fn into_patches(self) -> Vec<Patch> {
        self.patches
    }

    /// The closest approach of the step's core segment to the map (ignoring the radius), or
    /// `None` for an empty map. The step collides iff `distance ≤ step.radius()`. Ties go to
    /// the lowest id.
    pub fn step_distance<S: Step>(&self, step: &S) -> Option<StepDistance> {
        let (a, b) = (step.start(), step.end());
        let mut best: Option<StepDistance> = None;
        for (i, patch) in self.patches.iter().enumerate() {
            let s = patch.segment_distance(&a, &b);
            if best.is_none_or(|b| s.distance < b.distance) {
                best = Some(StepDistance {
                    patch: PatchId(i as u32),
                    distance: s.distance,
                    t: s.t,
                    point: s.point,
                });
            }
        }
        best
    }

    fn ids(&self) -> impl Iterator<Item = (PatchId, &Patch)> + '_ {
        self.patches.iter().enumerate().map(|(i, p)| (PatchId(i as u32), p))
    }
}

impl TryFrom<Vec<Patch>> for BruteForceMap {
    type Error = MapError;
    fn try_from(patches: Vec<Patch>) -> Result<Self, Self::Error> {
        BruteForceMap::from_patches(patches)
    }
}

impl From<BruteForceMap> for Vec<Patch> {
    fn from(map: BruteForceMap) -> Self {
        map.patches
    }
}

impl PatchMap for BruteForceMap {
    fn patches(&self) -> &[Patch] {
        &self.patches
    }

    fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// [`Tolerance::EXACT`](crate::Tolerance::EXACT): the reference's kernels are the exact
    /// ones the others are measured against.
    fn tolerance(&self) -> crate::Tolerance {
        crate::Tolerance::EXACT
    }
}

impl PatchMapMut for BruteForceMap {
    fn add_patch(&mut self, patch: Patch) -> Result<PatchId, MapError> {
        let id = u32::try_from(self.patches.len())
            .ok()
            .filter(|&i| i < u32::MAX)
            .ok_or(MapError::TooManyPatches)?;
        self.bounds = self.bounds.union(&patch.bounds());
        self.patches.push(patch);
        Ok(PatchId(id))
    }
}

impl FromPatches for BruteForceMap {
    type Error = MapError;

    fn from_patches(patches: impl IntoIterator<Item = Patch>) -> Result<Self, Self::Error> {
        let mut map = BruteForceMap::new();
        for patch in patches {
            map.add_patch(patch)?;
        }
        Ok(map)
    }
}

impl ProximityQuery for BruteForceMap {
    fn closest_patch(&self, point: &Point3, max_dist: Real) -> Option<Proximity> {
        if max_dist.is_nan() || max_dist < 0.0 || !point.iter().all(|c| c.is_finite()) {
            return None;
        }
        let mut best: Option<Proximity> = None;
        for (id, patch) in self.ids() {
            let c = patch.closest_point(point);
            if best.is_none_or(|b| c.distance < b.distance) {
                best = Some(Proximity { patch: id, point: c.point, distance: c.distance });
            }
        }
        best.filter(|b| b.distance <= max_dist)
    }
}

impl<S: Step> UnspecificStepIntersector<S> for BruteForceMap {
    fn is_step_free(&self, step: &S) -> bool {
        !self.patches.iter().any(|p| p.collides_with(step))
    }
}

/// The earliest contact over all patches; among patches touched at the same `t`, the one
/// nearest to the sphere's centre, then the lowest id.
impl<S: Step> SpecificStepIntersector<S> for BruteForceMap {
    fn first_hit(&self, step: &S) -> Option<StepHit> {
        let mut best: Option<(StepHit, Real)> = None;
        for (id, patch) in self.ids() {
            if let Some(c) = patch.step_contact(step) {
                let gap = (step.point_at(c.t) - c.point).norm_squared();
                if best.is_none_or(|(b, g)| earlier(c.t, gap, b.t, g)) {
                    let hit = StepHit { patch: id, t: c.t, point: c.point, normal: c.normal };
                    best = Some((hit, gap));
                }
            }
        }
        best.map(|(hit, _)| hit)
    }
}
