//! Named benchmarks, one JSON object per measurement on standard output.
//!
//! Run them through `cargo xtask bench [NAME ...]`, which builds this program in release mode and
//! appends every row, with the provenance of the run, to `target/bench/results.jsonl`. Each row
//! has `bench`, `case`, `metric`, `value`, `unit`, plus benchmark-specific keys. Timings are the
//! median of several repetitions measured in this one process, so rows of one run can be
//! compared with each other (ratios), not with rows of another machine.
//!
//! Criterion benches (`cargo bench -p scene-sim`) give the statistically careful figures for the
//! same operations; these rows are the matrix's raw material.

use anyhow::{Context, Result, bail};
use pointcloud::io::Precision;
use pointcloud::io::pcd::{PcdEncoding, PcdWriteOptions, read_pcd, write_pcd};
use pointcloud::io::ply::{PlyEncoding, PlyWriteOptions, read_ply, write_ply};
use pointcloud::io::{ReadOptions, xyz};
use scene_sim::{Alrf, RangeCamera, RangeSensor, StereoCamera, scene_by_name};
use serde_json::{Value, json};
use std::time::Instant;

mod lab_volume;
mod roadmap;
mod terrain;

/// Receives the rows of a matrix benchmark as they come.
type Emit<'a> = &'a mut dyn FnMut(Value) -> Result<()>;

/// How a benchmark runs.
enum Run {
    /// A function of the seed giving all its rows at the end.
    Rows(fn(u64) -> Result<Vec<Value>>),
    /// A matrix of cases: takes the selection (`--scene`, `--backend`, `--planner`, `--seeds`,
    /// `--jobs`, `--resume`) and hands over the rows of each case as it finishes, so an
    /// interrupted run keeps what it did.
    Matrix(fn(&roadmap::MatrixArgs, Emit<'_>) -> Result<()>),
}

/// A named benchmark.
struct Bench {
    name: &'static str,
    about: &'static str,
    run: Run,
}

const BENCHES: &[Bench] = &[
    Bench {
        name: "raycast",
        about: "simulated scans of the lab: full ALRF (195,301 beams), range camera, stereo camera",
        run: Run::Rows(raycast),
    },
    Bench {
        name: "io",
        about: "write and read a full ALRF scan in PLY (binary, ascii), PCD (binary, compressed), XYZ",
        run: Run::Rows(io),
    },
    Bench {
        name: "tof",
        about: "Table 2.4: AT 160/240, AAT, AAT+unwrap, two-frequency, AAT+unwrap+spatial on six simulated \
                scenes and a folded real frame; AAT speed",
        run: Run::Rows(tof),
    },
    Bench {
        name: "terrain",
        about: "Tables 4.3, 4.6, 4.7: Hough terrain classes and drivability on simulated snapshots and real \
                frames; votes per second against the literal Algorithm 2",
        run: Run::Rows(terrain::run),
    },
    Bench {
        name: "terrain-mount",
        about: "mount self-calibration (height, pitch, roll from the ground plane) on the simulated \
                snapshots of Table 4.3 from a level and a tilted mount: per frame and over the drive",
        run: Run::Rows(terrain::run_mount),
    },
    Bench {
        name: "roadmap",
        about: "Tables 5.3-5.11, Fig 6.4: scenes (office, lab, lab-scans-{planes,hybrid,trimesh,pc} with \
                $PATCHNAV_LAB_MAPS) x backends x planners x seeds; \
                --scene, --backend, --planner (repeatable or comma-separated), --seeds N, --jobs N, \
                --resume FILE (case keys to skip, one a line)",
        run: Run::Matrix(roadmap::run),
    },
    Bench {
        name: "lab-volume",
        about: "Tables 6.1, 6.2, 6.4: what the lab's four maps from scans hold, and the explored \
                volume of RRT (4 corner starts x --seeds) and PRM (--seeds) on each with the % \
                not explored on the others ($PATCHNAV_LAB_MAPS; --seeds N, --jobs N; \
                PATCHNAV_LAB_VOLUME_K, _PRM_K, _STARTS, _CELLS)",
        run: Run::Matrix(lab_volume::run),
    },
];

fn main() {
    if let Err(e) = try_main() {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn try_main() -> Result<()> {
    let mut seed = 0u64;
    let mut names = Vec::new();
    let mut matrix = roadmap::MatrixArgs {
        scenes: Vec::new(),
        backends: Vec::new(),
        planners: Vec::new(),
        seed: 0,
        seeds: 10,
        jobs: 1,
        skip: Default::default(),
    };
    let mut args = std::env::args().skip(1);
    let list =
        |v: String| v.split(',').filter(|s| !s.is_empty()).map(str::to_owned).collect::<Vec<_>>();
    while let Some(a) = args.next() {
        match a.as_str() {
            "--scene" => matrix.scenes.extend(list(args.next().context("--scene needs a name")?)),
            "--backend" => {
                matrix.backends.extend(list(args.next().context("--backend needs a name")?))
            }
            "--planner" => {
                matrix.planners.extend(list(args.next().context("--planner needs a name")?))
            }
            "--seeds" => {
                let v = args.next().context("--seeds needs a value")?;
                matrix.seeds = v.parse().with_context(|| format!("bad --seeds `{v}`"))?;
            }
            "--jobs" => {
                let v = args.next().context("--jobs needs a value")?;
                matrix.jobs = v.parse().with_context(|| format!("bad --jobs `{v}`"))?;
            }
            "--resume" => {
                let path = args.next().context("--resume needs a file")?;
                let text =
                    std::fs::read_to_string(&path).with_context(|| format!("reading {path}"))?;
                matrix.skip.extend(
                    text.lines().map(str::trim).filter(|l| !l.is_empty()).map(str::to_owned),
                );
            }
            "--list" => {
                for b in BENCHES {
                    println!("{:<10} {}", b.name, b.about);
                }
                return Ok(());
            }
            "--seed" => {
                let v = args.next().context("--seed needs a value")?;
                seed = v.parse().with_context(|| format!("bad --seed `{v}`"))?;
            }
            _ => names.push(a),
        }
    }
    for n in &names {
        if !BENCHES.iter().any(|b| b.name == n) {
            let known: Vec<_> = BENCHES.iter().map(|b| b.name).collect();
            bail!("unknown benchmark `{n}`; known: {}", known.join(", "));
        }
    }
    matrix.seed = seed;
    for b in BENCHES.iter().filter(|b| names.is_empty() || names.iter().any(|n| n == b.name)) {
        let mut emit = |mut row: Value| -> Result<()> {
            use std::io::Write as _;
            if let Some(obj) = row.as_object_mut() {
                obj.insert("bench".into(), b.name.into());
                obj.insert("tool".into(), concat!("patchnav-", env!("CARGO_PKG_VERSION")).into());
            }
            let mut out = std::io::stdout().lock();
            writeln!(out, "{row}")?;
            out.flush()?;
            Ok(())
        };
        match &b.run {
            Run::Rows(run) => {
                for row in run(seed).with_context(|| format!("benchmark `{}`", b.name))? {
                    emit(row)?;
                }
            }
            Run::Matrix(run) => {
                run(&matrix, &mut emit).with_context(|| format!("benchmark `{}`", b.name))?
            }
        }
    }
    Ok(())
}

/// The median wall time of `repeats` calls of `f`, in seconds.
pub(crate) fn median_seconds(repeats: usize, mut f: impl FnMut() -> Result<()>) -> Result<f64> {
    let mut times = Vec::with_capacity(repeats);
    for _ in 0..repeats {
        let t = Instant::now();
        f()?;
        times.push(t.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    Ok(times[times.len() / 2])
}

fn raycast(seed: u64) -> Result<Vec<Value>> {
    let lab = scene_by_name("lab", seed)?;
    let body = *lab.scan_poses(1, 0.6, seed).first().context("no pose in the lab")?;
    let sensors: [(&str, Box<dyn RangeSensor>); 3] = [
        ("lab/alrf-s300", Box::new(Alrf::sick_s300())),
        ("lab/tof-sr3000", Box::new(RangeCamera::swissranger_sr3000())),
        ("lab/stereo-stoc", Box::new(StereoCamera::stoc())),
    ];
    let mut rows = Vec::new();
    for (case, sensor) in &sensors {
        let pose = sensor.mount(&body);
        let pixels = sensor.scan(&lab, &pose, seed).image.ranges().len();
        let secs = median_seconds(5, || {
            let scan = sensor.scan(&lab, &pose, seed);
            std::hint::black_box(scan);
            Ok(())
        })?;
        rows.push(json!({
            "case": case, "metric": "time_per_scan", "value": secs * 1e3, "unit": "ms",
            "beams": pixels, "beams_per_s": pixels as f64 / secs, "repeats": 5, "seed": seed,
        }));
    }
    Ok(rows)
}

fn io(seed: u64) -> Result<Vec<Value>> {
    let lab = scene_by_name("lab", seed)?;
    let body = *lab.scan_poses(1, 0.6, seed).first().context("no pose in the lab")?;
    let alrf = Alrf::sick_s300();
    let cloud = alrf.scan(&lab, &alrf.mount(&body), seed).to_cloud()?;
    let strict = ReadOptions::STRICT;
    type Writer = Box<dyn Fn(&mut Vec<u8>) -> Result<()>>;
    type Reader = fn(&[u8], &ReadOptions) -> Result<usize>;
    let ply = |encoding| {
        let cloud = cloud.clone();
        let w: Writer = Box::new(move |buf: &mut Vec<u8>| {
            let o = PlyWriteOptions { encoding, precision: Precision::F32 };
            Ok(write_ply(buf, &cloud, &o)?)
        });
        w
    };
    let pcd = |encoding| {
        let cloud = cloud.clone();
        let w: Writer = Box::new(move |buf: &mut Vec<u8>| {
            let o = PcdWriteOptions { encoding, precision: Precision::F32 };
            Ok(write_pcd(buf, &cloud, &o)?)
        });
        w
    };
    let xyz_cloud = cloud.clone();
    let read_ply_len: Reader = |b, o| Ok(read_ply(b, o)?.len());
    let read_pcd_len: Reader = |b, o| Ok(read_pcd(b, o)?.len());
    let read_xyz_len: Reader = |b, o| Ok(xyz::read_xyz(b, o)?.len());
    let cases: Vec<(&str, Writer, Reader)> = vec![
        ("ply-binary-le", ply(PlyEncoding::BinaryLittleEndian), read_ply_len),
        ("ply-ascii", ply(PlyEncoding::Ascii), read_ply_len),
        ("pcd-binary", pcd(PcdEncoding::Binary), read_pcd_len),
        ("pcd-binary-compressed", pcd(PcdEncoding::BinaryCompressed), read_pcd_len),
        (
            "xyz",
            Box::new(move |buf: &mut Vec<u8>| Ok(xyz::write_xyz(buf, &xyz_cloud)?)),
            read_xyz_len,
        ),
    ];
    let mut rows = Vec::new();
    for (case, write, read) in &cases {
        let mut bytes = Vec::new();
        write(&mut bytes)?;
        let write_s = median_seconds(3, || {
            let mut buf = Vec::with_capacity(bytes.len());
            write(&mut buf)
        })?;
        let mut read_points = 0;
        let read_s = median_seconds(3, || {
            read_points = read(&bytes, &strict)?;
            Ok(())
        })?;
        if read_points != cloud.len() {
            bail!("{case}: read {read_points} points, wrote {}", cloud.len());
        }
        let mb = bytes.len() as f64 / 1e6;
        for (metric, secs) in [("write", write_s), ("read", read_s)] {
            rows.push(json!({
                "case": format!("alrf-scan/{case}"), "metric": metric, "value": secs * 1e3,
                "unit": "ms", "points": cloud.len(), "bytes": bytes.len(),
                "mb_per_s": mb / secs, "repeats": 3, "seed": seed,
            }));
        }
    }
    Ok(rows)
}

/// The shared data folder (`$PATCHNAV_REAL_DATA`, else `shared/data/real` next to the checkout).
pub(crate) fn real_data_dir() -> Option<std::path::PathBuf> {
    let dir = match std::env::var_os("PATCHNAV_REAL_DATA") {
        Some(d) => std::path::PathBuf::from(d),
        None => std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/real"),
    };
    dir.is_dir().then_some(dir)
}

fn tof(seed: u64) -> Result<Vec<Value>> {
    use sensor_tof::experiment::{
        Method, evaluate_folded, evaluate_scene, quality_table, table_2_4, tune_on_scenes,
        yield_table,
    };
    let mut rows = Vec::new();
    let mut results = Vec::new();
    // Region unwrapping is tuned on the next seed and scored on this one.
    let tuned = tune_on_scenes(seed + 1)?;
    let mut methods = Method::all();
    methods.push(Method::Regions(Box::new(tuned.config.clone())));
    for scene in sensor_tof::scenes::all_scenes()? {
        let mut r = evaluate_scene(&scene, &methods, seed)?;
        if let Some(m) = r.results.last_mut() {
            m.method = "regions (tuned)".into();
        }
        for m in &r.results {
            let q = &m.score;
            for (metric, value, unit) in [
                ("discarded", q.discarded_percent, "%"),
                ("wrong_kept", q.wrong_kept_percent, "%"),
                ("gross", q.gross_percent, "%"),
                ("wrapped_kept", q.wrapped_kept_percent, "%"),
                ("unwrapped_correct", q.unwrapped_correct_percent, "%"),
                ("correct", q.correct_percent, "%"),
                ("yield", q.yield_percent, "%"),
                ("rmse_correct", q.rmse_correct * 100.0, "cm"),
            ] {
                rows.push(json!({
                    "case": format!("{}/{}", r.scene, m.method), "metric": metric, "value": value,
                    "unit": unit, "seed": seed, "wrapped_percent": r.wrapped_percent,
                    "recoverable_percent": r.recoverable_percent,
                    "thesis_aat": r.thesis.aat, "thesis_at160": r.thesis.at160, "thesis_at240": r.thesis.at240,
                }));
            }
        }
        results.push(r);
    }
    eprintln!("{}", table_2_4(&results));
    eprintln!("{}", quality_table(&results));
    eprintln!(
        "region unwrapping tuned on seed {} (training: mean yield {:.1} %, worst wrong {:.2} %): {:?}",
        seed + 1,
        tuned.train_yield_percent,
        tuned.train_max_wrong_percent,
        tuned.config
    );
    eprintln!("{}", yield_table(&results));

    // The real ifm O3R frame (0.2–2 m, median 0.51 m): distances folded at 0.5 m and at 0.7 m
    // (second frequency 1.2 times further), tuned on the even rows, scored on the odd rows.
    match real_data_dir().map(|d| d.join("ifm_o3r_tof_frame")) {
        Some(dir) if dir.is_dir() => {
            let meta = sensor_tof::io::read_meta(&dir.join("frame_meta.json"))?;
            let frame = sensor_tof::io::read_png_pair(
                &dir.join("radial_distance_u16.png"),
                &dir.join("normalized_amplitude_u16.png"),
                &meta,
            )?;
            let noise = sensor_tof::io::read_png_pair(
                &dir.join("radial_distance_noise_u16.png"),
                &dir.join("normalized_amplitude_u16.png"),
                &meta,
            )?;
            for fold in [0.5, 0.7] {
                let f = evaluate_folded(&frame, Some(noise.range()), fold, 1.2 * fold, seed)?;
                eprintln!(
                    "ifm O3R frame folded at {} m (second frequency {} m): {} measured pixels, {:.1} % wrapped; \
                     thresholds tuned on the even rows: {:?}; regions tuned on the even rows: {:?}; scored on the odd rows:",
                    f.fold_m,
                    f.second_fold_m,
                    f.measured,
                    f.wrapped_percent,
                    f.thresholds,
                    f.regions.config
                );
                let as_scene = f.as_scene();
                eprintln!("{}", quality_table(std::slice::from_ref(&as_scene)));
                eprintln!("{}", yield_table(std::slice::from_ref(&as_scene)));
                for m in &f.results {
                    for (metric, value) in [
                        ("discarded", m.score.discarded_percent),
                        ("wrong_kept", m.score.wrong_kept_percent),
                        ("unwrapped_correct", m.score.unwrapped_correct_percent),
                        ("correct", m.score.correct_percent),
                        ("yield", m.score.yield_percent),
                    ] {
                        rows.push(json!({
                            "case": format!("ifm-folded-{fold}m/{}", m.method), "metric": metric, "value": value,
                            "unit": "%", "seed": seed, "recoverable_percent": f.recoverable_percent,
                        }));
                    }
                }
            }
        }
        _ => eprintln!(
            "SKIPPED: the real ifm frame (no shared/data/real/ifm_o3r_tof_frame next to the checkout)"
        ),
    }

    // Speed of AAT + unwrap + points against a plain copy of the frame, 176 × 144.
    let scene = sensor_tof::scenes::tof_scene("rack-and-door")?;
    let sim = sensor_tof::sim::TofSimulator::new(scene.sim.clone())?;
    let frame = sim.simulate(&scene.scene, &scene.pose, seed)?.frame;
    let aat = sensor_tof::experiment::aat_for(&sim);
    let filter = sensor_tof::TofFilter::new(
        frame.camera(),
        frame.kind(),
        &sensor_tof::FilterConfig::aat_unwrap(aat, None),
    )?;
    let n = frame.range().len();
    let mut out = sensor_tof::FilterOutput::default();
    let (mut points, mut pixels) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let reps = 2000;
    let work = median_seconds(5, || {
        for _ in 0..reps {
            filter.apply(&frame, &mut out)?;
            points.clear();
            pixels.clear();
            out.points_into(filter.tables(), &mut points, &mut pixels);
            std::hint::black_box(points.len());
        }
        Ok(())
    })? / reps as f64;
    let (mut r, mut a) = (vec![0f32; n], vec![0f32; n]);
    let copy = median_seconds(5, || {
        for _ in 0..reps {
            r.copy_from_slice(std::hint::black_box(frame.range()));
            a.copy_from_slice(std::hint::black_box(frame.amplitude()));
            std::hint::black_box(r[n - 1] + a[n - 1]);
        }
        Ok(())
    })? / reps as f64;
    eprintln!(
        "AAT + unwrap + points, 176 x 144 simulated frame: {:.1} µs ({:.0} frames/s), plain copy {:.2} µs: ratio {:.1}",
        work * 1e6,
        1.0 / work,
        copy * 1e6,
        work / copy
    );
    rows.push(json!({"case": "rack-and-door/aat-unwrap-points", "metric": "time_per_frame", "value": work * 1e6,
        "unit": "us", "frames_per_s": 1.0 / work, "copy_us": copy * 1e6, "ratio_to_copy": work / copy}));
    Ok(rows)
}
