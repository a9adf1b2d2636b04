//! 16-bit grayscale PNG depth (or range) images, and the small JSON files that give their
//! pinhole intrinsics.
//!
//! A pixel value `v` means `v × depth_scale` metres; `0` means "no measurement". The value is
//! the z coordinate in the camera's optical frame (x right, y down, z forward) for depth images
//! ([`RangeKind::Depth`], what Kinect / OpenNI / TUM depth PNGs store), or the distance along the
//! beam for radial images ([`RangeKind::Radial`], e.g. the ifm O3R's `radial_distance` image:
//! read it with [`read_range_png`]). Common scales:
//!
//! | data | depth_scale (m per unit) | camera |
//! |---|---|---|
//! | TUM RGB-D | 1/5000 | [`DepthCamera::tum_kinect`] |
//! | OpenNI / PCL (mm) | 0.001 | [`DepthCamera::openni_mm`] |
//! | ifm O3R radial distance | 0.00015259021893143654 | its own intrinsics, [`RangeKind::Radial`] |
//!
//! Reading rejects PNGs that are not 16-bit single-channel grayscale with
//! [`ErrorKind::Unsupported`], and maps every decoding failure of the `png` crate (truncated,
//! corrupt, bad checksum) into an [`Error`] whose byte position is how far the decoder had read
//! when it failed. Headers declaring more pixels than the file could possibly hold (beyond the
//! deflate limit of about 1032 : 1) are refused before memory is reserved.

use super::{Error, ErrorKind, Format, Position};
use crate::{BeamModel, PinholeIntrinsics, RangeImage, RangeKind};
use std::io::{Cursor, Read, Write};

const FORMAT: Format = Format::DepthPng;

/// A depth camera: pinhole intrinsics and the metres per PNG unit.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct DepthCamera {
    /// Pinhole intrinsics of the depth image.
    pub intrinsics: PinholeIntrinsics,
    /// Metres per unit of the 16-bit pixel values.
    pub depth_scale: f64,
}

impl DepthCamera {
    /// The TUM RGB-D default for a Kinect v1 of unknown calibration: fx = fy = 525,
    /// cx = 319.5, cy = 239.5, 5000 units per metre.
    pub fn tum_kinect() -> DepthCamera {
        DepthCamera {
            intrinsics: PinholeIntrinsics { fx: 525.0, fy: 525.0, cx: 319.5, cy: 239.5 },
            depth_scale: 1.0 / 5000.0,
        }
    }

    /// The OpenNI default for Kinect v1 / PrimeSense class cameras: fx = fy = 525, cx = 320,
    /// cy = 240, millimetres.
    pub fn openni_mm() -> DepthCamera {
        DepthCamera {
            intrinsics: PinholeIntrinsics { fx: 525.0, fy: 525.0, cx: 320.0, cy: 240.0 },
            depth_scale: 0.001,
        }
    }
}

fn check_scale(depth_scale: f64) -> Result<(), Error> {
    if depth_scale.is_finite() && depth_scale > 0.0 {
        Ok(())
    } else {
        Err(Error::new(
            FORMAT,
            ErrorKind::BadValue(format!("depth scale {depth_scale} is not a positive number")),
        ))
    }
}

/// Reads a 16-bit grayscale PNG depth image (z in the optical frame, `0` = no measurement) as a
/// [`RangeImage`] with [`RangeKind::Depth`] and the camera's pinhole model.
pub fn read_depth_png(reader: impl Read, camera: &DepthCamera) -> Result<RangeImage, Error> {
    read_range_png(reader, camera, RangeKind::Depth)
}

/// Reads a 16-bit grayscale PNG range image whose values measure `kind`: z depth, or the radial
/// distance along each pixel's beam. `0` = no measurement.
pub fn read_range_png(
    mut reader: impl Read,
    camera: &DepthCamera,
    kind: RangeKind,
) -> Result<RangeImage, Error> {
    check_scale(camera.depth_scale)?;
    let mut data = Vec::new();
    reader
        .read_to_end(&mut data)
        .map_err(|e| Error::at(FORMAT, Position::Byte(data.len() as u64), e))?;
    let (width, height, values) = decode_u16_gray(&data)?;
    let scale = camera.depth_scale;
    let ranges =
        values.iter().map(|&v| (v != 0).then_some((v as f64 * scale) as f32)).collect::<Vec<_>>();
    RangeImage::new(width, height, BeamModel::Pinhole(camera.intrinsics), kind, ranges)
        .map_err(|e| Error::new(FORMAT, ErrorKind::BadValue(e.to_string())))
}

/// Decodes a 16-bit grayscale PNG into its width, height and row-major values.
pub fn decode_u16_gray(data: &[u8]) -> Result<(u32, u32, Vec<u16>), Error> {
    let mut cursor = Cursor::new(data);
    let result = decode_inner(&mut cursor, data.len());
    result.map_err(|e| match e {
        Decode::Png(e) => png_error(e, cursor.position()),
        Decode::Ours(e) => e,
    })
}

enum Decode {
    Png(png::DecodingError),
    Ours(Error),
}

impl From<png::DecodingError> for Decode {
    fn from(e: png::DecodingError) -> Decode {
        Decode::Png(e)
    }
}

fn decode_inner(
    cursor: &mut Cursor<&[u8]>,
    file_len: usize,
) -> Result<(u32, u32, Vec<u16>), Decode> {
    let mut decoder = png::Decoder::new(&mut *cursor);
    let info = decoder.read_header_info()?;
    let (width, height) = (info.width, info.height);
    if info.color_type != png::ColorType::Grayscale || info.bit_depth != png::BitDepth::Sixteen {
        return Err(Decode::Ours(Error::at(
            FORMAT,
            Position::Byte(24),
            ErrorKind::Unsupported(format!(
                "a {}-bit {:?} PNG: depth images must be 16-bit grayscale",
                info.bit_depth as u8, info.color_type
            )),
        )));
    }
    // Deflate cannot expand data by more than about 1032 : 1; a header that declares more pixel
    // bytes than that is lying, and is refused before anything is reserved.
    let raw = (width as u64 * 2 + 1) * height as u64;
    if raw > 1100 * file_len as u64 + 4096 {
        return Err(Decode::Ours(Error::at(
            FORMAT,
            Position::Byte(16),
            ErrorKind::BadHeader(format!(
                "{width}×{height} pixels cannot fit in a {file_len}-byte file"
            )),
        )));
    }
    let mut reader = decoder.read_info()?;
    let size = reader.output_buffer_size().ok_or_else(|| {
        Decode::Ours(Error::new(FORMAT, ErrorKind::Unsupported("image too large".into())))
    })?;
    let mut buf = vec![0u8; size];
    let out = reader.next_frame(&mut buf)?;
    if out.width != width || out.height != height || out.line_size != width as usize * 2 {
        return Err(Decode::Ours(Error::new(
            FORMAT,
            ErrorKind::Unsupported("an animated PNG whose first frame is not the image".into()),
        )));
    }
    reader.finish()?;
    let values = buf[..out.buffer_size()]
        .chunks_exact(2)
        .map(|b| u16::from_be_bytes([b[0], b[1]]))
        .collect();
    Ok((width, height, values))
}

fn png_error(e: png::DecodingError, position: u64) -> Error {
    let at = Position::Byte(position);
    match e {
        png::DecodingError::IoError(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            Error::at(FORMAT, at, ErrorKind::UnexpectedEof { expected: "more PNG data".into() })
        }
        png::DecodingError::IoError(io) => Error::at(FORMAT, at, io),
        png::DecodingError::LimitsExceeded => Error::at(
            FORMAT,
            at,
            ErrorKind::Unsupported("the PNG needs more memory than the decoder allows".into()),
        ),
        other => Error::at(FORMAT, at, ErrorKind::BadValue(format!("corrupt PNG: {other}"))),
    }
}

/// Writes `image` as a 16-bit grayscale PNG with `depth_scale` metres per unit: each range `r`
/// becomes `round(r / depth_scale)`, pixels without a measurement become `0`.
///
/// The values are written as they are, whatever the image's [`RangeKind`] (the PNG does not
/// record it, nor the intrinsics). A range that does not fit (rounds to more than 65 535, or to
/// 0, which would read back as "no measurement") is an error naming the pixel, never clamped.
pub fn write_depth_png(
    writer: impl Write,
    image: &RangeImage,
    depth_scale: f64,
) -> Result<(), Error> {
    check_scale(depth_scale)?;
    let (width, height) = (image.width(), image.height());
    let mut bytes = Vec::with_capacity(image.ranges().len() * 2);
    for (index, r) in image.ranges().iter().enumerate() {
        let v = match *r {
            None => 0u16,
            Some(r) => {
                let v = (r as f64 / depth_scale).round();
                if !(1.0..=u16::MAX as f64).contains(&v) {
                    let (col, row) = (index % width as usize, index / width as usize);
                    return Err(Error::new(
                        FORMAT,
                        ErrorKind::BadValue(format!(
                            "range {r} m at pixel ({col}, {row}) is {v} units of {depth_scale} m, \
                             outside 1..=65535"
                        )),
                    ));
                }
                v as u16
            }
        };
        bytes.extend_from_slice(&v.to_be_bytes());
    }
    let png_err = |e: png::EncodingError| match e {
        png::EncodingError::IoError(io) => Error::new(FORMAT, io),
        other => Error::new(FORMAT, ErrorKind::BadValue(other.to_string())),
    };
    let mut encoder = png::Encoder::new(writer, width, height);
    encoder.set_color(png::ColorType::Grayscale);
    encoder.set_depth(png::BitDepth::Sixteen);
    let mut w = encoder.write_header().map_err(png_err)?;
    w.write_image_data(&bytes).map_err(png_err)?;
    w.finish().map_err(png_err)
}

/// The contents of an intrinsics JSON file.
#[derive(serde::Deserialize)]
pub(crate) struct IntrinsicsJson {
    pub(crate) fx: f64,
    pub(crate) fy: f64,
    pub(crate) cx: f64,
    pub(crate) cy: f64,
    #[serde(default)]
    pub(crate) width: Option<u32>,
    #[serde(default)]
    pub(crate) height: Option<u32>,
    #[serde(default)]
    pub(crate) depth_scale: Option<f64>,
}

pub(crate) fn parse_intrinsics_json(reader: impl Read) -> Result<IntrinsicsJson, Error> {
    let j: IntrinsicsJson = serde_json::from_reader(reader).map_err(|e| {
        let position = (e.line() > 0).then_some(Position::Line(e.line() as u64));
        let kind = if e.is_io() {
            ErrorKind::Io(e.into())
        } else {
            ErrorKind::BadValue(format!("intrinsics JSON: {e}"))
        };
        Error { format: Some(FORMAT), path: None, position, kind }
    })?;
    let k = [("fx", j.fx), ("fy", j.fy), ("cx", j.cx), ("cy", j.cy)];
    for (name, v) in k {
        let positive = name.starts_with('f');
        if !v.is_finite() || (positive && v <= 0.0) {
            return Err(Error::new(
                FORMAT,
                ErrorKind::BadValue(format!("intrinsics JSON: {name} = {v} is not valid")),
            ));
        }
    }
    if let Some(s) = j.depth_scale {
        check_scale(s)?;
    }
    Ok(j)
}

/// Reads pinhole intrinsics from a JSON object with numeric keys `fx`, `fy`, `cx`, `cy`
/// (pixels); other keys (`width`, `height`, `note`, ...) are allowed and ignored. Focal lengths
/// must be positive and all four values finite.
pub fn read_intrinsics_json(reader: impl Read) -> Result<PinholeIntrinsics, Error> {
    let j = parse_intrinsics_json(reader)?;
    Ok(PinholeIntrinsics { fx: j.fx, fy: j.fy, cx: j.cx, cy: j.cy })
}
