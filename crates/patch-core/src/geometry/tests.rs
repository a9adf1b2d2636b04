//! Hand-computed cases for every branch of the kernels. Property tests against sampling
//! oracles live in `tests/kernels.rs`.

use super::*;

fn p3(x: Real, y: Real, z: Real) -> Point3 {
    Point3::new(x, y, z)
}

fn square(lo: Real, hi: Real) -> Vec<Point2> {
    vec![Point2::new(lo, lo), Point2::new(hi, lo), Point2::new(hi, hi), Point2::new(lo, hi)]
}

/// The square [0, 4]² with the hole [1, 2]².
fn holed() -> Polygon {
    Polygon::new(square(0.0, 4.0), vec![square(1.0, 2.0)]).unwrap()
}

fn close(a: Real, b: Real, eps: Real) -> bool {
    (a - b).abs() <= eps
}

#[test]
fn segment_segment_all_branches() {
    // Crossing.
    let s = closest_points_segment_segment(
        &p3(-1.0, 0.0, 0.0),
        &p3(1.0, 0.0, 0.0),
        &p3(0.0, -1.0, 0.0),
        &p3(0.0, 1.0, 0.0),
    );
    assert_eq!(s.distance, 0.0);
    assert_eq!((s.s, s.t), (0.5, 0.5));
    // Skew, closest in the interiors.
    let s = closest_points_segment_segment(
        &p3(-1.0, 0.0, 0.0),
        &p3(1.0, 0.0, 0.0),
        &p3(0.0, -1.0, 2.0),
        &p3(0.0, 1.0, 2.0),
    );
    assert_eq!(s.distance, 2.0);
    // Parallel, offset, overlapping in projection.
    let s = closest_points_segment_segment(
        &p3(0.0, 0.0, 0.0),
        &p3(2.0, 0.0, 0.0),
        &p3(1.0, 1.0, 0.0),
        &p3(3.0, 1.0, 0.0),
    );
    assert_eq!(s.distance, 1.0);
    assert!((s.point_a - s.point_b).norm() == 1.0);
    // Parallel, disjoint in projection: endpoint to endpoint.
    let s = closest_points_segment_segment(
        &p3(0.0, 0.0, 0.0),
        &p3(1.0, 0.0, 0.0),
        &p3(3.0, 1.0, 0.0),
        &p3(4.0, 1.0, 0.0),
    );
    assert!(close(s.distance, 5.0f64.sqrt(), 1e-15));
    assert_eq!((s.s, s.t), (1.0, 0.0));
    // Collinear, overlapping.
    let s = closest_points_segment_segment(
        &p3(0.0, 0.0, 0.0),
        &p3(2.0, 0.0, 0.0),
        &p3(1.0, 0.0, 0.0),
        &p3(3.0, 0.0, 0.0),
    );
    assert_eq!(s.distance, 0.0);
    // Collinear, disjoint.
    let s = closest_points_segment_segment(
        &p3(0.0, 0.0, 0.0),
        &p3(1.0, 0.0, 0.0),
        &p3(3.0, 0.0, 0.0),
        &p3(2.0, 0.0, 0.0),
    );
    assert_eq!(s.distance, 1.0);
    assert_eq!((s.s, s.t), (1.0, 1.0));
    // Both points.
    let s = closest_points_segment_segment(
        &p3(0.0, 0.0, 0.0),
        &p3(0.0, 0.0, 0.0),
        &p3(0.0, 3.0, 4.0),
        &p3(0.0, 3.0, 4.0),
    );
    assert_eq!(s.distance, 5.0);
    // First a point.
    let s = closest_points_segment_segment(
        &p3(1.0, 1.0, 0.0),
        &p3(1.0, 1.0, 0.0),
        &p3(0.0, 0.0, 0.0),
        &p3(2.0, 0.0, 0.0),
    );
    assert_eq!((s.distance, s.t), (1.0, 0.5));
    // Second a point.
    let s = closest_points_segment_segment(
        &p3(0.0, 0.0, 0.0),
        &p3(2.0, 0.0, 0.0),
        &p3(3.0, 0.0, 0.0),
        &p3(3.0, 0.0, 0.0),
    );
    assert_eq!((s.distance, s.s), (1.0, 1.0));
    // t clamped at both ends, forcing the re-projection of s.
    let s = closest_points_segment_segment(
        &p3(0.0, 0.0, 0.0),
        &p3(4.0, 0.0, 0.0),
        &p3(5.0, 1.0, 0.0),
        &p3(6.0, 3.0, 0.0),
    );
    assert_eq!((s.s, s.t), (1.0, 0.0));
    assert!(close(s.distance, 2.0f64.sqrt(), 1e-15));
}

#[test]
fn closest_point_on_segment_handles_zero_length() {
    let a = p3(1.0, 2.0, 3.0);
    assert_eq!(closest_point_on_segment(&p3(0.0, 0.0, 0.0), &a, &a), a);
    assert_eq!(
        closest_point_on_segment(&p3(5.0, 1.0, 0.0), &p3(0.0, 0.0, 0.0), &p3(2.0, 0.0, 0.0)),
        p3(2.0, 0.0, 0.0)
    );
    assert_eq!(
        closest_point_on_segment(&p3(1.0, 1.0, 0.0), &p3(0.0, 0.0, 0.0), &p3(2.0, 0.0, 0.0)),
        p3(1.0, 0.0, 0.0)
    );
}

#[test]
fn closest_point_on_region_branches() {
    let poly = holed();
    // Above the interior.
    let c = closest_point_on_region(&poly, &p3(3.0, 3.0, -2.0));
    assert_eq!((c.point, c.distance), (p3(3.0, 3.0, 0.0), 2.0));
    // On the region.
    assert_eq!(closest_point_on_region(&poly, &p3(0.5, 3.0, 0.0)).distance, 0.0);
    // Outside next to an edge.
    let c = closest_point_on_region(&poly, &p3(6.0, 3.0, 0.0));
    assert_eq!((c.point, c.distance), (p3(4.0, 3.0, 0.0), 2.0));
    // Outside a corner, above the plane.
    let c = closest_point_on_region(&poly, &p3(-3.0, -4.0, 12.0));
    assert_eq!((c.point, c.distance), (p3(0.0, 0.0, 0.0), 13.0));
    // Above the hole: the nearest hole edge.
    let c = closest_point_on_region(&poly, &p3(1.5, 1.25, 0.0));
    assert_eq!((c.point, c.distance), (p3(1.5, 1.0, 0.0), 0.25));
    // On the hole's boundary: inside.
    let c = closest_point_on_region(&poly, &p3(1.0, 1.5, 0.75));
    assert_eq!((c.point, c.distance), (p3(1.0, 1.5, 0.0), 0.75));
}

#[test]
fn first_entry_2d_branches() {
    let poly = holed();
    let e = |a: (Real, Real), b: (Real, Real)| {
        first_entry_2d(&poly, &Point2::new(a.0, a.1), &Point2::new(b.0, b.1))
    };
    assert_eq!(e((3.0, 3.0), (9.0, 9.0)), Some(0.0)); // starts inside
    assert_eq!(e((-2.0, 3.0), (2.0, 3.0)), Some(0.5)); // crosses the outer edge
    assert_eq!(e((-2.0, 3.0), (-1.0, 3.0)), None); // misses
    assert_eq!(e((-2.0, 3.0), (-2.0, 3.0)), None); // zero length outside
    assert_eq!(e((3.0, 3.0), (3.0, 3.0)), Some(0.0)); // zero length inside
    assert_eq!(e((-2.0, 0.0), (2.0, 0.0)), Some(0.5)); // collinear with the bottom edge
    assert_eq!(e((6.0, 4.0), (-2.0, 4.0)), Some(0.25)); // collinear, entering from the right
}

#[test]
fn first_entry_2d_from_a_hole() {
    let poly = holed();
    // The hole interior is outside the region; the rim is inside.
    let u = first_entry_2d(&poly, &Point2::new(1.5, 1.5), &Point2::new(1.5, 3.0));
    assert!(close(u.unwrap(), 1.0 / 3.0, 1e-15));
    // Staying inside the hole: never in the region.
    let u = first_entry_2d(&poly, &Point2::new(1.25, 1.5), &Point2::new(1.25, 1.75));
    assert_eq!(u, None);
}

#[test]
fn segment_region_distance_branches() {
    let poly = holed();
    let d = |a: Point3, b: Point3| segment_region_distance(&poly, &a, &b);
    // Crossing inside: 0 at the crossing.
    let s = d(p3(3.0, 3.0, 1.0), p3(3.0, 3.0, -3.0));
    assert_eq!((s.distance, s.t, s.point), (0.0, 0.25, p3(3.0, 3.0, 0.0)));
    // Crossing inside the hole: distance to the hole's nearest edge.
    let s = d(p3(1.5, 1.25, 1.0), p3(1.5, 1.25, -1.0));
    assert!(close(s.distance, 0.25, 1e-15));
    assert!(close(s.t, 0.5, 1e-15));
    // Parallel above the interior.
    assert_eq!(d(p3(0.5, 0.5, 2.0), p3(3.5, 0.5, 2.0)).distance, 2.0);
    // Parallel above, crossing over the outer edge: distance |z| at the edge.
    assert_eq!(d(p3(-3.0, 3.0, 2.0), p3(0.0, 3.0, 2.0)).distance, 2.0);
    // Parallel, wholly outside.
    assert_eq!(d(p3(-3.0, 3.0, 0.0), p3(-1.0, 3.0, 0.0)).distance, 1.0);
    // In the plane crossing an edge: exactly 0 at the first entry.
    let s = d(p3(-2.0, 3.0, 0.0), p3(2.0, 3.0, 0.0));
    assert_eq!((s.distance, s.t), (0.0, 0.5));
    // In the plane inside the hole.
    assert!(close(d(p3(1.25, 1.5, 0.0), p3(1.75, 1.5, 0.0)).distance, 0.25, 1e-15));
    // Zero length: the point distance.
    assert_eq!(d(p3(3.0, 3.0, 0.5), p3(3.0, 3.0, 0.5)).distance, 0.5);
    assert_eq!(d(p3(3.0, 3.0, 0.0), p3(3.0, 3.0, 0.0)).distance, 0.0);
    // Endpoint exactly on the region.
    assert_eq!(d(p3(3.0, 3.0, 1.0), p3(3.0, 3.0, 0.0)).distance, 0.0);
    // Endpoint on the plane outside; the other above: distance to the edge.
    assert!(close(d(p3(5.0, 3.0, 0.0), p3(5.0, 3.0, 2.0)).distance, 1.0, 1e-15));
    // Crossing the plane outside, near a corner.
    let s = d(p3(-1.0, -1.0, 1.0), p3(-1.0, -1.0, -1.0));
    assert!(close(s.distance, 2.0f64.sqrt(), 1e-15));
    assert_eq!(s.point, p3(0.0, 0.0, 0.0));
}

#[test]
fn sphere_casts() {
    let o = p3(0.0, 0.0, 0.0);
    // Head-on towards a point.
    assert_eq!(
        sphere_cast_point(&p3(-2.0, 0.0, 0.0), &Vector3::new(4.0, 0.0, 0.0), 1.0, &o),
        Some(0.25)
    );
    // Moving away, passing by, no motion.
    assert_eq!(sphere_cast_point(&p3(2.0, 0.0, 0.0), &Vector3::new(4.0, 0.0, 0.0), 1.0, &o), None);
    assert_eq!(sphere_cast_point(&p3(-2.0, 2.0, 0.0), &Vector3::new(4.0, 0.0, 0.0), 1.0, &o), None);
    assert_eq!(sphere_cast_point(&p3(-2.0, 0.0, 0.0), &Vector3::zeros(), 1.0, &o), None);
    // Falls short.
    assert_eq!(sphere_cast_point(&p3(-2.0, 0.0, 0.0), &Vector3::new(0.5, 0.0, 0.0), 1.0, &o), None);
    // Ends exactly touching.
    assert_eq!(
        sphere_cast_point(&p3(-2.0, 0.0, 0.0), &Vector3::new(1.0, 0.0, 0.0), 1.0, &o),
        Some(1.0)
    );
    // Radius 0 through the point.
    assert_eq!(
        sphere_cast_point(&p3(-2.0, 0.0, 0.0), &Vector3::new(4.0, 0.0, 0.0), 0.0, &o),
        Some(0.5)
    );
    // Cylinder side of an edge along y.
    let (e0, e1) = (p3(0.0, -1.0, 0.0), p3(0.0, 1.0, 0.0));
    let t = sphere_cast_segment(&p3(-2.0, 0.5, 0.0), &Vector3::new(4.0, 0.0, 0.0), 1.0, &e0, &e1);
    assert_eq!(t, Some(0.25));
    // Beyond the edge's end: only the end cap sphere counts.
    let t = sphere_cast_segment(&p3(-2.0, 1.6, 0.0), &Vector3::new(4.0, 0.0, 0.0), 1.0, &e0, &e1)
        .unwrap();
    assert!(close(t, (2.0 - 0.8) / 4.0, 1e-15)); // |(x, 0.6)| = 1 at x = -0.8
    // Motion parallel to the edge, within the cylinder radius: meets the end cap.
    let t = sphere_cast_segment(&p3(0.5, -4.0, 0.0), &Vector3::new(0.0, 8.0, 0.0), 1.0, &e0, &e1)
        .unwrap();
    assert!(close(t, (3.0 - 0.75f64.sqrt()) / 8.0, 1e-15));
    // A zero-length edge is a point.
    let t = sphere_cast_segment(&p3(-2.0, 0.0, 0.0), &Vector3::new(4.0, 0.0, 0.0), 1.0, &o, &o);
    assert_eq!(t, Some(0.25));
}

#[test]
fn first_contact_face_from_both_sides_and_zero_radius() {
    let poly = holed();
    let c = first_contact_region(&poly, &p3(3.0, 3.0, 2.0), &p3(3.0, 3.0, -2.0), 0.5).unwrap();
    assert_eq!((c.t, c.point), (0.375, p3(3.0, 3.0, 0.0)));
    assert_eq!(c.normal, Vector3::z_axis());
    let c = first_contact_region(&poly, &p3(3.0, 3.0, -2.0), &p3(3.0, 3.0, 2.0), 0.5).unwrap();
    assert_eq!(c.t, 0.375);
    assert_eq!(c.normal, -Vector3::z_axis());
    // Radius 0: the crossing, normal toward the start side.
    let c = first_contact_region(&poly, &p3(3.0, 3.0, -2.0), &p3(3.0, 3.0, 2.0), 0.0).unwrap();
    assert_eq!((c.t, c.normal), (0.5, -Vector3::z_axis()));
    // Through the hole with radius 0: free; with a radius reaching the rim: contact.
    assert!(first_contact_region(&poly, &p3(1.5, 1.5, -2.0), &p3(1.5, 1.5, 2.0), 0.0).is_none());
    assert!(first_contact_region(&poly, &p3(1.5, 1.5, -2.0), &p3(1.5, 1.5, 2.0), 0.49).is_none());
    let c = first_contact_region(&poly, &p3(1.5, 1.5, -2.0), &p3(1.5, 1.5, 2.0), 0.5).unwrap();
    assert!(close(c.t, 0.5, 1e-15)); // touches the rim exactly in the plane
    // Ending exactly at distance r.
    let c = first_contact_region(&poly, &p3(3.0, 3.0, 3.0), &p3(3.0, 3.0, 0.5), 0.5).unwrap();
    assert_eq!(c.t, 1.0);
    // Ending just short.
    assert!(
        first_contact_region(&poly, &p3(3.0, 3.0, 3.0), &p3(3.0, 3.0, 0.5 + 1e-12), 0.5).is_none()
    );
}

#[test]
fn first_contact_start_touching_and_zero_length() {
    let poly = holed();
    let c = first_contact_region(&poly, &p3(3.0, 3.0, 0.25), &p3(3.0, 9.0, 0.25), 0.5).unwrap();
    assert_eq!((c.t, c.point), (0.0, p3(3.0, 3.0, 0.0)));
    // Zero length: sphere tests, including exactly touching.
    let a = p3(3.0, 3.0, 0.5);
    assert_eq!(first_contact_region(&poly, &a, &a, 0.5).unwrap().t, 0.0);
    assert!(first_contact_region(&poly, &a, &a, 0.4999).is_none());
    // Zero length and zero radius on the region.
    let a = p3(3.0, 3.0, 0.0);
    assert_eq!(first_contact_region(&poly, &a, &a, 0.0).unwrap().t, 0.0);
    // Zero length in the hole.
    let a = p3(1.5, 1.5, 0.0);
    assert!(first_contact_region(&poly, &a, &a, 0.49).is_none());
    assert_eq!(first_contact_region(&poly, &a, &a, 0.5).unwrap().t, 0.0);
}

#[test]
fn first_contact_edges_and_vertices() {
    let poly = holed();
    // Horizontal motion at height 0.3 toward the edge x = 0: cylinder contact at x = -0.4.
    let c = first_contact_region(&poly, &p3(-2.0, 2.5, 0.3), &p3(2.0, 2.5, 0.3), 0.5).unwrap();
    assert!(close(c.t, 0.4, 1e-15));
    assert!((c.point - p3(0.0, 2.5, 0.0)).norm() < 1e-15);
    assert_eq!(c.normal, Vector3::z_axis());
    // In-plane diagonal approach of the corner (0, 0): vertex sphere.
    let c = first_contact_region(&poly, &p3(-2.0, -2.0, 0.0), &p3(2.0, 2.0, 0.0), 0.5).unwrap();
    let s = 0.5 / 2.0f64.sqrt();
    assert!(close(c.t, (2.0 - s) / 4.0, 1e-15));
    assert!((c.point - p3(0.0, 0.0, 0.0)).norm() < 1e-15);
    assert_eq!(c.normal, Vector3::z_axis()); // in-plane motion: +z
    // Same from below the plane, moving up: center below => -z.
    let c = first_contact_region(&poly, &p3(-2.0, 2.5, -0.3), &p3(2.0, 2.5, -0.3), 0.5).unwrap();
    assert_eq!(c.normal, -Vector3::z_axis());
}

#[test]
fn first_contact_parallel_to_the_plane() {
    let poly = holed();
    // At height exactly r: grazes the face from x = 0 on.
    let c = first_contact_region(&poly, &p3(-1.0, 3.0, 0.5), &p3(5.0, 3.0, 0.5), 0.5).unwrap();
    assert!(close(c.t, 1.0 / 6.0, 1e-15));
    assert!((c.point - p3(0.0, 3.0, 0.0)).norm() < 1e-15);
    // Just above: free.
    assert!(
        first_contact_region(&poly, &p3(-1.0, 3.0, 0.5 + 1e-9), &p3(5.0, 3.0, 0.5 + 1e-9), 0.5)
            .is_none()
    );
    // In the plane, radius 0: first entry through the edge.
    let c = first_contact_region(&poly, &p3(-1.0, 3.0, 0.0), &p3(5.0, 3.0, 0.0), 0.0).unwrap();
    assert!(close(c.t, 1.0 / 6.0, 1e-15));
    assert_eq!(c.normal, Vector3::z_axis());
    // In the plane from inside the hole, radius 0: enters at the hole rim.
    let c = first_contact_region(&poly, &p3(1.5, 1.5, 0.0), &p3(1.5, 3.0, 0.0), 0.0).unwrap();
    assert!(close(c.t, 1.0 / 3.0, 1e-15));
    // In the plane, radius 0, along an edge's line from outside.
    let c = first_contact_region(&poly, &p3(-2.0, 0.0, 0.0), &p3(2.0, 0.0, 0.0), 0.0).unwrap();
    assert_eq!(c.t, 0.5);
    // Parallel, at height r, above the hole only: grazing the hole rim from inside the hole.
    let c = first_contact_region(&poly, &p3(1.5, 1.25, 0.5), &p3(1.5, 1.75, 0.5), 0.5);
    assert!(c.is_none()); // the rim is at least 0.25 away horizontally: sqrt(0.25² + 0.5²) > 0.5
}

#[test]
fn triangle_frame_and_kernels() {
    let tri = [p3(0.0, 0.0, 1.0), p3(2.0, 0.0, 1.0), p3(0.0, 2.0, 1.0)];
    let f = TriangleFrame::new(&tri).unwrap();
    assert_eq!(f.normal(), Vector3::z_axis());
    let p = p3(0.3, -0.7, 4.0);
    assert!((f.to_world(&f.to_local(&p)) - p).norm() < 1e-15);
    assert!(
        TriangleFrame::new(&[p3(0.0, 0.0, 0.0), p3(1.0, 1.0, 1.0), p3(2.0, 2.0, 2.0)]).is_none()
    );
    // Closest points.
    let c = closest_point_on_triangle(&p3(0.5, 0.5, 3.0), &tri);
    assert!(close(c.distance, 2.0, 1e-15));
    let c = closest_point_on_triangle(&p3(3.0, 3.0, 1.0), &tri);
    assert!(close(c.distance, 2.0f64.sqrt() * 2.0, 1e-14));
    // Segment distance: crossing, and parallel above.
    assert_eq!(
        segment_triangle_distance(&p3(0.5, 0.5, 0.0), &p3(0.5, 0.5, 2.0), &tri).distance,
        0.0
    );
    assert!(close(
        segment_triangle_distance(&p3(-1.0, 0.5, 2.0), &p3(3.0, 0.5, 2.0), &tri).distance,
        1.0,
        1e-15
    ));
    // Contact from above with a radius.
    let c = first_contact_triangle(&tri, &p3(0.5, 0.5, 3.0), &p3(0.5, 0.5, -1.0), 1.0).unwrap();
    assert!(close(c.t, 0.25, 1e-15));
    assert_eq!(c.normal, Vector3::z_axis());
    // Degenerate triangles: distances over the edges, no contact frame.
    let flat = [p3(0.0, 0.0, 0.0), p3(1.0, 0.0, 0.0), p3(2.0, 0.0, 0.0)];
    assert!(close(closest_point_on_triangle(&p3(1.0, 1.0, 0.0), &flat).distance, 1.0, 1e-15));
    assert!(close(
        segment_triangle_distance(&p3(1.0, 1.0, 0.0), &p3(1.0, 2.0, 0.0), &flat).distance,
        1.0,
        1e-15
    ));
    assert!(first_contact_triangle(&flat, &p3(1.0, 1.0, 0.0), &p3(1.0, -1.0, 0.0), 0.0).is_none());
}

#[test]
fn segment_triangle_intersection_branches() {
    let tri = [p3(0.0, 0.0, 0.0), p3(2.0, 0.0, 0.0), p3(0.0, 2.0, 0.0)];
    let hit = |a: Point3, b: Point3| segment_triangle_intersection(&a, &b, &tri);
    assert_eq!(hit(p3(0.5, 0.5, 1.0), p3(0.5, 0.5, -1.0)), Some(0.5)); // interior
    assert_eq!(hit(p3(0.0, 0.0, 1.0), p3(0.0, 0.0, -3.0)), Some(0.25)); // through a vertex
    assert_eq!(hit(p3(1.0, 1.0, 1.0), p3(1.0, 1.0, -1.0)), Some(0.5)); // through the hypotenuse
    assert_eq!(hit(p3(1.0, 1.01, 1.0), p3(1.0, 1.01, -1.0)), None); // just past it
    assert_eq!(hit(p3(0.5, 0.5, 1.0), p3(0.5, 0.5, 0.5)), None); // same side
    assert_eq!(hit(p3(0.5, 0.5, 1.0), p3(0.5, 0.5, 0.0)), Some(1.0)); // ends on the triangle
    assert_eq!(hit(p3(0.5, 0.5, 0.0), p3(0.5, 0.5, 0.0)), Some(0.0)); // a point on it
    assert_eq!(hit(p3(-1.0, 0.5, 0.0), p3(3.0, 0.5, 0.0)), Some(0.25)); // coplanar crossing
    assert_eq!(hit(p3(-1.0, -0.5, 0.0), p3(3.0, -0.5, 0.0)), None); // coplanar miss
    assert_eq!(hit(p3(-1.0, 0.5, 1.0), p3(3.0, 0.5, 1.0)), None); // parallel above
}
