//! Sensor poses.

use crate::{Isometry3, Point3, Real};
use serde::{Deserialize, Serialize};

/// Where a sensor was when it took a scan: the rigid transform `world_from_sensor` that takes
/// a point in the sensor frame to the world frame (`point_in_world = world_from_sensor *
/// point_in_sensor`).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SensorPose {
    /// Takes sensor-frame points to the world frame.
    pub world_from_sensor: Isometry3,
}

impl SensorPose {
    /// The sensor at the world origin, axes aligned with the world.
    pub fn identity() -> SensorPose {
        SensorPose { world_from_sensor: Isometry3::identity() }
    }

    /// A pose from a position and roll, pitch, yaw angles in radians (rotation applied as
    /// yaw about z, then pitch about y, then roll about x: `R = Rz(yaw) Ry(pitch) Rx(roll)`).
    pub fn from_position_rpy(position: Point3, roll: Real, pitch: Real, yaw: Real) -> SensorPose {
        let rotation = na::UnitQuaternion::from_euler_angles(roll, pitch, yaw);
        SensorPose { world_from_sensor: Isometry3::from_parts(position.coords.into(), rotation) }
    }

    /// The sensor origin in the world frame.
    pub fn origin(&self) -> Point3 {
        self.world_from_sensor.translation.vector.into()
    }

    /// Whether every number of the transform is finite.
    pub fn is_finite(&self) -> bool {
        let t = &self.world_from_sensor.translation.vector;
        let q = &self.world_from_sensor.rotation.coords;
        t.iter().chain(q.iter()).all(|v| v.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rpy_pose_moves_points() {
        let pose = SensorPose::from_position_rpy(
            Point3::new(1.0, 2.0, 3.0),
            0.0,
            0.0,
            std::f64::consts::FRAC_PI_2,
        );
        let p = pose.world_from_sensor * Point3::new(1.0, 0.0, 0.0);
        assert!((p - Point3::new(1.0, 3.0, 3.0)).norm() < 1e-12);
        assert_eq!(pose.origin(), Point3::new(1.0, 2.0, 3.0));
        assert!(pose.is_finite());
    }
}
