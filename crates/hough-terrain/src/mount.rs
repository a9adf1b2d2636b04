//! Where the sensor sits: the transform from the sensor frame to the levelled frame in which the
//! Hough transform votes (spec §6.8).
//!
//! **The levelled frame** has its origin at the sensor and axes x forward (the robot's heading,
//! horizontal), y right, z down (along gravity). This is the frame in which the thesis's
//! statements all hold at once: positive ρx is downhill ahead (L3524–3526), and the floor, a
//! height `h` below the sensor, is the plane `ρx = ρy = 0, d = +h`, inside the thesis's range
//! d ∈ [−1, 2] m. In a z-up frame Algorithm 2 would make positive ρx uphill; [`crate::Plane::to_z_up`]
//! converts results for callers who think z-up.

use crate::error::{HoughError, Result};
use nalgebra::{Isometry3, Matrix3, Point3, UnitQuaternion, Vector3};
use pointcloud::SensorPose;
use serde::{Deserialize, Serialize};

/// Which axes the sensor's own frame uses.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum SensorAxes {
    /// Laser-scanner / robot-body axes: x forward, y left, z up.
    Body,
    /// Camera optical axes: x right, y down, z forward (range and stereo cameras).
    Optical,
}

impl SensorAxes {
    /// The rotation taking this frame's vectors to body axes (x forward, y left, z up).
    pub(crate) fn body_from_sensor(self) -> Matrix3<f64> {
        match self {
            SensorAxes::Body => Matrix3::identity(),
            SensorAxes::Optical => Matrix3::new(0.0, 0.0, 1.0, -1.0, 0.0, 0.0, 0.0, -1.0, 0.0),
        }
    }

    /// The sensor's forward axis in its own frame.
    fn forward(self) -> Vector3<f64> {
        match self {
            SensorAxes::Body => Vector3::x(),
            SensorAxes::Optical => Vector3::z(),
        }
    }
}

/// The sensor's mounting relative to the ground under the robot: the rotation that levels its
/// points (into x forward, y right, z down at the sensor) and its height above the floor, which
/// fixes the floor bin (`d = height`, spec §6.9).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SensorMount {
    levelled_from_sensor: Matrix3<f64>,
    height: f64,
}

/// The z-down levelled axes from z-up ground axes: (x, y, z) ↦ (x, −y, −z).
fn levelled_from_ground() -> Matrix3<f64> {
    Matrix3::new(1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, -1.0)
}

impl SensorMount {
    /// From the pose of the sensor in a ground frame (x forward along the robot's heading, y
    /// left, z up along gravity, origin on the floor): the rotation levels the points, the
    /// translation's z is the sensor height (x and y do not matter).
    pub fn new(ground_from_sensor: &Isometry3<f64>) -> Result<SensorMount> {
        let height = ground_from_sensor.translation.vector.z;
        let r = ground_from_sensor.rotation.to_rotation_matrix().into_inner();
        if !(height.is_finite() && r.iter().all(|v| v.is_finite())) {
            return Err(HoughError::BadParameter {
                what: "sensor mount",
                value: height,
                allowed: "a finite pose",
            });
        }
        Ok(SensorMount { levelled_from_sensor: levelled_from_ground() * r, height })
    }

    /// A sensor `height` metres above the floor, looking ahead, pitched down by `pitch` and
    /// rolled by `roll` (radians; positive roll lowers the right side), with `axes` its frame.
    pub fn looking_ahead(
        height: f64,
        pitch: f64,
        roll: f64,
        axes: SensorAxes,
    ) -> Result<SensorMount> {
        for (what, v) in [("mount height", height), ("mount pitch", pitch), ("mount roll", roll)] {
            if !v.is_finite() {
                return Err(HoughError::BadParameter { what, value: v, allowed: "finite" });
            }
        }
        // Body pitch about +y (left) by +pitch tips x down in a z-up frame.
        let body = UnitQuaternion::from_euler_angles(roll, pitch, 0.0);
        let r = body.to_rotation_matrix().into_inner() * axes.body_from_sensor();
        Ok(SensorMount { levelled_from_sensor: levelled_from_ground() * r, height })
    }

    /// From a world pose (world z up along gravity) and the floor's height `floor_z` in the
    /// world: the sensor's heading (its forward axis projected on the floor) becomes x.
    pub fn from_world_pose(
        pose: &SensorPose,
        axes: SensorAxes,
        floor_z: f64,
    ) -> Result<SensorMount> {
        if !(pose.is_finite() && floor_z.is_finite()) {
            return Err(HoughError::BadParameter {
                what: "sensor pose",
                value: floor_z,
                allowed: "a finite pose and floor height",
            });
        }
        let world_from_sensor = pose.world_from_sensor;
        let f = world_from_sensor.rotation * axes.forward();
        if f.x.hypot(f.y) < 1e-9 {
            return Err(HoughError::BadParameter {
                what: "sensor pose",
                value: f.z,
                allowed: "a sensor not looking straight up or down (no heading)",
            });
        }
        let yaw = f.y.atan2(f.x);
        let rotation =
            UnitQuaternion::from_euler_angles(0.0, 0.0, -yaw) * world_from_sensor.rotation;
        let height = world_from_sensor.translation.vector.z - floor_z;
        let g = Isometry3::from_parts(Vector3::new(0.0, 0.0, height).into(), rotation);
        SensorMount::new(&g)
    }

    /// The sensor's height above the floor, metres: the floor is the plane `d = height`.
    pub fn height(&self) -> f64 {
        self.height
    }

    /// The rotation taking sensor-frame vectors to the levelled frame (x forward, y right, z down).
    pub fn levelled_from_sensor(&self) -> &Matrix3<f64> {
        &self.levelled_from_sensor
    }

    /// A sensor-frame point in the levelled frame.
    #[inline]
    pub fn to_levelled(&self, p: &Point3<f64>) -> Point3<f64> {
        let m = &self.levelled_from_sensor;
        Point3::new(
            m[(0, 0)] * p.x + m[(0, 1)] * p.y + m[(0, 2)] * p.z,
            m[(1, 0)] * p.x + m[(1, 1)] * p.y + m[(1, 2)] * p.z,
            m[(2, 0)] * p.x + m[(2, 1)] * p.y + m[(2, 2)] * p.z,
        )
    }

    /// A sensor already in the levelled frame (identity rotation) at `height`.
    pub fn levelled(height: f64) -> Result<SensorMount> {
        if !height.is_finite() {
            return Err(HoughError::BadParameter {
                what: "mount height",
                value: height,
                allowed: "finite",
            });
        }
        Ok(SensorMount { levelled_from_sensor: Matrix3::identity(), height })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floor_point_lands_at_height_below() {
        // A camera 0.5 m up pitched down 30°: its optical axis hits the floor 0.5/tan 30° ahead.
        let m =
            SensorMount::looking_ahead(0.5, 30f64.to_radians(), 0.0, SensorAxes::Optical).unwrap();
        let range = 0.5 / 30f64.to_radians().sin();
        let p = m.to_levelled(&Point3::new(0.0, 0.0, range));
        assert!((p.x - 0.5 / 30f64.to_radians().tan()).abs() < 1e-9, "{p}");
        assert!(p.y.abs() < 1e-9 && (p.z - 0.5).abs() < 1e-9, "{p}");
        // Image right (optical +x) is levelled +y.
        let q = m.to_levelled(&Point3::new(1.0, 0.0, 0.0));
        assert!((q.y - 1.0).abs() < 1e-9, "{q}");
        // Body frame: x forward stays forward, y left becomes −y.
        let b = SensorMount::looking_ahead(0.3, 0.0, 0.0, SensorAxes::Body).unwrap();
        assert_eq!(b.to_levelled(&Point3::new(1.0, 2.0, 3.0)), Point3::new(1.0, -2.0, -3.0));
    }

    #[test]
    fn world_pose_matches_looking_ahead() {
        let body = SensorPose::from_position_rpy(Point3::new(3.0, -1.0, 0.45), 0.0, 0.4, 1.1);
        let cam = SensorPose {
            world_from_sensor: body.world_from_sensor
                * Isometry3::from_parts(
                    nalgebra::Translation3::identity(),
                    UnitQuaternion::from_matrix(&SensorAxes::Optical.body_from_sensor()),
                ),
        };
        let a = SensorMount::from_world_pose(&cam, SensorAxes::Optical, 0.0).unwrap();
        let b = SensorMount::looking_ahead(0.45, 0.4, 0.0, SensorAxes::Optical).unwrap();
        assert!((a.height() - 0.45).abs() < 1e-12);
        assert!((a.levelled_from_sensor() - b.levelled_from_sensor()).norm() < 1e-9);
        assert!(SensorMount::looking_ahead(f64::NAN, 0.0, 0.0, SensorAxes::Body).is_err());
    }
}
