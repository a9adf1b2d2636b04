//! `cargo xtask bench`: runs the named benchmarks of `bench-matrix` in release mode and appends
//! their rows, with provenance, to a JSONL file.
//!
//! Rows are appended as the benchmark prints them, so an interrupted run keeps every case it
//! finished; `--resume` then skips the cases of the `roadmap` matrix already in the results
//! file for the same git revision (a case key holds the scene, backend, planner and seed). After
//! a run of the matrix its rows of this revision are also written as OMPL benchmark logs, one per
//! scene and backend, under `target/bench/ompl/` (see [`evaluation::ompl_log`]).
//!
//! # The lab's maps from scans
//! The matrix's `lab-scans-*` scenes (thesis Fig 6.4 as the thesis ran it) and the
//! `lab-volume` benchmark (Tables 6.1, 6.2, 6.4) use the lab's four map types built from
//! simulated ALRF scans. The scan → extraction pipeline lives in `patchnav`, so when the
//! selection runs any of those scenes (the matrix with no `--scene`, `--scene lab-scans`, or a
//! `lab-scans-*` name) or `lab-volume` (named, or all benchmarks) this command builds the
//! release `patchnav` and, once, the four map files with `patchnav map build --scene lab
//! --kind K --source scans` (patch maps in the polygon backend, the pc map as a point-cloud
//! map) into `target/bench/lab-maps/<key>/`, the key naming every build parameter
//! ([`LabMapParams`]); both benchmarks read the same folder.
//! The folder is reused while its `build.json` (written last, after all four maps) is newer
//! than the `patchnav` binary, so a changed pipeline rebuilds it. `bench-matrix` gets the
//! folder in `$PATCHNAV_LAB_MAPS`. `--lab-scans N` (default 8, `patchnav experiment
//! lab-timing`'s default; the thesis's Lab has 29) and `--lab-scan-step-deg D` (default: the
//! S300's 0.5°) choose the scans. `lab-volume` takes `--seeds N` and `--jobs N` as the matrix
//! does, and its size from the environment `bench-matrix` inherits
//! (`PATCHNAV_LAB_VOLUME_K`, `_PRM_K`, `_STARTS`, `_CELLS`).

use anyhow::{Context, Result, bail};
use patch_map::Backend;
use patch_pipeline::scene_map::MapKind;
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
    /// How the lab's maps from scans are built.
    lab: LabMapParams,
}

/// The build parameters of the lab's maps from scans: the cache key, and the options of
/// `patchnav map build`.
#[derive(Clone, Debug, PartialEq)]
pub struct LabMapParams {
    /// Seed of the lab scene, the scan poses and the sensor noise (the matrix's exact lab uses
    /// seed 0).
    pub scene_seed: u64,
    /// Simulated ALRF scans.
    pub scans: u64,
    /// Scanner height above the floor, metres.
    pub scan_height: f64,
    /// Angular step of the ALRF in degrees; `None`: the S300's 0.5°.
    pub scan_step_deg: Option<f64>,
}

impl Default for LabMapParams {
    /// `patchnav experiment lab-timing`'s defaults.
    fn default() -> LabMapParams {
        LabMapParams { scene_seed: 0, scans: 8, scan_height: 0.5, scan_step_deg: None }
    }
}

impl LabMapParams {
    /// Checks the numbers.
    pub fn validate(&self) -> Result<()> {
        if self.scans == 0 || self.scans > 1000 {
            bail!("--lab-scans must be between 1 and 1000, got {}", self.scans);
        }
        if let Some(step) = self.scan_step_deg
            && !(step.is_finite() && step > 0.0 && step <= 30.0)
        {
            bail!("--lab-scan-step-deg must be above 0 and at most 30 degrees, got {step}");
        }
        if !(self.scan_height.is_finite() && self.scan_height > 0.0) {
            bail!("the scan height must be a positive number of metres, got {}", self.scan_height);
        }
        Ok(())
    }

    /// The cache folder's name: every parameter, so different builds never share a folder.
    pub fn key(&self) -> String {
        let step = self.scan_step_deg.map_or_else(|| "s300".to_owned(), |s| s.to_string());
        format!("lab-seed{}-scans{}-h{}-step{step}", self.scene_seed, self.scans, self.scan_height)
    }

    /// The arguments of `patchnav` that build the map of `kind` into `out`.
    pub fn patchnav_args(&self, kind: MapKind, out: &Path) -> Vec<String> {
        let backend = if kind == MapKind::Pc { Backend::PointCloud } else { Backend::Polygon };
        let mut a: Vec<String> = [
            "--quiet",
            "map",
            "build",
            "--scene",
            "lab",
            "--kind",
            kind.name(),
            "--source",
            "scans",
            "--backend",
            backend.name(),
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        a.extend(["--scene-seed".into(), self.scene_seed.to_string()]);
        a.extend(["--scans".into(), self.scans.to_string()]);
        a.extend(["--scan-height".into(), self.scan_height.to_string()]);
        if let Some(step) = self.scan_step_deg {
            a.extend(["--scan-step-deg".into(), step.to_string()]);
        }
        a.extend(["--out".into(), out.display().to_string()]);
        a
    }
}

fn parse(args: &[String]) -> Result<Args> {
    let mut parsed = Args {
        names: Vec::new(),
        seed: 0,
        out: crate::project_root().join("target/bench/results.jsonl"),
        list: false,
        matrix: Vec::new(),
        resume: false,
        lab: LabMapParams::default(),
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
            "--lab-scans" => {
                let v = it.next().context("--lab-scans needs a value")?;
                parsed.lab.scans = v.parse().with_context(|| format!("bad --lab-scans `{v}`"))?;
            }
            "--lab-scan-step-deg" => {
                let v = it.next().context("--lab-scan-step-deg needs a value")?;
                parsed.lab.scan_step_deg =
                    Some(v.parse().with_context(|| format!("bad --lab-scan-step-deg `{v}`"))?);
            }
            flag @ ("--scene" | "--backend" | "--planner" | "--seeds" | "--jobs") => {
                let v = it.next().with_context(|| format!("{flag} needs a value"))?;
                parsed.matrix.extend([flag.to_owned(), v.clone()]);
            }
            flag if flag.starts_with('-') => bail!("unknown flag `{flag}`"),
            name => parsed.names.push(name.to_owned()),
        }
    }
    parsed.lab.validate()?;
    Ok(parsed)
}

/// Whether the selection runs a `lab-scans-*` scene of the matrix: the matrix runs, and no
/// `--scene` is given or one names `lab-scans` or a `lab-scans-*` scene.
fn runs_lab_scans(names: &[String], matrix: &[String]) -> bool {
    let scenes: Vec<&str> = matrix
        .chunks(2)
        .filter(|f| f[0] == "--scene")
        .flat_map(|f| f.get(1).map_or("", String::as_str).split(','))
        .filter(|s| !s.is_empty())
        .collect();
    runs_matrix(names)
        && (scenes.is_empty()
            || scenes.iter().any(|s| *s == "lab-scans" || s.starts_with("lab-scans-")))
}

/// Whether the selection runs the `lab-volume` benchmark: it is named, or no name is given
/// (all benchmarks).
fn runs_lab_volume(names: &[String]) -> bool {
    names.is_empty() || names.iter().any(|n| n == "lab-volume")
}

/// Whether the selection needs the lab's maps from scans: it runs a `lab-scans-*` scene of
/// the matrix or the `lab-volume` benchmark (both read the same cached build).
fn needs_lab_maps(names: &[String], matrix: &[String]) -> bool {
    runs_lab_scans(names, matrix) || runs_lab_volume(names)
}

/// Whether `dir` holds a complete build newer than `binary`: all four map files and
/// `build.json` (written last), whose modification time is not before the binary's.
pub fn lab_maps_fresh(dir: &Path, binary: &Path) -> bool {
    let modified = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    let (Some(built), Some(bin)) = (modified(&dir.join("build.json")), modified(binary)) else {
        return false;
    };
    built >= bin && MapKind::ALL.iter().all(|k| dir.join(format!("{k}.pmap")).is_file())
}

/// The folder of the lab's four maps from scans for `params`, built with the release
/// `patchnav` unless a fresh build is there.
fn lab_maps(params: &LabMapParams) -> Result<PathBuf> {
    let root = crate::project_root();
    let binary = crate::build_patchnav(&root)?;
    let dir = root.join("target/bench/lab-maps").join(params.key());
    if lab_maps_fresh(&dir, &binary) {
        println!("lab maps from scans: reusing {}", dir.display());
        return Ok(dir);
    }
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let _ = std::fs::remove_file(dir.join("build.json"));
    let mut commands = Vec::new();
    for kind in MapKind::ALL {
        let t0 = std::time::Instant::now();
        let (tmp, out) = (dir.join(format!("{kind}.pmap.tmp")), dir.join(format!("{kind}.pmap")));
        let args = params.patchnav_args(kind, &tmp);
        crate::capture(Command::new(&binary).args(&args))
            .with_context(|| format!("building the lab's {kind} map from scans"))?;
        std::fs::rename(&tmp, &out)
            .with_context(|| format!("renaming {} to {}", tmp.display(), out.display()))?;
        println!(
            "lab maps from scans: built {} in {:.1} s",
            out.display(),
            t0.elapsed().as_secs_f64()
        );
        commands.push(format!("patchnav {}", params.patchnav_args(kind, &out).join(" ")));
    }
    let manifest = serde_json::json!({
        "scene": "lab",
        "source": "scans",
        "scene_seed": params.scene_seed,
        "scans": params.scans,
        "scan_height": params.scan_height,
        "scan_step_deg": params.scan_step_deg,
        "commands": commands,
    });
    let path = dir.join("build.json");
    pointcloud::io::write_bytes_atomically(&path, format!("{manifest:#}\n"))?;
    Ok(dir)
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
    if needs_lab_maps(&args.names, &args.matrix) {
        cmd.env("PATCHNAV_LAB_MAPS", lab_maps(&args.lab)?);
    }
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
        pointcloud::io::write_bytes_atomically(&list, text)?;
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
        for path in evaluation::ompl_log::write_logs(&rows, &dir)? {
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
        assert_eq!(p.lab, LabMapParams::default());
        assert!(!runs_lab_scans(&p.names, &p.matrix), "--scene office only");
        for bad in [&["--lab-scans", "0"][..], &["--lab-scans"], &["--lab-scan-step-deg", "NaN"]] {
            let bad: Vec<String> = bad.iter().map(|s| s.to_string()).collect();
            assert!(parse(&bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn lab_scans_scenes_get_maps_built_by_their_parameters() {
        let strings = |a: &[&str]| a.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        let p =
            parse(&strings(&["roadmap", "--scene", "lab,lab-scans", "--lab-scans", "3"])).unwrap();
        assert!(runs_lab_scans(&p.names, &p.matrix));
        assert!(runs_lab_scans(&[], &[]), "the whole matrix");
        assert!(runs_lab_scans(&[], &strings(&["--scene", "lab-scans-pc", "--jobs", "2"])));
        assert!(!runs_lab_scans(&strings(&["tof"]), &[]));
        assert!(!runs_lab_scans(&[], &strings(&["--jobs", "2", "--scene", "lab"])));
        // lab-volume reads the same maps, whatever the matrix's scenes.
        assert!(needs_lab_maps(&strings(&["lab-volume"]), &[]));
        assert!(needs_lab_maps(&strings(&["tof", "lab-volume"]), &strings(&["--seeds", "3"])));
        assert!(needs_lab_maps(&[], &strings(&["--scene", "office"])), "all benchmarks");
        assert!(!needs_lab_maps(&strings(&["roadmap"]), &strings(&["--scene", "office"])));
        assert!(!needs_lab_maps(&strings(&["tof", "io"]), &[]));
        assert!(needs_lab_maps(&strings(&["roadmap"]), &[]), "the whole matrix");
        let v = parse(&strings(&["lab-volume", "--seeds", "24", "--jobs", "2"])).unwrap();
        assert_eq!(v.matrix, ["--seeds", "24", "--jobs", "2"], "--seeds and --jobs pass through");
        assert!(needs_lab_maps(&v.names, &v.matrix) && !runs_matrix(&v.names));
        // Every parameter is in the key.
        let base = p.lab.clone();
        assert_eq!(base.scans, 3);
        let variants = [
            LabMapParams { scene_seed: 1, ..base.clone() },
            LabMapParams { scans: 4, ..base.clone() },
            LabMapParams { scan_height: 0.6, ..base.clone() },
            LabMapParams { scan_step_deg: Some(0.5), ..base.clone() },
            base.clone(),
        ];
        let keys: HashSet<String> = variants.iter().map(LabMapParams::key).collect();
        assert_eq!(keys.len(), variants.len(), "{keys:?}");
        assert!(keys.iter().all(|k| !k.contains('/') && !k.contains(' ')));
        // The patchnav command line builds from scans with the parameters.
        let a = LabMapParams { scan_step_deg: Some(2.0), ..base }
            .patchnav_args(MapKind::Pc, Path::new("d/pc.pmap"));
        let line = a.join(" ");
        assert!(line.contains("map build --scene lab --kind pc --source scans"), "{line}");
        assert!(line.contains("--backend pointcloud") && line.contains("--scans 3"), "{line}");
        assert!(line.contains("--scan-step-deg 2") && line.ends_with("--out d/pc.pmap"), "{line}");
        let planes = LabMapParams::default().patchnav_args(MapKind::Planes, Path::new("p.pmap"));
        assert!(planes.join(" ").contains("--backend polygon"));
        assert!(!planes.iter().any(|a| a == "--scan-step-deg"));
    }

    #[test]
    fn a_cached_build_is_fresh_only_when_complete_and_newer_than_patchnav() {
        use std::time::{Duration, SystemTime};
        let dir = tempfile::tempdir().unwrap();
        let binary = dir.path().join("patchnav");
        std::fs::write(&binary, "").unwrap();
        let maps = dir.path().join("maps");
        std::fs::create_dir(&maps).unwrap();
        let touch = |p: &Path, t: SystemTime| {
            std::fs::write(p, "x").unwrap();
            std::fs::File::options().write(true).open(p).unwrap().set_modified(t).unwrap();
        };
        let now = SystemTime::now();
        touch(&binary, now - Duration::from_secs(60));
        for k in MapKind::ALL {
            touch(&maps.join(format!("{k}.pmap")), now);
        }
        assert!(!lab_maps_fresh(&maps, &binary), "no build.json: interrupted");
        touch(&maps.join("build.json"), now);
        assert!(lab_maps_fresh(&maps, &binary));
        touch(&binary, now + Duration::from_secs(60));
        assert!(!lab_maps_fresh(&maps, &binary), "patchnav changed since");
        touch(&binary, now - Duration::from_secs(60));
        std::fs::remove_file(maps.join("pc.pmap")).unwrap();
        assert!(!lab_maps_fresh(&maps, &binary), "a map is missing");
        assert!(!lab_maps_fresh(&maps, &dir.path().join("no-such-binary")));
    }
}
