//! Terrain class and drivability of the view ahead by the plane Hough transform (thesis Ch. 4,
//! Algorithms 2 and 3, spec `tof-hough.md` §3, §6), as `patchnav terrain` and `patchnav run`
//! classify a frame.
//!
//! The frame's points are levelled with the sensor's axes, height and pitch
//! ([`SensorMount::looking_ahead`]), given or estimated from the frame's ground plane
//! ([`estimate_mount`]: height, pitch and roll), optionally cut to the forward view (±45° of azimuth, a
//! horizontal range limit), voted into the thesis's Hough space at the chosen angular
//! resolution and classified by the chosen [`Method`]: the ground-ahead rule (the default) or
//! Algorithm 3 with the thesis's thresholds. Sectors are always classified by Algorithm 3.

pub mod ground;

pub use hough_terrain::Method;

use crate::input::{self, CloudInput};
use anyhow::{Context, Result, bail, ensure};
use hough_terrain::{
    Classification, HistogramStyle, HoughClassifier, HoughConfig, MountEstimate, MountSearch,
    SectorClassifier, SectorGrid, SensorAxes, SensorMount, estimate_mount, hough_png_file,
};
use pointcloud::{Point3, PointCloud};
use std::path::PathBuf;
use std::time::Instant;

crate::names::named_enum! {
    /// The sensor's axis convention.
    pub enum AxesChoice ("axes") {
        /// x forward, y left, z up (laser scanners such as KITTI's Velodyne, 3DTK scans).
        Lidar = "lidar",
            "x forward, y left, z up (laser scanners such as KITTI's Velodyne, 3DTK scans)";
        /// z forward, x right, y down (range and stereo cameras, depth images).
        Camera = "camera", "z forward, x right, y down (range and stereo cameras, depth images)";
    }
}

/// How to classify a frame. Error messages name the command line's flags.
#[derive(Clone, Debug, PartialEq)]
pub struct TerrainSetup {
    /// A range frame or point cloud (.ply .pcd .xyz .txt .bin .3d, or a 16-bit .png depth image).
    pub frame: PathBuf,
    /// Angular resolution of the Hough space, degrees (thesis: 45 for drivability, 15 or 9 for
    /// classes).
    pub resolution: f64,
    /// Which rule decides: the ground-ahead rule (recommended) or Algorithm 3 verbatim.
    pub method: Method,
    /// Also classify this many azimuth sectors (left to right) of the forward view.
    pub sectors: Option<usize>,
    /// Write the Hough space (thesis Fig 4.3 layout) as a PNG.
    pub hough_png: Option<PathBuf>,
    /// The sensor's axes (`None`: camera for organised frames, lidar otherwise).
    pub axes: Option<AxesChoice>,
    /// The sensor's height above the floor, metres (`None`: estimated from the frame with
    /// [`estimate_mount`], as are pitch and roll).
    pub sensor_height: Option<f64>,
    /// The sensor's pitch, degrees down from level (`None`: estimated from the frame, or level
    /// when the height is given).
    pub pitch: Option<f64>,
    /// Keep only points ahead (±45° of azimuth) within this horizontal range, metres. Lidar
    /// frames are always cut to the forward view.
    pub max_range: Option<f64>,
    /// Classify the frame this many times and report the median time.
    pub repeat: usize,
    /// How to read the frame.
    pub input: CloudInput,
}

impl TerrainSetup {
    /// The command line's defaults for `frame`: 15° bins, the mount estimated from the frame,
    /// the whole view, one run.
    pub fn new(frame: PathBuf) -> TerrainSetup {
        TerrainSetup {
            frame,
            resolution: 15.0,
            method: Method::GroundAhead,
            sectors: None,
            hough_png: None,
            axes: None,
            sensor_height: None,
            pitch: None,
            max_range: None,
            repeat: 1,
            input: CloudInput::default(),
        }
    }
}

/// A frame classified by [`classify`]: what `patchnav terrain` prints (and `patchnav run`
/// reports).
pub struct Classified {
    /// Points in the frame.
    pub cloud_points: usize,
    /// The points voted (the forward view, if cut).
    pub points: Vec<Point3>,
    /// The axes used.
    pub axes: AxesChoice,
    /// The mount used: height (m), pitch and roll (degrees down, degrees).
    pub mount: (f64, f64, f64),
    /// The estimate, when the mount (or part of it) came from the frame.
    pub estimated: Option<MountEstimate>,
    /// The whole view's classification.
    pub result: Classification,
    /// Median classification time, seconds.
    pub seconds: f64,
    /// The classifier, holding the last run's Hough space.
    pub classifier: HoughClassifier,
    /// The per-sector classifications (empty without `--sectors`).
    pub sectors: Vec<hough_terrain::Sector>,
}

/// Checks the arguments, reads the frame, classifies it (`repeat` times), writes the Hough PNG
/// if asked, and classifies the sectors.
///
/// # Errors
/// A parameter out of range, an unreadable or empty frame, no point ahead, or a classifier
/// refusing its input.
pub fn classify(args: &TerrainSetup) -> Result<Classified> {
    check(args)?;
    let cloud = input::read_cloud(&args.frame, &args.input)?;
    classify_checked(&cloud, args)
}

/// Checks the parameters of a [`TerrainSetup`].
fn check(args: &TerrainSetup) -> Result<()> {
    ensure!(
        args.resolution.is_finite() && args.resolution > 0.0 && args.resolution <= 90.0,
        "--resolution must be in (0, 90] degrees, not {}",
        args.resolution
    );
    if let Some(h) = args.sensor_height {
        ensure!(
            h.is_finite() && h.abs() <= 100.0,
            "--sensor-height must be a finite height in metres, not {h}"
        );
    }
    if let Some(p) = args.pitch {
        ensure!(p.is_finite() && p.abs() < 90.0, "--pitch must be in (−90, 90) degrees, not {p}");
    }
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
    Ok(())
}

/// [`classify`] on a cloud in memory (from a bag, or the Python package's arrays): `args.frame`
/// only names the frame in messages, `args.input` is not used.
///
/// # Errors
/// As [`classify`], but for reading.
pub fn classify_cloud(cloud: &PointCloud, args: &TerrainSetup) -> Result<Classified> {
    check(args)?;
    classify_checked(cloud, args)
}

fn classify_checked(cloud: &PointCloud, args: &TerrainSetup) -> Result<Classified> {
    ensure!(!cloud.is_empty(), "{}: the frame has no points", args.frame.display());
    let organised = cloud.grid().is_some();
    let axes = args.axes.unwrap_or_else(|| AxesChoice::default_for(cloud));
    let sensor_axes = axes.sensor_axes();
    let (height, pitch, roll, estimated) = match args.sensor_height {
        Some(h) => (h, args.pitch.unwrap_or(0.0).to_radians(), 0.0, None),
        None => {
            let e = frame_mount(cloud, sensor_axes, &args.frame)?;
            (e.height, args.pitch.map_or(e.pitch, f64::to_radians), e.roll, Some(e))
        }
    };
    let mount = SensorMount::looking_ahead(height, pitch, roll, sensor_axes)?;
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
    let mut config = HoughConfig::thesis(args.resolution.to_radians(), mount)?;
    config.method = args.method;
    // The Hough space is filled under either method: `Classified` holds it for its picture.
    config.ahead.hough = true;
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

    Ok(Classified {
        cloud_points: cloud.len(),
        points,
        axes,
        mount: (height, pitch.to_degrees(), roll.to_degrees()),
        estimated,
        result,
        seconds,
        classifier,
        sectors,
    })
}

impl AxesChoice {
    /// The default for a cloud: camera axes for an organised frame, lidar axes otherwise.
    pub fn default_for(cloud: &pointcloud::PointCloud) -> AxesChoice {
        if cloud.grid().is_some() { AxesChoice::Camera } else { AxesChoice::Lidar }
    }

    /// The classifier's axes.
    pub fn sensor_axes(self) -> SensorAxes {
        match self {
            AxesChoice::Lidar => SensorAxes::Body,
            AxesChoice::Camera => SensorAxes::Optical,
        }
    }
}

/// The sensor's mount estimated from the frame's ground plane ([`estimate_mount`]); the error
/// names the file and how to give the mount instead.
pub(crate) fn frame_mount(
    cloud: &pointcloud::PointCloud,
    axes: SensorAxes,
    frame: &std::path::Path,
) -> Result<MountEstimate> {
    estimate_mount(cloud.positions(), &MountSearch::new(axes)).with_context(|| {
        format!(
            "{}: estimating the sensor's mount (give --sensor-height and --pitch)",
            frame.display()
        )
    })
}

/// The class's lower-case name (`floor`, `ramp`, ...).
pub fn class_name(c: &Classification) -> String {
    format!("{:?}", c.class).to_lowercase()
}

/// The points ahead (`patchnav terrain`, the terrain benchmark): in the levelled frame x > 0,
/// azimuth within ±45°, horizontal range at most `max_range`.
pub fn forward_view(points: &[Point3], mount: &SensorMount, max_range: f64) -> Vec<Point3> {
    points
        .iter()
        .filter(|p| {
            let l = mount.to_levelled(p);
            l.x > 0.0 && l.y.abs() <= l.x && l.x.hypot(l.y) <= max_range
        })
        .copied()
        .collect()
}
