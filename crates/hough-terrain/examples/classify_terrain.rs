//! Classifies simulated terrain frames: five `scene-sim` terrain scenes (a floor, a 20° and a
//! 45° ramp, a 0.3 m deep canyon, a wall), each seen by a simulated SwissRanger SR-3000 mounted
//! level 0.45 m above the ground, classified by the plane Hough transform at 15°
//! (Algorithms 2 and 3). Prints the class, drivability, winning plane and time of each frame.
//!
//! ```sh
//! cargo run -p hough-terrain --example classify_terrain
//! ```

use hough_terrain::{HoughClassifier, HoughConfig, SensorAxes, SensorMount};
use pointcloud::{Point3, SensorPose};
use scene_sim::{RangeCamera, RangeSensor, TerrainSpec, terrain};
use std::time::Instant;

const HEIGHT: f64 = 0.45;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let camera = RangeCamera::swissranger_sr3000();
    // The robot at the origin looking along +x, the camera level at 0.45 m.
    let robot = SensorPose::from_position_rpy(Point3::new(0.0, 0.0, HEIGHT), 0.0, 0.0, 0.0);
    let mount = SensorMount::looking_ahead(HEIGHT, 0.0, 0.0, SensorAxes::Optical)?;
    let mut classifier = HoughClassifier::new(HoughConfig::thesis(15f64.to_radians(), mount)?)?;

    let ramp = |deg: f64| TerrainSpec::Ramp { pitch: deg.to_radians(), roll: 0.0, distance: 1.5 };
    let specs = [
        ("floor", TerrainSpec::Floor),
        ("ramp 20°", ramp(20.0)),
        ("ramp 45°", ramp(45.0)),
        ("canyon 0.3 m", TerrainSpec::Canyon { depth: 0.3, distance: 1.5 }),
        ("wall", TerrainSpec::Wall { distance: 1.0, height: 2.0 }),
    ];
    for (name, spec) in specs {
        let scene = terrain(&spec, 3)?;
        let frame = camera.scan(&scene, &camera.mount(&robot), 1).to_cloud()?;
        let t = Instant::now();
        let c = classifier.classify_cloud(&frame)?;
        let took = t.elapsed();
        let plane = c.plane.map_or(String::from("none"), |p| {
            format!(
                "ρx {:.0}°, ρy {:.0}°, d {:.2} m",
                p.rho_x.to_degrees(),
                p.rho_y.to_degrees(),
                p.d
            )
        });
        println!(
            "{name:>12}: {:?}, drivable {}, plane {plane}, {} points in {:.1} ms",
            c.class,
            c.drivable,
            frame.len(),
            took.as_secs_f64() * 1e3
        );
    }
    Ok(())
}
