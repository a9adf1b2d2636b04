//! Collision queries of a spherical robot on a tiny map of planar patches: a floor and a wall
//! with a window (a polygon with a hole), in the brute-force reference map every backend is
//! checked against. Three capsule steps (a sphere swept along a segment): through the window,
//! into the wall beside it, and too low over the floor; for each, whether it is free and, if
//! not, where it first touches; then the clearance of a point.
//!
//! ```sh
//! cargo run -p patch-core --example capsule_step
//! ```

use patch_core::{
    BruteForceMap, CapsuleStep, FromPatches, Isometry3, PlanarPatch, Point2, Point3,
    ProximityQuery, SpecificStepIntersector, UnspecificStepIntersector,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // A 6 m × 4 m floor at z = 0.
    let floor = PlanarPatch::rectangle(
        Isometry3::identity(),
        Point2::new(0.0, 0.0),
        Point2::new(6.0, 4.0),
    )?;
    // A wall across the room at x = 3, 2.5 m high, with a 1 m × 1 m window from y = 1.5 to 2.5
    // and z = 0.75 to 1.75.
    let corner = |y: f64, z: f64| Point3::new(3.0, y, z);
    let wall = PlanarPatch::from_world_polygon(
        &[corner(0.0, 0.0), corner(4.0, 0.0), corner(4.0, 2.5), corner(0.0, 2.5)],
        &[vec![corner(1.5, 0.75), corner(2.5, 0.75), corner(2.5, 1.75), corner(1.5, 1.75)]],
        1e-9,
    )?;
    let map = BruteForceMap::from_patches([floor.into(), wall.into()])?;

    // A robot of radius 0.3 m; steps from x = 1 to x = 5.
    let steps = [
        ("through the window", 2.0, 1.25),
        ("into the wall beside it", 0.8, 1.25),
        ("too low over the floor", 2.0, 0.2),
    ];
    for (what, y, z) in steps {
        let step = CapsuleStep::new(Point3::new(1.0, y, z), Point3::new(5.0, y, z), 0.3)?;
        // The unspecific query answers "any contact?", the specific one finds the first.
        let free = map.is_step_free(&step);
        let hit = map.first_hit(&step);
        assert_eq!(free, hit.is_none());
        match hit {
            None => println!("{what}: free"),
            Some(hit) => println!(
                "{what}: hits patch {} at t = {:.3}, point ({:.2}, {:.2}, {:.2})",
                hit.patch.0, hit.t, hit.point.x, hit.point.y, hit.point.z
            ),
        }
    }
    let p = Point3::new(3.0, 2.0, 1.25);
    println!("clearance in the middle of the window: {:.2} m", map.clearance(&p, 10.0));
    Ok(())
}
