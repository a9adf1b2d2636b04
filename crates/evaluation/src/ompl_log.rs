//! OMPL benchmark logs of the `roadmap` matrix, so Planner Arena and OMPL's
//! `ompl_benchmark_statistics.py` read our runs as they read OMPL's own.
//!
//! The layout is the text that `ompl::tools::Benchmark::saveResultsToStream` writes and the
//! statistics script parses line by line:
//!
//! ```text
//! patchnav version 0.0.0                     library and version (optional line)
//! Experiment office-polygon                  one token: the name is the last token
//! Running on HOST
//! Starting at 2026-11-22T05:30:00
//! <<<|                                       the set-up, free text
//! ...
//! |>>>
//! <<<|                                       the CPU (optional block)
//! ...
//! |>>>
//! 0 is the random seed
//! 1.25 seconds per run
//! 0 MB per run
//! 10 runs per planner
//! 12.5 seconds spent to collect the data
//! 1 enum type
//! status|Unknown status|Invalid start|...    enum name, then its values 0, 1, ...
//! 9 planners
//! geometric_RRT                              per planner: its name,
//! 3 common properties                        "name = value" lines,
//! backend STRING = polygon
//! ...
//! 11 properties for each run                 "name TYPE" lines (BOOLEAN, INTEGER, REAL, ENUM),
//! collision_checks INTEGER
//! ...
//! 10 runs                                    one line per run, every value followed by "; "
//! 5904; 60.2; ...;                           (an empty value is a missing one),
//! .                                          and "." (no progress properties)
//! ```
//!
//! Choices where our runs differ from OMPL's: the runs are capped by iterations, not time, so
//! the time limit is the longest run's time (an upper bound that held) and the set-up names the
//! cap; memory is not measured (0 MB); the seed line holds the first run's seed and every run
//! has its own `seed` property; planners are named `geometric_<OMPL-style name>` so Planner
//! Arena strips the prefix as for OMPL's.

use anyhow::{Context, Result};
use roadmap::PlannerKind;
use serde_json::Value;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// OMPL's planner status names (`ompl::base::PlannerStatus::asString`), in enum order.
pub const STATUS_NAMES: [&str; 9] = [
    "Unknown status",
    "Invalid start",
    "Invalid goal",
    "Unrecognized goal type",
    "Timeout",
    "Approximate solution",
    "Exact solution",
    "Crash",
    "Abort",
];

/// The value of OMPL's status enum for the matrix's `status` key.
pub fn status_value(status: &str) -> usize {
    match status {
        "invalid-start" => 1,
        "invalid-goal" => 2,
        "timeout" => 4,
        "approximate" => 5,
        "exact" => 6,
        _ => 0,
    }
}

/// The OMPL-style name of a matrix planner (`rrt-star` → `geometric_RRTstar`); a name that is
/// no [`PlannerKind`]'s keeps its letters and digits.
pub fn planner_name(planner: &str) -> String {
    let name: &str = match planner.parse() {
        Ok(kind) => ompl_name(kind),
        Err(_) => planner,
    };
    format!("geometric_{}", name.replace(|c: char| !c.is_ascii_alphanumeric(), "_"))
}

/// The OMPL-style name of `kind` (OMPL's own where it has the planner).
fn ompl_name(kind: PlannerKind) -> &'static str {
    match kind {
        PlannerKind::Rrt => "RRT",
        PlannerKind::RrtStar => "RRTstar",
        PlannerKind::RrtConnect => "RRTConnect",
        PlannerKind::Prm => "PRM",
        PlannerKind::PrmStar => "PRMstar",
        PlannerKind::LazyPrm => "LazyPRM",
        PlannerKind::EvasionRrt => "EvasionRRT",
        PlannerKind::MaPrm => "MAPRM",
        PlannerKind::MaRrt => "MARRT",
        // OMPL's PRM builds this roadmap; the name tells them apart.
        PlannerKind::PrmValid => kind.name(),
    }
}

/// A run property: the matrix metric, the OMPL property name and its type.
const PROPERTIES: [(&str, &str, &str); 13] = [
    ("time", "time", "REAL"),
    ("time_k100", "time_k100", "REAL"),
    ("time_k500", "time_k500", "REAL"),
    ("solved", "solved", "BOOLEAN"),
    ("iterations", "iterations", "INTEGER"),
    ("vertices", "graph_states", "INTEGER"),
    ("collision_checks", "collision_checks", "INTEGER"),
    ("path_length", "solution_length", "REAL"),
    ("turns", "turns", "INTEGER"),
    ("steep_turns", "steep_turns", "INTEGER"),
    ("curviness", "curviness", "REAL"),
    ("seed", "seed", "INTEGER"),
    ("status", "status", "ENUM"),
];

/// The runs of one planner: seed → metric → value (the status as its enum value).
pub type Runs = BTreeMap<u64, BTreeMap<String, f64>>;

/// One experiment (one log file): the runs of every planner on one scene and backend.
#[derive(Clone, Debug, PartialEq)]
pub struct Experiment {
    /// `scene-backend`.
    pub name: String,
    /// Host, date, set-up text, CPU, library version.
    pub host: String,
    /// ISO date of the first run.
    pub date: String,
    /// Free text: scene, backend, caps, provenance.
    pub setup: String,
    /// The CPU model.
    pub cpu: String,
    /// The library's version.
    pub version: String,
    /// The first seed.
    pub seed: u64,
    /// Per planner (matrix name), per seed, per metric: the value (status as its enum value).
    pub planners: BTreeMap<String, Runs>,
}

/// The keys of one row of the planning matrix (`bench-matrix roadmap`): the case and one
/// metric's value.
pub struct MatrixRow {
    /// Scene of the case.
    pub scene: String,
    /// Backend of the case.
    pub backend: String,
    /// Planner of the case.
    pub planner: String,
    /// The metric's name.
    pub metric: String,
    /// Seed of the case.
    pub seed: u64,
    /// The metric's value.
    pub value: f64,
}

impl MatrixRow {
    /// The keys of `r`, or `None` when one is missing or of the wrong type.
    pub fn of(r: &Value) -> Option<MatrixRow> {
        let s = |k: &str| r.get(k).and_then(Value::as_str).map(str::to_owned);
        Some(MatrixRow {
            scene: s("scene")?,
            backend: s("backend")?,
            planner: s("planner")?,
            metric: s("metric")?,
            seed: r.get("seed").and_then(Value::as_u64)?,
            value: r.get("value").and_then(Value::as_f64)?,
        })
    }
}

/// Groups the matrix rows (bench `roadmap`) by scene and backend; a later row of a case and
/// metric replaces an earlier one.
pub fn experiments(rows: &[Value]) -> Vec<Experiment> {
    let mut out: BTreeMap<(String, String), Experiment> = BTreeMap::new();
    for r in rows.iter().filter(|r| r.get("bench").and_then(Value::as_str) == Some("roadmap")) {
        let s = |k: &str| r.get(k).and_then(Value::as_str).map(str::to_owned);
        let Some(MatrixRow { scene, backend, planner, metric, seed, value }) = MatrixRow::of(r)
        else {
            continue;
        };
        let p = |k: &str| {
            r.pointer(&format!("/provenance/{k}"))
                .and_then(Value::as_str)
                .unwrap_or("UNKNOWN")
                .to_owned()
        };
        let e = out.entry((scene.clone(), backend.clone())).or_insert_with(|| Experiment {
            name: format!("{scene}-{backend}"),
            host: p("host"),
            date: p("date").trim_end_matches('Z').to_owned(),
            setup: format!(
                "scene {scene}, backend {backend}, mode {}, iteration cap {} (no time limit)\n\
                 git revision {}, rustc {}, {} cores\n",
                s("mode").unwrap_or_default(),
                r.get("max_iterations").and_then(Value::as_u64).unwrap_or(0),
                p("git_revision"),
                p("rustc"),
                r.pointer("/provenance/cores").and_then(Value::as_u64).unwrap_or(0),
            ),
            cpu: p("cpu"),
            version: s("tool").unwrap_or_default().trim_start_matches("patchnav-").to_owned(),
            seed,
            planners: BTreeMap::new(),
        });
        e.seed = e.seed.min(seed);
        let run = e.planners.entry(planner).or_default().entry(seed).or_default();
        run.insert(metric, value);
        run.insert("seed".into(), seed as f64);
        if let Some(status) = s("status") {
            run.insert("status".into(), status_value(&status) as f64);
        }
    }
    out.into_values().collect()
}

/// A value as the log holds it: integers and booleans without a fraction.
fn value_text(x: f64, kind: &str) -> String {
    match kind {
        "INTEGER" | "BOOLEAN" | "ENUM" => format!("{}", x.round() as i64),
        _ => format!("{x}"),
    }
}

/// The log text of one experiment.
pub fn format_log(e: &Experiment) -> String {
    let mut out = String::new();
    let runs = |p: &Runs| p.values().cloned().collect::<Vec<_>>();
    let all: Vec<BTreeMap<String, f64>> = e.planners.values().flat_map(runs).collect();
    let time = |r: &BTreeMap<String, f64>| r.get("time").copied().unwrap_or(0.0);
    let longest = all.iter().map(time).fold(0.0, f64::max);
    let total: f64 = all.iter().map(time).sum();
    let run_count = e.planners.values().map(BTreeMap::len).max().unwrap_or(0);
    let one_token = |s: &str| s.split_whitespace().collect::<Vec<_>>().join("_");
    let _ = writeln!(out, "patchnav version {}", one_token(&e.version));
    let _ = writeln!(out, "Experiment {}", one_token(&e.name));
    let _ = writeln!(out, "Running on {}", one_token(&e.host));
    let _ = writeln!(out, "Starting at {}", e.date);
    let _ = write!(out, "<<<|\n{}|>>>\n", e.setup);
    let _ = write!(out, "<<<|\n{}\n|>>>\n", e.cpu);
    let _ = writeln!(out, "{} is the random seed", e.seed);
    let _ = writeln!(out, "{longest} seconds per run");
    let _ = writeln!(out, "0 MB per run");
    let _ = writeln!(out, "{run_count} runs per planner");
    let _ = writeln!(out, "{total} seconds spent to collect the data");
    let _ = writeln!(out, "1 enum type");
    let _ = writeln!(out, "status|{}", STATUS_NAMES.join("|"));
    let _ = writeln!(out, "{} planners", e.planners.len());
    for (planner, seeds) in &e.planners {
        let _ = writeln!(out, "{}", planner_name(planner));
        let _ = writeln!(out, "1 common properties");
        let _ = writeln!(out, "planner STRING = {planner}");
        // The properties any run of this planner has, sorted by name as OMPL sorts them.
        let mut props: Vec<(&str, &str, &str)> = PROPERTIES
            .iter()
            .copied()
            .filter(|(m, _, _)| seeds.values().any(|r| r.contains_key(*m)))
            .collect();
        props.sort_by_key(|p| p.1);
        let _ = writeln!(out, "{} properties for each run", props.len());
        for (_, name, kind) in &props {
            let _ = writeln!(out, "{name} {kind}");
        }
        let _ = writeln!(out, "{} runs", seeds.len());
        for run in seeds.values() {
            for (metric, _, kind) in &props {
                if let Some(x) = run.get(*metric).filter(|x| x.is_finite()) {
                    out.push_str(&value_text(*x, kind));
                }
                out.push_str("; ");
            }
            out.push('\n');
        }
        out.push_str(".\n");
    }
    out
}

/// Writes one log per scene and backend into `dir` (`<scene>-<backend>.log`); returns the paths.
pub fn write_logs(rows: &[Value], dir: &Path) -> Result<Vec<PathBuf>> {
    let exps = experiments(rows);
    if exps.is_empty() {
        return Ok(Vec::new());
    }
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    exps.iter()
        .map(|e| {
            let path = dir.join(format!("{}.log", e.name));
            pointcloud::io::write_bytes_atomically(&path, format_log(e))?;
            Ok(path)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn rows() -> Vec<Value> {
        let prov = json!({"host": "box one", "date": "2026-11-22T05:30:00Z", "git_revision": "abc", "cpu": "X"});
        let mut rows = Vec::new();
        for (planner, seed, solved) in [("rrt", 0, true), ("rrt", 1, false), ("ma-prm", 0, true)] {
            let mut metrics = vec![
                ("time", 0.5 + seed as f64),
                ("iterations", 120.0),
                ("solved", f64::from(solved)),
            ];
            if solved {
                metrics.push(("path_length", 54.25));
            }
            for (metric, value) in metrics {
                rows.push(json!({
                    "bench": "roadmap", "case": format!("office/polygon/{planner}/{seed}"), "metric": metric,
                    "value": value, "scene": "office", "backend": "polygon", "planner": planner, "seed": seed,
                    "status": if solved { "exact" } else { "approximate" }, "mode": "roi",
                    "max_iterations": 100000, "tool": "patchnav-0.0.0", "provenance": prov,
                }));
            }
        }
        rows.push(json!({"bench": "tof", "case": "x", "metric": "time", "value": 1.0}));
        rows
    }

    /// Parses a log by the rules of OMPL's statistics script: returns (experiment name, host,
    /// per planner: property names with types and the runs' values).
    #[allow(clippy::type_complexity)]
    fn parse(
        log: &str,
    ) -> (String, String, Vec<(String, Vec<(String, String)>, Vec<Vec<Option<String>>>)>) {
        let mut lines = log.lines().peekable();
        let last = |l: &str| l.split_whitespace().last().unwrap().to_owned();
        let first = lines.next().unwrap();
        assert_eq!(first.split_whitespace().nth(1), Some("version"));
        let exp = lines.next().unwrap();
        assert!(exp.starts_with("Experiment "));
        let name = last(exp);
        let host_line = lines.next().unwrap();
        assert!(host_line.starts_with("Running on "));
        assert!(lines.next().unwrap().starts_with("Starting at "));
        for _ in 0..2 {
            assert_eq!(lines.next(), Some("<<<|"));
            while lines.next().unwrap() != "|>>>" {}
        }
        for suffix in [
            "is the random seed",
            "seconds per run",
            "MB per run",
            "runs per planner",
            "seconds spent to collect the data",
        ] {
            let l = lines.next().unwrap();
            assert!(l.ends_with(suffix), "{l}");
            l.split_whitespace().next().unwrap().parse::<f64>().unwrap();
        }
        let enums: usize =
            lines.next().unwrap().split_whitespace().next().unwrap().parse().unwrap();
        for _ in 0..enums {
            assert!(lines.next().unwrap().contains('|'));
        }
        let planners_line = lines.next().unwrap();
        assert!(planners_line.ends_with(" planners"));
        let n: usize = planners_line.split_whitespace().next().unwrap().parse().unwrap();
        let mut planners = Vec::new();
        for _ in 0..n {
            let pname = lines.next().unwrap().to_owned();
            let common: usize =
                lines.next().unwrap().split_whitespace().next().unwrap().parse().unwrap();
            for _ in 0..common {
                assert!(lines.next().unwrap().contains(" = "));
            }
            let nprops: usize =
                lines.next().unwrap().split_whitespace().next().unwrap().parse().unwrap();
            let props: Vec<(String, String)> = (0..nprops)
                .map(|_| {
                    let f: Vec<&str> = lines.next().unwrap().split_whitespace().collect();
                    let kind = f.last().unwrap().to_string();
                    assert!(
                        ["BOOLEAN", "INTEGER", "REAL", "ENUM", "STRING"].contains(&kind.as_str())
                    );
                    (f[..f.len() - 1].join("_"), kind)
                })
                .collect();
            let nruns: usize =
                lines.next().unwrap().split_whitespace().next().unwrap().parse().unwrap();
            let runs: Vec<Vec<Option<String>>> = (0..nruns)
                .map(|_| {
                    let line = format!("{}\n", lines.next().unwrap());
                    let parts: Vec<&str> = line.split("; ").collect();
                    parts[..parts.len() - 1]
                        .iter()
                        .map(|x| (!x.is_empty()).then(|| x.to_string()))
                        .collect()
                })
                .collect();
            assert_eq!(lines.next().map(str::trim), Some("."));
            planners.push((pname, props, runs));
        }
        assert!(lines.next().is_none());
        (name, last(host_line), planners)
    }

    #[test]
    fn log_parses_by_ompls_rules() {
        let exps = experiments(&rows());
        assert_eq!(exps.len(), 1, "one scene and backend; the tof row is ignored");
        let log = format_log(&exps[0]);
        let (name, host, planners) = parse(&log);
        assert_eq!(name, "office-polygon");
        assert_eq!(host, "box_one", "the host is one token");
        assert_eq!(planners.len(), 2);
        let (pname, props, runs) = &planners[1];
        assert_eq!(pname, "geometric_RRT");
        let names: Vec<&str> = props.iter().map(|p| p.0.as_str()).collect();
        let mut sorted = names.clone();
        sorted.sort();
        assert_eq!(names, sorted, "properties sorted as OMPL sorts them");
        assert_eq!(runs.len(), 2);
        for run in runs {
            assert_eq!(run.len(), props.len(), "one value per property");
        }
        let col = |n: &str| names.iter().position(|x| *x == n).unwrap();
        assert_eq!(runs[0][col("solution_length")].as_deref(), Some("54.25"));
        assert_eq!(runs[1][col("solution_length")], None, "an unsolved run has no length");
        assert_eq!(runs[1][col("solved")].as_deref(), Some("0"));
        assert_eq!(runs[0][col("status")].as_deref(), Some("6"));
        assert_eq!(runs[1][col("status")].as_deref(), Some("5"));
        assert_eq!(STATUS_NAMES[6], "Exact solution");
        assert!(log.contains("\n1.5 seconds per run\n"), "the longest run bounds the time");
        assert!(log.contains("\n2 runs per planner\n"));
    }

    #[test]
    fn later_rows_replace_earlier_ones() {
        let mut r = rows();
        let mut again = r[0].clone();
        again["value"] = json!(9.0);
        r.push(again);
        let e = &experiments(&r)[0];
        assert_eq!(e.planners["rrt"][&0]["time"], 9.0);
        assert_eq!(planner_name("rrt-star"), "geometric_RRTstar");
        assert_eq!(planner_name("odd name"), "geometric_odd_name");
    }
}
