//! Writes a point cloud in three formats and reads each file back: a small cloud made here (or
//! the file given as argument, in any format `read_cloud` knows) goes to PLY, PCD and XYZ in a
//! temporary directory; each line tells the file's size, what came back and how far any point
//! moved (PLY stores doubles, PCD floats, XYZ exact decimal text).
//!
//! ```sh
//! cargo run -p patchnav-pointcloud --example read_write
//! cargo run -p patchnav-pointcloud --example read_write -- fixtures/lab-alrf-2deg.ply
//! ```

use pointcloud::io::{ReadOptions, read_cloud, write_cloud};
use pointcloud::{Point3, PointCloud};
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let cloud = match std::env::args().nth(1) {
        Some(path) => read_cloud(Path::new(&path), &ReadOptions::STRICT)?,
        None => {
            // A 2 m × 1 m wavy floor sampled every 5 cm, with an intensity per point.
            let positions = (0..800)
                .map(|i| {
                    let (x, y) = ((i % 40) as f64 * 0.05, (i / 40) as f64 * 0.05);
                    Point3::new(x, y, 0.02 * (3.0 * x).sin())
                })
                .collect();
            let mut cloud = PointCloud::from_positions(positions)?;
            cloud.set_intensity(Some((0..800).map(|i| (i % 256) as f32).collect()))?;
            cloud
        }
    };
    let b = cloud.bounds();
    println!(
        "{} points in [{:.2}, {:.2}, {:.2}] .. [{:.2}, {:.2}, {:.2}]",
        cloud.len(),
        b.min.x,
        b.min.y,
        b.min.z,
        b.max.x,
        b.max.y,
        b.max.z
    );

    let dir = tempfile::tempdir()?;
    for name in ["cloud.ply", "cloud.pcd", "cloud.xyz"] {
        let path = dir.path().join(name);
        write_cloud(&path, &cloud)?;
        let back = read_cloud(&path, &ReadOptions::STRICT)?;
        let moved = cloud
            .positions()
            .iter()
            .zip(back.positions())
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        let intensity = if back.intensity().is_some() { "with" } else { "without" };
        println!(
            "{name}: {} bytes, {} points {intensity} intensity, largest move {moved:.1e} m",
            std::fs::metadata(&path)?.len(),
            back.len(),
        );
    }
    Ok(())
}
