//! The ROS `sensor_msgs/PointCloud2` data layout: decoding and encoding, without any bag or
//! serialisation format.
//!
//! A [`PointCloud2`] is the message minus its `header`: `height × width` points of `point_step`
//! bytes, rows `row_step` bytes apart, described by a list of [`PointField`]s (name, byte offset
//! in the point, datatype, count). [`decode`] turns it into a [`PointCloud`]:
//!
//! | field | cloud |
//! |---|---|
//! | `x`, `y`, `z` (`FLOAT32` or `FLOAT64`, required) | positions |
//! | `normal_x`, `normal_y`, `normal_z` (floats) | normals |
//! | `intensity` (or `i`) | intensity (when every value converts to `f32` exactly) |
//! | `ring` | rings (when every value is an integer that fits `u16`) |
//! | `label` | labels (when every value is an integer that fits `u32`) |
//! | anything else (`t`, `time`, `timestamp`, `rgb`, `reflectivity`, …) | an extra field in its stored type |
//!
//! A field with `count` n > 1 becomes n extra fields `name_0` … `name_{n-1}`; a field with
//! `count` 0 is skipped. Bytes no field covers are padding.
//!
//! `height` > 1 makes an organised cloud that stays organised: its [`Grid`] has
//! `width × height` pixels, and a point with a non-finite coordinate is an invalid pixel. With
//! `height` 1 (unorganised), non-finite points are dropped. `is_dense` claims there is no
//! non-finite point: a dense cloud with one is an [`Pc2Error::NotDense`] error.
//!
//! Every size is checked before anything is allocated: the data must hold exactly
//! `row_step × height` bytes, a row must fit `width × point_step` bytes and every field must lie
//! inside the point, so a header that claims 10⁹ points over a few bytes is an error, not an
//! allocation.
//!
//! [`encode`] writes a cloud in a chosen [`Pc2Layout`] (float32 or float64 positions, padding,
//! byte order): the fixtures and the tests use it.

use crate::Vector3;
use crate::io::Precision;
use crate::{AttributeError, FieldData, Grid, INVALID_PIXEL, Point3, PointCloud, ScalarField};

/// `sensor_msgs/PointField` datatype codes.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
#[allow(missing_docs)]
pub enum Datatype {
    Int8 = 1,
    Uint8 = 2,
    Int16 = 3,
    Uint16 = 4,
    Int32 = 5,
    Uint32 = 6,
    Float32 = 7,
    Float64 = 8,
}

impl Datatype {
    /// The datatype of a `PointField` code, if known.
    pub fn from_code(code: u8) -> Option<Datatype> {
        Some(match code {
            1 => Datatype::Int8,
            2 => Datatype::Uint8,
            3 => Datatype::Int16,
            4 => Datatype::Uint16,
            5 => Datatype::Int32,
            6 => Datatype::Uint32,
            7 => Datatype::Float32,
            8 => Datatype::Float64,
            _ => return None,
        })
    }

    /// The `PointField` code.
    pub fn code(self) -> u8 {
        self as u8
    }

    /// Bytes per value.
    pub fn size(self) -> usize {
        match self {
            Datatype::Int8 | Datatype::Uint8 => 1,
            Datatype::Int16 | Datatype::Uint16 => 2,
            Datatype::Int32 | Datatype::Uint32 | Datatype::Float32 => 4,
            Datatype::Float64 => 8,
        }
    }

    fn of_field(data: &FieldData) -> Datatype {
        match data {
            FieldData::I8(_) => Datatype::Int8,
            FieldData::U8(_) => Datatype::Uint8,
            FieldData::I16(_) => Datatype::Int16,
            FieldData::U16(_) => Datatype::Uint16,
            FieldData::I32(_) => Datatype::Int32,
            FieldData::U32(_) => Datatype::Uint32,
            FieldData::F32(_) => Datatype::Float32,
            FieldData::F64(_) => Datatype::Float64,
        }
    }

    fn is_float(self) -> bool {
        matches!(self, Datatype::Float32 | Datatype::Float64)
    }
}

/// One `sensor_msgs/PointField`: where a named value lies in a point.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PointField {
    /// The field name (`x`, `intensity`, `ring`, …).
    pub name: String,
    /// Byte offset from the start of the point.
    pub offset: u32,
    /// The datatype code (see [`Datatype`]); unknown codes are kept so the error can name them.
    pub datatype: u8,
    /// The number of values.
    pub count: u32,
}

/// A `sensor_msgs/PointCloud2` without its `header`.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct PointCloud2 {
    /// Rows; 1 for an unorganised cloud.
    pub height: u32,
    /// Points per row.
    pub width: u32,
    /// The layout of a point.
    pub fields: Vec<PointField>,
    /// Whether multi-byte values are big-endian.
    pub is_bigendian: bool,
    /// Bytes per point.
    pub point_step: u32,
    /// Bytes per row.
    pub row_step: u32,
    /// `row_step × height` bytes.
    pub data: Vec<u8>,
    /// The message's claim that no point is invalid.
    pub is_dense: bool,
}

/// Why a `PointCloud2` could not be decoded or encoded.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Pc2Error {
    /// A required field is absent.
    #[error("no field `{field}`")]
    MissingField {
        /// The missing field.
        field: String,
    },
    /// A field's datatype code is not one of 1 to 8.
    #[error("field `{field}` has unknown datatype {datatype}")]
    UnknownDatatype {
        /// The field.
        field: String,
        /// Its datatype code.
        datatype: u8,
    },
    /// A field has a datatype it cannot have (`x`, `y`, `z` and normals must be floats).
    #[error("field `{field}` must be FLOAT32 or FLOAT64, not datatype {datatype}")]
    WrongDatatype {
        /// The field.
        field: String,
        /// Its datatype code.
        datatype: u8,
    },
    /// A field reaches beyond `point_step`.
    #[error(
        "field `{field}` at offset {offset} needs {bytes} bytes, beyond point_step {point_step}"
    )]
    FieldOutsidePoint {
        /// The field.
        field: String,
        /// Its offset.
        offset: u32,
        /// Its size in bytes (datatype size × count).
        bytes: u64,
        /// The point step.
        point_step: u32,
    },
    /// A field name appears twice.
    #[error("field `{field}` appears twice")]
    DuplicateField {
        /// The field.
        field: String,
    },
    /// `row_step` is smaller than `width × point_step`.
    #[error("row_step {row_step} is less than width {width} × point_step {point_step}")]
    RowStep {
        /// The row step.
        row_step: u32,
        /// The width.
        width: u32,
        /// The point step.
        point_step: u32,
    },
    /// The data do not hold `row_step × height` bytes.
    #[error("data has {found} bytes, but row_step {row_step} × height {height} needs {expected}")]
    DataLength {
        /// Bytes needed.
        expected: u64,
        /// Bytes present.
        found: u64,
        /// The row step.
        row_step: u32,
        /// The height.
        height: u32,
    },
    /// `is_dense` is set but a point has a non-finite coordinate.
    #[error("is_dense is set but point {point} (row {row}, column {col}) is not finite")]
    NotDense {
        /// The point's index in the message (row-major).
        point: u64,
        /// Its row.
        row: u32,
        /// Its column.
        col: u32,
    },
    /// The decoded values do not form a valid cloud.
    #[error(transparent)]
    Attribute(#[from] AttributeError),
}

/// A resolved field: where its values are and how to read them.
#[derive(Clone, Debug)]
struct Slot {
    name: String,
    offset: usize,
    datatype: Datatype,
}

/// The fields of a message, validated against `point_step`.
fn resolve_fields(msg: &PointCloud2) -> Result<Vec<Slot>, Pc2Error> {
    let mut slots: Vec<Slot> = Vec::new();
    for f in &msg.fields {
        if msg.fields.iter().filter(|g| g.name == f.name).count() > 1 {
            return Err(Pc2Error::DuplicateField { field: f.name.clone() });
        }
        let datatype = Datatype::from_code(f.datatype)
            .ok_or(Pc2Error::UnknownDatatype { field: f.name.clone(), datatype: f.datatype })?;
        let bytes = datatype.size() as u64 * f.count as u64;
        if f.offset as u64 + bytes > msg.point_step as u64 {
            return Err(Pc2Error::FieldOutsidePoint {
                field: f.name.clone(),
                offset: f.offset,
                bytes,
                point_step: msg.point_step,
            });
        }
        match f.count {
            0 => {}
            1 => slots.push(Slot { name: f.name.clone(), offset: f.offset as usize, datatype }),
            n => {
                for k in 0..n {
                    slots.push(Slot {
                        name: format!("{}_{k}", f.name),
                        offset: f.offset as usize + k as usize * datatype.size(),
                        datatype,
                    });
                }
            }
        }
    }
    Ok(slots)
}

fn take_float(slots: &mut Vec<Slot>, name: &str) -> Result<Option<Slot>, Pc2Error> {
    let Some(i) = slots.iter().position(|s| s.name == name) else { return Ok(None) };
    let slot = slots.remove(i);
    if !slot.datatype.is_float() {
        return Err(Pc2Error::WrongDatatype {
            field: name.to_owned(),
            datatype: slot.datatype.code(),
        });
    }
    Ok(Some(slot))
}

fn read_f64(point: &[u8], slot: &Slot, big: bool) -> f64 {
    macro_rules! get {
        ($t:ty, $n:expr) => {{
            let mut b = [0u8; $n];
            b.copy_from_slice(&point[slot.offset..slot.offset + $n]);
            if big { <$t>::from_be_bytes(b) } else { <$t>::from_le_bytes(b) }
        }};
    }
    match slot.datatype {
        Datatype::Int8 => point[slot.offset] as i8 as f64,
        Datatype::Uint8 => point[slot.offset] as f64,
        Datatype::Int16 => get!(i16, 2) as f64,
        Datatype::Uint16 => get!(u16, 2) as f64,
        Datatype::Int32 => get!(i32, 4) as f64,
        Datatype::Uint32 => get!(u32, 4) as f64,
        Datatype::Float32 => get!(f32, 4) as f64,
        Datatype::Float64 => get!(f64, 8),
    }
}

fn empty_data(datatype: Datatype, capacity: usize) -> FieldData {
    match datatype {
        Datatype::Int8 => FieldData::I8(Vec::with_capacity(capacity)),
        Datatype::Uint8 => FieldData::U8(Vec::with_capacity(capacity)),
        Datatype::Int16 => FieldData::I16(Vec::with_capacity(capacity)),
        Datatype::Uint16 => FieldData::U16(Vec::with_capacity(capacity)),
        Datatype::Int32 => FieldData::I32(Vec::with_capacity(capacity)),
        Datatype::Uint32 => FieldData::U32(Vec::with_capacity(capacity)),
        Datatype::Float32 => FieldData::F32(Vec::with_capacity(capacity)),
        Datatype::Float64 => FieldData::F64(Vec::with_capacity(capacity)),
    }
}

/// Appends the value of `slot` in `point` to `data` in its stored type (bit for bit).
fn push_raw(data: &mut FieldData, point: &[u8], slot: &Slot, big: bool) {
    macro_rules! get {
        ($t:ty, $n:expr) => {{
            let mut b = [0u8; $n];
            b.copy_from_slice(&point[slot.offset..slot.offset + $n]);
            if big { <$t>::from_be_bytes(b) } else { <$t>::from_le_bytes(b) }
        }};
    }
    match data {
        FieldData::I8(v) => v.push(point[slot.offset] as i8),
        FieldData::U8(v) => v.push(point[slot.offset]),
        FieldData::I16(v) => v.push(get!(i16, 2)),
        FieldData::U16(v) => v.push(get!(u16, 2)),
        FieldData::I32(v) => v.push(get!(i32, 4)),
        FieldData::U32(v) => v.push(get!(u32, 4)),
        FieldData::F32(v) => v.push(get!(f32, 4)),
        FieldData::F64(v) => v.push(get!(f64, 8)),
    }
}

/// Checks the sizes of `msg` against its data; returns the number of points.
fn check_sizes(msg: &PointCloud2) -> Result<usize, Pc2Error> {
    let row_bytes = msg.width as u64 * msg.point_step as u64;
    if (msg.row_step as u64) < row_bytes {
        return Err(Pc2Error::RowStep {
            row_step: msg.row_step,
            width: msg.width,
            point_step: msg.point_step,
        });
    }
    let expected = msg.row_step as u64 * msg.height as u64;
    if msg.data.len() as u64 != expected {
        return Err(Pc2Error::DataLength {
            expected,
            found: msg.data.len() as u64,
            row_step: msg.row_step,
            height: msg.height,
        });
    }
    // Each point has `point_step` > 0 bytes present (a zero step with points has no x field
    // inside it and fails in `resolve_fields`), so this count is bounded by the data.
    Ok(msg.width as usize * msg.height as usize)
}

/// Decodes a `PointCloud2` (see the [module documentation](self) for the mapping).
///
/// # Errors
/// A [`Pc2Error`] naming the field or the size that is wrong; never a panic.
pub fn decode(msg: &PointCloud2) -> Result<PointCloud, Pc2Error> {
    let mut slots = resolve_fields(msg)?;
    let mut xyz = Vec::with_capacity(3);
    for name in ["x", "y", "z"] {
        xyz.push(
            take_float(&mut slots, name)?.ok_or(Pc2Error::MissingField { field: name.into() })?,
        );
    }
    let n_points = check_sizes(msg)?;
    let normals = match (
        take_float(&mut slots, "normal_x")?,
        take_float(&mut slots, "normal_y")?,
        take_float(&mut slots, "normal_z")?,
    ) {
        (Some(a), Some(b), Some(c)) => Some([a, b, c]),
        (a, b, c) => {
            // An incomplete triple stays as extra fields.
            slots.extend([a, b, c].into_iter().flatten());
            None
        }
    };
    let big = msg.is_bigendian;
    let organised = msg.height > 1;

    let mut positions = Vec::with_capacity(n_points);
    let mut pixels = Vec::with_capacity(if organised { n_points } else { 0 });
    let mut normal_values = Vec::new();
    let mut extras: Vec<FieldData> = slots.iter().map(|s| empty_data(s.datatype, 0)).collect();
    for row in 0..msg.height {
        let row_data = &msg.data[row as usize * msg.row_step as usize..];
        for col in 0..msg.width {
            let start = col as usize * msg.point_step as usize;
            let point = &row_data[start..start + msg.point_step as usize];
            let p = Point3::new(
                read_f64(point, &xyz[0], big),
                read_f64(point, &xyz[1], big),
                read_f64(point, &xyz[2], big),
            );
            if !p.coords.iter().all(|v| v.is_finite()) {
                if msg.is_dense {
                    let point = row as u64 * msg.width as u64 + col as u64;
                    return Err(Pc2Error::NotDense { point, row, col });
                }
                if organised {
                    pixels.push(INVALID_PIXEL);
                }
                continue;
            }
            if organised {
                pixels.push(positions.len() as u32);
            }
            positions.push(p);
            if let Some(ns) = &normals {
                normal_values.push(Vector3::new(
                    read_f64(point, &ns[0], big),
                    read_f64(point, &ns[1], big),
                    read_f64(point, &ns[2], big),
                ));
            }
            for (data, slot) in extras.iter_mut().zip(&slots) {
                push_raw(data, point, slot, big);
            }
        }
    }

    let mut cloud = PointCloud::from_positions(positions)?;
    if normals.is_some() {
        cloud.set_normals(Some(normal_values))?;
    }
    for (slot, data) in slots.into_iter().zip(extras) {
        let n = data.len();
        let values = || (0..n).map(|i| data.get_f64(i).unwrap_or(f64::NAN));
        let integral =
            |max: f64| !slot.datatype.is_float() && values().all(|v| (0.0..=max).contains(&v));
        match slot.name.as_str() {
            "intensity" | "i"
                if cloud.intensity().is_none()
                    && values().all(|v| v.is_nan() || (v as f32) as f64 == v) =>
            {
                cloud.set_intensity(Some(values().map(|v| v as f32).collect()))?;
            }
            "ring" if integral(u16::MAX as f64) => {
                cloud.set_rings(Some(values().map(|v| v as u16).collect()))?;
            }
            "label" if integral(u32::MAX as f64) => {
                cloud.set_labels(Some(values().map(|v| v as u32).collect()))?;
            }
            _ => cloud.push_extra_field(ScalarField { name: slot.name, data })?,
        }
    }
    if organised {
        let grid = Grid::new(msg.width, msg.height, pixels, cloud.len())?;
        cloud.set_grid(Some(grid))?;
    }
    Ok(cloud)
}

/// How [`encode`] lays out a point.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct Pc2Layout {
    /// `FLOAT32` or `FLOAT64` positions and normals.
    pub precision: Precision,
    /// Unused bytes after every field.
    pub padding: u32,
    /// Unused bytes at the end of every row.
    pub row_padding: u32,
    /// Big-endian values.
    pub big_endian: bool,
    /// The position fields after the other fields instead of first.
    pub positions_last: bool,
}

impl Default for Pc2Layout {
    /// `FLOAT32` x, y, z first, no padding, little-endian: what most drivers publish.
    fn default() -> Pc2Layout {
        Pc2Layout {
            precision: Precision::F32,
            padding: 0,
            row_padding: 0,
            big_endian: false,
            positions_last: false,
        }
    }
}

/// What one encoded field holds.
enum Source<'a> {
    Position(usize),
    Normal(usize),
    Intensity(&'a [f32]),
    Ring(&'a [u16]),
    Label(&'a [u32]),
    Extra(&'a FieldData),
}

/// Encodes `cloud` as a `PointCloud2` in `layout`.
///
/// An organised cloud keeps its image (`height` rows) with NaN positions (and zero attributes)
/// at invalid pixels and `is_dense` false; an unorganised one is a single row with `is_dense`
/// true. Attributes: normals as `normal_x/y/z`, intensity `FLOAT32`, ring `UINT16`, label
/// `UINT32`, extra fields in their stored type.
///
/// # Errors
/// [`Pc2Error::DataLength`] when the message would exceed `u32` sizes.
pub fn encode(cloud: &PointCloud, layout: &Pc2Layout) -> Result<PointCloud2, Pc2Error> {
    let float = match layout.precision {
        Precision::F32 => Datatype::Float32,
        Precision::F64 => Datatype::Float64,
    };
    let mut position_fields = vec![
        ("x".to_owned(), float, Source::Position(0)),
        ("y".to_owned(), float, Source::Position(1)),
        ("z".to_owned(), float, Source::Position(2)),
    ];
    let mut fields = Vec::new();
    if cloud.normals().is_some() {
        for (k, n) in ["normal_x", "normal_y", "normal_z"].into_iter().enumerate() {
            fields.push((n.to_owned(), float, Source::Normal(k)));
        }
    }
    if let Some(v) = cloud.intensity() {
        fields.push(("intensity".into(), Datatype::Float32, Source::Intensity(v)));
    }
    if let Some(v) = cloud.rings() {
        fields.push(("ring".into(), Datatype::Uint16, Source::Ring(v)));
    }
    if let Some(v) = cloud.labels() {
        fields.push(("label".into(), Datatype::Uint32, Source::Label(v)));
    }
    for f in cloud.extra_fields() {
        fields.push((f.name.clone(), Datatype::of_field(&f.data), Source::Extra(&f.data)));
    }
    if layout.positions_last {
        fields.append(&mut position_fields);
    } else {
        position_fields.append(&mut fields);
        fields = position_fields;
    }
    let mut point_fields = Vec::with_capacity(fields.len());
    let mut offset = 0u64;
    for (name, datatype, _) in &fields {
        point_fields.push(PointField {
            name: name.clone(),
            offset: offset as u32,
            datatype: datatype.code(),
            count: 1,
        });
        offset += datatype.size() as u64 + layout.padding as u64;
    }
    let point_step = offset;
    let (width, height) = match cloud.grid() {
        Some(g) => (g.width() as u64, g.height() as u64),
        None => (cloud.len() as u64, 1),
    };
    let row_step = width * point_step + layout.row_padding as u64;
    let too_big = || Pc2Error::DataLength {
        expected: row_step.saturating_mul(height),
        found: 0,
        row_step: u32::MAX,
        height: height as u32,
    };
    if point_step > u32::MAX as u64 || row_step > u32::MAX as u64 || width > u32::MAX as u64 {
        return Err(too_big());
    }
    let mut data = vec![0u8; (row_step * height) as usize];
    let big = layout.big_endian;
    let put = |out: &mut [u8], datatype: Datatype, v: f64, raw: Option<(&FieldData, usize)>| {
        macro_rules! w {
            ($x:expr) => {{
                let b = if big { $x.to_be_bytes() } else { $x.to_le_bytes() };
                out[..b.len()].copy_from_slice(&b);
            }};
        }
        if let Some((d, i)) = raw {
            match d {
                FieldData::I8(x) => w!(x[i]),
                FieldData::U8(x) => w!(x[i]),
                FieldData::I16(x) => w!(x[i]),
                FieldData::U16(x) => w!(x[i]),
                FieldData::I32(x) => w!(x[i]),
                FieldData::U32(x) => w!(x[i]),
                FieldData::F32(x) => w!(x[i]),
                FieldData::F64(x) => w!(x[i]),
            }
            return;
        }
        match datatype {
            Datatype::Float32 => w!(v as f32),
            Datatype::Float64 => w!(v),
            Datatype::Uint16 => w!(v as u16),
            Datatype::Uint32 => w!(v as u32),
            _ => unreachable!("only floats, rings and labels are written from f64"),
        }
    };
    let point_of_pixel = |pixel: usize| -> Option<usize> {
        match cloud.grid() {
            Some(g) => {
                let p = g.pixels()[pixel];
                (p != INVALID_PIXEL).then_some(p as usize)
            }
            None => Some(pixel),
        }
    };
    for row in 0..height as usize {
        for col in 0..width as usize {
            let base = row * row_step as usize + col * point_step as usize;
            let index = point_of_pixel(row * width as usize + col);
            for (field, (_, datatype, source)) in point_fields.iter().zip(&fields) {
                let out = &mut data[base + field.offset as usize..];
                let Some(i) = index else {
                    if datatype.is_float() {
                        put(out, *datatype, f64::NAN, None);
                    }
                    continue;
                };
                match source {
                    Source::Position(k) => put(out, *datatype, cloud.positions()[i][*k], None),
                    Source::Normal(k) => put(out, *datatype, cloud.normals().unwrap()[i][*k], None),
                    Source::Intensity(v) => put(out, *datatype, v[i] as f64, None),
                    Source::Ring(v) => put(out, *datatype, v[i] as f64, None),
                    Source::Label(v) => put(out, *datatype, v[i] as f64, None),
                    Source::Extra(d) => put(out, *datatype, 0.0, Some((d, i))),
                }
            }
        }
    }
    Ok(PointCloud2 {
        height: height as u32,
        width: width as u32,
        fields: point_fields,
        is_bigendian: big,
        point_step: point_step as u32,
        row_step: row_step as u32,
        data,
        is_dense: cloud.grid().is_none_or(|g| g.num_valid() == g.num_pixels()),
    })
}
