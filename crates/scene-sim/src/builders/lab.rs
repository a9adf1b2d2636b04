//! The robotics lab of the thesis's Lab dataset (§3.2.1): "a circuit around our lab",
//! 29 actuated-LRF clouds of up to 541 × 361 points, in a room with "a locomotion test arena
//! in form of a high bay rack" (Fig. 3.7). Table 3.2 gives the dataset's mean bounding volume
//! as 343.59 m³, which a 12 × 9 × 4 m room (432 m³, partly unseen) matches.
//!
//! Layout (metres, x east, y north, z up; interior faces of the room only):
//!
//! * room x ∈ [0, 12], y ∈ [0, 9], floor z = 0 (concrete), ceiling z = 4 (white);
//! * a door opening 1.2 × 2.1 m in the south wall at x ∈ [1.0, 2.2] and two windows
//!   1.5 × 1.4 m in the east wall (y ∈ [2, 3.5] and [5.5, 7], z ∈ [1, 2.4]): beams through them
//!   hit nothing, as beams into the sky return nothing;
//! * the high-bay rack along the north wall: x ∈ [1, 7], y ∈ [7.3, 8.8], eight posts
//!   (0.08 × 0.08 × 3.1 m) at x = 1, 3, 5, 7, four wooden levels (0.04 m boards) at
//!   z = 0.75, 1.5, 2.25, 3.0, a ramp from the floor at x = 9 up to the first level, and
//!   seeded boxes on the levels;
//! * seeded free-standing objects on the floor (x ∈ [0.5, 11.5], y ∈ [0.5, 6.8], clear of the
//!   door): two tables (1.6 × 0.8 m top at 0.75 m on four cylindrical legs, radius 2.5 cm), five
//!   cardboard boxes (0.3–0.8 m, any yaw), a dark barrel (cylinder r 0.3 m, 0.9 m high,
//!   asphalt-like 17 % reflectivity) and a ball (sphere r 0.25 m).
//!
//! Simplified: no people, cables, lamps or clutter on the walls; materials from Table 2.3.

use super::geometry::{horizontal_rect, vertical_rect};
use crate::shapes::Point2;
use crate::{Cuboid, Cylinder, Material, PlanarPolygon, Scene, SceneBuilder, SceneError, Sphere};
use pointcloud::{Point3, Real, Vector3};
use rand::{Rng as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;

/// Room size (x, y, z), metres.
pub const ROOM: [Real; 3] = [12.0, 9.0, 4.0];

/// The lab with seeded furniture (see the module documentation for the layout).
pub fn lab(seed: u64) -> Result<Scene, SceneError> {
    let [lx, ly, lz] = ROOM;
    let mut b = SceneBuilder::new("lab");
    let wall = Material::WHITE_MASONRY;
    let (lo, hi) = (Point2::new(0.0, 0.0), Point2::new(lx, ly));
    b.add("floor", horizontal_rect(lo, hi, 0.0, true, &[])?, Material::CONCRETE)?;
    b.add("ceiling", horizontal_rect(lo, hi, lz, false, &[])?, wall)?;
    // vertical_rect's horizontal coordinate runs along z × normal from the origin.
    // South wall (y = 0), normal +y: along z × y = −x.
    b.add(
        "wall-south",
        vertical_rect(
            Point3::origin(),
            Vector3::y(),
            (-lx, 0.0),
            (0.0, lz),
            &[(-2.2, -1.0, 0.0, 2.1)],
        )?,
        wall,
    )?;
    // North wall (y = 9), normal −y: along +x.
    b.add(
        "wall-north",
        vertical_rect(Point3::new(0.0, ly, 0.0), -Vector3::y(), (0.0, lx), (0.0, lz), &[])?,
        wall,
    )?;
    // West wall (x = 0), normal +x: along +y.
    b.add(
        "wall-west",
        vertical_rect(Point3::origin(), Vector3::x(), (0.0, ly), (0.0, lz), &[])?,
        wall,
    )?;
    // East wall (x = 12), normal −x: along −y.
    b.add(
        "wall-east",
        vertical_rect(
            Point3::new(lx, 0.0, 0.0),
            -Vector3::x(),
            (-ly, 0.0),
            (0.0, lz),
            &[(-3.5, -2.0, 1.0, 2.4), (-7.0, -5.5, 1.0, 2.4)],
        )?,
        wall,
    )?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    add_rack(&mut b, &mut rng)?;
    add_floor_objects(&mut b, &mut rng)?;
    b.build()
}

const RACK_X: (Real, Real) = (1.0, 7.0);
const RACK_Y: (Real, Real) = (7.3, 8.8);
const LEVELS: [Real; 4] = [0.75, 1.5, 2.25, 3.0];

fn add_rack(b: &mut SceneBuilder, rng: &mut ChaCha8Rng) -> Result<(), SceneError> {
    let post = 0.08;
    for (i, x) in [1.0, 3.0, 5.0, 7.0].into_iter().enumerate() {
        for (j, y) in [RACK_Y.0, RACK_Y.1].into_iter().enumerate() {
            b.add(
                format!("rack/post-{i}-{j}"),
                Cuboid::standing(Point2::new(x, y), 0.0, Vector3::new(post, post, 3.1), 0.0)?,
                Material::ASPHALT,
            )?;
        }
    }
    let board = 0.04;
    for (k, z) in LEVELS.into_iter().enumerate() {
        b.add(
            format!("rack/level-{k}"),
            Cuboid::axis_aligned(
                Point3::new(RACK_X.0 - post / 2.0, RACK_Y.0 - post / 2.0, z - board),
                Point3::new(RACK_X.1 + post / 2.0, RACK_Y.1 + post / 2.0, z),
            )?,
            Material::WOOD,
        )?;
        // One or two boxes on each level, between the posts.
        for n in 0..rng.random_range(1..=2) {
            let s = Vector3::new(
                rng.random_range(0.3..0.6),
                rng.random_range(0.3..0.6),
                rng.random_range(0.2..0.5),
            );
            let cx = rng.random_range(RACK_X.0 + 0.5..RACK_X.1 - 0.5);
            let cy = rng.random_range(RACK_Y.0 + 0.4..RACK_Y.1 - 0.4);
            b.add(
                format!("rack/level-{k}/box-{n}"),
                Cuboid::standing(Point2::new(cx, cy), z, s, rng.random_range(-0.3..0.3))?,
                Material::NEWSPAPER,
            )?;
        }
    }
    // The ramp from the floor at x = 9 to the first level at the rack's east end.
    let (y0, y1) = (RACK_Y.0 + 0.05, RACK_Y.1 - 0.05);
    b.add(
        "rack/ramp",
        PlanarPolygon::parallelogram(
            Point3::new(9.0, y0, 0.0),
            Vector3::new(0.0, y1 - y0, 0.0),
            Vector3::new(RACK_X.1 + 0.04 - 9.0, 0.0, LEVELS[0]),
        )?,
        Material::WOOD,
    )?;
    Ok(())
}

/// Free-standing objects by footprint circle, kept apart by rejection sampling.
fn add_floor_objects(b: &mut SceneBuilder, rng: &mut ChaCha8Rng) -> Result<(), SceneError> {
    let mut placed: Vec<(Real, Real, Real)> = vec![(1.6, 0.0, 1.4)]; // keep the door free
    let mut spot = |rng: &mut ChaCha8Rng, reach: Real| -> Option<(Real, Real)> {
        for _ in 0..200 {
            let x = rng.random_range(0.5 + reach..ROOM[0] - 0.5 - reach);
            let y = rng.random_range(0.5 + reach..6.8 - reach);
            if placed.iter().all(|&(px, py, pr)| (px - x).hypot(py - y) > pr + reach + 0.4) {
                placed.push((x, y, reach));
                return Some((x, y));
            }
        }
        None
    };
    for t in 0..2 {
        let (w, d, h) = (1.6, 0.8, 0.75);
        let Some((x, y)) = spot(rng, (w as Real).hypot(d) / 2.0) else { continue };
        let yaw = if rng.random_bool(0.5) { 0.0 } else { std::f64::consts::FRAC_PI_2 };
        let top = 0.03;
        b.add(
            format!("table-{t}/top"),
            Cuboid::standing(Point2::new(x, y), h - top, Vector3::new(w, d, top), yaw)?,
            Material::WOOD,
        )?;
        let (c, s) = (yaw.cos(), yaw.sin());
        for (k, (fx, fy)) in
            [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)].into_iter().enumerate()
        {
            let (lx, ly) = (fx * (w / 2.0 - 0.08), fy * (d / 2.0 - 0.08));
            let p = Point3::new(x + c * lx - s * ly, y + s * lx + c * ly, 0.0);
            b.add(
                format!("table-{t}/leg-{k}"),
                Cylinder::upright(p, 0.025, h - top)?,
                Material::ASPHALT,
            )?;
        }
    }
    for n in 0..5 {
        let s = Vector3::new(
            rng.random_range(0.3..0.8),
            rng.random_range(0.3..0.8),
            rng.random_range(0.3..0.8),
        );
        let Some((x, y)) = spot(rng, s.x.hypot(s.y) / 2.0) else { continue };
        let yaw = rng.random_range(-std::f64::consts::PI..std::f64::consts::PI);
        b.add(
            format!("box-{n}"),
            Cuboid::standing(Point2::new(x, y), 0.0, s, yaw)?,
            Material::NEWSPAPER,
        )?;
    }
    if let Some((x, y)) = spot(rng, 0.3) {
        b.add("barrel", Cylinder::upright(Point3::new(x, y, 0.0), 0.3, 0.9)?, Material::ASPHALT)?;
    }
    if let Some((x, y)) = spot(rng, 0.25) {
        b.add("ball", Sphere::new(Point3::new(x, y, 0.25), 0.25)?, Material::WHITE_PAPER)?;
    }
    Ok(())
}
