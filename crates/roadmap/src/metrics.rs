//! Path metrics of the thesis's synthetic benchmark (§5.5.4, Tables 5.5–5.11; spec §5.1):
//! path length, the length summed over all goals, turns, steep turns and curviness.
//!
//! # Definitions
//! * A path is a polyline of points. Consecutive equal points (zero-length segments) are
//!   skipped before anything is measured, so repeating a point changes no metric.
//! * The **turn angle** at an interior vertex is the angle between the directions of the
//!   segment arriving and the segment leaving it, in `[0, π]` radians (0: straight on, π: a
//!   U-turn). It is computed as `atan2(|a × b|, a · b)`, which is accurate near 0 and π.
//! * A **turn** is an interior vertex whose turn angle exceeds [`STRAIGHT_TOLERANCE`] (so
//!   collinear vertices, up to rounding, are not turns); a **steep turn** one whose angle
//!   exceeds 90° (thesis: "steep turns (> 90°)").
//! * **Curviness** is the upper quartile of the turn angles of all interior vertices
//!   (straight ones count with angle 0), in radians; 0 for a path without interior vertex.
//!   The thesis does not say how it computes quartiles; here it is linear interpolation
//!   between closest ranks (Hyndman & Fan type 7, the default of R and NumPy): for sorted
//!   values `x_0 ≤ … ≤ x_{n−1}`, `h = 0.75 (n − 1)` and
//!   `Q3 = x_⌊h⌋ + (h − ⌊h⌋)(x_⌊h⌋+1 − x_⌊h⌋)` (see [`upper_quartile`]).

use patch_core::{Point3, Real, Vector3};

use crate::planner::Planner;

/// Turn angles at or below this many radians count as going straight (not a turn).
pub const STRAIGHT_TOLERANCE: Real = 1e-9;

/// The metrics of one path (thesis Tables 5.5–5.11 report them per run).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PathMetrics {
    /// The sum of the segment lengths, in metres.
    pub length: Real,
    /// Interior vertices where the direction changes (angle > [`STRAIGHT_TOLERANCE`]).
    pub turns: usize,
    /// Turns with an angle above 90°.
    pub steep_turns: usize,
    /// The upper quartile of the turn angles, in radians (see the [module docs](self)).
    pub curviness: Real,
}

impl PathMetrics {
    /// The metrics of `path` (an empty or one-point path has length 0 and no turns).
    pub fn of(path: &[Point3]) -> PathMetrics {
        let angles = turn_angles(path);
        let turns = angles.iter().filter(|&&a| a > STRAIGHT_TOLERANCE).count();
        let steep_turns = angles.iter().filter(|&&a| a > std::f64::consts::FRAC_PI_2).count();
        PathMetrics {
            length: path_length(path),
            turns,
            steep_turns,
            curviness: upper_quartile(&angles).unwrap_or(0.0),
        }
    }
}

/// The length of a polyline: the sum of its segment lengths.
pub fn path_length(path: &[Point3]) -> Real {
    path.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

/// The turn angles (radians, in `[0, π]`) at the interior vertices of `path`, in path order,
/// after skipping zero-length segments.
pub fn turn_angles(path: &[Point3]) -> Vec<Real> {
    let directions: Vec<Vector3> =
        path.windows(2).map(|w| w[1] - w[0]).filter(|d| *d != Vector3::zeros()).collect();
    directions.windows(2).map(|d| d[0].cross(&d[1]).norm().atan2(d[0].dot(&d[1]))).collect()
}

/// The `p`-quantile (`0 ≤ p ≤ 1`) of `values` by linear interpolation between closest ranks
/// (Hyndman & Fan type 7, R's default): over the sorted values, `h = p (n − 1)`,
/// `Q = x_⌊h⌋ + (h − ⌊h⌋)(x_⌊h⌋+1 − x_⌊h⌋)`. `None` for no values or a `p` outside `[0, 1]`.
/// NaNs sort last (total order). The experiments report every median and quartile with it.
pub fn quantile(values: &[Real], p: Real) -> Option<Real> {
    if values.is_empty() || !(0.0..=1.0).contains(&p) {
        return None;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(Real::total_cmp);
    let h = p * (sorted.len() - 1) as Real;
    let lo = h.floor() as usize;
    let hi = (lo + 1).min(sorted.len() - 1);
    Some(sorted[lo] + (h - lo as Real) * (sorted[hi] - sorted[lo]))
}

/// The upper quartile of `values` ([`quantile`] at 0.75, type 7): the thesis's curviness is
/// the upper quartile of the turn angles. `None` for no values.
pub fn upper_quartile(values: &[Real]) -> Option<Real> {
    quantile(values, 0.75)
}

/// The thesis's "summed path length to all ROIs" (Table 5.5): the sum of the lengths of the
/// given paths, one per goal.
pub fn added_length<'a>(paths: impl IntoIterator<Item = &'a [Point3]>) -> Real {
    paths.into_iter().map(path_length).sum()
}

/// [`added_length`] over the paths of the planner's last solve to goals `0..goals`, or `None`
/// if some goal is unreached (the thesis reports successful runs only).
pub fn planner_added_length(planner: &dyn Planner, goals: usize) -> Option<Real> {
    let paths = (0..goals).map(|g| planner.path_to(g)).collect::<Option<Vec<_>>>()?;
    Some(added_length(paths.iter().map(Vec::as_slice)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

    fn p(x: Real, y: Real, z: Real) -> Point3 {
        Point3::new(x, y, z)
    }

    fn close(a: Real, b: Real) -> bool {
        (a - b).abs() < 1e-12
    }

    #[test]
    fn straight_path() {
        let path = [p(0.0, 0.0, 0.0), p(1.0, 0.0, 0.0), p(3.0, 0.0, 0.0), p(6.0, 0.0, 0.0)];
        let m = PathMetrics::of(&path);
        assert!(close(m.length, 6.0));
        assert_eq!((m.turns, m.steep_turns), (0, 0));
        assert_eq!(m.curviness, 0.0);
        assert_eq!(turn_angles(&path), vec![0.0, 0.0]);
    }

    #[test]
    fn empty_and_single_points() {
        for path in [&[][..], &[p(1.0, 2.0, 3.0)][..], &[p(1.0, 2.0, 3.0); 4][..]] {
            let m = PathMetrics::of(path);
            assert_eq!(m, PathMetrics { length: 0.0, turns: 0, steep_turns: 0, curviness: 0.0 });
        }
    }

    #[test]
    fn right_angles() {
        // A staircase in the xy plane: three 90° turns, none steep (not > 90°).
        let path = [p(0.0, 0.0, 0.0), p(1.0, 0.0, 0.0), p(1.0, 1.0, 0.0), p(2.0, 1.0, 0.0)];
        let path = [&path[..], &[p(2.0, 1.0, 1.0)]].concat();
        let m = PathMetrics::of(&path);
        assert!(close(m.length, 4.0));
        assert_eq!((m.turns, m.steep_turns), (3, 0));
        assert!(close(m.curviness, FRAC_PI_2));
    }

    #[test]
    fn u_turn_and_mixed_angles() {
        // Out and back: one turn of π, steep.
        let m = PathMetrics::of(&[p(0.0, 0.0, 0.0), p(2.0, 0.0, 0.0), p(1.0, 0.0, 0.0)]);
        assert!(close(m.length, 3.0));
        assert_eq!((m.turns, m.steep_turns), (1, 1));
        assert!(close(m.curviness, PI));
        // Angles 0, π/4, 3π/4: sorted [0, π/4, 3π/4], h = 1.5, Q3 = π/4 + 0.5·π/2 = π/2.
        let path = [
            p(0.0, 0.0, 0.0),
            p(1.0, 0.0, 0.0),
            p(2.0, 0.0, 0.0), // straight
            p(3.0, 1.0, 0.0), // 45° left
            p(3.0, 0.0, 0.0), // from (1,1) to (0,−1): 135°
        ];
        let angles = turn_angles(&path);
        assert_eq!(angles.len(), 3);
        assert!(close(angles[0], 0.0) && close(angles[1], FRAC_PI_4));
        assert!(close(angles[2], 3.0 * FRAC_PI_4));
        let m = PathMetrics::of(&path);
        assert_eq!((m.turns, m.steep_turns), (2, 1));
        assert!(close(m.curviness, FRAC_PI_2));
        assert!(close(m.length, 2.0 + Real::sqrt(2.0) + 1.0));
    }

    #[test]
    fn repeated_points_are_skipped() {
        let plain = [p(0.0, 0.0, 0.0), p(1.0, 0.0, 0.0), p(1.0, 1.0, 0.0)];
        let repeated = [plain[0], plain[0], plain[1], plain[1], plain[1], plain[2], plain[2]];
        assert_eq!(PathMetrics::of(&plain), PathMetrics::of(&repeated));
        assert_eq!(turn_angles(&repeated).len(), 1);
    }

    #[test]
    fn quartiles_and_added_length() {
        assert_eq!(upper_quartile(&[]), None);
        assert_eq!(upper_quartile(&[2.0]), Some(2.0));
        // n = 4: h = 2.25 → 3 + 0.25·(4 − 3).
        assert_eq!(upper_quartile(&[4.0, 1.0, 3.0, 2.0]), Some(3.25));
        // n = 5: h = 3 exactly.
        assert_eq!(upper_quartile(&[5.0, 1.0, 4.0, 2.0, 3.0]), Some(4.0));
        let a = [p(0.0, 0.0, 0.0), p(3.0, 4.0, 0.0)];
        let b = [p(0.0, 0.0, 0.0), p(0.0, 0.0, 2.0), p(0.0, 1.0, 2.0)];
        assert!(close(added_length([&a[..], &b[..]]), 8.0));
        assert_eq!(added_length(std::iter::empty()), 0.0);
    }
}
