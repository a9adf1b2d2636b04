//! Real frames of the shared data folder: class, winning plane and time per frame, with the
//! Hough space as a picture (thesis Fig 4.3) under `target/bench/terrain/`.
//!
//! None of these frames comes with the sensor's height and pitch except KITTI (Velodyne
//! 1.73 m above the road, level); the others use the assumed mounts listed in [`frames`], so
//! their classes are only as good as those assumptions. Spinning lidars are cut to the forward
//! 90° and to a near-field range.

use anyhow::{Context, Result};
use hough_terrain::{
    HistogramStyle, HoughClassifier, HoughConfig, MountSearch, SensorAxes, SensorMount,
    estimate_mount, hough_png_file,
};
use pointcloud::io::{self, ReadOptions, depth_png::DepthCamera};
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

/// One real frame and the mount assumed for it.
struct RealFrame {
    name: &'static str,
    file: &'static str,
    axes: SensorAxes,
    height: f64,
    pitch_deg: f64,
    max_range: Option<f64>,
    tum: bool,
    mount_note: &'static str,
}

fn frames() -> Vec<RealFrame> {
    use SensorAxes::{Body, Optical};
    let f = |name, file, axes, height, pitch_deg, max_range, tum, mount_note| RealFrame {
        name,
        file,
        axes,
        height,
        pitch_deg,
        max_range,
        tum,
        mount_note,
    };
    vec![
        f(
            "tum-kinect",
            "tum_rgbd_kinect_frame/TUM_depth.png",
            Optical,
            1.2,
            20.0,
            None,
            true,
            "assumed (hand-held)",
        ),
        f(
            "pcl-office",
            "pcl_kinect_office/office1_zdepth_mm.png",
            Optical,
            1.0,
            0.0,
            None,
            false,
            "assumed",
        ),
        f(
            "pcl-boxes",
            "pcl_openni_grabber_boxes/frame_20121214T142255.814212_depth_mm.png",
            Optical,
            1.0,
            20.0,
            None,
            false,
            "assumed",
        ),
        f(
            "kitti-000000",
            "kitti_velodyne_frontfov/000000.bin",
            Body,
            1.73,
            0.0,
            Some(20.0),
            false,
            "KITTI setup",
        ),
        f(
            "kitti-000001",
            "kitti_velodyne_frontfov/000001.bin",
            Body,
            1.73,
            0.0,
            Some(20.0),
            false,
            "KITTI setup",
        ),
        f(
            "kitti-000003",
            "kitti_velodyne_frontfov/000003.bin",
            Body,
            1.73,
            0.0,
            Some(20.0),
            false,
            "KITTI setup",
        ),
        f(
            "rellis-offroad",
            "rellis3d_ouster_offroad/000000.bin",
            Body,
            1.0,
            0.0,
            Some(15.0),
            false,
            "assumed",
        ),
        f(
            "3dtk-scan000",
            "3dtk_kurt3d_scans/scan000.3d",
            Body,
            0.5,
            0.0,
            Some(10.0),
            false,
            "assumed",
        ),
    ]
}

pub(crate) use patch_pipeline::terrain::forward_view;

fn out_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/bench/terrain")
}

/// Classifies every real frame at 45°, 15° and 9°; the 15° Hough space is written as a PNG.
pub(crate) fn run() -> Result<Vec<Value>> {
    let Some(dir) = crate::real_data_dir() else {
        eprintln!(
            "SKIPPED: real frames (no shared/data/real next to the checkout; set PATCHNAV_REAL_DATA)"
        );
        return Ok(Vec::new());
    };
    let out = out_dir();
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let out = out.canonicalize().unwrap_or(out);
    let mut rows = Vec::new();
    let mut table = String::from(
        "Real frames (mount: height m / pitch ° down): class, drivable, winning plane (ρx, ρy in °, d in m), \
         #PC, ms per frame (median of 5)\n| frame | mount | points used | @45° | @15° | @9° | ms @45/15/9 |\n\
         |---|---|---|---|---|---|---|\n",
    );
    for f in frames() {
        let path = dir.join(f.file);
        if !path.is_file() {
            eprintln!("SKIPPED: {} ({} is missing)", f.name, path.display());
            continue;
        }
        let cloud = if f.tum {
            io::read_range_image(&path, Some(&DepthCamera::tum_kinect()))?.to_cloud()?
        } else {
            io::read_cloud(&path, &ReadOptions::STRICT)?
        };
        let given = SensorMount::looking_ahead(f.height, f.pitch_deg.to_radians(), 0.0, f.axes)?;
        let estimate = estimate_mount(cloud.positions(), &MountSearch::new(f.axes));
        let mut mounts =
            vec![(given, format!("{} / {} ({})", f.height, f.pitch_deg, f.mount_note), "")];
        match &estimate {
            Ok(e) => mounts.push((
                e.mount,
                format!(
                    "estimated: {:.2} / {:.1}, roll {:.1}",
                    e.height,
                    e.pitch.to_degrees(),
                    e.roll.to_degrees()
                ),
                "/estimated-mount",
            )),
            Err(why) => eprintln!("{}: no mount estimate: {why}", f.name),
        }
        let frame_pixels = cloud.grid().map_or(cloud.len(), |g| g.num_pixels());
        for (mount, mount_label, suffix) in mounts {
            let (points, pixels) = match f.max_range {
                Some(r) => {
                    let p = forward_view(cloud.positions(), &mount, r);
                    let n = p.len();
                    (p, n)
                }
                None => (cloud.positions().to_vec(), frame_pixels),
            };
            if points.is_empty() {
                eprintln!("SKIPPED: {} (no point ahead)", f.name);
                continue;
            }
            let mut cells = Vec::new();
            let mut times = Vec::new();
            for res in super::RESOLUTIONS {
                let mut c = HoughClassifier::new(HoughConfig::thesis(res.to_radians(), mount)?)?;
                let mut result = None;
                let secs = crate::median_seconds(5, || {
                    result = Some(c.classify_frame(&points, pixels)?);
                    Ok(())
                })?;
                let r = result.context("classified")?;
                let plane = r.plane.map_or("–".to_owned(), |p| {
                    format!(
                        "({:.0}, {:.0}, {:.2})",
                        p.rho_x.to_degrees(),
                        p.rho_y.to_degrees(),
                        p.d
                    )
                });
                cells.push(format!(
                    "{:?}{} {}{plane}",
                    r.class,
                    if r.accepted { "" } else { " (rejected)" },
                    if r.drivable { "drivable " } else { "not drivable " },
                ));
                times.push(format!("{:.2}", secs * 1e3));
                if res == 15.0 {
                    let png = out.join(format!("{}{}-15deg.png", f.name, suffix.replace('/', "-")));
                    hough_png_file(
                        c.accumulator(),
                        &HistogramStyle::thesis(Some(c.floor_bin())),
                        &png,
                    )?;
                }
                rows.push(json!({
                    "case": format!("real/{}{suffix}", f.name), "metric": "time_per_frame", "value": secs * 1e3, "unit": "ms",
                    "resolution_deg": res, "class": format!("{:?}", r.class), "drivable": r.drivable,
                    "accepted": r.accepted, "points": r.points, "high_bins": r.high_bins,
                    "plane": r.plane.map(|p| json!({"rho_x_deg": p.rho_x.to_degrees(), "rho_y_deg": p.rho_y.to_degrees(), "d": p.d})),
                    "mount_height": f.height, "mount_pitch_deg": f.pitch_deg, "mount": f.mount_note,
                    "mount_used": mount_label,
                }));
            }
            table += &format!(
                "| {} | {mount_label} | {} | {} | {} |\n",
                f.name,
                points.len(),
                cells.join(" | "),
                times.join(" / ")
            );
        }
    }
    table += &format!("Hough spaces at 15°: {}/*-15deg.png", out.display());
    eprintln!("{table}");
    Ok(rows)
}
