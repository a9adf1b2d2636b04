//! `examples/data/room.obj`, the mesh `examples/plan_on_mesh.rs` plans on, is made here: an
//! 8 m × 6 m × 2.5 m room with two partitions that force an S-shaped path from (1, 1, 1) to
//! (7, 5, 1) and a low crate a robot can pass over. The test fails if the committed file differs
//! from what this code makes; `UPDATE_EXAMPLE_DATA=1 cargo test -p patchnav-roadmap --test it example_data::`
//! rewrites it.

use pointcloud::io::obj::write_obj;
use pointcloud::{Point3, PolygonMesh};
use std::path::Path;

/// The room's outer box and its three boxes, `(min, max)` corners in metres.
const ROOM: ([f64; 3], [f64; 3]) = ([0.0, 0.0, 0.0], [8.0, 6.0, 2.5]);
const BOXES: [([f64; 3], [f64; 3]); 3] = [
    ([2.5, 0.5, 0.0], [3.5, 4.0, 2.0]), // a partition: pass it at y > 4
    ([5.0, 2.0, 0.0], [6.0, 5.5, 2.0]), // another: pass it at y < 2
    ([1.0, 3.5, 0.0], [1.8, 4.3, 0.8]), // a crate to fly over
];

/// The six quads of an axis-aligned box; the room's face inward, the boxes' outward (a map
/// does not care, a viewer does).
fn add_box(
    vertices: &mut Vec<Point3>,
    faces: &mut Vec<Vec<u32>>,
    (lo, hi): ([f64; 3], [f64; 3]),
    inward: bool,
) {
    let base = vertices.len() as u32;
    for i in 0..8 {
        let pick = |axis: usize| if i >> axis & 1 == 0 { lo[axis] } else { hi[axis] };
        vertices.push(Point3::new(pick(0), pick(1), pick(2)));
    }
    // Corner indices of each face, counter-clockwise seen from outside.
    let quads =
        [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    for q in quads {
        let mut face: Vec<u32> = q.iter().map(|&c| base + c).collect();
        if inward {
            face.reverse();
        }
        faces.push(face);
    }
}

fn room_obj() -> Vec<u8> {
    let (mut vertices, mut faces) = (Vec::new(), Vec::new());
    add_box(&mut vertices, &mut faces, ROOM, true);
    for b in BOXES {
        add_box(&mut vertices, &mut faces, b, false);
    }
    let mesh = PolygonMesh::new(vertices, faces).unwrap();
    let mut obj =
        b"# An 8 m x 6 m x 2.5 m room, two partitions and a crate: tests/it/example_data.rs\n"
            .to_vec();
    write_obj(&mut obj, &mesh.triangulated()).unwrap();
    obj
}

#[test]
fn room_obj_is_current() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data/room.obj");
    let obj = room_obj();
    if std::env::var_os("UPDATE_EXAMPLE_DATA").is_some() {
        std::fs::write(&path, &obj).unwrap();
    }
    let committed = std::fs::read(&path).unwrap_or_default();
    assert!(
        committed == obj,
        "{} is stale: run `UPDATE_EXAMPLE_DATA=1 cargo test -p patchnav-roadmap --test it example_data::`",
        path.display()
    );
}
