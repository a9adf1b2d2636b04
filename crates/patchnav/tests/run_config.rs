//! `patchnav run CONFIG.toml` as a user meets it: real processes, real files, exit codes and
//! messages.

use serde_json::Value;
use std::path::Path;
use std::process::{Command, Output};

fn patchnav(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_patchnav")).args(args).output().expect("patchnav runs")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn fixture(name: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures").join(name);
    p.to_str().unwrap().to_owned()
}

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
         [terrain]\nframe = \"{}\"\naxes = \"camera\"\n[output]\ndir = \"result\"\n",
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
    // The rack-and-door frame wraps: the AAT flags part of it and unwrapping keeps those pixels.
    let outcomes = r["tof"]["outcomes"].as_array().unwrap();
    assert!(outcomes.iter().any(|o| o == 0) && outcomes.iter().any(|o| o == 1));
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
    assert_eq!(kinds, ["planes", "hybrid", "pc"]);
    // 6 room faces + 5 visible faces of the wall (its bottom lies on the floor, still a face).
    let planar = r["maps"][0]["planar_patches"].as_u64().unwrap();
    assert!((6..=12).contains(&planar), "{planar}");
    assert_eq!(r["scene"]["name"], "room");
    let plans = r["plans"].as_array().unwrap();
    assert_eq!(plans.len(), 3 * 2);
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
        (format!("[input]\nmesh = \"room.obj\"\n[maps]\ntypes = [\"trimesh\"]\n{ROOM_PLAN}"), "maps.types"),
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
