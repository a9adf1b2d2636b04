//! Quality measures of triangulations and outlines (thesis §5.3.3, L5148–5154, Figs 5.12–5.14).
//!
//! * **Spikyness** of a triangle with inner angles `α₀, α₁, α₂` is `Σᵢ (π/3 − αᵢ)²`: 0 for an
//!   equilateral triangle, `π²/24 ≈ 0.411` for a right isosceles one, `2π²/3 ≈ 6.58` for a
//!   degenerate one (angles π, 0, 0), which is its largest value.
//! * [`MeshStats`] is the record the survey benchmark reports per method: polygon and triangle
//!   counts and the spikyness of the triangles (the time is measured by the caller).
//! * [`symmetric_difference_area`] measures how faithfully an outline follows a reference.

use geo::orient::Direction;
use geo::{Area as _, BooleanOps as _, Orient as _};
use patch_core::{Point2, Point3, Polygon, Real};
use std::f64::consts::PI;

/// Spikyness of a triangle whose inner angles are `angles` (radians): `Σᵢ (π/3 − αᵢ)²`.
pub fn spikyness_of_angles(angles: [Real; 3]) -> Real {
    angles.iter().map(|a| (PI / 3.0 - a).powi(2)).sum()
}

/// The spikyness of a degenerate triangle (angles π, 0, 0): `2π²/3`, the largest possible.
pub const DEGENERATE_SPIKYNESS: Real = 2.0 * PI * PI / 3.0;

/// The angle at `a` between the directions to `b` and `c`, or `None` if an edge has zero length.
fn angle_3d(a: &Point3, b: &Point3, c: &Point3) -> Option<Real> {
    let u = b - a;
    let v = c - a;
    if u.norm_squared() == 0.0 || v.norm_squared() == 0.0 {
        return None;
    }
    // atan2 of |u × v| and u · v is accurate for small and obtuse angles alike.
    Some(u.cross(&v).norm().atan2(u.dot(&v)))
}

/// Spikyness of the 3D triangle `abc`. Triangles with a zero-length edge count as degenerate
/// ([`DEGENERATE_SPIKYNESS`]).
pub fn spikyness(a: &Point3, b: &Point3, c: &Point3) -> Real {
    match (angle_3d(a, b, c), angle_3d(b, c, a)) {
        (Some(alpha), Some(beta)) => {
            let gamma = (PI - alpha - beta).max(0.0);
            spikyness_of_angles([alpha, beta, gamma])
        }
        _ => DEGENERATE_SPIKYNESS,
    }
}

/// Spikyness of the 2D triangle `abc` (for triangulations in pixel or plane coordinates).
pub fn spikyness_2d(a: [Real; 2], b: [Real; 2], c: [Real; 2]) -> Real {
    let lift = |p: [Real; 2]| Point3::new(p[0], p[1], 0.0);
    spikyness(&lift(a), &lift(b), &lift(c))
}

/// Counts and spikyness of a triangulation, the figures of the survey benchmark (Figs 5.12–5.14).
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct MeshStats {
    /// Number of triangles.
    pub triangles: usize,
    /// Number of polygons the method produced before triangulating (equal to `triangles` for
    /// methods that produce triangles directly, the number of outlines for indirect methods).
    pub polygons: usize,
    /// Number of distinct vertices.
    pub vertices: usize,
    /// Sum of the triangles' spikyness.
    pub spikyness_sum: Real,
    /// Mean spikyness per triangle (0 without triangles).
    pub spikyness_mean: Real,
}

impl MeshStats {
    /// Stats of the triangles (indices into `vertices`) in 3D. `polygons` is passed through;
    /// `vertices` counts the distinct indices the triangles use.
    ///
    /// # Panics
    /// If a triangle names a vertex out of range.
    pub fn from_triangles(vertices: &[Point3], triangles: &[[u32; 3]], polygons: usize) -> Self {
        let sum: Real = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| &vertices[i as usize]);
                spikyness(a, b, c)
            })
            .sum();
        let mut seen = vec![false; vertices.len()];
        for &i in triangles.iter().flatten() {
            seen[i as usize] = true;
        }
        MeshStats::from_parts(triangles.len(), polygons, seen.iter().filter(|&&s| s).count(), sum)
    }

    /// Stats from precomputed parts.
    pub fn from_parts(
        triangles: usize,
        polygons: usize,
        vertices: usize,
        spikyness_sum: Real,
    ) -> Self {
        let spikyness_mean = if triangles == 0 { 0.0 } else { spikyness_sum / triangles as Real };
        MeshStats { triangles, polygons, vertices, spikyness_sum, spikyness_mean }
    }

    /// The stats of two triangulations together (counts and sums add, the mean is recomputed).
    pub fn combine(&self, other: &MeshStats) -> MeshStats {
        MeshStats::from_parts(
            self.triangles + other.triangles,
            self.polygons + other.polygons,
            self.vertices + other.vertices,
            self.spikyness_sum + other.spikyness_sum,
        )
    }
}

/// Sum of the spikyness of 3D triangles given as index triples into `vertices`.
pub fn total_spikyness(vertices: &[Point3], triangles: &[[u32; 3]]) -> Real {
    MeshStats::from_triangles(vertices, triangles, 0).spikyness_sum
}

fn geo_ring(points: &[Point2]) -> geo::LineString<Real> {
    geo::LineString::from(points.iter().map(|p| (p.x, p.y)).collect::<Vec<_>>())
}

fn to_geo(p: &Polygon) -> geo::Polygon<Real> {
    geo::Polygon::new(
        geo_ring(p.outer().points()),
        p.holes().iter().map(|h| geo_ring(h.points())).collect(),
    )
}

/// Area of the symmetric difference `a △ b` of two polygons (holes respected): 0 for equal
/// polygons, `area(a) + area(b)` for disjoint ones. Measures outline fidelity against a
/// reference outline.
pub fn symmetric_difference_area(a: &Polygon, b: &Polygon) -> Real {
    to_geo(a).xor(&to_geo(b)).unsigned_area()
}

/// [`symmetric_difference_area`] of polygons given as 2D rings (`rings[0]` outer, the rest
/// holes; orientation and closure do not matter), for outlines that are not validated
/// [`Polygon`]s.
pub fn symmetric_difference_area_rings(a: &[Vec<[Real; 2]>], b: &[Vec<[Real; 2]>]) -> Real {
    let poly = |rings: &[Vec<[Real; 2]>]| -> geo::Polygon<Real> {
        let ring = |r: &Vec<[Real; 2]>| {
            geo::LineString::from(r.iter().map(|p| (p[0], p[1])).collect::<Vec<_>>())
        };
        match rings.split_first() {
            Some((outer, holes)) => {
                geo::Polygon::new(ring(outer), holes.iter().map(ring).collect())
            }
            None => geo::Polygon::new(geo::LineString::new(Vec::new()), Vec::new()),
        }
        // Boolean operations expect counter-clockwise outer rings and clockwise holes.
        .orient(Direction::Default)
    };
    poly(a).xor(&poly(b)).unsigned_area()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reference_spikyness_values() {
        let s = 3f64.sqrt() / 2.0;
        let eq = spikyness(
            &Point3::new(0.0, 0.0, 0.0),
            &Point3::new(1.0, 0.0, 0.0),
            &Point3::new(0.5, s, 0.0),
        );
        assert!(eq.abs() < 1e-12, "{eq}");
        let right = spikyness_2d([0.0, 0.0], [1.0, 0.0], [0.0, 1.0]);
        assert!((right - PI * PI / 24.0).abs() < 1e-12, "{right}");
        assert!((right - 0.411).abs() < 1e-3);
        let flat = spikyness_2d([0.0, 0.0], [1.0, 0.0], [2.0, 0.0]);
        assert!((flat - DEGENERATE_SPIKYNESS).abs() < 1e-9, "{flat}");
        assert_eq!(spikyness_2d([0.0, 0.0], [0.0, 0.0], [2.0, 0.0]), DEGENERATE_SPIKYNESS);
    }

    #[test]
    fn stats_of_a_square() {
        let v = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(1.0, 1.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
            Point3::new(9.0, 9.0, 9.0),
        ];
        let s = MeshStats::from_triangles(&v, &[[0, 1, 2], [0, 2, 3]], 1);
        assert_eq!((s.triangles, s.polygons, s.vertices), (2, 1, 4));
        assert!((s.spikyness_mean - PI * PI / 24.0).abs() < 1e-12);
        assert_eq!(MeshStats::from_triangles(&v, &[], 0).spikyness_mean, 0.0);
    }

    #[test]
    fn symmetric_difference_of_shifted_squares() {
        let sq =
            |x: Real| Polygon::rectangle(Point2::new(x, 0.0), Point2::new(x + 2.0, 2.0)).unwrap();
        assert!(symmetric_difference_area(&sq(0.0), &sq(0.0)).abs() < 1e-12);
        assert!((symmetric_difference_area(&sq(0.0), &sq(1.0)) - 4.0).abs() < 1e-9);
        assert!((symmetric_difference_area(&sq(0.0), &sq(5.0)) - 8.0).abs() < 1e-9);
        let ring = |x: Real| vec![[x, 0.0], [x + 2.0, 0.0], [x + 2.0, 2.0], [x, 2.0]];
        let hole = vec![[0.5, 0.5], [1.5, 0.5], [1.5, 1.5], [0.5, 1.5]];
        let d = symmetric_difference_area_rings(&[ring(0.0), hole.clone()], &[ring(0.0)]);
        assert!((d - 1.0).abs() < 1e-9, "{d}");
        let mut cw = ring(1.0);
        cw.reverse();
        let d = symmetric_difference_area_rings(&[cw], &[ring(0.0), hole]);
        assert!((d - 4.0).abs() < 1e-9, "{d}");
    }
}
