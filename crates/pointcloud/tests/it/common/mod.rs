//! Proptest strategies shared by the format round-trip tests.
#![allow(dead_code)] // each test binary uses a different subset

use pointcloud::na::UnitQuaternion;
use pointcloud::{FieldData, Isometry3, SensorPose, Vector3};
use proptest::collection::vec;
use proptest::prelude::*;

pub fn finite_f32() -> impl Strategy<Value = f32> {
    use proptest::num::f32::*;
    POSITIVE | NEGATIVE | NORMAL | SUBNORMAL | ZERO
}

pub fn finite_f64() -> impl Strategy<Value = f64> {
    use proptest::num::f64::*;
    POSITIVE | NEGATIVE | NORMAL | SUBNORMAL | ZERO
}

pub fn field_data(n: usize) -> impl Strategy<Value = FieldData> {
    prop_oneof![
        vec(any::<i8>(), n).prop_map(FieldData::I8),
        vec(any::<u8>(), n).prop_map(FieldData::U8),
        vec(any::<i16>(), n).prop_map(FieldData::I16),
        vec(any::<u16>(), n).prop_map(FieldData::U16),
        vec(any::<i32>(), n).prop_map(FieldData::I32),
        vec(any::<u32>(), n).prop_map(FieldData::U32),
        vec(finite_f32(), n).prop_map(FieldData::F32),
        vec(finite_f64(), n).prop_map(FieldData::F64),
    ]
}

pub fn pose() -> impl Strategy<Value = SensorPose> {
    let angle = -3.2f64..3.2;
    (vec(-100.0f64..100.0, 3), angle.clone(), angle.clone(), angle).prop_map(|(t, r, p, y)| {
        let rotation = UnitQuaternion::from_euler_angles(r, p, y);
        SensorPose {
            world_from_sensor: Isometry3::from_parts(
                Vector3::new(t[0], t[1], t[2]).into(),
                rotation,
            ),
        }
    })
}
