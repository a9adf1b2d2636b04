//! Simulates one scan of the lab with the actuated laser range finder (a SICK S300 tilted in
//! 2° steps) and writes it as a PLY file into a temporary directory: an organised cloud in the
//! sensor frame with the sensor pose in the header and, as labels, the surface each beam hit.
//! Prints the scan's size, the surfaces hit most and the file written.
//!
//! ```sh
//! cargo run -p scene-sim --example scan_to_ply
//! ```

use pointcloud::io::write_cloud;
use scene_sim::{Alrf, AlrfConfig, RangeSensor, SurfaceId, lab};
use std::collections::BTreeMap;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // The same seed gives the same scene, the same poses and the same noise.
    let scene = lab(1)?;
    let robot = scene.scan_poses(1, 0.6, 1)[0];
    let alrf = Alrf::new(AlrfConfig::sick_s300_with_step(2f64.to_radians())?)?;
    let scan = alrf.scan(&scene, &alrf.mount(&robot), 1);
    let cloud = scan.to_cloud()?;
    let grid = cloud.grid().ok_or("an ALRF scan is organised")?;
    println!(
        "{} points from {} × {} beams of `{}`",
        cloud.len(),
        grid.width(),
        grid.height(),
        scene.name()
    );

    let mut hits: BTreeMap<u32, usize> = BTreeMap::new();
    for &label in cloud.labels().unwrap_or_default() {
        *hits.entry(label).or_default() += 1;
    }
    let mut hits: Vec<(u32, usize)> = hits.into_iter().collect();
    hits.sort_by_key(|&(_, n)| std::cmp::Reverse(n));
    for (label, n) in hits.iter().take(3) {
        let name = scene.surface(SurfaceId(*label)).map_or("?", |s| s.name.as_str());
        println!("  {n:>6} points on {name}");
    }

    let dir = tempfile::tempdir()?;
    let path = dir.path().join("lab-scan.ply");
    write_cloud(&path, &cloud)?;
    println!("wrote {} ({} bytes)", path.display(), std::fs::metadata(&path)?.len());
    Ok(())
}
