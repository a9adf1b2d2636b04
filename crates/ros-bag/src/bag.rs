//! Opening a bag and walking its messages in file order.

use crate::error::BagError;
use crate::msgs::normalise_type;
use crate::wire::Encoding;
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
use std::collections::HashMap;
use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};

/// The kind of a bag.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum BagFormat {
    /// One ROS 2 `.mcap` file.
    Mcap,
    /// A rosbag2 folder (`metadata.yaml` and its `.mcap` files, read in name order).
    Rosbag2Folder,
    /// A ROS 1 `.bag` file (format 2.0).
    Ros1,
}

impl BagFormat {
    /// A short name for messages.
    pub fn name(self) -> &'static str {
        match self {
            BagFormat::Mcap => "MCAP",
            BagFormat::Rosbag2Folder => "rosbag2 folder (MCAP)",
            BagFormat::Ros1 => "ROS 1 bag",
        }
    }

    /// The encoding of the messages this crate writes in this format.
    pub fn encoding(self) -> Encoding {
        match self {
            BagFormat::Mcap | BagFormat::Rosbag2Folder => Encoding::Cdr,
            BagFormat::Ros1 => Encoding::Ros1,
        }
    }
}

/// One message as stored, borrowed for the duration of a callback.
#[derive(Copy, Clone, Debug)]
pub struct MessageRef<'a> {
    /// The file it is in.
    pub file: &'a Path,
    /// Its topic.
    pub topic: &'a str,
    /// Its type, without ROS 2's `/msg/` (`sensor_msgs/PointCloud2`).
    pub type_name: &'a str,
    /// Its encoding, or `None` for one this crate cannot decode.
    pub encoding: Option<Encoding>,
    /// When it was recorded, in nanoseconds since the epoch.
    pub log_time_ns: u64,
    /// Its serialised bytes.
    pub data: &'a [u8],
    /// Where it is: MCAP, the file position just past its record or the chunk holding it;
    /// ROS 1, the position of its chunk.
    pub offset: u64,
}

/// A bag opened for reading: a `.mcap` file, a rosbag2 folder or a ROS 1 `.bag`.
///
/// rosbag2's SQLite storage (`.db3`) is not read: MCAP is ROS 2's default storage since Iron,
/// and `ros2 bag convert` turns a `.db3` bag into one. Reading SQLite would add a C library
/// build to every user of this crate for a storage format ROS 2 has moved away from.
#[derive(Clone, Debug)]
pub struct Bag {
    path: PathBuf,
    format: BagFormat,
    files: Vec<PathBuf>,
}

/// The longest MCAP record read, relative to the file size: a hostile length cannot make the
/// reader allocate more than this (decompressed chunks may be larger than the file).
fn record_limit(file_len: u64) -> usize {
    file_len.saturating_mul(16).clamp(1 << 20, 4 << 30) as usize
}

impl Bag {
    /// Opens `path`: a `.mcap` file, a folder holding `.mcap` files (a rosbag2 folder), or a
    /// `.bag` file. Nothing but the folder listing and, for ROS 1, the bag header is read yet.
    pub fn open(path: impl AsRef<Path>) -> Result<Bag, BagError> {
        let path = path.as_ref().to_owned();
        let io = |e| BagError::Io { path: path.clone(), source: e };
        if path.is_dir() {
            let mut mcaps = Vec::new();
            let mut db3 = false;
            for entry in std::fs::read_dir(&path).map_err(io)? {
                let p = entry.map_err(io)?.path();
                match p.extension().and_then(|e| e.to_str()) {
                    Some("mcap") => mcaps.push(p),
                    Some("db3") => db3 = true,
                    _ => {}
                }
            }
            mcaps.sort();
            if mcaps.is_empty() {
                return Err(if db3 {
                    BagError::Db3 { path }
                } else {
                    BagError::NotABag { path, reason: "a folder without .mcap files".into() }
                });
            }
            return Ok(Bag { path, format: BagFormat::Rosbag2Folder, files: mcaps });
        }
        let format = match path.extension().and_then(|e| e.to_str()) {
            Some("mcap") => BagFormat::Mcap,
            Some("bag") => BagFormat::Ros1,
            Some("db3") => return Err(BagError::Db3 { path }),
            _ => {
                return Err(BagError::NotABag {
                    path,
                    reason: "not a .mcap or .bag file, nor a rosbag2 folder".into(),
                });
            }
        };
        File::open(&path).map_err(io)?;
        Ok(Bag { files: vec![path.clone()], path, format })
    }

    /// The path given to [`Bag::open`].
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// What kind of bag this is.
    pub fn format(&self) -> BagFormat {
        self.format
    }

    /// The files holding the messages.
    pub fn files(&self) -> &[PathBuf] {
        &self.files
    }

    /// Calls `f` with every message, in file order, stopping at the first error (of the bag or
    /// of `f`).
    ///
    /// # Errors
    /// [`BagError::Container`] with the file position for a truncated or corrupt bag;
    /// whatever `f` returns.
    pub fn for_each_message(
        &self,
        mut f: impl FnMut(&MessageRef<'_>) -> Result<(), BagError>,
    ) -> Result<(), BagError> {
        for file in &self.files {
            match self.format {
                BagFormat::Mcap | BagFormat::Rosbag2Folder => read_mcap(file, &mut f)?,
                BagFormat::Ros1 => read_ros1(file, &mut f)?,
            }
        }
        Ok(())
    }
}

fn encoding_of(name: &str) -> Option<Encoding> {
    match name {
        "cdr" => Some(Encoding::Cdr),
        "ros1" => Some(Encoding::Ros1),
        _ => None,
    }
}

/// The schemas and channels seen so far in an MCAP file.
#[derive(Default)]
struct McapState {
    schemas: HashMap<u16, String>,
    /// channel id → (topic, type, encoding)
    channels: HashMap<u16, (String, String, Option<Encoding>)>,
}

/// One record outside or inside a chunk; `offset` is the file position past it (or its chunk).
fn mcap_record(
    path: &Path,
    state: &mut McapState,
    record: mcap::records::Record<'_>,
    offset: u64,
    limit: usize,
    f: &mut dyn FnMut(&MessageRef<'_>) -> Result<(), BagError>,
) -> Result<(), BagError> {
    let container = |reason: String| BagError::Container { path: path.to_owned(), offset, reason };
    match record {
        mcap::records::Record::Schema { header, .. } => {
            state.schemas.insert(header.id, normalise_type(&header.name));
        }
        mcap::records::Record::Channel(c) => {
            let type_name = state.schemas.get(&c.schema_id).cloned().unwrap_or_default();
            let encoding = encoding_of(&c.message_encoding);
            state.channels.insert(c.id, (c.topic, type_name, encoding));
        }
        mcap::records::Record::Message { header, data } => {
            let (topic, type_name, encoding) =
                state.channels.get(&header.channel_id).ok_or_else(|| {
                    container(format!("message on unknown channel {}", header.channel_id))
                })?;
            f(&MessageRef {
                file: path,
                topic,
                type_name,
                encoding: *encoding,
                log_time_ns: header.log_time,
                data: &data,
                offset,
            })?;
        }
        mcap::records::Record::Chunk { header, data } => {
            if header.compression.is_empty() {
                // Uncompressed records are walked here, every length checked against the chunk.
                let mut rest: &[u8] = &data;
                while !rest.is_empty() {
                    let Some((&opcode, tail)) = rest.split_first() else { break };
                    let len = tail
                        .get(..8)
                        .map(|b| u64::from_le_bytes(b.try_into().unwrap_or_default()))
                        .ok_or_else(|| container("a chunk record without its length".into()))?;
                    let body = usize::try_from(len)
                        .ok()
                        .and_then(|n| tail.get(8..8usize.checked_add(n)?))
                        .ok_or_else(|| {
                            container(format!("a chunk record of {len} bytes beyond its chunk"))
                        })?;
                    let record =
                        mcap::parse_record(opcode, body).map_err(|e| container(e.to_string()))?;
                    mcap_record(path, state, record, offset, limit, f)?;
                    rest = &tail[8 + body.len()..];
                }
            } else {
                if header.uncompressed_size > limit as u64 {
                    return Err(container(format!(
                        "a chunk claims {} bytes uncompressed",
                        header.uncompressed_size
                    )));
                }
                let chunk = mcap::read::ChunkReader::new(header, &data)
                    .map_err(|e| container(e.to_string()))?;
                for record in chunk {
                    let record = record.map_err(|e| container(e.to_string()))?;
                    mcap_record(path, state, record, offset, limit, f)?;
                }
            }
        }
        _ => {}
    }
    Ok(())
}

fn read_mcap(
    path: &Path,
    f: &mut dyn FnMut(&MessageRef<'_>) -> Result<(), BagError>,
) -> Result<(), BagError> {
    let io = |e| BagError::Io { path: path.to_owned(), source: e };
    let mut file = File::open(path).map_err(io)?;
    let len = file.metadata().map_err(io)?.len();
    let limit = record_limit(len);
    // Chunks come whole and are unpacked in `mcap_record`: the reader's own walk through an
    // uncompressed chunk trusts record lengths (an overflow on a corrupt one).
    let options =
        LinearReaderOptions::default().with_record_length_limit(limit).with_emit_chunks(true);
    let mut reader = LinearReader::new_with_options(options);
    let mut fed = 0u64;
    let mut state = McapState::default();
    let container =
        |offset: u64, reason: String| BagError::Container { path: path.to_owned(), offset, reason };
    while let Some(event) = reader.next_event() {
        match event.map_err(|e| container(fed, e.to_string()))? {
            LinearReadEvent::ReadRequest(n) => {
                let buf = reader.insert(n);
                let read = file.read(buf).map_err(io)?;
                reader.notify_read(read);
                fed += read as u64;
            }
            LinearReadEvent::Record { data, opcode } => {
                let record =
                    mcap::parse_record(opcode, data).map_err(|e| container(fed, e.to_string()))?;
                mcap_record(path, &mut state, record, fed, limit, f)?;
            }
        }
    }
    Ok(())
}

/// The end of the ROS 1 bag header record and the header's `index_pos`, checked against the
/// file length: the `rosbag` crate slices the file by them.
fn ros1_index_pos(path: &Path, len: u64) -> Result<(u64, u64), BagError> {
    let io = |e| BagError::Io { path: path.to_owned(), source: e };
    let container = |offset: u64, reason: &str| BagError::Container {
        path: path.to_owned(),
        offset,
        reason: reason.to_owned(),
    };
    let mut head = Vec::new();
    File::open(path).map_err(io)?.take(1 << 16).read_to_end(&mut head).map_err(io)?;
    const MAGIC: &[u8] = b"#ROSBAG V2.0\n";
    if !head.starts_with(MAGIC) {
        return Err(container(0, "not a ROS 1 bag of version 2.0 (no #ROSBAG V2.0 line)"));
    }
    let u32_at = |at: usize| -> Option<usize> {
        Some(u32::from_le_bytes(head.get(at..at + 4)?.try_into().ok()?) as usize)
    };
    let m = MAGIC.len();
    let header_len = u32_at(m).ok_or_else(|| container(m as u64, "truncated bag header"))?;
    let fields = head
        .get(m + 4..m + 4 + header_len)
        .ok_or_else(|| container(m as u64, "truncated bag header"))?;
    let data_at = m + 4 + header_len;
    let data_len =
        u32_at(data_at).ok_or_else(|| container(data_at as u64, "truncated bag header"))?;
    let start = (data_at + 4 + data_len) as u64;
    let mut index_pos = None;
    let mut rest = fields;
    while rest.len() >= 4 {
        let n = u32::from_le_bytes(rest[..4].try_into().unwrap_or_default()) as usize;
        let Some(field) = rest.get(4..4 + n) else { break };
        if let Some(v) = field.strip_prefix(b"index_pos=")
            && let Ok(b) = <[u8; 8]>::try_from(v)
        {
            index_pos = Some(u64::from_le_bytes(b));
        }
        rest = &rest[4 + n..];
    }
    let index_pos = index_pos.ok_or_else(|| container(m as u64, "bag header without index_pos"))?;
    if index_pos == 0 {
        return Err(container(
            m as u64,
            "the bag has no index (its recording was interrupted); reindex it first",
        ));
    }
    if start > len || index_pos < start || index_pos > len {
        return Err(BagError::Container {
            path: path.to_owned(),
            offset: len,
            reason: format!(
                "truncated: the index starts at byte {index_pos} but the file has {len} bytes"
            ),
        });
    }
    Ok((start, index_pos))
}

/// Walks the record headers of the chunk section and refuses a chunk whose declared
/// uncompressed size is out of proportion to its data: the `rosbag` crate reserves that size
/// before decompressing.
fn check_ros1_chunks(path: &Path, start: u64, index_pos: u64) -> Result<(), BagError> {
    use std::io::{Seek, SeekFrom};
    let io = |e| BagError::Io { path: path.to_owned(), source: e };
    let container =
        |offset: u64, reason: String| BagError::Container { path: path.to_owned(), offset, reason };
    let mut file = File::open(path).map_err(io)?;
    let mut at = start;
    let mut word = [0u8; 4];
    while at < index_pos {
        file.seek(SeekFrom::Start(at)).map_err(io)?;
        file.read_exact(&mut word).map_err(|_| container(at, "truncated record".into()))?;
        let header_len = u32::from_le_bytes(word) as u64;
        if at + 8 + header_len > index_pos {
            return Err(container(at, format!("a record header of {header_len} bytes")));
        }
        let mut header = vec![0u8; header_len as usize];
        file.read_exact(&mut header).map_err(|_| container(at, "truncated record".into()))?;
        file.read_exact(&mut word).map_err(|_| container(at, "truncated record".into()))?;
        let data_len = u32::from_le_bytes(word) as u64;
        let mut size = None;
        let mut rest = &header[..];
        while rest.len() >= 4 {
            let n = u32::from_le_bytes([rest[0], rest[1], rest[2], rest[3]]) as usize;
            let Some(field) = rest.get(4..4 + n) else { break };
            if let Some(v) = field.strip_prefix(b"size=")
                && let Ok(b) = <[u8; 4]>::try_from(v)
            {
                size = Some(u32::from_le_bytes(b) as u64);
            }
            rest = &rest[4 + n..];
        }
        if let Some(size) = size
            && size > data_len.saturating_mul(1024) + (1 << 20)
        {
            return Err(container(
                at,
                format!("a chunk claims {size} bytes uncompressed from {data_len} bytes"),
            ));
        }
        at += 8 + header_len + data_len;
    }
    Ok(())
}

fn read_ros1(
    path: &Path,
    f: &mut dyn FnMut(&MessageRef<'_>) -> Result<(), BagError>,
) -> Result<(), BagError> {
    let io = |e| BagError::Io { path: path.to_owned(), source: e };
    let len = std::fs::metadata(path).map_err(io)?.len();
    let (start, index_pos) = ros1_index_pos(path, len)?;
    check_ros1_chunks(path, start, index_pos)?;
    let container =
        |offset: u64, reason: String| BagError::Container { path: path.to_owned(), offset, reason };
    let bag = rosbag::RosBag::new(path).map_err(|e| container(0, e.to_string()))?;
    let mut chunk_positions = Vec::new();
    let mut connections: HashMap<u32, (String, String)> = HashMap::new();
    for record in bag.index_records() {
        match record.map_err(|e| container(index_pos, format!("index section: {e}")))? {
            rosbag::IndexRecord::ChunkInfo(info) => chunk_positions.push(info.chunk_pos),
            rosbag::IndexRecord::Connection(c) => {
                connections.insert(c.id, (c.topic.to_owned(), normalise_type(c.tp)));
            }
            rosbag::IndexRecord::IndexData(_) => {}
        }
    }
    chunk_positions.sort_unstable();
    let mut chunk = 0usize;
    for record in bag.chunk_records() {
        let at = chunk_positions.get(chunk).copied().unwrap_or(index_pos);
        let rosbag::ChunkRecord::Chunk(c) =
            record.map_err(|e| container(at, format!("chunk section: {e}")))?
        else {
            continue;
        };
        chunk += 1;
        for m in c.messages() {
            match m.map_err(|e| container(at, format!("chunk: {e}")))? {
                rosbag::MessageRecord::Connection(c) => {
                    connections.insert(c.id, (c.topic.to_owned(), normalise_type(c.tp)));
                }
                rosbag::MessageRecord::MessageData(m) => {
                    let (topic, type_name) = connections.get(&m.conn_id).ok_or_else(|| {
                        container(at, format!("message on unknown connection {}", m.conn_id))
                    })?;
                    f(&MessageRef {
                        file: path,
                        topic,
                        type_name,
                        encoding: Some(Encoding::Ros1),
                        log_time_ns: m.time,
                        data: m.data,
                        offset: at,
                    })?;
                }
            }
        }
    }
    Ok(())
}
