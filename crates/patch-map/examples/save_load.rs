//! Builds a map, saves it and loads it back: the lab's exact surfaces (planar patches for the
//! walls, boxes and shelves, triangle meshes for the barrel and table legs) go into the parry
//! trimesh backend, which is written to a map file in a temporary directory and read back with
//! `load_any` (any backend, chosen by the file's header). The loaded map is then checked
//! against the exact 6D bounding-box map on 20,000 random capsule steps of a 0.3 m robot.
//!
//! ```sh
//! cargo run -p patch-map --example save_load
//! ```

use patch_core::FromPatches;
use patch_map::{
    AnyMap, Attribution, BBox6dMap, MapFile, StepSampling, TrimeshMap, compare_maps, load_any,
};
use scene_sim::patches::{Tessellation, scene_patches};
use std::fs::File;
use std::io::{BufReader, BufWriter};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let scene = scene_sim::lab(1)?;
    let patches = scene_patches(&scene, &Tessellation::default())?;
    let map = TrimeshMap::from_patches(patches.clone())?;
    println!("{} patches, {} triangles", patches.len(), map.num_triangles());

    let dir = tempfile::tempdir()?;
    let path = dir.path().join("lab.pmap");
    let bytes = map.save(BufWriter::new(File::create(&path)?))?;
    let loaded = load_any(BufReader::new(File::open(&path)?))?;
    let n = loaded.counts();
    println!(
        "saved {bytes} bytes; loaded a `{}` map of {} planar and {} trimesh patches",
        loaded.backend(),
        n.planar_patches,
        n.trimesh_patches
    );

    // The truth: the same patches in an exact backend, as a map chosen at run time (`AnyMap`),
    // the kind `compare_maps` takes.
    let exact = AnyMap::BBox6d(BBox6dMap::from_patches(patches)?);
    let sampling = StepSampling { samples: 20_000, ..StepSampling::in_box(scene.bounds()) };
    let c = compare_maps(&exact, &loaded, &sampling, Attribution::None)?;
    println!(
        "{} steps: {} collide, the loaded map calls {} of those free and {} free ones colliding",
        c.steps(),
        c.truly_colliding(),
        c.unsafe_steps,
        c.overcautious_steps
    );
    Ok(())
}
