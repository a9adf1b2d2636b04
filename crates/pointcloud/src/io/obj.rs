//! Wavefront OBJ meshes: `v` (vertex) and `f` (face) records.
//!
//! # Reading
//! * `v x y z [w | r g b]`: a vertex; the first three numbers are its position, further numbers
//!   (a homogeneous weight or a vertex colour) are ignored. A NaN or infinite coordinate is an
//!   error.
//! * `f a b c ...`: a face with three or more corners. Each corner is a 1-based vertex index; of
//!   an item such as `1/2/3` or `1//3` only the part before the first `/` counts. A negative
//!   index is relative to the vertices read so far (`-1` is the last one), as the OBJ
//!   specification says. An index may name a vertex defined further down the file; every
//!   index is checked once the whole file is read.
//! * Every other record (`#` comments, `vn`, `vt`, `o`, `g`, `s`, `usemtl`, `mtllib`, `l`, ...)
//!   and blank lines are ignored; so is a trailing comment after `#` on a `v` or `f` line.
//! * Faces keep all their corners; [`PolygonMesh::triangulated`] splits them as fans.
//!
//! # Writing
//! `v x y z` lines (numbers printed so that they parse back to the same `f64`), then one
//! `f a b c ...` line per face with 1-based indices. Faces are written as they are: to produce the
//! triangle-only files of the exchange format, write `mesh.triangulated()`.

use super::xyz::{Real, TextLines, parse_f64, strip_comment};
use super::{Error, ErrorKind, Format, Position};
use crate::{MeshError, Point3, PolygonMesh};
use std::io::{BufRead, Write};

const FORMAT: Format = Format::Obj;

fn bad(line: u64, message: String) -> Error {
    Error::at(FORMAT, Position::Line(line), ErrorKind::BadValue(message))
}

/// Reads the vertices and faces of an OBJ file (see the [module docs](self) for the rules).
pub fn read_obj(reader: impl BufRead) -> Result<PolygonMesh, Error> {
    let mut lines = TextLines::new(reader, FORMAT);
    let mut vertices: Vec<Point3> = Vec::new();
    // Faces packed: face `i` is `corners[offsets[i]..offsets[i + 1]]`.
    let mut offsets: Vec<u32> = vec![0];
    let mut corners: Vec<u32> = Vec::new();
    // The line of every face, to name it if an index turns out to be out of range.
    let mut face_lines: Vec<u64> = Vec::new();
    while let Some((line_no, line)) = lines.next_line()? {
        let at = Position::Line(line_no);
        let mut fields = strip_comment(line).split_whitespace();
        match fields.next() {
            Some("v") => {
                let mut xyz = [0.0; 3];
                for (k, c) in xyz.iter_mut().enumerate() {
                    let text = fields.next().ok_or_else(|| {
                        bad(line_no, format!("a vertex needs 3 coordinates, found {k}"))
                    })?;
                    *c = parse_f64(text, FORMAT, at)?;
                }
                if !xyz.iter().all(|v| v.is_finite()) {
                    return Err(Error::at(
                        FORMAT,
                        at,
                        ErrorKind::NonFinite { point: vertices.len() as u64 },
                    ));
                }
                if vertices.len() >= u32::MAX as usize {
                    return Err(Error::at(
                        FORMAT,
                        at,
                        ErrorKind::Unsupported("more than 2^32 - 1 vertices".into()),
                    ));
                }
                vertices.push(Point3::new(xyz[0], xyz[1], xyz[2]));
            }
            Some("f") => {
                let start = corners.len();
                for item in fields {
                    corners.push(parse_index(item, vertices.len(), line_no)?);
                }
                let n = corners.len() - start;
                if n < 3 {
                    return Err(bad(
                        line_no,
                        format!("a face needs at least 3 corners, found {n}"),
                    ));
                }
                let end = u32::try_from(corners.len()).map_err(|_| {
                    Error::at(
                        FORMAT,
                        at,
                        ErrorKind::Unsupported("more than 2^32 - 1 face corners".into()),
                    )
                })?;
                offsets.push(end);
                face_lines.push(line_no);
            }
            _ => {}
        }
    }
    PolygonMesh::from_parts(vertices, offsets, corners).map_err(|e| match e {
        MeshError::IndexOutOfRange { face, index, num_vertices } => bad(
            face_lines[face],
            format!(
                "vertex index {} is out of range: the file has {num_vertices} vertices",
                index as u64 + 1
            ),
        ),
        other => Error::new(FORMAT, ErrorKind::BadValue(other.to_string())),
    })
}

/// Parses one face corner (`i`, `i/t`, `i/t/n` or `i//n`) into a 0-based vertex index.
/// A negative index counts back from the `defined` vertices read so far.
fn parse_index(item: &str, defined: usize, line: u64) -> Result<u32, Error> {
    let text = item.split('/').next().unwrap_or(item);
    let i: i64 = text.parse().map_err(|_| bad(line, format!("`{text}` is not a vertex index")))?;
    let zero_based = if i > 0 {
        i - 1
    } else if i < 0 {
        let k = defined as i64 + i;
        if k < 0 {
            return Err(bad(
                line,
                format!(
                    "relative vertex index {i} reaches before the first vertex ({defined} read so far)"
                ),
            ));
        }
        k
    } else {
        return Err(bad(line, "vertex index 0 (OBJ indices start at 1)".into()));
    };
    u32::try_from(zero_based)
        .ok()
        .filter(|&k| k != u32::MAX)
        .ok_or_else(|| bad(line, format!("vertex index {i} is too large")))
}

/// Writes `mesh` as OBJ: its vertices, then its faces with 1-based indices, polygons as they
/// are (write `mesh.triangulated()` for a triangle-only file).
pub fn write_obj(writer: impl Write, mesh: &PolygonMesh) -> Result<(), Error> {
    let mut w = std::io::BufWriter::new(writer);
    let io = |e: std::io::Error| Error::new(FORMAT, e);
    for p in mesh.vertices() {
        writeln!(w, "v {} {} {}", Real(p.x), Real(p.y), Real(p.z)).map_err(io)?;
    }
    for face in mesh.faces() {
        w.write_all(b"f").map_err(io)?;
        for &i in face {
            write!(w, " {}", i as u64 + 1).map_err(io)?;
        }
        w.write_all(b"\n").map_err(io)?;
    }
    w.flush().map_err(io)
}
