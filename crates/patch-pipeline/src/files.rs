//! The files the programs read and write around the pipeline: scan poses (`poses.json`),
//! trajectories (TUM format) and map files of any backend.

use anyhow::{Context, Result, bail};
use patch_core::{Aabb, Isometry3, Patch, Real, na};
use patch_map::{AnyMap, AnyMapError, Backend, load_any};
use pointcloud::io;
use serde_json::Value;
use std::collections::HashMap;
use std::fs::File;
use std::io::BufReader;
use std::path::Path;

/// Reads a `poses.json`: file name → `world_from_sensor`.
///
/// # Errors
/// An unreadable file, no JSON, or an entry without a file name or a rigid 4 × 4 transform.
pub fn read_poses(path: &Path) -> Result<HashMap<String, Isometry3>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let v: Value =
        serde_json::from_str(&text).with_context(|| format!("{} is not JSON", path.display()))?;
    let scans = v
        .get("scans")
        .and_then(Value::as_array)
        .with_context(|| format!("{}: no `scans` array", path.display()))?;
    let mut out = HashMap::new();
    for (i, s) in scans.iter().enumerate() {
        let what = || format!("{}: scans[{i}]", path.display());
        let file = s
            .get("file")
            .and_then(Value::as_str)
            .with_context(|| format!("{}: `file` is missing", what()))?;
        let rows = s
            .get("world_from_sensor")
            .and_then(Value::as_array)
            .with_context(|| format!("{}: `world_from_sensor` is missing", what()))?;
        let m: Vec<Real> = rows
            .iter()
            .flat_map(|r| r.as_array().into_iter().flatten())
            .map(|x| x.as_f64().unwrap_or(Real::NAN))
            .collect();
        let pose =
            rigid_from_rows(&m).with_context(|| format!("{}: `world_from_sensor`", what()))?;
        out.insert(file.to_owned(), pose);
    }
    Ok(out)
}

/// A rigid transform from the 16 entries of a 4 × 4 matrix, row by row.
///
/// # Errors
/// Not 16 finite numbers, or not a rotation (orthonormal to 1e-6, determinant +1) and a
/// translation over the row `0 0 0 1`.
pub fn rigid_from_rows(m: &[Real]) -> Result<Isometry3> {
    if m.len() != 16 || !m.iter().all(|x| x.is_finite()) {
        bail!("not 4 rows of 4 finite numbers");
    }
    let m = na::Matrix4::from_row_slice(m);
    let r = m.fixed_view::<3, 3>(0, 0).into_owned();
    if (r.transpose() * r - na::Matrix3::identity()).norm() > 1e-6
        || r.determinant() < 0.0
        || m.row(3).transpose() != na::Vector4::new(0.0, 0.0, 0.0, 1.0)
    {
        bail!("not a rigid transform");
    }
    let rotation = na::UnitQuaternion::from_matrix(&r);
    let translation = na::Translation3::new(m[(0, 3)], m[(1, 3)], m[(2, 3)]);
    Ok(Isometry3::from_parts(translation, rotation))
}

/// Reads a trajectory in the TUM RGB-D format: one pose per line, `timestamp tx ty tz qx qy qz
/// qw` (seconds, metres, a unit quaternion; spaces or commas between the numbers), `#` comment
/// lines. Returns `(stamp in nanoseconds, world_from_sensor)` in file order.
///
/// # Errors
/// An unreadable file, a line without 8 finite numbers, a zero quaternion, stamps that do not
/// increase, or no pose at all; every error names the line.
pub fn read_trajectory(path: &Path) -> Result<Vec<(i64, Isometry3)>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut out: Vec<(i64, Isometry3)> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let at = || format!("{}, line {}", path.display(), i + 1);
        let v: Vec<Real> = line
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|s| !s.is_empty())
            .map(str::parse)
            .collect::<Result<_, _>>()
            .with_context(|| format!("{}: not numbers", at()))?;
        if v.len() != 8 || !v.iter().all(|x| x.is_finite()) {
            bail!("{}: want 8 finite numbers `t tx ty tz qx qy qz qw`, got {}", at(), v.len());
        }
        let q = na::Quaternion::new(v[7], v[4], v[5], v[6]);
        if q.norm() < 1e-9 {
            bail!("{}: the quaternion is zero", at());
        }
        let stamp_ns = (v[0] * 1e9).round();
        if stamp_ns.abs() > 9e18 {
            bail!("{}: time {} s is out of range", at(), v[0]);
        }
        let stamp_ns = stamp_ns as i64;
        if out.last().is_some_and(|&(last, _)| stamp_ns <= last) {
            bail!("{}: the stamps must increase", at());
        }
        let pose = Isometry3::from_parts(
            na::Translation3::new(v[1], v[2], v[3]),
            na::UnitQuaternion::from_quaternion(q),
        );
        out.push((stamp_ns, pose));
    }
    if out.is_empty() {
        bail!("{}: no pose", path.display());
    }
    Ok(out)
}

/// Reads a map file of any backend.
///
/// # Errors
/// An unreadable or damaged file, named with its path.
pub fn open_map(path: &Path) -> Result<AnyMap> {
    let file = File::open(path).with_context(|| format!("opening {}", path.display()))?;
    load_any(BufReader::new(file)).with_context(|| format!("reading {}", path.display()))
}

/// Writes `map` to `out` (atomically); returns the bytes on disk and in memory.
///
/// # Errors
/// The file could not be written.
pub fn save_map(map: &AnyMap, out: &Path) -> Result<(u64, usize)> {
    let bytes = io::write_atomically(out, |w| {
        map.save(w).with_context(|| format!("writing {}", out.display()))
    })?;
    Ok((bytes, map.memory_bytes()))
}

/// Writes `patches` as a map file of `backend` (`spacing`: the sample spacing of a point-cloud
/// map made from patches, which it needs); returns the bytes on disk and in memory.
///
/// # Errors
/// A patch the backend cannot hold, no spacing for a point-cloud map, or the file.
pub fn save_patches(
    patches: Vec<Patch>,
    backend: Backend,
    spacing: Option<f64>,
    out: &Path,
) -> Result<(u64, usize)> {
    save_map(&map_of_patches(patches, backend, spacing)?, out)
}

/// A map of `backend` holding `patches` (`spacing`: the sample spacing of a point-cloud map
/// made from patches, which it needs).
///
/// # Errors
/// A patch the backend cannot hold, or no spacing for a point-cloud map.
pub fn map_of_patches(
    patches: Vec<Patch>,
    backend: Backend,
    spacing: Option<f64>,
) -> Result<AnyMap> {
    match AnyMap::from_patches(backend, patches, spacing) {
        Err(AnyMapError::NeedsSpacing) => {
            bail!("the pointcloud backend needs a point cloud, or --spacing to sample the patches")
        }
        map => Ok(map?),
    }
}

/// A box as `(x, y, z)..(x, y, z)` in centimetres' precision, for messages.
pub fn box_text(b: &Aabb) -> String {
    format!(
        "({:.2}, {:.2}, {:.2})..({:.2}, {:.2}, {:.2})",
        b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z
    )
}
