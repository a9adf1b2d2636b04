//! The bending test of the segmentation (`SegmentConfig::max_bending`): facets of curved
//! surfaces are refused, planes are kept.

use patch_core::{Point3, Real, Vector3};
use patch_extract::Segmentation;
use patch_extract::segment::{SegmentConfig, SegmentError, segment};
use pointcloud::PointCloud;

/// What a pixel's beam hit.
#[derive(Copy, Clone, Debug, PartialEq)]
enum Hit {
    Wall,
    Ball,
    Barrel,
}

fn uniform(state: &mut u64) -> Real {
    *state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    (*state >> 11) as Real / (1u64 << 53) as Real
}

/// The nearest positive root of `a t² + b t + c = 0`.
fn nearest_root(a: Real, b: Real, c: Real) -> Option<Real> {
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return None;
    }
    let t = (-b - disc.sqrt()) / (2.0 * a);
    (t > 0.0).then_some(t)
}

/// A 176 × 144 range-camera frame (47.5° × 39.6°, camera frame: x right, y down, z forward)
/// of a wall at z = 4 m, optionally with a ball (radius 0.3 m, centre 2 m ahead, 0.5 m left)
/// and an upright barrel (radius 0.3 m, 1.2 m tall, axis 2.2 m ahead, 0.6 m right) before it;
/// Gaussian range noise of σ = 1 cm along the beams. Returns the cloud and what each point hit.
fn frame(with_curved: bool, seed: u64) -> (PointCloud, Vec<Hit>) {
    let (w, h) = (176u32, 144u32);
    let f = (w as Real / 2.0) / (23.75 as Real).to_radians().tan();
    let ball = Vector3::new(-0.5, 0.0, 2.0);
    let (barrel_x, barrel_z) = (0.6, 2.2);
    let mut state = seed;
    let mut hits = Vec::new();
    let mut pixels = Vec::new();
    for row in 0..h {
        for col in 0..w {
            let d = Vector3::new(
                (col as Real + 0.5 - w as Real / 2.0) / f,
                (row as Real + 0.5 - h as Real / 2.0) / f,
                1.0,
            )
            .normalize();
            let mut hit = (4.0 / d.z, Hit::Wall);
            if with_curved {
                if let Some(t) = nearest_root(1.0, -2.0 * d.dot(&ball), ball.norm_squared() - 0.09)
                    && t < hit.0
                {
                    hit = (t, Hit::Ball);
                }
                let a = d.x * d.x + d.z * d.z;
                let b = -2.0 * (d.x * barrel_x + d.z * barrel_z);
                let c = barrel_x * barrel_x + barrel_z * barrel_z - 0.09;
                if let Some(t) = nearest_root(a, b, c)
                    && t < hit.0
                    && (t * d.y).abs() <= 0.6
                {
                    hit = (t, Hit::Barrel);
                }
            }
            let (u1, u2) = (uniform(&mut state).max(1e-12), uniform(&mut state));
            let gauss = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
            pixels.push(Some(Point3::from(d * (hit.0 + 0.01 * gauss))));
            hits.push(hit.1);
        }
    }
    let cloud = PointCloud::from_pixels(w, h, pixels).unwrap();
    // Every pixel is valid, so point indices follow the pixels.
    assert_eq!(cloud.len(), hits.len());
    (cloud, hits)
}

fn with_bending(b: Option<Real>) -> SegmentConfig {
    SegmentConfig { max_bending: b, ..SegmentConfig::range_camera() }
}

/// Per region: the share of its points on each surface `[wall, ball, barrel]`.
fn shares(seg: &Segmentation, hits: &[Hit]) -> Vec<[Real; 3]> {
    seg.regions
        .iter()
        .map(|r| {
            let mut s = [0.0; 3];
            for &p in &r.points {
                s[hits[p as usize] as usize] += 1.0;
            }
            s.map(|x| x / r.points.len() as Real)
        })
        .collect()
}

#[test]
fn the_bending_test_refuses_facets_of_a_ball_and_a_barrel_but_keeps_the_wall() {
    let (cloud, hits) = frame(true, 11);
    let curved_region = |s: &[Real; 3]| s[1] + s[2] > 0.5;

    // Without the test the curved surfaces are cut into planar facets.
    let plain = segment(&cloud, &with_bending(None)).unwrap();
    let plain_shares = shares(&plain, &hits);
    assert!(
        plain_shares.iter().filter(|s| curved_region(s)).count() >= 2,
        "expected facets without the test: {plain_shares:?}"
    );

    let bent = segment(&cloud, &with_bending(Some(0.3))).unwrap();
    let bent_shares = shares(&bent, &hits);
    assert!(!bent_shares.iter().any(curved_region), "curved regions left: {bent_shares:?}");
    let wall = bent
        .regions
        .iter()
        .zip(&bent_shares)
        .find(|(_, s)| s[0] > 0.99)
        .map(|(r, _)| r)
        .expect("the wall is still a region");
    let on_wall = hits.iter().filter(|&&h| h == Hit::Wall).count();
    assert!(wall.points.len() as Real > 0.9 * on_wall as Real, "wall region too small");
    assert!(wall.plane.normal.z.abs() > 0.999, "wall normal {:?}", wall.plane.normal);
    // Every point is in exactly one region or the remainder.
    let total: usize = bent.regions.iter().map(|r| r.points.len()).sum::<usize>();
    assert_eq!(total + bent.remainder.len(), cloud.len());
}

#[test]
fn the_bending_test_leaves_a_plane_only_frame_unchanged() {
    let (cloud, _) = frame(false, 5);
    let plain = segment(&cloud, &with_bending(None)).unwrap();
    assert!(!plain.regions.is_empty());
    for b in [0.1, 0.3, 0.5] {
        assert_eq!(segment(&cloud, &with_bending(Some(b))).unwrap(), plain, "max_bending {b}");
    }
}

#[test]
fn bad_bending_limits_are_refused() {
    let (cloud, _) = frame(false, 1);
    for b in [0.0, -0.3, Real::NAN, Real::INFINITY] {
        assert!(
            matches!(
                segment(&cloud, &with_bending(Some(b))),
                Err(SegmentError::BadParameter { name: "max_bending", .. })
            ),
            "max_bending {b} accepted"
        );
    }
}
