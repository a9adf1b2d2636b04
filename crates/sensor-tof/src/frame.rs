//! One frame of a time-of-flight camera: range and amplitude images (plus intensity and
//! confidence when the camera gives them) of one [`TofCamera`], as one validated type.

use crate::{TofCamera, TofError};
use pointcloud::{PointCloud, RangeKind, Real, ScalarField};

/// A frame: per pixel (row-major, pixel (0, 0) top left) the reported range in metres (`0` =
/// no measurement, as the SwissRanger driver reports pixels below its own amplitude threshold,
/// L1853–1855) and the amplitude in the camera's units; optionally the intensity (Eq 2.3) and
/// a confidence value.
///
/// Ranges are either distances to the image plane ([`RangeKind::Depth`], the SwissRanger's
/// convention, L1804–1806) or along the beam ([`RangeKind::Radial`]). Every value is finite and
/// non-negative, and every image has `width × height` entries: [`TofFrame::new`] checks.
#[derive(Clone, Debug, PartialEq)]
pub struct TofFrame {
    camera: TofCamera,
    kind: RangeKind,
    range: Vec<f32>,
    amplitude: Vec<f32>,
    intensity: Option<Vec<f32>>,
    confidence: Option<Vec<u16>>,
}

fn check_image(what: &'static str, values: &[f32], n: usize) -> Result<(), TofError> {
    if values.len() != n {
        return Err(TofError::BadImage {
            what,
            why: format!("{} values for {n} pixels", values.len()),
        });
    }
    if let Some(i) = values.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
        return Err(TofError::BadImage {
            what,
            why: format!("pixel {i} holds {} (want finite and ≥ 0)", values[i]),
        });
    }
    Ok(())
}

impl TofFrame {
    /// A frame of `camera` with ranges of `kind` (metres, 0 = no measurement) and amplitudes.
    pub fn new(
        camera: TofCamera,
        kind: RangeKind,
        range: Vec<f32>,
        amplitude: Vec<f32>,
    ) -> Result<TofFrame, TofError> {
        camera.validate()?;
        let n = camera.num_pixels();
        check_image("range", &range, n)?;
        check_image("amplitude", &amplitude, n)?;
        Ok(TofFrame { camera, kind, range, amplitude, intensity: None, confidence: None })
    }

    /// Adds the intensity image (Eq 2.3).
    pub fn with_intensity(mut self, intensity: Vec<f32>) -> Result<TofFrame, TofError> {
        check_image("intensity", &intensity, self.camera.num_pixels())?;
        self.intensity = Some(intensity);
        Ok(self)
    }

    /// Adds a confidence image (camera-specific values, e.g. the SwissRanger's confidence map
    /// or an ifm confidence bit field).
    pub fn with_confidence(mut self, confidence: Vec<u16>) -> Result<TofFrame, TofError> {
        let n = self.camera.num_pixels();
        if confidence.len() != n {
            return Err(TofError::BadImage {
                what: "confidence",
                why: format!("{} values for {n} pixels", confidence.len()),
            });
        }
        self.confidence = Some(confidence);
        Ok(self)
    }

    /// The camera.
    pub fn camera(&self) -> &TofCamera {
        &self.camera
    }

    /// What the ranges measure.
    pub fn kind(&self) -> RangeKind {
        self.kind
    }

    /// The range image, metres, 0 = no measurement.
    pub fn range(&self) -> &[f32] {
        &self.range
    }

    /// The amplitude image.
    pub fn amplitude(&self) -> &[f32] {
        &self.amplitude
    }

    /// The intensity image, if any.
    pub fn intensity(&self) -> Option<&[f32]> {
        self.intensity.as_deref()
    }

    /// The confidence image, if any.
    pub fn confidence(&self) -> Option<&[u16]> {
        self.confidence.as_deref()
    }

    /// The number of pixels with a measurement (range > 0).
    pub fn num_measured(&self) -> usize {
        self.range.iter().filter(|&&r| r > 0.0).count()
    }

    /// The radial distance of pixel `i` (0 = no measurement).
    pub fn radial(&self, i: usize) -> Real {
        let (col, row) = self.col_row(i);
        let r = self.range[i] as Real;
        match self.kind {
            RangeKind::Radial => r,
            RangeKind::Depth => r * self.camera.ray(col, row).norm(),
        }
    }

    /// The distance to the image plane of pixel `i` (0 = no measurement).
    pub fn depth(&self, i: usize) -> Real {
        let (col, row) = self.col_row(i);
        let r = self.range[i] as Real;
        match self.kind {
            RangeKind::Depth => r,
            RangeKind::Radial => r / self.camera.ray(col, row).norm(),
        }
    }

    /// (column, row) of pixel `i`.
    pub fn col_row(&self, i: usize) -> (u32, u32) {
        let w = self.camera.width as usize;
        ((i % w) as u32, (i / w) as u32)
    }

    /// The same frame with ranges of the other kind (values converted pixel by pixel).
    pub fn converted(&self, kind: RangeKind) -> TofFrame {
        if kind == self.kind {
            return self.clone();
        }
        let range = (0..self.range.len())
            .map(|i| match kind {
                RangeKind::Radial => self.radial(i) as f32,
                RangeKind::Depth => self.depth(i) as f32,
            })
            .collect();
        TofFrame { range, kind, ..self.clone() }
    }

    /// The organised point cloud of every measured pixel (camera optical frame), amplitude as
    /// intensity, plus the fields `amplitude` and (if present) `confidence` and `tof_intensity`.
    pub fn to_cloud(&self) -> PointCloud {
        let (w, h) = (self.camera.width, self.camera.height);
        let pixels = (0..self.range.len()).map(|i| {
            let (col, row) = self.col_row(i);
            (self.range[i] > 0.0)
                .then(|| self.camera.point(col, row, self.range[i] as Real, self.kind))
        });
        let mut cloud =
            PointCloud::from_pixels(w, h, pixels).expect("finite points, consistent grid");
        let measured: Vec<usize> = (0..self.range.len()).filter(|&i| self.range[i] > 0.0).collect();
        let pick = |v: &[f32]| measured.iter().map(|&i| v[i]).collect::<Vec<f32>>();
        cloud.set_intensity(Some(pick(&self.amplitude))).expect("one value per point");
        if let Some(b) = &self.intensity {
            let field = ScalarField {
                name: "tof_intensity".into(),
                data: pointcloud::FieldData::F32(pick(b)),
            };
            cloud.push_extra_field(field).expect("one value per point");
        }
        if let Some(c) = &self.confidence {
            let data = pointcloud::FieldData::U16(measured.iter().map(|&i| c[i]).collect());
            cloud
                .push_extra_field(ScalarField { name: "confidence".into(), data })
                .expect("one value per point");
        }
        cloud
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> TofFrame {
        let c = TofCamera::sr3000();
        let n = c.num_pixels();
        let mut range = vec![2.0f32; n];
        range[5] = 0.0;
        TofFrame::new(c, RangeKind::Depth, range, vec![100.0; n]).unwrap()
    }

    #[test]
    fn bad_images_are_refused() {
        let c = TofCamera::sr3000();
        let n = c.num_pixels();
        assert!(TofFrame::new(c, RangeKind::Depth, vec![1.0; n - 1], vec![1.0; n]).is_err());
        let mut r = vec![1.0; n];
        r[7] = f32::NAN;
        let e = TofFrame::new(c, RangeKind::Depth, r, vec![1.0; n]).unwrap_err();
        assert!(e.to_string().contains("pixel 7"), "{e}");
        let mut a = vec![1.0; n];
        a[3] = -1.0;
        assert!(TofFrame::new(c, RangeKind::Depth, vec![1.0; n], a).is_err());
        assert!(frame().with_confidence(vec![0; 3]).is_err());
    }

    #[test]
    fn kinds_convert_both_ways() {
        let f = frame();
        let r = f.converted(RangeKind::Radial);
        let back = r.converted(RangeKind::Depth);
        for i in 0..f.range().len() {
            assert!((back.range()[i] - f.range()[i]).abs() < 1e-5);
            assert!(r.range()[i] >= f.range()[i]);
        }
        let cloud = f.to_cloud();
        assert_eq!(cloud.len(), f.num_measured());
        assert_eq!(cloud.grid().unwrap().num_pixels(), f.range().len());
        assert!(cloud.positions().iter().all(|p| (p.z - 2.0).abs() < 1e-6));
    }
}
