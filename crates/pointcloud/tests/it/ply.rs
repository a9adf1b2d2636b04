//! PLY reading and writing: hand-written files in every encoding, malformed input, and round
//! trips of random clouds.

use pointcloud::io::ply::{PlyEncoding, PlyWriteOptions, read_ply, write_ply};
use pointcloud::io::{Error, ErrorKind, Position, Precision, ReadOptions};
use pointcloud::{FieldData, Point3, PointCloud, ScalarField, Vector3};
use proptest::collection::vec;
use proptest::prelude::*;

use crate::common;
use common::*;

fn read(bytes: &[u8]) -> Result<PointCloud, Error> {
    read_ply(bytes, &ReadOptions::STRICT)
}

fn read_err(bytes: &[u8]) -> Error {
    read(bytes).expect_err("the file is malformed")
}

fn write(cloud: &PointCloud, encoding: PlyEncoding, precision: Precision) -> Vec<u8> {
    let mut out = Vec::new();
    write_ply(&mut out, cloud, &PlyWriteOptions { encoding, precision }).unwrap();
    out
}

const ENCODINGS: [PlyEncoding; 3] =
    [PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian, PlyEncoding::BinaryBigEndian];

// ---------------------------------------------------------------------------------------------
// Hand-written files

#[test]
fn ascii_with_attributes_and_faces() {
    let text = b"ply\r
format ascii 1.0\r
comment made by hand\r
obj_info nothing to see\r
element vertex 3\r
property float x\r
property float y\r
property float z\r
property uchar red\r
property float intensity\r
property int label\r
property ushort ring\r
element face 2\r
property list uchar int vertex_indices\r
end_header\r
0 0 0 255 0.5 1 7\r
1 0 0 0 1.5 2 8\r
\r
0 1 0.25 7 2.5 3 9\r
3 0 1 2\r
0\r
";
    let cloud = read(text).unwrap();
    assert_eq!(
        cloud.positions(),
        [Point3::new(0., 0., 0.), Point3::new(1., 0., 0.), Point3::new(0., 1., 0.25)]
    );
    assert_eq!(cloud.intensity().unwrap(), [0.5, 1.5, 2.5]);
    assert_eq!(cloud.labels().unwrap(), [1, 2, 3]);
    assert_eq!(cloud.rings().unwrap(), [7, 8, 9]);
    assert_eq!(
        cloud.extra_fields(),
        [ScalarField { name: "red".into(), data: FieldData::U8(vec![255, 0, 7]) }]
    );
    assert!(cloud.grid().is_none() && cloud.sensor_pose().is_none() && cloud.normals().is_none());
}

#[test]
fn every_type_name_and_alias() {
    let names = [
        "char", "uchar", "short", "ushort", "int", "uint", "float", "double", "int8", "uint8",
        "int16", "uint16", "int32", "uint32", "float32", "float64",
    ];
    let mut text = String::from("ply\nformat ascii 1.0\nelement vertex 1\n");
    for (i, name) in names.iter().enumerate() {
        text += &format!("property {name} p{i}\n");
    }
    text += "property float64 x\nproperty int8 y\nproperty uint32 z\nend_header\n";
    text += "-1 2 -3 4 -5 6 7.5 8.5 -9 10 -11 12 -13 14 15.5 16.5 1.5 -2 3\n";
    let cloud = read(text.as_bytes()).unwrap();
    assert_eq!(cloud.positions(), [Point3::new(1.5, -2.0, 3.0)]);
    let expected = [
        FieldData::I8(vec![-1]),
        FieldData::U8(vec![2]),
        FieldData::I16(vec![-3]),
        FieldData::U16(vec![4]),
        FieldData::I32(vec![-5]),
        FieldData::U32(vec![6]),
        FieldData::F32(vec![7.5]),
        FieldData::F64(vec![8.5]),
        FieldData::I8(vec![-9]),
        FieldData::U8(vec![10]),
        FieldData::I16(vec![-11]),
        FieldData::U16(vec![12]),
        FieldData::I32(vec![-13]),
        FieldData::U32(vec![14]),
        FieldData::F32(vec![15.5]),
        FieldData::F64(vec![16.5]),
    ];
    for (i, data) in expected.into_iter().enumerate() {
        assert_eq!(cloud.extra_field(&format!("p{i}")).unwrap().data, data, "p{i}");
    }
}

/// A vertex element with `double x, short y, uchar z, float nx ny nz` and a face element with
/// `list uchar int`, then an `edge` element, laid out by hand.
fn binary_file(big_endian: bool) -> Vec<u8> {
    let format = if big_endian { "binary_big_endian" } else { "binary_little_endian" };
    let mut bytes = format!(
        "ply\nformat {format} 1.0\nelement vertex 2\nproperty double x\nproperty short y\n\
         property uchar z\nproperty float nx\nproperty float ny\nproperty float nz\n\
         element face 2\nproperty list uchar int vertex_indices\n\
         element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n"
    )
    .into_bytes();
    macro_rules! put {
        ($v:expr) => {
            bytes.extend_from_slice(&if big_endian { $v.to_be_bytes() } else { $v.to_le_bytes() })
        };
    }
    for (x, y, z, n) in [(1.5f64, -2i16, 3u8, [0f32, 0., 1.]), (-0.25, 300, 255, [1., 0., 0.])] {
        put!(x);
        put!(y);
        put!(z);
        for v in n {
            put!(v);
        }
    }
    put!(3u8);
    for i in [0i32, 1, 0] {
        put!(i);
    }
    put!(0u8);
    put!(0i32);
    put!(1i32);
    bytes
}

#[test]
fn binary_little_and_big_endian_by_hand() {
    for big_endian in [false, true] {
        let cloud = read(&binary_file(big_endian)).unwrap();
        assert_eq!(
            cloud.positions(),
            [Point3::new(1.5, -2.0, 3.0), Point3::new(-0.25, 300.0, 255.0)]
        );
        assert_eq!(cloud.normals().unwrap(), [Vector3::z(), Vector3::x()]);
        assert!(cloud.extra_fields().is_empty());
    }
}

#[test]
fn every_prefix_of_a_binary_file_is_an_error() {
    for big_endian in [false, true] {
        let bytes = binary_file(big_endian);
        assert!(read(&bytes).is_ok());
        for len in 0..bytes.len() {
            assert!(read(&bytes[..len]).is_err(), "prefix of {len} bytes");
        }
    }
}

#[test]
fn organised_ascii_with_invalid_pixels_and_sensor_pose() {
    let text = b"ply
format ascii 1.0
comment organized 3 2
comment sensor_origin 0 0 0
comment sensor_to_world 0 0 1 10 -1 0 0 7.5 0 -1 0 1.25
element vertex 6
property float x
property float y
property float z
end_header
0 0 1
nan nan nan
1 0 1
NaN NAN nan
0 1 -inf
0 2 2
";
    let cloud = read(text).unwrap();
    assert_eq!(cloud.len(), 3);
    let grid = cloud.grid().unwrap();
    assert_eq!((grid.width(), grid.height()), (3, 2));
    assert_eq!(grid.point_index(0, 0), Some(0));
    assert_eq!(grid.point_index(1, 0), None);
    assert_eq!(grid.point_index(2, 0), Some(1));
    assert_eq!(grid.point_index(0, 1), None);
    assert_eq!(grid.point_index(1, 1), None);
    assert_eq!(grid.point_index(2, 1), Some(2));
    assert_eq!(cloud.positions()[2], Point3::new(0.0, 2.0, 2.0));
    // The optical axis (z) of the sensor looks along the world's x.
    let world = cloud.to_world();
    assert!((world.positions()[0] - Point3::new(11.0, 7.5, 1.25)).norm() < 1e-12);
}

#[test]
fn non_finite_values_in_unorganised_clouds() {
    let text = b"ply
format ascii 1.0
element vertex 3
property float x
property float y
property float z
property double s
end_header
0 0 0 INF
1 Infinity 0 -Infinity
2 0 0 nan
";
    let err = read_err(text);
    assert!(matches!(err.kind, ErrorKind::NonFinite { point: 1 }), "{err}");
    assert_eq!(err.position, Some(Position::Line(10)));
    let cloud = read_ply(&text[..], &ReadOptions::SKIP_NON_FINITE).unwrap();
    assert_eq!(cloud.positions(), [Point3::origin(), Point3::new(2.0, 0.0, 0.0)]);
    let FieldData::F64(s) = &cloud.extra_field("s").unwrap().data else { panic!() };
    assert_eq!(s[0], f64::INFINITY);
    assert!(s[1].is_nan());
}

#[test]
fn non_finite_binary_point_names_its_byte() {
    let mut bytes = b"ply\nformat binary_little_endian 1.0\nelement vertex 2\n\
property float x\nproperty float y\nproperty float z\nend_header\n"
        .to_vec();
    let header = bytes.len() as u64;
    for v in [1f32, 2., 3., 4., f32::NAN, 6.] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    let err = read_err(&bytes);
    assert!(matches!(err.kind, ErrorKind::NonFinite { point: 1 }));
    assert_eq!(err.position, Some(Position::Byte(header + 12)));
}

#[test]
fn slot_names_with_values_that_do_not_fit_stay_extra_fields() {
    let text = b"ply
format ascii 1.0
element vertex 2
property float x
property float y
property float z
property int label
property float ring
property double intensity
end_header
0 0 0 -1 1.5 0.1
0 0 0 2 2 0.5
";
    let cloud = read(text).unwrap();
    assert!(cloud.labels().is_none() && cloud.rings().is_none() && cloud.intensity().is_none());
    assert_eq!(cloud.extra_field("label").unwrap().data, FieldData::I32(vec![-1, 2]));
    assert_eq!(cloud.extra_field("intensity").unwrap().data, FieldData::F64(vec![0.1, 0.5]));
}

#[test]
fn writer_output_is_plain_ply() {
    let mut cloud =
        PointCloud::from_positions(vec![Point3::new(1.0, 2.0, 3.0), Point3::new(0.5, -1.0, 1e-7)])
            .unwrap();
    cloud.set_labels(Some(vec![4, 5])).unwrap();
    let text = write(&cloud, PlyEncoding::Ascii, Precision::F32);
    assert_eq!(
        String::from_utf8(text).unwrap(),
        "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n\
         property float z\nproperty uint label\nend_header\n1 2 3 4\n0.5 -1 1e-7 5\n"
    );
    let binary = write(&cloud, PlyEncoding::BinaryBigEndian, Precision::F64);
    let body = &binary[binary.len() - 2 * 28..];
    assert_eq!(body[..8], 1.0f64.to_be_bytes());
    assert_eq!(body[24..28], 4u32.to_be_bytes());
}

#[test]
fn writer_refuses_bad_or_repeated_names() {
    let mut cloud = PointCloud::from_positions(vec![Point3::origin()]).unwrap();
    cloud.push_extra_field(ScalarField { name: "x".into(), data: FieldData::U8(vec![1]) }).unwrap();
    let mut out = Vec::new();
    let err = write_ply(&mut out, &cloud, &PlyWriteOptions::default()).unwrap_err();
    assert!(matches!(err.kind, ErrorKind::BadValue(_)));
    let mut cloud = PointCloud::from_positions(vec![Point3::origin()]).unwrap();
    cloud
        .push_extra_field(ScalarField { name: "a b".into(), data: FieldData::U8(vec![1]) })
        .unwrap();
    assert!(write_ply(&mut out, &cloud, &PlyWriteOptions::default()).is_err());
}

#[test]
fn organised_writing_fills_invalid_pixels() {
    let mut cloud =
        PointCloud::from_pixels(2, 1, [None, Some(Point3::new(1.0, 2.0, 3.0))]).unwrap();
    cloud.set_labels(Some(vec![9])).unwrap();
    let text = String::from_utf8(write(&cloud, PlyEncoding::Ascii, Precision::F64)).unwrap();
    assert!(text.contains("comment organized 2 1\n"));
    assert!(text.ends_with("end_header\nnan nan nan 0\n1 2 3 9\n"), "{text}");
    assert_eq!(read(text.as_bytes()).unwrap(), cloud);
}

#[test]
fn points_of_a_grid_in_any_order_come_back_in_pixel_order() {
    let cloud = PointCloud::from_pixels(
        2,
        2,
        [
            Some(Point3::new(0., 0., 1.)),
            None,
            Some(Point3::new(1., 0., 1.)),
            Some(Point3::new(2., 0., 1.)),
        ],
    )
    .unwrap();
    let in_pixel_order = cloud.clone();
    let shuffled = {
        // Points 2, 0, 1 of `cloud`, with the grid pointing at them.
        let mut c = PointCloud::from_positions(vec![
            cloud.positions()[2],
            cloud.positions()[0],
            cloud.positions()[1],
        ])
        .unwrap();
        let grid = pointcloud::Grid::new(2, 2, vec![1, u32::MAX, 2, 0], 3).unwrap();
        c.set_grid(Some(grid)).unwrap();
        c
    };
    for encoding in ENCODINGS {
        let back = read(&write(&shuffled, encoding, Precision::F64)).unwrap();
        assert_eq!(back, in_pixel_order);
    }
}

// ---------------------------------------------------------------------------------------------
// Malformed files

const XYZ: &str = "property float x\nproperty float y\nproperty float z\n";

fn ascii(header_extra: &str, body: &str) -> Vec<u8> {
    format!("ply\nformat ascii 1.0\n{header_extra}end_header\n{body}").into_bytes()
}

fn assert_header_error(bytes: &[u8], line: u64) {
    let err = read_err(bytes);
    assert!(matches!(err.kind, ErrorKind::BadHeader(_) | ErrorKind::Unsupported(_)), "{err}");
    assert_eq!(err.position, Some(Position::Line(line)), "{err}");
}

#[test]
fn header_errors_name_their_line() {
    assert_header_error(b"PLY\nformat ascii 1.0\n", 1);
    assert_header_error(b"", 1);
    assert_header_error(&ascii(&format!("element vertex 1\n{XYZ}property float128 w\n"), ""), 7);
    assert_header_error(&ascii(&format!("property float w\nelement vertex 1\n{XYZ}"), ""), 3);
    assert_header_error(&ascii(&format!("element vertex 1\n{XYZ}property float y\n"), ""), 7);
    assert_header_error(
        &ascii("element vertex 1\nproperty list uchar float x\nproperty float y\n", ""),
        4,
    );
    assert_header_error(&ascii("element vertex 1\nproperty list float int i\n", ""), 4);
    assert_header_error(&ascii("element vertex 1\nproperty float x\nproperty float y\n", ""), 6);
    assert_header_error(&ascii("element face 1\nproperty uchar f\n", ""), 5);
    assert_header_error(&ascii(&format!("element vertex 1\n{XYZ}element vertex 1\n"), ""), 7);
    assert_header_error(&ascii(&format!("element vertex -1\n{XYZ}"), ""), 3);
    assert_header_error(&ascii(&format!("format ascii 1.0\nelement vertex 1\n{XYZ}"), ""), 3);
    assert_header_error(&ascii(&format!("elements vertex 1\n{XYZ}"), ""), 3);
    assert_header_error(&ascii(&format!("comment organized 2 2\nelement vertex 3\n{XYZ}"), ""), 3);
    assert_header_error(&ascii(&format!("comment organized 2 x\nelement vertex 4\n{XYZ}"), ""), 3);
    assert_header_error(
        &ascii(
            &format!("comment sensor_to_world 1 0 0 0 0 1 0 0 0 0 1\nelement vertex 1\n{XYZ}"),
            "",
        ),
        3,
    );
    assert_header_error(
        &ascii(
            &format!("comment sensor_to_world 2 0 0 0 0 2 0 0 0 0 2 0\nelement vertex 1\n{XYZ}"),
            "",
        ),
        3,
    );
    assert_header_error(
        &format!("ply\nformat ascii 2.0\nelement vertex 1\n{XYZ}end_header\n").into_bytes(),
        2,
    );
    assert_header_error(
        &format!("ply\nformat utf8 1.0\nelement vertex 1\n{XYZ}end_header\n").into_bytes(),
        2,
    );
    assert_header_error(&format!("ply\nelement vertex 1\n{XYZ}end_header\n").into_bytes(), 6);
    let err = read_err(format!("ply\nformat ascii 1.0\nelement vertex 1\n{XYZ}").as_bytes());
    assert!(matches!(err.kind, ErrorKind::UnexpectedEof { .. }), "{err}");
    assert_eq!(err.position, Some(Position::Line(7)));
}

#[test]
fn ascii_count_errors() {
    let header = format!("element vertex 3\n{XYZ}");
    let err = read_err(&ascii(&header, "0 0 0\n1 1 1\n"));
    assert!(matches!(err.kind, ErrorKind::CountMismatch { declared: 3, found: 2, .. }), "{err}");
    assert_eq!(err.position, Some(Position::Line(10)));
    let err = read_err(&ascii(&header, "0 0 0\n1 1 1\n2 2 2\n3 3 3\n\n"));
    assert!(matches!(err.kind, ErrorKind::CountMismatch { declared: 3, found: 4, .. }), "{err}");
    assert_eq!(err.position, Some(Position::Line(11)));
    let err = read_err(&ascii(&header, "0 0 0\n1 1 1 1\n2 2 2\n"));
    assert!(matches!(err.kind, ErrorKind::BadValue(_)), "{err}");
    assert_eq!(err.position, Some(Position::Line(9)));
    let err = read_err(&ascii(&header, "0 0 0\n1 1\n2 2 2\n"));
    assert_eq!(err.position, Some(Position::Line(9)));
    let err = read_err(&ascii(&header, "0 0 0\n1 1 1\n2 2 two\n"));
    assert!(matches!(err.kind, ErrorKind::BadValue(_)), "{err}");
    assert_eq!(err.position, Some(Position::Line(10)));
    let header = format!(
        "element vertex 1\n{XYZ}property uchar c\nelement face 1\nproperty list uchar int v\n"
    );
    let err = read_err(&ascii(&header, "0 0 0 256\n3 0 0 0\n"));
    assert_eq!(err.position, Some(Position::Line(11)));
    let err = read_err(&ascii(&header, "0 0 0 1\n3 0 0\n"));
    assert_eq!(err.position, Some(Position::Line(12)));
    let err = read_err(&ascii(&header, "0 0 0 1\n-1\n"));
    assert_eq!(err.position, Some(Position::Line(12)));
    let err = read_err(&ascii(&header, "0 0 0 1\n"));
    assert!(matches!(err.kind, ErrorKind::CountMismatch { declared: 1, found: 0, .. }), "{err}");
    // A huge list length with few items is an error, quickly.
    let err = read_err(&ascii(
        &format!("element vertex 1\n{XYZ}element face 1\nproperty list uint int v\n"),
        "0 0 0\n4000000000 1 2\n",
    ));
    assert_eq!(err.position, Some(Position::Line(11)));
}

#[test]
fn binary_count_errors_name_bytes() {
    let header = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\n{XYZ}end_header\n"
    );
    let mut bytes = header.clone().into_bytes();
    bytes.extend_from_slice(&[0; 24]);
    let err = read_err(&bytes);
    assert!(
        matches!(err.kind, ErrorKind::CountMismatch { declared: 1_000_000_000_000, found: 2, .. }),
        "{err}"
    );
    assert_eq!(err.position, Some(Position::Byte(bytes.len() as u64)));
    // u64::MAX elements: the size computation overflows, which is reported, not a panic.
    let bytes = format!(
        "ply\nformat binary_big_endian 1.0\nelement vertex 18446744073709551615\n{XYZ}end_header\n"
    );
    assert!(matches!(read_err(bytes.as_bytes()).kind, ErrorKind::CountMismatch { .. }));
    // Trailing bytes mean the count was too small.
    let mut bytes =
        format!("ply\nformat binary_little_endian 1.0\nelement vertex 1\n{XYZ}end_header\n")
            .into_bytes();
    let end = bytes.len() as u64 + 12;
    bytes.extend_from_slice(&[0; 13]);
    let err = read_err(&bytes);
    assert!(matches!(err.kind, ErrorKind::CountMismatch { .. }), "{err}");
    assert_eq!(err.position, Some(Position::Byte(end)));
    // A negative list length.
    let mut bytes = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex 1\n{XYZ}element face 1\n\
         property list char int v\nend_header\n"
    )
    .into_bytes();
    bytes.extend_from_slice(&[0; 12]);
    let at = bytes.len() as u64;
    bytes.push(0xff);
    let err = read_err(&bytes);
    assert!(matches!(err.kind, ErrorKind::BadValue(_)), "{err}");
    assert_eq!(err.position, Some(Position::Byte(at)));
}

#[test]
fn elements_without_properties_cost_nothing() {
    let text =
        ascii(&format!("element nothing 18446744073709551615\nelement vertex 1\n{XYZ}"), "1 2 3\n");
    assert_eq!(read(&text).unwrap().len(), 1);
    let mut bytes = format!(
        "ply\nformat binary_little_endian 1.0\nelement nothing 18446744073709551615\n\
         element vertex 1\n{XYZ}end_header\n"
    )
    .into_bytes();
    bytes.extend_from_slice(&[0; 12]);
    assert_eq!(read(&bytes).unwrap().len(), 1);
}

#[test]
fn a_header_line_without_end_is_refused() {
    let mut bytes = b"ply\ncomment ".to_vec();
    bytes.resize(3 << 20, b'a');
    let err = read_err(&bytes);
    assert!(matches!(err.kind, ErrorKind::BadHeader(_)), "{err}");
    assert_eq!(err.position, Some(Position::Line(2)));
}

// ---------------------------------------------------------------------------------------------
// Round trips of random clouds

/// `None` for an unorganised cloud of `mask.len()` points, else the image size; `mask` says
/// which records are valid.
fn layout() -> impl Strategy<Value = (Option<(u32, u32)>, Vec<bool>)> {
    prop_oneof![
        (0usize..25).prop_map(|n| (None, vec![true; n])),
        (1u32..6, 1u32..6).prop_flat_map(|(w, h)| {
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
        cloud.set_sensor_pose(pose);
        cloud
    }
}

/// What a cloud reads back as: positions and normals rounded to `f32` for [`Precision::F32`],
/// and no pose (poses are compared apart, to rounding).
fn expected(cloud: &PointCloud, precision: Precision) -> PointCloud {
    let round = |v: f64| match precision {
        Precision::F32 => v as f32 as f64,
        Precision::F64 => v,
    };
    let mut out =
        PointCloud::from_positions(cloud.positions().iter().map(|p| p.map(round)).collect())
            .unwrap();
    out.set_normals(cloud.normals().map(|n| n.iter().map(|v| v.map(round)).collect())).unwrap();
    out.set_intensity(cloud.intensity().map(<[f32]>::to_vec)).unwrap();
    out.set_labels(cloud.labels().map(<[u32]>::to_vec)).unwrap();
    out.set_rings(cloud.rings().map(<[u16]>::to_vec)).unwrap();
    for field in cloud.extra_fields() {
        out.push_extra_field(field.clone()).unwrap();
    }
    out.set_grid(cloud.grid().cloned()).unwrap();
    out
}

fn check_round_trip(cloud: &PointCloud, encoding: PlyEncoding, precision: Precision) {
    let bytes = write(cloud, encoding, precision);
    let mut back = read(&bytes).unwrap_or_else(|e| panic!("{encoding:?} {precision:?}: {e}"));
    match (cloud.sensor_pose(), back.sensor_pose()) {
        (None, None) => {}
        (Some(a), Some(b)) => {
            let (a, b) = (a.world_from_sensor, b.world_from_sensor);
            assert!((a.translation.vector - b.translation.vector).norm() < 1e-12);
            assert!(a.rotation.angle_to(&b.rotation) < 1e-9);
        }
        (a, b) => panic!("pose {a:?} came back as {b:?}"),
    }
    back.set_sensor_pose(None);
    assert_eq!(back, expected(cloud, precision), "{encoding:?} {precision:?}");
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
        for header in [
            "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 2\nproperty list uchar int v\nend_header\n",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 2\nproperty list uchar int v\nend_header\n",
            "ply\nformat ascii 1.0\n",
        ] {
            let mut file = header.as_bytes().to_vec();
            file.extend_from_slice(&bytes);
            let _ = read(&file);
        }
    }

    #[test]
    fn damaged_files_never_panic(
        big_endian in any::<bool>(),
        damage in vec((any::<prop::sample::Index>(), any::<u8>()), 1..8),
    ) {
        let mut bytes = binary_file(big_endian);
        for (at, value) in damage {
            let i = at.index(bytes.len());
            bytes[i] = value;
        }
        let _ = read(&bytes);
    }
}

#[test]
fn meshes_are_written_as_binary_ply_with_faces() {
    use pointcloud::PolygonMesh;
    let vertices = vec![
        pointcloud::Point3::new(0.0, 0.0, 0.0),
        pointcloud::Point3::new(1.0, 0.0, 0.0),
        pointcloud::Point3::new(1.0, 1.0, 0.5),
        pointcloud::Point3::new(0.0, 1.0, -0.25),
    ];
    let mesh = PolygonMesh::new(vertices.clone(), vec![vec![0, 1, 2], vec![0, 2, 3]]).unwrap();
    let mut bytes = Vec::new();
    pointcloud::io::ply::write_ply_mesh(&mut bytes, &mesh).unwrap();
    let header_end = bytes.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let header = std::str::from_utf8(&bytes[..header_end]).unwrap();
    assert!(header.contains("element vertex 4\n") && header.contains("element face 2\n"));
    assert!(header.contains("property list uchar uint vertex_indices\n"));
    // 4 vertices of 3 doubles, then 2 faces of 1 count byte and 3 indices.
    assert_eq!(bytes.len() - header_end, 4 * 24 + 2 * (1 + 12));
    let face = &bytes[header_end + 96..header_end + 96 + 13];
    assert_eq!(face[0], 3);
    assert_eq!(u32::from_le_bytes(face[9..13].try_into().unwrap()), 2);
    // Our reader takes the vertices as a cloud (faces are skipped).
    let cloud = pointcloud::io::ply::read_ply(
        std::io::Cursor::new(&bytes),
        &pointcloud::io::ReadOptions::STRICT,
    )
    .unwrap();
    assert_eq!(cloud.positions(), &vertices[..]);
    // write_mesh picks the format by extension.
    let dir = tempfile::tempdir().unwrap();
    for name in ["m.ply", "m.obj"] {
        let path = dir.path().join(name);
        pointcloud::io::write_mesh(&path, &mesh).unwrap();
        let text = std::fs::read(&path).unwrap();
        assert_eq!(text.starts_with(b"ply\n"), name.ends_with(".ply"));
    }
}
