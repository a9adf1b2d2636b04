//! Bags written by our own code from simulated lab scans: a moving base, `/tf` with
//! odom → base_link, `/tf_static` with base_link → sensor, organised float32 clouds on
//! `/points` and the same scans unorganised in a padded float64 layout on `/points_flat`.

use pointcloud::io::Precision;
use pointcloud::io::pointcloud2::{Pc2Layout, encode};
use pointcloud::{Isometry3, PointCloud, na};
use ros_bag::msgs::{POINT_CLOUD2, TF_MESSAGE};
use ros_bag::{BagFormat, BagWriter, Header, TransformStamped};
use scene_sim::{Alrf, AlrfConfig, RangeSensor, lab};

/// One simulated scan: its stamp, the cloud in the sensor frame (no pose), and the poses.
pub struct Scan {
    pub stamp_ns: i64,
    pub cloud: PointCloud,
    pub odom_from_base: Isometry3,
    pub odom_from_sensor: Isometry3,
}

/// The sensor on the base: 0.1 m forward, 0.5 m up.
pub fn base_from_sensor() -> Isometry3 {
    Isometry3::translation(0.1, 0.0, 0.5)
}

/// A coarse layout for fast tests: the lab scanned by the ALRF in 10° steps from `n` poses.
pub fn scans(n: usize) -> Vec<Scan> {
    let scene = lab(1).unwrap();
    let alrf = Alrf::new(AlrfConfig::sick_s300_with_step(10f64.to_radians()).unwrap()).unwrap();
    scene
        .scan_poses(n, 0.6, 7)
        .into_iter()
        .enumerate()
        .map(|(k, body)| {
            let sensor = alrf.mount(&body);
            let mut cloud = alrf.scan(&scene, &sensor, k as u64).to_cloud().unwrap();
            cloud.set_sensor_pose(None);
            let odom_from_sensor = sensor.world_from_sensor;
            Scan {
                stamp_ns: 1_700_000_000_000_000_000 + k as i64 * 500_000_000,
                cloud,
                odom_from_base: odom_from_sensor * base_from_sensor().inverse(),
                odom_from_sensor,
            }
        })
        .collect()
}

pub fn padded_f64() -> Pc2Layout {
    Pc2Layout {
        precision: Precision::F64,
        padding: 3,
        row_padding: 5,
        big_endian: false,
        positions_last: true,
    }
}

fn tf(stamp_ns: i64, parent: &str, child: &str, m: Isometry3) -> TransformStamped {
    TransformStamped {
        header: Header { stamp_ns, frame_id: parent.into() },
        child_frame_id: child.into(),
        parent_from_child: m,
    }
}

/// A bag of `scans` in `format`: `/tf_static` first, then per scan `/tf` 50 ms before, at and
/// 50 ms after the stamp (the base creeping 1 cm along x between samples), and the cloud on
/// `/points` (organised, float32) and `/points_flat` (unorganised, padded float64).
pub fn bag(format: BagFormat, scans: &[Scan]) -> Vec<u8> {
    let mut w = BagWriter::new(format).unwrap();
    let tf_static = w.add_topic("/tf_static", TF_MESSAGE).unwrap();
    let tf_topic = w.add_topic("/tf", TF_MESSAGE).unwrap();
    let points = w.add_topic("/points", POINT_CLOUD2).unwrap();
    let flat = w.add_topic("/points_flat", POINT_CLOUD2).unwrap();
    let t0 = scans[0].stamp_ns;
    w.write_tf(
        tf_static,
        t0 as u64 - 100_000_000,
        &[tf(t0, "base_link", "sensor", base_from_sensor())],
    )
    .unwrap();
    for s in scans {
        for dt in [-50_000_000i64, 0, 50_000_000] {
            let creep = Isometry3::translation(dt as f64 * 0.2e-9, 0.0, 0.0);
            let t = s.stamp_ns + dt;
            w.write_tf(tf_topic, t as u64, &[tf(t, "odom", "base_link", s.odom_from_base * creep)])
                .unwrap();
            if dt == 0 {
                let header = Header { stamp_ns: s.stamp_ns, frame_id: "sensor".into() };
                w.write_cloud(points, &header, &encode(&s.cloud, &Pc2Layout::default()).unwrap())
                    .unwrap();
                let unorganised = {
                    let mut c = s.cloud.clone();
                    c.set_grid(None).unwrap();
                    c
                };
                w.write_cloud(flat, &header, &encode(&unorganised, &padded_f64()).unwrap())
                    .unwrap();
            }
        }
    }
    w.finish().unwrap()
}

/// `cloud` as float32 positions give it back.
pub fn rounded_to_f32(cloud: &PointCloud) -> PointCloud {
    let p = cloud
        .positions()
        .iter()
        .map(|p| na::Point3::new(p.x as f32 as f64, p.y as f32 as f64, p.z as f32 as f64))
        .collect();
    cloud.with_positions(p).unwrap()
}
