//! Points sampled on patches at a guaranteed spacing: how a point-cloud map is made from a patch
//! map (for comparing the two, as the thesis's Table 6.1 does, and for testing the point-cloud
//! backend against surfaces).
//!
//! # Guarantee
//! Every triangle (trimesh triangles, and planar patches triangulated by
//! [`triangulate_polygon`](crate::triangulate::triangulate_polygon)) is sampled on the lattice `a + (i/n)(b − a) + (j/n)(c − a)`,
//! `i + j ≤ n`, with `n = ⌈longest edge / h⌉`. The lattice cuts the triangle into copies of it
//! scaled by `1/n`, whose edges are at most `h`, and every point of a triangle is within its
//! longest edge of each corner; so **every surface point is within `h` of a sample**, and every
//! sample lies on a patch. A capsule of radius `r` whose segment comes within `r − h` of a patch
//! therefore contains a sample: with `h < r/2` the point-cloud map's Algorithm 10 cannot miss
//! such a step (the density assumption of [`point_cloud`](crate::point_cloud)).

use crate::triangulate::{TriangulationError, patch_triangles};
use patch_core::{Patch, Point3, Real};

/// Appends the lattice samples of one triangle with spacing at most `spacing`.
fn sample_triangle(corners: [Point3; 3], spacing: Real, out: &mut Vec<Point3>) {
    let [a, b, c] = corners;
    let longest = [(b - a).norm(), (c - b).norm(), (a - c).norm()].into_iter().fold(0.0, Real::max);
    let n = (longest / spacing).ceil().max(1.0) as usize;
    for i in 0..=n {
        for j in 0..=n - i {
            let (u, v) = (i as Real / n as Real, j as Real / n as Real);
            out.push(a + (b - a) * u + (c - a) * v);
        }
    }
}

/// Why patches could not be sampled.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SamplingError {
    /// The spacing is not a positive finite number.
    #[error("sample spacing must be a positive number of metres, got {0}")]
    BadSpacing(Real),
    /// A planar patch could not be triangulated.
    #[error("patch {patch}: {source}")]
    Triangulation {
        /// The patch's index in the input.
        patch: usize,
        /// Why.
        source: TriangulationError,
    },
}

/// Samples every patch so that each surface point is within `spacing` of a sample (see the
/// module docs). Points along shared triangle edges appear more than once.
///
/// # Complexity
/// `O(A / spacing²)` points for a total area `A` (about `2A / spacing²` on a grid of triangles).
pub fn sample_patch_points(patches: &[Patch], spacing: Real) -> Result<Vec<Point3>, SamplingError> {
    if !(spacing.is_finite() && spacing > 0.0) {
        return Err(SamplingError::BadSpacing(spacing));
    }
    let mut out = Vec::new();
    for (index, patch) in patches.iter().enumerate() {
        let triangles = patch_triangles(patch)
            .map_err(|source| SamplingError::Triangulation { patch: index, source })?;
        for tri in triangles {
            sample_triangle(tri, spacing, &mut out);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use patch_core::{BruteForceMap, FromPatches, Isometry3, PlanarPatch, Point2, ProximityQuery};

    #[test]
    fn samples_cover_a_patch_and_lie_on_it() {
        let p = PlanarPatch::rectangle(
            Isometry3::identity(),
            Point2::new(0.0, 0.0),
            Point2::new(2.0, 1.0),
        )
        .unwrap();
        let patches = vec![Patch::Planar(p)];
        let h = 0.1;
        let points = sample_patch_points(&patches, h).unwrap();
        let map = BruteForceMap::from_patches(patches).unwrap();
        for q in &points {
            assert!(map.closest_patch(q, 1.0).unwrap().distance < 1e-12, "{q} is off the patch");
        }
        // Every point of a fine grid over the patch has a sample within h.
        for i in 0..=40 {
            for j in 0..=20 {
                let s = Point3::new(i as Real * 0.05, j as Real * 0.05, 0.0);
                let d = points.iter().map(|q| (q - s).norm()).fold(Real::INFINITY, Real::min);
                assert!(d <= h, "{s} is {d} from every sample");
            }
        }
        assert_eq!(sample_patch_points(&[], h).unwrap().len(), 0);
        assert_eq!(sample_patch_points(&[], 0.0), Err(SamplingError::BadSpacing(0.0)));
        assert!(sample_patch_points(&[], Real::NAN).is_err());
    }
}
