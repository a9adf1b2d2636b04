//! Spherical range-image grids for unorganised scans, so that trimesh growing
//! ([`crate::trimesh_grow`], Alg 4 and 5) meshes their non-planar remainder too
//! ([`mesh_unorganised`], run by [`crate::pipeline::extract`] for scans without a pixel grid).
//!
//! **An addition beyond the thesis.** Its hybrid maps (§6.1) mesh the remainder of organised
//! scans only: Alg 4 and 5 grow over the triangles of a pixel grid. Real lidar scans often come
//! unorganised (3DTK `.3d` scans, KITTI-style `.bin` frames of spinning lidars), and their
//! hybrid maps were their planes maps (`patchnav experiment map-coverage`: 55–93 % of their
//! points within 3σ of a patch). A [`SphericalGrid`] gives such a cloud back the range image its
//! sensor sampled, and trimesh growing applies unchanged; with the splats below, every point
//! of those scans but a few per ten thousand lies within 3σ of a patch (`docs/map-safety.md`).
//!
//! # The grid
//! The cloud must be in its sensor frame (sensor at the origin; the pose is separate, in
//! [`PointCloud::sensor_pose`]). For an axis `a` of the sensor frame (one of `x`, `y`, `z`,
//! [`SensorAxis`]) and the two others `u`, `v` in cyclic order, a point `p` at range `r = |p|`
//! has the angle about the axis `φ = atan2(p·v, p·u)` (its column) and the angle from the plane
//! normal to the axis `ψ = asin(p·a / r)` (its row, highest first). A spinning lidar turns
//! about its `z` axis and fires its rings at fixed elevations: `φ` is the azimuth, `ψ` the
//! elevation. A nodding 2D scanner (3DTK's Kurt3D: a SICK scanner pitched about `y`) sweeps a
//! fan that turns about `y`: `φ` is the pitch, `ψ` the angle within the fan. Either way the
//! points lie on a lattice of `(φ, ψ)`.
//!
//! * **Axis.** Given ([`SphericalGridConfig::axis`]), or the one of the three whose grid at
//!   the estimated steps holds the most grid triangles (2×2-quad halves with three occupied
//!   corners) over the whole cloud: Z for the KITTI, SemanticKITTI and RELLIS frames, Y for the
//!   3DTK scans.
//! * **Steps.** Given in radians ([`AngularResolution::Fixed`]), or estimated
//!   ([`AngularResolution::Estimated`]): for up to 4,096 points (spread over the cloud, or over a
//!   window of 2¹⁹ points adjacent in `φ` for larger clouds, which keeps the local spacing), their
//!   32 nearest neighbours in `(φ, ψ)` are split into mostly-along-`φ` (`|Δφ| > |Δψ|`) and
//!   mostly-along-`ψ` ones; the column step is the median over the points of the smallest `|Δφ|`
//!   of the first kind, the row step the median of the smallest `|Δψ|` of the second kind,
//!   both times `scale`. Neighbours on adjacent rings that are staggered in `φ` are
//!   mostly-along-`ψ`, so the column step is the spacing *within* a ring, and no ring is left
//!   with every other cell empty. (Measured: 0.176° × 0.535° for the RELLIS OS1-64, 2048 × 64
//!   cells; 0.517° × 0.500° for the Kurt3D scans.)
//! * **Rows** follow the rings, which need not be evenly spaced (the HDL-64E's upper block is
//!   1/3° apart, its lower block 1/2°; uniform rows left a row empty every few rings, and the
//!   rings on either side without triangles): on a histogram of `ψ`, rows end at the valleys
//!   between its peaks; a band without valleys (rings blurred together) or a gap without points
//!   is cut into rows one step wide.
//! * **Columns.** The first column starts after the widest empty interval of `φ` (a partial
//!   field of view gives a grid only as wide as its data; a full turn puts its seam where the
//!   data are sparsest); each row's columns are centred on that row's own lattice of `φ` (the
//!   circular mean of `φ` modulo the step: rings of spinning lidars are staggered in azimuth),
//!   so a point goes to the nearest lattice node and points on the lattice never straddle two
//!   cells.
//! * **Collisions.** A cell keeps its nearest point (the first surface along the beam);
//!   [`BinnedCloud::dropped`] lists the others. Rings whose elevation seen from the origin
//!   drifts with range (the HDL-64E's lasers sit up to ~0.2 m off its origin, and
//!   SemanticKITTI's scan is tilted ~0.75° against its `z` axis) overlap in `ψ`: about 15 % of
//!   that scan's remainder shares a cell; those points are left to the splats.
//! * **Bounded size.** The grid never has more than [`SphericalGridConfig::max_cells`] cells:
//!   estimated steps are coarsened until it fits, given steps that do not fit are refused
//!   ([`SphericalGridError::TooManyCells`]) before anything grid-sized is allocated. Memory is
//!   `O(n)` for the cloud's angles plus `O(max_cells)` for the grid (trimesh growing needs
//!   about 60 bytes a cell).
//!
//! # Edges at range
//! Trimesh growing refuses sides of at least `θ_s` (phase 2) and `phase1_max_side` (phase 1),
//! fixed lengths in metres. Neighbouring beams of a spinning lidar are `r · Δ` apart (KITTI's
//! HDL-64E: 0.15 m at 20 m, 0.35 m at 50 m), so fixed limits stop meshing at range.
//! [`SphericalGridConfig::max_side_steps`] lets both limits grow with range
//! ([`crate::trimesh_grow::TrimeshGrowConfig::side_per_range`] = steps × the larger angular
//! step): phase 2 also accepts a side shorter than `max_side_steps · Δ · r` at the range `r`
//! of its nearer end. A side of a surface seen at incidence `λ` (between surface and beam) is
//! about `r · Δ / sin λ` long, so 3 steps accept surfaces down to `λ ≈ 20°`; a depth jump
//! between a near and a far surface is bridged only below `3 · Δ · r` (2.8 % of the range with
//! the OS1-64's 0.535° rings) or below `θ_s`. `None` keeps the fixed limits.
//!
//! # Splats
//! What the meshes leave out is mostly far ground between rings (seen at a few degrees of
//! incidence, its rings are metres apart) and vegetation, whose neighbouring returns lie at
//! unrelated depths: meshing them needs sides of 10–20 steps, which would equally bridge a
//! post and the wall behind it. Such a point gets a splat instead ([`mesh_unorganised`]): a
//! triangle facing the sensor, centred on it, at most 0.45 steps across, so that it stays
//! between the neighbouring beams; points within `splat_sigmas · σ(r)` of a mesh vertex or of
//! an earlier splat need none. Splats of the full `3σ(r)` radius were measured to block the
//! beams of 11,000 of the 81,000 points of a Kurt3D scan (beams that reached farther than the
//! splat, i.e. saw free space where it is); footprint-sized ones block 254.
//!
//! # Complexity
//! `O(n log n)` for the seam (a sort of `φ`) and the estimation (a k-d tree of at most 2¹⁹
//! points), `O(n + cells)` for binning and growing; automatic axis choice fits three grids.

use crate::trimesh_grow::{GrownTrimeshes, TrimeshGrowConfig, TrimeshGrowError, grow_trimeshes};
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use patch_core::{Point3, Real, TrimeshPatch, Vector3};
use pointcloud::{AttributeError, INVALID_PIXEL, PointCloud};
use std::collections::{BTreeMap, HashMap, HashSet};
use std::f64::consts::TAU;
use std::num::NonZeroUsize;

/// Smallest angular step accepted, radians (about 0.0006°).
pub const MIN_STEP: Real = 1e-5;
/// Largest angular step accepted, radians (about 28.6°).
pub const MAX_STEP: Real = 0.5;
/// Largest [`SphericalGridConfig::max_cells`] accepted (2²⁸ cells, about 16 GB of trimesh
/// growing state: beyond any sensor).
pub const MAX_CELLS_LIMIT: usize = 1 << 28;
/// Smallest [`SphericalGridConfig::max_cells`] accepted.
pub const MIN_CELLS: usize = 16;
/// Points adjacent in `φ` that the step estimation looks at, at most.
const ESTIMATION_WINDOW: usize = 1 << 19;
/// Points whose neighbourhoods the step estimation looks at, at most.
const ESTIMATION_QUERIES: usize = 4096;
/// Neighbours per query point.
const ESTIMATION_NEIGHBOURS: usize = 32;
/// Fewest spacings a median is taken over.
const MIN_SPACINGS: usize = 8;

/// An axis of the sensor frame, the one the sensor turns about.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum SensorAxis {
    /// `x`: `φ = atan2(z, y)`, `ψ = asin(x / r)`.
    X,
    /// `y` (a scanner nodding about its left axis): `φ = atan2(x, z)`, `ψ = asin(y / r)`.
    Y,
    /// `z` (a spinning lidar): `φ = atan2(y, x)` the azimuth, `ψ = asin(z / r)` the elevation.
    Z,
}

impl SensorAxis {
    /// The three axes, in the order automatic choice prefers them on ties.
    pub const ALL: [SensorAxis; 3] = [SensorAxis::Z, SensorAxis::Y, SensorAxis::X];

    /// `(φ, ψ)` of `p` at range `r > 0`.
    fn angles(self, p: &Point3, r: Real) -> (Real, Real) {
        let (u, v, a) = match self {
            SensorAxis::X => (p.y, p.z, p.x),
            SensorAxis::Y => (p.z, p.x, p.y),
            SensorAxis::Z => (p.x, p.y, p.z),
        };
        (v.atan2(u), (a / r).clamp(-1.0, 1.0).asin())
    }
}

/// How the grid's angular steps are chosen.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum AngularResolution {
    /// Estimated from the cloud (see the module docs), times `scale` (1 keeps the sensor's
    /// spacing; above 1 gives smaller meshes, whose triangles reach across the dropped
    /// points' beams).
    Estimated {
        /// Factor on both estimated steps, in `[0.25, 8]`.
        scale: Real,
    },
    /// Given steps, radians, each in `[MIN_STEP, MAX_STEP]`.
    Fixed {
        /// Step of `φ` between columns.
        column: Real,
        /// Step of `ψ` between rows.
        row: Real,
    },
}

/// Parameters of [`SphericalGrid::fit`] and [`mesh_unorganised`]. No `Default`: start from
/// [`SphericalGridConfig::estimated`] or [`SphericalGridConfig::fixed`].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct SphericalGridConfig {
    /// The axis the sensor turns about; `None`: the axis whose grid holds the most triangles.
    pub axis: Option<SensorAxis>,
    /// The angular steps.
    pub resolution: AngularResolution,
    /// Points nearer the sensor are left out (their angles are unreliable), metres, `≥ 0`.
    pub min_range: Real,
    /// Most cells of the grid, in `[MIN_CELLS, MAX_CELLS_LIMIT]`.
    pub max_cells: usize,
    /// Trimesh side limits grow with range: a side is also accepted when shorter than this
    /// many grid steps at the range of its nearer end (see the module docs); `None`: the fixed
    /// limits of the [`TrimeshGrowConfig`]. Positive, at most 1000.
    pub max_side_steps: Option<Real>,
    /// Replaces the [`TrimeshGrowConfig::min_triangles`] for binned scans (a small object
    /// seen by a sparse lidar is a mesh of one or two triangles); `None` keeps it.
    pub min_triangles: Option<usize>,
    /// Every remainder point beyond `min_range` ends up within `splat_sigmas · σ(r)` of a
    /// patch: the points the meshes leave farther away get splats (see [`mesh_unorganised`]).
    /// `None`: no splats (1–19 % of the real lidar scans' points then stay uncovered).
    /// Positive, at most 100.
    pub splat_sigmas: Option<Real>,
}

impl SphericalGridConfig {
    /// Estimated steps at the sensor's spacing (`scale` 1), the axis chosen by the data, points
    /// from 1 cm, at most 2²¹ cells (about 125 MB of trimesh growing state; the real scans need
    /// at most 132,000), side limits growing to 3 steps at range, meshes from one triangle,
    /// splats within 3σ.
    ///
    /// Measured on the real scans of `patchnav experiment map-coverage` (`docs/map-safety.md`):
    /// 10 steps instead of 3 leave 3,000 splats instead of 8,100 on the OS1-64 frame, but
    /// bridge depth jumps three times as deep for the same map bytes, and the SemanticKITTI
    /// frame's meshes block the beams of 683 points instead of 281 (beams that passed the
    /// triangle and returned from farther); a grid twice as coarse (`scale` 2) halves the
    /// meshes' bytes, but its triangles block the beams of up to 5,300 points.
    pub fn estimated() -> SphericalGridConfig {
        SphericalGridConfig {
            axis: None,
            resolution: AngularResolution::Estimated { scale: 1.0 },
            min_range: 0.01,
            max_cells: 1 << 21,
            max_side_steps: Some(3.0),
            min_triangles: Some(1),
            splat_sigmas: Some(3.0),
        }
    }

    /// Given steps (radians) about a given axis, otherwise as [`SphericalGridConfig::estimated`].
    ///
    /// # Errors
    /// [`SphericalGridError::BadParameter`] for steps outside `[MIN_STEP, MAX_STEP]`.
    pub fn fixed(
        axis: SensorAxis,
        column: Real,
        row: Real,
    ) -> Result<SphericalGridConfig, SphericalGridError> {
        let config = SphericalGridConfig {
            axis: Some(axis),
            resolution: AngularResolution::Fixed { column, row },
            ..SphericalGridConfig::estimated()
        };
        config.validate()?;
        Ok(config)
    }

    /// Checks the fields (for configurations built as struct literals).
    ///
    /// # Errors
    /// [`SphericalGridError::BadParameter`], [`SphericalGridError::MaxCells`].
    pub fn validate(&self) -> Result<(), SphericalGridError> {
        let check = |name: &'static str, value: Real, lo: Real, hi: Real, expected| {
            if value.is_finite() && (lo..=hi).contains(&value) {
                Ok(())
            } else {
                Err(SphericalGridError::BadParameter { name, value, expected })
            }
        };
        match self.resolution {
            AngularResolution::Estimated { scale } => {
                check("scale", scale, 0.25, 8.0, "in [0.25, 8]")?;
            }
            AngularResolution::Fixed { column, row } => {
                let expected = "in [1e-5, 0.5] radians";
                check("column step", column, MIN_STEP, MAX_STEP, expected)?;
                check("row step", row, MIN_STEP, MAX_STEP, expected)?;
            }
        }
        check("min_range", self.min_range, 0.0, Real::MAX, "finite and ≥ 0")?;
        if let Some(steps) = self.max_side_steps
            && !(steps > 0.0 && steps <= 1000.0)
        {
            return Err(SphericalGridError::BadParameter {
                name: "max_side_steps",
                value: steps,
                expected: "positive and at most 1000",
            });
        }
        if let Some(sigmas) = self.splat_sigmas
            && !(sigmas > 0.0 && sigmas <= 100.0)
        {
            return Err(SphericalGridError::BadParameter {
                name: "splat_sigmas",
                value: sigmas,
                expected: "positive and at most 100",
            });
        }
        if self.min_triangles == Some(0) {
            return Err(SphericalGridError::BadParameter {
                name: "min_triangles",
                value: 0.0,
                expected: "at least 1",
            });
        }
        if !(MIN_CELLS..=MAX_CELLS_LIMIT).contains(&self.max_cells) {
            return Err(SphericalGridError::MaxCells(self.max_cells));
        }
        Ok(())
    }
}

/// Why a spherical grid could not be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SphericalGridError {
    /// A parameter is NaN, infinite or out of its range.
    #[error("spherical grid parameter {name} = {value}: must be {expected}")]
    BadParameter {
        /// The parameter.
        name: &'static str,
        /// Its value.
        value: Real,
        /// What it must be.
        expected: &'static str,
    },
    /// `max_cells` is out of range.
    #[error("spherical grid max_cells = {0}: need 16 ≤ max_cells ≤ 2^28")]
    MaxCells(usize),
    /// Given steps would make a grid larger than `max_cells`.
    #[error(
        "the spherical grid would have {width} × {height} cells, more than max_cells = {max_cells}"
    )]
    TooManyCells {
        /// Columns (rounded up).
        width: Real,
        /// Rows (rounded up).
        height: Real,
        /// The limit.
        max_cells: usize,
    },
    /// A position is NaN or infinite.
    #[error("point {index} is not finite")]
    NonFinite {
        /// Its index.
        index: usize,
    },
    /// An index names no point.
    #[error("point index {index} is beyond the {len} points")]
    IndexOutOfRange {
        /// The index.
        index: u32,
        /// The number of points.
        len: usize,
    },
    /// No point lies farther than `min_range` from the sensor.
    #[error("no point farther than min_range from the sensor")]
    Empty,
    /// The points' angular spacing cannot be estimated (too few points, all on one ray).
    #[error("the angular spacing of {points} points cannot be estimated")]
    Unresolvable {
        /// Points farther than `min_range`.
        points: usize,
    },
    /// The binned cloud was refused (a bug: binned points are finite and distinct).
    #[error(transparent)]
    Cloud(#[from] AttributeError),
    /// Trimesh growing refused its parameters.
    #[error("trimesh growing: {0}")]
    Trimesh(#[from] TrimeshGrowError),
}

impl SphericalGridError {
    /// Whether the error is about the cloud's content (empty, no spacing to estimate), not
    /// about the parameters: the pipeline meshes nothing for such a scan and goes on.
    pub fn is_content_error(&self) -> bool {
        matches!(self, SphericalGridError::Empty | SphericalGridError::Unresolvable { .. })
    }
}

/// A lattice of `(φ, ψ)` cells fitted to a cloud: which cell each point falls in.
#[derive(Clone, Debug, PartialEq)]
pub struct SphericalGrid {
    axis: SensorAxis,
    column_step: Real,
    row_step: Real,
    /// `φ` where the first column starts; `φ' = (φ − seam) mod 2π`.
    seam: Real,
    /// The rows' bounds of `ψ`, ascending: row `height − 1 − k` holds `[edges[k], edges[k + 1])`.
    row_edges: Vec<Real>,
    /// Per row: its columns are centred at `phase + j · column_step` (in `φ'`), column `j − j_min`.
    column_phases: Vec<Real>,
    j_min: i64,
    width: u32,
    height: u32,
    min_range: Real,
}

/// The points of a cloud binned into a [`SphericalGrid`]: an organised cloud (in the same
/// frame) and, per point of it, the index of the point in the input.
#[derive(Clone, Debug)]
pub struct BinnedCloud {
    /// The organised cloud: one point per occupied cell, the nearest of the cell's points.
    pub cloud: PointCloud,
    /// Per point of `cloud`, its index in the binned positions.
    pub source: Vec<u32>,
    /// Points (indices into the binned positions) dropped because a nearer point shared their
    /// cell, in the order they were dropped.
    pub dropped: Vec<u32>,
    /// Points outside the grid or nearer than `min_range`.
    pub outside: usize,
}

impl SphericalGrid {
    /// The grid of the points `positions` (in their sensor frame), see the module docs.
    ///
    /// # Errors
    /// [`SphericalGridError`]: bad parameters, a non-finite position, given steps whose grid
    /// exceeds `max_cells`, no point beyond `min_range` ([`SphericalGridError::Empty`]), a
    /// spacing that cannot be estimated.
    pub fn fit(
        positions: &[Point3],
        config: &SphericalGridConfig,
    ) -> Result<SphericalGrid, SphericalGridError> {
        config.validate()?;
        let mut valid: Vec<(u32, Real)> = Vec::with_capacity(positions.len());
        for (index, p) in positions.iter().enumerate() {
            if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
                return Err(SphericalGridError::NonFinite { index });
            }
            let r = p.coords.norm();
            if r > config.min_range && r > 0.0 && index <= u32::MAX as usize {
                valid.push((index as u32, r));
            }
        }
        if valid.is_empty() {
            return Err(SphericalGridError::Empty);
        }
        let Some(axis) = config.axis else {
            // The axis whose grid at the sensor's own spacing holds the most triangles (a
            // coarser `scale` would blur the comparison), then the grid asked for on it.
            let probe = match config.resolution {
                AngularResolution::Estimated { .. } => SphericalGridConfig {
                    resolution: AngularResolution::Estimated { scale: 1.0 },
                    ..*config
                },
                AngularResolution::Fixed { .. } => *config,
            };
            let mut best: Option<(usize, SphericalGrid)> = None;
            let mut first_error = None;
            for axis in SensorAxis::ALL {
                match fit_axis(positions, &valid, axis, &probe) {
                    Ok(grid) => {
                        let score = grid.triangles(positions, &valid);
                        if best.as_ref().is_none_or(|(s, _)| score > *s) {
                            best = Some((score, grid));
                        }
                    }
                    Err(e) => {
                        first_error.get_or_insert(e);
                    }
                }
            }
            return match (best, first_error) {
                (Some((_, grid)), _) if probe == *config => Ok(grid),
                (Some((_, grid)), _) => fit_axis(positions, &valid, grid.axis, config),
                (None, Some(e)) => Err(e),
                (None, None) => Err(SphericalGridError::Unresolvable { points: valid.len() }),
            };
        };
        fit_axis(positions, &valid, axis, config)
    }

    /// The axis the grid turns about.
    pub fn axis(&self) -> SensorAxis {
        self.axis
    }

    /// Step of `φ` between columns, radians.
    pub fn column_step(&self) -> Real {
        self.column_step
    }

    /// Step of `ψ` between rows, radians.
    pub fn row_step(&self) -> Real {
        self.row_step
    }

    /// Columns.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Rows.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The cell `(column, row)` of `p` (sensor frame), or `None` outside the grid, nearer than
    /// `min_range` or not finite.
    pub fn cell(&self, p: &Point3) -> Option<(u32, u32)> {
        let r = p.coords.norm();
        if !(r.is_finite() && r > self.min_range && r > 0.0) {
            return None;
        }
        let (phi, psi) = self.axis.angles(p, r);
        self.cell_of_angles(phi, psi)
    }

    fn cell_of_angles(&self, phi: Real, psi: Real) -> Option<(u32, u32)> {
        let above = self.row_edges.partition_point(|&e| e <= psi);
        if above == 0 || above >= self.row_edges.len() {
            return None;
        }
        let row = (self.row_edges.len() - 1 - above) as u32;
        let phi = wrapped(phi - self.seam);
        let j = ((phi - self.column_phases[row as usize]) / self.column_step).round();
        let col = j - self.j_min as Real;
        if !(col >= 0.0 && col < self.width as Real) {
            return None;
        }
        Some((col as u32, row))
    }

    /// Bins the points `indices` of `positions` (e.g. a segmentation's remainder): each cell
    /// keeps its nearest point.
    ///
    /// # Errors
    /// [`SphericalGridError::IndexOutOfRange`], [`SphericalGridError::NonFinite`].
    pub fn bin(
        &self,
        positions: &[Point3],
        indices: &[u32],
    ) -> Result<BinnedCloud, SphericalGridError> {
        let w = self.width as usize;
        let mut pixels = vec![INVALID_PIXEL; w * self.height as usize];
        let (mut dropped, mut outside) = (Vec::new(), 0);
        for &index in indices {
            let p = positions
                .get(index as usize)
                .ok_or(SphericalGridError::IndexOutOfRange { index, len: positions.len() })?;
            if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
                return Err(SphericalGridError::NonFinite { index: index as usize });
            }
            let Some((c, r)) = self.cell(p) else {
                outside += 1;
                continue;
            };
            let slot = &mut pixels[r as usize * w + c as usize];
            if *slot == INVALID_PIXEL {
                *slot = index;
                continue;
            }
            let (rp, ro) = (p.coords.norm(), positions[*slot as usize].coords.norm());
            if rp < ro || (rp == ro && index < *slot) {
                dropped.push(std::mem::replace(slot, index));
            } else {
                dropped.push(index);
            }
        }
        let source: Vec<u32> = pixels.iter().copied().filter(|&p| p != INVALID_PIXEL).collect();
        let cloud = PointCloud::from_pixels(
            self.width,
            self.height,
            pixels.iter().map(|&p| (p != INVALID_PIXEL).then(|| positions[p as usize])),
        )?;
        Ok(BinnedCloud { cloud, source, dropped, outside })
    }

    /// `grow` with its side limits growing with range as `config.max_side_steps` asks (see the
    /// module docs) and `config.min_triangles`; each left as in `grow` when `None`.
    pub fn grow_config(
        &self,
        grow: &TrimeshGrowConfig,
        config: &SphericalGridConfig,
    ) -> TrimeshGrowConfig {
        TrimeshGrowConfig {
            side_per_range: config
                .max_side_steps
                .map(|steps| steps * self.column_step.max(self.row_step))
                .or(grow.side_per_range),
            min_triangles: config.min_triangles.unwrap_or(grow.min_triangles),
            ..*grow
        }
    }

    /// Grid triangles (2×2 quads' halves with three occupied corners) when the points `valid`
    /// are binned: how well the grid fits the sampling.
    fn triangles(&self, positions: &[Point3], valid: &[(u32, Real)]) -> usize {
        let (w, h) = (self.width as usize, self.height as usize);
        let mut occupied = vec![false; w * h];
        for &(i, r) in valid {
            let (phi, psi) = self.axis.angles(&positions[i as usize], r);
            if let Some((c, r)) = self.cell_of_angles(phi, psi) {
                occupied[r as usize * w + c as usize] = true;
            }
        }
        let mut count = 0;
        for r in 0..h.saturating_sub(1) {
            for c in 0..w.saturating_sub(1) {
                let at = |c: usize, r: usize| occupied[r * w + c];
                let (tl, tr, bl, br) = (at(c, r), at(c + 1, r), at(c, r + 1), at(c + 1, r + 1));
                count += usize::from(tl && bl && tr) + usize::from(tr && bl && br);
            }
        }
        count
    }
}

/// `x` wrapped into `[0, 2π)`.
fn wrapped(x: Real) -> Real {
    let y = x.rem_euclid(TAU);
    if y >= TAU { 0.0 } else { y }
}

/// The phase in `[0, step)` of the lattice `phase + k · step` that the values sit on best
/// (their circular mean modulo `step`).
fn lattice_phase(sin_sum: Real, cos_sum: Real, step: Real) -> Real {
    if sin_sum == 0.0 && cos_sum == 0.0 {
        return 0.0;
    }
    (sin_sum.atan2(cos_sum) / TAU * step).rem_euclid(step).min(step * (1.0 - Real::EPSILON))
}

fn fit_axis(
    positions: &[Point3],
    valid: &[(u32, Real)],
    axis: SensorAxis,
    config: &SphericalGridConfig,
) -> Result<SphericalGrid, SphericalGridError> {
    let mut angles: Vec<(Real, Real)> =
        valid.iter().map(|&(i, r)| axis.angles(&positions[i as usize], r)).collect();
    // The seam: after the widest empty interval of φ.
    let mut order: Vec<u32> = (0..angles.len() as u32).collect();
    order.sort_unstable_by(|&a, &b| angles[a as usize].0.total_cmp(&angles[b as usize].0));
    let phi_at = |k: usize| angles[order[k] as usize].0;
    let n = order.len();
    let (mut gap, mut start) = (phi_at(0) + TAU - phi_at(n - 1), 0);
    for k in 1..n {
        if phi_at(k) - phi_at(k - 1) > gap {
            (gap, start) = (phi_at(k) - phi_at(k - 1), k);
        }
    }
    let seam = phi_at(start);
    // From here on `φ' = φ − seam`, in place (clouds of 10⁷ points: no second copy).
    for a in &mut angles {
        a.0 = wrapped(a.0 - seam);
    }
    let local = angles;
    // `order` rotated to start at the seam is `local` sorted by φ'.
    order.rotate_left(start);

    let (mut column_step, mut row_step) = match config.resolution {
        AngularResolution::Fixed { column, row } => (column, row),
        AngularResolution::Estimated { scale } => {
            let (c, r) = estimate_steps(&local, &order)
                .ok_or(SphericalGridError::Unresolvable { points: valid.len() })?;
            ((c * scale).clamp(MIN_STEP, MAX_STEP), (r * scale).clamp(MIN_STEP, MAX_STEP))
        }
    };
    let phi_max = local.iter().map(|a| a.0).fold(0.0, Real::max);
    let psi_min = local.iter().map(|a| a.1).fold(Real::INFINITY, Real::min);
    let psi_max = local.iter().map(|a| a.1).fold(Real::NEG_INFINITY, Real::max);
    // Size bound before anything grid-sized is allocated: columns ≤ ⌊φ'max / step⌋ + 3 (a
    // row's lattice phase moves its columns by less than a step); the rows are found on a
    // histogram of at most 2¹⁶ bins. Coarsening multiplies both steps by more than 1.01 a
    // round, so it ends (3 × 1 cells fit MIN_CELLS); the round limit is a guard.
    let mut round = 0;
    let row_edges = loop {
        let width = (phi_max / column_step).floor() + 3.0;
        let edges = (width <= config.max_cells as Real)
            .then(|| row_edges(&local, row_step, psi_min, psi_max));
        let height = edges.as_ref().map_or(1.0, |e| (e.len() - 1) as Real);
        if let Some(edges) = edges
            && width * height <= config.max_cells as Real
        {
            break edges;
        }
        match config.resolution {
            AngularResolution::Estimated { .. } if round < 10_000 => {
                let factor = (width * height / config.max_cells as Real).sqrt().max(1.0) * 1.01;
                column_step *= factor;
                row_step *= factor;
                round += 1;
            }
            _ => {
                return Err(SphericalGridError::TooManyCells {
                    width,
                    height,
                    max_cells: config.max_cells,
                });
            }
        }
    };
    let height = row_edges.len() - 1;
    let row_of = |psi: Real| height - row_edges.partition_point(|&e| e <= psi).clamp(1, height);
    let mut sums = vec![(0.0, 0.0); height];
    for &(phi, psi) in &local {
        let row = row_of(psi);
        let t = TAU * phi / column_step;
        sums[row].0 += t.sin();
        sums[row].1 += t.cos();
    }
    let column_phases: Vec<Real> =
        sums.iter().map(|&(s, c)| lattice_phase(s, c, column_step)).collect();
    let (mut j_min, mut j_max) = (i64::MAX, i64::MIN);
    for &(phi, psi) in &local {
        let row = row_of(psi);
        let j = ((phi - column_phases[row]) / column_step).round() as i64;
        j_min = j_min.min(j);
        j_max = j_max.max(j);
    }
    let width = (j_max - j_min + 1) as usize;
    if width * height > config.max_cells {
        // Unreachable by the bound above; refused rather than trusted.
        return Err(SphericalGridError::TooManyCells {
            width: width as Real,
            height: height as Real,
            max_cells: config.max_cells,
        });
    }
    Ok(SphericalGrid {
        axis,
        column_step,
        row_step,
        seam,
        row_edges,
        column_phases,
        j_min,
        width: width as u32,
        height: height as u32,
        min_range: config.min_range,
    })
}

/// The bounds of the rows (ascending, one more than the rows), so that each ring of the
/// sensor falls into one row although rings need not be evenly spaced (the HDL-64E's upper
/// block is 1/3° apart, its lower block 1/2°).
///
/// On a histogram of `ψ` (bins of `row_step / 8`, smoothed over 5 bins), peaks separated by a
/// valley at most half as high as the lower of the two are rings; rows end at the valleys.
/// A row wider than 1.5 row steps (a blurred band of rings, or a gap without points) is cut
/// into rows one step wide centred on its peak; rows narrower than half a step are merged
/// into the previous one.
fn row_edges(local: &[(Real, Real)], row_step: Real, psi_min: Real, psi_max: Real) -> Vec<Real> {
    let span = psi_max - psi_min;
    let bin = (row_step / 8.0).max(span / 65536.0).max(MIN_STEP * 1e-3);
    let bins = ((span / bin) as usize + 1).clamp(1, 65537);
    let mut hist = vec![0.0; bins];
    for &(_, psi) in local {
        hist[(((psi - psi_min) / bin) as usize).min(bins - 1)] += 1.0;
    }
    let smooth: Vec<Real> = (0..bins)
        .map(|k| {
            (k.saturating_sub(2)..(k + 3).min(bins))
                .map(|j| (3 - k.abs_diff(j)) as Real * hist[j])
                .sum::<Real>()
                / 9.0
        })
        .collect();
    let argmin = |a: usize, b: usize| (a..=b).min_by(|&x, &y| smooth[x].total_cmp(&smooth[y]));
    // Peaks kept so far and the valleys between them (`valleys[i]` between `peaks[i]` and
    // `peaks[i + 1]`).
    let (mut peaks, mut valleys): (Vec<usize>, Vec<usize>) = (Vec::new(), Vec::new());
    for m in (0..bins).filter(|&k| {
        smooth[k] > 0.0
            && (k == 0 || smooth[k] > smooth[k - 1])
            && (k + 1 == bins || smooth[k] >= smooth[k + 1])
    }) {
        loop {
            let Some(&top) = peaks.last() else {
                peaks.push(m);
                break;
            };
            let v = argmin(top, m).unwrap_or(top);
            if smooth[v] <= 0.5 * smooth[top].min(smooth[m]) {
                valleys.push(v);
                peaks.push(m);
                break;
            }
            if smooth[m] <= smooth[top] {
                break; // `m` is a shoulder of `top`
            }
            peaks.pop(); // `top` is a shoulder of `m`
            valleys.pop();
        }
    }
    let at = |k: usize| psi_min + (k as Real + 0.5) * bin;
    // The outer rows reach half a step beyond the data, as wide as the inner ones.
    let mut edges = vec![psi_min - 0.5 * row_step];
    for (i, &peak) in peaks.iter().enumerate() {
        let low = *edges.last().unwrap_or(&psi_min);
        let high = valleys.get(i).map_or(psi_max + 0.5 * row_step, |&v| at(v));
        // Cuts one step apart, centred on the peak, inside (low, high).
        let centre = at(peak);
        let first = ((low - centre) / row_step - 0.5).floor() as i64 + 1;
        let last = ((high - centre) / row_step - 0.5).ceil() as i64 - 1;
        if high - low > 1.5 * row_step {
            for k in first..=last {
                edges.push(centre + (k as Real + 0.5) * row_step);
            }
        }
        edges.push(high);
    }
    if peaks.is_empty() {
        edges.push(psi_max + 0.5 * row_step);
    }
    // Merge rows narrower than half a step into the previous one.
    let mut merged = vec![edges[0]];
    for &e in &edges[1..] {
        if e - merged[merged.len() - 1] >= 0.5 * row_step || merged.len() == 1 {
            merged.push(e);
        } else {
            let last = merged.len() - 1;
            merged[last] = e;
        }
    }
    merged.dedup();
    merged
}

/// The spacing of the points `angles` (`(φ', ψ)`, `sorted` their indices by `φ'`) along `φ`
/// and along `ψ` (see the module docs), or `None` without enough distinct neighbours.
fn estimate_steps(angles: &[(Real, Real)], sorted: &[u32]) -> Option<(Real, Real)> {
    let window = if sorted.len() > ESTIMATION_WINDOW {
        let start = (sorted.len() - ESTIMATION_WINDOW) / 2;
        &sorted[start..start + ESTIMATION_WINDOW]
    } else {
        sorted
    };
    let coords: Vec<[Real; 2]> =
        window.iter().map(|&i| [angles[i as usize].0, angles[i as usize].1]).collect();
    let tree = ImmutableKdTree::<Real, 2>::new_from_slice(&coords).ok()?;
    let stride = coords.len().div_ceil(ESTIMATION_QUERIES).max(1);
    let qty = NonZeroUsize::new(ESTIMATION_NEIGHBOURS + 1).unwrap_or(NonZeroUsize::MIN);
    let (mut along_phi, mut along_psi) = (Vec::new(), Vec::new());
    for q in coords.iter().step_by(stride) {
        let (mut h, mut v) = (Real::INFINITY, Real::INFINITY);
        for found in tree.query(q).nearest_n::<SquaredEuclidean<Real>>(qty).execute() {
            let o = coords[found.item as usize];
            let (dphi, dpsi) = ((o[0] - q[0]).abs(), (o[1] - q[1]).abs());
            if dphi.max(dpsi) < MIN_STEP * 1e-3 {
                continue; // itself, or a duplicate direction
            }
            if dphi > dpsi {
                h = h.min(dphi);
            } else {
                v = v.min(dpsi);
            }
        }
        if h.is_finite() {
            along_phi.push(h);
        }
        if v.is_finite() {
            along_psi.push(v);
        }
    }
    let median = |mut v: Vec<Real>| -> Option<Real> {
        if v.len() < MIN_SPACINGS {
            return None;
        }
        let mid = v.len() / 2;
        let (_, m, _) = v.select_nth_unstable_by(mid, Real::total_cmp);
        Some(*m)
    };
    match (median(along_phi), median(along_psi)) {
        (Some(c), Some(r)) => Some((c, r)),
        (Some(s), None) | (None, Some(s)) => Some((s, s)),
        (None, None) => None,
    }
}

/// Smallest splat circumradius and tolerance, metres.
pub const MIN_SPLAT_RADIUS: Real = 0.001;
/// A splat's circumradius at range `r` is at most this share of `r ·` the smaller angular
/// step: it never reaches the neighbouring beams, so no beam that saw free space passes
/// through it.
const SPLAT_FOOTPRINT: Real = 0.45;
/// Edge of the cubes splats and small meshes are grouped by into patches, metres.
const GROUP_CUBE: Real = 4.0;

/// What [`mesh_unorganised`] made, in the cloud's (sensor) frame.
#[derive(Clone, Debug, Default)]
pub struct UnorganisedMeshes {
    /// The meshes grown on the binned remainder with at least the [`TrimeshGrowConfig`]'s
    /// `min_triangles` (its `stats` count all of them).
    pub grown: GrownTrimeshes,
    /// The splats and the smaller grown meshes ([`SphericalGridConfig::min_triangles`] lets
    /// them grow), grouped into patches by 4 m cubes (each at most `max_triangles`), so that
    /// a thousand scattered triangles are tens of patches, not a thousand.
    pub scattered: Vec<TrimeshPatch>,
    /// Splats (one triangle each) in `scattered`.
    pub splat_triangles: usize,
    /// Remainder points that got a grid cell.
    pub binned: usize,
    /// The grid, when one was made.
    pub grid: Option<SphericalGrid>,
}

/// Meshes the points `remainder` of the unorganised cloud `positions` (its sensor frame, the
/// whole scan: the grid is fitted to all of it): the remainder is binned into the
/// [`SphericalGrid`] ([`SphericalGrid::bin`]), and trimesh growing ([`crate::trimesh_grow`],
/// with [`SphericalGrid::grow_config`]) runs on the binned cloud. Meshes and splats are in
/// the sensor frame.
///
/// With [`SphericalGridConfig::splat_sigmas`] `= Some(k)`, every remainder point (beyond
/// `min_range`) ends up within its tolerance `t(r) = max(k · σ(r), 1 mm)` of a patch (`σ` the
/// range noise the caller passes, `r` the point's range): a point that is no mesh vertex, has
/// no mesh vertex within `t` among its grid neighbours (for a dropped point: its cell's and
/// their neighbours) and lies farther than `t` from every earlier splat's centre gets a splat,
/// a triangle facing the sensor centred on it, of circumradius `0.45 · r · Δ` (`Δ` the smaller
/// angular step; at most `t`, at least 1 mm): it stays between the neighbouring beams. A
/// return no surface explains (a leaf, a wire, a far return between rings) so stays in the map
/// as an obstacle the size of its beam, rather than being bridged to its neighbours by a long
/// triangle through free space.
///
/// A cloud whose content gives no grid (no point beyond `min_range`, no spacing to estimate)
/// gives nothing.
///
/// # Errors
/// [`SphericalGridError`] for bad parameters (of the grid or of trimesh growing), an index
/// out of range or a non-finite position.
pub fn mesh_unorganised(
    positions: &[Point3],
    remainder: &[u32],
    config: &SphericalGridConfig,
    grow: &TrimeshGrowConfig,
    sigma: &dyn Fn(Real) -> Real,
) -> Result<UnorganisedMeshes, SphericalGridError> {
    config.validate()?;
    grow.validate()?;
    if remainder.is_empty() {
        return Ok(UnorganisedMeshes::default());
    }
    let grid = match SphericalGrid::fit(positions, config) {
        Ok(grid) => grid,
        Err(e) if e.is_content_error() => return Ok(UnorganisedMeshes::default()),
        Err(e) => return Err(e),
    };
    let binned = grid.bin(positions, remainder)?;
    let grown = grow_trimeshes(&binned.cloud, &grid.grow_config(grow, config))?;
    let mut out = UnorganisedMeshes { binned: binned.cloud.len(), ..UnorganisedMeshes::default() };
    let mut scattered: Vec<[Point3; 3]> = Vec::new();
    if let Some(k) = config.splat_sigmas {
        let tolerance = |p: &Point3| {
            let t = k * sigma(p.coords.norm());
            if t.is_finite() { t.max(MIN_SPLAT_RADIUS) } else { MIN_SPLAT_RADIUS }
        };
        let footprint = SPLAT_FOOTPRINT * grid.column_step.min(grid.row_step);
        let radius =
            |p: &Point3| (footprint * p.coords.norm()).clamp(MIN_SPLAT_RADIUS, tolerance(p));
        scattered = splats(&grid, &binned, &grown, positions, &tolerance, &radius);
        out.splat_triangles = scattered.len();
    }
    let (mut grown, small) = (grown, grow.min_triangles);
    grown.meshes.retain(|m| {
        let keep = m.patch.triangles().len() >= small;
        if !keep {
            let v = m.patch.vertices();
            scattered.extend(m.patch.triangles().iter().map(|t| t.map(|i| v[i as usize])));
        }
        keep
    });
    out.scattered = group_by_cube(&scattered, grow.max_triangles);
    out.grown = grown;
    out.grid = Some(grid);
    Ok(out)
}

/// `triangles` as patches of at most `max_triangles`, each of the triangles whose first
/// vertex lies in one 4 m cube (shared vertices merged).
fn group_by_cube(triangles: &[[Point3; 3]], max_triangles: usize) -> Vec<TrimeshPatch> {
    let cube =
        |p: &Point3| [p.x, p.y, p.z].map(|c| (c / GROUP_CUBE).floor().clamp(-1e15, 1e15) as i64);
    let mut groups: BTreeMap<[i64; 3], Vec<&[Point3; 3]>> = BTreeMap::new();
    for t in triangles {
        groups.entry(cube(&t[0])).or_default().push(t);
    }
    let bits = |p: &Point3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
    let mut patches = Vec::new();
    for group in groups.into_values() {
        for chunk in group.chunks(max_triangles.max(1)) {
            let mut index: HashMap<[u64; 3], u32> = HashMap::new();
            let mut vertices = Vec::new();
            let triangles: Vec<[u32; 3]> = chunk
                .iter()
                .map(|t| {
                    t.map(|p| {
                        *index.entry(bits(&p)).or_insert_with(|| {
                            vertices.push(p);
                            (vertices.len() - 1) as u32
                        })
                    })
                })
                .collect();
            // Grown and splat triangles are valid; a refused one would be dropped, not panic.
            if let Ok(patch) = TrimeshPatch::new(vertices, triangles) {
                patches.push(patch);
            }
        }
    }
    patches
}

/// The splats of [`mesh_unorganised`].
fn splats(
    grid: &SphericalGrid,
    binned: &BinnedCloud,
    grown: &GrownTrimeshes,
    positions: &[Point3],
    tolerance: &dyn Fn(&Point3) -> Real,
    radius: &dyn Fn(&Point3) -> Real,
) -> Vec<[Point3; 3]> {
    let Some(cells) = binned.cloud.grid() else { return Vec::new() };
    let bits = |p: &Point3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
    let vertices: HashSet<[u64; 3]> =
        grown.meshes.iter().flat_map(|m| m.patch.vertices().iter().map(bits)).collect();
    let points = binned.cloud.positions();
    let meshed: Vec<bool> = points.iter().map(|p| vertices.contains(&bits(p))).collect();
    let (w, h) = (cells.width() as i64, cells.height() as i64);
    // Whether a mesh vertex within `rho` of `p` sits at or next to cell `(c, r)`.
    let near_mesh = |p: &Point3, c: i64, r: i64, rho: Real| {
        (r - 1..=r + 1).any(|rr| {
            (c - 1..=c + 1).any(|cc| {
                rr >= 0
                    && cc >= 0
                    && rr < h
                    && cc < w
                    && cells
                        .point_index(cc as u32, rr as u32)
                        .is_some_and(|i| meshed[i] && (points[i] - p).norm() <= rho)
            })
        })
    };
    let mut left: Vec<Point3> = Vec::new();
    for (pixel, &i) in cells.pixels().iter().enumerate() {
        if i == INVALID_PIXEL || meshed[i as usize] {
            continue;
        }
        let p = points[i as usize];
        let (c, r) = ((pixel % w as usize) as i64, (pixel / w as usize) as i64);
        if !near_mesh(&p, c, r, tolerance(&p)) {
            left.push(p);
        }
    }
    for &d in &binned.dropped {
        let p = positions[d as usize];
        let Some((c, r)) = grid.cell(&p) else { continue };
        if !near_mesh(&p, c as i64, r as i64, tolerance(&p)) {
            left.push(p);
        }
    }
    // Greedy: a point within its tolerance of an earlier splat's centre is covered by it.
    const HASH: Real = 0.5;
    let key = |p: &Point3, size: Real| {
        [(p.x / size).floor() as i64, (p.y / size).floor() as i64, (p.z / size).floor() as i64]
    };
    let mut centres: HashMap<[i64; 3], Vec<Point3>> = HashMap::new();
    let mut out = Vec::new();
    for p in left {
        let tol = tolerance(&p);
        let reach = (tol / HASH).ceil().min(8.0) as i64;
        let k = key(&p, HASH);
        let covered = (-reach..=reach).any(|dx| {
            (-reach..=reach).any(|dy| {
                (-reach..=reach).any(|dz| {
                    centres
                        .get(&[k[0] + dx, k[1] + dy, k[2] + dz])
                        .is_some_and(|cs| cs.iter().any(|c| (c - p).norm() <= tol))
                })
            })
        });
        if covered {
            continue;
        }
        centres.entry(k).or_default().push(p);
        let rho = radius(&p);
        let beam = p.coords / p.coords.norm().max(Real::MIN_POSITIVE);
        let side = if beam.z.abs() < 0.9 { Vector3::z() } else { Vector3::x() };
        let e1 = beam.cross(&side).normalize();
        let e2 = beam.cross(&e1);
        out.push([0, 1, 2].map(|k| {
            let angle = std::f64::consts::FRAC_PI_2 + k as Real * TAU / 3.0;
            p + rho * (angle.cos() * e1 + angle.sin() * e2)
        }));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trimesh_grow::TrimeshGrowConfig;
    use kiddo::ImmutableKdTree;

    const SPHERE_CENTRE: [Real; 3] = [5.0, 0.0, 0.0];
    const SPHERE_RADIUS: Real = 1.0;
    const WALL_X: Real = 12.0;
    const FLOOR_Z: Real = -1.7;
    const SIGMA: Real = 0.01;

    /// The first hit of the ray from the origin along unit `d`: a floating ball in front of a
    /// wall, above a floor that meets the wall.
    fn cast(d: &Vector3) -> Option<Real> {
        let c = Vector3::from(SPHERE_CENTRE);
        let b = d.dot(&c);
        let disc = b * b - (c.norm_squared() - SPHERE_RADIUS * SPHERE_RADIUS);
        let sphere = (disc >= 0.0).then(|| b - disc.sqrt()).filter(|&t| t > 0.0);
        let wall = (d.x > 1e-9).then(|| WALL_X / d.x).filter(|&t| (d.y * t).abs() < 20.0);
        let floor = (d.z < -1e-9).then(|| FLOOR_Z / d.z).filter(|&t| d.x * t <= WALL_X);
        [sphere, wall, floor].into_iter().flatten().min_by(Real::total_cmp)
    }

    /// The scan of `directions` of the scene, shuffled (an unorganised cloud).
    fn scan(directions: impl Iterator<Item = Vector3>) -> Vec<Point3> {
        let mut points: Vec<Point3> =
            directions.filter_map(|d| cast(&d).map(|t| Point3::from(d * t))).collect();
        let mut keys: Vec<(u64, usize)> = (0..points.len())
            .map(|i| ((i as u64).wrapping_mul(2_654_435_761) % (1 << 32), i))
            .collect();
        keys.sort_unstable();
        points = keys.iter().map(|&(_, i)| points[i]).collect();
        points
    }

    /// Elevations of 24 rings: 12 half a degree apart, then 12 a third of a degree apart
    /// (as the HDL-64E's two blocks), −14° to +0.2°.
    fn rings() -> Vec<Real> {
        let mut e: Vec<Real> = (0..12).map(|k| -14.0 + 0.5 * k as Real).collect();
        e.extend((0..12).map(|k| -8.0 + k as Real / 3.0 + 0.1));
        e
    }

    /// A spinning lidar about `z`, ±60° of azimuth in 0.2° steps, every other ring staggered
    /// by half a step.
    fn lidar_scan() -> Vec<Point3> {
        let rings = rings();
        scan(rings.clone().into_iter().enumerate().flat_map(|(k, e)| {
            let stagger = if k % 2 == 0 { 0.0 } else { 0.1 };
            (0..600).map(move |j| {
                let (a, e) = ((-60.0 + 0.2 * j as Real + stagger).to_radians(), e.to_radians());
                Vector3::new(e.cos() * a.cos(), e.cos() * a.sin(), e.sin())
            })
        }))
    }

    fn triangles_of<'a>(patches: impl Iterator<Item = &'a TrimeshPatch>) -> Vec<[Point3; 3]> {
        patches
            .flat_map(|m| m.triangles().iter().map(|t| t.map(|i| m.vertices()[i as usize])))
            .collect()
    }

    #[test]
    fn a_spinning_lidar_gets_its_axis_steps_and_rings() {
        let points = lidar_scan();
        let grid = SphericalGrid::fit(&points, &SphericalGridConfig::estimated()).unwrap();
        assert_eq!(grid.axis(), SensorAxis::Z);
        let column = grid.column_step().to_degrees();
        assert!((column - 0.2).abs() < 0.01, "column step {column}°");
        // Every ring in a row of its own, although the rings are unevenly spaced.
        let mut row_of_ring = vec![None; rings().len()];
        for p in &points {
            let e = (p.z / p.coords.norm()).asin().to_degrees();
            let ring = rings().iter().position(|&r| (r - e).abs() < 1e-6).unwrap();
            let (_, row) = grid.cell(p).unwrap();
            assert_eq!(*row_of_ring[ring].get_or_insert(row), row, "ring {ring} in two rows");
        }
        let mut rows: Vec<u32> = row_of_ring.iter().flatten().copied().collect();
        rows.dedup();
        assert_eq!(rows.len(), rings().len(), "rings share rows: {rows:?}");
        assert!(rows.windows(2).all(|w| w[0] > w[1]), "higher rings above: {rows:?}");
        // The partial field of view gives a grid as wide as the data.
        assert!(grid.width() <= 602, "{} columns", grid.width());
        // Staggered rings keep one point per cell.
        let all: Vec<u32> = (0..points.len() as u32).collect();
        let binned = grid.bin(&points, &all).unwrap();
        assert!(binned.dropped.len() * 100 < points.len(), "{} dropped", binned.dropped.len());
        assert_eq!(binned.source.len(), binned.cloud.len());
        for (k, &i) in binned.source.iter().enumerate() {
            assert_eq!(binned.cloud.positions()[k], points[i as usize]);
        }
    }

    #[test]
    fn a_nodding_scanner_gets_the_y_axis() {
        // A fan from −90° to 90° in 1° steps, pitched about y from −40° to 60° in 1° steps.
        let points = scan((0..101).flat_map(|j| {
            (0..181).map(move |k| {
                let (theta, alpha) =
                    ((-40.0 + j as Real).to_radians(), (-90.0 + k as Real).to_radians());
                Vector3::new(alpha.cos() * theta.cos(), alpha.sin(), alpha.cos() * theta.sin())
            })
        }));
        let grid = SphericalGrid::fit(&points, &SphericalGridConfig::estimated()).unwrap();
        assert_eq!(grid.axis(), SensorAxis::Y);
        for step in [grid.column_step(), grid.row_step()] {
            assert!((step.to_degrees() - 1.0).abs() < 0.02, "step {}°", step.to_degrees());
        }
    }

    #[test]
    fn a_ball_in_front_of_a_wall_is_meshed_without_bridging_the_depth_jump() {
        let points = lidar_scan();
        let all: Vec<u32> = (0..points.len() as u32).collect();
        let grow = TrimeshGrowConfig::alrf();
        // Small meshes grouped with the splats (the default): every mesh left is large.
        let config = SphericalGridConfig::estimated();
        let made = mesh_unorganised(&points, &all, &config, &grow, &|_| SIGMA).unwrap();
        assert!(made.grown.meshes.iter().all(|m| m.patch.triangles().len() >= grow.min_triangles));
        assert!(made.scattered.iter().all(|m| m.triangles().len() <= grow.max_triangles));
        // Without small meshes, the scattered patches hold the splats alone.
        let config = SphericalGridConfig { min_triangles: None, ..config };
        let made = mesh_unorganised(&points, &all, &config, &grow, &|_| SIGMA).unwrap();
        let on_ball =
            |p: &Point3| ((p - Point3::from(SPHERE_CENTRE)).norm() - SPHERE_RADIUS).abs() < 1e-6;
        let meshes = triangles_of(made.grown.meshes.iter().map(|m| &m.patch));
        assert!(meshes.len() > 1000, "{} triangles", meshes.len());
        // No triangle joins the ball to the wall or floor behind it.
        for t in &meshes {
            let ball = t.iter().filter(|p| on_ball(p)).count();
            assert!(ball == 0 || ball == 3, "a triangle spans the depth jump: {t:?}");
        }
        // The ball's points are mesh vertices.
        let bits = |p: &Point3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
        let vertices: HashSet<[u64; 3]> = meshes.iter().flatten().map(bits).collect();
        let ball: Vec<&Point3> = points.iter().filter(|p| on_ball(p)).collect();
        let meshed = ball.iter().filter(|p| vertices.contains(&bits(p))).count();
        // (The others lie on its rim, seen at grazing incidence: splats.)
        assert!(meshed * 100 >= 90 * ball.len(), "{meshed} of {} ball points meshed", ball.len());
        // Splats stay between the beams, and every point lies within 3σ of a mesh vertex or a
        // splat's centre.
        let splats = triangles_of(made.scattered.iter());
        assert_eq!(splats.len(), made.splat_triangles);
        let step = made.grid.as_ref().unwrap().column_step().min(made.grid.unwrap().row_step());
        let mut anchors: Vec<[Real; 3]> = vertices
            .iter()
            .map(|b| [Real::from_bits(b[0]), Real::from_bits(b[1]), Real::from_bits(b[2])])
            .collect();
        for t in &splats {
            let centre = Point3::from((t[0].coords + t[1].coords + t[2].coords) / 3.0);
            let radius = (t[0] - centre).norm();
            assert!(radius <= 0.45 * step * centre.coords.norm() + 1e-9, "splat radius {radius}");
            anchors.push([centre.x, centre.y, centre.z]);
        }
        let tree = ImmutableKdTree::<Real, 3>::new_from_slice(&anchors).unwrap();
        for p in &points {
            let one = NonZeroUsize::MIN;
            let near =
                tree.query(&[p.x, p.y, p.z]).nearest_n::<SquaredEuclidean<Real>>(one).execute();
            assert!(near[0].distance <= (3.0 * SIGMA).powi(2) + 1e-12, "{p} is left out");
        }
    }

    #[test]
    fn the_nearest_point_keeps_the_cell() {
        let near = Point3::new(2.0, 0.0, 0.0);
        let far = Point3::new(6.0, 0.0, 0.0);
        let mut points = lidar_scan();
        points.extend([far, near]);
        let grid = SphericalGrid::fit(&points, &SphericalGridConfig::estimated()).unwrap();
        let n = points.len() as u32;
        let binned = grid.bin(&points, &[n - 2, n - 1]).unwrap();
        assert_eq!(binned.cloud.positions(), &[near]);
        assert_eq!(binned.dropped, vec![n - 2]);
    }

    #[test]
    fn bad_parameters_and_inputs_are_errors() {
        let points = lidar_scan();
        let bad = |config: SphericalGridConfig| SphericalGrid::fit(&points, &config).unwrap_err();
        let base = SphericalGridConfig::estimated();
        for scale in [Real::NAN, 0.0, -1.0, 100.0, Real::INFINITY] {
            let e = bad(SphericalGridConfig {
                resolution: AngularResolution::Estimated { scale },
                ..base
            });
            assert!(matches!(e, SphericalGridError::BadParameter { name: "scale", .. }), "{e}");
        }
        for step in [Real::NAN, 0.0, 1e-9, 1.0, -0.01] {
            let e = SphericalGridConfig::fixed(SensorAxis::Z, step, 0.01).unwrap_err();
            assert!(matches!(e, SphericalGridError::BadParameter { .. }), "{e}");
        }
        let e = bad(SphericalGridConfig { min_range: Real::NAN, ..base });
        assert!(matches!(e, SphericalGridError::BadParameter { name: "min_range", .. }));
        let e = bad(SphericalGridConfig { max_side_steps: Some(0.0), ..base });
        assert!(matches!(e, SphericalGridError::BadParameter { name: "max_side_steps", .. }));
        let e = bad(SphericalGridConfig { splat_sigmas: Some(Real::NAN), ..base });
        assert!(matches!(e, SphericalGridError::BadParameter { name: "splat_sigmas", .. }));
        let e = bad(SphericalGridConfig { min_triangles: Some(0), ..base });
        assert!(matches!(e, SphericalGridError::BadParameter { name: "min_triangles", .. }));
        for max_cells in [0, 15, MAX_CELLS_LIMIT + 1] {
            assert_eq!(bad(SphericalGridConfig { max_cells, ..base }), {
                SphericalGridError::MaxCells(max_cells)
            });
        }
        // Given steps far too fine: refused before any grid is allocated.
        let fine = SphericalGridConfig::fixed(SensorAxis::Z, MIN_STEP, MIN_STEP).unwrap();
        assert!(matches!(bad(fine), SphericalGridError::TooManyCells { .. }));
        // Content.
        let config = &base;
        assert_eq!(SphericalGrid::fit(&[], config).unwrap_err(), SphericalGridError::Empty);
        let origin = [Point3::origin(); 3];
        assert_eq!(SphericalGrid::fit(&origin, config).unwrap_err(), SphericalGridError::Empty);
        let one = [Point3::new(1.0, 0.0, 0.0)];
        let e = SphericalGrid::fit(&one, config).unwrap_err();
        assert!(e.is_content_error(), "{e}");
        let nan = [Point3::new(1.0, 0.0, 0.0), Point3::new(Real::NAN, 0.0, 0.0)];
        assert_eq!(
            SphericalGrid::fit(&nan, config).unwrap_err(),
            SphericalGridError::NonFinite { index: 1 }
        );
        let grid = SphericalGrid::fit(&points, config).unwrap();
        let n = points.len();
        assert_eq!(
            grid.bin(&points, &[0, n as u32]).unwrap_err(),
            SphericalGridError::IndexOutOfRange { index: n as u32, len: n }
        );
        // The pipeline's entry point: parameters are errors, content is not.
        let grow = TrimeshGrowConfig::alrf();
        let e = mesh_unorganised(
            &points,
            &[0],
            &SphericalGridConfig { max_cells: 1, ..base },
            &grow,
            &|_| SIGMA,
        );
        assert!(matches!(e, Err(SphericalGridError::MaxCells(1))));
        let e = mesh_unorganised(
            &points,
            &[0],
            config,
            &TrimeshGrowConfig { max_side: Real::NAN, ..grow },
            &|_| SIGMA,
        );
        assert!(matches!(e, Err(SphericalGridError::Trimesh(_))));
        let made = mesh_unorganised(&one, &[0], config, &grow, &|_| SIGMA).unwrap();
        assert!(made.grid.is_none() && made.scattered.is_empty());
        let made = mesh_unorganised(&points, &[], config, &grow, &|_| SIGMA).unwrap();
        assert_eq!(made.binned, 0);
    }

    #[test]
    fn estimated_grids_are_coarsened_to_fit_max_cells() {
        let points = lidar_scan();
        let config = SphericalGridConfig { max_cells: 2000, ..SphericalGridConfig::estimated() };
        let grid = SphericalGrid::fit(&points, &config).unwrap();
        assert!(grid.width() as usize * grid.height() as usize <= 2000);
        assert!(grid.column_step().to_degrees() > 0.5);
        let all: Vec<u32> = (0..points.len() as u32).collect();
        let binned = grid.bin(&points, &all).unwrap();
        assert_eq!(binned.cloud.len() + binned.dropped.len() + binned.outside, points.len());
    }

    #[test]
    fn side_limits_grow_with_range_only_when_asked() {
        let points = lidar_scan();
        let grid = SphericalGrid::fit(&points, &SphericalGridConfig::estimated()).unwrap();
        let grow = TrimeshGrowConfig::alrf();
        let fixed = SphericalGridConfig {
            max_side_steps: None,
            min_triangles: None,
            ..SphericalGridConfig::estimated()
        };
        assert_eq!(grid.grow_config(&grow, &fixed), grow);
        let scaled = grid.grow_config(&grow, &SphericalGridConfig::estimated());
        let k = scaled.side_per_range.unwrap();
        assert!((k - 3.0 * grid.column_step().max(grid.row_step())).abs() < 1e-12);
        assert_eq!(scaled.min_triangles, 1);
        let nan = TrimeshGrowConfig { side_per_range: Some(Real::NAN), ..grow };
        assert!(nan.validate().is_err());
    }
}
