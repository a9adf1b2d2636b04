//! Outline simplification with Douglas–Peucker (thesis §5.3.3, L5249–5353; spec §2.4).
//!
//! The thesis runs Douglas–Peucker on each closed outline as an **open polyline from its first
//! to its last vertex** (the ring order as CGAL gives it), so both of these always stay
//! (L5345–5351), and reports an outline of 141 vertices simplified to 9 (Fig. 5.15). It gives
//! no ε; the pipeline's choice is documented on `PolygonizeConfig`.
//!
//! Douglas–Peucker may make rings self-intersecting or let a hole cross the outer ring (geo's
//! docs say so too). Two variants:
//! * [`simplify_polygon`]: every ring simplified with ε, the result validated as a
//!   [`Polygon`]; an invalid result is an error (the thesis's plain behaviour, made explicit).
//! * [`simplify_polygon_valid`]: if the result at ε is invalid (or a ring collapses below 3
//!   vertices), ε is halved and the simplification retried, up to
//!   [`MAX_HALVINGS`] times; if every attempt fails, the original polygon is returned
//!   unchanged. The ε finally used is reported. The result is always a valid polygon.
//!
//! The per-ring work is geo's `SimplifyIdx` (Douglas–Peucker on the ring's vertex indices).

use geo::{Coord, LineString, SimplifyIdx as _};
use patch_core::{PatchError, Point2, Polygon, Real, Ring};

/// How often [`simplify_polygon_valid`] halves ε before giving up.
pub const MAX_HALVINGS: u32 = 6;

/// Why a polygon could not be simplified.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SimplifyError {
    /// ε is negative or not finite.
    #[error("invalid ε = {epsilon}")]
    InvalidEpsilon {
        /// The value given.
        epsilon: Real,
    },
    /// The simplified rings do not form a valid polygon.
    #[error("simplified polygon is invalid: {0}")]
    Invalid(#[from] PatchError),
}

/// The result of [`simplify_polygon_valid`].
#[derive(Clone, Debug, PartialEq)]
pub struct Simplified {
    /// The simplified (always valid) polygon.
    pub polygon: Polygon,
    /// The ε that produced it: the requested one, a halved one, or `0` for the original.
    pub epsilon: Real,
    /// Total vertex count before.
    pub vertices_before: usize,
    /// Total vertex count after.
    pub vertices_after: usize,
}

/// Douglas–Peucker of a closed ring treated as the open polyline `ring[0] … ring[n-1]`
/// (the closing edge is not part of the polyline; both ends are kept). `epsilon ≤ 0` returns
/// the ring unchanged. The result may have fewer than 3 vertices.
pub fn douglas_peucker_ring(ring: &[Point2], epsilon: Real) -> Vec<Point2> {
    if epsilon <= 0.0 || ring.len() < 3 {
        return ring.to_vec();
    }
    let line: LineString<Real> = ring.iter().map(|p| Coord { x: p.x, y: p.y }).collect();
    line.simplify_idx(epsilon).into_iter().map(|i| ring[i]).collect()
}

fn check_epsilon(epsilon: Real) -> Result<(), SimplifyError> {
    if epsilon.is_finite() && epsilon >= 0.0 {
        Ok(())
    } else {
        Err(SimplifyError::InvalidEpsilon { epsilon })
    }
}

fn simplify_rings(polygon: &Polygon, epsilon: Real) -> Result<Polygon, PatchError> {
    let simplify = |r: &Ring| douglas_peucker_ring(r.points(), epsilon);
    Polygon::new(simplify(polygon.outer()), polygon.holes().iter().map(simplify).collect())
}

/// Every ring simplified with ε as in the thesis, then validated.
///
/// # Errors
/// [`SimplifyError::InvalidEpsilon`]; [`SimplifyError::Invalid`] when the simplified rings are
/// not a valid polygon (a ring collapsed below 3 vertices, crossed itself, or a hole crossed
/// the outer ring).
///
/// # Complexity
/// O(n log n) typical, O(n²) worst case (Douglas–Peucker), plus validation.
pub fn simplify_polygon(polygon: &Polygon, epsilon: Real) -> Result<Polygon, SimplifyError> {
    check_epsilon(epsilon)?;
    Ok(simplify_rings(polygon, epsilon)?)
}

/// As [`simplify_polygon`], but never returns an invalid polygon: see the module docs for the
/// fallback (halve ε up to [`MAX_HALVINGS`] times, then the original).
///
/// # Errors
/// [`SimplifyError::InvalidEpsilon`] only.
pub fn simplify_polygon_valid(
    polygon: &Polygon,
    epsilon: Real,
) -> Result<Simplified, SimplifyError> {
    check_epsilon(epsilon)?;
    let vertices_before = polygon.num_vertices();
    let mut eps = epsilon;
    if eps > 0.0 {
        for _ in 0..=MAX_HALVINGS {
            if let Ok(p) = simplify_rings(polygon, eps) {
                let vertices_after = p.num_vertices();
                return Ok(Simplified {
                    polygon: p,
                    epsilon: eps,
                    vertices_before,
                    vertices_after,
                });
            }
            eps *= 0.5;
        }
    }
    Ok(Simplified {
        polygon: polygon.clone(),
        epsilon: 0.0,
        vertices_before,
        vertices_after: vertices_before,
    })
}
