//! `sensor_msgs/PointCloud2` layouts: hand-made messages, hostile headers, random round trips.

use pointcloud::io::Precision;
use pointcloud::io::pointcloud2::{Pc2Error, Pc2Layout, PointCloud2, PointField, decode, encode};
use pointcloud::{FieldData, Point3, PointCloud, ScalarField};
use proptest::prelude::*;

fn field(name: &str, offset: u32, datatype: u8) -> PointField {
    PointField { name: name.into(), offset, datatype, count: 1 }
}

/// A driver-style layout: x y z float32, 4 bytes padding, intensity float32, ring uint16,
/// 2 bytes padding, time float32 (32 bytes per point).
fn velodyne_like(points: &[([f32; 3], f32, u16, f32)]) -> PointCloud2 {
    let mut data = Vec::new();
    for (p, i, r, t) in points {
        for v in p {
            data.extend(v.to_le_bytes());
        }
        data.extend([0u8; 4]);
        data.extend(i.to_le_bytes());
        data.extend(r.to_le_bytes());
        data.extend([0u8; 2]);
        data.extend(t.to_le_bytes());
        data.extend([0u8; 4]);
    }
    PointCloud2 {
        height: 1,
        width: points.len() as u32,
        fields: vec![
            field("x", 0, 7),
            field("y", 4, 7),
            field("z", 8, 7),
            field("intensity", 16, 7),
            field("ring", 20, 4),
            field("time", 24, 7),
        ],
        is_bigendian: false,
        point_step: 32,
        row_step: 32 * points.len() as u32,
        data,
        is_dense: false,
    }
}

#[test]
fn padded_driver_layout_with_intensity_ring_and_time() {
    let msg = velodyne_like(&[
        ([1.0, 2.0, 3.0], 10.0, 5, 0.01),
        ([f32::NAN, 0.0, 0.0], 0.0, 0, 0.0),
        ([-1.5, 0.5, 0.25], 20.0, 7, 0.02),
    ]);
    let c = decode(&msg).unwrap();
    assert_eq!(c.len(), 2, "the NaN point of an unorganised cloud is dropped");
    assert!(c.grid().is_none());
    assert_eq!(c.positions()[1], Point3::new(-1.5, 0.5, 0.25));
    assert_eq!(c.intensity(), Some(&[10.0f32, 20.0][..]));
    assert_eq!(c.rings(), Some(&[5u16, 7][..]));
    assert_eq!(c.extra_field("time").unwrap().data, FieldData::F32(vec![0.01, 0.02]));
}

#[test]
fn big_endian_float64_positions() {
    let mut data = Vec::new();
    for v in [1.0f64, -2.0, 0.125] {
        data.extend(v.to_be_bytes());
    }
    data.extend(300u16.to_be_bytes());
    let msg = PointCloud2 {
        height: 1,
        width: 1,
        fields: vec![field("z", 16, 8), field("x", 0, 8), field("y", 8, 8), field("ring", 24, 4)],
        is_bigendian: true,
        point_step: 26,
        row_step: 26,
        data,
        is_dense: true,
    };
    let c = decode(&msg).unwrap();
    assert_eq!(c.positions(), &[Point3::new(1.0, -2.0, 0.125)]);
    assert_eq!(c.rings(), Some(&[300u16][..]));
}

#[test]
fn organised_cloud_stays_organised_with_nan_pixels_invalid() {
    let pixels = vec![
        Some(Point3::new(1.0, 0.0, 0.0)),
        None,
        Some(Point3::new(0.0, 1.0, 0.0)),
        Some(Point3::new(0.0, 0.0, 1.0)),
        None,
        Some(Point3::new(2.0, 0.0, 0.0)),
    ];
    let c = PointCloud::from_pixels(3, 2, pixels).unwrap();
    let msg = encode(&c, &Pc2Layout::default()).unwrap();
    assert_eq!((msg.width, msg.height, msg.is_dense), (3, 2, false));
    let d = decode(&msg).unwrap();
    let g = d.grid().unwrap();
    assert_eq!((g.width(), g.height(), g.num_valid()), (3, 2, 4));
    assert_eq!(g.point_index(1, 0), None);
    assert_eq!(g.point_index(1, 1), None);
    assert_eq!(d, c);
}

#[test]
fn dense_claim_with_a_nan_point_is_an_error() {
    let mut msg =
        velodyne_like(&[([1.0, 2.0, 3.0], 1.0, 0, 0.0), ([0.0, f32::NAN, 0.0], 1.0, 0, 0.0)]);
    msg.is_dense = true;
    assert_eq!(decode(&msg).unwrap_err(), Pc2Error::NotDense { point: 1, row: 0, col: 1 });
}

#[test]
fn a_billion_point_header_over_a_few_bytes_is_an_error_not_an_allocation() {
    let mut msg = velodyne_like(&[([1.0, 2.0, 3.0], 1.0, 0, 0.0)]);
    msg.width = 100_000;
    msg.height = 10_000;
    msg.row_step = 32 * 100_000;
    assert!(matches!(
        decode(&msg).unwrap_err(),
        Pc2Error::DataLength { expected: 32_000_000_000, found: 32, .. }
    ));
    msg.width = 1_000_000_000;
    msg.height = 1;
    msg.row_step = 32;
    assert!(matches!(decode(&msg).unwrap_err(), Pc2Error::RowStep { .. }));
}

#[test]
fn inconsistent_steps_and_lengths_are_errors() {
    let good = velodyne_like(&[([1.0, 2.0, 3.0], 1.0, 0, 0.0); 2]);
    let mut msg = good.clone();
    msg.data.pop();
    assert!(matches!(
        decode(&msg).unwrap_err(),
        Pc2Error::DataLength { expected: 64, found: 63, .. }
    ));
    let mut msg = good.clone();
    msg.point_step = 16;
    assert_eq!(
        decode(&msg).unwrap_err(),
        Pc2Error::FieldOutsidePoint {
            field: "intensity".into(),
            offset: 16,
            bytes: 4,
            point_step: 16
        }
    );
    let mut msg = good.clone();
    msg.row_step = 40;
    assert!(matches!(decode(&msg).unwrap_err(), Pc2Error::RowStep { row_step: 40, .. }));
    let mut msg = good.clone();
    msg.point_step = 0;
    msg.row_step = 0;
    assert!(matches!(decode(&msg).unwrap_err(), Pc2Error::FieldOutsidePoint { .. }));
}

#[test]
fn bad_fields_are_named() {
    let good = velodyne_like(&[([1.0, 2.0, 3.0], 1.0, 0, 0.0)]);
    let mut msg = good.clone();
    msg.fields[3].datatype = 9;
    assert_eq!(
        decode(&msg).unwrap_err(),
        Pc2Error::UnknownDatatype { field: "intensity".into(), datatype: 9 }
    );
    let mut msg = good.clone();
    msg.fields.remove(2);
    assert_eq!(decode(&msg).unwrap_err(), Pc2Error::MissingField { field: "z".into() });
    let mut msg = good.clone();
    msg.fields[1].datatype = 6;
    assert_eq!(
        decode(&msg).unwrap_err(),
        Pc2Error::WrongDatatype { field: "y".into(), datatype: 6 }
    );
    let mut msg = good.clone();
    msg.fields[4].name = "x".into();
    assert_eq!(decode(&msg).unwrap_err(), Pc2Error::DuplicateField { field: "x".into() });
    let mut msg = good;
    msg.fields[3].count = u32::MAX;
    assert!(matches!(decode(&msg).unwrap_err(), Pc2Error::FieldOutsidePoint { .. }));
}

#[test]
fn counted_fields_and_unconvertible_rings_become_extra_fields() {
    let mut msg = velodyne_like(&[([1.0, 2.0, 3.0], 1.0, 0, 0.0)]);
    msg.fields[5].count = 2; // time_0, time_1 (bytes 24..32)
    msg.fields[4].datatype = 7; // a float ring stays an extra field
    msg.data[20..24].copy_from_slice(&2.5f32.to_le_bytes());
    let c = decode(&msg).unwrap();
    assert!(c.rings().is_none());
    assert_eq!(c.extra_field("ring").unwrap().data, FieldData::F32(vec![2.5]));
    assert!(c.extra_field("time_0").is_some() && c.extra_field("time_1").is_some());
}

#[test]
fn garbage_never_panics() {
    let mut runner = proptest::test_runner::TestRunner::deterministic();
    runner
        .run(
            &(
                prop::collection::vec(any::<u8>(), 0..200),
                prop::collection::vec((0u32..40, 0u8..10, 0u32..4), 0..6),
                0u32..50,
                0u32..5,
                0u32..200,
                0u32..4,
                any::<bool>(),
            ),
            |(data, fields, point_step, width, row_step, height, big)| {
                let names = ["x", "y", "z", "intensity", "ring", "t"];
                let fields = fields
                    .iter()
                    .enumerate()
                    .map(|(k, &(offset, datatype, count))| PointField {
                        name: names[k].into(),
                        offset,
                        datatype,
                        count,
                    })
                    .collect();
                let msg = PointCloud2 {
                    height,
                    width,
                    fields,
                    is_bigendian: big,
                    point_step,
                    row_step,
                    data,
                    is_dense: false,
                };
                let _ = decode(&msg);
                Ok(())
            },
        )
        .unwrap();
}

fn f32_exact() -> impl Strategy<Value = f64> {
    (-1000.0f32..1000.0).prop_map(|v| v as f64)
}

fn point() -> impl Strategy<Value = Point3> {
    (f32_exact(), f32_exact(), f32_exact()).prop_map(|(x, y, z)| Point3::new(x, y, z))
}

/// A random cloud: organised (with invalid pixels, more than one row) or not, with some of intensity, rings,
/// labels, normals and a time field of either float width.
fn cloud() -> impl Strategy<Value = PointCloud> {
    (1u32..6, 1u32..5, any::<bool>())
        .prop_flat_map(|(w, h, organised)| {
            let n = (w * h) as usize;
            (
                Just((w, h, organised)),
                prop::collection::vec(prop::option::weighted(0.8, point()), n),
                prop::collection::vec((any::<u16>(), -1e3f32..1e3, any::<u32>(), -1.0f32..1.0), n),
                any::<[bool; 5]>(),
            )
        })
        .prop_map(|((w, h, organised), pixels, attrs, has)| {
            // A single row is unorganised in ROS.
            let mut c = if organised && h > 1 {
                PointCloud::from_pixels(w, h, pixels).unwrap()
            } else {
                PointCloud::from_positions(pixels.into_iter().flatten().collect()).unwrap()
            };
            let attrs = &attrs[..c.len()];
            if has[0] {
                c.set_rings(Some(attrs.iter().map(|a| a.0).collect())).unwrap();
            }
            if has[1] {
                c.set_intensity(Some(attrs.iter().map(|a| a.1).collect())).unwrap();
            }
            if has[2] {
                c.set_labels(Some(attrs.iter().map(|a| a.2).collect())).unwrap();
            }
            if has[3] {
                let n = attrs.iter().map(|a| pointcloud::Vector3::new(a.3 as f64, 0.5, -0.25));
                c.set_normals(Some(n.collect())).unwrap();
            }
            let t: Vec<f64> = (0..c.len()).map(|i| i as f64 * 1e-5).collect();
            let data = if has[4] {
                FieldData::F64(t)
            } else {
                FieldData::F32(t.iter().map(|&v| v as f32).collect())
            };
            c.push_extra_field(ScalarField { name: "t".into(), data }).unwrap();
            c
        })
}

fn layout() -> impl Strategy<Value = Pc2Layout> {
    (any::<bool>(), 0u32..5, 0u32..9, any::<bool>(), any::<bool>()).prop_map(
        |(f64s, padding, row_padding, big_endian, positions_last)| Pc2Layout {
            precision: if f64s { Precision::F64 } else { Precision::F32 },
            padding,
            row_padding,
            big_endian,
            positions_last,
        },
    )
}

proptest! {
    #[test]
    fn random_clouds_round_trip_in_random_layouts(c in cloud(), layout in layout(), shuffle in any::<u64>()) {
        let mut msg = encode(&c, &layout).unwrap();
        // The order of the field list is not the order of the bytes.
        let n = msg.fields.len();
        msg.fields.rotate_left((shuffle % n as u64) as usize);
        let d = decode(&msg).unwrap();
        prop_assert_eq!(d, c);
    }
}
