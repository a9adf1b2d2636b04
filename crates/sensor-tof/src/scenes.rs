//! The six test scenes of Table 2.4 (thesis §2.5.6, Figs 2.16–2.19), rebuilt as analytic
//! scenes for the [`crate::sim`] simulator, each with the SR-3100 the experiments used (L2462)
//! and the thesis's "% discarded pixels" beside it.
//!
//! The thesis shows the scenes only as webcam photographs and range images and gives no sizes:
//! distances and materials below are read off the captions and the text, with reflectivities
//! from Table 2.3 where it lists the material. World frame: x east, y north, z up, metres; the
//! camera stands 0.7 m above the floor (our choice; the thesis does not say).
//!
//! | scene | what the thesis shows | how it is built here |
//! |---|---|---|
//! | rack-and-door | "wrap-around in the corner and behind the door" (Fig 2.17a) | a lab, a rack on the left at 3 m, an open door at 6 m to a crossing corridor (far wall 7.9 m), an alcove whose far corner is at ≈ 10 m |
//! | corner-window | "wrap-around in the corner, noise on the window" (Fig 2.17b) | a 6.8 m square room seen diagonally (far corner ≈ 8.2 m), a window with sunlit trees at ≈ 19 m behind it |
//! | gates | "mostly wrapped around, noise on windows" (Fig 2.17c) | open gates at 2 m into a 24 × 23 m hall, 9 m high, a window band with daylight in the far wall |
//! | close-boxes | light scattering (Fig 2.19a, g, j) | white boxes at 0.7–1.2 m before dark crates, a cabinet and a concrete wall at 3.2–4 m, scattering on |
//! | dark-material | "dark and too close trouser material" (Fig 2.19b) | dark trousers (4 %) at 2.5 m and black rubber tyres (2 %) at 3 m in a white room |
//! | sun | "sun causes random noise" (Fig 2.19c) | sunlight through a window on the floor and on a locker at ≈ 3 m |
//!
//! `cargo test -p sensor-tof --test it scenes:: -- --nocapture` prints the % discarded pixels of
//! the AAT, AT 160 and AT 240 on each scene beside Table 2.4, with what the truth says about
//! them (wrapped pixels kept, correct pixels dropped).
//!
//! Every scene has the camera's light scattering ([`Scattering::sr3000`]), the low-amplitude
//! bias of the preset, rough surfaces ([`ROUGHNESS`]) and 50 % floors; the sunlit ones have
//! [`SunRegion`]s of irradiance [`SUN_IRRADIANCE`].

use crate::TofError;
use crate::sim::{Scattering, SimConfig, SunRegion};
use pointcloud::{Point3, Real, SensorPose};
use scene_sim::{Cuboid, Cylinder, Material, Scene, SceneBuilder, camera_pose_looking};

/// The names of the six scenes, in Table 2.4's order.
pub const SCENE_NAMES: [&str; 6] =
    ["rack-and-door", "corner-window", "gates", "close-boxes", "dark-material", "sun"];

/// The intensity a white surface in direct sunlight adds to a pixel, in the camera's amplitude
/// units (where a white wall at 1 m gives 12,000). The thesis gives only the camera's limit of
/// 400 W/m²/µm (L2013), half of full sunlight; the value is ours. With the default full well
/// of 65,535 it saturates sunlit surfaces brighter than 26 %: a sunlit floor (50 %) or locker
/// returns random ranges of tiny amplitude, noise at AT 0 that a plain AT removes (Fig 2.8:
/// clean at AT 300); darker sunlit surfaces keep their signal under strong shot noise.
pub const SUN_IRRADIANCE: Real = 2.5e5;

/// The Oren–Nayar roughness of every surface, radians (see [`SimConfig::roughness`]). Under
/// Lambert's law a floor seen at grazing incidence has an apparent reflectivity `ρ cos θ` far
/// below the AAT's 0.2 beyond 2 m even when white, so the AAT would drop every floor, which the
/// thesis's results (16.7 % discarded in a lab scene with floor) contradict; rough surfaces
/// send light back towards the source, and σ = 0.5 keeps a 50 % floor above 0.2 to 7 m. The
/// table test prints the AAT's result with Lambertian surfaces beside.
pub const ROUGHNESS: Real = 0.5;

/// The floors: light grey PVC or coated concrete, 50 %, our choice (Table 2.3 has no floor
/// covering). With bare concrete (24 %) the AAT drops floors seen at grazing incidence: the
/// `gates` hall then loses 91 % of its pixels to the AAT instead of 64 %.
const LAB_FLOOR: Material = Material { reflectivity: 0.5, textured: true };

/// Painted metal (a locker, steel gates), 50 %: not in Table 2.3, our choice.
const PAINTED_METAL: Material = Material { reflectivity: 0.5, textured: false };
/// Dark trouser cloth: the 2–5 % range of the darkest materials (Table 2.3 lists rubber at 2 %).
const DARK_CLOTH: Material = Material { reflectivity: 0.04, textured: true };

/// The thesis's result for one scene (Table 2.4): % of discarded pixels.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ThesisRow {
    /// The adaptive amplitude threshold (Eq 2.4, Â = 12,000, AAT = 0.2).
    pub aat: f64,
    /// The plain amplitude threshold 160.
    pub at160: f64,
    /// The plain amplitude threshold 240 (not given for close boxes).
    pub at240: Option<f64>,
}

/// One test scene: the geometry, the camera pose, the simulator configuration and what the
/// thesis reports for it.
#[derive(Clone, Debug)]
pub struct TofScene {
    /// One of [`SCENE_NAMES`].
    pub name: &'static str,
    /// What the scene shows and why (the thesis's caption, and how it is modelled).
    pub description: &'static str,
    /// The geometry.
    pub scene: Scene,
    /// The camera's pose (optical frame: x right, y down, z forward).
    pub pose: SensorPose,
    /// The simulator configuration (SR-3100, scattering, sunlight).
    pub sim: SimConfig,
    /// Table 2.4's row.
    pub thesis: ThesisRow,
}

/// The scene called `name` (one of [`SCENE_NAMES`]).
pub fn tof_scene(name: &str) -> Result<TofScene, TofError> {
    match name {
        "rack-and-door" => rack_and_door(),
        "corner-window" => corner_window(),
        "gates" => gates(),
        "close-boxes" => close_boxes(),
        "dark-material" => dark_material(),
        "sun" => sun(),
        "white-wall" => white_wall(1.0),
        _ => Err(TofError::BadParameter {
            what: "scene name",
            why: format!("{name:?} (known: {}, white-wall)", SCENE_NAMES.join(", ")),
        }),
    }
}

/// The calibration scene of L2338–2340: a plain white wall (ρ = 1) perpendicular to the optical
/// axis at `distance` metres, filling the view, no scattering, no sun (`tof_scene("white-wall")`
/// is the thesis's 1 m). Fails for a distance outside (0.3, 10] m.
pub fn white_wall(distance: Real) -> Result<TofScene, TofError> {
    if !(distance > 0.3 && distance <= 10.0) {
        return Err(TofError::BadParameter {
            what: "white-wall distance",
            why: format!("{distance} m (want (0.3, 10] m)"),
        });
    }
    let mut b = SceneBuilder::new("white-wall");
    let white = Material::new(1.0, false)?;
    slab(&mut b, "wall", [-20.0, distance, -20.0], [20.0, distance + 0.1, 20.0], white)?;
    Ok(TofScene {
        name: "white-wall",
        description: "A white wall perpendicular to the optical axis, filling the view: the \
                      frame the illumination model is calibrated on (Eq 2.5, L2338–2340).",
        scene: b.build()?,
        pose: camera(0.0, 0.0, 90.0, 0.0),
        sim: SimConfig { roughness: 0.0, ..SimConfig::sr3100() },
        thesis: ThesisRow { aat: Real::NAN, at160: Real::NAN, at240: None },
    })
}

/// All six scenes in Table 2.4's order.
pub fn all_scenes() -> Result<Vec<TofScene>, TofError> {
    SCENE_NAMES.iter().map(|n| tof_scene(n)).collect()
}

/// Adds the axis-aligned box `[lo, hi]`.
fn slab(
    b: &mut SceneBuilder,
    name: &str,
    lo: [Real; 3],
    hi: [Real; 3],
    m: Material,
) -> Result<(), TofError> {
    b.add(name, Cuboid::axis_aligned(Point3::from(lo), Point3::from(hi))?, m)?;
    Ok(())
}

/// A floor of `floor` and a white ceiling over `[x0, x1] × [y0, y1]`, ceiling at `height`.
fn floor_and_ceiling(
    b: &mut SceneBuilder,
    x: (Real, Real),
    y: (Real, Real),
    height: Real,
    floor: Material,
) -> Result<(), TofError> {
    slab(b, "floor", [x.0, y.0, -0.1], [x.1, y.1, 0.0], floor)?;
    slab(b, "ceiling", [x.0, y.0, height], [x.1, y.1, height + 0.1], Material::WHITE_MASONRY)
}

/// The camera at (`x`, `y`) 0.7 m above the floor, heading `yaw_deg` (counter-clockwise from
/// east), tilted up by `pitch_deg`.
fn camera(x: Real, y: Real, yaw_deg: Real, pitch_deg: Real) -> SensorPose {
    camera_pose_looking(Point3::new(x, y, 0.7), yaw_deg.to_radians(), pitch_deg.to_radians())
}

/// The SR-3100 with the camera's light scattering and the given sunlit regions.
fn config(sun: Vec<SunRegion>) -> SimConfig {
    SimConfig {
        scattering: Some(Scattering::sr3000()),
        sun,
        roughness: ROUGHNESS,
        ..SimConfig::sr3100()
    }
}

/// A sunlit box `[lo, hi]`.
fn sunlit(lo: [Real; 3], hi: [Real; 3]) -> SunRegion {
    SunRegion { min: Point3::from(lo), max: Point3::from(hi), irradiance: SUN_IRRADIANCE }
}

/// Fig 2.16a / 2.17 left column.
fn rack_and_door() -> Result<TofScene, TofError> {
    let mut b = SceneBuilder::new("rack-and-door");
    let wall = Material::WHITE_MASONRY;
    floor_and_ceiling(&mut b, (-1.5, 5.5), (-0.5, 9.8), 3.0, LAB_FLOOR)?;
    slab(&mut b, "wall-west", [-1.6, -0.5, 0.0], [-1.5, 9.8, 3.0], wall)?;
    slab(&mut b, "wall-east", [5.5, -0.5, 0.0], [5.6, 9.8, 3.0], wall)?;
    slab(&mut b, "wall-south", [-1.5, -0.6, 0.0], [5.5, -0.5, 3.0], wall)?;
    // The front wall at y = 6 with the open door (x ∈ [1.6, 2.6], 2.1 m high).
    slab(&mut b, "wall-front-left", [-1.5, 6.0, 0.0], [1.6, 6.1, 3.0], wall)?;
    slab(&mut b, "wall-front-right", [2.6, 6.0, 0.0], [3.5, 6.1, 3.0], wall)?;
    slab(&mut b, "wall-front-lintel", [1.6, 6.0, 2.1], [2.6, 6.1, 3.0], wall)?;
    // The alcove on the right: x ∈ [3.5, 5.5] reaches back to y = 9.8.
    slab(&mut b, "alcove-west", [3.5, 8.0, 0.0], [3.6, 9.8, 3.0], wall)?;
    slab(&mut b, "alcove-north", [3.5, 9.8, 0.0], [5.6, 9.9, 3.0], wall)?;
    // The corridor behind the door runs east–west, 1.8 m wide; its far wall (7.9 m from the
    // camera, wrapping to 0.4 m) carries a white notice board.
    slab(&mut b, "corridor-floor", [-8.0, 6.1, -0.1], [14.0, 7.9, 0.0], LAB_FLOOR)?;
    slab(&mut b, "corridor-ceiling", [-8.0, 6.1, 2.6], [14.0, 7.9, 2.7], wall)?;
    slab(&mut b, "corridor-wall", [-8.0, 7.9, 0.0], [14.0, 8.0, 2.7], wall)?;
    slab(&mut b, "notice-board", [1.4, 7.88, 0.9], [2.4, 7.9, 1.9], Material::WHITE_PAPER)?;
    // The rack on the left at 2.8–3.4 m: metal posts, wooden shelves, cardboard boxes.
    for (i, x) in [-1.0, 0.3, 1.6].into_iter().enumerate() {
        for (j, y) in [2.8, 3.35].into_iter().enumerate() {
            slab(
                &mut b,
                &format!("rack/post-{i}-{j}"),
                [x - 0.03, y, 0.0],
                [x + 0.03, y + 0.05, 2.0],
                Material::ASPHALT,
            )?;
        }
    }
    for (k, z) in [0.4, 1.0, 1.6].into_iter().enumerate() {
        slab(
            &mut b,
            &format!("rack/shelf-{k}"),
            [-1.03, 2.8, z - 0.03],
            [1.63, 3.4, z],
            Material::WOOD,
        )?;
    }
    slab(&mut b, "rack/box-0", [-0.8, 2.9, 0.4], [-0.2, 3.35, 0.8], Material::NEWSPAPER)?;
    slab(&mut b, "rack/box-1", [0.5, 2.85, 1.0], [1.2, 3.35, 1.35], Material::NEWSPAPER)?;
    slab(&mut b, "rack/box-2", [-0.4, 2.9, 1.6], [0.4, 3.35, 1.9], Material::NEWSPAPER)?;
    slab(&mut b, "box", [2.8, 2.0, 0.0], [3.3, 2.5, 0.5], Material::NEWSPAPER)?;
    Ok(TofScene {
        name: "rack-and-door",
        description: "A lab with a rack in front (2.8 m, left), an open door in the front wall at \
                      6 m to a crossing corridor whose far wall is at 7.9 m, and an alcove on the \
                      right whose far wall is at 9.8 m: wrap-around behind the door and in the \
                      far corner (Fig 2.17a).",
        scene: b.build()?,
        pose: camera(2.0, 0.0, 90.0, -3.0),
        sim: config(Vec::new()),
        thesis: ThesisRow { aat: 16.7, at160: 46.3, at240: Some(60.3) },
    })
}

/// Fig 2.16b / 2.17 middle column.
fn corner_window() -> Result<TofScene, TofError> {
    let mut b = SceneBuilder::new("corner-window");
    let wall = Material::WHITE_MASONRY;
    let s = 6.8;
    floor_and_ceiling(&mut b, (0.0, s), (0.0, s), 3.0, LAB_FLOOR)?;
    slab(&mut b, "wall-west", [-0.1, 0.0, 0.0], [0.0, s, 3.0], wall)?;
    slab(&mut b, "wall-south", [0.0, -0.1, 0.0], [s, 0.0, 3.0], wall)?;
    slab(&mut b, "wall-east", [s, 0.0, 0.0], [s + 0.1, s, 3.0], wall)?;
    // The north wall with a window x ∈ [3.4, 5.0], z ∈ [0.9, 2.2].
    let (w0, w1, z0, z1) = (3.4, 5.0, 0.9, 2.2);
    slab(&mut b, "wall-north-left", [0.0, s, 0.0], [w0, s + 0.1, 3.0], wall)?;
    slab(&mut b, "wall-north-right", [w1, s, 0.0], [s, s + 0.1, 3.0], wall)?;
    slab(&mut b, "wall-north-sill", [w0, s, 0.0], [w1, s + 0.1, z0], wall)?;
    slab(&mut b, "wall-north-lintel", [w0, s, z1], [w1, s + 0.1, 3.0], wall)?;
    // Outside: sunlit trees (Table 2.3: deciduous, typ. 60 %) 19 m from the camera.
    let trees = Material { reflectivity: 0.6, textured: true };
    slab(&mut b, "outside/trees", [-10.0, 19.0, 0.0], [30.0, 20.0, 15.0], trees)?;
    slab(&mut b, "outside/ground", [-10.0, s + 0.1, -0.1], [30.0, 19.0, 0.0], Material::CONCRETE)?;
    // A desk by the east wall and a cabinet by the west wall.
    slab(&mut b, "desk", [5.2, 2.0, 0.72], [s, 3.6, 0.75], Material::WOOD)?;
    slab(&mut b, "cabinet", [0.0, 3.5, 0.0], [0.5, 4.5, 1.2], Material::WOOD)?;
    let sun = vec![sunlit([-10.0, s + 0.1, -1.0], [30.0, 25.0, 20.0])];
    Ok(TofScene {
        name: "corner-window",
        description: "A 6.8 m square room seen diagonally from one corner: the far corner (8.2 m) \
                      wraps around; through a window in the left wall sunlit trees at 19 m wrap \
                      twice and are noisy (Fig 2.17b).",
        scene: b.build()?,
        pose: camera(1.0, 1.0, 45.0, 0.0),
        sim: config(sun),
        thesis: ThesisRow { aat: 21.7, at160: 43.3, at240: Some(54.7) },
    })
}

/// Fig 2.16c / 2.17 right column.
fn gates() -> Result<TofScene, TofError> {
    let mut b = SceneBuilder::new("gates");
    let wall = Material::CONCRETE;
    // The gate wall at y = 2 with an opening x ∈ [-1.5, 1.5], 3 m high, steel gate leaves
    // swung open into the hall (the open gates fill the view; their frame lies just outside).
    slab(&mut b, "gate-wall-left", [-12.0, 2.0, 0.0], [-1.5, 2.2, 9.0], wall)?;
    slab(&mut b, "gate-wall-right", [1.5, 2.0, 0.0], [12.0, 2.2, 9.0], wall)?;
    slab(&mut b, "gate-lintel", [-1.5, 2.0, 3.0], [1.5, 2.2, 9.0], wall)?;
    slab(&mut b, "gate-leaf-left", [-1.5, 2.2, 0.0], [-1.45, 3.7, 2.9], PAINTED_METAL)?;
    slab(&mut b, "gate-leaf-right", [1.45, 2.2, 0.0], [1.5, 3.7, 2.9], PAINTED_METAL)?;
    slab(&mut b, "floor-outside", [-3.0, -1.0, -0.1], [3.0, 2.0, 0.0], LAB_FLOOR)?;
    // The hall: x ∈ [-12, 12], y ∈ [2.2, 25], 9 m high.
    floor_and_ceiling(&mut b, (-12.0, 12.0), (2.2, 25.0), 9.0, LAB_FLOOR)?;
    slab(&mut b, "hall-west", [-12.1, 2.2, 0.0], [-12.0, 25.0, 9.0], wall)?;
    slab(&mut b, "hall-east", [12.0, 2.2, 0.0], [12.1, 25.0, 9.0], wall)?;
    // The far wall with a window band z ∈ [3, 6] (frosted glass bricks in daylight).
    slab(&mut b, "hall-north-low", [-12.0, 25.0, 0.0], [12.0, 25.1, 3.0], wall)?;
    slab(&mut b, "hall-north-high", [-12.0, 25.0, 6.0], [12.0, 25.1, 9.0], wall)?;
    let glass = Material { reflectivity: 0.3, textured: false };
    slab(&mut b, "hall-north-windows", [-12.0, 25.05, 3.0], [12.0, 25.1, 6.0], glass)?;
    // Crates and a container in the hall.
    slab(&mut b, "crate-0", [-4.0, 10.0, 0.0], [-2.5, 11.5, 1.2], Material::WOOD)?;
    slab(&mut b, "crate-1", [2.0, 14.0, 0.0], [3.5, 15.0, 1.0], Material::WOOD)?;
    slab(&mut b, "container", [-1.0, 18.0, 0.0], [3.0, 20.5, 2.6], PAINTED_METAL)?;
    let sun = vec![sunlit([-12.0, 24.9, 3.0], [12.0, 25.2, 6.0])];
    Ok(TofScene {
        name: "gates",
        description: "Open gates at 2 m into a large hall (24 × 23 m, 9 m high): most of the \
                      image is beyond 7.5 m and wraps; the window band in the far wall is noisy \
                      in daylight (Fig 2.17c).",
        scene: b.build()?,
        pose: camera(0.0, 0.0, 90.0, 3.0),
        sim: config(sun),
        thesis: ThesisRow { aat: 56.3, at160: 92.8, at240: Some(100.0) },
    })
}

/// Fig 2.18a / 2.19 left column.
fn close_boxes() -> Result<TofScene, TofError> {
    let mut b = SceneBuilder::new("close-boxes");
    floor_and_ceiling(&mut b, (-3.0, 3.0), (-0.5, 4.0), 2.8, LAB_FLOOR)?;
    slab(&mut b, "wall-back", [-3.0, 4.0, 0.0], [3.0, 4.1, 2.8], Material::CONCRETE)?;
    slab(&mut b, "wall-west", [-3.1, -0.5, 0.0], [-3.0, 4.0, 2.8], Material::CONCRETE)?;
    slab(&mut b, "wall-east", [3.0, -0.5, 0.0], [3.1, 4.0, 2.8], Material::CONCRETE)?;
    // Darker things before the wall: a wooden cabinet, dark crates (asphalt-like, 17 %).
    slab(&mut b, "cabinet", [0.6, 3.4, 0.0], [1.6, 4.0, 1.4], Material::WOOD)?;
    slab(&mut b, "crate-0", [-1.4, 3.2, 0.0], [-0.6, 3.8, 0.7], Material::ASPHALT)?;
    slab(&mut b, "crate-1", [-0.3, 3.3, 0.0], [0.3, 3.8, 1.1], Material::ASPHALT)?;
    // White boxes close to the camera: the left quarter of the image and lower right.
    slab(&mut b, "box-left", [-0.55, 0.72, 0.0], [-0.12, 1.1, 0.95], Material::WHITE_PAPER)?;
    slab(&mut b, "box-right", [0.15, 1.0, 0.0], [0.5, 1.25, 0.45], Material::NEWSPAPER)?;
    Ok(TofScene {
        name: "close-boxes",
        description: "White boxes at 0.7–1.2 m before a background at 3.2–4 m of dark crates (17 \
                      %), a wooden cabinet (25 %) and a concrete wall (24 %); the light the boxes \
                      scatter inside the camera pulls the background, the dark parts most, closer \
                      (Fig 2.19a).",
        scene: b.build()?,
        pose: camera(0.0, 0.0, 90.0, -5.0),
        sim: config(Vec::new()),
        thesis: ThesisRow { aat: 38.1, at160: 35.0, at240: None },
    })
}

/// Fig 2.18b / 2.19 middle column.
fn dark_material() -> Result<TofScene, TofError> {
    let mut b = SceneBuilder::new("dark-material");
    let wall = Material::WHITE_MASONRY;
    floor_and_ceiling(&mut b, (-2.2, 2.2), (-0.5, 4.8), 2.8, LAB_FLOOR)?;
    slab(&mut b, "wall-back", [-2.2, 4.8, 0.0], [2.2, 4.9, 2.8], wall)?;
    slab(&mut b, "wall-west", [-2.3, -0.5, 0.0], [-2.2, 4.8, 2.8], wall)?;
    slab(&mut b, "wall-east", [2.2, -0.5, 0.0], [2.3, 4.8, 2.8], wall)?;
    // Dark trousers hanging from a stand at 2.5 m, left of centre.
    slab(&mut b, "trousers", [-0.85, 2.5, 0.15], [-0.4, 2.6, 1.15], DARK_CLOTH)?;
    slab(&mut b, "stand", [-0.9, 2.6, 1.15], [-0.35, 2.65, 1.2], PAINTED_METAL)?;
    // Black rubber: two stacked tyres at 3 m on the right.
    for (k, z) in [0.0, 0.25].into_iter().enumerate() {
        let tyre = Cylinder::upright(Point3::new(0.7, 3.0, z), 0.33, 0.24)?;
        b.add(format!("tyre-{k}"), tyre, Material::BLACK_RUBBER)?;
    }
    slab(&mut b, "table", [-1.9, 1.8, 0.72], [-1.0, 3.0, 0.75], Material::WOOD)?;
    slab(&mut b, "box", [1.3, 3.8, 0.0], [1.9, 4.4, 0.6], Material::NEWSPAPER)?;
    Ok(TofScene {
        name: "dark-material",
        description: "An ordinary white room (back wall at 4.8 m) with dark trousers (4 %) at 2.5 \
                      m and black rubber tyres (2 %, Table 2.3) at 3 m: too dark, noisy and read \
                      too close (the amplitude-related range error, L2141–2149; Fig 2.19b).",
        scene: b.build()?,
        pose: camera(0.0, 0.0, 90.0, -5.0),
        sim: config(Vec::new()),
        thesis: ThesisRow { aat: 13.1, at160: 28.0, at240: Some(43.1) },
    })
}

/// Fig 2.18c / 2.19 right column.
fn sun() -> Result<TofScene, TofError> {
    let mut b = SceneBuilder::new("sun");
    let wall = Material::WHITE_MASONRY;
    floor_and_ceiling(&mut b, (-2.5, 2.5), (-0.5, 5.0), 2.8, LAB_FLOOR)?;
    slab(&mut b, "wall-back", [-2.5, 5.0, 0.0], [2.5, 5.1, 2.8], wall)?;
    slab(&mut b, "wall-east", [2.5, -0.5, 0.0], [2.6, 5.0, 2.8], wall)?;
    // The west wall with a large window (y ∈ [1, 4.5], z ∈ [0.5, 2.5]) the sun shines through.
    slab(&mut b, "wall-west-south", [-2.6, -0.5, 0.0], [-2.5, 1.0, 2.8], wall)?;
    slab(&mut b, "wall-west-north", [-2.6, 4.5, 0.0], [-2.5, 5.0, 2.8], wall)?;
    slab(&mut b, "wall-west-sill", [-2.6, 1.0, 0.0], [-2.5, 4.5, 0.5], wall)?;
    slab(&mut b, "wall-west-lintel", [-2.6, 1.0, 2.5], [-2.5, 4.5, 2.8], wall)?;
    slab(
        &mut b,
        "outside",
        [-30.0, -10.0, 0.0],
        [-29.0, 20.0, 10.0],
        Material { reflectivity: 0.6, textured: true },
    )?;
    // The locker on the right at ≈ 3 m.
    slab(&mut b, "locker", [0.4, 2.9, 0.0], [1.4, 3.4, 1.9], PAINTED_METAL)?;
    slab(&mut b, "chair-seat", [-1.2, 3.6, 0.45], [-0.7, 4.1, 0.5], Material::WOOD)?;
    // The sunlit patch on the floor and on the locker's front and left side.
    let sun = vec![
        sunlit([-2.5, 1.2, -0.05], [0.3, 4.2, 0.05]),
        sunlit([0.35, 2.85, 0.0], [0.9, 3.45, 1.3]),
    ];
    Ok(TofScene {
        name: "sun",
        description: "Sunlight through a window on the left falls on the floor (1.2–4.2 m) and on \
                      a locker at 2.9 m: shot noise swamps the modulated light there (Fig 2.19c).",
        scene: b.build()?,
        pose: camera(0.0, 0.0, 90.0, -12.0),
        sim: config(sun),
        thesis: ThesisRow { aat: 44.9, at160: 73.1, at240: Some(84.6) },
    })
}
