//! Per-point ground of a frame, as `patchnav terrain FRAME --ground-out OUT.ply` labels it
//! ([`hough_terrain::GroundSegmenter`]; not in the thesis, it applies the thesis's step and
//! slope limits, L3453–3460, point by point).
//!
//! The output cloud is the input cloud (every point, in the input's order, its attributes and
//! organisation kept) with one more per-point field, [`GROUND_FIELD`] (`u8`: 1 = drivable
//! ground, 0 = not).

use super::AxesChoice;
use crate::input::{self, CloudInput};
use anyhow::{Context, Result, ensure};
use hough_terrain::{GroundSegmenter, GroundSettings, GroundSummary, MountEstimate, SensorMount};
use pointcloud::{FieldData, PointCloud, ScalarField};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The name of the per-point label field the ground output carries (`u8`, 1 = ground).
pub const GROUND_FIELD: &str = "ground";

/// How to label a frame's ground points. Error messages name the command line's flags.
#[derive(Clone, Debug, PartialEq)]
pub struct GroundSetup {
    /// A range frame or point cloud.
    pub frame: PathBuf,
    /// How to read it.
    pub input: CloudInput,
    /// The sensor's axes (`None`: camera for organised frames, lidar otherwise).
    pub axes: Option<AxesChoice>,
    /// The mount: height (m), pitch (degrees down) and roll (degrees); `None`: estimated from
    /// the frame ([`hough_terrain::estimate_mount`]).
    pub mount: Option<(f64, f64, f64)>,
    /// Where to write the labelled cloud (any cloud format that keeps extra fields: PLY, PCD).
    pub out: Option<PathBuf>,
    /// Label the frame this many times (timing: first, best, median).
    pub repeat: usize,
    /// The segmentation's settings.
    pub settings: GroundSettings,
}

impl GroundSetup {
    /// The command line's defaults: axes by organisation, the mount estimated, one run, no
    /// output file, the default settings.
    pub fn new(frame: PathBuf) -> GroundSetup {
        GroundSetup {
            frame,
            input: CloudInput::default(),
            axes: None,
            mount: None,
            out: None,
            repeat: 1,
            settings: GroundSettings::default(),
        }
    }
}

/// A frame's ground labels and how long they took.
#[derive(Clone, Debug)]
pub struct Grounded {
    /// One label per point of the frame, in its order.
    pub labels: Vec<bool>,
    /// Counts.
    pub summary: GroundSummary,
    /// The axes used.
    pub axes: AxesChoice,
    /// The mount used: height (m), pitch and roll (degrees down, degrees).
    pub mount: (f64, f64, f64),
    /// The estimate, when the mount came from the frame.
    pub estimated: Option<MountEstimate>,
    /// Seconds per run (levelling, grid, fits and labels; not reading or the mount estimate).
    pub times: Vec<f64>,
}

impl Grounded {
    /// The first run's time, seconds.
    pub fn first(&self) -> f64 {
        self.times[0]
    }

    /// The best of the runs after the first (the first alone if there is one), seconds.
    pub fn best(&self) -> f64 {
        self.later().iter().copied().fold(f64::INFINITY, f64::min)
    }

    /// The median of the runs after the first (the first alone if there is one), seconds.
    pub fn median(&self) -> f64 {
        evaluation::stats::median(self.later().to_vec()).unwrap_or(f64::NAN)
    }

    fn later(&self) -> &[f64] {
        if self.times.len() > 1 { &self.times[1..] } else { &self.times }
    }
}

/// Reads the frame, levels it with the given or estimated mount, labels its ground points
/// (`repeat + 1` times when `repeat > 1`: a first, cold run and `repeat` timed ones) and writes
/// the labelled cloud if asked.
///
/// # Errors
/// A parameter out of range, an unreadable or empty frame, no ground plane for the mount
/// estimate, or the output file.
pub fn segment_ground(args: &GroundSetup) -> Result<Grounded> {
    ensure!((1..=100_000).contains(&args.repeat), "--repeat must be in 1..=100000");
    let cloud = input::read_cloud(&args.frame, &args.input)?;
    let grounded = segment_cloud_ground(&cloud, args)?;
    if let Some(out) = &args.out {
        write_ground(out, &cloud, &grounded.labels)?;
    }
    Ok(grounded)
}

/// [`segment_ground`] on a cloud in memory (the Python package's arrays): `args.frame` only
/// names the frame in messages; `args.input` and `args.out` are not used.
///
/// # Errors
/// A parameter out of range, an empty cloud, or no ground plane for the mount estimate.
pub fn segment_cloud_ground(cloud: &PointCloud, args: &GroundSetup) -> Result<Grounded> {
    ensure!((1..=100_000).contains(&args.repeat), "--repeat must be in 1..=100000");
    ensure!(!cloud.is_empty(), "{}: the frame has no points", args.frame.display());
    let axes = args.axes.unwrap_or_else(|| AxesChoice::default_for(cloud));
    let sensor_axes = axes.sensor_axes();
    let (height, pitch, roll, estimated) = match args.mount {
        Some((h, p, r)) => {
            ensure!(h.is_finite() && h.abs() <= 100.0, "--sensor-height must be finite, not {h}");
            ensure!(p.is_finite() && p.abs() < 90.0, "--pitch must be in (−90, 90), not {p}");
            (h, p.to_radians(), r.to_radians(), None)
        }
        None => {
            let e = super::frame_mount(cloud, sensor_axes, &args.frame)?;
            (e.height, e.pitch, e.roll, Some(e))
        }
    };
    let mount = SensorMount::looking_ahead(height, pitch, roll, sensor_axes)?;
    let mut segmenter = GroundSegmenter::new(args.settings)?;
    let runs = if args.repeat > 1 { args.repeat + 1 } else { 1 };
    let mut labels = Vec::new();
    let mut times = Vec::with_capacity(runs);
    let mut summary = None;
    for _ in 0..runs {
        let t = Instant::now();
        summary = Some(segmenter.segment(cloud.positions(), &mount, &mut labels)?);
        times.push(t.elapsed().as_secs_f64());
    }
    let summary = summary.context("segmented")?;
    Ok(Grounded {
        labels,
        summary,
        axes,
        mount: (height, pitch.to_degrees(), roll.to_degrees()),
        estimated,
        times,
    })
}

/// Writes `cloud` with the [`GROUND_FIELD`] field from `labels` (through
/// [`pointcloud::io::write_cloud`], atomically); an existing field of that name is replaced.
///
/// # Errors
/// Labels of another length than the cloud, or the file.
pub fn write_ground(path: &Path, cloud: &PointCloud, labels: &[bool]) -> Result<()> {
    let mut out = cloud.clone();
    let _ = out.take_extra_field(GROUND_FIELD);
    out.push_extra_field(ScalarField {
        name: GROUND_FIELD.to_owned(),
        data: FieldData::U8(labels.iter().map(|&g| u8::from(g)).collect()),
    })
    .map_err(|e| anyhow::anyhow!("{e}"))?;
    pointcloud::io::write_cloud(path, &out).with_context(|| format!("writing {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flat_frame_is_ground_and_the_labels_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let points: Vec<pointcloud::Point3> = (0..3000)
            .map(|i| {
                let (r, a) = (2.0 + (i / 100) as f64 * 0.2, (i % 100) as f64 * 0.0628);
                pointcloud::Point3::new(r * a.cos(), r * a.sin(), -1.0)
            })
            .chain((0..100).map(|i| pointcloud::Point3::new(3.0, i as f64 * 0.01, 0.5)))
            .collect();
        let frame = dir.path().join("frame.ply");
        pointcloud::io::write_cloud(&frame, &PointCloud::from_positions(points).unwrap()).unwrap();
        let out = dir.path().join("ground.ply");
        let setup = GroundSetup {
            mount: Some((1.0, 0.0, 0.0)),
            out: Some(out.clone()),
            repeat: 3,
            ..GroundSetup::new(frame)
        };
        let g = segment_ground(&setup).unwrap();
        assert_eq!(g.times.len(), 4);
        assert_eq!(g.summary.ground, 3000);
        let back = input::read_cloud(&out, &CloudInput::default()).unwrap();
        let field = back.extra_field(GROUND_FIELD).unwrap();
        assert_eq!(field.data, FieldData::U8(g.labels.iter().map(|&v| u8::from(v)).collect()));
        assert!(segment_ground(&GroundSetup { repeat: 0, ..setup }).is_err());
    }
}

#[cfg(test)]
mod demo_tests {
    /// The demo's terrain snapshot (a passable 30° ramp) scores its ground labels.
    #[test]
    fn the_demo_snapshot_scores_its_ground() {
        let dir = tempfile::tempdir().unwrap();
        let mut files = crate::demo::Files::new(dir.path());
        let t = crate::demo::sensors::terrain(1, &mut files).unwrap();
        let g = t.ground.unwrap();
        assert!(g.share > 0.3, "{g:?}");
        assert!(g.f1 > 0.95, "{g:?}");
    }
}
