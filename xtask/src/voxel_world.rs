//! `cargo xtask voxel-world [--seed S] [--out DIR]`: the generated city-like voxel world of
//! `scene_sim::voxel` (mixed patch sizes, more than 100,000 triangles) as an OBJ mesh and a
//! planning problem in the shared exchange format, for the planning comparison at scale
//! (docs/performance.md).

use anyhow::{Context, Result, bail};
use scene_sim::voxel::{VoxelWorld, VoxelWorldConfig};
use std::path::PathBuf;

/// Writes `voxel-world.obj` and `voxel-world.json` into the output folder.
pub fn run(args: &[String]) -> Result<()> {
    let mut seed = 1u64;
    let mut out = crate::project_root().join("target/bench/voxel-world");
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = || it.next().with_context(|| format!("{a} needs a value"));
        match a.as_str() {
            "--seed" => seed = value()?.parse().context("--seed")?,
            "--out" => out = PathBuf::from(value()?),
            other => bail!("voxel-world: unknown argument `{other}`"),
        }
    }
    let world = VoxelWorld::try_generate(&VoxelWorldConfig::city(seed))?;
    let mesh = world.mesh();
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let obj = out.join("voxel-world.obj");
    pointcloud::io::write_mesh(&obj, &mesh)?;
    let start = world.free_point().context("the world has no free start")?;
    // Goals at street crossings far from the start (the streets run every 16 cells).
    let [nx, ny, _] = world.size();
    let goals: Vec<_> = [(1, 1), (nx / 16 - 2, 1), (1, ny / 16 - 2), (nx / 16 - 2, ny / 16 - 2)]
        .iter()
        .filter_map(|&(a, b)| world.clear_point_near([16 * a + 3, 16 * b + 3, 2]))
        .collect();
    let (lo, hi) = world.bounds();
    let p = |q: &roadmap::Point3| vec![q.x, q.y, q.z];
    let problem = serde_json::json!({
        "name": "voxel-world",
        "mesh": "voxel-world.obj",
        "robot_radius": 0.3,
        "max_step": 1.0,
        "bounds": { "min": p(&lo), "max": p(&hi) },
        "start": p(&start),
        "goals": goals.iter().map(p).collect::<Vec<_>>(),
        "goal_tolerance": 0.5,
        "iterations": 5000,
        "seeds": (0..10).collect::<Vec<u64>>(),
    });
    let json = out.join("voxel-world.json");
    std::fs::write(&json, serde_json::to_string_pretty(&problem)? + "\n")
        .with_context(|| format!("writing {}", json.display()))?;
    println!("wrote {} ({} triangles) and {}", obj.display(), mesh.num_triangles(), json.display());
    Ok(())
}
