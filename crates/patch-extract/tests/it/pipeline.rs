//! The whole pipeline on simulated range-camera frames of one room corner from two poses.

use patch_core::{Patch, PlanarPatch, Point3, Real, Vector3};
use patch_extract::pipeline::{ExtractError, PipelineConfig, extract, extract_with_threads};
use patch_extract::trimesh_grow::TrimeshGrowConfig;
use pointcloud::{PointCloud, SensorPose};
use scene_sim::{
    Cuboid, Material, PlanarPolygon, RangeCamera, RangeCameraConfig, RangeSensor, Scene,
    SceneBuilder, camera_pose_looking,
};

/// A floor, a back wall and a box on the floor.
fn room() -> Scene {
    let mut b = SceneBuilder::new("room");
    let floor = PlanarPolygon::parallelogram(
        Point3::new(-1.0, -4.0, 0.0),
        Vector3::new(7.0, 0.0, 0.0),
        Vector3::new(0.0, 8.0, 0.0),
    )
    .unwrap();
    let back = PlanarPolygon::parallelogram(
        Point3::new(5.0, 4.0, 0.0),
        Vector3::new(0.0, -8.0, 0.0),
        Vector3::new(0.0, 0.0, 3.0),
    )
    .unwrap();
    let cube =
        Cuboid::axis_aligned(Point3::new(2.8, 0.3, 0.0), Point3::new(3.6, 1.3, 0.7)).unwrap();
    b.add("floor", floor, Material::CONCRETE).unwrap();
    b.add("back", back, Material::WHITE_MASONRY).unwrap();
    b.add("cube", cube, Material::WOOD).unwrap();
    b.build().unwrap()
}

/// Two frames from poses 0.6 m apart looking the same way: they overlap on the floor and wall.
fn scans() -> Vec<PointCloud> {
    let camera = RangeCamera::new(RangeCameraConfig {
        range_sigma: 0.01,
        ..RangeCameraConfig::swissranger_sr3000()
    })
    .unwrap();
    let scene = room();
    [(0.0, -0.3), (0.0, 0.3)]
        .iter()
        .enumerate()
        .map(|(k, &(x, y))| {
            let pose = camera_pose_looking(Point3::new(x, y, 1.3), 0.0, -0.35);
            camera.scan(&scene, &pose, k as u64).to_cloud().unwrap()
        })
        .collect()
}

fn planar(patches: &[Patch]) -> Vec<&PlanarPatch> {
    patches.iter().filter_map(Patch::as_planar).collect()
}

/// The patches on the plane z = 0 (the floor).
fn floor_patches<'a>(patches: &[&'a PlanarPatch]) -> Vec<&'a PlanarPatch> {
    patches
        .iter()
        .copied()
        .filter(|p| p.normal().z.abs() > 0.99 && p.bounds().max.z.abs() < 0.1)
        .collect()
}

#[test]
fn scans_become_world_patches_and_overlaps_merge() {
    let scans = scans();
    let mut seen = Vec::new();
    let merged = extract(&scans, &PipelineConfig::range_camera(), |i| seen.push(i)).unwrap();
    assert_eq!(seen, [0, 1], "progress after each scan");
    assert_eq!(merged.scans.len(), 2);
    for r in &merged.scans {
        assert!(r.regions >= 3, "floor, wall and box faces: {r:?}");
        assert_eq!(r.planar_patches + r.failed_regions, r.regions, "one patch per region");
        assert!(r.outline_vertices.1 < r.outline_vertices.0, "simplified: {r:?}");
    }
    let stats = merged.merge.unwrap();
    assert!(stats.groups_merged >= 2, "floor and wall seen twice: {stats:?}");
    assert!(stats.output < stats.input);

    let unmerged_config = PipelineConfig { merge: None, ..PipelineConfig::range_camera() };
    let unmerged = extract(&scans, &unmerged_config, |_| {}).unwrap();
    assert!(unmerged.merge.is_none());
    let (m, u) = (planar(&merged.patches), planar(&unmerged.patches));
    assert!(m.len() < u.len(), "{} merged vs {} unmerged", m.len(), u.len());
    assert_eq!(u.len(), stats.input);

    // The floor: two patches before merging, one after, at least as large as either.
    let (fm, fu) = (floor_patches(&m), floor_patches(&u));
    assert_eq!(fu.len(), 2, "one floor patch per scan");
    assert_eq!(fm.len(), 1, "one floor patch after merging");
    assert!(fu.iter().all(|p| fm[0].area() >= p.area() - 1e-9));
    assert!(fm[0].area() < fu.iter().map(|p| p.area()).sum::<Real>() + 1e-9);

    // World frame: every outline vertex of every patch lies on the floor, the wall (x = 5) or
    // the box.
    let on_scene = |q: Point3| {
        q.z.abs() < 0.05
            || (q.x - 5.0).abs() < 0.05
            || ((2.75..=3.65).contains(&q.x) && (0.25..=1.35).contains(&q.y) && q.z < 0.75)
    };
    for p in &m {
        for v in p.polygon().outer().points() {
            let q = p.to_world(v);
            assert!(on_scene(q), "vertex {q} of a patch is on no surface");
        }
    }
    assert!(merged.times.total() >= merged.times.segmentation);
}

#[test]
fn hybrid_maps_add_world_trimeshes_for_the_remainder() {
    let scans = scans();
    let config = PipelineConfig::range_camera().with_remainder(TrimeshGrowConfig::range_camera());
    let out = extract(&scans, &config, |_| {}).unwrap();
    let meshes: Vec<_> = out.patches.iter().filter_map(Patch::as_trimesh).collect();
    assert_eq!(meshes.len(), out.scans.iter().map(|r| r.trimesh_patches).sum::<usize>());
    for m in &meshes {
        for v in m.vertices() {
            // Remainder points are near the scene's surfaces (edges, mixed pixels), in the
            // world frame: inside the room's box.
            assert!(v.z > -0.2 && v.z < 3.2 && v.x > -1.2 && v.x < 5.2, "{v}");
        }
    }
    // Planar patches come first.
    let first_mesh = out.patches.iter().position(|p| p.as_trimesh().is_some());
    if let Some(i) = first_mesh {
        assert!(out.patches[i..].iter().all(|p| p.as_trimesh().is_some()));
    }
}

/// Unorganised scans (the same frames without their pixel grid) get remainder meshes too,
/// through the spherical grid (not in the thesis); `unorganised: None` keeps the old
/// behaviour (planes only), and bad spherical-grid parameters are errors.
#[test]
fn hybrid_maps_of_unorganised_scans_mesh_the_remainder_too() {
    let scans: Vec<PointCloud> = scans()
        .into_iter()
        .map(|mut s| {
            s.set_grid(None).unwrap();
            s
        })
        .collect();
    let config = PipelineConfig::range_camera().with_remainder(TrimeshGrowConfig::range_camera());
    let out = extract(&scans, &config, |_| {}).unwrap();
    for r in &out.scans {
        assert!(r.remainder_points > 0);
        assert!(r.trimesh_patches > 0, "{r:?}");
        assert!(r.binned_remainder > 0 && r.binned_remainder <= r.remainder_points, "{r:?}");
    }
    let meshes: Vec<_> = out.patches.iter().filter_map(Patch::as_trimesh).collect();
    assert!(!meshes.is_empty());
    for m in &meshes {
        for v in m.vertices() {
            assert!(v.z > -0.2 && v.z < 3.2 && v.x > -1.2 && v.x < 5.2, "{v}");
        }
    }

    let planes_only = PipelineConfig { unorganised: None, ..config.clone() };
    let out = extract(&scans, &planes_only, |_| {}).unwrap();
    assert!(out.patches.iter().all(|p| p.as_trimesh().is_none()));
    assert!(out.scans.iter().all(|r| r.trimesh_patches == 0 && r.splats == 0));

    let mut bad = config;
    if let Some(grid) = &mut bad.unorganised {
        grid.max_side_steps = Some(Real::NAN);
    }
    let err = extract(&scans, &bad, |_| {}).unwrap_err();
    assert!(matches!(err, ExtractError::SphericalGrid { scan: 0, .. }), "{err}");
}

/// The scans shared among threads give what one thread gives, and progress comes in scan
/// order.
#[test]
fn any_thread_count_gives_the_same_extraction() {
    let mut scans = scans();
    scans.extend(scans.clone());
    let config = PipelineConfig::range_camera().with_remainder(TrimeshGrowConfig::range_camera());
    let run = |threads: usize| {
        let mut seen = Vec::new();
        let threads = std::num::NonZeroUsize::new(threads).unwrap();
        let out = extract_with_threads(&scans, &config, threads, |i| seen.push(i)).unwrap();
        assert_eq!(seen, (0..scans.len()).collect::<Vec<_>>(), "{threads} threads");
        out
    };
    let one = run(1);
    assert!(!one.patches.is_empty());
    for threads in [2, 3, 8] {
        let many = run(threads);
        assert_eq!(many.patches, one.patches, "{threads} threads");
        assert_eq!(many.back_faces, one.back_faces);
        assert_eq!(many.scans, one.scans);
        assert_eq!(format!("{:?}", many.merge), format!("{:?}", one.merge));
        assert_eq!(many.filled_holes, one.filled_holes);
    }
}

#[test]
fn empty_scans_bad_poses_and_bad_parameters() {
    let out = extract(&[], &PipelineConfig::exact(), |_| {}).unwrap();
    assert!(out.patches.is_empty() && out.scans.is_empty());
    let empty = PointCloud::new();
    let out = extract(&[empty], &PipelineConfig::exact(), |_| {}).unwrap();
    assert!(out.patches.is_empty());
    assert_eq!(out.scans[0].points, 0);

    let mut scan = scans().remove(0);
    let mut pose = SensorPose::identity();
    pose.world_from_sensor.translation.vector.x = Real::NAN;
    scan.set_sensor_pose(Some(pose));
    assert!(matches!(
        extract(&[scan], &PipelineConfig::exact(), |_| {}),
        Err(ExtractError::BadPose { scan: 0 })
    ));

    let mut config = PipelineConfig::exact();
    config.segment.distance_factor = -1.0;
    let err = extract(&scans(), &config, |_| {}).unwrap_err();
    assert!(matches!(err, ExtractError::Segment { scan: 0, .. }), "{err}");
}
