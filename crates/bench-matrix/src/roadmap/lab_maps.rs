//! The lab's four maps built from simulated scans (thesis §6.1, Table 6.1, Fig 6.4), read from
//! a folder of map files: `planes.pmap`, `hybrid.pmap`, `trimesh.pmap` (patch maps of any
//! patch backend) and `pc.pmap` (a point-cloud map). `cargo xtask bench` writes that folder
//! with `patchnav map build --scene lab --kind K --source scans` and names it in
//! [`LAB_MAPS_ENV`]; the scan → extraction pipeline stays in `patchnav`.
//!
//! Each patch map is loaded into every patch backend (polygon, bbox6d, trimesh, rapier) from
//! its patches; the pc map only into the point-cloud backend (thesis §6.1: Algorithm 10 for
//! the raw clouds, L6576–6582). Every map samples in its own box (thesis L6460, as
//! `patchnav experiment lab-timing`): the box of its patches or points. The start is the
//! experiment's first corner start: the first point of the south-west spiral that is free on
//! all four maps and inside the box common to them
//! ([`patch_pipeline::experiment::lab::corner_starts`]).

use anyhow::{Context, Result, bail};
use patch_core::{Point3, Real};
use patch_map::{AnyMap, Backend, load_any};
use patch_pipeline::experiment::lab::{LAB_ROOM, common_box, corner_starts};
use patch_pipeline::scene_map::MapKind;
use pointcloud::Aabb;
use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

/// The environment variable naming the folder of map files (set by `cargo xtask bench`).
pub(crate) const LAB_MAPS_ENV: &str = "PATCHNAV_LAB_MAPS";
/// The prefix of the scenes planned on these maps: scene `lab-scans-<kind>`.
pub(crate) const SCENE_PREFIX: &str = "lab-scans-";
/// The map kind of a scene `lab-scans-<kind>`, if it is one.
pub(crate) fn kind_of(scene: &str) -> Option<MapKind> {
    scene.strip_prefix(SCENE_PREFIX)?.parse().ok()
}

/// Whether `backend` can hold a map of `kind`: the patch backends hold the patch maps, the
/// point-cloud map holds `pc`.
pub(crate) fn holds(backend: Backend, kind: MapKind) -> bool {
    backend.holds_patches() != (kind == MapKind::Pc)
}

/// The folder of map files named by [`LAB_MAPS_ENV`], if set.
pub(crate) fn folder_from_env() -> Option<PathBuf> {
    std::env::var_os(LAB_MAPS_ENV).filter(|v| !v.is_empty()).map(PathBuf::from)
}

/// The four maps as read from their files, and the start common to them.
pub(crate) struct LabMaps {
    /// The folder they came from (its name goes into every row as `lab_maps`).
    pub folder: PathBuf,
    /// Per kind of [`MapKind::ALL`] (the thesis's map types, Table 6.1), the map as its file holds it (`None` once taken).
    maps: Vec<(MapKind, Option<AnyMap>)>,
    /// Per kind, the box the map samples in.
    bounds: Vec<(MapKind, Aabb)>,
    /// The RRT's start: free on all four maps.
    pub start: Point3,
}

/// The path of the map file of `kind` in `folder`: `<kind>.pmap`.
pub(crate) fn map_path(folder: &Path, kind: MapKind) -> PathBuf {
    folder.join(format!("{kind}.pmap"))
}

/// Reads the four map files of `folder` and finds the start (robot `radius`).
///
/// # Errors
/// A missing or unreadable file (named), a pc file that is not a point-cloud map or a patch
/// file that is, an empty map, or no free start near the south-west corner.
pub(crate) fn load(folder: &Path, radius: Real) -> Result<LabMaps> {
    let mut maps = Vec::new();
    let mut bounds = Vec::new();
    for kind in MapKind::ALL {
        let path = map_path(folder, kind);
        let file = File::open(&path).with_context(|| {
            format!(
                "opening {} (build it with `patchnav map build --scene lab --kind {kind} \
                 --source scans`, or run `cargo xtask bench roadmap`)",
                path.display()
            )
        })?;
        let map = load_any(BufReader::new(file))
            .with_context(|| format!("reading {}", path.display()))?;
        match (kind, &map) {
            (MapKind::Pc, AnyMap::PointCloud(_)) => {}
            (MapKind::Pc, other) => bail!(
                "{}: the pc map must be a point-cloud map, not a `{}` map",
                path.display(),
                other.backend()
            ),
            (_, AnyMap::PointCloud(_)) => {
                bail!("{}: the {kind} map must be a patch map, not a point cloud", path.display())
            }
            _ => {}
        }
        let b = map.bounds();
        if b.is_empty() {
            bail!("{}: the {kind} map is empty", path.display());
        }
        maps.push((kind, Some(map)));
        bounds.push((kind, b));
    }
    let common = common_box(bounds.iter().map(|(_, b)| *b));
    let all: Vec<&AnyMap> = maps.iter().filter_map(|(_, m)| m.as_ref()).collect();
    let start = corner_starts(&all, &common, radius, LAB_ROOM, 1)
        .with_context(|| format!("the maps of {}", folder.display()))?[0];
    Ok(LabMaps { folder: folder.to_owned(), maps, bounds, start })
}

impl LabMaps {
    /// The box the map of `kind` samples in.
    pub(crate) fn bounds(&self, kind: MapKind) -> Result<Aabb> {
        self.bounds.iter().find(|(k, _)| *k == kind).map(|(_, b)| *b).context("no such map kind")
    }

    /// The map of `kind` in each of `backends` that can hold it (in the order of
    /// `backends`); the file's own map is moved into the backend it was saved in, the others
    /// are built from its patches. Takes the map: a second call for `kind` is an error.
    pub(crate) fn take_maps(
        &mut self,
        kind: MapKind,
        backends: &[Backend],
    ) -> Result<Vec<(Backend, AnyMap)>> {
        let slot = self.maps.iter_mut().find(|(k, _)| *k == kind).context("no such map kind")?;
        let mut own =
            Some(slot.1.take().with_context(|| format!("the {kind} map was already used"))?);
        let patches = own.as_ref().and_then(AnyMap::patches).map(<[_]>::to_vec);
        let mut out = Vec::new();
        for &backend in backends.iter().filter(|&&b| holds(b, kind)) {
            let map = match own.take_if(|m| m.backend() == backend) {
                Some(map) => map,
                None => {
                    let patches = patches.clone().context("a point-cloud map has no patches")?;
                    AnyMap::from_patches(backend, patches, None).with_context(|| {
                        format!("a {kind} map cannot be held by the `{backend}` backend")
                    })?
                }
            };
            out.push((backend, map));
        }
        Ok(out)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use patch_core::{FromPatches, PlanarPatch, TrimeshPatch};
    use patch_map::{
        BBox6dMap, MapFile, PointCloudMap, PolygonMap, TrimeshMap, sample_patch_points,
    };

    /// A fresh folder under the system's temporary folder, removed on drop.
    pub(crate) struct TempDir(pub PathBuf);

    impl TempDir {
        pub(crate) fn new(name: &str) -> TempDir {
            let dir =
                std::env::temp_dir().join(format!("bench-matrix-{name}-{}", std::process::id()));
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir_all(&dir).unwrap();
            TempDir(dir)
        }
    }

    impl Drop for TempDir {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    fn p(x: Real, y: Real, z: Real) -> Point3 {
        Point3::new(x, y, z)
    }

    /// A 4 × 4 m floor and a 2 m wall along x = 4, as planar patches.
    fn room() -> Vec<patch_core::Patch> {
        let floor = [p(0.0, 0.0, 0.0), p(4.0, 0.0, 0.0), p(4.0, 4.0, 0.0), p(0.0, 4.0, 0.0)];
        let wall = [p(4.0, 0.0, 0.0), p(4.0, 4.0, 0.0), p(4.0, 4.0, 2.0), p(4.0, 0.0, 2.0)];
        [floor, wall]
            .iter()
            .map(|r| PlanarPatch::from_world_polygon(r, &[], 1e-9).unwrap().into())
            .collect()
    }

    /// The same room as triangle meshes.
    fn room_mesh() -> Vec<patch_core::Patch> {
        let quad = |v: [Point3; 4]| {
            TrimeshPatch::new(v.to_vec(), vec![[0, 1, 2], [0, 2, 3]]).unwrap().into()
        };
        vec![
            quad([p(0.0, 0.0, 0.0), p(4.0, 0.0, 0.0), p(4.0, 4.0, 0.0), p(0.0, 4.0, 0.0)]),
            quad([p(4.0, 0.0, 0.0), p(4.0, 4.0, 0.0), p(4.0, 4.0, 2.0), p(4.0, 0.0, 2.0)]),
        ]
    }

    fn save(map: &impl MapFile, path: &Path) {
        map.save(std::io::BufWriter::new(File::create(path).unwrap())).unwrap();
    }

    /// Writes the four tiny maps into `dir`: planes as a polygon map, hybrid (planes + a
    /// triangle) as a bbox6d map, trimesh as a trimesh map, pc as sampled points.
    pub(crate) fn write_tiny_maps(dir: &Path) {
        save(&PolygonMap::from_patches(room()).unwrap(), &dir.join("planes.pmap"));
        let mut hybrid = room();
        hybrid.push(
            TrimeshPatch::new(
                vec![p(2.0, 2.0, 0.5), p(2.5, 2.0, 0.5), p(2.0, 2.5, 0.9)],
                vec![[0, 1, 2]],
            )
            .unwrap()
            .into(),
        );
        save(&BBox6dMap::from_patches(hybrid).unwrap(), &dir.join("hybrid.pmap"));
        save(&TrimeshMap::from_patches(room_mesh()).unwrap(), &dir.join("trimesh.pmap"));
        let points = sample_patch_points(&room(), 0.05).unwrap();
        save(&PointCloudMap::from_points(&points).unwrap(), &dir.join("pc.pmap"));
    }

    #[test]
    fn maps_load_into_every_backend_that_can_hold_them() {
        let dir = TempDir::new("lab-maps-load");
        write_tiny_maps(&dir.0);
        let mut maps = load(&dir.0, 0.3).unwrap();
        // The start lies inside every map's box and is free on all four.
        assert_eq!(maps.start, p(0.6, 0.6, 1.0));
        assert!(maps.bounds(MapKind::Pc).unwrap().max.z > 1.9);
        let all = Backend::ALL;
        let hybrid = maps.take_maps(MapKind::Hybrid, &all).unwrap();
        let names: Vec<Backend> = hybrid.iter().map(|m| m.0).collect();
        assert_eq!(
            names,
            Backend::patch_backends().collect::<Vec<_>>(),
            "patch maps in the four patch backends"
        );
        for (backend, map) in &hybrid {
            assert_eq!(map.backend(), *backend);
            assert_eq!(map.patches().unwrap().len(), 3, "{backend}");
        }
        assert!(maps.take_maps(MapKind::Hybrid, &all).is_err(), "taken once");
        let pc = maps.take_maps(MapKind::Pc, &all).unwrap();
        assert_eq!(pc.len(), 1);
        assert_eq!(pc[0].1.backend(), Backend::PointCloud);
        assert!(maps.take_maps(MapKind::Planes, &[Backend::PointCloud]).unwrap().is_empty());
        assert_eq!(kind_of("lab-scans-pc"), Some(MapKind::Pc));
        assert_eq!(kind_of("lab-scans-moon"), None);
        assert_eq!(kind_of("lab"), None);
    }

    #[test]
    fn missing_and_mismatched_files_are_clear_errors() {
        let dir = TempDir::new("lab-maps-bad");
        write_tiny_maps(&dir.0);
        std::fs::remove_file(dir.0.join("trimesh.pmap")).unwrap();
        let e = format!("{:#}", load(&dir.0, 0.3).err().unwrap());
        assert!(e.contains("trimesh.pmap"), "{e}");
        // A patch map where the pc map belongs.
        std::fs::copy(dir.0.join("planes.pmap"), dir.0.join("trimesh.pmap")).unwrap();
        std::fs::copy(dir.0.join("planes.pmap"), dir.0.join("pc.pmap")).unwrap();
        let e = format!("{:#}", load(&dir.0, 0.3).err().unwrap());
        assert!(e.contains("point-cloud map"), "{e}");
        // A truncated file.
        write_tiny_maps(&dir.0);
        let bytes = std::fs::read(dir.0.join("hybrid.pmap")).unwrap();
        std::fs::write(dir.0.join("hybrid.pmap"), &bytes[..bytes.len() / 2]).unwrap();
        let e = format!("{:#}", load(&dir.0, 0.3).err().unwrap());
        assert!(e.contains("hybrid.pmap"), "{e}");
        // No free start: a robot too large for the room.
        write_tiny_maps(&dir.0);
        assert!(load(&dir.0, 5.0).is_err());
    }
}
