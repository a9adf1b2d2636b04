//! Thesis §5.3 (Figs 5.12–5.14, Table 5.1) and the map-size headline of §6.1 (Table 6.1):
//! `patchnav experiment extraction` prints our figures beside the thesis's statements.
//!
//! 1. **Segmentation quality**: simulated scans of the `lab` from `--poses` body poses, by the
//!    SICK S300 ALRF (`--alrf-step-deg`, default its 0.5°; the ±90° columns removed first,
//!    thesis App. A) and the SR-3000 range camera, at three noise levels: none, the sensor
//!    model's default (ALRF σ = 3 cm with mixed pixels, camera σ = 1 cm) and twice that. Each
//!    is segmented with the matching [`SegmentConfig`] preset (`exact` for noise-free scans, the
//!    sensor's preset with `noise.sigma_0` scaled by the noise factor otherwise) and scored
//!    with SegComp (Hoover et al. 1996) at T = 0.8 against scene-sim's per-point surface
//!    labels; ground-truth surfaces with fewer than [`MIN_TRUTH`] points are ignored. The plane
//!    angle error is that of the correct detections against the surfaces' true planes.
//! 2. **Outlining survey** (Figs 5.12–5.14): per method, the time per scan, the polygon and
//!    triangle counts and the mean spikyness, on the default-noise scans of (1) and on real
//!    organised scans under `--real` when present. Regions: our segmentation's (default) or
//!    the ground-truth labels' (`--regions truth`, simulated scans only). Region masks are
//!    built before the clock starts; α-shape and hull times include the projection.
//!    * *chain code + CDT*: the crack-following rings are in pixel coordinates. They are
//!      triangulated there (constrained Delaunay, no Steiner points, so every triangle vertex
//!      is a ring vertex, a pixel corner) and each vertex is **lifted** to 3D as the mean of
//!      the region's pixels sharing that corner (one to three of the four; a ring corner always
//!      touches the region), projected onto the region's plane. Spikyness is then measured in
//!      3D like every other method's; the pixel-space figure is printed in a note.
//!    * *α-shape + DP + CDT*: `polygonize_region` with the thesis's configuration, then the
//!      constrained Delaunay triangulation of each patch; *convex hull + CDT* the same with
//!      [`PolygonizeConfig::convex_hull`]. Their polygon count is the number of patches.
//!
//!    The thesis's ranking (L5193–5237) is then checked against the table, claim by claim.
//! 3. **Outline fidelity**: for each correct detection of (1), the α-shape + DP patch of the
//!    region against two references, as the symmetric-difference area over the reference's
//!    area: (a) the α-shape + DP outline of the surface's ground-truth-labelled points,
//!    computed in the same plane frame (the region's fitted plane), so only the outline
//!    differs, never the plane; (b) the surface's full true polygon (scene geometry, moved into
//!    the patch frame and projected orthogonally onto the fitted plane). (b) is large wherever
//!    a surface is partly occluded or out of range (the scan sees only part of it): the ratio
//!    of the visible (GT α-shape) area to the true area is printed beside it. Cylinder caps
//!    are 64-gons; spheres and cylinder sides are never planar detections.
//! 4. **Table 5.1 and the map-size headline**: bytes per patch for the default-noise scans'
//!    patches, before merging (median over patches):
//!    * *plane + outline*: what our map file stores per planar patch, the bincode encoding of
//!      `Patch::Planar` (f64 frame and vertices, ring lengths, the optional 4×4 plane
//!      covariance, which our patches carry); and, beside it, a packed f32 figure closer to the
//!      thesis's storage: 7 floats for the frame (quaternion + translation), 2 floats per
//!      vertex, 4 bytes per ring length;
//!    * *triangulated outline*: the CDT of the polygon, 3 f32 per vertex + 3 u32 per triangle;
//!    * *triangulated region*: the naive grid triangulation of the region's points (the thesis
//!      used a Delaunay triangulation of the sub-cloud, about as many triangles), 3 f32 per
//!      vertex used + 3 u32 per triangle.
//!
//!    Then `--map-scans` (default 29, the thesis's Lab) ALRF scans of the lab at default noise
//!    go through `patch_extract::pipeline::extract` once, with trimesh growing on the remainder
//!    (`PipelineConfig::alrf().with_remainder(TrimeshGrowConfig::alrf())`) and merging off;
//!    the planar patches are then merged by the pipeline's own merge step (`merge_coplanar`
//!    with the preset's `MergeConfig::alrf`), which is what `extract` with merging on does.
//!    The planes map (merged planar patches), the same unmerged, and the hybrid map (merged
//!    planar + trimesh patches) are saved as `bbox6d` map files and compared with the raw
//!    scans (all valid points, world frame, ±90° columns kept) as binary little-endian PLY
//!    with f32 positions (one file per scan) and as a point-cloud map file.
//!    File sizes are counted, nothing is written to disk.
//!
//! `--quick` shrinks everything for tests (ALRF at 3°, a 88 × 72 camera, one pose, one map
//! scan, smaller minimum region sizes). `--jsonl FILE` writes one JSON object per table row.

use crate::Progress;
use crate::experiment::ByteCount;
use crate::input::DepthConvention;
use crate::input::{CloudInput, read_cloud};
use anyhow::{Context, Result, bail};
use evaluation::stats::median;
use patch_core::triangulate::triangulate_polygon;
use patch_core::{
    FromPatches as _, Isometry3, Patch, PlanarPatch, Plane, Point3, Real, UnitVector3,
};
use patch_extract::chain_code::chain_code_outlines;
use patch_extract::evaluate::{SegCompConfig, SegCompReport, segcomp};
use patch_extract::grid_mesh::{RegionMask, naive_triangulation};
use patch_extract::merge::merge_coplanar;
use patch_extract::pipeline::{PipelineConfig, extract};
use patch_extract::polygonize::{PolygonizeConfig, polygonize_region};
use patch_extract::projection::{AlrfSideColumns, invalidate_alrf_side_columns};
use patch_extract::quality::{
    MeshStats, spikyness_2d, symmetric_difference_area, symmetric_difference_area_rings,
};
use patch_extract::scanline::{ScanLineVersion, scan_line};
use patch_extract::segment::{SegmentConfig, segment};
use patch_extract::trimesh_grow::TrimeshGrowConfig;
use patch_extract::{PlanarRegion, Segmentation};
use patch_map::mapfile::{HEADER_LEN, MapCounts, write_map};
use patch_map::{BBox6dMap, MapFile as _, PointCloudMap};
use pointcloud::io::ply::{PlyWriteOptions, write_ply};
use pointcloud::{BeamModel, PointCloud, SensorPose};
use scene_sim::{
    Alrf, AlrfConfig, RangeCamera, RangeCameraConfig, RangeSensor, Scene, Shape, SurfaceId,
};
use serde_json::{Value, json};
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Ground-truth surfaces with fewer points are ignored by SegComp (full-size scans).
pub const MIN_TRUTH: usize = 200;
/// [`MIN_TRUTH`] with `--quick`.
const MIN_TRUTH_QUICK: usize = 40;
/// Height of the ALRF above the floor, metres (as the lab experiments).
const ALRF_HEIGHT: Real = 0.5;
/// Height of the range camera above the floor, metres.
const CAMERA_HEIGHT: Real = 1.0;
/// The noise factors of the three levels.
const NOISE_FACTORS: [Real; 3] = [0.0, 1.0, 2.0];

crate::names::named_enum! {
    /// Where the survey's regions come from.
    pub enum RegionSource ("region source") {
        /// Our plane segmentation's regions.
        Segmented = "segmented", "Our plane segmentation's regions";
        /// Scene-sim's ground-truth labels (simulated scans; real scans keep the segmentation).
        Truth = "truth",
            "Scene-sim's ground-truth labels (simulated scans; real scans keep the segmentation)";
    }
}

/// The settings (defaults: the command line's) of `patchnav experiment extraction`.
#[derive(Clone, Debug, PartialEq)]
pub struct ExtractionSetup {
    /// Scan poses per sensor and noise level.
    pub poses: usize,
    /// Seed of the lab's furniture, the poses and the sensor noise.
    pub seed: u64,
    /// Angular step of the simulated ALRF in degrees (the S300: 0.5°; 1° is 4× faster).
    pub alrf_step_deg: Real,
    /// ALRF scans extracted into the planes and hybrid maps for the map-size comparison (the
    /// thesis's Lab: 29).
    pub map_scans: usize,
    /// Regions of the outlining survey.
    pub regions: RegionSource,
    /// Directory of real scans (see its README.md); skipped with a note when absent.
    pub real: PathBuf,
    /// Tiny sizes, for tests.
    pub quick: bool,
    /// Also write every table row as a JSON object per line to this file.
    pub jsonl: Option<PathBuf>,
}

impl Default for ExtractionSetup {
    fn default() -> ExtractionSetup {
        ExtractionSetup {
            poses: 3,
            seed: 7,
            alrf_step_deg: 0.5,
            map_scans: 29,
            regions: RegionSource::Segmented,
            real: PathBuf::from("../shared/data/real"),
            quick: false,
            jsonl: None,
        }
    }
}

#[derive(Copy, Clone, Debug, PartialEq, Eq)]
enum SensorKind {
    Alrf,
    Camera,
}

impl SensorKind {
    fn name(self) -> &'static str {
        match self {
            SensorKind::Alrf => "ALRF",
            SensorKind::Camera => "SR-3000",
        }
    }
}

/// Sizes derived from the arguments.
struct Setup {
    alrf_step_deg: Real,
    camera_size: (u32, u32),
    poses: usize,
    map_scans: usize,
    min_truth: usize,
    min_region: Option<usize>,
}

impl Setup {
    fn of(args: &ExtractionSetup) -> Result<Setup> {
        if args.poses == 0 {
            bail!("--poses must be at least 1");
        }
        if args.map_scans == 0 {
            bail!("--map-scans must be at least 1");
        }
        Ok(if args.quick {
            Setup {
                alrf_step_deg: args.alrf_step_deg.max(3.0),
                camera_size: (88, 72),
                poses: 1,
                map_scans: 1,
                min_truth: MIN_TRUTH_QUICK,
                min_region: Some(30),
            }
        } else {
            Setup {
                alrf_step_deg: args.alrf_step_deg,
                camera_size: (176, 144),
                poses: args.poses,
                map_scans: args.map_scans,
                min_truth: MIN_TRUTH,
                min_region: None,
            }
        })
    }

    fn alrf(&self, factor: Real) -> Result<Alrf> {
        let mut config = if (self.alrf_step_deg - 0.5).abs() < 1e-12 {
            AlrfConfig::sick_s300()
        } else {
            AlrfConfig::sick_s300_with_step(self.alrf_step_deg.to_radians())
                .with_context(|| format!("ALRF step {}°", self.alrf_step_deg))?
        };
        config.range_sigma *= factor;
        if factor == 0.0 {
            config.mixed_pixels = None;
        }
        Ok(Alrf::new(config)?)
    }

    fn camera(&self, factor: Real) -> Result<RangeCamera> {
        let mut config = RangeCameraConfig::swissranger_sr3000();
        (config.width, config.height) = self.camera_size;
        config.range_sigma *= factor;
        Ok(RangeCamera::new(config)?)
    }

    fn sensor(&self, kind: SensorKind, factor: Real) -> Result<Box<dyn RangeSensor>> {
        Ok(match kind {
            SensorKind::Alrf => Box::new(self.alrf(factor)?),
            SensorKind::Camera => Box::new(self.camera(factor)?),
        })
    }

    /// The matching preset: `exact` without noise, else the sensor's with σ₀ scaled.
    fn segment_config(&self, kind: SensorKind, factor: Real) -> SegmentConfig {
        let mut c = if factor == 0.0 {
            SegmentConfig::exact()
        } else {
            let mut c = match kind {
                SensorKind::Alrf => SegmentConfig::alrf(),
                SensorKind::Camera => SegmentConfig::range_camera(),
            };
            c.noise.sigma_0 *= factor;
            c
        };
        if let Some(m) = self.min_region {
            c.min_region_size = m;
        }
        c
    }

    fn height(kind: SensorKind) -> Real {
        match kind {
            SensorKind::Alrf => ALRF_HEIGHT,
            SensorKind::Camera => CAMERA_HEIGHT,
        }
    }
}

/// One segmented simulated scan.
struct Case {
    kind: SensorKind,
    level: usize,
    pose: SensorPose,
    cloud: PointCloud,
    seg: Segmentation,
    report: SegCompReport,
    seg_ms: Real,
}

/// The cloud of a simulated scan, with the ALRF's ±90° columns removed.
fn scan_cloud(
    sensor: &dyn RangeSensor,
    scene: &Scene,
    body: &SensorPose,
    seed: u64,
) -> Result<(PointCloud, PointCloud)> {
    let scan = sensor.scan(scene, &sensor.mount(body), seed);
    let raw = scan.to_cloud().context("building a scan's cloud")?;
    let cloud = match scan.image.beams() {
        BeamModel::ActuatedLrf(model) => {
            invalidate_alrf_side_columns(&raw, model, &AlrfSideColumns::thesis())?.0
        }
        _ => raw.clone(),
    };
    Ok((raw, cloud))
}

/// The true plane of `surface` in the sensor frame of `pose`.
fn plane_in_sensor(scene: &Scene, pose: &SensorPose, surface: u32) -> Option<Plane> {
    let plane = scene.surface(SurfaceId(surface))?.plane?;
    let m = &pose.world_from_sensor;
    let normal = UnitVector3::new_normalize(m.rotation.inverse() * plane.normal.into_inner());
    let offset = plane.offset - plane.normal.dot(&m.translation.vector);
    Some(Plane { normal, offset })
}

/// A markdown table.
fn table(out: &mut String, header: &[&str], rows: &[Vec<String>]) {
    let _ = writeln!(out, "| {} |", header.join(" | "));
    let _ = writeln!(out, "|{}", "---|".repeat(header.len()));
    for row in rows {
        let _ = writeln!(out, "| {} |", row.join(" | "));
    }
}

fn opt(v: Option<Real>, digits: usize) -> String {
    v.map_or_else(|| "–".to_owned(), |v| format!("{v:.digits$}"))
}

fn mean(values: &[Real]) -> Option<Real> {
    (!values.is_empty()).then(|| values.iter().sum::<Real>() / values.len() as Real)
}

/// Runs the experiment.
pub fn run(args: &ExtractionSetup, progress: &dyn Progress) -> Result<()> {
    let started = Instant::now();
    let setup = Setup::of(args)?;
    let scene = scene_sim::scene_by_name("lab", args.seed)?;
    let mut rows: Vec<Value> = Vec::new();
    let mut out = String::new();
    writeln!(
        out,
        "Extraction experiment (thesis §5.3, Table 5.1, Table 6.1): simulated lab (seed {}), \
         {} pose(s) per sensor and noise level, ALRF at {}°, SR-3000 {}×{}",
        args.seed, setup.poses, setup.alrf_step_deg, setup.camera_size.0, setup.camera_size.1
    )?;

    let cases = simulate_cases(&setup, &scene, args.seed, progress)?;
    segmentation_section(&mut out, &mut rows, &setup, &cases)?;
    survey_section(&mut out, &mut rows, &setup, args, &cases, progress)?;
    fidelity_section(&mut out, &mut rows, &scene, &cases, progress)?;
    storage_section(&mut out, &mut rows, &cases)?;
    map_size_section(&mut out, &mut rows, &setup, &scene, args.seed, progress)?;
    writeln!(out, "\nTotal time: {:.1} s", started.elapsed().as_secs_f64())?;
    progress.report(out.trim_end());
    if let Some(path) = &args.jsonl {
        pointcloud::io::write_atomically(path, |f| -> Result<()> {
            for row in &rows {
                writeln!(f, "{row}")?;
            }
            Ok(())
        })?;
    }
    Ok(())
}

fn simulate_cases(
    setup: &Setup,
    scene: &Scene,
    seed: u64,
    progress: &dyn Progress,
) -> Result<Vec<Case>> {
    let kinds = [SensorKind::Alrf, SensorKind::Camera];
    let bar = progress.bar((kinds.len() * NOISE_FACTORS.len() * setup.poses) as u64, "scans");
    let mut cases = Vec::new();
    for kind in kinds {
        let bodies = scene.scan_poses(setup.poses, Setup::height(kind), seed);
        if bodies.len() < setup.poses {
            bail!("the lab has room for only {} scan poses", bodies.len());
        }
        for (level, &factor) in NOISE_FACTORS.iter().enumerate() {
            let sensor = setup.sensor(kind, factor)?;
            let config = setup.segment_config(kind, factor);
            for (k, body) in bodies.iter().enumerate() {
                let noise_seed = scene_sim::sensors::derive_seed(seed, k as u64);
                let (_, cloud) = scan_cloud(sensor.as_ref(), scene, body, noise_seed)?;
                let t = Instant::now();
                let seg = segment(&cloud, &config)?;
                let seg_ms = t.elapsed().as_secs_f64() * 1e3;
                let pose = *cloud.sensor_pose().context("simulated scans have a pose")?;
                let labels = cloud.labels().context("simulated scans have labels")?;
                let report = segcomp(labels, &seg, &SegCompConfig::hoover(setup.min_truth), |l| {
                    plane_in_sensor(scene, &pose, l)
                })?;
                cases.push(Case { kind, level, pose, cloud, seg, report, seg_ms });
                bar.inc(1);
            }
        }
    }
    bar.finish_and_clear();
    Ok(cases)
}

fn noise_name(kind: SensorKind, level: usize) -> String {
    let sigma = match kind {
        SensorKind::Alrf => 0.03,
        SensorKind::Camera => 0.01,
    } * NOISE_FACTORS[level];
    let mixed = if kind == SensorKind::Alrf && level > 0 { "+mixed" } else { "" };
    format!("σ={:.0}cm{mixed}", sigma * 100.0)
}

fn segmentation_section(
    out: &mut String,
    rows: &mut Vec<Value>,
    setup: &Setup,
    cases: &[Case],
) -> Result<()> {
    writeln!(
        out,
        "\n## 1. Segmentation quality (SegComp, T = 0.8, GT surfaces ≥ {} points; summed over \
         scans)",
        setup.min_truth
    )?;
    writeln!(
        out,
        "Thesis: no figures (the segmentation is Poppinga et al. 2008, not described in the \
         thesis; SegComp is Hoover et al. 1996)."
    )?;
    let mut table_rows = Vec::new();
    for kind in [SensorKind::Alrf, SensorKind::Camera] {
        for level in 0..NOISE_FACTORS.len() {
            let group: Vec<&Case> =
                cases.iter().filter(|c| c.kind == kind && c.level == level).collect();
            let sum = |f: &dyn Fn(&SegCompReport) -> usize| -> usize {
                group.iter().map(|c| f(&c.report)).sum()
            };
            let points: usize = group.iter().map(|c| c.cloud.len()).sum();
            let gt = sum(&|r| r.num_truth);
            let machine = sum(&|r| r.num_machine);
            let correct = sum(&|r| r.correct.len());
            let over = sum(&|r| r.over.len());
            let under = sum(&|r| r.under.len());
            let missed = sum(&|r| r.missed.len());
            let noise = sum(&|r| r.noise.len());
            let angles: Vec<Real> = group.iter().flat_map(|c| c.report.angle_errors()).collect();
            let mean_angle = mean(&angles);
            let max_angle = angles.iter().copied().reduce(Real::max);
            let ms = group.iter().map(|c| c.seg_ms).sum::<Real>() / group.len().max(1) as Real;
            let n = group.len().max(1);
            table_rows.push(vec![
                kind.name().to_owned(),
                noise_name(kind, level),
                format!("{}", points / n),
                gt.to_string(),
                machine.to_string(),
                correct.to_string(),
                over.to_string(),
                under.to_string(),
                missed.to_string(),
                noise.to_string(),
                opt(mean_angle, 3),
                opt(max_angle, 3),
                format!("{ms:.1}"),
            ]);
            rows.push(json!({
                "table": "segmentation", "sensor": kind.name(), "noise": noise_name(kind, level),
                "scans": group.len(), "points_per_scan": points / n, "gt": gt,
                "machine": machine, "correct": correct, "over": over, "under": under,
                "missed": missed, "noise_regions": noise, "angle_mean_deg": mean_angle,
                "angle_max_deg": max_angle, "ms_per_scan": ms,
            }));
        }
    }
    table(
        out,
        &[
            "sensor",
            "noise level",
            "points/scan",
            "GT",
            "machine",
            "correct",
            "over",
            "under",
            "missed",
            "noise",
            "angle mean [°]",
            "angle max [°]",
            "ms/scan",
        ],
        &table_rows,
    );
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// 2. Outlining survey

const METHODS: [&str; 6] = [
    "naive triangulation",
    "scanLine V1",
    "scanLine V2",
    "chain code + CDT",
    "α-shape + DP + CDT",
    "convex hull + CDT",
];
const NAIVE: usize = 0;
const V1: usize = 1;
const V2: usize = 2;
const CHAIN: usize = 3;
const ALPHA: usize = 4;
const HULL: usize = 5;

/// Per-method totals of one survey input.
#[derive(Clone, Debug, Default)]
struct MethodTotals {
    seconds: Real,
    stats: MeshStats,
    failures: usize,
    /// Chain code only: spikyness summed in pixel space.
    pixel_spikyness: Real,
}

/// One input of the survey: organised scans with their regions.
struct SurveyInput {
    name: String,
    scans: Vec<(PointCloud, Vec<PlanarRegion>)>,
}

/// The ground-truth regions of a labelled simulated scan
/// ([`patch_extract::evaluate::truth_regions`]).
fn truth_regions(cloud: &PointCloud, min_size: usize) -> Vec<PlanarRegion> {
    let Some(labels) = cloud.labels() else { return Vec::new() };
    patch_extract::evaluate::truth_regions(labels, cloud.positions(), min_size, u32::MAX)
}

/// CDT of rings, with the spikyness of its triangles (in the rings' plane).
fn cdt_stats(rings: &[Vec<[f64; 2]>]) -> Option<MeshStats> {
    let tri = triangulate_polygon(rings).ok()?;
    let s: Real = tri
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| tri.vertices[i as usize]);
            spikyness_2d(a, b, c)
        })
        .sum();
    Some(MeshStats::from_parts(tri.triangles.len(), 1, tri.vertices.len(), s))
}

fn patch_rings(p: &PlanarPatch) -> Vec<Vec<[f64; 2]>> {
    p.polygon().rings().map(|r| r.points().iter().map(|q| [q.x, q.y]).collect()).collect()
}

/// Lifts a pixel corner (ring vertex in pixel-centre coordinates) to the region's plane.
fn lift_corner(
    cloud: &PointCloud,
    mask: &RegionMask,
    region: &PlanarRegion,
    v: [f64; 2],
) -> Option<Point3> {
    let grid = cloud.grid()?;
    let (c, r) = ((v[0] + 0.5).round() as i64, (v[1] + 0.5).round() as i64);
    let mut sum = Point3::origin().coords;
    let mut n = 0;
    for (col, row) in [(c - 1, r - 1), (c, r - 1), (c - 1, r), (c, r)] {
        if mask.contains(col, row)
            && let Some(i) = grid.point_index(col as u32, row as u32)
        {
            sum += cloud.positions()[i].coords;
            n += 1;
        }
    }
    if n == 0 {
        return None;
    }
    let p = Point3::from(sum / n as Real);
    let normal = region.plane.normal.into_inner();
    Some(p - normal * (normal.dot(&p.coords) - region.plane.offset))
}

fn survey_scan(
    cloud: &PointCloud,
    regions: &[PlanarRegion],
    totals: &mut [MethodTotals],
) -> Result<()> {
    let grid = cloud.grid().context("the survey needs organised scans")?;
    let masks: Vec<RegionMask> =
        regions.iter().map(|r| RegionMask::from_points(grid, &r.points)).collect();

    let t = Instant::now();
    for m in &masks {
        let mesh = naive_triangulation(cloud, m)?;
        totals[NAIVE].stats = totals[NAIVE].stats.combine(&mesh.stats);
    }
    totals[NAIVE].seconds += t.elapsed().as_secs_f64();

    for (index, version) in [(V1, ScanLineVersion::V1), (V2, ScanLineVersion::V2)] {
        let t = Instant::now();
        for m in &masks {
            let mesh = scan_line(cloud, m, version)?;
            totals[index].stats = totals[index].stats.combine(&mesh.mesh.stats);
        }
        totals[index].seconds += t.elapsed().as_secs_f64();
    }

    let t = Instant::now();
    for (m, region) in masks.iter().zip(regions) {
        for outline in chain_code_outlines(cloud, m)? {
            let rings = outline.rings();
            let Ok(tri) = triangulate_polygon(&rings) else {
                totals[CHAIN].failures += 1;
                continue;
            };
            let lifted: Option<Vec<Point3>> =
                tri.vertices.iter().map(|&v| lift_corner(cloud, m, region, v)).collect();
            let Some(lifted) = lifted else {
                totals[CHAIN].failures += 1;
                continue;
            };
            totals[CHAIN].pixel_spikyness += tri
                .triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|i| tri.vertices[i as usize]);
                    spikyness_2d(a, b, c)
                })
                .sum::<Real>();
            let stats = MeshStats::from_triangles(&lifted, &tri.triangles, 1);
            totals[CHAIN].stats = totals[CHAIN].stats.combine(&stats);
        }
    }
    totals[CHAIN].seconds += t.elapsed().as_secs_f64();

    for (index, config) in
        [(ALPHA, PolygonizeConfig::thesis()), (HULL, PolygonizeConfig::convex_hull())]
    {
        let t = Instant::now();
        for region in regions {
            let Ok(p) = polygonize_region(cloud, region, &config) else {
                totals[index].failures += 1;
                continue;
            };
            for patch in &p.patches {
                match cdt_stats(&patch_rings(patch)) {
                    Some(s) => totals[index].stats = totals[index].stats.combine(&s),
                    None => totals[index].failures += 1,
                }
            }
        }
        totals[index].seconds += t.elapsed().as_secs_f64();
    }
    Ok(())
}

/// A claim of the thesis and whether the numbers agree.
fn claim(
    out: &mut String,
    rows: &mut Vec<Value>,
    input: &str,
    text: &str,
    holds: bool,
    numbers: String,
) {
    let verdict = if holds { "agrees" } else { "disagrees" };
    let _ = writeln!(out, "- {text}: {verdict} ({numbers})");
    rows.push(json!({"table": "survey_claims", "input": input, "claim": text, "agrees": holds}));
}

fn survey_claims(
    out: &mut String,
    rows: &mut Vec<Value>,
    input: &str,
    t: &[MethodTotals],
    is_camera: bool,
) {
    let ms = |i: usize| t[i].seconds;
    let polys = |i: usize| t[i].stats.polygons;
    let spiky = |i: usize| t[i].stats.spikyness_mean;
    let _ = writeln!(out, "Thesis's ranking (L5193–5237) on {input}:");
    let fastest = (0..METHODS.len()).min_by(|&a, &b| ms(a).total_cmp(&ms(b))).unwrap_or(HULL);
    claim(
        out,
        rows,
        input,
        "time: the convex hull is the single fastest",
        fastest == HULL,
        format!("fastest: {}", METHODS[fastest]),
    );
    claim(
        out,
        rows,
        input,
        "time: scanLine V1, V2 and the hull are faster than naive triangulation",
        ms(V1).max(ms(V2)).max(ms(HULL)) < ms(NAIVE),
        format!(
            "V1 {:.1}, V2 {:.1}, hull {:.1}, naive {:.1} ms in all",
            ms(V1) * 1e3,
            ms(V2) * 1e3,
            ms(HULL) * 1e3,
            ms(NAIVE) * 1e3
        ),
    );
    claim(
        out,
        rows,
        input,
        "time: α-shapes are the slowest",
        (0..METHODS.len()).all(|i| ms(i) <= ms(ALPHA)),
        format!("α {:.1} ms in all", ms(ALPHA) * 1e3),
    );
    claim(
        out,
        rows,
        input,
        "time: chain code between naive triangulation and α-shapes (RI)",
        ms(NAIVE) <= ms(CHAIN) && ms(CHAIN) <= ms(ALPHA),
        format!(
            "naive {:.1}, chain {:.1}, α {:.1} ms",
            ms(NAIVE) * 1e3,
            ms(CHAIN) * 1e3,
            ms(ALPHA) * 1e3
        ),
    );
    claim(
        out,
        rows,
        input,
        "polygons: naive ≫ V1 > V2 > α ≥ hull",
        polys(NAIVE) > 2 * polys(V1)
            && polys(V1) > polys(V2)
            && polys(V2) > polys(ALPHA)
            && polys(ALPHA) >= polys(HULL),
        format!(
            "{} / {} / {} / {} / {}",
            polys(NAIVE),
            polys(V1),
            polys(V2),
            polys(ALPHA),
            polys(HULL)
        ),
    );
    claim(
        out,
        rows,
        input,
        "spikyness: scanLine spikier than α-shapes, V2 slightly less than V1",
        spiky(V1).min(spiky(V2)) > spiky(ALPHA) && spiky(V2) <= spiky(V1),
        format!("V1 {:.3}, V2 {:.3}, α {:.3}", spiky(V1), spiky(V2), spiky(ALPHA)),
    );
    if is_camera {
        claim(
            out,
            rows,
            input,
            "spikyness (range camera): naive less spiky than α (RI); chain code slightly \
             worse than α; hull slightly better than V2",
            spiky(NAIVE) < spiky(ALPHA) && spiky(CHAIN) > spiky(ALPHA) && spiky(HULL) < spiky(V2),
            format!(
                "naive {:.3}, α {:.3}, chain {:.3}, hull {:.3}, V2 {:.3}",
                spiky(NAIVE),
                spiky(ALPHA),
                spiky(CHAIN),
                spiky(HULL),
                spiky(V2)
            ),
        );
    } else {
        let worst =
            (0..METHODS.len()).max_by(|&a, &b| spiky(a).total_cmp(&spiky(b))).unwrap_or(HULL);
        claim(
            out,
            rows,
            input,
            "spikyness (ALRF): the convex hull is worst",
            worst == HULL,
            format!("worst: {} {:.3}", METHODS[worst], spiky(worst)),
        );
    }
}

fn survey_section(
    out: &mut String,
    rows: &mut Vec<Value>,
    setup: &Setup,
    args: &ExtractionSetup,
    cases: &[Case],
    progress: &dyn Progress,
) -> Result<()> {
    writeln!(out, "\n## 2. Outlining survey (thesis Figs 5.12–5.14)")?;
    let which = match args.regions {
        RegionSource::Segmented => "our segmentation's regions",
        RegionSource::Truth => "ground-truth label regions",
    };
    writeln!(
        out,
        "Regions: {which}; default-noise scans of (1); times summed over the regions, per scan."
    )?;
    let mut inputs = Vec::new();
    for kind in [SensorKind::Alrf, SensorKind::Camera] {
        let scans = cases
            .iter()
            .filter(|c| c.kind == kind && c.level == 1)
            .map(|c| {
                let regions = match args.regions {
                    RegionSource::Segmented => c.seg.regions.clone(),
                    RegionSource::Truth => truth_regions(&c.cloud, setup.min_truth),
                };
                (c.cloud.clone(), regions)
            })
            .collect();
        inputs.push((
            kind == SensorKind::Camera,
            SurveyInput { name: format!("simulated lab, {}", kind.name()), scans },
        ));
    }
    for (is_camera, input) in real_inputs(&args.real, out)? {
        inputs.push((is_camera, input));
    }
    let bar = progress.bar(inputs.len() as u64, "survey");
    for (is_camera, input) in &inputs {
        let mut totals = vec![MethodTotals::default(); METHODS.len()];
        for (cloud, regions) in &input.scans {
            survey_scan(cloud, regions, &mut totals)?;
        }
        bar.inc(1);
        let n = input.scans.len().max(1) as Real;
        let num_regions: usize = input.scans.iter().map(|s| s.1.len()).sum();
        let points: usize =
            input.scans.iter().map(|s| s.1.iter().map(|r| r.points.len()).sum::<usize>()).sum();
        writeln!(
            out,
            "\n### {}: {} scan(s), {num_regions} regions, {points} region points",
            input.name,
            input.scans.len()
        )?;
        let mut table_rows = Vec::new();
        for (i, method) in METHODS.iter().enumerate() {
            let t = &totals[i];
            table_rows.push(vec![
                method.to_string(),
                format!("{:.2}", t.seconds * 1e3 / n),
                t.stats.polygons.to_string(),
                t.stats.triangles.to_string(),
                format!("{:.3}", t.stats.spikyness_mean),
                t.failures.to_string(),
            ]);
            rows.push(json!({
                "table": "survey", "input": input.name, "method": method,
                "ms_per_scan": t.seconds * 1e3 / n, "polygons": t.stats.polygons,
                "triangles": t.stats.triangles, "vertices": t.stats.vertices,
                "spikyness_mean": t.stats.spikyness_mean, "failures": t.failures,
            }));
        }
        table(
            out,
            &["method", "ms/scan", "polygons", "triangles", "mean spikyness", "failures"],
            &table_rows,
        );
        let chain = &totals[CHAIN];
        if chain.stats.triangles > 0 {
            writeln!(
                out,
                "Chain code: CDT in pixel space, vertices lifted to the region plane; mean \
                 spikyness in pixel space {:.3}.",
                chain.pixel_spikyness / chain.stats.triangles as Real
            )?;
        }
        survey_claims(out, rows, &input.name, &totals, *is_camera);
    }
    bar.finish_and_clear();
    Ok(())
}

/// The organised real scans under `dir`, segmented; notes what is missing.
fn real_inputs(dir: &Path, out: &mut String) -> Result<Vec<(bool, SurveyInput)>> {
    if !dir.is_dir() {
        writeln!(out, "\nReal scans: {} not found; skipped.", dir.display())?;
        return Ok(Vec::new());
    }
    // Kinect-class depth noise grows with the square of the range.
    let kinect = SegmentConfig::structured_light();
    let files: [(&str, Option<DepthConvention>, &str); 2] = [
        ("pcl_kinect_office/office1.pcd", None, "real: PCL Kinect office1.pcd (640×480)"),
        (
            "tum_rgbd_kinect_frame/TUM_depth.png",
            Some(DepthConvention::Tum),
            "real: TUM RGB-D depth frame (640×480)",
        ),
    ];
    let mut inputs = Vec::new();
    for (file, depth_camera, name) in files {
        let path = dir.join(file);
        if !path.is_file() {
            writeln!(out, "\nReal scan {} not found; skipped.", path.display())?;
            continue;
        }
        let cloud = read_cloud(&path, &CloudInput { skip_non_finite: false, depth: depth_camera })
            .with_context(|| format!("reading {}", path.display()))?;
        if cloud.grid().is_none() {
            writeln!(out, "\nReal scan {} is not organised; skipped.", path.display())?;
            continue;
        }
        let seg = segment(&cloud, &kinect)?;
        inputs
            .push((true, SurveyInput { name: name.to_owned(), scans: vec![(cloud, seg.regions)] }));
    }
    writeln!(
        out,
        "\nReal scans: the 3DTK Kurt3D scans are unorganised (no pixel grid for the grid \
         methods) and the ifm ToF frame needs its own radial-distance intrinsics; both are left \
         out."
    )?;
    Ok(inputs)
}

// ---------------------------------------------------------------------------------------------
// 3. Outline fidelity

/// The 3D rings (outer first) of a planar surface in the world, if it is planar.
fn true_rings(scene: &Scene, surface: u32) -> Option<Vec<Vec<Point3>>> {
    let s = scene.surface(SurfaceId(surface))?;
    let primitive = scene.primitive(s.primitive)?;
    match &primitive.shape {
        Shape::Polygon(p) => {
            let m = p.world_from_patch();
            let lift = |ring: &[scene_sim::Point2]| -> Vec<Point3> {
                ring.iter().map(|q| m * Point3::new(q.x, q.y, 0.0)).collect()
            };
            Some(std::iter::once(lift(p.outline())).chain(p.holes().map(lift)).collect())
        }
        Shape::Cuboid(c) => {
            let axes = c.world_from_box().rotation.to_rotation_matrix().into_inner();
            let h = *c.half_extents();
            let a = (s.part / 2) as usize;
            let (i, j) = ((a + 1) % 3, (a + 2) % 3);
            let u = axes.column(i) * h[i];
            let v = axes.column(j) * h[j];
            let centre = c.face_center(s.part);
            Some(vec![vec![centre - u - v, centre + u - v, centre + u + v, centre - u + v]])
        }
        Shape::Cylinder(c) if s.part > 0 => {
            let m: &Isometry3 = c.world_from_cylinder();
            let z = if s.part == 1 { -c.half_height() } else { c.half_height() };
            let ring = (0..64)
                .map(|k| {
                    let a = std::f64::consts::TAU * k as Real / 64.0;
                    m * Point3::new(c.radius() * a.cos(), c.radius() * a.sin(), z)
                })
                .collect();
            Some(vec![ring])
        }
        _ => None,
    }
}

fn ring_area(ring: &[[f64; 2]]) -> Real {
    let n = ring.len();
    (0..n)
        .map(|i| {
            let (a, b) = (ring[i], ring[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<Real>()
        .abs()
        * 0.5
}

struct Fidelity {
    vs_gt: Vec<Real>,
    vs_true: Vec<Real>,
    visible: Vec<Real>,
    failures: usize,
}

fn fidelity_of(scene: &Scene, case: &Case) -> Fidelity {
    let mut f =
        Fidelity { vs_gt: Vec::new(), vs_true: Vec::new(), visible: Vec::new(), failures: 0 };
    let Some(labels) = case.cloud.labels() else { return f };
    let mut by_label: HashMap<u32, Vec<u32>> = HashMap::new();
    for (i, &l) in labels.iter().enumerate() {
        by_label.entry(l).or_default().push(i as u32);
    }
    let thesis = PolygonizeConfig::thesis();
    let sensor_from_world = case.pose.world_from_sensor.inverse();
    for c in &case.report.correct {
        let region = &case.seg.regions[c.region];
        let extracted = polygonize_region(&case.cloud, region, &thesis)
            .ok()
            .and_then(|p| p.patches.into_iter().next());
        let truth_region = PlanarRegion {
            points: by_label.get(&c.truth).cloned().unwrap_or_default(),
            plane: region.plane,
            centroid: region.centroid,
            mse: region.mse,
            covariance: None,
        };
        let gt = polygonize_region(&case.cloud, &truth_region, &thesis)
            .ok()
            .and_then(|p| p.patches.into_iter().next());
        let (Some(extracted), Some(gt)) = (extracted, gt) else {
            f.failures += 1;
            continue;
        };
        if gt.area() > 0.0 {
            f.vs_gt.push(symmetric_difference_area(extracted.polygon(), gt.polygon()) / gt.area());
        }
        if let Some(rings) = true_rings(scene, c.truth) {
            let patch_from_world = extracted.world_from_patch().inverse() * sensor_from_world;
            let rings2: Vec<Vec<[f64; 2]>> = rings
                .iter()
                .map(|r| {
                    r.iter()
                        .map(|p| {
                            let q = patch_from_world * p;
                            [q.x, q.y]
                        })
                        .collect()
                })
                .collect();
            let area =
                ring_area(&rings2[0]) - rings2[1..].iter().map(|r| ring_area(r)).sum::<Real>();
            if area > 0.0 {
                let diff = symmetric_difference_area_rings(&patch_rings(&extracted), &rings2);
                f.vs_true.push(diff / area);
                f.visible.push(gt.area() / area);
            }
        }
    }
    f
}

fn fidelity_section(
    out: &mut String,
    rows: &mut Vec<Value>,
    scene: &Scene,
    cases: &[Case],
    progress: &dyn Progress,
) -> Result<()> {
    writeln!(
        out,
        "\n## 3. Outline fidelity: |extracted △ reference| / |reference| of the α-shape + DP \
         patches of correct detections"
    )?;
    writeln!(
        out,
        "References: (a) the α-shape + DP outline of the surface's ground-truth points, in the \
         same plane frame; (b) the surface's full true polygon, projected onto the fitted plane \
         (occluded and out-of-range parts count as error: see the visible/true area column). \
         Thesis: no figures."
    )?;
    let bar = progress.bar(cases.len() as u64, "fidelity");
    let mut table_rows = Vec::new();
    for kind in [SensorKind::Alrf, SensorKind::Camera] {
        for level in 0..NOISE_FACTORS.len() {
            let mut all = Fidelity {
                vs_gt: Vec::new(),
                vs_true: Vec::new(),
                visible: Vec::new(),
                failures: 0,
            };
            for case in cases.iter().filter(|c| c.kind == kind && c.level == level) {
                let f = fidelity_of(scene, case);
                all.vs_gt.extend(f.vs_gt);
                all.vs_true.extend(f.vs_true);
                all.visible.extend(f.visible);
                all.failures += f.failures;
                bar.inc(1);
            }
            let (gt_mean, gt_median) = (mean(&all.vs_gt), median(all.vs_gt.iter().copied()));
            let (true_mean, true_median) =
                (mean(&all.vs_true), median(all.vs_true.iter().copied()));
            let visible = median(all.visible.iter().copied());
            table_rows.push(vec![
                kind.name().to_owned(),
                noise_name(kind, level),
                all.vs_gt.len().to_string(),
                opt(gt_mean, 3),
                opt(gt_median, 3),
                all.vs_true.len().to_string(),
                opt(true_mean, 3),
                opt(true_median, 3),
                opt(visible, 3),
                all.failures.to_string(),
            ]);
            rows.push(json!({
                "table": "fidelity", "sensor": kind.name(), "noise": noise_name(kind, level),
                "detections_vs_gt": all.vs_gt.len(), "vs_gt_mean": gt_mean,
                "vs_gt_median": gt_median, "detections_vs_true": all.vs_true.len(),
                "vs_true_mean": true_mean, "vs_true_median": true_median,
                "visible_over_true_median": visible, "failures": all.failures,
            }));
        }
    }
    bar.finish_and_clear();
    table(
        out,
        &[
            "sensor",
            "noise level",
            "n (a)",
            "vs GT α mean",
            "vs GT α median",
            "n (b)",
            "vs true mean",
            "vs true median",
            "visible/true median",
            "failures",
        ],
        &table_rows,
    );
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// 4. Table 5.1 and map sizes

/// The bytes the map file's payload spends on one patch (its bincode encoding).
fn encoded_bytes(patch: &Patch) -> Result<u64> {
    let total = write_map(std::io::sink(), "patch", MapCounts::default(), patch)?;
    Ok(total - HEADER_LEN as u64)
}

/// Plane + outline packed as f32: frame (quaternion + translation) 28 B, 8 B per vertex, 4 B
/// per ring length.
fn packed_bytes(p: &PlanarPatch) -> u64 {
    let rings = p.polygon().rings().count() as u64;
    28 + 8 * p.polygon().num_vertices() as u64 + 4 * rings
}

fn storage_section(out: &mut String, rows: &mut Vec<Value>, cases: &[Case]) -> Result<()> {
    writeln!(
        out,
        "\n## 4. Table 5.1: median bytes per patch (default-noise scans of (1), before merging)"
    )?;
    writeln!(
        out,
        "Plane + outline: bincode of `Patch::Planar` as our map file stores it (f64, with the \
         4×4 plane covariance), and packed f32 (28 B frame + 8 B/vertex + 4 B/ring); \
         triangulated outline: CDT, 12 B per vertex (3 f32) + 12 B per triangle (3 u32); \
         triangulated region: naive grid triangulation of the region's points, same sizes."
    )?;
    // The thesis's 151 B is plane + outline in its own packing: it sits in the packed column.
    let mut table_rows = vec![
        ["thesis Lab (ALRF)", "–", "151", "280", "1.944", "3913", "25.295", "11"]
            .map(str::to_owned)
            .to_vec(),
    ];
    for kind in [SensorKind::Alrf, SensorKind::Camera] {
        let (mut map, mut packed, mut tri_outline, mut tri_region, mut vertices) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut tri_ratio = Vec::new();
        let mut region_ratio = Vec::new();
        for case in cases.iter().filter(|c| c.kind == kind && c.level == 1) {
            let grid = case.cloud.grid().context("simulated scans are organised")?;
            for region in &case.seg.regions {
                let Ok(p) = polygonize_region(&case.cloud, region, &PolygonizeConfig::thesis())
                else {
                    continue;
                };
                let mask = RegionMask::from_points(grid, &region.points);
                let mesh = naive_triangulation(&case.cloud, &mask)?;
                let region_bytes = 12.0 * (mesh.stats.vertices + mesh.stats.triangles) as Real;
                for patch in p.patches {
                    let Ok(tri) = triangulate_polygon(&patch_rings(&patch)) else { continue };
                    let outline_bytes = 12.0 * (tri.vertices.len() + tri.triangles.len()) as Real;
                    let encoded = encoded_bytes(&Patch::Planar(patch.clone()))? as Real;
                    let packed_patch = packed_bytes(&patch) as Real;
                    map.push(encoded);
                    packed.push(packed_patch);
                    tri_outline.push(outline_bytes);
                    tri_region.push(region_bytes);
                    tri_ratio.push(outline_bytes / packed_patch);
                    region_ratio.push(region_bytes / packed_patch);
                    vertices.push(patch.polygon().num_vertices() as Real);
                }
            }
        }
        let n = map.len();
        let cells = [
            median(map.iter().copied()),
            median(packed.iter().copied()),
            median(tri_outline.iter().copied()),
            median(tri_ratio.iter().copied()),
            median(tri_region.iter().copied()),
            median(region_ratio.iter().copied()),
            median(vertices.iter().copied()),
        ];
        let mut row = vec![format!("ours, lab {} ({n} patches)", kind.name())];
        row.push(opt(cells[0], 0));
        row.push(opt(cells[1], 0));
        row.push(opt(cells[2], 0));
        row.push(opt(cells[3], 3));
        row.push(opt(cells[4], 0));
        row.push(opt(cells[5], 3));
        row.push(opt(cells[6], 0));
        table_rows.push(row);
        rows.push(json!({
            "table": "patch_storage", "sensor": kind.name(), "patches": n,
            "plane_outline_mapfile_bytes": cells[0], "plane_outline_packed_bytes": cells[1],
            "triangulated_outline_bytes": cells[2], "triangulated_outline_increase": cells[3],
            "triangulated_region_bytes": cells[4], "triangulated_region_increase": cells[5],
            "outline_vertices": cells[6],
        }));
    }
    table(
        out,
        &[
            "data set",
            "plane+outl. map file [B]",
            "plane+outl. packed f32 [B]",
            "tri. outline [B]",
            "increase",
            "tri. region [B]",
            "increase",
            "outline vertices",
        ],
        &table_rows,
    );
    writeln!(
        out,
        "Increases: medians over patches of the ratio to the packed f32 plane + outline (all \
         three in f32); the thesis's are ratios of its medians to 151 B. The thesis's 11 \
         outline vertices are Table 6.1's median polygon size (Ch. 6 maps)."
    )?;
    Ok(())
}

fn mb(bytes: u64) -> String {
    format!("{:.3}", bytes as Real / 1e6)
}

fn map_size_section(
    out: &mut String,
    rows: &mut Vec<Value>,
    setup: &Setup,
    scene: &Scene,
    seed: u64,
    progress: &dyn Progress,
) -> Result<()> {
    let n = setup.map_scans;
    let sensor = setup.alrf(1.0)?;
    let bodies = scene.scan_poses(n, ALRF_HEIGHT, seed);
    if bodies.len() < n {
        bail!("the lab has room for only {} scan poses", bodies.len());
    }
    let bar = progress.bar(n as u64, "map scans");
    let mut scans = Vec::with_capacity(n);
    let mut ply_bytes = 0;
    let mut world_points = Vec::new();
    for (k, body) in bodies.iter().enumerate() {
        let noise_seed = scene_sim::sensors::derive_seed(seed, 1000 + k as u64);
        let (raw, cloud) = scan_cloud(&sensor, scene, body, noise_seed)?;
        let world = PointCloud::from_positions(raw.to_world().positions().to_vec())?;
        let mut count = ByteCount(0);
        write_ply(&mut count, &world, &PlyWriteOptions::default())?;
        ply_bytes += count.0;
        world_points.extend_from_slice(world.positions());
        scans.push(cloud);
        bar.inc(1);
    }
    bar.finish_and_clear();
    let spinner = progress.spinner("extracting the maps");
    // One pipeline run with the remainder meshes and without merging; then the pipeline's
    // own merge step (`merge_coplanar` with `MergeConfig::alrf`, as `PipelineConfig::alrf`)
    // on the planar patches. Planes map = merged planar patches; hybrid = those + the meshes.
    let t = Instant::now();
    let config = PipelineConfig {
        merge: None,
        slab_thickness: None,
        ..PipelineConfig::alrf().with_remainder(TrimeshGrowConfig::alrf())
    };
    let extraction = extract(&scans, &config, |_| {})?;
    let (unmerged, meshes): (Vec<Patch>, Vec<Patch>) =
        extraction.patches.into_iter().partition(|p| matches!(p, Patch::Planar(_)));
    let unmerged: Vec<PlanarPatch> =
        unmerged.into_iter().filter_map(|p| p.as_planar().cloned()).collect();
    let merge_config = PipelineConfig::alrf().merge.context("the ALRF preset merges")?;
    let (merged, _) = merge_coplanar(&unmerged, &merge_config)?;
    let extract_s = t.elapsed().as_secs_f64();
    spinner.finish_and_clear();
    let planes_count = merged.len();
    let unmerged_count = unmerged.len();
    let hybrid_trimesh = meshes.len();
    let planes: Vec<Patch> = merged.into_iter().map(Patch::Planar).collect();
    let hybrid: Vec<Patch> = planes.iter().cloned().chain(meshes).collect();
    let unmerged: Vec<Patch> = unmerged.into_iter().map(Patch::Planar).collect();
    let planes_bytes = BBox6dMap::from_patches(planes)?.save(std::io::sink())?;
    let unmerged_bytes = BBox6dMap::from_patches(unmerged)?.save(std::io::sink())?;
    let hybrid_bytes = BBox6dMap::from_patches(hybrid)?.save(std::io::sink())?;
    let pc_bytes = PointCloudMap::from_points(&world_points)?.save(std::io::sink())?;

    writeln!(
        out,
        "\n## 5. Map size versus raw points (thesis Table 6.1, Lab: 29 ALRF scans; \"18× smaller\" = 54.0 / 3.0 MB)"
    )?;
    writeln!(
        out,
        "Ours: {n} simulated ALRF scan(s) of the lab at default noise ({} points), \
         `pipeline::extract` with trimesh growing on the remainder and the pipeline's merging \
         ({extract_s:.1} s); patch maps saved as bbox6d map files.",
        world_points.len()
    )?;
    let ratio = |a: u64, b: u64| if b == 0 { 0.0 } else { a as Real / b as Real };
    let table_rows = vec![
        vec![
            "planes, not merged".to_owned(),
            mb(unmerged_bytes),
            unmerged_count.to_string(),
            "0".to_owned(),
            format!("{:.2}", ratio(unmerged_bytes, planes_bytes)),
            "–".to_owned(),
            "–".to_owned(),
        ],
        vec![
            "planes".to_owned(),
            mb(planes_bytes),
            planes_count.to_string(),
            "0".to_owned(),
            "1.00".to_owned(),
            "3.0".to_owned(),
            "1.00".to_owned(),
        ],
        vec![
            "hybrid".to_owned(),
            mb(hybrid_bytes),
            planes_count.to_string(),
            hybrid_trimesh.to_string(),
            format!("{:.2}", ratio(hybrid_bytes, planes_bytes)),
            "8.7".to_owned(),
            format!("{:.2}", 8.7 / 3.0),
        ],
        vec![
            "pc (binary PLY, f32)".to_owned(),
            mb(ply_bytes),
            "0".to_owned(),
            "0".to_owned(),
            format!("{:.2}", ratio(ply_bytes, planes_bytes)),
            "54.0".to_owned(),
            format!("{:.2}", 54.0 / 3.0),
        ],
        vec![
            "pc (point-cloud map file)".to_owned(),
            mb(pc_bytes),
            "0".to_owned(),
            "0".to_owned(),
            format!("{:.2}", ratio(pc_bytes, planes_bytes)),
            "54.0".to_owned(),
            format!("{:.2}", 54.0 / 3.0),
        ],
    ];
    table(
        out,
        &[
            "map",
            "ours [MB]",
            "planar patches",
            "trimesh patches",
            "ours / planes",
            "thesis [MB]",
            "thesis / planes",
        ],
        &table_rows,
    );
    writeln!(
        out,
        "Ratio: raw PLY / planes map = {:.1}× (point-cloud map file: {:.1}×, raw PLY / \
         unmerged planes {:.1}×, hybrid / planes {:.2}×); thesis: 54.0 / 3.0 = 18.0× (hybrid / \
         planes 2.90×; 5906 planar patches).",
        ratio(ply_bytes, planes_bytes),
        ratio(pc_bytes, planes_bytes),
        ratio(ply_bytes, unmerged_bytes),
        ratio(hybrid_bytes, planes_bytes)
    )?;
    rows.push(json!({
        "table": "map_size", "scans": n, "points": world_points.len(),
        "planes_bytes": planes_bytes, "hybrid_bytes": hybrid_bytes, "ply_bytes": ply_bytes,
        "pc_map_bytes": pc_bytes, "planar_patches": planes_count,
        "unmerged_planar_patches": unmerged_count, "unmerged_planes_bytes": unmerged_bytes,
        "hybrid_trimesh_patches": hybrid_trimesh,
        "ply_over_planes": ratio(ply_bytes, planes_bytes),
        "pc_map_over_planes": ratio(pc_bytes, planes_bytes),
        "hybrid_over_planes": ratio(hybrid_bytes, planes_bytes),
    }));
    Ok(())
}
