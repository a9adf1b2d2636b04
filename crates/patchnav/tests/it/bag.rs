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

/// Three ALRF scans of the lab from a moving base: yaw 0 or 180° and translations in quarter
/// metres, so that every pose is exact in a PLY header's matrix, a quaternion and their
/// products, and the bag's scans equal the PLY scans bit for bit.
fn lab_scans() -> Vec<(i64, Isometry3, PointCloud)> {
    use scene_sim::{Alrf, AlrfConfig, RangeSensor, lab};
    let scene = lab(1).unwrap();
    let alrf = Alrf::new(AlrfConfig::sick_s300_with_step(4f64.to_radians()).unwrap()).unwrap();
    use pointcloud::na::{Quaternion, Translation3, UnitQuaternion};
    let base = [(3.0, 3.0, false), (4.0, 3.25, true), (5.5, 3.5, false)];
    base.iter()
        .enumerate()
        .map(|(k, &(x, y, turned))| {
            // yaw 180° as the exact quaternion (w, x, y, z) = (0, 0, 0, 1)
            let yaw =
                if turned { Quaternion::new(0.0, 0.0, 0.0, 1.0) } else { Quaternion::identity() };
            let odom_from_base = Isometry3::from_parts(
                Translation3::new(x, y, 0.0),
                UnitQuaternion::new_unchecked(yaw),
            );
            let sensor = pointcloud::SensorPose { world_from_sensor: odom_from_base * mount() };
            let mut cloud = alrf.scan(&scene, &alrf.mount(&sensor), k as u64).to_cloud().unwrap();
            cloud.set_sensor_pose(Some(sensor));
            (T0 + k as i64 * 400_000_000, odom_from_base, cloud)
        })
        .collect()
}

fn mount() -> Isometry3 {
    Isometry3::translation(0.125, 0.0, 0.5)
}

/// The lab scans as a bag: `/tf_static`, and `/tf` samples 100 ms before, at and after each
/// scan (the base creeping forward between them), clouds in float64.
fn lab_bag(format: BagFormat, scans: &[(i64, Isometry3, PointCloud)], with_tf: bool) -> Vec<u8> {
    let tf = |stamp_ns, parent: &str, child: &str, m| TransformStamped {
        header: Header { stamp_ns, frame_id: parent.into() },
        child_frame_id: child.into(),
        parent_from_child: m,
    };
    let layout = Pc2Layout { precision: pointcloud::io::Precision::F64, ..Pc2Layout::default() };
    let mut w = BagWriter::new(format).unwrap();
    let s = w.add_topic("/tf_static", TF_MESSAGE).unwrap();
    let t = w.add_topic("/tf", TF_MESSAGE).unwrap();
    let p = w.add_topic("/points", POINT_CLOUD2).unwrap();
    if with_tf {
        w.write_tf(s, T0 as u64, &[tf(T0, "base_link", "laser", mount())]).unwrap();
    }
    for (stamp, odom_from_base, cloud) in scans {
        for dt in [-100_000_000i64, 0, 100_000_000] {
            let creep = Isometry3::translation(dt as f64 * 1e-9, 0.0, 0.0);
            if with_tf {
                let m = odom_from_base * creep;
                w.write_tf(t, (stamp + dt) as u64, &[tf(stamp + dt, "odom", "base_link", m)])
                    .unwrap();
            }
            if dt == 0 {
                let mut c = cloud.clone();
                c.set_sensor_pose(None);
                let header = Header { stamp_ns: *stamp, frame_id: "laser".into() };
                w.write_cloud(p, &header, &encode(&c, &layout).unwrap()).unwrap();
            }
        }
    }
    w.finish().unwrap()
}

#[test]
fn extract_from_a_bag_gives_the_map_of_the_ply_scans() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_owned();
    let scans = lab_scans();
    let mut plys = Vec::new();
    for (k, (_, _, cloud)) in scans.iter().enumerate() {
        let p = path(&format!("scan{k}.ply"));
        pointcloud::io::write_cloud(std::path::Path::new(&p), cloud).unwrap();
        plys.push(p);
    }
    let mut args: Vec<&str> = vec!["extract"];
    args.extend(plys.iter().map(String::as_str));
    let ply_map = path("ply.pmap");
    args.extend(["--out", &ply_map]);
    let o = patchnav(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let expected = std::fs::read(&ply_map).unwrap();

    for (format, name) in [(BagFormat::Mcap, "lab.mcap"), (BagFormat::Ros1, "lab.bag")] {
        std::fs::write(path(name), lab_bag(format, &scans, true)).unwrap();
        let out = path(&format!("{name}.pmap"));
        let o = patchnav(&["extract", &path(name), "--topic", "/points", "--out", &out]);
        assert!(o.status.success(), "{}", stderr(&o));
        let text = stdout(&o);
        assert!(
            text.contains("3 of 3 clouds on /points (3 in the time window), posed in odom"),
            "{text}"
        );
        assert!(
            std::fs::read(&out).unwrap() == expected,
            "{name}: the bag's map differs from the PLY scans' map"
        );
    }
}

#[test]
fn extract_picks_scans_by_count_motion_and_time() {
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("lab.mcap");
    std::fs::write(&bag, lab_bag(BagFormat::Mcap, &lab_scans(), true)).unwrap();
    let bag = bag.to_str().unwrap();
    let out = dir.path().join("m.pmap");
    let out = out.to_str().unwrap();
    let kept = |extra: &[&str]| {
        let mut args = vec!["extract", bag, "--topic", "/points", "--out", out];
        args.extend(extra);
        let o = patchnav(&args);
        assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
        stdout(&o).lines().next().unwrap().to_owned()
    };
    assert!(kept(&["--every", "2"]).contains("2 of 3 clouds"));
    // the sensor moves 0.79 m, then 1.77 m (2.5 m from the first scan)
    assert!(kept(&["--min-motion", "1.2"]).contains("2 of 3 clouds"));
    // the bag starts 100 ms before the first scan; scans at 0.1, 0.5, 0.9 s
    assert!(
        kept(&["--start", "0.3", "--end", "0.7"])
            .contains("1 of 3 clouds on /points (1 in the time window)")
    );
    assert!(kept(&["--fixed-frame", "base_link"]).contains("posed in base_link"));
}

#[test]
fn extract_names_a_broken_chain_and_warns_without_tf() {
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("lab.bag");
    std::fs::write(&bag, lab_bag(BagFormat::Ros1, &lab_scans()[..1], true)).unwrap();
    let out = dir.path().join("m.pmap");
    let o = patchnav(&[
        "extract",
        bag.to_str().unwrap(),
        "--topic",
        "/points",
        "--fixed-frame",
        "map",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_one_line_error(&o, "topic /points: no transform chain from `laser` to `map`");
    let o = patchnav(&["extract", bag.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert_one_line_error(&o, "--topic");

    let bare = dir.path().join("bare.mcap");
    std::fs::write(&bare, lab_bag(BagFormat::Mcap, &lab_scans()[..1], false)).unwrap();
    let o = patchnav(&[
        "extract",
        bare.to_str().unwrap(),
        "--topic",
        "/points",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("warning: no transform from `laser`"), "{}", stderr(&o));
    assert!(stdout(&o).contains("posed in the sensor frame"), "{}", stdout(&o));
}

/// `terrain BAG --topic T` classifies every message: the simulated floor frames as floor.
#[test]
fn terrain_on_a_bag_classifies_every_message() {
    let dir = tempfile::tempdir().unwrap();
    // A range camera 0.5 m over a flat floor, looking ahead and slightly down.
    let cloud = PointCloud::from_positions(
        (0..40)
            .flat_map(|i| (0..30).map(move |j| (i, j)))
            .map(|(i, j)| Point3::new(1.0 + 0.1 * i as f64, -1.5 + 0.1 * j as f64, -0.5))
            .collect(),
    )
    .unwrap();
    let mut w = BagWriter::new(BagFormat::Ros1).unwrap();
    let p = w.add_topic("/front/points", POINT_CLOUD2).unwrap();
    for k in 0..4i64 {
        let header = Header { stamp_ns: T0 + k * 100_000_000, frame_id: "lidar".into() };
        w.write_cloud(p, &header, &encode(&cloud, &Pc2Layout::default()).unwrap()).unwrap();
    }
    let path = dir.path().join("floor.bag");
    std::fs::write(&path, w.finish().unwrap()).unwrap();
    let o = patchnav(&[
        "terrain",
        path.to_str().unwrap(),
        "--topic",
        "/front/points",
        "--resolution",
        "45",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    let rows: Vec<&str> = text.lines().filter(|l| l.contains(" s  ")).collect();
    assert_eq!(rows.len(), 4, "{text}");
    assert!(rows.iter().all(|r| r.contains("floor") && r.contains("drivable yes")), "{text}");
    let o = patchnav(&["terrain", path.to_str().unwrap(), "--topic", "/front/points", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let json: Vec<serde_json::Value> =
        stdout(&o).lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(json.len(), 4);
    assert_eq!(json[3]["stamp_ns"], T0 + 300_000_000);
    assert_one_line_error(&patchnav(&["terrain", path.to_str().unwrap()]), "needs --topic");
    assert_one_line_error(
        &patchnav(&["terrain", path.to_str().unwrap(), "--topic", "/nothing"]),
        "no message on topic /nothing",
    );
}

/// `extract BAG --topic T --poses TRAJECTORY`: a bag without /tf posed by a TUM trajectory.
#[test]
fn extract_poses_a_bag_by_a_trajectory() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.mcap");
    std::fs::write(&path, bag(BagFormat::Mcap)).unwrap();
    let trajectory = dir.path().join("traj.txt");
    std::fs::write(
        &trajectory,
        "# t tx ty tz qx qy qz qw\n1700000000.0 0 0 0.4 0 0 0 1\n1700000000.3 3 0 0.4 0 0 0 1\n",
    )
    .unwrap();
    let out = dir.path().join("m.pmap");
    let (b, t, o) = (path.to_str().unwrap(), trajectory.to_str().unwrap(), out.to_str().unwrap());
    let run = patchnav(&[
        "extract", b, "--topic", "/points", "--poses", t, "--out", o, "--sensor", "exact",
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(stdout(&run).contains("posed in trajectory"), "{}", stdout(&run));
    std::fs::write(&trajectory, "1700000000.0 0 0 0.4 0 0 0 1\n1699999999.0 0 0 0 0 0 0 1\n")
        .unwrap();
    assert_one_line_error(
        &patchnav(&["extract", b, "--topic", "/points", "--poses", t, "--out", o]),
        "line 2: the stamps must increase",
    );
    std::fs::write(&trajectory, "1700000000.0 0 0 0.4 0 0 0\n").unwrap();
    assert_one_line_error(
        &patchnav(&["extract", b, "--topic", "/points", "--poses", t, "--out", o]),
        "want 8 finite numbers",
    );
}
