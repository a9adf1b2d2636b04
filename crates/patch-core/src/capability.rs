//! The capability traits of a patch map (thesis §5.4.1) and their result types.
//!
//! | trait | thesis interface | question |
//! |---|---|---|
//! | [`PatchMap`] | PatchMapInterface (read side) | which patches, which bounds? |
//! | [`PatchMapMut`] | PatchMapInterface (add patches) | add one patch |
//! | [`FromPatches`] | — | build a map from patches at once |
//! | [`ProximityQuery`] | ProximityQueryPatchMap | which patch is closest to a point, and where? |
//! | [`UnspecificStepIntersector<S>`] | Unspecific{Line,Capsule}Intersector | is this step free? |
//! | [`SpecificStepIntersector<S>`] | Specific{Line,Capsule}Intersector | where does it first hit what? |
//!
//! The step type `S` is [`LineStep`](crate::LineStep) (the line intersectors) or
//! [`CapsuleStep`] (the capsule intersectors); a backend implements the
//! step intersectors for the step types it supports.
//!
//! # The collision contract
//! A step collides with a map iff
//!
//! ```text
//! min over t ∈ [0, 1] of dist(step.point_at(t), patches) ≤ step.radius()
//! ```
//!
//! where `dist` is the Euclidean distance to the nearest point of any patch region (a planar
//! patch is its closed polygon with holes, a trimesh patch the union of its closed triangles).
//! Touching counts as collision; a zero-length step is a sphere test; a step of radius 0 is a
//! segment test. Every input has a defined answer: steps may start, end or lie inside or on a
//! patch, run along a plane, or have zero length. (OMPL's motion validator *assumes* a valid
//! start; these traits do not.)
//!
//! A backend declares a [`Tolerance`]. With `ε = tolerance.numeric` and
//! `δ = tolerance.conservative`, writing `d` for the exact minimum distance above and `r` for
//! the radius:
//!
//! * `is_step_free(s) == true` only if `d > r − ε`: **a colliding step is never reported free**
//!   (beyond float rounding `ε`);
//! * `is_step_free(s) == false` only if `d ≤ r + δ + ε`: false alarms are allowed only within
//!   the declared conservative margin `δ` (0 for exact backends);
//! * `first_hit(s)` is `None` under the same conditions as `is_step_free(s) == true`, and the
//!   two agree whenever `d` is outside the ambiguous band `[r − ε, r + δ + ε]` (exact backends
//!   derive one from the other and agree always);
//! * a hit at `t` means: the sphere at `t` is within `r + δ + ε` of the hit patch, and the
//!   part of the step before `t` stays farther than `r − ε` from every patch (so `t` is the
//!   first contact up to tolerance; with `t = 0` the start touches).
//!
//! [`BruteForceMap`](crate::BruteForceMap) is exact (`δ = 0`, `ε` = rounding of a few ulps).
//! The conformance suite (feature `conformance`) checks these statements for any backend
//! against it.

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::step::{CapsuleStep, Step};
use crate::{Aabb, MapError, Patch, Point3, Real, UnitVector3};

/// The identity of a patch in a map: its insertion index, dense from 0.
///
/// Every backend numbers patches the same way (the order of [`FromPatches::from_patches`] or
/// of [`PatchMapMut::add_patch`] calls), so results can be compared across backends.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct PatchId(pub u32);

impl PatchId {
    /// The id as an index into [`PatchMap::patches`].
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

impl fmt::Display for PatchId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "patch {}", self.0)
    }
}

/// How far a backend's answers may be from the exact ones (see the module docs for the
/// precise statements).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tolerance {
    /// Float rounding allowed in both directions, in metres.
    pub numeric: Real,
    /// Extra distance within which a free step may be reported as colliding (and clearance
    /// may be underestimated), in metres. 0 for exact backends.
    pub conservative: Real,
}

impl Tolerance {
    /// An exact backend: only float rounding (1e-9 m, generous for scenes of tens of metres
    /// where f64 rounding is about 1e-14 m).
    pub const EXACT: Tolerance = Tolerance { numeric: 1e-9, conservative: 0.0 };

    /// A conservative backend that may report collisions up to `margin` metres early.
    pub fn conservative(margin: Real) -> Tolerance {
        Tolerance { numeric: Tolerance::EXACT.numeric, conservative: margin }
    }
}

/// Read access to the patches of a map (thesis PatchMapInterface).
///
/// # Complexity
/// `patches`, `patch`, `len` are O(1); `bounds` should be O(1) (cached).
pub trait PatchMap {
    /// All patches, indexed by [`PatchId`].
    fn patches(&self) -> &[Patch];

    /// The box of all patches ([`Aabb::EMPTY`] for an empty map).
    fn bounds(&self) -> Aabb;

    /// The tolerance within which this backend's answers hold (the module docs state what it
    /// bounds); the conformance suite checks the backend against it.
    fn tolerance(&self) -> Tolerance;

    /// The patch with this id, if any.
    fn patch(&self, id: PatchId) -> Option<&Patch> {
        self.patches().get(id.index())
    }

    /// The number of patches.
    fn len(&self) -> usize {
        self.patches().len()
    }

    /// Whether the map holds no patch.
    fn is_empty(&self) -> bool {
        self.patches().is_empty()
    }
}

/// Adding patches one by one (thesis PatchMapInterface, "add patches").
pub trait PatchMapMut: PatchMap {
    /// Adds a patch and returns its id, the previous [`PatchMap::len`].
    ///
    /// # Errors
    /// [`MapError::Unsupported`] if the backend does not store this kind of patch;
    /// [`MapError::TooManyPatches`] past `u32::MAX` patches. The map is unchanged on error.
    fn add_patch(&mut self, patch: Patch) -> Result<PatchId, MapError>;
}

/// Building a map from patches at once (lets a backend build its acceleration structure in
/// one go). The patches get ids `0, 1, …` in iteration order.
pub trait FromPatches: Sized {
    /// Why the map could not be built (for example [`MapError`]).
    type Error: std::error::Error + Send + Sync + 'static;

    /// Builds the map.
    ///
    /// # Errors
    /// Backend-specific; typically a patch kind the backend does not store.
    fn from_patches(patches: impl IntoIterator<Item = Patch>) -> Result<Self, Self::Error>;
}

/// The patch closest to a point.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Proximity {
    /// The closest patch.
    pub patch: PatchId,
    /// The closest point on it.
    pub point: Point3,
    /// The Euclidean distance from the query point to `point` (0 on the patch).
    pub distance: Real,
}

/// Closest-patch queries (thesis ProximityQueryPatchMap; needed by the medial-axis planners,
/// Table 5.2).
///
/// The distance is the Euclidean point-to-region distance (spec §7.6; it equals the distance
/// along the plane normal when the point projects into a planar patch). Quality: exact up to
/// the backend's [`Tolerance`] (OMPL's `ClearanceComputationType::EXACT` for exact backends);
/// a conservative backend may underestimate distances by at most its margin.
pub trait ProximityQuery: PatchMap {
    /// The patch nearest to `point`, if its distance is at most `max_dist` (which may be
    /// `Real::INFINITY`). Ties go to any of the tied patches. `None` for an empty map, a
    /// negative or NaN `max_dist`, or a non-finite `point`.
    fn closest_patch(&self, point: &Point3, max_dist: Real) -> Option<Proximity>;

    /// The clearance of `point`: the distance to the nearest patch, capped at `max_dist`.
    /// Returns 0 for a non-finite `point` (clearance is never overstated).
    fn clearance(&self, point: &Point3, max_dist: Real) -> Real {
        if !point.iter().all(|c| c.is_finite()) {
            return 0.0;
        }
        self.closest_patch(point, max_dist).map_or(max_dist, |p| p.distance)
    }
}

/// "Is this step free?" (thesis Unspecific{Line,Capsule}Intersector; enough for RRT and PRM,
/// Table 5.2).
///
/// See the [module docs](self) for the contract: never reports a colliding step as free; may
/// report a free step as colliding only within the backend's conservative margin. The step
/// type defaults to [`CapsuleStep`], the robot's motion the planners test.
pub trait UnspecificStepIntersector<S: Step = CapsuleStep> {
    /// Whether no patch comes within the step's radius of its segment.
    fn is_step_free(&self, step: &S) -> bool;
}

/// The first contact of a step (thesis Specific{Line,Capsule}Intersector: the colliding patch
/// and the collision point; needed by the Evasion RRT, Table 5.2).
///
/// Not every implementor of the unspecific query derives it from this one: a backend may have
/// a faster any-hit test (OMPL's motion validator bisects for the boolean and walks for the
/// first failure). Backends without one write the unspecific half with
/// [`is_step_free_via_first_hit`].
pub trait SpecificStepIntersector<S: Step = CapsuleStep>:
    UnspecificStepIntersector<S> + PatchMap
{
    /// The first contact along the step, or `None` if it is free (see the module docs for the
    /// tolerance statements).
    fn first_hit(&self, step: &S) -> Option<StepHit>;
}

/// An action on a map with every capability of a patch map, generic over its backend: what
/// [`MaybePatchMap::with_patch_map`] runs on the concrete map it holds. A trait, because a
/// closure cannot be generic over the map type.
///
/// Planners that need more than step tests (thesis Table 5.2: the Evasion RRT needs specific
/// hits, the medial-axis planners proximity queries) are built through it on a map whose
/// backend is known only at run time.
pub trait PatchMapVisitor<'m> {
    /// What the action gives.
    type Output;

    /// Runs the action on `map`.
    fn visit<M>(self, map: &'m M) -> Self::Output
    where
        M: ProximityQuery + SpecificStepIntersector<crate::CapsuleStep>;
}

/// A map whose backend is chosen at run time and may or may not be a patch map with every
/// capability (a point-cloud map is not: it answers neither proximity queries nor specific
/// hits, thesis Table 5.2).
pub trait MaybePatchMap {
    /// Runs `visitor` on the concrete patch map held, or gives it back unrun when this map has
    /// no patches (`Err(visitor)`).
    fn with_patch_map<'m, V: PatchMapVisitor<'m>>(&'m self, visitor: V) -> Result<V::Output, V>;

    /// The backend's name, for messages.
    fn backend_name(&self) -> &'static str;
}

/// Where a step first touches the map.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StepHit {
    /// The patch touched.
    pub patch: PatchId,
    /// The first parameter in `[0, 1]` at which the swept sphere touches (0 if the start
    /// already touches).
    pub t: Real,
    /// The contact point on the patch: its point closest to the sphere's centre at `t`.
    pub point: Point3,
    /// The patch's surface normal at the contact (the plane normal of a planar patch, the
    /// triangle normal of a trimesh patch), oriented toward the sphere's centre at `t`; if the
    /// centre lies in the plane (always for radius 0), toward the side the step starts on; if
    /// the start lies in the plane too, against the motion; if the whole step lies in the
    /// plane, the patch's own normal.
    pub normal: UnitVector3,
}

/// The unspecific query answered through the specific one: `first_hit(step).is_none()`.
pub fn is_step_free_via_first_hit<M, S>(map: &M, step: &S) -> bool
where
    M: SpecificStepIntersector<S> + ?Sized,
    S: Step,
{
    map.first_hit(step).is_none()
}

impl<M: PatchMap + ?Sized> PatchMap for &M {
    fn patches(&self) -> &[Patch] {
        (**self).patches()
    }
    fn bounds(&self) -> Aabb {
        (**self).bounds()
    }
    fn tolerance(&self) -> Tolerance {
        (**self).tolerance()
    }
    fn patch(&self, id: PatchId) -> Option<&Patch> {
        (**self).patch(id)
    }
    fn len(&self) -> usize {
        (**self).len()
    }
    fn is_empty(&self) -> bool {
        (**self).is_empty()
    }
}

impl<M: ProximityQuery + ?Sized> ProximityQuery for &M {
    fn closest_patch(&self, point: &Point3, max_dist: Real) -> Option<Proximity> {
        (**self).closest_patch(point, max_dist)
    }
    fn clearance(&self, point: &Point3, max_dist: Real) -> Real {
        (**self).clearance(point, max_dist)
    }
}

impl<M: UnspecificStepIntersector<S> + ?Sized, S: Step> UnspecificStepIntersector<S> for &M {
    fn is_step_free(&self, step: &S) -> bool {
        (**self).is_step_free(step)
    }
}

impl<M: SpecificStepIntersector<S> + ?Sized, S: Step> SpecificStepIntersector<S> for &M {
    fn first_hit(&self, step: &S) -> Option<StepHit> {
        (**self).first_hit(step)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{BruteForceMap, CapsuleStep, Counted, LineStep};

    fn full<M>()
    where
        M: PatchMap + ProximityQuery + SpecificStepIntersector<LineStep> + SpecificStepIntersector,
    {
    }
    fn mutable<M: PatchMapMut + FromPatches>() {}

    /// The capability matrix of this crate's maps, pinned at compile time.
    #[test]
    fn capability_matrix() {
        full::<BruteForceMap>();
        full::<&BruteForceMap>();
        full::<Counted<BruteForceMap>>();
        full::<Counted<&BruteForceMap>>();
        mutable::<BruteForceMap>();
        mutable::<Counted<BruteForceMap>>();
    }

    #[test]
    fn ids_and_tolerances() {
        assert_eq!(PatchId(7).index(), 7);
        assert_eq!(PatchId(7).to_string(), "patch 7");
        assert_eq!(Tolerance::conservative(0.01).conservative, 0.01);
        assert_eq!(Tolerance::conservative(0.01).numeric, Tolerance::EXACT.numeric);
    }

    #[test]
    fn empty_map_answers() {
        let map = BruteForceMap::new();
        let p = Point3::origin();
        assert!(map.is_empty() && map.bounds().is_empty());
        assert!(map.closest_patch(&p, Real::INFINITY).is_none());
        assert_eq!(map.clearance(&p, 3.0), 3.0);
        assert_eq!(map.clearance(&Point3::new(Real::NAN, 0.0, 0.0), 3.0), 0.0);
        let step = CapsuleStep::sphere(p, 1.0).unwrap();
        assert!(map.is_step_free(&step) && map.first_hit(&step).is_none());
        assert!(is_step_free_via_first_hit(&map, &step));
        assert!(map.step_distance(&step).is_none());
    }
}
