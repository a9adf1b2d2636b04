//! Path-level reading and writing: format by extension, sidecar files, errors naming the path,
//! and the atomic writer (a failed or killed write leaves the old file intact).

use pointcloud::io::depth_png::{DepthCamera, write_depth_png};
use pointcloud::io::{
    ErrorKind, Format, ReadOptions, WriteStep, depth_camera_for, read_cloud, read_mesh,
    read_range_image, write_atomically, write_bytes_atomically, write_cloud,
};
use pointcloud::{
    BeamModel, PinholeIntrinsics, Point3, PointCloud, RangeImage, RangeKind, SensorPose,
};
use std::path::Path;

fn cloud() -> PointCloud {
    let mut c = PointCloud::from_positions(vec![
        Point3::new(1.0, 2.0, 3.0),
        Point3::new(-4.5, 0.25, 6.0),
        Point3::new(7.0, -8.0, 0.125),
    ])
    .unwrap();
    c.set_intensity(Some(vec![0.5, 1.0, 0.0])).unwrap();
    c
}

#[test]
fn every_writable_format_round_trips() {
    let dir = tempfile::tempdir().unwrap();
    let c = cloud();
    for ext in ["ply", "pcd", "xyz", "txt", "bin", "3d", "obj"] {
        let path = dir.path().join(format!("cloud.{ext}"));
        write_cloud(&path, &c).unwrap_or_else(|e| panic!("{e}"));
        let back = read_cloud(&path, &ReadOptions::STRICT).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(back.len(), 3, "{ext}");
        for (a, b) in back.positions().iter().zip(c.positions()) {
            assert!((a - b).norm() < 1e-12, "{ext}: {a} vs {b}");
        }
        if ext != "obj" {
            assert_eq!(back.intensity(), c.intensity(), "{ext}");
        }
    }
}

#[test]
fn uos_scans_carry_their_pose_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scan007.3d");
    let mut c = cloud();
    let pose = SensorPose::from_position_rpy(Point3::new(1.0, -2.0, 0.5), 0.1, -0.2, 0.3);
    c.set_sensor_pose(Some(pose));
    write_cloud(&path, &c).unwrap();
    assert!(dir.path().join("scan007.pose").is_file());
    let back = read_cloud(&path, &ReadOptions::STRICT).unwrap();
    let d = back.sensor_pose().unwrap().world_from_sensor.to_homogeneous()
        - pose.world_from_sensor.to_homogeneous();
    assert!(d.norm() < 1e-12);
    // A bad pose file fails, naming the pose file.
    std::fs::write(dir.path().join("scan007.pose"), "1 2 3\n").unwrap();
    let e = read_cloud(&path, &ReadOptions::STRICT).unwrap_err();
    assert_eq!(e.path.as_deref(), Some(dir.path().join("scan007.pose").as_path()));
    // Without a pose, identity is written.
    write_cloud(&path, &cloud()).unwrap();
    let back = read_cloud(&path, &ReadOptions::STRICT).unwrap();
    assert_eq!(back.sensor_pose().unwrap().world_from_sensor.rotation.angle(), 0.0);
}

fn write_png(path: &Path, w: u32, h: u32, values: &[u16], scale: f64) {
    let k = PinholeIntrinsics { fx: 1.0, fy: 1.0, cx: 0.0, cy: 0.0 };
    let ranges = values.iter().map(|&v| (v != 0).then_some((v as f64 * scale) as f32)).collect();
    let img = RangeImage::new(w, h, BeamModel::Pinhole(k), RangeKind::Depth, ranges).unwrap();
    write_depth_png(std::fs::File::create(path).unwrap(), &img, scale).unwrap();
}

#[test]
fn depth_pngs_find_their_sidecar_intrinsics() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("scene_intrinsics_fitted.json"),
        r#"{"fx": 100, "fy": 101, "cx": 1.5, "cy": 0.5, "width": 4, "height": 2,
            "depth_scale": 0.0002, "note": "test"}"#,
    )
    .unwrap();
    std::fs::write(
        d.join("scene_depth_intrinsics.json"),
        r#"{"fx": 7, "fy": 7, "cx": 0, "cy": 0}"#,
    )
    .unwrap();
    write_png(&d.join("scene_zdepth_mm.png"), 4, 2, &[0, 5000, 10000, 1, 2, 3, 4, 0], 0.0002);
    write_png(&d.join("scene_depth.png"), 4, 2, &[1; 8], 0.001);
    write_png(&d.join("scenery.png"), 4, 2, &[1; 8], 0.001);
    write_png(&d.join("scene_big.png"), 5, 2, &[1; 10], 0.001);

    let cam = depth_camera_for(&d.join("scene_zdepth_mm.png")).unwrap();
    assert_eq!(cam.intrinsics, PinholeIntrinsics { fx: 100.0, fy: 101.0, cx: 1.5, cy: 0.5 });
    assert_eq!(cam.depth_scale, 0.0002);
    let img = read_range_image(&d.join("scene_zdepth_mm.png"), None).unwrap();
    assert_eq!(img.range(1, 0), Some(1.0));
    assert_eq!(img.num_valid(), 6);
    let c = read_cloud(&d.join("scene_zdepth_mm.png"), &ReadOptions::STRICT).unwrap();
    assert_eq!((c.len(), c.grid().unwrap().num_pixels()), (6, 8));

    // The longest matching prefix wins.
    assert_eq!(depth_camera_for(&d.join("scene_depth.png")).unwrap().intrinsics.fx, 7.0);
    // `scene` does not serve `scenery`: OpenNI defaults.
    assert_eq!(depth_camera_for(&d.join("scenery.png")).unwrap(), DepthCamera::openni_mm());
    // The sidecar's size must match the image.
    let e = read_range_image(&d.join("scene_big.png"), None).unwrap_err();
    assert!(e.to_string().contains("4×2"), "{e}");
    // An explicit camera overrides the sidecar.
    let img = read_range_image(&d.join("scene_big.png"), Some(&DepthCamera::tum_kinect())).unwrap();
    assert_eq!(img.width(), 5);
    // A broken sidecar fails, naming the JSON file.
    std::fs::write(d.join("broken_intrinsics.json"), "{\"fx\": }").unwrap();
    write_png(&d.join("broken.png"), 1, 1, &[1], 0.001);
    let e = read_cloud(&d.join("broken.png"), &ReadOptions::STRICT).unwrap_err();
    assert_eq!(e.path.as_deref(), Some(d.join("broken_intrinsics.json").as_path()));
}

#[test]
fn errors_name_the_path() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.ply");
    let e = read_cloud(&missing, &ReadOptions::STRICT).unwrap_err();
    assert_eq!(e.path.as_deref(), Some(missing.as_path()));
    assert!(matches!(e.kind, ErrorKind::Io(_)));

    let unknown = dir.path().join("cloud.las");
    std::fs::write(&unknown, "x").unwrap();
    let e = read_cloud(&unknown, &ReadOptions::STRICT).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::Unsupported(_)));
    assert!(e.to_string().contains("las"), "{e}");
    assert!(write_cloud(&unknown, &cloud()).is_err());
    assert!(read_cloud(&dir.path().join("no_extension"), &ReadOptions::STRICT).is_err());

    let bad = dir.path().join("bad.xyz");
    std::fs::write(&bad, "1 2 3\n1 2\n").unwrap();
    let e = read_cloud(&bad, &ReadOptions::STRICT).unwrap_err();
    assert_eq!(e.path.as_deref(), Some(bad.as_path()));
    assert!(e.to_string().contains("line 2"), "{e}");

    let png = dir.path().join("cloud.png");
    let e = write_cloud(&png, &cloud()).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::Unsupported(_)));
    assert!(!png.exists());
}

#[test]
fn obj_paths_read_meshes_and_vertices() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.obj");
    std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
    let m = read_mesh(&path).unwrap();
    assert_eq!((m.num_faces(), m.num_triangles()), (1, 2));
    assert_eq!(read_cloud(&path, &ReadOptions::STRICT).unwrap().len(), 4);
}

/// What a replaced file held before.
const OLD: &[u8] = b"the user's map, which must survive\n";

/// New content, larger than any write buffer, so half of it reaches the disk before the crash.
fn new_content() -> Vec<u8> {
    (0..200_000u32).map(|i| (i % 251) as u8).collect()
}

/// The names in `dir` other than `keep`.
fn others(dir: &Path, keep: &str) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != keep)
        .collect();
    names.sort();
    names
}

#[test]
fn an_atomic_write_replaces_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("map.pmap");
    // A new file.
    let n = write_atomically(&path, |w| w.write_all(OLD).map(|()| OLD.len())).unwrap();
    assert_eq!((n, std::fs::read(&path).unwrap()), (OLD.len(), OLD.to_vec()));
    // Replacing it, shorter and longer.
    write_bytes_atomically(&path, b"short").unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), b"short");
    let new = new_content();
    write_bytes_atomically(&path, &new).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), new);
    assert_eq!(others(dir.path(), "map.pmap"), Vec::<String>::new());
    #[cfg(unix)]
    {
        // The replaced file keeps its mode; a symbolic link is followed, not replaced.
        use std::os::unix::fs::PermissionsExt as _;
        let mode = std::fs::Permissions::from_mode(0o640);
        std::fs::set_permissions(&path, mode).unwrap();
        write_bytes_atomically(&path, OLD).unwrap();
        let meta = std::fs::metadata(&path).unwrap();
        assert_eq!(meta.permissions().mode() & 0o777, 0o640);
        let link = dir.path().join("link.pmap");
        std::os::unix::fs::symlink(&path, &link).unwrap();
        write_bytes_atomically(&link, b"through the link").unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read(&path).unwrap(), b"through the link");
    }
}

#[test]
fn a_failed_atomic_write_leaves_the_old_file_and_no_temporary_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("map.pmap");
    std::fs::write(&path, OLD).unwrap();
    let new = new_content();
    let e = write_atomically(&path, |w| {
        w.write_all(&new[..new.len() / 2])?;
        w.flush()?;
        Err::<(), _>(std::io::Error::other("stopped half-way"))
    })
    .unwrap_err();
    // The closure's own error comes back as it was.
    assert_eq!(e.to_string(), "stopped half-way");
    assert_eq!(std::fs::read(&path).unwrap(), OLD);
    assert_eq!(others(dir.path(), "map.pmap"), Vec::<String>::new());

    // A format error half-way through a cloud leaves the old cloud file too.
    let ply = dir.path().join("cloud.ply");
    write_cloud(&ply, &cloud()).unwrap();
    let before = std::fs::read(&ply).unwrap();
    let e = write_atomically(&ply, |w| {
        let ply_error = |kind: ErrorKind| pointcloud::io::Error::new(Format::Ply, kind);
        w.write_all(&before[..before.len() / 2]).map_err(|e| ply_error(e.into()))?;
        Err::<(), _>(ply_error(ErrorKind::BadValue("no more".into())))
    })
    .unwrap_err();
    assert!(matches!(e.kind, ErrorKind::BadValue(_)), "{e}");
    assert_eq!(std::fs::read(&ply).unwrap(), before);
    assert_eq!(others(dir.path(), "cloud.ply"), vec!["map.pmap".to_owned()]);
}

#[test]
fn the_writer_s_own_errors_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("no such folder").join("map.pmap");
    let e = write_bytes_atomically(&path, OLD).unwrap_err();
    assert_eq!((e.path.as_path(), e.step), (path.as_path(), WriteStep::CreateTemp));
    assert!(e.to_string().contains("no such folder"), "{e}");
    let io: std::io::Error = e.into();
    assert_eq!(io.kind(), std::io::ErrorKind::NotFound);
    assert!(io.to_string().contains("map.pmap"), "{io}");
    let e = write_cloud(&path.with_extension("ply"), &cloud()).unwrap_err();
    assert_eq!(e.path.as_deref(), Some(path.with_extension("ply").as_path()));
    assert_eq!(e.format, Some(Format::Ply));
    assert!(matches!(e.kind, ErrorKind::Io(_)));
}

/// Set in the child process of [`a_write_killed_mid_file_leaves_the_old_file`]: the file it
/// writes and then dies writing.
const KILLED_WRITE: &str = "POINTCLOUD_TEST_KILLED_WRITE";

#[test]
fn a_write_killed_mid_file_leaves_the_old_file() {
    let new = new_content();
    if let Some(target) = std::env::var_os(KILLED_WRITE) {
        // The child: half of the new content reaches the temporary file, then the process dies.
        let _ = write_atomically(&target, |w| -> std::io::Result<()> {
            w.write_all(&new[..new.len() / 2])?;
            w.flush()?;
            std::process::abort()
        });
        unreachable!("the child writer returned instead of dying");
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("map.pmap");
    std::fs::write(&path, OLD).unwrap();
    // This test's name as the harness knows it: its module path without the binary's name.
    let test_path = concat!(module_path!(), "::a_write_killed_mid_file_leaves_the_old_file");
    let own_name = test_path.split_once("::").map_or(test_path, |(_, rest)| rest);
    let out = std::process::Command::new(std::env::current_exe().unwrap())
        .args(["--exact", own_name, "--nocapture"])
        .env(KILLED_WRITE, &path)
        .output()
        .unwrap();
    assert!(!out.status.success(), "the child did not die: {out:?}");
    #[cfg(unix)]
    {
        use std::os::unix::process::ExitStatusExt as _;
        assert_eq!(out.status.signal(), Some(6), "not SIGABRT: {out:?}");
    }
    assert_eq!(std::fs::read(&path).unwrap(), OLD);
    // The crash left its temporary file, recognisable by name, holding the half it wrote.
    let left = others(dir.path(), "map.pmap");
    assert_eq!(left.len(), 1, "{left:?}");
    assert!(left[0].starts_with(".map.pmap.tmp"), "{left:?}");
    assert_eq!(std::fs::read(dir.path().join(&left[0])).unwrap(), new[..new.len() / 2]);
}
