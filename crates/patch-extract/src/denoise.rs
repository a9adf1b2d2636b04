//! Range denoising of organised scans along their beams (not in the thesis).
//!
//! Raw points scatter by the range noise σ along their beams. A mesh through them (the
//! trimesh and hybrid maps, thesis §6.1) or the points themselves (the point-cloud map) then
//! reach about 2σ into the free space in front of every surface: at σ = 3 cm, robot steps that
//! pass a wall, the floor or the ceiling within 6 cm are blocked. Thin obstacles and edges
//! must survive, so nothing is moved that is not locally a plane.
//!
//! # Method
//! For each valid pixel `p` (range `r`), the pixels of its `(2k + 1)²` window
//! ([`BeamDenoiseConfig::radius`] `= k`) that pass the segmentation's jump test to `p`
//! (`|p − q| ≤ jump_absolute + jump_relative · max(r_p, r_q)`) are fitted with a
//! least-squares plane. If at least [`BeamDenoiseConfig::min_points`] took part, the plane's
//! residual RMS is at most `max_rms_sigmas · σ(r)` (a plane within the noise: not an edge, a
//! corner or a thin post seen with the wall behind it), and the beam meets the plane less
//! than `max_shift_sigmas · σ(r)` from `p`, `p` moves along its beam onto the plane. The
//! noise lies along the beam, so this removes most of it (averaging `n` points divides it by
//! about `√n`) without moving points sideways. The sensor sits at the origin of the cloud's
//! frame (scans as simulated or read, before [`pointcloud::PointCloud::to_world`]).
//!
//! # Complexity
//! O(N · (2k + 1)²) for N pixels.

use patch_core::{Point3, Real};
use pointcloud::{INVALID_PIXEL, PointCloud};

use crate::plane_fit::PlaneAccumulator;
use crate::segment::RangeNoise;

/// Parameters of [`denoise_along_beams`]. No `Default`: start from a named preset.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct BeamDenoiseConfig {
    /// The noise model the thresholds scale with.
    pub noise: RangeNoise,
    /// Half the window's side in pixels (≥ 1).
    pub radius: u32,
    /// Jump test, constant part, metres (≥ 0).
    pub jump_absolute: Real,
    /// Jump test, part proportional to range (≥ 0).
    pub jump_relative: Real,
    /// Fewest window points (the pixel included) for a plane (≥ 3).
    pub min_points: usize,
    /// Largest residual RMS of the window's plane, in σ at the pixel's range (> 0).
    pub max_rms_sigmas: Real,
    /// Largest move along the beam, in σ at the pixel's range (> 0).
    pub max_shift_sigmas: Real,
}

impl BeamDenoiseConfig {
    /// For the actuated LRF (SICK S300, σ = 3 cm, [`crate::segment::SegmentConfig::alrf`]'s
    /// noise and jump test): 5 × 5 windows of at least 12 points, residual RMS within 1.5σ,
    /// moves up to 3σ.
    pub fn alrf() -> BeamDenoiseConfig {
        let segment = crate::segment::SegmentConfig::alrf();
        BeamDenoiseConfig {
            noise: segment.noise,
            radius: 2,
            jump_absolute: segment.jump_absolute,
            jump_relative: segment.jump_relative,
            min_points: 12,
            max_rms_sigmas: 1.5,
            max_shift_sigmas: 3.0,
        }
    }

    /// Checks every parameter.
    ///
    /// # Errors
    /// [`DenoiseError::BadParameter`] naming the first parameter out of range.
    pub fn validate(&self) -> Result<(), DenoiseError> {
        let check = |name: &'static str, value: Real, ok: bool| {
            if ok { Ok(()) } else { Err(DenoiseError::BadParameter { name, value }) }
        };
        let finite_pos = |v: Real| v.is_finite() && v > 0.0;
        let finite_non_neg = |v: Real| v.is_finite() && v >= 0.0;
        check("noise.sigma_0", self.noise.sigma_0, finite_pos(self.noise.sigma_0))?;
        check("noise.sigma_r2", self.noise.sigma_r2, finite_non_neg(self.noise.sigma_r2))?;
        check("radius", self.radius as Real, (1..=16).contains(&self.radius))?;
        check("jump_absolute", self.jump_absolute, finite_non_neg(self.jump_absolute))?;
        check("jump_relative", self.jump_relative, finite_non_neg(self.jump_relative))?;
        check("min_points", self.min_points as Real, self.min_points >= 3)?;
        check("max_rms_sigmas", self.max_rms_sigmas, finite_pos(self.max_rms_sigmas))?;
        check("max_shift_sigmas", self.max_shift_sigmas, finite_pos(self.max_shift_sigmas))
    }
}

/// Why [`denoise_along_beams`] refused its input.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DenoiseError {
    /// The cloud has no pixel grid.
    #[error("beam denoising needs an organised cloud (with a pixel grid)")]
    NoGrid,
    /// A parameter is out of range.
    #[error("denoise parameter {name} = {value} is out of range")]
    BadParameter {
        /// The parameter.
        name: &'static str,
        /// Its value.
        value: Real,
    },
}

/// The cloud with every locally planar point moved along its beam onto its neighbourhood's
/// plane (module docs), and how many points moved. Attributes, grid and pose are kept.
///
/// # Errors
/// [`DenoiseError`] for an unorganised cloud or a bad parameter.
pub fn denoise_along_beams(
    cloud: &PointCloud,
    config: &BeamDenoiseConfig,
) -> Result<(PointCloud, usize), DenoiseError> {
    denoise_along_beams_where(cloud, config, |_| true)
}

/// [`denoise_along_beams`] for the points `i` with `only(i)`; the others stay as they are but
/// still serve as neighbours (e.g. a segmentation's remainder, before it is meshed).
///
/// # Errors
/// As [`denoise_along_beams`].
pub fn denoise_along_beams_where(
    cloud: &PointCloud,
    config: &BeamDenoiseConfig,
    only: impl Fn(usize) -> bool,
) -> Result<(PointCloud, usize), DenoiseError> {
    config.validate()?;
    let grid = cloud.grid().ok_or(DenoiseError::NoGrid)?;
    let points = cloud.positions();
    let (w, h, k) = (grid.width() as i64, grid.height() as i64, config.radius as i64);
    let mut out = points.to_vec();
    let mut moved = 0;
    for (pixel, &index) in grid.pixels().iter().enumerate() {
        if index == INVALID_PIXEL || !only(index as usize) {
            continue;
        }
        let p = points[index as usize];
        let range = p.coords.norm();
        if range <= 0.0 {
            continue;
        }
        let (col, row) = (pixel as i64 % w, pixel as i64 / w);
        let mut acc = PlaneAccumulator::default();
        for r in (row - k).max(0)..=(row + k).min(h - 1) {
            for c in (col - k).max(0)..=(col + k).min(w - 1) {
                let Some(q) = grid.point_index(c as u32, r as u32).map(|i| points[i]) else {
                    continue;
                };
                let limit =
                    config.jump_absolute + config.jump_relative * range.max(q.coords.norm());
                if (q - p).norm() <= limit {
                    acc.add(&q);
                }
            }
        }
        if acc.len() < config.min_points {
            continue;
        }
        let Some(fit) = acc.fit(&Point3::origin()) else { continue };
        let sigma = config.noise.sigma(range);
        if fit.mse.sqrt() > config.max_rms_sigmas * sigma {
            continue;
        }
        // The beam t · p̂ meets n · x = n · c at t = n · c / n · p̂.
        let beam = p.coords / range;
        let along = fit.plane.normal.dot(&beam);
        if along.abs() < 1e-6 {
            continue;
        }
        let t = fit.plane.normal.dot(&fit.centroid.coords) / along;
        if t > 0.0 && (t - range).abs() <= config.max_shift_sigmas * sigma {
            out[index as usize] = Point3::from(beam * t);
            moved += 1;
        }
    }
    let denoised = cloud
        .with_positions(out)
        .map_err(|_| DenoiseError::BadParameter { name: "positions", value: Real::NAN })?;
    Ok((denoised, moved))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mixed_pixels::tests::scan;

    /// A deterministic ±1 pattern.
    fn noise(col: u32, row: u32) -> Real {
        let x = (col.wrapping_mul(2654435761) ^ row.wrapping_mul(40503)).wrapping_mul(2246822519);
        (x >> 8) as Real / (1u32 << 24) as Real * 2.0 - 1.0
    }

    /// Distance of the point of beam (col, row) from the wall x = 4.
    fn wall_error(cloud: &PointCloud) -> Real {
        let d: Vec<Real> = cloud.positions().iter().map(|p| (p.x - 4.0).abs()).collect();
        (d.iter().map(|e| e * e).sum::<Real>() / d.len() as Real).sqrt()
    }

    #[test]
    fn a_noisy_wall_gets_flatter_along_its_beams() {
        let cloud = scan(40, 30, |c, r| {
            let step = 0.5f64.to_radians();
            let yaw = (c as Real - 20.0) * step;
            let pitch = (r as Real - 15.0) * step;
            Some(4.0 / (yaw.cos() * pitch.cos()) + 0.05 * noise(c, r))
        });
        let (out, moved) = denoise_along_beams(&cloud, &BeamDenoiseConfig::alrf()).unwrap();
        assert!(moved > 1000, "{moved} of {} moved", cloud.len());
        let (before, after) = (wall_error(&cloud), wall_error(&out));
        assert!(after < 0.5 * before, "RMS off the wall {before:.4} → {after:.4}");
        // Every point stays on its beam.
        for (a, b) in cloud.positions().iter().zip(out.positions()) {
            assert!(a.coords.normalize().dot(&b.coords.normalize()) > 1.0 - 1e-12);
        }
        assert_eq!(out.grid(), cloud.grid());
    }

    #[test]
    fn a_thin_post_in_front_of_a_wall_stays_where_it_is() {
        // Columns 18–20 see a post at 2 m, the rest a wall at 4 m.
        let cloud = scan(40, 30, |c, _| Some(if (18..=20).contains(&c) { 2.0 } else { 4.0 }));
        let (out, _) = denoise_along_beams(&cloud, &BeamDenoiseConfig::alrf()).unwrap();
        for (a, b) in cloud.positions().iter().zip(out.positions()) {
            let (ra, rb) = (a.coords.norm(), b.coords.norm());
            assert!((ra - rb).abs() < 0.02, "a point moved from {ra:.3} to {rb:.3}");
        }
    }

    #[test]
    fn bad_input_is_a_typed_error() {
        let unorganised = PointCloud::from_positions(vec![Point3::new(1.0, 0.0, 0.0)]).unwrap();
        let config = BeamDenoiseConfig::alrf();
        assert_eq!(denoise_along_beams(&unorganised, &config), Err(DenoiseError::NoGrid));
        let cloud = scan(4, 4, |_, _| Some(2.0));
        for bad in [
            BeamDenoiseConfig { radius: 0, ..config },
            BeamDenoiseConfig { min_points: 2, ..config },
            BeamDenoiseConfig { max_rms_sigmas: Real::NAN, ..config },
            BeamDenoiseConfig { jump_relative: -1.0, ..config },
        ] {
            assert!(matches!(
                denoise_along_beams(&cloud, &bad),
                Err(DenoiseError::BadParameter { .. })
            ));
        }
        let empty = PointCloud::from_pixels(3, 3, vec![None; 9]).unwrap();
        assert_eq!(denoise_along_beams(&empty, &config).unwrap().1, 0);
    }
}
