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
use evaluation::compare::{Env, segmentation};
use serde_json::Value;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::Command;

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
        evaluation::compare::planning::lab_inputs(&env, args.poses)?;
    }
    if args.planning {
        let (rows, table) = evaluation::compare::planning::run(&env, args.seeds)?;
        part("planning", rows, table)?;
    }
    if args.mapsize {
        let (rows, table) = evaluation::compare::mapsize::run(&env, args.poses)?;
        part("mapsize", rows, table)?;
    }
    if args.segmentation {
        let mut options = segmentation::Options::from_env(&root);
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

#[cfg(test)]
mod tests {
    use super::*;

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
