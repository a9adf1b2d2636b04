//! 3DTK uos reader and writer: frame conversion, header lines, filters, poses, round trips.

use pointcloud::io::uos::{
    UosReadOptions, pose_from_uos, pose_to_uos, read_uos_pose, read_uos_scan, write_uos_pose,
    write_uos_scan,
};
use pointcloud::io::{ErrorKind, Position, ReadOptions};
use pointcloud::{Point3, PointCloud, SensorPose, Vector3};
use proptest::prelude::*;

fn read(text: &str) -> Result<PointCloud, pointcloud::io::Error> {
    read_uos_scan(text.as_bytes(), &UosReadOptions::default())
}

fn err_line(text: &str) -> u64 {
    match read(text).unwrap_err().position {
        Some(Position::Line(l)) => l,
        other => panic!("expected a line position, got {other:?}"),
    }
}

#[test]
fn converts_centimetres_left_handed_to_metres_right_handed() {
    // 3DTK: x right, y up, z forward. 300 cm forward, 100 cm right, 200 cm up.
    let c = read("100 200 300\n").unwrap();
    assert_eq!(c.positions(), &[Point3::new(3.0, -1.0, 2.0)]);
    assert!(c.intensity().is_none());
}

#[test]
fn header_extra_columns_and_comments() {
    let c = read("2 x 1\n100 0 0 7\n# comment\n\n0 100 0 9\r\n").unwrap();
    assert_eq!(c.len(), 2);
    assert_eq!(c.intensity(), Some(&[7.0f32, 9.0][..]));
    let c = read("0 0 100 1 2 3\n0 0 200 4 5 6\n").unwrap();
    assert_eq!(c.intensity(), Some(&[1.0f32, 4.0][..]));
    // Only the first data line may be a header.
    assert_eq!(err_line("1 2 3\n2 x 1\n"), 2);
}

#[test]
fn malformed_scans_name_the_line() {
    assert_eq!(err_line("1 2\n"), 1);
    assert_eq!(err_line("1 2 3\n1 2 3 4\n"), 2);
    assert_eq!(err_line("1 2 3\n1 b 3\n"), 2);
    assert_eq!(err_line("1 2 3 4 5\n1 2 3 4 x\n"), 2);
    assert_eq!(err_line("1 2 3\nnan 2 3\n"), 2);
    let o = UosReadOptions { non_finite: ReadOptions::SKIP_NON_FINITE, ..Default::default() };
    let c = read_uos_scan("1 2 3\nnan 2 3\n4 5 inf\n".as_bytes(), &o).unwrap();
    assert_eq!(c.len(), 1);
}

#[test]
fn range_filters_drop_junk_and_no_echo() {
    let text = "0 0 10\n0 0 20\n0 0 1000\n0 0 3276\n0 0 3300\n";
    assert_eq!(read(text).unwrap().len(), 5);
    let c = read_uos_scan(text.as_bytes(), &UosReadOptions::KURT3D).unwrap();
    let xs: Vec<f64> = c.positions().iter().map(|p| p.x).collect();
    assert_eq!(xs, [0.2, 10.0]);
    let nan = UosReadOptions { min_range_m: Some(f64::NAN), ..Default::default() };
    assert!(read_uos_scan(text.as_bytes(), &nan).is_err());
}

#[test]
fn reads_poses() {
    let p = read_uos_pose("0 0 0\n-0 0 -0\n\n".as_bytes()).unwrap();
    assert!(
        (p.world_from_sensor.to_homogeneous()
            - SensorPose::identity().world_from_sensor.to_homogeneous())
        .norm()
            < 1e-15
    );
    // 3DTK: 200 cm forward, turned by θy = 90° about its up axis (y), which is a turn of −90°
    // about our z axis.
    let p = read_uos_pose("0 0 200\n0 90 0\n".as_bytes()).unwrap();
    assert!((p.origin() - Point3::new(2.0, 0.0, 0.0)).norm() < 1e-12);
    let fwd = p.world_from_sensor.rotation * Vector3::x();
    assert!((fwd - Vector3::new(0.0, -1.0, 0.0)).norm() < 1e-12, "{fwd}");
    // θx (about 3DTK's x = our −y) by 90° tilts forward into 3DTK's −y = our −z... check it:
    // Rx(90°) takes 3DTK z (forward) to −y (down), i.e. our x to −z.
    let p = read_uos_pose("0 0 0 90 0 0".as_bytes()).unwrap();
    let fwd = p.world_from_sensor.rotation * Vector3::x();
    assert!((fwd - Vector3::new(0.0, 0.0, -1.0)).norm() < 1e-12, "{fwd}");
}

#[test]
fn malformed_poses_are_errors() {
    let e = read_uos_pose("0 0 0\n0 0\n".as_bytes()).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::UnexpectedEof { .. }));
    assert_eq!(e.position, Some(Position::Line(2)));
    let e = read_uos_pose("0 0 0\n0 0 0\n1\n".as_bytes()).unwrap_err();
    assert_eq!(e.position, Some(Position::Line(3)));
    let e = read_uos_pose("0 0 0\n0 x 0\n".as_bytes()).unwrap_err();
    assert_eq!(e.position, Some(Position::Line(2)));
    assert!(read_uos_pose("0 0 0\n0 nan 0\n".as_bytes()).is_err());
    assert!(read_uos_pose("".as_bytes()).is_err());
}

fn coord() -> impl Strategy<Value = f64> {
    prop_oneof![-1e4..1e4f64, -1.0..1.0f64]
}

fn angle() -> impl Strategy<Value = f64> {
    -179.0..179.0f64
}

proptest! {
    #[test]
    fn scan_round_trip(
        pts in prop::collection::vec((coord(), coord(), coord(), any::<f32>()), 0..40),
        with_i in any::<bool>(),
    ) {
        let mut c = PointCloud::from_positions(
            pts.iter().map(|p| Point3::new(p.0, p.1, p.2)).collect(),
        ).unwrap();
        if with_i && !pts.is_empty() {
            c.set_intensity(Some(pts.iter().map(|p| p.3).collect())).unwrap();
        }
        let mut out = Vec::new();
        write_uos_scan(&mut out, &c).unwrap();
        let back = read_uos_scan(&out[..], &UosReadOptions::default()).unwrap();
        prop_assert_eq!(back.len(), c.len());
        for (a, b) in back.positions().iter().zip(c.positions()) {
            prop_assert!((a - b).norm() <= 1e-14 * (1.0 + b.coords.norm()), "{} vs {}", a, b);
        }
        match (back.intensity(), c.intensity()) {
            (Some(a), Some(b)) => prop_assert!(
                a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()))
            ),
            (None, None) => {}
            other => prop_assert!(false, "intensity mismatch {:?}", other),
        }
    }

    #[test]
    fn pose_round_trip(
        t in (coord(), coord(), coord()), a in (angle(), -89.0..89.0f64, angle()),
    ) {
        let pose = pose_from_uos([t.0, t.1, t.2], [a.0, a.1, a.2]);
        let (t2, a2) = pose_to_uos(&pose);
        for (x, y) in [t.0, t.1, t.2].iter().zip(t2) {
            prop_assert!((x - y).abs() < 1e-9 * (1.0 + x.abs()));
        }
        for (x, y) in [a.0, a.1, a.2].iter().zip(a2) {
            prop_assert!((x - y).abs() < 1e-7, "{:?} vs {:?}", a, a2);
        }
        let mut out = Vec::new();
        write_uos_pose(&mut out, &pose).unwrap();
        let back = read_uos_pose(&out[..]).unwrap();
        let d = back.world_from_sensor.to_homogeneous() - pose.world_from_sensor.to_homogeneous();
        prop_assert!(d.norm() < 1e-9 * (1.0 + t.0.abs() + t.1.abs() + t.2.abs()));
    }

    #[test]
    fn garbage_never_panics(bytes in prop::collection::vec(any::<u8>(), 0..300)) {
        for o in [UosReadOptions::default(), UosReadOptions::KURT3D] {
            if let Err(e) = read_uos_scan(&bytes[..], &o) {
                prop_assert!(matches!(e.position, Some(Position::Line(_))));
            }
        }
        let _ = read_uos_pose(&bytes[..]);
    }
}

#[test]
fn every_prefix_reads_or_fails_with_a_line() {
    let text = "3 x 1\n100 0 0 7\n0 100 0 8\n0 0 100 9\n";
    for len in 0..=text.len() {
        match read(&text[..len]) {
            Ok(c) => assert!(c.len() <= 3),
            Err(e) => assert!(matches!(e.position, Some(Position::Line(_))), "{len}: {e}"),
        }
    }
    let pose = "-3.1 -7.5 156.9\n1.35 -0.85 -0.56\n";
    for len in 0..=pose.len() {
        if let Err(e) = read_uos_pose(&pose.as_bytes()[..len]) {
            assert!(matches!(e.position, Some(Position::Line(_))), "{len}: {e}");
        }
    }
}
