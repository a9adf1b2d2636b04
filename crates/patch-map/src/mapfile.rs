//! Map files: a fixed little-endian header, then the map serialised with serde and `bincode`.
//!
//! ```text
//! offset  size  field
//!      0     8  magic "PATCHMAP"
//!      8     4  format version (u32) — this crate writes and reads FORMAT_VERSION
//!     12    16  backend tag, ASCII, zero padded ("polygon", "bbox6d", "trimesh", ...)
//!     28     8  planar patches (u64)
//!     36     8  trimesh patches (u64)
//!     44     8  triangles (u64)
//!     52     8  points (u64)
//!     60     8  payload length in bytes (u64)
//!     68     4  CRC-32 of the payload
//!     72     4  CRC-32 of bytes 0..72 (the header itself)
//!     76     …  payload: bincode 2 (standard configuration) of the map's serde form
//! ```
//!
//! Reading checks, in order: the magic, the version (a newer file is
//! [`MapFileError::UnsupportedVersion`], never misread), the header checksum, the payload length
//! against the bytes present, the payload checksum, then decodes. Decoding goes through the
//! types' validating `Deserialize` impls, so a file cannot smuggle in an invalid patch. Nothing is
//! allocated for a declared length before the bytes have been read.

use serde::Serialize;
use serde::de::DeserializeOwned;
use std::io::{Read, Write};

/// The first eight bytes of every map file.
pub const MAGIC: [u8; 8] = *b"PATCHMAP";
/// The format version this crate writes and the only one it reads.
pub const FORMAT_VERSION: u32 = 1;
/// Header length in bytes.
pub const HEADER_LEN: usize = 76;
const TAG_LEN: usize = 16;

/// What a map holds, as recorded in its file header (and printed by `patchnav map info`).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct MapCounts {
    /// Planar patches.
    pub planar_patches: u64,
    /// Triangle-mesh patches.
    pub trimesh_patches: u64,
    /// Triangles (of the trimesh patches, plus those a backend made from planar patches).
    pub triangles: u64,
    /// Points (point-cloud maps).
    pub points: u64,
}

/// The decoded header of a map file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MapFileHeader {
    /// The format version of the file.
    pub version: u32,
    /// The backend that wrote the map.
    pub backend: String,
    /// What the map holds.
    pub counts: MapCounts,
    /// Payload length in bytes.
    pub payload_len: u64,
    /// CRC-32 of the payload.
    pub payload_crc32: u32,
}

/// Why a map file could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum MapFileError {
    /// The operating system refused.
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// The file does not start with the magic bytes.
    #[error("not a patch map file (magic {found:02x?}, expected \"PATCHMAP\")")]
    BadMagic {
        /// The first bytes found.
        found: Vec<u8>,
    },
    /// The file was written by a newer (or unknown) format version.
    #[error(
        "map file format version {found} is not supported (this build reads version {supported})"
    )]
    UnsupportedVersion {
        /// The file's version.
        found: u32,
        /// The version this build reads.
        supported: u32,
    },
    /// The header's own checksum does not match: the header is corrupt.
    #[error("map file header is corrupt (checksum mismatch)")]
    HeaderChecksum,
    /// The file ends before the header or the payload does.
    #[error("map file is truncated: {what} needs {expected} bytes, {found} present")]
    Truncated {
        /// The part that is cut.
        what: &'static str,
        /// Bytes needed.
        expected: u64,
        /// Bytes present.
        found: u64,
    },
    /// Bytes follow the payload.
    #[error("map file has {0} unexpected bytes after the payload")]
    TrailingBytes(u64),
    /// The payload's checksum does not match: the payload is corrupt.
    #[error("map file payload is corrupt (CRC-32 {found:08x}, header says {expected:08x})")]
    PayloadChecksum {
        /// The checksum in the header.
        expected: u32,
        /// The checksum of the bytes read.
        found: u32,
    },
    /// The file holds a map of another backend.
    #[error("map file holds a `{found}` map, expected `{expected}`")]
    BackendMismatch {
        /// The backend asked for.
        expected: String,
        /// The backend in the file.
        found: String,
    },
    /// The file holds a map of a backend this build does not know.
    #[error("map file holds a `{found}` map, which this build cannot load")]
    UnknownBackend {
        /// The backend in the file.
        found: String,
    },
    /// The backend tag is empty, not printable ASCII, or longer than 16 bytes.
    #[error("bad backend tag {0:?}")]
    BadTag(String),
    /// The payload passed its checksum but does not decode (or decodes to invalid data).
    #[error("map file payload does not decode: {0}")]
    Decode(String),
    /// The map could not be encoded.
    #[error("map could not be encoded: {0}")]
    Encode(String),
}

fn config() -> impl bincode::config::Config {
    bincode::config::standard()
}

/// Writes `payload` as a map file of `backend` with the given counts; returns the bytes written.
pub fn write_map<T: Serialize>(
    writer: impl Write,
    backend: &str,
    counts: MapCounts,
    payload: &T,
) -> Result<u64, MapFileError> {
    if backend.is_empty()
        || backend.len() > TAG_LEN
        || !backend.bytes().all(|b| b.is_ascii_graphic())
    {
        return Err(MapFileError::BadTag(backend.to_owned()));
    }
    // Two passes, so the body is never held in memory (a map of millions of triangles encodes
    // to hundreds of MB): the first only counts and checksums the bytes the second writes.
    let mut digest = Digest { len: 0, crc: crc32fast::Hasher::new() };
    bincode::serde::encode_into_std_write(payload, &mut digest, config())
        .map_err(|e| MapFileError::Encode(e.to_string()))?;
    let (body_len, body_crc) = (digest.len, digest.crc.finalize());
    let mut header = Vec::with_capacity(HEADER_LEN);
    header.extend_from_slice(&MAGIC);
    header.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    let mut tag = [0u8; TAG_LEN];
    tag[..backend.len()].copy_from_slice(backend.as_bytes());
    header.extend_from_slice(&tag);
    for v in [counts.planar_patches, counts.trimesh_patches, counts.triangles, counts.points] {
        header.extend_from_slice(&v.to_le_bytes());
    }
    header.extend_from_slice(&body_len.to_le_bytes());
    header.extend_from_slice(&body_crc.to_le_bytes());
    let header_crc = crc32fast::hash(&header);
    header.extend_from_slice(&header_crc.to_le_bytes());
    debug_assert_eq!(header.len(), HEADER_LEN);
    let mut out = std::io::BufWriter::new(writer);
    out.write_all(&header)?;
    let written = bincode::serde::encode_into_std_write(payload, &mut out, config())
        .map_err(|e| MapFileError::Encode(e.to_string()))?;
    if written as u64 != body_len {
        return Err(MapFileError::Encode(format!(
            "the payload encoded to {written} bytes, {body_len} the first time"
        )));
    }
    out.flush()?;
    Ok(HEADER_LEN as u64 + body_len)
}

/// Counts and checksums the bytes written to it.
struct Digest {
    len: u64,
    crc: crc32fast::Hasher,
}

impl Write for Digest {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.len += buf.len() as u64;
        self.crc.update(buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Reads exactly `buf.len()` bytes, or reports how many were there.
fn read_full(reader: &mut impl Read, buf: &mut [u8]) -> Result<usize, std::io::Error> {
    let mut filled = 0;
    while filled < buf.len() {
        match reader.read(&mut buf[filled..]) {
            Ok(0) => break,
            Ok(n) => filled += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(filled)
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap_or([0; 4]))
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().unwrap_or([0; 8]))
}

/// Reads and checks the header of a map file (and nothing more).
pub fn read_header(mut reader: impl Read) -> Result<MapFileHeader, MapFileError> {
    let mut h = [0u8; HEADER_LEN];
    let n = read_full(&mut reader, &mut h)?;
    if h[..n.min(8)] != MAGIC[..n.min(8)] || n == 0 {
        return Err(MapFileError::BadMagic { found: h[..n.min(8)].to_vec() });
    }
    if n < 12 {
        return Err(MapFileError::Truncated {
            what: "header",
            expected: HEADER_LEN as u64,
            found: n as u64,
        });
    }
    let version = u32_at(&h, 8);
    if version != FORMAT_VERSION {
        return Err(MapFileError::UnsupportedVersion { found: version, supported: FORMAT_VERSION });
    }
    if n < HEADER_LEN {
        return Err(MapFileError::Truncated {
            what: "header",
            expected: HEADER_LEN as u64,
            found: n as u64,
        });
    }
    if crc32fast::hash(&h[..72]) != u32_at(&h, 72) {
        return Err(MapFileError::HeaderChecksum);
    }
    let tag = &h[12..12 + TAG_LEN];
    let end = tag.iter().position(|&b| b == 0).unwrap_or(TAG_LEN);
    let backend = String::from_utf8_lossy(&tag[..end]).into_owned();
    Ok(MapFileHeader {
        version,
        backend,
        counts: MapCounts {
            planar_patches: u64_at(&h, 28),
            trimesh_patches: u64_at(&h, 36),
            triangles: u64_at(&h, 44),
            points: u64_at(&h, 52),
        },
        payload_len: u64_at(&h, 60),
        payload_crc32: u32_at(&h, 68),
    })
}

/// Reads a whole map file: checks the header and the payload, then decodes the payload. With
/// `expected_backend`, a file of another backend is [`MapFileError::BackendMismatch`].
pub fn read_map<T: DeserializeOwned>(
    mut reader: impl Read,
    expected_backend: Option<&str>,
) -> Result<(MapFileHeader, T), MapFileError> {
    let header = read_header(&mut reader)?;
    if let Some(expected) = expected_backend
        && expected != header.backend
    {
        return Err(MapFileError::BackendMismatch {
            expected: expected.to_owned(),
            found: header.backend,
        });
    }
    // `take` bounds the read; the buffer grows with the bytes actually present.
    let mut body = Vec::new();
    let _ = (&mut reader).take(header.payload_len).read_to_end(&mut body)?;
    if (body.len() as u64) < header.payload_len {
        return Err(MapFileError::Truncated {
            what: "payload",
            expected: header.payload_len,
            found: body.len() as u64,
        });
    }
    let mut rest = Vec::new();
    let trailing = reader.take(1 << 20).read_to_end(&mut rest)?;
    if trailing > 0 {
        return Err(MapFileError::TrailingBytes(trailing as u64));
    }
    let found = crc32fast::hash(&body);
    if found != header.payload_crc32 {
        return Err(MapFileError::PayloadChecksum { expected: header.payload_crc32, found });
    }
    let (value, used) = bincode::serde::decode_from_slice(&body, config())
        .map_err(|e| MapFileError::Decode(e.to_string()))?;
    if used != body.len() {
        return Err(MapFileError::Decode(format!(
            "{} of {} payload bytes left undecoded",
            body.len() - used,
            body.len()
        )));
    }
    Ok((header, value))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[derive(Debug, PartialEq, serde::Serialize, serde::Deserialize)]
    struct Payload {
        name: String,
        values: Vec<f64>,
    }

    fn sample() -> (Vec<u8>, Payload) {
        let p = Payload { name: "walls".into(), values: vec![1.0, -2.5, f64::MAX] };
        let counts = MapCounts { planar_patches: 3, trimesh_patches: 1, triangles: 9, points: 0 };
        let mut buf = Vec::new();
        let n = write_map(&mut buf, "polygon", counts, &p).unwrap();
        assert_eq!(n as usize, buf.len());
        (buf, p)
    }

    #[test]
    fn round_trip_keeps_header_and_payload() {
        let (buf, p) = sample();
        let (h, back): (_, Payload) = read_map(&buf[..], Some("polygon")).unwrap();
        assert_eq!(back, p);
        assert_eq!(h.backend, "polygon");
        assert_eq!(h.version, FORMAT_VERSION);
        assert_eq!(h.counts.triangles, 9);
        assert_eq!(read_header(&buf[..]).unwrap(), h);
    }

    #[test]
    fn every_prefix_is_an_error() {
        let (buf, _) = sample();
        for cut in 0..buf.len() {
            let r: Result<(_, Payload), _> = read_map(&buf[..cut], None);
            assert!(r.is_err(), "prefix of {cut} bytes was accepted");
        }
    }

    #[test]
    fn corruption_is_detected_by_kind() {
        let (buf, _) = sample();
        let read = |b: &[u8]| read_map::<Payload>(b, None).unwrap_err();
        let mut b = buf.clone();
        b[0] = b'X';
        assert!(matches!(read(&b), MapFileError::BadMagic { .. }));
        let mut b = buf.clone();
        b[8..12].copy_from_slice(&2u32.to_le_bytes());
        assert!(matches!(
            read(&b),
            MapFileError::UnsupportedVersion { found: 2, supported: FORMAT_VERSION }
        ));
        let mut b = buf.clone();
        b[30] ^= 1; // a count
        assert!(matches!(read(&b), MapFileError::HeaderChecksum));
        let mut b = buf.clone();
        let last = b.len() - 1;
        b[last] ^= 0x40;
        assert!(matches!(read(&b), MapFileError::PayloadChecksum { .. }));
        let mut b = buf.clone();
        b.push(0);
        assert!(matches!(read(&b), MapFileError::TrailingBytes(1)));
        assert!(matches!(
            read_map::<Payload>(&buf[..], Some("trimesh")).unwrap_err(),
            MapFileError::BackendMismatch { .. }
        ));
    }

    #[test]
    fn a_checksummed_but_wrong_payload_is_a_decode_error() {
        // A valid container whose payload is not a `Payload`.
        let mut buf = Vec::new();
        write_map(&mut buf, "polygon", MapCounts::default(), &(7u8, 9u8)).unwrap();
        assert!(matches!(read_map::<Payload>(&buf[..], None), Err(MapFileError::Decode(_))));
    }

    #[test]
    fn bad_tags_are_refused() {
        let p = Payload { name: String::new(), values: vec![] };
        for tag in ["", "a tag with spaces", "seventeen-bytes-x", "ünicode"] {
            let r = write_map(Vec::new(), tag, MapCounts::default(), &p);
            assert!(matches!(r, Err(MapFileError::BadTag(_))), "{tag:?}");
        }
    }

    proptest! {
        #[test]
        fn random_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..200)) {
            let _ = read_map::<Payload>(&bytes[..], None);
        }

        #[test]
        fn random_flips_are_errors(flip in 0usize..10_000, bit in 0u8..8) {
            let (mut buf, _) = sample();
            let i = flip % buf.len();
            buf[i] ^= 1 << bit;
            prop_assert!(read_map::<Payload>(&buf[..], None).is_err());
        }
    }
}
