//! What `patchnav demo` and `patchnav run` measured: the data their pipeline produces and the
//! report ([`crate::report`]) draws. Written to `results.json` beside `report.html`, so the
//! report can be regenerated and its numbers read by other tools.
//!
//! Geometry is in world coordinates (metres, z up). Lists meant for pictures (points, triangles,
//! roadmap edges) are decimated by the pipeline to a few tens of thousands of items, so the
//! report stays small; the 3D files carry the full data.

use serde::{Deserialize, Serialize};

/// A point, metres.
pub type P3 = [f64; 3];

/// How much work the demo does.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Scale {
    /// A few seconds: 2 scans, short runs (tests and CI).
    Quick,
    /// About a minute on 2 cores (the default).
    Default,
    /// Several minutes: more scans, seeds and iterations.
    Full,
}

/// Everything the demo measured.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct DemoResults {
    /// The command that produced it (`demo` or `run`), for the report's title.
    #[serde(default)]
    pub command: String,
    /// The scale it ran at.
    pub scale: Option<Scale>,
    /// The seed of everything random.
    pub seed: u64,
    /// Wall time of each stage, in order.
    pub stages: Vec<StageTime>,
    /// The simulated scene.
    pub scene: SceneInfo,
    /// The time-of-flight part (thesis §2.5).
    pub tof: Option<TofSection>,
    /// The terrain part (thesis Ch. 4).
    pub terrain: Option<TerrainSection>,
    /// One row per map built (Table 6.1).
    pub maps: Vec<MapRow>,
    /// Geometry of each map type for the pictures.
    pub drawings: Vec<MapDrawing>,
    /// One row per planning run.
    pub plans: Vec<PlanRun>,
    /// Time against iterations per map type (Fig 6.4).
    pub timing: Vec<TimingCurve>,
    /// Explored volume (Table 6.2, Fig 6.1), if computed.
    pub volume: Option<VolumeSection>,
    /// Each map checked against the scene's exact surfaces, if computed.
    #[serde(default)]
    pub safety: Option<SafetySection>,
    /// Files written, relative to the output folder.
    pub files: Vec<FileEntry>,
}

/// One stage's wall time.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StageTime {
    /// What ran.
    pub stage: String,
    /// Seconds.
    pub seconds: f64,
}

/// The scene scanned.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct SceneInfo {
    /// Scene name (`lab`).
    pub name: String,
    /// Box of the scene.
    pub min: P3,
    /// Box of the scene.
    pub max: P3,
    /// Scan poses (sensor positions).
    pub scan_positions: Vec<P3>,
    /// Points scanned in total.
    pub points: usize,
}

/// The ToF frame, filtered.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TofSection {
    /// The Table 2.4 scene simulated.
    pub scene: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Per pixel (row-major): 0 kept, 1 unwrapped, 2 dropped, 3 no measurement.
    pub outcomes: Vec<u8>,
    /// Per pixel the output radial range (metres, 0 if none), for shading.
    pub radial: Vec<f32>,
    /// Method name (e.g. `AAT+unwrap`).
    pub method: String,
    /// % discarded (the thesis's metric).
    pub discarded_percent: f64,
    /// % of pixels whose surface was beyond the non-ambiguity range.
    pub wrapped_percent: f64,
    /// % of wrapped pixels put back within 5 cm.
    pub unwrapped_correct_percent: f64,
    /// % of output pixels that are wrong.
    pub wrong_percent: f64,
    /// Correct output pixels, % of the measured pixels (the yield; NaN without a truth).
    #[serde(default = "nan")]
    pub yield_percent: f64,
    /// Filter time, milliseconds.
    pub millis: f64,
}

/// The terrain snapshot, classified.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TerrainSection {
    /// The terrain scene (e.g. `terrain-ramp`).
    pub scene: String,
    /// The true class.
    pub truth: String,
    /// The class found.
    pub class: String,
    /// Drivable?
    pub drivable: bool,
    /// Winning plane: ρx, ρy (degrees), d (m).
    pub plane: [f64; 3],
    /// Angular resolution, degrees.
    pub resolution_deg: f64,
    /// Classification time, milliseconds.
    pub millis: f64,
    /// Points classified.
    pub points: usize,
    /// The Hough space as a PNG (Fig 4.3 layout).
    pub hough_png: Vec<u8>,
    /// Per sector (left, centre, right): class and drivable.
    pub sectors: Vec<(String, bool)>,
    /// Per-point ground of the snapshot (not in the thesis; absent from older results).
    #[serde(default)]
    pub ground: Option<GroundScore>,
}

/// The snapshot's per-point ground labels against the scene's drivable surfaces.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct GroundScore {
    /// Share of the points labelled ground.
    pub share: f64,
    /// Of the points labelled ground, the share on a drivable surface.
    pub precision: f64,
    /// Of the points on a drivable surface, the share labelled ground.
    pub recall: f64,
    /// Harmonic mean of precision and recall.
    pub f1: f64,
    /// Labelling time, milliseconds.
    pub millis: f64,
}

/// One map (Table 6.1).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MapRow {
    /// `planes`, `hybrid`, `trimesh` or `pc`.
    pub kind: String,
    /// Backend holding it.
    pub backend: String,
    /// Planar patches.
    pub planar_patches: usize,
    /// Trimesh patches.
    pub trimesh_patches: usize,
    /// Triangles in trimesh patches.
    pub triangles: usize,
    /// Points (pc map).
    pub points: usize,
    /// Memory of the map, bytes.
    pub memory_bytes: usize,
    /// Map file size, bytes (0 if not written).
    pub file_bytes: u64,
    /// Build time, seconds.
    pub build_seconds: f64,
}

/// Decimated geometry of one map type, for the top and perspective views.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct MapDrawing {
    /// Map type.
    pub kind: String,
    /// Planar patch outlines (outer rings, world frame).
    pub polygons: Vec<Vec<P3>>,
    /// Triangles (world frame).
    pub triangles: Vec<[P3; 3]>,
    /// Points (world frame).
    pub points: Vec<P3>,
}

/// Is the map safe? Each map compared with the scene's exact surfaces over random capsule
/// steps ([`patch_map::compare`]).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct SafetySection {
    /// Random steps per map.
    pub samples: u64,
    /// Robot radius, metres.
    pub radius: f64,
    /// Longest step, metres.
    pub max_length: f64,
    /// The exact scene's planar outlines, for the picture.
    pub truth: MapDrawing,
    /// One row per map type.
    pub rows: Vec<MapSafety>,
}

/// One map type against the truth.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct MapSafety {
    /// Map type.
    pub map: String,
    /// Colliding steps the map calls free, % of truly colliding steps, with the 95 % interval.
    pub unsafe_pct: [f64; 3],
    /// Free steps the map calls colliding, % of truly free steps, with the 95 % interval.
    pub overcautious_pct: [f64; 3],
    /// Unsafe steps and truly colliding steps.
    pub unsafe_steps: [u64; 2],
    /// Where unsafe steps first touch the truth (decimated).
    pub unsafe_hits: Vec<P3>,
}

/// One planning run.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PlanRun {
    /// Map type.
    pub map: String,
    /// Backend.
    pub backend: String,
    /// Planner (`rrt`, `prm`, ...).
    pub planner: String,
    /// Seed.
    pub seed: u64,
    /// Reached every goal?
    pub solved: bool,
    /// Wall time, seconds.
    pub seconds: f64,
    /// Iterations (samples).
    pub iterations: u64,
    /// Roadmap vertices.
    pub vertices: usize,
    /// Collision checks.
    pub collision_checks: u64,
    /// Summed path length to the goals, metres.
    pub path_length: f64,
    /// Turns on the paths.
    pub turns: usize,
    /// Turns > 90°.
    pub steep_turns: usize,
    /// Upper quartile of the turn angles, degrees.
    pub curviness_deg: f64,
    /// Start.
    pub start: P3,
    /// Goals.
    pub goals: Vec<P3>,
    /// The paths (one polyline per goal reached).
    pub paths: Vec<Vec<P3>>,
    /// Roadmap edges (decimated).
    pub edges: Vec<[P3; 2]>,
}

/// Time against iterations of one map type (Fig 6.4): per checkpoint the median and quartiles
/// over runs.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TimingCurve {
    /// Map type.
    pub map: String,
    /// Checkpoints (iterations).
    pub iterations: Vec<u64>,
    /// Median time at each, milliseconds.
    pub median_ms: Vec<f64>,
    /// Lower quartile, milliseconds.
    pub q1_ms: Vec<f64>,
    /// Upper quartile, milliseconds.
    pub q3_ms: Vec<f64>,
}

/// Explored volume.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct VolumeSection {
    /// The planner whose roadmaps were rasterised (`rrt`: Table 6.2, `prm`: Table 6.4; empty
    /// in results written before it was recorded).
    #[serde(default)]
    pub planner: String,
    /// Runs per map (starts × seeds).
    #[serde(default)]
    pub runs: usize,
    /// Iterations of every run (K).
    #[serde(default)]
    pub iterations: u64,
    /// Cell edge, metres.
    pub cell: f64,
    /// Map types, in table order.
    pub maps: Vec<String>,
    /// Explored volume per map type, m³ (Table 6.2's first column).
    #[serde(default)]
    pub volumes_m3: Vec<f64>,
    /// `table[i][j]`: % of map i's explored volume that map j's does not cover (Table 6.2
    /// layout; `None` on the diagonal).
    pub table: Vec<Vec<Option<f64>>>,
    /// A horizontal slice for the picture (Fig 6.1): height, grid origin and size.
    pub slice_z: f64,
    /// Slice origin (x, y), metres.
    pub slice_origin: [f64; 2],
    /// Slice size in cells (columns, rows).
    pub slice_size: [u32; 2],
    /// Per cell of the slice (row-major, row 0 at the smallest y) a bit per map type (bit i =
    /// map i explored it).
    pub slice_bits: Vec<u8>,
}

impl VolumeSection {
    /// The largest finite percentage of the table with its row and column map: (% of the
    /// row map's explored volume, row map, column map).
    pub fn largest_difference(&self) -> Option<(f64, &str, &str)> {
        let mut largest: Option<(f64, &str, &str)> = None;
        for (i, row) in self.table.iter().enumerate() {
            for (j, cell) in row.iter().enumerate() {
                if let (Some(x), Some(a), Some(b)) = (cell, self.maps.get(i), self.maps.get(j))
                    && x.is_finite()
                    && largest.is_none_or(|l| *x > l.0)
                {
                    largest = Some((*x, a, b));
                }
            }
        }
        largest
    }
}

/// A file the demo wrote.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FileEntry {
    /// What it is.
    pub label: String,
    /// Path relative to the output folder.
    pub path: String,
    /// Size, bytes.
    pub bytes: u64,
}

/// NaN: the serde default of a figure an older `results.json` lacks.
fn nan() -> f64 {
    f64::NAN
}
