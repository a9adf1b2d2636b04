//! `patchnav experiment office` as a user meets it, on a tiny problem of its own (a closed box
//! room with four goals in the corners), so the test never depends on the shared benchmark.

use std::path::{Path, PathBuf};

use crate::common;
use common::*;

const START: [f64; 3] = [3.0, 3.0, 1.0];
const GOALS: [[f64; 3]; 4] = [[1.0, 1.0, 1.0], [5.0, 1.0, 1.0], [1.0, 5.0, 1.0], [5.0, 5.0, 1.0]];
const TOLERANCE: f64 = 0.3;

/// A 6 × 6 × 2 m closed room (floor, ceiling, four walls) with two inner walls, at y = 2 and
/// y = 4 for 1.5 ≤ x ≤ 4.5, that block the straight line from the start to every goal; and its
/// problem JSON.
fn write_room(dir: &Path) -> PathBuf {
    std::fs::write(
        dir.join("box.obj"),
        "v 0 0 0\nv 6 0 0\nv 6 6 0\nv 0 6 0\nv 0 0 2\nv 6 0 2\nv 6 6 2\nv 0 6 2\n\
         v 1.5 2 0\nv 4.5 2 0\nv 4.5 2 2\nv 1.5 2 2\n\
         v 1.5 4 0\nv 4.5 4 0\nv 4.5 4 2\nv 1.5 4 2\n\
         f 1 2 3 4\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n\
         f 9 10 11 12\nf 13 14 15 16\n",
    )
    .unwrap();
    let problem = dir.join("box.json");
    let json = serde_json::json!({
        "name": "box", "mesh": "box.obj", "robot_radius": 0.2, "max_step": 0.5,
        "bounds": {"min": [0, 0, 0], "max": [6, 6, 2]}, "start": START, "goals": GOALS,
        "goal_tolerance": TOLERANCE, "iterations": 10, "seeds": [0],
    });
    std::fs::write(&problem, json.to_string()).unwrap();
    problem
}

/// The lines of the table whose title starts with `title`, up to the next blank or title line.
fn table<'a>(text: &'a str, title: &str) -> Vec<&'a str> {
    let mut lines = text.lines().skip_while(|l| !l.starts_with(title));
    assert!(lines.next().is_some(), "no table `{title}` in:\n{text}");
    lines.take_while(|l| !l.is_empty() && !l.starts_with("Table ")).collect()
}

/// The cells of `row` (a planner label) in a table, after the label.
fn cells<'a>(lines: &[&'a str], row: &str) -> Vec<&'a str> {
    let line = lines
        .iter()
        .find(|l| l.starts_with(&format!("{row} ")))
        .unwrap_or_else(|| panic!("no row `{row}` in {lines:#?}"));
    line[row.len()..].split_whitespace().collect()
}

fn numeric(cell: &str) -> bool {
    cell.split('/').all(|part| part.parse::<f64>().is_ok_and(f64::is_finite))
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

#[test]
fn office_prints_every_table_and_writes_json_rows() {
    let dir = tempfile::tempdir().unwrap();
    let problem = write_room(dir.path());
    let jsonl = dir.path().join("runs.jsonl");
    let o = patchnav(&[
        "experiment",
        "office",
        "--problem",
        problem.to_str().unwrap(),
        "--seeds",
        "2",
        "--planners",
        "rrt,prm",
        "--backends",
        "bbox6d,rapier",
        "--max-iterations",
        "20000",
        "--jsonl",
        jsonl.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    for id in ["5.3", "5.4", "5.5", "5.6", "5.7–5.9", "5.10", "5.11"] {
        let ours = table(&text, &format!("Table {id} (ours)"));
        assert!(ours[0].contains("bbox6d (BB6D)") && ours[0].contains("rapier (Bullet)"));
        assert!(!ours[0].contains("polygon"), "only the chosen backends: {}", ours[0]);
        let rows: &[&str] = if id == "5.7–5.9" {
            &["RRT, median", "RRT, lower", "RRT, upper", "PRM, median", "PRM, upper"]
        } else {
            &["RRT", "PRM"]
        };
        for row in rows {
            let c = cells(&ours, row);
            assert_eq!(c.len(), 2, "{id} {row}: {c:?}");
            assert!(c.iter().all(|c| numeric(c)), "{id} {row}: {c:?}");
        }
        assert!(ours.iter().any(|l| l.contains("n/N runs reached all ROIs")), "{ours:#?}");
        assert!(ours.iter().all(|l| !l.starts_with("MA PRM")), "only the chosen planners");
        // The thesis's table follows with all its rows and its numbers.
        let thesis = table(&text, &format!("Table {id} (thesis)"));
        assert!(thesis[0].contains("Simple") && thesis[0].contains("Bullet"));
        assert!(thesis.iter().any(|l| l.starts_with("MA PRM")));
    }
    assert!(table(&text, "Table 5.3 (thesis)").iter().any(|l| l.contains(".010057")));
    assert!(text.contains("RRT is the fastest algorithm"), "{text}");
    assert!(text.contains("thesis: Simple yes, BB6D yes, OPCODE no"), "{text}");

    let rows: Vec<serde_json::Value> = std::fs::read_to_string(&jsonl)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(rows.len(), 2 * 2 * 2, "one row per planner, backend and seed");
    let bound: f64 = GOALS.iter().map(|&g| (distance(START, g) - TOLERANCE).max(0.0)).sum();
    for r in &rows {
        assert_eq!(r["kind"], "planning");
        assert_eq!(r["mode"], "roi");
        assert_eq!(r["problem"], "box");
        assert_eq!(r["solved"], true, "{r}");
        let length = r["path_length"].as_f64().unwrap();
        assert!(length >= bound, "{length} < straight-line bound {bound}: {r}");
        assert_eq!(r["added_length"].as_f64(), Some(length));
        assert_eq!(r["goals"].as_array().unwrap().len(), 4);
        let (steep, turns) = (r["steep_turns"].as_u64().unwrap(), r["turns"].as_u64().unwrap());
        assert!(steep <= turns, "{r}");
        let curviness = r["curviness_deg"].as_f64().unwrap();
        assert!((0.0..=180.0).contains(&curviness), "{r}");
        assert!(r["time_s"].as_f64().unwrap() >= 0.0);
    }
    let seeds: Vec<u64> = rows.iter().map(|r| r["seed"].as_u64().unwrap()).collect();
    assert!(seeds.contains(&0) && seeds.contains(&1));
}

#[test]
fn office_marks_planners_that_cannot_run_and_reports_a_missing_problem() {
    let dir = tempfile::tempdir().unwrap();
    let problem = write_room(dir.path());
    let o = patchnav(&[
        "experiment",
        "office",
        "--problem",
        problem.to_str().unwrap(),
        "--seeds",
        "1",
        "--planners",
        "ma-rrt,rrt-connect",
        "--backends",
        "trimesh,pointcloud",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    let ours = table(&text, "Table 5.3 (ours)");
    let c = cells(&ours, "RRT-Connect");
    assert!(numeric(c[0]) && numeric(c[1]), "RRT-Connect runs on every map: {c:?}");
    let c = cells(&ours, "MA RRT");
    assert!(numeric(c[0]) && c[1] == "–", "the point-cloud map answers no proximity: {c:?}");

    let missing = dir.path().join("nowhere.json");
    let o = patchnav(&["experiment", "office", "--problem", missing.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(err.starts_with("error: ") && err.contains("nowhere.json"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
}

/// The seeds run on all cores; the runs' lines (but for their times) and the tables' counts are
/// those of one thread.
#[test]
fn any_thread_count_gives_the_same_runs() {
    let dir = tempfile::tempdir().unwrap();
    let problem = write_room(dir.path());
    let run = |threads: &str| {
        let jsonl = dir.path().join(format!("runs-{threads}.jsonl"));
        let o = patchnav(&[
            "experiment",
            "office",
            "--problem",
            problem.to_str().unwrap(),
            "--seeds",
            "6",
            "--planners",
            "rrt,prm,ma-rrt",
            "--backends",
            "polygon,bbox6d",
            "--max-iterations",
            "20000",
            "--threads",
            threads,
            "--jsonl",
            jsonl.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let lines: Vec<serde_json::Value> = std::fs::read_to_string(&jsonl)
            .unwrap()
            .lines()
            .map(|l| {
                let mut v: serde_json::Value = serde_json::from_str(l).unwrap();
                v.as_object_mut().unwrap().retain(|k, _| !k.contains("time"));
                v
            })
            .collect();
        lines
    };
    let one = run("1");
    assert_eq!(one.len(), 3 * 2 * 6);
    assert_eq!(run("2"), one);
    assert_eq!(run("5"), one);
}
