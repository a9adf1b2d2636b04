//! Typed errors of scene construction and sensor configuration.

/// Why a shape, a material, a scene or a scene name was refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SceneError {
    /// A coordinate, transform or parameter is NaN or infinite.
    #[error("{what} is not finite")]
    NonFinite {
        /// What was not finite.
        what: &'static str,
    },
    /// A transform's rotation is not a unit quaternion.
    #[error("{what}: rotation is not a unit quaternion (norm {norm})")]
    NonUnitRotation {
        /// Which transform.
        what: &'static str,
        /// The norm of the quaternion.
        norm: f64,
    },
    /// A polygon ring has fewer than three vertices.
    #[error("polygon ring {ring} has {count} vertices, needs at least 3")]
    TooFewVertices {
        /// Ring index: 0 is the outline, 1.. the holes.
        ring: usize,
        /// Number of vertices given.
        count: usize,
    },
    /// A polygon ring encloses (almost) no area: collinear or repeated vertices.
    #[error("polygon ring {ring} is degenerate (area {area} m²)")]
    DegeneratePolygon {
        /// Ring index: 0 is the outline, 1.. the holes.
        ring: usize,
        /// The absolute area of the ring.
        area: f64,
    },
    /// A size (radius, half extent, height, distance, ...) is out of its allowed range.
    #[error("{what} is {value}, outside its allowed range {allowed}")]
    BadParameter {
        /// Which parameter.
        what: &'static str,
        /// Its value.
        value: f64,
        /// The allowed range, in words.
        allowed: &'static str,
    },
    /// A reflectivity outside `[0, 1]` (or NaN).
    #[error("reflectivity {value} is outside [0, 1]")]
    BadReflectivity {
        /// The value.
        value: f32,
    },
    /// A scene needs at least one primitive.
    #[error("a scene needs at least one primitive")]
    Empty,
    /// The scene has more surfaces than a `u32` can number.
    #[error("too many surfaces")]
    TooManySurfaces,
    /// `scene_by_name` does not know the name.
    #[error("unknown scene `{name}` (known: {known})")]
    UnknownScene {
        /// The name asked for.
        name: String,
        /// The known names, comma separated.
        known: String,
    },
}

/// Why a sensor configuration was refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SensorError {
    /// The image is empty or too large (more than [`crate::sensors::MAX_PIXELS`] pixels).
    #[error("image size {width}×{height} is empty or too large")]
    ImageSize {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
    },
    /// A parameter is NaN, infinite or out of its allowed range.
    #[error("{what} is {value}, outside its allowed range {allowed}")]
    BadParameter {
        /// Which parameter.
        what: &'static str,
        /// Its value.
        value: f64,
        /// The allowed range, in words.
        allowed: &'static str,
    },
    /// `sensor_by_name` does not know the name.
    #[error("unknown sensor `{name}` (known: {known})")]
    UnknownSensor {
        /// The name asked for.
        name: String,
        /// The known names, comma separated.
        known: String,
    },
}
