//! PNG pairs, sidecars and clouds: round trips, corrupt and truncated files, absurd sidecars,
//! and the real ifm O3R frame.

use pointcloud::io::{ReadOptions, read_cloud, write_cloud};
use pointcloud::{PinholeIntrinsics, RangeKind, Real};
use proptest::prelude::*;
use sensor_tof::io::{
    AatMeta, CameraPreset, FrameMeta, frame_from_cloud, parse_meta, read_meta, read_png_pair,
    read_png_pair_with_confidence, write_confidence_png, write_json, write_meta, write_png_pair,
};
use sensor_tof::{Illumination, Parabola, TofCamera, TofError, TofFrame, WhiteWallTable};
use std::path::{Path, PathBuf};

/// A frame with a ramp of ranges, some pixels unmeasured, amplitudes falling with range.
fn frame(camera: TofCamera, kind: RangeKind) -> TofFrame {
    let n = camera.num_pixels();
    let range: Vec<f32> =
        (0..n).map(|i| if i % 7 == 3 { 0.0 } else { 0.5 + (i % 97) as f32 * 0.071 }).collect();
    let amplitude = range.iter().map(|&r| if r > 0.0 { 3000.0 / (r * r) } else { 12.5 }).collect();
    TofFrame::new(camera, kind, range, amplitude).unwrap()
}

fn paths(dir: &Path) -> (PathBuf, PathBuf, PathBuf) {
    (dir.join("range.png"), dir.join("amplitude.png"), dir.join("meta.json"))
}

#[test]
fn png_pair_round_trips_within_half_a_unit() {
    let dir = tempfile::tempdir().unwrap();
    let (r, a, m) = paths(dir.path());
    for kind in [RangeKind::Depth, RangeKind::Radial] {
        let f = frame(TofCamera::sr3000(), kind);
        let mut meta = FrameMeta::for_camera(f.camera(), kind, 0.0005);
        meta.amplitude_scale = 0.25;
        write_png_pair(&f, &r, &a, &meta).unwrap();
        write_meta(&m, &meta).unwrap();
        let meta2 = read_meta(&m).unwrap();
        assert_eq!(meta2, meta);
        let g = read_png_pair(&r, &a, &meta2).unwrap();
        assert_eq!(g.kind(), kind);
        assert_eq!(g.camera(), f.camera());
        for i in 0..f.range().len() {
            assert_eq!(f.range()[i] == 0.0, g.range()[i] == 0.0, "pixel {i}");
            assert!((f.range()[i] - g.range()[i]).abs() <= 0.00025 + 1e-6, "pixel {i}");
            assert!((f.amplitude()[i] - g.amplitude()[i]).abs() <= 0.125 + 1e-3, "pixel {i}");
        }
    }
}

#[test]
fn a_frame_of_the_other_kind_is_converted_on_writing() {
    let dir = tempfile::tempdir().unwrap();
    let (r, a, _) = paths(dir.path());
    let f = frame(TofCamera::sr3000(), RangeKind::Depth);
    let meta = FrameMeta::for_camera(f.camera(), RangeKind::Radial, 0.0002);
    write_png_pair(&f, &r, &a, &meta).unwrap();
    let g = read_png_pair(&r, &a, &meta).unwrap();
    assert_eq!(g.kind(), RangeKind::Radial);
    for i in 0..f.range().len() {
        assert!((g.depth(i) - f.depth(i)).abs() <= 0.0001 + 1e-6, "pixel {i}");
    }
}

#[test]
fn values_that_do_not_fit_are_refused_not_clamped() {
    let dir = tempfile::tempdir().unwrap();
    let (r, a, _) = paths(dir.path());
    let f = frame(TofCamera::sr3000(), RangeKind::Depth);
    // 7.3 m at 0.1 mm per unit is 73,000 units.
    let meta = FrameMeta::for_camera(f.camera(), RangeKind::Depth, 0.0001);
    let e = write_png_pair(&f, &r, &a, &meta).unwrap_err();
    assert!(matches!(e, TofError::BadImage { what: "range", .. }), "{e}");
    // A measured range that rounds to 0 would read back as "no measurement".
    let meta = FrameMeta::for_camera(f.camera(), RangeKind::Depth, 2.0);
    assert!(write_png_pair(&f, &r, &a, &meta).is_err());
    // Amplitudes beyond 65,535 units.
    let mut meta = FrameMeta::for_camera(f.camera(), RangeKind::Depth, 0.001);
    meta.amplitude_scale = 0.01;
    let e = write_png_pair(&f, &r, &a, &meta).unwrap_err();
    assert!(matches!(e, TofError::BadImage { what: "amplitude", .. }), "{e}");
    // A sidecar of another camera.
    let mut other = FrameMeta::for_camera(f.camera(), RangeKind::Depth, 0.001);
    other.fx = Some(100.0);
    assert!(matches!(write_png_pair(&f, &r, &a, &other), Err(TofError::Mismatch { .. })));
}

#[test]
fn confidence_round_trips_and_reads_8_bit() {
    let dir = tempfile::tempdir().unwrap();
    let (r, a, _) = paths(dir.path());
    let c = dir.path().join("confidence.png");
    let cam =
        TofCamera::pinhole(5, 4, PinholeIntrinsics { fx: 4.0, fy: 4.0, cx: 2.0, cy: 1.5 }, 20e6)
            .unwrap();
    let conf: Vec<u16> = (0..20).map(|i| i * 1000).collect();
    let f = frame(cam, RangeKind::Radial).with_confidence(conf.clone()).unwrap();
    let meta = FrameMeta::for_camera(&cam, RangeKind::Radial, 0.001);
    write_png_pair(&f, &r, &a, &meta).unwrap();
    write_confidence_png(&f, &c).unwrap();
    let g = read_png_pair_with_confidence(&r, &a, &c, &meta).unwrap();
    assert_eq!(g.confidence(), Some(conf.as_slice()));
    // An 8-bit confidence image.
    let bytes: Vec<u8> = (0..20).map(|i| (i * 13) as u8).collect();
    let mut enc = png::Encoder::new(std::fs::File::create(&c).unwrap(), 5, 4);
    enc.set_color(png::ColorType::Grayscale);
    enc.set_depth(png::BitDepth::Eight);
    enc.write_header().unwrap().write_image_data(&bytes).unwrap();
    let g = read_png_pair_with_confidence(&r, &a, &c, &meta).unwrap();
    let want: Vec<u16> = bytes.iter().map(|&b| b as u16).collect();
    assert_eq!(g.confidence(), Some(want.as_slice()));
}

#[test]
fn truncated_corrupt_and_missing_pngs_are_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let (r, a, _) = paths(dir.path());
    let f = frame(TofCamera::sr3000(), RangeKind::Depth);
    let meta = FrameMeta::for_camera(f.camera(), RangeKind::Depth, 0.001);
    write_png_pair(&f, &r, &a, &meta).unwrap();
    let good = std::fs::read(&r).unwrap();
    let bad = dir.path().join("bad.png");
    // Every truncation point over the header and a sample of the rest.
    let cuts: Vec<usize> = (0..80).chain((80..good.len()).step_by(97)).collect();
    for cut in cuts {
        std::fs::write(&bad, &good[..cut]).unwrap();
        let e = read_png_pair(&bad, &a, &meta).expect_err("truncated");
        assert!(matches!(e, TofError::Io(_)), "cut {cut}: {e}");
        assert!(e.to_string().contains("bad.png"), "{e}");
    }
    // Flipped bytes inside the data (the CRC or the deflate stream catches them).
    for at in (40..good.len() - 12).step_by(211) {
        let mut corrupt = good.clone();
        corrupt[at] ^= 0x5a;
        std::fs::write(&bad, &corrupt).unwrap();
        assert!(read_png_pair(&bad, &a, &meta).is_err(), "flip at {at}");
    }
    std::fs::write(&bad, b"not a png at all").unwrap();
    assert!(read_png_pair(&r, &bad, &meta).is_err());
    let missing = dir.path().join("missing.png");
    let e = read_png_pair(&missing, &a, &meta).unwrap_err();
    assert!(e.to_string().contains("missing.png"), "{e}");
    // An 8-bit range image is refused (ranges are 16-bit).
    let mut enc = png::Encoder::new(std::fs::File::create(&bad).unwrap(), 176, 144);
    enc.set_color(png::ColorType::Grayscale);
    enc.set_depth(png::BitDepth::Eight);
    enc.write_header().unwrap().write_image_data(&vec![1u8; 176 * 144]).unwrap();
    assert!(read_png_pair(&bad, &a, &meta).is_err());
}

#[test]
fn size_mismatch_between_pngs_and_sidecar_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let (r, a, _) = paths(dir.path());
    let f = frame(TofCamera::sr3000(), RangeKind::Depth);
    let meta = FrameMeta::for_camera(f.camera(), RangeKind::Depth, 0.001);
    write_png_pair(&f, &r, &a, &meta).unwrap();
    let mut wrong = meta.clone();
    wrong.width = 175;
    let e = read_png_pair(&r, &a, &wrong).unwrap_err();
    assert!(matches!(e, TofError::BadImage { what: "range", .. }), "{e}");
    assert!(e.to_string().contains("range.png is 176 × 144"), "{e}");
    // Amplitude of another size than the range.
    let small =
        TofCamera::pinhole(4, 4, PinholeIntrinsics { fx: 4.0, fy: 4.0, cx: 2.0, cy: 2.0 }, 20e6)
            .unwrap();
    let s = frame(small, RangeKind::Depth);
    let sa = dir.path().join("small_a.png");
    let sr = dir.path().join("small_r.png");
    write_png_pair(&s, &sr, &sa, &FrameMeta::for_camera(&small, RangeKind::Depth, 0.001)).unwrap();
    let e = read_png_pair(&r, &sa, &meta).unwrap_err();
    assert!(matches!(e, TofError::BadImage { what: "amplitude", .. }), "{e}");
}

#[test]
fn absurd_sidecars_are_refused() {
    let p = Path::new("meta.json");
    let ok = r#"{"width": 176, "height": 144, "metres_per_unit": 0.001, "range_kind": "z", "camera": "sr3000"}"#;
    let meta = parse_meta(ok, p).unwrap();
    assert_eq!(meta.camera().unwrap(), TofCamera::sr3000());
    assert_eq!(meta.aat().unwrap(), Some(sensor_tof::AatConfig::sr3000()));
    let bad = [
        r#"{"width": 0, "height": 144, "metres_per_unit": 0.001, "range_kind": "z", "fx": 1, "fy": 1, "cx": 0, "cy": 0}"#,
        r#"{"width": 176, "height": 144, "metres_per_unit": 0, "range_kind": "z", "camera": "sr3000"}"#,
        r#"{"width": 176, "height": 144, "metres_per_unit": 0.001, "range_kind": "x", "camera": "sr3000"}"#,
        r#"{"width": 176, "height": 144, "metres_per_unit": 0.001, "range_kind": "z"}"#,
        r#"{"width": 100, "height": 144, "metres_per_unit": 0.001, "range_kind": "z", "camera": "sr3000"}"#,
        r#"{"width": 176, "height": 144, "metres_per_unit": 0.001, "range_kind": "z", "camera": "sr3000", "fx": -3}"#,
        r#"{"width": 176, "height": 144, "metres_per_unit": 0.001, "range_kind": "z", "camera": "sr3000", "modulation_hz": 0}"#,
        r#"{"width": 176, "height": 144, "metres_per_unit": 0.001, "range_kind": "z", "camera": "sr3000", "typo": 1}"#,
        r#"{"width": 176, "height": 144, "metres_per_unit": 0.001, "range_kind": "z", "camera": "sr3000", "aat": {"a_hat": 1}}"#,
        r#"{"width": 176, "height": 144, "metres_per_unit": 0.001, "range_kind": "z", "camera": "sr3000", "aat": {"threshold": -1}}"#,
        r#"{"width": 176, "height": 144, "metres_per_unit": 0.001, "range_kind": "z", "fx": 1, "fy": 1, "cx": 0, "cy": 0, "aat": {}}"#,
        r#"{"width": 176, "height": 144, "metres_per_unit": 0.001, "range_kind": "z", "camera": "sr3000", "aat": {"a_hat": 1, "delta_x": 1, "delta_y": 1, "white_wall_table": "t.json"}}"#,
        r#"{"width": 176, "height": 144"#,
        r#"[]"#,
    ];
    for text in bad {
        let e = parse_meta(text, p).expect_err(text);
        assert!(e.to_string().starts_with("meta.json: "), "{e}");
    }
    // NaN cannot be written in JSON; a sidecar built in code is checked likewise.
    let mut m = meta.clone();
    m.fy = Some(Real::NAN);
    assert!(m.validate().is_err() && m.camera().is_err());
    let mut m = meta.clone();
    m.amplitude_scale = Real::INFINITY;
    assert!(m.validate().is_err());
}

#[test]
fn aat_blocks_give_parabola_table_or_calibration() {
    let dir = tempfile::tempdir().unwrap();
    let m = dir.path().join("meta.json");
    let mut meta = FrameMeta::for_camera(&TofCamera::sr3000(), RangeKind::Depth, 0.001);
    meta.aat = Some(AatMeta {
        threshold: 0.3,
        a_hat: Some(9000.0),
        delta_x: Some(80.0),
        delta_y: Some(70.0),
        curvature: None,
        white_wall_table: None,
        calibration: None,
    });
    write_meta(&m, &meta).unwrap();
    let aat = read_meta(&m).unwrap().aat().unwrap().unwrap();
    assert_eq!(aat.threshold, 0.3);
    let want = Parabola { a_hat: 9000.0, delta_x: 80.0, delta_y: 70.0, curvature: 1.0 };
    assert_eq!(aat.illumination, Illumination::Parabola(want));
    // A table file named relative to the sidecar.
    let table = WhiteWallTable { width: 176, height: 144, values: vec![5000.0; 176 * 144] };
    write_json(&dir.path().join("table.json"), &table).unwrap();
    meta.aat = Some(AatMeta {
        threshold: 0.2,
        a_hat: None,
        delta_x: None,
        delta_y: None,
        curvature: None,
        white_wall_table: Some("table.json".into()),
        calibration: None,
    });
    write_meta(&m, &meta).unwrap();
    let aat = read_meta(&m).unwrap().aat().unwrap().unwrap();
    assert_eq!(aat.illumination, Illumination::Table(table));
    // Without the `aat` block and without a preset there is none.
    let bare = FrameMeta::for_camera(&TofCamera::sr3000(), RangeKind::Depth, 0.001);
    assert_eq!(bare.aat().unwrap(), None);
    // A table of the wrong size is refused.
    let small = WhiteWallTable { width: 2, height: 2, values: vec![1.0; 4] };
    write_json(&dir.path().join("table.json"), &small).unwrap();
    assert!(read_meta(&m).unwrap().aat().is_err());
    let mut preset = bare.clone();
    preset.camera = Some(CameraPreset::Sr3100);
    assert_eq!(preset.aat().unwrap(), Some(sensor_tof::AatConfig::sr3100()));
}

#[test]
fn frames_come_back_from_their_clouds_through_files() {
    let dir = tempfile::tempdir().unwrap();
    for kind in [RangeKind::Depth, RangeKind::Radial] {
        let f = frame(TofCamera::sr3000(), kind).with_confidence(vec![7; 176 * 144]).unwrap();
        for ext in ["ply", "pcd"] {
            let path = dir.path().join(format!("frame.{ext}"));
            write_cloud(&path, &f.to_cloud()).unwrap();
            let cloud = read_cloud(&path, &ReadOptions::STRICT).unwrap();
            let g = frame_from_cloud(&cloud, f.camera(), kind).unwrap();
            for i in 0..f.range().len() {
                assert!((f.range()[i] - g.range()[i]).abs() < 1e-5, "{ext} pixel {i}");
                assert_eq!(f.amplitude()[i] == g.amplitude()[i], f.range()[i] > 0.0);
            }
            assert_eq!(g.confidence().map(|c| c[0]), Some(7));
        }
    }
    // The wrong camera, an unorganised cloud, a cloud without intensity.
    let f = frame(TofCamera::sr3000(), RangeKind::Depth);
    let cloud = f.to_cloud();
    let mut other = TofCamera::sr3000();
    other.intrinsics.fx *= 1.5;
    assert!(matches!(
        frame_from_cloud(&cloud, &other, RangeKind::Depth),
        Err(TofError::Mismatch { .. })
    ));
    let flat = pointcloud::PointCloud::from_positions(cloud.positions().to_vec()).unwrap();
    assert!(frame_from_cloud(&flat, f.camera(), RangeKind::Depth).is_err());
    let mut dark = cloud.clone();
    dark.set_intensity(None).unwrap();
    assert!(frame_from_cloud(&dark, f.camera(), RangeKind::Depth).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]
    /// Any small frame round-trips through the PNG pair within half a unit.
    #[test]
    fn any_frame_round_trips(
        w in 1u32..9, h in 1u32..9,
        values in proptest::collection::vec((0.0f32..6.0, 0.0f32..60_000.0), 64),
        radial in any::<bool>(),
    ) {
        let cam = TofCamera::pinhole(w, h, PinholeIntrinsics { fx: 5.0, fy: 6.0, cx: 1.5, cy: 2.5 }, 20e6)
            .unwrap();
        let n = cam.num_pixels();
        let kind = if radial { RangeKind::Radial } else { RangeKind::Depth };
        let range: Vec<f32> = values[..n].iter().map(|v| if v.0 < 0.5 { 0.0 } else { v.0 }).collect();
        let amplitude: Vec<f32> = values[..n].iter().map(|v| v.1).collect();
        let f = TofFrame::new(cam, kind, range, amplitude).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let (r, a, _) = paths(dir.path());
        let meta = FrameMeta::for_camera(&cam, kind, 0.0001);
        write_png_pair(&f, &r, &a, &meta).unwrap();
        let g = read_png_pair(&r, &a, &meta).unwrap();
        for i in 0..n {
            prop_assert!((f.range()[i] - g.range()[i]).abs() <= 0.00005 + 1e-6);
            prop_assert!((f.amplitude()[i] - g.amplitude()[i]).abs() <= 0.5);
        }
    }
}

fn real_frame_dir() -> Option<PathBuf> {
    shared_data::real_data("ifm_o3r_tof_frame")
}

/// The ifm O3R frame: its own sidecar is recognised, the pair and the 8-bit confidence read, and
/// the valid distance pixels are the 9,962 the foundation's reader counts.
#[test]
fn the_real_ifm_frame_reads() {
    let Some(dir) = real_frame_dir() else { return };
    let meta = read_meta(&dir.join("frame_meta.json")).unwrap();
    assert_eq!((meta.width, meta.height), (224, 172));
    assert_eq!(meta.range_kind, RangeKind::Radial);
    assert_eq!(meta.modulation_hz, 20e6);
    let camera = meta.camera().unwrap();
    assert!((camera.intrinsics.fx - 124.344).abs() < 1e-3 && camera.intrinsics.cx == 111.5);
    let f = read_png_pair_with_confidence(
        &dir.join("radial_distance_u16.png"),
        &dir.join("normalized_amplitude_u16.png"),
        &dir.join("confidence_u8.png"),
        &meta,
    )
    .unwrap();
    assert_eq!(f.num_measured(), 9962);
    let max = (0..f.range().len()).map(|i| f.radial(i)).fold(0.0, Real::max);
    assert!(max > 1.9 && max < 2.0, "SOURCE.md: valid distances in 0.20–1.97 m, got max {max}");
    // Confidence bit 0 marks invalid pixels: every pixel with a distance has it clear.
    let conf = f.confidence().unwrap();
    assert!((0..f.range().len()).all(|i| f.range()[i] == 0.0 || conf[i] & 1 == 0));
    // And the foundation reads the same range image.
    let cam = pointcloud::io::depth_png::DepthCamera {
        intrinsics: camera.intrinsics,
        depth_scale: meta.metres_per_unit,
    };
    let file = std::fs::File::open(dir.join("radial_distance_u16.png")).unwrap();
    let image = pointcloud::io::depth_png::read_range_png(file, &cam, RangeKind::Radial).unwrap();
    for (r, s) in f.range().iter().zip(image.ranges()) {
        assert_eq!(*r, s.unwrap_or(0.0));
    }
}
