//! Deterministic scene builders: the office floor plan, the lab, and one scene per terrain
//! class, plus lookup by name for the command line.
//!
//! Every builder takes a seed; the same seed gives the same scene (ChaCha8 random numbers),
//! and the fixed part of each layout (walls, rack, terrain feature) does not depend on it.

mod geometry;
mod lab;
mod office;
mod terrain;

/// The office's layout constants.
pub(crate) mod office_consts {
    pub use super::office::{DEPTH, DOOR_HEIGHT, GOALS, HEIGHT, START, THICKNESS, WIDTH};
}
/// The terrain scenes' layout constants.
pub(crate) mod terrain_consts {
    pub use super::terrain::{
        HALF_WIDTH, MAX_PASSABLE_SLOPE, MAX_PASSABLE_STEP, PLATFORM_LENGTH, RAMP_LENGTH,
        RAMP_WIDTH, X_BACK, X_FAR,
    };
}
/// The lab's layout constants.
pub(crate) mod lab_consts {
    pub use super::lab::ROOM;
}

pub use lab::lab;
pub use office::{office, office_floorplan};
pub use terrain::{HoughClass, TerrainClass, TerrainSpec, TerrainTruth, terrain};

use crate::{Scene, SceneError};

const NAMES: &[&str] = &[
    "office",
    "office-empty",
    "lab",
    "terrain-floor",
    "terrain-ramp",
    "terrain-ramp-down",
    "terrain-ramp-roll",
    "terrain-step-up",
    "terrain-step-down",
    "terrain-wall",
    "terrain-obstacles",
    "terrain-rubble",
];

/// The names [`scene_by_name`] knows.
pub fn scene_names() -> &'static [&'static str] {
    NAMES
}

/// The default terrain spec behind a `terrain-*` name of [`scene_names`], if it is one.
///
/// | name | spec |
/// |---|---|
/// | `terrain-floor` | flat floor |
/// | `terrain-ramp` | ramp up, pitch 15°, roll 0°, from 2 m |
/// | `terrain-ramp-down` | ramp down, pitch −15°, roll 0°, from 2 m |
/// | `terrain-ramp-roll` | ramp up, pitch 10°, roll 10°, from 2 m |
/// | `terrain-step-up` | plateau 0.3 m high from 2 m (not passable) |
/// | `terrain-step-down` | canyon 0.3 m deep from 2 m (not passable) |
/// | `terrain-wall` | wall 2 m high at 3 m |
/// | `terrain-obstacles` | 6 boxes and cylinders from 1.5 m |
/// | `terrain-rubble` | 150 pieces up to 0.15 m from 1.5 m |
pub fn terrain_spec_by_name(name: &str) -> Option<TerrainSpec> {
    let deg = |d: f64| d.to_radians();
    Some(match name {
        "terrain-floor" => TerrainSpec::Floor,
        "terrain-ramp" => TerrainSpec::Ramp { pitch: deg(15.0), roll: 0.0, distance: 2.0 },
        "terrain-ramp-down" => TerrainSpec::Ramp { pitch: deg(-15.0), roll: 0.0, distance: 2.0 },
        "terrain-ramp-roll" => {
            TerrainSpec::Ramp { pitch: deg(10.0), roll: deg(10.0), distance: 2.0 }
        }
        "terrain-step-up" => TerrainSpec::Plateau { height: 0.3, distance: 2.0 },
        "terrain-step-down" => TerrainSpec::Canyon { depth: 0.3, distance: 2.0 },
        "terrain-wall" => TerrainSpec::Wall { distance: 3.0, height: 2.0 },
        "terrain-obstacles" => TerrainSpec::Obstacles { count: 6, distance: 1.5 },
        "terrain-rubble" => TerrainSpec::Rubble { count: 150, max_size: 0.15, distance: 1.5 },
        _ => return None,
    })
}

/// The scene called `name` (one of [`scene_names`]) made with `seed`.
pub fn scene_by_name(name: &str, seed: u64) -> Result<Scene, SceneError> {
    match name {
        "office" => office(seed),
        "office-empty" => office_floorplan(),
        "lab" => lab(seed),
        _ => match terrain_spec_by_name(name) {
            Some(spec) => terrain(&spec, seed),
            None => {
                Err(SceneError::UnknownScene { name: name.to_owned(), known: NAMES.join(", ") })
            }
        },
    }
}
