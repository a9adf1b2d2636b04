//! `patchnav terrain FRAME`: the terrain class and drivability of the view ahead by the plane
//! Hough transform ([`patch_pipeline::terrain`]; thesis Ch. 4, Algorithms 2 and 3).
//! `patchnav terrain BAG --topic T`: the same for every message of a bag's cloud or depth
//! image topic, one line each.

use crate::input::InputArgs;
use crate::progress::Progress;
use anyhow::{Result, bail};
use patch_pipeline::terrain::ground::{GROUND_FIELD, GroundSetup, segment_ground};
use patch_pipeline::terrain::{
    AxesChoice, Classified, Method, TerrainSetup, class_name, classify, classify_cloud,
};
use std::path::PathBuf;

/// Arguments of `patchnav terrain`.
#[derive(Debug, clap::Args)]
pub struct TerrainArgs {
    /// A range frame or point cloud (.ply .pcd .xyz .txt .bin .3d, or a 16-bit .png depth
    /// image), or a ROS bag (.mcap, a rosbag2 folder, .bag) with --topic.
    pub frame: PathBuf,
    /// The bag's cloud topic (`sensor_msgs/PointCloud2`, `LaserScan`, or a depth `Image`):
    /// every message is classified, one result line each.
    #[arg(long)]
    pub topic: Option<String>,
    /// For a depth image topic: its `sensor_msgs/CameraInfo` topic (default: the sibling
    /// `camera_info`).
    #[arg(long, requires = "topic")]
    pub camera_info: Option<String>,
    /// Angular resolution of the Hough space, degrees (thesis: 45 for drivability, 15 or 9 for
    /// classes).
    #[arg(long, default_value_t = 15.0)]
    pub resolution: f64,
    /// Which rule decides the class: the ground-ahead rule, or the thesis's Algorithm 3
    /// verbatim (its tables).
    #[arg(long, default_value = "ground-ahead", value_parser = crate::names::all::<Method>())]
    pub method: Method,
    /// Also classify this many azimuth sectors (left to right) of the forward view.
    #[arg(long)]
    pub sectors: Option<usize>,
    /// Also label every point as drivable ground or not (local ground planes within the robot's
    /// 0.2 m step and 35° slope limits) and write the cloud with a `ground` field (u8: 1 =
    /// ground, 0 = not) to this file (.ply or .pcd).
    #[arg(long, value_name = "CLOUD")]
    pub ground_out: Option<PathBuf>,
    /// Write the Hough space (thesis Fig 4.3 layout) as a PNG.
    #[arg(long, value_name = "PNG")]
    pub hough_png: Option<PathBuf>,
    /// The sensor's axes [default: camera for organised frames (depth images, range-camera
    /// clouds), lidar otherwise].
    #[arg(long, value_parser = crate::names::all::<AxesChoice>())]
    pub axes: Option<AxesChoice>,
    /// The sensor's height above the floor, metres (fixes the floor bin) [default: estimated
    /// from the frame's ground plane, with pitch and roll].
    #[arg(long)]
    pub sensor_height: Option<f64>,
    /// The sensor's pitch, degrees down from level [default: estimated from the frame; level
    /// when --sensor-height is given].
    #[arg(long)]
    pub pitch: Option<f64>,
    /// Keep only points ahead (±45° of azimuth) within this horizontal range, metres. Lidar
    /// frames are always cut to the forward view (the method classifies the terrain ahead).
    #[arg(long)]
    pub max_range: Option<f64>,
    /// Classify the frame this many times and report the median time.
    #[arg(long, default_value_t = 1)]
    pub repeat: usize,
    /// Print the result as one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub input: InputArgs,
}

impl TerrainArgs {
    /// The library's settings.
    pub fn setup(&self) -> TerrainSetup {
        TerrainSetup {
            frame: self.frame.clone(),
            resolution: self.resolution,
            method: self.method,
            sectors: self.sectors,
            hough_png: self.hough_png.clone(),
            axes: self.axes,
            sensor_height: self.sensor_height,
            pitch: self.pitch,
            max_range: self.max_range,
            repeat: self.repeat,
            input: self.input.input(),
        }
    }
}

/// Runs `patchnav terrain`.
pub fn run(args: &TerrainArgs, progress: &Progress) -> Result<()> {
    if crate::extract::is_bag(&args.frame) || args.topic.is_some() {
        return run_bag(args, progress);
    }
    let classified = classify(&args.setup())?;
    let ground = match &args.ground_out {
        Some(out) => Some(segment_ground(&GroundSetup {
            frame: args.frame.clone(),
            input: args.input.input(),
            axes: Some(classified.axes),
            mount: Some(classified.mount),
            out: Some(out.clone()),
            repeat: args.repeat,
            ..GroundSetup::new(args.frame.clone())
        })?),
        None => None,
    };
    let Classified {
        cloud_points,
        points,
        axes,
        mount: (height, pitch, roll),
        estimated,
        result,
        seconds,
        classifier,
        sectors,
    } = classified;
    let ground_json = ground.as_ref().map(|g| {
        serde_json::json!({"points": g.summary.points, "ground": g.summary.ground,
            "cells": g.summary.cells, "ground_cells": g.summary.ground_cells,
            "first_ms": g.first() * 1e3, "best_ms": g.best() * 1e3, "median_ms": g.median() * 1e3,
            "runs": g.times.len(), "field": GROUND_FIELD})
    });
    if args.json {
        let sectors: Vec<_> = sectors
            .iter()
            .map(|s| {
                serde_json::json!({"azimuth_deg": [s.azimuth.0.to_degrees(), s.azimuth.1.to_degrees()],
                    "class": class_name(&s.classification), "drivable": s.classification.drivable})
            })
            .collect();
        let plane = result.plane.map(|p| {
            serde_json::json!({"rho_x_deg": p.rho_x.to_degrees(), "rho_y_deg": p.rho_y.to_degrees(), "d": p.d})
        });
        let row = serde_json::json!({
            "frame": args.frame.display().to_string(), "points": cloud_points, "points_used": points.len(),
            "resolution_deg": args.resolution, "class": class_name(&result), "drivable": result.drivable,
            "accepted": result.accepted, "rule": format!("{:?}", result.rule), "plane": plane,
            "votes": result.votes, "high_bins": result.high_bins, "time_ms": seconds * 1e3, "repeat": args.repeat,
            "sectors": sectors, "ground": ground_json,
            "mount": {"height_m": height, "pitch_deg": pitch, "roll_deg": roll,
                "estimated": estimated.map(|e| serde_json::json!({"inliers": e.inliers, "points": e.points, "rms_m": e.rms}))},
        });
        progress.report(row.to_string());
        return Ok(());
    }
    let space = classifier.config().space;
    progress.report(format!(
        "frame:     {} ({} points, {} used; {:?} axes)",
        args.frame.display(),
        cloud_points,
        points.len(),
        axes,
    ));
    progress.report(match estimated {
        Some(e) => format!(
            "mount:     {height:.2} m up, pitched {pitch:.1}° down, rolled {roll:.1}° (estimated: {} of {} points on the ground plane, rms {:.3} m)",
            e.inliers, e.points, e.rms
        ),
        None => format!("mount:     {height:.2} m up, pitched {pitch:.1}° down (given)"),
    });
    progress.report(format!("class:     {}", class_name(&result)));
    progress.report(format!("drivable:  {}", if result.drivable { "yes" } else { "no" }));
    progress.report(match result.plane {
        Some(p) => format!(
            "plane:     ρx {:.1}°, ρy {:.1}°, d {:.2} m (levelled frame, z down; {} votes of #PC {}, {} bins above t_m·max)",
            p.rho_x.to_degrees(),
            p.rho_y.to_degrees(),
            p.d,
            result.votes,
            result.points,
            result.high_bins
        ),
        None => "plane:     none (no vote in range)".to_owned(),
    });
    progress.report(format!(
        "rule:      {:?}{}",
        result.rule,
        if result.accepted { "" } else { " (too few valid points)" }
    ));
    progress.report(format!(
        "time:      {:.3} ms (Hough space {}° : {} × {} angles × {} d bins{})",
        seconds * 1e3,
        args.resolution,
        space.nx(),
        space.ny(),
        space.nd(),
        if args.repeat > 1 { format!(", median of {}", args.repeat) } else { String::new() }
    ));
    if let (Some(g), Some(out)) = (&ground, &args.ground_out) {
        let n = g.summary.points.max(1) as f64;
        progress.report(format!(
            "ground:    {} of {} points ({:.1} %), {} of {} cells; {:.3} ms{} -> {} (field `{GROUND_FIELD}`, u8 1 = ground)",
            g.summary.ground,
            g.summary.points,
            100.0 * g.summary.ground as f64 / n,
            g.summary.ground_cells,
            g.summary.cells,
            g.best() * 1e3,
            if g.times.len() > 1 {
                format!(" best, {:.3} median of {} after a first of {:.3}", g.median() * 1e3, g.times.len() - 1, g.first() * 1e3)
            } else {
                String::new()
            },
            out.display()
        ));
    }
    for (k, s) in sectors.iter().enumerate() {
        progress.report(format!(
            "sector {k}:  azimuth {:.0}°..{:.0}° (negative = left): {}, drivable: {}",
            s.azimuth.0.to_degrees(),
            s.azimuth.1.to_degrees(),
            class_name(&s.classification),
            if s.classification.drivable { "yes" } else { "no" }
        ));
    }
    Ok(())
}

/// `patchnav terrain BAG --topic T`: every message of the topic classified, one line (or JSON
/// object) each, in bag order; the mount is estimated per message unless given.
fn run_bag(args: &TerrainArgs, progress: &Progress) -> Result<()> {
    let Some(topic) = &args.topic else {
        bail!("{}: a bag needs --topic (`patchnav info` lists its topics)", args.frame.display());
    };
    if !crate::extract::is_bag(&args.frame) {
        bail!("--topic takes a ROS bag (.mcap, a rosbag2 folder, .bag)");
    }
    if args.ground_out.is_some() || args.hough_png.is_some() {
        bail!("--ground-out and --hough-png write one frame: give a frame file, not a bag");
    }
    let query = ros_bag::ScanQuery {
        camera_info: args.camera_info.clone(),
        posed: false,
        ..ros_bag::ScanQuery::all(topic)
    };
    let bag = ros_bag::Bag::open(&args.frame)?;
    let summary = ros_bag::for_each_scan(&bag, &query, |scan| -> Result<()> {
        let name = format!("{} {topic} at {:.3} s", args.frame.display(), scan.time_s);
        let setup = TerrainSetup { frame: PathBuf::from(&name), ..args.setup() };
        let c = classify_cloud(&scan.cloud, &setup)?;
        let (height, pitch, roll) = c.mount;
        if args.json {
            let row = serde_json::json!({
                "frame": name, "time_s": scan.time_s, "stamp_ns": scan.stamp_ns,
                "points": c.cloud_points, "points_used": c.points.len(),
                "class": class_name(&c.result), "drivable": c.result.drivable,
                "rule": format!("{:?}", c.result.rule), "time_ms": c.seconds * 1e3,
                "mount": {"height_m": height, "pitch_deg": pitch, "roll_deg": roll,
                    "estimated": c.estimated.is_some()},
            });
            progress.report(row.to_string());
        } else {
            progress.report(format!(
                "{:>9.3} s  {:<9} drivable {:<3}  {:?}; {} of {} points; mount {height:.2} m, \
                 pitch {pitch:.1}°, roll {roll:.1}°{}",
                scan.time_s,
                class_name(&c.result),
                if c.result.drivable { "yes" } else { "no" },
                c.result.rule,
                c.points.len(),
                c.cloud_points,
                if c.estimated.is_some() { " (estimated)" } else { "" }
            ));
        }
        Ok(())
    })?;
    if !args.json {
        let (on_topic, _, kept) = summary.counts;
        progress.say(format!("{kept} of {on_topic} messages on {topic} classified"));
    }
    Ok(())
}
