//! A time-of-flight camera simulator on `scene-sim`'s ray caster (thesis §2.3, §2.5.4,
//! spec §1): per pixel the camera's own modulated light comes back from the first surface the
//! beam meets, is mixed with scattered light, ambient light and sunlight, sampled four times
//! with noise and demodulated (Eqs 2.1–2.3). Wrap-around, amplitude noise, range noise, sunlight
//! noise, saturation and scattering all come out of that one model.
//!
//! # The model
//!
//! For pixel `p` whose beam (unit direction, optical frame) meets a surface of near-infrared
//! reflectivity `ρ` (Table 2.3) at radial distance `r` and incidence cosine `cos θ`:
//!
//! 1. **Direct return.** Amplitude `a = s · ρ · g(θ) · L_p / r²` and phase `φ = 2π r / R_amb`
//!    (mod 2π), `R_amb = c / (2 f)` (L1694). The `1/r²` is the thesis's argument (L2350–2362,
//!    Appendix A L7668–7682): the light per area on the obstacle falls as `1/r²`, the diffusely
//!    returned light per area and pixel falls as `1/r²`, the area a pixel sees grows as `r²`.
//!    `g(θ) = cos θ` is Lambert's law for the diffuse surface (the default). Rough surfaces send
//!    more light back towards a source beside the sensor at grazing incidence than Lambert's law
//!    (Oren & Nayar 1994): with source and sensor together (`θ_i = θ_r = θ`, same azimuth) their
//!    model gives radiance `∝ ρ (A cos θ + B sin² θ)`, `A = 1 − σ²/(2(σ² + 0.33))`,
//!    `B = 0.45 σ²/(σ² + 0.09)` for the facet slope deviation `σ` ([`SimConfig::roughness`]);
//!    the simulator uses `g(θ) = cos θ + (B/A) sin² θ`, normalised so that a surface seen
//!    head-on keeps its Table 2.3 reflectivity (σ = 0 is Lambert).
//!    `s` is [`SimConfig::amplitude_scale`].
//! 2. **The emitted pattern** `L_p` is chosen so that a white wall (`ρ = 1`) perpendicular to the
//!    optical axis at depth 1 m gives exactly the white-wall amplitude `aw_p` of the configured
//!    [`Illumination`] (the Eq 2.5 parabola by default): on that wall `r = |ray_p|` and
//!    `cos θ = 1/|ray_p|` with the ray scaled to z = 1, so `L_p = aw_p · |ray_p|³`. The thesis's
//!    AAT (Eq 2.4) with the thesis's parameters then reads the apparent reflectivity on simulated
//!    frames. Light cannot be negative, so `aw_p` is clamped at
//!    [`SimConfig::illumination_floor`] × the pattern's maximum where the parabola falls below it
//!    (it goes negative in the SR-3000's far corners, spec §6.2).
//! 3. **Scattering** (L1997–2005, optional): light reflected inside the camera (imager → lens →
//!    imager) spreads over the image. Every pixel receives `σ_s ×` a wide normalised blur (three
//!    passes of a separable box filter, O(n), ≈ Gaussian) of the complex image `a · e^{iφ}`. A
//!    close bright object then drags the phase of dark far neighbours towards its own: they
//!    appear too close, as in Fig 2.10.
//! 4. **Amplitude-related range error** (L2141–2149, Fig 2.9, optional [`LowAmplitudeBias`]):
//!    the phase of a weak return (after scattering) is moved towards the camera: dark surfaces
//!    read too close.
//! 5. **Intensity** (Eq 2.3): `B = ambient + Σ sun·ρ + m · a_total`: the constant
//!    [`SimConfig::ambient`] (room light, dark current), sunlight on hits inside a
//!    [`SunRegion`] (L2009–2017, Fig 2.8), and the mean of the modulated light itself
//!    (`m` = [`SimConfig::signal_offset`] ≥ 1, so no sample is negative).
//! 6. **Samples and noise.** The four samples `τk = B − A cos(φ − k·90°)` ([`modulate`]) each
//!    get Gaussian shot noise of variance `g · τk` (gain `g`), are clipped at the full-well level
//!    [`SimConfig::saturation`], and get Gaussian read noise `σ_read`. [`demodulate`] gives
//!    phase, amplitude and intensity; the reported radial range is
//!    [`range_from_phase`]`(φ, R_amb)`, converted to the distance to the image plane as the
//!    SwissRanger driver reports (L1804–1806). So wrap-around, amplitude noise and range noise
//!    all come out of one model. A pixel that sees nothing receives only noise (and scattered
//!    light): random phase, tiny amplitude. Strong sunlight adds shot noise; beyond the full
//!    well (the camera's suppression limit of 400 W/m²/µm, L2013) every sample clips and the
//!    pixel loses its modulation: tiny amplitude, random range. A bright object closer than
//!    the 0.6 m minimum range clips its brighter samples: its range is distorted (L2259–2269).
//! 7. **Driver threshold** (optional, L1853–1855): pixels whose amplitude is below
//!    [`SimConfig::driver_at`] get range 0.
//!
//! Not modelled: ghost images, fixed pattern noise, movement, reflections (L2193–2227).
//!
//! # Calibration of the default noise
//!
//! [`SimConfig::sr3000`] uses `g = 0.06`, `σ_read = 2`, ambient 300 (amplitude units of the
//! driver, in which Â = 12,000 and the thesis's AT values 160 and 240 are given). A
//! 25 %-reflective wall at 3 m then has a centre amplitude of ≈ 330 and a range standard
//! deviation of `σ_r = R_amb σ / (2π √2 A) ≈ 1.7 cm` (`σ² = g B + σ_read²`; measured: 1.6 cm);
//! a white wall at 1 m has ≈ 2 mm at the centre and ≈ 1.3 cm in the dim corners (Fig 2.7c
//! reports per-pixel variances between 5.6·10⁻⁶ and 3.9·10⁻⁴ at 1 m, i.e. 2.4 mm to 2 cm if in
//! m²). The test `noise_calibration` in `tests/it/sim.rs` measures it.

use crate::camera::{demodulate, modulate, phase_from_range, range_from_phase};
use crate::filter::illumination_table;
use crate::{FrameTruth, Illumination, Parabola, TofCamera, TofError, TofFrame};
use pointcloud::{BeamModel, Point3, RangeKind, Real, SensorPose};
use rand::{Rng as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use scene_sim::{HitImage, Scene, trace_image};
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// An axis-aligned box of the world in which surfaces are lit by sunlight (or another strong
/// near-infrared source): a hit inside gets `irradiance × ρ` added to its intensity, which adds
/// shot noise but no modulated light (L2009–2017).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SunRegion {
    /// The box's lower corner, world frame, metres.
    pub min: Point3,
    /// The box's upper corner, world frame, metres.
    pub max: Point3,
    /// The intensity a white surface inside receives, in the camera's amplitude units.
    pub irradiance: Real,
}

impl SunRegion {
    /// Whether `p` lies inside (boundary included).
    pub fn contains(&self, p: &Point3) -> bool {
        (0..3).all(|k| self.min[k] <= p[k] && p[k] <= self.max[k])
    }
}

/// Light scattered inside the camera (L1997–2005): every pixel receives `strength ×` the mean of
/// the complex return over a neighbourhood of about `radius` pixels (three box passes of
/// half-width `radius`).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Scattering {
    /// The fraction of the (blurred) returned light that reaches the pixel, in `[0, 1]`.
    pub strength: Real,
    /// Half-width of each box pass, pixels (≥ 1).
    pub radius: u32,
}

impl Scattering {
    /// The scattering used by the test scenes: 1 % of the light blurred over ≈ 30 pixels
    /// (a sixth of the image width). The thesis shows the effect (Fig 2.10) but gives no
    /// figures; with this strength a white box at 0.8–1.2 m pulls a 10 % wall at 3.5 m beside
    /// it ≈ 0.7 m closer, and the background (3.2–4 m) of the `close-boxes` scene 10–20 cm.
    pub fn sr3000() -> Scattering {
        Scattering { strength: 0.01, radius: 30 }
    }
}

/// The amplitude-related range error (L2141–2149, Fig 2.9): a pixel receiving little modulated
/// light reports its surface too close, by `max_shift · 2^(−A / half_amplitude)` for the
/// received (noise-free) amplitude `A`. The thesis names the effect and its cause (poor
/// near-infrared reflectivity: wood 25 % is fine, asphalt 17 % critical, a tyre 2 % far too
/// dark) but gives no figures; these are ours.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LowAmplitudeBias {
    /// The shift at zero amplitude, metres (≥ 0).
    pub max_shift: Real,
    /// The amplitude at which half of it remains (> 0).
    pub half_amplitude: Real,
}

impl LowAmplitudeBias {
    /// 0.3 m at zero amplitude, halved every 30 amplitude units: a 2 % tyre at 3 m
    /// (amplitude ≈ 27) reads ≈ 16 cm too close, a 25 % wall at 3 m (≈ 330) < 1 mm.
    pub fn sr3000() -> LowAmplitudeBias {
        LowAmplitudeBias { max_shift: 0.3, half_amplitude: 30.0 }
    }

    /// The shift towards the camera at amplitude `a`, metres.
    pub fn shift(&self, a: Real) -> Real {
        self.max_shift * (-a.max(0.0) / self.half_amplitude).exp2()
    }
}

/// Everything the simulator needs. All fields are public; [`SimConfig::validate`] checks them
/// (the simulator does so on construction). Start from [`SimConfig::sr3000`] or
/// [`SimConfig::sr3100`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SimConfig {
    /// The camera: image geometry and modulation frequency.
    pub camera: TofCamera,
    /// The emitted pattern, as the amplitude each pixel sees on a white wall at 1 m (`aw_p`):
    /// by default the Eq 2.5 parabola of the camera model.
    pub illumination: Illumination,
    /// Where the pattern falls below this fraction of its maximum it is clamped to it (light
    /// cannot be negative; the SR-3000 parabola is negative in the far corners). In `(0, 1]`;
    /// 0.04 by default.
    pub illumination_floor: Real,
    /// Multiplies every returned amplitude (1: the pattern is in driver units).
    pub amplitude_scale: Real,
    /// The mean (DC) of the received modulated light per unit of its amplitude (≥ 1: a fully
    /// modulated source has 1).
    pub signal_offset: Real,
    /// Constant intensity added to every pixel (room light, dark current), amplitude units.
    pub ambient: Real,
    /// Shot-noise gain: each sample's noise variance grows by this per unit of its value.
    pub shot_gain: Real,
    /// Read noise of each sample, standard deviation, amplitude units.
    pub read_sigma: Real,
    /// The full-well level of one sample, amplitude units (`None`: never saturates). 65,535 (a
    /// 16-bit sample) by default: a white wall saturates the centre pixels from about 0.6 m,
    /// the SR-3000's minimum range.
    pub saturation: Option<Real>,
    /// Sunlit regions of the world.
    pub sun: Vec<SunRegion>,
    /// Light scattering inside the camera (`None`: off).
    pub scattering: Option<Scattering>,
    /// The amplitude-related range error (L2141–2149, Fig 2.9): dark pixels read too close
    /// (`None`: off).
    pub low_amplitude_bias: Option<LowAmplitudeBias>,
    /// The driver's own amplitude threshold: pixels below it are reported with range 0
    /// (L1853–1855). `None`: AT 0, every pixel reported.
    pub driver_at: Option<Real>,
    /// Surface roughness, the Oren–Nayar facet slope standard deviation in radians (`[0, π/2]`;
    /// 0: Lambertian surfaces, the default). See the module documentation.
    pub roughness: Real,
    /// How far beams are cast, metres (beyond: no surface, only noise). 30 m = four
    /// non-ambiguity ranges at 20 MHz.
    pub cast_range: Real,
}

impl SimConfig {
    /// The SR-3000 (Table 2.1) with the Eq 2.5 parabola Â = 12,000, δ = (88, 61) as emitted
    /// pattern, clamped at 4 % of Â, Lambertian surfaces, no scattering, no sunlight, no driver AT,
    /// the low-amplitude bias of [`LowAmplitudeBias::sr3000`], a 16-bit full well, noise as in
    /// the module documentation, cast to 30 m.
    pub fn sr3000() -> SimConfig {
        SimConfig {
            camera: TofCamera::sr3000(),
            illumination: Illumination::Parabola(Parabola::sr3000()),
            illumination_floor: 0.04,
            amplitude_scale: 1.0,
            signal_offset: 1.0,
            ambient: 300.0,
            shot_gain: 0.06,
            read_sigma: 2.0,
            saturation: Some(65_535.0),
            sun: Vec::new(),
            scattering: None,
            low_amplitude_bias: Some(LowAmplitudeBias::sr3000()),
            driver_at: None,
            roughness: 0.0,
            cast_range: 30.0,
        }
    }

    /// The SR-3100 the thesis's experiments used (L2462): as [`SimConfig::sr3000`] with the
    /// pattern brightest at the image centre, δ = (88, 72).
    pub fn sr3100() -> SimConfig {
        SimConfig {
            camera: TofCamera::sr3100(),
            illumination: Illumination::Parabola(Parabola::sr3100()),
            ..SimConfig::sr3000()
        }
    }

    /// Checks every field: a valid camera and pattern (whose maximum is positive), a floor in
    /// `(0, 1]`, a scale in `(0, 10⁶]`, an offset in `[1, 100]`, finite non-negative ambient
    /// (≤ 10¹²), gain (≤ 10³) and read noise (≤ 10⁶), a positive saturation, sun regions with
    /// ordered finite corners and irradiance in `[0, 10¹²]`, scattering strength in `[0, 1]` with
    /// radius 1–10,000, a finite non-negative driver AT, a low-amplitude bias with shift in
    /// `[0, 10³]` m and half amplitude > 0, a roughness in `[0, π/2]`, a cast range in
    /// `(0, 10⁵]` m.
    pub fn validate(&self) -> Result<(), TofError> {
        self.camera.validate()?;
        let bad = |what: &'static str, why: String| Err(TofError::BadParameter { what, why });
        let within = |v: Real, lo: Real, hi: Real| v.is_finite() && lo <= v && v <= hi;
        let pattern = illumination_table(&self.illumination, &self.camera)?;
        let max = pattern.iter().copied().fold(Real::NEG_INFINITY, Real::max);
        if !(max.is_finite() && max > 0.0) {
            return bad("illumination", format!("maximum {max} (want a positive maximum)"));
        }
        if !(within(self.illumination_floor, 0.0, 1.0) && self.illumination_floor > 0.0) {
            return bad("illumination floor", format!("{} (want (0, 1])", self.illumination_floor));
        }
        if !(within(self.amplitude_scale, 0.0, 1e6) && self.amplitude_scale > 0.0) {
            return bad("amplitude scale", format!("{} (want (0, 1e6])", self.amplitude_scale));
        }
        if !within(self.signal_offset, 1.0, 100.0) {
            return bad("signal offset", format!("{} (want [1, 100])", self.signal_offset));
        }
        if !within(self.ambient, 0.0, 1e12) {
            return bad("ambient light", format!("{} (want [0, 1e12])", self.ambient));
        }
        if !within(self.shot_gain, 0.0, 1e3) {
            return bad("shot-noise gain", format!("{} (want [0, 1e3])", self.shot_gain));
        }
        if !within(self.read_sigma, 0.0, 1e6) {
            return bad("read noise", format!("{} (want [0, 1e6])", self.read_sigma));
        }
        if let Some(full) = self.saturation
            && !(within(full, 0.0, 1e15) && full > 0.0)
        {
            return bad("saturation", format!("{full} (want (0, 1e15])"));
        }
        for (i, s) in self.sun.iter().enumerate() {
            let corners_ok = (0..3)
                .all(|k| s.min[k].is_finite() && s.max[k].is_finite() && s.min[k] <= s.max[k]);
            if !corners_ok || !within(s.irradiance, 0.0, 1e12) {
                return bad(
                    "sun region",
                    format!(
                        "region {i}: {s:?} (want finite ordered corners, irradiance in [0, 1e12])"
                    ),
                );
            }
        }
        if let Some(l) = &self.low_amplitude_bias
            && !(within(l.max_shift, 0.0, 1e3)
                && within(l.half_amplitude, 0.0, 1e9)
                && l.half_amplitude > 0.0)
        {
            return bad(
                "low-amplitude bias",
                format!("{l:?} (want shift in [0, 1e3] m, half amplitude > 0)"),
            );
        }
        if let Some(s) = &self.scattering
            && !(within(s.strength, 0.0, 1.0) && (1..=10_000).contains(&s.radius))
        {
            return bad(
                "scattering",
                format!("{s:?} (want strength in [0, 1], radius 1 to 10,000)"),
            );
        }
        if let Some(t) = self.driver_at
            && !within(t, 0.0, Real::MAX)
        {
            return bad("driver amplitude threshold", format!("{t} (want finite ≥ 0)"));
        }
        if !within(self.roughness, 0.0, std::f64::consts::FRAC_PI_2) {
            return bad("roughness", format!("{} rad (want [0, π/2])", self.roughness));
        }
        if !(within(self.cast_range, 0.0, 1e5) && self.cast_range > 0.0) {
            return bad("cast range", format!("{} m (want (0, 1e5])", self.cast_range));
        }
        Ok(())
    }
}

/// One simulated frame: what the camera reports, what it really saw, and which surface each
/// pixel's beam met (`scene_sim::SurfaceId` numbers; `None`: nothing within the cast range).
#[derive(Clone, Debug, PartialEq)]
pub struct SimulatedFrame {
    /// The reported frame: depth (distance to the image plane, as the SwissRanger), amplitude
    /// and intensity.
    pub frame: TofFrame,
    /// True radial distances and wrap counts.
    pub truth: FrameTruth,
    /// The surface each pixel's beam met.
    pub surface: Vec<Option<u32>>,
}

/// The simulator: a checked [`SimConfig`] with its per-pixel emitted pattern precomputed.
#[derive(Clone, Debug)]
pub struct TofSimulator {
    config: SimConfig,
    /// `L_p` per pixel (row-major).
    emitted: Vec<Real>,
    /// `|ray_p|` (ray scaled to z = 1) per pixel.
    radial_per_depth: Vec<Real>,
}

impl TofSimulator {
    /// A simulator for `config` (validated).
    pub fn new(config: SimConfig) -> Result<TofSimulator, TofError> {
        config.validate()?;
        let aw = illumination_table(&config.illumination, &config.camera)?;
        let max = aw.iter().copied().fold(Real::NEG_INFINITY, Real::max);
        let floor = config.illumination_floor * max;
        let radial_per_depth = config.camera.radial_per_depth();
        let emitted =
            aw.iter().zip(&radial_per_depth).map(|(&a, &k)| a.max(floor) * k * k * k).collect();
        Ok(TofSimulator { config, emitted, radial_per_depth })
    }

    /// The configuration.
    pub fn config(&self) -> &SimConfig {
        &self.config
    }

    /// The emitted pattern `L_p` per pixel (row-major): the white-wall amplitude at 1 m
    /// (clamped at the floor) times `|ray_p|³`.
    pub fn emitted(&self) -> &[Real] {
        &self.emitted
    }

    /// The noise-free hits of every pixel of the camera at `pose` (optical frame) up to the
    /// cast range.
    pub fn trace(&self, scene: &Scene, pose: &SensorPose) -> Result<HitImage, TofError> {
        let m = &pose.world_from_sensor;
        let finite = m.translation.vector.iter().all(|v| v.is_finite())
            && m.rotation.coords.iter().all(|v| v.is_finite());
        if !finite {
            return Err(TofError::BadParameter {
                what: "pose",
                why: format!("{m:?} (want finite)"),
            });
        }
        let c = &self.config.camera;
        Ok(trace_image(
            scene,
            pose,
            &BeamModel::Pinhole(c.intrinsics),
            c.width,
            c.height,
            self.config.cast_range,
        ))
    }

    /// Simulates one frame of `scene` seen from `pose` (optical frame: x right, y down, z
    /// forward), noise drawn from `seed` (the same seed gives the same frame).
    pub fn simulate(
        &self,
        scene: &Scene,
        pose: &SensorPose,
        seed: u64,
    ) -> Result<SimulatedFrame, TofError> {
        let hits = self.trace(scene, pose)?;
        self.render(&hits, seed)
    }

    /// Simulates the same scene at the configured modulation frequency and at `second_hz`
    /// (independent noise): the input of two-frequency unwrapping. The first frame equals
    /// [`TofSimulator::simulate`] with `seed`.
    pub fn simulate_two_frequencies(
        &self,
        scene: &Scene,
        pose: &SensorPose,
        second_hz: Real,
        seed: u64,
    ) -> Result<(SimulatedFrame, SimulatedFrame), TofError> {
        let mut second = self.clone();
        second.config.camera.modulation_hz = second_hz;
        second.config.camera.validate()?;
        let hits = self.trace(scene, pose)?;
        let a = self.render(&hits, seed)?;
        let b = second.render(&hits, scene_sim::sensors::derive_seed(seed, 1))?;
        Ok((a, b))
    }

    /// Turns traced hits (from [`TofSimulator::trace`], or `scene_sim::trace_image` with this
    /// camera's pinhole model and size) into a frame. Fails if the hit image has another size.
    pub fn render(&self, hits: &HitImage, seed: u64) -> Result<SimulatedFrame, TofError> {
        let c = &self.config;
        let cam = &c.camera;
        let n = cam.num_pixels();
        if (hits.width, hits.height) != (cam.width, cam.height) || hits.hits.len() != n {
            return Err(TofError::Mismatch {
                why: format!(
                    "hit image {} × {} with {} hits, camera {} × {}",
                    hits.width,
                    hits.height,
                    hits.hits.len(),
                    cam.width,
                    cam.height
                ),
            });
        }
        let amb = cam.non_ambiguity_range();
        let m = &hits.pose.world_from_sensor;
        let retro = oren_nayar_retro(c.roughness);
        // Direct return as a phasor, its DC, and the background intensity per pixel.
        let mut re = vec![0.0; n];
        let mut im = vec![0.0; n];
        let mut dc = vec![0.0; n];
        let mut background = vec![c.ambient; n];
        let mut truth = FrameTruth { radial: vec![None; n], wraps: vec![0; n] };
        let mut surface = vec![None; n];
        for (i, hit) in hits.hits.iter().enumerate() {
            let Some(hit) = hit else { continue };
            let r = hit.range;
            truth.radial[i] = Some(r as f32);
            truth.wraps[i] = (r / amb).floor().clamp(0.0, 255.0) as u8;
            surface[i] = Some(hit.surface.0);
            let rho = Real::from(hit.reflectivity);
            let cos = hit.incidence_cos.clamp(0.0, 1.0);
            let a = c.amplitude_scale * rho * (cos + retro * (1.0 - cos * cos)) * self.emitted[i]
                / r.max(1e-3).powi(2);
            let (s, co) = phase_from_range(r, amb).sin_cos();
            re[i] = a * co;
            im[i] = a * s;
            dc[i] = c.signal_offset * a;
            if !c.sun.is_empty() {
                let p = m * Point3::from(hit.direction * r);
                for region in &c.sun {
                    if region.contains(&p) {
                        background[i] += region.irradiance * rho;
                    }
                }
            }
        }
        if let Some(s) = c.scattering
            && s.strength > 0.0
        {
            let (w, h) = (cam.width as usize, cam.height as usize);
            for img in [&mut re, &mut im, &mut dc] {
                let blurred = blur(img, w, h, s.radius as usize);
                for (v, b) in img.iter_mut().zip(blurred) {
                    *v += s.strength * b;
                }
            }
        }
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut range = Vec::with_capacity(n);
        let mut amplitude = Vec::with_capacity(n);
        let mut intensity = Vec::with_capacity(n);
        for i in 0..n {
            let a = re[i].hypot(im[i]);
            let mut phase = im[i].atan2(re[i]);
            if let Some(bias) = c.low_amplitude_bias {
                phase -= TAU * bias.shift(a) / amb;
            }
            let mut tau = modulate(phase, a, background[i] + dc[i]);
            for t in &mut tau {
                let shot: Real = rng.sample(StandardNormal);
                let read: Real = rng.sample(StandardNormal);
                *t += (c.shot_gain * t.max(0.0)).sqrt() * shot;
                if let Some(full) = c.saturation {
                    *t = t.min(full);
                }
                *t += c.read_sigma * read;
            }
            let d = demodulate(tau);
            let radial = range_from_phase(d.phase, amb);
            let below_driver_at = c.driver_at.is_some_and(|t| d.amplitude < t);
            let depth = if below_driver_at { 0.0 } else { radial / self.radial_per_depth[i] };
            range.push(depth as f32);
            amplitude.push(d.amplitude as f32);
            intensity.push(d.intensity.max(0.0) as f32);
        }
        let frame =
            TofFrame::new(*cam, RangeKind::Depth, range, amplitude)?.with_intensity(intensity)?;
        Ok(SimulatedFrame { frame, truth, surface })
    }
}

/// `B / A` of the Oren–Nayar model for facet slope deviation `sigma` (radians): the weight of
/// the retro-reflection term `sin² θ` relative to `cos θ` (0 for a Lambertian surface).
pub fn oren_nayar_retro(sigma: Real) -> Real {
    let s2 = sigma * sigma;
    let a = 1.0 - 0.5 * s2 / (s2 + 0.33);
    let b = 0.45 * s2 / (s2 + 0.09);
    b / a
}

/// Three passes of a normalised separable box blur of half-width `radius` (each output is the
/// mean over the in-image part of its window): ≈ a Gaussian of σ ≈ radius, O(n) per pass.
pub(crate) fn blur(img: &[Real], w: usize, h: usize, radius: usize) -> Vec<Real> {
    let mut a = img.to_vec();
    let mut line = Vec::with_capacity(w.max(h));
    for _ in 0..3 {
        for row in 0..h {
            line.clear();
            line.extend_from_slice(&a[row * w..(row + 1) * w]);
            box_line(&line, radius, |col, v| a[row * w + col] = v);
        }
        for col in 0..w {
            line.clear();
            line.extend((0..h).map(|row| a[row * w + col]));
            box_line(&line, radius, |row, v| a[row * w + col] = v);
        }
    }
    a
}

/// The windowed mean of `line` over `[i − radius, i + radius] ∩ [0, len)` for every `i`, by a
/// prefix sum.
fn box_line(line: &[Real], radius: usize, mut out: impl FnMut(usize, Real)) {
    let n = line.len();
    let mut prefix = Vec::with_capacity(n + 1);
    prefix.push(0.0);
    let mut sum = 0.0;
    for &v in line {
        sum += v;
        prefix.push(sum);
    }
    for i in 0..n {
        let lo = i.saturating_sub(radius);
        let hi = (i + radius + 1).min(n);
        out(i, (prefix[hi] - prefix[lo]) / (hi - lo) as Real);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The windowed mean by brute force.
    fn box_line_naive(line: &[Real], radius: usize) -> Vec<Real> {
        (0..line.len())
            .map(|i| {
                let lo = i.saturating_sub(radius);
                let hi = (i + radius + 1).min(line.len());
                line[lo..hi].iter().sum::<Real>() / (hi - lo) as Real
            })
            .collect()
    }

    proptest! {
        #[test]
        fn box_line_matches_brute_force(
            line in proptest::collection::vec(-1e3..1e3f64, 1..60),
            radius in 0usize..80,
        ) {
            let mut fast = vec![0.0; line.len()];
            box_line(&line, radius, |i, v| fast[i] = v);
            for (a, b) in fast.iter().zip(box_line_naive(&line, radius)) {
                prop_assert!((a - b).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn blur_keeps_constants_and_the_mean_roughly() {
        let (w, h) = (17, 11);
        let flat = vec![3.5; w * h];
        assert!(blur(&flat, w, h, 4).iter().all(|v| (v - 3.5).abs() < 1e-12));
        let mut spike = vec![0.0; w * h];
        spike[5 * w + 8] = 1.0;
        let b = blur(&spike, w, h, 2);
        assert!(b.iter().all(|&v| v >= 0.0));
        assert!(b[5 * w + 8] > b[5 * w + 12] && b[5 * w + 12] > 0.0);
    }

    #[test]
    fn pattern_reproduces_the_parabola_on_a_white_wall() {
        let sim = TofSimulator::new(SimConfig::sr3000()).unwrap();
        let cam = sim.config().camera;
        let p = Parabola::sr3000();
        for (col, row) in [(88, 61), (0, 0), (175, 143), (40, 100)] {
            let i = row as usize * 176 + col as usize;
            let k = cam.ray(col, row).norm();
            // White wall at depth 1: r = k, cos θ = 1/k.
            let a = sim.emitted()[i] / k / (k * k);
            let want = p.eval(col as Real, row as Real).max(0.04 * 12_000.0);
            assert!((a - want).abs() < 1e-6 * want, "{col},{row}: {a} vs {want}");
        }
    }
}
