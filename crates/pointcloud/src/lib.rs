//! Point clouds, organised scans, range images, sensor poses and their file formats.
//!
//! This is the vocabulary every other crate of the workspace speaks about range data:
//!
//! * [`PointCloud`]: finite positions plus optional per-point attributes (intensity or amplitude,
//!   normals, labels, rings, any extra scalar field a file carried). A cloud may be *organised*
//!   ([`Grid`]): then it remembers the image it came from, pixel by pixel, and pixels without a
//!   measurement are explicit ([`Grid::point_index`] returns `None` for them).
//! * [`RangeImage`]: a `width × height` image of ranges with a [`BeamModel`] (pinhole, spherical,
//!   or actuated laser range finder) that gives every pixel its beam direction.
//! * [`SensorPose`]: a `world_from_sensor` rigid transform.
//! * [`PolygonMesh`]: vertices and polygonal faces (environment meshes).
//! * [`Aabb`], [`Real`], [`Point3`], [`Vector3`], [`Isometry3`]: the math types of
//!   `patch-math`, re-exported.
//! * [`io`]: readers and writers for PLY, PCD v0.7, OBJ, XYZ, KITTI `.bin`, 3DTK `.3d`/`.pose`
//!   and 16-bit PNG depth images, and the data layout of ROS `sensor_msgs/PointCloud2`
//!   ([`io::pointcloud2`]). Every reader returns a typed error that names the file position or
//!   the field on corrupt input; none panics.
//!
//! All geometry is `f64` and uses [`nalgebra`] types, re-exported as [`na`].
//!
//! # Frames
//! Names carry the frame: `world_from_sensor * point_in_sensor` is a point in the world. The
//! world frame is right-handed with z up. Camera-like sensors use the optical frame (x right,
//! y down, z forward); laser range finders use x forward, y left, z up.

pub extern crate nalgebra as na;

mod cloud;
pub mod io;
mod mesh;
mod pose;
mod range_image;

pub use cloud::{AttributeError, FieldData, Grid, INVALID_PIXEL, PointCloud, ScalarField};
pub use mesh::{MeshError, PolygonMesh};
pub use patch_math::{Aabb, Isometry3, Point3, Real, Vector3};
pub use pose::SensorPose;
pub use range_image::{
    ActuatedLrfModel, BeamModel, PinholeIntrinsics, RangeImage, RangeImageError, RangeKind,
    SphericalModel,
};
