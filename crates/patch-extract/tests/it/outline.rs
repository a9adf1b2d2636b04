//! Outlines of planar regions: projection, α-shapes, convex hull, Douglas–Peucker and the
//! region → patch pipeline (thesis §5.3.2–§5.3.3).

use patch_core::na;
use patch_core::{Isometry3, Plane, PlaneCovariance, Point2, Point3, Polygon, Real, Vector3};
use patch_extract::PlanarRegion;
use patch_extract::alpha_shape::{
    AlphaChoice, AlphaShapeConfig, AlphaShapeError, ComponentPolicy, HoleFilter,
    ROBUST_MAX_UNCOVERED, alpha_shape, alpha_shape_filled, optimal_alpha,
};
use patch_extract::hull::{HullError, convex_hull, convex_hull_polygon};
use patch_extract::polygonize::{
    GridThinning, PolygonizeConfig, PolygonizeError, pixels_of_points, polygonize_region,
    region_to_patch, triangle_count,
};
use patch_extract::projection::{
    AlrfSideColumns, GrazingPolicy, ProjectionConfig, ProjectionError,
    invalidate_alrf_side_columns, plane_frame, project_indices, project_region,
};
use patch_extract::simplify::{
    SimplifyError, douglas_peucker_ring, simplify_polygon, simplify_polygon_valid,
};
use pointcloud::{ActuatedLrfModel, BeamModel, PointCloud, RangeImage, RangeKind};
use proptest::prelude::*;
use scene_sim::{
    Material, PlanarPolygon, RangeCamera, RangeCameraConfig, RangeSensor as _, SceneBuilder,
    camera_pose_looking,
};

/// A small deterministic generator (splitmix64) for test data.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [-1, 1).
    fn unit(&mut self) -> Real {
        (self.next_u64() >> 11) as Real / (1u64 << 52) as Real - 1.0
    }
}

/// A jittered grid with spacing `h` over `[x0, x1] × [y0, y1]` (jitter ±`h/4`, clamped into
/// the box), keeping points for which `keep` holds.
fn jittered_grid(
    (x0, x1): (Real, Real),
    (y0, y1): (Real, Real),
    h: Real,
    seed: u64,
    keep: impl Fn(&Point2) -> bool,
) -> Vec<Point2> {
    let mut rng = Rng(seed);
    let nx = ((x1 - x0) / h).round() as usize;
    let ny = ((y1 - y0) / h).round() as usize;
    let mut out = Vec::new();
    for i in 0..=nx {
        for j in 0..=ny {
            let x = (x0 + i as Real * h + 0.25 * h * rng.unit()).clamp(x0, x1);
            let y = (y0 + j as Real * h + 0.25 * h * rng.unit()).clamp(y0, y1);
            let p = Point2::new(x, y);
            if keep(&p) {
                out.push(p);
            }
        }
    }
    out
}

fn inside(p: &Point2, (x0, x1): (Real, Real), (y0, y1): (Real, Real)) -> bool {
    p.x > x0 && p.x < x1 && p.y > y0 && p.y < y1
}

fn rel(a: Real, b: Real) -> Real {
    (a - b).abs() / b.abs()
}

#[test]
fn alpha_shape_of_square_with_hole_has_one_outer_ring_and_one_hole() {
    let hole = ((1.25, 2.75), (1.25, 2.75));
    let points = jittered_grid((0.0, 4.0), (0.0, 4.0), 0.05, 1, |p| !inside(p, hole.0, hole.1));
    let shape = alpha_shape(&points, &AlphaShapeConfig::thesis()).unwrap();
    assert_eq!(shape.num_components, 1);
    assert_eq!(shape.polygons.len(), 1);
    let polygon = &shape.polygons[0];
    assert_eq!(polygon.holes().len(), 1, "the hole is kept");
    let outer_area = polygon.outer().signed_area();
    let hole_area = -polygon.holes()[0].signed_area();
    assert!(rel(outer_area, 16.0) < 0.02, "outer area {outer_area}");
    assert!(rel(hole_area, 2.25) < 0.10, "hole area {hole_area}");
    assert!(rel(polygon.area(), 13.75) < 0.03, "area {}", polygon.area());
    assert!(shape.filled_holes > 0, "jitter makes tiny holes at the optimal α");
    assert!(polygon.area() >= shape.interior_area - 1e-6, "filled holes only add area");
    // The exact complex keeps them.
    let exact = alpha_shape(
        &points,
        &AlphaShapeConfig { holes: HoleFilter::KeepAll, ..AlphaShapeConfig::thesis() },
    )
    .unwrap();
    assert_eq!(exact.polygons[0].holes().len(), 1 + shape.filled_holes);
    assert!((exact.polygons[0].area() - exact.interior_area).abs() < 1e-6);
}

#[test]
fn alpha_shape_of_an_l_stays_an_l() {
    let l = |p: &Point2| p.x <= 1.0 || p.y <= 1.0;
    let points = jittered_grid((0.0, 4.0), (0.0, 4.0), 0.05, 2, l);
    let shape = alpha_shape(&points, &AlphaShapeConfig::thesis()).unwrap();
    let polygon = &shape.polygons[0];
    // Jitter of ±¼ spacing makes the boundary triangles slivers that the optimal α leaves out:
    // the outline runs ~1.5 cm inside the true edge (16 m perimeter → ~3.5 %).
    assert!(rel(polygon.area(), 7.0) < 0.05, "area {}", polygon.area());
    assert!(!polygon.contains(&Point2::new(2.0, 2.0)), "not the convex hull");
    let hull = convex_hull_polygon(&points).unwrap();
    assert!(rel(hull.area(), 11.5) < 0.01, "hull area {}", hull.area());
    assert!(hull.contains(&Point2::new(2.0, 2.0)));
}

#[test]
fn optimal_alpha_gives_one_component_and_a_smaller_alpha_splits() {
    let points: Vec<Point2> = jittered_grid((0.0, 1.0), (0.0, 1.0), 0.05, 3, |_| true)
        .into_iter()
        .chain(jittered_grid((1.3, 2.3), (0.0, 1.0), 0.05, 4, |_| true))
        .collect();
    let alpha = optimal_alpha(&points, 1).unwrap();
    assert!(alpha > 0.1, "the 0.3 m gap must be bridged: α = {alpha}");
    let one = alpha_shape(&points, &AlphaShapeConfig::thesis()).unwrap();
    assert_eq!(one.num_components, 1);
    assert_eq!(one.alpha, alpha);
    let smaller = alpha_shape(&points, &AlphaShapeConfig::with_radius(0.9 * alpha)).unwrap();
    assert!(smaller.num_components >= 2, "{} components", smaller.num_components);
    assert_eq!(smaller.polygons.len(), smaller.num_components);
    assert!(smaller.polygons.windows(2).all(|w| w[0].area() >= w[1].area()), "largest first");
    let two = alpha_shape(
        &points,
        &AlphaShapeConfig {
            alpha: AlphaChoice::Optimal { max_components: 2 },
            components: ComponentPolicy::All,
            ..AlphaShapeConfig::thesis()
        },
    )
    .unwrap();
    assert_eq!(two.num_components, 2);
    assert!(two.alpha < 0.1);
    // Each 1 m² square; at this smaller α (≈ 0.75 spacings) the jitter costs a boundary strip
    // of ~2 cm (see the L test), so the areas are ~0.91–0.94 m².
    for p in &two.polygons {
        assert!((0.85..=1.0).contains(&p.area()), "area {}", p.area());
    }
    let largest = alpha_shape(
        &points,
        &AlphaShapeConfig {
            alpha: AlphaChoice::Radius(0.9 * alpha),
            components: ComponentPolicy::Largest,
            holes: HoleFilter::KeepAll,
            max_alpha: None,
        },
    )
    .unwrap();
    assert_eq!(largest.polygons.len(), 1);
}

#[test]
fn alpha_shapes_of_random_points_are_valid_and_keep_the_complex_area() {
    // Random points give pinches (vertices with ≥ 4 boundary edges) at small α: every
    // component must still become a valid polygon with all its holes.
    for seed in 0..40 {
        let mut rng = Rng(seed);
        let points: Vec<Point2> =
            (0..300).map(|_| Point2::new(rng.unit() * 5.0, rng.unit() * 5.0)).collect();
        for alpha in [0.25, 0.35, 0.5, 0.8] {
            let shape = alpha_shape(&points, &AlphaShapeConfig::with_radius(alpha)).unwrap();
            assert_eq!(shape.dropped_holes, 0, "seed {seed} α {alpha}");
            let total: Real = shape.polygons.iter().map(Polygon::area).sum();
            assert!(
                (total - shape.interior_area).abs() < 1e-4 * shape.interior_area.max(1.0),
                "seed {seed} α {alpha}: {total} vs {}",
                shape.interior_area
            );
        }
    }
}

#[test]
fn a_hole_touching_the_outer_ring_at_a_pinch_vertex_stays_a_valid_hole() {
    // A square frame of grid points (width 1, around a 4 × 4 hole) missing the point (3, 0):
    // the right-angled triangle (3,-1), (3,1), (2,0) has circumradius 1 > α, so (2, 0) has four
    // boundary edges: the outer ring and the hole touch there.
    let mut points = Vec::new();
    for x in -3..=3i32 {
        for y in -3..=3i32 {
            if x.abs().max(y.abs()) >= 2 && (x, y) != (3, 0) {
                points.push(Point2::new(x as Real, y as Real));
            }
        }
    }
    let shape = alpha_shape(&points, &AlphaShapeConfig::with_radius(0.8)).unwrap();
    assert_eq!(shape.num_components, 1);
    assert_eq!(shape.dropped_holes, 0);
    let polygon = &shape.polygons[0];
    assert_eq!(polygon.holes().len(), 1);
    // 6 × 6 minus the notch triangle (1) minus the hole: 4 × 4 with its corners cut by the
    // interior right triangles such as (1,2), (2,1), (2,2) (4 × ½).
    assert!((polygon.area() - 21.0).abs() < 1e-4, "area {}", polygon.area());
    assert!((polygon.holes()[0].signed_area() + 14.0).abs() < 1e-4);
    assert!((polygon.area() - shape.interior_area).abs() < 1e-4);
}

#[test]
fn degenerate_point_sets_are_typed_errors() {
    let p = |x, y| Point2::new(x, y);
    let thesis = AlphaShapeConfig::thesis();
    assert_eq!(
        alpha_shape(&[p(0.0, 0.0), p(1.0, 0.0)], &thesis),
        Err(AlphaShapeError::TooFewPoints { count: 2 })
    );
    assert_eq!(
        alpha_shape(&[p(0.0, 0.0), p(1.0, 0.0), p(1.0, 0.0), p(0.0, 0.0)], &thesis),
        Err(AlphaShapeError::TooFewDistinctPoints { distinct: 2 })
    );
    let line: Vec<Point2> = (0..10).map(|i| p(i as Real, 2.0 * i as Real)).collect();
    assert_eq!(alpha_shape(&line, &thesis), Err(AlphaShapeError::Collinear));
    assert_eq!(
        alpha_shape(&[p(0.0, 0.0), p(1.0, 0.0), p(Real::NAN, 1.0)], &thesis),
        Err(AlphaShapeError::BadCoordinate { index: 2 })
    );
    let tri = [p(0.0, 0.0), p(1.0, 0.0), p(0.0, 1.0)];
    assert!(matches!(
        alpha_shape(&tri, &AlphaShapeConfig::with_radius(-1.0)),
        Err(AlphaShapeError::InvalidAlpha { .. })
    ));
    assert!(matches!(
        alpha_shape(&tri, &AlphaShapeConfig::with_radius(0.1)),
        Err(AlphaShapeError::Empty { .. })
    ));
    let with_duplicates = [p(0.0, 0.0), p(1.0, 0.0), p(0.0, 1.0), p(1.0, 0.0)];
    let shape = alpha_shape(&with_duplicates, &thesis).unwrap();
    assert_eq!(shape.num_distinct_points, 3, "exact duplicates are merged");
    assert!((shape.polygons[0].area() - 0.5).abs() < 1e-12);
    assert_eq!(convex_hull(&line), Err(HullError::Degenerate));
    assert_eq!(convex_hull(&tri[..2]), Err(HullError::TooFewPoints { count: 2 }));
}

fn point_strategy() -> impl Strategy<Value = Point2> {
    (-100.0..100.0f64, -100.0..100.0f64).prop_map(|(x, y)| Point2::new(x, y))
}

proptest! {
    #[test]
    fn hull_contains_all_points_and_is_convex(
        points in proptest::collection::vec(point_strategy(), 3..80)
    ) {
        let hull = match convex_hull(&points) {
            Err(HullError::Degenerate) => return Ok(()),
            other => other.unwrap(),
        };
        let n = hull.len();
        for i in 0..n {
            let (a, b, c) = (hull[i], hull[(i + 1) % n], hull[(i + 2) % n]);
            prop_assert!((b - a).perp(&(c - b)) > 0.0, "strictly convex, counter-clockwise");
        }
        let polygon = Polygon::new(hull, Vec::new()).unwrap();
        for p in &points {
            prop_assert!(polygon.contains(p));
        }
    }
}

/// A rectangle outline with `n` vertices along its boundary, jittered by ±`noise`, starting
/// mid-way along the bottom edge.
fn noisy_rectangle(w: Real, h: Real, n: usize, noise: Real, seed: u64) -> Vec<Point2> {
    let mut rng = Rng(seed);
    let perimeter = 2.0 * (w + h);
    (0..n)
        .map(|i| {
            let s = (i as Real / n as Real * perimeter + 0.5 * w) % perimeter;
            let p = if s < w {
                Point2::new(s, 0.0)
            } else if s < w + h {
                Point2::new(w, s - w)
            } else if s < 2.0 * w + h {
                Point2::new(w - (s - w - h), h)
            } else {
                Point2::new(0.0, h - (s - 2.0 * w - h))
            };
            p + na::Vector2::new(rng.unit(), rng.unit()) * noise
        })
        .collect()
}

#[test]
fn douglas_peucker_keeps_the_ends_and_reduces_a_noisy_rectangle() {
    let ring = noisy_rectangle(4.0, 2.0, 141, 0.005, 5);
    let simplified = douglas_peucker_ring(&ring, 0.02);
    assert_eq!(simplified.first(), ring.first(), "first vertex kept");
    assert_eq!(simplified.last(), ring.last(), "last vertex kept");
    // About 2 per corner (no sample hits a corner exactly) + the first and last vertices.
    assert!((5..=10).contains(&simplified.len()), "{} vertices", simplified.len());
    let polygon = Polygon::new(ring, Vec::new()).unwrap();
    let valid = simplify_polygon_valid(&polygon, 0.02).unwrap();
    assert_eq!(valid.vertices_before, 141);
    assert!(valid.vertices_after <= 10, "{} vertices", valid.vertices_after);
    assert_eq!(valid.epsilon, 0.02);
    assert!(rel(valid.polygon.area(), 8.0) < 0.01);
    assert_eq!(simplify_polygon(&polygon, 0.0).unwrap(), polygon, "ε = 0 keeps everything");
    assert!(matches!(simplify_polygon(&polygon, -1.0), Err(SimplifyError::InvalidEpsilon { .. })));
}

#[test]
fn validity_preserving_simplification_falls_back_to_a_smaller_epsilon() {
    // A 10 × 4 rectangle with a 0.5 m bump on top holding a hole: plain DP with ε = 1 flattens
    // the bump and leaves the hole outside.
    let p = |x, y| Point2::new(x, y);
    let outer = vec![
        p(5.0, 0.0),
        p(10.0, 0.0),
        p(10.0, 4.0),
        p(6.0, 4.0),
        p(5.5, 4.5),
        p(4.5, 4.5),
        p(4.0, 4.0),
        p(0.0, 4.0),
        p(0.0, 0.0),
    ];
    let hole = vec![p(4.8, 4.1), p(4.8, 4.3), p(5.2, 4.3), p(5.2, 4.1)];
    let polygon = Polygon::new(outer, vec![hole]).unwrap();
    assert!(matches!(simplify_polygon(&polygon, 1.0), Err(SimplifyError::Invalid(_))));
    let valid = simplify_polygon_valid(&polygon, 1.0).unwrap();
    assert!(valid.epsilon < 0.5 && valid.epsilon > 0.0, "ε used {}", valid.epsilon);
    assert_eq!(valid.polygon.holes().len(), 1);
}

/// A cloud and region of points exactly on a tilted plane in front of the sensor (origin).
fn points_on_plane() -> (PointCloud, PlanarRegion) {
    let normal = na::Unit::new_normalize(Vector3::new(-0.3, 0.2, -1.0));
    let origin = Point3::new(0.4, -0.2, 3.0);
    let plane = Plane { normal, offset: normal.dot(&origin.coords) };
    let u = normal.cross(&Vector3::x()).normalize();
    let v = normal.cross(&u);
    let mut positions = Vec::new();
    for i in 0..20 {
        for j in 0..15 {
            positions.push(origin + u * (i as Real * 0.1 - 1.0) + v * (j as Real * 0.1 - 0.7));
        }
    }
    let centroid =
        Point3::from(positions.iter().map(|p| p.coords).sum::<Vector3>() / positions.len() as Real);
    let cloud = PointCloud::from_positions(positions).unwrap();
    let region = PlanarRegion {
        points: (0..cloud.len() as u32).collect(),
        plane,
        centroid,
        mse: 0.0,
        covariance: None,
    };
    (cloud, region)
}

#[test]
fn beam_and_orthogonal_projection_agree_on_the_plane() {
    let (cloud, region) = points_on_plane();
    let ortho = project_region(&cloud, &region, &ProjectionConfig::thesis()).unwrap();
    let beam = project_region(&cloud, &region, &ProjectionConfig::early_along_beam()).unwrap();
    assert_eq!(beam.dropped, 0);
    assert_eq!(ortho.indices, beam.indices);
    for (a, b) in ortho.points.iter().zip(&beam.points) {
        assert!((a - b).norm() < 1e-9);
    }
    // Off the plane the two differ: a point 10 cm in front of the plane slides along its ray.
    let frame = plane_frame(&region.plane, &region.centroid);
    let lifted: Vec<Point3> =
        cloud.positions().iter().map(|p| p + region.plane.normal.into_inner() * 0.1).collect();
    let lifted = PointCloud::from_positions(lifted).unwrap();
    let o =
        project_indices(&lifted, &region.plane, &frame, &[0], &ProjectionConfig::thesis()).unwrap();
    let b = project_indices(
        &lifted,
        &region.plane,
        &frame,
        &[0],
        &ProjectionConfig::early_along_beam(),
    )
    .unwrap();
    assert!((o.points[0] - b.points[0]).norm() > 1e-3);
    // The frame's origin is the centroid (on the plane), so the projected points average to 0.
    let mean = ortho.points.iter().map(|p| p.coords).sum::<na::Vector2<Real>>()
        / ortho.points.len() as Real;
    assert!(mean.norm() < 1e-9);
}

#[test]
fn grazing_beams_are_dropped_or_refused() {
    // The plane z = 1 seen through points almost in the sensor's xy-plane.
    let normal = na::Unit::new_normalize(Vector3::new(0.0, 0.0, -1.0));
    let plane = Plane { normal, offset: -1.0 };
    let cloud = PointCloud::from_positions(vec![
        Point3::new(0.0, 0.0, 1.0),
        Point3::new(100.0, 0.0, 1.0), // cos ≈ 0.01: grazing
        Point3::new(1.0, 0.0, -1.0),  // the ray meets z = 1 behind the sensor
    ])
    .unwrap();
    let frame = plane_frame(&plane, &Point3::new(0.0, 0.0, 1.0));
    let drop = ProjectionConfig::early_along_beam();
    let projected = project_indices(&cloud, &plane, &frame, &[0, 1, 2], &drop).unwrap();
    assert_eq!(projected.indices, vec![0]);
    assert_eq!(projected.dropped, 2);
    let strict = ProjectionConfig { grazing: GrazingPolicy::Error, ..drop };
    assert!(matches!(
        project_indices(&cloud, &plane, &frame, &[1], &strict),
        Err(ProjectionError::GrazingBeam { index: 1, .. })
    ));
    assert_eq!(
        project_indices(&cloud, &plane, &frame, &[2], &strict),
        Err(ProjectionError::PlaneBehindSensor { index: 2 })
    );
    assert_eq!(
        project_indices(&cloud, &plane, &frame, &[7], &strict),
        Err(ProjectionError::IndexOutOfRange { index: 7, len: 3 })
    );
}

#[test]
fn alrf_side_columns_are_invalidated_except_the_centre_pixel() {
    use std::f64::consts::FRAC_PI_4;
    let model = ActuatedLrfModel {
        beam_start: -3.0 * FRAC_PI_4,
        beam_end: 3.0 * FRAC_PI_4,
        pitch_top: 0.5,
        pitch_bottom: -0.5,
    };
    // 7 columns: -135°, -90°, -45°, 0°, 45°, 90°, 135°; 5 rows, pitch 0 in row 2.
    let image = RangeImage::new(
        7,
        5,
        BeamModel::ActuatedLrf(model),
        RangeKind::Radial,
        vec![Some(2.0); 35],
    )
    .unwrap();
    let cloud = image.to_cloud().unwrap();
    let (fixed, removed) =
        invalidate_alrf_side_columns(&cloud, &model, &AlrfSideColumns::thesis()).unwrap();
    assert_eq!(removed, 8);
    assert_eq!(fixed.len(), 27);
    let grid = fixed.grid().unwrap();
    for row in 0..5 {
        assert_eq!(grid.point_index(1, row).is_some(), row == 2);
        assert_eq!(grid.point_index(5, row).is_some(), row == 2);
        assert!(grid.point_index(0, row).is_some() && grid.point_index(3, row).is_some());
    }
    let all = AlrfSideColumns { tolerance: None, keep_centre_pixel: false };
    assert_eq!(invalidate_alrf_side_columns(&cloud, &model, &all).unwrap().1, 10);
    let unorganised = PointCloud::from_positions(cloud.positions().to_vec()).unwrap();
    assert_eq!(
        invalidate_alrf_side_columns(&unorganised, &model, &all).unwrap_err(),
        ProjectionError::NotOrganised
    );
}

/// Orthogonal least squares: centroid and the eigenvector of the smallest eigenvalue, the
/// normal turned toward the sensor origin.
fn fit_region(cloud: &PointCloud, points: Vec<u32>) -> PlanarRegion {
    let pos = cloud.positions();
    let n = points.len() as Real;
    let centroid =
        Point3::from(points.iter().map(|&i| pos[i as usize].coords).sum::<Vector3>() / n);
    let mut scatter = na::Matrix3::<Real>::zeros();
    for &i in &points {
        let d = pos[i as usize] - centroid;
        scatter += d * d.transpose();
    }
    let eigen = na::SymmetricEigen::new(scatter);
    let k = eigen.eigenvalues.imin();
    let mut normal: Vector3 = eigen.eigenvectors.column(k).into_owned();
    if normal.dot(&centroid.coords) > 0.0 {
        normal = -normal;
    }
    let normal = na::Unit::new_normalize(normal);
    PlanarRegion {
        points,
        plane: Plane { normal, offset: normal.dot(&centroid.coords) },
        centroid,
        mse: eigen.eigenvalues[k] / n,
        covariance: None,
    }
}

/// A range-camera scan of a 2 m × 1.5 m wall with a 0.5 m × 0.5 m window, 3 m in front of the
/// camera, and the region of the wall's points (by surface label).
fn scanned_wall(config: RangeCameraConfig, distance: Real) -> (PointCloud, PlanarRegion) {
    let x = Vector3::new(0.0, -1.0, 0.0);
    let y = Vector3::new(0.0, 0.0, 1.0);
    let rotation =
        na::UnitQuaternion::from_rotation_matrix(&na::Rotation3::from_basis_unchecked(&[
            x,
            y,
            x.cross(&y),
        ]));
    let world_from_wall =
        Isometry3::from_parts(na::Translation3::new(distance, 1.0, 0.25), rotation);
    let wall = PlanarPolygon::rectangle(
        world_from_wall,
        Point2::new(0.0, 0.0),
        Point2::new(2.0, 1.5),
        &[(Point2::new(0.75, 0.5), Point2::new(1.25, 1.0))],
    )
    .unwrap();
    let mut builder = SceneBuilder::new("wall");
    let id = builder.add("wall", wall, Material::WHITE_MASONRY).unwrap();
    let scene = builder.build().unwrap();
    let label = scene.primitive(id).unwrap().first_surface.0;
    let camera = RangeCamera::new(config).unwrap();
    let pose = camera_pose_looking(Point3::new(0.0, 0.0, 1.0), 0.0, 0.0);
    let cloud = camera.scan(&scene, &pose, 7).to_cloud().unwrap();
    let points: Vec<u32> = cloud
        .labels()
        .unwrap()
        .iter()
        .enumerate()
        .filter(|&(_, &l)| l == label)
        .map(|(i, _)| i as u32)
        .collect();
    let region = fit_region(&cloud, points);
    (cloud, region)
}

#[test]
fn region_to_patch_of_a_scanned_wall_has_the_visible_area() {
    let (cloud, mut region) = scanned_wall(RangeCameraConfig::swissranger_sr3000(), 3.0);
    assert!(region.points.len() > 5000, "{} wall points", region.points.len());
    let covariance = PlaneCovariance::new(na::Matrix4::identity() * 1e-6).unwrap();
    region.covariance = Some(covariance);
    let out = polygonize_region(&cloud, &region, &PolygonizeConfig::thesis()).unwrap();
    assert_eq!(out.patches.len(), 1);
    let patch = &out.patches[0];
    let truth = 2.0 * 1.5 - 0.25;
    assert!(rel(patch.area(), truth) < 0.10, "area {} vs {truth}", patch.area());
    assert_eq!(patch.polygon().holes().len(), 1, "the window stays a hole");
    assert!(out.vertices_after < out.vertices_before / 5, "{out:?}");
    assert_eq!(patch.covariance(), Some(&covariance));
    // The patch lies in the fitted plane, normal toward the camera.
    assert!((patch.normal().dot(&region.plane.normal) - 1.0).abs() < 1e-9);
    assert!((patch.offset() - region.plane.offset).abs() < 1e-9);
    assert!(triangle_count(patch).unwrap() >= patch.polygon().num_vertices() - 2);
    // The hull covers the window too.
    let hull = region_to_patch(&cloud, &region, &PolygonizeConfig::convex_hull()).unwrap();
    assert!(rel(hull[0].area(), 3.0) < 0.10, "hull area {}", hull[0].area());
}

/// Thinning on the pixel grid keeps a band along the wall's outline and around its window,
/// and a sparse lattice inside: the outline is the thesis's up to a few per mille of area,
/// the window stays a hole, and the α-shape sees a fraction of the points.
#[test]
fn thinned_outline_of_a_scanned_wall_matches_the_thesis() {
    let config =
        RangeCameraConfig { width: 352, height: 288, ..RangeCameraConfig::swissranger_sr3000() };
    let (cloud, region) = scanned_wall(config, 3.0);
    let thesis = polygonize_region(&cloud, &region, &PolygonizeConfig::thesis()).unwrap();
    let thinned = polygonize_region(&cloud, &region, &PolygonizeConfig::thinned()).unwrap();
    let (a, b) = (&thesis.patches[0], &thinned.patches[0]);
    assert!(rel(b.area(), a.area()) < 0.005, "area {} vs {}", b.area(), a.area());
    assert_eq!(b.polygon().holes().len(), 1, "the window stays a hole");
    let alpha = (thesis.alpha.unwrap(), thinned.alpha.unwrap());
    assert!(rel(alpha.1, alpha.0) < 0.05, "α {alpha:?}");
    let grid = cloud.grid().unwrap();
    let (band, fill) = GridThinning::standard()
        .split(grid, &pixels_of_points(grid, cloud.len()), &region.points)
        .unwrap();
    assert!(band.len() + fill.len() < region.points.len() / 2, "{} + {}", band.len(), fill.len());
    assert!(band.iter().chain(&fill).all(|p| region.points.binary_search(p).is_ok()));
}

/// Without fill points the filled α-shape is the α-shape.
#[test]
fn alpha_shape_filled_without_fill_is_the_alpha_shape() {
    let points: Vec<Point2> = (0..400)
        .map(|k| {
            let (i, j) = ((k % 20) as Real, (k / 20) as Real);
            Point2::new(i + 0.3 * (j * 1.7).sin(), j + 0.3 * (i * 2.3).cos())
        })
        .collect();
    let config = AlphaShapeConfig::thesis();
    assert_eq!(alpha_shape_filled(&points, &[], &config), alpha_shape(&points, &config));
}

#[test]
fn region_to_patch_reports_degenerate_regions() {
    let (cloud, region) = points_on_plane();
    let tiny = PlanarRegion { points: vec![0, 1], ..region.clone() };
    assert_eq!(
        region_to_patch(&cloud, &tiny, &PolygonizeConfig::thesis()),
        Err(PolygonizeError::AlphaShape(AlphaShapeError::TooFewPoints { count: 2 }))
    );
    let line = PlanarRegion { points: (0..15).collect(), ..region.clone() };
    assert_eq!(
        region_to_patch(&cloud, &line, &PolygonizeConfig::thesis()),
        Err(PolygonizeError::AlphaShape(AlphaShapeError::Collinear))
    );
    let out_of_range = PlanarRegion { points: vec![0, 1, 10_000], ..region.clone() };
    assert!(matches!(
        region_to_patch(&cloud, &out_of_range, &PolygonizeConfig::thesis()),
        Err(PolygonizeError::Projection(ProjectionError::IndexOutOfRange { .. }))
    ));
    let mut late = PolygonizeConfig::thesis();
    late.projection = ProjectionConfig::late_orthogonal();
    assert_eq!(region_to_patch(&cloud, &region, &late), Err(PolygonizeError::LateProjection));
    // The grid of points on the plane gives its 1.9 m × 1.4 m rectangle: 4 corners plus the
    // ring's first and last vertices, which Douglas–Peucker keeps (thesis L5345–5351).
    let patches = region_to_patch(&cloud, &region, &PolygonizeConfig::thesis()).unwrap();
    assert!(rel(patches[0].area(), 1.9 * 1.4) < 1e-6, "area {}", patches[0].area());
    assert!(patches[0].polygon().num_vertices() <= 6);
}

/// Release measurement: `cargo test --release -p patch-extract --test it outline:: -- --ignored
/// --nocapture measure_region_to_patch`.
#[test]
#[ignore = "measurement; run in release with --nocapture"]
fn measure_region_to_patch() {
    let config =
        RangeCameraConfig { width: 200, height: 160, ..RangeCameraConfig::swissranger_sr3000() };
    let (cloud, region) = scanned_wall(config, 2.4);
    let runs = 20;
    let start = std::time::Instant::now();
    let mut out = None;
    for _ in 0..runs {
        out = Some(polygonize_region(&cloud, &region, &PolygonizeConfig::thesis()).unwrap());
    }
    let per_run = start.elapsed().as_secs_f64() / runs as Real;
    let out = out.unwrap();
    let hull_start = std::time::Instant::now();
    for _ in 0..runs {
        region_to_patch(&cloud, &region, &PolygonizeConfig::convex_hull()).unwrap();
    }
    let hull_per_run = hull_start.elapsed().as_secs_f64() / runs as Real;
    let stage = std::time::Instant::now();
    let projected = project_region(&cloud, &region, &ProjectionConfig::thesis()).unwrap();
    let projection_ms = stage.elapsed().as_secs_f64() * 1e3;
    let stage = std::time::Instant::now();
    optimal_alpha(&projected.points, 1).unwrap();
    let optimal_ms = stage.elapsed().as_secs_f64() * 1e3;
    let stage = std::time::Instant::now();
    let shape = alpha_shape(&projected.points, &AlphaShapeConfig::thesis()).unwrap();
    let alpha_ms = stage.elapsed().as_secs_f64() * 1e3;
    let stage = std::time::Instant::now();
    simplify_polygon_valid(&shape.polygons[0], 0.02).unwrap();
    let simplify_ms = stage.elapsed().as_secs_f64() * 1e3;
    println!(
        "stages (one run): projection {projection_ms:.2} ms | α-shape {alpha_ms:.2} ms (of which \
         Delaunay + optimal α {optimal_ms:.2} ms) | \
         DP {simplify_ms:.2} ms | filled sampling holes {}",
        shape.filled_holes
    );
    println!(
        "points {} | region_to_patch (thesis) {:.2} ms | hull {:.2} ms | α = {:.4} m | \
         vertices before DP {} after {} | area {:.4} m² | triangles {}",
        region.points.len(),
        per_run * 1e3,
        hull_per_run * 1e3,
        out.alpha.unwrap(),
        out.vertices_before,
        out.vertices_after,
        out.patches[0].area(),
        triangle_count(&out.patches[0]).unwrap(),
    );
}

/// A square of points and two stray points a metre away: the optimal α must reach them and
/// bridges the gap; the robust α leaves them out and keeps the square's own spacing.
#[test]
fn robust_alpha_leaves_stray_points_out() {
    let mut points = jittered_grid((0.0, 1.0), (0.0, 1.0), 0.05, 5, |_| true);
    let n = points.len();
    points.extend([Point2::new(2.0, 0.5), Point2::new(2.05, 0.55)]);
    let optimal = optimal_alpha(&points, 1).unwrap();
    assert!(optimal > 0.4, "the optimal α bridges the 1 m gap: {optimal}");
    let robust = alpha_shape(&points, &AlphaShapeConfig::robust()).unwrap();
    assert!(2.0 / points.len() as Real <= ROBUST_MAX_UNCOVERED, "{n} points");
    assert!(robust.alpha < 0.1, "α = {}", robust.alpha);
    assert_eq!(robust.polygons.len(), 1);
    let area = robust.polygons[0].area();
    assert!((0.85..=1.0).contains(&area), "the square alone: {area} m²");
    // Parameters out of range are typed errors.
    for (max_components, max_uncovered) in [(0, 0.02), (1, 1.0), (1, -0.1), (1, Real::NAN)] {
        let config = AlphaShapeConfig {
            alpha: AlphaChoice::Robust { max_components, max_uncovered },
            ..AlphaShapeConfig::robust()
        };
        assert!(
            matches!(alpha_shape(&points, &config), Err(AlphaShapeError::InvalidAlpha { .. })),
            "{max_components} {max_uncovered}"
        );
    }
}

/// A wall seen sparsely with a doorway and no lintel: the optimal α for one component bridges
/// the 0.9 m doorway (with triangles across it); an α of at most 0.2 m keeps it open, as two
/// polygons.
#[test]
fn a_limited_alpha_keeps_a_doorway_open() {
    let points = jittered_grid((0.0, 3.0), (0.0, 2.5), 0.12, 11, |p| !(1.0..1.9).contains(&p.x));
    let bridged = alpha_shape(&points, &AlphaShapeConfig::robust()).unwrap();
    assert!(bridged.alpha > 0.4, "α = {}", bridged.alpha);
    assert_eq!(bridged.polygons.len(), 1, "one polygon across the doorway");
    let open = alpha_shape(&points, &AlphaShapeConfig::robust_at_most(0.2)).unwrap();
    assert!(open.alpha <= 0.2 + 1e-12, "α = {}", open.alpha);
    assert_eq!(open.polygons.len(), 2);
    let area: Real = open.polygons.iter().map(Polygon::area).sum();
    assert!((4.5..5.3).contains(&area), "two wall parts: {area} m²");
    let bad = AlphaShapeConfig { max_alpha: Some(-1.0), ..AlphaShapeConfig::robust() };
    assert!(matches!(alpha_shape(&points, &bad), Err(AlphaShapeError::InvalidAlpha { .. })));
}
