//! Conservative outline offset: a patch's outline moved outward so that it covers the
//! surface the scan saw, not only the hull of its sample points.
//!
//! An α-shape (thesis Alg. 6) runs through the outermost sample points, and the true edge of
//! the surface lies up to one point spacing beyond them, plus the range noise that moves
//! the boundary points in or out. A map that stops at the α-shape therefore calls steps
//! free that graze a table's edge or a board's front. This module grows a region's polygon by
//!
//! ```text
//! δ = min(max, spacing_factor · √(A / n) + noise_factor · √mse)
//! ```
//!
//! where `A` is the polygon's area and `n` the number of projected points (so `√(A / n)` is
//! the mean point spacing, large for sparse grazing views), and `mse` the region's mean squared
//! plane distance (its noise). The offset is a Minkowski sum with a disc, as polygons are
//! buffered in GIS (geo's `Buffer`, mitred joins so corners stay corners); holes shrink and
//! may close. It is not in the thesis, which leaves outlines as the α-shape gives them:
//! [`PolygonizeConfig::thesis`](crate::PolygonizeConfig::thesis) keeps that, the ALRF
//! pipeline preset turns the offset on. Its cost is free space called colliding near the
//! grown edges, measured by `patchnav experiment map-safety`.

use crate::merge::to_geo;
use geo::algorithm::buffer::{BufferStyle, LineJoin};
use geo::{Buffer as _, LineString, MultiPolygon};
use patch_core::{Point2, Polygon, Real};

/// How far outlines are grown (module docs). No `Default`: start from a preset.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct OutlineOffset {
    /// Multiple of the mean point spacing `√(A / n)` (finite, ≥ 0).
    pub spacing_factor: Real,
    /// Multiple of the region's RMS plane distance (finite, ≥ 0).
    pub noise_factor: Real,
    /// The largest offset, metres (finite, ≥ 0).
    pub max: Real,
}

impl OutlineOffset {
    /// For actuated-LRF scans: half the mean spacing plus one RMS noise, at most 5 cm.
    ///
    /// Measured on the lab (8 scans, step seed 1; `patchnav map compare`), unsafe / overcautious
    /// % of the planes map: no offset 3.27 / 1.56; (0.5, 1, 5 cm) 2.83 / 2.39; (1, 1, 10 cm)
    /// 2.67 / 3.00; (0.5, 0, 10 cm) 3.03 / 1.99; (0, 2, 10 cm) 2.82 / 2.54.
    pub fn alrf() -> OutlineOffset {
        OutlineOffset { spacing_factor: 0.5, noise_factor: 1.0, max: 0.05 }
    }

    /// Whether every field is finite and ≥ 0.
    pub fn is_valid(&self) -> bool {
        [self.spacing_factor, self.noise_factor, self.max]
            .iter()
            .all(|v| v.is_finite() && *v >= 0.0)
    }

    /// The offset of a polygon of `area` made from `points` projected points of a region with
    /// mean squared plane distance `mse`.
    pub fn distance(&self, area: Real, points: usize, mse: Real) -> Real {
        let spacing = if points > 0 { (area.max(0.0) / points as Real).sqrt() } else { 0.0 };
        let d = self.spacing_factor * spacing + self.noise_factor * mse.max(0.0).sqrt();
        if d.is_finite() { d.min(self.max) } else { 0.0 }
    }
}

fn ring_from_geo(ring: &LineString<Real>) -> Vec<Point2> {
    let mut pts: Vec<Point2> = ring.coords().map(|c| Point2::new(c.x, c.y)).collect();
    if pts.len() > 1 && pts.first() == pts.last() {
        pts.pop();
    }
    pts
}

/// `polygon` grown outward by `distance` metres: it contains the disc offset (every point
/// within `distance` of the polygon); corners are mitred, at most twice the distance out. `None` when the grown polygon is not a valid patch polygon; a distance ≤ 0 (or not
/// finite) gives the polygon unchanged.
pub fn grow_polygon(polygon: &Polygon, distance: Real) -> Option<Polygon> {
    if !(distance.is_finite() && distance > 0.0) {
        return Some(polygon.clone());
    }
    let style = BufferStyle::new(distance).line_join(LineJoin::Miter(2.0));
    let grown: MultiPolygon<Real> = to_geo(polygon).buffer_with_style(style);
    // Growing a connected polygon keeps it connected: the result is one polygon.
    let largest = grown.0.iter().max_by(|a, b| {
        use geo::Area as _;
        a.unsigned_area().total_cmp(&b.unsigned_area())
    })?;
    let outer = ring_from_geo(largest.exterior());
    let holes: Vec<Vec<Point2>> = largest.interiors().iter().map(ring_from_geo).collect();
    Polygon::new(outer, holes).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(a: Real, b: Real) -> Vec<Point2> {
        vec![Point2::new(a, a), Point2::new(b, a), Point2::new(b, b), Point2::new(a, b)]
    }

    #[test]
    fn a_square_grows_by_the_distance_on_every_side() {
        let p = Polygon::new(square(0.0, 1.0), vec![]).unwrap();
        let g = grow_polygon(&p, 0.1).unwrap();
        // Between the disc offset (rounded corners) and the mitred square.
        let round = 1.0 + 4.0 * 0.1 + std::f64::consts::PI * 0.01;
        assert!(g.area() >= round - 1e-9 && g.area() <= 1.2 * 1.2 + 1e-9, "{}", g.area());
        for q in g.outer().points() {
            assert!(q.x >= -0.1 - 1e-9 && q.x <= 1.1 + 1e-9 && q.y >= -0.1 - 1e-9);
        }
        assert_eq!(grow_polygon(&p, 0.0).unwrap(), p);
        assert_eq!(grow_polygon(&p, Real::NAN).unwrap(), p);
    }

    #[test]
    fn holes_shrink_and_close() {
        let p = Polygon::new(square(0.0, 3.0), vec![square(1.0, 2.0)]).unwrap();
        let g = grow_polygon(&p, 0.1).unwrap();
        assert_eq!(g.holes().len(), 1);
        let round = 9.0 + 12.0 * 0.1 + std::f64::consts::PI * 0.01 - 0.8 * 0.8;
        assert!(g.area() >= round - 1e-9 && g.area() <= 3.2 * 3.2 - 0.64 + 1e-9, "{}", g.area());
        let closed = grow_polygon(&p, 0.6).unwrap();
        assert!(closed.holes().is_empty());
    }

    #[test]
    fn distance_follows_spacing_and_noise_and_is_capped() {
        let o = OutlineOffset::alrf();
        assert!(o.is_valid());
        // 1 m² from 25 points: 20 cm spacing, half of it capped at 5 cm.
        assert!((o.distance(1.0, 25, 0.0) - 0.05).abs() < 1e-12);
        // 1 m² from 10,000 points: half of 1 cm spacing plus 2 cm noise.
        assert!((o.distance(1.0, 10_000, 0.0004) - 0.025).abs() < 1e-12);
        assert_eq!(o.distance(1.0, 0, 0.0), 0.0);
        assert!(!OutlineOffset { max: -1.0, ..o }.is_valid());
    }
}
