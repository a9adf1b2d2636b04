//! Thesis §6.1 on the simulated lab (Fig 6.4, Tables 6.1, 6.2 and 6.4).
//!
//! Both experiments build the thesis's four map types of the `lab` scene from simulated ALRF
//! scans ([`crate::scene_map`]; `--source scans`, the default, as the thesis built its maps:
//! `planes` = planar patches extracted and merged across scans, `hybrid` = planes + trimesh
//! patches grown on each scan's remainder, `trimesh` = the whole scans meshed by trimesh
//! growing, `pc` = the raw scans; `--source scene` takes the planes, hybrid and trimesh maps
//! from the scene's exact geometry instead), print what each holds beside the thesis's
//! Table 6.1, and grow
//! RRTs (thesis Algorithm 13 as run for §6.1: uniform samples in the box of the map, no goal)
//! from free points near the four room corners.
//!
//! * `lab-timing` (Fig 6.4): one run per start × seed, timed cumulatively at checkpoints
//!   (spec §7.13: with a fixed seed a run is prefix-consistent, so the time at K = 500 of a
//!   run to 1000 is the time of a run to 500); writes `lab-timing.csv` and `lab-timing.svg`
//!   and prints median times and the ratios to the planes map beside the thesis's claims.
//! * `lab-volume` (Tables 6.2, 6.4): the union of all RRTs (starts × seeds) and of all PRMs
//!   (seeds) per map type, rasterised into one voxel grid covering every map's box, and the
//!   congruence tables beside the thesis's.
//!
//! # Choices the thesis leaves open
//! * Radius and step for the Lab are not given (spec §5.2): `--radius 0.3`, `--step 1.0` m.
//! * Starts: the thesis's "room corners"; here the first point free on every map (a sphere of
//!   the radius) on a small spiral from 0.6 m inside each corner, at 1.0 m height. With the
//!   default scans a mixed-pixel point floats 0.42 m from the west wall near the north-west
//!   corner, so that start moves to (1.6, 7.0, 1.0) (the raw pc map keeps such points, as the
//!   thesis's raw clouds did).
//! * Each map samples in its own box (thesis L6460: the box of all patches; for pc, of all
//!   points, which sensor noise makes a few centimetres larger); the volume grid covers all.
//! * The pc map is a [`PointCloudMap`](patch_map::PointCloudMap) checked by Algorithm 10
//!   (spec §7.12); the patch maps use `--backend` (default `trimesh`, a parry BVH, the role of
//!   the thesis's Bullet). The backend decides how much the trimesh map's triangle count
//!   costs: one BVH over all triangles (`trimesh`, `rapier`) hides most of it, a per-patch
//!   broad phase with a linear narrow phase (`bbox6d`) pays for every triangle of each
//!   candidate patch.
//! * The trimesh map's resolution (`--mesh-edge`, default 0.1 m: 312,144 triangles in 1078
//!   patches of ≤ 324) is coarser than the thesis's scan-grid meshes (5.6 M triangles); 0.05 m
//!   gives 1.2 M.
//! * PRM: six neighbours, no edge-length limit (`PrmConfig::thesis`), started from the first
//!   corner; the thesis's PRM seeds and K for the volume are not given (spec §7.11).
//!
//! # Thesis-sized runs
//! `patchnav experiment lab-timing --max-iterations 10000` (4 × 24 runs per map, as Fig 6.4's
//! second range) and `patchnav experiment lab-volume --seeds 120 --max-iterations 10000
//! --prm-seeds 120 --cells 1024` (480 RRTs per map, K = 10,000, the thesis's 1024³ grid; spec
//! §5.2). The thesis's 29 scans: `--scans 29`. These take hours, not minutes.

use crate::Progress;
use crate::scene_map::{
    BuiltMap, MapKind, MapSource, PcCleaning, ScanSetup, SceneSurfaces, Tessellation, build_map,
};
use anyhow::{Context, Result, bail};
use evaluation::thesis;
use patch_core::{CapsuleStep, Point3, Real, UnspecificStepIntersector as _};
use patch_extract::denoise::BeamDenoiseConfig;
use patch_extract::{MixedPixelConfig, MixedPixelFix};
use patch_map::{AnyMap, Backend};
use pointcloud::Aabb;
use roadmap::metrics::quantile;
use roadmap::volume::{CongruenceTable, VoxelGrid};
use roadmap::{
    MaxIterations, Planner as _, PlannerStatus, PlanningSpace, Prm, PrmConfig, Problem, Roadmap,
    Rrt, RrtConfig, Termination,
};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

/// How the lab and its maps are made (shared by both experiments). [`Default`] is the
/// command line's default.
#[derive(Clone, Debug, PartialEq)]
pub struct LabSetup {
    /// Seed of the lab's furniture (scene-sim's `lab`).
    pub scene_seed: u64,
    /// Simulated ALRF scans in the pc map (the thesis's Lab has 29).
    pub scans: usize,
    /// Angular step of the simulated ALRF in degrees (default: the S300's 0.5°).
    pub scan_step_deg: Option<Real>,
    /// Height of the scanner above the floor, metres.
    pub scan_height: Real,
    /// Longest edge when tessellating curved surfaces (hybrid and trimesh maps), metres.
    pub curved_edge: Real,
    /// Longest triangle edge of the trimesh map, metres.
    pub mesh_edge: Real,
    /// Most triangles per trimesh patch of the trimesh map (the thesis's average: 324).
    pub max_patch_triangles: usize,
    /// Where the planes, hybrid and trimesh maps come from: the scene's exact geometry, or
    /// patch extraction from the simulated scans (as the thesis built its maps).
    pub source: MapSource,
    /// Backend of the planes, hybrid and trimesh maps (the pc map is always a point-cloud map).
    pub backend: Backend,
    /// The map types to run, comma-separated.
    pub maps: Vec<MapKind>,
    /// Robot radius (the capsule of every step), metres (not given in the thesis for the Lab).
    pub radius: Real,
    /// Longest RRT edge, metres (not given in the thesis for the Lab).
    pub step: Real,
    /// Starts near the room corners (1–4).
    pub starts: u64,
    /// Iterations of every run (K).
    pub max_iterations: u64,
    /// Clean the pc map's scans of mixed pixels first (`snap` onto their foreground, or
    /// `remove`); without it the pc map is the raw scans, as the thesis's.
    pub pc_mixed_pixels: Option<MixedPixelFix>,
    /// Denoise the pc map's scans along their beams (after --pc-mixed-pixels).
    pub pc_denoise: bool,
    /// Sample every map in the box common to all maps (their intersection) instead of each
    /// map's own box (the thesis's choice, L6460; the pc map's box is larger by the sensor
    /// noise).
    pub common_box: bool,
}

/// The lab-timing experiment's settings.
#[derive(Clone, Debug, PartialEq)]
pub struct LabTimingSetup {
    /// The lab and its maps.
    pub lab: LabSetup,
    /// RRT seeds per start (seeds 1..=N).
    pub seeds: u64,
    /// Checkpoints per run: the time is recorded every K/N iterations (and at 100, 500, 1000).
    pub checkpoints: u64,
    /// Directory for `lab-timing.csv` and `lab-timing.svg`.
    pub out: Option<PathBuf>,
}

/// The lab-volume experiment's settings.
#[derive(Clone, Debug, PartialEq)]
pub struct LabVolumeSetup {
    /// The lab and its maps.
    pub lab: LabSetup,
    /// RRT seeds per start (the thesis: 120, so 480 RRTs per map).
    pub seeds: u64,
    /// PRM seeds (the thesis does not say; spec §7.11 suggests 120).
    pub prm_seeds: u64,
    /// PRM iterations (default: --max-iterations).
    pub prm_iterations: Option<u64>,
    /// Voxels per axis of the common grid (the thesis: 1024 cells of 38.684 mm; 320 gives
    /// about that cell size on the lab).
    pub cells: u32,
}

impl Default for LabSetup {
    fn default() -> LabSetup {
        LabSetup {
            scene_seed: 0,
            scans: 8,
            scan_step_deg: None,
            scan_height: 0.5,
            curved_edge: 0.1,
            mesh_edge: 0.1,
            max_patch_triangles: 324,
            source: MapSource::Scans,
            backend: Backend::Trimesh,
            maps: MapKind::ALL.to_vec(),
            radius: 0.3,
            step: 1.0,
            starts: 4,
            max_iterations: 1000,
            pc_mixed_pixels: None,
            pc_denoise: false,
            common_box: false,
        }
    }
}

impl Default for LabTimingSetup {
    fn default() -> LabTimingSetup {
        LabTimingSetup { lab: LabSetup::default(), seeds: 24, checkpoints: 20, out: None }
    }
}

impl Default for LabVolumeSetup {
    fn default() -> LabVolumeSetup {
        LabVolumeSetup {
            lab: LabSetup::default(),
            seeds: 24,
            prm_seeds: 24,
            prm_iterations: None,
            cells: 320,
        }
    }
}

/// The thesis's timing claims for Fig 6.4 (L6784–6818).
const THESIS_FIG_6_4: &str = "thesis Fig 6.4 (Lab, i7 920, Bullet / Alg. 10): at K = 500 \
     trimesh and pc take \"well over 4 s\", planes and hybrid \"< 0.4 s\"; trimesh and pc are \
     \"more than an order of magnitude slower\"; trimesh is faster than pc at low K, pc faster \
     at high K; time grows sub-linearly in K";

/// The lab, its maps and the starts.
struct Lab {
    maps: Vec<BuiltMap>,
    starts: Vec<Point3>,
    build_seconds: Vec<f64>,
}

/// The box common to all of `boxes` (their intersection; a box that misses another shrinks
/// to a flat or point box at the larger min corner, so it stays well formed); the empty box
/// for none.
pub fn common_box(boxes: impl IntoIterator<Item = Aabb>) -> Aabb {
    let mut boxes = boxes.into_iter();
    let Some(first) = boxes.next() else { return Aabb::EMPTY };
    boxes.fold(first, |a, b| {
        let (min, max) = (a.min.sup(&b.min), a.max.inf(&b.max));
        Aabb::new(min, max.sup(&min))
    })
}

/// The box common to the maps' boxes ([`common_box`]).
pub fn common_box_of(maps: &[BuiltMap]) -> Aabb {
    common_box(maps.iter().map(|m| m.map.bounds()))
}

impl Lab {
    fn space(&self, map: &BuiltMap, args: &LabSetup) -> Result<PlanningSpace> {
        let bounds = if args.common_box { common_box_of(&self.maps) } else { map.map.bounds() };
        PlanningSpace::new(bounds, args.radius, args.step)
            .context("--radius and --step must be positive numbers of metres")
    }
}

fn build_lab(args: &LabSetup, progress: &dyn Progress) -> Result<Lab> {
    if args.maps.is_empty() {
        bail!("--maps names no map type");
    }
    let mut kinds = args.maps.clone();
    kinds.sort();
    kinds.dedup();
    let scene = scene_sim::lab(args.scene_seed).context("building the lab scene")?;
    let t = Tessellation {
        curved_edge: args.curved_edge,
        mesh_edge: args.mesh_edge,
        max_patch_triangles: args.max_patch_triangles,
        ..Tessellation::lab()
    };
    let scans = ScanSetup {
        scans: args.scans,
        height: args.scan_height,
        step_deg: args.scan_step_deg,
        seed: args.scene_seed,
        noise: 1.0,
    };
    let surfaces = SceneSurfaces::of(&scene, &t)?;
    let mut maps = Vec::new();
    let mut build_seconds = Vec::new();
    for kind in kinds {
        let spinner = progress.spinner(&format!("building the {kind} map"));
        let t0 = Instant::now();
        let pc = PcCleaning {
            mixed_pixels: args.pc_mixed_pixels.map(|fix| (MixedPixelConfig::alrf(), fix)),
            denoise: args.pc_denoise.then(BeamDenoiseConfig::alrf),
            carve: None,
        };
        let map = build_map(&scene, &surfaces, kind, args.backend, &t, &scans, args.source, &pc)
            .with_context(|| format!("building the {kind} map"))?;
        build_seconds.push(t0.elapsed().as_secs_f64());
        spinner.finish_and_clear();
        maps.push(map);
    }
    let on: Vec<&AnyMap> = maps.iter().map(|m| &m.map).collect();
    let starts =
        corner_starts(&on, &common_box_of(&maps), args.radius, LAB_ROOM, args.starts as usize)?;
    Ok(Lab { maps, starts, build_seconds })
}

/// The lab's floor, metres: the room spans `(0, 0)`–`LAB_ROOM` ([`scene_sim::lab_layout::ROOM`]).
pub const LAB_ROOM: [Real; 2] = [scene_sim::lab_layout::ROOM[0], scene_sim::lab_layout::ROOM[1]];

/// The first `n` (1–4) RRT starts: for each room corner in the order south-west, south-east,
/// north-east, north-west (the room spans `(0, 0)`–`room`), the first point free on every map
/// (a sphere of `radius`) and inside `within` on a small spiral from 0.6 m inside the corner
/// ([`near_corner`]), at 1.0 m height. The rule of the lab experiments, the demo and the
/// benchmark matrix's lab scenes.
///
/// # Errors
/// No free point near a corner.
pub fn corner_starts(
    maps: &[&AnyMap],
    within: &Aabb,
    radius: Real,
    room: [Real; 2],
    n: usize,
) -> Result<Vec<Point3>> {
    let [lx, ly] = room;
    let corners =
        [(0.0, 0.0, 1.0, 1.0), (lx, 0.0, -1.0, 1.0), (lx, ly, -1.0, -1.0), (0.0, ly, 1.0, -1.0)];
    let free = |p: &Point3| {
        within.contains(p)
            && maps
                .iter()
                .all(|m| CapsuleStep::sphere(*p, radius).is_ok_and(|s| m.is_step_free(&s)))
    };
    corners
        .iter()
        .take(n)
        .map(|&(cx, cy, sx, sy)| {
            near_corner(Point3::new(cx, cy, 1.0), [sx, sy], free)
                .with_context(|| format!("no free start near the room corner ({cx}, {cy})"))
        })
        .collect()
}

/// The first point `free` accepts on a small spiral from 0.6 m inside a room corner at
/// `corner` (its height kept), stepping 0.2 m into the room along `inwards` (±1 per axis),
/// eight rings.
pub fn near_corner(
    corner: Point3,
    inwards: [Real; 2],
    free: impl Fn(&Point3) -> bool,
) -> Option<Point3> {
    (0..8)
        .flat_map(|ring| {
            let d = 0.6 + 0.2 * Real::from(ring);
            (0..=ring).flat_map(move |k| {
                let e = 0.6 + 0.2 * Real::from(k);
                [(d, e), (e, d)]
            })
        })
        .map(|(dx, dy)| {
            Point3::new(corner.x + inwards[0] * dx, corner.y + inwards[1] * dy, corner.z)
        })
        .find(|p| free(p))
}

/// Prints our Table 6.1 analogue beside the thesis's.
fn table_6_1(lab: &Lab, args: &LabSetup) -> Result<String> {
    let mut out = String::new();
    writeln!(
        out,
        "Table 6.1 analogue: lab scene (seed {}), patch maps from {} in the `{}` backend, \
         {} simulated ALRF scans",
        args.scene_seed,
        match args.source {
            MapSource::Scans => "patch extraction from the scans",
            MapSource::Scene => "the scene's exact geometry",
        },
        args.backend.name(),
        args.scans
    )?;
    writeln!(
        out,
        "| Map | planar patches | trimesh patches | point clouds | triangles | points | memory bytes | built in [s] |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|---|---|")?;
    for (m, s) in lab.maps.iter().zip(&lab.build_seconds) {
        writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} | {} | {s:.2} |",
            m.kind,
            m.planar_patches,
            m.trimesh_patches,
            m.point_clouds,
            m.triangles,
            m.points,
            m.memory_bytes()
        )?;
    }
    writeln!(out, "thesis Table 6.1 (Lab, 29 ALRF scans, patch extraction):")?;
    writeln!(
        out,
        "| Map | file size | planar patches | trimesh patches | point clouds | triangles |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|")?;
    for r in thesis::TABLE_6_1 {
        writeln!(
            out,
            "| {} | {:.1} MB | {} | {} | {} | {} |",
            r.map,
            r.file_size_mb,
            thesis_count(r.planar_patches),
            thesis_count(r.trimesh_patches),
            thesis_count(r.point_clouds),
            thesis_count(r.triangles)
        )?;
    }
    let find = |k: MapKind| lab.maps.iter().find(|m| m.kind == k).map(BuiltMap::memory_bytes);
    if let (Some(planes), Some(pc)) = (find(MapKind::Planes), find(MapKind::Pc)) {
        writeln!(
            out,
            "pc / planes memory: {:.1}× (thesis: \"18× smaller\" = 54.0 MB / 3.0 MB files)",
            pc as f64 / planes.max(1) as f64
        )?;
    }
    let starts: Vec<String> =
        lab.starts.iter().map(|p| format!("({:.1}, {:.1}, {:.1})", p.x, p.y, p.z)).collect();
    writeln!(out, "starts: {}", starts.join(", "))?;
    let b = common_box_of(&lab.maps);
    // Rounding leaves −1e-16 where the walls are at 0: print it as 0.
    let c = |x: Real| if x.abs() < 5e-3 { 0.0 } else { x };
    writeln!(
        out,
        "sampling box: {} (common box ({:.2}, {:.2}, {:.2}) .. ({:.2}, {:.2}, {:.2}) m)",
        if args.common_box { "the box common to all maps" } else { "each map's own (thesis)" },
        c(b.min.x),
        c(b.min.y),
        c(b.min.z),
        c(b.max.x),
        c(b.max.y),
        c(b.max.z)
    )?;
    Ok(out)
}

/// A [`Termination`] that records the time since `solve` began whenever the iteration count
/// reaches the next checkpoint, and stops at the last one.
pub struct CheckpointTimer {
    checkpoints: Vec<u64>,
    /// Seconds since the start at each checkpoint reached so far.
    pub seconds: Vec<f64>,
    /// Roadmap vertices at each checkpoint (for the time per vertex).
    pub vertices: Vec<usize>,
}

impl CheckpointTimer {
    /// A timer for these iteration counts (ascending).
    pub fn new(checkpoints: Vec<u64>) -> CheckpointTimer {
        CheckpointTimer {
            seconds: Vec::with_capacity(checkpoints.len()),
            vertices: Vec::with_capacity(checkpoints.len()),
            checkpoints,
        }
    }
}

impl Termination for CheckpointTimer {
    fn should_stop(&mut self, progress: &roadmap::Progress) -> bool {
        while let Some(&next) = self.checkpoints.get(self.seconds.len()) {
            if progress.iterations < next {
                break;
            }
            self.seconds.push(progress.elapsed().as_secs_f64());
            self.vertices.push(progress.vertices);
        }
        self.seconds.len() == self.checkpoints.len()
    }
}

/// The checkpoints of a run to `k`: every `k / n` iterations (rounded up), plus 100, 500 and
/// 1000 when they are below `k`.
pub fn checkpoints(k: u64, n: u64) -> Vec<u64> {
    let step = k.div_ceil(n.max(1)).max(1);
    let mut c: Vec<u64> = (1..).map(|i| i * step).take_while(|&x| x < k).collect();
    c.extend([100, 500, 1000].into_iter().filter(|&x| x < k));
    c.push(k);
    c.sort_unstable();
    c.dedup();
    c
}

/// One timed run.
struct TimedRun {
    map: MapKind,
    start: usize,
    seed: u64,
    /// Seconds at each checkpoint.
    seconds: Vec<f64>,
    /// Roadmap vertices at each checkpoint.
    vertices: Vec<usize>,
}

/// (lower quartile, median, upper quartile) of the runs of `map` at checkpoint `c`.
fn quartiles(runs: &[TimedRun], map: MapKind, c: usize) -> (f64, f64, f64) {
    let v: Vec<f64> = runs.iter().filter(|r| r.map == map).map(|r| r.seconds[c]).collect();
    let [q1, m, q3] = evaluation::stats::quartiles(&v).unwrap_or([f64::NAN; 3]);
    (q1, m, q3)
}

/// The lab-timing experiment (Fig 6.4; `patchnav experiment lab-timing`): Table 6.1, the
/// timing table and, with `out`, `lab-timing.csv` and `lab-timing.svg`.
pub fn run_timing(args: &LabTimingSetup, progress: &dyn Progress) -> Result<()> {
    let a = &args.lab;
    if args.seeds == 0 || a.max_iterations == 0 {
        bail!("--seeds and --max-iterations must be at least 1");
    }
    let t0 = Instant::now();
    let lab = build_lab(a, progress)?;
    progress.report(&table_6_1(&lab, a)?);
    let cps = checkpoints(a.max_iterations, args.checkpoints);
    let bar =
        progress.bar(lab.maps.len() as u64 * lab.starts.len() as u64 * args.seeds, "rrt runs");
    let mut runs = Vec::new();
    for map in &lab.maps {
        let space = lab.space(map, a)?;
        for (s, &start) in lab.starts.iter().enumerate() {
            for seed in 1..=args.seeds {
                let mut rrt = Rrt::new(&map.map, space, RrtConfig::thesis(), seed);
                let mut timer = CheckpointTimer::new(cps.clone());
                let status = rrt.solve(&Problem { start, goals: Vec::new() }, &mut timer);
                if status == PlannerStatus::InvalidStart {
                    bail!("start {s} is not free on the {} map", map.kind);
                }
                if timer.seconds.len() != cps.len() {
                    bail!("the {} run (start {s}, seed {seed}) stopped early", map.kind);
                }
                runs.push(TimedRun {
                    map: map.kind,
                    start: s,
                    seed,
                    seconds: timer.seconds,
                    vertices: timer.vertices,
                });
                bar.inc(1);
            }
        }
    }
    bar.finish_and_clear();
    let kinds: Vec<MapKind> = lab.maps.iter().map(|m| m.kind).collect();
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        let csv = dir.join("lab-timing.csv");
        pointcloud::io::write_bytes_atomically(&csv, timing_csv(&runs, &cps))?;
        let svg = dir.join("lab-timing.svg");
        pointcloud::io::write_bytes_atomically(&svg, timing_svg(&runs, &cps, &kinds, a))?;
        progress.say(&format!("wrote {} and {}", csv.display(), svg.display()));
    }
    progress.report(&timing_table(&runs, &cps, &kinds, a, args.seeds * lab.starts.len() as u64)?);
    progress.report(&format!("total wall time {:.1} s", t0.elapsed().as_secs_f64()));
    Ok(())
}

fn timing_csv(runs: &[TimedRun], cps: &[u64]) -> String {
    let mut out = String::from("map,start,seed,iterations,seconds,vertices\n");
    for r in runs {
        for ((k, s), v) in cps.iter().zip(&r.seconds).zip(&r.vertices) {
            let _ = writeln!(out, "{},{},{},{k},{s:.9},{v}", r.map, r.start, r.seed);
        }
    }
    out
}

fn timing_table(
    runs: &[TimedRun],
    cps: &[u64],
    kinds: &[MapKind],
    a: &LabSetup,
    per_map: u64,
) -> Result<String> {
    let mut out = String::new();
    writeln!(
        out,
        "Fig 6.4 analogue: RRT time per run [s], median (lower–upper quartile) of {per_map} runs \
         per map; r = {} m, step = {} m, patch maps in `{}`",
        a.radius,
        a.step,
        a.backend.name()
    )?;
    let mut header = String::from("| K |");
    let mut rule = String::from("|---|");
    for k in kinds {
        write!(header, " {k} |")?;
        rule.push_str("---|");
    }
    let has = |k: MapKind| kinds.contains(&k);
    let ratios: Vec<MapKind> = [MapKind::Hybrid, MapKind::Trimesh, MapKind::Pc]
        .into_iter()
        .filter(|&k| has(k) && has(MapKind::Planes))
        .collect();
    for k in &ratios {
        write!(header, " {k}/planes |")?;
        rule.push_str("---|");
    }
    writeln!(out, "{header}\n{rule}")?;
    let mut rows: Vec<usize> =
        [100, 500, 1000, 10_000].iter().filter_map(|k| cps.iter().position(|c| c == k)).collect();
    rows.push(cps.len() - 1);
    rows.dedup();
    for c in rows {
        let mut line = format!("| {} |", cps[c]);
        for &k in kinds {
            let (q1, m, q3) = quartiles(runs, k, c);
            write!(line, " {} ({}–{}) |", sig(m), sig(q1), sig(q3))?;
        }
        let planes = quartiles(runs, MapKind::Planes, c).1;
        for &k in &ratios {
            write!(line, " {:.2} |", quartiles(runs, k, c).1 / planes)?;
        }
        writeln!(out, "{line}")?;
    }
    // The thesis's other timing figure of merit (§6.2.3, Fig 6.12): time per roadmap vertex.
    let last = cps.len() - 1;
    write!(out, "time per vertex at K = {} [µs], median:", cps[last])?;
    for &k in kinds {
        let v: Vec<f64> = runs
            .iter()
            .filter(|r| r.map == k && r.vertices[last] > 0)
            .map(|r| r.seconds[last] / r.vertices[last] as f64 * 1e6)
            .collect();
        write!(out, " {k} {}", sig(quantile(&v, 0.5).unwrap_or(f64::NAN)))?;
    }
    writeln!(out)?;
    writeln!(out, "{THESIS_FIG_6_4}")?;
    Ok(out)
}

/// `x` with three significant digits (seconds span several orders of magnitude).
fn sig(x: f64) -> String {
    if !(x.is_finite() && x > 0.0) || x >= 100.0 {
        return format!("{x:.1}");
    }
    let decimals = (2 - x.log10().floor() as i32).clamp(0, 12) as usize;
    format!("{x:.decimals$}")
}

/// The colour of a map type's line in the plot.
fn colour(k: MapKind) -> &'static str {
    match k {
        MapKind::Planes => "#1f77b4",
        MapKind::Hybrid => "#2ca02c",
        MapKind::Trimesh => "#d62728",
        MapKind::Pc => "#9467bd",
    }
}

/// Fig 6.4 as SVG: iterations on x, time per run on a log axis, one line per map type with
/// the median and quartile error bars, a legend and axis labels.
fn timing_svg(runs: &[TimedRun], cps: &[u64], kinds: &[MapKind], a: &LabSetup) -> String {
    let (w, h) = (760.0, 500.0);
    let (left, right, top, bottom) = (80.0, 150.0, 40.0, 60.0);
    let (pw, ph) = (w - left - right, h - top - bottom);
    let stats: Vec<Vec<(f64, f64, f64)>> =
        kinds.iter().map(|&k| (0..cps.len()).map(|c| quartiles(runs, k, c)).collect()).collect();
    let positive = stats.iter().flatten().flat_map(|&(a, b, c)| [a, b, c]).filter(|v| *v > 0.0);
    let (lo, hi) = positive.fold((f64::INFINITY, 0.0_f64), |(l, h), v| (l.min(v), h.max(v)));
    let (lo, hi) = if lo.is_finite() { (lo, hi) } else { (1e-6, 1.0) };
    let (e0, e1) =
        (lo.log10().floor() as i32, (hi.log10().ceil() as i32).max(lo.log10().floor() as i32 + 1));
    let k_max = *cps.last().unwrap_or(&1) as f64;
    let x = |k: f64| left + pw * k / k_max;
    let y = |s: f64| {
        let l = s.max(10f64.powi(e0)).log10();
        top + ph * (1.0 - (l - f64::from(e0)) / f64::from(e1 - e0))
    };
    let mut o = String::new();
    let _ = writeln!(
        o,
        r#"<?xml version="1.0" encoding="UTF-8"?>
<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12">
<title>RRT time per run on the lab's map types (thesis Fig 6.4 analogue)</title>
<rect x="0" y="0" width="{w}" height="{h}" fill="white"/>
<rect x="{left}" y="{top}" width="{pw}" height="{ph}" fill="none" stroke="black"/>"#
    );
    let _ = writeln!(
        o,
        r#"<text x="{}" y="20" text-anchor="middle" font-size="14">RRT on the lab: median time per run, quartile bars (r = {} m, step = {} m)</text>"#,
        left + pw / 2.0,
        a.radius,
        a.step
    );
    for e in e0..=e1 {
        let yy = y(10f64.powi(e));
        let _ = writeln!(
            o,
            r##"<line x1="{left}" y1="{yy:.1}" x2="{:.1}" y2="{yy:.1}" stroke="#ddd"/><text x="{:.1}" y="{:.1}" text-anchor="end">1e{e}</text>"##,
            left + pw,
            left - 6.0,
            yy + 4.0
        );
    }
    for i in 0..=5 {
        let k = k_max * f64::from(i) / 5.0;
        let xx = x(k);
        let _ = writeln!(
            o,
            r#"<line x1="{xx:.1}" y1="{:.1}" x2="{xx:.1}" y2="{:.1}" stroke="black"/><text x="{xx:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
            top + ph,
            top + ph + 5.0,
            top + ph + 20.0,
            k.round()
        );
    }
    let _ = writeln!(
        o,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">iterations K</text>"#,
        left + pw / 2.0,
        h - 15.0
    );
    let _ = writeln!(
        o,
        r#"<text x="20" y="{:.1}" text-anchor="middle" transform="rotate(-90 20 {:.1})">time per run [s] (log scale)</text>"#,
        top + ph / 2.0,
        top + ph / 2.0
    );
    for (i, (&k, s)) in kinds.iter().zip(&stats).enumerate() {
        let c = colour(k);
        let points: Vec<String> = cps
            .iter()
            .zip(s)
            .map(|(&it, &(_, m, _))| format!("{:.1},{:.1}", x(it as f64), y(m)))
            .collect();
        let _ = writeln!(
            o,
            r#"<polyline fill="none" stroke="{c}" stroke-width="2" points="{}"/>"#,
            points.join(" ")
        );
        let bars: Vec<String> = cps
            .iter()
            .zip(s)
            .map(|(&it, &(q1, _, q3))| {
                let xx = x(it as f64);
                format!(
                    "M{:.1} {:.1}V{:.1}M{:.1} {:.1}H{:.1}M{:.1} {:.1}H{:.1}",
                    xx,
                    y(q1),
                    y(q3),
                    xx - 3.0,
                    y(q1),
                    xx + 3.0,
                    xx - 3.0,
                    y(q3),
                    xx + 3.0
                )
            })
            .collect();
        let _ = writeln!(o, r#"<path fill="none" stroke="{c}" d="{}"/>"#, bars.concat());
        let ly = top + 20.0 + 20.0 * i as f64;
        let lx = left + pw + 15.0;
        let _ = writeln!(
            o,
            r#"<line x1="{lx}" y1="{ly}" x2="{}" y2="{ly}" stroke="{c}" stroke-width="2"/><text x="{}" y="{}">{k}</text>"#,
            lx + 25.0,
            lx + 32.0,
            ly + 4.0
        );
    }
    o.push_str("</svg>\n");
    o
}

/// The explored part of `roadmap` ([`roadmap::volume::explored_part`]).
pub fn explored(roadmap: &Roadmap, map: &AnyMap, radius: Real) -> Result<Roadmap> {
    Ok(roadmap::volume::explored_part(roadmap, map, radius)?)
}

/// The lab-volume experiment (Tables 6.2, 6.4; `patchnav experiment lab-volume`).
pub fn run_volume(args: &LabVolumeSetup, progress: &dyn Progress) -> Result<()> {
    let a = &args.lab;
    if args.seeds == 0 || args.prm_seeds == 0 || a.max_iterations == 0 {
        bail!("--seeds, --prm-seeds and --max-iterations must be at least 1");
    }
    let prm_k = args.prm_iterations.unwrap_or(a.max_iterations);
    let t0 = Instant::now();
    let lab = build_lab(a, progress)?;
    progress.report(&table_6_1(&lab, a)?);
    let bounds: Vec<Aabb> = lab.maps.iter().map(|m| m.map.bounds()).collect();
    let empty = VoxelGrid::covering(bounds, args.cells)?;
    let runs = lab.maps.len() as u64 * (lab.starts.len() as u64 * args.seeds + args.prm_seeds);
    let bar = progress.bar(runs, "roadmaps");
    let mut rrt_grids = Vec::new();
    let mut prm_grids = Vec::new();
    for map in &lab.maps {
        let space = lab.space(map, a)?;
        let mut grid = empty.empty_like();
        for &start in &lab.starts {
            for seed in 1..=args.seeds {
                let mut rrt = Rrt::new(&map.map, space, RrtConfig::thesis(), seed);
                let problem = Problem { start, goals: Vec::new() };
                let status = rrt.solve(&problem, &mut MaxIterations(a.max_iterations));
                if status == PlannerStatus::InvalidStart {
                    bail!("a start is not free on the {} map", map.kind);
                }
                grid.add_roadmap(&explored(rrt.roadmap(), &map.map, a.radius)?, a.radius)?;
                bar.inc(1);
            }
        }
        rrt_grids.push(grid);
        let mut grid = empty.empty_like();
        for seed in 1..=args.prm_seeds {
            let mut prm = Prm::new(&map.map, space, PrmConfig::thesis(), seed);
            let problem = Problem { start: lab.starts[0], goals: Vec::new() };
            prm.solve(&problem, &mut MaxIterations(prm_k));
            grid.add_roadmap(&explored(prm.roadmap(), &map.map, a.radius)?, a.radius)?;
            bar.inc(1);
        }
        prm_grids.push(grid);
    }
    bar.finish_and_clear();
    let names: Vec<&str> = lab.maps.iter().map(|m| m.kind.name()).collect();
    let rrt = CongruenceTable::new(names.iter().copied().zip(&rrt_grids))?;
    let prm = CongruenceTable::new(names.iter().copied().zip(&prm_grids))?;
    let mut out = String::new();
    writeln!(
        out,
        "grid: {0}³ cells of {1:.3} mm covering every map's box; r = {2} m, step = {3} m",
        empty.cells_per_axis(),
        empty.cell_size() * 1000.0,
        a.radius,
        a.step
    )?;
    writeln!(
        out,
        "\nTable 6.2 analogue: RRT explored volume [m³] and % of the row's volume not in the \
         column's, {} starts × {} seeds, K = {}",
        lab.starts.len(),
        args.seeds,
        a.max_iterations
    )?;
    write!(out, "{rrt}")?;
    writeln!(out, "thesis Table 6.2 (RRT, Lab, 480 RRTs per map, K = 10,000, 1024³ × 38.684 mm):")?;
    write!(out, "{}", thesis::volume_table_markdown(&thesis::TABLE_6_2_RRT))?;
    writeln!(
        out,
        "\nTable 6.4 analogue: PRM explored volume [m³] and % not in, {} seeds, K = {prm_k}",
        args.prm_seeds
    )?;
    write!(out, "{prm}")?;
    writeln!(out, "thesis Table 6.4 (PRM, Lab):")?;
    write!(out, "{}", thesis::volume_table_markdown(&thesis::TABLE_6_4_PRM))?;
    writeln!(
        out,
        "\nThe thesis's volumes are of its own maps' boxes (objects seen through windows \
         inflate them, spec §7.18); compare the percentages, not the volumes."
    )?;
    writeln!(out, "total wall time {:.1} s", t0.elapsed().as_secs_f64())?;
    progress.report(out.trim_end());
    Ok(())
}

/// A count of Table 6.1 as the thesis prints it; "–" for none.
fn thesis_count(n: Option<u32>) -> String {
    n.map_or("–".to_owned(), |n| thesis::count_text(n.into()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::{Duration, Instant};

    #[test]
    fn checkpoints_cover_the_run_and_the_reported_k() {
        assert_eq!(checkpoints(1000, 4), vec![100, 250, 500, 750, 1000]);
        assert_eq!(
            checkpoints(50, 20),
            vec![3, 6, 9, 12, 15, 18, 21, 24, 27, 30, 33, 36, 39, 42, 45, 48, 50]
        );
        assert_eq!(checkpoints(1, 20), vec![1]);
    }

    #[test]
    fn timer_records_each_checkpoint_once_and_stops_at_the_last() {
        let mut t = CheckpointTimer::new(vec![2, 4]);
        let p = |iterations, ms| roadmap::Progress {
            iterations,
            vertices: 1,
            goals_reached: 0,
            goals_total: 0,
            started: Instant::now() - Duration::from_millis(ms),
        };
        assert!(!t.should_stop(&p(0, 0)));
        assert!(!t.should_stop(&p(1, 1)));
        assert!(!t.should_stop(&p(2, 5)));
        assert!(!t.should_stop(&p(3, 6)));
        assert!(t.should_stop(&p(4, 9)));
        // The clock runs on between `started` and the check: a little later, never earlier.
        assert_eq!(t.seconds.len(), 2);
        for (s, want) in t.seconds.iter().zip([0.005, 0.009]) {
            assert!(*s >= want && *s < want + 1.0, "{:?}", t.seconds);
        }
    }

    #[test]
    fn thesis_tables_print_as_the_thesis_prints_them() {
        assert_eq!(thesis_count(Some(5906)), "5906");
        assert_eq!(thesis_count(Some(5_600_612)), "5,600,612");
        assert_eq!(thesis_count(None), "–");
        let rrt = thesis::volume_table_markdown(&thesis::TABLE_6_2_RRT);
        assert!(rrt.starts_with("| Map | Volume [m³] | planes | hybrid | trimesh | pc |"), "{rrt}");
        assert!(rrt.contains("| planes | 9714.015 | – | 0.557 | 1.739 | 0.986 |"), "{rrt}");
        let prm = thesis::volume_table_markdown(&thesis::TABLE_6_4_PRM);
        assert!(prm.contains("| hybrid | 11841.7095 | 0.008 | – | 0.593 | 0.251 |"), "{prm}");
    }

    #[test]
    fn quartiles_interpolate() {
        assert_eq!(sig(0.012345), "0.0123");
        assert_eq!(sig(4.5678), "4.57");
        assert_eq!(sig(0.0), "0.0");
    }
}
