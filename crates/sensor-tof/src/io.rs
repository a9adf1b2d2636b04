//! Frames on disk: 16-bit grayscale PNG range/amplitude pairs (plus an optional 8- or 16-bit
//! confidence PNG) described by a JSON sidecar ([`FrameMeta`]), and frames from and to the
//! organised point clouds of every format `pointcloud::io` reads.
//!
//! # The sidecar
//!
//! ```json
//! {
//!   "width": 176, "height": 144,
//!   "metres_per_unit": 0.001,
//!   "range_kind": "z",
//!   "camera": "sr3000",
//!   "modulation_hz": 20000000,
//!   "amplitude_scale": 1,
//!   "aat": { "a_hat": 12000, "delta_x": 88, "delta_y": 61, "curvature": 1, "threshold": 0.2 },
//!   "min_range": 0.6
//! }
//! ```
//!
//! | key | meaning | default |
//! |---|---|---|
//! | `width`, `height` | image size, pixels (must match the PNGs) | required |
//! | `metres_per_unit` | metres per range PNG unit | required |
//! | `range_kind` | `"z"` (distance to the image plane, the SwissRanger's, L1804–1806; alias `"depth"`) or `"radial"` | required |
//! | `camera` | preset `"sr3000"` or `"sr3100"`: fills the intrinsics, the AAT parabola (thesis values) and the 0.6 m minimum range | none |
//! | `fx`, `fy`, `cx`, `cy` | pinhole intrinsics, pixels (pixel (0, 0) top left, its centre at coordinate 0) | the preset's; required without one |
//! | `modulation_hz` | modulation frequency: sets the non-ambiguity range `c / 2f` used to unwrap | 20 MHz, the SwissRanger's only calibrated one (L1916–1924) |
//! | `amplitude_scale` | amplitude units per amplitude PNG unit | 1 |
//! | `aat` | the adaptive amplitude threshold: `threshold` (AAT, default 0.2, L2370–2372) and one illumination source: Eq 2.5's `a_hat`, `delta_x`, `delta_y` (+ `curvature`, default 1), or `white_wall_table` (a [`WhiteWallTable`] JSON file), or `calibration` (a [`Calibration`] JSON file, as `patchnav tof calibrate` writes); with none of them, the preset's parabola | the preset's [`AatConfig`], else none |
//! | `min_range` | shortest well-measured radial distance, metres | the preset's, else 0 |
//!
//! File names in `aat` are relative to the sidecar's folder ([`read_meta`] resolves them).
//!
//! The sidecar of an ifm O3R frame (`distance_resolution_m_per_count`, `intrinsic_params_32`)
//! is recognised and read too ([`FrameMeta::from_ifm_json`]).
//!
//! # Quantisation
//!
//! [`write_png_pair`] stores `round(range / metres_per_unit)` and
//! `round(amplitude / amplitude_scale)`: a pair read back differs from the frame written by at
//! most half a unit of each (0.5 mm at 1 mm per unit). A range of 0 is "no measurement"; a
//! measured range that would round to 0 or above 65 535 units, or an amplitude above 65 535
//! units, is an error naming the pixel, never clamped.

use crate::calibrate::Calibration;
use crate::{AatConfig, Illumination, Parabola, TofCamera, TofError, TofFrame, WhiteWallTable};
use pointcloud::io::{Error as FileError, ErrorKind, Format, Position};
use pointcloud::{FieldData, PinholeIntrinsics, PointCloud, RangeKind, Real};
use serde::{Deserialize, Serialize};
use std::io::Cursor;
use std::path::{Path, PathBuf};

/// The default modulation frequency, Hz: the SwissRanger's default and only calibrated one
/// (L1916–1924).
pub const DEFAULT_MODULATION_HZ: Real = 20e6;

/// The default AAT (thesis L2370–2372).
pub const DEFAULT_AAT: Real = 0.2;

/// A camera preset named in a sidecar.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CameraPreset {
    /// [`TofCamera::sr3000`] with [`AatConfig::sr3000`].
    Sr3000,
    /// [`TofCamera::sr3100`] with [`AatConfig::sr3100`].
    Sr3100,
}

impl CameraPreset {
    fn camera(self) -> TofCamera {
        match self {
            CameraPreset::Sr3000 => TofCamera::sr3000(),
            CameraPreset::Sr3100 => TofCamera::sr3100(),
        }
    }

    fn aat(self) -> AatConfig {
        match self {
            CameraPreset::Sr3000 => AatConfig::sr3000(),
            CameraPreset::Sr3100 => AatConfig::sr3100(),
        }
    }
}

/// The `aat` block of a sidecar: the threshold and one illumination source (see the module
/// documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AatMeta {
    /// AAT, the apparent-reflectivity threshold (0.2 in the thesis).
    #[serde(default = "default_aat")]
    pub threshold: Real,
    /// Eq 2.5's Â.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub a_hat: Option<Real>,
    /// Eq 2.5's δx (column).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delta_x: Option<Real>,
    /// Eq 2.5's δy (row).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delta_y: Option<Real>,
    /// The parabola's curvature (1 in Eq 2.5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub curvature: Option<Real>,
    /// A [`WhiteWallTable`] JSON file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub white_wall_table: Option<PathBuf>,
    /// A [`Calibration`] JSON file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub calibration: Option<PathBuf>,
}

fn default_aat() -> Real {
    DEFAULT_AAT
}

fn default_modulation() -> Real {
    DEFAULT_MODULATION_HZ
}

fn one() -> Real {
    1.0
}

fn is_one(v: &Real) -> bool {
    *v == 1.0
}

/// The JSON sidecar of a PNG pair (see the module documentation for the keys and defaults).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameMeta {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Metres per range PNG unit.
    pub metres_per_unit: Real,
    /// What the range PNG measures: `"z"` ([`RangeKind::Depth`]) or `"radial"`.
    #[serde(with = "range_kind_name")]
    pub range_kind: RangeKind,
    /// A camera preset filling the intrinsics, the AAT parabola and the minimum range.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub camera: Option<CameraPreset>,
    /// Focal length along x, pixels.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fx: Option<Real>,
    /// Focal length along y, pixels.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fy: Option<Real>,
    /// Principal point column.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cx: Option<Real>,
    /// Principal point row.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cy: Option<Real>,
    /// Modulation frequency, Hz.
    #[serde(default = "default_modulation")]
    pub modulation_hz: Real,
    /// Amplitude units per amplitude PNG unit.
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub amplitude_scale: Real,
    /// The adaptive amplitude threshold's parameters.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aat: Option<AatMeta>,
    /// Shortest well-measured radial distance, metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_range: Option<Real>,
}

mod range_kind_name {
    use pointcloud::RangeKind;
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(kind: &RangeKind, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(match kind {
            RangeKind::Depth => "z",
            RangeKind::Radial => "radial",
        })
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<RangeKind, D::Error> {
        let s = String::deserialize(d)?;
        match s.as_str() {
            "z" | "depth" => Ok(RangeKind::Depth),
            "radial" => Ok(RangeKind::Radial),
            other => Err(serde::de::Error::custom(format!(
                "range_kind `{other}` (want \"z\" or \"radial\")"
            ))),
        }
    }
}

fn bad(what: &'static str, why: String) -> TofError {
    TofError::BadParameter { what, why }
}

impl FrameMeta {
    /// The sidecar describing frames of `camera` with ranges of `kind` stored at
    /// `metres_per_unit` (amplitude scale 1, no AAT block).
    pub fn for_camera(camera: &TofCamera, kind: RangeKind, metres_per_unit: Real) -> FrameMeta {
        let k = camera.intrinsics;
        FrameMeta {
            width: camera.width,
            height: camera.height,
            metres_per_unit,
            range_kind: kind,
            camera: None,
            fx: Some(k.fx),
            fy: Some(k.fy),
            cx: Some(k.cx),
            cy: Some(k.cy),
            modulation_hz: camera.modulation_hz,
            amplitude_scale: 1.0,
            aat: None,
            min_range: (camera.min_range > 0.0).then_some(camera.min_range),
        }
    }

    /// Reads the sidecar of an ifm O3R frame (the `frame_meta.json` layout: `width`, `height`,
    /// `distance_resolution_m_per_count`, `intrinsic_model_id` 0 with `intrinsic_params_32` =
    /// fx, fy, mx, my, then distortion). The distances are radial. The lens distortion is
    /// ignored (a pinhole model: at the O3R's 0.31 radial coefficient the image corners move by
    /// a few pixels). The file names no modulation frequency, and the O3R fuses several
    /// frequencies into distances that are already unwrapped, so the 20 MHz default
    /// ([`DEFAULT_MODULATION_HZ`]) only matters if such a frame is unwrapped again, which it
    /// should not be. The amplitude is the normalised amplitude count (scale 1). `path` names
    /// the file in errors.
    pub fn from_ifm_json(value: &serde_json::Value, path: &Path) -> Result<FrameMeta, TofError> {
        let json_err = |why: String| TofError::Json { path: path.display().to_string(), why };
        let uint = |key: &str| {
            value
                .get(key)
                .and_then(serde_json::Value::as_u64)
                .and_then(|v| u32::try_from(v).ok())
                .ok_or_else(|| json_err(format!("`{key}` is missing or not a 32-bit count")))
        };
        let width = uint("width")?;
        let height = uint("height")?;
        let scale = value
            .get("distance_resolution_m_per_count")
            .and_then(serde_json::Value::as_f64)
            .ok_or_else(|| json_err("`distance_resolution_m_per_count` is not a number".into()))?;
        if let Some(id) = value.get("intrinsic_model_id")
            && id.as_u64() != Some(0)
        {
            return Err(json_err(format!(
                "intrinsic_model_id {id}: only model 0 (fx, fy, mx, my, distortion) is known"
            )));
        }
        let params: Vec<Real> = value
            .get("intrinsic_params_32")
            .and_then(serde_json::Value::as_array)
            .map(|a| a.iter().map(|v| v.as_f64().unwrap_or(Real::NAN)).collect())
            .ok_or_else(|| json_err("`intrinsic_params_32` is not an array".into()))?;
        if params.len() < 4 {
            return Err(json_err(format!(
                "`intrinsic_params_32` has {} values (want fx, fy, mx, my first)",
                params.len()
            )));
        }
        let meta = FrameMeta {
            width,
            height,
            metres_per_unit: scale,
            range_kind: RangeKind::Radial,
            camera: None,
            fx: Some(params[0]),
            fy: Some(params[1]),
            cx: Some(params[2]),
            cy: Some(params[3]),
            modulation_hz: DEFAULT_MODULATION_HZ,
            amplitude_scale: 1.0,
            aat: None,
            min_range: None,
        };
        meta.validate()?;
        Ok(meta)
    }

    /// Checks every field: a non-empty image, positive finite scales, intrinsics (from the
    /// preset or all four given) finite with positive focal lengths, a modulation frequency in
    /// [1 kHz, 10 GHz], a preset's image size, and an `aat` block with a finite non-negative
    /// threshold and exactly one illumination source (or a preset to supply it).
    pub fn validate(&self) -> Result<(), TofError> {
        if !(self.metres_per_unit.is_finite() && self.metres_per_unit > 0.0) {
            return Err(bad(
                "metres per unit",
                format!("{} (want finite > 0)", self.metres_per_unit),
            ));
        }
        if !(self.amplitude_scale.is_finite() && self.amplitude_scale > 0.0) {
            return Err(bad(
                "amplitude scale",
                format!("{} (want finite > 0)", self.amplitude_scale),
            ));
        }
        if let Some(p) = self.camera {
            let c = p.camera();
            if (c.width, c.height) != (self.width, self.height) {
                return Err(bad(
                    "image size",
                    format!(
                        "{} × {} for the {p:?} preset, which is {} × {}",
                        self.width, self.height, c.width, c.height
                    ),
                ));
            }
        }
        self.camera()?;
        if let Some(a) = &self.aat {
            if !(a.threshold.is_finite() && a.threshold >= 0.0) {
                return Err(bad("AAT", format!("{} (want finite ≥ 0)", a.threshold)));
            }
            let parabola = [a.a_hat, a.delta_x, a.delta_y, a.curvature];
            let given = parabola.iter().filter(|v| v.is_some()).count();
            if given > 0 && (a.a_hat.is_none() || a.delta_x.is_none() || a.delta_y.is_none()) {
                return Err(bad(
                    "AAT parabola",
                    "give `a_hat`, `delta_x` and `delta_y` together (`curvature` optional)".into(),
                ));
            }
            if let Some(v) = parabola.iter().flatten().find(|v| !v.is_finite()) {
                return Err(bad("AAT parabola", format!("{v} (want finite)")));
            }
            let sources = usize::from(given > 0)
                + usize::from(a.white_wall_table.is_some())
                + usize::from(a.calibration.is_some());
            if sources > 1 {
                return Err(bad(
                    "AAT illumination",
                    "give one of the parabola, `white_wall_table` or `calibration`".into(),
                ));
            }
            if sources == 0 && self.camera.is_none() {
                return Err(bad(
                    "AAT illumination",
                    "no parabola, `white_wall_table` or `calibration`, and no camera preset to \
                     supply one"
                        .into(),
                ));
            }
        }
        Ok(())
    }

    /// The camera the sidecar describes (the preset with any intrinsics given overriding it).
    /// Fails on absurd values ([`TofCamera::validate`]) or missing intrinsics.
    pub fn camera(&self) -> Result<TofCamera, TofError> {
        let base = self.camera.map(CameraPreset::camera);
        let pick = |v: Option<Real>, preset: Option<Real>, name: &'static str| {
            v.or(preset)
                .ok_or_else(|| bad("intrinsics", format!("`{name}` is missing (and no preset)")))
        };
        let k = base.map(|c| c.intrinsics);
        let intrinsics = PinholeIntrinsics {
            fx: pick(self.fx, k.map(|k| k.fx), "fx")?,
            fy: pick(self.fy, k.map(|k| k.fy), "fy")?,
            cx: pick(self.cx, k.map(|k| k.cx), "cx")?,
            cy: pick(self.cy, k.map(|k| k.cy), "cy")?,
        };
        let camera = TofCamera {
            width: self.width,
            height: self.height,
            intrinsics,
            modulation_hz: self.modulation_hz,
            min_range: self.min_range.or(base.map(|c| c.min_range)).unwrap_or(0.0),
        };
        camera.validate()?;
        Ok(camera)
    }

    /// The AAT configuration the sidecar gives: from its `aat` block (reading the table or
    /// calibration file it names; a calibration also sets which range, z or radial, Eq 2.4
    /// uses), else the preset's, else `None`. Relative file names are taken as they are
    /// ([`read_meta`] makes them relative to the sidecar's folder).
    pub fn aat(&self) -> Result<Option<AatConfig>, TofError> {
        self.validate()?;
        let preset = self.camera.map(CameraPreset::aat);
        let Some(a) = &self.aat else { return Ok(preset) };
        let mut config = preset.unwrap_or_else(AatConfig::sr3000);
        config.threshold = a.threshold;
        if let (Some(a_hat), Some(delta_x), Some(delta_y)) = (a.a_hat, a.delta_x, a.delta_y) {
            config.illumination = Illumination::Parabola(Parabola {
                a_hat,
                delta_x,
                delta_y,
                curvature: a.curvature.unwrap_or(1.0),
            });
        } else if let Some(path) = &a.white_wall_table {
            let table: WhiteWallTable = read_json(path)?;
            if (table.width, table.height) != (self.width, self.height) {
                return Err(TofError::Mismatch {
                    why: format!(
                        "{}: a {} × {} table for {} × {} frames",
                        path.display(),
                        table.width,
                        table.height,
                        self.width,
                        self.height
                    ),
                });
            }
            config.illumination = Illumination::Table(table);
        } else if let Some(path) = &a.calibration {
            let calibration: Calibration = read_json(path)?;
            if (calibration.width, calibration.height) != (self.width, self.height) {
                return Err(TofError::Mismatch {
                    why: format!(
                        "{}: calibrated on {} × {} frames, these are {} × {}",
                        path.display(),
                        calibration.width,
                        calibration.height,
                        self.width,
                        self.height
                    ),
                });
            }
            config.illumination = Illumination::Parabola(calibration.parabola);
            config.range = calibration.range;
        }
        Ok(Some(config))
    }

    fn resolve_paths(&mut self, dir: &Path) {
        if let Some(a) = &mut self.aat {
            for p in [&mut a.white_wall_table, &mut a.calibration].into_iter().flatten() {
                if p.is_relative() {
                    *p = dir.join(&*p);
                }
            }
        }
    }
}

/// Reads a JSON file of type `T`; errors name the file.
pub fn read_json<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T, TofError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| TofError::Json { path: path.display().to_string(), why: e.to_string() })?;
    serde_json::from_str(&text)
        .map_err(|e| TofError::Json { path: path.display().to_string(), why: e.to_string() })
}

/// Writes `value` as pretty-printed JSON; errors name the file.
pub fn write_json<T: Serialize>(path: &Path, value: &T) -> Result<(), TofError> {
    let json_err = |why: String| TofError::Json { path: path.display().to_string(), why };
    let text = serde_json::to_string_pretty(value).map_err(|e| json_err(e.to_string()))?;
    pointcloud::io::write_bytes_atomically(path, text + "\n").map_err(|e| json_err(e.to_string()))
}

/// Parses sidecar text: an ifm O3R `frame_meta.json` (recognised by its
/// `distance_resolution_m_per_count` key) or a [`FrameMeta`]. Validated; `path` names the file
/// in errors, and relative file names in its `aat` block are left as they are.
pub fn parse_meta(text: &str, path: &Path) -> Result<FrameMeta, TofError> {
    let json_err = |why: String| TofError::Json { path: path.display().to_string(), why };
    let value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| json_err(e.to_string()))?;
    if value.get("distance_resolution_m_per_count").is_some() {
        return FrameMeta::from_ifm_json(&value, path);
    }
    let meta: FrameMeta = serde_json::from_value(value).map_err(|e| json_err(e.to_string()))?;
    meta.validate().map_err(|e| json_err(e.to_string()))?;
    Ok(meta)
}

/// Reads and validates a sidecar ([`parse_meta`]); file names in its `aat` block are made
/// relative to the sidecar's folder.
pub fn read_meta(path: &Path) -> Result<FrameMeta, TofError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| TofError::Json { path: path.display().to_string(), why: e.to_string() })?;
    let mut meta = parse_meta(&text, path)?;
    if let Some(dir) = path.parent() {
        meta.resolve_paths(dir);
    }
    Ok(meta)
}

/// Validates `meta` and writes it as JSON.
pub fn write_meta(path: &Path, meta: &FrameMeta) -> Result<(), TofError> {
    meta.validate()?;
    write_json(path, meta)
}

fn file_error(path: &Path, kind: impl Into<ErrorKind>) -> TofError {
    TofError::Io(FileError::new(Format::DepthPng, kind).with_path(path))
}

fn read_bytes(path: &Path) -> Result<Vec<u8>, TofError> {
    std::fs::read(path).map_err(|e| file_error(path, e))
}

/// Reads a 16-bit grayscale PNG.
fn read_u16_png(path: &Path) -> Result<(u32, u32, Vec<u16>), TofError> {
    let data = read_bytes(path)?;
    pointcloud::io::depth_png::decode_u16_gray(&data).map_err(|e| TofError::Io(e.with_path(path)))
}

/// Decodes an 8- or 16-bit grayscale PNG into its size and values.
fn decode_gray(data: &[u8]) -> Result<(u32, u32, Vec<u16>), FileError> {
    let at = |pos: u64, kind: ErrorKind| FileError::at(Format::DepthPng, Position::Byte(pos), kind);
    let png_err = |e: png::DecodingError, pos: u64| match e {
        png::DecodingError::IoError(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            at(pos, ErrorKind::UnexpectedEof { expected: "more PNG data".into() })
        }
        other => at(pos, ErrorKind::BadValue(format!("corrupt PNG: {other}"))),
    };
    let mut cursor = Cursor::new(data);
    let mut decoder = png::Decoder::new(&mut cursor);
    let info = match decoder.read_header_info() {
        Ok(i) => i,
        Err(e) => return Err(png_err(e, 0)),
    };
    let (width, height, depth) = (info.width, info.height, info.bit_depth);
    let bytes_per = match (info.color_type, depth) {
        (png::ColorType::Grayscale, png::BitDepth::Eight) => 1u64,
        (png::ColorType::Grayscale, png::BitDepth::Sixteen) => 2,
        (c, d) => {
            return Err(at(
                24,
                ErrorKind::Unsupported(format!(
                    "a {}-bit {c:?} PNG (want 8- or 16-bit grayscale)",
                    d as u8
                )),
            ));
        }
    };
    // Deflate expands by at most about 1032 : 1: refuse lying headers before reserving memory.
    if (width as u64 * bytes_per + 1) * height as u64 > 1100 * data.len() as u64 + 4096 {
        return Err(at(
            16,
            ErrorKind::BadHeader(format!(
                "{width}×{height} pixels cannot fit in a {}-byte file",
                data.len()
            )),
        ));
    }
    let mut reader = match decoder.read_info() {
        Ok(r) => r,
        Err(e) => return Err(png_err(e, 0)),
    };
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| at(0, ErrorKind::Unsupported("image too large".into())))?;
    let mut buf = vec![0u8; size];
    let frame = match reader.next_frame(&mut buf) {
        Ok(f) => f,
        Err(e) => return Err(png_err(e, 0)),
    };
    if frame.width != width || frame.height != height {
        return Err(at(0, ErrorKind::Unsupported("an animated PNG".into())));
    }
    let n = width as usize * height as usize;
    let values: Vec<u16> = if bytes_per == 1 {
        buf[..n].iter().map(|&b| b as u16).collect()
    } else {
        buf[..2 * n].chunks_exact(2).map(|b| u16::from_be_bytes([b[0], b[1]])).collect()
    };
    Ok((width, height, values))
}

fn check_size(
    path: &Path,
    what: &'static str,
    size: (u32, u32),
    meta: &FrameMeta,
) -> Result<(), TofError> {
    if size != (meta.width, meta.height) {
        return Err(TofError::BadImage {
            what,
            why: format!(
                "{} is {} × {}, the sidecar says {} × {}",
                path.display(),
                size.0,
                size.1,
                meta.width,
                meta.height
            ),
        });
    }
    Ok(())
}

/// Reads a frame from a 16-bit range PNG (`value × metres_per_unit` metres, 0 = no measurement)
/// and a 16-bit amplitude PNG (`value × amplitude_scale`) described by `meta`. Fails with
/// [`TofError::Io`] (naming the file and byte) on missing, truncated, corrupt or non-16-bit
/// grayscale PNGs and with [`TofError::BadImage`] when a PNG's size differs from the sidecar's.
pub fn read_png_pair(
    range_png: &Path,
    amplitude_png: &Path,
    meta: &FrameMeta,
) -> Result<TofFrame, TofError> {
    let camera = meta.camera()?;
    meta.validate()?;
    let (w, h, range) = read_u16_png(range_png)?;
    check_size(range_png, "range", (w, h), meta)?;
    let (w, h, amplitude) = read_u16_png(amplitude_png)?;
    check_size(amplitude_png, "amplitude", (w, h), meta)?;
    let scale = meta.metres_per_unit;
    let range = range.iter().map(|&v| (v as Real * scale) as f32).collect();
    let a = meta.amplitude_scale;
    let amplitude = amplitude.iter().map(|&v| (v as Real * a) as f32).collect();
    TofFrame::new(camera, meta.range_kind, range, amplitude)
}

/// [`read_png_pair`] plus a confidence PNG (8- or 16-bit grayscale, values kept as they are).
pub fn read_png_pair_with_confidence(
    range_png: &Path,
    amplitude_png: &Path,
    confidence_png: &Path,
    meta: &FrameMeta,
) -> Result<TofFrame, TofError> {
    let frame = read_png_pair(range_png, amplitude_png, meta)?;
    let data = read_bytes(confidence_png)?;
    let (w, h, values) =
        decode_gray(&data).map_err(|e| TofError::Io(e.with_path(confidence_png)))?;
    check_size(confidence_png, "confidence", (w, h), meta)?;
    frame.with_confidence(values)
}

fn encode_u16(path: &Path, width: u32, height: u32, values: &[u16]) -> Result<(), TofError> {
    let mut bytes = Vec::with_capacity(values.len() * 2);
    for v in values {
        bytes.extend_from_slice(&v.to_be_bytes());
    }
    encode(path, width, height, png::ColorType::Grayscale, png::BitDepth::Sixteen, &bytes)
}

/// Writes `bytes` as a PNG of the given colour type and depth.
pub(crate) fn encode(
    path: &Path,
    width: u32,
    height: u32,
    color: png::ColorType,
    depth: png::BitDepth,
    bytes: &[u8],
) -> Result<(), TofError> {
    let png_err = |e: png::EncodingError| match e {
        png::EncodingError::IoError(io) => file_error(path, io),
        other => file_error(path, ErrorKind::BadValue(other.to_string())),
    };
    pointcloud::io::write_atomically(path, |out| {
        let mut encoder = png::Encoder::new(out, width, height);
        encoder.set_color(color);
        encoder.set_depth(depth);
        let mut w = encoder.write_header().map_err(png_err)?;
        w.write_image_data(bytes).map_err(png_err)?;
        w.finish().map_err(png_err)
    })
}

/// Writes an 8-bit RGB PNG (`rgb` holds 3 bytes per pixel, row-major).
pub fn write_rgb_png(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<(), TofError> {
    if rgb.len() as u64 != 3 * width as u64 * height as u64 {
        return Err(TofError::BadImage {
            what: "RGB",
            why: format!("{} bytes for {width} × {height} pixels", rgb.len()),
        });
    }
    encode(path, width, height, png::ColorType::Rgb, png::BitDepth::Eight, rgb)
}

fn quantise(
    what: &'static str,
    values: &[f32],
    scale: Real,
    width: u32,
    zero_is_none: bool,
) -> Result<Vec<u16>, TofError> {
    values
        .iter()
        .enumerate()
        .map(|(i, &x)| {
            if x == 0.0 {
                return Ok(0);
            }
            let v = (x as Real / scale).round();
            let lo = if zero_is_none { 1.0 } else { 0.0 };
            if !(lo..=u16::MAX as Real).contains(&v) {
                let (col, row) = (i % width as usize, i / width as usize);
                return Err(TofError::BadImage {
                    what,
                    why: format!(
                        "{x} at pixel ({col}, {row}) is {v} units of {scale}, outside {lo}..=65535"
                    ),
                });
            }
            Ok(v as u16)
        })
        .collect()
}

/// Writes `frame` as a 16-bit range PNG and a 16-bit amplitude PNG described by `meta` (the
/// frame is converted to `meta.range_kind` first). Values are quantised to `metres_per_unit`
/// and `amplitude_scale` (see the module documentation). Fails if the frame's image size or
/// intrinsics differ from the sidecar's, or a value does not fit in 16 bits.
pub fn write_png_pair(
    frame: &TofFrame,
    range_png: &Path,
    amplitude_png: &Path,
    meta: &FrameMeta,
) -> Result<(), TofError> {
    let camera = meta.camera()?;
    meta.validate()?;
    let fc = frame.camera();
    let (a, b) = (fc.intrinsics, camera.intrinsics);
    let close = |x: Real, y: Real| (x - y).abs() <= 1e-9 * (1.0 + x.abs());
    if (fc.width, fc.height) != (camera.width, camera.height)
        || !(close(a.fx, b.fx) && close(a.fy, b.fy) && close(a.cx, b.cx) && close(a.cy, b.cy))
    {
        return Err(TofError::Mismatch {
            why: format!(
                "a {} × {} frame with {a:?}, the sidecar says {} × {} with {b:?}",
                fc.width, fc.height, camera.width, camera.height
            ),
        });
    }
    let frame = frame.converted(meta.range_kind);
    let range = quantise("range", frame.range(), meta.metres_per_unit, meta.width, true)?;
    let amplitude =
        quantise("amplitude", frame.amplitude(), meta.amplitude_scale, meta.width, false)?;
    encode_u16(range_png, meta.width, meta.height, &range)?;
    encode_u16(amplitude_png, meta.width, meta.height, &amplitude)
}

/// Writes the frame's confidence image as a 16-bit grayscale PNG (fails if it has none).
pub fn write_confidence_png(frame: &TofFrame, path: &Path) -> Result<(), TofError> {
    let c = frame.confidence().ok_or_else(|| TofError::BadImage {
        what: "confidence",
        why: "the frame has none".into(),
    })?;
    encode_u16(path, frame.camera().width, frame.camera().height, c)
}

/// The frame of an organised cloud of `camera` (the inverse of [`TofFrame::to_cloud`]): each
/// valid pixel's point gives the range of `kind` (its distance from the origin, or its z), the
/// cloud's intensity the amplitude; the fields `confidence` and `tof_intensity`, if present,
/// are kept. So a frame can come from any file `pointcloud::io::read_cloud` reads.
///
/// Fails if the cloud is not organised on the camera's grid, has no intensity, or a point lies
/// behind the camera or more than half a pixel off its pixel's beam (a cloud of another camera
/// or frame).
pub fn frame_from_cloud(
    cloud: &PointCloud,
    camera: &TofCamera,
    kind: RangeKind,
) -> Result<TofFrame, TofError> {
    camera.validate()?;
    let grid = cloud.grid().ok_or_else(|| TofError::Mismatch {
        why: "the cloud is not organised: a frame needs one point per pixel".into(),
    })?;
    if (grid.width(), grid.height()) != (camera.width, camera.height) {
        return Err(TofError::Mismatch {
            why: format!(
                "a {} × {} cloud for a {} × {} camera",
                grid.width(),
                grid.height(),
                camera.width,
                camera.height
            ),
        });
    }
    let intensity = cloud.intensity().ok_or_else(|| TofError::BadImage {
        what: "amplitude",
        why: "the cloud has no intensity (which holds the amplitude)".into(),
    })?;
    let n = camera.num_pixels();
    let mut range = vec![0f32; n];
    let mut amplitude = vec![0f32; n];
    let extra_f32 = |name: &str| match cloud.extra_field(name).map(|f| &f.data) {
        Some(FieldData::F32(v)) => Some(v.as_slice()),
        _ => None,
    };
    let tof_intensity = extra_f32("tof_intensity");
    let confidence = cloud.extra_field("confidence").map(|f| &f.data);
    let mut b = tof_intensity.map(|_| vec![0f32; n]);
    let mut c = confidence.map(|_| vec![0u16; n]);
    let k = camera.intrinsics;
    for (pixel, &index) in grid.pixels().iter().enumerate() {
        if index == pointcloud::INVALID_PIXEL {
            continue;
        }
        let index = index as usize;
        let p = cloud.positions()[index];
        let (col, row) =
            ((pixel % camera.width as usize) as Real, (pixel / camera.width as usize) as Real);
        let norm = p.coords.norm();
        if norm == 0.0 {
            continue;
        }
        let (u, v) = (k.fx * p.x / p.z + k.cx, k.fy * p.y / p.z + k.cy);
        if p.z <= 0.0 || (u - col).abs() > 0.5 || (v - row).abs() > 0.5 {
            return Err(TofError::Mismatch {
                why: format!(
                    "point {index} ({:.3}, {:.3}, {:.3}) of pixel ({col}, {row}) projects to \
                     ({u:.2}, {v:.2}): the cloud is not in this camera's optical frame",
                    p.x, p.y, p.z
                ),
            });
        }
        range[pixel] = match kind {
            RangeKind::Radial => norm as f32,
            RangeKind::Depth => p.z as f32,
        };
        amplitude[pixel] = intensity[index];
        if let (Some(b), Some(src)) = (&mut b, tof_intensity) {
            b[pixel] = src[index];
        }
        if let (Some(c), Some(src)) = (&mut c, confidence) {
            let v = src.get_f64(index).unwrap_or(0.0);
            c[pixel] = v.clamp(0.0, u16::MAX as Real) as u16;
        }
    }
    let mut frame = TofFrame::new(*camera, kind, range, amplitude)?;
    if let Some(b) = b {
        frame = frame.with_intensity(b)?;
    }
    if let Some(c) = c {
        frame = frame.with_confidence(c)?;
    }
    Ok(frame)
}
