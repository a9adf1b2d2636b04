use pointcloud::io::{ReadOptions, pcd::read_pcd, ply::read_ply};
use std::io::BufReader;
#[test]
fn real() {
    let root = std::env::var("REAL").unwrap();
    for f in ["pcl_kinect_office/office1.pcd", "pcl_openni_grabber_boxes/frame_20121214T142255.814212.pcd", "pcl_stereo_table_mug/table_scene_mug_stereo_textured.pcd", "pcl_stanford_bunny/bun0.pcd"] {
        let t = std::time::Instant::now();
        let r = BufReader::new(std::fs::File::open(format!("{root}/{f}")).unwrap());
        let c = read_pcd(r, &ReadOptions::STRICT).unwrap();
        let g = c.grid().map(|g| (g.width(), g.height(), g.num_pixels(), g.num_valid()));
        println!("{f}: {} points grid {:?} normals {} extras {:?} pose {:?} {:?}", c.len(), g, c.normals().is_some(),
          c.extra_fields().iter().map(|f| (f.name.clone(), f.data.len(), format!("{:?}", &f.data).chars().take(60).collect::<String>())).collect::<Vec<_>>(), c.sensor_pose(), t.elapsed());
        println!("  first {:?} bounds {:?}", c.positions().first(), c.bounds());
    }
    let f = "octomap_fr079_building/geb079_occupied_voxels.ply";
    let r = BufReader::new(std::fs::File::open(format!("{root}/{f}")).unwrap());
    let c = read_ply(r, &ReadOptions::STRICT).unwrap();
    println!("{f}: {} points extras {:?} bounds {:?}", c.len(), c.extra_fields().iter().map(|f| (f.name.clone(), f.data.len())).collect::<Vec<_>>(), c.bounds());
    for f in ["/work/shared/bench/floorplan_scan.ply", "/work/shared/bench/floorplan.ply"] {
        let r = BufReader::new(std::fs::File::open(f).unwrap());
        let c = read_ply(r, &ReadOptions::STRICT);
        match c { Ok(c) => println!("{f}: {} points grid {:?} pose {:?}", c.len(), c.grid().map(|g| (g.width(), g.height())), c.sensor_pose()), Err(e) => println!("{f}: {e}") }
    }
}
