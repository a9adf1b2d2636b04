//! Plane segmentation of simulated scans and synthetic clouds, scored with SegComp.

use patch_core::{Plane, Point3, Real, UnitVector3, Vector3};
use patch_extract::Segmentation;
use patch_extract::evaluate::{SegCompConfig, SegCompReport, segcomp};
use patch_extract::projection::{AlrfSideColumns, invalidate_alrf_side_columns};
use patch_extract::segment::{
    SegmentConfig, SegmentError, segment, segment_remainder, segment_unorganised,
};
use pointcloud::{BeamModel, PointCloud, SensorPose};
use scene_sim::{
    Alrf, AlrfConfig, Cuboid, Material, PlanarPolygon, RangeCamera, RangeCameraConfig, RangeSensor,
    Scene, SceneBuilder, SimulatedScan, SurfaceId, camera_pose_looking,
};
use std::time::Instant;

/// A room corner: floor, two walls, a box on the floor and a tilted board.
fn corner_scene() -> Scene {
    let mut b = SceneBuilder::new("corner");
    let floor = PlanarPolygon::parallelogram(
        Point3::new(-1.0, -4.0, 0.0),
        Vector3::new(7.0, 0.0, 0.0),
        Vector3::new(0.0, 8.0, 0.0),
    )
    .unwrap();
    let back = PlanarPolygon::parallelogram(
        Point3::new(5.0, 4.0, 0.0),
        Vector3::new(0.0, -8.0, 0.0),
        Vector3::new(0.0, 0.0, 3.0),
    )
    .unwrap();
    let side = PlanarPolygon::parallelogram(
        Point3::new(-1.0, 2.5, 0.0),
        Vector3::new(6.0, 0.0, 0.0),
        Vector3::new(0.0, 0.0, 3.0),
    )
    .unwrap();
    let board = PlanarPolygon::parallelogram(
        Point3::new(2.5, -2.2, 0.0),
        Vector3::new(0.0, 1.2, 0.0),
        Vector3::new(0.6, 0.0, 1.0),
    )
    .unwrap();
    let cube =
        Cuboid::axis_aligned(Point3::new(2.8, 0.3, 0.0), Point3::new(3.6, 1.3, 0.7)).unwrap();
    b.add("floor", floor, Material::CONCRETE).unwrap();
    b.add("back", back, Material::WHITE_MASONRY).unwrap();
    b.add("side", side, Material::WHITE_MASONRY).unwrap();
    b.add("board", board, Material::WOOD).unwrap();
    b.add("cube", cube, Material::WOOD).unwrap();
    b.build().unwrap()
}

fn camera(sigma: Real) -> RangeCamera {
    RangeCamera::new(RangeCameraConfig {
        range_sigma: sigma,
        ..RangeCameraConfig::swissranger_sr3000()
    })
    .unwrap()
}

fn alrf(step_deg: Real, sigma: Real, mixed: bool) -> Alrf {
    let mut config = AlrfConfig::sick_s300_with_step(step_deg.to_radians()).unwrap();
    config.range_sigma = sigma;
    if !mixed {
        config.mixed_pixels = None;
    }
    Alrf::new(config).unwrap()
}

fn camera_pose() -> SensorPose {
    camera_pose_looking(Point3::new(0.0, 0.0, 1.3), 0.1, -0.3)
}

/// The true plane of `surface` in the sensor frame of `pose`.
fn plane_in_sensor(scene: &Scene, pose: &SensorPose, surface: u32) -> Option<Plane> {
    let plane = scene.surface(SurfaceId(surface))?.plane?;
    let m = &pose.world_from_sensor;
    let normal = UnitVector3::new_normalize(m.rotation.inverse() * plane.normal.into_inner());
    let offset = plane.offset - plane.normal.dot(&m.translation.vector);
    Some(Plane { normal, offset })
}

/// Checks the segmentation invariants: disjoint ascending regions, largest first, the
/// remainder the rest, planes facing the sensor.
fn check_invariants(cloud: &PointCloud, seg: &Segmentation, min_size: usize) {
    let mut seen = vec![false; cloud.len()];
    for w in seg.regions.windows(2) {
        assert!(w[0].points.len() >= w[1].points.len());
    }
    for r in &seg.regions {
        assert!(r.points.len() >= min_size);
        assert!(r.points.windows(2).all(|w| w[0] < w[1]));
        assert!(r.plane.normal.dot(&(Point3::origin() - r.centroid)) >= 0.0);
        assert!(r.covariance.is_some());
        for &i in &r.points {
            assert!(!std::mem::replace(&mut seen[i as usize], true));
        }
    }
    assert!(seg.remainder.windows(2).all(|w| w[0] < w[1]));
    for &i in &seg.remainder {
        assert!(!std::mem::replace(&mut seen[i as usize], true));
    }
    assert!(seen.iter().all(|&s| s), "every point is in a region or the remainder");
}

fn evaluate(
    scene: &Scene,
    scan: &SimulatedScan,
    cloud: &PointCloud,
    seg: &Segmentation,
    min_truth: usize,
) -> SegCompReport {
    let report = segcomp(cloud.labels().unwrap(), seg, &SegCompConfig::hoover(min_truth), |l| {
        plane_in_sensor(scene, &scan.pose, l)
    })
    .unwrap();
    println!("{report}");
    report
}

#[test]
fn range_camera_noise_free_detects_every_large_surface() {
    let scene = corner_scene();
    let scan = camera(0.0).scan(&scene, &camera_pose(), 1);
    let cloud = scan.to_cloud().unwrap();
    let config = SegmentConfig::exact();
    let seg = segment(&cloud, &config).unwrap();
    check_invariants(&cloud, &seg, config.min_region_size);
    let report = evaluate(&scene, &scan, &cloud, &seg, 200);
    assert!(report.num_truth >= 5, "{report}");
    assert_eq!(report.correct.len(), report.num_truth, "{report}");
    assert!(report.max_angle_error_deg().unwrap() < 0.5, "{report}");
}

#[test]
fn range_camera_default_noise_detects_most_surfaces() {
    let scene = corner_scene();
    let scan = camera(0.01).scan(&scene, &camera_pose(), 2);
    let cloud = scan.to_cloud().unwrap();
    let config = SegmentConfig::range_camera();
    let seg = segment(&cloud, &config).unwrap();
    check_invariants(&cloud, &seg, config.min_region_size);
    let report = evaluate(&scene, &scan, &cloud, &seg, 200);
    assert!(report.correct_ratio() >= 0.8, "{report}");
    assert!(report.under.is_empty(), "{report}");
    assert!(report.mean_angle_error_deg().unwrap() < 2.0, "{report}");
}

#[test]
fn range_camera_unorganised_matches_organised_when_noise_free() {
    let scene = corner_scene();
    let scan = camera(0.0).scan(&scene, &camera_pose(), 3);
    let cloud = scan.to_cloud().unwrap();
    let config = SegmentConfig { knn_radius: 0.15, ..SegmentConfig::exact() };
    let seg = segment_unorganised(&cloud, &config).unwrap();
    check_invariants(&cloud, &seg, config.min_region_size);
    let report = evaluate(&scene, &scan, &cloud, &seg, 200);
    assert_eq!(report.correct.len(), report.num_truth, "{report}");
    assert!(report.max_angle_error_deg().unwrap() < 0.5, "{report}");
}

fn alrf_scan(sigma: Real, mixed: bool) -> (Scene, SimulatedScan, PointCloud) {
    let scene = corner_scene();
    let sensor = alrf(1.0, sigma, mixed);
    let pose = SensorPose::from_position_rpy(Point3::new(0.0, 0.0, 0.8), 0.0, 0.0, 0.2);
    let scan = sensor.scan(&scene, &pose, 4);
    let cloud = scan.to_cloud().unwrap();
    let BeamModel::ActuatedLrf(model) = sensor.beam_model() else { unreachable!() };
    let (cloud, _) =
        invalidate_alrf_side_columns(&cloud, &model, &AlrfSideColumns::thesis()).unwrap();
    (scene, scan, cloud)
}

#[test]
fn alrf_noise_free_detects_every_large_surface() {
    let (scene, scan, cloud) = alrf_scan(0.0, false);
    let config = SegmentConfig { min_region_size: 30, ..SegmentConfig::exact() };
    let seg = segment(&cloud, &config).unwrap();
    check_invariants(&cloud, &seg, config.min_region_size);
    let report = evaluate(&scene, &scan, &cloud, &seg, 100);
    assert!(report.num_truth >= 4, "{report}");
    assert!(report.missed.is_empty() && report.under.is_empty(), "{report}");
    assert!(report.correct.len() + report.over.len() == report.num_truth, "{report}");
    assert!(report.correct_ratio() >= 0.75, "{report}");
    assert!(report.max_angle_error_deg().unwrap() < 0.5, "{report}");
}

#[test]
fn alrf_default_noise_detects_most_surfaces() {
    let (scene, scan, cloud) = alrf_scan(0.03, true);
    let config = SegmentConfig { min_region_size: 30, ..SegmentConfig::alrf() };
    let seg = segment(&cloud, &config).unwrap();
    check_invariants(&cloud, &seg, config.min_region_size);
    let report = evaluate(&scene, &scan, &cloud, &seg, 100);
    assert!(report.correct_ratio() >= 0.75, "{report}");
    assert!(report.under.is_empty() && report.missed.is_empty(), "{report}");
    assert!(report.mean_angle_error_deg().unwrap() < 3.0, "{report}");
}

/// An organised `w × h` cloud of two planes meeting at a ridge at `x = 0` (a roof seen from
/// below: z = 3 − 0.8 |x|).
fn ridge_cloud(w: u32, h: u32) -> PointCloud {
    let pixels = (0..h).flat_map(|row| {
        (0..w).map(move |col| {
            let x = -1.0 + 2.0 * col as Real / (w - 1) as Real;
            let y = -0.6 + 1.2 * row as Real / (h - 1) as Real;
            Some(Point3::new(x, y, 3.0 - 0.8 * x.abs()))
        })
    });
    PointCloud::from_pixels(w, h, pixels).unwrap()
}

#[test]
fn two_planes_meeting_at_an_edge_give_two_regions() {
    let cloud = ridge_cloud(61, 40);
    for seg in [
        segment(&cloud, &SegmentConfig::exact()).unwrap(),
        segment_unorganised(&cloud, &SegmentConfig::exact()).unwrap(),
    ] {
        check_invariants(&cloud, &seg, 50);
        assert_eq!(seg.regions.len(), 2);
        for r in &seg.regions {
            // Each side has 30 columns of its own, the ridge column goes to either.
            assert!((30 * 40..=31 * 40).contains(&r.points.len()), "{}", r.points.len());
            assert!(r.mse < 1e-12);
            let slope = r.plane.normal.x.abs() / r.plane.normal.z.abs();
            assert!((slope - 0.8).abs() < 1e-6);
            assert!(r.plane.normal.z < 0.0, "faces the sensor at the origin");
        }
        assert!(seg.remainder.len() <= 40);
    }
}

/// A tiny deterministic generator (SplitMix64) for random clouds.
fn uniform(state: &mut u64) -> Real {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    (z ^ (z >> 31)) as Real / u64::MAX as Real
}

#[test]
fn random_points_give_no_large_regions() {
    let mut state = 42;
    let (w, h) = (60u32, 50u32);
    let pixels: Vec<Option<Point3>> = (0..w * h)
        .map(|_| {
            let x = uniform(&mut state) - 0.5;
            let y = uniform(&mut state) - 0.5;
            Some(Point3::new(x, y, 2.0 + uniform(&mut state)))
        })
        .collect();
    let cloud = PointCloud::from_pixels(w, h, pixels).unwrap();
    // Organised: pixel neighbours are unrelated points, nothing links.
    for config in [SegmentConfig::range_camera(), SegmentConfig::alrf()] {
        let seg = segment(&cloud, &config).unwrap();
        check_invariants(&cloud, &seg, config.min_region_size);
        assert!(seg.regions.is_empty(), "{} regions", seg.regions.len());
        assert_eq!(seg.remainder.len(), cloud.len());
    }
    // Unorganised at 1 cm noise: no slab of the cloud is thin enough to pass.
    let seg = segment_unorganised(&cloud, &SegmentConfig::range_camera()).unwrap();
    assert!(seg.regions.is_empty(), "{} regions", seg.regions.len());
    // At the scanner's 3 cm noise a ±3.6 cm slab of this dense cloud (3000 points per m³)
    // holds ~200 points and is a plane within that noise: regions appear, but none is large.
    let seg = segment_unorganised(&cloud, &SegmentConfig::alrf()).unwrap();
    check_invariants(&cloud, &seg, SegmentConfig::alrf().min_region_size);
    assert!(seg.regions.iter().all(|r| r.points.len() < cloud.len() / 5));
}

#[test]
fn bad_configs_are_errors() {
    let cloud = ridge_cloud(10, 10);
    let base = SegmentConfig::exact();
    let mut nan = base;
    nan.noise.sigma_0 = Real::NAN;
    let mut negative = base;
    negative.distance_factor = -1.0;
    let mut jump = base;
    jump.jump_relative = Real::INFINITY;
    let mut normal = base;
    normal.max_normal_angle = Some(2.0);
    let mut zero_normal = base;
    zero_normal.max_normal_angle = Some(0.0);
    let mut link = SegmentConfig::alrf();
    if let Some(g) = link.grazing.as_mut() {
        g.link_cos = Real::NAN;
    }
    for bad in [nan, negative, jump, normal, zero_normal, link] {
        assert!(matches!(segment(&cloud, &bad), Err(SegmentError::BadParameter { .. })));
        assert!(bad.validate().is_err());
    }
    let zero_min = SegmentConfig { min_region_size: 0, ..base };
    assert_eq!(
        segment(&cloud, &zero_min),
        Err(SegmentError::TooSmall { name: "min_region_size", value: 0, min: 4 })
    );
    let zero_k = SegmentConfig { knn: 0, ..base };
    assert!(segment_unorganised(&cloud, &zero_k).is_err());
    let zero_seed = SegmentConfig { seed_radius: 0, ..base };
    assert!(segment(&PointCloud::new(), &zero_seed).is_err(), "checked before the input");
    let msg = segment(&cloud, &negative).unwrap_err().to_string();
    assert!(msg.contains("distance_factor"), "{msg}");
}

/// Grids narrower or lower than a seed window, thin strips, and frames with holes, points at
/// the sensor and far-off points go through the contiguous-window (box sum) seeds without a panic, and every
/// point ends up in one region or the remainder.
#[test]
fn odd_grids_and_bad_points_segment_without_panics() {
    let mut state = 7u64;
    for (w, h) in [(1, 1), (2, 3), (5, 1), (1, 40), (3, 3), (33, 2), (70, 5), (65, 65)] {
        let pixels: Vec<Option<Point3>> = (0..h)
            .flat_map(|row| (0..w).map(move |col| (row, col)))
            .map(|(row, col)| {
                let u = uniform(&mut state);
                let p = Point3::new(Real::from(col) * 0.01, Real::from(row) * 0.01, 2.0);
                match (u * 50.0) as u32 {
                    0 => None,
                    1 => Some(Point3::new(0.0, 0.0, 1e-12)),
                    2 => Some(p + Vector3::new(0.0, 0.0, 1e6)),
                    _ => Some(p),
                }
            })
            .collect();
        let cloud = PointCloud::from_pixels(w, h, pixels).unwrap();
        for config in [SegmentConfig::range_camera(), SegmentConfig::structured_light()] {
            let config = SegmentConfig { min_region_size: 4, ..config };
            let seg = segment(&cloud, &config).unwrap();
            let mut seen: Vec<u32> =
                seg.regions.iter().flat_map(|r| r.points.iter().copied()).collect();
            seen.extend(&seg.remainder);
            seen.sort_unstable();
            assert_eq!(seen, (0..cloud.len() as u32).collect::<Vec<_>>(), "{w} x {h}");
        }
    }
}

#[test]
fn empty_clouds_give_empty_segmentations() {
    let config = SegmentConfig::alrf();
    assert_eq!(segment(&PointCloud::new(), &config).unwrap(), Segmentation::default());
    assert_eq!(segment_unorganised(&PointCloud::new(), &config).unwrap(), Segmentation::default());
    let all_invalid = PointCloud::from_pixels(4, 3, vec![None; 12]).unwrap();
    assert_eq!(segment(&all_invalid, &config).unwrap(), Segmentation::default());
    // A handful of points: no region, everything remainder.
    let few = ridge_cloud(3, 2);
    let seg = segment(&few, &SegmentConfig::exact()).unwrap();
    assert!(seg.regions.is_empty());
    assert_eq!(seg.remainder, (0..6).collect::<Vec<u32>>());
}

/// Release-mode measurements for the report, on three poses in the lab:
/// `cargo test --release -p patch-extract --test it segment:: -- --ignored --nocapture`.
#[test]
#[ignore = "measurement; run in release"]
fn measure_lab_scans() {
    let scene = scene_sim::scene_by_name("lab", 7).unwrap();
    let bodies = scene.scan_poses(3, 0.8, 7);
    let runs: [(&str, Box<dyn RangeSensor>, SegmentConfig); 6] = [
        ("alrf 541x361 σ=0", Box::new(alrf(0.5, 0.0, false)), SegmentConfig::exact()),
        ("alrf 541x361 σ=3cm+mixed", Box::new(alrf(0.5, 0.03, true)), SegmentConfig::alrf()),
        ("alrf 541x361 σ=6cm+mixed", Box::new(alrf(0.5, 0.06, true)), alrf_scaled(2.0)),
        ("sr3000 176x144 σ=0", Box::new(camera(0.0)), SegmentConfig::exact()),
        ("sr3000 176x144 σ=1cm", Box::new(camera(0.01)), SegmentConfig::range_camera()),
        ("sr3000 176x144 σ=2cm", Box::new(camera(0.02)), camera_scaled(2.0)),
    ];
    for (name, sensor, config) in runs {
        let mut line = Vec::new();
        let (mut ms, mut totals) = (0.0, [0usize; 6]);
        let mut angles = Vec::new();
        for (k, body) in bodies.iter().enumerate() {
            let pose = sensor.mount(body);
            let scan = sensor.scan(&scene, &pose, 11 + k as u64);
            let mut cloud = scan.to_cloud().unwrap();
            if let BeamModel::ActuatedLrf(model) = scan.image.beams() {
                cloud = invalidate_alrf_side_columns(&cloud, model, &AlrfSideColumns::thesis())
                    .unwrap()
                    .0;
            }
            let start = Instant::now();
            let seg = segment(&cloud, &config).unwrap();
            let elapsed = start.elapsed().as_secs_f64() * 1e3;
            ms += elapsed;
            let report = segcomp(cloud.labels().unwrap(), &seg, &SegCompConfig::hoover(200), |l| {
                plane_in_sensor(&scene, &scan.pose, l)
            })
            .unwrap();
            let counts = [
                report.num_truth,
                report.correct.len(),
                report.over.len(),
                report.under.len(),
                report.missed.len(),
                report.noise.len(),
            ];
            for (t, c) in totals.iter_mut().zip(counts) {
                *t += c;
            }
            angles.extend(report.angle_errors());
            line.push(format!("{} pts {elapsed:.1} ms", cloud.len()));
        }
        let mean = angles.iter().sum::<Real>() / angles.len().max(1) as Real;
        let max = angles.iter().copied().fold(0.0, Real::max);
        println!(
            "{name}: [{}] mean {:.1} ms/scan; GT {} correct {} over {} under {} missed {} noise {}; \
             angle mean {mean:.3}° max {max:.3}°",
            line.join(", "),
            ms / bodies.len() as Real,
            totals[0],
            totals[1],
            totals[2],
            totals[3],
            totals[4],
            totals[5]
        );
    }
}

fn alrf_scaled(f: Real) -> SegmentConfig {
    let mut c = SegmentConfig::alrf();
    c.noise.sigma_0 *= f;
    c
}

fn camera_scaled(f: Real) -> SegmentConfig {
    let mut c = SegmentConfig::range_camera();
    c.noise.sigma_0 *= f;
    c
}

/// A 320 × 240 organised frame of a wall at 45° (z = 3 + x) before a structured-light camera
/// (57° × 43° field of view), 2–6.5 m away, with Kinect-like depth: Gaussian noise of
/// σ(z) = 1.2 mm + 1.9 mm/m² · z² and depth quantised to disparity steps of 2.85 mm/m² · z².
fn kinect_wall(seed: u64) -> PointCloud {
    let (w, h) = (320u32, 240u32);
    let f = (w as Real / 2.0) / (28.5 as Real).to_radians().tan();
    let mut state = seed;
    let pixels: Vec<Option<Point3>> = (0..h)
        .flat_map(|row| (0..w).map(move |col| (row, col)))
        .map(|(row, col)| {
            // Camera frame: x right, y down, z forward; the wall is z = 3 + x.
            let d = Vector3::new(
                (col as Real + 0.5 - w as Real / 2.0) / f,
                (row as Real + 0.5 - h as Real / 2.0) / f,
                1.0,
            );
            let z = 3.0 / (1.0 - d.x);
            let (u1, u2) = (uniform(&mut state).max(1e-12), uniform(&mut state));
            let gauss = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
            let noisy = z + gauss * (0.0012 + 0.0019 * z * z);
            let step = 0.00285 * z * z;
            let quantised = (noisy / step).round() * step;
            Some(Point3::from(d * quantised))
        })
        .collect();
    PointCloud::from_pixels(w, h, pixels).unwrap()
}

#[test]
fn structured_light_frames_keep_a_far_wall_whole_where_the_range_camera_preset_fragments_it() {
    let cloud = kinect_wall(7);
    let largest_share = |seg: &Segmentation| {
        let largest = seg.regions.iter().map(|r| r.points.len()).max().unwrap_or(0);
        largest as Real / cloud.len() as Real
    };
    let light = segment(&cloud, &SegmentConfig::structured_light()).unwrap();
    check_invariants(&cloud, &light, SegmentConfig::structured_light().min_region_size);
    assert!(largest_share(&light) > 0.9, "{} regions", light.regions.len());
    for r in &light.regions {
        let n = r.plane.normal;
        assert!((n.x.abs() - n.z.abs()).abs() < 0.05 && n.y.abs() < 0.05, "tilted: {n:?}");
    }
    let tof = segment(&cloud, &SegmentConfig::range_camera()).unwrap();
    assert!(
        tof.regions.len() > light.regions.len() && largest_share(&tof) < largest_share(&light),
        "range camera: {} regions, largest {:.2}; structured light: {} regions, largest {:.2}",
        tof.regions.len(),
        largest_share(&tof),
        light.regions.len(),
        largest_share(&light)
    );
}

/// An organised cloud seen from the origin at 1° per pixel: a wall at x = 3 m whose rows
/// `band` alone show between two nearer boards (x = 1.5 m) that hide the rest of it above
/// row 20.
fn wall_band_behind_boards(band: std::ops::Range<u32>) -> PointCloud {
    let (w, h) = (60u32, 60u32);
    let pixels = (0..h).flat_map(move |row| {
        let band = band.clone();
        (0..w).map(move |col| {
            let az = (Real::from(col) - 30.0).to_radians();
            let el = (Real::from(row) - 30.0).to_radians();
            let dir = Vector3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
            let x = if row < 20 || band.contains(&row) { 3.0 } else { 1.5 };
            Some(Point3::from(dir * (x / dir.x)))
        })
    });
    PointCloud::from_pixels(w, h, pixels).unwrap()
}

#[test]
fn the_second_pass_finds_a_band_of_wall_too_narrow_for_the_first_pass_seeds() {
    let cloud = wall_band_behind_boards(40..43);
    let mut seg = segment(&cloud, &SegmentConfig::alrf()).unwrap();
    let on_band = |i: &u32| (40 * 60..43 * 60).contains(i);
    assert!(seg.regions.iter().all(|r| !r.points.iter().any(on_band)), "no 5×5 window fits");
    let before = seg.regions.len();
    let added = segment_remainder(&cloud, &mut seg, &SegmentConfig::alrf_second_pass()).unwrap();
    assert_eq!(added, 1);
    assert_eq!(seg.regions.len(), before + 1);
    check_invariants(&cloud, &seg, 20);
    let band = seg.regions.iter().find(|r| r.points.iter().any(on_band)).unwrap();
    assert!(band.points.iter().all(on_band));
    assert!(band.points.len() >= 150, "{}", band.points.len());
    assert!(band.plane.normal.x.abs() > 0.999, "the wall's plane x = 3");
    assert!((band.plane.signed_distance(&Point3::new(3.0, 0.0, 0.0))).abs() < 1e-6);
    // Regions stay largest first, and the remainder lost the band.
    assert!(seg.regions.windows(2).all(|p| p[0].points.len() >= p[1].points.len()));
    assert!(seg.remainder.iter().filter(|i| on_band(i)).count() + band.points.len() == 180);
}

#[test]
fn the_second_pass_leaves_an_unorganised_cloud_alone() {
    let grid = wall_band_behind_boards(40..43);
    let cloud = PointCloud::from_positions(grid.positions().to_vec()).unwrap();
    let mut seg = segment(&cloud, &SegmentConfig::alrf()).unwrap();
    let before = seg.clone();
    assert_eq!(segment_remainder(&cloud, &mut seg, &SegmentConfig::alrf_second_pass()).unwrap(), 0);
    assert_eq!(seg, before);
}

/// Seeds computed on several threads give the segmentation of one thread, bit for bit, on a
/// VGA frame (above the per-thread minimum) with the normal test on (its window normals are
/// split among the threads too).
#[test]
fn segmentation_does_not_depend_on_the_thread_count() {
    let camera = RangeCamera::new(RangeCameraConfig {
        width: 480,
        height: 360,
        ..RangeCameraConfig::swissranger_sr3000()
    })
    .unwrap();
    let cloud = camera.scan(&corner_scene(), &camera_pose(), 3).to_cloud().unwrap();
    assert!(cloud.len() > 150_000, "{} points", cloud.len());
    let config = SegmentConfig {
        max_normal_angle: Some(60f64.to_radians()),
        ..SegmentConfig::range_camera()
    };
    let one = segment(&cloud, &config).unwrap();
    assert!(one.regions.len() >= 4, "{} regions", one.regions.len());
    for threads in [2, 3] {
        let many = patch_extract::segment_with_threads(
            &cloud,
            &config,
            std::num::NonZeroUsize::new(threads).unwrap(),
        )
        .unwrap();
        assert_eq!(many, one, "{threads} threads");
    }
}
