//! PCD v0.7 reading and writing: hand-written files in every encoding (compressed data built by
//! hand), malformed input, and round trips of random clouds.

use pointcloud::io::pcd::{PcdEncoding, PcdWriteOptions, read_pcd, write_pcd};
use pointcloud::io::{Error, ErrorKind, Position, Precision, ReadOptions};
use pointcloud::{FieldData, Point3, PointCloud, ScalarField, Vector3};
use proptest::collection::vec;
use proptest::prelude::*;

use crate::common;
use common::*;

fn read(bytes: &[u8]) -> Result<PointCloud, Error> {
    read_pcd(bytes, &ReadOptions::STRICT)
}

fn read_err(bytes: &[u8]) -> Error {
    read(bytes).expect_err("the file is malformed")
}

fn write(cloud: &PointCloud, encoding: PcdEncoding, precision: Precision) -> Vec<u8> {
    let mut out = Vec::new();
    write_pcd(&mut out, cloud, &PcdWriteOptions { encoding, precision }).unwrap();
    out
}

const ENCODINGS: [PcdEncoding; 3] =
    [PcdEncoding::Ascii, PcdEncoding::Binary, PcdEncoding::BinaryCompressed];

/// A valid LZF stream of literal runs only.
fn lzf_literals(data: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    for chunk in data.chunks(32) {
        out.push(chunk.len() as u8 - 1);
        out.extend_from_slice(chunk);
    }
    out
}

fn header(
    fields: &str,
    sizes: &str,
    types: &str,
    counts: &str,
    w: u64,
    h: u64,
    data: &str,
) -> String {
    format!(
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS {fields}\nSIZE {sizes}\n\
         TYPE {types}\nCOUNT {counts}\nWIDTH {w}\nHEIGHT {h}\nVIEWPOINT 0 0 0 1 0 0 0\n\
         POINTS {}\nDATA {data}\n",
        w * h
    )
}

fn xyz_header(points: u64, data: &str) -> String {
    header("x y z", "4 4 4", "F F F", "1 1 1", points, 1, data)
}

// ---------------------------------------------------------------------------------------------
// Hand-written files

#[test]
fn ascii_with_normals_like_the_stanford_bunny() {
    let text = "# .PCD v0.7 - Point Cloud Data file format
VERSION 0.7
FIELDS x y z normal_x normal_y normal_z curvature
SIZE 4 4 4 4 4 4 4
TYPE F F F F F F F
COUNT 1 1 1 1 1 1 1
WIDTH 2
HEIGHT 1
VIEWPOINT 0 0 0 1 0 0 0
POINTS 2
DATA ascii
0.0054215998 0.11349 0.040748999 -0.16884723 -0.45159745 -0.87609947 0.0030943851
-0.0017447 0.11425 0.041273002 -0.011541721 -0.46529692 -0.88507944 0.0056861709
";
    let cloud = read(text.as_bytes()).unwrap();
    assert_eq!(cloud.len(), 2);
    assert_eq!(cloud.positions()[1].x, f64::from(-0.0017447f32));
    assert_eq!(cloud.normals().unwrap()[0].z, f64::from(-0.87609947f32));
    assert_eq!(
        cloud.extra_field("curvature").unwrap().data,
        FieldData::F32(vec!["0.0030943851".parse().unwrap(), "0.0056861709".parse().unwrap()])
    );
    assert!(cloud.grid().is_none() && cloud.sensor_pose().is_none());
}

#[test]
fn ascii_with_padding_counts_and_packed_colour() {
    let text = header(
        "x y z rgb _ h intensity label ring rgba",
        "4 4 4 4 1 2 4 4 2 4",
        "F F F U U U F U U U",
        "1 1 1 1 2 3 1 1 1 1",
        2,
        1,
        "ascii",
    ) + "1 2 3 4286611584 0 0 10 11 12 0.5 7 3 4294967295\n\
         4 5 6 255 9 9 20 21 22 1.5 8 4 0\n";
    let cloud = read(text.as_bytes()).unwrap();
    assert_eq!(cloud.positions()[1], Point3::new(4.0, 5.0, 6.0));
    let FieldData::F32(rgb) = &cloud.extra_field("rgb").unwrap().data else { panic!() };
    assert_eq!(rgb[0].to_bits(), 0xFF80_8080);
    assert_eq!(rgb[1].to_bits(), 255);
    assert_eq!(cloud.extra_field("h_0").unwrap().data, FieldData::U16(vec![10, 20]));
    assert_eq!(cloud.extra_field("h_2").unwrap().data, FieldData::U16(vec![12, 22]));
    assert_eq!(cloud.extra_field("rgba").unwrap().data, FieldData::U32(vec![u32::MAX, 0]));
    assert!(cloud.extra_field("_").is_none());
    assert_eq!(cloud.intensity().unwrap(), [0.5, 1.5]);
    assert_eq!(cloud.labels().unwrap(), [7, 8]);
    assert_eq!(cloud.rings().unwrap(), [3, 4]);
    let names: Vec<_> = cloud.extra_fields().iter().map(|f| f.name.as_str()).collect();
    assert_eq!(names, ["rgb", "h_0", "h_1", "h_2", "rgba"]);
}

/// An organised 2 × 2 binary file: `x y z` (F 4), 4 bytes of padding, `rgb` (F 4); pixel 1 has
/// no measurement; the viewpoint is a half turn about x at (1, 2, 3).
fn organised_binary() -> Vec<u8> {
    let mut bytes = header("x y z _ rgb", "4 4 4 1 4", "F F F U F", "1 1 1 4 1", 2, 2, "binary")
        .replace("VIEWPOINT 0 0 0 1 0 0 0", "VIEWPOINT 1 2 3 0 1 0 0")
        .into_bytes();
    let points = [[0.0, 0.0, 1.0], [f32::NAN; 3], [1.0, 0.0, 2.0], [0.5, -0.5, 3.0]];
    for (i, p) in points.iter().enumerate() {
        for v in p {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        bytes.extend_from_slice(&[0xAB; 4]);
        bytes.extend_from_slice(&(0xFF00_0000u32 + i as u32).to_le_bytes());
    }
    bytes
}

#[test]
fn organised_binary_by_hand() {
    let cloud = read(&organised_binary()).unwrap();
    assert_eq!(cloud.len(), 3);
    let grid = cloud.grid().unwrap();
    assert_eq!((grid.width(), grid.height(), grid.num_valid()), (2, 2, 3));
    assert_eq!(grid.point_index(1, 0), None);
    assert_eq!(grid.point_index(1, 1), Some(2));
    assert_eq!(cloud.positions()[2], Point3::new(0.5, -0.5, 3.0));
    let FieldData::F32(rgb) = &cloud.extra_field("rgb").unwrap().data else { panic!() };
    let bits: Vec<u32> = rgb.iter().map(|v| v.to_bits()).collect();
    assert_eq!(bits, [0xFF00_0000, 0xFF00_0002, 0xFF00_0003]);
    let world = cloud.to_world();
    assert!((world.positions()[1] - Point3::new(2.0, 2.0, 1.0)).norm() < 1e-12);
}

#[test]
fn compressed_by_hand() {
    let xs = [1f32, 2., 3.];
    let (ys, zs, is) = ([4f32, 5., 6.], [7f32, 8., 9.], [0.5f32, 0.25, 0.125]);
    let mut raw = Vec::new();
    for v in xs.iter().chain(&ys).chain(&zs).chain(&is) {
        raw.extend_from_slice(&v.to_le_bytes());
    }
    let stream = lzf_literals(&raw);
    let mut bytes =
        header("x y z intensity", "4 4 4 4", "F F F F", "1 1 1 1", 3, 1, "binary_compressed")
            .into_bytes();
    bytes.extend_from_slice(&(stream.len() as u32).to_le_bytes());
    bytes.extend_from_slice(&(raw.len() as u32).to_le_bytes());
    bytes.extend_from_slice(&stream);
    let cloud = read(&bytes).unwrap();
    assert_eq!(cloud.positions()[2], Point3::new(3.0, 6.0, 9.0));
    assert_eq!(cloud.intensity().unwrap(), is);
    // Zeros from one back-reference: 13 literal bytes, then 35 bytes from 1 back.
    let mut raw = Vec::new();
    for v in xs {
        raw.extend_from_slice(&v.to_le_bytes());
    }
    raw.resize(48, 0);
    let mut stream = vec![12];
    stream.extend_from_slice(&raw[..13]);
    stream.extend_from_slice(&[0xE0, 35 - 2 - 7, 0]);
    let mut bytes =
        header("x y z intensity", "4 4 4 4", "F F F F", "1 1 1 1", 3, 1, "binary_compressed")
            .into_bytes();
    bytes.extend_from_slice(&(stream.len() as u32).to_le_bytes());
    bytes.extend_from_slice(&48u32.to_le_bytes());
    bytes.extend_from_slice(&stream);
    let cloud = read(&bytes).unwrap();
    assert_eq!(cloud.positions()[2], Point3::new(3.0, 0.0, 0.0));
    assert_eq!(cloud.intensity().unwrap(), [0.0; 3]);
}

/// A compressed file with padding (which has no bytes in compressed data) and a 64-bit field.
fn compressed_with_padding() -> Vec<u8> {
    let mut raw = Vec::new();
    for v in [1f32, 2., 3., 4., 5., 6.] {
        raw.extend_from_slice(&v.to_le_bytes());
    }
    for t in [u64::MAX, 1 << 53] {
        raw.extend_from_slice(&t.to_le_bytes());
    }
    let stream = lzf_literals(&raw);
    let mut bytes =
        header("x _ y z t", "4 1 4 4 8", "F U F F U", "1 3 1 1 1", 2, 1, "binary_compressed")
            .into_bytes();
    bytes.extend_from_slice(&(stream.len() as u32).to_le_bytes());
    bytes.extend_from_slice(&(raw.len() as u32).to_le_bytes());
    bytes.extend_from_slice(&stream);
    bytes
}

#[test]
fn compressed_padding_and_wide_integers() {
    let cloud = read(&compressed_with_padding()).unwrap();
    assert_eq!(cloud.positions(), [Point3::new(1.0, 3.0, 5.0), Point3::new(2.0, 4.0, 6.0)]);
    assert_eq!(
        cloud.extra_field("t").unwrap().data,
        FieldData::F64(vec![u64::MAX as f64, (1u64 << 53) as f64])
    );
}

#[test]
fn every_prefix_of_a_binary_file_is_an_error() {
    for bytes in [organised_binary(), compressed_with_padding()] {
        assert!(read(&bytes).is_ok());
        for len in 0..bytes.len() {
            assert!(read(&bytes[..len]).is_err(), "prefix of {len} bytes");
        }
    }
}

#[test]
fn trailing_zeros_are_padding_but_other_bytes_are_not() {
    for mut bytes in [organised_binary(), compressed_with_padding()] {
        let end = bytes.len() as u64;
        bytes.extend_from_slice(&[0; 100]);
        assert!(read(&bytes).is_ok());
        bytes.push(1);
        let err = read_err(&bytes);
        assert!(matches!(err.kind, ErrorKind::CountMismatch { .. }), "{err}");
        assert_eq!(err.position, Some(Position::Byte(end)));
    }
}

#[test]
fn non_finite_points_of_unorganised_clouds() {
    let text = xyz_header(3, "ascii") + "0 0 0\n1 nan 1\n\n2 2 inf\n";
    let err = read_err(text.as_bytes());
    assert!(matches!(err.kind, ErrorKind::NonFinite { point: 1 }), "{err}");
    assert_eq!(err.position, Some(Position::Line(13)));
    let cloud = read_pcd(text.as_bytes(), &ReadOptions::SKIP_NON_FINITE).unwrap();
    assert_eq!(cloud.positions(), [Point3::origin()]);

    let mut bytes = xyz_header(2, "binary").into_bytes();
    let start = bytes.len() as u64;
    for v in [0f32, 0., 0., 1., 1., f32::INFINITY] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    let err = read_err(&bytes);
    assert!(matches!(err.kind, ErrorKind::NonFinite { point: 1 }), "{err}");
    assert_eq!(err.position, Some(Position::Byte(start + 12)));
}

#[test]
fn header_keys_in_any_order_with_defaults() {
    // No VERSION, COUNT, HEIGHT, VIEWPOINT or WIDTH; keys shuffled; comments and blank lines.
    let text =
        "# hello\n\nTYPE F F F\nFIELDS x y z\nSIZE 4 4 4\nPOINTS 2\nDATA ascii\n1 2 3\n4 5 6\n";
    let cloud = read(text.as_bytes()).unwrap();
    assert_eq!(cloud.len(), 2);
    assert!(cloud.grid().is_none());
}

// ---------------------------------------------------------------------------------------------
// Malformed files

fn assert_header_error(text: &str, line: u64) {
    let err = read_err(text.as_bytes());
    assert!(matches!(err.kind, ErrorKind::BadHeader(_) | ErrorKind::Unsupported(_)), "{err}");
    assert_eq!(err.position, Some(Position::Line(line)), "{text}: {err}");
}

#[test]
fn header_errors_name_their_line() {
    let good = xyz_header(1, "ascii");
    let edit = |from: &str, to: &str| good.replace(from, to);
    assert_header_error(&edit("FIELDS x y z\n", ""), 10);
    assert_header_error(&edit("SIZE 4 4 4", "SIZE 4 4"), 4);
    assert_header_error(&edit("TYPE F F F", "TYPE F F G"), 5);
    assert_header_error(&edit("SIZE 4 4 4", "SIZE 4 4 2"), 5);
    assert_header_error(&edit("COUNT 1 1 1", "COUNT 1 0 1"), 6);
    assert_header_error(&edit("COUNT 1 1 1", "COUNT 1 1 100000"), 6);
    assert_header_error(&edit("FIELDS x y z", "FIELDS x y y"), 3);
    assert_header_error(&edit("FIELDS x y z", "FIELDS x y w"), 3);
    assert_header_error(&edit("WIDTH 1", "WIDTH one"), 7);
    assert_header_error(&edit("WIDTH 1", "WIDTH 1 2"), 7);
    assert_header_error(&edit("WIDTH 1\nHEIGHT 1", "WIDTH 4294967296\nHEIGHT 4294967296"), 8);
    assert_header_error(
        &edit("WIDTH 1\nHEIGHT 1", "WIDTH 100000\nHEIGHT 100000")
            .replace("POINTS 1\n", "POINTS 10000000000\n"),
        8,
    );
    assert_header_error(
        &edit("WIDTH 1\nHEIGHT 1", "WIDTH 0\nHEIGHT 4294967296")
            .replace("POINTS 1\n", "POINTS 0\n"),
        8,
    );
    assert_header_error(&edit("POINTS 1", "POINTS 2"), 10);
    assert_header_error(&edit("VIEWPOINT 0 0 0 1 0 0 0", "VIEWPOINT 0 0 0 1 0 0"), 9);
    assert_header_error(&edit("VIEWPOINT 0 0 0 1 0 0 0", "VIEWPOINT 1 0 0 0 0 0 0"), 9);
    assert_header_error(&edit("VIEWPOINT 0 0 0 1 0 0 0", "VIEWPOINT 0 0 0 nan 0 0 0"), 9);
    assert_header_error(&edit("DATA ascii", "DATA text"), 11);
    assert_header_error(&edit("VERSION 0.7", "WIDTH 1"), 7);
    assert_header_error(&edit("VERSION 0.7", "COLOR red"), 2);
    let err = read_err(edit("DATA ascii\n", "").as_bytes());
    assert!(matches!(err.kind, ErrorKind::UnexpectedEof { .. }), "{err}");
    assert_eq!(err.position, Some(Position::Line(11)));
}

#[test]
fn ascii_count_errors() {
    let text = xyz_header(3, "ascii");
    let err = read_err((text.clone() + "0 0 0\n1 1 1\n").as_bytes());
    assert!(matches!(err.kind, ErrorKind::CountMismatch { declared: 3, found: 2, .. }), "{err}");
    assert_eq!(err.position, Some(Position::Line(14)));
    let err = read_err((text.clone() + "0 0 0\n1 1 1\n2 2 2\n3 3 3\n4 4 4\n").as_bytes());
    assert!(matches!(err.kind, ErrorKind::CountMismatch { declared: 3, found: 5, .. }), "{err}");
    assert_eq!(err.position, Some(Position::Line(15)));
    let err = read_err((text.clone() + "0 0 0\n1 1\n2 2 2\n").as_bytes());
    assert!(matches!(err.kind, ErrorKind::BadValue(_)), "{err}");
    assert_eq!(err.position, Some(Position::Line(13)));
    let err = read_err((text.clone() + "0 0 0\n1 1 1 1\n2 2 2\n").as_bytes());
    assert_eq!(err.position, Some(Position::Line(13)));
    let err = read_err((text + "0 0 0\n1 1 1\n2 2 0x2\n").as_bytes());
    assert!(matches!(err.kind, ErrorKind::BadValue(_)), "{err}");
    assert_eq!(err.position, Some(Position::Line(14)));
}

#[test]
fn header_lies_about_binary_sizes() {
    // A trillion points declared, two present: refused before any allocation.
    let mut bytes = xyz_header(1_000_000_000_000, "binary").into_bytes();
    bytes.extend_from_slice(&[0; 24]);
    let err = read_err(&bytes);
    assert!(matches!(err.kind, ErrorKind::CountMismatch { found: 2, .. }), "{err}");
    assert_eq!(err.position, Some(Position::Byte(bytes.len() as u64)));
    // An organised header with little data.
    let mut bytes = header("x y z", "4 4 4", "F F F", "1 1 1", 640, 480, "binary").into_bytes();
    bytes.extend_from_slice(&[0; 100]);
    assert!(matches!(read_err(&bytes).kind, ErrorKind::CountMismatch { .. }));

    let compressed = |compressed: u32, uncompressed: u32, stream: &[u8]| {
        let mut bytes = xyz_header(2, "binary_compressed").into_bytes();
        let start = bytes.len() as u64;
        bytes.extend_from_slice(&compressed.to_le_bytes());
        bytes.extend_from_slice(&uncompressed.to_le_bytes());
        bytes.extend_from_slice(stream);
        (bytes, start)
    };
    let stream = lzf_literals(&[0; 24]);
    let (bytes, _) = compressed(stream.len() as u32, 24, &stream);
    assert_eq!(read(&bytes).unwrap().len(), 2);
    // Uncompressed size different from POINTS × point size.
    let (bytes, start) = compressed(stream.len() as u32, u32::MAX, &stream);
    let err = read_err(&bytes);
    assert!(matches!(err.kind, ErrorKind::CountMismatch { declared: 24, .. }), "{err}");
    assert_eq!(err.position, Some(Position::Byte(start + 4)));
    // Compressed size larger than the file.
    let (bytes, _) = compressed(1 << 30, 24, &stream);
    let err = read_err(&bytes);
    assert!(matches!(err.kind, ErrorKind::UnexpectedEof { .. }), "{err}");
    assert_eq!(err.position, Some(Position::Byte(bytes.len() as u64)));
    // A back-reference before the start of the output.
    let (bytes, start) = compressed(2, 24, &[0x20, 0x00]);
    let err = read_err(&bytes);
    assert!(matches!(err.kind, ErrorKind::BadValue(_)), "{err}");
    assert_eq!(err.position, Some(Position::Byte(start + 8)));
    // A literal run cut short.
    let (bytes, start) = compressed(3, 24, &[0x00, 0x00, 0x1F]);
    let err = read_err(&bytes);
    assert_eq!(err.position, Some(Position::Byte(start + 8 + 2)));
    // Fewer than 8 bytes of sizes.
    let mut bytes = xyz_header(2, "binary_compressed").into_bytes();
    bytes.extend_from_slice(&[1, 2, 3]);
    assert!(matches!(read_err(&bytes).kind, ErrorKind::UnexpectedEof { .. }));
}

// ---------------------------------------------------------------------------------------------
// Writing

#[test]
fn writer_output_is_plain_pcd() {
    let mut cloud =
        PointCloud::from_positions(vec![Point3::new(1.0, 2.0, 3.0), Point3::new(0.5, -1.0, 0.0)])
            .unwrap();
    cloud.set_labels(Some(vec![4, 5])).unwrap();
    cloud
        .push_extra_field(ScalarField {
            name: "rgb".into(),
            data: FieldData::F32(vec![f32::from_bits(0xFF10_2030), f32::from_bits(7)]),
        })
        .unwrap();
    let text = String::from_utf8(write(&cloud, PcdEncoding::Ascii, Precision::F32)).unwrap();
    assert_eq!(
        text,
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z label rgb\n\
         SIZE 4 4 4 4 4\nTYPE F F F U U\nCOUNT 1 1 1 1 1\nWIDTH 2\nHEIGHT 1\n\
         VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n1 2 3 4 4279246896\n0.5 -1 0 5 7\n"
    );
    let binary = write(&cloud, PcdEncoding::Binary, Precision::F64);
    let text = String::from_utf8_lossy(&binary);
    assert!(text.contains("SIZE 8 8 8 4 4\nTYPE F F F U F\n"), "{text}");
    assert_eq!(binary[binary.len() - 32..][..8], 0.5f64.to_le_bytes());
}

#[test]
fn one_row_grids_are_written_unorganised() {
    let cloud = PointCloud::from_pixels(
        3,
        1,
        [Some(Point3::new(1., 2., 3.)), None, Some(Point3::origin())],
    )
    .unwrap();
    for encoding in ENCODINGS {
        let back = read(&write(&cloud, encoding, Precision::F64)).unwrap();
        assert!(back.grid().is_none());
        assert_eq!(back.positions(), cloud.positions());
    }
}

#[test]
fn writer_refuses_padding_and_repeated_names() {
    for name in ["_", "normal_x", "", "a\tb"] {
        let mut cloud = PointCloud::from_positions(vec![Point3::origin()]).unwrap();
        cloud.set_normals(Some(vec![Vector3::z()])).unwrap();
        cloud
            .push_extra_field(ScalarField { name: name.into(), data: FieldData::U8(vec![1]) })
            .unwrap();
        let err = write_pcd(Vec::new(), &cloud, &PcdWriteOptions::default()).unwrap_err();
        assert!(matches!(err.kind, ErrorKind::BadValue(_)), "{name:?}");
    }
}

// ---------------------------------------------------------------------------------------------
// Round trips of random clouds

/// `None` for an unorganised cloud, else the image size (at least two rows: PCD's `HEIGHT 1` is
/// an unorganised cloud); `mask` says which records are valid.
fn layout() -> impl Strategy<Value = (Option<(u32, u32)>, Vec<bool>)> {
    prop_oneof![
        (0usize..25).prop_map(|n| (None, vec![true; n])),
        (1u32..6, 2u32..6).prop_flat_map(|(w, h)| {
            vec(prop::bool::weighted(0.7), (w * h) as usize).prop_map(move |m| (Some((w, h)), m))
        }),
    ]
}

prop_compose! {
    fn cloud()((grid, mask) in layout())(
        positions in vec((-1e3f64..1e3, -1e3f64..1e3, -1e3f64..1e3), mask.iter().filter(|&&b| b).count()),
        normals in proptest::option::of(vec((-1f64..1., -1f64..1., -1f64..1.), mask.iter().filter(|&&b| b).count())),
        intensity in proptest::option::of(vec(finite_f32(), mask.iter().filter(|&&b| b).count())),
        labels in proptest::option::of(vec(any::<u32>(), mask.iter().filter(|&&b| b).count())),
        rings in proptest::option::of(vec(any::<u16>(), mask.iter().filter(|&&b| b).count())),
        extras in vec(field_data(mask.iter().filter(|&&b| b).count()), 0..3),
        rgb in proptest::option::of(vec(any::<u32>(), mask.iter().filter(|&&b| b).count())),
        pose in proptest::option::of(pose()),
        grid in Just(grid),
        mask in Just(mask),
    ) -> PointCloud {
        let points: Vec<Point3> = positions.iter().map(|&(x, y, z)| Point3::new(x, y, z)).collect();
        let mut cloud = match grid {
            Some((w, h)) => {
                let mut it = points.into_iter();
                PointCloud::from_pixels(w, h, mask.iter().map(|&valid| if valid { it.next() } else { None })).unwrap()
            }
            None => PointCloud::from_positions(points).unwrap(),
        };
        cloud.set_normals(normals.map(|n| n.into_iter().map(|(x, y, z)| Vector3::new(x, y, z)).collect())).unwrap();
        cloud.set_intensity(intensity).unwrap();
        cloud.set_labels(labels).unwrap();
        cloud.set_rings(rings).unwrap();
        for (i, data) in extras.into_iter().enumerate() {
            cloud.push_extra_field(ScalarField { name: format!("f{i}"), data }).unwrap();
        }
        if let Some(bits) = rgb {
            // Any bit pattern, NaN payloads included, as PCL's packed colours are.
            let data = FieldData::F32(bits.into_iter().map(f32::from_bits).collect());
            cloud.push_extra_field(ScalarField { name: "rgb".into(), data }).unwrap();
        }
        cloud.set_sensor_pose(pose);
        cloud
    }
}

/// Field values compared bit for bit (so NaN payloads count).
fn bits(data: &FieldData) -> Vec<u64> {
    match data {
        FieldData::F32(v) => v.iter().map(|x| u64::from(x.to_bits())).collect(),
        FieldData::F64(v) => v.iter().map(|x| x.to_bits()).collect(),
        other => (0..other.len()).map(|i| other.get_f64(i).unwrap().to_bits()).collect(),
    }
}

fn check_round_trip(cloud: &PointCloud, encoding: PcdEncoding, precision: Precision) {
    let context = format!("{encoding:?} {precision:?}");
    let bytes = write(cloud, encoding, precision);
    let back = read(&bytes).unwrap_or_else(|e| panic!("{context}: {e}"));
    let round = |v: f64| match precision {
        Precision::F32 => v as f32 as f64,
        Precision::F64 => v,
    };
    let positions: Vec<Point3> = cloud.positions().iter().map(|p| p.map(round)).collect();
    assert_eq!(back.positions(), positions, "{context}");
    let normals: Option<Vec<Vector3>> =
        cloud.normals().map(|n| n.iter().map(|v| v.map(round)).collect());
    assert_eq!(back.normals(), normals.as_deref(), "{context}");
    assert_eq!(back.intensity(), cloud.intensity(), "{context}");
    assert_eq!(back.labels(), cloud.labels(), "{context}");
    assert_eq!(back.rings(), cloud.rings(), "{context}");
    assert_eq!(back.grid(), cloud.grid(), "{context}");
    // Poses go through the quaternion's own digits: exact.
    assert_eq!(back.sensor_pose(), cloud.sensor_pose(), "{context}");
    assert_eq!(back.extra_fields().len(), cloud.extra_fields().len(), "{context}");
    for (a, b) in cloud.extra_fields().iter().zip(back.extra_fields()) {
        assert_eq!(a.name, b.name, "{context}");
        assert_eq!(bits(&a.data), bits(&b.data), "{context} {}", a.name);
        assert_eq!(std::mem::discriminant(&a.data), std::mem::discriminant(&b.data), "{context}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn random_clouds_round_trip(cloud in cloud()) {
        for encoding in ENCODINGS {
            for precision in [Precision::F32, Precision::F64] {
                check_round_trip(&cloud, encoding, precision);
            }
        }
    }

    #[test]
    fn garbage_never_panics(bytes in vec(any::<u8>(), 0..300)) {
        let _ = read(&bytes);
        for data in ["ascii", "binary", "binary_compressed"] {
            let mut file = header("x y z _ h", "4 4 4 1 2", "F F F U I", "1 1 1 3 2", 2, 2, data).into_bytes();
            file.extend_from_slice(&bytes);
            let _ = read(&file);
        }
    }

    #[test]
    fn damaged_files_never_panic(
        compressed in any::<bool>(),
        damage in vec((any::<prop::sample::Index>(), any::<u8>()), 1..8),
    ) {
        let mut bytes = if compressed { compressed_with_padding() } else { organised_binary() };
        for (at, value) in damage {
            let i = at.index(bytes.len());
            bytes[i] = value;
        }
        let _ = read(&bytes);
    }

    #[test]
    fn damaged_lzf_streams_never_panic(damage in vec((any::<prop::sample::Index>(), any::<u8>()), 1..6)) {
        let cloud = PointCloud::from_positions((0..50).map(|i| Point3::new(f64::from(i), 0.0, 1.0)).collect()).unwrap();
        let mut bytes = write(&cloud, PcdEncoding::BinaryCompressed, Precision::F32);
        let start = String::from_utf8_lossy(&bytes).find("DATA binary_compressed\n").unwrap() + 23 + 8;
        for (at, value) in damage {
            let i = start + at.index(bytes.len() - start);
            bytes[i] = value;
        }
        let _ = read(&bytes);
    }
}
