//! `patchnav extract SCANS... --out MAP [--backend B] [--sensor S] [--hybrid] [--no-merge]
//! [--poses FILE] [--export FILE.obj]`: planar patches (and, with `--hybrid`, trimesh patches
//! for the non-planar remainder) from range scans, merged across scans, written as a map file
//! of any patch backend (thesis §5.3, §6.1; `patch_extract::pipeline`).
//!
//! Each scan is read in its sensor frame with its pose: PLY files written by `patchnav
//! simulate` carry it, PCD files have `VIEWPOINT`, 3DTK `.3d` scans the sibling `.pose` file.
//! `--poses FILE` overrides them with the `poses.json` layout `patchnav simulate` writes
//! (`{"scans": [{"file": NAME, "world_from_sensor": 4×4 rows}, ...]}`, matched by file name).

use crate::input::InputArgs;
use crate::map::{BackendChoice, save_patches};
use crate::progress::Progress;
use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use patch_core::na;
use patch_core::triangulate::patch_triangles;
use patch_core::{Isometry3, Patch, Point3, Real};
use patch_extract::pipeline::{PipelineConfig, extract};
use patch_extract::trimesh_grow::TrimeshGrowConfig;
use pointcloud::{PointCloud, PolygonMesh, SensorPose};
use serde_json::Value;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Sensor presets of the pipeline's thresholds.
#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum SensorPreset {
    /// Actuated laser range finder (S300-like, 1–3 cm noise).
    Alrf,
    /// Time-of-flight range camera (SR-3000-like).
    RangeCamera,
    /// Noise-free synthetic scans.
    Exact,
}

/// Arguments of `patchnav extract`.
#[derive(Args, Debug)]
pub struct ExtractArgs {
    /// Scans in their sensor frame with their pose (.ply .pcd .3d .bin .xyz .png).
    #[arg(required = true)]
    pub scans: Vec<PathBuf>,
    /// The map file to write.
    #[arg(long, required_unless_present = "export")]
    pub out: Option<PathBuf>,
    /// The backend of the map file.
    #[arg(long, value_enum, default_value_t = BackendChoice::Bbox6d)]
    pub backend: BackendChoice,
    /// For `--backend pointcloud`: sample the patches every SPACING metres.
    #[arg(long)]
    pub spacing: Option<f64>,
    /// Threshold presets (segmentation noise model, trimesh growing, merging tolerances).
    #[arg(long, value_enum, default_value_t = SensorPreset::Alrf)]
    pub sensor: SensorPreset,
    /// Also grow trimesh patches on the points in no plane (the thesis's hybrid map).
    #[arg(long)]
    pub hybrid: bool,
    /// Keep every scan's patches instead of merging coplanar overlapping ones.
    #[arg(long)]
    pub no_merge: bool,
    /// A poses JSON overriding the scans' own poses.
    #[arg(long)]
    pub poses: Option<PathBuf>,
    /// Also write the patches, triangulated, as an OBJ mesh for any 3D viewer.
    #[arg(long)]
    pub export: Option<PathBuf>,
    #[command(flatten)]
    pub input: InputArgs,
}

fn config(args: &ExtractArgs) -> PipelineConfig {
    let (mut config, grow) = match args.sensor {
        SensorPreset::Alrf => (PipelineConfig::alrf(), TrimeshGrowConfig::alrf()),
        SensorPreset::RangeCamera => {
            (PipelineConfig::range_camera(), TrimeshGrowConfig::range_camera())
        }
        SensorPreset::Exact => (PipelineConfig::exact(), TrimeshGrowConfig::range_camera()),
    };
    if args.hybrid {
        config.remainder = Some(grow);
    }
    if args.no_merge {
        config.merge = None;
    }
    config
}

/// Reads a `poses.json`: file name → `world_from_sensor`.
fn read_poses(path: &Path) -> Result<HashMap<String, Isometry3>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let v: Value =
        serde_json::from_str(&text).with_context(|| format!("{} is not JSON", path.display()))?;
    let scans = v
        .get("scans")
        .and_then(Value::as_array)
        .with_context(|| format!("{}: no `scans` array", path.display()))?;
    let mut out = HashMap::new();
    for (i, s) in scans.iter().enumerate() {
        let what = || format!("{}: scans[{i}]", path.display());
        let file = s
            .get("file")
            .and_then(Value::as_str)
            .with_context(|| format!("{}: `file` is missing", what()))?;
        let rows = s
            .get("world_from_sensor")
            .and_then(Value::as_array)
            .with_context(|| format!("{}: `world_from_sensor` is missing", what()))?;
        let m: Vec<Real> = rows
            .iter()
            .flat_map(|r| r.as_array().into_iter().flatten())
            .map(|x| x.as_f64().unwrap_or(Real::NAN))
            .collect();
        if m.len() != 16 || !m.iter().all(|x| x.is_finite()) {
            bail!("{}: `world_from_sensor` is not 4 rows of 4 finite numbers", what());
        }
        let m = na::Matrix4::from_row_slice(&m);
        let r = m.fixed_view::<3, 3>(0, 0).into_owned();
        if (r.transpose() * r - na::Matrix3::identity()).norm() > 1e-6
            || r.determinant() < 0.0
            || m.row(3).transpose() != na::Vector4::new(0.0, 0.0, 0.0, 1.0)
        {
            bail!("{}: `world_from_sensor` is not a rigid transform", what());
        }
        let rotation = na::UnitQuaternion::from_matrix(&r);
        let translation = na::Translation3::new(m[(0, 3)], m[(1, 3)], m[(2, 3)]);
        out.insert(file.to_owned(), Isometry3::from_parts(translation, rotation));
    }
    Ok(out)
}

fn read_scans(args: &ExtractArgs, progress: &Progress) -> Result<Vec<PointCloud>> {
    let poses = args.poses.as_deref().map(read_poses).transpose()?;
    let bar = progress.bar(args.scans.len() as u64, "reading");
    let mut scans = Vec::with_capacity(args.scans.len());
    for path in &args.scans {
        let mut cloud = crate::input::read_cloud(path, &args.input)?;
        if let Some(poses) = &poses {
            let name = path.file_name().map(|f| f.to_string_lossy().into_owned());
            let pose = name
                .as_ref()
                .and_then(|n| poses.get(n))
                .with_context(|| format!("{} is not in the poses file", path.display()))?;
            cloud.set_sensor_pose(Some(SensorPose { world_from_sensor: *pose }));
        }
        scans.push(cloud);
        bar.inc(1);
    }
    bar.finish_and_clear();
    Ok(scans)
}

/// The patches as one OBJ mesh (planar patches triangulated).
fn write_export(path: &Path, patches: &[Patch]) -> Result<()> {
    let mut vertices: Vec<Point3> = Vec::new();
    let mut faces: Vec<Vec<u32>> = Vec::new();
    for (i, patch) in patches.iter().enumerate() {
        for tri in patch_triangles(patch).with_context(|| format!("triangulating patch {i}"))? {
            let base = vertices.len() as u32;
            vertices.extend(tri);
            faces.push(vec![base, base + 1, base + 2]);
        }
    }
    let mesh = PolygonMesh::new(vertices, faces).context("building the export mesh")?;
    pointcloud::io::write_mesh(path, &mesh)?;
    Ok(())
}

/// Runs `patchnav extract`.
pub fn run(args: &ExtractArgs, progress: &Progress) -> Result<()> {
    if let Some(export) = &args.export
        && !export.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj"))
    {
        bail!("--export writes OBJ meshes; give a file ending in .obj");
    }
    let scans = read_scans(args, progress)?;
    let config = config(args);
    let bar = progress.bar(scans.len() as u64, "extracting");
    let result = extract(&scans, &config, |_| bar.inc(1))?;
    bar.finish_and_clear();

    let mut out = String::new();
    for (path, r) in args.scans.iter().zip(&result.scans) {
        writeln!(
            out,
            "{}: {} points, {} planes ({} points), {} planar patches, {} failed, \
             {} remainder points, {} trimesh patches; outline vertices {} -> {}",
            path.display(),
            r.points,
            r.regions,
            r.region_points,
            r.planar_patches,
            r.failed_regions,
            r.remainder_points,
            r.trimesh_patches,
            r.outline_vertices.0,
            r.outline_vertices.1
        )?;
        for reason in &r.failures {
            writeln!(out, "    failed region: {reason}")?;
        }
    }
    if let Some(m) = result.merge {
        writeln!(
            out,
            "merging: {} planar patches -> {} ({} groups united, {} kept unmerged)",
            m.input, m.output, m.groups_merged, m.kept_unmerged
        )?;
    }
    let t = result.times;
    writeln!(
        out,
        "time: segmentation {:.3} s, polygons {:.3} s, trimeshes {:.3} s, merging {:.3} s",
        t.segmentation.as_secs_f64(),
        t.polygonization.as_secs_f64(),
        t.trimesh.as_secs_f64(),
        t.merging.as_secs_f64()
    )?;
    let planar = result.patches.iter().filter(|p| p.as_planar().is_some()).count();
    writeln!(out, "patches: {planar} planar, {} trimesh", result.patches.len() - planar)?;
    if let Some(export) = &args.export {
        write_export(export, &result.patches)?;
        writeln!(out, "wrote {}", export.display())?;
    }
    if let Some(map) = &args.out {
        let (bytes, memory) = save_patches(result.patches, args.backend, args.spacing, map)?;
        writeln!(
            out,
            "wrote {} ({} backend, {bytes} bytes on disk, {memory} bytes in memory)",
            map.display(),
            args.backend.name()
        )?;
    }
    progress.say(out.trim_end());
    Ok(())
}
