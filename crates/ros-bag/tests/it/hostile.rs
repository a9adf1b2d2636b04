//! Hostile and broken bags: typed errors with the file position (and topic), never a panic.

use crate::fixture;
use pointcloud::io::pointcloud2::{Pc2Error, PointCloud2, PointField};
use ros_bag::msgs::{POINT_CLOUD2, TF_MESSAGE};
use ros_bag::{Bag, BagError, BagFormat, BagInfo, BagWriter, Header};
use std::path::Path;

fn read_all(path: &Path) -> Result<usize, BagError> {
    let bag = Bag::open(path)?;
    let mut n = 0;
    bag.for_each_message(|m| {
        match m.type_name {
            "sensor_msgs/PointCloud2" => drop(m.cloud()?),
            "tf2_msgs/TFMessage" => drop(m.transforms()?),
            _ => {}
        }
        n += 1;
        Ok(())
    })?;
    Ok(n)
}

fn small_bag(format: BagFormat) -> Vec<u8> {
    fixture::bag(format, &fixture::scans(1))
}

#[test]
fn every_truncation_is_an_error_with_an_offset() {
    let dir = tempfile::tempdir().unwrap();
    for (format, name) in [(BagFormat::Mcap, "t.mcap"), (BagFormat::Ros1, "t.bag")] {
        let bytes = small_bag(format);
        let path = dir.path().join(name);
        let step = (bytes.len() / 97).max(1);
        for cut in (0..bytes.len()).step_by(step).chain([bytes.len() - 1]) {
            std::fs::write(&path, &bytes[..cut]).unwrap();
            match read_all(&path) {
                Err(BagError::Container { offset, .. }) => assert!(offset <= cut as u64),
                other => panic!("{format:?} cut at {cut}: {other:?}"),
            }
        }
        std::fs::write(&path, &bytes).unwrap();
        assert_eq!(read_all(&path).unwrap(), 6);
    }
}

#[test]
fn random_corruption_never_panics() {
    let dir = tempfile::tempdir().unwrap();
    for (format, name) in [(BagFormat::Mcap, "c.mcap"), (BagFormat::Ros1, "c.bag")] {
        let bytes = small_bag(format);
        let path = dir.path().join(name);
        let mut state = 12345u64;
        for _ in 0..300 {
            let mut b = bytes.clone();
            for _ in 0..4 {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                let at = (state >> 33) as usize % b.len();
                b[at] = (state >> 13) as u8;
            }
            std::fs::write(&path, &b).unwrap();
            let _ = read_all(&path);
        }
    }
}

/// A bag whose `/points` topic claims `PointCloud2` but carries other bytes.
fn wrong_schema(format: BagFormat) -> Vec<u8> {
    let mut w = BagWriter::new(format).unwrap();
    let t = w.add_topic("/points", POINT_CLOUD2).unwrap();
    let tf = ros_bag::msgs::encode_tf(&[], w.encoding());
    w.write(t, 5, &tf).unwrap();
    w.finish().unwrap()
}

#[test]
fn wrong_schema_names_topic_offset_and_field() {
    let dir = tempfile::tempdir().unwrap();
    for (format, name) in [(BagFormat::Mcap, "w.mcap"), (BagFormat::Ros1, "w.bag")] {
        let path = dir.path().join(name);
        std::fs::write(&path, wrong_schema(format)).unwrap();
        match read_all(&path).unwrap_err() {
            BagError::Message { topic, offset, source, .. } => {
                assert_eq!(topic, "/points");
                assert!(offset > 0);
                assert!(source.what.contains("header"), "{source}");
            }
            e => panic!("{e:?}"),
        }
        // info decodes headers too
        assert!(matches!(BagInfo::of(&Bag::open(&path).unwrap()), Err(BagError::Message { .. })));
    }
}

#[test]
fn asking_for_a_cloud_on_a_tf_topic_is_a_wrong_type() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.mcap");
    std::fs::write(&path, small_bag(BagFormat::Mcap)).unwrap();
    let err = Bag::open(&path)
        .unwrap()
        .for_each_message(|m| if m.topic == "/tf" { m.cloud().map(drop) } else { Ok(()) })
        .unwrap_err();
    assert!(matches!(err, BagError::WrongType { ref topic, .. } if topic == "/tf"), "{err}");
}

#[test]
fn a_billion_point_cloud_header_is_a_cloud_error_not_an_allocation() {
    let dir = tempfile::tempdir().unwrap();
    for (format, name) in [(BagFormat::Mcap, "b.mcap"), (BagFormat::Ros1, "b.bag")] {
        let mut w = BagWriter::new(format).unwrap();
        let t = w.add_topic("/points", POINT_CLOUD2).unwrap();
        let field =
            |name: &str, offset| PointField { name: name.into(), offset, datatype: 7, count: 1 };
        let cloud = PointCloud2 {
            height: 10_000,
            width: 100_000,
            fields: vec![field("x", 0), field("y", 4), field("z", 8)],
            is_bigendian: false,
            point_step: 12,
            row_step: 1_200_000,
            data: vec![0; 24],
            is_dense: true,
        };
        w.write_cloud(t, &Header { stamp_ns: 1, frame_id: "lidar".into() }, &cloud).unwrap();
        let path = dir.path().join(name);
        std::fs::write(&path, w.finish().unwrap()).unwrap();
        let err = read_all(&path).unwrap_err();
        match &err {
            BagError::Cloud {
                topic,
                source: Pc2Error::DataLength { expected, found: 24, .. },
                ..
            } => {
                assert_eq!(topic, "/points");
                assert_eq!(*expected, 12_000_000_000);
            }
            e => panic!("{e:?}"),
        }
        assert!(err.to_string().contains("topic /points"), "{err}");
    }
}

#[test]
fn a_sequence_longer_than_the_message_is_a_message_error() {
    let dir = tempfile::tempdir().unwrap();
    let mut w = BagWriter::new(BagFormat::Mcap).unwrap();
    let t = w.add_topic("/tf", TF_MESSAGE).unwrap();
    w.write(t, 1, &[0, 1, 0, 0, 0xff, 0xff, 0xff, 0x7f]).unwrap();
    let path = dir.path().join("s.mcap");
    std::fs::write(&path, w.finish().unwrap()).unwrap();
    match read_all(&path).unwrap_err() {
        BagError::Message { topic, source, .. } => {
            assert_eq!(topic, "/tf");
            assert_eq!(source.offset, 4);
            assert!(source.what.contains("`transforms` declares 2147483647"), "{source}");
        }
        e => panic!("{e:?}"),
    }
}

#[test]
fn unknown_paths_and_db3_folders_are_named() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bag_0.db3"), b"SQLite format 3\0").unwrap();
    assert!(matches!(Bag::open(dir.path()), Err(BagError::Db3 { .. })));
    let empty = tempfile::tempdir().unwrap();
    assert!(matches!(Bag::open(empty.path()), Err(BagError::NotABag { .. })));
    assert!(matches!(Bag::open(dir.path().join("x.ply")), Err(BagError::NotABag { .. })));
    let unindexed = dir.path().join("u.bag");
    let mut bytes = small_bag(BagFormat::Ros1);
    // index_pos = 0: a recording that was interrupted
    let at = bytes.windows(10).position(|w| w == b"index_pos=").unwrap() + 10;
    bytes[at..at + 8].fill(0);
    std::fs::write(&unindexed, &bytes).unwrap();
    let err = read_all(&unindexed).unwrap_err();
    assert!(err.to_string().contains("no index"), "{err}");
}

#[test]
fn a_ros1_chunk_claiming_gigabytes_is_refused_before_decompression() {
    let dir = tempfile::tempdir().unwrap();
    let mut bytes = small_bag(BagFormat::Ros1);
    let size = bytes.windows(5).position(|w| w == b"size=").unwrap() + 5;
    bytes[size..size + 4].copy_from_slice(&u32::MAX.to_le_bytes());
    let path = dir.path().join("big.bag");
    std::fs::write(&path, &bytes).unwrap();
    let err = read_all(&path).unwrap_err();
    assert!(err.to_string().contains("a chunk claims 4294967295 bytes"), "{err}");
}

/// A record inside an uncompressed chunk whose length reaches past the chunk (the `mcap`
/// crate's own walk through chunks overflows on it).
#[test]
fn an_mcap_record_longer_than_its_chunk_is_a_container_error() {
    let dir = tempfile::tempdir().unwrap();
    let mut bytes = small_bag(BagFormat::Mcap);
    let name = bytes.windows(22).position(|w| w == b"tf2_msgs/msg/TFMessage").unwrap();
    assert_eq!(bytes[name - 15], 0x03, "a schema record");
    bytes[name - 14..name - 6].copy_from_slice(&0xff_ffff_ffffu64.to_le_bytes());
    let path = dir.path().join("long.mcap");
    std::fs::write(&path, &bytes).unwrap();
    assert!(matches!(read_all(&path), Err(BagError::Container { .. })));
}
