//! The message types this crate decodes and encodes: `std_msgs/Header`,
//! `sensor_msgs/PointCloud2`, `sensor_msgs/LaserScan` and `tf2_msgs/TFMessage`, in either
//! [`Encoding`] (depth images and camera infos are in [`crate::image`]);
//! `visualization_msgs/Marker` and `MarkerArray` in CDR ([`markers`]).

pub mod markers;

use crate::wire::{Encoding, Reader, WireError, Writer};
use pointcloud::io::pointcloud2::{PointCloud2, PointField};
use pointcloud::{AttributeError, Isometry3, Point3, PointCloud, na};

/// `sensor_msgs/PointCloud2`.
pub const POINT_CLOUD2: &str = "sensor_msgs/PointCloud2";
/// `sensor_msgs/LaserScan`.
pub const LASER_SCAN: &str = "sensor_msgs/LaserScan";
/// `tf2_msgs/TFMessage` (on `/tf` and `/tf_static`).
pub const TF_MESSAGE: &str = "tf2_msgs/TFMessage";
/// `visualization_msgs/Marker` (CDR only, [`markers::Marker`]).
pub const MARKER: &str = "visualization_msgs/Marker";
/// `visualization_msgs/MarkerArray` (CDR only, [`markers::MarkerArray`]).
pub const MARKER_ARRAY: &str = "visualization_msgs/MarkerArray";

/// A type name without ROS 2's `/msg/` (`sensor_msgs/msg/PointCloud2` → `sensor_msgs/PointCloud2`).
pub fn normalise_type(name: &str) -> String {
    name.replacen("/msg/", "/", 1)
}

/// Whether messages of this type start with a `std_msgs/Header` (so their frame can be read).
pub fn has_header(type_name: &str) -> bool {
    const STAMPED: &[&str] = &[
        "sensor_msgs/PointCloud2",
        "sensor_msgs/PointCloud",
        "sensor_msgs/LaserScan",
        "sensor_msgs/Image",
        "sensor_msgs/CompressedImage",
        "sensor_msgs/CameraInfo",
        "sensor_msgs/Imu",
        "sensor_msgs/NavSatFix",
        "sensor_msgs/Range",
        "sensor_msgs/MagneticField",
        "sensor_msgs/JointState",
        "nav_msgs/Odometry",
        "nav_msgs/Path",
        "nav_msgs/OccupancyGrid",
        "std_msgs/Header",
        "visualization_msgs/Marker",
    ];
    let t = normalise_type(type_name);
    STAMPED.contains(&t.as_str()) || (t.starts_with("geometry_msgs/") && t.ends_with("Stamped"))
}

/// A `std_msgs/Header` (ROS 1's `seq` is read and dropped).
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct Header {
    /// Nanoseconds since the epoch.
    pub stamp_ns: i64,
    /// The frame the data are in.
    pub frame_id: String,
}

impl Header {
    /// Reads a header.
    pub fn read(r: &mut Reader<'_>, encoding: Encoding) -> Result<Header, WireError> {
        let (sec, nsec) = match encoding {
            Encoding::Ros1 => {
                r.u32("header.seq")?;
                (r.u32("header.stamp.sec")? as i64, r.u32("header.stamp.nsec")?)
            }
            Encoding::Cdr => (r.i32("header.stamp.sec")? as i64, r.u32("header.stamp.nanosec")?),
        };
        let frame_id = r.string("header.frame_id")?;
        Ok(Header { stamp_ns: sec * 1_000_000_000 + nsec as i64, frame_id })
    }

    /// Writes a header.
    pub fn write(&self, w: &mut Writer, encoding: Encoding) {
        let sec = self.stamp_ns.div_euclid(1_000_000_000);
        let nsec = self.stamp_ns.rem_euclid(1_000_000_000) as u32;
        match encoding {
            Encoding::Ros1 => {
                w.u32(0);
                w.u32(sec as u32);
            }
            Encoding::Cdr => w.i32(sec as i32),
        }
        w.u32(nsec);
        w.string(&self.frame_id);
    }
}

/// Reads the header at the start of a stamped message.
pub fn read_header(data: &[u8], encoding: Encoding) -> Result<Header, WireError> {
    Header::read(&mut Reader::new(data, encoding)?, encoding)
}

/// A `sensor_msgs/PointCloud2` message: its header and its cloud layout and data.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct PointCloud2Msg {
    /// Stamp and frame.
    pub header: Header,
    /// Everything else.
    pub cloud: PointCloud2,
}

impl PointCloud2Msg {
    /// Decodes a message.
    pub fn decode(data: &[u8], encoding: Encoding) -> Result<PointCloud2Msg, WireError> {
        let r = &mut Reader::new(data, encoding)?;
        let header = Header::read(r, encoding)?;
        let height = r.u32("height")?;
        let width = r.u32("width")?;
        // name (4 + at least 0 bytes), offset, datatype, count
        let n = r.count("fields", 13)?;
        let mut fields = Vec::with_capacity(n);
        for _ in 0..n {
            fields.push(PointField {
                name: r.string("fields.name")?,
                offset: r.u32("fields.offset")?,
                datatype: r.u8("fields.datatype")?,
                count: r.u32("fields.count")?,
            });
        }
        let is_bigendian = r.bool("is_bigendian")?;
        let point_step = r.u32("point_step")?;
        let row_step = r.u32("row_step")?;
        let data = r.bytes("data")?.to_vec();
        let is_dense = r.bool("is_dense")?;
        let cloud = PointCloud2 {
            height,
            width,
            fields,
            is_bigendian,
            point_step,
            row_step,
            data,
            is_dense,
        };
        Ok(PointCloud2Msg { header, cloud })
    }

    /// Encodes the message.
    pub fn encode(&self, encoding: Encoding) -> Vec<u8> {
        let mut w = Writer::new(encoding);
        self.header.write(&mut w, encoding);
        let c = &self.cloud;
        w.u32(c.height);
        w.u32(c.width);
        w.u32(c.fields.len() as u32);
        for f in &c.fields {
            w.string(&f.name);
            w.u32(f.offset);
            w.u8(f.datatype);
            w.u32(f.count);
        }
        w.bool(c.is_bigendian);
        w.u32(c.point_step);
        w.u32(c.row_step);
        w.bytes(&c.data);
        w.bool(c.is_dense);
        w.finish()
    }
}

/// A `sensor_msgs/LaserScan`: ranges of beams in the x-y plane of its frame, counterclockwise
/// from `angle_min` (0 along x).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct LaserScan {
    /// Stamp and frame.
    pub header: Header,
    /// The first beam's angle (rad).
    pub angle_min: f32,
    /// The last beam's angle (rad).
    pub angle_max: f32,
    /// The angle between beams (rad).
    pub angle_increment: f32,
    /// The time between beams (s).
    pub time_increment: f32,
    /// The time between scans (s).
    pub scan_time: f32,
    /// Ranges below are no measurement (m).
    pub range_min: f32,
    /// Ranges above are no measurement (m).
    pub range_max: f32,
    /// One range per beam (m).
    pub ranges: Vec<f32>,
    /// One intensity per beam, or none.
    pub intensities: Vec<f32>,
}

impl LaserScan {
    /// Decodes a message.
    pub fn decode(data: &[u8], encoding: Encoding) -> Result<LaserScan, WireError> {
        let r = &mut Reader::new(data, encoding)?;
        let header = Header::read(r, encoding)?;
        let mut v = [0f32; 7];
        for (k, name) in [
            "angle_min",
            "angle_max",
            "angle_increment",
            "time_increment",
            "scan_time",
            "range_min",
            "range_max",
        ]
        .into_iter()
        .enumerate()
        {
            v[k] = r.f32(name)?;
        }
        let mut floats = |name: &str| -> Result<Vec<f32>, WireError> {
            let n = r.count(name, 4)?;
            (0..n).map(|_| r.f32(name)).collect()
        };
        let ranges = floats("ranges")?;
        let intensities = floats("intensities")?;
        let [
            angle_min,
            angle_max,
            angle_increment,
            time_increment,
            scan_time,
            range_min,
            range_max,
        ] = v;
        Ok(LaserScan {
            header,
            angle_min,
            angle_max,
            angle_increment,
            time_increment,
            scan_time,
            range_min,
            range_max,
            ranges,
            intensities,
        })
    }

    /// Encodes the message.
    pub fn encode(&self, encoding: Encoding) -> Vec<u8> {
        let mut w = Writer::new(encoding);
        self.header.write(&mut w, encoding);
        for v in [
            self.angle_min,
            self.angle_max,
            self.angle_increment,
            self.time_increment,
            self.scan_time,
            self.range_min,
            self.range_max,
        ] {
            w.f32(v);
        }
        for values in [&self.ranges, &self.intensities] {
            w.u32(values.len() as u32);
            for &v in values {
                w.f32(v);
            }
        }
        w.finish()
    }

    /// The scan as an organised cloud of one row (one pixel per beam) in its frame: a beam
    /// whose range is not finite or outside `[range_min, range_max]` is an invalid pixel.
    /// Intensities, when there is one per beam, become the cloud's intensity.
    pub fn to_cloud(&self) -> Result<PointCloud, AttributeError> {
        let valid = |r: f32| r.is_finite() && r >= self.range_min && r <= self.range_max;
        let pixels = self.ranges.iter().enumerate().map(|(i, &r)| {
            let a = self.angle_min as f64 + i as f64 * self.angle_increment as f64;
            valid(r).then(|| Point3::new(r as f64 * a.cos(), r as f64 * a.sin(), 0.0))
        });
        let mut cloud = PointCloud::from_pixels(self.ranges.len() as u32, 1, pixels)?;
        if self.intensities.len() == self.ranges.len() {
            let kept = self.ranges.iter().zip(&self.intensities).filter(|(r, _)| valid(**r));
            cloud.set_intensity(Some(kept.map(|(_, &i)| i).collect()))?;
        }
        Ok(cloud)
    }
}

/// A `geometry_msgs/TransformStamped`: `parent_from_child` at a time.
#[derive(Clone, Debug, PartialEq)]
pub struct TransformStamped {
    /// Stamp and the parent frame (`header.frame_id`).
    pub header: Header,
    /// The child frame.
    pub child_frame_id: String,
    /// Takes points in the child frame to the parent frame.
    pub parent_from_child: Isometry3,
}

/// Decodes a `tf2_msgs/TFMessage`.
pub fn decode_tf(data: &[u8], encoding: Encoding) -> Result<Vec<TransformStamped>, WireError> {
    let r = &mut Reader::new(data, encoding)?;
    // header (≥ 16) + child frame (≥ 4) + 7 float64
    let n = r.count("transforms", 76)?;
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        let header = Header::read(r, encoding)?;
        let child_frame_id = r.string("child_frame_id")?;
        let mut v = [0.0; 7];
        for (k, name) in ["x", "y", "z", "rotation.x", "rotation.y", "rotation.z", "rotation.w"]
            .into_iter()
            .enumerate()
        {
            v[k] = r.f64(name)?;
        }
        let at = r.offset();
        let q = na::Quaternion::new(v[6], v[3], v[4], v[5]);
        if !v.iter().all(|x| x.is_finite()) || q.norm() < 1e-9 {
            return Err(WireError {
                offset: at,
                what: format!("a finite transform with a non-zero rotation for `{child_frame_id}`"),
            });
        }
        let parent_from_child = Isometry3::from_parts(
            na::Translation3::new(v[0], v[1], v[2]),
            na::UnitQuaternion::from_quaternion(q),
        );
        out.push(TransformStamped { header, child_frame_id, parent_from_child });
    }
    Ok(out)
}

/// Encodes a `tf2_msgs/TFMessage`.
pub fn encode_tf(transforms: &[TransformStamped], encoding: Encoding) -> Vec<u8> {
    let mut w = Writer::new(encoding);
    w.u32(transforms.len() as u32);
    for t in transforms {
        t.header.write(&mut w, encoding);
        w.string(&t.child_frame_id);
        let p = t.parent_from_child.translation.vector;
        let q = t.parent_from_child.rotation.quaternion();
        for v in [p.x, p.y, p.z, q.i, q.j, q.k, q.w] {
            w.f64(v);
        }
    }
    w.finish()
}

const SEPARATOR: &str =
    "================================================================================\n";

/// The message definition text (ROS 2 `ros2msg` or ROS 1 `.msg` with its dependencies, in
/// the encoding's own `std_msgs/Header`) and the ROS 1 MD5 sum of the types this crate writes.
/// The markers have a ROS 2 text only (their MD5 sum is empty).
pub(crate) fn definition(type_name: &str, encoding: Encoding) -> Option<(String, &'static str)> {
    let marker_body;
    let (body, md5) = match type_name {
        MARKER | MARKER_ARRAY if encoding == Encoding::Ros1 => return None,
        MARKER => (markers::MARKER_DEFINITION, ""),
        MARKER_ARRAY => {
            marker_body = format!(
                "visualization_msgs/Marker[] markers\n{SEPARATOR}MSG: visualization_msgs/Marker\n{}",
                markers::MARKER_DEFINITION
            );
            (marker_body.as_str(), "")
        }
        POINT_CLOUD2 => (
            concat!(
                "std_msgs/Header header\nuint32 height\nuint32 width\nPointField[] fields\n",
                "bool is_bigendian\nuint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n",
                "================================================================================\n",
                "MSG: sensor_msgs/PointField\nuint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\n",
                "uint8 UINT16=4\nuint8 INT32=5\nuint8 UINT32=6\nuint8 FLOAT32=7\nuint8 FLOAT64=8\n",
                "string name\nuint32 offset\nuint8 datatype\nuint32 count\n",
            ),
            "1158d486dd51d683ce2f1be655c3c181",
        ),
        TF_MESSAGE => (
            concat!(
                "geometry_msgs/TransformStamped[] transforms\n",
                "================================================================================\n",
                "MSG: geometry_msgs/TransformStamped\nstd_msgs/Header header\nstring child_frame_id\n",
                "geometry_msgs/Transform transform\n",
                "================================================================================\n",
                "MSG: geometry_msgs/Transform\ngeometry_msgs/Vector3 translation\n",
                "geometry_msgs/Quaternion rotation\n",
                "================================================================================\n",
                "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n",
                "================================================================================\n",
                "MSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w\n",
            ),
            "94810edda583a504dfda3829e70d7eec",
        ),
        LASER_SCAN => (
            concat!(
                "std_msgs/Header header\nfloat32 angle_min\nfloat32 angle_max\n",
                "float32 angle_increment\nfloat32 time_increment\nfloat32 scan_time\n",
                "float32 range_min\nfloat32 range_max\nfloat32[] ranges\nfloat32[] intensities\n",
            ),
            "90c7ef2dc6895d81024acba2ac42f369",
        ),
        crate::image::IMAGE => (
            concat!(
                "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\n",
                "uint8 is_bigendian\nuint32 step\nuint8[] data\n",
            ),
            "060021388200f6f0f447d0fcd9c64743",
        ),
        // ROS 1 names the matrices D, K, R, P; ROS 2 d, k, r, p. The layout is the same.
        crate::image::CAMERA_INFO if encoding == Encoding::Ros1 => (
            concat!(
                "std_msgs/Header header\nuint32 height\nuint32 width\nstring distortion_model\n",
                "float64[] D\nfloat64[9] K\nfloat64[9] R\nfloat64[12] P\nuint32 binning_x\n",
                "uint32 binning_y\nsensor_msgs/RegionOfInterest roi\n",
                "================================================================================\n",
                "MSG: sensor_msgs/RegionOfInterest\nuint32 x_offset\nuint32 y_offset\n",
                "uint32 height\nuint32 width\nbool do_rectify\n",
            ),
            "c9a58c1b0b154e0e6da7578cb991d214",
        ),
        crate::image::CAMERA_INFO => (
            concat!(
                "std_msgs/Header header\nuint32 height\nuint32 width\nstring distortion_model\n",
                "float64[] d\nfloat64[9] k\nfloat64[9] r\nfloat64[12] p\nuint32 binning_x\n",
                "uint32 binning_y\nsensor_msgs/RegionOfInterest roi\n",
                "================================================================================\n",
                "MSG: sensor_msgs/RegionOfInterest\nuint32 x_offset\nuint32 y_offset\n",
                "uint32 height\nuint32 width\nbool do_rectify\n",
            ),
            "c9a58c1b0b154e0e6da7578cb991d214",
        ),
        _ => return None,
    };
    let header = match encoding {
        Encoding::Ros1 => {
            "MSG: std_msgs/Header\nuint32 seq\ntime stamp\nstring frame_id\n".to_owned()
        }
        Encoding::Cdr => format!(
            "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n{SEPARATOR}\
             MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"
        ),
    };
    Some((format!("{body}{SEPARATOR}{header}"), md5))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The `MSG:` sections of a definition, in order.
    fn sections(text: &str) -> Vec<&str> {
        text.lines().filter_map(|l| l.strip_prefix("MSG: ")).collect()
    }

    #[test]
    fn marker_definitions_name_every_nested_type_once() {
        let (array, md5) = definition(MARKER_ARRAY, Encoding::Cdr).unwrap();
        assert!(md5.is_empty());
        assert!(array.starts_with("visualization_msgs/Marker[] markers\n"));
        let names = sections(&array);
        let expected = [
            "visualization_msgs/Marker",
            "geometry_msgs/Pose",
            "geometry_msgs/Point",
            "geometry_msgs/Quaternion",
            "geometry_msgs/Vector3",
            "std_msgs/ColorRGBA",
            "builtin_interfaces/Duration",
            "sensor_msgs/CompressedImage",
            "visualization_msgs/UVCoordinate",
            "visualization_msgs/MeshFile",
            "std_msgs/Header",
            "builtin_interfaces/Time",
        ];
        assert_eq!(names, expected);
        // Every section is preceded by the 80-character separator line.
        assert_eq!(array.matches(SEPARATOR).count(), expected.len());
        let (marker, _) = definition(MARKER, Encoding::Cdr).unwrap();
        assert!(marker.starts_with("int32 ARROW=0\n"));
        assert_eq!(sections(&marker), expected[1..]);
        // Every field type the Marker names has its section (or is a primitive).
        let primitive = ["bool", "int32", "uint32", "float32", "float64", "string", "uint8"];
        for line in array.lines().filter(|l| !l.starts_with("MSG: ") && !l.starts_with('=')) {
            let ty = line.split_whitespace().next().unwrap().trim_end_matches("[]");
            assert!(primitive.contains(&ty) || names.contains(&ty), "{line}");
        }
        assert!(definition(MARKER, Encoding::Ros1).is_none());
        assert!(definition(MARKER_ARRAY, Encoding::Ros1).is_none());
    }
}
