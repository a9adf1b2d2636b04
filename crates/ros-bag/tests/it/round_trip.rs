//! Bags written by our code read back: clouds, transforms, info; MCAP, rosbag2 folders, ROS 1.

use crate::fixture::{self, Scan};
use pointcloud::PointCloud;
use ros_bag::{Bag, BagFormat, BagInfo};
use std::path::Path;

struct Read {
    organised: Vec<(i64, String, PointCloud)>,
    flat: Vec<PointCloud>,
    tf: Vec<(i64, String, String, pointcloud::Isometry3)>,
    tf_static: Vec<pointcloud::Isometry3>,
}

fn read(path: &Path) -> Read {
    let bag = Bag::open(path).unwrap();
    let mut r =
        Read { organised: Vec::new(), flat: Vec::new(), tf: Vec::new(), tf_static: Vec::new() };
    bag.for_each_message(|m| {
        match m.topic {
            "/points" => {
                let (h, c) = m.cloud()?;
                r.organised.push((h.stamp_ns, h.frame_id, c));
            }
            "/points_flat" => r.flat.push(m.cloud()?.1),
            "/tf" => {
                for t in m.transforms()? {
                    r.tf.push((
                        t.header.stamp_ns,
                        t.header.frame_id,
                        t.child_frame_id,
                        t.parent_from_child,
                    ));
                }
            }
            "/tf_static" => r.tf_static.extend(m.transforms()?.iter().map(|t| t.parent_from_child)),
            other => panic!("unexpected topic {other}"),
        }
        Ok(())
    })
    .unwrap();
    r
}

fn check(r: &Read, scans: &[Scan]) {
    assert_eq!(r.organised.len(), scans.len());
    assert_eq!(r.flat.len(), scans.len());
    assert_eq!(r.tf.len(), 3 * scans.len());
    assert_eq!(r.tf_static.len(), 1);
    for (k, s) in scans.iter().enumerate() {
        let (stamp, parent, child, odom_from_base) = &r.tf[3 * k + 1];
        assert_eq!((*stamp, parent.as_str(), child.as_str()), (s.stamp_ns, "odom", "base_link"));
        let odom_from_sensor = odom_from_base * r.tf_static[0];
        assert!(
            (odom_from_sensor.to_homogeneous() - s.odom_from_sensor.to_homogeneous()).abs().max()
                < 1e-12
        );
    }
    for ((stamp, frame, cloud), (flat, s)) in r.organised.iter().zip(r.flat.iter().zip(scans)) {
        assert_eq!(*stamp, s.stamp_ns);
        assert_eq!(frame, "sensor");
        let g = cloud.grid().expect("organised clouds stay organised");
        assert_eq!(g, s.cloud.grid().unwrap());
        assert!(g.num_valid() < g.num_pixels(), "the lab scan has invalid pixels");
        assert_eq!(cloud, &fixture::rounded_to_f32(&s.cloud));
        // float64 positions in a padded layout are exact
        let mut unorganised = s.cloud.clone();
        unorganised.set_grid(None).unwrap();
        assert_eq!(flat, &unorganised);
    }
}

#[test]
fn mcap_fixture_round_trips() {
    let scans = fixture::scans(3);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("lab.mcap");
    std::fs::write(&path, fixture::bag(BagFormat::Mcap, &scans)).unwrap();
    check(&read(&path), &scans);
}

#[test]
fn rosbag2_folder_round_trips() {
    let scans = fixture::scans(2);
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("metadata.yaml"), "rosbag2_bagfile_information: {}\n").unwrap();
    std::fs::write(dir.path().join("lab_0.mcap"), fixture::bag(BagFormat::Mcap, &scans)).unwrap();
    let bag = Bag::open(dir.path()).unwrap();
    assert_eq!(bag.format(), BagFormat::Rosbag2Folder);
    check(&read(dir.path()), &scans);
}

#[test]
fn ros1_fixture_round_trips() {
    let scans = fixture::scans(3);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("lab.bag");
    std::fs::write(&path, fixture::bag(BagFormat::Ros1, &scans)).unwrap();
    check(&read(&path), &scans);
}

#[test]
fn info_lists_topics_counts_span_and_frames() {
    let scans = fixture::scans(2);
    let dir = tempfile::tempdir().unwrap();
    for format in [BagFormat::Mcap, BagFormat::Ros1] {
        let path = dir.path().join(if format == BagFormat::Ros1 { "a.bag" } else { "a.mcap" });
        std::fs::write(&path, fixture::bag(format, &scans)).unwrap();
        let info = BagInfo::of(&Bag::open(&path).unwrap()).unwrap();
        let names: Vec<_> = info.topics.iter().map(|t| (t.topic.as_str(), t.count)).collect();
        assert_eq!(names, [("/points", 2), ("/points_flat", 2), ("/tf", 6), ("/tf_static", 1)]);
        assert_eq!(info.topics[0].type_name, "sensor_msgs/PointCloud2");
        assert_eq!(info.topics[2].type_name, "tf2_msgs/TFMessage");
        assert_eq!(info.messages, 11);
        assert_eq!(info.start_ns, scans[0].stamp_ns as u64 - 100_000_000);
        assert_eq!(info.end_ns, scans[1].stamp_ns as u64 + 50_000_000);
        let frames: Vec<_> = info.frames.iter().map(String::as_str).collect();
        assert_eq!(frames, ["base_link", "odom", "sensor"]);
        assert_eq!(info.transforms.len(), 2);
    }
}

#[test]
fn read_scans_poses_each_cloud_by_the_transform_chain() {
    let scans = fixture::scans(3);
    let dir = tempfile::tempdir().unwrap();
    for (format, name) in [(BagFormat::Mcap, "p.mcap"), (BagFormat::Ros1, "p.bag")] {
        let path = dir.path().join(name);
        std::fs::write(&path, fixture::bag(format, &scans)).unwrap();
        let bag = Bag::open(&path).unwrap();
        let found = ros_bag::read_scans(&bag, &ros_bag::ScanQuery::all("/points")).unwrap();
        assert_eq!(found.fixed_frame.as_deref(), Some("odom"));
        assert_eq!(found.counts, (3, 3, 3));
        assert!(found.warnings.is_empty());
        for (got, s) in found.scans.iter().zip(&scans) {
            assert_eq!(got.stamp_ns, s.stamp_ns);
            let pose = got.cloud.sensor_pose().unwrap().world_from_sensor;
            let d = (pose.to_homogeneous() - s.odom_from_sensor.to_homogeneous()).abs().max();
            assert!(d < 1e-12, "{d}");
        }
        let mut query = ros_bag::ScanQuery::all("/points_flat");
        query.fixed_frame = Some("map".into());
        let err = ros_bag::read_scans(&bag, &query).unwrap_err();
        assert!(
            matches!(&err, ros_bag::BagError::Tf { topic, .. } if topic == "/points_flat"),
            "{err}"
        );
    }
}
