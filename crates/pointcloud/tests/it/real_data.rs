//! Loads every file of our formats in the real-data folder and checks the counts its
//! `SOURCE.md` files state.
//!
//! The folders are found by `shared_data` (`$PATCHNAV_REAL_DATA` or `shared/data/real` next
//! to the checkout; the exchange-format mesh at `$PATCHNAV_BENCH` or `shared/bench`): missing,
//! they skip with a `SKIPPED` line, or fail where `PATCHNAV_REQUIRE_DATA` is set (CI).

use pointcloud::io::depth_png::{DepthCamera, read_depth_png, read_range_png};
use pointcloud::io::kitti::{KittiReadOptions, read_kitti_bin};
use pointcloud::io::uos::{UosReadOptions, read_uos_pose, read_uos_scan};
use pointcloud::io::{ErrorKind, Format, ReadOptions, read_cloud, read_mesh, read_range_image};
use pointcloud::{PinholeIntrinsics, Point3, PointCloud, RangeKind};
use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

fn real_data() -> Option<PathBuf> {
    shared_data::real_data("")
}

fn open(path: &Path) -> BufReader<File> {
    BufReader::new(File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())))
}

fn load(dir: &Path, rel: &str) -> PointCloud {
    let path = dir.join(rel);
    read_cloud(&path, &ReadOptions::STRICT).unwrap_or_else(|e| panic!("{e}"))
}

fn valid_pixels(c: &PointCloud) -> usize {
    c.grid().map_or(c.len(), |g| g.num_valid())
}

/// Every file whose extension names one of our formats loads with [`read_cloud`], except the
/// ones listed as not being point data (8-bit PNGs, a KITTI calibration `.txt`), which fail
/// with a clear error.
#[test]
fn every_file_of_our_formats_loads() {
    let Some(dir) = real_data() else { return };
    let not_clouds = ["confidence_u8.png", "TUM_color.png", "calib.txt"];
    let mut loaded = 0;
    let mut dirs: Vec<PathBuf> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
    dirs.sort();
    for sub in dirs.iter().filter(|p| p.is_dir()) {
        let mut files: Vec<PathBuf> =
            std::fs::read_dir(sub).unwrap().map(|e| e.unwrap().path()).collect();
        files.sort();
        for path in files {
            let Some(format) = Format::from_path(&path) else { continue };
            let name = path.file_name().unwrap().to_str().unwrap();
            let result = read_cloud(&path, &ReadOptions::STRICT);
            if not_clouds.contains(&name) {
                let e = result.expect_err(name);
                assert_eq!(e.path.as_deref(), Some(path.as_path()));
                if format == Format::DepthPng {
                    assert!(matches!(e.kind, ErrorKind::Unsupported(_)), "{e}");
                }
                eprintln!("{name}: refused as expected: {e}");
            } else {
                let c = result.unwrap_or_else(|e| panic!("{e}"));
                assert!(!c.is_empty(), "{name}");
                eprintln!(
                    "{name}: {} points ({} pixels)",
                    c.len(),
                    c.grid().map_or(0, |g| g.num_pixels())
                );
                loaded += 1;
            }
        }
    }
    assert!(loaded >= 20, "only {loaded} files loaded");
}

#[test]
fn kitti_velodyne_frames() {
    let Some(dir) = real_data() else { return };
    for (name, n) in [("000000.bin", 20_285), ("000001.bin", 18_630), ("000003.bin", 18_911)] {
        let path = dir.join("kitti_velodyne_frontfov").join(name);
        let c = load(&dir, &format!("kitti_velodyne_frontfov/{name}"));
        assert_eq!(c.len(), n, "{name}");
        let raw = KittiReadOptions { zero_is_invalid: false, ..Default::default() };
        assert_eq!(read_kitti_bin(open(&path), &raw).unwrap().len(), n, "no zero records");
        let b = c.bounds();
        assert!(b.min.x > 0.0 && b.max.x < 80.0, "front field of view, x forward: {b:?}");
        assert!(b.min.z > -5.0 && b.max.z < 5.0, "z up: {b:?}");
        let i = c.intensity().unwrap();
        assert!(i.iter().all(|&v| (0.0..=1.0).contains(&v)));
    }
}

#[test]
fn rellis3d_ouster_scan() {
    let Some(dir) = real_data() else { return };
    let path = dir.join("rellis3d_ouster_offroad/000000.bin");
    let raw = KittiReadOptions { zero_is_invalid: false, ..Default::default() };
    assert_eq!(read_kitti_bin(open(&path), &raw).unwrap().len(), 131_072);
    let c = read_kitti_bin(open(&path), &KittiReadOptions::ouster(64)).unwrap();
    let g = c.grid().unwrap();
    assert_eq!((g.width(), g.height()), (2048, 64));
    assert_eq!(c.len(), 78_658);
    assert_eq!(load(&dir, "rellis3d_ouster_offroad/000000.bin").len(), 78_658);
    // Ring 0 is the highest beam: mean elevation falls from row 0 to row 63.
    let mean_elevation = |row: u32| {
        let e: Vec<f64> = (0..g.width())
            .filter_map(|col| g.point_index(col, row))
            .map(|i| {
                let p = c.positions()[i];
                p.z.atan2(p.x.hypot(p.y)).to_degrees()
            })
            .collect();
        e.iter().sum::<f64>() / e.len() as f64
    };
    let (top, bottom) = (mean_elevation(0), mean_elevation(63));
    assert!(top > 10.0 && bottom < -10.0, "top {top}°, bottom {bottom}°");
    assert!(c.rings().unwrap().iter().all(|&r| r < 64));
}

#[test]
fn threedtk_kurt3d_scans() {
    let Some(dir) = real_data() else { return };
    let sub = dir.join("3dtk_kurt3d_scans");
    // (points, kept by UosReadOptions::KURT3D: 0.2 m <= r < 32.75 m)
    for (name, kept) in [("scan000", 77_987), ("scan001", 78_320), ("scan002", 78_118)] {
        let c = load(&dir, &format!("3dtk_kurt3d_scans/{name}.3d"));
        assert_eq!(c.len(), 81_360, "{name}");
        assert!(c.sensor_pose().is_some(), "{name}: the sibling .pose is applied");
        let path = sub.join(format!("{name}.3d"));
        let f = read_uos_scan(open(&path), &UosReadOptions::KURT3D).unwrap();
        assert_eq!(f.len(), kept, "{name}");
        let r_max = f.positions().iter().map(|p| p.coords.norm()).fold(0.0, f64::max);
        assert!(r_max < 32.75);
    }
    // The first point of scan000 is 10.1 cm along 3DTK's x (right): our −y.
    let c = load(&dir, "3dtk_kurt3d_scans/scan000.3d");
    assert!((c.positions()[0] - Point3::new(0.0, -0.101, 0.0)).norm() < 1e-12);
    let p0 = read_uos_pose(open(&sub.join("scan000.pose"))).unwrap();
    assert!(p0.origin().coords.norm() == 0.0);
    assert!(p0.world_from_sensor.rotation.angle() == 0.0);
    // scan001: "-3.10605 -7.50803 156.917 / 1.35694 -0.852409 -0.56224": 1.57 m forward.
    let p1 = read_uos_pose(open(&sub.join("scan001.pose"))).unwrap();
    assert!((p1.origin() - Point3::new(1.56917, 0.0310605, -0.0750803)).norm() < 1e-12);
    let angle = p1.world_from_sensor.rotation.angle().to_degrees();
    assert!((1.0..2.0).contains(&angle), "{angle}°");
    // Up is z: the scanner sits above a floor, so far more points lie below it than above
    // the same distance up.
    let below = c.positions().iter().filter(|p| p.z < -0.3).count();
    assert!(below > c.len() / 10, "{below}");
}

#[test]
fn tum_depth_png() {
    let Some(dir) = real_data() else { return };
    let path = dir.join("tum_rgbd_kinect_frame/TUM_depth.png");
    let img = read_depth_png(open(&path), &DepthCamera::tum_kinect()).unwrap();
    assert_eq!((img.width(), img.height()), (640, 480));
    assert_eq!(img.num_valid(), 248_250);
    let max = img.ranges().iter().flatten().fold(0.0f32, |a, &b| a.max(b));
    assert!((max - 46_655.0 / 5000.0).abs() < 1e-5, "{max}");
    let same = read_range_image(&path, Some(&DepthCamera::tum_kinect())).unwrap();
    assert_eq!(same, img);
    // Without a sidecar the path-level reader falls back to OpenNI millimetres.
    let c = load(&dir, "tum_rgbd_kinect_frame/TUM_depth.png");
    assert_eq!(valid_pixels(&c), 248_250);
    assert_eq!(c.grid().unwrap().num_pixels(), 640 * 480);
}

#[test]
fn pcl_depth_pngs() {
    let Some(dir) = real_data() else { return };
    for (rel, valid, fx) in [
        ("pcl_kinect_office/office1_zdepth_mm.png", 254_456, 524.9999921470268),
        ("pcl_openni_grabber_boxes/frame_20121214T142255.814212_depth_mm.png", 271_575, 525.0),
        ("pcl_openni_grabber_boxes/frame_20121214T142256.068683_depth_mm.png", 271_395, 525.0),
        ("pcl_openni_grabber_boxes/frame_20121214T142256.332395_depth_mm.png", 271_328, 525.0),
        (
            "pcl_stereo_table_mug/table_scene_mug_stereo_textured_zdepth_mm.png",
            209_280,
            964.3586742779013,
        ),
    ] {
        let path = dir.join(rel);
        let img = read_range_image(&path, None).unwrap();
        assert_eq!((img.width(), img.height()), (640, 480), "{rel}");
        assert_eq!(img.num_valid(), valid, "{rel}");
        let pointcloud::BeamModel::Pinhole(k) = img.beams() else { panic!() };
        assert_eq!(k.fx, fx, "{rel}: intrinsics from the sidecar JSON, else OpenNI");
        let max = img.ranges().iter().flatten().fold(0.0f32, |a, &b| a.max(b));
        assert!(max > 1.0 && max < 6.0, "{rel}: millimetres: {max}");
        assert_eq!(valid_pixels(&load(&dir, rel)), valid);
    }
}

#[test]
fn ifm_o3r_radial_distance_png() {
    let Some(dir) = real_data() else { return };
    // A radial distance along each pixel's beam, not a z depth. fx = fy = 124.344, principal
    // point (111.5, 85.5) from frame_meta.json (lens distortion not modelled here).
    let camera = DepthCamera {
        intrinsics: PinholeIntrinsics {
            fx: 124.34428405761719,
            fy: 124.34428405761719,
            cx: 111.5,
            cy: 85.5,
        },
        depth_scale: 0.00015259021893143654,
    };
    let path = dir.join("ifm_o3r_tof_frame/radial_distance_u16.png");
    let img = read_range_png(open(&path), &camera, RangeKind::Radial).unwrap();
    assert_eq!((img.width(), img.height()), (224, 172));
    assert_eq!(img.num_valid(), 9_962);
    let r: Vec<f32> = img.ranges().iter().flatten().copied().collect();
    let (min, max) = r.iter().fold((f32::MAX, 0.0f32), |(a, b), &v| (a.min(v), b.max(v)));
    assert!(min >= 0.19 && max <= 1.98, "valid distances 0.20-1.97 m: {min}..{max}");
    let cloud = img.to_cloud().unwrap();
    for (p, r) in cloud.positions().iter().zip(&r) {
        assert!((p.coords.norm() - *r as f64).abs() < 1e-6);
    }
    let e = read_depth_png(open(&dir.join("ifm_o3r_tof_frame/confidence_u8.png")), &camera)
        .unwrap_err();
    assert!(matches!(e.kind, ErrorKind::Unsupported(_)));
}

#[test]
fn pcd_files() {
    let Some(dir) = real_data() else { return };
    for (rel, valid) in [
        ("pcl_kinect_office/office1.pcd", 254_456),
        ("pcl_openni_grabber_boxes/frame_20121214T142255.814212.pcd", 271_575),
        ("pcl_stereo_table_mug/table_scene_mug_stereo_textured.pcd", 209_280),
    ] {
        let c = load(&dir, rel);
        let g = c.grid().unwrap_or_else(|| panic!("{rel} is organised"));
        assert_eq!((g.width(), g.height()), (640, 480), "{rel}");
        assert_eq!(c.len(), valid, "{rel}");
    }
    let bunny = load(&dir, "pcl_stanford_bunny/bun0.pcd");
    assert_eq!(bunny.len(), 397);
    assert!(bunny.normals().is_some());
    assert!(bunny.grid().is_none());
}

/// The z-depth PNG and the fitted intrinsics rebuild the organised PCD they were made from.
#[test]
fn office_png_matches_its_pcd() {
    let Some(dir) = real_data() else { return };
    let pcd = load(&dir, "pcl_kinect_office/office1.pcd");
    let png = load(&dir, "pcl_kinect_office/office1_zdepth_mm.png");
    let (gp, gi) = (pcd.grid().unwrap(), png.grid().unwrap());
    let mut compared = 0;
    for row in 0..480 {
        for col in 0..640 {
            let a = gp.point_index(col, row).map(|i| pcd.positions()[i]);
            let b = gi.point_index(col, row).map(|i| png.positions()[i]);
            assert_eq!(a.is_some(), b.is_some(), "pixel ({col}, {row})");
            if let (Some(a), Some(b)) = (a, b) {
                assert!((a.z - b.z).abs() <= 0.0005 + 1e-6, "z at ({col}, {row}): {a} vs {b}");
                assert!((a - b).norm() < 0.005, "({col}, {row}): {a} vs {b}");
                compared += 1;
            }
        }
    }
    assert_eq!(compared, 254_456);
}

#[test]
fn octomap_voxel_ply() {
    let Some(dir) = real_data() else { return };
    let c = load(&dir, "octomap_fr079_building/geb079_occupied_voxels.ply");
    assert_eq!(c.len(), 143_729);
    let size = c.extra_field("size").expect("the `size` property is kept");
    assert_eq!(size.data.len(), 143_729);
    let sizes: Vec<f64> = (0..size.data.len()).map(|i| size.data.get_f64(i).unwrap()).collect();
    let fine = sizes.iter().filter(|&&s| (s - 0.08).abs() < 1e-6).count();
    assert_eq!(fine, 137_745);
}

#[test]
fn bench_floorplan_mesh() {
    let Some(dir) = shared_data::bench("") else { return };
    let path = dir.join("floorplan.obj");
    let m = read_mesh(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.num_vertices(), 188);
    assert_eq!(m.num_faces(), 226);
    assert!(m.is_triangle_mesh());
    let b = m.bounds();
    assert!(b.min.x < 0.0 && b.max.x > 20.0 && b.max.z == 2.5, "{b:?}");
    assert_eq!(load(&dir, "floorplan.obj").len(), 188);
}
