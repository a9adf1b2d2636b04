//! OBJ reader and writer: hand-written files, malformed input, round trips.

use pointcloud::io::obj::{read_obj, write_obj};
use pointcloud::io::{ErrorKind, Position};
use pointcloud::{Point3, PolygonMesh};
use proptest::prelude::*;

fn read(text: &str) -> Result<PolygonMesh, pointcloud::io::Error> {
    read_obj(text.as_bytes())
}

fn err_line(text: &str) -> u64 {
    match read(text) {
        Ok(m) => panic!("expected an error, got {m:?}"),
        Err(e) => match e.position {
            Some(Position::Line(l)) => l,
            other => panic!("expected a line position, got {other:?} ({e})"),
        },
    }
}

#[test]
fn reads_vertices_faces_and_ignores_the_rest() {
    let text = "# a comment\r\n\
                mtllib x.mtl\n\
                o thing\n\
                v 0 0 0\n\
                v 1 0 0 1.0\n\
                v 1 1 0 0.5 0.5 0.5\n\
                v 0 1 0 # trailing comment\n\
                vn 0 0 1\n\
                vt 0 0\n\
                \n\
                g group\n\
                usemtl m\n\
                s off\n\
                f 1/1/1 2/2/1 3/3/1 4/4/1\r\n\
                f 1//1 2//1 3//1\n\
                f -4 -3 -1\n\
                l 1 2\n";
    let m = read(text).unwrap();
    assert_eq!(m.num_vertices(), 4);
    assert_eq!(m.vertices()[2], Point3::new(1.0, 1.0, 0.0));
    assert_eq!(m.num_faces(), 3);
    assert_eq!(m.face(0), Some(&[0, 1, 2, 3][..]));
    assert_eq!(m.face(1), Some(&[0, 1, 2][..]));
    assert_eq!(m.face(2), Some(&[0, 1, 3][..]));
    assert_eq!(m.num_triangles(), 4);
    let t = m.triangulated();
    assert_eq!(t.num_faces(), 4);
    assert_eq!(t.face(1), Some(&[0, 2, 3][..]));
}

#[test]
fn negative_indices_count_from_the_vertices_read_so_far() {
    let m = read("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 5 5 5\nf -1 -2 -3\n").unwrap();
    assert_eq!(m.face(0), Some(&[0, 1, 2][..]));
    assert_eq!(m.face(1), Some(&[3, 2, 1][..]));
}

#[test]
fn forward_references_are_resolved_at_the_end() {
    let m = read("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n").unwrap();
    assert_eq!(m.face(0), Some(&[0, 1, 2][..]));
}

#[test]
fn malformed_files_name_the_line() {
    assert_eq!(err_line("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n"), 4);
    assert_eq!(err_line("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n"), 4);
    assert_eq!(err_line("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 4\n"), 5);
    assert_eq!(err_line("v 0 0 0\nv 1 0 0\nf 1 2 -3\n"), 3);
    assert_eq!(err_line("v 0 0\n"), 1);
    assert_eq!(err_line("v 0 zero 0\n"), 1);
    assert_eq!(err_line("v 0 0 0\nv 0 0 nan\n"), 2);
    assert_eq!(err_line("v 0 0 0\nv inf 0 0\n"), 2);
    assert_eq!(err_line("v 0 0 0\nf a b c\n"), 2);
    assert_eq!(err_line("v 0 0 0\nf 1 1 99999999999999999999\n"), 2);
    assert!(read("# ok\n\u{0}\u{ff}\nv 0 0 0\n").is_ok(), "unknown records are ignored");
    let mut bytes = b"v 0 0 0\n".to_vec();
    bytes.extend_from_slice(&[b'v', b' ', 0xff, 0xfe, b'\n']);
    let e = read_obj(&bytes[..]).unwrap_err();
    assert_eq!(e.position, Some(Position::Line(2)));
    assert!(matches!(e.kind, ErrorKind::BadValue(_)));
}

#[test]
fn writes_one_based_polygons() {
    let m = PolygonMesh::new(
        vec![Point3::new(0.0, 0.0, 0.0), Point3::new(1.5, 0.0, 0.0), Point3::new(0.0, -2.0, 1e-9)],
        vec![vec![0, 1, 2]],
    )
    .unwrap();
    let mut out = Vec::new();
    write_obj(&mut out, &m).unwrap();
    assert_eq!(String::from_utf8(out).unwrap(), "v 0 0 0\nv 1.5 0 0\nv 0 -2 1e-9\nf 1 2 3\n");
}

fn finite() -> impl Strategy<Value = f64> {
    prop_oneof![
        -1e3..1e3f64,
        any::<f64>().prop_filter("finite", |v| v.is_finite()),
        Just(0.0),
        Just(-0.0),
    ]
}

fn mesh() -> impl Strategy<Value = PolygonMesh> {
    prop::collection::vec((finite(), finite(), finite()), 1..30).prop_flat_map(|v| {
        let n = v.len() as u32;
        let faces = prop::collection::vec(prop::collection::vec(0..n, 3..7), 0..20);
        (Just(v), faces).prop_map(|(v, faces)| {
            let v = v.into_iter().map(|(x, y, z)| Point3::new(x, y, z)).collect();
            PolygonMesh::new(v, faces).unwrap()
        })
    })
}

proptest! {
    #[test]
    fn round_trip_is_exact(m in mesh()) {
        let mut out = Vec::new();
        write_obj(&mut out, &m).unwrap();
        let back = read_obj(&out[..]).unwrap();
        prop_assert_eq!(back.num_faces(), m.num_faces());
        for (a, b) in back.vertices().iter().zip(m.vertices()) {
            for k in 0..3 {
                prop_assert_eq!(a[k].to_bits(), b[k].to_bits());
            }
        }
        prop_assert_eq!(back, m.clone());
        let t = m.triangulated();
        prop_assert_eq!(t.num_faces(), m.num_triangles());
        prop_assert!(t.is_triangle_mesh());
    }

    #[test]
    fn garbage_never_panics(bytes in prop::collection::vec(any::<u8>(), 0..300)) {
        let _ = read_obj(&bytes[..]);
    }

    #[test]
    fn token_soup_never_panics(
        tokens in prop::collection::vec(
            prop_oneof![
                Just("v"), Just("f"), Just("vn"), Just("1"), Just("-1"), Just("0"), Just("2/3"),
                Just("/"), Just("-9999999999999"), Just("1e999"), Just("nan"), Just("\n"),
                Just("#"), Just("3//4"), Just("4294967296"),
            ],
            0..60,
        )
    ) {
        let text = tokens.join(" ");
        if let Err(e) = read_obj(text.as_bytes()) {
            prop_assert!(e.position.is_some() || matches!(e.kind, ErrorKind::BadValue(_)));
        }
    }
}

#[test]
fn every_prefix_reads_or_fails_with_a_line() {
    let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1/1 2/2 3/3 4/4\nf -4 -3 -2\n";
    for len in 0..=text.len() {
        match read(&text[..len]) {
            Ok(m) => assert!(m.num_faces() <= 2),
            Err(e) => assert!(matches!(e.position, Some(Position::Line(_))), "{len}: {e}"),
        }
    }
}
