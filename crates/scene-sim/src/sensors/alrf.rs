//! The actuated laser range finder (thesis §2.1 and §3.2): a SICK S300 2D safety scanner
//! (270° in 0.5° steps, 0–20 m) pitched by a servo from −90° to +90°, giving up to
//! 541 × 361 = 195,301 beams per 3D scan (the Lab dataset, §3.2.1).
//!
//! Modelled: the beam grid of [`BeamModel::ActuatedLrf`] (x forward, y left, z up; beams beyond
//! ±90° look backwards), a range window, Gaussian range noise, no return from surfaces whose
//! remission (reflectivity × incidence cosine) is below the scanner's detection limit, and
//! mixed pixels at depth discontinuities. Not modelled: the sweep's duration (a real scan takes
//! about ten seconds, thesis Table 2.1: 0.1 Hz), the actuator occluding beams, multiple echoes.

use super::{
    GroundTruth, RangeSensor, SimulatedScan, check_range, check_size, make_image, trace_image,
};
use crate::{Scene, SensorError, UnitVector3};
use pointcloud::{ActuatedLrfModel, BeamModel, Point3, RangeKind, Real, SensorPose, Vector3};
use rand::{Rng as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};

/// Mixed pixels: a beam's footprint straddling a depth edge reports a range between the
/// foreground and the background.
///
/// Simulated by casting a second ray offset from the beam axis by half the `divergence`, in a
/// random direction around it: if it hits another surface and its range differs from the main
/// ray's by more than `min_jump`, then with probability `probability` the beam reports
/// `r_main + w·(r_second − r_main)`, `w` uniform in [0, 1]. A second ray that hits nothing
/// within range leaves the beam alone.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MixedPixelConfig {
    /// Full beam divergence, radians, in [0, 0.1].
    pub divergence: Real,
    /// Probability that a straddling beam reports a mixture, in [0, 1].
    pub probability: Real,
    /// Range difference that counts as an edge, metres (≥ 0).
    pub min_jump: Real,
}

/// Configuration of an [`Alrf`]. No `Default`: start from a preset.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AlrfConfig {
    /// Beams per 2D scan (image columns).
    pub columns: u32,
    /// 2D scans per 3D scan (image rows).
    pub rows: u32,
    /// Beam angle of column 0, radians.
    pub beam_start: Real,
    /// Beam angle of the last column, radians.
    pub beam_end: Real,
    /// Pitch of row 0, radians (positive tilts the forward beam up).
    pub pitch_top: Real,
    /// Pitch of the last row, radians.
    pub pitch_bottom: Real,
    /// Shortest range reported, metres.
    pub min_range: Real,
    /// Longest range reported, metres; farther surfaces give no measurement.
    pub max_range: Real,
    /// Standard deviation of the Gaussian range noise, metres.
    pub range_sigma: Real,
    /// Surfaces whose reflectivity × incidence cosine is below this return nothing.
    pub min_remission: Real,
    /// Mixed pixels at depth edges, if simulated.
    pub mixed_pixels: Option<MixedPixelConfig>,
}

impl AlrfConfig {
    /// The thesis's ALRF: SICK S300 with 541 beams over 270° (−135° … +135°, 0.5° steps),
    /// pitched over 361 rows from +90° to −90° (0.5° steps), 0–20 m.
    ///
    /// Noise σ = 0.03 m: the S300's datasheet gives a systematic error of about ±3 cm (it is a
    /// safety scanner, not a measuring one); the thesis gives no figure. Detection limit:
    /// remission 1.8 % (the S300's rated minimum). Mixed pixels: footprint 0.5° (about the
    /// angular step), probability 0.5, edges above 5 cm — assumptions, not datasheet values.
    pub fn sick_s300() -> AlrfConfig {
        let deg = |d: Real| d.to_radians();
        AlrfConfig {
            columns: 541,
            rows: 361,
            beam_start: deg(-135.0),
            beam_end: deg(135.0),
            pitch_top: deg(90.0),
            pitch_bottom: deg(-90.0),
            min_range: 0.0,
            max_range: 20.0,
            range_sigma: 0.03,
            min_remission: 0.018,
            mixed_pixels: Some(MixedPixelConfig {
                divergence: deg(0.5),
                probability: 0.5,
                min_jump: 0.05,
            }),
        }
    }

    /// [`AlrfConfig::sick_s300`] down-sampled to `step` radians in both beam angle and pitch
    /// (for example 1° like the thesis's Hannover datasets: 271 × 181 beams; 2° or 5° for
    /// fast tests). The grid stays centred; `step` must be in [0.1°, 90°].
    pub fn sick_s300_with_step(step: Real) -> Result<AlrfConfig, SensorError> {
        check_range(
            "ALRF angular step (radians)",
            step,
            0.1f64.to_radians(),
            90f64.to_radians(),
            "[0.001745, 1.5708] (0.1° to 90°)",
        )?;
        let mut c = AlrfConfig::sick_s300();
        let beam_span = c.beam_end - c.beam_start;
        let pitch_span = c.pitch_top - c.pitch_bottom;
        let columns = (beam_span / step + 1e-9).floor() as u32 + 1;
        let rows = (pitch_span / step + 1e-9).floor() as u32 + 1;
        let half_b = (columns - 1) as Real * step / 2.0;
        let half_p = (rows - 1) as Real * step / 2.0;
        c.columns = columns;
        c.rows = rows;
        c.beam_start = -half_b;
        c.beam_end = half_b;
        c.pitch_top = half_p;
        c.pitch_bottom = -half_p;
        Ok(c)
    }

    /// The beam model of this configuration.
    pub fn beam_model(&self) -> BeamModel {
        BeamModel::ActuatedLrf(ActuatedLrfModel {
            beam_start: self.beam_start,
            beam_end: self.beam_end,
            pitch_top: self.pitch_top,
            pitch_bottom: self.pitch_bottom,
        })
    }

    /// Checks every parameter.
    pub fn validate(&self) -> Result<(), SensorError> {
        check_size(self.columns, self.rows)?;
        let two_pi = 2.0 * std::f64::consts::PI;
        for (what, v) in [
            ("beam_start", self.beam_start),
            ("beam_end", self.beam_end),
            ("pitch_top", self.pitch_top),
            ("pitch_bottom", self.pitch_bottom),
        ] {
            check_range(what, v, -two_pi, two_pi, "[-2π, 2π]")?;
        }
        check_range("min_range", self.min_range, 0.0, 1e4, "[0, 10 km]")?;
        check_range("max_range", self.max_range, self.min_range, 1e4, "[min_range, 10 km]")?;
        if self.max_range <= 0.0 {
            return Err(SensorError::BadParameter {
                what: "max_range",
                value: self.max_range,
                allowed: "> 0",
            });
        }
        check_range("range_sigma", self.range_sigma, 0.0, 10.0, "[0, 10] m")?;
        check_range("min_remission", self.min_remission, 0.0, 1.0, "[0, 1]")?;
        if let Some(m) = &self.mixed_pixels {
            check_range("mixed-pixel divergence", m.divergence, 0.0, 0.1, "[0, 0.1] rad")?;
            check_range("mixed-pixel probability", m.probability, 0.0, 1.0, "[0, 1]")?;
            check_range("mixed-pixel min_jump", m.min_jump, 0.0, 1e4, "≥ 0")?;
        }
        Ok(())
    }
}

/// A simulated actuated laser range finder (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Alrf {
    config: AlrfConfig,
}

impl Alrf {
    /// A scanner with a checked configuration.
    pub fn new(config: AlrfConfig) -> Result<Alrf, SensorError> {
        config.validate()?;
        Ok(Alrf { config })
    }

    /// The full-resolution SICK S300 scanner ([`AlrfConfig::sick_s300`]).
    pub fn sick_s300() -> Alrf {
        Alrf { config: AlrfConfig::sick_s300() }
    }

    /// The configuration.
    pub fn config(&self) -> &AlrfConfig {
        &self.config
    }

    /// The beam model of the scans.
    pub fn beam_model(&self) -> BeamModel {
        self.config.beam_model()
    }
}

/// Two unit vectors completing `d` (unit) to an orthonormal basis.
fn perpendiculars(d: &Vector3) -> (Vector3, Vector3) {
    let a = if d.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() };
    let e1 = d.cross(&a).normalize();
    (e1, d.cross(&e1))
}

impl RangeSensor for Alrf {
    fn scan(&self, scene: &Scene, pose: &SensorPose, seed: u64) -> SimulatedScan {
        let c = &self.config;
        let beams = c.beam_model();
        let hits = trace_image(scene, pose, &beams, c.columns, c.rows, c.max_range);
        let n = hits.hits.len();
        let mut truth = GroundTruth::with_len(n);
        let mut ranges = vec![None; n];
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let origin: Point3 = pose.world_from_sensor.translation.vector.into();
        let rotation = pose.world_from_sensor.rotation;
        for (i, hit) in hits.hits.iter().enumerate() {
            let Some(hit) = hit else { continue };
            truth.set(i, hit, hit.range);
            if hit.reflectivity as Real * hit.incidence_cos < c.min_remission {
                continue;
            }
            let mut r = hit.range;
            if let Some(m) = &c.mixed_pixels {
                let (e1, e2) = perpendiculars(&hit.direction);
                let psi = rng.random_range(0.0..2.0 * std::f64::consts::PI);
                let off = (m.divergence / 2.0).tan();
                let d2 = hit.direction + (e1 * psi.cos() + e2 * psi.sin()) * off;
                let dir2 = UnitVector3::new_normalize(rotation * d2);
                if let Some(h2) = scene.cast_ray(&origin, &dir2, c.max_range)
                    && h2.surface != hit.surface
                    && (h2.distance - r).abs() > m.min_jump
                    && rng.random_bool(m.probability)
                {
                    r += rng.random_range(0.0..=1.0) * (h2.distance - r);
                    truth.mixed_pixel[i] = true;
                }
            }
            let noise: Real = rng.sample(StandardNormal);
            let r = r + c.range_sigma * noise;
            if r >= c.min_range && r <= c.max_range && r >= 0.0 {
                ranges[i] = Some(r as f32);
            }
        }
        SimulatedScan {
            image: make_image(c.columns, c.rows, beams, RangeKind::Radial, ranges),
            pose: *pose,
            truth,
        }
    }
}
