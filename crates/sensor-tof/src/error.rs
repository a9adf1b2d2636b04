//! Errors.

use thiserror::Error;

/// Everything that can go wrong in this crate: bad parameters, bad images, mismatched frames,
/// files. Messages name the parameter or image and the offending value.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum TofError {
    /// A parameter out of its domain.
    #[error("bad {what}: {why}")]
    BadParameter {
        /// Which parameter.
        what: &'static str,
        /// Its value and the domain.
        why: String,
    },
    /// An image of the wrong size or with invalid values.
    #[error("bad {what} image: {why}")]
    BadImage {
        /// Which image.
        what: &'static str,
        /// What is wrong.
        why: String,
    },
    /// Frames, filters or truths that do not belong together.
    #[error("mismatch: {why}")]
    Mismatch {
        /// What differs.
        why: String,
    },
    /// Reading or writing a file.
    #[error(transparent)]
    Io(#[from] pointcloud::io::Error),
    /// A sidecar or calibration file that is not valid JSON of the expected shape.
    #[error("{path}: {why}")]
    Json {
        /// The file.
        path: String,
        /// What is wrong.
        why: String,
    },
    /// A simulated scene could not be built.
    #[error(transparent)]
    Scene(#[from] scene_sim::SceneError),
}

/// A failure of [`pointcloud::io::write_atomically`], as [`TofError::Io`] naming the file.
impl From<pointcloud::io::WriteError> for TofError {
    fn from(e: pointcloud::io::WriteError) -> TofError {
        TofError::Io(e.into())
    }
}
