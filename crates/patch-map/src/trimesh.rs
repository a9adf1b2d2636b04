//! The trimesh map: every patch as triangles in one compact triangle mesh with its bounding
//! volume hierarchy (the role of the thesis's OPCODE and Bullet maps, §5.4.2: "planar patches
//! are Delaunay-triangulated into trimeshes", the step is a sphere cast, L5572–5582), queried
//! with parry's per-triangle geometry.
//!
//! # Layout
//! * Planar patches are triangulated in their own 2D frame ([`triangulate_polygon`], a
//!   constrained Delaunay triangulation with holes, checked to tile the polygon) and the
//!   triangles mapped to the world by `world_from_patch`; trimesh patches are taken as they
//!   are.
//! * All triangles go into one compact mesh (no vertex merging, no topology): `f64` vertices,
//!   a `[u32; 3]` per triangle, and a BVH of 32-byte nodes with `f32` boxes rounded outwards
//!   and up to four triangles per leaf, built by the surface area heuristic; triangles and
//!   vertices are stored in the tree's order. A table `patch_of[triangle]` maps every triangle
//!   back to its [`PatchId`]. About 60 bytes per triangle plus the patches themselves
//!   (91 bytes per triangle in all on the lab's exact trimesh map; parry's `TriMesh`, with one
//!   `f64` BVH leaf per triangle, took 206).
//!
//! # Queries
//! Every query walks the mesh's BVH (best-first for first hits and nearest points, depth-first
//! for any-hit tests; at a leaf each triangle's own `f64` box is tested first) and runs
//! parry's per-triangle geometry on the triangles:
//!
//! | query | per triangle | degenerate branches |
//! |---|---|---|
//! | proximity | parry's point projection on each triangle the walk reaches | — |
//! | line step | parry's ray–triangle test along `end − start` | segments (nearly) parallel to the triangle, zero-length ones included: `patch-core`'s kernel in the triangle's frame ([`TriangleFrame::first_contact`] with radius 0) |
//! | capsule step, free? | the closed-form segment–triangle distance from parry's primitives (ray–triangle crossing, point projections of both ends, segment–segment closest points to the three edges), compared with `r`; boxes are pruned by casting the segment through them grown by `r` | zero length (below [`SHORT_STEP`]): point projection within `r`; radius 0: the line step |
//! | capsule step, first hit | on triangles within `r` of the segment (as above): parry's shape cast of a [`Ball`] moving `start → end` (`stop_at_penetration`, so a start that already touches gives `t = 0`) | the cast can miss grazing contacts (see below); for a triangle the distance test says is touched but the cast misses, `patch-core`'s exact sweep kernel gives the time ([`TriangleFrame::first_contact`]); zero length: a sphere test at the start; radius 0: the line step |
//!
//! The walk reports the triangle it hit, which names the patch (parry's
//! [`ShapeCastHit`](parry3d_f64::query::ShapeCastHit) has no triangle). The [`StepHit`] is then completed from the patch, not from parry's
//! witness points (which are undefined at `t = 0`): the contact point is the patch's point
//! closest to the sphere's centre at `t` (a projection restricted to that patch's triangles),
//! the normal is the plane normal of a planar patch or the normal of that closest triangle of
//! a trimesh patch, oriented by the rule of [`StepHit::normal`].
//!
//! # Accuracy, measured
//! * Point projections and segment–triangle distances are closed formulas: errors of a few
//!   ulps, except that parry's segment–segment closest points treat segments within a few
//!   ulps of parallel (`a·e ≈ b²`, angles below about 3e-8 rad) as parallel and then pick a
//!   pair that can be up to `angle × length` too far apart (1.2e-7 m measured over 10⁶ cases
//!   nearly parallel to an edge).
//! * parry's ball cast is GJK's ray cast on the Minkowski difference: it reports a *lower*
//!   bound of the time of impact (over 10⁶ random casts the sphere was at most 4.5e-6 m short
//!   of touching at the reported time, never penetrating by more than 1e-14 m; in the
//!   conformance scenes, with radii down to 1 mm, up to 1.1e-5 m short), and it can miss
//!   contacts that graze a vertex (32 of 10⁵ vertex-grazing casts penetrating by 1e-4 m were
//!   reported free), which is why the distance test decides *whether* a triangle is hit. The
//!   map checks the start first (a start within about 1e-7 m of touching got a small positive
//!   time from the cast), then tightens the cast's time by up to [`ADVANCE_STEPS`] steps of
//!   conservative advancement on the hit triangle (advance by the gap over the step length,
//!   which never passes the contact); oblique contacts converge slowly, and up to 3.3e-6 m
//!   remained in 40,000 conformance cases.
//! * Not used, because they can report colliding steps free: parry's GJK `intersection_test`
//!   of a [`Capsule`](parry3d_f64::shape::Capsule) against a triangle (7 missed contacts in
//!   10⁶ random cases, one by 0.55 m) and its GJK `distance` between a segment and a triangle
//!   (off by 33 m once in 10⁶); parry's ray–triangle test for nearly parallel segments (its
//!   barycentric coordinates become ratios of rounding-sized numbers: a hit 4.5 cm off the
//!   triangle was reported).
//!
//! Hence [`TrimeshMap::TOLERANCE`]: a numeric band of 1e-6 m (whether a step collides) and a
//! conservative margin of 1e-5 m (a first hit may come that much early); a colliding step is
//! never reported free beyond the numeric band.
//!
//! # Adding patches
//! A mesh is immutable (appending rebuilds it). [`FromPatches::from_patches`] and
//! loading build one mesh; [`PatchMapMut::add_patch`] uses the logarithmic method (Bentley and
//! Saxe): the new patch's triangles become a small mesh of their own, and while the newest
//! mesh holds at least half as many triangles as the one before it, the two are merged and
//! rebuilt. Mesh sizes thus at least double from newest to oldest: a map of `n` triangles has
//! at most `log₂ n + 1` meshes, every query walks each of them, and every triangle is rebuilt
//! `O(log n)` times, so an add of `k` triangles costs amortised `O(k log² n)` (a rebuild of `m`
//! triangles is the `O(m log m)` binned BVH build) plus the triangulation of the patch
//! (`O(v log v)` for `v` vertices). [`TrimeshMap::compact`] merges everything back into one
//! mesh.

use std::fmt;
use std::io::{Read, Write};

use parry3d_f64::bounding_volume::Aabb as BoxAabb;
use parry3d_f64::math::Isometry;
use parry3d_f64::query::details::closest_points_segment_segment_with_locations_nD;
use parry3d_f64::query::{
    DefaultQueryDispatcher, PointQuery as _, QueryDispatcher as _, Ray, RayCast as _,
    ShapeCastOptions,
};
use parry3d_f64::shape::{Ball, Segment, Triangle};
use patch_core::geometry::TriangleFrame;
use patch_core::{
    Aabb, CapsuleStep, FromPatches, LineStep, MapError, Patch, PatchId, PatchKind, PatchMap,
    PatchMapMut, PlanarPatch, Point2, Point3, Proximity, ProximityQuery, Real,
    SpecificStepIntersector, Step, StepHit, Tolerance, UnitVector3, UnspecificStepIntersector,
    Vector3,
};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::Backend;
use crate::compact_mesh::CompactMesh;
use crate::mapfile::{MapCounts, MapFileError, read_map, write_map};
use crate::persist::{MapFile, MemoryUsage, patch_counts, patches_memory_bytes};
use crate::triangulate::{TriangulationError, triangulate_polygon};

/// Steps shorter than this (in metres) are tested as a sphere at their start: parry's shape
/// cast treats a motion of length below about 2e-16 as no motion, and the end of such a step
/// is within rounding of its start anyway.
pub const SHORT_STEP: Real = 1e-12;

/// `|n̂ · d̂|` up to which a segment counts as parallel to a triangle's plane, so `patch-core`'s
/// kernel decides instead of parry's ray–triangle test (see [`segment_hits_triangle`]). Beyond
/// it, parry's barycentric coordinates have relative errors below about `1e-16 / PARALLEL`.
const PARALLEL: Real = 1e-6;

/// How much (in metres) boxes are grown before a probe is tested against them, so pruning
/// never drops a contact that parry's float slab test puts an ulp outside a box face. Far
/// below any tolerance, far above the rounding of coordinates up to 10⁶ m.
const PRUNE_SLACK: Real = 1e-9;

/// Conservative-advancement steps applied to parry's time of impact of a ball cast (see the
/// module docs, "Accuracy").
pub const ADVANCE_STEPS: usize = 4;

/// Just above 1: parry's best-first searches keep only costs strictly below their bound, and
/// a contact at exactly `t = 1` (the end touches) must count.
pub(crate) const AFTER_END: Real = 1.0 + Real::EPSILON;

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
    pub(crate) fn into_map_error(self, kind: PatchKind) -> MapError {
        match self {
            MeshMapError::Map(e) => e,
            _ => MapError::Unsupported { kind },
        }
    }
}

/// The next id, or [`MapError::TooManyPatches`].
pub(crate) fn next_id(len: usize) -> Result<PatchId, MapError> {
    u32::try_from(len).ok().filter(|&i| i < u32::MAX).map(PatchId).ok_or(MapError::TooManyPatches)
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

/// The options of every shape cast: times of impact below `max_t`; a start that already
/// touches stops the cast at 0.
fn cast_options(max_t: Real) -> ShapeCastOptions {
    ShapeCastOptions {
        max_time_of_impact: max_t,
        target_distance: 0.0,
        stop_at_penetration: true,
        compute_impact_geometry_on_penetration: false,
    }
}

/// The first time in `[0, max_t]` at which `ray.origin + t ray.dir` is inside the box grown by
/// `grow` (0 if the origin is inside): the slab test, with `inv` the componentwise inverse of
/// `ray.dir` (computed once per probe: the walks test many boxes). Equal to parry's `cast_local_ray` on the
/// grown box with `solid`, without building the grown box.
fn segment_enters_box(
    ray: &Ray,
    inv: &Vector3,
    aabb: &BoxAabb,
    grow: Real,
    max_t: Real,
) -> Option<Real> {
    let (mut t0, mut t1): (Real, Real) = (0.0, max_t);
    for k in 0..3 {
        let (lo, hi) = (aabb.mins[k] - grow, aabb.maxs[k] + grow);
        let (o, d) = (ray.origin[k], ray.dir[k]);
        if d == 0.0 {
            if o < lo || o > hi {
                return None;
            }
        } else {
            let (a, b) = ((lo - o) * inv[k], (hi - o) * inv[k]);
            let (a, b) = if a <= b { (a, b) } else { (b, a) };
            t0 = t0.max(a);
            t1 = t1.min(b);
            if t0 > t1 {
                return None;
            }
        }
    }
    Some(t0)
}

/// The distance between the segment `a b` and the edge `p q` (parry's closed form).
fn segment_segment_distance(a: &Point3, b: &Point3, p: &Point3, q: &Point3) -> Real {
    let (la, lb) = closest_points_segment_segment_with_locations_nD((a, b), (p, q));
    (Segment::new(*a, *b).point_at(&la) - Segment::new(*p, *q).point_at(&lb)).norm()
}

/// A step prepared for parry's queries, in the frame of the meshes it is run against: a
/// segment (radius 0, any length), a sphere (radius > 0, length up to [`SHORT_STEP`]) or a
/// sweep (radius > 0).
#[derive(Clone, Debug)]
pub(crate) enum Probe {
    /// A line step: the segment `ray.origin → b` (`ray` runs along `b − a`).
    Segment {
        /// The end.
        b: Point3,
        /// `a` along `b − a`.
        ray: Ray,
        /// `1 / (b − a)` componentwise, for the slab tests.
        inv: Vector3,
    },
    /// A sphere at `center` (a zero-length or very short step).
    Sphere {
        /// The centre.
        center: Point3,
        /// The radius, > 0.
        r: Real,
    },
    /// A sphere of radius `r > 0` swept from `a` to `b`.
    Sweep {
        /// The start.
        a: Point3,
        /// The end.
        b: Point3,
        /// The radius, > 0.
        r: Real,
        /// `a` along `b − a`.
        ray: Ray,
        /// `1 / (b − a)` componentwise, for the slab tests.
        inv: Vector3,
        /// The ball for parry's shape cast.
        ball: Ball,
    },
}

impl Probe {
    /// The probe of a step.
    pub(crate) fn of<S: Step>(step: &S) -> Probe {
        let (a, b, r) = (step.start(), step.end(), step.radius());
        if r == 0.0 {
            Probe::Segment { b, ray: Ray::new(a, b - a), inv: (b - a).map(|d| 1.0 / d) }
        } else if (b - a).norm() <= SHORT_STEP {
            Probe::Sphere { center: a, r }
        } else {
            let inv = (b - a).map(|d| 1.0 / d);
            Probe::Sweep { a, b, r, ray: Ray::new(a, b - a), inv, ball: Ball::new(r) }
        }
    }

    /// Whether the probe may touch something inside the box: conservative, the box is grown
    /// by [`PRUNE_SLACK`] (a float slab test can miss a contact exactly on a box face by an ulp).
    pub(crate) fn may_touch(&self, aabb: &BoxAabb) -> bool {
        match self {
            Probe::Segment { ray, inv, .. } => {
                segment_enters_box(ray, inv, aabb, PRUNE_SLACK, 1.0).is_some()
            }
            Probe::Sphere { center, r } => {
                aabb.distance_to_local_point(center, true) <= r + PRUNE_SLACK
            }
            Probe::Sweep { r, ray, inv, .. } => {
                segment_enters_box(ray, inv, aabb, r + PRUNE_SLACK, 1.0).is_some()
            }
        }
    }

    /// A lower bound of the first contact time with anything inside the box (grown by
    /// [`PRUNE_SLACK`]), if below `bound`; `Real::MAX` if none (the convention of the
    /// best-first searches).
    pub(crate) fn box_entry(&self, aabb: &BoxAabb, bound: Real) -> Real {
        let entry = match self {
            Probe::Segment { ray, inv, .. } => {
                segment_enters_box(ray, inv, aabb, PRUNE_SLACK, bound)
            }
            Probe::Sphere { .. } => self.may_touch(aabb).then_some(0.0),
            Probe::Sweep { r, ray, inv, .. } => {
                segment_enters_box(ray, inv, aabb, r + PRUNE_SLACK, bound)
            }
        };
        entry.unwrap_or(Real::MAX)
    }

    /// Whether the probe touches the triangle (see the module docs for the method).
    pub(crate) fn touches(&self, tri: &Triangle) -> bool {
        match self {
            Probe::Segment { b, ray, .. } => segment_hits_triangle(tri, ray, b, 1.0).is_some(),
            Probe::Sphere { center, r } => {
                (tri.project_local_point(center, false).point - center).norm() <= *r
            }
            Probe::Sweep { a, b, r, ray, .. } => {
                let r = *r;
                let near = |p: &Point3| (tri.project_local_point(p, false).point - p).norm() <= r;
                near(a)
                    || near(b)
                    || segment_segment_distance(a, b, &tri.a, &tri.b) <= r
                    || segment_segment_distance(a, b, &tri.b, &tri.c) <= r
                    || segment_segment_distance(a, b, &tri.c, &tri.a) <= r
                    || segment_hits_triangle(tri, ray, b, 1.0).is_some()
            }
        }
    }

    /// The first contact time with the triangle, if below `bound`.
    pub(crate) fn first_contact(&self, tri: &Triangle, bound: Real) -> Option<Real> {
        let t = match self {
            Probe::Segment { b, ray, .. } => segment_hits_triangle(tri, ray, b, bound)?,
            Probe::Sphere { .. } => {
                if !self.touches(tri) {
                    return None;
                }
                0.0
            }
            Probe::Sweep { a, b, r, ray, ball, .. } => {
                if !self.touches(tri) {
                    return None;
                }
                let r = *r;
                let gap = |t: Real| {
                    let c = a + ray.dir * t;
                    (tri.project_local_point(&c, false).point - c).norm() - r
                };
                if gap(0.0) <= 0.0 {
                    // The start touches; parry's cast would report a tiny positive time when
                    // the start is within about 1e-7 m of touching.
                    return (0.0 < bound).then_some(0.0);
                }
                let start = Isometry::translation(a.x, a.y, a.z);
                match DefaultQueryDispatcher.cast_shapes(
                    &start,
                    &ray.dir,
                    tri,
                    ball,
                    cast_options(bound),
                ) {
                    Ok(Some(hit)) => {
                        // parry's time is a lower bound (up to about 1e-5 m early); conservative
                        // advancement on this triangle tightens it without passing the contact.
                        let len = ray.dir.norm();
                        let mut t = hit.time_of_impact.clamp(0.0, 1.0);
                        for _ in 0..ADVANCE_STEPS {
                            let g = gap(t);
                            if g <= 0.0 {
                                break;
                            }
                            let next = (t + g / len).min(1.0);
                            if next <= t {
                                break;
                            }
                            t = next;
                        }
                        t
                    }
                    // A contact the cast missed (grazing), or one at or after `bound`.
                    _ => TriangleFrame::new(&[tri.a, tri.b, tri.c])?.first_contact(a, b, r)?.t,
                }
            }
        };
        (t < bound).then_some(t)
    }

    /// Whether the probe touches a triangle of the mesh.
    pub(crate) fn touches_mesh(&self, mesh: &CompactMesh) -> bool {
        mesh.any_triangle(|aabb| self.may_touch(aabb), |tri| self.touches(&mesh.triangle(tri)))
    }

    /// The first triangle of the mesh the probe touches before `bound`: `(triangle, t)`.
    pub(crate) fn first_in_mesh(&self, mesh: &CompactMesh, bound: Real) -> Option<(u32, Real)> {
        mesh.find_best(
            bound,
            |aabb, best| self.box_entry(aabb, best),
            |tri, best| self.first_contact(&mesh.triangle(tri), best),
        )
    }
}

/// The triangle of the mesh nearest to `point`, if closer than `bound`: `(triangle, closest
/// point, distance)` (best-first over the boxes, parry's point projection on the triangles).
fn mesh_nearest(mesh: &CompactMesh, point: &Point3, bound: Real) -> Option<(u32, Point3, Real)> {
    let (tri, (d, q)) = mesh.find_best(
        bound,
        |aabb, _| aabb.distance_to_local_point(point, true),
        |tri, _| {
            let q = mesh.triangle(tri).project_local_point(point, false).point;
            Some(((q - point).norm(), q))
        },
    )?;
    Some((tri, q, d))
}

/// The closest point of a mesh to `point` among the triangles accepted by `keep`, starting
/// from triangle `first` (which must be accepted): `(triangle, point, distance)`.
pub(crate) fn closest_on_triangles(
    mesh: &CompactMesh,
    point: &Point3,
    first: u32,
    keep: impl Fn(u32) -> bool,
) -> (u32, Point3, Real) {
    let project = |tri: u32| {
        let q = mesh.triangle(tri).project_local_point(point, false).point;
        ((q - point).norm(), q)
    };
    let (d0, q0) = project(first);
    mesh.find_best(
        d0,
        |aabb, _| aabb.distance_to_local_point(point, true),
        |tri, _| keep(tri).then(|| project(tri)),
    )
    .map_or((first, q0, d0), |(tri, (d, q))| (tri, q, d))
}

/// The hit of a step on `patch` at `t`, whose triangles in `mesh` are those accepted by
/// `keep`; `tri` is one of them touched at `t`.
pub(crate) fn complete_hit<S: Step>(
    mesh: &CompactMesh,
    tri: u32,
    keep: impl Fn(u32) -> bool,
    id: PatchId,
    patch: &Patch,
    t: Real,
    step: &S,
) -> StepHit {
    let center = step.point_at(t);
    let (tri, point, _) = closest_on_triangles(mesh, &center, tri, keep);
    let surface = triangle_normal(&mesh.triangle(tri));
    let normal = contact_normal(patch, surface, &point, &center, step);
    StepHit { patch: id, t, point, normal }
}

fn finite(p: &Point3) -> bool {
    p.iter().all(|c| c.is_finite())
}

/// Whether `closest_patch` has an answer at all: a finite point and a non-negative
/// `max_dist`.
pub(crate) fn valid_proximity_query(point: &Point3, max_dist: Real) -> bool {
    !(max_dist.is_nan() || max_dist < 0.0) && finite(point)
}

/// One immutable mesh and the patch of each of its triangles.
#[derive(Clone)]
struct Level {
    mesh: CompactMesh,
    patch_of: Vec<PatchId>,
}

impl Level {
    /// The mesh of these triangles; `None` if there are none.
    fn build(
        vertices: Vec<Point3>,
        indices: Vec<[u32; 3]>,
        patch_of: Vec<PatchId>,
    ) -> Option<Level> {
        // The build reorders the triangles and `patch_of` with them.
        let (mesh, patch_of) = CompactMesh::build(vertices, indices, patch_of)?;
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

    /// The mesh's heap (vertices, indices and BVH nodes, by capacity) and the triangle → patch
    /// table.
    fn heap_bytes(&self) -> usize {
        self.mesh.heap_bytes() + self.patch_of.capacity() * size_of::<PatchId>()
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
    /// A builder with room for the patches' triangles (a planar patch of `n` vertices and `h`
    /// holes triangulates into at most `n` vertices and `n + 2h − 2` triangles), so the buffers
    /// never grow by doubling past what they hold.
    fn for_patches(patches: &[Patch]) -> MeshBuilder {
        let (v, t) = patches.iter().fold((0, 0), |(v, t), patch| match patch {
            Patch::Planar(p) => {
                let (n, h) = (p.polygon().num_vertices(), p.polygon().holes().len());
                (v + n, t + (n + 2 * h).saturating_sub(2))
            }
            Patch::Trimesh(m) => (v + m.vertices().len(), t + m.triangles().len()),
        });
        MeshBuilder {
            vertices: Vec::with_capacity(v),
            indices: Vec::with_capacity(t),
            patch_of: Vec::with_capacity(t),
        }
    }

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

/// The trimesh map (thesis §5.4.2, the OPCODE/Bullet role): all patches as triangles in one
/// compact mesh with its BVH; see the [module docs](self) for the queries, their
/// degenerate branches, the measured accuracy and the cost of adding patches.
///
/// Implements every capability: [`PatchMap`], [`PatchMapMut`], [`FromPatches`],
/// [`ProximityQuery`], and the unspecific and specific step intersectors for [`LineStep`] and
/// [`CapsuleStep`], within [`TrimeshMap::TOLERANCE`].
///
/// # Complexity
/// With `n` triangles in all: queries are BVH walks, `O(log n)` for well-spread triangles and
/// short steps, on each of at most `log₂ n + 1` meshes (one after
/// [`FromPatches::from_patches`] or [`TrimeshMap::compact`]); building is `O(n log n)`.
///
/// # Example
/// ```
/// use patch_core::{
///     CapsuleStep, FromPatches, Isometry3, PlanarPatch, Point2, Point3,
///     SpecificStepIntersector, UnspecificStepIntersector,
/// };
/// use patch_map::TrimeshMap;
///
/// let floor =
///     PlanarPatch::rectangle(Isometry3::identity(), Point2::new(0.0, 0.0), Point2::new(4.0, 3.0))?;
/// let map = TrimeshMap::from_patches([floor.into()])?;
/// assert_eq!(map.num_triangles(), 2);
/// let fall = CapsuleStep::new(Point3::new(1.0, 1.0, 1.0), Point3::new(1.0, 1.0, -1.0), 0.25)?;
/// assert!(!map.is_step_free(&fall));
/// let hit = map.first_hit(&fall).unwrap();
/// assert!((hit.t - 0.375).abs() < 1e-5); // the sphere touches at height 0.25
/// assert!(hit.normal.z > 0.99);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
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
    /// The declared tolerance: a numeric band of 1e-6 m and a conservative margin of 1e-5 m.
    ///
    /// Measured (see the [module docs](self)): parry's segment–segment closest points can be
    /// 1.2e-7 m off for segments within 3e-8 rad of parallel (the numeric band: whether a step
    /// collides is decided by distances exact up to that); its ball cast reports contacts early,
    /// up to 1.1e-5 m before conservative advancement and 3.3e-6 m after it, never late (the
    /// conservative margin: a first hit may come that much before the sphere touches).
    /// Everything else is exact to a few ulps.
    pub const TOLERANCE: Tolerance = Tolerance { numeric: 1e-6, conservative: 1e-5 };

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
        let mut builder = MeshBuilder::for_patches(&patches);
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
    /// `O(n log n)`. Meshes that together would exceed `u32::MAX` vertices stay separate.
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
    /// Gives the patches back, in id order (the meshes are dropped).
    pub fn into_patches(self) -> Vec<Patch> {
        self.patches
    }

    /// The number of triangles (of all patches).
    pub fn num_triangles(&self) -> usize {
        self.levels.iter().map(Level::len).sum()
    }

    /// The number of meshes the triangles are in (1 after building at once or
    /// [`compact`](Self::compact), at most `log₂ n + 1` after incremental adds; 0 when empty).
    pub fn num_meshes(&self) -> usize {
        self.levels.len()
    }

    /// Every triangle of the map with the patch it belongs to, mesh by mesh.
    pub fn triangles(&self) -> impl Iterator<Item = ([Point3; 3], PatchId)> + '_ {
        self.levels.iter().flat_map(|level| {
            level.patch_of.iter().enumerate().map(|(i, &id)| {
                let t = level.mesh.triangle(i as u32);
                ([t.a, t.b, t.c], id)
            })
        })
    }

    /// The heap bytes of the meshes (vertices, indices and BVH nodes, by capacity) and of the
    /// triangle → patch tables; without the patch list.
    pub fn mesh_memory_bytes(&self) -> usize {
        self.levels.capacity() * size_of::<Level>()
            + self.levels.iter().map(Level::heap_bytes).sum::<usize>()
    }
}

/// # Queries on the meshes
impl TrimeshMap {
    /// Whether the probe touches any triangle.
    fn touches(&self, probe: &Probe) -> bool {
        self.levels.iter().any(|level| probe.touches_mesh(&level.mesh))
    }

    /// The first contact of the step, completed to a [`StepHit`].
    fn first<S: Step>(&self, step: &S) -> Option<StepHit> {
        let probe = Probe::of(step);
        let mut best: Option<(usize, u32, Real)> = None;
        for (k, level) in self.levels.iter().enumerate() {
            let bound = best.map_or(AFTER_END, |b| b.2);
            if let Some((tri, t)) = probe.first_in_mesh(&level.mesh, bound) {
                best = Some((k, tri, t));
            }
        }
        let (k, tri, t) = best?;
        let level = &self.levels[k];
        let id = level.patch_of[tri as usize];
        let keep = |i: u32| level.patch_of[i as usize] == id;
        Some(complete_hit(&level.mesh, tri, keep, id, &self.patches[id.index()], t, step))
    }
}

impl PatchMap for TrimeshMap {
    fn patches(&self) -> &[Patch] {
        &self.patches
    }

    fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// [`TrimeshMap::TOLERANCE`]: parry's GJK decides grazing contacts to a relative precision.
    fn tolerance(&self) -> patch_core::Tolerance {
        Self::TOLERANCE
    }
}

impl PatchMapMut for TrimeshMap {
    /// Adds a patch; amortised `O(k log² n)` for a patch of `k` triangles in a map of `n` (see
    /// the [module docs](self)). A planar patch that cannot be triangulated is refused as
    /// [`MapError::Unsupported`] ([`TrimeshMap::try_add_patch`] says why).
    fn add_patch(&mut self, patch: Patch) -> Result<PatchId, MapError> {
        let kind = patch.kind();
        self.try_add_patch(patch).map_err(|e| e.into_map_error(kind))
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
        if !valid_proximity_query(point, max_dist) {
            return None;
        }
        // The searches keep distances strictly below their bound; one of exactly `max_dist`
        // counts.
        let mut bound = max_dist.next_up();
        let mut best = None;
        for level in &self.levels {
            if let Some((tri, q, d)) = mesh_nearest(&level.mesh, point, bound) {
                bound = d;
                best =
                    Some(Proximity { patch: level.patch_of[tri as usize], point: q, distance: d });
            }
        }
        best
    }
}

impl UnspecificStepIntersector<LineStep> for TrimeshMap {
    /// Any-hit ray casts (see the [module docs](self)).
    fn is_step_free(&self, step: &LineStep) -> bool {
        !self.touches(&Probe::of(step))
    }
}

impl SpecificStepIntersector<LineStep> for TrimeshMap {
    /// Best-first ray casts (see the [module docs](self)).
    fn first_hit(&self, step: &LineStep) -> Option<StepHit> {
        self.first(step)
    }
}

impl UnspecificStepIntersector for TrimeshMap {
    /// Closed-form segment–triangle distances on the triangles near the segment (see the
    /// [module docs](self)).
    fn is_step_free(&self, step: &CapsuleStep) -> bool {
        !self.touches(&Probe::of(step))
    }
}

impl SpecificStepIntersector for TrimeshMap {
    /// parry's ball cast on the triangles within the radius (see the [module docs](self)).
    fn first_hit(&self, step: &CapsuleStep) -> Option<StepHit> {
        self.first(step)
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

impl MapFile for TrimeshMap {
    const BACKEND: Backend = Backend::Trimesh;

    /// Writes the patch list (in id order; the mesh is not stored).
    fn save(&self, writer: impl Write) -> Result<u64, MapFileError> {
        write_map(writer, Self::BACKEND.name(), self.counts(), &self.patches)
    }

    /// Reads the patch list and rebuilds the mesh and its BVH (one mesh, `O(n log n)`).
    fn load(reader: impl Read) -> Result<Self, MapFileError> {
        let (_, patches): (_, Vec<Patch>) = read_map(reader, Some(Self::BACKEND.name()))?;
        TrimeshMap::build(patches).map_err(|e| MapFileError::Decode(e.to_string()))
    }

    /// The patch counts, with the triangles of the mesh (planar patches' included).
    fn counts(&self) -> MapCounts {
        MapCounts { triangles: self.num_triangles() as u64, ..patch_counts(&self.patches) }
    }
}

impl MemoryUsage for TrimeshMap {
    /// The patch list ([`patches_memory_bytes`]) and the meshes
    /// ([`TrimeshMap::mesh_memory_bytes`]: parry's count of vertices, indices and BVH nodes
    /// from their capacities, and the triangle → patch tables). parry's count is exact for the
    /// buffers it names; nothing else is allocated by the map.
    fn memory_bytes(&self) -> usize {
        patches_memory_bytes(&self.patches) + self.mesh_memory_bytes()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::load_any;
    use crate::persist::AnyMap;
    use patch_core::conformance::SceneKind;
    use patch_core::conformance::strategies::{scene_with_capsule_steps, scene_with_points};
    use patch_core::{Isometry3, Polygon, TrimeshPatch, na};
    use proptest::prelude::*;

    fn square(a: Real, b: Real) -> Vec<Point2> {
        vec![Point2::new(a, a), Point2::new(b, a), Point2::new(b, b), Point2::new(a, b)]
    }

    /// A floor with a hole, a wall at x = 4 facing −x, and a two-triangle mesh above.
    fn scene() -> Vec<Patch> {
        let floor = PlanarPatch::new(
            Polygon::new(square(0.0, 4.0), vec![square(1.0, 2.0)]).unwrap(),
            Isometry3::identity(),
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
        let mesh = TrimeshPatch::new(
            vec![
                Point3::new(0.0, 0.0, 3.0),
                Point3::new(2.0, 0.0, 3.5),
                Point3::new(2.0, 2.0, 3.0),
                Point3::new(0.0, 2.0, 3.5),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        )
        .unwrap();
        vec![floor.into(), wall.into(), mesh.into()]
    }

    fn line(a: [Real; 3], b: [Real; 3]) -> LineStep {
        LineStep::new(Point3::from(a), Point3::from(b)).unwrap()
    }

    fn capsule(a: [Real; 3], b: [Real; 3], r: Real) -> CapsuleStep {
        CapsuleStep::new(Point3::from(a), Point3::from(b), r).unwrap()
    }

    #[test]
    fn every_triangle_lies_on_its_patch_and_tiles_it() {
        let patches = scene();
        let map = TrimeshMap::from_patches(patches.clone()).unwrap();
        assert_eq!(map.num_meshes(), 1);
        // Floor with a hole: 8 vertices, 1 hole → 8 triangles; wall 2; mesh 2.
        assert_eq!(map.num_triangles(), 12);
        let mut area = [0.0; 3];
        for ([a, b, c], id) in map.triangles() {
            let patch = &patches[id.index()];
            for p in [a, b, c, Point3::from((a.coords + b.coords + c.coords) / 3.0)] {
                assert!(patch.closest_point(&p).distance < 1e-12, "{p} off {id}");
            }
            area[id.index()] += 0.5 * (b - a).cross(&(c - a)).norm();
        }
        for (i, patch) in patches.iter().enumerate() {
            assert!(
                (area[i] - patch.area()).abs() < 1e-12,
                "patch {i}: {} vs {}",
                area[i],
                patch.area()
            );
            assert_eq!(
                map.triangles().filter(|(_, id)| id.index() == i).count(),
                patch.num_triangles_hint()
            );
        }
    }

    #[test]
    fn hits_name_the_right_patch_with_its_normal() {
        let map = TrimeshMap::from_patches(scene()).unwrap();
        // Down onto the floor (not over the hole).
        let hit = map.first_hit(&line([0.5, 0.5, 1.0], [0.5, 0.5, -1.0])).unwrap();
        assert_eq!(hit.patch, PatchId(0));
        assert!((hit.t - 0.5).abs() < 1e-12 && hit.normal.z == 1.0);
        // Up from below: the floor's normal flips toward the start.
        let hit = map.first_hit(&line([0.5, 0.5, -1.0], [0.5, 0.5, 1.0])).unwrap();
        assert_eq!(hit.patch, PatchId(0));
        assert!((hit.normal.z + 1.0).abs() < 1e-12);
        // Through the hole: the mesh above is hit first.
        let hit = map.first_hit(&line([1.5, 1.5, -1.0], [1.5, 1.5, 5.0])).unwrap();
        assert_eq!(hit.patch, PatchId(2));
        assert!(hit.normal.z < 0.0, "faces the start below: {:?}", hit.normal);
        // A capsule toward the wall touches it at x = 4 − r.
        let hit = map.first_hit(&capsule([1.0, 3.0, 1.0], [6.0, 3.0, 1.0], 0.25)).unwrap();
        assert_eq!(hit.patch, PatchId(1));
        assert!((hit.t - 2.75 / 5.0).abs() < 1e-5, "{}", hit.t);
        assert!((hit.normal.x + 1.0).abs() < 1e-12);
        assert!((hit.point - Point3::new(4.0, 3.0, 1.0)).norm() < 1e-5);
        // Proximity: the wall is 0.5 away, the floor 1.
        let q = Point3::new(3.5, 3.0, 1.0);
        let p = map.closest_patch(&q, Real::INFINITY).unwrap();
        assert_eq!(p.patch, PatchId(1));
        assert!((p.distance - 0.5).abs() < 1e-12);
        assert!((p.point - Point3::new(4.0, 3.0, 1.0)).norm() < 1e-12);
        assert!(map.closest_patch(&q, 0.25).is_none());
        assert_eq!(map.closest_patch(&q, 0.5).unwrap().patch, PatchId(1), "max_dist is inclusive");
        assert!(map.closest_patch(&Point3::new(Real::NAN, 0.0, 0.0), 1.0).is_none());
        assert!(map.closest_patch(&Point3::origin(), -1.0).is_none());
    }

    #[test]
    fn degenerate_steps_follow_the_contract() {
        let map = TrimeshMap::from_patches(scene()).unwrap();
        // Zero-length line steps: on the floor, over the hole, in the air.
        assert!(!map.is_step_free(&line([0.5, 0.5, 0.0], [0.5, 0.5, 0.0])));
        assert!(map.is_step_free(&line([1.5, 1.5, 0.0], [1.5, 1.5, 0.0])));
        assert!(map.is_step_free(&line([0.5, 0.5, 0.1], [0.5, 0.5, 0.1])));
        let hit = map.first_hit(&line([0.5, 0.5, 0.0], [0.5, 0.5, 0.0])).unwrap();
        assert_eq!((hit.patch, hit.t), (PatchId(0), 0.0));
        assert_eq!(hit.normal.z, 1.0, "a step in the plane gets the patch's own normal");
        // A line in the floor's plane, starting over the hole and leaving it at x = 2.
        let hit = map.first_hit(&line([1.5, 1.5, 0.0], [3.5, 1.5, 0.0])).unwrap();
        assert_eq!(hit.patch, PatchId(0));
        assert!((hit.t - 0.25).abs() < 1e-12, "{}", hit.t);
        assert!(!map.is_step_free(&line([1.5, 1.5, 0.0], [3.5, 1.5, 0.0])));
        // In the plane but outside the floor.
        assert!(map.is_step_free(&line([-1.0, -1.0, 0.0], [-1.0, 5.0, 0.0])));
        // Radius 0 capsules are line steps.
        let c = capsule([1.5, 1.5, 0.0], [3.5, 1.5, 0.0], 0.0);
        assert_eq!(map.first_hit(&c), map.first_hit(&c.line()));
        // Zero-length capsules are sphere tests, touching counts.
        assert!(!map.is_step_free(&capsule([0.5, 0.5, 0.25], [0.5, 0.5, 0.25], 0.25)));
        assert!(map.is_step_free(&capsule([0.5, 0.5, 0.25], [0.5, 0.5, 0.25], 0.2499)));
        let hit = map.first_hit(&capsule([0.5, 0.5, 0.25], [0.5, 0.5, 0.25], 0.3)).unwrap();
        assert_eq!((hit.patch, hit.t), (PatchId(0), 0.0));
        assert!((hit.point - Point3::new(0.5, 0.5, 0.0)).norm() < 1e-12);
        // Very short steps are sphere tests at their start.
        let short = capsule([0.5, 0.5, 0.3], [0.5, 0.5, 0.3 - 1e-13], 0.3);
        assert_eq!(map.first_hit(&short).map(|h| h.t), Some(0.0));
        // A sphere sliding along the floor at height r touches from the start; just above, it
        // is free.
        assert_eq!(
            map.first_hit(&capsule([0.5, 0.5, 0.25], [3.0, 3.5, 0.25], 0.25)).unwrap().t,
            0.0
        );
        assert!(map.is_step_free(&capsule([0.5, 0.5, 0.26], [3.5, 0.5, 0.26], 0.25)));
        // Starting inside the hole's column, sliding into the floor at height r/2.
        let hit = map.first_hit(&capsule([1.5, 1.5, 0.1], [1.5, 3.5, 0.1], 0.2)).unwrap();
        assert_eq!(hit.patch, PatchId(0));
        assert!(hit.t > 0.0 && hit.t < 0.25, "{}", hit.t);
        assert!(hit.normal.z > 0.0);
        // The empty map.
        let empty = TrimeshMap::new();
        assert!(empty.is_step_free(&capsule([0.0; 3], [1.0; 3], 1.0)));
        assert!(empty.first_hit(&line([0.0; 3], [1.0; 3])).is_none());
        assert!(empty.closest_patch(&Point3::origin(), Real::INFINITY).is_none());
        assert!(empty.bounds().is_empty());
    }

    /// A segment almost in a triangle's plane, 4.5 cm off the triangle: parry's ray–triangle
    /// test reports a hit (its barycentric coordinates are ratios of rounding-sized numbers).
    #[test]
    fn nearly_parallel_segments_are_not_hits() {
        let tri = [
            Point3::new(-0.954284478668633, 0.4255379585000465, -2.760283098389448),
            Point3::new(0.5352039953631125, 1.1704945309809376, -1.1809708494308009),
            Point3::new(0.17624640365724897, 0.13160716409188472, -2.5416311037407935),
        ];
        let a = Point3::new(-0.3155386596756419, -0.3439741004179231, -3.324942294977837);
        let b = Point3::new(0.0051460015697198935, 0.14634896257784513, -2.608643727929932);
        let ray = Ray::new(a, b - a);
        let t = Triangle::new(tri[0], tri[1], tri[2]);
        assert!(t.cast_local_ray(&ray, 1.0, true).is_some(), "parry's answer changed");
        assert!(segment_hits_triangle(&t, &ray, &b, 1.0).is_none());
        let mesh = TrimeshPatch::new(tri.to_vec(), vec![[0, 1, 2]]).unwrap();
        let map = TrimeshMap::from_patches([mesh.into()]).unwrap();
        assert!(map.is_step_free(&LineStep::new(a, b).unwrap()));
    }

    #[test]
    fn patches_that_cannot_be_triangulated_are_errors() {
        // Valid for patch-core, beyond the range of spade's exact predicates.
        let huge = PlanarPatch::new(
            Polygon::rectangle(Point2::new(0.0, 0.0), Point2::new(1e61, 1e61)).unwrap(),
            Isometry3::identity(),
        )
        .unwrap();
        let err =
            TrimeshMap::from_patches(scene().into_iter().chain([huge.clone().into()])).unwrap_err();
        assert!(matches!(err, MeshMapError::Triangulation { patch: 3, .. }), "{err}");
        let mut map = TrimeshMap::from_patches(scene()).unwrap();
        let before = map.num_triangles();
        assert_eq!(
            map.add_patch(huge.clone().into()),
            Err(MapError::Unsupported { kind: PatchKind::Planar })
        );
        assert!(matches!(map.try_add_patch(huge.into()), Err(MeshMapError::Triangulation { .. })));
        assert_eq!((map.len(), map.num_triangles()), (3, before), "unchanged on error");
    }

    #[test]
    fn adds_keep_few_meshes_and_compact_merges_them() {
        let mut map = TrimeshMap::new();
        let mut n = 0;
        for i in 0..200 {
            let x = Real::from(i);
            let p = PlanarPatch::rectangle(
                Isometry3::translation(x, 0.0, 0.0),
                Point2::new(0.0, 0.0),
                Point2::new(0.5, 0.5),
            )
            .unwrap();
            assert_eq!(map.add_patch(p.into()), Ok(PatchId(i)));
            n += 2;
            assert_eq!(map.num_triangles(), n);
            assert!(
                map.num_meshes() as f64 <= (n as f64).log2() + 1.0,
                "{} meshes",
                map.num_meshes()
            );
        }
        let hit = map.first_hit(&line([137.25, 0.25, 1.0], [137.25, 0.25, -1.0])).unwrap();
        assert_eq!(hit.patch, PatchId(137));
        map.compact();
        assert_eq!(map.num_meshes(), 1);
        assert_eq!(map.first_hit(&line([137.25, 0.25, 1.0], [137.25, 0.25, -1.0])), Some(hit));
    }

    #[test]
    fn map_files_round_trip() {
        let map = TrimeshMap::from_patches(scene()).unwrap();
        let mut buf = Vec::new();
        let n = map.save(&mut buf).unwrap();
        assert_eq!(n as usize, buf.len());
        let back = TrimeshMap::load(&buf[..]).unwrap();
        assert_eq!(back.patches(), map.patches());
        assert_eq!(back.counts(), map.counts());
        assert_eq!(
            map.counts(),
            MapCounts { planar_patches: 2, trimesh_patches: 1, triangles: 12, points: 0 }
        );
        let step = capsule([0.5, 3.0, 1.0], [5.0, 3.0, 1.0], 0.3);
        assert_eq!(back.first_hit(&step), map.first_hit(&step));
        let any = load_any(&buf[..]).unwrap();
        assert!(matches!(any, AnyMap::Trimesh(_)));
        assert_eq!(any.backend(), Backend::Trimesh);
        assert_eq!(any.patches(), Some(map.patches()));
        #[cfg(feature = "rapier")]
        assert!(matches!(
            crate::RapierMap::load(&buf[..]),
            Err(MapFileError::BackendMismatch { .. })
        ));
        // Serde gives the patch list.
        let json = serde_json_like(&map);
        assert_eq!(json, serde_json_like(&back));
    }

    /// The serialised form through bincode (the crate's payload codec).
    fn serde_json_like(map: &TrimeshMap) -> Vec<u8> {
        bincode::serde::encode_to_vec(map, bincode::config::standard()).unwrap()
    }

    #[test]
    fn memory_counts_the_meshes() {
        let empty = TrimeshMap::new();
        assert_eq!(empty.memory_bytes(), 0);
        let map = TrimeshMap::from_patches(scene()).unwrap();
        let mesh = map.mesh_memory_bytes();
        // At least the vertices, indices and triangle → patch table.
        assert!(mesh >= 12 * (size_of::<[u32; 3]>() + size_of::<PatchId>()) + 16 * 24, "{mesh}");
        assert_eq!(map.memory_bytes(), patches_memory_bytes(&map.patches) + mesh);
    }

    fn assert_send_sync<T: Send + Sync>() {}

    #[test]
    fn maps_are_send_and_sync() {
        assert_send_sync::<TrimeshMap>();
    }

    proptest! {
        #![proptest_config(ProptestConfig {
            cases: 64,
            failure_persistence: None,
            rng_seed: proptest::test_runner::RngSeed::Fixed(0x5eed_2010),
            ..ProptestConfig::default()
        })]

        /// A map grown patch by patch (several meshes) answers like one built at once (one
        /// mesh): the same triangles, so the same distances and times; only ties between
        /// patches may go another way.
        #[test]
        fn incremental_adds_answer_like_a_map_built_at_once(
            (patches, steps) in scene_with_capsule_steps(SceneKind::Mixed, 0..=8, 1..=16)
        ) {
            let whole = TrimeshMap::from_patches(patches.clone()).unwrap();
            let mut grown = TrimeshMap::new();
            for p in &patches {
                grown.add_patch(p.clone()).unwrap();
            }
            prop_assert_eq!(grown.patches(), whole.patches());
            prop_assert_eq!(grown.bounds(), whole.bounds());
            prop_assert_eq!(grown.num_triangles(), whole.num_triangles());
            for s in &steps {
                prop_assert_eq!(grown.is_step_free(s), whole.is_step_free(s));
                prop_assert_eq!(grown.first_hit(s).map(|h| h.t), whole.first_hit(s).map(|h| h.t));
                let l = s.line();
                prop_assert_eq!(grown.is_step_free(&l), whole.is_step_free(&l));
                prop_assert_eq!(grown.first_hit(&l).map(|h| h.t), whole.first_hit(&l).map(|h| h.t));
                let c = s.start();
                prop_assert_eq!(
                    grown.closest_patch(&c, Real::INFINITY).map(|p| p.distance),
                    whole.closest_patch(&c, Real::INFINITY).map(|p| p.distance)
                );
            }
        }

        /// Every answer of the map is on a patch the point query agrees with.
        #[test]
        fn nearest_points_lie_on_their_patch(
            (patches, points) in scene_with_points(SceneKind::Mixed, 1..=6, 1..=16)
        ) {
            let map = TrimeshMap::from_patches(patches.clone()).unwrap();
            for p in &points {
                let near = map.closest_patch(p, Real::INFINITY).unwrap();
                prop_assert!(patches[near.patch.index()].closest_point(&near.point).distance < 1e-9);
                prop_assert!((na::distance(&near.point, p) - near.distance).abs() < 1e-12);
            }
        }
    }
}
