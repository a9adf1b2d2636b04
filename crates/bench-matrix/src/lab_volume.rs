//! `lab-volume`: thesis §6.1–6.2 on the lab's four maps built from simulated scans — what each
//! map holds (Table 6.1, L6721–6739) and how much of the volume the roadmaps explore on one map
//! is not explored on another (Table 6.2 for the RRT, L6760–6778; Table 6.4 for the PRM,
//! L7068–7086).
//!
//! # Maps
//! The four map files of the folder named by `$PATCHNAV_LAB_MAPS` ([`lab_maps`]; `cargo xtask
//! bench lab-volume` builds and caches them as for the matrix's `lab-scans-*` scenes). The
//! three patch maps run in the `trimesh` backend (one parry BVH): the thesis ran all its patch
//! maps in one collision library (Bullet, §6.1); pc runs in the `pointcloud` backend (Algorithm
//! 10, spec §7.12).
//!
//! # Runs (thesis §6.1.1, §6.2.1, §6.2.2)
//! * RRT (Algorithm 13 as run for §6.1, [`RrtConfig::thesis`]: uniform samples in the map's
//!   own box, L6460, no goal) from each of the first `starts` room corners × every seed, K
//!   iterations. A start is the first point of a small spiral from 0.6 m inside the corner at
//!   1.0 m height that is free on all four maps and inside the box common to them (the rule of
//!   the matrix's lab scenes and of `patchnav experiment lab-volume`; the thesis says "the four
//!   corners of the room", L6712–6714).
//! * PRM (Algorithm 14, [`PrmConfig::thesis`]: six neighbours) for every seed, from the first
//!   start, K_PRM iterations (the thesis gives neither its PRM seeds for the volume nor K,
//!   spec §7.11).
//! * Each roadmap's explored part ([`roadmap::volume::explored_part`]: edges, and vertices
//!   that have an edge or a free sphere) goes into one [`VoxelGrid`] per map and planner; all
//!   grids share one lattice of `cells³` cubic cells over the box covering every map (the
//!   thesis's "smallest octree covering all maps", L6600–6606). The congruence entry of row A,
//!   column B is `|A∖B| / |A| · 100` ([`CongruenceTable`]).
//!
//! Robot radius 0.3 m and step 1 m, as the matrix's lab scenes (the thesis does not give them
//! for the lab, spec §5.2).
//!
//! # Size
//! Defaults sized for well under two minutes on two cores: 4 starts × `--seeds` (the program's
//! default, 10) RRTs and `--seeds` PRMs per map, K = 1000, [`DEFAULT_CELLS`]³ cells (about
//! 25 s with one thread, 8 s of it loading the maps). Scale
//! with `--seeds N`, `--jobs N` (threads; the result does not depend on it) and the
//! environment: [`K_ENV`], [`PRM_K_ENV`], [`STARTS_ENV`], [`CELLS_ENV`]. The thesis's size
//! (L6895–6899): `--seeds 120` with `PATCHNAV_LAB_VOLUME_K=10000` and
//! `PATCHNAV_LAB_VOLUME_CELLS=1024` — hours, not minutes.
//!
//! # Rows
//! * `lab-volume/contents/<map>`: `planar_patches`, `trimesh_patches`, `triangles` (of the
//!   trimesh patches and of the planar patches' triangulations, as the trimesh backend holds
//!   them), `points`, `point_clouds` (pc only, from the folder's `build.json`), `memory_bytes`
//!   (heap bytes of the map in its backend), `file_bytes` (the `.pmap` file).
//! * `lab-volume/<planner>/<map>`: `volume` (m³) and `voxels`.
//! * `lab-volume/<planner>/<row map>/<column map>`: `not_in` (% of the row map's volume not
//!   explored on the column map).
//!
//! Every volume row carries the grid (`cells`, `cell_size_m`), `seeds`, `first_seed`,
//! `starts`, `k`, `runs`, `radius`, the RRT's `step` or the PRM's `neighbours`, and `lab_maps`
//! (the folder's name, which holds the build parameters).

use crate::roadmap::{MatrixArgs, lab_maps};
use anyhow::{Context, Result, bail};
use evaluation::thesis;
use patch_core::{Point3, Real};
use patch_map::{AnyMap, Backend};
use patch_pipeline::experiment::lab::{common_box, corner_starts};
use patch_pipeline::scene_map::MapKind;
use pointcloud::Aabb;
use roadmap::volume::{CongruenceTable, VoxelGrid, explored_part};
use roadmap::{
    MaxIterations, Planner, PlannerKind, PlannerStatus, PlanningSpace, Prm, PrmConfig, Problem,
    Rrt, RrtConfig,
};
use serde_json::{Value, json};
use std::fmt::Write as _;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Instant;

/// Robot radius of every run, metres (the matrix's lab scenes; not given in the thesis).
const RADIUS: Real = 0.3;
/// Longest RRT edge, metres (the matrix's lab scenes; not given in the thesis).
const STEP: Real = 1.0;
/// The backend of the patch maps (one BVH over all triangles: the role of the thesis's
/// Bullet, in which it ran every patch map).
const PATCH_BACKEND: Backend = Backend::Trimesh;
/// The backend of the pc map (Algorithm 10).
const PC_BACKEND: Backend = Backend::PointCloud;
/// The planners, in the order of the thesis's tables (6.2 before 6.4).
const PLANNERS: [PlannerKind; 2] = [PlannerKind::Rrt, PlannerKind::Prm];

/// Iterations of every RRT (K); default [`DEFAULT_K`].
pub(crate) const K_ENV: &str = "PATCHNAV_LAB_VOLUME_K";
/// Iterations of every PRM; default: the RRT's K.
pub(crate) const PRM_K_ENV: &str = "PATCHNAV_LAB_VOLUME_PRM_K";
/// Room corners the RRTs start from (1–4); default 4, the thesis's.
pub(crate) const STARTS_ENV: &str = "PATCHNAV_LAB_VOLUME_STARTS";
/// Cells per axis of the grid; default [`DEFAULT_CELLS`].
pub(crate) const CELLS_ENV: &str = "PATCHNAV_LAB_VOLUME_CELLS";
/// The default K (the matrix's lab runs; the thesis: 10,000).
pub(crate) const DEFAULT_K: u64 = 1000;
/// The default cells per axis: 320 over the lab's ≈ 12.2 m give ≈ 38 mm cells, the thesis's
/// 38.684 mm (its 1024³ grid covered a larger box, L6604–6606; `patchnav experiment
/// lab-volume`'s default too).
pub(crate) const DEFAULT_CELLS: u32 = 320;
/// The largest K accepted (the thesis's is 10,000).
const MAX_K: u64 = 1_000_000;
/// The largest grid accepted (the thesis's is 1024³; a capsule's cost grows with the square).
const MAX_CELLS: u32 = 2048;

/// The parameters of a run.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct VolumeConfig {
    /// First seed; runs use `seed..seed + seeds`.
    pub seed: u64,
    /// RRT seeds per start, and PRM seeds.
    pub seeds: u64,
    /// Room corners the RRTs start from (1–4).
    pub starts: usize,
    /// RRT iterations.
    pub k: u64,
    /// PRM iterations.
    pub prm_k: u64,
    /// Cells per axis of the grid.
    pub cells: u32,
    /// Worker threads.
    pub jobs: usize,
}

impl VolumeConfig {
    /// The configuration from the program's options (`--seed`, `--seeds`, `--jobs`) and the
    /// environment (`env` looks a variable up).
    ///
    /// # Errors
    /// A variable that is not a number, or any number [`validate`](Self::validate) refuses.
    pub(crate) fn from_args(
        args: &MatrixArgs,
        env: &dyn Fn(&str) -> Option<String>,
    ) -> Result<VolumeConfig> {
        let number = |name: &str, default: u64| -> Result<u64> {
            match env(name).filter(|v| !v.trim().is_empty()) {
                Some(v) => v.trim().parse().with_context(|| format!("bad {name} `{v}`")),
                None => Ok(default),
            }
        };
        let k = number(K_ENV, DEFAULT_K)?;
        let cells = number(CELLS_ENV, u64::from(DEFAULT_CELLS))?;
        let config = VolumeConfig {
            seed: args.seed,
            seeds: args.seeds,
            starts: usize::try_from(number(STARTS_ENV, 4)?).unwrap_or(usize::MAX),
            k,
            prm_k: number(PRM_K_ENV, k)?,
            cells: u32::try_from(cells).unwrap_or(u32::MAX),
            jobs: args.jobs,
        };
        config.validate()?;
        Ok(config)
    }

    /// Checks the numbers.
    ///
    /// # Errors
    /// Seeds outside 1–1,000,000 or overflowing from the first seed, starts outside 1–4, K
    /// outside 1–1,000,000, cells outside 1–2048, jobs outside 1–1024.
    pub(crate) fn validate(&self) -> Result<()> {
        if self.seeds == 0 || self.seeds > 1_000_000 {
            bail!("--seeds must be between 1 and 1,000,000, got {}", self.seeds);
        }
        if self.seed.checked_add(self.seeds).is_none() {
            bail!("--seed {} + --seeds {} overflows", self.seed, self.seeds);
        }
        if !(1..=4).contains(&self.starts) {
            bail!("{STARTS_ENV} must be between 1 and 4 (room corners), got {}", self.starts);
        }
        for (name, k) in [(K_ENV, self.k), (PRM_K_ENV, self.prm_k)] {
            if !(1..=MAX_K).contains(&k) {
                bail!("{name} must be between 1 and {MAX_K}, got {k}");
            }
        }
        if !(1..=MAX_CELLS).contains(&self.cells) {
            bail!("{CELLS_ENV} must be between 1 and {MAX_CELLS}, got {}", self.cells);
        }
        if self.jobs == 0 || self.jobs > 1024 {
            bail!("--jobs must be between 1 and 1024, got {}", self.jobs);
        }
        Ok(())
    }

    fn seeds(&self) -> std::ops::Range<u64> {
        self.seed..self.seed + self.seeds
    }
}

/// What one map holds: a row of our Table 6.1.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Contents {
    /// Planar patches.
    pub planar_patches: u64,
    /// Trimesh patches.
    pub trimesh_patches: u64,
    /// Triangles of the map in its backend (for the trimesh backend: the trimesh patches' and
    /// the planar patches' triangulations, as the thesis counts them).
    pub triangles: u64,
    /// Points (the pc map).
    pub points: u64,
    /// Scans merged into the pc map, when the folder's `build.json` says.
    pub point_clouds: Option<u64>,
    /// Heap bytes of the map in its backend.
    pub memory_bytes: u64,
    /// Size of its `.pmap` file.
    pub file_bytes: u64,
}

/// One of the four maps, in the backend it is planned in.
struct LabMap {
    kind: MapKind,
    backend: Backend,
    map: AnyMap,
    /// The box it samples in (its own, thesis L6460).
    bounds: Aabb,
    contents: Contents,
}

/// Runs the benchmark; `emit` gets every row. Without `$PATCHNAV_LAB_MAPS` it is skipped with
/// a note.
///
/// # Errors
/// Bad options, unreadable maps, no free start, a start that is not free on a map.
pub(crate) fn run(args: &MatrixArgs, emit: &mut dyn FnMut(Value) -> Result<()>) -> Result<()> {
    let config = VolumeConfig::from_args(args, &|k| std::env::var(k).ok())?;
    let Some(folder) = lab_maps::folder_from_env() else {
        eprintln!(
            "SKIPPED: lab-volume (no maps built from scans: set {} to a folder of \
             planes/hybrid/trimesh/pc .pmap files, as `cargo xtask bench lab-volume` does)",
            lab_maps::LAB_MAPS_ENV
        );
        return Ok(());
    };
    let [lx, ly, _] = scene_sim::lab_layout::ROOM;
    run_with(&config, &folder, [lx, ly], emit)
}

/// [`run`] on the maps of `folder`, the room's corners at `(0, 0)` and `room`.
fn run_with(
    config: &VolumeConfig,
    folder: &Path,
    room: [Real; 2],
    emit: &mut dyn FnMut(Value) -> Result<()>,
) -> Result<()> {
    config.validate()?;
    let t0 = Instant::now();
    let maps = load_maps(folder)?;
    let lab_maps_key = folder.file_name().map(|n| n.to_string_lossy().into_owned());
    eprintln!(
        "lab-volume: {} maps loaded from {} in {:.1} s",
        maps.len(),
        folder.display(),
        t0.elapsed().as_secs_f64()
    );
    for m in &maps {
        emit_contents(m, lab_maps_key.as_deref(), emit)?;
    }
    eprint!("{}", contents_table(&maps));

    let all: Vec<&AnyMap> = maps.iter().map(|m| &m.map).collect();
    let common = common_box(maps.iter().map(|m| m.bounds));
    let starts = corner_starts(&all, &common, RADIUS, room, config.starts)?;
    let empty = VoxelGrid::covering(maps.iter().map(|m| m.bounds), config.cells)
        .context("the voxel grid over the maps")?;
    let mut items = Vec::new();
    for m in 0..maps.len() {
        for &start in &starts {
            items.extend(config.seeds().map(|seed| Item { map: m, planner: 0, start, seed }));
        }
        items.extend(config.seeds().map(|seed| Item {
            map: m,
            planner: 1,
            start: starts[0],
            seed,
        }));
    }
    eprintln!(
        "lab-volume: {} roadmaps ({} starts × {} seeds RRT, K = {}; {} seeds PRM, K = {}) on {} \
         maps, {}³ cells of {:.1} mm, {} thread(s)",
        items.len(),
        starts.len(),
        config.seeds,
        config.k,
        config.seeds,
        config.prm_k,
        maps.len(),
        config.cells,
        empty.cell_size() * 1e3,
        config.jobs
    );
    let grids = run_items(&maps, &items, &empty, config)?;
    let names: Vec<&str> = maps.iter().map(|m| m.kind.name()).collect();
    for (p, &planner) in PLANNERS.iter().enumerate() {
        let table = CongruenceTable::new(names.iter().copied().zip(grids.iter().map(|g| &g[p])))
            .context("the congruence table")?;
        let params = Params {
            planner,
            starts: if p == 0 { starts.len() } else { 1 },
            k: if p == 0 { config.k } else { config.prm_k },
            cells: config.cells,
            cell_size: empty.cell_size(),
            config,
            lab_maps: lab_maps_key.as_deref(),
        };
        for row in volume_rows(&table, &maps, &params) {
            emit(row)?;
        }
        let (number, thesis_rows) = match p {
            0 => ("6.2", &thesis::TABLE_6_2_RRT),
            _ => ("6.4", &thesis::TABLE_6_4_PRM),
        };
        eprintln!(
            "\nTable {number} analogue ({planner}): explored volume [m³] and % of the row's \
             volume not explored on the column's map; {} start(s) × {} seeds, K = {}",
            params.starts, config.seeds, params.k
        );
        eprint!("{table}");
        eprintln!("thesis Table {number}:");
        eprint!("{}", thesis::volume_table_markdown(thesis_rows));
    }
    eprintln!("lab-volume: done in {:.1} s", t0.elapsed().as_secs_f64());
    Ok(())
}

/// Loads the four maps of `folder` into the backends they are planned in, with their contents.
fn load_maps(folder: &Path) -> Result<Vec<LabMap>> {
    let mut loaded = lab_maps::load(folder, RADIUS)?;
    let point_clouds = scans_of_build(folder);
    let mut maps = Vec::new();
    for kind in MapKind::ALL {
        let backend = if kind == MapKind::Pc { PC_BACKEND } else { PATCH_BACKEND };
        let (_, map) = loaded
            .take_maps(kind, &[backend])
            .with_context(|| format!("loading the {kind} map"))?
            .pop()
            .with_context(|| format!("the {kind} map cannot be held by the `{backend}` backend"))?;
        let path = lab_maps::map_path(folder, kind);
        let file_bytes = std::fs::metadata(&path)
            .with_context(|| format!("reading the size of {}", path.display()))?
            .len();
        let counts = map.counts();
        let contents = Contents {
            planar_patches: counts.planar_patches,
            trimesh_patches: counts.trimesh_patches,
            triangles: counts.triangles,
            points: counts.points,
            point_clouds: if kind == MapKind::Pc { point_clouds } else { None },
            memory_bytes: map.memory_bytes() as u64,
            file_bytes,
        };
        maps.push(LabMap { kind, backend, map, bounds: loaded.bounds(kind)?, contents });
    }
    Ok(maps)
}

/// The number of scans the folder's maps were built from (`build.json`'s `scans`, written by
/// `cargo xtask bench`), if it says.
fn scans_of_build(folder: &Path) -> Option<u64> {
    let text = std::fs::read_to_string(folder.join("build.json")).ok()?;
    serde_json::from_str::<Value>(&text).ok()?.get("scans")?.as_u64()
}

/// One roadmap to grow: on map `map`, planner `PLANNERS[planner]`.
#[derive(Copy, Clone, Debug)]
struct Item {
    map: usize,
    planner: usize,
    start: Point3,
    seed: u64,
}

/// Grows every item's roadmap on `jobs` threads and rasterises its explored part; per map,
/// the RRT and the PRM grid (the union over all runs, so the result does not depend on the
/// threads).
fn run_items(
    maps: &[LabMap],
    items: &[Item],
    empty: &VoxelGrid,
    config: &VolumeConfig,
) -> Result<Vec<[VoxelGrid; 2]>> {
    let next = AtomicUsize::new(0);
    let failed = AtomicBool::new(false);
    let fresh = || -> Vec<[VoxelGrid; 2]> {
        maps.iter().map(|_| [empty.empty_like(), empty.empty_like()]).collect()
    };
    let spaces = maps
        .iter()
        .map(|m| {
            PlanningSpace::new(m.bounds, RADIUS, STEP)
                .with_context(|| format!("the planning space of the {} map", m.kind))
        })
        .collect::<Result<Vec<_>>>()?;
    let parts = std::thread::scope(|s| {
        let workers: Vec<_> = (0..config.jobs.min(items.len()).max(1))
            .map(|_| {
                let (next, failed, spaces) = (&next, &failed, &spaces);
                s.spawn(move || -> Result<Vec<[VoxelGrid; 2]>> {
                    let mut grids = fresh();
                    while !failed.load(Ordering::Relaxed) {
                        let Some(item) = items.get(next.fetch_add(1, Ordering::Relaxed)) else {
                            break;
                        };
                        let m = &maps[item.map];
                        let r = explore(m, spaces[item.map], item, config).and_then(|part| {
                            Ok(grids[item.map][item.planner].add_roadmap(&part, RADIUS)?)
                        });
                        if let Err(e) = r {
                            failed.store(true, Ordering::Relaxed);
                            return Err(e);
                        }
                    }
                    Ok(grids)
                })
            })
            .collect();
        workers
            .into_iter()
            .map(|w| w.join().unwrap_or_else(|_| Err(anyhow::anyhow!("a worker panicked"))))
            .collect::<Result<Vec<_>>>()
    })?;
    let mut parts = parts.into_iter();
    let mut total = parts.next().unwrap_or_else(fresh);
    for part in parts {
        for (t, p) in total.iter_mut().zip(&part) {
            t[0].union_with(&p[0])?;
            t[1].union_with(&p[1])?;
        }
    }
    Ok(total)
}

/// The explored part of one item's roadmap ([`explored_part`]).
fn explore(
    m: &LabMap,
    space: PlanningSpace,
    item: &Item,
    config: &VolumeConfig,
) -> Result<roadmap::Roadmap> {
    let problem = Problem { start: item.start, goals: Vec::new() };
    let (mut planner, k): (Box<dyn Planner + '_>, u64) = if item.planner == 0 {
        (Box::new(Rrt::new(&m.map, space, RrtConfig::thesis(), item.seed)), config.k)
    } else {
        (Box::new(Prm::new(&m.map, space, PrmConfig::thesis(), item.seed)), config.prm_k)
    };
    if planner.solve(&problem, &mut MaxIterations(k)) == PlannerStatus::InvalidStart
        && item.planner == 0
    {
        let p = item.start;
        bail!("the start ({:.2}, {:.2}, {:.2}) is not free on the {} map", p.x, p.y, p.z, m.kind);
    }
    Ok(explored_part(planner.roadmap(), &m.map, RADIUS)?)
}

/// What every volume row of one planner carries.
struct Params<'a> {
    planner: PlannerKind,
    starts: usize,
    k: u64,
    cells: u32,
    cell_size: Real,
    config: &'a VolumeConfig,
    lab_maps: Option<&'a str>,
}

impl Params<'_> {
    /// A row of this planner with the run's parameters.
    fn row(&self, case: String, metric: &str, value: Value, unit: &str) -> Value {
        let runs = self.starts as u64 * self.config.seeds;
        let mut row = json!({
            "case": case, "metric": metric, "value": value, "unit": unit,
            "planner": self.planner.name(), "starts": self.starts, "seeds": self.config.seeds,
            "first_seed": self.config.seed, "runs": runs, "k": self.k, "cells": self.cells,
            "cell_size_m": self.cell_size, "radius": RADIUS, "jobs": self.config.jobs,
            "table": if self.planner == PlannerKind::Rrt { "6.2" } else { "6.4" },
        });
        if let Some(obj) = row.as_object_mut() {
            // The RRT's step; the thesis's PRM has no edge-length limit, only its neighbours.
            if self.planner == PlannerKind::Rrt {
                obj.insert("step".into(), STEP.into());
            } else {
                obj.insert("neighbours".into(), PrmConfig::thesis().neighbours.into());
            }
            if let Some(key) = self.lab_maps {
                obj.insert("lab_maps".into(), key.into());
            }
        }
        row
    }
}

/// The rows of one planner's congruence table: per map its volume and voxels, per ordered
/// pair of maps the % not in (none on the diagonal or for a map that explored nothing).
fn volume_rows(table: &CongruenceTable, maps: &[LabMap], params: &Params<'_>) -> Vec<Value> {
    let mut rows = Vec::new();
    for (r, m) in maps.iter().enumerate() {
        let case = format!("lab-volume/{}/{}", params.planner, m.kind);
        let with_map = |mut row: Value| {
            if let Some(obj) = row.as_object_mut() {
                obj.insert("map".into(), m.kind.name().into());
                obj.insert("backend".into(), m.backend.name().into());
            }
            row
        };
        rows.push(with_map(params.row(case.clone(), "volume", json!(table.volume(r)), "m3")));
        rows.push(with_map(params.row(case, "voxels", json!(table.count(r)), "count")));
        for (c, other) in maps.iter().enumerate() {
            let Some(percent) = table.percent_not_in(r, c) else { continue };
            let case = format!("lab-volume/{}/{}/{}", params.planner, m.kind, other.kind);
            let mut row = with_map(params.row(case, "not_in", json!(percent), "%"));
            if let Some(obj) = row.as_object_mut() {
                obj.insert("column_map".into(), other.kind.name().into());
                obj.insert("voxels_not_in".into(), table.count_not_in(r, c).into());
            }
            rows.push(row);
        }
    }
    rows
}

/// Emits the contents rows of one map (Table 6.1).
fn emit_contents(
    m: &LabMap,
    lab_maps_key: Option<&str>,
    emit: &mut dyn FnMut(Value) -> Result<()>,
) -> Result<()> {
    let c = &m.contents;
    let mut metrics = vec![
        ("planar_patches", c.planar_patches, "count"),
        ("trimesh_patches", c.trimesh_patches, "count"),
        ("triangles", c.triangles, "count"),
        ("points", c.points, "count"),
    ];
    if let Some(n) = c.point_clouds {
        metrics.push(("point_clouds", n, "count"));
    }
    metrics.push(("memory_bytes", c.memory_bytes, "bytes"));
    metrics.push(("file_bytes", c.file_bytes, "bytes"));
    for (metric, value, unit) in metrics {
        let mut row = json!({
            "case": format!("lab-volume/contents/{}", m.kind), "metric": metric, "value": value,
            "unit": unit, "map": m.kind.name(), "backend": m.backend.name(), "table": "6.1",
        });
        if let (Some(key), Some(obj)) = (lab_maps_key, row.as_object_mut()) {
            obj.insert("lab_maps".into(), key.into());
        }
        emit(row)?;
    }
    Ok(())
}

/// Our Table 6.1 analogue, for standard error.
fn contents_table(maps: &[LabMap]) -> String {
    let mut o = String::from(
        "\nTable 6.1 analogue: | map | backend | planar patches | trimesh patches | triangles | \
         points | memory [MB] | file [MB] |\n",
    );
    for m in maps {
        let c = &m.contents;
        let _ = writeln!(
            o,
            "| {} | {} | {} | {} | {} | {} | {:.1} | {:.1} |",
            m.kind,
            m.backend,
            c.planar_patches,
            c.trimesh_patches,
            c.triangles,
            c.points,
            c.memory_bytes as f64 / 1e6,
            c.file_bytes as f64 / 1e6
        );
    }
    o
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::roadmap::lab_maps::tests::{TempDir, write_tiny_maps};
    use patch_core::{CapsuleStep, UnspecificStepIntersector as _};
    use std::collections::{HashMap, HashSet};

    fn args(seeds: u64, jobs: usize) -> MatrixArgs {
        MatrixArgs {
            scenes: Vec::new(),
            backends: Vec::new(),
            planners: Vec::new(),
            seed: 1,
            seeds,
            jobs,
            skip: HashSet::new(),
        }
    }

    fn config(seeds: u64, jobs: usize) -> VolumeConfig {
        VolumeConfig { seed: 1, seeds, starts: 4, k: 40, prm_k: 30, cells: 32, jobs }
    }

    fn rows_of(config: &VolumeConfig, folder: &Path) -> Vec<Value> {
        let mut rows = Vec::new();
        run_with(config, folder, [4.0, 4.0], &mut |r| {
            rows.push(r);
            Ok(())
        })
        .unwrap();
        rows
    }

    fn value(rows: &[Value], case: &str, metric: &str) -> f64 {
        rows.iter()
            .find(|r| r["case"] == case && r["metric"] == metric)
            .unwrap_or_else(|| panic!("no {case} {metric}"))["value"]
            .as_f64()
            .unwrap()
    }

    #[test]
    fn options_come_from_the_arguments_and_the_environment() {
        let none = |_: &str| None;
        let c = VolumeConfig::from_args(&args(3, 2), &none).unwrap();
        assert_eq!(
            c,
            VolumeConfig {
                seed: 1,
                seeds: 3,
                starts: 4,
                k: DEFAULT_K,
                prm_k: DEFAULT_K,
                cells: DEFAULT_CELLS,
                jobs: 2
            }
        );
        let env = |k: &str| match k {
            K_ENV => Some("500".to_owned()),
            CELLS_ENV => Some(" 64 ".to_owned()),
            STARTS_ENV => Some("2".to_owned()),
            _ => None,
        };
        let c = VolumeConfig::from_args(&args(3, 1), &env).unwrap();
        assert_eq!((c.k, c.prm_k, c.cells, c.starts), (500, 500, 64, 2), "PRM K follows K");
        for (name, bad) in [
            (K_ENV, "0"),
            (K_ENV, "ten"),
            (PRM_K_ENV, "-1"),
            (STARTS_ENV, "5"),
            (CELLS_ENV, "0"),
            (CELLS_ENV, "99999999999"),
        ] {
            let env = |k: &str| (k == name).then(|| bad.to_owned());
            let e = VolumeConfig::from_args(&args(3, 1), &env).unwrap_err();
            assert!(format!("{e:#}").contains(name), "{name}={bad}: {e:#}");
        }
        assert!(VolumeConfig::from_args(&args(0, 1), &none).is_err());
        assert!(VolumeConfig::from_args(&args(3, 0), &none).is_err());
        assert!(
            VolumeConfig::from_args(&MatrixArgs { seed: u64::MAX, ..args(3, 1) }, &none).is_err()
        );
    }

    #[test]
    fn starts_are_free_inside_every_corner_and_the_first_is_the_matrix_start() {
        let dir = TempDir::new("lab-volume-starts");
        write_tiny_maps(&dir.0);
        let loaded = lab_maps::load(&dir.0, RADIUS).unwrap();
        let maps = load_maps(&dir.0).unwrap();
        let all: Vec<&AnyMap> = maps.iter().map(|m| &m.map).collect();
        let common = common_box(maps.iter().map(|m| m.bounds));
        let starts = corner_starts(&all, &common, RADIUS, [4.0, 4.0], 4).unwrap();
        assert_eq!(starts.len(), 4);
        assert_eq!(starts[0], loaded.start, "the matrix's lab-scans start");
        for s in &starts {
            assert!(common.contains(s), "{s:?}");
            for m in &all {
                assert!(m.is_step_free(&CapsuleStep::sphere(*s, RADIUS).unwrap()));
            }
        }
        // The wall at x = 4 pushes the east starts out of its 0.3 m: x ≤ 3.4.
        assert!(starts[1].x <= 3.4 + 1e-9 && starts[1].y < 2.0, "{:?}", starts[1]);
        assert!(starts[2].x <= 3.4 + 1e-9 && starts[2].y > 2.0, "{:?}", starts[2]);
        assert!(corner_starts(&all, &common, RADIUS, [4.0, 4.0], 1).unwrap().len() == 1);
        // A robot too large for the room finds no start.
        assert!(corner_starts(&all, &common, 3.0, [4.0, 4.0], 1).is_err());
    }

    #[test]
    fn tables_hold_every_map_and_pair_and_do_not_depend_on_the_threads() {
        let dir = TempDir::new("lab-volume-run");
        write_tiny_maps(&dir.0);
        std::fs::write(dir.0.join("build.json"), r#"{"scans": 3}"#).unwrap();
        let rows = rows_of(&config(2, 1), &dir.0);
        let folder = dir.0.file_name().unwrap().to_str().unwrap();
        assert!(rows.iter().all(|r| r["lab_maps"] == folder));
        // Contents: the tiny maps (2 planar patches; hybrid adds one triangle; trimesh holds
        // the room as 4 triangles in 2 mesh patches; pc the sampled points).
        let contents = |kind: MapKind, metric: &str| {
            value(&rows, &format!("lab-volume/contents/{kind}"), metric)
        };
        assert_eq!(contents(MapKind::Planes, "planar_patches"), 2.0);
        assert_eq!(contents(MapKind::Hybrid, "trimesh_patches"), 1.0);
        assert_eq!(
            contents(MapKind::Hybrid, "triangles"),
            contents(MapKind::Planes, "triangles") + 1.0
        );
        assert_eq!(contents(MapKind::Trimesh, "triangles"), 4.0);
        assert!(
            contents(MapKind::Pc, "points") > 1000.0
                && contents(MapKind::Pc, "planar_patches") == 0.0
        );
        assert_eq!(contents(MapKind::Pc, "point_clouds"), 3.0, "from build.json");
        for kind in MapKind::ALL {
            let file = std::fs::metadata(lab_maps::map_path(&dir.0, kind)).unwrap().len();
            assert_eq!(contents(kind, "file_bytes"), file as f64);
            assert!(contents(kind, "memory_bytes") > 0.0);
        }
        // Volumes and the congruence entries of both planners.
        let cell =
            rows.iter().find(|r| r["metric"] == "volume").unwrap()["cell_size_m"].as_f64().unwrap();
        for planner in PLANNERS {
            for row in MapKind::ALL {
                let case = format!("lab-volume/{planner}/{row}");
                let volume = value(&rows, &case, "volume");
                let voxels = value(&rows, &case, "voxels");
                assert!(voxels > 0.0, "{case}");
                assert!((volume - voxels * cell.powi(3)).abs() < 1e-9 * volume, "{case}");
                for col in MapKind::ALL {
                    let pair = format!("{case}/{col}");
                    let has = rows.iter().any(|r| r["case"] == pair);
                    assert_eq!(has, row != col, "{pair}");
                    if row != col {
                        let p = value(&rows, &pair, "not_in");
                        assert!((0.0..=100.0).contains(&p), "{pair}: {p}");
                    }
                }
            }
        }
        let rrt = rows.iter().find(|r| r["case"] == "lab-volume/rrt/planes").unwrap();
        assert_eq!((rrt["runs"].as_u64(), rrt["k"].as_u64()), (Some(8), Some(40)), "4 × 2");
        let prm = rows.iter().find(|r| r["case"] == "lab-volume/prm/planes").unwrap();
        assert_eq!((prm["runs"].as_u64(), prm["k"].as_u64()), (Some(2), Some(30)));
        assert_eq!((rrt["step"].as_f64(), prm["neighbours"].as_u64()), (Some(STEP), Some(6)));
        assert!(prm.get("step").is_none(), "the thesis's PRM has no step");
        assert_eq!((rrt["cells"].as_u64(), rrt["table"].as_str()), (Some(32), Some("6.2")));
        // Two threads give the same grids.
        let again = rows_of(&config(2, 2), &dir.0);
        let values = |rows: &[Value]| -> HashMap<String, String> {
            rows.iter()
                .filter(|r| r["metric"] == "voxels" || r["metric"] == "not_in")
                .map(|r| (format!("{} {}", r["case"], r["metric"]), r["value"].to_string()))
                .collect()
        };
        assert_eq!(values(&rows), values(&again));
        // More seeds explore at least as much.
        let more = rows_of(&config(3, 2), &dir.0);
        for kind in MapKind::ALL {
            let case = format!("lab-volume/rrt/{kind}");
            assert!(value(&more, &case, "voxels") >= value(&rows, &case, "voxels"), "{case}");
        }
    }

    #[test]
    fn missing_maps_and_bad_numbers_are_errors() {
        let dir = TempDir::new("lab-volume-bad");
        let mut sink = |_: Value| Ok(());
        let e = run_with(&config(1, 1), &dir.0, [4.0, 4.0], &mut sink).unwrap_err();
        assert!(format!("{e:#}").contains("planes.pmap"), "{e:#}");
        write_tiny_maps(&dir.0);
        let bad = VolumeConfig { cells: 0, ..config(1, 1) };
        assert!(run_with(&bad, &dir.0, [4.0, 4.0], &mut sink).is_err());
        // A room whose corners lie outside the maps: no start there.
        let e = run_with(&config(1, 1), &dir.0, [40.0, 40.0], &mut sink).unwrap_err();
        assert!(format!("{e:#}").contains("no free start"), "{e:#}");
        assert_eq!(scans_of_build(&dir.0), None);
    }
}
