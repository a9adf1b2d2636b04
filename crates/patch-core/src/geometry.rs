//! Exact-as-floats geometric kernels: the narrow phase every backend can share.
//!
//! Most kernels work in the **local frame of a planar region**: the region lies in the plane
//! `z = 0` and is described by a [`PlanarRegion`] (a [`Polygon`] with holes, or a
//! [`Triangle2`]). A caller holding a patch transforms its query into that frame first
//! (`patch_from_world = world_from_patch.inverse()`) and the results back; the
//! patch types do exactly that in their query methods ([`PlanarPatch::first_contact`] etc.).
//! [`TriangleFrame`] gives a triangle in 3D such a frame.
//!
//! "Exact as floats" means: every yes/no decision that can be made by an exact predicate is
//! (`orient2d` for point-in-polygon and segment crossings, `orient3d` for
//! [`segment_triangle_intersection`]); constructed values (distances, parameters, points) are
//! floating-point results of closed formulas, evaluated so that no division happens before
//! its result has been checked to lie in range (compare before divide), and every degenerate
//! configuration (zero-length segments, parallel segments, segments in the plane, zero radius)
//! has its own branch and test. Their error is a few ulps of the coordinates involved.
//!
//! The distance semantics follow spec §3.3 and §7.6 of the project (Euclidean point-to-region
//! distance; a capsule collides with a region iff the distance between its core segment and the
//! region is at most its radius, touching included).
//!
//! [`PlanarPatch::first_contact`]: crate::PlanarPatch::first_contact

use serde::{Deserialize, Serialize};

use crate::polygon::{closest_point_on_segment2, orient, segments_intersect};
use crate::{Point2, Point3, Polygon, Real, UnitVector3, Vector3, na};

/// A closed region in the plane `z = 0` of a local frame: a set with a boundary made of
/// straight edges. Implemented by [`Polygon`] (with holes) and [`Triangle2`].
///
/// The kernels need only a closed point-membership test and the boundary edges; they are
/// correct for any closed region whose boundary is exactly the union of the edges.
pub trait PlanarRegion {
    /// Whether `p` lies in the closed region (boundary included).
    fn contains(&self, p: &Point2) -> bool;

    /// Every boundary edge, as `(from, to)`.
    fn edges(&self) -> impl Iterator<Item = (Point2, Point2)> + '_;

    /// The bounding rectangle of the region.
    fn bounds2(&self) -> crate::Bounds2;
}

impl PlanarRegion for Polygon {
    fn contains(&self, p: &Point2) -> bool {
        Polygon::contains(self, p)
    }

    fn bounds2(&self) -> crate::Bounds2 {
        Polygon::bounds2(self)
    }

    fn edges(&self) -> impl Iterator<Item = (Point2, Point2)> + '_ {
        Polygon::edges(self)
    }
}

/// A non-degenerate triangle in the plane, counter-clockwise.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Triangle2 {
    vertices: [Point2; 3],
}

impl Triangle2 {
    /// The triangle with these corners, reordered to run counter-clockwise; `None` if the
    /// corners are collinear or not finite (decided exactly with `orient2d`).
    pub fn new(a: Point2, b: Point2, c: Point2) -> Option<Triangle2> {
        if ![a, b, c].iter().all(|p| p.x.is_finite() && p.y.is_finite()) {
            return None;
        }
        let o = orient(&a, &b, &c);
        if o > 0.0 {
            Some(Triangle2 { vertices: [a, b, c] })
        } else if o < 0.0 {
            Some(Triangle2 { vertices: [a, c, b] })
        } else {
            None
        }
    }

    /// The corners, counter-clockwise.
    pub fn vertices(&self) -> &[Point2; 3] {
        &self.vertices
    }
}

impl PlanarRegion for Triangle2 {
    fn contains(&self, p: &Point2) -> bool {
        let [a, b, c] = &self.vertices;
        orient(a, b, p) >= 0.0 && orient(b, c, p) >= 0.0 && orient(c, a, p) >= 0.0
    }

    fn edges(&self) -> impl Iterator<Item = (Point2, Point2)> + '_ {
        (0..3).map(move |i| (self.vertices[i], self.vertices[(i + 1) % 3]))
    }

    fn bounds2(&self) -> crate::Bounds2 {
        crate::Bounds2::of(&self.vertices)
    }
}

/// The closest point of some set to a query point.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ClosestPoint {
    /// The closest point of the set (in the caller's frame).
    pub point: Point3,
    /// The Euclidean distance from the query point to it.
    pub distance: Real,
}

/// The closest approach of a query segment `a → b` to some set.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SegmentDistance {
    /// The smallest Euclidean distance between the segment and the set.
    pub distance: Real,
    /// A parameter in `[0, 1]` along the segment (`a + t (b − a)`) where it is attained.
    pub t: Real,
    /// The point of the set where it is attained.
    pub point: Point3,
}

/// The closest points of two segments `p(s) = p0 + s (p1 − p0)` and `q(t) = q0 + t (q1 − q0)`.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SegmentSegment {
    /// Parameter on the first segment, in `[0, 1]`.
    pub s: Real,
    /// Parameter on the second segment, in `[0, 1]`.
    pub t: Real,
    /// `p(s)`.
    pub point_a: Point3,
    /// `q(t)`.
    pub point_b: Point3,
    /// `|p(s) − q(t)|`, the distance between the segments.
    pub distance: Real,
}

/// The first contact of a sphere swept along a segment with some set.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Contact {
    /// The smallest parameter `t` in `[0, 1]` at which the sphere centred at `a + t (b − a)`
    /// touches the set (0 if it touches at the start).
    pub t: Real,
    /// The point of the set closest to the sphere's centre at `t` (the contact point).
    pub point: Point3,
    /// The set's surface normal at the contact (for planar sets: the plane normal), oriented
    /// toward the side the sphere is on; see [`StepHit`](crate::StepHit) for the exact rule.
    pub normal: UnitVector3,
}

fn lift(p: &Point2) -> Point3 {
    Point3::new(p.x, p.y, 0.0)
}

/// `num / den` clamped to `[0, 1]`, for `den > 0`, without dividing when the result is clamped.
fn ratio_clamped(num: Real, den: Real) -> Real {
    if num <= 0.0 {
        0.0
    } else if num >= den {
        1.0
    } else {
        num / den
    }
}

/// The point of the closed segment `a b` closest to `p`, in 3D. A zero-length segment gives `a`.
pub fn closest_point_on_segment(p: &Point3, a: &Point3, b: &Point3) -> Point3 {
    let ab = b - a;
    let den = ab.norm_squared();
    if den <= 0.0 {
        return *a;
    }
    a + ab * ratio_clamped((p - a).dot(&ab), den)
}

/// The closest points of two closed segments in 3D.
///
/// # Method
/// Minimises `|p(s) − q(t)|²` over the unit square (Ericson, *Real-Time Collision Detection*,
/// §5.1.9): the unconstrained minimiser of the first parameter is clamped, the second is
/// computed from it and clamped, and if that clamped, the first is recomputed from it.
///
/// # Degenerate cases
/// Both segments points: the two points. One segment a point: point-segment distance.
/// Parallel segments (`a e − b² ≤ 0`): `s = 0` is chosen, which with the re-projection step
/// still yields a closest pair (the distance between parallel lines is constant).
pub fn closest_points_segment_segment(
    p0: &Point3,
    p1: &Point3,
    q0: &Point3,
    q1: &Point3,
) -> SegmentSegment {
    let d1 = p1 - p0;
    let d2 = q1 - q0;
    let r = p0 - q0;
    let a = d1.norm_squared();
    let e = d2.norm_squared();
    let f = d2.dot(&r);
    let (s, t) = if a <= 0.0 && e <= 0.0 {
        (0.0, 0.0)
    } else if a <= 0.0 {
        (0.0, ratio_clamped(f, e))
    } else {
        let c = d1.dot(&r);
        if e <= 0.0 {
            (ratio_clamped(-c, a), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let s = if denom > 0.0 { ratio_clamped(b * f - c * e, denom) } else { 0.0 };
            let t_num = b * s + f;
            if t_num <= 0.0 {
                (ratio_clamped(-c, a), 0.0)
            } else if t_num >= e {
                (ratio_clamped(b - c, a), 1.0)
            } else {
                (s, t_num / e)
            }
        }
    };
    let point_a = p0 + d1 * s;
    let point_b = q0 + d2 * t;
    SegmentSegment { s, t, point_a, point_b, distance: (point_a - point_b).norm() }
}

/// The point of a planar region (local frame, plane `z = 0`) closest to `p`.
///
/// # Method
/// If `p` projects into the region, the closest point is the projection and the distance
/// `|p.z|`. Otherwise the closest point lies on the boundary: the closest point in the plane
/// over all edges, at distance `sqrt(d_plane² + p.z²)`.
///
/// # Complexity
/// O(n) in the number of edges.
pub fn closest_point_on_region<R: PlanarRegion + ?Sized>(region: &R, p: &Point3) -> ClosestPoint {
    let p2 = p.xy();
    if region.contains(&p2) {
        return ClosestPoint { point: Point3::new(p.x, p.y, 0.0), distance: p.z.abs() };
    }
    let mut best = (p2, Real::INFINITY);
    for (a, b) in region.edges() {
        let q = closest_point_on_segment2(&p2, &a, &b);
        let d2 = (q - p2).norm_squared();
        if d2 < best.1 {
            best = (q, d2);
        }
    }
    ClosestPoint { point: lift(&best.0), distance: (best.1 + p.z * p.z).sqrt() }
}

/// The smallest parameter `u ∈ [0, 1]` at which the plane segment `p → q` is in the closed
/// region, or `None` if it never is.
///
/// # Method
/// 0 if `p` is in the region. Otherwise the segment can only enter through the boundary: for
/// every edge it meets (decided exactly, `orient2d`), the parameter of the first common point:
/// the crossing parameter `cross(e0 − p, e) / cross(q − p, e)` for a transversal edge, the
/// nearer edge endpoint's projection for a collinear overlap (collinearity decided exactly).
///
/// # Degenerate cases
/// A zero-length segment: `Some(0)` if the point is in the region, else `None`.
pub fn first_entry_2d<R: PlanarRegion + ?Sized>(
    region: &R,
    p: &Point2,
    q: &Point2,
) -> Option<Real> {
    if region.contains(p) {
        return Some(0.0);
    }
    let d = q - p;
    let dd = d.norm_squared();
    if dd <= 0.0 {
        return None;
    }
    let mut best: Option<Real> = None;
    for (e0, e1) in region.edges() {
        if !segments_intersect(p, q, &e0, &e1) {
            continue;
        }
        let u = if orient(p, q, &e0) == 0.0 && orient(p, q, &e1) == 0.0 {
            // Collinear overlap: it starts at the edge endpoint nearer to p (p itself is
            // outside the region, so not on this edge).
            let u0 = (e0 - p).dot(&d);
            let u1 = (e1 - p).dot(&d);
            ratio_clamped(u0.min(u1), dd)
        } else {
            let e = e1 - e0;
            let den = d.x * e.y - d.y * e.x;
            let w = e0 - p;
            let num = w.x * e.y - w.y * e.x;
            // The segments meet and are not collinear, so den ≠ 0 in exact arithmetic;
            // normalise the sign and clamp (rounding can push the ratio out of [0, 1]).
            if den == 0.0 {
                // Rounding made nearly-parallel segments look parallel: the nearer endpoint
                // of the edge is within rounding of the meeting point.
                ratio_clamped((e0 - p).dot(&d).min((e1 - p).dot(&d)), dd)
            } else if den > 0.0 {
                ratio_clamped(num, den)
            } else {
                ratio_clamped(-num, -den)
            }
        };
        best = Some(best.map_or(u, |b| b.min(u)));
    }
    best
}

/// The distance between the segment `a → b` and a planar region (local frame, plane `z = 0`),
/// with where it is attained.
///
/// # Method (spec §3.3)
/// 1. If the segment meets the plane at a single point (`a.z` and `b.z` of opposite signs or one
///    of them zero) and that point is in the region: distance 0 there.
/// 2. If the segment lies in the plane (`a.z = b.z = 0`): distance 0 at the first point in the
///    region ([`first_entry_2d`], exact), if any.
/// 3. Otherwise the minimum over: `|a.z|` if `a` projects into the region, `|b.z|` if `b` does,
///    and the segment–segment distance to every boundary edge.
///
/// Why 3 is complete, also for segments parallel to the plane: let `(s*, q*)` be a closest pair
/// (segment point, region point) and assume the segment does not meet the region. If `q*` is on
/// an edge, the edge term finds the distance. Otherwise `q*` is interior to the region, so
/// `s* − q*` is normal to the plane (else moving `q*` would get closer) and the distance is
/// `|z(s*)|`, with `s*` projecting inside. Along the segment `z` is affine and does not vanish
/// where the projection is inside (the segment would meet the region), so `|z|` is affine there.
/// If it strictly decreases one way, `s*` must be an endpoint (else moving along the segment gets
/// closer), and the endpoint term finds it. If `z` is constant (segment parallel to the plane),
/// slide `s*` along the segment keeping the projection inside and the distance `|z|`: either an
/// endpoint is reached (endpoint term) or the projection reaches the boundary at an edge point
/// at distance `|z|` (edge term). Conversely every term is a distance to a point of the region,
/// so the minimum is exactly the distance.
///
/// # Degenerate cases
/// A segment whose ends are both within [`IN_PLANE_ULPS`] (relative) of the plane is treated as
/// lying in it, so that a segment coplanar with a patch in world coordinates is not turned into
/// a plane crossing at a random point by the rounding of the frame transform.
/// A zero-length segment is the point distance. Step 1 computes the crossing point in floats;
/// a crossing within rounding of the boundary may be classified outside, and then step 3 returns
/// a distance of a few ulps instead of 0.
///
/// # Complexity
/// O(n) in the number of edges.
pub fn segment_region_distance<R: PlanarRegion + ?Sized>(
    region: &R,
    a: &Point3,
    b: &Point3,
) -> SegmentDistance {
    let (a, b) = &snap_to_plane(a, b);
    let (za, zb) = (a.z, b.z);
    let d = b - a;
    if za == 0.0 && zb == 0.0 {
        if let Some(u) = first_entry_2d(region, &a.xy(), &b.xy()) {
            let x = a + d * u;
            return SegmentDistance { distance: 0.0, t: u, point: Point3::new(x.x, x.y, 0.0) };
        }
    } else if (za <= 0.0 && zb >= 0.0) || (za >= 0.0 && zb <= 0.0) {
        // Signs differ and not both zero: za − zb ≠ 0 and the ratio lies in [0, 1].
        let t = ratio_clamped(za.abs(), (za - zb).abs());
        let x = if t >= 1.0 { *b } else { a + d * t };
        let x2 = x.xy();
        if region.contains(&x2) {
            return SegmentDistance { distance: 0.0, t, point: lift(&x2) };
        }
    }
    let mut best = SegmentDistance { distance: Real::INFINITY, t: 0.0, point: Point3::origin() };
    for (t, p) in [(0.0, a), (1.0, b)] {
        let p2 = p.xy();
        if p.z.abs() < best.distance && region.contains(&p2) {
            best = SegmentDistance { distance: p.z.abs(), t, point: lift(&p2) };
        }
    }
    for (e0, e1) in region.edges() {
        let ss = closest_points_segment_segment(a, b, &lift(&e0), &lift(&e1));
        if ss.distance < best.distance {
            best = SegmentDistance { distance: ss.distance, t: ss.s, point: ss.point_b };
        }
    }
    best
}

/// Whether the segment `a → b` (in the region's frame) comes within `radius` of the region:
/// the answer of `segment_region_distance(region, a, b).distance <= radius`, found faster.
///
/// Two rejects come first, each by a margin far above rounding (`1e-9` relative), so they never
/// change the answer: both ends on one side of the plane and farther than `radius` from it, or
/// the segment's box in the plane farther than `radius` from the region's
/// [`bounds2`](PlanarRegion::bounds2). The exact test then stops at the first part of the region
/// within `radius`, instead of measuring them all.
pub fn segment_region_within<R: PlanarRegion + ?Sized>(
    region: &R,
    a: &Point3,
    b: &Point3,
    radius: Real,
) -> bool {
    let scale = 1.0 + radius.abs() + a.coords.amax().max(b.coords.amax());
    let reach = radius + 1e-9 * scale;
    if (a.z > reach && b.z > reach) || (a.z < -reach && b.z < -reach) {
        return false;
    }
    let r = region.bounds2();
    let gap = |lo: Real, hi: Real, min: Real, max: Real| (min - hi).max(lo - max);
    if gap(a.x.min(b.x), a.x.max(b.x), r.min.x, r.max.x) > reach
        || gap(a.y.min(b.y), a.y.max(b.y), r.min.y, r.max.y) > reach
    {
        return false;
    }
    // What follows is `segment_region_distance`, stopping at the first distance within reach.
    let (a, b) = &snap_to_plane(a, b);
    let (za, zb) = (a.z, b.z);
    let d = b - a;
    if za == 0.0 && zb == 0.0 {
        if first_entry_2d(region, &a.xy(), &b.xy()).is_some() {
            return 0.0 <= radius;
        }
    } else if (za <= 0.0 && zb >= 0.0) || (za >= 0.0 && zb <= 0.0) {
        let t = ratio_clamped(za.abs(), (za - zb).abs());
        let x = if t >= 1.0 { *b } else { a + d * t };
        if region.contains(&x.xy()) {
            return 0.0 <= radius;
        }
    }
    if [a, b].iter().any(|p| p.z.abs() <= radius && region.contains(&p.xy())) {
        return true;
    }
    // An edge whose box in the plane misses the segment's box grown by `reach` is farther
    // than `radius` (the margin again covers rounding): skip it before the exact test.
    let (lo_x, hi_x) = (a.x.min(b.x) - reach, a.x.max(b.x) + reach);
    let (lo_y, hi_y) = (a.y.min(b.y) - reach, a.y.max(b.y) + reach);
    region.edges().any(|(e0, e1)| {
        e0.x.max(e1.x) >= lo_x
            && e0.x.min(e1.x) <= hi_x
            && e0.y.max(e1.y) >= lo_y
            && e0.y.min(e1.y) <= hi_y
            && closest_points_segment_segment(a, b, &lift(&e0), &lift(&e1)).distance <= radius
    })
}

/// How close to the plane (relative to the coordinates' magnitude) both ends of a segment must
/// be for it to count as lying in the plane: 64 ulps, the rounding a frame transform leaves on a
/// segment that lies in the plane in world coordinates.
pub const IN_PLANE_ULPS: Real = 64.0 * Real::EPSILON;

/// The segment with both heights set to 0 if both are within [`IN_PLANE_ULPS`] of the plane
/// (relative to `1 + max |coordinate|`), else unchanged.
fn snap_to_plane(a: &Point3, b: &Point3) -> (Point3, Point3) {
    let scale = 1.0 + a.coords.amax().max(b.coords.amax());
    let tau = IN_PLANE_ULPS * scale;
    if a.z.abs() <= tau && b.z.abs() <= tau && (a.z != 0.0 || b.z != 0.0) {
        (Point3::new(a.x, a.y, 0.0), Point3::new(b.x, b.y, 0.0))
    } else {
        (*a, *b)
    }
}

/// The smallest root in `[0, 1]` of `A t² + 2 B t + C = 0` at which the quadratic goes from
/// positive to non-positive (an *entry*), for `C > 0`. `None` if there is none.
///
/// Compare before divide: with `B < 0` (approaching), `q = −B + √(B² − A C) > 0` and the entry
/// root is `C / q`, which lies in `[0, 1]` iff `C ≤ q`. No cancellation, no division by a tiny
/// `A`.
fn entry_root(a: Real, b: Real, c: Real) -> Option<Real> {
    let approaching = a > 0.0 && b < 0.0 && c > 0.0;
    if !approaching {
        // Already inside (c ≤ 0) or not approaching at t = 0: with c > 0 and b ≥ 0 both roots
        // are ≤ 0; a = 0 means no relative motion.
        return None;
    }
    let disc = b * b - a * c;
    if disc < 0.0 {
        return None;
    }
    let q = -b + disc.sqrt();
    if c <= q { Some(c / q) } else { None }
}

/// The first parameter `t ∈ [0, 1]` at which a sphere of radius `r` centred at `a + t d`
/// touches the point `v`, for a start outside the sphere (`|a − v| > r`). `None` if it never
/// does.
///
/// # Method
/// The entry root of `|a − v + t d|² = r²` (see the module docs on compare before divide).
/// A zero-length motion never touches.
pub fn sphere_cast_point(a: &Point3, d: &Vector3, r: Real, v: &Point3) -> Option<Real> {
    let f = a - v;
    entry_root(d.norm_squared(), f.dot(d), f.norm_squared() - r * r)
}

/// The first parameter `t ∈ [0, 1]` at which a sphere of radius `r` centred at `a + t d`
/// touches the closed segment `e0 e1`, for a start farther than `r` from it. `None` if it
/// never does.
///
/// # Method
/// The earliest of: the entry into the infinite cylinder of radius `r` around the edge's line
/// (a quadratic in the components perpendicular to the edge), valid if the foot of the centre
/// on the line lies within the edge at that time; and the entries into the spheres around both
/// endpoints. If the centre first comes within `r` of the line beyond an endpoint, the endpoint
/// sphere is met no later, so the three candidates together give the first contact.
///
/// # Degenerate cases
/// A zero-length edge is a point. Motion parallel to the edge has no cylinder entry (the
/// distance to the line is constant) and meets the edge through an endpoint sphere. Grazing
/// contacts (a double root) may be lost to rounding when the discriminant comes out slightly
/// negative; [`first_contact_region`] covers that case by its fallback.
pub fn sphere_cast_segment(
    a: &Point3,
    d: &Vector3,
    r: Real,
    e0: &Point3,
    e1: &Point3,
) -> Option<Real> {
    let mut best = sphere_cast_point(a, d, r, e0);
    if let Some(t) = sphere_cast_point(a, d, r, e1) {
        best = Some(best.map_or(t, |b| b.min(t)));
    }
    let e = e1 - e0;
    let ee = e.norm_squared();
    if ee > 0.0 {
        let f = a - e0;
        let m = f - e * (e.dot(&f) / ee);
        let n = d - e * (e.dot(d) / ee);
        if let Some(t) = entry_root(n.norm_squared(), m.dot(&n), m.norm_squared() - r * r) {
            let foot = e.dot(&(f + d * t));
            if (0.0..=ee).contains(&foot) {
                best = Some(best.map_or(t, |b| b.min(t)));
            }
        }
    }
    best
}

/// The first parameter at which the sphere centred at `a + t d` has its centre within `r` of
/// the plane *and* above the region (a face contact), or `None`.
fn face_entry<R: PlanarRegion + ?Sized>(
    region: &R,
    a: &Point3,
    d: &Vector3,
    r: Real,
) -> Option<Real> {
    let (lo, hi) = if d.z == 0.0 {
        if a.z.abs() <= r { (0.0, 1.0) } else { return None }
    } else {
        let t1 = (r - a.z) / d.z;
        let t2 = (-r - a.z) / d.z;
        (t1.min(t2).max(0.0), t1.max(t2).min(1.0))
    };
    if lo > hi {
        return None;
    }
    let p = a + d * lo;
    let q = a + d * hi;
    let u = first_entry_2d(region, &p.xy(), &q.xy())?;
    Some(lo + u * (hi - lo))
}

/// The local-frame contact normal `±z`: toward the sphere centre at contact; if that lies in
/// the plane (or `r = 0`), toward the start's side; if the start is in the plane too, against
/// the motion; `+z` if the motion lies in the plane.
fn contact_normal(center_z: Real, start_z: Real, motion_z: Real, r: Real) -> UnitVector3 {
    let up = if r > 0.0 && center_z != 0.0 {
        center_z > 0.0
    } else if start_z != 0.0 {
        start_z > 0.0
    } else if motion_z != 0.0 {
        motion_z < 0.0
    } else {
        true
    };
    if up { Vector3::z_axis() } else { -Vector3::z_axis() }
}

/// The first contact of a sphere of radius `r` swept from `a` to `b` with a planar region
/// (local frame, plane `z = 0`), or `None` if the swept sphere (a capsule) stays farther than
/// `r` from the region.
///
/// # Method
/// 1. `None` iff [`segment_region_distance`] is greater than `r` (so this function and a
///    distance test can never disagree).
/// 2. `t = 0` if the start is already within `r` ([`closest_point_on_region`]).
/// 3. Otherwise the first contact happens at a time when the closest region point is interior
///    (then `|z| = r` with the centre above the region: the face candidate, the first entry of
///    the centre's projection into the region while `|z| ≤ r`), on an edge (cylinder
///    candidate) or a vertex (sphere candidate); the earliest valid candidate is the answer
///    (see [`sphere_cast_segment`]). The parameter of closest approach from step 1 is a time
///    of contact too and bounds the result from above, which also covers grazing contacts
///    whose quadratic lost its double root to rounding.
///
/// The contact point is the region point closest to the centre at `t`; the normal is `±z` by
/// the rule of [`StepHit`](crate::StepHit).
///
/// # Degenerate cases
/// `r = 0`: a segment–region intersection; the face candidate alone decides (the plane
/// crossing; in-plane segments, also those within [`IN_PLANE_ULPS`], use the exact 2D entry). Zero-length segments: a sphere test (steps 1–2). Motion
/// parallel to the plane at height exactly `r`: the face candidate's `|z| ≤ r` interval is
/// all of `[0, 1]` and the entry is found in 2D.
///
/// # Complexity
/// O(n) in the number of edges (a few passes).
pub fn first_contact_region<R: PlanarRegion + ?Sized>(
    region: &R,
    a: &Point3,
    b: &Point3,
    r: Real,
) -> Option<Contact> {
    let closest = segment_region_distance(region, a, b);
    let touches = closest.distance <= r;
    if !touches {
        return None;
    }
    let (a, b) = &snap_to_plane(a, b);
    let d = b - a;
    let start = closest_point_on_region(region, a);
    let (t, point) = if start.distance <= r {
        (0.0, start.point)
    } else {
        let mut t = closest.t;
        if let Some(tf) = face_entry(region, a, &d, r) {
            t = t.min(tf);
        }
        // With r = 0 the face candidate alone is complete (the plane crossing, or the exact 2D
        // entry of an in-plane segment), and the edge quadratics would only have double roots,
        // whose rounding error is the square root of the coefficients' (about 1e-8).
        if r > 0.0 {
            for (e0, e1) in region.edges() {
                if let Some(te) = sphere_cast_segment(a, &d, r, &lift(&e0), &lift(&e1)) {
                    t = t.min(te);
                }
            }
        }
        let center = a + d * t;
        (t, closest_point_on_region(region, &center).point)
    };
    let center_z = a.z + d.z * t;
    Some(Contact { t, point, normal: contact_normal(center_z, a.z, d.z, r) })
}

/// A triangle in 3D with a local frame in which it lies in the plane `z = 0`: origin at the
/// first corner, x along the first edge, z along the normal `(b − a) × (c − a)`.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct TriangleFrame {
    origin: Point3,
    /// Columns: the local x, y and z axes in world coordinates.
    axes: na::Matrix3<Real>,
    triangle: Triangle2,
}

impl TriangleFrame {
    /// The frame of the triangle `[a, b, c]`; `None` if it is degenerate (zero normal, or
    /// collinear after projection) or not finite.
    pub fn new(corners: &[Point3; 3]) -> Option<TriangleFrame> {
        let [a, b, c] = corners;
        let ab = b - a;
        let ac = c - a;
        let x = ab.try_normalize(0.0)?;
        let z = ab.cross(&ac).try_normalize(0.0)?;
        let y = z.cross(&x);
        let axes = na::Matrix3::from_columns(&[x, y, z]);
        let local = |p: &Vector3| Point2::new(x.dot(p), y.dot(p));
        let triangle = Triangle2::new(Point2::origin(), local(&ab), local(&ac))?;
        Some(TriangleFrame { origin: *a, axes, triangle })
    }

    /// A world point in the triangle's frame.
    pub fn to_local(&self, p: &Point3) -> Point3 {
        Point3::from(self.axes.tr_mul(&(p - self.origin)))
    }

    /// A point of the triangle's frame in the world.
    pub fn to_world(&self, p: &Point3) -> Point3 {
        self.origin + self.axes * p.coords
    }

    /// The unit normal `(b − a) × (c − a) / |…|`.
    pub fn normal(&self) -> UnitVector3 {
        UnitVector3::new_unchecked(self.axes.column(2).into_owned())
    }

    /// The triangle in its own frame.
    pub fn triangle(&self) -> &Triangle2 {
        &self.triangle
    }

    /// The closest point of the triangle to the world point `p` (world frame).
    pub fn closest_point(&self, p: &Point3) -> ClosestPoint {
        let c = closest_point_on_region(&self.triangle, &self.to_local(p));
        ClosestPoint { point: self.to_world(&c.point), distance: c.distance }
    }

    /// Whether the world segment `a → b` comes within `radius` of the triangle
    /// ([`segment_region_within`]).
    pub fn segment_within(&self, a: &Point3, b: &Point3, radius: Real) -> bool {
        segment_region_within(&self.triangle, &self.to_local(a), &self.to_local(b), radius)
    }

    /// The distance between the world segment `a → b` and the triangle (world frame).
    pub fn segment_distance(&self, a: &Point3, b: &Point3) -> SegmentDistance {
        let s = segment_region_distance(&self.triangle, &self.to_local(a), &self.to_local(b));
        SegmentDistance { point: self.to_world(&s.point), ..s }
    }

    /// The first contact of a sphere of radius `r` swept from `a` to `b` (world frame).
    pub fn first_contact(&self, a: &Point3, b: &Point3, r: Real) -> Option<Contact> {
        let c = first_contact_region(&self.triangle, &self.to_local(a), &self.to_local(b), r)?;
        Some(Contact {
            t: c.t,
            point: self.to_world(&c.point),
            normal: UnitVector3::new_unchecked(self.axes * c.normal.into_inner()),
        })
    }
}

/// The closest point of the triangle `tri` to `p` (world frame). A degenerate triangle gives
/// the closest point of its longest edge.
pub fn closest_point_on_triangle(p: &Point3, tri: &[Point3; 3]) -> ClosestPoint {
    match TriangleFrame::new(tri) {
        Some(frame) => frame.closest_point(p),
        None => {
            let mut best = ClosestPoint { point: tri[0], distance: Real::INFINITY };
            for i in 0..3 {
                let q = closest_point_on_segment(p, &tri[i], &tri[(i + 1) % 3]);
                let d = (q - p).norm();
                if d < best.distance {
                    best = ClosestPoint { point: q, distance: d };
                }
            }
            best
        }
    }
}

/// The parameter `t ∈ [0, 1]` of the first point of the segment `a → b` in the closed triangle
/// `tri`, or `None` (a line step against a trimesh triangle).
///
/// # Method
/// Every decision is exact (`orient3d`): the segment misses if both endpoints are strictly on
/// one side of the triangle's plane; if it crosses the plane (or ends on it), the crossing lies
/// in the triangle iff the line `a b` passes no triangle edge on the wrong side (the three
/// `orient3d(a, b, v_i, v_{i+1})` have no opposite signs). The parameter is then
/// `o_a / (o_a − o_b)` from the signed volumes, computed after the sign test (never dividing by
/// zero). A segment in the triangle's plane is solved in 2D in the triangle's frame
/// ([`first_entry_2d`]); so is a zero-length segment on the plane. A degenerate triangle is
/// treated as its edges (then `t` is a parameter of contact, not necessarily the first).
pub fn segment_triangle_intersection(a: &Point3, b: &Point3, tri: &[Point3; 3]) -> Option<Real> {
    let c3 = |p: &Point3| robust::Coord3D { x: p.x, y: p.y, z: p.z };
    let [v0, v1, v2] = tri;
    let oa = robust::orient3d(c3(v0), c3(v1), c3(v2), c3(a));
    let ob = robust::orient3d(c3(v0), c3(v1), c3(v2), c3(b));
    if (oa > 0.0 && ob > 0.0) || (oa < 0.0 && ob < 0.0) {
        return None;
    }
    if oa == 0.0 && ob == 0.0 {
        // Coplanar (or a degenerate triangle): solve in the triangle's frame.
        let Some(frame) = TriangleFrame::new(tri) else {
            let s = segment_triangle_distance(a, b, tri);
            return (s.distance == 0.0).then_some(s.t);
        };
        let (la, lb) = (frame.to_local(a), frame.to_local(b));
        return first_entry_2d(frame.triangle(), &la.xy(), &lb.xy());
    }
    let s0 = robust::orient3d(c3(a), c3(b), c3(v0), c3(v1));
    let s1 = robust::orient3d(c3(a), c3(b), c3(v1), c3(v2));
    let s2 = robust::orient3d(c3(a), c3(b), c3(v2), c3(v0));
    let has_pos = s0 > 0.0 || s1 > 0.0 || s2 > 0.0;
    let has_neg = s0 < 0.0 || s1 < 0.0 || s2 < 0.0;
    if has_pos && has_neg {
        return None;
    }
    if !has_pos && !has_neg {
        // The line a b lies in the triangle's plane direction through all edges: only possible
        // for a degenerate triangle; fall back to the distance kernel.
        let s = segment_triangle_distance(a, b, tri);
        return (s.distance == 0.0).then_some(s.t);
    }
    Some(ratio_clamped(oa.abs(), (oa - ob).abs()))
}

/// The distance between the segment `a → b` and the triangle `tri` (world frame). A degenerate
/// triangle is treated as its three edges.
pub fn segment_triangle_distance(a: &Point3, b: &Point3, tri: &[Point3; 3]) -> SegmentDistance {
    match TriangleFrame::new(tri) {
        Some(frame) => frame.segment_distance(a, b),
        None => {
            let mut best = SegmentDistance { distance: Real::INFINITY, t: 0.0, point: tri[0] };
            for i in 0..3 {
                let ss = closest_points_segment_segment(a, b, &tri[i], &tri[(i + 1) % 3]);
                if ss.distance < best.distance {
                    best = SegmentDistance { distance: ss.distance, t: ss.s, point: ss.point_b };
                }
            }
            best
        }
    }
}

/// The first contact of a sphere of radius `r` swept from `a` to `b` with the triangle `tri`
/// (world frame); `None` for a degenerate triangle or no contact. See [`first_contact_region`].
pub fn first_contact_triangle(
    tri: &[Point3; 3],
    a: &Point3,
    b: &Point3,
    r: Real,
) -> Option<Contact> {
    TriangleFrame::new(tri)?.first_contact(a, b, r)
}

#[cfg(test)]
mod tests;
