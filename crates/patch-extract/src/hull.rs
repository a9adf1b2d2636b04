//! The convex hull of projected region points: the thesis's coarsest "indirect" outliner
//! (§5.3.2, L4811–4831: outline first, then triangulate; fastest of all methods, L5243, but
//! too coarse, L5239–5247).
//!
//! Andrew's monotone chain with the exact orientation predicate of geo's `RobustKernel`
//! (Shewchuk's adaptive `orient2d`), so collinear points are recognised exactly and never
//! become hull vertices.

use geo::{Coord, Kernel as _, Orientation, kernels::RobustKernel};
use patch_core::{PatchError, Point2, Polygon};

/// Why no hull polygon exists.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum HullError {
    /// Fewer than 3 points were given.
    #[error("{count} points given, at least 3 are needed")]
    TooFewPoints {
        /// The number of points.
        count: usize,
    },
    /// A coordinate is NaN or infinite.
    #[error("point {index} is not finite")]
    NonFinite {
        /// The point index.
        index: usize,
    },
    /// All points are collinear (or there are fewer than 3 distinct points): the hull has no
    /// area.
    #[error("all points are collinear: the hull has no area")]
    Degenerate,
    /// The hull ring was refused by [`Polygon::new`] (should not happen).
    #[error("hull polygon is invalid: {0}")]
    InvalidPolygon(#[from] PatchError),
}

fn orientation(p: &Point2, q: &Point2, r: &Point2) -> Orientation {
    RobustKernel::orient2d(
        Coord { x: p.x, y: p.y },
        Coord { x: q.x, y: q.y },
        Coord { x: r.x, y: r.y },
    )
}

/// The vertices of the convex hull of `points`, counter-clockwise, starting at the
/// lexicographically smallest point, without collinear or repeated vertices.
///
/// # Errors
/// [`HullError::TooFewPoints`], [`HullError::NonFinite`], [`HullError::Degenerate`].
///
/// # Complexity
/// O(n log n) (the sort).
pub fn convex_hull(points: &[Point2]) -> Result<Vec<Point2>, HullError> {
    if points.len() < 3 {
        return Err(HullError::TooFewPoints { count: points.len() });
    }
    if let Some(index) = points.iter().position(|p| !(p.x.is_finite() && p.y.is_finite())) {
        return Err(HullError::NonFinite { index });
    }
    let mut sorted = points.to_vec();
    sorted.sort_unstable_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    sorted.dedup();
    if sorted.len() < 3 {
        return Err(HullError::Degenerate);
    }
    let hull = monotone_chain(&sorted);
    if hull.len() < 3 {
        return Err(HullError::Degenerate);
    }
    Ok(hull)
}

/// Andrew's monotone chain over lexicographically sorted distinct points: the lower chain
/// left to right, then the upper chain right to left, popping every vertex that is not a
/// strict left turn.
fn monotone_chain(sorted: &[Point2]) -> Vec<Point2> {
    let mut hull: Vec<Point2> = Vec::with_capacity(sorted.len() + 1);
    let turn_ok = |h: &Vec<Point2>, p: &Point2| {
        orientation(&h[h.len() - 2], &h[h.len() - 1], p) == Orientation::CounterClockwise
    };
    for p in sorted {
        while hull.len() >= 2 && !turn_ok(&hull, p) {
            hull.pop();
        }
        hull.push(*p);
    }
    let lower_len = hull.len() + 1;
    for p in sorted.iter().rev().skip(1) {
        while hull.len() >= lower_len && !turn_ok(&hull, p) {
            hull.pop();
        }
        hull.push(*p);
    }
    hull.pop(); // the first point again
    hull
}

/// The convex hull as a validated [`Polygon`] (counter-clockwise, no holes).
///
/// # Errors
/// As [`convex_hull`].
pub fn convex_hull_polygon(points: &[Point2]) -> Result<Polygon, HullError> {
    Ok(Polygon::new(convex_hull(points)?, Vec::new())?)
}
