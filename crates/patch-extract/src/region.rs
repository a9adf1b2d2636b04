//! The result of plane segmentation: planar regions of a cloud and the remainder.

use crate::plane_fit::PlaneAccumulator;
use patch_core::{Plane, PlaneCovariance, Point3, Real};

/// One planar region of a point cloud: the indices of its points in the cloud, the plane fitted
/// to them by orthogonal least squares (thesis §5.3.2, L4624–4628) and the fit's quality.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanarRegion {
    /// Indices of the region's points in the segmented cloud, ascending.
    pub points: Vec<u32>,
    /// The fitted plane `normal · x = offset`; the normal points toward the sensor origin
    /// (`offset` is the plane's signed distance from the sensor along the normal).
    pub plane: Plane,
    /// The centroid of the points.
    pub centroid: Point3,
    /// Mean squared point-to-plane distance of the points, m².
    pub mse: Real,
    /// The covariance of `(n, d)` from the fit, when the segmentation computes it.
    pub covariance: Option<PlaneCovariance>,
}

impl PlanarRegion {
    /// The region of the points `points` (indices into `positions`, sorted here) with the
    /// least-squares plane fitted to them, its normal toward `viewpoint` (the sensor; the
    /// origin for clouds in the sensor frame). `None` for fewer than three points, collinear
    /// points or an index out of range.
    pub fn fit(positions: &[Point3], mut points: Vec<u32>, viewpoint: &Point3) -> Option<Self> {
        points.sort_unstable();
        points.dedup();
        let mut acc = PlaneAccumulator::new();
        for &i in &points {
            acc.add(positions.get(i as usize)?);
        }
        let fit = acc.fit(viewpoint)?;
        Some(PlanarRegion {
            points,
            plane: fit.plane,
            centroid: fit.centroid,
            mse: fit.mse,
            covariance: fit.covariance(),
        })
    }
}

/// Planar regions and the points that belong to none (the remainder cloud, thesis L4502–4506:
/// the non-planar points that hybrid maps turn into trimesh patches).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Segmentation {
    /// The planar regions, largest first.
    pub regions: Vec<PlanarRegion>,
    /// Indices of valid points in no region, ascending.
    pub remainder: Vec<u32>,
}
