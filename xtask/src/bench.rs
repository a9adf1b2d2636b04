//! `cargo xtask bench`: runs the named benchmarks of `bench-matrix` in release mode and appends
//! their rows, with provenance, to a JSONL file.
//!
//! Rows are appended as the benchmark prints them, so an interrupted run keeps every case it
//! finished; `--resume` then skips the cases of the `roadmap` matrix already in the results
//! file for the same git revision (a case key holds the scene, backend, planner and seed). After
//! a run of the matrix its rows of this revision are also written as OMPL benchmark logs, one per
//! scene and backend, under `target/bench/ompl/` (see [`crate::ompl_log`]).

use anyhow::{Context, Result, bail};
use serde_json::Value;
use std::collections::HashSet;
use std::io::{BufRead as _, Write as _};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

struct Args {
    names: Vec<String>,
    seed: u64,
    out: PathBuf,
    list: bool,
    /// Options passed through to the matrix benchmarks (`--scene`, `--backend`, ...).
    matrix: Vec<String>,
    resume: bool,
}

fn parse(args: &[String]) -> Result<Args> {
    let mut parsed = Args {
        names: Vec::new(),
        seed: 0,
        out: crate::project_root().join("target/bench/results.jsonl"),
        list: false,
        matrix: Vec::new(),
        resume: false,
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
            "--resume" => parsed.resume = true,
            flag @ ("--scene" | "--backend" | "--planner" | "--seeds" | "--jobs") => {
                let v = it.next().with_context(|| format!("{flag} needs a value"))?;
                parsed.matrix.extend([flag.to_owned(), v.clone()]);
            }
            flag if flag.starts_with('-') => bail!("unknown flag `{flag}`"),
            name => parsed.names.push(name.to_owned()),
        }
    }
    Ok(parsed)
}

/// The case keys of the `roadmap` matrix that are complete in `results` (JSONL) for git
/// `revision`: a case is complete when its `solved` row, the last of a case, is there. Lines
/// that are not JSON objects (a line cut short by an interrupted run) are ignored.
pub fn done_cases(results: &str, revision: &str) -> HashSet<String> {
    results
        .lines()
        .filter_map(|l| serde_json::from_str::<Value>(l).ok())
        .filter(|r| {
            r.get("bench").and_then(Value::as_str) == Some("roadmap")
                && r.get("metric").and_then(Value::as_str) == Some("solved")
                && r.pointer("/provenance/git_revision").and_then(Value::as_str) == Some(revision)
        })
        .filter_map(|r| r.get("case").and_then(Value::as_str).map(str::to_owned))
        .collect()
}

/// Whether the selection runs the `roadmap` matrix.
fn runs_matrix(names: &[String]) -> bool {
    names.is_empty() || names.iter().any(|n| n == "roadmap")
}

/// Runs `cargo xtask bench ARGS`.
pub fn run(args: &[String]) -> Result<()> {
    let command = format!("cargo xtask bench {}", args.join(" ")).trim_end().to_owned();
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
    cmd.arg("--seed").arg(args.seed.to_string()).args(&args.names).args(&args.matrix);
    let provenance = crate::provenance::collect(args.seed);
    let revision = provenance.get("git_revision").and_then(Value::as_str).unwrap_or("").to_owned();
    if let Some(dir) = args.out.parent() {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    if args.resume {
        let done = match std::fs::read_to_string(&args.out) {
            Ok(text) => done_cases(&text, &revision),
            Err(_) => HashSet::new(),
        };
        let list = args.out.with_extension("resume.txt");
        let mut keys: Vec<&String> = done.iter().collect();
        keys.sort();
        let text: String = keys.iter().map(|k| format!("{k}\n")).collect();
        std::fs::write(&list, text).with_context(|| format!("writing {}", list.display()))?;
        println!(
            "resuming: {} cases of revision {revision} already in {}",
            done.len(),
            args.out.display()
        );
        cmd.arg("--resume").arg(&list);
    }
    let mut file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&args.out)
        .with_context(|| format!("opening {}", args.out.display()))?;
    // Benchmarks print their tables (thesis beside ours) on standard error: show them.
    cmd.stderr(Stdio::inherit()).stdout(Stdio::piped());
    let mut child = cmd.spawn().with_context(|| format!("could not start {cmd:?}"))?;
    let stdout = child.stdout.take().context("no standard output of bench-matrix")?;
    let mut rows = 0;
    for line in std::io::BufReader::new(stdout).lines() {
        let line = line?;
        if line.trim().is_empty() {
            continue;
        }
        let mut row: Value = serde_json::from_str(&line)
            .with_context(|| format!("bench-matrix printed `{line}`"))?;
        let Some(obj) = row.as_object_mut() else { bail!("bench row is not an object: {line}") };
        obj.insert("provenance".to_owned(), provenance.clone());
        obj.insert("command".to_owned(), command.clone().into());
        writeln!(file, "{row}")?;
        file.flush()?;
        println!("{}", summary(&row));
        rows += 1;
    }
    let status = child.wait()?;
    println!("appended {rows} rows to {}", args.out.display());
    if !status.success() {
        bail!("bench-matrix failed ({status})");
    }
    if runs_matrix(&args.names) {
        let dir = args.out.parent().unwrap_or(Path::new(".")).join("ompl");
        let text = std::fs::read_to_string(&args.out)?;
        let rows: Vec<Value> = text
            .lines()
            .filter_map(|l| serde_json::from_str::<Value>(l).ok())
            .filter(|r| {
                r.pointer("/provenance/git_revision").and_then(Value::as_str)
                    == Some(revision.as_str())
            })
            .collect();
        for path in crate::ompl_log::write_logs(&rows, &dir)? {
            println!("wrote {}", path.display());
        }
    }
    Ok(())
}

fn summary(row: &Value) -> String {
    let s = |k: &str| row.get(k).and_then(Value::as_str).unwrap_or("?").to_owned();
    let value = row.get("value").and_then(Value::as_f64).unwrap_or(f64::NAN);
    format!("{:<8} {:<34} {:<14} {:>12.3} {}", s("bench"), s("case"), s("metric"), value, s("unit"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resume_takes_complete_cases_of_the_same_revision_only() {
        let row = |case: &str, metric: &str, rev: &str| {
            format!(
                r#"{{"bench":"roadmap","case":"{case}","metric":"{metric}","value":1,"provenance":{{"git_revision":"{rev}"}}}}"#
            )
        };
        let text = [
            row("office/polygon/rrt/0", "time", "abc"),
            row("office/polygon/rrt/0", "solved", "abc"),
            // Interrupted before its last row: not done.
            row("office/polygon/rrt/1", "time", "abc"),
            // Another revision: not done for this one.
            row("office/polygon/rrt/2", "solved", "old"),
            // Another benchmark with the same metric name.
            r#"{"bench":"tof","case":"x","metric":"solved","provenance":{"git_revision":"abc"}}"#
                .to_owned(),
            // A line cut short.
            r#"{"bench":"roadmap","case":"office/polygon/rrt/3","metr"#.to_owned(),
        ]
        .join("\n");
        let done = done_cases(&text, "abc");
        assert_eq!(done, HashSet::from(["office/polygon/rrt/0".to_owned()]));
        assert_eq!(done_cases(&text, "old"), HashSet::from(["office/polygon/rrt/2".to_owned()]));
        assert!(done_cases("", "abc").is_empty());
    }

    #[test]
    fn matrix_options_pass_through() {
        let a: Vec<String> = ["roadmap", "--scene", "office", "--jobs", "2", "--resume"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let p = parse(&a).unwrap();
        assert_eq!(p.names, ["roadmap"]);
        assert_eq!(p.matrix, ["--scene", "office", "--jobs", "2"]);
        assert!(p.resume);
        assert!(parse(&["--seeds".to_owned()]).is_err());
        assert!(runs_matrix(&[]) && runs_matrix(&p.names) && !runs_matrix(&["tof".to_owned()]));
    }
}
