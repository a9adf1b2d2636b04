//! Simulated range sensors with per-pixel ground truth.
//!
//! The three sensors of the thesis's Table 2.1 that see the scenes of this crate:
//!
//! | sensor | model | pixels | field of view | range | beams | what it reports |
//! |---|---|---|---|---|---|---|
//! | [`Alrf`] | SICK S300 on a pitching servo (§2.1, §3.2) | 541 × 361 | 270° × 180° | 0–20 m | [`BeamModel::ActuatedLrf`] | radial range |
//! | [`RangeCamera`] | SwissRanger SR-3000 (§2.3) | 176 × 144 | 47° × 39° | 0.6–7.5 m | pinhole | depth (distance to the image plane) |
//! | [`StereoCamera`] | Videre STOC (§2.2) | 640 × 480 | 65.5° × 51.5° | 0.686 m – | pinhole | depth |
//!
//! Every sensor implements [`RangeSensor`]: `scan(scene, pose, seed)` casts one ray per pixel
//! through the scene's hierarchy and returns a [`SimulatedScan`]: the measured [`RangeImage`]
//! in the sensor frame, the pose, and [`GroundTruth`] per pixel (surface, true range,
//! incidence cosine, reflectivity). The same seed gives the same scan, bit for bit.
//!
//! # Frames
//! The laser scanner uses x forward, y left, z up. Cameras use the optical frame (x right,
//! y down, z forward), so a camera's `world_from_sensor` includes the optical rotation: place a
//! camera with [`camera_pose_looking`] or [`camera_pose_from_body`], or with
//! [`RangeSensor::mount`], which does the right thing for each sensor given a robot-style body
//! pose (x forward, z up) such as [`crate::Scene::scan_poses`] returns.
//!
//! # What is simplified
//! Beams are infinitely thin rays (apart from the scanner's mixed pixels), all pixels of a scan
//! are taken at once (no motion during the ALRF's ten-second sweep), surfaces are Lambertian
//! without multipath or specular reflection, the sensor's own body is not seen, and noise is
//! independent Gaussian per pixel. The range camera has no time-of-flight effects: a ToF model
//! (amplitude, wrap-around, amplitude thresholds) builds on [`RangeCamera::scan_hits`].

mod alrf;
mod range_camera;
mod stereo;

pub use alrf::{Alrf, AlrfConfig, MixedPixelConfig};
pub use range_camera::{RangeCamera, RangeCameraConfig};
pub use stereo::{StereoCamera, StereoCameraConfig};

use crate::{Scene, SensorError, SurfaceId, UnitVector3};
use pointcloud::{
    BeamModel, Isometry3, Point3, PointCloud, RangeImage, RangeImageError, Real, SensorPose,
    Vector3,
};

/// The largest number of pixels a sensor configuration may ask for (2²⁴).
pub const MAX_PIXELS: u64 = 1 << 24;

/// A simulated range sensor.
///
/// Implementations are deterministic: the same scene, pose and seed give the same scan.
pub trait RangeSensor {
    /// One scan of `scene` from `pose` (`world_from_sensor` in the sensor's own frame, see the
    /// module docs), with noise drawn from `seed`.
    fn scan(&self, scene: &Scene, pose: &SensorPose, seed: u64) -> SimulatedScan;

    /// The sensor pose of this sensor mounted on a robot body at `body_pose` (x forward, y left,
    /// z up), looking along the body's x axis. Laser scanners use the body frame itself (the
    /// default); cameras add the optical rotation ([`camera_pose_from_body`]).
    fn mount(&self, body_pose: &SensorPose) -> SensorPose {
        *body_pose
    }
}

impl<S: RangeSensor + ?Sized> RangeSensor for &S {
    fn scan(&self, scene: &Scene, pose: &SensorPose, seed: u64) -> SimulatedScan {
        (**self).scan(scene, pose, seed)
    }

    fn mount(&self, body_pose: &SensorPose) -> SensorPose {
        (**self).mount(body_pose)
    }
}

/// Per-pixel ground truth of a scan, row-major like the image. A pixel has truth when its beam
/// hits a surface within the sensor's casting limit, whether or not the sensor reported a
/// measurement there (dropouts, out-of-range, too dark).
#[derive(Clone, Debug, PartialEq)]
pub struct GroundTruth {
    /// The surface the beam hits.
    pub surface: Vec<Option<SurfaceId>>,
    /// The noise-free range, in the image's [`pointcloud::RangeKind`] (radial for the scanner,
    /// depth for cameras).
    pub true_range: Vec<Option<f32>>,
    /// Cosine of the angle between beam and surface normal.
    pub incidence_cos: Vec<Option<f32>>,
    /// The surface's near-infrared reflectivity.
    pub reflectivity: Vec<Option<f32>>,
    /// Whether the reported range is a mixed pixel (a blend of two surfaces at an edge).
    pub mixed_pixel: Vec<bool>,
}

impl GroundTruth {
    fn with_len(n: usize) -> GroundTruth {
        GroundTruth {
            surface: vec![None; n],
            true_range: vec![None; n],
            incidence_cos: vec![None; n],
            reflectivity: vec![None; n],
            mixed_pixel: vec![false; n],
        }
    }

    fn set(&mut self, i: usize, hit: &BeamHit, true_range: Real) {
        self.surface[i] = Some(hit.surface);
        self.true_range[i] = Some(true_range as f32);
        self.incidence_cos[i] = Some(hit.incidence_cos as f32);
        self.reflectivity[i] = Some(hit.reflectivity);
    }
}

/// A simulated scan: what the sensor reported, where it was, and the truth.
#[derive(Clone, Debug, PartialEq)]
pub struct SimulatedScan {
    /// The measured ranges in the sensor frame.
    pub image: RangeImage,
    /// The sensor pose the scan was taken from.
    pub pose: SensorPose,
    /// Per-pixel ground truth.
    pub truth: GroundTruth,
}

impl SimulatedScan {
    /// The organised point cloud of the measurements, in the sensor frame with
    /// [`PointCloud::sensor_pose`] set, and labels = the [`SurfaceId`] each point's beam hit.
    pub fn to_cloud(&self) -> Result<PointCloud, RangeImageError> {
        let mut cloud = self.image.to_cloud()?;
        let labels: Vec<u32> = self
            .image
            .ranges()
            .iter()
            .zip(&self.truth.surface)
            .filter(|(r, _)| r.is_some())
            .map(|(_, s)| s.map_or(u32::MAX, |s| s.0))
            .collect();
        cloud.set_labels(Some(labels))?;
        cloud.set_sensor_pose(Some(self.pose));
        Ok(cloud)
    }

    /// The fraction of pixels with a measurement (the thesis's "valid ratio", Table 3.1).
    pub fn valid_ratio(&self) -> Real {
        let n = self.image.ranges().len();
        if n == 0 { 0.0 } else { self.image.num_valid() as Real / n as Real }
    }
}

/// What one beam hit, before any sensor effect: the hook for sensor models built elsewhere
/// (a time-of-flight model computes amplitude and wrapped range from these).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct BeamHit {
    /// Euclidean distance from the sensor origin, metres.
    pub range: Real,
    /// The unit beam direction in the sensor frame.
    pub direction: Vector3,
    /// Cosine of the angle between beam and surface normal.
    pub incidence_cos: Real,
    /// Near-infrared reflectivity of the surface.
    pub reflectivity: f32,
    /// Whether the surface is textured.
    pub textured: bool,
    /// The surface hit.
    pub surface: SurfaceId,
}

/// One noise-free ray per pixel: what each beam of a sensor hits.
#[derive(Clone, Debug, PartialEq)]
pub struct HitImage {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// The beam model giving each pixel's direction.
    pub beams: BeamModel,
    /// The sensor pose.
    pub pose: SensorPose,
    /// The casting limit used, metres.
    pub max_range: Real,
    /// Per pixel (row-major) the hit, if any within `max_range`.
    pub hits: Vec<Option<BeamHit>>,
}

fn lerp_index(start: Real, end: Real, i: u32, n: u32) -> Real {
    if n <= 1 { start } else { start + (end - start) * i as Real / (n - 1) as Real }
}

/// Calls `f(pixel_index, unit_direction_in_sensor_frame)` for every pixel, row-major. Equals
/// [`BeamModel::direction`] but evaluates the trigonometry once per row and column.
pub(crate) fn for_each_direction(
    beams: &BeamModel,
    width: u32,
    height: u32,
    mut f: impl FnMut(usize, Vector3),
) {
    let (w, h) = (width as usize, height as usize);
    match beams {
        BeamModel::Pinhole(_) => {
            for row in 0..height {
                for col in 0..width {
                    f(row as usize * w + col as usize, beams.direction(col, row, width, height));
                }
            }
        }
        BeamModel::Spherical(s) => {
            let cols: Vec<(Real, Real)> = (0..width)
                .map(|c| lerp_index(s.azimuth_start, s.azimuth_end, c, width).sin_cos())
                .collect();
            for row in 0..h {
                let (se, ce) =
                    lerp_index(s.elevation_top, s.elevation_bottom, row as u32, height).sin_cos();
                for (col, &(sa, ca)) in cols.iter().enumerate() {
                    f(row * w + col, Vector3::new(ce * ca, ce * sa, se));
                }
            }
        }
        BeamModel::ActuatedLrf(m) => {
            let cols: Vec<(Real, Real)> = (0..width)
                .map(|c| lerp_index(m.beam_start, m.beam_end, c, width).sin_cos())
                .collect();
            for row in 0..h {
                let (sp, cp) =
                    lerp_index(m.pitch_top, m.pitch_bottom, row as u32, height).sin_cos();
                for (col, &(st, ct)) in cols.iter().enumerate() {
                    f(row * w + col, Vector3::new(ct * cp, st, ct * sp));
                }
            }
        }
    }
}

/// Casts one ray per pixel of a `width × height` image with beam model `beams` from `pose`,
/// up to `max_range` metres: the noise-free core every sensor model starts from.
pub fn trace_image(
    scene: &Scene,
    pose: &SensorPose,
    beams: &BeamModel,
    width: u32,
    height: u32,
    max_range: Real,
) -> HitImage {
    let n = width as usize * height as usize;
    let mut hits = vec![None; n];
    let m = &pose.world_from_sensor;
    let origin: Point3 = m.translation.vector.into();
    let rotation = m.rotation.to_rotation_matrix();
    for_each_direction(beams, width, height, |i, d| {
        let dir = UnitVector3::new_unchecked(rotation * d);
        hits[i] = scene.cast_ray(&origin, &dir, max_range).map(|h| BeamHit {
            range: h.distance,
            direction: d,
            incidence_cos: h.incidence_cos,
            reflectivity: h.reflectivity,
            textured: h.textured,
            surface: h.surface,
        });
    });
    HitImage { width, height, beams: *beams, pose: *pose, max_range, hits }
}

/// One scan per pose; scan `i` uses the seed [`derive_seed`]`(seed, i)`, so scans differ in
/// their noise and the whole set is reproducible from `seed`.
pub fn scan_many<S: RangeSensor + ?Sized>(
    sensor: &S,
    scene: &Scene,
    poses: &[SensorPose],
    seed: u64,
) -> Vec<SimulatedScan> {
    poses
        .iter()
        .enumerate()
        .map(|(i, pose)| sensor.scan(scene, pose, derive_seed(seed, i as u64)))
        .collect()
}

const SENSOR_NAMES: &[&str] = &["alrf", "alrf-1deg", "alrf-2deg", "alrf-5deg", "sr3000", "stoc"];

/// The names [`sensor_by_name`] knows.
pub fn sensor_names() -> &'static [&'static str] {
    SENSOR_NAMES
}

/// A preset sensor by name, for the command line:
///
/// | name | sensor |
/// |---|---|
/// | `alrf` | [`Alrf::sick_s300`], 541 × 361 beams (0.5° steps) |
/// | `alrf-1deg`, `alrf-2deg`, `alrf-5deg` | [`AlrfConfig::sick_s300_with_step`] at 1°, 2°, 5° |
/// | `sr3000` | [`RangeCamera::swissranger_sr3000`] |
/// | `stoc` | [`StereoCamera::stoc`] |
pub fn sensor_by_name(name: &str) -> Result<Box<dyn RangeSensor + Send + Sync>, SensorError> {
    let alrf_step = |deg: Real| -> Result<Box<dyn RangeSensor + Send + Sync>, SensorError> {
        Ok(Box::new(Alrf::new(AlrfConfig::sick_s300_with_step(deg.to_radians())?)?))
    };
    match name {
        "alrf" => Ok(Box::new(Alrf::sick_s300())),
        "alrf-1deg" => alrf_step(1.0),
        "alrf-2deg" => alrf_step(2.0),
        "alrf-5deg" => alrf_step(5.0),
        "sr3000" => Ok(Box::new(RangeCamera::swissranger_sr3000())),
        "stoc" => Ok(Box::new(StereoCamera::stoc())),
        _ => Err(SensorError::UnknownSensor {
            name: name.to_owned(),
            known: SENSOR_NAMES.join(", "),
        }),
    }
}

/// A well-mixed seed for item `index` of a run seeded with `seed` (SplitMix64 finaliser).
pub fn derive_seed(seed: u64, index: u64) -> u64 {
    let mut z = seed ^ index.wrapping_add(1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The rotation taking camera optical-frame vectors (x right, y down, z forward) to the body
/// frame (x forward, y left, z up).
pub fn body_from_optical() -> nalgebra::UnitQuaternion<Real> {
    let m = nalgebra::Matrix3::new(0.0, 0.0, 1.0, -1.0, 0.0, 0.0, 0.0, -1.0, 0.0);
    nalgebra::UnitQuaternion::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(m))
}

/// The pose of a camera whose optical axis looks along the body pose's x axis (image right =
/// body −y, image down = body −z).
pub fn camera_pose_from_body(body_pose: &SensorPose) -> SensorPose {
    SensorPose {
        world_from_sensor: body_pose.world_from_sensor
            * Isometry3::from_parts(nalgebra::Translation3::identity(), body_from_optical()),
    }
}

/// The pose of a camera at `position` looking in the direction of heading `yaw` (radians,
/// counter-clockwise from world +x about +z) tilted up by `pitch` (radians; negative looks
/// down), with the image's horizontal axis level.
pub fn camera_pose_looking(position: Point3, yaw: Real, pitch: Real) -> SensorPose {
    let body = SensorPose::from_position_rpy(position, 0.0, -pitch, yaw);
    camera_pose_from_body(&body)
}

pub(crate) fn check_size(width: u32, height: u32) -> Result<(), SensorError> {
    let n = width as u64 * height as u64;
    if n == 0 || n > MAX_PIXELS {
        return Err(SensorError::ImageSize { width, height });
    }
    Ok(())
}

pub(crate) fn check_range(
    what: &'static str,
    value: Real,
    lo: Real,
    hi: Real,
    allowed: &'static str,
) -> Result<(), SensorError> {
    if !(value.is_finite() && lo <= value && value <= hi) {
        return Err(SensorError::BadParameter { what, value, allowed });
    }
    Ok(())
}

/// Builds the range image; the sensors only ever produce finite non-negative ranges of the
/// right count with a matching beam model and kind, so this cannot fail.
pub(crate) fn make_image(
    width: u32,
    height: u32,
    beams: BeamModel,
    kind: pointcloud::RangeKind,
    ranges: Vec<Option<f32>>,
) -> RangeImage {
    match RangeImage::new(width, height, beams, kind, ranges) {
        Ok(image) => image,
        Err(e) => unreachable!("sensor produced an invalid range image: {e}"),
    }
}
