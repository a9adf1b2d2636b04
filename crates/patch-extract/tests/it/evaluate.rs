//! SegComp on segmentations built from scene-sim ground truth and deliberately damaged.

use patch_core::{Plane, Point3, UnitVector3};
use patch_extract::evaluate::{OverSegmentation, SegCompConfig, UnderSegmentation, segcomp};
use patch_extract::{PlanarRegion, Segmentation};
use pointcloud::{PointCloud, SensorPose};
use scene_sim::{RangeCamera, RangeCameraConfig, RangeSensor, Scene, SurfaceId};
use std::collections::BTreeMap;

fn scan() -> (Scene, SensorPose, PointCloud) {
    let scene = scene_sim::lab(3).unwrap();
    let camera = RangeCamera::new(RangeCameraConfig {
        range_sigma: 0.0,
        ..RangeCameraConfig::swissranger_sr3000()
    })
    .unwrap();
    let body = scene.scan_poses(1, 0.8, 3)[0];
    let scan = camera.scan(&scene, &camera.mount(&body), 1);
    let cloud = scan.to_cloud().unwrap();
    (scene, scan.pose, cloud)
}

fn plane_in_sensor(scene: &Scene, pose: &SensorPose, surface: u32) -> Option<Plane> {
    let plane = scene.surface(SurfaceId(surface))?.plane?;
    let m = &pose.world_from_sensor;
    let normal = UnitVector3::new_normalize(m.rotation.inverse() * plane.normal.into_inner());
    let offset = plane.offset - plane.normal.dot(&m.translation.vector);
    Some(Plane { normal, offset })
}

fn region(cloud: &PointCloud, points: Vec<u32>) -> PlanarRegion {
    PlanarRegion::fit(cloud.positions(), points, &Point3::origin()).unwrap()
}

/// The points of each label with at least `min` points, largest first.
fn truth_groups(cloud: &PointCloud, min: usize) -> Vec<(u32, Vec<u32>)> {
    let mut groups: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
    for (i, &l) in cloud.labels().unwrap().iter().enumerate() {
        if l != u32::MAX {
            groups.entry(l).or_default().push(i as u32);
        }
    }
    let mut groups: Vec<(u32, Vec<u32>)> =
        groups.into_iter().filter(|(_, p)| p.len() >= min).collect();
    groups.sort_by(|a, b| b.1.len().cmp(&a.1.len()).then(a.0.cmp(&b.0)));
    groups
}

#[test]
fn ground_truth_segmentation_is_all_correct() {
    let (scene, pose, cloud) = scan();
    let groups = truth_groups(&cloud, 200);
    assert!(groups.len() >= 3, "the view shows a few surfaces");
    let seg = Segmentation {
        regions: groups.iter().map(|(_, p)| region(&cloud, p.clone())).collect(),
        remainder: Vec::new(),
    };
    let report = segcomp(cloud.labels().unwrap(), &seg, &SegCompConfig::hoover(200), |l| {
        plane_in_sensor(&scene, &pose, l)
    })
    .unwrap();
    assert_eq!(report.num_truth, groups.len());
    assert_eq!(report.correct.len(), groups.len(), "{report}");
    // Noise-free ranges are f32: the fitted planes agree with the truth to well below 0.01°.
    assert!(report.max_angle_error_deg().unwrap() < 0.01, "{report}");
}

#[test]
fn damaged_segmentations_are_classified() {
    let (_, _, cloud) = scan();
    let groups = truth_groups(&cloud, 200);
    assert!(groups.len() >= 5);
    let labels = cloud.labels().unwrap();
    let (l0, p0) = &groups[0];
    let (l1, p1) = &groups[1];
    let (l2, p2) = &groups[2];
    let (l3, p3) = &groups[3];
    let (l4, p4) = &groups[4];
    // Regions 0 and 1: the largest surface split in halves -> over-segmentation.
    let half = p0.len() / 2;
    // Region 2: surfaces 1 and 2 merged -> under-segmentation.
    let mut merged = p1.clone();
    merged.extend(p2);
    // Region 3: k points each of surfaces 3 and 4, their other points in the remainder ->
    // both missed, the region noise.
    let k = p3.len().min(p4.len()) / 2;
    let mixed: Vec<u32> = p3[..k].iter().chain(&p4[..k]).copied().collect();
    let mut remainder: Vec<u32> = p3[k..].iter().chain(&p4[k..]).copied().collect();
    remainder.sort_unstable();
    let seg = Segmentation {
        regions: vec![
            region(&cloud, p0[..half].to_vec()),
            region(&cloud, p0[half..].to_vec()),
            region(&cloud, merged),
            region(&cloud, mixed),
        ],
        remainder,
    };
    let report = segcomp(labels, &seg, &SegCompConfig::hoover(200), |_| None).unwrap();
    assert!(report.correct.is_empty(), "{report}");
    assert_eq!(report.over, vec![OverSegmentation { truth: *l0, regions: vec![0, 1] }]);
    let mut merged_labels = vec![*l1, *l2];
    merged_labels.sort_unstable();
    assert_eq!(report.under, vec![UnderSegmentation { region: 2, truths: merged_labels }]);
    assert!(report.missed.contains(l3) && report.missed.contains(l4), "{report}");
    assert_eq!(report.noise, vec![3]);
    // A stricter tolerance cannot create detections.
    let strict = SegCompConfig { tolerance: 0.95, ..SegCompConfig::hoover(200) };
    let strict = segcomp(labels, &seg, &strict, |_| None).unwrap();
    assert!(strict.correct.is_empty());
}
