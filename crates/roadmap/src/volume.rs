//! Explored volume (thesis §6.1.1): roadmaps rasterised into a sparse voxel grid, and the
//! congruence tables of the thesis (Tables 6.2–6.5).
//!
//! The thesis enters every roadmap "into an octree specific to the map and algorithm": each
//! vertex as a sphere and each edge as a cylinder of the planning radius, in one grid of
//! 1024³ cells that covers all maps compared (§6.1.1), takes the union over all runs, and
//! subtracts the grids of two maps to see how much volume was explored on one map but not on
//! the other (§6.2, Table 6.2). Here (spec §5.2 and §7 item 11):
//!
//! * A [`VoxelGrid`] is `N³` cubic cells (`N` a parameter; the thesis's 1024 in
//!   [`VoxelGrid::THESIS_CELLS_PER_AXIS`]) anchored at the min corner of the bounds, with cell
//!   side = the largest extent of the bounds / `N`, so one grid covers every map compared
//!   ([`VoxelGrid::covering`]). Its shorter axes reach past the bounds; cells outside the
//!   `N³` cube are never stored (shapes are clipped).
//! * A voxel belongs to a capsule (an edge with its end spheres; a vertex is a capsule with
//!   equal ends) iff its **centre** is within `r` of the segment, distance `≤ r` (closed):
//!   exactly the predicate [`capsule_contains_point`] evaluated at [`VoxelGrid::cell_center`],
//!   so the rasteriser can be checked voxel for voxel against a brute force.
//! * Runs are combined by [`VoxelGrid::union_with`]; the congruence entry "explored on A but
//!   not on B, in % of A" is `|A∖B| / |A| · 100` ([`VoxelGrid::count_not_in`],
//!   [`CongruenceTable`]), and a map's volume is `count · cell³` ([`VoxelGrid::volume`]).
//!
//! The thesis's 1024 × 38.684 mm cube is smaller than its own CCP volumes (spec §7 item 11),
//! so its cell size cannot be reproduced for every dataset; the grid's cell size always
//! follows from the bounds given.
//!
//! # Storage
//! A dense 1024³ bitset would take 128 MiB per map. The grid stores only *bricks* of
//! 64 × 8 × 8 voxels (one `u64` word per x-row of 64 voxels, 512 bytes per brick) that hold
//! at least one voxel, in a `Vec`, found through a hash map from the brick's coordinates with
//! a small deterministic hasher. Union and difference walk the bricks of one grid and look up
//! the other's.
//!
//! # Rasterisation
//! A capsule is convex, so the centres inside it on one x-row of voxels are contiguous. For
//! every (y, z) row of the capsule's box, [`VoxelGrid::add_capsule`] computes that x-interval
//! analytically (the end spheres' intervals and the cylinder's, from a quadratic in x cut to
//! the segment's parameter range), moves its ends until the predicate agrees (testing the
//! centres just inside and just outside each end), and sets the run of bits with word
//! operations. Rows farther from the segment than `r` (plus a rounding margin) are skipped
//! without any test. The predicate is decided exactly for the floating-point inputs (a filter
//! with an error bound, exact expansion arithmetic when that cannot decide), so its inside set
//! really is the closed capsule, contiguous along every row even in ties (a radius-0 segment
//! through centres, centres at distance exactly `r`), and the result equals the brute force
//! over every cell centre; the tests check this on random grids and capsules.
//!
//! # Performance
//! Measured on the 2-core development VM shared with other jobs (release profile, ignored test
//! `rasterise_lab_scale_timing`): 10,000 random 1 m capsules of radius 0.3 m into 1024³ cells
//! over a 12 × 9 × 4 m box (11.7 mm cells, about 8,300 rows and 250,000 voxels per capsule)
//! take about 5.2 s of CPU (7.8 s wall-clock under load; ≈ 0.5 ms per capsule), leaving 323
//! million voxels in 86,897 bricks (42 MiB of bricks, 66 MiB by capacity); `count_not_in` of
//! two such grids takes about 30 ms. The cost is per row, so
//! it falls with the square of the cell size: at 256³ (46.9 mm, near the thesis's 38.7 mm) a
//! capsule takes about 65 µs (`cargo bench -p patchnav-roadmap --bench volume`).
//!
//! # Example
//! ```
//! use patch_core::Point3;
//! use roadmap::volume::{CongruenceTable, VoxelGrid};
//!
//! let mut a = VoxelGrid::new(Point3::origin(), Point3::new(4.0, 4.0, 4.0), 64)?;
//! let mut b = a.empty_like();
//! a.add_capsule(Point3::new(1.0, 2.0, 2.0), Point3::new(3.0, 2.0, 2.0), 0.5)?;
//! b.add_sphere(Point3::new(1.0, 2.0, 2.0), 0.5)?;
//! assert_eq!(b.count_not_in(&a)?, 0); // the sphere is one end of the capsule
//! assert!(a.count_not_in(&b)? > 0);
//! let table = CongruenceTable::new([("capsule", &a), ("sphere", &b)])?;
//! assert_eq!(table.percent_not_in(1, 0), Some(0.0));
//! println!("{table}");
//! # Ok::<(), roadmap::volume::VolumeError>(())
//! ```

use std::collections::HashMap;
use std::fmt;
use std::hash::{BuildHasherDefault, Hasher};

use patch_core::{Aabb, CapsuleStep, Point3, Real, StepError, UnspecificStepIntersector, Vector3};

use crate::Roadmap;

/// Why a grid could not be built, or a shape or grid not used.
#[derive(Copy, Clone, Debug, PartialEq, thiserror::Error)]
pub enum VolumeError {
    /// The bounds are empty, have a coordinate that is not finite or beyond
    /// ±[`VoxelGrid::MAX_COORDINATE`], have zero extent on every axis, or give cells too small
    /// to be told apart in floating point (cell < 2⁻⁴⁰ × the largest coordinate magnitude).
    #[error("the grid bounds are empty, not finite, too large, a single point, or too fine")]
    InvalidBounds,
    /// The number of cells per axis is 0 or above [`VoxelGrid::MAX_CELLS_PER_AXIS`].
    #[error("{cells_per_axis} cells per axis is outside 1..=65536")]
    InvalidCellsPerAxis {
        /// The value given.
        cells_per_axis: u32,
    },
    /// The radius is negative, not finite, or above [`VoxelGrid::MAX_COORDINATE`].
    #[error("radius {radius} is not a number in [0, 1e30]")]
    InvalidRadius {
        /// The value given.
        radius: Real,
    },
    /// A point of a shape has a coordinate that is not finite or beyond
    /// ±[`VoxelGrid::MAX_COORDINATE`].
    #[error("a shape has a coordinate that is not finite or beyond ±1e30")]
    InvalidPoint,
    /// The two grids do not share the same lattice ([`VoxelGrid::same_lattice`]).
    #[error("the voxel grids have different lattices (origin, cell size or cells per axis)")]
    LatticeMismatch,
}

/// The part of `roadmap` that is explored space (thesis §6.2): every edge, and every vertex
/// with an edge or whose sphere of `radius` is free on `map`. The thesis's PRM adds samples
/// without a validity check (Algorithm 14, spec §4), so a sample inside an obstacle stays an
/// isolated vertex; its sphere is not explored volume.
///
/// # Errors
/// [`StepError`] for a radius that is not positive and finite.
pub fn explored_part<M>(roadmap: &Roadmap, map: &M, radius: Real) -> Result<Roadmap, StepError>
where
    M: UnspecificStepIntersector + ?Sized,
{
    let mut free = Vec::with_capacity(roadmap.node_count());
    for v in roadmap.node_indices() {
        let keep = roadmap.neighbors(v).next().is_some()
            || map.is_step_free(&CapsuleStep::sphere(roadmap[v], radius)?);
        free.push(keep);
    }
    Ok(roadmap.filter_map(|v, p| free[v.index()].then_some(*p), |_, w| Some(*w)))
}

/// Whether the point `p` lies within `radius` of the segment `a`–`b` (closed: distance
/// `≤ radius`): the capsule predicate of the explored volume (thesis §6.1.1).
///
/// This rule defines which voxels a capsule covers: a voxel is inside iff this returns `true`
/// for its [`VoxelGrid::cell_center`]. `p` is inside iff `|p − a|² ≤ r²`, or `|p − b|² ≤ r²`,
/// or `(p − a)·(b − a) > 0`, `(p − b)·(b − a) < 0` and `|(p − a) × (b − a)|² ≤ r²·|b − a|²`;
/// `a == b` is the sphere, `radius == 0` the segment itself.
///
/// The signs are decided **exactly** for the given floating-point values (a floating-point
/// filter with a proven error bound, and exact expansion arithmetic, Shewchuk 1997, when the
/// filter cannot decide), so the set of inside points is exactly the closed capsule and hence
/// convex: ties such as a centre lying exactly on a radius-0 segment or exactly at distance `r`
/// are decided consistently, which the row-wise rasteriser relies on. Exactness assumes no
/// product underflows (coordinate differences above ~1e-70) and magnitudes within
/// [`VoxelGrid::MAX_COORDINATE`].
pub fn capsule_contains_point(p: &Point3, a: &Point3, b: &Point3, radius: Real) -> bool {
    let r2 = radius * radius;
    let u = p - a;
    let v = p - b;
    for (w, end) in [(&u, a), (&v, b)] {
        let ww = w.norm_squared();
        if exact::le_zero(ww - r2, 8.0 * Real::EPSILON * (ww + r2), || {
            let w: Vec<exact::Exp> = (0..3).map(|i| exact::diff(p[i], end[i])).collect();
            let mut t = exact::dot(&w, &w);
            t.extend(exact::neg(&exact::mul(&[radius], &[radius])));
            t
        }) {
            return true;
        }
    }
    let d = b - a;
    if d == Vector3::zeros() {
        return false;
    }
    let exact_d = || -> Vec<exact::Exp> { (0..3).map(|i| exact::diff(b[i], a[i])).collect() };
    let exact_u = || -> Vec<exact::Exp> { (0..3).map(|i| exact::diff(p[i], a[i])).collect() };
    let abs_dot = |w: &Vector3| w.iter().zip(d.iter()).map(|(x, y)| (x * y).abs()).sum::<Real>();
    // (p − a)·d > 0, i.e. not (p − a)·d ≤ 0.
    if exact::le_zero(u.dot(&d), 8.0 * Real::EPSILON * abs_dot(&u), || {
        exact::dot(&exact_u(), &exact_d())
    }) {
        return false;
    }
    // (p − b)·d < 0, i.e. not −(p − b)·d ≤ 0.
    if exact::le_zero(-v.dot(&d), 8.0 * Real::EPSILON * abs_dot(&v), || {
        let vv: Vec<exact::Exp> = (0..3).map(|i| exact::diff(p[i], b[i])).collect();
        exact::neg(&exact::dot(&vv, &exact_d()))
    }) {
        return false;
    }
    let c = u.cross(&d);
    let m = Vector3::new(
        (u.y * d.z).abs() + (u.z * d.y).abs(),
        (u.z * d.x).abs() + (u.x * d.z).abs(),
        (u.x * d.y).abs() + (u.y * d.x).abs(),
    );
    let dd = d.norm_squared();
    let approx = c.norm_squared() - r2 * dd;
    exact::le_zero(approx, 16.0 * Real::EPSILON * (m.norm_squared() + r2 * dd), || {
        let (uu, du) = (exact_u(), exact_d());
        let cross: Vec<exact::Exp> = (0..3)
            .map(|i| {
                let (j, k) = ((i + 1) % 3, (i + 2) % 3);
                let mut t = exact::mul(&uu[j], &du[k]);
                t.extend(exact::neg(&exact::mul(&uu[k], &du[j])));
                t
            })
            .collect();
        let mut t = exact::dot(&cross, &cross);
        let r2 = exact::mul(&[radius], &[radius]);
        t.extend(exact::neg(&exact::mul(&r2, &exact::dot(&du, &du))));
        t
    })
}

/// Exact signs of small polynomials in floating-point values: a value is a list of terms
/// whose exact sum it is (an [`Exp`]); products are split exactly with an FMA, and the sign
/// comes from summing the terms into a nonoverlapping expansion (Shewchuk 1997, Grow-Expansion
/// with zero elimination), whose largest component has the sign of the sum.
mod exact {
    use patch_core::Real;

    /// Terms whose exact sum is the value.
    pub(super) type Exp = Vec<Real>;

    /// `a − b` exactly, as two terms.
    pub(super) fn diff(a: Real, b: Real) -> Exp {
        let s = a - b;
        let bv = a - s;
        let av = s + bv;
        let e = (a - av) + (bv - b);
        if e == 0.0 { vec![s] } else { vec![s, e] }
    }

    /// The exact product of two term lists.
    pub(super) fn mul(x: &[Real], y: &[Real]) -> Exp {
        let mut out = Vec::with_capacity(2 * x.len() * y.len());
        for &a in x {
            for &b in y {
                let p = a * b;
                let e = a.mul_add(b, -p);
                if p != 0.0 {
                    out.push(p);
                }
                if e != 0.0 {
                    out.push(e);
                }
            }
        }
        out
    }

    /// `−x`.
    pub(super) fn neg(x: &[Real]) -> Exp {
        x.iter().map(|t| -t).collect()
    }

    /// `Σ xᵢ·yᵢ` exactly.
    pub(super) fn dot(x: &[Exp], y: &[Exp]) -> Exp {
        x.iter().zip(y).flat_map(|(a, b)| mul(a, b)).collect()
    }

    /// Whether the exact sum of `terms` is `≤ 0`.
    #[cold]
    #[inline(never)]
    fn sum_le_zero(terms: &[Real]) -> bool {
        // Nonoverlapping expansion in increasing magnitude, zeros dropped.
        let mut e: Vec<Real> = Vec::with_capacity(16);
        for &b in terms {
            let mut q = b;
            let mut k = 0;
            for i in 0..e.len() {
                let x = e[i];
                let s = q + x;
                let bv = s - q;
                let av = s - bv;
                let h = (q - av) + (x - bv);
                q = s;
                if h != 0.0 {
                    e[k] = h;
                    k += 1;
                }
            }
            e.truncate(k);
            if q != 0.0 {
                e.push(q);
            }
        }
        e.last().is_none_or(|&top| top <= 0.0)
    }

    /// Whether a value is `≤ 0`, given its floating-point `approx` with `|error| ≤ bound`; only
    /// when that cannot decide are the exact terms computed.
    #[inline]
    pub(super) fn le_zero(approx: Real, bound: Real, exact: impl FnOnce() -> Exp) -> bool {
        if approx < -bound {
            true
        } else if approx > bound {
            false
        } else {
            sum_le_zero(&exact())
        }
    }
}

/// Voxels along x in one brick (one `u64` word per row).
const BRICK_X: u32 = 64;
/// log2 of the brick's extent along y and z.
const BRICK_YZ_SHIFT: u32 = 3;
/// The brick's extent along y and z.
const BRICK_YZ: u32 = 1 << BRICK_YZ_SHIFT;
/// Words (x-rows) per brick.
const BRICK_WORDS: usize = (BRICK_YZ * BRICK_YZ) as usize;

/// A brick: `BRICK_YZ × BRICK_YZ` rows of 64 voxels; word `(k % 8) · 8 + (j % 8)`, bit `i % 64`.
type Brick = [u64; BRICK_WORDS];

/// A deterministic hasher for packed brick keys: multiply–xor while writing, then the
/// MurmurHash3 finaliser so every key bit reaches the low and the high bits of the hash.
#[derive(Default, Clone, Copy)]
struct BrickHasher(u64);

impl Hasher for BrickHasher {
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }

    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x517c_c1b7_2722_0a95);
    }

    fn finish(&self) -> u64 {
        let mut h = self.0;
        h ^= h >> 33;
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^= h >> 33;
        h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
        h ^ (h >> 33)
    }
}

type BrickMap = HashMap<u64, u32, BuildHasherDefault<BrickHasher>>;

/// The key of the brick at brick coordinates `(bx, by, bz)` (each below 2²¹).
fn brick_key(bx: u32, by: u32, bz: u32) -> u64 {
    u64::from(bx) | (u64::from(by) << 21) | (u64::from(bz) << 42)
}

/// The bits `lo..=hi` of a word (`lo ≤ hi < 64`).
fn bit_run(lo: u32, hi: u32) -> u64 {
    (u64::MAX >> (63 - hi)) & (u64::MAX << lo)
}

/// A capsule with its derived quantities, for rasterising rows.
struct RowCapsule {
    a: Point3,
    b: Point3,
    r: Real,
    r2: Real,
    d: Vector3,
    dd: Real,
    /// `dy² + dz²`.
    dyz: Real,
    /// Rows whose distance² to the segment exceeds `r² + margin` hold no inside centre.
    margin: Real,
    /// `1 / cell`, `1 / dyz`, `1 / dx` (0 where undefined) and `|d|² / dyz`, for estimates.
    inv_cell: Real,
    inv_dyz: Real,
    inv_dx: Real,
    dd_over_dyz: Real,
    /// For a segment along x (`dyz = 0`), equally close to a row everywhere: its point nearest
    /// the grid's middle, where the fallback of `row_interval` looks for inside centres.
    x_along: Real,
}

/// `⌊x⌋` for `|x|` well inside the `i64` range (no libm call).
fn floor_i64(x: Real) -> i64 {
    let t = x as i64;
    if (t as Real) > x { t - 1 } else { t }
}

/// `⌈x⌉` for `|x|` well inside the `i64` range (no libm call).
fn ceil_i64(x: Real) -> i64 {
    let t = x as i64;
    if (t as Real) < x { t + 1 } else { t }
}

/// A sign decided by a floating-point filter: `Some(approx ≤ 0)` if `|approx| > bound`,
/// `None` if the error bound cannot decide.
fn filtered_le_zero(approx: Real, bound: Real) -> Option<bool> {
    (approx.abs() > bound).then_some(approx <= 0.0)
}

/// Three-valued `and`: `false` wins, then unknown.
fn and3(a: Option<bool>, b: Option<bool>) -> Option<bool> {
    match (a, b) {
        (Some(false), _) | (_, Some(false)) => Some(false),
        (Some(true), Some(true)) => Some(true),
        _ => None,
    }
}

/// Three-valued `or`: `true` wins, then unknown.
fn or3(a: Option<bool>, b: Option<bool>) -> Option<bool> {
    and3(a.map(|x| !x), b.map(|x| !x)).map(|x| !x)
}

/// The terms of [`capsule_contains_point`] that are constant along one x-row `(y, z)`, for a
/// cheap filtered evaluation at many `x`.
struct RowTerms {
    /// `(y − a_y, z − a_z)`.
    ey: Real,
    ez: Real,
    /// Squared yz-distances to `a` and to `b`.
    ka: Real,
    kb: Real,
    /// `(y − a_y, z − a_z)·(d_y, d_z)` and the sum of the absolute products.
    g: Real,
    g_abs: Real,
    /// The same for `b`.
    gb: Real,
    gb_abs: Real,
    /// The x-component of `(p − a) × d` and the sum of its absolute products.
    c0: Real,
    m0: Real,
}

impl RowTerms {
    fn new(cap: &RowCapsule, ey: Real, ez: Real, eyb: Real, ezb: Real) -> RowTerms {
        let d = &cap.d;
        RowTerms {
            ey,
            ez,
            ka: ey * ey + ez * ez,
            kb: eyb * eyb + ezb * ezb,
            g: ey * d.y + ez * d.z,
            g_abs: (ey * d.y).abs() + (ez * d.z).abs(),
            gb: eyb * d.y + ezb * d.z,
            gb_abs: (eyb * d.y).abs() + (ezb * d.z).abs(),
            c0: ey * d.z - ez * d.y,
            m0: (ey * d.z).abs() + (ez * d.y).abs(),
        }
    }

    /// [`capsule_contains_point`] at `(x, y, z)` by its floating-point filter alone (the same
    /// three tests, with error bounds at least as wide), `None` where a bound cannot decide.
    #[inline(always)]
    fn classify(&self, cap: &RowCapsule, x: Real) -> Option<bool> {
        let eps = Real::EPSILON;
        let (r2, d) = (cap.r2, &cap.d);
        let ux = x - cap.a.x;
        let wa = ux * ux + self.ka;
        let sa = filtered_le_zero(wa - r2, 8.0 * eps * (wa + r2));
        if sa == Some(true) {
            return sa;
        }
        let vx = x - cap.b.x;
        let wb = vx * vx + self.kb;
        let sb = filtered_le_zero(wb - r2, 8.0 * eps * (wb + r2));
        let spheres = or3(sa, sb);
        if spheres == Some(true) || cap.dd == 0.0 {
            return spheres;
        }
        // (p − a)·d > 0 and (p − b)·d < 0.
        let t1 = filtered_le_zero(ux * d.x + self.g, 8.0 * eps * ((ux * d.x).abs() + self.g_abs))
            .map(|le| !le);
        if t1 == Some(false) {
            return spheres;
        }
        let t2 =
            filtered_le_zero(-(vx * d.x + self.gb), 8.0 * eps * ((vx * d.x).abs() + self.gb_abs))
                .map(|le| !le);
        if t2 == Some(false) {
            return spheres;
        }
        let c1 = self.ez * d.x - ux * d.z;
        let c2 = ux * d.y - self.ey * d.x;
        let m1 = (self.ez * d.x).abs() + (ux * d.z).abs();
        let m2 = (ux * d.y).abs() + (self.ey * d.x).abs();
        let cyl = filtered_le_zero(
            self.c0 * self.c0 + c1 * c1 + c2 * c2 - r2 * cap.dd,
            16.0 * eps * (self.m0 * self.m0 + m1 * m1 + m2 * m2 + r2 * cap.dd),
        );
        or3(spheres, and3(and3(t1, t2), cyl))
    }

    /// Whether centre `i` of the row is inside: the filter, else the exact predicate.
    #[inline(always)]
    fn inside(&self, grid: &VoxelGrid, cap: &RowCapsule, i: i64, y: Real, z: Real) -> bool {
        let x = grid.center_coord(0, i as u32);
        match self.classify(cap, x) {
            Some(inside) => inside,
            None => capsule_contains_point(&Point3::new(x, y, z), &cap.a, &cap.b, cap.r),
        }
    }
}

/// Union of two optional closed intervals into their hull.
fn hull(acc: Option<(Real, Real)>, lo: Real, hi: Real) -> Option<(Real, Real)> {
    if lo.is_nan() || hi.is_nan() || lo > hi {
        return acc;
    }
    Some(match acc {
        None => (lo, hi),
        Some((l, h)) => (l.min(lo), h.max(hi)),
    })
}

/// A sparse voxel grid of `N³` cubic cells: the explored volume of one map and algorithm
/// (thesis §6.1.1; see the [module docs](self)).
///
/// Cell `(i, j, k)`, `0 ≤ i, j, k < N`, has its centre at `min + (i + ½, j + ½, k + ½) · cell`
/// ([`cell_center`](Self::cell_center)); grids are comparable iff they share this lattice
/// ([`same_lattice`](Self::same_lattice)).
#[derive(Clone, Debug)]
pub struct VoxelGrid {
    min: Point3,
    cell: Real,
    n: u32,
    /// Brick key → index into `bricks` and `keys`.
    index: BrickMap,
    keys: Vec<u64>,
    bricks: Vec<Brick>,
}

/// # Construction
impl VoxelGrid {
    /// Cells per axis in the thesis's explored-volume octree (§6.1.1).
    pub const THESIS_CELLS_PER_AXIS: u32 = 1024;
    /// The largest number of cells per axis accepted (2¹⁶).
    pub const MAX_CELLS_PER_AXIS: u32 = 1 << 16;
    /// The largest coordinate magnitude (and radius) accepted, so that the degree-4 terms of
    /// [`capsule_contains_point`] cannot overflow.
    pub const MAX_COORDINATE: Real = 1e30;

    /// An empty grid of `cells_per_axis³` cubic cells covering the box `[min, max]`: anchored
    /// at `min`, with cell side = the largest extent of the box / `cells_per_axis`.
    ///
    /// # Errors
    /// [`VolumeError::InvalidBounds`] if a coordinate is not finite or beyond
    /// ±[`MAX_COORDINATE`](Self::MAX_COORDINATE), `max < min` on some axis, the box is a
    /// single point (a box flat along one or two axes is fine), or the cell is below 2⁻⁴⁰ of
    /// the largest coordinate magnitude;
    /// [`VolumeError::InvalidCellsPerAxis`] for 0 or more than
    /// [`MAX_CELLS_PER_AXIS`](Self::MAX_CELLS_PER_AXIS).
    pub fn new(min: Point3, max: Point3, cells_per_axis: u32) -> Result<VoxelGrid, VolumeError> {
        if !(1..=Self::MAX_CELLS_PER_AXIS).contains(&cells_per_axis) {
            return Err(VolumeError::InvalidCellsPerAxis { cells_per_axis });
        }
        let in_range = min.iter().chain(max.iter()).all(|c| c.abs() <= Self::MAX_COORDINATE);
        let extents = max - min;
        if !in_range || extents.iter().any(|e| *e < 0.0) {
            return Err(VolumeError::InvalidBounds);
        }
        let cell = extents.max() / Real::from(cells_per_axis);
        let magnitude = min.coords.amax().max(max.coords.amax());
        if !(cell > 0.0 && cell >= magnitude * (2.0 as Real).powi(-40)) {
            return Err(VolumeError::InvalidBounds);
        }
        Ok(VoxelGrid {
            min,
            cell,
            n: cells_per_axis,
            index: BrickMap::default(),
            keys: Vec::new(),
            bricks: Vec::new(),
        })
    }

    /// An empty grid over the union of `bounds` (the thesis's "smallest octree covering all
    /// maps", §6.1.1), `cells_per_axis³` cells.
    ///
    /// # Errors
    /// As [`new`](Self::new); [`VolumeError::InvalidBounds`] also if `bounds` is empty or all
    /// boxes are.
    pub fn covering(
        bounds: impl IntoIterator<Item = Aabb>,
        cells_per_axis: u32,
    ) -> Result<VoxelGrid, VolumeError> {
        let all = bounds.into_iter().fold(Aabb::EMPTY, |acc, b| acc.union(&b));
        if all.is_empty() {
            return Err(VolumeError::InvalidBounds);
        }
        VoxelGrid::new(all.min, all.max, cells_per_axis)
    }

    /// An empty grid on the same lattice as `self` (for the next map to compare).
    pub fn empty_like(&self) -> VoxelGrid {
        VoxelGrid {
            min: self.min,
            cell: self.cell,
            n: self.n,
            index: BrickMap::default(),
            keys: Vec::new(),
            bricks: Vec::new(),
        }
    }
}

/// # Lattice
impl VoxelGrid {
    /// The side of a cell, in metres.
    pub fn cell_size(&self) -> Real {
        self.cell
    }

    /// `N`: the grid has `N³` cells.
    pub fn cells_per_axis(&self) -> u32 {
        self.n
    }

    /// The min corner of the grid (the min corner of the bounds it was built from).
    pub fn min(&self) -> Point3 {
        self.min
    }

    /// The cube the cells cover: `[min, min + N · cell]` on every axis.
    pub fn bounds(&self) -> Aabb {
        let side = self.cell * Real::from(self.n);
        Aabb::new(self.min, self.min + Vector3::repeat(side))
    }

    /// Whether `other` has the same origin, cell size and cells per axis (bitwise equal), so
    /// that cell `(i, j, k)` is the same cube in both.
    pub fn same_lattice(&self, other: &VoxelGrid) -> bool {
        self.n == other.n
            && self.cell.to_bits() == other.cell.to_bits()
            && self.min.iter().zip(other.min.iter()).all(|(a, b)| a.to_bits() == b.to_bits())
    }

    /// The centre of cell `(i, j, k)`: `min + (i + ½, j + ½, k + ½) · cell` (each coordinate
    /// computed as `min_c + (index + 0.5) · cell`). Defined for any index, also outside the
    /// grid.
    pub fn cell_center(&self, i: u32, j: u32, k: u32) -> Point3 {
        Point3::new(self.center_coord(0, i), self.center_coord(1, j), self.center_coord(2, k))
    }

    fn center_coord(&self, axis: usize, index: u32) -> Real {
        self.min[axis] + (Real::from(index) + 0.5) * self.cell
    }

    /// The continuous cell coordinate of `x` on `axis`: centres lie at whole numbers.
    fn cell_coord(&self, axis: usize, x: Real) -> Real {
        (x - self.min[axis]) / self.cell - 0.5
    }

    /// The cells whose centres may lie in `[lo, hi]` on `axis`, widened by one cell against
    /// rounding and clipped to the grid; `None` if that is empty.
    fn index_range(&self, axis: usize, lo: Real, hi: Real) -> Option<(u32, u32)> {
        let last = Real::from(self.n - 1);
        let l = (self.cell_coord(axis, lo).ceil() - 1.0).max(0.0);
        let h = (self.cell_coord(axis, hi).floor() + 1.0).min(last);
        // Both are whole numbers in [0, n − 1] when l ≤ h; NaN fails the comparison.
        (l <= h).then_some((l as u32, h as u32))
    }
}

/// # Rasterising (thesis §6.1.1)
impl VoxelGrid {
    /// Adds the voxels whose centres are within `radius` of `center` (a roadmap vertex).
    /// The same as [`add_capsule`](Self::add_capsule) with equal ends.
    ///
    /// # Errors
    /// As [`add_capsule`](Self::add_capsule).
    pub fn add_sphere(&mut self, center: Point3, radius: Real) -> Result<(), VolumeError> {
        self.add_capsule(center, center, radius)
    }

    /// Adds the voxels whose centres are within `radius` of the segment `a`–`b` (a roadmap
    /// edge with its end spheres): exactly the cells for which [`capsule_contains_point`]
    /// holds at the [`cell_center`](Self::cell_center). `a == b` is a sphere, `radius == 0`
    /// the segment itself; parts outside the grid are clipped.
    ///
    /// # Errors
    /// [`VolumeError::InvalidRadius`] unless `0 ≤ radius ≤`
    /// [`MAX_COORDINATE`](Self::MAX_COORDINATE); [`VolumeError::InvalidPoint`] if a
    /// coordinate is not finite or beyond ±[`MAX_COORDINATE`](Self::MAX_COORDINATE). The grid
    /// is unchanged on error.
    ///
    /// # Complexity
    /// `O(rows of the capsule's box + bricks touched)` hash look-ups and about four predicate
    /// tests per row crossing the capsule; no per-voxel test.
    pub fn add_capsule(&mut self, a: Point3, b: Point3, radius: Real) -> Result<(), VolumeError> {
        validate_capsule(&a, &b, radius)?;
        self.rasterise(&a, &b, radius);
        Ok(())
    }

    /// Adds a roadmap: every edge as a capsule between its end vertices and every isolated
    /// vertex as a sphere, all of radius `radius` (thesis §6.1.1). Vertices with edges need no
    /// sphere of their own: a capsule contains its end spheres exactly, so the result is the
    /// union of every edge's capsule and every vertex's sphere.
    ///
    /// # Errors
    /// As [`add_capsule`](Self::add_capsule), checked for all vertices before anything is
    /// added, so the grid is unchanged on error.
    pub fn add_roadmap(&mut self, roadmap: &Roadmap, radius: Real) -> Result<(), VolumeError> {
        validate_capsule(&Point3::origin(), &Point3::origin(), radius)?;
        for p in roadmap.node_weights() {
            validate_capsule(p, p, radius)?;
        }
        for e in roadmap.edge_indices() {
            let (u, v) = roadmap.edge_endpoints(e).expect("edge index from the graph");
            self.rasterise(&roadmap[u], &roadmap[v], radius);
        }
        for v in roadmap.node_indices() {
            if roadmap.neighbors(v).next().is_none() {
                let p = roadmap[v];
                self.rasterise(&p, &p, radius);
            }
        }
        Ok(())
    }

    /// Rasterises a validated capsule.
    fn rasterise(&mut self, a: &Point3, b: &Point3, r: Real) {
        let lo = a.coords.inf(&b.coords).add_scalar(-r);
        let hi = a.coords.sup(&b.coords).add_scalar(r);
        let (Some((i0, i1)), Some((j0, j1)), Some((k0, k1))) = (
            self.index_range(0, lo.x, hi.x),
            self.index_range(1, lo.y, hi.y),
            self.index_range(2, lo.z, hi.z),
        ) else {
            return;
        };
        let d = b - a;
        let dd = d.norm_squared();
        let dyz = d.y * d.y + d.z * d.z;
        // Rounding in the predicate is a few ulps of the squared coordinates involved.
        let scale = [a.coords.amax(), b.coords.amax(), self.bounds().max.coords.amax()]
            .into_iter()
            .fold(r + self.cell + self.min.coords.amax(), Real::max);
        let cap = RowCapsule {
            a: *a,
            b: *b,
            r,
            r2: r * r,
            d,
            dd,
            dyz,
            margin: 1e-10 * scale * scale,
            inv_cell: 1.0 / self.cell,
            inv_dyz: if dyz > 0.0 { 1.0 / dyz } else { 0.0 },
            inv_dx: if d.x != 0.0 { 1.0 / d.x } else { 0.0 },
            dd_over_dyz: if dyz > 0.0 { dd / dyz } else { 0.0 },
            x_along: (self.min.x + 0.5 * self.cell * Real::from(self.n))
                .clamp(a.x.min(b.x), a.x.max(b.x)),
        };
        // Brick cache for one (by, bz) block: x-brick → brick index (u32::MAX: not looked up).
        let (bx0, bx1) = (i0 / BRICK_X, i1 / BRICK_X);
        let mut cache = vec![u32::MAX; (bx1 - bx0 + 1) as usize];
        for bz in (k0 >> BRICK_YZ_SHIFT)..=(k1 >> BRICK_YZ_SHIFT) {
            for by in (j0 >> BRICK_YZ_SHIFT)..=(j1 >> BRICK_YZ_SHIFT) {
                cache.fill(u32::MAX);
                let ks = (bz << BRICK_YZ_SHIFT).max(k0)
                    ..=((bz << BRICK_YZ_SHIFT) + BRICK_YZ - 1).min(k1);
                for k in ks {
                    let js = (by << BRICK_YZ_SHIFT).max(j0)
                        ..=((by << BRICK_YZ_SHIFT) + BRICK_YZ - 1).min(j1);
                    for j in js {
                        let Some((lo, hi)) = self.row_interval(&cap, j, k) else {
                            continue;
                        };
                        let word = ((k % BRICK_YZ) * BRICK_YZ + (j % BRICK_YZ)) as usize;
                        for bx in lo / BRICK_X..=hi / BRICK_X {
                            // Rounding may put an inside centre just outside the box.
                            let brick = match cache.get_mut(bx.wrapping_sub(bx0) as usize) {
                                Some(slot) => {
                                    if *slot == u32::MAX {
                                        *slot = self.brick_index_or_insert(brick_key(bx, by, bz));
                                    }
                                    *slot
                                }
                                None => self.brick_index_or_insert(brick_key(bx, by, bz)),
                            };
                            let first = bx * BRICK_X;
                            let run = bit_run(lo.max(first) - first, hi.min(first + 63) - first);
                            self.bricks[brick as usize][word] |= run;
                        }
                    }
                }
            }
        }
    }

    /// The inside cells `[lo, hi]` of row `(j, k)`, or `None` if the row has none.
    fn row_interval(&self, cap: &RowCapsule, j: u32, k: u32) -> Option<(u32, u32)> {
        let y = self.center_coord(1, j);
        let z = self.center_coord(2, k);
        let (ey, ez) = (y - cap.a.y, z - cap.a.z);
        let d = &cap.d;
        // Closest approach of the row line to the segment: for a fixed segment parameter t the
        // best x is a.x + t·dx, leaving the yz-distance, minimised over t in [0, 1].
        let g = ey * d.y + ez * d.z;
        let t_min = if cap.dyz > 0.0 { (g * cap.inv_dyz).clamp(0.0, 1.0) } else { 0.5 };
        let (ry, rz) = (ey - t_min * d.y, ez - t_min * d.z);
        if ry * ry + rz * rz > cap.r2 + cap.margin {
            return None;
        }
        let x_closest = if cap.dyz > 0.0 { cap.a.x + t_min * d.x } else { cap.x_along };
        let row = RowTerms::new(cap, ey, ez, y - cap.b.y, z - cap.b.z);

        // The analytic interval: end spheres and the cylinder part.
        let mut iv = None;
        for (c, k2) in [(&cap.a, row.ka), (&cap.b, row.kb)] {
            let s = cap.r2 - k2;
            if s >= 0.0 {
                let w = s.sqrt();
                iv = hull(iv, c.x - w, c.x + w);
            }
        }
        if cap.dd > 0.0 {
            // u = x − a.x; the segment parameter is t(u) = (u·dx + g) / |d|².
            let (t_lo, t_hi) = if d.x != 0.0 {
                let (u0, u1) = (-g * cap.inv_dx, (cap.dd - g) * cap.inv_dx);
                (u0.min(u1), u0.max(u1))
            } else if (0.0..=1.0).contains(&(g / cap.dd)) {
                (Real::NEG_INFINITY, Real::INFINITY)
            } else {
                (Real::INFINITY, Real::NEG_INFINITY)
            };
            if cap.dyz > 0.0 {
                // Perpendicular distance² to the axis = A (u − u_v)² + m, A = dyz / |d|².
                let m = row.ka - g * g * cap.inv_dyz;
                let s = cap.r2 - m;
                if s >= 0.0 {
                    let u_v = d.x * g * cap.inv_dyz;
                    let w = (s * cap.dd_over_dyz).sqrt();
                    iv = hull(iv, cap.a.x + (u_v - w).max(t_lo), cap.a.x + (u_v + w).min(t_hi));
                }
            } else if row.ka <= cap.r2 {
                iv = hull(iv, cap.a.x + t_lo, cap.a.x + t_hi);
            }
        }

        let last = i64::from(self.n - 1);
        let inside = |i: i64| row.inside(self, cap, i, y, z);
        let coord =
            |x: Real| ((x - self.min.x) * cap.inv_cell - 0.5).clamp(-2.0, last as Real + 2.0);
        let walk_out = |mut lo: i64, mut hi: i64| {
            while lo > 0 && inside(lo - 1) {
                lo -= 1;
            }
            while hi < last && inside(hi + 1) {
                hi += 1;
            }
            (lo as u32, hi as u32)
        };

        if let Some((xlo, xhi)) = iv {
            let e0 = ceil_i64(coord(xlo)).max(0);
            let e1 = floor_i64(coord(xhi)).min(last);
            if e0 <= e1 {
                // Left end: from e0 down while inside, or up to the first inside cell.
                let mut lo = e0;
                while lo <= e1 && !inside(lo) {
                    lo += 1;
                }
                if lo <= e1 {
                    let mut hi = e1;
                    while !inside(hi) {
                        hi -= 1;
                    }
                    return Some(walk_out(lo, hi));
                }
            }
        }
        // The estimate holds no inside centre: if the row has one, the centres bracketing the
        // closest approach are inside (the inside set is an interval around it). Two more on
        // either side guard against rounding of the closest approach.
        let c = floor_i64(coord(x_closest));
        (c - 1..=c + 2)
            .filter(|i| (0..=last).contains(i))
            .find(|&i| inside(i))
            .map(|s| walk_out(s, s))
    }

    /// The index of the brick with `key`, inserting an empty one if there is none.
    fn brick_index_or_insert(&mut self, key: u64) -> u32 {
        let next = self.bricks.len() as u32;
        let index = *self.index.entry(key).or_insert(next);
        if index == next {
            self.keys.push(key);
            self.bricks.push([0; BRICK_WORDS]);
        }
        index
    }

    fn brick(&self, key: u64) -> Option<&Brick> {
        self.index.get(&key).map(|&i| &self.bricks[i as usize])
    }
}

/// Checks a capsule's inputs (see [`VoxelGrid::add_capsule`]).
fn validate_capsule(a: &Point3, b: &Point3, radius: Real) -> Result<(), VolumeError> {
    if !(0.0..=VoxelGrid::MAX_COORDINATE).contains(&radius) {
        return Err(VolumeError::InvalidRadius { radius });
    }
    if !a.iter().chain(b.iter()).all(|c| c.abs() <= VoxelGrid::MAX_COORDINATE) {
        return Err(VolumeError::InvalidPoint);
    }
    Ok(())
}

/// # Set operations and measures
impl VoxelGrid {
    /// Whether cell `(i, j, k)` is set (`false` outside the grid).
    pub fn contains(&self, i: u32, j: u32, k: u32) -> bool {
        if i >= self.n || j >= self.n || k >= self.n {
            return false;
        }
        let key = brick_key(i / BRICK_X, j >> BRICK_YZ_SHIFT, k >> BRICK_YZ_SHIFT);
        let word = ((k % BRICK_YZ) * BRICK_YZ + (j % BRICK_YZ)) as usize;
        self.brick(key).is_some_and(|b| b[word] >> (i % BRICK_X) & 1 == 1)
    }

    /// The number of voxels set.
    pub fn count(&self) -> u64 {
        self.bricks.iter().flatten().map(|w| u64::from(w.count_ones())).sum()
    }

    /// Whether no voxel is set.
    pub fn is_empty(&self) -> bool {
        self.bricks.is_empty()
    }

    /// The explored volume in m³ (cubic units of the coordinates): `count · cell³`.
    pub fn volume(&self) -> Real {
        self.count() as Real * self.cell.powi(3)
    }

    /// Adds every voxel of `other` (the union over runs, thesis §6.1.1).
    ///
    /// # Errors
    /// [`VolumeError::LatticeMismatch`] unless [`same_lattice`](Self::same_lattice); `self`
    /// is unchanged then.
    pub fn union_with(&mut self, other: &VoxelGrid) -> Result<(), VolumeError> {
        if !self.same_lattice(other) {
            return Err(VolumeError::LatticeMismatch);
        }
        for (key, theirs) in other.keys.iter().zip(&other.bricks) {
            let i = self.brick_index_or_insert(*key) as usize;
            for (w, t) in self.bricks[i].iter_mut().zip(theirs) {
                *w |= t;
            }
        }
        Ok(())
    }

    /// `|self ∖ other|`: the voxels set here but not in `other` (the numerator of the
    /// congruence tables, thesis Table 6.2).
    ///
    /// # Errors
    /// [`VolumeError::LatticeMismatch`] unless [`same_lattice`](Self::same_lattice).
    pub fn count_not_in(&self, other: &VoxelGrid) -> Result<u64, VolumeError> {
        if !self.same_lattice(other) {
            return Err(VolumeError::LatticeMismatch);
        }
        let mut n = 0;
        for (key, mine) in self.keys.iter().zip(&self.bricks) {
            n += match other.brick(*key) {
                Some(theirs) => {
                    mine.iter().zip(theirs).map(|(m, t)| u64::from((m & !t).count_ones())).sum()
                }
                None => mine.iter().map(|m| u64::from(m.count_ones())).sum::<u64>(),
            };
        }
        Ok(n)
    }

    /// The set voxels as `(i, j, k)`, in storage order (bricks in insertion order).
    pub fn iter(&self) -> impl Iterator<Item = (u32, u32, u32)> + '_ {
        self.keys.iter().zip(&self.bricks).flat_map(|(&key, brick)| {
            let bx = (key & 0x1f_ffff) as u32;
            let by = ((key >> 21) & 0x1f_ffff) as u32;
            let bz = (key >> 42) as u32;
            brick.iter().enumerate().flat_map(move |(w, &bits)| {
                let j = (by << BRICK_YZ_SHIFT) + w as u32 % BRICK_YZ;
                let k = (bz << BRICK_YZ_SHIFT) + w as u32 / BRICK_YZ;
                (0..BRICK_X)
                    .filter(move |b| bits >> b & 1 == 1)
                    .map(move |b| (bx * BRICK_X + b, j, k))
            })
        })
    }

    /// The heap memory held, in bytes: the bricks (512 bytes each), their keys and the hash
    /// table (estimated as 8 + 4 + 1 bytes per bucket), by capacity.
    pub fn memory_bytes(&self) -> usize {
        self.bricks.capacity() * size_of::<Brick>()
            + self.keys.capacity() * size_of::<u64>()
            + self.index.capacity() * (size_of::<u64>() + size_of::<u32>() + 1)
    }

    /// The number of bricks (64 × 8 × 8 voxels each) stored.
    pub fn brick_count(&self) -> usize {
        self.bricks.len()
    }
}

/// The congruence of explored volumes on several maps (thesis §6.2, Tables 6.2–6.5): each
/// map's volume and, for each pair, the volume explored on the one but not on the other as a
/// percentage of the first's, `|A∖B| / |A| · 100`.
///
/// [`Display`](fmt::Display) prints a Markdown table in the thesis's layout, one row per map:
/// `Map | Volume [m³] | <name> | …`, where the column of map B holds "% of the row's volume
/// not in B", "–" on the diagonal and "n/a" for a row with no volume. Numbers have 3 decimals
/// (Table 6.2) unless a precision is given (`{:.4}`, Table 6.3).
#[derive(Clone, Debug, PartialEq)]
pub struct CongruenceTable {
    names: Vec<String>,
    counts: Vec<u64>,
    volumes: Vec<Real>,
    /// `not_in[a][b] = |a ∖ b|`.
    not_in: Vec<Vec<u64>>,
}

impl CongruenceTable {
    /// The table of the named grids, in the order given.
    ///
    /// # Errors
    /// [`VolumeError::LatticeMismatch`] unless all grids share one lattice.
    pub fn new<'a, S: Into<String>>(
        maps: impl IntoIterator<Item = (S, &'a VoxelGrid)>,
    ) -> Result<CongruenceTable, VolumeError> {
        let (names, grids): (Vec<String>, Vec<&VoxelGrid>) =
            maps.into_iter().map(|(s, g)| (s.into(), g)).unzip();
        let not_in = grids
            .iter()
            .map(|a| grids.iter().map(|b| a.count_not_in(b)).collect::<Result<Vec<_>, _>>())
            .collect::<Result<Vec<_>, _>>()?;
        Ok(CongruenceTable {
            names,
            counts: grids.iter().map(|g| g.count()).collect(),
            volumes: grids.iter().map(|g| g.volume()).collect(),
            not_in,
        })
    }

    /// The number of maps.
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// Whether the table has no maps.
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// The maps' names, in row (and column) order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The voxel count of map `row`.
    pub fn count(&self, row: usize) -> u64 {
        self.counts[row]
    }

    /// The explored volume of map `row`, m³.
    pub fn volume(&self, row: usize) -> Real {
        self.volumes[row]
    }

    /// `|row ∖ col|` in voxels.
    pub fn count_not_in(&self, row: usize, col: usize) -> u64 {
        self.not_in[row][col]
    }

    /// The volume explored on map `row` but not on map `col`, in % of the volume explored on
    /// `row`; `None` on the diagonal and if `row` explored nothing.
    pub fn percent_not_in(&self, row: usize, col: usize) -> Option<Real> {
        (row != col && self.counts[row] > 0)
            .then(|| self.not_in[row][col] as Real / self.counts[row] as Real * 100.0)
    }
}

impl fmt::Display for CongruenceTable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let prec = f.precision().unwrap_or(3);
        let mut rows: Vec<Vec<String>> = Vec::with_capacity(self.len() + 1);
        rows.push(
            ["Map".to_owned(), "Volume [m³]".to_owned()]
                .into_iter()
                .chain(self.names.iter().cloned())
                .collect(),
        );
        for (r, name) in self.names.iter().enumerate() {
            let mut row = vec![name.clone(), format!("{:.prec$}", self.volumes[r])];
            row.extend((0..self.len()).map(|c| match self.percent_not_in(r, c) {
                Some(p) => format!("{p:.prec$}"),
                None if r == c => "–".to_owned(),
                None => "n/a".to_owned(),
            }));
            rows.push(row);
        }
        let widths: Vec<usize> = (0..rows[0].len())
            .map(|c| rows.iter().map(|row| row[c].chars().count()).max().unwrap_or(0))
            .collect();
        let line = |f: &mut fmt::Formatter<'_>, row: &[String]| -> fmt::Result {
            for (cell, w) in row.iter().zip(&widths) {
                let pad = w - cell.chars().count();
                write!(f, "| {cell}{} ", " ".repeat(pad))?;
            }
            writeln!(f, "|")
        };
        line(f, &rows[0])?;
        let rule: Vec<String> = widths.iter().map(|w| "-".repeat(*w)).collect();
        line(f, &rule)?;
        for row in &rows[1..] {
            line(f, row)?;
        }
        Ok(())
    }
}
