//! Speed: frames per second and nanoseconds per vote at each resolution on a full SR-3000
//! frame (176 × 144 = 25,344 points) and a 72,000-point stereo frame (the size of the thesis's
//! Stereo Outdoor 1 snapshots), and the speed-up of the table-driven voting over the literal
//! Algorithm 2 ([`hough_terrain::vote_literal`]).

use anyhow::{Result, ensure};
use hough_terrain::{Accumulator, HoughClassifier, HoughConfig, Method, NormalTable, vote_literal};
use nalgebra::Point3;
use scene_sim::{RangeCamera, RangeSensor, StereoCamera, TerrainSpec, terrain};
use serde_json::{Value, json};

/// The stereo frame's size.
const STEREO_POINTS: usize = 72_000;

/// Every `len / n`-th point, `n` points in all (all of them if there are fewer).
fn subsample(points: &[Point3<f64>], n: usize) -> Vec<Point3<f64>> {
    if points.len() <= n {
        return points.to_vec();
    }
    (0..n).map(|i| points[i * points.len() / n]).collect()
}

/// A frame's name and its points (optical frame).
pub(crate) type NamedFrame = (&'static str, Vec<Point3<f64>>);

/// The frames of the speed test: a wall 3 m ahead over the floor fills the SR-3000's view.
pub(crate) fn frames(seed: u64) -> Result<Vec<NamedFrame>> {
    let scene = terrain(&TerrainSpec::Wall { distance: 3.0, height: 2.0 }, seed)?;
    let body = super::synthetic::body_pose();
    let tof = RangeCamera::swissranger_sr3000();
    let tof_cloud = tof.scan(&scene, &tof.mount(&body), seed).to_cloud()?;
    let stereo = StereoCamera::stoc();
    let stereo_cloud = stereo.scan(&scene, &stereo.mount(&body), seed).to_cloud()?;
    Ok(vec![
        ("tof-frame", tof_cloud.positions().to_vec()),
        ("stereo-frame", subsample(stereo_cloud.positions(), STEREO_POINTS)),
    ])
}

/// Runs the speed measurements.
pub(crate) fn run(seed: u64) -> Result<Vec<Value>> {
    let mount = super::synthetic::mount()?;
    let mut rows = Vec::new();
    let mut table = String::from(
        "Speed (one thread, median of repeats): full pipeline (levelling, preprocessing, Algorithm 2 + 3) per frame, \
         voting alone, literal Algorithm 2\n| frame | points | resolution | angle pairs | ms per frame | frames/s | \
         ns per vote | literal ms | speed-up of voting |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for (name, points) in frames(seed)? {
        ensure!(!points.is_empty(), "{name}: empty frame");
        for res in [45.0, 15.0, 9.0, 5.0] {
            let mut c = HoughClassifier::new(HoughConfig::thesis(f64::to_radians(res), mount)?)?;
            let space = c.config().space;
            let pairs = space.angle_pairs();
            let votes = (points.len() * pairs) as f64;
            let reps = (2e8 / votes).clamp(3.0, 200.0) as usize;
            let frame = crate::median_seconds(reps, || {
                std::hint::black_box(c.classify(&points)?);
                Ok(())
            })?;
            let levelled: Vec<Point3<f64>> = points.iter().map(|p| mount.to_levelled(p)).collect();
            let table_votes = NormalTable::new(&space);
            let mut acc = Accumulator::new(space);
            let vote = crate::median_seconds(reps, || {
                acc.clear();
                table_votes.vote(&levelled, &mut acc)?;
                std::hint::black_box(acc.total_votes());
                Ok(())
            })?;
            let literal = crate::median_seconds(3, || {
                let a = vote_literal(&space, &levelled)?;
                ensure!(a.counts() == acc.counts(), "literal and table voting disagree");
                Ok(())
            })?;
            let ns_per_vote = frame * 1e9 / votes;
            table += &format!(
                "| {name} | {} | {res}° | {pairs} | {:.3} | {:.0} | {ns_per_vote:.2} | {:.2} | {:.1} |\n",
                points.len(),
                frame * 1e3,
                1.0 / frame,
                literal * 1e3,
                literal / vote
            );
            rows.push(json!({
                "case": format!("speed/{name}"), "metric": "time_per_frame", "value": frame * 1e3, "unit": "ms",
                "resolution_deg": res, "points": points.len(), "angle_pairs": pairs, "frames_per_s": 1.0 / frame,
                "ns_per_vote": ns_per_vote, "vote_ms": vote * 1e3, "literal_ms": literal * 1e3,
                "speedup_over_literal": literal / vote, "repeats": reps,
            }));
        }
    }
    table += "Thesis Fig 4.4: about 0.47 µs per point (SR) and 0.75 µs per point (STOC) at 45°, hardware not stated. \
              RANSAC ground plane on the same frames: `cargo xtask peers terrain`.";
    eprintln!("{table}");
    eprintln!("{}", ahead_speed(seed, &mut rows)?);
    Ok(rows)
}

/// The ground-ahead rule's time per frame (levelling, preprocessing, Algorithm 2 for the
/// Hough space, the rule) beside Algorithm 3's, on every simulated frame kind of the
/// benchmark: the wall frame of [`frames`] and one frame of each sensor of each parameter set.
fn ahead_speed(seed: u64, rows: &mut Vec<Value>) -> Result<String> {
    let mount = super::synthetic::mount()?;
    let mut table = String::from(
        "Speed of the methods at 45° (one thread): median ms per frame over one frame of every parameter set\n\
         | sensor | method | median ms | max ms | frames |\n|---|---|---|---|---|\n",
    );
    let cases = super::synthetic::cases();
    // The masked sunlit frames are nearly empty: their times say nothing.
    for sensor in super::synthetic::Sensor::ALL
        .into_iter()
        .filter(|s| *s != super::synthetic::Sensor::TofSunMasked)
    {
        let mut maker = super::synthetic::FrameMaker::new(sensor)?;
        let mut frames = Vec::new();
        for case in &cases {
            let scene = super::synthetic::scene(case, 0, 1, seed)?;
            let mut points = Vec::new();
            let pixels = maker.frame(&scene, seed, &mut points)?;
            frames.push((points, pixels));
        }
        for name in super::synthetic::METHODS {
            let method: Method = name.parse()?;
            let config = HoughConfig { method, ..HoughConfig::thesis(45f64.to_radians(), mount)? };
            let mut c = HoughClassifier::new(config)?;
            let mut times = Vec::new();
            for (points, pixels) in &frames {
                times.push(crate::median_seconds(21, || {
                    std::hint::black_box(c.classify_frame(points, *pixels)?);
                    Ok(())
                })?);
            }
            times.sort_by(f64::total_cmp);
            let (median, max) = (times[times.len() / 2] * 1e3, times[times.len() - 1] * 1e3);
            table += &format!(
                "| {} | {name} | {median:.3} | {max:.3} | {} |\n",
                sensor.name(),
                times.len()
            );
            rows.push(json!({"case": format!("speed/{}", sensor.name()), "method": name,
                "metric": "time_per_frame", "value": median, "unit": "ms", "max_ms": max,
                "resolution_deg": 45, "frames": times.len()}));
        }
    }
    Ok(table)
}
