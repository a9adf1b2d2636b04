//! `cargo xtask docs`: writes `docs/benchmarks.md` and its plot from the matrix rows
//! ([`evaluation::benchmarks`] makes them).

use anyhow::{Context, Result, bail};
use evaluation::benchmarks::{Matrix, office_time_svg, page};
use serde_json::Value;
use std::path::PathBuf;

/// Runs `cargo xtask docs [--results FILE] [--out FILE]`.
pub fn run(args: &[String]) -> Result<()> {
    let root = crate::project_root();
    let mut results = root.join("target/bench/results.jsonl");
    let mut out = root.join("docs/benchmarks.md");
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--results" => results = PathBuf::from(it.next().context("--results needs a path")?),
            "--out" => out = PathBuf::from(it.next().context("--out needs a path")?),
            other => bail!("docs takes --results FILE and --out FILE, not `{other}`"),
        }
    }
    let text = std::fs::read_to_string(&results)
        .with_context(|| format!("reading {}", results.display()))?;
    let rows: Vec<Value> = text.lines().filter_map(|l| serde_json::from_str(l).ok()).collect();
    let m = Matrix::from_rows(&rows);
    let dir = out.parent().context("--out has no folder")?;
    let img = dir.join("img");
    std::fs::create_dir_all(&img).with_context(|| format!("creating {}", img.display()))?;
    let svg = img.join("benchmarks-office-time.svg");
    pointcloud::io::write_bytes_atomically(&svg, office_time_svg(&m))?;
    pointcloud::io::write_bytes_atomically(&out, page(&m, "img/benchmarks-office-time.svg")?)?;
    println!("wrote {} and {} from {} rows", out.display(), svg.display(), m.rows);
    Ok(())
}
