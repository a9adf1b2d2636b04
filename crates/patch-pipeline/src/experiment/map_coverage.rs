//! `patchnav experiment map-coverage`: how much of a real scan its planes and hybrid maps
//! hold. For each real scan in the real-data folder (never committed; `--real-dir`), the
//! planes and hybrid maps are extracted with the preset of the scan's sensor kind, and every
//! point counts as covered when a patch lies within `3σ(r)` of it (`σ(r)` the preset's range
//! noise at the point's range). Sizes: the map files against the scan as binary PLY with
//! 32-bit float positions (12 bytes a point). Unorganised scans (3DTK, KITTI-style `.bin`) get
//! their remainder meshed through a spherical range-image grid, with splats for the points no
//! mesh holds (`patch_extract::spherical_grid`, an addition beyond the thesis).

use crate::Progress;
use crate::SensorPreset;
use crate::input::{CloudInput, DepthConvention, read_cloud};
use crate::scene_map::{MapKind, extracted_patches_with};
use anyhow::{Context, Result};
use patch_core::{FromPatches, Patch, Point3, ProximityQuery, Real};
use patch_map::{BBox6dMap, MapFile};
use pointcloud::PointCloud;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::experiment::ByteCount;

/// The settings (defaults: the command line's) of `patchnav experiment map-coverage`.
#[derive(Clone, Debug, PartialEq)]
pub struct MapCoverageSetup {
    /// The real-data folder (each scan's folder holds a SOURCE.md).
    pub real_dir: PathBuf,
    /// Covered within this many σ(r) of a patch.
    pub sigmas: Real,
}

impl Default for MapCoverageSetup {
    fn default() -> MapCoverageSetup {
        MapCoverageSetup { real_dir: PathBuf::from("../shared/data/real"), sigmas: 3.0 }
    }
}

/// One real scan and how to read it.
struct RealScan {
    /// Path under the real-data folder.
    file: &'static str,
    /// The sensor preset of its kind.
    preset: SensorPreset,
    /// Depth-image convention, for PNG depth images.
    depth_camera: Option<DepthConvention>,
}

/// The scans measured: every real range scan of the folder that is a scene (not an object,
/// not a voxel map, not a ToF frame without intrinsics).
const SCANS: [RealScan; 9] = [
    RealScan {
        file: "3dtk_kurt3d_scans/scan000.3d",
        preset: SensorPreset::Alrf,
        depth_camera: None,
    },
    RealScan {
        file: "3dtk_kurt3d_scans/scan001.3d",
        preset: SensorPreset::Alrf,
        depth_camera: None,
    },
    RealScan {
        file: "kitti_velodyne_frontfov/000000.bin",
        preset: SensorPreset::Alrf,
        depth_camera: None,
    },
    RealScan {
        file: "rellis3d_ouster_offroad/000000.bin",
        preset: SensorPreset::Alrf,
        depth_camera: None,
    },
    RealScan {
        file: "pcl_kinect_office/office1.pcd",
        preset: SensorPreset::StructuredLight,
        depth_camera: None,
    },
    RealScan {
        file: "tum_rgbd_kinect_frame/TUM_depth.png",
        preset: SensorPreset::StructuredLight,
        depth_camera: Some(DepthConvention::Tum),
    },
    RealScan {
        file: "pcl_openni_grabber_boxes/frame_20121214T142255.814212.pcd",
        preset: SensorPreset::StructuredLight,
        depth_camera: None,
    },
    RealScan {
        file: "pcl_stereo_table_mug/table_scene_mug_stereo_textured.pcd",
        preset: SensorPreset::StructuredLight,
        depth_camera: None,
    },
    RealScan {
        file: "semantickitti_labelled_scan/000000.bin",
        preset: SensorPreset::Alrf,
        depth_camera: None,
    },
];

/// One row: a scan and its two maps.
#[derive(Clone, Debug, Serialize)]
pub struct CoverageRow {
    /// The scan's path under the real-data folder.
    pub scan: String,
    /// Whether it has a pixel grid.
    pub organised: bool,
    /// Its points.
    pub points: usize,
    /// Share of points within `sigmas · σ(r)` of the planes map.
    pub planes_coverage: Real,
    /// Share of points within `sigmas · σ(r)` of the hybrid map.
    pub hybrid_coverage: Real,
    /// Planes map file bytes.
    pub planes_bytes: u64,
    /// Hybrid map file bytes.
    pub hybrid_bytes: u64,
    /// Trimesh patches of the hybrid map (grown meshes and, for unorganised scans, splat
    /// groups).
    pub hybrid_trimesh_patches: usize,
    /// Triangles of those trimesh patches.
    pub hybrid_triangles: usize,
}

impl CoverageRow {
    /// The scan as binary PLY with float positions, bytes.
    pub fn ply_bytes(&self) -> u64 {
        12 * self.points as u64
    }
}

/// The share of `points` (world frame; `ranges` their sensor ranges) within `sigmas · σ(r)`
/// of `map`.
fn coverage(
    map: &impl ProximityQuery,
    points: &[Point3],
    ranges: &[Real],
    sigma: impl Fn(Real) -> Real,
    sigmas: Real,
) -> Real {
    if points.is_empty() {
        return 0.0;
    }
    let covered = points
        .iter()
        .zip(ranges)
        .filter(|(p, r)| map.closest_patch(p, sigmas * sigma(**r)).is_some())
        .count();
    covered as Real / points.len() as Real
}

/// The coverage row of one scan, or `None` if its file is missing.
///
/// # Errors
/// A file that cannot be read, or extraction refusing its parameters.
pub fn coverage_row(
    dir: &Path,
    scan: &str,
    preset: SensorPreset,
    depth_camera: Option<DepthConvention>,
    sigmas: Real,
) -> Result<Option<CoverageRow>> {
    let path = dir.join(scan);
    if !path.is_file() {
        return Ok(None);
    }
    let cloud: PointCloud =
        read_cloud(&path, &CloudInput { skip_non_finite: true, depth: depth_camera })
            .with_context(|| format!("reading {}", path.display()))?;
    cloud_coverage(scan, &cloud, preset, sigmas).map(Some)
}

/// The coverage row of `cloud` (a scan in its sensor frame, with its pose), named `scan`.
///
/// # Errors
/// Extraction refusing its parameters.
pub fn cloud_coverage(
    scan: &str,
    cloud: &PointCloud,
    preset: SensorPreset,
    sigmas: Real,
) -> Result<CoverageRow> {
    let (pipeline, grow) = preset.configs();
    let noise = pipeline.segment.noise;
    let ranges: Vec<Real> = cloud.positions().iter().map(|p| p.coords.norm()).collect();
    let world = cloud.to_world();
    let clouds = std::slice::from_ref(cloud);
    let mut out = CoverageRow {
        scan: scan.to_owned(),
        organised: cloud.grid().is_some(),
        points: cloud.len(),
        planes_coverage: 0.0,
        hybrid_coverage: 0.0,
        planes_bytes: 0,
        hybrid_bytes: 0,
        hybrid_trimesh_patches: 0,
        hybrid_triangles: 0,
    };
    for kind in [MapKind::Planes, MapKind::Hybrid] {
        let patches = extracted_patches_with(clouds, kind, pipeline.clone(), grow, None)?
            .context("patch maps have patches")?;
        if kind == MapKind::Hybrid {
            let meshes: Vec<_> = patches.iter().filter_map(Patch::as_trimesh).collect();
            out.hybrid_trimesh_patches = meshes.len();
            out.hybrid_triangles = meshes.iter().map(|m| m.triangles().len()).sum();
        }
        let map = BBox6dMap::from_patches(patches)?;
        let mut bytes = ByteCount(0);
        map.save(&mut bytes)?;
        let c = coverage(&map, world.positions(), &ranges, |r| noise.sigma(r), sigmas);
        match kind {
            MapKind::Planes => (out.planes_coverage, out.planes_bytes) = (c, bytes.0),
            _ => (out.hybrid_coverage, out.hybrid_bytes) = (c, bytes.0),
        }
    }
    Ok(out)
}

/// Runs `patchnav experiment map-coverage`.
pub fn run(args: &MapCoverageSetup, progress: &dyn Progress) -> Result<()> {
    let mut rows = Vec::new();
    let mut out = String::new();
    for s in &SCANS {
        let spinner = progress.spinner(s.file);
        let row = coverage_row(&args.real_dir, s.file, s.preset, s.depth_camera, args.sigmas)?;
        spinner.finish_and_clear();
        match row {
            Some(r) => rows.push(r),
            None => writeln!(out, "{}: not found, skipped", args.real_dir.join(s.file).display())?,
        }
    }
    writeln!(
        out,
        "| scan | organised | points | planes covered % | hybrid covered % | planes bytes | hybrid bytes | scan as PLY / planes | scan as PLY / hybrid | hybrid trimesh patches | hybrid triangles |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|---|---|---|---|---|")?;
    for r in &rows {
        let ratio = |b: u64| r.ply_bytes() as Real / b.max(1) as Real;
        writeln!(
            out,
            "| {} | {} | {} | {:.2} | {:.2} | {} | {} | {:.0}× | {:.1}× | {} | {} |",
            r.scan,
            if r.organised { "yes" } else { "no" },
            r.points,
            100.0 * r.planes_coverage,
            100.0 * r.hybrid_coverage,
            r.planes_bytes,
            r.hybrid_bytes,
            ratio(r.planes_bytes),
            ratio(r.hybrid_bytes),
            r.hybrid_trimesh_patches,
            r.hybrid_triangles
        )?;
    }
    print!("{out}");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene_map::{ScanSetup, scan_clouds};

    /// Hybrid maps of organised real scans hold ≥ 99 % of their points (issue's contract); the
    /// data is read from the shared real-data folder and never committed.
    #[test]
    fn hybrid_maps_cover_organised_real_scans() {
        // Missing data skips outside CI and fails in it (`shared_data`).
        let Some(dir) = shared_data::real_data("") else { return };
        for s in SCANS.iter().filter(|s| s.file.contains("boxes") || s.file.contains("stereo")) {
            let r = coverage_row(&dir, s.file, s.preset, s.depth_camera, 3.0).unwrap();
            let r = r.unwrap_or_else(|| panic!("{}: missing from {}", s.file, dir.display()));
            assert!(r.organised, "{}", s.file);
            assert!(
                r.hybrid_coverage >= 0.99,
                "{}: hybrid covers {:.4}",
                s.file,
                r.hybrid_coverage
            );
            assert!(r.planes_coverage >= 0.95, "{}: planes cover {:.4}", s.file, r.planes_coverage);
            assert!(r.ply_bytes() >= 40 * r.planes_bytes, "{}: planes map too large", s.file);
        }
    }

    /// Hybrid maps of unorganised scans hold ≥ 99 % of their points, their remainder meshed
    /// through a spherical grid (not in the thesis): always a simulated ALRF scan of the lab
    /// stripped of its pixel grid, and the real 3DTK Kurt3D scan when the real-data folder has
    /// it (its planes map alone holds about 91 %).
    #[test]
    fn hybrid_maps_cover_unorganised_scans() {
        let lab = scene_sim::lab(0).unwrap();
        let setup = ScanSetup { scans: 1, height: 0.5, step_deg: Some(1.0), seed: 3, noise: 1.0 };
        let mut cloud = scan_clouds(&lab, &setup).unwrap().remove(0);
        cloud.set_grid(None).unwrap();
        let r = cloud_coverage("simulated lab", &cloud, SensorPreset::Alrf, 3.0).unwrap();
        assert!(!r.organised);
        assert!(r.hybrid_coverage >= 0.99, "simulated lab: hybrid covers {:.4}", r.hybrid_coverage);
        assert!(r.hybrid_trimesh_patches > 0 && r.hybrid_coverage > r.planes_coverage, "{r:?}");

        let scan = "3dtk_kurt3d_scans/scan000.3d";
        let Some(path) = shared_data::real_data(scan) else { return };
        let dir = path.ancestors().nth(2).expect("the real-data folder");
        let r = coverage_row(dir, scan, SensorPreset::Alrf, None, 3.0).unwrap().expect("found");
        assert!(!r.organised);
        assert!(r.hybrid_coverage >= 0.99, "{scan}: hybrid covers {:.4}", r.hybrid_coverage);
        assert!(r.planes_coverage < r.hybrid_coverage, "{r:?}");
    }
}
