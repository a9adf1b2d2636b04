//! Opt-in: the official `mcap` Python reader with its ROS 2 decoder (`mcap`,
//! `mcap-ros2-support` from PyPI) decodes our MCAP output, schemas and CDR alike.
//!
//! ```sh
//! python3 -m venv /tmp/mcap && /tmp/mcap/bin/pip install mcap mcap-ros2-support
//! PATCHNAV_MCAP_PYTHON=/tmp/mcap/bin/python cargo test -p patchnav-ros-bag --test it -- --ignored official
//! ```
//!
//! The second test decodes a `visualization_msgs/MarkerArray` whose every kind of field is set.

use crate::fixture;
use ros_bag::BagFormat;

const SCRIPT: &str = r#"
import sys
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
counts = {}
with open(sys.argv[1], "rb") as f:
    reader = make_reader(f, decoder_factories=[DecoderFactory()])
    for schema, channel, message, msg in reader.iter_decoded_messages():
        counts[channel.topic] = counts.get(channel.topic, 0) + 1
        if channel.topic == "/points":
            assert schema.name == "sensor_msgs/msg/PointCloud2"
            assert msg.header.frame_id == "sensor" and msg.height > 1
            assert len(msg.data) == msg.row_step * msg.height
        if channel.topic == "/tf":
            assert msg.transforms[0].child_frame_id == "base_link"
print(sorted(counts.items()))
"#;

#[test]
#[ignore = "needs PATCHNAV_MCAP_PYTHON: a Python with mcap and mcap-ros2-support"]
fn official_python_reader_decodes_our_mcap() {
    let python = std::env::var("PATCHNAV_MCAP_PYTHON").expect("PATCHNAV_MCAP_PYTHON is not set");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("lab.mcap");
    std::fs::write(&path, fixture::bag(BagFormat::Mcap, &fixture::scans(2))).unwrap();
    let o = std::process::Command::new(python).arg("-c").arg(SCRIPT).arg(&path).output().unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{out}{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(out.trim(), "[('/points', 2), ('/points_flat', 2), ('/tf', 6), ('/tf_static', 1)]");
}

const MARKER_SCRIPT: &str = r#"
import sys
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
with open(sys.argv[1], "rb") as f:
    reader = make_reader(f, decoder_factories=[DecoderFactory()])
    out = []
    for schema, channel, message, msg in reader.iter_decoded_messages():
        for m in msg.markers:
            out.append((schema.name, m.header.frame_id, m.ns, m.id, m.type, len(m.points),
                        m.points[-1].y, round(m.color.g, 3), m.lifetime.nanosec, m.texture.format,
                        len(m.uv_coordinates), m.mesh_file.filename, bytes(m.mesh_file.data).hex(),
                        m.mesh_use_embedded_materials))
print(out)
"#;

#[test]
#[ignore = "needs PATCHNAV_MCAP_PYTHON: a Python with mcap and mcap-ros2-support"]
fn official_python_reader_decodes_our_markers() {
    use pointcloud::Point3;
    use ros_bag::msgs::markers::{Duration, Marker, MarkerArray, MeshFile, TRIANGLE_LIST};
    use ros_bag::msgs::{MARKER_ARRAY, markers::ColorRgba};
    use ros_bag::{BagWriter, Header};
    let python = std::env::var("PATCHNAV_MCAP_PYTHON").expect("PATCHNAV_MCAP_PYTHON is not set");
    let mut m = Marker::new(Header { stamp_ns: 3, frame_id: "map".into() }, "floor", 4);
    m.kind = TRIANGLE_LIST;
    m.points = vec![Point3::origin(), Point3::new(1.0, 0.0, 0.0), Point3::new(0.0, 2.5, 0.0)];
    m.color = ColorRgba::new(0.1, 0.5, 0.9, 1.0);
    m.lifetime = Duration { sec: 1, nanosec: 7 };
    m.texture.format = "png".into();
    m.uv_coordinates = vec![Default::default(); 3];
    m.mesh_file = MeshFile { filename: "a.stl".into(), data: vec![0xab, 0xcd] };
    m.mesh_use_embedded_materials = true;
    let mut bag = BagWriter::new(BagFormat::Mcap).unwrap();
    let topic = bag.add_topic("/markers", MARKER_ARRAY).unwrap();
    bag.write_markers(topic, 3, &MarkerArray { markers: vec![m] }).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("markers.mcap");
    std::fs::write(&path, bag.finish().unwrap()).unwrap();
    let o = std::process::Command::new(python)
        .arg("-c")
        .arg(MARKER_SCRIPT)
        .arg(&path)
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{out}{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        out.trim(),
        "[('visualization_msgs/msg/MarkerArray', 'map', 'floor', 4, 11, 3, 2.5, 0.5, 7, 'png', 3, \
         'a.stl', 'abcd', True)]"
    );
}
