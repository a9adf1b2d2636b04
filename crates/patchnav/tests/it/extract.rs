//! `patchnav extract`: simulated scans in, a map file and an OBJ export out.

use crate::common;
use common::*;

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

#[test]
fn scans_become_a_map_that_plans_and_an_obj_export() {
    let dir = tempfile::tempdir().unwrap();
    let d = |name: &str| dir.path().join(name).to_str().unwrap().to_owned();
    let o = patchnav(&[
        "--quiet",
        "simulate",
        "lab",
        "--sensor",
        "tof",
        "--poses",
        "2",
        "--out",
        &d("scans"),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let scans = [d("scans/scan000.ply"), d("scans/scan001.ply")];
    let o = patchnav(&[
        "extract",
        &scans[0],
        &scans[1],
        "--sensor",
        "range-camera",
        "--hybrid",
        "--out",
        &d("map.pmap"),
        "--export",
        &d("patches.obj"),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let out = text(&o.stdout);
    assert_eq!(out.matches("planar patches, ").count(), 2, "one line per scan:\n{out}");
    assert!(out.contains("merging:") && out.contains("time: segmentation"), "{out}");
    let planar: usize = out
        .lines()
        .find_map(|l| l.strip_prefix("patches: "))
        .and_then(|l| l.split(' ').next())
        .and_then(|n| n.parse().ok())
        .expect("a patches line");
    assert!(planar >= 3, "{out}");

    // The export is an OBJ of triangles; the map file opens and plans.
    let obj = std::fs::read_to_string(d("patches.obj")).unwrap();
    assert!(obj.lines().filter(|l| l.starts_with("f ")).count() >= planar);
    let info = patchnav(&["map", "info", &d("map.pmap")]);
    assert!(info.status.success(), "{}", text(&info.stderr));
    assert!(text(&info.stdout).contains("bbox6d"), "{}", text(&info.stdout));

    // A PLY export of the same patches: a binary mesh with as many faces as the OBJ.
    let o = patchnav(&[
        "--quiet",
        "extract",
        &scans[0],
        &scans[1],
        "--sensor",
        "range-camera",
        "--hybrid",
        "--export",
        &d("patches.ply"),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let ply = std::fs::read(d("patches.ply")).unwrap();
    let faces = obj.lines().filter(|l| l.starts_with("f ")).count();
    let header = String::from_utf8_lossy(&ply[..ply.len().min(400)]).into_owned();
    assert!(header.contains(&format!("element face {faces}\n")), "{header}");

    // Poses from the simulation's poses.json give the same patches as the files' own poses.
    let again = patchnav(&[
        "extract",
        &scans[0],
        &scans[1],
        "--sensor",
        "range-camera",
        "--hybrid",
        "--poses",
        &d("scans/poses.json"),
        "--out",
        &d("map2.pmap"),
    ]);
    assert!(again.status.success(), "{}", text(&again.stderr));
    let patches_line = |s: &str| s.lines().find(|l| l.starts_with("patches: ")).map(str::to_owned);
    assert_eq!(patches_line(&out), patches_line(&text(&again.stdout)));
}

#[test]
fn bad_inputs_are_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = |name: &str| dir.path().join(name).to_str().unwrap().to_owned();
    std::fs::write(d("bad.ply"), "ply\nformat ascii 1.0\nelement vertex 3\n").unwrap();
    std::fs::write(
        d("poses.json"),
        r#"{"scans": [{"file": "x.ply", "world_from_sensor": [[1]]}]}"#,
    )
    .unwrap();
    let cases: [(Vec<String>, &str); 3] = [
        (vec![d("bad.ply"), "--out".into(), d("m.pmap")], "bad.ply"),
        (vec![d("missing.ply"), "--out".into(), d("m.pmap")], "missing.ply"),
        (vec![d("bad.ply"), "--export".into(), d("patches.stl")], "OBJ"),
    ];
    for (args, needle) in cases {
        let mut all = vec!["extract".to_owned()];
        all.extend(args);
        let refs: Vec<&str> = all.iter().map(String::as_str).collect();
        let o = patchnav(&refs);
        assert_eq!(o.status.code(), Some(1), "{refs:?}");
        let err = text(&o.stderr);
        assert!(err.starts_with("error: ") && err.contains(needle), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
    }
}
