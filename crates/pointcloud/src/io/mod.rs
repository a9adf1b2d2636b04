//! Readers and writers for point-cloud, mesh and depth-image files.
//!
//! | format | module | read | write | notes |
//! |---|---|---|---|---|
//! | PLY | [`ply`] | ascii, binary LE/BE, any numeric type | ascii, binary LE/BE | extra properties kept; `comment organized W H` keeps the image |
//! | PCD v0.7 | [`pcd`] | ascii, binary, binary_compressed (LZF) | all three | `WIDTH × HEIGHT` organised clouds kept |
//! | OBJ | [`obj`] | `v` and `f` (polygons kept or triangulated) | `v` and `f` | |
//! | XYZ | [`xyz`] | `x y z [intensity]` text | same | |
//! | KITTI / Ouster `.bin` | [`kitti`] | float32 `x y z i` | same | |
//! | 3DTK `.3d` + `.pose` | [`uos`] | cm, left-handed → m, right-handed | same | |
//! | 16-bit PNG depth | [`depth_png`] | with pinhole intrinsics and a depth scale | same | |
//!
//! Every reader returns a typed [`Error`] naming the file position (line or byte offset) on
//! corrupt input, truncation, a header that lies about the point count, or a non-finite value;
//! none panics, and none allocates more than the input can fill (declared counts are checked
//! against the bytes that are there before memory is reserved).
//!
//! [`read_cloud`] and [`write_cloud`] pick the format from the file extension.

use crate::AttributeError;
use std::fmt;
use std::path::{Path, PathBuf};

pub mod depth_png;
pub mod kitti;
pub(crate) mod lzf;
pub mod obj;
pub mod pcd;
pub mod ply;
pub mod uos;
pub mod xyz;

/// The file formats this crate reads and writes.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    /// Stanford polygon file format.
    Ply,
    /// Point Cloud Library PCD v0.7.
    Pcd,
    /// Wavefront OBJ (vertices and faces).
    Obj,
    /// Plain text `x y z [intensity]` per line.
    Xyz,
    /// KITTI / Ouster style little-endian float32 `x y z intensity` records.
    KittiBin,
    /// 3DTK "uos" `.3d` scans (and `.pose` files).
    Uos,
    /// 16-bit PNG depth image.
    DepthPng,
}

impl Format {
    /// The format for a file extension (case-insensitive), if known: `ply`, `pcd`, `obj`,
    /// `xyz`/`txt`, `bin`, `3d`, `png`.
    pub fn from_extension(ext: &str) -> Option<Format> {
        Some(match ext.to_ascii_lowercase().as_str() {
            "ply" => Format::Ply,
            "pcd" => Format::Pcd,
            "obj" => Format::Obj,
            "xyz" | "txt" => Format::Xyz,
            "bin" => Format::KittiBin,
            "3d" => Format::Uos,
            "png" => Format::DepthPng,
            _ => return None,
        })
    }

    /// The format of a path, from its extension.
    pub fn from_path(path: &Path) -> Option<Format> {
        Format::from_extension(path.extension()?.to_str()?)
    }

    /// A short human name.
    pub fn name(self) -> &'static str {
        match self {
            Format::Ply => "PLY",
            Format::Pcd => "PCD",
            Format::Obj => "OBJ",
            Format::Xyz => "XYZ",
            Format::KittiBin => "KITTI bin",
            Format::Uos => "3DTK uos",
            Format::DepthPng => "PNG depth",
        }
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Where in a file something went wrong.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Position {
    /// A 1-based line of a text file or text header.
    Line(u64),
    /// A 0-based byte offset into the file.
    Byte(u64),
}

impl fmt::Display for Position {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Position::Line(l) => write!(f, "line {l}"),
            Position::Byte(b) => write!(f, "byte {b}"),
        }
    }
}

/// What went wrong while reading or writing a file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ErrorKind {
    /// The operating system refused to read or write.
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// The file ended early.
    #[error("unexpected end of file: expected {expected}")]
    UnexpectedEof {
        /// What was still expected.
        expected: String,
    },
    /// The header is malformed.
    #[error("bad header: {0}")]
    BadHeader(String),
    /// A value could not be parsed or is out of range.
    #[error("bad value: {0}")]
    BadValue(String),
    /// A coordinate is NaN or infinite in an unorganised cloud (organised clouds mark such
    /// pixels invalid instead; see [`ReadOptions::skip_non_finite`]).
    #[error("point {point} has a non-finite coordinate")]
    NonFinite {
        /// The index of the point in the file.
        point: u64,
    },
    /// The header declares a different number of elements than the data holds.
    #[error("header declares {declared} {what} but the data hold {found}")]
    CountMismatch {
        /// What is counted.
        what: &'static str,
        /// The declared count.
        declared: u64,
        /// The count found.
        found: u64,
    },
    /// A valid file that uses something this reader does not support.
    #[error("unsupported: {0}")]
    Unsupported(String),
    /// The data read do not form a valid cloud.
    #[error(transparent)]
    Attribute(#[from] AttributeError),
}

/// A read or write failure, with the format and, where known, the file and the position.
#[derive(Debug)]
pub struct Error {
    /// The format being read or written.
    pub format: Format,
    /// The file, when reading or writing by path.
    pub path: Option<PathBuf>,
    /// Where in the file, when known.
    pub position: Option<Position>,
    /// What went wrong.
    pub kind: ErrorKind,
}

impl Error {
    /// An error at a position.
    pub fn at(format: Format, position: Position, kind: impl Into<ErrorKind>) -> Error {
        Error { format, path: None, position: Some(position), kind: kind.into() }
    }

    /// An error without a position.
    pub fn new(format: Format, kind: impl Into<ErrorKind>) -> Error {
        Error { format, path: None, position: None, kind: kind.into() }
    }

    /// The same error, naming `path`.
    pub fn with_path(mut self, path: &Path) -> Error {
        self.path = Some(path.to_owned());
        self
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.path {
            Some(p) => write!(f, "{} ({})", p.display(), self.format)?,
            None => write!(f, "{}", self.format)?,
        }
        if let Some(pos) = self.position {
            write!(f, ", {pos}")?;
        }
        write!(f, ": {}", self.kind)
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match &self.kind {
            ErrorKind::Io(e) => Some(e),
            ErrorKind::Attribute(e) => Some(e),
            _ => None,
        }
    }
}

/// Options shared by the cloud readers.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct ReadOptions {
    /// In an *unorganised* cloud, drop points with a NaN or infinite coordinate instead of
    /// failing with [`ErrorKind::NonFinite`]. Organised clouds always keep such pixels, as
    /// explicit invalid pixels.
    pub skip_non_finite: bool,
}

impl ReadOptions {
    /// Strict reading: a non-finite point in an unorganised cloud is an error.
    pub const STRICT: ReadOptions = ReadOptions { skip_non_finite: false };
    /// Lenient reading: non-finite points of unorganised clouds are dropped.
    pub const SKIP_NON_FINITE: ReadOptions = ReadOptions { skip_non_finite: true };
}

/// The floating-point width used for positions when writing.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Precision {
    /// 32-bit floats (what most tools expect; about 0.1 mm at 1 km).
    F32,
    /// 64-bit floats (exact round trip of our `f64` positions).
    F64,
}
