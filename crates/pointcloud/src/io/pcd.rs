//! PCD v0.7 (Point Cloud Library) point clouds.
//!
//! Format reference: "The PCD (Point Cloud Data) file format"
//! (<https://pointclouds.org/documentation/tutorials/pcd_file_format.html>), and PCL's
//! `pcd_io.cpp` for what the specification leaves open (padding fields, the compressed layout,
//! `rgb` in ASCII data).
//!
//! # What is read
//! A PCD file is a text header of `KEY values` lines (`#` starts a comment line) ending with the
//! `DATA` line, followed by the point data:
//!
//! ```text
//! VERSION 0.7
//! FIELDS x y z rgb           field names (`COLUMNS` is an old synonym)
//! SIZE 4 4 4 4               bytes per value: 1, 2, 4 or 8
//! TYPE F F F F               I signed, U unsigned integer, F floating point (4 or 8 bytes)
//! COUNT 1 1 1 1              values per field (default 1)
//! WIDTH 640                  points per row
//! HEIGHT 480                 rows; more than 1 means an organised (image) cloud
//! VIEWPOINT 0 0 0 1 0 0 0    tx ty tz qw qx qy qz (default identity)
//! POINTS 307200              WIDTH × HEIGHT (default WIDTH × HEIGHT)
//! DATA binary_compressed     ascii, binary or binary_compressed
//! ```
//!
//! * `ascii`: one point per line, the values of every field (COUNT of them each) in order.
//! * `binary`: the points back to back as little-endian records (an array of structs).
//! * `binary_compressed`: a little-endian `u32` compressed size, a `u32` uncompressed size, then
//!   an LZF stream (liblzf format) whose output is a struct of arrays: all values of the first
//!   field (`POINTS × SIZE × COUNT` bytes), then all of the second, and so on. As in PCL,
//!   padding fields named `_` have no bytes in it.
//!
//! Fields map to the cloud as follows:
//!
//! | field | cloud |
//! |---|---|
//! | `x`, `y`, `z` (any numeric type, required) | positions |
//! | `normal_x`, `normal_y`, `normal_z` (or `nx`, `ny`, `nz`) | normals |
//! | `intensity` | intensity (when every value converts to `f32` exactly) |
//! | `label` | labels (when every value is an integer that fits `u32`) |
//! | `ring` | rings (when every value is an integer that fits `u16`) |
//! | `_` | nothing: PCL's padding, skipped |
//! | anything else (`rgb`, `rgba`, `curvature`, ...) | an extra field in its stored type |
//!
//! A field with `COUNT` n > 1 becomes n extra fields `name_0` … `name_{n-1}`. `rgb` is PCL's
//! packed colour, a float whose bits are `0xAARRGGBB`: it is kept as an `f32` field bit for bit,
//! also when a file stores it as `U 4` (as PCL's ASCII writer does). 64-bit integer fields
//! (`I 8`, `U 8`) are kept as `f64` fields, exact up to 2^53.
//!
//! `HEIGHT` > 1 makes an organised cloud: points with a non-finite coordinate are invalid
//! [`Grid`](crate::Grid) pixels. With `HEIGHT` 1 a non-finite point is an
//! [`ErrorKind::NonFinite`] error, or is dropped with [`ReadOptions::skip_non_finite`].
//!
//! `VIEWPOINT` is where the sensor was: PCL's viewer places the cloud in the world with it, so
//! it becomes the cloud's [`SensorPose`] (`world_from_sensor`); the identity viewpoint means
//! no pose.
//!
//! Counts are checked against the data present before memory is reserved; data beyond the
//! declared points is an error, except zero bytes (older PCL versions make binary files a page
//! longer than their header and data).
//!
//! # What is written
//! `x y z` as `F 4` or `F 8` ([`Precision`]), `normal_x normal_y normal_z` likewise if the cloud
//! has normals, `intensity` (`F 4`), `label` (`U 4`), `ring` (`U 2`) if present, then every
//! extra field in its own type, all with `COUNT 1`. An organised cloud of at least two rows is
//! written pixel by pixel with invalid pixels as NaN in floating-point fields and 0 in integer
//! ones; a cloud organised as a single row is written unorganised, because PCD cannot tell a
//! one-row image from an unorganised cloud. In ASCII data an `f32` `rgb` field is written as
//! `U 4` with the integer of its bits, as PCL does, since packed colours are often NaN as
//! floats; other NaN payloads are not kept by ASCII data.

use super::lzf;
use super::ply::common::{
    Column, Cursor, HeaderReader, Layout, OutColumn, RowPositions, ScalarType, SlotNames, Table,
    TextLines, Value, assemble, out_columns, push_f64, row_point,
};
use super::{Error, ErrorKind, Format, Position, Precision, ReadOptions};
use crate::{INVALID_PIXEL, Isometry3, PointCloud, SensorPose};
use std::collections::HashSet;
use std::io::{BufRead, BufWriter, Write};

/// The three PCD data encodings.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum PcdEncoding {
    /// `DATA ascii`: one point per text line.
    Ascii,
    /// `DATA binary`: little-endian records, one per point.
    Binary,
    /// `DATA binary_compressed`: LZF-compressed, field by field.
    BinaryCompressed,
}

impl PcdEncoding {
    fn keyword(self) -> &'static str {
        match self {
            PcdEncoding::Ascii => "ascii",
            PcdEncoding::Binary => "binary",
            PcdEncoding::BinaryCompressed => "binary_compressed",
        }
    }
}

/// How [`write_pcd`] writes a cloud.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct PcdWriteOptions {
    /// The data encoding.
    pub encoding: PcdEncoding,
    /// `F 4` or `F 8` for positions and normals.
    pub precision: Precision,
}

impl Default for PcdWriteOptions {
    /// Binary with `F 4` positions, what PCL tools expect.
    fn default() -> PcdWriteOptions {
        PcdWriteOptions { encoding: PcdEncoding::Binary, precision: Precision::F32 }
    }
}

/// Names of the dedicated slots in PCD files; the first normal triple is the one written.
const NAMES: SlotNames = SlotNames {
    normals: &[["normal_x", "normal_y", "normal_z"], ["nx", "ny", "nz"]],
    intensity: "intensity",
    label: "label",
    ring: "ring",
};

/// The most values one point may have (a sanity bound on `COUNT`).
const MAX_VALUES_PER_POINT: u64 = 1 << 16;

/// Reads a PCD v0.7 point cloud (see the [module documentation](self) for what is mapped
/// where).
///
/// Errors name the header or data line of ASCII data and the byte offset of binary data.
pub fn read_pcd(reader: impl BufRead, options: &ReadOptions) -> Result<PointCloud, Error> {
    let mut lines = HeaderReader::new(reader, Format::Pcd);
    let header = parse_header(&mut lines)?;
    let first_body_line = lines.line() + 1;
    let body_start = lines.bytes();
    let body = lines.into_body()?;
    let (table, rows) = match header.data {
        PcdEncoding::Ascii => read_ascii(&header, &body, first_body_line)?,
        PcdEncoding::Binary => read_binary(&header, &body, body_start)?,
        PcdEncoding::BinaryCompressed => read_compressed(&header, &body, body_start)?,
    };
    let layout = if header.height > 1 {
        // parse_header checked that both fit u32.
        Layout::Organised { width: header.width as u32, height: header.height as u32 }
    } else {
        Layout::Unorganised
    };
    assemble(Format::Pcd, table, &rows, layout, header.pose, options, NAMES.normals)
}

/// Writes `cloud` as PCD v0.7 (see the [module documentation](self) for the layout).
///
/// Fails on an I/O error, if an extra field's name is not a single printable ASCII word other
/// than `_` or repeats a name already written, or if compressed data would exceed 4 GiB.
pub fn write_pcd(
    writer: impl Write,
    cloud: &PointCloud,
    options: &PcdWriteOptions,
) -> Result<(), Error> {
    let columns = out_columns(Format::Pcd, cloud, options.precision, &NAMES)?;
    if columns.iter().any(|c| c.name == "_") {
        return Err(Error::new(
            Format::Pcd,
            ErrorKind::BadValue("a field named `_` would be read as padding".into()),
        ));
    }
    let records = Records::of(cloud);
    let io = |e: std::io::Error| Error::new(Format::Pcd, e);
    let mut w = BufWriter::new(writer);
    write_header(&mut w, cloud, &columns, &records, options.encoding).map_err(io)?;
    match options.encoding {
        PcdEncoding::Ascii => write_ascii(&mut w, &columns, &records).map_err(io)?,
        PcdEncoding::Binary => write_binary(&mut w, &columns, &records).map_err(io)?,
        PcdEncoding::BinaryCompressed => write_compressed(&mut w, &columns, &records)?,
    }
    w.flush().map_err(io)
}

// ---------------------------------------------------------------------------------------------
// Header

/// One `FIELDS` entry.
#[derive(Clone, Debug)]
struct Field {
    name: String,
    ty: ScalarType,
    count: usize,
}

impl Field {
    fn is_padding(&self) -> bool {
        self.name == "_"
    }

    fn bytes(&self) -> usize {
        self.ty.size() * self.count
    }

    /// PCL's packed colour: kept as `f32` bits whether stored as `F 4` or `U 4`.
    fn is_packed_rgb(&self) -> bool {
        self.name == "rgb"
            && self.count == 1
            && matches!(self.ty, ScalarType::F32 | ScalarType::U32)
    }
}

#[derive(Debug)]
struct Header {
    fields: Vec<Field>,
    width: u64,
    height: u64,
    points: u64,
    pose: Option<SensorPose>,
    data: PcdEncoding,
}

impl Header {
    /// Bytes per point in `binary` data.
    fn record_size(&self) -> usize {
        self.fields.iter().map(Field::bytes).sum()
    }

    /// Bytes per point in `binary_compressed` data (padding has none).
    fn packed_size(&self) -> usize {
        self.fields.iter().filter(|f| !f.is_padding()).map(Field::bytes).sum()
    }
}

/// Header values with the line they were on.
#[derive(Default)]
struct RawHeader {
    fields: Option<(Vec<String>, u64)>,
    sizes: Option<(Vec<u64>, u64)>,
    types: Option<(Vec<String>, u64)>,
    counts: Option<(Vec<u64>, u64)>,
    width: Option<(u64, u64)>,
    height: Option<(u64, u64)>,
    points: Option<(u64, u64)>,
    viewpoint: Option<([f64; 7], u64)>,
}

fn bad_header(line: u64, message: impl Into<String>) -> Error {
    Error::at(Format::Pcd, Position::Line(line), ErrorKind::BadHeader(message.into()))
}

fn set<T>(slot: &mut Option<(T, u64)>, value: T, key: &str, line: u64) -> Result<(), Error> {
    if slot.is_some() {
        return Err(bad_header(line, format!("a second {key} line")));
    }
    *slot = Some((value, line));
    Ok(())
}

fn parse_numbers(values: &[&str], key: &str, line: u64) -> Result<Vec<u64>, Error> {
    values
        .iter()
        .map(|v| v.parse::<u64>().map_err(|_| bad_header(line, format!("{key}: bad number `{v}`"))))
        .collect()
}

fn parse_one(values: &[&str], key: &str, line: u64) -> Result<u64, Error> {
    match parse_numbers(values, key, line)?.as_slice() {
        [value] => Ok(*value),
        _ => Err(bad_header(line, format!("{key} needs exactly one number"))),
    }
}

fn parse_viewpoint(values: &[&str], line: u64) -> Result<[f64; 7], Error> {
    let numbers: Option<Vec<f64>> =
        values.iter().map(|v| v.parse::<f64>().ok().filter(|x| x.is_finite())).collect();
    numbers
        .and_then(|v| <[f64; 7]>::try_from(v).ok())
        .ok_or_else(|| bad_header(line, "VIEWPOINT needs 7 finite numbers: tx ty tz qw qx qy qz"))
}

fn parse_header<R: BufRead>(lines: &mut HeaderReader<R>) -> Result<Header, Error> {
    let mut raw = RawHeader::default();
    loop {
        let Some(text) = lines.next_line()? else {
            return Err(Error::at(
                Format::Pcd,
                Position::Line(lines.line() + 1),
                ErrorKind::UnexpectedEof { expected: "the DATA line".into() },
            ));
        };
        let line = lines.line();
        let tokens: Vec<&str> = text.split_ascii_whitespace().collect();
        let Some((&key, values)) = tokens.split_first() else { continue };
        if key.starts_with('#') {
            continue;
        }
        let strings = || values.iter().map(|v| (*v).to_owned()).collect::<Vec<_>>();
        match key {
            "VERSION" => {}
            "FIELDS" | "COLUMNS" => set(&mut raw.fields, strings(), key, line)?,
            "SIZE" => set(&mut raw.sizes, parse_numbers(values, key, line)?, key, line)?,
            "TYPE" => set(&mut raw.types, strings(), key, line)?,
            "COUNT" => set(&mut raw.counts, parse_numbers(values, key, line)?, key, line)?,
            "WIDTH" => set(&mut raw.width, parse_one(values, key, line)?, key, line)?,
            "HEIGHT" => set(&mut raw.height, parse_one(values, key, line)?, key, line)?,
            "POINTS" => set(&mut raw.points, parse_one(values, key, line)?, key, line)?,
            "VIEWPOINT" => set(&mut raw.viewpoint, parse_viewpoint(values, line)?, key, line)?,
            "DATA" => {
                let data = match values {
                    [v] if v.eq_ignore_ascii_case("ascii") => PcdEncoding::Ascii,
                    [v] if v.eq_ignore_ascii_case("binary") => PcdEncoding::Binary,
                    [v] if v.eq_ignore_ascii_case("binary_compressed") => {
                        PcdEncoding::BinaryCompressed
                    }
                    _ => {
                        return Err(bad_header(
                            line,
                            "DATA must be ascii, binary or binary_compressed",
                        ));
                    }
                };
                return finish_header(raw, data, line);
            }
            other => return Err(bad_header(line, format!("unknown header key `{other}`"))),
        }
    }
}

/// The type of a `TYPE` letter and `SIZE`.
fn scalar_type(letter: &str, size: u64) -> Option<ScalarType> {
    Some(match (letter, size) {
        ("I", 1) => ScalarType::I8,
        ("I", 2) => ScalarType::I16,
        ("I", 4) => ScalarType::I32,
        ("I", 8) => ScalarType::I64,
        ("U", 1) => ScalarType::U8,
        ("U", 2) => ScalarType::U16,
        ("U", 4) => ScalarType::U32,
        ("U", 8) => ScalarType::U64,
        ("F", 4) => ScalarType::F32,
        ("F", 8) => ScalarType::F64,
        _ => return None,
    })
}

fn finish_header(raw: RawHeader, data: PcdEncoding, data_line: u64) -> Result<Header, Error> {
    let fields = parse_fields(&raw, data_line)?;
    let (width, height, points) = dimensions(&raw, data_line)?;
    let pose = match raw.viewpoint {
        Some((v, line)) => pose_from_viewpoint(v).map_err(|m| bad_header(line, m))?,
        None => None,
    };
    Ok(Header { fields, width, height, points, pose, data })
}

fn parse_fields(raw: &RawHeader, data_line: u64) -> Result<Vec<Field>, Error> {
    let missing = |key: &str| bad_header(data_line, format!("no {key} line before DATA"));
    let (names, names_line) = raw.fields.as_ref().ok_or_else(|| missing("FIELDS"))?;
    let (sizes, sizes_line) = raw.sizes.as_ref().ok_or_else(|| missing("SIZE"))?;
    let (types, types_line) = raw.types.as_ref().ok_or_else(|| missing("TYPE"))?;
    let ones = (vec![1; names.len()], *names_line);
    let (counts, counts_line) = raw.counts.as_ref().unwrap_or(&ones);
    if names.is_empty() {
        return Err(bad_header(*names_line, "FIELDS is empty"));
    }
    for (key, len, line) in [
        ("SIZE", sizes.len(), sizes_line),
        ("TYPE", types.len(), types_line),
        ("COUNT", counts.len(), counts_line),
    ] {
        if len != names.len() {
            let message = format!("{key} has {len} entries for {} fields", names.len());
            return Err(bad_header(*line, message));
        }
    }
    let total: u64 = counts.iter().fold(0u64, |a, &c| a.saturating_add(c));
    if counts.contains(&0) || total > MAX_VALUES_PER_POINT {
        let message =
            format!("COUNT must be between 1 and {MAX_VALUES_PER_POINT} values per point");
        return Err(bad_header(*counts_line, message));
    }
    let mut fields = Vec::with_capacity(names.len());
    for i in 0..names.len() {
        let ty = scalar_type(&types[i], sizes[i]).ok_or_else(|| {
            Error::at(
                Format::Pcd,
                Position::Line(*types_line),
                ErrorKind::Unsupported(format!("TYPE {} with SIZE {}", types[i], sizes[i])),
            )
        })?;
        fields.push(Field { name: names[i].clone(), ty, count: counts[i] as usize });
    }
    let mut seen = HashSet::new();
    for name in fields.iter().filter(|f| !f.is_padding()).flat_map(column_names) {
        if !seen.insert(name.clone()) {
            return Err(bad_header(*names_line, format!("field `{name}` appears twice")));
        }
    }
    for axis in ["x", "y", "z"] {
        if !seen.contains(axis) {
            return Err(bad_header(*names_line, format!("no field `{axis}` with COUNT 1")));
        }
    }
    Ok(fields)
}

/// The names of a field's values: `name`, or `name_0` … for COUNT > 1.
fn column_names(field: &Field) -> Vec<String> {
    if field.count == 1 {
        vec![field.name.clone()]
    } else {
        (0..field.count).map(|k| format!("{}_{k}", field.name)).collect()
    }
}

/// `(WIDTH, HEIGHT, POINTS)`, defaults filled in and checked.
fn dimensions(raw: &RawHeader, data_line: u64) -> Result<(u64, u64, u64), Error> {
    let (height, height_line) = raw.height.unwrap_or((1, data_line));
    let (width, width_line) = match (raw.width, raw.points) {
        (Some(w), _) => w,
        (None, Some((points, line))) if raw.height.is_none() => (points, line),
        _ => return Err(bad_header(data_line, "no WIDTH line before DATA")),
    };
    let pixels = width.checked_mul(height).ok_or_else(|| {
        bad_header(height_line, format!("WIDTH {width} × HEIGHT {height} overflows"))
    })?;
    let points = match raw.points {
        Some((points, line)) if points != pixels => {
            let message = format!("POINTS {points} differs from WIDTH × HEIGHT = {pixels}");
            return Err(bad_header(line, message));
        }
        _ => pixels,
    };
    let too_large = u32::try_from(width).is_err() || u32::try_from(height).is_err();
    if height > 1 && (too_large || pixels >= u64::from(INVALID_PIXEL)) {
        return Err(Error::at(
            Format::Pcd,
            Position::Line(width_line.max(height_line)),
            ErrorKind::Unsupported(format!("an organised cloud of {width} × {height} points")),
        ));
    }
    Ok((width, height, points))
}

/// The pose of a `VIEWPOINT tx ty tz qw qx qy qz`; `None` for the identity.
fn pose_from_viewpoint(v: [f64; 7]) -> Result<Option<SensorPose>, String> {
    let [tx, ty, tz, qw, qx, qy, qz] = v;
    if [tx, ty, tz, qx, qy, qz] == [0.0; 6] {
        return Ok(None);
    }
    let q = na::Quaternion::new(qw, qx, qy, qz);
    let norm = q.norm();
    if norm <= 1e-6 {
        return Err("VIEWPOINT has a zero quaternion".into());
    }
    // Keep a quaternion that is unit to rounding as it is, so poses round-trip bit for bit.
    let rotation = if (norm - 1.0).abs() <= 1e-12 {
        na::UnitQuaternion::new_unchecked(q)
    } else {
        na::UnitQuaternion::new_normalize(q)
    };
    let translation = na::Translation3::new(tx, ty, tz);
    Ok(Some(SensorPose { world_from_sensor: Isometry3::from_parts(translation, rotation) }))
}

// ---------------------------------------------------------------------------------------------
// Data

/// Where one value of a point is stored and which column it goes to.
struct Slot {
    /// `None` for padding.
    column: Option<usize>,
    ty: ScalarType,
    /// Offset in a `binary` record.
    record_offset: usize,
    /// Offset in the `binary_compressed` buffer of this value of point 0.
    block_offset: usize,
    /// Bytes from one point to the next in the `binary_compressed` buffer.
    block_stride: usize,
}

/// The columns to fill and the slots of one point, in file order.
fn layout(header: &Header, capacity: usize) -> (Vec<Column>, Vec<Slot>) {
    let points = header.points as usize;
    let mut columns = Vec::new();
    let mut slots = Vec::new();
    let (mut record_offset, mut packed_offset) = (0, 0);
    for field in &header.fields {
        let names = if field.is_padding() { Vec::new() } else { column_names(field) };
        for k in 0..field.count {
            let column = names.get(k).map(|name| {
                let ty = if field.is_packed_rgb() { ScalarType::F32 } else { field.ty };
                columns.push(Column::new(name, ty, capacity));
                columns.len() - 1
            });
            slots.push(Slot {
                column,
                ty: field.ty,
                record_offset: record_offset + k * field.ty.size(),
                block_offset: points.saturating_mul(packed_offset) + k * field.ty.size(),
                block_stride: field.bytes(),
            });
        }
        record_offset += field.bytes();
        if !field.is_padding() {
            packed_offset += field.bytes();
        }
    }
    (columns, slots)
}

/// Fails unless `available` bytes hold `points × size` bytes exactly.
fn check_data_size(
    header: &Header,
    size: usize,
    available: usize,
    cursor: &Cursor<'_>,
) -> Result<usize, Error> {
    let needed = header.points.checked_mul(size as u64);
    match needed {
        Some(needed) if needed <= available as u64 => Ok(needed as usize),
        _ => Err(Error::at(
            Format::Pcd,
            cursor.end_position(),
            ErrorKind::CountMismatch {
                what: "points",
                declared: header.points,
                found: (available / size.max(1)) as u64,
            },
        )),
    }
}

/// Fails if data follow the points, except zero bytes: older PCL versions size binary files to
/// a page plus the data, leaving zeros after the points.
fn check_trailing(cursor: &Cursor<'_>, declared: usize) -> Result<(), Error> {
    if cursor.rest().iter().all(|&b| b == 0) {
        return Ok(());
    }
    Err(Error::at(
        Format::Pcd,
        cursor.position(),
        ErrorKind::CountMismatch {
            what: "bytes of point data",
            declared: declared as u64,
            found: (declared + cursor.remaining()) as u64,
        },
    ))
}

fn read_binary(
    header: &Header,
    body: &[u8],
    body_start: u64,
) -> Result<(Table, RowPositions), Error> {
    let mut cursor = Cursor::new(body, body_start);
    let record = header.record_size();
    let needed = check_data_size(header, record, body.len(), &cursor)?;
    let data = cursor.take(needed).unwrap_or_default();
    check_trailing(&cursor, needed)?;
    let rows = header.points as usize;
    let (mut columns, slots) = layout(header, rows);
    for point in data.chunks_exact(record) {
        for slot in &slots {
            if let Some(c) = slot.column {
                let bytes = point.get(slot.record_offset..).unwrap_or_default();
                columns[c].push(slot.ty.decode(bytes, false));
            }
        }
    }
    let positions = RowPositions::Records { start: body_start, stride: record as u64 };
    Ok((Table { columns, rows }, positions))
}

fn read_compressed(
    header: &Header,
    body: &[u8],
    body_start: u64,
) -> Result<(Table, RowPositions), Error> {
    let mut cursor = Cursor::new(body, body_start);
    let sizes = cursor.take(8).ok_or_else(|| {
        Error::at(
            Format::Pcd,
            cursor.end_position(),
            ErrorKind::UnexpectedEof { expected: "the compressed and uncompressed sizes".into() },
        )
    })?;
    let word = |i: usize| ScalarType::U32.decode(&sizes[i..], false).as_i128() as usize;
    let (compressed, uncompressed) = (word(0), word(4));
    let expected = header.points.checked_mul(header.packed_size() as u64);
    if expected != Some(uncompressed as u64) {
        return Err(Error::at(
            Format::Pcd,
            Position::Byte(body_start + 4),
            ErrorKind::CountMismatch {
                what: "bytes of uncompressed data",
                declared: expected.unwrap_or(u64::MAX),
                found: uncompressed as u64,
            },
        ));
    }
    let stream_start = cursor.absolute();
    let stream = cursor.take(compressed).ok_or_else(|| {
        Error::at(
            Format::Pcd,
            cursor.end_position(),
            ErrorKind::UnexpectedEof { expected: format!("{compressed} bytes of LZF data") },
        )
    })?;
    check_trailing(&cursor, 8 + compressed)?;
    let buffer = lzf::decompress(stream, uncompressed).map_err(|e| {
        let position = Position::Byte(stream_start + e.offset(stream.len()) as u64);
        Error::at(Format::Pcd, position, ErrorKind::BadValue(e.to_string()))
    })?;
    let rows = header.points as usize;
    let (mut columns, slots) = layout(header, rows);
    for slot in &slots {
        let Some(c) = slot.column else { continue };
        for row in 0..rows {
            let at = slot.block_offset + row * slot.block_stride;
            columns[c].push(slot.ty.decode(buffer.get(at..).unwrap_or_default(), false));
        }
    }
    Ok((Table { columns, rows }, RowPositions::Block(body_start)))
}

fn bad_value(line: u64, message: String) -> Error {
    Error::at(Format::Pcd, Position::Line(line), ErrorKind::BadValue(message))
}

fn read_ascii(
    header: &Header,
    body: &[u8],
    first_line: u64,
) -> Result<(Table, RowPositions), Error> {
    let mut lines = TextLines::new(body, first_line);
    let capacity = header.points.min(lines.count_nonblank() as u64) as usize;
    let (mut columns, slots) = layout(header, capacity);
    let mut row_lines = Vec::with_capacity(capacity);
    for found in 0..header.points {
        let Some(text) = lines.next_nonblank() else {
            return Err(Error::at(
                Format::Pcd,
                Position::Line(lines.line() + 1),
                ErrorKind::CountMismatch { what: "points", declared: header.points, found },
            ));
        };
        let line = lines.line();
        row_lines.push(line);
        let text = std::str::from_utf8(text)
            .map_err(|_| bad_value(line, "the line is not UTF-8 text".into()))?;
        let mut tokens = text.split_ascii_whitespace();
        for (k, slot) in slots.iter().enumerate() {
            let token = tokens
                .next()
                .ok_or_else(|| bad_value(line, format!("{k} values, {} expected", slots.len())))?;
            if let Some(c) = slot.column {
                let value = slot
                    .ty
                    .parse(token)
                    .map_err(|e| bad_value(line, format!("field `{}`: {e}", columns[c].name)))?;
                columns[c].push(value);
            }
        }
        if tokens.next().is_some() {
            return Err(bad_value(line, format!("more than the {} values expected", slots.len())));
        }
    }
    if lines.next_nonblank().is_some() {
        let found = header.points.saturating_add(1 + lines.count_nonblank() as u64);
        return Err(Error::at(
            Format::Pcd,
            Position::Line(lines.line()),
            ErrorKind::CountMismatch { what: "points", declared: header.points, found },
        ));
    }
    let rows = row_lines.len();
    Ok((Table { columns, rows }, RowPositions::Lines(row_lines)))
}

// ---------------------------------------------------------------------------------------------
// Writing

/// The records written: the pixels of a cloud organised in at least two rows, else the points.
struct Records<'a> {
    cloud: &'a PointCloud,
    width: usize,
    height: usize,
    organised: bool,
}

impl Records<'_> {
    fn of(cloud: &PointCloud) -> Records<'_> {
        match cloud.grid() {
            Some(g) if g.height() > 1 => Records {
                cloud,
                width: g.width() as usize,
                height: g.height() as usize,
                organised: true,
            },
            _ => Records { cloud, width: cloud.len(), height: 1, organised: false },
        }
    }

    fn count(&self) -> usize {
        self.width * self.height
    }

    fn point(&self, row: usize) -> Option<usize> {
        if self.organised { row_point(self.cloud, row) } else { Some(row) }
    }
}

/// Whether an ASCII column is PCL's packed `rgb` float, written as `U 4` bits.
fn ascii_packed(column: &OutColumn<'_>, encoding: PcdEncoding) -> bool {
    encoding == PcdEncoding::Ascii && column.name == "rgb" && column.ty == ScalarType::F32
}

fn type_letter(ty: ScalarType) -> char {
    match ty {
        ScalarType::F32 | ScalarType::F64 => 'F',
        ScalarType::I8 | ScalarType::I16 | ScalarType::I32 | ScalarType::I64 => 'I',
        ScalarType::U8 | ScalarType::U16 | ScalarType::U32 | ScalarType::U64 => 'U',
    }
}

fn write_header(
    w: &mut impl Write,
    cloud: &PointCloud,
    columns: &[OutColumn<'_>],
    records: &Records<'_>,
    encoding: PcdEncoding,
) -> std::io::Result<()> {
    let list =
        |f: &dyn Fn(&OutColumn<'_>) -> String| columns.iter().map(f).collect::<Vec<_>>().join(" ");
    writeln!(w, "# .PCD v0.7 - Point Cloud Data file format")?;
    writeln!(w, "VERSION 0.7")?;
    writeln!(w, "FIELDS {}", list(&|c| c.name.to_owned()))?;
    writeln!(w, "SIZE {}", list(&|c| c.ty.size().to_string()))?;
    let letter = |c: &OutColumn<'_>| {
        if ascii_packed(c, encoding) { 'U' } else { type_letter(c.ty) }.to_string()
    };
    writeln!(w, "TYPE {}", list(&letter))?;
    writeln!(w, "COUNT {}", list(&|_| "1".to_owned()))?;
    writeln!(w, "WIDTH {}", records.width)?;
    writeln!(w, "HEIGHT {}", records.height)?;
    let mut viewpoint = String::from("VIEWPOINT");
    let numbers = match cloud.sensor_pose() {
        Some(pose) => {
            let t = pose.world_from_sensor.translation.vector;
            let q = pose.world_from_sensor.rotation.into_inner();
            [t.x, t.y, t.z, q.w, q.i, q.j, q.k]
        }
        None => [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
    };
    for value in numbers {
        viewpoint.push(' ');
        push_f64(&mut viewpoint, value);
    }
    writeln!(w, "{viewpoint}")?;
    writeln!(w, "POINTS {}", records.count())?;
    writeln!(w, "DATA {}", encoding.keyword())
}

fn write_ascii(
    w: &mut impl Write,
    columns: &[OutColumn<'_>],
    records: &Records<'_>,
) -> std::io::Result<()> {
    let packed: Vec<bool> = columns.iter().map(|c| ascii_packed(c, PcdEncoding::Ascii)).collect();
    let mut text = String::new();
    for row in 0..records.count() {
        text.clear();
        let point = records.point(row);
        for (i, column) in columns.iter().enumerate() {
            if i > 0 {
                text.push(' ');
            }
            match column.value(point) {
                Value::F32(x) if packed[i] => {
                    ScalarType::U32.format(Value::Int(x.to_bits().into()), &mut text);
                }
                Value::F64(x) if packed[i] => {
                    // The filler of an invalid pixel.
                    ScalarType::U32.format(Value::Int((x as f32).to_bits().into()), &mut text);
                }
                value => column.ty.format(value, &mut text),
            }
        }
        text.push('\n');
        w.write_all(text.as_bytes())?;
    }
    Ok(())
}

fn write_binary(
    w: &mut impl Write,
    columns: &[OutColumn<'_>],
    records: &Records<'_>,
) -> std::io::Result<()> {
    let mut bytes = Vec::new();
    for row in 0..records.count() {
        bytes.clear();
        let point = records.point(row);
        for column in columns {
            column.ty.encode(column.value(point), false, &mut bytes);
        }
        w.write_all(&bytes)?;
    }
    Ok(())
}

fn write_compressed(
    w: &mut impl Write,
    columns: &[OutColumn<'_>],
    records: &Records<'_>,
) -> Result<(), Error> {
    let record: usize = columns.iter().map(|c| c.ty.size()).sum();
    let mut buffer = Vec::with_capacity(record * records.count());
    for column in columns {
        for row in 0..records.count() {
            column.ty.encode(column.value(records.point(row)), false, &mut buffer);
        }
    }
    let packed = lzf::compress(&buffer);
    let too_large = |what: &str| {
        Error::new(
            Format::Pcd,
            ErrorKind::Unsupported(format!("{what} larger than 4 GiB in binary_compressed data")),
        )
    };
    let compressed = u32::try_from(packed.len()).map_err(|_| too_large("compressed data"))?;
    let uncompressed = u32::try_from(buffer.len()).map_err(|_| too_large("point data"))?;
    let io = |e: std::io::Error| Error::new(Format::Pcd, e);
    w.write_all(&compressed.to_le_bytes()).map_err(io)?;
    w.write_all(&uncompressed.to_le_bytes()).map_err(io)?;
    w.write_all(&packed).map_err(io)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viewpoint_identity_is_no_pose() {
        assert_eq!(pose_from_viewpoint([0., 0., 0., 1., 0., 0., 0.]), Ok(None));
        assert_eq!(pose_from_viewpoint([0., 0., 0., -1., 0., 0., 0.]), Ok(None));
        assert!(pose_from_viewpoint([1., 0., 0., 0., 0., 0., 0.]).is_err());
        let pose = pose_from_viewpoint([1., 2., 3., 0., 1., 0., 0.]).unwrap().unwrap();
        let p = pose.world_from_sensor * crate::Point3::new(0.0, 1.0, 1.0);
        assert!((p - crate::Point3::new(1.0, 1.0, 2.0)).norm() < 1e-12);
        // A quaternion that is not unit is normalised.
        let pose = pose_from_viewpoint([0., 0., 0., 2., 0., 0., 0.1]).unwrap().unwrap();
        assert!((pose.world_from_sensor.rotation.into_inner().norm() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn compressed_layout_skips_padding() {
        let header = Header {
            fields: vec![
                Field { name: "x".into(), ty: ScalarType::F32, count: 1 },
                Field { name: "_".into(), ty: ScalarType::U8, count: 4 },
                Field { name: "h".into(), ty: ScalarType::U16, count: 3 },
            ],
            width: 10,
            height: 1,
            points: 10,
            pose: None,
            data: PcdEncoding::BinaryCompressed,
        };
        assert_eq!(header.record_size(), 4 + 4 + 6);
        assert_eq!(header.packed_size(), 4 + 6);
        let (columns, slots) = layout(&header, 0);
        let names: Vec<_> = columns.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["x", "h_0", "h_1", "h_2"]);
        assert_eq!(slots.len(), 1 + 4 + 3);
        let h1 = &slots[6];
        assert_eq!(h1.column, Some(2));
        assert_eq!(h1.record_offset, 4 + 4 + 2);
        assert_eq!(h1.block_offset, 10 * 4 + 2);
        assert_eq!(h1.block_stride, 6);
    }
}
