use super::*;
use crate::CapsuleStep;

fn p3(x: Real, y: Real, z: Real) -> Point3 {
    Point3::new(x, y, z)
}

fn tilted() -> Isometry3 {
    Isometry3::new(Vector3::new(1.0, -2.0, 0.5), Vector3::new(0.3, -0.7, 1.1))
}

fn wall_points() -> Vec<Point3> {
    vec![p3(2.0, 0.0, 0.0), p3(2.0, 0.0, 2.0), p3(2.0, 3.0, 2.0), p3(2.0, 3.0, 0.0)]
}

#[test]
fn plane_is_derived_from_the_transform() {
    let patch =
        PlanarPatch::rectangle(tilted(), Point2::new(-1.0, -1.0), Point2::new(2.0, 1.0)).unwrap();
    let n = patch.normal();
    assert!((n.into_inner() - tilted().rotation * Vector3::z()).norm() < 1e-15);
    for p in patch.polygon().outer().points() {
        let w = patch.to_world(p);
        assert!(patch.plane().signed_distance(&w).abs() < 1e-14);
        let back = patch.to_local(&w);
        assert!((back.xy() - p).norm() < 1e-14 && back.z.abs() < 1e-14);
    }
    assert!((patch.offset() - n.dot(&tilted().translation.vector)).abs() < 1e-15);
    assert!((patch.area() - 6.0).abs() < 1e-14);
    let above = patch.to_world(&Point2::new(0.0, 0.0)) + n.into_inner() * 2.0;
    assert!((patch.plane().signed_distance(&above) - 2.0).abs() < 1e-14);
}

#[test]
fn from_world_polygon_fits_and_orients() {
    let wall = PlanarPatch::from_world_polygon(&wall_points(), &[], 1e-9).unwrap();
    assert!((wall.normal().into_inner() - Vector3::new(-1.0, 0.0, 0.0)).norm() < 1e-12);
    assert!((wall.offset() + 2.0).abs() < 1e-12);
    assert!((wall.area() - 6.0).abs() < 1e-12);
    // Origin at the centroid; x the world axis least aligned with the normal (y here, ties
    // between y and z go to y); frame right-handed.
    let iso = wall.world_from_patch();
    assert!((iso.translation.vector - Vector3::new(2.0, 1.5, 1.0)).norm() < 1e-12);
    let x = iso.rotation * Vector3::x();
    assert!((x - Vector3::y()).norm() < 1e-12);
    // Reversed ring: the normal flips.
    let mut rev = wall_points();
    rev.reverse();
    let wall2 = PlanarPatch::from_world_polygon(&rev, &[], 1e-9).unwrap();
    assert!((wall2.normal().into_inner() - Vector3::new(1.0, 0.0, 0.0)).norm() < 1e-12);
    let b = wall.bounds();
    assert!(
        (b.min - p3(2.0, 0.0, 0.0)).norm() < 1e-12 && (b.max - p3(2.0, 3.0, 2.0)).norm() < 1e-12
    );
}

#[test]
fn from_world_polygon_with_a_hole_and_errors() {
    let hole = vec![p3(2.0, 1.0, 0.5), p3(2.0, 2.0, 0.5), p3(2.0, 2.0, 1.5), p3(2.0, 1.0, 1.5)];
    let wall = PlanarPatch::from_world_polygon(&wall_points(), &[hole], 1e-9).unwrap();
    assert!((wall.area() - 5.0).abs() < 1e-12);
    let mut bent = wall_points();
    bent[2].x += 0.01;
    assert!(matches!(
        PlanarPatch::from_world_polygon(&bent, &[], 1e-3),
        Err(PatchError::NotPlanar { ring: RingId::Outer, .. })
    ));
    assert!(PlanarPatch::from_world_polygon(&bent, &[], 0.01).is_ok());
    assert!(matches!(
        PlanarPatch::from_world_polygon(&wall_points(), &[], -1.0),
        Err(PatchError::InvalidTolerance { .. })
    ));
    assert!(matches!(
        PlanarPatch::from_world_polygon(&wall_points()[..2], &[], 1e-9),
        Err(PatchError::TooFewVertices { count: 2, .. })
    ));
    let mut nan = wall_points();
    nan[1].y = Real::NAN;
    assert!(matches!(
        PlanarPatch::from_world_polygon(&nan, &[], 1e-9),
        Err(PatchError::NonFiniteVertex { vertex: 1, .. })
    ));
    let outside = vec![p3(2.0, 5.0, 0.5), p3(2.0, 6.0, 0.5), p3(2.0, 6.0, 1.5)];
    assert!(matches!(
        PlanarPatch::from_world_polygon(&wall_points(), &[outside], 1e-9),
        Err(PatchError::HoleOutside { hole: 0 })
    ));
    // Collinear points: zero area.
    let line = vec![p3(0.0, 0.0, 0.0), p3(1.0, 1.0, 1.0), p3(2.0, 2.0, 2.0)];
    assert!(PlanarPatch::from_world_polygon(&line, &[], 1e-9).is_err());
}

#[test]
fn transforms_are_validated() {
    let poly = Polygon::rectangle(Point2::new(0.0, 0.0), Point2::new(1.0, 1.0)).unwrap();
    let mut iso = Isometry3::identity();
    iso.translation.vector.x = Real::NAN;
    assert_eq!(PlanarPatch::new(poly.clone(), iso), Err(PatchError::InvalidTransform));
    let bad = Isometry3::from_parts(
        na::Translation3::identity(),
        na::UnitQuaternion::new_unchecked(na::Quaternion::new(2.0, 0.0, 0.0, 0.0)),
    );
    assert_eq!(PlanarPatch::new(poly.clone(), bad), Err(PatchError::InvalidTransform));
    let slightly = Isometry3::from_parts(
        na::Translation3::identity(),
        na::UnitQuaternion::new_unchecked(na::Quaternion::new(1.0 + 1e-9, 0.0, 0.0, 0.0)),
    );
    let p = PlanarPatch::new(poly, slightly).unwrap();
    assert!((p.world_from_patch().rotation.into_inner().norm() - 1.0).abs() < 1e-15);
}

#[test]
fn covariance_is_validated() {
    let mut m = na::Matrix4::<Real>::identity() * 0.01;
    m[(0, 3)] = 0.001;
    m[(3, 0)] = 0.001;
    let c = PlaneCovariance::new(m).unwrap();
    assert_eq!(c.matrix(), &m);
    let mut asym = m;
    asym[(3, 0)] = 0.002;
    assert_eq!(
        PlaneCovariance::new(asym),
        Err(PatchError::AsymmetricCovariance { row: 0, col: 3 })
    );
    let mut neg = m;
    neg[(2, 2)] = -1.0;
    assert_eq!(PlaneCovariance::new(neg), Err(PatchError::NegativeVariance { index: 2 }));
    let mut nan = m;
    nan[(1, 2)] = Real::NAN;
    assert_eq!(PlaneCovariance::new(nan), Err(PatchError::NonFiniteCovariance { row: 1, col: 2 }));
    let patch = PlanarPatch::rectangle(tilted(), Point2::new(0.0, 0.0), Point2::new(1.0, 1.0))
        .unwrap()
        .with_covariance(c);
    assert_eq!(patch.covariance(), Some(&c));
}

fn mesh() -> TrimeshPatch {
    TrimeshPatch::new(
        vec![p3(0.0, 0.0, 0.0), p3(1.0, 0.0, 0.0), p3(0.0, 1.0, 0.0), p3(1.0, 1.0, 1.0)],
        vec![[0, 1, 2], [1, 3, 2]],
    )
    .unwrap()
}

#[test]
fn trimesh_is_validated() {
    let m = mesh();
    assert_eq!(m.num_triangles(), 2);
    assert!((m.area() - (0.5 + 0.5 * 3.0f64.sqrt())).abs() < 1e-12);
    assert_eq!(m.bounds(), Aabb::new(p3(0.0, 0.0, 0.0), p3(1.0, 1.0, 1.0)));
    assert_eq!(TrimeshPatch::new(vec![p3(0.0, 0.0, 0.0)], vec![]), Err(PatchError::NoTriangles));
    assert_eq!(
        TrimeshPatch::new(vec![p3(0.0, 0.0, 0.0), p3(1.0, 0.0, 0.0)], vec![[0, 1, 2]]),
        Err(PatchError::IndexOutOfRange { triangle: 0, index: 2, num_vertices: 2 })
    );
    assert_eq!(
        TrimeshPatch::new(vec![p3(0.0, 0.0, Real::INFINITY)], vec![[0, 0, 0]]),
        Err(PatchError::NonFiniteMeshVertex { vertex: 0 })
    );
    let tiny = TrimeshPatch::new(
        vec![p3(0.0, 0.0, 0.0), p3(1e-6, 0.0, 0.0), p3(0.0, 1e-6, 0.0)],
        vec![[0, 1, 2]],
    );
    assert!(matches!(tiny, Err(PatchError::DegenerateTriangle { triangle: 0, .. })));
    let repeated = TrimeshPatch::new(vec![p3(0.0, 0.0, 0.0), p3(1.0, 0.0, 0.0)], vec![[0, 1, 1]]);
    assert!(matches!(repeated, Err(PatchError::DegenerateTriangle { .. })));
}

#[test]
fn patch_enum_dispatches() {
    let planar: Patch =
        PlanarPatch::rectangle(tilted(), Point2::new(0.0, 0.0), Point2::new(1.0, 1.0))
            .unwrap()
            .into();
    let trimesh: Patch = mesh().into();
    assert_eq!(planar.kind(), PatchKind::Planar);
    assert_eq!(trimesh.kind(), PatchKind::Trimesh);
    assert!(planar.as_planar().is_some() && planar.as_trimesh().is_none());
    assert!(trimesh.as_trimesh().is_some() && trimesh.as_planar().is_none());
    assert_eq!(planar.num_triangles_hint(), 2);
    assert_eq!(trimesh.num_triangles_hint(), 2);
    let holed = PlanarPatch::new(
        Polygon::new(
            vec![
                Point2::new(0.0, 0.0),
                Point2::new(4.0, 0.0),
                Point2::new(4.0, 4.0),
                Point2::new(0.0, 4.0),
            ],
            vec![vec![Point2::new(1.0, 1.0), Point2::new(2.0, 1.0), Point2::new(2.0, 2.0)]],
        )
        .unwrap(),
        Isometry3::identity(),
    )
    .unwrap();
    assert_eq!(Patch::from(holed).num_triangles_hint(), 7);
    assert_eq!(PatchKind::Trimesh.to_string(), "trimesh");
}

#[test]
fn planar_queries_match_the_local_kernels() {
    let patch =
        PlanarPatch::rectangle(tilted(), Point2::new(-1.0, -1.0), Point2::new(2.0, 1.0)).unwrap();
    let n = patch.normal().into_inner();
    let on = patch.to_world(&Point2::new(0.5, 0.25));
    let above = on + n * 0.75;
    let c = patch.closest_point(&above);
    assert!((c.distance - 0.75).abs() < 1e-14 && (c.point - on).norm() < 1e-14);
    // Falling onto the patch along -n with radius 0.25 from 2 m above.
    let start = on + n * 2.0;
    let end = on - n * 2.0;
    let contact = patch.first_contact(&start, &end, 0.25).unwrap();
    assert!((contact.t - 1.75 / 4.0).abs() < 1e-14);
    assert!((contact.normal.into_inner() - n).norm() < 1e-14);
    assert!((contact.point - on).norm() < 1e-14);
    let s = patch.segment_distance(&start, &end);
    assert!(s.distance < 1e-14 && (s.t - 0.5).abs() < 1e-14);
    let patch: Patch = patch.into();
    let step = CapsuleStep::new(start, end, 0.25).unwrap();
    assert!(patch.collides_with(&step));
    assert_eq!(patch.step_contact(&step).unwrap().t, contact.t);
}

#[test]
fn trimesh_queries_take_the_earliest_triangle() {
    let m = mesh();
    // Falling onto the flat triangle [0, 1, 2] at (0.25, 0.25).
    let c = m.first_contact(&p3(0.25, 0.25, 2.0), &p3(0.25, 0.25, -2.0), 0.0).unwrap();
    assert!((c.t - 0.5).abs() < 1e-15);
    assert!((c.normal.into_inner() - Vector3::z()).norm() < 1e-15);
    // Moving along +x at height 0.5 over y = 0.75: the sloped triangle is met first.
    let c = m.first_contact(&p3(-1.0, 0.75, 0.5), &p3(2.0, 0.75, 0.5), 0.0).unwrap();
    // Triangle [1, 3, 2] is the plane x + y − z = 1 over its footprint: at y = 0.75, z = 0.5:
    // x = 0.75.
    assert!((c.t - 1.75 / 3.0).abs() < 1e-12, "{c:?}");
    assert!(m.first_contact(&p3(-1.0, 0.75, 2.0), &p3(2.0, 0.75, 2.0), 0.1).is_none());
    assert!((m.closest_point(&p3(0.25, 0.25, -1.0)).distance - 1.0).abs() < 1e-15);
    assert_eq!(m.segment_distance(&p3(0.25, 0.25, 1.0), &p3(0.25, 0.25, -1.0)).distance, 0.0);
}

#[test]
fn serde_round_trips_and_revalidates() {
    let c = PlaneCovariance::new(na::Matrix4::identity() * 0.5).unwrap();
    let planar = PlanarPatch::rectangle(tilted(), Point2::new(-1.0, -1.0), Point2::new(2.0, 1.0))
        .unwrap()
        .with_covariance(c);
    let patches = vec![Patch::from(planar), Patch::from(mesh())];
    let json = serde_json::to_string(&patches).unwrap();
    let back: Vec<Patch> = serde_json::from_str(&json).unwrap();
    assert_eq!(back, patches);

    // A bow-tie polygon smuggled into a file.
    let bow = r#"{"planar":{"polygon":{"outer":[[0,0],[1,1],[1,0],[0,1]],"holes":[]},
        "world_from_patch":{"rotation":[0,0,0,1],"translation":[0,0,0]}}}"#;
    let err = serde_json::from_str::<Patch>(bow).unwrap_err().to_string();
    assert!(err.contains("meets edge"), "{err}");
    // A good polygon deserialises; a clockwise ring comes back counter-clockwise.
    let cw = r#"{"planar":{"polygon":{"outer":[[0,0],[0,1],[1,1],[1,0]]},
        "world_from_patch":{"rotation":[0,0,0,1],"translation":[0,0,0]}}}"#;
    let p: Patch = serde_json::from_str(cw).unwrap();
    assert!(p.as_planar().unwrap().polygon().outer().is_ccw());
    // A non-unit rotation.
    let rot = r#"{"planar":{"polygon":{"outer":[[0,0],[0,1],[1,1]]},
        "world_from_patch":{"rotation":[0,0,0,2],"translation":[0,0,0]}}}"#;
    assert!(serde_json::from_str::<Patch>(rot).is_err());
    // A bad covariance.
    let cov = r#"{"planar":{"polygon":{"outer":[[0,0],[0,1],[1,1]]},
        "world_from_patch":{"rotation":[0,0,0,1],"translation":[0,0,0]},
        "covariance":[1,0,0,0, 5,1,0,0, 0,0,1,0, 0,0,0,1]}}"#;
    assert!(serde_json::from_str::<Patch>(cov).is_err());
    // A mesh with an index out of range, and an empty one.
    let bad_mesh = r#"{"trimesh":{"vertices":[[0,0,0],[1,0,0],[0,1,0]],"triangles":[[0,1,3]]}}"#;
    assert!(serde_json::from_str::<Patch>(bad_mesh).is_err());
    let empty = r#"{"trimesh":{"vertices":[],"triangles":[]}}"#;
    assert!(serde_json::from_str::<Patch>(empty).is_err());
}

#[test]
fn rigid_motion_moves_geometry_and_covariance() {
    let motion = Isometry3::from_parts(
        na::Translation3::new(1.0, -2.0, 0.5),
        na::UnitQuaternion::from_euler_angles(0.3, -0.2, 1.1),
    );
    let cov = na::Matrix4::from_fn(|r, c| if r == c { 0.01 * (r + 1) as Real } else { 0.001 });
    let patch = PlanarPatch::rectangle(tilted(), Point2::new(0.2, 0.3), Point2::new(2.2, 1.3))
        .unwrap()
        .with_covariance(PlaneCovariance::new(cov).unwrap());
    let moved = patch.transformed(&motion);
    assert!((moved.area() - patch.area()).abs() < 1e-12);
    let q = Point3::new(0.7, 0.1, 3.0);
    let d0 = patch.closest_point(&q).distance;
    let d1 = moved.closest_point(&(motion * q)).distance;
    assert!((d0 - d1).abs() < 1e-12, "{d0} vs {d1}");
    // The plane parameters move linearly: (n + δn, d + δd) maps to (n', d') + J (δn, δd).
    let plane_of = |n: Vector3, d: Real| {
        let n2 = motion.rotation * n;
        (n2, d + n2.dot(&motion.translation.vector))
    };
    let (n, d) = (patch.normal().into_inner(), patch.offset());
    let (n1, d1) = plane_of(n, d);
    assert!(
        (moved.normal().into_inner() - n1).norm() < 1e-12 && (moved.offset() - d1).abs() < 1e-12
    );
    let j = {
        let r = motion.rotation.to_rotation_matrix().into_inner();
        let t = r.transpose() * motion.translation.vector;
        let mut j = na::Matrix4::<Real>::zeros();
        j.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
        j[(3, 0)] = t.x;
        j[(3, 1)] = t.y;
        j[(3, 2)] = t.z;
        j[(3, 3)] = 1.0;
        j
    };
    let delta = na::Vector4::new(1e-3, -2e-3, 0.5e-3, 0.01);
    let (n2, d2) = plane_of(n + delta.fixed_rows::<3>(0), d + delta[3]);
    let lin = j * delta;
    assert!((n2 - n1 - lin.fixed_rows::<3>(0)).norm() < 1e-12 && (d2 - d1 - lin[3]).abs() < 1e-12);
    let expected = j * cov * j.transpose();
    assert!((moved.covariance().unwrap().matrix() - expected).norm() < 1e-12);
    // A mesh keeps its triangles and moves its vertices.
    let m = mesh();
    let mm = Patch::from(m.clone()).transformed(&motion);
    let mm = mm.as_trimesh().unwrap();
    assert_eq!(mm.triangles(), m.triangles());
    assert!(mm.vertices().iter().zip(m.vertices()).all(|(a, b)| (a - motion * b).norm() < 1e-12));
}
