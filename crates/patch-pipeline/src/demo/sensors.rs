//! The time-of-flight frame (thesis §2.5: a Table 2.4 scene, filtered by region unwrapping,
//! the safe mode beyond the thesis) and
//! the terrain snapshot (Ch. 4: the plane Hough transform and Algorithm 3).

use super::Files;
use crate::results::{TerrainSection, TofSection};
use anyhow::{Context, Result};
use hough_terrain::{
    HistogramStyle, HoughClassifier, HoughConfig, SectorClassifier, SectorGrid, SensorAxes,
    SensorMount, TerrainClass, hough_png,
};
use pointcloud::{Point3, SensorPose};
use scene_sim::{HoughClass, RangeCamera, RangeSensor, TerrainSpec, terrain as terrain_scene};
use sensor_tof::experiment::{TOLERANCE_M, aat_for};
use sensor_tof::regions::{RegionConfig, RegionUnwrapper};
use sensor_tof::scenes::tof_scene;
use sensor_tof::sim::TofSimulator;
use sensor_tof::{PixelOutcome, score};
use std::time::Instant;

/// The Table 2.4 scene the demo filters: a rack before an open door, the room behind beyond
/// the non-ambiguity range, so part of the frame wraps around.
pub const TOF_SCENE: &str = "rack-and-door";

/// Camera height above the floor of the terrain snapshot, metres (a level camera on a
/// Rugbot-sized robot, mid distance bin so noise does not split the floor's votes).
pub const TERRAIN_HEIGHT: f64 = 0.45;

/// Angular resolution of the terrain's Hough space, degrees (thesis: 15° or 9° for classes).
pub const TERRAIN_RESOLUTION_DEG: f64 = 15.0;

/// Half width of the forward view split into left, centre and right sectors, degrees.
pub const SECTOR_HALF_WIDTH_DEG: f64 = 30.0;

/// The terrain snapshot: a ramp climbing 30° from 1.5 m ahead (a class Algorithm 3 tells at
/// 15°, drivable for Rugbot's 35°).
fn terrain_spec() -> TerrainSpec {
    TerrainSpec::Ramp { pitch: 30f64.to_radians(), roll: 0.0, distance: 1.5 }
}

/// Simulates the ToF frame, filters it with region unwrapping (the safe mode beyond the
/// thesis, [`RegionConfig::simulated_sr3000`]: it unwraps only where a region's ranges and
/// amplitudes agree), scores it against the simulator's truth (wrong % and yield) and writes
/// the output cloud (`tof-cloud.ply`, with the `outcome` field) in the camera's optical frame.
pub fn tof(seed: u64, files: &mut Files) -> Result<TofSection> {
    let scene = tof_scene(TOF_SCENE)?;
    let simulator = TofSimulator::new(scene.sim.clone())?;
    let sim = simulator.simulate(&scene.scene, &scene.pose, seed)?;
    let frame = &sim.frame;
    let config = RegionConfig::simulated_sr3000(aat_for(&simulator));
    let unwrapper = RegionUnwrapper::new(frame.camera(), frame.kind(), &config)?;
    let t0 = Instant::now();
    let out = unwrapper.run(frame)?;
    let millis = t0.elapsed().as_secs_f64() * 1e3;
    let measured: Vec<bool> = frame.range().iter().map(|&r| r > 0.0).collect();
    let s = score(&out, &measured, &sim.truth, TOLERANCE_M)?;
    let outcomes = outcome_codes(&out.outcomes, &measured);
    let wrapped = sim.truth.wraps.iter().filter(|&&w| w > 0).count();
    let mut cloud = out.to_cloud(frame, false);
    cloud.set_sensor_pose(Some(scene.pose));
    let name = "tof-cloud.ply";
    pointcloud::io::write_cloud(&files.path(name), &cloud)?;
    files.add(
        format!(
            "ToF output cloud of `{TOF_SCENE}` (camera frame; field `outcome`: 0 kept, 1 unwrapped)"
        ),
        name,
    )?;
    let camera = frame.camera();
    Ok(TofSection {
        scene: TOF_SCENE.to_owned(),
        width: camera.width,
        height: camera.height,
        outcomes,
        radial: out.radial.clone(),
        method: "regions".to_owned(),
        discarded_percent: s.discarded_percent,
        wrapped_percent: 100.0 * wrapped as f64 / sim.truth.wraps.len().max(1) as f64,
        unwrapped_correct_percent: s.unwrapped_correct_percent,
        wrong_percent: s.wrong_kept_percent,
        yield_percent: s.yield_percent,
        millis,
    })
}

/// The lower-case name of a class.
fn class_name(c: TerrainClass) -> String {
    format!("{c:?}").to_lowercase()
}

/// The lower-case name of a scene's true class.
fn truth_name(c: HoughClass) -> String {
    format!("{c:?}").to_lowercase()
}

/// Simulates the SR-3000 on a robot at the origin looking along +x at the terrain scene,
/// classifies the frame by the ground-ahead rule (Hough space at 15°) and per left/centre/right
/// sector by Algorithm 3, and writes the frame
/// (`terrain-frame.ply`) and its Hough space (`terrain-hough.png`, Fig 4.3 layout).
pub fn terrain(seed: u64, files: &mut Files) -> Result<TerrainSection> {
    let spec = terrain_spec();
    let scene = terrain_scene(&spec, seed).context("building the terrain scene")?;
    let truth = scene.terrain_truth().context("a terrain scene has its truth")?.label;
    let camera = RangeCamera::swissranger_sr3000();
    let body = SensorPose::from_position_rpy(Point3::new(0.0, 0.0, TERRAIN_HEIGHT), 0.0, 0.0, 0.0);
    let cloud = camera.scan(&scene, &camera.mount(&body), seed).to_cloud()?;
    let mount = SensorMount::looking_ahead(TERRAIN_HEIGHT, 0.0, 0.0, SensorAxes::Optical)?;
    // The recommended method decides; the Hough space is filled for its picture, and the
    // sectors are Algorithm 3's.
    let mut config = HoughConfig::recommended(TERRAIN_RESOLUTION_DEG.to_radians(), mount)?;
    config.ahead.hough = true;
    let mut classifier = HoughClassifier::new(config)?;
    let t0 = Instant::now();
    let result = classifier.classify_cloud(&cloud)?;
    let millis = t0.elapsed().as_secs_f64() * 1e3;
    let mut png = Vec::new();
    hough_png(
        classifier.accumulator(),
        &HistogramStyle::thesis(Some(classifier.floor_bin())),
        &mut png,
    )?;
    let grid = SectorGrid::left_centre_right(SECTOR_HALF_WIDTH_DEG.to_radians())?;
    let sectors = SectorClassifier::new(config, grid)?
        .classify(cloud.positions())?
        .iter()
        .map(|s| (class_name(s.classification.class), s.classification.drivable))
        .collect();
    let name = "terrain-frame.ply";
    pointcloud::io::write_cloud(&files.path(name), &cloud)?;
    files.add("terrain snapshot, SR-3000 frame (optical frame, with its pose)", name)?;
    let name = "terrain-hough.png";
    pointcloud::io::write_bytes_atomically(files.path(name), &png)?;
    files.add("terrain Hough space (thesis Fig 4.3 layout)", name)?;
    let ground = terrain_ground(&scene, &cloud, &mount)?;
    let p = result.plane.context("the terrain frame gave no votes")?;
    let plane = [p.rho_x.to_degrees(), p.rho_y.to_degrees(), p.d];
    Ok(TerrainSection {
        scene: "ramp 30° from 1.5 m".to_owned(),
        truth: truth_name(truth),
        class: class_name(result.class),
        drivable: result.drivable,
        plane,
        resolution_deg: TERRAIN_RESOLUTION_DEG,
        millis,
        points: result.points,
        hough_png: png,
        sectors,
        ground: Some(ground),
    })
}

/// The snapshot's per-point ground ([`hough_terrain::GroundSegmenter`]) scored against the
/// scene's drivable surfaces: the floor, and the ramp and its platform if passable.
fn terrain_ground(
    scene: &scene_sim::Scene,
    cloud: &pointcloud::PointCloud,
    mount: &SensorMount,
) -> Result<crate::results::GroundScore> {
    let passable = scene.terrain_truth().is_some_and(|t| t.passable);
    let drivable: Vec<bool> = scene
        .surfaces()
        .iter()
        .map(|s| {
            s.name == "floor" || (passable && ["ramp", "platform/+z"].contains(&s.name.as_str()))
        })
        .collect();
    let labels = cloud.labels().context("the snapshot has surface labels")?;
    let truth: Vec<Option<bool>> =
        labels.iter().map(|&l| Some(drivable.get(l as usize).copied().unwrap_or(false))).collect();
    let mut segmenter =
        hough_terrain::GroundSegmenter::new(hough_terrain::GroundSettings::default())?;
    let mut ground = Vec::new();
    let t0 = Instant::now();
    let summary = segmenter.segment(cloud.positions(), mount, &mut ground)?;
    let millis = t0.elapsed().as_secs_f64() * 1e3;
    let s = evaluation::peers::ground::score(&ground, &truth)?;
    Ok(crate::results::GroundScore {
        share: summary.ground as f64 / summary.points.max(1) as f64,
        precision: s.precision(),
        recall: s.recall(),
        f1: s.f1(),
        millis,
    })
}

/// The pixel outcomes as [`TofSection::outcomes`] stores them: 0 kept, 1 unwrapped, 2 dropped,
/// 3 not measured (range 0) — shared by the demo and `patchnav run`.
pub fn outcome_codes(outcomes: &[PixelOutcome], measured: &[bool]) -> Vec<u8> {
    outcomes
        .iter()
        .zip(measured)
        .map(|(&o, &m)| match o {
            PixelOutcome::Kept => 0,
            PixelOutcome::Unwrapped => 1,
            PixelOutcome::Dropped if m => 2,
            PixelOutcome::Dropped => 3,
        })
        .collect()
}
