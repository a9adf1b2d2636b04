//! The backends of this crate by name: [`Backend`], the one list of backends in the workspace.
//!
//! A backend's name is the tag its map files carry in their header ([`mapfile`](crate::mapfile))
//! and the name programs accept on their command lines; [`Backend::name`] is the one table of
//! these names, and [`FromStr`] and [`Display`](fmt::Display) go through it.
//!
//! ```
//! use patch_map::Backend;
//!
//! let backend: Backend = "bbox6d".parse()?;
//! assert_eq!(backend, Backend::BBox6d);
//! assert_eq!(backend.to_string(), "bbox6d");
//! assert!(!Backend::PointCloud.holds_patches());
//! let e = "octree".parse::<Backend>().unwrap_err();
//! assert_eq!(e.to_string(), "unknown backend `octree`; known: polygon, bbox6d, trimesh, rapier, pointcloud");
//! # Ok::<(), patch_map::UnknownBackend>(())
//! ```

use std::fmt;
use std::str::FromStr;

/// A backend of this crate ([`AnyMap`](crate::AnyMap) holds a map of any of them).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Backend {
    /// [`PolygonMap`](crate::PolygonMap), tag `polygon`.
    Polygon,
    /// [`BBox6dMap`](crate::BBox6dMap), tag `bbox6d`.
    BBox6d,
    /// [`TrimeshMap`](crate::TrimeshMap), tag `trimesh`.
    Trimesh,
    /// [`RapierMap`](crate::RapierMap), tag `rapier`.
    Rapier,
    /// [`PointCloudMap`](crate::PointCloudMap), tag `pointcloud`.
    PointCloud,
}

impl Backend {
    /// All five, in the thesis's column order (Simple, BB6D, OPCODE, Bullet), then the
    /// point-cloud map.
    pub const ALL: [Backend; 5] =
        [Backend::Polygon, Backend::BBox6d, Backend::Trimesh, Backend::Rapier, Backend::PointCloud];

    /// The map-file tag, which is also the name on command lines.
    pub const fn name(self) -> &'static str {
        match self {
            Backend::Polygon => "polygon",
            Backend::BBox6d => "bbox6d",
            Backend::Trimesh => "trimesh",
            Backend::Rapier => "rapier",
            Backend::PointCloud => "pointcloud",
        }
    }

    /// One line for help texts.
    pub const fn description(self) -> &'static str {
        match self {
            Backend::Polygon => "Native polygons, no broad phase (the thesis's SimplePatchMap)",
            Backend::BBox6d => {
                "Patch boxes as 6D points in a k-d forest (the thesis's BoundingBox6DPatchMap)"
            }
            Backend::Trimesh => "Triangulated patches in one parry triangle mesh with a BVH",
            Backend::Rapier => "One collider per patch in a rapier query pipeline",
            Backend::PointCloud => {
                "Points in k-d trees (patches are sampled), checked by the thesis's Algorithm 10"
            }
        }
    }

    /// Whether the backend holds patches: every backend but the point-cloud map, which holds
    /// points.
    pub const fn holds_patches(self) -> bool {
        !matches!(self, Backend::PointCloud)
    }

    /// Whether this build has the backend: all but `rapier`, which needs the `rapier` feature
    /// (on by default).
    pub const fn is_built(self) -> bool {
        !matches!(self, Backend::Rapier) || cfg!(feature = "rapier")
    }

    /// The backends that hold patches, in [`ALL`](Self::ALL) order.
    pub fn patch_backends() -> impl Iterator<Item = Backend> {
        Backend::ALL.into_iter().filter(|b| b.holds_patches())
    }
}

impl fmt::Display for Backend {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A name that is no backend's ([`Backend`]'s [`FromStr`]).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown backend `{name}`; known: {}", Backend::ALL.map(Backend::name).join(", "))]
pub struct UnknownBackend {
    /// The name given.
    pub name: String,
}

impl FromStr for Backend {
    type Err = UnknownBackend;

    fn from_str(name: &str) -> Result<Backend, UnknownBackend> {
        Backend::ALL
            .into_iter()
            .find(|b| b.name() == name)
            .ok_or_else(|| UnknownBackend { name: name.to_owned() })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_are_distinct() {
        for b in Backend::ALL {
            assert_eq!(b.name().parse::<Backend>(), Ok(b));
            assert_eq!(b.to_string(), b.name());
            assert!(!b.description().is_empty() && !b.description().contains('\n'), "{b}");
        }
        let mut names = Backend::ALL.map(Backend::name).to_vec();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), Backend::ALL.len());
    }

    #[test]
    fn unknown_names_list_the_known_ones() {
        for bad in ["octree", "Polygon", " bbox6d", "", "point-cloud"] {
            let e = bad.parse::<Backend>().unwrap_err();
            assert_eq!(e, UnknownBackend { name: bad.to_owned() });
            let text = e.to_string();
            assert!(text.contains(&format!("`{bad}`")), "{text}");
            for b in Backend::ALL {
                assert!(text.contains(b.name()), "{text}");
            }
        }
    }

    #[test]
    fn only_the_point_cloud_map_holds_no_patches() {
        let points: Vec<Backend> =
            Backend::ALL.into_iter().filter(|b| !b.holds_patches()).collect();
        assert_eq!(points, [Backend::PointCloud]);
        let patches: Vec<Backend> = Backend::patch_backends().collect();
        assert_eq!(patches, [Backend::Polygon, Backend::BBox6d, Backend::Trimesh, Backend::Rapier]);
    }
}
