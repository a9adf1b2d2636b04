//! 16-bit PNG depth images: round trips, wrong image types, truncation, lying headers, JSON
//! intrinsics.

use pointcloud::io::depth_png::{
    DepthCamera, read_depth_png, read_intrinsics_json, read_range_png, write_depth_png,
};
use pointcloud::io::{ErrorKind, Position};
use pointcloud::{BeamModel, PinholeIntrinsics, RangeImage, RangeKind};
use proptest::prelude::*;

fn camera(scale: f64) -> DepthCamera {
    DepthCamera {
        intrinsics: PinholeIntrinsics { fx: 10.0, fy: 12.0, cx: 1.5, cy: 0.5 },
        depth_scale: scale,
    }
}

fn image(w: u32, h: u32, values: &[u16], scale: f64) -> RangeImage {
    let ranges = values.iter().map(|&v| (v != 0).then_some((v as f64 * scale) as f32)).collect();
    RangeImage::new(w, h, BeamModel::Pinhole(camera(scale).intrinsics), RangeKind::Depth, ranges)
        .unwrap()
}

fn png_bytes(w: u32, h: u32, values: &[u16], scale: f64) -> Vec<u8> {
    let mut out = Vec::new();
    write_depth_png(&mut out, &image(w, h, values, scale), scale).unwrap();
    out
}

fn encode(w: u32, h: u32, color: png::ColorType, depth: png::BitDepth, data: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut e = png::Encoder::new(&mut out, w, h);
    e.set_color(color);
    e.set_depth(depth);
    let mut wr = e.write_header().unwrap();
    wr.write_image_data(data).unwrap();
    wr.finish().unwrap();
    out
}

fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xffff_ffffu32;
    for &b in bytes {
        crc ^= b as u32;
        for _ in 0..8 {
            crc = if crc & 1 != 0 { (crc >> 1) ^ 0xedb8_8320 } else { crc >> 1 };
        }
    }
    !crc
}

#[test]
fn reads_values_as_depth_with_zero_invalid() {
    let data = png_bytes(4, 2, &[0, 1000, 2000, 65535, 1, 0, 0, 5], 0.001);
    let img = read_depth_png(&data[..], &camera(0.001)).unwrap();
    assert_eq!((img.width(), img.height()), (4, 2));
    assert_eq!(img.kind(), RangeKind::Depth);
    assert_eq!(img.num_valid(), 5);
    assert_eq!(img.range(0, 0), None);
    assert_eq!(img.range(1, 0), Some(1.0));
    assert_eq!(img.range(3, 0), Some(65.535));
    assert_eq!(img.beams(), &BeamModel::Pinhole(camera(0.001).intrinsics));
    let cloud = img.to_cloud().unwrap();
    assert_eq!(cloud.len(), 5);
    let radial = read_range_png(&data[..], &camera(0.001), RangeKind::Radial).unwrap();
    assert_eq!(radial.kind(), RangeKind::Radial);
}

#[test]
fn camera_presets() {
    let t = DepthCamera::tum_kinect();
    assert_eq!((t.intrinsics.fx, t.intrinsics.cx, t.intrinsics.cy), (525.0, 319.5, 239.5));
    assert_eq!(t.depth_scale, 0.0002);
    let o = DepthCamera::openni_mm();
    assert_eq!((o.intrinsics.fy, o.intrinsics.cx, o.intrinsics.cy), (525.0, 320.0, 240.0));
    assert_eq!(o.depth_scale, 0.001);
}

#[test]
fn other_png_types_are_unsupported() {
    let cases = [
        encode(2, 2, png::ColorType::Grayscale, png::BitDepth::Eight, &[0; 4]),
        encode(2, 2, png::ColorType::Rgb, png::BitDepth::Sixteen, &[0; 24]),
        encode(2, 2, png::ColorType::Rgb, png::BitDepth::Eight, &[0; 12]),
        encode(2, 2, png::ColorType::GrayscaleAlpha, png::BitDepth::Sixteen, &[0; 16]),
    ];
    for data in cases {
        let e = read_depth_png(&data[..], &camera(0.001)).unwrap_err();
        assert!(matches!(e.kind, ErrorKind::Unsupported(_)), "{e}");
        assert!(e.to_string().contains("16-bit grayscale"), "{e}");
    }
    let e = read_depth_png(&b"not a png at all"[..], &camera(0.001)).unwrap_err();
    assert!(matches!(e.position, Some(Position::Byte(_))), "{e}");
}

#[test]
fn bad_scales_are_refused() {
    let data = png_bytes(1, 1, &[1], 0.001);
    for s in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(read_depth_png(&data[..], &camera(s)).is_err());
        assert!(write_depth_png(Vec::new(), &image(1, 1, &[1], 0.001), s).is_err());
    }
}

#[test]
fn out_of_range_depths_are_errors_not_clamped() {
    let k = BeamModel::Pinhole(camera(0.001).intrinsics);
    let too_far = RangeImage::new(2, 1, k, RangeKind::Depth, vec![None, Some(70.0)]).unwrap();
    let e = write_depth_png(Vec::new(), &too_far, 0.001).unwrap_err();
    assert!(e.to_string().contains("(1, 0)"), "{e}");
    let zero = RangeImage::new(1, 1, k, RangeKind::Depth, vec![Some(0.0001)]).unwrap();
    assert!(write_depth_png(Vec::new(), &zero, 0.001).is_err());
    let ok = RangeImage::new(1, 1, k, RangeKind::Depth, vec![Some(65.535)]).unwrap();
    assert!(write_depth_png(Vec::new(), &ok, 0.001).is_ok());
}

#[test]
fn every_prefix_of_a_png_is_an_error() {
    let values: Vec<u16> = (0..48).map(|i| i * 977).collect();
    let data = png_bytes(8, 6, &values, 0.001);
    for len in 0..data.len() {
        match read_depth_png(&data[..len], &camera(0.001)) {
            Ok(img) => panic!("prefix of {len} of {} bytes read as {img:?}", data.len()),
            Err(e) => {
                let Some(Position::Byte(b)) = e.position else { panic!("{e}: no byte position") };
                assert!(b <= len as u64, "{e}");
            }
        }
    }
    assert!(read_depth_png(&data[..], &camera(0.001)).is_ok());
}

#[test]
fn corrupt_bytes_never_panic() {
    let values: Vec<u16> = (0..48).map(|i| i * 977).collect();
    let data = png_bytes(8, 6, &values, 0.001);
    for i in 0..data.len() {
        for flip in [0x01u8, 0x80, 0xff] {
            let mut d = data.clone();
            d[i] ^= flip;
            let _ = read_depth_png(&d[..], &camera(0.001));
        }
    }
}

#[test]
fn lying_header_is_refused_before_allocating() {
    let mut data = png_bytes(2, 2, &[1, 2, 3, 4], 0.001);
    // IHDR data start at byte 16: width, height (big-endian), then its CRC at byte 29.
    data[16..20].copy_from_slice(&60_000u32.to_be_bytes());
    data[20..24].copy_from_slice(&60_000u32.to_be_bytes());
    let crc = crc32(&data[12..29]);
    data[29..33].copy_from_slice(&crc.to_be_bytes());
    let e = read_depth_png(&data[..], &camera(0.001)).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::BadHeader(_)), "{e}");
    assert_eq!(e.position, Some(Position::Byte(16)));
    // A lie that still fits the bound fails as truncated data.
    data[16..20].copy_from_slice(&20u32.to_be_bytes());
    data[20..24].copy_from_slice(&20u32.to_be_bytes());
    let crc = crc32(&data[12..29]);
    data[29..33].copy_from_slice(&crc.to_be_bytes());
    assert!(read_depth_png(&data[..], &camera(0.001)).is_err());
}

#[test]
fn intrinsics_json() {
    let text = r#"{"fx": 524.9, "fy": 525.1, "cx": 319.9, "cy": 239.9, "width": 640,
                  "height": 480, "note": "anything"}"#;
    let k = read_intrinsics_json(text.as_bytes()).unwrap();
    assert_eq!(k, PinholeIntrinsics { fx: 524.9, fy: 525.1, cx: 319.9, cy: 239.9 });
    let e = read_intrinsics_json("{\n\"fx\": 1, \"fy\": 1,\n \"cx\": 0}".as_bytes()).unwrap_err();
    assert_eq!(e.position, Some(Position::Line(3)), "{e}");
    assert!(read_intrinsics_json(r#"{"fx": "a", "fy": 1, "cx": 0, "cy": 0}"#.as_bytes()).is_err());
    assert!(read_intrinsics_json(r#"{"fx": -5, "fy": 1, "cx": 0, "cy": 0}"#.as_bytes()).is_err());
    assert!(read_intrinsics_json(r#"[1, 2, 3]"#.as_bytes()).is_err());
    assert!(
        read_intrinsics_json(r#"{"fx": 1e999, "fy": 1, "cx": 0, "cy": 0}"#.as_bytes()).is_err()
    );
    assert!(read_intrinsics_json("".as_bytes()).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn round_trip_keeps_every_value(
        (w, h, values) in (1u32..12, 1u32..12).prop_flat_map(|(w, h)| {
            (Just(w), Just(h), prop::collection::vec(any::<u16>(), (w * h) as usize))
        }),
        scale in prop_oneof![Just(0.001), Just(1.0 / 5000.0), Just(0.00015259021893143654)],
    ) {
        let data = png_bytes(w, h, &values, scale);
        let img = read_depth_png(&data[..], &camera(scale)).unwrap();
        let expected = image(w, h, &values, scale);
        prop_assert_eq!(img.ranges(), expected.ranges());
        let mut again = Vec::new();
        write_depth_png(&mut again, &img, scale).unwrap();
        prop_assert_eq!(again, data);
    }

    #[test]
    fn garbage_never_panics(bytes in prop::collection::vec(any::<u8>(), 0..200)) {
        let mut with_magic = b"\x89PNG\r\n\x1a\n".to_vec();
        with_magic.extend_from_slice(&bytes);
        for d in [&bytes[..], &with_magic[..]] {
            prop_assert!(read_depth_png(d, &camera(0.001)).is_err());
        }
    }
}
