//! A spatial consistency check of the AAT's decisions (beyond the thesis).
//!
//! The adaptive amplitude threshold (Eq 2.4, thesis §2.5.5) judges each pixel alone, so its
//! mistakes come as isolated pixels: a dark spot on a near surface looks wrapped (its apparent
//! reflectivity is low, L2376–2402) and is dropped or unwrapped; a wrapped pixel in a corner
//! where `aw_p < 0` (spec §6.2), or a noisy bright one, passes. Surfaces are seldom one pixel
//! wide, so [`reconsider`] asks each pixel's neighbours (a `(2·radius + 1)²` window) which
//! hypothesis they support:
//!
//! - **as measured**: the pixel's reported radial range `r` agrees with the output range of a
//!   neighbour the filter kept;
//! - **wrapped once**: `r + R_amb` agrees with the output range of a neighbour the filter
//!   unwrapped ([`FlagPolicy::Unwrap`]), or with `r_j + R_amb` of a measured neighbour the
//!   filter dropped ([`FlagPolicy::Drop`], the AAT without unwrapping).
//!
//! With `K` and `W` the numbers of neighbours supporting each and `s` =
//! [`SpatialConfig::min_support`], decided from the filter's outcomes (a copy; no pixel sees
//! another's new outcome, so the result does not depend on the scan order):
//!
//! | filter said | condition | becomes |
//! |---|---|---|
//! | dropped (measured) or unwrapped | `K ≥ s` and `K > W` | kept at `r` |
//! | kept | `K = 0` and `W ≥ s` | unwrapped at `r + R_amb` (policy `Unwrap`) or dropped (`Drop`) |
//! | dropped (measured), policy `Unwrap` | `W ≥ s` and `W > K` | unwrapped at `r + R_amb` |
//! | kept or unwrapped, [`SpatialConfig::isolation_support`] `= m > 0` | fewer than `m` output neighbours agree with its output range | dropped |
//!
//! With [`SpatialConfig::passes`] > 1 the check is repeated on its own output (each pass again
//! from a copy), so restored pixels support their neighbours in the next pass.
//!
//! A kept pixel is only turned over when *no* kept neighbour agrees with it, so a genuinely
//! separate near object of two or more pixels survives; a flagged pixel needs `s` agreeing kept
//! neighbours, so one or two wrong neighbours cannot restore it.
//!
//! Ranges agree when `|x − y| ≤ absolute + relative · max(x, y)` ([`RangeTolerance`]): the
//! absolute part covers the noise, the relative part the range step between neighbouring pixels
//! on an oblique surface (`r·Δθ / tan α` at a grazing angle `α`; the SR-3000's pixel pitch is
//! Δθ ≈ 0.0047 rad, L1488–1492, so 3 % covers surfaces down to about 12° from the beam along
//! the diagonal).
//!
//! # What it can and cannot fix
//!
//! It fixes what is local: single pixels and patches up to 3 pixels across. It cannot decide a
//! whole region: a dark object and a wrapped wall both arrive as a region of flagged pixels, and
//! at the region's edge both hypotheses are equally supported. On the simulated scenes of
//! Table 2.4 (the ignored test `scores_on_the_six_scenes` in `tests/it/spatial.rs`) the AAT's
//! mistakes are such regions (dark material, sunlit areas, scattering), so the default check
//! changes a few dozen pixels per frame; dropping output pixels with fewer than 3 agreeing
//! neighbours ([`SpatialConfig::isolation_support`]) halves the gross errors of the AAT with
//! unwrapping (sunlight noise it had unwrapped) at an unchanged number of correct pixels.
//!
//! # Complexity
//!
//! `O(passes · n · (2·radius + 1)²)`; no allocation once the [`SpatialScratch`] buffers have
//! grown to the image size.

use crate::{FilterConfig, FilterOutput, PixelOutcome, RayTables, TofError, TofFrame};
use pointcloud::{RangeKind, Real};
use serde::{Deserialize, Serialize};

/// The largest accepted [`SpatialConfig::radius`] (a 15 × 15 window).
pub const MAX_RADIUS: u32 = 7;

/// The largest accepted [`SpatialConfig::passes`].
pub const MAX_PASSES: u32 = 1000;

/// When two radial ranges agree: `|x − y| ≤ absolute_m + relative · max(x, y)`.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RangeTolerance {
    /// The absolute part, metres (noise).
    pub absolute_m: Real,
    /// The part relative to the larger range (oblique surfaces), in `[0, 1)`.
    pub relative: Real,
}

impl RangeTolerance {
    /// Whether `x` and `y` (metres) agree.
    pub fn agree(&self, x: Real, y: Real) -> bool {
        (x - y).abs() <= self.absolute_m + self.relative * x.max(y)
    }
}

/// What the filter whose output is reconsidered did with the pixels its detector flagged.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum FlagPolicy {
    /// Unwrapped them (the AAT with unwrapping): evidence for "wrapped" comes from unwrapped
    /// neighbours, and a kept pixel judged wrapped is unwrapped.
    Unwrap,
    /// Dropped them (the AAT alone): evidence for "wrapped" comes from measured dropped
    /// neighbours, and a kept pixel judged wrapped is dropped.
    Drop,
}

/// The parameters of [`reconsider`]. Build with [`SpatialConfig::for_filter`] (or a literal);
/// [`SpatialConfig::validate`] checks every field.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpatialConfig {
    /// Neighbourhood half-size: the window is `(2·radius + 1)²` pixels (default 1: 3 × 3).
    pub radius: u32,
    /// How many agreeing neighbours a hypothesis needs (default 3 of 8: a pixel at a convex
    /// right-angled corner of a region still has 3 neighbours on it, and one or two wrong
    /// neighbours cannot flip a pixel).
    pub min_support: u32,
    /// When ranges agree (default 5 cm + 3 %).
    pub tolerance: RangeTolerance,
    /// What the filter did with flagged pixels.
    pub policy: FlagPolicy,
    /// Drop output pixels whose output range fewer than this many output neighbours agree with
    /// (0: off, the default; 1: only pixels no neighbour agrees with at all). Removes noise
    /// (sunlight, pixels that saw nothing) that the AAT let through or unwrapped; at grazing
    /// angles single pixels of a real surface can be dropped too.
    pub isolation_support: u32,
    /// How many passes (≥ 1; default 1). Each pass decides every pixel from the outcomes of
    /// the previous one, so restored pixels support their neighbours in the next: a flagged
    /// patch up to 3 pixels across is restored from its corners inwards. Larger regions stay:
    /// at their straight edges flagged and kept neighbours tie, and the majority rule `K > W`,
    /// which keeps a wrapped region from being eaten by a wrongly kept neighbour region (the
    /// corners where `aw_p < 0`), stops the growth there. Stops early when a pass changes
    /// nothing.
    pub passes: u32,
}

impl SpatialConfig {
    /// The defaults (3 × 3, support 3, 5 cm + 3 %, isolated pixels kept, one pass) for the
    /// output of a
    /// [`crate::TofFilter`] built from `filter`: policy `Unwrap` if it unwraps, else `Drop`.
    pub fn for_filter(filter: &FilterConfig) -> SpatialConfig {
        SpatialConfig {
            radius: 1,
            min_support: 3,
            tolerance: RangeTolerance { absolute_m: 0.05, relative: 0.03 },
            policy: if filter.unwrap.is_some() { FlagPolicy::Unwrap } else { FlagPolicy::Drop },
            isolation_support: 0,
            passes: 1,
        }
    }

    /// Checks every field: radius in 1..=[`MAX_RADIUS`], support between 1 and the number of
    /// neighbours (isolation support: 0 too), a finite absolute tolerance ≥ 0 and a relative
    /// one in `[0, 1)`, passes in 1..=[`MAX_PASSES`].
    pub fn validate(&self) -> Result<(), TofError> {
        let bad = |what: &'static str, why: String| Err(TofError::BadParameter { what, why });
        if !(1..=MAX_RADIUS).contains(&self.radius) {
            return bad("radius", format!("{} (want 1 to {MAX_RADIUS})", self.radius));
        }
        let side = 2 * self.radius + 1;
        let neighbours = side * side - 1;
        if !(1..=neighbours).contains(&self.min_support) {
            return bad(
                "minimum support",
                format!(
                    "{} (want 1 to {neighbours}, the neighbours in the window)",
                    self.min_support
                ),
            );
        }
        if self.isolation_support > neighbours {
            return bad(
                "isolation support",
                format!("{} (want 0 to {neighbours})", self.isolation_support),
            );
        }
        if !(1..=MAX_PASSES).contains(&self.passes) {
            return bad("passes", format!("{} (want 1 to {MAX_PASSES})", self.passes));
        }
        let t = &self.tolerance;
        if !(t.absolute_m.is_finite() && t.absolute_m >= 0.0) {
            return bad(
                "absolute range tolerance",
                format!("{} m (want finite ≥ 0)", t.absolute_m),
            );
        }
        if !(t.relative.is_finite() && (0.0..1.0).contains(&t.relative)) {
            return bad("relative range tolerance", format!("{} (want in [0, 1))", t.relative));
        }
        Ok(())
    }
}

/// What [`reconsider`] changed, pixel counts by the filter's outcome and the final one (a pixel
/// changed back in a later pass is not counted).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct SpatialStats {
    /// Dropped (measured) → kept: e.g. a dark spot on a near surface.
    pub dropped_to_kept: usize,
    /// Unwrapped → kept.
    pub unwrapped_to_kept: usize,
    /// Kept → unwrapped: a wrapped pixel that had passed (policy `Unwrap`).
    pub kept_to_unwrapped: usize,
    /// Kept → dropped as wrapped (policy `Drop`).
    pub kept_to_dropped: usize,
    /// Dropped (measured) → unwrapped inside an unwrapped region (policy `Unwrap`).
    pub dropped_to_unwrapped: usize,
    /// Output pixels dropped as isolated ([`SpatialConfig::isolation_support`]).
    pub isolated_dropped: usize,
}

impl SpatialStats {
    /// All changed pixels.
    pub fn changed(&self) -> usize {
        self.dropped_to_kept
            + self.unwrapped_to_kept
            + self.kept_to_unwrapped
            + self.kept_to_dropped
            + self.dropped_to_unwrapped
            + self.isolated_dropped
    }
}

/// Scratch buffers of [`reconsider_with`]: the outcomes before the check and before each pass,
/// the reported radial ranges, per pixel the range that supports each hypothesis, why pixels
/// were dropped. Reuse one across frames to avoid allocating.
#[derive(Clone, Debug, Default)]
pub struct SpatialScratch {
    original: Vec<PixelOutcome>,
    outcomes: Vec<PixelOutcome>,
    radial: Vec<f32>,
    reported: Vec<f32>,
    /// The range a neighbour offers to "as measured" (its output range if kept, else NaN).
    as_measured: Vec<Real>,
    /// The range a neighbour offers to "wrapped once" (NaN if none).
    as_wrapped: Vec<Real>,
    /// Why a pixel was dropped: 0 not by the check, 1 as wrapped, 2 as isolated.
    reason: Vec<u8>,
}

/// [`reconsider_with`] with fresh scratch buffers.
pub fn reconsider(
    frame: &TofFrame,
    out: &mut FilterOutput,
    config: &SpatialConfig,
    tables: &RayTables,
) -> Result<SpatialStats, TofError> {
    reconsider_with(frame, out, config, tables, &mut SpatialScratch::default())
}

/// Reconsiders the output `out` of a filter (usually [`crate::TofFilter::apply`] with the AAT,
/// with or without unwrapping) on `frame` by the pixels' neighbours (module doc), in place;
/// recounts `out.counts` and returns what changed (original outcome → final outcome). `tables`
/// are the camera's ray tables (for depth frames). Fails on an invalid configuration or when
/// frame, output and tables differ in size.
pub fn reconsider_with(
    frame: &TofFrame,
    out: &mut FilterOutput,
    config: &SpatialConfig,
    tables: &RayTables,
    scratch: &mut SpatialScratch,
) -> Result<SpatialStats, TofError> {
    config.validate()?;
    let n = frame.range().len();
    if out.outcomes.len() != n || out.radial.len() != n || tables.radial_per_depth.len() != n {
        return Err(TofError::Mismatch {
            why: format!(
                "frame of {n} pixels, output of {} outcomes and {} ranges, ray tables of {}",
                out.outcomes.len(),
                out.radial.len(),
                tables.radial_per_depth.len()
            ),
        });
    }
    let depth = frame.kind() == RangeKind::Depth;
    scratch.reported.clear();
    scratch.reported.extend(
        frame
            .range()
            .iter()
            .zip(&tables.radial_per_depth)
            .map(|(&r, &k)| if depth { r * k } else { r }),
    );
    scratch.original.clear();
    scratch.original.extend_from_slice(&out.outcomes);
    scratch.reason.clear();
    scratch.reason.resize(n, 0);
    for _ in 0..config.passes {
        if pass(frame, out, config, scratch) == 0 {
            break;
        }
    }
    let mut stats = SpatialStats::default();
    for i in 0..n {
        use PixelOutcome::{Dropped, Kept, Unwrapped};
        match (scratch.original[i], out.outcomes[i]) {
            (Dropped, Kept) => stats.dropped_to_kept += 1,
            (Unwrapped, Kept) => stats.unwrapped_to_kept += 1,
            (Kept, Unwrapped) => stats.kept_to_unwrapped += 1,
            (Dropped, Unwrapped) => stats.dropped_to_unwrapped += 1,
            (Kept | Unwrapped, Dropped) if scratch.reason[i] == 2 => stats.isolated_dropped += 1,
            (Kept | Unwrapped, Dropped) => stats.kept_to_dropped += 1,
            _ => {}
        }
    }
    out.recount();
    Ok(stats)
}

/// One pass over every pixel, deciding from a copy of `out`; returns how many pixels changed.
fn pass(
    frame: &TofFrame,
    out: &mut FilterOutput,
    config: &SpatialConfig,
    scratch: &mut SpatialScratch,
) -> usize {
    let amb = frame.camera().non_ambiguity_range();
    scratch.outcomes.clear();
    scratch.outcomes.extend_from_slice(&out.outcomes);
    scratch.radial.clear();
    scratch.radial.extend_from_slice(&out.radial);
    scratch.as_measured.clear();
    scratch.as_wrapped.clear();
    for ((&o, &r), &m) in scratch.outcomes.iter().zip(&scratch.radial).zip(&scratch.reported) {
        let (r, m) = (r as Real, m as Real);
        let (kept, wrapped) = match (o, config.policy) {
            (PixelOutcome::Kept, _) => (r, Real::NAN),
            (PixelOutcome::Unwrapped, FlagPolicy::Unwrap) => (Real::NAN, r),
            (PixelOutcome::Dropped, FlagPolicy::Drop) if m > 0.0 => (Real::NAN, m + amb),
            _ => (Real::NAN, Real::NAN),
        };
        scratch.as_measured.push(kept);
        scratch.as_wrapped.push(wrapped);
    }
    let before = &scratch.outcomes;
    let (radial, reported) = (&scratch.radial, &scratch.reported);
    let (as_measured, as_wrapped) = (&scratch.as_measured, &scratch.as_wrapped);
    let (w, h) = (frame.camera().width as usize, frame.camera().height as usize);
    let rad = config.radius as usize;
    let support = config.min_support as usize;
    let tol = config.tolerance;
    let mut changed = 0;
    for y in 0..h {
        let (y0, y1) = (y.saturating_sub(rad), (y + rad).min(h - 1));
        for x in 0..w {
            let i = y * w + x;
            let r = reported[i] as Real;
            if !(r > 0.0 && r.is_finite()) {
                continue;
            }
            let o = before[i];
            let (x0, x1) = (x.saturating_sub(rad), (x + rad).min(w - 1));
            let wrapped = r + amb;
            // The pixel itself is in the window; its own offer is taken out afterwards.
            let (mut k, mut wr) = (0usize, 0usize);
            for yy in y0..=y1 {
                let row = yy * w;
                for j in row + x0..=row + x1 {
                    k += usize::from(tol.agree(r, as_measured[j]));
                    wr += usize::from(tol.agree(wrapped, as_wrapped[j]));
                }
            }
            k -= usize::from(tol.agree(r, as_measured[i]));
            wr -= usize::from(tol.agree(wrapped, as_wrapped[i]));
            let mut iso = 0usize;
            if config.isolation_support > 0 && o.is_output() {
                let own = radial[i] as Real;
                for yy in y0..=y1 {
                    for xx in x0..=x1 {
                        let j = yy * w + xx;
                        if j != i && before[j].is_output() {
                            iso += usize::from(tol.agree(own, radial[j] as Real));
                        }
                    }
                }
            }
            let decision = decide(o, k, wr, iso, support, config);
            if decision != Decision::Keep {
                changed += 1;
                apply(decision, i, r, amb, out, &mut scratch.reason);
            }
        }
    }
    changed
}

/// What becomes of a pixel.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
enum Decision {
    Keep,
    ToKept,
    ToUnwrapped,
    DropWrapped,
    DropIsolated,
}

/// The decision table of the module doc for a measured pixel with filter outcome `o`, `k`
/// neighbours supporting "as measured", `w` supporting "wrapped once", `iso` output neighbours
/// agreeing with its output range.
fn decide(
    o: PixelOutcome,
    k: usize,
    w: usize,
    iso: usize,
    support: usize,
    config: &SpatialConfig,
) -> Decision {
    let isolated = iso < config.isolation_support as usize;
    match o {
        PixelOutcome::Kept if k == 0 && w >= support => match config.policy {
            FlagPolicy::Unwrap => Decision::ToUnwrapped,
            FlagPolicy::Drop => Decision::DropWrapped,
        },
        PixelOutcome::Kept if isolated => Decision::DropIsolated,
        PixelOutcome::Kept => Decision::Keep,
        PixelOutcome::Unwrapped if k >= support && k > w => Decision::ToKept,
        PixelOutcome::Unwrapped if isolated => Decision::DropIsolated,
        PixelOutcome::Unwrapped => Decision::Keep,
        PixelOutcome::Dropped if k >= support && k > w => Decision::ToKept,
        PixelOutcome::Dropped if config.policy == FlagPolicy::Unwrap && w >= support && w > k => {
            Decision::ToUnwrapped
        }
        PixelOutcome::Dropped => Decision::Keep,
    }
}

fn apply(
    decision: Decision,
    i: usize,
    r: Real,
    amb: Real,
    out: &mut FilterOutput,
    reason: &mut [u8],
) {
    let (o, radial) = match decision {
        Decision::Keep => return,
        Decision::ToKept => (PixelOutcome::Kept, r),
        Decision::ToUnwrapped => (PixelOutcome::Unwrapped, r + amb),
        Decision::DropWrapped => (PixelOutcome::Dropped, 0.0),
        Decision::DropIsolated => (PixelOutcome::Dropped, 0.0),
    };
    reason[i] = match decision {
        Decision::DropWrapped => 1,
        Decision::DropIsolated => 2,
        _ => 0,
    };
    out.outcomes[i] = o;
    out.radial[i] = radial as f32;
}
