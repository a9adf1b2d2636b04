//! `Map` (a map of any backend), `extract` (scans to a map) and `plan` (one planning run).

use crate::arrays;
use crate::errors::{Kind, from_anyhow, invalid};
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use patch_core::{CapsuleStep, Real, UnspecificStepIntersector};
use patch_map::{AnyMap, Backend};
use patch_pipeline::SensorPreset;
use patch_pipeline::names::Named;
use patch_pipeline::plan::{PlanSetup, plan_on_map};
use patch_pipeline::preset::ExtractChoices;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use roadmap::{PathMetrics, PlannerKind};
use std::num::NonZeroUsize;
use std::path::PathBuf;
use std::sync::Arc;

/// A name of one of our vocabularies, or an `InvalidInputError` listing the known names.
pub(crate) fn parse<T: Named>(py: Python<'_>, what: &str, name: &str) -> PyResult<T>
where
    T::Err: std::fmt::Display,
{
    name.parse::<T>().map_err(|e| invalid(py, format!("{what}: {e}")))
}

/// A map a robot plans on, of any backend (`patch_map::AnyMap`). Immutable: share it between
/// threads freely.
#[pyclass(frozen, module = "patchnav._patchnav", name = "Map")]
pub(crate) struct Map {
    inner: Arc<AnyMap>,
}

fn positive(py: Python<'_>, what: &str, value: Real) -> PyResult<Real> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(invalid(py, format!("{what} must be a positive number of metres, not {value}")))
    }
}

#[pymethods]
impl Map {
    /// A map from a triangle mesh: coplanar faces become planar patches
    /// (`patch_map::planar_patches_from_mesh` with the exact-CAD tolerances), as `patchnav map
    /// build` does with an OBJ file.
    #[staticmethod]
    #[pyo3(signature = (vertices, triangles, backend = "bbox6d", spacing = None))]
    fn from_mesh(
        py: Python<'_>,
        vertices: &Bound<'_, PyAny>,
        triangles: &Bound<'_, PyAny>,
        backend: &str,
        spacing: Option<Real>,
    ) -> PyResult<Map> {
        let backend: Backend = parse(py, "backend", backend)?;
        let vertices = arrays::points(py, vertices, "vertices")?;
        let t = arrays::floats(triangles, "triangles")?;
        let t = t.as_array();
        if t.ndim() != 2 || t.shape()[1] != 3 {
            return Err(invalid(
                py,
                format!("triangles: want an M × 3 array, got {:?}", t.shape()),
            ));
        }
        let mut faces = Vec::with_capacity(t.shape()[0]);
        for (i, row) in t.outer_iter().enumerate() {
            let mut face = Vec::with_capacity(3);
            for &v in row {
                if v.fract() != 0.0 || v < 0.0 || v >= vertices.len() as f64 {
                    return Err(invalid(
                        py,
                        format!(
                            "triangles: row {i} names vertex {v}; want whole numbers below {}",
                            vertices.len()
                        ),
                    ));
                }
                face.push(v as u32);
            }
            faces.push(face);
        }
        let mesh = pointcloud::PolygonMesh::new(vertices, faces)
            .map_err(|e| invalid(py, format!("mesh: {e}")))?;
        let map = py
            .detach(|| {
                let config = patch_map::MeshToPatchesConfig::exact_cad();
                let (patches, _) = patch_map::planar_patches_from_mesh(&mesh, &config);
                patch_pipeline::files::map_of_patches(patches, backend, spacing)
            })
            .map_err(|e| from_anyhow(py, Kind::Map, &e))?;
        Ok(Map { inner: Arc::new(map) })
    }

    /// Reads a map file (`patchnav map build`, `patchnav extract`, `Map.save`).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Map> {
        let map = py
            .detach(|| patch_pipeline::files::open_map(&path))
            .map_err(|e| from_anyhow(py, Kind::Map, &e))?;
        Ok(Map { inner: Arc::new(map) })
    }

    /// Writes the map file (atomically); returns its size in bytes.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<u64> {
        let map = Arc::clone(&self.inner);
        let (bytes, _) = py
            .detach(|| patch_pipeline::files::save_map(&map, &path))
            .map_err(|e| from_anyhow(py, Kind::Map, &e))?;
        Ok(bytes)
    }

    /// Per step `i`: whether the robot (a sphere of `radius`) moves from `starts[i]` to
    /// `ends[i]` without touching the map (the capsule test every planner asks).
    fn is_free<'py>(
        &self,
        py: Python<'py>,
        starts: &Bound<'py, PyAny>,
        ends: &Bound<'py, PyAny>,
        radius: Real,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let radius = positive(py, "radius", radius)?;
        let starts = arrays::one_or_many(py, starts, "starts")?;
        let ends = arrays::one_or_many(py, ends, "ends")?;
        if starts.len() != ends.len() {
            return Err(invalid(
                py,
                format!(
                    "starts has {} rows, ends {}: want one end per start",
                    starts.len(),
                    ends.len()
                ),
            ));
        }
        let steps = starts
            .iter()
            .zip(&ends)
            .map(|(a, b)| CapsuleStep::new(*a, *b, radius))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| invalid(py, format!("step: {e}")))?;
        let map = Arc::clone(&self.inner);
        let free: Vec<bool> = py.detach(|| steps.iter().map(|s| map.is_step_free(s)).collect());
        Ok(PyArray1::from_vec(py, free))
    }

    /// The backend's name (`bbox6d`, `trimesh`, ...).
    #[getter]
    fn backend(&self) -> &'static str {
        self.inner.backend().name()
    }

    /// The box around the map: `(min, max)`, each an array of 3.
    #[getter]
    fn bounds<'py>(
        &self,
        py: Python<'py>,
    ) -> (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>) {
        let b = self.inner.bounds();
        (
            PyArray1::from_vec(py, vec![b.min.x, b.min.y, b.min.z]),
            PyArray1::from_vec(py, vec![b.max.x, b.max.y, b.max.z]),
        )
    }

    /// What the map holds: planar and trimesh patches, triangles, points, bytes in memory.
    fn counts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let c = self.inner.counts();
        let d = PyDict::new(py);
        d.set_item("planar_patches", c.planar_patches)?;
        d.set_item("trimesh_patches", c.trimesh_patches)?;
        d.set_item("triangles", c.triangles)?;
        d.set_item("points", c.points)?;
        d.set_item("memory_bytes", self.inner.memory_bytes())?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        let c = self.inner.counts();
        format!(
            "Map(backend={:?}, planar_patches={}, trimesh_patches={}, points={})",
            self.inner.backend().name(),
            c.planar_patches,
            c.trimesh_patches,
            c.points
        )
    }
}

/// Patches from range scans, merged across scans, as a map (thesis §5.3; `patchnav extract`).
#[pyfunction]
#[pyo3(signature = (
    scans, sensor = "alrf", pose = None, *, hybrid = false, merge = true, second_pass = true,
    carve = false, slab_thickness = None, backend = "bbox6d", spacing = None, threads = None
))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn extract(
    py: Python<'_>,
    scans: &Bound<'_, PyAny>,
    sensor: &str,
    pose: Option<&Bound<'_, PyAny>>,
    hybrid: bool,
    merge: bool,
    second_pass: bool,
    carve: bool,
    slab_thickness: Option<Real>,
    backend: &str,
    spacing: Option<Real>,
    threads: Option<usize>,
) -> PyResult<Map> {
    let sensor: SensorPreset = parse(py, "sensor", sensor)?;
    let backend: Backend = parse(py, "backend", backend)?;
    if carve && !hybrid {
        return Err(invalid(py, "carve=True needs hybrid=True: it drops remainder triangles"));
    }
    if let Some(t) = slab_thickness
        && !(t.is_finite() && t >= 0.0)
    {
        return Err(invalid(py, format!("slab_thickness must be ≥ 0 metres, not {t}")));
    }
    // One scan (an array) or a list of them, with one pose or a list of poses.
    let (scan_objs, many) = match scans.cast::<PyList>() {
        Ok(list) => (list.iter().collect::<Vec<_>>(), true),
        Err(_) => (vec![scans.clone()], false),
    };
    if scan_objs.is_empty() {
        return Err(invalid(py, "scans: the list is empty"));
    }
    let poses: Vec<Option<Bound<'_, PyAny>>> = match pose {
        None => vec![None; scan_objs.len()],
        Some(p) if many && p.cast::<PyList>().is_ok() => {
            let list: Vec<_> = p.cast::<PyList>()?.iter().map(Some).collect();
            if list.len() != scan_objs.len() {
                return Err(invalid(
                    py,
                    format!("pose: {} poses for {} scans", list.len(), scan_objs.len()),
                ));
            }
            list
        }
        Some(p) if many => {
            return Err(invalid(py, format!("pose: give one 4 × 4 pose per scan, not {p}")));
        }
        Some(p) => vec![Some(p.clone())],
    };
    let mut clouds = Vec::with_capacity(scan_objs.len());
    for (i, (scan, pose)) in scan_objs.iter().zip(&poses).enumerate() {
        let what = if many { format!("scans[{i}]") } else { "scans".to_owned() };
        let mut cloud = arrays::cloud(py, scan, &what)?;
        if let Some(p) = pose {
            let world_from_sensor = arrays::pose(py, p, &format!("pose of {what}"))?;
            cloud.set_sensor_pose(Some(pointcloud::SensorPose { world_from_sensor }));
        }
        clouds.push(cloud);
    }
    let choices = ExtractChoices { sensor, hybrid, merge, second_pass, carve, slab_thickness };
    let threads = match threads {
        Some(0) => return Err(invalid(py, "threads must be at least 1")),
        Some(n) => NonZeroUsize::new(n).unwrap_or(NonZeroUsize::MIN),
        None => std::thread::available_parallelism().unwrap_or(NonZeroUsize::MIN),
    };
    let map = py
        .detach(|| -> anyhow::Result<AnyMap> {
            let config = choices.config();
            let result =
                patch_extract::pipeline::extract_with_threads(&clouds, &config, threads, |_| {})?;
            patch_pipeline::files::map_of_patches(result.into_map_patches(), backend, spacing)
        })
        .map_err(|e| from_anyhow(py, Kind::Map, &e))?;
    Ok(Map { inner: Arc::new(map) })
}

/// One planning run on `map` (`patchnav plan`): the path to the first goal (K × 3; empty
/// when unreached) and the run's statistics.
#[pyfunction]
#[pyo3(signature = (
    map, start, goals, planner, radius, seed = 0, iterations = 10_000, *,
    step = 1.0, goal_tolerance = 0.5, explore = false, shortcut = false, roadmap = false
))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn plan<'py>(
    py: Python<'py>,
    map: &Map,
    start: &Bound<'py, PyAny>,
    goals: &Bound<'py, PyAny>,
    planner: &str,
    radius: Real,
    seed: u64,
    iterations: u64,
    step: Real,
    goal_tolerance: Real,
    explore: bool,
    shortcut: bool,
    roadmap: bool,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyDict>)> {
    let kind: PlannerKind = parse(py, "planner", planner)?;
    let start = arrays::point(py, start, "start")?;
    let goals = arrays::one_or_many(py, goals, "goals")?;
    let setup = PlanSetup {
        start,
        goals,
        goal_tolerance,
        planner: kind,
        radius,
        step,
        seed,
        iterations,
        explore,
        shortcut,
    };
    let shared = Arc::clone(&map.inner);
    let outcome =
        py.detach(|| plan_on_map(&shared, &setup)).map_err(|e| from_anyhow(py, Kind::Plan, &e))?;
    let c = outcome.counters;
    let stats = PyDict::new(py);
    stats.set_item("planner", outcome.planner)?;
    stats.set_item("status", format!("{:?}", outcome.status))?;
    stats.set_item("samples", c.samples)?;
    stats.set_item("vertices", c.vertices)?;
    stats.set_item("edges", c.edges)?;
    stats.set_item("collision_checks", c.collision_checks)?;
    stats.set_item("collision_time_s", c.collision_time.as_secs_f64())?;
    stats.set_item("reached", outcome.paths.iter().map(Option::is_some).collect::<Vec<_>>())?;
    let paths = PyList::empty(py);
    let lengths = PyList::empty(py);
    for p in &outcome.paths {
        match p {
            Some(p) => {
                paths.append(arrays::points_out(py, p))?;
                lengths.append(PathMetrics::of(p).length)?;
            }
            None => {
                paths.append(py.None())?;
                lengths.append(py.None())?;
            }
        }
    }
    stats.set_item("paths", paths)?;
    stats.set_item("lengths", lengths)?;
    if shortcut {
        let shortcuts = PyList::empty(py);
        for p in &outcome.shortcuts {
            match p {
                Some(p) => shortcuts.append(arrays::points_out(py, p))?,
                None => shortcuts.append(py.None())?,
            }
        }
        stats.set_item("shortcuts", shortcuts)?;
    }
    if roadmap {
        let g = &outcome.roadmap;
        let vertices: Vec<_> = g.node_weights().copied().collect();
        let edges: Vec<usize> = g
            .edge_indices()
            .filter_map(|e| g.edge_endpoints(e))
            .flat_map(|(a, b)| [a.index(), b.index()])
            .collect();
        let n = edges.len() / 2;
        stats.set_item("roadmap_vertices", arrays::points_out(py, &vertices))?;
        stats.set_item(
            "roadmap_edges",
            PyArray1::from_vec(py, edges).reshape([n, 2]).expect("E × 2 elements"),
        )?;
    }
    let path = outcome.paths[0].as_deref().unwrap_or_default();
    Ok((arrays::points_out(py, path), stats))
}
