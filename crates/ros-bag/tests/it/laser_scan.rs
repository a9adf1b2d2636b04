//! `sensor_msgs/LaserScan`: both encodings, beams to points, scans from a bag.

use pointcloud::{Isometry3, Point3};
use ros_bag::msgs::{LASER_SCAN, LaserScan, TF_MESSAGE};
use ros_bag::wire::Encoding;
use ros_bag::{Bag, BagFormat, BagWriter, Header, ScanQuery, TransformStamped, read_scans};
use std::f32::consts::FRAC_PI_2;

fn scan(stamp_ns: i64) -> LaserScan {
    LaserScan {
        header: Header { stamp_ns, frame_id: "laser".into() },
        angle_min: -FRAC_PI_2,
        angle_max: FRAC_PI_2,
        angle_increment: FRAC_PI_2,
        time_increment: 0.001,
        scan_time: 0.1,
        range_min: 0.1,
        range_max: 10.0,
        ranges: vec![2.0, f32::INFINITY, 4.0],
        intensities: vec![5.0, 6.0, 7.0],
    }
}

#[test]
fn laser_scans_round_trip_in_both_encodings() {
    for encoding in [Encoding::Cdr, Encoding::Ros1] {
        let s = scan(12);
        assert_eq!(LaserScan::decode(&s.encode(encoding), encoding).unwrap(), s);
        let bytes = s.encode(encoding);
        let err = LaserScan::decode(&bytes[..bytes.len() - 3], encoding).unwrap_err();
        assert!(err.what.contains("intensities"), "{err}");
    }
}

#[test]
fn beams_become_one_organised_row_with_invalid_pixels() {
    let c = scan(0).to_cloud().unwrap();
    let g = c.grid().unwrap();
    assert_eq!((g.width(), g.height(), c.len()), (3, 1, 2));
    assert_eq!(g.point_index(1, 0), None, "an infinite range has no point");
    let right = c.positions()[0];
    let left = c.positions()[1];
    assert!((right - Point3::new(0.0, -2.0, 0.0)).norm() < 1e-6, "{right}");
    assert!((left - Point3::new(0.0, 4.0, 0.0)).norm() < 1e-6, "{left}");
    assert_eq!(c.intensity(), Some(&[5.0f32, 7.0][..]));
}

#[test]
fn scans_on_a_laser_topic_are_posed_like_clouds() {
    let dir = tempfile::tempdir().unwrap();
    for (format, name) in [(BagFormat::Mcap, "s.mcap"), (BagFormat::Ros1, "s.bag")] {
        let mut w = BagWriter::new(format).unwrap();
        let tf = w.add_topic("/tf", TF_MESSAGE).unwrap();
        let topic = w.add_topic("/scan", LASER_SCAN).unwrap();
        for k in 0..2i64 {
            let m = Isometry3::translation(k as f64, 0.0, 0.0);
            let t = TransformStamped {
                header: Header { stamp_ns: k * 10, frame_id: "odom".into() },
                child_frame_id: "laser".into(),
                parent_from_child: m,
            };
            w.write_tf(tf, (k * 10) as u64, &[t]).unwrap();
            let data = scan(k * 10).encode(w.encoding());
            w.write(topic, (k * 10) as u64, &data).unwrap();
        }
        let path = dir.path().join(name);
        w.save(&path).unwrap();
        let found = read_scans(&Bag::open(&path).unwrap(), &ScanQuery::all("/scan")).unwrap();
        assert_eq!(found.counts, (2, 2, 2));
        let pose = found.scans[1].cloud.sensor_pose().unwrap().world_from_sensor;
        assert_eq!(pose, Isometry3::translation(1.0, 0.0, 0.0));
        assert_eq!(found.scans[1].cloud.grid().unwrap().width(), 3);
    }
}
