//! numpy arrays in and out, checked: any array-like of numbers (lists, any dtype numpy can
//! cast to float64, any strides) is accepted; a wrong shape or a non-finite value is an
//! `InvalidInputError` that names the argument and the row.

use crate::errors::invalid;
use numpy::ndarray::{ArrayViewD, Axis};
use numpy::{AllowTypeChange, PyArray1, PyArray2, PyArrayLikeDyn, PyArrayMethods};
use patch_core::{Isometry3, Point3};
use pointcloud::PointCloud;
use pyo3::prelude::*;

/// `obj` as a float64 array (a read-only view, copied only when numpy must cast).
pub(crate) fn floats<'py>(
    obj: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<PyArrayLikeDyn<'py, f64, AllowTypeChange>> {
    obj.extract().map_err(|e| invalid(obj.py(), format!("{what}: not an array of numbers ({e})")))
}

fn shape_text(a: &ArrayViewD<'_, f64>) -> String {
    let dims: Vec<String> = a.shape().iter().map(usize::to_string).collect();
    format!("({})", dims.join(", "))
}

/// An N × 3 array of finite numbers as points.
pub(crate) fn points(py: Python<'_>, obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<Point3>> {
    let a = floats(obj, what)?;
    let a = a.as_array();
    if a.ndim() != 2 || a.shape()[1] != 3 {
        return Err(invalid(
            py,
            format!("{what}: want an N × 3 array, got shape {}", shape_text(&a)),
        ));
    }
    let mut out = Vec::with_capacity(a.shape()[0]);
    for (i, row) in a.axis_iter(Axis(0)).enumerate() {
        let p = Point3::new(row[0], row[1], row[2]);
        if !p.iter().all(|c| c.is_finite()) {
            return Err(invalid(py, format!("{what}: row {i} is not finite ({p:?})")));
        }
        out.push(p);
    }
    Ok(out)
}

/// One point: a sequence of 3 finite numbers.
pub(crate) fn point(py: Python<'_>, obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Point3> {
    let a = floats(obj, what)?;
    let a = a.as_array();
    if a.len() != 3 || a.ndim() > 2 {
        return Err(invalid(
            py,
            format!("{what}: want 3 numbers x, y, z, got shape {}", shape_text(&a)),
        ));
    }
    let v: Vec<f64> = a.iter().copied().collect();
    let p = Point3::new(v[0], v[1], v[2]);
    if !p.iter().all(|c| c.is_finite()) {
        return Err(invalid(py, format!("{what}: {p:?} is not finite")));
    }
    Ok(p)
}

/// One point (3 numbers) or an N × 3 array, as points.
pub(crate) fn one_or_many(
    py: Python<'_>,
    obj: &Bound<'_, PyAny>,
    what: &str,
) -> PyResult<Vec<Point3>> {
    let ndim = floats(obj, what)?.as_array().ndim();
    if ndim == 1 { Ok(vec![point(py, obj, what)?]) } else { points(py, obj, what) }
}

/// A scan: an N × 3 array of finite points (unorganised), or an H × W × 3 array (organised;
/// a pixel with a non-finite coordinate has no measurement).
pub(crate) fn cloud(py: Python<'_>, obj: &Bound<'_, PyAny>, what: &str) -> PyResult<PointCloud> {
    let a = floats(obj, what)?;
    let a = a.as_array();
    match a.shape() {
        [_, 3] => PointCloud::from_positions(points(py, obj, what)?)
            .map_err(|e| invalid(py, format!("{what}: {e}"))),
        &[h, w, 3] => {
            let (Ok(height), Ok(width)) = (u32::try_from(h), u32::try_from(w)) else {
                return Err(invalid(py, format!("{what}: {h} × {w} pixels is too large")));
            };
            let pixels = a.as_standard_layout();
            let flat = pixels.as_slice().unwrap_or_default();
            let cells = flat.chunks_exact(3).map(|c| {
                let p = Point3::new(c[0], c[1], c[2]);
                p.iter().all(|c| c.is_finite()).then_some(p)
            });
            PointCloud::from_pixels(width, height, cells)
                .map_err(|e| invalid(py, format!("{what}: {e}")))
        }
        _ => Err(invalid(
            py,
            format!(
                "{what}: want N × 3 points or an organised H × W × 3 array, got shape {}",
                shape_text(&a)
            ),
        )),
    }
}

/// A 4 × 4 rigid transform (`world_from_sensor`).
pub(crate) fn pose(py: Python<'_>, obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Isometry3> {
    let a = floats(obj, what)?;
    let a = a.as_array();
    if a.shape() != [4, 4] {
        return Err(invalid(
            py,
            format!("{what}: want a 4 × 4 matrix, got shape {}", shape_text(&a)),
        ));
    }
    let rows: Vec<f64> = a.iter().copied().collect();
    patch_pipeline::files::rigid_from_rows(&rows).map_err(|e| invalid(py, format!("{what}: {e}")))
}

/// Points as an N × 3 array.
pub(crate) fn points_out<'py>(py: Python<'py>, points: &[Point3]) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = points.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
    PyArray1::from_vec(py, flat).reshape([points.len(), 3]).expect("N × 3 elements")
}

/// Per pixel of `cloud`'s grid (row-major), the index of its point or `None`; per point when
/// it has no grid.
pub(crate) fn pixel_points(cloud: &PointCloud) -> Vec<Option<usize>> {
    match cloud.grid() {
        Some(g) => g
            .pixels()
            .iter()
            .map(|&p| (p != pointcloud::INVALID_PIXEL).then_some(p as usize))
            .collect(),
        None => (0..cloud.len()).map(Some).collect(),
    }
}

/// A cloud's points: N × 3, or for an organised cloud H·W × 3 in row-major pixel order with
/// NaN rows for the pixels without a measurement.
pub(crate) fn cloud_points<'py>(py: Python<'py>, cloud: &PointCloud) -> Bound<'py, PyArray2<f64>> {
    let positions = cloud.positions();
    let cells = pixel_points(cloud);
    let flat: Vec<f64> = cells
        .iter()
        .flat_map(|c| c.map_or([f64::NAN; 3], |i| [positions[i].x, positions[i].y, positions[i].z]))
        .collect();
    PyArray1::from_vec(py, flat).reshape([cells.len(), 3]).expect("N × 3 elements")
}

/// The organised shape `(height, width)` of a cloud, if it has one.
pub(crate) fn organised_shape(cloud: &PointCloud) -> Option<(usize, usize)> {
    cloud.grid().map(|g| (g.height() as usize, g.width() as usize))
}

/// An H × W image from row-major values.
pub(crate) fn image<'py, T: numpy::Element>(
    py: Python<'py>,
    values: Vec<T>,
    height: usize,
    width: usize,
) -> Bound<'py, PyArray2<T>> {
    PyArray1::from_vec(py, values).reshape([height, width]).expect("H × W elements")
}
