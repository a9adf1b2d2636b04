//! The lab part of `docs/benchmarks.md`: thesis §6.1 (Fig 6.4) timing rows of the matrix.
//!
//! Two tables: the scene `lab` (the lab's exact geometry in every backend), and the scenes
//! `lab-scans-<kind>` (the thesis's four map types built from simulated ALRF scans, as Fig 6.4
//! compares them: planes, hybrid and trimesh by patch extraction in the four patch backends,
//! pc the raw scan points in the point-cloud map). Both put the thesis's prose bounds at
//! K = 500 (L6813–6818, [`crate::thesis`]) beside our RRT medians, with the ratio ours /
//! bound.

use super::{BACKENDS, Matrix, PLANNERS, quantile, sig3, time_text};
use crate::thesis::{FIG_6_4_PATCH_MAPS_BELOW_S, FIG_6_4_SLOW_MAPS_ABOVE_S, LAB_MAPS};
use patch_map::Backend;
use roadmap::PlannerKind;
use std::fmt::Write as _;

/// The scene of the matrix holding the runs on the map `kind` built from scans.
fn scans_scene(kind: &str) -> String {
    format!("lab-scans-{kind}")
}

/// The checkpoints of a lab run and the metric holding each.
const CHECKPOINTS: [(u64, &str); 3] = [(100, "time_k100"), (500, "time_k500"), (1000, "time")];

/// The thesis's bound on the RRT at K = 500 on map `kind`, as text beside `median`, with the
/// ratio ours / bound: "< 0.4 s" for planes and hybrid, "> 4 s" for trimesh and pc.
fn bound_text(kind: &str, median: f64) -> String {
    let (sign, bound) = match kind {
        "trimesh" | "pc" => (">", FIG_6_4_SLOW_MAPS_ABOVE_S),
        _ => ("<", FIG_6_4_PATCH_MAPS_BELOW_S),
    };
    format!(" / thesis {sign} {bound} s (×{})", sig3(median / bound))
}

/// "median (lower–upper quartile)" of `values`, or `None` without values.
fn quartile_text(values: &[f64]) -> Option<(f64, String)> {
    let [lo, med, up] = crate::stats::quartiles(values)?;
    Some((med, format!("{} ({}–{})", time_text(med), time_text(lo), time_text(up))))
}

/// The exact-geometry lab table: per planner and backend the median time at K (lower–upper
/// quartile) beside the thesis's bound at K = 500; a note when the rows hold no run of scene
/// `lab`. The maps built from scans have their own section ([`lab_scans_section`]).
pub(super) fn lab_table(m: &Matrix) -> String {
    let has_exact = m.cells.keys().any(|(scene, _, _)| scene == "lab");
    if !has_exact {
        return String::from(
            "The rows hold no run of scene `lab` (exact geometry); run the command above.\n",
        );
    }
    let mut out = String::from("| planner | K |");
    let mut rule = String::from("|---|---|");
    for (b, _) in BACKENDS {
        let _ = write!(out, " {b} |");
        rule.push_str("---|");
    }
    let _ = writeln!(out, "\n{rule}");
    for (p, label) in PLANNERS {
        if !BACKENDS.iter().any(|&(b, _)| m.solved("lab", b, p).is_some()) {
            continue;
        }
        for (k, metric) in CHECKPOINTS {
            let _ = write!(out, "| {label} | {k} |");
            for (b, _) in BACKENDS {
                let text = match quartile_text(&m.values("lab", b, p, metric)) {
                    Some((med, text)) => {
                        // The exact map is the thesis's hybrid; its point-cloud map plays pc.
                        let kind = if b == Backend::PointCloud { "pc" } else { "hybrid" };
                        let bound =
                            (p == PlannerKind::Rrt && k == 500).then(|| bound_text(kind, med));
                        format!("{text}{}", bound.unwrap_or_default())
                    }
                    None => "–".into(),
                };
                let _ = write!(out, " {text} |");
            }
            out.push('\n');
        }
    }
    out
}

/// Whether the rows hold any run of the maps built from scans.
fn has_scans(m: &Matrix) -> bool {
    m.cells.keys().any(|(scene, _, _)| scene.starts_with("lab-scans-"))
}

/// The section of the lab's maps built from scans (scenes `lab-scans-<kind>`): per planner,
/// map type and K, the median time (lower–upper quartile) per backend, the thesis's bound
/// beside the RRT at K = 500, and the slow / fast ratios Fig 6.4's prose states. Empty when
/// the rows hold none.
pub(super) fn lab_scans_section(m: &Matrix) -> String {
    if !has_scans(m) {
        return String::new();
    }
    let mut o = String::from(
        "### Lab from simulated scans: the thesis's four maps (Fig 6.4)\n\n\
         The thesis's Fig 6.4 compares four maps of the lab built from its scans (§6.1, Table \
         6.1): `planes` (planar patches extracted and merged across scans), `hybrid` (planes plus \
         trimesh patches grown on the non-planar remainder), `trimesh` (whole scans meshed by \
         trimesh growing) and `pc` (the raw scan points). Here they are built from simulated ALRF \
         scans of the lab (`patchnav map build --scene lab --kind K --source scans`; 8 scans at \
         0.5° unless the command below says otherwise, the rows' `lab_maps` key names the build) \
         and run as above, each map sampling in its own box (thesis L6460) from a start free on \
         all four. Patch maps run in the four patch backends, pc only in the point-cloud map \
         (Algorithm 10); the thesis ran the patch maps in Bullet (our rapier's role). Bounds at \
         K = 500 (L6813–6818): \"less then 0.4 seconds\" [sic] on planes and hybrid, \"well over \
         4 seconds\" on trimesh and pc; the ratio is ours / that bound.\n\nCommand: `cargo xtask \
         bench roadmap --scene lab-scans` (maps cached in `target/bench/lab-maps/`), then \
         `cargo xtask docs`.\n\n",
    );
    let _ = write!(o, "| planner | map | K |");
    let mut rule = String::from("|---|---|---|");
    for (b, thesis) in BACKENDS {
        if b == Backend::Rapier {
            let _ = write!(o, " {b} ({thesis}) |");
        } else {
            let _ = write!(o, " {b} |");
        }
        rule.push_str("---|");
    }
    let _ = writeln!(o, "\n{rule}");
    for (p, label) in PLANNERS {
        for kind in LAB_MAPS {
            let scene = scans_scene(kind);
            if !BACKENDS.iter().any(|&(b, _)| m.solved(&scene, b, p).is_some()) {
                continue;
            }
            for (k, metric) in CHECKPOINTS {
                let _ = write!(o, "| {label} | {kind} | {k} |");
                for (b, _) in BACKENDS {
                    let text = match quartile_text(&m.values(&scene, b, p, metric)) {
                        Some((med, text)) => {
                            let bound =
                                (p == PlannerKind::Rrt && k == 500).then(|| bound_text(kind, med));
                            format!("{text}{}", bound.unwrap_or_default())
                        }
                        None => "–".into(),
                    };
                    let _ = write!(o, " {text} |");
                }
                o.push('\n');
            }
        }
    }
    o.push_str(&slow_fast_line(m));
    o
}

/// Fig 6.4's first finding (L6784–6786: trimesh and pc "more than an order of magnitude
/// slower" than planes and hybrid) on our RRT medians at K = 500: trimesh / planes per patch
/// backend, and pc / planes against the planes map in rapier (the thesis's Bullet).
fn slow_fast_line(m: &Matrix) -> String {
    let med = |kind: &str, b: Backend| {
        quantile(&m.values(&scans_scene(kind), b, PlannerKind::Rrt, "time_k500"), 0.5)
            .filter(|v| *v > 0.0)
    };
    let mut parts = Vec::new();
    for &(b, _) in &BACKENDS[..4] {
        if let (Some(slow), Some(fast)) = (med("trimesh", b), med("planes", b)) {
            parts.push(format!("trimesh / planes in {b} ×{}", sig3(slow / fast)));
        }
    }
    let (pc_backend, bullet) = (Backend::PointCloud, Backend::Rapier);
    if let (Some(pc), Some(planes)) = (med("pc", pc_backend), med("planes", bullet)) {
        parts.push(format!("pc ({pc_backend}) / planes ({bullet}) ×{}", sig3(pc / planes)));
    }
    if parts.is_empty() {
        return String::new();
    }
    format!(
        "\nRRT at K = 500 from scans, ours: {}; thesis: \"more than an order of magnitude \
         slower\" (L6784–6786; > 4 s against < 0.4 s, so > ×10).\n",
        parts.join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::{Value, json};

    fn row(scene: &str, backend: &str, seed: u64, metric: &str, value: f64) -> Value {
        json!({
            "bench": "roadmap", "scene": scene, "backend": backend, "planner": "rrt", "seed": seed,
            "metric": metric, "value": value, "jobs": 1, "command": "cargo xtask bench roadmap",
            "provenance": {"git_revision": "r", "date": "2026-11-22T05:00:00Z"},
        })
    }

    /// Three runs of `scene` on `backend` with K = 500 times `t`, `2t`, `3t`.
    fn runs(scene: &str, backend: &str, t: f64) -> Vec<Value> {
        (0..3)
            .flat_map(|s| {
                let k500 = t * (s + 1) as f64;
                [
                    row(scene, backend, s, "time_k100", k500 / 4.0),
                    row(scene, backend, s, "time_k500", k500),
                    row(scene, backend, s, "time", k500 * 2.0),
                    row(scene, backend, s, "solved", 0.0),
                ]
            })
            .collect()
    }

    #[test]
    fn scans_rows_get_their_own_table_beside_the_thesis_bounds() {
        let mut rows = runs("lab", "polygon", 0.001);
        rows.extend(runs("lab", "pointcloud", 0.01));
        rows.extend(runs("lab-scans-planes", "rapier", 0.01));
        rows.extend(runs("lab-scans-planes", "polygon", 0.02));
        rows.extend(runs("lab-scans-trimesh", "polygon", 0.5));
        rows.extend(runs("lab-scans-pc", "pointcloud", 0.2));
        let m = Matrix::from_rows(&rows);
        let text = lab_table(&m);
        // The exact-geometry table is still there: the exact map is a hybrid map.
        assert!(
            text.contains("| RRT | 500 | 2.00 ms (1.50 ms–2.50 ms) / thesis < 0.4 s (×0.00500) |")
        );
        assert!(!text.contains("### Lab from simulated scans"), "the page adds that section");
        let section = lab_scans_section(&m);
        let scans = &section[section.find("### Lab from simulated scans").unwrap()..];
        let line = |kind: &str, k: u64| {
            scans
                .lines()
                .find(|l| l.starts_with(&format!("| RRT | {kind} | {k} |")))
                .unwrap_or_else(|| panic!("no {kind} K={k} line: {scans}"))
                .to_owned()
        };
        // Columns: polygon, bbox6d, trimesh, rapier, pointcloud.
        let cells = |l: String| l.split(" | ").skip(3).map(str::to_owned).collect::<Vec<_>>();
        let planes = cells(line("planes", 500));
        assert_eq!(planes[0], "40.0 ms (30.0 ms–50.0 ms) / thesis < 0.4 s (×0.100)");
        assert_eq!(planes[1], "–");
        assert_eq!(planes[3], "20.0 ms (15.0 ms–25.0 ms) / thesis < 0.4 s (×0.0500)");
        let trimesh = cells(line("trimesh", 500));
        assert_eq!(trimesh[0], "1.00 s (750 ms–1.25 s) / thesis > 4 s (×0.250)");
        let pc = cells(line("pc", 500));
        assert!(pc[4].starts_with("400 ms (300 ms–500 ms) / thesis > 4 s (×0.100)"), "{pc:?}");
        // No bound away from K = 500; no hybrid rows without runs.
        assert!(!line("pc", 1000).contains("thesis"));
        assert_eq!(cells(line("pc", 100))[4].trim_end_matches(" |"), "100 ms (75.0 ms–125 ms)");
        assert!(!scans.contains("| RRT | hybrid |"));
        // trimesh / planes in polygon: 1 s / 40 ms; pc / planes in rapier: 400 ms / 20 ms.
        assert!(scans.contains("trimesh / planes in polygon ×25.0"), "{scans}");
        assert!(scans.contains("pc (pointcloud) / planes (rapier) ×20.0"), "{scans}");
        // Without scans rows there is no scans section.
        let exact = Matrix::from_rows(&runs("lab", "polygon", 0.001));
        assert!(
            lab_scans_section(&exact).is_empty() && lab_table(&exact).contains("| RRT | 1000 |")
        );
        // Without exact rows: a note instead of the exact table, and the scans section.
        let only = Matrix::from_rows(&runs("lab-scans-pc", "pointcloud", 0.2));
        let text = lab_table(&only);
        assert!(text.starts_with("The rows hold no run of scene `lab`"), "{text}");
        assert!(!text.contains("| planner | K |"));
        assert!(lab_scans_section(&only).contains("| RRT | pc | 500 |"));
    }
}
