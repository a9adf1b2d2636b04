//! The stereo camera (thesis §2.2): a Videre STOC, 640 × 480 pixels, 65.5° × 51.5° field of
//! view, from 0.686 m (Table 2.1), depth images.
//!
//! Modelled: depth noise that grows with the square of the depth, as disparity noise does:
//! `z = f·b/d`, so `σ_z = z²·σ_d/(f·b)` with focal length `f` (pixels), baseline `b` and
//! disparity noise `σ_d`; and dropouts: stereo matching fails on surfaces without texture
//! (plain walls), which is why the thesis's stereo data has valid ratios of 4–14 % (Table 3.1).
//! Not modelled: matching errors (outliers), smoothing across edges, occlusion between the two
//! views, the sub-pixel disparity quantisation.

use super::{
    GroundTruth, RangeSensor, SimulatedScan, camera_pose_from_body, check_range, check_size,
    make_image, trace_image,
};
use crate::{Scene, SensorError};
use pointcloud::{BeamModel, PinholeIntrinsics, RangeKind, Real, SensorPose};
use rand::{Rng as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};

/// Configuration of a [`StereoCamera`]. No `Default`: start from a preset.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StereoCameraConfig {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Full horizontal field of view, radians.
    pub fov_x: Real,
    /// Full vertical field of view, radians.
    pub fov_y: Real,
    /// Shortest depth reported, metres (the largest disparity searched).
    pub min_range: Real,
    /// Longest depth reported, metres.
    pub max_range: Real,
    /// Stereo baseline, metres.
    pub baseline: Real,
    /// Standard deviation of the disparity, pixels.
    pub disparity_sigma: Real,
    /// Probability that a pixel on a textureless surface has no measurement.
    pub untextured_dropout: Real,
    /// Probability that a pixel on a textured surface has no measurement.
    pub textured_dropout: Real,
}

impl StereoCameraConfig {
    /// The STOC of Table 2.1: 640 × 480, 65.5° × 51.5°, from 0.686 m. Baseline 9 cm, disparity
    /// noise 0.1 px, so with `f ≈ 497.6` px, `k = σ_d/(f·b) ≈ 2.23·10⁻³ m⁻¹`: σ_z ≈ 9 mm at
    /// 2 m, 5.6 cm at 5 m. Depths beyond 30 m (disparity below 1.5 px) are dropped. Dropouts:
    /// 95 % on textureless, 5 % on textured surfaces (assumptions).
    pub fn stoc() -> StereoCameraConfig {
        StereoCameraConfig {
            width: 640,
            height: 480,
            fov_x: 65.5f64.to_radians(),
            fov_y: 51.5f64.to_radians(),
            min_range: 0.686,
            max_range: 30.0,
            baseline: 0.09,
            disparity_sigma: 0.1,
            untextured_dropout: 0.95,
            textured_dropout: 0.05,
        }
    }

    /// The pinhole intrinsics.
    pub fn intrinsics(&self) -> PinholeIntrinsics {
        PinholeIntrinsics::from_fov(self.width, self.height, self.fov_x, self.fov_y)
    }

    /// The factor `k` of the depth noise `σ_z = k·z²`: `σ_d/(f_x·b)`, per metre.
    pub fn depth_noise_factor(&self) -> Real {
        self.disparity_sigma / (self.intrinsics().fx * self.baseline)
    }

    /// Checks every parameter.
    pub fn validate(&self) -> Result<(), SensorError> {
        check_size(self.width, self.height)?;
        let pi = std::f64::consts::PI;
        check_range("fov_x", self.fov_x, 1e-3, pi - 1e-3, "(0, 180°)")?;
        check_range("fov_y", self.fov_y, 1e-3, pi - 1e-3, "(0, 180°)")?;
        check_range("min_range", self.min_range, 0.0, 1e4, "[0, 10 km]")?;
        check_range("max_range", self.max_range, self.min_range, 1e4, "[min_range, 10 km]")?;
        check_range("baseline", self.baseline, 1e-4, 10.0, "[0.1 mm, 10 m]")?;
        check_range("disparity_sigma", self.disparity_sigma, 0.0, 100.0, "[0, 100] px")?;
        check_range("untextured_dropout", self.untextured_dropout, 0.0, 1.0, "[0, 1]")?;
        check_range("textured_dropout", self.textured_dropout, 0.0, 1.0, "[0, 1]")?;
        Ok(())
    }
}

/// A simulated stereo camera (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct StereoCamera {
    config: StereoCameraConfig,
}

impl StereoCamera {
    /// A camera with a checked configuration.
    pub fn new(config: StereoCameraConfig) -> Result<StereoCamera, SensorError> {
        config.validate()?;
        Ok(StereoCamera { config })
    }

    /// The STOC ([`StereoCameraConfig::stoc`]).
    pub fn stoc() -> StereoCamera {
        StereoCamera { config: StereoCameraConfig::stoc() }
    }

    /// The configuration.
    pub fn config(&self) -> &StereoCameraConfig {
        &self.config
    }

    /// The beam model (pinhole).
    pub fn beam_model(&self) -> BeamModel {
        BeamModel::Pinhole(self.config.intrinsics())
    }

    /// The depth noise standard deviation at depth `z`, metres.
    pub fn depth_sigma(&self, z: Real) -> Real {
        self.config.depth_noise_factor() * z * z
    }
}

impl RangeSensor for StereoCamera {
    fn scan(&self, scene: &Scene, pose: &SensorPose, seed: u64) -> SimulatedScan {
        let c = &self.config;
        let beams = self.beam_model();
        // A corner pixel's radial range is its depth times the length of its pinhole ray.
        let corner = ((c.fov_x / 2.0).tan().powi(2) + (c.fov_y / 2.0).tan().powi(2) + 1.0).sqrt();
        let reach = c.max_range * corner + 1.0;
        let hits = trace_image(scene, pose, &beams, c.width, c.height, reach);
        let k = c.depth_noise_factor();
        let n = hits.hits.len();
        let mut truth = GroundTruth::with_len(n);
        let mut ranges = vec![None; n];
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        for (i, hit) in hits.hits.iter().enumerate() {
            let Some(hit) = hit else { continue };
            let z = hit.range * hit.direction.z;
            truth.set(i, hit, z);
            let dropout = if hit.textured { c.textured_dropout } else { c.untextured_dropout };
            if rng.random_bool(dropout) {
                continue;
            }
            let noise: Real = rng.sample(StandardNormal);
            let zm = z + k * z * z * noise;
            if z >= c.min_range && z <= c.max_range && zm >= c.min_range && zm <= c.max_range {
                ranges[i] = Some(zm as f32);
            }
        }
        SimulatedScan {
            image: make_image(c.width, c.height, beams, RangeKind::Depth, ranges),
            pose: *pose,
            truth,
        }
    }

    fn mount(&self, body_pose: &SensorPose) -> SensorPose {
        camera_pose_from_body(body_pose)
    }
}
