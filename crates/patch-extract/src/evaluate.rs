//! Segmentation quality by the SegComp protocol of Hoover et al. 1996 ("An Experimental
//! Comparison of Range Image Segmentation Algorithms", IEEE PAMI 18(7)), plus the plane-angle
//! error of correctly detected regions.
//!
//! # Protocol
//! Ground truth is one label per point (scene-sim's `SimulatedScan::to_cloud` labels each
//! point with the surface its beam hit). With `Pₘ` the size of ground-truth region `m`, `Pₙ`
//! the size of machine region `n` and `Oₘₙ` their overlap, at tolerance `T` (0.5 < T ≤ 1):
//!
//! * **correct detection** of `m` by `n`: `Oₘₙ ≥ T Pₘ` and `Oₘₙ ≥ T Pₙ`;
//! * **over-segmentation** of `m` into `n₁ … n_x` (x ≥ 2): every `Oₘₙᵢ ≥ T Pₙᵢ` and
//!   `Σᵢ Oₘₙᵢ ≥ T Pₘ`;
//! * **under-segmentation** of `m₁ … m_x` (x ≥ 2) into `n`: every `Oₘᵢₙ ≥ T Pₘᵢ` and
//!   `Σᵢ Oₘᵢₙ ≥ T Pₙ`;
//! * **missed**: a ground-truth region in none of the above; **noise**: a machine region in
//!   none of the above.
//!
//! Classification is in that order (correct first; a region already classified takes no
//! further part), as in Hoover's tool. For `T > 0.5` each instance is unique.
//!
//! # What counts
//! * Points whose label is [`SegCompConfig::unlabelled`] (scene-sim's "no surface",
//!   `u32::MAX`) are ignored everywhere: they count in no `P` and no `O`.
//! * Ground-truth regions with fewer than [`SegCompConfig::min_truth_size`] points are
//!   *ignored*: never missed, never part of an instance. Their points still count in the
//!   sizes `Pₙ` of the machine regions containing them (a machine region that is mostly an
//!   ignored surface is noise).
//! * Points in the remainder belong to no machine region; they still count in `Pₘ`.
//!
//! # Angle error
//! For each correct detection, if the caller's `true_plane(label)` knows the surface's plane
//! (in the cloud's frame), the angle between the region's normal and the true normal,
//! `acos |n · n_true|` in degrees (orientation ignored).

use crate::region::{PlanarRegion, Segmentation};
use patch_core::{Plane, Point3, Real};
use std::collections::HashMap;
use std::fmt;

/// Parameters of [`segcomp`]. No `Default`: use [`SegCompConfig::hoover`].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct SegCompConfig {
    /// The overlap tolerance `T`, in (0.5, 1].
    pub tolerance: Real,
    /// Ground-truth regions with fewer points are ignored.
    pub min_truth_size: usize,
    /// The label of points without ground truth.
    pub unlabelled: u32,
}

impl SegCompConfig {
    /// Hoover's default tolerance `T = 0.8`, unlabelled = `u32::MAX`, ground-truth regions
    /// below `min_truth_size` points ignored.
    pub fn hoover(min_truth_size: usize) -> SegCompConfig {
        SegCompConfig { tolerance: 0.8, min_truth_size, unlabelled: u32::MAX }
    }
}

/// Why [`segcomp`] refused its input.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EvaluateError {
    /// The tolerance is not in (0.5, 1].
    #[error("SegComp tolerance {0} must be in (0.5, 1]")]
    Tolerance(Real),
    /// A region or remainder names a point beyond the labels.
    #[error("segmentation names point {index}, but there are {num_labels} labels")]
    IndexOutOfRange {
        /// The point index.
        index: u32,
        /// The number of labels.
        num_labels: usize,
    },
    /// A point is in two regions.
    #[error("point {index} is in two machine regions")]
    Overlapping {
        /// The point index.
        index: u32,
    },
}

/// A ground-truth region detected by exactly one machine region.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct CorrectDetection {
    /// The ground-truth label.
    pub truth: u32,
    /// The index of the machine region in [`Segmentation::regions`].
    pub region: usize,
    /// The overlap in points.
    pub overlap: usize,
    /// The angle between the region's normal and the true one, degrees, if the true plane is
    /// known.
    pub angle_error_deg: Option<Real>,
}

/// One ground-truth region split into several machine regions.
#[derive(Clone, Debug, PartialEq)]
pub struct OverSegmentation {
    /// The ground-truth label.
    pub truth: u32,
    /// The machine regions, ascending.
    pub regions: Vec<usize>,
}

/// Several ground-truth regions merged into one machine region.
#[derive(Clone, Debug, PartialEq)]
pub struct UnderSegmentation {
    /// The machine region.
    pub region: usize,
    /// The ground-truth labels, ascending.
    pub truths: Vec<u32>,
}

/// The SegComp classification of one segmentation.
#[derive(Clone, Debug, PartialEq)]
pub struct SegCompReport {
    /// The tolerance used.
    pub tolerance: Real,
    /// Ground-truth regions considered (at least the minimum size).
    pub num_truth: usize,
    /// Machine regions.
    pub num_machine: usize,
    /// Correct detections, by ground-truth label.
    pub correct: Vec<CorrectDetection>,
    /// Over-segmentations, by ground-truth label.
    pub over: Vec<OverSegmentation>,
    /// Under-segmentations, by machine region.
    pub under: Vec<UnderSegmentation>,
    /// Missed ground-truth labels, ascending.
    pub missed: Vec<u32>,
    /// Noise machine regions, ascending.
    pub noise: Vec<usize>,
}

impl SegCompReport {
    /// The angle errors (degrees) of the correct detections whose true plane is known.
    pub fn angle_errors(&self) -> impl Iterator<Item = Real> + '_ {
        self.correct.iter().filter_map(|c| c.angle_error_deg)
    }

    /// Mean angle error of correct detections, degrees; `None` if none is known.
    pub fn mean_angle_error_deg(&self) -> Option<Real> {
        let (sum, n) = self.angle_errors().fold((0.0, 0usize), |(s, n), a| (s + a, n + 1));
        (n > 0).then(|| sum / n as Real)
    }

    /// Largest angle error of correct detections, degrees; `None` if none is known.
    pub fn max_angle_error_deg(&self) -> Option<Real> {
        self.angle_errors().reduce(Real::max)
    }

    /// Fraction of considered ground-truth regions detected correctly (1 if there are none).
    pub fn correct_ratio(&self) -> Real {
        if self.num_truth == 0 { 1.0 } else { self.correct.len() as Real / self.num_truth as Real }
    }
}

impl fmt::Display for SegCompReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "SegComp T={:.2}: {} GT, {} machine; correct {}, over {}, under {}, missed {}, noise {}",
            self.tolerance,
            self.num_truth,
            self.num_machine,
            self.correct.len(),
            self.over.len(),
            self.under.len(),
            self.missed.len(),
            self.noise.len()
        )?;
        if let (Some(mean), Some(max)) = (self.mean_angle_error_deg(), self.max_angle_error_deg()) {
            write!(f, "; angle error mean {mean:.3}°, max {max:.3}°")?;
        }
        Ok(())
    }
}

/// Classifies `segmentation` against per-point ground-truth `labels` (module docs).
/// `true_plane(label)` gives the true plane of a surface in the cloud's frame, if known, for
/// the angle errors of correct detections (pass `|_| None` to skip them).
///
/// # Errors
/// [`EvaluateError`] for a tolerance outside (0.5, 1], a point index beyond `labels`, or a
/// point in two regions.
///
/// # Complexity
/// O(N + K log K) for N labelled points and K non-zero overlaps.
pub fn segcomp(
    labels: &[u32],
    segmentation: &Segmentation,
    config: &SegCompConfig,
    true_plane: impl Fn(u32) -> Option<Plane>,
) -> Result<SegCompReport, EvaluateError> {
    let t = config.tolerance;
    if !(t > 0.5 && t <= 1.0) {
        return Err(EvaluateError::Tolerance(t));
    }
    let unlabelled = config.unlabelled;

    // Ground-truth sizes.
    let mut truth_size: HashMap<u32, usize> = HashMap::new();
    for &l in labels.iter().filter(|&&l| l != unlabelled) {
        *truth_size.entry(l).or_default() += 1;
    }
    let considered = |l: u32| truth_size.get(&l).is_some_and(|&s| s >= config.min_truth_size);

    // Machine sizes and overlaps.
    let mut seen = vec![false; labels.len()];
    let mut machine_size = vec![0usize; segmentation.regions.len()];
    let mut overlap: HashMap<(u32, usize), usize> = HashMap::new();
    for (n, region) in segmentation.regions.iter().enumerate() {
        for &i in &region.points {
            let label = *labels
                .get(i as usize)
                .ok_or(EvaluateError::IndexOutOfRange { index: i, num_labels: labels.len() })?;
            if std::mem::replace(&mut seen[i as usize], true) {
                return Err(EvaluateError::Overlapping { index: i });
            }
            if label == unlabelled {
                continue;
            }
            machine_size[n] += 1;
            if considered(label) {
                *overlap.entry((label, n)).or_default() += 1;
            }
        }
    }
    if let Some(&index) = segmentation.remainder.iter().find(|&&i| i as usize >= labels.len()) {
        return Err(EvaluateError::IndexOutOfRange { index, num_labels: labels.len() });
    }

    let mut truths: Vec<u32> = truth_size.keys().copied().filter(|&l| considered(l)).collect();
    truths.sort_unstable();
    let mut pairs: Vec<((u32, usize), usize)> = overlap.into_iter().collect();
    pairs.sort_unstable();
    let by_truth = |m: u32| {
        let start = pairs.partition_point(|((l, _), _)| *l < m);
        pairs[start..].iter().take_while(move |((l, _), _)| *l == m).map(|&((_, n), o)| (n, o))
    };
    let mut by_machine: Vec<Vec<(u32, usize)>> = vec![Vec::new(); machine_size.len()];
    for &((l, n), o) in &pairs {
        by_machine[n].push((l, o));
    }
    let at_least = |o: usize, size: usize| o as Real >= t * size as Real;

    let mut truth_done: HashMap<u32, bool> = truths.iter().map(|&l| (l, false)).collect();
    let mut machine_done = vec![false; machine_size.len()];

    // Correct detections.
    let mut correct = Vec::new();
    for &m in &truths {
        let pm = truth_size[&m];
        if let Some((n, o)) =
            by_truth(m).find(|&(n, o)| at_least(o, pm) && at_least(o, machine_size[n]))
        {
            let angle_error_deg = true_plane(m).map(|p| {
                let c = segmentation.regions[n].plane.normal.dot(&p.normal).abs().min(1.0);
                c.acos().to_degrees()
            });
            correct.push(CorrectDetection { truth: m, region: n, overlap: o, angle_error_deg });
            truth_done.insert(m, true);
            machine_done[n] = true;
        }
    }

    // Over-segmentations.
    let mut over = Vec::new();
    for &m in &truths {
        if truth_done[&m] {
            continue;
        }
        let parts: Vec<(usize, usize)> = by_truth(m)
            .filter(|&(n, o)| !machine_done[n] && at_least(o, machine_size[n]))
            .collect();
        let total: usize = parts.iter().map(|&(_, o)| o).sum();
        if parts.len() >= 2 && at_least(total, truth_size[&m]) {
            let regions: Vec<usize> = parts.iter().map(|&(n, _)| n).collect();
            for &n in &regions {
                machine_done[n] = true;
            }
            truth_done.insert(m, true);
            over.push(OverSegmentation { truth: m, regions });
        }
    }

    // Under-segmentations.
    let mut under = Vec::new();
    for (n, list) in by_machine.iter().enumerate() {
        if machine_done[n] {
            continue;
        }
        let parts: Vec<(u32, usize)> = list
            .iter()
            .copied()
            .filter(|&(m, o)| !truth_done[&m] && at_least(o, truth_size[&m]))
            .collect();
        let total: usize = parts.iter().map(|&(_, o)| o).sum();
        if parts.len() >= 2 && at_least(total, machine_size[n]) {
            let truths: Vec<u32> = parts.iter().map(|&(m, _)| m).collect();
            for &m in &truths {
                truth_done.insert(m, true);
            }
            machine_done[n] = true;
            under.push(UnderSegmentation { region: n, truths });
        }
    }

    let missed = truths.iter().copied().filter(|m| !truth_done[m]).collect();
    let noise = (0..machine_size.len()).filter(|&n| !machine_done[n]).collect();
    Ok(SegCompReport {
        tolerance: t,
        num_truth: truths.len(),
        num_machine: machine_size.len(),
        correct,
        over,
        under,
        missed,
        noise,
    })
}

/// The ground-truth segmentation of a labelled cloud: one region per label with at least
/// `min_size` points (label `unlabelled` excluded), each with its least-squares plane seen from
/// the sensor at the origin ([`PlanarRegion::fit`]); regions ordered by label. Labels of
/// simulated scans are the surfaces their beams hit, so this is the segmentation SegComp
/// compares against; it is also the input of the outlining survey's "truth" regions.
pub fn truth_regions(
    labels: &[u32],
    positions: &[Point3],
    min_size: usize,
    unlabelled: u32,
) -> Vec<PlanarRegion> {
    let mut by_label: std::collections::BTreeMap<u32, Vec<u32>> = Default::default();
    for (i, &l) in labels.iter().enumerate() {
        if l != unlabelled {
            by_label.entry(l).or_default().push(i as u32);
        }
    }
    by_label
        .into_values()
        .filter(|points| points.len() >= min_size.max(3))
        .filter_map(|points| PlanarRegion::fit(positions, points, &Point3::origin()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::region::PlanarRegion;
    use patch_core::{Point3, UnitVector3, Vector3};

    fn region(points: Vec<u32>, normal: Vector3) -> PlanarRegion {
        PlanarRegion {
            points,
            plane: Plane { normal: UnitVector3::new_normalize(normal), offset: 0.0 },
            centroid: Point3::origin(),
            mse: 0.0,
            covariance: None,
        }
    }

    fn seg(regions: Vec<Vec<u32>>) -> Segmentation {
        Segmentation {
            regions: regions.into_iter().map(|p| region(p, Vector3::z())).collect(),
            remainder: Vec::new(),
        }
    }

    fn range(a: u32, b: u32) -> Vec<u32> {
        (a..b).collect()
    }

    #[test]
    fn each_category_is_found() {
        // GT: A = 0..100, B = 100..200, C = 200..300, D = 300..400, E = 400..500, tiny F.
        let mut labels: Vec<u32> = (0..500).map(|i| i / 100).collect();
        labels.extend([9, 9, 9]); // F: 3 points, ignored
        labels.extend([u32::MAX; 5]); // unlabelled
        let s = seg(vec![
            range(0, 95),                                                     // correct A
            range(100, 150),                                                  // over B (1)
            range(150, 195),                                                  // over B (2)
            [range(200, 300), range(300, 400)].concat(),                      // under C+D
            range(400, 450), // half of E: E missed, noise
            [range(450, 460), vec![500, 501, 502], range(503, 508)].concat(), // noise
        ]);
        let r = segcomp(&labels, &s, &SegCompConfig::hoover(10), |_| None).unwrap();
        assert_eq!(r.num_truth, 5);
        assert_eq!(r.num_machine, 6);
        assert_eq!(r.correct.len(), 1);
        assert_eq!((r.correct[0].truth, r.correct[0].region), (0, 0));
        assert_eq!(r.over, vec![OverSegmentation { truth: 1, regions: vec![1, 2] }]);
        assert_eq!(r.under, vec![UnderSegmentation { region: 3, truths: vec![2, 3] }]);
        assert_eq!(r.missed, vec![4]);
        // Region 4 is all E but covers only half of it; region 5 is 10 E + 3 tiny-F points.
        assert_eq!(r.noise, vec![4, 5]);
        let text = r.to_string();
        assert!(text.contains("correct 1, over 1, under 1, missed 1, noise 2"), "{text}");
    }

    #[test]
    fn tolerance_decides() {
        let labels: Vec<u32> = (0..100).map(|i| i / 50).collect();
        // Region 0 holds 42 of GT 0 and 8 of GT 1: 84 % / 84 %.
        let s = seg(vec![[range(0, 42), range(50, 58)].concat(), range(58, 100)]);
        let loose = segcomp(&labels, &s, &SegCompConfig::hoover(1), |_| None).unwrap();
        assert_eq!(loose.correct.len(), 2);
        let strict = SegCompConfig { tolerance: 0.9, ..SegCompConfig::hoover(1) };
        let strict = segcomp(&labels, &s, &strict, |_| None).unwrap();
        assert_eq!(strict.correct.len(), 0);
        assert_eq!(strict.missed, vec![0, 1]);
        assert_eq!(strict.noise, vec![0, 1]);
    }

    #[test]
    fn angle_error_uses_true_planes_up_to_sign() {
        let labels: Vec<u32> = vec![7; 20];
        let mut s = seg(vec![range(0, 20)]);
        let tilt = 2f64.to_radians();
        s.regions[0].plane.normal =
            UnitVector3::new_normalize(Vector3::new(tilt.sin(), 0.0, -tilt.cos()));
        let truth = |l: u32| {
            (l == 7)
                .then(|| Plane { normal: UnitVector3::new_normalize(Vector3::z()), offset: 1.0 })
        };
        let r = segcomp(&labels, &s, &SegCompConfig::hoover(1), truth).unwrap();
        assert!((r.mean_angle_error_deg().unwrap() - 2.0).abs() < 1e-9);
        assert!((r.max_angle_error_deg().unwrap() - 2.0).abs() < 1e-9);
        assert!(r.to_string().contains("angle error mean 2.000°"));
    }

    #[test]
    fn bad_inputs_are_errors() {
        let labels = vec![0u32; 10];
        let bad_t = SegCompConfig { tolerance: 0.5, ..SegCompConfig::hoover(1) };
        assert_eq!(
            segcomp(&labels, &seg(vec![]), &bad_t, |_| None),
            Err(EvaluateError::Tolerance(0.5))
        );
        let nan_t = SegCompConfig { tolerance: Real::NAN, ..SegCompConfig::hoover(1) };
        assert!(segcomp(&labels, &seg(vec![]), &nan_t, |_| None).is_err());
        assert!(matches!(
            segcomp(&labels, &seg(vec![vec![3, 10]]), &SegCompConfig::hoover(1), |_| None),
            Err(EvaluateError::IndexOutOfRange { index: 10, .. })
        ));
        assert!(matches!(
            segcomp(&labels, &seg(vec![vec![1, 2], vec![2]]), &SegCompConfig::hoover(1), |_| None),
            Err(EvaluateError::Overlapping { index: 2 })
        ));
    }

    #[test]
    fn empty_inputs_give_empty_reports() {
        let r =
            segcomp(&[], &Segmentation::default(), &SegCompConfig::hoover(1), |_| None).unwrap();
        assert_eq!((r.num_truth, r.num_machine), (0, 0));
        assert_eq!(r.correct_ratio(), 1.0);
        assert_eq!(r.mean_angle_error_deg(), None);
        let labels = vec![1u32; 30];
        let r = segcomp(&labels, &Segmentation::default(), &SegCompConfig::hoover(10), |_| None)
            .unwrap();
        assert_eq!(r.missed, vec![1]);
    }
}
