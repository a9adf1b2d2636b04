//! Two-frequency unwrapping on synthetic frames: planes at known distances, amplitude from the
//! thesis's model `a = ρ·aw_p / z²` (Eq 2.5 parabola of the SR-3000), reported range = true
//! range mod R_amb, seeded noise.

use pointcloud::{PinholeIntrinsics, RangeKind, Real};
use proptest::prelude::*;
use rand::{Rng as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution as _, Normal};
use sensor_tof::two_freq::{
    Combination, MAX_WRAPS, SR3000_PHASE_NOISE_RAD, TwoFreqConfig, TwoFreqUnwrapper,
    candidate_separation, choose_wraps, unwrap_two_frequencies,
};
use sensor_tof::{
    FilterOutput, Parabola, PixelOutcome, TofCamera, TofError, TofFrame, non_ambiguity_range,
};
use std::f64::consts::TAU;

fn camera(frequency_hz: Real) -> TofCamera {
    TofCamera { modulation_hz: frequency_hz, ..TofCamera::sr3000() }
}

/// A frame of `camera` whose pixel `i` sees a surface of reflectivity `rho` at true radial
/// distance `truth[i]`, with range noise of phase standard deviation `phase_noise`.
fn synth(
    camera: &TofCamera,
    kind: RangeKind,
    truth: &[Real],
    rho: Real,
    phase_noise: Real,
    rng: &mut ChaCha8Rng,
) -> TofFrame {
    let amb = camera.non_ambiguity_range();
    let parabola = Parabola::sr3000();
    let noise = Normal::new(0.0, phase_noise * amb / TAU).unwrap();
    let (mut range, mut amplitude) = (Vec::new(), Vec::new());
    for (i, &t) in truth.iter().enumerate() {
        let (col, row) = ((i % camera.width as usize) as u32, (i / camera.width as usize) as u32);
        let k = camera.ray(col, row).norm();
        let reported = (t + noise.sample(rng)).rem_euclid(amb);
        range.push(match kind {
            RangeKind::Radial => reported as f32,
            RangeKind::Depth => (reported / k) as f32,
        });
        let z = t / k;
        let aw = parabola.eval(col as Real, row as Real).max(0.0);
        amplitude.push((rho * aw / (z * z)) as f32);
    }
    TofFrame::new(*camera, kind, range, amplitude).unwrap()
}

/// Four planes side by side (columns), at depths 3, 9, 16 and 24.5 m: 0, 1, 2 and 3 wraps at
/// 20 MHz. Returns the true radial distances.
fn four_planes(camera: &TofCamera) -> Vec<Real> {
    let depths = [3.0, 9.0, 16.0, 24.5];
    let w = camera.width as usize;
    (0..camera.num_pixels())
        .map(|i| {
            let (col, row) = ((i % w) as u32, (i / w) as u32);
            depths[col as usize * 4 / w] * camera.ray(col, row).norm()
        })
        .collect()
}

#[test]
fn noise_free_planes_with_0_to_3_wraps_are_recovered_exactly() {
    let config = TwoFreqConfig::sr3000();
    let (ca, cb) = (camera(20e6), camera(5e6));
    let truth = four_planes(&ca);
    let r_a = non_ambiguity_range(20e6);
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    for kind in [RangeKind::Depth, RangeKind::Radial] {
        let a = synth(&ca, kind, &truth, 0.5, 0.0, &mut rng);
        let b = synth(&cb, kind, &truth, 0.5, 0.0, &mut rng);
        let mut out = FilterOutput::default();
        unwrap_two_frequencies(&a, &b, &config, &mut out).unwrap();
        let prepared = TwoFreqUnwrapper::new(&ca, kind, &config).unwrap().run(&a, &b).unwrap();
        let mut wraps_seen = [0usize; 4];
        for (i, &t) in truth.iter().enumerate() {
            let wraps = (t / r_a).floor() as usize;
            wraps_seen[wraps] += 1;
            let want = if wraps == 0 { PixelOutcome::Kept } else { PixelOutcome::Unwrapped };
            assert_eq!(out.outcomes[i], want, "pixel {i} at {t} m");
            assert!(
                (out.radial[i] as Real - t).abs() < 1e-3,
                "pixel {i}: {} vs {t}",
                out.radial[i]
            );
            assert_eq!(prepared.outcomes[i], out.outcomes[i]);
            assert!((prepared.radial[i] - out.radial[i]).abs() < 1e-4);
        }
        assert!(wraps_seen.iter().all(|&c| c > 1000), "{wraps_seen:?}");
        assert_eq!(out.counts.kept, wraps_seen[0]);
        assert_eq!(out.counts.unwrapped, truth.len() - wraps_seen[0]);
        assert_eq!(out.counts.dropped, 0);
    }
}

#[test]
fn the_reference_frame_decides_kept_or_unwrapped() {
    // With the 5 MHz frame as `a` nothing below 29.98 m has wrapped in `a`: all pixels kept.
    let mut config = TwoFreqConfig::sr3000();
    (config.frequency_a_hz, config.frequency_b_hz) = (5e6, 20e6);
    let (ca, cb) = (camera(5e6), camera(20e6));
    let truth = four_planes(&ca);
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let a = synth(&ca, RangeKind::Depth, &truth, 0.5, 0.0, &mut rng);
    let b = synth(&cb, RangeKind::Depth, &truth, 0.5, 0.0, &mut rng);
    let mut out = FilterOutput::default();
    unwrap_two_frequencies(&a, &b, &config, &mut out).unwrap();
    assert_eq!(out.counts.kept, truth.len());
    for (r, t) in out.radial.iter().zip(&truth) {
        assert!((*r as Real - t).abs() < 1e-3);
    }
}

/// Runs the preset on the four planes with the preset's noise; returns (accepted share,
/// rmse of the accepted pixels).
fn noisy_run(combination: Combination, seed: u64) -> (Real, Real) {
    let mut config = TwoFreqConfig::sr3000();
    config.combination = combination;
    let (ca, cb) = (camera(20e6), camera(5e6));
    let truth = four_planes(&ca);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let a = synth(&ca, RangeKind::Depth, &truth, 0.5, SR3000_PHASE_NOISE_RAD, &mut rng);
    let b = synth(&cb, RangeKind::Depth, &truth, 0.5, SR3000_PHASE_NOISE_RAD, &mut rng);
    let mut out = FilterOutput::default();
    unwrap_two_frequencies(&a, &b, &config, &mut out).unwrap();
    let (mut n, mut se) = (0usize, 0.0);
    for (i, &t) in truth.iter().enumerate() {
        if out.outcomes[i] == PixelOutcome::Dropped {
            continue;
        }
        // No wrong wrap count: every accepted pixel is within the tolerance of the truth.
        let e = out.radial[i] as Real - t;
        assert!(e.abs() <= config.tolerance_m, "pixel {i}: {} vs {t}", out.radial[i]);
        n += 1;
        se += e * e;
    }
    (n as Real / truth.len() as Real, (se / n as Real).sqrt())
}

#[test]
fn noise_within_the_tolerance_is_accepted_and_averaged() {
    let sigma_a = SR3000_PHASE_NOISE_RAD * non_ambiguity_range(20e6) / TAU;
    let (share, rmse_iv) = noisy_run(Combination::InverseVariance, 3);
    // The tolerance is three standard deviations of the difference: ≈ 0.3 % dropped.
    assert!(share > 0.99, "{share}");
    let (_, rmse_first) = noisy_run(Combination::FirstFrame, 3);
    let (_, rmse_amp) = noisy_run(Combination::Amplitude, 3);
    // Inverse-variance weights beat the 20 MHz frame alone (σ_a), which beats equal weights
    // (√17/2 · σ_a with the 4× noisier 5 MHz frame).
    assert!(rmse_iv < rmse_first && rmse_first < rmse_amp, "{rmse_iv} {rmse_first} {rmse_amp}");
    assert!((rmse_first / sigma_a - 1.0).abs() < 0.05, "{rmse_first} vs {sigma_a}");
    assert!((rmse_amp / sigma_a - 17f64.sqrt() / 2.0).abs() < 0.15, "{rmse_amp}");
}

#[test]
fn pixels_that_saw_nothing_are_mostly_dropped() {
    let config = TwoFreqConfig::sr3000();
    let (ca, cb) = (camera(20e6), camera(5e6));
    let n = ca.num_pixels();
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let mut random_frame = |c: &TofCamera| {
        let amb = c.non_ambiguity_range();
        let range = (0..n).map(|_| rng.random_range(1e-3..amb) as f32).collect();
        let amplitude = (0..n).map(|_| rng.random_range(0.0..40.0) as f32).collect();
        TofFrame::new(*c, RangeKind::Radial, range, amplitude).unwrap()
    };
    let (a, b) = (random_frame(&ca), random_frame(&cb));
    let mut out = FilterOutput::default();
    unwrap_two_frequencies(&a, &b, &config, &mut out).unwrap();
    let passed = (n - out.counts.dropped) as Real / n as Real;
    // Expected about 2 · tolerance / R_a ≈ 6 %.
    let expect = 2.0 * config.tolerance_m / non_ambiguity_range(20e6);
    assert!((passed - expect).abs() < 0.015, "{passed} vs {expect}");
    // An amplitude threshold above the noise removes them.
    let strict = TwoFreqConfig { min_amplitude: Some(40.0), ..config };
    unwrap_two_frequencies(&a, &b, &strict, &mut out).unwrap();
    assert_eq!(out.counts.dropped, n);
    // Unmeasured pixels (range 0) are dropped too.
    let zero = TofFrame::new(ca, RangeKind::Radial, vec![0.0; n], vec![100.0; n]).unwrap();
    unwrap_two_frequencies(&zero, &b, &config, &mut out).unwrap();
    assert_eq!(out.counts.dropped, n);
}

#[test]
fn mismatched_frames_and_absurd_configs_are_refused() {
    let config = TwoFreqConfig::sr3000();
    let (ca, cb) = (camera(20e6), camera(5e6));
    let truth = four_planes(&ca);
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let a = synth(&ca, RangeKind::Depth, &truth, 0.5, 0.0, &mut rng);
    let b = synth(&cb, RangeKind::Depth, &truth, 0.5, 0.0, &mut rng);
    let mut out = FilterOutput::default();
    let mismatch = |r: Result<(), TofError>| matches!(r, Err(TofError::Mismatch { .. }));
    // Same frequency twice.
    assert!(mismatch(unwrap_two_frequencies(&a, &a, &config, &mut out)));
    // Swapped.
    assert!(mismatch(unwrap_two_frequencies(&b, &a, &config, &mut out)));
    // Another size.
    let small = TofCamera::pinhole(10, 10, ca.intrinsics, 5e6).unwrap();
    let s = TofFrame::new(small, RangeKind::Depth, vec![1.0; 100], vec![1.0; 100]).unwrap();
    assert!(mismatch(unwrap_two_frequencies(&a, &s, &config, &mut out)));
    // Other intrinsics.
    let mut other = cb;
    other.intrinsics = PinholeIntrinsics { fx: cb.intrinsics.fx * 1.1, ..cb.intrinsics };
    let o =
        TofFrame::new(other, RangeKind::Depth, b.range().to_vec(), b.amplitude().to_vec()).unwrap();
    assert!(mismatch(unwrap_two_frequencies(&a, &o, &config, &mut out)));
    // Another range kind.
    let radial = b.converted(RangeKind::Radial);
    assert!(mismatch(unwrap_two_frequencies(&a, &radial, &config, &mut out)));
    // A prepared unwrapper refuses frames of another kind or size.
    let prepared = TwoFreqUnwrapper::new(&ca, RangeKind::Radial, &config).unwrap();
    assert!(mismatch(prepared.apply(&a, &b, &mut out)));
    let prepared = TwoFreqUnwrapper::new(&small, RangeKind::Depth, &config).unwrap();
    assert!(mismatch(prepared.apply(&a, &b, &mut out)));

    // Absurd configurations.
    let mut bad = |c: TwoFreqConfig| {
        matches!(c.validate(), Err(TofError::BadParameter { .. }))
            && matches!(
                unwrap_two_frequencies(&a, &b, &c, &mut out),
                Err(TofError::BadParameter { .. })
            )
    };
    assert!(bad(TwoFreqConfig { frequency_b_hz: 20e6, ..config }));
    assert!(bad(TwoFreqConfig { frequency_b_hz: Real::NAN, ..config }));
    assert!(bad(TwoFreqConfig { tolerance_m: Real::NAN, ..config }));
    assert!(bad(TwoFreqConfig { tolerance_m: -0.1, ..config }));
    assert!(bad(TwoFreqConfig { tolerance_m: 3.8, ..config })); // ≥ half the 7.49 m separation
    assert!(bad(TwoFreqConfig { max_range_m: 0.0, ..config }));
    assert!(bad(TwoFreqConfig { max_range_m: Real::INFINITY, ..config }));
    assert!(bad(TwoFreqConfig { max_range_m: 31.0, ..config })); // beyond the joint 29.98 m
    assert!(bad(TwoFreqConfig { max_range_m: 1e7, frequency_b_hz: 19e6, ..config }));
    assert!(bad(TwoFreqConfig { min_amplitude: Some(Real::NAN), ..config }));
    assert!(TwoFreqConfig::for_pair(20e6, 19e6, 100.0, 1.0).is_err()); // noise too large
    assert!(TwoFreqConfig::for_pair(20e6, 19e6, 100.0, -1.0).is_err());
    assert!(
        TwoFreqUnwrapper::new(&ca, RangeKind::Depth, &TwoFreqConfig { tolerance_m: 5.0, ..config })
            .is_err()
    );
    // The search itself refuses absurd inputs instead of looping.
    assert_eq!(choose_wraps(1.0, 1.0, 7.5, 1e-9, 1e6), None);
    assert_eq!(choose_wraps(Real::NAN, 1.0, 7.5, 30.0, 29.0), None);
    assert_eq!(choose_wraps(-1.0, 1.0, 7.5, 30.0, 29.0), None);
}

/// The smallest disagreement of a wrong pair, by trying every pair of wrap-count differences.
fn brute_separation(ra: Real, rb: Real, max_range: Real) -> Real {
    let (na, nb) = ((max_range / ra) as i64 + 1, (max_range / rb) as i64 + 1);
    let mut best = Real::INFINITY;
    for dn in -na..=na {
        for dm in -nb..=nb {
            let (x, y) = (dn as Real * ra, dm as Real * rb);
            let spread = x.max(y).max(0.0) - x.min(y).min(0.0);
            if (dn, dm) != (0, 0) && spread <= max_range {
                best = best.min((x - y).abs());
            }
        }
    }
    best
}

/// The candidate pair with the smallest disagreement, by trying every pair.
fn brute_choice(
    ra: Real,
    rb: Real,
    big_a: Real,
    big_b: Real,
    max_range: Real,
) -> Option<(u32, u32, Real)> {
    let mut best: Option<(u32, u32, Real)> = None;
    let mut n = 0;
    while ra + n as Real * big_a <= max_range {
        let mut m = 0;
        while rb + m as Real * big_b <= max_range {
            let e = ((ra + n as Real * big_a) - (rb + m as Real * big_b)).abs();
            if best.is_none_or(|b| e < b.2) {
                best = Some((n, m, e));
            }
            m += 1;
        }
        n += 1;
    }
    best
}

const SR3000_MHZ: [Real; 7] = [5.0, 6.6, 10.0, 19.0, 20.0, 21.0, 30.0];

#[test]
fn separations_in_the_module_doc() {
    let sep = |f: Real, d: Real| candidate_separation(20e6, f * 1e6, d).unwrap();
    let r_a = non_ambiguity_range(20e6);
    assert!((sep(5.0, 29.9) - r_a).abs() < 1e-9);
    assert!((sep(10.0, 14.9) - r_a).abs() < 1e-9);
    assert!((sep(6.6, 22.5) - r_a).abs() < 1e-9);
    assert!((sep(6.6, 29.9) - 0.227).abs() < 1e-3);
    assert!((sep(19.0, 29.9) - 0.394).abs() < 1e-3);
    assert!((sep(21.0, 140.0) - 0.357).abs() < 1e-3);
    assert!((sep(30.0, 14.9) - 2.498).abs() < 1e-3);
    assert_eq!(sep(10.0, 15.0), 0.0);
    // The preset's pair has the widest margin up to 30 m, in units of the noise difference.
    let merit = |f: Real| sep(f, 29.9) / r_a.hypot(non_ambiguity_range(f * 1e6));
    for f in [6.6, 19.0, 21.0] {
        assert!(merit(5.0) > 6.0 * merit(f), "{f} MHz");
    }
}

fn pair_config() -> impl Strategy<Value = TwoFreqConfig> {
    // (a, b, max range) with valid separations; the tolerance from the preset's phase noise.
    prop_oneof![
        Just((20e6, 5e6, 29.5)),
        Just((20e6, 10e6, 14.5)),
        Just((20e6, 6.6e6, 22.0)),
        Just((20e6, 19e6, 100.0)),
        Just((21e6, 20e6, 60.0)),
        Just((5e6, 20e6, 29.5)),
    ]
    .prop_map(|(fa, fb, d)| TwoFreqConfig::for_pair(fa, fb, d, SR3000_PHASE_NOISE_RAD).unwrap())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn separation_matches_brute_force(
        ia in 0usize..7, ib in 0usize..7, max_range in 0.5..200.0f64,
    ) {
        prop_assume!(ia != ib);
        let (fa, fb) = (SR3000_MHZ[ia] * 1e6, SR3000_MHZ[ib] * 1e6);
        let fast = candidate_separation(fa, fb, max_range).unwrap();
        let slow = brute_separation(non_ambiguity_range(fa), non_ambiguity_range(fb), max_range);
        prop_assert!((fast - slow).abs() < 1e-9 || (fast.is_infinite() && slow.is_infinite()),
            "{fast} vs {slow}");
    }

    #[test]
    fn candidate_search_matches_brute_force(
        config in pair_config(), ua in 0.0..1.0f64, ub in 0.0..1.0f64,
    ) {
        let (big_a, big_b) = config.non_ambiguity_ranges();
        let (ra, rb) = (ua * big_a, ub * big_b);
        let d = config.max_range_m;
        let fast = choose_wraps(ra, rb, big_a, big_b, d);
        let slow = brute_choice(ra, rb, big_a, big_b, d);
        prop_assert_eq!(fast.is_some(), slow.is_some());
        if let (Some(f), Some(s)) = (fast, slow) {
            prop_assert!((f.disagreement - s.2).abs() < 1e-9, "{f:?} vs {s:?}");
            prop_assert!(ra + f.wraps_a as Real * big_a <= d && rb + f.wraps_b as Real * big_b <= d);
        }
    }

    /// Oracle: the true range. Noise below half the tolerance in each frame.
    #[test]
    fn random_true_ranges_are_recovered_within_the_tolerance(
        config in pair_config(),
        radial in any::<bool>(),
        truth in prop::collection::vec(0.0..1.0f64, 16),
        noise in prop::collection::vec(-1.0..1.0f64, 32),
    ) {
        let tol = config.tolerance_m;
        let d = config.max_range_m;
        let k = PinholeIntrinsics::from_fov(16, 1, 0.8, 0.05);
        let ca = TofCamera::pinhole(16, 1, k, config.frequency_a_hz).unwrap();
        let cb = TofCamera::pinhole(16, 1, k, config.frequency_b_hz).unwrap();
        let kind = if radial { RangeKind::Radial } else { RangeKind::Depth };
        let truth: Vec<Real> = truth.iter().map(|u| tol + u * (d - 2.0 * tol)).collect();
        let frame = |c: &TofCamera, off: usize| {
            let amb = c.non_ambiguity_range();
            let range = truth.iter().enumerate().map(|(i, t)| {
                let r = (t + noise[off + i] * 0.49 * tol).rem_euclid(amb);
                let kk = c.ray(i as u32, 0).norm();
                (if radial { r } else { r / kk }) as f32
            }).collect();
            TofFrame::new(*c, kind, range, vec![100.0; 16]).unwrap()
        };
        let (a, b) = (frame(&ca, 0), frame(&cb, 16));
        let mut out = FilterOutput::default();
        unwrap_two_frequencies(&a, &b, &config, &mut out).unwrap();
        let (big_a, _) = config.non_ambiguity_ranges();
        for (i, &t) in truth.iter().enumerate() {
            prop_assert!(out.outcomes[i].is_output(), "pixel {} at {} m dropped", i, t);
            prop_assert!((out.radial[i] as Real - t).abs() <= 0.5 * tol + 1e-4,
                "pixel {}: {} vs {}", i, out.radial[i], t);
            let a_wrapped = t + noise[i] * 0.49 * tol >= big_a;
            prop_assert_eq!(out.outcomes[i] == PixelOutcome::Unwrapped, a_wrapped);
        }
        let prepared = TwoFreqUnwrapper::new(&ca, kind, &config).unwrap().run(&a, &b).unwrap();
        prop_assert_eq!(&prepared.outcomes, &out.outcomes);
    }
}

#[test]
fn max_wraps_bounds_the_search() {
    let r_a = non_ambiguity_range(20e6);
    assert!(candidate_separation(20e6, 19e6, MAX_WRAPS as Real * r_a * 0.99).is_ok());
    assert!(candidate_separation(20e6, 19e6, MAX_WRAPS as Real * r_a * 1.01).is_err());
}
