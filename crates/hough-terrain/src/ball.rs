//! Beyond the thesis: free-orientation plane detection with an equal-area "ball" accumulator in
//! the style of 3DTK's (Borrmann et al., "The 3D Hough Transform for plane detection in point
//! clouds: A review and a new accumulator design", 3D Research 2011).
//!
//! The accumulator covers the hemisphere of unit normals `n` with `n_z ≥ 0` (a plane and its
//! flipped normal are the same plane, with `ρ` negated): rows of equal polar-angle height, each
//! with a number of azimuth cells proportional to the row's circumference (`∝ cos` of the
//! latitude), so every cell covers about the same solid angle, unlike a (θ, φ) grid whose cells
//! shrink towards the pole. Each point votes, in every cell, for the distance bin of
//! `ρ = n·p`, `ρ ∈ [−ρ_max, ρ_max)`. Peaks are picked greedily with non-maximum suppression and
//! can be refined by a least-squares fit of the points near the plane ([`refine_plane`]).

use crate::error::{HoughError, Result};
use crate::space::MAX_BINS;
use nalgebra::{Matrix3, Point3, Unit, Vector3};
use serde::{Deserialize, Serialize};

/// Discretisation of the ball accumulator.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BallConfig {
    /// Polar row height and approximate cell width, radians; in [0.1°, 30°].
    pub step: f64,
    /// Largest |ρ|, metres; positive.
    pub rho_max: f64,
    /// Distance bin width, metres; positive.
    pub rho_res: f64,
}

impl BallConfig {
    /// 2° cells, |ρ| < 10 m at 5 cm.
    pub fn recommended() -> BallConfig {
        BallConfig { step: 2f64.to_radians(), rho_max: 10.0, rho_res: 0.05 }
    }
}

/// A detected plane `normal · p = distance`.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BallPlane {
    /// Unit normal (z ≥ 0 for accumulator cells).
    pub normal: Unit<Vector3<f64>>,
    /// Signed distance from the origin along `normal`, metres.
    pub distance: f64,
    /// Votes of its cell (or inliers after [`refine_plane`]).
    pub votes: u32,
}

impl BallPlane {
    /// The angle between the two planes' normals, ignoring orientation, radians in [0, 90°].
    pub fn angle_to(&self, normal: &Vector3<f64>) -> f64 {
        (self.normal.dot(normal).abs() / normal.norm()).clamp(-1.0, 1.0).acos()
    }
}

/// The equal-area accumulator (see the module docs).
#[derive(Clone, Debug)]
pub struct BallAccumulator {
    config: BallConfig,
    /// First cell of each polar row, plus the total at the end.
    row_start: Vec<usize>,
    nx: Vec<f64>,
    ny: Vec<f64>,
    nz: Vec<f64>,
    nrho: usize,
    counts: Vec<u32>,
    points: usize,
}

impl BallAccumulator {
    /// Builds the cells. Fails on absurd parameters or more than [`MAX_BINS`] bins.
    pub fn new(config: BallConfig) -> Result<BallAccumulator> {
        let half_pi = std::f64::consts::FRAC_PI_2;
        let (lo, hi) = (0.1f64.to_radians(), 30f64.to_radians());
        if !(lo..=hi).contains(&config.step) {
            return Err(HoughError::BadParameter {
                what: "ball step",
                value: config.step,
                allowed: "[0.1°, 30°]",
            });
        }
        for (what, v) in [("ball rho_max", config.rho_max), ("ball rho_res", config.rho_res)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(HoughError::BadParameter { what, value: v, allowed: "> 0 m" });
            }
        }
        let nrho_f = (2.0 * config.rho_max / config.rho_res).ceil();
        let rows = (half_pi / config.step).ceil() as usize;
        let dtheta = half_pi / rows as f64;
        let mut row_start = vec![0];
        let (mut nx, mut ny, mut nz) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..rows {
            let theta = (i as f64 + 0.5) * dtheta;
            let cells = ((std::f64::consts::TAU * theta.sin() / dtheta).round() as usize).max(1);
            let (st, ct) = theta.sin_cos();
            for j in 0..cells {
                let phi = (j as f64 + 0.5) * std::f64::consts::TAU / cells as f64;
                let (sp, cp) = phi.sin_cos();
                nx.push(st * cp);
                ny.push(st * sp);
                nz.push(ct);
            }
            row_start.push(nx.len());
        }
        let bins = nx.len() as f64 * nrho_f;
        if bins.is_nan() || bins > MAX_BINS as f64 {
            return Err(HoughError::TooManyBins {
                what: "ball accumulator",
                bins: bins as u64,
                limit: MAX_BINS,
            });
        }
        let nrho = nrho_f as usize;
        Ok(BallAccumulator {
            counts: vec![0; nx.len() * nrho],
            config,
            row_start,
            nx,
            ny,
            nz,
            nrho,
            points: 0,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &BallConfig {
        &self.config
    }

    /// Number of normal cells.
    pub fn cells(&self) -> usize {
        self.nx.len()
    }

    /// Number of polar rows.
    pub fn rows(&self) -> usize {
        self.row_start.len() - 1
    }

    /// Number of cells in polar row `i` (grows like the sine of the polar angle).
    pub fn row_cells(&self, i: usize) -> usize {
        self.row_start[i + 1] - self.row_start[i]
    }

    /// The unit normal at the centre of cell `c`.
    pub fn cell_normal(&self, c: usize) -> Vector3<f64> {
        Vector3::new(self.nx[c], self.ny[c], self.nz[c])
    }

    /// Points voted so far.
    pub fn points(&self) -> usize {
        self.points
    }

    /// Zeroes the counts.
    pub fn clear(&mut self) {
        self.counts.fill(0);
        self.points = 0;
    }

    /// Adds the votes of `points` (any frame). Fails on a non-finite point.
    pub fn vote(&mut self, points: &[Point3<f64>]) -> Result<()> {
        if let Some(index) =
            points.iter().position(|p| !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()))
        {
            return Err(HoughError::NonFinitePoint { index });
        }
        let nrho = self.nrho;
        let nf = nrho as f64;
        let (rmin, res) = (-self.config.rho_max, self.config.rho_res);
        const B: usize = 256;
        let (mut xs, mut ys, mut zs) = ([0.0; B], [0.0; B], [0.0; B]);
        for block in points.chunks(B) {
            for (i, p) in block.iter().enumerate() {
                (xs[i], ys[i], zs[i]) = (p.x, p.y, p.z);
            }
            let m = block.len();
            for (c, row) in self.counts.chunks_exact_mut(nrho).enumerate() {
                let (a, b, cz) = (self.nx[c], self.ny[c], self.nz[c]);
                for i in 0..m {
                    let t = (a * xs[i] + b * ys[i] + cz * zs[i] - rmin) / res;
                    if t >= 0.0 && t < nf {
                        row[t as usize] += 1;
                    }
                }
            }
        }
        self.points += points.len();
        Ok(())
    }

    /// The `k` strongest planes, strongest first: bins in decreasing count, skipping any within
    /// `min_angle` (radians) and `min_distance` (metres) of a plane already taken (comparing a
    /// normal and its flip). Bins with fewer than `min_votes` votes are not considered.
    pub fn peaks(
        &self,
        k: usize,
        min_angle: f64,
        min_distance: f64,
        min_votes: u32,
    ) -> Vec<BallPlane> {
        let max = self.counts.iter().copied().max().unwrap_or(0);
        let floor = min_votes.max(1).max(max / 50);
        let mut cand: Vec<(u32, usize)> = self
            .counts
            .iter()
            .enumerate()
            .filter(|(_, c)| **c >= floor)
            .map(|(i, c)| (*c, i))
            .collect();
        cand.sort_unstable_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
        let mut out: Vec<BallPlane> = Vec::new();
        let cos_min = min_angle.cos();
        for (votes, i) in cand {
            if out.len() >= k {
                break;
            }
            let (c, ir) = (i / self.nrho, i % self.nrho);
            let n = self.cell_normal(c);
            let rho = -self.config.rho_max + (ir as f64 + 0.5) * self.config.rho_res;
            let near = out.iter().any(|p| {
                let dot = p.normal.dot(&n);
                dot.abs() >= cos_min && (rho - dot.signum() * p.distance).abs() < min_distance
            });
            if !near {
                out.push(BallPlane { normal: Unit::new_unchecked(n), distance: rho, votes });
            }
        }
        out
    }
}

/// Least-squares refinement: the points within `band` metres of `plane` are fitted by the
/// plane through their centroid with the normal of least variance (turned to agree with
/// `plane`'s); this is repeated with the band halved twice, so that points of neighbouring
/// planes near the first, coarse plane drop out. `None` with fewer than 3 such points or a
/// degenerate (collinear) set.
pub fn refine_plane(points: &[Point3<f64>], plane: &BallPlane, band: f64) -> Option<BallPlane> {
    let mut current = *plane;
    for b in [band, band / 2.0, band / 4.0] {
        current = fit_band(points, &current, b)?;
    }
    Some(current)
}

/// One least-squares fit of the points within `band` of `plane`.
fn fit_band(points: &[Point3<f64>], plane: &BallPlane, band: f64) -> Option<BallPlane> {
    let n = plane.normal.into_inner();
    let inliers = || points.iter().filter(|p| (n.dot(&p.coords) - plane.distance).abs() < band);
    let count = inliers().count();
    if count < 3 {
        return None;
    }
    let centroid = inliers().fold(Vector3::zeros(), |s, p| s + p.coords) / count as f64;
    let cov = inliers().fold(Matrix3::zeros(), |s, p| {
        let d = p.coords - centroid;
        s + d * d.transpose()
    });
    let eig = cov.symmetric_eigen();
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    if eig.eigenvalues[order[1]] <= 1e-12 * eig.eigenvalues[order[2]].max(1e-300) {
        return None;
    }
    let mut normal = eig.eigenvectors.column(order[0]).into_owned();
    if normal.dot(&n) < 0.0 {
        normal = -normal;
    }
    let normal = Unit::new_normalize(normal);
    Some(BallPlane { normal, distance: normal.dot(&centroid), votes: count as u32 })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_are_about_equal_area() {
        let b = BallAccumulator::new(BallConfig {
            step: 3f64.to_radians(),
            rho_max: 1.0,
            rho_res: 0.1,
        })
        .unwrap();
        assert_eq!(b.rows(), 30);
        assert_eq!(
            b.row_cells(0),
            1.max(
                (std::f64::consts::TAU * (1.5f64.to_radians()).sin() / 3f64.to_radians()).round()
                    as usize
            )
        );
        // Solid angle per cell: 2π(cos θ0 − cos θ1)/cells, within 40 % of the mean away from the pole.
        let dtheta = std::f64::consts::FRAC_PI_2 / 30.0;
        let mean = std::f64::consts::TAU / b.cells() as f64;
        for i in 2..30 {
            let area = std::f64::consts::TAU
                * ((i as f64 * dtheta).cos() - ((i + 1) as f64 * dtheta).cos())
                / b.row_cells(i) as f64;
            assert!((area / mean - 1.0).abs() < 0.4, "row {i}: {area} vs {mean}");
        }
        for c in 0..b.cells() {
            assert!((b.cell_normal(c).norm() - 1.0).abs() < 1e-12 && b.cell_normal(c).z >= 0.0);
        }
        assert!(
            BallAccumulator::new(BallConfig { step: 0.0, rho_max: 1.0, rho_res: 0.1 }).is_err()
        );
        assert!(
            BallAccumulator::new(BallConfig { step: 0.05, rho_max: -1.0, rho_res: 0.1 }).is_err()
        );
        assert!(
            BallAccumulator::new(BallConfig { step: 0.002, rho_max: 100.0, rho_res: 0.001 })
                .is_err()
        );
    }
}
