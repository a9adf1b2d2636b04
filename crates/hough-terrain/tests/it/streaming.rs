//! The streaming classifier: inputs (slices, organised clouds), typed errors, the preprocessing
//! test, buffer reuse from frame to frame, parallel = serial, and the histogram export.

use crate::common;

use common::{deg, mount, sr_frame, stereo_frame};
use hough_terrain::{
    HistogramStyle, HoughClassifier, HoughConfig, HoughError, Rule, SensorMount, TerrainClass,
    hough_png, hough_png_file,
};
use nalgebra::Point3;
use scene_sim::TerrainSpec;

fn classifier(res: f64) -> HoughClassifier {
    HoughClassifier::new(HoughConfig::thesis(deg(res), mount()).unwrap()).unwrap()
}

#[test]
fn buffers_are_reused_across_frames() {
    let frames: Vec<_> =
        [TerrainSpec::Floor, TerrainSpec::Wall { distance: 1.0, height: 2.0 }, TerrainSpec::Floor]
            .iter()
            .map(|s| sr_frame(s, 1))
            .collect();
    let mut c = classifier(15.0);
    // Warm up on the largest frame, then nothing grows or moves.
    let largest = frames.iter().max_by_key(|f| f.len()).unwrap();
    c.classify_cloud(largest).unwrap();
    let bytes = c.capacity_bytes();
    let counts = c.accumulator().counts().as_ptr();
    let levelled = c.levelled_points().as_ptr();
    for f in frames.iter().cycle().take(9) {
        c.classify_cloud(f).unwrap();
        assert_eq!(c.capacity_bytes(), bytes);
        assert_eq!(c.accumulator().counts().as_ptr(), counts);
        assert_eq!(c.levelled_points().as_ptr(), levelled);
    }
    // The same frame gives the same answer every time.
    let a = c.classify_cloud(&frames[0]).unwrap();
    c.classify_cloud(&frames[1]).unwrap();
    assert_eq!(c.classify_cloud(&frames[0]).unwrap(), a);
}

#[test]
fn parallel_voting_gives_the_same_classification() {
    let cloud = sr_frame(&TerrainSpec::Ramp { pitch: deg(30.0), roll: 0.0, distance: 1.5 }, 2);
    for res in [45.0, 15.0, 9.0] {
        let mut serial = classifier(res);
        let mut config = HoughConfig::thesis(deg(res), mount()).unwrap();
        config.threads = 3;
        let mut par = HoughClassifier::new(config).unwrap();
        assert_eq!(par.classify_cloud(&cloud).unwrap(), serial.classify_cloud(&cloud).unwrap());
        assert_eq!(par.accumulator(), serial.accumulator());
    }
}

#[test]
fn bad_input_is_a_typed_error() {
    let mut c = classifier(15.0);
    assert!(matches!(c.classify(&[]), Err(HoughError::EmptyCloud)));
    let pts = [Point3::new(1.0, 0.0, 2.0), Point3::new(0.0, f64::INFINITY, 1.0)];
    assert!(matches!(c.classify(&pts), Err(HoughError::NonFinitePoint { index: 1 })));
    assert!(matches!(c.classify_frame(&pts[..1], 0), Err(HoughError::EmptyCloud)));
    assert!(matches!(c.classify_frame(&pts, 1), Err(HoughError::Mismatch { .. })));
    // Absurd configurations.
    let mut cfg = HoughConfig::thesis(deg(15.0), mount()).unwrap();
    cfg.threads = 0;
    assert!(HoughClassifier::new(cfg).is_err());
    let mut cfg = HoughConfig::thesis(deg(15.0), mount()).unwrap();
    cfg.classifier.thresholds.t_m = 1.5;
    assert!(HoughClassifier::new(cfg).is_err());
    let mut cfg = HoughConfig::thesis(deg(15.0), mount()).unwrap();
    cfg.classifier.thresholds.t_n = 0;
    assert!(HoughClassifier::new(cfg).is_err());
    // The floor must have a bin: a sensor 3 m up is outside d ∈ [−1, 2).
    let high = SensorMount::levelled(3.0).unwrap();
    assert!(matches!(
        HoughClassifier::new(HoughConfig::thesis(deg(15.0), high).unwrap()),
        Err(HoughError::NoFloorBin { .. })
    ));
    // 0° is not sampled with 20° steps from −45°.
    assert!(matches!(
        HoughClassifier::new(HoughConfig::thesis(deg(20.0), mount()).unwrap()),
        Err(HoughError::NoFloorBin { .. })
    ));
    assert!(HoughConfig::thesis(0.0, mount()).is_err());
    assert!(HoughConfig::thesis(deg(91.0), mount()).is_err());
}

#[test]
fn preprocessing_rejects_sparse_frames() {
    let mut c = classifier(45.0);
    // The SR frame of the floor: about half the pixels see the floor.
    let sr = sr_frame(&TerrainSpec::Floor, 1);
    let r = c.classify_cloud(&sr).unwrap();
    assert!(r.accepted && r.valid_fraction > 0.3 && r.valid_fraction < 0.7, "{r:?}");
    assert_eq!(r.points, sr.len());
    // The same points as a frame 10× larger: below 10 % valid.
    let r = c.classify_frame(sr.positions(), sr.len() * 11).unwrap();
    assert!(!r.accepted && !r.drivable);
    assert_eq!((r.rule, r.class), (Rule::Rejected, TerrainClass::Obstacle));
    assert_eq!(c.accumulator().total_votes(), 0);
    // Missing pixels as all-zero points count as pixels, not points.
    let mut pts = sr.positions().to_vec();
    pts.resize(pts.len() * 20, Point3::origin());
    let r = c.classify(&pts).unwrap();
    assert!(!r.accepted, "{r:?}");
    // The stereo camera sees textured floor: accepted, floor.
    let st = stereo_frame(&TerrainSpec::Floor, 1);
    let r = c.classify_cloud(&st).unwrap();
    assert!(r.accepted && r.class == TerrainClass::Floor, "{r:?}");
}

#[test]
fn unit_normal_option_finds_the_same_classes() {
    for spec in
        [TerrainSpec::Floor, TerrainSpec::Ramp { pitch: deg(30.0), roll: 0.0, distance: 1.5 }]
    {
        let cloud = sr_frame(&spec, 1);
        let mut thesis = classifier(15.0);
        let mut cfg = HoughConfig::thesis(deg(15.0), mount()).unwrap();
        cfg.space = cfg.space.with_normal(hough_terrain::NormalKind::Unit);
        let mut unit = HoughClassifier::new(cfg).unwrap();
        let (a, b) = (thesis.classify_cloud(&cloud).unwrap(), unit.classify_cloud(&cloud).unwrap());
        assert_eq!(a.class, b.class, "{spec:?}");
    }
}

#[test]
fn histogram_png_of_a_frame() {
    let mut c = classifier(9.0);
    c.classify_cloud(&sr_frame(
        &TerrainSpec::Ramp { pitch: deg(30.0), roll: 0.0, distance: 1.5 },
        1,
    ))
    .unwrap();
    let style = HistogramStyle::thesis(Some(c.floor_bin()));
    let mut bytes = Vec::new();
    hough_png(c.accumulator(), &style, &mut bytes).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    let path = std::env::temp_dir().join(format!("hough-terrain-test-{}.png", std::process::id()));
    hough_png_file(c.accumulator(), &style, &path).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), bytes);
    std::fs::remove_file(&path).unwrap();
}
