//! Algorithm 2 (thesis §4.1.2, L3330–3350): every point votes, for every sampled angle pair
//! `(ρx, ρy)`, for the distance bin of `d = n·p`; votes outside the distance range are dropped
//! (L3429–3437: that is how walls are excluded).
//!
//! Two implementations give the same counts bin for bin:
//! * [`vote_literal`]: the reference, a line-by-line transcription with the trigonometry in the
//!   inner loop;
//! * [`NormalTable`]: the fast one. The normals are computed once per Hough space (with the same
//!   expressions, so bit-identical); points are copied into small structure-of-arrays blocks
//!   that stay in L1 cache; for each angle pair the block's distances are computed in a tight
//!   loop (no trigonometry, auto-vectorisable) and counted into that pair's `nd` contiguous
//!   `u32` bins. [`NormalTable::vote_parallel`] splits the points over scoped threads with one
//!   accumulator each and adds them up.

use crate::error::{HoughError, Result};
use crate::space::{Bin, HoughSpace, NormalKind};
use nalgebra::Point3;

/// Counts per bin of a [`HoughSpace`] (layout: see [`HoughSpace`]) and the number of points that
/// voted, `#PC` of Algorithm 3 (including points whose every vote fell outside the ranges).
#[derive(Clone, Debug, PartialEq)]
pub struct Accumulator {
    space: HoughSpace,
    counts: Vec<u32>,
    points: usize,
}

impl Accumulator {
    /// An empty accumulator (all counts 0, no points).
    pub fn new(space: HoughSpace) -> Accumulator {
        Accumulator { counts: vec![0; space.len()], space, points: 0 }
    }

    /// An accumulator with given counts (flat, in [`HoughSpace::index`] order) and `#PC`; for
    /// tests and for loading. Fails if the length does not match the space.
    pub fn from_counts(space: HoughSpace, counts: Vec<u32>, points: usize) -> Result<Accumulator> {
        if counts.len() != space.len() {
            return Err(HoughError::Mismatch {
                why: format!("{} counts for a space of {} bins", counts.len(), space.len()),
            });
        }
        Ok(Accumulator { space, counts, points })
    }

    /// The Hough space.
    pub fn space(&self) -> &HoughSpace {
        &self.space
    }

    /// All counts, flat.
    pub fn counts(&self) -> &[u32] {
        &self.counts
    }

    /// The count of one bin.
    ///
    /// # Panics
    /// If the bin is outside the space (like slice indexing).
    pub fn count(&self, bin: Bin) -> u32 {
        self.counts[self.space.index(bin)]
    }

    /// Adds `n` votes to a bin (saturating).
    ///
    /// # Panics
    /// If the bin is outside the space (like slice indexing).
    pub fn add(&mut self, bin: Bin, n: u32) {
        let i = self.space.index(bin);
        self.counts[i] = self.counts[i].saturating_add(n);
    }

    /// `#PC`: the number of points that voted.
    pub fn points(&self) -> usize {
        self.points
    }

    /// Sets `#PC` (for hand-built accumulators).
    pub fn set_points(&mut self, points: usize) {
        self.points = points;
    }

    /// Zeroes all counts and `#PC`, keeping the memory.
    pub fn clear(&mut self) {
        self.counts.fill(0);
        self.points = 0;
    }

    /// The sum of all counts (votes that landed in range).
    pub fn total_votes(&self) -> u64 {
        self.counts.iter().map(|&c| c as u64).sum()
    }

    /// `bin_max` of Algorithm 3: the bin with the most votes and its count; ties go to the first
    /// in storage order (ρy, then ρx, then d ascending). `None` if every count is 0.
    pub fn max_bin(&self) -> Option<(Bin, u32)> {
        let mut best = (0, 0);
        for (i, &c) in self.counts.iter().enumerate() {
            if c > best.1 {
                best = (i, c);
            }
        }
        (best.1 > 0).then(|| (self.space.bin(best.0), best.1))
    }

    /// The number of bins with strictly more than `threshold` votes (Algorithm 3's
    /// `#{bin | #bin > t_m · #bin_max}` with `threshold = t_m · #bin_max`).
    pub fn bins_above(&self, threshold: f64) -> usize {
        self.counts.iter().filter(|&&c| c as f64 > threshold).count()
    }

    /// Adds another accumulator of the same space (counts and `#PC`).
    pub fn merge(&mut self, other: &Accumulator) -> Result<()> {
        if other.space != self.space {
            return Err(HoughError::Mismatch {
                why: "merging accumulators of different spaces".into(),
            });
        }
        for (a, b) in self.counts.iter_mut().zip(&other.counts) {
            *a = a.saturating_add(*b);
        }
        self.points += other.points;
        Ok(())
    }

    /// Heap bytes held (for checking buffer reuse).
    pub fn capacity_bytes(&self) -> usize {
        self.counts.capacity() * std::mem::size_of::<u32>()
    }
}

fn check_space(acc: &Accumulator, space: &HoughSpace) -> Result<()> {
    if acc.space != *space {
        return Err(HoughError::Mismatch { why: "accumulator of another Hough space".into() });
    }
    Ok(())
}

fn check_points(points: &[Point3<f64>]) -> Result<()> {
    match points.iter().position(|p| !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite())) {
        Some(index) => Err(HoughError::NonFinitePoint { index }),
        None => Ok(()),
    }
}

/// The plane normal of the angle pair (`ρx`, `ρy`) of Algorithm 2:
/// `(−sin ρx cos ρy, −cos ρx sin ρy, cos ρx cos ρy)`, not of unit length (the thesis's), or
/// normalised for [`NormalKind::Unit`].
#[inline(always)]
fn normal(rho_x: f64, rho_y: f64, kind: NormalKind) -> [f64; 3] {
    let n = [-rho_x.sin() * rho_y.cos(), -rho_x.cos() * rho_y.sin(), rho_x.cos() * rho_y.cos()];
    if kind == NormalKind::Unit {
        let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        [n[0] / length, n[1] / length, n[2] / length]
    } else {
        n
    }
}

/// Algorithm 2 transcribed literally (L3330–3350), the reference the fast voting is tested
/// against and the baseline of the benchmark: for every point, every sampled `ρx`, every
/// sampled `ρy`: compute `n` with `sin`/`cos`, `d = n·p`, and increment the bin
/// `⌊(d − d_min)/d_res⌋` if it exists. Points are in the levelled frame; each counts once in
/// `#PC`. Fails on a non-finite point.
pub fn vote_literal(space: &HoughSpace, points: &[Point3<f64>]) -> Result<Accumulator> {
    check_points(points)?;
    let mut acc = Accumulator::new(*space);
    let d_axis = space.d_axis();
    for p in points {
        for ix in 0..space.nx() {
            let rho_x = space.rho_x(ix);
            for iy in 0..space.ny() {
                let rho_y = space.rho_y(iy);
                // Trigonometry per vote, as Algorithm 2 is written.
                let n = normal(rho_x, rho_y, space.normal_kind());
                let d = n[0] * p.x + n[1] * p.y + n[2] * p.z;
                let bin = ((d - d_axis.min) / d_axis.resolution).floor();
                if bin >= 0.0 && bin < space.nd() as f64 {
                    acc.add(Bin { ix, iy, id: bin as usize }, 1);
                }
            }
        }
    }
    acc.points = points.len();
    Ok(acc)
}

/// Points per structure-of-arrays block (3 × 256 × 8 B = 6 KiB on the stack, in L1).
const BLOCK: usize = 256;

/// The precomputed normals of a Hough space, one per angle pair in storage order: the fast
/// Algorithm 2 (see the module docs). Build once per space; voting allocates nothing.
#[derive(Clone, Debug)]
pub struct NormalTable {
    space: HoughSpace,
    nx: Vec<f64>,
    ny: Vec<f64>,
    nz: Vec<f64>,
}

impl NormalTable {
    /// The normals of every angle pair of `space` (the only trigonometry of the fast path).
    pub fn new(space: &HoughSpace) -> NormalTable {
        let pairs = space.angle_pairs();
        let (mut nx, mut ny, mut nz) =
            (Vec::with_capacity(pairs), Vec::with_capacity(pairs), Vec::with_capacity(pairs));
        for iy in 0..space.ny() {
            let rho_y = space.rho_y(iy);
            for ix in 0..space.nx() {
                let rho_x = space.rho_x(ix);
                // The same function as `vote_literal`, so the same bits.
                let n = normal(rho_x, rho_y, space.normal_kind());
                nx.push(n[0]);
                ny.push(n[1]);
                nz.push(n[2]);
            }
        }
        NormalTable { space: *space, nx, ny, nz }
    }

    /// The Hough space.
    pub fn space(&self) -> &HoughSpace {
        &self.space
    }

    /// Adds the votes of `points` (levelled frame) to `acc` and `points.len()` to its `#PC`.
    /// Fails on a non-finite point (before voting) or an accumulator of another space.
    pub fn vote(&self, points: &[Point3<f64>], acc: &mut Accumulator) -> Result<()> {
        check_space(acc, &self.space)?;
        check_points(points)?;
        self.vote_unchecked(points, &mut acc.counts);
        acc.points += points.len();
        Ok(())
    }

    /// [`Self::vote`] on up to `threads` scoped threads, each with its own accumulator from
    /// `partials` (grown to `threads − 1` and reused across calls), added up at the end. Falls
    /// back to one thread for small inputs (fewer than 2 blocks per thread).
    pub fn vote_parallel(
        &self,
        points: &[Point3<f64>],
        acc: &mut Accumulator,
        partials: &mut Vec<Accumulator>,
        threads: usize,
    ) -> Result<()> {
        check_space(acc, &self.space)?;
        check_points(points)?;
        let threads = threads.clamp(1, points.len().div_ceil(2 * BLOCK).max(1));
        if threads == 1 {
            self.vote_unchecked(points, &mut acc.counts);
            acc.points += points.len();
            return Ok(());
        }
        if partials.len() < threads - 1 || partials.iter().any(|p| p.space != self.space) {
            partials.clear();
            partials.resize_with(threads - 1, || Accumulator::new(self.space));
        }
        let chunk = points.len().div_ceil(threads);
        let mut chunks = points.chunks(chunk);
        let first = chunks.next().unwrap_or(&[]);
        std::thread::scope(|s| {
            for (part, ch) in partials.iter_mut().zip(chunks) {
                part.counts.fill(0);
                s.spawn(move || self.vote_unchecked(ch, &mut part.counts));
            }
            self.vote_unchecked(first, &mut acc.counts);
        });
        let used = points.len().div_ceil(chunk) - 1;
        for part in &partials[..used] {
            for (a, b) in acc.counts.iter_mut().zip(&part.counts) {
                *a = a.saturating_add(*b);
            }
        }
        acc.points += points.len();
        Ok(())
    }

    /// The voting kernel on checked input.
    fn vote_unchecked(&self, points: &[Point3<f64>], counts: &mut [u32]) {
        if self.space.nd() < SMALL_ND {
            self.vote_small(points, counts);
        } else {
            self.vote_direct(points, counts);
        }
    }

    /// Direct kernel for any number of distance bins: compute, test, increment.
    fn vote_direct(&self, points: &[Point3<f64>], counts: &mut [u32]) {
        let nd = self.space.nd();
        let ndf = nd as f64;
        let d_min = self.space.d_axis().min;
        let d_res = self.space.d_axis().resolution;
        let mut xs = [0.0f64; BLOCK];
        let mut ys = [0.0f64; BLOCK];
        let mut zs = [0.0f64; BLOCK];
        for block in points.chunks(BLOCK) {
            let m = load_block(block, &mut xs, &mut ys, &mut zs);
            let (xs, ys, zs) = (&xs[..m], &ys[..m], &zs[..m]);
            for (k, row) in counts.chunks_exact_mut(nd).enumerate() {
                let (a, b, c) = (self.nx[k], self.ny[k], self.nz[k]);
                for i in 0..m {
                    let d = a * xs[i] + b * ys[i] + c * zs[i];
                    let t = (d - d_min) / d_res;
                    if t >= 0.0 && t < ndf {
                        row[t as usize] += 1;
                    }
                }
            }
        }
    }

    /// Kernel for fewer than [`SMALL_ND`] distance bins (the thesis has 30): per angle pair,
    /// first the block's bin indices in a branch-free loop (out-of-range votes go to a trash
    /// slot `nd`), then the increments spread over [`LANES`] interleaved copies of the pair's
    /// histogram so that runs of equal bins (a floor) do not serialise on one counter, then the
    /// copies are added into the accumulator.
    fn vote_small(&self, points: &[Point3<f64>], counts: &mut [u32]) {
        let nd = self.space.nd();
        let ndf = nd as f64;
        let d_min = self.space.d_axis().min;
        let d_res = self.space.d_axis().resolution;
        let mut xs = [0.0f64; BLOCK];
        let mut ys = [0.0f64; BLOCK];
        let mut zs = [0.0f64; BLOCK];
        let mut idx = [0u32; BLOCK];
        let mut hist = [[0u32; SMALL_ND]; LANES];
        for block in points.chunks(BLOCK) {
            let m = load_block(block, &mut xs, &mut ys, &mut zs);
            let (xs, ys, zs) = (&xs[..m], &ys[..m], &zs[..m]);
            for (k, row) in counts.chunks_exact_mut(nd).enumerate() {
                let (a, b, c) = (self.nx[k], self.ny[k], self.nz[k]);
                for i in 0..m {
                    let d = a * xs[i] + b * ys[i] + c * zs[i];
                    let t = (d - d_min) / d_res;
                    idx[i] = if t >= 0.0 && t < ndf { t as u32 } else { nd as u32 };
                }
                let mut lanes = idx[..m].chunks_exact(LANES);
                for quad in &mut lanes {
                    for (h, &j) in hist.iter_mut().zip(quad) {
                        h[j as usize & (SMALL_ND - 1)] += 1;
                    }
                }
                for (h, &j) in hist.iter_mut().zip(lanes.remainder()) {
                    h[j as usize & (SMALL_ND - 1)] += 1;
                }
                for h in &mut hist {
                    for (r, v) in row.iter_mut().zip(&mut h[..nd]) {
                        *r += *v;
                        *v = 0;
                    }
                    h[nd] = 0;
                }
            }
        }
    }
}

/// Distance-bin counts below which [`NormalTable`] uses the interleaved-histogram kernel (a
/// power of two: indices are masked with `SMALL_ND − 1` instead of bounds-checked).
const SMALL_ND: usize = 256;
/// Interleaved histogram copies in the small kernel.
const LANES: usize = 4;

/// Copies a block of points into the structure-of-arrays buffers; returns its length.
#[inline]
fn load_block(
    block: &[Point3<f64>],
    xs: &mut [f64; BLOCK],
    ys: &mut [f64; BLOCK],
    zs: &mut [f64; BLOCK],
) -> usize {
    for (i, p) in block.iter().enumerate() {
        xs[i] = p.x;
        ys[i] = p.y;
        zs[i] = p.z;
    }
    block.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floor_points_vote_for_the_floor_bin() {
        let space = HoughSpace::thesis_degrees(15.0).unwrap();
        let pts: Vec<_> = (0..100)
            .map(|i| Point3::new(1.0 + i as f64 * 0.03, (i % 7) as f64 * 0.1 - 0.3, 0.45))
            .collect();
        let acc = vote_literal(&space, &pts).unwrap();
        let ix = HoughSpace::zero_index(space.rho_x_axis(), space.nx()).unwrap();
        let iy = HoughSpace::zero_index(space.rho_y_axis(), space.ny()).unwrap();
        let id = space.d_bin(0.45).unwrap();
        assert_eq!(acc.count(Bin { ix, iy, id }), 100);
        assert_eq!(acc.max_bin(), Some((Bin { ix, iy, id }, 100)));
        assert_eq!(acc.points(), 100);
        let mut fast = Accumulator::new(space);
        NormalTable::new(&space).vote(&pts, &mut fast).unwrap();
        assert_eq!(fast, acc);
    }

    #[test]
    fn wall_votes_are_dropped() {
        // A wall 1 m ahead: at the sampled angles (−45°, 0°) d = n·p stays in [−1, 2) only for
        // points up to 3 m above the sensor; higher up (z < −3 m) every vote is dropped.
        let space = HoughSpace::thesis_degrees(45.0).unwrap();
        let pts: Vec<_> = (0..50).map(|i| Point3::new(1.0, 0.0, -3.1 - i as f64 * 0.1)).collect();
        let acc = vote_literal(&space, &pts).unwrap();
        assert_eq!(acc.total_votes(), 0);
        assert_eq!(acc.points(), 50);
        assert_eq!(acc.max_bin(), None);
    }

    #[test]
    fn bad_points_and_spaces_are_errors() {
        let space = HoughSpace::thesis_degrees(45.0).unwrap();
        let pts = [Point3::new(0.0, 0.0, 1.0), Point3::new(f64::NAN, 0.0, 0.0)];
        assert!(matches!(vote_literal(&space, &pts), Err(HoughError::NonFinitePoint { index: 1 })));
        let table = NormalTable::new(&space);
        let mut acc = Accumulator::new(space);
        assert!(table.vote(&pts, &mut acc).is_err());
        let mut other = Accumulator::new(HoughSpace::thesis_degrees(15.0).unwrap());
        assert!(table.vote(&pts[..1], &mut other).is_err());
        assert!(Accumulator::from_counts(space, vec![0; 3], 0).is_err());
    }

    #[test]
    fn parallel_equals_serial() {
        let space = HoughSpace::thesis_degrees(9.0).unwrap();
        let pts: Vec<_> = (0..5000)
            .map(|i| {
                let f = i as f64;
                Point3::new((f * 0.37).sin() * 3.0, (f * 0.11).cos() * 2.0, (f * 0.05).sin())
            })
            .collect();
        let table = NormalTable::new(&space);
        let mut serial = Accumulator::new(space);
        table.vote(&pts, &mut serial).unwrap();
        let mut partials = Vec::new();
        for threads in [1, 2, 3, 8] {
            let mut par = Accumulator::new(space);
            table.vote_parallel(&pts, &mut par, &mut partials, threads).unwrap();
            assert_eq!(par, serial, "{threads} threads");
        }
    }
}
