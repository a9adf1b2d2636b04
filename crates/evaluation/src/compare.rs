//! The project beside established systems on the same inputs, measured in one run: the
//! generators of `cargo xtask compare` (docs/comparison.md). xtask builds the programs and
//! writes the rows; each part here runs both sides and returns its rows and table.
//!
//! * [`planning`]: OMPL's RRT, RRTConnect and PRM with FCL sphere / capsule checks on a
//!   triangle mesh (`compare/src/cmp_plan.cpp`) against `patchnav plan --problem` on the same
//!   mesh loaded as planar patches (polygon and 6D-bounding-box backends) and as the same
//!   triangles (trimesh backend); problems: the shared floor plan and the lab's extracted patch
//!   map exported as OBJ.
//! * [`mapsize`]: OctoMap trees at 5 cm and 10 cm from the simulated lab scans
//!   (`compare/src/cmp_octomap.cpp`) against our planes, hybrid, trimesh and point-cloud map
//!   files from the same scans.
//! * [`segmentation`]: PCL's organised multi-plane segmentation with concave hulls
//!   (`compare/src/cmp_segment.cpp`) against `patchnav extract` on the shared floor-plan depth
//!   image, simulated range-camera frames of the lab and the organised real frames.

use anyhow::{Context, Result, bail};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

pub mod mapsize;
pub mod planning;
pub mod segmentation;

pub use crate::stats::median;

/// The programs and folders every part uses.
pub struct Env {
    /// The release build of `patchnav`.
    pub patchnav: PathBuf,
    /// Where the C++ programs are.
    pub build: PathBuf,
    /// Where rows, inputs and intermediate files go.
    pub out: PathBuf,
    /// The shared bench (floor plan mesh, problem, depth image).
    pub bench: PathBuf,
}

/// Runs a command and returns its standard output, failing with its standard error.
pub fn capture(cmd: &mut Command) -> Result<String> {
    let out = cmd.output().with_context(|| format!("could not start {cmd:?}"))?;
    if !out.status.success() {
        bail!("{cmd:?} failed: {}", String::from_utf8_lossy(&out.stderr).trim());
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// Runs a program and returns the JSON objects it printed, one per line; a failure is an error
/// naming the command and the last line of its standard error.
pub fn json_lines(program: &Path, args: &[String]) -> Result<Vec<Value>> {
    let out = Command::new(program)
        .args(args)
        .output()
        .with_context(|| format!("could not start {}", program.display()))?;
    if !out.status.success() {
        let err = String::from_utf8_lossy(&out.stderr);
        bail!(
            "{} {} failed: {}",
            program.display(),
            args.join(" "),
            err.lines().last().unwrap_or("no output")
        );
    }
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter(|l| l.starts_with('{'))
        .map(|l| {
            serde_json::from_str(l).with_context(|| format!("{} printed `{l}`", program.display()))
        })
        .collect()
}

/// `ours / theirs` as text (`–` when either is missing or `theirs` is zero).
pub fn ratio(ours: Option<f64>, theirs: Option<f64>) -> String {
    match (ours, theirs) {
        (Some(a), Some(b)) if b != 0.0 && a.is_finite() && b.is_finite() => format!("{:.3}", a / b),
        _ => "–".to_owned(),
    }
}

/// A number with three decimals from 1 up, three significant digits below 1, none from 1000
/// up; `–` when missing.
pub fn num(v: Option<f64>) -> String {
    match v {
        None => "–".to_owned(),
        Some(x) if !x.is_finite() => "–".to_owned(),
        Some(x) if x.abs() >= 1000.0 => format!("{x:.0}"),
        Some(x) if x.abs() >= 1.0 => format!("{x:.3}"),
        Some(0.0) => "0".to_owned(),
        Some(x) => {
            let decimals = (2.0 - x.abs().log10().floor()).clamp(0.0, 12.0) as usize;
            format!("{x:.decimals$}")
        }
    }
}

/// `s` as a command-line argument.
pub fn arg(s: impl AsRef<std::ffi::OsStr>) -> String {
    s.as_ref().to_string_lossy().into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even_counts_and_nan() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(vec![4.0, 1.0, 2.0, 3.0]), Some(2.5));
        assert_eq!(median(vec![f64::NAN]), None);
        assert_eq!(median(Vec::new()), None);
    }

    #[test]
    fn num_keeps_three_significant_digits_below_one() {
        assert_eq!(num(Some(0.0123456)), "0.0123");
        assert_eq!(num(Some(0.5)), "0.500");
        assert_eq!(num(Some(12.34567)), "12.346");
        assert_eq!(num(Some(123456.7)), "123457");
        assert_eq!(num(Some(f64::NAN)), "–");
        assert_eq!(num(None), "–");
    }

    #[test]
    fn ratio_guards_zero_and_missing() {
        assert_eq!(ratio(Some(1.0), Some(4.0)), "0.250");
        assert_eq!(ratio(Some(1.0), Some(0.0)), "–");
        assert_eq!(ratio(None, Some(1.0)), "–");
    }
}
