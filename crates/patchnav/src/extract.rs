//! `patchnav extract SCANS... --out MAP [--backend B] [--sensor S] [--hybrid] [--no-merge]
//! [--poses FILE] [--export FILE.obj|ply] [--jsonl FILE] [--polygons FILE]`: planar patches (and, with `--hybrid`, trimesh patches
//! for the non-planar remainder) from range scans, merged across scans, written as a map file
//! of any patch backend (thesis §5.3, §6.1; `patch_extract::pipeline`).
//!
//! `patchnav extract BAG --topic T [--fixed-frame F] [--every N | --min-motion M] [--start S]
//! [--end S]` takes the scans from the `sensor_msgs/PointCloud2` messages of a ROS bag (`.mcap`,
//! rosbag2 folder, ROS 1 `.bag`), each posed by the bag's `/tf` and `/tf_static` at its stamp
//! (`ros_bag::read_scans`), or by a trajectory (`--poses`, TUM format). A depth image topic
//! (`sensor_msgs/Image`, 16UC1 or 32FC1) gives organised clouds through its
//! `sensor_msgs/CameraInfo` (`--camera-info`, default the sibling `camera_info` topic).
//!
//! Each scan is read in its sensor frame with its pose: PLY files written by `patchnav
//! simulate` carry it, PCD files have `VIEWPOINT`, 3DTK `.3d` scans the sibling `.pose` file.
//! `--poses FILE` overrides them with the `poses.json` layout `patchnav simulate` writes
//! (`{"scans": [{"file": NAME, "world_from_sensor": 4×4 rows}, ...]}`, matched by file name).
//!
//! `--jsonl FILE` appends one line per run in the peers' result format (`shared/peers/FORMAT.md`
//! §4, kind `planes`), so that `summarize.py` and `cargo xtask peers planes` read our runs beside
//! PCL's and Open3D's; `--polygons FILE` writes the planar patches in the peers' plane-polygon
//! format (§5). The mapping of our figures onto those keys:
//!
//! | key | ours |
//! |---|---|
//! | `planes`, `inliers` | planar regions of the segmentation and their points, summed over the scans |
//! | `polygons`, `polygon_vertices` | planar patches written (after merging) and their outline vertices (outer rings and holes) |
//! | `time_normals_s` | `null`: the segmentation fits its seed windows itself, there is no separate normal stage |
//! | `time_seg_s`, `time_hull_s` | segmentation; projection + α-shape + Douglas–Peucker |
//! | `time_s` | every stage: segmentation + polygons + trimeshes + merging (also given one by one) |
//! | `peak_rss_kib`, `rss_after_load_kib` | `VmHWM` of `/proc/self/status` at the end and after reading (`null` elsewhere) |

use crate::input::InputArgs;
use crate::names;
use crate::progress::Progress;
use anyhow::{Context, Result, bail};
use clap::Args;
use patch_core::triangulate::patch_triangles;
use patch_core::{Patch, Point3};
use patch_extract::pipeline::{PipelineConfig, extract_with_threads};
use patch_extract::visibility::Carved;
use patch_map::Backend;
pub use patch_pipeline::SensorPreset;
use patch_pipeline::files::{read_poses, read_trajectory, save_patches};
use patch_pipeline::preset::ExtractChoices;
use pointcloud::{PointCloud, PolygonMesh, SensorPose};
use serde_json::{Value, json};
use std::fmt::Write as _;
use std::num::NonZeroUsize;
use std::path::{Path, PathBuf};

/// Arguments of `patchnav extract`.
#[derive(Args, Debug)]
pub struct ExtractArgs {
    /// Scans in their sensor frame with their pose (.ply .pcd .3d .bin .xyz .png), or one ROS
    /// bag (.mcap, a rosbag2 folder, .bag) with --topic.
    #[arg(required = true)]
    pub scans: Vec<PathBuf>,
    /// The bag's `sensor_msgs/PointCloud2` or `sensor_msgs/LaserScan` topic to take scans from.
    #[arg(long)]
    pub topic: Option<String>,
    /// The frame bag scans are posed in (default: the root of the clouds' transform chain).
    #[arg(long, requires = "topic", conflicts_with = "poses")]
    pub fixed_frame: Option<String>,
    /// For a depth image topic: its `sensor_msgs/CameraInfo` topic (default: the sibling
    /// `camera_info` of the image topic).
    #[arg(long, requires = "topic")]
    pub camera_info: Option<String>,
    /// Take every N-th cloud of the bag's time window.
    #[arg(long, requires = "topic", default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..))]
    pub every: u64,
    /// Take a bag cloud only when the sensor moved at least M metres since the last one taken.
    #[arg(long, requires = "topic", conflicts_with = "every")]
    pub min_motion: Option<f64>,
    /// Bag clouds from this many seconds after the bag's first message.
    #[arg(long, requires = "topic")]
    pub start: Option<f64>,
    /// Bag clouds up to this many seconds after the bag's first message.
    #[arg(long, requires = "topic")]
    pub end: Option<f64>,
    /// The map file to write.
    #[arg(long, required_unless_present_any = ["export", "jsonl", "polygons"])]
    pub out: Option<PathBuf>,
    /// The backend of the map file.
    #[arg(long, value_parser = names::all::<Backend>(), default_value_t = Backend::BBox6d)]
    pub backend: Backend,
    /// For `--backend pointcloud`: sample the patches every SPACING metres.
    #[arg(long)]
    pub spacing: Option<f64>,
    /// Threshold presets (segmentation noise model, trimesh growing, merging tolerances).
    #[arg(long, value_parser = crate::names::all::<SensorPreset>(), default_value_t = SensorPreset::Alrf)]
    pub sensor: SensorPreset,
    /// Also grow trimesh patches on the points in no plane (the thesis's hybrid map); for
    /// unorganised scans through a spherical range-image grid, with splats for the points no
    /// mesh holds (`patch_extract::spherical_grid`, not in the thesis).
    #[arg(long)]
    pub hybrid: bool,
    /// Keep every scan's patches instead of merging coplanar overlapping ones.
    #[arg(long)]
    pub no_merge: bool,
    /// Segment each scan once, without the second pass over the points in no plane with
    /// smaller seed windows and regions (on in the `alrf` preset; off in the others).
    #[arg(long)]
    pub no_second_pass: bool,
    /// With --hybrid: drop the remainder triangles another scan saw through (free-space
    /// carving with the ALRF's thresholds, `patch_extract::visibility`; off by default).
    #[arg(long, requires = "hybrid")]
    pub carve: bool,
    /// Each planar patch gets a back face this many metres behind the side it was seen from,
    /// so that the map holds slabs (0: bare surfaces; default: the sensor preset's, 0.04 m
    /// for `alrf`, none for the others). The mesh export and the plane polygons hold the
    /// surfaces alone.
    #[arg(long)]
    pub slab_thickness: Option<f64>,
    /// Poses overriding the scans' own: for scan files a poses JSON; for a bag a trajectory in
    /// the TUM format (`t tx ty tz qx qy qz qw` per line, `world_from_sensor` at time t in
    /// seconds, the clock of the clouds' stamps), interpolated at each cloud's stamp instead of
    /// `/tf`.
    #[arg(long)]
    pub poses: Option<PathBuf>,
    /// Scans extracted at once (default: one per core; the result does not depend on it).
    #[arg(long)]
    pub threads: Option<NonZeroUsize>,
    /// Also write the patches, triangulated, as a mesh for any 3D viewer (`.obj`, or `.ply`:
    /// binary PLY).
    #[arg(long)]
    pub export: Option<PathBuf>,
    /// Append one JSON line (the peers' result format, kind `planes`) describing this run.
    #[arg(long)]
    pub jsonl: Option<PathBuf>,
    /// Write the planar patches as the peers' plane-polygon JSON (world frame).
    #[arg(long)]
    pub polygons: Option<PathBuf>,
    #[command(flatten)]
    pub input: InputArgs,
}

fn config(args: &ExtractArgs) -> PipelineConfig {
    ExtractChoices {
        sensor: args.sensor,
        hybrid: args.hybrid,
        merge: !args.no_merge,
        second_pass: !args.no_second_pass,
        carve: args.carve,
        slab_thickness: args.slab_thickness,
    }
    .config()
}

/// Whether `path` names a ROS bag: a folder (rosbag2), `.mcap`, `.bag` or `.db3`.
pub fn is_bag(path: &Path) -> bool {
    path.is_dir()
        || matches!(path.extension().and_then(|e| e.to_str()), Some("mcap" | "bag" | "db3"))
}

/// The scans of `--topic` in the bag, posed by its transforms, and one name per scan.
fn read_bag_scans(
    args: &ExtractArgs,
    bag: &Path,
    progress: &Progress,
) -> Result<(Vec<PointCloud>, Vec<String>)> {
    let Some(topic) = &args.topic else {
        bail!("{}: a bag needs --topic (`patchnav info` lists its topics)", bag.display());
    };
    let trajectory = args.poses.as_deref().map(read_trajectory).transpose()?;
    let query = ros_bag::ScanQuery {
        topic: topic.clone(),
        camera_info: args.camera_info.clone(),
        trajectory,
        posed: true,
        fixed_frame: args.fixed_frame.clone(),
        every: args.every as usize,
        min_motion: args.min_motion,
        start_s: args.start,
        end_s: args.end,
    };
    let spinner = progress.spinner("reading the bag");
    let found = ros_bag::read_scans(&ros_bag::Bag::open(bag)?, &query)?;
    spinner.finish_and_clear();
    for w in &found.warnings {
        eprintln!("warning: {w}");
    }
    let (on_topic, in_window, kept) = found.counts;
    let frame = found.fixed_frame.as_deref().unwrap_or("the sensor frame");
    progress.say(format!(
        "{}: {kept} of {on_topic} clouds on {topic} ({in_window} in the time window), posed in {frame}",
        bag.display()
    ));
    let names = found.scans.iter().map(|s| format!("{topic} at {:.3} s", s.time_s)).collect();
    Ok((found.scans.into_iter().map(|s| s.cloud).collect(), names))
}

fn read_scans(args: &ExtractArgs, progress: &Progress) -> Result<(Vec<PointCloud>, Vec<String>)> {
    if let [bag] = &args.scans[..]
        && is_bag(bag)
    {
        return read_bag_scans(args, bag, progress);
    }
    if args.topic.is_some() {
        bail!("--topic takes one ROS bag (.mcap, a rosbag2 folder, .bag)");
    }
    let names = args.scans.iter().map(|p| p.display().to_string()).collect();
    let poses = args.poses.as_deref().map(read_poses).transpose()?;
    let bar = progress.bar(args.scans.len() as u64, "reading");
    // The files are read on the extraction's threads, in order (the first error is the first
    // file's that fails, as one thread would report it).
    let threads = patch_pipeline::parallel::threads_or_cores(args.threads);
    let read = patch_pipeline::parallel::map_in_order(args.scans.len(), threads, |i| {
        let cloud = crate::input::read_cloud(&args.scans[i], &args.input);
        bar.inc(1);
        cloud
    });
    let mut scans = Vec::with_capacity(args.scans.len());
    for (path, cloud) in args.scans.iter().zip(read) {
        let mut cloud = cloud?;
        if let Some(poses) = &poses {
            let name = path.file_name().map(|f| f.to_string_lossy().into_owned());
            let pose = name
                .as_ref()
                .and_then(|n| poses.get(n))
                .with_context(|| format!("{} is not in the poses file", path.display()))?;
            cloud.set_sensor_pose(Some(SensorPose { world_from_sensor: *pose }));
        }
        scans.push(cloud);
    }
    bar.finish_and_clear();
    Ok((scans, names))
}

/// The patches as one OBJ or PLY mesh (planar patches triangulated).
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
        && !export
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("obj") || e.eq_ignore_ascii_case("ply"))
    {
        bail!("--export writes OBJ or PLY meshes; give a file ending in .obj or .ply");
    }
    let (scans, names) = read_scans(args, progress)?;
    let rss_after_load = peak_rss_kib();
    let config = config(args);
    let bar = progress.bar(scans.len() as u64, "extracting");
    let threads = patch_pipeline::parallel::threads_or_cores(args.threads);
    let result = extract_with_threads(&scans, &config, threads, |_| bar.inc(1))?;
    bar.finish_and_clear();

    let mut out = String::new();
    for (name, r) in names.iter().zip(&result.scans) {
        writeln!(
            out,
            "{}: {} points, {} planes ({} of them from the second pass; {} points), {} planar \
             patches, {} failed, {} remainder points, {} trimesh patches; outline vertices {} -> {}",
            name,
            r.points,
            r.regions,
            r.second_pass_regions,
            r.region_points,
            r.planar_patches,
            r.failed_regions,
            r.remainder_points,
            r.trimesh_patches,
            r.outline_vertices.0,
            r.outline_vertices.1
        )?;
        if r.binned_remainder > 0 {
            writeln!(
                out,
                "    unorganised: {} remainder points binned into its spherical grid, {} splats",
                r.binned_remainder, r.splats
            )?;
        }
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
    let carved = result.scans.iter().fold(Carved::default(), |mut sum, s| {
        sum += s.carved;
        sum
    });
    if carved.tested > 0 {
        writeln!(
            out,
            "free-space carving: {} of {} remainder triangles tested dropped, {:.3} s",
            carved.removed,
            carved.tested,
            t.carving.as_secs_f64()
        )?;
    }
    let planar = result.patches.iter().filter(|p| p.as_planar().is_some()).count();
    write!(out, "patches: {planar} planar, {} trimesh", result.patches.len() - planar)?;
    if result.filled_holes > 0 {
        write!(out, "; {} holes of upward surfaces filled", result.filled_holes)?;
    }
    match config.slab_thickness {
        Some(t) if !result.back_faces.is_empty() => {
            writeln!(out, "; in the map with {} back faces {t} m behind", result.back_faces.len())?
        }
        _ => writeln!(out)?,
    }
    if let Some(export) = &args.export {
        write_export(export, &result.patches)?;
        writeln!(out, "wrote {}", export.display())?;
    }
    if let Some(path) = &args.polygons {
        write_polygons(path, &map_name(&args.scans), &result.patches)?;
        writeln!(out, "wrote {}", path.display())?;
    }
    if let Some(path) = &args.jsonl {
        let line = result_line(args, &config, &scans, &result, rss_after_load);
        append_line(path, &line)?;
        writeln!(out, "appended a result line to {}", path.display())?;
    }
    if let Some(map) = &args.out {
        let patches = result.into_map_patches();
        let (bytes, memory) = save_patches(patches, args.backend, args.spacing, map)?;
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

/// The tool name and version of the result lines.
fn tool_name() -> String {
    format!("patchnav-{}", env!("CARGO_PKG_VERSION"))
}

/// The `map` of the result lines: the scan's file stem, or the stems joined by `+`.
fn map_name(scans: &[PathBuf]) -> String {
    let stems: Vec<String> = scans
        .iter()
        .map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default())
        .collect();
    stems.join("+")
}

/// The process's peak resident memory in KiB (`VmHWM`), where `/proc` has it.
fn peak_rss_kib() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
}

/// One result line (peers' FORMAT.md §4, kind `planes`) for this run.
fn result_line(
    args: &ExtractArgs,
    config: &PipelineConfig,
    scans: &[PointCloud],
    result: &patch_extract::pipeline::Extraction,
    rss_after_load: Option<u64>,
) -> Value {
    let sum = |f: fn(&patch_extract::pipeline::ScanReport) -> usize| -> usize {
        result.scans.iter().map(f).sum()
    };
    let planar: Vec<&patch_core::PlanarPatch> =
        result.patches.iter().filter_map(Patch::as_planar).collect();
    let vertices: usize = planar.iter().map(|p| p.polygon().num_vertices()).sum();
    let t = result.times;
    let seg = &config.segment;
    json!({
        "kind": "planes",
        "tool": tool_name(),
        "method": if args.hybrid { "region-growing+hybrid" } else { "region-growing" },
        "map": map_name(&args.scans),
        "scans": scans.len(),
        "points": sum(|r| r.points),
        "organized": scans.iter().all(|s| s.grid().is_some()),
        "planes": sum(|r| r.regions),
        "inliers": sum(|r| r.region_points),
        "polygons": planar.len(),
        "polygon_vertices": vertices,
        "failed_regions": sum(|r| r.failed_regions),
        "trimesh_patches": result.patches.len() - planar.len(),
        "merged_patches": result.merge.as_ref().map(|m| m.output),
        "time_normals_s": null,
        "time_seg_s": t.segmentation.as_secs_f64(),
        "time_hull_s": t.polygonization.as_secs_f64(),
        "time_trimesh_s": t.trimesh.as_secs_f64(),
        "time_merge_s": t.merging.as_secs_f64(),
        "time_s": t.total().as_secs_f64(),
        "rss_after_load_kib": rss_after_load,
        "peak_rss_kib": peak_rss_kib(),
        "params": {
            "sensor": args.sensor.name(),
            "merge": config.merge.is_some(),
            "hybrid": args.hybrid,
            "sigma_0": seg.noise.sigma_0,
            "sigma_r2": seg.noise.sigma_r2,
            "distance_factor": seg.distance_factor,
            "min_inliers": seg.min_region_size,
            "min_incidence_cos": seg.min_incidence_cos,
            "k": seg.knn,
            "knn_radius": seg.knn_radius,
        },
    })
}

/// Appends `line` and a newline to `path`, creating it if needed.
fn append_line(path: &Path, line: &Value) -> Result<()> {
    use std::io::Write as _;
    let mut file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .with_context(|| format!("opening {}", path.display()))?;
    writeln!(file, "{line}").with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}

/// The planar patches as the peers' plane-polygon JSON (FORMAT.md §5): one plane per patch,
/// `normal · p + d = 0`, its outer ring in `polygons` and its holes, if any, in `holes`.
fn write_polygons(path: &Path, map: &str, patches: &[Patch]) -> Result<()> {
    let ring = |pts: &[patch_core::Point2], p: &patch_core::PlanarPatch| -> Value {
        pts.iter()
            .map(|q| {
                let w = p.to_world(q);
                json!([w.x, w.y, w.z])
            })
            .collect()
    };
    let planes: Vec<Value> = patches
        .iter()
        .filter_map(Patch::as_planar)
        .map(|p| {
            let n = p.normal();
            let polygon = p.polygon();
            json!({
                "normal": [n.x, n.y, n.z],
                "d": -p.offset(),
                "inliers": null,
                "polygons": [ring(polygon.outer().points(), p)],
                "holes": polygon.holes().iter().map(|h| ring(h.points(), p)).collect::<Vec<_>>(),
            })
        })
        .collect();
    let doc =
        json!({"tool": tool_name(), "method": "region-growing", "map": map, "planes": planes});
    pointcloud::io::write_bytes_atomically(path, format!("{doc}\n"))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use patch_core::Real;

    /// A 2 m × 2 m wall 2 m in front of the sensor, 5 cm grid, unorganised.
    fn wall(path: &Path) {
        let points: Vec<Point3> = (0..41)
            .flat_map(|i| {
                (0..41).map(move |j| Point3::new(2.0, -1.0 + 0.05 * i as Real, 0.05 * j as Real))
            })
            .collect();
        let cloud = PointCloud::from_positions(points).unwrap();
        pointcloud::io::write_cloud(path, &cloud).unwrap();
    }

    #[test]
    fn jsonl_lines_and_polygons_in_the_peers_format() {
        let dir = tempfile::tempdir().unwrap();
        let scan = dir.path().join("wall.ply");
        wall(&scan);
        let jsonl = dir.path().join("runs.jsonl");
        let polygons = dir.path().join("wall.polygons.json");
        let args = ExtractArgs {
            scans: vec![scan],
            topic: None,
            fixed_frame: None,
            camera_info: None,
            every: 1,
            min_motion: None,
            start: None,
            end: None,
            out: None,
            backend: Backend::BBox6d,
            spacing: None,
            sensor: SensorPreset::RangeCamera,
            hybrid: false,
            no_merge: false,
            no_second_pass: false,
            carve: false,
            slab_thickness: None,
            poses: None,
            threads: None,
            export: None,
            jsonl: Some(jsonl.clone()),
            polygons: Some(polygons.clone()),
            input: InputArgs { skip_non_finite: false, depth_camera: None },
        };
        let progress = Progress::new(true);
        run(&args, &progress).unwrap();
        run(&args, &progress).unwrap();
        let text = std::fs::read_to_string(&jsonl).unwrap();
        assert_eq!(text.lines().count(), 2, "one appended line per run:\n{text}");
        let row: Value = serde_json::from_str(text.lines().next().unwrap()).unwrap();
        for key in [
            "tool",
            "method",
            "map",
            "points",
            "organized",
            "planes",
            "inliers",
            "polygons",
            "polygon_vertices",
            "time_normals_s",
            "time_seg_s",
            "time_hull_s",
            "time_s",
            "peak_rss_kib",
            "rss_after_load_kib",
            "params",
        ] {
            assert!(row.get(key).is_some(), "no `{key}` in {row}");
        }
        assert_eq!(row["kind"], "planes");
        assert_eq!(row["map"], "wall");
        assert_eq!(row["points"], 41 * 41);
        assert_eq!(row["planes"], 1);
        assert_eq!(row["polygons"], 1);

        let doc: Value =
            serde_json::from_str(&std::fs::read_to_string(&polygons).unwrap()).unwrap();
        let plane = &doc["planes"][0];
        // n · p + d = 0 for the wall x = 2 (the normal faces the sensor at the origin).
        let n: Vec<f64> =
            plane["normal"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
        let d = plane["d"].as_f64().unwrap();
        for v in plane["polygons"][0].as_array().unwrap() {
            let p: Vec<f64> = v.as_array().unwrap().iter().map(|c| c.as_f64().unwrap()).collect();
            assert!((n[0] * p[0] + n[1] * p[1] + n[2] * p[2] + d).abs() < 1e-6);
            assert!((p[0] - 2.0).abs() < 1e-6);
        }
    }
}
