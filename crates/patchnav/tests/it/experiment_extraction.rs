//! `patchnav experiment extraction` as a user runs it, at toy sizes (`--quick`: one pose, ALRF
//! at 3°, a small camera, one map scan) and without real data.

use std::collections::BTreeSet;
use std::sync::OnceLock;

use crate::common;
use common::*;

const QUICK: &[&str] = &["experiment", "extraction", "--quick", "--real", "/nonexistent"];

/// The printed output of the quick run (run once for all tests).
fn quick_output() -> &'static str {
    static OUT: OnceLock<String> = OnceLock::new();
    OUT.get_or_init(|| {
        let o = patchnav(QUICK);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout).into_owned()
    })
}

/// A markdown table: the header cells and the data rows' cells.
struct Table {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

fn cells(line: &str) -> Vec<String> {
    line.trim().trim_matches('|').split('|').map(|c| c.trim().to_owned()).collect()
}

fn tables(text: &str) -> Vec<Table> {
    let mut out = Vec::new();
    let lines: Vec<&str> = text.lines().collect();
    let mut i = 0;
    while i < lines.len() {
        if lines[i].starts_with('|') && lines.get(i + 1).is_some_and(|l| l.starts_with("|---")) {
            let header = cells(lines[i]);
            let mut rows = Vec::new();
            i += 2;
            while i < lines.len() && lines[i].starts_with('|') {
                rows.push(cells(lines[i]));
                i += 1;
            }
            out.push(Table { header, rows });
        } else {
            i += 1;
        }
    }
    out
}

fn number(cell: &str) -> Option<f64> {
    cell.parse::<f64>().ok().filter(|v| v.is_finite())
}

fn table_with<'a>(all: &'a [Table], first: &str, column: &str) -> Vec<&'a Table> {
    all.iter().filter(|t| t.header[0] == first && t.header.iter().any(|h| h == column)).collect()
}

fn column(t: &Table, name: &str) -> usize {
    t.header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column `{name}`"))
}

#[test]
fn every_section_prints_a_table_with_numeric_cells() {
    let text = quick_output();
    for heading in [
        "## 1. Segmentation quality",
        "## 2. Outlining survey",
        "## 3. Outline fidelity",
        "## 4. Table 5.1",
        "## 5. Map size",
    ] {
        assert!(text.contains(heading), "`{heading}` not in:\n{text}");
    }
    let all = tables(text);
    // Segmentation, two survey inputs (ALRF, camera), fidelity, storage, map sizes.
    assert_eq!(all.len(), 6, "{text}");
    for t in &all {
        assert!(!t.rows.is_empty(), "an empty table: {:?}", t.header);
        for row in &t.rows {
            assert_eq!(row.len(), t.header.len(), "{row:?} under {:?}", t.header);
            let numeric = row.iter().filter(|c| number(c).is_some()).count();
            let labels = row.iter().filter(|c| number(c).is_none() && *c != "–").count();
            assert!(labels <= 2, "too many non-numeric cells in {row:?}");
            assert!(numeric >= 3, "too few numbers in {row:?}");
        }
    }
    assert!(text.contains("Real scans: /nonexistent not found; skipped."), "{text}");
    assert!(text.contains("Thesis's ranking (L5193–5237)"), "{text}");
    assert!(text.contains("agrees"), "the claims are judged: {text}");
}

#[test]
fn segcomp_counts_add_up() {
    let all = tables(quick_output());
    let seg = table_with(&all, "sensor", "correct");
    assert_eq!(seg.len(), 1);
    let t = seg[0];
    assert_eq!(t.rows.len(), 6, "two sensors × three noise levels");
    let get = |row: &Vec<String>, name: &str| -> usize {
        row[column(t, name)].parse().unwrap_or_else(|_| panic!("{name} in {row:?}"))
    };
    for row in &t.rows {
        let (gt, machine) = (get(row, "GT"), get(row, "machine"));
        let (correct, over, under) = (get(row, "correct"), get(row, "over"), get(row, "under"));
        let (missed, noise) = (get(row, "missed"), get(row, "noise"));
        assert!(gt > 0, "{row:?}");
        // Each GT region is in at most one instance; an under-segmentation holds ≥ 2.
        assert!(correct + over + 2 * under + missed <= gt, "{row:?}");
        // Each machine region likewise; an over-segmentation holds ≥ 2.
        assert!(correct + 2 * over + under + noise <= machine, "{row:?}");
        let angle = number(&row[column(t, "angle mean [°]")]);
        assert!(correct == 0 || angle.is_some_and(|a| (0.0..5.0).contains(&a)), "{row:?}");
    }
    // Noise-free scans are segmented with their plane angles exact.
    for row in t.rows.iter().filter(|r| r[1] == "σ=0cm") {
        let max = number(&row[column(t, "angle max [°]")]).unwrap_or(0.0);
        assert!(max < 0.01, "{row:?}");
    }
}

#[test]
fn naive_triangulation_has_the_most_triangles() {
    let all = tables(quick_output());
    let survey = table_with(&all, "method", "triangles");
    assert_eq!(survey.len(), 2, "ALRF and range camera");
    for t in survey {
        let methods: Vec<&str> = t.rows.iter().map(|r| r[0].as_str()).collect();
        assert_eq!(
            methods,
            [
                "naive triangulation",
                "scanLine V1",
                "scanLine V2",
                "chain code + CDT",
                "α-shape + DP + CDT",
                "convex hull + CDT"
            ]
        );
        let tri = column(t, "triangles");
        let counts: Vec<u64> = t.rows.iter().map(|r| r[tri].parse().unwrap()).collect();
        assert!(counts[1..].iter().all(|&c| c < counts[0]), "{counts:?}");
        // Naive triangulation makes one polygon per triangle; outliners one per region.
        let polygons = column(t, "polygons");
        assert_eq!(t.rows[0][polygons], t.rows[0][tri]);
        let spiky = column(t, "mean spikyness");
        for row in &t.rows {
            let s = number(&row[spiky]).unwrap();
            assert!((0.0..=6.6).contains(&s), "{row:?}");
        }
    }
}

#[test]
fn table_5_1_and_the_ratio_line_are_printed() {
    let text = quick_output();
    let all = tables(text);
    let storage = table_with(&all, "data set", "tri. outline [B]");
    assert_eq!(storage.len(), 1);
    let t = storage[0];
    assert_eq!(t.rows[0][0], "thesis Lab (ALRF)");
    assert_eq!(t.rows[0][column(t, "tri. region [B]")], "3913");
    for row in &t.rows[1..] {
        let outline = number(&row[column(t, "tri. outline [B]")]).unwrap();
        let region = number(&row[column(t, "tri. region [B]")]).unwrap();
        let packed = number(&row[column(t, "plane+outl. packed f32 [B]")]).unwrap();
        assert!(packed > 28.0 && outline > packed && region > outline, "{row:?}");
    }

    let line = text.lines().find(|l| l.starts_with("Ratio: raw PLY / planes map = ")).expect(text);
    let ratio: f64 = line["Ratio: raw PLY / planes map = ".len()..]
        .split('×')
        .next()
        .and_then(|r| r.parse().ok())
        .expect(line);
    assert!(ratio > 1.0, "{line}");
    assert!(line.contains("54.0 / 3.0 = 18.0×"), "{line}");
    let maps = table_with(&all, "map", "ours [MB]");
    assert_eq!(maps.len(), 1);
    let names: BTreeSet<&str> = maps[0].rows.iter().map(|r| r[0].as_str()).collect();
    for name in ["planes", "hybrid", "pc (binary PLY, f32)", "pc (point-cloud map file)"] {
        assert!(names.contains(name), "{names:?}");
    }
}

#[test]
fn jsonl_has_a_row_per_table_row() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rows.jsonl");
    let mut args = QUICK.to_vec();
    args.extend(["--quiet", "--regions", "truth", "--jsonl", path.to_str().unwrap()]);
    let o = patchnav(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // --quiet silences progress, not the tables the experiment exists to print.
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("## 1. Segmentation quality"), "{stdout}");
    assert!(o.stderr.is_empty(), "no progress output: {}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&path).unwrap();
    let mut kinds = BTreeSet::new();
    for line in text.lines() {
        let v: serde_json::Value = serde_json::from_str(line).expect(line);
        kinds.insert(v["table"].as_str().expect(line).to_owned());
    }
    for kind in ["segmentation", "survey", "survey_claims", "fidelity", "patch_storage", "map_size"]
    {
        assert!(kinds.contains(kind), "{kinds:?}");
    }
    let segmentation = text.lines().filter(|l| l.contains(r#""table":"segmentation""#)).count();
    assert_eq!(segmentation, 6);
}

#[test]
fn bad_arguments_are_errors() {
    let o = patchnav(&["experiment", "extraction", "--poses", "0", "--real", "/nonexistent"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--poses"));
}
