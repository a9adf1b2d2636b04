//! `visualization_msgs/Marker` and `visualization_msgs/MarkerArray` of ROS 2 (Humble and
//! later: with `texture_resource`, `texture`, `uv_coordinates` and `mesh_file`), the shapes
//! RViz and Foxglove draw, with the small `geometry_msgs`, `std_msgs`, `sensor_msgs` and
//! `builtin_interfaces` types inside them.
//!
//! CDR only: ROS 1's `Marker` lacks the texture and mesh-file fields, so these types are not
//! written to ROS 1 bags ([`crate::BagWriter::add_topic`] gives them no ROS 1 definition, and
//! [`crate::BagWriter::write_markers`] refuses a ROS 1 bag).
//!
//! ```
//! use ros_bag::msgs::markers::{ColorRgba, Marker, MarkerArray, TRIANGLE_LIST};
//! use ros_bag::Header;
//! use pointcloud::Point3;
//!
//! let mut m = Marker::new(Header { stamp_ns: 0, frame_id: "map".into() }, "floor", 0);
//! m.kind = TRIANGLE_LIST;
//! m.color = ColorRgba::new(0.2, 0.5, 0.9, 1.0);
//! m.points = vec![Point3::origin(), Point3::new(1.0, 0.0, 0.0), Point3::new(0.0, 1.0, 0.0)];
//! let array = MarkerArray { markers: vec![m] };
//! assert_eq!(MarkerArray::decode(&array.encode())?, array);
//! # Ok::<(), ros_bag::wire::WireError>(())
//! ```

use crate::msgs::Header;
use crate::wire::{Encoding, Reader, WireError, Writer};
use pointcloud::{Point3, Vector3, na};

/// `Marker.ARROW`.
pub const ARROW: i32 = 0;
/// `Marker.CUBE`.
pub const CUBE: i32 = 1;
/// `Marker.SPHERE`.
pub const SPHERE: i32 = 2;
/// `Marker.CYLINDER`.
pub const CYLINDER: i32 = 3;
/// `Marker.LINE_STRIP`.
pub const LINE_STRIP: i32 = 4;
/// `Marker.LINE_LIST`.
pub const LINE_LIST: i32 = 5;
/// `Marker.CUBE_LIST`.
pub const CUBE_LIST: i32 = 6;
/// `Marker.SPHERE_LIST`.
pub const SPHERE_LIST: i32 = 7;
/// `Marker.POINTS`.
pub const POINTS: i32 = 8;
/// `Marker.TEXT_VIEW_FACING`.
pub const TEXT_VIEW_FACING: i32 = 9;
/// `Marker.MESH_RESOURCE`.
pub const MESH_RESOURCE: i32 = 10;
/// `Marker.TRIANGLE_LIST`.
pub const TRIANGLE_LIST: i32 = 11;
/// `Marker.ARROW_STRIP`.
pub const ARROW_STRIP: i32 = 12;

/// `Marker.ADD` (also `MODIFY`): add or replace the marker of this namespace and id.
pub const ADD: i32 = 0;
/// `Marker.DELETE`: delete the marker of this namespace and id.
pub const DELETE: i32 = 2;
/// `Marker.DELETEALL`: delete every marker (of the namespace, if one is given).
pub const DELETEALL: i32 = 3;

/// `std_msgs/ColorRGBA`: components in `[0, 1]`.
#[derive(Copy, Clone, Debug, PartialEq, Default)]
pub struct ColorRgba {
    /// Red.
    pub r: f32,
    /// Green.
    pub g: f32,
    /// Blue.
    pub b: f32,
    /// Opacity (1: opaque).
    pub a: f32,
}

impl ColorRgba {
    /// A colour.
    pub const fn new(r: f32, g: f32, b: f32, a: f32) -> ColorRgba {
        ColorRgba { r, g, b, a }
    }

    fn read(r: &mut Reader<'_>, field: &str) -> Result<ColorRgba, WireError> {
        Ok(ColorRgba { r: r.f32(field)?, g: r.f32(field)?, b: r.f32(field)?, a: r.f32(field)? })
    }

    fn write(&self, w: &mut Writer) {
        for v in [self.r, self.g, self.b, self.a] {
            w.f32(v);
        }
    }
}

/// `geometry_msgs/Pose`: where a marker's own frame sits in its header's frame.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Pose {
    /// `position` (`geometry_msgs/Point`).
    pub position: Point3,
    /// `orientation` (`geometry_msgs/Quaternion`), as sent: not necessarily unit.
    pub orientation: na::Quaternion<f64>,
}

impl Default for Pose {
    /// The identity: at the origin, not rotated.
    fn default() -> Pose {
        Pose { position: Point3::origin(), orientation: na::Quaternion::identity() }
    }
}

/// `builtin_interfaces/Duration`.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Default)]
pub struct Duration {
    /// Whole seconds.
    pub sec: i32,
    /// Nanoseconds added to `sec`, below 10⁹.
    pub nanosec: u32,
}

/// `sensor_msgs/CompressedImage` (a marker's texture).
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct CompressedImage {
    /// Stamp and the camera's optical frame.
    pub header: Header,
    /// `jpeg`, `png`, or an image transport's format string.
    pub format: String,
    /// The compressed image.
    pub data: Vec<u8>,
}

/// `visualization_msgs/UVCoordinate`: a vertex's place in a texture, in `[0, 1]`.
#[derive(Copy, Clone, Debug, PartialEq, Default)]
pub struct UvCoordinate {
    /// Across the texture's width.
    pub u: f64,
    /// Across the texture's height.
    pub v: f64,
}

/// `visualization_msgs/MeshFile`: a mesh file sent inside the message.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct MeshFile {
    /// The file's name (its extension picks the parser).
    pub filename: String,
    /// The file's bytes.
    pub data: Vec<u8>,
}

/// `visualization_msgs/Marker` (ROS 2 Humble and later), every field.
#[derive(Clone, Debug, PartialEq)]
pub struct Marker {
    /// Stamp and the frame `pose` is in.
    pub header: Header,
    /// Namespace; with `id`, names the marker.
    pub ns: String,
    /// Id within the namespace.
    pub id: i32,
    /// `type`: [`TRIANGLE_LIST`], [`LINE_LIST`], [`LINE_STRIP`], ...
    pub kind: i32,
    /// [`ADD`], [`DELETE`] or [`DELETEALL`].
    pub action: i32,
    /// The marker's frame in the header's frame; `points` are in the marker's frame.
    pub pose: Pose,
    /// Scale (for lines: `x` is the width in metres; for triangle lists a factor on `points`).
    pub scale: Vector3,
    /// The colour of the whole marker when `colors` is empty.
    pub color: ColorRgba,
    /// How long the marker stays (zero: until replaced or deleted).
    pub lifetime: Duration,
    /// Re-transform the marker into its frame at every time step.
    pub frame_locked: bool,
    /// Points of line, point and triangle markers.
    pub points: Vec<Point3>,
    /// No colours, or one per point.
    pub colors: Vec<ColorRgba>,
    /// A texture's URI (`embedded://NAME` for `texture`).
    pub texture_resource: String,
    /// The embedded texture.
    pub texture: CompressedImage,
    /// One texture coordinate per point, or none.
    pub uv_coordinates: Vec<UvCoordinate>,
    /// Text of text markers.
    pub text: String,
    /// A mesh's URI (`embedded://NAME` for `mesh_file`).
    pub mesh_resource: String,
    /// The embedded mesh.
    pub mesh_file: MeshFile,
    /// Draw the mesh with its own materials.
    pub mesh_use_embedded_materials: bool,
}

impl Marker {
    /// An [`ADD`] marker of type [`ARROW`] (set `kind`), at the identity pose, scale 1, opaque
    /// white, living forever, without points.
    pub fn new(header: Header, ns: impl Into<String>, id: i32) -> Marker {
        Marker {
            header,
            ns: ns.into(),
            id,
            kind: ARROW,
            action: ADD,
            pose: Pose::default(),
            scale: Vector3::new(1.0, 1.0, 1.0),
            color: ColorRgba::new(1.0, 1.0, 1.0, 1.0),
            lifetime: Duration::default(),
            frame_locked: false,
            points: Vec::new(),
            colors: Vec::new(),
            texture_resource: String::new(),
            texture: CompressedImage::default(),
            uv_coordinates: Vec::new(),
            text: String::new(),
            mesh_resource: String::new(),
            mesh_file: MeshFile::default(),
            mesh_use_embedded_materials: false,
        }
    }

    /// Decodes a CDR message.
    ///
    /// # Errors
    /// [`WireError`] with the byte and field where the message ends early or is malformed.
    pub fn decode(data: &[u8]) -> Result<Marker, WireError> {
        Marker::read(&mut Reader::new(data, Encoding::Cdr)?)
    }

    /// Encodes the marker as a CDR message.
    pub fn encode(&self) -> Vec<u8> {
        let mut w = Writer::new(Encoding::Cdr);
        self.write(&mut w);
        w.finish()
    }

    fn read(r: &mut Reader<'_>) -> Result<Marker, WireError> {
        let header = Header::read(r, Encoding::Cdr)?;
        let ns = r.string("ns")?;
        let id = r.i32("id")?;
        let kind = r.i32("type")?;
        let action = r.i32("action")?;
        let position = read_point(r, "pose.position")?;
        let q = [0; 4].map(|_| r.f64("pose.orientation"));
        let [x, y, z, qw] = q;
        let orientation = na::Quaternion::new(qw?, x?, y?, z?);
        let scale = read_point(r, "scale")?.coords;
        let color = ColorRgba::read(r, "color")?;
        let lifetime =
            Duration { sec: r.i32("lifetime.sec")?, nanosec: r.u32("lifetime.nanosec")? };
        let frame_locked = r.bool("frame_locked")?;
        let n = r.count("points", 24)?;
        let points = (0..n).map(|_| read_point(r, "points")).collect::<Result<_, _>>()?;
        let n = r.count("colors", 16)?;
        let colors = (0..n).map(|_| ColorRgba::read(r, "colors")).collect::<Result<_, _>>()?;
        let texture_resource = r.string("texture_resource")?;
        let texture = CompressedImage {
            header: Header::read(r, Encoding::Cdr)?,
            format: r.string("texture.format")?,
            data: r.bytes("texture.data")?.to_vec(),
        };
        let n = r.count("uv_coordinates", 16)?;
        let uv_coordinates = (0..n)
            .map(|_| Ok(UvCoordinate { u: r.f64("uv_coordinates")?, v: r.f64("uv_coordinates")? }))
            .collect::<Result<_, WireError>>()?;
        let text = r.string("text")?;
        let mesh_resource = r.string("mesh_resource")?;
        let mesh_file = MeshFile {
            filename: r.string("mesh_file.filename")?,
            data: r.bytes("mesh_file.data")?.to_vec(),
        };
        let mesh_use_embedded_materials = r.bool("mesh_use_embedded_materials")?;
        Ok(Marker {
            header,
            ns,
            id,
            kind,
            action,
            pose: Pose { position, orientation },
            scale,
            color,
            lifetime,
            frame_locked,
            points,
            colors,
            texture_resource,
            texture,
            uv_coordinates,
            text,
            mesh_resource,
            mesh_file,
            mesh_use_embedded_materials,
        })
    }

    fn write(&self, w: &mut Writer) {
        self.header.write(w, Encoding::Cdr);
        w.string(&self.ns);
        w.i32(self.id);
        w.i32(self.kind);
        w.i32(self.action);
        write_point(w, &self.pose.position);
        let q = &self.pose.orientation;
        for v in [q.i, q.j, q.k, q.w] {
            w.f64(v);
        }
        write_point(w, &Point3::from(self.scale));
        self.color.write(w);
        w.i32(self.lifetime.sec);
        w.u32(self.lifetime.nanosec);
        w.bool(self.frame_locked);
        w.u32(self.points.len() as u32);
        for p in &self.points {
            write_point(w, p);
        }
        w.u32(self.colors.len() as u32);
        for c in &self.colors {
            c.write(w);
        }
        w.string(&self.texture_resource);
        self.texture.header.write(w, Encoding::Cdr);
        w.string(&self.texture.format);
        w.bytes(&self.texture.data);
        w.u32(self.uv_coordinates.len() as u32);
        for uv in &self.uv_coordinates {
            w.f64(uv.u);
            w.f64(uv.v);
        }
        w.string(&self.text);
        w.string(&self.mesh_resource);
        w.string(&self.mesh_file.filename);
        w.bytes(&self.mesh_file.data);
        w.bool(self.mesh_use_embedded_materials);
    }
}

/// `visualization_msgs/MarkerArray`.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct MarkerArray {
    /// The markers.
    pub markers: Vec<Marker>,
}

impl MarkerArray {
    /// The least CDR bytes one marker takes (checked against the bytes left before the
    /// markers are read): fixed fields and empty strings and sequences.
    const MIN_MARKER_BYTES: usize = 64;

    /// Decodes a CDR message.
    ///
    /// # Errors
    /// [`WireError`] with the byte and field where the message ends early or is malformed.
    pub fn decode(data: &[u8]) -> Result<MarkerArray, WireError> {
        let r = &mut Reader::new(data, Encoding::Cdr)?;
        let n = r.count("markers", MarkerArray::MIN_MARKER_BYTES)?;
        let mut markers = Vec::with_capacity(n);
        for _ in 0..n {
            markers.push(Marker::read(r)?);
        }
        Ok(MarkerArray { markers })
    }

    /// Encodes the array as a CDR message.
    pub fn encode(&self) -> Vec<u8> {
        let mut w = Writer::new(Encoding::Cdr);
        w.u32(self.markers.len() as u32);
        for m in &self.markers {
            m.write(&mut w);
        }
        w.finish()
    }
}

fn read_point(r: &mut Reader<'_>, field: &str) -> Result<Point3, WireError> {
    Ok(Point3::new(r.f64(field)?, r.f64(field)?, r.f64(field)?))
}

fn write_point(w: &mut Writer, p: &Point3) {
    w.f64(p.x);
    w.f64(p.y);
    w.f64(p.z);
}

/// The `ros2msg` text of `visualization_msgs/Marker` without its `std_msgs/Header` and
/// `builtin_interfaces/Time` sections ([`super::definition`] appends them).
pub(crate) const MARKER_DEFINITION: &str = concat!(
    "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\nint32 LINE_STRIP=4\n",
    "int32 LINE_LIST=5\nint32 CUBE_LIST=6\nint32 SPHERE_LIST=7\nint32 POINTS=8\n",
    "int32 TEXT_VIEW_FACING=9\nint32 MESH_RESOURCE=10\nint32 TRIANGLE_LIST=11\n",
    "int32 ARROW_STRIP=12\n",
    "int32 ADD=0\nint32 MODIFY=0\nint32 DELETE=2\nint32 DELETEALL=3\n",
    "std_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\n",
    "geometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\n",
    "builtin_interfaces/Duration lifetime\nbool frame_locked\n",
    "geometry_msgs/Point[] points\nstd_msgs/ColorRGBA[] colors\n",
    "string texture_resource\nsensor_msgs/CompressedImage texture\n",
    "visualization_msgs/UVCoordinate[] uv_coordinates\nstring text\nstring mesh_resource\n",
    "visualization_msgs/MeshFile mesh_file\nbool mesh_use_embedded_materials\n",
    "================================================================================\n",
    "MSG: geometry_msgs/Pose\ngeometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n",
    "================================================================================\n",
    "MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n",
    "================================================================================\n",
    "MSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w\n",
    "================================================================================\n",
    "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n",
    "================================================================================\n",
    "MSG: std_msgs/ColorRGBA\nfloat32 r\nfloat32 g\nfloat32 b\nfloat32 a\n",
    "================================================================================\n",
    "MSG: builtin_interfaces/Duration\nint32 sec\nuint32 nanosec\n",
    "================================================================================\n",
    "MSG: sensor_msgs/CompressedImage\nstd_msgs/Header header\nstring format\nuint8[] data\n",
    "================================================================================\n",
    "MSG: visualization_msgs/UVCoordinate\nfloat64 u\nfloat64 v\n",
    "================================================================================\n",
    "MSG: visualization_msgs/MeshFile\nstring filename\nuint8[] data\n",
);

#[cfg(test)]
mod tests {
    use super::*;

    fn full_marker() -> Marker {
        let mut m = Marker::new(Header { stamp_ns: 1_500_000_007, frame_id: "map".into() }, "p", 7);
        m.kind = TRIANGLE_LIST;
        m.action = DELETE;
        m.pose = Pose {
            position: Point3::new(1.0, -2.0, 3.5),
            orientation: na::Quaternion::new(0.5, 0.5, -0.5, 0.5),
        };
        m.scale = Vector3::new(0.1, 0.2, 0.3);
        m.color = ColorRgba::new(0.25, 0.5, 0.75, 1.0);
        m.lifetime = Duration { sec: 2, nanosec: 300 };
        m.frame_locked = true;
        m.points = vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ];
        m.colors = vec![ColorRgba::new(1.0, 0.0, 0.0, 1.0); 3];
        m.texture_resource = "embedded://t".into();
        m.texture = CompressedImage {
            header: Header { stamp_ns: 5, frame_id: "cam".into() },
            format: "png".into(),
            data: vec![1, 2, 3],
        };
        m.uv_coordinates = vec![UvCoordinate { u: 0.0, v: 1.0 }; 3];
        m.text = "hello".into();
        m.mesh_resource = "embedded://m".into();
        m.mesh_file = MeshFile { filename: "m.stl".into(), data: vec![9; 5] };
        m.mesh_use_embedded_materials = true;
        m
    }

    #[test]
    fn every_field_survives_a_round_trip() {
        let array =
            MarkerArray { markers: vec![full_marker(), Marker::new(Header::default(), "", 0)] };
        let bytes = array.encode();
        assert_eq!(MarkerArray::decode(&bytes).unwrap(), array);
        let one = full_marker();
        assert_eq!(Marker::decode(&one.encode()).unwrap(), one);
    }

    #[test]
    fn the_byte_layout_is_cdr() {
        let m = Marker::new(Header { stamp_ns: 0, frame_id: "m".into() }, "ns", 3);
        let b = m.encode();
        let f64_at = |at: usize| f64::from_le_bytes(b[at..at + 8].try_into().unwrap());
        // Offsets count from the message's start; CDR aligns relative to the end of the
        // 4-byte encapsulation header.
        assert_eq!(&b[..4], &[0, 1, 0, 0]);
        assert_eq!(&b[12..18], &[2, 0, 0, 0, b'm', 0]); // frame_id
        assert_eq!(&b[20..27], &[3, 0, 0, 0, b'n', b's', 0]); // ns after 2 bytes of padding
        assert_eq!(&b[28..40], &[3, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]); // id, type ARROW, action ADD
        // The pose's float64s are aligned to 8 (relative offset 40): position at 44, the
        // orientation's w at 92, scale at 100.
        assert_eq!([f64_at(44), f64_at(52), f64_at(60)], [0.0; 3]);
        assert_eq!([f64_at(68), f64_at(76), f64_at(84), f64_at(92)], [0.0, 0.0, 0.0, 1.0]);
        assert_eq!([f64_at(100), f64_at(108), f64_at(116)], [1.0; 3]);
        assert_eq!(&b[124..128], &1f32.to_le_bytes()); // color.r
        assert_eq!(b[148], 0); // frame_locked after the lifetime at 140
        // Then empty sequences and strings, each aligned to 4, and the last bool at 228.
        assert_eq!(&b[152..160], &[0; 8]); // points, colors
        assert_eq!(&b[160..165], &[1, 0, 0, 0, 0]); // texture_resource ""
        assert_eq!(b.len(), 229);
        assert!(b.len() - 4 >= MarkerArray::MIN_MARKER_BYTES);
    }

    #[test]
    fn truncated_and_lying_messages_are_errors() {
        let bytes = MarkerArray { markers: vec![full_marker()] }.encode();
        for cut in [3, 4, 8, 40, 100, bytes.len() - 1] {
            assert!(MarkerArray::decode(&bytes[..cut]).is_err(), "cut at {cut}");
        }
        let mut lying = bytes.clone();
        lying[4..8].copy_from_slice(&u32::MAX.to_le_bytes());
        let e = MarkerArray::decode(&lying).unwrap_err();
        assert!(e.what.contains("`markers` declares"), "{e}");
    }

    #[test]
    fn the_constants_are_the_definitions() {
        let consts = [
            ("ARROW", ARROW),
            ("CUBE", CUBE),
            ("SPHERE", SPHERE),
            ("CYLINDER", CYLINDER),
            ("LINE_STRIP", LINE_STRIP),
            ("LINE_LIST", LINE_LIST),
            ("CUBE_LIST", CUBE_LIST),
            ("SPHERE_LIST", SPHERE_LIST),
            ("POINTS", POINTS),
            ("TEXT_VIEW_FACING", TEXT_VIEW_FACING),
            ("MESH_RESOURCE", MESH_RESOURCE),
            ("TRIANGLE_LIST", TRIANGLE_LIST),
            ("ARROW_STRIP", ARROW_STRIP),
            ("ADD", ADD),
            ("DELETE", DELETE),
            ("DELETEALL", DELETEALL),
        ];
        for (name, value) in consts {
            let line = format!("int32 {name}={value}\n");
            assert!(MARKER_DEFINITION.contains(&line), "{line}");
        }
        assert_eq!((TRIANGLE_LIST, LINE_LIST, LINE_STRIP), (11, 5, 4));
    }
}
