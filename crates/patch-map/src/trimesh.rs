//! The parry trimesh map: every patch as triangles in one parry [`TriMesh`] with its bounding
//! volume hierarchy (the role of the thesis's OPCODE and Bullet maps, §5.4.2: "planar patches
//! are Delaunay-triangulated into trimeshes").
//!
//! # Layout
//! * Planar patches are triangulated in their own 2D frame ([`triangulate_polygon`], a
//!   constrained Delaunay triangulation with holes) and the triangles mapped to the world by
//!   `world_from_patch`; trimesh patches are taken as they are.
//! * All triangles go into one parry [`TriMesh`] (no vertex merging, no topology: the index
//!   buffer stays exactly as built), and a table `patch_of[triangle]` maps every triangle back
//!   to its [`PatchId`].
//!
//! # Queries
//! Every query is a walk of the mesh's BVH with parry's per-triangle tests:
//!
//! | query | parry | degenerate branches |
//! |---|---|---|
//! | proximity | point projection with location (`project_local_point_and_get_location`) | — |
//! | line step | ray–triangle casts along `end − start` (best-first for the first hit, any-hit otherwise) | a segment parallel to a triangle's plane (which parry's ray–triangle test ignores) and a zero-length segment are decided by `patch-core`'s kernel in the triangle's frame ([`TriangleFrame::first_contact`] with radius 0) |
//! | capsule step, free? | GJK `intersection_test` of a [`Capsule`] against each triangle whose box, grown by `r`, the segment passes | zero length: a [`Ball`] test (point projection); radius 0: the line step |
//! | capsule step, first hit | `cast_shape` of a [`Ball`] moving `start → end` (max time of impact 1, `stop_at_penetration`, so a start that already touches gives `t = 0`) | zero length (below [`SHORT_STEP`]): a ball test at the start; radius 0: the line step |
//!
//! parry's composite shape cast reports the triangle it hit (`CompositeShapeRef::cast_shape`
//! returns the part index with the [`ShapeCastHit`](parry3d_f64::query::ShapeCastHit)), which
//! names the patch. The [`StepHit`] is then completed from the patch, not from parry's witness
//! points (which are undefined at `t = 0`): the contact point is the patch's point closest to the
//! sphere's centre at `t` (a projection restricted to that patch's triangles), the normal is the
//! plane normal of a planar patch or the normal of that closest triangle of a trimesh patch,
//! oriented by the rule of [`StepHit::normal`].
//!
//! # Accuracy
//! Projections and ray–triangle tests are closed formulas (errors of a few ulps). The capsule
//! tests run GJK, which stops when its distance bounds agree to a relative `sqrt(10 ε_f64)` ≈
//! 5e-8 or after 100 iterations, so grazing contacts are decided only to about that relative
//! precision. [`TrimeshMap::TOLERANCE`] states the resulting band; the conformance suite checks
//! it.
//!
//! # Adding patches
//! parry's [`TriMesh`] is immutable (appending rebuilds it). [`FromPatches::from_patches`] and
//! loading build one mesh; [`PatchMapMut::add_patch`] uses the logarithmic method (Bentley and
//! Saxe): the new patch's triangles become a small mesh of their own, and while the newest
//! mesh holds at least half as many triangles as the one before it, the two are merged and
//! rebuilt. Mesh sizes thus at least double from newest to oldest: a map of `n` triangles has
//! at most `log₂ n + 1` meshes, every query walks each of them, and every triangle is rebuilt
//! `O(log n)` times, so an add of `k` triangles costs amortised `O(k log² n)` (a rebuild of `m`
//! triangles is parry's `O(m log m)` binned BVH build). [`TrimeshMap::compact`] merges
//! everything back into one mesh.

use std::fmt;

use parry3d_f64::bounding_volume::BoundingVolume as _;
use parry3d_f64::math::Isometry;
use parry3d_f64::partitioning::BvhNode;
use parry3d_f64::query::{
    DefaultQueryDispatcher, PointQuery as _, Ray, RayCast as _, ShapeCastOptions,
};
use parry3d_f64::shape::{Ball, Capsule, CompositeShapeRef, TriMesh, TriMeshFlags, Triangle};
use patch_core::geometry::TriangleFrame;
use patch_core::{
    Aabb, CapsuleStep, FromPatches, LineStep, MapError, Patch, PatchId, PatchMap, PatchMapMut,
    PlanarPatch, Point2, Point3, Proximity, ProximityQuery, Real, SpecificStepIntersector, Step,
    StepHit, Tolerance, UnitVector3, UnspecificStepIntersector, Vector3,
};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::triangulate::{TriangulationError, triangulate_polygon};

/// Steps shorter than this (in metres) are tested as a sphere at their start: parry's shape
/// cast treats a motion of length below about 2e-16 as no motion, and the end of such a step
/// is within rounding of its start anyway.
pub const SHORT_STEP: Real = 1e-12;

/// `|n̂ · d̂|` up to which a segment counts as parallel to a triangle's plane, so the exact
/// kernel decides instead of parry's ray–triangle test (see [`segment_hits_triangle`]). Beyond
/// it, parry's barycentric coordinates have relative errors below about `1e-16 / PARALLEL`.
const PARALLEL: Real = 1e-6;

/// Why a patch could not become triangles of a mesh map ([`TrimeshMap`],
/// [`RapierMap`](crate::RapierMap)).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MeshMapError {
    /// The constrained Delaunay triangulation of a planar patch failed (coordinates beyond the
    /// range of spade's exact predicates, about 3e60 m).
    #[error("patch {patch}: {source}")]
    Triangulation {
        /// The index of the patch in the input (or its would-be id when added).
        patch: usize,
        /// Why.
        #[source]
        source: TriangulationError,
    },
    /// The triangulation of a planar patch does not tile its polygon: a triangulation of a
    /// polygon with `n` vertices and `h` holes has `n + 2h − 2` triangles whose areas add up to
    /// the polygon's (to a relative 1e-9). Checked so a misclassified triangle can never leave
    /// a gap in the map.
    #[error(
        "patch {patch}: the triangulation has {found} triangles of total area {found_area} m², \
         expected {expected} of total area {expected_area} m²"
    )]
    Tiling {
        /// The index of the patch.
        patch: usize,
        /// Triangles produced.
        found: usize,
        /// Triangles expected.
        expected: usize,
        /// Their total area.
        found_area: Real,
        /// The polygon's area.
        expected_area: Real,
    },
    /// A single mesh would hold more than `u32::MAX` vertices (parry indexes them with `u32`).
    #[error("the mesh would hold more than u32::MAX vertices")]
    MeshTooLarge,
    /// The map refused the patch.
    #[error(transparent)]
    Map(#[from] MapError),
}

impl MeshMapError {
    /// The error as the [`MapError`] of [`PatchMapMut::add_patch`]: a patch that cannot be
    /// triangulated is refused as [`MapError::Unsupported`] of its kind (the trait's error type
    /// has no variant for it; the inherent `try_add_patch` of each map gives the cause).
    pub(crate) fn into_map_error(self, patch: &Patch) -> MapError {
        match self {
            MeshMapError::Map(e) => e,
            _ => MapError::Unsupported { kind: patch.kind() },
        }
    }
}

/// The next id, or [`MapError::TooManyPatches`].
pub(crate) fn next_id(len: usize) -> Result<PatchId, MapError> {
    u32::try_from(len)
        .ok()
        .filter(|&i| i < u32::MAX)
        .map(PatchId)
        .ok_or(MapError::TooManyPatches)
}

/// A planar patch triangulated in its own frame: 2D vertices and counter-clockwise triangles,
/// checked to tile the polygon (see [`MeshMapError::Tiling`]).
pub(crate) fn triangulate_planar(
    patch: &PlanarPatch,
    index: usize,
) -> Result<(Vec<Point2>, Vec<[u32; 3]>), MeshMapError> {
    let polygon = patch.polygon();
    let rings: Vec<Vec<[Real; 2]>> =
        polygon.rings().map(|r| r.points().iter().map(|p| [p.x, p.y]).collect()).collect();
    let t = triangulate_polygon(&rings)
        .map_err(|source| MeshMapError::Triangulation { patch: index, source })?;
    let vertices: Vec<Point2> = t.vertices.iter().map(|v| Point2::new(v[0], v[1])).collect();
    let area = |tri: &[u32; 3]| {
        let [a, b, c] = tri.map(|i| vertices[i as usize]);
        0.5 * (b - a).perp(&(c - a))
    };
    let found_area: Real = t.triangles.iter().map(area).sum();
    let expected = polygon.num_vertices() + 2 * polygon.holes().len() - 2;
    let expected_area = polygon.area();
    let positive = t.triangles.iter().all(|tri| area(tri) > 0.0);
    if t.triangles.len() != expected
        || !positive
        || (found_area - expected_area).abs() > 1e-9 * expected_area
    {
        return Err(MeshMapError::Tiling {
            patch: index,
            found: t.triangles.len(),
            expected,
            found_area,
            expected_area,
        });
    }
    Ok((vertices, t.triangles))
}

/// The triangles of a patch in world coordinates: the triangulation of a planar patch mapped
/// by `world_from_patch`, or a mesh's own vertices and triangles.
pub(crate) fn world_triangles(
    patch: &Patch,
    index: usize,
) -> Result<(Vec<Point3>, Vec<[u32; 3]>), MeshMapError> {
    match patch {
        Patch::Planar(p) => {
            let (vertices, triangles) = triangulate_planar(p, index)?;
            Ok((vertices.iter().map(|v| p.to_world(v)).collect(), triangles))
        }
        Patch::Trimesh(m) => Ok((m.vertices().to_vec(), m.triangles().to_vec())),
    }
}

/// The normal of a mesh triangle by the formula of [`TriangleFrame`] (`(b − a) × (c − a)`
/// normalised), so a trimesh patch's hit normals are exactly its triangles' normals.
pub(crate) fn triangle_normal(tri: &Triangle) -> UnitVector3 {
    TriangleFrame::new(&[tri.a, tri.b, tri.c]).map_or_else(
        || UnitVector3::try_new(tri.scaled_normal(), 0.0).unwrap_or(Vector3::z_axis()),
        |f| f.normal(),
    )
}

/// Orients a surface normal by the rule of [`StepHit::normal`], given the signed distances
/// (along `normal`) of the sphere's centre at contact and of the start from the surface's
/// plane, and the motion along the normal.
pub(crate) fn orient_normal(
    normal: UnitVector3,
    center: Real,
    start: Real,
    motion: Real,
    radius: Real,
) -> UnitVector3 {
    let keep = if radius > 0.0 && center != 0.0 {
        center > 0.0
    } else if start != 0.0 {
        start > 0.0
    } else if motion != 0.0 {
        motion < 0.0
    } else {
        true
    };
    if keep { normal } else { -normal }
}

/// The oriented contact normal of `patch` at `point` for a step whose sphere is centred at
/// `center` at contact: the plane normal of a planar patch (signed distances taken in the
/// patch frame), or the normal of the touched triangle `surface` of a trimesh patch.
pub(crate) fn contact_normal<S: Step>(
    patch: &Patch,
    surface: UnitVector3,
    point: &Point3,
    center: &Point3,
    step: &S,
) -> UnitVector3 {
    let r = step.radius();
    match patch {
        Patch::Planar(p) => {
            let (c, a, b) =
                (p.to_local(center).z, p.to_local(&step.start()).z, p.to_local(&step.end()).z);
            orient_normal(p.normal(), c, a, b - a, r)
        }
        Patch::Trimesh(_) => {
            let n = surface.into_inner();
            let c = n.dot(&(center - point));
            let a = n.dot(&(step.start() - point));
            orient_normal(surface, c, a, n.dot(&step.delta()), r)
        }
    }
}

/// Whether the segment `a → b` (`ray` is `a` along `b − a`) meets the closed triangle, and at
/// which parameter (at most `max_t`): parry's ray–triangle test, except for segments (nearly)
/// parallel to the triangle's plane, zero-length ones included, which `patch-core`'s kernel
/// decides in the triangle's frame ([`TriangleFrame::first_contact`] with radius 0: a segment
/// within rounding of the plane is solved in 2D). parry skips exactly parallel rays, and for
/// nearly parallel ones its barycentric coordinates are ratios of rounding-sized numbers: it
/// can report a hit 5 cm off the triangle. (The plane crossing of a nearly parallel segment is
/// ill-conditioned for any method that computes it from signed volumes, so the kernel's own
/// 2D entry is used, whose point is consistent with its parameter.)
pub(crate) fn segment_hits_triangle(
    tri: &Triangle,
    ray: &Ray,
    b: &Point3,
    max_t: Real,
) -> Option<Real> {
    let n = tri.scaled_normal();
    if n.dot(&ray.dir).abs() <= PARALLEL * n.norm() * ray.dir.norm() {
        TriangleFrame::new(&[tri.a, tri.b, tri.c])?
            .first_contact(&ray.origin, b, 0.0)
            .map(|c| c.t)
            .filter(|&t| t <= max_t)
    } else {
        tri.cast_local_ray(ray, max_t, true).map(|t| t.min(1.0))
    }
}

/// The options of every shape cast: times of impact up to and including 1, a start that
/// already touches stops the cast at 0.
pub(crate) fn cast_options(max_t: Real) -> ShapeCastOptions {
    ShapeCastOptions {
        max_time_of_impact: max_t,
        target_distance: 0.0,
        stop_at_penetration: true,
        compute_impact_geometry_on_penetration: false,
    }
}

/// Just above 1: parry's best-first searches keep only costs strictly below their bound, and
/// a contact at exactly `t = 1` (the end touches) must count.
pub(crate) const AFTER_END: Real = 1.0 + Real::EPSILON;

/// The closest point of a mesh to `point` among the triangles accepted by `keep`, starting
/// from triangle `first` (which must be accepted): `(triangle, point, distance)`.
pub(crate) fn closest_on_triangles(
    mesh: &TriMesh,
    point: &Point3,
    first: u32,
    keep: impl Fn(u32) -> bool,
) -> (u32, Point3, Real) {
    let project = |tri: u32| {
        let q = mesh.triangle(tri).project_local_point(point, false).point;
        ((q - point).norm(), q)
    };
    let (d0, q0) = project(first);
    mesh.bvh()
        .find_best(
            d0,
            |node: &BvhNode, _| node.aabb().distance_to_local_point(point, true),
            |tri, _| keep(tri).then(|| project(tri)),
        )
        .map_or((first, q0, d0), |(tri, (d, q))| (tri, q, d))
}

/// One immutable mesh and the patch of each of its triangles.
#[derive(Clone)]
struct Level {
    mesh: TriMesh,
    patch_of: Vec<PatchId>,
}

impl Level {
    /// The mesh of these triangles; `None` if there are none.
    fn build(vertices: Vec<Point3>, indices: Vec<[u32; 3]>, patch_of: Vec<PatchId>) -> Option<Level> {
        // No flags: parry neither merges vertices nor deletes triangles, so triangle `i` of the
        // mesh is `indices[i]` and `patch_of` stays aligned.
        let mesh = TriMesh::with_flags(vertices, indices, TriMeshFlags::empty()).ok()?;
        Some(Level { mesh, patch_of })
    }

    /// The mesh of the triangles of both levels (`self`'s first); `None` if it would exceed
    /// `u32::MAX` vertices.
    fn merged(&self, other: &Level) -> Option<Level> {
        let base = u32::try_from(self.mesh.vertices().len()).ok()?;
        let n = self.mesh.vertices().len() + other.mesh.vertices().len();
        u32::try_from(n).ok()?;
        let mut vertices = Vec::with_capacity(n);
        vertices.extend_from_slice(self.mesh.vertices());
        vertices.extend_from_slice(other.mesh.vertices());
        let mut indices = Vec::with_capacity(self.len() + other.len());
        indices.extend_from_slice(self.mesh.indices());
        indices.extend(other.mesh.indices().iter().map(|t| t.map(|i| i + base)));
        let mut patch_of = Vec::with_capacity(self.len() + other.len());
        patch_of.extend_from_slice(&self.patch_of);
        patch_of.extend_from_slice(&other.patch_of);
        Level::build(vertices, indices, patch_of)
    }

    fn len(&self) -> usize {
        self.patch_of.len()
    }

    fn memory_bytes(&self) -> usize {
        self.mesh.heap_memory_size() + self.patch_of.capacity() * size_of::<PatchId>()
    }
}

/// Concatenates patches' triangles into the buffers of one mesh.
#[derive(Default)]
struct MeshBuilder {
    vertices: Vec<Point3>,
    indices: Vec<[u32; 3]>,
    patch_of: Vec<PatchId>,
}

impl MeshBuilder {
    fn push(
        &mut self,
        id: PatchId,
        vertices: &[Point3],
        triangles: &[[u32; 3]],
    ) -> Result<(), MeshMapError> {
        let base = u32::try_from(self.vertices.len()).map_err(|_| MeshMapError::MeshTooLarge)?;
        if u32::try_from(self.vertices.len() + vertices.len()).is_err() {
            return Err(MeshMapError::MeshTooLarge);
        }
        self.vertices.extend_from_slice(vertices);
        self.indices.extend(triangles.iter().map(|t| t.map(|i| i + base)));
        self.patch_of.extend(std::iter::repeat_n(id, triangles.len()));
        Ok(())
    }

    fn build(self) -> Option<Level> {
        Level::build(self.vertices, self.indices, self.patch_of)
    }
}

/// The parry trimesh map (thesis §5.4.2, the OPCODE/Bullet role): all patches as triangles in
/// one parry [`TriMesh`] with its BVH; see the [module docs](self) for the queries, their
/// degenerate branches and the cost of adding patches.
///
/// Implements every capability: [`PatchMap`], [`PatchMapMut`], [`FromPatches`],
/// [`ProximityQuery`], and the unspecific and specific step intersectors for [`LineStep`] and
/// [`CapsuleStep`], within [`TrimeshMap::TOLERANCE`].
///
/// # Complexity
/// With `n` triangles in all: queries are `O(log n)` BVH walks on each of at most
/// `log₂ n + 1` meshes (one after [`FromPatches::from_patches`] or [`TrimeshMap::compact`]) for
/// well-spread triangles; building is `O(n log n)`.
///
/// Serialises as the list of its patches; deserialising rebuilds the mesh.
#[derive(Clone)]
pub struct TrimeshMap {
    patches: Vec<Patch>,
    bounds: Aabb,
    /// Oldest (largest) first.
    levels: Vec<Level>,
}

impl fmt::Debug for TrimeshMap {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("TrimeshMap")
            .field("patches", &self.patches.len())
            .field("triangles", &self.num_triangles())
            .field("meshes", &self.levels.len())
            .field("bounds", &self.bounds)
            .finish()
    }
}

impl Default for TrimeshMap {
    fn default() -> Self {
        TrimeshMap::new()
    }
}

/// # Construction
impl TrimeshMap {
    /// The declared tolerance: a numeric band of 1e-6 m, no conservative margin.
    ///
    /// Projections and ray casts are exact to a few ulps, but the capsule tests run parry's
    /// GJK, which decides contacts only to a relative `sqrt(10 ε_f64)` ≈ 5e-8 of the distances
    /// involved (up to 20 m in the conformance scenes), so grazing contacts within about 1e-6
    /// m of touching may go either way, and a first hit may come that much early or late.
    pub const TOLERANCE: Tolerance = Tolerance { numeric: 1e-6, conservative: 0.0 };

    /// The empty map.
    pub fn new() -> TrimeshMap {
        TrimeshMap { patches: Vec::new(), bounds: Aabb::EMPTY, levels: Vec::new() }
    }

    /// Builds the map from patches at once (one mesh). Like [`FromPatches::from_patches`],
    /// with the concrete error type.
    ///
    /// # Errors
    /// [`MeshMapError`] naming the first patch that cannot be triangulated;
    /// [`MapError::TooManyPatches`] past `u32::MAX` patches.
    pub fn build(patches: impl IntoIterator<Item = Patch>) -> Result<TrimeshMap, MeshMapError> {
        let patches: Vec<Patch> = patches.into_iter().collect();
        let mut builder = MeshBuilder::default();
        let mut bounds = Aabb::EMPTY;
        for (i, patch) in patches.iter().enumerate() {
            let id = next_id(i)?;
            let (vertices, triangles) = world_triangles(patch, i)?;
            builder.push(id, &vertices, &triangles)?;
            bounds = bounds.union(&patch.bounds());
        }
        let levels = builder.build().into_iter().collect();
        Ok(TrimeshMap { patches, bounds, levels })
    }

    /// Adds a patch (see the [module docs](self) for the cost). Like
    /// [`PatchMapMut::add_patch`], with the concrete error type.
    ///
    /// # Errors
    /// As [`TrimeshMap::build`]; the map is unchanged on error.
    pub fn try_add_patch(&mut self, patch: Patch) -> Result<PatchId, MeshMapError> {
        let id = next_id(self.patches.len())?;
        let (vertices, triangles) = world_triangles(&patch, id.index())?;
        let mut builder = MeshBuilder::default();
        builder.push(id, &vertices, &triangles)?;
        if let Some(level) = builder.build() {
            self.levels.push(level);
            while let [.., older, newer] = self.levels.as_slice() {
                if older.len() > 2 * newer.len() {
                    break;
                }
                // `None`: too many vertices for one mesh; keep both.
                let Some(merged) = older.merged(newer) else {
                    break;
                };
                self.levels.truncate(self.levels.len() - 2);
                self.levels.push(merged);
            }
        }
        self.bounds = self.bounds.union(&patch.bounds());
        self.patches.push(patch);
        Ok(id)
    }

    /// Merges all meshes into one (after incremental adds), so queries walk a single BVH.
    /// `O(n log n)`. Meshes that together exceed `u32::MAX` vertices stay separate.
    pub fn compact(&mut self) {
        let mut levels = std::mem::take(&mut self.levels).into_iter();
        let Some(mut merged) = levels.next() else {
            return;
        };
        for level in levels {
            match merged.merged(&level) {
                Some(m) => merged = m,
                None => {
                    self.levels.push(merged);
                    merged = level;
                }
            }
        }
        self.levels.push(merged);
    }
}

/// # Inspection
impl TrimeshMap {
    /// The number of triangles (of all patches).
    pub fn num_triangles(&self) -> usize {
        self.levels.iter().map(Level::len).sum()
    }

    /// The number of parry meshes the triangles are in (1 after building at once or
    /// [`compact`](Self::compact), at most `log₂ n + 1` after incremental adds; 0 when empty).
    pub fn num_meshes(&self) -> usize {
        self.levels.len()
    }

    /// Every triangle of the map with the patch it belongs to, in no particular order.
    pub fn triangles(&self) -> impl Iterator<Item = ([Point3; 3], PatchId)> + '_ {
        self.levels.iter().flat_map(|level| {
            level.patch_of.iter().enumerate().map(|(i, &id)| {
                let t = level.mesh.triangle(i as u32);
                ([t.a, t.b, t.c], id)
            })
        })
    }

    /// The bytes held by the meshes (parry's own count of vertices, indices and BVH nodes
    /// from their capacities, [`TriMesh::total_memory_size`]) and the triangle → patch tables;
    /// without the patch list.
    pub fn mesh_memory_bytes(&self) -> usize {
        self.levels.capacity() * size_of::<Level>()
            + self.levels.iter().map(Level::memory_bytes).sum::<usize>()
    }
}

/// # Queries on the meshes
impl TrimeshMap {
    /// The hit of `patch` at `t`, whose triangles are in `level`; `tri` is one of them
    /// touched at `t`.
    fn hit<S: Step>(&self, level: &Level, tri: u32, t: Real, step: &S) -> StepHit {
        let patch = level.patch_of[tri as usize];
        let center = step.point_at(t);
        let (tri, point, _) =
            closest_on_triangles(&level.mesh, &center, tri, |i| level.patch_of[i as usize] == patch);
        let surface = triangle_normal(&level.mesh.triangle(tri));
        let normal = contact_normal(&self.patches[patch.index()], surface, &point, &center, step);
        StepHit { patch, t, point, normal }
    }

    /// Whether the segment `a → b` meets a triangle.
    fn segment_touches(&self, a: &Point3, b: &Point3) -> bool {
        let ray = Ray::new(*a, b - a);
        self.levels.iter().any(|level| {
            level
                .mesh
                .bvh()
                .leaves(|node: &BvhNode| node.aabb().cast_local_ray(&ray, 1.0, true).is_some())
                .any(|tri| segment_hits_triangle(&level.mesh.triangle(tri), &ray, b, 1.0).is_some())
        })
    }

    /// The first triangle the segment `a → b` meets: `(level, triangle, t)`.
    fn segment_first(&self, a: &Point3, b: &Point3) -> Option<(usize, u32, Real)> {
        let ray = Ray::new(*a, b - a);
        let mut best: Option<(usize, u32, Real)> = None;
        for (k, level) in self.levels.iter().enumerate() {
            let bound = best.map_or(AFTER_END, |b| b.2);
            let found = level.mesh.bvh().find_best(
                bound,
                |node: &BvhNode, best_t| node.cast_ray(&ray, best_t),
                |tri, best_t| segment_hits_triangle(&level.mesh.triangle(tri), &ray, b, best_t),
            );
            if let Some((tri, t)) = found {
                best = Some((k, tri, t));
            }
        }
        best
    }

    /// The triangle nearest to `point` within `max_dist` (inclusive): `(level, triangle,
    /// closest point, distance)`.
    fn nearest(&self, point: &Point3, max_dist: Real) -> Option<(usize, u32, Point3, Real)> {
        let mut best: Option<(usize, u32, Point3, Real)> = None;
        for (k, level) in self.levels.iter().enumerate() {
            // The search keeps distances strictly below its bound; a point at exactly
            // `max_dist` counts.
            let bound = best.map_or(max_dist.next_up(), |b| b.3);
            let found = CompositeShapeRef(&level.mesh)
                .project_local_point_and_get_location(point, bound, false);
            if let Some((tri, (proj, _))) = found {
                let d = (proj.point - point).norm();
                if d < bound {
                    best = Some((k, tri, proj.point, d));
                }
            }
        }
        best.filter(|b| b.3 <= max_dist)
    }

    /// Whether the capsule `a → b` of radius `r > 0` touches a triangle.
    fn capsule_touches(&self, a: &Point3, b: &Point3, r: Real) -> bool {
        if (b - a).norm() <= SHORT_STEP {
            return self.nearest(a, r).is_some();
        }
        let capsule = Capsule::new(*a, *b, r);
        let ray = Ray::new(*a, b - a);
        let identity = Isometry::identity();
        self.levels.iter().any(|level| {
            level
                .mesh
                .bvh()
                .leaves(|node: &BvhNode| {
                    node.aabb().loosened(r).cast_local_ray(&ray, 1.0, true).is_some()
                })
                .any(|tri| {
                    let triangle = level.mesh.triangle(tri);
                    parry3d_f64::query::intersection_test(&identity, &triangle, &identity, &capsule)
                        .unwrap_or(true)
                })
        })
    }

    /// The first contact of a ball of radius `r > 0` moving `a → b`: `(level, triangle, t)`.
    fn capsule_first(&self, a: &Point3, b: &Point3, r: Real) -> Option<(usize, u32, Real)> {
        if (b - a).norm() <= SHORT_STEP {
            return self.nearest(a, r).map(|(k, tri, _, _)| (k, tri, 0.0));
        }
        let ball = Ball::new(r);
        let start = Isometry::translation(a.x, a.y, a.z);
        let velocity = b - a;
        let mut best: Option<(usize, u32, Real)> = None;
        for (k, level) in self.levels.iter().enumerate() {
            let bound = best.map_or(AFTER_END, |b| b.2);
            let found = CompositeShapeRef(&level.mesh).cast_shape(
                &DefaultQueryDispatcher,
                &start,
                &velocity,
                &ball,
                cast_options(bound),
            );
            if let Some((tri, hit)) = found {
                let t = hit.time_of_impact.clamp(0.0, 1.0);
                if best.is_none_or(|b| t < b.2) {
                    best = Some((k, tri, t));
                }
            }
        }
        best
    }
}

fn finite(p: &Point3) -> bool {
    p.iter().all(|c| c.is_finite())
}

impl PatchMap for TrimeshMap {
    fn patches(&self) -> &[Patch] {
        &self.patches
    }

    fn bounds(&self) -> Aabb {
        self.bounds
    }
}

impl PatchMapMut for TrimeshMap {
    /// Adds a patch; amortised `O(k log² n)` for a patch of `k` triangles in a map of `n` (see
    /// the [module docs](self)). A planar patch that cannot be triangulated is refused as
    /// [`MapError::Unsupported`] ([`TrimeshMap::try_add_patch`] says why).
    fn add_patch(&mut self, patch: Patch) -> Result<PatchId, MapError> {
        let kind_of = patch.clone();
        self.try_add_patch(patch).map_err(|e| e.into_map_error(&kind_of))
    }
}

impl FromPatches for TrimeshMap {
    type Error = MeshMapError;

    fn from_patches(patches: impl IntoIterator<Item = Patch>) -> Result<Self, Self::Error> {
        TrimeshMap::build(patches)
    }
}

impl ProximityQuery for TrimeshMap {
    /// parry's point projection on each mesh (best-first on the BVH, pruned by the best
    /// distance so far); the distance is that of the projected point, exact to rounding.
    fn closest_patch(&self, point: &Point3, max_dist: Real) -> Option<Proximity> {
        if max_dist.is_nan() || max_dist < 0.0 || !finite(point) {
            return None;
        }
        self.nearest(point, max_dist).map(|(k, tri, q, d)| Proximity {
            patch: self.levels[k].patch_of[tri as usize],
            point: q,
            distance: d,
        })
    }
}

impl UnspecificStepIntersector<LineStep> for TrimeshMap {
    /// Any-hit ray casts (see the [module docs](self)).
    fn is_step_free(&self, step: &LineStep) -> bool {
        !self.segment_touches(&step.start(), &step.end())
    }
}

impl SpecificStepIntersector<LineStep> for TrimeshMap {
    /// Best-first ray casts (see the [module docs](self)).
    fn first_hit(&self, step: &LineStep) -> Option<StepHit> {
        let (k, tri, t) = self.segment_first(&step.start(), &step.end())?;
        Some(self.hit(&self.levels[k], tri, t, step))
    }
}

impl UnspecificStepIntersector<CapsuleStep> for TrimeshMap {
    /// GJK intersection tests of the capsule against the triangles near its segment (see the
    /// [module docs](self)).
    fn is_step_free(&self, step: &CapsuleStep) -> bool {
        let (a, b, r) = (step.start(), step.end(), step.radius());
        if r == 0.0 {
            !self.segment_touches(&a, &b)
        } else {
            !self.capsule_touches(&a, &b, r)
        }
    }
}

impl SpecificStepIntersector<CapsuleStep> for TrimeshMap {
    /// parry's shape cast of a ball (see the [module docs](self)).
    fn first_hit(&self, step: &CapsuleStep) -> Option<StepHit> {
        let (a, b, r) = (step.start(), step.end(), step.radius());
        let (k, tri, t) =
            if r == 0.0 { self.segment_first(&a, &b)? } else { self.capsule_first(&a, &b, r)? };
        Some(self.hit(&self.levels[k], tri, t, step))
    }
}

impl Serialize for TrimeshMap {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.patches.serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for TrimeshMap {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let patches = Vec::<Patch>::deserialize(deserializer)?;
        TrimeshMap::build(patches).map_err(serde::de::Error::custom)
    }
}
