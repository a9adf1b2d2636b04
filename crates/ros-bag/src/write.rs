//! Writing small bags: the fixtures and tests of this workspace, and anyone who wants a bag of
//! clouds and transforms.
//!
//! MCAP goes through the `mcap` crate (uncompressed chunks, `ros2msg` schemas, `cdr` messages).
//! The `rosbag` crate only reads, so ROS 1 bags (format 2.0) are written here: the bag header,
//! one uncompressed chunk holding the connections and messages, its index data, then the index
//! section (connections and chunk info), as `rosbag record` lays them out.

use crate::bag::BagFormat;
use crate::error::BagError;
use crate::msgs::markers::MarkerArray;
use crate::msgs::{self, Header, PointCloud2Msg, TransformStamped};
use crate::wire::Encoding;
use pointcloud::io::pointcloud2::PointCloud2;
use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::Path;

/// A topic of a [`BagWriter`].
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct TopicId(usize);

struct Topic {
    name: String,
    type_name: String,
    mcap_channel: u16,
}

enum Inner {
    Mcap(Box<mcap::Writer<Cursor<Vec<u8>>>>),
    Ros1(Ros1Writer),
}

/// Writes a bag in memory; [`BagWriter::finish`] returns the bytes, [`BagWriter::save`] writes
/// them atomically.
pub struct BagWriter {
    inner: Inner,
    topics: Vec<Topic>,
    format: BagFormat,
}

fn write_error(e: impl std::fmt::Display) -> BagError {
    BagError::Write(e.to_string())
}

impl BagWriter {
    /// A writer of `format` ([`BagFormat::Mcap`] or [`BagFormat::Ros1`]; a rosbag2 folder is
    /// an MCAP file in a folder).
    pub fn new(format: BagFormat) -> Result<BagWriter, BagError> {
        let inner = match format {
            BagFormat::Mcap | BagFormat::Rosbag2Folder => {
                let options = mcap::WriteOptions::new().compression(None).profile("ros2");
                let w = options.create(Cursor::new(Vec::new())).map_err(write_error)?;
                Inner::Mcap(Box::new(w))
            }
            BagFormat::Ros1 => Inner::Ros1(Ros1Writer::default()),
        };
        Ok(BagWriter { inner, topics: Vec::new(), format })
    }

    /// The encoding messages must have ([`BagWriter::write`] takes them serialised).
    pub fn encoding(&self) -> Encoding {
        self.format.encoding()
    }

    /// Adds a topic of a type (`sensor_msgs/PointCloud2`, `sensor_msgs/LaserScan`,
    /// `tf2_msgs/TFMessage`, and in MCAP `visualization_msgs/Marker` and `MarkerArray`, with
    /// their full definitions; other types get an empty definition).
    pub fn add_topic(&mut self, name: &str, type_name: &str) -> Result<TopicId, BagError> {
        let encoding = self.encoding();
        let (definition, md5) = msgs::definition(type_name, encoding).unwrap_or_default();
        let mut mcap_channel = 0;
        match &mut self.inner {
            Inner::Mcap(w) => {
                let (package, ty) = type_name.split_once('/').unwrap_or(("", type_name));
                let schema_name = format!("{package}/msg/{ty}");
                let schema = w
                    .add_schema(&schema_name, "ros2msg", definition.as_bytes())
                    .map_err(write_error)?;
                mcap_channel =
                    w.add_channel(schema, name, "cdr", &BTreeMap::new()).map_err(write_error)?;
            }
            Inner::Ros1(w) => w.connections.push(Ros1Connection {
                topic: name.to_owned(),
                type_name: type_name.to_owned(),
                md5: if md5.is_empty() { "0".repeat(32) } else { md5.to_owned() },
                definition,
            }),
        }
        self.topics.push(Topic {
            name: name.to_owned(),
            type_name: type_name.to_owned(),
            mcap_channel,
        });
        Ok(TopicId(self.topics.len() - 1))
    }

    /// Writes a serialised message (in [`BagWriter::encoding`]) recorded at `log_time_ns`.
    pub fn write(&mut self, topic: TopicId, log_time_ns: u64, data: &[u8]) -> Result<(), BagError> {
        let t = self.topics.get(topic.0).ok_or_else(|| write_error("unknown topic"))?;
        match &mut self.inner {
            Inner::Mcap(w) => {
                let header = mcap::records::MessageHeader {
                    channel_id: t.mcap_channel,
                    sequence: 0,
                    log_time: log_time_ns,
                    publish_time: log_time_ns,
                };
                w.write_to_known_channel(&header, data).map_err(write_error)
            }
            Inner::Ros1(w) => {
                w.messages.push((topic.0 as u32, log_time_ns, data.to_vec()));
                Ok(())
            }
        }
    }

    /// Writes a `PointCloud2` message stamped `header.stamp_ns`, recorded at that time.
    pub fn write_cloud(
        &mut self,
        topic: TopicId,
        header: &Header,
        cloud: &PointCloud2,
    ) -> Result<(), BagError> {
        let msg = PointCloud2Msg { header: header.clone(), cloud: cloud.clone() };
        let data = msg.encode(self.encoding());
        self.write(topic, header.stamp_ns.max(0) as u64, &data)
    }

    /// Writes a `TFMessage` recorded at `log_time_ns`.
    pub fn write_tf(
        &mut self,
        topic: TopicId,
        log_time_ns: u64,
        transforms: &[TransformStamped],
    ) -> Result<(), BagError> {
        let data = msgs::encode_tf(transforms, self.encoding());
        self.write(topic, log_time_ns, &data)
    }

    /// Writes a `MarkerArray` recorded at `log_time_ns`.
    ///
    /// # Errors
    /// [`BagError::Write`] in a ROS 1 bag (markers are written in CDR only) or for an unknown
    /// topic.
    pub fn write_markers(
        &mut self,
        topic: TopicId,
        log_time_ns: u64,
        markers: &MarkerArray,
    ) -> Result<(), BagError> {
        if self.encoding() != Encoding::Cdr {
            return Err(write_error("markers are written to MCAP (CDR) bags only"));
        }
        self.write(topic, log_time_ns, &markers.encode())
    }

    /// The bag's bytes.
    pub fn finish(self) -> Result<Vec<u8>, BagError> {
        match self.inner {
            Inner::Mcap(mut w) => {
                w.finish().map_err(write_error)?;
                Ok(w.into_inner().into_inner())
            }
            Inner::Ros1(w) => Ok(w.finish()),
        }
    }

    /// Writes the bag to `path` through [`pointcloud::io::write_bytes_atomically`].
    pub fn save(self, path: impl AsRef<Path>) -> Result<(), BagError> {
        let bytes = self.finish()?;
        pointcloud::io::write_bytes_atomically(path, bytes).map_err(write_error)
    }

    /// The topics added so far: (name, type).
    pub fn topics(&self) -> impl Iterator<Item = (&str, &str)> {
        self.topics.iter().map(|t| (t.name.as_str(), t.type_name.as_str()))
    }
}

struct Ros1Connection {
    topic: String,
    type_name: String,
    md5: String,
    definition: String,
}

#[derive(Default)]
struct Ros1Writer {
    connections: Vec<Ros1Connection>,
    /// (connection, time, data)
    messages: Vec<(u32, u64, Vec<u8>)>,
}

/// A ROS 1 record: header fields `name=value`, then the data.
fn record(out: &mut Vec<u8>, fields: &[(&str, &[u8])], data: &[u8]) {
    let mut header = Vec::new();
    for (name, value) in fields {
        header.extend(((name.len() + 1 + value.len()) as u32).to_le_bytes());
        header.extend(name.as_bytes());
        header.push(b'=');
        header.extend(*value);
    }
    out.extend((header.len() as u32).to_le_bytes());
    out.extend(header);
    out.extend((data.len() as u32).to_le_bytes());
    out.extend(data);
}

fn ros1_time(ns: u64) -> [u8; 8] {
    let mut t = [0u8; 8];
    t[..4].copy_from_slice(&((ns / 1_000_000_000) as u32).to_le_bytes());
    t[4..].copy_from_slice(&((ns % 1_000_000_000) as u32).to_le_bytes());
    t
}

impl Ros1Writer {
    fn connection_record(&self, out: &mut Vec<u8>, id: u32) {
        let c = &self.connections[id as usize];
        let mut data = Vec::new();
        record(
            &mut data,
            &[
                ("topic", c.topic.as_bytes()),
                ("type", c.type_name.as_bytes()),
                ("md5sum", c.md5.as_bytes()),
                ("message_definition", c.definition.as_bytes()),
            ],
            &[],
        );
        // The connection's data is a header-format field list without the data part.
        data.truncate(data.len() - 4);
        let fields = data.split_off(4);
        record(
            out,
            &[("op", &[0x07]), ("conn", &id.to_le_bytes()), ("topic", c.topic.as_bytes())],
            &fields,
        );
    }

    fn finish(self) -> Vec<u8> {
        const MAGIC: &[u8] = b"#ROSBAG V2.0\n";
        const HEADER_RECORD_LEN: usize = 4096;
        // The chunk: every connection, then the messages.
        let mut chunk = Vec::new();
        for id in 0..self.connections.len() as u32 {
            self.connection_record(&mut chunk, id);
        }
        let mut per_connection: BTreeMap<u32, Vec<(u64, u32)>> = BTreeMap::new();
        for (conn, time, data) in &self.messages {
            per_connection.entry(*conn).or_default().push((*time, chunk.len() as u32));
            record(
                &mut chunk,
                &[("op", &[0x02]), ("conn", &conn.to_le_bytes()), ("time", &ros1_time(*time))],
                data,
            );
        }
        let start = self.messages.iter().map(|m| m.1).min().unwrap_or(0);
        let end = self.messages.iter().map(|m| m.1).max().unwrap_or(0);

        let mut out = MAGIC.to_vec();
        let header_at = out.len();
        out.resize(header_at + HEADER_RECORD_LEN, 0); // the bag header, written last
        let chunk_pos = out.len() as u64;
        record(
            &mut out,
            &[
                ("op", &[0x05]),
                ("compression", b"none"),
                ("size", &(chunk.len() as u32).to_le_bytes()),
            ],
            &chunk,
        );
        for (conn, entries) in &per_connection {
            let mut data = Vec::new();
            for (time, offset) in entries {
                data.extend(ros1_time(*time));
                data.extend(offset.to_le_bytes());
            }
            record(
                &mut out,
                &[
                    ("op", &[0x04]),
                    ("ver", &1u32.to_le_bytes()),
                    ("conn", &conn.to_le_bytes()),
                    ("count", &(entries.len() as u32).to_le_bytes()),
                ],
                &data,
            );
        }
        let index_pos = out.len() as u64;
        for id in 0..self.connections.len() as u32 {
            self.connection_record(&mut out, id);
        }
        let chunk_count = u32::from(!self.messages.is_empty() || !self.connections.is_empty());
        if chunk_count == 1 {
            let mut data = Vec::new();
            for (conn, entries) in &per_connection {
                data.extend(conn.to_le_bytes());
                data.extend((entries.len() as u32).to_le_bytes());
            }
            record(
                &mut out,
                &[
                    ("op", &[0x06]),
                    ("ver", &1u32.to_le_bytes()),
                    ("chunk_pos", &chunk_pos.to_le_bytes()),
                    ("start_time", &ros1_time(start)),
                    ("end_time", &ros1_time(end)),
                    ("count", &(per_connection.len() as u32).to_le_bytes()),
                ],
                &data,
            );
        }
        // The bag header record, padded with spaces to its fixed length.
        let mut header = Vec::new();
        record(
            &mut header,
            &[
                ("op", &[0x03]),
                ("index_pos", &index_pos.to_le_bytes()),
                ("conn_count", &(self.connections.len() as u32).to_le_bytes()),
                ("chunk_count", &chunk_count.to_le_bytes()),
            ],
            &[],
        );
        header.truncate(header.len() - 4);
        let padding = HEADER_RECORD_LEN - header.len() - 4;
        header.extend((padding as u32).to_le_bytes());
        header.resize(HEADER_RECORD_LEN, b' ');
        out[header_at..header_at + HEADER_RECORD_LEN].copy_from_slice(&header);
        out
    }
}
