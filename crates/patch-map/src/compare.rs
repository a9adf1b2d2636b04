//! Is a map safe? A test map compared with a truth map over capsule steps.
//!
//! A robot trusts a map to call a colliding step colliding. This module asks both maps the
//! same question — is this capsule step free? — and counts the four outcomes:
//!
//! | truth \ test | free | colliding |
//! |---|---|---|
//! | **free** | agree | *overcautious* (the map blocks free space) |
//! | **colliding** | *unsafe* (the map lets a collision through) | agree |
//!
//! The **unsafe rate** is unsafe steps over the steps that truly collide (the miss rate); the
//! **overcautious rate** is overcautious steps over the steps that are truly free (the false
//! alarm rate). Each comes with a 95 % Wilson score interval ([`Rate`]).
//!
//! Steps are either drawn at random in a box ([`StepSampling`], [`random_steps`]) — the robot's
//! bounding sphere (thesis §6.1) swept along a segment of random direction and length — or given,
//! for example every edge of a roadmap ([`compare_on_steps`]). With [`Attribution::FirstContact`]
//! every unsafe step is traced to the truth patch it touches first, so misses can be tied to
//! surfaces ([`MapComparison::unsafe_by_patch`]).
//!
//! Any backend works on either side, a point-cloud map included; the truth needs patches only
//! for attribution.

use patch_core::{
    Aabb, CapsuleStep, MaybePatchMap, PatchId, PatchMapVisitor, Point3, ProximityQuery, Real,
    SpecificStepIntersector, UnspecificStepIntersector, Vector3,
};
use rand::{Rng as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;
use std::collections::BTreeMap;

/// z of the 95 % two-sided normal quantile.
const Z95: Real = 1.959_963_984_540_054;

/// Most attempts to draw one step whose end stays in the box before the end is clamped.
const MAX_DRAWS: usize = 64;

/// Most steps one comparison draws (a guard against absurd sample counts).
pub const MAX_SAMPLES: usize = 100_000_000;

/// Why a comparison could not be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CompareError {
    /// The robot radius is not a finite number ≥ 0.
    #[error("the step radius must be a finite number of metres ≥ 0, got {0}")]
    BadRadius(Real),
    /// The longest step is not a finite number ≥ 0.
    #[error("the longest step must be a finite number of metres ≥ 0, got {0}")]
    BadLength(Real),
    /// No steps, or more than [`MAX_SAMPLES`].
    #[error("the number of sampled steps must be in 1..={MAX_SAMPLES}, got {0}")]
    BadSamples(usize),
    /// The box is empty, not finite, or has min > max on some axis.
    #[error("the sampling box must be finite with min ≤ max on every axis, got {min:?} … {max:?}")]
    BadBox {
        /// The box's lower corner.
        min: [Real; 3],
        /// The box's upper corner.
        max: [Real; 3],
    },
}

/// How random steps are drawn: start uniform in `bounds`, direction uniform on the sphere,
/// length uniform in `[0, max_length]`; a step whose end leaves the box is drawn again (after
/// 64 tries its end is clamped into the box).
#[derive(Copy, Clone, Debug, PartialEq, Serialize)]
pub struct StepSampling {
    /// The robot's bounding-sphere radius, metres (default 0.3).
    pub radius: Real,
    /// The longest step, metres (default 1).
    pub max_length: Real,
    /// How many steps (default 100,000).
    pub samples: usize,
    /// Seed of the step stream.
    pub seed: u64,
    /// Where steps start and end.
    pub bounds: Aabb,
}

impl StepSampling {
    /// The defaults in `bounds`: radius 0.3 m, steps up to 1 m, 100,000 samples, seed 0.
    pub fn in_box(bounds: Aabb) -> StepSampling {
        StepSampling { radius: 0.3, max_length: 1.0, samples: 100_000, seed: 0, bounds }
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`CompareError`] naming the bad field.
    pub fn validate(&self) -> Result<(), CompareError> {
        if !(self.radius.is_finite() && self.radius >= 0.0) {
            return Err(CompareError::BadRadius(self.radius));
        }
        if !(self.max_length.is_finite() && self.max_length >= 0.0) {
            return Err(CompareError::BadLength(self.max_length));
        }
        if self.samples == 0 || self.samples > MAX_SAMPLES {
            return Err(CompareError::BadSamples(self.samples));
        }
        let (lo, hi) = (self.bounds.min, self.bounds.max);
        if !(lo.iter().chain(hi.iter()).all(|c| c.is_finite()) && (0..3).all(|i| lo[i] <= hi[i])) {
            return Err(CompareError::BadBox { min: [lo.x, lo.y, lo.z], max: [hi.x, hi.y, hi.z] });
        }
        Ok(())
    }
}

/// The steps of `sampling`, deterministic for its seed.
///
/// # Errors
/// As [`StepSampling::validate`].
pub fn random_steps(sampling: &StepSampling) -> Result<Vec<CapsuleStep>, CompareError> {
    sampling.validate()?;
    let b = sampling.bounds;
    let mut rng = ChaCha8Rng::seed_from_u64(sampling.seed);
    let uniform = |lo: Real, hi: Real, rng: &mut ChaCha8Rng| {
        if hi > lo { rng.random_range(lo..=hi) } else { lo }
    };
    let mut out = Vec::with_capacity(sampling.samples);
    for _ in 0..sampling.samples {
        let start = Point3::new(
            uniform(b.min.x, b.max.x, &mut rng),
            uniform(b.min.y, b.max.y, &mut rng),
            uniform(b.min.z, b.max.z, &mut rng),
        );
        let mut end = start;
        for attempt in 0..MAX_DRAWS {
            // Uniform direction: z uniform in [-1, 1], azimuth uniform.
            let z: Real = rng.random_range(-1.0..=1.0);
            let phi: Real = rng.random_range(0.0..std::f64::consts::TAU);
            let s = (1.0 - z * z).max(0.0).sqrt();
            let dir = Vector3::new(s * phi.cos(), s * phi.sin(), z);
            let len = rng.random_range(0.0..=1.0) * sampling.max_length;
            end = start + dir * len;
            if b.contains(&end) {
                break;
            }
            if attempt + 1 == MAX_DRAWS {
                end = end.sup(&b.min).inf(&b.max);
            }
        }
        // Finite points and radius were checked: the constructor cannot fail.
        out.push(CapsuleStep::new(start, end, sampling.radius).expect("checked step"));
    }
    Ok(out)
}

/// A proportion with its 95 % Wilson score interval.
#[derive(Copy, Clone, Debug, PartialEq, Serialize)]
pub struct Rate {
    /// The cases counted.
    pub count: u64,
    /// Out of this many.
    pub total: u64,
    /// `count / total` (0 when `total` is 0).
    pub value: Real,
    /// Lower end of the 95 % interval.
    pub low: Real,
    /// Upper end of the 95 % interval.
    pub high: Real,
}

impl Rate {
    /// `count` out of `total` with its Wilson interval; with `total = 0` the rate is 0 and the
    /// interval the whole of [0, 1].
    pub fn wilson(count: u64, total: u64) -> Rate {
        if total == 0 {
            return Rate { count, total, value: 0.0, low: 0.0, high: 1.0 };
        }
        let n = total as Real;
        let p = count.min(total) as Real / n;
        let z2 = Z95 * Z95;
        let denom = 1.0 + z2 / n;
        let centre = (p + z2 / (2.0 * n)) / denom;
        let half = Z95 / denom * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt();
        Rate {
            count,
            total,
            value: p,
            low: (centre - half).max(0.0),
            high: (centre + half).min(1.0),
        }
    }
}

impl std::fmt::Display for Rate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{:.2} % [{:.2}, {:.2}] ({} of {})",
            100.0 * self.value,
            100.0 * self.low,
            100.0 * self.high,
            self.count,
            self.total
        )
    }
}

/// Whether unsafe steps are traced to the truth patch they touch first.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Attribution {
    /// Count only.
    None,
    /// Also ask for the first contact of each step the maps disagree on: an unsafe step's
    /// on the truth, an overcautious step's on the test map (a map without patches, a
    /// point-cloud map, gives no contacts).
    FirstContact,
}

/// A step the two maps disagree on and where it first touches the map that calls it
/// colliding (the truth for an unsafe step, the test map for an overcautious one).
#[derive(Copy, Clone, Debug, PartialEq, Serialize)]
pub struct UnsafeStep {
    /// The step (index into the compared steps).
    pub index: usize,
    /// The patch touched first.
    pub patch: PatchId,
    /// The contact point on it.
    pub point: Point3,
}

/// The outcome of comparing a test map with a truth map.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct MapComparison {
    /// Steps free in both.
    pub both_free: u64,
    /// Steps colliding in both.
    pub both_colliding: u64,
    /// Steps that collide in the truth but the test map calls free.
    pub unsafe_steps: u64,
    /// Steps free in the truth that the test map calls colliding.
    pub overcautious_steps: u64,
    /// With [`Attribution::FirstContact`] and a truth with patches: every unsafe step's first
    /// contact with the truth, in step order.
    pub unsafe_contacts: Vec<UnsafeStep>,
    /// With [`Attribution::FirstContact`] and a test map with patches: every overcautious
    /// step's first contact with the test map (the patch that blocks free space), in step
    /// order.
    pub overcautious_contacts: Vec<UnsafeStep>,
}

impl MapComparison {
    /// All steps compared.
    pub fn steps(&self) -> u64 {
        self.both_free + self.both_colliding + self.unsafe_steps + self.overcautious_steps
    }

    /// Steps that collide in the truth.
    pub fn truly_colliding(&self) -> u64 {
        self.both_colliding + self.unsafe_steps
    }

    /// Steps that are free in the truth.
    pub fn truly_free(&self) -> u64 {
        self.both_free + self.overcautious_steps
    }

    /// Unsafe steps over truly colliding steps, with its 95 % interval.
    pub fn unsafe_rate(&self) -> Rate {
        Rate::wilson(self.unsafe_steps, self.truly_colliding())
    }

    /// Overcautious steps over truly free steps, with its 95 % interval.
    pub fn overcautious_rate(&self) -> Rate {
        Rate::wilson(self.overcautious_steps, self.truly_free())
    }

    /// Unsafe steps per truth patch touched first, most first (ties by patch id).
    pub fn unsafe_by_patch(&self) -> Vec<(PatchId, u64)> {
        by_patch(&self.unsafe_contacts)
    }

    /// Overcautious steps per test-map patch touched first, most first (ties by patch id).
    pub fn overcautious_by_patch(&self) -> Vec<(PatchId, u64)> {
        by_patch(&self.overcautious_contacts)
    }

    fn add(&mut self, other: MapComparison) {
        self.both_free += other.both_free;
        self.both_colliding += other.both_colliding;
        self.unsafe_steps += other.unsafe_steps;
        self.overcautious_steps += other.overcautious_steps;
        self.unsafe_contacts.extend(other.unsafe_contacts);
        self.overcautious_contacts.extend(other.overcautious_contacts);
    }
}

/// Steps per patch, most first (ties by patch id).
fn by_patch(contacts: &[UnsafeStep]) -> Vec<(PatchId, u64)> {
    let mut counts: BTreeMap<PatchId, u64> = BTreeMap::new();
    for c in contacts {
        *counts.entry(c.patch).or_default() += 1;
    }
    let mut v: Vec<_> = counts.into_iter().collect();
    v.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    v
}

/// Asks a patch map for a step's first contact (through [`MaybePatchMap`]).
struct FirstContact<'s>(&'s CapsuleStep);

impl<'m> PatchMapVisitor<'m> for FirstContact<'_> {
    type Output = Option<(PatchId, Point3)>;
    fn visit<M>(self, map: &'m M) -> Self::Output
    where
        M: ProximityQuery + SpecificStepIntersector,
    {
        map.first_hit(self.0).map(|h| (h.patch, h.point))
    }
}

/// Compares `test` with `truth` on `steps` (for example a roadmap's edges). Runs on all cores;
/// the result does not depend on their number.
pub fn compare_on_steps<T, M>(
    truth: &T,
    test: &M,
    steps: &[CapsuleStep],
    attribution: Attribution,
) -> MapComparison
where
    T: UnspecificStepIntersector + MaybePatchMap + Sync,
    M: UnspecificStepIntersector + MaybePatchMap + Sync,
{
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get()).clamp(1, 64);
    let chunk = steps.len().div_ceil(threads).max(1);
    let run = |offset: usize, part: &[CapsuleStep]| {
        let mut out = MapComparison::default();
        for (i, step) in part.iter().enumerate() {
            match (truth.is_step_free(step), test.is_step_free(step)) {
                (true, true) => out.both_free += 1,
                (false, false) => out.both_colliding += 1,
                (true, false) => {
                    out.overcautious_steps += 1;
                    if attribution == Attribution::FirstContact
                        && let Ok(Some((patch, point))) = test.with_patch_map(FirstContact(step))
                    {
                        out.overcautious_contacts.push(UnsafeStep {
                            index: offset + i,
                            patch,
                            point,
                        });
                    }
                }
                (false, true) => {
                    out.unsafe_steps += 1;
                    if attribution == Attribution::FirstContact
                        && let Ok(Some((patch, point))) = truth.with_patch_map(FirstContact(step))
                    {
                        out.unsafe_contacts.push(UnsafeStep { index: offset + i, patch, point });
                    }
                }
            }
        }
        out
    };
    if threads == 1 || steps.len() < 2 * chunk {
        return run(0, steps);
    }
    std::thread::scope(|scope| {
        let handles: Vec<_> = steps
            .chunks(chunk)
            .enumerate()
            .map(|(k, part)| {
                let run = &run;
                scope.spawn(move || run(k * chunk, part))
            })
            .collect();
        let mut total = MapComparison::default();
        for h in handles {
            // A panic in a worker is a bug in a backend: pass it on.
            total.add(h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)));
        }
        total
    })
}

/// Compares `test` with `truth` on the random steps of `sampling`.
///
/// # Errors
/// As [`StepSampling::validate`].
pub fn compare_maps<T, M>(
    truth: &T,
    test: &M,
    sampling: &StepSampling,
    attribution: Attribution,
) -> Result<MapComparison, CompareError>
where
    T: UnspecificStepIntersector + MaybePatchMap + Sync,
    M: UnspecificStepIntersector + MaybePatchMap + Sync,
{
    let steps = random_steps(sampling)?;
    Ok(compare_on_steps(truth, test, &steps, attribution))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{AnyMap, PolygonMap};
    use patch_core::{FromPatches, Isometry3, Patch, PlanarPatch, Point2};

    fn square(z: Real, half: Real) -> Patch {
        PlanarPatch::rectangle(
            Isometry3::translation(0.0, 0.0, z),
            Point2::new(-half, -half),
            Point2::new(half, half),
        )
        .unwrap()
        .into()
    }

    #[test]
    fn wilson_matches_hand_values() {
        // 10 of 100: the textbook interval [0.0552, 0.1744].
        let r = Rate::wilson(10, 100);
        assert!((r.value - 0.1).abs() < 1e-12);
        assert!((r.low - 0.0552).abs() < 1e-4 && (r.high - 0.1744).abs() < 1e-4, "{r:?}");
        let zero = Rate::wilson(0, 50);
        assert_eq!(zero.low, 0.0);
        assert!(zero.high > 0.0 && zero.high < 0.08);
        let none = Rate::wilson(0, 0);
        assert_eq!((none.value, none.low, none.high), (0.0, 0.0, 1.0));
    }

    #[test]
    fn steps_stay_in_the_box_and_repeat_for_a_seed() {
        let b = Aabb::new(Point3::new(0.0, 0.0, 0.0), Point3::new(2.0, 1.0, 0.5));
        let s = StepSampling { samples: 2_000, seed: 3, ..StepSampling::in_box(b) };
        let steps = random_steps(&s).unwrap();
        assert_eq!(steps.len(), 2_000);
        for st in &steps {
            use patch_core::Step as _;
            assert!(b.contains(&st.start()) && b.contains(&st.end()));
            assert!(st.length() <= 1.0 + 1e-12);
            assert_eq!(st.radius(), 0.3);
        }
        assert_eq!(steps, random_steps(&s).unwrap());
        assert_ne!(steps, random_steps(&StepSampling { seed: 4, ..s }).unwrap());
        // A flat box still works (steps lie in it).
        let flat = Aabb::new(Point3::new(0.0, 0.0, 0.3), Point3::new(2.0, 1.0, 0.3));
        assert_eq!(
            random_steps(&StepSampling { samples: 10, bounds: flat, ..s }).unwrap().len(),
            10
        );
    }

    #[test]
    fn bad_sampling_is_refused() {
        let b = Aabb::new(Point3::origin(), Point3::new(1.0, 1.0, 1.0));
        let ok = StepSampling::in_box(b);
        for bad in [
            StepSampling { radius: -1.0, ..ok },
            StepSampling { radius: Real::NAN, ..ok },
            StepSampling { max_length: Real::INFINITY, ..ok },
            StepSampling { samples: 0, ..ok },
            StepSampling { bounds: Aabb::EMPTY, ..ok },
        ] {
            assert!(random_steps(&bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn a_map_missing_a_patch_is_unsafe_there_and_traced_to_it() {
        let truth = AnyMap::Polygon(
            PolygonMap::from_patches([square(0.0, 2.0), square(1.0, 0.5)]).unwrap(),
        );
        // The test map lacks the small upper square.
        let test = AnyMap::Polygon(PolygonMap::from_patches([square(0.0, 2.0)]).unwrap());
        let b = Aabb::new(Point3::new(-2.0, -2.0, 0.0), Point3::new(2.0, 2.0, 2.0));
        let s = StepSampling { samples: 20_000, seed: 1, ..StepSampling::in_box(b) };
        let c = compare_maps(&truth, &test, &s, Attribution::FirstContact).unwrap();
        assert_eq!(c.steps(), 20_000);
        assert_eq!(c.overcautious_steps, 0, "a subset of the truth never blocks free space");
        assert!(c.unsafe_steps > 0);
        assert_eq!(c.unsafe_contacts.len() as u64, c.unsafe_steps);
        assert_eq!(c.unsafe_by_patch(), vec![(PatchId(1), c.unsafe_steps)]);
        for u in &c.unsafe_contacts {
            assert!((u.point.z - 1.0).abs() < 1e-12);
        }
        // The same map is never unsafe nor overcautious; the answers do not depend on threads.
        let same = compare_maps(&truth, &truth, &s, Attribution::None).unwrap();
        assert_eq!((same.unsafe_steps, same.overcautious_steps), (0, 0));
        assert_eq!(same.truly_colliding(), c.truly_colliding());
        let steps = random_steps(&s).unwrap();
        let one = compare_on_steps(&truth, &test, &steps[..1], Attribution::FirstContact);
        assert_eq!(one.steps(), 1);
        let r = c.unsafe_rate();
        assert!(r.low <= r.value && r.value <= r.high);
    }
}
