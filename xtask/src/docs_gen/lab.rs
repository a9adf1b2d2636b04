//! The lab part of `docs/benchmarks.md`: thesis §6.1 (Fig 6.4) timing rows of the matrix.

use super::{BACKENDS, Matrix, PLANNERS, quantile, sig3, time_text};
use std::fmt::Write as _;

/// Thesis §6.1 (L6813–6818), RRT on the Lab at K = 500: under 0.4 s on the planes
/// and hybrid maps (Bullet), "well over 4 seconds" on the point-cloud map (Algorithm 10).
const THESIS_LAB_PATCH_BOUND_S: f64 = 0.4;
const THESIS_LAB_PC_BOUND_S: f64 = 4.0;

/// The lab table: per planner and backend the median time at K (lower–upper quartile), beside the
/// thesis's bound at K = 500.
pub(super) fn lab_table(m: &Matrix) -> String {
    let mut out = String::from("| planner | K |");
    let mut rule = String::from("|---|---|");
    for (b, _) in BACKENDS {
        let _ = write!(out, " {b} |");
        rule.push_str("---|");
    }
    let _ = writeln!(out, "\n{rule}");
    for (p, label) in PLANNERS {
        if !BACKENDS.iter().any(|(b, _)| m.solved("lab", b, p).is_some()) {
            continue;
        }
        for (k, metric) in [(100, "time_k100"), (500, "time_k500"), (1000, "time")] {
            let _ = write!(out, "| {label} | {k} |");
            for (b, _) in BACKENDS {
                let v = m.values("lab", b, p, metric);
                let text = match (quantile(&v, 0.25), quantile(&v, 0.5), quantile(&v, 0.75)) {
                    (Some(lo), Some(med), Some(up)) => {
                        let bound = (p == "rrt" && k == 500).then(|| {
                            if b == "pointcloud" {
                                format!(
                                    " / thesis > {} s (×{})",
                                    THESIS_LAB_PC_BOUND_S,
                                    sig3(med / THESIS_LAB_PC_BOUND_S)
                                )
                            } else {
                                format!(
                                    " / thesis < {} s (×{})",
                                    THESIS_LAB_PATCH_BOUND_S,
                                    sig3(med / THESIS_LAB_PATCH_BOUND_S)
                                )
                            }
                        });
                        format!(
                            "{} ({}–{}){}",
                            time_text(med),
                            time_text(lo),
                            time_text(up),
                            bound.unwrap_or_default()
                        )
                    }
                    _ => "–".into(),
                };
                let _ = write!(out, " {text} |");
            }
            out.push('\n');
        }
    }
    out
}
