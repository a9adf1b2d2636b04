//! PLY (Stanford polygon file format) point clouds.
//!
//! Format reference: "The PLY Polygon File Format"
//! (<https://paulbourke.net/dataformats/ply/>), version 1.0; the header comments are those of
//! the project's exchange format.
//!
//! # What is read
//! A PLY file is a text header followed by the data of its elements, in header order:
//!
//! ```text
//! ply
//! format ascii 1.0            (or binary_little_endian 1.0, binary_big_endian 1.0)
//! comment ...                 (any number, anywhere in the header; obj_info lines likewise)
//! element vertex 3
//! property float x            (scalar: char uchar short ushort int uint float double, or the
//! property float y             aliases int8 uint8 int16 uint16 int32 uint32 float32 float64)
//! property float z
//! element face 1
//! property list uchar int vertex_indices   (list: count type, item type)
//! end_header
//! ```
//!
//! In ASCII files every element instance is one line (blank lines are skipped); numbers may be
//! written like `nan`, `NaN`, `inf`, `-Infinity` (any case). Binary files hold the instances
//! back to back, list properties as their count followed by the items.
//!
//! The `vertex` element becomes the cloud; every other element is parsed (so a lying count or a
//! truncated face list is still reported) and dropped. Vertex properties map to:
//!
//! | property | cloud |
//! |---|---|
//! | `x`, `y`, `z` (any numeric type, required) | positions |
//! | `nx`, `ny`, `nz` (or `normal_x`, `normal_y`, `normal_z`) | normals |
//! | `intensity` | intensity (when every value converts to `f32` exactly) |
//! | `label` | labels (when every value is an integer that fits `u32`) |
//! | `ring` | rings (when every value is an integer that fits `u16`) |
//! | anything else | an extra [`ScalarField`](crate::ScalarField) in the stored type |
//!
//! A property named like a dedicated slot whose values do not fit it (say a `label` of `-1`)
//! stays an extra field, so nothing is lost. List properties of the vertex element are dropped.
//!
//! Header comments of the project's exchange format:
//!
//! * `comment organized WIDTH HEIGHT`: the vertices are a row-major image, row 0 at the top;
//!   `WIDTH × HEIGHT` must equal the vertex count. A vertex with a non-finite coordinate
//!   (`nan nan nan`) is a pixel without a measurement and becomes an invalid [`Grid`] pixel.
//! * `comment sensor_to_world R00 R01 R02 TX R10 R11 R12 TY R20 R21 R22 TZ`: the row-major
//!   `[R | t]` that takes the cloud's points to the world frame; it becomes the
//!   [`SensorPose`]. `R` must be a rotation to within 1e-3 and is orthonormalised.
//! * `comment sensor_origin X Y Z`: where the sensor was in the cloud's own frame. The cloud
//!   has no slot for a sensor position that is not the origin of its frame, so the reader
//!   ignores this comment (the writer writes `0 0 0` along with `sensor_to_world`, which is
//!   what it means for a cloud in its sensor's frame).
//!
//! In an unorganised cloud a vertex with a non-finite coordinate is an
//! [`ErrorKind::NonFinite`] error, or is dropped with [`ReadOptions::skip_non_finite`].
//!
//! Data after the last element (in binary files any byte, in ASCII files any non-blank line) is
//! an error: it means the header's counts are wrong.
//!
//! # What is written
//! One `vertex` element: `x y z` as `float` or `double` ([`Precision`]), then `nx ny nz` (same
//! type) if the cloud has normals, `float intensity`, `uint label`, `ushort ring` if present, and
//! every extra field in its own type. Organised clouds are written pixel by pixel with
//! `comment organized`; invalid pixels get NaN in floating-point properties and 0 in integer
//! ones. A sensor pose is written as `comment sensor_origin 0 0 0` and
//! `comment sensor_to_world`. Floating-point text uses the shortest decimal that reads back to
//! the same value, so ASCII files round-trip exactly except for NaN payloads.
//!
//! [`Grid`]: crate::Grid
//! [`SensorPose`]: crate::SensorPose

use self::common::{
    Column, Cursor, HeaderReader, Layout, OutColumn, RowPositions, ScalarType, SlotNames, Table,
    TextLines, assemble, out_columns, row_count, row_point,
};
use super::{Error, ErrorKind, Format, Position, Precision, ReadOptions};
use crate::{Isometry3, PointCloud, SensorPose};
use std::io::{BufRead, BufWriter, Write};

/// The three PLY data encodings.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum PlyEncoding {
    /// `format ascii 1.0`: one element instance per text line.
    Ascii,
    /// `format binary_little_endian 1.0`.
    BinaryLittleEndian,
    /// `format binary_big_endian 1.0`.
    BinaryBigEndian,
}

impl PlyEncoding {
    fn keyword(self) -> &'static str {
        match self {
            PlyEncoding::Ascii => "ascii",
            PlyEncoding::BinaryLittleEndian => "binary_little_endian",
            PlyEncoding::BinaryBigEndian => "binary_big_endian",
        }
    }
}

/// How [`write_ply`] writes a cloud.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct PlyWriteOptions {
    /// The data encoding.
    pub encoding: PlyEncoding,
    /// `float` or `double` for positions and normals.
    pub precision: Precision,
}

impl Default for PlyWriteOptions {
    /// Binary little-endian with `float` positions, what most tools read fastest.
    fn default() -> PlyWriteOptions {
        PlyWriteOptions { encoding: PlyEncoding::BinaryLittleEndian, precision: Precision::F32 }
    }
}

/// Names of the dedicated slots in PLY files; the first normal triple is the one written.
const NAMES: SlotNames = SlotNames {
    normals: &[["nx", "ny", "nz"], ["normal_x", "normal_y", "normal_z"]],
    intensity: "intensity",
    label: "label",
    ring: "ring",
};

/// Reads a PLY point cloud (see the [module documentation](self) for what is mapped where).
///
/// Errors name the header or data line of ASCII files and the byte offset of binary data.
pub fn read_ply(reader: impl BufRead, options: &ReadOptions) -> Result<PointCloud, Error> {
    let mut lines = HeaderReader::new(reader, Format::Ply);
    let header = parse_header(&mut lines)?;
    let first_body_line = lines.line() + 1;
    let body_start = lines.bytes();
    let body = lines.into_body()?;
    let (table, rows) = match header.encoding {
        PlyEncoding::Ascii => read_ascii(&header, &body, first_body_line)?,
        PlyEncoding::BinaryLittleEndian => read_binary(&header, &body, body_start, false)?,
        PlyEncoding::BinaryBigEndian => read_binary(&header, &body, body_start, true)?,
    };
    let layout = match header.organized {
        Some((width, height)) => Layout::Organised { width, height },
        None => Layout::Unorganised,
    };
    assemble(Format::Ply, table, &rows, layout, header.pose, options, NAMES.normals)
}

/// Writes `cloud` as PLY (see the [module documentation](self) for the layout).
///
/// Fails on an I/O error, or if an extra field's name is not a single printable ASCII word or
/// repeats a name already written.
pub fn write_ply(
    writer: impl Write,
    cloud: &PointCloud,
    options: &PlyWriteOptions,
) -> Result<(), Error> {
    let columns = out_columns(Format::Ply, cloud, options.precision, &NAMES)?;
    let io = |e: std::io::Error| Error::new(Format::Ply, e);
    let mut w = BufWriter::new(writer);
    write_header(&mut w, cloud, &columns, options.encoding).map_err(io)?;
    match options.encoding {
        PlyEncoding::Ascii => write_ascii_rows(&mut w, cloud, &columns),
        PlyEncoding::BinaryLittleEndian => write_binary_rows(&mut w, cloud, &columns, false),
        PlyEncoding::BinaryBigEndian => write_binary_rows(&mut w, cloud, &columns, true),
    }
    .map_err(io)?;
    w.flush().map_err(io)
}

/// Writes `mesh` as a binary little-endian PLY mesh: `element vertex` with `double x, y, z`
/// and `element face` with `list uchar uint vertex_indices` (every face of up to 255
/// vertices; larger faces are fan-triangulated). Any PLY viewer opens it; [`read_ply`] reads
/// its vertices as a cloud.
pub fn write_ply_mesh(writer: impl Write, mesh: &crate::PolygonMesh) -> Result<(), Error> {
    let io = |e: std::io::Error| Error::new(Format::Ply, e);
    let mut faces: Vec<Vec<u32>> = Vec::with_capacity(mesh.num_faces());
    for face in mesh.faces() {
        if face.len() <= usize::from(u8::MAX) {
            faces.push(face.to_vec());
        } else {
            faces.extend((1..face.len() - 1).map(|k| vec![face[0], face[k], face[k + 1]]));
        }
    }
    let mut w = BufWriter::new(writer);
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment written by patchnav\n\
         element vertex {}\nproperty double x\nproperty double y\nproperty double z\n\
         element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        mesh.num_vertices(),
        faces.len()
    )
    .map_err(io)?;
    for p in mesh.vertices() {
        for c in [p.x, p.y, p.z] {
            w.write_all(&c.to_le_bytes()).map_err(io)?;
        }
    }
    for face in &faces {
        w.write_all(&[face.len() as u8]).map_err(io)?;
        for &i in face {
            w.write_all(&i.to_le_bytes()).map_err(io)?;
        }
    }
    w.flush().map_err(io)
}

// ---------------------------------------------------------------------------------------------
// Header

/// A property of an element.
#[derive(Clone, Debug)]
struct Property {
    name: String,
    kind: PropertyKind,
}

#[derive(Copy, Clone, Debug)]
enum PropertyKind {
    Scalar(ScalarType),
    List { count: ScalarType, item: ScalarType },
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: u64,
    properties: Vec<Property>,
}

impl Element {
    /// The size of one instance, if it has no list property.
    fn fixed_size(&self) -> Option<usize> {
        self.properties
            .iter()
            .map(|p| match p.kind {
                PropertyKind::Scalar(t) => Some(t.size()),
                PropertyKind::List { .. } => None,
            })
            .sum()
    }

    /// The least size of one instance (lists empty).
    fn min_size(&self) -> usize {
        self.properties
            .iter()
            .map(|p| match p.kind {
                PropertyKind::Scalar(t) | PropertyKind::List { count: t, .. } => t.size(),
            })
            .sum()
    }

    fn what(&self) -> &'static str {
        if self.name == "vertex" { "vertices" } else { "element instances" }
    }
}

#[derive(Debug)]
struct Header {
    encoding: PlyEncoding,
    elements: Vec<Element>,
    vertex: usize,
    organized: Option<(u32, u32)>,
    pose: Option<SensorPose>,
}

/// What the header parser has seen so far.
#[derive(Default)]
struct HeaderState {
    encoding: Option<PlyEncoding>,
    elements: Vec<Element>,
    vertex: Option<usize>,
    organized: Option<(u32, u32, u64)>,
    pose: Option<SensorPose>,
}

fn bad_header(line: u64, message: impl Into<String>) -> Error {
    Error::at(Format::Ply, Position::Line(line), ErrorKind::BadHeader(message.into()))
}

fn parse_header<R: BufRead>(lines: &mut HeaderReader<R>) -> Result<Header, Error> {
    let magic = lines.next_line()?;
    if magic.as_deref().map(str::trim) != Some("ply") {
        return Err(bad_header(1, "the file does not start with `ply`"));
    }
    let mut state = HeaderState::default();
    loop {
        let Some(text) = lines.next_line()? else {
            return Err(Error::at(
                Format::Ply,
                Position::Line(lines.line() + 1),
                ErrorKind::UnexpectedEof { expected: "`end_header`".into() },
            ));
        };
        let line = lines.line();
        let tokens: Vec<&str> = text.split_ascii_whitespace().collect();
        match tokens.as_slice() {
            [] | ["obj_info", ..] => {}
            ["end_header"] => break,
            ["format", rest @ ..] => parse_format(&mut state, rest, line)?,
            ["comment", rest @ ..] => parse_comment(&mut state, rest, line)?,
            ["element", rest @ ..] => parse_element(&mut state, rest, line)?,
            ["property", rest @ ..] => parse_property(&mut state, rest, line)?,
            [keyword, ..] => {
                return Err(bad_header(line, format!("unknown header keyword `{keyword}`")));
            }
        }
    }
    finish_header(state, lines.line())
}

fn parse_format(state: &mut HeaderState, rest: &[&str], line: u64) -> Result<(), Error> {
    if state.encoding.is_some() {
        return Err(bad_header(line, "a second `format` line"));
    }
    let [encoding, version] = rest else {
        return Err(bad_header(line, "expected `format <encoding> 1.0`"));
    };
    if !matches!(*version, "1.0" | "1") {
        return Err(Error::at(
            Format::Ply,
            Position::Line(line),
            ErrorKind::Unsupported(format!("PLY version {version}")),
        ));
    }
    state.encoding = Some(match *encoding {
        "ascii" => PlyEncoding::Ascii,
        "binary_little_endian" => PlyEncoding::BinaryLittleEndian,
        "binary_big_endian" => PlyEncoding::BinaryBigEndian,
        other => return Err(bad_header(line, format!("unknown encoding `{other}`"))),
    });
    Ok(())
}

fn parse_comment(state: &mut HeaderState, rest: &[&str], line: u64) -> Result<(), Error> {
    match rest {
        ["organized", dims @ ..] => {
            let dims: Vec<Option<u32>> = dims.iter().map(|t| t.parse().ok()).collect();
            let [Some(width), Some(height)] = dims[..] else {
                return Err(bad_header(line, "expected `comment organized WIDTH HEIGHT`"));
            };
            if state.organized.is_some() {
                return Err(bad_header(line, "a second `comment organized`"));
            }
            state.organized = Some((width, height, line));
        }
        ["sensor_to_world", numbers @ ..] => {
            let values: Option<Vec<f64>> =
                numbers.iter().map(|t| t.parse::<f64>().ok().filter(|v| v.is_finite())).collect();
            let pose = values
                .filter(|v| v.len() == 12)
                .ok_or_else(|| bad_header(line, "expected 12 finite numbers after sensor_to_world"))
                .and_then(|v| pose_from_rows(&v).map_err(|m| bad_header(line, m)))?;
            if state.pose.is_some() {
                return Err(bad_header(line, "a second `comment sensor_to_world`"));
            }
            state.pose = Some(pose);
        }
        _ => {}
    }
    Ok(())
}

/// A pose from the 12 numbers of a row-major `[R | t]`.
fn pose_from_rows(v: &[f64]) -> Result<SensorPose, String> {
    let r = na::Matrix3::new(v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10]);
    let t = na::Vector3::new(v[3], v[7], v[11]);
    let error = (r.transpose() * r - na::Matrix3::identity()).abs().max();
    if error > 1e-3 || r.determinant() <= 0.0 {
        return Err("sensor_to_world: the 3 × 3 part is not a rotation".into());
    }
    let q = na::UnitQuaternion::from_rotation_matrix(&na::Rotation3::from_matrix_unchecked(r));
    let rotation = na::UnitQuaternion::new_normalize(q.into_inner());
    Ok(SensorPose { world_from_sensor: Isometry3::from_parts(t.into(), rotation) })
}

fn parse_element(state: &mut HeaderState, rest: &[&str], line: u64) -> Result<(), Error> {
    let [name, count] = rest else {
        return Err(bad_header(line, "expected `element <name> <count>`"));
    };
    let count = count
        .parse::<u64>()
        .map_err(|_| bad_header(line, format!("bad element count `{count}`")))?;
    if *name == "vertex" {
        if state.vertex.is_some() {
            return Err(bad_header(line, "a second `vertex` element"));
        }
        state.vertex = Some(state.elements.len());
    }
    state.elements.push(Element { name: (*name).to_owned(), count, properties: Vec::new() });
    Ok(())
}

fn scalar_type(name: &str, line: u64) -> Result<ScalarType, Error> {
    ScalarType::from_ply_name(name)
        .ok_or_else(|| bad_header(line, format!("unknown property type `{name}`")))
}

fn parse_property(state: &mut HeaderState, rest: &[&str], line: u64) -> Result<(), Error> {
    let (kind, name) = match rest {
        ["list", count, item, name] => {
            let count = scalar_type(count, line)?;
            if !count.is_integer() {
                return Err(bad_header(line, "a list count must have an integer type"));
            }
            (PropertyKind::List { count, item: scalar_type(item, line)? }, *name)
        }
        [ty, name] if *ty != "list" => (PropertyKind::Scalar(scalar_type(ty, line)?), *name),
        _ => {
            return Err(bad_header(
                line,
                "expected `property <type> <name>` or `property list <type> <type> <name>`",
            ));
        }
    };
    let Some(element) = state.elements.last_mut() else {
        return Err(bad_header(line, "a property before any element"));
    };
    if element.properties.iter().any(|p| p.name == name) {
        return Err(bad_header(line, format!("property `{name}` declared twice")));
    }
    let is_coordinate = matches!(name, "x" | "y" | "z");
    if element.name == "vertex" && is_coordinate && matches!(kind, PropertyKind::List { .. }) {
        return Err(bad_header(line, format!("vertex coordinate `{name}` is a list")));
    }
    element.properties.push(Property { name: name.to_owned(), kind });
    Ok(())
}

fn finish_header(state: HeaderState, end_line: u64) -> Result<Header, Error> {
    let encoding = state.encoding.ok_or_else(|| bad_header(end_line, "no `format` line"))?;
    let vertex = state.vertex.ok_or_else(|| bad_header(end_line, "no `vertex` element"))?;
    let element = &state.elements[vertex];
    for axis in ["x", "y", "z"] {
        if !element.properties.iter().any(|p| p.name == axis) {
            return Err(bad_header(end_line, format!("the vertex element has no `{axis}`")));
        }
    }
    let organized = match state.organized {
        None => None,
        Some((width, height, line)) => {
            let pixels = u64::from(width) * u64::from(height);
            if pixels != element.count {
                return Err(bad_header(
                    line,
                    format!(
                        "organized {width} × {height} = {pixels} pixels, but {} vertices",
                        element.count
                    ),
                ));
            }
            if pixels >= u64::from(crate::INVALID_PIXEL) {
                return Err(Error::at(
                    Format::Ply,
                    Position::Line(line),
                    ErrorKind::Unsupported(format!("an image of {pixels} pixels")),
                ));
            }
            Some((width, height))
        }
    };
    Ok(Header { encoding, elements: state.elements, vertex, organized, pose: state.pose })
}

// ---------------------------------------------------------------------------------------------
// Data

/// The vertex columns: one per scalar property, `None` for list properties.
fn vertex_columns(element: &Element, capacity: usize) -> Vec<Option<Column>> {
    element
        .properties
        .iter()
        .map(|p| match p.kind {
            PropertyKind::Scalar(ty) => Some(Column::new(&p.name, ty, capacity)),
            PropertyKind::List { .. } => None,
        })
        .collect()
}

fn into_table(columns: Vec<Option<Column>>, rows: usize) -> Table {
    Table { columns: columns.into_iter().flatten().collect(), rows }
}

fn eof_at(position: Position, expected: String) -> Error {
    Error::at(Format::Ply, position, ErrorKind::UnexpectedEof { expected })
}

fn read_binary(
    header: &Header,
    body: &[u8],
    body_start: u64,
    big_endian: bool,
) -> Result<(Table, RowPositions), Error> {
    let mut cursor = Cursor::new(body, body_start);
    let mut vertices = None;
    for (index, element) in header.elements.iter().enumerate() {
        if element.properties.is_empty() {
            continue;
        }
        check_binary_count(element, &cursor)?;
        if index == header.vertex {
            vertices = Some(read_binary_vertices(element, &mut cursor, big_endian)?);
        } else {
            for _ in 0..element.count {
                read_binary_instance(element, &mut cursor, big_endian, &mut [])?;
            }
        }
    }
    if cursor.remaining() > 0 {
        return Err(Error::at(
            Format::Ply,
            cursor.position(),
            ErrorKind::CountMismatch {
                what: "bytes of element data",
                declared: cursor.offset() as u64,
                found: body.len() as u64,
            },
        ));
    }
    vertices.ok_or_else(|| bad_header(1, "no `vertex` element"))
}

/// Fails unless the rest of the data can hold `element.count` instances of least size.
fn check_binary_count(element: &Element, cursor: &Cursor<'_>) -> Result<(), Error> {
    let size = element.min_size() as u64;
    let fits = element.count.checked_mul(size).is_some_and(|n| n <= cursor.remaining() as u64);
    if fits {
        return Ok(());
    }
    Err(Error::at(
        Format::Ply,
        cursor.end_position(),
        ErrorKind::CountMismatch {
            what: element.what(),
            declared: element.count,
            found: cursor.remaining() as u64 / size.max(1),
        },
    ))
}

fn read_binary_vertices(
    element: &Element,
    cursor: &mut Cursor<'_>,
    big_endian: bool,
) -> Result<(Table, RowPositions), Error> {
    // check_binary_count bounds the count by the bytes present.
    let rows = element.count as usize;
    let mut columns = vertex_columns(element, rows);
    let start = cursor.absolute();
    let mut offsets = Vec::new();
    let fixed = element.fixed_size();
    for _ in 0..rows {
        if fixed.is_none() {
            offsets.push(cursor.absolute());
        }
        read_binary_instance(element, cursor, big_endian, &mut columns)?;
    }
    let positions = match fixed {
        Some(size) => RowPositions::Records { start, stride: size as u64 },
        None => RowPositions::Offsets(offsets),
    };
    Ok((into_table(columns, rows), positions))
}

/// Reads one instance, pushing scalar `i` into `columns[i]` where there is one.
fn read_binary_instance(
    element: &Element,
    cursor: &mut Cursor<'_>,
    big_endian: bool,
    columns: &mut [Option<Column>],
) -> Result<(), Error> {
    for (i, property) in element.properties.iter().enumerate() {
        let expected = || format!("property `{}` of `{}`", property.name, element.name);
        match property.kind {
            PropertyKind::Scalar(ty) => {
                let position = cursor.position();
                let bytes = cursor.take(ty.size()).ok_or_else(|| eof_at(position, expected()))?;
                if let Some(Some(column)) = columns.get_mut(i) {
                    column.push(ty.decode(bytes, big_endian));
                }
            }
            PropertyKind::List { count, item } => {
                let position = cursor.position();
                let bytes =
                    cursor.take(count.size()).ok_or_else(|| eof_at(position, expected()))?;
                let len = count.decode(bytes, big_endian).as_i128();
                let total = usize::try_from(len)
                    .ok()
                    .and_then(|n| n.checked_mul(item.size()))
                    .ok_or_else(|| {
                        Error::at(
                            Format::Ply,
                            position,
                            ErrorKind::BadValue(format!(
                                "list length {len} of `{}`",
                                property.name
                            )),
                        )
                    })?;
                let position = cursor.position();
                cursor.take(total).ok_or_else(|| eof_at(position, expected()))?;
            }
        }
    }
    Ok(())
}

fn bad_value(line: u64, message: String) -> Error {
    Error::at(Format::Ply, Position::Line(line), ErrorKind::BadValue(message))
}

fn read_ascii(
    header: &Header,
    body: &[u8],
    first_line: u64,
) -> Result<(Table, RowPositions), Error> {
    let mut lines = TextLines::new(body, first_line);
    let mut vertices = None;
    let mut declared = 0u64;
    for (index, element) in header.elements.iter().enumerate() {
        if element.properties.is_empty() {
            continue;
        }
        declared = declared.saturating_add(element.count);
        if index == header.vertex {
            vertices = Some(read_ascii_vertices(element, &mut lines)?);
        } else {
            for found in 0..element.count {
                read_ascii_instance(element, &mut lines, found, &mut [])?;
            }
        }
    }
    if lines.next_nonblank().is_some() {
        let line = lines.line();
        let found = declared.saturating_add(1 + lines.count_nonblank() as u64);
        return Err(Error::at(
            Format::Ply,
            Position::Line(line),
            ErrorKind::CountMismatch { what: "data lines", declared, found },
        ));
    }
    vertices.ok_or_else(|| bad_header(1, "no `vertex` element"))
}

fn read_ascii_vertices(
    element: &Element,
    lines: &mut TextLines<'_>,
) -> Result<(Table, RowPositions), Error> {
    let capacity = element.count.min(lines.count_nonblank() as u64) as usize;
    let mut columns = vertex_columns(element, capacity);
    let mut row_lines = Vec::with_capacity(capacity);
    for found in 0..element.count {
        read_ascii_instance(element, lines, found, &mut columns)?;
        row_lines.push(lines.line());
    }
    Ok((into_table(columns, row_lines.len()), RowPositions::Lines(row_lines)))
}

/// Reads instance number `found` (one line), pushing scalar `i` into `columns[i]` where there
/// is one.
fn read_ascii_instance(
    element: &Element,
    lines: &mut TextLines<'_>,
    found: u64,
    columns: &mut [Option<Column>],
) -> Result<(), Error> {
    let Some(text) = lines.next_nonblank() else {
        return Err(Error::at(
            Format::Ply,
            Position::Line(lines.line() + 1),
            ErrorKind::CountMismatch { what: element.what(), declared: element.count, found },
        ));
    };
    let line = lines.line();
    let text = std::str::from_utf8(text)
        .map_err(|_| bad_value(line, "the line is not UTF-8 text".into()))?;
    let mut tokens = text.split_ascii_whitespace();
    let mut next = |name: &str| {
        tokens.next().ok_or_else(|| {
            bad_value(line, format!("the line ends before property `{name}` of `{}`", element.name))
        })
    };
    let parse = |ty: ScalarType, token: &str, name: &str| {
        ty.parse(token).map_err(|e| bad_value(line, format!("property `{name}`: {e}")))
    };
    for (i, property) in element.properties.iter().enumerate() {
        let name = property.name.as_str();
        match property.kind {
            PropertyKind::Scalar(ty) => {
                let value = parse(ty, next(name)?, name)?;
                if let Some(Some(column)) = columns.get_mut(i) {
                    column.push(value);
                }
            }
            PropertyKind::List { count, item } => {
                let len = parse(count, next(name)?, name)?.as_i128();
                if len < 0 {
                    let message = format!("property `{name}`: negative list length {len}");
                    return Err(bad_value(line, message));
                }
                for _ in 0..len {
                    parse(item, next(name)?, name)?;
                }
            }
        }
    }
    if tokens.next().is_some() {
        return Err(bad_value(
            line,
            format!(
                "more values than the {} properties of `{}`",
                element.properties.len(),
                element.name
            ),
        ));
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Writing

fn write_header(
    w: &mut impl Write,
    cloud: &PointCloud,
    columns: &[OutColumn<'_>],
    encoding: PlyEncoding,
) -> std::io::Result<()> {
    writeln!(w, "ply")?;
    writeln!(w, "format {} 1.0", encoding.keyword())?;
    if let Some(grid) = cloud.grid() {
        writeln!(w, "comment organized {} {}", grid.width(), grid.height())?;
    }
    if let Some(pose) = cloud.sensor_pose() {
        let r = pose.world_from_sensor.rotation.to_rotation_matrix().into_inner();
        let t = pose.world_from_sensor.translation.vector;
        writeln!(w, "comment sensor_origin 0 0 0")?;
        let mut text = String::from("comment sensor_to_world");
        for row in 0..3 {
            for value in [r[(row, 0)], r[(row, 1)], r[(row, 2)], t[row]] {
                text.push(' ');
                common::push_f64(&mut text, value);
            }
        }
        writeln!(w, "{text}")?;
    }
    writeln!(w, "element vertex {}", row_count(cloud))?;
    for column in columns {
        writeln!(w, "property {} {}", column.ty.ply_name(), column.name)?;
    }
    writeln!(w, "end_header")
}

fn write_ascii_rows(
    w: &mut impl Write,
    cloud: &PointCloud,
    columns: &[OutColumn<'_>],
) -> std::io::Result<()> {
    let mut text = String::new();
    for row in 0..row_count(cloud) {
        text.clear();
        let point = row_point(cloud, row);
        for (i, column) in columns.iter().enumerate() {
            if i > 0 {
                text.push(' ');
            }
            column.ty.format(column.value(point), &mut text);
        }
        text.push('\n');
        w.write_all(text.as_bytes())?;
    }
    Ok(())
}

fn write_binary_rows(
    w: &mut impl Write,
    cloud: &PointCloud,
    columns: &[OutColumn<'_>],
    big_endian: bool,
) -> std::io::Result<()> {
    let mut bytes = Vec::new();
    for row in 0..row_count(cloud) {
        bytes.clear();
        let point = row_point(cloud, row);
        for column in columns {
            column.ty.encode(column.value(point), big_endian, &mut bytes);
        }
        w.write_all(&bytes)?;
    }
    Ok(())
}

/// The machinery the PLY and PCD readers and writers share: scalar types, text and binary
/// decoding, header lines, and the assembly of named columns into a [`PointCloud`].
pub(crate) mod common {
    use crate::io::{Error, ErrorKind, Format, Position, Precision, ReadOptions};
    use crate::{
        FieldData, Grid, INVALID_PIXEL, Point3, PointCloud, ScalarField, SensorPose, Vector3,
    };
    use std::fmt::Write as _;
    use std::io::BufRead;

    /// The longest header line accepted.
    const MAX_HEADER_LINE: usize = 1 << 20;

    /// A numeric type a file stores a value in.
    #[derive(Copy, Clone, Debug, PartialEq, Eq)]
    pub(crate) enum ScalarType {
        I8,
        U8,
        I16,
        U16,
        I32,
        U32,
        I64,
        U64,
        F32,
        F64,
    }

    /// A decoded value.
    #[derive(Copy, Clone, Debug, PartialEq)]
    pub(crate) enum Value {
        Int(i128),
        F32(f32),
        F64(f64),
    }

    impl Value {
        /// The value as an integer (floats saturate, NaN is 0).
        pub(crate) fn as_i128(self) -> i128 {
            match self {
                Value::Int(i) => i,
                Value::F32(x) => x as i128,
                Value::F64(x) => x as i128,
            }
        }

        fn as_f32(self) -> f32 {
            match self {
                Value::Int(i) => i as f32,
                Value::F32(x) => x,
                Value::F64(x) => x as f32,
            }
        }

        fn as_f64(self) -> f64 {
            match self {
                Value::Int(i) => i as f64,
                Value::F32(x) => f64::from(x),
                Value::F64(x) => x,
            }
        }
    }

    macro_rules! read_num {
        ($t:ty, $bytes:expr, $big_endian:expr) => {{
            const N: usize = std::mem::size_of::<$t>();
            let array: [u8; N] = $bytes.first_chunk::<N>().copied().unwrap_or([0; N]);
            if $big_endian { <$t>::from_be_bytes(array) } else { <$t>::from_le_bytes(array) }
        }};
    }

    macro_rules! write_num {
        ($value:expr, $big_endian:expr, $out:expr) => {{
            let value = $value;
            $out.extend_from_slice(&if $big_endian {
                value.to_be_bytes()
            } else {
                value.to_le_bytes()
            });
        }};
    }

    impl ScalarType {
        /// The size in bytes.
        pub(crate) fn size(self) -> usize {
            match self {
                ScalarType::I8 | ScalarType::U8 => 1,
                ScalarType::I16 | ScalarType::U16 => 2,
                ScalarType::I32 | ScalarType::U32 | ScalarType::F32 => 4,
                ScalarType::I64 | ScalarType::U64 | ScalarType::F64 => 8,
            }
        }

        /// Whether the type is an integer type.
        pub(crate) fn is_integer(self) -> bool {
            !matches!(self, ScalarType::F32 | ScalarType::F64)
        }

        /// The type values of `data` are stored in.
        pub(crate) fn of_field(data: &FieldData) -> ScalarType {
            match data {
                FieldData::I8(_) => ScalarType::I8,
                FieldData::U8(_) => ScalarType::U8,
                FieldData::I16(_) => ScalarType::I16,
                FieldData::U16(_) => ScalarType::U16,
                FieldData::I32(_) => ScalarType::I32,
                FieldData::U32(_) => ScalarType::U32,
                FieldData::F32(_) => ScalarType::F32,
                FieldData::F64(_) => ScalarType::F64,
            }
        }

        /// The type of a PLY type name (`uchar`, `uint8`, `float32`, ...).
        pub(crate) fn from_ply_name(name: &str) -> Option<ScalarType> {
            Some(match name {
                "char" | "int8" => ScalarType::I8,
                "uchar" | "uint8" => ScalarType::U8,
                "short" | "int16" => ScalarType::I16,
                "ushort" | "uint16" => ScalarType::U16,
                "int" | "int32" => ScalarType::I32,
                "uint" | "uint32" => ScalarType::U32,
                "float" | "float32" => ScalarType::F32,
                "double" | "float64" => ScalarType::F64,
                _ => return None,
            })
        }

        /// The classic PLY name of the type (64-bit integers, which PLY lacks, never reach the
        /// writer: cloud fields have no such type).
        pub(crate) fn ply_name(self) -> &'static str {
            match self {
                ScalarType::I8 => "char",
                ScalarType::U8 => "uchar",
                ScalarType::I16 => "short",
                ScalarType::U16 => "ushort",
                ScalarType::I32 => "int",
                ScalarType::U32 => "uint",
                ScalarType::I64 => "int64",
                ScalarType::U64 => "uint64",
                ScalarType::F32 => "float",
                ScalarType::F64 => "double",
            }
        }

        fn int_range(self) -> (i128, i128) {
            match self {
                ScalarType::I8 => (i8::MIN.into(), i8::MAX.into()),
                ScalarType::U8 => (0, u8::MAX.into()),
                ScalarType::I16 => (i16::MIN.into(), i16::MAX.into()),
                ScalarType::U16 => (0, u16::MAX.into()),
                ScalarType::I32 => (i32::MIN.into(), i32::MAX.into()),
                ScalarType::U32 => (0, u32::MAX.into()),
                ScalarType::I64 => (i64::MIN.into(), i64::MAX.into()),
                ScalarType::U64 => (0, u64::MAX.into()),
                ScalarType::F32 | ScalarType::F64 => (i128::MIN, i128::MAX),
            }
        }

        /// Decodes the first [`size`](Self::size) bytes of `bytes` (which the caller has checked
        /// are there).
        pub(crate) fn decode(self, bytes: &[u8], big_endian: bool) -> Value {
            match self {
                ScalarType::I8 => Value::Int(read_num!(i8, bytes, big_endian).into()),
                ScalarType::U8 => Value::Int(read_num!(u8, bytes, big_endian).into()),
                ScalarType::I16 => Value::Int(read_num!(i16, bytes, big_endian).into()),
                ScalarType::U16 => Value::Int(read_num!(u16, bytes, big_endian).into()),
                ScalarType::I32 => Value::Int(read_num!(i32, bytes, big_endian).into()),
                ScalarType::U32 => Value::Int(read_num!(u32, bytes, big_endian).into()),
                ScalarType::I64 => Value::Int(read_num!(i64, bytes, big_endian).into()),
                ScalarType::U64 => Value::Int(read_num!(u64, bytes, big_endian).into()),
                ScalarType::F32 => Value::F32(read_num!(f32, bytes, big_endian)),
                ScalarType::F64 => Value::F64(read_num!(f64, bytes, big_endian)),
            }
        }

        /// Appends `value` in this type.
        pub(crate) fn encode(self, value: Value, big_endian: bool, out: &mut Vec<u8>) {
            let i = value.as_i128();
            match self {
                ScalarType::I8 => write_num!(i as i8, big_endian, out),
                ScalarType::U8 => write_num!(i as u8, big_endian, out),
                ScalarType::I16 => write_num!(i as i16, big_endian, out),
                ScalarType::U16 => write_num!(i as u16, big_endian, out),
                ScalarType::I32 => write_num!(i as i32, big_endian, out),
                ScalarType::U32 => write_num!(i as u32, big_endian, out),
                ScalarType::I64 => write_num!(i as i64, big_endian, out),
                ScalarType::U64 => write_num!(i as u64, big_endian, out),
                ScalarType::F32 => write_num!(value.as_f32(), big_endian, out),
                ScalarType::F64 => write_num!(value.as_f64(), big_endian, out),
            }
        }

        /// Parses a text token as a value of this type.
        pub(crate) fn parse(self, token: &str) -> Result<Value, String> {
            match self {
                ScalarType::F32 => token
                    .parse::<f32>()
                    .ok()
                    .or_else(|| special_float(token).map(|v| v as f32))
                    .map(Value::F32)
                    .ok_or_else(|| format!("`{token}` is not a number")),
                ScalarType::F64 => token
                    .parse::<f64>()
                    .ok()
                    .or_else(|| special_float(token))
                    .map(Value::F64)
                    .ok_or_else(|| format!("`{token}` is not a number")),
                _ => {
                    let value = parse_integer(token)?;
                    let (low, high) = self.int_range();
                    if value < low || value > high {
                        return Err(format!("{token} is out of range for {self:?}"));
                    }
                    Ok(Value::Int(value))
                }
            }
        }

        /// Appends `value` in this type as text.
        pub(crate) fn format(self, value: Value, out: &mut String) {
            match self {
                ScalarType::F32 => push_f32(out, value.as_f32()),
                ScalarType::F64 => push_f64(out, value.as_f64()),
                _ => {
                    let _ = write!(out, "{}", value.as_i128());
                }
            }
        }
    }

    /// An integer token; also accepts a float spelling of an integer (`3.0`, `1e3`).
    fn parse_integer(token: &str) -> Result<i128, String> {
        if let Ok(v) = token.parse::<i128>() {
            return Ok(v);
        }
        match token.parse::<f64>() {
            Ok(v) if v.is_finite() && v.fract() == 0.0 && v.abs() < 1e38 => Ok(v as i128),
            _ => Err(format!("`{token}` is not an integer")),
        }
    }

    /// Spellings of NaN and infinity that Rust's parser does not take: `nan(ind)`, `-nan(ind)`,
    /// `1.#QNAN`, `1.#IND`, `-1.#INF`.
    fn special_float(token: &str) -> Option<f64> {
        let lower = token.to_ascii_lowercase();
        let (negative, rest) = match lower.strip_prefix('-') {
            Some(rest) => (true, rest),
            None => (false, lower.strip_prefix('+').unwrap_or(&lower)),
        };
        if rest.starts_with("nan")
            || ["1.#qnan", "1.#snan", "1.#ind"].iter().any(|p| rest.starts_with(p))
        {
            Some(f64::NAN)
        } else if rest.starts_with("1.#inf") {
            Some(if negative { f64::NEG_INFINITY } else { f64::INFINITY })
        } else {
            None
        }
    }

    macro_rules! push_float {
        ($name:ident, $t:ty) => {
            /// Appends the shortest text that reads back to the same value (`nan`, `inf` and
            /// `-inf` for the special values).
            pub(crate) fn $name(out: &mut String, value: $t) {
                if value.is_nan() {
                    out.push_str("nan");
                } else if value.is_infinite() {
                    out.push_str(if value > 0.0 { "inf" } else { "-inf" });
                } else if value == 0.0 || (1e-5..1e16).contains(&value.abs()) {
                    let _ = write!(out, "{value}");
                } else {
                    let _ = write!(out, "{value:e}");
                }
            }
        };
    }
    push_float!(push_f32, f32);
    push_float!(push_f64, f64);

    // -----------------------------------------------------------------------------------------
    // Reading text and bytes

    /// Reads header lines, counting lines and bytes.
    pub(crate) struct HeaderReader<R> {
        reader: R,
        format: Format,
        line: u64,
        bytes: u64,
    }

    impl<R: BufRead> HeaderReader<R> {
        pub(crate) fn new(reader: R, format: Format) -> HeaderReader<R> {
            HeaderReader { reader, format, line: 0, bytes: 0 }
        }

        /// The number of the last line returned (1-based).
        pub(crate) fn line(&self) -> u64 {
            self.line
        }

        /// The bytes consumed so far.
        pub(crate) fn bytes(&self) -> u64 {
            self.bytes
        }

        /// The next line without its `\n` or `\r\n`, or `None` at the end of the input. Bytes
        /// that are not UTF-8 are replaced.
        pub(crate) fn next_line(&mut self) -> Result<Option<String>, Error> {
            let mut buf = Vec::new();
            loop {
                let available = match self.reader.fill_buf() {
                    Ok(available) => available,
                    Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                    Err(e) => return Err(Error::new(self.format, e)),
                };
                if available.is_empty() {
                    if buf.is_empty() {
                        return Ok(None);
                    }
                    break;
                }
                let newline = available.iter().position(|&b| b == b'\n');
                let take = newline.map_or(available.len(), |i| i + 1);
                if buf.len() + take > MAX_HEADER_LINE {
                    return Err(Error::at(
                        self.format,
                        Position::Line(self.line + 1),
                        ErrorKind::BadHeader(format!(
                            "a header line longer than {MAX_HEADER_LINE} bytes"
                        )),
                    ));
                }
                buf.extend_from_slice(&available[..take]);
                self.reader.consume(take);
                self.bytes += take as u64;
                if newline.is_some() {
                    break;
                }
            }
            self.line += 1;
            if buf.last() == Some(&b'\n') {
                buf.pop();
            }
            if buf.last() == Some(&b'\r') {
                buf.pop();
            }
            Ok(Some(String::from_utf8_lossy(&buf).into_owned()))
        }

        /// The rest of the input.
        pub(crate) fn into_body(mut self) -> Result<Vec<u8>, Error> {
            let mut body = Vec::new();
            self.reader.read_to_end(&mut body).map_err(|e| Error::new(self.format, e))?;
            Ok(body)
        }
    }

    /// The lines of a text body.
    pub(crate) struct TextLines<'a> {
        data: &'a [u8],
        pos: usize,
        line: u64,
    }

    impl<'a> TextLines<'a> {
        /// Lines of `data`, the first of which is line `first_line` of the file.
        pub(crate) fn new(data: &'a [u8], first_line: u64) -> TextLines<'a> {
            TextLines { data, pos: 0, line: first_line.saturating_sub(1) }
        }

        /// The number of the last line returned.
        pub(crate) fn line(&self) -> u64 {
            self.line
        }

        /// The next line with something other than white space on it.
        pub(crate) fn next_nonblank(&mut self) -> Option<&'a [u8]> {
            while self.pos < self.data.len() {
                let rest = &self.data[self.pos..];
                let len = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
                self.pos += len + 1;
                self.line += 1;
                let text = &rest[..len];
                if text.iter().any(|b| !b.is_ascii_whitespace()) {
                    return Some(text);
                }
            }
            None
        }

        /// How many non-blank lines are left.
        pub(crate) fn count_nonblank(&self) -> usize {
            let rest = self.data.get(self.pos..).unwrap_or_default();
            rest.split(|&b| b == b'\n')
                .filter(|l| l.iter().any(|b| !b.is_ascii_whitespace()))
                .count()
        }
    }

    /// A read position in binary data that starts at byte `base` of the file.
    pub(crate) struct Cursor<'a> {
        data: &'a [u8],
        pos: usize,
        base: u64,
    }

    impl<'a> Cursor<'a> {
        pub(crate) fn new(data: &'a [u8], base: u64) -> Cursor<'a> {
            Cursor { data, pos: 0, base }
        }

        /// The next `n` bytes, or `None` (consuming nothing) if fewer are left.
        pub(crate) fn take(&mut self, n: usize) -> Option<&'a [u8]> {
            let end = self.pos.checked_add(n)?;
            let bytes = self.data.get(self.pos..end)?;
            self.pos = end;
            Some(bytes)
        }

        pub(crate) fn remaining(&self) -> usize {
            self.data.len() - self.pos
        }

        /// The bytes not read yet.
        pub(crate) fn rest(&self) -> &'a [u8] {
            self.data.get(self.pos..).unwrap_or_default()
        }

        /// The offset into the data.
        pub(crate) fn offset(&self) -> usize {
            self.pos
        }

        /// The offset into the file.
        pub(crate) fn absolute(&self) -> u64 {
            self.base + self.pos as u64
        }

        pub(crate) fn position(&self) -> Position {
            Position::Byte(self.absolute())
        }

        /// The position of the end of the data.
        pub(crate) fn end_position(&self) -> Position {
            Position::Byte(self.base + self.data.len() as u64)
        }
    }

    // -----------------------------------------------------------------------------------------
    // Assembling a cloud

    /// A named column of values read from a file, stored in the file's type (64-bit integers
    /// as `f64`).
    pub(crate) struct Column {
        pub(crate) name: String,
        pub(crate) data: FieldData,
    }

    impl Column {
        /// An empty column for values of type `ty`.
        pub(crate) fn new(name: &str, ty: ScalarType, capacity: usize) -> Column {
            let data = match ty {
                ScalarType::I8 => FieldData::I8(Vec::with_capacity(capacity)),
                ScalarType::U8 => FieldData::U8(Vec::with_capacity(capacity)),
                ScalarType::I16 => FieldData::I16(Vec::with_capacity(capacity)),
                ScalarType::U16 => FieldData::U16(Vec::with_capacity(capacity)),
                ScalarType::I32 => FieldData::I32(Vec::with_capacity(capacity)),
                ScalarType::U32 => FieldData::U32(Vec::with_capacity(capacity)),
                ScalarType::F32 => FieldData::F32(Vec::with_capacity(capacity)),
                ScalarType::I64 | ScalarType::U64 | ScalarType::F64 => {
                    FieldData::F64(Vec::with_capacity(capacity))
                }
            };
            Column { name: name.to_owned(), data }
        }

        /// Appends a value. An integer pushed into an `f32` column is taken as the float's bit
        /// pattern (PCD's packed `rgb`).
        pub(crate) fn push(&mut self, value: Value) {
            let i = value.as_i128();
            match &mut self.data {
                FieldData::I8(v) => v.push(i as i8),
                FieldData::U8(v) => v.push(i as u8),
                FieldData::I16(v) => v.push(i as i16),
                FieldData::U16(v) => v.push(i as u16),
                FieldData::I32(v) => v.push(i as i32),
                FieldData::U32(v) => v.push(i as u32),
                FieldData::F32(v) => v.push(match value {
                    Value::Int(bits) => f32::from_bits(bits as u32),
                    other => other.as_f32(),
                }),
                FieldData::F64(v) => v.push(value.as_f64()),
            }
        }
    }

    /// The columns read from a file, each with `rows` values (one per record, invalid pixels
    /// included).
    pub(crate) struct Table {
        pub(crate) columns: Vec<Column>,
        pub(crate) rows: usize,
    }

    /// Whether the records are an image.
    #[derive(Copy, Clone, Debug)]
    pub(crate) enum Layout {
        Unorganised,
        Organised { width: u32, height: u32 },
    }

    /// Where each record is in the file, to name it in errors.
    pub(crate) enum RowPositions {
        /// Record `i` is on line `lines[i]`.
        Lines(Vec<u64>),
        /// Fixed-size records.
        Records { start: u64, stride: u64 },
        /// Record `i` starts at byte `offsets[i]`.
        Offsets(Vec<u64>),
        /// The records are in one block (compressed data) starting at this byte.
        Block(u64),
    }

    impl RowPositions {
        fn get(&self, row: usize) -> Option<Position> {
            match self {
                RowPositions::Lines(lines) => lines.get(row).copied().map(Position::Line),
                RowPositions::Records { start, stride } => {
                    Some(Position::Byte(start + stride * row as u64))
                }
                RowPositions::Offsets(offsets) => offsets.get(row).copied().map(Position::Byte),
                RowPositions::Block(start) => Some(Position::Byte(*start)),
            }
        }
    }

    /// The names of the dedicated slots in a format; a reader takes the first normal triple
    /// present.
    pub(crate) struct SlotNames {
        pub(crate) normals: &'static [[&'static str; 3]],
        pub(crate) intensity: &'static str,
        pub(crate) label: &'static str,
        pub(crate) ring: &'static str,
    }

    fn take_column(columns: &mut Vec<Column>, name: &str) -> Option<Column> {
        let i = columns.iter().position(|c| c.name == name)?;
        Some(columns.remove(i))
    }

    /// Removes the column `name` and returns its values if `convert` takes all of them.
    fn take_converted<T>(
        columns: &mut Vec<Column>,
        name: &str,
        convert: impl Fn(&FieldData) -> Option<Vec<T>>,
    ) -> Option<Vec<T>> {
        let i = columns.iter().position(|c| c.name == name)?;
        let values = convert(&columns[i].data)?;
        columns.remove(i);
        Some(values)
    }

    fn convert_each<T>(data: &FieldData, f: impl Fn(f64) -> Option<T>) -> Option<Vec<T>> {
        (0..data.len()).map(|i| data.get_f64(i).and_then(&f)).collect()
    }

    fn exact_f32(data: &FieldData) -> Option<Vec<f32>> {
        if let FieldData::F32(v) = data {
            return Some(v.clone());
        }
        convert_each(data, |x| {
            let y = x as f32;
            (f64::from(y) == x || x.is_nan()).then_some(y)
        })
    }

    fn exact_integer<T: TryFrom<u64>>(data: &FieldData) -> Option<Vec<T>> {
        convert_each(data, |x| {
            if x.fract() != 0.0 || !(0.0..=u64::MAX as f64).contains(&x) {
                return None;
            }
            T::try_from(x as u64).ok()
        })
    }

    /// The values of `data` at the rows `keep`.
    fn select(data: &FieldData, keep: &[usize]) -> FieldData {
        fn pick<T: Copy>(v: &[T], keep: &[usize]) -> Vec<T> {
            keep.iter().filter_map(|&i| v.get(i).copied()).collect()
        }
        match data {
            FieldData::I8(v) => FieldData::I8(pick(v, keep)),
            FieldData::U8(v) => FieldData::U8(pick(v, keep)),
            FieldData::I16(v) => FieldData::I16(pick(v, keep)),
            FieldData::U16(v) => FieldData::U16(pick(v, keep)),
            FieldData::I32(v) => FieldData::I32(pick(v, keep)),
            FieldData::U32(v) => FieldData::U32(pick(v, keep)),
            FieldData::F32(v) => FieldData::F32(pick(v, keep)),
            FieldData::F64(v) => FieldData::F64(pick(v, keep)),
        }
    }

    /// Builds the cloud: positions from `x y z`, the dedicated slots from their columns, the
    /// rest as extra fields; non-finite records become invalid pixels (organised), are dropped
    /// (`skip_non_finite`) or are an error naming the record.
    pub(crate) fn assemble(
        format: Format,
        table: Table,
        rows: &RowPositions,
        layout: Layout,
        pose: Option<SensorPose>,
        options: &ReadOptions,
        normal_names: &[[&str; 3]],
    ) -> Result<PointCloud, Error> {
        let Table { mut columns, rows: num_rows } = table;
        let attr = |e| Error::new(format, ErrorKind::Attribute(e));
        let [Some(x), Some(y), Some(z)] = ["x", "y", "z"].map(|n| take_column(&mut columns, n))
        else {
            return Err(Error::new(format, ErrorKind::BadHeader("no x, y and z".into())));
        };
        let coordinate = |c: &Column, i| c.data.get_f64(i).unwrap_or(f64::NAN);
        let mut positions = Vec::with_capacity(num_rows);
        let mut keep = Vec::with_capacity(num_rows);
        let mut pixels = Vec::new();
        for i in 0..num_rows {
            let p = Point3::new(coordinate(&x, i), coordinate(&y, i), coordinate(&z, i));
            let finite = p.coords.iter().all(|v| v.is_finite());
            match layout {
                Layout::Organised { .. } => {
                    pixels.push(if finite { positions.len() as u32 } else { INVALID_PIXEL });
                }
                Layout::Unorganised if !finite && !options.skip_non_finite => {
                    let kind = ErrorKind::NonFinite { point: i as u64 };
                    return Err(Error {
                        format: Some(format),
                        path: None,
                        position: rows.get(i),
                        kind,
                    });
                }
                Layout::Unorganised => {}
            }
            if finite {
                positions.push(p);
                keep.push(i);
            }
        }
        if keep.len() != num_rows {
            for column in &mut columns {
                column.data = select(&column.data, &keep);
            }
        }
        let mut cloud = PointCloud::from_positions(positions).map_err(attr)?;
        for names in normal_names {
            if names.iter().all(|n| columns.iter().any(|c| c.name == *n)) {
                let [nx, ny, nz] = names.map(|n| take_column(&mut columns, n));
                let (Some(nx), Some(ny), Some(nz)) = (nx, ny, nz) else { continue };
                let normals = (0..cloud.len())
                    .map(|i| {
                        Vector3::new(coordinate(&nx, i), coordinate(&ny, i), coordinate(&nz, i))
                    })
                    .collect();
                cloud.set_normals(Some(normals)).map_err(attr)?;
                break;
            }
        }
        cloud.set_intensity(take_converted(&mut columns, "intensity", exact_f32)).map_err(attr)?;
        cloud.set_labels(take_converted(&mut columns, "label", exact_integer)).map_err(attr)?;
        cloud.set_rings(take_converted(&mut columns, "ring", exact_integer)).map_err(attr)?;
        for column in columns {
            cloud
                .push_extra_field(ScalarField { name: column.name, data: column.data })
                .map_err(attr)?;
        }
        if let Layout::Organised { width, height } = layout {
            let grid = Grid::new(width, height, pixels, cloud.len()).map_err(attr)?;
            cloud.set_grid(Some(grid)).map_err(attr)?;
        }
        cloud.set_sensor_pose(pose);
        Ok(cloud)
    }

    // -----------------------------------------------------------------------------------------
    // Writing

    /// Where a written column takes its values.
    enum Source<'a> {
        Position(&'a [Point3], usize),
        Normal(&'a [Vector3], usize),
        Intensity(&'a [f32]),
        Label(&'a [u32]),
        Ring(&'a [u16]),
        Extra(&'a FieldData),
    }

    /// A column to write: its name, its type, and where its values come from.
    pub(crate) struct OutColumn<'a> {
        pub(crate) name: &'a str,
        pub(crate) ty: ScalarType,
        source: Source<'a>,
    }

    impl OutColumn<'_> {
        /// The value for a point, or the filler of an invalid pixel (`None`): NaN for
        /// floating-point columns, 0 for integer ones.
        pub(crate) fn value(&self, point: Option<usize>) -> Value {
            let value = point.and_then(|i| match self.source {
                Source::Position(p, axis) => p.get(i).map(|p| Value::F64(p[axis])),
                Source::Normal(n, axis) => n.get(i).map(|n| Value::F64(n[axis])),
                Source::Intensity(v) => v.get(i).map(|&x| Value::F32(x)),
                Source::Label(v) => v.get(i).map(|&x| Value::Int(x.into())),
                Source::Ring(v) => v.get(i).map(|&x| Value::Int(x.into())),
                Source::Extra(data) => field_value(data, i),
            });
            value.unwrap_or(if self.ty.is_integer() { Value::Int(0) } else { Value::F64(f64::NAN) })
        }
    }

    fn field_value(data: &FieldData, i: usize) -> Option<Value> {
        Some(match data {
            FieldData::I8(v) => Value::Int((*v.get(i)?).into()),
            FieldData::U8(v) => Value::Int((*v.get(i)?).into()),
            FieldData::I16(v) => Value::Int((*v.get(i)?).into()),
            FieldData::U16(v) => Value::Int((*v.get(i)?).into()),
            FieldData::I32(v) => Value::Int((*v.get(i)?).into()),
            FieldData::U32(v) => Value::Int((*v.get(i)?).into()),
            FieldData::F32(v) => Value::F32(*v.get(i)?),
            FieldData::F64(v) => Value::F64(*v.get(i)?),
        })
    }

    /// The columns to write for `cloud`: positions, normals (the first triple of
    /// `names.normals`), intensity, labels, rings, extra fields. Fails if a name is not a
    /// printable ASCII word or is used twice.
    pub(crate) fn out_columns<'a>(
        format: Format,
        cloud: &'a PointCloud,
        precision: Precision,
        names: &SlotNames,
    ) -> Result<Vec<OutColumn<'a>>, Error> {
        let float = match precision {
            Precision::F32 => ScalarType::F32,
            Precision::F64 => ScalarType::F64,
        };
        let mut columns = Vec::new();
        for (axis, name) in ["x", "y", "z"].into_iter().enumerate() {
            columns.push(OutColumn {
                name,
                ty: float,
                source: Source::Position(cloud.positions(), axis),
            });
        }
        if let (Some(normals), Some(triple)) = (cloud.normals(), names.normals.first()) {
            for (axis, &name) in triple.iter().enumerate() {
                columns.push(OutColumn { name, ty: float, source: Source::Normal(normals, axis) });
            }
        }
        if let Some(v) = cloud.intensity() {
            columns.push(OutColumn {
                name: names.intensity,
                ty: ScalarType::F32,
                source: Source::Intensity(v),
            });
        }
        if let Some(v) = cloud.labels() {
            columns.push(OutColumn {
                name: names.label,
                ty: ScalarType::U32,
                source: Source::Label(v),
            });
        }
        if let Some(v) = cloud.rings() {
            columns.push(OutColumn {
                name: names.ring,
                ty: ScalarType::U16,
                source: Source::Ring(v),
            });
        }
        for field in cloud.extra_fields() {
            let name = field.name.as_str();
            if name.is_empty() || !name.bytes().all(|b| b.is_ascii_graphic()) {
                return Err(bad_name(
                    format,
                    format!("field name {name:?} is not a printable ASCII word"),
                ));
            }
            let ty = ScalarType::of_field(&field.data);
            columns.push(OutColumn { name, ty, source: Source::Extra(&field.data) });
        }
        for (i, column) in columns.iter().enumerate() {
            if columns[..i].iter().any(|c| c.name == column.name) {
                return Err(bad_name(
                    format,
                    format!("field name `{}` is used twice", column.name),
                ));
            }
        }
        Ok(columns)
    }

    fn bad_name(format: Format, message: String) -> Error {
        Error::new(format, ErrorKind::BadValue(message))
    }

    /// The number of records to write: the pixels of an organised cloud, else the points.
    pub(crate) fn row_count(cloud: &PointCloud) -> usize {
        cloud.grid().map_or(cloud.len(), |g| g.num_pixels())
    }

    /// The point of record `row` (`None` for an invalid pixel).
    pub(crate) fn row_point(cloud: &PointCloud, row: usize) -> Option<usize> {
        match cloud.grid() {
            Some(grid) => {
                grid.pixels().get(row).filter(|&&p| p != INVALID_PIXEL).map(|&p| p as usize)
            }
            None => Some(row),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::common::{ScalarType, Value};
    use super::*;

    #[test]
    fn scalar_types_parse_their_range() {
        assert_eq!(ScalarType::U8.parse("255"), Ok(Value::Int(255)));
        assert!(ScalarType::U8.parse("256").is_err());
        assert!(ScalarType::U8.parse("-1").is_err());
        assert_eq!(ScalarType::I16.parse("-3.0"), Ok(Value::Int(-3)));
        assert!(ScalarType::I16.parse("1.5").is_err());
        assert!(ScalarType::I32.parse("nan").is_err());
        for token in ["nan", "NaN", "-nan", "nan(ind)", "1.#QNAN", "-1.#IND"] {
            assert!(
                matches!(ScalarType::F32.parse(token), Ok(Value::F32(x)) if x.is_nan()),
                "{token}"
            );
            assert!(
                matches!(ScalarType::F64.parse(token), Ok(Value::F64(x)) if x.is_nan()),
                "{token}"
            );
        }
        assert_eq!(ScalarType::F64.parse("-Infinity"), Ok(Value::F64(f64::NEG_INFINITY)));
        assert_eq!(ScalarType::F64.parse("1.#INF"), Ok(Value::F64(f64::INFINITY)));
        assert_eq!(ScalarType::F64.parse("INF"), Ok(Value::F64(f64::INFINITY)));
        assert!(ScalarType::F64.parse("1,5").is_err());
    }

    #[test]
    fn binary_encoding_round_trips_every_type() {
        use ScalarType::*;
        for ty in [I8, U8, I16, U16, I32, U32, I64, U64, F32, F64] {
            for big_endian in [false, true] {
                let mut bytes = Vec::new();
                ty.encode(Value::Int(100), big_endian, &mut bytes);
                assert_eq!(bytes.len(), ty.size());
                assert_eq!(ty.decode(&bytes, big_endian).as_i128(), 100, "{ty:?}");
            }
        }
        let mut bytes = Vec::new();
        ScalarType::U16.encode(Value::Int(0x0102), true, &mut bytes);
        assert_eq!(bytes, [1, 2]);
    }

    #[test]
    fn floats_print_shortest_round_trip_text() {
        let mut s = String::new();
        for x in [0.1f64, -2.5e-300, 1e300, 123456.789, -0.0, 7.0] {
            s.clear();
            common::push_f64(&mut s, x);
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), x.to_bits(), "{s}");
        }
        for x in [0.1f32, 3.4e38, 1e-40, -1.5] {
            s.clear();
            common::push_f32(&mut s, x);
            assert_eq!(s.parse::<f32>().unwrap().to_bits(), x.to_bits(), "{s}");
        }
    }

    #[test]
    fn rotation_check() {
        let v = [0., 0., 1., 10., -1., 0., 0., 7.5, 0., -1., 0., 1.25];
        let pose = pose_from_rows(&v).unwrap();
        let p = pose.world_from_sensor * crate::Point3::new(0.0, 0.0, 2.0);
        assert!((p - crate::Point3::new(12.0, 7.5, 1.25)).norm() < 1e-12);
        let mirror = [1., 0., 0., 0., 0., 1., 0., 0., 0., 0., -1., 0.];
        assert!(pose_from_rows(&mirror).is_err());
        let scaled = [2., 0., 0., 0., 0., 2., 0., 0., 0., 0., 2., 0.];
        assert!(pose_from_rows(&scaled).is_err());
    }
}
