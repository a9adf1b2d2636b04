//! Point clouds with optional per-point attributes and an optional image organisation.

use crate::{Aabb, Point3, SensorPose, Vector3};
use serde::{Deserialize, Serialize};

/// Marks a pixel without a measurement in [`Grid`]'s pixel table.
pub const INVALID_PIXEL: u32 = u32::MAX;

/// The values of one per-point scalar field, in the type the file stored them in.
///
/// Keeping the stored type makes round trips exact (a packed PCD `rgb` float stays bit for bit
/// the same, a PLY `uchar` stays a byte).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[allow(missing_docs)]
pub enum FieldData {
    I8(Vec<i8>),
    U8(Vec<u8>),
    I16(Vec<i16>),
    U16(Vec<u16>),
    I32(Vec<i32>),
    U32(Vec<u32>),
    F32(Vec<f32>),
    F64(Vec<f64>),
}

macro_rules! for_each_field {
    ($data:expr, $v:ident => $body:expr) => {
        match $data {
            FieldData::I8($v) => $body,
            FieldData::U8($v) => $body,
            FieldData::I16($v) => $body,
            FieldData::U16($v) => $body,
            FieldData::I32($v) => $body,
            FieldData::U32($v) => $body,
            FieldData::F32($v) => $body,
            FieldData::F64($v) => $body,
        }
    };
}

#[allow(clippy::unnecessary_cast)] // the macro body is shared by every variant, f64 included
fn field_as_f64(data: &FieldData, i: usize) -> Option<f64> {
    for_each_field!(data, v => v.get(i).map(|&x| x as f64))
}

impl FieldData {
    /// The number of values.
    pub fn len(&self) -> usize {
        for_each_field!(self, v => v.len())
    }

    /// Whether there are no values.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Value `i` as `f64` (exact for every stored type).
    pub fn get_f64(&self, i: usize) -> Option<f64> {
        field_as_f64(self, i)
    }

    /// An empty field of the same type.
    pub fn empty_like(&self) -> FieldData {
        match self {
            FieldData::I8(_) => FieldData::I8(Vec::new()),
            FieldData::U8(_) => FieldData::U8(Vec::new()),
            FieldData::I16(_) => FieldData::I16(Vec::new()),
            FieldData::U16(_) => FieldData::U16(Vec::new()),
            FieldData::I32(_) => FieldData::I32(Vec::new()),
            FieldData::U32(_) => FieldData::U32(Vec::new()),
            FieldData::F32(_) => FieldData::F32(Vec::new()),
            FieldData::F64(_) => FieldData::F64(Vec::new()),
        }
    }

    /// Appends value `i` of `other` (which must have the same type) to `self`.
    ///
    /// # Panics
    /// If the types differ or `i` is out of range: callers pair fields of one cloud.
    fn push_from(&mut self, other: &FieldData, i: usize) {
        match (self, other) {
            (FieldData::I8(a), FieldData::I8(b)) => a.push(b[i]),
            (FieldData::U8(a), FieldData::U8(b)) => a.push(b[i]),
            (FieldData::I16(a), FieldData::I16(b)) => a.push(b[i]),
            (FieldData::U16(a), FieldData::U16(b)) => a.push(b[i]),
            (FieldData::I32(a), FieldData::I32(b)) => a.push(b[i]),
            (FieldData::U32(a), FieldData::U32(b)) => a.push(b[i]),
            (FieldData::F32(a), FieldData::F32(b)) => a.push(b[i]),
            (FieldData::F64(a), FieldData::F64(b)) => a.push(b[i]),
            _ => unreachable!("push_from pairs fields of one type"),
        }
    }
}

/// A named per-point scalar field that has no dedicated slot in [`PointCloud`] (colour, curvature,
/// timestamps, anything a file carried).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ScalarField {
    /// The property name as the file spelled it.
    pub name: String,
    /// One value per point.
    pub data: FieldData,
}

/// The image a cloud came from: `width × height` pixels in row-major order, row 0 at the top.
///
/// Every pixel either names the index of its point in the cloud or is explicitly invalid (no
/// measurement). Valid pixels map to distinct points, and every point has exactly one pixel.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Grid {
    width: u32,
    height: u32,
    /// Per pixel: the point index, or [`INVALID_PIXEL`].
    pixels: Vec<u32>,
}

impl Grid {
    /// A grid from its pixel table. Fails unless `pixels.len() == width * height`, every valid
    /// entry is below `num_points`, no two pixels share a point and every point has a pixel.
    pub fn new(
        width: u32,
        height: u32,
        pixels: Vec<u32>,
        num_points: usize,
    ) -> Result<Grid, AttributeError> {
        let expected = width as u64 * height as u64;
        if pixels.len() as u64 != expected {
            return Err(AttributeError::GridSize { width, height, len: pixels.len() });
        }
        let mut seen = vec![false; num_points];
        let mut count = 0usize;
        for &p in &pixels {
            if p == INVALID_PIXEL {
                continue;
            }
            let slot = seen
                .get_mut(p as usize)
                .ok_or(AttributeError::GridIndex { index: p, num_points })?;
            if *slot {
                return Err(AttributeError::GridDuplicate { index: p });
            }
            *slot = true;
            count += 1;
        }
        if count != num_points {
            return Err(AttributeError::GridUncovered { valid: count, num_points });
        }
        Ok(Grid { width, height, pixels })
    }

    /// Image width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Image height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The number of pixels, valid or not.
    pub fn num_pixels(&self) -> usize {
        self.pixels.len()
    }

    /// The number of valid pixels.
    pub fn num_valid(&self) -> usize {
        self.pixels.iter().filter(|&&p| p != INVALID_PIXEL).count()
    }

    /// The point index of pixel (`col`, `row`), or `None` if the pixel has no measurement or
    /// lies outside the image.
    pub fn point_index(&self, col: u32, row: u32) -> Option<usize> {
        if col >= self.width || row >= self.height {
            return None;
        }
        let p = self.pixels[row as usize * self.width as usize + col as usize];
        (p != INVALID_PIXEL).then_some(p as usize)
    }

    /// The raw pixel table: per pixel the point index or [`INVALID_PIXEL`].
    pub fn pixels(&self) -> &[u32] {
        &self.pixels
    }
}

/// Why a cloud attribute was refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum AttributeError {
    /// An attribute has a different number of values than the cloud has points.
    #[error("attribute `{name}` has {len} values but the cloud has {num_points} points")]
    Length {
        /// The attribute name.
        name: String,
        /// Its number of values.
        len: usize,
        /// The number of points.
        num_points: usize,
    },
    /// A position is NaN or infinite.
    #[error("point {index} is not finite")]
    NonFinite {
        /// The offending point index.
        index: usize,
    },
    /// The grid's pixel table does not have `width × height` entries.
    #[error("grid {width}×{height} needs {} pixels, got {len}", *width as u64 * *height as u64)]
    GridSize {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
        /// Pixel table length.
        len: usize,
    },
    /// A pixel names a point that does not exist.
    #[error("grid pixel names point {index}, but the cloud has {num_points} points")]
    GridIndex {
        /// The index named.
        index: u32,
        /// The number of points.
        num_points: usize,
    },
    /// Two pixels name the same point.
    #[error("two grid pixels name point {index}")]
    GridDuplicate {
        /// The index named twice.
        index: u32,
    },
    /// Some points have no pixel.
    #[error("grid has {valid} valid pixels but the cloud has {num_points} points")]
    GridUncovered {
        /// Valid pixels.
        valid: usize,
        /// Points.
        num_points: usize,
    },
    /// A field name is used twice.
    #[error("field `{name}` is present twice")]
    DuplicateField {
        /// The name.
        name: String,
    },
}

/// A set of 3D points with optional per-point attributes.
///
/// # Invariants
/// * every position is finite (measurements that are missing live in the [`Grid`] as invalid
///   pixels, never as NaN points);
/// * every attribute present has exactly one value per point;
/// * the grid, if any, maps its valid pixels one-to-one onto the points.
///
/// The setters check these and return [`AttributeError`]; the fields are private so the
/// invariants hold for every cloud a function receives.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PointCloud {
    positions: Vec<Point3>,
    intensity: Option<Vec<f32>>,
    normals: Option<Vec<Vector3>>,
    labels: Option<Vec<u32>>,
    rings: Option<Vec<u16>>,
    extra: Vec<ScalarField>,
    grid: Option<Grid>,
    sensor_pose: Option<SensorPose>,
}

fn check_len(name: &str, len: usize, num_points: usize) -> Result<(), AttributeError> {
    if len == num_points {
        Ok(())
    } else {
        Err(AttributeError::Length { name: name.to_owned(), len, num_points })
    }
}

impl PointCloud {
    /// An empty cloud.
    pub fn new() -> PointCloud {
        PointCloud::default()
    }

    /// A cloud of the given positions, which must all be finite.
    pub fn from_positions(positions: Vec<Point3>) -> Result<PointCloud, AttributeError> {
        if let Some(index) = positions.iter().position(|p| !p.coords.iter().all(|v| v.is_finite()))
        {
            return Err(AttributeError::NonFinite { index });
        }
        Ok(PointCloud { positions, ..PointCloud::default() })
    }

    /// The number of points.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// Whether the cloud has no point.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// The point positions, in the cloud's frame (see [`PointCloud::sensor_pose`]).
    pub fn positions(&self) -> &[Point3] {
        &self.positions
    }

    /// The point positions, dropping every other attribute.
    pub fn into_positions(self) -> Vec<Point3> {
        self.positions
    }

    /// Per-point intensity, reflectance or amplitude, if known.
    pub fn intensity(&self) -> Option<&[f32]> {
        self.intensity.as_deref()
    }

    /// Per-point normals, if known (not necessarily unit length: files store what they store).
    pub fn normals(&self) -> Option<&[Vector3]> {
        self.normals.as_deref()
    }

    /// Per-point labels (surface or class ids), if known.
    pub fn labels(&self) -> Option<&[u32]> {
        self.labels.as_deref()
    }

    /// Per-point ring (laser channel) of a spinning lidar, if known.
    pub fn rings(&self) -> Option<&[u16]> {
        self.rings.as_deref()
    }

    /// Further named scalar fields the cloud carries.
    pub fn extra_fields(&self) -> &[ScalarField] {
        &self.extra
    }

    /// The extra field called `name`, if present.
    pub fn extra_field(&self, name: &str) -> Option<&ScalarField> {
        self.extra.iter().find(|f| f.name == name)
    }

    /// The image organisation, if the cloud is organised.
    pub fn grid(&self) -> Option<&Grid> {
        self.grid.as_ref()
    }

    /// Where the sensor was: `world_from_sensor` takes this cloud's points to the world frame.
    /// `None` means the points are already in the world frame.
    pub fn sensor_pose(&self) -> Option<&SensorPose> {
        self.sensor_pose.as_ref()
    }

    /// The bounding box of the positions (in the cloud's own frame).
    pub fn bounds(&self) -> Aabb {
        Aabb::from_points(&self.positions)
    }

    /// Sets the intensity, one value per point.
    pub fn set_intensity(&mut self, values: Option<Vec<f32>>) -> Result<(), AttributeError> {
        if let Some(v) = &values {
            check_len("intensity", v.len(), self.len())?;
        }
        self.intensity = values;
        Ok(())
    }

    /// Sets the normals, one per point.
    pub fn set_normals(&mut self, values: Option<Vec<Vector3>>) -> Result<(), AttributeError> {
        if let Some(v) = &values {
            check_len("normals", v.len(), self.len())?;
        }
        self.normals = values;
        Ok(())
    }

    /// Sets the labels, one per point.
    pub fn set_labels(&mut self, values: Option<Vec<u32>>) -> Result<(), AttributeError> {
        if let Some(v) = &values {
            check_len("labels", v.len(), self.len())?;
        }
        self.labels = values;
        Ok(())
    }

    /// Sets the rings, one per point.
    pub fn set_rings(&mut self, values: Option<Vec<u16>>) -> Result<(), AttributeError> {
        if let Some(v) = &values {
            check_len("rings", v.len(), self.len())?;
        }
        self.rings = values;
        Ok(())
    }

    /// Adds an extra scalar field (one value per point, a name not used yet).
    pub fn push_extra_field(&mut self, field: ScalarField) -> Result<(), AttributeError> {
        check_len(&field.name, field.data.len(), self.len())?;
        if self.extra_field(&field.name).is_some() {
            return Err(AttributeError::DuplicateField { name: field.name });
        }
        self.extra.push(field);
        Ok(())
    }

    /// Removes and returns the extra field called `name`.
    pub fn take_extra_field(&mut self, name: &str) -> Option<ScalarField> {
        let i = self.extra.iter().position(|f| f.name == name)?;
        Some(self.extra.remove(i))
    }

    /// Organises the cloud as an image (see [`Grid::new`] for what is checked), or makes it
    /// unorganised with `None`.
    pub fn set_grid(&mut self, grid: Option<Grid>) -> Result<(), AttributeError> {
        if let Some(g) = &grid
            && g.num_valid() != self.len()
        {
            return Err(AttributeError::GridUncovered {
                valid: g.num_valid(),
                num_points: self.len(),
            });
        }
        self.grid = grid;
        Ok(())
    }

    /// Sets where the sensor was.
    pub fn set_sensor_pose(&mut self, pose: Option<SensorPose>) {
        self.sensor_pose = pose;
    }

    /// The cloud with its points moved to the world frame by the sensor pose (which is then
    /// `None`). Normals are rotated along.
    pub fn to_world(&self) -> PointCloud {
        let mut out = self.clone();
        if let Some(pose) = out.sensor_pose.take() {
            let m = pose.world_from_sensor;
            for p in &mut out.positions {
                *p = m * *p;
            }
            if let Some(ns) = &mut out.normals {
                for n in ns {
                    *n = m.rotation * *n;
                }
            }
        }
        out
    }

    /// This cloud with its points moved to `positions` (one per point, all finite), every
    /// attribute, the grid and the pose kept.
    ///
    /// # Errors
    /// [`AttributeError::Length`] for a wrong count, [`AttributeError::NonFinite`].
    pub fn with_positions(&self, positions: Vec<Point3>) -> Result<PointCloud, AttributeError> {
        check_len("positions", positions.len(), self.len())?;
        if let Some(index) = positions.iter().position(|p| !p.coords.iter().all(|v| v.is_finite()))
        {
            return Err(AttributeError::NonFinite { index });
        }
        Ok(PointCloud { positions, ..self.clone() })
    }

    /// Keeps the points for which `keep(index)` is true, with all their attributes. The grid
    /// marks the pixels of dropped points invalid.
    pub fn retain_indices(&self, mut keep: impl FnMut(usize) -> bool) -> PointCloud {
        let mut new_index = vec![INVALID_PIXEL; self.len()];
        let mut kept = Vec::new();
        for (i, slot) in new_index.iter_mut().enumerate() {
            if keep(i) {
                *slot = kept.len() as u32;
                kept.push(i);
            }
        }
        fn pick<T: Copy>(kept: &[usize], v: &[T]) -> Vec<T> {
            kept.iter().map(|&i| v[i]).collect()
        }
        let extra = self
            .extra
            .iter()
            .map(|f| {
                let mut data = f.data.empty_like();
                for &i in &kept {
                    data.push_from(&f.data, i);
                }
                ScalarField { name: f.name.clone(), data }
            })
            .collect();
        let grid = self.grid.as_ref().map(|g| Grid {
            width: g.width,
            height: g.height,
            pixels: g
                .pixels
                .iter()
                .map(|&p| if p == INVALID_PIXEL { p } else { new_index[p as usize] })
                .collect(),
        });
        PointCloud {
            positions: pick(&kept, &self.positions),
            intensity: self.intensity.as_deref().map(|v| pick(&kept, v)),
            normals: self.normals.as_deref().map(|v| pick(&kept, v)),
            labels: self.labels.as_deref().map(|v| pick(&kept, v)),
            rings: self.rings.as_deref().map(|v| pick(&kept, v)),
            extra,
            grid,
            sensor_pose: self.sensor_pose,
        }
    }

    /// An organised cloud from one entry per pixel (row-major, `width × height` entries), `None`
    /// for pixels without a measurement. Fails on a wrong entry count or a non-finite point.
    pub fn from_pixels(
        width: u32,
        height: u32,
        pixels: impl IntoIterator<Item = Option<Point3>>,
    ) -> Result<PointCloud, AttributeError> {
        let mut positions = Vec::new();
        let mut table = Vec::new();
        for p in pixels {
            match p {
                Some(p) => {
                    table.push(positions.len() as u32);
                    positions.push(p);
                }
                None => table.push(INVALID_PIXEL),
            }
        }
        let mut cloud = PointCloud::from_positions(positions)?;
        let grid = Grid::new(width, height, table, cloud.len())?;
        cloud.grid = Some(grid);
        Ok(cloud)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_finite_positions_are_refused() {
        let err =
            PointCloud::from_positions(vec![Point3::origin(), Point3::new(f64::NAN, 0.0, 0.0)])
                .unwrap_err();
        assert_eq!(err, AttributeError::NonFinite { index: 1 });
        let err =
            PointCloud::from_positions(vec![Point3::new(0.0, f64::INFINITY, 0.0)]).unwrap_err();
        assert_eq!(err, AttributeError::NonFinite { index: 0 });
    }

    #[test]
    fn attributes_must_match_point_count() {
        let mut c = PointCloud::from_positions(vec![Point3::origin(); 3]).unwrap();
        assert!(c.set_intensity(Some(vec![1.0; 2])).is_err());
        c.set_intensity(Some(vec![1.0; 3])).unwrap();
        let f = ScalarField { name: "rgb".into(), data: FieldData::F32(vec![0.0; 3]) };
        c.push_extra_field(f.clone()).unwrap();
        assert_eq!(
            c.push_extra_field(f).unwrap_err(),
            AttributeError::DuplicateField { name: "rgb".into() }
        );
    }

    #[test]
    fn organised_cloud_keeps_invalid_pixels_explicit() {
        let px =
            vec![Some(Point3::new(1.0, 0.0, 0.0)), None, None, Some(Point3::new(0.0, 1.0, 0.0))];
        let c = PointCloud::from_pixels(2, 2, px).unwrap();
        let g = c.grid().unwrap();
        assert_eq!(c.len(), 2);
        assert_eq!(g.num_pixels(), 4);
        assert_eq!(g.point_index(0, 0), Some(0));
        assert_eq!(g.point_index(1, 0), None);
        assert_eq!(g.point_index(1, 1), Some(1));
        assert_eq!(g.point_index(2, 1), None);
        assert!(PointCloud::from_pixels(3, 2, vec![None; 4]).is_err());
    }

    #[test]
    fn retain_keeps_attributes_and_grid_consistent() {
        let px = (0..6).map(|i| Some(Point3::new(i as f64, 0.0, 0.0)));
        let mut c = PointCloud::from_pixels(3, 2, px).unwrap();
        c.set_labels(Some((0..6).collect())).unwrap();
        c.push_extra_field(ScalarField { name: "t".into(), data: FieldData::U8((0..6).collect()) })
            .unwrap();
        let odd = c.retain_indices(|i| i % 2 == 1);
        assert_eq!(odd.len(), 3);
        assert_eq!(odd.labels().unwrap(), &[1, 3, 5]);
        assert_eq!(odd.extra_field("t").unwrap().data, FieldData::U8(vec![1, 3, 5]));
        let g = odd.grid().unwrap();
        assert_eq!(g.point_index(0, 0), None);
        assert_eq!(g.point_index(1, 0), Some(0));
        assert_eq!(g.point_index(2, 1), Some(2));
    }

    #[test]
    fn grid_rejects_bad_tables() {
        assert!(matches!(
            Grid::new(2, 1, vec![0, 0], 1),
            Err(AttributeError::GridDuplicate { .. })
        ));
        assert!(matches!(Grid::new(2, 1, vec![0, 5], 2), Err(AttributeError::GridIndex { .. })));
        assert!(matches!(
            Grid::new(2, 1, vec![0, INVALID_PIXEL], 2),
            Err(AttributeError::GridUncovered { .. })
        ));
    }
}
