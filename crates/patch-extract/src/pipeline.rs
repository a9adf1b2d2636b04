//! One call from scans to patches (thesis §5.3 and the Ch.6 pipeline, L5341–5343, L6580–6700):
//! per scan, plane segmentation ([`mod@crate::segment`]) → early orthogonal projection, α-shape,
//! Douglas–Peucker ([`crate::polygonize`]) → planar patches; optionally trimesh growing on the
//! remainder ([`crate::trimesh_grow`], the thesis's hybrid maps); every patch moved to the world
//! by the scan's pose; then optionally outline merging across scans ([`crate::merge`]). Every
//! stage is timed.
//!
//! Scans are organised or unorganised [`PointCloud`]s **in their sensor frame** with their
//! [`PointCloud::sensor_pose`] set (as range images and simulated scans give them); a cloud
//! without a pose is taken as a scan from the world origin. Trimesh growing needs a pixel
//! grid: the remainder of an unorganised scan is binned into a spherical range-image grid
//! around its sensor first ([`crate::spherical_grid`], an addition beyond the thesis, whose
//! hybrid maps mesh organised scans only), when [`PipelineConfig::unorganised`] asks for it.
//!
//! A region that polygonisation refuses (too few distinct points after projection, a degenerate
//! outline) is counted in [`ScanReport::failed_regions`] with its reason in
//! [`ScanReport::failures`]; it never stops the pipeline. Extraction from actuated-LRF scans
//! should first drop the ±90° columns ([`crate::projection::invalidate_alrf_side_columns`],
//! thesis App. A), which needs the scan's beam model and so is the caller's step.

use std::num::NonZeroUsize;

use crate::denoise::{BeamDenoiseConfig, DenoiseError, denoise_along_beams_where};
use crate::fill::{FillError, fill_upward_holes};
use crate::grid_mesh::RegionMask;
use crate::merge::{MergeConfig, MergeError, MergeStats, merge_coplanar};
use crate::mixed_pixels::{MixedPixelConfig, MixedPixelError, remove_mixed_pixels};
use crate::polygonize::{PolygonizeConfig, pixels_of_points, polygonize_region_with};
use crate::segment::{SegmentConfig, SegmentError, segment_remainder, segment_with_threads};
use crate::slab::{SlabError, back_faces};
use crate::spherical_grid::{SphericalGridConfig, SphericalGridError, mesh_unorganised};
use crate::trimesh_grow::{GrownTrimeshes, TrimeshGrowConfig, TrimeshGrowError, grow_trimeshes_in};
use crate::visibility::{Carved, FreeSpace, VisibilityConfig, VisibilityError};
use patch_core::{Isometry3, Patch, PlanarPatch, Real, Vector3};
use pointcloud::PointCloud;
use std::time::{Duration, Instant};

/// [`PipelineConfig::alrf`]'s slab thickness, metres: the thinnest boards and table tops of
/// indoor scenes (2–4 cm). Measured on the lab (8 scans, scene seed 0, step seed 1, holes not
/// filled; unsafe / overcautious %): planes map none 2.77 / 1.28, 2 cm 2.41 / 1.40, 4 cm
/// 2.12 / 1.52, 6 cm 1.97 / 1.71, 8 cm 1.85 / 1.91; hybrid map none 1.16 / 1.85, 2 cm
/// 0.92 / 1.94, 4 cm 0.76 / 2.05, 6 cm 0.71 / 2.21, 8 cm 0.64 / 2.39. With the holes filled,
/// 3 cm gives planes 2.01 / 1.46 and hybrid 0.62 / 2.00, 4 cm 1.87 / 1.52 and 0.53 / 2.05:
/// the safer one is kept.
pub const ALRF_SLAB_THICKNESS: Real = 0.04;

/// [`PipelineConfig::alrf`]'s tilt limit for filling holes, radians (30°): floors and table
/// tops, and ramps a wheeled robot drives on.
pub const ALRF_FILL_TILT: Real = std::f64::consts::FRAC_PI_6;

/// Every stage's parameters. No `Default`: start from a sensor preset.
#[derive(Clone, Debug, PartialEq)]
pub struct PipelineConfig {
    /// Plane segmentation.
    pub segment: SegmentConfig,
    /// A second segmentation of each organised scan's remainder, usually with smaller seed
    /// windows and regions ([`crate::segment::segment_remainder`], not in the thesis); `None`:
    /// one pass.
    pub second_pass: Option<SegmentConfig>,
    /// Projection, outline and simplification of each region.
    pub polygonize: PolygonizeConfig,
    /// Trimesh growing on the remainder (hybrid maps, thesis §6.1); `None`: planes only.
    pub remainder: Option<TrimeshGrowConfig>,
    /// Outline merging across scans; `None`: every scan's patches are kept as they are.
    pub merge: Option<MergeConfig>,
    /// Mixed pixels removed from each organised scan before segmentation
    /// ([`mod@crate::mixed_pixels`]); `None`: scans are segmented as they are (the thesis).
    /// Unorganised scans are never filtered.
    pub mixed_pixels: Option<MixedPixelConfig>,
    /// With `remainder`: how the remainder of an unorganised scan gets the pixel grid trimesh
    /// growing needs ([`crate::spherical_grid`], an addition beyond the thesis); `None`: the
    /// remainder of unorganised scans is not meshed (organised scans are meshed either way).
    /// Every preset sets [`SphericalGridConfig::estimated`].
    pub unorganised: Option<SphericalGridConfig>,
    /// With `remainder`: each organised scan denoised along its beams before its remainder is
    /// meshed ([`crate::denoise`], not in the thesis); `None`: meshed as measured. Planar
    /// regions fit their planes to the raw points either way.
    pub denoise: Option<BeamDenoiseConfig>,
    /// Each planar patch, after merging, gets a back face this many metres behind the side it
    /// was seen from, so that maps hold slabs ([`crate::slab`], not in the thesis); `None`:
    /// bare surfaces.
    pub slab_thickness: Option<Real>,
    /// After merging, the holes of planar patches facing up (normal within this many radians
    /// of the world's +z) are filled ([`crate::fill`], not in the thesis); `None`: outlines
    /// keep their holes.
    pub fill_upward_holes: Option<Real>,
    /// With `remainder`: the triangles of the remainder meshes that another scan saw through
    /// are dropped ([`crate::visibility`], not in the thesis): veils across depth jumps.
    /// `None`: every triangle stays.
    pub carve: Option<VisibilityConfig>,
}

impl PipelineConfig {
    /// For actuated-LRF scans (S300-like, 1–3 cm noise): [`SegmentConfig::alrf`], a second
    /// pass over the remainder ([`SegmentConfig::alrf_second_pass`]),
    /// [`PolygonizeConfig::conservative`] (outlines grown to cover what the scan saw),
    /// merging with [`MergeConfig::alrf`], no remainder meshes, no mixed-pixel filter (on the
    /// lab it removes real obstacle points: planes map unsafe 2.8 → 3.7 %; see
    /// `patchnav experiment map-safety`), the holes of upward-facing patches filled
    /// ([`ALRF_FILL_TILT`]), slabs [`ALRF_SLAB_THICKNESS`] thick. No free-space carving of
    /// the remainder meshes (`carve`): on the tuning seed it lets a few more colliding steps
    /// through (docs/map-safety.md, item 12); set it to [`VisibilityConfig::alrf`] to trade
    /// them for fewer blocked free steps.
    pub fn alrf() -> PipelineConfig {
        PipelineConfig {
            segment: SegmentConfig::alrf(),
            second_pass: Some(SegmentConfig::alrf_second_pass()),
            polygonize: PolygonizeConfig::conservative(),
            remainder: None,
            merge: Some(MergeConfig::alrf()),
            mixed_pixels: None,
            unorganised: Some(SphericalGridConfig::estimated()),
            denoise: Some(BeamDenoiseConfig::alrf()),
            slab_thickness: Some(ALRF_SLAB_THICKNESS),
            fill_upward_holes: Some(ALRF_FILL_TILT),
            carve: None,
        }
    }

    /// The ALRF pipeline as the thesis describes it: no mixed-pixel filter, the strict
    /// incidence test ([`SegmentConfig::alrf`] without [`crate::GrazingPlanes`]), α-shape
    /// outlines as found ([`PolygonizeConfig::thesis`]), remainders meshed as measured; for
    /// reproducing the thesis's tables.
    pub fn alrf_thesis() -> PipelineConfig {
        PipelineConfig {
            segment: SegmentConfig { grazing: None, ..SegmentConfig::alrf() },
            second_pass: None,
            polygonize: PolygonizeConfig::thesis(),
            denoise: None,
            slab_thickness: None,
            fill_upward_holes: None,
            carve: None,
            ..PipelineConfig::alrf()
        }
    }

    /// For range-camera frames (SR-3000-like): [`SegmentConfig::range_camera`],
    /// [`PolygonizeConfig::thinned`] (the thesis's outlines from the points along each
    /// region's pixel outline), merging with [`MergeConfig::alrf`], no remainder meshes.
    pub fn range_camera() -> PipelineConfig {
        PipelineConfig {
            segment: SegmentConfig::range_camera(),
            second_pass: None,
            polygonize: PolygonizeConfig::thinned(),
            remainder: None,
            merge: Some(MergeConfig::alrf()),
            mixed_pixels: None,
            unorganised: Some(SphericalGridConfig::estimated()),
            denoise: None,
            slab_thickness: None,
            fill_upward_holes: None,
            carve: None,
        }
    }

    /// For structured-light depth frames (Kinect-like): [`SegmentConfig::structured_light`],
    /// [`PolygonizeConfig::thinned`], merging with [`MergeConfig::alrf`], no remainder meshes.
    pub fn structured_light() -> PipelineConfig {
        PipelineConfig {
            segment: SegmentConfig::structured_light(),
            second_pass: None,
            polygonize: PolygonizeConfig::thinned(),
            remainder: None,
            merge: Some(MergeConfig::alrf()),
            mixed_pixels: None,
            unorganised: Some(SphericalGridConfig::estimated()),
            denoise: None,
            slab_thickness: None,
            fill_upward_holes: None,
            carve: None,
        }
    }

    /// For noise-free scans of synthetic scenes: [`SegmentConfig::exact`],
    /// [`PolygonizeConfig::thesis`], merging with [`MergeConfig::exact`].
    pub fn exact() -> PipelineConfig {
        PipelineConfig {
            segment: SegmentConfig::exact(),
            second_pass: None,
            polygonize: PolygonizeConfig::thesis(),
            remainder: None,
            merge: Some(MergeConfig::exact()),
            mixed_pixels: None,
            unorganised: Some(SphericalGridConfig::estimated()),
            denoise: None,
            slab_thickness: None,
            fill_upward_holes: None,
            carve: None,
        }
    }

    /// This configuration with trimesh patches for the remainder (a hybrid map).
    pub fn with_remainder(mut self, config: TrimeshGrowConfig) -> PipelineConfig {
        self.remainder = Some(config);
        self
    }
}

/// Why the pipeline stopped. Bad regions do not stop it (see [`ScanReport::failures`]).
#[derive(Debug, thiserror::Error)]
pub enum ExtractError {
    /// The segmentation refused its parameters.
    #[error("scan {scan}: segmentation: {source}")]
    Segment {
        /// Index of the scan.
        scan: usize,
        /// The reason.
        source: SegmentError,
    },
    /// The spherical grid of an unorganised scan (or trimesh growing on it) refused its
    /// parameters.
    #[error("scan {scan}: spherical grid: {source}")]
    SphericalGrid {
        /// Index of the scan.
        scan: usize,
        /// The reason.
        source: SphericalGridError,
    },
    /// Trimesh growing refused its parameters.
    #[error("scan {scan}: trimesh growing: {source}")]
    Trimesh {
        /// Index of the scan.
        scan: usize,
        /// The reason.
        source: TrimeshGrowError,
    },
    /// Merging refused its parameters.
    #[error("merging: {0}")]
    Merge(#[from] MergeError),
    /// The slab thickness is out of range.
    #[error(transparent)]
    Slab(#[from] SlabError),
    /// The tilt limit for filling holes is out of range.
    #[error(transparent)]
    Fill(#[from] FillError),
    /// Beam denoising refused its parameters.
    #[error("scan {scan}: beam denoising: {source}")]
    Denoise {
        /// Index of the scan.
        scan: usize,
        /// The reason.
        source: DenoiseError,
    },
    /// The mixed-pixel filter refused its parameters.
    #[error("scan {scan}: mixed-pixel filter: {source}")]
    MixedPixels {
        /// Index of the scan.
        scan: usize,
        /// The reason.
        source: MixedPixelError,
    },
    /// Free-space carving refused its parameters or a scan.
    #[error(transparent)]
    Carve(#[from] VisibilityError),
    /// A scan's pose is not finite.
    #[error("scan {scan}: the sensor pose is not finite")]
    BadPose {
        /// Index of the scan.
        scan: usize,
    },
}

/// What happened to one scan.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ScanReport {
    /// Valid points of the scan.
    pub points: usize,
    /// Planar regions found.
    pub regions: usize,
    /// Points in planar regions.
    pub region_points: usize,
    /// Of the regions, those found by the second pass over the remainder
    /// ([`PipelineConfig::second_pass`]).
    pub second_pass_regions: usize,
    /// Planar patches made from the regions.
    pub planar_patches: usize,
    /// Regions that could not be polygonised.
    pub failed_regions: usize,
    /// The first few reasons (at most 8), for diagnosis.
    pub failures: Vec<String>,
    /// Points in no region.
    pub remainder_points: usize,
    /// Mixed pixels removed before segmentation.
    pub mixed_pixels: usize,
    /// Trimesh patches grown on the remainder.
    pub trimesh_patches: usize,
    /// Remainder points of an unorganised scan that got a cell of its spherical grid (the
    /// others shared a cell with a nearer point, or lay nearer than its `min_range`); 0 for
    /// organised scans.
    pub binned_remainder: usize,
    /// Splats (one triangle each) for remainder points of an unorganised scan that no grown
    /// mesh holds ([`crate::spherical_grid::mesh_unorganised`]). They and the grown meshes
    /// smaller than the grow config's `min_triangles` are grouped into trimesh patches of
    /// their own in [`Extraction::patches`], not counted in `trimesh_patches`.
    pub splats: usize,
    /// Outline vertices before and after simplification, summed over the regions.
    pub outline_vertices: (usize, usize),
    /// Remainder-mesh triangles tested and dropped by free-space carving
    /// ([`PipelineConfig::carve`]).
    pub carved: Carved,
}

/// Wall time per stage, summed over the scans.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct StageTimes {
    /// The mixed-pixel filter.
    pub mixed_pixels: Duration,
    /// Plane segmentation.
    pub segmentation: Duration,
    /// Projection, outlines, simplification, patch building.
    pub polygonization: Duration,
    /// Trimesh growing on the remainders.
    pub trimesh: Duration,
    /// Outline merging across scans.
    pub merging: Duration,
    /// Free-space carving: indexing every scan's beams, testing the remainder meshes.
    pub carving: Duration,
}

impl StageTimes {
    /// Adds `other`'s stages to these.
    pub fn add(&mut self, other: &StageTimes) {
        self.mixed_pixels += other.mixed_pixels;
        self.segmentation += other.segmentation;
        self.polygonization += other.polygonization;
        self.trimesh += other.trimesh;
        self.merging += other.merging;
        self.carving += other.carving;
    }

    /// The sum of the stages.
    pub fn total(&self) -> Duration {
        self.mixed_pixels
            + self.segmentation
            + self.polygonization
            + self.trimesh
            + self.merging
            + self.carving
    }
}

/// The patches of a set of scans, in the world frame, and how they were made.
#[derive(Clone, Debug, Default)]
pub struct Extraction {
    /// Planar patches first (merged if asked), then the trimesh patches (per scan: the grown
    /// meshes, then an unorganised scan's groups of splats and small meshes).
    pub patches: Vec<Patch>,
    /// The planar patches' back faces ([`PipelineConfig::slab_thickness`]), in their order;
    /// empty without.
    pub back_faces: Vec<Patch>,
    /// Holes filled in upward-facing patches ([`PipelineConfig::fill_upward_holes`]).
    pub filled_holes: usize,
    /// One report per scan.
    pub scans: Vec<ScanReport>,
    /// What merging did, if it ran.
    pub merge: Option<MergeStats>,
    /// Time per stage.
    pub times: StageTimes,
}

impl Extraction {
    /// The patches a map holds: the surfaces and their back faces.
    pub fn into_map_patches(self) -> Vec<Patch> {
        let mut patches = self.patches;
        patches.extend(self.back_faces);
        patches
    }
}

/// Extracts the patches of `scans` (see the module docs) on all cores: the scans are shared
/// among [`std::thread::available_parallelism`] threads and their results joined in scan
/// order, so the output equals [`extract_with_threads`]'s on one thread. `progress` is called
/// with each scan's index, in order, once the scans before it are done too.
///
/// # Errors
/// [`ExtractError`] for refused parameters or a non-finite pose (the first scan's error, in
/// scan order); never for the content of a scan (see [`ScanReport::failures`]).
pub fn extract(
    scans: &[PointCloud],
    config: &PipelineConfig,
    progress: impl FnMut(usize),
) -> Result<Extraction, ExtractError> {
    let threads = std::thread::available_parallelism().unwrap_or(NonZeroUsize::MIN);
    extract_with_threads(scans, config, threads, progress)
}

/// [`extract`] on at most `threads` threads (one: no thread is started). The result does not
/// depend on the count; [`StageTimes`] sum the stages over the scans, so with several threads
/// they exceed the wall time.
///
/// # Errors
/// As [`extract`].
pub fn extract_with_threads(
    scans: &[PointCloud],
    config: &PipelineConfig,
    threads: NonZeroUsize,
    mut progress: impl FnMut(usize),
) -> Result<Extraction, ExtractError> {
    let mut out = Extraction::default();
    let free_space = match (&config.carve, &config.remainder) {
        (Some(carve), Some(_)) => {
            let t = Instant::now();
            let space = FreeSpace::new(scans, carve)?;
            out.times.carving += t.elapsed();
            Some(space)
        }
        _ => None,
    };
    let free_space = free_space.as_ref();
    let requested = threads.get();
    let threads = requested.min(scans.len());
    // Threads left over per scan (fewer scans than threads) go to its segmentation's seeds.
    let inner = NonZeroUsize::new(requested / threads.max(1)).unwrap_or(NonZeroUsize::MIN);
    let mut parts: Vec<Option<Result<ScanPart, ExtractError>>> = Vec::new();
    parts.resize_with(scans.len(), || None);
    let mut reported = 0;
    let mut report_done = |parts: &[Option<Result<ScanPart, ExtractError>>]| {
        while reported < parts.len() && parts[reported].is_some() {
            progress(reported);
            reported += 1;
        }
    };
    if threads <= 1 {
        for (index, scan) in scans.iter().enumerate() {
            parts[index] = Some(extract_scan(index, scan, config, free_space, inner));
            report_done(&parts);
        }
    } else {
        let next = std::sync::atomic::AtomicUsize::new(0);
        let (sender, receiver) = std::sync::mpsc::channel();
        std::thread::scope(|s| {
            for _ in 0..threads {
                let (next, sender) = (&next, sender.clone());
                s.spawn(move || {
                    loop {
                        let index = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(scan) = scans.get(index) else { break };
                        let part = extract_scan(index, scan, config, free_space, inner);
                        if sender.send((index, part)).is_err() {
                            break;
                        }
                    }
                });
            }
            drop(sender);
            for (index, part) in receiver {
                parts[index] = Some(part);
                report_done(&parts);
            }
        });
    }
    let mut planar: Vec<PlanarPatch> = Vec::new();
    let mut meshes: Vec<Patch> = Vec::new();
    for part in parts {
        // Every index was taken by a worker, and each sent its part before it ended.
        let Some(part) = part else { unreachable!("a scan without a result") };
        let part = part?;
        out.times.add(&part.times);
        out.scans.push(part.report);
        planar.extend(part.planar);
        meshes.extend(part.meshes);
    }
    if let Some(merge) = &config.merge {
        let t = Instant::now();
        let (merged, stats) = merge_coplanar(&planar, merge)?;
        planar = merged;
        out.merge = Some(stats);
        out.times.merging += t.elapsed();
    }
    if let Some(tilt) = config.fill_upward_holes {
        out.filled_holes = fill_upward_holes(&mut planar, &Vector3::z(), tilt)?;
    }
    if let Some(t) = config.slab_thickness {
        out.back_faces = back_faces(&planar, t)?.into_iter().map(Patch::Planar).collect();
    }
    out.patches = planar.into_iter().map(Patch::Planar).chain(meshes).collect();
    Ok(out)
}

/// What one scan gives: its report, its patches in the world frame, the time of its stages.
struct ScanPart {
    report: ScanReport,
    planar: Vec<PlanarPatch>,
    meshes: Vec<Patch>,
    times: StageTimes,
}

/// The per-scan stages of [`extract`] on scan `index`.
fn extract_scan(
    index: usize,
    scan: &PointCloud,
    config: &PipelineConfig,
    free_space: Option<&FreeSpace>,
    threads: NonZeroUsize,
) -> Result<ScanPart, ExtractError> {
    let mut times = StageTimes::default();
    let mut planar: Vec<PlanarPatch> = Vec::new();
    let mut meshes: Vec<Patch> = Vec::new();
    let motion = match scan.sensor_pose() {
        Some(pose) if !pose.is_finite() => return Err(ExtractError::BadPose { scan: index }),
        Some(pose) => pose.world_from_sensor,
        None => Isometry3::identity(),
    };
    let mut report = ScanReport { points: scan.len(), ..ScanReport::default() };
    let filtered;
    let scan = match (&config.mixed_pixels, scan.grid()) {
        (Some(filter), Some(_)) => {
            let t = Instant::now();
            let (kept, removed) = remove_mixed_pixels(scan, filter)
                .map_err(|source| ExtractError::MixedPixels { scan: index, source })?;
            times.mixed_pixels += t.elapsed();
            report.mixed_pixels = removed;
            filtered = kept;
            &filtered
        }
        _ => scan,
    };
    let t = Instant::now();
    let mut segmentation = segment_with_threads(scan, &config.segment, threads)
        .map_err(|source| ExtractError::Segment { scan: index, source })?;
    if let Some(second) = &config.second_pass {
        report.second_pass_regions = segment_remainder(scan, &mut segmentation, second)
            .map_err(|source| ExtractError::Segment { scan: index, source })?;
    }
    times.segmentation += t.elapsed();
    report.regions = segmentation.regions.len();
    report.region_points = segmentation.regions.iter().map(|r| r.points.len()).sum();
    report.remainder_points = segmentation.remainder.len();

    let t = Instant::now();
    let pixel_of = match (config.polygonize.thinning, scan.grid()) {
        (Some(_), Some(grid)) => Some(pixels_of_points(grid, scan.len())),
        _ => None,
    };
    for region in &segmentation.regions {
        match polygonize_region_with(scan, region, &config.polygonize, pixel_of.as_deref()) {
            Ok(p) => {
                report.planar_patches += p.patches.len();
                report.outline_vertices.0 += p.vertices_before;
                report.outline_vertices.1 += p.vertices_after;
                planar.extend(p.patches.iter().map(|patch| patch.transformed(&motion)));
            }
            Err(e) => {
                report.failed_regions += 1;
                if report.failures.len() < 8 {
                    report.failures.push(e.to_string());
                }
            }
        }
    }
    times.polygonization += t.elapsed();

    if let Some(grow) = &config.remainder {
        let t = Instant::now();
        let mut scattered = Vec::new();
        let grown = match (scan.grid(), &config.unorganised) {
            (Some(grid), _) => {
                let mask = RegionMask::from_points(grid, &segmentation.remainder);
                let denoised;
                let scan = match &config.denoise {
                    Some(d) => {
                        let mut in_remainder = vec![false; scan.len()];
                        for &i in &segmentation.remainder {
                            in_remainder[i as usize] = true;
                        }
                        denoised = denoise_along_beams_where(scan, d, |i| in_remainder[i])
                            .map_err(|source| ExtractError::Denoise { scan: index, source })?
                            .0;
                        &denoised
                    }
                    None => scan,
                };
                grow_trimeshes_in(scan, &mask, grow)
                    .map_err(|source| ExtractError::Trimesh { scan: index, source })?
            }
            (None, Some(spherical)) => {
                let noise = config.segment.noise;
                let made = mesh_unorganised(
                    scan.positions(),
                    &segmentation.remainder,
                    spherical,
                    grow,
                    &|r| noise.sigma(r),
                )
                .map_err(|source| ExtractError::SphericalGrid { scan: index, source })?;
                report.binned_remainder = made.binned;
                report.splats = made.splat_triangles;
                scattered = made.scattered;
                made.grown
            }
            (None, None) => GrownTrimeshes::default(),
        };
        report.trimesh_patches = grown.meshes.len();
        let grown = grown.into_patches().into_iter().chain(scattered);
        let grown = grown.map(|m| m.transformed(&motion));
        times.trimesh += t.elapsed();
        match &free_space {
            Some(space) => {
                let t = Instant::now();
                let grown: Vec<_> = grown.collect();
                let (kept, carved) = space.carve_trimeshes(&grown, Some(index));
                report.carved = carved;
                meshes.extend(kept.into_iter().map(Patch::Trimesh));
                times.carving += t.elapsed();
            }
            None => meshes.extend(grown.map(Patch::Trimesh)),
        }
    }
    Ok(ScanPart { report, planar, meshes, times })
}
