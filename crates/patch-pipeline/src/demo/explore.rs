//! Exploration runs on every map, shared by `patchnav demo` and `patchnav run`: RRTs grown
//! without a goal and timed against iterations (Fig 6.4, thesis Algorithm 13 as run for §6.1),
//! and the space the roadmaps explored, rasterised into one voxel grid covering all maps and
//! compared (Table 6.2 for the RRT, Table 6.4 for the PRM, a horizontal slice as Fig 6.1).
//!
//! One call does both from the same runs when both are asked for (the demo's way: the timed
//! RRTs fill the grid), or either alone.

use crate::Progress;
use crate::experiment::lab::{CheckpointTimer, checkpoints, explored};
use crate::results::{TimingCurve, VolumeSection};
use anyhow::{Context, Result, bail};
use patch_core::{Point3, Real};
use patch_map::AnyMap;
use pointcloud::Aabb;
use roadmap::metrics::quantile;
use roadmap::volume::{CongruenceTable, VoxelGrid};
use roadmap::{
    MaxIterations, Planner, PlannerKind, PlannerStatus, PlanningSpace, Prm, PrmConfig, Problem,
    Rrt, RrtConfig,
};

/// Most maps one explored-volume comparison holds: the slice picture keeps one bit per map in
/// a byte.
pub const MAX_VOLUME_MAPS: usize = 8;

/// The planners whose roadmaps are grown without a goal: thesis Algorithm 13
/// ([`RrtConfig::thesis`]; Table 6.2, Fig 6.4) and Algorithm 14 ([`PrmConfig::thesis`]: six
/// neighbours, samples unchecked; Table 6.4).
pub const EXPLORE_PLANNERS: [PlannerKind; 2] = [PlannerKind::Rrt, PlannerKind::Prm];

/// The planner `kind` of [`EXPLORE_PLANNERS`] in the thesis's configuration.
fn explorer<'m>(
    kind: PlannerKind,
    map: &'m AnyMap,
    space: PlanningSpace,
    seed: u64,
) -> Result<Box<dyn Planner + 'm>> {
    Ok(match kind {
        PlannerKind::Rrt => Box::new(Rrt::new(map, space, RrtConfig::thesis(), seed)),
        PlannerKind::Prm => Box::new(Prm::new(map, space, PrmConfig::thesis(), seed)),
        other => bail!("an exploration grows the thesis's rrt or prm, not {other}"),
    })
}

/// One map to explore, with its name in the results (the map type, or type and backend).
pub struct Target<'a> {
    /// Name in the timing curves and the volume table.
    pub name: String,
    /// The map.
    pub map: &'a AnyMap,
}

/// What to grow on every map: one run per start and seed, each to `iterations`.
pub struct Exploration<'a> {
    /// The planner, one of [`EXPLORE_PLANNERS`].
    pub planner: PlannerKind,
    /// Iterations of every run (K).
    pub iterations: u64,
    /// Starts; the slice lies at the first one's height.
    pub starts: &'a [Point3],
    /// Seeds, each run from every start.
    pub seeds: &'a [u64],
    /// Robot radius, metres.
    pub radius: Real,
    /// Longest RRT edge, metres.
    pub step: Real,
    /// `Some(n)`: time every run at about `n` checkpoints ([`checkpoints`]) for the Fig 6.4
    /// curves.
    pub checkpoints: Option<u64>,
    /// `Some(n)`: rasterise every run's explored space into `n`³ voxels covering all maps.
    pub cells: Option<u32>,
}

/// Grows `e.planner` from every start with every seed on every target, each map sampled in
/// its own box (thesis L6460): per map the timing curve (median and quartiles at each
/// checkpoint, milliseconds) if `e.checkpoints` is set, and the explored-volume comparison if
/// `e.cells` is set.
///
/// # Errors
/// No target, start or seed; a start not free on a map; a run that stopped before its last
/// checkpoint; a bad grid (see [`VoxelGrid::covering`]); more than [`MAX_VOLUME_MAPS`] maps
/// with a grid.
pub fn explore(
    targets: &[Target<'_>],
    e: &Exploration<'_>,
    progress: &dyn Progress,
) -> Result<(Vec<TimingCurve>, Option<VolumeSection>)> {
    if targets.is_empty() || e.starts.is_empty() || e.seeds.is_empty() || e.iterations == 0 {
        bail!("an exploration needs maps, starts, seeds and iterations");
    }
    if e.cells.is_some() && targets.len() > MAX_VOLUME_MAPS {
        bail!(
            "an explored-volume comparison holds at most {MAX_VOLUME_MAPS} maps, not {}",
            targets.len()
        );
    }
    let cps = e.checkpoints.map(|n| checkpoints(e.iterations, n));
    let bounds: Vec<Aabb> = targets.iter().map(|t| t.map.bounds()).collect();
    let empty = e.cells.map(|n| VoxelGrid::covering(bounds.iter().copied(), n)).transpose()?;
    let label = if cps.is_some() { "rrt timing" } else { "explored volume" };
    let runs_per_map = (e.starts.len() * e.seeds.len()) as u64;
    let bar = progress.bar(targets.len() as u64 * runs_per_map, label);
    let mut curves = Vec::new();
    let mut grids = Vec::new();
    for (t, bounds) in targets.iter().zip(&bounds) {
        let space = PlanningSpace::new(*bounds, e.radius, e.step)
            .with_context(|| format!("the {} map's planning space", t.name))?;
        let mut grid = empty.as_ref().map(VoxelGrid::empty_like);
        let mut timed: Vec<Vec<f64>> = Vec::new();
        for &start in e.starts {
            for &seed in e.seeds {
                let mut run = explorer(e.planner, t.map, space, seed)?;
                let problem = Problem { start, goals: Vec::new() };
                let status = match &cps {
                    Some(cps) => {
                        let mut timer = CheckpointTimer::new(cps.clone());
                        let status = run.solve(&problem, &mut timer);
                        if status != PlannerStatus::InvalidStart && timer.seconds.len() != cps.len()
                        {
                            bail!("a {} on the {} map stopped early", run.name(), t.name);
                        }
                        timed.push(timer.seconds);
                        status
                    }
                    None => run.solve(&problem, &mut MaxIterations(e.iterations)),
                };
                if status == PlannerStatus::InvalidStart {
                    bail!(
                        "the start ({}, {}, {}) is not free on the {} map",
                        start.x,
                        start.y,
                        start.z,
                        t.name
                    );
                }
                if let Some(grid) = grid.as_mut() {
                    grid.add_roadmap(&explored(run.roadmap(), t.map, e.radius)?, e.radius)?;
                }
                bar.inc(1);
            }
        }
        if let Some(cps) = &cps {
            curves.push(curve(&t.name, cps, &timed));
        }
        grids.extend(grid);
    }
    bar.finish_and_clear();
    let volume = match &empty {
        Some(empty) => {
            let all = bounds.iter().fold(Aabb::EMPTY, |a, b| a.union(b));
            Some(volume_section(targets, &grids, empty, &all, e)?)
        }
        None => None,
    };
    Ok((curves, volume))
}

/// The Fig 6.4 curve of one map: median and quartiles over `runs` (seconds at each
/// checkpoint) in milliseconds.
fn curve(name: &str, cps: &[u64], runs: &[Vec<f64>]) -> TimingCurve {
    let q = |c: usize, p: f64| {
        let v: Vec<f64> = runs.iter().map(|r| r[c]).collect();
        quantile(&v, p).unwrap_or(f64::NAN) * 1e3
    };
    TimingCurve {
        map: name.to_owned(),
        iterations: cps.to_vec(),
        median_ms: (0..cps.len()).map(|c| q(c, 0.5)).collect(),
        q1_ms: (0..cps.len()).map(|c| q(c, 0.25)).collect(),
        q3_ms: (0..cps.len()).map(|c| q(c, 0.75)).collect(),
    }
}

/// The congruence table of the maps' grids (Table 6.2 layout) and the layer of cells holding
/// the first start's height over the maps' box `all` (Fig 6.1).
fn volume_section(
    targets: &[Target<'_>],
    grids: &[VoxelGrid],
    empty: &VoxelGrid,
    all: &Aabb,
    e: &Exploration<'_>,
) -> Result<VolumeSection> {
    let z = e.starts[0].z;
    let names: Vec<&str> = targets.iter().map(|t| t.name.as_str()).collect();
    let table = CongruenceTable::new(names.iter().copied().zip(grids))?;
    let n = names.len();
    let volumes_m3: Vec<f64> = (0..n).map(|i| table.volume(i)).collect();
    let table: Vec<Vec<Option<f64>>> =
        (0..n).map(|i| (0..n).map(|j| table.percent_not_in(i, j)).collect()).collect();
    let (min, cell, cells) = (empty.min(), empty.cell_size(), empty.cells_per_axis());
    let k = (((z - min.z) / cell).floor().max(0.0) as u32).min(cells - 1);
    let span = |lo: f64, hi: f64| (((hi - lo) / cell).ceil() as u32).clamp(1, cells);
    let (nx, ny) = (span(min.x, all.max.x), span(min.y, all.max.y));
    let mut bits = Vec::with_capacity((nx * ny) as usize);
    for j in 0..ny {
        for i in 0..nx {
            let b = grids
                .iter()
                .enumerate()
                .fold(0u8, |b, (g, grid)| b | (u8::from(grid.contains(i, j, k)) << g));
            bits.push(b);
        }
    }
    Ok(VolumeSection {
        planner: e.planner.name().to_owned(),
        runs: e.starts.len() * e.seeds.len(),
        iterations: e.iterations,
        cell,
        maps: names.iter().map(|s| (*s).to_owned()).collect(),
        volumes_m3,
        table,
        slice_z: empty.cell_center(0, 0, k).z,
        slice_origin: [min.x, min.y],
        slice_size: [nx, ny],
        slice_bits: bits,
    })
}
