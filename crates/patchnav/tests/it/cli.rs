//! The command line as a user meets it: real processes, real files, exit codes and messages.

use std::path::{Path, PathBuf};

use crate::common;
use common::*;

#[test]
fn info_describes_every_fixture_format() {
    let o = patchnav(&["info", &fixture("lab-alrf-2deg.ply")]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.contains("format:     PLY"), "{text}");
    assert!(text.contains("organised:  136 × 91 (12376 pixels"), "{text}");
    assert!(text.contains("attributes: labels"), "{text}");
    assert!(text.contains("sensor:     at"), "{text}");

    let pcd = stdout(&patchnav(&["info", &fixture("lab-tof.pcd")]));
    let png = stdout(&patchnav(&["info", &fixture("lab-tof-depth.png")]));
    assert!(pcd.contains("organised:  176 × 144"), "{pcd}");
    assert!(png.contains("organised:  176 × 144"), "{png}");
    let points = |t: &str| t.lines().find(|l| l.starts_with("points:")).unwrap().to_owned();
    assert_eq!(points(&pcd), points(&png), "the PCD and PNG fixtures are one frame");

    for name in ["terrain-ramp-stereo.bin", "lab-alrf-2deg.3d"] {
        let o = patchnav(&["info", &fixture(name)]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        assert!(stdout(&o).contains("points:"), "{name}");
    }
}

#[test]
fn depth_camera_choice_scales_png_depth() {
    let png = fixture("lab-tof-depth.png");
    let far = |args: &[&str]| -> f64 {
        let o = patchnav(args);
        assert!(o.status.success(), "{}", stderr(&o));
        let text = stdout(&o);
        let line = text.lines().find(|l| l.starts_with("bounds:")).unwrap().to_owned();
        // "bounds:     (x, y, z) .. (x, y, z) m, ...": the far z of the box.
        let max = line.split("..").nth(1).unwrap();
        let inside = &max[max.find('(').unwrap() + 1..max.find(')').unwrap()];
        inside.split(',').nth(2).unwrap().trim().parse().unwrap()
    };
    let sidecar = far(&["info", &png]);
    let openni = far(&["info", &png, "--depth-camera", "openni"]);
    let tum = far(&["info", &png, "--depth-camera", "tum"]);
    assert!((sidecar - openni).abs() < 1e-3, "the sidecar says millimetres: {sidecar} vs {openni}");
    assert!((tum * 5.0 - openni).abs() < 1e-2, "TUM is 1/5000 m per unit: {tum} vs {openni}");
    assert_one_line_error(
        &patchnav(&["info", &fixture("lab-tof.pcd"), "--depth-camera", "tum"]),
        "--depth-camera",
    );
}

#[test]
fn convert_round_trips_through_formats() {
    let dir = tempfile::tempdir().unwrap();
    let pcd = dir.path().join("scan.pcd");
    let xyz = dir.path().join("scan.xyz");
    let back = dir.path().join("back.ply");
    let src = fixture("lab-alrf-2deg.ply");
    for (from, to) in [(src.as_str(), &pcd), (pcd.to_str().unwrap(), &xyz)] {
        let o = patchnav(&["--quiet", "convert", from, to.to_str().unwrap()]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(stdout(&o).is_empty(), "--quiet prints nothing");
    }
    let o = patchnav(&["convert", xyz.to_str().unwrap(), back.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let points = |p: &str| {
        stdout(&patchnav(&["info", p]))
            .lines()
            .find(|l| l.starts_with("points:"))
            .unwrap()
            .to_owned()
    };
    assert_eq!(points(&src), points(back.to_str().unwrap()));
    assert_eq!(points(&src), points(pcd.to_str().unwrap()));
}

#[test]
fn simulate_writes_scans_poses_and_truth() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("lab");
    let o = patchnav(&[
        "simulate",
        "lab",
        "--sensor",
        "alrf",
        "--poses",
        "2",
        "--step-deg",
        "5",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("wrote 2 scans of `lab`"), "{}", stdout(&o));
    for f in ["scan000.ply", "scan001.ply", "scan000_truth.ply", "poses.json", "scene.json"] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let info = stdout(&patchnav(&["info", out.join("scan001.ply").to_str().unwrap()]));
    assert!(info.contains("organised:  55 × 37"), "{info}");
    let truth = stdout(&patchnav(&["info", out.join("scan001_truth.ply").to_str().unwrap()]));
    assert!(truth.contains("true_range"), "{truth}");
    let poses: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("poses.json")).unwrap()).unwrap();
    assert_eq!(poses["scans"].as_array().unwrap().len(), 2);
    let scene: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("scene.json")).unwrap()).unwrap();
    assert!(scene["surfaces"].as_array().unwrap().len() > 10);
}

#[test]
fn simulate_is_deterministic_for_a_seed() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str, seed: &str| -> PathBuf {
        let out = dir.path().join(name);
        let o = patchnav(&[
            "-q",
            "simulate",
            "terrain-ramp",
            "--sensor",
            "tof",
            "--poses",
            "1",
            "--seed",
            seed,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        out.join("scan000.ply")
    };
    let a = std::fs::read(run("a", "3")).unwrap();
    let b = std::fs::read(run("b", "3")).unwrap();
    let c = std::fs::read(run("c", "4")).unwrap();
    assert_eq!(a, b);
    assert_ne!(a, c);
}

#[test]
fn errors_are_one_line_with_exit_code_one() {
    assert_one_line_error(&patchnav(&["info", "no/such/file.ply"]), "no/such/file.ply");
    assert_one_line_error(&patchnav(&["info", "file.unknown"]), "extension");

    let dir = tempfile::tempdir().unwrap();
    let bytes = std::fs::read(fixture("lab-alrf-2deg.ply")).unwrap();
    let cut = dir.path().join("cut.ply");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    assert_one_line_error(&patchnav(&["info", cut.to_str().unwrap()]), "cut.ply");

    let out = dir.path().join("x");
    let out = out.to_str().unwrap();
    assert_one_line_error(
        &patchnav(&["simulate", "moon", "--sensor", "alrf", "--out", out]),
        "unknown scene `moon`",
    );
    assert_one_line_error(
        &patchnav(&["simulate", "lab", "--sensor", "alrf", "--poses", "0", "--out", out]),
        "--poses",
    );
    assert_one_line_error(
        &patchnav(&["simulate", "lab", "--sensor", "tof", "--step-deg", "1", "--out", out]),
        "--step-deg",
    );
    assert_one_line_error(
        &patchnav(&["simulate", "lab", "--sensor", "alrf", "--step-deg=-3", "--out", out]),
        "--step-deg",
    );
}

/// A small OBJ: a 4 × 3 floor of two triangles and a wall of two quads meeting in a T-junction.
fn write_small_obj(dir: &Path) -> PathBuf {
    let obj = dir.join("room.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 4 0 0\nv 4 3 0\nv 0 3 0\n\
         v 0 0 0\nv 2 0 0\nv 2 0 2\nv 0 0 2\n\
         v 2 0 0\nv 4 0 0\nv 4 0 2\nv 2 0 2\n\
         f 1 2 3\nf 1 3 4\nf 5 6 7 8\nf 9 10 11 12\n",
    )
    .unwrap();
    obj
}

fn info_field(text: &str, field: &str) -> String {
    text.lines()
        .find(|l| l.starts_with(field))
        .unwrap_or_else(|| panic!("no `{field}` in {text}"))
        .split(':')
        .nth(1)
        .unwrap()
        .trim()
        .to_owned()
}

#[test]
fn map_build_and_info_for_every_backend() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write_small_obj(dir.path());
    for backend in ["polygon", "bbox6d", "trimesh", "rapier"] {
        let out = dir.path().join(format!("{backend}.pmap"));
        let o = patchnav(&[
            "map",
            "build",
            obj.to_str().unwrap(),
            "--backend",
            backend,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{backend}: {}", stderr(&o));
        assert!(stdout(&o).contains("2 planar patches"), "{}", stdout(&o));
        let info = stdout(&patchnav(&["map", "info", out.to_str().unwrap()]));
        assert!(info_field(&info, "backend").starts_with(backend), "{info}");
        assert_eq!(info_field(&info, "planar patches"), "2", "{info}");
        assert!(info.contains("size 4.000 × 3.000 × 2.000 m"), "{info}");
        let file_bytes: u64 = info_field(&info, "file bytes").parse().unwrap();
        assert_eq!(file_bytes, std::fs::metadata(&out).unwrap().len());
        assert!(info_field(&info, "memory bytes").parse::<u64>().unwrap() > 0);
    }
    // A map file converts to another backend.
    let back = dir.path().join("again.pmap");
    let from = dir.path().join("polygon.pmap");
    let o = patchnav(&[
        "map",
        "build",
        from.to_str().unwrap(),
        "--backend",
        "bbox6d",
        "--out",
        back.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    // A point cloud builds the point-cloud backend, and only that.
    let pc = dir.path().join("cloud.pmap");
    let scan = fixture("lab-alrf-2deg.ply");
    let o = patchnav(&[
        "map",
        "build",
        &scan,
        "--backend",
        "pointcloud",
        "--out",
        pc.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let info = stdout(&patchnav(&["map", "info", pc.to_str().unwrap()]));
    let scan_points = info_field(&stdout(&patchnav(&["info", &scan])), "points");
    assert_eq!(info_field(&info, "points"), scan_points);
    assert_one_line_error(
        &patchnav(&[
            "map",
            "build",
            &scan,
            "--backend",
            "polygon",
            "--out",
            back.to_str().unwrap(),
        ]),
        "no patches",
    );
    assert_one_line_error(
        &patchnav(&[
            "map",
            "build",
            obj.to_str().unwrap(),
            "--backend",
            "pointcloud",
            "--out",
            back.to_str().unwrap(),
        ]),
        "--spacing",
    );
    // With --spacing the patches are sampled: the 4 × 3 floor and the 4 × 2 wall at 0.1 m give
    // at least 41 × 31 + 41 × 21 points.
    let sampled = dir.path().join("sampled.pmap");
    let o = patchnav(&[
        "map",
        "build",
        obj.to_str().unwrap(),
        "--backend",
        "pointcloud",
        "--spacing",
        "0.1",
        "--out",
        sampled.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let info = stdout(&patchnav(&["map", "info", sampled.to_str().unwrap()]));
    let n: usize = info_field(&info, "points").parse().unwrap();
    assert!(n >= 41 * 31 + 41 * 21, "{n} points");
}

#[test]
fn corrupt_map_files_are_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write_small_obj(dir.path());
    let good = dir.path().join("good.pmap");
    let o = patchnav(&[
        "-q",
        "map",
        "build",
        obj.to_str().unwrap(),
        "--backend",
        "polygon",
        "--out",
        good.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(&good).unwrap();
    let cut = dir.path().join("cut.pmap");
    std::fs::write(&cut, &bytes[..bytes.len() - 3]).unwrap();
    assert_one_line_error(&patchnav(&["map", "info", cut.to_str().unwrap()]), "truncated");
    let mut flipped = bytes.clone();
    let last = flipped.len() - 1;
    flipped[last] ^= 0x10;
    let bad = dir.path().join("bad.pmap");
    std::fs::write(&bad, &flipped).unwrap();
    assert_one_line_error(&patchnav(&["map", "info", bad.to_str().unwrap()]), "corrupt");
    let mut future = bytes;
    future[8] = 9;
    std::fs::write(&bad, &future).unwrap();
    assert_one_line_error(&patchnav(&["map", "info", bad.to_str().unwrap()]), "version 9");
    assert_one_line_error(&patchnav(&["map", "info", obj.to_str().unwrap()]), "not a patch map");
}

#[test]
fn plan_reaches_goals_deterministically_and_writes_obj_lines() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write_small_obj(dir.path());
    let map = dir.path().join("room.pmap");
    let o = patchnav(&[
        "-q",
        "map",
        "build",
        obj.to_str().unwrap(),
        "--backend",
        "bbox6d",
        "--out",
        map.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let roadmap = dir.path().join("roadmap.obj");
    let path = dir.path().join("path.obj");
    let plan = |seed: &str| {
        patchnav(&[
            "plan",
            map.to_str().unwrap(),
            "--start",
            "0.5,2.5,1",
            "--goal",
            "3.5,2.5,1.5",
            "--goal",
            "3.5,0.5,0.5",
            "--radius",
            "0.2",
            "--step",
            "0.5",
            "--seed",
            seed,
            "--roadmap-out",
            roadmap.to_str().unwrap(),
            "--path-out",
            path.to_str().unwrap(),
        ])
    };
    let shortcut = patchnav(&[
        "plan",
        map.to_str().unwrap(),
        "--start",
        "0.5,2.5,1",
        "--goal",
        "3.5,0.5,0.5",
        "--radius",
        "0.2",
        "--step",
        "0.5",
        "--shortcut",
    ]);
    assert!(shortcut.status.success(), "{}", stderr(&shortcut));
    let text = stdout(&shortcut);
    let metres = |line: &str| -> f64 {
        line.split(", ")
            .find(|p| p.ends_with(" m"))
            .unwrap()
            .trim_end_matches(" m")
            .parse()
            .unwrap()
    };
    let raw = text.lines().find(|l| l.starts_with("goal 0")).unwrap();
    let short = text.lines().find(|l| l.trim_start().starts_with("shortcut:")).unwrap();
    assert!(metres(short) <= metres(raw) + 1e-9, "{text}");
    let first = plan("7");
    assert!(first.status.success(), "{}", stderr(&first));
    let text = stdout(&first);
    assert_eq!(info_field(&text, "status"), "Exact", "{text}");
    assert!(text.contains("goal 0 (3.50, 2.50, 1.50): reached"), "{text}");
    assert!(text.contains("goal 1 (3.50, 0.50, 0.50): reached"), "{text}");
    assert_eq!(stdout(&plan("7")), text, "same seed, same run");
    let lines = std::fs::read_to_string(&path).unwrap();
    assert!(lines.starts_with("v 0.5 2.5 1\n"), "{lines}");
    assert_eq!(lines.lines().filter(|l| l.starts_with("l ")).count(), 1);
    let graph = std::fs::read_to_string(&roadmap).unwrap();
    let vertices = graph.lines().filter(|l| l.starts_with("v ")).count();
    assert_eq!(vertices.to_string(), info_field(&text, "vertices"));

    // A start inside the wall's radius is an outcome, not an error.
    let o = patchnav(&[
        "plan",
        map.to_str().unwrap(),
        "--start",
        "2,0.1,1",
        "--goal",
        "3.5,2.5,1",
        "--radius",
        "0.2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(info_field(&stdout(&o), "status"), "InvalidStart");
    // A malformed point is a usage error (exit code 2, clap's message).
    let o = patchnav(&[
        "plan",
        map.to_str().unwrap(),
        "--start",
        "1,2",
        "--goal",
        "3,2,1",
        "--radius",
        "0.2",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("is not three finite numbers x,y,z"), "{}", stderr(&o));
}

#[test]
fn plan_offers_rrt_connect_and_evasion_rrt_where_the_map_allows() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write_small_obj(dir.path());
    let map = dir.path().join("room.pmap");
    let cloud = dir.path().join("cloud.pmap");
    for (backend, out, extra) in [("trimesh", &map, None), ("pointcloud", &cloud, Some("0.05"))] {
        let mut args = vec!["-q", "map", "build", obj.to_str().unwrap(), "--backend", backend];
        if let Some(spacing) = extra {
            args.extend(["--spacing", spacing]);
        }
        args.extend(["--out", out.to_str().unwrap()]);
        let o = patchnav(&args);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let plan = |map: &Path, planner: &str, goals: &[&str]| {
        let mut args =
            vec!["plan", map.to_str().unwrap(), "--start", "0.5,2.5,1", "--radius", "0.2"];
        for g in goals {
            args.extend(["--goal", g]);
        }
        args.extend(["--step", "0.5", "--planner", planner]);
        patchnav(&args)
    };
    for planner in ["rrt-connect", "evasion-rrt", "prm", "prm-star"] {
        let o = plan(&map, planner, &["3.5,2.5,1.5"]);
        assert!(o.status.success(), "{planner}: {}", stderr(&o));
        assert_eq!(info_field(&stdout(&o), "status"), "Exact", "{planner}: {}", stdout(&o));
        assert!(stdout(&o).contains("curviness"), "{}", stdout(&o));
    }
    let o = plan(&map, "rrt-connect", &["3.5,2.5,1.5", "3.5,0.5,0.5"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(info_field(&stdout(&o), "status"), "Exact", "{}", stdout(&o));
    assert_one_line_error(&plan(&cloud, "evasion-rrt", &["3.5,2.5,1.5"]), "`pointcloud` map");
    for planner in ["ma-prm", "ma-rrt"] {
        assert_one_line_error(&plan(&cloud, planner, &["3.5,2.5,1.5"]), "proximity");
        let o = plan(&map, planner, &["3.5,2.5,1.5"]);
        assert!(o.status.success(), "{planner}: {}", stderr(&o));
        assert!(stdout(&o).contains("status:"), "{}", stdout(&o));
    }
    let o = plan(&cloud, "rrt", &["3.5,2.5,1.5"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(info_field(&stdout(&o), "status"), "Exact", "{}", stdout(&o));
}

#[test]
fn plan_runs_a_shared_format_problem_as_json_lines() {
    let dir = tempfile::tempdir().unwrap();
    write_small_obj(dir.path());
    let problem = dir.path().join("room.json");
    std::fs::write(
        &problem,
        r#"{"name": "room", "mesh": "room.obj", "robot_radius": 0.2, "max_step": 0.5,
            "bounds": {"min": [0, 0, 0], "max": [4, 3, 2]}, "start": [0.5, 2.5, 1],
            "goals": [[3.5, 2.5, 1.5], [3.5, 0.5, 0.5]], "goal_tolerance": 0.3,
            "iterations": 300, "seeds": [4, 5, 6], "unknown_key": "ignored"}"#,
    )
    .unwrap();
    let rows = |mode: &str, backend: &str| -> Vec<serde_json::Value> {
        let o = patchnav(&[
            "plan",
            "--problem",
            problem.to_str().unwrap(),
            "--backend",
            backend,
            "--mode",
            mode,
        ]);
        assert!(o.status.success(), "{mode}: {}", stderr(&o));
        stdout(&o).lines().map(|l| serde_json::from_str(l).unwrap()).collect()
    };
    let roi = rows("roi", "bbox6d");
    assert_eq!(roi.len(), 3, "one line per seed");
    for r in &roi {
        assert_eq!(r["kind"], "planning");
        assert_eq!(r["problem"], "room");
        assert_eq!(r["solved"], true, "{r}");
        assert_eq!(r["goals"].as_array().unwrap().len(), 2);
        assert!(r["path_length"].as_f64().unwrap() > 0.0);
    }
    let solve = rows("solve", "trimesh");
    assert_eq!(solve.len(), 6, "one line per seed and goal");
    assert_eq!(solve[1]["goal"], 1);
    let explore = rows("explore", "pointcloud");
    assert!(explore.iter().all(|r| r["iterations"] == 300 && r["solved"] == false));
    // Same seeds, same results (up to the timing).
    let again = rows("roi", "bbox6d");
    for (a, b) in roi.iter().zip(&again) {
        assert_eq!(a["vertices"], b["vertices"]);
        assert_eq!(a["path_length"], b["path_length"]);
    }
    // The Evasion RRT needs specific hits, which a point-cloud map cannot give: its runs are
    // recorded as skipped, not failed.
    let o = patchnav(&[
        "plan",
        "--problem",
        problem.to_str().unwrap(),
        "--planner",
        "evasion-rrt",
        "--backend",
        "pointcloud",
        "--mode",
        "roi",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let skipped: Vec<serde_json::Value> =
        stdout(&o).lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(skipped.len(), 3);
    assert!(skipped.iter().all(|r| r["skipped"].as_str().unwrap().contains("`pointcloud` map")));
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, r#"{"mesh": "room.obj"}"#).unwrap();
    assert_one_line_error(&patchnav(&["plan", "--problem", bad.to_str().unwrap()]), "missing");
}
