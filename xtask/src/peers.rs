//! `cargo xtask peers planes|terrain`: builds `patchnav`, finds the peers' programs, runs the
//! generators of [`evaluation::peers`] and writes their rows (JSONL) and tables.
//!
//! * `planes [--peers-dir D] [--peers-build D] [--bench-dir D] [--out F]`: our plane extraction
//!   beside PCL's and Open3D's on the shared floor-plan clouds (docs/extraction-peers.md).
//! * `terrain [--peers-dir D] [--peers-build D] [--out F]`: our Hough terrain classification
//!   beside one RANSAC ground-plane fit (docs/terrain.md).
//! * `ground [--scan-dir D] [--seeds 1,2,3] [--venv D] [--out F]`: our per-point ground
//!   segmentation beside Patchwork++ (PyPI `pypatchworkpp`, installed into a virtual environment
//!   under `target/peers/venv`) on the labelled SemanticKITTI scan, and ours on simulated frames
//!   (docs/terrain.md).

use anyhow::{Context, Result, bail};
use evaluation::peers::Peers;
use std::fmt::Write as _;
use std::path::PathBuf;

/// Which comparison, and where things are.
#[derive(Debug)]
struct Args {
    terrain: bool,
    ground: bool,
    scan_dir: PathBuf,
    seeds: Vec<u64>,
    venv: PathBuf,
    peers_dir: PathBuf,
    peers_build: Option<PathBuf>,
    bench_dir: Option<PathBuf>,
    out: PathBuf,
}

fn parse(args: &[String]) -> Result<Args> {
    let root = crate::project_root();
    let mut it = args.iter();
    let (terrain, ground) = match it.next().map(String::as_str) {
        Some("planes") => (false, false),
        Some("terrain") => (true, false),
        Some("ground") => (false, true),
        Some(other) => {
            bail!("unknown peers comparison `{other}` (`planes`, `terrain` or `ground`)")
        }
        None => bail!("peers needs a comparison: `planes`, `terrain` or `ground`"),
    };
    let out = match (terrain, ground) {
        (true, _) => "target/peers/terrain.jsonl",
        (_, true) => "target/peers/ground.jsonl",
        _ => "target/peers/planes.jsonl",
    };
    let mut parsed = Args {
        terrain,
        ground,
        scan_dir: root.join("../shared/data/real/semantickitti_labelled_scan"),
        seeds: vec![2, 3],
        venv: root.join("target/peers/venv"),
        peers_dir: root.join("../shared/peers"),
        peers_build: std::env::var_os("PEERS_BUILD_DIR").map(PathBuf::from),
        bench_dir: None,
        out: root.join(out),
    };
    while let Some(a) = it.next() {
        let mut value = || it.next().with_context(|| format!("{a} needs a value"));
        match a.as_str() {
            "--peers-dir" => parsed.peers_dir = value()?.into(),
            "--peers-build" => parsed.peers_build = Some(value()?.into()),
            "--bench-dir" if !terrain && !ground => parsed.bench_dir = Some(value()?.into()),
            "--scan-dir" if ground => parsed.scan_dir = value()?.into(),
            "--venv" if ground => parsed.venv = value()?.into(),
            "--seeds" if ground => {
                parsed.seeds = value()?
                    .split(',')
                    .map(|v| v.trim().parse().with_context(|| format!("--seeds: bad seed `{v}`")))
                    .collect::<Result<_>>()?;
            }
            "--out" => parsed.out = value()?.into(),
            other => bail!("unknown argument `{other}`"),
        }
    }
    Ok(parsed)
}

/// Runs `cargo xtask peers ARGS`.
pub fn run(args: &[String]) -> Result<()> {
    let args = parse(args)?;
    let root = crate::project_root();
    let work = args.out.with_extension("d");
    std::fs::create_dir_all(&work).with_context(|| format!("creating {}", work.display()))?;
    let build_dir = args.peers_build.clone().unwrap_or_else(|| {
        let own = args.peers_dir.join("build");
        if own.join("pcl_planes").is_file() { own } else { root.join("target/peers-build") }
    });
    let env = Peers {
        patchnav: crate::build_patchnav(&root)?,
        bench: args.bench_dir.clone().unwrap_or_else(|| args.peers_dir.join("../bench")),
        peers_dir: args.peers_dir,
        build_dir,
        work,
    };
    let (mut rows, table) = if args.ground {
        let run = evaluation::peers::ground::GroundRun {
            scan_dir: args.scan_dir.clone(),
            patchwork: patchwork(&root, &args.venv),
            seeds: args.seeds.clone(),
        };
        evaluation::peers::ground::run(&env, &run)?
    } else if args.terrain {
        evaluation::peers::terrain::run(&env)?
    } else {
        evaluation::peers::planes(&env)?
    };
    let provenance = crate::provenance::collect(0);
    let mut text = String::new();
    for row in &mut rows {
        if !args.terrain {
            row["provenance"] = provenance.clone();
        }
        writeln!(text, "{row}")?;
    }
    pointcloud::io::write_bytes_atomically(&args.out, text)?;
    if args.terrain || args.ground {
        println!("{table}rows: {}", args.out.display());
    } else {
        println!("{table}");
        let (n, work) = (rows.len(), env.work.display());
        println!("\nwrote {} ({n} rows; polygons in {work})", args.out.display());
    }
    Ok(())
}

/// The virtual environment with Patchwork++ (`pypatchworkpp`, NumPy), created and installed
/// with pip if missing; `Err` says why it is not available.
fn patchwork(
    root: &std::path::Path,
    venv: &std::path::Path,
) -> Result<evaluation::peers::ground::Patchwork, String> {
    use std::process::Command;
    let python = venv.join("bin/python");
    let script = root.join("compare/ground/patchworkpp.py");
    let ok = |python: &std::path::Path| {
        Command::new(python)
            .args(["-c", "import pypatchworkpp, numpy"])
            .output()
            .is_ok_and(|o| o.status.success())
    };
    if !ok(&python) {
        eprintln!(
            "installing Patchwork++ into {} (python3 -m venv; pip install pypatchworkpp numpy)",
            venv.display()
        );
        let run = |cmd: &mut Command| -> Result<(), String> {
            let out = cmd.output().map_err(|e| format!("could not start {cmd:?}: {e}"))?;
            if out.status.success() {
                Ok(())
            } else {
                let err = String::from_utf8_lossy(&out.stderr);
                let last = err.lines().rev().find(|l| !l.trim().is_empty()).unwrap_or("");
                Err(format!("{cmd:?} failed: {last}"))
            }
        };
        run(Command::new("python3").arg("-m").arg("venv").arg(venv))?;
        run(Command::new(&python).args(["-m", "pip", "install", "--quiet", "pypatchworkpp", "numpy"]))
            .map_err(|e| format!("{e} (pip needs network access to PyPI; install pypatchworkpp into {} by hand, or pass --venv)", venv.display()))?;
        if !ok(&python) {
            return Err(format!(
                "{} cannot import pypatchworkpp after installing it",
                python.display()
            ));
        }
    }
    Ok(evaluation::peers::ground::Patchwork { python, script })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arguments() {
        let a = |v: &[&str]| parse(&v.iter().map(|s| s.to_string()).collect::<Vec<_>>());
        let p = a(&["planes", "--peers-dir", "/p", "--out", "/o.jsonl"]).unwrap();
        assert_eq!(p.peers_dir, PathBuf::from("/p"));
        assert_eq!(p.out, PathBuf::from("/o.jsonl"));
        assert!(!p.terrain);
        assert!(a(&["terrain"]).unwrap().terrain);
        assert!(a(&["terrain", "--bench-dir", "/b"]).is_err());
        assert!(a(&[]).is_err());
        assert!(a(&["planning"]).is_err());
        let g = a(&["ground", "--seeds", "4,5", "--scan-dir", "/s"]).unwrap();
        assert!(g.ground && !g.terrain);
        assert_eq!((g.seeds, g.scan_dir), (vec![4, 5], PathBuf::from("/s")));
        assert!(a(&["ground", "--seeds", "x"]).is_err());
        assert!(a(&["planes", "--seeds", "1"]).is_err());
        assert!(a(&["planes", "--out"]).is_err());
        assert!(a(&["planes", "--bogus"]).is_err());
    }
}
