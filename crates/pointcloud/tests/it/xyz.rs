//! XYZ reader and writer: hand-written files, malformed input, round trips.

use pointcloud::io::xyz::{read_xyz, write_xyz};
use pointcloud::io::{ErrorKind, Position, ReadOptions};
use pointcloud::{Point3, PointCloud};
use proptest::prelude::*;

fn read(text: &str) -> Result<PointCloud, pointcloud::io::Error> {
    read_xyz(text.as_bytes(), &ReadOptions::STRICT)
}

fn err_line(text: &str, options: &ReadOptions) -> (u64, ErrorKind) {
    let e = read_xyz(text.as_bytes(), options).unwrap_err();
    match e.position {
        Some(Position::Line(l)) => (l, e.kind),
        other => panic!("expected a line position, got {other:?} ({e})"),
    }
}

#[test]
fn reads_whitespace_and_comma_separated_files() {
    let c =
        read("# header\n\n1 2 3\n  4\t5   6  \r\n# more\n7,8 , 9\n-1e3 +2 .5 # comment\n").unwrap();
    assert_eq!(c.len(), 4);
    assert_eq!(c.positions()[1], Point3::new(4.0, 5.0, 6.0));
    assert_eq!(c.positions()[2], Point3::new(7.0, 8.0, 9.0));
    assert_eq!(c.positions()[3], Point3::new(-1000.0, 2.0, 0.5));
    assert!(c.intensity().is_none());

    let c = read("1 2 3 0.5\n4 5 6 7\n").unwrap();
    assert_eq!(c.intensity(), Some(&[0.5f32, 7.0][..]));
    assert!(read("").unwrap().is_empty());
    assert!(read("# only comments\n\n").unwrap().is_empty());
}

#[test]
fn wrong_column_counts_name_the_line() {
    let s = ReadOptions::STRICT;
    assert_eq!(err_line("1 2\n", &s).0, 1);
    assert_eq!(err_line("1 2 3 4 5\n", &s).0, 1);
    assert_eq!(err_line("1 2 3\n\n1 2 3 4\n", &s).0, 3);
    assert_eq!(err_line("1 2 3 4\n1 2 3\n", &s).0, 2);
    assert_eq!(err_line("1,,3\n", &s).0, 1);
    assert_eq!(err_line("1 2 x\n", &s).0, 1);
    assert_eq!(err_line("1 2 3\n1 2 3 # ok\n1 2 3 zz\n", &s).0, 3);
}

#[test]
fn non_finite_points_fail_unless_skipped() {
    let text = "1 2 3\nnan 0 0\n0 inf 0\n0 0 -inf 1\n";
    let (line, kind) = err_line("1 2 3\nnan 0 0\n", &ReadOptions::STRICT);
    assert_eq!(line, 2);
    assert!(matches!(kind, ErrorKind::NonFinite { point: 1 }));
    let (line, _) = err_line(text, &ReadOptions::SKIP_NON_FINITE);
    assert_eq!(line, 4, "the column count still has to match");
    let c = read_xyz("1 2 3\nnan 0 0\n0 inf 0\n4 5 6\n".as_bytes(), &ReadOptions::SKIP_NON_FINITE)
        .unwrap();
    assert_eq!(c.positions(), &[Point3::new(1.0, 2.0, 3.0), Point3::new(4.0, 5.0, 6.0)]);
    // A NaN intensity is a value like any other.
    let c = read("1 2 3 nan\n").unwrap();
    assert!(c.intensity().unwrap()[0].is_nan());
}

#[test]
fn invalid_utf8_names_the_line() {
    let e = read_xyz(&b"1 2 3\n1 2 \xff\n"[..], &ReadOptions::STRICT).unwrap_err();
    assert_eq!(e.position, Some(Position::Line(2)));
}

#[test]
fn writes_intensity_as_a_fourth_column() {
    let mut c = PointCloud::from_positions(vec![Point3::new(1.0, -0.5, 1e-7)]).unwrap();
    let mut out = Vec::new();
    write_xyz(&mut out, &c).unwrap();
    assert_eq!(String::from_utf8(out).unwrap(), "1 -0.5 1e-7\n");
    c.set_intensity(Some(vec![0.25])).unwrap();
    let mut out = Vec::new();
    write_xyz(&mut out, &c).unwrap();
    assert_eq!(String::from_utf8(out).unwrap(), "1 -0.5 1e-7 0.25\n");
}

fn finite() -> impl Strategy<Value = f64> {
    prop_oneof![-1e3..1e3f64, any::<f64>().prop_filter("finite", |v| v.is_finite())]
}

fn cloud() -> impl Strategy<Value = PointCloud> {
    (prop::collection::vec((finite(), finite(), finite(), any::<f32>()), 0..50), any::<bool>())
        .prop_map(|(pts, with_i)| {
            let mut c = PointCloud::from_positions(
                pts.iter().map(|&(x, y, z, _)| Point3::new(x, y, z)).collect(),
            )
            .unwrap();
            if with_i && !pts.is_empty() {
                c.set_intensity(Some(pts.iter().map(|p| p.3).collect())).unwrap();
            }
            c
        })
}

proptest! {
    #[test]
    fn round_trip_is_exact(c in cloud()) {
        let mut out = Vec::new();
        write_xyz(&mut out, &c).unwrap();
        let back = read_xyz(&out[..], &ReadOptions::STRICT).unwrap();
        prop_assert_eq!(back.len(), c.len());
        for (a, b) in back.positions().iter().zip(c.positions()) {
            for k in 0..3 {
                prop_assert_eq!(a[k].to_bits(), b[k].to_bits());
            }
        }
        match (back.intensity(), c.intensity()) {
            (Some(a), Some(b)) => {
                for (x, y) in a.iter().zip(b) {
                    prop_assert!(x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()));
                }
            }
            (None, None) => {}
            other => prop_assert!(false, "intensity mismatch {:?}", other),
        }
    }

    #[test]
    fn garbage_never_panics(bytes in prop::collection::vec(any::<u8>(), 0..300)) {
        for options in [ReadOptions::STRICT, ReadOptions::SKIP_NON_FINITE] {
            if let Err(e) = read_xyz(&bytes[..], &options) {
                prop_assert!(matches!(e.position, Some(Position::Line(_))));
            }
        }
    }
}

#[test]
fn every_prefix_reads_or_fails_with_a_line() {
    let text = "# xyz\n1.5 2 3 0.25\n-4e-3, 5, 6, 1\n\n7 8 9 0\n";
    for len in 0..=text.len() {
        match read_xyz(&text.as_bytes()[..len], &ReadOptions::STRICT) {
            Ok(c) => assert!(c.len() <= 3),
            Err(e) => assert!(matches!(e.position, Some(Position::Line(_))), "{len}: {e}"),
        }
    }
}
