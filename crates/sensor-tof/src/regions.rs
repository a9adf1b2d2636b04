//! Region unwrapping: unwrap only where the frame agrees (beyond the thesis).
//!
//! The thesis's AAT (Eq 2.4, §2.5.5) judges every pixel alone by its apparent reflectivity
//! `a · r² / aw`, and its unwrapping (L2404–2458) trusts every flag: a dark near surface is
//! flagged and unwrapped as if it were a bright far one. Here a pixel is judged with the
//! surface it belongs to:
//!
//! 1. **Regions.** The range image is segmented into smooth regions: two 4-neighbours join when
//!    their ranges agree *modulo the non-ambiguity range* `R` (a surface that crosses `R`
//!    reads `R − ε` on one side and `ε` on the other: it joins with a relative wrap step of
//!    one) and their amplitudes differ by at most [`RegionConfig::max_amplitude_ratio`]. The
//!    flood fill gives every pixel a wrap count relative to its region, so a floor that runs
//!    through several multiples of `R` is unwrapped as one surface. Where two paths through a
//!    region give a pixel different wrap counts (a loop that does not close), the region is
//!    inconsistent.
//! 2. **One wrap count per region.** For each absolute offset `K` of the region, a pixel
//!    supports `K` when its apparent reflectivity at the unwrapped range lies in the plausible
//!    band `[T, B · T]` (`T` the AAT threshold, `B` = [`RegionConfig::max_brightness`]): too
//!    dark for the range means wrapped (the AAT's criterion), too bright for the range means
//!    the unwrapping went too far (amplitude ∝ reflectivity · cos / r²). The region takes the
//!    offset most of its pixels support, if that share is at least
//!    [`RegionConfig::min_support`] and beats the runner-up by [`RegionConfig::min_margin`];
//!    then every pixel of the region is output at that offset, also the dark spots the AAT
//!    alone would have flagged.
//! 3. **Drop what stays ambiguous**: regions smaller than [`RegionConfig::min_region_pixels`]
//!    (noise: sunlight, pixels that saw nothing, grazing edges), inconsistent regions, regions
//!    without a clear winner, and pixels whose absolute wrap count exceeds
//!    [`RegionConfig::max_wraps`].
//!
//! What it cannot fix: range errors that are not wrap-around (the scattering bias of a dim
//! surface beside a bright one, noise beyond the tolerance) keep their region's decision, and
//! a region that is plausible both as measured and unwrapped (a wall whose reflectivity is
//! inside the band at either range, which happens when `R` is short against the ranges) is
//! dropped.
//!
//! # Complexity
//!
//! `O(n)` time and memory for `n` pixels: one flood fill, one pass per offset over each region.

use crate::filter::illumination_table;
use crate::{
    AatConfig, AatRange, FilterOutput, NegativeIllumination, PixelOutcome, RayTables, TofCamera,
    TofError, TofFrame,
};
use pointcloud::{RangeKind, Real};
use serde::{Deserialize, Serialize};

/// The largest accepted [`RegionConfig::max_wraps`].
pub const MAX_WRAPS: u8 = 8;

/// The parameters of [`RegionUnwrapper`]. [`RegionConfig::new`] gives the defaults for an AAT
/// configuration; [`RegionConfig::validate`] checks every field.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RegionConfig {
    /// The per-pixel evidence: illumination `aw_p`, threshold `T` and which range (Eq 2.4).
    pub aat: AatConfig,
    /// Two neighbours join when their ranges (modulo `R`) differ by at most this, metres
    /// (default 0.05: the noise of a dim SR-3000 pixel at 5–7 m is 2–3 cm).
    pub join_absolute_m: Real,
    /// … plus this share of the larger reported range (default 0.03: the range step between
    /// neighbouring pixels of an oblique surface, as in [`crate::spatial`]).
    pub join_relative: Real,
    /// Two neighbours also join only when their step (modulo `R`) continues the step before
    /// or after them along the same line within this, metres (a second difference; `None`:
    /// off, the default; 0.005 suits the millimetre noise of the ifm O3R). A depth jump that
    /// happens to match a multiple of `R` seldom continues the surface's slope on either side.
    pub join_curvature_m: Option<Real>,
    /// Two neighbours join only when their amplitudes differ by at most this factor (≥ 1,
    /// default 2): a near bright object does not join a far dim wall that happens to read the
    /// same range modulo `R`.
    pub max_amplitude_ratio: Real,
    /// Regions with fewer pixels are dropped (≥ 1, default 20).
    pub min_region_pixels: usize,
    /// A pixel supports an offset only when its apparent reflectivity there is at least this
    /// times `T` (> 0, default 1: the AAT's own criterion; below 1 a dark region is plausible
    /// both as measured and unwrapped, and the fit or its border must decide).
    pub min_brightness: Real,
    /// `B`: a pixel supports an offset when its apparent reflectivity there is at most `B · T`
    /// (> 1, default 10, i.e. twice a white wall with the thesis's `T` = 0.2: surfaces at
    /// grazing incidence and the illumination model's errors leave room above 1).
    pub max_brightness: Real,
    /// The share of a region's pixels that must support its offset (in (0, 1], default 0.5).
    pub min_support: Real,
    /// … and by how much that share must exceed the runner-up's (in [0, 1], default 0.2).
    pub min_margin: Real,
    /// A region's offset is also chosen by how well its amplitude follows `1/r²`: the offset
    /// whose `ln(a · u²)` has the smallest median absolute deviation over the region wins if
    /// that spread is at most this share of the next smallest (in (0, 1]; `None`: off; default
    /// 0.7) and its band support is at least half [`RegionConfig::min_support`]. When this and
    /// the band support both decide and disagree, the region is dropped.
    pub spread_ratio: Option<Real>,
    /// A decided region is dropped when at least this many of its border edges to a larger
    /// decided region join that region's ranges only at another offset, and more than join at
    /// its own (`None`: off; default 3): its neighbours say it was unwrapped wrongly.
    pub boundary_edges: Option<usize>,
    /// The highest absolute wrap count output (default 1: pixels wrapped more than once are
    /// dropped, as the thesis's low AT does, L2446–2452).
    pub max_wraps: u8,
    /// Regions whose loops disagree on more than this share of their joins are dropped (in
    /// [0, 1], default 0.01).
    pub max_conflicts: Real,
    /// Pixels with amplitude at or below this are dropped before segmentation (the thesis's low
    /// AT, L2446–2452; default `None`).
    pub low_at: Option<Real>,
    /// Drop output pixels whose local range noise exceeds this, metres (`None`: off). The noise
    /// is estimated from the neighbours: the mean square of the second differences
    /// `u_i − (u_l + u_r)/2` (and vertically) of the unwrapped ranges within the region, over a
    /// `(2·`[`RegionConfig::noise_radius`]` + 1)²` window, divided by 1.5 (a plane's second
    /// difference is its noise, with variance `1.5 σ²`). Default 0.02: with a 5 cm tolerance a
    /// pixel of σ = 2 cm is wrong 1.2 % of the time.
    pub max_noise_m: Option<Real>,
    /// The half-size of the noise window (1 to 7, default 2: 5 × 5).
    pub noise_radius: u32,
    /// Passes that give a dropped measured pixel (of a small region, say) the wrap count of
    /// its output 8-neighbours, when at least two agree within
    /// [`RegionConfig::absorb_tolerance_m`] (plus the relative join tolerance) and none
    /// disagrees (default 0: off). Each pass grows the output by one pixel.
    pub absorb_passes: u32,
    /// The absolute tolerance of that agreement, metres (default 0.02).
    pub absorb_tolerance_m: Real,
    /// Drop pixels that light scattered inside the camera may have pulled too close (`None`:
    /// off, the default).
    pub scattering: Option<ScatterGate>,
}

/// Light scattered inside the camera (thesis L1997–2005, Fig 2.10) adds to every pixel a blur
/// of the whole frame's returns, which pulls a dim pixel beside bright ones towards their
/// range. The gate estimates it from the frame: `strength ×` three box blurs of half-width
/// `radius` of the complex image `a · e^{iφ}` (the camera's scattering, from a calibration),
/// and drops a pixel whose estimated scattered amplitude exceeds `max_share` of its own
/// (beyond the thesis).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ScatterGate {
    /// The fraction of the blurred light that reaches a pixel, in (0, 1].
    pub strength: Real,
    /// Half-width of each box pass, pixels (1 to 1000).
    pub radius: u32,
    /// The largest tolerated share of scattered to measured amplitude (> 0): with `s/a` the
    /// phase errs by up to about `s/a` radians, i.e. `R · s/a / 2π` metres.
    pub max_share: Real,
}

impl ScatterGate {
    /// The simulator's SR-3000 scattering ([`crate::sim::Scattering::sr3000`]: 1 %, radius
    /// 30) with a share of 0.02 (at most 2.4 cm of error at R = 7.5 m).
    pub fn sr3000() -> ScatterGate {
        ScatterGate { strength: 0.01, radius: 30, max_share: 0.02 }
    }
}

impl RegionConfig {
    /// The defaults (see each field) around the AAT configuration `aat`.
    pub fn new(aat: AatConfig) -> RegionConfig {
        RegionConfig {
            aat,
            join_absolute_m: 0.05,
            join_relative: 0.03,
            join_curvature_m: None,
            max_amplitude_ratio: 2.0,
            min_region_pixels: 20,
            min_brightness: 1.0,
            max_brightness: 10.0,
            min_support: 0.5,
            min_margin: 0.2,
            spread_ratio: Some(0.7),
            boundary_edges: Some(3),
            max_wraps: 1,
            max_conflicts: 0.01,
            low_at: None,
            max_noise_m: Some(0.02),
            noise_radius: 2,
            absorb_passes: 0,
            absorb_tolerance_m: 0.02,
            scattering: None,
        }
    }

    /// The parameters tuned on the six simulated Table 2.4 scenes of seed 1 (`patchnav
    /// experiment tof` prints the tuning; SR-3000/3100 amplitudes): [`RegionConfig::new`] with
    /// brightness ≤ 6 T, a low AT of 200, three absorbing passes and the scattering gate of the
    /// simulated camera ([`ScatterGate::sr3000`]). The demo's mode.
    pub fn simulated_sr3000(aat: AatConfig) -> RegionConfig {
        RegionConfig {
            max_brightness: 6.0,
            low_at: Some(200.0),
            absorb_passes: 3,
            scattering: Some(ScatterGate::sr3000()),
            ..RegionConfig::new(aat)
        }
    }

    /// Checks every field (the AAT's own fields are checked by [`RegionUnwrapper::new`]).
    pub fn validate(&self) -> Result<(), TofError> {
        let bad = |what: &'static str, why: String| Err(TofError::BadParameter { what, why });
        let unit = |v: Real| v.is_finite() && (0.0..=1.0).contains(&v);
        if !(self.aat.threshold.is_finite() && self.aat.threshold > 0.0) {
            return bad("AAT", format!("{} (want finite > 0)", self.aat.threshold));
        }
        if !(self.join_absolute_m.is_finite() && self.join_absolute_m >= 0.0) {
            return bad("join tolerance", format!("{} m (want finite ≥ 0)", self.join_absolute_m));
        }
        if !(self.join_relative.is_finite() && (0.0..0.5).contains(&self.join_relative)) {
            return bad(
                "relative join tolerance",
                format!("{} (want in [0, 0.5))", self.join_relative),
            );
        }
        if let Some(t) = self.join_curvature_m
            && !(t.is_finite() && t >= 0.0)
        {
            return bad("join curvature", format!("{t} m (want finite ≥ 0)"));
        }
        if !(self.max_amplitude_ratio.is_finite() && self.max_amplitude_ratio >= 1.0) {
            return bad(
                "amplitude ratio",
                format!("{} (want finite ≥ 1)", self.max_amplitude_ratio),
            );
        }
        if self.min_region_pixels == 0 {
            return bad("minimum region size", "0 (want ≥ 1)".into());
        }
        if !(self.max_brightness.is_finite() && self.max_brightness > 1.0) {
            return bad("maximum brightness", format!("{} (want finite > 1)", self.max_brightness));
        }
        if !(unit(self.min_support) && self.min_support > 0.0) {
            return bad("minimum support", format!("{} (want in (0, 1])", self.min_support));
        }
        if !unit(self.min_margin) {
            return bad("minimum margin", format!("{} (want in [0, 1])", self.min_margin));
        }
        if let Some(r) = self.spread_ratio
            && !(unit(r) && r > 0.0)
        {
            return bad("spread ratio", format!("{r} (want in (0, 1])"));
        }
        if self.max_wraps > MAX_WRAPS {
            return bad("maximum wraps", format!("{} (want 0 to {MAX_WRAPS})", self.max_wraps));
        }
        if !unit(self.max_conflicts) {
            return bad("maximum conflicts", format!("{} (want in [0, 1])", self.max_conflicts));
        }
        if let Some(t) = self.low_at
            && !(t.is_finite() && t >= 0.0)
        {
            return bad("low amplitude threshold", format!("{t} (want finite ≥ 0)"));
        }
        if let Some(t) = self.max_noise_m
            && !(t.is_finite() && t > 0.0)
        {
            return bad("maximum noise", format!("{t} m (want finite > 0)"));
        }
        if !(self.min_brightness.is_finite() && self.min_brightness > 0.0)
            || self.min_brightness >= self.max_brightness
        {
            return bad(
                "minimum brightness",
                format!("{} (want finite > 0 and below the maximum)", self.min_brightness),
            );
        }
        if self.absorb_passes > 100 {
            return bad("absorb passes", format!("{} (want 0 to 100)", self.absorb_passes));
        }
        if !(self.absorb_tolerance_m.is_finite() && self.absorb_tolerance_m >= 0.0) {
            return bad(
                "absorb tolerance",
                format!("{} m (want finite ≥ 0)", self.absorb_tolerance_m),
            );
        }
        if let Some(g) = self.scattering
            && !(g.strength.is_finite()
                && g.strength > 0.0
                && g.strength <= 1.0
                && (1..=1000).contains(&g.radius)
                && g.max_share.is_finite()
                && g.max_share > 0.0)
        {
            return bad(
                "scattering gate",
                format!("{g:?} (want strength in (0, 1], radius 1 to 1000, share > 0)"),
            );
        }
        if !(1..=7).contains(&self.noise_radius) {
            return bad("noise radius", format!("{} (want 1 to 7)", self.noise_radius));
        }
        Ok(())
    }
}

/// What [`RegionUnwrapper::apply`] found, pixel counts.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct RegionStats {
    /// Regions of at least the minimum size.
    pub regions: usize,
    /// Of those, decided (an offset with enough support and margin, loops consistent).
    pub decided: usize,
    /// Pixels dropped in regions below the minimum size.
    pub small: usize,
    /// Pixels dropped in inconsistent or undecided regions.
    pub ambiguous: usize,
    /// Pixels dropped because their absolute wrap count exceeds the maximum.
    pub too_many_wraps: usize,
    /// Pixels dropped as too noisy ([`RegionConfig::max_noise_m`]).
    pub noisy: usize,
    /// Pixels dropped by the scattering gate ([`RegionConfig::scattering`]).
    pub scattered: usize,
    /// Dropped pixels given their output neighbours' wrap count
    /// ([`RegionConfig::absorb_passes`]).
    pub absorbed: usize,
}

/// [`RegionConfig`] prepared for one camera and range kind (illumination and ray tables
/// computed once).
#[derive(Clone, Debug)]
pub struct RegionUnwrapper {
    camera: TofCamera,
    kind: RangeKind,
    config: RegionConfig,
    tables: RayTables,
    /// `aw_p · T` per pixel (`≤ 0`: the pixel gives no evidence).
    limit: Vec<Real>,
    non_ambiguity: Real,
}

const NONE: u32 = u32::MAX;

/// The median absolute deviation from the median of `v` (reordered; 0 if empty).
fn mad(v: &mut [Real]) -> Real {
    if v.is_empty() {
        return 0.0;
    }
    let m = v.len() / 2;
    let median = *v.select_nth_unstable_by(m, Real::total_cmp).1;
    v.iter_mut().for_each(|x| *x = (*x - median).abs());
    *v.select_nth_unstable_by(m, Real::total_cmp).1
}

/// How many offsets beyond [`RegionConfig::max_wraps`] a region is also tested at: a region
/// that fits better there is dropped rather than unwrapped too little.
const EXTRA_OFFSETS: usize = 3;

/// Gives dropped measured pixels the wrap count their output neighbours agree on
/// ([`RegionConfig::absorb_passes`]); returns how many were added.
fn absorb(
    out: &mut FilterOutput,
    radial: &[Real],
    valid: &[bool],
    w: usize,
    h: usize,
    amb: Real,
    cfg: &RegionConfig,
) -> usize {
    let mut added = 0;
    for _ in 0..cfg.absorb_passes {
        let before = out.outcomes.clone();
        let ranges = out.radial.clone();
        let mut changed = 0;
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                if !valid[i] || before[i].is_output() {
                    continue;
                }
                let (mut k_agreed, mut votes, mut against) = (None, 0u32, false);
                for dy in -1isize..=1 {
                    for dx in -1isize..=1 {
                        let (nx, ny) = (x as isize + dx, y as isize + dy);
                        if (dx, dy) == (0, 0)
                            || nx < 0
                            || ny < 0
                            || nx >= w as isize
                            || ny >= h as isize
                        {
                            continue;
                        }
                        let j = ny as usize * w + nx as usize;
                        if !before[j].is_output() {
                            continue;
                        }
                        let u = ranges[j] as Real;
                        let k = ((u - radial[i]) / amb).round();
                        let tol = cfg.absorb_tolerance_m + cfg.join_relative * u;
                        if (radial[i] + k * amb - u).abs() > tol || k < 0.0 {
                            against = true;
                        } else if k_agreed.is_none_or(|a| a == k) {
                            k_agreed = Some(k);
                            votes += 1;
                        } else {
                            against = true;
                        }
                    }
                }
                if let (Some(k), false) = (k_agreed, against)
                    && votes >= 2
                    && k <= cfg.max_wraps as Real
                {
                    out.outcomes[i] =
                        if k == 0.0 { PixelOutcome::Kept } else { PixelOutcome::Unwrapped };
                    out.radial[i] = (radial[i] + k * amb) as f32;
                    changed += 1;
                }
            }
        }
        added += changed;
        if changed == 0 {
            break;
        }
    }
    added
}

/// Drops the output pixels whose local noise estimate exceeds `max` ([`RegionConfig::max_noise_m`]);
/// returns how many.
fn drop_noisy(
    out: &mut FilterOutput,
    label: &[u32],
    w: usize,
    h: usize,
    radius: usize,
    max: Real,
) -> usize {
    let n = w * h;
    let output: Vec<bool> = out.outcomes.iter().map(|o| o.is_output()).collect();
    let on = |i: usize| output[i];
    let u = out.radial.clone();
    // Squared second differences per pixel (sum and count of the available directions).
    let mut sq = vec![0.0 as Real; n];
    let mut cnt = vec![0u32; n];
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            if !on(i) {
                continue;
            }
            let mut pair = |a: usize, b: usize| {
                if on(a) && on(b) && label[a] == label[i] && label[b] == label[i] {
                    let d = u[i] as Real - 0.5 * (u[a] as Real + u[b] as Real);
                    sq[i] += d * d;
                    cnt[i] += 1;
                }
            };
            if x > 0 && x + 1 < w {
                pair(i - 1, i + 1);
            }
            if y > 0 && y + 1 < h {
                pair(i - w, i + w);
            }
        }
    }
    // Box sums through summed-area tables.
    let (w1, h1) = (w + 1, h + 1);
    let mut s_sq = vec![0.0 as Real; w1 * h1];
    let mut s_n = vec![0u64; w1 * h1];
    for y in 0..h {
        for x in 0..w {
            let (i, j) = (y * w + x, (y + 1) * w1 + x + 1);
            s_sq[j] = sq[i] + s_sq[j - 1] + s_sq[j - w1] - s_sq[j - w1 - 1];
            s_n[j] = cnt[i] as u64 + s_n[j - 1] + s_n[j - w1] - s_n[j - w1 - 1];
        }
    }
    let mut dropped = 0;
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            if !on(i) {
                continue;
            }
            let (x0, y0) = (x.saturating_sub(radius), y.saturating_sub(radius));
            let (x1, y1) = ((x + radius + 1).min(w), (y + radius + 1).min(h));
            let box_sum =
                |t: &[Real]| t[y1 * w1 + x1] - t[y0 * w1 + x1] - t[y1 * w1 + x0] + t[y0 * w1 + x0];
            let count =
                s_n[y1 * w1 + x1] + s_n[y0 * w1 + x0] - s_n[y0 * w1 + x1] - s_n[y1 * w1 + x0];
            // Too few residuals to judge: the pixel stands nearly alone, drop it too.
            let noisy = count < 3 || box_sum(&s_sq) / (1.5 * count as Real) > max * max;
            if noisy {
                out.outcomes[i] = PixelOutcome::Dropped;
                out.radial[i] = 0.0;
                dropped += 1;
            }
        }
    }
    dropped
}

impl RegionUnwrapper {
    /// Prepares `config` for frames of `camera` whose ranges are of `kind`.
    ///
    /// # Errors
    /// A parameter out of its domain ([`RegionConfig::validate`], the illumination model, a
    /// clamp ≤ 0), or a join tolerance at the non-ambiguity range of a quarter of it or more
    /// (wrapped and unwrapped neighbours could not be told apart).
    pub fn new(
        camera: &TofCamera,
        kind: RangeKind,
        config: &RegionConfig,
    ) -> Result<RegionUnwrapper, TofError> {
        camera.validate()?;
        config.validate()?;
        let non_ambiguity = camera.non_ambiguity_range();
        let tol = config.join_absolute_m + config.join_relative * non_ambiguity;
        if tol >= non_ambiguity / 4.0 {
            return Err(TofError::BadParameter {
                what: "join tolerance",
                why: format!(
                    "{tol:.3} m at the non-ambiguity range {non_ambiguity:.3} m (want < a quarter of it)"
                ),
            });
        }
        let aw = illumination_table(&config.aat.illumination, camera)?;
        let clamp = match config.aat.negative {
            NegativeIllumination::Literal => None,
            NegativeIllumination::Clamp(m) if m.is_finite() && m > 0.0 => Some(m),
            NegativeIllumination::Clamp(m) => {
                return Err(TofError::BadParameter {
                    what: "illumination clamp",
                    why: format!("{m} (want finite > 0)"),
                });
            }
        };
        let limit =
            aw.iter().map(|&a| clamp.map_or(a, |m| a.max(m)) * config.aat.threshold).collect();
        Ok(RegionUnwrapper {
            camera: *camera,
            kind,
            config: config.clone(),
            tables: RayTables::new(camera),
            limit,
            non_ambiguity,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &RegionConfig {
        &self.config
    }

    /// The ray tables.
    pub fn tables(&self) -> &RayTables {
        &self.tables
    }

    /// Unwraps `frame` into `out` and says what it dropped and why.
    ///
    /// # Errors
    /// A frame of another size or range kind than prepared for.
    pub fn apply(&self, frame: &TofFrame, out: &mut FilterOutput) -> Result<RegionStats, TofError> {
        crate::filter::check_prepared(frame, &self.camera, self.kind, "region unwrapper")?;
        let c = frame.camera();
        let (w, h) = (c.width as usize, c.height as usize);
        let n = w * h;
        out.reset(n);
        let cfg = &self.config;
        let amb = self.non_ambiguity;
        let rpd = &self.tables.radial_per_depth;
        let radial: Vec<Real> = (0..n)
            .map(|i| {
                let r = frame.range()[i] as Real;
                if self.kind == RangeKind::Depth { r * rpd[i] as Real } else { r }
            })
            .collect();
        let amp = frame.amplitude();
        let low = cfg.low_at.unwrap_or(Real::NEG_INFINITY);
        let valid: Vec<bool> = (0..n)
            .map(|i| frame.range()[i] > 0.0 && (amp[i] as Real) > low && amp[i] > 0.0)
            .collect();
        let mut valid = valid;
        let mut scattered_out = 0;
        if let Some(g) = cfg.scattering {
            let (mut re, mut im) = (vec![0.0; n], vec![0.0; n]);
            for i in 0..n {
                if frame.range()[i] > 0.0 {
                    let phi = std::f64::consts::TAU * radial[i] / amb;
                    re[i] = amp[i] as Real * phi.cos();
                    im[i] = amp[i] as Real * phi.sin();
                }
            }
            let r = g.radius as usize;
            let (re, im) = (crate::sim::blur(&re, w, h, r), crate::sim::blur(&im, w, h, r));
            for i in 0..n {
                let scattered = g.strength * re[i].hypot(im[i]);
                if scattered > g.max_share * amp[i] as Real {
                    scattered_out += valid[i] as usize;
                    valid[i] = false;
                }
            }
        }
        let mut label = vec![NONE; n];
        let mut wrap = vec![0i32; n];
        let mut queue: Vec<usize> = Vec::new();
        let mut members: Vec<usize> = Vec::new();
        let mut logs: Vec<Real> = Vec::new();
        let mut stats = RegionStats { scattered: scattered_out, ..RegionStats::default() };
        let ratio = cfg.max_amplitude_ratio as f32;
        // The relative wrap step from i to j if they join, else None.
        // The step from a to b modulo the non-ambiguity range.
        let wrapped_step = |a: usize, b: usize| {
            let d = radial[b] - radial[a];
            d - (d / amb).round() * amb
        };
        let join = |i: usize, j: usize| -> Option<i32> {
            if !valid[j] {
                return None;
            }
            let (ai, aj) = (amp[i], amp[j]);
            if ai.max(aj) > ratio * ai.min(aj) {
                return None;
            }
            let d = radial[j] - radial[i];
            let step = -(d / amb).round();
            let e = (d + step * amb).abs();
            let tol = cfg.join_absolute_m + cfg.join_relative * radial[i].max(radial[j]);
            if e > tol {
                return None;
            }
            if let Some(t) = cfg.join_curvature_m {
                // The step i → j must continue the step before i or the one after j.
                let (xi, xj) = ((i % w) as isize, (j % w) as isize);
                let (yi, yj) = ((i / w) as isize, (j / w) as isize);
                let (dx, dy) = (xj - xi, yj - yi);
                let at = |x: isize, y: isize| {
                    (x >= 0 && y >= 0 && (x as usize) < w && (y as usize) < h)
                        .then(|| y as usize * w + x as usize)
                        .filter(|&k| valid[k])
                };
                let here = wrapped_step(i, j);
                let before = at(xi - dx, yi - dy).map(|p| wrapped_step(p, i));
                let after = at(xj + dx, yj + dy).map(|q| wrapped_step(j, q));
                let smooth = |s: Option<Real>| s.is_some_and(|s| (s - here).abs() <= t);
                if (before.is_some() || after.is_some()) && !smooth(before) && !smooth(after) {
                    return None;
                }
            }
            Some(step as i32)
        };
        let neighbours = |i: usize| {
            let (x, y) = (i % w, i / w);
            [
                (x > 0).then(|| i - 1),
                (x + 1 < w).then(|| i + 1),
                (y > 0).then(|| i - w),
                (y + 1 < h).then(|| i + w),
            ]
        };
        let max_k = cfg.max_wraps as i32;
        let mut next_label = 0u32;
        // Per region the absolute wrap count of relative wrap 0, once decided.
        let mut offset: Vec<Option<i32>> = Vec::new();
        for seed in 0..n {
            if !valid[seed] || label[seed] != NONE {
                continue;
            }
            // Flood fill with relative wrap counts.
            let id = next_label;
            next_label += 1;
            offset.push(None);
            label[seed] = id;
            wrap[seed] = 0;
            queue.clear();
            members.clear();
            queue.push(seed);
            let (mut joins, mut conflicts) = (0usize, 0usize);
            while let Some(i) = queue.pop() {
                members.push(i);
                for j in neighbours(i).into_iter().flatten() {
                    let Some(step) = join(i, j) else { continue };
                    let k = wrap[i] + step;
                    if label[j] == NONE {
                        label[j] = id;
                        wrap[j] = k;
                        queue.push(j);
                    } else if label[j] == id {
                        joins += 1;
                        conflicts += (wrap[j] != k) as usize;
                    }
                }
            }
            if members.len() < cfg.min_region_pixels {
                stats.small += members.len();
                continue;
            }
            stats.regions += 1;
            // Each join is seen from both ends.
            if conflicts as Real > cfg.max_conflicts * (joins.max(1) as Real) {
                stats.ambiguous += members.len();
                continue;
            }
            let k_min = members.iter().map(|&i| wrap[i]).min().unwrap_or(0);
            // Support of each absolute offset K of the region's lowest pixel.
            let mut support = vec![0usize; max_k as usize + 1 + EXTRA_OFFSETS];
            let mut voters = 0usize;
            for &i in &members {
                let lim = self.limit[i];
                if lim <= 0.0 {
                    continue; // Eq 2.4 literal in a corner with aw ≤ 0: no evidence
                }
                voters += 1;
                let a = amp[i] as Real;
                for (big_k, s) in support.iter_mut().enumerate() {
                    let u = radial[i] + (wrap[i] - k_min + big_k as i32) as Real * amb;
                    let q = match cfg.aat.range {
                        AatRange::Radial => u,
                        AatRange::Depth => u / rpd[i] as Real,
                    };
                    let rho = a * q * q;
                    *s += (rho >= cfg.min_brightness * lim && rho <= cfg.max_brightness * lim)
                        as usize;
                }
            }
            let share = |k: usize| support[k] as Real / voters.max(1) as Real;
            let best =
                (0..support.len()).max_by_key(|&k| (support[k], usize::MAX - k)).unwrap_or(0);
            let runner = (0..support.len()).filter(|&k| k != best).map(share).fold(0.0, Real::max);
            let by_band = (voters > 0
                && share(best) >= cfg.min_support
                && share(best) - runner >= cfg.min_margin)
                .then_some(best);
            // The offset under which the amplitude best follows 1/r² across the region.
            let by_spread = cfg.spread_ratio.and_then(|ratio| {
                let spreads: Vec<Real> = (0..support.len())
                    .map(|big_k| {
                        logs.clear();
                        logs.extend(members.iter().filter(|&&i| amp[i] > 0.0).map(|&i| {
                            let u = radial[i] + (wrap[i] - k_min + big_k as i32) as Real * amb;
                            (amp[i] as Real * u * u).ln()
                        }));
                        mad(&mut logs)
                    })
                    .collect();
                let k = (0..spreads.len()).min_by(|&a, &b| spreads[a].total_cmp(&spreads[b]))?;
                let second = (0..spreads.len())
                    .filter(|&j| j != k)
                    .map(|j| spreads[j])
                    .fold(Real::INFINITY, Real::min);
                (spreads[k] <= ratio * second && share(k) >= cfg.min_support / 2.0).then_some(k)
            });
            let chosen = match (by_band, by_spread) {
                (Some(a), Some(b)) if a != b => None,
                (a, b) => a.or(b),
            };
            let decided = chosen.is_some_and(|k| k as i32 <= max_k);
            let best = chosen.unwrap_or(0);
            if !decided {
                stats.ambiguous += members.len();
                continue;
            }
            stats.decided += 1;
            offset[id as usize] = Some(best as i32 - k_min);
        }
        // Boundaries: a decided region whose border joins a larger decided neighbour's range
        // only at another offset than its own (a dark patch on a near surface taken for a
        // wrapped one) is dropped.
        if let Some(min_edges) = cfg.boundary_edges {
            let regions = next_label as usize;
            let mut size = vec![0usize; regions];
            label.iter().filter(|&&l| l != NONE).for_each(|&l| size[l as usize] += 1);
            let (mut agree, mut against) = (vec![0usize; regions], vec![0usize; regions]);
            let unwrapped = |i: usize, off: i32| radial[i] + (wrap[i] + off) as Real * amb;
            for i in 0..n {
                let a = label[i];
                if a == NONE {
                    continue;
                }
                let Some(oa) = offset[a as usize] else { continue };
                for j in [(i % w + 1 < w).then(|| i + 1), (i + w < n).then(|| i + w)]
                    .into_iter()
                    .flatten()
                {
                    let b = label[j];
                    if b == NONE || b == a {
                        continue;
                    }
                    let Some(ob) = offset[b as usize] else { continue };
                    let (ui, uj) = (unwrapped(i, oa), unwrapped(j, ob));
                    let tol = cfg.join_absolute_m + cfg.join_relative * radial[i].max(radial[j]);
                    let e = uj - ui;
                    let off = (e - (e / amb).round() * amb).abs();
                    // Blame the smaller region.
                    let small = if size[a as usize] <= size[b as usize] { a } else { b } as usize;
                    if e.abs() <= tol {
                        agree[small] += 1;
                    } else if off <= tol {
                        against[small] += 1;
                    }
                }
            }
            for r in 0..regions {
                if offset[r].is_some() && against[r] >= min_edges && against[r] > agree[r] {
                    offset[r] = None;
                    stats.decided -= 1;
                    stats.ambiguous += size[r];
                }
            }
        }
        for i in 0..n {
            let Some(off) = label.get(i).filter(|&&l| l != NONE).and_then(|&l| offset[l as usize])
            else {
                continue;
            };
            let k = wrap[i] + off;
            if k > max_k {
                stats.too_many_wraps += 1;
                continue;
            }
            out.outcomes[i] = if k == 0 { PixelOutcome::Kept } else { PixelOutcome::Unwrapped };
            out.radial[i] = (radial[i] + k as Real * amb) as f32;
        }
        if cfg.absorb_passes > 0 {
            stats.absorbed = absorb(out, &radial, &valid, w, h, amb, cfg);
        }
        if let Some(max) = cfg.max_noise_m {
            stats.noisy = drop_noisy(out, &label, w, h, cfg.noise_radius as usize, max);
        }
        out.recount();
        Ok(stats)
    }

    /// [`RegionUnwrapper::apply`] into a new output.
    ///
    /// # Errors
    /// As [`RegionUnwrapper::apply`].
    pub fn run(&self, frame: &TofFrame) -> Result<FilterOutput, TofError> {
        let mut out = FilterOutput::default();
        self.apply(frame, &mut out)?;
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{FrameTruth, Illumination, Parabola, score};
    use pointcloud::PinholeIntrinsics;

    const A_HAT: Real = 10_000.0;

    /// A small camera at 15 MHz (R = 9.99 m) and the AAT of a flat illumination `A_HAT`.
    fn setup(modulation_hz: Real) -> (TofCamera, RegionConfig) {
        let c = TofCamera::pinhole(
            40,
            30,
            PinholeIntrinsics { fx: 40.0, fy: 40.0, cx: 19.5, cy: 14.5 },
            modulation_hz,
        )
        .unwrap();
        let aat = AatConfig {
            illumination: Illumination::Parabola(Parabola {
                a_hat: A_HAT,
                delta_x: 0.0,
                delta_y: 0.0,
                curvature: 0.0,
            }),
            threshold: 0.2,
            range: AatRange::Radial,
            negative: NegativeIllumination::Literal,
        };
        let config = RegionConfig { max_noise_m: None, ..RegionConfig::new(aat) };
        (c, config)
    }

    /// A noise-free frame of the scene `hit(ray) -> (true radial distance, reflectivity)`
    /// (no hit: no measurement), folded at the camera's non-ambiguity range, amplitude
    /// `ρ · cos · Â / r²` with the incidence taken as normal.
    fn render(
        c: &TofCamera,
        hit: impl Fn(pointcloud::Vector3) -> Option<(Real, Real)>,
    ) -> (TofFrame, FrameTruth) {
        let amb = c.non_ambiguity_range();
        let (mut range, mut amp, mut truth) = (Vec::new(), Vec::new(), FrameTruth::default());
        for row in 0..c.height {
            for col in 0..c.width {
                let d = c.ray(col, row).normalize();
                match hit(d) {
                    Some((t, rho)) => {
                        range.push((t.rem_euclid(amb) as f32).max(1e-4));
                        amp.push((rho * A_HAT / (t * t)) as f32);
                        truth.radial.push(Some(t as f32));
                        truth.wraps.push((t / amb).floor() as u8);
                    }
                    None => {
                        range.push(0.0);
                        amp.push(0.0);
                        truth.radial.push(None);
                        truth.wraps.push(0);
                    }
                }
            }
        }
        (TofFrame::new(*c, RangeKind::Radial, range, amp).unwrap(), truth)
    }

    /// The distance along unit ray `d` to the plane `n · p = offset`, if in front.
    fn plane(d: pointcloud::Vector3, n: pointcloud::Vector3, offset: Real) -> Option<Real> {
        let denom = n.dot(&d);
        (denom.abs() > 1e-9).then(|| offset / denom).filter(|&t| t > 0.0)
    }

    fn measured(f: &TofFrame) -> Vec<bool> {
        f.range().iter().map(|&r| r > 0.0).collect()
    }

    #[test]
    fn a_wall_through_the_non_ambiguity_range_is_unwrapped_as_one_surface() {
        let (c, config) = setup(15e6);
        // A wall leaning back: 7.2 m at the bottom row to 10.4 m at the top (R = 9.99 m): the
        // wrapped top rows are unwrapped.
        let n = pointcloud::Vector3::new(0.0, 0.5, 1.0).normalize();
        let (frame, truth) = render(&c, |d| plane(d, n, 8.0 * n.z).map(|t| (t, 0.6)));
        assert!(truth.wraps.contains(&1) && truth.wraps.contains(&0));
        let u = RegionUnwrapper::new(&c, RangeKind::Radial, &config).unwrap();
        let mut out = FilterOutput::default();
        let stats = u.apply(&frame, &mut out).unwrap();
        let s = score(&out, &measured(&frame), &truth, 0.01).unwrap();
        assert_eq!(s.wrong_kept_percent, 0.0, "{s:?} {stats:?}");
        // The corners of the top rows, where the range grows fastest, are dropped.
        assert!(s.yield_percent > 90.0, "{s:?} {stats:?}");
        assert!(out.counts.unwrapped > 0 && out.counts.kept > 0, "{:?}", out.counts);
    }

    #[test]
    fn a_bright_far_wall_is_unwrapped_and_a_dim_near_one_is_kept() {
        let (c, config) = setup(15e6);
        let u = RegionUnwrapper::new(&c, RangeKind::Radial, &config).unwrap();
        let z = pointcloud::Vector3::z();
        // A white wall 12 m away reads 2 m, 36 times too dark for 2 m.
        let (far, far_truth) = render(&c, |d| plane(d, z, 12.0).map(|t| (t, 0.9)));
        let out = u.run(&far).unwrap();
        assert_eq!(out.counts.unwrapped, far.num_measured());
        assert_eq!(score(&out, &measured(&far), &far_truth, 0.01).unwrap().wrong_kept_percent, 0.0);
        // A 40 % wall at 3 m: plausible as measured, 13 times too bright at 12.99 m.
        let (near, near_truth) = render(&c, |d| plane(d, z, 3.0).map(|t| (t, 0.4)));
        let out = u.run(&near).unwrap();
        assert_eq!(out.counts.kept, near.num_measured());
        assert_eq!(
            score(&out, &measured(&near), &near_truth, 0.01).unwrap().wrong_kept_percent,
            0.0
        );
    }

    #[test]
    fn a_dark_patch_on_a_near_wall_is_not_unwrapped() {
        let (c, config) = setup(15e6);
        let z = pointcloud::Vector3::z();
        // A 50 % wall at 2 m with a 5 % patch (10 × 10 pixels): the AAT alone flags the patch
        // as wrapped; its border continues the wall at the measured range.
        let (frame, truth) = render(&c, |d| {
            let t = plane(d, z, 2.0)?;
            let (x, y) = (d.x / d.z, d.y / d.z);
            let dark = x.abs() < 0.125 && y.abs() < 0.125;
            Some((t, if dark { 0.05 } else { 0.5 }))
        });
        let out =
            RegionUnwrapper::new(&c, RangeKind::Radial, &config).unwrap().run(&frame).unwrap();
        assert_eq!(out.counts.unwrapped, 0, "{:?}", out.counts);
        assert!(out.counts.kept >= frame.num_measured() - 100);
        assert_eq!(score(&out, &measured(&frame), &truth, 0.01).unwrap().wrong_kept_percent, 0.0);
    }

    #[test]
    fn absorbing_fills_a_small_patch_its_neighbours_agree_on() {
        let (c, config) = setup(15e6);
        let z = pointcloud::Vector3::z();
        // A 50 % wall at 3 m with a 4 × 4 patch five times brighter: too unlike its neighbours
        // to join them, too small to stand alone.
        let (frame, truth) = render(&c, |d| {
            let t = plane(d, z, 3.0)?;
            let (x, y) = (d.x / d.z, d.y / d.z);
            let bright = x.abs() < 0.04 && y.abs() < 0.04;
            Some((t, if bright { 2.5 } else { 0.5 }))
        });
        let u = RegionUnwrapper::new(&c, RangeKind::Radial, &config).unwrap();
        let mut out = FilterOutput::default();
        let stats = u.apply(&frame, &mut out).unwrap();
        let patch = stats.small;
        assert!(patch > 0 && out.counts.kept == frame.num_measured() - patch, "{stats:?}");
        let cfg = RegionConfig { absorb_passes: 3, ..config };
        let u = RegionUnwrapper::new(&c, RangeKind::Radial, &cfg).unwrap();
        let stats = u.apply(&frame, &mut out).unwrap();
        assert_eq!((stats.absorbed, out.counts.kept), (patch, frame.num_measured()), "{stats:?}");
        assert_eq!(score(&out, &measured(&frame), &truth, 0.01).unwrap().wrong_kept_percent, 0.0);
    }

    #[test]
    fn absurd_parameters_are_refused() {
        let (c, base) = setup(15e6);
        let bad: [fn(&mut RegionConfig); 15] = [
            |c| c.scattering = Some(ScatterGate { radius: 0, ..ScatterGate::sr3000() }),
            |c| c.min_brightness = 0.0,
            |c| c.min_brightness = c.max_brightness,
            |c| c.absorb_passes = 101,
            |c| c.join_absolute_m = -1.0,
            |c| c.join_relative = 0.5,
            |c| c.join_curvature_m = Some(Real::NAN),
            |c| c.max_amplitude_ratio = 0.5,
            |c| c.min_region_pixels = 0,
            |c| c.max_brightness = 1.0,
            |c| c.min_support = 0.0,
            |c| c.spread_ratio = Some(1.5),
            |c| c.max_wraps = MAX_WRAPS + 1,
            |c| c.max_noise_m = Some(0.0),
            |c| c.aat.threshold = 0.0,
        ];
        for (k, f) in bad.iter().enumerate() {
            let mut cfg = base.clone();
            f(&mut cfg);
            assert!(RegionUnwrapper::new(&c, RangeKind::Radial, &cfg).is_err(), "case {k}");
        }
        // A tolerance too wide for the non-ambiguity range (0.15 m at 1 GHz).
        let short = TofCamera { modulation_hz: 1e9, ..c };
        assert!(RegionUnwrapper::new(&short, RangeKind::Radial, &base).is_err());
        // A frame of another kind than prepared for.
        let u = RegionUnwrapper::new(&c, RangeKind::Depth, &base).unwrap();
        let (frame, _) = render(&c, |d| plane(d, pointcloud::Vector3::z(), 3.0).map(|t| (t, 0.5)));
        assert!(u.run(&frame).is_err());
    }

    proptest::proptest! {
        /// On a noise-free tilted wall of plausible reflectivity, whatever its distance and
        /// tilt, every output pixel is within 1 cm of the truth, and every output range is the
        /// reported one plus a whole number (≤ `max_wraps`) of non-ambiguity ranges.
        #[test]
        fn a_plane_is_never_unwrapped_wrongly(
            distance in 0.5..25.0f64,
            tilt_x in -0.6..0.6f64,
            tilt_y in -0.6..0.6f64,
            rho in 0.5..1.0f64,
        ) {
            let (c, config) = setup(15e6);
            let amb = c.non_ambiguity_range();
            let n = pointcloud::Vector3::new(tilt_x, tilt_y, 1.0).normalize();
            let (frame, truth) = render(&c, |d| {
                plane(d, n, distance * n.z).filter(|&t| t < 40.0).map(|t| (t, rho))
            });
            let out = RegionUnwrapper::new(&c, RangeKind::Radial, &config).unwrap().run(&frame).unwrap();
            let s = score(&out, &measured(&frame), &truth, 0.01).unwrap();
            proptest::prop_assert_eq!(s.wrong_kept_percent, 0.0, "{:?}", s);
            for i in 0..out.outcomes.len() {
                if out.outcomes[i].is_output() {
                    let k = (out.radial[i] as Real - frame.range()[i] as Real) / amb;
                    proptest::prop_assert!((k - k.round()).abs() < 1e-4 && k.round() <= config.max_wraps as Real);
                }
            }
        }
    }
}
