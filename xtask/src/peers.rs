//! `cargo xtask peers planes|terrain`: builds `patchnav`, finds the peers' programs, runs the
//! generators of [`evaluation::peers`] and writes their rows (JSONL) and tables.
//!
//! * `planes [--peers-dir D] [--peers-build D] [--bench-dir D] [--out F]`: our plane extraction
//!   beside PCL's and Open3D's on the shared floor-plan clouds (docs/extraction-peers.md).
//! * `terrain [--peers-dir D] [--peers-build D] [--out F]`: our Hough terrain classification
//!   beside one RANSAC ground-plane fit (docs/terrain.md).

use anyhow::{Context, Result, bail};
use evaluation::peers::Peers;
use std::fmt::Write as _;
use std::path::PathBuf;

/// Which comparison, and where things are.
#[derive(Debug)]
struct Args {
    terrain: bool,
    peers_dir: PathBuf,
    peers_build: Option<PathBuf>,
    bench_dir: Option<PathBuf>,
    out: PathBuf,
}

fn parse(args: &[String]) -> Result<Args> {
    let root = crate::project_root();
    let mut it = args.iter();
    let terrain = match it.next().map(String::as_str) {
        Some("planes") => false,
        Some("terrain") => true,
        Some(other) => bail!("unknown peers comparison `{other}` (`planes` or `terrain`)"),
        None => bail!("peers needs a comparison: `planes` or `terrain`"),
    };
    let out = if terrain { "target/peers/terrain.jsonl" } else { "target/peers/planes.jsonl" };
    let mut parsed = Args {
        terrain,
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
            "--bench-dir" if !terrain => parsed.bench_dir = Some(value()?.into()),
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
    let (mut rows, table) = if args.terrain {
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
    if args.terrain {
        println!("{table}rows: {}", args.out.display());
    } else {
        println!("{table}");
        let (n, work) = (rows.len(), env.work.display());
        println!("\nwrote {} ({n} rows; polygons in {work})", args.out.display());
    }
    Ok(())
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
        assert!(a(&["planes", "--out"]).is_err());
        assert!(a(&["planes", "--bogus"]).is_err());
    }
}
