//! KITTI / Ouster style `.bin` point files: headerless little-endian `float32` records
//! `x y z intensity` (16 bytes per point), metres, sensor frame (x forward, y left, z up).
//!
//! # Layouts
//! * [`KittiLayout::Unorganized`] (KITTI Velodyne): the records are a list of points.
//! * [`KittiLayout::ColumnMajor`] (Ouster, e.g. RELLIS-3D): the records are a `rings × columns`
//!   image stored column by column: record `column * rings + ring`, ring 0 the highest beam.
//!   The cloud is organised ([`Grid`] of `rings` rows × `columns` columns, row 0 =
//!   ring 0), points in row-major pixel order, with [`PointCloud::rings`] set.
//!
//! # Missing returns
//! With [`KittiReadOptions::zero_is_invalid`], a record whose x, y and z are all zero means "no
//! return" (what Ouster drivers write): it becomes an invalid pixel of an organised cloud, and is
//! dropped from an unorganised one. A record with a NaN or infinite coordinate is an invalid
//! pixel of an organised cloud; in an unorganised cloud it fails with
//! [`ErrorKind::NonFinite`] unless [`ReadOptions::skip_non_finite`] (in
//! [`KittiReadOptions::non_finite`]) drops it.
//!
//! # Writing
//! [`write_kitti_bin`] writes one record per point in point order, intensity 0 when the cloud
//! has none, positions rounded to `f32` (a coordinate beyond the `f32` range is an error).
//! An *organised* cloud is written column-major as above, one record per pixel with zeros for
//! invalid pixels, so that [`KittiLayout::ColumnMajor`] with `rings` = the grid height and
//! `zero_is_invalid` reads it back. (A valid point exactly at the origin would then read back
//! as invalid; real sensors do not measure such points.)

use super::{Error, ErrorKind, Format, Position, ReadOptions};
use crate::{Grid, INVALID_PIXEL, Point3, PointCloud};
use std::io::{Read, Write};

const FORMAT: Format = Format::KittiBin;
/// Bytes per record: four little-endian `f32`.
pub const RECORD_BYTES: usize = 16;

/// How the records of a `.bin` file are arranged.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Default)]
pub enum KittiLayout {
    /// A plain list of points (KITTI Velodyne scans).
    #[default]
    Unorganized,
    /// A `rings × columns` image stored column by column: record `column * rings + ring`, ring 0
    /// the highest beam (Ouster scans such as RELLIS-3D's, with `rings` = 64).
    ColumnMajor {
        /// The number of rings (laser channels, image rows).
        rings: u32,
    },
}

/// Options for [`read_kitti_bin`].
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct KittiReadOptions {
    /// How the records are arranged.
    pub layout: KittiLayout,
    /// Whether a record with x = y = z = 0 means "no return" (dropped, or an invalid pixel).
    pub zero_is_invalid: bool,
    /// What to do with non-finite records of an unorganised file.
    pub non_finite: ReadOptions,
}

impl Default for KittiReadOptions {
    /// Unorganised, all-zero records are "no return", non-finite records are an error.
    fn default() -> KittiReadOptions {
        KittiReadOptions {
            layout: KittiLayout::Unorganized,
            zero_is_invalid: true,
            non_finite: ReadOptions::STRICT,
        }
    }
}

impl KittiReadOptions {
    /// An Ouster scan with `rings` beams (column-major, zeros are "no return").
    pub fn ouster(rings: u32) -> KittiReadOptions {
        KittiReadOptions { layout: KittiLayout::ColumnMajor { rings }, ..Default::default() }
    }
}

fn record(bytes: &[u8]) -> [f32; 4] {
    let f = |k: usize| {
        f32::from_le_bytes([bytes[4 * k], bytes[4 * k + 1], bytes[4 * k + 2], bytes[4 * k + 3]])
    };
    [f(0), f(1), f(2), f(3)]
}

/// Reads a KITTI / Ouster `.bin` file (see the [module docs](self)).
///
/// Fails if the length is not a whole number of 16-byte records (naming the byte where the
/// incomplete record starts), or, for [`KittiLayout::ColumnMajor`], if `rings` is 0, above
/// 65 536, or does not divide the number of records.
pub fn read_kitti_bin(
    mut reader: impl Read,
    options: &KittiReadOptions,
) -> Result<PointCloud, Error> {
    let mut data = Vec::new();
    reader
        .read_to_end(&mut data)
        .map_err(|e| Error::at(FORMAT, Position::Byte(data.len() as u64), e))?;
    let whole = data.len() - data.len() % RECORD_BYTES;
    if whole != data.len() {
        return Err(Error::at(
            FORMAT,
            Position::Byte(whole as u64),
            ErrorKind::UnexpectedEof {
                expected: format!(
                    "a whole {RECORD_BYTES}-byte record (the file has {} bytes, {} past the last whole record)",
                    data.len(),
                    data.len() - whole
                ),
            },
        ));
    }
    let records = data.chunks_exact(RECORD_BYTES);
    let n = records.len();
    let is_missing =
        |r: &[f32; 4]| options.zero_is_invalid && r[0] == 0.0 && r[1] == 0.0 && r[2] == 0.0;
    let cloud_err = |e| Error::new(FORMAT, e);
    match options.layout {
        KittiLayout::Unorganized => {
            let mut positions = Vec::with_capacity(n);
            let mut intensity = Vec::with_capacity(n);
            for (k, bytes) in records.enumerate() {
                let r = record(bytes);
                if !(r[0].is_finite() && r[1].is_finite() && r[2].is_finite()) {
                    if options.non_finite.skip_non_finite {
                        continue;
                    }
                    return Err(Error::at(
                        FORMAT,
                        Position::Byte((k * RECORD_BYTES) as u64),
                        ErrorKind::NonFinite { point: k as u64 },
                    ));
                }
                if is_missing(&r) {
                    continue;
                }
                positions.push(Point3::new(r[0] as f64, r[1] as f64, r[2] as f64));
                intensity.push(r[3]);
            }
            let mut cloud = PointCloud::from_positions(positions).map_err(cloud_err)?;
            cloud.set_intensity(Some(intensity)).map_err(cloud_err)?;
            Ok(cloud)
        }
        KittiLayout::ColumnMajor { rings } => {
            if rings == 0 || rings > u16::MAX as u32 + 1 {
                return Err(Error::new(
                    FORMAT,
                    ErrorKind::BadValue(format!("{rings} rings: expected 1 to 65536")),
                ));
            }
            let rings_us = rings as usize;
            if n % rings_us != 0 {
                return Err(Error::at(
                    FORMAT,
                    Position::Byte(((n - n % rings_us) * RECORD_BYTES) as u64),
                    ErrorKind::BadValue(format!(
                        "{n} records are not a whole number of columns of {rings} rings"
                    )),
                ));
            }
            let columns = n / rings_us;
            let columns_u32 = u32::try_from(columns).map_err(|_| {
                Error::new(FORMAT, ErrorKind::Unsupported(format!("{columns} columns")))
            })?;
            if n >= INVALID_PIXEL as usize {
                return Err(Error::new(
                    FORMAT,
                    ErrorKind::Unsupported(format!("{n} records: too many for one image")),
                ));
            }
            let mut positions = Vec::with_capacity(n);
            let mut intensity = Vec::with_capacity(n);
            let mut ring_of = Vec::with_capacity(n);
            let mut pixels = Vec::with_capacity(n);
            for ring in 0..rings_us {
                for col in 0..columns {
                    let k = col * rings_us + ring;
                    let r = record(&data[k * RECORD_BYTES..(k + 1) * RECORD_BYTES]);
                    let finite = r[0].is_finite() && r[1].is_finite() && r[2].is_finite();
                    if !finite || is_missing(&r) {
                        pixels.push(INVALID_PIXEL);
                        continue;
                    }
                    pixels.push(positions.len() as u32);
                    positions.push(Point3::new(r[0] as f64, r[1] as f64, r[2] as f64));
                    intensity.push(r[3]);
                    ring_of.push(ring as u16);
                }
            }
            let mut cloud = PointCloud::from_positions(positions).map_err(cloud_err)?;
            let grid = Grid::new(columns_u32, rings, pixels, cloud.len()).map_err(cloud_err)?;
            cloud.set_intensity(Some(intensity)).map_err(cloud_err)?;
            cloud.set_rings(Some(ring_of)).map_err(cloud_err)?;
            cloud.set_grid(Some(grid)).map_err(cloud_err)?;
            Ok(cloud)
        }
    }
}

fn to_f32(v: f64, point: usize) -> Result<f32, Error> {
    let f = v as f32;
    if f.is_finite() {
        Ok(f)
    } else {
        Err(Error::new(
            FORMAT,
            ErrorKind::BadValue(format!("point {point}: coordinate {v} is beyond the f32 range")),
        ))
    }
}

/// Writes `cloud` as a `.bin` file: float32 `x y z intensity` records (intensity 0 when the
/// cloud has none). Unorganised clouds are written point by point; organised clouds column by
/// column, one record per pixel, zeros for invalid pixels (see the [module docs](self)).
pub fn write_kitti_bin(writer: impl Write, cloud: &PointCloud) -> Result<(), Error> {
    let mut w = std::io::BufWriter::new(writer);
    let io = |e: std::io::Error| Error::new(FORMAT, e);
    let intensity = cloud.intensity();
    let put = |w: &mut std::io::BufWriter<_>, point: Option<usize>| -> Result<(), Error> {
        let mut buf = [0u8; RECORD_BYTES];
        if let Some(k) = point {
            let p = cloud.positions()[k];
            let vals = [
                to_f32(p.x, k)?,
                to_f32(p.y, k)?,
                to_f32(p.z, k)?,
                intensity.map_or(0.0, |i| i[k]),
            ];
            for (j, v) in vals.iter().enumerate() {
                buf[4 * j..4 * j + 4].copy_from_slice(&v.to_le_bytes());
            }
        }
        w.write_all(&buf).map_err(io)
    };
    match cloud.grid() {
        None => {
            for k in 0..cloud.len() {
                put(&mut w, Some(k))?;
            }
        }
        Some(g) => {
            for col in 0..g.width() {
                for row in 0..g.height() {
                    put(&mut w, g.point_index(col, row))?;
                }
            }
        }
    }
    w.flush().map_err(io)
}
