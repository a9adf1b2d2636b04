//! The per-sector mode on a floor with an obstacle on the left: the whole frame says "floor,
//! drivable", the sectors say "left blocked, centre and right free".

use crate::common;

use common::{camera_pose, deg, mount};
use hough_terrain::{HoughClassifier, HoughConfig, SectorClassifier, SectorGrid, TerrainClass};
use pointcloud::{Isometry3, Point3};
use scene_sim::{
    Cuboid, Material, PlanarPolygon, Point2, RangeCamera, RangeSensor, Scene, SceneBuilder,
};

/// Floor plus a 1.2 m high box 1.4–2.4 m ahead, 0.35–1.6 m to the left (world +y).
fn scene_with(left: bool) -> Scene {
    let mut b = SceneBuilder::new("floor-and-box");
    let floor = PlanarPolygon::rectangle(
        Isometry3::identity(),
        Point2::new(-3.0, -6.0),
        Point2::new(12.0, 6.0),
        &[],
    )
    .unwrap();
    b.add("floor", floor, Material::CONCRETE).unwrap();
    let (y0, y1) = if left { (0.35, 1.6) } else { (-1.6, -0.35) };
    let cube = Cuboid::axis_aligned(Point3::new(1.4, y0, 0.0), Point3::new(2.4, y1, 1.2)).unwrap();
    b.add("box", cube, Material::WOOD).unwrap();
    b.build().unwrap()
}

fn frame(scene: &Scene, seed: u64) -> Vec<Point3> {
    let cam = RangeCamera::swissranger_sr3000();
    cam.scan(scene, &camera_pose(&cam), seed).to_cloud().unwrap().positions().to_vec()
}

#[test]
fn obstacle_on_one_side() {
    let grid = SectorGrid::left_centre_right(deg(23.5)).unwrap();
    for left in [true, false] {
        let scene = scene_with(left);
        for seed in 1..=2 {
            let points = frame(&scene, seed);
            for res in [45.0, 15.0, 9.0] {
                let config = HoughConfig::thesis(deg(res), mount()).unwrap();
                let whole = HoughClassifier::new(config).unwrap().classify(&points).unwrap();
                let sectors =
                    SectorClassifier::new(config, grid.clone()).unwrap().classify(&points).unwrap();
                let line: Vec<_> = sectors
                    .iter()
                    .map(|s| {
                        format!(
                            "{:?}/{} ({} pts)",
                            s.classification.class,
                            s.classification.drivable,
                            s.classification.points
                        )
                    })
                    .collect();
                println!(
                    "box {} seed {seed} {res}°: whole {:?}/{}; sectors {line:?}",
                    if left { "left" } else { "right" },
                    whole.class,
                    whole.drivable
                );
                // The whole frame sees mostly floor and calls it drivable: the sectors do not.
                assert!(whole.drivable, "{whole:?}");
                let (blocked, free) = if left { (0, 2) } else { (2, 0) };
                assert!(
                    !sectors[blocked].classification.drivable,
                    "blocked side: {:?}",
                    sectors[blocked]
                );
                assert!(sectors[1].classification.drivable, "centre: {:?}", sectors[1]);
                assert!(sectors[free].classification.drivable, "free side: {:?}", sectors[free]);
                assert_eq!(sectors[free].classification.class, TerrainClass::Floor);
                // Sector points add up to at most the frame's valid points.
                let total: usize = sectors.iter().map(|s| s.classification.points).sum();
                assert!(total <= points.len());
            }
        }
    }
}

#[test]
fn range_rings_and_errors() {
    let grid = SectorGrid::new(vec![deg(-23.5), 0.0, deg(23.5)], vec![0.0, 2.0, 8.0]).unwrap();
    let config = HoughConfig::thesis(deg(15.0), mount()).unwrap();
    let mut c = SectorClassifier::new(config, grid).unwrap();
    let points = frame(&scene_with(true), 1);
    let s = c.classify(&points).unwrap();
    assert_eq!(s.len(), 4);
    assert_eq!(c.accumulators().len(), 4);
    // Near right: floor; the far ring holds the box on the left.
    assert_eq!(s[1].classification.class, TerrainClass::Floor);
    assert!(s[0].range == (0.0, 2.0) && s[2].range == (2.0, 8.0));
    assert!(c.classify(&[]).is_err());
    assert!(c.classify(&[Point3::new(f64::NAN, 0.0, 1.0)]).is_err());
}
