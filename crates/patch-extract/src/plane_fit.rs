//! Incremental orthogonal least-squares plane fitting (thesis §5.3.2, L4624–4628: "the optimal
//! plane" of a region is its orthogonal least-squares fit).
//!
//! A [`PlaneAccumulator`] keeps the running sums of a point set: the count `n`, `Σ x` (3 sums)
//! and `Σ x xᵀ` (6 sums of the symmetric matrix), all taken relative to a *reference point*
//! (the first point added) so that points far from the origin do not cancel catastrophically
//! when the scatter matrix `S = Σ x xᵀ − n c cᵀ` is formed. Adding or removing a point and
//! merging two accumulators are O(1); [`PlaneAccumulator::fit`] solves the 3×3 symmetric
//! eigenproblem of `S` on demand (nalgebra's `SymmetricEigen` algorithm, its QR iteration
//! written out for the fixed size with the same floating-point operations, so the results are
//! bit for bit nalgebra's):
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
        // `add` for each point, with the sums in locals: the same operations in the same order.
        let mut points = points.into_iter();
        let Some(first) = points.next() else { return PlaneAccumulator::new() };
        let reference = first.coords;
        let mut count = 0;
        let (mut sx, mut sy, mut sz) = (0.0, 0.0, 0.0);
        let (mut xx, mut xy, mut xz, mut yy, mut yz, mut zz) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        for p in std::iter::once(first).chain(points) {
            count += 1;
            let (x, y, z) = (p.x - reference.x, p.y - reference.y, p.z - reference.z);
            sx += x;
            sy += y;
            sz += z;
            xx += x * x;
            xy += x * y;
            xz += x * z;
            yy += y * y;
            yz += y * z;
            zz += z * z;
        }
        PlaneAccumulator {
            count,
            reference,
            sum: Vector3::new(sx, sy, sz),
            sum_sq: [xx, xy, xz, yy, yz, zz],
        }
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
    #[inline]
    pub fn add(&mut self, p: &Point3) {
        if self.count == 0 {
            *self = PlaneAccumulator { reference: p.coords, ..PlaneAccumulator::default() };
        }
        self.count += 1;
        let v = p.coords - self.reference;
        // `accumulate(&v, 1.0)` without the multiplications by 1, which are exact.
        self.sum += v;
        let s = &mut self.sum_sq;
        s[0] += v.x * v.x;
        s[1] += v.x * v.y;
        s[2] += v.x * v.z;
        s[3] += v.y * v.y;
        s[4] += v.y * v.z;
        s[5] += v.z * v.z;
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

    /// For a unit `normal`: `(Σ dᵢ, Σ dᵢ²)` with `dᵢ = normal · (xᵢ − r)` for the points'
    /// reference `r` ([`PlaneAccumulator::offset_along`]). With them, `nᵀ S n` of the points
    /// plus one more at offset `d` is `Σ dᵢ² + d² − (Σ dᵢ + d)² / (n + 1)` in O(1)
    /// ([`PlaneAccumulator::mse_along`] without the scatter matrix). O(1).
    pub(crate) fn moments_along(&self, normal: &Vector3) -> (Real, Real) {
        let s = &self.sum_sq;
        let (x, y, z) = (normal.x, normal.y, normal.z);
        let quadratic = x * x * s[0]
            + y * y * s[3]
            + z * z * s[5]
            + 2.0 * (x * y * s[1] + x * z * s[2] + y * z * s[4]);
        (normal.dot(&self.sum), quadratic)
    }

    /// `normal · (p − r)` for the points' reference `r` (see
    /// [`PlaneAccumulator::moments_along`]).
    pub(crate) fn offset_along(&self, normal: &Vector3, p: &Point3) -> Real {
        normal.dot(&(p.coords - self.reference))
    }

    /// [`PlaneFit::curvature`] of [`PlaneAccumulator::fit`] to within rounding, without its
    /// eigendecomposition: the smallest eigenvalue by Newton's method on the characteristic
    /// polynomial `det(S − λI)`, from the certified Rayleigh quotient just above it
    /// ([`PlaneAccumulator::certified_plane`]; below the second eigenvalue, so the iteration
    /// falls monotonically onto the smallest), over the scatter's trace. `None` where the
    /// bounds are not certified. O(1).
    pub(crate) fn polished_curvature(&self) -> Option<Real> {
        if self.count < 3 {
            return None;
        }
        let m = self.scatter()?;
        let bound = certify(&m)?;
        let sym = |i: usize, j: usize| 0.5 * (m[(i, j)] + m[(j, i)]);
        let (a, b, c, d, e, f) = (sym(0, 0), sym(0, 1), sym(0, 2), sym(1, 1), sym(1, 2), sym(2, 2));
        let trace = a + d + f;
        let mut lambda = bound.lambda0_upper;
        for _ in 0..4 {
            let (ad, dd, fd) = (a - lambda, d - lambda, f - lambda);
            let (m1, m2, m3) = (dd * fd - e * e, ad * fd - c * c, ad * dd - b * b);
            let p = ad * m1 - b * (b * fd - c * e) + c * (b * e - c * dd);
            let slope = -(m1 + m2 + m3);
            if slope.is_nan() || slope >= 0.0 {
                break;
            }
            let step = p / slope;
            if !step.is_finite() {
                break;
            }
            lambda -= step;
            if step.abs() <= 1e-15 * trace {
                break;
            }
        }
        let curvature = lambda.max(0.0) / trace;
        (curvature.is_finite() && trace > 0.0).then_some(curvature)
    }

    /// The least-squares plane, normal oriented toward `viewpoint`. `None` with fewer than
    /// three points or when the points are (numerically) collinear or coincident, i.e. when
    /// the middle eigenvalue is at most `1e-12` times the largest.
    pub fn fit(&self, viewpoint: &Point3) -> Option<PlaneFit> {
        if self.count < 3 {
            return None;
        }
        let centroid = self.centroid()?;
        let eig = symmetric_eigen(self.scatter()?);
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

/// A plane fit's normal and surface variation known to within certified bounds, from
/// [`PlaneAccumulator::certified_plane`] (without the eigendecomposition of
/// [`PlaneAccumulator::fit`]).
#[derive(Copy, Clone, Debug, PartialEq)]
pub(crate) struct CertifiedPlane {
    /// At most [`PlaneFit::curvature`] of the fit, in [`f64::total_cmp`] order.
    pub curvature_lower: Real,
    /// A unit vector within `normal_error` (Euclidean distance) of the fit's normal or of
    /// its opposite.
    pub normal: Vector3,
    /// See `normal`.
    pub normal_error: Real,
    /// At least the scatter's smallest eigenvalue (the Rayleigh quotient of `normal`), within
    /// the certified distance of it.
    pub lambda0_upper: Real,
}

impl PlaneAccumulator {
    /// Bounds on what [`PlaneAccumulator::fit`] (with any viewpoint) gives, certified for
    /// rounding: `None` when they cannot be certified cheaply (non-finite sums, nearly equal
    /// smallest eigenvalues, fewer than three points), and then only [`fit`](Self::fit)
    /// tells. When `Some`, the fit is `Some` too.
    ///
    /// The normal is the smallest eigenvector of the scatter matrix `S` by one step of power
    /// iteration on its adjugate; with `λ'` its Rayleigh quotient and `r` its residual, the
    /// second eigenvalue `λ₁` is at least the smaller eigenvalue `μ₁` of `S` compressed to the
    /// normal's orthogonal complement (Cauchy interlacing), so the angle to the true normal is
    /// at most `|r| / (μ₁ − λ')` (Davis–Kahan) and `λ₀ ≥ λ' − |r|² / (μ₁ − λ')` (Kato–Temple).
    /// Slack far above rounding (relative `1e-10` of `|S|`) covers the floating-point
    /// evaluation here and in `fit`'s eigensolver.
    pub(crate) fn certified_plane(&self) -> Option<CertifiedPlane> {
        if self.count < 3 {
            return None;
        }
        certify(&self.scatter()?)
    }
}

/// [`PlaneAccumulator::certified_plane`] of the points `members` of `points` (at least three,
/// at most 49: the bounds allow for the summation order, which is not `from_points`'s).
pub(crate) fn certified_window_plane(points: &[Point3], members: &[u32]) -> Option<CertifiedPlane> {
    if !(3..=49).contains(&members.len()) {
        return None;
    }
    let reference = points[members[0] as usize].coords;
    // Two interleaved partial sums (independent dependency chains), relative to the first
    // point: [x, y, z, xx, xy, xz, yy, yz, zz].
    let terms = |p: u32| {
        let v = points[p as usize].coords - reference;
        [v.x, v.y, v.z, v.x * v.x, v.x * v.y, v.x * v.z, v.y * v.y, v.y * v.z, v.z * v.z]
    };
    let add =
        |acc: [Real; 9], t: [Real; 9]| -> [Real; 9] { std::array::from_fn(|k| acc[k] + t[k]) };
    let (mut even, mut odd) = ([0.0; 9], [0.0; 9]);
    let mut pairs = members.chunks_exact(2);
    for pair in &mut pairs {
        even = add(even, terms(pair[0]));
        odd = add(odd, terms(pair[1]));
    }
    if let [last] = pairs.remainder() {
        even = add(even, terms(*last));
    }
    let t = add(even, odd);
    let n = members.len() as Real;
    let sum = Vector3::new(t[0], t[1], t[2]);
    let m = sum / n;
    let raw = Matrix3::new(t[3], t[4], t[5], t[4], t[6], t[7], t[5], t[7], t[8]);
    certify(&(raw - m * sum.transpose()))
}

/// The bounds of [`PlaneAccumulator::certified_plane`] from a scatter matrix `m` (of at least
/// three points; symmetric up to rounding).
pub(crate) fn certify(m: &Matrix3<Real>) -> Option<CertifiedPlane> {
    if !m.iter().all(|e| e.is_finite()) {
        return None;
    }
    let sym = |i: usize, j: usize| 0.5 * (m[(i, j)] + m[(j, i)]);
    let (a, b, c, d, e, f) = (sym(0, 0), sym(0, 1), sym(0, 2), sym(1, 1), sym(1, 2), sym(2, 2));
    let s = Matrix3::new(a, b, c, b, d, e, c, e, f);
    // A bound of the spectral norm (the sum of the entries' magnitudes, at least the
    // Frobenius norm).
    let norm: Real = m.iter().map(|x| x.abs()).sum();
    if !(norm > 0.0 && norm.is_finite()) {
        return None;
    }
    let adj = Matrix3::new(
        d * f - e * e,
        c * e - b * f,
        b * e - c * d,
        c * e - b * f,
        a * f - c * c,
        b * c - a * e,
        b * e - c * d,
        b * c - a * e,
        a * d - b * b,
    );
    let column = (0..3)
        .max_by(|&i, &j| adj.column(i).norm_squared().total_cmp(&adj.column(j).norm_squared()))?;
    // The adjugate's largest column and its image, normalised once (scale aside, both are
    // the same direction; entries are of the order |S|⁴ at most, far from overflow for any
    // plausible window, and a non-finite or zero length gives no bound).
    let v = adj * adj.column(column);
    let length = v.norm();
    if !(length > 0.0 && length.is_finite()) {
        return None;
    }
    let v = v * (1.0 / length);
    let rayleigh = v.dot(&(s * v));
    let residual = (s * v - v * rayleigh).norm();
    // The compression of S to v's orthogonal complement: trace and determinant.
    let t = (a + d + f) - rayleigh;
    let q = v.dot(&(adj * v));
    let mu2 = 0.5 * (t + (t * t - 4.0 * q).max(0.0).sqrt());
    if mu2.is_nan() || mu2 <= 0.0 {
        return None;
    }
    // Reciprocals instead of divisions: their extra ulp is far inside the slack.
    let inverse_mu2 = 1.0 / mu2;
    let mu1 = q * inverse_mu2;
    let slack = 1e-10 * norm;
    let mu1_lower = mu1 - slack - 1e-10 * norm * norm * inverse_mu2;
    let gap = mu1_lower - rayleigh - slack;
    if !(gap > 1e-6 * norm && mu1_lower > 1e-9 * norm) {
        return None;
    }
    let inverse_gap = 1.0 / gap;
    let angle = (residual + slack) * inverse_gap + 1e-9;
    if angle.is_nan() || angle >= 0.5 {
        return None;
    }
    let lambda0_lower = (rayleigh - residual * residual * inverse_gap - slack).max(0.0);
    let total_upper = (a + d + f) + 3.0 * slack;
    let lower = lambda0_lower / total_upper * (1.0 - 1e-9);
    let curvature_lower = if lower > 0.0 && lower.is_finite() { lower } else { -0.0 };
    // sin θ ≤ `angle` < 1/2, so the chord 2 sin(θ/2) is below 1.04 `angle`.
    Some(CertifiedPlane {
        curvature_lower,
        normal: v,
        normal_error: 1.05 * angle,
        lambda0_upper: rayleigh,
    })
}

/// `nalgebra::SymmetricEigen::new(m)` for a 3×3 matrix, bit for bit: the same operations in
/// the same order (scaling by the largest entry, Householder tridiagonalisation by nalgebra
/// itself, then the implicit symmetric QR iteration with Wilkinson shifts and Givens
/// rotations, and the closed-form 2×2 step), written out for fixed sizes, which the generic
/// code is not. A matrix with a non-finite entry goes to nalgebra.
fn symmetric_eigen(mut m: Matrix3<Real>) -> SymmetricEigen<Real, nalgebra::U3> {
    if !m.iter().all(|e| e.is_finite()) {
        return SymmetricEigen::new(m);
    }
    let eps = Real::EPSILON;
    let m_amax = m.iter().fold(0.0, |a: Real, e| a.max(e.abs()));
    if m_amax != 0.0 {
        m.iter_mut().for_each(|e| *e /= m_amax);
    }
    let (mut q, diag, off) = nalgebra::linalg::SymmetricTridiagonal::new(m).unpack();
    let mut d = [diag[0], diag[1], diag[2]];
    let mut o = [off[0], off[1]];
    // Rotates columns `i` and `i + 1` of `q` by (c, s) as `GivensRotation::rotate_rows`.
    let rotate = |q: &mut Matrix3<Real>, i: usize, c: Real, s: Real| {
        for j in 0..3 {
            let (a, b) = (q[(j, i)], q[(j, i + 1)]);
            q[(j, i)] = a * c + s * b;
            q[(j, i + 1)] = -s * a + b * c;
        }
    };
    let (mut start, mut end) = delimit_subproblem(&d, &mut o, 2, eps);
    while end != start {
        let subdim = end - start + 1;
        if subdim > 2 {
            let (mm, n) = (end - 1, end);
            let (mut vx, mut vy) = (d[start] - wilkinson_shift(d[mm], d[n], o[mm]), o[start]);
            for i in start..n {
                let j = i + 1;
                // `GivensRotation::cancel_y`.
                if vy == 0.0 {
                    break;
                }
                let (mod0, sign0) = if vx >= 0.0 { (vx, 1.0) } else { (-vx, -1.0) };
                let denom = (mod0 * mod0 + vy * vy).sqrt();
                let c = mod0 / denom;
                let s = -vy / (sign0 * denom);
                let norm = sign0 * denom;
                if i > start {
                    o[i - 1] = norm;
                }
                let (mii, mjj, mij) = (d[i], d[j], o[i]);
                let (cc, ss, cs) = (c * c, s * s, c * s);
                let b = cs * 2.0 * mij;
                d[i] = (cc * mii + ss * mjj) - b;
                d[j] = (ss * mii + cc * mjj) + b;
                o[i] = cs * (mii - mjj) + mij * (cc - ss);
                if i != n - 1 {
                    vx = o[i];
                    vy = -s * o[i + 1];
                    o[i + 1] *= c;
                }
                // The inverse rotation: sine −s.
                rotate(&mut q, i, c, -s);
            }
            if o[mm].abs() <= eps * (d[mm].abs() + d[n].abs()) {
                end -= 1;
            }
        } else if subdim == 2 {
            // `compute_2x2_eigvals` of [[d0, o], [o, d1]]; the discriminant is a sum of
            // squares, so its square root always exists.
            let (h00, h11, h01) = (d[start], d[start + 1], o[start]);
            let val = (h00 - h11) * 0.5;
            let discr = h01 * h01 + val * val;
            let sqrt_discr = discr.sqrt();
            let half_tra = (h00 + h11) * 0.5;
            let (e0, e1) = (half_tra + sqrt_discr, half_tra - sqrt_discr);
            let (bx, by) = if (e0 - d[start + 1]).abs() > (e0 - d[start]).abs() {
                (e0 - d[start + 1], o[start])
            } else {
                (o[start], e0 - d[start])
            };
            d[start] = e0;
            d[start + 1] = e1;
            // `GivensRotation::try_new(bx, by, eps)`.
            let (mod0, sign0) = if bx >= 0.0 { (bx, 1.0) } else { (-bx, -1.0) };
            let denom = (mod0 * mod0 + by * by).sqrt();
            if denom > eps {
                let norm = sign0 * denom;
                rotate(&mut q, start, mod0 / denom, by / norm);
            }
            end -= 1;
        }
        (start, end) = delimit_subproblem(&d, &mut o, end, eps);
    }
    let eigenvalues = Vector3::new(d[0] * m_amax, d[1] * m_amax, d[2] * m_amax);
    SymmetricEigen { eigenvectors: q, eigenvalues }
}

/// nalgebra's `wilkinson_shift`: the eigenvalue of `[[tmm, tmn], [tmn, tnn]]` nearer `tnn`.
fn wilkinson_shift(tmm: Real, tnn: Real, tmn: Real) -> Real {
    let sq_tmn = tmn * tmn;
    if sq_tmn != 0.0 {
        let d = (tmm - tnn) * 0.5;
        tnn - sq_tmn / (d + d.signum() * (d * d + sq_tmn).sqrt())
    } else {
        tnn
    }
}

/// nalgebra's `SymmetricEigen::delimit_subproblem` for a 3×3 tridiagonal matrix.
fn delimit_subproblem(d: &[Real; 3], o: &mut [Real; 2], end: usize, eps: Real) -> (usize, usize) {
    let mut n = end;
    while n > 0 {
        let m = n - 1;
        if o[m].abs() > eps * (d[n].abs() + d[m].abs()) {
            break;
        }
        n -= 1;
    }
    if n == 0 {
        return (0, 0);
    }
    let mut new_start = n - 1;
    while new_start > 0 {
        let m = new_start - 1;
        if o[m] == 0.0 || o[m].abs() <= eps * (d[new_start].abs() + d[m].abs()) {
            o[m] = 0.0;
            break;
        }
        new_start -= 1;
    }
    (new_start, n)
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

    /// Bits of a decomposition, for exact comparison.
    fn eigen_bits(e: &SymmetricEigen<Real, nalgebra::U3>) -> Vec<u64> {
        e.eigenvalues.iter().chain(e.eigenvectors.iter()).map(|x| x.to_bits()).collect()
    }

    #[test]
    fn symmetric_eigen_matches_nalgebra_bit_for_bit() {
        // A small deterministic generator: scatter matrices of random point sets (flat, thin,
        // blob-like, far from the origin), exactly diagonal and repeated-eigenvalue matrices.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as Real / (1u64 << 53) as Real * 2.0 - 1.0
        };
        let mut matrices = vec![
            Matrix3::zeros(),
            Matrix3::identity(),
            Matrix3::from_diagonal(&NVector3::new(1.0, 2.0, 3.0)),
            Matrix3::from_diagonal(&NVector3::new(3.0, 3.0, 1e-9)),
            Matrix3::new(2.0, 1.0, 0.0, 1.0, 2.0, 0.0, 0.0, 0.0, 5.0),
            Matrix3::new(0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        ];
        for k in 0..20_000 {
            let scale = [1e-6, 1e-3, 1.0, 1e3][k % 4];
            let flat = [1.0, 0.1, 1e-3, 0.0][(k / 4) % 4];
            let n = 3 + k % 30;
            let mut acc = PlaneAccumulator::new();
            let shift = Vector3::new(next(), next(), next()) * 10.0;
            for _ in 0..n {
                let p = Vector3::new(next(), next() * [1.0, 0.01][k % 2], next() * flat) * scale;
                acc.add(&Point3::from(p + shift));
            }
            matrices.push(acc.scatter().unwrap());
            let (a, b, c, d, e, f) = (next(), next(), next(), next(), next(), next());
            matrices.push(Matrix3::new(a, b, c, b, d, e, c, e, f) * scale);
        }
        for m in matrices {
            assert_eq!(eigen_bits(&symmetric_eigen(m)), eigen_bits(&SymmetricEigen::new(m)), "{m}");
        }
    }

    #[test]
    fn certified_planes_bound_the_fit() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as Real / (1u64 << 53) as Real * 2.0 - 1.0
        };
        let mut certified = 0;
        for k in 0..20_000 {
            let noise = [0.3, 0.1, 0.01, 1e-4, 0.0][k % 5];
            let stretch = [1.0, 0.2, 0.02][(k / 5) % 3];
            let rotation = nalgebra::Rotation3::new(Vector3::new(next(), next(), next()) * 3.0);
            let shift = Vector3::new(next(), next(), next()) * 20.0;
            let points: Vec<Point3> = (0..3 + k % 45)
                .map(|_| {
                    let p = Vector3::new(next(), next() * stretch, next() * noise);
                    Point3::from(rotation * p + shift)
                })
                .collect();
            let acc = PlaneAccumulator::from_points(&points);
            let members: Vec<u32> = (0..points.len() as u32).collect();
            let bounds = [acc.certified_plane(), certified_window_plane(&points, &members)];
            for bound in bounds.into_iter().flatten() {
                certified += 1;
                let fit = acc.fit(&Point3::origin()).expect("certified planes have a fit");
                assert!(bound.curvature_lower.total_cmp(&fit.curvature()).is_le(), "{k}");
                let n = fit.plane.normal.into_inner();
                let off = (bound.normal - n).norm().min((bound.normal + n).norm());
                assert!(off <= bound.normal_error, "{k}: {off} > {}", bound.normal_error);
            }
            if let Some(polished) = acc.polished_curvature() {
                let fitted = acc.fit(&Point3::origin()).expect("certified planes have a fit");
                let lower = acc.certified_plane().expect("polished needs bounds").curvature_lower;
                assert!(lower <= polished, "{k}: {lower} > {polished}");
                let error = (polished - fitted.curvature()).abs();
                assert!(error <= 1e-12, "{k}: {polished} against {}", fitted.curvature());
            }
        }
        assert!(certified > 20_000, "{certified}");
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
