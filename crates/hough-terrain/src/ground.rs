//! Per-point ground segmentation: for each point of a frame, whether it lies on drivable ground.
//! Not in the thesis; it applies the thesis's passability limits (Rugbot passes steps up to
//! 0.2 m and slopes up to 35°, L3453–3460, [`RobotLimits`]) point by point instead of per frame.
//!
//! # The rule
//!
//! 1. **Level** the points with the sensor's mount ([`SensorMount`], given or from
//!    [`crate::estimate_mount`]): heights are measured up from the sensor, the nominal ground is
//!    the plane `z = −height`.
//! 2. **Polar grid** (rings × sectors) around the sensor in the levelled frame: rings are
//!    [`GroundSettings::min_cell`] wide near the sensor and grow to
//!    [`GroundSettings::cell_growth`] times their range further out; each ring has as many
//!    sectors as makes its cells about square. Azimuth is the *diamond angle* (a monotone
//!    stand-in for `atan2` that needs no trigonometry), so sectors are equal in it, not in
//!    degrees. Organised and unorganised clouds, 360° lidar scans and camera frames all fall
//!    into the same grid.
//! 3. **Local plane per cell** (with at least [`GroundSettings::min_points`] points): the mean
//!    height of the lowest points ([`GroundSettings::seed_points`], at most a quarter of the
//!    cell), the points within the seed band above it ([`GroundSettings::seed_band`], at most
//!    [`GroundSettings::seed_band_per_width`] of the ring's width) as seeds, a least-squares
//!    plane through them (PCA: the covariance's smallest eigenvector, nalgebra's
//!    `SymmetricEigen`), refitted [`GroundSettings::fit_iterations`] times to the points within
//!    its band. The **band** is [`GroundSettings::band_sigmas`] times the rms distance of the
//!    points *below* the plane (what stands on the ground lies above it and must not widen the
//!    band), at least [`GroundSettings::min_band`] and [`GroundSettings::band_per_width`] of the
//!    ring's width, at most [`GroundSettings::max_band`].
//! 4. **Candidates**: a plane whose normal is within the robot's slope limit of vertical, whose
//!    points spread across the cell ([`GroundSettings::min_spread`], not one scan line) and which
//!    is not rough and raised at once (seed rms above [`GroundSettings::max_roughness`] and
//!    more than [`GroundSettings::rough_height`] above the nominal ground: bushes, the top of a
//!    hedge).
//! 5. **Accept by growing** from the candidates that pass within [`GroundSettings::seed_step`]
//!    of the nominal ground: a candidate next to accepted ground (the neighbouring sectors, the
//!    overlapping cells of the neighbouring rings, or across up to
//!    [`GroundSettings::max_gap_rings`] rings without any candidate) is ground if the two planes,
//!    each evaluated where its own cell ends towards the other, differ by at most the robot's
//!    step limit plus [`GroundSettings::grade`] per metre between those ends. So ground is what
//!    the robot could reach over passable steps and slopes: a step of more than 0.2 m and what
//!    lies beyond it is not ground, nor is a ramp steeper than 35°, a table top, a car roof or a
//!    ceiling, while a curb and the sidewalk behind it are.
//! 6. **Label**: a point is ground if it lies within the band of its cell's accepted plane or
//!    of the nearest accepted plane inwards (so both sides of a passable step inside one cell
//!    are ground; a cell with too few points or a rejected plane, such as a wall with a little
//!    ground at its foot, is labelled by that plane alone, its band narrowed by
//!    [`GroundSettings::reference_band`], or by the nominal ground with
//!    [`GroundSettings::max_band`] when there is none).
//!
//! The defaults were chosen on simulated frames (range camera and laser scanner, scene seed 1)
//! and on the one labelled SemanticKITTI scan (the roughness rule, the band per width); see
//! docs/terrain.md for the figures on other seeds.
//!
//! # Performance
//!
//! Linear in the points (one levelling pass, a counting sort into cells, a few passes per cell)
//! plus a 3 × 3 eigen-decomposition per cell and fit; [`GroundSegmenter`] keeps its buffers, so
//! a frame allocates nothing once the buffers have grown to the largest frame.

use crate::classify::RobotLimits;
use crate::error::{HoughError, Result};
use crate::mount::SensorMount;
use nalgebra::{Matrix3, Point3, SymmetricEigen, Vector3};

/// How [`GroundSegmenter`] decides. `Default` suits spinning lidar on a car (KITTI's
/// HDL-64E, an Ouster) as well as range and stereo cameras on a small robot.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct GroundSettings {
    /// The robot's step and slope limits (default Rugbot's: 0.2 m, 35°, thesis L3453–3460).
    pub limits: RobotLimits,
    /// Points nearer than this horizontal range are never ground, metres (default 0).
    pub min_range: f64,
    /// Points beyond this horizontal range are never ground, metres (default 80).
    pub max_range: f64,
    /// The width of the innermost rings, metres (default 0.25).
    pub min_cell: f64,
    /// Further out a ring is this share of its inner range wide (default 0.12), and its cells
    /// as long along the ring.
    pub cell_growth: f64,
    /// A cell needs this many points for a plane of its own (default 5).
    pub min_points: usize,
    /// The mean of the lowest this many points of a cell (at most a quarter of them) is its
    /// seed height (default 20).
    pub seed_points: usize,
    /// Seeds are the points up to this far above the seed height, metres (default 0.15)...
    pub seed_band: f64,
    /// ...but at most this share of the ring's width (default 0.4): in small cells near a
    /// small robot's camera a wide seed band reaches up walls and box sides.
    pub seed_band_per_width: f64,
    /// A plane's points must spread across the cell, not along one line (a single scan line
    /// far out): the standard deviation across their main direction at least this share of the
    /// ring's width (default 0.05). Otherwise the cell is labelled by the plane inwards.
    pub min_spread: f64,
    /// A cell whose seeds lie farther than this from their plane (rms, metres) is rough, not
    /// ground: bushes, rubble, the top of a crowd (default 0.03)...
    pub max_roughness: f64,
    /// ...if it lies more than this above the nominal ground, metres (default 0.2).
    pub rough_height: f64,
    /// Refits of the plane to the points within its band (default 1).
    pub fit_iterations: usize,
    /// The band's residual counts the points up to this far below the plane, metres (default
    /// 0.125).
    pub fit_band: f64,
    /// The band is this many times the rms distance of the points below the plane (default
    /// 3)...
    pub band_sigmas: f64,
    /// ...at least this, metres (default 0.02)...
    pub min_band: f64,
    /// ...and at most this, metres (default 0.15).
    pub max_band: f64,
    /// ...but at least this share of the ring's width (default 0.08): a plane fitted over a
    /// larger cell misses curved ground by more.
    pub band_per_width: f64,
    /// A point in a cell without an accepted plane of its own is labelled by the plane inwards
    /// with this share of that plane's band (default 1). Less trims the foot of walls and boxes
    /// in camera frames (0.5: simulated F1 .982 → .986 on seed 1) but loses floor next to them
    /// where the plane inwards is tilted.
    pub reference_band: f64,
    /// Growing starts from the cells whose plane passes within this height of the nominal
    /// ground at their centre, metres (default 0.2, the step limit).
    pub seed_step: f64,
    /// The allowed height difference between two cells grows by this per metre between their
    /// ends (default 0.02), so that gently curved ground stays ground across gaps.
    pub grade: f64,
    /// Growing jumps over at most this many rings without a candidate, and the labels look this
    /// many rings inwards for a plane (default 8).
    pub max_gap_rings: usize,
}

impl Default for GroundSettings {
    fn default() -> Self {
        GroundSettings {
            limits: RobotLimits::rugbot(),
            min_range: 0.0,
            max_range: 80.0,
            min_cell: 0.25,
            cell_growth: 0.12,
            min_points: 5,
            seed_points: 20,
            seed_band: 0.15,
            seed_band_per_width: 0.4,
            min_spread: 0.05,
            max_roughness: 0.03,
            rough_height: 0.2,
            fit_iterations: 1,
            fit_band: 0.125,
            band_sigmas: 3.0,
            min_band: 0.02,
            max_band: 0.15,
            band_per_width: 0.08,
            seed_step: 0.2,
            reference_band: 1.0,
            grade: 0.02,
            max_gap_rings: 8,
        }
    }
}

/// At most this many cells in the polar grid.
const MAX_CELLS: usize = 1 << 20;

impl GroundSettings {
    /// Checks every field's domain.
    ///
    /// # Errors
    /// [`HoughError::BadParameter`] naming the first field out of its domain.
    pub fn validate(&self) -> Result<()> {
        let bad =
            |what, value: f64, allowed| Err(HoughError::BadParameter { what, value, allowed });
        let l = &self.limits;
        if !(l.max_step.is_finite() && l.max_step >= 0.0) {
            return bad("max step", l.max_step, "finite, ≥ 0 m");
        }
        if !(l.max_slope.is_finite() && l.max_slope >= 0.0 && l.max_slope < 90f64.to_radians()) {
            return bad("max slope", l.max_slope, "[0°, 90°)");
        }
        if !(self.min_range.is_finite() && self.min_range >= 0.0) {
            return bad("min range", self.min_range, "finite, ≥ 0 m");
        }
        if !(self.max_range.is_finite() && self.max_range > self.min_range) {
            return bad("max range", self.max_range, "finite, above min range");
        }
        if !(self.min_cell.is_finite() && self.min_cell > 0.0) {
            return bad("min cell", self.min_cell, "finite, > 0 m");
        }
        if !(self.cell_growth.is_finite() && self.cell_growth > 0.0 && self.cell_growth <= 2.0) {
            return bad("cell growth", self.cell_growth, "(0, 2]");
        }
        if self.min_points < 3 {
            return bad("min points", self.min_points as f64, "at least 3 (a plane)");
        }
        if self.seed_points == 0 {
            return bad("seed points", 0.0, "at least 1");
        }
        for (what, v) in [
            ("seed band", self.seed_band),
            ("fit band", self.fit_band),
            ("band sigmas", self.band_sigmas),
            ("min band", self.min_band),
            ("seed band per width", self.seed_band_per_width),
            ("band per width", self.band_per_width),
            ("min spread", self.min_spread),
            ("max roughness", self.max_roughness),
            ("grade", self.grade),
            ("seed step", self.seed_step),
            ("reference band", self.reference_band),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(what, v, "finite, ≥ 0");
            }
        }
        if !(self.max_band.is_finite() && self.max_band >= self.min_band) {
            return bad("max band", self.max_band, "finite, ≥ min band");
        }
        if self.fit_iterations > 100 {
            return bad("fit iterations", self.fit_iterations as f64, "at most 100");
        }
        Ok(())
    }
}

/// What one call of [`GroundSegmenter::segment`] found.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct GroundSummary {
    /// Points in the frame.
    pub points: usize,
    /// Points labelled ground.
    pub ground: usize,
    /// Cells of the polar grid holding at least [`GroundSettings::min_points`] points.
    pub cells: usize,
    /// Of those, cells whose plane was accepted as ground.
    pub ground_cells: usize,
}

/// A cell's plane `n · p = d` in the levelled z-up frame (`n.z > 0`), its label band and the
/// centre of its points.
#[derive(Copy, Clone, Debug)]
struct CellPlane {
    n: Vector3<f64>,
    d: f64,
    band: f64,
    cx: f64,
    cy: f64,
    /// The spread across the points' main direction (square root of the middle eigenvalue).
    spread: f64,
    /// The rms distance of the fitted points from the plane (square root of the smallest
    /// eigenvalue).
    roughness: f64,
    /// Half the width of the cell's ring: how far from the centre the plane is supported.
    reach: f64,
}

impl CellPlane {
    /// The plane's height at (x, y).
    #[inline]
    fn height_at(&self, x: f64, y: f64) -> f64 {
        (self.d - self.n.x * x - self.n.y * y) / self.n.z
    }

    #[inline]
    fn distance(&self, p: &[f64; 3]) -> f64 {
        self.n.x * p[0] + self.n.y * p[1] + self.n.z * p[2] - self.d
    }
}

/// The rings and sectors, fixed by the settings.
#[derive(Clone, Debug)]
struct PolarGrid {
    /// Ring edges (horizontal range), `rings + 1` values from `min_range` to `max_range`.
    edges: Vec<f64>,
    /// Sectors of each ring.
    sectors: Vec<u32>,
    /// Index of each ring's first cell; one more entry with the number of cells.
    first: Vec<u32>,
    /// The ring of each cell.
    ring_of: Vec<u32>,
    /// The ring lookup by range: entry `i` covers [i, i + 1) · lut_step.
    lut: Vec<LutEntry>,
    /// LUT entries per metre.
    lut_scale: f64,
}

/// One bucket of the ring lookup: the ring (first cell, sectors) below `next`, and the one from
/// `next` on.
#[derive(Copy, Clone, Debug)]
struct LutEntry {
    next: f64,
    lo: [u32; 2],
    hi: [u32; 2],
}

/// The diamond angle of (x, y) in [0, 4): monotone in the azimuth, no trigonometry.
#[inline]
fn diamond_angle(x: f64, y: f64) -> f64 {
    let s = x.abs() + y.abs();
    if s == 0.0 {
        return 0.0;
    }
    if y >= 0.0 {
        if x >= 0.0 { y / s } else { 1.0 - x / s }
    } else if x < 0.0 {
        2.0 - y / s
    } else {
        3.0 + x / s
    }
}

impl PolarGrid {
    fn new(s: &GroundSettings) -> Result<PolarGrid> {
        let mut edges = vec![s.min_range];
        let mut r = s.min_range;
        while r < s.max_range {
            r = (r + s.min_cell.max(s.cell_growth * r)).min(s.max_range);
            edges.push(r);
            if edges.len() > 100_000 {
                return Err(HoughError::TooManyBins {
                    what: "ground rings",
                    bins: edges.len() as u64,
                    limit: 100_000,
                });
            }
        }
        let mut sectors = Vec::with_capacity(edges.len() - 1);
        let mut first = vec![0u32];
        let mut cells = 0usize;
        for k in 0..edges.len() - 1 {
            let width = edges[k + 1] - edges[k];
            let mid = 0.5 * (edges[k] + edges[k + 1]);
            let n = ((std::f64::consts::TAU * mid / width).ceil() as usize).clamp(4, 4096);
            cells += n;
            if cells > MAX_CELLS {
                return Err(HoughError::TooManyBins {
                    what: "ground cells",
                    bins: cells as u64,
                    limit: MAX_CELLS as u64,
                });
            }
            sectors.push(n as u32);
            first.push(cells as u32);
        }
        let lut_step = s.min_cell.min(s.max_range / 4096.0);
        let lut_len = (s.max_range / lut_step).ceil() as usize + 1;
        let mut lut = Vec::with_capacity(lut_len);
        let mut ring = 0usize;
        for i in 0..lut_len {
            let r = i as f64 * lut_step;
            while ring + 1 < sectors.len() && edges[ring + 1] <= r {
                ring += 1;
            }
            // Rings are at least `lut_step` wide: a bucket reaches at most into the next one.
            let hi = (ring + 1).min(sectors.len() - 1);
            lut.push(LutEntry {
                next: edges[ring + 1],
                lo: [first[ring], sectors[ring]],
                hi: [first[hi], sectors[hi]],
            });
        }
        let ring_of = (0..sectors.len())
            .flat_map(|k| std::iter::repeat_n(k as u32, sectors[k] as usize))
            .collect();
        Ok(PolarGrid { edges, sectors, first, ring_of, lut, lut_scale: 1.0 / lut_step })
    }

    fn rings(&self) -> usize {
        self.sectors.len()
    }

    fn cells(&self) -> usize {
        self.first[self.rings()] as usize
    }

    /// The cell of a point at horizontal range `r` and diamond angle `a`, if within range.
    #[inline]
    fn cell(&self, r: f64, a: f64) -> Option<u32> {
        if r < self.edges[0] || r >= self.edges[self.rings()] {
            return None;
        }
        let e = &self.lut[((r * self.lut_scale) as usize).min(self.lut.len() - 1)];
        let [first, n] = if r < e.next { e.lo } else { e.hi };
        Some(first + ((a * 0.25 * n as f64) as u32).min(n - 1))
    }

    #[inline]
    fn sector(&self, ring: usize, a: f64) -> u32 {
        let n = self.sectors[ring];
        ((a * 0.25 * n as f64) as u32).min(n - 1)
    }
}

/// Labels each point of a frame as drivable ground or not (see the [module docs](self)).
/// Prepare once per settings; [`GroundSegmenter::segment`] reuses the buffers.
///
/// ```
/// use hough_terrain::{GroundSegmenter, GroundSettings, SensorAxes, SensorMount};
/// use nalgebra::Point3;
///
/// // A lidar 1.7 m above a flat road (x forward, y left, z up), with a box 2 m tall at 6 m.
/// let mut points: Vec<Point3<f64>> = (0..4000)
///     .map(|i| {
///         let (r, a) = (3.0 + (i / 100) as f64 * 0.3, (i % 100) as f64 * 0.0628);
///         Point3::new(r * a.cos(), r * a.sin(), -1.7)
///     })
///     .collect();
/// points.extend((0..200).map(|i| Point3::new(6.0, (i % 20) as f64 * 0.05, -1.6 + (i / 20) as f64 * 0.2)));
/// let mount = SensorMount::looking_ahead(1.7, 0.0, 0.0, SensorAxes::Body)?;
/// let mut segmenter = GroundSegmenter::new(GroundSettings::default())?;
/// let mut ground = Vec::new();
/// let summary = segmenter.segment(&points, &mount, &mut ground)?;
/// let road = ground[..4000].iter().filter(|&&g| g).count();
/// assert!(road >= 3980, "{road}"); // the road (a few points right behind the box are missed)
/// assert!(ground[4000..].iter().filter(|&&g| g).count() <= 20); // the box's foot at most
/// assert_eq!(summary.ground, ground.iter().filter(|&&g| g).count());
/// # Ok::<(), hough_terrain::HoughError>(())
/// ```
#[derive(Clone, Debug)]
pub struct GroundSegmenter {
    settings: GroundSettings,
    grid: PolarGrid,
    /// Cell of each input point (`u32::MAX`: outside the grid).
    cell_of: Vec<u32>,
    /// Start of each cell's run in `order` (`cells + 1` entries).
    start: Vec<u32>,
    /// Input indices sorted by cell.
    order: Vec<u32>,
    /// The points in `order`.
    sorted: Vec<[f64; 3]>,
    /// Scratch heights for the seed selection.
    heights: Vec<f64>,
    /// Next free slot of each cell during the counting sort.
    cursor: Vec<u32>,
    /// Each cell's accepted plane.
    planes: Vec<Option<CellPlane>>,
    /// Each cell's plane within the slope limit, accepted or not.
    candidates: Vec<Option<CellPlane>>,
    /// Accepted cells, in the order the growing reached them.
    queue: Vec<u32>,
}

impl GroundSegmenter {
    /// A segmenter with `settings`.
    ///
    /// # Errors
    /// A setting out of its domain ([`GroundSettings::validate`]) or a grid of more than a
    /// million cells.
    pub fn new(settings: GroundSettings) -> Result<GroundSegmenter> {
        settings.validate()?;
        let grid = PolarGrid::new(&settings)?;
        let cells = grid.cells();
        Ok(GroundSegmenter {
            settings,
            grid,
            cell_of: Vec::new(),
            start: vec![0; cells + 1],
            order: Vec::new(),
            sorted: Vec::new(),
            heights: Vec::new(),
            cursor: Vec::new(),
            planes: vec![None; cells],
            candidates: vec![None; cells],
            queue: Vec::new(),
        })
    }

    /// The settings.
    pub fn settings(&self) -> &GroundSettings {
        &self.settings
    }

    /// The number of rings and of cells of the polar grid.
    pub fn grid_size(&self) -> (usize, usize) {
        (self.grid.rings(), self.grid.cells())
    }

    /// Labels `points` (in the sensor's frame, `mount` levelling them): `ground[i]` says
    /// whether point `i` is drivable ground. `ground` is cleared and refilled.
    ///
    /// # Errors
    /// [`HoughError::EmptyCloud`] for no points, [`HoughError::NonFinitePoint`] for a NaN or
    /// infinite coordinate, [`HoughError::TooManyBins`] for more than `u32::MAX` points.
    pub fn segment(
        &mut self,
        points: &[Point3<f64>],
        mount: &SensorMount,
        ground: &mut Vec<bool>,
    ) -> Result<GroundSummary> {
        if points.is_empty() {
            return Err(HoughError::EmptyCloud);
        }
        if points.len() >= u32::MAX as usize {
            return Err(HoughError::TooManyBins {
                what: "ground points",
                bins: points.len() as u64,
                limit: u32::MAX as u64 - 1,
            });
        }
        if let Some(index) = points.iter().position(|p| !p.coords.iter().all(|c| c.is_finite())) {
            return Err(HoughError::NonFinitePoint { index });
        }
        self.bin(points, mount);
        let (cells, ground_cells) = self.fit_cells(mount.height());
        ground.clear();
        ground.resize(points.len(), false);
        let count = self.label(mount.height(), ground);
        Ok(GroundSummary { points: points.len(), ground: count, cells, ground_cells })
    }

    /// Levels the points and sorts them into cells.
    fn bin(&mut self, points: &[Point3<f64>], mount: &SensorMount) {
        let m = mount.levelled_from_sensor();
        // Levelled axes are x forward, y right, z down; keep x, flip y and z for z up.
        let rows = [
            [m[(0, 0)], m[(0, 1)], m[(0, 2)]],
            [-m[(1, 0)], -m[(1, 1)], -m[(1, 2)]],
            [-m[(2, 0)], -m[(2, 1)], -m[(2, 2)]],
        ];
        let level = |p: &Point3<f64>| rows.map(|r| r[0] * p.x + r[1] * p.y + r[2] * p.z);
        self.cell_of.clear();
        self.start.iter_mut().for_each(|s| *s = 0);
        for p in points {
            let q = level(p);
            let r = (q[0] * q[0] + q[1] * q[1]).sqrt();
            let c = self.grid.cell(r, diamond_angle(q[0], q[1])).unwrap_or(u32::MAX);
            if c != u32::MAX {
                self.start[c as usize + 1] += 1;
            }
            self.cell_of.push(c);
        }
        for i in 1..self.start.len() {
            self.start[i] += self.start[i - 1];
        }
        // Every slot below is overwritten: resize without clearing.
        let inside = *self.start.last().unwrap_or(&0) as usize;
        self.order.resize(inside, 0);
        self.sorted.resize(inside, [0.0; 3]);
        self.cursor.clear();
        self.cursor.extend_from_slice(&self.start[..self.start.len() - 1]);
        for (i, (&c, p)) in self.cell_of.iter().zip(points).enumerate() {
            if c != u32::MAX {
                let slot = self.cursor[c as usize] as usize;
                self.cursor[c as usize] += 1;
                self.order[slot] = i as u32;
                self.sorted[slot] = level(p);
            }
        }
    }

    /// Fits each cell's plane, then accepts ground by growing from the cells on the nominal
    /// ground: (cells with enough points, accepted cells).
    fn fit_cells(&mut self, height: f64) -> (usize, usize) {
        let s = self.settings;
        let cos_max = s.limits.max_slope.cos();
        let mut cells = 0;
        self.queue.clear();
        for ring in 0..self.grid.rings() {
            let width = self.grid.edges[ring + 1] - self.grid.edges[ring];
            for sector in 0..self.grid.sectors[ring] {
                let c = (self.grid.first[ring] + sector) as usize;
                self.planes[c] = None;
                self.candidates[c] = None;
                let (a, b) = (self.start[c] as usize, self.start[c + 1] as usize);
                if b - a < s.min_points {
                    continue;
                }
                cells += 1;
                let points = &self.sorted[a..b];
                self.heights.clear();
                self.heights.extend(points.iter().map(|p| p[2]));
                let k = s.seed_points.min(points.len() / 4).max(1);
                self.heights.select_nth_unstable_by(k - 1, f64::total_cmp);
                let seed = self.heights[..k].iter().sum::<f64>() / k as f64;
                let seed_band = s.seed_band.min(s.seed_band_per_width * width);
                let Some(mut plane) = fit(points, &s, |p| p[2] <= seed + seed_band) else {
                    continue;
                };
                let roughness = plane.roughness;
                for _ in 0..s.fit_iterations {
                    let band = lower_band(points, &plane, &s);
                    match fit(points, &s, |p| plane.distance(p).abs() <= band) {
                        Some(p) => plane = p,
                        None => break,
                    }
                }
                plane.band =
                    lower_band(points, &plane, &s).max(s.band_per_width * width).min(s.max_band);
                plane.reach = 0.5 * width;
                if plane.n.z < cos_max
                    || plane.spread < s.min_spread * width
                    || (roughness > s.max_roughness
                        && plane.height_at(plane.cx, plane.cy) + height > s.rough_height)
                {
                    continue;
                }
                self.candidates[c] = Some(plane);
                if (plane.height_at(plane.cx, plane.cy) + height).abs() <= s.seed_step {
                    self.planes[c] = Some(plane);
                    self.queue.push(c as u32);
                }
            }
        }
        // Grow: a candidate next to accepted ground (or across a gap of cells without a plane)
        // is ground if the two planes meet within the step limit halfway between their centres.
        let mut next = 0;
        while next < self.queue.len() {
            let c = self.queue[next] as usize;
            next += 1;
            let here = self.planes[c].unwrap_or_else(|| unreachable!("queued cells are accepted"));
            let ring = self.grid.ring_of[c] as usize;
            let sector = c as u32 - self.grid.first[ring];
            let n = self.grid.sectors[ring];
            for j in [(sector + n - 1) % n, (sector + 1) % n] {
                self.try_accept(&here, (self.grid.first[ring] + j) as usize);
            }
            let (a0, a1) = (sector as f64 * 4.0 / n as f64, (sector + 1) as f64 * 4.0 / n as f64);
            for up in [false, true] {
                for d in 1..=s.max_gap_rings {
                    let k = if up { ring + d } else { ring.wrapping_sub(d) };
                    if k >= self.grid.rings() {
                        break;
                    }
                    let nk = self.grid.sectors[k];
                    let lo = (a0 * nk as f64 * 0.25) as u32;
                    let hi = ((a1 * nk as f64 * 0.25).ceil() as u32).clamp(lo + 1, nk);
                    let mut any = false;
                    for j in lo..hi {
                        let other = (self.grid.first[k] + j) as usize;
                        any |= self.candidates[other].is_some();
                        self.try_accept(&here, other);
                    }
                    if any {
                        break;
                    }
                }
            }
        }
        let accepted = self.queue.len();
        (cells, accepted)
    }

    /// Accepts candidate `other` if it meets the accepted plane `here` within the step limit
    /// (plus the grade over the distance between them): each plane is evaluated where its own
    /// points end towards the other (at most half a ring width from its centre, at most halfway),
    /// so that a tilted plane is not extrapolated across a gap.
    #[inline]
    fn try_accept(&mut self, here: &CellPlane, other: usize) {
        if self.planes[other].is_some() {
            return;
        }
        let Some(there) = self.candidates[other] else {
            return;
        };
        let (dx, dy) = (there.cx - here.cx, there.cy - here.cy);
        let dist = dx.hypot(dy);
        let (ux, uy) = if dist > 0.0 { (dx / dist, dy / dist) } else { (0.0, 0.0) };
        let a = here.reach.min(0.5 * dist);
        let b = there.reach.min(0.5 * dist);
        let h_here = here.height_at(here.cx + a * ux, here.cy + a * uy);
        let h_there = there.height_at(there.cx - b * ux, there.cy - b * uy);
        let tolerance = self.settings.limits.max_step + self.settings.grade * (dist - a - b);
        if (h_here - h_there).abs() <= tolerance {
            self.planes[other] = Some(there);
            self.queue.push(other as u32);
        }
    }

    /// The accepted plane nearest to (x, y) among the cells at the same azimuth and its two
    /// neighbours in the nearest ring inwards (of `ring`) that has one, with its centre's
    /// horizontal distance from (x, y).
    fn reference(&self, ring: usize, x: f64, y: f64) -> Option<(CellPlane, f64)> {
        let a = diamond_angle(x, y);
        let lowest = ring.saturating_sub(self.settings.max_gap_rings);
        for k in (lowest..ring).rev() {
            let n = self.grid.sectors[k];
            let s = self.grid.sector(k, a);
            let first = self.grid.first[k];
            let best = [s, (s + n - 1) % n, (s + 1) % n]
                .into_iter()
                .filter_map(|j| self.planes[(first + j) as usize])
                .map(|p| (p, (p.cx - x).hypot(p.cy - y)))
                .min_by(|u, v| u.1.total_cmp(&v.1));
            if best.is_some() {
                return best;
            }
        }
        None
    }

    /// Labels the points of every cell; returns the ground count. A point is ground within the
    /// band of its cell's accepted plane or of the reference plane inwards (so both sides of a
    /// passable step in one cell are ground); a cell with neither uses the nominal ground.
    fn label(&self, height: f64, ground: &mut [bool]) -> usize {
        let nominal = CellPlane {
            n: Vector3::z(),
            d: -height,
            band: self.settings.max_band,
            cx: 0.0,
            cy: 0.0,
            spread: 0.0,
            roughness: 0.0,
            reach: 0.0,
        };
        let mut count = 0;
        for ring in 0..self.grid.rings() {
            for sector in 0..self.grid.sectors[ring] {
                let c = (self.grid.first[ring] + sector) as usize;
                let (a, b) = (self.start[c] as usize, self.start[c + 1] as usize);
                if a == b {
                    continue;
                }
                let points = &self.sorted[a..b];
                let own = self.planes[c];
                let (cx, cy) = match own {
                    Some(p) => (p.cx, p.cy),
                    None => {
                        let inv = 1.0 / points.len() as f64;
                        let cx = points.iter().map(|p| p[0]).sum::<f64>() * inv;
                        let cy = points.iter().map(|p| p[1]).sum::<f64>() * inv;
                        (cx, cy)
                    }
                };
                let reference = match self.reference(ring, cx, cy) {
                    Some((mut p, _)) if own.is_none() => {
                        p.band *= self.settings.reference_band;
                        Some(p)
                    }
                    Some((p, _)) => Some(p),
                    None if own.is_none() => Some(nominal),
                    None => None,
                };
                let on = |plane: &Option<CellPlane>, p: &[f64; 3]| {
                    plane.is_some_and(|q| q.distance(p).abs() <= q.band)
                };
                for (p, &i) in points.iter().zip(&self.order[a..b]) {
                    if on(&own, p) || on(&reference, p) {
                        ground[i as usize] = true;
                        count += 1;
                    }
                }
            }
        }
        count
    }
}

/// The label band of `plane`: [`GroundSettings::band_sigmas`] times the rms distance of the
/// points up to [`GroundSettings::fit_band`] *below* it, clamped to the band limits. Only the
/// points below count: noise spreads ground both ways, while what stands on the ground (a
/// wall's foot, a box, grass blades) lies above it and would widen a two-sided band.
fn lower_band(points: &[[f64; 3]], plane: &CellPlane, s: &GroundSettings) -> f64 {
    let (mut sum, mut n) = (0.0, 0.0);
    for p in points {
        let d = plane.distance(p);
        // Branch-free: the sign of d is a coin toss on flat ground.
        let w = f64::from(u8::from(d < 0.0 && d > -s.fit_band));
        sum += w * d * d;
        n += w;
    }
    let sigma = if n >= 3.0 { (sum / n).sqrt() } else { s.max_band };
    (s.band_sigmas * sigma).clamp(s.min_band, s.max_band)
}

/// The least-squares plane (PCA) of the points `keep` selects, normal up, with its label band
/// and centre; `None` for fewer than 3 points or a degenerate spread.
fn fit(
    points: &[[f64; 3]],
    s: &GroundSettings,
    keep: impl Fn(&[f64; 3]) -> bool,
) -> Option<CellPlane> {
    // One pass of moments about the first point (cells are metres wide: no cancellation).
    let o = *points.first()?;
    let (mut n, mut m1, mut m2) = (0usize, [0.0; 3], [0.0; 6]);
    for p in points.iter().filter(|p| keep(p)) {
        let (x, y, z) = (p[0] - o[0], p[1] - o[1], p[2] - o[2]);
        n += 1;
        m1[0] += x;
        m1[1] += y;
        m1[2] += z;
        m2[0] += x * x;
        m2[1] += x * y;
        m2[2] += x * z;
        m2[3] += y * y;
        m2[4] += y * z;
        m2[5] += z * z;
    }
    if n < 3 {
        return None;
    }
    let inv = 1.0 / n as f64;
    let c = m1.map(|v| v * inv);
    let cov = [
        m2[0] * inv - c[0] * c[0],
        m2[1] * inv - c[0] * c[1],
        m2[2] * inv - c[0] * c[2],
        m2[3] * inv - c[1] * c[1],
        m2[4] * inv - c[1] * c[2],
        m2[5] * inv - c[2] * c[2],
    ];
    let mean = [c[0] + o[0], c[1] + o[1], c[2] + o[2]];
    let m = Matrix3::new(cov[0], cov[1], cov[2], cov[1], cov[3], cov[4], cov[2], cov[4], cov[5]);
    let eigen = SymmetricEigen::new(m);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]));
    let (i, lambda) = (order[0], eigen.eigenvalues[order[0]]);
    let mut normal: Vector3<f64> = eigen.eigenvectors.column(i).into_owned();
    let norm = normal.norm();
    if !(norm > 0.5 && lambda.is_finite()) {
        return None;
    }
    normal /= norm;
    if normal.z < 0.0 {
        normal = -normal;
    }
    let band = (s.band_sigmas * lambda.max(0.0).sqrt()).clamp(s.min_band, s.max_band);
    Some(CellPlane {
        n: normal,
        d: normal.x * mean[0] + normal.y * mean[1] + normal.z * mean[2],
        band,
        cx: mean[0],
        cy: mean[1],
        spread: eigen.eigenvalues[order[1]].max(0.0).sqrt(),
        roughness: lambda.max(0.0).sqrt(),
        reach: 0.0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mount::SensorAxes;
    use proptest::prelude::*;
    use rand::{Rng as _, SeedableRng as _};
    use rand_chacha::ChaCha8Rng;

    const H: f64 = 0.5;

    /// Points every `step` metres over x ∈ [x0, x1), y ∈ [−w, w) of the ground height `z(x, y)`
    /// (z up, 0 = the robot's floor), seen from a level body-axes sensor `H` above the floor.
    fn surface(
        x0: f64,
        x1: f64,
        w: f64,
        step: f64,
        z: impl Fn(f64, f64) -> f64,
    ) -> Vec<Point3<f64>> {
        let mut out = Vec::new();
        let mut x = x0;
        while x < x1 {
            let mut y = -w;
            while y < w {
                out.push(Point3::new(x, y, z(x, y) - H));
                y += step;
            }
            x += step;
        }
        out
    }

    fn segment(points: &[Point3<f64>]) -> Vec<bool> {
        let mount = SensorMount::looking_ahead(H, 0.0, 0.0, SensorAxes::Body).unwrap();
        let mut g = GroundSegmenter::new(GroundSettings::default()).unwrap();
        let mut ground = Vec::new();
        let summary = g.segment(points, &mount, &mut ground).unwrap();
        assert_eq!(summary.ground, ground.iter().filter(|&&v| v).count());
        assert_eq!(summary.points, points.len());
        ground
    }

    fn share(labels: &[bool]) -> f64 {
        labels.iter().filter(|&&v| v).count() as f64 / labels.len().max(1) as f64
    }

    #[test]
    fn flat_floor_is_ground() {
        let floor = surface(0.3, 8.0, 4.0, 0.05, |_, _| 0.0);
        assert_eq!(share(&segment(&floor)), 1.0);
    }

    #[test]
    fn ramp_within_the_slope_limit_is_ground_a_steeper_one_is_not() {
        for (deg, drivable) in [(20.0f64, true), (30.0, true), (45.0, false), (60.0, false)] {
            let t = deg.to_radians().tan();
            let pts = surface(0.3, 6.0, 3.0, 0.04, |x, _| (x - 2.0).max(0.0) * t);
            let g = segment(&pts);
            // The ramp beyond its foot (the foot's first 0.3 m may join the floor's band).
            let ramp: Vec<bool> =
                pts.iter().zip(&g).filter(|(p, _)| p.x > 2.5).map(|(_, &v)| v).collect();
            let floor: Vec<bool> =
                pts.iter().zip(&g).filter(|(p, _)| p.x < 1.8).map(|(_, &v)| v).collect();
            assert_eq!(share(&floor), 1.0, "{deg}°: floor");
            if drivable {
                assert!(share(&ramp) > 0.97, "{deg}°: ramp share {}", share(&ramp));
            } else {
                assert!(share(&ramp) < 0.02, "{deg}°: ramp share {}", share(&ramp));
            }
        }
    }

    #[test]
    fn steps_up_and_down_within_the_step_limit_are_ground() {
        for (step, drivable) in [(0.1, true), (-0.15, true), (0.3, false), (-0.4, false)] {
            let pts = surface(0.3, 7.0, 3.0, 0.04, |x, _| if x >= 2.0 { step } else { 0.0 });
            let g = segment(&pts);
            let beyond: Vec<bool> =
                pts.iter().zip(&g).filter(|(p, _)| p.x > 2.3).map(|(_, &v)| v).collect();
            let near: Vec<bool> =
                pts.iter().zip(&g).filter(|(p, _)| p.x < 1.9).map(|(_, &v)| v).collect();
            assert_eq!(share(&near), 1.0, "step {step}: floor");
            if drivable {
                assert!(share(&beyond) > 0.98, "step {step}: beyond {}", share(&beyond));
            } else {
                assert_eq!(share(&beyond), 0.0, "step {step}");
            }
        }
    }

    #[test]
    fn walls_and_boxes_are_not_ground() {
        let mut pts = surface(0.3, 3.0, 3.0, 0.04, |_, _| 0.0);
        let floor = pts.len();
        // A wall at 3 m, 2 m high.
        for i in 0..150 {
            for j in 0..50 {
                pts.push(Point3::new(3.0, -3.0 + i as f64 * 0.04, j as f64 * 0.04 - H));
            }
        }
        // A box 0.4 m high, 0.6 m wide, on the floor at (1.5, 1): its top and its front.
        for i in 0..15 {
            for j in 0..15 {
                pts.push(Point3::new(1.2 + i as f64 * 0.04, 0.7 + j as f64 * 0.04, 0.4 - H));
            }
            for j in 0..10 {
                pts.push(Point3::new(1.2, 0.7 + i as f64 * 0.04, j as f64 * 0.04 + 0.02 - H));
            }
        }
        let g = segment(&pts);
        // The floor is ground except where the box stands on it.
        let under_box = |p: &Point3<f64>| (1.2..1.8).contains(&p.x) && (0.7..1.3).contains(&p.y);
        assert!(pts[..floor].iter().zip(&g).all(|(p, &v)| v || under_box(p)));
        // Nothing above the step limit (0.2 m) is ground.
        for (p, &v) in pts[floor..].iter().zip(&g[floor..]) {
            assert!(!v || p.z + H < 0.2, "{p} labelled ground");
        }
    }

    #[test]
    fn a_camera_looking_down_sees_ground() {
        // Optical axes (x right, y down, z forward), pitched 30° down, 1 m up.
        let pitch = 30f64.to_radians();
        let mount = SensorMount::looking_ahead(1.0, pitch, 0.0, SensorAxes::Optical).unwrap();
        let body_from_optical = Matrix3::new(0.0, 0.0, 1.0, -1.0, 0.0, 0.0, 0.0, -1.0, 0.0);
        let rot = nalgebra::UnitQuaternion::from_euler_angles(0.0, pitch, 0.0);
        let ground_from_sensor = rot.to_rotation_matrix().into_inner() * body_from_optical;
        let sensor_from_ground = ground_from_sensor.transpose();
        let mut pts = Vec::new();
        for i in 0..60 {
            for j in 0..60 {
                let g = Vector3::new(0.8 + i as f64 * 0.05, -1.5 + j as f64 * 0.05, -1.0);
                pts.push(Point3::from(sensor_from_ground * g));
                // A table top 0.7 m above the floor.
                if i < 20 && j < 20 {
                    let t = Vector3::new(g.x + 1.0, g.y, -0.3);
                    pts.push(Point3::from(sensor_from_ground * t));
                }
            }
        }
        let mut ground = Vec::new();
        let mut g = GroundSegmenter::new(GroundSettings::default()).unwrap();
        g.segment(&pts, &mount, &mut ground).unwrap();
        let mut wrong = Vec::new();
        for (p, &v) in pts.iter().zip(&ground) {
            let q = ground_from_sensor * p.coords;
            if v != (q.z < -0.9) {
                wrong.push(q);
            }
        }
        assert!(wrong.is_empty(), "{} wrong: {:?}", wrong.len(), &wrong[..wrong.len().min(10)]);
    }

    #[test]
    fn errors_are_typed() {
        let mount = SensorMount::levelled(1.0).unwrap();
        let mut g = GroundSegmenter::new(GroundSettings::default()).unwrap();
        let mut out = Vec::new();
        assert!(matches!(g.segment(&[], &mount, &mut out), Err(HoughError::EmptyCloud)));
        let bad = [Point3::new(1.0, 0.0, 1.0), Point3::new(f64::NAN, 0.0, 0.0)];
        assert!(matches!(
            g.segment(&bad, &mount, &mut out),
            Err(HoughError::NonFinitePoint { index: 1 })
        ));
        let d = GroundSettings::default();
        for s in [
            GroundSettings { max_range: 0.0, ..d },
            GroundSettings { min_cell: 0.0, ..d },
            GroundSettings { cell_growth: f64::NAN, ..d },
            GroundSettings { min_points: 2, ..d },
            GroundSettings { seed_points: 0, ..d },
            GroundSettings { max_band: 0.01, ..d },
            GroundSettings { grade: -1.0, ..d },
            GroundSettings { limits: RobotLimits { max_step: 0.2, max_slope: 2.0 }, ..d },
            GroundSettings { min_cell: 1e-9, cell_growth: 1e-9, ..d },
        ] {
            assert!(GroundSegmenter::new(s).is_err(), "{s:?}");
        }
        // Points outside the grid are not ground; a frame with none inside labels nothing.
        let far = [Point3::new(100.0, 0.0, -1.0); 10];
        let s = g.segment(&far, &SensorMount::levelled(1.0).unwrap(), &mut out).unwrap();
        assert_eq!((s.ground, out.len()), (0, 10));
    }

    #[test]
    fn buffers_are_reused_and_results_repeat() {
        let pts = surface(0.3, 6.0, 3.0, 0.05, |x, y| 0.02 * (x + y).sin());
        let mount = SensorMount::looking_ahead(H, 0.0, 0.0, SensorAxes::Body).unwrap();
        let mut g = GroundSegmenter::new(GroundSettings::default()).unwrap();
        let (mut a, mut b) = (Vec::new(), Vec::new());
        let sa = g.segment(&pts, &mount, &mut a).unwrap();
        g.segment(&pts[..100], &mount, &mut b).unwrap();
        let sb = g.segment(&pts, &mount, &mut b).unwrap();
        assert_eq!((a, sa), (b, sb));
    }

    /// A noisy tilted plane around a sensor at `height` with clutter far above it.
    fn noisy_scene(seed: u64, height: f64, tilt: f64, noise: f64) -> (Vec<Point3<f64>>, usize) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let t = tilt.tan();
        let mut pts = Vec::new();
        for _ in 0..20_000 {
            let (r, a) = (rng.random_range(0.5..15.0f64), rng.random_range(-3.2..3.2f64));
            let (x, y) = (r * a.cos(), r * a.sin());
            pts.push(Point3::new(x, y, t * x - height + noise * rng.random_range(-1.0..1.0)));
        }
        let ground = pts.len();
        for _ in 0..1000 {
            let (r, a) = (rng.random_range(0.5..15.0f64), rng.random_range(-3.2..3.2f64));
            let (x, y) = (r * a.cos(), r * a.sin());
            pts.push(Point3::new(x, y, t * x - height + rng.random_range(0.5..3.0)));
        }
        (pts, ground)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        #[test]
        fn noisy_plane_is_ground_and_points_far_above_never(
            seed in 0u64..1000,
            height in 0.3f64..2.5,
            tilt in -0.15f64..0.15,
            noise in 0.0f64..0.02,
        ) {
            let (pts, n) = noisy_scene(seed, height, tilt, noise);
            let mount = SensorMount::looking_ahead(height, 0.0, 0.0, SensorAxes::Body).unwrap();
            let mut g = GroundSegmenter::new(GroundSettings::default()).unwrap();
            let mut ground = Vec::new();
            g.segment(&pts, &mount, &mut ground).unwrap();
            let plane_share = share(&ground[..n]);
            prop_assert!(plane_share > 0.97, "plane share {}", plane_share);
            prop_assert!(ground[n..].iter().all(|&v| !v), "a point 0.5 m above is ground");
        }
    }
}
