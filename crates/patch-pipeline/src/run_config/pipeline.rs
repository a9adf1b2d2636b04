//! The stages of `patchnav run`: filter the ToF frame and classify the terrain frame if given,
//! read the input, build the map types in their backends, plan with every planner and seed on
//! every map, time RRTs and compare explored volumes if asked, and collect it all in the demo's
//! [`DemoResults`].

use super::config::{Config, Input, TerrainConfig, TofConfig};
use crate::Progress;
use crate::SensorPreset;
use crate::demo::explore::{Exploration, Target, explore};
use crate::demo::maps::{drawing, patch_mesh, point_map_entry};
use crate::demo::planning::RunRecord;
use crate::demo::{Clock, Files, p3, write_mesh_f32, write_ply_f32};
use crate::input::CloudInput;
use crate::results::{
    DemoResults, MapDrawing, MapRow, PlanRun, SceneInfo, TerrainSection, TimingCurve, TofSection,
    VolumeSection,
};
use crate::scene_map::{MapKind, SceneSurfaces, Tessellation, patch_map};
use crate::terrain::TerrainSetup;
use crate::tof::{FilterSetup, FrameSource, filter_frame};
use anyhow::{Context, Result, bail};
use hough_terrain::{HistogramStyle, hough_png};
use patch_core::{CapsuleStep, Patch, Point3, UnspecificStepIntersector};
use patch_map::{
    AnyMap, Backend, MeshToPatchesConfig, PointCloudMap, planar_patches_from_mesh,
    sample_patch_points,
};
use pointcloud::{Aabb, PointCloud, SensorPose};
use roadmap::{
    AnyOf, Goal, GoalReached, MaxIterations, PlannerKind, PlannerStatus, PlanningSpace, Problem,
};
use std::path::Path;
use std::time::Instant;

/// The backend each patch map is loaded into when `maps.backends` is not given: the parry BVH,
/// as the demo plans on ([`crate::demo::maps::plan_backend`]).
pub const DEFAULT_BACKEND: Backend = Backend::Trimesh;

/// One map built, in one backend.
pub struct Built {
    /// Map type.
    pub kind: MapKind,
    /// The map.
    pub map: AnyMap,
}

/// What was read.
enum Source {
    /// Scans in their sensor frames with their poses.
    Scans(Vec<PointCloud>),
    /// A mesh's surfaces: its planar patches (coplanar faces merged) and the trimesh patches
    /// of faces that make no valid polygon, with the mesh's box.
    Mesh(SceneSurfaces, Aabb),
    /// A map file's map.
    Map(AnyMap),
    /// World points.
    Points(Vec<Point3>),
}

/// The patches of a map type from scans (thesis §6.1), with the thresholds of `sensor`
/// ([`crate::scene_map::extracted_patches_with`]).
fn scan_patches(clouds: &[PointCloud], kind: MapKind, sensor: SensorPreset) -> Result<Vec<Patch>> {
    let (pipeline, grow) = sensor.configs();
    crate::scene_map::extracted_patches_with(clouds, kind, pipeline, grow, None)?
        .context("the pc map has no patches")
}

/// The map type a map file holds: `pc` for points, else by its patches.
fn kind_of(map: &AnyMap) -> MapKind {
    let Some(patches) = map.patches() else { return MapKind::Pc };
    let planar = patches.iter().filter(|p| p.as_planar().is_some()).count();
    match (planar, patches.len() - planar) {
        (_, 0) => MapKind::Planes,
        (0, _) => MapKind::Trimesh,
        _ => MapKind::Hybrid,
    }
}

/// Reads the input.
fn read(config: &Config, progress: &dyn Progress) -> Result<Source> {
    let options = CloudInput { skip_non_finite: config.skip_non_finite, depth: None };
    Ok(match &config.input {
        Input::Scans { files, poses } => {
            let poses = poses.as_deref().map(crate::files::read_poses).transpose()?;
            let bar = progress.bar(files.len() as u64, "reading");
            let mut clouds = Vec::with_capacity(files.len());
            for path in files {
                let mut cloud = crate::input::read_cloud(path, &options)?;
                if let Some(poses) = &poses {
                    let name = path.file_name().map(|f| f.to_string_lossy().into_owned());
                    let pose = name.as_ref().and_then(|n| poses.get(n)).with_context(|| {
                        format!("input.poses: {} is not in the poses file", path.display())
                    })?;
                    cloud.set_sensor_pose(Some(SensorPose { world_from_sensor: *pose }));
                }
                if cloud.is_empty() {
                    bail!("input.scans: {} has no points", path.display());
                }
                clouds.push(cloud);
                bar.inc(1);
            }
            bar.finish_and_clear();
            Source::Scans(clouds)
        }
        Input::Mesh(path) => {
            let mesh = pointcloud::io::read_mesh(path)?;
            let (patches, _) = planar_patches_from_mesh(&mesh, &MeshToPatchesConfig::exact_cad());
            if patches.is_empty() {
                bail!("input.mesh: {} has no usable faces", path.display());
            }
            let mut surfaces = SceneSurfaces { planar: Vec::new(), curved: Vec::new() };
            for p in patches {
                match p {
                    Patch::Planar(p) => surfaces.planar.push(p),
                    Patch::Trimesh(m) => surfaces.curved.push(m),
                }
            }
            Source::Mesh(surfaces, mesh.bounds())
        }
        Input::Map(path) => Source::Map(crate::files::open_map(path)?),
        Input::Cloud(path) => {
            let cloud = crate::input::read_cloud(path, &options)?.to_world();
            if cloud.is_empty() {
                bail!("input.cloud: {} has no points", path.display());
            }
            Source::Points(cloud.positions().to_vec())
        }
    })
}

/// Maps, rows and drawings, built up.
struct Maps {
    built: Vec<Built>,
    rows: Vec<MapRow>,
    drawings: Vec<MapDrawing>,
}

impl Maps {
    /// The name of `m` in file names, timing curves and the volume table: its type, or type
    /// and backend when the type is in several backends.
    fn name(&self, m: &Built) -> String {
        if self.built.iter().filter(|b| b.kind == m.kind).count() > 1 {
            format!("{}-{}", m.kind, m.map.backend())
        } else {
            m.kind.name().to_owned()
        }
    }

    /// Loads `patches` into every backend, records the rows, the drawing and the mesh file.
    fn add_patches(
        &mut self,
        kind: MapKind,
        patches: Vec<Patch>,
        seconds: f64,
        backends: &[Backend],
        files: &mut Files,
        write_3d: bool,
    ) -> Result<()> {
        if patches.is_empty() {
            bail!(
                "the {kind} map has no patches (nothing was extracted); leave it out of maps.types"
            );
        }
        let (planar, trimesh, triangles) = crate::demo::maps::patch_counts(&patches)?;
        for &backend in backends {
            let t0 = Instant::now();
            let map = patch_map(patches.clone(), backend)
                .with_context(|| format!("loading the {kind} map into {}", backend.name()))?;
            let load = t0.elapsed().as_secs_f64();
            self.rows.push(crate::demo::maps::patch_map_row(
                kind,
                &map,
                (planar, trimesh, triangles),
                seconds + load,
            )?);
            self.built.push(Built { kind, map });
        }
        self.drawings.push(drawing(kind, &patches));
        if write_3d {
            let name = format!("map-{kind}.ply");
            let (vertices, faces) = patch_mesh(&patches)?;
            write_mesh_f32(&files.path(&name), &vertices, &faces)?;
            files.add(
                format!("{kind} map: {planar} planar patches (triangulated) and {trimesh} trimesh patches, PLY mesh"),
                &name,
            )?;
        }
        Ok(())
    }

    /// Records a map used as it is (a map file's, or the pc map).
    fn add_map(
        &mut self,
        kind: MapKind,
        map: AnyMap,
        seconds: f64,
        files: &mut Files,
        write_3d: bool,
    ) -> Result<()> {
        if let Some(patches) = map.patches() {
            let patches = patches.to_vec();
            let counts = crate::demo::maps::patch_counts(&patches)?;
            self.rows.push(crate::demo::maps::patch_map_row(kind, &map, counts, seconds)?);
            self.drawings.push(drawing(kind, &patches));
            if write_3d {
                let name = format!("map-{kind}.ply");
                let (vertices, faces) = patch_mesh(&patches)?;
                write_mesh_f32(&files.path(&name), &vertices, &faces)?;
                files.add(format!("{kind} map (PLY mesh)"), &name)?;
            }
        } else {
            let AnyMap::PointCloud(pc) = &map else {
                bail!("a `{}` map has neither patches nor points", map.backend())
            };
            if pc.is_empty() {
                bail!("the pc map has no points");
            }
            let (row, drawing) = point_map_entry(&map, seconds)?;
            self.rows.push(row);
            self.drawings.push(drawing);
            if write_3d {
                let name = "map-pc.ply";
                let points: Vec<Point3> = pc.points().collect();
                write_ply_f32(&files.path(name), &PointCloud::from_positions(points)?)?;
                files.add("pc map: its points in the world frame", name)?;
            }
        }
        self.built.push(Built { kind, map });
        Ok(())
    }
}

/// How a mesh's trimesh map is made (thesis §6.1: the trimesh map holds every surface as
/// triangles): the mesh's surfaces are triangulated (planar patches by constrained Delaunay),
/// split until no edge is longer than `maps.mesh_edge` (unsplit without it: twice the mesh's
/// box diagonal bounds every edge) and cut into patches of at most `maps.max_patch_triangles`,
/// as [`SceneSurfaces::patches`] meshes a simulated scene.
fn mesh_tessellation(config: &Config, bounds: &Aabb) -> Tessellation {
    let diagonal = (bounds.max - bounds.min).norm();
    Tessellation {
        mesh_edge: config.mesh_edge.unwrap_or(2.0 * diagonal.max(1.0)),
        max_patch_triangles: config.max_patch_triangles,
        ..Tessellation::lab()
    }
}

/// Builds the configured map types from `source`.
fn build(
    config: &Config,
    source: Source,
    progress: &dyn Progress,
    files: &mut Files,
) -> Result<Maps> {
    let mut maps = Maps { built: Vec::new(), rows: Vec::new(), drawings: Vec::new() };
    let backends = config.backends.clone().unwrap_or_else(|| vec![DEFAULT_BACKEND]);
    let bar = progress.bar(config.types.len() as u64, "maps");
    let w = config.write_3d;
    let point_map = |points: &[Point3]| -> Result<AnyMap> {
        Ok(AnyMap::PointCloud(PointCloudMap::from_points(points)?))
    };
    match source {
        Source::Scans(clouds) => {
            for &kind in &config.types {
                let t0 = Instant::now();
                if kind == MapKind::Pc {
                    let points: Vec<Point3> =
                        clouds.iter().flat_map(|c| c.to_world().positions().to_vec()).collect();
                    let map = point_map(&points)?;
                    maps.add_map(kind, map, t0.elapsed().as_secs_f64(), files, w)?;
                } else {
                    let patches = scan_patches(&clouds, kind, config.sensor)
                        .with_context(|| format!("extracting the {kind} map"))?;
                    maps.add_patches(
                        kind,
                        patches,
                        t0.elapsed().as_secs_f64(),
                        &backends,
                        files,
                        w,
                    )?;
                }
                bar.inc(1);
            }
        }
        Source::Mesh(surfaces, bounds) => {
            let tessellation = mesh_tessellation(config, &bounds);
            for &kind in &config.types {
                let t0 = Instant::now();
                let patches = surfaces.patches(kind, &tessellation).with_context(|| {
                    format!("maps.mesh_edge: meshing the {kind} map of the mesh")
                })?;
                match patches {
                    Some(patches) => maps.add_patches(
                        kind,
                        patches,
                        t0.elapsed().as_secs_f64(),
                        &backends,
                        files,
                        w,
                    )?,
                    None => {
                        let hybrid = surfaces
                            .patches(MapKind::Hybrid, &tessellation)?
                            .context("the hybrid map has patches")?;
                        let points = sample_patch_points(&hybrid, config.spacing)?;
                        let map = point_map(&points)?;
                        maps.add_map(kind, map, t0.elapsed().as_secs_f64(), files, w)?;
                    }
                }
                bar.inc(1);
            }
        }
        Source::Map(map) => {
            let kind = kind_of(&map);
            if !config.types.contains(&kind) {
                let asked: Vec<&str> = config.types.iter().map(|k| k.name()).collect();
                bail!("maps.types: the map file holds a {kind} map, not {}", asked.join(", "));
            }
            match (&config.backends, map.patches()) {
                (Some(b), Some(patches)) => {
                    maps.add_patches(kind, patches.to_vec(), 0.0, b, files, w)?;
                }
                (Some(_), None) => {
                    bail!("maps.backends: a pc map stays in the {} backend", Backend::PointCloud)
                }
                (None, _) => maps.add_map(kind, map, 0.0, files, w)?,
            }
            bar.inc(1);
        }
        Source::Points(points) => {
            let t0 = Instant::now();
            let map = point_map(&points)?;
            maps.add_map(MapKind::Pc, map, t0.elapsed().as_secs_f64(), files, w)?;
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    Ok(maps)
}

/// Checks every start (`plan.start`, `timing.starts`, `volume.starts`) before any run.
fn check_starts(config: &Config, maps: &Maps) -> Result<()> {
    let r = config.plan.radius;
    check_start("plan.start", &config.plan.start, maps, r)?;
    let lists = [
        ("timing", config.timing.as_ref().map(|t| &t.starts)),
        ("volume", config.volume.as_ref().map(|v| &v.starts)),
    ];
    for (section, starts) in lists {
        for (k, s) in starts.into_iter().flatten().enumerate() {
            check_start(&format!("{section}.starts[{k}]"), s, maps, r)?;
        }
    }
    Ok(())
}

/// Checks that `start` (the value of `key`) lies in every map's box and is free (no surface
/// within `radius`): the commonest mistake, named in one line.
fn check_start(key: &str, start: &Point3, maps: &Maps, radius: f64) -> Result<()> {
    let at = format!("{key} ({}, {}, {})", start.x, start.y, start.z);
    for m in &maps.built {
        let b = m.map.bounds();
        if !b.contains(start) {
            bail!("{at} is outside the {} map's box {}", m.kind, crate::files::box_text(&b));
        }
        if !CapsuleStep::sphere(*start, radius).is_ok_and(|s| m.map.is_step_free(&s)) {
            bail!(
                "{at} is not free on the {} map: a surface is within plan.radius = {radius} m",
                m.kind
            );
        }
    }
    Ok(())
}

/// The RRT timing curves (`[timing]`, Fig 6.4) and the explored-volume comparison
/// (`[volume]`, Table 6.2 / 6.4, Fig 6.1) on every map, as the demo makes them
/// ([`explore`]); one set of runs gives both when `[volume]` asks for the timed RRTs' very
/// runs (its defaults).
fn timing_and_volume(
    config: &Config,
    maps: &Maps,
    progress: &dyn Progress,
) -> Result<(Vec<TimingCurve>, Option<VolumeSection>)> {
    let p = &config.plan;
    let targets: Vec<Target<'_>> =
        maps.built.iter().map(|m| Target { name: maps.name(m), map: &m.map }).collect();
    let run = |planner, iterations, starts, seeds, checkpoints, cells| {
        let e = Exploration {
            planner,
            iterations,
            starts,
            seeds,
            radius: p.radius,
            step: p.step,
            checkpoints,
            cells,
        };
        explore(&targets, &e, progress)
    };
    let mut curves = Vec::new();
    if let Some(t) = &config.timing {
        let shared = config.volume.as_ref().filter(|v| v.shares_runs_with(t));
        let (c, volume) = run(
            PlannerKind::Rrt,
            t.iterations,
            &t.starts,
            &t.seeds,
            Some(t.checkpoints),
            shared.map(|v| v.cells),
        )?;
        if shared.is_some() {
            return Ok((c, volume));
        }
        curves = c;
    }
    let Some(v) = &config.volume else { return Ok((curves, None)) };
    let (_, volume) = run(v.planner, v.iterations, &v.starts, &v.seeds, None, Some(v.cells))?;
    Ok((curves, volume))
}

/// The planning runs and the lines of runs skipped.
fn plan(
    config: &Config,
    maps: &Maps,
    progress: &dyn Progress,
    files: &mut Files,
) -> Result<(Vec<PlanRun>, Vec<String>)> {
    let p = &config.plan;
    let problem = Problem {
        start: p.start,
        goals: p.goals.iter().map(|&center| Goal { center, tolerance: p.goal_tolerance }).collect(),
    };
    let runs_per_map = (p.planners.len() * p.seeds.len()) as u64;
    let bar = progress.bar(maps.built.len() as u64 * runs_per_map, "planning");
    let mut runs = Vec::new();
    let mut skipped = Vec::new();
    for m in &maps.built {
        let space = PlanningSpace::new(m.map.bounds(), p.radius, p.step)
            .with_context(|| format!("the {} map's planning space", m.kind))?;
        for &kind in &p.planners {
            if !kind.runs_on(&m.map) {
                skipped.push(format!(
                    "{kind} skipped on the {} map: it needs a patch map (proximity queries or specific hits)",
                    m.kind
                ));
                bar.inc(p.seeds.len() as u64);
                continue;
            }
            for (k, &seed) in p.seeds.iter().enumerate() {
                let mut run = roadmap::named_planner_on(kind, &m.map, space, seed)?;
                let t0 = Instant::now();
                let status =
                    run.solve(&problem, &mut AnyOf(GoalReached, MaxIterations(p.max_iterations)));
                let seconds = t0.elapsed().as_secs_f64();
                if status == PlannerStatus::InvalidStart {
                    bail!("plan.start is not a valid start on the {} map ({})", m.kind, run.name());
                }
                let name = kind.to_string();
                let record = RunRecord {
                    kind: m.kind,
                    map: &m.map,
                    drawn: k == 0,
                    obj_tag: (k == 0 && config.write_3d)
                        .then(|| format!("{}-{name}", maps.name(m))),
                    name,
                    seed,
                    seconds,
                    start: p.start,
                    goals: &p.goals,
                };
                runs.push(record.record(run.as_ref(), files)?);
                bar.inc(1);
            }
        }
    }
    bar.finish_and_clear();
    Ok((runs, skipped))
}

/// Filters the ToF frame as `patchnav tof filter --method M` does (region unwrapping by
/// default) and writes the output cloud (`tof-cloud.ply`). Without the truth of a
/// simulation, the wrapped, unwrapped-correctly and wrong percentages are unknown (NaN; `null`
/// in `results.json`, a dash in the report).
fn tof(t: &TofConfig, files: &mut Files, write_3d: bool) -> Result<TofSection> {
    let frame = FrameSource {
        range: Some(t.range.clone()),
        amplitude: Some(t.amplitude.clone()),
        confidence: t.confidence.clone(),
        meta: t.meta.clone(),
    };
    let setup = FilterSetup {
        aat: t.aat,
        unwrap: t.unwrap,
        low_at: t.low_at,
        ..FilterSetup::new(frame, t.method)
    };
    let out_path = files.path("tof-cloud.ply");
    let t0 = Instant::now();
    let (frame, out, name) = filter_frame(&setup).context("[tof]")?;
    let millis = t0.elapsed().as_secs_f64() * 1e3;
    let measured: Vec<bool> = frame.range().iter().map(|&r| r > 0.0).collect();
    let outcomes = crate::demo::sensors::outcome_codes(&out.outcomes, &measured);
    if write_3d {
        let cloud = out.to_cloud(&frame, false);
        pointcloud::io::write_cloud(&out_path, &cloud)?;
        files.add(
            "ToF output cloud (camera frame; field `outcome`: 0 kept, 1 unwrapped)",
            "tof-cloud.ply",
        )?;
    }
    let camera = frame.camera();
    Ok(TofSection {
        scene: t.range.file_name().map_or_else(String::new, |f| f.to_string_lossy().into_owned()),
        width: camera.width,
        height: camera.height,
        outcomes,
        radial: out.radial.clone(),
        method: if t.unwrap { format!("{name} + unwrap") } else { name },
        discarded_percent: out.counts.discarded_percent(),
        wrapped_percent: f64::NAN,
        unwrapped_correct_percent: f64::NAN,
        wrong_percent: f64::NAN,
        yield_percent: f64::NAN,
        millis,
    })
}

/// Classifies the terrain frame as `patchnav terrain --sectors N` does and writes its Hough
/// space (`terrain-hough.png`, Fig 4.3 layout).
fn terrain(t: &TerrainConfig, files: &mut Files) -> Result<TerrainSection> {
    let setup = TerrainSetup {
        sectors: Some(t.sectors),
        axes: t.axes,
        resolution: t.resolution,
        sensor_height: t.sensor_height,
        pitch: t.pitch,
        max_range: t.max_range,
        ..TerrainSetup::new(t.frame.clone())
    };
    let c = crate::terrain::classify(&setup).context("[terrain]")?;
    let mut png = Vec::new();
    hough_png(
        c.classifier.accumulator(),
        &HistogramStyle::thesis(Some(c.classifier.floor_bin())),
        &mut png,
    )?;
    let name = "terrain-hough.png";
    pointcloud::io::write_bytes_atomically(files.path(name), &png)?;
    files.add("terrain Hough space (thesis Fig 4.3 layout)", name)?;
    let class = |x: hough_terrain::TerrainClass| format!("{x:?}").to_lowercase();
    let plane =
        c.result.plane.map_or([f64::NAN; 3], |p| [p.rho_x.to_degrees(), p.rho_y.to_degrees(), p.d]);
    Ok(TerrainSection {
        scene: t.frame.file_name().map_or_else(String::new, |f| f.to_string_lossy().into_owned()),
        truth: "unknown".to_owned(),
        class: class(c.result.class),
        drivable: c.result.drivable,
        plane,
        resolution_deg: t.resolution,
        millis: c.seconds * 1e3,
        points: c.result.points,
        hough_png: png,
        sectors: c
            .sectors
            .iter()
            .map(|s| (class(s.classification.class), s.classification.drivable))
            .collect(),
        // The user's frame has no per-point truth to score ground labels against.
        ground: None,
    })
}

/// Runs every stage, writing the 3D files into `config.out` (which must exist); returns the
/// results and the lines about runs skipped.
///
/// # Errors
/// An input that cannot be read, a map type that cannot be built from it, a start that is not
/// free, a planner refusing its map, a ToF or terrain frame that cannot be processed, or a file
/// that cannot be written.
pub fn run(config: &Config, progress: &dyn Progress) -> Result<(DemoResults, Vec<String>)> {
    let out: &Path = &config.out;
    let mut files = Files::new(out);
    let mut clock = Clock::new();
    let tof = match &config.tof {
        Some(t) => {
            let section = tof(t, &mut files, config.write_3d)?;
            clock.lap("ToF: filter");
            Some(section)
        }
        None => None,
    };
    let terrain = match &config.terrain {
        Some(t) => {
            let section = terrain(t, &mut files)?;
            clock.lap("terrain: classify");
            Some(section)
        }
        None => None,
    };
    let spinner = progress.spinner("reading the input");
    let source = read(config, progress)?;
    spinner.finish_and_clear();
    let (scan_positions, points) = match &source {
        Source::Scans(clouds) => (
            clouds
                .iter()
                .map(|c| {
                    c.sensor_pose().map_or([0.0; 3], |p| {
                        p3(&Point3::from(p.world_from_sensor.translation.vector))
                    })
                })
                .collect(),
            clouds.iter().map(PointCloud::len).sum(),
        ),
        Source::Points(p) => (Vec::new(), p.len()),
        _ => (Vec::new(), 0),
    };
    clock.lap("input: read");
    let maps = build(config, source, progress, &mut files)?;
    clock.lap("maps: extract and load");
    check_starts(config, &maps)?;
    let (plans, skipped) = plan(config, &maps, progress, &mut files)?;
    clock.lap("planning");
    let (timing, volume) = timing_and_volume(config, &maps, progress)?;
    match (&config.timing, &config.volume) {
        (Some(_), Some(_)) => clock.lap("RRT timing and explored volume"),
        (Some(_), None) => clock.lap("RRT timing"),
        (None, Some(_)) => clock.lap("explored volume"),
        (None, None) => {}
    }
    let bounds = maps.built.iter().map(|m| m.map.bounds()).fold(Aabb::EMPTY, |a, b| a.union(&b));
    let scene = SceneInfo {
        name: config.name.clone(),
        min: p3(&bounds.min),
        max: p3(&bounds.max),
        scan_positions,
        points,
    };
    let results = DemoResults {
        command: "run".to_owned(),
        scale: None,
        seed: config.plan.seeds[0],
        stages: clock.stages,
        scene,
        tof,
        terrain,
        maps: maps.rows,
        drawings: maps.drawings,
        plans,
        timing,
        volume,
        safety: None,
        files: files.entries,
    };
    Ok((results, skipped))
}
