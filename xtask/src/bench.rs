//! `cargo xtask bench`: runs the named benchmarks of `bench-matrix` in release mode and appends
//! their rows, with provenance, to a JSONL file.

use anyhow::{Context, Result, bail};
use serde_json::Value;
use std::io::Write as _;
use std::path::PathBuf;
use std::process::Command;

struct Args {
    names: Vec<String>,
    seed: u64,
    out: PathBuf,
    list: bool,
}

fn parse(args: &[String]) -> Result<Args> {
    let mut parsed = Args {
        names: Vec::new(),
        seed: 0,
        out: crate::project_root().join("target/bench/results.jsonl"),
        list: false,
    };
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--seed" => {
                let v = it.next().context("--seed needs a value")?;
                parsed.seed = v.parse().with_context(|| format!("bad --seed `{v}`"))?;
            }
            "--out" => parsed.out = it.next().context("--out needs a path")?.into(),
            "--list" => parsed.list = true,
            flag if flag.starts_with('-') => bail!("unknown flag `{flag}`"),
            name => parsed.names.push(name.to_owned()),
        }
    }
    Ok(parsed)
}

/// Runs `cargo xtask bench ARGS`.
pub fn run(args: &[String]) -> Result<()> {
    let args = parse(args)?;
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    let mut cmd = Command::new(cargo);
    cmd.current_dir(crate::project_root()).args([
        "run",
        "--quiet",
        "--release",
        "-p",
        "bench-matrix",
        "--",
    ]);
    if args.list {
        cmd.arg("--list");
        print!("{}", crate::capture(&mut cmd)?);
        return Ok(());
    }
    cmd.arg("--seed").arg(args.seed.to_string()).args(&args.names);
    let provenance = crate::provenance::collect(args.seed);
    // Benchmarks print their tables (thesis beside ours) on standard error: show them.
    cmd.stderr(std::process::Stdio::inherit());
    let stdout = crate::capture(&mut cmd)?;
    if let Some(dir) = args.out.parent() {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let mut file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&args.out)
        .with_context(|| format!("opening {}", args.out.display()))?;
    let mut rows = 0;
    for line in stdout.lines().filter(|l| !l.trim().is_empty()) {
        let mut row: Value =
            serde_json::from_str(line).with_context(|| format!("bench-matrix printed `{line}`"))?;
        let Some(obj) = row.as_object_mut() else { bail!("bench row is not an object: {line}") };
        obj.insert("provenance".to_owned(), provenance.clone());
        writeln!(file, "{row}")?;
        println!("{}", summary(&row));
        rows += 1;
    }
    println!("appended {rows} rows to {}", args.out.display());
    Ok(())
}

fn summary(row: &Value) -> String {
    let s = |k: &str| row.get(k).and_then(Value::as_str).unwrap_or("?").to_owned();
    let value = row.get("value").and_then(Value::as_f64).unwrap_or(f64::NAN);
    format!("{:<8} {:<34} {:<14} {:>12.3} {}", s("bench"), s("case"), s("metric"), value, s("unit"))
}
