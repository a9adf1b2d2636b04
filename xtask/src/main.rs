//! Project automation, run as `cargo xtask <command>` (see `.cargo/config.toml`).
//!
//! * `cargo xtask fixtures [--check]`: regenerates the small committed files in `fixtures/`
//!   deterministically from our own simulator (`--check` only compares).
//! * `cargo xtask bench [NAME ...] [--seed N] [--out FILE]`: runs named benchmarks of the
//!   `bench-matrix` program in release mode and appends one JSON line per measurement, with the
//!   provenance of the run (git revision, host, CPU, date, seed), to `target/bench/results.jsonl`.
//! * `cargo xtask bench roadmap [--scene S] [--backend B] [--planner P] [--seeds N] [--jobs N]
//!   [--resume]`: the planning matrix; also OMPL benchmark logs in `target/bench/ompl/`.
//! * `cargo xtask docs [--results F] [--out F]`: generates `docs/benchmarks.md` from the results.
//! * `cargo xtask peers planes [--peers-dir DIR] [--peers-build DIR] [--bench-dir DIR] [--out F]`:
//!   our plane extraction beside PCL's and Open3D's on the shared floor-plan clouds, one process
//!   per run, quality against the floor plan's mesh; JSONL rows to `target/peers/planes.jsonl`
//!   and a side-by-side table on stdout (docs/extraction-peers.md).
//! * `cargo xtask peers terrain [--peers-dir DIR] [--peers-build DIR] [--out F]`: our Hough
//!   terrain classification beside one RANSAC ground-plane fit of PCL and Open3D on the same
//!   frames, ratio ours/theirs (docs/terrain.md).
//! * `cargo xtask peers ground [--scan-dir DIR] [--seeds 2,3] [--venv DIR] [--out F]`: our
//!   per-point ground segmentation beside Patchwork++ (PyPI `pypatchworkpp` in a virtual
//!   environment it creates) on the labelled SemanticKITTI scan, precision / recall / F1 and ms;
//!   ours on simulated frames (docs/terrain.md).
//! * `cargo xtask compare [planning|mapsize|segmentation|all] [--install] [--seeds N] [--poses N]`:
//!   OMPL + FCL planners, OctoMap and PCL segmentation built from `compare/` beside ours on the
//!   same inputs in one run, ratios ours/theirs; JSONL rows to `target/compare/`
//!   (docs/comparison.md).
//! * `cargo xtask voxel-world [--seed S] [--out DIR]`: the generated city-like voxel world
//!   (more than 100,000 triangles, mixed patch sizes) as OBJ and planning problem
//!   (docs/performance.md).

use anyhow::{Result, bail};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

mod bench;
mod compare;
mod docs;
mod fixtures;
mod peers;
mod provenance;
mod voxel_world;

const USAGE: &str = "\
usage: cargo xtask <command>

commands:
  fixtures [--check]                    regenerate fixtures/ (or check they are current)
  bench [NAME ...] [--seed N] [--out F] run named benchmarks (default: all), append JSONL rows
  bench --list                          list the benchmark names
  bench lab-volume [--seeds N] [--jobs N]
                                        Tables 6.1, 6.2, 6.4 on the lab maps built from scans
  bench roadmap [--scene S] [--backend B] [--planner P] [--seeds N] [--jobs N] [--resume]
                                        the planning matrix (scenes x backends x planners x seeds);
                                        scenes office, lab, lab-scans (maps built from simulated
                                        scans: [--lab-scans N] [--lab-scan-step-deg D]);
                                        --resume skips cases already in the results for this git
                                        revision; also writes OMPL logs to target/bench/ompl/
  docs [--results F] [--out F]          generate docs/benchmarks.md (and docs/img/) from the results
  peers planes [--peers-dir D] [--peers-build D] [--bench-dir D] [--out F]
                                        our plane extraction beside PCL and Open3D (same inputs)
  peers terrain [--peers-dir D] [--peers-build D] [--out F]
                                        Hough terrain classes beside a RANSAC ground plane (PCL, Open3D)
  peers ground [--scan-dir D] [--seeds 2,3] [--venv D] [--out F]
                                        per-point ground beside Patchwork++ (pip, in a venv)
  compare [planning|mapsize|segmentation|all] [--install] [--seeds N] [--poses N]
          [--lab-frames N] [--real-dir D]
                                        OMPL+FCL, OctoMap, PCL (built from compare/) beside ours
  voxel-world [--seed S] [--out D]      a generated city of voxels (mixed patch sizes, >100k
                                        triangles) as OBJ + planning problem, for the planners
";

fn main() -> ExitCode {
    match try_main() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn try_main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some((command, rest)) = args.split_first() else {
        print!("{USAGE}");
        return Ok(());
    };
    match command.as_str() {
        "fixtures" => {
            let check = match rest {
                [] => false,
                [flag] if flag == "--check" => true,
                _ => bail!("fixtures takes only --check\n\n{USAGE}"),
            };
            let dir = project_root().join("fixtures");
            if check {
                let stale = fixtures::check(&dir)?;
                if !stale.is_empty() {
                    bail!("fixtures are stale: {} (run `cargo xtask fixtures`)", stale.join(", "));
                }
                println!("fixtures are current");
            } else {
                for name in fixtures::write_all(&dir)? {
                    println!("wrote fixtures/{name}");
                }
            }
            Ok(())
        }
        "bench" => bench::run(rest),
        "docs" => docs::run(rest),
        "peers" => peers::run(rest),
        "compare" => compare::run(rest),
        "voxel-world" => voxel_world::run(rest),
        "help" | "--help" | "-h" => {
            print!("{USAGE}");
            Ok(())
        }
        other => bail!("unknown command `{other}`\n\n{USAGE}"),
    }
}

/// The workspace root (the parent of this crate's directory).
fn project_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().map(Path::to_path_buf).unwrap_or_default()
}

/// Builds `patchnav` in release mode and returns the path of the binary (the peer comparisons
/// run it as one process per measurement).
fn build_patchnav(root: &Path) -> Result<PathBuf> {
    eprintln!("building patchnav (release)");
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    capture(std::process::Command::new(cargo).current_dir(root).args([
        "build",
        "--quiet",
        "--release",
        "-p",
        "patchnav",
    ]))?;
    Ok(root.join("target/release/patchnav"))
}

use evaluation::compare::capture;
