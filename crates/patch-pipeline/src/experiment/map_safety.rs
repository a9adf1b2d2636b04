//! `patchnav experiment map-safety`: is a map built from scans safe to plan on?
//!
//! For each scene (lab, office), sensor noise level and number of scans, the planes, hybrid,
//! trimesh and pc maps are built from simulated ALRF scans as `patchnav map build --source
//! scans` builds them, and each is compared with the scene's exact surfaces (the hybrid map
//! of `--source scene`) over seeded random capsule steps ([`patch_map::compare`]):
//!
//! * **unsafe**: colliding steps the map calls free, over all truly colliding steps;
//! * **overcautious**: free steps the map calls colliding, over all truly free steps.
//!
//! The pc map's unsafe rate is the occlusion floor: surfaces no scan saw (or saw with too
//! few points). A planner view grows RRT and PRM roadmaps on each map and re-checks every
//! edge on the truth: the share of edges that collide, and of paths to the goals that
//! contain a colliding edge. The tuning seed of the extraction is 0; the default step and
//! planner seeds are 1, and the scene seed is a flag.
//!
//! Beside the four maps: `hybrid-carved` and `trimesh-carved`, without the (remainder)
//! triangles another scan saw through; the pc map cleaned five ways (`pc-removed`, `pc-snapped`,
//! `pc-snapped-denoised`: mixed pixels removed or snapped; `pc-carved`,
//! `pc-denoised-carved`: points another scan saw through dropped,
//! [`patch_extract::visibility`]); and `pc-no-phantoms`, `pc-no-phantoms-denoised`, what a
//! perfect mixed-pixel filter would give (the simulator's own phantoms dropped).

use crate::Progress;
use crate::experiment::ByteCount;
use crate::scene_map::{
    MapKind, PcCleaning, ScanSetup, extracted_patches, extracted_patches_with, patch_map,
    pc_points, scan_clouds, scan_clouds_without_phantoms, truth_patches,
};
use anyhow::{Context, Result, bail};
use patch_core::{CapsuleStep, Point3, Real, UnspecificStepIntersector};
use patch_extract::denoise::BeamDenoiseConfig;
use patch_extract::{
    MixedPixelConfig, MixedPixelFix, PipelineConfig, TrimeshGrowConfig, VisibilityConfig,
};
use patch_map::{
    AnyMap, Attribution, Backend, MapComparison, PointCloudMap, StepSampling, compare_maps,
};
use roadmap::{Goal, MaxIterations, PlannerKind, PlanningSpace, Problem, named_planner_on};
use serde::Serialize;
use std::fmt::Write as _;
use std::time::Instant;

/// A mixed pixel more than this many metres off its own surface is a phantom in the
/// `pc-no-phantoms` row (3σ of the S300 model).
const PHANTOM_TOLERANCE: Real = 0.09;

/// The settings (defaults: the command line's) of `patchnav experiment map-safety`.
#[derive(Clone, Debug, PartialEq)]
pub struct MapSafetySetup {
    /// Scenes, comma-separated (`lab`, `office`).
    pub scenes: Vec<String>,
    /// Noise levels as multipliers of the S300 model's σ = 3 cm, comma-separated (0 is
    /// noise-free and without mixed pixels).
    pub noise: Vec<Real>,
    /// Numbers of scans, comma-separated.
    pub scans: Vec<usize>,
    /// The map types, comma-separated.
    pub maps: Vec<MapKind>,
    /// Random capsule steps per map.
    pub samples: usize,
    /// Seed of the random steps and the planners.
    pub seed: u64,
    /// Seed of the scene's furniture, the scan poses and the sensor noise.
    pub scene_seed: u64,
    /// Robot radius, metres.
    pub radius: Real,
    /// Longest random step, metres.
    pub max_length: Real,
    /// Iterations of each RRT and PRM run in the planner view (0: no planner view).
    pub planner_iterations: u64,
    /// Planner runs per planner and map (seeds `seed`, `seed + 1`, ...).
    pub planner_seeds: u64,
    /// Height of the scanner above the floor, metres.
    pub scan_height: Real,
    /// Angular step of the simulated ALRF in degrees (default: the S300's 0.5°).
    pub scan_step_deg: Option<Real>,
    /// Also write the rows as JSON to this file.
    pub json: Option<std::path::PathBuf>,
}

impl Default for MapSafetySetup {
    fn default() -> MapSafetySetup {
        MapSafetySetup {
            scenes: ["lab".to_owned(), "office".to_owned()].to_vec(),
            noise: [0.0, 1.0, 2.0].to_vec(),
            scans: [8usize, 29].to_vec(),
            maps: MapKind::ALL.to_vec(),
            samples: 100_000,
            seed: 1,
            scene_seed: 0,
            radius: 0.3,
            max_length: 1.0,
            planner_iterations: 2000,
            planner_seeds: 2,
            scan_height: 0.5,
            scan_step_deg: None,
            json: None,
        }
    }
}

/// One row of the table: one map of one scene, noise level and scan count.
#[derive(Clone, Debug, Serialize)]
pub struct SafetyRow {
    /// The scene.
    pub scene: String,
    /// Noise multiplier.
    pub noise: Real,
    /// Number of scans.
    pub scans: usize,
    /// The map type.
    pub map: String,
    /// The comparison with the truth.
    pub comparison: MapComparison,
    /// Map file bytes.
    pub file_bytes: u64,
    /// Heap bytes of the map in its backend.
    pub memory_bytes: usize,
    /// Extraction (or, for the pc maps, point gathering and cleaning) time per scan, seconds.
    pub seconds_per_scan: Real,
    /// Loading the whole map into its backend (trimesh for patch maps, the point-cloud
    /// backend for pc maps), seconds.
    pub load_seconds: Real,
    /// Planner view: roadmap edges re-checked on the truth.
    pub edges: u64,
    /// Of those, edges that collide with the truth.
    pub colliding_edges: u64,
    /// Paths to goals found.
    pub paths: u64,
    /// Of those, paths with at least one colliding edge.
    pub colliding_paths: u64,
}

/// A row for `map` of the cell (`scene`, `noise`, `scans`), compared with `truth`; the planner
/// view is left empty.
fn safety_row(
    cell: (&str, Real, usize),
    kind: &str,
    truth: &AnyMap,
    map: &AnyMap,
    sampling: &StepSampling,
    (seconds_per_scan, load_seconds): (Real, Real),
) -> Result<SafetyRow> {
    let mut bytes = ByteCount(0);
    map.save(&mut bytes)?;
    Ok(SafetyRow {
        scene: cell.0.to_owned(),
        noise: cell.1,
        scans: cell.2,
        map: kind.to_owned(),
        comparison: compare_maps(truth, map, sampling, Attribution::None)?,
        file_bytes: bytes.0,
        memory_bytes: map.memory_bytes(),
        seconds_per_scan,
        load_seconds,
        edges: 0,
        colliding_edges: 0,
        paths: 0,
        colliding_paths: 0,
    })
}

/// Runs `patchnav experiment map-safety`.
pub fn run(args: &MapSafetySetup, progress: &dyn Progress) -> Result<()> {
    let rows = safety_rows(args, progress)?;
    print!("{}", safety_table(&rows));
    if let Some(path) = &args.json {
        pointcloud::io::write_bytes_atomically(path, serde_json::to_string_pretty(&rows)?)?;
    }
    Ok(())
}

/// The map `load` builds from what `extract` gives, with the row's times: extraction per scan
/// (of `scans`) and loading, seconds.
fn timed<T>(
    scans: usize,
    extract: impl FnOnce() -> Result<T>,
    load: impl FnOnce(T) -> Result<AnyMap>,
) -> Result<(AnyMap, (Real, Real))> {
    let started = Instant::now();
    let extracted = extract()?;
    let extract_seconds = started.elapsed().as_secs_f64();
    let started = Instant::now();
    let map = load(extracted)?;
    Ok((map, (extract_seconds / scans.max(1) as Real, started.elapsed().as_secs_f64())))
}

/// Every row of the experiment.
pub fn safety_rows(args: &MapSafetySetup, progress: &dyn Progress) -> Result<Vec<SafetyRow>> {
    if args.scenes.is_empty() || args.noise.is_empty() || args.scans.is_empty() {
        bail!("--scenes, --noise and --scans each need at least one value");
    }
    let mut rows = Vec::new();
    for name in &args.scenes {
        if !["lab", "office"].contains(&name.as_str()) {
            bail!("unknown scene `{name}`; map-safety runs on `lab` and `office`");
        }
        let scene = scene_sim::scene_by_name(name, args.scene_seed)
            .with_context(|| format!("building scene `{name}`"))?;
        let truth = patch_map(truth_patches(&scene)?, Backend::BBox6d)?;
        let sampling = StepSampling {
            radius: args.radius,
            max_length: args.max_length,
            samples: args.samples,
            seed: args.seed,
            bounds: truth.bounds(),
        };
        for &noise in &args.noise {
            for &scans in &args.scans {
                let setup = ScanSetup {
                    scans,
                    height: args.scan_height,
                    step_deg: args.scan_step_deg,
                    seed: args.scene_seed,
                    noise,
                };
                let spinner = progress.spinner(&format!("{name} noise {noise} scans {scans}"));
                let clouds = scan_clouds(&scene, &setup)?;
                for &kind in &args.maps {
                    let (map, times) = timed(
                        scans,
                        || {
                            Ok(match extracted_patches(&clouds, kind)? {
                                Some(patches) => (Some(patches), Vec::new()),
                                None => (None, pc_points(&clouds, &PcCleaning::default())?),
                            })
                        },
                        |(patches, points)| match patches {
                            Some(patches) => patch_map(patches, Backend::Trimesh),
                            None => Ok(AnyMap::PointCloud(PointCloudMap::from_points(&points)?)),
                        },
                    )?;
                    let mut row = safety_row(
                        (name, noise, scans),
                        kind.name(),
                        &truth,
                        &map,
                        &sampling,
                        times,
                    )?;
                    if args.planner_iterations > 0 {
                        planner_view(&truth, &map, args, &mut row)?;
                    }
                    progress.say(&format!(
                        "{name} noise {noise} scans {scans} {kind}: unsafe {}, overcautious {}",
                        row.comparison.unsafe_rate(),
                        row.comparison.overcautious_rate()
                    ));
                    rows.push(row);
                }
                // The hybrid and trimesh maps without the triangles another scan saw through.
                for kind in [MapKind::Hybrid, MapKind::Trimesh] {
                    if !args.maps.contains(&kind) {
                        continue;
                    }
                    let carve = Some(VisibilityConfig::alrf());
                    let (map, times) = timed(
                        scans,
                        || {
                            extracted_patches_with(
                                &clouds,
                                kind,
                                PipelineConfig { carve, ..PipelineConfig::alrf() },
                                TrimeshGrowConfig::alrf(),
                                carve,
                            )?
                            .context("patch maps have patches")
                        },
                        |patches| patch_map(patches, Backend::Trimesh),
                    )?;
                    rows.push(safety_row(
                        (name, noise, scans),
                        &format!("{kind}-carved"),
                        &truth,
                        &map,
                        &sampling,
                        times,
                    )?);
                }
                if args.maps.contains(&MapKind::Pc) {
                    // The pc map cleaned five ways, and the one a perfect mixed-pixel filter
                    // would give (the simulator's phantoms dropped), raw and denoised.
                    let mixed = |fix| Some((MixedPixelConfig::alrf(), fix));
                    let (remove, snap) = (MixedPixelFix::Remove, MixedPixelFix::SnapToForeground);
                    let denoise = Some(BeamDenoiseConfig::alrf());
                    let carve = Some(VisibilityConfig::alrf());
                    let clean = scan_clouds_without_phantoms(&scene, &setup, PHANTOM_TOLERANCE)?;
                    let cleanings = [
                        ("pc-removed", &clouds, mixed(remove), None, None),
                        ("pc-snapped", &clouds, mixed(snap), None, None),
                        ("pc-snapped-denoised", &clouds, mixed(snap), denoise, None),
                        ("pc-carved", &clouds, None, None, carve),
                        ("pc-denoised-carved", &clouds, None, denoise, carve),
                        ("pc-no-phantoms", &clean, None, None, None),
                        ("pc-no-phantoms-denoised", &clean, None, denoise, None),
                    ];
                    for (label, source, mixed_pixels, denoise, carve) in cleanings {
                        let (map, times) = timed(
                            scans,
                            || pc_points(source, &PcCleaning { mixed_pixels, denoise, carve }),
                            |points| Ok(AnyMap::PointCloud(PointCloudMap::from_points(&points)?)),
                        )?;
                        rows.push(safety_row(
                            (name, noise, scans),
                            label,
                            &truth,
                            &map,
                            &sampling,
                            times,
                        )?);
                    }
                }
                spinner.finish_and_clear();
            }
        }
    }
    Ok(rows)
}

/// Up to `n` points free on both maps and at least 1 m apart, 1 m above the box's floor:
/// candidates inset 10 %, 20 %, 30 % and 40 % from the box's four corners, in that order.
fn free_points(truth: &AnyMap, map: &AnyMap, radius: Real, n: usize) -> Vec<Point3> {
    let b = truth.bounds();
    let free = |p: &Point3| {
        CapsuleStep::sphere(*p, radius)
            .is_ok_and(|s| truth.is_step_free(&s) && map.is_step_free(&s))
    };
    let mut out = Vec::new();
    let inset = |lo: Real, hi: Real, f: Real| lo + (hi - lo) * f;
    for f in [0.1, 0.2, 0.3, 0.4] {
        for (fx, fy) in [(f, f), (1.0 - f, f), (1.0 - f, 1.0 - f), (f, 1.0 - f)] {
            let p = Point3::new(
                inset(b.min.x, b.max.x, fx),
                inset(b.min.y, b.max.y, fy),
                b.min.z + 1.0,
            );
            if out.len() < n && free(&p) && out.iter().all(|q: &Point3| (q - p).norm() > 1.0) {
                out.push(p);
            }
        }
    }
    out
}

/// Grows RRT and PRM on `map` from one free point toward three others, re-checks every edge
/// on the truth, and counts colliding edges and paths.
fn planner_view(
    truth: &AnyMap,
    map: &AnyMap,
    args: &MapSafetySetup,
    row: &mut SafetyRow,
) -> Result<()> {
    let points = free_points(truth, map, args.radius, 4);
    let Some((start, goals)) = points.split_first() else {
        return Ok(());
    };
    let problem = Problem {
        start: *start,
        goals: goals.iter().map(|&center| Goal { center, tolerance: 0.5 }).collect(),
    };
    let space = PlanningSpace::new(truth.bounds(), args.radius, 1.0)
        .context("the planning space of the truth's box")?;
    for kind in [PlannerKind::Rrt, PlannerKind::Prm] {
        for k in 0..args.planner_seeds {
            let mut planner = named_planner_on(kind, map, space, args.seed + k)?;
            planner.solve(&problem, &mut MaxIterations(args.planner_iterations));
            let graph = planner.roadmap();
            let collides = |a: &Point3, b: &Point3| {
                CapsuleStep::new(*a, *b, args.radius).is_ok_and(|s| !truth.is_step_free(&s))
            };
            for e in graph.edge_indices() {
                if let Some((a, b)) = graph.edge_endpoints(e) {
                    row.edges += 1;
                    row.colliding_edges += u64::from(collides(&graph[a], &graph[b]));
                }
            }
            for g in 0..problem.goals.len() {
                if let Some(path) = planner.path_to(g) {
                    row.paths += 1;
                    row.colliding_paths +=
                        u64::from(path.windows(2).any(|w| collides(&w[0], &w[1])));
                }
            }
        }
    }
    Ok(())
}

fn pct(count: u64, total: u64) -> String {
    if total == 0 {
        "–".to_owned()
    } else {
        format!("{:.2}", 100.0 * count as Real / total as Real)
    }
}

/// The table as markdown: one block per scene, noise and scan count.
pub fn safety_table(rows: &[SafetyRow]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "| scene | noise | scans | map | unsafe % [95 %] | over- cautious % [95 %] | unsafe − floor | file bytes | memory bytes | extract s / scan | load s | colliding edges % | colliding paths % |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for r in rows {
        let floor = rows
            .iter()
            .find(|q| {
                q.scene == r.scene && q.noise == r.noise && q.scans == r.scans && q.map == "pc"
            })
            .map(|q| q.comparison.unsafe_rate().value);
        let u = r.comparison.unsafe_rate();
        let o = r.comparison.overcautious_rate();
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {:.2} [{:.2}, {:.2}] | {:.2} [{:.2}, {:.2}] | {} | {} | {} | {:.3} | {:.2} | {} | {} |",
            r.scene,
            r.noise,
            r.scans,
            r.map,
            100.0 * u.value,
            100.0 * u.low,
            100.0 * u.high,
            100.0 * o.value,
            100.0 * o.low,
            100.0 * o.high,
            floor.map_or("–".to_owned(), |f| format!("{:+.2}", 100.0 * (u.value - f))),
            r.file_bytes,
            r.memory_bytes,
            r.seconds_per_scan,
            r.load_seconds,
            pct(r.colliding_edges, r.edges),
            pct(r.colliding_paths, r.paths),
        );
    }
    out
}
