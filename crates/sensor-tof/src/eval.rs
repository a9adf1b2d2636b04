//! Scoring a filter against the truth of a frame (the metrics beyond the thesis's
//! "% discarded pixels", which is all Table 2.4 reports, spec §2).

use crate::{FilterOutput, PixelOutcome, TofError};
use pointcloud::Real;
use serde::{Deserialize, Serialize};

/// What each pixel really saw: the true radial distance of the surface its beam hits (`None`:
/// nothing within the simulator's casting range) and how many times that distance wrapped
/// around (`⌊true / R_amb⌋`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FrameTruth {
    /// True radial distance per pixel, metres.
    pub radial: Vec<Option<f32>>,
    /// Wrap count per pixel (0 for pixels without a hit).
    pub wraps: Vec<u8>,
}

/// How one filter did on one frame. Percentages are of the pixels named in each field's doc.
#[derive(Copy, Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Score {
    /// Pixels in the frame.
    pub pixels: usize,
    /// The thesis's metric: dropped pixels, % of all pixels.
    pub discarded_percent: Real,
    /// Output pixels (kept or unwrapped).
    pub output: usize,
    /// Wrong output pixels (no true surface, or more than the tolerance off), % of output pixels.
    pub wrong_kept_percent: Real,
    /// Output pixels whose true surface wrapped around but which were output at the wrapped
    /// (unchanged) range, % of output pixels: the wrap-around that got through.
    pub wrapped_kept_percent: Real,
    /// Measured pixels whose true surface wrapped at least once.
    pub wrapped: usize,
    /// Of those, % output within the tolerance of the truth (correctly unwrapped).
    pub unwrapped_correct_percent: Real,
    /// Output pixels with no true surface or more than 1 m off (a wrong wrap decision, a pixel
    /// that saw nothing), % of output pixels.
    pub gross_percent: Real,
    /// Root mean square radial error of all output pixels with a true surface, metres.
    pub rmse_output: Real,
    /// Root mean square radial error of the correct output pixels (the noise level), metres.
    pub rmse_correct: Real,
    /// Correct output pixels, % of the measured pixels whose truth is known: density of good
    /// data.
    pub correct_percent: Real,
    /// Correct output pixels, % of the measured pixels (those with a range, whether or not a
    /// true surface is known): the yield.
    #[serde(default)]
    pub yield_percent: Real,
}

/// Scores `out` against `truth`: a pixel is correct iff it is output within `tolerance`
/// metres (radially) of its true surface (the issue uses 5 cm). `measured[i]` tells whether
/// the camera reported a range for pixel `i`.
pub fn score(
    out: &FilterOutput,
    measured: &[bool],
    truth: &FrameTruth,
    tolerance: Real,
) -> Result<Score, TofError> {
    let n = out.outcomes.len();
    if truth.radial.len() != n
        || truth.wraps.len() != n
        || measured.len() != n
        || out.radial.len() != n
    {
        return Err(TofError::Mismatch {
            why: format!(
                "{n} outcomes, {} radii, {} truths, {} wrap counts, {} measured flags",
                out.radial.len(),
                truth.radial.len(),
                truth.wraps.len(),
                measured.len()
            ),
        });
    }
    let mut s = Score { pixels: n, ..Score::default() };
    let (mut dropped, mut wrong, mut wrapped_kept, mut unwrapped_ok, mut correct, mut known) =
        (0, 0, 0, 0, 0, 0);
    let n_measured = measured.iter().filter(|&&m| m).count();
    let mut gross = 0usize;
    let (mut se_all, mut n_all, mut se_ok) = (0.0, 0usize, 0.0);
    #[allow(clippy::needless_range_loop)] // five parallel arrays
    for i in 0..n {
        let t = truth.radial[i];
        let is_wrapped = measured[i] && t.is_some() && truth.wraps[i] > 0;
        if is_wrapped {
            s.wrapped += 1;
        }
        if measured[i] && t.is_some() {
            known += 1;
        }
        if out.outcomes[i] == PixelOutcome::Dropped {
            dropped += 1;
            continue;
        }
        s.output += 1;
        let Some(t) = t else {
            wrong += 1;
            gross += 1;
            continue;
        };
        let e = (out.radial[i] - t) as Real;
        gross += (e.abs() > 1.0) as usize;
        se_all += e * e;
        n_all += 1;
        if e.abs() <= tolerance {
            correct += 1;
            se_ok += e * e;
            if is_wrapped {
                unwrapped_ok += 1;
            }
        } else {
            wrong += 1;
            if is_wrapped && out.outcomes[i] == PixelOutcome::Kept {
                wrapped_kept += 1;
            }
        }
    }
    let pct = |a: usize, b: usize| if b == 0 { 0.0 } else { 100.0 * a as Real / b as Real };
    s.discarded_percent = pct(dropped, n);
    s.wrong_kept_percent = pct(wrong, s.output);
    s.wrapped_kept_percent = pct(wrapped_kept, s.output);
    s.gross_percent = pct(gross, s.output);
    s.unwrapped_correct_percent = pct(unwrapped_ok, s.wrapped);
    s.correct_percent = pct(correct, known);
    s.yield_percent = pct(correct, n_measured);
    s.rmse_output = if n_all == 0 { 0.0 } else { (se_all / n_all as Real).sqrt() };
    s.rmse_correct = if correct == 0 { 0.0 } else { (se_ok / correct as Real).sqrt() };
    Ok(s)
}

/// The most any single-frame unwrapping can output correctly: the % of measured pixels (range
/// `reported` > 0, radial metres) whose reported range plus some number `k ≤ max_wraps` of
/// non-ambiguity ranges `non_ambiguity` lies within `tolerance` of the truth. Pixels without a
/// true surface (noise) and pixels whose error is not wrap-around (scattering, noise beyond the
/// tolerance) are not recoverable.
pub fn recoverable_percent(
    reported: &[f32],
    truth: &FrameTruth,
    non_ambiguity: Real,
    max_wraps: u8,
    tolerance: Real,
) -> Real {
    let (mut measured, mut ok) = (0usize, 0usize);
    for (i, &r) in reported.iter().enumerate() {
        if r <= 0.0 {
            continue;
        }
        measured += 1;
        let Some(t) = truth.radial.get(i).copied().flatten() else { continue };
        let k = ((t as Real - r as Real) / non_ambiguity).round().max(0.0);
        let e = (r as Real + k * non_ambiguity - t as Real).abs();
        ok += (k <= max_wraps as Real && e <= tolerance) as usize;
    }
    if measured == 0 { 0.0 } else { 100.0 * ok as Real / measured as Real }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::OutcomeCounts;

    #[test]
    fn scores_count_what_they_say() {
        use PixelOutcome::*;
        let outcomes = vec![Kept, Kept, Unwrapped, Dropped, Kept];
        let radial = vec![2.0, 1.5, 9.0, 0.0, 3.0];
        let mut out = FilterOutput { outcomes, radial, counts: OutcomeCounts::default() };
        out.recount();
        let truth = FrameTruth {
            radial: vec![Some(2.01), Some(9.0), Some(9.02), Some(8.0), None],
            wraps: vec![0, 1, 1, 1, 0],
        };
        let s = score(&out, &[true; 5], &truth, 0.05).unwrap();
        assert_eq!(s.discarded_percent, 20.0);
        assert_eq!(s.output, 4);
        assert_eq!(s.wrong_kept_percent, 50.0); // pixel 1 (wrapped, kept) and 4 (no surface)
        assert_eq!(s.wrapped_kept_percent, 25.0);
        assert_eq!(s.gross_percent, 50.0); // pixel 1 (7.5 m off) and 4 (no surface)
        assert_eq!(s.wrapped, 3);
        assert_eq!(s.yield_percent, 40.0); // pixels 0 and 2 of 5 measured
        assert!((s.unwrapped_correct_percent - 100.0 / 3.0).abs() < 1e-9);
        assert!((s.rmse_correct - ((0.01f64.powi(2) + 0.02f64.powi(2)) / 2.0).sqrt()).abs() < 1e-6);
        assert!(score(&out, &[true; 4], &truth, 0.05).is_err());
    }

    #[test]
    fn recoverable_counts_wrap_multiples() {
        let truth = FrameTruth {
            radial: vec![Some(1.0), Some(8.52), Some(16.0), Some(3.0), None, Some(2.0)],
            wraps: vec![0, 1, 2, 0, 0, 0],
        };
        // 1.0 as is; 1.0 + 7.5 within 5 cm of 8.52; 1.0 + 15 ≠ 16; 2.8 is 20 cm off; no truth.
        let reported = [1.0, 1.0, 1.0, 2.8, 4.0, 0.0];
        let p = recoverable_percent(&reported, &truth, 7.5, 1, 0.05);
        assert!((p - 40.0).abs() < 1e-9, "{p}");
        let truth2 = FrameTruth { radial: vec![Some(16.0)], wraps: vec![2] };
        assert_eq!(recoverable_percent(&[1.0], &truth2, 7.5, 1, 0.05), 0.0);
        assert_eq!(recoverable_percent(&[1.0], &truth2, 7.5, 2, 0.05), 100.0);
    }
}
