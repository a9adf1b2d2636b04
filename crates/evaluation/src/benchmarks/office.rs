//! The office part of `docs/benchmarks.md`: thesis §5.5.3 Tables 5.3–5.11 from the matrix
//! rows of scene `office`, each cell ours / thesis (×ours/thesis), and the plot of Table 5.3.
//!
//! The thesis's figures come from [`crate::thesis`]. A run's metrics are those
//! `bench-matrix` writes for a run that reached all four ROIs: `time` (s), `path_length` (the
//! added length of the four paths, m), `turns` and `steep_turns` (sums over the four paths),
//! `curviness` (the upper quartile of the turn angles of the four paths pooled, °). Tables 5.7–5.9
//! take the quantile of steep turns and of all turns separately and print their quotient, as
//! the thesis's figures show (3/20 = .150); 0 where a run has no turns.

use super::{BACKENDS, Matrix, PLANNERS, quantile, sig3, time_text};
use crate::thesis::{self, OfficeTable, QuartileRatios, Turns};
use patch_map::Backend;
use roadmap::PlannerKind;
use std::fmt::Write as _;

/// How the cells of a table are made from the runs and from the thesis.
#[derive(Copy, Clone)]
enum Measure {
    /// The median of a metric, printed with `fmt`.
    Median { metric: &'static str, thesis: &'static OfficeTable<f64>, fmt: fn(f64) -> String },
    /// Lower and upper quartile of a metric as ratios to its median.
    Quartiles { metric: &'static str, thesis: &'static OfficeTable<QuartileRatios> },
    /// Steep turns / turns / ratio at quantile `p`.
    Turns { p: f64, thesis: &'static OfficeTable<Turns> },
}

impl Measure {
    /// The metrics of a run the measure needs.
    fn metrics(self) -> Vec<&'static str> {
        match self {
            Measure::Median { metric, .. } | Measure::Quartiles { metric, .. } => vec![metric],
            Measure::Turns { .. } => vec!["steep_turns", "turns"],
        }
    }

    fn thesis_number(self) -> &'static str {
        match self {
            Measure::Median { thesis, .. } => thesis.number,
            Measure::Quartiles { thesis, .. } => thesis.number,
            Measure::Turns { thesis, .. } => thesis.number,
        }
    }

    fn thesis_caption_lines(self) -> (&'static str, [u32; 2]) {
        match self {
            Measure::Median { thesis, .. } => (thesis.caption, thesis.lines),
            Measure::Quartiles { thesis, .. } => (thesis.caption, thesis.lines),
            Measure::Turns { thesis, .. } => (thesis.caption, thesis.lines),
        }
    }
}

/// One section of the page: a thesis table and what it measures, in one line.
struct Section {
    measure: Measure,
    what: &'static str,
}

fn metres(x: f64) -> String {
    format!("{} m", sig3(x))
}

fn degrees(x: f64) -> String {
    format!("{}°", sig3(x))
}

/// The sections, in the thesis's order.
const SECTIONS: [Section; 9] = [
    Section {
        measure: Measure::Median { metric: "time", thesis: &thesis::TABLE_5_3, fmt: time_text },
        what: "the median wall time of `solve` until the one growing tree or roadmap has reached \
               all four ROIs.",
    },
    Section {
        measure: Measure::Quartiles { metric: "time", thesis: &thesis::TABLE_5_4 },
        what: "the spread of that time: its lower and upper quartile divided by its median \
               (lower/upper); the ratio is given for each.",
    },
    Section {
        measure: Measure::Median { metric: "path_length", thesis: &thesis::TABLE_5_5, fmt: metres },
        what: "the sum of the four paths' lengths, start to each ROI (a shared prefix counted per \
               path). Our floor plan is the shared benchmark's, not the thesis's (whose dimensions \
               are lost), so lengths compare relatively.",
    },
    Section {
        measure: Measure::Quartiles { metric: "path_length", thesis: &thesis::TABLE_5_6 },
        what: "the spread of the added length: lower and upper quartile over the median \
               (lower/upper).",
    },
    Section {
        measure: Measure::Turns { p: 0.5, thesis: &thesis::TABLE_5_7 },
        what: "the median number of steep turns (> 90°) / the median number of turns / their \
               quotient, counted over the four paths of a run (the thesis's RRT median of 20 turns \
               on 23 m of added length fits a sum over the four paths); the ratio is given for each.",
    },
    Section {
        measure: Measure::Turns { p: 0.25, thesis: &thesis::TABLE_5_8 },
        what: "Table 5.7 at the lower quartile: lower quartile of steep turns / of all turns / \
               their quotient.",
    },
    Section {
        measure: Measure::Turns { p: 0.75, thesis: &thesis::TABLE_5_9 },
        what: "Table 5.7 at the upper quartile: upper quartile of steep turns / of all turns / \
               their quotient.",
    },
    Section {
        measure: Measure::Median { metric: "curviness", thesis: &thesis::TABLE_5_10, fmt: degrees },
        what: "the median curviness, the upper quartile of the turn angles at the interior \
               vertices of a run's four paths pooled (a straight vertex counts as 0°; L6364–6366).",
    },
    Section {
        measure: Measure::Quartiles { metric: "curviness", thesis: &thesis::TABLE_5_11 },
        what: "the spread of the curviness: lower and upper quartile over the median \
               (lower/upper).",
    },
];

/// "×ours/thesis", or "×–" where the thesis's figure is 0.
fn times(ours: f64, thesis: f64) -> String {
    if thesis == 0.0 { "×–".into() } else { format!("×{}", sig3(ours / thesis)) }
}

/// One cell "ours / thesis (×ours/thesis)".
pub(super) fn cell(ours: Option<f64>, thesis: Option<f64>, fmt: fn(f64) -> String) -> String {
    match (ours, thesis) {
        (None, _) => "–".into(),
        (Some(o), None) => fmt(o),
        (Some(o), Some(t)) => format!("{} / {} ({})", fmt(o), fmt(t), times(o, t)),
    }
}

/// Lower and upper quartile over the median; `None` without values or with a median of 0.
fn quartile_ratios(values: &[f64]) -> Option<QuartileRatios> {
    let median = quantile(values, 0.5).filter(|m| *m != 0.0)?;
    Some(QuartileRatios {
        lower: quantile(values, 0.25)? / median,
        upper: quantile(values, 0.75)? / median,
    })
}

/// A turn count: whole numbers as such, interpolated quantiles with up to two decimals.
fn count(x: f64) -> String {
    let s = format!("{x:.2}");
    s.trim_end_matches('0').trim_end_matches('.').to_owned()
}

/// Steep turns over turns; 0 without turns (no turn is steep).
fn steep_ratio(steep: f64, turns: f64) -> f64 {
    if turns > 0.0 { steep / turns } else { 0.0 }
}

/// The text of one cell of `measure` for planner `p` on backend `b` (column `col` of
/// [`BACKENDS`]).
fn cell_text(measure: Measure, m: &Matrix, b: Backend, col: usize, p: PlannerKind) -> String {
    match measure {
        Measure::Median { metric, thesis, fmt } => {
            let ours = quantile(&m.values("office", b, p, metric), 0.5);
            cell(ours, thesis.cell(p, col), fmt)
        }
        Measure::Quartiles { metric, thesis } => {
            let Some(o) = quartile_ratios(&m.values("office", b, p, metric)) else {
                return "–".into();
            };
            let ours = format!("{:.3}/{:.3}", o.lower, o.upper);
            match thesis.cell(p, col) {
                None => ours,
                Some(t) => format!(
                    "{ours} / {:.3}/{:.3} ({}/{})",
                    t.lower,
                    t.upper,
                    times(o.lower, t.lower),
                    times(o.upper, t.upper)
                ),
            }
        }
        Measure::Turns { p: q, thesis } => {
            let steep = quantile(&m.values("office", b, p, "steep_turns"), q);
            let turns = quantile(&m.values("office", b, p, "turns"), q);
            let (Some(steep), Some(turns)) = (steep, turns) else { return "–".into() };
            let ratio = steep_ratio(steep, turns);
            let ours = format!("{}/{}/{ratio:.3}", count(steep), count(turns));
            match thesis.cell(p, col) {
                None => ours,
                Some(t) => format!(
                    "{ours} / {}/{}/{:.3} ({}/{}/{})",
                    t.steep,
                    t.total,
                    t.ratio,
                    times(steep, f64::from(t.steep)),
                    times(turns, f64::from(t.total)),
                    times(ratio, t.ratio)
                ),
            }
        }
    }
}

/// A table of the office: planners × backends, then the solved runs per backend.
fn office_table(m: &Matrix, measure: Measure) -> String {
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
        if !BACKENDS.iter().any(|&(b, _)| m.solved("office", b, p).is_some()) {
            continue;
        }
        let _ = write!(out, "| {label} |");
        let mut solved = Vec::new();
        for (i, &(b, _)) in BACKENDS.iter().enumerate() {
            let text = if m.solved("office", b, p).is_some() {
                cell_text(measure, m, b, i, p)
            } else {
                "–".into()
            };
            let _ = write!(out, " {text} |");
            solved.push(m.solved("office", b, p).map_or("–".into(), |(s, n)| format!("{s}/{n}")));
        }
        let _ = writeln!(out, " {} |", solved.join(" "));
    }
    out
}

/// Whether any successful office run of the matrix carries `metric` (the tables are over
/// successful runs only).
fn has_metric(m: &Matrix, metric: &str) -> bool {
    m.cells.iter().filter(|((scene, _, _), _)| scene == "office").any(|(_, runs)| {
        runs.values().any(|r| r.get("solved") == Some(&1.0) && r.contains_key(metric))
    })
}

/// The commands that wrote the office rows, as Markdown code spans.
fn commands(m: &Matrix) -> String {
    match m.scene_commands.get("office").filter(|c| !c.is_empty()) {
        Some(c) => c.iter().map(|c| format!("`{c}`")).collect::<Vec<_>>().join(", "),
        None => "`cargo xtask bench roadmap --scene office` (the rows record no command)".into(),
    }
}

/// The office sections of the page: Tables 5.3–5.11, the plot after Table 5.3.
pub(super) fn office_sections(m: &Matrix, svg_name: &str) -> String {
    let mut o = String::new();
    if !m.cells.keys().any(|(scene, _, _)| scene == "office") {
        let _ = writeln!(
            o,
            "## Office: Tables 5.3–5.11 (thesis §5.5.3)\n\nNot reproduced: the rows of this \
             revision hold no run of scene `office` (run `cargo xtask bench roadmap --scene \
             office --jobs 1`, then `cargo xtask docs`).\n"
        );
        return o;
    }
    let ma_prm: Vec<String> = (0..4)
        .filter(|&c| thesis::TABLE_5_3.cell(PlannerKind::MaPrm, c).is_some())
        .map(|c| format!("{} {}/50", thesis::OFFICE_COLUMNS[c], thesis::MA_PRM_SOLVED_OF_50[c]))
        .collect();
    let _ = writeln!(
        o,
        "## Office: Tables 5.3–5.11 (thesis §5.5.3)\n\nThe shared floor plan (20 × 15 × 2.5 m), \
         robot radius 0.3 m, step 1 m, one growing tree or roadmap from the centre to the four \
         corner rooms, at most 100,000 iterations; statistics over the runs that reached all four \
         ROIs, as the thesis's (L6119–6121). Cells: ours / thesis (×ours/thesis); the thesis's \
         columns are Simple, BB6D, OPCODE and Bullet, in the roles of our polygon, bbox6d, trimesh \
         and rapier maps; \"–\": the planner cannot run on that map, or no figure. `solved`: runs \
         that reached all four ROIs per backend (the thesis's MA PRM, with its vertex count found \
         by binary search: {}; L6141–6145). The thesis ran 50 seeds and ray checks (L6105).\n",
        ma_prm.join(", ")
    );
    for section in &SECTIONS {
        let measure = section.measure;
        let (caption, [first, last]) = measure.thesis_caption_lines();
        let _ = writeln!(o, "### Table {}: {caption} (L{first}–{last})\n", measure.thesis_number());
        let _ = writeln!(o, "Measures {}\n", section.what);
        let _ = writeln!(
            o,
            "Command: {} (the thesis's 50 runs: `--seeds 50`), then `cargo xtask docs`.\n",
            commands(m)
        );
        let missing: Vec<&str> =
            measure.metrics().into_iter().filter(|metric| !has_metric(m, metric)).collect();
        if !missing.is_empty() {
            let _ = writeln!(
                o,
                "Not reproduced: the office rows of this revision carry no `{}` metric (rows \
                 written before `bench-matrix` recorded it); rerun the command above.\n",
                missing.join("`, `")
            );
            continue;
        }
        o.push_str(&office_table(m, measure));
        if measure.thesis_number() == "5.3" {
            let _ = writeln!(o, "\n![median office time per planner and backend]({svg_name})");
        }
        o.push('\n');
    }
    o
}

/// The plot: median office time per planner (groups) and backend (bars) on a log axis, the
/// thesis's Table 5.3 as black ticks on the bars of its four columns.
pub fn office_time_svg(m: &Matrix) -> String {
    let planners: Vec<(PlannerKind, &str)> = PLANNERS
        .iter()
        .copied()
        .filter(|&(p, _)| BACKENDS.iter().any(|&(b, _)| m.solved("office", b, p).is_some()))
        .collect();
    let colours = ["#4e79a7", "#f28e2b", "#59a14f", "#e15759", "#9c755f"];
    let thesis_time = |p: PlannerKind, column: usize| thesis::TABLE_5_3.cell(p, column);
    let mut values = Vec::new();
    for &(p, _) in &planners {
        for (b, _) in BACKENDS {
            values.extend(quantile(&m.values("office", b, p, "time"), 0.5));
        }
    }
    values.extend(thesis::TABLE_5_3.rows.iter().flat_map(|r| r.cells.iter().flatten().copied()));
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
    for (g, &(p, label)) in planners.iter().enumerate() {
        let x0 = left + g as f64 * group + group * 0.1;
        for (i, &(b, _)) in BACKENDS.iter().enumerate() {
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
            if let Some(t) = thesis_time(p, i) {
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
