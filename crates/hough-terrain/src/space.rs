//! The discretised plane parameter space of Algorithm 2 (thesis §4.1.2, L3330–3410; ranges and
//! resolutions L3522–3542; spec §6.6–6.8).
//!
//! A plane is `(ρx, ρy, d)`: `ρx` is the angle between the x axis and the plane's intersection
//! with the xz plane, `ρy` the same for y, and `d = n·p` with the thesis's normal
//! `n = (−sin ρx cos ρy, −cos ρx sin ρy, cos ρx cos ρy)`, so the plane is
//! `z = tan ρx · x + tan ρy · y + d / (cos ρx cos ρy)` and `d` has the sign of the plane's z
//! intercept. All of this is in the levelled frame of [`crate::SensorMount`] (x forward, y right,
//! z down).

use crate::error::{HoughError, Result};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// The largest number of bins (or cells) any accumulator of this crate may have (2²⁴, 64 MiB of
/// `u32` counts).
pub const MAX_BINS: u64 = 1 << 24;

/// Slack when counting samples, so that `63° / 9°` is 7 samples despite rounding in radians.
const COUNT_SLACK: f64 = 1e-9;

/// One angle axis: samples `min + k · resolution` for `k = 0 .. ⌈(max − min)/resolution⌉ − 1`
/// (spec §6.6), radians. `max` itself is sampled only if it is not a whole number of steps away
/// from `min` (the range is half open).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AngleAxis {
    /// First sampled angle, radians; above −90°.
    pub min: f64,
    /// End of the range (exclusive), radians; at most 90°.
    pub max: f64,
    /// Step between samples, radians; in (0, 90°].
    pub resolution: f64,
}

impl AngleAxis {
    /// An axis from degrees (the thesis's unit): `min`, `max`, `resolution` in degrees.
    pub fn degrees(min: f64, max: f64, resolution: f64) -> AngleAxis {
        AngleAxis {
            min: min.to_radians(),
            max: max.to_radians(),
            resolution: resolution.to_radians(),
        }
    }

    fn check(&self, what: &'static str) -> Result<usize> {
        let right = std::f64::consts::FRAC_PI_2;
        if !(self.resolution.is_finite()
            && self.resolution > 0.0
            && self.resolution <= right + 1e-12)
        {
            return Err(HoughError::BadParameter {
                what,
                value: self.resolution,
                allowed: "angular resolution in (0, 90°]",
            });
        }
        if !(self.min.is_finite() && self.max.is_finite() && self.min < self.max) {
            return Err(HoughError::EmptyRange { what, min: self.min, max: self.max });
        }
        if self.min <= -right || self.max > right + 1e-12 {
            return Err(HoughError::BadParameter {
                what,
                value: if self.min <= -right { self.min } else { self.max },
                allowed: "angles in (−90°, 90°] (the parameterisation is singular at ±90°)",
            });
        }
        let n = ((self.max - self.min) / self.resolution - COUNT_SLACK).ceil();
        if n > MAX_BINS as f64 {
            return Err(HoughError::TooManyBins { what, bins: n as u64, limit: MAX_BINS });
        }
        Ok((n as usize).max(1))
    }
}

/// The distance axis: bins `[min + k·resolution, min + (k+1)·resolution)` for
/// `k = 0 .. ⌈(max − min)/resolution⌉ − 1`, metres (spec §6.6: bin = ⌊(d − min)/resolution⌋).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DistanceAxis {
    /// Lower end, metres.
    pub min: f64,
    /// Upper end (exclusive), metres.
    pub max: f64,
    /// Bin width, metres; positive.
    pub resolution: f64,
}

impl DistanceAxis {
    fn check(&self) -> Result<usize> {
        let what = "distance axis";
        if !(self.resolution.is_finite() && self.resolution > 0.0) {
            return Err(HoughError::BadParameter {
                what,
                value: self.resolution,
                allowed: "distance resolution > 0",
            });
        }
        if !(self.min.is_finite() && self.max.is_finite() && self.min < self.max) {
            return Err(HoughError::EmptyRange { what, min: self.min, max: self.max });
        }
        let n = ((self.max - self.min) / self.resolution - COUNT_SLACK).ceil();
        if n.is_nan() || n > MAX_BINS as f64 {
            return Err(HoughError::TooManyBins { what, bins: n as u64, limit: MAX_BINS });
        }
        Ok((n as usize).max(1))
    }
}

/// Which normal Algorithm 2 uses for `d = n·p`.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum NormalKind {
    /// The thesis's `n = (−sin ρx cos ρy, −cos ρx sin ρy, cos ρx cos ρy)` verbatim (L3338); not
    /// unit length (`|n|² = sin²ρx cos²ρy + cos²ρx`), so `d` is the Euclidean distance times
    /// `|n|` (spec §3, §6.7).
    Thesis,
    /// The same direction normalised: `d` is the Euclidean signed distance.
    Unit,
}

/// A bin of the accumulator: angle sample indices and distance bin.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Bin {
    /// Index of the ρx sample.
    pub ix: usize,
    /// Index of the ρy sample.
    pub iy: usize,
    /// Index of the distance bin.
    pub id: usize,
}

/// A plane in the thesis's parameters, in the levelled frame (x forward, y right, z down).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Plane {
    /// ρx, radians (positive: the plane falls away, i.e. goes downhill, ahead).
    pub rho_x: f64,
    /// ρy, radians (positive: the plane falls away to the right).
    pub rho_y: f64,
    /// Signed distance `d` of Algorithm 2 (with the space's [`NormalKind`]), metres; positive
    /// when the plane crosses the z axis below the sensor.
    pub d: f64,
}

impl Plane {
    /// The thesis's normal `(−sin ρx cos ρy, −cos ρx sin ρy, cos ρx cos ρy)` (not unit length).
    pub fn thesis_normal(&self) -> Vector3<f64> {
        thesis_normal(self.rho_x, self.rho_y)
    }

    /// The unit normal, pointing down (z > 0 in the levelled frame).
    pub fn unit_normal(&self) -> Vector3<f64> {
        self.thesis_normal().normalize()
    }

    /// The "combined angle" of the thesis (L3453–3460): the angle between the plane's normal
    /// and the vertical, `atan √(tan²ρx + tan²ρy)`, radians.
    pub fn tilt(&self) -> f64 {
        let n = self.thesis_normal();
        (n.z.abs() / n.norm()).clamp(-1.0, 1.0).acos()
    }

    /// The height of the plane below the sensor on the z axis (`d / (cos ρx cos ρy)`), metres.
    pub fn z_intercept(&self) -> f64 {
        self.d / (self.rho_x.cos() * self.rho_y.cos())
    }

    /// The same plane in a z-up frame (x forward, y left, z up) at the sensor: `(−ρx, ρy, −d)`.
    pub fn to_z_up(&self) -> Plane {
        Plane { rho_x: -self.rho_x, rho_y: self.rho_y, d: -self.d }
    }
}

/// Sample `k` of an angle axis, snapped to exactly 0 within 10⁻⁹ rad (so the floor's angles
/// are exact).
fn sample(axis: &AngleAxis, k: usize) -> f64 {
    let v = axis.min + k as f64 * axis.resolution;
    if v.abs() < 1e-9 { 0.0 } else { v }
}

/// The thesis's normal for the angles (L3338).
pub fn thesis_normal(rho_x: f64, rho_y: f64) -> Vector3<f64> {
    let (sx, cx) = rho_x.sin_cos();
    let (sy, cy) = rho_y.sin_cos();
    Vector3::new(-sx * cy, -cx * sy, cx * cy)
}

/// The validated Hough space: three axes and the normal kind. The accumulator is one flat
/// `Vec<u32>` indexed `(iy · nx + ix) · nd + id`: ρy outer, ρx inner (the column order of
/// Fig 4.3), distance innermost so one angle pair's bins are contiguous.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HoughSpace {
    rho_x: AngleAxis,
    rho_y: AngleAxis,
    d: DistanceAxis,
    normal: NormalKind,
    nx: usize,
    ny: usize,
    nd: usize,
}

impl HoughSpace {
    /// Checks the axes: angles finite in (−90°, 90°], resolutions in (0, 90°], ranges not
    /// empty, distance resolution positive, at most [`MAX_BINS`] bins.
    pub fn new(
        rho_x: AngleAxis,
        rho_y: AngleAxis,
        d: DistanceAxis,
        normal: NormalKind,
    ) -> Result<HoughSpace> {
        let nx = rho_x.check("ρx axis")?;
        let ny = rho_y.check("ρy axis")?;
        let nd = d.check()?;
        let bins = nx as u64 * ny as u64 * nd as u64;
        if bins > MAX_BINS {
            return Err(HoughError::TooManyBins { what: "Hough space", bins, limit: MAX_BINS });
        }
        Ok(HoughSpace { rho_x, rho_y, d, normal, nx, ny, nd })
    }

    /// The thesis's space (L3522–3542) at angular `resolution` (radians): ρx ∈ [−45°, 18°),
    /// ρy ∈ [−45°, 45°), d ∈ [−1, 2) m at 0.1 m, the thesis's normal. The thesis used 45°
    /// (drivability), 15° and 9° (classes).
    pub fn thesis(resolution: f64) -> Result<HoughSpace> {
        HoughSpace::new(
            AngleAxis { min: -45f64.to_radians(), max: 18f64.to_radians(), resolution },
            AngleAxis { min: -45f64.to_radians(), max: 45f64.to_radians(), resolution },
            DistanceAxis { min: -1.0, max: 2.0, resolution: 0.1 },
            NormalKind::Thesis,
        )
    }

    /// [`HoughSpace::thesis`] with the resolution in degrees.
    pub fn thesis_degrees(resolution_deg: f64) -> Result<HoughSpace> {
        HoughSpace::thesis(resolution_deg.to_radians())
    }

    /// The same axes with another normal kind.
    pub fn with_normal(mut self, normal: NormalKind) -> HoughSpace {
        self.normal = normal;
        self
    }

    /// The ρx axis.
    pub fn rho_x_axis(&self) -> &AngleAxis {
        &self.rho_x
    }

    /// The ρy axis.
    pub fn rho_y_axis(&self) -> &AngleAxis {
        &self.rho_y
    }

    /// The distance axis.
    pub fn d_axis(&self) -> &DistanceAxis {
        &self.d
    }

    /// The normal kind.
    pub fn normal_kind(&self) -> NormalKind {
        self.normal
    }

    /// Number of ρx samples.
    pub fn nx(&self) -> usize {
        self.nx
    }

    /// Number of ρy samples.
    pub fn ny(&self) -> usize {
        self.ny
    }

    /// Number of distance bins.
    pub fn nd(&self) -> usize {
        self.nd
    }

    /// Number of angle pairs (votes per point).
    pub fn angle_pairs(&self) -> usize {
        self.nx * self.ny
    }

    /// Number of bins.
    pub fn len(&self) -> usize {
        self.nx * self.ny * self.nd
    }

    /// Always false (a valid space has at least one bin); for symmetry with [`Self::len`].
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The sampled ρx of index `ix`: `min + ix · resolution`, radians (a sample within 10⁻⁹ rad
    /// of 0 is exactly 0).
    pub fn rho_x(&self, ix: usize) -> f64 {
        sample(&self.rho_x, ix)
    }

    /// The sampled ρy of index `iy`, radians (snapped to 0 like [`Self::rho_x`]).
    pub fn rho_y(&self, iy: usize) -> f64 {
        sample(&self.rho_y, iy)
    }

    /// The centre of distance bin `id`, metres.
    pub fn d_center(&self, id: usize) -> f64 {
        self.d.min + (id as f64 + 0.5) * self.d.resolution
    }

    /// The distance bin of `d`: `⌊(d − min)/resolution⌋` if that is in `0..nd`.
    pub fn d_bin(&self, d: f64) -> Option<usize> {
        let t = ((d - self.d.min) / self.d.resolution).floor();
        (t >= 0.0 && t < self.nd as f64).then_some(t as usize)
    }

    /// The index of a sampled angle equal to 0 (within 10⁻⁹ rad) on an axis, if any.
    pub fn zero_index(axis: &AngleAxis, n: usize) -> Option<usize> {
        (0..n).find(|&k| sample(axis, k) == 0.0)
    }

    /// The flat index of a bin.
    pub fn index(&self, bin: Bin) -> usize {
        (bin.iy * self.nx + bin.ix) * self.nd + bin.id
    }

    /// The bin of a flat index.
    pub fn bin(&self, index: usize) -> Bin {
        let id = index % self.nd;
        let pair = index / self.nd;
        Bin { ix: pair % self.nx, iy: pair / self.nx, id }
    }

    /// The normal used for voting at sample `(ix, iy)`: the thesis's or its unit version.
    pub fn normal(&self, ix: usize, iy: usize) -> Vector3<f64> {
        let n = thesis_normal(self.rho_x(ix), self.rho_y(iy));
        match self.normal {
            NormalKind::Thesis => n,
            NormalKind::Unit => n / n.norm(),
        }
    }

    /// The plane of a bin (distance at the bin centre).
    pub fn plane(&self, bin: Bin) -> Plane {
        Plane { rho_x: self.rho_x(bin.ix), rho_y: self.rho_y(bin.iy), d: self.d_center(bin.id) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thesis_sampling_matches_spec() {
        // Spec §6.6: 2×2 at 45°, 5×6 at 15°, 7×10 at 9°; 30 distance bins; 0° sampled.
        for (res, nx, ny) in [(45.0, 2, 2), (15.0, 5, 6), (9.0, 7, 10)] {
            let s = HoughSpace::thesis_degrees(res).unwrap();
            assert_eq!((s.nx(), s.ny(), s.nd()), (nx, ny, 30), "{res}°");
            assert!(HoughSpace::zero_index(s.rho_x_axis(), s.nx()).is_some());
            assert!(HoughSpace::zero_index(s.rho_y_axis(), s.ny()).is_some());
        }
        let s = HoughSpace::thesis_degrees(45.0).unwrap();
        assert!((s.rho_x(0) + 45f64.to_radians()).abs() < 1e-12 && s.rho_x(1) == 0.0);
        assert_eq!(s.d_bin(-1.0), Some(0));
        assert_eq!(s.d_bin(1.99), Some(29));
        assert_eq!(s.d_bin(2.0), None);
        assert_eq!(s.d_bin(-1.0001), None);
    }

    #[test]
    fn index_round_trips() {
        let s = HoughSpace::thesis_degrees(9.0).unwrap();
        for i in 0..s.len() {
            assert_eq!(s.index(s.bin(i)), i);
        }
    }

    #[test]
    fn absurd_parameters_are_errors() {
        let d = DistanceAxis { min: -1.0, max: 2.0, resolution: 0.1 };
        let ok = AngleAxis::degrees(-45.0, 45.0, 15.0);
        let t = NormalKind::Thesis;
        for bad in [
            AngleAxis::degrees(-45.0, 45.0, 0.0),
            AngleAxis::degrees(-45.0, 45.0, 91.0),
            AngleAxis::degrees(-45.0, 45.0, -5.0),
            AngleAxis::degrees(-45.0, 45.0, f64::NAN),
            AngleAxis::degrees(45.0, -45.0, 15.0),
            AngleAxis::degrees(10.0, 10.0, 15.0),
            AngleAxis::degrees(-90.0, 45.0, 15.0),
            AngleAxis::degrees(-45.0, 120.0, 15.0),
            AngleAxis::degrees(-45.0, 45.0, 1e-9),
        ] {
            assert!(HoughSpace::new(bad, ok, d, t).is_err(), "{bad:?}");
            assert!(HoughSpace::new(ok, bad, d, t).is_err(), "{bad:?}");
        }
        for bad in [
            DistanceAxis { min: 2.0, max: -1.0, resolution: 0.1 },
            DistanceAxis { min: 0.0, max: 0.0, resolution: 0.1 },
            DistanceAxis { min: -1.0, max: 2.0, resolution: 0.0 },
            DistanceAxis { min: -1.0, max: f64::INFINITY, resolution: 0.1 },
            DistanceAxis { min: -1.0, max: 2.0, resolution: 1e-12 },
        ] {
            assert!(HoughSpace::new(ok, ok, bad, t).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn plane_geometry() {
        // n·p = d is z = tan ρx x + tan ρy y + d/(cos ρx cos ρy).
        let p = Plane { rho_x: 0.3, rho_y: -0.2, d: 0.7 };
        let (x, y) = (1.3, -0.4);
        let z = p.rho_x.tan() * x + p.rho_y.tan() * y + p.z_intercept();
        assert!((p.thesis_normal().dot(&Vector3::new(x, y, z)) - p.d).abs() < 1e-12);
        let tilt = (p.rho_x.tan().powi(2) + p.rho_y.tan().powi(2)).sqrt().atan();
        assert!((p.tilt() - tilt).abs() < 1e-12);
        let up = p.to_z_up();
        // The same point in the z-up frame (x, −y, −z) lies on the mirrored plane.
        assert!((up.thesis_normal().dot(&Vector3::new(x, -y, -z)) - up.d).abs() < 1e-12);
    }
}
