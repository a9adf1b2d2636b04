//! Beyond the thesis: classify each part of the view separately, so the robot knows where to
//! steer. The levelled frame's ground plane is cut into a grid of azimuth × horizontal-range
//! sectors; every sector gets its own accumulator and runs Algorithm 3 with `#PC` = its own
//! points.

use crate::accumulator::{Accumulator, NormalTable};
use crate::classifier::HoughConfig;
use crate::classify::{Classification, algorithm3, floor_bin, rejected};
use crate::error::{HoughError, Result};
use crate::space::Bin;
use nalgebra::Point3;
use serde::{Deserialize, Serialize};

/// Sector boundaries in the levelled frame. Azimuth is `atan2(y, x)` with y to the right, so
/// **negative azimuths are left** of the heading; range is the horizontal distance
/// `√(x² + y²)`. Sector `(ia, ir)` has index `ir · n_azimuth + ia` (left to right, near to
/// far). Points outside every sector are ignored.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SectorGrid {
    azimuth_edges: Vec<f64>,
    range_edges: Vec<f64>,
    /// `tan` of the azimuth edges (points ahead are sorted without trigonometry).
    tan_edges: Vec<f64>,
}

impl SectorGrid {
    /// Sectors between consecutive `azimuth_edges` (radians, strictly increasing, inside
    /// (−90°, 90°)) and consecutive `range_edges` (metres, strictly increasing, from ≥ 0; the
    /// last may be infinite). At least two edges each.
    pub fn new(azimuth_edges: Vec<f64>, range_edges: Vec<f64>) -> Result<SectorGrid> {
        let right = std::f64::consts::FRAC_PI_2;
        let increasing = |v: &[f64]| v.len() >= 2 && v.windows(2).all(|w| w[0] < w[1]);
        if !increasing(&azimuth_edges)
            || azimuth_edges.iter().any(|a| a.is_nan() || a.abs() >= right)
        {
            return Err(HoughError::BadParameter {
                what: "sector azimuth edges",
                value: azimuth_edges.first().copied().unwrap_or(f64::NAN),
                allowed: "≥ 2 strictly increasing angles in (−90°, 90°)",
            });
        }
        if !increasing(&range_edges) || range_edges[0].is_nan() || range_edges[0] < 0.0 {
            return Err(HoughError::BadParameter {
                what: "sector range edges",
                value: range_edges.first().copied().unwrap_or(f64::NAN),
                allowed: "≥ 2 strictly increasing distances from ≥ 0 m",
            });
        }
        let tan_edges = azimuth_edges.iter().map(|a| a.tan()).collect();
        Ok(SectorGrid { azimuth_edges, range_edges, tan_edges })
    }

    /// Three sectors, left, centre, right, splitting `[−half_width, half_width]` (radians)
    /// into thirds, at any range.
    pub fn left_centre_right(half_width: f64) -> Result<SectorGrid> {
        let h = half_width;
        SectorGrid::new(vec![-h, -h / 3.0, h / 3.0, h], vec![0.0, f64::INFINITY])
    }

    /// Number of sectors.
    pub fn len(&self) -> usize {
        (self.azimuth_edges.len() - 1) * (self.range_edges.len() - 1)
    }

    /// Always false (a grid has at least one sector).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Number of azimuth sectors.
    pub fn n_azimuth(&self) -> usize {
        self.azimuth_edges.len() - 1
    }

    /// The azimuth interval (radians) and range interval (metres) of sector `index`.
    pub fn bounds(&self, index: usize) -> ((f64, f64), (f64, f64)) {
        let (ia, ir) = (index % self.n_azimuth(), index / self.n_azimuth());
        (
            (self.azimuth_edges[ia], self.azimuth_edges[ia + 1]),
            (self.range_edges[ir], self.range_edges[ir + 1]),
        )
    }

    /// The sector of a levelled point, if any (half-open intervals).
    pub fn sector_of(&self, p: &Point3<f64>) -> Option<usize> {
        if p.x <= 0.0 {
            return None; // edges are inside (−90°, 90°): only points ahead
        }
        // azimuth ≥ edge ⇔ y ≥ tan(edge) · x for x > 0.
        let ia = self.tan_edges.iter().take_while(|&&t| p.y >= t * p.x).count();
        if ia == 0 || ia == self.tan_edges.len() {
            return None;
        }
        let r = p.x.hypot(p.y);
        let ir = self.range_edges.iter().take_while(|&&e| r >= e).count();
        if ir == 0 || ir == self.range_edges.len() {
            return None;
        }
        Some((ir - 1) * self.n_azimuth() + ia - 1)
    }
}

/// One sector's result.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sector {
    /// Azimuth interval, radians (negative = left).
    pub azimuth: (f64, f64),
    /// Horizontal range interval, metres.
    pub range: (f64, f64),
    /// Algorithm 3 on this sector's points.
    pub classification: Classification,
}

/// Algorithm 2 + 3 per sector of a [`SectorGrid`]; buffers are reused across frames.
#[derive(Clone, Debug)]
pub struct SectorClassifier {
    config: HoughConfig,
    grid: SectorGrid,
    table: NormalTable,
    floor: Bin,
    accs: Vec<Accumulator>,
    buckets: Vec<Vec<Point3<f64>>>,
}

impl SectorClassifier {
    /// Prepares one accumulator per sector. Same checks as [`crate::HoughClassifier::new`].
    pub fn new(config: HoughConfig, grid: SectorGrid) -> Result<SectorClassifier> {
        config.classifier.validate()?;
        let floor = floor_bin(&config.space, config.mount.height())?;
        Ok(SectorClassifier {
            table: NormalTable::new(&config.space),
            accs: vec![Accumulator::new(config.space); grid.len()],
            buckets: vec![Vec::new(); grid.len()],
            floor,
            grid,
            config,
        })
    }

    /// The grid.
    pub fn grid(&self) -> &SectorGrid {
        &self.grid
    }

    /// The last frame's accumulators, one per sector.
    pub fn accumulators(&self) -> &[Accumulator] {
        &self.accs
    }

    /// Classifies every sector of a frame of sensor-frame points (frame size `points.len()`,
    /// all-zero points are missing pixels). The frame-level preprocessing test applies to the
    /// whole frame; a sector additionally needs `min_points` points of its own. Fails on an
    /// empty slice or a non-finite point.
    pub fn classify(&mut self, points: &[Point3<f64>]) -> Result<Vec<Sector>> {
        if points.is_empty() {
            return Err(HoughError::EmptyCloud);
        }
        for b in &mut self.buckets {
            b.clear();
        }
        let mount = &self.config.mount;
        let mut valid = 0;
        for (index, p) in points.iter().enumerate() {
            if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
                return Err(HoughError::NonFinitePoint { index });
            }
            if p.x == 0.0 && p.y == 0.0 && p.z == 0.0 {
                continue;
            }
            valid += 1;
            let q = mount.to_levelled(p);
            if let Some(s) = self.grid.sector_of(&q) {
                self.buckets[s].push(q);
            }
        }
        let pre = &self.config.classifier.preprocessing;
        let frame_ok = pre.accepts(valid, points.len());
        let fraction = valid as f64 / points.len() as f64;
        let mut out = Vec::with_capacity(self.grid.len());
        for (s, (acc, bucket)) in self.accs.iter_mut().zip(&self.buckets).enumerate() {
            acc.clear();
            let (azimuth, range) = self.grid.bounds(s);
            let classification = if frame_ok && bucket.len() >= pre.min_points.max(1) {
                self.table.vote(bucket, acc)?;
                let mut c = algorithm3(acc, self.floor, &self.config.classifier)?;
                c.valid_fraction = fraction;
                c
            } else {
                rejected(bucket.len(), fraction)
            };
            out.push(Sector { azimuth, range, classification });
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sectors_are_found_left_to_right_near_to_far() {
        let g = SectorGrid::new(vec![-0.6, -0.2, 0.2, 0.6], vec![0.0, 2.0, 5.0]).unwrap();
        assert_eq!(g.len(), 6);
        // y right: a point to the left has y < 0.
        assert_eq!(g.sector_of(&Point3::new(1.0, -0.5, 0.4)), Some(0));
        assert_eq!(g.sector_of(&Point3::new(1.0, 0.0, 0.4)), Some(1));
        assert_eq!(g.sector_of(&Point3::new(1.0, 0.5, 0.4)), Some(2));
        assert_eq!(g.sector_of(&Point3::new(3.0, 0.0, 0.4)), Some(4));
        assert_eq!(g.sector_of(&Point3::new(6.0, 0.0, 0.4)), None);
        assert_eq!(g.sector_of(&Point3::new(1.0, 5.0, 0.4)), None);
        assert_eq!(g.sector_of(&Point3::new(-1.0, 0.0, 0.4)), None);
        assert_eq!(g.bounds(4), ((-0.2, 0.2), (2.0, 5.0)));
        assert!(SectorGrid::new(vec![0.3, 0.1], vec![0.0, 1.0]).is_err());
        assert!(SectorGrid::new(vec![-2.0, 0.1], vec![0.0, 1.0]).is_err());
        assert!(SectorGrid::new(vec![-0.2, 0.1], vec![-1.0, 1.0]).is_err());
        assert!(SectorGrid::new(vec![-0.2, 0.1], vec![1.0]).is_err());
    }
}
