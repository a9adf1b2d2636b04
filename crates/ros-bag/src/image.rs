//! Depth images: `sensor_msgs/Image` (encodings `16UC1`, millimetres, and `32FC1`, metres)
//! with the `sensor_msgs/CameraInfo` of their camera, turned into organised clouds in the
//! camera's optical frame (x right, y down, z forward).
//!
//! The pinhole model is the projection matrix `P` of the camera info (the rectified camera,
//! what `depth_image_proc` uses), or `K` when `P` is all zeros. Distortion is not undone:
//! depth images on ROS topics are normally rectified (`image_rect`), and an unrectified one
//! gives points off by the lens distortion.

use crate::msgs::Header;
use crate::wire::{Encoding, Reader, WireError, Writer};
use pointcloud::{BeamModel, PinholeIntrinsics, PointCloud, RangeImage, RangeKind};

/// `sensor_msgs/Image`.
pub const IMAGE: &str = "sensor_msgs/Image";
/// `sensor_msgs/CameraInfo`.
pub const CAMERA_INFO: &str = "sensor_msgs/CameraInfo";

/// A `sensor_msgs/Image`.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct Image {
    /// Stamp and the camera's optical frame.
    pub header: Header,
    /// Rows.
    pub height: u32,
    /// Columns.
    pub width: u32,
    /// Pixel encoding (`16UC1`, `32FC1`, `mono16`, `rgb8`, ...).
    pub encoding: String,
    /// Whether multi-byte pixels are big-endian.
    pub is_bigendian: bool,
    /// Bytes per row.
    pub step: u32,
    /// `step × height` bytes.
    pub data: Vec<u8>,
}

/// Why a depth image could not become a cloud.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DepthError {
    /// Not a depth encoding.
    #[error(
        "image encoding `{0}` is not a depth image (want 16UC1 in millimetres or 32FC1 in metres)"
    )]
    Encoding(String),
    /// `step` or `data` do not hold the image.
    #[error(
        "a {width} × {height} {encoding} image needs step ≥ {min_step} and {need} bytes; has step {step} and {have} bytes"
    )]
    Size {
        /// Columns.
        width: u32,
        /// Rows.
        height: u32,
        /// Encoding.
        encoding: String,
        /// Least bytes per row.
        min_step: u64,
        /// Bytes per row.
        step: u32,
        /// Bytes needed.
        need: u64,
        /// Bytes present.
        have: usize,
    },
    /// The camera info is of another size or has no focal length.
    #[error("camera info: {0}")]
    Camera(String),
    /// The cloud could not be built.
    #[error(transparent)]
    Cloud(#[from] pointcloud::RangeImageError),
}

impl Image {
    /// Decodes a message.
    pub fn decode(data: &[u8], encoding: Encoding) -> Result<Image, WireError> {
        let r = &mut Reader::new(data, encoding)?;
        Ok(Image {
            header: Header::read(r, encoding)?,
            height: r.u32("height")?,
            width: r.u32("width")?,
            encoding: r.string("encoding")?,
            is_bigendian: r.u8("is_bigendian")? != 0,
            step: r.u32("step")?,
            data: r.bytes("data")?.to_vec(),
        })
    }

    /// Encodes the message.
    pub fn encode(&self, encoding: Encoding) -> Vec<u8> {
        let mut w = Writer::new(encoding);
        self.header.write(&mut w, encoding);
        w.u32(self.height);
        w.u32(self.width);
        w.string(&self.encoding);
        w.u8(u8::from(self.is_bigendian));
        w.u32(self.step);
        w.bytes(&self.data);
        w.finish()
    }

    /// A depth image of `depth` metres per pixel (row-major, `None`: no measurement) in
    /// `encoding` `16UC1` (rounded to millimetres, 0 = none) or `32FC1` (NaN = none).
    pub fn from_depth(
        header: Header,
        width: u32,
        height: u32,
        depth: &[Option<f32>],
        encoding: &str,
    ) -> Result<Image, DepthError> {
        let data: Vec<u8> = match encoding {
            "16UC1" => depth
                .iter()
                .flat_map(|d| {
                    let mm = d.map_or(0.0, |d| (d * 1000.0).round()).clamp(0.0, 65535.0);
                    (mm as u16).to_le_bytes()
                })
                .collect(),
            "32FC1" => depth.iter().flat_map(|d| d.unwrap_or(f32::NAN).to_le_bytes()).collect(),
            other => return Err(DepthError::Encoding(other.to_owned())),
        };
        let step = width * if encoding == "16UC1" { 2 } else { 4 };
        Ok(Image {
            header,
            height,
            width,
            encoding: encoding.to_owned(),
            is_bigendian: false,
            step,
            data,
        })
    }

    /// The depth per pixel in metres (row-major; `None`: no measurement, i.e. 0, NaN or a
    /// negative value).
    pub fn depths(&self) -> Result<Vec<Option<f32>>, DepthError> {
        let (bytes, scale) = match self.encoding.as_str() {
            "16UC1" | "mono16" => (2usize, 1e-3f32),
            "32FC1" => (4, 1.0),
            other => return Err(DepthError::Encoding(other.to_owned())),
        };
        let min_step = self.width as u64 * bytes as u64;
        let need = self.step as u64 * self.height as u64;
        if (self.step as u64) < min_step || (self.data.len() as u64) < need {
            return Err(DepthError::Size {
                width: self.width,
                height: self.height,
                encoding: self.encoding.clone(),
                min_step,
                step: self.step,
                need,
                have: self.data.len(),
            });
        }
        let mut out = Vec::with_capacity(self.width as usize * self.height as usize);
        for row in self.data.chunks(self.step as usize).take(self.height as usize) {
            for px in row[..min_step as usize].chunks_exact(bytes) {
                let v = match (bytes, self.is_bigendian) {
                    (2, false) => u16::from_le_bytes([px[0], px[1]]) as f32,
                    (2, true) => u16::from_be_bytes([px[0], px[1]]) as f32,
                    (_, false) => f32::from_le_bytes([px[0], px[1], px[2], px[3]]),
                    (_, true) => f32::from_be_bytes([px[0], px[1], px[2], px[3]]),
                } * scale;
                out.push((v.is_finite() && v > 0.0).then_some(v));
            }
        }
        Ok(out)
    }

    /// The image as an organised cloud in the camera's optical frame, by the pinhole model of
    /// `info` (see the [module docs](self)).
    pub fn to_cloud(&self, info: &CameraInfo) -> Result<PointCloud, DepthError> {
        if (info.width, info.height) != (self.width, self.height) {
            return Err(DepthError::Camera(format!(
                "{} × {} pixels, the image {} × {}",
                info.width, info.height, self.width, self.height
            )));
        }
        let intrinsics = info.intrinsics()?;
        let image = RangeImage::new(
            self.width,
            self.height,
            BeamModel::Pinhole(intrinsics),
            RangeKind::Depth,
            self.depths()?,
        )?;
        Ok(image.to_cloud()?)
    }
}

/// A `sensor_msgs/CameraInfo` (ROS 1 names its matrices `D`, `K`, `R`, `P`; the layout is the
/// same).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct CameraInfo {
    /// Stamp and the camera's optical frame.
    pub header: Header,
    /// Rows.
    pub height: u32,
    /// Columns.
    pub width: u32,
    /// `plumb_bob`, `rational_polynomial`, ...
    pub distortion_model: String,
    /// Distortion coefficients.
    pub d: Vec<f64>,
    /// Intrinsic matrix of the raw image, row-major.
    pub k: [f64; 9],
    /// Rectification rotation, row-major.
    pub r: [f64; 9],
    /// Projection matrix of the rectified image, row-major 3 × 4.
    pub p: [f64; 12],
    /// Horizontal binning.
    pub binning_x: u32,
    /// Vertical binning.
    pub binning_y: u32,
    /// Region of interest: x offset, y offset, height, width, do_rectify.
    pub roi: (u32, u32, u32, u32, bool),
}

impl CameraInfo {
    /// Decodes a message.
    pub fn decode(data: &[u8], encoding: Encoding) -> Result<CameraInfo, WireError> {
        let r = &mut Reader::new(data, encoding)?;
        let header = Header::read(r, encoding)?;
        let height = r.u32("height")?;
        let width = r.u32("width")?;
        let distortion_model = r.string("distortion_model")?;
        let n = r.count("d", 8)?;
        let d = (0..n).map(|_| r.f64("d")).collect::<Result<Vec<_>, _>>()?;
        let mut k = [0.0; 9];
        for v in &mut k {
            *v = r.f64("k")?;
        }
        let mut rot = [0.0; 9];
        for v in &mut rot {
            *v = r.f64("r")?;
        }
        let mut p = [0.0; 12];
        for v in &mut p {
            *v = r.f64("p")?;
        }
        Ok(CameraInfo {
            header,
            height,
            width,
            distortion_model,
            d,
            k,
            r: rot,
            p,
            binning_x: r.u32("binning_x")?,
            binning_y: r.u32("binning_y")?,
            roi: (
                r.u32("roi.x_offset")?,
                r.u32("roi.y_offset")?,
                r.u32("roi.height")?,
                r.u32("roi.width")?,
                r.bool("roi.do_rectify")?,
            ),
        })
    }

    /// Encodes the message.
    pub fn encode(&self, encoding: Encoding) -> Vec<u8> {
        let mut w = Writer::new(encoding);
        self.header.write(&mut w, encoding);
        w.u32(self.height);
        w.u32(self.width);
        w.string(&self.distortion_model);
        w.u32(self.d.len() as u32);
        for &v in self.d.iter().chain(&self.k).chain(&self.r).chain(&self.p) {
            w.f64(v);
        }
        w.u32(self.binning_x);
        w.u32(self.binning_y);
        let (x, y, h, wd, rect) = self.roi;
        for v in [x, y, h, wd] {
            w.u32(v);
        }
        w.bool(rect);
        w.finish()
    }

    /// The camera info of an ideal pinhole camera (no distortion, `P = [K | 0]`).
    pub fn pinhole(header: Header, width: u32, height: u32, k: PinholeIntrinsics) -> CameraInfo {
        let PinholeIntrinsics { fx, fy, cx, cy } = k;
        CameraInfo {
            header,
            height,
            width,
            distortion_model: "plumb_bob".to_owned(),
            d: vec![0.0; 5],
            k: [fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0],
            r: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
            p: [fx, 0.0, cx, 0.0, 0.0, fy, cy, 0.0, 0.0, 0.0, 1.0, 0.0],
            binning_x: 0,
            binning_y: 0,
            roi: (0, 0, 0, 0, false),
        }
    }

    /// The pinhole model: from `P` (the rectified camera), or from `K` when `P` is all zeros.
    pub fn intrinsics(&self) -> Result<PinholeIntrinsics, DepthError> {
        let (fx, fy, cx, cy) = if self.p.iter().any(|&v| v != 0.0) {
            (self.p[0], self.p[5], self.p[2], self.p[6])
        } else {
            (self.k[0], self.k[4], self.k[2], self.k[5])
        };
        let focal = fx.is_finite() && fy.is_finite() && fx > 0.0 && fy > 0.0;
        if !(focal && cx.is_finite() && cy.is_finite()) {
            return Err(DepthError::Camera(format!(
                "focal lengths ({fx}, {fy}) and principal point ({cx}, {cy}) are not a camera"
            )));
        }
        Ok(PinholeIntrinsics { fx, fy, cx, cy })
    }
}
