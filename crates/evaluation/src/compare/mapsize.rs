//! Map size: OctoMap trees (`cmp_octomap`, 5 cm and 10 cm, every scan inserted as ray casts
//! from its sensor origin) against our map files from the same lab scans: the planar patch map
//! (polygon, bbox6d and trimesh backends), the hybrid map (planes plus trimesh patches on the
//! rest), and the point-cloud map.

use super::planning::{lab_dir, lab_scans};
use super::{Env, arg, json_lines, num, ratio};
use anyhow::{Context, Result, bail};
use patch_map::Backend;
use serde_json::{Value, json};
use std::fmt::Write as _;
use std::path::Path;

/// OctoMap resolutions, metres.
const RESOLUTIONS: [f64; 2] = [0.05, 0.10];

/// `memory bytes` and `file bytes` of a map file, from `patchnav map info`.
fn map_info(patchnav: &Path, file: &Path) -> Result<(u64, u64)> {
    let text =
        super::capture(std::process::Command::new(patchnav).args(["map", "info"]).arg(file))?;
    let field = |key: &str| -> Result<u64> {
        text.lines()
            .find_map(|l| l.strip_prefix(key))
            .and_then(|v| v.trim().parse().ok())
            .with_context(|| format!("`map info {}` has no `{key}`", file.display()))
    };
    Ok((field("memory bytes:")?, field("file bytes:")?))
}

/// Builds every map; returns the rows and the table.
pub fn run(env: &Env, poses: usize) -> Result<(Vec<Value>, String)> {
    let dir = lab_dir(env);
    let scans = lab_scans(env, poses);
    if let Some(missing) = scans.iter().find(|s| !s.is_file()) {
        bail!("missing {}", missing.display());
    }
    let mut rows = Vec::new();
    for res in RESOLUTIONS {
        eprintln!("mapsize: octomap {res} m");
        let bt = dir.join(format!("octomap-{:.0}cm.bt", res * 100.0));
        let mut a: Vec<String> = scans.iter().map(arg).collect();
        a.extend(["--resolution".into(), res.to_string(), "--out".into(), arg(&bt)]);
        for mut r in json_lines(&env.build.join("cmp_octomap"), &a)? {
            r["side"] = json!("octomap");
            r["label"] = json!(format!("OcTree {:.0} cm", res * 100.0));
            r["file_bytes"] = r["bt_bytes"].clone();
            rows.push(r);
        }
    }
    // (label, extract options) — one extraction per map, its own timing row
    let ours: [(&str, &[&str]); 4] = [
        ("planes, polygon backend", &["--backend", Backend::Polygon.name()]),
        ("planes, bbox6d backend", &["--backend", Backend::BBox6d.name()]),
        ("planes, trimesh backend", &["--backend", Backend::Trimesh.name()]),
        ("hybrid, polygon backend", &["--backend", Backend::Polygon.name(), "--hybrid"]),
    ];
    for (i, (label, options)) in ours.iter().enumerate() {
        eprintln!("mapsize: ours, {label}");
        let file = dir.join(format!("ours-{i}.pmap"));
        let jsonl = dir.join(format!("ours-{i}.jsonl"));
        let _ = std::fs::remove_file(&jsonl);
        let mut a: Vec<String> = vec!["--quiet".into(), "extract".into()];
        a.extend(scans.iter().map(arg));
        a.extend(options.iter().map(|s| s.to_string()));
        a.extend(["--out".into(), arg(&file), "--jsonl".into(), arg(&jsonl)]);
        json_lines(&env.patchnav, &a)?;
        let text = std::fs::read_to_string(&jsonl)
            .with_context(|| format!("reading {}", jsonl.display()))?;
        let mut r: Value = serde_json::from_str(text.lines().last().unwrap_or("{}"))?;
        let (memory, bytes) = map_info(&env.patchnav, &file)?;
        r["side"] = json!("ours");
        r["label"] = json!(label);
        r["memory_usage_bytes"] = json!(memory);
        r["file_bytes"] = json!(bytes);
        rows.push(r);
    }
    eprintln!("mapsize: ours, point-cloud map");
    let pc = dir.join("ours-pc.pmap");
    let t = std::time::Instant::now();
    json_lines(
        &env.patchnav,
        &[
            "--quiet",
            "map",
            "build",
            "--scene",
            "lab",
            "--kind",
            "pc",
            "--scans",
            &poses.to_string(),
        ]
        .map(str::to_owned)
        .into_iter()
        .chain(["--backend".into(), Backend::PointCloud.to_string(), "--out".into(), arg(&pc)])
        .collect::<Vec<_>>(),
    )?;
    let wall = t.elapsed().as_secs_f64();
    let (memory, bytes) = map_info(&env.patchnav, &pc)?;
    rows.push(
        json!({"kind": "map", "tool": "patchnav", "side": "ours", "label": "point cloud (pc)",
                     "memory_usage_bytes": memory, "file_bytes": bytes, "time_s": null,
                     "wall_s_with_simulation": wall}),
    );
    Ok((rows.clone(), table(&rows)))
}

fn table(rows: &[Value]) -> String {
    let f = |r: &Value, k: &str| r.get(k).and_then(Value::as_f64);
    let octo: Vec<&Value> = rows.iter().filter(|r| r["side"] == json!("octomap")).collect();
    let (o5, o10) = (octo.first().copied(), octo.get(1).copied());
    let of = |o: Option<&Value>, k: &str| o.and_then(|o| f(o, k));
    let mut out = String::from(
        "| map | contents | file bytes | memory bytes | build s | file / OcTree 5 cm | file / OcTree 10 cm | memory / OcTree 5 cm | memory / OcTree 10 cm | build / OcTree 5 cm | build / OcTree 10 cm |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let contents = if r["side"] == json!("octomap") {
            format!(
                "{} occupied + {} free leaves, {} nodes",
                r["occupied_leaves"], r["free_leaves"], r["nodes"]
            )
        } else if let Some(p) = r.get("polygons").and_then(Value::as_u64) {
            let tri = r.get("trimesh_patches").and_then(Value::as_u64).unwrap_or(0);
            if tri > 0 {
                format!("{p} planar patches + {tri} trimesh patches")
            } else {
                format!("{p} planar patches")
            }
        } else {
            "points of the same scans".to_owned()
        };
        let is_ours = r["side"] == json!("ours");
        let rr = |a: Option<f64>, b: Option<f64>| if is_ours { ratio(a, b) } else { String::new() };
        let _ = writeln!(
            out,
            "| {} | {contents} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            r["label"].as_str().unwrap_or("?"),
            num(f(r, "file_bytes")),
            num(f(r, "memory_usage_bytes")),
            num(f(r, "time_s")),
            rr(f(r, "file_bytes"), of(o5, "file_bytes")),
            rr(f(r, "file_bytes"), of(o10, "file_bytes")),
            rr(f(r, "memory_usage_bytes"), of(o5, "memory_usage_bytes")),
            rr(f(r, "memory_usage_bytes"), of(o10, "memory_usage_bytes")),
            rr(f(r, "time_s"), of(o5, "time_s")),
            rr(f(r, "time_s"), of(o10, "time_s")),
        );
    }
    out
}
