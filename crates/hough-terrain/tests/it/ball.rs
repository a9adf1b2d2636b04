//! The equal-area ball accumulator: the three planes of a box corner in any orientation, and
//! the floor and wall of a simulated scene, against their true planes.

use crate::common;

use hough_terrain::{BallAccumulator, BallConfig, BallPlane, refine_plane};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use scene_sim::TerrainSpec;

/// Deterministic pseudo-random numbers in [0, 1) (no dependency on `rand`).
fn lcg(state: &mut u64) -> f64 {
    *state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

/// Points on the three faces x = 0, y = 0, z = 0 of a corner, 1.5 m squares, 3 mm noise,
/// moved by `pose`.
fn corner(pose: &Isometry3<f64>, per_face: usize, seed: u64) -> Vec<Point3<f64>> {
    let mut s = seed;
    let mut out = Vec::new();
    for face in 0..3 {
        for _ in 0..per_face {
            let (u, v, w) = (lcg(&mut s) * 1.5, lcg(&mut s) * 1.5, (lcg(&mut s) - 0.5) * 0.006);
            let p = match face {
                0 => Point3::new(w, u, v),
                1 => Point3::new(u, w, v),
                _ => Point3::new(u, v, w),
            };
            out.push(pose * p);
        }
    }
    out
}

/// The best angle error (degrees) of `found` against each true normal.
fn errors(found: &[BallPlane], truth: &[Vector3<f64>]) -> Vec<f64> {
    truth
        .iter()
        .map(|n| found.iter().map(|p| p.angle_to(n).to_degrees()).fold(f64::INFINITY, f64::min))
        .collect()
}

#[test]
fn box_corner_planes_within_a_few_degrees() {
    let config = BallConfig { step: 2f64.to_radians(), rho_max: 4.0, rho_res: 0.02 };
    let mut worst_raw: f64 = 0.0;
    let mut worst_refined: f64 = 0.0;
    for (k, (r, p, y)) in [(0.3, -0.5, 1.1), (1.2, 0.4, -2.0), (0.0, 0.0, 0.0), (-0.7, 0.9, 0.2)]
        .into_iter()
        .enumerate()
    {
        let rot = UnitQuaternion::from_euler_angles(r, p, y);
        let pose = Isometry3::from_parts(Translation3::new(0.8, -0.4, 1.1), rot);
        let points = corner(&pose, 1500, 11 + k as u64);
        let mut ball = BallAccumulator::new(config).unwrap();
        ball.vote(&points).unwrap();
        let peaks = ball.peaks(3, 10f64.to_radians(), 0.2, 50);
        assert_eq!(peaks.len(), 3);
        let truth: Vec<_> =
            [Vector3::x(), Vector3::y(), Vector3::z()].iter().map(|n| rot * n).collect();
        let raw = errors(&peaks, &truth);
        let refined: Vec<_> =
            peaks.iter().map(|p| refine_plane(&points, p, 0.05).unwrap()).collect();
        let fine = errors(&refined, &truth);
        println!("corner {k}: cell errors {raw:.2?}°, refined {fine:.3?}°");
        for (e, f) in raw.iter().zip(&fine) {
            worst_raw = worst_raw.max(*e);
            worst_refined = worst_refined.max(*f);
        }
        // Each true plane's distance: the corner's faces pass through the pose's origin.
        for plane in &refined {
            let origin = pose.translation.vector;
            assert!((plane.normal.dot(&origin) - plane.distance).abs() < 0.01, "{plane:?}");
        }
    }
    println!("worst: cell {worst_raw:.2}°, refined {worst_refined:.3}°");
    assert!(worst_raw < 3.0, "{worst_raw}");
    assert!(worst_refined < 0.2, "{worst_refined}");
}

#[test]
fn floor_and_wall_of_a_simulated_scene() {
    let cloud = common::sr_frame(&TerrainSpec::Wall { distance: 2.5, height: 2.0 }, 1).to_world();
    // Every 4th point keeps the test quick.
    let points: Vec<_> = cloud.positions().iter().step_by(4).copied().collect();
    let mut ball =
        BallAccumulator::new(BallConfig { step: 2f64.to_radians(), rho_max: 4.0, rho_res: 0.02 })
            .unwrap();
    ball.vote(&points).unwrap();
    let peaks = ball.peaks(2, 10f64.to_radians(), 0.2, 50);
    let truth = [Vector3::z(), Vector3::x()];
    let raw = errors(&peaks, &truth);
    let refined: Vec<_> = peaks.iter().filter_map(|p| refine_plane(&points, p, 0.05)).collect();
    let fine = errors(&refined, &truth);
    println!("floor, wall: cell errors {raw:.2?}°, refined {fine:.3?}°; {peaks:?}");
    assert!(raw.iter().all(|e| *e < 3.0), "{raw:?}");
    assert!(fine.iter().all(|e| *e < 0.3), "{fine:?}");
    // The floor is z = 0, the wall x = 2.5.
    for p in &refined {
        let d = if p.normal.z.abs() > 0.9 { 0.0 } else { 2.5 };
        assert!((p.distance.abs() - d).abs() < 0.03, "{p:?}");
    }
}
