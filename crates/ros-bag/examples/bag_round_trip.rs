//! Writes a tiny ROS 2 MCAP bag and a ROS 1 bag (a moving sensor's organised cloud on
//! `/points`, `/tf` and `/tf_static`) into a temporary directory, then reads each back: the
//! topics, counts, time span and frames, and the first cloud with its grid.
//!
//! ```sh
//! cargo run -p patchnav-ros-bag --example bag_round_trip
//! ```

use pointcloud::io::pointcloud2::{Pc2Layout, encode};
use pointcloud::{Isometry3, Point3, PointCloud};
use ros_bag::msgs::{POINT_CLOUD2, TF_MESSAGE};
use ros_bag::{Bag, BagFormat, BagInfo, BagWriter, Header, TransformStamped};

fn tf(stamp_ns: i64, parent: &str, child: &str, parent_from_child: Isometry3) -> TransformStamped {
    let header = Header { stamp_ns, frame_id: parent.into() };
    TransformStamped { header, child_frame_id: child.into(), parent_from_child }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // A 4 × 3 image of a wall 2 m ahead, one pixel without a return.
    let pixels = (0..12)
        .map(|i| (i != 5).then(|| Point3::new(2.0, (i % 4) as f64 * 0.1, (i / 4) as f64 * 0.1)));
    let cloud = PointCloud::from_pixels(4, 3, pixels)?;
    let dir = tempfile::tempdir()?;
    for (format, name) in [(BagFormat::Mcap, "scans.mcap"), (BagFormat::Ros1, "scans.bag")] {
        let mut w = BagWriter::new(format)?;
        let tf_static = w.add_topic("/tf_static", TF_MESSAGE)?;
        let tf_topic = w.add_topic("/tf", TF_MESSAGE)?;
        let points = w.add_topic("/points", POINT_CLOUD2)?;
        let t0 = 1_700_000_000_000_000_000i64;
        let mount = Isometry3::translation(0.1, 0.0, 0.5);
        w.write_tf(tf_static, t0 as u64, &[tf(t0, "base_link", "lidar", mount)])?;
        for k in 0..3 {
            let t = t0 + k * 100_000_000;
            let odom_from_base = Isometry3::translation(0.2 * k as f64, 0.0, 0.0);
            w.write_tf(tf_topic, t as u64, &[tf(t, "odom", "base_link", odom_from_base)])?;
            let header = Header { stamp_ns: t, frame_id: "lidar".into() };
            w.write_cloud(points, &header, &encode(&cloud, &Pc2Layout::default())?)?;
        }
        let path = dir.path().join(name);
        w.save(&path)?;

        let bag = Bag::open(&path)?;
        let info = BagInfo::of(&bag)?;
        println!("{name}: {} ({} bytes)", bag.format().name(), std::fs::metadata(&path)?.len());
        for t in &info.topics {
            println!("  {:<11} {:<24} {} messages", t.topic, t.type_name, t.count);
        }
        let span = (info.end_ns - info.start_ns) as f64 * 1e-9;
        let frames: Vec<&str> = info.frames.iter().map(String::as_str).collect();
        println!("  {span:.1} s, frames {}", frames.join(", "));
        let mut first = None;
        bag.for_each_message(|m| {
            if m.topic == "/points" && first.is_none() {
                first = Some(m.cloud()?);
            }
            Ok(())
        })?;
        let (header, back) = first.ok_or("no cloud")?;
        let grid = back.grid().ok_or("the cloud stays organised")?;
        println!(
            "  first cloud in `{}`: {} points, {} × {} pixels",
            header.frame_id,
            back.len(),
            grid.width(),
            grid.height()
        );
    }
    Ok(())
}
