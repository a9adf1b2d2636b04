//! The simulator against the physics it claims (thesis §2.5.4, Eqs 2.1–2.5).

use pointcloud::{Point3, Real, SensorPose};
use scene_sim::{Cuboid, Material, Scene, SceneBuilder, camera_pose_looking};
use sensor_tof::sim::{
    LowAmplitudeBias, Scattering, SimConfig, SunRegion, TofSimulator, oren_nayar_retro,
};
use sensor_tof::{AatConfig, FilterConfig, Parabola, TofFilter};

/// The camera at the origin at height 1 m looking along +x.
fn pose() -> SensorPose {
    camera_pose_looking(Point3::new(0.0, 0.0, 1.0), 0.0, 0.0)
}

/// A large wall perpendicular to the optical axis at depth `d`, of reflectivity `rho`.
fn wall(d: Real, rho: f32) -> Scene {
    let mut b = SceneBuilder::new("wall");
    let m = Material::new(rho, false).unwrap();
    b.add(
        "wall",
        Cuboid::axis_aligned(Point3::new(d, -50.0, -50.0), Point3::new(d + 0.1, 50.0, 50.0))
            .unwrap(),
        m,
    )
    .unwrap();
    b.build().unwrap()
}

fn centre(row: usize, col: usize) -> usize {
    row * 176 + col
}

/// Mean and standard deviation of `values`.
fn stats(values: &[Real]) -> (Real, Real) {
    let n = values.len() as Real;
    let mean = values.iter().sum::<Real>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<Real>() / (n - 1.0);
    (mean, var.sqrt())
}

#[test]
fn white_wall_at_one_metre_reproduces_eq_2_5() {
    let sim = TofSimulator::new(SimConfig::sr3000()).unwrap();
    let f = sim.simulate(&wall(1.0, 1.0), &pose(), 1).unwrap();
    let p = Parabola::sr3000();
    let floor = 0.04 * p.a_hat;
    let mut checked = 0;
    for row in (0..144).step_by(7) {
        for col in (0..176).step_by(5) {
            let i = centre(row, col);
            let want = p.eval(col as Real, row as Real).max(floor);
            let got = f.frame.amplitude()[i] as Real;
            // The amplitude noise is ≈ √(g B)/√2; 5 σ bound.
            let sigma = (0.06 * (300.0 + want) + 4.0).sqrt() / 2f64.sqrt();
            assert!(
                (got - want).abs() < 5.0 * sigma + 1e-3 * want,
                "({col}, {row}): {got} vs {want}"
            );
            assert!((f.frame.range()[i] - 1.0).abs() < 0.03, "depth {}", f.frame.range()[i]);
            checked += 1;
        }
    }
    assert!(checked > 500);
    // Intensity (Eq 2.3) = ambient + the signal's mean.
    let i = centre(72, 88);
    let b = f.frame.intensity().unwrap()[i] as Real;
    let want = 300.0 + p.eval(88.0, 72.0);
    assert!((b - want).abs() < 0.02 * want, "{b} vs {want}");
}

#[test]
fn a_wall_beyond_the_non_ambiguity_range_wraps_around() {
    let sim = TofSimulator::new(SimConfig::sr3000()).unwrap();
    let amb = sim.config().camera.non_ambiguity_range();
    let f = sim.simulate(&wall(9.0, 0.85), &pose(), 2).unwrap();
    let i = centre(71, 87);
    let r = f.frame.radial(i);
    assert!((r - (f.truth.radial[i].unwrap() as Real - amb)).abs() < 0.15, "{r}");
    assert!((f.frame.depth(i) - (9.0 - amb)).abs() < 0.15, "{}", f.frame.depth(i));
    assert_eq!(f.truth.wraps[i], 1);
    assert!(f.truth.wraps.iter().all(|&w| w == 1));
    let wrapped_near = (0..f.frame.range().len()).filter(|&i| f.frame.depth(i) < 2.5).count();
    assert!(wrapped_near > f.frame.range().len() * 9 / 10, "{wrapped_near}");
}

#[test]
fn amplitude_falls_as_one_over_r_squared() {
    let sim = TofSimulator::new(SimConfig::sr3000()).unwrap();
    let mean_centre = |d: Real| {
        let f = sim.simulate(&wall(d, 0.5), &pose(), 3).unwrap();
        let mut v = Vec::new();
        for row in 66..78 {
            for col in 82..94 {
                v.push(f.frame.amplitude()[centre(row, col)] as Real);
            }
        }
        stats(&v).0
    };
    let (a1, a2, a4) = (mean_centre(1.5), mean_centre(3.0), mean_centre(6.0));
    assert!((a1 / a2 - 4.0).abs() < 0.1, "{a1} / {a2}");
    assert!((a2 / a4 - 4.0).abs() < 0.3, "{a2} / {a4}");
}

#[test]
fn noise_calibration() {
    // A 25 % wall at 3 m: the centre pixel's range over many seeds.
    let sim = TofSimulator::new(SimConfig::sr3000()).unwrap();
    let scene = wall(3.0, 0.25);
    let hits = sim.trace(&scene, &pose()).unwrap();
    let i = centre(72, 88);
    let r: Vec<Real> = (0..400).map(|s| sim.render(&hits, s).unwrap().frame.depth(i)).collect();
    let (mean, sigma) = stats(&r);
    println!(
        "25 % wall at 3 m, centre pixel: mean depth {mean:.4} m, sigma {:.2} cm",
        sigma * 100.0
    );
    assert!((mean - 3.0).abs() < 0.01, "{mean}");
    assert!((0.01..=0.025).contains(&sigma), "{sigma}");
}

#[test]
fn the_aat_keeps_a_near_wall_and_drops_a_wrapped_one() {
    let sim = TofSimulator::new(SimConfig::sr3000()).unwrap();
    let cam = sim.config().camera;
    let filter =
        TofFilter::new(&cam, pointcloud::RangeKind::Depth, &FilterConfig::aat(AatConfig::sr3000()))
            .unwrap();
    let near = sim.simulate(&wall(3.0, 0.5), &pose(), 4).unwrap();
    let out = filter.run(&near.frame).unwrap();
    let n = cam.num_pixels();
    assert!(out.counts.kept as Real > 0.99 * n as Real, "{:?}", out.counts);
    let far = sim.simulate(&wall(9.0, 0.5), &pose(), 5).unwrap();
    let out = filter.run(&far.frame).unwrap();
    // Only the far corners, where the parabola is negative, pass Eq 2.4 taken literally.
    let aw_negative = (0..n)
        .filter(|&i| {
            let (c, r) = far.frame.col_row(i);
            Parabola::sr3000().eval(c as Real, r as Real) <= 0.0
        })
        .count();
    assert!(out.counts.kept <= aw_negative + n / 100, "{:?} vs {aw_negative}", out.counts);
    assert!(out.counts.dropped > n * 3 / 4);
}

/// A bright box close to the camera on the left half of the image before a dark wall.
fn box_before_wall(with_box: bool) -> Scene {
    let mut b = SceneBuilder::new("box");
    b.add(
        "wall",
        Cuboid::axis_aligned(Point3::new(3.5, -50.0, -50.0), Point3::new(3.6, 50.0, 50.0)).unwrap(),
        Material::new(0.1, false).unwrap(),
    )
    .unwrap();
    if with_box {
        // Left of the image = world +y for a camera looking along +x.
        let bx =
            Cuboid::axis_aligned(Point3::new(0.8, 0.0, 0.0), Point3::new(1.2, 1.0, 2.0)).unwrap();
        b.add("box", bx, Material::WHITE_PAPER).unwrap();
    }
    b.build().unwrap()
}

#[test]
fn scattering_makes_dark_far_pixels_beside_a_bright_box_read_too_close() {
    let mut cfg = SimConfig::sr3000();
    cfg.scattering = Some(Scattering::sr3000());
    cfg.low_amplitude_bias = None;
    let sim = TofSimulator::new(cfg).unwrap();
    let with = sim.simulate(&box_before_wall(true), &pose(), 6).unwrap();
    let without = sim.simulate(&box_before_wall(false), &pose(), 6).unwrap();
    // Wall pixels just right of the box edge.
    let mut err_with = Vec::new();
    let mut err_without = Vec::new();
    for i in 0..with.truth.radial.len() {
        let (col, row) = with.frame.col_row(i);
        let truth = with.truth.radial[i].unwrap() as Real;
        if truth > 3.0 && (70..75).contains(&row) && (95..110).contains(&col) {
            err_with.push(with.frame.radial(i) - truth);
            err_without.push(without.frame.radial(i) - without.truth.radial[i].unwrap() as Real);
        }
    }
    assert!(!err_with.is_empty());
    let (bias_with, _) = stats(&err_with);
    let (bias_without, _) = stats(&err_without);
    println!(
        "scattering bias beside the box {bias_with:.3} m, without the box {bias_without:.3} m"
    );
    assert!(bias_with < -0.1, "{bias_with}");
    assert!(bias_without.abs() < 0.03, "{bias_without}");
}

#[test]
fn sunlight_raises_range_noise() {
    let scene = wall(3.0, 0.5);
    let mut cfg = SimConfig::sr3000();
    let quiet = TofSimulator::new(cfg.clone()).unwrap().simulate(&scene, &pose(), 7).unwrap();
    cfg.sun.push(SunRegion {
        min: Point3::new(2.9, -50.0, -50.0),
        max: Point3::new(3.1, 50.0, 50.0),
        irradiance: 1e5,
    });
    let sunny = TofSimulator::new(cfg).unwrap().simulate(&scene, &pose(), 7).unwrap();
    let spread = |f: &sensor_tof::sim::SimulatedFrame| {
        let e: Vec<Real> = (0..f.truth.radial.len())
            .filter(|&i| {
                let (c, r) = f.frame.col_row(i);
                (60..84).contains(&r) && (76..100).contains(&c)
            })
            .map(|i| f.frame.radial(i) - f.truth.radial[i].unwrap() as Real)
            .collect();
        stats(&e).1
    };
    let (q, s) = (spread(&quiet), spread(&sunny));
    assert!(s > 5.0 * q, "sunny {s}, quiet {q}");
    // The intensity shows the sunlight.
    let i = centre(72, 88);
    assert!(sunny.frame.intensity().unwrap()[i] > 10.0 * quiet.frame.intensity().unwrap()[i]);
}

#[test]
fn frames_are_deterministic_per_seed() {
    let mut cfg = SimConfig::sr3100();
    cfg.scattering = Some(Scattering::sr3000());
    let sim = TofSimulator::new(cfg).unwrap();
    let scene = box_before_wall(true);
    let a = sim.simulate(&scene, &pose(), 11).unwrap();
    let b = sim.simulate(&scene, &pose(), 11).unwrap();
    let c = sim.simulate(&scene, &pose(), 12).unwrap();
    assert_eq!(a, b);
    assert_ne!(a.frame, c.frame);
    assert_eq!(a.truth, c.truth);
}

#[test]
fn nothing_seen_gives_noise_and_the_driver_at_blanks_it() {
    let mut b = SceneBuilder::new("far");
    b.add(
        "wall",
        Cuboid::axis_aligned(Point3::new(40.0, -1.0, -1.0), Point3::new(41.0, 1.0, 1.0)).unwrap(),
        Material::WHITE_PAPER,
    )
    .unwrap();
    let scene = b.build().unwrap();
    let mut cfg = SimConfig::sr3000();
    let f = TofSimulator::new(cfg.clone()).unwrap().simulate(&scene, &pose(), 8).unwrap();
    assert!(f.truth.radial.iter().all(Option::is_none));
    assert!(f.surface.iter().all(Option::is_none));
    let amp: Vec<Real> = f.frame.amplitude().iter().map(|&a| a as Real).collect();
    assert!(stats(&amp).0 < 20.0);
    // Random phase: the ranges spread over the whole non-ambiguity range.
    let radial: Vec<Real> = (0..amp.len()).map(|i| f.frame.radial(i)).collect();
    let (mean, sd) = stats(&radial);
    assert!((mean - 3.75).abs() < 0.3 && sd > 1.8, "{mean} {sd}");
    cfg.driver_at = Some(50.0);
    let f = TofSimulator::new(cfg).unwrap().simulate(&scene, &pose(), 8).unwrap();
    assert_eq!(f.frame.num_measured(), 0);
}

#[test]
fn two_frequencies_share_the_truth_and_differ_in_phase() {
    let sim = TofSimulator::new(SimConfig::sr3000()).unwrap();
    let (a, b) = sim.simulate_two_frequencies(&wall(9.0, 0.85), &pose(), 5e6, 9).unwrap();
    assert_eq!(a, sim.simulate(&wall(9.0, 0.85), &pose(), 9).unwrap());
    assert_eq!(a.truth.radial, b.truth.radial);
    assert!((b.frame.camera().non_ambiguity_range() - 29.98).abs() < 0.01);
    let i = centre(72, 88);
    // At 5 MHz the 9 m wall is inside the non-ambiguity range.
    assert!(
        (b.frame.radial(i) - a.truth.radial[i].unwrap() as Real).abs() < 0.5,
        "{}",
        b.frame.radial(i)
    );
    assert!(sim.simulate_two_frequencies(&wall(9.0, 0.85), &pose(), 0.0, 9).is_err());
}

/// Spoils one field of a configuration.
type Spoil = Box<dyn Fn(&mut SimConfig)>;

#[test]
fn bad_configs_are_refused() {
    let ok = SimConfig::sr3000();
    assert!(ok.validate().is_ok());
    let cases: Vec<Spoil> = vec![
        Box::new(|c| c.illumination_floor = 0.0),
        Box::new(|c| c.illumination_floor = Real::NAN),
        Box::new(|c| c.amplitude_scale = -1.0),
        Box::new(|c| c.signal_offset = 0.5),
        Box::new(|c| c.ambient = Real::INFINITY),
        Box::new(|c| c.shot_gain = -0.1),
        Box::new(|c| c.read_sigma = Real::NAN),
        Box::new(|c| c.cast_range = 0.0),
        Box::new(|c| c.roughness = -0.1),
        Box::new(|c| c.saturation = Some(0.0)),
        Box::new(|c| {
            c.low_amplitude_bias = Some(LowAmplitudeBias { max_shift: -1.0, half_amplitude: 30.0 })
        }),
        Box::new(|c| {
            c.low_amplitude_bias = Some(LowAmplitudeBias { max_shift: 0.1, half_amplitude: 0.0 })
        }),
        Box::new(|c| c.driver_at = Some(-1.0)),
        Box::new(|c| c.scattering = Some(Scattering { strength: 2.0, radius: 5 })),
        Box::new(|c| c.scattering = Some(Scattering { strength: 0.1, radius: 0 })),
        Box::new(|c| c.camera.modulation_hz = 0.0),
        Box::new(|c| {
            c.sun.push(SunRegion {
                min: Point3::new(1.0, 0.0, 0.0),
                max: Point3::new(0.0, 1.0, 1.0),
                irradiance: 1.0,
            })
        }),
        Box::new(|c| {
            c.sun.push(SunRegion {
                min: Point3::origin(),
                max: Point3::new(1.0, 1.0, 1.0),
                irradiance: Real::NAN,
            })
        }),
        Box::new(|c| {
            c.illumination = sensor_tof::Illumination::Parabola(Parabola {
                a_hat: -5.0,
                delta_x: 0.0,
                delta_y: 0.0,
                curvature: 1.0,
            })
        }),
    ];
    for (k, spoil) in cases.iter().enumerate() {
        let mut c = ok.clone();
        spoil(&mut c);
        assert!(c.validate().is_err(), "case {k}");
        assert!(TofSimulator::new(c).is_err(), "case {k}");
    }
    // A hit image of another size and a non-finite pose are refused too.
    let sim = TofSimulator::new(ok).unwrap();
    let mut hits = sim.trace(&wall(2.0, 0.5), &pose()).unwrap();
    hits.hits.pop();
    assert!(sim.render(&hits, 1).is_err());
    let mut bad = pose();
    bad.world_from_sensor.translation.vector.x = Real::NAN;
    assert!(sim.simulate(&wall(2.0, 0.5), &bad, 1).is_err());
}

/// Mean radial error over the central 24 × 24 pixels.
fn centre_bias(f: &sensor_tof::sim::SimulatedFrame) -> Real {
    let e: Vec<Real> = (0..f.truth.radial.len())
        .filter(|&i| {
            let (c, r) = f.frame.col_row(i);
            (60..84).contains(&r) && (76..100).contains(&c)
        })
        .map(|i| f.frame.radial(i) - f.truth.radial[i].unwrap() as Real)
        .collect();
    stats(&e).0
}

#[test]
fn dark_surfaces_read_too_close() {
    let sim = TofSimulator::new(SimConfig::sr3000()).unwrap();
    let dark = centre_bias(&sim.simulate(&wall(3.0, 0.02), &pose(), 13).unwrap());
    let bright = centre_bias(&sim.simulate(&wall(3.0, 0.5), &pose(), 13).unwrap());
    let want = -LowAmplitudeBias::sr3000().shift(0.02 * 11_879.0 / 9.0);
    assert!((dark - want).abs() < 0.03, "dark {dark}, want {want}");
    assert!(dark < -0.1, "{dark}");
    assert!(bright.abs() < 0.01, "{bright}");
}

#[test]
fn saturation_distorts_close_objects_and_blinds_sunlit_ones() {
    let sim = TofSimulator::new(SimConfig::sr3000()).unwrap();
    let i = centre(72, 88);
    // A white wall at 0.4 m: A ≈ 74,000, so the brighter samples clip at the 16-bit full well:
    // the amplitude collapses and the range is distorted (L2259–2269).
    let f = sim.simulate(&wall(0.4, 1.0), &pose(), 14).unwrap();
    assert!(f.frame.amplitude()[i] < 0.6 * 74_000.0, "{}", f.frame.amplitude()[i]);
    let err = |f: &sensor_tof::sim::SimulatedFrame| centre_bias(f).abs();
    assert!(err(&f) > 0.02, "{}", err(&f));
    // Without a full well the close wall is measured.
    let mut cfg = SimConfig::sr3000();
    cfg.saturation = None;
    let g = TofSimulator::new(cfg).unwrap().simulate(&wall(0.4, 1.0), &pose(), 14).unwrap();
    assert!(err(&g) < 0.005, "{}", err(&g));
    // Sunlight far beyond the full well leaves only read noise: tiny amplitude.
    let mut cfg = SimConfig::sr3000();
    cfg.sun.push(SunRegion {
        min: Point3::new(2.9, -50.0, -50.0),
        max: Point3::new(3.1, 50.0, 50.0),
        irradiance: 1e6,
    });
    let f = TofSimulator::new(cfg).unwrap().simulate(&wall(3.0, 0.5), &pose(), 14).unwrap();
    let amp: Vec<Real> = f.frame.amplitude().iter().map(|&a| a as Real).collect();
    assert!(stats(&amp).0 < 10.0, "{}", stats(&amp).0);
}

#[test]
fn rough_surfaces_return_more_light_at_grazing_incidence() {
    // A floor 1 m below the camera seen 3 m ahead.
    let mut b = SceneBuilder::new("floor");
    b.add(
        "floor",
        Cuboid::axis_aligned(Point3::new(-1.0, -20.0, -0.1), Point3::new(30.0, 20.0, 0.0)).unwrap(),
        Material::new(0.5, false).unwrap(),
    )
    .unwrap();
    let scene = b.build().unwrap();
    let pose = camera_pose_looking(Point3::new(0.0, 0.0, 1.0), 0.0, -(1f64 / 3.0).atan());
    let amp = |roughness: Real| {
        let mut cfg = SimConfig::sr3000();
        cfg.roughness = roughness;
        let f = TofSimulator::new(cfg).unwrap().simulate(&scene, &pose, 15).unwrap();
        f.frame.amplitude()[centre(72, 88)] as Real
    };
    let (lambert, rough) = (amp(0.0), amp(0.5));
    let cos = 1.0 / 10f64.sqrt();
    let want = (cos + oren_nayar_retro(0.5) * (1.0 - cos * cos)) / cos;
    assert!((rough / lambert - want).abs() < 0.05 * want, "{rough} / {lambert} vs {want}");
    // Head-on the roughness changes nothing.
    let head_on = |roughness: Real| {
        let mut cfg = SimConfig::sr3000();
        cfg.roughness = roughness;
        TofSimulator::new(cfg)
            .unwrap()
            .simulate(&wall(2.0, 0.5), &pose_flat(), 16)
            .unwrap()
            .frame
            .amplitude()[centre(72, 88)] as Real
    };
    assert!((head_on(0.5) / head_on(0.0) - 1.0).abs() < 0.01);
}

fn pose_flat() -> SensorPose {
    pose()
}
