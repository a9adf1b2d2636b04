//! Patches, steps and the capability traits of patch maps: the vocabulary that map backends
//! (`patch-map`) implement and roadmap planners (`roadmap`) are generic over.
//!
//! The thesis this workspace implements (Poppinga 2010, "Towards Autonomous Navigation for
//! Robots with 3D Sensors") represents the environment by *patches* (Chapter 5) and plans
//! through a few collision queries on a map of them (§5.4.1). This crate holds exactly that
//! interface, a brute-force reference map, and (feature `conformance`) the test suite every
//! backend runs against the reference.
//!
//! # Patches (§5.1)
//! * A [`PlanarPatch`] is a [`Polygon`] (outer ring and holes) in the xy-plane of its own
//!   frame, plus the rigid transform `world_from_patch` that places the frame in the world:
//!   the thesis's "2D vertices plus one full transform", chosen over a canonical `(n, d)` plane
//!   because canonical in-plane axes are discontinuous and because 2D polygon operations then
//!   stay 2D. The plane normal and offset are derived from the transform
//!   ([`PlanarPatch::normal`], [`PlanarPatch::offset`]). An optional [`PlaneCovariance`]
//!   carries the fit's uncertainty.
//! * A [`TrimeshPatch`] is a triangle mesh: the non-planar part of hybrid maps and the whole of
//!   trimesh maps.
//! * [`Patch`] is either. Constructors validate (simple rings, holes strictly inside, finite
//!   coordinates, no zero-area polygons or triangles) and deserialisation re-validates, so a
//!   file cannot smuggle an invalid patch in.
//!
//! # Capabilities (§5.4.1)
//! Each thesis interface is one small trait with one required method ([`capability`] has the
//! contracts):
//!
//! | trait | required method | thesis interface |
//! |---|---|---|
//! | [`PatchMap`] | [`patches`](PatchMap::patches), [`bounds`](PatchMap::bounds) | PatchMapInterface |
//! | [`PatchMapMut`], [`FromPatches`] | [`add_patch`](PatchMapMut::add_patch), [`from_patches`](FromPatches::from_patches) | PatchMapInterface (adding) |
//! | [`ProximityQuery`] | [`closest_patch`](ProximityQuery::closest_patch) | ProximityQueryPatchMap |
//! | [`UnspecificStepIntersector<S>`] | [`is_step_free`](UnspecificStepIntersector::is_step_free) | Unspecific{Line,Capsule}Intersector |
//! | [`SpecificStepIntersector<S>`] | [`first_hit`](SpecificStepIntersector::first_hit) | Specific{Line,Capsule}Intersector |
//!
//! The step `S` is a [`LineStep`] (radius 0) or a [`CapsuleStep`] (a sphere swept along a
//! segment). Planners ask only for what they use (thesis Table 5.2, as reconstructed in the
//! spec):
//!
//! | planner | proximity | specific step | unspecific step |
//! |---|---|---|---|
//! | RRT, PRM | – | – | ✓ |
//! | Evasion RRT | – | ✓ | – |
//! | MA RRT, MA PRM | ✓ | – | ✓ |
//!
//! and the backends of `patch-map` offer (thesis §5.4.2, with capsules added where the thesis
//! used only Bullet for them; `patch-map`'s crate docs pin the table with compile-time tests):
//!
//! | backend | proximity | specific | unspecific | line | capsule |
//! |---|---|---|---|---|---|
//! | [`BruteForceMap`] (reference) | ✓ | ✓ | ✓ | ✓ | ✓ |
//! | native polygon map | ✓ | ✓ | ✓ | ✓ | ✓ |
//! | 6D bounding-box kD-tree | ✓ | ✓ | ✓ | ✓ | ✓ |
//! | parry trimesh map, rapier collider set | ✓ | ✓ | ✓ | ✓ | ✓ |
//! | point-cloud kD-tree (Alg. 10; lines as capsules of radius 0) | – | – | ✓ | ✓ | ✓ |
//!
//! [`PatchId`]s are insertion indices, the same in every backend, so answers can be compared
//! across backends. [`Counted`] wraps any map and counts its queries.
//!
//! # Contracts and tolerance
//! A step collides iff some point of its segment is within its radius of some patch (touching
//! counts; zero-length steps are sphere tests; every input has an answer, no "start must be
//! free" precondition). A backend declares a [`Tolerance`] `(numeric ε, conservative δ)`:
//! it may never call a step free whose exact distance `d` is `≤ r − ε` (a colliding step is
//! never reported free), and may call it colliding only if `d ≤ r + δ + ε`. Exact backends
//! have `δ = 0`. The full statements, including those for `first_hit` and proximity, are in
//! [`capability`].
//!
//! # Kernels
//! [`geometry`] has the exact-as-floats narrow phase (point–region, segment–region and
//! sphere-sweep–region in a patch's local frame, and their triangle versions), documented with
//! their methods and degenerate cases, for backends to reuse.
//!
//! # Example
//! ```
//! use patch_core::{
//!     BruteForceMap, CapsuleStep, FromPatches, Isometry3, PatchMap, PlanarPatch, Point2,
//!     Point3, ProximityQuery, SpecificStepIntersector, UnspecificStepIntersector, Vector3,
//! };
//!
//! // A 4 m × 3 m floor at z = 0 and a wall at x = 2 facing -x.
//! let floor = PlanarPatch::rectangle(
//!     Isometry3::identity(),
//!     Point2::new(0.0, 0.0),
//!     Point2::new(4.0, 3.0),
//! )?;
//! let wall = PlanarPatch::from_world_polygon(
//!     &[
//!         Point3::new(2.0, 0.0, 0.0),
//!         Point3::new(2.0, 0.0, 2.0),
//!         Point3::new(2.0, 3.0, 2.0),
//!         Point3::new(2.0, 3.0, 0.0),
//!     ],
//!     &[],
//!     1e-9,
//! )?;
//! assert!((wall.normal().into_inner() - Vector3::new(-1.0, 0.0, 0.0)).norm() < 1e-12);
//! let map = BruteForceMap::from_patches([floor.into(), wall.into()])?;
//! assert_eq!(map.len(), 2);
//!
//! // A robot of radius 0.25 m flying at 1 m height toward the wall.
//! let step = CapsuleStep::new(Point3::new(0.5, 1.5, 1.0), Point3::new(3.5, 1.5, 1.0), 0.25)?;
//! assert!(!map.is_step_free(&step));
//! let hit = map.first_hit(&step).unwrap();
//! assert_eq!(hit.patch.0, 1);
//! assert!((hit.t - 1.25 / 3.0).abs() < 1e-12); // centre at x = 1.75, touching x = 2
//! assert!((hit.normal.into_inner() - Vector3::new(-1.0, 0.0, 0.0)).norm() < 1e-12);
//! assert!((map.clearance(&Point3::new(1.0, 1.5, 0.5), 10.0) - 0.5).abs() < 1e-12);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub use patch_math::na;

pub mod capability;
#[cfg(feature = "conformance")]
pub mod conformance;
mod counted;
mod error;
pub mod geometry;
mod patch;
mod polygon;
mod reference;
mod step;
pub mod triangulate;

pub use capability::{
    FromPatches, MaybePatchMap, PatchId, PatchMap, PatchMapMut, PatchMapVisitor, Proximity,
    ProximityQuery, SpecificStepIntersector, StepHit, Tolerance, UnspecificStepIntersector,
    is_step_free_via_first_hit,
};
pub use counted::{Counted, QueryCounts};
pub use error::{MapError, PatchError, StepError};
pub use patch::{
    MIN_TRIANGLE_AREA, Patch, PatchKind, PlanarPatch, Plane, PlaneCovariance, TrimeshPatch,
    plane_frame,
};
pub use patch_math::{Aabb, Isometry3, Point3, Real, Vector3};
pub use polygon::{Bounds2, Polygon, Ring, RingId};
pub use reference::{BruteForceMap, StepDistance};
pub use step::{CapsuleStep, LineStep, Step};

/// A point in a patch's plane (patch-frame coordinates).
pub type Point2 = na::Point2<Real>;
/// A unit vector in 3D (normals).
pub type UnitVector3 = na::Unit<Vector3>;
