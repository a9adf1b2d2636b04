//! The generators of `cargo xtask peers`. [`planes`]: our plane extraction beside PCL's and
//! Open3D's, on the same inputs, one process per run, with one side-by-side table
//! (docs/extraction-peers.md). [`terrain`] (docs/terrain.md): our Hough terrain classification
//! beside one RANSAC ground-plane fit on the same frames.
//!
//! Inputs: the shared bench's `floorplan_scan.ply` (organised 640 × 480 depth image in the
//! camera's optical frame) and `floorplan.ply` (unorganised surface samples in the world frame).
//! Runs: `patchnav extract` (release build, `--sensor range-camera`, `--jsonl`, `--polygons`);
//! the peers' `pcl_planes` methods `omps`, `rg`, `ransac` with `run_bench.sh`'s parameters;
//! Open3D's `open3d_planes.py --method segment_plane`. A peer that is not built or not
//! installed gives a row saying so and how to get it; it never fails the command.
//!
//! Quality, from the world-frame plane polygons every run writes (peers' FORMAT.md §5) and the
//! floor plan's mesh `floorplan.obj`:
//! * **true planes**: the mesh's distinct planes (triangles grouped by normal within 1° and
//!   offset within 1 cm). A true plane is *visible* in a cloud when ≥ 500 of the cloud's points
//!   lie within 2 cm of its triangles. `found` counts the visible true planes that some
//!   extracted plane matches (normals within 2°, offsets within 2 cm); `off` counts extracted
//!   planes that match no true plane at all.
//! * **vertices on surface**: the fraction of all polygon vertices within 2 cm of a mesh
//!   triangle (outlines that stray across doors, off the ends of walls, or off the plane lose).

use anyhow::{Context, Result, bail};
use pointcloud::{Point3, Vector3};

pub mod ground;
pub mod terrain;
use serde_json::{Value, json};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// Points within this distance of a mesh triangle are on it (metres).
pub const ON_SURFACE: f64 = 0.02;
/// A true plane is visible with at least this many points on it (PCL's `min_inliers`).
pub const VISIBLE_POINTS: usize = 500;
/// An extracted plane matches a true plane within this angle (degrees)...
pub const MATCH_ANGLE_DEG: f64 = 2.0;
/// ... and this offset (metres).
pub const MATCH_OFFSET: f64 = 0.02;
/// `floorplan.ply` moved so that its frame's origin is the floor plan's start point, with that
/// move as its `sensor_to_world`: the same world points, but a viewpoint for our sensor-centred
/// segmentation (which otherwise takes the world origin, a corner of the floor, as the sensor).
const VIEWPOINT_CLOUD: &str = "floorplan_at_start";
const START: [f64; 3] = [10.0, 7.5, 1.25];

/// The programs and folders of a peer comparison.
pub struct Peers {
    /// The release build of `patchnav`.
    pub patchnav: PathBuf,
    /// The peers' scripts (`shared/peers`).
    pub peers_dir: PathBuf,
    /// Where the peers' programs are built (`pcl_planes`).
    pub build_dir: PathBuf,
    /// The shared bench (floor plan mesh, clouds).
    pub bench: PathBuf,
    /// Where inputs, polygons and intermediate files go.
    pub work: PathBuf,
}

/// One process to run.
struct Run {
    cloud: &'static str,
    tool: &'static str,
    method: &'static str,
    /// Program and arguments, or why it cannot run.
    command: Result<Vec<String>, String>,
    /// Where the run writes its polygons (a file, or a folder it writes one file into).
    polygons: PathBuf,
}

/// Runs every extraction of `cargo xtask peers planes` and scores it against the floor plan:
/// one row per run (a peer that is not built gives a row saying so) and the table.
pub fn planes(env: &Peers) -> Result<(Vec<Value>, String)> {
    let peers = env.peers_dir.clone();
    let bench = env.bench.clone();
    for f in ["floorplan.obj", "floorplan.ply", "floorplan_scan.ply"] {
        if !bench.join(f).is_file() {
            bail!(
                "missing {} (run /usr/bin/python3 {}/gen_floorplan.py)",
                bench.join(f).display(),
                peers.display()
            );
        }
    }
    let (work, patchnav, build_dir) = (&env.work, &env.patchnav, &env.build_dir);
    let pcl = build_dir.join("pcl_planes");
    let pcl_missing = (!pcl.is_file()).then(|| {
        format!(
            "not built: PEERS_BUILD_DIR={} bash {}/build.sh",
            build_dir.display(),
            peers.display()
        )
    });
    let python = "/usr/bin/python3";
    let open3d_script = peers.join("open3d_planes.py");
    let open3d_missing = match Command::new(python).args(["-c", "import open3d"]).output() {
        Ok(o) if o.status.success() && open3d_script.is_file() => None,
        _ => Some(format!(
            "not available: {python} cannot import open3d (apt-get install python3-open3d, or bash {}/build.sh)",
            peers.display()
        )),
    };

    let s = |p: &Path| p.display().to_string();
    let jsonl = work.join("ours.jsonl");
    let _ = std::fs::remove_file(&jsonl);
    // Our extraction of `file` as `cloud`.
    let ours = |cloud: &'static str, file: String| {
        let polys = work.join(format!("{cloud}.patchnav.polygons.json"));
        let command = [&s(patchnav), "extract", &file, "--sensor", "range-camera", "--jsonl"]
            .into_iter()
            .map(str::to_owned)
            .chain([s(&jsonl), "--polygons".into(), s(&polys)])
            .collect();
        Run {
            cloud,
            tool: "patchnav",
            method: "region-growing",
            command: Ok(command),
            polygons: polys,
        }
    };
    let mut runs = Vec::new();
    for (cloud, k) in [("floorplan_scan", "30"), ("floorplan", "10")] {
        let file = s(&bench.join(format!("{cloud}.ply")));
        runs.push(ours(cloud, file.clone()));
        for method in ["omps", "rg", "ransac"] {
            let dir = work.join(format!("{cloud}.pcl_{method}"));
            let mut cmd = vec![s(&pcl), file.clone(), "--method".into(), method.into()];
            if method == "rg" {
                cmd.extend(["--k".into(), k.into()]);
            }
            cmd.extend(["--out-dir".into(), s(&dir)]);
            runs.push(Run {
                cloud,
                tool: "pcl",
                method,
                command: pcl_missing.clone().map_or(Ok(cmd), Err),
                polygons: dir,
            });
        }
        let dir = work.join(format!("{cloud}.open3d"));
        let cmd = vec![
            python.into(),
            s(&open3d_script),
            file.clone(),
            "--method".into(),
            "segment_plane".into(),
            "--seed".into(),
            "0".into(),
            "--out-dir".into(),
            s(&dir),
        ];
        runs.push(Run {
            cloud,
            tool: "open3d",
            method: "segment_plane",
            command: open3d_missing.clone().map_or(Ok(cmd), Err),
            polygons: dir,
        });
    }

    // Our segmentation assumes the sensor at the cloud's origin: also give it floorplan.ply seen
    // from the start point (the same world points; only ours runs on this copy).
    let moved = work.join(format!("{VIEWPOINT_CLOUD}.ply"));
    write_viewpoint_copy(&bench.join("floorplan.ply"), &moved)?;
    runs.push(ours(VIEWPOINT_CLOUD, s(&moved)));

    eprintln!("ground truth: distinct planes of floorplan.obj, visible planes per cloud");
    let truth = Truth::load(&bench)?;
    let mut rows = Vec::new();
    for run in &runs {
        let row = match &run.command {
            Err(why) => json!({"kind": "planes", "tool": run.tool, "method": run.method,
                               "map": run.cloud, "skipped": why}),
            Ok(cmd) => {
                eprintln!("{} {} on {}", run.tool, run.method, run.cloud);
                if run.tool != "patchnav" {
                    std::fs::create_dir_all(&run.polygons)?;
                }
                let load = std::fs::read_to_string("/proc/loadavg").ok();
                let load1 = load.as_deref().and_then(|l| l.split(' ').next()?.parse::<f64>().ok());
                let t = Instant::now();
                let out = Command::new(&cmd[0])
                    .args(&cmd[1..])
                    .output()
                    .with_context(|| format!("could not start {}", cmd[0]))?;
                let wall = t.elapsed().as_secs_f64();
                let line = if run.tool == "patchnav" {
                    std::fs::read_to_string(&jsonl)
                        .unwrap_or_default()
                        .lines()
                        .last()
                        .map(str::to_owned)
                } else {
                    String::from_utf8_lossy(&out.stdout)
                        .lines()
                        .rev()
                        .find(|l| l.starts_with('{'))
                        .map(str::to_owned)
                };
                match (out.status.success(), line) {
                    (true, Some(line)) => {
                        let mut row: Value = serde_json::from_str(&line)
                            .with_context(|| format!("{} printed `{line}`", run.tool))?;
                        if row.get("skipped").is_none() {
                            let polys = find_polygons(&run.polygons)?;
                            let q = truth.quality(run.cloud, &polys);
                            row["quality"] = q;
                        }
                        row["wall_s"] = json!(wall);
                        row["loadavg_1min_before"] = json!(load1);
                        row["command"] = json!(cmd.join(" "));
                        row
                    }
                    (ok, _) => {
                        let err = String::from_utf8_lossy(&out.stderr);
                        let last = err.lines().last().unwrap_or("no output");
                        json!({"kind": "planes", "tool": run.tool, "method": run.method,
                               "map": run.cloud, "skipped": format!("failed (success: {ok}): {last}")})
                    }
                }
            }
        };
        rows.push(row);
    }

    let table = table(&rows, &truth);
    Ok((rows, table))
}

/// Writes `input` (world frame) with its points moved by −START and `sensor_to_world` = +START.
fn write_viewpoint_copy(input: &Path, output: &Path) -> Result<()> {
    let cloud =
        pointcloud::io::read_cloud(input, &pointcloud::io::ReadOptions { skip_non_finite: false })?;
    let shift = Vector3::new(START[0], START[1], START[2]);
    let moved: Vec<Point3> = cloud.positions().iter().map(|p| p - shift).collect();
    let mut out = pointcloud::PointCloud::from_positions(moved)
        .map_err(|e| anyhow::anyhow!("{}: {e}", input.display()))?;
    out.set_sensor_pose(Some(pointcloud::SensorPose {
        world_from_sensor: pointcloud::Isometry3::translation(START[0], START[1], START[2]),
    }));
    pointcloud::io::write_cloud(output, &out)?;
    Ok(())
}

/// The polygons JSON of a run: the file itself, or the one `*.polygons.json` in its folder.
fn find_polygons(path: &Path) -> Result<Value> {
    let file = if path.is_dir() {
        std::fs::read_dir(path)?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .find(|p| p.to_string_lossy().ends_with(".polygons.json"))
            .with_context(|| format!("no polygons file in {}", path.display()))?
    } else {
        path.to_owned()
    };
    let text =
        std::fs::read_to_string(&file).with_context(|| format!("reading {}", file.display()))?;
    serde_json::from_str(&text).with_context(|| format!("{} is not JSON", file.display()))
}

/// A plane `normal · p = offset` with a unit normal.
#[derive(Copy, Clone, Debug, PartialEq)]
pub(crate) struct Plane {
    pub(crate) normal: Vector3,
    pub(crate) offset: f64,
}

impl Plane {
    /// The plane with `normal` (any length > 0) and `offset` scaled alike; `None` when either is
    /// not finite or the normal is zero.
    pub(crate) fn new(normal: Vector3, offset: f64) -> Option<Plane> {
        let len = normal.norm();
        (len.is_finite() && len > 0.0 && offset.is_finite())
            .then(|| Plane { normal: normal / len, offset: offset / len })
    }

    /// [`Plane::new`] with the normal's largest component positive (one orientation per
    /// plane, for grouping and printing).
    fn canonical(normal: Vector3, offset: f64) -> Option<Plane> {
        let p = Plane::new(normal, offset)?;
        Some(if p.normal[p.normal.iamax()] < 0.0 {
            Plane { normal: -p.normal, offset: -p.offset }
        } else {
            p
        })
    }

    /// Whether `other` is the same plane within `angle_deg` and `dist`, in either orientation.
    pub(crate) fn same(&self, other: &Plane, angle_deg: f64, dist: f64) -> bool {
        let dot = self.normal.dot(&other.normal);
        let sign = if dot < 0.0 { -1.0 } else { 1.0 };
        dot.abs() >= angle_deg.to_radians().cos()
            && (self.offset - sign * other.offset).abs() <= dist
    }

    /// Distance of `p` from the plane.
    fn distance(&self, p: &Point3) -> f64 {
        (self.normal.dot(&p.coords) - self.offset).abs()
    }
}

/// One plane of a run's plane-polygon JSON: its plane and its polygon vertices (outer rings and
/// holes).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Extracted {
    /// `None` when the JSON's normal or `d` is missing, zero or not finite.
    pub(crate) plane: Option<Plane>,
    pub(crate) corners: Vec<Point3>,
}

impl Extracted {
    /// The indices of the `truth` planes this plane matches: normals within
    /// [`MATCH_ANGLE_DEG`] (either orientation) and the polygon's vertices on average within
    /// [`MATCH_OFFSET`] of the true plane (measured where the patch is, not at the origin, so
    /// that a far patch is not penalised for its lever arm).
    pub(crate) fn matches(&self, truth: &[Plane]) -> Vec<usize> {
        let Some(plane) = self.plane.filter(|_| !self.corners.is_empty()) else {
            return Vec::new();
        };
        (0..truth.len())
            .filter(|&i| {
                let t = &truth[i];
                let mean = self.corners.iter().map(|q| t.distance(q)).sum::<f64>()
                    / self.corners.len() as f64;
                plane.same(t, MATCH_ANGLE_DEG, f64::INFINITY) && mean <= MATCH_OFFSET
            })
            .collect()
    }
}

/// The planes of a plane-polygon JSON (`{"planes": [{"normal", "d", "polygons", "holes"?}]}`,
/// each plane `normal · p + d = 0`); missing or malformed parts give empty or `None` fields,
/// never an error, so that a bad run scores badly instead of stopping the comparison.
pub(crate) fn parse_planes(polygons: &Value) -> Vec<Extracted> {
    let num = |v: Option<&Value>| v.and_then(Value::as_f64).unwrap_or(f64::NAN);
    let point = |v: &Value| {
        let a = v.as_array();
        let at = |i: usize| num(a.and_then(|a| a.get(i)));
        Point3::new(at(0), at(1), at(2))
    };
    let planes = polygons.get("planes").and_then(Value::as_array);
    planes
        .into_iter()
        .flatten()
        .map(|p| {
            let n = p.get("normal").map(point).unwrap_or(Point3::new(f64::NAN, 0.0, 0.0));
            let d = num(p.get("d"));
            let corners = ["polygons", "holes"]
                .iter()
                .filter_map(|k| p.get(*k).and_then(Value::as_array))
                .flatten()
                .filter_map(Value::as_array)
                .flatten()
                .filter(|v| v.is_array())
                .map(point)
                .collect();
            Extracted { plane: Plane::new(n.coords, -d), corners }
        })
        .collect()
}

/// The floor plan's triangles, their distinct planes, and which planes each cloud shows.
pub struct Truth {
    triangles: Vec<[Point3; 3]>,
    /// Plane index of each triangle.
    plane_of: Vec<usize>,
    planes: Vec<Plane>,
    /// Per cloud: (points, points within 2 cm of the mesh, visible plane indices).
    visible: Vec<(&'static str, usize, usize, Vec<usize>)>,
}

impl Truth {
    /// The floor plan's mesh of `bench` and the clouds' visible planes.
    pub fn load(bench: &Path) -> Result<Truth> {
        let mesh = pointcloud::io::read_mesh(&bench.join("floorplan.obj"))?;
        let v = mesh.vertices();
        let triangles: Vec<[Point3; 3]> = mesh
            .triangulated()
            .triangles()
            .map(|[a, b, c]| [v[a as usize], v[b as usize], v[c as usize]])
            .collect();
        let (planes, plane_of) = distinct_planes(&triangles);
        let mut truth = Truth { triangles, plane_of, planes, visible: Vec::new() };
        for cloud in ["floorplan_scan", "floorplan"] {
            let path = bench.join(format!("{cloud}.ply"));
            let points = pointcloud::io::read_cloud(
                &path,
                &pointcloud::io::ReadOptions { skip_non_finite: false },
            )?
            .to_world();
            let mut counts = vec![0usize; truth.planes.len()];
            let mut on = 0;
            let mut n = 0;
            for p in points.positions().iter().filter(|p| p.coords.iter().all(|c| c.is_finite())) {
                n += 1;
                if let Some((tri, _)) = truth.nearest(p) {
                    on += 1;
                    counts[truth.plane_of[tri]] += 1;
                }
            }
            let visible = (0..counts.len()).filter(|&i| counts[i] >= VISIBLE_POINTS).collect();
            truth.visible.push((cloud, n, on, visible));
        }
        Ok(truth)
    }

    /// The nearest triangle within [`ON_SURFACE`] of `p`, and its distance.
    fn nearest(&self, p: &Point3) -> Option<(usize, f64)> {
        let mut best: Option<(usize, f64)> = None;
        for (i, t) in self.triangles.iter().enumerate() {
            let plane = &self.planes[self.plane_of[i]];
            if (plane.normal.dot(&p.coords) - plane.offset).abs() > ON_SURFACE + 1e-3 {
                continue;
            }
            let d = (closest_on_triangle(p, t) - p).norm();
            if d <= ON_SURFACE && best.is_none_or(|(_, b)| d < b) {
                best = Some((i, d));
            }
        }
        best
    }

    fn visible(&self, cloud: &str) -> &[usize] {
        let cloud = if cloud == VIEWPOINT_CLOUD { "floorplan" } else { cloud };
        self.visible.iter().find(|v| v.0 == cloud).map_or(&[], |v| &v.3)
    }

    /// Quality of a run's polygons JSON on `cloud` (see the module docs).
    pub fn quality(&self, cloud: &str, polygons: &Value) -> Value {
        let tally = MatchTally::of_polygons(polygons, &self.planes, |q| self.nearest(q).is_some());
        tally.report(self.visible(cloud), |i| {
            let t = &self.planes[i];
            format!(
                "n ({:.0} {:.0} {:.0}) · x = {:.2}",
                t.normal.x, t.normal.y, t.normal.z, t.offset
            )
        })
    }
}

/// Groups triangles by plane (normals within 1°, offsets within 1 cm): the planes and the
/// plane index of each triangle (degenerate triangles get a plane of their own).
fn distinct_planes(triangles: &[[Point3; 3]]) -> (Vec<Plane>, Vec<usize>) {
    let mut planes: Vec<Plane> = Vec::new();
    let mut plane_of = Vec::with_capacity(triangles.len());
    for [a, b, c] in triangles {
        let n = (b - a).cross(&(c - a));
        let plane = Plane::canonical(n, n.dot(&a.coords))
            .unwrap_or(Plane { normal: Vector3::z(), offset: f64::NAN });
        let i = planes.iter().position(|p| p.same(&plane, 1.0, 0.01)).unwrap_or_else(|| {
            planes.push(plane);
            planes.len() - 1
        });
        plane_of.push(i);
    }
    (planes, plane_of)
}

/// The point of triangle `t` closest to `p` (Ericson, Real-Time Collision Detection §5.1.5).
fn closest_on_triangle(p: &Point3, t: &[Point3; 3]) -> Point3 {
    let [a, b, c] = *t;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// The side-by-side Markdown table.
fn table(rows: &[Value], truth: &Truth) -> String {
    let mut out = String::new();
    let f = |v: Option<&Value>, digits: usize| match v.and_then(Value::as_f64) {
        Some(x) if x.fract() == 0.0 && x.abs() < 1e15 => format!("{x:.0}"),
        Some(x) => format!("{x:.digits$}"),
        None => "–".to_owned(),
    };
    for (cloud, n, on, visible) in &truth.visible {
        let _ = writeln!(
            out,
            "{cloud}: {n} points, {on} within {ON_SURFACE} m of the mesh, {} of the mesh's {} \
             distinct planes visible (≥ {VISIBLE_POINTS} points)",
            visible.len(),
            truth.planes.len()
        );
    }
    out.push('\n');
    out.push_str(
        "| cloud | tool | method | time_s (normals + seg + polygons) | wall_s | planes | in planes | \
         polygons | vertices / polygon | true planes found | planes off truth | vertices on surface | peak MiB |\n",
    );
    out.push_str("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for r in rows {
        let s = |k: &str| r.get(k).and_then(Value::as_str).unwrap_or("?").to_owned();
        if let Some(why) = r.get("skipped").and_then(Value::as_str) {
            let _ = writeln!(
                out,
                "| {} | {} | {} | {why} | | | | | | | | | |",
                s("map"),
                s("tool"),
                s("method")
            );
            continue;
        }
        let num = |k: &str| r.get(k).and_then(Value::as_f64);
        let stages = format!(
            "{} ({} + {} + {})",
            f(r.get("time_s"), 3),
            f(r.get("time_normals_s"), 3),
            f(r.get("time_seg_s"), 3),
            f(r.get("time_hull_s"), 3)
        );
        let in_planes = match (num("inliers"), num("points")) {
            (Some(i), Some(p)) if p > 0.0 => format!("{:.1} %", 100.0 * i / p),
            _ => "–".into(),
        };
        let per_poly = match (num("polygon_vertices"), num("polygons")) {
            (Some(v), Some(p)) if p > 0.0 => format!("{:.1}", v / p),
            _ => "–".into(),
        };
        let q = r.get("quality").cloned().unwrap_or(Value::Null);
        let found = format!(
            "{} / {}",
            f(q.get("true_planes_found"), 0),
            f(q.get("true_planes_visible"), 0)
        );
        let on = q
            .get("vertices_on_surface")
            .and_then(Value::as_f64)
            .map_or("–".into(), |x| format!("{:.1} %", 100.0 * x));
        let _ = writeln!(
            out,
            "| {} | {} | {} | {stages} | {} | {} | {in_planes} | {} | {per_poly} | {found} | {} | {on} | {} |",
            s("map"),
            s("tool"),
            s("method"),
            f(r.get("wall_s"), 2),
            f(r.get("planes"), 0),
            f(r.get("polygons"), 0),
            f(q.get("planes_off_truth"), 0),
            num("peak_rss_kib").map_or("–".into(), |k| format!("{:.0}", k / 1024.0)),
        );
    }
    out.push_str("\nvisible true planes that no extracted plane matches:\n");
    for r in rows {
        let missed = r.pointer("/quality/true_planes_missed").and_then(Value::as_array);
        if let Some(missed) = missed.filter(|m| !m.is_empty()) {
            let list: Vec<&str> = missed.iter().filter_map(Value::as_str).collect();
            let s = |k: &str| r.get(k).and_then(Value::as_str).unwrap_or("?").to_owned();
            let _ =
                writeln!(out, "- {} {} {}: {}", s("map"), s("tool"), s("method"), list.join("; "));
        }
    }
    out
}

/// The tally of one run's plane polygons against the true planes, shared by every scorer of
/// extracted planes (`peers planes` here, `compare segmentation`'s lab truth): which true
/// planes some polygon matched, the polygons that matched none, and the polygon vertices on a
/// true surface.
pub struct MatchTally {
    found: Vec<bool>,
    off: usize,
    vertices: usize,
    on_surface: usize,
}

impl MatchTally {
    /// A tally over `true_planes` true planes.
    pub fn new(true_planes: usize) -> MatchTally {
        MatchTally { found: vec![false; true_planes], off: 0, vertices: 0, on_surface: 0 }
    }

    /// The tally of a run's plane-polygon JSON against `truth`, a vertex counting as on a
    /// surface where `on_surface` says so.
    pub(crate) fn of_polygons(
        polygons: &Value,
        truth: &[Plane],
        on_surface: impl Fn(&Point3) -> bool,
    ) -> MatchTally {
        let mut tally = MatchTally::new(truth.len());
        for e in parse_planes(polygons) {
            for q in &e.corners {
                tally.vertex(on_surface(q));
            }
            tally.plane(e.matches(truth));
        }
        tally
    }

    /// One polygon vertex, on a true surface or not.
    pub fn vertex(&mut self, on_surface: bool) {
        self.vertices += 1;
        self.on_surface += usize::from(on_surface);
    }

    /// One extracted plane and the true planes it matches (none: off truth).
    pub fn plane(&mut self, matched: Vec<usize>) {
        if matched.is_empty() {
            self.off += 1;
        }
        for i in matched {
            if let Some(f) = self.found.get_mut(i) {
                *f = true;
            }
        }
    }

    /// The quality JSON (the keys of the shared results rows): `visible` true planes, found,
    /// missed (each described by `describe`), off truth, vertices on a surface.
    pub fn report(&self, visible: &[usize], describe: impl Fn(usize) -> String) -> Value {
        let found = |i: usize| self.found.get(i).copied().unwrap_or(false);
        let missed: Vec<String> =
            visible.iter().filter(|&&i| !found(i)).map(|&i| describe(i)).collect();
        let vertices = self.vertices;
        json!({
            "true_planes_missed": missed,
            "true_planes_visible": visible.len(),
            "true_planes_found": visible.iter().filter(|&&i| found(i)).count(),
            "planes_off_truth": self.off,
            "polygon_vertices_checked": vertices,
            "vertices_on_surface": if vertices > 0 { json!(self.on_surface as f64 / vertices as f64) } else { Value::Null },
            "match_angle_deg": MATCH_ANGLE_DEG,
            "match_offset_m": MATCH_OFFSET,
            "on_surface_m": ON_SURFACE,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closest_point_on_a_triangle() {
        let t = [Point3::origin(), Point3::new(1.0, 0.0, 0.0), Point3::new(0.0, 1.0, 0.0)];
        let q = closest_on_triangle(&Point3::new(0.2, 0.2, 0.5), &t);
        assert!((q - Point3::new(0.2, 0.2, 0.0)).norm() < 1e-12);
        let q = closest_on_triangle(&Point3::new(2.0, -1.0, 0.0), &t);
        assert!((q - Point3::new(1.0, 0.0, 0.0)).norm() < 1e-12);
        let q = closest_on_triangle(&Point3::new(1.0, 1.0, 0.0), &t);
        assert!((q - Point3::new(0.5, 0.5, 0.0)).norm() < 1e-12);
    }

    #[test]
    fn coplanar_triangles_share_a_plane_whatever_their_orientation() {
        let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
        let tris = [
            [p(0.0, 0.0, 1.0), p(1.0, 0.0, 1.0), p(0.0, 1.0, 1.0)],
            [p(5.0, 5.0, 1.0), p(5.0, 6.0, 1.0), p(6.0, 5.0, 1.0)],
            [p(0.0, 0.0, 2.0), p(1.0, 0.0, 2.0), p(0.0, 1.0, 2.0)],
        ];
        let (planes, of) = distinct_planes(&tris);
        assert_eq!(planes.len(), 2);
        assert_eq!(of, vec![0, 0, 1]);
        // FORMAT.md writes n · p + d = 0: the floor z = 1 as ((0, 0, -1), 1) matches.
        let e = Plane::canonical(Vector3::new(0.0, 0.0, -1.0), -1.0).unwrap();
        assert!(e.same(&planes[0], 2.0, 0.02));
        assert!(!e.same(&planes[1], 2.0, 0.02));
    }
}
