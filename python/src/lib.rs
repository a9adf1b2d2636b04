//! The extension module `patchnav._patchnav` of the Python package: thin bindings over
//! `patch-pipeline` and the library crates, numpy arrays in and out.
//!
//! Every function checks its arrays (shape, finiteness) before it calls the libraries, and
//! turns their errors into the Python exceptions of `patchnav.errors` (module `errors`). Long
//! calls (reading, extraction, map building, collision queries, planning, terrain and ToF
//! filtering) release the GIL.

mod arrays;
mod errors;
mod map;
mod perception;

use pyo3::prelude::*;

/// The module `patchnav._patchnav`.
#[pymodule]
fn _patchnav(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<map::Map>()?;
    m.add_function(wrap_pyfunction!(map::plan, m)?)?;
    m.add_function(wrap_pyfunction!(map::extract, m)?)?;
    m.add_function(wrap_pyfunction!(perception::read_cloud, m)?)?;
    m.add_function(wrap_pyfunction!(perception::classify_terrain, m)?)?;
    m.add_function(wrap_pyfunction!(perception::ground_points, m)?)?;
    m.add_function(wrap_pyfunction!(perception::tof_filter, m)?)?;
    m.add_function(wrap_pyfunction!(names, m)?)?;
    Ok(())
}

/// The names a vocabulary accepts: `backend`, `planner`, `sensor`, `terrain_method`,
/// `tof_method` or `axes`.
#[pyfunction]
fn names(py: Python<'_>, vocabulary: &str) -> PyResult<Vec<&'static str>> {
    use patch_pipeline::names::Named;
    fn all<T: Named>() -> Vec<&'static str> {
        T::ALL.iter().map(|v| v.name()).collect()
    }
    Ok(match vocabulary {
        "backend" => all::<patch_map::Backend>(),
        "planner" => all::<roadmap::PlannerKind>(),
        "sensor" => all::<patch_pipeline::SensorPreset>(),
        "terrain_method" => all::<hough_terrain::Method>(),
        "tof_method" => all::<patch_pipeline::tof::Method>(),
        "axes" => all::<patch_pipeline::terrain::AxesChoice>(),
        other => {
            return Err(errors::invalid(
                py,
                format!(
                    "unknown vocabulary `{other}`; known: backend, planner, sensor, \
                     terrain_method, tof_method, axes"
                ),
            ));
        }
    })
}
