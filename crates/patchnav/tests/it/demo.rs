//! `patchnav demo --quick` end to end: the real binary writes `results.json`, `report.html`
//! and the 3D files, and the results hold what the pipeline promises.

use serde_json::Value;
use std::collections::BTreeSet;
use std::process::Command;

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array().expect("an array").iter().map(|x| x.as_f64().expect("a number")).collect()
}

#[test]
fn quick_demo_fills_every_section() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("demo");
    let o = Command::new(env!("CARGO_BIN_EXE_patchnav"))
        .args(["--quiet", "demo", "--quick", "--out"])
        .arg(&out)
        .output()
        .expect("patchnav runs");
    assert!(o.status.success(), "stderr: {}", String::from_utf8_lossy(&o.stderr));
    assert!(out.join("report.html").is_file(), "no report.html");
    let r: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    assert_eq!(r["scale"], "Quick");

    // Every stage timed.
    let stages = r["stages"].as_array().unwrap();
    assert!(stages.len() >= 5, "{stages:?}");
    assert!(stages.iter().all(|s| s["seconds"].as_f64().unwrap() >= 0.0));

    // Four map types with non-zero sizes; the pc map in the point-cloud backend.
    let kinds = ["planes", "hybrid", "trimesh", "pc"];
    let maps = r["maps"].as_array().unwrap();
    for kind in kinds {
        let rows: Vec<&Value> = maps.iter().filter(|m| m["kind"] == kind).collect();
        assert!(!rows.is_empty(), "no {kind} map");
        for m in &rows {
            assert!(m["memory_bytes"].as_u64().unwrap() > 0, "{m}");
            assert!(m["file_bytes"].as_u64().unwrap() > 0, "{m}");
            let held = ["planar_patches", "trimesh_patches", "points"]
                .iter()
                .map(|k| m[*k].as_u64().unwrap())
                .sum::<u64>();
            assert!(held > 0, "{m}");
        }
    }
    let pc = maps.iter().find(|m| m["kind"] == "pc").unwrap();
    assert_eq!(pc["backend"], "pointcloud");
    let planes = maps.iter().find(|m| m["kind"] == "planes").unwrap();
    let trimesh = maps.iter().find(|m| m["kind"] == "trimesh").unwrap();
    assert_eq!(trimesh["planar_patches"], 0);
    assert!(
        trimesh["triangles"].as_u64().unwrap() > 10 * planes["triangles"].as_u64().unwrap(),
        "a meshed scan has many more triangles than its planes"
    );
    let drawn: BTreeSet<&str> =
        r["drawings"].as_array().unwrap().iter().map(|d| d["kind"].as_str().unwrap()).collect();
    assert_eq!(drawn, kinds.into_iter().collect());

    // At least one solved plan per map type, with a path reaching each goal.
    let plans = r["plans"].as_array().unwrap();
    for kind in kinds {
        let solved: Vec<&Value> =
            plans.iter().filter(|p| p["map"] == kind && p["solved"] == true).collect();
        assert!(!solved.is_empty(), "no solved plan on the {kind} map");
        for p in solved {
            let goals = p["goals"].as_array().unwrap();
            let paths = p["paths"].as_array().unwrap();
            assert_eq!(paths.len(), goals.len());
            assert!(p["path_length"].as_f64().unwrap() > 0.0);
            for (path, goal) in paths.iter().zip(goals) {
                let path = path.as_array().unwrap();
                assert_eq!(numbers(&path[0]), numbers(&p["start"]));
                let (end, g) = (numbers(path.last().unwrap()), numbers(goal));
                let d = end.iter().zip(&g).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
                assert!(d <= 0.5 + 1e-9, "path ends {d} m from its goal");
            }
            assert!(p["edges"].as_array().unwrap().len() <= 20_000);
        }
    }

    // ToF: the AAT unwrapped some pixels; the outcome image has one value per pixel.
    let tof = &r["tof"];
    let pixels = (tof["width"].as_u64().unwrap() * tof["height"].as_u64().unwrap()) as usize;
    let outcomes: Vec<u64> =
        tof["outcomes"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap()).collect();
    assert_eq!(outcomes.len(), pixels);
    assert_eq!(tof["radial"].as_array().unwrap().len(), pixels);
    assert!(outcomes.iter().all(|&o| o <= 3));
    // Region unwrapping keeps what its regions agree on and drops the rest; at ≤ 1 % wrong it
    // unwraps little or nothing of the dim, noisy far room (docs/tof.md).
    assert!(outcomes.contains(&0) && outcomes.contains(&2), "kept and dropped pixels");
    assert!(tof["wrapped_percent"].as_f64().unwrap() > 0.0);
    assert!(tof["unwrapped_correct_percent"].as_f64().unwrap() >= 0.0);
    // The safe mode: at most 1 % of the output wrong, and the yield stated.
    assert_eq!(tof["method"], "regions");
    assert!(tof["wrong_percent"].as_f64().unwrap() <= 1.0, "{tof:?}");
    assert!(tof["yield_percent"].as_f64().unwrap() > 0.0);

    // Terrain: the class found is the truth; a Hough picture (PNG signature) and three sectors.
    let t = &r["terrain"];
    assert_eq!(t["class"], t["truth"], "{t:?}");
    assert!(t["points"].as_u64().unwrap() > 0);
    let png: Vec<u64> =
        t["hough_png"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap()).collect();
    assert_eq!(&png[..4], &[0x89, b'P' as u64, b'N' as u64, b'G' as u64]);
    assert_eq!(t["sectors"].as_array().unwrap().len(), 3);

    // Timing curves per map type, increasing.
    let timing = r["timing"].as_array().unwrap();
    assert_eq!(timing.len(), 4);
    for c in timing {
        let k = numbers(&c["iterations"]);
        let m = numbers(&c["median_ms"]);
        assert_eq!(k.len(), m.len());
        assert!(k.len() >= 2);
        assert!(k.windows(2).all(|w| w[0] < w[1]), "{k:?}");
        assert!(m.windows(2).all(|w| w[0] <= w[1]), "{}: {m:?}", c["map"]);
        assert!(m.last().unwrap() > m.first().unwrap());
        for (q1, q3) in numbers(&c["q1_ms"]).iter().zip(numbers(&c["q3_ms"])) {
            assert!(*q1 <= q3);
        }
    }

    // Volume: a 4 × 4 table with nothing on the diagonal, percentages elsewhere.
    let v = &r["volume"];
    let table = v["table"].as_array().unwrap();
    assert_eq!(table.len(), 4);
    for (i, row) in table.iter().enumerate() {
        let row = row.as_array().unwrap();
        assert_eq!(row.len(), 4);
        for (j, cell) in row.iter().enumerate() {
            if i == j {
                assert!(cell.is_null(), "diagonal {i}: {cell}");
            } else {
                let p = cell.as_f64().unwrap();
                assert!((0.0..=100.0).contains(&p), "{p}");
            }
        }
    }
    let size = numbers(&v["slice_size"]);
    assert_eq!(v["slice_bits"].as_array().unwrap().len(), (size[0] * size[1]) as usize);
    assert!(v["slice_bits"].as_array().unwrap().iter().any(|b| b.as_u64().unwrap() == 0b1111));

    // Every listed file exists with its size; the 3D files are there.
    let files = r["files"].as_array().unwrap();
    for f in files {
        let path = out.join(f["path"].as_str().unwrap());
        let len =
            std::fs::metadata(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).len();
        assert_eq!(len, f["bytes"].as_u64().unwrap(), "{}", path.display());
    }
    let names: BTreeSet<&str> = files.iter().map(|f| f["path"].as_str().unwrap()).collect();
    for name in ["scan-1.ply", "map-planes.ply", "map-pc.ply", "tof-cloud.ply", "path-pc-rrt.obj"] {
        assert!(names.contains(name), "{name} not listed: {names:?}");
    }
}
