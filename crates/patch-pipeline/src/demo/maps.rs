//! The lab scanned by the simulated ALRF and its four map types (thesis §6.1, Table 6.1):
//! patch extraction on the scans, every patch map loaded into every patch backend, the pc map
//! into the point-cloud backend, with the drawings and 3D files of each.

use super::{
    Files, MAX_DRAWN, SCAN_HEIGHT, Settings, decimate, p3mm, write_mesh_f32, write_ply_f32,
};
use crate::Progress;
use crate::results::{MapDrawing, MapRow, P3};
use crate::scene_map::{
    BuiltMap, MapKind, ScanSetup, extracted_patches, patch_map, planar_triangles, scan_clouds,
};
use anyhow::{Context, Result, bail};
use patch_core::triangulate::patch_triangles;
use patch_core::{Patch, Point3};
use patch_map::{AnyMap, Backend, PointCloudMap};
use pointcloud::PointCloud;
use scene_sim::Scene;
use std::io::{BufReader, BufWriter, Read, Seek, SeekFrom, Write};
use std::path::Path;
use std::time::Instant;

/// The backend each patch map type is planned on: the parry BVH (the role of the thesis's
/// Bullet maps). A trimesh map in `polygon` or `bbox6d` pays for every triangle of each
/// candidate patch (about 1.5 s per 300 RRT iterations on two scans' map, against 5 ms).
pub fn plan_backend(_kind: MapKind) -> Backend {
    Backend::Trimesh
}

/// The scanned lab (its scans are returned beside it by [`scan_lab`], for [`build_maps`] to
/// consume).
pub struct Lab {
    /// The scene.
    pub scene: Scene,
    /// Scanner positions.
    pub positions: Vec<Point3>,
    /// Points of all scans.
    pub points: usize,
}

/// Simulates the lab's ALRF scans and writes each (`scan-N.ply`, sensor frame with its pose):
/// the lab, and its organised scans in the sensor frame with their poses (the ±90° columns
/// dropped).
pub fn scan_lab(
    seed: u64,
    settings: &Settings,
    files: &mut Files,
) -> Result<(Lab, Vec<PointCloud>)> {
    let scene = scene_sim::lab(seed).context("building the lab scene")?;
    let setup =
        ScanSetup { scans: settings.scans, height: SCAN_HEIGHT, step_deg: None, seed, noise: 1.0 };
    let clouds = scan_clouds(&scene, &setup)?;
    let mut positions = Vec::with_capacity(clouds.len());
    let mut points = 0;
    for (i, cloud) in clouds.iter().enumerate() {
        let pose = cloud.sensor_pose().context("a simulated scan has its pose")?;
        positions.push(Point3::from(pose.world_from_sensor.translation.vector));
        points += cloud.positions().len();
        let name = format!("scan-{}.ply", i + 1);
        write_ply_f32(&files.path(&name), cloud)?;
        files.add(format!("ALRF scan {} (sensor frame, with its pose)", i + 1), &name)?;
    }
    Ok((Lab { scene, positions, points }, clouds))
}

/// Everything built from the scans.
pub struct Built {
    /// One map per type, in the planning backend.
    pub maps: Vec<BuiltMap>,
    /// Table 6.1 rows.
    pub rows: Vec<MapRow>,
    /// Drawings per map type.
    pub drawings: Vec<MapDrawing>,
}

/// The Table 6.1 row of a patch map of `kind` (its backend's tag from `map`), with the counts
/// of [`patch_counts`]; the file size is that of the map file it would save.
pub fn patch_map_row(
    kind: MapKind,
    map: &AnyMap,
    (planar, trimesh, triangles): (usize, usize, usize),
    build_seconds: f64,
) -> Result<MapRow> {
    Ok(MapRow {
        kind: kind.name().to_owned(),
        backend: map.backend().to_string(),
        planar_patches: planar,
        trimesh_patches: trimesh,
        triangles,
        points: 0,
        memory_bytes: map.memory_bytes(),
        file_bytes: map.save(std::io::sink())?,
        build_seconds,
    })
}

/// Planar patches, trimesh patches, and triangles in all (planar patches triangulated), for
/// Table 6.1.
pub fn patch_counts(patches: &[Patch]) -> Result<(usize, usize, usize)> {
    let (mut planar, mut trimesh, mut triangles) = (0, 0, 0);
    for p in patches {
        match p {
            Patch::Planar(p) => {
                planar += 1;
                triangles += planar_triangles(p)?.1.len();
            }
            Patch::Trimesh(m) => {
                trimesh += 1;
                triangles += m.num_triangles();
            }
        }
    }
    Ok((planar, trimesh, triangles))
}

/// Simplifies `triangles` by vertex clustering for the pictures: vertices snapped to the centre
/// of mass of their cell of a cubic grid, collapsed and repeated triangles dropped, the cell
/// doubled from 5 cm until at most `budget` remain (then thinned evenly). A coarse but complete
/// surface, unlike every n-th triangle. `triangles` makes the input afresh for each pass, so a
/// map of millions of triangles is never copied whole.
fn cluster_triangles<I: Iterator<Item = [P3; 3]>>(
    triangles: impl Fn() -> I,
    budget: usize,
) -> Vec<[P3; 3]> {
    use std::collections::{HashMap, HashSet};
    let mut cell = 0.05;
    loop {
        let key = |q: &P3| q.map(|c| (c / cell).floor() as i64);
        let mut sums: HashMap<[i64; 3], ([f64; 3], f64)> = HashMap::new();
        for q in triangles().flatten() {
            let e = sums.entry(key(&q)).or_insert(([0.0; 3], 0.0));
            (0..3).for_each(|i| e.0[i] += q[i]);
            e.1 += 1.0;
        }
        let mut seen = HashSet::new();
        let mut out = Vec::new();
        for t in triangles() {
            let k = t.map(|q| key(&q));
            if k[0] == k[1] || k[1] == k[2] || k[0] == k[2] {
                continue;
            }
            let mut sorted = k;
            sorted.sort();
            if seen.insert(sorted) {
                out.push(k.map(|c| {
                    let (sum, n) = sums[&c];
                    p3mm_raw(sum.map(|v| v / n))
                }));
            }
        }
        if out.len() <= budget || cell > 5.0 {
            return decimate(&out, budget);
        }
        cell *= 2.0;
    }
}

/// Rounds to millimetres, as [`p3mm`] does.
fn p3mm_raw(q: P3) -> P3 {
    q.map(|c| (c * 1000.0).round() / 1000.0)
}

/// The drawing of patches: outlines of planar patches, triangles of trimesh patches
/// (simplified by clustering the triangles).
pub fn drawing(kind: MapKind, patches: &[Patch]) -> MapDrawing {
    let polygons: Vec<_> = patches
        .iter()
        .filter_map(|patch| match patch {
            Patch::Planar(p) => {
                Some(p.polygon().outer().points().iter().map(|q| p3mm(&p.to_world(q))).collect())
            }
            Patch::Trimesh(_) => None,
        })
        .collect();
    let triangles = || {
        patches
            .iter()
            .filter_map(|patch| match patch {
                Patch::Trimesh(m) => Some(m),
                Patch::Planar(_) => None,
            })
            .flat_map(|m| {
                let v = m.vertices();
                m.triangles().iter().map(move |t| t.map(|i| p3mm(&v[i as usize])))
            })
    };
    MapDrawing {
        kind: kind.name().to_owned(),
        polygons: decimate(&polygons, MAX_DRAWN),
        triangles: cluster_triangles(triangles, MAX_DRAWN),
        points: Vec::new(),
    }
}

/// The patches as one triangle mesh: planar patches triangulated, trimesh patches with their
/// shared vertices.
pub fn patch_mesh(patches: &[Patch]) -> Result<(Vec<Point3>, Vec<[u32; 3]>)> {
    let mut vertices: Vec<Point3> = Vec::new();
    let mut faces: Vec<[u32; 3]> = Vec::new();
    for (i, patch) in patches.iter().enumerate() {
        let base = u32::try_from(vertices.len()).context("more than 2³² vertices")?;
        match patch {
            Patch::Planar(_) => {
                for tri in
                    patch_triangles(patch).with_context(|| format!("triangulating patch {i}"))?
                {
                    let b = u32::try_from(vertices.len()).context("more than 2³² vertices")?;
                    vertices.extend(tri);
                    faces.push([b, b + 1, b + 2]);
                }
            }
            Patch::Trimesh(m) => {
                vertices.extend_from_slice(m.vertices());
                faces.extend(m.triangles().iter().map(|t| t.map(|k| base + k)));
            }
        }
    }
    Ok((vertices, faces))
}

/// Extracts the planes, hybrid and trimesh maps' patches from the scans `clouds` (of
/// [`scan_lab`]), loads each into every patch backend (keeping the planning backend's), builds
/// the pc map, and writes each map's 3D file (`map-KIND.ply`). The scans are dropped once the
/// last kind's patches and the pc map's points are taken from them, before that kind's maps
/// are built (the demo's memory peak).
pub fn build_maps(
    clouds: Vec<PointCloud>,
    progress: &dyn Progress,
    files: &mut Files,
) -> Result<Built> {
    let kinds = [MapKind::Planes, MapKind::Hybrid, MapKind::Trimesh];
    let bar =
        progress.bar((kinds.len() * (Backend::patch_backends().count() + 1) + 1) as u64, "maps");
    let mut built = Built { maps: Vec::new(), rows: Vec::new(), drawings: Vec::new() };
    // The scans until their last use (the last kind's extraction), then the pc map's points
    // taken from them (and the seconds that took).
    let mut clouds = Some(clouds);
    let mut pc = None;
    for kind in kinds {
        let t0 = Instant::now();
        let scans = clouds.as_ref().context("the scans are kept until the last extraction")?;
        let patches = extracted_patches(scans, kind)
            .with_context(|| format!("extracting the {kind} map"))?
            .context("a patch map has patches")?;
        let extraction = t0.elapsed().as_secs_f64();
        if Some(&kind) == kinds.last() {
            let t0 = Instant::now();
            let points: Vec<Point3> = crate::scene_map::pc_points(scans, &Default::default())?;
            let gathered = t0.elapsed().as_secs_f64();
            pc = Some((ParkedPoints::park(points, &files.path(""))?, scans.len(), gathered));
            clouds = None;
        }
        bar.inc(1);
        let (planar, trimesh, triangles) = patch_counts(&patches)?;
        built.drawings.push(drawing(kind, &patches));
        let name = format!("map-{kind}.ply");
        let (vertices, faces) = patch_mesh(&patches)?;
        write_mesh_f32(&files.path(&name), &vertices, &faces)?;
        drop((vertices, faces));
        files.add(
            format!(
                "{kind} map: {planar} planar patches (triangulated) and {trimesh} trimesh \
                 patches, PLY mesh"
            ),
            &name,
        )?;
        // One set of patches goes through every backend in turn (each map gives it back), the
        // planning backend's last, so no two maps and no copy of the patches are alive at once.
        let keep = plan_backend(kind);
        let mut patches = Some(patches);
        let mut rows = Vec::new();
        for backend in Backend::patch_backends().filter(|&b| b != keep).chain([keep]) {
            let input = patches.take().context("every map gives its patches back")?;
            let t1 = Instant::now();
            let map = patch_map(input, backend)
                .with_context(|| format!("loading the {kind} map into {}", backend.name()))?;
            let load = t1.elapsed().as_secs_f64();
            rows.push((
                backend,
                patch_map_row(kind, &map, (planar, trimesh, triangles), extraction + load)?,
            ));
            bar.inc(1);
            if backend == keep {
                built.maps.push(BuiltMap {
                    kind,
                    map,
                    planar_patches: planar,
                    trimesh_patches: trimesh,
                    triangles,
                    point_clouds: 0,
                    points: 0,
                });
            } else {
                patches = map.into_patches();
            }
        }
        // The rows in the backends' order.
        rows.sort_by_key(|(backend, _)| Backend::ALL.iter().position(|b| b == backend));
        built.rows.extend(rows.into_iter().map(|(_, row)| row));
    }
    let (parked, scans, gather_seconds) = pc.context("the pc points are taken")?;
    let cloud = PointCloud::from_positions(parked.take()?)?;
    let name = "map-pc.ply";
    write_ply_f32(&files.path(name), &cloud)?;
    files.add("pc map: the scans' points in the world frame", name)?;
    let points_len = cloud.len();
    let t0 = Instant::now();
    let map = AnyMap::PointCloud(PointCloudMap::from_point_vec(cloud.into_positions())?);
    let build_seconds = gather_seconds + t0.elapsed().as_secs_f64();
    let (row, drawing) = point_map_entry(&map, build_seconds)?;
    built.rows.push(row);
    built.drawings.push(drawing);
    built.maps.push(BuiltMap {
        kind: MapKind::Pc,
        map,
        planar_patches: 0,
        trimesh_patches: 0,
        triangles: 0,
        point_clouds: scans,
        points: points_len,
    });
    bar.inc(1);
    bar.finish_and_clear();
    Ok(built)
}

/// The Table 6.1 row and the drawing (at most [`MAX_DRAWN`] of its points) of a point-cloud
/// (`pc`) map built in `build_seconds` — shared by the demo and `patchnav run`.
///
/// # Errors
/// `map` not a point-cloud map.
pub fn point_map_entry(map: &AnyMap, build_seconds: f64) -> Result<(MapRow, MapDrawing)> {
    let AnyMap::PointCloud(pc) = map else {
        bail!("a `{}` map is not a point-cloud map", map.backend())
    };
    let row = MapRow {
        kind: MapKind::Pc.name().to_owned(),
        backend: map.backend().to_string(),
        planar_patches: 0,
        trimesh_patches: 0,
        triangles: 0,
        points: pc.len(),
        memory_bytes: map.memory_bytes(),
        file_bytes: map.save(std::io::sink())?,
        build_seconds,
    };
    let stride = pc.len().div_ceil(MAX_DRAWN).max(1);
    let drawing = MapDrawing {
        kind: MapKind::Pc.name().to_owned(),
        points: pc.points().step_by(stride).map(|p| p3mm(&p)).collect(),
        ..MapDrawing::default()
    };
    Ok((row, drawing))
}

/// Points waiting in an unnamed temporary file (exact `f64`s, removed when closed), so they
/// take no memory meanwhile: the demo parks the pc map's points while the trimesh map, its
/// memory peak, is built.
struct ParkedPoints {
    file: std::fs::File,
    len: usize,
}

impl ParkedPoints {
    /// Writes `points` to a temporary file in `dir` and frees them.
    fn park(points: Vec<Point3>, dir: &Path) -> Result<ParkedPoints> {
        let context = || format!("parking the pc points in a temporary file in {}", dir.display());
        let file = tempfile::tempfile_in(dir).with_context(context)?;
        let mut w = BufWriter::new(file);
        for p in &points {
            for c in [p.x, p.y, p.z] {
                w.write_all(&c.to_le_bytes()).with_context(context)?;
            }
        }
        let file = w.into_inner().map_err(|e| e.into_error()).with_context(context)?;
        Ok(ParkedPoints { file, len: points.len() })
    }

    /// The points, read back.
    fn take(self) -> Result<Vec<Point3>> {
        let context = || "reading the parked pc points back";
        let mut file = self.file;
        file.seek(SeekFrom::Start(0)).with_context(context)?;
        let mut r = BufReader::new(file);
        let mut points = Vec::with_capacity(self.len);
        let mut buf = [0u8; 24];
        for _ in 0..self.len {
            r.read_exact(&mut buf).with_context(context)?;
            let c =
                |k: usize| f64::from_le_bytes(buf[8 * k..8 * k + 8].try_into().expect("8 bytes"));
            points.push(Point3::new(c(0), c(1), c(2)));
        }
        Ok(points)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parked_points_come_back_exactly() {
        let dir = tempfile::tempdir().unwrap();
        let points = vec![
            Point3::new(0.1, -0.0, 1e-310),
            Point3::new(f64::MAX, f64::MIN_POSITIVE, -123_456.789_012_345),
            Point3::new(1.0 / 3.0, 2.0_f64.sqrt(), -1e300),
        ];
        let parked = ParkedPoints::park(points.clone(), dir.path()).unwrap();
        // The file is unnamed: nothing is left in the folder.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        let back = parked.take().unwrap();
        assert_eq!(back.len(), points.len());
        for (a, b) in back.iter().zip(&points) {
            for k in 0..3 {
                assert_eq!(a[k].to_bits(), b[k].to_bits());
            }
        }
        assert!(ParkedPoints::park(Vec::new(), dir.path()).unwrap().take().unwrap().is_empty());
    }

    #[test]
    fn parking_in_a_missing_folder_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("missing");
        let err = ParkedPoints::park(vec![Point3::origin()], &missing).err().unwrap();
        assert!(format!("{err:#}").contains("parking the pc points"), "{err:#}");
    }
}
