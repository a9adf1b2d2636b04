//! `patchnav info BAG` on bags written by our own code: MCAP, a rosbag2 folder, ROS 1.

use crate::common::*;
use pointcloud::io::pointcloud2::{Pc2Layout, encode};
use pointcloud::{Isometry3, Point3, PointCloud};
use ros_bag::msgs::{POINT_CLOUD2, TF_MESSAGE};
use ros_bag::{BagFormat, BagWriter, Header, TransformStamped};

const T0: i64 = 1_700_000_000_000_000_000;

/// Two clouds of a moving base, `/tf` (odom → base_link) and `/tf_static` (base_link → lidar).
fn bag(format: BagFormat) -> Vec<u8> {
    let tf = |stamp_ns, parent: &str, child: &str, m| TransformStamped {
        header: Header { stamp_ns, frame_id: parent.into() },
        child_frame_id: child.into(),
        parent_from_child: m,
    };
    let cloud =
        PointCloud::from_positions((0..5).map(|i| Point3::new(2.0, i as f64 * 0.1, 0.0)).collect())
            .unwrap();
    let mut w = BagWriter::new(format).unwrap();
    let s = w.add_topic("/tf_static", TF_MESSAGE).unwrap();
    let t = w.add_topic("/tf", TF_MESSAGE).unwrap();
    let p = w.add_topic("/points", POINT_CLOUD2).unwrap();
    w.write_tf(
        s,
        T0 as u64,
        &[tf(T0, "base_link", "lidar", Isometry3::translation(0.0, 0.0, 0.4))],
    )
    .unwrap();
    for k in 0..2 {
        let stamp = T0 + k * 250_000_000;
        let m = Isometry3::translation(k as f64, 0.0, 0.0);
        w.write_tf(t, stamp as u64, &[tf(stamp, "odom", "base_link", m)]).unwrap();
        let header = Header { stamp_ns: stamp, frame_id: "lidar".into() };
        w.write_cloud(p, &header, &encode(&cloud, &Pc2Layout::default()).unwrap()).unwrap();
    }
    w.finish().unwrap()
}

fn check(text: &str, format: &str) {
    assert!(text.contains(&format!("format:     {format}")), "{text}");
    assert!(text.contains("messages:   5"), "{text}");
    assert!(text.contains("time:       1700000000.000 .. 1700000000.250 s (0.250 s)"), "{text}");
    assert!(text.contains("frames:     base_link, lidar, odom"), "{text}");
    assert!(text.contains("transforms: base_link -> lidar, odom -> base_link"), "{text}");
    let points = text.lines().find(|l| l.trim_start().starts_with("/points")).unwrap();
    assert!(points.contains("sensor_msgs/PointCloud2"), "{points}");
    assert!(points.contains("2 msgs"), "{points}");
    assert!(points.ends_with("frames lidar"), "{points}");
}

#[test]
fn info_lists_topics_types_counts_span_and_frames_of_every_bag_kind() {
    let dir = tempfile::tempdir().unwrap();
    let mcap = dir.path().join("run.mcap");
    std::fs::write(&mcap, bag(BagFormat::Mcap)).unwrap();
    let folder = dir.path().join("run");
    std::fs::create_dir(&folder).unwrap();
    std::fs::write(folder.join("metadata.yaml"), "rosbag2_bagfile_information: {}\n").unwrap();
    std::fs::write(folder.join("run_0.mcap"), bag(BagFormat::Mcap)).unwrap();
    let ros1 = dir.path().join("run.bag");
    std::fs::write(&ros1, bag(BagFormat::Ros1)).unwrap();
    for (path, format) in
        [(&mcap, "MCAP"), (&folder, "rosbag2 folder (MCAP)"), (&ros1, "ROS 1 bag")]
    {
        let o = patchnav(&["info", path.to_str().unwrap()]);
        assert!(o.status.success(), "{}", stderr(&o));
        check(&stdout(&o), format);
    }
}

#[test]
fn info_on_a_broken_bag_is_one_line_with_the_position() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = bag(BagFormat::Mcap);
    let cut = dir.path().join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    assert_one_line_error(&patchnav(&["info", cut.to_str().unwrap()]), "cut.mcap, byte ");
    let db3 = dir.path().join("old");
    std::fs::create_dir(&db3).unwrap();
    std::fs::write(db3.join("old_0.db3"), b"SQLite format 3\0").unwrap();
    assert_one_line_error(&patchnav(&["info", db3.to_str().unwrap()]), "ros2 bag convert");
}
