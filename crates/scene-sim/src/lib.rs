//! Synthetic scenes with ground truth and simulated range sensors.
//!
//! The thesis this workspace implements (Poppinga 2010, "Towards Autonomous Navigation for
//! Robots with 3D Sensors") works on range data from three sensors and builds planar-patch maps
//! from it. This crate makes such data with known answers:
//!
//! * **Scenes** ([`Scene`], built with [`SceneBuilder`]) of analytic primitives: planar
//!   polygons with holes (the thesis's patches, §5.1), posed boxes, spheres and capped cylinders
//!   (the non-planar objects of the PRH dataset, §3.1). Each has [`SurfaceId`]s, a near-infrared
//!   reflectivity (Table 2.3) and a texture flag. [`Scene::cast_ray`] finds the first surface a
//!   ray meets through a bounding volume hierarchy.
//! * **Scene builders**, deterministic from a seed: [`office`] (the floor plan of the planning
//!   experiment, §5.5.3 and Fig. 5.19, identical in layout to the shared benchmark floor plan),
//!   [`lab`] (the Lab dataset's room with its high-bay rack, §3.2.1), and [`terrain`] (one scene
//!   per class of the Hough terrain classifier, Chapter 4, with [`TerrainTruth`]).
//!   [`scene_by_name`] and [`scene_names`] serve the command line, [`Scene::scan_poses`] places
//!   sensors.
//! * **Sensors** implementing [`RangeSensor`]: the actuated laser range finder [`Alrf`]
//!   (SICK S300, §2.1), the time-of-flight camera [`RangeCamera`] (SwissRanger SR-3000, §2.3;
//!   geometry and noise only, with [`RangeCamera::scan_hits`] as the hook for a ToF model) and
//!   the [`StereoCamera`] (STOC, §2.2). A scan is a [`SimulatedScan`]: a
//!   [`pointcloud::RangeImage`] plus per-pixel [`GroundTruth`].
//!
//! ```
//! use scene_sim::{Alrf, AlrfConfig, RangeSensor, lab};
//! let scene = lab(7).unwrap();
//! let poses = scene.scan_poses(2, 0.5, 7);
//! let alrf = Alrf::new(AlrfConfig::sick_s300_with_step(5f64.to_radians()).unwrap()).unwrap();
//! let scan = alrf.scan(&scene, &poses[0], 1);
//! let cloud = scan.to_cloud().unwrap();
//! assert_eq!(cloud.labels().unwrap().len(), cloud.len());
//! ```
//!
//! All lengths are metres, angles radians, frames right-handed with z up (see
//! [`pointcloud`] for the sensor frames). Everything is single-threaded and deterministic.

mod builders;
mod bvh;
mod error;
mod material;
pub mod patches;
mod scene;
pub mod sensors;
pub mod shapes;
pub mod voxel;

pub use builders::{
    HoughClass, TerrainClass, TerrainSpec, TerrainTruth, lab, office, office_floorplan,
    scene_by_name, scene_names, terrain, terrain_spec_by_name,
};
pub use error::{SceneError, SensorError};
pub use material::{Material, SurfaceId};
pub use scene::{
    Hit, Plane, Primitive, PrimitiveId, SCAN_POSE_CLEARANCE, Scene, SceneBuilder, Surface,
    UnitVector3,
};
pub use sensors::{
    Alrf, AlrfConfig, BeamHit, GroundTruth, HitImage, MixedPixelConfig, RangeCamera,
    RangeCameraConfig, RangeSensor, SimulatedScan, StereoCamera, StereoCameraConfig,
    camera_pose_from_body, camera_pose_looking, scan_many, sensor_by_name, sensor_names,
    trace_image,
};
pub use shapes::{Cuboid, Cylinder, PlanarPolygon, Point2, Shape, Sphere};

/// Office layout constants (building size, doors, start and regions of interest).
pub mod office_layout {
    pub use crate::builders::office_consts::*;
}

/// Terrain scene layout constants (extent, ramp size, passability limits).
pub mod terrain_layout {
    pub use crate::builders::terrain_consts::*;
}

/// Lab layout constants.
pub mod lab_layout {
    pub use crate::builders::lab_consts::*;
}
