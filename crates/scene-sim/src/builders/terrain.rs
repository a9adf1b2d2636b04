//! One scene per terrain class of the thesis's Hough-transform terrain classification
//! (Chapter 4, §4.2): floor, ramp, plateau, canyon and obstacle, with walls, clutter and rubble
//! as kinds of obstacle.
//!
//! The robot stands at the origin looking along +x; the floor is `z = 0`. Every scene spans
//! x ∈ [−3, 12] m, y ∈ [−6, 6] m, the terrain feature starts at `distance` ahead. Each scene
//! carries its [`TerrainTruth`] ([`crate::Scene::terrain_truth`]): the class, the parameters,
//! whether Rugbot could pass (thesis §4.2: steps above 0.2 m and ramps whose combined angle
//! exceeds 35° are not passable), and the label the thesis's evaluation would give it.
//!
//! | spec | geometry |
//! |---|---|
//! | `Floor` | the floor alone |
//! | `Ramp` | a 4 m wide, 4 m long ramp starting at `distance`, pitched (positive climbs) and rolled about its own axes; uphill it rests on the floor and ends at a 3 m platform, downhill it leads into a trench of the same width with side and end walls |
//! | `Plateau` | the ground ahead is a block `height` high over the full width from `distance` on (a step up) |
//! | `Canyon` | the ground ahead drops by `depth` over the full width from `distance` on (a step down) |
//! | `Wall` | an 8 m wide vertical wall at `distance` |
//! | `Obstacles` | `count` boxes and upright cylinders (0.2–0.8 m wide, 0.3–1.2 m high) in x ∈ [d, d+4], y ∈ [−2.5, 2.5] |
//! | `Rubble` | `count` small boxes (edges 30–100 % of `max_size`, any yaw, tilted up to 25°, partly sunk) in x ∈ [d, d+3], y ∈ [−2, 2] |
//!
//! Simplified: with roll the ramp's start edge is tilted about its centre, so one side starts
//! up to 2 m·|sin roll| above the floor (the other side is below it, hidden); the rolled top
//! platform of an uphill ramp is a tilted box.

use super::geometry::{horizontal_rect, vertical_rect};
use crate::shapes::Point2;
use crate::{Cuboid, Cylinder, Material, PlanarPolygon, Scene, SceneBuilder, SceneError};
use pointcloud::{Isometry3, Point3, Real, Vector3};
use rand::{Rng as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// The ground's extent behind the robot, metres (x).
pub const X_BACK: Real = -3.0;
/// The ground's extent ahead of the robot, metres (x).
pub const X_FAR: Real = 12.0;
/// Half the ground's width, metres (y).
pub const HALF_WIDTH: Real = 6.0;
/// A ramp's width, metres.
pub const RAMP_WIDTH: Real = 4.0;
/// A ramp's length along its slope, metres.
pub const RAMP_LENGTH: Real = 4.0;
/// The length of the platform after an uphill ramp, metres.
pub const PLATFORM_LENGTH: Real = 3.0;
/// Rugbot's largest passable step (thesis §4.2), metres.
pub const MAX_PASSABLE_STEP: Real = 0.2;
/// Rugbot's largest passable combined ramp angle (thesis §4.2), radians (35°).
pub const MAX_PASSABLE_SLOPE: Real = 35.0 * std::f64::consts::PI / 180.0;

/// A terrain scene to build. Angles in radians, lengths in metres; `distance` is where the
/// feature starts ahead of the robot (along +x).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum TerrainSpec {
    /// Flat floor only.
    Floor,
    /// An inclined plane: `pitch` in [−60°, 60°] (positive climbs along +x), `roll` in
    /// [−45°, 45°] (positive raises the left, +y, side). The ramp's frame is rotated by
    /// `Ry(−pitch)·Rx(roll)` about the centre of its start edge.
    Ramp {
        /// Slope along x, radians.
        pitch: Real,
        /// Slope across, radians.
        roll: Real,
        /// Start of the ramp, metres ahead.
        distance: Real,
    },
    /// A step up to even ground `height` (0, 3] m above the robot.
    Plateau {
        /// Step height, metres.
        height: Real,
        /// Step position, metres ahead.
        distance: Real,
    },
    /// A step down to even ground `depth` (0, 5] m below the robot.
    Canyon {
        /// Step depth, metres.
        depth: Real,
        /// Step position, metres ahead.
        distance: Real,
    },
    /// A vertical wall `height` (0, 5] m high.
    Wall {
        /// Wall position, metres ahead.
        distance: Real,
        /// Wall height, metres.
        height: Real,
    },
    /// `count` (1–100) random boxes and cylinders.
    Obstacles {
        /// Number of obstacles.
        count: u32,
        /// Start of the cluttered area, metres ahead.
        distance: Real,
    },
    /// `count` (1–5000) small random boxes, edges up to `max_size` ([0.02, 1] m).
    Rubble {
        /// Number of pieces.
        count: u32,
        /// Largest edge length, metres.
        max_size: Real,
        /// Start of the rubble field, metres ahead.
        distance: Real,
    },
}

/// The kind of terrain a scene shows.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum TerrainClass {
    /// Flat ground at robot level.
    Floor,
    /// Inclined ground ahead.
    Ramp,
    /// Even ground above the robot (a step up).
    Plateau,
    /// Even ground below the robot (a step down).
    Canyon,
    /// A vertical wall.
    Wall,
    /// Cluttered free-standing obstacles.
    Obstacle,
    /// Small pieces of rubble on the floor.
    Rubble,
}

/// The five classes of the thesis's Hough classifier (Algorithm 3).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum HoughClass {
    /// Flat ground at robot level.
    Floor,
    /// Inclined ground.
    Ramp,
    /// Even ground below the robot.
    Canyon,
    /// Even ground above the robot.
    Plateau,
    /// Anything else in the way.
    Obstacle,
}

/// What a terrain scene shows, for scoring a classifier.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TerrainTruth {
    /// The scene's class.
    pub class: TerrainClass,
    /// The parameters it was built from.
    pub spec: TerrainSpec,
    /// Whether Rugbot could drive over it (thesis §4.2: steps ≤ 0.2 m, combined ramp angle
    /// ≤ 35°; walls and obstacles never; rubble if no piece exceeds 0.2 m).
    pub passable: bool,
    /// The label the thesis's evaluation gives: drivable plateaus and canyons (curbs) and
    /// drivable rubble are labelled floor (§4.4.1), walls, clutter and high rubble obstacle.
    pub label: HoughClass,
}

impl TerrainSpec {
    /// The class of scene this spec builds.
    pub fn class(&self) -> TerrainClass {
        match self {
            TerrainSpec::Floor => TerrainClass::Floor,
            TerrainSpec::Ramp { .. } => TerrainClass::Ramp,
            TerrainSpec::Plateau { .. } => TerrainClass::Plateau,
            TerrainSpec::Canyon { .. } => TerrainClass::Canyon,
            TerrainSpec::Wall { .. } => TerrainClass::Wall,
            TerrainSpec::Obstacles { .. } => TerrainClass::Obstacle,
            TerrainSpec::Rubble { .. } => TerrainClass::Rubble,
        }
    }

    /// The combined angle of a ramp: the angle between its normal and the vertical,
    /// `acos(cos pitch · cos roll)`; 0 for other specs.
    pub fn combined_slope(&self) -> Real {
        match *self {
            TerrainSpec::Ramp { pitch, roll, .. } => {
                (pitch.cos() * roll.cos()).clamp(-1.0, 1.0).acos()
            }
            _ => 0.0,
        }
    }

    /// The ground truth of a scene built from this spec.
    pub fn truth(&self) -> TerrainTruth {
        let class = self.class();
        let (passable, label) = match *self {
            TerrainSpec::Floor => (true, HoughClass::Floor),
            TerrainSpec::Ramp { .. } => {
                let slope = self.combined_slope();
                let label = if slope < 1e-9 { HoughClass::Floor } else { HoughClass::Ramp };
                (slope <= MAX_PASSABLE_SLOPE, label)
            }
            TerrainSpec::Plateau { height, .. } => {
                let ok = height <= MAX_PASSABLE_STEP;
                (ok, if ok { HoughClass::Floor } else { HoughClass::Plateau })
            }
            TerrainSpec::Canyon { depth, .. } => {
                let ok = depth <= MAX_PASSABLE_STEP;
                (ok, if ok { HoughClass::Floor } else { HoughClass::Canyon })
            }
            TerrainSpec::Wall { .. } | TerrainSpec::Obstacles { .. } => {
                (false, HoughClass::Obstacle)
            }
            TerrainSpec::Rubble { max_size, .. } => {
                let ok = max_size <= MAX_PASSABLE_STEP;
                (ok, if ok { HoughClass::Floor } else { HoughClass::Obstacle })
            }
        };
        TerrainTruth { class, spec: *self, passable, label }
    }

    /// Checks every parameter against the ranges in the variant docs.
    pub fn validate(&self) -> Result<(), SceneError> {
        fn range(
            what: &'static str,
            v: Real,
            lo: Real,
            hi: Real,
            allowed: &'static str,
        ) -> Result<(), SceneError> {
            if !v.is_finite() {
                return Err(SceneError::NonFinite { what });
            }
            if !(lo..=hi).contains(&v) {
                return Err(SceneError::BadParameter { what, value: v, allowed });
            }
            Ok(())
        }
        fn positive(
            what: &'static str,
            v: Real,
            hi: Real,
            allowed: &'static str,
        ) -> Result<(), SceneError> {
            range(what, v, 0.0, hi, allowed)?;
            if v == 0.0 {
                return Err(SceneError::BadParameter { what, value: v, allowed });
            }
            Ok(())
        }
        let dist = |d: Real| range("terrain distance", d, 0.5, 8.0, "[0.5, 8] m");
        let count = |c: u32, hi: u32, allowed| {
            if c == 0 || c > hi {
                Err(SceneError::BadParameter { what: "terrain count", value: c as Real, allowed })
            } else {
                Ok(())
            }
        };
        match *self {
            TerrainSpec::Floor => Ok(()),
            TerrainSpec::Ramp { pitch, roll, distance } => {
                range("ramp pitch", pitch, -60f64.to_radians(), 60f64.to_radians(), "[-60°, 60°]")?;
                range("ramp roll", roll, -45f64.to_radians(), 45f64.to_radians(), "[-45°, 45°]")?;
                dist(distance)
            }
            TerrainSpec::Plateau { height, distance } => {
                positive("plateau height", height, 3.0, "(0, 3] m")?;
                dist(distance)
            }
            TerrainSpec::Canyon { depth, distance } => {
                positive("canyon depth", depth, 5.0, "(0, 5] m")?;
                dist(distance)
            }
            TerrainSpec::Wall { distance, height } => {
                positive("wall height", height, 5.0, "(0, 5] m")?;
                dist(distance)
            }
            TerrainSpec::Obstacles { count: c, distance } => {
                count(c, 100, "1..=100")?;
                dist(distance)
            }
            TerrainSpec::Rubble { count: c, max_size, distance } => {
                count(c, 5000, "1..=5000")?;
                range("rubble size", max_size, 0.02, 1.0, "[0.02, 1] m")?;
                dist(distance)
            }
        }
    }

    /// A short name: `floor`, `ramp`, `plateau`, `canyon`, `wall`, `obstacles`, `rubble`.
    pub fn short_name(&self) -> &'static str {
        match self {
            TerrainSpec::Floor => "floor",
            TerrainSpec::Ramp { .. } => "ramp",
            TerrainSpec::Plateau { .. } => "plateau",
            TerrainSpec::Canyon { .. } => "canyon",
            TerrainSpec::Wall { .. } => "wall",
            TerrainSpec::Obstacles { .. } => "obstacles",
            TerrainSpec::Rubble { .. } => "rubble",
        }
    }
}

fn floor_rect(
    x0: Real,
    x1: Real,
    z: Real,
    holes: &[(Point2, Point2)],
) -> Result<PlanarPolygon, SceneError> {
    horizontal_rect(Point2::new(x0, -HALF_WIDTH), Point2::new(x1, HALF_WIDTH), z, true, holes)
}

/// The terrain scene `spec` describes (see the module docs), seeded for obstacles and rubble.
/// Fails if a parameter is out of range ([`TerrainSpec::validate`]).
pub fn terrain(spec: &TerrainSpec, seed: u64) -> Result<Scene, SceneError> {
    spec.validate()?;
    let mut b = SceneBuilder::new(format!("terrain-{}", spec.short_name()));
    b.set_terrain_truth(spec.truth());
    let ground = Material::CONCRETE;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    match *spec {
        TerrainSpec::Floor => {
            b.add("floor", floor_rect(X_BACK, X_FAR, 0.0, &[])?, ground)?;
        }
        TerrainSpec::Ramp { pitch, roll, distance } => add_ramp(&mut b, pitch, roll, distance)?,
        TerrainSpec::Plateau { height, distance } => {
            b.add("floor", floor_rect(X_BACK, distance, 0.0, &[])?, ground)?;
            b.add(
                "plateau",
                Cuboid::axis_aligned(
                    Point3::new(distance, -HALF_WIDTH, 0.0),
                    Point3::new(X_FAR, HALF_WIDTH, height),
                )?,
                ground,
            )?;
        }
        TerrainSpec::Canyon { depth, distance } => {
            b.add("floor", floor_rect(X_BACK, distance, 0.0, &[])?, ground)?;
            b.add(
                "canyon/drop",
                vertical_rect(
                    Point3::new(distance, 0.0, 0.0),
                    -Vector3::x(),
                    (-HALF_WIDTH, HALF_WIDTH),
                    (-depth, 0.0),
                    &[],
                )?,
                ground,
            )?;
            b.add("canyon/floor", floor_rect(distance, X_FAR, -depth, &[])?, ground)?;
        }
        TerrainSpec::Wall { distance, height } => {
            b.add("floor", floor_rect(X_BACK, X_FAR, 0.0, &[])?, ground)?;
            b.add(
                "wall",
                vertical_rect(
                    Point3::new(distance, 0.0, 0.0),
                    -Vector3::x(),
                    (-4.0, 4.0),
                    (0.0, height),
                    &[],
                )?,
                Material::WHITE_MASONRY,
            )?;
        }
        TerrainSpec::Obstacles { count, distance } => {
            b.add("floor", floor_rect(X_BACK, X_FAR, 0.0, &[])?, ground)?;
            for i in 0..count {
                let x = rng.random_range(distance..distance + 4.0);
                let y = rng.random_range(-2.5..2.5);
                let h = rng.random_range(0.3..1.2);
                if rng.random_bool(0.6) {
                    let s = Vector3::new(rng.random_range(0.2..0.8), rng.random_range(0.2..0.8), h);
                    let yaw = rng.random_range(-std::f64::consts::PI..std::f64::consts::PI);
                    b.add(
                        format!("obstacle-{i}"),
                        Cuboid::standing(Point2::new(x, y), 0.0, s, yaw)?,
                        Material::WOOD,
                    )?;
                } else {
                    let r = rng.random_range(0.1..0.4);
                    b.add(
                        format!("obstacle-{i}"),
                        Cylinder::upright(Point3::new(x, y, 0.0), r, h)?,
                        Material::NEWSPAPER,
                    )?;
                }
            }
        }
        TerrainSpec::Rubble { count, max_size, distance } => {
            b.add("floor", floor_rect(X_BACK, X_FAR, 0.0, &[])?, ground)?;
            let tilt = 25f64.to_radians();
            for i in 0..count {
                let s = Vector3::from_fn(|_, _| rng.random_range(0.3..1.0) * max_size);
                let x = rng.random_range(distance..distance + 3.0);
                let y = rng.random_range(-2.0..2.0);
                let rot = nalgebra::UnitQuaternion::from_euler_angles(
                    rng.random_range(-tilt..tilt),
                    rng.random_range(-tilt..tilt),
                    rng.random_range(-std::f64::consts::PI..std::f64::consts::PI),
                );
                let m = Isometry3::from_parts(nalgebra::Translation3::new(x, y, s.z * 0.25), rot);
                let material = if i % 2 == 0 { Material::LIMESTONE } else { Material::ASPHALT };
                b.add(format!("rubble-{i}"), Cuboid::new(m, s / 2.0)?, material)?;
            }
        }
    }
    b.build()
}

/// A vertical polygon in the plane `y = y_side` from world (x, z) corners.
fn side_polygon(y_side: Real, xz: Vec<Point2>) -> Result<PlanarPolygon, SceneError> {
    // Local (x, y) = world (x, z); the normal (local z) is world −y.
    let m =
        Isometry3::new(Vector3::new(0.0, y_side, 0.0), Vector3::x() * std::f64::consts::FRAC_PI_2);
    PlanarPolygon::new(m, xz, Vec::new())
}

fn add_ramp(b: &mut SceneBuilder, pitch: Real, roll: Real, d: Real) -> Result<(), SceneError> {
    let ground = Material::CONCRETE;
    let rot = nalgebra::UnitQuaternion::from_euler_angles(roll, -pitch, 0.0);
    let (u, v) = (rot * Vector3::x(), rot * Vector3::y());
    let start = Point3::new(d, 0.0, 0.0);
    let end = start + u * RAMP_LENGTH;
    let hw = RAMP_WIDTH / 2.0;
    let ramp = PlanarPolygon::rectangle(
        Isometry3::from_parts(start.coords.into(), rot),
        Point2::new(0.0, -hw),
        Point2::new(RAMP_LENGTH, hw),
        &[],
    )?;
    // Platform / trench floor frame: y along the ramp's end edge (v), x horizontal.
    let px = v.cross(&Vector3::z()).normalize();
    let pz = px.cross(&v);
    let platform_rot = nalgebra::UnitQuaternion::from_rotation_matrix(
        &nalgebra::Rotation3::from_basis_unchecked(&[px, v, pz]),
    );
    let y_side = hw * v.y;
    if pitch >= 0.0 {
        b.add("floor", floor_rect(X_BACK, X_FAR, 0.0, &[])?, ground)?;
        b.add("ramp", ramp, Material::WOOD)?;
        // Side walls under the ramp, where the ramp edge is above the floor.
        for (name, t) in [("ramp/side-left", hw), ("ramp/side-right", -hw)] {
            let p0 = start + v * t;
            let p1 = p0 + u * RAMP_LENGTH;
            if p1.z <= 1e-3 {
                continue;
            }
            let poly = if p0.z >= 0.0 {
                vec![
                    Point2::new(p0.x, 0.0),
                    Point2::new(p1.x, 0.0),
                    Point2::new(p1.x, p1.z),
                    Point2::new(p0.x, p0.z),
                ]
            } else {
                let s0 = -p0.z / (p1.z - p0.z);
                let x0 = p0.x + s0 * (p1.x - p0.x);
                vec![Point2::new(x0, 0.0), Point2::new(p1.x, 0.0), Point2::new(p1.x, p1.z)]
            };
            if let Ok(p) = side_polygon(p0.y, poly) {
                b.add(name, p, Material::WOOD)?;
            }
        }
        // The platform: a box whose top face continues from the ramp's end edge.
        let top = end.z + hw * v.z.abs();
        let hz = (top + 0.05).max(0.05) / 2.0;
        let center = end + px * (PLATFORM_LENGTH / 2.0) - pz * hz;
        b.add(
            "platform",
            Cuboid::new(
                Isometry3::from_parts(center.coords.into(), platform_rot),
                Vector3::new(PLATFORM_LENGTH / 2.0, hw, hz),
            )?,
            ground,
        )?;
    } else {
        let hole = (Point2::new(d, -y_side.abs()), Point2::new(X_FAR, y_side.abs()));
        b.add("floor", floor_rect(X_BACK, X_FAR, 0.0, &[hole])?, ground)?;
        b.add("ramp", ramp, Material::WOOD)?;
        let rest = X_FAR - end.x;
        if rest > 0.01 {
            b.add(
                "trench/floor",
                PlanarPolygon::rectangle(
                    Isometry3::from_parts(end.coords.into(), platform_rot),
                    Point2::new(0.0, -hw),
                    Point2::new(rest / px.x.max(1e-6), hw),
                    &[],
                )?,
                ground,
            )?;
        }
        let bottom = end.z - hw * v.z.abs() - 0.05;
        for (name, y) in [("trench/side-left", y_side.abs()), ("trench/side-right", -y_side.abs())]
        {
            let normal = if y > 0.0 { -Vector3::y() } else { Vector3::y() };
            let t = Vector3::z().cross(&normal);
            let s = t.x;
            b.add(
                name,
                vertical_rect(
                    Point3::new(0.0, y, 0.0),
                    normal,
                    (s * d, s * X_FAR),
                    (bottom, 0.0),
                    &[],
                )?,
                ground,
            )?;
        }
        b.add(
            "trench/end",
            vertical_rect(
                Point3::new(X_FAR, 0.0, 0.0),
                -Vector3::x(),
                (-y_side.abs(), y_side.abs()),
                (bottom, 0.0),
                &[],
            )?,
            ground,
        )?;
    }
    Ok(())
}
