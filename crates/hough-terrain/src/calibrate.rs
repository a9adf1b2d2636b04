//! Mount self-calibration: the sensor's height, pitch and roll above the ground, estimated from
//! the frame itself, so that a user need not measure them (the thesis takes them as given,
//! L3417–3419; this module is not in the thesis).
//!
//! **The rule.** The ground is the dominant plane that nothing stands beneath. Among planes
//! through three sampled points (RANSAC) whose normal is within [`MountSearch::max_tilt`] of the
//! sensor's nominal up axis and which pass between [`MountSearch::min_height`] and
//! [`MountSearch::max_height`] below the sensor, the search keeps the one with the most points
//! within [`MountSearch::inlier_distance`] minus the points more than
//! [`MountSearch::below_margin`] below it (a table top or a plateau has the floor beneath it;
//! the floor has nothing). Its points must spread over an area ([`MountSearch::min_spread`]).
//! The winner is refitted by least squares to its inliers, near points weighted more (range
//! noise grows with range), the band widened to the residuals' spread on noisy frames. Height is
//! the sensor's distance from that plane; pitch and roll are the tilt of its normal in the
//! sensor's nominal body axes (x forward, y left, z up).
//!
//! One frame that shows mostly a ramp or a plateau calibrates to that surface: a robot should
//! calibrate on frames of its ground, or keep a running median over many frames
//! ([`MountWindow`]), which outvotes the few frames that show mostly something else.

use crate::error::{HoughError, Result};
use crate::mount::{SensorAxes, SensorMount};
use nalgebra::{Matrix3, Point3, Vector3};
use rand::{Rng as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;
use std::collections::VecDeque;

/// How the ground plane is searched for. `Default` suits range cameras, stereo cameras and
/// spinning lidar mounted on a ground robot or a car.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct MountSearch {
    /// The sensor's axis convention, which fixes its nominal forward and up axes.
    pub axes: SensorAxes,
    /// Largest tilt of the ground's normal from the nominal up axis, radians (default 40°).
    pub max_tilt: f64,
    /// Lowest accepted sensor height above the ground, metres (default 0.05).
    pub min_height: f64,
    /// Highest accepted sensor height above the ground, metres (default 5).
    pub max_height: f64,
    /// Only points within this horizontal range of the sensor take part, metres (default 30).
    pub max_range: f64,
    /// A point within this distance of a plane supports it, metres (default 0.04).
    pub inlier_distance: f64,
    /// A point more than this below a plane counts against it, metres (default 0.25): a table
    /// top or a plateau has the floor beneath it. Well above the range noise, so that the
    /// floor's own noisy points do not count against the floor.
    pub below_margin: f64,
    /// The ground's supporting points must spread at least this far (standard deviation,
    /// metres) in both directions of the plane (default 0.15): a band across a wall or the
    /// edge of a box top is no ground.
    pub min_spread: f64,
    /// Planes tried (default 400).
    pub iterations: usize,
    /// At most this many points, taken evenly from the frame, take part (default 6000).
    pub max_points: usize,
    /// Seed of the plane sampling: the same frame and seed give the same estimate.
    pub seed: u64,
}

impl Default for MountSearch {
    fn default() -> Self {
        MountSearch {
            axes: SensorAxes::Body,
            max_tilt: 40f64.to_radians(),
            min_height: 0.05,
            max_height: 5.0,
            max_range: 30.0,
            inlier_distance: 0.04,
            below_margin: 0.25,
            min_spread: 0.15,
            iterations: 400,
            max_points: 6000,
            seed: 0,
        }
    }
}

impl MountSearch {
    /// The default search for a sensor with `axes`.
    pub fn new(axes: SensorAxes) -> MountSearch {
        MountSearch { axes, ..MountSearch::default() }
    }

    /// Checks every parameter.
    ///
    /// # Errors
    /// [`HoughError::BadParameter`] naming the first parameter out of range.
    pub fn validate(&self) -> Result<()> {
        let bad = |what: &'static str, value: f64, allowed: &'static str| {
            Err(HoughError::BadParameter { what, value, allowed })
        };
        if !(self.max_tilt > 0.0 && self.max_tilt < std::f64::consts::FRAC_PI_2) {
            return bad("mount search max_tilt", self.max_tilt, "in (0, π/2) radians");
        }
        if !(self.min_height.is_finite() && self.min_height >= 0.0) {
            return bad("mount search min_height", self.min_height, "finite and ≥ 0");
        }
        if !(self.max_height.is_finite() && self.max_height > self.min_height) {
            return bad("mount search max_height", self.max_height, "finite and > min_height");
        }
        if !(self.max_range.is_finite() && self.max_range > 0.0) {
            return bad("mount search max_range", self.max_range, "finite and > 0");
        }
        if !(self.inlier_distance.is_finite() && self.inlier_distance > 0.0) {
            return bad("mount search inlier_distance", self.inlier_distance, "finite and > 0");
        }
        if !(self.below_margin.is_finite() && self.below_margin > 0.0) {
            return bad("mount search below_margin", self.below_margin, "finite and > 0");
        }
        if !(self.min_spread.is_finite() && self.min_spread >= 0.0) {
            return bad("mount search min_spread", self.min_spread, "finite and ≥ 0");
        }
        if !(1..=1_000_000).contains(&self.iterations) {
            return bad("mount search iterations", self.iterations as f64, "1 to 1,000,000");
        }
        if !(3..=10_000_000).contains(&self.max_points) {
            return bad("mount search max_points", self.max_points as f64, "3 to 10,000,000");
        }
        Ok(())
    }
}

/// The mount found by [`estimate_mount`].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct MountEstimate {
    /// The mount, ready for [`crate::HoughConfig::thesis`].
    pub mount: SensorMount,
    /// The sensor's height above the ground plane, metres.
    pub height: f64,
    /// Pitch, radians down from level (as [`SensorMount::looking_ahead`] takes it).
    pub pitch: f64,
    /// Roll, radians; positive lowers the right side.
    pub roll: f64,
    /// Points within the inlier distance of the ground plane.
    pub inliers: usize,
    /// Points that took part.
    pub points: usize,
    /// Root-mean-square distance of the inliers from the plane, metres.
    pub rms: f64,
}

/// A plane `n · p + d = 0` in body axes with `n` a unit vector pointing up: `d` is the height
/// of the origin above it.
#[derive(Copy, Clone, Debug)]
struct Ground {
    n: Vector3<f64>,
    d: f64,
}

impl Ground {
    /// The plane through three points, oriented up; `None` when they are (nearly) collinear.
    fn through(a: &Point3<f64>, b: &Point3<f64>, c: &Point3<f64>) -> Option<Ground> {
        let n = (b - a).cross(&(c - a));
        let len = n.norm();
        if len.is_nan() || len <= 1e-9 {
            return None;
        }
        let n = if n.z < 0.0 { -n / len } else { n / len };
        Some(Ground { n, d: -n.dot(&a.coords) })
    }

    fn distance(&self, p: &Point3<f64>) -> f64 {
        self.n.dot(&p.coords) + self.d
    }
}

/// Estimates the sensor's mount from one frame of sensor-frame points (see the module docs).
///
/// # Errors
/// A bad parameter, fewer than three usable points, or no plane the search accepts.
pub fn estimate_mount(points: &[Point3<f64>], search: &MountSearch) -> Result<MountEstimate> {
    search.validate()?;
    let body_from_sensor = search.axes.body_from_sensor();
    let usable: Vec<Point3<f64>> = points
        .iter()
        .map(|p| body_from_sensor * p)
        .filter(|p| {
            let r = p.x.hypot(p.y);
            p.iter().all(|v| v.is_finite()) && r > 0.0 && r <= search.max_range
        })
        .collect();
    let step = usable.len().div_ceil(search.max_points).max(1);
    let pts: Vec<Point3<f64>> = usable.into_iter().step_by(step).collect();
    if pts.len() < 3 {
        return Err(HoughError::NotEnoughPoints { got: pts.len(), need: 3 });
    }
    let mut tol = search.inlier_distance;
    let min_up = search.max_tilt.cos();
    let accept =
        |g: &Ground| g.n.z >= min_up && (search.min_height..=search.max_height).contains(&g.d);
    let score = |g: &Ground| {
        pts.iter().fold(0i64, |s, p| {
            let e = g.distance(p);
            if e.abs() <= tol {
                s + 1
            } else if e < -search.below_margin {
                s - 1
            } else {
                s
            }
        })
    };
    let mut rng = ChaCha8Rng::seed_from_u64(search.seed);
    let mut best: Option<(i64, Ground)> = None;
    for _ in 0..search.iterations {
        let i = rng.random_range(0..pts.len());
        let j = rng.random_range(0..pts.len());
        let k = rng.random_range(0..pts.len());
        if i == j || j == k || i == k {
            continue;
        }
        let Some(g) = Ground::through(&pts[i], &pts[j], &pts[k]).filter(accept) else {
            continue;
        };
        let s = score(&g);
        if best.is_none_or(|(b, _)| s > b) && spread(&pts, &g, tol) >= search.min_spread {
            best = Some((s, g));
        }
    }
    let Some((_, mut ground)) = best else {
        return Err(HoughError::NoGround {
            tried: search.iterations,
            max_tilt_deg: search.max_tilt.to_degrees(),
        });
    };
    let refine = |ground: Ground, tol: f64| {
        refit(&pts, &ground, tol)
            .filter(|g| accept(g) && spread(&pts, g, tol) >= search.min_spread)
            .unwrap_or(ground)
    };
    ground = refine(refine(ground, tol), tol);
    // Noisy frames (sunlit time of flight): widen the band to the residuals' robust spread
    // (2.5 σ from the median absolute residual within 5 tolerances), at most 5 tolerances.
    let wide = 5.0 * search.inlier_distance;
    let mut r: Vec<f64> =
        pts.iter().map(|p| ground.distance(p).abs()).filter(|e| *e <= wide).collect();
    if r.len() >= 3 {
        r.sort_by(f64::total_cmp);
        tol = (2.5 * 1.4826 * r[r.len() / 2]).clamp(search.inlier_distance, wide);
    }
    ground = refine(ground, tol);
    let inliers: Vec<f64> =
        pts.iter().map(|p| ground.distance(p)).filter(|e| e.abs() <= tol).collect();
    let rms = (inliers.iter().map(|e| e * e).sum::<f64>() / inliers.len().max(1) as f64).sqrt();
    let (height, pitch, roll) = (ground.d, (-ground.n.x).asin(), ground.n.y.atan2(ground.n.z));
    Ok(MountEstimate {
        mount: SensorMount::looking_ahead(height, pitch, roll, search.axes)?,
        height,
        pitch,
        roll,
        inliers: inliers.len(),
        points: pts.len(),
        rms,
    })
}

/// The smaller in-plane standard deviation of the points within `tol` of `ground`, metres (0
/// with fewer than three).
fn spread(pts: &[Point3<f64>], ground: &Ground, tol: f64) -> f64 {
    let near: Vec<&Point3<f64>> = pts.iter().filter(|p| ground.distance(p).abs() <= tol).collect();
    if near.len() < 3 {
        return 0.0;
    }
    let c = near.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / near.len() as f64;
    let cov = near.iter().fold(Matrix3::zeros(), |m, p| {
        let v = p.coords - c;
        m + v * v.transpose()
    }) / near.len() as f64;
    // Eigenvalues ascending: the smallest is across the plane, the middle one the smaller
    // in-plane spread.
    let mut ev: Vec<f64> = cov.symmetric_eigenvalues().iter().copied().collect();
    ev.sort_by(f64::total_cmp);
    ev[1].max(0.0).sqrt()
}

/// The least-squares plane of the points within `tol` of `ground`, oriented up, each point
/// weighted by `1 / r²` (`r` its distance from the sensor, at least 0.5 m): range noise grows
/// with range, and the floor near the robot is seen at the steepest angle.
fn refit(pts: &[Point3<f64>], ground: &Ground, tol: f64) -> Option<Ground> {
    let near: Vec<(&Point3<f64>, f64)> = pts
        .iter()
        .filter(|p| ground.distance(p).abs() <= tol)
        .map(|p| (p, 1.0 / p.coords.norm_squared().max(0.25)))
        .collect();
    if near.len() < 3 {
        return None;
    }
    let total: f64 = near.iter().map(|(_, w)| w).sum();
    let c = near.iter().fold(Vector3::zeros(), |s, (p, w)| s + p.coords * *w) / total;
    let cov = near.iter().fold(Matrix3::zeros(), |m, (p, w)| {
        let v = p.coords - c;
        m + v * v.transpose() * *w
    });
    let eig = cov.symmetric_eigen();
    let n = eig.eigenvectors.column(eig.eigenvalues.imin()).into_owned();
    let n = if n.z < 0.0 { -n } else { n };
    (n.norm() > 0.5).then(|| Ground { n, d: -n.dot(&c) })
}

/// A running median of mount estimates over the last frames: a robot that calibrates while it
/// drives outvotes the frames that show mostly a ramp, a plateau or a wall.
#[derive(Clone, Debug)]
pub struct MountWindow {
    axes: SensorAxes,
    len: usize,
    recent: VecDeque<(f64, f64, f64)>,
}

impl MountWindow {
    /// A window over the last `len` estimates (at least 1) of a sensor with `axes`.
    pub fn new(axes: SensorAxes, len: usize) -> MountWindow {
        MountWindow { axes, len: len.max(1), recent: VecDeque::new() }
    }

    /// Adds one frame's estimate, forgetting the oldest beyond the window.
    pub fn push(&mut self, e: &MountEstimate) {
        if self.recent.len() == self.len {
            self.recent.pop_front();
        }
        self.recent.push_back((e.height, e.pitch, e.roll));
    }

    /// Estimates in the window.
    pub fn len(&self) -> usize {
        self.recent.len()
    }

    /// Whether the window holds no estimate.
    pub fn is_empty(&self) -> bool {
        self.recent.is_empty()
    }

    /// The median height (m), pitch and roll (radians) of the window, each on its own, or
    /// `None` while empty.
    pub fn median(&self) -> Option<(f64, f64, f64)> {
        if self.recent.is_empty() {
            return None;
        }
        let median = |f: fn(&(f64, f64, f64)) -> f64| {
            let mut v: Vec<f64> = self.recent.iter().map(f).collect();
            v.sort_by(f64::total_cmp);
            let m = v.len() / 2;
            if v.len() % 2 == 1 { v[m] } else { 0.5 * (v[m - 1] + v[m]) }
        };
        Some((median(|e| e.0), median(|e| e.1), median(|e| e.2)))
    }

    /// The mount of [`MountWindow::median`], or `None` while empty.
    pub fn mount(&self) -> Option<SensorMount> {
        let (h, p, r) = self.median()?;
        SensorMount::looking_ahead(h, p, r, self.axes).ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Floor points seen by a sensor at `height`, `pitch`, `roll` with `axes`, plus a box on the
    /// floor (a plateau the rule must not take for the ground) and a wall.
    fn frame(height: f64, pitch: f64, roll: f64, axes: SensorAxes) -> Vec<Point3<f64>> {
        let m = SensorMount::looking_ahead(height, pitch, roll, axes).unwrap();
        let sensor_from_levelled = m.levelled_from_sensor().transpose();
        let mut levelled = Vec::new();
        for i in 0..60 {
            for j in 0..40 {
                let (x, y) = (0.8 + i as f64 * 0.06, -1.2 + j as f64 * 0.06);
                // A 0.3 m high box top, 1.5–2.1 m ahead and right of centre, has nothing
                // of the floor under it in view, but the floor around it is lower.
                let top = (1.5..2.1).contains(&x) && (0.0..0.9).contains(&y);
                levelled.push(Point3::new(x, y, if top { height - 0.3 } else { height }));
            }
        }
        for j in 0..40 {
            for k in 0..20 {
                levelled.push(Point3::new(4.5, -1.2 + j as f64 * 0.06, height - k as f64 * 0.1));
            }
        }
        levelled.iter().map(|q| Point3::from(sensor_from_levelled * q.coords)).collect()
    }

    #[test]
    fn recovers_height_pitch_and_roll() {
        for (h, p, r, axes) in [
            (0.45, 0.0, 0.0, SensorAxes::Optical),
            (0.8, 12f64.to_radians(), -4f64.to_radians(), SensorAxes::Optical),
            (1.73, 2f64.to_radians(), 1f64.to_radians(), SensorAxes::Body),
        ] {
            let e = estimate_mount(&frame(h, p, r, axes), &MountSearch::new(axes)).unwrap();
            assert!((e.height - h).abs() < 1e-6, "{h}: {e:?}");
            assert!((e.pitch - p).abs() < 1e-6 && (e.roll - r).abs() < 1e-6, "{p} {r}: {e:?}");
            let want = SensorMount::looking_ahead(h, p, r, axes).unwrap();
            assert!((e.mount.levelled_from_sensor() - want.levelled_from_sensor()).norm() < 1e-6);
        }
    }

    #[test]
    fn refuses_bad_input_with_a_typed_error() {
        let s = MountSearch::default();
        assert!(matches!(estimate_mount(&[], &s), Err(HoughError::NotEnoughPoints { .. })));
        let nan = vec![Point3::new(f64::NAN, 0.0, 0.0); 10];
        assert!(matches!(estimate_mount(&nan, &s), Err(HoughError::NotEnoughPoints { .. })));
        // A wall seen from 1 m with nothing of the floor: a band across it is no ground.
        let wall_only: Vec<_> = (0..400)
            .map(|i| Point3::new(1.0, (i % 40) as f64 * 0.05 - 1.0, (i / 40) as f64 * 0.07 - 0.35))
            .collect();
        assert!(matches!(estimate_mount(&wall_only, &s), Err(HoughError::NoGround { .. })));
        // Only a wall: no plane within the tilt limit.
        let wall: Vec<_> = (0..100)
            .map(|i| Point3::new(2.0, (i % 10) as f64 * 0.1, (i / 10) as f64 * 0.1))
            .collect();
        assert!(matches!(estimate_mount(&wall, &s), Err(HoughError::NoGround { .. })));
        for bad in [
            MountSearch { max_tilt: 0.0, ..s },
            MountSearch { max_height: 0.0, ..s },
            MountSearch { inlier_distance: f64::NAN, ..s },
            MountSearch { iterations: 0, ..s },
            MountSearch { min_spread: -1.0, ..s },
            MountSearch { below_margin: 0.0, ..s },
        ] {
            assert!(matches!(
                estimate_mount(&frame(0.5, 0.0, 0.0, SensorAxes::Body), &bad),
                Err(HoughError::BadParameter { .. })
            ));
        }
    }

    #[test]
    fn a_window_takes_the_median() {
        let axes = SensorAxes::Body;
        let mut w = MountWindow::new(axes, 3);
        assert!(w.mount().is_none());
        let e = |h: f64| MountEstimate {
            mount: SensorMount::looking_ahead(h, 0.0, 0.0, axes).unwrap(),
            height: h,
            pitch: 0.0,
            roll: 0.0,
            inliers: 10,
            points: 10,
            rms: 0.0,
        };
        for h in [9.0, 0.5, 0.4, 0.45] {
            w.push(&e(h));
        }
        assert_eq!(w.len(), 3);
        assert!((w.mount().unwrap().height() - 0.45).abs() < 1e-12);
    }
}
