//! Range images and the beam models that give each pixel its direction.

use crate::{AttributeError, PointCloud, Real, Vector3};
use serde::{Deserialize, Serialize};

/// Pinhole camera intrinsics in pixels. The camera looks along +z of its optical frame
/// (x right, y down); pixel (`u`, `v`) = (column, row) looks along `((u − cx)/fx, (v − cy)/fy, 1)`.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PinholeIntrinsics {
    /// Focal length along x, in pixels.
    pub fx: Real,
    /// Focal length along y, in pixels.
    pub fy: Real,
    /// Principal point column.
    pub cx: Real,
    /// Principal point row.
    pub cy: Real,
}

impl PinholeIntrinsics {
    /// The intrinsics of an ideal `width × height` camera with the given full horizontal and
    /// vertical fields of view (radians), principal point at the image centre.
    pub fn from_fov(width: u32, height: u32, fov_x: Real, fov_y: Real) -> PinholeIntrinsics {
        PinholeIntrinsics {
            fx: width as Real / 2.0 / (fov_x / 2.0).tan(),
            fy: height as Real / 2.0 / (fov_y / 2.0).tan(),
            cx: (width as Real - 1.0) / 2.0,
            cy: (height as Real - 1.0) / 2.0,
        }
    }
}

/// A spinning or scanning sensor with a regular azimuth × elevation grid (x forward, y left,
/// z up). Column 0 has `azimuth_start`, the last column `azimuth_end`; row 0 has
/// `elevation_top` (the highest beam), the last row `elevation_bottom`. Angles in radians;
/// the direction of (azimuth a, elevation e) is `(cos e cos a, cos e sin a, sin e)`.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SphericalModel {
    /// Azimuth of column 0.
    pub azimuth_start: Real,
    /// Azimuth of the last column.
    pub azimuth_end: Real,
    /// Elevation of row 0.
    pub elevation_top: Real,
    /// Elevation of the last row.
    pub elevation_bottom: Real,
}

/// An actuated (pitching, "nodding") 2D laser range finder, as the thesis's ALRF (§3.2.1): each
/// row is one 2D scan in the scanner's plane, and the plane is pitched about the sensor's y axis
/// from row to row (x forward, y left, z up).
///
/// Column `u` has beam angle `θ` from `beam_start` to `beam_end` in the scan plane; row `v` has
/// pitch `φ` from `pitch_top` (row 0) to `pitch_bottom`. The direction is
/// `(cos θ cos φ, sin θ, cos θ sin φ)`: positive pitch tilts the forward beam up. Beams with
/// `θ = ±90°` lie on the pitch axis and see the same line in every row; beams beyond ±90° look
/// backwards (the thesis's Appendix A discusses both).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ActuatedLrfModel {
    /// Beam angle of column 0.
    pub beam_start: Real,
    /// Beam angle of the last column.
    pub beam_end: Real,
    /// Pitch of row 0.
    pub pitch_top: Real,
    /// Pitch of the last row.
    pub pitch_bottom: Real,
}

/// How a sensor's pixels map to beam directions.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum BeamModel {
    /// A pinhole camera (optical frame: x right, y down, z forward).
    Pinhole(PinholeIntrinsics),
    /// A regular azimuth × elevation grid (x forward, y left, z up).
    Spherical(SphericalModel),
    /// A pitching 2D laser range finder (x forward, y left, z up).
    ActuatedLrf(ActuatedLrfModel),
}

fn lerp_index(start: Real, end: Real, i: u32, n: u32) -> Real {
    if n <= 1 { start } else { start + (end - start) * i as Real / (n - 1) as Real }
}

impl BeamModel {
    /// The direction of pixel (`col`, `row`) of a `width × height` image, in the sensor frame.
    /// For a pinhole camera the vector has z = 1 (not unit length), so `depth * ray` is the point;
    /// for the other models it is a unit vector.
    pub fn ray(&self, col: u32, row: u32, width: u32, height: u32) -> Vector3 {
        match self {
            BeamModel::Pinhole(k) => {
                Vector3::new((col as Real - k.cx) / k.fx, (row as Real - k.cy) / k.fy, 1.0)
            }
            BeamModel::Spherical(s) => {
                let a = lerp_index(s.azimuth_start, s.azimuth_end, col, width);
                let e = lerp_index(s.elevation_top, s.elevation_bottom, row, height);
                Vector3::new(e.cos() * a.cos(), e.cos() * a.sin(), e.sin())
            }
            BeamModel::ActuatedLrf(m) => {
                let t = lerp_index(m.beam_start, m.beam_end, col, width);
                let p = lerp_index(m.pitch_top, m.pitch_bottom, row, height);
                Vector3::new(t.cos() * p.cos(), t.sin(), t.cos() * p.sin())
            }
        }
    }

    /// The unit beam direction of pixel (`col`, `row`).
    pub fn direction(&self, col: u32, row: u32, width: u32, height: u32) -> Vector3 {
        self.ray(col, row, width, height).normalize()
    }
}

/// What a range image's numbers measure.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum RangeKind {
    /// Euclidean distance from the sensor origin along the beam.
    Radial,
    /// Distance to the image plane (the z coordinate in the optical frame): the thesis's
    /// convention for range cameras, and what depth images store. Only meaningful for
    /// [`BeamModel::Pinhole`].
    Depth,
}

/// Why a range image was refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RangeImageError {
    /// The number of ranges is not `width × height`.
    #[error("range image {width}×{height} needs {} ranges, got {len}", *width as u64 * *height as u64)]
    Size {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
        /// Number of ranges given.
        len: usize,
    },
    /// A range is negative, NaN or infinite (use `None` for no measurement).
    #[error("range at pixel {index} is {value}, not a finite non-negative number")]
    BadRange {
        /// Pixel index (row-major).
        index: usize,
        /// The value.
        value: f32,
    },
    /// Depth ranges need a pinhole model.
    #[error("depth ranges need a pinhole beam model")]
    DepthNeedsPinhole,
    /// The cloud could not be built.
    #[error(transparent)]
    Cloud(#[from] AttributeError),
}

/// A `width × height` image of ranges (metres), row-major, row 0 at the top, with a beam model.
/// Pixels without a measurement are `None`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RangeImage {
    width: u32,
    height: u32,
    beams: BeamModel,
    kind: RangeKind,
    ranges: Vec<Option<f32>>,
}

impl RangeImage {
    /// A range image. Fails on a wrong number of ranges, a non-finite or negative range, or
    /// depth ranges with a non-pinhole model.
    pub fn new(
        width: u32,
        height: u32,
        beams: BeamModel,
        kind: RangeKind,
        ranges: Vec<Option<f32>>,
    ) -> Result<RangeImage, RangeImageError> {
        if ranges.len() as u64 != width as u64 * height as u64 {
            return Err(RangeImageError::Size { width, height, len: ranges.len() });
        }
        if kind == RangeKind::Depth && !matches!(beams, BeamModel::Pinhole(_)) {
            return Err(RangeImageError::DepthNeedsPinhole);
        }
        for (index, r) in ranges.iter().enumerate() {
            if let Some(value) = *r
                && !(value.is_finite() && value >= 0.0)
            {
                return Err(RangeImageError::BadRange { index, value });
            }
        }
        Ok(RangeImage { width, height, beams, kind, ranges })
    }

    /// Image width.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Image height.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The beam model.
    pub fn beams(&self) -> &BeamModel {
        &self.beams
    }

    /// What the ranges measure.
    pub fn kind(&self) -> RangeKind {
        self.kind
    }

    /// All ranges, row-major.
    pub fn ranges(&self) -> &[Option<f32>] {
        &self.ranges
    }

    /// The range at pixel (`col`, `row`).
    pub fn range(&self, col: u32, row: u32) -> Option<f32> {
        if col >= self.width || row >= self.height {
            return None;
        }
        self.ranges[row as usize * self.width as usize + col as usize]
    }

    /// The number of pixels with a measurement.
    pub fn num_valid(&self) -> usize {
        self.ranges.iter().filter(|r| r.is_some()).count()
    }

    /// The organised point cloud in the sensor frame (invalid pixels stay invalid).
    pub fn to_cloud(&self) -> Result<PointCloud, RangeImageError> {
        let (w, h) = (self.width, self.height);
        let pixels = (0..h).flat_map(|row| (0..w).map(move |col| (col, row))).map(|(col, row)| {
            let r = self.ranges[row as usize * w as usize + col as usize]? as Real;
            let ray = self.beams.ray(col, row, w, h);
            Some(match self.kind {
                RangeKind::Depth => (ray * r).into(),
                RangeKind::Radial => (ray.normalize() * r).into(),
            })
        });
        Ok(PointCloud::from_pixels(w, h, pixels)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pinhole_depth_and_radial_agree_on_the_axis() {
        let k = PinholeIntrinsics { fx: 100.0, fy: 100.0, cx: 1.0, cy: 1.0 };
        let depth =
            RangeImage::new(3, 3, BeamModel::Pinhole(k), RangeKind::Depth, vec![Some(2.0); 9])
                .unwrap();
        let c = depth.to_cloud().unwrap();
        let centre = c.positions()[c.grid().unwrap().point_index(1, 1).unwrap()];
        assert!((centre.z - 2.0).abs() < 1e-12 && centre.x.abs() < 1e-12);
        let corner = c.positions()[0];
        assert!((corner.z - 2.0).abs() < 1e-12, "depth is distance to the image plane");
        let radial =
            RangeImage::new(3, 3, BeamModel::Pinhole(k), RangeKind::Radial, vec![Some(2.0); 9])
                .unwrap()
                .to_cloud()
                .unwrap();
        assert!((radial.positions()[0].coords.norm() - 2.0).abs() < 1e-12);
    }

    #[test]
    fn actuated_lrf_side_beam_ignores_pitch() {
        let m = BeamModel::ActuatedLrf(ActuatedLrfModel {
            beam_start: -std::f64::consts::FRAC_PI_2,
            beam_end: std::f64::consts::FRAC_PI_2,
            pitch_top: 1.0,
            pitch_bottom: -1.0,
        });
        let a = m.direction(0, 0, 3, 5);
        let b = m.direction(0, 4, 3, 5);
        assert!((a - b).norm() < 1e-12);
        assert!((a - Vector3::new(0.0, -1.0, 0.0)).norm() < 1e-12);
        let up = m.direction(1, 0, 3, 5);
        assert!(up.z > 0.8, "row 0 pitches the forward beam up");
    }

    #[test]
    fn bad_images_are_refused() {
        let k = BeamModel::Pinhole(PinholeIntrinsics { fx: 1.0, fy: 1.0, cx: 0.0, cy: 0.0 });
        assert!(matches!(
            RangeImage::new(2, 2, k, RangeKind::Depth, vec![None; 3]),
            Err(RangeImageError::Size { .. })
        ));
        assert!(matches!(
            RangeImage::new(1, 1, k, RangeKind::Depth, vec![Some(f32::NAN)]),
            Err(RangeImageError::BadRange { .. })
        ));
        assert!(matches!(
            RangeImage::new(1, 1, k, RangeKind::Depth, vec![Some(-1.0)]),
            Err(RangeImageError::BadRange { .. })
        ));
        let s = BeamModel::Spherical(SphericalModel {
            azimuth_start: 0.0,
            azimuth_end: 1.0,
            elevation_top: 0.0,
            elevation_bottom: 0.0,
        });
        assert_eq!(
            RangeImage::new(1, 1, s, RangeKind::Depth, vec![None]),
            Err(RangeImageError::DepthNeedsPinhole)
        );
    }
}
