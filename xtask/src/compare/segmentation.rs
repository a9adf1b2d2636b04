//! Segmentation: PCL's organised multi-plane segmentation + concave hulls (`cmp_segment`)
//! against `patchnav extract --sensor range-camera` on the shared floor plan's organised depth
//! image (`floorplan_scan.ply`, 640 × 480), quality from the plane polygons against the floor
//! plan's mesh with the scoring of `cargo xtask peers planes` ([`crate::peers::Truth`]).

use super::{Env, arg, json_lines, median, num, ratio};
use anyhow::{Context, Result, bail};
use serde_json::{Value, json};
use std::fmt::Write as _;

/// Repetitions per side (alternating), for the median time.
const REPS: usize = 3;
const CLOUD: &str = "floorplan_scan";

/// Runs both sides `REPS` times; returns the rows and the table.
pub(crate) fn run(env: &Env) -> Result<(Vec<Value>, String)> {
    let scan = env.bench.join(format!("{CLOUD}.ply"));
    if !scan.is_file() {
        bail!("missing {} (the shared bench)", scan.display());
    }
    let dir = env.out.join("segmentation");
    std::fs::create_dir_all(&dir)?;
    eprintln!("segmentation: ground truth from floorplan.obj");
    let truth = crate::peers::Truth::load(&env.bench)?;
    let mut rows = Vec::new();
    for rep in 0..REPS {
        eprintln!("segmentation: repetition {}", rep + 1);
        let polys = dir.join("pcl.polygons.json");
        let a = [arg(&scan), "--polygons".into(), arg(&polys)];
        let mut r = json_lines(&env.build.join("cmp_segment"), &a)?
            .pop()
            .context("cmp_segment printed no row")?;
        r["side"] = json!("pcl");
        r["rep"] = json!(rep);
        r["quality"] = truth.quality(CLOUD, &read_json(&polys)?);
        rows.push(r);

        let polys = dir.join("ours.polygons.json");
        let jsonl = dir.join("ours.jsonl");
        let _ = std::fs::remove_file(&jsonl);
        let a = [
            "--quiet",
            "extract",
            &arg(&scan),
            "--sensor",
            "range-camera",
            "--jsonl",
            &arg(&jsonl),
            "--polygons",
            &arg(&polys),
        ]
        .map(str::to_owned);
        json_lines(&env.patchnav, &a)?;
        let text = std::fs::read_to_string(&jsonl)
            .with_context(|| format!("reading {}", jsonl.display()))?;
        let mut r: Value = serde_json::from_str(text.lines().last().unwrap_or("{}"))?;
        r["side"] = json!("ours");
        r["rep"] = json!(rep);
        r["quality"] = truth.quality(CLOUD, &read_json(&polys)?);
        rows.push(r);
    }
    Ok((rows.clone(), table(&rows)))
}

fn read_json(path: &std::path::Path) -> Result<Value> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    serde_json::from_str(&text).with_context(|| format!("{} is not JSON", path.display()))
}

fn table(rows: &[Value]) -> String {
    let pick =
        |side: &str| -> Vec<&Value> { rows.iter().filter(|r| r["side"] == json!(side)).collect() };
    let med = |rs: &[&Value], k: &str| {
        median(rs.iter().filter_map(|r| r.get(k).and_then(Value::as_f64)).collect())
    };
    let theirs = pick("pcl");
    let t_theirs = med(&theirs, "time_s");
    let mut out = String::from(
        "| side | method | runs | median time s | normals / segmentation / hulls s | planes | polygons | polygon vertices | true planes found | planes off truth | vertices on surface | peak RSS KiB | time ours/theirs |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for (side, rs) in [("PCL", theirs.clone()), ("ours", pick("ours"))] {
        let Some(first) = rs.first() else { continue };
        let q = &first["quality"];
        let t = med(&rs, "time_s");
        let _ = writeln!(
            out,
            "| {side} | {} | {} | {} | {} / {} / {} | {} | {} | {} | {}/{} | {} | {} | {} | {} |",
            first["method"].as_str().unwrap_or("?"),
            rs.len(),
            num(t),
            num(med(&rs, "time_normals_s")),
            num(med(&rs, "time_seg_s")),
            num(med(&rs, "time_hull_s")),
            first["planes"],
            first["polygons"],
            first["polygon_vertices"],
            q["true_planes_found"],
            q["true_planes_visible"],
            q["planes_off_truth"],
            num(q["vertices_on_surface"].as_f64()),
            num(med(&rs, "peak_rss_kib")),
            if side == "ours" { ratio(t, t_theirs) } else { String::new() },
        );
    }
    out
}
