//! KITTI / Ouster `.bin` reader and writer: layouts, missing returns, truncation, round trips.

use pointcloud::io::kitti::{KittiLayout, KittiReadOptions, read_kitti_bin, write_kitti_bin};
use pointcloud::io::{ErrorKind, Position, ReadOptions};
use pointcloud::{Point3, PointCloud};
use proptest::prelude::*;

fn bin(records: &[[f32; 4]]) -> Vec<u8> {
    records.iter().flatten().flat_map(|v| v.to_le_bytes()).collect()
}

fn raw() -> KittiReadOptions {
    KittiReadOptions { zero_is_invalid: false, ..KittiReadOptions::default() }
}

#[test]
fn reads_unorganised_records() {
    let data = bin(&[[1.0, 2.0, 3.0, 0.5], [0.0, 0.0, 0.0, 0.0], [-4.0, 5.5, 6.0, 1.0]]);
    let c = read_kitti_bin(&data[..], &KittiReadOptions::default()).unwrap();
    assert_eq!(c.len(), 2, "the all-zero record is a missing return");
    assert_eq!(c.positions()[1], Point3::new(-4.0, 5.5, 6.0));
    assert_eq!(c.intensity(), Some(&[0.5f32, 1.0][..]));
    assert!(c.grid().is_none());
    let c = read_kitti_bin(&data[..], &raw()).unwrap();
    assert_eq!(c.len(), 3);
    assert!(read_kitti_bin(&[][..], &raw()).unwrap().is_empty());
}

#[test]
fn reads_column_major_ouster_layout() {
    // 2 rings × 3 columns; record k = column * 2 + ring; x = column, y = ring.
    let mut records = Vec::new();
    for col in 0..3 {
        for ring in 0..2 {
            records.push([col as f32 + 1.0, ring as f32, 1.0, (10 * col + ring) as f32]);
        }
    }
    records[3] = [0.0; 4]; // column 1, ring 1: no return
    records[4] = [f32::NAN, 0.0, 0.0, 0.0]; // column 2, ring 0: invalid
    let c = read_kitti_bin(&bin(&records)[..], &KittiReadOptions::ouster(2)).unwrap();
    let g = c.grid().unwrap();
    assert_eq!((g.width(), g.height()), (3, 2));
    assert_eq!(c.len(), 4);
    assert_eq!(g.point_index(1, 1), None);
    assert_eq!(g.point_index(2, 0), None);
    for (col, row) in [(0, 0), (1, 0), (0, 1), (2, 1)] {
        let p = c.positions()[g.point_index(col, row).unwrap()];
        assert_eq!(p, Point3::new(col as f64 + 1.0, row as f64, 1.0));
        let i = g.point_index(col, row).unwrap();
        assert_eq!(c.rings().unwrap()[i], row as u16);
        assert_eq!(c.intensity().unwrap()[i], (10 * col + row) as f32);
    }
}

#[test]
fn bad_layouts_and_lengths_are_errors() {
    let data = bin(&[[1.0, 2.0, 3.0, 0.5]; 6]);
    let e = read_kitti_bin(&data[..], &KittiReadOptions::ouster(4)).unwrap_err();
    assert_eq!(e.position, Some(Position::Byte(64)));
    assert!(read_kitti_bin(&data[..], &KittiReadOptions::ouster(0)).is_err());
    assert!(read_kitti_bin(&data[..], &KittiReadOptions::ouster(70_000)).is_err());
    let e = read_kitti_bin(&data[..data.len() - 3], &raw()).unwrap_err();
    assert_eq!(e.position, Some(Position::Byte(80)));
    assert!(matches!(e.kind, ErrorKind::UnexpectedEof { .. }));
}

#[test]
fn every_prefix_is_an_error_or_the_whole_records() {
    let records: Vec<[f32; 4]> = (0..5).map(|i| [i as f32 + 1.0, 2.0, 3.0, 0.1]).collect();
    let data = bin(&records);
    for len in 0..=data.len() {
        match read_kitti_bin(&data[..len], &raw()) {
            Ok(c) => {
                assert_eq!(len % 16, 0);
                assert_eq!(c.len(), len / 16);
            }
            Err(e) => {
                assert_ne!(len % 16, 0);
                assert_eq!(e.position, Some(Position::Byte((len - len % 16) as u64)));
            }
        }
    }
}

#[test]
fn non_finite_records_fail_unless_skipped() {
    let data = bin(&[[1.0, 2.0, 3.0, 0.0], [1.0, f32::INFINITY, 3.0, 0.0], [4.0, 5.0, 6.0, 0.0]]);
    let e = read_kitti_bin(&data[..], &raw()).unwrap_err();
    assert_eq!(e.position, Some(Position::Byte(16)));
    assert!(matches!(e.kind, ErrorKind::NonFinite { point: 1 }));
    let options = KittiReadOptions { non_finite: ReadOptions::SKIP_NON_FINITE, ..raw() };
    assert_eq!(read_kitti_bin(&data[..], &options).unwrap().len(), 2);
    // A NaN intensity is kept: only the position must be finite.
    let data = bin(&[[1.0, 2.0, 3.0, f32::NAN]]);
    assert!(read_kitti_bin(&data[..], &raw()).unwrap().intensity().unwrap()[0].is_nan());
}

#[test]
fn writer_refuses_coordinates_beyond_f32() {
    let c = PointCloud::from_positions(vec![Point3::new(1e300, 0.0, 0.0)]).unwrap();
    assert!(write_kitti_bin(Vec::new(), &c).is_err());
}

#[test]
fn writer_defaults_intensity_to_zero() {
    let c = PointCloud::from_positions(vec![Point3::new(1.0, 2.0, 3.0)]).unwrap();
    let mut out = Vec::new();
    write_kitti_bin(&mut out, &c).unwrap();
    assert_eq!(out, bin(&[[1.0, 2.0, 3.0, 0.0]]));
}

fn f32_coord() -> impl Strategy<Value = f64> {
    prop_oneof![
        -100.0f32..100.0,
        Just(0.0f32),
        any::<f32>().prop_filter("finite", |v| v.is_finite())
    ]
    .prop_map(|v| v as f64)
}

proptest! {
    #[test]
    fn unorganised_round_trip_is_exact(
        pts in prop::collection::vec((f32_coord(), f32_coord(), f32_coord(), any::<f32>()), 0..40)
    ) {
        let pts: Vec<_> = pts.into_iter().filter(|p| (p.0, p.1, p.2) != (0.0, 0.0, 0.0)).collect();
        let mut c = PointCloud::from_positions(
            pts.iter().map(|p| Point3::new(p.0, p.1, p.2)).collect(),
        ).unwrap();
        c.set_intensity(Some(pts.iter().map(|p| p.3).collect())).unwrap();
        let mut out = Vec::new();
        write_kitti_bin(&mut out, &c).unwrap();
        prop_assert_eq!(out.len(), 16 * c.len());
        let back = read_kitti_bin(&out[..], &KittiReadOptions::default()).unwrap();
        prop_assert_eq!(back.positions(), c.positions());
        let (a, b) = (back.intensity().unwrap(), c.intensity().unwrap());
        prop_assert!(a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()));
    }

    #[test]
    fn organised_round_trip_keeps_the_grid(
        w in 1u32..8, h in 1u32..6, seed in prop::collection::vec((any::<bool>(), -50.0f32..50.0), 48)
    ) {
        let pixels = (0..w * h).map(|k| {
            let (valid, v) = seed[k as usize];
            valid.then(|| Point3::new(v as f64, k as f64 + 1.0, -(v as f64)))
        });
        let c = PointCloud::from_pixels(w, h, pixels).unwrap();
        let mut out = Vec::new();
        write_kitti_bin(&mut out, &c).unwrap();
        prop_assert_eq!(out.len(), 16 * (w * h) as usize);
        let back = read_kitti_bin(&out[..], &KittiReadOptions::ouster(h)).unwrap();
        let (g, gb) = (c.grid().unwrap(), back.grid().unwrap());
        prop_assert_eq!((gb.width(), gb.height()), (w, h));
        for row in 0..h {
            for col in 0..w {
                let a = g.point_index(col, row).map(|i| c.positions()[i]);
                let b = gb.point_index(col, row).map(|i| back.positions()[i]);
                prop_assert_eq!(a, b);
            }
        }
    }

    #[test]
    fn garbage_never_panics(bytes in prop::collection::vec(any::<u8>(), 0..200), rings in 0u32..5) {
        for layout in [KittiLayout::Unorganized, KittiLayout::ColumnMajor { rings }] {
            for zero_is_invalid in [false, true] {
                let o = KittiReadOptions { layout, zero_is_invalid, non_finite: ReadOptions::STRICT };
                let _ = read_kitti_bin(&bytes[..], &o);
            }
        }
    }
}
