//! Surface identities and materials.
//!
//! Reflectivities follow Table 2.3 of the thesis (near-infrared reflectivity at 900 nm,
//! reproduced there from Lange 2000). The `textured` flag stands in for what a stereo camera
//! needs to match: plain painted walls and ceilings have no texture, wood, concrete and printed
//! cardboard do.

use crate::SceneError;
use serde::{Deserialize, Serialize};

/// Identifies one smooth surface of a scene: a polygon, one face of a box, a sphere, or the
/// side or one cap of a cylinder. Numbered densely from 0 in the order the surfaces were added;
/// [`crate::Scene::surface`] tells what it is.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct SurfaceId(pub u32);

/// What a surface is made of, as far as the simulated sensors care.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Material {
    /// Near-infrared (≈ 900 nm) diffuse reflectivity in `[0, 1]`.
    pub reflectivity: f32,
    /// Whether the surface has visual texture a stereo matcher can lock onto.
    pub textured: bool,
}

impl Material {
    /// White paper (Table 2.3: up to 100 %), textured (print).
    pub const WHITE_PAPER: Material = Material { reflectivity: 1.0, textured: true };
    /// White masonry (85 %), as plain painted walls and ceilings: no texture.
    pub const WHITE_MASONRY: Material = Material { reflectivity: 0.85, textured: false };
    /// Limestone or clay (75 %), textured.
    pub const LIMESTONE: Material = Material { reflectivity: 0.75, textured: true };
    /// Newspaper (69 %), textured; stands in for printed cardboard.
    pub const NEWSPAPER: Material = Material { reflectivity: 0.69, textured: true };
    /// Dry carbonate sand (57 %), textured.
    pub const DRY_SAND: Material = Material { reflectivity: 0.57, textured: true };
    /// Rough clean wood pallet (25 %), textured; used for shelves, tables and desks.
    pub const WOOD: Material = Material { reflectivity: 0.25, textured: true };
    /// Smooth concrete (24 %), textured; used for floors.
    pub const CONCRETE: Material = Material { reflectivity: 0.24, textured: true };
    /// Dry asphalt with pebbles (17 %), textured.
    pub const ASPHALT: Material = Material { reflectivity: 0.17, textured: true };
    /// Black rubber tyre (2 %), untextured: too dark for most range sensors.
    pub const BLACK_RUBBER: Material = Material { reflectivity: 0.02, textured: false };

    /// A material with a checked reflectivity.
    pub fn new(reflectivity: f32, textured: bool) -> Result<Material, SceneError> {
        let m = Material { reflectivity, textured };
        m.validate()?;
        Ok(m)
    }

    /// Checks that the reflectivity lies in `[0, 1]`.
    pub fn validate(&self) -> Result<(), SceneError> {
        if (0.0..=1.0).contains(&self.reflectivity) {
            Ok(())
        } else {
            Err(SceneError::BadReflectivity { value: self.reflectivity })
        }
    }
}
