//! Simple polygons with holes in the plane: the 2D part of a planar patch (thesis §5.1).
//!
//! Every decision here (does an edge cross another, is a point inside, which way does a ring
//! turn) is made with Shewchuk's exact `orient2d` predicate ([`robust`]), so validation and
//! point-in-polygon never disagree with each other because of rounding.

use std::cmp::Ordering;
use std::fmt;

use robust::{Coord, orient2d};
use serde::{Deserialize, Serialize};

use crate::{PatchError, Point2, Real};

/// Names one ring of a [`Polygon`]: the outer ring or a hole (by its index in
/// [`Polygon::holes`]). Errors use it to say where a problem is.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum RingId {
    /// The outer boundary.
    Outer,
    /// Hole number `k` (0-based, in the order given to [`Polygon::new`]).
    Hole(usize),
}

impl fmt::Display for RingId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RingId::Outer => write!(f, "outer ring"),
            RingId::Hole(k) => write!(f, "hole {k}"),
        }
    }
}

/// An axis-aligned rectangle in the plane, `[min, max]` (closed).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Bounds2 {
    /// The corner with the smallest coordinates.
    pub min: Point2,
    /// The corner with the largest coordinates.
    pub max: Point2,
}

impl Bounds2 {
    /// The rectangle of `points`, which must not be empty (rings and triangles never are).
    pub(crate) fn of(points: &[Point2]) -> Bounds2 {
        let (min, max) =
            points[1..].iter().fold((points[0], points[0]), |(lo, hi), p| (lo.inf(p), hi.sup(p)));
        Bounds2 { min, max }
    }
}

/// A closed ring of vertices: the last vertex connects back to the first, which is *not*
/// repeated at the end.
///
/// A ring only exists inside a validated [`Polygon`]: it has at least 3 finite vertices, no two
/// consecutive vertices are equal, it does not touch or cross itself, and it has nonzero area.
#[derive(Clone, Debug, PartialEq)]
pub struct Ring {
    points: Vec<Point2>,
    /// The rectangle of `points`, kept so point-in-polygon tests skip rings they lie
    /// outside of.
    bounds: Bounds2,
}

impl Ring {
    /// The heap bytes this ring owns (its vertex buffer, by capacity).
    pub fn heap_bytes(&self) -> usize {
        self.points.capacity() * std::mem::size_of::<Point2>()
    }

    /// The bounding rectangle of the vertices.
    pub fn bounds2(&self) -> Bounds2 {
        self.bounds
    }

    /// The vertices, in ring order (the closing edge from the last to the first is implied).
    pub fn points(&self) -> &[Point2] {
        &self.points
    }

    /// The number of vertices (= the number of edges).
    pub fn num_vertices(&self) -> usize {
        self.points.len()
    }

    /// The edges `(from, to)` in ring order, including the closing edge.
    pub fn edges(&self) -> impl Iterator<Item = (Point2, Point2)> + '_ {
        let n = self.points.len();
        (0..n).map(move |i| (self.points[i], self.points[(i + 1) % n]))
    }

    /// The signed area: positive for counter-clockwise rings (shoelace formula, evaluated
    /// relative to the first vertex to limit cancellation).
    pub fn signed_area(&self) -> Real {
        signed_area(&self.points)
    }

    /// Whether the ring runs counter-clockwise. Decided exactly with `orient2d` at the
    /// lexicographically smallest vertex, which is a convex corner of any simple ring.
    pub fn is_ccw(&self) -> bool {
        is_ccw(&self.points)
    }
}

/// A simple polygon with holes: the region inside the outer ring and outside every hole,
/// boundary included.
///
/// Constructed only through [`Polygon::new`] (or deserialisation, which runs the same checks),
/// so every `Polygon` satisfies:
///
/// * every ring has at least 3 vertices, all finite, no two consecutive ones equal;
/// * every ring is simple (no edge crosses or touches a non-adjacent edge, adjacent edges do not
///   fold back onto each other) and has nonzero area;
/// * every hole lies strictly inside the outer ring; no two rings share a point (holes neither
///   touch the outer ring nor each other); no hole lies inside another hole;
/// * the outer ring is counter-clockwise and every hole clockwise: the polygon's interior is
///   always to the **left** of every edge. Rings given the other way round are reversed, not
///   rejected.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawPolygon", into = "RawPolygon")]
pub struct Polygon {
    outer: Ring,
    holes: Vec<Ring>,
}

/// The unvalidated serialised form of a [`Polygon`].
#[derive(Serialize, Deserialize)]
struct RawPolygon {
    outer: Vec<Point2>,
    #[serde(default)]
    holes: Vec<Vec<Point2>>,
}

impl TryFrom<RawPolygon> for Polygon {
    type Error = PatchError;
    fn try_from(raw: RawPolygon) -> Result<Self, Self::Error> {
        Polygon::new(raw.outer, raw.holes)
    }
}

impl From<Polygon> for RawPolygon {
    fn from(p: Polygon) -> Self {
        RawPolygon { outer: p.outer.points, holes: p.holes.into_iter().map(|h| h.points).collect() }
    }
}

/// # Construction
impl Polygon {
    /// The heap bytes this polygon owns: every ring's vertex buffer and the hole list, by
    /// capacity.
    pub fn heap_bytes(&self) -> usize {
        self.outer.heap_bytes()
            + self.holes.capacity() * std::mem::size_of::<Ring>()
            + self.holes.iter().map(Ring::heap_bytes).sum::<usize>()
    }

    /// Validates the rings and builds the polygon; see [`Polygon`] for what is checked.
    /// Rings are reoriented (outer counter-clockwise, holes clockwise) as needed.
    ///
    /// # Errors
    /// The first problem found, naming the ring and vertex or edge indices (indices refer to
    /// the rings as given, before any reversal).
    ///
    /// # Complexity
    /// Edges of all rings are sorted by their smallest x and swept: a pair is tested only when
    /// the x-ranges overlap. The worst case (many edges sharing an x-range) is O(n²) for n
    /// vertices in total, typical outlines behave like O(n log n). Hole nesting checks cost
    /// O(h·n) for h holes.
    pub fn new(outer: Vec<Point2>, holes: Vec<Vec<Point2>>) -> Result<Polygon, PatchError> {
        let mut rings = Vec::with_capacity(1 + holes.len());
        rings.push((RingId::Outer, outer));
        rings.extend(holes.into_iter().enumerate().map(|(k, h)| (RingId::Hole(k), h)));
        for (id, points) in &rings {
            check_ring_vertices(*id, points)?;
        }
        check_no_intersections(&rings)?;
        let outer_points = &rings[0].1;
        for (id, points) in &rings[1..] {
            // No edges meet, so a hole lies wholly inside or wholly outside the outer ring.
            if winding_number(outer_points, &points[0]) == 0 {
                return Err(PatchError::HoleOutside { hole: hole_index(*id) });
            }
        }
        for (i, (id_i, inner)) in rings.iter().enumerate().skip(1) {
            for (j, (id_j, container)) in rings.iter().enumerate().skip(1) {
                if i != j && winding_number(container, &inner[0]) != 0 {
                    return Err(PatchError::NestedHoles {
                        outer_hole: hole_index(*id_j),
                        inner_hole: hole_index(*id_i),
                    });
                }
            }
        }
        let mut rings = rings.into_iter().map(|(id, mut points)| {
            let want_ccw = id == RingId::Outer;
            if is_ccw(&points) != want_ccw {
                points.reverse();
            }
            // Tight buffers: maps hold many patches, and their memory is reported exactly.
            points.shrink_to_fit();
            let bounds = Bounds2::of(&points);
            Ring { points, bounds }
        });
        let outer = rings.next().expect("the outer ring is always present");
        let mut holes: Vec<Ring> = rings.collect();
        holes.shrink_to_fit();
        Ok(Polygon { outer, holes })
    }

    /// The axis-aligned rectangle spanned by two opposite corners, without holes.
    ///
    /// # Errors
    /// [`PatchError::NonFiniteVertex`] for non-finite corners, [`PatchError::RepeatedVertex`]
    /// or [`PatchError::ZeroArea`] if the corners agree on an axis.
    pub fn rectangle(a: Point2, b: Point2) -> Result<Polygon, PatchError> {
        for (vertex, p) in [(0, a), (2, b)] {
            if !(p.x.is_finite() && p.y.is_finite()) {
                return Err(PatchError::NonFiniteVertex { ring: RingId::Outer, vertex });
            }
        }
        let (min, max) = (a.inf(&b), a.sup(&b));
        let corners = vec![min, Point2::new(max.x, min.y), max, Point2::new(min.x, max.y)];
        Polygon::new(corners, Vec::new())
    }
}

/// # Access and measures
impl Polygon {
    /// The outer ring (counter-clockwise).
    pub fn outer(&self) -> &Ring {
        &self.outer
    }

    /// The holes (each clockwise).
    pub fn holes(&self) -> &[Ring] {
        &self.holes
    }

    /// All rings: the outer ring first, then the holes.
    pub fn rings(&self) -> impl Iterator<Item = &Ring> + '_ {
        std::iter::once(&self.outer).chain(self.holes.iter())
    }

    /// The total number of vertices of all rings.
    pub fn num_vertices(&self) -> usize {
        self.rings().map(Ring::num_vertices).sum()
    }

    /// All edges of all rings, outer ring first. The polygon's interior is to the left of each.
    pub fn edges(&self) -> impl Iterator<Item = (Point2, Point2)> + '_ {
        self.rings().flat_map(Ring::edges)
    }

    /// The area: outer area minus the hole areas (always positive).
    pub fn area(&self) -> Real {
        self.outer.signed_area() + self.holes.iter().map(Ring::signed_area).sum::<Real>()
    }

    /// The bounding rectangle (that of the outer ring).
    pub fn bounds2(&self) -> Bounds2 {
        self.outer.bounds
    }

    /// Whether `p` lies in the closed polygon: inside the outer ring and not strictly inside any
    /// hole. **Points on any boundary, including a hole's, count as inside**, so the polygon
    /// is a closed set and "touching counts as collision" holds at hole rims too.
    ///
    /// Exact: the on-edge test and the winding number use `orient2d`. A non-finite `p` is
    /// outside.
    ///
    /// # Complexity
    /// O(n) in the number of vertices.
    pub fn contains(&self, p: &Point2) -> bool {
        if !(p.x.is_finite() && p.y.is_finite()) {
            return false;
        }
        let mut winding = 0;
        for ring in self.rings() {
            // Outside a ring's rectangle a point is outside the ring and not on it: it adds
            // nothing to the winding number (and outside the outer ring's, it is outside).
            let b = &ring.bounds;
            if p.x < b.min.x || p.x > b.max.x || p.y < b.min.y || p.y > b.max.y {
                continue;
            }
            match ring_winding_or_boundary(&ring.points, p) {
                None => return true,
                Some(w) => winding += w,
            }
        }
        winding != 0
    }

    /// The distance in the plane from `p` to the polygon's boundary (any ring), and the
    /// closest boundary point.
    pub fn closest_boundary_point(&self, p: &Point2) -> (Point2, Real) {
        let mut best = (self.outer.points[0], Real::INFINITY);
        for (a, b) in self.edges() {
            let q = closest_point_on_segment2(p, &a, &b);
            let d2 = (q - p).norm_squared();
            if d2 < best.1 {
                best = (q, d2);
            }
        }
        (best.0, best.1.sqrt())
    }
}

fn hole_index(id: RingId) -> usize {
    match id {
        RingId::Hole(k) => k,
        RingId::Outer => unreachable!("only holes are checked for nesting"),
    }
}

fn coord(p: &Point2) -> Coord<Real> {
    Coord { x: p.x, y: p.y }
}

/// Exact orientation of `c` relative to the directed line `a → b`: positive if `a, b, c` turn
/// counter-clockwise, negative if clockwise, zero if collinear (`robust::orient2d`).
pub(crate) fn orient(a: &Point2, b: &Point2, c: &Point2) -> Real {
    orient2d(coord(a), coord(b), coord(c))
}

/// Whether `p`, known to be collinear with `a` and `b`, lies on the closed segment `a b`.
/// Exact (coordinate comparisons only).
fn on_collinear_segment(a: &Point2, b: &Point2, p: &Point2) -> bool {
    a.x.min(b.x) <= p.x && p.x <= a.x.max(b.x) && a.y.min(b.y) <= p.y && p.y <= a.y.max(b.y)
}

/// Whether `p` lies on the closed segment `a b`. Exact.
#[cfg(test)]
pub(crate) fn on_segment(a: &Point2, b: &Point2, p: &Point2) -> bool {
    orient(a, b, p) == 0.0 && on_collinear_segment(a, b, p)
}

/// Whether the closed segments `a b` and `c d` share at least one point. Exact.
pub(crate) fn segments_intersect(a: &Point2, b: &Point2, c: &Point2, d: &Point2) -> bool {
    let d1 = orient(c, d, a);
    let d2 = orient(c, d, b);
    let d3 = orient(a, b, c);
    let d4 = orient(a, b, d);
    let straddles = |x: Real, y: Real| (x > 0.0 && y < 0.0) || (x < 0.0 && y > 0.0);
    if straddles(d1, d2) && straddles(d3, d4) {
        return true;
    }
    (d1 == 0.0 && on_collinear_segment(c, d, a))
        || (d2 == 0.0 && on_collinear_segment(c, d, b))
        || (d3 == 0.0 && on_collinear_segment(a, b, c))
        || (d4 == 0.0 && on_collinear_segment(a, b, d))
}

/// The point of the closed segment `a b` closest to `p` (in the plane).
pub(crate) fn closest_point_on_segment2(p: &Point2, a: &Point2, b: &Point2) -> Point2 {
    let ab = b - a;
    let denom = ab.norm_squared();
    let num = (p - a).dot(&ab);
    // Compare before dividing: the parameter is clamped to [0, 1] without a division where
    // it would leave that range, and a zero-length segment never divides.
    if num <= 0.0 || denom <= 0.0 {
        *a
    } else if num >= denom {
        *b
    } else {
        a + ab * (num / denom)
    }
}

fn signed_area(points: &[Point2]) -> Real {
    let o = points[0];
    let mut twice = 0.0;
    for i in 1..points.len() - 1 {
        let u = points[i] - o;
        let v = points[i + 1] - o;
        twice += u.x * v.y - u.y * v.x;
    }
    0.5 * twice
}

fn lexicographic(a: &Point2, b: &Point2) -> Ordering {
    a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y))
}

fn is_ccw(points: &[Point2]) -> bool {
    let n = points.len();
    let (i, _) = points
        .iter()
        .enumerate()
        .min_by(|(_, a), (_, b)| lexicographic(a, b))
        .expect("rings have at least 3 vertices");
    let prev = &points[(i + n - 1) % n];
    let next = &points[(i + 1) % n];
    orient(prev, &points[i], next) > 0.0
}

/// The winding number of `ring` around `p`, or `None` if `p` is on the ring. Exact
/// (Sunday's crossing rule with `orient2d` for the side tests).
fn ring_winding_or_boundary(ring: &[Point2], p: &Point2) -> Option<i32> {
    let n = ring.len();
    let mut winding = 0;
    for i in 0..n {
        let a = &ring[i];
        let b = &ring[(i + 1) % n];
        let o = orient(a, b, p);
        if o == 0.0 && on_collinear_segment(a, b, p) {
            return None;
        }
        if a.y <= p.y {
            if b.y > p.y && o > 0.0 {
                winding += 1;
            }
        } else if b.y <= p.y && o < 0.0 {
            winding -= 1;
        }
    }
    Some(winding)
}

/// The winding number of a ring around a point known not to lie on it.
fn winding_number(ring: &[Point2], p: &Point2) -> i32 {
    ring_winding_or_boundary(ring, p).unwrap_or(1)
}

fn check_ring_vertices(id: RingId, points: &[Point2]) -> Result<(), PatchError> {
    if points.len() < 3 {
        return Err(PatchError::TooFewVertices { ring: id, count: points.len() });
    }
    if let Some(vertex) = points.iter().position(|p| !(p.x.is_finite() && p.y.is_finite())) {
        return Err(PatchError::NonFiniteVertex { ring: id, vertex });
    }
    let n = points.len();
    if let Some(vertex) = (0..n).find(|&i| points[i] == points[(i + 1) % n]) {
        return Err(PatchError::RepeatedVertex { ring: id, vertex });
    }
    // All vertices on one line: zero area. (Such a ring also folds back on itself, but this
    // error says more.)
    if points[2..].iter().all(|p| orient(&points[0], &points[1], p) == 0.0) {
        return Err(PatchError::ZeroArea { ring: id });
    }
    Ok(())
}

struct Edge {
    ring: usize,
    index: usize,
    a: Point2,
    b: Point2,
    min_x: Real,
    max_x: Real,
}

/// Checks that no two edges of any rings meet, except adjacent edges of one ring at their
/// shared vertex (and there they must not fold back onto each other).
fn check_no_intersections(rings: &[(RingId, Vec<Point2>)]) -> Result<(), PatchError> {
    let mut edges = Vec::new();
    for (r, (_, points)) in rings.iter().enumerate() {
        let n = points.len();
        for i in 0..n {
            let a = points[i];
            let b = points[(i + 1) % n];
            edges.push(Edge { ring: r, index: i, a, b, min_x: a.x.min(b.x), max_x: a.x.max(b.x) });
        }
    }
    edges.sort_by(|e, f| e.min_x.total_cmp(&f.min_x));
    for (i, e) in edges.iter().enumerate() {
        for f in &edges[i + 1..] {
            if f.min_x > e.max_x {
                break;
            }
            if edges_conflict(rings, e, f) {
                let (first, second) =
                    if (e.ring, e.index) < (f.ring, f.index) { (e, f) } else { (f, e) };
                return Err(PatchError::EdgesIntersect {
                    ring_a: rings[first.ring].0,
                    edge_a: first.index,
                    ring_b: rings[second.ring].0,
                    edge_b: second.index,
                });
            }
        }
    }
    Ok(())
}

fn edges_conflict(rings: &[(RingId, Vec<Point2>)], e: &Edge, f: &Edge) -> bool {
    if e.ring == f.ring {
        let n = rings[e.ring].1.len();
        // Edge i runs from vertex i to vertex i + 1: consecutive edges share one vertex.
        let (first, second) = if (e.index + 1) % n == f.index {
            (e, f)
        } else if (f.index + 1) % n == e.index {
            (f, e)
        } else {
            return segments_intersect(&e.a, &e.b, &f.a, &f.b);
        };
        // first = (u, v), second = (v, w): they meet only at v unless collinear with w on u's
        // side of v (a spike folding back). Along a line through v, "same side" means the
        // coordinate-wise comparisons with v agree.
        let (u, v, w) = (&first.a, &first.b, &second.b);
        return orient(u, v, w) == 0.0
            && u.x.total_cmp(&v.x) == w.x.total_cmp(&v.x)
            && u.y.total_cmp(&v.y) == w.y.total_cmp(&v.y);
    }
    segments_intersect(&e.a, &e.b, &f.a, &f.b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::na::{self, Vector2};

    fn pts(c: &[(Real, Real)]) -> Vec<Point2> {
        c.iter().map(|&(x, y)| Point2::new(x, y)).collect()
    }

    fn square(lo: Real, hi: Real) -> Vec<Point2> {
        pts(&[(lo, lo), (hi, lo), (hi, hi), (lo, hi)])
    }

    #[test]
    fn square_with_hole_has_area_and_orientation() {
        let mut hole = square(1.0, 2.0);
        hole.reverse(); // given clockwise: kept clockwise
        let p = Polygon::new(square(0.0, 4.0), vec![square(1.0, 2.0)]).unwrap();
        assert!((p.area() - 15.0).abs() < 1e-12);
        assert!(p.outer().is_ccw());
        assert!(!p.holes()[0].is_ccw());
        assert_eq!(p.num_vertices(), 8);
        assert_eq!(p.edges().count(), 8);
        let q = Polygon::new(square(0.0, 4.0), vec![hole]).unwrap();
        assert_eq!(p, q);
    }

    #[test]
    fn clockwise_outer_ring_is_reversed() {
        let mut outer = square(0.0, 1.0);
        outer.reverse();
        let p = Polygon::new(outer, vec![]).unwrap();
        assert!(p.outer().is_ccw());
        assert!((p.area() - 1.0).abs() < 1e-15);
        assert!(p.outer().signed_area() > 0.0);
    }

    #[test]
    fn interior_is_left_of_every_edge() {
        let p = Polygon::new(square(0.0, 4.0), vec![square(1.0, 2.0)]).unwrap();
        for (a, b) in p.edges() {
            let mid = na::center(&a, &b);
            let left = mid + Vector2::new(-(b - a).y, (b - a).x) * 1e-3;
            assert!(p.contains(&left), "{a} -> {b}");
        }
    }

    #[test]
    fn contains_counts_boundaries_as_inside() {
        let p = Polygon::new(square(0.0, 4.0), vec![square(1.0, 2.0)]).unwrap();
        assert!(p.contains(&Point2::new(0.5, 0.5)));
        assert!(p.contains(&Point2::new(0.0, 0.0))); // outer vertex
        assert!(p.contains(&Point2::new(4.0, 2.0))); // outer edge
        assert!(!p.contains(&Point2::new(1.5, 1.5))); // inside the hole
        assert!(p.contains(&Point2::new(1.0, 1.5))); // on the hole boundary
        assert!(p.contains(&Point2::new(2.0, 2.0))); // hole vertex
        assert!(!p.contains(&Point2::new(4.0 + 1e-15, 2.0)));
        assert!(!p.contains(&Point2::new(-1.0, 2.0)));
        assert!(!p.contains(&Point2::new(Real::NAN, 2.0)));
        // Ray along an edge's supporting line and through vertices.
        assert!(!p.contains(&Point2::new(-1.0, 0.0)));
        assert!(!p.contains(&Point2::new(5.0, 4.0)));
    }

    #[test]
    fn contains_in_a_concave_polygon() {
        // A U shape: a wall with a door.
        let u = Polygon::new(
            pts(&[
                (0.0, 0.0),
                (1.0, 0.0),
                (1.0, 2.0),
                (2.0, 2.0),
                (2.0, 0.0),
                (3.0, 0.0),
                (3.0, 3.0),
                (0.0, 3.0),
            ]),
            vec![],
        )
        .unwrap();
        assert!(!u.contains(&Point2::new(1.5, 1.0)));
        assert!(u.contains(&Point2::new(1.5, 2.0)));
        assert!(u.contains(&Point2::new(0.5, 1.0)));
        assert!((u.area() - 7.0).abs() < 1e-12);
    }

    #[test]
    fn rejects_too_few_nonfinite_repeated() {
        assert!(matches!(
            Polygon::new(pts(&[(0.0, 0.0), (1.0, 0.0)]), vec![]),
            Err(PatchError::TooFewVertices { ring: RingId::Outer, count: 2 })
        ));
        assert!(matches!(
            Polygon::new(pts(&[(0.0, 0.0), (1.0, Real::NAN), (1.0, 1.0)]), vec![]),
            Err(PatchError::NonFiniteVertex { ring: RingId::Outer, vertex: 1 })
        ));
        assert!(matches!(
            Polygon::new(pts(&[(0.0, 0.0), (1.0, 0.0), (1.0, Real::INFINITY)]), vec![]),
            Err(PatchError::NonFiniteVertex { vertex: 2, .. })
        ));
        assert!(matches!(
            Polygon::new(pts(&[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 0.0)]), vec![]),
            Err(PatchError::RepeatedVertex { ring: RingId::Outer, vertex: 3 })
        ));
        assert!(matches!(
            Polygon::new(
                square(0.0, 4.0),
                vec![pts(&[(1.0, 1.0), (1.0, 1.0), (2.0, 2.0), (1.0, 2.0)])]
            ),
            Err(PatchError::RepeatedVertex { ring: RingId::Hole(0), vertex: 0 })
        ));
    }

    #[test]
    fn rejects_zero_area_and_spikes() {
        assert!(matches!(
            Polygon::new(pts(&[(0.0, 0.0), (1.0, 1.0), (2.0, 2.0)]), vec![]),
            Err(PatchError::ZeroArea { ring: RingId::Outer })
        ));
        assert!(matches!(
            Polygon::new(pts(&[(0.0, 0.0), (2.0, 0.0), (1.0, 0.0), (1.0, 1.0)]), vec![]),
            Err(PatchError::EdgesIntersect { .. })
        ));
        // A spike out of a square: (2,1) -> (3,1) -> (2,1) would repeat; go out and back along
        // a line through a vertex instead.
        assert!(matches!(
            Polygon::new(
                pts(&[(0.0, 0.0), (2.0, 0.0), (3.0, 0.0), (2.0, 0.0 + 0.0), (2.0, 2.0)]),
                vec![]
            ),
            Err(PatchError::EdgesIntersect { .. })
        ));
        assert!(Polygon::rectangle(Point2::new(0.0, 0.0), Point2::new(0.0, 1.0)).is_err());
        assert!(Polygon::rectangle(Point2::new(0.0, 0.0), Point2::new(1.0, 1.0)).is_ok());
    }

    #[test]
    fn rejects_self_intersections() {
        // Bow-tie.
        assert!(matches!(
            Polygon::new(pts(&[(0.0, 0.0), (1.0, 1.0), (1.0, 0.0), (0.0, 1.0)]), vec![]),
            Err(PatchError::EdgesIntersect {
                ring_a: RingId::Outer,
                edge_a: 0,
                ring_b: RingId::Outer,
                edge_b: 2
            })
        ));
        // Figure eight touching at one vertex.
        assert!(matches!(
            Polygon::new(
                pts(&[
                    (0.0, 0.0),
                    (1.0, 0.0),
                    (1.0, 1.0),
                    (2.0, 1.0),
                    (2.0, 2.0),
                    (1.0, 2.0),
                    (1.0, 1.0),
                    (0.0, 1.0)
                ]),
                vec![]
            ),
            Err(PatchError::EdgesIntersect { .. })
        ));
        // A vertex touching a non-adjacent edge.
        assert!(matches!(
            Polygon::new(
                pts(&[(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (1.0, 0.0), (0.0, 2.0)]),
                vec![]
            ),
            Err(PatchError::EdgesIntersect { .. })
        ));
    }

    #[test]
    fn rejects_bad_holes() {
        let outer = square(0.0, 4.0);
        assert!(matches!(
            Polygon::new(outer.clone(), vec![square(5.0, 6.0)]),
            Err(PatchError::HoleOutside { hole: 0 })
        ));
        // Hole touching the outer ring at a vertex.
        assert!(matches!(
            Polygon::new(outer.clone(), vec![square(0.0, 1.0)]),
            Err(PatchError::EdgesIntersect { ring_a: RingId::Outer, ring_b: RingId::Hole(0), .. })
        ));
        // Hole crossing the outer ring.
        assert!(matches!(
            Polygon::new(outer.clone(), vec![square(3.0, 5.0)]),
            Err(PatchError::EdgesIntersect { .. })
        ));
        // Holes touching each other along an edge, and at a corner.
        assert!(matches!(
            Polygon::new(
                outer.clone(),
                vec![square(1.0, 2.0), pts(&[(2.0, 1.0), (3.0, 1.0), (3.0, 2.0), (2.0, 2.0)])]
            ),
            Err(PatchError::EdgesIntersect {
                ring_a: RingId::Hole(0),
                ring_b: RingId::Hole(1),
                ..
            })
        ));
        assert!(matches!(
            Polygon::new(outer.clone(), vec![square(1.0, 2.0), square(2.0, 3.0)]),
            Err(PatchError::EdgesIntersect { .. })
        ));
        // Nested holes.
        assert!(matches!(
            Polygon::new(outer.clone(), vec![square(0.5, 3.5), square(1.0, 2.0)]),
            Err(PatchError::NestedHoles { outer_hole: 0, inner_hole: 1 })
        ));
        // Outer ring inside the hole is "hole outside".
        assert!(matches!(
            Polygon::new(square(1.0, 2.0), vec![outer]),
            Err(PatchError::HoleOutside { hole: 0 })
        ));
    }

    #[test]
    fn triangle_rings_are_accepted_in_both_orientations() {
        let t = pts(&[(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]);
        let mut r = t.clone();
        r.reverse();
        let a = Polygon::new(t, vec![]).unwrap();
        let b = Polygon::new(r, vec![]).unwrap();
        assert!((a.area() - 0.5).abs() < 1e-15);
        assert!((b.area() - 0.5).abs() < 1e-15);
    }

    #[test]
    fn closest_boundary_point_includes_holes() {
        let p = Polygon::new(square(0.0, 4.0), vec![square(1.0, 2.0)]).unwrap();
        let (q, d) = p.closest_boundary_point(&Point2::new(1.5, 1.4));
        assert!((d - 0.4).abs() < 1e-12);
        assert!((q - Point2::new(1.5, 1.0)).norm() < 1e-12);
        let b = p.bounds2();
        assert_eq!(b.min, Point2::new(0.0, 0.0));
        assert_eq!(b.max, Point2::new(4.0, 4.0));
    }

    #[test]
    fn segment_predicates_are_exact() {
        let a = Point2::new(0.1, 0.1);
        let b = Point2::new(0.3, 0.3);
        // 0.2 is not exactly between in binary, but (0.2, 0.2) is collinear only if exact.
        let c = Point2::new(0.2, 0.2);
        assert_eq!(on_segment(&a, &b, &c), orient(&a, &b, &c) == 0.0);
        assert!(segments_intersect(
            &Point2::new(0.0, 0.0),
            &Point2::new(2.0, 0.0),
            &Point2::new(1.0, 0.0),
            &Point2::new(1.0, 5.0)
        ));
        assert!(segments_intersect(
            &Point2::new(0.0, 0.0),
            &Point2::new(2.0, 0.0),
            &Point2::new(1.0, 0.0),
            &Point2::new(3.0, 0.0)
        ));
        assert!(!segments_intersect(
            &Point2::new(0.0, 0.0),
            &Point2::new(2.0, 0.0),
            &Point2::new(2.5, 0.0),
            &Point2::new(3.0, 0.0)
        ));
        assert!(!segments_intersect(
            &Point2::new(0.0, 0.0),
            &Point2::new(2.0, 0.0),
            &Point2::new(1.0, 1e-300),
            &Point2::new(1.0, 5.0)
        ));
    }
}
