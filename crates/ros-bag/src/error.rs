//! The one error type of this crate.

use crate::tf::TfError;
use crate::wire::WireError;
use pointcloud::io::pointcloud2::Pc2Error;
use std::path::PathBuf;

/// Why a bag could not be read or written. Every variant about a bag's content names the file
/// and a byte position; the ones about a message name its topic too.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum BagError {
    /// The operating system refused.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The path is not a bag this crate reads.
    #[error("{}: {reason}", path.display())]
    NotABag {
        /// The path.
        path: PathBuf,
        /// Why not.
        reason: String,
    },
    /// A rosbag2 bag in SQLite storage, which is not read.
    #[error(
        "{}: rosbag2 SQLite storage (.db3) is not read; convert it to MCAP with `ros2 bag convert`",
        path.display()
    )]
    Db3 {
        /// The path.
        path: PathBuf,
    },
    /// The bag's structure is broken: truncated, a corrupt record or index.
    #[error("{}, byte {offset}: {reason}", path.display())]
    Container {
        /// The file.
        path: PathBuf,
        /// Where (see [`MessageRef::offset`](crate::MessageRef::offset)).
        offset: u64,
        /// What is wrong.
        reason: String,
    },
    /// A message whose type is not the one asked for.
    #[error("{}, byte {offset}, topic {topic}: type {found}, expected {expected}", path.display())]
    WrongType {
        /// The file.
        path: PathBuf,
        /// Where the message is.
        offset: u64,
        /// Its topic.
        topic: String,
        /// The type expected.
        expected: String,
        /// The type the bag names.
        found: String,
    },
    /// A message in an encoding this crate does not decode (neither `cdr` nor `ros1`).
    #[error("{}, byte {offset}, topic {topic}: message encoding not cdr or ros1", path.display())]
    UnknownEncoding {
        /// The file.
        path: PathBuf,
        /// Where the message is.
        offset: u64,
        /// Its topic.
        topic: String,
    },
    /// A message whose bytes do not decode as its type.
    #[error("{}, byte {offset}, topic {topic} ({type_name}): {source}", path.display())]
    Message {
        /// The file.
        path: PathBuf,
        /// Where the message is.
        offset: u64,
        /// Its topic.
        topic: String,
        /// Its type.
        type_name: String,
        /// Where in the message and what was expected.
        source: WireError,
    },
    /// A `PointCloud2` message whose layout or data are inconsistent.
    #[error("{}, byte {offset}, topic {topic}: {source}", path.display())]
    Cloud {
        /// The file.
        path: PathBuf,
        /// Where the message is.
        offset: u64,
        /// Its topic.
        topic: String,
        /// What is wrong with the cloud.
        source: Pc2Error,
    },
    /// A depth image that cannot become a cloud (encoding, size, camera info).
    #[error("{}, byte {offset}, topic {topic}: {source}", path.display())]
    Depth {
        /// The file.
        path: PathBuf,
        /// Where the image is.
        offset: u64,
        /// Its topic.
        topic: String,
        /// What is wrong.
        source: crate::image::DepthError,
    },
    /// A cloud whose transform to the fixed frame cannot be looked up.
    #[error("{}, byte {offset}, topic {topic}: {source}", path.display())]
    Tf {
        /// The file.
        path: PathBuf,
        /// Where the cloud is.
        offset: u64,
        /// Its topic.
        topic: String,
        /// The broken chain or the missing time.
        source: Box<TfError>,
    },
    /// A walk stopped by its caller's callback ([`crate::for_each_scan`] returns the
    /// callback's own error instead).
    #[error("stopped by the caller")]
    Stopped,
    /// A bag could not be written.
    #[error("writing a bag: {0}")]
    Write(String),
}
