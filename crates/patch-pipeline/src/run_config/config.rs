//! The configuration file of `patchnav run`: parsed with `deny_unknown_fields`, every value
//! checked, paths resolved against the file's folder (the keys and their defaults are in the
//! parent module's documentation).

use crate::SensorPreset;
use crate::demo::Settings;
use crate::demo::explore::{EXPLORE_PLANNERS, MAX_VOLUME_MAPS};
use crate::names::{self, NameParser, Named};
use crate::results::Scale;
use crate::scene_map::{MapKind, Tessellation};
use crate::terrain::AxesChoice;
use anyhow::{Context, Result, bail};
use patch_core::{Point3, Real};
use patch_map::Backend;
use roadmap::PlannerKind;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// Robot radius when `plan.radius` is not given, metres (the demo's choice).
pub const DEFAULT_RADIUS: Real = 0.3;
/// Longest RRT edge when `plan.step` is not given, metres.
pub const DEFAULT_STEP: Real = 1.0;
/// Goal tolerance when `plan.goal_tolerance` is not given, metres.
pub const DEFAULT_GOAL_TOLERANCE: Real = 0.5;
/// Iteration budget of one planning run when `plan.max_iterations` is not given.
pub const DEFAULT_MAX_ITERATIONS: u64 = 10_000;
/// Largest accepted `plan.max_iterations` (a run of this many takes hours).
pub const MAX_ITERATIONS_LIMIT: u64 = 100_000_000;
/// Spacing of the points sampled on a mesh's patches for its `pc` map, metres (below half the
/// default robot radius, the point-cloud map's density assumption).
pub const DEFAULT_SPACING: Real = 0.05;
/// Output folder, relative to the configuration file's folder.
pub const DEFAULT_OUT: &str = "out/run";
/// Largest accepted `maps.max_patch_triangles`.
pub const MAX_PATCH_TRIANGLES_LIMIT: u64 = 1_000_000;
/// Largest accepted `timing.checkpoints` (as `patchnav experiment lab-timing --checkpoints`).
pub const MAX_CHECKPOINTS: u64 = 10_000;
/// Largest accepted `volume.cells` (the thesis's grid: 1024 cells of 38.684 mm, §6.1.1).
pub const MAX_CELLS: u64 = 1024;

/// The demo's default scale, whose timing and volume settings are the defaults of `[timing]`
/// and `[volume]`.
fn demo_settings() -> Settings {
    Settings::of(Scale::Default)
}

/// The file as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawConfig {
    input: RawInput,
    #[serde(default)]
    maps: RawMaps,
    plan: RawPlan,
    tof: Option<RawTof>,
    terrain: Option<RawTerrain>,
    timing: Option<RawTiming>,
    volume: Option<RawVolume>,
    #[serde(default)]
    output: RawOutput,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawInput {
    name: Option<String>,
    scans: Option<Vec<PathBuf>>,
    poses: Option<PathBuf>,
    mesh: Option<PathBuf>,
    map: Option<PathBuf>,
    cloud: Option<PathBuf>,
    skip_non_finite: Option<bool>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMaps {
    types: Option<Vec<String>>,
    backends: Option<Vec<String>>,
    sensor: Option<String>,
    spacing: Option<Real>,
    mesh_edge: Option<Real>,
    max_patch_triangles: Option<i64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPlan {
    start: [Real; 3],
    goals: Vec<[Real; 3]>,
    radius: Option<Real>,
    step: Option<Real>,
    goal_tolerance: Option<Real>,
    planners: Option<Vec<String>>,
    seeds: Option<Vec<u64>>,
    max_iterations: Option<u64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTof {
    range: PathBuf,
    amplitude: PathBuf,
    meta: PathBuf,
    confidence: Option<PathBuf>,
    method: Option<String>,
    aat: Option<Real>,
    unwrap: Option<bool>,
    low_at: Option<Real>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTerrain {
    frame: PathBuf,
    resolution: Option<f64>,
    sensor_height: Option<f64>,
    pitch: Option<f64>,
    axes: Option<String>,
    max_range: Option<f64>,
    sectors: Option<usize>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTiming {
    iterations: Option<i64>,
    checkpoints: Option<i64>,
    seeds: Option<Vec<u64>>,
    starts: Option<Vec<[Real; 3]>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawVolume {
    planner: Option<String>,
    iterations: Option<i64>,
    seeds: Option<Vec<u64>>,
    starts: Option<Vec<[Real; 3]>>,
    cells: Option<i64>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawOutput {
    dir: Option<PathBuf>,
    write_3d: Option<bool>,
}

/// What the maps are built from.
#[derive(Debug, Clone, PartialEq)]
pub enum Input {
    /// Range scans in their sensor frames, with an optional `poses.json`.
    Scans {
        /// The scan files.
        files: Vec<PathBuf>,
        /// Poses overriding the scans' own.
        poses: Option<PathBuf>,
    },
    /// A triangle mesh (OBJ): coplanar faces become planar patches.
    Mesh(PathBuf),
    /// A map file of any backend.
    Map(PathBuf),
    /// A point cloud in the world frame: the `pc` map.
    Cloud(PathBuf),
}

/// The planning problem and its planners.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanConfig {
    /// Start.
    pub start: Point3,
    /// Goals, each reached within `goal_tolerance`.
    pub goals: Vec<Point3>,
    /// Robot radius, metres.
    pub radius: Real,
    /// Longest RRT edge, metres.
    pub step: Real,
    /// How close a vertex must come to a goal, metres.
    pub goal_tolerance: Real,
    /// Planners, in order.
    pub planners: Vec<PlannerKind>,
    /// Seeds of every planner.
    pub seeds: Vec<u64>,
    /// Iteration budget of each run (it stops earlier once every goal is reached).
    pub max_iterations: u64,
}

/// The ToF frame to filter (`[tof]`).
#[derive(Debug, Clone, PartialEq)]
pub struct TofConfig {
    /// 16-bit range PNG.
    pub range: PathBuf,
    /// 16-bit amplitude PNG.
    pub amplitude: PathBuf,
    /// JSON sidecar.
    pub meta: PathBuf,
    /// Optional confidence PNG.
    pub confidence: Option<PathBuf>,
    /// The filter: region unwrapping (the default), the AAT or the plain AT.
    pub method: crate::tof::Method,
    /// AAT override.
    pub aat: Option<Real>,
    /// With the AAT: unwrap flagged pixels instead of dropping them.
    pub unwrap: bool,
    /// Drop pixels with amplitude ≤ this: before segmenting (regions), or the flagged ones
    /// instead of unwrapping them (AAT with `unwrap`).
    pub low_at: Option<Real>,
}

/// The terrain frame to classify (`[terrain]`).
#[derive(Debug, Clone, PartialEq)]
pub struct TerrainConfig {
    /// The frame.
    pub frame: PathBuf,
    /// Hough resolution, degrees.
    pub resolution: f64,
    /// Sensor height, metres (`None`: estimated from the frame).
    pub sensor_height: Option<f64>,
    /// Pitch down, degrees (`None`: estimated from the frame, or level with a given height).
    pub pitch: Option<f64>,
    /// Axes (`None`: by the frame).
    pub axes: Option<AxesChoice>,
    /// Horizontal range limit, metres.
    pub max_range: Option<f64>,
    /// Azimuth sectors.
    pub sectors: usize,
}

/// RRTs timed against iterations (`[timing]`, thesis Fig 6.4).
#[derive(Debug, Clone, PartialEq)]
pub struct TimingConfig {
    /// Iterations of every run (K).
    pub iterations: u64,
    /// Checkpoints per run (about; 100, 500 and 1000 are added below K).
    pub checkpoints: u64,
    /// Seeds, each run from every start.
    pub seeds: Vec<u64>,
    /// Starts.
    pub starts: Vec<Point3>,
}

/// Explored volume compared across the maps (`[volume]`, thesis Table 6.2 / 6.4, Fig 6.1).
#[derive(Debug, Clone, PartialEq)]
pub struct VolumeConfig {
    /// The planner grown, one of [`EXPLORE_PLANNERS`].
    pub planner: PlannerKind,
    /// Iterations of every run.
    pub iterations: u64,
    /// Seeds, each run from every start.
    pub seeds: Vec<u64>,
    /// Starts; the slice picture lies at the first one's height.
    pub starts: Vec<Point3>,
    /// Voxels per axis of the grid covering every map.
    pub cells: u32,
}

impl VolumeConfig {
    /// Whether the volume comes from the very runs `timing` makes (same planner, iterations,
    /// seeds and starts), as in the demo.
    pub fn shares_runs_with(&self, timing: &TimingConfig) -> bool {
        self.planner == PlannerKind::Rrt
            && self.iterations == timing.iterations
            && self.seeds == timing.seeds
            && self.starts == timing.starts
    }
}

/// A checked configuration, paths resolved.
#[derive(Debug, Clone, PartialEq)]
pub struct Config {
    /// Name of the data set (the report's title).
    pub name: String,
    /// The input.
    pub input: Input,
    /// Drop non-finite points of unorganised clouds.
    pub skip_non_finite: bool,
    /// Map types to build.
    pub types: Vec<MapKind>,
    /// Backends each patch map is loaded into, each a patch backend (`None`: a map file's own).
    pub backends: Option<Vec<Backend>>,
    /// Extraction preset for scans.
    pub sensor: SensorPreset,
    /// Sample spacing of a mesh's `pc` map, metres.
    pub spacing: Real,
    /// A mesh's trimesh map: longest triangle edge, metres (`None`: the surfaces' own
    /// triangles, unsplit).
    pub mesh_edge: Option<Real>,
    /// A mesh's trimesh map: most triangles per trimesh patch.
    pub max_patch_triangles: usize,
    /// Planning.
    pub plan: PlanConfig,
    /// ToF frame.
    pub tof: Option<TofConfig>,
    /// Terrain frame.
    pub terrain: Option<TerrainConfig>,
    /// RRT timing.
    pub timing: Option<TimingConfig>,
    /// Explored volume.
    pub volume: Option<VolumeConfig>,
    /// Output folder.
    pub out: PathBuf,
    /// Write the 3D files.
    pub write_3d: bool,
}

/// The map types each input allows, in build order (the default of `maps.types`).
pub fn allowed_types(input: &Input) -> &'static [MapKind] {
    match input {
        Input::Scans { .. } => &MapKind::ALL,
        Input::Mesh(_) => &MapKind::ALL,
        // A map file holds one type, known once it is read.
        Input::Map(_) => &MapKind::ALL,
        Input::Cloud(_) => &[MapKind::Pc],
    }
}

/// One of a library vocabulary's names that `parser` accepts, or an error naming `key` and the
/// choices.
fn named<T: Named>(key: &str, text: &str, parser: NameParser<T>) -> Result<T> {
    parser.parse(text).map_err(|e| anyhow::anyhow!("{key}: {e}"))
}

/// Every item of `texts` as a name `parser` accepts, no repeats, at least one.
fn named_list<T: Named>(key: &str, texts: &[String], parser: NameParser<T>) -> Result<Vec<T>> {
    list(key, texts, |k, t| named(k, t, parser))
}

/// Every item of `texts` as `one` reads it (given the item's key), no repeats, at least one.
fn list<T: PartialEq>(
    key: &str,
    texts: &[String],
    one: impl Fn(&str, &str) -> Result<T>,
) -> Result<Vec<T>> {
    if texts.is_empty() {
        bail!("{key}: give at least one value");
    }
    let mut out: Vec<T> = Vec::with_capacity(texts.len());
    for (i, t) in texts.iter().enumerate() {
        let v = one(&format!("{key}[{i}]"), t)?;
        if out.contains(&v) {
            bail!("{key}: `{t}` is listed twice");
        }
        out.push(v);
    }
    Ok(out)
}

/// The planners `[volume]` grows ([`EXPLORE_PLANNERS`]).
fn explore_planners() -> NameParser<PlannerKind> {
    names::only(|k| EXPLORE_PLANNERS.contains(&k), "the volume grows the thesis's RRT or PRM")
}

/// A positive finite number of metres, or an error naming `key`.
fn positive(key: &str, v: Real) -> Result<Real> {
    if !(v.is_finite() && v > 0.0) {
        bail!("{key} must be a positive number of metres, not {v}");
    }
    Ok(v)
}

/// An integer in `1..=max`, or an error naming `key`.
fn count(key: &str, v: i64, max: u64) -> Result<u64> {
    match u64::try_from(v) {
        Ok(n @ 1..) if n <= max => Ok(n),
        _ => bail!("{key} must be in 1..={max}, not {v}"),
    }
}

/// Seeds: at least one, none twice.
fn seed_list(key: &str, seeds: Vec<u64>) -> Result<Vec<u64>> {
    if seeds.is_empty() {
        bail!("{key}: give at least one seed");
    }
    if let Some((i, s)) = seeds.iter().enumerate().find(|(i, s)| seeds[..*i].contains(s)) {
        bail!("{key}[{i}]: seed {s} is listed twice");
    }
    Ok(seeds)
}

/// Finite points, at least one.
fn point_list(key: &str, points: &[[Real; 3]]) -> Result<Vec<Point3>> {
    if points.is_empty() {
        bail!("{key}: give at least one point [x, y, z]");
    }
    points.iter().enumerate().map(|(k, p)| point(&format!("{key}[{k}]"), *p)).collect()
}

/// The maps built for `types` in `backends` (`None`: one each): one per patch type and
/// backend, one `pc` map.
fn map_count(input: &Input, types: &[MapKind], backends: Option<&[Backend]>) -> usize {
    let per_type = backends.map_or(1, <[Backend]>::len);
    match input {
        Input::Map(_) => per_type,
        _ => types.iter().map(|&k| if k == MapKind::Pc { 1 } else { per_type }).sum(),
    }
}

/// A finite point.
fn point(key: &str, p: [Real; 3]) -> Result<Point3> {
    if !p.iter().all(|c| c.is_finite()) {
        bail!("{key} must be three finite numbers [x, y, z], not {p:?}");
    }
    Ok(Point3::new(p[0], p[1], p[2]))
}

/// `path` against `base`, checked to be a file.
fn existing(key: &str, base: &Path, path: &Path) -> Result<PathBuf> {
    let full = base.join(path);
    if !full.is_file() {
        bail!("{key}: no file {}", full.display());
    }
    Ok(full)
}

/// Reads and checks the configuration file `path`.
///
/// # Errors
/// An unreadable file, TOML syntax, an unknown or missing key, a value of the wrong type or
/// out of range, a missing input file, or keys that contradict each other (two inputs, a map
/// type the input cannot give); every message is one line naming the key.
pub fn load(path: &Path) -> Result<Config> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let raw: RawConfig = toml::from_str(&text).map_err(|e| {
        let start = e.span().map(|s| s.start.min(text.len()));
        let line = start.map(|s| text.as_bytes()[..s].iter().filter(|&&b| b == b'\n').count() + 1);
        let mut message = e.message().split_whitespace().collect::<Vec<_>>().join(" ");
        // A value of the wrong type or range: name its key, as the checks below do.
        if message.starts_with("invalid")
            && let Some(key) = start.and_then(|s| key_at(&text, s))
        {
            message = format!("{key}: {message}");
        }
        match line {
            Some(l) => anyhow::anyhow!("{} line {l}: {message}", path.display()),
            None => anyhow::anyhow!("{}: {message}", path.display()),
        }
    })?;
    let base = path.parent().map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    let base = if base.as_os_str().is_empty() { PathBuf::from(".") } else { base };
    resolve(raw, &base, path)
}

/// The `table.key` whose value holds byte `offset` of `text`, when that line reads
/// `key = value` below a `[table]` header (the layout of every key of this file).
fn key_at(text: &str, offset: usize) -> Option<String> {
    let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let line = text[line_start..].lines().next()?;
    let key = line.split_once('=')?.0.trim();
    let bare = |k: &str| {
        !k.is_empty() && k.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
    };
    if !bare(key) {
        return None;
    }
    let table = text[..line_start].lines().rev().find_map(|l| {
        let l = l.trim();
        l.strip_prefix('[').filter(|r| !r.starts_with('[')).and_then(|r| r.split_once(']'))
    });
    Some(match table {
        Some((t, _)) if bare(t.trim()) => format!("{}.{key}", t.trim()),
        _ => key.to_owned(),
    })
}

fn resolve(raw: RawConfig, base: &Path, path: &Path) -> Result<Config> {
    let i = raw.input;
    let given: Vec<&str> = [
        ("scans", i.scans.is_some()),
        ("mesh", i.mesh.is_some()),
        ("map", i.map.is_some()),
        ("cloud", i.cloud.is_some()),
    ]
    .iter()
    .filter(|(_, g)| *g)
    .map(|(k, _)| *k)
    .collect();
    if given.len() != 1 {
        bail!(
            "[input] needs exactly one of `scans`, `mesh`, `map`, `cloud`; {}",
            if given.is_empty() {
                "none is given".to_owned()
            } else {
                format!(
                    "got {}",
                    given.iter().map(|k| format!("`{k}`")).collect::<Vec<_>>().join(" and ")
                )
            }
        );
    }
    if i.poses.is_some() && i.scans.is_none() {
        bail!("input.poses applies to `scans` only");
    }
    let input = match (i.scans, i.mesh, i.map, i.cloud) {
        (Some(scans), ..) => {
            if scans.is_empty() {
                bail!("input.scans: give at least one scan");
            }
            let files = scans
                .iter()
                .enumerate()
                .map(|(k, s)| existing(&format!("input.scans[{k}]"), base, s))
                .collect::<Result<Vec<_>>>()?;
            let poses = i.poses.as_deref().map(|p| existing("input.poses", base, p)).transpose()?;
            Input::Scans { files, poses }
        }
        (_, Some(m), ..) => {
            let full = existing("input.mesh", base, &m)?;
            if !full.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj")) {
                bail!("input.mesh: {} is not an OBJ mesh (.obj)", full.display());
            }
            Input::Mesh(full)
        }
        (_, _, Some(m), _) => Input::Map(existing("input.map", base, &m)?),
        (.., Some(c)) => Input::Cloud(existing("input.cloud", base, &c)?),
        (None, None, None, None) => bail!("[input] needs one of `scans`, `mesh`, `map`, `cloud`"),
    };
    let name = match i.name {
        Some(n) if n.trim().is_empty() => bail!("input.name must not be empty"),
        Some(n) => n,
        None => {
            path.file_stem().map_or_else(|| "run".to_owned(), |s| s.to_string_lossy().into_owned())
        }
    };

    let m = raw.maps;
    let allowed = allowed_types(&input);
    let types = match &m.types {
        Some(t) => {
            let t: Vec<MapKind> = named_list("maps.types", t, names::all())?;
            if let Some(bad) = t.iter().find(|k| !allowed.contains(k)) {
                let from = match input {
                    Input::Scans { .. } => "scans",
                    Input::Mesh(_) => "a mesh",
                    Input::Map(_) => "a map file",
                    Input::Cloud(_) => "a point cloud",
                };
                let names: Vec<&str> = allowed.iter().map(|k| k.name()).collect();
                bail!(
                    "maps.types: a {bad} map cannot be built from {from} (it gives: {})",
                    names.join(", ")
                );
            }
            t
        }
        None => allowed.to_vec(),
    };
    let backends = m
        .backends
        .as_deref()
        .map(|b| named_list("maps.backends", b, names::patch_backends()))
        .transpose()?;
    let sensor = match (&m.sensor, &input) {
        (Some(s), Input::Scans { .. }) => named("maps.sensor", s, names::all())?,
        (Some(_), _) => bail!("maps.sensor applies to `scans` input only"),
        (None, _) => SensorPreset::Alrf,
    };
    let spacing = match (m.spacing, &input) {
        (Some(s), Input::Mesh(_)) => positive("maps.spacing", s)?,
        (Some(_), _) => bail!("maps.spacing applies to `mesh` input only (its pc map)"),
        (None, _) => DEFAULT_SPACING,
    };
    for (key, given) in [
        ("maps.mesh_edge", m.mesh_edge.is_some()),
        ("maps.max_patch_triangles", m.max_patch_triangles.is_some()),
    ] {
        if given && !matches!(input, Input::Mesh(_)) {
            bail!("{key} applies to `mesh` input only (its trimesh map)");
        }
        if given && !types.contains(&MapKind::Trimesh) {
            bail!("{key} applies to the trimesh map, which maps.types leaves out");
        }
    }
    let mesh_edge = m.mesh_edge.map(|e| positive("maps.mesh_edge", e)).transpose()?;
    let max_patch_triangles = match m.max_patch_triangles {
        Some(n) => count("maps.max_patch_triangles", n, MAX_PATCH_TRIANGLES_LIMIT)? as usize,
        None => Tessellation::lab().max_patch_triangles,
    };

    let p = raw.plan;
    if p.goals.is_empty() {
        bail!("plan.goals: give at least one goal [x, y, z]");
    }
    let plan = PlanConfig {
        start: point("plan.start", p.start)?,
        goals: p
            .goals
            .iter()
            .enumerate()
            .map(|(k, g)| point(&format!("plan.goals[{k}]"), *g))
            .collect::<Result<_>>()?,
        radius: positive("plan.radius", p.radius.unwrap_or(DEFAULT_RADIUS))?,
        step: positive("plan.step", p.step.unwrap_or(DEFAULT_STEP))?,
        goal_tolerance: positive(
            "plan.goal_tolerance",
            p.goal_tolerance.unwrap_or(DEFAULT_GOAL_TOLERANCE),
        )?,
        planners: match &p.planners {
            Some(planners) => named_list("plan.planners", planners, names::all())?,
            None => vec![PlannerKind::Rrt, PlannerKind::Prm],
        },
        seeds: match p.seeds {
            Some(s) if s.is_empty() => bail!("plan.seeds: give at least one seed"),
            Some(s) => s,
            None => vec![1],
        },
        max_iterations: match p.max_iterations.unwrap_or(DEFAULT_MAX_ITERATIONS) {
            n @ 1..=MAX_ITERATIONS_LIMIT => n,
            n => bail!("plan.max_iterations must be in 1..={MAX_ITERATIONS_LIMIT}, not {n}"),
        },
    };

    let tof = raw
        .tof
        .map(|t| -> Result<TofConfig> {
            if let Some(a) = t.aat
                && !(a.is_finite() && a > 0.0)
            {
                bail!("tof.aat must be a positive threshold, not {a}");
            }
            use crate::tof::Method;
            let method = t
                .method
                .as_deref()
                .map_or(Ok(Method::Regions), |m| named("tof.method", m, names::all()))?;
            if method == Method::TwoFreq {
                bail!("tof.method: two-freq needs a second frame, which [tof] does not take");
            }
            let unwrap = t.unwrap.unwrap_or(false);
            if unwrap && method != Method::Aat {
                bail!(
                    "tof.unwrap = true needs tof.method = \"aat\" (region unwrapping decides \
                     what to unwrap itself)"
                );
            }
            if let Some(l) = t.low_at {
                if !(unwrap || method == Method::Regions) {
                    bail!(
                        "tof.low_at applies only with tof.method = \"regions\" or with \
                         tof.unwrap = true"
                    );
                }
                if !(l.is_finite() && l >= 0.0) {
                    bail!("tof.low_at must be a non-negative amplitude, not {l}");
                }
            }
            Ok(TofConfig {
                range: existing("tof.range", base, &t.range)?,
                amplitude: existing("tof.amplitude", base, &t.amplitude)?,
                meta: existing("tof.meta", base, &t.meta)?,
                confidence: t
                    .confidence
                    .as_deref()
                    .map(|c| existing("tof.confidence", base, c))
                    .transpose()?,
                method,
                aat: t.aat,
                unwrap,
                low_at: t.low_at,
            })
        })
        .transpose()?;

    let terrain = raw
        .terrain
        .map(|t| -> Result<TerrainConfig> {
            let resolution = t.resolution.unwrap_or(15.0);
            if !(resolution.is_finite() && resolution > 0.0 && resolution <= 90.0) {
                bail!("terrain.resolution must be in (0, 90] degrees, not {resolution}");
            }
            let sensor_height = t.sensor_height;
            if let Some(h) = sensor_height
                && !(h.is_finite() && h.abs() <= 100.0)
            {
                bail!("terrain.sensor_height must be a finite height in metres, not {h}");
            }
            let pitch = t.pitch;
            if let Some(p) = pitch
                && !(p.is_finite() && p.abs() < 90.0)
            {
                bail!("terrain.pitch must be in (-90, 90) degrees, not {p}");
            }
            if let Some(r) = t.max_range
                && !(r.is_finite() && r > 0.0)
            {
                bail!("terrain.max_range must be a positive distance in metres, not {r}");
            }
            let sectors = t.sectors.unwrap_or(3);
            if !(1..=90).contains(&sectors) {
                bail!("terrain.sectors must be in 1..=90, not {sectors}");
            }
            Ok(TerrainConfig {
                frame: existing("terrain.frame", base, &t.frame)?,
                resolution,
                sensor_height,
                pitch,
                axes: t
                    .axes
                    .as_deref()
                    .map(|a| named("terrain.axes", a, names::all()))
                    .transpose()?,
                max_range: t.max_range,
                sectors,
            })
        })
        .transpose()?;

    let demo = demo_settings();
    let demo_seeds = || (1..=demo.timing_seeds).collect::<Vec<u64>>();
    let timing = raw
        .timing
        .map(|t| -> Result<TimingConfig> {
            Ok(TimingConfig {
                iterations: t.iterations.map_or(Ok(demo.iterations), |n| {
                    count("timing.iterations", n, MAX_ITERATIONS_LIMIT)
                })?,
                checkpoints: t.checkpoints.map_or(Ok(demo.checkpoints), |n| {
                    count("timing.checkpoints", n, MAX_CHECKPOINTS)
                })?,
                seeds: seed_list("timing.seeds", t.seeds.unwrap_or_else(demo_seeds))?,
                starts: match &t.starts {
                    Some(s) => point_list("timing.starts", s)?,
                    None => vec![plan.start],
                },
            })
        })
        .transpose()?;
    let volume = raw
        .volume
        .map(|v| -> Result<VolumeConfig> {
            let n = map_count(&input, &types, backends.as_deref());
            if n > MAX_VOLUME_MAPS {
                bail!(
                    "[volume] compares at most {MAX_VOLUME_MAPS} maps, but maps.types × maps.backends \
                     give {n}; list fewer"
                );
            }
            Ok(VolumeConfig {
                planner: match &v.planner {
                    Some(p) => named("volume.planner", p, explore_planners())?,
                    None => PlannerKind::Rrt,
                },
                iterations: match (v.iterations, &timing) {
                    (Some(n), _) => count("volume.iterations", n, MAX_ITERATIONS_LIMIT)?,
                    (None, Some(t)) => t.iterations,
                    (None, None) => demo.iterations,
                },
                seeds: match (v.seeds, &timing) {
                    (Some(s), _) => seed_list("volume.seeds", s)?,
                    (None, Some(t)) => t.seeds.clone(),
                    (None, None) => demo_seeds(),
                },
                starts: match (&v.starts, &timing) {
                    (Some(s), _) => point_list("volume.starts", s)?,
                    (None, Some(t)) => t.starts.clone(),
                    (None, None) => vec![plan.start],
                },
                cells: v.cells.map_or(Ok(demo.cells), |n| {
                    count("volume.cells", n, MAX_CELLS).map(|c| c as u32)
                })?,
            })
        })
        .transpose()?;

    let out = base.join(raw.output.dir.unwrap_or_else(|| PathBuf::from(DEFAULT_OUT)));
    if out.is_file() {
        bail!("output.dir: {} is a file, not a folder", out.display());
    }
    Ok(Config {
        name,
        input,
        skip_non_finite: i.skip_non_finite.unwrap_or(false),
        types,
        backends,
        sensor,
        spacing,
        mesh_edge,
        max_patch_triangles,
        plan,
        tof,
        terrain,
        timing,
        volume,
        out,
        write_3d: raw.output.write_3d.unwrap_or(true),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, text: &str) -> PathBuf {
        std::fs::write(dir.join("a.ply"), "").unwrap();
        std::fs::write(dir.join("a.obj"), "").unwrap();
        let p = dir.join("run.toml");
        std::fs::write(&p, text).unwrap();
        p
    }

    const PLAN: &str = "[plan]\nstart = [0, 0, 1]\ngoals = [[1, 0, 1]]\n";

    #[test]
    fn defaults_fill_every_optional_key() {
        let dir = tempfile::tempdir().unwrap();
        let c = load(&write(dir.path(), &format!("[input]\ncloud = \"a.ply\"\n{PLAN}"))).unwrap();
        assert_eq!(c.input, Input::Cloud(dir.path().join("a.ply")));
        assert_eq!(c.types, vec![MapKind::Pc]);
        assert_eq!(c.name, "run");
        assert_eq!(c.plan.radius, DEFAULT_RADIUS);
        assert_eq!(c.plan.planners, vec![PlannerKind::Rrt, PlannerKind::Prm]);
        assert_eq!(c.plan.seeds, vec![1]);
        assert_eq!(c.out, dir.path().join(DEFAULT_OUT));
        assert!(c.write_3d && c.tof.is_none() && c.terrain.is_none());
    }

    #[test]
    fn bad_values_name_their_key() {
        let dir = tempfile::tempdir().unwrap();
        let cases = [
            ("[input]\ncloud = \"a.ply\"\nmesh = \"a.ply\"\n", "exactly one of"),
            ("[input]\ncloud = \"b.ply\"\n", "input.cloud"),
            ("[input]\ncloud = \"a.ply\"\n[maps]\ntypes = [\"planes\"]\n", "maps.types"),
            ("[input]\ncloud = \"a.ply\"\n[maps]\nsensor = \"alrf\"\n", "maps.sensor"),
            ("[input]\nscans = [\"a.ply\"]\n[maps]\nbackends = [\"bullet\"]\n", "maps.backends[0]"),
            ("[input]\ncloud = \"a.ply\"\nfoo = 1\n", "unknown field `foo`"),
        ];
        for (head, needle) in cases {
            let e = load(&write(dir.path(), &format!("{head}{PLAN}"))).unwrap_err().to_string();
            assert!(e.contains(needle) && !e.contains('\n'), "{needle}: {e}");
        }
        let plans = [
            ("radius = nan", "plan.radius"),
            ("step = -1.0", "plan.step"),
            ("goal_tolerance = 0.0", "plan.goal_tolerance"),
            ("planners = [\"rrt\", \"rrt\"]", "plan.planners"),
            ("planners = [\"astar\"]", "plan.planners[0]"),
            ("seeds = []", "plan.seeds"),
            ("max_iterations = 0", "plan.max_iterations"),
        ];
        for (line, needle) in plans {
            let text = format!("[input]\ncloud = \"a.ply\"\n{PLAN}{line}\n");
            let e = load(&write(dir.path(), &text)).unwrap_err().to_string();
            assert!(e.contains(needle) && !e.contains('\n'), "{needle}: {e}");
        }
        let text = "[input]\ncloud = \"a.ply\"\n[plan]\nstart = [0, nan, 1]\ngoals = [[1, 0, 1]]\n";
        let e = load(&write(dir.path(), text)).unwrap_err().to_string();
        assert!(e.contains("plan.start"), "{e}");
    }

    #[test]
    fn tof_defaults_to_region_unwrapping_and_unwrap_needs_the_aat() {
        use crate::tof::Method;
        let dir = tempfile::tempdir().unwrap();
        for f in ["r.png", "a.png", "m.json"] {
            std::fs::write(dir.path().join(f), "").unwrap();
        }
        let tof = |keys: &str| {
            let text = format!(
                "[input]\ncloud = \"a.ply\"\n{PLAN}[tof]\nrange = \"r.png\"\namplitude = \"a.png\"\n\
                 meta = \"m.json\"\n{keys}"
            );
            load(&write(dir.path(), &text))
        };
        let t = tof("").unwrap().tof.unwrap();
        assert_eq!((t.method, t.unwrap, t.low_at), (Method::Regions, false, None));
        let t = tof("method = \"aat\"\nunwrap = true\nlow_at = 20.0\n").unwrap().tof.unwrap();
        assert_eq!((t.method, t.unwrap, t.low_at), (Method::Aat, true, Some(20.0)));
        assert_eq!(tof("low_at = 50.0\n").unwrap().tof.unwrap().low_at, Some(50.0));
        for (keys, needle) in [
            ("unwrap = true\n", "tof.unwrap"),
            ("method = \"aat\"\nlow_at = 20.0\n", "tof.low_at"),
            ("method = \"two-freq\"\n", "tof.method"),
            ("method = \"fold\"\n", "tof.method"),
        ] {
            let e = tof(keys).unwrap_err().to_string();
            assert!(e.contains(needle), "{keys}: {e}");
        }
    }

    #[test]
    fn timing_and_volume_take_the_demo_defaults_and_share_runs() {
        let dir = tempfile::tempdir().unwrap();
        let head = format!("[input]\ncloud = \"a.ply\"\n{PLAN}");
        let c = load(&write(dir.path(), &format!("{head}[timing]\n[volume]\n"))).unwrap();
        let demo = demo_settings();
        let t = c.timing.as_ref().unwrap();
        assert_eq!((t.iterations, t.checkpoints), (demo.iterations, demo.checkpoints));
        assert_eq!(t.seeds, (1..=demo.timing_seeds).collect::<Vec<_>>());
        assert_eq!(t.starts, vec![c.plan.start]);
        let v = c.volume.as_ref().unwrap();
        assert_eq!((v.planner, v.cells), (PlannerKind::Rrt, demo.cells));
        assert!(v.shares_runs_with(t));
        // Any difference in the runs, or the PRM, needs runs of its own.
        for extra in ["planner = \"prm\"", "iterations = 10", "seeds = [9]", "starts = [[0, 0, 2]]"]
        {
            let text = format!("{head}[timing]\n[volume]\n{extra}\n");
            let c = load(&write(dir.path(), &text)).unwrap();
            assert!(!c.volume.unwrap().shares_runs_with(c.timing.as_ref().unwrap()), "{extra}");
        }
        // Without [timing], [volume] runs from the plan's start.
        let c = load(&write(dir.path(), &format!("{head}[volume]\ncells = 7\n"))).unwrap();
        let v = c.volume.unwrap();
        assert_eq!((v.cells, v.starts), (7, vec![c.plan.start]));
        assert!(c.timing.is_none());
    }

    #[test]
    fn mesh_input_gives_every_map_type_and_its_trimesh_keys() {
        let dir = tempfile::tempdir().unwrap();
        let text = format!(
            "[input]\nmesh = \"a.obj\"\n[maps]\nmesh_edge = 0.2\nmax_patch_triangles = 9\n{PLAN}"
        );
        let c = load(&write(dir.path(), &text)).unwrap();
        assert_eq!(c.types, MapKind::ALL.to_vec());
        assert_eq!((c.mesh_edge, c.max_patch_triangles), (Some(0.2), 9));
        let c = load(&write(dir.path(), &format!("[input]\nmesh = \"a.obj\"\n{PLAN}"))).unwrap();
        assert_eq!((c.mesh_edge, c.max_patch_triangles), (None, 324));
    }

    #[test]
    fn bad_timing_volume_and_trimesh_values_name_their_key() {
        let dir = tempfile::tempdir().unwrap();
        let cloud = format!("[input]\ncloud = \"a.ply\"\n{PLAN}");
        let mesh = format!("[input]\nmesh = \"a.obj\"\n{PLAN}");
        let cases = [
            (format!("{cloud}[timing]\niterations = -5\n"), "timing.iterations must be in 1..="),
            (format!("{cloud}[timing]\ncheckpoints = 0\n"), "timing.checkpoints"),
            (format!("{cloud}[timing]\nseeds = []\n"), "timing.seeds"),
            (format!("{cloud}[timing]\nseeds = [4, 2, 4]\n"), "timing.seeds[2]: seed 4"),
            (format!("{cloud}[timing]\nseeds = [1, -2]\n"), "timing.seeds: invalid value"),
            (format!("{cloud}[timing]\nstarts = []\n"), "timing.starts"),
            (format!("{cloud}[timing]\nstarts = [[0, 0, 1], [0, nan, 1]]\n"), "timing.starts[1]"),
            (format!("{cloud}[timing]\nk = 3\n"), "unknown field `k`"),
            (format!("{cloud}[volume]\ncells = 0\n"), "volume.cells must be in 1..=1024, not 0"),
            (format!("{cloud}[volume]\ncells = 5000\n"), "volume.cells"),
            (format!("{cloud}[volume]\niterations = -1\n"), "volume.iterations"),
            (format!("{cloud}[volume]\nplanner = \"astar\"\n"), "volume.planner: unknown value"),
            (format!("{cloud}[volume]\ncells = \"many\"\n"), "volume.cells: invalid type"),
            (format!("{cloud}[maps]\nmesh_edge = 0.1\n"), "maps.mesh_edge applies to `mesh`"),
            (format!("{mesh}[maps]\nmesh_edge = -0.1\n"), "maps.mesh_edge"),
            (format!("{mesh}[maps]\nmax_patch_triangles = 0\n"), "maps.max_patch_triangles"),
            (
                format!("{mesh}[maps]\ntypes = [\"planes\"]\nmax_patch_triangles = 5\n"),
                "maps.max_patch_triangles applies to the trimesh map",
            ),
            (format!("{mesh}[maps]\ntypes = [\"voxels\"]\n"), "maps.types[0]: unknown value"),
            (
                format!(
                    "{mesh}[maps]\nbackends = [\"polygon\", \"bbox6d\", \"trimesh\"]\n[volume]\n"
                ),
                "[volume] compares at most 8 maps",
            ),
            (format!("{cloud}max_iterations = -5\n"), "plan.max_iterations: invalid value"),
        ];
        for (text, needle) in &cases {
            let e = load(&write(dir.path(), text)).unwrap_err().to_string();
            assert!(e.contains(needle) && !e.contains('\n'), "{needle}: {e}");
        }
    }

    #[test]
    fn names_outside_a_keys_subset_are_refused_with_the_choices() {
        let dir = tempfile::tempdir().unwrap();
        let cases = [
            (
                "[input]\nscans = [\"a.ply\"]\n[maps]\nbackends = [\"rapier\", \"pointcloud\"]\n",
                "maps.backends[1]: unknown value `pointcloud` here (it holds points, not \
                 patches); choose one of: polygon, bbox6d, trimesh, rapier",
            ),
            (
                "[input]\ncloud = \"a.ply\"\n[volume]\nplanner = \"prm-star\"\n",
                "volume.planner: unknown value `prm-star` here (the volume grows the thesis's \
                 RRT or PRM); choose one of: rrt, prm",
            ),
        ];
        for (head, message) in cases {
            let e = load(&write(dir.path(), &format!("{head}{PLAN}"))).unwrap_err().to_string();
            assert!(e.ends_with(message), "{e}");
        }
        let text = "[input]\nmesh = \"a.obj\"\n[maps]\nbackends = [\"bbox6d\", \"trimesh\"]\n";
        let c = load(&write(
            dir.path(),
            &format!("{text}{PLAN}planners = [\"prm-valid\", \"ma-rrt\"]\n"),
        ))
        .unwrap();
        assert_eq!(c.backends, Some(vec![Backend::BBox6d, Backend::Trimesh]));
        assert_eq!(c.plan.planners, [PlannerKind::PrmValid, PlannerKind::MaRrt]);
    }

    #[test]
    fn keys_are_found_under_their_table() {
        let text = "[input]\ncloud = \"a\"\n\n[plan] # the plan\nseeds = [1, -2]\n";
        let at = text.find("-2").unwrap();
        assert_eq!(key_at(text, at).as_deref(), Some("plan.seeds"));
        assert_eq!(key_at(text, 0), None, "a header has no key");
        assert_eq!(key_at("x = 1\n", 4).as_deref(), Some("x"));
        assert_eq!(key_at("[a]\n\"odd key\" = 1\n", 14), None);
    }
}
