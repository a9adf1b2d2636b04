//! Beyond the thesis: the *ground-ahead* rule, a drivability and class decision that looks at
//! where the points are rather than only at how many vote for one plane.
//!
//! Algorithm 3 (§4.1.3) counts votes over the whole frame, so a wall 3 m ahead loses to the
//! floor at 1 m, and a floor bin full of votes says "floor" whatever stands on it. The
//! ground-ahead rule keeps the thesis's vocabulary (its five classes, Rugbot's step and slope
//! limits, L3453–3460) and decides in the levelled frame, on the points within `lookahead`
//! metres ahead and `half_width` metres to either side:
//!
//! 1. Heights are measured above the floor the mount gives (`h − z`, z down). Points within
//!    `floor_band` of it are *floor*; the rest are *off-floor*. Fewer than `min_points` points
//!    ahead is an obstacle (nothing seen is not free).
//! 2. A sampled plane fit (RANSAC, `iterations` tries of ground-like planes, at most
//!    `steep_tilt` from level, on at most `sample` off-floor points, refined by least squares)
//!    finds the dominant ground plane among the off-floor points. It is the *surface* ahead if
//!    it holds at least `surface_share` of them and spreads at least `surface_width` across; if
//!    it does not float (at most `max_floating` of the cells it covers show more floor below it
//!    than surface: a sheet of wrapped-around time-of-flight pixels hovers over visible floor, a
//!    real plateau hides the floor behind its edge); and if it shows in at least `min_coverage`
//!    of the occupied cells of its extent (the tops of scattered objects are no surface).
//! 3. Every `cell` × `cell` column is checked for something standing on the ground: its points
//!    are binned by height (`bin` metres). A bin counts if it holds `min_column_fraction` of what
//!    a vertical surface at that distance shows this sensor (`pixel_pitch`), and at least
//!    `min_bin_points`: range noise scatters points thinly along the beams, surfaces do not.
//!    From the ground (the floor's height, or the surface's where the surface lies) the
//!    occupied bins are followed upwards across gaps of at most `max_gap`; a column rising more
//!    than the robot's `max_step` above the ground is an obstacle cell. Points that float (no
//!    occupied bin joins them to the ground) do not count. `obstacle_cells` obstacle cells make
//!    the frame an obstacle, unless they form a *ledge*: in at least `ledge_share` of the
//!    lateral rows that show points (up to the farthest such column; range noise scatters
//!    points beyond and out to the side), the nearest obstacle cell's top agrees within
//!    `ledge_spread` and lies at most `ledge_rise` above the sensor. That is a plateau too high
//!    to climb whose face spans the view (its top may be out of sight); a wall's columns end at
//!    the view's upper edge instead. Either way the frame is not drivable.
//! 4. In the strip `strip_half_width` to either side straight ahead, the rows that show ground
//!    (floor or surface, at `min_ground_fraction` of the density the floor would show there)
//!    are followed outwards. At a break of at least `min_drop_gap` with points beyond, the
//!    `drop_quantile` of those points' heights is the ground beyond (range noise drags points
//!    along their beams towards the sensor, that is up); deeper than the step is a *canyon*.
//! 5. Otherwise the surface decides: a level one (within `level_tilt`) is a plateau above the
//!    floor or a canyon below it, passable up to `max_step + step_allowance`; a step the robot
//!    can take is *floor*, as the thesis's evaluation labels curbs (§4.4.1); a tilted one is a
//!    ramp, passable up to `max_slope`. Without a surface the frame is floor.
//!
//! docs/terrain.md has the rule's figures beside Algorithm 3's on the simulated snapshots.

use crate::ball::{BallPlane, refine_plane};
use crate::classify::{Classification, RobotLimits, Rule, TerrainClass, not_drivable};
use crate::error::{HoughError, Result};
use crate::space::Plane;
use nalgebra::{Point3, Unit, Vector3};
use rand::{Rng as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// Points that show a surface (or the floor) in a cell.
const SHOWS: u16 = 3;

/// Height bins per column (one `u8` count each): heights from [`GroundAhead::min_height`] up.
const BINS: usize = 64;

/// The ground-ahead rule's parameters (see the module documentation). Lengths in metres,
/// angles in radians, shares in [0, 1].
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GroundAhead {
    /// How far ahead (horizontal distance along the heading) points are looked at. 7 m.
    pub lookahead: f64,
    /// How far to either side points are looked at. 2 m.
    pub half_width: f64,
    /// Points within this height of the floor are floor. 0.08 m.
    pub floor_band: f64,
    /// Fewer points ahead than this is obstacle (nothing seen is not free). 100.
    pub min_points: usize,
    /// Inlier distance of the plane fit. 0.05 m.
    pub plane_band: f64,
    /// Planes tried by the sampled fit. 64.
    pub iterations: usize,
    /// Off-floor points the sampled fit looks at (evenly picked). 1500.
    pub sample: usize,
    /// Least share of the off-floor points on the surface. 0.15.
    pub surface_share: f64,
    /// Least lateral spread of the surface's points. 0.8 m.
    pub surface_width: f64,
    /// Steepest surface (a steeper plane is a wall, not ground). 60°.
    pub steep_tilt: f64,
    /// A surface at most this far from level is a step (plateau or canyon), else a ramp. 8°.
    pub level_tilt: f64,
    /// Largest share of the surface's cells that may show floor below it. 0.3.
    pub max_floating: f64,
    /// Least share of the cells with points within the surface's extent that show it (the
    /// patchy tops of scattered objects are no surface). 0.35.
    pub min_coverage: f64,
    /// Column size of the obstacle grid. 0.2 m.
    pub cell: f64,
    /// Height bin of the columns. 0.05 m.
    pub bin: f64,
    /// Points a height bin needs to count as occupied, at least. 3.
    pub min_bin_points: u8,
    /// The sensor's angle between neighbouring pixels or beams, radians: what a surface at a
    /// known distance shows is counted against it. 0.27° (SR-3000: 47.5° / 176 pixels).
    pub pixel_pitch: f64,
    /// Share of the points a vertical surface would show that a height bin needs to count as
    /// occupied: `cell · bin / (pixel_pitch · x)²` at `x` metres (range noise scatters far
    /// fewer). 0.1.
    pub min_column_fraction: f64,
    /// Largest empty gap a column may have and still stand. 0.1 m.
    pub max_gap: f64,
    /// Obstacle cells that make the frame an obstacle (or a ledge). 2.
    pub obstacle_cells: usize,
    /// Least share of the lateral rows that show points in which the nearest standing column
    /// must belong to a ledge: a face across the view with a level top edge. 0.3.
    pub ledge_share: f64,
    /// How far above the sensor a ledge's top edge may lie (higher, it is the view's edge on a
    /// wall). 0.15 m.
    pub ledge_rise: f64,
    /// Largest spread of the ledge's top edge (its 10th to 90th percentile). 0.15 m.
    pub ledge_spread: f64,
    /// What a measured step may exceed the robot's `max_step` by and still pass: the range
    /// noise's share of the fit (the thesis's steps are rounded to its 0.1 m d bins). 0.05 m.
    pub step_allowance: f64,
    /// Half the width of the strip ahead in which the ground must continue. 0.6 m.
    pub strip_half_width: f64,
    /// Shortest break in the strip's ground that is looked beyond for a drop. 0.4 m.
    pub min_drop_gap: f64,
    /// Which height quantile of the points beyond a break is the ground there. 0.25.
    pub drop_quantile: f64,
    /// Share of the points the floor would show (`2 · strip_half_width · cell · h /
    /// (pixel_pitch² · x³)` for a sensor `h` metres up) that a row of the strip ahead needs to
    /// count as ground. 0.25.
    pub min_ground_fraction: f64,
    /// Seed of the sampled fit (the result is deterministic for a frame).
    pub seed: u64,
    /// Also fill the Hough space (for its picture and Algorithm 3's plane beside the rule):
    /// about a quarter of a millisecond per SR-3000 frame at 45°. Off.
    pub hough: bool,
}

impl GroundAhead {
    /// The defaults listed on the fields.
    pub fn recommended() -> GroundAhead {
        GroundAhead {
            lookahead: 7.0,
            half_width: 2.0,
            floor_band: 0.08,
            min_points: 100,
            plane_band: 0.05,
            iterations: 64,
            sample: 1500,
            surface_share: 0.15,
            surface_width: 0.8,
            steep_tilt: 60f64.to_radians(),
            level_tilt: 8f64.to_radians(),
            max_floating: 0.3,
            min_coverage: 0.35,
            cell: 0.2,
            bin: 0.05,
            min_bin_points: 3,
            pixel_pitch: (47.5f64 / 176.0).to_radians(),
            min_column_fraction: 0.1,
            min_ground_fraction: 0.25,
            max_gap: 0.1,
            obstacle_cells: 2,
            ledge_share: 0.3,
            ledge_rise: 0.15,
            ledge_spread: 0.15,
            step_allowance: 0.05,
            strip_half_width: 0.6,
            min_drop_gap: 0.4,
            drop_quantile: 0.25,
            seed: 0x5eed,
            hough: false,
        }
    }

    /// The lowest height a column bin holds: `−(BINS/4)·bin` (a quarter of the bins below the
    /// floor, for canyons).
    pub fn min_height(&self) -> f64 {
        -((BINS / 4) as f64) * self.bin
    }

    /// Checks every field: lengths positive and finite (the grid at most 10⁶ cells), shares in
    /// [0, 1], angles in [0, 90°], counts at least 1.
    pub fn validate(&self) -> Result<()> {
        let positive = |what, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(HoughError::BadParameter { what, value: v, allowed: "> 0 and finite" })
            }
        };
        positive("lookahead", self.lookahead)?;
        positive("half_width", self.half_width)?;
        positive("floor_band", self.floor_band)?;
        positive("plane_band", self.plane_band)?;
        positive("cell", self.cell)?;
        positive("bin", self.bin)?;
        positive("strip_half_width", self.strip_half_width)?;
        positive("min_drop_gap", self.min_drop_gap)?;
        if !(0.0..=1.0).contains(&self.step_allowance) {
            return Err(HoughError::BadParameter {
                what: "step_allowance",
                value: self.step_allowance,
                allowed: "[0, 1] m",
            });
        }
        if !(self.pixel_pitch.is_finite() && (1e-5..=0.5).contains(&self.pixel_pitch)) {
            return Err(HoughError::BadParameter {
                what: "pixel_pitch",
                value: self.pixel_pitch,
                allowed: "[0.0006°, 28°]",
            });
        }
        if !(-1e3..=1e3).contains(&self.ledge_rise) {
            return Err(HoughError::BadParameter {
                what: "ledge_rise",
                value: self.ledge_rise,
                allowed: "[-1000, 1000] m",
            });
        }
        if !(0.0..=1e3).contains(&self.ledge_spread) {
            return Err(HoughError::BadParameter {
                what: "ledge_spread",
                value: self.ledge_spread,
                allowed: "[0, 1000] m",
            });
        }
        if !(self.max_gap.is_finite() && self.max_gap >= 0.0) {
            return Err(HoughError::BadParameter {
                what: "max_gap",
                value: self.max_gap,
                allowed: "≥ 0 m",
            });
        }
        if !(0.0..=1e3).contains(&self.surface_width) {
            return Err(HoughError::BadParameter {
                what: "surface_width",
                value: self.surface_width,
                allowed: "[0, 1000] m",
            });
        }
        for (what, v) in [
            ("surface_share", self.surface_share),
            ("max_floating", self.max_floating),
            ("min_coverage", self.min_coverage),
            ("min_column_fraction", self.min_column_fraction),
            ("min_ground_fraction", self.min_ground_fraction),
            ("drop_quantile", self.drop_quantile),
            ("ledge_share", self.ledge_share),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return Err(HoughError::BadParameter { what, value: v, allowed: "[0, 1]" });
            }
        }
        let right = std::f64::consts::FRAC_PI_2;
        for (what, v) in [("steep_tilt", self.steep_tilt), ("level_tilt", self.level_tilt)] {
            if !(0.0..=right).contains(&v) {
                return Err(HoughError::BadParameter { what, value: v, allowed: "[0, 90°]" });
            }
        }
        for (what, v) in [
            ("iterations", self.iterations),
            ("sample", self.sample),
            ("min_points", self.min_points),
            ("obstacle_cells", self.obstacle_cells),
            ("min_bin_points", usize::from(self.min_bin_points)),
        ] {
            if v == 0 || v > 100_000_000 {
                return Err(HoughError::BadParameter {
                    what, value: v as f64, allowed: "1..=10⁸"
                });
            }
        }
        let cells =
            (self.lookahead / self.cell).ceil() * (2.0 * self.half_width / self.cell).ceil();
        if cells > 1e6 {
            return Err(HoughError::TooManyBins {
                what: "ground-ahead grid",
                bins: cells as u64,
                limit: 1_000_000,
            });
        }
        Ok(())
    }

    fn nx(&self) -> usize {
        (self.lookahead / self.cell).ceil() as usize
    }

    /// The centre (x ahead, y left) of cell `c` of a grid `nx` cells long.
    fn cell_centre(&self, c: usize, nx: usize) -> (f64, f64) {
        (((c % nx) as f64 + 0.5) * self.cell, ((c / nx) as f64 + 0.5) * self.cell - self.half_width)
    }

    fn ny(&self) -> usize {
        (2.0 * self.half_width / self.cell).ceil() as usize
    }
}

/// What the ground-ahead rule saw, beside the [`Classification`] it returns.
#[derive(Copy, Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct AheadFacts {
    /// Points within the lookahead and the width.
    pub points: usize,
    /// Of those, the off-floor points.
    pub off_floor: usize,
    /// Points on the surface (0 without one).
    pub surface_points: usize,
    /// Columns with something standing higher than the robot's step.
    pub obstacle_cells: usize,
    /// A plane was found among the off-floor points but rejected as floating over floor.
    pub floating_surface: bool,
    /// Points on the best ground plane among the off-floor points, surface or not.
    pub surface_candidate: usize,
    /// The share of the cells within the surface's extent that show it.
    pub surface_coverage: f64,
    /// The first break of the ground in the strip ahead with points beyond, metres (0: none).
    pub ground_gap: f64,
    /// How far below the floor the ground beyond that break lies, metres.
    pub drop_depth: f64,
    /// The share of the lateral rows showing points whose nearest column stands (0 without
    /// obstacle cells).
    pub front_share: f64,
    /// The median top of those columns above the floor, metres.
    pub front_top: f64,
    /// The spread of their tops (10th to 90th percentile), metres.
    pub front_spread: f64,
}

/// Reused buffers of the ground-ahead rule: no allocation per frame once grown.
#[derive(Clone, Debug, Default)]
pub struct AheadScratch {
    /// Points ahead, levelled frame, z up (height above the floor).
    ahead: Vec<Point3<f64>>,
    off: Vec<Point3<f64>>,
    sample: Vec<Point3<f64>>,
    counts: Vec<u8>,
    /// Per lateral row, the nearest standing column: its cell along the heading and its top.
    front: Vec<Option<(usize, f64)>>,
    floor_cells: Vec<u16>,
    surface_cells: Vec<u16>,
    rows: Vec<u16>,
    cell_points: Vec<u16>,
    heights: Vec<f64>,
    /// The facts of the last call.
    pub facts: AheadFacts,
}

impl AheadScratch {
    /// Heap bytes held.
    pub fn capacity_bytes(&self) -> usize {
        (self.ahead.capacity() + self.off.capacity() + self.sample.capacity())
            * std::mem::size_of::<Point3<f64>>()
            + self.heights.capacity() * 8
            + self.front.capacity() * std::mem::size_of::<Option<(usize, f64)>>()
            + self.counts.capacity()
            + (self.floor_cells.capacity()
                + self.surface_cells.capacity()
                + self.rows.capacity()
                + self.cell_points.capacity())
                * 2
    }
}

/// A surface ahead in the z-up frame: `normal · p = distance`, unit normal pointing up.
#[derive(Copy, Clone, Debug)]
struct Surface {
    normal: Vector3<f64>,
    distance: f64,
    points: usize,
    x_min: f64,
    x_max: f64,
}

impl Surface {
    /// Height of the surface above the floor at (x, y); `None` for a vertical plane.
    fn height_at(&self, x: f64, y: f64) -> Option<f64> {
        (self.normal.z > 1e-9)
            .then(|| (self.distance - self.normal.x * x - self.normal.y * y) / self.normal.z)
    }

    fn tilt(&self) -> f64 {
        self.normal.z.abs().clamp(0.0, 1.0).acos()
    }
}

/// The ground-ahead rule on levelled points (x forward, y right, z down; the floor at
/// `z = height`). Returns the class with `rule` one of the `Ahead*` variants of [`Rule`];
/// `scratch.facts` tells what it saw. Fails only on a bad `rule` (see
/// [`GroundAhead::validate`]).
pub fn classify_ahead(
    levelled: &[Point3<f64>],
    height: f64,
    limits: &RobotLimits,
    rule: &GroundAhead,
    scratch: &mut AheadScratch,
) -> Result<Classification> {
    rule.validate()?;
    let (nx, ny) = (rule.nx(), rule.ny());
    scratch.facts = AheadFacts::default();
    scratch.ahead.clear();
    scratch.off.clear();
    let per_cell = rule.cell.recip();
    let cell_of = |p: &Point3<f64>| -> usize {
        let ix = ((p.x * per_cell) as usize).min(nx - 1);
        let iy = (((p.y + rule.half_width) * per_cell).max(0.0) as usize).min(ny - 1);
        iy * nx + ix
    };
    // One pass: the points ahead, those off the floor, the points and floor points per cell,
    // and the columns' height-bin counts.
    scratch.floor_cells.clear();
    scratch.floor_cells.resize(nx * ny, 0);
    scratch.cell_points.clear();
    scratch.cell_points.resize(nx * ny, 0);
    scratch.counts.clear();
    scratch.counts.resize(nx * ny * BINS, 0);
    let h0 = rule.min_height();
    let per_bin = rule.bin.recip();
    for p in levelled {
        if !(p.x > 0.0 && p.x <= rule.lookahead && p.y.abs() <= rule.half_width) {
            continue;
        }
        // z up, y left: the frame of `Plane::to_z_up`.
        let q = Point3::new(p.x, -p.y, height - p.z);
        scratch.ahead.push(q);
        let c = cell_of(&q);
        scratch.cell_points[c] = scratch.cell_points[c].saturating_add(1);
        if q.z.abs() > rule.floor_band {
            scratch.off.push(q);
        } else {
            scratch.floor_cells[c] = scratch.floor_cells[c].saturating_add(1);
        }
        // Truncation is the floor for b ≥ 0 (and `f64::floor` is a libm call here).
        let b = (q.z - h0) * per_bin;
        if b >= 0.0 && b < BINS as f64 {
            let i = c * BINS + b as usize;
            scratch.counts[i] = scratch.counts[i].saturating_add(1);
        }
    }
    let mut out = base(levelled.len(), height);
    scratch.facts.points = scratch.ahead.len();
    scratch.facts.off_floor = scratch.off.len();
    if scratch.ahead.len() < rule.min_points {
        out.rule = Rule::AheadTooFew;
        return Ok(out);
    }

    let surface = find_surface(rule, scratch, &cell_of, nx);
    if let Some(s) = &surface {
        scratch.facts.surface_points = s.points;
    }
    let gap_bins = (rule.max_gap / rule.bin).floor() as usize;
    let mut obstacle_cells = 0;
    scratch.front.clear();
    scratch.front.resize(ny, None);
    for iy in 0..ny {
        for ix in 0..nx {
            let c = iy * nx + ix;
            let column = &scratch.counts[c * BINS..(c + 1) * BINS];
            let (x, y) = rule.cell_centre(c, nx);
            let x_lo = ix as f64 * rule.cell;
            let ground = surface
                .and_then(|s| {
                    (x_lo + rule.cell >= s.x_min - rule.cell && x_lo <= s.x_max + rule.cell)
                        .then(|| s.height_at(x, y))
                        .flatten()
                })
                .map_or(0.0, |g| g.max(0.0));
            let full = rule.cell * rule.bin / (rule.pixel_pitch * x).powi(2);
            let least = (rule.min_column_fraction * full).max(f64::from(rule.min_bin_points));
            let least = least.min(255.0) as u8;
            if let Some(top) = stands(column, ground, least, rule, limits, gap_bins) {
                obstacle_cells += 1;
                // Rows are visited nearest cell first.
                scratch.front[iy].get_or_insert((ix, top));
            }
        }
    }
    scratch.facts.obstacle_cells = obstacle_cells;
    if obstacle_cells >= rule.obstacle_cells {
        out.rule = Rule::AheadObstacle;
        if let Some(top) = ledge(rule, height, scratch, nx) {
            // Higher than a step by construction of the columns: not passable.
            out.class = TerrainClass::Plateau;
            out.rule = Rule::AheadLedge;
            out.step = top;
        }
        return Ok(out);
    }
    // Does the ground drop away beyond a break in the strip ahead?
    if let Some((gap, depth)) = ground_break(rule, height, surface.as_ref(), scratch, nx) {
        scratch.facts.ground_gap = gap;
        scratch.facts.drop_depth = depth;
        if depth > limits.max_step + rule.step_allowance {
            out.class = TerrainClass::Canyon;
            out.rule = Rule::AheadDrop;
            out.step = -depth;
            return Ok(out);
        }
    }
    let Some(s) = surface else {
        out.class = TerrainClass::Floor;
        out.passable = true;
        out.drivable = true;
        out.rule = Rule::AheadFloor;
        out.votes = (scratch.ahead.len() - scratch.off.len()) as u32;
        return Ok(out);
    };
    // The surface decides.
    let tilt = s.tilt();
    out.rule = Rule::AheadSurface;
    out.votes = s.points as u32;
    out.tilt = tilt;
    // In the levelled frame (z down, y right) the plane is n'·p = d' with n' = (nx, −ny, −nz)
    // and d' = distance − nz·height; as (ρx, ρy, d) with the thesis's normal.
    let down = Vector3::new(-s.normal.x, s.normal.y, s.normal.z);
    let d_down = s.normal.z * height - s.distance;
    let rho_x = (-down.x / down.z).atan();
    let rho_y = (-down.y / down.z).atan();
    let z0 = d_down / down.z;
    out.plane = Some(Plane { rho_x, rho_y, d: z0 * rho_x.cos() * rho_y.cos() });
    if tilt <= rule.level_tilt {
        // Its mean height over its points' extent.
        let step = s.height_at(0.5 * (s.x_min + s.x_max), 0.0).unwrap_or(0.0);
        out.step = step;
        out.passable = step.abs() <= limits.max_step + rule.step_allowance;
        out.class = if out.passable {
            TerrainClass::Floor
        } else if step > 0.0 {
            TerrainClass::Plateau
        } else {
            TerrainClass::Canyon
        };
    } else {
        out.class = TerrainClass::Ramp;
        out.passable = tilt <= limits.max_slope + 1e-12;
    }
    out.drivable = out.passable;
    Ok(out)
}

/// Where the ground of the central strip (`strip_half_width` to either side) breaks off for at
/// least `min_drop_gap` with more points beyond: the gap's length and how far below the floor
/// those points lie (their `drop_quantile` height, negated: range noise drags points along
/// their beams towards the sensor, that is up, so the low ones are the ground beyond).
fn ground_break(
    rule: &GroundAhead,
    height: f64,
    surface: Option<&Surface>,
    scratch: &mut AheadScratch,
    nx: usize,
) -> Option<(f64, f64)> {
    // [ground rows | occupied rows].
    let rows = &mut scratch.rows;
    rows.clear();
    rows.resize(2 * nx, 0);
    let on_ground = |p: &Point3<f64>| {
        p.z.abs() <= rule.floor_band
            || surface.is_some_and(|s| {
                (s.normal.dot(&p.coords) - s.distance).abs() <= 2.0 * rule.plane_band
            })
    };
    for p in &scratch.ahead {
        if p.y.abs() <= rule.strip_half_width {
            let ix = ((p.x / rule.cell) as usize).min(nx - 1);
            if on_ground(p) {
                rows[ix] = rows[ix].saturating_add(1);
            }
            rows[nx + ix] = rows[nx + ix].saturating_add(1);
        }
    }
    let full = |x: f64| {
        2.0 * rule.strip_half_width * rule.cell * height.max(0.05)
            / (rule.pixel_pitch.powi(2) * x.powi(3))
    };
    let is_ground = |ix: usize| {
        let x = (ix as f64 + 0.5) * rule.cell;
        f64::from(rows[ix]) >= (rule.min_ground_fraction * full(x)).max(f64::from(SHOWS))
    };
    let first = (0..nx).find(|&ix| is_ground(ix))?;
    let min_rows = (rule.min_drop_gap / rule.cell).ceil() as usize;
    let mut ix = first;
    while ix < nx {
        if is_ground(ix) {
            ix += 1;
            continue;
        }
        let start = ix;
        let end = (start..nx).find(|&k| is_ground(k)).unwrap_or(nx);
        let beyond = (start + min_rows..nx).any(|k| rows[nx + k] >= SHOWS);
        if end - start >= min_rows && beyond {
            let from = (start + min_rows) as f64 * rule.cell;
            let heights = &mut scratch.heights;
            heights.clear();
            heights.extend(
                scratch
                    .ahead
                    .iter()
                    .filter(|p| p.y.abs() <= rule.strip_half_width && p.x >= from)
                    .map(|p| p.z),
            );
            if heights.len() < usize::from(SHOWS) {
                return None;
            }
            let k = ((heights.len() - 1) as f64 * rule.drop_quantile) as usize;
            let (_, q, _) = heights.select_nth_unstable_by(k, f64::total_cmp);
            return Some(((end - start) as f64 * rule.cell, -*q));
        }
        ix = end;
    }
    None
}

/// The height of a ledge ahead, if the nearest standing columns form one: in at least
/// `ledge_share` of the lateral rows that show points up to the farthest of them, with top
/// edges that agree within `ledge_spread` and lie at most `ledge_rise` above the sensor (a
/// plateau too high to climb whose face spans the view; a wall's columns end at the view's
/// upper edge instead).
fn ledge(rule: &GroundAhead, height: f64, scratch: &mut AheadScratch, nx: usize) -> Option<f64> {
    // Range noise scatters points along the beams, beyond the face and out to the side: only
    // cells up to the farthest front count.
    let reach = scratch.front.iter().flatten().map(|f| f.0).max()?;
    let rows = scratch
        .cell_points
        .chunks(nx)
        .filter(|row| row[..=reach].iter().any(|&n| n >= SHOWS))
        .count();
    let tops = &mut scratch.heights;
    tops.clear();
    tops.extend(scratch.front.iter().flatten().map(|f| f.1));
    if tops.is_empty() {
        return None;
    }
    tops.sort_by(f64::total_cmp);
    let at = |q: f64| tops[((tops.len() - 1) as f64 * q).round() as usize];
    let (low, median, high) = (at(0.1), at(0.5), at(0.9));
    let share = tops.len() as f64 / rows.max(1) as f64;
    let facts = &mut scratch.facts;
    (facts.front_share, facts.front_top, facts.front_spread) = (share, median, high - low);
    (share >= rule.ledge_share
        && high - low <= rule.ledge_spread
        && median <= height + rule.ledge_rise)
        .then_some(median)
}

/// A not-drivable obstacle with the floor as its plane and nothing counted.
fn base(points: usize, height: f64) -> Classification {
    not_drivable(Rule::AheadObstacle, points, Some(Plane { rho_x: 0.0, rho_y: 0.0, d: height }))
}

/// Whether a column holds something standing on `ground` higher than the robot's step.
fn stands(
    column: &[u8],
    ground: f64,
    least: u8,
    rule: &GroundAhead,
    limits: &RobotLimits,
    gap: usize,
) -> Option<f64> {
    let h0 = rule.min_height();
    let bin_of = |z: f64| ((z - h0) / rule.bin).floor().clamp(0.0, (BINS - 1) as f64) as usize;
    let occupied = |b: usize| column[b] >= least;
    // The run starts at an occupied bin within the floor band of the ground, or, where the
    // ground itself is hidden, at the lowest occupied bin no higher than a step above it.
    let lo = bin_of(ground - rule.floor_band);
    let top_start = bin_of(ground + limits.max_step);
    let start = (lo..=top_start).find(|&b| occupied(b))?;
    let mut top = start;
    let mut b = start + 1;
    while b < BINS && b <= top + gap + 1 {
        if occupied(b) {
            top = b;
        }
        b += 1;
    }
    let top_height = h0 + (top + 1) as f64 * rule.bin;
    (top_height > ground + limits.max_step + rule.bin).then_some(top_height)
}

/// The dominant plane among the off-floor points, if it is a surface (see the module docs).
fn find_surface(
    rule: &GroundAhead,
    scratch: &mut AheadScratch,
    cell_of: &dyn Fn(&Point3<f64>) -> usize,
    nx: usize,
) -> Option<Surface> {
    let cells = scratch.floor_cells.len();
    let off = &scratch.off;
    if off.len() < 3 {
        return None;
    }
    scratch.sample.clear();
    let stride = off.len().div_ceil(rule.sample).max(1);
    scratch.sample.extend(off.iter().step_by(stride).copied());
    let sample = &scratch.sample;
    if sample.len() < 3 {
        return None;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(rule.seed ^ off.len() as u64);
    let cos_steep = rule.steep_tilt.cos();
    let mut best: Option<(usize, Unit<Vector3<f64>>, f64)> = None;
    for _ in 0..rule.iterations {
        let (a, b, c) = (
            sample[rng.random_range(0..sample.len())],
            sample[rng.random_range(0..sample.len())],
            sample[rng.random_range(0..sample.len())],
        );
        let n = (b - a).cross(&(c - a));
        if n.norm() < 1e-9 {
            continue;
        }
        let mut n = Unit::new_normalize(n);
        if n.z < 0.0 {
            n = -n;
        }
        if n.z < cos_steep {
            // Ground only: a wall is no surface to drive on.
            continue;
        }
        let d = n.dot(&a.coords);
        let count =
            sample.iter().filter(|p| (n.dot(&p.coords) - d).abs() <= rule.plane_band).count();
        if best.is_none_or(|(c, _, _)| count > c) {
            best = Some((count, n, d));
        }
    }
    let (_, normal, distance) = best?;
    let coarse = BallPlane { normal, distance, votes: 0 };
    // The least-squares refinement may lean towards a step's face next to the plane; a refined
    // plane steeper than ground keeps the sampled one.
    let fine = refine_plane(sample, &coarse, 2.0 * rule.plane_band)
        .filter(|f| f.normal.z.abs() >= cos_steep)
        .unwrap_or(coarse);
    let n = fine.normal.into_inner();
    let on = |p: &&Point3<f64>| (n.dot(&p.coords) - fine.distance).abs() <= rule.plane_band;
    let mut count = 0usize;
    let (mut x_min, mut x_max, mut y_min, mut y_max) =
        (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    scratch.surface_cells.clear();
    scratch.surface_cells.resize(cells, 0);
    for p in off.iter().filter(on) {
        count += 1;
        x_min = x_min.min(p.x);
        x_max = x_max.max(p.x);
        y_min = y_min.min(p.y);
        y_max = y_max.max(p.y);
        let c = &mut scratch.surface_cells[cell_of(p)];
        *c = c.saturating_add(1);
    }
    let surface = Surface { normal: n, distance: fine.distance, points: count, x_min, x_max };
    scratch.facts.surface_candidate = count;
    if (count as f64) < rule.surface_share * off.len() as f64
        || y_max - y_min < rule.surface_width
        || surface.tilt() > rule.steep_tilt
    {
        return None;
    }
    // Floating: the floor shows in the cells it covers (more of it than of the surface), where
    // it lies clearly off the floor.
    // Patchy: within its extent, the cells that show points show it.
    let (mut covered, mut over_floor, mut occupied, mut shown) = (0usize, 0usize, 0usize, 0usize);
    for (c, (&on_surface, &on_floor)) in
        scratch.surface_cells.iter().zip(&scratch.floor_cells).enumerate()
    {
        let (x, y) = rule.cell_centre(c, nx);
        let inside = (x_min..=x_max).contains(&x) && (y_min..=y_max).contains(&y);
        let has_points = scratch.cell_points[c] >= SHOWS;
        if inside && has_points {
            occupied += 1;
        }
        if on_surface < SHOWS {
            continue;
        }
        covered += 1;
        if inside && has_points {
            shown += 1;
        }
        let apart = surface.height_at(x, y).is_some_and(|h| h.abs() > 2.0 * rule.floor_band);
        if apart && on_floor >= SHOWS.max(on_surface) {
            over_floor += 1;
        }
    }
    if over_floor as f64 > rule.max_floating * covered as f64 {
        scratch.facts.floating_surface = true;
        return None;
    }
    scratch.facts.surface_coverage = shown as f64 / occupied.max(1) as f64;
    if (shown as f64) < rule.min_coverage * occupied as f64 {
        return None;
    }
    Some(surface)
}
