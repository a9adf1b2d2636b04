//! The time-of-flight range camera (thesis §2.3): a MESA SwissRanger SR-3000, 176 × 144
//! pixels, 47° × 39° field of view, 0.6–7.5 m (Table 2.1). Its driver reports the distance to
//! the image plane ("depth", §2.3.2), which is what the images here hold.
//!
//! This model is the geometric part only: pinhole beams, the range window and Gaussian noise.
//! The camera's time-of-flight effects (amplitude falling with range and reflectivity,
//! wrap-around beyond the 7.5 m non-ambiguity range, amplitude thresholds, §2.5) belong to a
//! ToF model that starts from [`RangeCamera::scan_hits`]: the noise-free hits per pixel with
//! radial range, incidence cosine, reflectivity and beam direction, cast up to
//! [`RangeCameraConfig::cast_range`] (beyond the camera's range, so wrapped surfaces are
//! there).

use super::{
    GroundTruth, HitImage, RangeSensor, SimulatedScan, camera_pose_from_body, check_range,
    check_size, make_image, trace_image,
};
use crate::{Scene, SensorError};
use pointcloud::{BeamModel, PinholeIntrinsics, RangeKind, Real, SensorPose};
use rand::Rng as _;
use rand::SeedableRng as _;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};

/// Configuration of a [`RangeCamera`]. No `Default`: start from a preset.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RangeCameraConfig {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Full horizontal field of view, radians.
    pub fov_x: Real,
    /// Full vertical field of view, radians.
    pub fov_y: Real,
    /// Shortest radial range reported, metres.
    pub min_range: Real,
    /// Longest radial range reported, metres (farther surfaces give no measurement here; a
    /// ToF model wraps them instead).
    pub max_range: Real,
    /// Standard deviation of the Gaussian noise along the beam, metres.
    pub range_sigma: Real,
    /// How far [`RangeCamera::scan_hits`] casts, metres (≥ `max_range`).
    pub cast_range: Real,
}

impl RangeCameraConfig {
    /// The SwissRanger SR-3000 of Table 2.1: 176 × 144, 47° × 39°, 0.6–7.5 m. Noise
    /// σ = 1 cm along the beam (the thesis measured per-pixel variances up to 3.9·10⁻⁴ at 1 m,
    /// §2.5.3, i.e. σ up to 2 cm if in m²; 1 cm is the manufacturer's typical figure). Hits are
    /// cast to 30 m, four non-ambiguity ranges.
    pub fn swissranger_sr3000() -> RangeCameraConfig {
        RangeCameraConfig {
            width: 176,
            height: 144,
            fov_x: 47f64.to_radians(),
            fov_y: 39f64.to_radians(),
            min_range: 0.6,
            max_range: 7.5,
            range_sigma: 0.01,
            cast_range: 30.0,
        }
    }

    /// The pinhole intrinsics.
    pub fn intrinsics(&self) -> PinholeIntrinsics {
        PinholeIntrinsics::from_fov(self.width, self.height, self.fov_x, self.fov_y)
    }

    /// Checks every parameter.
    pub fn validate(&self) -> Result<(), SensorError> {
        check_size(self.width, self.height)?;
        let pi = std::f64::consts::PI;
        check_range("fov_x", self.fov_x, 1e-3, pi - 1e-3, "(0, 180°)")?;
        check_range("fov_y", self.fov_y, 1e-3, pi - 1e-3, "(0, 180°)")?;
        check_range("min_range", self.min_range, 0.0, 1e4, "[0, 10 km]")?;
        check_range("max_range", self.max_range, self.min_range, 1e4, "[min_range, 10 km]")?;
        check_range("range_sigma", self.range_sigma, 0.0, 10.0, "[0, 10] m")?;
        check_range("cast_range", self.cast_range, self.max_range, 1e5, "[max_range, 100 km]")?;
        Ok(())
    }
}

/// A simulated range camera (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct RangeCamera {
    config: RangeCameraConfig,
}

impl RangeCamera {
    /// A camera with a checked configuration.
    pub fn new(config: RangeCameraConfig) -> Result<RangeCamera, SensorError> {
        config.validate()?;
        Ok(RangeCamera { config })
    }

    /// The SwissRanger SR-3000 ([`RangeCameraConfig::swissranger_sr3000`]).
    pub fn swissranger_sr3000() -> RangeCamera {
        RangeCamera { config: RangeCameraConfig::swissranger_sr3000() }
    }

    /// The configuration.
    pub fn config(&self) -> &RangeCameraConfig {
        &self.config
    }

    /// The beam model (pinhole).
    pub fn beam_model(&self) -> BeamModel {
        BeamModel::Pinhole(self.config.intrinsics())
    }

    /// The noise-free hit of every pixel up to [`RangeCameraConfig::cast_range`]: the input of
    /// a time-of-flight model. `pose` is the optical-frame pose, as for [`RangeSensor::scan`].
    pub fn scan_hits(&self, scene: &Scene, pose: &SensorPose) -> HitImage {
        let c = &self.config;
        trace_image(scene, pose, &self.beam_model(), c.width, c.height, c.cast_range)
    }
}

impl RangeSensor for RangeCamera {
    fn scan(&self, scene: &Scene, pose: &SensorPose, seed: u64) -> SimulatedScan {
        let c = &self.config;
        let hits = self.scan_hits(scene, pose);
        let n = hits.hits.len();
        let mut truth = GroundTruth::with_len(n);
        let mut ranges = vec![None; n];
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        for (i, hit) in hits.hits.iter().enumerate() {
            let Some(hit) = hit else { continue };
            // Unit direction in the optical frame: depth = radial range × its z.
            truth.set(i, hit, hit.range * hit.direction.z);
            let noise: Real = rng.sample(StandardNormal);
            let r = hit.range + c.range_sigma * noise;
            if hit.range <= c.max_range && r >= c.min_range && r <= c.max_range {
                ranges[i] = Some((r * hit.direction.z) as f32);
            }
        }
        SimulatedScan {
            image: make_image(c.width, c.height, hits.beams, RangeKind::Depth, ranges),
            pose: *pose,
            truth,
        }
    }

    fn mount(&self, body_pose: &SensorPose) -> SensorPose {
        camera_pose_from_body(body_pose)
    }
}
