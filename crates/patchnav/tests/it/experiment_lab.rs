//! `patchnav experiment lab-timing` and `lab-volume` as a user runs them, at toy sizes: one
//! sparse scan, a coarse trimesh, few iterations and a coarse voxel grid.

use std::collections::BTreeMap;

use crate::common;
use common::*;

/// Small maps: one ALRF scan at 2°, 0.5 m triangles.
const TOY_MAPS: &[&str] =
    &["--scans", "1", "--scan-step-deg", "2", "--mesh-edge", "0.5", "--curved-edge", "0.3"];

/// Checks that `text` is well-formed enough: every tag closes in order, the root is `svg`.
/// Returns the number of times each element name occurs.
fn svg_elements(text: &str) -> BTreeMap<String, usize> {
    let body = text.trim_start();
    let body = match body.strip_prefix("<?xml") {
        Some(rest) => &rest[rest.find("?>").expect("XML declaration closes") + 2..],
        None => body,
    };
    let mut stack: Vec<String> = Vec::new();
    let mut counts = BTreeMap::new();
    let mut rest = body;
    let mut roots = 0;
    while let Some(open) = rest.find('<') {
        assert!(rest[..open].trim().is_empty() || !stack.is_empty(), "text outside the root");
        let close = rest[open..].find('>').expect("tag closes") + open;
        let tag = &rest[open + 1..close];
        rest = &rest[close + 1..];
        if let Some(name) = tag.strip_prefix('/') {
            assert_eq!(stack.pop().as_deref(), Some(name.trim()), "mismatched </{name}>");
            continue;
        }
        let name = tag.split_whitespace().next().expect("element name").trim_end_matches('/');
        assert_eq!(tag.matches('"').count() % 2, 0, "unbalanced quotes in <{tag}>");
        if stack.is_empty() {
            roots += 1;
            assert_eq!(name, "svg", "the root element");
            assert!(tag.contains(r#"xmlns="http://www.w3.org/2000/svg""#));
        }
        *counts.entry(name.to_owned()).or_insert(0) += 1;
        if !tag.ends_with('/') {
            stack.push(name.to_owned());
        }
    }
    assert!(stack.is_empty(), "unclosed elements: {stack:?}");
    assert!(rest.trim().is_empty());
    assert_eq!(roots, 1);
    counts
}

#[test]
fn lab_timing_writes_a_row_per_checkpoint_and_a_plot_per_map() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let mut args = vec!["experiment", "lab-timing", "--starts", "1", "--seeds", "2"];
    args.extend(["--max-iterations", "50", "--checkpoints", "5", "--out", out]);
    args.extend(TOY_MAPS);
    let o = patchnav(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    for needle in ["Table 6.1 analogue", "thesis Table 6.1", "Fig 6.4 analogue", "well over 4 s"] {
        assert!(text.contains(needle), "`{needle}` not in:\n{text}");
    }
    assert!(text.contains("| 50 |"), "the row for K = 50:\n{text}");
    assert!(text.contains("trimesh/planes") && text.contains("pc/planes"), "{text}");
    assert!(text.contains("time per vertex at K = 50"), "{text}");

    let csv = std::fs::read_to_string(dir.path().join("lab-timing.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("map,start,seed,iterations,seconds,vertices"));
    // Per run (map, start, seed): (iterations, seconds, vertices) in order.
    type Checkpoint = (u64, f64, usize);
    let mut runs: BTreeMap<(String, u32, u64), Vec<Checkpoint>> = BTreeMap::new();
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f.len(), 6, "{line}");
        let key = (f[0].to_owned(), f[1].parse().unwrap(), f[2].parse().unwrap());
        let row = (f[3].parse().unwrap(), f[4].parse().unwrap(), f[5].parse().unwrap());
        runs.entry(key).or_default().push(row);
    }
    // 4 maps × 1 start × 2 seeds, checkpoints every 10 iterations to 50.
    assert_eq!(runs.len(), 8, "{:?}", runs.keys());
    for map in ["planes", "hybrid", "trimesh", "pc"] {
        for seed in [1, 2] {
            let run = &runs[&(map.to_owned(), 0, seed)];
            let iterations: Vec<u64> = run.iter().map(|r| r.0).collect();
            assert_eq!(iterations, [10, 20, 30, 40, 50], "{map} seed {seed}");
            assert!(run.iter().all(|r| r.1 > 0.0 && r.1.is_finite()));
            assert!(run.windows(2).all(|w| w[0].1 <= w[1].1), "times grow: {run:?}");
            // An RRT adds at most one vertex per iteration, to the start's one.
            assert!(run.windows(2).all(|w| w[0].2 <= w[1].2), "vertices grow: {run:?}");
            assert!(run.iter().all(|r| r.2 >= 1 && r.2 as u64 <= r.0 + 1), "{run:?}");
        }
    }

    let svg = std::fs::read_to_string(dir.path().join("lab-timing.svg")).unwrap();
    let elements = svg_elements(&svg);
    assert_eq!(elements.get("polyline"), Some(&4), "one median line per map: {elements:?}");
    assert_eq!(elements.get("path"), Some(&4), "one set of quartile bars per map");
    for label in ["planes", "hybrid", "trimesh", "pc", "iterations K", "log scale"] {
        assert!(svg.contains(label), "`{label}` not in the plot");
    }
}

#[test]
fn lab_timing_runs_a_subset_of_maps_in_another_backend() {
    let mut args = vec!["experiment", "lab-timing", "--starts", "2", "--seeds", "1"];
    args.extend(["--max-iterations", "20", "--maps", "planes,hybrid", "--backend", "bbox6d"]);
    // The maps from the scene's exact geometry instead of extraction from scans.
    args.extend(["--source", "scene"]);
    args.extend(TOY_MAPS);
    let o = patchnav(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.contains("hybrid/planes"), "{text}");
    assert_eq!(text.matches("| pc |").count(), 1, "only the thesis's row:\n{text}");
    assert!(text.contains("`bbox6d` backend"), "{text}");
}

/// The rows `| name | volume | … |` of the table under `heading`.
fn table_rows(text: &str, heading: &str) -> Vec<Vec<String>> {
    let start = text.find(heading).unwrap_or_else(|| panic!("`{heading}` not in:\n{text}"));
    text[start..]
        .lines()
        .skip(1)
        .take_while(|l| l.starts_with('|'))
        .map(|l| l.trim_matches('|').split('|').map(|c| c.trim().to_owned()).collect())
        .filter(|cells: &Vec<String>| ["planes", "hybrid", "trimesh", "pc"].contains(&&*cells[0]))
        .collect()
}

#[test]
fn lab_volume_prints_congruence_tables_in_percent() {
    let mut args = vec!["experiment", "lab-volume", "--starts", "2", "--seeds", "1"];
    args.extend(["--prm-seeds", "1", "--max-iterations", "40", "--cells", "32"]);
    args.extend(TOY_MAPS);
    let o = patchnav(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.contains("grid: 32³ cells"), "{text}");
    for heading in ["Table 6.2 analogue", "Table 6.4 analogue"] {
        let rows = table_rows(&text, heading);
        assert_eq!(rows.len(), 4, "{heading}:\n{text}");
        for (r, row) in rows.iter().enumerate() {
            assert_eq!(row.len(), 6, "{row:?}");
            let volume: f64 = row[1].parse().unwrap();
            assert!(volume > 0.0, "{row:?}");
            for (c, cell) in row[2..].iter().enumerate() {
                if c == r {
                    assert_eq!(cell, "–");
                } else {
                    let p: f64 = cell.parse().unwrap_or_else(|_| panic!("{cell} in {row:?}"));
                    assert!((0.0..=100.0).contains(&p), "{row:?}");
                }
            }
        }
    }
    // The thesis's tables are printed beside ours.
    assert!(text.contains("| planes | 9714.015 |"), "{text}");
    assert!(text.contains("| planes | 11859.6544 |"), "{text}");
}

#[test]
fn lab_experiments_refuse_bad_options() {
    let o = patchnav(&["experiment", "lab-timing", "--starts", "5"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let mut args = vec!["experiment", "lab-timing", "--seeds", "0"];
    args.extend(TOY_MAPS);
    let o = patchnav(&args);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).starts_with("error: "), "{}", stderr(&o));
}

#[test]
fn map_build_from_the_lab_scene_writes_each_map_type() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("planes.pmap");
    let f = file.to_str().unwrap();
    let args = ["map", "build", "--scene", "lab", "--kind", "planes", "--backend", "trimesh"];
    let o = patchnav(&[&args[..], &["--out", f]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let info = stdout(&patchnav(&["map", "info", f]));
    assert!(info.contains("backend:         trimesh"), "{info}");
    let planar: u64 = info
        .lines()
        .find_map(|l| l.strip_prefix("planar patches:"))
        .map(|n| n.trim().parse().unwrap())
        .unwrap();
    assert!(planar > 100, "{info}");
    assert!(info.contains("trimesh patches: 0"), "{info}");

    let hybrid = dir.path().join("hybrid.pmap");
    let args = ["map", "build", "--scene", "lab", "--kind", "hybrid", "--backend", "bbox6d"];
    let o = patchnav(&[&args[..], &["--out", hybrid.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let info = stdout(&patchnav(&["map", "info", hybrid.to_str().unwrap()]));
    assert!(info.contains(&format!("planar patches:  {planar}")), "hybrid ⊇ planes: {info}");
    assert!(!info.contains("trimesh patches: 0"), "{info}");

    // A pc map has no patches for a patch backend; --kind needs --scene.
    let args = ["map", "build", "--scene", "lab", "--kind", "pc", "--scans", "1"];
    let o = patchnav(&[&args[..], &["--backend", "polygon", "--out", f]].concat());
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("has no patches"), "{}", stderr(&o));
    let o = patchnav(&["map", "build", "--kind", "pc", "--backend", "polygon", "--out", f]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}
