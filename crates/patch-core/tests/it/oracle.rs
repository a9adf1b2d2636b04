//! The kernels and the reference map against slower, independent oracles: dense sampling of
//! regions and of segments.
//!
//! A sampled distance is an upper bound of the exact one (the samples are points of the set)
//! and exceeds it by at most the sampling resolution, so the kernel must lie in
//! `[sampled − resolution, sampled + rounding]`.

use patch_core::conformance::SceneKind;
use patch_core::conformance::strategies::{self, probe_step, scene_bounds};
use patch_core::geometry::{
    PlanarRegion, closest_point_on_region, closest_points_segment_segment, first_contact_region,
    first_contact_triangle, segment_region_distance, segment_region_within,
    segment_triangle_intersection,
};
use patch_core::{
    BruteForceMap, CapsuleStep, FromPatches, Patch, PlanarPatch, Point2, Point3, Polygon,
    ProximityQuery, Real, SpecificStepIntersector, Step, UnspecificStepIntersector,
};
use proptest::prelude::*;

/// Rounding allowance of the kernels.
const ROUND: Real = 1e-9;

/// Points of the region on a grid of spacing `h` and along every edge at spacing `h / 2`.
fn sample_region(poly: &Polygon, h: Real) -> Vec<Point2> {
    let b = poly.bounds2();
    let mut out = Vec::new();
    let nx = ((b.max.x - b.min.x) / h).ceil() as usize;
    let ny = ((b.max.y - b.min.y) / h).ceil() as usize;
    for i in 0..=nx {
        for j in 0..=ny {
            let p = Point2::new(b.min.x + i as Real * h, b.min.y + j as Real * h);
            if poly.contains(&p) {
                out.push(p);
            }
        }
    }
    for (a, c) in poly.edges() {
        let n = ((c - a).norm() / (0.5 * h)).ceil().max(1.0) as usize;
        out.extend((0..=n).map(|k| a + (c - a) * (k as Real / n as Real)));
    }
    out
}

fn local_point() -> impl Strategy<Value = Point3> {
    (-5.0..5.0, -5.0..5.0, -3.0..3.0).prop_map(|(x, y, z)| Point3::new(x, y, z))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn closest_point_on_region_matches_sampling(poly in strategies::polygon(), p in local_point()) {
        let b = poly.bounds2();
        let h = (b.max - b.min).amax() / 60.0;
        let k = closest_point_on_region(&poly, &p);
        let sampled = sample_region(&poly, h)
            .iter()
            .map(|s| (Point3::new(s.x, s.y, 0.0) - p).norm())
            .fold(Real::INFINITY, Real::min);
        prop_assert!(k.distance <= sampled + ROUND, "kernel {} > sampled {}", k.distance, sampled);
        prop_assert!(k.distance >= sampled - 2.0 * h, "kernel {} ≪ sampled {}", k.distance, sampled);
        prop_assert!(((k.point - p).norm() - k.distance).abs() <= ROUND);
        prop_assert!(k.point.z == 0.0);
        let on = poly.contains(&k.point.xy()) || poly.closest_boundary_point(&k.point.xy()).1 <= ROUND;
        prop_assert!(on, "closest point {} is not in the region", k.point);
    }

    #[test]
    fn segment_region_distance_matches_sampling(
        poly in strategies::polygon(),
        a in local_point(),
        b in local_point(),
        flat in 0usize..4,
    ) {
        // One case in four lies in the plane, one in four parallel to it.
        let (a, b) = match flat {
            0 => (Point3::new(a.x, a.y, 0.0), Point3::new(b.x, b.y, 0.0)),
            1 => (a, Point3::new(b.x, b.y, a.z)),
            _ => (a, b),
        };
        let k = segment_region_distance(&poly, &a, &b);
        let m = 400;
        let sampled = (0..=m)
            .map(|i| closest_point_on_region(&poly, &(a + (b - a) * (i as Real / m as Real))).distance)
            .fold(Real::INFINITY, Real::min);
        let resolution = (b - a).norm() / (2.0 * m as Real);
        prop_assert!(k.distance <= sampled + ROUND, "kernel {} > sampled {}", k.distance, sampled);
        prop_assert!(k.distance >= sampled - resolution - ROUND, "kernel {} ≪ sampled {}", k.distance, sampled);
        let at = a + (b - a) * k.t;
        prop_assert!(((at - k.point).norm() - k.distance).abs() <= ROUND);
        prop_assert!(closest_point_on_region(&poly, &k.point).distance <= ROUND);
    }

    #[test]
    fn segment_region_within_answers_as_the_distance(
        poly in strategies::polygon(),
        a in local_point(),
        b in local_point(),
        flat in 0usize..4,
        r in 0.0..2.0,
        at_distance in any::<bool>(),
    ) {
        // One case in four lies in the plane, one in four parallel to it; half the radii are
        // the distance itself (touching), where an early exit must not change the answer.
        let (a, b) = match flat {
            0 => (Point3::new(a.x, a.y, 0.0), Point3::new(b.x, b.y, 0.0)),
            1 => (a, Point3::new(b.x, b.y, a.z)),
            _ => (a, b),
        };
        let d = segment_region_distance(&poly, &a, &b).distance;
        let r = if at_distance { d } else { r };
        prop_assert_eq!(segment_region_within(&poly, &a, &b, r), d <= r, "d {} r {}", d, r);
        let patch = Patch::Planar(PlanarPatch::new(poly.clone(), patch_core::Isometry3::translation(0.3, -1.0, 2.0)).unwrap());
        let shift = patch_core::Vector3::new(0.3, -1.0, 2.0);
        let (wa, wb) = (a + shift, b + shift);
        let wd = patch.segment_distance(&wa, &wb).distance;
        let wr = if at_distance { wd } else { r };
        let collides = CapsuleStep::new(wa, wb, wr).map(|step| patch.collides_with(&step));
        if let Ok(collides) = collides {
            prop_assert_eq!(collides, wd <= wr);
        }
    }

    #[test]
    fn segment_segment_matches_sampling(p in proptest::array::uniform4(local_point()), parallel in any::<bool>()) {
        let [p0, p1, q0, mut q1] = p;
        if parallel {
            q1 = q0 + (p1 - p0) * 0.7;
        }
        let k = closest_points_segment_segment(&p0, &p1, &q0, &q1);
        let m = 300;
        let mut sampled = Real::INFINITY;
        for i in 0..=m {
            let x = p0 + (p1 - p0) * (i as Real / m as Real);
            let q = patch_core::geometry::closest_point_on_segment(&x, &q0, &q1);
            sampled = sampled.min((q - x).norm());
        }
        let resolution = (p1 - p0).norm() / (2.0 * m as Real);
        prop_assert!(k.distance <= sampled + ROUND);
        prop_assert!(k.distance >= sampled - resolution - ROUND);
        prop_assert!((0.0..=1.0).contains(&k.s) && (0.0..=1.0).contains(&k.t));
    }

    #[test]
    fn first_contact_region_matches_sampling(
        poly in strategies::polygon(),
        a in local_point(),
        b in local_point(),
        r in 0.0..1.5,
        flat in 0usize..4,
    ) {
        let (a, b) = match flat {
            0 => (Point3::new(a.x, a.y, 0.0), Point3::new(b.x, b.y, 0.0)),
            1 => (a, Point3::new(b.x, b.y, a.z)),
            _ => (a, b),
        };
        check_contact_by_sampling(&poly, &a, &b, r)?;
    }

    #[test]
    fn segment_triangle_intersection_matches_the_contact_kernel(
        tri in proptest::array::uniform3(local_point()),
        a in local_point(),
        b in local_point(),
    ) {
        let exact = segment_triangle_intersection(&a, &b, &tri);
        let Some(frame) = patch_core::geometry::TriangleFrame::new(&tri) else { return Ok(()) };
        let contact = first_contact_triangle(&tri, &a, &b, 0.0);
        let distance = frame.segment_distance(&a, &b).distance;
        // Both agree except within rounding of a touch.
        if distance > ROUND {
            prop_assert!(exact.is_none() && contact.is_none());
        } else if let (Some(t), Some(c)) = (exact, contact) {
            let x = a + (b - a) * t;
            prop_assert!(frame.closest_point(&x).distance <= ROUND, "exact t {} is off the triangle", t);
            prop_assert!((t - c.t).abs() * (b - a).norm() <= 1e-6, "t {} vs {}", t, c.t);
        }
    }
}

/// The contact kernel against the sampled distance along the segment: no sample before `t` is
/// within `r − ROUND`, the centre at `t` is within `r + ROUND`, and `None` only if no sample is
/// within `r − ROUND`.
fn check_contact_by_sampling(
    poly: &Polygon,
    a: &Point3,
    b: &Point3,
    r: Real,
) -> Result<(), TestCaseError> {
    let contact = first_contact_region(poly, a, b, r);
    let m = 400;
    let dist = |t: Real| closest_point_on_region(poly, &(a + (b - a) * t)).distance;
    let t_end = contact.map_or(1.0, |c| c.t);
    for i in 0..=m {
        let t = i as Real / m as Real;
        if t < t_end || contact.is_none() {
            prop_assert!(
                dist(t) > r - ROUND,
                "sample t = {} at distance {} ≤ r = {} before contact {:?}",
                t,
                dist(t),
                r,
                contact
            );
        }
    }
    if let Some(c) = contact {
        prop_assert!(
            dist(c.t) <= r + ROUND,
            "distance {} at contact t = {}, r = {}",
            dist(c.t),
            c.t,
            r
        );
        prop_assert!(((a + (b - a) * c.t - c.point).norm() - dist(c.t)).abs() <= ROUND);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// The reference map on probe steps (grazing, along planes, radius 0) against sampling the
    /// step with the point distance.
    #[test]
    fn reference_matches_sampling_on_probe_steps(
        (patches, steps) in strategies::scene_with_capsule_steps(SceneKind::Mixed, 1..=4, 1..=8)
    ) {
        let map = BruteForceMap::from_patches(patches).unwrap();
        for step in &steps {
            let m = 200;
            let dist = |t: Real| map.clearance(&step.point_at(t), Real::INFINITY);
            let sampled = (0..=m).map(|i| dist(i as Real / m as Real)).fold(Real::INFINITY, Real::min);
            let exact = map.step_distance(step).unwrap().distance;
            let resolution = step.length() / (2.0 * m as Real);
            prop_assert!(exact <= sampled + ROUND && exact >= sampled - resolution - ROUND,
                "step distance {} vs sampled {} ({:?})", exact, sampled, step);
            let r = step.radius();
            match map.first_hit(step) {
                None => prop_assert!(sampled > r - ROUND && map.is_step_free(step)),
                Some(hit) => {
                    prop_assert!(!map.is_step_free(step));
                    prop_assert!(dist(hit.t) <= r + ROUND);
                    for i in 0..=m {
                        let t = i as Real / m as Real;
                        if t < hit.t {
                            prop_assert!(dist(t) > r - ROUND, "sample {} within r before hit {:?}", t, hit);
                        }
                    }
                }
            }
        }
    }

    /// Contacts on single planar patches with probe steps, in the local frame.
    #[test]
    fn contact_kernel_on_probe_steps(
        (patch, step) in strategies::planar_patch().prop_flat_map(|p| {
            let shared: std::sync::Arc<[Patch]> = vec![Patch::from(p.clone())].into();
            (Just(p), probe_step(shared, strategies::radius()))
        })
    ) {
        let (a, b) = (patch.to_local(&step.start()), patch.to_local(&step.end()));
        check_contact_by_sampling(patch.polygon(), &a, &b, step.radius())?;
    }
}

#[test]
fn exact_rotations_are_exact() {
    for q in strategies::exact_rotations() {
        let v = q * patch_core::Vector3::new(0.25, -1.5, 3.75);
        for c in v.iter() {
            assert_eq!(c * 4.0, (c * 4.0).round(), "{q:?} rounds {v}");
        }
    }
    assert_eq!(strategies::exact_rotations().len(), 12);
    assert!(!scene_bounds().is_empty());
}

#[test]
fn building_scene_by_hand() {
    // Floor, and a wall with a window; a robot flying through the window.
    let floor = PlanarPatch::rectangle(
        patch_core::Isometry3::identity(),
        Point2::new(0.0, 0.0),
        Point2::new(4.0, 4.0),
    )
    .unwrap();
    let wall = PlanarPatch::from_world_polygon(
        &[
            Point3::new(2.0, 0.0, 0.0),
            Point3::new(2.0, 4.0, 0.0),
            Point3::new(2.0, 4.0, 3.0),
            Point3::new(2.0, 0.0, 3.0),
        ],
        &[vec![
            Point3::new(2.0, 1.0, 1.0),
            Point3::new(2.0, 3.0, 1.0),
            Point3::new(2.0, 3.0, 2.0),
            Point3::new(2.0, 1.0, 2.0),
        ]],
        1e-12,
    )
    .unwrap();
    let map = BruteForceMap::from_patches([floor.into(), wall.into()]).unwrap();
    let through = |r: Real| {
        CapsuleStep::new(Point3::new(0.5, 2.0, 1.5), Point3::new(3.5, 2.0, 1.5), r).unwrap()
    };
    assert!(map.is_step_free(&through(0.49)));
    assert!(!map.is_step_free(&through(0.5))); // touches the window's rim
    let hit = map.first_hit(&through(0.5)).unwrap();
    assert!((hit.t - 0.5).abs() < 1e-12);
    assert_eq!(hit.patch.0, 1);
    // The same along the floor at exactly its radius: touching.
    let along =
        CapsuleStep::new(Point3::new(0.5, 0.5, 0.25), Point3::new(1.5, 3.5, 0.25), 0.25).unwrap();
    assert_eq!(map.first_hit(&along).unwrap().t, 0.0);
    assert!(
        map.is_step_free(
            &CapsuleStep::new(
                along.start() + patch_core::Vector3::z() * 1e-6,
                along.end() + patch_core::Vector3::z() * 1e-6,
                0.25
            )
            .unwrap()
        )
    );
    let near = map.closest_patch(&Point3::new(1.0, 2.0, 1.0), 10.0).unwrap();
    assert_eq!((near.patch.0, near.distance), (0, 1.0));
    assert_eq!(map.clearance(&Point3::new(1.0, 2.0, 1.0), 0.5), 0.5);
    assert!(map.closest_patch(&Point3::new(1.0, 2.0, 1.0), 0.5).is_none());
}

#[test]
fn region_trait_is_implemented_for_polygons() {
    fn edges<R: PlanarRegion>(r: &R) -> usize {
        r.edges().count()
    }
    let p = Polygon::rectangle(Point2::new(0.0, 0.0), Point2::new(1.0, 1.0)).unwrap();
    assert_eq!(edges(&p), 4);
}
