//! The rapier map: one collider per patch in a rapier collider set with rapier's broad-phase
//! BVH (the thesis's BulletPatchMap set-up, §5.4.2 L5572–5582: every patch its own collision
//! object in the engine's world, the step a sphere cast).
//!
//! # Layout
//! * Every patch becomes one rapier [`Collider`] whose shape is a triangle mesh: a planar
//!   patch its constrained Delaunay triangulation, a trimesh patch its triangles. The shape is
//!   the trimesh map's compact mesh (a custom parry shape: `f64` vertices, `u32` indices and a
//!   BVH of `f32` boxes with up to four triangles per leaf, about 60 bytes per triangle, where
//!   parry's own `TriMesh` took about 200 with its per-triangle BVH and build buffers). The
//!   collider sits at the identity with world-coordinate vertices, so its triangles are exactly
//!   those of the [`TrimeshMap`](crate::TrimeshMap): the two maps differ only in their
//!   acceleration structure (one BVH over all triangles there; here rapier's BVH over the
//!   colliders' boxes, then each collider's own triangle BVH). The collider's `user_data` is
//!   its [`PatchId`]. (parry 0.25 has no flat convex polygon shape in 3D, and a
//!   `ConvexPolyhedron` needs a non-degenerate hull, so convex planar patches are triangle
//!   meshes too.)
//! * The colliders live in a [`ColliderSet`] without rigid bodies; their boxes are inserted
//!   into a [`BroadPhaseBvh`] with [`BroadPhaseBvh::set_aabb`], and queries see them through
//!   the [`QueryPipeline`] that [`BroadPhaseBvh::as_query_pipeline`] returns.
//!
//! # Queries
//! Proximity is rapier's [`QueryPipeline::project_point`] as it is (in each candidate collider,
//! the mesh's best-first walk with parry's exact point projection on the triangles). The step queries walk the pipeline's collider BVH
//! and run, in each collider whose box the step may reach, the same guarded per-mesh queries as
//! the trimesh map ([module docs there](crate::trimesh)), because rapier's own `cast_ray`,
//! `cast_shape` and `intersect_shape` call the parry per-triangle tests the trimesh map had to
//! guard: the ray–triangle test reports hits centimetres off nearly parallel triangles, the
//! GJK capsule intersection test and the ball cast can miss contacts (measured in the trimesh
//! map's docs). The walk keeps the structure rapier would use: any-hit over the colliders for
//! the unspecific queries, best-first by the time the step enters a collider's box (grown by
//! the radius) for the first hit.
//!
//! # Adding patches
//! [`PatchMapMut::add_patch`] triangulates the patch (`O(v log v)` for `v` vertices), builds
//! its collider's triangle mesh and BVH (`O(k log k)` for `k` triangles), inserts the collider
//! into the set (amortised `O(1)`) and its box into the broad-phase BVH (parry's SAH-guided
//! insertion, `O(log P)` on average, `O(P)` worst case for `P` colliders; the tree is not
//! re-optimised, as rapier would do incrementally during simulation steps). Building from
//! patches at once inserts them one by one the same way: rapier's broad phase has no bulk
//! build.

use std::fmt;
use std::io::{Read, Write};

use patch_core::{
    Aabb, CapsuleStep, FromPatches, LineStep, MapError, Patch, PatchId, PatchMap, PatchMapMut,
    Point3, Proximity, ProximityQuery, Real, SpecificStepIntersector, Step, StepHit, Tolerance,
    UnspecificStepIntersector,
};
use rapier3d_f64::dynamics::{IntegrationParameters, RigidBodySet};
use rapier3d_f64::geometry::{BroadPhaseBvh, Collider, ColliderBuilder, ColliderSet};
use rapier3d_f64::parry::partitioning::BvhNode;
use rapier3d_f64::parry::query::DefaultQueryDispatcher;
use rapier3d_f64::parry::shape::SharedShape;
use rapier3d_f64::pipeline::{QueryFilter, QueryPipeline};

use crate::Backend;
use crate::compact_mesh::CompactMesh;
use crate::mapfile::{MapCounts, MapFileError, read_map, write_map};
use crate::persist::{MapFile, MemoryUsage, patch_counts, patches_memory_bytes};
use crate::trimesh::{
    AFTER_END, MeshMapError, Probe, complete_hit, next_id, valid_proximity_query, world_triangles,
};

/// The rapier structures of a [`RapierMap`].
#[derive(Clone)]
struct World {
    colliders: ColliderSet,
    /// Empty: the colliders have no parent body, but the pipeline takes a body set.
    bodies: RigidBodySet,
    broad_phase: BroadPhaseBvh,
}

/// The rapier map (thesis §5.4.2, the BulletPatchMap set-up): one collider per patch in a
/// rapier collider set and broad phase; see the [module docs](self).
///
/// Implements every capability: [`PatchMap`], [`PatchMapMut`], [`FromPatches`],
/// [`ProximityQuery`], and the unspecific and specific step intersectors for [`LineStep`] and
/// [`CapsuleStep`], within [`RapierMap::TOLERANCE`] (the trimesh map's: the narrow phase is
/// the same).
///
/// # Complexity
/// With `P` patches of `k` triangles each: a query walks the collider BVH (`O(log P)` for
/// well-spread patches) and the triangle BVH of every collider it reaches (`O(log k)` each).
///
/// Serialises (as a map file) as the list of its patches; loading rebuilds the colliders.
#[derive(Clone)]
pub struct RapierMap {
    patches: Vec<Patch>,
    bounds: Aabb,
    /// Boxed: rapier's sets are large values (about a kilobyte), the map stays small.
    world: Box<World>,
    triangles: usize,
}

impl fmt::Debug for RapierMap {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("RapierMap")
            .field("patches", &self.patches.len())
            .field("triangles", &self.triangles)
            .field("bounds", &self.bounds)
            .finish()
    }
}

impl Default for RapierMap {
    fn default() -> Self {
        RapierMap::new()
    }
}

/// # Construction
impl RapierMap {
    /// The declared tolerance, the trimesh map's ([`TrimeshMap::TOLERANCE`](crate::TrimeshMap::TOLERANCE)):
    /// the per-mesh narrow phase is the same code on the same triangles.
    pub const TOLERANCE: Tolerance = crate::TrimeshMap::TOLERANCE;

    /// The empty map.
    pub fn new() -> RapierMap {
        RapierMap {
            patches: Vec::new(),
            bounds: Aabb::EMPTY,
            world: Box::new(World {
                colliders: ColliderSet::new(),
                bodies: RigidBodySet::new(),
                broad_phase: BroadPhaseBvh::new(),
            }),
            triangles: 0,
        }
    }

    /// Builds the map from patches (one collider insertion each, see the [module
    /// docs](self)). Like [`FromPatches::from_patches`], with the concrete error type.
    ///
    /// # Errors
    /// [`MeshMapError`] naming the first patch that cannot be triangulated;
    /// [`MapError::TooManyPatches`] past `u32::MAX` patches.
    pub fn build(patches: impl IntoIterator<Item = Patch>) -> Result<RapierMap, MeshMapError> {
        let mut map = RapierMap::new();
        for patch in patches {
            map.try_add_patch(patch)?;
        }
        Ok(map)
    }

    /// Adds a patch as one collider (see the [module docs](self) for the cost). Like
    /// [`PatchMapMut::add_patch`], with the concrete error type.
    ///
    /// # Errors
    /// As [`RapierMap::build`]; the map is unchanged on error.
    pub fn try_add_patch(&mut self, patch: Patch) -> Result<PatchId, MeshMapError> {
        let id = next_id(self.patches.len())?;
        let (vertices, triangles) = world_triangles(&patch, id.index())?;
        let k = triangles.len();
        // `world_triangles` makes at least one triangle of every patch.
        let (mesh, _) = CompactMesh::build(vertices, triangles, vec![(); k])
            .ok_or(MeshMapError::MeshTooLarge)?;
        let collider =
            ColliderBuilder::new(SharedShape::new(mesh)).user_data(u128::from(id.0)).build();
        let aabb = collider.compute_aabb();
        let handle = self.world.colliders.insert(collider);
        self.world.broad_phase.set_aabb(&IntegrationParameters::default(), handle, aabb);
        self.bounds = self.bounds.union(&patch.bounds());
        self.patches.push(patch);
        self.triangles += k;
        Ok(id)
    }
}

/// # Inspection
impl RapierMap {
    /// Gives the patches back, in id order (the colliders are dropped).
    pub fn into_patches(self) -> Vec<Patch> {
        self.patches
    }

    /// The number of triangles (of all colliders).
    pub fn num_triangles(&self) -> usize {
        self.triangles
    }

    /// The rapier query pipeline over the colliders (no filter).
    pub fn query_pipeline(&self) -> QueryPipeline<'_> {
        self.world.broad_phase.as_query_pipeline(
            &DefaultQueryDispatcher,
            &self.world.bodies,
            &self.world.colliders,
            QueryFilter::default(),
        )
    }

    /// The heap bytes this map can see: the patch list
    /// ([`patches_memory_bytes`]), the boxed rapier sets
    /// (collider set, empty body set, broad phase: their inline parts), one [`Collider`] per
    /// patch in the set, each collider's triangle mesh (the shape value behind its `Arc` plus
    /// parry's count of its vertices, indices and BVH nodes from their capacities) and the
    /// broad-phase BVH (parry's count of its nodes). Not visible, so not counted: the spare
    /// capacity and generation tags of the collider arena, rapier's change-tracking lists, the
    /// `Arc` headers and the broad phase's (unused) pair table.
    pub fn memory_bytes(&self) -> usize {
        let colliders: usize = self
            .world
            .colliders
            .iter()
            .map(|(_, c)| {
                size_of::<Collider>()
                    + c.shape()
                        .as_shape::<CompactMesh>()
                        .map_or(0, |m| size_of::<CompactMesh>() + m.heap_bytes())
            })
            .sum();
        patches_memory_bytes(&self.patches)
            + size_of::<World>()
            + colliders
            + self.query_pipeline().bvh.heap_memory_size()
    }
}

/// # Queries on the colliders
impl RapierMap {
    /// The patch and triangle mesh of the collider at BVH leaf `leaf`.
    fn collider(&self, leaf: u32) -> Option<(PatchId, &CompactMesh)> {
        let (collider, _) = self.world.colliders.get_unknown_gen(leaf)?;
        let id = PatchId(u32::try_from(collider.user_data).ok()?);
        Some((id, collider.shape().as_shape::<CompactMesh>()?))
    }

    /// Whether the probe touches any collider.
    fn touches(&self, probe: &Probe) -> bool {
        let pipeline = self.query_pipeline();
        pipeline
            .bvh
            .leaves(|node: &BvhNode| probe.may_touch(&node.aabb()))
            .any(|leaf| self.collider(leaf).is_some_and(|(_, mesh)| probe.touches_mesh(mesh)))
    }

    /// The first contact of the step, completed to a [`StepHit`].
    fn first<S: Step>(&self, step: &S) -> Option<StepHit> {
        let probe = Probe::of(step);
        let pipeline = self.query_pipeline();
        let (_, (t, (id, tri))) = pipeline.bvh.find_best(
            AFTER_END,
            |node: &BvhNode, best| probe.box_entry(&node.aabb(), best),
            |leaf, best| {
                let (id, mesh) = self.collider(leaf)?;
                let (tri, t) = probe.first_in_mesh(mesh, best)?;
                Some((t, (id, tri)))
            },
        )?;
        let mesh = self.collider_of(id)?;
        Some(complete_hit(mesh, tri, |_| true, id, &self.patches[id.index()], t, step))
    }

    /// The triangle mesh of a patch's collider.
    fn collider_of(&self, id: PatchId) -> Option<&CompactMesh> {
        // Colliders are inserted in id order into a set nothing is ever removed from, so the
        // arena index of patch `i` is `i`; checked through the user data anyway.
        self.collider(id.0).filter(|(found, _)| *found == id).map(|(_, mesh)| mesh)
    }
}

impl PatchMap for RapierMap {
    fn patches(&self) -> &[Patch] {
        &self.patches
    }

    fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// [`RapierMap::TOLERANCE`]: the trimesh map's narrow phase in each collider.
    fn tolerance(&self) -> patch_core::Tolerance {
        Self::TOLERANCE
    }
}

impl PatchMapMut for RapierMap {
    /// Adds a patch as one collider (see the [module docs](self) for the cost). A planar patch
    /// that cannot be triangulated is refused as [`MapError::Unsupported`]
    /// ([`RapierMap::try_add_patch`] says why).
    fn add_patch(&mut self, patch: Patch) -> Result<PatchId, MapError> {
        let kind = patch.kind();
        self.try_add_patch(patch).map_err(|e| e.into_map_error(kind))
    }
}

impl FromPatches for RapierMap {
    type Error = MeshMapError;

    fn from_patches(patches: impl IntoIterator<Item = Patch>) -> Result<Self, Self::Error> {
        RapierMap::build(patches)
    }
}

impl ProximityQuery for RapierMap {
    /// rapier's [`QueryPipeline::project_point`] (best-first over the colliders, parry's
    /// projection in each); `max_dist` only filters the answer, as rapier ignores it.
    fn closest_patch(&self, point: &Point3, max_dist: Real) -> Option<Proximity> {
        // rapier's projection unwraps its search, which finds nothing in an empty set.
        if !valid_proximity_query(point, max_dist) || self.patches.is_empty() {
            return None;
        }
        let (handle, proj) = self.query_pipeline().project_point(point, max_dist, false)?;
        let distance = (proj.point - point).norm();
        let id = u32::try_from(self.world.colliders.get(handle)?.user_data).ok()?;
        (distance <= max_dist).then_some(Proximity {
            patch: PatchId(id),
            point: proj.point,
            distance,
        })
    }
}

impl UnspecificStepIntersector<LineStep> for RapierMap {
    /// Any-hit over the colliders, ray casts in each (see the [module docs](self)).
    fn is_step_free(&self, step: &LineStep) -> bool {
        !self.touches(&Probe::of(step))
    }
}

impl SpecificStepIntersector<LineStep> for RapierMap {
    /// Best-first over the colliders, ray casts in each (see the [module docs](self)).
    fn first_hit(&self, step: &LineStep) -> Option<StepHit> {
        self.first(step)
    }
}

impl UnspecificStepIntersector for RapierMap {
    /// Any-hit over the colliders, closed-form segment–triangle distances in each (see the
    /// [module docs](self)).
    fn is_step_free(&self, step: &CapsuleStep) -> bool {
        !self.touches(&Probe::of(step))
    }
}

impl SpecificStepIntersector for RapierMap {
    /// Best-first over the colliders, ball casts in each (see the [module docs](self)).
    fn first_hit(&self, step: &CapsuleStep) -> Option<StepHit> {
        self.first(step)
    }
}

impl MapFile for RapierMap {
    const BACKEND: Backend = Backend::Rapier;

    /// Writes the patch list (in id order).
    fn save(&self, writer: impl Write) -> Result<u64, MapFileError> {
        write_map(writer, Self::BACKEND.name(), self.counts(), &self.patches)
    }

    /// Reads the patch list and rebuilds the colliders and the broad phase.
    fn load(reader: impl Read) -> Result<Self, MapFileError> {
        let (_, patches): (_, Vec<Patch>) = read_map(reader, Some(Self::BACKEND.name()))?;
        RapierMap::build(patches).map_err(|e| MapFileError::Decode(e.to_string()))
    }

    /// The patch counts, with the triangles of all colliders (planar patches' included).
    fn counts(&self) -> MapCounts {
        MapCounts { triangles: self.triangles as u64, ..patch_counts(&self.patches) }
    }
}

impl MemoryUsage for RapierMap {
    /// [`RapierMap::memory_bytes`].
    fn memory_bytes(&self) -> usize {
        RapierMap::memory_bytes(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::persist::AnyMap;
    use crate::{TrimeshMap, load_any};
    use patch_core::conformance::SceneKind;
    use patch_core::conformance::strategies::{scene_with_capsule_steps, scene_with_points};
    use patch_core::{Isometry3, PatchKind, PlanarPatch, Point2, Polygon};
    use proptest::prelude::*;

    fn floor_and_wall() -> Vec<Patch> {
        let floor = PlanarPatch::rectangle(
            Isometry3::identity(),
            Point2::new(0.0, 0.0),
            Point2::new(4.0, 4.0),
        )
        .unwrap();
        let wall = PlanarPatch::from_world_polygon(
            &[
                Point3::new(4.0, 0.0, 0.0),
                Point3::new(4.0, 0.0, 2.0),
                Point3::new(4.0, 4.0, 2.0),
                Point3::new(4.0, 4.0, 0.0),
            ],
            &[],
            1e-9,
        )
        .unwrap();
        vec![floor.into(), wall.into()]
    }

    #[test]
    fn one_collider_per_patch_with_its_id() {
        let map = RapierMap::from_patches(floor_and_wall()).unwrap();
        assert_eq!(map.len(), 2);
        assert_eq!(map.num_triangles(), 4);
        let pipeline = map.query_pipeline();
        assert_eq!(pipeline.colliders.len(), 2);
        for (i, (_, c)) in pipeline.colliders.iter().enumerate() {
            assert_eq!(c.user_data, i as u128);
            assert_eq!(c.shape().as_shape::<CompactMesh>().map(|m| m.num_triangles()), Some(2));
        }
        let step =
            CapsuleStep::new(Point3::new(1.0, 2.0, 1.0), Point3::new(6.0, 2.0, 1.0), 0.5).unwrap();
        let hit = map.first_hit(&step).unwrap();
        assert_eq!(hit.patch, PatchId(1));
        assert!((hit.t - 0.5).abs() < 1e-5);
        assert!((hit.normal.x + 1.0).abs() < 1e-12);
        assert!(!map.is_step_free(&step));
        let p = map.closest_patch(&Point3::new(3.5, 2.0, 1.0), Real::INFINITY).unwrap();
        assert_eq!(p.patch, PatchId(1));
        assert!((p.distance - 0.5).abs() < 1e-12);
        assert!(map.closest_patch(&Point3::new(3.5, 2.0, 1.0), 0.4).is_none());
    }

    #[test]
    fn the_empty_map_answers_without_panicking() {
        let map = RapierMap::new();
        let step = CapsuleStep::new(Point3::origin(), Point3::new(1.0, 1.0, 1.0), 0.5).unwrap();
        assert!(map.is_step_free(&step) && map.first_hit(&step).is_none());
        assert!(map.is_step_free(&step.line()) && map.first_hit(&step.line()).is_none());
        assert!(map.closest_patch(&Point3::origin(), Real::INFINITY).is_none());
        assert!(map.bounds().is_empty());
    }

    #[test]
    fn patches_that_cannot_be_triangulated_are_errors() {
        let huge = PlanarPatch::new(
            Polygon::rectangle(Point2::new(0.0, 0.0), Point2::new(1e61, 1e61)).unwrap(),
            Isometry3::identity(),
        )
        .unwrap();
        let mut map = RapierMap::from_patches(floor_and_wall()).unwrap();
        assert_eq!(
            map.add_patch(huge.clone().into()),
            Err(MapError::Unsupported { kind: PatchKind::Planar })
        );
        assert_eq!((map.len(), map.query_pipeline().colliders.len()), (2, 2));
        assert!(matches!(
            RapierMap::from_patches([huge.into()]),
            Err(MeshMapError::Triangulation { patch: 0, .. })
        ));
    }

    #[test]
    fn map_files_round_trip() {
        let map = RapierMap::from_patches(floor_and_wall()).unwrap();
        let mut buf = Vec::new();
        map.save(&mut buf).unwrap();
        let back = RapierMap::load(&buf[..]).unwrap();
        assert_eq!(back.patches(), map.patches());
        assert_eq!(
            back.counts(),
            MapCounts { planar_patches: 2, trimesh_patches: 0, triangles: 4, points: 0 }
        );
        let any = load_any(&buf[..]).unwrap();
        assert!(matches!(any, AnyMap::Rapier(_)));
        assert_eq!(any.counts(), map.counts());
        assert!(matches!(TrimeshMap::load(&buf[..]), Err(MapFileError::BackendMismatch { .. })));
    }

    #[test]
    fn memory_counts_colliders_and_broad_phase() {
        let map = RapierMap::from_patches(floor_and_wall()).unwrap();
        let bytes = map.memory_bytes();
        assert!(bytes > patches_memory_bytes(&map.patches) + 2 * size_of::<Collider>(), "{bytes}");
        let mut bigger = map.clone();
        bigger.add_patch(floor_and_wall().remove(0)).unwrap();
        assert!(bigger.memory_bytes() > bytes);
    }

    fn assert_send_sync<T: Send + Sync>() {}

    #[test]
    fn maps_are_send_and_sync() {
        assert_send_sync::<RapierMap>();
    }

    proptest! {
        #![proptest_config(ProptestConfig {
            cases: 64,
            failure_persistence: None,
            rng_seed: proptest::test_runner::RngSeed::Fixed(0x5eed_2010),
            ..ProptestConfig::default()
        })]

        /// Same triangles, same per-mesh queries: the rapier map answers like the trimesh map
        /// (only ties between patches may go another way).
        #[test]
        fn answers_like_the_trimesh_map(
            (patches, steps) in scene_with_capsule_steps(SceneKind::Mixed, 0..=8, 1..=16)
        ) {
            let rapier = RapierMap::from_patches(patches.clone()).unwrap();
            let trimesh = TrimeshMap::from_patches(patches).unwrap();
            prop_assert_eq!(rapier.num_triangles(), trimesh.num_triangles());
            for s in &steps {
                prop_assert_eq!(rapier.is_step_free(s), trimesh.is_step_free(s));
                prop_assert_eq!(rapier.first_hit(s).map(|h| h.t), trimesh.first_hit(s).map(|h| h.t));
                let l = s.line();
                prop_assert_eq!(rapier.is_step_free(&l), trimesh.is_step_free(&l));
                prop_assert_eq!(rapier.first_hit(&l).map(|h| h.t), trimesh.first_hit(&l).map(|h| h.t));
            }
        }

        #[test]
        fn nearest_distances_match_the_trimesh_map(
            (patches, points) in scene_with_points(SceneKind::Mixed, 0..=6, 1..=16)
        ) {
            let rapier = RapierMap::from_patches(patches.clone()).unwrap();
            let trimesh = TrimeshMap::from_patches(patches).unwrap();
            for p in &points {
                for max_dist in [Real::INFINITY, 0.5, 0.0] {
                    prop_assert_eq!(
                        rapier.closest_patch(p, max_dist).map(|q| q.distance),
                        trimesh.closest_patch(p, max_dist).map(|q| q.distance)
                    );
                }
            }
        }
    }
}
