//! 3DTK "uos" scans: `scanNNN.3d` point files and `scanNNN.pose` pose files, as written and
//! read by The 3D Toolkit (3DTK, slam6d) and used by its sample data (Kurt3D scans).
//!
//! # The 3DTK frame and units
//! 3DTK stores points in **centimetres** in a **left-handed** frame: x right, y up, z forward.
//! We use metres and the right-handed sensor frame x forward, y left, z up, so
//!
//! ```text
//! (x, y, z)_ours = (z, −x, y)_3dtk / 100        (x, y, z)_3dtk = 100 · (−y, z, x)_ours
//! ```
//!
//! i.e. `p_ours = M p_3dtk / 100` with `M = [[0, 0, 1], [−1, 0, 0], [0, 1, 0]]` (det M = −1: the
//! handedness flips). This is the inverse of 3DTK's own conversion of right-handed, z-up metre
//! data into its frame (`ScanDataTransform_xyz` in `src/scanio/helper.cc`, used by the `xyz`
//! reader for "right-handed coordinate system, with z as height"):
//! `x_3dtk = −100 y`, `y_3dtk = 100 z`, `z_3dtk = 100 x`. The `uos` reader itself applies the
//! identity transform: `.3d` files are in 3DTK's frame already.
//!
//! # `.3d` files
//! One point per line, `x y z` in centimetres, whitespace separated. Extra columns are allowed
//! (every line must have as many as the first): the fourth, if any, is kept as the intensity
//! (reflectance), further ones are checked to be numbers and ignored. Blank lines and `#`
//! comments are skipped, as by 3DTK, and so is an optional first line `W x H` (e.g. `361 x 201`,
//! the "uos header" 3DTK's `uosHeaderTest` skips). Points are returned in the sensor frame,
//! without the pose.
//!
//! The Kurt3D sample scans (SICK LMS) mark "no echo" with readings at the maximum range, about
//! 32.76 m, and contain junk closer than about 0.2 m. [`UosReadOptions::KURT3D`] drops both
//! (keeps 0.2 m ≤ r < 32.75 m); [`UosReadOptions::default`] keeps every point.
//!
//! # `.pose` files
//! Six numbers: the position `x y z` in centimetres and the Euler angles `θx θy θz` in degrees,
//! all in 3DTK's frame (conventionally on two lines). 3DTK turns them into the 4 × 4 matrix of
//! `EulerToMatrix4` (`include/slam6d/globals.icc`), which is
//!
//! ```text
//! R_3dtk = Rx(θx) · Ry(θy) · Rz(θz)        p_world = R_3dtk p_scan + t     (all in 3DTK's frame)
//! ```
//!
//! (its column-major entries: `[8] = sin θy`, `[9] = −sin θx cos θy`, `[10] = cos θx cos θy`,
//! ...; `transform3` applies it as `R p + t`). In our frame the same motion is
//! `R_ours = M R_3dtk Mᵀ` and `t_ours = M t / 100`, a proper rotation since M appears twice. In
//! words: θx turns about our +y axis by θx, θy about our z axis by −θy (yaw = −θy), θz about our x
//! axis by −θz. The pose is `world_from_sensor`, as 3DTK uses it to place the scan.

use super::xyz::{Real, Real32, TextLines, parse_f32, parse_f64, strip_comment};
use super::{Error, ErrorKind, Format, Position, ReadOptions};
use crate::{Isometry3, Point3, PointCloud, Real as Scalar, SensorPose, Vector3};
use na::{Matrix3, Rotation3, Translation3, UnitQuaternion};
use std::io::{BufRead, Write};

const FORMAT: Format = Format::Uos;

/// Options for [`read_uos_scan`].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct UosReadOptions {
    /// Drop points closer than this (metres) to the sensor.
    pub min_range_m: Option<f64>,
    /// Drop points this far (metres) from the sensor or farther.
    pub max_range_m: Option<f64>,
    /// What to do with points that have a NaN or infinite coordinate.
    pub non_finite: ReadOptions,
}

impl Default for UosReadOptions {
    /// Keep every point; a non-finite point is an error.
    fn default() -> UosReadOptions {
        UosReadOptions { min_range_m: None, max_range_m: None, non_finite: ReadOptions::STRICT }
    }
}

impl UosReadOptions {
    /// For the Kurt3D (SICK LMS) sample scans: keep `0.2 m ≤ r < 32.75 m`, dropping the "no echo"
    /// readings at the maximum range (about 32.76 m) and the junk close to the scanner.
    pub const KURT3D: UosReadOptions = UosReadOptions {
        min_range_m: Some(0.2),
        max_range_m: Some(32.75),
        non_finite: ReadOptions::STRICT,
    };
}

/// The axis permutation `M` with `p_ours = M p_3dtk` (before the scale to metres).
fn m() -> Matrix3<Scalar> {
    Matrix3::new(0.0, 0.0, 1.0, -1.0, 0.0, 0.0, 0.0, 1.0, 0.0)
}

/// A point of a `.3d` file (centimetres, 3DTK's left-handed frame) in our frame (metres).
pub fn point_from_uos(cm: [f64; 3]) -> Point3 {
    Point3::new(cm[2] / 100.0, -cm[0] / 100.0, cm[1] / 100.0)
}

/// A point in our frame (metres) as a `.3d` file stores it (centimetres, 3DTK's frame).
pub fn point_to_uos(p: &Point3) -> [f64; 3] {
    [-p.y * 100.0, p.z * 100.0, p.x * 100.0]
}

/// The pose of a `.pose` file (position in centimetres, `θx θy θz` in degrees, 3DTK's frame)
/// as a `world_from_sensor` pose in our frame (see the [module docs](self)).
pub fn pose_from_uos(position_cm: [f64; 3], angles_deg: [f64; 3]) -> SensorPose {
    let [ax, ay, az] = angles_deg.map(f64::to_radians);
    let r3 = *(Rotation3::from_axis_angle(&Vector3::x_axis(), ax)
        * Rotation3::from_axis_angle(&Vector3::y_axis(), ay)
        * Rotation3::from_axis_angle(&Vector3::z_axis(), az))
    .matrix();
    let m = m();
    let r = m * r3 * m.transpose();
    let t = point_from_uos(position_cm);
    let rotation = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
    SensorPose { world_from_sensor: Isometry3::from_parts(Translation3::from(t.coords), rotation) }
}

/// The inverse of [`pose_from_uos`]: position in centimetres and `θx θy θz` in degrees
/// (θy in [−90°, 90°]; at θy = ±90° θx is set to 0).
pub fn pose_to_uos(pose: &SensorPose) -> ([f64; 3], [f64; 3]) {
    let m = m();
    let r = m.transpose() * pose.world_from_sensor.rotation.to_rotation_matrix().matrix() * m;
    let ay = r[(0, 2)].atan2((r[(0, 0)].powi(2) + r[(0, 1)].powi(2)).sqrt());
    let (ax, az) = if r[(0, 0)].abs() + r[(0, 1)].abs() > 1e-12 {
        ((-r[(1, 2)]).atan2(r[(2, 2)]), (-r[(0, 1)]).atan2(r[(0, 0)]))
    } else {
        // Gimbal lock (θy = ±90°): only θx ± θz is defined; take θx = 0.
        (0.0, r[(1, 0)].atan2(r[(1, 1)]))
    };
    let position = point_to_uos(&pose.origin());
    (position, [ax, ay, az].map(f64::to_degrees))
}

/// Whether a line is the optional `W x H` header of a `.3d` file.
fn is_uos_header(line: &str) -> bool {
    let mut parts = line.trim_end().split(' ');
    let digits =
        |s: Option<&str>| s.is_some_and(|s| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit()));
    digits(parts.next())
        && parts.next() == Some("x")
        && digits(parts.next())
        && parts.next().is_none()
}

/// Reads a `.3d` scan: points in our sensor frame (metres, x forward, y left, z up), the
/// fourth column (if any) as intensity. See the [module docs](self).
pub fn read_uos_scan(reader: impl BufRead, options: &UosReadOptions) -> Result<PointCloud, Error> {
    for (name, v) in [("min_range_m", options.min_range_m), ("max_range_m", options.max_range_m)] {
        if v.is_some_and(|v| v.is_nan()) {
            return Err(Error::new(FORMAT, ErrorKind::BadValue(format!("{name} is NaN"))));
        }
    }
    let mut lines = TextLines::new(reader, FORMAT);
    let mut positions = Vec::new();
    let mut intensity = Vec::new();
    let mut columns: Option<usize> = None;
    let mut first_data_line = true;
    let mut point_index = 0u64;
    while let Some((line_no, line)) = lines.next_line()? {
        let at = Position::Line(line_no);
        let data = strip_comment(line);
        if data.trim().is_empty() {
            continue;
        }
        if std::mem::take(&mut first_data_line) && is_uos_header(data) {
            continue;
        }
        let mut xyz = [0.0; 3];
        let mut refl = None;
        let mut n = 0;
        for field in data.split_whitespace() {
            match n {
                0..3 => xyz[n] = parse_f64(field, FORMAT, at)?,
                3 => refl = Some(parse_f32(field, FORMAT, at)?),
                _ => {
                    parse_f64(field, FORMAT, at)?;
                }
            }
            n += 1;
        }
        match columns {
            _ if n < 3 => {
                return Err(Error::at(
                    FORMAT,
                    at,
                    ErrorKind::BadValue(format!("expected at least 3 columns (x y z), found {n}")),
                ));
            }
            None => columns = Some(n),
            Some(c) if c != n => {
                return Err(Error::at(
                    FORMAT,
                    at,
                    ErrorKind::BadValue(format!(
                        "found {n} columns, but the first data line has {c}"
                    )),
                ));
            }
            Some(_) => {}
        }
        let index = point_index;
        point_index += 1;
        if !xyz.iter().all(|v| v.is_finite()) {
            if options.non_finite.skip_non_finite {
                continue;
            }
            return Err(Error::at(FORMAT, at, ErrorKind::NonFinite { point: index }));
        }
        let p = point_from_uos(xyz);
        let r = p.coords.norm();
        if options.min_range_m.is_some_and(|min| r < min)
            || options.max_range_m.is_some_and(|max| r >= max)
        {
            continue;
        }
        positions.push(p);
        if let Some(i) = refl {
            intensity.push(i);
        }
    }
    let cloud_err = |e| Error::new(FORMAT, e);
    let mut cloud = PointCloud::from_positions(positions).map_err(cloud_err)?;
    if columns.is_some_and(|c| c >= 4) {
        cloud.set_intensity(Some(intensity)).map_err(cloud_err)?;
    }
    Ok(cloud)
}

/// Writes `cloud` as a `.3d` scan: its positions (in the cloud's own frame; the sensor pose is
/// not applied, write it with [`write_uos_pose`]) converted to centimetres in 3DTK's frame, and
/// the intensity as a fourth column when present.
pub fn write_uos_scan(writer: impl Write, cloud: &PointCloud) -> Result<(), Error> {
    let mut w = std::io::BufWriter::new(writer);
    let io = |e: std::io::Error| Error::new(FORMAT, e);
    let intensity = cloud.intensity();
    for (k, p) in cloud.positions().iter().enumerate() {
        let [x, y, z] = point_to_uos(p);
        write!(w, "{} {} {}", Real(x), Real(y), Real(z)).map_err(io)?;
        if let Some(i) = intensity {
            write!(w, " {}", Real32(i[k])).map_err(io)?;
        }
        w.write_all(b"\n").map_err(io)?;
    }
    w.flush().map_err(io)
}

/// Reads a `.pose` file: six numbers (position in cm, Euler angles in degrees, 3DTK's frame),
/// returned as a `world_from_sensor` pose in our frame (see the [module docs](self)).
pub fn read_uos_pose(reader: impl BufRead) -> Result<SensorPose, Error> {
    let mut lines = TextLines::new(reader, FORMAT);
    let mut values = [0.0; 6];
    let mut n = 0;
    let mut last_line = 0;
    while let Some((line_no, line)) = lines.next_line()? {
        last_line = line_no;
        let at = Position::Line(line_no);
        for field in strip_comment(line).split_whitespace() {
            let v = parse_f64(field, FORMAT, at)?;
            if n == 6 {
                return Err(Error::at(
                    FORMAT,
                    at,
                    ErrorKind::BadValue("more than 6 numbers in a pose file".into()),
                ));
            }
            if !v.is_finite() {
                return Err(Error::at(
                    FORMAT,
                    at,
                    ErrorKind::BadValue(format!("pose value `{field}` is not finite")),
                ));
            }
            values[n] = v;
            n += 1;
        }
    }
    if n < 6 {
        return Err(Error::at(
            FORMAT,
            Position::Line(last_line.max(1)),
            ErrorKind::UnexpectedEof {
                expected: format!("6 pose numbers (x y z θx θy θz), found {n}"),
            },
        ));
    }
    Ok(pose_from_uos([values[0], values[1], values[2]], [values[3], values[4], values[5]]))
}

/// Writes a `.pose` file: `x y z` (cm) on the first line, `θx θy θz` (degrees) on the second,
/// in 3DTK's frame (see [`pose_to_uos`]).
pub fn write_uos_pose(mut writer: impl Write, pose: &SensorPose) -> Result<(), Error> {
    if !pose.is_finite() {
        return Err(Error::new(FORMAT, ErrorKind::BadValue("the pose is not finite".into())));
    }
    let (t, a) = pose_to_uos(pose);
    writeln!(
        writer,
        "{} {} {}\n{} {} {}",
        Real(t[0]),
        Real(t[1]),
        Real(t[2]),
        Real(a[0]),
        Real(a[1]),
        Real(a[2])
    )
    .map_err(|e| Error::new(FORMAT, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uos_header_is_recognised() {
        assert!(is_uos_header("361 x 201"));
        assert!(is_uos_header("361 x 201\r"));
        assert!(!is_uos_header("361 0 201"));
        assert!(!is_uos_header("361 x"));
        assert!(!is_uos_header("1.5 x 2"));
    }

    #[test]
    fn frame_conversion_matches_3dtk_xyz_transform() {
        // 3DTK's ScanDataTransform_xyz takes right-handed z-up metres (x, y, z) to
        // (−100 y, 100 z, 100 x); reading that back must give the original point.
        let ours = Point3::new(1.5, -2.0, 0.25);
        let tk = [-100.0 * ours.y, 100.0 * ours.z, 100.0 * ours.x];
        assert_eq!(point_from_uos(tk), ours);
        assert_eq!(point_to_uos(&ours), tk);
    }

    #[test]
    fn pose_matches_euler_to_matrix4() {
        // EulerToMatrix4's column-major entries, written out as in globals.icc.
        let (ax, ay, az) = (0.3_f64, -0.7_f64, 1.1_f64);
        let (sx, cx, sy, cy, sz, cz) = (ax.sin(), ax.cos(), ay.sin(), ay.cos(), az.sin(), az.cos());
        let a = [
            cy * cz,
            sx * sy * cz + cx * sz,
            -cx * sy * cz + sx * sz,
            -cy * sz,
            -sx * sy * sz + cx * cz,
            cx * sy * sz + sx * cz,
            sy,
            -sx * cy,
            cx * cy,
        ];
        let t = [12.0, -30.0, 250.0];
        // transform3: p' = R p + t with R[i][j] = a[i + 3 j].
        let p3 = [40.0, -5.0, 120.0];
        let q3: Vec<f64> =
            (0..3).map(|i| (0..3).map(|j| a[i + 3 * j] * p3[j]).sum::<f64>() + t[i]).collect();
        let pose = pose_from_uos(t, [ax, ay, az].map(f64::to_degrees));
        let q = pose.world_from_sensor * point_from_uos(p3);
        assert!((q - point_from_uos([q3[0], q3[1], q3[2]])).norm() < 1e-12);
        let (t2, a2) = pose_to_uos(&pose);
        for k in 0..3 {
            assert!((t2[k] - t[k]).abs() < 1e-9);
            assert!((a2[k].to_radians() - [ax, ay, az][k]).abs() < 1e-9);
        }
    }
}
