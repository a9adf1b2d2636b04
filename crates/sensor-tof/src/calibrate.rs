//! White-wall calibration of the illumination model `aw_p` of the adaptive amplitude threshold
//! (thesis §2.5.5, L2338–2348, Eq 2.5, Fig 2.15).
//!
//! `aw_p` is "the amplitude of pixel p when viewing a white wall at roughly one meter"
//! (L2338–2340). From one frame of a perpendicular white wall at any distance, every measured
//! pixel gives `aw_p = a_p · r_p²` (amplitude falls with the squared range, L2350–2362, so this
//! is the amplitude the pixel would see at 1 m; `r_p` is the depth, as in Eq 2.4, or the radial
//! distance, [`CalibrationOptions::range`]). Then either
//!
//! - [`fit_parabola`] fits Eq 2.5, generalised by a curvature `k`,
//!   `aw = Â − k((x − δx)² + (y − δy)²)`, by linear least squares on
//!   `aw = c0 + c1 x + c2 y + c3 (x² + y²)`: `k = −c3`, `δx = c1 / 2k`, `δy = c2 / 2k`,
//!   `Â = c0 + k(δx² + δy²)` (or with `k = 1` fixed, as printed in Eq 2.5); or
//! - [`white_wall_table`] keeps the per-pixel values, the look-up table the thesis names as the
//!   alternative (L2344–2348), with the pixels the wall frame lacks filled from the parabola.
//!
//! The thesis fitted by hand and reports that the parabola is "reasonably close, except for the
//! very edges" (Fig 2.15): [`Calibration::residual_rms`] measures how close.

use crate::filter::{
    AatConfig, AatRange, Illumination, NegativeIllumination, Parabola, WhiteWallTable,
};
use crate::{TofError, TofFrame};
use nalgebra::{Matrix4, Vector4};
use pointcloud::Real;
use serde::{Deserialize, Serialize};

/// How to calibrate.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CalibrationOptions {
    /// Which range normalises the amplitude to 1 m: the depth (Eq 2.4's `r_p`, default) or the
    /// radial distance. Use the same in the filter.
    pub range: AatRange,
    /// Fix the curvature to 1, as Eq 2.5 is printed (default: fit it).
    pub fixed_curvature: bool,
    /// Refuse walls with fewer measured pixels than this (default 100; at least 4).
    pub min_pixels: usize,
    /// Refit without the pixels whose residual exceeds this many RMS residuals, until none is
    /// removed (at most 10 rounds): drops specular spots and wall edges. `None` (default): one
    /// plain least-squares fit over every measured pixel.
    pub trim_sigma: Option<Real>,
}

impl Default for CalibrationOptions {
    fn default() -> CalibrationOptions {
        CalibrationOptions {
            range: AatRange::Depth,
            fixed_curvature: false,
            min_pixels: 100,
            trim_sigma: None,
        }
    }
}

/// A fitted illumination parabola and how well it fits (the JSON `patchnav tof calibrate`
/// writes, which a frame sidecar can name).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Calibration {
    /// The fitted Eq 2.5 (generalised by the curvature).
    pub parabola: Parabola,
    /// Which range normalised the amplitudes (use the same in the filter).
    pub range: AatRange,
    /// Whether the curvature was fixed to 1.
    pub fixed_curvature: bool,
    /// Root mean square of `aw_p − parabola(p)` over the pixels used, amplitude units.
    pub residual_rms: Real,
    /// Pixels used in the final fit.
    pub used_pixels: usize,
    /// `used_pixels` over all pixels of the frame.
    pub used_fraction: Real,
    /// Image width the calibration belongs to.
    pub width: u32,
    /// Image height.
    pub height: u32,
}

impl Calibration {
    /// The AAT with this illumination, `threshold` (0.2 in the thesis), the calibration's range
    /// kind and the corners taken literally.
    pub fn aat_config(&self, threshold: Real) -> AatConfig {
        AatConfig {
            illumination: Illumination::Parabola(self.parabola),
            threshold,
            range: self.range,
            negative: NegativeIllumination::Literal,
        }
    }
}

fn degenerate(why: String) -> TofError {
    TofError::BadImage { what: "white wall", why }
}

/// Per pixel `aw_p = a_p · r_p²` (`None` where nothing was measured or the value is not finite).
pub fn white_wall_samples(frame: &TofFrame, range: AatRange) -> Vec<Option<Real>> {
    (0..frame.range().len())
        .map(|i| {
            if frame.range()[i] <= 0.0 {
                return None;
            }
            let r = match range {
                AatRange::Depth => frame.depth(i),
                AatRange::Radial => frame.radial(i),
            };
            let aw = frame.amplitude()[i] as Real * r * r;
            aw.is_finite().then_some(aw)
        })
        .collect()
}

/// The pixel coordinates in a scaled frame centred on the image (for a well-conditioned fit).
struct Scaling {
    x0: Real,
    y0: Real,
    s: Real,
}

impl Scaling {
    fn uv(&self, x: Real, y: Real) -> (Real, Real) {
        ((x - self.x0) / self.s, (y - self.y0) / self.s)
    }
}

/// One least-squares fit over `used`; returns the parabola in pixel coordinates.
fn fit_once(
    frame: &TofFrame,
    samples: &[Option<Real>],
    used: &[bool],
    fixed: bool,
    sc: &Scaling,
) -> Result<Parabola, TofError> {
    // Unknowns (scaled coordinates u, v): aw = b0 + b1 u + b2 v + b3 (u² + v²); with the
    // curvature fixed to 1 in pixels (k_u = s²): aw + s²(u² + v²) = b0 + b1 u + b2 v.
    let k_fixed = sc.s * sc.s;
    let mut ata = Matrix4::<Real>::zeros();
    let mut atb = Vector4::<Real>::zeros();
    for (i, aw) in samples.iter().enumerate() {
        let (Some(aw), true) = (*aw, used[i]) else { continue };
        let (col, row) = frame.col_row(i);
        let (u, v) = sc.uv(col as Real, row as Real);
        let q = u * u + v * v;
        let (row_vec, target) = if fixed {
            (Vector4::new(1.0, u, v, 0.0), aw + k_fixed * q)
        } else {
            (Vector4::new(1.0, u, v, q), aw)
        };
        ata += row_vec * row_vec.transpose();
        atb += row_vec * target;
    }
    if fixed {
        ata[(3, 3)] = ata[(0, 0)];
    }
    // A rank-deficient system (pixels on one line) is refused even where rounding would let a
    // Cholesky factorisation through.
    let eig = ata.symmetric_eigenvalues();
    let (lo, hi) = (eig.min(), eig.max());
    if lo.is_nan() || lo <= 1e-10 * hi {
        return Err(degenerate(
            "the measured pixels do not determine a parabola (all on one line?)".into(),
        ));
    }
    let b = ata.cholesky().map(|c| c.solve(&atb)).ok_or_else(|| {
        degenerate("the measured pixels do not determine a parabola (all on one line?)".into())
    })?;
    if !b.iter().all(|v| v.is_finite()) {
        return Err(degenerate("the fit is not finite".into()));
    }
    let k_u = if fixed { k_fixed } else { -b[3] };
    // k ≤ 0, or a fall-off over half the image below a millionth of the brightness (a flat
    // wall up to rounding), determines no centre.
    if k_u.is_nan() || k_u <= 1e-6 * b[0].abs() {
        return Err(degenerate(format!(
            "the fitted curvature is {:.3e} (want > 0: a wall brightest inside the image and \
             darker towards the edges)",
            k_u / (sc.s * sc.s)
        )));
    }
    let (du, dv) = (b[1] / (2.0 * k_u), b[2] / (2.0 * k_u));
    let a_hat = b[0] + k_u * (du * du + dv * dv);
    let parabola = Parabola {
        a_hat,
        delta_x: sc.x0 + sc.s * du,
        delta_y: sc.y0 + sc.s * dv,
        curvature: if fixed { 1.0 } else { k_u / (sc.s * sc.s) },
    };
    if !(a_hat.is_finite() && a_hat > 0.0) {
        return Err(degenerate(format!("the fitted Â is {a_hat} (want > 0)")));
    }
    Ok(parabola)
}

fn residuals(frame: &TofFrame, samples: &[Option<Real>], p: &Parabola) -> Vec<Option<Real>> {
    samples
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let (col, row) = frame.col_row(i);
            s.map(|aw| aw - p.eval(col as Real, row as Real))
        })
        .collect()
}

/// Fits the illumination parabola (Eq 2.5 with a curvature) to a white-wall frame (see the
/// module documentation). Pixels without a measurement (range 0) are skipped.
///
/// Fails with [`TofError::BadImage`] when fewer than `min_pixels` pixels are measured, the
/// pixels do not determine a parabola, or the fit has `k ≤ 0` (or a fall-off over half the
/// image below 10⁻⁶ Â: flat) or `Â ≤ 0` (not a wall lit by the camera), and with [`TofError::BadParameter`] on absurd options.
pub fn fit_parabola(
    frame: &TofFrame,
    options: &CalibrationOptions,
) -> Result<Calibration, TofError> {
    if let Some(t) = options.trim_sigma
        && !(t.is_finite() && t > 0.0)
    {
        return Err(TofError::BadParameter {
            what: "trim sigma",
            why: format!("{t} (want finite > 0)"),
        });
    }
    let samples = white_wall_samples(frame, options.range);
    let min = options.min_pixels.max(4);
    let mut used: Vec<bool> = samples.iter().map(Option::is_some).collect();
    let count = |used: &[bool]| used.iter().filter(|&&u| u).count();
    let n = count(&used);
    if n < min {
        return Err(degenerate(format!("{n} measured pixels (want at least {min})")));
    }
    let c = frame.camera();
    let sc = Scaling {
        x0: (c.width as Real - 1.0) / 2.0,
        y0: (c.height as Real - 1.0) / 2.0,
        s: (c.width.max(c.height) as Real / 2.0).max(1.0),
    };
    let mut parabola = fit_once(frame, &samples, &used, options.fixed_curvature, &sc)?;
    if let Some(t) = options.trim_sigma {
        for _ in 0..10 {
            let res = residuals(frame, &samples, &parabola);
            let used_res: Vec<Real> =
                res.iter().zip(&used).filter_map(|(r, &u)| r.filter(|_| u)).collect();
            let rms =
                (used_res.iter().map(|r| r * r).sum::<Real>() / used_res.len() as Real).sqrt();
            let mut changed = false;
            for (u, r) in used.iter_mut().zip(&res) {
                if *u && r.is_some_and(|r| r.abs() > t * rms) {
                    *u = false;
                    changed = true;
                }
            }
            if !changed {
                break;
            }
            let left = count(&used);
            if left < min {
                return Err(degenerate(format!(
                    "{left} pixels left after trimming at {t} σ (want at least {min})"
                )));
            }
            parabola = fit_once(frame, &samples, &used, options.fixed_curvature, &sc)?;
        }
    }
    let res = residuals(frame, &samples, &parabola);
    let (mut sum, mut m) = (0.0, 0usize);
    for (r, &u) in res.iter().zip(&used) {
        if let (Some(r), true) = (r, u) {
            sum += r * r;
            m += 1;
        }
    }
    Ok(Calibration {
        parabola,
        range: options.range,
        fixed_curvature: options.fixed_curvature,
        residual_rms: (sum / m as Real).sqrt(),
        used_pixels: m,
        used_fraction: m as Real / frame.range().len() as Real,
        width: c.width,
        height: c.height,
    })
}

/// The per-pixel white-wall table (L2344–2348): `aw_p = a_p · r_p²` where the wall frame has a
/// measurement, the fitted parabola ([`fit_parabola`] with `options`) elsewhere. Fails as
/// [`fit_parabola`] does when pixels are missing and the parabola cannot be fitted.
pub fn white_wall_table(
    frame: &TofFrame,
    options: &CalibrationOptions,
) -> Result<WhiteWallTable, TofError> {
    let samples = white_wall_samples(frame, options.range);
    let fill = if samples.iter().any(Option::is_none) {
        Some(fit_parabola(frame, options)?.parabola)
    } else {
        None
    };
    let values = samples
        .iter()
        .enumerate()
        .map(|(i, s)| match s {
            Some(aw) => *aw as f32,
            None => {
                let (col, row) = frame.col_row(i);
                // `fill` is set whenever a pixel is missing.
                fill.map_or(0.0, |p| p.eval(col as Real, row as Real) as f32)
            }
        })
        .collect();
    let c = frame.camera();
    Ok(WhiteWallTable { width: c.width, height: c.height, values })
}
