//! `read_cloud`, `classify_terrain`, `ground_points` and `tof_filter`.

use crate::arrays;
use crate::errors::{Kind, from_anyhow, invalid};
use crate::map::parse;
use hough_terrain::{GroundSettings, Method};
use numpy::{PyArray1, PyArrayMethods};
use patch_pipeline::input::{CloudInput, DepthConvention};
use patch_pipeline::terrain::ground::{GroundSetup, segment_cloud_ground};
use patch_pipeline::terrain::{AxesChoice, TerrainSetup, class_name, classify_cloud};
use patch_pipeline::tof::{FilterSetup, FrameSource, filter_loaded};
use pointcloud::{FieldData, PointCloud};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use sensor_tof::TofFrame;
use std::path::{Path, PathBuf};

/// Per pixel (organised) or per point: `values[point]`, `missing` where a pixel has none.
fn per_cell<T: Copy>(cloud: &PointCloud, values: impl Fn(usize) -> T, missing: T) -> Vec<T> {
    arrays::pixel_points(cloud).iter().map(|c| c.map_or(missing, &values)).collect()
}

/// What `read_cloud` returns: points, attributes, organised shape, pose (or `None`).
type CloudParts<'py> =
    (Bound<'py, PyAny>, Bound<'py, PyDict>, Option<(usize, usize)>, Bound<'py, PyAny>);

/// Reads a point cloud, range image or scan file (any format `patchnav` reads): the points,
/// their attributes as float64 arrays, the organised shape and the sensor pose.
#[pyfunction]
#[pyo3(signature = (path, *, skip_non_finite = false, depth = None))]
pub(crate) fn read_cloud<'py>(
    py: Python<'py>,
    path: PathBuf,
    skip_non_finite: bool,
    depth: Option<&str>,
) -> PyResult<CloudParts<'py>> {
    let depth: Option<DepthConvention> = depth.map(|d| parse(py, "depth", d)).transpose()?;
    let input = CloudInput { skip_non_finite, depth };
    let cloud = py
        .detach(|| patch_pipeline::input::read_cloud(&path, &input))
        .map_err(|e| from_anyhow(py, Kind::Read, &e))?;
    let attributes = PyDict::new(py);
    let n = arrays::pixel_points(&cloud).len();
    let add = |name: &str, values: Vec<f64>| -> PyResult<()> {
        attributes.set_item(name, PyArray1::from_vec(py, values))
    };
    if let Some(v) = cloud.intensity() {
        add("intensity", per_cell(&cloud, |i| f64::from(v[i]), f64::NAN))?;
    }
    if let Some(v) = cloud.labels() {
        add("label", per_cell(&cloud, |i| f64::from(v[i]), f64::NAN))?;
    }
    if let Some(v) = cloud.rings() {
        add("ring", per_cell(&cloud, |i| f64::from(v[i]), f64::NAN))?;
    }
    if let Some(v) = cloud.normals() {
        let flat: Vec<f64> = per_cell(&cloud, |i| [v[i].x, v[i].y, v[i].z], [f64::NAN; 3])
            .into_iter()
            .flatten()
            .collect();
        let normals = PyArray1::from_vec(py, flat).reshape([n, 3])?;
        attributes.set_item("normal", normals)?;
    }
    for field in cloud.extra_fields() {
        let data: &FieldData = &field.data;
        add(&field.name, per_cell(&cloud, |i| data.get_f64(i).unwrap_or(f64::NAN), f64::NAN))?;
    }
    let pose = match cloud.sensor_pose() {
        Some(p) => {
            let m = p.world_from_sensor.to_homogeneous();
            let rows: Vec<f64> = (0..4).flat_map(|r| (0..4).map(move |c| m[(r, c)])).collect();
            PyArray1::from_vec(py, rows).reshape([4, 4])?.into_any()
        }
        None => py.None().into_bound(py),
    };
    Ok((
        arrays::cloud_points(py, &cloud).into_any(),
        attributes,
        arrays::organised_shape(&cloud),
        pose,
    ))
}

fn axes_of(py: Python<'_>, axes: Option<&str>) -> PyResult<Option<AxesChoice>> {
    axes.map(|a| parse(py, "axes", a)).transpose()
}

const SOURCE: &str = "<array>";

/// The terrain class and drivability of the view ahead by the plane Hough transform (thesis
/// Ch. 4; `patchnav terrain`).
#[pyfunction]
#[pyo3(signature = (
    points, *, resolution = 15.0, method = "ground-ahead", axes = None, sensor_height = None,
    pitch = None, max_range = None, sectors = None
))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn classify_terrain<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    resolution: f64,
    method: &str,
    axes: Option<&str>,
    sensor_height: Option<f64>,
    pitch: Option<f64>,
    max_range: Option<f64>,
    sectors: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let method: Method = parse(py, "method", method)?;
    let cloud = arrays::cloud(py, points, "points")?;
    let setup = TerrainSetup {
        resolution,
        method,
        sectors,
        axes: axes_of(py, axes)?,
        sensor_height,
        pitch,
        max_range,
        ..TerrainSetup::new(PathBuf::from(SOURCE))
    };
    let c = py
        .detach(|| classify_cloud(&cloud, &setup))
        .map_err(|e| from_anyhow(py, Kind::Terrain, &e))?;
    let d = PyDict::new(py);
    d.set_item("class", class_name(&c.result))?;
    d.set_item("drivable", c.result.drivable)?;
    d.set_item("passable", c.result.passable)?;
    d.set_item("rule", format!("{:?}", c.result.rule))?;
    d.set_item("step", c.result.step)?;
    d.set_item("points", c.points.len())?;
    d.set_item("axes", c.axes.name())?;
    d.set_item("mount", c.mount)?;
    d.set_item("mount_estimated", c.estimated.is_some())?;
    d.set_item("seconds", c.seconds)?;
    let sectors: Vec<(String, bool)> = c
        .sectors
        .iter()
        .map(|s| (class_name(&s.classification), s.classification.drivable))
        .collect();
    d.set_item("sectors", sectors)?;
    Ok(d)
}

/// Sets the fields of `settings` named in `overrides` (numbers; `max_step` and `max_slope`
/// set the robot's limits).
fn ground_settings(
    py: Python<'_>,
    overrides: Option<&Bound<'_, PyDict>>,
) -> PyResult<GroundSettings> {
    let mut s = GroundSettings::default();
    let Some(overrides) = overrides else { return Ok(s) };
    for (key, value) in overrides.iter() {
        let key: String = key.extract()?;
        let number: f64 = value
            .extract()
            .map_err(|_| invalid(py, format!("settings[{key:?}]: want a number")))?;
        let count = || -> PyResult<usize> {
            if number.fract() == 0.0 && (0.0..=1e9).contains(&number) {
                Ok(number as usize)
            } else {
                Err(invalid(py, format!("settings[{key:?}]: want a whole number, not {number}")))
            }
        };
        macro_rules! fields {
            ($($f:ident),*; $($n:ident),*) => {
                match key.as_str() {
                    "max_step" => s.limits.max_step = number,
                    "max_slope" => s.limits.max_slope = number,
                    $(stringify!($f) => s.$f = number,)*
                    $(stringify!($n) => s.$n = count()?,)*
                    _ => return Err(invalid(py, format!(
                        "settings: unknown key {key:?}; known: max_step, max_slope, {}",
                        [$(stringify!($f)),*, $(stringify!($n)),*].join(", ")
                    ))),
                }
            };
        }
        fields!(
            min_range, max_range, min_cell, cell_growth, seed_band, seed_band_per_width,
            min_spread, max_roughness, rough_height, fit_band, band_sigmas, min_band, max_band,
            band_per_width, reference_band, seed_step, grade;
            min_points, seed_points, fit_iterations, max_gap_rings
        );
    }
    Ok(s)
}

/// Per point (or per pixel of an organised array): whether it is drivable ground (the
/// per-point segmentation of `patchnav terrain --ground-out`).
#[pyfunction]
#[pyo3(signature = (points, *, axes = None, mount = None, settings = None))]
pub(crate) fn ground_points<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    axes: Option<&str>,
    mount: Option<(f64, f64, f64)>,
    settings: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let cloud = arrays::cloud(py, points, "points")?;
    let setup = GroundSetup {
        axes: axes_of(py, axes)?,
        mount,
        settings: ground_settings(py, settings)?,
        ..GroundSetup::new(PathBuf::from(SOURCE))
    };
    let grounded = py
        .detach(|| segment_cloud_ground(&cloud, &setup))
        .map_err(|e| from_anyhow(py, Kind::Terrain, &e))?;
    let labels = per_cell(&cloud, |i| grounded.labels[i], false);
    Ok(match arrays::organised_shape(&cloud) {
        Some((h, w)) => arrays::image(py, labels, h, w).into_any(),
        None => PyArray1::from_vec(py, labels).into_any(),
    })
}

/// Filters a time-of-flight frame (thesis §2.5.5; `patchnav tof filter`): range (metres, 0 =
/// no measurement) and amplitude as H × W arrays, `meta` the frame's sidecar (a dict, or the
/// path of its JSON file).
#[pyfunction]
#[pyo3(signature = (
    range, amplitude, meta, *, method = "regions", at = 160.0, aat = None, unwrap = false,
    low_at = None, radial = false, intensity = None
))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn tof_filter<'py>(
    py: Python<'py>,
    range: &Bound<'py, PyAny>,
    amplitude: &Bound<'py, PyAny>,
    meta: &Bound<'py, PyAny>,
    method: &str,
    at: f64,
    aat: Option<f64>,
    unwrap: bool,
    low_at: Option<f64>,
    radial: bool,
    intensity: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    use patch_pipeline::tof::Method as TofMethod;
    let method: TofMethod = parse(py, "method", method)?;
    if method == TofMethod::TwoFreq {
        return Err(invalid(
            py,
            "method two-freq reads two frames from files: use `patchnav tof filter`",
        ));
    }
    let (meta, meta_path) = if let Ok(d) = meta.cast::<PyDict>() {
        let text: String = py.import("json")?.call_method1("dumps", (d,))?.extract()?;
        let meta = sensor_tof::io::parse_meta(&text, Path::new("<meta>"))
            .map_err(|e| invalid(py, format!("meta: {e}")))?;
        (meta, PathBuf::from("<meta>"))
    } else if meta.is_instance_of::<PyString>() || meta.hasattr("__fspath__")? {
        let path: PathBuf = meta.extract()?;
        let meta = sensor_tof::io::read_meta(&path)
            .map_err(|e| crate::errors::raise(py, Kind::Read, format!("{e}")))?;
        (meta, path)
    } else {
        return Err(invalid(py, "meta: want the sidecar as a dict or the path of its JSON file"));
    };
    let camera = meta.camera().map_err(|e| invalid(py, format!("meta: {e}")))?;
    let (w, h) = (camera.width as usize, camera.height as usize);
    let image = |obj: &Bound<'py, PyAny>, what: &str| -> PyResult<Vec<f32>> {
        let a = arrays::floats(obj, what)?;
        let a = a.as_array();
        if a.shape() != [h, w] {
            return Err(invalid(
                py,
                format!("{what}: want the camera's {h} × {w} image, got shape {:?}", a.shape()),
            ));
        }
        Ok(a.as_standard_layout().iter().map(|&v| v as f32).collect())
    };
    let mut frame = TofFrame::new(
        camera,
        meta.range_kind,
        image(range, "range")?,
        image(amplitude, "amplitude")?,
    )
    .map_err(|e| invalid(py, format!("{e}")))?;
    if let Some(i) = intensity {
        frame = frame
            .with_intensity(image(i, "intensity")?)
            .map_err(|e| invalid(py, format!("{e}")))?;
    }
    let frame_source =
        FrameSource { range: None, amplitude: None, confidence: None, meta: meta_path };
    let setup =
        FilterSetup { at, aat, unwrap, low_at, radial, ..FilterSetup::new(frame_source, method) };
    let (output, name) = py
        .detach(|| filter_loaded(&frame, &meta, &setup))
        .map_err(|e| from_anyhow(py, Kind::Tof, &e))?;
    let cloud = output.to_cloud(&frame, false);
    let d = PyDict::new(py);
    d.set_item("method", name)?;
    d.set_item("range", arrays::image(py, output.radial.clone(), h, w))?;
    let outcomes: Vec<u8> = output.outcomes.iter().map(|&o| o as u8).collect();
    d.set_item("outcome", arrays::image(py, outcomes, h, w))?;
    d.set_item("points", arrays::cloud_points(py, &cloud).reshape([h, w, 3])?)?;
    d.set_item("kept", output.counts.kept)?;
    d.set_item("unwrapped", output.counts.unwrapped)?;
    d.set_item("dropped", output.counts.dropped)?;
    Ok(d)
}
