//! The mixed-pixel filter against the simulator's truth: phantoms removed, real surfaces
//! (thin obstacles, grazing floor) kept; bad input refused.
//!
//! The full-resolution figures of the module docs come from the ignored
//! `report_full_resolution`:
//! `cargo test --release -p patch-extract --test it mixed_pixels:: -- --ignored --nocapture`.

use patch_extract::mixed_pixels::{
    MixedPixelConfig, MixedPixelError, mixed_pixels, remove_mixed_pixels,
};
use patch_extract::projection::{AlrfSideColumns, invalidate_alrf_side_columns};
use pointcloud::{BeamModel, INVALID_PIXEL, Point3, PointCloud, SensorPose, Vector3};
use scene_sim::{
    Alrf, AlrfConfig, Cuboid, Cylinder, Material, Point2, RangeSensor, Scene, SceneBuilder,
    SimulatedScan, sensors::derive_seed,
};

/// Counts of one or more scans, against the simulator's truth.
#[derive(Default, Debug, Clone, Copy)]
struct Stats {
    points: usize,
    removed: usize,
    /// Pixels the simulator blended.
    mixed: usize,
    mixed_removed: usize,
    /// Mixed pixels more than 9 cm (3σ) from their own surface's true range.
    far: usize,
    far_removed: usize,
    /// Mixed pixels more than 9 cm from the true range of every pixel of their 3 × 3 window.
    phantom: usize,
    phantom_removed: usize,
    /// The same beyond 20 cm.
    phantom20: usize,
    phantom20_removed: usize,
    /// Points that are not mixed pixels.
    clean: usize,
    clean_removed: usize,
    /// Clean points on table legs, desk legs and rack posts.
    thin: usize,
    thin_removed: usize,
    /// Clean floor points with true range above 4 m.
    floor: usize,
    floor_removed: usize,
    /// Those whose 5 × 5 window is all valid, clean floor.
    inner_floor: usize,
    inner_floor_removed: usize,
}

fn frac(a: usize, b: usize) -> f64 {
    if b == 0 { 0.0 } else { a as f64 / b as f64 }
}

impl Stats {
    fn add(&mut self, o: &Stats) {
        let pairs = [
            (&mut self.points, o.points),
            (&mut self.removed, o.removed),
            (&mut self.mixed, o.mixed),
            (&mut self.mixed_removed, o.mixed_removed),
            (&mut self.far, o.far),
            (&mut self.far_removed, o.far_removed),
            (&mut self.phantom, o.phantom),
            (&mut self.phantom_removed, o.phantom_removed),
            (&mut self.phantom20, o.phantom20),
            (&mut self.phantom20_removed, o.phantom20_removed),
            (&mut self.clean, o.clean),
            (&mut self.clean_removed, o.clean_removed),
            (&mut self.thin, o.thin),
            (&mut self.thin_removed, o.thin_removed),
            (&mut self.floor, o.floor),
            (&mut self.floor_removed, o.floor_removed),
            (&mut self.inner_floor, o.inner_floor),
            (&mut self.inner_floor_removed, o.inner_floor_removed),
        ];
        for (a, b) in pairs {
            *a += b;
        }
    }

    fn recall(&self) -> f64 {
        frac(self.mixed_removed, self.mixed)
    }
    fn far_recall(&self) -> f64 {
        frac(self.far_removed, self.far)
    }
    fn phantom_recall(&self) -> f64 {
        frac(self.phantom_removed, self.phantom)
    }
    fn phantom20_recall(&self) -> f64 {
        frac(self.phantom20_removed, self.phantom20)
    }
    fn clean_loss(&self) -> f64 {
        frac(self.clean_removed, self.clean)
    }
    fn thin_loss(&self) -> f64 {
        frac(self.thin_removed, self.thin)
    }
    fn floor_loss(&self) -> f64 {
        frac(self.floor_removed, self.floor)
    }
    fn inner_floor_loss(&self) -> f64 {
        frac(self.inner_floor_removed, self.inner_floor)
    }

    /// One markdown table row.
    fn row(&self, what: &str, ms: f64) -> String {
        let pc = |x: f64| format!("{:.1} %", 100.0 * x);
        let pc2 = |x: f64| format!("{:.2} %", 100.0 * x);
        let cells = [
            what.to_string(),
            self.points.to_string(),
            format!("{} ({})", self.removed, pc(frac(self.removed, self.points))),
            pc(self.recall()),
            format!("{} ({})", pc(self.far_recall()), self.far),
            format!("{} ({})", pc(self.phantom_recall()), self.phantom),
            format!("{} ({})", pc(self.phantom20_recall()), self.phantom20),
            pc2(self.clean_loss()),
            format!("{} ({})", pc(self.thin_loss()), self.thin),
            format!(
                "{} ({}; interior {})",
                pc2(self.floor_loss()),
                self.floor,
                pc2(self.inner_floor_loss())
            ),
            format!("{ms:.1} ms"),
        ];
        format!("| {} |", cells.join(" | "))
    }
}

fn is_thin(name: &str) -> bool {
    name.contains("/leg-") || name.contains("/desk-leg-") || name.starts_with("rack/post-")
}

/// The cloud of `scan` as the project builds it (`patchnav::scene_map::scan_clouds`): the
/// ALRF's ±90° columns invalidated.
fn project_cloud(scan: &SimulatedScan) -> PointCloud {
    let cloud = scan.to_cloud().unwrap();
    match scan.image.beams() {
        BeamModel::ActuatedLrf(model) => {
            invalidate_alrf_side_columns(&cloud, model, &AlrfSideColumns::thesis()).unwrap().0
        }
        _ => cloud,
    }
}

fn evaluate(scene: &Scene, scan: &SimulatedScan, cloud: &PointCloud, flags: &[bool]) -> Stats {
    let grid = cloud.grid().unwrap();
    let t = &scan.truth;
    let (w, h) = (grid.width() as i64, grid.height() as i64);
    let window = |k: usize, rad: i64| {
        let (c, r) = (k as i64 % w, k as i64 / w);
        (-rad..=rad)
            .flat_map(move |dr| (-rad..=rad).map(move |dc| (c + dc, r + dr)))
            .filter(move |&(c, r)| c >= 0 && r >= 0 && c < w && r < h)
            .map(move |(c, r)| (r * w + c) as usize)
    };
    let mut s = Stats::default();
    for (k, &i) in grid.pixels().iter().enumerate() {
        if i == INVALID_PIXEL {
            continue;
        }
        let removed = flags[i as usize] as usize;
        s.points += 1;
        s.removed += removed;
        let r = cloud.positions()[i as usize].coords.norm();
        if t.mixed_pixel[k] {
            s.mixed += 1;
            s.mixed_removed += removed;
            if (r - t.true_range[k].unwrap() as f64).abs() > 0.09 {
                s.far += 1;
                s.far_removed += removed;
            }
            let off = |d: f64| {
                window(k, 1).all(|kk| t.true_range[kk].is_none_or(|x| (r - x as f64).abs() > d))
            };
            if off(0.09) {
                s.phantom += 1;
                s.phantom_removed += removed;
            }
            if off(0.2) {
                s.phantom20 += 1;
                s.phantom20_removed += removed;
            }
            continue;
        }
        s.clean += 1;
        s.clean_removed += removed;
        let Some(id) = t.surface[k] else { continue };
        let name = &scene.surface(id).unwrap().name;
        if is_thin(name) {
            s.thin += 1;
            s.thin_removed += removed;
        }
        if name.starts_with("floor") && t.true_range[k].unwrap() > 4.0 {
            s.floor += 1;
            s.floor_removed += removed;
            if window(k, 2).count() == 25
                && window(k, 2).all(|kk| {
                    t.surface[kk] == Some(id)
                        && !t.mixed_pixel[kk]
                        && grid.pixels()[kk] != INVALID_PIXEL
                })
            {
                s.inner_floor += 1;
                s.inner_floor_removed += removed;
            }
        }
    }
    s
}

/// `scans` scans of `scene` as the project takes them (0.5 m high poses), filtered with
/// `config`: the pooled statistics and the mean filter time per scan, milliseconds (the best of
/// `repeat` runs).
fn run(
    scene: &Scene,
    alrf: &Alrf,
    scans: usize,
    seed: u64,
    config: &MixedPixelConfig,
    repeat: usize,
) -> (Stats, f64) {
    let mut total = Stats::default();
    let mut ms = 0.0;
    let bodies = scene.scan_poses(scans, 0.5, seed);
    assert_eq!(bodies.len(), scans);
    for (n, body) in bodies.iter().enumerate() {
        let scan = alrf.scan(scene, &alrf.mount(body), derive_seed(seed, n as u64));
        let cloud = project_cloud(&scan);
        let mut best = f64::INFINITY;
        let mut flags = Vec::new();
        for _ in 0..repeat.max(1) {
            let t0 = std::time::Instant::now();
            flags = mixed_pixels(&cloud, config).unwrap();
            best = best.min(t0.elapsed().as_secs_f64() * 1e3);
        }
        ms += best;
        total.add(&evaluate(scene, &scan, &cloud, &flags));
    }
    (total, ms / scans as f64)
}

fn alrf_1deg() -> Alrf {
    Alrf::new(AlrfConfig::sick_s300_with_step(1f64.to_radians()).unwrap()).unwrap()
}

#[test]
fn lab_phantoms_go_real_surfaces_stay() {
    let (s, _) =
        run(&scene_sim::lab(7).unwrap(), &Alrf::sick_s300(), 2, 7, &MixedPixelConfig::alrf(), 1);
    println!("{}", s.row("lab", 0.0));
    assert!(s.phantom > 300 && s.thin > 1000 && s.inner_floor > 500, "{s:?}");
    // The foreground guard keeps phantoms next to a nearer surface (0.95 with it, 0.99
    // without).
    assert!(s.phantom20_recall() > 0.93, "{s:?}");
    assert!(s.phantom_recall() > 0.88, "{s:?}");
    assert!(s.far_recall() > 0.78, "{s:?}");
    assert!(s.clean_loss() < 0.005, "{s:?}");
    // Mostly posts 6–11 m away (one pixel wide) and legs seen by the backward beams.
    assert!(s.thin_loss() < 0.15, "{s:?}");
    assert!(s.floor_loss() < 0.02, "{s:?}");
    assert!(s.inner_floor_loss() < 0.005, "{s:?}");
}

#[test]
fn office_phantoms_go_real_surfaces_stay() {
    let (s, _) =
        run(&scene_sim::office(7).unwrap(), &Alrf::sick_s300(), 2, 7, &MixedPixelConfig::alrf(), 1);
    println!("{}", s.row("office", 0.0));
    assert!(s.phantom > 100 && s.thin > 500 && s.floor > 1000, "{s:?}");
    assert!(s.phantom20_recall() > 0.9, "{s:?}");
    assert!(s.phantom_recall() > 0.85, "{s:?}");
    assert!(s.far_recall() > 0.65, "{s:?}");
    assert!(s.clean_loss() < 0.005, "{s:?}");
    assert!(s.thin_loss() < 0.05, "{s:?}");
    assert!(s.floor_loss() < 0.02, "{s:?}");
}

/// A post 8 cm square and a leg of radius 2.5 cm, 3 m in front of a wall 8 m away, on a floor,
/// seen from 0.5 m height: they keep most of their points and lose their phantoms.
#[test]
fn thin_posts_keep_their_points() {
    let mut b = SceneBuilder::new("posts");
    let floor = Cuboid::axis_aligned(Point3::new(-1.0, -6.0, -0.1), Point3::new(9.0, 6.0, 0.0));
    b.add("floor", floor.unwrap(), Material::CONCRETE).unwrap();
    let wall = Cuboid::axis_aligned(Point3::new(8.0, -6.0, 0.0), Point3::new(8.2, 6.0, 3.0));
    b.add("wall", wall.unwrap(), Material::WHITE_MASONRY).unwrap();
    let post = Cuboid::standing(Point2::new(3.0, 0.3), 0.0, Vector3::new(0.08, 0.08, 1.5), 0.0);
    b.add("post", post.unwrap(), Material::ASPHALT).unwrap();
    let leg = Cylinder::upright(Point3::new(3.0, -0.3, 0.0), 0.025, 0.72);
    b.add("leg", leg.unwrap(), Material::ASPHALT).unwrap();
    let scene = b.build().unwrap();
    let alrf = Alrf::sick_s300();
    let pose = SensorPose::from_position_rpy(Point3::new(0.0, 0.0, 0.5), 0.0, 0.0, 0.0);
    let config = MixedPixelConfig::alrf();
    let (mut kept, mut total, mut phantoms, mut phantoms_removed) = (0, 0, 0, 0);
    for seed in 0..3 {
        let scan = alrf.scan(&scene, &pose, seed);
        let cloud = project_cloud(&scan);
        let flags = mixed_pixels(&cloud, &config).unwrap();
        let grid = cloud.grid().unwrap();
        let (w, h) = (grid.width() as usize, grid.height() as usize);
        for (k, &i) in grid.pixels().iter().enumerate() {
            if i == INVALID_PIXEL {
                continue;
            }
            let name = &scene.surface(scan.truth.surface[k].unwrap()).unwrap().name;
            let r = cloud.positions()[i as usize].coords.norm();
            if scan.truth.mixed_pixel[k] {
                // A phantom: more than 20 cm from both surfaces (every true range around it).
                let (c0, r0) = ((k % w) as i64, (k / w) as i64);
                let off_all = (-1..=1i64)
                    .flat_map(|dr| (-1..=1i64).map(move |dc| (c0 + dc, r0 + dr)))
                    .filter(|&(c, rr)| c >= 0 && rr >= 0 && c < w as i64 && rr < h as i64)
                    .all(|(c, rr)| {
                        let t = scan.truth.true_range[rr as usize * w + c as usize];
                        t.is_none_or(|t| (r - t as f64).abs() > 0.2)
                    });
                if off_all {
                    phantoms += 1;
                    phantoms_removed += flags[i as usize] as usize;
                }
            } else if name.starts_with("post") || name.starts_with("leg") {
                total += 1;
                kept += !flags[i as usize] as usize;
            }
        }
    }
    println!("thin: kept {kept} of {total}; phantoms removed {phantoms_removed} of {phantoms}");
    assert!(total > 500, "{total}");
    assert!(kept as f64 > 0.9 * total as f64, "kept {kept} of {total}");
    assert!(phantoms > 30, "{phantoms}");
    // The foreground guard keeps the phantoms that lie just behind the post's silhouette.
    assert!(phantoms_removed as f64 > 0.75 * phantoms as f64, "{phantoms_removed} of {phantoms}");
}

#[test]
fn removal_keeps_the_grid_and_the_attributes() {
    let alrf = Alrf::new(AlrfConfig::sick_s300_with_step(2f64.to_radians()).unwrap()).unwrap();
    let scene = scene_sim::lab(3).unwrap();
    let body = scene.scan_poses(1, 0.5, 3)[0];
    let cloud = project_cloud(&alrf.scan(&scene, &alrf.mount(&body), 3));
    let config = MixedPixelConfig::alrf();
    let flags = mixed_pixels(&cloud, &config).unwrap();
    assert_eq!(flags.len(), cloud.len());
    let (kept, removed) = remove_mixed_pixels(&cloud, &config).unwrap();
    assert!(removed > 0);
    assert_eq!(removed, flags.iter().filter(|&&f| f).count());
    assert_eq!(kept.len() + removed, cloud.len());
    let (g0, g1) = (cloud.grid().unwrap(), kept.grid().unwrap());
    assert_eq!((g0.width(), g0.height()), (g1.width(), g1.height()));
    assert_eq!(g1.num_valid(), kept.len());
    for (&a, &b) in g0.pixels().iter().zip(g1.pixels()) {
        if a == INVALID_PIXEL || flags[a as usize] {
            assert_eq!(b, INVALID_PIXEL);
        } else {
            assert_eq!(cloud.positions()[a as usize], kept.positions()[b as usize]);
            assert_eq!(cloud.labels().unwrap()[a as usize], kept.labels().unwrap()[b as usize]);
        }
    }
    assert_eq!(kept.sensor_pose(), cloud.sensor_pose());
}

#[test]
fn a_grazing_floor_loses_nothing() {
    // An organised noise-free scan of a floor 0.5 m below the sensor whose grid is skewed like
    // the ALRF's backward-looking half: the depression angle changes along every grid line
    // (0.25° per column, 0.5° per row), so at 1.5°–5° of depression (ranges 6–19 m) every grid
    // line is a veil edge and only plane support keeps the floor.
    let (w, h) = (121u32, 60u32);
    let mut pixels = Vec::new();
    for row in 0..h {
        for col in 0..w {
            let yaw = (col as f64 - 60.0).to_radians() * 0.5;
            let down = (1.5 + 0.25 * col as f64 + 0.5 * row as f64).to_radians();
            let dir = Vector3::new(yaw.cos() * down.cos(), yaw.sin() * down.cos(), -down.sin());
            pixels.push(Some(Point3::from(dir * (0.5 / down.sin()))));
        }
    }
    let floor = PointCloud::from_pixels(w, h, pixels).unwrap();
    let flags = mixed_pixels(&floor, &MixedPixelConfig::alrf()).unwrap();
    assert_eq!(flags.iter().filter(|&&f| f).count(), 0);
    let no_plane = MixedPixelConfig { plane_tolerance: None, ..MixedPixelConfig::alrf() };
    let flags = mixed_pixels(&floor, &no_plane).unwrap();
    assert!(flags.iter().filter(|&&f| f).count() > 100);
}

#[test]
fn bad_input_is_refused() {
    let config = MixedPixelConfig::alrf();
    // Unorganised clouds, empty or not.
    let loose = PointCloud::from_positions(vec![Point3::new(1.0, 0.0, 0.0); 4]).unwrap();
    assert_eq!(mixed_pixels(&loose, &config), Err(MixedPixelError::NotOrganised));
    assert_eq!(mixed_pixels(&PointCloud::new(), &config), Err(MixedPixelError::NotOrganised));
    assert!(matches!(remove_mixed_pixels(&loose, &config), Err(MixedPixelError::NotOrganised)));
    // Organised but empty (no valid pixel, or no pixel): no flags.
    let empty = PointCloud::from_pixels(3, 2, vec![None; 6]).unwrap();
    assert_eq!(mixed_pixels(&empty, &config), Ok(vec![]));
    let (out, n) = remove_mixed_pixels(&empty, &config).unwrap();
    assert_eq!((out.len(), n), (0, 0));
    let nothing = PointCloud::from_pixels(0, 0, Vec::new()).unwrap();
    assert_eq!(mixed_pixels(&nothing, &config), Ok(vec![]));
    // A point at the sensor origin has no beam: never flagged, no panic.
    let origin = [Some(Point3::origin()), Some(Point3::new(5.0, 0.0, 0.0))];
    let origin = PointCloud::from_pixels(2, 1, origin).unwrap();
    assert!(!mixed_pixels(&origin, &config).unwrap()[0]);
    // Bad configurations.
    let bad = [
        MixedPixelConfig { max_veil_angle: 0.0, ..config },
        MixedPixelConfig { max_veil_angle: std::f64::consts::FRAC_PI_2, ..config },
        MixedPixelConfig { max_veil_angle: f64::NAN, ..config },
        MixedPixelConfig { min_jump: -0.1, ..config },
        MixedPixelConfig { min_jump: f64::INFINITY, ..config },
        MixedPixelConfig { min_jump: 1e6, ..config },
        MixedPixelConfig { plane_tolerance: Some(0.0), ..config },
        MixedPixelConfig { plane_tolerance: Some(f64::NAN), ..config },
        MixedPixelConfig { plane_tolerance: Some(1e9), ..config },
    ];
    for c in bad {
        assert!(matches!(c.validate(), Err(MixedPixelError::BadParameter { .. })), "{c:?}");
        assert!(matches!(mixed_pixels(&empty, &c), Err(MixedPixelError::BadParameter { .. })));
    }
    for sigma in [0.0, -0.01, f64::NAN, 2.0] {
        assert!(MixedPixelConfig::for_range_noise(sigma).is_err(), "{sigma}");
    }
    assert_eq!(MixedPixelConfig::for_range_noise(0.03).unwrap(), MixedPixelConfig::alrf());
    for c in [MixedPixelConfig::alrf(), MixedPixelConfig::range_camera()] {
        c.validate().unwrap();
    }
}

/// The figures of the module docs: S300 scans of the lab and the office at full resolution
/// (0.5°) and at 1° (`AlrfConfig::sick_s300_with_step`), 3 seeds × 4 scan poses each.
#[test]
#[ignore = "full resolution, slow in debug: cargo test --release ... -- --ignored --nocapture"]
fn report_full_resolution() {
    let config = MixedPixelConfig::alrf();
    println!(
        "| scene | points | removed | recall, all mixed | recall > 3σ (n) | phantom recall > 9 cm (n) | > 20 cm (n) | clean loss | thin-obstacle loss (n) | far-floor loss (n; interior) | time/scan |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for (step, alrf) in [("0.5°", Alrf::sick_s300()), ("1°", alrf_1deg())] {
        for (name, build) in [
            ("lab", scene_sim::lab as fn(u64) -> Result<Scene, scene_sim::SceneError>),
            ("office", scene_sim::office),
        ] {
            let mut all = Stats::default();
            let mut ms = 0.0;
            let seeds = [1u64, 2, 3];
            for seed in seeds {
                let (s, t) = run(&build(seed).unwrap(), &alrf, 4, seed, &config, 5);
                all.add(&s);
                ms += t / seeds.len() as f64;
            }
            println!("{}", all.row(&format!("{name}, {step}"), ms));
        }
    }
}
