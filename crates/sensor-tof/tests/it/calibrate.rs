//! White-wall calibration: synthetic walls generated from known parabolas (with noise and
//! unmeasured pixels) are recovered, the table matches the generator, and the recovered AAT
//! filter decides like the original.

use pointcloud::{RangeKind, Real};
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use sensor_tof::calibrate::{CalibrationOptions, fit_parabola, white_wall_table};
use sensor_tof::{
    AatConfig, AatRange, FilterConfig, Illumination, NegativeIllumination, Parabola, PixelOutcome,
    TofCamera, TofError, TofFilter, TofFrame,
};

/// A perpendicular white wall at depth `z`: amplitude `aw(x, y) / r²` (r the depth or the
/// radial distance) times `1 + noise`, a fraction `missing` of the pixels unmeasured.
fn wall(
    truth: &Parabola,
    z: Real,
    range: AatRange,
    noise: Real,
    missing: f64,
    seed: u64,
) -> TofFrame {
    let c = TofCamera::sr3000();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let normal = Normal::new(0.0, noise.max(1e-300)).unwrap();
    let (mut rr, mut aa) = (Vec::new(), Vec::new());
    for row in 0..c.height {
        for col in 0..c.width {
            let k = c.ray(col, row).norm();
            let r = match range {
                AatRange::Depth => z,
                AatRange::Radial => z * k,
            };
            let aw = truth.eval(col as Real, row as Real);
            let e = if noise > 0.0 { normal.sample(&mut rng) } else { 0.0 };
            let measured = !rng.random_bool(missing);
            rr.push(if measured { z as f32 } else { 0.0 });
            aa.push(((aw / (r * r)) * (1.0 + e)).max(0.0) as f32);
        }
    }
    TofFrame::new(c, RangeKind::Depth, rr, aa).unwrap()
}

fn truth() -> Parabola {
    Parabola { a_hat: 12_000.0, delta_x: 84.0, delta_y: 63.5, curvature: 0.4 }
}

#[test]
fn a_noisy_wall_with_holes_gives_back_its_parabola() {
    let t = truth();
    for (z, range) in [(1.0, AatRange::Depth), (2.7, AatRange::Depth), (1.8, AatRange::Radial)] {
        let f = wall(&t, z, range, 0.01, 0.05, 7);
        let options = CalibrationOptions { range, ..Default::default() };
        let c = fit_parabola(&f, &options).unwrap();
        let p = c.parabola;
        assert!((p.a_hat / t.a_hat - 1.0).abs() < 0.005, "{z} {range:?}: {p:?}");
        assert!((p.delta_x - t.delta_x).abs() < 0.5, "{p:?}");
        assert!((p.delta_y - t.delta_y).abs() < 0.5, "{p:?}");
        assert!((p.curvature / t.curvature - 1.0).abs() < 0.02, "{p:?}");
        // The residual is the noise: 1 % of aw, which averages ≈ 8,000 here.
        assert!(c.residual_rms > 40.0 && c.residual_rms < 150.0, "{}", c.residual_rms);
        let measured = f.num_measured();
        assert_eq!(c.used_pixels, measured);
        assert!((c.used_fraction - measured as Real / 25_344.0).abs() < 1e-12);
        assert!(c.used_fraction > 0.9 && c.used_fraction < 0.99);
    }
}

#[test]
fn the_wrong_range_kind_biases_the_fit() {
    // A wall generated with radial fall-off and fitted with depth: the corners look darker than
    // they are, so the curvature comes out too large. The option matters.
    let t = truth();
    let f = wall(&t, 1.5, AatRange::Radial, 0.0, 0.0, 1);
    let depth = fit_parabola(&f, &CalibrationOptions::default()).unwrap();
    let radial =
        fit_parabola(&f, &CalibrationOptions { range: AatRange::Radial, ..Default::default() })
            .unwrap();
    assert!((radial.parabola.curvature / t.curvature - 1.0).abs() < 1e-6, "{radial:?}");
    assert!(depth.parabola.curvature > 1.05 * t.curvature, "{depth:?}");
    assert!(radial.residual_rms < 1e-6 * t.a_hat && depth.residual_rms > 1.0);
}

#[test]
fn eq_2_5_with_fixed_curvature() {
    let t = Parabola { a_hat: 20_000.0, delta_x: 88.0, delta_y: 61.0, curvature: 1.0 };
    let f = wall(&t, 1.2, AatRange::Depth, 0.01, 0.1, 3);
    let c = fit_parabola(&f, &CalibrationOptions { fixed_curvature: true, ..Default::default() })
        .unwrap();
    assert_eq!(c.parabola.curvature, 1.0);
    assert!(c.fixed_curvature);
    assert!((c.parabola.a_hat / t.a_hat - 1.0).abs() < 0.005, "{:?}", c.parabola);
    assert!((c.parabola.delta_x - 88.0).abs() < 0.5 && (c.parabola.delta_y - 61.0).abs() < 0.5);
    // Fixing the curvature of a wall whose curvature is not 1 shows in the residual.
    let f = wall(&truth(), 1.2, AatRange::Depth, 0.0, 0.0, 3);
    let free = fit_parabola(&f, &CalibrationOptions::default()).unwrap();
    let fixed =
        fit_parabola(&f, &CalibrationOptions { fixed_curvature: true, ..Default::default() });
    match fixed {
        Ok(fixed) => assert!(fixed.residual_rms > 100.0 * free.residual_rms.max(1e-6)),
        Err(e) => assert!(matches!(e, TofError::BadImage { .. })),
    }
}

#[test]
fn trimming_ignores_a_specular_spot() {
    let t = truth();
    let mut f = wall(&t, 1.0, AatRange::Depth, 0.01, 0.0, 11);
    // A specular reflection: a 12 × 12 patch three times too bright, off centre.
    let mut amp = f.amplitude().to_vec();
    for row in 20..32 {
        for col in 120..132 {
            amp[row * 176 + col] *= 3.0;
        }
    }
    f = TofFrame::new(*f.camera(), f.kind(), f.range().to_vec(), amp).unwrap();
    let plain = fit_parabola(&f, &CalibrationOptions::default()).unwrap();
    let trimmed =
        fit_parabola(&f, &CalibrationOptions { trim_sigma: Some(3.0), ..Default::default() })
            .unwrap();
    let err = |p: &Parabola| (p.delta_x - t.delta_x).hypot(p.delta_y - t.delta_y);
    assert!(err(&trimmed.parabola) < 0.5, "{:?}", trimmed.parabola);
    assert!(err(&plain.parabola) > 2.0 * err(&trimmed.parabola), "{:?}", plain.parabola);
    assert!(trimmed.used_pixels <= 25_344 - 144 && trimmed.used_pixels > 24_000);
}

#[test]
fn degenerate_walls_are_refused() {
    let c = TofCamera::sr3000();
    let n = c.num_pixels();
    let opts = CalibrationOptions::default();
    // Nothing measured.
    let f = TofFrame::new(c, RangeKind::Depth, vec![0.0; n], vec![100.0; n]).unwrap();
    assert!(matches!(fit_parabola(&f, &opts), Err(TofError::BadImage { .. })));
    assert!(white_wall_table(&f, &opts).is_err());
    // Too few pixels.
    let mut r = vec![0.0; n];
    for v in r.iter_mut().step_by(500) {
        *v = 1.0;
    }
    let f = TofFrame::new(c, RangeKind::Depth, r, vec![100.0; n]).unwrap();
    assert!(fit_parabola(&f, &opts).is_err());
    // Brighter at the edges than in the middle: k ≤ 0.
    let inverted = Parabola { a_hat: 1000.0, delta_x: 88.0, delta_y: 72.0, curvature: -0.3 };
    let f = wall(&inverted, 1.0, AatRange::Depth, 0.0, 0.0, 1);
    let e = fit_parabola(&f, &opts).unwrap_err();
    assert!(e.to_string().contains("curvature"), "{e}");
    // A flat wall: k = 0.
    let f = TofFrame::new(c, RangeKind::Depth, vec![1.0; n], vec![500.0; n]).unwrap();
    assert!(fit_parabola(&f, &opts).is_err());
    // Only one row measured: the rows' direction is undetermined.
    let mut r = vec![0.0; n];
    for v in &mut r[176 * 50..176 * 51] {
        *v = 1.0;
    }
    let amp: Vec<f32> = (0..n).map(|i| 10_000.0 - ((i % 176) as f32 - 80.0).powi(2)).collect();
    let f = TofFrame::new(c, RangeKind::Depth, r, amp).unwrap();
    assert!(fit_parabola(&f, &CalibrationOptions { min_pixels: 4, ..opts }).is_err());
    // Absurd options.
    let f = wall(&truth(), 1.0, AatRange::Depth, 0.0, 0.0, 1);
    for t in [0.0, -1.0, Real::NAN] {
        assert!(fit_parabola(&f, &CalibrationOptions { trim_sigma: Some(t), ..opts }).is_err());
    }
}

#[test]
fn the_table_equals_the_generator_within_noise() {
    let t = truth();
    let f = wall(&t, 2.0, AatRange::Depth, 0.01, 0.05, 5);
    let table = white_wall_table(&f, &CalibrationOptions::default()).unwrap();
    assert_eq!((table.width, table.height, table.values.len()), (176, 144, 176 * 144));
    let mut worst_measured: Real = 0.0;
    let mut worst_filled: Real = 0.0;
    for (i, &v) in table.values.iter().enumerate() {
        let (col, row) = f.col_row(i);
        let aw = t.eval(col as Real, row as Real);
        let rel = (v as Real / aw - 1.0).abs();
        if f.range()[i] > 0.0 {
            worst_measured = worst_measured.max(rel);
        } else {
            worst_filled = worst_filled.max(rel);
        }
    }
    // 1 % Gaussian noise over ~24,000 pixels: the worst is about 4.5 σ.
    assert!(worst_measured < 0.06, "{worst_measured}");
    // The parabola fills the holes far better than one noisy pixel.
    assert!(worst_filled < 0.005, "{worst_filled}");
    // A wall without holes needs no fit: every value is the pixel's own.
    let full = wall(&t, 2.0, AatRange::Depth, 0.0, 0.0, 5);
    let table = white_wall_table(&full, &CalibrationOptions::default()).unwrap();
    for (i, &v) in table.values.iter().enumerate() {
        let want = full.amplitude()[i] as Real * 4.0;
        assert!((v as Real - want).abs() <= 1e-3 * want, "pixel {i}");
    }
}

/// A test scene: every pixel sees a surface of random reflectivity at a random true distance up
/// to 14 m (so about half wrap around once), lit by `truth`.
fn scene(truth: &Parabola, seed: u64) -> TofFrame {
    let c = TofCamera::sr3000();
    let amb = c.non_ambiguity_range();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (mut rr, mut aa) = (Vec::new(), Vec::new());
    for row in 0..c.height {
        for col in 0..c.width {
            let k = c.ray(col, row).norm();
            let true_radial: Real = rng.random_range(0.7..14.0);
            let rho: Real = rng.random_range(0.05..1.0);
            let z = true_radial / k;
            rr.push((true_radial.rem_euclid(amb) / k) as f32);
            aa.push((rho * truth.eval(col as Real, row as Real).max(0.0) / (z * z)) as f32);
        }
    }
    TofFrame::new(c, RangeKind::Depth, rr, aa).unwrap()
}

fn outcomes(illumination: Illumination, frame: &TofFrame) -> Vec<PixelOutcome> {
    let config = AatConfig {
        illumination,
        threshold: 0.2,
        range: AatRange::Depth,
        negative: NegativeIllumination::Clamp(1.0),
    };
    let f =
        TofFilter::new(frame.camera(), RangeKind::Depth, &FilterConfig::aat_unwrap(config, None))
            .unwrap();
    f.run(frame).unwrap().outcomes
}

#[test]
fn the_recovered_filter_decides_like_the_original() {
    let t = truth();
    let c = fit_parabola(
        &wall(&t, 1.3, AatRange::Depth, 0.01, 0.05, 21),
        &CalibrationOptions::default(),
    )
    .unwrap();
    let table = white_wall_table(
        &wall(&t, 1.3, AatRange::Depth, 0.01, 0.05, 22),
        &CalibrationOptions::default(),
    )
    .unwrap();
    let frame = scene(&t, 99);
    let original = outcomes(Illumination::Parabola(t), &frame);
    let unwrapped = original.iter().filter(|&&o| o == PixelOutcome::Unwrapped).count();
    assert!(unwrapped > 5_000 && unwrapped < 20_000, "{unwrapped}: a scene with both kinds");
    for (name, illumination) in
        [("parabola", Illumination::Parabola(c.parabola)), ("table", Illumination::Table(table))]
    {
        let got = outcomes(illumination, &frame);
        let differ = got.iter().zip(&original).filter(|(a, b)| a != b).count();
        // Only pixels within the calibration error of the threshold can flip.
        assert!(differ < 25_344 / 100, "{name}: {differ} pixels decided differently");
    }
    // The calibration's own AAT config is the same filter.
    assert_eq!(c.aat_config(0.2).illumination, Illumination::Parabola(c.parabola));
    // Serde: the JSON the CLI writes reads back.
    let json = serde_json::to_string(&c).unwrap();
    assert_eq!(serde_json::from_str::<sensor_tof::calibrate::Calibration>(&json).unwrap(), c);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    /// Noise-free walls of any plausible parabola are recovered exactly (the generator is the
    /// oracle).
    #[test]
    fn any_noise_free_parabola_is_recovered(
        a_hat in 500.0..50_000.0f64,
        dx in 40.0..136.0f64,
        dy in 30.0..114.0f64,
        rel_k in 0.05..0.95f64,
        z in 0.5..7.0f64,
    ) {
        // Curvature such that the dimmest corner keeps (1 − rel_k) of Â: aw > 0 everywhere.
        let far = [(0.0, 0.0), (175.0, 0.0), (0.0, 143.0), (175.0, 143.0)]
            .iter()
            .map(|(x, y): &(f64, f64)| (x - dx).powi(2) + (y - dy).powi(2))
            .fold(0.0, f64::max);
        let t = Parabola { a_hat, delta_x: dx, delta_y: dy, curvature: rel_k * a_hat / far };
        let f = wall(&t, z, AatRange::Depth, 0.0, 0.02, 0);
        let c = fit_parabola(&f, &CalibrationOptions::default()).unwrap();
        let p = c.parabola;
        prop_assert!((p.a_hat / a_hat - 1.0).abs() < 1e-4, "{:?} vs {:?}", p, t);
        prop_assert!((p.delta_x - dx).abs() < 0.05 && (p.delta_y - dy).abs() < 0.05, "{:?} vs {:?}", p, t);
        prop_assert!((p.curvature / t.curvature - 1.0).abs() < 1e-3, "{:?} vs {:?}", p, t);
    }
}

/// The simulator and the calibration agree: a simulated white wall at 1 m (noise, saturation,
/// the 4 % light floor in the corners) gives back the SR-3100 parabola the simulator was built
/// with (Eq 2.5: Â = 12,000, δ = (88, 72), k = 1).
#[test]
fn calibration_recovers_the_simulated_camera() {
    let scene = sensor_tof::scenes::white_wall(1.0).unwrap();
    let sim = sensor_tof::sim::TofSimulator::new(scene.sim.clone()).unwrap();
    let frame = sim.simulate(&scene.scene, &scene.pose, 5).unwrap().frame;
    // The floored corners are not on the parabola: trim them away.
    let options = CalibrationOptions { trim_sigma: Some(3.0), ..CalibrationOptions::default() };
    let c = fit_parabola(&frame, &options).unwrap();
    let p = c.parabola;
    assert!((p.a_hat / 12_000.0 - 1.0).abs() < 0.02, "{p:?}");
    assert!((p.delta_x - 88.0).abs() < 1.0 && (p.delta_y - 72.0).abs() < 1.0, "{p:?}");
    assert!((p.curvature - 1.0).abs() < 0.05, "{p:?}");
    assert!(sensor_tof::scenes::white_wall(0.0).is_err());
}
