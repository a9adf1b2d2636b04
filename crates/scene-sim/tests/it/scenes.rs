//! Scenes: the hierarchy against brute force, the builders' layouts and ground truth, scan
//! poses, and refused input.

use pointcloud::{Isometry3, Point3, Real, Vector3};
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use scene_sim::{
    Cuboid, Cylinder, HoughClass, Material, PlanarPolygon, Point2, Scene, SceneBuilder, SceneError,
    Sphere, TerrainClass, TerrainSpec, UnitVector3, lab, office, office_floorplan, scene_by_name,
    scene_names, terrain,
};

fn random_pose(rng: &mut ChaCha8Rng, extent: Real) -> Isometry3 {
    Isometry3::new(
        Vector3::from_fn(|_, _| rng.random_range(-extent..extent)),
        Vector3::from_fn(|_, _| rng.random_range(-3.0..3.0)),
    )
}

/// A scene of `n` random primitives of every kind in [−10, 10]³.
fn random_scene(seed: u64, n: usize) -> Scene {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut b = SceneBuilder::new("random");
    for i in 0..n {
        let m = random_pose(&mut rng, 10.0);
        let mut s = || rng.random_range(0.1..3.0);
        let (sx, sy) = (s(), s());
        match i % 4 {
            0 => {
                let hole = (Point2::new(-sx / 3.0, -sy / 3.0), Point2::new(sx / 4.0, sy / 5.0));
                let p = PlanarPolygon::rectangle(
                    m,
                    Point2::new(-sx, -sy),
                    Point2::new(sx, sy),
                    &[hole],
                );
                b.add(format!("p{i}"), p.unwrap(), Material::WOOD).unwrap()
            }
            1 => b
                .add(
                    format!("b{i}"),
                    Cuboid::new(m, Vector3::new(sx, sy, s())).unwrap(),
                    Material::WOOD,
                )
                .unwrap(),
            2 => b
                .add(
                    format!("s{i}"),
                    Sphere::new(m.translation.vector.into(), sx).unwrap(),
                    Material::WOOD,
                )
                .unwrap(),
            _ => b
                .add(format!("c{i}"), Cylinder::new(m, sx / 2.0, sy).unwrap(), Material::WOOD)
                .unwrap(),
        };
    }
    b.build().unwrap()
}

fn same_hit(scene: &Scene, o: &Point3, d: &UnitVector3, max: Real) -> Result<(), String> {
    let fast = scene.cast_ray(o, d, max);
    let slow = scene.cast_ray_exhaustive(o, d, max);
    match (fast, slow) {
        (None, None) => Ok(()),
        (Some(a), Some(b)) if (a.distance - b.distance).abs() <= 1e-9 => {
            if a.surface != b.surface && (a.distance - b.distance).abs() > 0.0 {
                return Err(format!("different surfaces {a:?} {b:?}"));
            }
            Ok(())
        }
        (a, b) => Err(format!("BVH {a:?} vs brute force {b:?} for {o} {d:?}")),
    }
}

fn unit(v: Vector3) -> Option<UnitVector3> {
    UnitVector3::try_new(v, 1e-6)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn bvh_equals_brute_force_on_random_scenes(
        seed in 0u64..1000,
        n in 1usize..120,
        rays in proptest::collection::vec(
            (proptest::array::uniform3(-14.0f64..14.0), proptest::array::uniform3(-1.0f64..1.0), 0.5f64..40.0),
            32,
        ),
    ) {
        let scene = random_scene(seed, n);
        for (o, d, max) in rays {
            let Some(d) = unit(Vector3::from(d)) else { continue };
            let o = Point3::from(o);
            if let Err(e) = same_hit(&scene, &o, &d, max) {
                prop_assert!(false, "{}", e);
            }
        }
    }
}

#[test]
fn bvh_equals_brute_force_on_the_built_scenes() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for name in ["office", "lab", "terrain-rubble", "terrain-ramp-roll", "terrain-ramp-down"] {
        let scene = scene_by_name(name, 2).unwrap();
        let b = scene.bounds();
        let mut hits = 0;
        for _ in 0..3000 {
            let o = Point3::from(Vector3::from_fn(|i, _| rng.random_range(b.min[i]..=b.max[i])));
            let d = unit(Vector3::from_fn(|_, _| rng.random_range(-1.0..1.0))).unwrap();
            same_hit(&scene, &o, &d, 30.0).unwrap();
            hits += usize::from(scene.cast_ray(&o, &d, 30.0).is_some());
        }
        assert!(hits > 1000, "{name}: {hits}");
    }
}

#[test]
fn every_name_builds_and_unknown_names_fail() {
    for name in scene_names() {
        let s = scene_by_name(name, 1).unwrap();
        assert!(!s.primitives().is_empty(), "{name}");
        assert_eq!(s.terrain_truth().is_some(), name.starts_with("terrain-"), "{name}");
    }
    assert!(matches!(scene_by_name("moon", 1), Err(SceneError::UnknownScene { .. })));
}

#[test]
fn builders_are_deterministic() {
    let pts = |s: &Scene| s.primitives().iter().map(|p| p.shape.clone()).collect::<Vec<_>>();
    assert_eq!(pts(&office(4).unwrap()), pts(&office(4).unwrap()));
    assert_ne!(pts(&office(4).unwrap()), pts(&office(5).unwrap()));
    assert_eq!(pts(&lab(4).unwrap()), pts(&lab(4).unwrap()));
    assert_ne!(pts(&lab(4).unwrap()), pts(&lab(5).unwrap()));
    let rubble = TerrainSpec::Rubble { count: 50, max_size: 0.2, distance: 2.0 };
    assert_eq!(pts(&terrain(&rubble, 1).unwrap()), pts(&terrain(&rubble, 1).unwrap()));
}

fn ray(scene: &Scene, o: [Real; 3], d: [Real; 3]) -> Option<scene_sim::Hit> {
    scene.cast_ray(&Point3::from(o), &unit(Vector3::from(d)).unwrap(), 100.0)
}

#[test]
fn office_matches_the_benchmark_floor_plan() {
    let s = office_floorplan().unwrap();
    let b = s.bounds();
    assert!((b.min - Point3::new(-0.05, -0.05, 0.0)).norm() < 1e-5, "{b:?}");
    assert!((b.max - Point3::new(20.05, 15.05, 2.5)).norm() < 1e-5, "{b:?}");
    // Along the corridor from the start to the east wall's inner face.
    let h = ray(&s, [10.0, 7.5, 1.25], [1.0, 0.0, 0.0]).unwrap();
    assert!((h.distance - 9.95).abs() < 1e-9);
    assert!(s.surface(h.surface).unwrap().name.starts_with("wall-3/"));
    // Through the S1 door (x 3.5–4.5 in the wall y = 6.5) to the south wall.
    let h = ray(&s, [4.0, 7.5, 1.0], [0.0, -1.0, 0.0]).unwrap();
    assert!((h.distance - 7.45).abs() < 1e-9);
    // Above the door the lintel stops it at the corridor-side face.
    let h = ray(&s, [4.0, 7.5, 2.2], [0.0, -1.0, 0.0]).unwrap();
    assert!((h.distance - 0.95).abs() < 1e-9);
    // Up hits the ceiling, whose plane faces down.
    let h = ray(&s, [4.0, 7.5, 1.0], [0.0, 0.0, 1.0]).unwrap();
    let plane = s.surface(h.surface).unwrap().plane.unwrap();
    assert!((h.distance - 1.5).abs() < 1e-9 && plane.normal.z < -0.99);
    // The lintel underside of the door at x 4–5 … in the corridor's north wall (y = 8.5).
    let h = ray(&s, [5.0, 8.5, 1.0], [0.0, 0.0, 1.0]).unwrap();
    assert!((h.distance - 1.0).abs() < 1e-9);
    // The furnished office adds objects but keeps the corridor free.
    let f = office(1).unwrap();
    assert!(f.primitives().len() > s.primitives().len() + 7);
    let h = ray(&f, [10.0, 7.5, 0.3], [1.0, 0.0, 0.0]).unwrap();
    assert!((h.distance - 9.95).abs() < 1e-9);
}

#[test]
fn lab_has_its_rack_windows_and_door() {
    let s = lab(2).unwrap();
    let b = s.bounds();
    assert!((b.min - Point3::new(0.0, 0.0, 0.0)).norm() < 1e-5);
    assert!((b.max - Point3::new(12.0, 9.0, 4.0)).norm() < 1e-5);
    // Under the rack's first level.
    let h = ray(&s, [4.0, 8.0, 0.1], [0.0, 0.0, 1.0]).unwrap();
    assert!((h.distance - 0.61).abs() < 1e-9, "{h:?}");
    assert!(s.surface(h.surface).unwrap().name.starts_with("rack/level-0"));
    // Out through a window: nothing; between the windows: the east wall.
    assert!(ray(&s, [6.0, 2.75, 1.7], [1.0, 0.0, 0.0]).is_none());
    let h = ray(&s, [6.0, 4.5, 1.7], [1.0, 0.0, 0.0]).unwrap();
    assert!((h.distance - 6.0).abs() < 1e-9);
    // Out through the door.
    assert!(ray(&s, [1.6, 3.0, 1.0], [0.0, -1.0, 0.0]).is_none());
    // The non-planar objects are there.
    let names: Vec<&str> = s.primitives().iter().map(|p| p.name.as_str()).collect();
    assert!(names.contains(&"barrel") && names.contains(&"ball"), "{names:?}");
    assert!(s.surfaces().iter().any(|x| x.plane.is_none()));
}

#[test]
fn terrain_scenes_have_their_geometry_and_truth() {
    let deg = |d: Real| d.to_radians();
    let down = [0.0, 0.0, -1.0];
    // Floor.
    let s = terrain(&TerrainSpec::Floor, 1).unwrap();
    let t = s.terrain_truth().unwrap();
    assert_eq!((t.class, t.label, t.passable), (TerrainClass::Floor, HoughClass::Floor, true));
    assert!((ray(&s, [5.0, 1.0, 0.5], down).unwrap().distance - 0.5).abs() < 1e-9);
    // Ramp up 15° from 2 m: at x = 3 (1 m in) the surface is at tan 15° m.
    let s = terrain(&TerrainSpec::Ramp { pitch: deg(15.0), roll: 0.0, distance: 2.0 }, 1).unwrap();
    let h = ray(&s, [3.0, 0.0, 2.0], down).unwrap();
    assert!((2.0 - h.distance - deg(15.0).tan()).abs() < 1e-9);
    assert!(
        (h.normal.into_inner() - Vector3::new(-deg(15.0).sin(), 0.0, deg(15.0).cos())).norm()
            < 1e-9
    );
    let t = s.terrain_truth().unwrap();
    assert_eq!((t.class, t.label, t.passable), (TerrainClass::Ramp, HoughClass::Ramp, true));
    // Past the ramp: the platform at the ramp's top height.
    let top = 4.0 * deg(15.0).sin();
    let h = ray(&s, [2.0 + 4.0 * deg(15.0).cos() + 1.0, 0.0, 3.0], down).unwrap();
    assert!((3.0 - h.distance - top).abs() < 1e-9);
    // Ramp down into a trench.
    let s = terrain(&TerrainSpec::Ramp { pitch: deg(-20.0), roll: 0.0, distance: 2.0 }, 1).unwrap();
    let h = ray(&s, [3.0, 0.0, 1.0], down).unwrap();
    assert!((1.0 - h.distance + deg(20.0).tan()).abs() < 1e-9);
    let h = ray(&s, [9.0, 0.0, 1.0], down).unwrap();
    assert!((1.0 - h.distance + 4.0 * deg(20.0).sin()).abs() < 1e-9, "trench floor");
    let h = ray(&s, [5.0, 0.0, -0.5], [0.0, 1.0, 0.0]).unwrap();
    assert!((h.distance - 2.0).abs() < 1e-9, "trench side wall");
    // Rolled ramp: its normal leans to −y (left side up), combined angle from pitch and roll.
    let spec = TerrainSpec::Ramp { pitch: deg(30.0), roll: deg(30.0), distance: 2.0 };
    let s = terrain(&spec, 1).unwrap();
    let h = ray(&s, [3.5, 0.0, 3.0], down).unwrap();
    assert!(h.normal.y < -0.3 && h.normal.x < -0.3);
    assert!((h.normal.z - deg(30.0).cos() * deg(30.0).cos()).abs() < 1e-9);
    let t = s.terrain_truth().unwrap();
    assert!(!t.passable, "combined angle {:.1}° > 35°", spec.combined_slope().to_degrees());
    // Step up and step down.
    let s = terrain(&TerrainSpec::Plateau { height: 0.3, distance: 2.5 }, 1).unwrap();
    assert!((ray(&s, [0.0, 0.0, 0.1], [1.0, 0.0, 0.0]).unwrap().distance - 2.5).abs() < 1e-9);
    assert!((ray(&s, [4.0, 0.0, 1.0], down).unwrap().distance - 0.7).abs() < 1e-9);
    let t = s.terrain_truth().unwrap();
    assert_eq!((t.class, t.label, t.passable), (TerrainClass::Plateau, HoughClass::Plateau, false));
    let low = terrain(&TerrainSpec::Plateau { height: 0.1, distance: 2.5 }, 1).unwrap();
    assert_eq!(low.terrain_truth().unwrap().label, HoughClass::Floor, "a curb is labelled floor");
    let s = terrain(&TerrainSpec::Canyon { depth: 0.5, distance: 2.0 }, 1).unwrap();
    assert!((ray(&s, [4.0, 0.0, 1.0], down).unwrap().distance - 1.5).abs() < 1e-9);
    assert!((ray(&s, [0.0, 0.0, -0.2], [1.0, 0.0, 0.0]).unwrap().distance - 2.0).abs() < 1e-9);
    assert_eq!(s.terrain_truth().unwrap().label, HoughClass::Canyon);
    // Wall.
    let s = terrain(&TerrainSpec::Wall { distance: 3.0, height: 2.0 }, 1).unwrap();
    assert!((ray(&s, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]).unwrap().distance - 3.0).abs() < 1e-9);
    assert!(ray(&s, [0.0, 0.0, 2.5], [1.0, 0.0, 0.0]).is_none());
    assert_eq!(s.terrain_truth().unwrap().label, HoughClass::Obstacle);
    // Obstacles and rubble: the right number of pieces, in their area.
    let s = terrain(&TerrainSpec::Obstacles { count: 7, distance: 1.5 }, 3).unwrap();
    assert_eq!(s.primitives().len(), 8);
    let s = terrain(&TerrainSpec::Rubble { count: 200, max_size: 0.15, distance: 1.5 }, 3).unwrap();
    assert_eq!(s.primitives().len(), 201);
    for p in &s.primitives()[1..] {
        let b = p.shape.aabb();
        assert!(b.min.x > 1.2 && b.max.x < 4.8 && b.max.z < 0.2, "{b:?}");
    }
    let t = s.terrain_truth().unwrap();
    assert_eq!((t.class, t.passable, t.label), (TerrainClass::Rubble, true, HoughClass::Floor));
}

#[test]
fn bad_terrain_specs_are_refused() {
    let bad = [
        TerrainSpec::Ramp { pitch: 2.0, roll: 0.0, distance: 2.0 },
        TerrainSpec::Ramp { pitch: 0.1, roll: Real::NAN, distance: 2.0 },
        TerrainSpec::Plateau { height: 0.0, distance: 2.0 },
        TerrainSpec::Canyon { depth: 0.3, distance: 0.1 },
        TerrainSpec::Wall { distance: 3.0, height: -1.0 },
        TerrainSpec::Obstacles { count: 0, distance: 2.0 },
        TerrainSpec::Rubble { count: 10, max_size: 5.0, distance: 2.0 },
    ];
    for spec in bad {
        assert!(terrain(&spec, 1).is_err(), "{spec:?}");
    }
}

#[test]
fn scan_poses_are_free_spread_and_deterministic() {
    for (name, n, height) in [("office", 10, 1.25), ("lab", 8, 0.5), ("terrain-obstacles", 4, 0.5)]
    {
        let s = scene_by_name(name, 6).unwrap();
        let poses = s.scan_poses(n, height, 6);
        assert_eq!(poses.len(), n, "{name}");
        assert_eq!(poses, s.scan_poses(n, height, 6));
        assert_ne!(poses, s.scan_poses(n, height, 7));
        let b = s.bounds();
        for p in &poses {
            let o = p.origin();
            assert!(b.contains(&o) && (o.z - height).abs() < 1e-12, "{name} {o}");
            assert!(s.is_free_standing_spot(o.x, o.y, height));
            for prim in s.primitives() {
                for dz in [0.1, height / 2.0, height] {
                    let q = Point3::new(o.x, o.y, dz);
                    assert!(!prim.shape.contains(&q), "{name}: {o} inside {}", prim.name);
                }
            }
        }
        let min_gap = poses
            .iter()
            .enumerate()
            .flat_map(|(i, a)| poses[i + 1..].iter().map(move |b| (a.origin() - b.origin()).norm()))
            .fold(Real::INFINITY, Real::min);
        assert!(min_gap > 1.0, "{name}: poses {min_gap} m apart");
    }
    // The office poses reach several rooms and the corridor.
    let s = office(6).unwrap();
    let rooms: std::collections::BTreeSet<(i32, i32)> = s
        .scan_poses(12, 1.25, 1)
        .iter()
        .map(|p| {
            let o = p.origin();
            let row = if o.y < 6.5 {
                0
            } else if o.y < 8.5 {
                1
            } else {
                2
            };
            (row, (o.x / 5.0) as i32)
        })
        .collect();
    assert!(rooms.len() >= 6, "{rooms:?}");
    // A sensor higher than the ceiling finds no pose.
    assert!(s.scan_poses(3, 3.0, 1).is_empty());
}

#[test]
fn bad_scene_input_is_refused() {
    assert_eq!(SceneBuilder::new("empty").build().unwrap_err(), SceneError::Empty);
    let mut b = SceneBuilder::new("x");
    let ball = Sphere::new(Point3::origin(), 1.0).unwrap();
    assert!(matches!(
        b.add("ball", ball.clone(), Material { reflectivity: 1.5, textured: true }),
        Err(SceneError::BadReflectivity { .. })
    ));
    assert!(Material::new(-0.1, true).is_err());
    b.add("ball", ball, Material::new(0.3, true).unwrap()).unwrap();
    let s = b.build().unwrap();
    // Non-finite rays find nothing rather than panicking.
    let d = unit(Vector3::x()).unwrap();
    assert!(s.cast_ray(&Point3::new(Real::NAN, 0.0, 0.0), &d, 10.0).is_none());
    assert!(s.cast_ray(&Point3::new(-5.0, 0.0, 0.0), &d, Real::NAN).is_none());
    assert!(s.cast_ray(&Point3::new(-5.0, 0.0, 0.0), &d, Real::INFINITY).is_some());
}
