//! Patch map backends (thesis §5.4.2): the maps that answer the collision queries of
//! `patch-core`'s capability traits (§5.4.1), and the files they are stored in.
//!
//! # Backends
//! Every backend follows the thesis's split (L5422–5428): a cheap broad phase picks candidate
//! patches, an exact narrow phase decides on them. The narrow phase of the native backends is
//! `patch-core`'s [`geometry`](patch_core::geometry) kernels, the same as the reference
//! [`BruteForceMap`](patch_core::BruteForceMap), so their answers match it exactly.
//!
//! * [`PolygonMap`] — the thesis's SimplePatchMap (L5489–5499): a list of patches, no broad
//!   phase (a per-patch box test inside the loop), exact kernels. The simplest correct map.
//! * [`BBox6dMap`] — the thesis's BoundingBox6DPatchMap (L5501–5554, "a variant of sweep and
//!   prune"): each patch's box as a point in a 6D k-d forest ([`kdtree`]), one orthogonal range
//!   query per check, exact kernels on the candidates.
//! * [`TrimeshMap`] — the role of the thesis's BulletPatchMap (L5572–5582): planar patches
//!   triangulated ([`triangulate`]) into one parry triangle mesh with a BVH. Whether a step
//!   collides is decided by closed-form segment–triangle distances on parry's exact primitives;
//!   parry's own GJK and shape casts miss rare contacts (measured; see [`trimesh`]).
//! * [`RapierMap`] — the thesis's set-up with Bullet's collision world: one collider per patch
//!   in a rapier query pipeline (a dynamic broad phase), the same narrow phase as [`TrimeshMap`].
//!   Behind the default feature `rapier`; without it, asking for the backend is
//!   [`AnyMapError::NotBuilt`].
//! * [`PointCloudMap`] — the thesis's PointCloudMap (L5584–5784): no patches at all; the scan
//!   points in k-d trees and Algorithm 10 for capsule steps ([`point_cloud`]).
//!
//! # Capabilities
//! Checked at compile time by `tests/it/capabilities.rs`; the tolerance is the one each backend's
//! conformance suite runs with (`tests/it/conformance.rs`, against the reference map):
//!
//! | backend | map | add | proximity | line unspec. | line spec. | capsule unspec. | capsule spec. | tolerance |
//! |---|---|---|---|---|---|---|---|---|
//! | [`PolygonMap`] | ✓ | ✓ | ✓ | ✓ | ✓ | ✓ | ✓ | exact |
//! | [`BBox6dMap`] | ✓ | ✓ | ✓ | ✓ | ✓ | ✓ | ✓ | exact |
//! | [`TrimeshMap`] | ✓ | ✓ | ✓ | ✓ | ✓ | ✓ | ✓ | numeric 1e-6 m, conservative 1e-5 m |
//! | [`RapierMap`] | ✓ | ✓ | ✓ | ✓ | ✓ | ✓ | ✓ | numeric 1e-6 m, conservative 1e-5 m |
//! | [`PointCloudMap`] | – | points | – | ✓ | – | ✓ | – | exact against the points; against surfaces only if sampled denser than the radius |
//!
//! "map" is [`PatchMap`](patch_core::PatchMap) and [`FromPatches`](patch_core::FromPatches),
//! "add" [`PatchMapMut`](patch_core::PatchMapMut), "proximity"
//! [`ProximityQuery`](patch_core::ProximityQuery), "unspec."
//! [`UnspecificStepIntersector`](patch_core::UnspecificStepIntersector), "spec."
//! [`SpecificStepIntersector`](patch_core::SpecificStepIntersector), for [`LineStep`](patch_core::LineStep) and
//! [`CapsuleStep`](patch_core::CapsuleStep). The point-cloud map has only the unspecific step
//! queries, as the thesis scopes it (L5762–5784), so the planners that need proximity (MA RRT,
//! MA PRM) or specific hits (Evasion RRT) do not compile with it (thesis Table 5.2).
//!
//! # Which one to pick
//! Measured on the benchmark matrix (`docs/benchmarks.md`, `cargo xtask bench roadmap --jobs 1`:
//! the office floor plan with ten planners, the lab's exact geometry and the lab's maps built
//! from scans with RRT and PRM; every backend on the same map in one run) and on the generated
//! voxel world (docs/performance.md). No backend is the fastest everywhere; each pick below is
//! within the stated factor of the fastest backend's median time on every planner of the
//! matrix's scenes it names (at b2b3363):
//! * A map of a few hundred planar patches (rooms, floor plans) with any planner: [`PolygonMap`].
//!   Office, median time to the four goals: RRT 189 µs against bbox6d's 285 µs, rapier's 455 µs
//!   and trimesh's 554 µs; within 1.35× of the fastest on all ten planners (RRT-Connect and
//!   RRT*, where [`BBox6dMap`] is fastest). [`BBox6dMap`] is within 1.5× on eight of them (MA RRT
//!   1.93×, RRT 1.50×).
//! * Maps with trimesh patches or built from scans (the lab's exact geometry with its curved
//!   objects; its planes, hybrid and trimesh maps from scans): [`RapierMap`] (feature `rapier`, on
//!   by default), within 1.15× of the fastest on every case (RRT and PRM, K = 100, 500 and the
//!   whole run). Without the feature, [`TrimeshMap`]: within 1.7× on the lab's maps, but 2.3–2.5×
//!   slower than rapier for PRM on whole-scan meshes (the trimesh map).
//! * Large finished maps of many planar patches of mixed sizes: [`TrimeshMap`]. On the generated
//!   voxel world (`cargo xtask voxel-world`: 38,293 patches, 120,932 triangles; not in the
//!   matrix) RRT takes 3.16 µs per iteration on it, 4.64 µs on [`BBox6dMap`] and 8.47 µs on
//!   [`RapierMap`].
//! * The Evasion RRT (it asks for the first contact of a step): [`PolygonMap`] or [`BBox6dMap`].
//!   Office: 1.15 and 1.45 ms; rapier 6.66 ms, trimesh 7.74 ms.
//! * Maps that grow while the robot explores (patches added between queries): [`BBox6dMap`];
//!   adding stays exact and sublinear. Its k-d nodes keep the union of the patch boxes below
//!   them, so maps of mixed patch sizes stay fast, but a large patch's box still makes it a
//!   candidate for every step near it; prefer the mesh backends for a finished map.
//! * Tests, or a second opinion: [`PolygonMap`] (every query is O(P)).
//! * Raw scans without patch extraction: [`PointCloudMap`], for RRT and PRM only, and only if
//!   the scan is denser than the robot (see [`point_cloud`]).
//!
//! # Cost of adding
//!
//! | backend | adding one patch (P patches, n vertices each) | from scratch |
//! |---|---|---|
//! | [`PolygonMap`] | O(n) box + amortised O(1) push | O(P·n) |
//! | [`BBox6dMap`] | O(n) box + amortised O(log² P) forest insertion | O(P·n + P log P) |
//! | [`TrimeshMap`] | k triangles: amortised O(k log² T) (meshes of similar size merged; queries walk at most log₂ T + 1 meshes; `compact` merges to one) | O(T log T), one mesh |
//! | [`RapierMap`] | triangulation + the collider's BVH O(k log k) + one broad-phase insertion O(log P) | P insertions |
//! | [`PointCloudMap`] | points: amortised O(log² N) each | O(N log N) |
//!
//! # Is the map safe?
//! [`compare`] checks a map against a truth map (a scene's exact surfaces, say) over seeded
//! random capsule steps or given ones: how many colliding steps the map calls free (unsafe),
//! how many free ones it blocks (overcautious), each with a 95 % interval, and which truth
//! surfaces the misses hit.
//!
//! # Backends chosen at run time
//! [`Backend`] names the five backends: its names are the map files' backend tags, and the
//! names programs accept. [`AnyMap`] holds a map of any of them: [`AnyMap::from_patches`]
//! builds one from patches, [`load_any`] reads one from a file.
//!
//! # Files and memory
//! [`MapFile`] saves and loads each backend through the [`mapfile`] container (header with
//! backend tag and counts, checksums, bincode payload; indices are rebuilt on load);
//! [`load_any`] reads any of them into an [`AnyMap`]. [`MemoryUsage`] reports the heap bytes a
//! map owns. [`map_from_obj`] builds a map of any backend from an OBJ mesh, its faces as
//! planar patches ([`from_mesh`]).

pub mod any_map;
pub mod backend;
pub mod bbox6d;
mod compact_mesh;
pub mod compare;
pub mod from_mesh;
pub mod kdtree;
pub mod mapfile;
pub mod persist;
pub mod point_cloud;
pub mod polygon;
#[cfg(feature = "rapier")]
pub mod rapier;
pub mod sampling;
/// Constrained Delaunay triangulation of polygons with holes; it lives in `patch-core`, which
/// patch extraction shares, and is re-exported here.
pub use patch_core::triangulate;
pub mod trimesh;

pub use from_mesh::{
    MeshToPatchesConfig, MeshToPatchesStats, ObjMapError, map_from_obj, planar_patches_from_mesh,
};
pub use point_cloud::{PointCloudMap, PointCloudMapError};
pub use sampling::{SamplingError, sample_patch_points};

pub use any_map::{AnyMap, AnyMapError};
pub use backend::{Backend, UnknownBackend};
pub use bbox6d::BBox6dMap;
pub use compare::{
    Attribution, CompareError, MapComparison, Rate, StepSampling, compare_maps, compare_on_steps,
    random_steps,
};
pub use persist::{MapFile, MemoryUsage, load_any};
pub use polygon::PolygonMap;
#[cfg(feature = "rapier")]
pub use rapier::RapierMap;
pub use trimesh::{MeshMapError, TrimeshMap};
