//! The saturation test against the simulator, which knows when a sample clips.

use pointcloud::{Point3, SensorPose};
use scene_sim::{Cuboid, Material, SceneBuilder, camera_pose_looking};
use sensor_tof::sim::{SimConfig, SunRegion, TofSimulator};
use sensor_tof::{Saturation, TofCamera, TofError, TofFrame};

fn pose() -> SensorPose {
    camera_pose_looking(Point3::new(0.0, 0.0, 1.0), 0.0, 0.0)
}

/// The share of flagged pixels of a 50 % wall at 3 m under sunlight of `irradiance` (none: 0),
/// and the median range error of the flagged and of the other pixels.
fn flagged(irradiance: f64) -> (f64, f64, f64) {
    let mut b = SceneBuilder::new("wall");
    let wall = Cuboid::axis_aligned(Point3::new(3.0, -50.0, -50.0), Point3::new(3.1, 50.0, 50.0));
    b.add("wall", wall.unwrap(), Material::new(0.5, false).unwrap()).unwrap();
    let scene = b.build().unwrap();
    let mut cfg = SimConfig::sr3000();
    if irradiance > 0.0 {
        cfg.sun.push(SunRegion {
            min: Point3::new(2.9, -50.0, -50.0),
            max: Point3::new(3.2, 50.0, 50.0),
            irradiance,
        });
    }
    let f = TofSimulator::new(cfg).unwrap().simulate(&scene, &pose(), 3).unwrap();
    let mask = Saturation::sr3000().mask(&f.frame).unwrap();
    let mut errors = [Vec::new(), Vec::new()];
    for (i, truth) in f.truth.radial.iter().enumerate() {
        let Some(t) = truth else { continue };
        let (col, row) = f.frame.col_row(i);
        let p = f.frame.camera().point(col, row, f64::from(f.frame.range()[i]), f.frame.kind());
        errors[usize::from(mask[i])].push((p.coords.norm() - f64::from(*t)).abs());
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
    };
    let share = mask.iter().filter(|m| **m).count() as f64 / mask.len() as f64;
    (share, median(&mut errors[1]), median(&mut errors[0]))
}

#[test]
fn sunlight_beyond_the_full_well_is_flagged_and_its_ranges_are_wrong() {
    let (share, _, good) = flagged(0.0);
    assert_eq!(share, 0.0);
    assert!(good < 0.03, "{good}");
    // 2.5·10⁵ on a 50 % wall: B ≈ 125,000, twice the 16-bit full well.
    let (share, bad, _) = flagged(2.5e5);
    assert_eq!(share, 1.0);
    assert!(bad > 0.1, "the flagged pixels' median error is {bad} m");
    // A tenth of it stays below the full well: shot noise, no flags.
    let (share, _, good) = flagged(2.5e4);
    assert_eq!(share, 0.0);
    assert!(good < 0.05, "{good}");
}

#[test]
fn bad_parameters_and_a_frame_without_intensity_are_refused() {
    for (full, fraction) in [(0.0, 0.9), (f64::NAN, 0.9), (65_535.0, 0.0), (65_535.0, 1.5)] {
        assert!(matches!(Saturation::new(full, fraction), Err(TofError::BadParameter { .. })));
    }
    let cam = TofCamera::sr3000();
    let n = cam.num_pixels();
    let frame =
        TofFrame::new(cam, pointcloud::RangeKind::Depth, vec![1.0; n], vec![100.0; n]).unwrap();
    let e = Saturation::sr3000().mask(&frame).unwrap_err();
    assert!(e.to_string().contains("intensity"), "{e}");
}
