//! Our errors as the Python exceptions of `patchnav.errors`.
//!
//! The classes are defined in Python (`patchnav/errors.py`) so that they can derive from
//! both `PatchnavError` and the matching built-in (`ValueError`, `OSError`); this module
//! looks them up when it raises. Messages are the whole `anyhow` context chain.

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

/// The exception classes of `patchnav.errors`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    /// A bad argument: array shape, dtype, non-finite value, unknown name, absurd parameter.
    InvalidInput,
    /// A file that cannot be read or written.
    Read,
    /// A map that cannot be built, loaded or queried.
    Map,
    /// A planning run that cannot start.
    Plan,
    /// A terrain frame that cannot be classified or segmented.
    Terrain,
    /// A time-of-flight frame that cannot be filtered.
    Tof,
}

impl Kind {
    fn class_name(self) -> &'static str {
        match self {
            Kind::InvalidInput => "InvalidInputError",
            Kind::Read => "ReadError",
            Kind::Map => "MapError",
            Kind::Plan => "PlanError",
            Kind::Terrain => "TerrainError",
            Kind::Tof => "TofError",
        }
    }
}

/// A Python exception of `kind` with `message`.
pub(crate) fn raise(py: Python<'_>, kind: Kind, message: String) -> PyErr {
    let class = py
        .import("patchnav.errors")
        .and_then(|m| m.getattr(kind.class_name()))
        .and_then(|class| class.call1((message.clone(),)));
    match class {
        Ok(exception) => PyErr::from_value(exception),
        // The module is imported without its package: still an exception, never a crash.
        Err(_) => PyRuntimeError::new_err(message),
    }
}

/// An [`Kind::InvalidInput`] exception.
pub(crate) fn invalid(py: Python<'_>, message: impl Into<String>) -> PyErr {
    raise(py, Kind::InvalidInput, message.into())
}

/// `error` as the exception of `kind`, or [`Kind::Read`] when a file could not be read or
/// written.
pub(crate) fn from_anyhow(py: Python<'_>, kind: Kind, error: &anyhow::Error) -> PyErr {
    let is_file = error.chain().any(|e| {
        e.is::<std::io::Error>()
            || e.is::<pointcloud::io::Error>()
            || e.is::<patch_map::mapfile::MapFileError>()
    });
    let kind = if is_file && kind != Kind::InvalidInput { Kind::Read } else { kind };
    raise(py, kind, format!("{error:#}"))
}
