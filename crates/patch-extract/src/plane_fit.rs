//! Incremental orthogonal least-squares plane fitting (thesis §5.3.2, L4624–4628: "the optimal
//! plane" of a region is its orthogonal least-squares fit).
//!
//! A [`PlaneAccumulator`] keeps the running sums of a point set: the count `n`, `Σ x` (3 sums)
//! and `Σ x xᵀ` (6 sums of the symmetric matrix), all taken relative to a *reference point*
//! (the first point added) so that points far from the origin do not cancel catastrophically
//! when the scatter matrix `S = Σ x xᵀ − n c cᵀ` is formed. Adding or removing a point and
//! merging two accumulators are O(1); [`PlaneAccumulator::fit`] solves the 3×3 symmetric
//! eigenproblem of `S` on demand (nalgebra's `SymmetricEigen`):
//!
//! * the centroid `c = Σ x / n`;
//! * the normal `n̂` = the eigenvector of the smallest eigenvalue `λ₀` of `S`;
//! * the offset `d = n̂ · c`, so the plane is `n̂ · x = d`;
//! * the mean squared orthogonal distance `MSE = λ₀ / n` (the minimum of
//!   `Σ (n̂ · xᵢ − d)² / n` over all planes);
//! * the orientation rule: `n̂` is flipped so that it points toward a *viewpoint* (the sensor
//!   origin, i.e. the origin of a sensor-frame cloud): `n̂ · (viewpoint − c) ≥ 0`. With the
//!   viewpoint at the origin, `d ≤ 0` is the signed distance of the plane from the sensor along
//!   its normal.
//!
//! # Covariance of `(n, d)`
//! [`PlaneFit::covariance`] is the standard first-order covariance of the constrained
//! least-squares estimate, the same construction as [Pathak et al. 2010] ("Fast registration
//! based on noisy planes with unknown correspondences", T-RO 26(3)) with one variance for all
//! points instead of their per-point range-dependent variances:
//!
//! 1. Perturb the fit in its two rotational degrees of freedom and its offset *at the
//!    centroid*: `n = n̂ + a e₁ + b e₂` (`e₁`, `e₂` the other two eigenvectors, `|n| = 1`
//!    enforced to second order) and `n · x = n · c + δ`. The cost
//!    `J = Σ (n · (xᵢ − c) − δ)²` has at the optimum the Hessian (halved)
//!    `diag(λ₁ − λ₀, λ₂ − λ₀, n)` in `(a, b, δ)`: the cross terms vanish because the `eᵢ` are
//!    eigenvectors and `Σ (xᵢ − c) = 0`; `−λ₀` is the curvature of the unit-norm constraint.
//! 2. With independent isotropic errors of variance `σ²` along the normal,
//!    `Cov(a, b, δ) = σ² diag(1 / (λ₁ − λ₀), 1 / (λ₂ − λ₀), 1 / n)`, where `σ²` is estimated
//!    from the residuals as `λ₀ / (n − 3)` (three parameters fitted).
//! 3. Map to `(nx, ny, nz, d)` with the Jacobian of `n = n̂ + a e₁ + b e₂`,
//!    `d = n · c + δ`: columns `(e₁, e₁ · c)`, `(e₂, e₂ · c)`, `(0, 1)`; the 4×4 covariance is
//!    `J Cov(a, b, δ) Jᵀ` (rank 3: no variance along `n̂` itself).
//!
//! This is exact for Gaussian noise to first order; it is *not* the full Pathak model (no
//! per-point variances, no sensor-beam-direction noise).

use nalgebra::{Matrix3, Matrix4x3, SymmetricEigen, Vector3 as NVector3};
use patch_core::{Plane, PlaneCovariance, Point3, Real, UnitVector3, Vector3};

/// Running sums of a point set for O(1) incremental plane fitting. See the module docs.
///
/// `Copy` and 88 bytes: cheap to clone for "what if I added this point" queries.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct PlaneAccumulator {
    count: usize,
    /// The reference point all sums are taken relative to (the first point added).
    reference: Vector3,
    /// `Σ (x − reference)`.
    sum: Vector3,
    /// `Σ (x − reference)(x − reference)ᵀ` as `[xx, xy, xz, yy, yz, zz]`.
    sum_sq: [Real; 6],
}

/// The least-squares plane of a point set, from [`PlaneAccumulator::fit`].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PlaneFit {
    /// The plane, normal toward the viewpoint given to [`PlaneAccumulator::fit`].
    pub plane: Plane,
    /// The centroid of the points.
    pub centroid: Point3,
    /// Mean squared orthogonal distance of the points to the plane, `λ₀ / n`.
    pub mse: Real,
    /// Eigenvalues of the scatter matrix `Σ (x − c)(x − c)ᵀ`, ascending (`λ₀ ≤ λ₁ ≤ λ₂`).
    pub eigenvalues: Vector3,
    /// The matching unit eigenvectors as columns (column 0 is ± the normal).
    pub eigenvectors: Matrix3<Real>,
    /// The number of points.
    pub count: usize,
}

impl PlaneFit {
    /// The surface variation `λ₀ / (λ₀ + λ₁ + λ₂)` (Pauly et al. 2002): 0 for a perfect plane,
    /// at most 1/3 for an isotropic blob. Scale-free, for ordering seeds.
    pub fn curvature(&self) -> Real {
        let total = self.eigenvalues.sum();
        if total > 0.0 { self.eigenvalues[0] / total } else { 0.0 }
    }

    /// The first-order covariance of `(nx, ny, nz, d)` (module docs, "Covariance of (n, d)").
    /// `None` with fewer than four points (no residual degree of freedom) or when the two larger
    /// eigenvalues do not exceed the smallest (the in-plane extent does not fix the normal).
    pub fn covariance(&self) -> Option<PlaneCovariance> {
        if self.count < 4 {
            return None;
        }
        let l = &self.eigenvalues;
        let (g1, g2) = (l[1] - l[0], l[2] - l[0]);
        if !(g1 > 0.0 && g2 > 0.0) {
            return None;
        }
        let sigma2 = l[0].max(0.0) / (self.count - 3) as Real;
        let e1: NVector3<Real> = self.eigenvectors.column(1).into_owned();
        let e2: NVector3<Real> = self.eigenvectors.column(2).into_owned();
        let c = self.centroid.coords;
        let jac = Matrix4x3::new(
            e1.x,
            e2.x,
            0.0,
            e1.y,
            e2.y,
            0.0,
            e1.z,
            e2.z,
            0.0,
            e1.dot(&c),
            e2.dot(&c),
            1.0,
        );
        let inner = Matrix3::from_diagonal(&NVector3::new(
            sigma2 / g1,
            sigma2 / g2,
            sigma2 / self.count as Real,
        ));
        PlaneCovariance::new(jac * inner * jac.transpose()).ok()
    }
}

impl PlaneAccumulator {
    /// An empty accumulator.
    pub fn new() -> PlaneAccumulator {
        PlaneAccumulator::default()
    }

    /// The sums of `points`.
    pub fn from_points<'a>(points: impl IntoIterator<Item = &'a Point3>) -> PlaneAccumulator {
        let mut acc = PlaneAccumulator::new();
        for p in points {
            acc.add(p);
        }
        acc
    }

    /// The number of points.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether no point is in the set.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    fn accumulate(&mut self, v: &Vector3, sign: Real) {
        self.sum += v * sign;
        let s = &mut self.sum_sq;
        s[0] += sign * v.x * v.x;
        s[1] += sign * v.x * v.y;
        s[2] += sign * v.x * v.z;
        s[3] += sign * v.y * v.y;
        s[4] += sign * v.y * v.z;
        s[5] += sign * v.z * v.z;
    }

    /// Adds a point. O(1).
    pub fn add(&mut self, p: &Point3) {
        if self.count == 0 {
            *self = PlaneAccumulator { reference: p.coords, ..PlaneAccumulator::default() };
        }
        self.count += 1;
        let v = p.coords - self.reference;
        self.accumulate(&v, 1.0);
    }

    /// Removes a point that was added before (removing a point that is not in the set gives
    /// meaningless sums; removing the last point resets the accumulator). O(1).
    pub fn remove(&mut self, p: &Point3) {
        match self.count {
            0 => {}
            1 => *self = PlaneAccumulator::default(),
            _ => {
                self.count -= 1;
                let v = p.coords - self.reference;
                self.accumulate(&v, -1.0);
            }
        }
    }

    /// Adds all points of `other`, re-expressing its sums relative to this reference. O(1).
    pub fn merge(&mut self, other: &PlaneAccumulator) {
        if other.count == 0 {
            return;
        }
        if self.count == 0 {
            *self = *other;
            return;
        }
        // other's points relative to our reference: v = w + t with t = other.ref − self.ref.
        let t = other.reference - self.reference;
        let n = other.count as Real;
        let (w, ws) = (&other.sum, &other.sum_sq);
        let cross = |i: usize, j: usize| w[i] * t[j] + t[i] * w[j] + n * t[i] * t[j];
        self.count += other.count;
        self.sum += w + t * n;
        self.sum_sq[0] += ws[0] + cross(0, 0);
        self.sum_sq[1] += ws[1] + cross(0, 1);
        self.sum_sq[2] += ws[2] + cross(0, 2);
        self.sum_sq[3] += ws[3] + cross(1, 1);
        self.sum_sq[4] += ws[4] + cross(1, 2);
        self.sum_sq[5] += ws[5] + cross(2, 2);
    }

    /// The centroid, `None` for an empty set.
    pub fn centroid(&self) -> Option<Point3> {
        (self.count > 0).then(|| Point3::from(self.reference + self.sum / self.count as Real))
    }

    /// The scatter matrix `Σ (x − c)(x − c)ᵀ`, `None` for an empty set.
    pub fn scatter(&self) -> Option<Matrix3<Real>> {
        if self.count == 0 {
            return None;
        }
        let m = self.sum / self.count as Real;
        let s = &self.sum_sq;
        let raw = Matrix3::new(s[0], s[1], s[2], s[1], s[3], s[4], s[2], s[4], s[5]);
        Some(raw - m * self.sum.transpose())
    }

    /// The mean squared distance of the points to the plane through their centroid with
    /// normal `normal` (unit): `nᵀ S n / n`. An upper bound of the fitted [`PlaneFit::mse`]
    /// (Rayleigh quotient), equal to it when `normal` is the fitted normal. O(1).
    pub fn mse_along(&self, normal: &Vector3) -> Option<Real> {
        let s = self.scatter()?;
        Some((normal.dot(&(s * normal)) / self.count as Real).max(0.0))
    }

    /// The least-squares plane, normal oriented toward `viewpoint`. `None` with fewer than
    /// three points or when the points are (numerically) collinear or coincident, i.e. when
    /// the middle eigenvalue is at most `1e-12` times the largest.
    pub fn fit(&self, viewpoint: &Point3) -> Option<PlaneFit> {
        if self.count < 3 {
            return None;
        }
        let centroid = self.centroid()?;
        let eig = SymmetricEigen::new(self.scatter()?);
        let mut order = [0usize, 1, 2];
        order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
        let eigenvalues = Vector3::new(
            eig.eigenvalues[order[0]].max(0.0),
            eig.eigenvalues[order[1]],
            eig.eigenvalues[order[2]],
        );
        if !(eigenvalues[2] > 0.0 && eigenvalues[1] > 1e-12 * eigenvalues[2]) {
            return None;
        }
        let mut eigenvectors = Matrix3::zeros();
        for (k, &i) in order.iter().enumerate() {
            eigenvectors.set_column(k, &eig.eigenvectors.column(i));
        }
        let mut normal: Vector3 = eigenvectors.column(0).into_owned();
        if normal.dot(&(viewpoint - centroid)) < 0.0 {
            normal = -normal;
            eigenvectors.set_column(0, &normal);
        }
        let normal = UnitVector3::new_normalize(normal);
        let offset = normal.dot(&centroid.coords);
        Some(PlaneFit {
            plane: Plane { normal, offset },
            centroid,
            mse: eigenvalues[0] / self.count as Real,
            eigenvalues,
            eigenvectors,
            count: self.count,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The batch reference: SVD of the centred point matrix, smallest singular vector.
    fn batch_fit(points: &[Point3]) -> (Vector3, Real, Real) {
        let n = points.len() as Real;
        let c = points.iter().fold(Vector3::zeros(), |a, p| a + p.coords) / n;
        let m = nalgebra::DMatrix::from_fn(points.len(), 3, |i, j| points[i][j] - c[j]);
        let svd = m.svd(false, true);
        let (k, _) = svd.singular_values.argmin();
        let v_t = svd.v_t.unwrap();
        let normal = Vector3::new(v_t[(k, 0)], v_t[(k, 1)], v_t[(k, 2)]);
        let s = svd.singular_values[k];
        (normal, normal.dot(&c), s * s / n)
    }

    fn noisy_plane() -> impl Strategy<Value = Vec<Point3>> {
        (
            -1.0..1.0f64,
            -1.0..1.0f64,
            0.2..1.0f64,
            -20.0..20.0f64,
            prop::collection::vec((-3.0..3.0f64, -3.0..3.0f64, -0.05..0.05f64), 5..60),
            -50.0..50.0f64,
        )
            .prop_map(|(nx, ny, nz, d, uvw, shift)| {
                let n = Vector3::new(nx, ny, nz).normalize();
                let u = n.cross(&Vector3::x()).try_normalize(1e-6).unwrap_or(Vector3::y());
                let v = n.cross(&u);
                uvw.iter()
                    .map(|&(a, b, w)| {
                        Point3::from(n * d + u * a + v * b + n * w + Vector3::repeat(shift))
                    })
                    .collect()
            })
    }

    proptest! {
        #[test]
        fn incremental_fit_matches_batch_svd(points in noisy_plane()) {
            let acc = PlaneAccumulator::from_points(&points);
            let fit = acc.fit(&Point3::origin()).unwrap();
            let (n, d, mse) = batch_fit(&points);
            let sign = fit.plane.normal.dot(&n).signum();
            prop_assert!((fit.plane.normal.into_inner() - n * sign).norm() < 1e-7);
            prop_assert!((fit.plane.offset - d * sign).abs() < 1e-6);
            prop_assert!((fit.mse - mse).abs() < 1e-9 * (1.0 + mse));
            // Orientation: toward the origin.
            prop_assert!(fit.plane.normal.dot(&(Point3::origin() - fit.centroid)) >= 0.0);
            prop_assert!(fit.plane.offset <= 1e-12);
        }

        #[test]
        fn add_remove_and_merge_agree(points in noisy_plane(), split in 0usize..60) {
            let split = split.min(points.len());
            let full = PlaneAccumulator::from_points(&points);
            let mut a = PlaneAccumulator::from_points(&points[..split]);
            let b = PlaneAccumulator::from_points(&points[split..]);
            a.merge(&b);
            prop_assert_eq!(a.len(), full.len());
            let (fa, ff) = (a.fit(&Point3::origin()).unwrap(), full.fit(&Point3::origin()).unwrap());
            prop_assert!((fa.plane.normal.into_inner() - ff.plane.normal.into_inner()).norm() < 1e-8);
            prop_assert!((fa.mse - ff.mse).abs() < 1e-9 * (1.0 + ff.mse));
            // Remove the second part again: back to the first part's fit.
            let mut r = full;
            for p in &points[split..] {
                r.remove(p);
            }
            let first = PlaneAccumulator::from_points(&points[..split]);
            prop_assert_eq!(r.len(), first.len());
            if let (Some(fr), Some(f1)) = (r.fit(&Point3::origin()), first.fit(&Point3::origin())) {
                prop_assert!((fr.centroid - f1.centroid).norm() < 1e-8);
                prop_assert!((fr.mse - f1.mse).abs() < 1e-8 * (1.0 + f1.mse));
            }
            // The Rayleigh bound holds and is tight at the fitted normal.
            let n = ff.plane.normal.into_inner();
            prop_assert!((full.mse_along(&n).unwrap() - ff.mse).abs() < 1e-9 * (1.0 + ff.mse));
            prop_assert!(full.mse_along(&Vector3::z()).unwrap() >= ff.mse - 1e-12);
        }
    }

    #[test]
    fn far_from_origin_is_well_conditioned() {
        let base = Vector3::new(1e6, -2e6, 3e5);
        let pts: Vec<Point3> = (0..100)
            .map(|i| {
                let (a, b) = ((i % 10) as Real * 0.1, (i / 10) as Real * 0.1);
                Point3::from(base + Vector3::new(a, b, 1e-4 * ((i * 7) % 3) as Real))
            })
            .collect();
        let fit = PlaneAccumulator::from_points(&pts).fit(&Point3::origin()).unwrap();
        assert!(fit.plane.normal.z.abs() > 1.0 - 1e-6);
        assert!(fit.mse < 1e-8);
    }

    #[test]
    fn degenerate_sets_have_no_fit() {
        let mut acc = PlaneAccumulator::new();
        assert!(acc.fit(&Point3::origin()).is_none());
        assert!(acc.centroid().is_none());
        for i in 0..5 {
            acc.add(&Point3::new(i as Real, 2.0 * i as Real, 1.0));
        }
        assert!(acc.fit(&Point3::origin()).is_none(), "collinear");
        acc.remove(&Point3::origin());
        let mut one = PlaneAccumulator::new();
        one.add(&Point3::new(1.0, 2.0, 3.0));
        one.remove(&Point3::new(1.0, 2.0, 3.0));
        assert!(one.is_empty());
    }

    #[test]
    fn covariance_shrinks_with_more_points() {
        let grid = |k: usize| -> Vec<Point3> {
            (0..k * k)
                .map(|i| {
                    let (a, b) = ((i % k) as Real / k as Real, (i / k) as Real / k as Real);
                    let noise = 0.01 * (((i * 7919) % 13) as Real / 6.0 - 1.0);
                    Point3::new(a, b, 2.0 + noise)
                })
                .collect()
        };
        let small = PlaneAccumulator::from_points(&grid(5)).fit(&Point3::origin()).unwrap();
        let large = PlaneAccumulator::from_points(&grid(40)).fit(&Point3::origin()).unwrap();
        let (cs, cl) = (small.covariance().unwrap(), large.covariance().unwrap());
        assert!(cl.matrix()[(3, 3)] < cs.matrix()[(3, 3)]);
        assert!(cl.matrix()[(0, 0)] < cs.matrix()[(0, 0)]);
        // No variance along the normal itself.
        let n = large.plane.normal.into_inner();
        let nn = nalgebra::Vector4::new(n.x, n.y, n.z, 0.0);
        assert!(nn.dot(&(cl.matrix() * nn)).abs() < 1e-15);
        // Normal points toward the origin: plane z = 2 has normal −z, offset −2.
        assert!(large.plane.normal.z < -0.999);
        assert!((large.plane.offset + 2.0).abs() < 1e-2);
    }
}
