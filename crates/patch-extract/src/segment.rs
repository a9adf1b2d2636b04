//! Plane segmentation by region growing with incremental plane fitting.
//!
//! The thesis takes its planar regions from [Poppinga et al. 2008] ("Fast Plane Detection and
//! Polygonalization in noisy 3D Range Images", IROS 2008; thesis L4221, L4502) but never
//! describes that method (spec §2.0, §7 item 2). This module is a region grower in that
//! spirit; everything below is our own choice, stated exactly.
//!
//! # Method
//! Input: a point cloud in the **sensor frame** (the sensor at the origin, as
//! [`PointCloud`]s made from range images are). `rᵢ = |pᵢ|` is the range of point `i` and
//! `σ(r) = sigma_0 + sigma_r2 · r²` ([`RangeNoise`]) its assumed noise along the normal.
//!
//! 1. **Neighbourhoods.** Organised clouds (with a [`Grid`]): growth neighbours are the
//!    4-neighbours in the pixel grid; the seed window of a pixel is the
//!    `(2s + 1) × (2s + 1)` block around it (`s` = [`SegmentConfig::seed_radius`]), taking
//!    every `t`-th pixel along each grid direction. The strides `t` (one per direction) are
//!    1 unless [`SegmentConfig::seed_min_extent`] `= e > 0`: then each is the smallest
//!    `t ≤ 32` for which the window's outermost pixels in that direction (through the centre)
//!    are at least `e · σ(r) / r` radians apart as seen from the sensor (`r` the centre's
//!    range; the angle between beam directions, which range noise does not change), and a
//!    pixel without such a `t` seeds nothing. Without this, close surfaces, whose pixels lie
//!    much closer together than the range noise, give seed windows of pure noise and no
//!    region ([`SegmentConfig::seed_min_extent`]).
//!    Unorganised clouds: the `k` nearest points within `radius` from an
//!    [`kiddo::ImmutableKdTree`] ([`SegmentConfig::knn`], [`SegmentConfig::knn_radius`]) are
//!    both the growth neighbours and the seed window.
//! 2. **Jump test** (no growth across depth discontinuities): neighbours `p`, `q` are linked
//!    only if `|p − q| ≤ jump_absolute + jump_relative · max(r_p, r_q)`.
//! 3. **Seeds.** Every point whose seed window is complete (all pixels valid, every window
//!    pixel joined to the centre by a chain of jump-test links: along the centre's row to the
//!    pixel's column, then along that column, or column first, then row; for k-NN at least 3
//!    neighbours) gets the surface variation `λ₀ / (λ₀ + λ₁ + λ₂)` of its window's
//!    plane fit; seeds are tried in ascending variation (flattest first; ties by index).
//!    A seed starts a region if no window point is taken yet, the window passes the two
//!    plane tests below, and its plane is not seen at grazing incidence:
//!    `|n · c| ≥ min_incidence_cos · |c|` for the window centroid `c`
//!    ([`SegmentConfig::min_incidence_cos`] explains why this test is essential).
//! 4. **Growth** (breadth first from the seed window): a free neighbour `m` of a region point
//!    joins iff it passes the jump test to that region point, **and** its distance to the
//!    region's current plane is at most `distance_factor · σ(r_m)`, **and** the region's
//!    mean squared distance after adding it is at most `mse_factor² · mean σ(rᵢ)²` over the
//!    region's points including `m`. The MSE after adding is the Rayleigh quotient
//!    `nᵀ S' n / (n + 1)` of the updated scatter `S'` ([`PlaneAccumulator::mse_along`]) with
//!    the current normal: an O(1) upper bound of the refitted MSE, so the test is
//!    conservative. With [`SegmentConfig::max_normal_angle`] `= Some(a)`, `m` must also
//!    not have a seed window (complete, as in step 3) whose plane is more than `a` from the
//!    region's. In a region seen at grazing incidence ([`GrazingPlanes::link_cos`]) the jump
//!    test's range part is stretched to the row spacing of the region's plane, and a seed
//!    window that the plain links do not chain may seed such a plane with the stretched links.
//!    The plane is refitted (3×3 eigenproblem) after every accepted point
//!    while the region is small and thereafter whenever it has grown by 5 %; the running
//!    sums are exact, so the final plane is the exact least-squares fit of the region's
//!    points. A point rejected from one region point may be accepted later from another.
//! 5. **Minimum size.** A region that stops growing with fewer than `min_region_size` points,
//!    or whose plane then fails the incidence test (with [`GrazingPlanes`], the stricter
//!    region form of it), is dissolved: its points become free again (later seeds may use
//!    them).
//! 6. **Bending test** (optional, [`SegmentConfig::max_bending`] `= Some(b)`). A region that
//!    reaches the minimum size is fitted once more: with `(u, v)` its points' coordinates
//!    along the plane's in-plane axes (centred, scaled by their RMS) and `dᵢ` their signed
//!    distances to its plane, the weighted least-squares regressions of `d` on `(1, u, v)` and
//!    on `(1, u, v, u², uv, v²)` (weights `1/σ(rᵢ)²`) are compared. The drop `D` of the
//!    weighted residual sum from the first to the second is the part of the residuals a
//!    quadratic surface explains, in units of σ²: on a plane with Gaussian noise of the
//!    assumed σ it is χ²(3)-distributed whatever the region's size; on a facet of a sphere or
//!    cylinder it grows with the number of points. The region is **bent** iff
//!    `D > n · b²` (the quadratic part's RMS exceeds `b` σ) **and** `D > 16.27` (the 99.9 %
//!    quantile of χ²(3), so small regions are not rejected for noise alone). A bent region
//!    is not kept and its points join the remainder for good (neither seeds nor growth use
//!    them again; freeing them would let every seed on a ball grow and reject another facet).
//!    It plays the part of the curvature limit of PCL's `OrganizedMultiPlaneSegmentation`
//!    (`setMaximumCurvature`), which drops a finished segment whose surface variation
//!    `λ₀ / (λ₀ + λ₁ + λ₂)` of its own scatter matrix (Pauly et al. 2002; the "curvature" of
//!    Rusu 2009, PhD thesis, TU München) is at or above the limit. That ratio mixes noise and
//!    bending and does not scale with σ(r): its noise part falls with the square of the
//!    region's width and its bending part grows with it, so one limit both refuses narrow
//!    noisy planes and passes narrow curved facets. The test here separates
//!    the quadratic part from the noise. It costs one pass over the region's points
//!    and a 6×6 Cholesky solve, O(points).
//! 7. **Output.** Regions largest first (ties by smallest point index), points ascending;
//!    each region's plane is the least-squares fit with its normal toward the sensor
//!    (origin), with the first-order [`PlaneFit::covariance`]. A region whose final plane
//!    fails the incidence test is dissolved. Points in no region form the remainder.
//!
//! # Complexity
//! Seeding is O(N w) for windows of `w` points plus O(N) to bucket the seeds and an
//! O(N log N) sort at worst (in practice only the seeds still open when their bucket comes up
//! are sorted). Growth tests each
//! neighbour of every accepted point once per acceptance, O(N α) in total where α is the
//! average number of regions (grown or dissolved) that reach a point, bounded by
//! `4 × (1 + dissolutions touching it)`; dissolved regions are smaller than
//! `min_region_size`, so the worst case is O(N · min_region_size), the typical case O(N).
//! k-NN neighbourhoods add O(N log N) for the tree and the queries.
//!
//! # Performance
//! Most seed windows are never tried (their point or a window point is taken by a region
//! grown from a flatter seed first), so their planes are not fitted up front: the seed order
//! and the normal test start from certified bounds on each window's curvature and normal
//! (one cheap power step on the adjugate of the scatter matrix, with interlacing and
//! Davis–Kahan/Kato–Temple error bounds), and a window is fitted exactly (3×3 eigenproblem)
//! only when its seed is tried or its bound cannot decide the normal test. A seed that comes
//! up untaken gets its exact curvature from Newton's method on the characteristic polynomial
//! (equal to the fit's to within 10⁻¹² and certified above its bound,
//! `PlaneAccumulator::polished_curvature`), and waits at it if another seed comes first.
//! The segmentation is that of fitting every window first (the same regions on every input
//! of `cargo xtask compare segmentation` and the lab's scans; seeds whose curvatures agree to
//! 10⁻¹² could in principle swap).
//! Release build, one core of a shared 2-core machine: a simulated 541 × 361 ALRF scan of
//! scene-sim's lab (≈ 190,000 points, 3 cm noise) takes ≈ 95 ms, ≈ 215 ms with every window
//! fitted up front, `atan2` for every seed stride and the generic eigensolver (measured with
//! `patchnav extract`'s stage times); see also the ignored test `measure_lab_scans` in
//! `tests/it/segment.rs`.
//!
//! Contiguous seed windows of organised clouds (every stride 1, windows up to 7 × 7) take
//! their moments from separable box sums over tiles of pixels ("integral images", relative to
//! a point of each tile; not in the thesis) instead of summing each window's points: on the
//! Kinect office frame and the floor-plan scan this cut the segmentation's time by about a
//! quarter. Such a window is queued at a floor of its curvature from the scatter's invariants
//! alone (`det / m₂` over the trace, `m₂` the sum of the principal 2 × 2 minors; about as
//! tight as the certified bound for flat windows, at a tenth of its cost; `curvature_floor`),
//! so the segmentation is again the same.
//!
//! The seeds' bounds are independent per point: [`segment_with_threads`] (and the pipeline,
//! with the cores its scans leave free) computes them for large organised clouds on several
//! threads and orders them as one list, so the segmentation does not depend on the count.
//! The bending test of a grown region decides only whether its points stay in it or go to
//! the remainder, not the growth after it, so with a second thread it runs there while the
//! growth goes on.
//!
//! # Actuated LRF scans
//! The ±90° beam column of an actuated LRF sees one line in every row (thesis App. A); run
//! [`crate::projection::invalidate_alrf_side_columns`] on the organised cloud **before**
//! segmenting it (it changes point indices). Segmentation itself treats the ALRF image like
//! any other grid; a surface seen both in front and (via beams beyond ±90°) behind the
//! sensor may come out as two regions.
//!
//! # Not guaranteed
//! Regions are not merged afterwards (two regions of one surface separated by an occluder
//! stay two), points are never moved between regions, and results depend on the seed order
//! (deterministic for a given cloud).

use crate::plane_fit::{PlaneAccumulator, PlaneFit, certified_window_plane};
use crate::region::{PlanarRegion, Segmentation};
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use nalgebra::Matrix3;
use patch_core::{Plane, Point3, Real, Vector3};
use pointcloud::{Grid, INVALID_PIXEL, PointCloud};
use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::num::NonZeroUsize;

/// The assumed range noise along a surface normal: `σ(r) = sigma_0 + sigma_r2 · r²` metres at
/// range `r`.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct RangeNoise {
    /// Constant part, metres (> 0).
    pub sigma_0: Real,
    /// Quadratic part, 1/m (≥ 0).
    pub sigma_r2: Real,
}

impl RangeNoise {
    /// `σ(r)`.
    pub fn sigma(&self, range: Real) -> Real {
        self.sigma_0 + self.sigma_r2 * range * range
    }
}

/// Surfaces seen at grazing incidence that are planes all the same: the undersides of table
/// tops and rack boards a scanner below them sees, the floor far away.
///
/// A strip of pixels gives a "plane" through the sensor (see
/// [`SegmentConfig::min_incidence_cos`]). A real horizontal surface seen grazingly keeps its
/// height: a table underside 0.22 m above the scanner is 0.22 m above it however far away it
/// is seen. So a seed or region whose plane fails the incidence test is accepted iff
///
/// * `|n · c| ≥ min_cos · |c|` (`c` the centroid relative to the sensor, `n` the normal);
/// * the centroid lies at least `min_offset_sigmas · σ(|c|)` above or below the sensor (the
///   height, not the plane's distance `|n · c|` from the sensor: a slightly tilted strip
///   through the sensor's height misses the sensor by its tilt times the range);
/// * the plane is within `max_tilt` of horizontal (`max_seed_tilt` for a seed window), the
///   world's up taken from the cloud's sensor pose (without a pose, the sensor frame's z);
/// * a region (not a seed) is at least `min_width_sigmas · σ(|c|)` wide (RMS) along its
///   narrower in-plane axis, and its points' heights spread (RMS) by at most
///   `max_height_rms_sigmas · σ(|c|)`.
///
/// Why horizontal only: the grazing surfaces a ground robot's scanner cannot see better
/// from elsewhere are the undersides of things above it and the floor far away, all
/// horizontal; accepting grazing planes of any orientation lets the curved (conical) pixel
/// columns of an actuated scanner, whose planes miss the sensor by more than the noise, in
/// as large phantom planes (measured on the lab: 7.6 % of free steps blocked).
///
/// Measured on the lab (8 scans, scene seed 0, step seed 1; planes map, unsafe / overcautious
/// %, before the outline offset): no grazing planes 7.32 / 0.62; (min_cos, offset, tilt, seed
/// tilt, width) = (0.03, 3, 8°, 15°, 3) 3.27 / 1.56 (the preset); (0.03, 3, 6°, 15°, 3)
/// 4.56 / 1.26; (0.03, 3, 4°, 15°, 3) 4.58 / 1.02; (0.02, 3, 6°, 20°, 3) 4.19 / 1.06. With
/// the plane's distance instead of the height and 10° for both tilts: 2.93 / 2.35; with
/// cos ≥ 0.02 and 20° seeds: 2.06 / 7.04 (phantom planes). The height spread limit (after the
/// outline offset and with regions dissolved at once), 8 / 29 scans: none 2.71 / 2.48 and
/// 0.85 / 13.33; 2.5σ (the preset) 2.75 / 2.24 and 0.86 / 8.99; 1.5σ 3.85 / 1.76 and
/// 0.94 / 6.93; 1σ 3.87 / 1.63 and 0.99 / 5.58. Seed windows chained by plain jump-test links
/// (8 scans; a window across a depth jump had joined wall points to a table's underside):
/// 4.00 / 1.40, the boards of the rack, seen from afar, no longer seeded; with windows
/// chained by links stretched to the grazing plane's row spacing (`link_cos`) and the normal
/// test ([`SegmentConfig::max_normal_angle`]): 2.73 / 1.39; held out (scene seed 1, step seed
/// 2): 1.87 / 3.37 before, 1.90 / 1.53 after.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct GrazingPlanes {
    /// The most grazing incidence accepted, as its cosine, in [0, 1).
    pub min_cos: Real,
    /// The plane's least distance from the sensor in units of the noise σ at the centroid's
    /// range (finite, ≥ 0).
    pub min_offset_sigmas: Real,
    /// The largest angle between a region's plane normal and the world's up (or down),
    /// radians, in [0, π/2].
    pub max_tilt: Real,
    /// The same for a seed window's plane, whose few points give a rougher normal, radians,
    /// in [0, π/2].
    pub max_seed_tilt: Real,
    /// A region's least RMS extent along its narrower in-plane axis, in units of the noise σ
    /// at the centroid's range (finite, ≥ 0; seeds are not tested). A strip one or two pixel
    /// rows wide is a line in space whose "plane" any rotation about the line fits: its
    /// normal, and so its incidence, says nothing.
    pub min_width_sigmas: Real,
    /// A region's largest RMS spread of heights (along the world's up), in units of σ at the
    /// centroid's range (finite, > 0; seeds are not tested). A horizontal surface's points
    /// differ in height by their noise only; a phantom plane tilted by a few degrees over
    /// metres spans tens of centimetres.
    pub max_height_rms_sigmas: Real,
    /// The incidence cosine down to which the jump test's `jump_relative` connects the
    /// points of one plane (> 0; `jump_relative` is the pixel spacing divided by it).
    /// Growing a region whose plane is seen more grazingly from the region point `q`, a
    /// neighbour is linked within `jump_absolute + jump_relative · r · link_cos / max(c,
    /// min_cos)` (`c = |n · q̂|`): the rows of a grazing plane lie `r · Δθ / c` apart, more
    /// than the plain jump test allows beyond a few metres. The plane test (within
    /// `distance_factor · σ` of the region's plane) still guards depth jumps. `1` (or
    /// above): no stretch.
    pub link_cos: Real,
}

/// Parameters of [`segment`]. No `Default`: start from a named preset and adjust.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct SegmentConfig {
    /// The noise model the thresholds scale with.
    pub noise: RangeNoise,
    /// A point joins only within `distance_factor · σ(r)` of the region's plane (> 0).
    pub distance_factor: Real,
    /// A region's MSE must stay within `mse_factor² · mean σ²` (> 0).
    pub mse_factor: Real,
    /// Jump test, constant part, metres (≥ 0).
    pub jump_absolute: Real,
    /// Jump test, part proportional to range (≥ 0; angular pixel spacing divided by the cosine
    /// of the steepest incidence angle that should still connect).
    pub jump_relative: Real,
    /// Regions with fewer points are dissolved (≥ 4).
    pub min_region_size: usize,
    /// Seeds and regions need `|n · c| ≥ min_incidence_cos · |c|` (`c` the centroid, the
    /// sensor at the origin), in [0, 1): planes seen at grazing incidence are refused. This
    /// matters beyond grazing surfaces: the points of any straight strip of pixels lie in a
    /// plane through the sensor however noisy their ranges (range noise moves points along
    /// their beams, inside that plane), so without this test thin strips across several
    /// surfaces make perfect "planes".
    pub min_incidence_cos: Real,
    /// Planes seen more grazingly than `min_incidence_cos` that are accepted all the same
    /// ([`GrazingPlanes`]); `None`: none (the strict test above).
    pub grazing: Option<GrazingPlanes>,
    /// Seed window half-size in pixels for organised clouds (1 = 3×3, 2 = 5×5; ≥ 1).
    pub seed_radius: u32,
    /// Organised clouds: the seed window is widened (every `t`-th pixel, `t ≤ 32` per grid
    /// direction) until it spans at least this many `σ(r)` across in each direction, measured
    /// by the angle between the beam directions of its outermost pixels times the range
    /// (module docs, step 1); pixels whose window cannot be widened enough seed nothing.
    /// 0 = contiguous windows (≥ 0). A plane fitted to a window a few σ across has a normal
    /// off by tens of degrees, so its region stalls and is dissolved: an ALRF at 0.5° sees a
    /// box face 0.8 m away with a pixel every 7 mm, and 5 × 5 contiguous pixels at σ = 3 cm
    /// never seed it.
    pub seed_min_extent: Real,
    /// Neighbours per point for unorganised clouds (≥ 3).
    pub knn: usize,
    /// Largest neighbour distance for unorganised clouds, metres (> 0).
    pub knn_radius: Real,
    /// Bending test (module docs, step 6): `Some(b)` rejects a region whose residuals a
    /// quadratic surface explains with an RMS above `b · σ` (and significantly, beyond the
    /// 99.9 % quantile of pure noise), i.e. facets of curved surfaces; `b` finite and > 0.
    /// `None`: no test. The MSE test already bounds a region's residual RMS by
    /// `mse_factor · σ`, so `b` must be well below `sqrt(mse_factor² − 1)` to matter.
    pub max_bending: Option<Real>,
    /// Normal agreement (module docs, step 4): `Some(a)` keeps a point out of a region when
    /// the plane of its own seed window (if complete) is more than `a` radians from the
    /// region's plane, in (0, π/2]. It stops a plane growing along a band of another surface
    /// that crosses it: the strip of a wall within the noise of a shelf's height, the rows
    /// of wall just behind a board's edge. `None`: no test.
    pub max_normal_angle: Option<Real>,
}

/// Why [`segment`] refused a configuration.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SegmentError {
    /// A real parameter is NaN, infinite or outside its range.
    #[error("segmentation parameter `{name}` = {value} must be {allowed}")]
    BadParameter {
        /// The field name.
        name: &'static str,
        /// The value given.
        value: Real,
        /// The allowed range.
        allowed: &'static str,
    },
    /// An integer parameter is outside its range.
    #[error("segmentation parameter `{name}` = {value} must be at least {min}")]
    TooSmall {
        /// The field name.
        name: &'static str,
        /// The value given.
        value: usize,
        /// The smallest allowed value.
        min: usize,
    },
}

impl SegmentConfig {
    /// The jump test's longest link between points whose larger range is `range`, its range
    /// part multiplied by `stretch` (1: the plain test; [`GrazingPlanes::link_cos`]).
    pub fn jump_limit(&self, range: Real, stretch: Real) -> Real {
        self.jump_absolute + self.jump_relative * stretch * range
    }

    /// The thesis's actuated LRF (SICK S300, §2.1; scene-sim's model has σ = 3 cm):
    /// σ(r) = 3 cm + 0.1 mm/m² r², points within 2σ, MSE within (1.2σ)², 5×5 seeds widened
    /// to span at least 3σ ([`ALRF_SEED_MIN_EXTENT`]), jumps up
    /// to 5 cm + 0.1 r (0.5° spacing at incidence up to ≈ 85°), seeds and regions seen at
    /// incidence below ≈ 78° (cos 0.2), regions of ≥ 100 points. k-NN: 8 within 25 cm.
    pub fn alrf() -> SegmentConfig {
        SegmentConfig {
            noise: RangeNoise { sigma_0: 0.03, sigma_r2: 1e-4 },
            distance_factor: 2.0,
            mse_factor: 1.2,
            jump_absolute: 0.05,
            jump_relative: 0.1,
            min_region_size: 100,
            min_incidence_cos: 0.2,
            grazing: Some(GrazingPlanes {
                min_cos: 0.03,
                min_offset_sigmas: 3.0,
                max_tilt: 8f64.to_radians(),
                max_seed_tilt: 15f64.to_radians(),
                min_width_sigmas: 3.0,
                max_height_rms_sigmas: 2.5,
                link_cos: GRAZING_LINK_COS,
            }),
            seed_radius: 2,
            seed_min_extent: ALRF_SEED_MIN_EXTENT,
            knn: 8,
            knn_radius: 0.25,
            max_bending: None,
            max_normal_angle: Some(ALRF_MAX_NORMAL_ANGLE),
        }
    }

    /// [`SegmentConfig::alrf`] for a second pass over an organised scan's remainder
    /// ([`segment_remainder`]): 3×3 seed windows widened to span at least
    /// [`ALRF_SECOND_PASS_SEED_MIN_EXTENT`] σ, regions of ≥ [`ALRF_SECOND_PASS_MIN_REGION`]
    /// points. Bands of wall a few rows high, seen between occluders, fit no 5×5 window.
    pub fn alrf_second_pass() -> SegmentConfig {
        SegmentConfig {
            seed_radius: 1,
            seed_min_extent: ALRF_SECOND_PASS_SEED_MIN_EXTENT,
            min_region_size: ALRF_SECOND_PASS_MIN_REGION,
            ..SegmentConfig::alrf()
        }
    }

    /// A time-of-flight range camera (SwissRanger SR-3000, §2.3): σ = 1 cm at every range, as
    /// scene-sim's model (a real camera's noise grows with range and falls with amplitude:
    /// raise `noise.sigma_r2` for real data), points within 3σ, MSE within (1.2σ)², 3×3 seeds,
    /// jumps up to 3 cm + 0.05 r (0.27° spacing at incidence up to ≈ 85°), seeds and regions
    /// seen at incidence below ≈ 78° (cos 0.2), regions of ≥ 100 points, the bending test at
    /// [`RANGE_CAMERA_MAX_BENDING`]. k-NN: 8 within 10 cm.
    pub fn range_camera() -> SegmentConfig {
        SegmentConfig {
            noise: RangeNoise { sigma_0: 0.01, sigma_r2: 0.0 },
            distance_factor: 3.0,
            mse_factor: 1.2,
            jump_absolute: 0.03,
            jump_relative: 0.05,
            min_region_size: 100,
            min_incidence_cos: 0.2,
            grazing: None,
            seed_radius: 1,
            seed_min_extent: 0.0,
            knn: 8,
            knn_radius: 0.1,
            max_bending: Some(RANGE_CAMERA_MAX_BENDING),
            max_normal_angle: None,
        }
    }

    /// A structured-light depth camera (Kinect v1, Xtion, PrimeSense: 640 × 480, 57° × 43°):
    /// the depth error grows with the square of the range, σ(r) = 1.2 mm + 1.9 mm/m² · r²
    /// (Nguyen, Izadi & Lovell 2012 fit σ_z = 1.2 mm + 1.9 mm/m² · (z − 0.4 m)²; the r² form
    /// is a little wider near the camera; 8.8 mm at 2 m, 3.2 cm at 4 m), points within 3σ,
    /// MSE within (1.5σ)² (the disparity steps make the residuals wider than Gaussian noise),
    /// 5×5 seeds, jumps up to 3 cm + 0.05 r, incidence below ≈ 78° (cos 0.2), regions of ≥ 500
    /// points (a 640 × 480 frame has 12× the pixels of a range camera's). k-NN: 8 within
    /// 10 cm. Not in the thesis, which used time-of-flight cameras; a range camera's constant
    /// σ fragments such frames into many small regions (172 planes instead of 22 on a Kinect
    /// office frame).
    pub fn structured_light() -> SegmentConfig {
        SegmentConfig {
            noise: RangeNoise { sigma_0: 0.0012, sigma_r2: 0.0019 },
            distance_factor: 3.0,
            mse_factor: 1.5,
            jump_absolute: 0.03,
            jump_relative: 0.05,
            min_region_size: 500,
            min_incidence_cos: 0.2,
            grazing: None,
            seed_radius: 2,
            seed_min_extent: 0.0,
            knn: 8,
            knn_radius: 0.1,
            max_bending: None,
            max_normal_angle: None,
        }
    }

    /// Noise-free data (ranges stored as `f32`, so about 1e-7 relative error remains):
    /// σ(r) = 10 µm + 1 µm/m² r², points within 3σ, MSE within (3σ)², 3×3 seeds, jumps up to
    /// 5 cm + 0.1 r, incidence below ≈ 84° (cos 0.1), regions of ≥ 50 points. k-NN: 8 within
    /// 25 cm.
    pub fn exact() -> SegmentConfig {
        SegmentConfig {
            noise: RangeNoise { sigma_0: 1e-5, sigma_r2: 1e-6 },
            distance_factor: 3.0,
            mse_factor: 3.0,
            jump_absolute: 0.05,
            jump_relative: 0.1,
            min_region_size: 50,
            min_incidence_cos: 0.1,
            grazing: None,
            seed_radius: 1,
            seed_min_extent: 0.0,
            knn: 8,
            knn_radius: 0.25,
            max_bending: None,
            max_normal_angle: None,
        }
    }

    /// Checks every parameter.
    pub fn validate(&self) -> Result<(), SegmentError> {
        let positive = |name, value: Real| {
            if value.is_finite() && value > 0.0 {
                Ok(())
            } else {
                Err(SegmentError::BadParameter { name, value, allowed: "finite and > 0" })
            }
        };
        let non_negative = |name, value: Real| {
            if value.is_finite() && value >= 0.0 {
                Ok(())
            } else {
                Err(SegmentError::BadParameter { name, value, allowed: "finite and ≥ 0" })
            }
        };
        let at_least = |name, value: usize, min: usize| {
            if value >= min { Ok(()) } else { Err(SegmentError::TooSmall { name, value, min }) }
        };
        positive("noise.sigma_0", self.noise.sigma_0)?;
        non_negative("noise.sigma_r2", self.noise.sigma_r2)?;
        positive("distance_factor", self.distance_factor)?;
        positive("mse_factor", self.mse_factor)?;
        non_negative("jump_absolute", self.jump_absolute)?;
        non_negative("jump_relative", self.jump_relative)?;
        non_negative("seed_min_extent", self.seed_min_extent)?;
        positive("knn_radius", self.knn_radius)?;
        if let Some(a) = self.max_normal_angle
            && !(a > 0.0 && a <= std::f64::consts::FRAC_PI_2)
        {
            return Err(SegmentError::BadParameter {
                name: "max_normal_angle",
                value: a,
                allowed: "in (0, π/2] radians",
            });
        }
        if let Some(b) = self.max_bending {
            positive("max_bending", b)?;
        }
        if !(self.min_incidence_cos >= 0.0 && self.min_incidence_cos < 1.0) {
            return Err(SegmentError::BadParameter {
                name: "min_incidence_cos",
                value: self.min_incidence_cos,
                allowed: "in [0, 1)",
            });
        }
        if let Some(g) = self.grazing {
            if !(g.min_cos >= 0.0 && g.min_cos < 1.0) {
                return Err(SegmentError::BadParameter {
                    name: "grazing.min_cos",
                    value: g.min_cos,
                    allowed: "in [0, 1)",
                });
            }
            non_negative("grazing.min_offset_sigmas", g.min_offset_sigmas)?;
            non_negative("grazing.min_width_sigmas", g.min_width_sigmas)?;
            positive("grazing.max_height_rms_sigmas", g.max_height_rms_sigmas)?;
            positive("grazing.link_cos", g.link_cos)?;
            for (name, value) in
                [("grazing.max_tilt", g.max_tilt), ("grazing.max_seed_tilt", g.max_seed_tilt)]
            {
                if !(0.0..=std::f64::consts::FRAC_PI_2).contains(&value) {
                    return Err(SegmentError::BadParameter {
                        name,
                        value,
                        allowed: "in [0, π/2] radians",
                    });
                }
            }
        }
        at_least("min_region_size", self.min_region_size, 4)?;
        at_least("seed_radius", self.seed_radius as usize, 1)?;
        at_least("knn", self.knn, 3)?;
        Ok(())
    }
}

/// Segments `cloud` (sensor frame) into planar regions: by pixel neighbourhoods if it has a
/// [`Grid`], else by k-nearest neighbours (module docs). An empty cloud gives an empty
/// segmentation.
///
/// # Errors
/// [`SegmentError`] for an invalid configuration (checked before anything else).
///
/// # Complexity
/// O(N α) growth plus O(N log N) seed ordering (module docs, "Complexity").
pub fn segment(cloud: &PointCloud, config: &SegmentConfig) -> Result<Segmentation, SegmentError> {
    segment_with_threads(cloud, config, NonZeroUsize::MIN)
}

/// [`segment`] with the seeds of a large organised cloud (at least 50,000 points per thread)
/// computed on up to `threads` threads (one: no thread is started). The segmentation does not
/// depend on the count.
///
/// # Errors
/// As [`segment`].
pub fn segment_with_threads(
    cloud: &PointCloud,
    config: &SegmentConfig,
    threads: NonZeroUsize,
) -> Result<Segmentation, SegmentError> {
    config.validate()?;
    match cloud.grid() {
        Some(grid) if !cloud.is_empty() => {
            let tests = Tests::new(cloud.positions(), config, up(cloud));
            let graph = Graph::grid(grid, &tests);
            Ok(grow(&graph, &tests, threads))
        }
        _ => segment_unorganised(cloud, config),
    }
}

/// The world's up (+z) in the sensor frame of `cloud` (+z without a pose).
pub(crate) fn up(cloud: &PointCloud) -> Vector3 {
    cloud.sensor_pose().map_or_else(Vector3::z, |pose| {
        let up = pose.world_from_sensor.rotation.inverse() * Vector3::z();
        if up.iter().all(|c| c.is_finite()) { up } else { Vector3::z() }
    })
}

/// A second segmentation of an organised cloud's remainder (its points in no region of
/// `first`, a [`segment`] of the same cloud) with `config`, usually smaller seed windows and
/// regions ([`SegmentConfig::alrf_second_pass`]; not in the thesis). The regions found are
/// appended to `first`'s, and its remainder shrinks to the points still in no region.
/// Returns how many regions were added; unorganised clouds are left as they are (0).
///
/// # Errors
/// [`SegmentError`] for an invalid configuration.
///
/// # Complexity
/// That of [`segment`] on the remainder, plus O(N) for the cloud's N points.
pub fn segment_remainder(
    cloud: &PointCloud,
    first: &mut Segmentation,
    config: &SegmentConfig,
) -> Result<usize, SegmentError> {
    config.validate()?;
    if cloud.grid().is_none() || first.remainder.is_empty() {
        return Ok(0);
    }
    let mut in_remainder = vec![false; cloud.len()];
    for &i in &first.remainder {
        in_remainder[i as usize] = true;
    }
    // The kept points keep their order: index k of `rest` is `first.remainder[k]`.
    let rest = cloud.retain_indices(|i| in_remainder[i]);
    let second = segment(&rest, config)?;
    let original = |k: &u32| first.remainder[*k as usize];
    let added = second.regions.len();
    let regions: Vec<PlanarRegion> = second
        .regions
        .into_iter()
        .map(|mut r| {
            r.points = r.points.iter().map(original).collect();
            r
        })
        .collect();
    first.remainder = second.remainder.iter().map(original).collect();
    first.regions.extend(regions);
    sort_largest_first(&mut first.regions);
    Ok(added)
}

/// [`segment`] with k-nearest-neighbour neighbourhoods even if `cloud` is organised.
///
/// # Errors
/// [`SegmentError`] for an invalid configuration.
pub fn segment_unorganised(
    cloud: &PointCloud,
    config: &SegmentConfig,
) -> Result<Segmentation, SegmentError> {
    config.validate()?;
    if cloud.is_empty() {
        return Ok(Segmentation::default());
    }
    let graph = Graph::knn(cloud.positions(), config.knn, config.knn_radius);
    let tests = Tests::new(cloud.positions(), config, up(cloud));
    Ok(grow(&graph, &tests, NonZeroUsize::MIN))
}

/// Neighbourhoods of the points: pixel grid or k-NN lists.
enum Graph<'a> {
    Grid {
        grid: &'a Grid,
        /// Per point: its pixel (row-major index).
        pixel_of: Vec<u32>,
        seed_radius: u32,
        /// Per point: the seed window's strides along columns and rows.
        strides: Strides,
        /// Per pixel: the first pixel of its run along its row (column) of valid pixels each
        /// linked to the next by the jump test; two pixels of one row (column) are joined by
        /// a chain of links iff their runs start at the same pixel.
        row_runs: Vec<u32>,
        col_runs: Vec<u32>,
        /// Per pixel, its links to the pixel on its left and the one above ([`LEFT`],
        /// [`LEFT_LINKED`], [`UP`], [`UP_LINKED`]).
        links: Vec<u8>,
    },
    Lists {
        /// `neighbours[offsets[i]..offsets[i + 1]]` are point `i`'s neighbours.
        offsets: Vec<u32>,
        neighbours: Vec<u32>,
    },
}

impl<'a> Graph<'a> {
    fn grid(grid: &'a Grid, tests: &Tests<'_>) -> Graph<'a> {
        let (points, config) = (tests.points, tests.config);
        let mut pixel_of = vec![INVALID_PIXEL; points.len()];
        for (pixel, &p) in grid.pixels().iter().enumerate() {
            if p != INVALID_PIXEL {
                pixel_of[p as usize] = pixel as u32;
            }
        }
        let strides = seed_strides(grid, &pixel_of, points, config);
        let (row_runs, col_runs, links) = link_runs(grid, tests);
        Graph::Grid {
            grid,
            pixel_of,
            seed_radius: config.seed_radius,
            strides,
            row_runs,
            col_runs,
            links,
        }
    }

    fn knn(points: &[Point3], k: usize, radius: Real) -> Graph<'static> {
        let coords: Vec<[Real; 3]> = points.iter().map(|p| [p.x, p.y, p.z]).collect();
        let mut offsets = vec![0u32];
        let mut neighbours = Vec::with_capacity(points.len() * k);
        // kiddo refuses only clouds beyond its u32 item range; then every point is isolated.
        if let Ok(tree) = ImmutableKdTree::<Real, 3>::new_from_slice(&coords) {
            let qty = NonZeroUsize::new(k + 1).unwrap_or(NonZeroUsize::MIN);
            for (i, q) in coords.iter().enumerate() {
                let found = tree.query(q).nearest_n::<SquaredEuclidean<Real>>(qty).execute();
                neighbours.extend(
                    found
                        .into_iter()
                        .filter(|n| n.item as usize != i && n.distance <= radius * radius)
                        .map(|n| n.item)
                        .take(k),
                );
                offsets.push(neighbours.len() as u32);
            }
        } else {
            offsets.resize(points.len() + 1, 0);
        }
        Graph::Lists { offsets, neighbours }
    }

    /// [`Graph::seed_window`] of a grid point into `members` (row-major, as there), or why
    /// not: an incomplete window, or one wider than [`MAX_WINDOW_SPAN`] (then
    /// [`seed_window_general`] takes it); for k-NN lists always `Incomplete`.
    fn grid_window(&self, i: usize, members: &mut [u32; WINDOW_CAPACITY]) -> GridWindow {
        let Graph::Grid { grid, pixel_of, seed_radius, strides, row_runs, col_runs, .. } = self
        else {
            return GridWindow::Incomplete;
        };
        let (w, h, s) = (grid.width(), grid.height(), *seed_radius);
        let pixel = pixel_of[i];
        let (col, row) = (pixel % w, pixel / w);
        let [tc, tr] = strides.of(i);
        let (sc, sr) = (s * tc, s * tr);
        if tc == 0 || tr == 0 || col < sc || row < sr || col + sc >= w || row + sr >= h {
            return GridWindow::Incomplete;
        }
        let span = 2 * s as usize + 1;
        if span > MAX_WINDOW_SPAN {
            return GridWindow::Wide;
        }
        // A member (c, r) is joined to the centre along the centre's row, then along its
        // column (`row_then_column`), or the other way round; the parts that depend on the
        // column or row alone are looked up once per column and row.
        let (wu, tcu, tru) = (w as usize, tc as usize, tr as usize);
        let (c0, r0, centre) = ((col - sc) as usize, (row - sr) as usize, pixel as usize);
        let centre_row_run = row_runs[centre];
        let centre_col_run = col_runs[centre];
        let row_base = row as usize * wu;
        // Per window column: whether the centre's row run reaches it, and its column run at
        // the centre's row.
        let mut by_column = [(false, 0u32); MAX_WINDOW_SPAN];
        for (k, slot) in by_column.iter_mut().take(span).enumerate() {
            let c = c0 + k * tcu;
            *slot = (centre_row_run == row_runs[row_base + c], col_runs[row_base + c]);
        }
        let pixels = grid.pixels();
        let mut len = 0;
        let mut chained = true;
        for kr in 0..span {
            let base = (r0 + kr * tru) * wu;
            // Whether the centre's column run reaches this row, and the row run of the
            // centre's column at this row.
            let column_reaches = centre_col_run == col_runs[base + col as usize];
            let row_run_here = row_runs[base + col as usize];
            for (kc, &(row_reaches, column_run)) in by_column.iter().take(span).enumerate() {
                let at = base + c0 + kc * tcu;
                let p = pixels[at];
                if p == INVALID_PIXEL {
                    return GridWindow::Incomplete;
                }
                members[len] = p;
                len += 1;
                if chained {
                    chained = (row_reaches && column_run == col_runs[at])
                        || (column_reaches && row_run_here == row_runs[at]);
                }
            }
        }
        GridWindow::Members(len, chained)
    }

    /// The growth neighbours of point `i` (on a grid: left, right, above, below), each with
    /// whether the plain jump test (stretch 1) links it to `i`, where the graph knows it (grids).
    fn neighbours(&self, i: usize, out: &mut Vec<(u32, Option<bool>)>) {
        out.clear();
        match self {
            Graph::Grid { grid, pixel_of, links, .. } => {
                let (w, pixels) = (grid.width() as usize, grid.pixels());
                let pixel = pixel_of[i] as usize;
                // A neighbour's bits are its own (left, above) or the pixel's on its other side
                // (right, below); pixels past the grid have none.
                let bits = |at: usize| links.get(at).copied().unwrap_or(0);
                let mut push = |at: usize, exists: bool, linked: bool| {
                    if exists {
                        out.push((pixels[at], Some(linked)));
                    }
                };
                let (here, right, below) = (bits(pixel), bits(pixel + 1), bits(pixel + w));
                push(pixel.wrapping_sub(1), here & LEFT != 0, here & LEFT_LINKED != 0);
                push(pixel + 1, right & LEFT != 0, right & LEFT_LINKED != 0);
                push(pixel.wrapping_sub(w), here & UP != 0, here & UP_LINKED != 0);
                push(pixel + w, below & UP != 0, below & UP_LINKED != 0);
            }
            Graph::Lists { offsets, neighbours } => {
                let list = &neighbours[offsets[i] as usize..offsets[i + 1] as usize];
                out.extend(list.iter().map(|&m| (m, None)));
            }
        }
    }

    /// The seed window of point `i` (including `i`) with, per member, the neighbour steps the
    /// jump test must allow between it and `i` (0: the grid's link chains join them already);
    /// `false` if the window is incomplete.
    fn seed_window(&self, i: usize, out: &mut Vec<(u32, u32)>) -> Option<bool> {
        out.clear();
        match self {
            Graph::Grid { grid, pixel_of, seed_radius, strides, row_runs, col_runs, .. } => {
                let mut members = [0u32; WINDOW_CAPACITY];
                match self.grid_window(i, &mut members) {
                    GridWindow::Members(len, chained) => {
                        out.extend(members[..len].iter().map(|&p| (p, 0)));
                        Some(chained)
                    }
                    GridWindow::Incomplete => None,
                    GridWindow::Wide => {
                        let (w, s) = (grid.width(), *seed_radius);
                        let pixel = pixel_of[i];
                        let [tc, tr] = strides.of(i);
                        seed_window_general(
                            grid,
                            row_runs,
                            col_runs,
                            (pixel % w, pixel / w),
                            (s * tc, s * tr),
                            (tc, tr),
                            out,
                        )
                    }
                }
            }
            Graph::Lists { offsets, neighbours } => {
                let list = &neighbours[offsets[i] as usize..offsets[i + 1] as usize];
                out.push((i as u32, 0));
                out.extend(list.iter().map(|&p| (p, 1)));
                (list.len() >= 3).then_some(true)
            }
        }
    }

    /// Whether every member of point `i`'s (complete) grid seed window is joined to `i` by a
    /// chain of pixels, along `i`'s row and then along the member's column, each pair of
    /// which passes `linked`. Always `true` for k-NN lists.
    fn window_chained(&self, i: usize, linked: impl Fn(usize, usize) -> bool) -> bool {
        let Graph::Grid { grid, pixel_of, seed_radius, strides, .. } = self else {
            return true;
        };
        let w = grid.width();
        let (col, row) = (pixel_of[i] % w, pixel_of[i] / w);
        let [tc, tr] = strides.of(i);
        let (sc, sr) = (seed_radius * tc, seed_radius * tr);
        let point = |c: u32, r: u32| grid.point_index(c, r);
        let walk = |from: (u32, u32), to: (u32, u32)| -> bool {
            let (mut c, mut r) = from;
            let Some(mut a) = point(c, r) else { return false };
            while (c, r) != to {
                if c != to.0 {
                    c = if c < to.0 { c + 1 } else { c - 1 };
                } else {
                    r = if r < to.1 { r + 1 } else { r - 1 };
                }
                match point(c, r) {
                    Some(b) if linked(a, b) => a = b,
                    _ => return false,
                }
            }
            true
        };
        (col - sc..=col + sc).step_by(tc as usize).all(|c| {
            walk((col, row), (c, row))
                && walk((c, row), (c, row - sr))
                && walk((c, row), (c, row + sr))
        })
    }
}

/// The most pixels along one direction of a seed window that [`Graph::grid_window`] handles
/// on the stack (`seed_radius` ≤ 3); wider windows take [`seed_window_general`].
const MAX_WINDOW_SPAN: usize = 7;

/// The most members of a window [`Graph::grid_window`] handles.
const WINDOW_CAPACITY: usize = MAX_WINDOW_SPAN * MAX_WINDOW_SPAN;

/// What [`Graph::grid_window`] found.
enum GridWindow {
    /// The window is complete: its first `.0` members, chained (`.1`) or not.
    Members(usize, bool),
    /// Not a complete window (or not a grid).
    Incomplete,
    /// Too wide for the stack: use [`Graph::seed_window`].
    Wide,
}

/// [`Graph::seed_window`] of the pixel (`col`, `row`) for any window size: half-extents
/// `(sc, sr)` and strides `(tc, tr)` in pixels, the window inside the grid.
fn seed_window_general(
    grid: &Grid,
    row_runs: &[u32],
    col_runs: &[u32],
    (col, row): (u32, u32),
    (sc, sr): (u32, u32),
    (tc, tr): (u32, u32),
    out: &mut Vec<(u32, u32)>,
) -> Option<bool> {
    let w = grid.width();
    let at = |c: u32, r: u32| (r * w + c) as usize;
    let joined = |c: u32, r: u32| {
        let row_then_column = row_runs[at(col, row)] == row_runs[at(c, row)]
            && col_runs[at(c, row)] == col_runs[at(c, r)];
        row_then_column
            || (col_runs[at(col, row)] == col_runs[at(col, r)]
                && row_runs[at(col, r)] == row_runs[at(c, r)])
    };
    let mut chained = true;
    for r in (row - sr..=row + sr).step_by(tr as usize) {
        for c in (col - sc..=col + sc).step_by(tc as usize) {
            out.push((grid.point_index(c, r)? as u32, 0));
            chained &= joined(c, r);
        }
    }
    Some(chained)
}

/// The default [`SegmentConfig::seed_min_extent`] of [`SegmentConfig::alrf`]: 3σ, so 9 cm at
/// σ = 3 cm. The ALRF's 5 × 5 contiguous windows at 0.5° spacing span 3σ at about 2.6 m (away
/// from the rotation axis), so only nearer surfaces, and pixels near the axis where the rows
/// crowd together, get wider windows. Measured on 8 scans of scene-sim's lab (σ = 3 cm;
/// `tests/it/lab_coverage.rs`, points whose noise-free hit lies within 5 cm of a merged patch):
/// 0 (contiguous): 96.4 %, a box face 0.8 m from the sensor missed; 3σ: 98.3 %; 4σ: 98.2 %;
/// 6σ: 94.4 % and 8σ: 93.7 % (with strides up to 8: windows wider than small faces seed
/// nothing on them).
pub const ALRF_SEED_MIN_EXTENT: Real = 3.0;

/// [`SegmentConfig::alrf_second_pass`]'s least seed-window extent, in σ. Measured on the lab
/// (8 scans, scene seed 0, step seed 1; planes map unsafe / overcautious %): without a second
/// pass 1.87 / 1.52; 3×3 windows of 3σ, regions of 30: 1.65 / 1.58; 1.5σ, 30: 1.37 / 1.74;
/// 1.5σ, 20: 1.34 / 1.76; 1.5σ, 50: 1.47 / 1.64; 0 (contiguous), 30: 1.37 / 1.79; 5×5
/// windows of 3σ, 30: 1.84 / 1.53.
pub const ALRF_SECOND_PASS_SEED_MIN_EXTENT: Real = 1.5;

/// [`SegmentConfig::alrf_second_pass`]'s least region size, points (see
/// [`ALRF_SECOND_PASS_SEED_MIN_EXTENT`]).
pub const ALRF_SECOND_PASS_MIN_REGION: usize = 20;

/// The [`SegmentConfig::max_normal_angle`] of [`SegmentConfig::alrf`]: 60°. It is meant to keep
/// out the points of surfaces across the region's (90°: walls below a shelf); a seed window's
/// normal wanders by about 8° on a plane seen head-on and by less at grazing incidence, but
/// windows at a region's edge mix both sides. Measured on the lab (8 scans, scene seed 0, step
/// seed 1; planes and hybrid maps, unsafe / overcautious %, with chained seed windows and
/// grazing links): 30° 2.76 / 1.33 and 1.11 / 1.98; 60° 2.73 / 1.39 and 1.11 / 1.88. Without
/// the test, chained windows alone: planes 4.00 / 1.40 (before grazing links); with it
/// 3.95 / 1.27.
pub const ALRF_MAX_NORMAL_ANGLE: Real = std::f64::consts::FRAC_PI_3;

/// The [`GrazingPlanes::link_cos`] of [`SegmentConfig::alrf`]: cos 85°, the incidence its
/// `jump_relative` of 0.1 connects at the S300's 0.5° spacing.
pub const GRAZING_LINK_COS: Real = 0.087;

/// The [`SegmentConfig::max_bending`] of [`SegmentConfig::range_camera`]: 0.3 σ. Measured on
/// 6 simulated range-camera frames of scene-sim's lab (σ = 1 cm; `cargo xtask compare
/// segmentation --lab-frames 6`, 16 visible true planes): without the test 15 true planes
/// found and 23 planes matching no true plane (facets of a ball, a barrel and table legs, and
/// box faces grown over an edge); 0.2: 13 found, 0 off; 0.3: 15 found, 0 off; 0.4: 15 found,
/// 2 off; 0.5: 15 found, 6 off. Freeing the points of bent regions for later seeds instead of
/// dropping them gave 15 found, 2 off at up to 3.6× the time.
pub const RANGE_CAMERA_MAX_BENDING: Real = 0.3;

/// Largest stride of a widened seed window (near an ALRF's rotation axis the rows crowd
/// together: 25° from the axis a 0.5° pitch step moves the beam by 0.21°).
const MAX_SEED_STRIDE: u32 = 32;

/// Per point: the strides of its seed window along columns and rows (module docs, step 1).
enum Strides {
    /// `[1, 1]` for every point (`seed_min_extent` is 0).
    Ones,
    /// `0` where no stride up to [`MAX_SEED_STRIDE`] widens the window enough.
    Each(Vec<[u8; 2]>),
}

impl Strides {
    /// Point `i`'s strides.
    #[inline]
    fn of(&self, i: usize) -> [u32; 2] {
        match self {
            Strides::Ones => [1, 1],
            Strides::Each(strides) => strides[i].map(u32::from),
        }
    }
}

/// The points' [`Strides`].
fn seed_strides(
    grid: &Grid,
    pixel_of: &[u32],
    points: &[Point3],
    config: &SegmentConfig,
) -> Strides {
    if config.seed_min_extent <= 0.0 {
        return Strides::Ones;
    }
    let (w, h, s) = (grid.width() as usize, grid.height() as usize, config.seed_radius as usize);
    let pixels = grid.pixels();
    // Per pixel: the unit direction of its point (NaN without a point or for the origin,
    // where the quick test leaves the decision to the full one).
    let unit: Vec<Vector3> = pixels
        .iter()
        .map(|&p| match p {
            INVALID_PIXEL => Vector3::repeat(Real::NAN),
            p => points[p as usize].coords / points[p as usize].coords.norm(),
        })
        .collect();
    let strides = points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let range = p.coords.norm();
            if range.is_nan() || range <= 0.0 || pixel_of[i] == INVALID_PIXEL {
                return [0, 0];
            }
            let needed = config.seed_min_extent * config.noise.sigma(range) / range;
            let wide_enough = AngleTest { needed };
            let pixel = pixel_of[i] as usize;
            let (col, row) = (pixel % w, pixel / w);
            // The first stride whose window ends (`step` pixels apart per unit of stride
            // along the grid) are both measured and wide enough, if the window stays inside
            // the grid up to it.
            let stride = |step: usize, room: usize| -> u8 {
                let last = (room / s).min(MAX_SEED_STRIDE as usize);
                for t in 1..=last {
                    let (a, b) = (pixel - s * t * step, pixel + s * t * step);
                    let wide = wide_enough.quick(&unit[a], &unit[b]).unwrap_or_else(|| {
                        match (pixels[a], pixels[b]) {
                            (INVALID_PIXEL, _) | (_, INVALID_PIXEL) => false,
                            (a, b) => wide_enough.exact(&points[a as usize], &points[b as usize]),
                        }
                    });
                    if wide {
                        return t as u8;
                    }
                }
                0
            };
            [stride(1, col.min(w - 1 - col)), stride(w, row.min(h - 1 - row))]
        })
        .collect();
    Strides::Each(strides)
}

/// The test `angle(a, b) ≥ needed` of [`seed_strides`] for the angle
/// `atan2(|a × b|, a · b)` between two beam directions, decided without `atan2` where the
/// answer is certain: the chord `c = |â − b̂|` between the unit directions and the angle `θ`
/// satisfy `c ≤ θ ≤ c + c³/20` for `c ≤ 1` (`θ = 2 asin(c/2)`). Near the threshold (within
/// `1e-9`, far beyond the `1e-15` or so of rounding in either form) it evaluates `atan2`
/// itself, so the answer is always that of the plain `atan2` comparison.
struct AngleTest {
    needed: Real,
}

impl AngleTest {
    /// The answer where the chord decides it.
    fn quick(&self, unit_a: &Vector3, unit_b: &Vector3) -> Option<bool> {
        // Compared squared: `chord ≥ needed + margin`, and for `chord ≤ 1`
        // `chord (1 + chord² / 20) < needed − margin` (rounding stays far inside the margin).
        let chord2 = (unit_a - unit_b).norm_squared();
        let margin = 1e-9 * (1.0 + self.needed);
        let high = self.needed + margin;
        if chord2 >= high * high {
            return Some(true);
        }
        let low = self.needed - margin;
        if chord2 <= 1.0 && low > 0.0 && {
            let stretch = 1.0 + chord2 * 0.05;
            chord2 * stretch * stretch < low * low
        } {
            return Some(false);
        }
        None
    }

    /// The plain test.
    fn exact(&self, a: &Point3, b: &Point3) -> bool {
        let (a, b) = (a.coords, b.coords);
        a.cross(&b).norm().atan2(a.dot(&b)) >= self.needed
    }

    /// The test for points `a`, `b` with unit directions `unit_a`, `unit_b`.
    #[cfg(test)]
    fn passes(&self, a: &Vector3, b: &Vector3, unit_a: &Vector3, unit_b: &Vector3) -> bool {
        self.quick(unit_a, unit_b)
            .unwrap_or_else(|| self.exact(&Point3::from(*a), &Point3::from(*b)))
    }
}

/// A pixel's bit in [`Graph::Grid`]'s `links`: it and the pixel on its left are valid.
const LEFT: u8 = 1;
/// ... and the plain jump test (stretch 1) links them.
const LEFT_LINKED: u8 = 2;
/// A pixel's bit: it and the pixel above are valid.
const UP: u8 = 4;
/// ... and the plain jump test links them.
const UP_LINKED: u8 = 8;

/// Per pixel, the first pixel of its run of linked pixels along its row and along its column
/// ([`Graph::Grid`]'s `row_runs`, `col_runs`; invalid pixels are runs of their own), and its
/// links to the pixels on its left and above (`links`).
fn link_runs(grid: &Grid, tests: &Tests<'_>) -> (Vec<u32>, Vec<u32>, Vec<u8>) {
    let (w, h) = (grid.width() as usize, grid.height() as usize);
    let pixels = grid.pixels();
    // The bits of the pair `a`, `b` (`a` the pixel left of or above `b`): both valid, linked.
    let link = |a: usize, b: usize, valid: u8, linked: u8| match (pixels[a], pixels[b]) {
        (pa, pb) if pa != INVALID_PIXEL && pb != INVALID_PIXEL => {
            if tests.linked(pa as usize, pb as usize, 1) { valid | linked } else { valid }
        }
        _ => 0,
    };
    let mut links = vec![0u8; w * h];
    let mut row_runs: Vec<u32> = (0..(w * h) as u32).collect();
    let mut col_runs = row_runs.clone();
    for r in 0..h {
        for c in 0..w {
            let b = r * w + c;
            let mut bits = 0;
            if c > 0 {
                bits |= link(b - 1, b, LEFT, LEFT_LINKED);
            }
            if r > 0 {
                bits |= link(b - w, b, UP, UP_LINKED);
            }
            if bits & LEFT_LINKED != 0 {
                row_runs[b] = row_runs[b - 1];
            }
            if bits & UP_LINKED != 0 {
                col_runs[b] = col_runs[b - w];
            }
            links[b] = bits;
        }
    }
    (row_runs, col_runs, links)
}

/// Per-point quantities and the thresholds derived from the configuration.
struct Tests<'a> {
    points: &'a [Point3],
    /// Per point: its range.
    range: Vec<Real>,
    sigma: Sigmas,
    config: &'a SegmentConfig,
    /// The world's up in the sensor frame.
    up: Vector3,
}

impl<'a> Tests<'a> {
    fn new(points: &'a [Point3], config: &'a SegmentConfig, up: Vector3) -> Tests<'a> {
        let range: Vec<Real> = points.iter().map(|p| p.coords.norm()).collect();
        let sigma = Sigmas::new(&config.noise, &range);
        Tests { points, range, sigma, config, up }
    }

    fn linked(&self, a: usize, b: usize, steps: u32) -> bool {
        let limit = self.config.jump_limit(self.range[a].max(self.range[b]), 1.0);
        (self.points[a] - self.points[b]).norm() <= limit * steps as Real
    }

    /// The factor ≥ 1 on the jump test's range part for a plane seen from `point` (sensor
    /// frame) ([`GrazingPlanes::link_cos`]); 1 unless the plane is seen grazingly.
    fn stretch(&self, normal: &Vector3, point: &Vector3) -> Real {
        let Some(g) = self.config.grazing else { return 1.0 };
        let range = point.norm();
        if range.is_nan() || range <= 0.0 {
            return 1.0;
        }
        let c = normal.dot(point).abs() / range;
        if c < self.config.min_incidence_cos {
            (g.link_cos / c.max(g.min_cos)).max(1.0)
        } else {
            1.0
        }
    }

    /// The stretch of a seed window's plane seen from its centroid, if the plane is seen
    /// grazingly and grazing planes are configured.
    fn grazing_stretch(&self, fit: &PlaneFit) -> Option<Real> {
        let stretch = self.stretch(&fit.plane.normal, &fit.centroid.coords);
        (stretch > 1.0).then_some(stretch)
    }

    /// The jump test with its range part multiplied by `stretch`.
    fn linked_by(&self, a: usize, b: usize, stretch: Real) -> bool {
        let limit = self.config.jump_limit(self.range[a].max(self.range[b]), stretch);
        (self.points[a] - self.points[b]).norm() <= limit
    }

    /// The jump test between region point `q` and its neighbour `m` while growing a region
    /// with `plane` ([`GrazingPlanes::link_cos`]); `plain`: the plain test's answer (stretch
    /// 1), if known.
    fn linked_on(&self, plane: &Plane, q: usize, m: usize, plain: Option<bool>) -> bool {
        match (self.stretch(&plane.normal, &self.points[q].coords), plain) {
            (1.0, Some(linked)) => linked,
            (stretch, _) => self.linked_by(q, m, stretch),
        }
    }

    fn near_plane(&self, plane: &Plane, m: usize) -> bool {
        plane.signed_distance(&self.points[m]).abs()
            <= self.config.distance_factor * self.sigma.of(m)
    }

    /// The incidence test of a region's plane (`seed`: of a seed window's).
    fn facing(&self, fit: &PlaneFit, seed: bool) -> bool {
        let c = fit.centroid.coords;
        let (offset, range) = (fit.plane.normal.dot(&c).abs(), c.norm());
        if offset >= self.config.min_incidence_cos * range {
            return true;
        }
        let sigma = self.config.noise.sigma(range);
        self.config.grazing.is_some_and(|g| {
            offset >= g.min_cos * range
                && c.dot(&self.up).abs() >= g.min_offset_sigmas * sigma
                && (seed
                    || (fit.eigenvalues[1]
                        >= (g.min_width_sigmas * sigma).powi(2) * fit.count as Real
                        && height_variance(fit, &self.up)
                            <= (g.max_height_rms_sigmas * sigma).powi(2)))
                && fit.plane.normal.dot(&self.up).abs()
                    >= if seed { g.max_seed_tilt } else { g.max_tilt }.cos()
        })
    }

    fn mse_ok(&self, mse: Real, sum_sigma2: Real, count: usize) -> bool {
        let f = self.config.mse_factor;
        mse <= f * f * sum_sigma2 / count as Real
    }
}

/// Each point's σ, the noise model at its range ([`RangeNoise::sigma`]): one value where the
/// model is constant, which is then exactly each point's σ (it saves a frame's worth of
/// memory on the hot path of range cameras).
enum Sigmas {
    Same(Real),
    Each(Vec<Real>),
}

impl Sigmas {
    fn new(noise: &RangeNoise, range: &[Real]) -> Sigmas {
        // `sigma_0 + 0 · r²` is `sigma_0` unless `r²` overflows.
        if noise.sigma_r2 == 0.0 && range.iter().all(|r| (r * r).is_finite()) {
            Sigmas::Same(noise.sigma_0)
        } else {
            Sigmas::Each(range.iter().map(|&r| noise.sigma(r)).collect())
        }
    }

    /// Point `i`'s σ.
    #[inline]
    fn of(&self, i: usize) -> Real {
        match self {
            Sigmas::Same(sigma) => *sigma,
            Sigmas::Each(sigma) => sigma[i],
        }
    }
}

/// The variance of a fit's points along `up` (unit): `upᵀ S up / n` for the scatter `S`.
fn height_variance(fit: &PlaneFit, up: &Vector3) -> Real {
    let n = fit.count.max(1) as Real;
    (0..3).map(|k| fit.eigenvalues[k] * fit.eigenvectors.column(k).dot(up).powi(2)).sum::<Real>()
        / n
}

/// An integer whose order is [`f64::total_cmp`]'s order of `x` (the key `total_cmp` itself
/// compares).
fn total_order_key(x: Real) -> i64 {
    let bits = x.to_bits() as i64;
    bits ^ ((((bits >> 63) as u64) >> 1) as i64)
}

const FREE: u32 = u32::MAX;
/// Owner of the points of a region rejected by the bending test: in no region, never reused.
const BENT: u32 = u32::MAX - 1;

/// The 99.9 % quantile of χ²(3).
const CHI2_3_999: Real = 16.266;

/// The bending statistic of a region (module docs, step 6): the drop `D` of the
/// `1/σ²`-weighted residual sum from the linear to the quadratic regression of the points'
/// plane distances on their in-plane coordinates. `None` if the region has no plane fit or
/// the regression is degenerate (points on a line or a conic in the plane), then the region
/// counts as not bent.
fn bending(
    points: &[Point3],
    region: &[u32],
    sigma: &Sigmas,
    acc: &PlaneAccumulator,
) -> Option<Real> {
    let fit = acc.fit(&Point3::origin())?;
    let n = fit.count as Real;
    let normal: Vector3 = fit.eigenvectors.column(0).into_owned();
    let scale = |k: usize| (fit.eigenvalues[k] / n).sqrt();
    let (s1, s2) = (scale(1), scale(2));
    if !(s1 > 0.0 && s2 > 0.0) {
        return None;
    }
    let e1: Vector3 = fit.eigenvectors.column(1).into_owned() / s1;
    let e2: Vector3 = fit.eigenvectors.column(2).into_owned() / s2;
    // `a += w φ φᵀ` (its lower triangle) and `b += w d φ` per point, in the operations of
    // nalgebra's `syger` and `axpy` (each product rounded, then added), so the sums are
    // theirs bit for bit, without their general-size loops.
    let mut lower = [[0.0; 6]; 6];
    let mut rhs = [0.0; 6];
    for &i in region {
        let q = points[i as usize] - fit.centroid;
        let (u, v, d) = (q.dot(&e1), q.dot(&e2), q.dot(&normal));
        let s = sigma.of(i as usize);
        let w = 1.0 / (s * s);
        let phi = [1.0, u, v, u * u, u * v, v * v];
        for j in 0..6 {
            let wj = w * phi[j];
            for k in j..6 {
                lower[k][j] += wj * phi[k];
            }
        }
        let wd = w * d;
        for k in 0..6 {
            rhs[k] += wd * phi[k];
        }
    }
    let a = nalgebra::Matrix6::<Real>::from_fn(|r, c| if r >= c { lower[r][c] } else { 0.0 });
    let b = nalgebra::Vector6::<Real>::from(rhs);
    let full = a.cholesky()?.solve(&b);
    let a3 = a.fixed_view::<3, 3>(0, 0).into_owned();
    let b3 = b.fixed_rows::<3>(0).into_owned();
    let linear = a3.cholesky()?.solve(&b3);
    let drop = b.dot(&full) - b3.dot(&linear);
    drop.is_finite().then_some(drop.max(0.0))
}

/// A seed in the seed order, packed so that integer order is the order of its window's
/// curvature (a lower bound of it until `fitted`) in [`f64::total_cmp`] order, then of its
/// point: the curvature's order key with its sign bit flipped (signed to unsigned order) in
/// the top 64 bits, the point in the next 32, whether the curvature is the fitted one in the
/// lowest bit.
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct Seed(u128);

impl Seed {
    fn new(curvature: Real, point: u32, fitted: bool) -> Seed {
        let key = (total_order_key(curvature) as u64) ^ (1 << 63);
        Seed(((key as u128) << 64) | ((point as u128) << 1) | fitted as u128)
    }

    fn point(self) -> usize {
        ((self.0 >> 1) as u32) as usize
    }

    /// The curvature's order key (the top 64 bits).
    fn key(self) -> u64 {
        (self.0 >> 64) as u64
    }

    fn fitted(self) -> bool {
        self.0 & 1 == 1
    }
}

/// Bits of each of a [`SeedQueue`]'s two bucket levels: up to 64 coarse buckets of up to 64
/// fine ones.
const SEED_BUCKET_BITS: u32 = 6;

/// The seeds in ascending order, sorted lazily. The key's integer range is split evenly into
/// up to 4,096 fine buckets, 64 to a coarse bucket. The seeds come in shares (one per seed
/// thread), and each share is ordered by coarse bucket in place, the shares on threads of
/// their own. When the growth reaches a coarse bucket, each share's part of it loses the
/// seeds whose points are taken or spent by then and is ordered by fine bucket the same way;
/// when the growth reaches a fine bucket, its open seeds from every share are sorted. That
/// drops nothing still to be tried: between two seeds a taken point stays taken (a dissolved
/// region frees only the points it took, before the next seed) and a spent one stays spent.
/// On a VGA frame most seeds are taken before their bucket comes up, so this replaces
/// sorting 250,000–300,000 seeds by sorting a few thousand, with no second array of seeds;
/// and with at most 64 buckets per pass the in-place passes write to 64 places at a time,
/// which stay in cache (4,096 at once cost a cache and TLB miss per seed).
struct SeedQueue {
    /// The seeds; each share by coarse bucket, its part of the current coarse bucket by fine
    /// bucket.
    seeds: Vec<Seed>,
    /// The smallest key, and the shift that maps `key - min` to its fine bucket's index over
    /// all coarse buckets.
    min: u64,
    shift: u32,
    shares: Vec<QueueShare>,
    coarse_buckets: usize,
    /// The next coarse bucket to prepare, and the next fine bucket of the current one
    /// ([`FINE_BUCKETS`]: none left).
    next_coarse: usize,
    next_fine: usize,
    /// The current fine bucket's open seeds, sorted, and the next of them.
    current: Vec<Seed>,
    next: usize,
}

/// Fine buckets per coarse bucket of a [`SeedQueue`].
const FINE_BUCKETS: usize = 1 << SEED_BUCKET_BITS;

/// One share of a [`SeedQueue`]'s seeds: `seeds[coarse[c]..coarse[c + 1]]` is its part of
/// coarse bucket `c`, and `seeds[fine[f]..fine[f + 1]]` its open seeds of fine bucket `f` of
/// the current coarse bucket.
struct QueueShare {
    coarse: Vec<usize>,
    fine: Vec<usize>,
}

impl SeedQueue {
    /// The queue of the packed seeds ([`Seed`]'s `u128`) `packed[r]` of each share `r` (in
    /// ascending order, not overlapping; the rest of `packed` is ignored), each in any order.
    fn new(packed: Vec<u128>, shares: &[std::ops::Range<usize>]) -> SeedQueue {
        let mut seeds: Vec<Seed> = packed.into_iter().map(Seed).collect();
        let (min, max) = shares
            .iter()
            .flat_map(|r| &seeds[r.clone()])
            .fold((u64::MAX, 0), |(lo, hi), s| (lo.min(s.key()), hi.max(s.key())));
        let (min, max) = if min > max { (0, 0) } else { (min, max) };
        let shift = (u64::BITS - (max - min).leading_zeros()).saturating_sub(2 * SEED_BUCKET_BITS);
        let coarse_buckets = (((max - min) >> shift >> SEED_BUCKET_BITS) + 1) as usize;
        // Each share's slice, with its offset.
        let mut slices = Vec::with_capacity(shares.len());
        let (mut rest, mut offset) = (&mut seeds[..], 0);
        for r in shares {
            let (_, tail) = std::mem::take(&mut rest).split_at_mut(r.start - offset);
            let (share, tail) = tail.split_at_mut(r.len());
            slices.push((r.start, share));
            (rest, offset) = (tail, r.end);
        }
        let shares = in_parts(slices, |(start, share)| {
            let coarse = partition_seeds(share, coarse_buckets, |s| {
                ((s.key() - min) >> shift >> SEED_BUCKET_BITS) as usize
            });
            QueueShare { coarse: coarse.into_iter().map(|k| start + k).collect(), fine: Vec::new() }
        });
        SeedQueue {
            seeds,
            min,
            shift,
            shares,
            coarse_buckets,
            next_coarse: 0,
            next_fine: FINE_BUCKETS,
            current: Vec::new(),
            next: 0,
        }
    }

    /// The next seed, without taking it; `closed(point)`: whether a point is taken or spent.
    fn peek(&mut self, closed: impl Fn(usize) -> bool) -> Option<Seed> {
        loop {
            if let Some(&seed) = self.current.get(self.next) {
                return Some(seed);
            }
            if self.next_fine < FINE_BUCKETS {
                let f = self.next_fine;
                self.next_fine += 1;
                self.current.clear();
                self.next = 0;
                for share in &self.shares {
                    if let (Some(&a), Some(&b)) = (share.fine.get(f), share.fine.get(f + 1)) {
                        let open = self.seeds[a..b].iter().filter(|s| !closed(s.point()));
                        self.current.extend(open);
                    }
                }
                self.current.sort_unstable();
                continue;
            }
            if self.next_coarse >= self.coarse_buckets {
                return None;
            }
            let c = self.next_coarse;
            self.next_coarse += 1;
            self.next_fine = 0;
            let (min, shift) = (self.min, self.shift);
            let fine_of = |s: &Seed| ((s.key() - min) >> shift) as usize & (FINE_BUCKETS - 1);
            for share in &mut self.shares {
                let (a, b) = (share.coarse[c], share.coarse[c + 1]);
                let open = a + retain_open(&mut self.seeds[a..b], &closed);
                let fine = partition_seeds(&mut self.seeds[a..open], FINE_BUCKETS, fine_of);
                share.fine = fine.into_iter().map(|k| a + k).collect();
            }
        }
    }

    /// Takes the seed [`peek`](Self::peek) gave.
    fn pop(&mut self) {
        debug_assert!(self.next < self.current.len());
        self.next += 1;
    }
}

/// Moves the seeds of `seeds` whose points are open (not `closed`) to its front, in order;
/// returns how many.
fn retain_open(seeds: &mut [Seed], closed: impl Fn(usize) -> bool) -> usize {
    let mut open = 0;
    for k in 0..seeds.len() {
        let seed = seeds[k];
        if !closed(seed.point()) {
            seeds[open] = seed;
            open += 1;
        }
    }
    open
}

/// Orders `seeds` by `bucket` (< `buckets`) in place, by counts and swaps (each seed moves
/// once, to its bucket's next free place); returns the `buckets + 1` bucket bounds.
fn partition_seeds(
    seeds: &mut [Seed],
    buckets: usize,
    bucket: impl Fn(&Seed) -> usize,
) -> Vec<usize> {
    let mut starts = vec![0; buckets + 1];
    for s in seeds.iter() {
        starts[bucket(s) + 1] += 1;
    }
    for b in 1..starts.len() {
        starts[b] += starts[b - 1];
    }
    // `seeds[starts[b]..fill[b]]` hold bucket `b`'s seeds.
    let mut fill = starts.clone();
    for b in 0..buckets {
        while fill[b] < starts[b + 1] {
            let t = bucket(&seeds[fill[b]]);
            if t != b {
                seeds.swap(fill[b], fill[t]);
            }
            fill[t] += 1;
        }
    }
    starts
}

/// The seeds of points `range` (module docs, step 3, and "Performance": certified bounds where
/// they exist) and, with the normal test, their windows' normals and how far they may be from
/// the fitted ones (index `i - range.start`).
fn seeds_in(
    range: std::ops::Range<usize>,
    points: &[Point3],
    graph: &Graph<'_>,
    tests: &Tests<'_>,
    with_normals: bool,
) -> (Vec<Seed>, Vec<(Vector3, Real)>) {
    let offset = range.start;
    let mut scratch = SeedScratch::default();
    let mut seeds: Vec<Seed> = Vec::new();
    let mut normals = vec![(Vector3::zeros(), 0.0); if with_normals { range.len() } else { 0 }];
    for i in range {
        if let Some((seed, normal)) = seed_of(i, points, graph, tests, &mut scratch) {
            seeds.push(seed);
            if let Some(slot) = normals.get_mut(i - offset) {
                *slot = normal;
            }
        }
    }
    (seeds, normals)
}

/// Reusable buffers of [`seed_of`].
struct SeedScratch {
    members: [u32; WINDOW_CAPACITY],
    window: Vec<(u32, u32)>,
}

impl Default for SeedScratch {
    fn default() -> Self {
        SeedScratch { members: [0; WINDOW_CAPACITY], window: Vec::new() }
    }
}

/// The seed of point `i` and its window's normal with how far it may be from the fitted one,
/// or `None` if `i` seeds nothing (module docs, step 3).
fn seed_of(
    i: usize,
    points: &[Point3],
    graph: &Graph<'_>,
    tests: &Tests<'_>,
    scratch: &mut SeedScratch,
) -> Option<(Seed, (Vector3, Real))> {
    // Grid windows straight from the pixels; others (k-NN lists, wide windows) as listed.
    let (chained, acc) = match graph.grid_window(i, &mut scratch.members) {
        GridWindow::Members(len, chained) => {
            let members = &scratch.members[..len];
            if chained && let Some(bound) = certified_window_plane(points, members) {
                let seed = Seed::new(bound.curvature_lower, i as u32, false);
                return Some((seed, (bound.normal, bound.normal_error)));
            }
            let acc = PlaneAccumulator::from_points(members.iter().map(|&p| &points[p as usize]));
            (chained, acc)
        }
        GridWindow::Incomplete if matches!(graph, Graph::Grid { .. }) => return None,
        _ => {
            let window = &mut scratch.window;
            let chained = graph.seed_window(i, window)?;
            if !window.iter().all(|&(p, steps)| steps == 0 || tests.linked(i, p as usize, steps)) {
                return None;
            }
            let acc =
                PlaneAccumulator::from_points(window.iter().map(|&(p, _)| &points[p as usize]));
            (chained, acc)
        }
    };
    if chained && let Some(bound) = acc.certified_plane() {
        let seed = Seed::new(bound.curvature_lower, i as u32, false);
        return Some((seed, (bound.normal, bound.normal_error)));
    }
    let fit = acc.fit(&Point3::origin())?;
    if !chained {
        // A window across pixels the plain jump test does not chain seeds only a grazing
        // plane, whose rows lie further apart ([`GrazingPlanes::link_cos`]).
        let stretch = tests.grazing_stretch(&fit)?;
        if !(tests.facing(&fit, true)
            && graph.window_chained(i, |a, b| tests.linked_by(a, b, stretch)))
        {
            return None;
        }
    }
    Some((Seed::new(fit.curvature(), i as u32, true), (fit.plane.normal.into_inner(), 0.0)))
}

/// The lower bound of a window's curvature from its box sums `[n, x, y, z, xx, xy, xz, yy,
/// yz, zz]` (relative to its tile's point), [`curvature_floor`]; `None` when the sums are not
/// precise enough ([`BOX_SUM_MAX_SPREAD`]) or the matrix is not finite.
fn box_sum_curvature_lower(t: &[Real; 10]) -> Option<Real> {
    let sum = Vector3::new(t[1], t[2], t[3]);
    let raw = Matrix3::new(t[4], t[5], t[6], t[5], t[7], t[8], t[6], t[8], t[9]);
    let scatter = raw - (sum / t[0]) * sum.transpose();
    let spread = t[4] + t[7] + t[9];
    if spread.is_nan() || spread > BOX_SUM_MAX_SPREAD * scatter.trace() {
        return None;
    }
    curvature_floor(&scatter)
}

/// A lower bound of the surface variation `λ₀ / (λ₀ + λ₁ + λ₂)` of a scatter matrix, from its
/// invariants alone (no eigenvectors): `det = λ₀ λ₁ λ₂` and the sum of its principal 2 × 2
/// minors `m₂ = λ₀λ₁ + λ₀λ₂ + λ₁λ₂ ≥ λ₁λ₂`, so `λ₀ ≥ det / m₂`. For a flat window
/// (`λ₀ ≪ λ₁`) the bound is within a factor `1 − λ₀ (1/λ₁ + 1/λ₂)` of `λ₀`, as tight as
/// [`certify`](crate::plane_fit::certify)'s at a tenth of its cost; it is the seed order's key
/// of the box-sum windows. The slack covers the rounding of the invariants and the box sums'
/// error ([`BOX_SUM_MAX_SPREAD`]: at most `2 · 9 · 1024 · 60 ε ‖S‖³` in the determinant, below
/// `1e-9 ‖S‖³`) and, like the certified bounds, `1e-10 ‖S‖` for the rounding of the fitted
/// curvature it must not exceed. `None` for a non-finite or zero matrix.
fn curvature_floor(m: &Matrix3<Real>) -> Option<Real> {
    // A bound of the spectral norm (the sum of the entries' magnitudes).
    let norm: Real = m.iter().map(|x| x.abs()).sum();
    let trace = m.trace();
    if !(norm.is_finite() && norm > 0.0 && trace > 0.0) {
        return None;
    }
    let sym = |i: usize, j: usize| 0.5 * (m[(i, j)] + m[(j, i)]);
    let (a, b, c, d, e, f) = (sym(0, 0), sym(0, 1), sym(0, 2), sym(1, 1), sym(1, 2), sym(2, 2));
    let (m1, m2, m3) = (d * f - e * e, a * f - c * c, a * d - b * b);
    let det_lower = a * m1 - b * (b * f - c * e) + c * (b * e - c * d) - 1e-9 * norm * norm * norm;
    let minors_upper = m1 + m2 + m3 + 1e-9 * norm * norm;
    let lambda0_lower = if det_lower > 0.0 && minors_upper > 0.0 {
        det_lower / minors_upper - 1e-10 * norm
    } else {
        0.0
    };
    let total_upper = trace + 3e-10 * norm;
    Some((lambda0_lower / total_upper).max(0.0) * (1.0 - 1e-9))
}

/// Side of the square tiles of window centres in [`seeds_in_rows`], pixels.
const TILE: usize = 32;

/// The largest ratio of a window's squared distances from its tile's reference point to its
/// scatter's trace for which [`seeds_in_rows`] trusts its box sums: the rounding error of the
/// scatter is then below `1024 · 60 ε` of its trace, far inside the `1e-10` slack of the
/// certified bounds ([`crate::plane_fit::certify`]).
const BOX_SUM_MAX_SPREAD: Real = 1024.0;

/// Whether [`seeds_in_rows`] applies: a grid whose seed windows are contiguous (every stride
/// 1, [`SegmentConfig::seed_min_extent`] 0) and at most [`MAX_WINDOW_SPAN`] wide, without the
/// normal test (which keeps every window's normal).
fn box_windows(graph: &Graph<'_>, config: &SegmentConfig) -> bool {
    matches!(graph, Graph::Grid { .. })
        && config.seed_min_extent <= 0.0
        && 2 * (config.seed_radius as usize) < MAX_WINDOW_SPAN
        && config.max_normal_angle.is_none()
}

/// The seeds of the points whose pixels lie in the grid rows `rows` ([`box_windows`] must
/// hold): the seeds of [`seed_of`], with the plane bounds of windows whose pixels are all
/// linked along their rows and columns taken from box sums of the window moments (not in the
/// thesis; the "integral images" of organised plane fitting, as separable sums over tiles of
/// [`TILE`]² centres, relative to a point of the tile so that the sums keep their precision).
/// Any other window, or one whose sums are not precise enough ([`BOX_SUM_MAX_SPREAD`]), goes
/// through [`seed_of`]. The bounds are certified either way, so the segmentation is the same
/// (module docs, "Performance"). Writes the packed seeds ([`Seed`]'s `u128`) to the start of
/// `out`, which has room for one per valid pixel of `rows`; returns how many.
fn seeds_in_rows(
    rows: std::ops::Range<usize>,
    points: &[Point3],
    graph: &Graph<'_>,
    tests: &Tests<'_>,
    out: &mut [u128],
) -> usize {
    let Graph::Grid { grid, seed_radius, row_runs, col_runs, .. } = graph else {
        return 0;
    };
    let (w, h, s) = (grid.width() as usize, grid.height() as usize, *seed_radius as usize);
    let pixels = grid.pixels();
    let mut scratch = SeedScratch::default();
    let mut len = 0;
    let mut push = |seed: Seed| {
        out[len] = seed.0;
        len += 1;
    };
    // Per halo pixel: [1, x, y, z, xx, xy, xz, yy, yz, zz] relative to the tile's reference
    // (zero for invalid pixels); per halo row and centre column: the row's box sums.
    let halo = TILE + 2 * s;
    let mut terms = vec![[0.0; 10]; halo * halo];
    let mut row_sums = vec![[0.0; 10]; halo * TILE];
    let full = ((2 * s + 1) * (2 * s + 1)) as Real;
    for r0 in rows.clone().step_by(TILE) {
        let r1 = (r0 + TILE).min(rows.end);
        for c0 in (0..w).step_by(TILE) {
            let c1 = (c0 + TILE).min(w);
            let (hr0, hr1) = (r0.saturating_sub(s), (r1 + s).min(h));
            let (hc0, hc1) = (c0.saturating_sub(s), (c1 + s).min(w));
            let hw = hc1 - hc0;
            // The reference: the valid pixel nearest the tile's middle along its middle row,
            // else any valid pixel of the halo.
            let middle = ((r0 + r1) / 2) * w;
            let reference = (c0..c1)
                .map(|c| pixels[middle + c])
                .chain((hr0..hr1).flat_map(|r| pixels[r * w + hc0..r * w + hc1].iter().copied()))
                .find(|&p| p != INVALID_PIXEL);
            let Some(reference) = reference else { continue };
            let reference = points[reference as usize].coords;
            for r in hr0..hr1 {
                for c in hc0..hc1 {
                    let p = pixels[r * w + c];
                    terms[(r - hr0) * hw + (c - hc0)] = if p == INVALID_PIXEL {
                        [0.0; 10]
                    } else {
                        let v = points[p as usize].coords - reference;
                        let (x, y, z) = (v.x, v.y, v.z);
                        [1.0, x, y, z, x * x, x * y, x * z, y * y, y * z, z * z]
                    };
                }
            }
            // Centres with their window inside the grid.
            let (cc0, cc1) = (c0.max(s), c1.min(w.saturating_sub(s)));
            let (rc0, rc1) = (r0.max(s), r1.min(h.saturating_sub(s)));
            if cc0 >= cc1 || rc0 >= rc1 {
                continue;
            }
            for r in hr0..hr1 {
                let line = &terms[(r - hr0) * hw..(r - hr0 + 1) * hw];
                for c in cc0..cc1 {
                    let mut sum = [0.0; 10];
                    for t in &line[c - s - hc0..=c + s - hc0] {
                        for k in 0..10 {
                            sum[k] += t[k];
                        }
                    }
                    row_sums[(r - hr0) * TILE + (c - c0)] = sum;
                }
            }
            for r in rc0..rc1 {
                for c in cc0..cc1 {
                    let centre = r * w + c;
                    let i = pixels[centre];
                    if i == INVALID_PIXEL {
                        continue;
                    }
                    let i = i as usize;
                    // Every row of the window one run of links, and every column: the window
                    // is complete and chained (runs are contiguous, and a link needs two valid
                    // pixels).
                    let linked = (r - s..=r + s)
                        .all(|rr| row_runs[rr * w + c - s] == row_runs[rr * w + c + s])
                        && (c - s..=c + s)
                            .all(|cc| col_runs[(r - s) * w + cc] == col_runs[(r + s) * w + cc]);
                    let bound = linked
                        .then(|| {
                            let mut t = [0.0; 10];
                            for rr in r - s..=r + s {
                                let sum = &row_sums[(rr - hr0) * TILE + (c - c0)];
                                for k in 0..10 {
                                    t[k] += sum[k];
                                }
                            }
                            debug_assert_eq!(t[0], full);
                            box_sum_curvature_lower(&t)
                        })
                        .flatten();
                    match bound {
                        Some(lower) => push(Seed::new(lower, i as u32, false)),
                        None => {
                            if let Some((seed, _)) = seed_of(i, points, graph, tests, &mut scratch)
                            {
                                push(seed);
                            }
                        }
                    }
                }
            }
        }
    }
    len
}

/// A region kept by [`grow`]: how many points it took, and their sums.
struct Grown {
    len: usize,
    acc: PlaneAccumulator,
    /// Refused by the bending test: its points go to the remainder.
    bent: bool,
}

fn grow(graph: &Graph<'_>, tests: &Tests<'_>, threads: NonZeroUsize) -> Segmentation {
    grow_counted(graph, tests, threads, true).0
}

/// `f` of each part, in order: the first on this thread, the others on scoped threads of
/// their own (a panic in `f` propagates).
fn in_parts<P: Send, T: Send>(parts: Vec<P>, f: impl Fn(P) -> T + Sync) -> Vec<T> {
    std::thread::scope(|s| {
        let f = &f;
        let mut parts = parts.into_iter();
        let first = parts.next();
        let handles: Vec<_> = parts.map(|p| s.spawn(move || f(p))).collect();
        let mut out: Vec<T> = first.map(f).into_iter().collect();
        out.extend(
            handles.into_iter().map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e))),
        );
        out
    })
}

/// The fewest points per thread for which [`grow`] computes seeds on several threads.
const PARALLEL_SEEDS_MIN: usize = 50_000;

/// [`grow`], and how many times a point was taken by a region (growth work: dissolved
/// regions count again when their points are taken anew).
fn grow_counted(
    graph: &Graph<'_>,
    tests: &Tests<'_>,
    threads: NonZeroUsize,
    box_sums: bool,
) -> (Segmentation, usize) {
    let (points, config) = (tests.points, tests.config);
    let n = points.len();
    let origin = Point3::origin();
    let min_normal_cos = config.max_normal_angle.map_or(-1.0, Real::cos);

    // Seed order: flattest windows first. Most seeds are never tried (their point or window
    // is taken by then), so a window's plane is fitted only when it must be: with certified
    // bounds on its curvature and normal ([`PlaneAccumulator::certified_plane`]) a seed is
    // queued at its curvature's lower bound; when it comes up with its point and window
    // still free, its exact curvature is computed (polished from the bounds, or fitted), and
    // it is tried at once if no other seed comes before that, else queued again at it; the
    // normal test fits a window only when the bound cannot decide it. Taken points stay
    // taken between seeds (a dissolved region frees only the points it took), so a seed
    // skipped early would be skipped at its exact turn too, and seeds are tried in exactly
    // the order of their exact curvatures (ties by index).
    // Per point: its seed window's plane normal (zero without a complete window, which
    // passes the normal test) and how far it may be from the fitted one (0: fitted).
    // Large clouds share the points among `threads` threads; the seeds are ordered below, so
    // the order does not depend on the split.
    let with_normals = config.max_normal_angle.is_some();
    let parts = threads.get().min(n.div_ceil(PARALLEL_SEEDS_MIN)).max(1);
    let (seeds, shares, mut window_normal) = if let Graph::Grid { grid, .. } = graph
        && box_sums
        && box_windows(graph, config)
    {
        // Bands of whole tiles of rows, one per part. The seeds go to one zeroed buffer (its
        // pages are touched only where written) with room for one per valid pixel: each band
        // writes its seeds at the start of its share of it.
        let (w, h) = (grid.width() as usize, grid.height() as usize);
        let band = (h.div_ceil(parts).div_ceil(TILE) * TILE).max(1);
        let rows: Vec<_> = (0..h).step_by(band).map(|r0| r0..(r0 + band).min(h)).collect();
        let room: Vec<usize> = rows
            .iter()
            .map(|r| {
                grid.pixels()[r.start * w..r.end * w]
                    .iter()
                    .filter(|&&p| p != INVALID_PIXEL)
                    .count()
            })
            .collect();
        let mut packed = vec![0u128; room.iter().sum()];
        let mut bands = Vec::with_capacity(rows.len());
        let mut rest = &mut packed[..];
        for (r, &k) in rows.into_iter().zip(&room) {
            let (share, tail) = std::mem::take(&mut rest).split_at_mut(k);
            bands.push((r, share));
            rest = tail;
        }
        let counts = in_parts(bands, |(r, out)| seeds_in_rows(r, points, graph, tests, out));
        let shares = offsets(&room).zip(counts).map(|(start, count)| start..start + count);
        (packed, shares.collect::<Vec<_>>(), Vec::new())
    } else {
        let chunk = n.div_ceil(parts);
        let ranges: Vec<_> = (0..parts).map(|k| k * chunk..((k + 1) * chunk).min(n)).collect();
        let found = in_parts(ranges, |range| seeds_in(range, points, graph, tests, with_normals));
        let (seeds, normals): (Vec<_>, Vec<_>) = found.into_iter().unzip();
        // One share per part, back to back.
        let lens: Vec<usize> = seeds.iter().map(Vec::len).collect();
        let shares: Vec<_> =
            offsets(&lens).zip(&lens).map(|(start, len)| start..start + len).collect();
        let packed: Vec<u128> = seeds.into_iter().flatten().map(|s| s.0).collect();
        (packed, shares, normals.concat())
    };
    let mut window = Vec::new();
    // Flattest first, ties by index (the seeds are distinct: one per point).
    let mut seeds = SeedQueue::new(seeds, &shares);
    // Seeds fitted on the way, by exact curvature.
    let mut fitted: BinaryHeap<Reverse<Seed>> = BinaryHeap::new();
    let mut scratch = Vec::new();

    let mut owner = vec![FREE; n];
    // Points of a region dissolved by the incidence test: free to join other regions, but
    // not tried as seeds again (they would regrow about the same region and fail the same
    // way, once per seed, quadratic in the region's size).
    let mut spent = vec![false; n];
    let mut taken = 0;
    let mut grown: Vec<Grown> = Vec::new();
    let mut queue: Vec<u32> = Vec::new();
    let mut nbrs = Vec::new();
    // The bending test of a grown region (module docs, step 6) decides only whether its
    // points end in the region or in the remainder, not the growth after it (either way they
    // are taken). So on a cloud large enough for several parts it runs on a thread of its
    // own while the growth goes on; the result is the same.
    let is_bent = |region: &[u32], acc: &PlaneAccumulator| {
        config.max_bending.is_some_and(|b| {
            bending(points, region, &tests.sigma, acc)
                .is_some_and(|d| d > CHI2_3_999 && d > region.len() as Real * b * b)
        })
    };
    std::thread::scope(|scope| {
        let (bending_jobs, bending_worker) = if parts > 1 && config.max_bending.is_some() {
            let (jobs, received) =
                std::sync::mpsc::channel::<(usize, Vec<u32>, PlaneAccumulator)>();
            let worker = scope.spawn(move || {
                received.into_iter().map(|(k, region, acc)| (k, is_bent(&region, &acc))).collect()
            });
            (Some(jobs), Some(worker))
        } else {
            (None, None)
        };
        loop {
            let next = seeds.peek(closed(&owner, &spent));
            let from_list = match (next, fitted.peek()) {
                (Some(s), Some(Reverse(f))) => s < *f,
                (Some(_), None) => true,
                (None, Some(_)) => false,
                (None, None) => break,
            };
            let (seed, unfitted) = if let (true, Some(s)) = (from_list, next) {
                seeds.pop();
                (s.point(), !s.fitted())
            } else {
                let Some(Reverse(s)) = fitted.pop() else { break };
                (s.point(), false)
            };
            if owner[seed] != FREE || spent[seed] {
                continue;
            }
            let _ = graph.seed_window(seed, &mut window);
            if window.iter().any(|&(p, _)| owner[p as usize] != FREE) {
                continue;
            }
            let mut acc =
                PlaneAccumulator::from_points(window.iter().map(|&(p, _)| &points[p as usize]));
            let mut fit_now = None;
            if unfitted {
                // Its turn comes now unless another seed comes before its exact curvature; then
                // it waits for its turn (its point and window are checked again then). Most
                // seeds wait and are taken by others, so the curvature comes without the
                // eigendecomposition where the bounds allow.
                let curvature = match acc.polished_curvature() {
                    Some(c) => c,
                    None => {
                        let Some(fit) = acc.fit(&origin) else { continue };
                        fit_now = Some(fit);
                        fit.curvature()
                    }
                };
                let exact = Seed::new(curvature, seed as u32, true);
                if seeds.peek(closed(&owner, &spent)).is_some_and(|s| s < exact)
                    || fitted.peek().is_some_and(|Reverse(f)| *f < exact)
                {
                    fitted.push(Reverse(exact));
                    continue;
                }
            }
            let Some(fit) = fit_now.or_else(|| acc.fit(&origin)) else { continue };
            let mut sum_sigma2: Real =
                window.iter().map(|&(p, _)| tests.sigma.of(p as usize).powi(2)).sum();
            if !tests.mse_ok(fit.mse, sum_sigma2, acc.len())
                || !tests.facing(&fit, true)
                || !window.iter().all(|&(p, _)| tests.near_plane(&fit.plane, p as usize))
            {
                continue;
            }
            let id = grown.len() as u32;
            queue.clear();
            taken += window.len();
            for &(p, _) in &window {
                owner[p as usize] = id;
                queue.push(p);
            }
            let mut plane = fit.plane;
            let mut along = acc.moments_along(&plane.normal);
            let mut next_refit = acc.len() + 1;
            let mut head = 0;
            while head < queue.len() {
                let q = queue[head] as usize;
                head += 1;
                graph.neighbours(q, &mut nbrs);
                for &(m, linked) in &nbrs {
                    let m = m as usize;
                    if owner[m] != FREE
                        || !tests.linked_on(&plane, q, m, linked)
                        || !tests.near_plane(&plane, m)
                        || window_normal.get_mut(m).is_some_and(|w| {
                            let refused = |w: &Vector3| {
                                *w != Vector3::zeros()
                                    && w.dot(&plane.normal).abs() < min_normal_cos
                            };
                            let (normal, error) = *w;
                            if error == 0.0 {
                                return refused(&normal);
                            }
                            let cos = normal.dot(&plane.normal).abs();
                            if cos - error > min_normal_cos + 1e-12 {
                                return false;
                            }
                            if cos + error < min_normal_cos - 1e-12 {
                                return true;
                            }
                            // The bound cannot decide: fit the window.
                            let _ = graph.seed_window(m, &mut scratch);
                            let acc = PlaneAccumulator::from_points(
                                scratch.iter().map(|&(p, _)| &points[p as usize]),
                            );
                            let normal = acc
                                .fit(&origin)
                                .map_or(Vector3::zeros(), |f| f.plane.normal.into_inner());
                            *w = (normal, 0.0);
                            refused(&normal)
                        })
                    {
                        continue;
                    }
                    // The MSE along the plane's normal with `m` added (the Rayleigh quotient
                    // `nᵀ S' n / (n + 1)` from the running sums along the normal).
                    let d = acc.offset_along(&plane.normal, &points[m]);
                    let (a, b) = (along.0 + d, along.1 + d * d);
                    let count = acc.len() + 1;
                    let mse = ((b - a * a / count as Real) / count as Real).max(0.0);
                    let s2 = sum_sigma2 + tests.sigma.of(m).powi(2);
                    if !tests.mse_ok(mse, s2, count) {
                        continue;
                    }
                    acc.add(&points[m]);
                    along = (a, b);
                    sum_sigma2 = s2;
                    owner[m] = id;
                    taken += 1;
                    queue.push(m as u32);
                    if acc.len() >= next_refit {
                        if let Some(f) = acc.fit(&origin) {
                            plane = f.plane;
                            along = acc.moments_along(&plane.normal);
                        }
                        next_refit = acc.len() + (acc.len() / 20).max(1);
                    }
                }
            }
            if queue.len() < config.min_region_size {
                for &p in &queue {
                    owner[p as usize] = FREE;
                }
            } else if !acc.fit(&origin).is_some_and(|f| tests.facing(&f, false)) {
                for &p in &queue {
                    owner[p as usize] = FREE;
                    spent[p as usize] = true;
                }
            } else {
                let bent = match &bending_jobs {
                    Some(jobs) => {
                        // An error means the worker panicked, which its join passes on.
                        let _ = jobs.send((grown.len(), queue.clone(), acc));
                        false
                    }
                    None => is_bent(&queue, &acc),
                };
                grown.push(Grown { len: queue.len(), acc, bent });
            }
        }
        drop(bending_jobs);
        if let Some(worker) = bending_worker {
            let results: Vec<(usize, bool)> =
                worker.join().unwrap_or_else(|e| std::panic::resume_unwind(e));
            for (k, bent) in results {
                grown[k].bent = bent;
            }
        }
    });

    // Each region's points in ascending order, from one pass over the owners (the owner of
    // every point of a grown region is its index in `grown`; dissolved regions freed theirs).
    let mut ascending: Vec<Vec<u32>> = grown.iter().map(|g| Vec::with_capacity(g.len)).collect();
    for (i, &o) in owner.iter().enumerate() {
        if let Some(list) = ascending.get_mut(o as usize) {
            list.push(i as u32);
        }
    }
    let mut regions = Vec::with_capacity(grown.len());
    for (g, pts) in grown.into_iter().zip(ascending) {
        debug_assert_eq!(pts.len(), g.len);
        if g.bent {
            for &p in &pts {
                owner[p as usize] = BENT;
            }
            continue;
        }
        match g.acc.fit(&origin) {
            Some(fit) if tests.facing(&fit, false) => regions.push(region_from_fit(pts, &fit)),
            _ => {
                for &p in &pts {
                    owner[p as usize] = FREE;
                }
            }
        }
    }
    sort_largest_first(&mut regions);
    let remainder = (0..n as u32).filter(|&i| matches!(owner[i as usize], FREE | BENT)).collect();
    (Segmentation { regions, remainder }, taken)
}

/// Where each of slices of lengths `lens` starts when they lie back to back from 0.
fn offsets(lens: &[usize]) -> impl Iterator<Item = usize> + '_ {
    lens.iter().scan(0, |end, len| {
        *end += len;
        Some(*end - len)
    })
}

/// Whether a point is closed to seeds: taken by a region (or bent) or spent.
fn closed<'a>(owner: &'a [u32], spent: &'a [bool]) -> impl Fn(usize) -> bool + 'a {
    |p| owner[p] != FREE || spent[p]
}

/// Largest region first, ties by the smallest point index ([`Segmentation::regions`]' order).
fn sort_largest_first(regions: &mut [PlanarRegion]) {
    regions.sort_by(|a, b| b.points.len().cmp(&a.points.len()).then(a.points[0].cmp(&b.points[0])));
}

fn region_from_fit(points: Vec<u32>, fit: &PlaneFit) -> PlanarRegion {
    PlanarRegion {
        points,
        plane: fit.plane,
        centroid: fit.centroid,
        mse: fit.mse,
        covariance: fit.covariance(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn random(state: &mut u64) -> Real {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        (*state >> 11) as Real / (1u64 << 53) as Real * 2.0 - 1.0
    }

    /// A `w × h` organised frame: pixel (column, row) is `pixel(column, row, state)`, `state`
    /// the [`random`] state started at `seed`.
    fn frame(
        (w, h): (u32, u32),
        seed: u64,
        mut pixel: impl FnMut(u32, u32, &mut u64) -> Option<Point3>,
    ) -> PointCloud {
        let mut state = seed;
        let pixels: Vec<Option<Point3>> = (0..h)
            .flat_map(|row| (0..w).map(move |col| (row, col)))
            .map(|(row, col)| pixel(col, row, &mut state))
            .collect();
        PointCloud::from_pixels(w, h, pixels).unwrap()
    }

    /// The segmentation of `cloud` on one thread, checked to be that on two.
    fn segment_on_one_and_two_threads(cloud: &PointCloud, config: &SegmentConfig) -> Segmentation {
        let one = segment_with_threads(cloud, config, NonZeroUsize::MIN).unwrap();
        let two = segment_with_threads(cloud, config, NonZeroUsize::new(2).unwrap()).unwrap();
        assert_eq!(one, two);
        one
    }

    #[test]
    fn angle_test_agrees_with_atan2() {
        let mut state = 0x853c_49e6_748f_ea9bu64;
        let exact =
            |a: &Vector3, b: &Vector3, needed: Real| a.cross(b).norm().atan2(a.dot(b)) >= needed;
        for k in 0..200_000 {
            let a = Vector3::new(random(&mut state), random(&mut state), random(&mut state))
                * (0.1 + 10.0 * random(&mut state).abs());
            let turn = [1e-4, 1e-2, 0.3, 2.0][k % 4] * random(&mut state);
            let axis = Vector3::new(random(&mut state), random(&mut state), random(&mut state));
            let b = nalgebra::Rotation3::new(axis.normalize() * turn) * a * 1.7;
            let angle = a.cross(&b).norm().atan2(a.dot(&b));
            // Thresholds at the angle itself (to the last bits), near it and far from it.
            let needed = match k % 5 {
                0 => angle,
                1 => angle * (1.0 + 1e-15),
                2 => angle * (1.0 - 1e-12),
                3 => angle * (1.0 + 1e-6),
                _ => random(&mut state).abs() * 3.0,
            };
            let test = AngleTest { needed };
            let (ua, ub) = (a / a.norm(), b / b.norm());
            assert_eq!(test.passes(&a, &b, &ua, &ub), exact(&a, &b, needed), "{k}");
        }
        let zero = Vector3::zeros();
        let nan = zero / zero.norm();
        let a = Vector3::x();
        assert_eq!(AngleTest { needed: 0.1 }.passes(&zero, &a, &nan, &a), exact(&zero, &a, 0.1));
    }

    /// One σ for constant noise is each point's σ; a range whose square overflows, or noise
    /// growing with the range, keeps one per point.
    #[test]
    fn one_sigma_for_constant_noise_is_each_points_sigma() {
        let range = [0.0, 0.5, 3.0, 1e150];
        let constant = RangeNoise { sigma_0: 0.01, sigma_r2: 0.0 };
        let sigmas = Sigmas::new(&constant, &range);
        assert!(matches!(sigmas, Sigmas::Same(_)));
        for (i, &r) in range.iter().enumerate() {
            assert_eq!(sigmas.of(i).to_bits(), constant.sigma(r).to_bits());
        }
        assert!(matches!(Sigmas::new(&constant, &[1.0, 1e200]), Sigmas::Each(_)));
        let growing = RangeNoise { sigma_0: 0.0012, sigma_r2: 0.0019 };
        let sigmas = Sigmas::new(&growing, &range);
        assert!(matches!(sigmas, Sigmas::Each(_)));
        for (i, &r) in range.iter().enumerate() {
            assert_eq!(sigmas.of(i).to_bits(), growing.sigma(r).to_bits());
        }
    }

    #[test]
    fn total_order_key_orders_as_total_cmp() {
        let values = [
            Real::NEG_INFINITY,
            -1.0,
            -Real::MIN_POSITIVE,
            -0.0,
            0.0,
            Real::MIN_POSITIVE,
            1e-300,
            0.5,
            1.0,
            Real::INFINITY,
            Real::NAN,
        ];
        for a in values {
            for b in values {
                assert_eq!(total_order_key(a).cmp(&total_order_key(b)), a.total_cmp(&b));
            }
        }
    }

    /// A floor tilted 12° sideways, seen grazingly from 0.5 m above it: seed windows pass
    /// the incidence test (their tilt limit is 15°) but the grown region does not (8°).
    /// Each point is taken a bounded number of times, not once per seed inside the region.
    #[test]
    fn a_region_refused_by_the_incidence_test_is_not_regrown_from_each_of_its_seeds() {
        let (w, h) = (120u32, 60u32);
        let tilt = 12f64.to_radians().tan();
        let pixels = (0..h).flat_map(|row| {
            (0..w).map(move |col| {
                let x = 3.0 + 5.0 * Real::from(col) / Real::from(w - 1);
                let y = -1.5 + 3.0 * Real::from(row) / Real::from(h - 1);
                Some(Point3::new(x, y, -0.5 + tilt * y))
            })
        });
        let cloud = PointCloud::from_pixels(w, h, pixels).unwrap();
        let config = SegmentConfig::alrf();
        let tests = Tests::new(cloud.positions(), &config, up(&cloud));
        let graph = Graph::grid(cloud.grid().unwrap(), &tests);
        let (seg, taken) = grow_counted(&graph, &tests, NonZeroUsize::MIN, true);
        let n = cloud.len();
        assert!(seg.regions.is_empty(), "{} regions", seg.regions.len());
        assert_eq!(seg.remainder.len(), n);
        assert!(taken <= 2 * n, "{taken} points taken for {n} points");
    }

    /// The segmentation with and without box sums of the seed windows, one thread and two.
    fn assert_box_sums_agree(cloud: &PointCloud, config: &SegmentConfig) {
        let tests = Tests::new(cloud.positions(), config, up(cloud));
        let graph = Graph::grid(cloud.grid().unwrap(), &tests);
        assert!(box_windows(&graph, config));
        let run = |threads: usize, box_sums: bool| {
            let threads = NonZeroUsize::new(threads).unwrap();
            grow_counted(&graph, &tests, threads, box_sums).0
        };
        let reference = run(1, false);
        assert!(!reference.regions.is_empty());
        assert_eq!(run(1, true), reference);
        assert_eq!(run(2, true), reference);
    }

    /// Box sums give the segmentation of per-window sums, bit for bit: on simulated
    /// range-camera frames of the lab (3×3 and 5×5 windows), and on a synthetic frame of
    /// staggered noisy planes far from the sensor with holes and depth jumps, whose tiles
    /// straddle the jumps (the spread guard sends their windows to the per-window path).
    #[test]
    fn box_sums_of_seed_windows_give_the_segmentation_of_per_window_sums() {
        use scene_sim::{RangeCamera, RangeCameraConfig, RangeSensor as _};
        let scene = scene_sim::scene_by_name("lab", 0).unwrap();
        let camera = RangeCamera::new(RangeCameraConfig {
            width: 320,
            height: 240,
            ..RangeCameraConfig::swissranger_sr3000()
        })
        .unwrap();
        for (k, body) in scene.scan_poses(2, 1.0, 0).into_iter().enumerate() {
            let cloud = camera.scan(&scene, &body, k as u64).to_cloud().unwrap();
            assert_box_sums_agree(&cloud, &SegmentConfig::range_camera());
            assert_box_sums_agree(&cloud, &SegmentConfig::structured_light());
        }

        let cloud = frame((200, 150), 0x9e37_79b9_7f4a_7c15, |col, row, state| {
            let noise = 0.002 * random(state);
            if random(state) > 0.995 {
                return None;
            }
            // Columns in bands of 25 at depths 40 m apart, rows tilted.
            let band = Real::from(col / 25);
            let (x, y) = (Real::from(col) * 0.01, Real::from(row) * 0.01);
            Some(Point3::new(x, y, 500.0 + 40.0 * band + 0.2 * y + noise))
        });
        let config = SegmentConfig {
            noise: RangeNoise { sigma_0: 0.002, sigma_r2: 0.0 },
            jump_absolute: 0.05,
            jump_relative: 0.0,
            ..SegmentConfig::range_camera()
        };
        assert_box_sums_agree(&cloud, &config);
    }

    /// A bent region goes to the remainder whether its bending test runs at once (one
    /// thread) or beside the growth (two): a flat half and a curved half of a frame large
    /// enough for two parts, a metre apart in depth.
    #[test]
    fn the_bending_test_beside_the_growth_gives_the_same_segmentation() {
        let (w, h) = (400u32, 300u32);
        let cloud = frame((w, h), 0x1234_5678_9abc_def1, |col, row, state| {
            let (x, y) = (Real::from(col) * 0.005 - 1.0, Real::from(row) * 0.005 - 0.75);
            let z = if col < w / 2 { 3.0 } else { 4.0 + 0.1 * (x - 0.5).powi(2) };
            Some(Point3::new(x, y, z + 0.002 * random(state)))
        });
        let one = segment_on_one_and_two_threads(&cloud, &SegmentConfig::range_camera());
        // The flat half is a region; the curved half is grown, refused as bent, and left over.
        let half = (w * h / 2) as usize;
        assert!(one.regions.iter().any(|r| r.points.len() > half * 9 / 10));
        let curved_left = one.remainder.iter().filter(|&&i| i % w >= w / 2).count();
        assert!(curved_left > half * 9 / 10, "{curved_left} curved points in the remainder");
    }

    /// A frame whose lower half has no valid pixel, large enough for two seed threads: the
    /// second band has no room for seeds and finds none, and the result is that of one
    /// thread.
    #[test]
    fn a_seed_band_without_valid_pixels_gives_the_segmentation_of_one_thread() {
        let h = 480;
        let cloud = frame((500, h), 0x0f1e_2d3c_4b5a_6978, |col, row, state| {
            let (x, y) = (Real::from(col) * 0.005 - 1.25, Real::from(row) * 0.005 - 0.6);
            (row < h / 2).then(|| Point3::new(x, y, 3.0 + 0.2 * y + 0.002 * random(state)))
        });
        assert!(cloud.len() >= 2 * PARALLEL_SEEDS_MIN);
        let one = segment_on_one_and_two_threads(&cloud, &SegmentConfig::range_camera());
        assert_eq!(one.regions.len(), 1);
    }

    /// The curvature floor of windows whose bounds fail is at most the fitted curvature.
    #[test]
    fn curvature_floors_are_below_the_fit() {
        let mut state = 0x6a09_e667_f3bc_c909u64;
        let (mut floors, mut tight) = (0, 0);
        for k in 0..20_000 {
            let (noise, stretch) = ([1.0, 0.5, 0.1, 1e-3][k % 4], [1.0, 0.3, 0.01][(k / 4) % 3]);
            let shift = Vector3::new(random(&mut state), random(&mut state), random(&mut state));
            let points: Vec<Point3> = (0..3 + k % 30)
                .map(|_| {
                    let p = Vector3::new(
                        random(&mut state),
                        random(&mut state) * stretch,
                        random(&mut state) * noise,
                    );
                    Point3::from(p + shift * 10.0)
                })
                .collect();
            let acc = PlaneAccumulator::from_points(&points);
            let (Some(m), Some(fit)) = (acc.scatter(), acc.fit(&Point3::origin())) else {
                continue;
            };
            let floor = curvature_floor(&m).expect("a finite non-zero scatter");
            assert!(floor <= fit.curvature(), "{k}: {floor} > {}", fit.curvature());
            floors += usize::from(floor > 0.0);
            tight += usize::from(floor >= 0.99 * fit.curvature() && fit.curvature() < 1e-3);
        }
        assert!(floors > 1000, "{floors} positive floors");
        // Flat windows' floors are within 1 % of their curvature.
        assert!(tight > 1000, "{tight} tight floors");
    }

    /// The seed queue gives `sort_unstable`'s order (ties of curvature keys, keys that share
    /// bits, one bucket or many, one share or several, with gaps between them), and drops
    /// exactly the closed seeds.
    #[test]
    fn the_seed_queue_gives_the_sorted_order_of_open_seeds() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for (n, distinct) in [(0usize, 1u64), (1, 1), (5000, 3), (20_000, 1000), (70_000, u64::MAX)]
        {
            let seeds: Vec<Seed> = (0..n)
                .map(|i| {
                    let c = (random(&mut state).abs() * distinct as Real).floor() * 1e-3;
                    Seed::new(c, ((i * 7919) % n) as u32, random(&mut state) > 0.0)
                })
                .collect();
            for (parts, closed) in [(1, false), (3, false), (2, true)] {
                // The shares in a buffer with a gap of zeros before each.
                let chunk = n.div_ceil(parts).max(1);
                let (mut packed, mut shares) = (Vec::new(), Vec::new());
                for part in seeds.chunks(chunk) {
                    packed.extend([0, 0]);
                    shares.push(packed.len()..packed.len() + part.len());
                    packed.extend(part.iter().map(|s| s.0));
                }
                let mut queue = SeedQueue::new(packed, &shares);
                // Closed: every third point.
                let is_closed = |p: usize| closed && p.is_multiple_of(3);
                let mut expected: Vec<Seed> =
                    seeds.iter().copied().filter(|s| !is_closed(s.point())).collect();
                expected.sort_unstable();
                let mut got = Vec::new();
                while let Some(s) = queue.peek(is_closed) {
                    got.push(s);
                    queue.pop();
                }
                assert_eq!(got, expected, "{n} seeds, {parts} shares, closed {closed}");
            }
        }
    }
}
