//! Roadmaps and paths as OBJ polylines (`v x y z`, `l i j ...`, 1-based), for viewers.

use anyhow::Result;
use patch_core::Point3;
use std::fmt::Write as _;
use std::path::Path;

/// Writes a roadmap as OBJ: its vertices and one two-point polyline per edge.
///
/// # Errors
/// The file could not be written.
pub fn write_obj_roadmap(path: &Path, graph: &roadmap::Roadmap) -> Result<()> {
    let points: Vec<Point3> = graph.node_weights().copied().collect();
    let lines = graph
        .edge_indices()
        .filter_map(|e| graph.edge_endpoints(e))
        .map(|(a, b)| vec![a.index(), b.index()]);
    write_obj_lines(path, &points, lines)
}

/// Writes `paths` as OBJ polylines, one per path.
///
/// # Errors
/// The file could not be written.
pub fn write_obj_paths(path: &Path, paths: &[Vec<Point3>]) -> Result<()> {
    let points: Vec<Point3> = paths.iter().flatten().copied().collect();
    let mut first = 0;
    let lines = paths.iter().map(move |p| {
        let line = (first..first + p.len()).collect();
        first += p.len();
        line
    });
    write_obj_lines(path, &points, lines)
}

/// Writes `points` and polylines through them (indices into `points`, 0-based) as OBJ.
///
/// # Errors
/// The file could not be written.
pub fn write_obj_lines(
    path: &Path,
    points: &[Point3],
    lines: impl Iterator<Item = Vec<usize>>,
) -> Result<()> {
    let mut text = String::new();
    for p in points {
        writeln!(text, "v {} {} {}", p.x, p.y, p.z)?;
    }
    for line in lines {
        let ids: Vec<String> = line.iter().map(|i| (i + 1).to_string()).collect();
        writeln!(text, "l {}", ids.join(" "))?;
    }
    pointcloud::io::write_bytes_atomically(path, text)?;
    Ok(())
}
