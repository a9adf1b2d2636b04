//! The `terrain` benchmark: Tables 4.3, 4.6 and 4.7 of the thesis (Chapter 4, spec
//! `tof-hough.md` §3, §5) on simulated snapshots with ground truth, the real frames of the
//! shared data folder, and the speed of the plane Hough transform against the literal
//! Algorithm 2.
//!
//! The number of snapshots per parameter set is `PATCHNAV_TERRAIN_SNAPSHOTS` (default 20 for
//! the range camera, half of it for the stereo camera, whose frames are 12 times larger).
//! Tables go to standard error, one JSON row per measurement to standard output.

use anyhow::{Context, Result};
use hough_terrain::TerrainClass;
use serde_json::{Value, json};

mod mount;
mod real;
mod speed;
mod synthetic;
mod thesis;

use synthetic::{CaseResult, METHODS, Outcome, RESOLUTIONS, Sensor};

/// Snapshots per parameter set by default.
const DEFAULT_SNAPSHOTS: usize = 20;

/// Snapshots per parameter set: `PATCHNAV_TERRAIN_SNAPSHOTS`, else [`DEFAULT_SNAPSHOTS`].
fn snapshots() -> Result<usize> {
    Ok(match std::env::var("PATCHNAV_TERRAIN_SNAPSHOTS") {
        Ok(v) => {
            v.parse::<usize>().ok().filter(|&n| (1..=10_000).contains(&n)).with_context(|| {
                format!("PATCHNAV_TERRAIN_SNAPSHOTS must be a count in 1..=10000, not `{v}`")
            })?
        }
        Err(_) => DEFAULT_SNAPSHOTS,
    })
}

/// Runs the `terrain-mount` benchmark: the mount self-calibration on the simulated snapshots.
pub fn run_mount(seed: u64) -> Result<Vec<Value>> {
    mount::run(snapshots()?, seed)
}

/// Runs the terrain benchmark.
pub fn run(seed: u64) -> Result<Vec<Value>> {
    let n = snapshots()?;
    let mut rows = Vec::new();
    eprintln!(
        "Simulated snapshots: camera {} m above the floor, pitched down {}°, optical axes; {n} snapshots \
         per parameter set (range camera), {} (stereo); seed {seed}",
        synthetic::HEIGHT,
        synthetic::PITCH_DEG,
        n.div_ceil(2)
    );
    let results = synthetic::run_all(n, seed)?;
    eprintln!("{}", table_4_3(&results, &mut rows));
    for (sensor, title, thesis_rows, printed) in [
        (Sensor::Stereo, "Table 4.6 (stereo)", &thesis::TABLE_4_6[..], thesis::TABLE_4_6_MEAN),
        (Sensor::Tof, "Table 4.7 (time of flight)", &thesis::TABLE_4_7[..], thesis::TABLE_4_7_MEAN),
        (
            Sensor::TofSun,
            "Table 4.7 (time of flight, sunlit)",
            &thesis::TABLE_4_7[..],
            thesis::TABLE_4_7_MEAN,
        ),
        (
            Sensor::TofSunMasked,
            "Table 4.7 (time of flight, sunlit, saturated pixels left out)",
            &thesis::TABLE_4_7[..],
            thesis::TABLE_4_7_MEAN,
        ),
    ] {
        for method in METHODS {
            eprintln!(
                "{}",
                class_table(&results, method, sensor, title, thesis_rows, printed, &mut rows)
            );
        }
    }
    rows.extend(real::run()?);
    rows.extend(speed::run(seed)?);
    Ok(rows)
}

/// Success, false negatives, false positives (shares of accepted snapshots) and mean ms at 45°.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub(crate) struct Drive {
    /// Snapshots scored.
    pub snapshots: usize,
    /// Snapshots the preprocessing accepted.
    pub accepted: usize,
    /// Share judged as the truth says.
    pub success: f64,
    /// Share judged not drivable although passable.
    pub fneg: f64,
    /// Share judged drivable although not passable.
    pub fpos: f64,
    /// Mean ms per snapshot.
    pub ms: f64,
    /// Mean `#PC`.
    pub points: f64,
}

/// Scores drivability: `(passable, outcome)` per snapshot; rejected snapshots are excluded
/// (as the thesis excluded what its preprocessing rejected, Table 4.2).
pub(crate) fn score_drive(items: &[(bool, Outcome)]) -> Drive {
    let accepted: Vec<_> = items.iter().filter(|(_, o)| o.accepted).collect();
    let a = accepted.len().max(1) as f64;
    let count = |f: &dyn Fn(bool, &Outcome) -> bool| {
        accepted.iter().filter(|(p, o)| f(*p, o)).count() as f64 / a
    };
    Drive {
        snapshots: items.len(),
        accepted: accepted.len(),
        success: count(&|p, o| p == o.drivable),
        fneg: count(&|p, o| p && !o.drivable),
        fpos: count(&|p, o| !p && o.drivable),
        ms: items.iter().map(|(_, o)| o.seconds).sum::<f64>() * 1e3 / items.len().max(1) as f64,
        points: items.iter().map(|(_, o)| o.points as f64).sum::<f64>() / items.len().max(1) as f64,
    }
}

/// The share of accepted snapshots classified as `label`, and the mean ms.
pub(crate) fn class_rate(label: TerrainClass, outcomes: &[Outcome]) -> (f64, f64) {
    let accepted: Vec<_> = outcomes.iter().filter(|o| o.accepted).collect();
    let rate =
        accepted.iter().filter(|o| o.class == label).count() as f64 / accepted.len().max(1) as f64;
    let ms = outcomes.iter().map(|o| o.seconds).sum::<f64>() * 1e3 / outcomes.len().max(1) as f64;
    (rate, ms)
}

fn fmt_rate(v: f64) -> String {
    if v == 0.0 || v == 1.0 {
        format!("{v:.0}")
    } else {
        format!("{v:.3}").trim_start_matches('0').to_owned()
    }
}

fn fmt_drive(d: &Drive) -> String {
    format!("{} / {} / {} / {:.2}", fmt_rate(d.success), fmt_rate(d.fneg), fmt_rate(d.fpos), d.ms)
}

fn table_4_3(results: &[CaseResult], rows: &mut Vec<Value>) -> String {
    let mut s = String::from(
        "Table 4.3: drivability at 45° (success / FN / FP / ms per snapshot), ours on simulated snapshots beside \
         the thesis's datasets\n| sensor | method | ours | snapshots (excluded) | mean points | thesis Arena | thesis Outdoor 1 | \
         thesis Outdoor 2 | thesis Outdoor 3 |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for (sensor, method) in Sensor::ALL.into_iter().flat_map(|s| METHODS.map(|m| (s, m))) {
        let items: Vec<(bool, Outcome)> = results
            .iter()
            .filter(|r| r.sensor == sensor && r.method == method)
            .flat_map(|r| r.outcomes[0].iter().map(|o| (r.case.passable, *o)))
            .collect();
        let d = score_drive(&items);
        let thesis_sensor = if sensor == Sensor::Stereo { "Stereo" } else { "TOF" };
        let thesis: Vec<String> = ["Arena", "Outdoor 1", "Outdoor 2", "Outdoor 3"]
            .iter()
            .map(|ds| {
                thesis::TABLE_4_3
                    .iter()
                    .find(|r| r.sensor == thesis_sensor && r.dataset == *ds)
                    .map_or("excluded".to_owned(), |r| {
                        format!(
                            "{} / {} / {} / {}",
                            fmt_rate(r.success),
                            fmt_rate(r.fneg),
                            fmt_rate(r.fpos),
                            r.ms
                        )
                    })
            })
            .collect();
        let excluded = 1.0 - d.accepted as f64 / d.snapshots.max(1) as f64;
        s += &format!(
            "| {} | {method} | {} | {} ({:.0} %) | {:.0} | {} |\n",
            sensor.name(),
            fmt_drive(&d),
            d.snapshots,
            excluded * 100.0,
            d.points,
            thesis.join(" | ")
        );
        for (metric, value, unit) in [
            ("drive_success", d.success, "share"),
            ("drive_false_negative", d.fneg, "share"),
            ("drive_false_positive", d.fpos, "share"),
            ("time_per_snapshot", d.ms, "ms"),
            ("excluded", excluded, "share"),
        ] {
            rows.push(
                json!({"case": format!("sim/{}", sensor.name()), "method": method, "metric": metric,
                "value": value, "unit": unit, "resolution_deg": 45, "snapshots": d.snapshots,
                "mean_points": d.points}),
            );
        }
    }
    s += "Thesis: success 83–100 %, stereo 98–100 %, 5–50 ms per frame (hardware not stated).";
    s
}

fn class_table(
    results: &[CaseResult],
    method: &str,
    sensor: Sensor,
    title: &str,
    thesis_rows: &[thesis::SceneRow],
    printed: [(f64, f64); 3],
    rows: &mut Vec<Value>,
) -> String {
    let mut s = format!(
        "{title}, method {method}: classification rate / ms per snapshot at 45° | 15° | 9°\n| set | label | snapshots | mean points | \
         drivable | @45° | @15° | @9° |\n|---|---|---|---|---|---|---|---|\n"
    );
    let mut sums = [(0.0, 0.0); 3];
    let mut count = 0usize;
    for r in results.iter().filter(|r| r.sensor == sensor && r.method == method) {
        let cols: Vec<(f64, f64)> =
            r.outcomes.iter().map(|o| class_rate(r.case.label, o)).collect();
        let points = r.outcomes[0].iter().map(|o| o.points as f64).sum::<f64>()
            / r.outcomes[0].len().max(1) as f64;
        s += &format!(
            "| {} | {:?} | {} | {:.0} | {} | {} |\n",
            r.case.name,
            r.case.label,
            r.outcomes[0].len(),
            points,
            if r.case.passable { "yes" } else { "no" },
            cols.iter()
                .map(|(rate, ms)| format!("{}/{ms:.2}", fmt_rate(*rate)))
                .collect::<Vec<_>>()
                .join(" | ")
        );
        for (k, (rate, ms)) in cols.iter().enumerate() {
            sums[k].0 += rate;
            sums[k].1 += ms;
            rows.push(json!({"case": format!("sim/{}/{}", sensor.name(), r.case.name), "method": method,
                "metric": "class_rate",
                "value": rate, "unit": "share", "resolution_deg": RESOLUTIONS[k], "ms": ms,
                "label": format!("{:?}", r.case.label), "snapshots": r.outcomes[k].len(), "mean_points": points}));
        }
        count += 1;
    }
    let ours: Vec<String> = sums
        .iter()
        .map(|(r, t)| {
            format!("{}/{:.2}", fmt_rate(r / count.max(1) as f64), t / count.max(1) as f64)
        })
        .collect();
    for (k, (r, t)) in sums.iter().enumerate() {
        rows.push(json!({"case": format!("sim/{}", sensor.name()), "method": method, "metric": "class_rate_mean",
            "value": r / count.max(1) as f64, "unit": "share", "resolution_deg": RESOLUTIONS[k],
            "ms": t / count.max(1) as f64, "thesis_printed": printed[k].0}));
    }
    let fmt3 = |m: [(f64, f64); 3]| {
        m.iter().map(|(r, t)| format!("{r:.2}/{t:.1}")).collect::<Vec<_>>().join(" | ")
    };
    let true_mean = thesis::column_means(thesis_rows, thesis_rows.len() as f64);
    s += &format!("| **ours ({method}), mean of {count} sets** | | | | | {} |\n", ours.join(" | "));
    s += &format!("| thesis, printed mean | | | | | {} |\n", fmt3(printed));
    s += &format!(
        "| thesis, true mean of its {} scenes | | | | | {} |",
        thesis_rows.len(),
        fmt3(true_mean)
    );
    if thesis_rows.len() == 30 {
        s += &format!(
            "\n| thesis, its column sums / 27 (how the printed mean came about) | | | | | {} |",
            fmt3(thesis::column_means(thesis_rows, 27.0))
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn o(class: TerrainClass, drivable: bool, accepted: bool) -> Outcome {
        Outcome { class, drivable, accepted, points: 10, seconds: 0.001 }
    }

    #[test]
    fn drivability_shares_add_up_and_exclude_rejected() {
        use TerrainClass::*;
        let items = [
            (true, o(Floor, true, true)),
            (true, o(Obstacle, false, true)),
            (false, o(Floor, true, true)),
            (false, o(Obstacle, false, true)),
            (true, o(Obstacle, false, false)),
        ];
        let d = score_drive(&items);
        assert_eq!((d.snapshots, d.accepted), (5, 4));
        assert_eq!((d.success, d.fneg, d.fpos), (0.5, 0.25, 0.25));
        assert!((d.success + d.fneg + d.fpos - 1.0).abs() < 1e-12);
        let outs: Vec<Outcome> = items.iter().map(|x| x.1).collect();
        assert_eq!(class_rate(Floor, &outs).0, 0.5);
        assert_eq!(fmt_rate(0.831), ".831");
        assert_eq!(fmt_rate(1.0), "1");
    }
}
