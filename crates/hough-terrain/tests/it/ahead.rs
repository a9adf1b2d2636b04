//! The ground-ahead rule on scene-sim terrain scenes seen by the simulated SR-3000 and STOC
//! from the Rugbot-like pose of `common`, and on synthetic point sets.

use crate::common;

use common::{deg, mount, sr_frame, stereo_frame};
use hough_terrain::{
    GroundAhead, HoughClassifier, HoughConfig, HoughError, Method, RobotLimits, Rule, TerrainClass,
    classify_ahead,
};
use nalgebra::Point3;
use pointcloud::PointCloud;
use proptest::prelude::*;
use scene_sim::TerrainSpec;

fn classify(cloud: &PointCloud) -> hough_terrain::Classification {
    let config = HoughConfig::recommended(deg(45.0), mount()).unwrap();
    let mut c = HoughClassifier::new(config).unwrap();
    c.classify_cloud(cloud).unwrap()
}

#[test]
fn scenes_get_their_drivability_and_class() {
    use TerrainClass::*;
    let ramp = |pitch: f64| TerrainSpec::Ramp { pitch: deg(pitch), roll: 0.0, distance: 1.5 };
    let cases = [
        (TerrainSpec::Floor, Floor, true),
        (ramp(20.0), Ramp, true),
        (ramp(30.0), Ramp, true),
        (ramp(45.0), Ramp, false),
        (TerrainSpec::Plateau { height: 0.3, distance: 1.5 }, Plateau, false),
        (TerrainSpec::Plateau { height: 0.5, distance: 1.5 }, Plateau, false),
        (TerrainSpec::Canyon { depth: 0.5, distance: 1.5 }, Canyon, false),
        (TerrainSpec::Canyon { depth: 0.1, distance: 1.5 }, Floor, true),
        (TerrainSpec::Wall { distance: 3.0, height: 2.0 }, Obstacle, false),
        (TerrainSpec::Wall { distance: 1.0, height: 2.0 }, Obstacle, false),
        (TerrainSpec::Obstacles { count: 10, distance: 1.5 }, Obstacle, false),
        (TerrainSpec::Rubble { count: 300, max_size: 0.1, distance: 1.0 }, Floor, true),
    ];
    // Rubble higher than a step: not drivable, whether as an obstacle or a plateau of rubble.
    let rubble = TerrainSpec::Rubble { count: 300, max_size: 0.4, distance: 1.0 };
    for seed in 1..=2 {
        for cloud in [sr_frame(&rubble, seed), stereo_frame(&rubble, seed)] {
            assert!(!classify(&cloud).drivable, "rubble seed {seed}");
        }
    }
    for (spec, class, drivable) in cases {
        for seed in 1..=2 {
            for (sensor, cloud) in
                [("sr", sr_frame(&spec, seed)), ("stereo", stereo_frame(&spec, seed))]
            {
                let c = classify(&cloud);
                assert_eq!(
                    (c.class, c.drivable),
                    (class, drivable),
                    "{spec:?} {sensor} seed {seed}: {c:?}"
                );
            }
        }
    }
}

#[test]
fn the_thesis_method_stays_algorithm_3() {
    let cloud = sr_frame(&TerrainSpec::Wall { distance: 3.0, height: 2.0 }, 1);
    let mut thesis =
        HoughClassifier::new(HoughConfig::thesis(deg(45.0), mount()).unwrap()).unwrap();
    let c = thesis.classify_cloud(&cloud).unwrap();
    // Algorithm 3 lets the floor outvote the wall 3 m ahead (docs/terrain.md, "Limits found").
    assert_eq!((c.class, c.drivable), (TerrainClass::Floor, true));
    assert_eq!(thesis.config().method, Method::Thesis);
    let ahead = classify(&cloud);
    assert_eq!((ahead.rule, ahead.class), (Rule::AheadObstacle, TerrainClass::Obstacle));
}

#[test]
fn a_face_across_the_view_with_a_level_top_is_a_ledge_and_a_wall_is_not() {
    // The plateau's top (0.5 m) is out of sight behind its edge; its face spans the view.
    for seed in 1..=2 {
        let plateau = sr_frame(&TerrainSpec::Plateau { height: 0.5, distance: 1.5 }, seed);
        let c = classify(&plateau);
        assert_eq!((c.rule, c.class, c.drivable), (Rule::AheadLedge, TerrainClass::Plateau, false));
        assert!((c.step - 0.5).abs() <= 0.05, "step {}", c.step);
        // A wall's columns end at the view's upper edge, far above the sensor.
        let wall = sr_frame(&TerrainSpec::Wall { distance: 2.0, height: 2.0 }, seed);
        assert_eq!(classify(&wall).rule, Rule::AheadObstacle);
    }
}

#[test]
fn methods_parse_by_name() {
    for m in Method::ALL {
        assert_eq!(m.name().parse::<Method>().unwrap(), m);
    }
    assert!(matches!("algorithm-4".parse::<Method>(), Err(HoughError::UnknownName { .. })));
}

#[test]
fn absurd_parameters_are_errors() {
    let limits = RobotLimits::rugbot();
    let floor = [Point3::new(1.0, 0.0, 0.45)];
    for bad in [
        GroundAhead { lookahead: f64::NAN, ..GroundAhead::recommended() },
        GroundAhead { half_width: -1.0, ..GroundAhead::recommended() },
        GroundAhead { cell: 1e-6, ..GroundAhead::recommended() },
        GroundAhead { surface_share: 1.5, ..GroundAhead::recommended() },
        GroundAhead { iterations: 0, ..GroundAhead::recommended() },
        GroundAhead { steep_tilt: 4.0, ..GroundAhead::recommended() },
        GroundAhead { ledge_share: 1.5, ..GroundAhead::recommended() },
        GroundAhead { ledge_spread: f64::INFINITY, ..GroundAhead::recommended() },
        GroundAhead { drop_quantile: -0.1, ..GroundAhead::recommended() },
    ] {
        let mut scratch = Default::default();
        assert!(classify_ahead(&floor, 0.45, &limits, &bad, &mut scratch).is_err(), "{bad:?}");
        let config =
            HoughConfig { ahead: bad, ..HoughConfig::recommended(deg(45.0), mount()).unwrap() };
        assert!(HoughClassifier::new(config).is_err());
    }
}

/// A levelled grid of floor points (z down, the floor at `h`) from 1 to 6 m ahead.
fn floor_points(h: f64, noise: &[f64]) -> Vec<Point3<f64>> {
    let mut v = Vec::new();
    for i in 0..50 {
        for j in 0..30 {
            let k = (i * 30 + j) % noise.len();
            v.push(Point3::new(1.0 + 0.1 * i as f64, -1.5 + 0.1 * j as f64, h + noise[k]));
        }
    }
    v
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// A floor with noise within the floor band is floor; a box standing on it higher than
    /// the robot's step makes it an obstacle; the same points floating above the floor
    /// (wrapped-around pixels) do not.
    #[test]
    fn standing_things_stop_floating_ones_do_not(
        noise in proptest::collection::vec(-0.03f64..0.03, 1..50),
        x in 1.5f64..5.5,
        y in -1.5f64..1.1,
        top in 0.3f64..1.5,
        lift in 0.35f64..0.4,
    ) {
        // The points below are 2 cm apart at any distance, as from a sensor of 0.02 rad
        // pixels 1 m away: the densities are judged against that.
        let rule = GroundAhead { pixel_pitch: 0.02, ..GroundAhead::recommended() };
        let (h, limits) = (0.45, RobotLimits::rugbot());
        let mut scratch = Default::default();
        let floor = floor_points(h, &noise);
        let c = classify_ahead(&floor, h, &limits, &rule, &mut scratch).unwrap();
        prop_assert_eq!((c.class, c.drivable), (TerrainClass::Floor, true));

        // A 0.4 m wide face standing on the floor, sampled every 2 cm.
        let face = |from: f64, to: f64| {
            let mut v = Vec::new();
            let mut z = from;
            while z <= to {
                for k in 0..20 {
                    v.push(Point3::new(x, y + 0.02 * k as f64, h - z));
                }
                z += 0.02;
            }
            v
        };
        let mut standing = floor.clone();
        standing.extend(face(0.0, top));
        let c = classify_ahead(&standing, h, &limits, &rule, &mut scratch).unwrap();
        prop_assert_eq!((c.class, c.drivable), (TerrainClass::Obstacle, false));

        let mut floating = floor.clone();
        floating.extend(face(lift, lift + 0.05));
        let c = classify_ahead(&floating, h, &limits, &rule, &mut scratch).unwrap();
        prop_assert_eq!((c.class, c.drivable), (TerrainClass::Floor, true));
    }
}
