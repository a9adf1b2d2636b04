//! The crate's error type.

use thiserror::Error;

/// Everything that can go wrong: absurd parameters, bad input clouds, writing a histogram.
/// Messages name the parameter and the offending value.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum HoughError {
    /// A parameter outside its domain (ranges, resolutions, thresholds, limits, mounts).
    #[error("bad {what}: {value} (allowed: {allowed})")]
    BadParameter {
        /// Which parameter.
        what: &'static str,
        /// Its value (radians for angles, metres for lengths).
        value: f64,
        /// The domain, in words.
        allowed: &'static str,
    },
    /// A range whose minimum is not below its maximum, or with a non-finite end.
    #[error("empty or non-finite {what} range [{min}, {max})")]
    EmptyRange {
        /// Which axis.
        what: &'static str,
        /// Lower end.
        min: f64,
        /// Upper end.
        max: f64,
    },
    /// A discretisation with more bins or cells than [`crate::MAX_BINS`].
    #[error("{what} would need {bins} bins (at most {limit})")]
    TooManyBins {
        /// Which structure.
        what: &'static str,
        /// Bins asked for.
        bins: u64,
        /// The limit.
        limit: u64,
    },
    /// An input point with a NaN or infinite coordinate.
    #[error("point {index} is not finite")]
    NonFinitePoint {
        /// Its index in the input.
        index: usize,
    },
    /// An input with no points at all.
    #[error("empty point cloud")]
    EmptyCloud,
    /// The floor plane (ρx = ρy = 0, d = sensor height) has no bin in the Hough space.
    #[error("the floor has no bin: {why}")]
    NoFloorBin {
        /// Which part is missing.
        why: String,
    },
    /// Sizes that do not belong together (counts vs. Hough space, accumulators to merge).
    #[error("size mismatch: {why}")]
    Mismatch {
        /// What differs.
        why: String,
    },
    /// Too few usable points (finite, within range) for a fit.
    #[error("{got} usable points, at least {need} needed")]
    NotEnoughPoints {
        /// Usable points.
        got: usize,
        /// Points needed.
        need: usize,
    },
    /// The mount search found no plane within its tilt and height limits.
    #[error(
        "no ground plane found: none of {tried} sampled planes was within {max_tilt_deg:.0}° of level and the height limits with its points spread over an area"
    )]
    NoGround {
        /// Planes sampled.
        tried: usize,
        /// The tilt limit, degrees.
        max_tilt_deg: f64,
    },
    /// A name (of a method) that is not known.
    #[error("unknown {what} `{name}` (known: {allowed})")]
    UnknownName {
        /// What was named.
        what: &'static str,
        /// The name given.
        name: String,
        /// The known names.
        allowed: String,
    },
    /// Writing the histogram image.
    #[error("writing PNG: {0}")]
    Png(String),
    /// Writing the histogram file (the message names it).
    #[error(transparent)]
    Io(#[from] std::io::Error),
}

/// A failure of [`pointcloud::io::write_atomically`], as [`HoughError::Io`] naming the file.
impl From<pointcloud::io::WriteError> for HoughError {
    fn from(e: pointcloud::io::WriteError) -> HoughError {
        HoughError::Io(e.into())
    }
}

/// Shorthand for this crate's results.
pub type Result<T, E = HoughError> = std::result::Result<T, E>;
