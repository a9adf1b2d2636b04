//! One check per capability: a backend's answer against the reference, under the backend's
//! [`Tolerance`] (the statements in [`capability`](crate::capability)), plus cross-checks
//! of one capability's answer against another's. Each returns a
//! [`TestCaseError`] describing the disagreement, for
//! use inside `proptest!` or [`TestRunner::run`](proptest::test_runner::TestRunner::run).
//!
//! The reference distances come from [`BruteForceMap`]; the reference is itself checked
//! against sampling oracles in this crate's tests.

use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

use crate::{
    BruteForceMap, CapsuleStep, Patch, PatchMap, Point3, ProximityQuery, Real,
    SpecificStepIntersector, Step, Tolerance, UnspecificStepIntersector,
};

/// How far a unit normal may be from length 1.
const UNIT_SLACK: Real = 1e-9;

fn reference_distance<S: Step>(reference: &BruteForceMap, step: &S) -> Real {
    reference.step_distance(step).map_or(Real::INFINITY, |d| d.distance)
}

/// The band `(r − ε, r + δ + ε]` in which the answers of a backend may legitimately differ
/// from the exact ones.
fn band(r: Real, tolerance: Tolerance) -> (Real, Real) {
    (r - tolerance.numeric, r + tolerance.conservative + tolerance.numeric)
}

/// Checks that `map` holds exactly `patches`, in order, with consistent defaults and bounds
/// (the map's bounds must contain every patch's and exceed their union by at most the
/// tolerance), and the map declares ([`PatchMap::tolerance`]) the tolerance it is checked with.
pub fn check_map<M: PatchMap + ?Sized>(
    map: &M,
    patches: &[Patch],
    tolerance: Tolerance,
) -> Result<(), TestCaseError> {
    prop_assert_eq!(
        map.tolerance(),
        tolerance,
        "the map declares another tolerance than the suite checks"
    );
    prop_assert_eq!(map.len(), patches.len(), "number of patches");
    prop_assert_eq!(map.is_empty(), patches.is_empty());
    prop_assert!(
        map.patches() == patches,
        "the patches differ from the input, or their order does"
    );
    for (i, p) in patches.iter().enumerate() {
        prop_assert!(map.patch(crate::PatchId(i as u32)) == Some(p), "patch({}) differs", i);
    }
    prop_assert!(map.patch(crate::PatchId(patches.len() as u32)).is_none(), "patch(len) exists");
    let union = patches.iter().fold(crate::Aabb::EMPTY, |b, p| b.union(&p.bounds()));
    let bounds = map.bounds();
    if union.is_empty() {
        prop_assert!(bounds.is_empty(), "an empty map has bounds {:?}", bounds);
    } else {
        let slack = tolerance.numeric + tolerance.conservative;
        for i in 0..3 {
            prop_assert!(
                bounds.min[i] <= union.min[i]
                    && union.min[i] - slack <= bounds.min[i]
                    && union.max[i] <= bounds.max[i]
                    && bounds.max[i] <= union.max[i] + slack,
                "bounds {:?} do not match the patches' {:?}",
                bounds,
                union
            );
        }
    }
    Ok(())
}

/// Checks one answer of [`UnspecificStepIntersector::is_step_free`]: a step reported free
/// must be farther than `r − ε` from every patch; a step reported colliding must come within
/// `r + δ + ε`.
pub fn check_unspecific<M, S>(
    map: &M,
    reference: &BruteForceMap,
    step: &S,
    tolerance: Tolerance,
) -> Result<(), TestCaseError>
where
    M: UnspecificStepIntersector<S> + ?Sized,
    S: Step,
{
    let free = map.is_step_free(step);
    let d = reference_distance(reference, step);
    let (lo, hi) = band(step.radius(), tolerance);
    if free {
        prop_assert!(
            d > lo,
            "a colliding step was reported free: distance {} ≤ radius {} ({:?})",
            d,
            step.radius(),
            step
        );
    } else {
        prop_assert!(
            d <= hi,
            "a free step was reported colliding: distance {} > radius {} + tolerance ({:?})",
            d,
            step.radius(),
            step
        );
    }
    Ok(())
}

/// Checks one answer of [`SpecificStepIntersector::first_hit`] and its consistency with
/// [`UnspecificStepIntersector::is_step_free`]:
///
/// * `first_hit` is `None` iff `is_step_free`, except inside the tolerance band;
/// * `None` only for steps farther than `r − ε`; a hit only for steps within `r + δ + ε`;
/// * a hit has `t ∈ [0, 1]`, names a patch of the map, has a unit normal which is the patch's
///   plane normal (planar patch) or a touched triangle's normal (trimesh), up to sign, facing
///   the sphere's centre at `t` (up to tolerance);
/// * its contact point lies on that patch, is (up to tolerance) the patch point closest to the
///   centre at `t`, and is within `r + δ + ε` of it;
/// * the step before `t` stays farther than `r − ε` from every patch (so `t` is the first
///   contact up to tolerance; compared through distances rather than against the reference
///   `t`, because near a grazing contact the first time is not a continuous function of the
///   geometry).
pub fn check_specific<M, S>(
    map: &M,
    reference: &BruteForceMap,
    step: &S,
    tolerance: Tolerance,
) -> Result<(), TestCaseError>
where
    M: SpecificStepIntersector<S> + ?Sized,
    S: Step,
{
    let hit = map.first_hit(step);
    let free = map.is_step_free(step);
    let d = reference_distance(reference, step);
    let r = step.radius();
    let (lo, hi) = band(r, tolerance);
    let slack = tolerance.numeric + tolerance.conservative;
    if hit.is_none() != free {
        prop_assert!(
            d > lo && d <= hi,
            "first_hit {:?} and is_step_free {} disagree at distance {} from radius {} ({:?})",
            hit,
            free,
            d,
            r,
            step
        );
    }
    let Some(hit) = hit else {
        prop_assert!(
            d > lo,
            "first_hit missed a colliding step: distance {} ≤ radius {} ({:?})",
            d,
            r,
            step
        );
        return Ok(());
    };
    prop_assert!(
        d <= hi,
        "first_hit {:?} on a free step: distance {} > radius {} + tolerance ({:?})",
        hit,
        d,
        r,
        step
    );
    prop_assert!((0.0..=1.0).contains(&hit.t), "t = {} outside [0, 1]", hit.t);
    let Some(patch) = reference.patch(hit.patch) else {
        return Err(TestCaseError::fail(format!(
            "first_hit names {} which does not exist",
            hit.patch
        )));
    };
    prop_assert!(
        map.patch(hit.patch) == Some(patch),
        "the map's {} differs from the reference's",
        hit.patch
    );
    prop_assert!(
        (hit.normal.norm() - 1.0).abs() <= UNIT_SLACK,
        "normal {:?} is not unit",
        hit.normal
    );
    let center = step.point_at(hit.t);
    let on_patch = patch.closest_point(&hit.point).distance;
    prop_assert!(
        on_patch <= slack,
        "contact point {} is {} from {}",
        hit.point,
        on_patch,
        hit.patch
    );
    let gap = (center - hit.point).norm();
    prop_assert!(
        gap <= hi,
        "contact point {} is {} from the centre at t = {}, radius {}",
        hit.point,
        gap,
        hit.t,
        r
    );
    let nearest = patch.closest_point(&center).distance;
    prop_assert!(
        gap <= nearest + slack,
        "contact point {} is not the closest ({} vs {})",
        hit.point,
        gap,
        nearest
    );
    prop_assert!(
        hit.normal.dot(&(center - hit.point)) >= -slack,
        "normal {:?} faces away from the centre {} at t = {}",
        hit.normal,
        center,
        hit.t
    );
    let normal_ok = match patch {
        Patch::Planar(p) => (hit.normal.dot(&p.normal()).abs() - 1.0).abs() <= 1e-9,
        Patch::Trimesh(m) => m.triangle_frames().any(|f| {
            (hit.normal.dot(&f.normal()).abs() - 1.0).abs() <= 1e-9
                && f.closest_point(&hit.point).distance <= slack
        }),
    };
    prop_assert!(
        normal_ok,
        "normal {:?} is not the surface normal of {} at {}",
        hit.normal,
        hit.patch,
        hit.point
    );
    if hit.t > 0.0 {
        let prefix = CapsuleStep::new(step.start(), center, r).expect("finite step");
        let before = reference_distance(reference, &prefix);
        prop_assert!(
            before > lo,
            "the step already collides before t = {}: distance {} ≤ radius {} ({:?})",
            hit.t,
            before,
            r,
            step
        );
    }
    Ok(())
}

/// Checks one answer of [`ProximityQuery::closest_patch`] and [`ProximityQuery::clearance`]:
/// the distance equals the reference distance (a conservative backend may underestimate it by
/// `δ`), the point lies on the named patch at that distance from the query, `None` only when
/// nothing is within `max_dist`, and the clearance is the capped distance.
pub fn check_proximity<M: ProximityQuery + ?Sized>(
    map: &M,
    reference: &BruteForceMap,
    point: &Point3,
    max_dist: Real,
    tolerance: Tolerance,
) -> Result<(), TestCaseError> {
    let exact =
        reference.closest_patch(point, Real::INFINITY).map_or(Real::INFINITY, |p| p.distance);
    let (eps, delta) = (tolerance.numeric, tolerance.conservative);
    match map.closest_patch(point, max_dist) {
        None => prop_assert!(
            exact.is_infinite() || exact > max_dist - eps,
            "closest_patch found nothing within {} of {}, but patches are {} away",
            max_dist,
            point,
            exact
        ),
        Some(p) => {
            prop_assert!(
                p.distance <= max_dist,
                "distance {} beyond max_dist {}",
                p.distance,
                max_dist
            );
            prop_assert!(
                p.distance >= exact - delta - eps && p.distance <= exact + eps,
                "closest_patch distance {} but the nearest patch is {} away (from {})",
                p.distance,
                exact,
                point
            );
            let Some(patch) = reference.patch(p.patch) else {
                return Err(TestCaseError::fail(format!(
                    "closest_patch names {} which does not exist",
                    p.patch
                )));
            };
            let on = patch.closest_point(&p.point).distance;
            prop_assert!(on <= eps + delta, "closest point {} is {} from {}", p.point, on, p.patch);
            let reach = (p.point - point).norm();
            prop_assert!(
                (reach - p.distance).abs() <= eps,
                "closest point {} is {} away, distance says {}",
                p.point,
                reach,
                p.distance
            );
        }
    }
    let clearance = map.clearance(point, max_dist);
    let capped = exact.min(max_dist);
    prop_assert!(
        clearance <= capped + eps && clearance >= capped - delta - eps,
        "clearance {} but the capped distance is {} (from {})",
        clearance,
        capped,
        point
    );
    Ok(())
}

/// The cross-check between proximity and steps: a sphere at `point` whose
/// radius is clearly below the clearance is free, one clearly above it collides.
pub fn check_clearance_vs_capsule<M>(
    map: &M,
    point: &Point3,
    tolerance: Tolerance,
) -> Result<(), TestCaseError>
where
    M: ProximityQuery + UnspecificStepIntersector + ?Sized,
{
    let (eps, delta) = (tolerance.numeric, tolerance.conservative);
    let clearance = map.clearance(point, Real::INFINITY);
    if !clearance.is_finite() {
        let sphere = CapsuleStep::sphere(*point, 1.0).expect("finite");
        prop_assert!(
            map.is_step_free(&sphere),
            "infinite clearance at {} but a unit sphere collides",
            point
        );
        return Ok(());
    }
    let inside = clearance - delta - 3.0 * eps;
    if inside >= 0.0 {
        let sphere = CapsuleStep::sphere(*point, inside).expect("finite");
        prop_assert!(
            map.is_step_free(&sphere),
            "clearance {} at {} but a sphere of radius {} collides",
            clearance,
            point,
            inside
        );
    }
    let outside = clearance + delta + 3.0 * eps;
    let sphere = CapsuleStep::sphere(*point, outside).expect("finite");
    prop_assert!(
        !map.is_step_free(&sphere),
        "clearance {} at {} but a sphere of radius {} is free",
        clearance,
        point,
        outside
    );
    Ok(())
}
