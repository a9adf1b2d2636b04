//! The camera model (thesis §2.3, spec §1): image geometry, modulation frequency and
//! non-ambiguity range, the four-sample demodulation of Eqs 2.1–2.3, and the two range
//! conventions (distance to the image plane, as the SwissRanger driver reports, or radial
//! distance along the beam).

use crate::TofError;
use pointcloud::{PinholeIntrinsics, Point3, RangeKind, Real, Vector3};
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// The speed of light in vacuum, m/s.
pub const SPEED_OF_LIGHT: Real = 299_792_458.0;

/// The non-ambiguity range `c / (2 f)` of a phase-measuring camera modulated at `frequency_hz`:
/// 7.49 m at 20 MHz, 29.98 m at 5 MHz (thesis L1694, L1928).
pub fn non_ambiguity_range(frequency_hz: Real) -> Real {
    SPEED_OF_LIGHT / (2.0 * frequency_hz)
}

/// The range of a phase `phase ∈ [0, 2π)` at the given non-ambiguity range:
/// `r = φ / (2π) · R_amb` (spec §6.4).
pub fn range_from_phase(phase: Real, non_ambiguity_range: Real) -> Real {
    phase.rem_euclid(TAU) / TAU * non_ambiguity_range
}

/// The phase in `[0, 2π)` that a surface at `range` produces.
pub fn phase_from_range(range: Real, non_ambiguity_range: Real) -> Real {
    (range / non_ambiguity_range * TAU).rem_euclid(TAU)
}

/// What a pixel's four samples give (Eqs 2.1–2.3).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Demodulated {
    /// Phase shift, radians in `[0, 2π)`.
    pub phase: Real,
    /// Amplitude of the modulated light.
    pub amplitude: Real,
    /// Intensity (the offset: ambient plus mean signal).
    pub intensity: Real,
}

/// Demodulates the four samples `τ0..τ3` of a pixel taken at illumination phases 0°, 90°,
/// 180°, 270° (Eqs 2.1–2.3):
///
/// - φ = atan2(τ3 − τ1, τ2 − τ0) mod 2π (Eq 2.1 writes `atan` of the quotient; the quadrant
///   follows from the signs, spec §6.4),
/// - A = √((τ3 − τ1)² + (τ2 − τ0)²) / 2,
/// - B = (τ0 + τ1 + τ2 + τ3) / 4.
///
/// The thesis does not say which sample is τ0 (its figure numbers them τ1..τ4); this crate
/// uses `τk = B − A·cos(φ − k·90°)` ([`modulate`]), the convention under which Eq 2.1 holds as
/// printed.
pub fn demodulate(tau: [Real; 4]) -> Demodulated {
    let s = tau[3] - tau[1];
    let c = tau[2] - tau[0];
    Demodulated {
        phase: s.atan2(c).rem_euclid(TAU),
        amplitude: (s * s + c * c).sqrt() / 2.0,
        intensity: (tau[0] + tau[1] + tau[2] + tau[3]) / 4.0,
    }
}

/// The four samples a pixel takes of light with phase `phase`, amplitude `amplitude` and
/// intensity `intensity`: `τk = B − A·cos(φ − k·90°)`. [`demodulate`] inverts it exactly.
pub fn modulate(phase: Real, amplitude: Real, intensity: Real) -> [Real; 4] {
    let (s, c) = phase.sin_cos();
    [
        intensity - amplitude * c,
        intensity - amplitude * s,
        intensity + amplitude * c,
        intensity + amplitude * s,
    ]
}

/// A time-of-flight camera: a pinhole image of `width × height` pixels (optical frame x right,
/// y down, z forward; pixel (0, 0) top left), a modulation frequency, and its working range.
///
/// Construct it from a preset ([`TofCamera::sr3000`], [`TofCamera::sr3100`]) or
/// [`TofCamera::pinhole`]; [`TofCamera::validate`] checks every field.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TofCamera {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Pinhole intrinsics.
    pub intrinsics: PinholeIntrinsics,
    /// Modulation frequency, Hz (the SwissRanger's default and only calibrated one: 20 MHz).
    pub modulation_hz: Real,
    /// Shortest radial distance the camera measures well, metres (SR-3000: 0.6 m; closer
    /// objects are distorted, thesis L2259–2269).
    pub min_range: Real,
}

impl TofCamera {
    /// The MESA SwissRanger SR-3000 (Table 2.1): 176 × 144 pixels, 47° × 39°, 0.6–7.5 m at
    /// 20 MHz.
    pub fn sr3000() -> TofCamera {
        TofCamera {
            width: 176,
            height: 144,
            intrinsics: PinholeIntrinsics::from_fov(
                176,
                144,
                47f64.to_radians(),
                39f64.to_radians(),
            ),
            modulation_hz: 20e6,
            min_range: 0.6,
        }
    }

    /// The SR-3100 the thesis's AAT experiments used (L2462): the same imager and optics as
    /// the SR-3000 (Table 2.2 lists one set of figures).
    pub fn sr3100() -> TofCamera {
        TofCamera::sr3000()
    }

    /// A generic pinhole camera.
    pub fn pinhole(
        width: u32,
        height: u32,
        intrinsics: PinholeIntrinsics,
        modulation_hz: Real,
    ) -> Result<TofCamera, TofError> {
        let camera = TofCamera { width, height, intrinsics, modulation_hz, min_range: 0.0 };
        camera.validate()?;
        Ok(camera)
    }

    /// Checks every field: a non-empty image of at most 2²⁶ pixels, finite positive focal
    /// lengths, a finite principal point, a modulation frequency in [1 kHz, 10 GHz], a finite
    /// non-negative minimum range.
    pub fn validate(&self) -> Result<(), TofError> {
        let bad = |what: &'static str, why: String| Err(TofError::BadParameter { what, why });
        if self.width == 0 || self.height == 0 || (self.width as u64 * self.height as u64) > 1 << 26
        {
            return bad(
                "image size",
                format!("{} × {} pixels (want 1 to 2^26)", self.width, self.height),
            );
        }
        let k = &self.intrinsics;
        if !(k.fx.is_finite() && k.fy.is_finite() && k.fx > 0.0 && k.fy > 0.0) {
            return bad("focal length", format!("fx = {}, fy = {} (want finite > 0)", k.fx, k.fy));
        }
        if !(k.cx.is_finite() && k.cy.is_finite()) {
            return bad("principal point", format!("cx = {}, cy = {} (want finite)", k.cx, k.cy));
        }
        if !(1e3..=1e10).contains(&self.modulation_hz) {
            return bad(
                "modulation frequency",
                format!("{} Hz (want 1 kHz to 10 GHz)", self.modulation_hz),
            );
        }
        if !(self.min_range.is_finite() && self.min_range >= 0.0) {
            return bad("minimum range", format!("{} m (want finite ≥ 0)", self.min_range));
        }
        Ok(())
    }

    /// The number of pixels.
    pub fn num_pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// The non-ambiguity range `c / (2 f)`, metres (7.49 m at 20 MHz).
    pub fn non_ambiguity_range(&self) -> Real {
        non_ambiguity_range(self.modulation_hz)
    }

    /// The ray of pixel (`col`, `row`) scaled to z = 1: `((u − cx)/fx, (v − cy)/fy, 1)`. A
    /// depth `z` is the point `z · ray`.
    pub fn ray(&self, col: u32, row: u32) -> Vector3 {
        let k = &self.intrinsics;
        Vector3::new((col as Real - k.cx) / k.fx, (row as Real - k.cy) / k.fy, 1.0)
    }

    /// Per pixel (row-major) the factor `radial / depth = |ray|` (≥ 1).
    pub fn radial_per_depth(&self) -> Vec<Real> {
        let mut out = Vec::with_capacity(self.num_pixels());
        for row in 0..self.height {
            for col in 0..self.width {
                out.push(self.ray(col, row).norm());
            }
        }
        out
    }

    /// The point of pixel (`col`, `row`) at `range` of the given kind.
    pub fn point(&self, col: u32, row: u32, range: Real, kind: RangeKind) -> Point3 {
        let ray = self.ray(col, row);
        let z = match kind {
            RangeKind::Depth => range,
            RangeKind::Radial => range / ray.norm(),
        };
        Point3::from(ray * z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn sr3000_preset_matches_table_2_1() {
        let c = TofCamera::sr3000();
        c.validate().unwrap();
        assert_eq!((c.width, c.height), (176, 144));
        assert!((c.non_ambiguity_range() - 7.4948).abs() < 1e-3);
        assert!((non_ambiguity_range(5e6) - 29.979).abs() < 1e-3);
        // The edge pixels see half the field of view.
        let half_fov = ((c.intrinsics.cx + 0.5) / c.intrinsics.fx).atan().to_degrees();
        assert!((half_fov - 23.5).abs() < 0.01, "{half_fov}");
    }

    #[test]
    fn absurd_cameras_are_refused() {
        let mut c = TofCamera::sr3000();
        c.modulation_hz = 0.0;
        assert!(c.validate().is_err());
        let mut c = TofCamera::sr3000();
        c.intrinsics.fx = Real::NAN;
        assert!(c.validate().is_err());
        let mut c = TofCamera::sr3000();
        c.width = 0;
        assert!(c.validate().is_err());
        assert!(TofCamera::pinhole(10, 10, TofCamera::sr3000().intrinsics, -1.0).is_err());
    }

    #[test]
    fn eq_2_1_holds_as_printed() {
        // φ = atan((τ3 − τ1)/(τ2 − τ0)) in the first quadrant.
        let tau = modulate(0.3, 100.0, 500.0);
        let printed = ((tau[3] - tau[1]) / (tau[2] - tau[0])).atan();
        assert!((printed - 0.3).abs() < 1e-12);
    }

    proptest! {
        #[test]
        fn demodulate_inverts_modulate(phase in 0.0..TAU, a in 0.0..1e5f64, b in 0.0..1e5f64) {
            let d = demodulate(modulate(phase, a, b));
            prop_assert!((d.amplitude - a).abs() <= 1e-9 * (1.0 + a + b));
            prop_assert!((d.intensity - b).abs() <= 1e-9 * (1.0 + a + b));
            if a > 1e-3 {
                let dphi = (d.phase - phase).abs();
                prop_assert!(dphi.min(TAU - dphi) < 1e-6, "{} vs {}", d.phase, phase);
            }
        }

        #[test]
        fn range_and_phase_round_trip(r in 0.0..7.4f64) {
            let amb = non_ambiguity_range(20e6);
            prop_assert!((range_from_phase(phase_from_range(r, amb), amb) - r).abs() < 1e-9);
            // One non-ambiguity range further gives the same phase: the wrap-around.
            let wrapped = range_from_phase(phase_from_range(r + amb, amb), amb);
            prop_assert!((wrapped - r).abs() < 1e-9);
        }

        #[test]
        fn depth_and_radial_points_agree(col in 0u32..176, row in 0u32..144, z in 0.1..20.0f64) {
            let c = TofCamera::sr3000();
            let p = c.point(col, row, z, RangeKind::Depth);
            prop_assert!((p.z - z).abs() < 1e-12);
            let q = c.point(col, row, p.coords.norm(), RangeKind::Radial);
            prop_assert!((p - q).norm() < 1e-9);
        }
    }
}
