//! The benchmarks page (`docs/benchmarks.md`, written by `cargo xtask docs`) and its plot, made from the rows
//! of the `roadmap` matrix in `target/bench/results.jsonl`.
//!
//! The page holds every thesis table the matrix reproduces — the office benchmark's Tables
//! 5.3–5.11 (median time to reach the four ROIs and its quartiles, added path length, steep and
//! total turns at the median and both quartiles, curviness; the `office` module) per planner and backend,
//! and the lab RRT time per map at K = 500 (Fig 6.4, whose numbers the thesis gives only as
//! bounds in its prose, L6813–6818) — with the thesis's figure beside ours (from
//! [`crate::thesis`]) and the ratio ours / thesis, one SVG plot, the provenance of the rows
//! used and the command that made them. A table whose metric the rows lack says so instead.
//!
//! Rows used: per scene, those of the git revision of the scene's last matrix row in the file
//! (scenes may be run at different revisions: `--scene office`, then `--scene lab`); of several
//! rows of one case and metric the last one. Medians and quartiles are over the successful runs, as in
//! the thesis (L6119–6121), interpolated between closest ranks (Hyndman & Fan type 7, the method
//! of `roadmap::metrics::quantile`).

mod lab;

use crate::ompl_log::MatrixRow;
mod office;
mod volume;

use crate::thesis;
use anyhow::{Result, bail};
use lab::{lab_scans_section, lab_table};
use office::office_sections;
pub use office::office_time_svg;
use patch_map::Backend;
use roadmap::PlannerKind;
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;

/// The matrix's backends in the thesis's column order, with the thesis's name for each
/// ([`thesis::OFFICE_COLUMNS`]; the point-cloud map has no counterpart in its tables).
const BACKENDS: [(Backend, &str); 5] = [
    (Backend::Polygon, thesis::OFFICE_COLUMNS[0]),
    (Backend::BBox6d, thesis::OFFICE_COLUMNS[1]),
    (Backend::Trimesh, thesis::OFFICE_COLUMNS[2]),
    (Backend::Rapier, thesis::OFFICE_COLUMNS[3]),
    (Backend::PointCloud, "–"),
];
/// The matrix's planners, the thesis's five first, with their labels.
const PLANNERS: [(PlannerKind, &str); 10] = [
    (PlannerKind::Rrt, "RRT"),
    (PlannerKind::MaRrt, "MA RRT"),
    (PlannerKind::EvasionRrt, "Ev. RRT"),
    (PlannerKind::Prm, "PRM"),
    (PlannerKind::MaPrm, "MA PRM"),
    (PlannerKind::RrtConnect, "RRT-Connect"),
    (PlannerKind::PrmStar, "PRM*"),
    (PlannerKind::LazyPrm, "lazy PRM"),
    (PlannerKind::RrtStar, "RRT*"),
    (PlannerKind::PrmValid, "PRM (valid samples)"),
];

pub use crate::stats::quantile;

/// The runs of one cell: seed → metric → value.
pub type Runs = BTreeMap<u64, BTreeMap<String, f64>>;

/// The matrix rows of each scene's last revision, reduced to per-case metrics.
#[derive(Debug, Default)]
pub struct Matrix {
    /// (scene, backend, planner) → seed → metric → value; rows naming no [`Backend`] or no
    /// [`PlannerKind`] are left out.
    pub cells: BTreeMap<(String, Backend, PlannerKind), Runs>,
    /// The rows used.
    pub rows: usize,
    /// The git revision of the last matrix row.
    pub revision: String,
    /// Whether any row used came from a modified tree.
    pub dirty: bool,
    /// Distinct hosts.
    pub hosts: BTreeSet<String>,
    /// Distinct CPUs.
    pub cpus: BTreeSet<String>,
    /// Distinct rustc versions.
    pub rustc: BTreeSet<String>,
    /// Distinct worker counts.
    pub jobs: BTreeSet<u64>,
    /// Distinct commands.
    pub commands: BTreeSet<String>,
    /// The commands per scene.
    pub scene_commands: BTreeMap<String, BTreeSet<String>>,
    /// The first and the last date.
    pub dates: (String, String),
    /// Per scene, the git revision whose rows are used.
    pub scene_revisions: BTreeMap<String, String>,
    /// The rows of bench `lab-volume` (Tables 6.1, 6.2, 6.4; `volume_section` picks
    /// the last run).
    pub volume: Vec<Value>,
}

impl Matrix {
    /// The rows of bench `roadmap`, per scene those of the revision of its last row.
    pub fn from_rows(rows: &[Value]) -> Matrix {
        let rev = |r: &Value| {
            r.pointer("/provenance/git_revision").and_then(Value::as_str).unwrap_or("").to_owned()
        };
        let ours: Vec<&Value> = rows
            .iter()
            .filter(|r| r.get("bench").and_then(Value::as_str) == Some("roadmap"))
            .collect();
        let scene = |r: &Value| r.get("scene").and_then(Value::as_str).unwrap_or("").to_owned();
        let mut m = Matrix {
            volume: rows
                .iter()
                .filter(|r| r.get("bench").and_then(Value::as_str) == Some("lab-volume"))
                .cloned()
                .collect(),
            revision: ours.last().map(|r| rev(r)).unwrap_or_default(),
            scene_revisions: ours.iter().map(|r| (scene(r), rev(r))).collect(),
            ..Matrix::default()
        };
        for r in ours.into_iter().filter(|r| m.scene_revisions.get(&scene(r)) == Some(&rev(r))) {
            let s = |k: &str| r.get(k).and_then(Value::as_str).map(str::to_owned);
            let p = |k: &str| {
                r.pointer(&format!("/provenance/{k}")).and_then(Value::as_str).map(str::to_owned)
            };
            let Some(MatrixRow { scene, backend, planner, metric, seed, value }) = MatrixRow::of(r)
            else {
                continue;
            };
            let (Ok(backend), Ok(planner)) = (backend.parse(), planner.parse()) else {
                continue;
            };
            m.scene_commands.entry(scene.clone()).or_default().extend(s("command"));
            m.cells
                .entry((scene, backend, planner))
                .or_default()
                .entry(seed)
                .or_default()
                .insert(metric, value);
            m.rows += 1;
            m.dirty |= r.pointer("/provenance/git_dirty").and_then(Value::as_bool).unwrap_or(false);
            m.hosts.extend(p("host"));
            m.cpus.extend(p("cpu"));
            m.rustc.extend(p("rustc"));
            m.jobs.extend(r.get("jobs").and_then(Value::as_u64));
            m.commands.extend(s("command"));
            if let Some(d) = p("date") {
                if m.dates.0.is_empty() || d < m.dates.0 {
                    m.dates.0 = d.clone();
                }
                if d > m.dates.1 {
                    m.dates.1 = d;
                }
            }
        }
        m
    }

    /// The values of `metric` over the successful runs of a cell (for explore runs, over all).
    fn values(
        &self,
        scene: &str,
        backend: Backend,
        planner: PlannerKind,
        metric: &str,
    ) -> Vec<f64> {
        let Some(runs) = self.cells.get(&(scene.into(), backend, planner)) else {
            return Vec::new();
        };
        runs.values()
            .filter(|r| scene != "office" || r.get("solved") == Some(&1.0))
            .filter_map(|r| r.get(metric).copied())
            .collect()
    }

    /// "solved/runs" of a cell, or `None` if it has no runs.
    fn solved(
        &self,
        scene: &str,
        backend: Backend,
        planner: PlannerKind,
    ) -> Option<(usize, usize)> {
        let runs = self.cells.get(&(scene.into(), backend, planner))?;
        Some((runs.values().filter(|r| r.get("solved") == Some(&1.0)).count(), runs.len()))
    }

    fn seeds(&self) -> usize {
        self.cells.values().map(BTreeMap::len).max().unwrap_or(0)
    }
}

/// A time in s, ms or µs with three significant digits.
fn time_text(s: f64) -> String {
    let (v, unit) = if s >= 1.0 {
        (s, "s")
    } else if s >= 1e-3 {
        (s * 1e3, "ms")
    } else {
        (s * 1e6, "µs")
    };
    format!("{} {unit}", sig3(v))
}

/// Three significant digits.
fn sig3(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let decimals = (2 - x.abs().log10().floor() as i64).max(0) as usize;
    format!("{x:.decimals$}")
}

/// The page.
pub fn page(m: &Matrix, svg_name: &str) -> Result<String> {
    if m.rows == 0 {
        bail!(
            "no rows of the `roadmap` benchmark in the results (run `cargo xtask bench roadmap` first)"
        );
    }
    let mut o = String::new();
    let list = |s: &BTreeSet<String>| s.iter().map(String::as_str).collect::<Vec<_>>().join("; ");
    writeln!(o, "# Benchmarks: the planning matrix\n")?;
    writeln!(
        o,
        "Generated by `cargo xtask docs` from the rows of `cargo xtask bench roadmap` in \
         `target/bench/results.jsonl`; do not edit by hand. Scenes × backends × planners × seeds, \
         one run per case `scene/backend/planner/seed`; the same rows are in OMPL's benchmark log \
         format under `target/bench/ompl/` (`ompl_benchmark_statistics <log> -d bench.db` makes a \
         database Planner Arena opens). Medians are over the successful runs. Times are wall \
         times on the machine below: compare ratios, not absolute values, across machines — the \
         thesis ran on an i7 920 (2010).\n"
    )?;
    writeln!(o, "## Provenance\n")?;
    writeln!(o, "| | |\n|---|---|")?;
    writeln!(o, "| rows | {} ({} cells, up to {} seeds each) |", m.rows, m.cells.len(), m.seeds())?;
    let mut scenes_of: BTreeMap<&String, Vec<&str>> = BTreeMap::new();
    for (scene, rev) in &m.scene_revisions {
        scenes_of.entry(rev).or_default().push(scene);
    }
    let revision = if scenes_of.len() <= 1 {
        format!("`{}`", m.revision)
    } else {
        let per_rev: Vec<String> =
            scenes_of.iter().map(|(r, s)| format!("`{r}` ({})", s.join(", "))).collect();
        per_rev.join("; ")
    };
    writeln!(o, "| git revision | {revision}{} |", if m.dirty { " (modified tree)" } else { "" })?;
    writeln!(o, "| host, CPU | {}; {} |", list(&m.hosts), list(&m.cpus))?;
    writeln!(o, "| rustc | {} |", list(&m.rustc))?;
    writeln!(o, "| dates | {} – {} |", m.dates.0, m.dates.1)?;
    let jobs: Vec<String> = m.jobs.iter().map(u64::to_string).collect();
    writeln!(o, "| worker threads (`--jobs`) | {} |", jobs.join(", "))?;
    writeln!(
        o,
        "| commands | {} |\n",
        m.commands.iter().map(|c| format!("`{c}`")).collect::<Vec<_>>().join(", ")
    )?;

    o.push_str(&office_sections(m, svg_name));
    writeln!(o, "## Lab: RRT time per map (thesis §6.1, Fig 6.4)\n")?;
    writeln!(
        o,
        "The simulated lab's exact geometry (planar patches plus the tessellated barrel, ball and \
         table legs: the thesis's `hybrid` map as a perfect extraction gives it) in every backend; \
         the point-cloud map samples the same surfaces every 7.5 cm. RRT (and PRM) from a free point \
         near the south-west corner, no goal, timed at K = 100, 500 and 1000 iterations; median \
         (lower–upper quartile). The thesis gives Fig 6.4's numbers only as bounds at K = 500 \
         (L6813–6818): \"less then 0.4 seconds\" [sic] on the planes and hybrid maps, \"well over 4 \
         seconds\" on the point-cloud map; the ratio is ours / that bound.\n\nCommand: `cargo xtask \
         bench roadmap --scene lab`, then `cargo xtask docs`.\n"
    )?;
    o.push_str(&lab_table(m));
    let med = |b: Backend| quantile(&m.values("lab", b, PlannerKind::Rrt, "time_k500"), 0.5);
    let fastest = BACKENDS[..4]
        .iter()
        .filter_map(|&(b, _)| Some((med(b)?, b)))
        .min_by(|x, y| x.0.total_cmp(&y.0));
    if let (Some(pc), Some((patch, name))) = (med(Backend::PointCloud), fastest) {
        writeln!(
            o,
            "\nRRT at K = 500, point-cloud map / fastest patch map ({name}): ours ×{}; thesis: \"more than \
             an order of magnitude slower\" (L6784–6785; > 4 s against < 0.4 s, so > ×10).",
            sig3(pc / patch)
        )?;
    }
    let scans = lab_scans_section(m);
    if !scans.is_empty() {
        o.push('\n');
        o.push_str(&scans);
    }
    o.push('\n');
    o.push_str(&backend_ratios(m)?);
    o.push('\n');
    o.push_str(&volume::volume_section(&m.volume));
    Ok(o)
}

/// Per scene and patch backend, the largest ratio of its median time to the fastest patch
/// backend's over the scene's planners and times (the whole run, K = 100 and K = 500), with
/// where it occurs: the figures behind the crate docs' advice on which backend to pick.
fn backend_ratios(m: &Matrix) -> Result<String> {
    const TIMES: [(&str, &str); 3] =
        [("time", ""), ("time_k100", " K=100"), ("time_k500", " K=500")];
    let patch = &BACKENDS[..4];
    let scenes: BTreeSet<&str> = m.cells.keys().map(|(s, _, _)| s.as_str()).collect();
    let mut o = String::new();
    writeln!(o, "## Which backend: time against the fastest\n")?;
    writeln!(
        o,
        "Per scene, each patch backend's largest ratio of its median time to the fastest patch \
         backend's, over the scene's planners and times (the whole run; K = 100 and 500 on the \
         lab scenes), with the planner where it occurs: the figures behind `patch-map`'s advice \
         on which backend to pick (crate docs, \"Which one to pick\").\n"
    )?;
    writeln!(
        o,
        "| scene | {} |",
        patch.iter().map(|(b, _)| b.name()).collect::<Vec<_>>().join(" | ")
    )?;
    writeln!(o, "|---|{}", "---|".repeat(patch.len()))?;
    for scene in scenes {
        // Per backend: the worst ratio and where.
        let mut worst: Vec<Option<(f64, String)>> = vec![None; patch.len()];
        for (planner, label) in PLANNERS {
            for (metric, k) in TIMES {
                let medians: Vec<Option<f64>> = patch
                    .iter()
                    .map(|&(b, _)| quantile(&m.values(scene, b, planner, metric), 0.5))
                    .collect();
                let Some(best) = medians.iter().flatten().copied().min_by(f64::total_cmp) else {
                    continue;
                };
                if best.is_nan() || best <= 0.0 {
                    continue;
                }
                for (slot, median) in worst.iter_mut().zip(&medians) {
                    if let Some(v) = median {
                        let ratio = v / best;
                        if slot.as_ref().is_none_or(|(w, _)| ratio > *w) {
                            *slot = Some((ratio, format!("{label}{k}")));
                        }
                    }
                }
            }
        }
        if worst.iter().all(Option::is_none) {
            continue;
        }
        let cells: Vec<String> = worst
            .iter()
            .map(|w| w.as_ref().map_or("–".to_owned(), |(r, at)| format!("×{:.2} ({at})", r)))
            .collect();
        writeln!(o, "| {scene} | {} |", cells.join(" | "))?;
    }
    Ok(o)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn row(
        scene: &str,
        backend: &str,
        planner: &str,
        seed: u64,
        metric: &str,
        value: f64,
        rev: &str,
    ) -> Value {
        json!({
            "bench": "roadmap", "scene": scene, "backend": backend, "planner": planner, "seed": seed,
            "metric": metric, "value": value, "jobs": 1, "command": "cargo xtask bench roadmap",
            "provenance": {"git_revision": rev, "host": "h", "cpu": "c", "rustc": "r", "date": "2026-11-22T05:00:00Z"},
        })
    }

    #[test]
    fn quantiles_interpolate_between_closest_ranks() {
        assert_eq!(quantile(&[3.0, 1.0, 2.0, 4.0], 0.5), Some(2.5));
        assert_eq!(quantile(&[1.0, 2.0, 3.0, 4.0, 5.0], 0.25), Some(2.0));
        assert_eq!(quantile(&[7.0], 0.75), Some(7.0));
        assert_eq!(quantile(&[], 0.5), None);
        assert_eq!(quantile(&[f64::NAN, 1.0], 0.5), Some(1.0));
        assert_eq!(quantile(&[1.0], 1.5), None);
    }

    #[test]
    fn tables_put_the_thesis_beside_ours_over_successful_runs_of_the_last_revision() {
        let mut rows = Vec::new();
        // An old revision with absurd numbers: must not be used.
        rows.push(row("office", "rapier", "rrt", 0, "time", 100.0, "old"));
        rows.push(row("office", "rapier", "rrt", 0, "solved", 1.0, "old"));
        for (seed, time, solved) in [(0, 0.004, 1.0), (1, 0.006, 1.0), (2, 9.0, 0.0)] {
            rows.push(row("office", "rapier", "rrt", seed, "time", time, "new"));
            rows.push(row("office", "rapier", "rrt", seed, "solved", solved, "new"));
        }
        // A repeated case: the later row wins.
        rows.push(row("office", "rapier", "rrt", 1, "time", 0.0050, "new"));
        rows.push(row("office", "rapier", "rrt", 0, "path_length", 50.0, "new"));
        rows.push(row("office", "rapier", "rrt", 1, "path_length", 60.0, "new"));
        rows.push(row("lab", "polygon", "rrt", 0, "time_k500", 0.001, "new"));
        rows.push(row("lab", "polygon", "rrt", 0, "solved", 0.0, "new"));
        rows.push(row("lab", "pointcloud", "rrt", 0, "time_k500", 0.05, "new"));
        let m = Matrix::from_rows(&rows);
        assert_eq!(m.revision, "new");
        let page = page(&m, "img/x.svg").unwrap();
        // Median of the two successful runs (4 ms, 5 ms) = 4.5 ms; thesis Bullet RRT 4.721 ms.
        let ratio = sig3(0.0045 / 0.004721);
        assert!(page.contains(&format!("4.50 ms / 4.72 ms (×{ratio})")), "{page}");
        assert!(page.contains("| 0/0 0/0 0/0 2/3 0/0 |") || page.contains("2/3"), "solved counts");
        assert!(
            page.contains("55.0 m / 23.2 m (×2.37)"),
            "path length median 55 m against 23.1608 m"
        );
        assert!(page.contains("1.00 ms (1.00 ms–1.00 ms) / thesis < 0.4 s (×0.00250)"), "{page}");
        assert!(page.contains("| git revision | `new` |") && !page.contains("100 s"), "{page}");
        assert!(page.contains("fastest patch map (polygon): ours ×50.0"), "{page}");
        let svg = office_time_svg(&m);
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("RRT on rapier: 4.50 ms"));
        assert!(page_of_nothing_fails());
    }

    #[test]
    fn backend_ratios_give_each_backends_worst_ratio_to_the_fastest() {
        let mut rows = Vec::new();
        for (backend, rrt, prm) in [("polygon", 1.0, 4.0), ("bbox6d", 3.0, 2.0)] {
            for (planner, time) in [("rrt", rrt), ("prm", prm)] {
                rows.push(row("office", backend, planner, 0, "time", time, "r"));
                rows.push(row("office", backend, planner, 0, "solved", 1.0, "r"));
            }
        }
        let table = backend_ratios(&Matrix::from_rows(&rows)).unwrap();
        assert!(table.contains("| office | ×2.00 (PRM) | ×3.00 (RRT) | – | – |"), "{table}");
    }

    #[test]
    fn each_scene_uses_the_rows_of_its_own_last_revision() {
        let rows = vec![
            row("office", "rapier", "rrt", 0, "time", 0.1, "a"),
            row("office", "rapier", "rrt", 0, "solved", 1.0, "a"),
            row("lab", "polygon", "rrt", 0, "time_k500", 9.0, "a"),
            row("office", "rapier", "rrt", 0, "time", 0.004, "b"),
            row("office", "rapier", "rrt", 0, "solved", 1.0, "b"),
            row("lab", "polygon", "rrt", 0, "time_k500", 0.002, "c"),
            row("lab", "polygon", "rrt", 0, "solved", 0.0, "c"),
        ];
        let m = Matrix::from_rows(&rows);
        assert_eq!(m.revision, "c");
        assert_eq!(m.rows, 4, "office from b, lab from c");
        let page = page(&m, "x.svg").unwrap();
        assert!(page.contains("4.00 ms / 4.72 ms"), "{page}");
        assert!(page.contains("2.00 ms (2.00 ms–2.00 ms) / thesis < 0.4 s"), "{page}");
        assert!(page.contains("| git revision | `b` (office); `c` (lab) |"), "{page}");
    }

    fn page_of_nothing_fails() -> bool {
        page(&Matrix::from_rows(&[]), "x").is_err()
    }

    #[test]
    fn numbers_print_with_three_significant_digits() {
        assert_eq!(time_text(0.004721), "4.72 ms");
        assert_eq!(time_text(1.96683), "1.97 s");
        assert_eq!(time_text(0.000147), "147 µs");
        assert_eq!(sig3(23.1608), "23.2");
        assert_eq!(office::cell(None, Some(1.0), sig3), "–");
        assert_eq!(office::cell(Some(2.0), None, sig3), "2.00");
        assert_eq!(office::cell(Some(2.0), Some(0.0), sig3), "2.00 / 0 (×–)");
    }

    /// Five solved office runs of RRT on rapier (the thesis's Bullet column) with known
    /// quartiles, an unsolved one that must not count, and one run of a planner the thesis
    /// does not have; `metrics` picks which metrics the rows carry.
    fn office_rows(metrics: &[&str]) -> Vec<Value> {
        let mut rows = Vec::new();
        for seed in 0..5u64 {
            let i = seed as f64;
            let values = [
                ("time", 0.001 * (i + 1.0)),
                ("path_length", 20.0 + 2.0 * i),
                ("steep_turns", [2.0, 3.0, 3.0, 4.0, 5.0][seed as usize]),
                ("turns", 16.0 + 2.0 * i),
                ("curviness", [72.0, 76.0, 80.0, 88.0, 90.0][seed as usize]),
            ];
            for (metric, value) in values.into_iter().filter(|(m, _)| metrics.contains(m)) {
                rows.push(row("office", "rapier", "rrt", seed, metric, value, "r"));
            }
            rows.push(row("office", "rapier", "rrt", seed, "solved", 1.0, "r"));
        }
        rows.push(row("office", "rapier", "rrt", 5, "time", 50.0, "r"));
        rows.push(row("office", "rapier", "rrt", 5, "turns", 500.0, "r"));
        rows.push(row("office", "rapier", "rrt", 5, "solved", 0.0, "r"));
        rows.push(row("office", "rapier", "prm-valid", 0, "time", 0.01, "r"));
        rows.push(row("office", "rapier", "prm-valid", 0, "solved", 1.0, "r"));
        rows
    }

    /// The line of the table under heading `table` ("5.4") of the planner `label`.
    fn table_line<'a>(page: &'a str, table: &str, label: &str) -> &'a str {
        let start = page.find(&format!("### Table {table}:")).expect("the table's heading");
        let section = &page[start..];
        let end = section[4..].find("\n#").map_or(section.len(), |e| e + 4);
        section[..end]
            .lines()
            .find(|l| l.starts_with(&format!("| {label} |")))
            .unwrap_or_else(|| panic!("no row {label} in Table {table}: {section}"))
    }

    #[test]
    fn every_office_table_puts_the_thesis_beside_ours() {
        let all = ["time", "path_length", "steep_turns", "turns", "curviness"];
        let m = Matrix::from_rows(&office_rows(&all));
        let page = page(&m, "img/x.svg").unwrap();
        // The columns: polygon, bbox6d, trimesh, rapier (Bullet), pointcloud, solved.
        let bullet = |table: &str| {
            let line = table_line(&page, table, "RRT");
            line.split(" | ").nth(4).unwrap().to_owned()
        };
        // Table 5.3: median 3 ms against the thesis's Bullet RRT 4.721 ms.
        assert_eq!(bullet("5.3"), "3.00 ms / 4.72 ms (×0.635)");
        // Table 5.4: quartiles 2 and 4 ms over the median 3 ms, against .570/1.730.
        assert_eq!(bullet("5.4"), "0.667/1.333 / 0.570/1.730 (×1.17/×0.771)");
        // Table 5.5: median 24 m against 23.1608 m; 5.6: 22/24 and 26/24 against .904/1.060.
        assert_eq!(bullet("5.5"), "24.0 m / 23.2 m (×1.04)");
        assert_eq!(bullet("5.6"), "0.917/1.083 / 0.904/1.060 (×1.01/×1.02)");
        // Tables 5.7–5.9: steep turns 3, 3, 4 and turns 18, 20, 22 at the quartiles.
        assert_eq!(bullet("5.7"), "3/20/0.150 / 3/20/0.150 (×1.00/×1.00/×1.00)");
        assert_eq!(bullet("5.8"), "3/18/0.167 / 2/17/0.118 (×1.50/×1.06/×1.41)");
        assert_eq!(bullet("5.9"), "4/22/0.182 / 4/22/0.182 (×1.00/×1.00/×0.999)");
        // Tables 5.10, 5.11: median 80° against 78.0185°; 76/80 and 88/80 against .850/1.093.
        assert_eq!(bullet("5.10"), "80.0° / 78.0° (×1.03)");
        assert_eq!(bullet("5.11"), "0.950/1.100 / 0.850/1.093 (×1.12/×1.01)");
        for table in ["5.3", "5.4", "5.5", "5.6", "5.7", "5.8", "5.9", "5.10", "5.11"] {
            let line = table_line(&page, table, "RRT");
            assert!(line.ends_with("| – – – 5/6 – |"), "Table {table}: {line}");
            // A planner the thesis does not have: ours alone.
            let ours = table_line(&page, table, "PRM (valid samples)");
            assert!(!ours.contains(" / ") && !ours.contains('×'), "Table {table}: {ours}");
        }
        assert!(table_line(&page, "5.3", "PRM (valid samples)").contains("| 10.0 ms |"));
        // Each table explains itself and names the command that made the rows.
        assert_eq!(page.matches("\nMeasures ").count(), 9, "{page}");
        assert_eq!(page.matches("Command: `cargo xtask bench roadmap` (the thesis's").count(), 9);
        assert!(page.contains("(L6154–6166)") && page.contains("(L6386–6402)"), "{page}");
        assert!(page.contains("Simple 28/50, BB6D 28/50, Bullet 30/50"), "{page}");
        assert!(!page.contains("Not reproduced"), "{page}");
    }

    #[test]
    fn a_table_whose_metric_the_rows_lack_says_so() {
        let m = Matrix::from_rows(&office_rows(&["time", "path_length"]));
        let page = page(&m, "img/x.svg").unwrap();
        assert_eq!(bullet_of(&page, "5.3"), "3.00 ms / 4.72 ms (×0.635)");
        assert_eq!(bullet_of(&page, "5.6"), "0.917/1.083 / 0.904/1.060 (×1.01/×1.02)");
        // The unsolved run's turns must not count as the metric being there.
        let lacks = |metrics: &str| page.matches(&format!("carry no {metrics} metric")).count();
        assert_eq!(lacks("`steep_turns`, `turns`"), 3, "Tables 5.7–5.9: {page}");
        assert_eq!(lacks("`curviness`"), 2, "Tables 5.10, 5.11: {page}");
        assert_eq!(page.matches("Not reproduced").count(), 5);
        // No office rows at all: one note instead of the tables, the lab section still there.
        let lab = vec![
            row("lab", "polygon", "rrt", 0, "time_k500", 0.001, "r"),
            row("lab", "polygon", "rrt", 0, "solved", 0.0, "r"),
        ];
        let page = super::page(&Matrix::from_rows(&lab), "x.svg").unwrap();
        assert!(page.contains("hold no run of scene `office`"), "{page}");
        assert!(!page.contains("### Table") && page.contains("## Lab"), "{page}");
    }

    fn bullet_of(page: &str, table: &str) -> String {
        table_line(page, table, "RRT").split(" | ").nth(4).unwrap().to_owned()
    }

    #[test]
    fn the_lists_follow_the_thesis_and_the_planner_names() {
        // The thesis's five planners first, in its row order.
        let first: Vec<roadmap::PlannerKind> = PLANNERS[..5].iter().map(|(p, _)| *p).collect();
        let rows: Vec<roadmap::PlannerKind> =
            thesis::TABLE_5_3.rows.iter().map(|r| r.planner).collect();
        assert_eq!(first, rows);
        // Every planner of the crate has a row.
        for kind in roadmap::PlannerKind::ALL {
            assert!(PLANNERS.iter().any(|(p, _)| *p == kind), "{kind} has no row");
        }
        let columns: Vec<&str> = BACKENDS[..4].iter().map(|b| b.1).collect();
        assert_eq!(columns, thesis::OFFICE_COLUMNS);
    }
}
