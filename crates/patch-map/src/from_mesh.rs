//! Planar patches from a triangle mesh: the coplanar faces of a mesh become planar patches
//! (polygons with holes on their plane), the input `patchnav map build` takes from an OBJ file.
//!
//! # Method
//! 1. Faces are split into triangles (fans). Triangles with an area below
//!    [`MeshToPatchesConfig::min_triangle_area`] are dropped (and counted).
//! 2. Triangles are clustered by plane: a triangle joins the first cluster whose plane it
//!    matches (normals within `max_angle` of each other in either orientation — meshes need not
//!    be consistently oriented — and its vertices within `max_distance` of the plane), else it
//!    starts a cluster. `O(T · C)` for `T` triangles and `C` planes.
//! 3. Each cluster's triangles are projected into the 2D frame of its plane and united with
//!    `geo`'s boolean operations (`unary_union`), which also merges triangles that meet along
//!    T-junctions (common in exported meshes: a wall split around a door). Every polygon of the
//!    union (outer ring and holes) becomes a [`PlanarPatch`] in the cluster's frame.
//! 4. A union polygon that patch validation refuses (it can touch itself at a vertex) is kept
//!    exactly as a [`TrimeshPatch`] of the cluster triangles whose centroids it covers, and
//!    counted as a fallback.
//!
//! The union moves vertices by at most the float overlay's snapping (about 1e-9 of the
//! cluster's extent); no area is lost or added beyond that.
//!
//! [`map_from_obj`] does all of it for an OBJ file and builds a map of any backend:
//!
//! ```no_run
//! use patch_map::{BBox6dMap, map_from_obj};
//! let map: BBox6dMap = map_from_obj("floorplan.obj")?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use geo::{Contains, Coord, LineString, MultiPolygon, Polygon as GeoPolygon, unary_union};
use patch_core::{
    FromPatches, Isometry3, Patch, PlanarPatch, Point2, Point3, Polygon, Real, TrimeshPatch,
    Vector3, plane_frame,
};
use pointcloud::PolygonMesh;
use std::path::Path;

/// Parameters of [`planar_patches_from_mesh`]. No `Default`: the tolerances depend on the
/// mesh's units and noise; [`MeshToPatchesConfig::exact_cad`] suits exported CAD or synthetic
/// meshes in metres.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct MeshToPatchesConfig {
    /// Largest angle between the normal of a triangle and its cluster's plane, radians.
    pub max_angle: Real,
    /// Largest distance of a triangle's vertices from its cluster's plane, metres.
    pub max_distance: Real,
    /// Triangles smaller than this (m²) are dropped as degenerate.
    pub min_triangle_area: Real,
}

impl MeshToPatchesConfig {
    /// For meshes whose planar parts are exactly planar (CAD, synthetic scenes): 0.1°, 1 mm.
    pub fn exact_cad() -> MeshToPatchesConfig {
        MeshToPatchesConfig {
            max_angle: 0.1f64.to_radians(),
            max_distance: 1e-3,
            min_triangle_area: 1e-12,
        }
    }
}

/// What [`planar_patches_from_mesh`] made of a mesh.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct MeshToPatchesStats {
    /// Planar patches made.
    pub planar_patches: usize,
    /// Trimesh patches made where a union polygon was not a valid patch polygon.
    pub trimesh_fallbacks: usize,
    /// Triangles dropped as degenerate (zero area, repeated vertices).
    pub degenerate_triangles: usize,
}

/// A plane with its 2D frame: `world_from_plane` maps (x, y, 0) onto the plane.
struct Cluster {
    world_from_plane: Isometry3,
    normal: Vector3,
    offset: Real,
    triangles: Vec<[Point3; 3]>,
}

impl Cluster {
    fn new(tri: [Point3; 3], normal: Vector3) -> Cluster {
        // The frame every patch of this plane gets (`patch_core::plane_frame`).
        let world_from_plane = plane_frame(&normal, &tri[0]);
        Cluster {
            world_from_plane,
            normal,
            offset: normal.dot(&tri[0].coords),
            triangles: vec![tri],
        }
    }

    fn accepts(&self, tri: &[Point3; 3], normal: &Vector3, config: &MeshToPatchesConfig) -> bool {
        self.normal.dot(normal).abs() >= config.max_angle.cos()
            && tri
                .iter()
                .all(|p| (self.normal.dot(&p.coords) - self.offset).abs() <= config.max_distance)
    }

    fn local(&self, p: &Point3) -> Point2 {
        let l = self.world_from_plane.inverse_transform_point(p);
        Point2::new(l.x, l.y)
    }
}

/// Turns `mesh` into patches (see the module docs); returns the patches and what happened.
pub fn planar_patches_from_mesh(
    mesh: &PolygonMesh,
    config: &MeshToPatchesConfig,
) -> (Vec<Patch>, MeshToPatchesStats) {
    let mut stats = MeshToPatchesStats::default();
    let vertices = mesh.vertices();
    let mut clusters: Vec<Cluster> = Vec::new();
    for t in mesh.triangles() {
        let tri = [vertices[t[0] as usize], vertices[t[1] as usize], vertices[t[2] as usize]];
        let cross = (tri[1] - tri[0]).cross(&(tri[2] - tri[0]));
        let area = cross.norm() / 2.0;
        if !area.is_finite() || area <= config.min_triangle_area {
            stats.degenerate_triangles += 1;
            continue;
        }
        let normal = cross / (2.0 * area);
        match clusters.iter_mut().find(|c| c.accepts(&tri, &normal, config)) {
            Some(c) => c.triangles.push(tri),
            None => clusters.push(Cluster::new(tri, normal)),
        }
    }
    let mut patches = Vec::new();
    for cluster in &clusters {
        let flat: Vec<GeoPolygon<Real>> = cluster
            .triangles
            .iter()
            .map(|tri| {
                let mut ring: Vec<Coord<Real>> = tri
                    .iter()
                    .map(|p| {
                        let q = cluster.local(p);
                        Coord { x: q.x, y: q.y }
                    })
                    .collect();
                let [a, b, c] = [ring[0], ring[1], ring[2]];
                if (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y) < 0.0 {
                    ring.swap(1, 2); // counter-clockwise, as the union's fill rule expects
                }
                GeoPolygon::new(LineString::from(ring), Vec::new())
            })
            .collect();
        let union: MultiPolygon<Real> = unary_union(&flat);
        for poly in &union.0 {
            match planar_patch(cluster, poly) {
                Some(p) => {
                    stats.planar_patches += 1;
                    patches.push(Patch::Planar(p));
                }
                None => {
                    let covered: Vec<[Point3; 3]> = cluster
                        .triangles
                        .iter()
                        .zip(&flat)
                        .filter(|(_, f)| {
                            let c = geo::Centroid::centroid(*f);
                            c.is_some_and(|c| poly.contains(&c))
                        })
                        .map(|(t, _)| *t)
                        .collect();
                    if let Some(m) = trimesh_of(&covered) {
                        stats.trimesh_fallbacks += 1;
                        patches.push(Patch::Trimesh(m));
                    }
                }
            }
        }
    }
    (patches, stats)
}

/// Why [`map_from_obj`] failed; `E` is the backend's [`FromPatches::Error`].
#[derive(Debug, thiserror::Error)]
pub enum ObjMapError<E: std::error::Error + 'static> {
    /// The OBJ file could not be read (the error names the file and the line).
    #[error(transparent)]
    Read(#[from] pointcloud::io::Error),
    /// The backend refused the patches.
    #[error("building the map: {0}")]
    Build(#[source] E),
}

/// Reads the OBJ mesh at `path` ([`pointcloud::io::read_mesh`]), turns its faces into patches
/// with [`MeshToPatchesConfig::exact_cad`] ([`planar_patches_from_mesh`]) and builds a map of
/// backend `M` from them: what `patchnav map build` does with an OBJ file. For other
/// tolerances, or to see the [`MeshToPatchesStats`], call those two functions yourself.
///
/// # Errors
/// [`ObjMapError::Read`] if the file cannot be read or is not a valid OBJ mesh,
/// [`ObjMapError::Build`] if the backend refuses a patch.
pub fn map_from_obj<M: FromPatches>(path: impl AsRef<Path>) -> Result<M, ObjMapError<M::Error>> {
    let mesh = pointcloud::io::read_mesh(path.as_ref())?;
    let (patches, _) = planar_patches_from_mesh(&mesh, &MeshToPatchesConfig::exact_cad());
    M::from_patches(patches).map_err(ObjMapError::Build)
}

fn ring_points(ring: &LineString<Real>) -> Vec<Point2> {
    let mut pts: Vec<Point2> = ring.coords().map(|c| Point2::new(c.x, c.y)).collect();
    if pts.len() > 1 && pts.first() == pts.last() {
        pts.pop();
    }
    pts
}

fn planar_patch(cluster: &Cluster, poly: &GeoPolygon<Real>) -> Option<PlanarPatch> {
    let outer = ring_points(poly.exterior());
    let holes = poly.interiors().iter().map(ring_points).collect();
    let polygon = Polygon::new(outer, holes).ok()?;
    PlanarPatch::new(polygon, cluster.world_from_plane).ok()
}

fn trimesh_of(triangles: &[[Point3; 3]]) -> Option<TrimeshPatch> {
    let vertices: Vec<Point3> = triangles.iter().flatten().copied().collect();
    let indices = (0..triangles.len() as u32).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
    TrimeshPatch::new(vertices, indices).ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use patch_core::{BruteForceMap, FromPatches, PatchMap, ProximityQuery};

    fn quad(mesh_v: &mut Vec<Point3>, faces: &mut Vec<Vec<u32>>, c: [[f64; 3]; 4]) {
        let base = mesh_v.len() as u32;
        mesh_v.extend(c.iter().map(|p| Point3::new(p[0], p[1], p[2])));
        faces.push(vec![base, base + 1, base + 2]);
        faces.push(vec![base, base + 2, base + 3]);
    }

    #[test]
    fn a_floor_of_two_triangles_becomes_one_rectangle() {
        let mut v = Vec::new();
        let mut f = Vec::new();
        quad(&mut v, &mut f, [[0., 0., 0.], [4., 0., 0.], [4., 3., 0.], [0., 3., 0.]]);
        let mesh = PolygonMesh::new(v, f).unwrap();
        let (patches, stats) = planar_patches_from_mesh(&mesh, &MeshToPatchesConfig::exact_cad());
        assert_eq!(stats.planar_patches, 1);
        assert_eq!(patches.len(), 1);
        let p = patches[0].as_planar().unwrap();
        assert!((p.area() - 12.0).abs() < 1e-6);
        assert_eq!(p.polygon().num_vertices(), 4, "the diagonal disappears in the union");
    }

    #[test]
    fn a_wall_with_a_door_keeps_the_hole_and_distances() {
        // A 6 × 3 wall in the plane y = 0 around a 1 × 2 door, as three quads meeting in
        // T-junctions (as exporters write walls split around openings), plus a degenerate quad.
        let mut v = Vec::new();
        let mut f = Vec::new();
        let q = |x0: f64, x1: f64, z0: f64, z1: f64| {
            [[x0, 0., z0], [x1, 0., z0], [x1, 0., z1], [x0, 0., z1]]
        };
        quad(&mut v, &mut f, q(0., 2.5, 0., 3.));
        quad(&mut v, &mut f, q(3.5, 6., 0., 3.));
        quad(&mut v, &mut f, q(2.5, 3.5, 2., 3.));
        quad(&mut v, &mut f, q(2.5, 3.5, 0., 0.0) /* degenerate: zero height */);
        let mesh = PolygonMesh::new(v, f).unwrap();
        let (patches, stats) = planar_patches_from_mesh(&mesh, &MeshToPatchesConfig::exact_cad());
        assert_eq!(stats.degenerate_triangles, 2);
        assert_eq!(patches.len(), 1, "{stats:?}");
        let p = patches[0].as_planar().unwrap();
        // The door is open at the floor, so it is a notch of the outer ring, not a hole.
        assert!((p.area() - 16.0).abs() < 1e-6);
        let map = BruteForceMap::from_patches(patches).unwrap();
        let through_door = map.closest_patch(&Point3::new(3.0, 0.0, 1.0), 10.0).unwrap();
        assert!((through_door.distance - 0.5).abs() < 1e-6);
    }

    #[test]
    fn a_window_becomes_a_hole_and_folds_become_separate_patches() {
        // A 4 × 4 square in z = 0 with a 2 × 2 window, plus a perpendicular flap sharing an edge.
        let mut v = Vec::new();
        let mut f = Vec::new();
        let z0 = |x0: f64, x1: f64, y0: f64, y1: f64| {
            [[x0, y0, 0.], [x1, y0, 0.], [x1, y1, 0.], [x0, y1, 0.]]
        };
        quad(&mut v, &mut f, z0(0., 4., 0., 1.));
        quad(&mut v, &mut f, z0(0., 4., 3., 4.));
        quad(&mut v, &mut f, z0(0., 1., 1., 3.));
        quad(&mut v, &mut f, z0(3., 4., 1., 3.));
        quad(&mut v, &mut f, [[0., 0., 0.], [4., 0., 0.], [4., 0., 2.], [0., 0., 2.]]);
        let mesh = PolygonMesh::new(v, f).unwrap();
        let (patches, stats) = planar_patches_from_mesh(&mesh, &MeshToPatchesConfig::exact_cad());
        assert_eq!(stats.planar_patches, 2, "{stats:?}");
        let with_hole = patches
            .iter()
            .filter_map(|p| p.as_planar())
            .find(|p| !p.polygon().holes().is_empty())
            .expect("the window is a hole");
        assert!((with_hole.area() - 12.0).abs() < 1e-6);
    }

    #[test]
    fn touching_corners_fall_back_to_a_trimesh_patch() {
        // Two triangles meeting at a single vertex in one plane: not a simple polygon.
        let v = vec![
            Point3::new(0., 0., 0.),
            Point3::new(1., 0., 0.),
            Point3::new(0., 1., 0.),
            Point3::new(-1., 0., 0.),
            Point3::new(0., -1., 0.),
        ];
        let mesh = PolygonMesh::new(v, vec![vec![0, 1, 2], vec![0, 3, 4]]).unwrap();
        let (patches, stats) = planar_patches_from_mesh(&mesh, &MeshToPatchesConfig::exact_cad());
        // Not edge-connected, so two groups, each a plain triangle.
        assert_eq!(stats.planar_patches, 2);
        assert_eq!(patches.len(), 2);
        // Two triangles sharing an edge and a third touching at a vertex of that pair.
        let v = vec![
            Point3::new(0., 0., 0.),
            Point3::new(2., 0., 0.),
            Point3::new(1., 1., 0.),
            Point3::new(0., 2., 0.),
            Point3::new(2., 2., 0.),
            Point3::new(1., 3., 0.),
        ];
        let faces = vec![vec![0, 1, 2], vec![2, 3, 0], vec![2, 4, 5], vec![2, 5, 3]];
        let mesh = PolygonMesh::new(v, faces).unwrap();
        let (patches, stats) = planar_patches_from_mesh(&mesh, &MeshToPatchesConfig::exact_cad());
        let triangles: usize = patches.iter().map(|p| p.num_triangles_hint()).sum();
        assert!(triangles >= 4, "nothing is lost: {stats:?}");
    }

    #[test]
    fn map_from_obj_reads_any_backend_and_names_bad_files() {
        // A unit square split into two triangles, and a wall standing on one of its edges.
        let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\n\
                   f 1 2 3\nf 1 3 4\nf 1 2 6 5\n";
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("corner.obj");
        std::fs::write(&path, obj).unwrap();
        let polygons: crate::PolygonMap = map_from_obj(&path).unwrap();
        let trimesh: crate::TrimeshMap = map_from_obj(&path).unwrap();
        assert_eq!(polygons.len(), 2, "the floor's triangles are united, the wall is one patch");
        assert_eq!(trimesh.len(), 2);

        let missing = map_from_obj::<crate::BBox6dMap>(dir.path().join("missing.obj"));
        assert!(matches!(missing, Err(ObjMapError::Read(_))), "{missing:?}");
        std::fs::write(&path, "v 0 0 0\nf 1 2 3\n").unwrap();
        let err = map_from_obj::<crate::BBox6dMap>(&path).unwrap_err();
        assert!(err.to_string().contains("corner.obj"), "{err}");
    }
}
