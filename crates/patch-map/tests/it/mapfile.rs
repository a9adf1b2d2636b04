//! Map files of the backends ([`MapFile`], [`load_any`]): random maps survive a round trip with
//! identical query answers; corrupt, truncated, future-version, wrong-backend and invalid files
//! give typed errors.

use patch_core::conformance::SceneKind;
use patch_core::conformance::strategies::{capsule_step, point3, scene, step_bounds};
use patch_core::{
    CapsuleStep, FromPatches, Isometry3, LineStep, Patch, PatchMap, PlanarPatch, Point2, Point3,
    ProximityQuery, Real, SpecificStepIntersector, TrimeshPatch, UnspecificStepIntersector,
};
use patch_map::mapfile::{FORMAT_VERSION, MapCounts, MapFileError, read_header, write_map};
use patch_map::{
    AnyMap, BBox6dMap, Backend, MapFile, MemoryUsage, PointCloudMap, PolygonMap, load_any,
};
use proptest::prelude::*;

fn save<M: MapFile>(map: &M) -> Vec<u8> {
    let mut buf = Vec::new();
    let n = map.save(&mut buf).unwrap();
    assert_eq!(n as usize, buf.len());
    buf
}

/// A small hybrid scene: a floor with a hole, a wall, a two-triangle mesh.
fn small_scene() -> Vec<Patch> {
    let square = |a: Real, b: Real| {
        vec![Point2::new(a, a), Point2::new(b, a), Point2::new(b, b), Point2::new(a, b)]
    };
    let floor = PlanarPatch::new(
        patch_core::Polygon::new(square(0.0, 4.0), vec![square(1.0, 2.0)]).unwrap(),
        Isometry3::identity(),
    )
    .unwrap();
    let wall = PlanarPatch::from_world_polygon(
        &[
            Point3::new(4.0, 0.0, 0.0),
            Point3::new(4.0, 0.0, 2.0),
            Point3::new(4.0, 4.0, 2.0),
            Point3::new(4.0, 4.0, 0.0),
        ],
        &[],
        1e-9,
    )
    .unwrap();
    let mesh = TrimeshPatch::new(
        vec![
            Point3::new(0.0, 0.0, 3.0),
            Point3::new(2.0, 0.0, 3.5),
            Point3::new(2.0, 2.0, 3.0),
            Point3::new(0.0, 2.0, 3.5),
        ],
        vec![[0, 1, 2], [0, 2, 3]],
    )
    .unwrap();
    vec![floor.into(), wall.into(), mesh.into()]
}

fn small_cloud() -> PointCloudMap {
    let points: Vec<Point3> = (0..500)
        .map(|i| {
            Point3::new((i % 20) as Real * 0.1, (i / 20) as Real * 0.1, 0.25 * (i % 3) as Real)
        })
        .collect();
    PointCloudMap::from_points(&points).unwrap()
}

/// Every kind of map, saved.
fn files() -> Vec<(&'static str, Vec<u8>)> {
    vec![
        ("polygon", save(&PolygonMap::from_patches(small_scene()).unwrap())),
        ("bbox6d", save(&BBox6dMap::from_patches(small_scene()).unwrap())),
        ("pointcloud", save(&small_cloud())),
    ]
}

fn load_as(tag: &str, bytes: &[u8]) -> Result<(), MapFileError> {
    match tag {
        "polygon" => PolygonMap::load(bytes).map(drop),
        "bbox6d" => BBox6dMap::load(bytes).map(drop),
        "pointcloud" => PointCloudMap::load(bytes).map(drop),
        _ => unreachable!(),
    }
}

/// The patch maps answer every query the same way.
fn same_answers<A, B>(a: &A, b: &B, steps: &[CapsuleStep], points: &[Point3]) -> bool
where
    A: ProximityQuery + SpecificStepIntersector + SpecificStepIntersector<LineStep>,
    B: ProximityQuery + SpecificStepIntersector + SpecificStepIntersector<LineStep>,
{
    steps.iter().all(|s| {
        a.first_hit(s) == b.first_hit(s)
            && a.is_step_free(s) == b.is_step_free(s)
            && a.first_hit(&s.line()) == b.first_hit(&s.line())
    }) && points.iter().all(|p| {
        a.closest_patch(p, Real::INFINITY) == b.closest_patch(p, Real::INFINITY)
            && a.closest_patch(p, 0.5) == b.closest_patch(p, 0.5)
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn patch_maps_round_trip(
        patches in scene(SceneKind::Mixed, 0..=10),
        steps in prop::collection::vec(capsule_step(step_bounds()), 1..16),
        points in prop::collection::vec(point3(step_bounds()), 1..8),
    ) {
        let polygon = PolygonMap::from_patches(patches.clone()).unwrap();
        let bytes = save(&polygon);
        let header = read_header(&bytes[..]).unwrap();
        prop_assert_eq!(header.backend.as_str(), "polygon");
        prop_assert_eq!(header.counts, polygon.counts());
        let back = PolygonMap::load(&bytes[..]).unwrap();
        prop_assert!(back.patches() == patches.as_slice());
        prop_assert_eq!(back.bounds(), polygon.bounds());
        prop_assert!(same_answers(&polygon, &back, &steps, &points));

        let bbox = BBox6dMap::from_patches(patches.clone()).unwrap();
        let bytes = save(&bbox);
        let back = BBox6dMap::load(&bytes[..]).unwrap();
        prop_assert!(back.patches() == patches.as_slice());
        prop_assert_eq!(back.counts(), bbox.counts());
        prop_assert!(same_answers(&bbox, &back, &steps, &points));

        // Through `load_any`, by tag.
        match load_any(&bytes[..]).unwrap() {
            AnyMap::BBox6d(any) => prop_assert!(same_answers(&bbox, &any, &steps, &points)),
            other => prop_assert!(false, "loaded a {} map", other.backend()),
        }
    }

    #[test]
    fn point_cloud_maps_round_trip(
        points in prop::collection::vec(point3(step_bounds()), 0..300),
        steps in prop::collection::vec(capsule_step(step_bounds()), 1..16),
    ) {
        let map = PointCloudMap::from_points(&points).unwrap();
        let bytes = save(&map);
        prop_assert_eq!(read_header(&bytes[..]).unwrap().counts.points, points.len() as u64);
        let back = PointCloudMap::load(&bytes[..]).unwrap();
        prop_assert_eq!(back.len(), map.len());
        prop_assert_eq!(back.bounds(), map.bounds());
        let sorted = |m: &PointCloudMap| {
            let mut v: Vec<[Real; 3]> = m.points().map(|p| [p.x, p.y, p.z]).collect();
            v.sort_by(|a, b| a.partial_cmp(b).unwrap());
            v
        };
        prop_assert_eq!(sorted(&back), sorted(&map));
        for s in &steps {
            prop_assert_eq!(back.is_step_free(s), map.is_step_free(s));
            prop_assert_eq!(back.is_step_free(&s.line()), map.is_step_free(&s.line()));
        }
        let any = load_any(&bytes[..]).unwrap();
        prop_assert_eq!(any.backend(), Backend::PointCloud);
        prop_assert!(any.patches().is_none());
        for s in &steps {
            prop_assert_eq!(any.is_step_free(s), map.is_step_free(s));
        }
    }
}

#[test]
fn load_any_dispatches_on_the_tag() {
    for (tag, bytes) in files() {
        let any = load_any(&bytes[..]).unwrap();
        assert_eq!(any.backend().name(), tag);
        assert_eq!(any.counts(), read_header(&bytes[..]).unwrap().counts);
        assert!(any.memory_bytes() > 0);
        // Saving the loaded map gives the same file (the payload does not depend on indices).
        let mut again = Vec::new();
        any.save(&mut again).unwrap();
        assert_eq!(again, bytes, "{tag}");
    }
    let counts = PolygonMap::from_patches(small_scene()).unwrap().counts();
    assert_eq!(
        counts,
        MapCounts { planar_patches: 2, trimesh_patches: 1, triangles: 2, points: 0 }
    );
}

#[test]
fn every_prefix_is_a_typed_error() {
    for (tag, bytes) in files() {
        for cut in 0..bytes.len() {
            let err = load_as(tag, &bytes[..cut]).unwrap_err();
            assert!(
                matches!(err, MapFileError::BadMagic { .. } | MapFileError::Truncated { .. }),
                "{tag}, {cut} bytes: {err}"
            );
            let err = load_any(&bytes[..cut]).unwrap_err();
            assert!(
                matches!(err, MapFileError::BadMagic { .. } | MapFileError::Truncated { .. }),
                "load_any, {tag}, {cut} bytes: {err}"
            );
        }
    }
}

#[test]
fn flipped_bits_are_typed_errors() {
    for (tag, bytes) in files() {
        // Every byte of the header and a spread of payload bytes, one bit each.
        let positions = (0..bytes.len()).filter(|&i| i < 80 || i % 7 == 0);
        for i in positions {
            let mut b = bytes.clone();
            b[i] ^= 1 << (i % 8);
            let err = load_as(tag, &b).unwrap_err();
            assert!(
                matches!(
                    err,
                    MapFileError::BadMagic { .. }
                        | MapFileError::UnsupportedVersion { .. }
                        | MapFileError::HeaderChecksum
                        | MapFileError::PayloadChecksum { .. }
                ),
                "{tag}, byte {i}: {err}"
            );
        }
        let mut b = bytes.clone();
        b.extend_from_slice(b"junk");
        assert!(matches!(load_as(tag, &b), Err(MapFileError::TrailingBytes(4))));
    }
}

#[test]
fn a_future_version_is_refused_not_misread() {
    for (tag, bytes) in files() {
        let mut b = bytes.clone();
        b[8..12].copy_from_slice(&(FORMAT_VERSION + 1).to_le_bytes());
        let expected = FORMAT_VERSION + 1;
        for err in [load_as(tag, &b).unwrap_err(), load_any(&b[..]).unwrap_err()] {
            assert!(
                matches!(
                    err,
                    MapFileError::UnsupportedVersion { found, supported }
                        if found == expected && supported == FORMAT_VERSION
                ),
                "{tag}: {err}"
            );
        }
    }
}

#[test]
fn a_wrong_backend_is_a_mismatch() {
    for (tag, bytes) in files() {
        for other in ["polygon", "bbox6d", "pointcloud"].into_iter().filter(|&o| o != tag) {
            match load_as(other, &bytes) {
                Err(MapFileError::BackendMismatch { expected, found }) => {
                    assert_eq!((expected.as_str(), found.as_str()), (other, tag));
                }
                r => panic!("{tag} file loaded as {other}: {r:?}"),
            }
        }
    }
}

#[test]
fn an_unknown_backend_is_named() {
    let mut buf = Vec::new();
    write_map(&mut buf, "octree", MapCounts::default(), &Vec::<Patch>::new()).unwrap();
    match load_any(&buf[..]) {
        Err(MapFileError::UnknownBackend { found }) => assert_eq!(found, "octree"),
        r => panic!("{r:?}"),
    }
}

/// Payloads that pass the checksums but hold invalid data are decode errors: validation runs
/// on load.
#[test]
fn invalid_payloads_are_decode_errors() {
    // The serde layout of `Patch::Planar` with a polygon whose vertices are collinear.
    #[derive(serde::Serialize)]
    enum RawPatch {
        Planar(RawPlanar),
    }
    #[derive(serde::Serialize)]
    struct RawPlanar {
        polygon: RawPolygon,
        world_from_patch: Isometry3,
        covariance: Option<()>,
    }
    #[derive(serde::Serialize)]
    struct RawPolygon {
        outer: Vec<[Real; 2]>,
        holes: Vec<Vec<[Real; 2]>>,
    }
    let planar = |outer: Vec<[Real; 2]>| {
        vec![RawPatch::Planar(RawPlanar {
            polygon: RawPolygon { outer, holes: Vec::new() },
            world_from_patch: Isometry3::identity(),
            covariance: None,
        })]
    };
    // First make sure the mirror layout is right: a valid polygon loads.
    let mut ok = Vec::new();
    write_map(
        &mut ok,
        "polygon",
        MapCounts::default(),
        &planar(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
    )
    .unwrap();
    assert_eq!(PolygonMap::load(&ok[..]).unwrap().len(), 1);
    for tag in ["polygon", "bbox6d"] {
        let mut buf = Vec::new();
        let collinear = planar(vec![[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]);
        write_map(&mut buf, tag, MapCounts::default(), &collinear).unwrap();
        assert!(matches!(load_as(tag, &buf), Err(MapFileError::Decode(_))), "{tag}");
    }
    let mut buf = Vec::new();
    write_map(&mut buf, "pointcloud", MapCounts::default(), &vec![[0.0, Real::NAN, 0.0]]).unwrap();
    assert!(matches!(PointCloudMap::load(&buf[..]), Err(MapFileError::Decode(_))));
    let mut buf = Vec::new();
    write_map(&mut buf, "polygon", MapCounts::default(), &(1u8, 2u8)).unwrap();
    assert!(matches!(PolygonMap::load(&buf[..]), Err(MapFileError::Decode(_))));
}

#[test]
fn memory_grows_with_the_map() {
    let small = PolygonMap::from_patches(small_scene()).unwrap();
    let big = PolygonMap::from_patches(small_scene().into_iter().cycle().take(30)).unwrap();
    assert!(big.memory_bytes() > small.memory_bytes());
    let small6 = BBox6dMap::from_patches(small_scene()).unwrap();
    let big6 = BBox6dMap::from_patches(small_scene().into_iter().cycle().take(30)).unwrap();
    assert!(big6.memory_bytes() > small6.memory_bytes());
    // The 6D map's forest holds 6 coordinates and an id per patch on top of the patches.
    assert!(big6.memory_bytes() >= 30 * (6 * 8 + 4));
    assert!(MemoryUsage::memory_bytes(&small_cloud()) >= 500 * 24);
    assert_eq!(MemoryUsage::memory_bytes(&PointCloudMap::new()), 0);
}
