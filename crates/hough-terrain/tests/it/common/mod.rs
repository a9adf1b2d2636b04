//! Shared helpers: scene-sim terrain scenes seen by the simulated SR-3000 from a Rugbot-like
//! pose.

#![allow(dead_code)]

use hough_terrain::{SensorAxes, SensorMount};
use pointcloud::{Point3, PointCloud, SensorPose};
use scene_sim::{RangeCamera, RangeSensor, StereoCamera, TerrainSpec, terrain};

/// Camera height above the floor, metres: mid-bin (d bin [0.4, 0.5)), so noise does not split
/// the floor's votes.
pub const HEIGHT: f64 = 0.45;
/// Camera pitch, degrees (down). Level: the lower half of the image sees the floor from
/// 1.27 m on, so features 1.5 m ahead fill much of the view (with a camera pitched down 20° the
/// floor in front of the robot holds more than `t_h` of the points in every scene and
/// Algorithm 3 answers "floor" everywhere).
pub const PITCH_DEG: f64 = 0.0;

/// The camera pose on the robot at the origin looking along +x.
pub fn camera_pose(sensor: &dyn RangeSensor) -> SensorPose {
    let body = SensorPose::from_position_rpy(
        Point3::new(0.0, 0.0, HEIGHT),
        0.0,
        PITCH_DEG.to_radians(),
        0.0,
    );
    sensor.mount(&body)
}

/// The mount matching [`camera_pose`].
pub fn mount() -> SensorMount {
    SensorMount::looking_ahead(HEIGHT, PITCH_DEG.to_radians(), 0.0, SensorAxes::Optical).unwrap()
}

/// The scene seed (obstacle and rubble layout) of every test.
pub const SCENE_SEED: u64 = 3;

/// One SR-3000 frame of a terrain scene (organised cloud in the optical frame) with sensor
/// noise from `seed`.
pub fn sr_frame(spec: &TerrainSpec, seed: u64) -> PointCloud {
    let scene = terrain(spec, SCENE_SEED).unwrap();
    let cam = RangeCamera::swissranger_sr3000();
    cam.scan(&scene, &camera_pose(&cam), seed).to_cloud().unwrap()
}

/// One STOC frame of a terrain scene.
pub fn stereo_frame(spec: &TerrainSpec, seed: u64) -> PointCloud {
    let scene = terrain(spec, SCENE_SEED).unwrap();
    let cam = StereoCamera::stoc();
    cam.scan(&scene, &camera_pose(&cam), seed).to_cloud().unwrap()
}

/// Degrees to radians.
pub fn deg(d: f64) -> f64 {
    d.to_radians()
}
