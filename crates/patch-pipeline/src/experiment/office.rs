//! `patchnav experiment office`: the thesis's preliminary experiment (§5.5.3–5.5.4, Tables
//! 5.3–5.11; spec §5.1) on the office floor plan of the shared benchmark.
//!
//! Every planner of the planner table (`PLANNERS`) runs on every backend of the backend table
//! (`BACKENDS`) it can run on, once per seed `0..N`. A run reaches all four regions of interest (ROIs) from the central start with
//! one growing tree or roadmap and stops there, or after the iteration cap (the `roi` mode of
//! `patchnav plan --problem`, whose problem reading, map building, planner construction and
//! result rows it shares). Each map is built once per backend; only `solve` is timed.
//!
//! # Metrics of a run (successful runs only, as the thesis: L6119–6121)
//! The thesis measures "the paths from starting point to ROIs" (Tables 5.5–5.11), so every
//! metric of a run is taken over its four paths, start → ROI *i*, each a path in the one tree
//! or roadmap of the run (a shared prefix is counted once per path, as in the thesis's "added
//! length"):
//! * **time**: the wall time of `solve`, seconds;
//! * **added length**: the sum of the four path lengths ([`roadmap::metrics::added_length`]);
//! * **steep / total turns**: the sums over the four paths of [`roadmap::PathMetrics`]'s
//!   `steep_turns` (> 90°) and `turns`. The thesis's RRT median of 20 turns on 23 m of
//!   added length fits a sum over the four paths (about one turn per metre of path); as a
//!   per-path count it would need segments of about 0.3 m;
//! * **curviness**: the upper quartile of the turn angles at the interior vertices of all four
//!   paths pooled ([`roadmap::metrics::turn_angles`], then
//!   [`roadmap::metrics::upper_quartile`]; straight vertices count with angle 0, as in the
//!   metrics module), in degrees: the thesis's "upper quartile of the angle of all turns on
//!   paths to the ROIs" (L6364–6366).
//!
//! # Statistics
//! Medians and quartiles over the successful runs of a cell by linear interpolation between
//! closest ranks (Hyndman & Fan type 7, [`roadmap::metrics::quantile`], the method of the
//! curviness). Quartiles are printed as ratios to the median (Tables 5.4, 5.6, 5.11). In Tables 5.7–5.9 the ratio is
//! the quantile of steep turns over the quantile of total turns, as the thesis's numbers show
//! (3/20 = .150, 22/91 = .242); 0 where there are no turns at all.
//!
//! # The thesis's figures
//! Printed beside ours from [`evaluation::thesis`] (Tables 5.3–5.11 with their line references),
//! the one copy of them in the workspace.
//!
//! # Caps
//! The thesis found the MA PRM's number of vertices by binary search (L6123–6141); here every
//! planner gets the same iteration cap (`--max-iterations`, 100,000 by default) and a run that
//! has not reached all four ROIs by then counts as a failure, reported as `n/N`.

use crate::Progress;
use crate::problem::{
    Mode, map_from_patches, read_patches, read_problem, run_row, skipped_row, solve_timed,
};
use Backend as B;
use PlannerKind as P;
use anyhow::{Context, Result, bail};
use evaluation::stats::quartiles;
use evaluation::thesis::{self, OFFICE_COLUMNS, OfficeTable, QuartileRatios, Turns};
use patch_core::{Point3, Real};
use patch_map::Backend;
use roadmap::metrics::{added_length, quantile, turn_angles, upper_quartile};
use roadmap::{PathMetrics, Planner, PlannerKind};
use serde_json::json;
use std::fmt::Write as _;
use std::io::Write as _;
use std::num::NonZeroUsize;
use std::path::PathBuf;
use std::time::Instant;

/// The settings (defaults: the command line's) of `patchnav experiment office`.
#[derive(Clone, Debug, PartialEq)]
pub struct OfficeSetup {
    /// The planning problem JSON (mesh, robot_radius, max_step, bounds, start, four goals,
    /// goal_tolerance; its `iterations` and `seeds` are ignored), relative to the current
    /// directory.
    pub problem: PathBuf,
    /// Runs per planner and backend, with seeds 0..N.
    pub seeds: u64,
    /// Iteration cap of a run; a run that has not reached every ROI by then fails.
    pub max_iterations: u64,
    /// Only these planners (comma-separated; default: all, in the thesis's order).
    pub planners: Vec<PlannerKind>,
    /// Only these backends (comma-separated; default: all, in the thesis's column order).
    pub backends: Vec<Backend>,
    /// Also write one JSON line per run (the rows of `plan --problem` plus the metrics).
    pub jsonl: Option<PathBuf>,
    /// Point spacing of the `pointcloud` backend, metres (default: a quarter of the robot
    /// radius).
    pub sample_spacing: Option<Real>,
    /// Seeds run at once (default: one per core; the output but for the times does not depend
    /// on it). Each run's time is measured while the other threads run theirs; the timing
    /// table is cleanest with one thread.
    pub threads: Option<NonZeroUsize>,
}

impl Default for OfficeSetup {
    fn default() -> OfficeSetup {
        OfficeSetup {
            problem: PathBuf::from("../shared/bench/floorplan.json"),
            seeds: 50,
            max_iterations: 100_000,
            planners: Vec::new(),
            backends: Vec::new(),
            jsonl: None,
            sample_spacing: None,
            threads: None,
        }
    }
}

/// A row of the tables: a planner and its label.
struct PlannerRow {
    kind: PlannerKind,
    label: &'static str,
}

/// The rows of the tables: the thesis's five in its order (Table 5.3), then ours. Adding a
/// planner is one line here (a planner that cannot plan to four goals is reported as skipped).
const PLANNERS: &[PlannerRow] = &[
    PlannerRow { kind: PlannerKind::Rrt, label: "RRT" },
    PlannerRow { kind: PlannerKind::MaRrt, label: "MA RRT" },
    PlannerRow { kind: PlannerKind::EvasionRrt, label: "Ev. RRT" },
    PlannerRow { kind: PlannerKind::Prm, label: "PRM" },
    PlannerRow { kind: PlannerKind::MaPrm, label: "MA PRM" },
    PlannerRow { kind: PlannerKind::RrtConnect, label: "RRT-Connect" },
    PlannerRow { kind: PlannerKind::PrmStar, label: "PRM*" },
    PlannerRow { kind: PlannerKind::LazyPrm, label: "lazy PRM" },
    PlannerRow { kind: PlannerKind::RrtStar, label: "RRT*" },
];

/// The columns with the thesis's names: ours in the thesis's order Simple | BB6D | OPCODE |
/// Bullet, then the point-cloud map (Algorithm 10), which the thesis's table does not have.
const BACKENDS: &[(Backend, &str)] = &[
    (Backend::Polygon, "Simple"),
    (Backend::BBox6d, "BB6D"),
    (Backend::Trimesh, "OPCODE"),
    (Backend::Rapier, "Bullet"),
    (Backend::PointCloud, "–"),
];

/// The metrics of one successful run (see the [module docs](self)).
#[derive(Copy, Clone, Debug)]
struct RunMetrics {
    time_s: Real,
    length: Real,
    steep: Real,
    turns: Real,
    curviness_deg: Real,
}

impl RunMetrics {
    fn of(time_s: Real, paths: &[Vec<Point3>]) -> RunMetrics {
        let per_path: Vec<PathMetrics> = paths.iter().map(|p| PathMetrics::of(p)).collect();
        let angles: Vec<Real> = paths.iter().flat_map(|p| turn_angles(p)).collect();
        RunMetrics {
            time_s,
            length: added_length(paths.iter().map(Vec::as_slice)),
            steep: per_path.iter().map(|m| m.steep_turns as Real).sum(),
            turns: per_path.iter().map(|m| m.turns as Real).sum(),
            curviness_deg: upper_quartile(&angles).unwrap_or(0.0).to_degrees(),
        }
    }
}

/// The outcome of one planner on one backend.
enum Cell {
    /// The planner cannot run on this map (or on this problem): the reason.
    Cannot(String),
    /// The runs: per seed, the metrics if the run reached every ROI.
    Ran(Vec<Option<RunMetrics>>),
}

impl Cell {
    fn successes(&self) -> Vec<RunMetrics> {
        match self {
            Cell::Cannot(_) => Vec::new(),
            Cell::Ran(runs) => runs.iter().flatten().copied().collect(),
        }
    }
}

/// The results: `cells[planner][backend]` over the selected planners and backends.
struct Results<'a> {
    planners: Vec<&'a PlannerRow>,
    backends: Vec<&'a (Backend, &'static str)>,
    cells: Vec<Vec<Cell>>,
}

/// A number as the thesis prints it: six significant digits, no trailing zeros, no leading
/// zero before the decimal point (".010057", "23.1608").
fn thesis_number(x: Real) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let decimals = (5 - x.abs().log10().floor() as i64).max(0) as usize;
    let mut s = format!("{x:.decimals$}");
    if s.contains('.') {
        s = s.trim_end_matches('0').trim_end_matches('.').to_owned();
    }
    strip_leading_zero(s)
}

/// A ratio with three decimals and no leading zero (".547").
fn ratio(x: Real) -> String {
    strip_leading_zero(format!("{x:.3}"))
}

fn strip_leading_zero(s: String) -> String {
    match s.strip_prefix("0.") {
        Some(rest) => format!(".{rest}"),
        None => s,
    }
}

/// A turn count: whole numbers as such, interpolated quantiles with up to two decimals (the
/// quartiles of whole numbers fall on quarters).
fn count(x: Real) -> String {
    let s = format!("{x:.2}");
    s.trim_end_matches('0').trim_end_matches('.').to_owned()
}

/// "lower/upper" as ratios to the median (Tables 5.4, 5.6, 5.11).
fn quartile_ratios(values: &[Real]) -> Option<String> {
    let [lo, med, up] = quartiles(values)?;
    Some(format!("{}/{}", ratio(lo / med), ratio(up / med)))
}

/// Steep turns over total turns; 0 for no turns (no turn is steep).
fn steep_ratio(steep: Real, turns: Real) -> Real {
    if turns > 0.0 { steep / turns } else { 0.0 }
}

/// "steep/total/ratio" at quantile `p` (Tables 5.7–5.9).
fn turns_at(runs: &[RunMetrics], p: Real) -> Option<String> {
    let steep = quantile(&runs.iter().map(|r| r.steep).collect::<Vec<_>>(), p)?;
    let turns = quantile(&runs.iter().map(|r| r.turns).collect::<Vec<_>>(), p)?;
    Some(format!("{}/{}/{}", count(steep), count(turns), ratio(steep_ratio(steep, turns))))
}

fn metric(runs: &[RunMetrics], f: fn(&RunMetrics) -> Real) -> Vec<Real> {
    runs.iter().map(f).collect()
}

/// How a cell of a row variant of a table is printed from the successful runs (`None`: no
/// successful run).
type CellFormat = fn(&[RunMetrics]) -> Option<String>;

/// How the thesis's cell of a planner and column (an index into [`OFFICE_COLUMNS`]) is
/// printed, as the thesis prints it (`None`: its "–").
type ThesisCell = fn(PlannerKind, usize) -> Option<String>;

/// One printed table: ours, then the thesis's (from [`evaluation::thesis`]).
struct TableSpec {
    id: &'static str,
    caption: &'static str,
    /// The row variants: label suffix, our cell, the thesis's cell.
    rows: &'static [(&'static str, CellFormat, ThesisCell)],
}

fn thesis_quartiles(q: QuartileRatios) -> String {
    format!("{}/{}", ratio(q.lower), ratio(q.upper))
}

fn thesis_turns(t: Turns) -> String {
    format!("{}/{}/{}", t.steep, t.total, ratio(t.ratio))
}

const TABLES: &[TableSpec] = &[
    TableSpec {
        id: "5.3",
        caption: "median wall time [s] to reach the ROIs",
        rows: &[(
            "",
            |r| quantile(&metric(r, |m| m.time_s), 0.5).map(thesis_number),
            |p, c| thesis::TABLE_5_3.cell(p, c).map(thesis_number),
        )],
    },
    TableSpec {
        id: "5.4",
        caption: "lower/upper quartile of wall time, as factors of the median",
        rows: &[(
            "",
            |r| quartile_ratios(&metric(r, |m| m.time_s)),
            |p, c| thesis::TABLE_5_4.cell(p, c).map(thesis_quartiles),
        )],
    },
    TableSpec {
        id: "5.5",
        caption: "median added length [m] of the paths from the start to all ROIs",
        rows: &[(
            "",
            |r| quantile(&metric(r, |m| m.length), 0.5).map(thesis_number),
            |p, c| thesis::TABLE_5_5.cell(p, c).map(thesis_number),
        )],
    },
    TableSpec {
        id: "5.6",
        caption: "lower/upper quartile of added length, as factors of the median",
        rows: &[(
            "",
            |r| quartile_ratios(&metric(r, |m| m.length)),
            |p, c| thesis::TABLE_5_6.cell(p, c).map(thesis_quartiles),
        )],
    },
    TableSpec {
        id: "5.7–5.9",
        caption: "steep (> 90°) / total turns / ratio on the paths to the ROIs: median, lower \
                  and upper quartile",
        rows: &[
            (
                ", median",
                |r| turns_at(r, 0.5),
                |p, c| thesis::TABLE_5_7.cell(p, c).map(thesis_turns),
            ),
            (
                ", lower",
                |r| turns_at(r, 0.25),
                |p, c| thesis::TABLE_5_8.cell(p, c).map(thesis_turns),
            ),
            (
                ", upper",
                |r| turns_at(r, 0.75),
                |p, c| thesis::TABLE_5_9.cell(p, c).map(thesis_turns),
            ),
        ],
    },
    TableSpec {
        id: "5.10",
        caption: "median curviness [°] (upper quartile of the turn angles on the paths to the \
                  ROIs)",
        rows: &[(
            "",
            |r| quantile(&metric(r, |m| m.curviness_deg), 0.5).map(thesis_number),
            |p, c| thesis::TABLE_5_10.cell(p, c).map(thesis_number),
        )],
    },
    TableSpec {
        id: "5.11",
        caption: "lower/upper quartile of curviness, as factors of the median",
        rows: &[(
            "",
            |r| quartile_ratios(&metric(r, |m| m.curviness_deg)),
            |p, c| thesis::TABLE_5_11.cell(p, c).map(thesis_quartiles),
        )],
    },
];

/// The thesis's table of `spec`, laid out as the thesis prints it.
fn thesis_table(spec: &TableSpec) -> String {
    let mut rows =
        vec![std::iter::once("").chain(OFFICE_COLUMNS).map(str::to_owned).collect::<Vec<_>>()];
    for (row, &choice) in FIVE.iter().enumerate() {
        for (suffix, _, cell) in spec.rows {
            let mut line = vec![format!("{}{suffix}", thesis_label(row))];
            line.extend((0..4).map(|c| cell(choice, c).unwrap_or_else(|| "–".to_owned())));
            rows.push(line);
        }
    }
    layout(&rows)
}

/// Lays out rows of cells in columns: the first left-aligned, the others right-aligned.
fn layout(rows: &[Vec<String>]) -> String {
    let columns = rows.iter().map(Vec::len).max().unwrap_or(0);
    let width = |c: usize| rows.iter().filter_map(|r| r.get(c)).map(|s| s.chars().count()).max();
    let widths: Vec<usize> = (0..columns).map(|c| width(c).unwrap_or(0)).collect();
    let mut out = String::new();
    for row in rows {
        let mut line = String::new();
        for (c, cell) in row.iter().enumerate() {
            let pad = widths[c] - cell.chars().count();
            if c == 0 {
                line.push_str(cell);
                line.push_str(&" ".repeat(pad));
            } else {
                line.push_str("  ");
                line.push_str(&" ".repeat(pad));
                line.push_str(cell);
            }
        }
        out.push_str(line.trim_end());
        out.push('\n');
    }
    out
}

impl Results<'_> {
    fn cell(&self, planner: PlannerKind, backend: Backend) -> Option<&Cell> {
        let i = self.planners.iter().position(|p| p.kind == planner)?;
        let j = self.backends.iter().position(|b| b.0 == backend)?;
        Some(&self.cells[i][j])
    }

    /// The median of `f` over the successful runs of a cell.
    fn median(
        &self,
        planner: PlannerKind,
        backend: Backend,
        f: fn(&RunMetrics) -> Real,
    ) -> Option<Real> {
        quantile(&metric(&self.cell(planner, backend)?.successes(), f), 0.5)
    }

    fn quartiles(
        &self,
        planner: PlannerKind,
        backend: Backend,
        f: fn(&RunMetrics) -> Real,
    ) -> Option<[Real; 3]> {
        quartiles(&metric(&self.cell(planner, backend)?.successes(), f))
    }

    /// The planners that ran at least once, with a note for those that could run nowhere.
    fn skipped_planners(&self) -> Vec<String> {
        self.planners
            .iter()
            .zip(&self.cells)
            .filter_map(|(p, cells)| match cells.first() {
                Some(Cell::Cannot(reason))
                    if cells.iter().all(|c| matches!(c, Cell::Cannot(_))) =>
                {
                    Some(format!("{}: skipped on every backend ({reason})", p.label))
                }
                _ => None,
            })
            .collect()
    }

    fn shown_planners(&self) -> Vec<usize> {
        (0..self.planners.len())
            .filter(|&i| self.cells[i].iter().any(|c| matches!(c, Cell::Ran(_))))
            .collect()
    }

    fn successes_line(&self) -> String {
        let parts: Vec<String> = self
            .shown_planners()
            .into_iter()
            .map(|i| {
                let counts: Vec<String> = self.cells[i]
                    .iter()
                    .map(|c| match c {
                        Cell::Cannot(_) => "–".to_owned(),
                        Cell::Ran(runs) => {
                            format!("{}/{}", runs.iter().flatten().count(), runs.len())
                        }
                    })
                    .collect();
                format!("{} {}", self.planners[i].label, counts.join(" "))
            })
            .collect();
        format!("  n/N runs reached all ROIs (per column): {}", parts.join("; "))
    }

    fn print_table(&self, out: &mut String, spec: &TableSpec) -> Result<()> {
        writeln!(out, "Table {} (ours): {}", spec.id, spec.caption)?;
        let mut header = vec![String::new()];
        header.extend(
            self.backends
                .iter()
                .map(|b| if b.1 == "–" { b.0.to_string() } else { format!("{} ({})", b.0, b.1) }),
        );
        let mut rows = vec![header];
        for i in self.shown_planners() {
            for (suffix, format, _) in spec.rows {
                let mut row = vec![format!("{}{suffix}", self.planners[i].label)];
                row.extend(self.cells[i].iter().map(|c| match c {
                    Cell::Cannot(_) => "–".to_owned(),
                    Cell::Ran(_) => format(&c.successes()).unwrap_or_else(|| "none".to_owned()),
                }));
                rows.push(row);
            }
        }
        out.push_str(&layout(&rows));
        writeln!(out, "{}", self.successes_line())?;
        writeln!(out, "Table {} (thesis): {}", spec.id, spec.caption)?;
        out.push_str(&thesis_table(spec));
        writeln!(out)?;
        Ok(())
    }
}

/// Runs the experiment and prints the tables, then the thesis's claims checked on our data.
pub fn run(args: &OfficeSetup, progress: &dyn Progress) -> Result<()> {
    if !args.problem.exists() {
        bail!(
            "{}: no such problem file (give --problem PATH; the default is the shared \
             benchmark's floor plan, relative to the current directory)",
            args.problem.display()
        );
    }
    let p = read_problem(&args.problem)?;
    let space = p.space().with_context(|| args.problem.display().to_string())?;
    let query = p.query(&p.goals);
    let patches = read_patches(&p)?;
    for kind in &args.planners {
        if !PLANNERS.iter().any(|r| r.kind == *kind) {
            bail!("planner {kind} is not in the office experiment's list");
        }
    }
    let planners: Vec<&PlannerRow> = PLANNERS
        .iter()
        .filter(|r| args.planners.is_empty() || args.planners.contains(&r.kind))
        .collect();
    let backends: Vec<_> = BACKENDS
        .iter()
        .filter(|b| args.backends.is_empty() || args.backends.contains(&b.0))
        .collect();
    let threads = crate::parallel::threads_or_cores(args.threads);
    let started = Instant::now();
    // Every cell; with `jsonl`, one JSON line per run written to it as each cell ends.
    let run_cells = |mut jsonl: Option<&mut dyn std::io::Write>| -> Result<Vec<Vec<Cell>>> {
        let mut cells: Vec<Vec<Cell>> = planners.iter().map(|_| Vec::new()).collect();
        let bar = progress.bar((planners.len() * backends.len()) as u64 * args.seeds, "runs");
        for &&(backend, _) in &backends {
            let map = map_from_patches(&p, patches.clone(), backend, args.sample_spacing)
                .with_context(|| format!("building the `{backend}` map"))?;
            for (i, row) in planners.iter().enumerate() {
                // The seeds on all cores; lines and metrics joined in seed order, so the output
                // does not depend on the thread count.
                let seeds = usize::try_from(args.seeds).context("too many seeds")?;
                let want_lines = jsonl.is_some();
                let done = crate::parallel::map_in_order(seeds, threads, |seed| {
                    let seed = seed as u64;
                    let mut planner = match roadmap::named_planner_on(row.kind, &map, space, seed)
                        .map_err(anyhow::Error::from)
                    {
                        Ok(planner) => planner,
                        Err(reason) => {
                            let line = want_lines.then(|| {
                                skipped_row(&p, row.kind, map.backend(), Mode::Roi, seed, &reason)
                            });
                            return (line, Err(format!("{reason:#}")));
                        }
                    };
                    let outcome =
                        solve_timed(planner.as_mut(), &query, Mode::Roi, args.max_iterations);
                    let paths: Vec<Option<Vec<Point3>>> =
                        (0..p.goals.len()).map(|g| planner.path_to(g)).collect();
                    let all: Option<Vec<Vec<Point3>>> = paths.iter().cloned().collect();
                    let metrics = all.map(|paths| RunMetrics::of(outcome.1, &paths));
                    let line = want_lines.then(|| {
                        let mut line = run_row(
                            &p,
                            planner.as_ref() as &dyn Planner,
                            map.backend(),
                            Mode::Roi,
                            seed,
                            outcome,
                            &paths,
                        );
                        line["experiment"] = json!("office");
                        line["iteration_cap"] = json!(args.max_iterations);
                        if let Some(m) = metrics {
                            line["added_length"] = json!(m.length);
                            line["steep_turns"] = json!(m.steep as u64);
                            line["turns"] = json!(m.turns as u64);
                            line["steep_ratio"] = json!(steep_ratio(m.steep, m.turns));
                            line["curviness_deg"] = json!(m.curviness_deg);
                        }
                        line
                    });
                    (line, Ok(metrics))
                });
                bar.inc(args.seeds);
                let mut runs = Vec::new();
                let mut cannot = None;
                for (line, run) in done {
                    if let (Some(out), Some(line)) = (&mut jsonl, line) {
                        writeln!(out, "{line}")?;
                    }
                    match run {
                        Ok(metrics) => runs.push(metrics),
                        Err(reason) => cannot = Some(reason),
                    }
                }
                cells[i].push(match cannot {
                    Some(reason) if runs.is_empty() => Cell::Cannot(reason),
                    _ => Cell::Ran(runs),
                });
            }
        }
        bar.finish_and_clear();
        Ok(cells)
    };
    let cells = match &args.jsonl {
        Some(path) => pointcloud::io::write_atomically(path, |w| run_cells(Some(w)))?,
        None => run_cells(None)?,
    };
    let elapsed = started.elapsed().as_secs_f64();
    let results = Results { planners, backends, cells };
    let mut out = String::new();
    writeln!(
        out,
        "Office experiment (thesis §5.5.3): problem `{}`, {} seeds (0..{}), iteration cap {}, \
         {} of {} runs reached all {} ROIs; {elapsed:.1} s in all (planning and map building)",
        p.name,
        args.seeds,
        args.seeds,
        args.max_iterations,
        results.cells.iter().flatten().map(|c| c.successes().len()).sum::<usize>(),
        results
            .cells
            .iter()
            .flatten()
            .map(|c| match c {
                Cell::Cannot(_) => 0,
                Cell::Ran(runs) => runs.len(),
            })
            .sum::<usize>(),
        p.goals.len(),
    )?;
    writeln!(
        out,
        "Columns: ours (thesis's counterpart): Simple = polygon, BB6D = bbox6d, OPCODE = trimesh \
         (parry BVH), Bullet = rapier; pointcloud is ours only. \"–\": the planner cannot run \
         on that map; \"none\": no run reached all ROIs. Statistics over successful runs only."
    )?;
    for note in results.skipped_planners() {
        writeln!(out, "{note}")?;
    }
    writeln!(out)?;
    for spec in TABLES {
        results.print_table(&mut out, spec)?;
    }
    out.push_str(&claims(&results));
    progress.report(out.trim_end());
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// The thesis's prose claims (spec §5.1 "Claims in the prose", §7.15), checked on the data.

/// The thesis's five planners, its row order.
const FIVE: [PlannerKind; 5] = [P::Rrt, P::MaRrt, P::EvasionRrt, P::Prm, P::MaPrm];
/// Our counterparts of the thesis's columns.
const FOUR: [Backend; 4] = [B::Polygon, B::BBox6d, B::Trimesh, B::Rapier];

fn label(kind: PlannerKind) -> &'static str {
    PLANNERS.iter().find(|r| r.kind == kind).map_or("?", |r| r.label)
}

/// The thesis's figure of `table` at planner `row` (index into [`FIVE`]) and column `col`
/// (index into [`FOUR`] and [`OFFICE_COLUMNS`]); `None` for "–".
fn thesis_value<T: Copy>(table: &OfficeTable<T>, row: usize, col: usize) -> Option<T> {
    table.cell(FIVE[row], col)
}

/// The thesis's label of planner `row` (index into [`FIVE`]).
fn thesis_label(row: usize) -> &'static str {
    let kind = FIVE[row];
    thesis::TABLE_5_3.rows.iter().find(|r| r.planner == kind).map_or("?", |r| r.label)
}

/// One column of values for the claims: per planner of [`FIVE`], `Some(value)` where known.
type Column = [Option<Real>; 5];

fn argmin(col: &Column) -> Option<usize> {
    (0..5)
        .filter(|&i| col[i].is_some())
        .min_by(|&a, &b| col[a].unwrap().total_cmp(&col[b].unwrap()))
}

fn argmax(col: &Column) -> Option<usize> {
    (0..5)
        .filter(|&i| col[i].is_some())
        .max_by(|&a, &b| col[a].unwrap().total_cmp(&col[b].unwrap()))
}

fn yes(b: bool) -> &'static str {
    if b { "yes" } else { "no" }
}

/// Per column, `check` on the column's values (ours: our backends; thesis: its columns).
fn per_column(
    results: &Results<'_>,
    ours: impl Fn(PlannerKind, Backend) -> Option<Real>,
    thesis: impl Fn(usize, usize) -> Option<Real>,
    check: impl Fn(&Column) -> Option<String>,
) -> (String, String) {
    let thesis_parts: Vec<String> = (0..4)
        .filter_map(|c| {
            let col: Column = std::array::from_fn(|r| thesis(r, c));
            check(&col).map(|s| format!("{} {s}", OFFICE_COLUMNS[c]))
        })
        .collect();
    let our_parts: Vec<String> = results
        .backends
        .iter()
        .filter_map(|b| {
            let col: Column = std::array::from_fn(|r| ours(FIVE[r], b.0));
            check(&col).map(|s| format!("{} {s}", b.0))
        })
        .collect();
    (thesis_parts.join(", "), our_parts.join(", "))
}

fn claim(out: &mut String, text: &str, (thesis, ours): (String, String)) {
    let none = |s: String| if s.is_empty() { "no data".to_owned() } else { s };
    let _ = writeln!(out, "- {text}\n    thesis: {}\n    ours:   {}", none(thesis), none(ours));
}

fn claims(r: &Results<'_>) -> String {
    let mut out = String::from(
        "Claims of the thesis's prose (spec §5.1, §7.15), checked on the thesis's tables and on \
         ours (computed, over the thesis's five planners):\n",
    );
    let time = |m: &RunMetrics| m.time_s;
    let length = |m: &RunMetrics| m.length;
    let curv = |m: &RunMetrics| m.curviness_deg;
    let t_time = |row, col| thesis_value(&thesis::TABLE_5_3, row, col);

    claim(
        &mut out,
        "RRT is the fastest algorithm, PRM the runner-up (L6194–6196, Table 5.3)",
        per_column(
            r,
            |p, b| r.median(p, b, time),
            t_time,
            |col| {
                let fastest = argmin(col)?;
                let mut rest = *col;
                rest[fastest] = None;
                let second = argmin(&rest);
                let ok = fastest == 0 && second == Some(3);
                let second = second.map_or("–", thesis_label);
                Some(if ok {
                    "yes".to_owned()
                } else {
                    format!("no ({} fastest, {second} second)", thesis_label(fastest))
                })
            },
        ),
    );
    claim(
        &mut out,
        "All others are one or two orders of magnitude slower than RRT (L6196–6197): the \
         smallest factor of MA RRT, Ev. RRT, MA PRM over RRT ≥ 10",
        per_column(
            r,
            |p, b| r.median(p, b, time),
            t_time,
            |col| {
                let rrt = col[0]?;
                let min =
                    [1, 2, 4].iter().filter_map(|&i| col[i]).map(|t| t / rrt).reduce(Real::min)?;
                Some(format!("{} ({min:.1}×)", yes(min >= 10.0)))
            },
        ),
    );
    {
        // Naive (Simple, BB6D) over Bullet, per planner: worst and best factor.
        let factors = |value: &dyn Fn(usize, usize) -> Option<Real>, names: [&str; 2]| {
            let mut all: Vec<(Real, String)> = Vec::new();
            for row in 0..FIVE.len() {
                let name = thesis_label(row);
                for (c, col_name) in names.iter().enumerate() {
                    if let (Some(naive), Some(bullet)) = (value(row, c), value(row, 3)) {
                        all.push((naive / bullet, format!("{col_name}/{name}")));
                    }
                }
            }
            let worst = all.iter().max_by(|a, b| a.0.total_cmp(&b.0)).cloned();
            let best = all.iter().min_by(|a, b| a.0.total_cmp(&b.0)).cloned();
            match (worst, best) {
                (Some(w), Some(b)) => format!(
                    "worst {:.2} ({}), best {:.2} ({}); matches the claimed cells: {}",
                    w.0,
                    w.1,
                    b.0,
                    b.1,
                    yes(w.1.ends_with("/MA PRM")
                        && w.1.starts_with(names[0])
                        && b.1.ends_with("/MA RRT")
                        && b.1.starts_with(names[1]))
                ),
                _ => String::new(),
            }
        };
        let ours = |row: usize, c: usize| r.median(FIVE[row], FOUR[c], time);
        claim(
            &mut out,
            "Naive maps vs Bullet: factor 2.35 worst (Simple/MA PRM), 1.09 best (BB6D/MA RRT) \
             (L6200–6204; §7.15: the table gives 2.90)",
            (
                factors(&t_time, ["Simple", "BB6D"]),
                factors(&ours, [FOUR[0].name(), FOUR[1].name()]),
            ),
        );
    }
    {
        let thesis = thesis_value(&thesis::TABLE_5_3, 3, 2)
            .zip(thesis_value(&thesis::TABLE_5_3, 3, 3))
            .map(|(o, b)| format!("OPCODE/Bullet PRM time {:.2}: {}", o / b, yes(o > b)));
        let ours = r
            .median(P::Prm, B::Trimesh, time)
            .zip(r.median(P::Prm, B::Rapier, time))
            .map(|(o, b)| format!("trimesh/rapier PRM time {:.2}: {}", o / b, yes(o > b)));
        claim(
            &mut out,
            "OPCODE shows some weakness with PRM (L6199; §7.15: OPCODE's PRM is the fastest cell)",
            (thesis.unwrap_or_default(), ours.unwrap_or_default()),
        );
    }
    {
        // Time spread (upper − lower)/median.
        let spread = |q: [Real; 3]| (q[2] - q[0]) / q[1];
        let t_spread =
            |row, col| thesis_value(&thesis::TABLE_5_4, row, col).map(|q| q.upper - q.lower);
        claim(
            &mut out,
            "PRM has the largest variance of time (L6204–6205, Table 5.4): largest (upper − \
             lower)/median",
            per_column(
                r,
                |p, b| r.quartiles(p, b, time).map(spread),
                t_spread,
                |col| {
                    let i = argmax(col)?;
                    Some(if i == 3 {
                        "yes".to_owned()
                    } else {
                        format!("no ({})", thesis_label(i))
                    })
                },
            ),
        );
        let t_up = |row, col| thesis_value(&thesis::TABLE_5_4, row, col).map(|q| q.upper);
        let t_lo = |row, col| thesis_value(&thesis::TABLE_5_4, row, col).map(|q| q.lower);
        claim(
            &mut out,
            "MA PRM shows the smallest upward variance (L6205–6206): smallest upper/median",
            per_column(
                r,
                |p, b| r.quartiles(p, b, time).map(|q| q[2] / q[1]),
                t_up,
                |col| {
                    let i = argmin(col)?;
                    Some(if i == 4 {
                        "yes".to_owned()
                    } else {
                        format!("no ({})", thesis_label(i))
                    })
                },
            ),
        );
        claim(
            &mut out,
            "MA PRM has the largest downward variance (L6206): smallest lower/median",
            per_column(
                r,
                |p, b| r.quartiles(p, b, time).map(|q| q[0] / q[1]),
                t_lo,
                |col| {
                    let i = argmin(col)?;
                    Some(if i == 4 {
                        "yes".to_owned()
                    } else {
                        format!("no ({})", thesis_label(i))
                    })
                },
            ),
        );
        // Frameworks: the mean time spread of RRT and PRM (the planners every column runs).
        let mean_spread = |value: &dyn Fn(usize, usize) -> Option<Real>, names: &[&str]| {
            let spreads: Vec<(String, Real)> = (0..4)
                .filter_map(|c| {
                    let s = (value(0, c)? + value(3, c)?) / 2.0;
                    Some((names[c].to_owned(), s))
                })
                .collect();
            let most_stable = spreads.iter().min_by(|a, b| a.1.total_cmp(&b.1));
            let list: Vec<String> =
                spreads.iter().map(|(n, s)| format!("{n} {}", ratio(*s))).collect();
            match most_stable {
                Some((name, _)) => {
                    format!("{}; most stable: {name} ({})", list.join(", "), yes(name == names[2]))
                }
                None => String::new(),
            }
        };
        let ours = |row: usize, c: usize| r.quartiles(FIVE[row], FOUR[c], time).map(spread);
        claim(
            &mut out,
            "Among the frameworks OPCODE is the most stable, Bullet and Simple vary most \
             (L6207–6208): mean (upper − lower)/median of RRT and PRM time",
            (mean_spread(&t_spread, &OFFICE_COLUMNS), mean_spread(&ours, &FOUR.map(Backend::name))),
        );
    }
    let t_len = |row, col| thesis_value(&thesis::TABLE_5_5, row, col);
    claim(
        &mut out,
        "MA RRT produces the shortest paths, RRT's only marginally longer (L6214–6215, Table \
         5.5): shortest median added length; RRT/MA RRT",
        per_column(
            r,
            |p, b| r.median(p, b, length),
            t_len,
            |col| {
                let i = argmin(col)?;
                let factor = col[0].zip(col[1]).map(|(a, b)| format!(", RRT/MA RRT {:.3}", a / b));
                Some(format!(
                    "{}{}",
                    if i == 1 { "yes".to_owned() } else { format!("no ({})", thesis_label(i)) },
                    factor.unwrap_or_default()
                ))
            },
        ),
    );
    claim(
        &mut out,
        "The PRM-based algorithms produce long paths (L6215–6216): PRM and MA PRM longer than \
         every RRT variant",
        per_column(
            r,
            |p, b| r.median(p, b, length),
            t_len,
            |col| {
                let rrt_max = [0, 1, 2].iter().filter_map(|&i| col[i]).reduce(Real::max)?;
                let prm_min = [3, 4].iter().filter_map(|&i| col[i]).reduce(Real::min)?;
                Some(yes(prm_min > rrt_max).to_owned())
            },
        ),
    );
    let our_ratio = |p: PlannerKind, b: Backend| {
        let s = r.median(p, b, |m| m.steep)?;
        Some(steep_ratio(s, r.median(p, b, |m| m.turns)?))
    };
    let t_ratio = |row, col| thesis_value(&thesis::TABLE_5_7, row, col).map(|t| t.ratio);
    claim(
        &mut out,
        "PRM's paths have few turns, but 50% of them steep (L6282–6283, Table 5.7): PRM's \
         median steep/total ratio, and the highest of the five",
        per_column(r, our_ratio, t_ratio, |col| {
            let prm = col[3]?;
            Some(format!("{} {}", ratio(prm), yes(argmax(col) == Some(3))))
        }),
    );
    claim(
        &mut out,
        "MA PRM produces less than half as many steep turns (as a share) as PRM, the RRT-based \
         ones did better still (L6284–6287)",
        per_column(r, our_ratio, t_ratio, |col| {
            let half = col[4]? < col[3]? / 2.0;
            let rrts_better = [0, 1, 2].iter().filter_map(|&i| col[i]).all(|x| x < col[4].unwrap());
            Some(format!("{}/{}", yes(half), yes(rrts_better)))
        }),
    );
    claim(
        &mut out,
        "Evasion RRT creates the smoothest paths (L6301): lowest median steep/total ratio",
        per_column(r, our_ratio, t_ratio, |col| {
            let i = argmin(col)?;
            Some(if i == 2 { "yes".to_owned() } else { format!("no ({})", thesis_label(i)) })
        }),
    );
    let t_curv = |row, col| thesis_value(&thesis::TABLE_5_10, row, col);
    claim(
        &mut out,
        "Curviness: the RRT-based planners similar, MA PRM trails, PRM worst by far (L6361–6363, \
         Table 5.10)",
        per_column(
            r,
            |p, b| r.median(p, b, curv),
            t_curv,
            |col| {
                let prm_worst = argmax(col) == Some(3);
                let rrt_max = [0, 1, 2].iter().filter_map(|&i| col[i]).reduce(Real::max);
                let ma_prm_trails = col[4].zip(rrt_max).map(|(m, r)| m > r);
                Some(format!(
                    "PRM worst {}, MA PRM behind the RRTs {}",
                    yes(prm_worst),
                    ma_prm_trails.map_or("–", yes)
                ))
            },
        ),
    );
    {
        let extremes = |values: Vec<(Real, Real, String)>| {
            let lo = values.iter().min_by(|a, b| a.0.total_cmp(&b.0));
            let up = values.iter().max_by(|a, b| a.1.total_cmp(&b.1));
            match (lo, up) {
                (Some(lo), Some(up)) => format!(
                    "lowest lower/median {} ({}), highest upper/median {} ({})",
                    ratio(lo.0),
                    lo.2,
                    ratio(up.1),
                    up.2
                ),
                _ => String::new(),
            }
        };
        let mut theirs = Vec::new();
        let mut ours = Vec::new();
        for (row, &planner) in FIVE.iter().enumerate() {
            let name = thesis_label(row);
            for (c, col) in OFFICE_COLUMNS.iter().enumerate() {
                if let Some(q) = thesis_value(&thesis::TABLE_5_11, row, c) {
                    theirs.push((q.lower, q.upper, format!("{name}/{col}")));
                }
            }
            for b in &r.backends {
                if let Some(q) = r.quartiles(planner, b.0, curv) {
                    ours.push((q[0] / q[1], q[2] / q[1], format!("{name}/{}", b.0)));
                }
            }
        }
        claim(
            &mut out,
            "Curviness varies little: lower quartile below 83% of the median only once (.791, \
             MA RRT/Simple), upper above 110% only on OPCODE (L6367–6371, Table 5.11)",
            (extremes(theirs), extremes(ours)),
        );
    }
    claim(
        &mut out,
        "Bullet is the fastest implementation (L6383–6384; §7.15: OPCODE beats it where it \
         runs): per planner, the fastest of the four thesis columns",
        {
            let thesis: Vec<String> = (0..5)
                .map(|row| {
                    let col: Column =
                        std::array::from_fn(|c| (c < 4).then(|| t_time(row, c)).flatten());
                    let best = argmin(&col).map_or("–", |c| OFFICE_COLUMNS[c]);
                    format!("{} {best}", thesis_label(row))
                })
                .collect();
            let ours: Vec<String> = FIVE
                .iter()
                .map(|&p| {
                    let col: Column = std::array::from_fn(|c| {
                        (c < 4).then(|| r.median(p, FOUR[c], time)).flatten()
                    });
                    let best = argmin(&col).map_or_else(|| "–".to_owned(), |c| FOUR[c].to_string());
                    format!("{} {best}", label(p))
                })
                .collect();
            let verdict = |v: &[String], bullet: &str| {
                let all = v.iter().all(|s| s.ends_with(bullet) || s.ends_with(" –"));
                format!("{}: {}", yes(all), v.join(", "))
            };
            (verdict(&thesis, " Bullet"), verdict(&ours, " rapier"))
        },
    );
    {
        // Same seed, same paths on every implementation of the patch map (L6186–6192); the
        // point-cloud map is a different map (sampled points), so it is left out.
        let mut parts = Vec::new();
        for &p in &FIVE {
            let per_backend: Vec<&Vec<Option<RunMetrics>>> = FOUR
                .iter()
                .filter_map(|&b| match r.cell(p, b)? {
                    Cell::Ran(runs) => Some(runs),
                    Cell::Cannot(_) => None,
                })
                .collect();
            if per_backend.len() < 2 {
                continue;
            }
            let seeds = per_backend[0].len();
            let same = (0..seeds)
                .filter(|&s| {
                    let lengths: Vec<Option<Real>> =
                        per_backend.iter().map(|runs| runs[s].map(|m| m.length)).collect();
                    lengths.windows(2).all(|w| match (w[0], w[1]) {
                        (Some(a), Some(b)) => (a - b).abs() <= 1e-9 * a.max(1.0),
                        (None, None) => true,
                        _ => false,
                    })
                })
                .count();
            parts.push(format!("{} {same}/{seeds}", label(p)));
        }
        claim(
            &mut out,
            "With the same seed all values but time should be the same on every map (L6186–6192): \
             seeds whose added length agrees (1e-9) on all four patch-map backends",
            (
                "no: Table 5.5 differs between OPCODE and the others, and between the maps for \
                 MA RRT, Ev. RRT and MA PRM"
                    .to_owned(),
                parts.join(", "),
            ),
        );
    }
    {
        let ours: Vec<String> = r
            .backends
            .iter()
            .filter_map(|b| match r.cell(P::MaPrm, b.0)? {
                Cell::Ran(runs) => {
                    Some(format!("{} {}/{}", b.0, runs.iter().flatten().count(), runs.len()))
                }
                Cell::Cannot(_) => None,
            })
            .collect();
        claim(
            &mut out,
            "MA PRM reached all ROIs in 28 of 50 runs (Simple, BB6D, OPCODE) and 30 (Bullet) \
             (L6141–6145; §7.15: OPCODE cannot run MA PRM); ours with one iteration cap, no \
             binary search",
            (thesis_ma_prm_solved(), ours.join(", ")),
        );
    }
    out
}

/// The thesis's MA PRM successes out of 50 in the columns that can run it ("Simple 28/50, ...").
fn thesis_ma_prm_solved() -> String {
    let ma_prm = FIVE.iter().position(|&p| p == P::MaPrm).unwrap_or(4);
    (0..4)
        .filter(|&c| thesis_value(&thesis::TABLE_5_3, ma_prm, c).is_some())
        .map(|c| format!("{} {}/50", OFFICE_COLUMNS[c], thesis::MA_PRM_SOLVED_OF_50[c]))
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_print_as_in_the_thesis() {
        assert_eq!(thesis_number(0.010057), ".010057");
        assert_eq!(thesis_number(23.16080), "23.1608");
        assert_eq!(thesis_number(1.966831), "1.96683");
        assert_eq!(thesis_number(119.9031), "119.903");
        assert_eq!(ratio(0.5471), ".547");
        assert_eq!(ratio(1.8742), "1.874");
        assert_eq!(count(3.0), "3");
        assert_eq!(count(2.25), "2.25");
        assert_eq!(count(30.5), "30.5");
    }

    #[test]
    fn thesis_tables_print_as_the_thesis_prints_them() {
        let text: Vec<String> = TABLES.iter().map(thesis_table).collect();
        // Table 5.3, first and last rows (L6156, L6164).
        assert!(text[0].contains("RRT      .010057  .006137  .002435  .004721"), "{}", text[0]);
        assert!(text[0].contains("MA PRM   1.96683  1.20087        –  .678831"), "{}", text[0]);
        // Table 5.4 (L6176) and Tables 5.7–5.9 (L6257, L6313, L6336), the thesis's ratio digits.
        assert!(text[1].contains(".525/2.621  .520/2.830  .770/1.388  .452/3.123"), "{}", text[1]);
        assert!(text[4].contains("RRT, median"), "{}", text[4]);
        for needle in ["3/20/.150", "22/91/.242", "46/242/.190", "3/5/.600", "1/16/.062"] {
            assert!(text[4].contains(needle), "{needle}: {}", text[4]);
        }
        assert!(text[5].contains("119.903") && text[5].contains("71.383"), "{}", text[5]);
        // One line per thesis row (plus the header): 5 per table, 15 for Tables 5.7–5.9.
        let lines: Vec<usize> = text.iter().map(|t| t.lines().count()).collect();
        assert_eq!(lines, [6, 6, 6, 6, 16, 6, 6]);
        assert_eq!(thesis_ma_prm_solved(), "Simple 28/50, BB6D 28/50, Bullet 30/50");
    }

    #[test]
    fn the_thesis_rows_come_first_in_its_order() {
        // Every planner of the thesis has a row, in the thesis's order, before ours.
        let first: Vec<PlannerKind> = PLANNERS.iter().take(5).map(|r| r.kind).collect();
        let thesis: Vec<PlannerKind> = thesis::TABLE_5_3.rows.iter().map(|r| r.planner).collect();
        assert_eq!(first, thesis);
        assert_eq!(FIVE.to_vec(), thesis);
        let labels: Vec<&str> = PLANNERS.iter().take(5).map(|r| r.label).collect();
        assert_eq!(labels, (0..5).map(thesis_label).collect::<Vec<_>>());
        // The claims read the thesis through the planner: MA RRT has no OPCODE figure.
        assert_eq!(thesis_value(&thesis::TABLE_5_3, 1, 2), None);
        assert_eq!(thesis_value(&thesis::TABLE_5_7, 3, 0).map(|t| t.ratio), Some(0.5));
    }
}
