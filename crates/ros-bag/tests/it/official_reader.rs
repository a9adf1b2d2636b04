//! Opt-in: the official `mcap` Python reader with its ROS 2 decoder (`mcap`,
//! `mcap-ros2-support` from PyPI) decodes our MCAP output, schemas and CDR alike.
//!
//! ```sh
//! python3 -m venv /tmp/mcap && /tmp/mcap/bin/pip install mcap mcap-ros2-support
//! PATCHNAV_MCAP_PYTHON=/tmp/mcap/bin/python cargo test -p patchnav-ros-bag --test it -- --ignored official
//! ```

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
