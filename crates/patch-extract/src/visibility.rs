//! Free-space carving across scans: what one scan put where another scan saw empty space goes.
//!
//! A beam that returns at range `r` saw the space along it up to `r` empty. A phantom, a mixed
//! pixel in mid-air between a foreground and a background ([`mod@crate::mixed_pixels`]), or a
//! "veil" triangle that trimesh growing spans across a depth jump, lies in space that the
//! scan which made it could not see past; but a scan from another pose often looks straight
//! through it. This module asks every *other* scan whether it saw a small ball around a point
//! empty, and drops the points (or triangles) that one did.
//!
//! # The rule
//! Scan `B` **saw the ball** `𝔹(p, ρ)` (`ρ =` [`VisibilityConfig::ball_radius`]) **empty** when,
//! among `B`'s beams nearest to `p` in direction ([`VisibilityConfig::beams`] of them):
//!
//! * **no veto**: no beam that passes within `ρ` of `p` returns inside the ball or just
//!   short of it: with `t` its range at the point nearest to `p`, `ℓ` its distance from `p` and
//!   `h = √(ρ² − ℓ²)` half its chord through the ball, a beam returning in
//!   `[t − h − m, t + h + m]` (`m =` [`VisibilityConfig::return_margin`], the range noise of a
//!   return) hit something in or at the ball;
//! * **evidence around `p`**: the beams that pass within `g =` [`VisibilityConfig::max_gap`] of
//!   `p` and return beyond the ball (`> t + h + m`) lie on every side of `p`: seen on the plane
//!   through `p` across `B`'s view, no two neighbouring ones are more than
//!   [`VisibilityConfig::max_gap_angle`] apart around `p`, and there are at least three.
//!
//! Beams that return short of the ball (`< t − h − m`) were stopped before it: they neither veto
//! nor count as evidence. Beams with no return are not in a scan at all, so a scan never
//! carves with what it did not measure.
//!
//! `g` bounds how far apart the beams that saw the space around `p` are: an object narrower
//! than `B`'s beam spacing can slip between its beams, so a scan only carves where its beams are
//! at most `g` from `p` on every side, and an object whose silhouette reaches across `p` by more
//! than about `g` is hit by one of them (a veto). `ρ` makes a point within `ρ` of a surface `B`
//! saw safe from carving: noise around a surface, and a surface seen grazingly (where the
//! beam through a noisy point reaches the surface far beyond it), stay.
//!
//! A point is never tested against its own scan: its own beam returns at the point.
//!
//! **Never open unseen space** ([`VisibilityConfig::neighbourhood`] `= Some(D)`). A point seen
//! empty is carved only when the six points `D` from it, along its own beam both ways and
//! across it, were each seen by some scan, empty or as a surface (a beam returned in or beyond
//! their ball). A phantom or veil beside space no scan saw (the top of a board seen only from
//! below, the far side of a barrel) stood for that space in the map, so it stays.
//!
//! A scan whose median beam spacing at the point's range exceeds `2g` is not asked, and one
//! whose beams near the point (a coarse 2° table of each scan's farthest returns) all stop
//! short of the ball is answered "unseen" without a search; both only skip work.
//!
//! # Where it applies
//! * [`FreeSpace::carve_clouds`]: points of organised or unorganised scans (the pc map); of
//!   an organised scan only the points on a depth jump ([`VisibilityConfig::min_jump`]): a
//!   point in mid-air lies on one;
//! * [`FreeSpace::carve_trimesh`], [`FreeSpace::carve_trimeshes`]: triangles of a scan's
//!   trimesh patches, each tested at its centroid and edge midpoints and dropped when
//!   [`VisibilityConfig::min_empty_samples`] of them were seen empty; optionally only those
//!   seen more grazingly than [`VisibilityConfig::triangle_view_cos`] from their own scan (a
//!   veil across a depth jump contains its beams; a surface seen head-on is never one).
//!
//! Measured on the lab and the office against their exact surfaces in `docs/map-safety.md`
//! (item 12): it halves the blocked free space of a point-cloud map within 0.05 points of its
//! unsafe rate, but every carved map lets a few colliding steps through that the uncarved one
//! caught, so the pipeline presets leave it off.
//!
//! This is the consistency test of multi-view depth fusion and of occupancy mapping's free
//! space (OctoMap clears the voxels a beam passes); here it is exact per beam, with no voxel
//! size, and it only ever removes what another scan saw through. It is not in the thesis,
//! whose maps keep every point and triangle of every scan (§6.1).

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use patch_core::{Isometry3, Point3, Real, TrimeshPatch, Vector3};
use pointcloud::PointCloud;
use std::num::NonZeroUsize;

/// The thresholds of free-space carving. No `Default`: see [`VisibilityConfig::alrf`].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct VisibilityConfig {
    /// `ρ`: radius of the ball around a point that another scan must have seen empty, metres.
    /// Points closer than this to a surface that scan saw are never carved.
    pub ball_radius: Real,
    /// `m`: a return within this many metres of the ball counts as hitting it (range noise).
    pub return_margin: Real,
    /// `g`: the evidence beams must pass within this many metres of the point on every side.
    pub max_gap: Real,
    /// Largest angle around the point between neighbouring evidence beams, radians (below π,
    /// so the point lies inside their hull).
    pub max_gap_angle: Real,
    /// Beams of each other scan examined per point (nearest in direction).
    pub beams: usize,
    /// Only triangles whose unit normal `n` and their own beam `u` have `|n · u|` below this are
    /// tested by [`FreeSpace::carve_trimesh`] (`None`: every triangle).
    pub triangle_view_cos: Option<Real>,
    /// Only points of an organised scan whose range differs from one of its 8 grid neighbours'
    /// by more than this many metres are tested by [`FreeSpace::carve_clouds`]: a point in
    /// mid-air lies on a depth jump of its own scan (`None`, and unorganised scans: every
    /// point).
    pub min_jump: Option<Real>,
    /// `D`: also require the six points `D` metres from the point along its own beam (both
    /// ways) and across it to have been seen, empty or as a surface, by some scan, so that
    /// carving never opens space no scan saw: a phantom or veil beside an unseen surface (the
    /// top of a board seen only from below, the far side of a barrel) stays. `None`: no such
    /// test. For a point of no known scan the world axes stand for the beam.
    pub neighbourhood: Option<Real>,
    /// A triangle goes when at least this many of its four sample points (centroid, edge
    /// midpoints) were seen empty (1 to 4): a veil across a deep jump has its middle in
    /// mid-air, a noisy triangle at a silhouette at most a corner.
    pub min_empty_samples: usize,
}

impl VisibilityConfig {
    /// For the simulated SICK S300 ALRF (σ = 3 cm, 0.5° beams): `ρ = m = 3σ`; beams at most
    /// `g = 4` cm from the point on every side (a 5 cm table leg is hit; at 0.5° the seeing
    /// scan must be within about 4.6 m), gaps below 120°, the 12 nearest beams per scan;
    /// only points on a depth jump of 12 cm; triangles seen at more than 70° from their own
    /// scan, gone when two of their four samples were seen empty; the six points 0.3 m around
    /// (the robot radius of the experiments) seen.
    ///
    /// Chosen on the lab, scene seed 0, 8 scans, step seed 1 (`patchnav map build --scene lab
    /// --carve [--carve-neighbourhood D] [--carve-samples K]`, then `map compare` with the
    /// exact map; unsafe / overcautious %, and the colliding steps the map newly lets through):
    ///
    /// | map | without | `D` none, `K` 2 | `D` 0.3 m, `K` 2 (this) | `D` 0.3 m, `K` 3 |
    /// |---|---|---|---|---|
    /// | pc | 0.16 / 15.08 | 0.28 / 7.69 (+52) | 0.20 / 10.50 (+15) | = |
    /// | pc, denoised | 0.18 / 12.82 | 0.31 / 5.13 (+67) | 0.21 / 8.16 (+28) | = |
    /// | trimesh | 0.90 / 4.30 | 0.93 / 3.62 (+11) | 0.92 / 3.77 (+6) | 0.91 / 4.02 (+3) |
    /// | hybrid | 0.51 / 1.99 | 0.53 / 1.89 (+5) | 0.52 / 1.90 (+4) | 0.52 / 1.93 (+1) |
    ///
    /// (`K` only concerns triangles.) Wider gaps carve more and lose more: `g` 8 cm gave the
    /// denoised pc map 0.48 / 3.31 without `D`.
    pub fn alrf() -> VisibilityConfig {
        VisibilityConfig {
            ball_radius: 0.09,
            return_margin: 0.09,
            max_gap: 0.04,
            max_gap_angle: 120f64.to_radians(),
            beams: 12,
            triangle_view_cos: Some(70f64.to_radians().cos()),
            min_jump: Some(0.12),
            neighbourhood: Some(0.3),
            min_empty_samples: 2,
        }
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`VisibilityError::BadParameter`] naming the field.
    pub fn validate(&self) -> Result<(), VisibilityError> {
        let bad = |name: &'static str, value: Real| VisibilityError::BadParameter { name, value };
        if !(self.ball_radius.is_finite() && self.ball_radius > 0.0) {
            return Err(bad("ball_radius", self.ball_radius));
        }
        if !(self.return_margin.is_finite() && self.return_margin >= 0.0) {
            return Err(bad("return_margin", self.return_margin));
        }
        if !(self.max_gap.is_finite() && self.max_gap > 0.0 && self.max_gap <= self.ball_radius) {
            return Err(bad("max_gap", self.max_gap));
        }
        if !(self.max_gap_angle > 0.0 && self.max_gap_angle < std::f64::consts::PI) {
            return Err(bad("max_gap_angle", self.max_gap_angle));
        }
        if !(3..=256).contains(&self.beams) {
            return Err(bad("beams", self.beams as Real));
        }
        if let Some(c) = self.triangle_view_cos
            && !(0.0..=1.0).contains(&c)
        {
            return Err(bad("triangle_view_cos", c));
        }
        if let Some(j) = self.min_jump
            && !(j.is_finite() && j >= 0.0)
        {
            return Err(bad("min_jump", j));
        }
        if !(1..=SAMPLES_PER_TRIANGLE).contains(&self.min_empty_samples) {
            return Err(bad("min_empty_samples", self.min_empty_samples as Real));
        }
        if let Some(b) = self.neighbourhood
            && !(b.is_finite() && b > 0.0)
        {
            return Err(bad("neighbourhood", b));
        }
        Ok(())
    }
}

/// Why carving refused its input.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum VisibilityError {
    /// A threshold out of its range.
    #[error("free-space carving: {name} = {value} is out of range")]
    BadParameter {
        /// The field.
        name: &'static str,
        /// Its value.
        value: Real,
    },
    /// A scan's pose holds NaN or infinity.
    #[error("free-space carving: scan {scan}'s sensor pose is not finite")]
    BadPose {
        /// The scan.
        scan: usize,
    },
    /// A scan with more beams than the direction index holds.
    #[error("free-space carving: scan {scan} has too many points ({points}) to index")]
    TooManyPoints {
        /// The scan.
        scan: usize,
        /// Its points.
        points: usize,
    },
    /// [`FreeSpace::carve_clouds`] was given other scans than the index was built from.
    #[error("free-space carving: {given} scans given, the index holds {indexed}")]
    ScanCount {
        /// Scans given.
        given: usize,
        /// Scans indexed.
        indexed: usize,
    },
}

/// Points tested per triangle: the centroid and the three edge midpoints.
const SAMPLES_PER_TRIANGLE: usize = 4;

/// One scan's beams: unit directions in its sensor frame, indexed, and their ranges.
struct ScanBeams {
    sensor_from_world: Isometry3,
    origin: Point3,
    directions: Vec<Vector3>,
    ranges: Vec<Real>,
    tree: Option<ImmutableKdTree<Real, 3>>,
    /// The median angle between a beam and its nearest neighbour, radians: beyond
    /// `max_gap / spacing` metres this scan's beams are too far apart to carve.
    spacing: Real,
    /// The farthest return per [`COARSE_BIN`] azimuth × elevation bin (0: no beam), so that
    /// a ball every beam near it stops short of is found unseen without a search.
    farthest: Vec<f32>,
}

/// Size of the coarse bins of [`ScanBeams::farthest`], radians (2°).
const COARSE_BIN: Real = std::f64::consts::PI / 90.0;
const AZIMUTH_BINS: usize = 180;
const ELEVATION_BINS: usize = 90;

/// The coarse bin of a unit direction: (azimuth, elevation) indices.
fn coarse_bin(u: &Vector3) -> (usize, usize) {
    let az = u.y.atan2(u.x) + std::f64::consts::PI;
    let el = u.z.clamp(-1.0, 1.0).asin() + std::f64::consts::FRAC_PI_2;
    let a = ((az / COARSE_BIN) as usize).min(AZIMUTH_BINS - 1);
    let e = ((el / COARSE_BIN) as usize).min(ELEVATION_BINS - 1);
    (a, e)
}

impl ScanBeams {
    /// Whether every beam within 2° of `u` returns before `range` (`false` when `u` is more
    /// than 55° above or below the horizon).
    fn all_stop_before(&self, u: &Vector3, range: Real) -> bool {
        if u.z.abs() > 55f64.to_radians().sin() {
            return false;
        }
        let (a, e) = coarse_bin(u);
        // 2° from a direction within ±55° of the horizon stays within ±57°, where 2° across
        // spans at most 2° / cos 57° = 3.7° of azimuth: within ±2 bins of `u`'s own, and within
        // ±1 bin of elevation.
        for de in -1..=1i64 {
            let e2 = e as i64 + de;
            if !(0..ELEVATION_BINS as i64).contains(&e2) {
                continue;
            }
            for da in -2..=2i64 {
                let a2 = (a as i64 + da).rem_euclid(AZIMUTH_BINS as i64) as usize;
                if Real::from(self.farthest[e2 as usize * AZIMUTH_BINS + a2]) >= range {
                    return false;
                }
            }
        }
        true
    }
}

/// The beams of a set of scans, asked which points they saw through.
pub struct FreeSpace {
    scans: Vec<ScanBeams>,
    config: VisibilityConfig,
}

impl std::fmt::Debug for FreeSpace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FreeSpace")
            .field("scans", &self.scans.len())
            .field("config", &self.config)
            .finish()
    }
}

/// What [`FreeSpace::carve_clouds`] or [`FreeSpace::carve_trimesh`] removed.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct Carved {
    /// Points or triangles tested.
    pub tested: usize,
    /// Of those, removed.
    pub removed: usize,
}

impl std::ops::AddAssign for Carved {
    fn add_assign(&mut self, other: Carved) {
        self.tested += other.tested;
        self.removed += other.removed;
    }
}

impl FreeSpace {
    /// Indexes the beams of `scans`: clouds in their sensor frame (the sensor at the origin)
    /// with their poses ([`PointCloud::sensor_pose`]; none: the world frame). A point at the
    /// sensor is no beam.
    ///
    /// # Errors
    /// A refused config, a non-finite pose, a scan beyond the index's `u32` range.
    pub fn new(
        scans: &[PointCloud],
        config: &VisibilityConfig,
    ) -> Result<FreeSpace, VisibilityError> {
        config.validate()?;
        let mut out = Vec::with_capacity(scans.len());
        for (index, scan) in scans.iter().enumerate() {
            let world_from_sensor = match scan.sensor_pose() {
                Some(pose) if !pose.is_finite() => {
                    return Err(VisibilityError::BadPose { scan: index });
                }
                Some(pose) => pose.world_from_sensor,
                None => Isometry3::identity(),
            };
            if scan.len() >= u32::MAX as usize {
                return Err(VisibilityError::TooManyPoints { scan: index, points: scan.len() });
            }
            let mut directions = Vec::with_capacity(scan.len());
            let mut ranges = Vec::with_capacity(scan.len());
            for p in scan.positions() {
                let r = p.coords.norm();
                if r > 1e-9 {
                    directions.push(p.coords / r);
                    ranges.push(r);
                }
            }
            let coords: Vec<[Real; 3]> = directions.iter().map(|d| [d.x, d.y, d.z]).collect();
            let tree = if coords.is_empty() {
                None
            } else {
                ImmutableKdTree::<Real, 3>::new_from_slice(&coords).ok()
            };
            let spacing = tree.as_ref().map_or(0.0, |t| median_spacing(t, &coords));
            let mut farthest = vec![0f32; AZIMUTH_BINS * ELEVATION_BINS];
            for (u, &r) in directions.iter().zip(&ranges) {
                let (a, e) = coarse_bin(u);
                let slot = &mut farthest[e * AZIMUTH_BINS + a];
                // Rounded up, so the test never calls a beam shorter than it is.
                *slot = slot.max((r as f32).next_up());
            }
            out.push(ScanBeams {
                sensor_from_world: world_from_sensor.inverse(),
                origin: Point3::from(world_from_sensor.translation.vector),
                directions,
                ranges,
                tree,
                spacing,
                farthest,
            });
        }
        Ok(FreeSpace { scans: out, config: *config })
    }

    /// Number of scans indexed.
    pub fn num_scans(&self) -> usize {
        self.scans.len()
    }

    /// The thresholds.
    pub fn config(&self) -> &VisibilityConfig {
        &self.config
    }

    /// Whether some scan other than `own` saw the ball around `p` (world frame) empty (see the
    /// module docs).
    pub fn seen_empty(&self, p: &Point3, own: Option<usize>) -> bool {
        let mut scratch = Vec::new();
        self.seen_empty_with(p, own, &mut scratch)
    }

    fn seen_empty_with(&self, p: &Point3, own: Option<usize>, angles: &mut Vec<Real>) -> bool {
        let seen_empty = self.scans.iter().enumerate().any(|(i, scan)| {
            Some(i) != own && scan_sees(scan, p, &self.config, angles) == Sight::Empty
        });
        if !seen_empty {
            return false;
        }
        let Some(reach) = self.config.neighbourhood else { return true };
        let beam = own
            .and_then(|i| self.scans.get(i))
            .map(|scan| (p - scan.origin).normalize())
            .filter(|u| u.iter().all(|c| c.is_finite()))
            .unwrap_or_else(Vector3::z);
        let (across, up) = across(&beam);
        [beam, -beam, across, -across, up, -up].iter().all(|&offset| {
            let q = p + offset * reach;
            self.scans.iter().any(|scan| scan_sees(scan, &q, &self.config, angles) != Sight::Unseen)
        })
    }

    /// Each scan of `scans` (the ones the index was built from, in order) without the points
    /// another scan saw empty, and what was removed. The grid and every attribute follow
    /// ([`PointCloud::retain_indices`]).
    ///
    /// # Errors
    /// [`VisibilityError::ScanCount`] when `scans` are not the indexed ones.
    pub fn carve_clouds(
        &self,
        scans: &[PointCloud],
    ) -> Result<(Vec<PointCloud>, Carved), VisibilityError> {
        let candidates: Vec<Vec<usize>> = scans
            .iter()
            .map(|scan| match (self.config.min_jump, scan.grid()) {
                (Some(jump), Some(_)) => depth_jump_points(scan, jump),
                _ => (0..scan.len()).collect(),
            })
            .collect();
        self.carve_clouds_at(scans, &candidates)
    }

    /// [`FreeSpace::carve_clouds`] testing only the points `candidates[k]` of scan `k` (indices
    /// at or beyond a scan's length are ignored).
    ///
    /// # Errors
    /// [`VisibilityError::ScanCount`] when `scans` or `candidates` are not one per indexed
    /// scan.
    pub fn carve_clouds_at(
        &self,
        scans: &[PointCloud],
        candidates: &[Vec<usize>],
    ) -> Result<(Vec<PointCloud>, Carved), VisibilityError> {
        for given in [scans.len(), candidates.len()] {
            if given != self.scans.len() {
                return Err(VisibilityError::ScanCount { given, indexed: self.scans.len() });
            }
        }
        let mut out = Vec::with_capacity(scans.len());
        let mut carved = Carved::default();
        for (index, scan) in scans.iter().enumerate() {
            let world_from_sensor =
                scan.sensor_pose().map_or_else(Isometry3::identity, |pose| pose.world_from_sensor);
            let candidates: Vec<usize> =
                candidates[index].iter().copied().filter(|&i| i < scan.len()).collect();
            let world: Vec<Point3> =
                candidates.iter().map(|&i| world_from_sensor * scan.positions()[i]).collect();
            let flags = self.flags(&world, Some(index));
            let mut remove = vec![false; scan.len()];
            for (&i, &f) in candidates.iter().zip(&flags) {
                remove[i] = f;
            }
            carved += Carved { tested: world.len(), removed: flags.iter().filter(|&&r| r).count() };
            out.push(scan.retain_indices(|i| !remove[i]));
        }
        Ok((out, carved))
    }

    /// Per point of `points` (world frame): whether a scan other than `own` saw it empty. Runs
    /// on every core; the answer does not depend on their number.
    pub fn flags(&self, points: &[Point3], own: Option<usize>) -> Vec<bool> {
        let threads = std::thread::available_parallelism().map_or(1, NonZeroUsize::get);
        let chunk = points.len().div_ceil(threads).max(1024);
        let mut out = vec![false; points.len()];
        std::thread::scope(|s| {
            for (ps, flags) in points.chunks(chunk).zip(out.chunks_mut(chunk)) {
                s.spawn(move || {
                    let mut scratch = Vec::new();
                    for (p, f) in ps.iter().zip(flags) {
                        *f = self.seen_empty_with(p, own, &mut scratch);
                    }
                });
            }
        });
        out
    }

    /// `patch` (world frame) without the triangles of which a scan other than `own` saw
    /// [`VisibilityConfig::min_empty_samples`] of the centroid and the edge midpoints empty (a
    /// veil across a deep jump has its middle in mid-air, its corners on the surfaces); `None`
    /// when none is left. With [`VisibilityConfig::triangle_view_cos`] and a known
    /// `own` scan, only triangles seen that grazingly from it are tested.
    pub fn carve_trimesh(
        &self,
        patch: &TrimeshPatch,
        own: Option<usize>,
    ) -> (Option<TrimeshPatch>, Carved) {
        let (mut kept, carved) = self.carve_trimeshes(std::slice::from_ref(patch), own);
        (kept.pop(), carved)
    }

    /// [`FreeSpace::carve_trimesh`] for many patches of one scan at once (their tests share
    /// every core): the patches that keep a triangle, in their order.
    pub fn carve_trimeshes(
        &self,
        patches: &[TrimeshPatch],
        own: Option<usize>,
    ) -> (Vec<TrimeshPatch>, Carved) {
        let origin = own.and_then(|i| self.scans.get(i)).map(|s| s.origin);
        // Per tested triangle: its patch and index.
        let mut tested: Vec<(usize, usize)> = Vec::new();
        let mut samples = Vec::new();
        for (pi, patch) in patches.iter().enumerate() {
            let v = patch.vertices();
            for (k, t) in patch.triangles().iter().enumerate() {
                let [a, b, c] = t.map(|i| v[i as usize]);
                let centroid = Point3::from((a.coords + b.coords + c.coords) / 3.0);
                if let (Some(max_cos), Some(o)) = (self.config.triangle_view_cos, origin) {
                    let n = (b - a).cross(&(c - a));
                    let u = centroid - o;
                    let (nn, un) = (n.norm(), u.norm());
                    if nn > 0.0 && un > 0.0 && (n.dot(&u) / (nn * un)).abs() >= max_cos {
                        continue;
                    }
                }
                tested.push((pi, k));
                let mid = |p: Point3, q: Point3| Point3::from((p.coords + q.coords) * 0.5);
                samples.extend([centroid, mid(a, b), mid(b, c), mid(c, a)]);
            }
        }
        let flags = self.flags(&samples, own);
        let mut drop: Vec<Vec<bool>> =
            patches.iter().map(|p| vec![false; p.num_triangles()]).collect();
        let mut removed = 0;
        for (&(pi, k), f) in tested.iter().zip(flags.chunks(SAMPLES_PER_TRIANGLE)) {
            if f.iter().filter(|&&f| f).count() >= self.config.min_empty_samples {
                drop[pi][k] = true;
                removed += 1;
            }
        }
        let carved = Carved { tested: tested.len(), removed };
        let kept = patches.iter().zip(&drop).filter_map(|(patch, drop)| without(patch, drop));
        (kept.collect(), carved)
    }
}

/// `patch` without the triangles `drop` marks, and with only the vertices the rest use; `None`
/// when none is left.
fn without(patch: &TrimeshPatch, drop: &[bool]) -> Option<TrimeshPatch> {
    if !drop.contains(&true) {
        return Some(patch.clone());
    }
    let v = patch.vertices();
    let mut index = vec![u32::MAX; v.len()];
    let mut vertices = Vec::new();
    let triangles: Vec<[u32; 3]> = patch
        .triangles()
        .iter()
        .zip(drop)
        .filter(|&(_, &d)| !d)
        .map(|(t, _)| {
            t.map(|i| {
                let slot = &mut index[i as usize];
                if *slot == u32::MAX {
                    *slot = vertices.len() as u32;
                    vertices.push(v[i as usize]);
                }
                *slot
            })
        })
        .collect();
    // The kept triangles were valid in the patch; an empty rest is refused (None).
    TrimeshPatch::new(vertices, triangles).ok()
}

/// What one scan saw of the ball around a point.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
enum Sight {
    /// Beams on every side passed through it, none returned in it.
    Empty,
    /// A beam returned in it.
    Surface,
    /// Neither: out of view, occluded, or beams too far apart.
    Unseen,
}

/// What `scan` saw of the ball around `p` (world); `angles` is scratch space.
fn scan_sees(scan: &ScanBeams, p: &Point3, c: &VisibilityConfig, angles: &mut Vec<Real>) -> Sight {
    let Some(tree) = &scan.tree else { return Sight::Unseen };
    let q = scan.sensor_from_world * p;
    let d = q.coords.norm();
    // The ball must lie wholly in front of the sensor, and the beams near it must be able to
    // lie within `max_gap` of it on every side.
    if beyond_reach(scan, d, c) {
        return Sight::Unseen;
    }
    let u = q.coords / d;
    // Every beam that passes within ρ lies within 2° of `u` from this range on; when they all
    // stop short of the ball, none sees it.
    if c.ball_radius <= d * COARSE_BIN.sin()
        && scan.all_stop_before(&u, d - c.ball_radius - c.return_margin)
    {
        return Sight::Unseen;
    }
    scan_sees_searched(scan, tree, &q, d, &u, c, angles)
}

/// [`scan_sees`] by the search of the nearest beams alone (`q` in the sensor frame, `d` its
/// range, `u` its direction).
fn scan_sees_searched(
    scan: &ScanBeams,
    tree: &ImmutableKdTree<Real, 3>,
    q: &Point3,
    d: Real,
    u: &Vector3,
    c: &VisibilityConfig,
    angles: &mut Vec<Real>,
) -> Sight {
    if beyond_reach(scan, d, c) {
        return Sight::Unseen;
    }
    let qty = NonZeroUsize::new(c.beams).unwrap_or(NonZeroUsize::MIN);
    let found = tree.query(&[u.x, u.y, u.z]).nearest_n::<SquaredEuclidean<Real>>(qty).execute();
    // A frame on the plane across the view at p, for the angles of the evidence beams.
    let (e1, e2) = across(u);
    angles.clear();
    let rho2 = c.ball_radius * c.ball_radius;
    let gap2 = c.max_gap * c.max_gap;
    for n in found {
        let k = n.item as usize;
        let b = scan.directions[k];
        let t = b.dot(&q.coords);
        if t <= 0.0 {
            continue;
        }
        let off = q.coords - b * t;
        let l2 = off.norm_squared();
        if l2 > rho2 {
            continue;
        }
        let h = (rho2 - l2).sqrt();
        let r = scan.ranges[k];
        if r < t - h - c.return_margin {
            continue; // stopped before the ball: no evidence either way
        }
        if r <= t + h + c.return_margin {
            return Sight::Surface; // hit something in or at the ball
        }
        if l2 <= gap2 {
            angles.push(off.dot(&e2).atan2(off.dot(&e1)));
        }
    }
    if angles.len() < 3 {
        return Sight::Unseen;
    }
    angles.sort_by(Real::total_cmp);
    let wrap = angles[0] + std::f64::consts::TAU - angles[angles.len() - 1];
    let widest = angles.windows(2).map(|w| w[1] - w[0]).fold(wrap, Real::max);
    if widest <= c.max_gap_angle { Sight::Empty } else { Sight::Unseen }
}

/// Whether a ball at range `d` is out of `scan`'s reach: not wholly in front of the sensor,
/// or where its beams lie too far apart to be within `max_gap` of a point on every side.
fn beyond_reach(scan: &ScanBeams, d: Real, c: &VisibilityConfig) -> bool {
    d <= c.ball_radius || d * scan.spacing > 2.0 * c.max_gap
}

/// Two unit vectors that span the plane across the unit vector `u`.
fn across(u: &Vector3) -> (Vector3, Vector3) {
    let helper = if u.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() };
    let e1 = u.cross(&helper).normalize();
    (e1, u.cross(&e1))
}

/// The median angle between a beam and its nearest neighbour, over up to 1,000 beams spread
/// over the scan.
fn median_spacing(tree: &ImmutableKdTree<Real, 3>, coords: &[[Real; 3]]) -> Real {
    let two = NonZeroUsize::new(2).unwrap_or(NonZeroUsize::MIN);
    let stride = (coords.len() / 1000).max(1);
    let mut found: Vec<Real> = coords
        .iter()
        .step_by(stride)
        .filter_map(|q| {
            let n = tree.query(q).nearest_n::<SquaredEuclidean<Real>>(two).execute();
            n.get(1).map(|n| n.distance.sqrt())
        })
        .collect();
    if found.is_empty() {
        return 0.0;
    }
    let mid = found.len() / 2;
    *found.select_nth_unstable_by(mid, Real::total_cmp).1
}

/// The points of an organised scan with a grid neighbour (of 8) whose range differs by more
/// than `jump`, in index order.
fn depth_jump_points(scan: &PointCloud, jump: Real) -> Vec<usize> {
    let Some(grid) = scan.grid() else { return (0..scan.len()).collect() };
    let (w, h) = (grid.width() as i64, grid.height() as i64);
    let ranges: Vec<Real> = scan.positions().iter().map(|p| p.coords.norm()).collect();
    let range = |i: usize| ranges[i];
    let mut out = Vec::new();
    for row in 0..h {
        for col in 0..w {
            let Some(i) = grid.point_index(col as u32, row as u32) else { continue };
            let r = range(i);
            let edge = (-1..=1i64).any(|dr| {
                (-1..=1i64).any(|dc| {
                    let (c2, r2) = (col + dc, row + dr);
                    (dr, dc) != (0, 0)
                        && (0..w).contains(&c2)
                        && (0..h).contains(&r2)
                        && grid
                            .point_index(c2 as u32, r2 as u32)
                            .is_some_and(|j| (range(j) - r).abs() > jump)
                })
            });
            if edge {
                out.push(i);
            }
        }
    }
    out.sort_unstable();
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use pointcloud::SensorPose;

    /// A fan of 81 × 81 beams from `origin` toward +x (sensor frame = world shifted), every
    /// beam returning at `range(direction)`.
    fn fan(origin: Point3, step: Real, range: impl Fn(&Vector3) -> Real) -> PointCloud {
        let mut pts = Vec::new();
        for i in -40..=40 {
            for j in -40..=40 {
                let d = Vector3::new(1.0, i as Real * step, j as Real * step).normalize();
                pts.push(Point3::from(d * range(&d)));
            }
        }
        let mut c = PointCloud::from_positions(pts).unwrap();
        c.set_sensor_pose(Some(SensorPose {
            world_from_sensor: Isometry3::translation(origin.x, origin.y, origin.z),
        }));
        c
    }

    #[test]
    fn a_point_another_scan_saw_through_is_carved_and_one_on_its_wall_is_not() {
        // Scan 0 looks along +x at a wall at x = 3 (sensor at the origin), with beams
        // 0.5° apart (2.6 cm at 3 m).
        let wall = fan(Point3::origin(), 0.5f64.to_radians(), |d| 3.0 / d.x);
        let space = FreeSpace::new(&[wall], &VisibilityConfig::alrf()).unwrap();
        assert!(space.seen_empty(&Point3::new(2.0, 0.01, 0.013), None), "mid-air");
        assert!(!space.seen_empty(&Point3::new(2.98, 0.01, 0.013), None), "on the wall");
        assert!(!space.seen_empty(&Point3::new(2.95, 0.0, 0.0), None), "within ρ of it");
        assert!(!space.seen_empty(&Point3::new(3.5, 0.0, 0.0), None), "behind it");
        assert!(!space.seen_empty(&Point3::new(2.0, 0.01, 0.013), Some(0)), "own scan");
        // Off the fan's edge the point has no beams on one side.
        assert!(!space.seen_empty(&Point3::new(2.0, 0.74, 0.0), None), "edge of the view");
    }

    #[test]
    fn beams_too_far_apart_do_not_carve() {
        // 2° beams: 10 cm apart at 3 m, more than max_gap.
        let wall = fan(Point3::origin(), 2f64.to_radians(), |d| 3.0 / d.x);
        let space = FreeSpace::new(&[wall], &VisibilityConfig::alrf()).unwrap();
        assert!(!space.seen_empty(&Point3::new(2.9, 0.05, 0.05), None));
        let near = Point3::new(0.6, 0.005, 0.005);
        assert!(space.seen_empty(&near, None), "at 0.6 m they are 2 cm apart");
    }

    #[test]
    fn a_post_between_the_scanner_and_the_wall_vetoes() {
        // A 5 cm post at x = 2, |y| ≤ 2.5 cm, seen by 0.5° beams (1.7 cm apart at 2 m).
        let scan = fan(Point3::origin(), 0.5f64.to_radians(), |d| {
            let at_post = d * (2.0 / d.x);
            if at_post.y.abs() <= 0.025 { 2.0 / d.x } else { 3.0 / d.x }
        });
        let space = FreeSpace::new(&[scan], &VisibilityConfig::alrf()).unwrap();
        // A point on the post's back, which this scan could not see, and one on its edge.
        assert!(!space.seen_empty(&Point3::new(2.05, 0.0, 0.0), None));
        assert!(!space.seen_empty(&Point3::new(2.0, 0.025, 0.0), None));
        // Beside the post, in the open: carved.
        assert!(space.seen_empty(&Point3::new(2.0, 0.2, 0.0), None));
    }

    #[test]
    fn veil_triangles_go_and_wall_triangles_stay() {
        let wall = fan(Point3::origin(), 0.5f64.to_radians(), |d| 3.0 / d.x);
        // Scan 1 sits beside scan 0 with no beams of its own near the test triangles.
        let other = fan(Point3::new(0.0, 50.0, 0.0), 0.5f64.to_radians(), |d| 3.0 / d.x);
        let space = FreeSpace::new(&[wall.clone(), other], &VisibilityConfig::alrf()).unwrap();
        // Seen from scan 1 at (0, 50, 0), a veil along its beams.
        let veil = TrimeshPatch::new(
            vec![
                Point3::new(1.5, 49.99, 0.0),
                Point3::new(2.5, 50.01, 0.0),
                Point3::new(2.0, 50.0, 0.05),
            ],
            vec![[0, 1, 2]],
        )
        .unwrap();
        let (kept, carved) = space.carve_trimesh(&veil, Some(1));
        assert_eq!(carved, Carved { tested: 1, removed: 0 }, "scan 0 does not see there");
        assert!(kept.is_some());
        // Moved in front of scan 0 (and tested as scan 1's): carved.
        let veil = veil.transformed(&Isometry3::translation(0.0, -50.0, 0.0));
        let (kept, carved) = space.carve_trimesh(&veil, None);
        assert!(kept.is_none());
        assert_eq!(carved.removed, 1);
        // A triangle on scan 0's wall, tested as scan 1's: the wall vetoes.
        let on_wall = TrimeshPatch::new(
            vec![
                Point3::new(3.0, 0.0, 0.0),
                Point3::new(3.0, 0.05, 0.0),
                Point3::new(3.0, 0.0, 0.05),
            ],
            vec![[0, 1, 2]],
        )
        .unwrap();
        let (kept, carved) = space.carve_trimesh(&on_wall, None);
        assert_eq!(carved, Carved { tested: 1, removed: 0 });
        assert!(kept.is_some());
    }

    #[test]
    fn clouds_keep_what_no_other_scan_saw_through() {
        let a = fan(Point3::origin(), 0.5f64.to_radians(), |d| 3.0 / d.x);
        // Scan 1: at (1, 0, 0) looking along +x, its beams all stopped 1 m ahead, at a
        // surface at x = 2 that scan 0 went through... and its point at x=2 lies in scan 0's
        // free space, so it goes; scan 0's wall at x = 3 lies behind scan 1's returns, so it
        // stays.
        let b = fan(Point3::new(1.0, 0.0, 0.0), 0.5f64.to_radians(), |d| 1.0 / d.x);
        let space = FreeSpace::new(&[a.clone(), b.clone()], &VisibilityConfig::alrf()).unwrap();
        let (out, carved) = space.carve_clouds(&[a.clone(), b.clone()]).unwrap();
        assert_eq!(out[0].len(), a.len());
        assert!(out[1].len() < b.len() / 2, "{} of {}", out[1].len(), b.len());
        assert_eq!(carved.tested, a.len() + b.len());
        // Testing no point keeps every point; one candidate list per scan is needed.
        let (out, carved) =
            space.carve_clouds_at(&[a.clone(), b.clone()], &[vec![], vec![]]).unwrap();
        assert_eq!((out[1].len(), carved), (b.len(), Carved::default()));
        assert!(space.carve_clouds_at(&[a.clone(), b.clone()], &[vec![]]).is_err());
        assert!(matches!(
            space.carve_clouds(&[a]),
            Err(VisibilityError::ScanCount { given: 1, indexed: 2 })
        ));
    }

    #[test]
    fn a_phantom_in_front_of_space_no_scan_saw_stays() {
        // Scan 0 sees a wall at x = 3, but beams with y > 0.05 x stop at a box face at x = 2:
        // behind that face (x > 2) lies its shadow.
        let a = fan(Point3::origin(), 0.5f64.to_radians(), |d| {
            if d.y > 0.05 * d.x { 2.0 / d.x } else { 3.0 / d.x }
        });
        // Scan 1, at (1, 0.2, 0), put one point at (1.7, 0.2, 0): in space scan 0 saw empty,
        // but 0.3 m in front of its shadow, which the test looks 0.5 m behind the point into.
        // (Across the beam, 0.5 m off, lie the edges of scan 0's fan: unseen as well.)
        let mut b = PointCloud::from_positions(vec![Point3::new(0.7, 0.0, 0.0)]).unwrap();
        b.set_sensor_pose(Some(SensorPose {
            world_from_sensor: Isometry3::translation(1.0, 0.2, 0.0),
        }));
        let scans = [a, b];
        let config = VisibilityConfig { neighbourhood: Some(0.5), ..VisibilityConfig::alrf() };
        let (kept, carved) = FreeSpace::new(&scans, &config).unwrap().carve_clouds(&scans).unwrap();
        assert_eq!(kept[1].len(), 1, "{carved:?}");
        let blind = VisibilityConfig { neighbourhood: None, ..VisibilityConfig::alrf() };
        let (kept, _) = FreeSpace::new(&scans, &blind).unwrap().carve_clouds(&scans).unwrap();
        assert_eq!(kept[1].len(), 0, "without the neighbourhood test, it goes");
    }

    #[test]
    fn the_coarse_bins_never_change_an_answer() {
        // A wall at 6 m with a box face at 3 m over a quarter of the view; points spread over
        // 1–7 m, in front of, at and behind both.
        let scan = fan(Point3::origin(), 0.5f64.to_radians(), |d| {
            if d.y > 0.0 && d.z > 0.0 { 3.0 / d.x } else { 6.0 / d.x }
        });
        let space = FreeSpace::new(&[scan], &VisibilityConfig::alrf()).unwrap();
        let beams = &space.scans[0];
        let tree = beams.tree.as_ref().unwrap();
        let c = space.config;
        let mut angles = Vec::new();
        let (mut seen, mut skipped) = (std::collections::HashMap::new(), 0);
        for i in 0..4000u32 {
            // A fixed low-discrepancy spread: no randomness needed.
            let f = |k: u32, m: f64| (i as f64 * m + k as f64 * 0.37) % 1.0;
            let p = Point3::new(
                1.0 + 6.0 * f(0, 0.618),
                2.0 * f(1, 0.754) - 1.0,
                2.0 * f(2, 0.569) - 1.0,
            );
            let d = p.coords.norm();
            let u = p.coords / d;
            let fast = scan_sees(beams, &p, &c, &mut angles);
            let searched = scan_sees_searched(beams, tree, &p, d, &u, &c, &mut angles);
            assert_eq!(fast, searched, "{p:?}");
            *seen.entry(format!("{fast:?}")).or_insert(0) += 1;
            if c.ball_radius <= d * COARSE_BIN.sin()
                && beams.all_stop_before(&u, d - c.ball_radius - c.return_margin)
            {
                skipped += 1;
            }
        }
        assert_eq!(seen.len(), 3, "every answer occurs: {seen:?}");
        assert!(skipped > 100, "the bins decide some points: {skipped}");
    }

    #[test]
    fn bad_parameters_are_refused() {
        let bad = VisibilityConfig { max_gap: 0.2, ..VisibilityConfig::alrf() };
        assert!(matches!(
            bad.validate(),
            Err(VisibilityError::BadParameter { name: "max_gap", .. })
        ));
        let bad = VisibilityConfig { ball_radius: Real::NAN, ..VisibilityConfig::alrf() };
        assert!(FreeSpace::new(&[], &bad).is_err());
        let bad = VisibilityConfig { beams: 1, ..VisibilityConfig::alrf() };
        assert!(bad.validate().is_err());
        assert!(FreeSpace::new(&[PointCloud::new()], &VisibilityConfig::alrf()).is_ok());
    }
}
