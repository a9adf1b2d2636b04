//! Depth images (`sensor_msgs/Image` + `sensor_msgs/CameraInfo`) read as organised clouds and
//! posed by `/tf`; clouds posed by a trajectory instead of `/tf`.

use crate::fixture;
use pointcloud::{BeamModel, Isometry3, PinholeIntrinsics, RangeImage, RangeKind};
use ros_bag::image::{CAMERA_INFO, CameraInfo, IMAGE, Image};
use ros_bag::msgs::{POINT_CLOUD2, TF_MESSAGE};
use ros_bag::{
    Bag, BagError, BagFormat, BagWriter, Header, ScanQuery, TransformStamped, read_scans,
};

const W: u32 = 40;
const H: u32 = 30;
const T0: i64 = 1_700_000_000_000_000_000;

fn intrinsics() -> PinholeIntrinsics {
    PinholeIntrinsics { fx: 50.0, fy: 52.0, cx: 19.5, cy: 14.0 }
}

/// A slanted wall 1.5–2.7 m away with a hole (no measurement) in its middle.
fn depths() -> Vec<Option<f32>> {
    (0..H)
        .flat_map(|v| {
            (0..W).map(move |u| {
                let hole = (15..20).contains(&u) && (10..14).contains(&v);
                (!hole).then_some(1.5 + 0.03 * u as f32 + 0.001 * v as f32)
            })
        })
        .collect()
}

fn odom_from_base(k: usize) -> Isometry3 {
    Isometry3::translation(0.5 * k as f64, 0.2, 0.0)
}

fn base_from_camera() -> Isometry3 {
    Isometry3::translation(0.2, 0.0, 0.4)
}

fn tf(stamp_ns: i64, parent: &str, child: &str, m: Isometry3) -> TransformStamped {
    TransformStamped {
        header: Header { stamp_ns, frame_id: parent.into() },
        child_frame_id: child.into(),
        parent_from_child: m,
    }
}

/// Three depth images of `encoding` with their camera info and transforms.
fn depth_bag(format: BagFormat, encoding: &str, with_info: bool) -> Vec<u8> {
    let mut w = BagWriter::new(format).unwrap();
    let e = w.encoding();
    let tf_static = w.add_topic("/tf_static", TF_MESSAGE).unwrap();
    let tf_topic = w.add_topic("/tf", TF_MESSAGE).unwrap();
    let image = w.add_topic("/camera/depth/image_rect", IMAGE).unwrap();
    let info = w.add_topic("/camera/depth/camera_info", CAMERA_INFO).unwrap();
    w.write_tf(tf_static, T0 as u64, &[tf(T0, "base_link", "camera", base_from_camera())]).unwrap();
    for k in 0..3 {
        let t = T0 + k as i64 * 100_000_000;
        for dt in [-10_000_000, 10_000_000] {
            let odom = tf(t + dt, "odom", "base_link", odom_from_base(k));
            w.write_tf(tf_topic, (t + dt) as u64, &[odom]).unwrap();
        }
        let header = Header { stamp_ns: t, frame_id: "camera".into() };
        if with_info {
            let ci = CameraInfo::pinhole(header.clone(), W, H, intrinsics());
            w.write(info, t as u64, &ci.encode(e)).unwrap();
        }
        let img = Image::from_depth(header, W, H, &depths(), encoding).unwrap();
        w.write(image, t as u64, &img.encode(e)).unwrap();
    }
    w.finish().unwrap()
}

fn open(bytes: &[u8], format: BagFormat) -> (tempfile::TempDir, Bag) {
    let dir = tempfile::tempdir().unwrap();
    let name = if format == BagFormat::Ros1 { "d.bag" } else { "d.mcap" };
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    let bag = Bag::open(&path).unwrap();
    (dir, bag)
}

#[test]
fn depth_images_become_organised_posed_clouds() {
    let expected =
        RangeImage::new(W, H, BeamModel::Pinhole(intrinsics()), RangeKind::Depth, depths())
            .unwrap()
            .to_cloud()
            .unwrap();
    for format in [BagFormat::Mcap, BagFormat::Ros1] {
        for (encoding, tolerance) in [("16UC1", 6e-4), ("32FC1", 1e-6)] {
            let (_dir, bag) = open(&depth_bag(format, encoding, true), format);
            let found = read_scans(&bag, &ScanQuery::all("/camera/depth/image_rect")).unwrap();
            assert_eq!(found.fixed_frame.as_deref(), Some("odom"));
            assert_eq!(found.scans.len(), 3, "{format:?} {encoding}");
            for (k, scan) in found.scans.iter().enumerate() {
                let grid = scan.cloud.grid().unwrap();
                assert_eq!((grid.width(), grid.height()), (W, H));
                assert_eq!(scan.cloud.len(), expected.len());
                for (p, q) in scan.cloud.positions().iter().zip(expected.positions()) {
                    assert!((p - q).norm() < tolerance * 3.0, "{p} vs {q}");
                }
                let pose = scan.cloud.sensor_pose().unwrap().world_from_sensor;
                let truth = odom_from_base(k) * base_from_camera();
                assert!((pose.translation.vector - truth.translation.vector).norm() < 1e-9);
            }
        }
    }
}

#[test]
fn images_without_a_camera_info_or_of_another_encoding_are_errors() {
    let (_dir, bag) = open(&depth_bag(BagFormat::Mcap, "16UC1", false), BagFormat::Mcap);
    let err = read_scans(&bag, &ScanQuery::all("/camera/depth/image_rect")).unwrap_err();
    assert!(err.to_string().contains("no sensor_msgs/CameraInfo"), "{err}");
    // The camera info under another name.
    let (_dir, bag) = open(&depth_bag(BagFormat::Mcap, "16UC1", true), BagFormat::Mcap);
    let query = ScanQuery {
        camera_info: Some("/camera/depth/image_rect".into()),
        ..ScanQuery::all("/camera/depth/image_rect")
    };
    assert!(read_scans(&bag, &query).is_err());

    let mut img = Image::from_depth(Header::default(), W, H, &depths(), "16UC1").unwrap();
    img.encoding = "rgb8".into();
    let info = CameraInfo::pinhole(Header::default(), W, H, intrinsics());
    assert!(img.to_cloud(&info).unwrap_err().to_string().contains("rgb8"));
    let mut short = Image::from_depth(Header::default(), W, H, &depths(), "32FC1").unwrap();
    short.data.truncate(100);
    assert!(short.to_cloud(&info).unwrap_err().to_string().contains("bytes"));
    let small = CameraInfo::pinhole(Header::default(), W - 1, H, intrinsics());
    assert!(short.to_cloud(&small).is_err());
    let mut flat = info.clone();
    flat.p = [0.0; 12];
    flat.k = [0.0; 9];
    assert!(img.to_cloud(&flat).is_err());
}

#[test]
fn a_bad_image_in_a_bag_names_its_topic() {
    let mut w = BagWriter::new(BagFormat::Mcap).unwrap();
    let e = w.encoding();
    let image = w.add_topic("/depth", IMAGE).unwrap();
    let info = w.add_topic("/camera_info", CAMERA_INFO).unwrap();
    let header = Header { stamp_ns: T0, frame_id: "camera".into() };
    let ci = CameraInfo::pinhole(header.clone(), W, H, intrinsics());
    w.write(info, T0 as u64, &ci.encode(e)).unwrap();
    let mut img = Image::from_depth(header, W, H, &depths(), "16UC1").unwrap();
    img.encoding = "bgr8".into();
    w.write(image, T0 as u64, &img.encode(e)).unwrap();
    let (_dir, bag) = open(&w.finish().unwrap(), BagFormat::Mcap);
    let err = read_scans(&bag, &ScanQuery::all("/depth")).unwrap_err();
    assert!(matches!(err, BagError::Depth { .. }), "{err:?}");
    assert!(err.to_string().contains("topic /depth") && err.to_string().contains("bgr8"), "{err}");
}

#[test]
fn camera_infos_round_trip_in_both_encodings() {
    let header = Header { stamp_ns: T0, frame_id: "camera".into() };
    let mut ci = CameraInfo::pinhole(header, W, H, intrinsics());
    ci.d = vec![0.1, -0.2, 0.0, 0.001, 0.3];
    ci.roi = (1, 2, 3, 4, true);
    for e in [ros_bag::wire::Encoding::Cdr, ros_bag::wire::Encoding::Ros1] {
        assert_eq!(CameraInfo::decode(&ci.encode(e), e).unwrap(), ci);
        let img = Image::from_depth(ci.header.clone(), W, H, &depths(), "32FC1").unwrap();
        assert_eq!(Image::decode(&img.encode(e), e).unwrap(), img);
    }
}

#[test]
fn a_trajectory_poses_clouds_of_a_bag_without_tf() {
    let scans = fixture::scans(2);
    let mut w = BagWriter::new(BagFormat::Mcap).unwrap();
    let points = w.add_topic("/points", POINT_CLOUD2).unwrap();
    for s in &scans {
        let header = Header { stamp_ns: s.stamp_ns, frame_id: "sensor".into() };
        let layout = pointcloud::io::pointcloud2::Pc2Layout::default();
        w.write_cloud(
            points,
            &header,
            &pointcloud::io::pointcloud2::encode(&s.cloud, &layout).unwrap(),
        )
        .unwrap();
    }
    let (_dir, bag) = open(&w.finish().unwrap(), BagFormat::Mcap);
    let plain = read_scans(&bag, &ScanQuery::all("/points")).unwrap();
    assert!(plain.fixed_frame.is_none() && !plain.warnings.is_empty());
    let trajectory: Vec<(i64, Isometry3)> = scans
        .iter()
        .flat_map(|s| {
            let creep = Isometry3::translation(0.01, 0.0, 0.0);
            [
                (s.stamp_ns - 1000, s.odom_from_sensor),
                (s.stamp_ns + 1000, creep * s.odom_from_sensor),
            ]
        })
        .collect();
    let query = ScanQuery { trajectory: Some(trajectory), ..ScanQuery::all("/points") };
    let posed = read_scans(&bag, &query).unwrap();
    assert_eq!(posed.fixed_frame.as_deref(), Some(ros_bag::TRAJECTORY_FRAME));
    for (scan, s) in posed.scans.iter().zip(&scans) {
        let pose = scan.cloud.sensor_pose().unwrap().world_from_sensor;
        let midway = Isometry3::translation(0.005, 0.0, 0.0) * s.odom_from_sensor;
        assert!((pose.translation.vector - midway.translation.vector).norm() < 1e-9);
    }
    // A stamp outside the trajectory is an error that names the topic.
    let short = ScanQuery {
        trajectory: Some(vec![(0, Isometry3::identity()), (1, Isometry3::identity())]),
        ..ScanQuery::all("/points")
    };
    let err = read_scans(&bag, &short).unwrap_err();
    assert!(err.to_string().contains("topic /points"), "{err}");
}
