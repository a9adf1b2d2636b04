//! `patchnav run CONFIG.toml` as a user meets it: real processes, real files, exit codes and
//! messages.

use serde_json::Value;
use std::path::Path;
use std::process::Output;

use crate::common;
use common::*;

/// Asserts a failure reported as one `error:` line and exit code 1.
fn assert_one_line_error(o: &Output, needle: &str) {
    assert_eq!(o.status.code(), Some(1), "stdout: {}\nstderr: {}", stdout(o), stderr(o));
    let err = stderr(o);
    assert_eq!(err.lines().count(), 1, "one line expected, got: {err}");
    assert!(err.starts_with("error: "), "{err}");
    assert!(err.contains(needle), "`{needle}` not in: {err}");
}

fn results(dir: &Path) -> Value {
    let text = std::fs::read_to_string(dir.join("results.json")).expect("results.json written");
    serde_json::from_str(&text).expect("results.json is JSON")
}

/// Every file `results.json` lists exists with its size.
fn assert_files_listed(dir: &Path, r: &Value) {
    for f in r["files"].as_array().unwrap() {
        let path = dir.join(f["path"].as_str().unwrap());
        let bytes =
            std::fs::metadata(&path).unwrap_or_else(|_| panic!("{} missing", path.display())).len();
        assert_eq!(bytes, f["bytes"].as_u64().unwrap(), "{}", path.display());
    }
}

#[test]
fn lab_scans_with_poses_tof_and_terrain() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scans = d.join("scans");
    let o = patchnav(&[
        "simulate",
        "lab",
        "--sensor",
        "alrf",
        "--poses",
        "2",
        "--out",
        scans.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = patchnav(&[
        "-q",
        "tof",
        "simulate",
        "rack-and-door",
        "--out",
        d.join("tof").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let config = format!(
        "[input]\nscans = [\"scans/scan000.ply\", \"scans/scan001.ply\"]\nposes = \"scans/poses.json\"\n\
         [plan]\nstart = [0.8, 1.0, 1.0]\ngoals = [[11.0, 1.0, 1.0], [4.0, 6.0, 1.0]]\n\
         [tof]\nrange = \"tof/range.png\"\namplitude = \"tof/amplitude.png\"\nmeta = \"tof/meta.json\"\n\
         [terrain]\nframe = \"{}\"\naxes = \"camera\"\nsensor_height = 0.45\n[output]\ndir = \"result\"\n",
        fixture("terrain-ramp-stereo.bin")
    );
    std::fs::write(d.join("lab.toml"), config).unwrap();
    let o = patchnav(&["run", d.join("lab.toml").to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.contains("2 scans") && text.contains("report:"), "{text}");
    let out = d.join("result");
    assert!(std::fs::metadata(out.join("report.html")).unwrap().len() > 10_000);
    let r = results(&out);
    let kinds: Vec<&str> =
        r["maps"].as_array().unwrap().iter().map(|m| m["kind"].as_str().unwrap()).collect();
    assert_eq!(kinds, ["planes", "hybrid", "trimesh", "pc"]);
    for m in r["maps"].as_array().unwrap() {
        let held = m["planar_patches"].as_u64().unwrap()
            + m["trimesh_patches"].as_u64().unwrap()
            + m["points"].as_u64().unwrap();
        assert!(held > 0, "an empty map: {m}");
    }
    // The pc map holds every scanned point.
    assert_eq!(r["maps"][3]["points"], r["scene"]["points"]);
    assert_eq!(r["scene"]["scan_positions"].as_array().unwrap().len(), 2);
    let plans = r["plans"].as_array().unwrap();
    assert_eq!(plans.len(), 4 * 2, "rrt and prm on four maps, one seed");
    for p in plans.iter().filter(|p| p["solved"] == true) {
        assert_eq!(p["paths"].as_array().unwrap().len(), 2, "{}", p["planner"]);
        // A path is at least as long as the straight lines to the goals, less the tolerance.
        let straight = 10.2 + 3.2f64.hypot(5.0) - 2.0 * 0.5;
        assert!(p["path_length"].as_f64().unwrap() >= straight, "{} {}", p["map"], p["planner"]);
    }
    assert!(plans.iter().any(|p| p["solved"] == true), "no plan solved");
    assert!(r["tof"]["outcomes"].as_array().unwrap().len() == 176 * 144);
    assert!(r["tof"]["discarded_percent"].as_f64().is_some());
    // The rack-and-door frame wraps: region unwrapping (the default) keeps part of it and
    // drops what stays ambiguous.
    let outcomes = r["tof"]["outcomes"].as_array().unwrap();
    assert!(outcomes.iter().any(|o| o == 0) && outcomes.iter().any(|o| o == 2));
    assert!(r["tof"]["method"].as_str().unwrap().starts_with("regions"), "{}", r["tof"]["method"]);
    assert_eq!(r["terrain"]["sectors"].as_array().unwrap().len(), 3);
    // The fixture is a stereo frame of a ramp (camera axes).
    assert_eq!(r["terrain"]["class"], "ramp");
    assert!(r["volume"].is_null() && r["timing"].as_array().unwrap().is_empty());
    assert_files_listed(&out, &r);
    assert!(out.join("map-trimesh.ply").is_file() && out.join("terrain-hough.png").is_file());
}

/// A 6 × 4 × 2.5 m box room with a 1 m thick wall from the south side to y = 2.5, as OBJ.
fn room_obj() -> String {
    let mut v = Vec::new();
    let mut f = Vec::new();
    let mut cuboid = |lo: [f64; 3], hi: [f64; 3]| {
        let base = v.len() + 1;
        for k in 0..8 {
            v.push([
                if k & 1 == 0 { lo[0] } else { hi[0] },
                if k & 2 == 0 { lo[1] } else { hi[1] },
                if k & 4 == 0 { lo[2] } else { hi[2] },
            ]);
        }
        for q in
            [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
        {
            f.push([base + q[0], base + q[1], base + q[2]]);
            f.push([base + q[0], base + q[2], base + q[3]]);
        }
    };
    cuboid([0.0, 0.0, 0.0], [6.0, 4.0, 2.5]);
    cuboid([2.5, 0.0, 0.0], [3.5, 2.5, 2.5]);
    let mut text = String::new();
    for p in v {
        text += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for t in f {
        text += &format!("f {} {} {}\n", t[0], t[1], t[2]);
    }
    text
}

const ROOM_PLAN: &str =
    "[plan]\nstart = [1.0, 1.0, 1.0]\ngoals = [[5.0, 1.0, 1.0]]\nplanners = [\"rrt\"]\n";

#[test]
fn mesh_room_with_one_planner() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("room.obj"), room_obj()).unwrap();
    std::fs::write(
        d.join("room.toml"),
        format!(
            "[input]\nmesh = \"room.obj\"\n{ROOM_PLAN}seeds = [3, 4]\n[output]\nwrite_3d = false\n"
        ),
    )
    .unwrap();
    let o = patchnav(&["run", d.join("room.toml").to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = d.join("out/run");
    assert!(out.join("report.html").is_file());
    let r = results(&out);
    let kinds: Vec<&str> =
        r["maps"].as_array().unwrap().iter().map(|m| m["kind"].as_str().unwrap()).collect();
    assert_eq!(kinds, ["planes", "hybrid", "trimesh", "pc"]);
    // 6 room faces + 5 visible faces of the wall (its bottom lies on the floor, still a face).
    let planar = r["maps"][0]["planar_patches"].as_u64().unwrap();
    assert!((6..=12).contains(&planar), "{planar}");
    // The trimesh map: the same surfaces as triangles, unsplit (no maps.mesh_edge).
    let trimesh = &r["maps"][2];
    assert_eq!(trimesh["planar_patches"], 0);
    assert_eq!(trimesh["trimesh_patches"].as_u64().unwrap(), planar);
    assert_eq!(trimesh["triangles"], r["maps"][0]["triangles"]);
    assert_eq!(r["scene"]["name"], "room");
    let plans = r["plans"].as_array().unwrap();
    assert_eq!(plans.len(), 4 * 2);
    for p in plans {
        assert_eq!(p["planner"], "rrt");
        assert_eq!(p["solved"], true, "{}", p["map"]);
        // The wall blocks the straight 4 m line: the path goes round its end at y = 2.5.
        let length = p["path_length"].as_f64().unwrap();
        assert!(length > 4.0 + 1.0, "{length}");
        for q in p["paths"][0].as_array().unwrap() {
            let (x, y) = (q[0].as_f64().unwrap(), q[1].as_f64().unwrap());
            assert!(!((2.2..3.8).contains(&x) && y < 2.8), "vertex ({x}, {y}) inside the wall");
        }
    }
    // Without 3D files only the Hough PNG could be listed, and there is no terrain.
    assert!(r["files"].as_array().unwrap().is_empty());
    assert!(!out.join("map-planes.ply").exists());
}

#[test]
fn bad_configs_fail_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("room.obj"), room_obj()).unwrap();
    let cases = [
        (format!("[input]\nmesh = \"room.obj\"\ncolour = 1\n{ROOM_PLAN}"), "unknown field `colour`"),
        (format!("[input]\nmesh = \"room.obj\"\ncloud = \"room.obj\"\n{ROOM_PLAN}"), "exactly one of"),
        (format!("[input]\nmesh = \"nowhere.obj\"\n{ROOM_PLAN}"), "input.mesh: no file"),
        (format!("[input]\nmesh = \"room.obj\"\n{ROOM_PLAN}radius = nan\n"), "plan.radius"),
        (
            "[input]\nmesh = \"room.obj\"\n[plan]\nstart = [1.0, 1.0, 1.0]\ngoals = [[5.0, 1.0, 1.0]]\nplanners = [\"dijkstra\"]\n".to_owned(),
            "plan.planners[0]: unknown value `dijkstra`",
        ),
        (format!("[input]\nmesh = \"room.obj\"\n[maps]\ntypes = [\"voxels\"]\n{ROOM_PLAN}"), "maps.types[0]: unknown value `voxels`"),
        (format!("[input]\nmesh = \"room.obj\"\n{ROOM_PLAN}[timing]\niterations = -5\n"), "timing.iterations must be in 1..="),
        (format!("[input]\nmesh = \"room.obj\"\n{ROOM_PLAN}[volume]\ncells = 0\n"), "volume.cells must be in 1..=1024, not 0"),
        (format!("[input]\nmesh = \"room.obj\"\n{ROOM_PLAN}[volume]\nplanner = \"rrt-star\"\n"), "volume.planner: unknown value `rrt-star`"),
        (format!("[input]\nmesh = \"room.obj\"\n{ROOM_PLAN}[timing]\nseeds = [-1]\n"), "timing.seeds: invalid value"),
        (format!("[input]\nmesh = \"room.obj\"\n{ROOM_PLAN}[timing]\nstarts = [[1.0, 1.0, 1.0], [9.0, 1.0, 1.0]]\n"),
            "timing.starts[1] (9, 1, 1) is outside the planes map's box"),
        (format!("[input]\nmesh = \"room.obj\"\n{ROOM_PLAN}[volume]\nstarts = [[2.6, 1.0, 1.0]]\n"),
            "volume.starts[0] (2.6, 1, 1) is not free on the planes map"),
        (format!("[input]\nmesh = \"room.obj\"\n[maps]\ntypes = [\"planes\"]\nmesh_edge = 0.5\n{ROOM_PLAN}"),
            "maps.mesh_edge applies to the trimesh map"),
        ("[input]\nmesh = \"room.obj\"\n[plan]\ngoals = [[5.0, 1.0, 1.0]]\n".to_owned(), "missing field `start`"),
        ("[input]\nmesh = \"room.obj\"\n[plan]\nstart = [2.6, 1.0, 1.0]\ngoals = [[5.0, 1.0, 1.0]]\n".to_owned(),
            "plan.start (2.6, 1, 1) is not free on the planes map"),
        ("[input]\nmesh = \"room.obj\"\n[plan]\nstart = [9.0, 1.0, 1.0]\ngoals = [[5.0, 1.0, 1.0]]\n".to_owned(),
            "outside the planes map's box"),
        (format!("[input]\nmesh = \"room.obj\"\n{ROOM_PLAN}[terrain]\nframe = \"f.ply\"\nresolution = 0\n"), "terrain.resolution"),
        ("[input]\nmesh = \"room.obj\"\n\ncolour = 1\n".to_owned(), "line 4: unknown field `colour`"),
    ];
    for (text, needle) in &cases {
        std::fs::write(d.join("bad.toml"), text).unwrap();
        let o = patchnav(&["run", d.join("bad.toml").to_str().unwrap()]);
        assert_one_line_error(&o, needle);
    }
    assert!(!d.join("out/run/results.json").exists(), "no results from a bad config");
}

/// Every number of `v` (an array of numbers).
fn numbers(v: &Value) -> Vec<f64> {
    v.as_array().expect("an array").iter().map(|x| x.as_f64().expect("a number")).collect()
}

#[test]
fn mesh_room_timing_and_volume_on_planes_and_trimesh() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("room.obj"), room_obj()).unwrap();
    let config = format!(
        "[input]\nmesh = \"room.obj\"\n[maps]\ntypes = [\"planes\", \"trimesh\"]\nmesh_edge = 0.5\n\
         {ROOM_PLAN}[timing]\niterations = 200\ncheckpoints = 4\nseeds = [1, 2, 3]\n\
         starts = [[1.0, 1.0, 1.0], [5.0, 3.0, 1.5]]\n[volume]\ncells = 40\n[output]\nwrite_3d = false\n"
    );
    std::fs::write(d.join("room.toml"), config).unwrap();
    let o = patchnav(&["run", d.join("room.toml").to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.contains("rrt timing (2 starts × 3 seeds") && text.contains("explored volume"));
    let out = d.join("out/run");
    let r = results(&out);

    // The planes / trimesh pair: the same surfaces, the trimesh map split into 0.5 m triangles.
    let (planes, trimesh) = (&r["maps"][0], &r["maps"][1]);
    assert_eq!(
        (planes["kind"].as_str(), trimesh["kind"].as_str()),
        (Some("planes"), Some("trimesh"))
    );
    assert_eq!(trimesh["planar_patches"], 0);
    assert!(
        trimesh["triangles"].as_u64().unwrap() > 10 * planes["triangles"].as_u64().unwrap(),
        "{trimesh}"
    );

    // Fig 6.4: one curve per map, checkpoints rising to K, times rising, quartiles ordered.
    let timing = r["timing"].as_array().unwrap();
    let names: Vec<&str> = timing.iter().map(|c| c["map"].as_str().unwrap()).collect();
    assert_eq!(names, ["planes", "trimesh"]);
    for c in timing {
        let k = numbers(&c["iterations"]);
        assert!(k.len() >= 3 && k.windows(2).all(|w| w[0] < w[1]), "{k:?}");
        assert_eq!(*k.last().unwrap(), 200.0);
        let (q1, m, q3) = (numbers(&c["q1_ms"]), numbers(&c["median_ms"]), numbers(&c["q3_ms"]));
        assert!(m.windows(2).all(|w| w[0] <= w[1]) && m[0] > 0.0, "{m:?}");
        for i in 0..m.len() {
            assert!(q1[i] <= m[i] && m[i] <= q3[i], "{q1:?} {m:?} {q3:?}");
        }
    }

    // Table 6.2: from the timed runs (the defaults), two maps, percentages off the diagonal.
    let v = &r["volume"];
    assert_eq!(v["planner"], "rrt");
    assert_eq!((v["runs"].as_u64(), v["iterations"].as_u64()), (Some(6), Some(200)));
    assert_eq!(v["maps"], serde_json::json!(["planes", "trimesh"]));
    // The room (6 × 4 × 2.5 m) less the wall, grown by the robot radius at most.
    let free = 6.0 * 4.0 * 2.5 - 1.0 * 2.5 * 2.5;
    for x in numbers(&v["volumes_m3"]) {
        assert!(x > 0.1 * free && x < 6.6 * 4.6 * 3.1, "{x}");
    }
    let table = v["table"].as_array().unwrap();
    for (i, row) in table.iter().enumerate() {
        for (j, cell) in row.as_array().unwrap().iter().enumerate() {
            if i == j {
                assert!(cell.is_null());
            } else {
                // The same surfaces, the same seeds: nearly the same space explored.
                let p = cell.as_f64().unwrap();
                assert!((0.0..5.0).contains(&p), "{i} not in {j}: {p}");
            }
        }
    }
    let size = numbers(&v["slice_size"]);
    let bits = v["slice_bits"].as_array().unwrap();
    assert_eq!(bits.len(), (size[0] * size[1]) as usize);
    assert!(bits.iter().any(|b| b == 0b11), "no cell explored on both maps");
    let cell = v["cell"].as_f64().unwrap();
    assert!(
        (v["slice_z"].as_f64().unwrap() - 1.0).abs() <= cell,
        "the slice holds the first start"
    );

    // The report draws both sections.
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("6. Explored volume") && html.contains("Time against iterations"));
    for missing in ["Explored volume: not computed", "Time against iterations: not computed"] {
        assert!(!html.contains(missing), "{missing}");
    }
    assert!(html.contains("Thesis Table 6.2 (RRT, Lab)") && html.contains("RRT, 6 runs per map"));

    // The PRM's volume alone: its own runs from the plan's start, no timing.
    let config = format!(
        "[input]\nmesh = \"room.obj\"\n[maps]\ntypes = [\"planes\", \"pc\"]\n{ROOM_PLAN}\
         [volume]\nplanner = \"prm\"\niterations = 150\nseeds = [5]\ncells = 24\n\
         [output]\nwrite_3d = false\ndir = \"prm\"\n"
    );
    std::fs::write(d.join("prm.toml"), config).unwrap();
    let o = patchnav(&["run", d.join("prm.toml").to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let r = results(&d.join("prm"));
    assert!(r["timing"].as_array().unwrap().is_empty());
    let v = &r["volume"];
    assert_eq!((v["planner"].as_str(), v["runs"].as_u64()), (Some("prm"), Some(1)));
    assert_eq!(v["maps"], serde_json::json!(["planes", "pc"]));
    assert!(numbers(&v["volumes_m3"]).iter().all(|x| *x > 1.0));
    let html = std::fs::read_to_string(d.join("prm/report.html")).unwrap();
    assert!(html.contains("Thesis Table 6.4 (PRM, Lab)"));
    assert!(html.contains("Time against iterations: not computed"));
}
