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
//! | ROS `sensor_msgs/PointCloud2` data | [`pointcloud2`] | any field layout, float32/float64, either byte order, organised | same, in a chosen layout | a message's fields and bytes, no bag format |
//!
//! Every reader returns a typed [`Error`] naming the file position (line or byte offset) on
//! corrupt input, truncation, a header that lies about the point count, or a non-finite value;
//! none panics, and none allocates more than the input can fill (declared counts are checked
//! against the bytes that are there before memory is reserved).
//!
//! [`read_cloud`] and [`write_cloud`] pick the format from the file extension.
//!
//! Every file is written through [`write_atomically`] (or [`write_bytes_atomically`]): into a
//! temporary file beside the target, synced, then renamed over it, so an interrupted or failed
//! write leaves the old file intact. The workspace's programs write their outputs through it too.

use crate::AttributeError;
use std::fmt;
use std::path::{Path, PathBuf};

mod atomic;
pub mod depth_png;
pub mod kitti;
pub(crate) mod lzf;
pub mod obj;
pub mod pcd;
pub mod ply;
pub mod pointcloud2;
pub mod uos;
pub mod xyz;

pub use atomic::{WriteError, WriteStep, write_atomically, write_bytes_atomically};

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
    /// The format being read or written (`None` when the file's format is unknown).
    pub format: Option<Format>,
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
        Error { format: Some(format), path: None, position: Some(position), kind: kind.into() }
    }

    /// An error without a position.
    pub fn new(format: Format, kind: impl Into<ErrorKind>) -> Error {
        Error { format: Some(format), path: None, position: None, kind: kind.into() }
    }

    /// The same error, naming `path`.
    pub fn with_path(mut self, path: &Path) -> Error {
        self.path = Some(path.to_owned());
        self
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (&self.path, self.format) {
            (Some(p), Some(format)) => write!(f, "{} ({format})", p.display())?,
            (Some(p), None) => write!(f, "{}", p.display())?,
            (None, Some(format)) => write!(f, "{format}")?,
            (None, None) => write!(f, "file")?,
        }
        if let Some(pos) = self.position {
            write!(f, ", {pos}")?;
        }
        write!(f, ": {}", self.kind)
    }
}

/// A failure of [`write_atomically`] itself, as an [`ErrorKind::Io`] naming the file.
impl From<WriteError> for Error {
    fn from(e: WriteError) -> Error {
        let io = std::io::Error::new(e.error.kind(), format!("{}: {}", e.step, e.error));
        Error { format: None, path: Some(e.path), position: None, kind: ErrorKind::Io(io) }
    }
}

/// The message already contains the underlying cause ([`ErrorKind`]), so `source` is empty: a
/// chain printer (such as `anyhow`'s `{:#}`) shows it once.
impl std::error::Error for Error {}

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

// Path-level entry points: the format comes from the file extension.

/// Reads the cloud stored in `path`, with the reader its extension names
/// ([`Format::from_path`]):
///
/// | extension | reader | notes |
/// |---|---|---|
/// | `.ply` | [`ply::read_ply`] | |
/// | `.pcd` | [`pcd::read_pcd`] | |
/// | `.obj` | [`obj::read_obj`] | the mesh's vertices (faces dropped; see [`read_mesh`]) |
/// | `.xyz`, `.txt` | [`xyz::read_xyz`] | |
/// | `.bin` | [`kitti::read_kitti_bin`] | unorganised; all-zero records ("no return") dropped |
/// | `.3d` | [`uos::read_uos_scan`] | every point kept (no range filter); the sibling `.pose` file, if there is one, becomes the [`crate::PointCloud::sensor_pose`] |
/// | `.png` | [`read_range_image`] with the camera of [`depth_camera_for`] | the organised cloud in the camera's optical frame |
///
/// `options` applies to the unorganised readers (and to the `.bin`, `.3d` non-finite points).
/// Every error names `path` (or the `.pose` / intrinsics file it came from); an unknown
/// extension is [`ErrorKind::Unsupported`].
pub fn read_cloud(path: &Path, options: &ReadOptions) -> Result<crate::PointCloud, Error> {
    let format = format_of(path)?;
    let open = || open_read(format, path);
    let cloud = match format {
        Format::Ply => ply::read_ply(open()?, options),
        Format::Pcd => pcd::read_pcd(open()?, options),
        Format::Obj => obj::read_obj(open()?).and_then(|mesh| {
            crate::PointCloud::from_positions(mesh.vertices().to_vec())
                .map_err(|e| Error::new(format, e))
        }),
        Format::Xyz => xyz::read_xyz(open()?, options),
        Format::KittiBin => {
            let o = kitti::KittiReadOptions {
                layout: kitti::KittiLayout::Unorganized,
                zero_is_invalid: true,
                non_finite: *options,
            };
            kitti::read_kitti_bin(open()?, &o)
        }
        Format::Uos => {
            let o = uos::UosReadOptions { non_finite: *options, ..Default::default() };
            let mut cloud = uos::read_uos_scan(open()?, &o).map_err(|e| e.with_path(path))?;
            let pose_path = path.with_extension("pose");
            if pose_path.is_file() {
                let pose = uos::read_uos_pose(open_read(format, &pose_path)?)
                    .map_err(|e| e.with_path(&pose_path))?;
                cloud.set_sensor_pose(Some(pose));
            }
            return Ok(cloud);
        }
        Format::DepthPng => {
            return read_range_image(path, None)?.to_cloud().map_err(|e| {
                Error::new(format, ErrorKind::BadValue(e.to_string())).with_path(path)
            });
        }
    };
    cloud.map_err(|e| e.with_path(path))
}

/// Reads the mesh of an `.obj` file (see [`obj::read_obj`]); errors name `path`.
pub fn read_mesh(path: &Path) -> Result<crate::PolygonMesh, Error> {
    obj::read_obj(open_read(Format::Obj, path)?).map_err(|e| e.with_path(path))
}

/// Reads a 16-bit PNG depth image with `camera`, or, with `None`, with the camera
/// [`depth_camera_for`] finds for it. The values are z depths ([`crate::RangeKind::Depth`]);
/// for radial-distance images use [`depth_png::read_range_png`].
///
/// When the camera comes from a sidecar JSON file that states `width` and `height`, they must
/// match the image.
pub fn read_range_image(
    path: &Path,
    camera: Option<&depth_png::DepthCamera>,
) -> Result<crate::RangeImage, Error> {
    let format = Format::DepthPng;
    let (camera, sidecar) = match camera {
        Some(c) => (*c, None),
        None => find_depth_camera(path)?,
    };
    let image = depth_png::read_depth_png(open_read(format, path)?, &camera)
        .map_err(|e| e.with_path(path))?;
    if let Some((json, Some(size))) = sidecar
        && size != (image.width(), image.height())
    {
        return Err(Error::new(
            format,
            ErrorKind::BadValue(format!(
                "{} says the image is {}×{}, but {} is {}×{}",
                json.display(),
                size.0,
                size.1,
                path.display(),
                image.width(),
                image.height()
            )),
        )
        .with_path(path));
    }
    Ok(image)
}

/// The depth camera for the PNG depth image at `path`:
///
/// * the intrinsics JSON file next to it (see [`depth_png::read_intrinsics_json`]) whose name is
///   `<prefix>_intrinsics<anything>.json` where the image's file stem is `<prefix>` or starts
///   with `<prefix>_` (so `office1_intrinsics_fitted.json` serves `office1_zdepth_mm.png`); of
///   several, the longest prefix wins, then the first name in byte order. Its depth scale is the
///   JSON's optional `depth_scale` key (metres per unit), else millimetres (0.001);
/// * else [`depth_png::DepthCamera::openni_mm`] (fx = fy = 525, cx = 320, cy = 240, mm). Images
///   in another convention (TUM RGB-D: 1/5000 m) need an explicit camera: pass
///   [`depth_png::DepthCamera::tum_kinect`] to [`read_range_image`].
pub fn depth_camera_for(path: &Path) -> Result<depth_png::DepthCamera, Error> {
    Ok(find_depth_camera(path)?.0)
}

/// The sidecar JSON of a depth PNG and the image size it states, if any.
type Sidecar = (PathBuf, Option<(u32, u32)>);

fn find_depth_camera(path: &Path) -> Result<(depth_png::DepthCamera, Option<Sidecar>), Error> {
    let format = Format::DepthPng;
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("");
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let entries = std::fs::read_dir(dir).map_err(|e| Error::new(format, e).with_path(dir))?;
    let mut best: Option<(usize, String)> = None;
    for entry in entries {
        let entry = entry.map_err(|e| Error::new(format, e).with_path(dir))?;
        let Some(name) = entry.file_name().to_str().map(str::to_owned) else { continue };
        let Some(base) = name.strip_suffix(".json") else { continue };
        let Some(at) = base.find("_intrinsics") else { continue };
        let prefix = &base[..at];
        let serves = stem == prefix
            || (stem.starts_with(prefix) && stem.as_bytes().get(prefix.len()) == Some(&b'_'));
        if !serves || !entry.path().is_file() {
            continue;
        }
        let better = match &best {
            None => true,
            Some((len, n)) => prefix.len() > *len || (prefix.len() == *len && name < *n),
        };
        if better {
            best = Some((prefix.len(), name));
        }
    }
    let Some((_, name)) = best else {
        return Ok((depth_png::DepthCamera::openni_mm(), None));
    };
    let json = dir.join(name);
    let j = depth_png::parse_intrinsics_json(open_read(format, &json)?)
        .map_err(|e| e.with_path(&json))?;
    let camera = depth_png::DepthCamera {
        intrinsics: crate::PinholeIntrinsics { fx: j.fx, fy: j.fy, cx: j.cx, cy: j.cy },
        depth_scale: j.depth_scale.unwrap_or(0.001),
    };
    let size = j.width.zip(j.height);
    Ok((camera, Some((json, size))))
}

/// Writes `cloud` to `path` in the format its extension names ([`Format::from_path`]):
///
/// | extension | writer | what is written |
/// |---|---|---|
/// | `.ply` | [`ply::write_ply`] | binary little-endian, `double` positions and normals ([`Precision::F64`]: the round trip is exact) |
/// | `.pcd` | [`pcd::write_pcd`] | `binary_compressed`, `F 4` positions and normals ([`Precision::F32`], what PCL's point types expect; call [`pcd::write_pcd`] with [`Precision::F64`] for an exact round trip) |
/// | `.obj` | [`obj::write_obj`] | the positions as vertices, no faces |
/// | `.xyz`, `.txt` | [`xyz::write_xyz`] | positions and intensity, exact decimal text |
/// | `.bin` | [`kitti::write_kitti_bin`] | float32 records (organised clouds column-major) |
/// | `.3d` | [`uos::write_uos_scan`] | positions in cm in 3DTK's frame, plus the sibling `.pose` file ([`uos::write_uos_pose`]) with the sensor pose, identity when the cloud has none |
///
/// `.png` is refused ([`ErrorKind::Unsupported`]): a depth image needs a camera, so write a
/// [`crate::RangeImage`] with [`depth_png::write_depth_png`]. Every error names `path`.
pub fn write_cloud(path: &Path, cloud: &crate::PointCloud) -> Result<(), Error> {
    let format = format_of(path)?;
    let named = naming(format, path);
    match format {
        Format::Ply => {
            let o = ply::PlyWriteOptions {
                encoding: ply::PlyEncoding::BinaryLittleEndian,
                precision: Precision::F64,
            };
            write_atomically(path, |w| ply::write_ply(w, cloud, &o))
        }
        Format::Pcd => {
            let o = pcd::PcdWriteOptions {
                encoding: pcd::PcdEncoding::BinaryCompressed,
                precision: Precision::F32,
            };
            write_atomically(path, |w| pcd::write_pcd(w, cloud, &o))
        }
        Format::Obj => {
            let mesh = crate::PolygonMesh::new(cloud.positions().to_vec(), Vec::new())
                .map_err(|e| Error::new(format, ErrorKind::BadValue(e.to_string())))
                .map_err(named)?;
            write_atomically(path, |w| obj::write_obj(w, &mesh))
        }
        Format::Xyz => write_atomically(path, |w| xyz::write_xyz(w, cloud)),
        Format::KittiBin => write_atomically(path, |w| kitti::write_kitti_bin(w, cloud)),
        Format::Uos => {
            write_atomically(path, |w| uos::write_uos_scan(w, cloud)).map_err(named)?;
            let pose_path = path.with_extension("pose");
            let pose = cloud.sensor_pose().copied().unwrap_or_else(crate::SensorPose::identity);
            return write_atomically(&pose_path, |w| uos::write_uos_pose(w, &pose))
                .map_err(naming(format, &pose_path));
        }
        Format::DepthPng => Err(Error::new(
            format,
            ErrorKind::Unsupported(
                "a cloud cannot be written as a PNG depth image without a camera; \
                 write a RangeImage with depth_png::write_depth_png"
                    .into(),
            ),
        )),
    }
    .map_err(named)
}

/// Writes `mesh` to `path` as OBJ ([`obj::write_obj`]) or, for a `.ply` path, as a binary PLY
/// mesh ([`ply::write_ply_mesh`]); errors name `path`.
pub fn write_mesh(path: &Path, mesh: &crate::PolygonMesh) -> Result<(), Error> {
    let format =
        if Format::from_path(path) == Some(Format::Ply) { Format::Ply } else { Format::Obj };
    write_atomically(path, |w| match format {
        Format::Ply => ply::write_ply_mesh(w, mesh),
        _ => obj::write_obj(w, mesh),
    })
    .map_err(naming(format, path))
}

/// Names `path` in an error, and `format` when the error names none (the writer's own).
fn naming(format: Format, path: &Path) -> impl Fn(Error) -> Error + Copy + '_ {
    move |e| Error { format: e.format.or(Some(format)), ..e }.with_path(path)
}

/// The format of `path`, or an [`ErrorKind::Unsupported`] error naming the extension.
fn format_of(path: &Path) -> Result<Format, Error> {
    Format::from_path(path).ok_or_else(|| Error {
        format: None,
        path: Some(path.to_owned()),
        position: None,
        kind: ErrorKind::Unsupported(format!(
            "unknown file extension {:?} (expected ply, pcd, obj, xyz, txt, bin, 3d or png)",
            path.extension().map(|e| e.to_string_lossy()).unwrap_or_default()
        )),
    })
}

/// Opens `path` for buffered reading; the error names the path.
fn open_read(format: Format, path: &Path) -> Result<std::io::BufReader<std::fs::File>, Error> {
    std::fs::File::open(path)
        .map(std::io::BufReader::new)
        .map_err(|e| Error::new(format, e).with_path(path))
}
