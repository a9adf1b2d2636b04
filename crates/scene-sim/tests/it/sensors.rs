//! Simulated sensors against analytic scenes: exact ranges without noise, noise statistics,
//! determinism, ground truth, invalid configurations.

use pointcloud::{Point3, RangeKind, Real, SensorPose, Vector3};
use scene_sim::{
    Alrf, AlrfConfig, Cuboid, Material, MixedPixelConfig, PlanarPolygon, Point2, RangeCamera,
    RangeCameraConfig, RangeSensor, Scene, SceneBuilder, SensorError, StereoCamera,
    StereoCameraConfig, camera_pose_from_body, camera_pose_looking, scan_many,
};

const LO: [Real; 3] = [-4.0, -3.0, -1.0];
const HI: [Real; 3] = [6.0, 5.0, 2.0];

/// A box room seen from inside (one cuboid, six faces).
fn box_room(material: Material) -> Scene {
    let mut b = SceneBuilder::new("box-room");
    b.add("room", Cuboid::axis_aligned(Point3::from(LO), Point3::from(HI)).unwrap(), material)
        .unwrap();
    b.build().unwrap()
}

/// The distance from `o` along unit `d` to the room's walls.
fn room_distance(o: &Point3, d: &Vector3) -> Real {
    (0..3)
        .filter(|&i| d[i] != 0.0)
        .map(|i| ((if d[i] > 0.0 { HI[i] } else { LO[i] }) - o[i]) / d[i])
        .fold(Real::INFINITY, Real::min)
}

fn noise_free_alrf(step_deg: Real) -> Alrf {
    let c = AlrfConfig {
        range_sigma: 0.0,
        mixed_pixels: None,
        min_remission: 0.0,
        ..AlrfConfig::sick_s300_with_step(step_deg.to_radians()).unwrap()
    };
    Alrf::new(c).unwrap()
}

fn pose() -> SensorPose {
    SensorPose::from_position_rpy(Point3::new(0.3, -0.2, 0.4), 0.05, -0.1, 0.7)
}

#[test]
fn noise_free_alrf_measures_analytic_distances() {
    let scene = box_room(Material::WHITE_MASONRY);
    let alrf = noise_free_alrf(3.0);
    let pose = pose();
    let scan = alrf.scan(&scene, &pose, 1);
    let img = &scan.image;
    assert_eq!(img.kind(), RangeKind::Radial);
    assert_eq!((img.width(), img.height()), (91, 61));
    assert_eq!(img.num_valid(), 91 * 61, "a closed room returns every beam");
    let o = pose.origin();
    for row in 0..img.height() {
        for col in 0..img.width() {
            let d_sensor = img.beams().direction(col, row, img.width(), img.height());
            let d = pose.world_from_sensor.rotation * d_sensor;
            let expected = room_distance(&o, &d);
            let got = img.range(col, row).unwrap() as Real;
            assert!((got - expected).abs() < 1e-5 * expected.max(1.0), "{col},{row}");
            let i = (row * img.width() + col) as usize;
            assert_eq!(scan.truth.true_range[i], img.range(col, row));
        }
    }
    // The cloud puts every point on a wall of the room.
    let cloud = scan.to_cloud().unwrap().to_world();
    for p in cloud.positions() {
        let on_wall = (0..3).any(|i| (p[i] - LO[i]).abs() < 1e-4 || (p[i] - HI[i]).abs() < 1e-4);
        assert!(on_wall, "{p}");
    }
    let labels = scan.to_cloud().unwrap().labels().unwrap().to_vec();
    assert!(labels.iter().all(|&l| l < 6));
    assert_eq!(labels.iter().collect::<std::collections::BTreeSet<_>>().len(), 6);
}

#[test]
fn noise_free_range_camera_reports_depth() {
    let scene = box_room(Material::WHITE_MASONRY);
    let cam = RangeCamera::new(RangeCameraConfig {
        range_sigma: 0.0,
        max_range: 20.0,
        ..RangeCameraConfig::swissranger_sr3000()
    })
    .unwrap();
    let pose = camera_pose_looking(Point3::new(0.0, 0.0, 0.5), 0.3, -0.2);
    let scan = cam.scan(&scene, &pose, 3);
    assert_eq!(scan.image.kind(), RangeKind::Depth);
    assert_eq!(scan.image.num_valid(), 176 * 144);
    let o = pose.origin();
    let (w, h) = (scan.image.width(), scan.image.height());
    for (row, col) in [(0, 0), (71, 88), (143, 175), (10, 150)] {
        let ray = scan.image.beams().ray(col, row, w, h);
        let d = pose.world_from_sensor.rotation * ray.normalize();
        let radial = room_distance(&o, &d);
        let depth = scan.image.range(col, row).unwrap() as Real;
        assert!((depth - radial / ray.norm()).abs() < 1e-5, "depth = radial · cos");
    }
    // The camera looks along its heading: the centre pixel's world direction.
    let centre = pose.world_from_sensor.rotation * Vector3::z();
    let expected =
        Vector3::new(0.3f64.cos() * 0.2f64.cos(), 0.3f64.sin() * 0.2f64.cos(), -0.2f64.sin());
    assert!((centre - expected).norm() < 1e-12);
    // Hits for a ToF model extend past the camera's own range.
    let far = RangeCamera::swissranger_sr3000().scan_hits(&box_room(Material::WOOD), &pose);
    assert_eq!(far.hits.iter().filter(|h| h.is_some()).count(), 176 * 144);
}

#[test]
fn range_window_and_dark_surfaces() {
    let cam = RangeCamera::swissranger_sr3000();
    // A 12 m deep room: the far wall is beyond 7.5 m and gives no measurement, but has truth.
    let mut b = SceneBuilder::new("deep");
    b.add(
        "far",
        Cuboid::axis_aligned(Point3::new(12.0, -20.0, -20.0), Point3::new(13.0, 20.0, 20.0))
            .unwrap(),
        Material::WOOD,
    )
    .unwrap();
    let scene = b.build().unwrap();
    let pose = camera_pose_looking(Point3::origin(), 0.0, 0.0);
    let scan = cam.scan(&scene, &pose, 1);
    assert_eq!(scan.image.num_valid(), 0);
    assert!(scan.truth.true_range.iter().all(|r| r.is_some_and(|r| r >= 12.0 - 1e-4)));
    // The scanner drops surfaces darker than its detection limit.
    let dark = box_room(Material::BLACK_RUBBER);
    let scan = noise_free_alrf(6.0);
    let alrf = Alrf::new(AlrfConfig { min_remission: 0.018, ..*scan.config() }).unwrap();
    let s = alrf.scan(&dark, &SensorPose::identity(), 1);
    let total = s.image.ranges().len();
    assert!(s.image.num_valid() > 0 && s.image.num_valid() < total, "only steep beams return");
    for (r, c) in s.image.ranges().iter().zip(&s.truth.incidence_cos) {
        if r.is_some() {
            assert!(0.02 * c.unwrap() >= 0.018 - 1e-6);
        }
    }
}

fn mean_std(v: &[Real]) -> (Real, Real) {
    let n = v.len() as Real;
    let m = v.iter().sum::<Real>() / n;
    (m, (v.iter().map(|x| (x - m).powi(2)).sum::<Real>() / (n - 1.0)).sqrt())
}

#[test]
fn alrf_noise_has_the_configured_sigma() {
    let scene = box_room(Material::WHITE_MASONRY);
    let c = AlrfConfig {
        mixed_pixels: None,
        ..AlrfConfig::sick_s300_with_step(2f64.to_radians()).unwrap()
    };
    let alrf = Alrf::new(c).unwrap();
    let scan = alrf.scan(&scene, &pose(), 11);
    let errors: Vec<Real> = scan
        .image
        .ranges()
        .iter()
        .zip(&scan.truth.true_range)
        .filter_map(|(m, t)| Some(m.as_ref()? - t.as_ref()?).map(|e| e as Real))
        .collect();
    assert!(errors.len() > 10_000);
    let (m, s) = mean_std(&errors);
    assert!(m.abs() < 4.0 * 0.03 / (errors.len() as Real).sqrt(), "mean {m}");
    assert!((s - 0.03).abs() < 0.003, "sigma {s}");
}

#[test]
fn stereo_noise_grows_with_depth_squared_and_texture_matters() {
    let cfg = StereoCameraConfig {
        width: 160,
        height: 120,
        textured_dropout: 0.0,
        ..StereoCameraConfig::stoc()
    };
    let cam = StereoCamera::new(cfg).unwrap();
    let plane_at = |x: Real, material: Material| {
        let mut b = SceneBuilder::new("plane");
        b.add(
            "plane",
            PlanarPolygon::rectangle(
                pointcloud::Isometry3::new(
                    Vector3::new(x, 0.0, 0.0),
                    Vector3::y() * -std::f64::consts::FRAC_PI_2,
                ),
                Point2::new(-50.0, -50.0),
                Point2::new(50.0, 50.0),
                &[],
            )
            .unwrap(),
            material,
        )
        .unwrap();
        b.build().unwrap()
    };
    let pose = camera_pose_looking(Point3::origin(), 0.0, 0.0);
    let mut sigmas = Vec::new();
    for z in [2.0, 6.0] {
        let scan = cam.scan(&plane_at(z, Material::WOOD), &pose, 5);
        let errors: Vec<Real> =
            scan.image.ranges().iter().flatten().map(|&r| r as Real - z).collect();
        assert_eq!(errors.len(), 160 * 120);
        let (m, s) = mean_std(&errors);
        let expected = cam.depth_sigma(z);
        assert!(m.abs() < 4.0 * expected / (errors.len() as Real).sqrt());
        assert!((s / expected - 1.0).abs() < 0.05, "z {z}: {s} vs {expected}");
        sigmas.push(s);
    }
    assert!((sigmas[1] / sigmas[0] - 9.0).abs() < 0.6, "σ ∝ z²");
    assert!(
        (cam.config().depth_noise_factor() - 0.1 / (cam.config().intrinsics().fx * 0.09)).abs()
            < 1e-15
    );
    let plain = cam.scan(&plane_at(3.0, Material::WHITE_MASONRY), &pose, 5);
    let ratio = plain.valid_ratio();
    assert!((ratio - 0.05).abs() < 0.015, "textureless surfaces mostly drop out: {ratio}");
    assert!(plain.truth.surface.iter().all(|s| s.is_some()));
    // Closer than the minimum range: nothing.
    let near = cam.scan(&plane_at(0.5, Material::WOOD), &pose, 5);
    assert_eq!(near.image.num_valid(), 0);
}

#[test]
fn same_seed_same_scan_other_seed_other_noise() {
    let scene = scene_sim::lab(3).unwrap();
    let alrf = Alrf::new(AlrfConfig::sick_s300_with_step(4f64.to_radians()).unwrap()).unwrap();
    let poses = scene.scan_poses(2, 0.5, 3);
    let a = alrf.scan(&scene, &poses[0], 9);
    assert_eq!(a, alrf.scan(&scene, &poses[0], 9));
    let b = alrf.scan(&scene, &poses[0], 10);
    assert_ne!(a.image, b.image);
    assert_eq!(a.truth.surface, b.truth.surface, "truth does not depend on the noise");
    let many = scan_many(&alrf, &scene, &poses, 9);
    assert_eq!(many.len(), 2);
    assert_eq!(many, scan_many(&alrf, &scene, &poses, 9));
    assert_ne!(many[0].image, many[1].image);
    for cam in [&RangeCamera::swissranger_sr3000() as &dyn RangeSensor, &StereoCamera::stoc()] {
        let p = cam.mount(&poses[1]);
        assert_eq!(cam.scan(&scene, &p, 1), cam.scan(&scene, &p, 1));
        assert_ne!(cam.scan(&scene, &p, 1).image, cam.scan(&scene, &p, 2).image);
    }
}

#[test]
fn mixed_pixels_lie_between_foreground_and_background() {
    // A thin post in front of a wall: beams at its edges straddle both.
    let mut b = SceneBuilder::new("post");
    b.add(
        "wall",
        Cuboid::axis_aligned(Point3::new(5.0, -10.0, -10.0), Point3::new(5.5, 10.0, 10.0)).unwrap(),
        Material::WOOD,
    )
    .unwrap();
    b.add(
        "post",
        Cuboid::axis_aligned(Point3::new(2.0, -0.1, -10.0), Point3::new(2.2, 0.1, 10.0)).unwrap(),
        Material::WOOD,
    )
    .unwrap();
    let scene = b.build().unwrap();
    let cfg = AlrfConfig {
        range_sigma: 0.0,
        mixed_pixels: Some(MixedPixelConfig { divergence: 0.03, probability: 1.0, min_jump: 0.05 }),
        ..AlrfConfig::sick_s300_with_step(0.5f64.to_radians()).unwrap()
    };
    let scan = Alrf::new(cfg).unwrap().scan(&scene, &SensorPose::identity(), 4);
    let mixed: Vec<usize> =
        (0..scan.truth.mixed_pixel.len()).filter(|&i| scan.truth.mixed_pixel[i]).collect();
    assert!(!mixed.is_empty());
    // Level beams whose axis hits the post report a range between the post and the wall behind.
    let post = scene.primitive(scene_sim::PrimitiveId(1)).unwrap().first_surface.0;
    let w = scan.image.width() as usize;
    let level = |i: usize| (i / w).abs_diff(scan.image.height() as usize / 2) <= 5;
    let on_post: Vec<usize> = mixed
        .iter()
        .copied()
        .filter(|&i| level(i) && scan.truth.surface[i].unwrap().0 >= post)
        .collect();
    assert!(!on_post.is_empty());
    for &i in &on_post {
        let r = scan.image.ranges()[i].unwrap();
        let t = scan.truth.true_range[i].unwrap();
        assert!((1.99..=5.5).contains(&r), "{r} (true {t})");
    }
    assert!(mixed.len() < scan.image.num_valid() / 10, "only edge beams mix");
}

#[test]
fn camera_mount_and_helpers_agree() {
    let body = SensorPose::from_position_rpy(Point3::new(1.0, 2.0, 0.5), 0.0, 0.0, 0.4);
    let cam = camera_pose_from_body(&body);
    assert_eq!(cam, RangeCamera::swissranger_sr3000().mount(&body));
    assert_eq!(body, Alrf::sick_s300().mount(&body));
    let looking = camera_pose_looking(Point3::new(1.0, 2.0, 0.5), 0.4, 0.0);
    assert!(
        (looking.world_from_sensor.to_homogeneous() - cam.world_from_sensor.to_homogeneous())
            .norm()
            < 1e-12
    );
    // Optical axes: forward = body x, right = body −y, down = −z.
    let r = cam.world_from_sensor.rotation;
    assert!((r * Vector3::z() - body.world_from_sensor.rotation * Vector3::x()).norm() < 1e-12);
    assert!((r * Vector3::y() + Vector3::z()).norm() < 1e-12);
}

#[test]
fn bad_configurations_are_refused() {
    let ok = AlrfConfig::sick_s300();
    assert!(matches!(
        Alrf::new(AlrfConfig { columns: 0, ..ok }),
        Err(SensorError::ImageSize { .. })
    ));
    assert!(matches!(
        Alrf::new(AlrfConfig { rows: 100_000, columns: 100_000, ..ok }),
        Err(SensorError::ImageSize { .. })
    ));
    assert!(matches!(
        Alrf::new(AlrfConfig { range_sigma: -1.0, ..ok }),
        Err(SensorError::BadParameter { .. })
    ));
    assert!(matches!(
        Alrf::new(AlrfConfig { max_range: Real::NAN, ..ok }),
        Err(SensorError::BadParameter { .. })
    ));
    assert!(matches!(
        Alrf::new(AlrfConfig {
            mixed_pixels: Some(MixedPixelConfig {
                divergence: 0.01,
                probability: 1.5,
                min_jump: 0.1
            }),
            ..ok
        }),
        Err(SensorError::BadParameter { .. })
    ));
    assert!(AlrfConfig::sick_s300_with_step(0.0).is_err());
    let c = AlrfConfig::sick_s300_with_step(1f64.to_radians()).unwrap();
    assert_eq!((c.columns, c.rows), (271, 181));
    assert_eq!(AlrfConfig::sick_s300_with_step(0.5f64.to_radians()).unwrap().columns, 541);
    let rc = RangeCameraConfig::swissranger_sr3000();
    assert!(RangeCamera::new(RangeCameraConfig { fov_x: 4.0, ..rc }).is_err());
    assert!(RangeCamera::new(RangeCameraConfig { cast_range: 1.0, ..rc }).is_err());
    let st = StereoCameraConfig::stoc();
    assert!(StereoCamera::new(StereoCameraConfig { baseline: 0.0, ..st }).is_err());
    assert!(StereoCamera::new(StereoCameraConfig { untextured_dropout: 2.0, ..st }).is_err());
    assert!(StereoCamera::new(st).is_ok());
}

#[test]
fn non_finite_pose_gives_an_empty_scan() {
    let scene = box_room(Material::WOOD);
    let pose = SensorPose::from_position_rpy(Point3::new(Real::NAN, 0.0, 0.0), 0.0, 0.0, 0.0);
    let scan = noise_free_alrf(10.0).scan(&scene, &pose, 1);
    assert_eq!(scan.image.num_valid(), 0);
}

#[test]
fn sensors_by_name() {
    for name in scene_sim::sensor_names() {
        assert!(scene_sim::sensor_by_name(name).is_ok(), "{name}");
    }
    assert!(matches!(scene_sim::sensor_by_name("sonar"), Err(SensorError::UnknownSensor { .. })));
    let scene = box_room(Material::WOOD);
    let s = scene_sim::sensor_by_name("alrf-5deg").unwrap();
    let scan = s.scan(&scene, &s.mount(&SensorPose::identity()), 1);
    assert_eq!((scan.image.width(), scan.image.height()), (55, 37));
}
