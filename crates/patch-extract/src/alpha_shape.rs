//! 2D α-shapes of projected region points (thesis Alg. 6, L4839–4909; spec §2.3 and §7.3).
//!
//! The thesis uses CGAL's `Alpha_shape_2` with "the optimal α for one component". Its printed
//! Alg. 6 (keep Delaunay edges whose diametral circle is small and empty) is not the exact
//! α-exposure definition and drops holes, so this module follows the spec's resolution (§7.3):
//! CGAL's **regularized** α-complex, holes kept.
//!
//! # Definitions
//! * The Delaunay triangulation of the points is built with spade (exact predicates). Exact
//!   duplicate points are merged (spade keeps one); they are not an error unless fewer than 3
//!   distinct points remain. Input whose triangles have a total area below `1e-10` of the
//!   squared bounding-box diagonal counts as collinear (projection rounding turns a line of
//!   points into slivers).
//! * α is a **radius** in the points' units (metres). A triangle is *interior* iff its
//!   circumradius is `≤ α`. (CGAL's α is the squared radius: CGAL α = `alpha²`.)
//! * Regularized mode: the shape is the union of the interior triangles. A Delaunay edge is a
//!   *boundary* edge iff exactly one of its two triangles is interior (the convex-hull side
//!   counts as not interior). Isolated edges and vertices (CGAL's singular faces) are dropped.
//! * *Components* are the classes of interior triangles connected through shared edges
//!   (CGAL's "solid components"); triangles meeting at a vertex only are separate components.
//!
//! # The optimal α ([`AlphaChoice::Optimal`])
//! CGAL's `find_optimal_alpha(k)`: the smallest α such that (1) every point is a vertex of an
//! interior triangle ("on the boundary or in the interior") and (2) there are at most `k`
//! components. Candidate values are the triangles' circumradii (the complex only changes
//! there). They are sorted and the triangles added in that order (ties together) while a
//! union–find over edge-adjacent triangles counts components and a per-vertex flag counts
//! covered points; the first candidate meeting both conditions is returned, widened by a
//! relative `1e-9` so that cocircular points (regular grids), whose radii differ only by
//! rounding, count as ties. Coverage only grows with α, so no candidate below the smallest
//! radius at which enough points are covered (each point is covered from the smallest
//! circumradius of its triangles on: a selection, O(n)) can qualify: the triangles up to it
//! enter at once, and only the larger ones are sorted. This is
//! O(n log n) and exact; CGAL bisects over the candidates instead, which can return a larger α
//! where the component count is not monotone in α. The whole triangulation is always one
//! component covering every point, so a candidate always exists.
//!
//! [`AlphaChoice::Robust`] (not in the thesis) runs the same search but accepts the first
//! candidate that leaves at most a given share of the points uncovered: stray points (a band
//! of another surface that joined the region, a mixed pixel) no longer force α up to half
//! their distance from the rest. Measured on the lab (8 scans, scene seed 0, step seed 1;
//! planes map, unsafe / overcautious %): optimal α 2.73 / 1.39; robust, 2 % uncovered, one
//! component 2.77 / 1.28; three components (all kept) 2.84 / 1.18.
//!
//! # Rings
//! Boundary edges are directed with the interior on their left (outer rings counter-clockwise,
//! holes clockwise) and chained within their component. At a vertex with several outgoing
//! boundary edges of the component (a *pinch*, ≥ 4 boundary edges), the walk takes the first
//! outgoing edge counter-clockwise from the incoming edge's reverse, i.e. it goes around the
//! exterior sector on its right; so each ring bounds one face of the complement and visits a
//! vertex at most once. Rings belong to the component whose triangles border them: per
//! component the counter-clockwise ring of largest area is the outer ring and its clockwise
//! rings are holes (no containment tests needed). Where rings of one component still share a
//! vertex (a hole touching the outer ring or another hole at a point), each occurrence is moved
//! by `1e-6 ×` its shorter adjacent edge along the bisector into the exterior sector its ring
//! bounds there, so the rings are disjoint and form a valid [`Polygon`] with the touching hole
//! kept as a hole (the polygon gains a sliver of that width at the pinch). If a component's
//! rings still fail validation, its holes are dropped (counted in
//! [`AlphaShape::dropped_holes`]).
//!
//! # Holes and components
//! [`HoleFilter`] fills sampling holes (the thesis configuration fills holes smaller than a
//! disc of radius 2α). [`ComponentPolicy`] returns the largest component or all of them,
//! largest area first; at the optimal α for one component both give the same single polygon.

use patch_core::{PatchError, Point2, Polygon, Real};
use spade::{DelaunayTriangulation, Triangulation};

/// Which α to use.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum AlphaChoice {
    /// This radius (metres), `> 0`.
    Radius(Real),
    /// CGAL's `find_optimal_alpha(max_components)` (see the module docs); the thesis uses 1.
    Optimal {
        /// The largest acceptable number of components, `≥ 1`.
        max_components: usize,
    },
    /// The optimal α with stray points allowed: the smallest α at which at most
    /// `max_components` components cover all but a share `max_uncovered` of the points (not
    /// in the thesis). The optimal α must reach every point, so one stray point a metre from
    /// the rest (a band of another surface, a mixed pixel) makes α half a metre and the
    /// shape a blob across every gap; the stray points are left out instead.
    Robust {
        /// The largest acceptable number of components, `≥ 1`.
        max_components: usize,
        /// The largest share of points left uncovered, in [0, 1).
        max_uncovered: Real,
    },
}

/// The share of points [`AlphaShapeConfig::robust`] may leave out.
pub const ROBUST_MAX_UNCOVERED: Real = 0.02;

/// What to return when the shape at the chosen α has several components.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum ComponentPolicy {
    /// Only the component of largest area (the thesis wants one polygon per region).
    Largest,
    /// Every component as its own polygon, largest area first.
    All,
}

/// Which holes of the α-shape to keep.
///
/// At the optimal α, irregular sampling leaves many tiny holes: single Delaunay triangles (or
/// small groups) whose circumradius exceeds α, surrounded by interior triangles. They are
/// sampling noise, not openings of the surface; filtering them fills them (the polygon then
/// covers those triangles too).
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum HoleFilter {
    /// Keep every hole of the regularized α-complex (CGAL's output).
    KeepAll,
    /// Drop holes with an area below this many square metres.
    MinArea(Real),
    /// Drop holes with an area below `factor · α²` (`π` = smaller than a disc of radius α,
    /// which the α-shape cannot resolve anyway).
    AlphaScaled(Real),
}

/// α-shape parameters. No `Default`: start from [`AlphaShapeConfig::thesis`].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct AlphaShapeConfig {
    /// The α.
    pub alpha: AlphaChoice,
    /// Which components to return.
    pub components: ComponentPolicy,
    /// Which holes to keep.
    pub holes: HoleFilter,
    /// The largest α the optimal and robust choices may take, metres (> 0; not in the
    /// thesis); `None`: no limit. An α-shape closes every opening narrower than 2α, so a
    /// region seen sparsely (a wall far along a corridor) whose optimal α is half a metre
    /// closes its doorways. Above the limit the shape may have more components than asked
    /// for and leave more points out; [`ComponentPolicy::All`] keeps every component. If no
    /// triangle is small enough, the limit is not applied.
    pub max_alpha: Option<Real>,
}

impl AlphaShapeConfig {
    /// The thesis's choice (L4905–4909): the optimal α for one component; with that α the
    /// shape has exactly one component, so the policy only matters for a given α. Holes
    /// smaller than a disc of radius 2α are filled ([`HoleFilter::AlphaScaled`]`(4π)`; the
    /// thesis says nothing about holes, spec §7.3 keeps them). The factor is a heuristic: on
    /// a grid jittered by ±¼ of its spacing the optimal α is about 0.8 spacings and the
    /// sampling holes cover up to about 3 grid cells (≈ 4.5 α²), while openings worth mapping
    /// (windows, doors) are far larger than α.
    pub fn thesis() -> AlphaShapeConfig {
        AlphaShapeConfig {
            alpha: AlphaChoice::Optimal { max_components: 1 },
            components: ComponentPolicy::Largest,
            holes: HoleFilter::AlphaScaled(4.0 * std::f64::consts::PI),
            max_alpha: None,
        }
    }

    /// [`AlphaShapeConfig::thesis`] with [`AlphaChoice::Robust`]: one component covering all
    /// but [`ROBUST_MAX_UNCOVERED`] of the points.
    pub fn robust() -> AlphaShapeConfig {
        AlphaShapeConfig {
            alpha: AlphaChoice::Robust { max_components: 1, max_uncovered: ROBUST_MAX_UNCOVERED },
            ..AlphaShapeConfig::thesis()
        }
    }

    /// [`AlphaShapeConfig::robust`] with α at most `max_alpha` metres and every component
    /// kept: openings wider than `2 · max_alpha` stay open.
    pub fn robust_at_most(max_alpha: Real) -> AlphaShapeConfig {
        AlphaShapeConfig {
            components: ComponentPolicy::All,
            max_alpha: Some(max_alpha),
            ..AlphaShapeConfig::robust()
        }
    }

    /// The exact regularized α-complex for a fixed radius: all components, all holes.
    pub fn with_radius(alpha: Real) -> AlphaShapeConfig {
        AlphaShapeConfig {
            alpha: AlphaChoice::Radius(alpha),
            components: ComponentPolicy::All,
            holes: HoleFilter::KeepAll,
            max_alpha: None,
        }
    }
}

/// Why no α-shape could be computed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum AlphaShapeError {
    /// Fewer than 3 points were given.
    #[error("{count} points given, at least 3 are needed")]
    TooFewPoints {
        /// The number of points.
        count: usize,
    },
    /// Fewer than 3 distinct points remain after merging exact duplicates.
    #[error("only {distinct} distinct points, at least 3 are needed")]
    TooFewDistinctPoints {
        /// The number of distinct points.
        distinct: usize,
    },
    /// All points lie on one line: there is no triangle.
    #[error("all points are collinear")]
    Collinear,
    /// A coordinate is NaN, infinite or beyond what exact predicates handle.
    #[error("point {index} has a coordinate that cannot be triangulated")]
    BadCoordinate {
        /// The point index.
        index: usize,
    },
    /// The given α is not a positive finite number, `max_components` is 0, or the hole filter's
    /// parameter is negative or not finite.
    #[error("invalid α parameter {value}")]
    InvalidAlpha {
        /// The offending value.
        value: Real,
    },
    /// At the given α no triangle is interior.
    #[error("no triangle has a circumradius ≤ α = {alpha}")]
    Empty {
        /// The α used.
        alpha: Real,
    },
    /// A component's outer ring is not a valid polygon even without holes (should not happen).
    #[error("component outline is invalid: {0}")]
    InvalidOutline(PatchError),
}

/// The result of [`alpha_shape`].
#[derive(Clone, Debug, PartialEq)]
pub struct AlphaShape {
    /// The α used (a radius).
    pub alpha: Real,
    /// `alpha²`, exactly the value the triangles' squared circumradii were compared with
    /// (= CGAL's α).
    pub alpha_squared: Real,
    /// The polygons, largest area first (one unless [`ComponentPolicy::All`]).
    pub polygons: Vec<Polygon>,
    /// The number of components at this α (before the policy picked some).
    pub num_components: usize,
    /// The number of interior triangles.
    pub num_interior_triangles: usize,
    /// The total area of the interior triangles (all components): the exact area of the
    /// α-complex, which the polygons reproduce up to rounding and pinch separation.
    pub interior_area: Real,
    /// The number of distinct points (Delaunay vertices).
    pub num_distinct_points: usize,
    /// Holes dropped because their component failed validation with them.
    pub dropped_holes: usize,
    /// Holes filled by the [`HoleFilter`].
    pub filled_holes: usize,
}

const NONE: u32 = u32::MAX;

/// A Delaunay triangulation flattened into arrays: counter-clockwise triangles, the triangle
/// across each edge (`edge i` runs from vertex `i` to vertex `i + 1`), squared circumradii.
struct Mesh {
    vertices: Vec<Point2>,
    triangles: Vec<[u32; 3]>,
    neighbours: Vec<[u32; 3]>,
    radius2: Vec<Real>,
}

fn snap(v: Real) -> Real {
    if v.abs() < 1e-30 { 0.0 } else { v }
}

/// A Delaunay vertex: its position and whether it is a fill point ([`alpha_shape_filled`]).
#[derive(Copy, Clone, Debug)]
struct Site {
    position: spade::Point2<Real>,
    fill: bool,
}

impl spade::HasPosition for Site {
    type Scalar = Real;

    fn position(&self) -> spade::Point2<Real> {
        self.position
    }
}

/// The mesh of `points` followed by `fill` (see [`alpha_shape_filled`]): every triangle with a
/// fill vertex gets the squared radius [`Real::MIN_POSITIVE`], below every other triangle's,
/// so it is interior at every α and never decides α.
fn build_mesh(points: &[Point2], fill: &[Point2]) -> Result<Mesh, AlphaShapeError> {
    let all = || points.iter().chain(fill);
    if points.len() + fill.len() < 3 {
        return Err(AlphaShapeError::TooFewPoints { count: points.len() + fill.len() });
    }
    if let Some(index) = all().position(|p| !(p.x.is_finite() && p.y.is_finite())) {
        return Err(AlphaShapeError::BadCoordinate { index });
    }
    let input: Vec<Site> = all()
        .enumerate()
        .map(|(i, p)| Site {
            position: spade::Point2::new(snap(p.x), snap(p.y)),
            fill: i >= points.len(),
        })
        .collect();
    let dt = match DelaunayTriangulation::<Site>::bulk_load(input) {
        Ok(dt) => dt,
        Err(_) => {
            // Find the offending point for the error message.
            let index = all()
                .position(|p| {
                    spade::validate_coordinate(snap(p.x)).is_err()
                        || spade::validate_coordinate(snap(p.y)).is_err()
                })
                .unwrap_or(0);
            return Err(AlphaShapeError::BadCoordinate { index });
        }
    };
    let distinct = dt.num_vertices();
    if distinct < 3 {
        return Err(AlphaShapeError::TooFewDistinctPoints { distinct });
    }
    if dt.num_inner_faces() == 0 {
        return Err(AlphaShapeError::Collinear);
    }
    let vertices: Vec<Point2> =
        dt.vertices().map(|v| Point2::new(v.position().x, v.position().y)).collect();
    let is_fill: Vec<bool> = dt.vertices().map(|v| v.data().fill).collect();
    // Nearly collinear input (e.g. points of a line after projection rounding) gives only
    // slivers: treat a total area below 1e-10 of the squared bounding-box diagonal as
    // collinear.
    let (mut lo, mut hi) = (vertices[0], vertices[0]);
    for p in &vertices {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let n = dt.num_inner_faces();
    let mut triangles = vec![[0; 3]; n];
    let mut neighbours = vec![[NONE; 3]; n];
    // A face's corners in the order of its `adjacent_edges()` `[e0, e1, e2]` (`e1` its
    // `adjacent_edge()`, `e0` before it, `e2` after it) with the face across each edge, filled
    // edge by edge in storage order (fewer cache misses than walking each face's edges).
    // Inner faces are numbered from 1 (0 is the outer face).
    let adjacent: Vec<usize> = dt.inner_faces().map(|f| f.adjacent_edge().fix().index()).collect();
    for e in dt.directed_edges() {
        let Some(face) = e.face().as_inner() else { continue };
        let t = face.fix().index() - 1;
        let first = adjacent[t];
        let i = if e.fix().index() == first {
            1
        } else if e.next().fix().index() == first {
            0
        } else {
            2
        };
        triangles[t][i] = e.from().fix().index() as u32;
        neighbours[t][i] = e.rev().face().as_inner().map_or(NONE, |f| (f.fix().index() - 1) as u32);
    }
    // Areas and circumradii as spade's `area` and `circumcircle` compute them from the
    // face's vertex positions (in this order), summed in face order.
    let corners = |t: usize| {
        let [a, b, c] = triangles[t].map(|v| vertices[v as usize]);
        (a, b - a, c - a)
    };
    let total_area: Real = (0..n)
        .map(|t| {
            let (_, b, c) = corners(t);
            (b.x * c.y - b.y * c.x).abs() * 0.5
        })
        .sum();
    if total_area <= 1e-10 * (hi - lo).norm_squared() {
        return Err(AlphaShapeError::Collinear);
    }
    let radius2 = (0..n)
        .map(|t| {
            let (_, b, c) = corners(t);
            let d = 2.0 * (b.x * c.y - c.x * b.y);
            let (len_b, len_c) = (b.x * b.x + b.y * b.y, c.x * c.x + c.y * c.y);
            let d_inv = 1.0 / d;
            let x = (len_b * c.y - len_c * b.y) * d_inv;
            let y = (-len_b * c.x + len_c * b.x) * d_inv;
            let r2 = x * x + y * y;
            if triangles[t].iter().any(|&v| is_fill[v as usize]) {
                Real::MIN_POSITIVE
            } else if r2.is_nan() {
                Real::INFINITY
            } else {
                r2
            }
        })
        .collect();
    Ok(Mesh { vertices, triangles, neighbours, radius2 })
}

struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    fn new(n: usize) -> UnionFind {
        UnionFind { parent: (0..n as u32).collect() }
    }
    fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let p = self.parent[x as usize];
            self.parent[x as usize] = self.parent[p as usize];
            x = p;
        }
        x
    }
    /// Joins the classes; `true` if they were different.
    fn union(&mut self, a: u32, b: u32) -> bool {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra == rb {
            return false;
        }
        self.parent[ra.max(rb) as usize] = ra.min(rb);
        true
    }
}

/// An integer whose order is [`f64::total_cmp`]'s order of `x` (the key `total_cmp` itself
/// compares).
fn total_order_key(x: Real) -> i64 {
    let bits = x.to_bits() as i64;
    bits ^ ((((bits >> 63) as u64) >> 1) as i64)
}

/// The optimal squared radius with at most `allowed_uncovered` points uncovered: see the
/// module docs.
/// With the squared radius: the union–find over the triangles added by then (those with a
/// squared radius up to the candidate's, `added`), whose classes are their components.
fn optimal_alpha_squared(
    mesh: &Mesh,
    max_components: usize,
    allowed_uncovered: usize,
) -> (Real, UnionFind, Vec<bool>) {
    let n = mesh.triangles.len();
    let nv = mesh.vertices.len();
    let mut uf = UnionFind::new(n);
    let mut added = vec![false; n];
    let mut covered = vec![false; nv];
    let mut uncovered = nv;
    let mut components = 0usize;
    let mut add = |t: u32, uncovered: &mut usize, components: &mut usize| {
        added[t as usize] = true;
        *components += 1;
        for i in 0..3 {
            let v = mesh.triangles[t as usize][i] as usize;
            if !covered[v] {
                covered[v] = true;
                *uncovered -= 1;
            }
            let m = mesh.neighbours[t as usize][i];
            if m != NONE && added[m as usize] && uf.union(t, m) {
                *components -= 1;
            }
        }
    };
    // No candidate below the smallest squared radius `first` at which few enough points are
    // uncovered can be accepted (coverage only grows with α); a vertex is covered from the
    // smallest radius of its triangles on. The triangles up to `first` enter at once, in index
    // order (the component count and the coverage do not depend on the order); only the
    // larger ones are sorted. With every radius positive (no NaN, no zero) `==` ties and
    // `total_cmp` order agree.
    let (mut first, mut found) = (None, None);
    if n > 0 && allowed_uncovered < nv && mesh.radius2.iter().all(|&r2| r2 > 0.0) {
        let mut smallest = vec![Real::INFINITY; nv];
        for (tri, &r2) in mesh.triangles.iter().zip(&mesh.radius2) {
            for &v in tri {
                smallest[v as usize] = smallest[v as usize].min(r2);
            }
        }
        let k = nv - allowed_uncovered - 1;
        let (_, &mut threshold, _) = smallest.select_nth_unstable_by(k, Real::total_cmp);
        for t in 0..n {
            if mesh.radius2[t] <= threshold {
                add(t as u32, &mut uncovered, &mut components);
            }
        }
        if uncovered <= allowed_uncovered && components <= max_components {
            found = Some(threshold);
        }
        first = Some(threshold);
    }
    if let Some(r2) = found {
        return (r2 * (1.0 + 1e-9), uf, added);
    }
    // The other triangles by squared radius (`total_cmp` order, on its integer image sorted
    // with the index alongside); the order within ties does not matter, ties enter together.
    let mut keyed: Vec<(i64, u32)> = mesh
        .radius2
        .iter()
        .enumerate()
        .filter(|&(_, &r2)| first.is_none_or(|f| r2 > f))
        .map(|(t, &r2)| (total_order_key(r2), t as u32))
        .collect();
    keyed.sort_unstable_by_key(|&(key, _)| key);
    let order: Vec<u32> = keyed.into_iter().map(|(_, t)| t).collect();
    let mut k = 0;
    while k < order.len() {
        let r2 = mesh.radius2[order[k] as usize];
        // Add every triangle with this squared radius (ties enter together).
        while k < order.len() && mesh.radius2[order[k] as usize] == r2 {
            add(order[k], &mut uncovered, &mut components);
            k += 1;
        }
        if uncovered <= allowed_uncovered && components <= max_components {
            // Cocircular points (regular grids) give radii equal up to rounding: count values
            // within a relative 1e-9 as ties.
            return (r2 * (1.0 + 1e-9), uf, added);
        }
    }
    // Unreachable for a valid triangulation (all triangles = one covering component): the
    // largest squared radius.
    let largest = mesh.radius2.iter().copied().max_by(Real::total_cmp).unwrap_or(Real::INFINITY);
    (largest, uf, added)
}

/// CGAL's `find_optimal_alpha(max_components)` for these points, as a radius: see the module
/// docs for the exact rule.
///
/// # Errors
/// As [`alpha_shape`].
///
/// # Complexity
/// O(n log n).
pub fn optimal_alpha(points: &[Point2], max_components: usize) -> Result<Real, AlphaShapeError> {
    if max_components == 0 {
        return Err(AlphaShapeError::InvalidAlpha { value: 0.0 });
    }
    let mesh = build_mesh(points, &[])?;
    Ok(optimal_alpha_squared(&mesh, max_components, 0).0.sqrt())
}

/// The regularized α-shape of `points` as polygons with holes (see the module docs).
///
/// # Errors
/// [`AlphaShapeError::TooFewPoints`], [`AlphaShapeError::TooFewDistinctPoints`],
/// [`AlphaShapeError::Collinear`], [`AlphaShapeError::BadCoordinate`] for degenerate input;
/// [`AlphaShapeError::InvalidAlpha`] for a non-positive α or `max_components = 0`;
/// [`AlphaShapeError::Empty`] when a given α is smaller than every circumradius.
///
/// # Complexity
/// O(n log n) for n points (Delaunay triangulation, sorting, ring validation).
pub fn alpha_shape(
    points: &[Point2],
    config: &AlphaShapeConfig,
) -> Result<AlphaShape, AlphaShapeError> {
    alpha_shape_filled(points, &[], config)
}

/// [`alpha_shape`] of `points` together with `fill` points known to lie deep inside the
/// shape (not in the thesis): every Delaunay triangle with a fill vertex is interior whatever
/// its circumradius, and counts as the smallest, so fill points never decide α (they are
/// covered from the start; [`AlphaChoice::Robust`]'s share counts them too). With `fill`
/// empty this is [`alpha_shape`].
///
/// It is meant for the points of an organised region thinned to a band along its pixel
/// outline plus a sparse lattice inside ([`crate::polygonize::GridThinning`]): the band
/// decides the outline as all points would, the fill lattice joins the band's parts, so the
/// empty inside is neither a hole nor a second component.
///
/// # Errors
/// As [`alpha_shape`]; [`AlphaShapeError::BadCoordinate`] indexes `points` then `fill`.
///
/// # Complexity
/// O(n log n) for n points and fill points together.
pub fn alpha_shape_filled(
    points: &[Point2],
    fill: &[Point2],
    config: &AlphaShapeConfig,
) -> Result<AlphaShape, AlphaShapeError> {
    match config.alpha {
        AlphaChoice::Radius(a) if !(a.is_finite() && a > 0.0) => {
            return Err(AlphaShapeError::InvalidAlpha { value: a });
        }
        AlphaChoice::Optimal { max_components: 0 }
        | AlphaChoice::Robust { max_components: 0, .. } => {
            return Err(AlphaShapeError::InvalidAlpha { value: 0.0 });
        }
        AlphaChoice::Robust { max_uncovered, .. } if !(0.0..1.0).contains(&max_uncovered) => {
            return Err(AlphaShapeError::InvalidAlpha { value: max_uncovered });
        }
        _ => {}
    }
    if let HoleFilter::MinArea(v) | HoleFilter::AlphaScaled(v) = config.holes
        && !(v.is_finite() && v >= 0.0)
    {
        return Err(AlphaShapeError::InvalidAlpha { value: v });
    }
    if let Some(m) = config.max_alpha
        && !(m.is_finite() && m > 0.0)
    {
        return Err(AlphaShapeError::InvalidAlpha { value: m });
    }
    let mesh = build_mesh(points, fill)?;
    // With the search's union–find: the components of the triangles it added.
    let (alpha_squared, searched) = match config.alpha {
        AlphaChoice::Radius(a) => (a * a, None),
        AlphaChoice::Optimal { max_components } => {
            let (alpha_squared, uf, added) = optimal_alpha_squared(&mesh, max_components, 0);
            (alpha_squared, Some((uf, added)))
        }
        AlphaChoice::Robust { max_components, max_uncovered } => {
            let allowed = (max_uncovered * mesh.vertices.len() as Real).floor() as usize;
            let (alpha_squared, uf, added) = optimal_alpha_squared(&mesh, max_components, allowed);
            (alpha_squared, Some((uf, added)))
        }
    };
    // The limit (not for a given radius): the search's union–find then joined triangles above
    // it, so the components are found afresh.
    let (alpha_squared, searched) = match config.max_alpha {
        Some(m)
            if !matches!(config.alpha, AlphaChoice::Radius(_))
                && alpha_squared > m * m
                && mesh.radius2.iter().any(|&r2| r2 <= m * m) =>
        {
            (m * m, None)
        }
        _ => (alpha_squared, searched),
    };
    let alpha = alpha_squared.sqrt();
    let min_hole_area = match config.holes {
        HoleFilter::KeepAll => 0.0,
        HoleFilter::MinArea(a) => a,
        HoleFilter::AlphaScaled(f) => f * alpha_squared,
    };
    let mut filled_holes = 0;
    let interior: Vec<bool> = mesh.radius2.iter().map(|&r2| r2 <= alpha_squared).collect();
    let num_interior_triangles = interior.iter().filter(|&&b| b).count();
    let interior_area: Real = (0..mesh.triangles.len())
        .filter(|&t| interior[t])
        .map(|t| {
            let [a, b, c] = mesh.triangles[t].map(|v| mesh.vertices[v as usize]);
            0.5 * (b - a).perp(&(c - a))
        })
        .sum();
    if num_interior_triangles == 0 {
        return Err(AlphaShapeError::Empty { alpha });
    }
    // Components.
    // The classes do not depend on the order of the unions. The search added a subset of the
    // interior triangles (radii up to the candidate's, below α² = candidate · (1 + 1e-9)) and
    // joined every adjacent pair of them; the rest join their interior neighbours here.
    let n = mesh.triangles.len();
    let (mut uf, added) = searched.unwrap_or_else(|| (UnionFind::new(n), vec![false; n]));
    for t in 0..n {
        if !interior[t] || added[t] {
            continue;
        }
        for &m in &mesh.neighbours[t] {
            // A pair of two such triangles once, from its later one.
            if m != NONE && interior[m as usize] && (added[m as usize] || (m as usize) < t) {
                uf.union(t as u32, m);
            }
        }
    }
    let mut component_of_root = vec![NONE; n];
    let mut num_components = 0usize;
    for (t, &inside) in interior.iter().enumerate() {
        if inside {
            let r = uf.find(t as u32) as usize;
            if component_of_root[r] == NONE {
                component_of_root[r] = num_components as u32;
                num_components += 1;
            }
        }
    }
    // Boundary edges, interior on the left, grouped by start vertex (CSR).
    let mut edges: Vec<(u32, u32, u32)> = Vec::new(); // (from, to, component)
    for t in 0..n {
        if !interior[t] {
            continue;
        }
        let comp = component_of_root[uf.find(t as u32) as usize];
        for i in 0..3 {
            let m = mesh.neighbours[t][i];
            if m == NONE || !interior[m as usize] {
                edges.push((mesh.triangles[t][i], mesh.triangles[t][(i + 1) % 3], comp));
            }
        }
    }
    let nv = mesh.vertices.len();
    let mut start = vec![0u32; nv + 1];
    for &(from, _, _) in &edges {
        start[from as usize + 1] += 1;
    }
    for v in 0..nv {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    let mut outgoing = vec![0u32; edges.len()];
    for (e, &(from, _, _)) in edges.iter().enumerate() {
        outgoing[fill[from as usize] as usize] = e as u32;
        fill[from as usize] += 1;
    }
    let successor = |e: u32| -> u32 {
        let (u, v, comp) = edges[e as usize];
        let out = &outgoing[start[v as usize] as usize..start[v as usize + 1] as usize];
        if out.len() == 1 {
            return out[0];
        }
        let (pu, pv) = (mesh.vertices[u as usize], mesh.vertices[v as usize]);
        let d_in = pu - pv;
        let mut best = (Real::INFINITY, NONE);
        for &f in out {
            let (_, w, f_comp) = edges[f as usize];
            if f_comp != comp {
                continue;
            }
            let d_out = mesh.vertices[w as usize] - pv;
            // Counter-clockwise angle from d_in to d_out, in (0, 2π]: the first boundary edge
            // across the exterior sector on the incoming edge's right.
            let mut angle = d_in.perp(&d_out).atan2(d_in.dot(&d_out));
            if angle <= 0.0 {
                angle += std::f64::consts::TAU;
            }
            if angle < best.0 {
                best = (angle, f);
            }
        }
        best.1
    };
    let mut used = vec![false; edges.len()];
    // Rings as vertex-index lists, with their component.
    let mut rings: Vec<(u32, Vec<u32>)> = Vec::new();
    for e0 in 0..edges.len() as u32 {
        if used[e0 as usize] {
            continue;
        }
        let mut ring = Vec::new();
        let mut e = e0;
        loop {
            used[e as usize] = true;
            ring.push(edges[e as usize].0);
            e = successor(e);
            if e == NONE || e == e0 || used[e as usize] {
                break;
            }
        }
        rings.push((edges[e0 as usize].2, ring));
    }
    // Per component: occurrences of each vertex, to separate pinches.
    let mut by_component: Vec<Vec<Vec<u32>>> = vec![Vec::new(); num_components];
    for (comp, ring) in rings {
        by_component[comp as usize].push(ring);
    }
    let mut polygons: Vec<(Real, Polygon)> = Vec::new();
    let mut dropped_holes = 0;
    let mut count = vec![0u32; nv];
    for comp_rings in &by_component {
        for ring in comp_rings {
            for &v in ring {
                count[v as usize] += 1;
            }
        }
        let mut outers: Vec<(Real, Vec<Point2>)> = Vec::new();
        let mut holes: Vec<Vec<Point2>> = Vec::new();
        for ring in comp_rings {
            let points = ring_points(&mesh.vertices, ring, &count);
            let area = signed_area(&points);
            if area > 0.0 {
                outers.push((area, points));
            } else if -area < min_hole_area {
                filled_holes += 1;
            } else {
                holes.push(points);
            }
        }
        for ring in comp_rings {
            for &v in ring {
                count[v as usize] = 0;
            }
        }
        outers.sort_by(|a, b| b.0.total_cmp(&a.0));
        let mut outers = outers.into_iter();
        let Some((_, outer)) = outers.next() else {
            continue; // a component always has an outer ring; defensive
        };
        let polygon = match Polygon::new(outer.clone(), holes.clone()) {
            Ok(p) => p,
            Err(_) => {
                dropped_holes += holes.len();
                Polygon::new(outer, Vec::new()).map_err(AlphaShapeError::InvalidOutline)?
            }
        };
        polygons.push((polygon.area(), polygon));
        // Further counter-clockwise rings (not expected for edge-connected components) become
        // polygons of their own.
        for (_, extra) in outers {
            if let Ok(p) = Polygon::new(extra, Vec::new()) {
                polygons.push((p.area(), p));
            }
        }
    }
    polygons.sort_by(|a, b| b.0.total_cmp(&a.0));
    if config.components == ComponentPolicy::Largest {
        polygons.truncate(1);
    }
    Ok(AlphaShape {
        alpha,
        alpha_squared,
        polygons: polygons.into_iter().map(|(_, p)| p).collect(),
        num_components,
        num_interior_triangles,
        interior_area,
        num_distinct_points: nv,
        dropped_holes,
        filled_holes,
    })
}

/// The ring's points, with every vertex that occurs more than once in its component moved a
/// little into the exterior sector this ring bounds there (see the module docs).
fn ring_points(vertices: &[Point2], ring: &[u32], count: &[u32]) -> Vec<Point2> {
    let n = ring.len();
    (0..n)
        .map(|i| {
            let v = ring[i];
            let p = vertices[v as usize];
            if count[v as usize] < 2 {
                return p;
            }
            let prev = vertices[ring[(i + n - 1) % n] as usize];
            let next = vertices[ring[(i + 1) % n] as usize];
            let (a, b) = (prev - p, next - p);
            let (la, lb) = (a.norm(), b.norm());
            let delta = 1e-6 * la.min(lb);
            let bisector = a / la + b / lb;
            // The exterior is right of prev → p → next: a right turn has a convex exterior
            // sector (the bisector of the two edges points into it), a left turn a reflex one.
            let turn = (p - prev).perp(&(next - p));
            let outward = if bisector.norm() < 1e-12 {
                let t = (next - prev).normalize();
                patch_core::na::Vector2::new(t.y, -t.x)
            } else if turn < 0.0 {
                bisector.normalize()
            } else {
                -bisector.normalize()
            };
            p + outward * delta
        })
        .collect()
}

fn signed_area(points: &[Point2]) -> Real {
    let o = points[0];
    let mut twice = 0.0;
    for i in 1..points.len().saturating_sub(1) {
        twice += (points[i] - o).perp(&(points[i + 1] - o));
    }
    0.5 * twice
}
