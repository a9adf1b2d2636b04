//! The explored-volume part of `docs/benchmarks.md`: thesis §6.1–6.2 Tables 6.1 (what each of
//! the lab's four maps holds, L6721–6739), 6.2 (RRT explored volume and congruence,
//! L6760–6778) and 6.4 (the same for the PRM, L7068–7086) from the rows of `cargo xtask bench
//! lab-volume`, the thesis's figures ([`crate::thesis`]) beside ours.
//!
//! Rows used: those of bench `lab-volume` from its last run in the results (the git revision
//! and date of its last row); of several rows of one case and metric, the last. Table 6.1 puts
//! ours / thesis (×ours/thesis) where the thesis has a positive number; Tables 6.2 and 6.4 keep
//! the thesis's layout (rows and columns planes, hybrid, trimesh, pc) with ours / thesis in
//! every cell.

use super::sig3;
use crate::thesis::{self, LAB_MAPS, TABLE_6_1, VolumeRow};
use roadmap::PlannerKind;
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;

/// The benchmark whose rows this section reads.
const BENCH: &str = "lab-volume";

/// The rows of the last `lab-volume` run, reduced to values per case and metric.
#[derive(Debug, Default)]
struct VolumeRun {
    /// (case, metric) → value.
    values: BTreeMap<(String, String), f64>,
    /// case → its last row (for the run's parameters).
    rows: BTreeMap<String, Value>,
    revision: String,
    dirty: bool,
    date: String,
    hosts: BTreeSet<String>,
    commands: BTreeSet<String>,
}

impl VolumeRun {
    /// The rows of bench `lab-volume` with the git revision and date of the last of them.
    fn from_rows(rows: &[Value]) -> VolumeRun {
        let text = |r: &Value, pointer: &str| {
            r.pointer(pointer).and_then(Value::as_str).unwrap_or("").to_owned()
        };
        let run_of = |r: &Value| (text(r, "/provenance/git_revision"), text(r, "/provenance/date"));
        let ours: Vec<&Value> =
            rows.iter().filter(|r| r.get("bench").and_then(Value::as_str) == Some(BENCH)).collect();
        let Some(last) = ours.last().map(|r| run_of(r)) else { return VolumeRun::default() };
        let mut run =
            VolumeRun { revision: last.0.clone(), date: last.1.clone(), ..VolumeRun::default() };
        for r in ours.into_iter().filter(|r| run_of(r) == last) {
            let (Some(case), Some(metric), Some(value)) = (
                r.get("case").and_then(Value::as_str),
                r.get("metric").and_then(Value::as_str),
                r.get("value").and_then(Value::as_f64),
            ) else {
                continue;
            };
            run.values.insert((case.to_owned(), metric.to_owned()), value);
            run.rows.insert(case.to_owned(), r.clone());
            run.dirty |= r.pointer("/provenance/git_dirty").and_then(Value::as_bool) == Some(true);
            let host = format!("{}; {}", text(r, "/provenance/host"), text(r, "/provenance/cpu"));
            run.hosts.insert(host);
            run.commands.extend(r.get("command").and_then(Value::as_str).map(str::to_owned));
        }
        run
    }

    fn value(&self, case: &str, metric: &str) -> Option<f64> {
        self.values.get(&(case.to_owned(), metric.to_owned())).copied()
    }

    /// A key of the first volume row of `planner` (its parameters).
    fn param(&self, planner: PlannerKind, key: &str) -> Option<&Value> {
        LAB_MAPS.iter().find_map(|m| self.rows.get(&format!("lab-volume/{planner}/{m}"))?.get(key))
    }
}

const HEADING: &str =
    "## Lab: map contents and explored volume (thesis §6.1–6.2, Tables 6.1, 6.2, 6.4)";

/// The section: Table 6.1, 6.2 and 6.4, ours beside the thesis's; a sentence instead when the
/// rows hold no `lab-volume` run.
pub(super) fn volume_section(rows: &[Value]) -> String {
    let run = VolumeRun::from_rows(rows);
    let mut o = format!("{HEADING}\n\n");
    if run.values.is_empty() {
        o.push_str(
            "The results hold no rows of the `lab-volume` benchmark; run `cargo xtask bench \
             lab-volume`, then `cargo xtask docs`.\n",
        );
        return o;
    }
    o.push_str(
        "The lab's four maps built from simulated ALRF scans, as for the `lab-scans-*` scenes \
         above (`planes`, `hybrid` and `trimesh` by patch extraction, `pc` the raw scan \
         points). The patch maps run in the `trimesh` backend (one BVH over all triangles: the \
         thesis ran all its patch maps in one collision library, Bullet), pc in the \
         `pointcloud` backend (Algorithm 10). RRTs (thesis configuration: uniform samples in \
         each map's own box, no goal) grow from free points near the room's corners, PRMs (six \
         neighbours) from the first; each roadmap's explored part (its edges, and vertices with \
         an edge or a free sphere) is rasterised, a voxel counting when its centre lies within \
         the robot radius of a vertex or edge, into one grid per map and planner over the box \
         covering all maps (thesis §6.1.1, L6596–6606). A cell of Tables 6.2 and 6.4 is the \
         volume explored on the row's map but not on the column's, in % of the row's volume. \
         The thesis grew far more roadmaps (480 RRTs per map with K = 10,000, L6895–6899), so \
         our percentages carry more sampling noise; its noise floor is the hybrid row's planes \
         column (0.343 % for the RRT, ideally 0 since the planes map is part of the hybrid \
         one, L6885–6895). Its volumes are of its own lab and boxes (objects seen through \
         windows inflate them, spec §7.18): compare the percentages, not the volumes.\n\n",
    );
    let list = |s: &BTreeSet<String>| s.iter().cloned().collect::<Vec<_>>().join(", ");
    let maps = run
        .rows
        .values()
        .find_map(|r| r.get("lab_maps").and_then(Value::as_str))
        .map_or(String::new(), |k| format!("; maps `{k}`"));
    let _ = writeln!(
        o,
        "Rows of the run of {} at `{}`{}{maps}; {}. Command: {}; then `cargo xtask docs`. The \
         thesis's size: `PATCHNAV_LAB_VOLUME_K=10000 PATCHNAV_LAB_VOLUME_CELLS=1024 cargo \
         xtask bench lab-volume --seeds 120` (hours).\n",
        run.date,
        run.revision,
        if run.dirty { " (modified tree)" } else { "" },
        list(&run.hosts),
        if run.commands.is_empty() {
            "`cargo xtask bench lab-volume`".to_owned()
        } else {
            run.commands.iter().map(|c| format!("`{c}`")).collect::<Vec<_>>().join(", ")
        }
    );
    o.push_str(&contents_table(&run));
    o.push_str(&volume_table(&run, PlannerKind::Rrt, "6.2", "RRT", &thesis::TABLE_6_2_RRT));
    o.push_str(&volume_table(&run, PlannerKind::Prm, "6.4", "PRM", &thesis::TABLE_6_4_PRM));
    o
}

/// A count as the thesis prints it ([`thesis::count_text`]); a negative or non-finite value as
/// it is.
fn count_text(n: f64) -> String {
    if !(n.is_finite() && n >= 0.0) {
        return format!("{n}");
    }
    thesis::count_text(n.round() as u64)
}

/// Megabytes with three significant digits.
fn mb_text(bytes: f64) -> String {
    format!("{} MB", sig3(bytes / 1e6))
}

/// "ours / thesis (×ratio)" with a ratio only when both are positive; ours alone where the
/// thesis has no figure ("–" for none or zero of ours); "–" when ours is missing.
fn cell(ours: Option<f64>, thesis: Option<f64>, fmt: fn(f64) -> String) -> String {
    match (ours, thesis) {
        (None, _) | (Some(0.0), None) => "–".to_owned(),
        (Some(o), None) => fmt(o),
        (Some(o), Some(t)) if o > 0.0 && t > 0.0 => {
            format!("{} / {} (×{})", fmt(o), fmt(t), sig3(o / t))
        }
        (Some(o), Some(t)) => format!("{} / {}", fmt(o), fmt(t)),
    }
}

/// Table 6.1: per map (the thesis's row order) what it holds, ours / thesis.
fn contents_table(run: &VolumeRun) -> String {
    let mut o = String::from(
        "### Table 6.1: what each map holds\n\nOurs / thesis (×ours/thesis; the thesis's Lab \
         has 29 scans, L6721–6739). Triangles are those the map holds in our backend: of the \
         trimesh patches and of the planar patches' triangulations, as the thesis counts them. \
         Points, and the heap memory of the map in its backend, have no thesis column.\n\n\
         | Map | file size | planar patches | trimesh patches | point clouds | triangles | points | memory |\n\
         |---|---|---|---|---|---|---|---|\n",
    );
    let mut any = false;
    for t in TABLE_6_1 {
        let case = format!("lab-volume/contents/{}", t.map);
        let v = |metric: &str| run.value(&case, metric);
        any |= v("file_bytes").is_some();
        let count = |n: Option<u32>| n.map(f64::from);
        let file = match v("file_bytes") {
            Some(b) => {
                let ratio = sig3(b / 1e6 / t.file_size_mb);
                format!("{} / {:.1} MB (×{ratio})", mb_text(b), t.file_size_mb)
            }
            None => "–".to_owned(),
        };
        let _ = writeln!(
            o,
            "| {} | {file} | {} | {} | {} | {} | {} | {} |",
            t.map,
            cell(v("planar_patches"), count(t.planar_patches), count_text),
            cell(v("trimesh_patches"), count(t.trimesh_patches), count_text),
            cell(v("point_clouds"), count(t.point_clouds), count_text),
            cell(v("triangles"), count(t.triangles), count_text),
            cell(v("points"), None, count_text),
            cell(v("memory_bytes"), None, mb_text),
        );
    }
    if !any {
        return String::from(
            "### Table 6.1: what each map holds\n\nThe rows hold no `lab-volume/contents/*` \
             case.\n\n",
        );
    }
    let file = |map: &str| run.value(&format!("lab-volume/contents/{map}"), "file_bytes");
    let size = |map: &str| TABLE_6_1.iter().find(|t| t.map == map).map(|t| t.file_size_mb);
    if let (Some(pc), Some(planes), Some(tpc), Some(tplanes)) =
        (file("pc"), file("planes"), size("pc"), size("planes"))
        && planes > 0.0
    {
        let _ = writeln!(
            o,
            "\nFile size pc / planes: ours ×{}; thesis ×{} ({tpc:.1} MB / {tplanes:.1} MB, the \
             \"18× smaller\" of L108 and L7643).",
            sig3(pc / planes),
            sig3(tpc / tplanes)
        );
    }
    o.push('\n');
    o
}

/// A volume table (6.2 or 6.4) in the thesis's layout, ours / thesis per cell, with the run's
/// parameters; a sentence when the rows hold none of `planner`.
fn volume_table(
    run: &VolumeRun,
    planner: PlannerKind,
    number: &str,
    label: &str,
    thesis_rows: &[VolumeRow; 4],
) -> String {
    let mut o = format!(
        "### Table {number}: explored volume of the {label}, % not explored on the other maps\n\n"
    );
    let case = |map: &str| format!("lab-volume/{planner}/{map}");
    if !LAB_MAPS.iter().any(|m| run.value(&case(m), "volume").is_some()) {
        let _ = writeln!(o, "The rows hold no {label} volume (`lab-volume/{planner}/*`).\n");
        return o;
    }
    let p = |key: &str| run.param(planner, key).and_then(Value::as_f64);
    let n = |key: &str| p(key).map_or("?".to_owned(), |v| format!("{v}"));
    let cell_mm = p("cell_size_m").map_or("?".to_owned(), |c| sig3(c * 1e3));
    let runs = if planner == PlannerKind::Rrt {
        format!(
            "{} start(s) × {} seeds = {} roadmaps per map, K = {}, robot radius {} m, step {} m",
            n("starts"),
            n("seeds"),
            n("runs"),
            n("k"),
            n("radius"),
            n("step")
        )
    } else {
        format!(
            "{} seeds = {} roadmaps per map, K = {}, robot radius {} m, {} neighbours",
            n("seeds"),
            n("runs"),
            n("k"),
            n("radius"),
            n("neighbours")
        )
    };
    let _ = writeln!(
        o,
        "Ours / thesis. Ours: {runs}, {}³ cells of {cell_mm} mm; the thesis: {}, 1024³ cells of \
         38.684 mm.\n",
        n("cells"),
        if planner == PlannerKind::Rrt {
            "480 roadmaps per map (4 corners × 120 seeds), K = 10,000"
        } else {
            "seeds and K not given (spec §7.11)"
        }
    );
    let _ = writeln!(o, "| Map | Volume [m³] | {} |", LAB_MAPS.join(" | "));
    let _ = writeln!(o, "|---|---|---|---|---|---|");
    for t in thesis_rows {
        let volume = run.value(&case(t.map), "volume");
        let mut line = format!(
            "| {} | {} / {} |",
            t.map,
            volume.map_or("–".to_owned(), |v| format!("{v:.3}")),
            t.volume_m3
        );
        for (col, theirs) in LAB_MAPS.iter().zip(t.not_in_percent) {
            let text = match theirs {
                None => "–".to_owned(),
                Some(theirs) => {
                    let ours = run.value(&format!("{}/{col}", case(t.map)), "not_in");
                    format!("{} / {theirs:.3}", ours.map_or("–".to_owned(), |v| format!("{v:.3}")))
                }
            };
            let _ = write!(line, " {text} |");
        }
        let _ = writeln!(o, "{line}");
    }
    let noise = thesis_rows
        .iter()
        .find(|t| t.map == "hybrid")
        .and_then(|t| t.not_in_percent[0])
        .map(|theirs| (run.value(&format!("{}/planes", case("hybrid")), "not_in"), theirs));
    if let Some((Some(ours), theirs)) = noise {
        let _ = writeln!(
            o,
            "\nNoise floor (hybrid not in planes, ideally 0: the planes map is part of the \
             hybrid one): ours {ours:.3} %, thesis {theirs:.3} %."
        );
    }
    o.push('\n');
    o
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn row(case: &str, metric: &str, value: f64, date: &str) -> Value {
        json!({
            "bench": "lab-volume", "case": case, "metric": metric, "value": value,
            "planner": case.split('/').nth(1), "starts": 4, "seeds": 10, "runs": 40, "k": 1000,
            "cells": 320, "cell_size_m": 0.0383, "radius": 0.3, "step": 1.0, "neighbours": 6,
            "lab_maps": "lab-seed0-scans8-h0.5-steps300",
            "command": "cargo xtask bench lab-volume",
            "provenance": {"git_revision": "abc", "date": date, "host": "h", "cpu": "c"},
        })
    }

    /// A run: the four maps' contents, and both planners' volumes, with "not in" = row index
    /// + column index / 10 (so every cell is told apart).
    fn rows(date: &str, planners: &[&str]) -> Vec<Value> {
        let mut rows = Vec::new();
        let contents = [
            ("planes", [68.0, 0.0, 4038.0, 0.0, 900_000.0, 76_669.0]),
            ("hybrid", [68.0, 7263.0, 240_760.0, 0.0, 56_600_000.0, 6_232_654.0]),
            ("trimesh", [0.0, 54_703.0, 2_937_570.0, 0.0, 688_500_000.0, 77_741_934.0]),
            ("pc", [0.0, 0.0, 0.0, 1_517_339.0, 78_900_000.0, 36_416_217.0]),
        ];
        for (map, values) in contents {
            let metrics = [
                "planar_patches",
                "trimesh_patches",
                "triangles",
                "points",
                "memory_bytes",
                "file_bytes",
            ];
            for (metric, v) in metrics.iter().zip(values) {
                rows.push(row(&format!("lab-volume/contents/{map}"), metric, v, date));
            }
        }
        rows.push(row("lab-volume/contents/pc", "point_clouds", 8.0, date));
        for planner in planners {
            for (r, map) in LAB_MAPS.iter().enumerate() {
                let case = format!("lab-volume/{planner}/{map}");
                rows.push(row(&case, "volume", 300.0 + r as f64, date));
                for (c, col) in LAB_MAPS.iter().enumerate() {
                    if r != c {
                        let v = r as f64 + c as f64 / 10.0;
                        rows.push(row(&format!("{case}/{col}"), "not_in", v, date));
                    }
                }
            }
        }
        rows
    }

    fn line<'a>(text: &'a str, table: &str, map: &str) -> &'a str {
        let start = text.find(&format!("### Table {table}:")).expect("the table");
        text[start..]
            .lines()
            .find(|l| l.starts_with(&format!("| {map} |")))
            .unwrap_or_else(|| panic!("no {map} line in Table {table}: {text}"))
    }

    #[test]
    fn tables_put_ours_beside_the_thesis_in_its_layout() {
        let text = volume_section(&rows("2026-11-22T08:00:00Z", &["rrt", "prm"]));
        // Table 6.1, the thesis's row order (hybrid, pc, planes, trimesh).
        let order: Vec<usize> = ["| hybrid |", "| pc |", "| planes |", "| trimesh |"]
            .map(|m| text.find(m).unwrap())
            .to_vec();
        assert!(order.windows(2).all(|w| w[0] < w[1]), "{text}");
        assert_eq!(
            line(&text, "6.1", "planes"),
            "| planes | 0.0767 MB / 3.0 MB (×0.0256) | 68 / 5906 (×0.0115) | 0 / 0 | – | \
             4038 / 86,174 (×0.0469) | – | 0.900 MB |"
        );
        assert_eq!(
            line(&text, "6.1", "pc"),
            "| pc | 36.4 MB / 54.0 MB (×0.674) | – | – | 8 / 29 (×0.276) | – | 1,517,339 | 78.9 MB |"
        );
        assert!(line(&text, "6.1", "trimesh").contains("| 2,937,570 / 5,600,612 (×0.525) |"));
        // pc / planes file size: 36,416,217 / 76,669 = 475; thesis 54.0 / 3.0 = 18.
        assert!(text.contains("File size pc / planes: ours ×475; thesis ×18.0"), "{text}");
        // Tables 6.2 and 6.4: header and rows in the thesis's order, ours / thesis per cell.
        for (table, thesis) in [("6.2", "9714.015"), ("6.4", "11859.6544")] {
            let start = text.find(&format!("### Table {table}:")).unwrap();
            assert!(
                text[start..].contains("| Map | Volume [m³] | planes | hybrid | trimesh | pc |")
            );
            let planes = line(&text, table, "planes");
            assert!(
                planes.starts_with(&format!("| planes | 300.000 / {thesis} | – |")),
                "{planes}"
            );
        }
        assert_eq!(
            line(&text, "6.2", "hybrid"),
            "| hybrid | 301.000 / 9693.171 | 1.000 / 0.343 | – | 1.200 / 1.551 | 1.300 / 0.803 |"
        );
        assert_eq!(
            line(&text, "6.4", "pc"),
            "| pc | 303.000 / 11818.7659 | 3.000 / 0.042 | 3.100 / 0.057 | 3.200 / 0.416 | – |"
        );
        assert!(text.contains("ours 1.000 %, thesis 0.343 %"), "{text}");
        assert!(text.contains("ours 1.000 %, thesis 0.008 %"), "PRM noise floor: {text}");
        assert!(
            text.contains(
                "4 start(s) × 10 seeds = 40 roadmaps per map, K = 1000, robot radius 0.3 m, step 1 m"
            ),
            "{text}"
        );
        assert!(text.contains("K = 1000, robot radius 0.3 m, 6 neighbours, 320³"), "{text}");
        assert!(text.contains("320³ cells of 38.3 mm"), "{text}");
        assert!(text.contains("Command: `cargo xtask bench lab-volume`; then"), "{text}");
        assert!(text.contains("maps `lab-seed0-scans8-h0.5-steps300`"), "{text}");
    }

    #[test]
    fn the_last_run_is_used_and_missing_rows_are_said() {
        // An earlier run with other numbers, then a run with RRT rows only.
        let mut all: Vec<Value> = rows("2026-11-22T07:00:00Z", &["rrt", "prm"])
            .into_iter()
            .map(|mut r| {
                r["value"] = json!(999.0);
                r
            })
            .collect();
        all.extend(rows("2026-11-22T08:00:00Z", &["rrt"]));
        // Rows of another benchmark are not ours.
        all.push(json!({"bench": "roadmap", "case": "lab-volume/prm/planes", "metric": "volume", "value": 1.0}));
        let text = volume_section(&all);
        assert!(!text.contains("999"), "{text}");
        assert!(text.contains("| planes | 300.000 / 9714.015 |"), "{text}");
        assert!(text.contains("The rows hold no PRM volume (`lab-volume/prm/*`)."), "{text}");
        assert!(text.contains("2026-11-22T08:00:00Z"));
        // No lab-volume rows at all: one sentence under the heading.
        let none = volume_section(&all[all.len() - 1..]);
        assert!(none.starts_with(HEADING), "{none}");
        assert!(none.contains("hold no rows of the `lab-volume` benchmark"), "{none}");
        assert!(!none.contains("### Table"));
    }

    #[test]
    fn numbers_print_as_the_thesis_prints_them() {
        assert_eq!(count_text(5906.0), "5906");
        assert_eq!(count_text(5_600_612.0), "5,600,612");
        assert_eq!(count_text(17_273.0), "17,273");
        assert_eq!(cell(Some(0.0), Some(0.0), count_text), "0 / 0");
        assert_eq!(cell(Some(3.0), Some(0.0), count_text), "3 / 0");
        assert_eq!(cell(Some(0.0), None, count_text), "–");
        assert_eq!(cell(None, Some(3.0), count_text), "–");
        assert_eq!(mb_text(76_669.0), "0.0767 MB");
    }

    #[test]
    fn the_page_carries_the_volume_rows_of_the_results() {
        let mut rows = vec![json!({"bench": "roadmap", "scene": "lab", "backend": "polygon",
            "planner": "rrt", "metric": "time", "seed": 1, "value": 0.001, "case": "lab/polygon/rrt/1"})];
        rows.push(
            json!({"bench": "lab-volume", "case": "lab-volume/rrt/planes", "metric": "volume",
            "value": 354.7, "unit": "m3"}),
        );
        let m = super::super::Matrix::from_rows(&rows);
        assert_eq!(m.volume.len(), 1);
        let page = super::super::page(&m, "x.svg").unwrap();
        assert!(page.contains(HEADING), "{page}");
    }
}
