//! Map files and memory accounting for the backends of this crate.
//!
//! * [`MapFile`]: save a map to, and load it from, the container of [`mapfile`](crate::mapfile)
//!   (magic, version, backend tag, counts, CRC-32s, then the payload in bincode). Patch maps
//!   store their patches in id order (so ids survive the round trip) and rebuild their indices
//!   on load; the point-cloud map stores its points. Loading goes through the validating
//!   `Deserialize` impls of `patch-core`, so a file cannot smuggle in an invalid patch, and a
//!   file of another backend is [`MapFileError::BackendMismatch`].
//! * [`load_any`] reads whichever backend a file holds into an [`AnyMap`]; the header's tag is
//!   parsed as a [`Backend`] (its name).
//! * [`MemoryUsage`]: the heap bytes a map owns, counted from lengths and capacities
//!   (`patchnav map info` and the benchmarks report it).
//!
//! | backend | tag | payload | rebuilt on load |
//! |---|---|---|---|
//! | [`PolygonMap`] | `polygon` | patches | patch boxes, O(P·n) |
//! | [`BBox6dMap`] | `bbox6d` | patches | 6D k-d forest, O(P log P) |
//! | [`PointCloudMap`] | `pointcloud` | points | k-d trees, O(N log N) |
//! | [`TrimeshMap`] | `trimesh` | patches | triangulation, one parry mesh and BVH, O(n log n) for n triangles |
//! | [`RapierMap`] | `rapier` | patches | triangulation, one collider each, broad-phase insertions |

use std::io::{Read, Write};

use patch_core::{FromPatches, Patch, PatchMap, Point3, Real};

#[cfg(feature = "rapier")]
use crate::RapierMap;
pub use crate::any_map::AnyMap;
use crate::mapfile::{HEADER_LEN, MapCounts, MapFileError, read_header, read_map, write_map};
use crate::{BBox6dMap, Backend, PointCloudMap, PolygonMap, TrimeshMap};

/// A map that can be written to and read from a map file ([`mapfile`](crate::mapfile)).
pub trait MapFile: Sized {
    /// The backend; its [`name`](Backend::name) is the tag in the file header.
    const BACKEND: Backend;

    /// Writes the map; returns the number of bytes written.
    ///
    /// # Errors
    /// [`MapFileError::Io`] if the writer fails, [`MapFileError::Encode`] if the map cannot
    /// be encoded.
    fn save(&self, writer: impl Write) -> Result<u64, MapFileError>;

    /// Reads a map written by [`save`](Self::save) and rebuilds its indices.
    ///
    /// # Errors
    /// Every [`MapFileError`] of [`read_map`]: a file of another backend is
    /// [`MapFileError::BackendMismatch`]; a corrupt, truncated or newer file gets its own
    /// variant; a payload that decodes to invalid patches or points is
    /// [`MapFileError::Decode`].
    fn load(reader: impl Read) -> Result<Self, MapFileError>;

    /// What the map holds, as recorded in the file header.
    fn counts(&self) -> MapCounts;
}

/// The memory a map's own structures take.
pub trait MemoryUsage {
    /// The heap bytes the map owns (patches, points, indices), counted from the lengths and
    /// capacities of its buffers; `size_of_val(map)` itself is not included. Each
    /// implementation states what it cannot see.
    fn memory_bytes(&self) -> usize;
}

/// The heap bytes of one patch: its vertex, hole and triangle buffers, by capacity
/// ([`Patch::heap_bytes`]). The patch value itself (the enum with its transform and covariance)
/// lives in the map's patch list and is counted there.
pub fn patch_memory_bytes(patch: &Patch) -> usize {
    patch.heap_bytes()
}

/// The heap bytes of a patch list: its buffer (by capacity) and every patch's own buffers
/// ([`patch_memory_bytes`]).
#[allow(clippy::ptr_arg)] // the capacity is part of the answer
pub fn patches_memory_bytes(patches: &Vec<Patch>) -> usize {
    patches.capacity() * std::mem::size_of::<Patch>()
        + patches.iter().map(patch_memory_bytes).sum::<usize>()
}

/// The header counts of a patch list: planar and trimesh patches, and the triangles of the
/// trimesh patches (backends that triangulate planar patches add theirs).
pub fn patch_counts(patches: &[Patch]) -> MapCounts {
    let mut counts = MapCounts::default();
    for patch in patches {
        match patch {
            Patch::Planar(_) => counts.planar_patches += 1,
            Patch::Trimesh(m) => {
                counts.trimesh_patches += 1;
                counts.triangles += m.num_triangles() as u64;
            }
        }
    }
    counts
}

/// Reads the patch list of a patch-map file of `backend` and builds the map from it.
fn load_patches<M>(reader: impl Read, backend: Backend) -> Result<M, MapFileError>
where
    M: FromPatches,
{
    let (_, patches): (_, Vec<Patch>) = read_map(reader, Some(backend.name()))?;
    M::from_patches(patches).map_err(|e| MapFileError::Decode(e.to_string()))
}

impl MapFile for PolygonMap {
    const BACKEND: Backend = Backend::Polygon;

    fn save(&self, writer: impl Write) -> Result<u64, MapFileError> {
        write_map(writer, Self::BACKEND.name(), self.counts(), &self.patches())
    }

    fn load(reader: impl Read) -> Result<Self, MapFileError> {
        load_patches(reader, Self::BACKEND)
    }

    fn counts(&self) -> MapCounts {
        patch_counts(self.patches())
    }
}

impl MapFile for BBox6dMap {
    const BACKEND: Backend = Backend::BBox6d;

    fn save(&self, writer: impl Write) -> Result<u64, MapFileError> {
        write_map(writer, Self::BACKEND.name(), self.counts(), &self.patches())
    }

    /// Reads the patches and builds the forest in one go (balanced trees, O(P log P)).
    fn load(reader: impl Read) -> Result<Self, MapFileError> {
        load_patches(reader, Self::BACKEND)
    }

    fn counts(&self) -> MapCounts {
        patch_counts(self.patches())
    }
}

/// The points of a map, serialised as a sequence of `[x, y, z]` straight from the map (no copy
/// of millions of points just to write them).
struct PointTriples<'a>(&'a PointCloudMap);

impl serde::Serialize for PointTriples<'_> {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeSeq as _;
        let mut seq = serializer.serialize_seq(Some(self.0.len()))?;
        for p in self.0.points() {
            seq.serialize_element(&[p.x, p.y, p.z])?;
        }
        seq.end()
    }
}

impl MapFile for PointCloudMap {
    const BACKEND: Backend = Backend::PointCloud;

    /// Writes the points as `[x, y, z]` triples (in the map's level order, not necessarily the
    /// order they were added in; the answers of the map do not depend on it).
    fn save(&self, writer: impl Write) -> Result<u64, MapFileError> {
        write_map(writer, Self::BACKEND.name(), self.counts(), &PointTriples(self))
    }

    /// Reads the points and rebuilds the trees; a non-finite point is
    /// [`MapFileError::Decode`].
    fn load(reader: impl Read) -> Result<Self, MapFileError> {
        let (_, points): (_, Vec<[Real; 3]>) = read_map(reader, Some(Self::BACKEND.name()))?;
        let points: Vec<Point3> = points.into_iter().map(Point3::from).collect();
        PointCloudMap::from_points(&points).map_err(|e| MapFileError::Decode(e.to_string()))
    }

    fn counts(&self) -> MapCounts {
        MapCounts { points: self.len() as u64, ..MapCounts::default() }
    }
}

impl MemoryUsage for PolygonMap {
    /// The patch list ([`patches_memory_bytes`]) and the cached patch boxes.
    fn memory_bytes(&self) -> usize {
        self.heap_bytes()
    }
}

impl MemoryUsage for BBox6dMap {
    /// The patch list ([`patches_memory_bytes`]) and the k-d forest
    /// ([`KdForest::memory_bytes`](crate::kdtree::KdForest::memory_bytes)).
    fn memory_bytes(&self) -> usize {
        self.heap_bytes()
    }
}

impl MemoryUsage for PointCloudMap {
    /// [`PointCloudMap::memory_bytes`]: the points (held twice, in the level arrays and the
    /// trees' leaves) and the item ids; the `kiddo` trees' stems (a few bytes per leaf of 32
    /// points) are not visible and not counted.
    fn memory_bytes(&self) -> usize {
        PointCloudMap::memory_bytes(self)
    }
}

/// Reads a map file of any backend this build knows, choosing the backend by the header's tag.
///
/// # Errors
/// [`MapFileError::UnknownBackend`] for a tag no backend claims; otherwise as
/// [`MapFile::load`] of that backend (a corrupt, truncated or newer file, an invalid payload).
pub fn load_any(mut reader: impl Read) -> Result<AnyMap, MapFileError> {
    // Read the header once to learn the tag, then hand header and rest to the backend.
    let mut head = Vec::with_capacity(HEADER_LEN);
    (&mut reader).take(HEADER_LEN as u64).read_to_end(&mut head)?;
    let header = read_header(&head[..])?;
    let whole = Read::chain(&head[..], reader);
    let Ok(backend) = header.backend.parse::<Backend>() else {
        return Err(MapFileError::UnknownBackend { found: header.backend });
    };
    match backend {
        Backend::Polygon => PolygonMap::load(whole).map(AnyMap::Polygon),
        Backend::BBox6d => BBox6dMap::load(whole).map(AnyMap::BBox6d),
        Backend::PointCloud => PointCloudMap::load(whole).map(AnyMap::PointCloud),
        Backend::Trimesh => TrimeshMap::load(whole).map(AnyMap::Trimesh),
        #[cfg(feature = "rapier")]
        Backend::Rapier => RapierMap::load(whole).map(AnyMap::Rapier),
        #[cfg(not(feature = "rapier"))]
        Backend::Rapier => Err(MapFileError::UnknownBackend { found: backend.name().to_owned() }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use patch_core::{Isometry3, PlanarPatch, Point2, Polygon, TrimeshPatch};

    #[test]
    fn patch_bytes_follow_the_buffers() {
        let square = |a: f64, b: f64| {
            vec![Point2::new(a, a), Point2::new(b, a), Point2::new(b, b), Point2::new(a, b)]
        };
        let polygon = Polygon::new(square(0.0, 3.0), vec![square(1.0, 2.0)]).unwrap();
        let planar: Patch = PlanarPatch::new(polygon, Isometry3::identity()).unwrap().into();
        let ring = std::mem::size_of::<patch_core::Ring>();
        assert_eq!(patch_memory_bytes(&planar), 8 * 16 + ring);
        let mesh: Patch = TrimeshPatch::new(
            vec![Point3::origin(), Point3::new(1.0, 0.0, 0.0), Point3::new(0.0, 1.0, 0.0)],
            vec![[0, 1, 2]],
        )
        .unwrap()
        .into();
        assert_eq!(patch_memory_bytes(&mesh), 3 * 24 + 12);
        let list = vec![planar, mesh];
        assert_eq!(
            patches_memory_bytes(&list),
            list.capacity() * std::mem::size_of::<Patch>() + 8 * 16 + ring + 3 * 24 + 12
        );
        assert_eq!(
            patch_counts(&list),
            MapCounts { planar_patches: 1, trimesh_patches: 1, triangles: 1, points: 0 }
        );
    }
}
