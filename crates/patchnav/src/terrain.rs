//! `patchnav terrain FRAME`: the terrain class and drivability of the view ahead by the plane
//! Hough transform (thesis Ch. 4, Algorithms 2 and 3, spec `tof-hough.md` §3, §6).
//!
//! The frame's points are levelled with the sensor's axes, height and pitch
//! ([`SensorMount::looking_ahead`]), optionally cut to the forward view (±45° of azimuth, a
//! horizontal range limit), voted into the thesis's Hough space at the chosen angular
//! resolution and classified by Algorithm 3 with the thesis's thresholds.

use crate::input::{self, InputArgs};
use crate::progress::Progress;
use anyhow::{Context, Result, bail, ensure};
use clap::ValueEnum;
use hough_terrain::{
    Classification, HistogramStyle, HoughClassifier, HoughConfig, SectorClassifier, SectorGrid,
    SensorAxes, SensorMount, hough_png_file,
};
use pointcloud::Point3;
use std::path::PathBuf;
use std::time::Instant;

/// The sensor's axis convention.
#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum AxesChoice {
    /// x forward, y left, z up (laser scanners such as KITTI's Velodyne, 3DTK scans).
    Lidar,
    /// z forward, x right, y down (range and stereo cameras, depth images).
    Camera,
}

/// Arguments of `patchnav terrain`.
#[derive(Debug, clap::Args)]
pub struct TerrainArgs {
    /// A range frame or point cloud (.ply .pcd .xyz .txt .bin .3d, or a 16-bit .png depth image).
    pub frame: PathBuf,
    /// Angular resolution of the Hough space, degrees (thesis: 45 for drivability, 15 or 9 for
    /// classes).
    #[arg(long, default_value_t = 15.0)]
    pub resolution: f64,
    /// Also classify this many azimuth sectors (left to right) of the forward view.
    #[arg(long)]
    pub sectors: Option<usize>,
    /// Write the Hough space (thesis Fig 4.3 layout) as a PNG.
    #[arg(long, value_name = "PNG")]
    pub hough_png: Option<PathBuf>,
    /// The sensor's axes [default: camera for organised frames (depth images, range-camera
    /// clouds), lidar otherwise].
    #[arg(long, value_enum)]
    pub axes: Option<AxesChoice>,
    /// The sensor's height above the floor, metres (fixes the floor bin; the thesis does not
    /// give Rugbot's: 0.45 m is a level camera on a Rugbot-sized robot).
    #[arg(long, default_value_t = 0.45)]
    pub sensor_height: f64,
    /// The sensor's pitch, degrees down from level.
    #[arg(long, default_value_t = 0.0)]
    pub pitch: f64,
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

/// A frame classified by [`classify`]: what `patchnav terrain` prints (and `patchnav run`
/// reports).
pub(crate) struct Classified {
    /// Points in the frame.
    pub(crate) cloud_points: usize,
    /// The points voted (the forward view, if cut).
    pub(crate) points: Vec<Point3>,
    /// The axes used.
    pub(crate) axes: AxesChoice,
    /// The whole view's classification.
    pub(crate) result: Classification,
    /// Median classification time, seconds.
    pub(crate) seconds: f64,
    /// The classifier, holding the last run's Hough space.
    pub(crate) classifier: HoughClassifier,
    /// The per-sector classifications (empty without `--sectors`).
    pub(crate) sectors: Vec<hough_terrain::Sector>,
}

/// Checks the arguments, reads the frame, classifies it (`repeat` times), writes the Hough PNG
/// if asked, and classifies the sectors.
///
/// # Errors
/// A parameter out of range, an unreadable or empty frame, no point ahead, or a classifier
/// refusing its input.
pub(crate) fn classify(args: &TerrainArgs) -> Result<Classified> {
    ensure!(
        args.resolution.is_finite() && args.resolution > 0.0 && args.resolution <= 90.0,
        "--resolution must be in (0, 90] degrees, not {}",
        args.resolution
    );
    ensure!(
        args.sensor_height.is_finite() && args.sensor_height.abs() <= 100.0,
        "--sensor-height must be a finite height in metres, not {}",
        args.sensor_height
    );
    ensure!(
        args.pitch.is_finite() && args.pitch.abs() < 90.0,
        "--pitch must be in (−90, 90) degrees"
    );
    if let Some(r) = args.max_range {
        ensure!(
            r.is_finite() && r > 0.0,
            "--max-range must be a positive distance in metres, not {r}"
        );
    }
    if let Some(n) = args.sectors {
        ensure!((1..=90).contains(&n), "--sectors must be in 1..=90, not {n}");
    }
    ensure!((1..=100_000).contains(&args.repeat), "--repeat must be in 1..=100000");

    let cloud = input::read_cloud(&args.frame, &args.input)?;
    ensure!(!cloud.is_empty(), "{}: the frame has no points", args.frame.display());
    let organised = cloud.grid().is_some();
    let axes = args.axes.unwrap_or(if organised { AxesChoice::Camera } else { AxesChoice::Lidar });
    let sensor_axes = match axes {
        AxesChoice::Lidar => SensorAxes::Body,
        AxesChoice::Camera => SensorAxes::Optical,
    };
    let mount =
        SensorMount::looking_ahead(args.sensor_height, args.pitch.to_radians(), 0.0, sensor_axes)?;
    let frame_pixels = cloud.grid().map_or(cloud.len(), |g| g.num_pixels());
    let cut = args.max_range.is_some() || axes == AxesChoice::Lidar;
    let (points, pixels): (Vec<Point3>, usize) = if cut {
        let max = args.max_range.unwrap_or(f64::INFINITY);
        let p = forward_view(cloud.positions(), &mount, max);
        // An organised frame keeps its pixel count (the preprocessing's valid fraction); an
        // unorganised one is only the points kept.
        let pixels = if organised { frame_pixels } else { p.len() };
        (p, pixels)
    } else {
        (cloud.positions().to_vec(), frame_pixels)
    };
    if points.is_empty() {
        bail!(
            "{}: no point ahead of the sensor (check --axes and --max-range)",
            args.frame.display()
        );
    }
    let config = HoughConfig::thesis(args.resolution.to_radians(), mount)?;
    let mut classifier = HoughClassifier::new(config)?;
    let mut times = Vec::with_capacity(args.repeat);
    let mut result = None;
    for _ in 0..args.repeat {
        let t = Instant::now();
        result = Some(classifier.classify_frame(&points, pixels)?);
        times.push(t.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    let seconds = times[times.len() / 2];
    let result = result.context("classified")?;
    if let Some(png) = &args.hough_png {
        let style = HistogramStyle::thesis(Some(classifier.floor_bin()));
        hough_png_file(classifier.accumulator(), &style, png)
            .with_context(|| format!("writing {}", png.display()))?;
    }
    let sectors = match args.sectors {
        Some(n) => {
            let half = 45f64.to_radians();
            let edges = (0..=n).map(|k| -half + 2.0 * half * k as f64 / n as f64).collect();
            let grid = SectorGrid::new(edges, vec![0.0, args.max_range.unwrap_or(f64::INFINITY)])?;
            SectorClassifier::new(config, grid)?.classify(&points)?
        }
        None => Vec::new(),
    };

    Ok(Classified { cloud_points: cloud.len(), points, axes, result, seconds, classifier, sectors })
}

/// Runs `patchnav terrain`.
pub fn run(args: &TerrainArgs, progress: &Progress) -> Result<()> {
    let Classified { cloud_points, points, axes, result, seconds, classifier, sectors } =
        classify(args)?;
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
            "sectors": sectors,
        });
        progress.report(row.to_string());
        return Ok(());
    }
    let space = classifier.config().space;
    progress.report(format!(
        "frame:     {} ({} points, {} used; {:?} axes, {} m up, pitched {}° down)",
        args.frame.display(),
        cloud_points,
        points.len(),
        axes,
        args.sensor_height,
        args.pitch
    ));
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

fn class_name(c: &Classification) -> String {
    format!("{:?}", c.class).to_lowercase()
}

/// The points ahead: in the levelled frame x > 0, azimuth within ±45°, horizontal range at most
/// `max_range`.
fn forward_view(points: &[Point3], mount: &SensorMount, max_range: f64) -> Vec<Point3> {
    points
        .iter()
        .filter(|p| {
            let l = mount.to_levelled(p);
            l.x > 0.0 && l.y.abs() <= l.x && l.x.hypot(l.y) <= max_range
        })
        .copied()
        .collect()
}
