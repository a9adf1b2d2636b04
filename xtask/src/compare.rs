//! `cargo xtask compare [planning|mapsize|segmentation|all] [--install] [--seeds N] [--poses N]
//! [--lab-frames N] [--real-dir D]`:
//! the project beside established systems on the same inputs, measured in one run
//! (docs/comparison.md).
//!
//! * **planning**: OMPL's RRT, RRTConnect and PRM with FCL sphere / capsule checks on a triangle
//!   mesh (`compare/src/cmp_plan.cpp`) against `patchnav plan --problem` on the same mesh loaded
//!   as planar patches (polygon and 6D-bounding-box backends) and as the same triangles (trimesh
//!   backend); problems: the shared floor plan and the lab's extracted patch map exported as OBJ.
//! * **mapsize**: OctoMap trees at 5 cm and 10 cm from the simulated lab scans
//!   (`compare/src/cmp_octomap.cpp`) against our planes, hybrid, trimesh and point-cloud map
//!   files from the same scans.
//! * **segmentation**: PCL's organised multi-plane segmentation with concave hulls
//!   (`compare/src/cmp_segment.cpp`) against `patchnav extract` on the shared floor-plan depth
//!   image (scored against the floor plan's mesh as `peers planes` scores it), `--lab-frames`
//!   simulated range-camera frames of the lab (scored against the scene's exact surfaces) and
//!   the organised real frames of `shared/data/real` or `--real-dir` (time and coverage only).
//!
//! The C++ programs are built with CMake from Debian's packages into `target/compare-build/`;
//! a missing package stops the command with the `apt-get` line to run, or is installed with
//! `--install`. Rows (JSONL, the shared results schema plus `side`) go to `target/compare/`,
//! the side-by-side tables with ratios ours / theirs to stdout and `target/compare/summary.md`.

use anyhow::{Context, Result, bail};
use serde_json::Value;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

mod mapsize;
mod planning;
mod segmentation;

/// The Debian packages the C++ programs need.
const PACKAGES: [&str; 8] = [
    "cmake",
    "g++",
    "libeigen3-dev",
    "nlohmann-json3-dev",
    "libompl-dev",
    "libfcl-dev",
    "liboctomap-dev",
    "libpcl-dev",
];

/// What `compare` was asked to do.
struct Args {
    planning: bool,
    mapsize: bool,
    segmentation: bool,
    install: bool,
    seeds: u64,
    poses: usize,
    bench: PathBuf,
    /// Simulated lab frames of the segmentation part.
    lab_frames: usize,
    /// The real frames' folder of the segmentation part (`None`: its default).
    real_dir: Option<PathBuf>,
}

fn parse(args: &[String]) -> Result<Args> {
    let root = crate::project_root();
    let mut parsed = Args {
        planning: false,
        mapsize: false,
        segmentation: false,
        install: false,
        seeds: 10,
        poses: 4,
        bench: root.join("../shared/bench"),
        lab_frames: segmentation::LAB_FRAMES,
        real_dir: None,
    };
    let mut any = false;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = || it.next().with_context(|| format!("{a} needs a value"));
        match a.as_str() {
            "planning" => (parsed.planning, any) = (true, true),
            "mapsize" => (parsed.mapsize, any) = (true, true),
            "segmentation" => (parsed.segmentation, any) = (true, true),
            "all" => {
                (parsed.planning, parsed.mapsize, parsed.segmentation, any) =
                    (true, true, true, true)
            }
            "--install" => parsed.install = true,
            "--seeds" => {
                parsed.seeds = value()?.parse().context("--seeds takes a whole number")?;
                if !(1..=1000).contains(&parsed.seeds) {
                    bail!("--seeds must be between 1 and 1000");
                }
            }
            "--poses" => {
                parsed.poses = value()?.parse().context("--poses takes a whole number")?;
                if !(1..=64).contains(&parsed.poses) {
                    bail!("--poses must be between 1 and 64");
                }
            }
            "--lab-frames" => {
                parsed.lab_frames =
                    value()?.parse().context("--lab-frames takes a whole number")?;
                if !(1..=64).contains(&parsed.lab_frames) {
                    bail!("--lab-frames must be between 1 and 64");
                }
            }
            "--real-dir" => parsed.real_dir = Some(value()?.into()),
            "--bench-dir" => parsed.bench = value()?.into(),
            other => bail!(
                "unknown argument `{other}` (compare [planning|mapsize|segmentation|all] \
                 [--install] [--seeds N] [--poses N] [--lab-frames N] [--real-dir D] \
                 [--bench-dir D])"
            ),
        }
    }
    if !any {
        (parsed.planning, parsed.mapsize, parsed.segmentation) = (true, true, true);
    }
    Ok(parsed)
}

/// The programs and folders every part uses.
pub(crate) struct Env {
    /// The release build of `patchnav`.
    pub(crate) patchnav: PathBuf,
    /// Where the C++ programs are.
    pub(crate) build: PathBuf,
    /// Where rows, inputs and intermediate files go.
    pub(crate) out: PathBuf,
    /// The shared bench (floor plan mesh, problem, depth image).
    pub(crate) bench: PathBuf,
}

/// Runs `cargo xtask compare ARGS`.
pub fn run(args: &[String]) -> Result<()> {
    let args = parse(args)?;
    let root = crate::project_root();
    ensure_packages(args.install)?;
    let build = root.join("target/compare-build");
    eprintln!("building compare/ into {}", build.display());
    crate::capture(
        Command::new("cmake")
            .arg("-S")
            .arg(root.join("compare"))
            .arg("-B")
            .arg(&build)
            .arg("-DCMAKE_BUILD_TYPE=Release"),
    )?;
    crate::capture(Command::new("cmake").arg("--build").arg(&build).arg("-j2"))?;
    let patchnav = crate::build_patchnav(&root)?;
    let env = Env { patchnav, build, out: root.join("target/compare"), bench: args.bench.clone() };
    std::fs::create_dir_all(&env.out).with_context(|| format!("creating {}", env.out.display()))?;
    let provenance = crate::provenance::collect(0);
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let mut summary = format!(
        "# One run of `cargo xtask compare`\n\nhost: {}, CPU: {}, load average before the run: {}\n",
        provenance["host"],
        provenance["cpu"],
        load.trim()
    );
    let mut part = |name: &str, rows: Vec<Value>, table: String| -> Result<()> {
        let path = env.out.join(format!("{name}.jsonl"));
        let mut text = String::new();
        for mut row in rows {
            row["provenance"] = provenance.clone();
            writeln!(text, "{row}")?;
        }
        pointcloud::io::write_bytes_atomically(&path, text)?;
        println!("\n## {name}\n\n{table}\n(rows: {})", path.display());
        write!(summary, "\n## {name}\n\n{table}\n")?;
        Ok(())
    };
    if args.planning || args.mapsize {
        // The lab scans feed the lab planning problem and the map sizes.
        planning::lab_inputs(&env, args.poses)?;
    }
    if args.planning {
        let (rows, table) = planning::run(&env, args.seeds)?;
        part("planning", rows, table)?;
    }
    if args.mapsize {
        let (rows, table) = mapsize::run(&env, args.poses)?;
        part("mapsize", rows, table)?;
    }
    if args.segmentation {
        let mut options = segmentation::Options::from_env();
        options.lab_frames = args.lab_frames;
        if let Some(dir) = &args.real_dir {
            options.real_dir = dir.clone();
        }
        let (rows, table) = segmentation::run_with(&env, &options)?;
        part("segmentation", rows, table)?;
    }
    let path = env.out.join("summary.md");
    pointcloud::io::write_bytes_atomically(&path, summary)?;
    println!("\nwrote {}", path.display());
    Ok(())
}

/// Checks the Debian packages; installs the missing ones with `install`, else fails with the
/// command that would.
fn ensure_packages(install: bool) -> Result<()> {
    let missing: Vec<&str> = PACKAGES
        .iter()
        .copied()
        .filter(|p| {
            Command::new("dpkg-query")
                .args(["-W", "-f=${Status}", p])
                .output()
                .map(|o| !String::from_utf8_lossy(&o.stdout).contains("install ok installed"))
                .unwrap_or(true)
        })
        .collect();
    if missing.is_empty() {
        return Ok(());
    }
    let line = format!("apt-get install -y --no-install-recommends {}", missing.join(" "));
    if !install {
        bail!(
            "missing Debian packages: {} — run `{line}` (as root) or `cargo xtask compare --install`",
            missing.join(" ")
        );
    }
    eprintln!("installing {}", missing.join(" "));
    let root_user = Command::new("id").arg("-u").output().map(|o| o.stdout.starts_with(b"0"));
    let mut cmd = if matches!(root_user, Ok(true)) {
        Command::new("apt-get")
    } else {
        let mut c = Command::new("sudo");
        c.arg("apt-get");
        c
    };
    cmd.env("DEBIAN_FRONTEND", "noninteractive")
        .args(["install", "-y", "--no-install-recommends"])
        .args(&missing);
    let status = cmd.status().context("could not start apt-get")?;
    if !status.success() {
        bail!("`{line}` failed (try `apt-get update` first)");
    }
    Ok(())
}

/// Runs a program and returns the JSON objects it printed, one per line; a failure is an error
/// naming the command and the last line of its standard error.
pub(crate) fn json_lines(program: &Path, args: &[String]) -> Result<Vec<Value>> {
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

pub(crate) use evaluation::stats::median;

/// `ours / theirs` as text (`–` when either is missing or `theirs` is zero).
pub(crate) fn ratio(ours: Option<f64>, theirs: Option<f64>) -> String {
    match (ours, theirs) {
        (Some(a), Some(b)) if b != 0.0 && a.is_finite() && b.is_finite() => format!("{:.3}", a / b),
        _ => "–".to_owned(),
    }
}

/// A number with three decimals from 1 up, three significant digits below 1, none from 1000
/// up; `–` when missing.
pub(crate) fn num(v: Option<f64>) -> String {
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
pub(crate) fn arg(s: impl AsRef<std::ffi::OsStr>) -> String {
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

    #[test]
    fn parse_defaults_to_all_and_rejects_bad_seeds() {
        let a = parse(&[]).unwrap();
        assert!(a.planning && a.mapsize && a.segmentation && !a.install);
        let a = parse(&["planning".into(), "--seeds".into(), "3".into()]).unwrap();
        assert!(a.planning && !a.mapsize && a.seeds == 3);
        assert!(parse(&["--seeds".into(), "0".into()]).is_err());
        assert!(parse(&["--seeds".into(), "x".into()]).is_err());
        assert!(parse(&["bogus".into()]).is_err());
    }
}
