//! How well the mount self-calibration ([`hough_terrain::estimate_mount`]) recovers the true
//! mount on the simulated snapshots: per frame, and as the running median a robot would keep
//! while driving through every parameter set ([`hough_terrain::MountWindow`]).
//!
//! Two mounts: the thesis's pose (level camera 0.45 m above the floor) and a tilted one
//! ([`TILTED`]: 0.6 m, pitched down 15°, rolled 3°). Frames are those of the Table 4.3 sets; in
//! many of them (walls at 1–2 m, ramps and steps from 1.5 m) the level camera sees little or no
//! floor, so per-frame figures are given for every frame and for the frames of the sets whose
//! floor fills the view near the robot (floor, clutter, rubble, steps at 3 m). The drive visits
//! snapshot k of every set before snapshot k + 1, and its median is that of every frame.

use super::synthetic::{self, Case, FrameMaker, Sensor};
use anyhow::Result;
use hough_terrain::{MountSearch, MountWindow, SensorAxes, estimate_mount};
use nalgebra::Point3;
use serde_json::{Value, json};
use std::fmt::Write as _;

/// A tilted mount: height (m), pitch and roll (degrees).
pub(crate) const TILTED: (f64, f64, f64) = (0.6, 15.0, 3.0);
/// The goals: height within 5 cm, pitch and roll within 1°.
const HEIGHT_OK: f64 = 0.05;
const ANGLE_OK_DEG: f64 = 1.0;

/// Whether the floor fills the view near the robot in a set's frames.
fn floor_in_view(case: &Case) -> bool {
    case.name == "floor"
        || case.name.starts_with("clutter")
        || case.name.starts_with("rubble")
        || case.name.ends_with("@3")
}

/// Per-frame errors (height m, pitch °, roll °) or `None` when no ground was found.
type Errors = Option<(f64, f64, f64)>;

/// Runs the measurement with `n` snapshots per set and sensor; returns JSON rows and prints a
/// table to standard error.
pub(crate) fn run(n: usize, seed: u64) -> Result<Vec<Value>> {
    let cases = synthetic::cases();
    let mut rows = Vec::new();
    let mut table = String::from(
        "Mount self-calibration on the simulated snapshots (true mount → share of frames within 5 cm and 1°; \
         median / 95th-percentile |error|; the median over the whole drive)\n\
         | sensor | mount | frames | ground found | within goal (all) | within goal (floor in view) | height cm | pitch ° | roll ° | drive median: height cm, pitch °, roll ° |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut points: Vec<Point3<f64>> = Vec::new();
    for sensor in Sensor::ALL {
        let mut maker = FrameMaker::new(sensor)?;
        let n_sensor = if sensor == Sensor::Stereo { n.div_ceil(2) } else { n };
        for (label, (h, p_deg, r_deg)) in
            [("level 0.45 m", (synthetic::HEIGHT, synthetic::PITCH_DEG, 0.0)), ("tilted", TILTED)]
        {
            let body = pointcloud::SensorPose::from_position_rpy(
                Point3::new(0.0, 0.0, h),
                r_deg.to_radians(),
                p_deg.to_radians(),
                0.0,
            );
            let search = MountSearch { seed, ..MountSearch::new(SensorAxes::Optical) };
            let mut window = MountWindow::new(SensorAxes::Optical, cases.len() * n_sensor);
            let mut errors: Vec<(bool, Errors)> = Vec::new();
            for k in 0..n_sensor {
                for case in &cases {
                    let scene = synthetic::scene(case, k, n_sensor, seed)?;
                    maker.frame_from(
                        &scene,
                        &body,
                        seed.wrapping_add(k as u64 * 7919),
                        &mut points,
                    )?;
                    let e = estimate_mount(&points, &search).ok();
                    if let Some(e) = &e {
                        window.push(e);
                    }
                    errors.push((
                        floor_in_view(case),
                        e.map(|e| {
                            (
                                (e.height - h).abs(),
                                (e.pitch.to_degrees() - p_deg).abs(),
                                (e.roll.to_degrees() - r_deg).abs(),
                            )
                        }),
                    ));
                }
            }
            let ok = |e: &Errors| {
                e.is_some_and(|(dh, dp, dr)| {
                    dh <= HEIGHT_OK && dp <= ANGLE_OK_DEG && dr <= ANGLE_OK_DEG
                })
            };
            let share = |sel: &dyn Fn(bool) -> bool| {
                let v: Vec<_> = errors.iter().filter(|(f, _)| sel(*f)).collect();
                v.iter().filter(|(_, e)| ok(e)).count() as f64 / v.len().max(1) as f64
            };
            let (all, near) = (share(&|_| true), share(&|f| f));
            let found = errors.iter().filter(|(_, e)| e.is_some()).count();
            let stat = |f: fn(&(f64, f64, f64)) -> f64| {
                let v: Vec<f64> = errors.iter().filter_map(|(_, e)| e.as_ref().map(f)).collect();
                (
                    evaluation::stats::quantile(&v, 0.5).unwrap_or(f64::NAN),
                    evaluation::stats::quantile(&v, 0.95).unwrap_or(f64::NAN),
                )
            };
            let (hm, h95) = stat(|e| e.0 * 100.0);
            let (pm, p95) = stat(|e| e.1);
            let (rm, r95) = stat(|e| e.2);
            let win = window.median().map(|(wh, wp, wr)| {
                (
                    (wh - h).abs() * 100.0,
                    (wp.to_degrees() - p_deg).abs(),
                    (wr.to_degrees() - r_deg).abs(),
                )
            });
            let case = format!(
                "mount/{}/{}",
                sensor.name(),
                if label == "tilted" { "tilted" } else { "level" }
            );
            for (metric, value) in [
                ("within_goal", all),
                ("within_goal_floor_in_view", near),
                ("ground_found", found as f64 / errors.len().max(1) as f64),
                ("height_err_cm_median", hm),
                ("height_err_cm_p95", h95),
                ("pitch_err_deg_median", pm),
                ("pitch_err_deg_p95", p95),
                ("roll_err_deg_median", rm),
                ("roll_err_deg_p95", r95),
                ("window_height_err_cm", win.map_or(f64::NAN, |w| w.0)),
                ("window_pitch_err_deg", win.map_or(f64::NAN, |w| w.1)),
                ("window_roll_err_deg", win.map_or(f64::NAN, |w| w.2)),
            ] {
                rows.push(json!({"case": case, "metric": metric, "value": value, "frames": errors.len(), "seed": seed}));
            }
            let _ = writeln!(
                table,
                "| {} | {label} | {} | {found} | {all:.3} | {near:.3} | {hm:.2} / {h95:.2} | {pm:.2} / {p95:.2} | {rm:.2} / {r95:.2} | {} |",
                sensor.name(),
                errors.len(),
                win.map_or("–".to_owned(), |w| format!("{:.2}, {:.2}, {:.2}", w.0, w.1, w.2)),
            );
        }
    }
    eprintln!("{table}");
    Ok(rows)
}
