//! ROS bags in: ROS 2 MCAP files and rosbag2 folders, and ROS 1 `.bag` files, read into this
//! workspace's types.
//!
//! * [`Bag::open`] takes a `.mcap` file, a rosbag2 folder (its `.mcap` files, in name order) or a
//!   `.bag` file; [`Bag::for_each_message`] walks the messages in file order as
//!   [`MessageRef`]s, which decode themselves: [`MessageRef::cloud`] (a
//!   `sensor_msgs/PointCloud2` as a [`pointcloud::PointCloud`], organised clouds kept
//!   organised, or a `sensor_msgs/LaserScan` as one organised row), [`MessageRef::depth_cloud`]
//!   (a depth `sensor_msgs/Image` with its `sensor_msgs/CameraInfo`, [`image`]),
//!   [`MessageRef::transforms`] (`tf2_msgs/TFMessage`), [`MessageRef::header`].
//! * [`BagInfo::of`]: topics, types, counts, time span and frames.
//! * [`read_scans`]: the clouds (or depth images) of a topic, picked by time window, count or
//!   motion, each posed in a fixed frame by the bag's `/tf` and `/tf_static` ([`TfTree`],
//!   interpolated) or a trajectory; [`for_each_scan`] hands them over one at a time.
//! * [`BagWriter`]: small MCAP and ROS 1 bags of clouds and transforms (fixtures and tests),
//!   and in MCAP `visualization_msgs/MarkerArray`s ([`msgs::markers`]) that RViz and
//!   Foxglove draw.
//!
//! # Crates and what is written here
//! MCAP is read and written by the `mcap` crate (its streaming reader, with zstd and lz4
//! chunks), ROS 1 bags are read by the `rosbag` crate. Message bytes are decoded by a small
//! reader written here ([`wire`]) for the few types needed, for both CDR and ROS 1's
//! serialisation: its errors name the field and the byte, and it checks every length before
//! allocating. The `rosbag` crate cannot write, so [`BagWriter`] writes ROS 1 bags itself.
//! rosbag2's SQLite storage (`.db3`) is not read ([`BagError::Db3`]): MCAP is ROS 2's default
//! storage since Iron, and `ros2 bag convert` turns a `.db3` bag into MCAP.
//!
//! # Errors
//! A hostile or broken bag gives a [`BagError`], never a panic: truncation and corrupt records
//! as [`BagError::Container`] with the file position, a message that does not decode as
//! [`BagError::Message`] or [`BagError::Cloud`] with its topic, position and field. Record and
//! sequence lengths are checked against the bytes present before memory is reserved.

mod bag;
mod decode;
mod error;
pub mod image;
mod info;
pub mod msgs;
mod scans;
pub mod tf;
pub mod wire;
mod write;

pub use bag::{Bag, BagFormat, MessageRef};
pub use error::BagError;
pub use info::{BagInfo, TopicInfo};
pub use msgs::{Header, PointCloud2Msg, TransformStamped};
pub use scans::{
    BagScan, BagScans, ScanQuery, ScanSummary, TRAJECTORY_FRAME, for_each_scan, read_scans,
    sibling_camera_info,
};
pub use tf::{TfError, TfTree};
pub use write::{BagWriter, TopicId};
