//! The shared benchmark floor plan (an OBJ of triangles) turned into planar patches: nothing is
//! lost, and coplanar triangles merge. Runs when the benchmark folder exists (`shared/bench`
//! next to the checkout, or `$PATCHNAV_BENCH`; `shared_data`): skipped with a loud `SKIPPED` line
//! otherwise, failed where `PATCHNAV_REQUIRE_DATA` is set (CI).

use patch_core::{BruteForceMap, FromPatches, Patch, Point3, ProximityQuery, TrimeshPatch, na};
use patch_map::{MeshToPatchesConfig, planar_patches_from_mesh};
use pointcloud::io::read_mesh;
use std::path::PathBuf;

fn bench_dir() -> Option<PathBuf> {
    shared_data::bench("")
}

#[test]
fn floorplan_triangles_merge_into_planar_patches_without_loss() {
    let Some(dir) = bench_dir() else { return };
    let mesh = read_mesh(&dir.join("floorplan.obj")).unwrap();
    let (patches, stats) = planar_patches_from_mesh(&mesh, &MeshToPatchesConfig::exact_cad());
    assert_eq!(stats.trimesh_fallbacks, 0, "{stats:?}");
    let triangles: Vec<[u32; 3]> = mesh.triangles().collect();
    assert!(patches.len() < triangles.len() / 2, "{} patches", patches.len());
    // Wall bottoms and tops overlap the floor and ceiling, so areas do not add up; compare
    // the point sets instead. Nothing lost: points of every triangle lie on a patch.
    let patch_map = BruteForceMap::from_patches(patches.clone()).unwrap();
    let v = |i: u32| mesh.vertices()[i as usize];
    for t in &triangles {
        let (a, b, c) = (v(t[0]), v(t[1]), v(t[2]));
        let centroid = Point3::from((a.coords + b.coords + c.coords) / 3.0);
        for p in [centroid, a, b, c, na::center(&a, &b)] {
            let d = patch_map.closest_patch(&p, 1.0).map_or(1.0, |h| h.distance);
            assert!(d < 1e-6, "triangle point {p} is {d} m from every patch");
        }
    }
    // Nothing added: every patch's vertices and centroid-ish interior points lie on the mesh.
    let mesh_patch = TrimeshPatch::new(mesh.vertices().to_vec(), triangles).unwrap();
    let mesh_map = BruteForceMap::from_patches(vec![Patch::Trimesh(mesh_patch)]).unwrap();
    for patch in &patches {
        let planar = patch.as_planar().unwrap();
        for q in planar.polygon().outer().points() {
            let p = planar.to_world(q);
            let d = mesh_map.closest_patch(&p, 1.0).map_or(1.0, |h| h.distance);
            assert!(d < 1e-6, "patch vertex {p} is {d} m from the mesh");
        }
    }
    eprintln!("floorplan.obj: {} triangles -> {:?}", mesh.triangles().count(), stats);
}
