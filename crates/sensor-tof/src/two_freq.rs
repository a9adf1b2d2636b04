//! Two-frequency unwrapping (beyond the thesis): two frames of the same view taken at two
//! modulation frequencies, and per pixel the wrap counts on which both agree (a
//! Chinese-remainder search, as commercial continuous-wave cameras do).
//!
//! # The method
//!
//! A camera modulated at `f` reports `r = d mod R` with `R = c / (2 f)` (spec §1, §6.4), so a
//! pixel's true radial distance is one of `r + n·R`, `n = 0, 1, …`. With two frequencies `f_a`,
//! `f_b` the true distance is a candidate of both lists; every other pair `(n_a, n_b)` disagrees
//! by `|Δn_a·R_a − Δn_b·R_b|` (plus noise), where `Δ` are the differences from the true wrap
//! counts. Per pixel [`unwrap_two_frequencies`] takes the pair with the smallest disagreement
//! among the candidates up to [`TwoFreqConfig::max_range_m`]; if that disagreement is within
//! [`TwoFreqConfig::tolerance_m`] the pixel is output at the weighted mean of the two candidates
//! ([`Combination`]), else dropped. It is [`PixelOutcome::Kept`] when frame `a` had not wrapped
//! (`n_a = 0`), [`PixelOutcome::Unwrapped`] otherwise.
//!
//! On noise-free data a wrong pair disagrees by at least the **candidate separation**
//! ([`candidate_separation`]): the smallest `|Δn_a·R_a − Δn_b·R_b| > 0` that two candidates
//! within `[0, max_range]` can have (a pair is possible iff the spread of `{0, Δn_a·R_a,
//! Δn_b·R_b}` is at most the max range). The choice is right whenever the noise difference
//! `|e_a − e_b|` stays below half of it, so [`TwoFreqConfig::validate`] demands
//! `tolerance < separation / 2`. The max range must stay below the joint non-ambiguity range
//! `c / (2·gcd(f_a, f_b))`, where the separation becomes 0: beyond it distances alias (a surface
//! at 30.5 m reads like one at 0.5 m with 20 + 5 MHz) and no two-frequency method can tell them
//! apart.
//!
//! # Which pair (SR-3000 frequencies, thesis L1916–1924)
//!
//! The SR-3000 offers 5, 6.6, 10, 19, 20, 21 and 30 MHz, calibrated only at 20 MHz (L1920–1922),
//! so one frame is the 20 MHz one (`R_a` = 7.49 m). With the same phase noise `σ_φ` at both
//! frequencies the ranges have noise `σ_φ·R/(2π)`, their difference `σ_φ·√(R_a² + R_b²)/(2π)`;
//! the figure of merit is the separation over `√(R_a² + R_b²)` (how many "phase-noise units"
//! fit in the margin). Computed with [`candidate_separation`]:
//!
//! | second frequency | joint range | separation, max range < 15 m | < 22.5 m | < 30 m | merit at 30 m |
//! |---|---|---|---|---|---|
//! | 5 MHz | 29.98 m | 7.49 m | 7.49 m | 7.49 m | **0.243** |
//! | 6.6 MHz | 749 m | 7.49 m | 7.49 m | 0.227 m | 0.0095 |
//! | 10 MHz | 14.99 m | 7.49 m (merit **0.447**) | — | — | — |
//! | 19 MHz | 150 m | 0.394 m | 0.394 m | 0.394 m | 0.036 |
//! | 21 MHz | 150 m | 0.357 m | 0.357 m | 0.357 m | 0.035 |
//! | 30 MHz | 14.99 m | 2.50 m (merit 0.277) | — | — | — |
//!
//! Up to 15 m, 20 + 10 MHz has the widest margin; up to 22.5 m, 20 + 6.6 MHz; up to 30 m,
//! 20 + 5 MHz, with a margin seven times that of the neighbouring frequencies 19 or 21 MHz,
//! which only pay off beyond 30 m (up to 150 m) with a 0.36–0.39 m margin. The thesis calls
//! more than 15 m rare (L2446–2452), but a hall like its "gates" scene reaches beyond 20 m, and
//! three wraps at 20 MHz need 30 m, so the preset [`TwoFreqConfig::sr3000`] pairs 20 MHz with
//! 5 MHz, max range 29.5 m (below the joint 29.98 m, keeping a margin for noise at the far
//! end).
//!
//! # Tolerance
//!
//! [`TwoFreqConfig::for_pair`] sets the tolerance to three standard deviations of the noise
//! difference, `3·σ_φ·√(R_a² + R_b²)/(2π)`. The preset's phase noise comes from the thesis's
//! accuracy test: per-pixel variance at 1 m up to 3.868·10⁻⁴ m² (L2050–2056, units not stated;
//! read as m²), σ ≈ 2 cm at 20 MHz, i.e. σ_φ = 0.0165 rad; the preset's tolerance is 0.24 m
//! against a 7.49 m separation. A pixel that saw nothing (both phases random) passes with
//! probability about `2·tolerance / R_a` per candidate of the low frequency (6 % for the preset);
//! [`TwoFreqConfig::min_amplitude`] removes most of those.
//!
//! # On the simulated scenes
//!
//! On the six scenes of Table 2.4 simulated at 20 and 5 MHz (the ignored test
//! `scores_on_the_six_scenes` in `tests/it/two_freq.rs`), the preset outputs about as many pixels
//! within 5 cm of the truth as the AAT with unwrapping while discarding a quarter of the pixels;
//! its output has almost no gross errors (more than 1 m off: 1.7 % against the unwrapping AAT's
//! 25 %), and a plain amplitude threshold of 10 on both frames removes the remaining ones
//! (pixels that saw nothing, sunlight). The preset leaves [`TwoFreqConfig::min_amplitude`]
//! unset because the amplitude of a pixel that sees nothing depends on the ambient light; set
//! it to a few times the camera's amplitude noise.
//!
//! Not covered: distances within the noise of 0 (a phase wrapping below 0 reads near `R`) and
//! of the max range are dropped; the tolerance is one value for every pixel although real noise
//! grows as the amplitude falls.

use crate::{FilterOutput, OutcomeCounts, PixelOutcome, RayTables, TofCamera, TofError, TofFrame};
use pointcloud::{RangeKind, Real};
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// The most candidates per frequency a configuration may need (`max_range / R` of the higher
/// frequency); bounds the per-pixel search.
pub const MAX_WRAPS: usize = 1000;

/// The phase noise (standard deviation, radians) of the preset: σ ≈ 2 cm at 20 MHz, the
/// largest per-pixel spread of the thesis's accuracy test at 1 m (L2050–2056).
pub const SR3000_PHASE_NOISE_RAD: Real = 0.0165;

/// How the two candidate distances of an accepted pixel are combined.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Combination {
    /// Inverse-variance weights under equal phase noise `∝ 1/amplitude`: the range noise is
    /// `∝ R / a`, so weights `(a / R)²` (default). The high frequency dominates.
    InverseVariance,
    /// Weights proportional to the amplitudes.
    Amplitude,
    /// Frame `a`'s candidate only (e.g. the calibrated 20 MHz frame).
    FirstFrame,
}

/// The parameters of two-frequency unwrapping. Build with [`TwoFreqConfig::sr3000`] or
/// [`TwoFreqConfig::for_pair`]; [`TwoFreqConfig::validate`] checks every field and the pair.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TwoFreqConfig {
    /// Modulation frequency of frame `a` (the reference: `Kept` means `a` had not wrapped), Hz.
    pub frequency_a_hz: Real,
    /// Modulation frequency of frame `b`, Hz.
    pub frequency_b_hz: Real,
    /// The largest disagreement `|d_a − d_b|` of the chosen candidates that is accepted, metres.
    pub tolerance_m: Real,
    /// Candidates beyond this radial distance are not considered, metres. Below the joint
    /// non-ambiguity range of the pair.
    pub max_range_m: Real,
    /// A plain amplitude threshold both frames must exceed (`None`: no threshold).
    pub min_amplitude: Option<Real>,
    /// How the two candidates are combined.
    pub combination: Combination,
}

/// The smallest disagreement `|Δn_a·R_a − Δn_b·R_b| > 0` that a wrong pair of wrap counts can
/// have on noise-free data when every candidate lies in `[0, max_range_m]` (0 when the max
/// range reaches the joint non-ambiguity range of the pair). A pair of wrap-count differences
/// is possible iff the spread of `{0, Δn_a·R_a, Δn_b·R_b}` is at most `max_range_m`.
///
/// Fails on frequencies outside [1 kHz, 10 GHz], a max range that is not finite and positive,
/// or one needing more than [`MAX_WRAPS`] candidates per frequency.
pub fn candidate_separation(
    frequency_a_hz: Real,
    frequency_b_hz: Real,
    max_range_m: Real,
) -> Result<Real, TofError> {
    let (ra, rb) = check_pair(frequency_a_hz, frequency_b_hz, max_range_m)?;
    Ok(separation(ra, rb, max_range_m))
}

fn check_pair(fa: Real, fb: Real, max_range: Real) -> Result<(Real, Real), TofError> {
    let bad = |what: &'static str, why: String| Err(TofError::BadParameter { what, why });
    for f in [fa, fb] {
        if !(1e3..=1e10).contains(&f) {
            return bad("modulation frequency", format!("{f} Hz (want 1 kHz to 10 GHz)"));
        }
    }
    if !(max_range.is_finite() && max_range > 0.0) {
        return bad("max range", format!("{max_range} m (want finite > 0)"));
    }
    let (ra, rb) = (crate::non_ambiguity_range(fa), crate::non_ambiguity_range(fb));
    if max_range / ra.min(rb) > MAX_WRAPS as Real {
        return bad(
            "max range",
            format!(
                "{max_range} m spans more than {MAX_WRAPS} non-ambiguity ranges of {} m",
                ra.min(rb)
            ),
        );
    }
    Ok((ra, rb))
}

/// [`candidate_separation`] after the checks: per `Δn_a ≥ 0` (the pairs are symmetric) the
/// feasible `Δn_b` form an interval, and the closest one to `Δn_a·R_a / R_b` inside it is the
/// best (the disagreement is convex in `Δn_b`).
fn separation(ra: Real, rb: Real, max_range: Real) -> Real {
    let mut best = Real::INFINITY;
    let na = (max_range / ra).floor() as i64;
    for dn in 0..=na {
        let x = dn as Real * ra;
        // spread{0, x, y} ≤ D  ⟺  y ∈ [x − D, D] for x ≥ 0.
        let lo = ((x - max_range) / rb).ceil() as i64;
        let hi = (max_range / rb).floor() as i64;
        if lo > hi {
            continue;
        }
        let near = ((x / rb).round() as i64).clamp(lo, hi);
        for dm in [near - 1, near, near + 1] {
            if (dn, dm) == (0, 0) || dm < lo || dm > hi {
                continue;
            }
            best = best.min((x - dm as Real * rb).abs());
        }
    }
    best
}

impl TwoFreqConfig {
    /// The preset for the SR-3000 (module doc): 20 MHz (frame `a`) + 5 MHz (frame `b`), max
    /// range 29.5 m, tolerance from [`SR3000_PHASE_NOISE_RAD`] (≈ 0.24 m), no amplitude
    /// threshold, inverse-variance combination.
    pub fn sr3000() -> TwoFreqConfig {
        TwoFreqConfig::for_pair(20e6, 5e6, 29.5, SR3000_PHASE_NOISE_RAD)
            .expect("the preset pair is valid")
    }

    /// A configuration for frames at `frequency_a_hz` and `frequency_b_hz` with candidates up to
    /// `max_range_m` and a phase noise of `phase_noise_rad` (standard deviation, the same at
    /// both frequencies): tolerance `3·σ_φ·√(R_a² + R_b²)/(2π)`, no amplitude threshold,
    /// inverse-variance combination. Fails if the result does not validate (in particular if the
    /// noise is too large for the pair's separation).
    pub fn for_pair(
        frequency_a_hz: Real,
        frequency_b_hz: Real,
        max_range_m: Real,
        phase_noise_rad: Real,
    ) -> Result<TwoFreqConfig, TofError> {
        if !(phase_noise_rad.is_finite() && phase_noise_rad >= 0.0) {
            return Err(TofError::BadParameter {
                what: "phase noise",
                why: format!("{phase_noise_rad} rad (want finite ≥ 0)"),
            });
        }
        let (ra, rb) = check_pair(frequency_a_hz, frequency_b_hz, max_range_m)?;
        let config = TwoFreqConfig {
            frequency_a_hz,
            frequency_b_hz,
            tolerance_m: 3.0 * phase_noise_rad * ra.hypot(rb) / TAU,
            max_range_m,
            min_amplitude: None,
            combination: Combination::InverseVariance,
        };
        config.validate()?;
        Ok(config)
    }

    /// Checks every field: frequencies in [1 kHz, 10 GHz] and distinct, a finite positive max
    /// range of at most [`MAX_WRAPS`] non-ambiguity ranges, a finite tolerance ≥ 0 and below
    /// half the [`candidate_separation`] (so the best pair is unique), a finite amplitude
    /// threshold ≥ 0.
    pub fn validate(&self) -> Result<(), TofError> {
        let bad = |what: &'static str, why: String| Err(TofError::BadParameter { what, why });
        let (fa, fb) = (self.frequency_a_hz, self.frequency_b_hz);
        let (ra, rb) = check_pair(fa, fb, self.max_range_m)?;
        if (fa - fb).abs() <= 1e-9 * fa.max(fb) {
            return bad("modulation frequencies", format!("{fa} Hz twice (want two)"));
        }
        if !(self.tolerance_m.is_finite() && self.tolerance_m >= 0.0) {
            return bad("tolerance", format!("{} m (want finite ≥ 0)", self.tolerance_m));
        }
        let sep = separation(ra, rb, self.max_range_m);
        if 2.0 * self.tolerance_m >= sep {
            return bad(
                "tolerance",
                format!(
                    "{} m for {fa} + {fb} Hz up to {} m, where wrong candidates come within \
                     {sep} m (want tolerance < half of that; lower the max range below the \
                     joint non-ambiguity range or the tolerance)",
                    self.tolerance_m, self.max_range_m
                ),
            );
        }
        if let Some(t) = self.min_amplitude
            && !(t.is_finite() && t >= 0.0)
        {
            return bad("minimum amplitude", format!("{t} (want finite ≥ 0)"));
        }
        Ok(())
    }

    /// The non-ambiguity ranges `(R_a, R_b)` of the pair, metres.
    pub fn non_ambiguity_ranges(&self) -> (Real, Real) {
        (
            crate::non_ambiguity_range(self.frequency_a_hz),
            crate::non_ambiguity_range(self.frequency_b_hz),
        )
    }
}

/// The choice for one pixel: the wrap counts of frames `a` and `b` with the smallest
/// disagreement, or `None` if no candidate pair lies within the max range.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct WrapChoice {
    /// Wrap count of frame `a`.
    pub wraps_a: u32,
    /// Wrap count of frame `b`.
    pub wraps_b: u32,
    /// `|d_a − d_b|`, metres.
    pub disagreement: Real,
}

/// The candidate search of one pixel: radial ranges `ra ∈ [0, R_a)`, `rb ∈ [0, R_b)`, candidates
/// `r + n·R ≤ max_range`. Iterates over the candidates of the frequency with the longer
/// non-ambiguity range (fewer of them) and takes for each the closest feasible candidate of the
/// other (convexity), so at most `⌊max_range / R_long⌋ + 1` steps. Ties go to the nearer
/// distance. `None` also for inputs outside the domain (negative or non-finite values, more
/// than [`MAX_WRAPS`] candidates).
pub fn choose_wraps(
    ra: Real,
    rb: Real,
    non_ambiguity_a: Real,
    non_ambiguity_b: Real,
    max_range: Real,
) -> Option<WrapChoice> {
    let sane = non_ambiguity_a > 0.0
        && non_ambiguity_b > 0.0
        && non_ambiguity_a.is_finite()
        && non_ambiguity_b.is_finite()
        && max_range / non_ambiguity_a.min(non_ambiguity_b) <= MAX_WRAPS as Real;
    if !sane {
        return None;
    }
    Search::new(non_ambiguity_a, non_ambiguity_b, max_range).choose(ra, rb)
}

/// The per-configuration constants of the candidate search (`L`: the frequency with the longer
/// non-ambiguity range, `S`: the other), so a pixel costs no division.
#[derive(Copy, Clone, Debug)]
struct Search {
    a_long: bool,
    big_l: Real,
    inv_l: Real,
    big_s: Real,
    inv_s: Real,
    max_range: Real,
}

impl Search {
    /// Assumes positive finite non-ambiguity ranges and at most [`MAX_WRAPS`] candidates.
    fn new(non_ambiguity_a: Real, non_ambiguity_b: Real, max_range: Real) -> Search {
        let a_long = non_ambiguity_a >= non_ambiguity_b;
        let (big_l, big_s) = if a_long {
            (non_ambiguity_a, non_ambiguity_b)
        } else {
            (non_ambiguity_b, non_ambiguity_a)
        };
        Search { a_long, big_l, inv_l: 1.0 / big_l, big_s, inv_s: 1.0 / big_s, max_range }
    }

    /// [`choose_wraps`] for radial ranges `ra`, `rb`.
    #[inline]
    fn choose(&self, ra: Real, rb: Real) -> Option<WrapChoice> {
        let Search { a_long, big_l, inv_l, big_s, inv_s, max_range } = *self;
        let (rl, rs) = if a_long { (ra, rb) } else { (rb, ra) };
        if !((0.0..=max_range).contains(&rl) && (0.0..=max_range).contains(&rs)) {
            return None;
        }
        // Truncating casts of non-negative values are floors (and cheaper than `floor` and
        // `round`, which are library calls on baseline x86-64).
        let ns_max = ((max_range - rs) * inv_s) as u32;
        let nl_max = ((max_range - rl) * inv_l) as u32;
        let mut best: Option<(u32, u32, Real)> = None;
        for m in 0..=nl_max {
            let dl = rl + m as Real * big_l;
            if dl > max_range {
                break;
            }
            let mut n = (((dl - rs) * inv_s + 0.5).max(0.0) as u32).min(ns_max);
            if rs + n as Real * big_s > max_range {
                // Rounding at the boundary.
                let Some(lower) = n.checked_sub(1) else { continue };
                n = lower;
            }
            let e = (dl - (rs + n as Real * big_s)).abs();
            if best.is_none_or(|b| e < b.2) {
                best = Some((m, n, e));
            }
        }
        best.map(|(m, n, e)| {
            let (wraps_a, wraps_b) = if a_long { (m, n) } else { (n, m) };
            WrapChoice { wraps_a, wraps_b, disagreement: e }
        })
    }
}

/// Two-frequency unwrapping prepared for one camera geometry and range kind: the ray tables
/// (for depth frames) and the validated configuration.
#[derive(Clone, Debug)]
pub struct TwoFreqUnwrapper {
    camera: TofCamera,
    kind: RangeKind,
    config: TwoFreqConfig,
    radial_per_depth: Vec<f32>,
}

impl TwoFreqUnwrapper {
    /// Prepares `config` for frames of `camera`'s geometry (its modulation frequency is ignored:
    /// the frames carry theirs) with ranges of `kind`.
    pub fn new(
        camera: &TofCamera,
        kind: RangeKind,
        config: &TwoFreqConfig,
    ) -> Result<TwoFreqUnwrapper, TofError> {
        camera.validate()?;
        config.validate()?;
        Ok(TwoFreqUnwrapper {
            camera: *camera,
            kind,
            config: *config,
            radial_per_depth: RayTables::new(camera).radial_per_depth,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &TwoFreqConfig {
        &self.config
    }

    /// Unwraps the pair (`a` at [`TwoFreqConfig::frequency_a_hz`], `b` at
    /// [`TwoFreqConfig::frequency_b_hz`]) into `out` (buffers reused). Fails on frames of
    /// another geometry or range kind than prepared for, or of other frequencies than
    /// configured.
    pub fn apply(
        &self,
        a: &TofFrame,
        b: &TofFrame,
        out: &mut FilterOutput,
    ) -> Result<(), TofError> {
        check_frames(a, b, &self.config)?;
        if !same_geometry(a.camera(), &self.camera) || a.kind() != self.kind {
            return Err(TofError::Mismatch {
                why: format!(
                    "frames {} × {} {:?}, unwrapper prepared for {} × {} {:?}",
                    a.camera().width,
                    a.camera().height,
                    a.kind(),
                    self.camera.width,
                    self.camera.height,
                    self.kind
                ),
            });
        }
        let table = &self.radial_per_depth;
        run(a, b, &self.config, out, |i| table[i] as Real);
        Ok(())
    }

    /// [`TwoFreqUnwrapper::apply`] into a new output.
    pub fn run(&self, a: &TofFrame, b: &TofFrame) -> Result<FilterOutput, TofError> {
        let mut out = FilterOutput::default();
        self.apply(a, b, &mut out)?;
        Ok(out)
    }
}

/// Unwraps the frames `a` and `b` of one view at two modulation frequencies into `out` (module
/// doc): per pixel the candidate pair with the smallest disagreement within
/// [`TwoFreqConfig::max_range_m`]; accepted iff the disagreement is at most
/// [`TwoFreqConfig::tolerance_m`], both ranges are measured (> 0) and both amplitudes exceed
/// [`TwoFreqConfig::min_amplitude`]. Output radial range: the combined distance; outcome
/// `Kept` if frame `a` had not wrapped, `Unwrapped` if it had, `Dropped` if not accepted.
///
/// Fails if the configuration is invalid, the frames differ in image geometry (size,
/// intrinsics) or range kind, or their modulation frequencies are not the configured ones
/// (relative difference above 10⁻⁶). Allocates nothing beyond `out`'s buffers; per depth pixel
/// one square root (use [`TwoFreqUnwrapper`] to precompute them).
pub fn unwrap_two_frequencies(
    a: &TofFrame,
    b: &TofFrame,
    config: &TwoFreqConfig,
    out: &mut FilterOutput,
) -> Result<(), TofError> {
    config.validate()?;
    check_frames(a, b, config)?;
    let camera = *a.camera();
    let w = camera.width as usize;
    run(a, b, config, out, |i| camera.ray((i % w) as u32, (i / w) as u32).norm());
    Ok(())
}

fn same_geometry(a: &TofCamera, b: &TofCamera) -> bool {
    (a.width, a.height, a.intrinsics) == (b.width, b.height, b.intrinsics)
}

fn check_frames(a: &TofFrame, b: &TofFrame, config: &TwoFreqConfig) -> Result<(), TofError> {
    let (ca, cb) = (a.camera(), b.camera());
    if !same_geometry(ca, cb) {
        return Err(TofError::Mismatch {
            why: format!(
                "frame a {} × {} ({:?}), frame b {} × {} ({:?})",
                ca.width, ca.height, ca.intrinsics, cb.width, cb.height, cb.intrinsics
            ),
        });
    }
    if a.kind() != b.kind() {
        return Err(TofError::Mismatch {
            why: format!("frame a has {:?} ranges, frame b {:?}", a.kind(), b.kind()),
        });
    }
    let close = |f: Real, g: Real| (f - g).abs() <= 1e-6 * g;
    if !close(ca.modulation_hz, config.frequency_a_hz)
        || !close(cb.modulation_hz, config.frequency_b_hz)
    {
        return Err(TofError::Mismatch {
            why: format!(
                "frames at {} Hz and {} Hz, configuration for {} Hz and {} Hz",
                ca.modulation_hz, cb.modulation_hz, config.frequency_a_hz, config.frequency_b_hz
            ),
        });
    }
    Ok(())
}

/// The per-pixel loop; `radial_per_depth(i)` is only called for depth frames.
fn run(
    a: &TofFrame,
    b: &TofFrame,
    config: &TwoFreqConfig,
    out: &mut FilterOutput,
    radial_per_depth: impl Fn(usize) -> Real,
) {
    let n = a.range().len();
    out.reset(n);
    let (big_a, big_b) = config.non_ambiguity_ranges();
    let search = Search::new(big_a, big_b, config.max_range_m);
    let (inv_a2, inv_b2) = ((big_a * big_a).recip(), (big_b * big_b).recip());
    let min_amp = config.min_amplitude.unwrap_or(Real::NEG_INFINITY);
    let depth = a.kind() == RangeKind::Depth;
    let mut counts = OutcomeCounts::default();
    for i in 0..n {
        let (ra, rb) = (a.range()[i] as Real, b.range()[i] as Real);
        let (aa, ab) = (a.amplitude()[i] as Real, b.amplitude()[i] as Real);
        if ra <= 0.0 || rb <= 0.0 || aa <= min_amp || ab <= min_amp {
            counts.dropped += 1;
            continue;
        }
        let k = if depth { radial_per_depth(i) } else { 1.0 };
        let (ra, rb) = (ra * k, rb * k);
        let Some(choice) = search.choose(ra, rb) else {
            counts.dropped += 1;
            continue;
        };
        if choice.disagreement > config.tolerance_m {
            counts.dropped += 1;
            continue;
        }
        let da = ra + choice.wraps_a as Real * big_a;
        let db = rb + choice.wraps_b as Real * big_b;
        let (wa, wb) = match config.combination {
            Combination::InverseVariance => (aa * aa * inv_a2, ab * ab * inv_b2),
            Combination::Amplitude => (aa, ab),
            Combination::FirstFrame => (1.0, 0.0),
        };
        let d = if wa + wb > 0.0 && (wa + wb).is_finite() {
            (wa * da + wb * db) / (wa + wb)
        } else {
            0.5 * (da + db)
        };
        out.radial[i] = d as f32;
        if choice.wraps_a == 0 {
            out.outcomes[i] = PixelOutcome::Kept;
            counts.kept += 1;
        } else {
            out.outcomes[i] = PixelOutcome::Unwrapped;
            counts.unwrapped += 1;
        }
    }
    out.counts = counts;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn preset_is_valid_and_matches_the_doc() {
        let c = TwoFreqConfig::sr3000();
        c.validate().unwrap();
        assert!((c.tolerance_m - 0.24).abs() < 0.01, "{}", c.tolerance_m);
        let sep = candidate_separation(20e6, 5e6, 29.5).unwrap();
        assert!((sep - 7.4948).abs() < 1e-3, "{sep}");
        // Beyond the joint non-ambiguity range (29.98 m) wrong pairs coincide.
        assert_eq!(candidate_separation(20e6, 5e6, 30.5).unwrap(), 0.0);
        assert!(TwoFreqConfig::for_pair(20e6, 5e6, 30.5, SR3000_PHASE_NOISE_RAD).is_err());
    }
}
