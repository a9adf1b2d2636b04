//! `cargo xtask docs`: generates `docs/benchmarks.md` (and its plot, `docs/img/`) from the rows
//! of the `roadmap` matrix in `target/bench/results.jsonl`.
//!
//! The page holds every thesis table the matrix reproduces — Table 5.3 (median time to reach the
//! four ROIs of the office) and Table 5.5 (median added path length) per planner and backend,
//! and the lab RRT time per map at K = 500 (Fig 6.4, whose numbers the thesis gives only as
//! bounds in its prose, L6813–6818) — with the thesis's figure beside ours and the ratio
//! ours / thesis, one SVG plot, the provenance of the rows used and the command that made them.
//!
//! Rows used: those of the git revision of the last matrix row in the file; of several rows of
//! one case and metric the last one. Medians and quartiles are over the successful runs, as in
//! the thesis (L6119–6121), interpolated between closest ranks (Hyndman & Fan type 7, the method
//! of `roadmap::metrics::quantile`).

mod lab;

use anyhow::{Context, Result, bail};
use lab::lab_table;
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::PathBuf;

/// The matrix's backends in the thesis's column order, with the thesis's name for each.
const BACKENDS: [(&str, &str); 5] = [
    ("polygon", "Simple"),
    ("bbox6d", "BB6D"),
    ("trimesh", "OPCODE"),
    ("rapier", "Bullet"),
    ("pointcloud", "–"),
];
/// The matrix's planners, the thesis's five first, with their labels.
const PLANNERS: [(&str, &str); 9] = [
    ("rrt", "RRT"),
    ("ma-rrt", "MA RRT"),
    ("evasion-rrt", "Ev. RRT"),
    ("prm", "PRM"),
    ("ma-prm", "MA PRM"),
    ("rrt-connect", "RRT-Connect"),
    ("prm-star", "PRM*"),
    ("lazy-prm", "lazy PRM"),
    ("rrt-star", "RRT*"),
];

/// Thesis Table 5.3, median wall time in s (L6154–6166): Simple, BB6D, OPCODE, Bullet.
const THESIS_5_3: [(&str, [Option<f64>; 4]); 5] = [
    ("rrt", [Some(0.010057), Some(0.006137), Some(0.002435), Some(0.004721)]),
    ("ma-rrt", [Some(0.124055), Some(0.060409), None, Some(0.055298)]),
    ("evasion-rrt", [Some(0.18627), Some(0.156209), None, Some(0.099351)]),
    ("prm", [Some(0.013578), Some(0.010544), Some(0.001309), Some(0.008801)]),
    ("ma-prm", [Some(1.96683), Some(1.20087), None, Some(0.678831)]),
];
/// Thesis Table 5.5, median added path length in m (L6220–6232).
const THESIS_5_5: [(&str, [Option<f64>; 4]); 5] = [
    ("rrt", [Some(23.1608), Some(23.1608), Some(21.5803), Some(23.1608)]),
    ("ma-rrt", [Some(22.166), Some(22.3942), None, Some(22.1411)]),
    ("evasion-rrt", [Some(25.7439), Some(26.621), None, Some(26.621)]),
    ("prm", [Some(41.3277), Some(41.3277), Some(40.2935), Some(41.3277)]),
    ("ma-prm", [Some(66.0655), Some(64.6227), None, Some(68.2961)]),
];

/// Linear interpolation between closest ranks (type 7); `None` for no values.
pub fn quantile(values: &[f64], p: f64) -> Option<f64> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() || !(0.0..=1.0).contains(&p) {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let h = (v.len() - 1) as f64 * p;
    let (lo, hi) = (h.floor() as usize, h.ceil() as usize);
    Some(v[lo] + (h - lo as f64) * (v[hi] - v[lo]))
}

/// The runs of one cell: seed → metric → value.
pub type Runs = BTreeMap<u64, BTreeMap<String, f64>>;

/// The matrix rows of one revision, reduced to per-case metrics.
#[derive(Debug, Default)]
pub struct Matrix {
    /// (scene, backend, planner) → seed → metric → value.
    pub cells: BTreeMap<(String, String, String), Runs>,
    /// The rows used.
    pub rows: usize,
    /// The git revision, and whether any row came from a modified tree.
    pub revision: String,
    pub dirty: bool,
    /// Distinct hosts, CPUs, rustc versions, worker counts, commands; first and last date.
    pub hosts: BTreeSet<String>,
    pub cpus: BTreeSet<String>,
    pub rustc: BTreeSet<String>,
    pub jobs: BTreeSet<u64>,
    pub commands: BTreeSet<String>,
    pub dates: (String, String),
}

impl Matrix {
    /// The rows of bench `roadmap` of the last such row's revision.
    pub fn from_rows(rows: &[Value]) -> Matrix {
        let rev = |r: &Value| {
            r.pointer("/provenance/git_revision").and_then(Value::as_str).unwrap_or("").to_owned()
        };
        let ours: Vec<&Value> = rows
            .iter()
            .filter(|r| r.get("bench").and_then(Value::as_str) == Some("roadmap"))
            .collect();
        let mut m = Matrix {
            revision: ours.last().map(|r| rev(r)).unwrap_or_default(),
            ..Matrix::default()
        };
        for r in ours.into_iter().filter(|r| rev(r) == m.revision) {
            let s = |k: &str| r.get(k).and_then(Value::as_str).map(str::to_owned);
            let p = |k: &str| {
                r.pointer(&format!("/provenance/{k}")).and_then(Value::as_str).map(str::to_owned)
            };
            let (Some(scene), Some(backend), Some(planner), Some(metric), Some(seed), Some(value)) = (
                s("scene"),
                s("backend"),
                s("planner"),
                s("metric"),
                r.get("seed").and_then(Value::as_u64),
                r.get("value").and_then(Value::as_f64),
            ) else {
                continue;
            };
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
    fn values(&self, scene: &str, backend: &str, planner: &str, metric: &str) -> Vec<f64> {
        let Some(runs) = self.cells.get(&(scene.into(), backend.into(), planner.into())) else {
            return Vec::new();
        };
        runs.values()
            .filter(|r| scene != "office" || r.get("solved") == Some(&1.0))
            .filter_map(|r| r.get(metric).copied())
            .collect()
    }

    /// "solved/runs" of a cell, or `None` if it has no runs.
    fn solved(&self, scene: &str, backend: &str, planner: &str) -> Option<(usize, usize)> {
        let runs = self.cells.get(&(scene.into(), backend.into(), planner.into()))?;
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

/// One cell "ours / thesis (×ratio)".
fn cell(ours: Option<f64>, thesis: Option<f64>, fmt: fn(f64) -> String) -> String {
    match (ours, thesis) {
        (None, _) => "–".into(),
        (Some(o), None) => fmt(o),
        (Some(o), Some(t)) => format!("{} / {} (×{})", fmt(o), fmt(t), sig3(o / t)),
    }
}

/// A table of the office: planners × backends, cells "ours / thesis (×ratio)".
fn office_table(
    m: &Matrix,
    metric: &str,
    thesis: &[(&str, [Option<f64>; 4])],
    fmt: fn(f64) -> String,
) -> String {
    let mut out = String::from("| planner |");
    let mut rule = String::from("|---|");
    for (b, t) in BACKENDS {
        if t == "–" {
            let _ = write!(out, " {b} |");
        } else {
            let _ = write!(out, " {b} ({t}) |");
        }
        rule.push_str("---|");
    }
    out.push_str(" solved |\n");
    out.push_str(&rule);
    out.push_str("---|\n");
    for (p, label) in PLANNERS {
        if !BACKENDS.iter().any(|(b, _)| m.solved("office", b, p).is_some()) {
            continue;
        }
        let _ = write!(out, "| {label} |");
        let mut solved = Vec::new();
        for (i, (b, _)) in BACKENDS.iter().enumerate() {
            let t = thesis.iter().find(|r| r.0 == p).and_then(|r| r.1.get(i).copied().flatten());
            let ours = quantile(&m.values("office", b, p, metric), 0.5);
            let _ = write!(
                out,
                " {} |",
                if m.solved("office", b, p).is_some() { cell(ours, t, fmt) } else { "–".into() }
            );
            solved.push(m.solved("office", b, p).map_or("–".into(), |(s, n)| format!("{s}/{n}")));
        }
        let _ = writeln!(out, " {} |", solved.join(" "));
    }
    out
}

/// The plot: median office time per planner (groups) and backend (bars) on a log axis, the
/// thesis's Table 5.3 as black ticks on the bars of its four columns.
pub fn office_time_svg(m: &Matrix) -> String {
    let planners: Vec<(&str, &str)> = PLANNERS
        .iter()
        .copied()
        .filter(|(p, _)| BACKENDS.iter().any(|(b, _)| m.solved("office", b, p).is_some()))
        .collect();
    let colours = ["#4e79a7", "#f28e2b", "#59a14f", "#e15759", "#9c755f"];
    let mut values = Vec::new();
    for (p, _) in &planners {
        for (b, _) in BACKENDS {
            values.extend(quantile(&m.values("office", b, p, "time"), 0.5));
        }
    }
    values.extend(THESIS_5_3.iter().flat_map(|r| r.1.iter().flatten().copied()));
    let positive: Vec<f64> = values.into_iter().filter(|v| *v > 0.0).collect();
    let lo = positive.iter().copied().fold(f64::INFINITY, f64::min).log10().floor().min(-3.0);
    let hi =
        positive.iter().copied().fold(f64::NEG_INFINITY, f64::max).log10().ceil().max(lo + 1.0);
    let (w, h, left, top, bottom) = (960.0, 440.0, 70.0, 40.0, 90.0);
    let plot_h = h - top - bottom;
    let group = (w - left - 20.0) / planners.len().max(1) as f64;
    let bar = group * 0.8 / BACKENDS.len() as f64;
    let y = |v: f64| top + plot_h * (hi - v.log10()) / (hi - lo);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(s, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="20" text-anchor="middle" font-size="14">Office (thesis §5.5.3): median time to reach the four ROIs, log scale; black ticks: thesis Table 5.3</text>"#,
        w / 2.0
    );
    let mut d = lo;
    while d <= hi + 1e-9 {
        let yy = y(10f64.powf(d));
        let _ = writeln!(
            s,
            r##"<line x1="{left}" y1="{yy:.1}" x2="{}" y2="{yy:.1}" stroke="#ddd"/>"##,
            w - 20.0
        );
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{:.1}" text-anchor="end">{}</text>"#,
            left - 6.0,
            yy + 4.0,
            time_text(10f64.powf(d))
        );
        d += 1.0;
    }
    for (g, (p, label)) in planners.iter().enumerate() {
        let x0 = left + g as f64 * group + group * 0.1;
        for (i, (b, _)) in BACKENDS.iter().enumerate() {
            let x = x0 + i as f64 * bar;
            if let Some(v) = quantile(&m.values("office", b, p, "time"), 0.5).filter(|v| *v > 0.0) {
                let yy = y(v);
                let _ = writeln!(
                    s,
                    r#"<rect x="{x:.1}" y="{yy:.1}" width="{:.1}" height="{:.1}" fill="{}"><title>{label} on {b}: {}</title></rect>"#,
                    bar * 0.9,
                    (top + plot_h - yy).max(0.0),
                    colours[i],
                    time_text(v)
                );
            }
            let thesis =
                THESIS_5_3.iter().find(|r| r.0 == *p).and_then(|r| r.1.get(i).copied().flatten());
            if let Some(t) = thesis {
                let yy = y(t);
                let _ = writeln!(
                    s,
                    r#"<line x1="{x:.1}" y1="{yy:.1}" x2="{:.1}" y2="{yy:.1}" stroke="black" stroke-width="3"><title>thesis {label} on {}: {}</title></line>"#,
                    x + bar * 0.9,
                    BACKENDS[i].1,
                    time_text(t)
                );
            }
        }
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{label}</text>"#,
            left + g as f64 * group + group / 2.0,
            top + plot_h + 18.0
        );
    }
    for (i, (b, t)) in BACKENDS.iter().enumerate() {
        let x = left + i as f64 * 170.0;
        let yy = h - 30.0;
        let name = if *t == "–" { b.to_string() } else { format!("{b} ({t})") };
        let _ = writeln!(
            s,
            r#"<rect x="{x}" y="{}" width="12" height="12" fill="{}"/>"#,
            yy - 10.0,
            colours[i]
        );
        let _ = writeln!(s, r#"<text x="{}" y="{yy}">{name}</text>"#, x + 16.0);
    }
    s.push_str("</svg>\n");
    s
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
    writeln!(
        o,
        "| git revision | `{}`{} |",
        m.revision,
        if m.dirty { " (modified tree)" } else { "" }
    )?;
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

    writeln!(o, "## Office: Table 5.3, median time to reach the four ROIs (thesis §5.5.3)\n")?;
    writeln!(
        o,
        "The shared floor plan (20 × 15 × 2.5 m), robot radius 0.3 m, step 1 m, one growing tree or \
         roadmap from the centre to the four corner rooms, at most 100,000 iterations. Cells: ours \
         / thesis (×ours/thesis); the thesis's columns are Simple, BB6D, OPCODE and Bullet, in the \
         roles of our polygon, bbox6d, trimesh and rapier maps. `solved`: runs that reached all four \
         ROIs per backend.\n\nCommand: `cargo xtask bench roadmap --scene office` (the thesis's 50 \
         runs: `--seeds 50`), then `cargo xtask docs`.\n"
    )?;
    o.push_str(&office_table(m, "time", &THESIS_5_3, time_text));
    writeln!(o, "\n![median office time per planner and backend]({svg_name})\n")?;
    writeln!(o, "## Office: Table 5.5, median added length of the paths to the ROIs\n")?;
    writeln!(
        o,
        "The sum of the four paths' lengths, start to each ROI (a shared prefix counted per path). \
         Our floor plan is the shared benchmark's, not the thesis's (whose dimensions are lost), so \
         lengths compare relatively.\n\nCommand: as Table 5.3 (the same runs).\n"
    )?;
    o.push_str(&office_table(m, "path_length", &THESIS_5_5, |x| format!("{} m", sig3(x))));
    writeln!(o, "\n## Lab: RRT time per map (thesis §6.1, Fig 6.4)\n")?;
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
    let med = |b: &str| quantile(&m.values("lab", b, "rrt", "time_k500"), 0.5);
    let fastest = BACKENDS[..4]
        .iter()
        .filter_map(|(b, _)| Some((med(b)?, *b)))
        .min_by(|x, y| x.0.total_cmp(&y.0));
    if let (Some(pc), Some((patch, name))) = (med("pointcloud"), fastest) {
        writeln!(
            o,
            "\nRRT at K = 500, point-cloud map / fastest patch map ({name}): ours ×{}; thesis: \"more than \
             an order of magnitude slower\" (L6784–6785; > 4 s against < 0.4 s, so > ×10).",
            sig3(pc / patch)
        )?;
    }
    Ok(o)
}

/// Runs `cargo xtask docs [--results FILE] [--out FILE]`.
pub fn run(args: &[String]) -> Result<()> {
    let root = crate::project_root();
    let mut results = root.join("target/bench/results.jsonl");
    let mut out = root.join("docs/benchmarks.md");
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--results" => results = PathBuf::from(it.next().context("--results needs a path")?),
            "--out" => out = PathBuf::from(it.next().context("--out needs a path")?),
            other => bail!("docs takes --results FILE and --out FILE, not `{other}`"),
        }
    }
    let text = std::fs::read_to_string(&results)
        .with_context(|| format!("reading {}", results.display()))?;
    let rows: Vec<Value> = text.lines().filter_map(|l| serde_json::from_str(l).ok()).collect();
    let m = Matrix::from_rows(&rows);
    let dir = out.parent().context("--out has no folder")?;
    let img = dir.join("img");
    std::fs::create_dir_all(&img).with_context(|| format!("creating {}", img.display()))?;
    let svg = img.join("benchmarks-office-time.svg");
    std::fs::write(&svg, office_time_svg(&m))
        .with_context(|| format!("writing {}", svg.display()))?;
    std::fs::write(&out, page(&m, "img/benchmarks-office-time.svg")?)
        .with_context(|| format!("writing {}", out.display()))?;
    println!("wrote {} and {} from {} rows", out.display(), svg.display(), m.rows);
    Ok(())
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
        assert!(page.contains("`new`") && !page.contains("100 s"));
        assert!(page.contains("fastest patch map (polygon): ours ×50.0"), "{page}");
        let svg = office_time_svg(&m);
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("RRT on rapier: 4.50 ms"));
        assert!(page_of_nothing_fails());
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
        assert_eq!(cell(None, Some(1.0), sig3), "–");
        assert_eq!(cell(Some(2.0), None, sig3), "2.00");
    }
}
