//! `patchnav tof filter|calibrate` as a user meets them: real processes on PNG pairs written by
//! `sensor_tof::io`, checked against the library run in-process.

use pointcloud::io::{ReadOptions, read_cloud, write_cloud};
use pointcloud::{FieldData, RangeKind, Real};
use sensor_tof::calibrate::Calibration;
use sensor_tof::io::{CameraPreset, FrameMeta, read_png_pair, write_meta, write_png_pair};
use sensor_tof::{
    AatConfig, FilterConfig, OutcomeCounts, Parabola, TofCamera, TofFilter, TofFrame,
    WhiteWallTable,
};
use std::path::{Path, PathBuf};
use std::process::Output;

use crate::common;
use common::*;

/// `patchnav tof filter --range R --amplitude A --meta M EXTRA...`.
fn filter_cmd(range: &str, amplitude: &str, meta: &str, extra: &[&str]) -> Output {
    let mut args =
        vec!["tof", "filter", "--range", range, "--amplitude", amplitude, "--meta", meta];
    args.extend_from_slice(extra);
    patchnav(&args)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The SR-3000 seeing, left of column 88, a wall of reflectivity 0.5 at 3 m and, right of it, a
/// wall of reflectivity 0.6 at 9 m (which wraps around to 1.5 m), lit by Eq 2.5; the top row
/// unmeasured. Depth ranges.
fn scene(frequency_hz: Real, kind: RangeKind) -> TofFrame {
    let mut c = TofCamera::sr3000();
    c.modulation_hz = frequency_hz;
    let amb = c.non_ambiguity_range();
    let p = Parabola::sr3000();
    let (mut range, mut amp) = (Vec::new(), Vec::new());
    for row in 0..c.height {
        for col in 0..c.width {
            let k = c.ray(col, row).norm();
            let (true_radial, rho): (Real, Real) = if col < 88 { (3.0, 0.5) } else { (9.0, 0.6) };
            let reported = true_radial.rem_euclid(amb);
            let r = match kind {
                RangeKind::Radial => reported,
                RangeKind::Depth => reported / k,
            };
            range.push(if row == 0 { 0.0 } else { r as f32 });
            let z = true_radial / k;
            amp.push((rho * p.eval(col as Real, row as Real).max(0.0) / (z * z)) as f32);
        }
    }
    TofFrame::new(c, kind, range, amp).unwrap()
}

/// Writes `frame` as a PNG pair with an SR-3000 sidecar into `dir` under `name`; returns the
/// range, amplitude and sidecar paths.
fn write_pair(dir: &Path, name: &str, frame: &TofFrame) -> (PathBuf, PathBuf, PathBuf) {
    let mut meta = FrameMeta::for_camera(frame.camera(), frame.kind(), 0.0005);
    meta.camera = Some(CameraPreset::Sr3000);
    let paths = (
        dir.join(format!("{name}_range.png")),
        dir.join(format!("{name}_amplitude.png")),
        dir.join(format!("{name}_meta.json")),
    );
    write_png_pair(frame, &paths.0, &paths.1, &meta).unwrap();
    write_meta(&paths.2, &meta).unwrap();
    paths
}

/// The numbers of the summary line: (total, measured, kept, unwrapped, dropped, written).
fn summary(text: &str) -> [usize; 6] {
    assert_eq!(text.lines().count(), 1, "one summary line: {text}");
    // "<name>: N pixels, M measured: K kept, U unwrapped, D dropped (P % discarded); W points
    // written to <path>"
    let number = |marker: &str| -> usize {
        let at = text.find(marker).unwrap_or_else(|| panic!("`{marker}` not in {text}"));
        let word = text[..at].split_whitespace().last().unwrap();
        word.parse().unwrap_or_else(|_| panic!("`{word}` before `{marker}` in {text}"))
    };
    [" pixels,", " measured:", " kept,", " unwrapped,", " dropped (", " points written"].map(number)
}

fn outcome_counts(ply: &Path) -> (usize, usize, usize) {
    let cloud = read_cloud(ply, &ReadOptions::STRICT).unwrap();
    let Some(FieldData::U8(o)) = cloud.extra_field("outcome").map(|f| &f.data) else {
        panic!("no u8 outcome field");
    };
    assert!(matches!(cloud.extra_field("pixel").map(|f| &f.data), Some(FieldData::U32(_))));
    let count = |v: u8| o.iter().filter(|&&x| x == v).count();
    (count(0), count(1), count(2))
}

#[test]
fn filter_writes_a_cloud_whose_outcomes_match_the_summary() {
    let dir = tempfile::tempdir().unwrap();
    let frame = scene(20e6, RangeKind::Depth);
    let (r, a, m) = write_pair(dir.path(), "scene", &frame);
    let out = dir.path().join("out.ply");
    let png = dir.path().join("outcomes.png");
    let o = filter_cmd(
        s(&r),
        s(&a),
        s(&m),
        &["--method", "aat", "--unwrap", "--clamp-corners", "--out", s(&out), "--png", s(&png)],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let [total, measured, kept, unwrapped, dropped, written] = summary(&stdout(&o));
    assert_eq!(total, 176 * 144);
    assert_eq!(measured, 176 * 143);
    assert_eq!(kept + unwrapped + dropped, total);
    assert!(unwrapped > 5000, "the far wall is unwrapped: {}", stdout(&o));
    assert_eq!(outcome_counts(&out), (kept, unwrapped, 0));
    assert_eq!(written, kept + unwrapped);
    // The library on the same (quantised) frame gives the same counts.
    let mut meta = FrameMeta::for_camera(frame.camera(), RangeKind::Depth, 0.0005);
    meta.camera = Some(CameraPreset::Sr3000);
    let read = read_png_pair(&r, &a, &meta).unwrap();
    let mut aat = AatConfig::sr3000();
    aat.negative = sensor_tof::NegativeIllumination::Clamp(0.04 * 12_000.0);
    let lib = TofFilter::new(read.camera(), RangeKind::Depth, &FilterConfig::aat_unwrap(aat, None))
        .unwrap()
        .run(&read)
        .unwrap();
    assert_eq!(lib.counts, OutcomeCounts { kept, unwrapped, dropped });
    // The far wall is unwrapped back to 9 m, the near wall kept at 3 m; elsewhere only the dark
    // corners where Eq 2.5 gives (almost) no light are flagged once clamped.
    let cloud = read_cloud(&out, &ReadOptions::STRICT).unwrap();
    let field = |name: &str| cloud.extra_field(name).map(|f| f.data.clone());
    let (Some(FieldData::U8(outcome)), Some(FieldData::U32(pixel))) =
        (field("outcome"), field("pixel"))
    else {
        panic!("outcome and pixel fields")
    };
    let mut corners = 0;
    for ((p, &o), &i) in cloud.positions().iter().zip(&outcome).zip(&pixel) {
        let (col, row) = ((i % 176) as Real, (i / 176) as Real);
        let (near, norm) = (col < 88.0, p.coords.norm());
        match (near, o) {
            (true, 0) => assert!((norm - 3.0).abs() < 0.01, "{i}: {norm}"),
            (false, 1) => assert!((norm - 9.0).abs() < 0.01, "{i}: {norm}"),
            _ => {
                // Only where the light is below the clamp (4 % of Â) may the AAT err.
                assert!(Parabola::sr3000().eval(col, row) <= 480.0, "pixel {i}: outcome {o}");
                corners += 1;
            }
        }
    }
    assert!(corners < 1000, "{corners}");
    // The outcome image: black where unmeasured, blue-ish where unwrapped, grey where kept.
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&png).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height, info.color_type), (176, 144, png::ColorType::Rgb));
    let px: Vec<[u8; 3]> = buf.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    assert_eq!(px.iter().filter(|p| **p == [0, 0, 0]).count(), 176);
    let blue = px.iter().filter(|p| p[2] > p[0] && p[0] != 220).count();
    let grey = px.iter().filter(|p| p[0] == p[1] && p[1] == p[2] && p[0] > 0).count();
    assert_eq!((grey, blue), (kept, unwrapped));

    // --safe writes the kept pixels only; the summary still counts every outcome.
    let o = filter_cmd(
        s(&r),
        s(&a),
        s(&m),
        &["--method", "aat", "--unwrap", "--clamp-corners", "--safe", "--out", s(&out)],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let [_, _, k2, u2, _, w2] = summary(&stdout(&o));
    assert_eq!((k2, u2, w2), (kept, unwrapped, kept));
    assert_eq!(outcome_counts(&out), (kept, 0, 0));
}

#[test]
fn plain_at_and_cloud_input_agree_with_the_library() {
    let dir = tempfile::tempdir().unwrap();
    let frame = scene(20e6, RangeKind::Radial);
    let (r, a, m) = write_pair(dir.path(), "scene", &frame);
    let out = dir.path().join("at.ply");
    let o = filter_cmd(s(&r), s(&a), s(&m), &["--method", "at", "--at", "240", "--out", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let [_, _, kept, unwrapped, dropped, _] = summary(&stdout(&o));
    let meta = sensor_tof::io::read_meta(&m).unwrap();
    let read = read_png_pair(&r, &a, &meta).unwrap();
    let expect = (0..read.range().len())
        .filter(|&i| read.range()[i] > 0.0 && read.amplitude()[i] > 240.0)
        .count();
    assert_eq!((kept, unwrapped, dropped), (expect, 0, 176 * 144 - expect));
    assert_eq!(outcome_counts(&out), (kept, 0, 0));
    // The same frame as a cloud (PCD) gives the same AAT result as the PNG pair.
    let cloud = dir.path().join("frame.pcd");
    write_cloud(&cloud, &read.to_cloud()).unwrap();
    let run = |input: &[&str]| {
        let mut args = vec!["tof", "filter", "--meta", s(&m), "--method", "aat", "--unwrap"];
        args.extend_from_slice(input);
        args.extend_from_slice(&["--out", s(&out)]);
        let o = patchnav(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        summary(&stdout(&o))
    };
    let from_pair = run(&["--range", s(&r), "--amplitude", s(&a)]);
    let from_cloud = run(&["--cloud", s(&cloud)]);
    assert_eq!(from_pair[..5], from_cloud[..5]);
}

#[test]
fn two_frequencies_unwrap_the_far_wall() {
    let dir = tempfile::tempdir().unwrap();
    let (r, a, m) = write_pair(dir.path(), "f20", &scene(20e6, RangeKind::Depth));
    let (r2, a2, m2) = write_pair(dir.path(), "f5", &scene(5e6, RangeKind::Depth));
    let out = dir.path().join("two.ply");
    let o = filter_cmd(
        s(&r),
        s(&a),
        s(&m),
        &[
            "--method",
            "two-freq",
            "--range2",
            s(&r2),
            "--amplitude2",
            s(&a2),
            "--meta2",
            s(&m2),
            "--out",
            s(&out),
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let [total, _, kept, unwrapped, dropped, written] = summary(&stdout(&o));
    assert_eq!((total, dropped, written), (176 * 144, 176, kept + unwrapped));
    assert_eq!(unwrapped, 88 * 143);
    let cloud = read_cloud(&out, &ReadOptions::STRICT).unwrap();
    let Some(FieldData::U32(pixel)) = cloud.extra_field("pixel").map(|f| &f.data) else { panic!() };
    for (p, &i) in cloud.positions().iter().zip(pixel) {
        let want = if i % 176 < 88 { 3.0 } else { 9.0 };
        assert!((p.coords.norm() - want).abs() < 0.01, "pixel {i}: {}", p.coords.norm());
    }
    // Both frames at one frequency is refused, as is a missing second frame.
    let o = filter_cmd(
        s(&r),
        s(&a),
        s(&m),
        &[
            "--method",
            "two-freq",
            "--range2",
            s(&r),
            "--amplitude2",
            s(&a),
            "--meta2",
            s(&m),
            "--out",
            s(&out),
        ],
    );
    assert_one_line_error(&o, "frequencies");
    let o = filter_cmd(s(&r), s(&a), s(&m), &["--method", "two-freq", "--out", s(&out)]);
    assert_one_line_error(&o, "--range2");
}

#[test]
fn bad_inputs_exit_1_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let frame = scene(20e6, RangeKind::Depth);
    let (r, a, m) = write_pair(dir.path(), "scene", &frame);
    let out = dir.path().join("out.ply");
    let missing = dir.path().join("missing.png");
    let o = filter_cmd(s(&missing), s(&a), s(&m), &["--out", s(&out)]);
    assert_one_line_error(&o, "missing.png");
    // A sidecar of another size than the PNGs.
    let mut meta = FrameMeta::for_camera(frame.camera(), RangeKind::Depth, 0.0005);
    meta.width = 170;
    let wrong = dir.path().join("wrong.json");
    write_meta(&wrong, &meta).unwrap();
    let o = filter_cmd(s(&r), s(&a), s(&wrong), &["--method", "at", "--out", s(&out)]);
    assert_one_line_error(&o, "176 × 144, the sidecar says 170 × 144");
    // A truncated PNG, a broken sidecar, an AAT without parameters.
    let cut = dir.path().join("cut.png");
    std::fs::write(&cut, &std::fs::read(&r).unwrap()[..300]).unwrap();
    let o = filter_cmd(s(&cut), s(&a), s(&m), &["--out", s(&out)]);
    assert_one_line_error(&o, "cut.png");
    std::fs::write(&wrong, "{\"width\": 176,").unwrap();
    let o = filter_cmd(s(&r), s(&a), s(&wrong), &["--out", s(&out)]);
    assert_one_line_error(&o, "wrong.json");
    let bare = dir.path().join("bare.json");
    write_meta(&bare, &FrameMeta::for_camera(frame.camera(), RangeKind::Depth, 0.0005)).unwrap();
    let o = filter_cmd(s(&r), s(&a), s(&bare), &["--out", s(&out)]);
    assert_one_line_error(&o, "no AAT parameters");
    let o = patchnav(&["tof", "calibrate", "--meta", s(&m), "--out", s(&out)]);
    assert_one_line_error(&o, "no frame");
}

#[test]
fn calibrate_recovers_a_known_parabola() {
    let dir = tempfile::tempdir().unwrap();
    let t = Parabola { a_hat: 15_000.0, delta_x: 90.5, delta_y: 66.0, curvature: 0.5 };
    let c = TofCamera::sr3000();
    let n = c.num_pixels();
    let z = 1.7;
    let mut range = vec![z as f32; n];
    for v in range.iter_mut().step_by(13) {
        *v = 0.0;
    }
    let amp = (0..n)
        .map(|i| {
            let (col, row) = ((i % 176) as Real, (i / 176) as Real);
            // ±0.5 % deterministic ripple as noise.
            let ripple = 1.0 + 0.005 * ((i * 7919 % 1000) as Real / 500.0 - 1.0);
            (t.eval(col, row) / (z * z) * ripple) as f32
        })
        .collect();
    let wall = TofFrame::new(c, RangeKind::Depth, range, amp).unwrap();
    let (r, a, m) = write_pair(dir.path(), "wall", &wall);
    let calib = dir.path().join("calib.json");
    let table = dir.path().join("table.json");
    let o = patchnav(&[
        "tof",
        "calibrate",
        "--range",
        s(&r),
        "--amplitude",
        s(&a),
        "--meta",
        s(&m),
        "--table",
        s(&table),
        "--out",
        s(&calib),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.starts_with("Â = ") && text.contains("residual RMS"), "{text}");
    let cal: Calibration = serde_json::from_str(&std::fs::read_to_string(&calib).unwrap()).unwrap();
    let p = cal.parabola;
    assert!((p.a_hat / t.a_hat - 1.0).abs() < 0.003, "{p:?}");
    assert!((p.delta_x - t.delta_x).abs() < 0.2 && (p.delta_y - t.delta_y).abs() < 0.2, "{p:?}");
    assert!((p.curvature / t.curvature - 1.0).abs() < 0.01, "{p:?}");
    assert!(text.contains(&format!("Â = {:.1}", p.a_hat)), "{text}");
    let tab: WhiteWallTable =
        serde_json::from_str(&std::fs::read_to_string(&table).unwrap()).unwrap();
    assert_eq!((tab.width, tab.height, tab.values.len()), (176, 144, n));
    // The same wall as a cloud (positional argument) gives the same fit.
    let cloud = dir.path().join("wall.ply");
    let meta = sensor_tof::io::read_meta(&m).unwrap();
    write_cloud(&cloud, &read_png_pair(&r, &a, &meta).unwrap().to_cloud()).unwrap();
    let calib2 = dir.path().join("calib2.json");
    let o = patchnav(&["tof", "calibrate", s(&cloud), "--meta", s(&m), "--out", s(&calib2)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let cal2: Calibration =
        serde_json::from_str(&std::fs::read_to_string(&calib2).unwrap()).unwrap();
    assert!((cal2.parabola.a_hat - p.a_hat).abs() < 1e-3 * p.a_hat);
    // The calibration drives the filter.
    let (sr, sa, _) = write_pair(dir.path(), "scene", &scene(20e6, RangeKind::Depth));
    let out = dir.path().join("out.ply");
    let o = filter_cmd(
        s(&sr),
        s(&sa),
        s(&m),
        &["--method", "aat", "--calibration", s(&calib), "--out", s(&out)],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).starts_with("AAT 0.2:"), "{}", stdout(&o));
}

/// The real ifm O3R frame through the filter: its own sidecar, 9,962 measured pixels.
#[test]
fn the_real_ifm_frame_filters() {
    let Some(dir) = shared_data::real_data("ifm_o3r_tof_frame") else { return };
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("ifm.ply");
    let o = patchnav(&[
        "tof",
        "filter",
        "--range",
        s(&dir.join("radial_distance_u16.png")),
        "--amplitude",
        s(&dir.join("normalized_amplitude_u16.png")),
        "--confidence",
        s(&dir.join("confidence_u8.png")),
        "--meta",
        s(&dir.join("frame_meta.json")),
        "--method",
        "at",
        "--at",
        "3000",
        "--out",
        s(&out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let [total, measured, kept, unwrapped, dropped, written] = summary(&stdout(&o));
    assert_eq!((total, measured, unwrapped), (224 * 172, 9962, 0));
    assert!(kept < measured && kept > measured / 2, "{}", stdout(&o));
    assert_eq!((kept + dropped, written), (total, kept));
    assert_eq!(outcome_counts(&out), (kept, 0, 0));
}

/// `tof simulate` writes a pair the filter reads, with the truth; the AAT with unwrapping puts
/// most wrapped pixels of the rack-and-door scene back at their true range.
#[test]
fn simulate_then_filter() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let o =
        patchnav(&["tof", "simulate", "rack-and-door", "--out", s(d), "--second-frequency", "5e6"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("% wrapped"), "{}", stdout(&o));
    for f in
        ["range.png", "amplitude.png", "meta.json", "range2.png", "meta2.json", "truth_radial.png"]
    {
        assert!(d.join(f).is_file(), "{f} missing");
    }
    let meta = sensor_tof::io::read_meta(&d.join("meta.json")).unwrap();
    let frame = read_png_pair(&d.join("range.png"), &d.join("amplitude.png"), &meta).unwrap();
    let ply = d.join("out.ply");
    let o = filter_cmd(
        s(&d.join("range.png")),
        s(&d.join("amplitude.png")),
        s(&d.join("meta.json")),
        &["--method", "aat", "--unwrap", "--out", s(&ply)],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let cloud = read_cloud(&ply, &ReadOptions::STRICT).unwrap();
    let Some(FieldData::U8(outcomes)) = cloud.extra_field("outcome").map(|f| &f.data) else {
        panic!("no outcome")
    };
    let Some(FieldData::U32(pixels)) = cloud.extra_field("pixel").map(|f| &f.data) else {
        panic!("no pixel")
    };
    // The truth PNG holds the true radial distance at the sidecar's scale.
    let truth = pointcloud::io::depth_png::decode_u16_gray(
        &std::fs::read(d.join("truth_radial.png")).unwrap(),
    )
    .unwrap()
    .2;
    let (mut unwrapped, mut right) = (0, 0);
    for ((o, &px), p) in outcomes.iter().zip(pixels).zip(cloud.positions()) {
        if *o == 1 {
            unwrapped += 1;
            let t = truth[px as usize] as Real * meta.metres_per_unit;
            right += ((p.coords.norm() - t).abs() < 0.1) as usize;
        }
    }
    assert!(unwrapped > 1000, "{unwrapped}");
    assert!(right * 10 > unwrapped * 6, "{right} of {unwrapped} unwrapped pixels within 10 cm");
    assert_eq!(frame.range().len(), 176 * 144);
    let o = patchnav(&["tof", "simulate", "nowhere", "--out", s(d)]);
    assert_one_line_error(&o, "unknown scene");
}

/// The default `--method regions` unwraps the far wall of the two-wall scene (a whole region
/// too dark for its measured range) and keeps the near one, as the library does.
#[test]
fn regions_unwrap_the_far_wall_and_keep_the_near_one() {
    let dir = tempfile::tempdir().unwrap();
    let frame = scene(20e6, RangeKind::Depth);
    let (r, a, m) = write_pair(dir.path(), "two", &frame);
    let out = dir.path().join("regions.ply");
    let o = filter_cmd(s(&r), s(&a), s(&m), &["--out", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let [total, measured, kept, unwrapped, dropped, written] = summary(&stdout(&o));
    assert_eq!((total, kept + unwrapped + dropped), (176 * 144, total));
    assert_eq!(written, kept + unwrapped);
    // Left of column 88 the near wall (3 m), right of it the far one (9 m, read as 1.5 m).
    assert!(kept > measured / 3 && unwrapped > measured / 3, "{kept} kept, {unwrapped} unwrapped");
    let read = read_pair_of(&r, &a, &m);
    let lib = sensor_tof::RegionUnwrapper::new(
        read.camera(),
        read.kind(),
        &sensor_tof::RegionConfig::new(AatConfig::sr3000()),
    )
    .unwrap()
    .run(&read)
    .unwrap();
    assert_eq!((lib.counts.kept, lib.counts.unwrapped), (kept, unwrapped));
    let o = filter_cmd(s(&r), s(&a), s(&m), &["--unwrap", "--out", s(&out)]);
    assert_one_line_error(&o, "--unwrap is for --method aat");
}

fn read_pair_of(r: &Path, a: &Path, m: &Path) -> TofFrame {
    let meta = sensor_tof::io::read_meta(m).unwrap();
    read_png_pair(r, a, &meta).unwrap()
}

/// `experiment tof` prints Table 2.4 beside the thesis's.
#[test]
fn experiment_tof_prints_table_2_4() {
    let o = patchnav(&["experiment", "tof", "--seed", "3"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(out.contains("Table 2.4"), "{out}");
    for scene in sensor_tof::scenes::SCENE_NAMES {
        assert!(out.contains(scene), "{scene} missing: {out}");
    }
    assert!(out.contains("median"));
    // The yield table with the new mode, tuned on another seed.
    assert!(out.contains("regions (tuned)") && out.contains("yield%"), "{out}");
}

/// `tof filter --cloud BAG --topic T`: each frame of the bag filtered, one line each, with the
/// same counts as the frame's PNG pair.
#[test]
fn a_bag_of_frames_filters_one_line_per_message() {
    use ros_bag::msgs::POINT_CLOUD2;
    use ros_bag::{BagFormat, BagWriter, Header};
    let dir = tempfile::tempdir().unwrap();
    let frame = scene(20e6, RangeKind::Depth);
    let (r, a, m) = write_pair(dir.path(), "scene", &frame);
    let meta = sensor_tof::io::read_meta(&m).unwrap();
    let read = read_png_pair(&r, &a, &meta).unwrap();
    let layout = pointcloud::io::pointcloud2::Pc2Layout::default();
    let data = pointcloud::io::pointcloud2::encode(&read.to_cloud(), &layout).unwrap();
    let mut w = BagWriter::new(BagFormat::Mcap).unwrap();
    let topic = w.add_topic("/tof/points", POINT_CLOUD2).unwrap();
    for k in 0..3i64 {
        let header = Header { stamp_ns: 1_000_000_000 + k * 100_000_000, frame_id: "tof".into() };
        w.write_cloud(topic, &header, &data).unwrap();
    }
    let bag = dir.path().join("tof.mcap");
    std::fs::write(&bag, w.finish().unwrap()).unwrap();
    let pair = filter_cmd(s(&r), s(&a), s(&m), &["--out", s(&dir.path().join("o.ply"))]);
    assert!(pair.status.success(), "{}", stderr(&pair));
    let [_, measured, kept, unwrapped, dropped, _] = summary(&stdout(&pair));
    let o =
        patchnav(&["tof", "filter", "--cloud", s(&bag), "--topic", "/tof/points", "--meta", s(&m)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    let expected =
        format!("{measured} measured: {kept} kept, {unwrapped} unwrapped, {dropped} dropped");
    let lines: Vec<&str> = text.lines().filter(|l| l.contains(" s  regions")).collect();
    assert_eq!(lines.len(), 3, "{text}");
    assert!(lines.iter().all(|l| l.contains(&expected)), "{text}\nwant {expected}");
    assert!(text.contains("3 of 3 messages on /tof/points filtered"), "{text}");
    // A bag without --topic, or --topic with a file, is a one-line error.
    let o = patchnav(&["tof", "filter", "--cloud", s(&bag), "--meta", s(&m), "--out", "x.ply"]);
    assert_one_line_error(&o, "needs --topic");
}
