//! [`AnyMap`]: a map whose [`Backend`] is chosen at run time (read from a file by
//! [`load_any`](crate::load_any), or built from patches by [`AnyMap::from_patches`]).

use std::io::Write;

use patch_core::{
    Aabb, CapsuleStep, FromPatches, LineStep, MapError, MaybePatchMap, Patch, PatchMap,
    PatchMapVisitor, Real, UnspecificStepIntersector,
};

#[cfg(feature = "rapier")]
use crate::RapierMap;
use crate::mapfile::{MapCounts, MapFileError};
use crate::persist::{MapFile, MemoryUsage};
use crate::{
    BBox6dMap, Backend, MeshMapError, PointCloudMap, PointCloudMapError, PolygonMap, SamplingError,
    TrimeshMap, sample_patch_points,
};

/// A map of any backend of this crate.
///
/// New backends add a variant here, to [`Backend`], and an arm to each `match` below (the
/// compiler lists them).
#[derive(Debug)]
#[non_exhaustive]
pub enum AnyMap {
    /// A [`PolygonMap`] (tag `polygon`).
    Polygon(PolygonMap),
    /// A [`BBox6dMap`] (tag `bbox6d`).
    BBox6d(BBox6dMap),
    /// A [`PointCloudMap`] (tag `pointcloud`).
    PointCloud(PointCloudMap),
    /// A [`TrimeshMap`] (tag `trimesh`).
    Trimesh(TrimeshMap),
    /// A [`RapierMap`] (tag `rapier`; feature `rapier`).
    #[cfg(feature = "rapier")]
    Rapier(RapierMap),
}

/// Why [`AnyMap::from_patches`] failed.
#[derive(Debug, thiserror::Error)]
pub enum AnyMapError {
    /// The point-cloud backend was asked for without a spacing to sample the patches at.
    #[error(
        "the `pointcloud` backend holds points, not patches: it needs a spacing to sample them at"
    )]
    NeedsSpacing,
    /// The polygon or bbox6d backend refused a patch.
    #[error(transparent)]
    Patches(#[from] MapError),
    /// The trimesh or rapier backend could not triangulate a patch.
    #[error(transparent)]
    Mesh(#[from] MeshMapError),
    /// The patches could not be sampled into points.
    #[error(transparent)]
    Sampling(#[from] SamplingError),
    /// The point-cloud backend refused the sampled points.
    #[error(transparent)]
    Points(#[from] PointCloudMapError),
    /// The backend is left out of this build (its cargo feature is off).
    #[error("the `{backend}` backend is not in this build (enable the `{backend}` feature)")]
    NotBuilt {
        /// The backend asked for.
        backend: Backend,
    },
}

impl AnyMap {
    /// A map of `backend` holding `patches`. The point-cloud backend holds points: it samples
    /// the patches every `point_spacing` metres ([`sample_patch_points`]); the other backends
    /// ignore `point_spacing`.
    ///
    /// # Errors
    /// [`AnyMapError::NeedsSpacing`] for the point-cloud backend without `point_spacing`;
    /// otherwise the backend's own error (a bad spacing is [`AnyMapError::Sampling`]).
    pub fn from_patches(
        backend: Backend,
        patches: Vec<Patch>,
        point_spacing: Option<Real>,
    ) -> Result<AnyMap, AnyMapError> {
        Ok(match backend {
            Backend::Polygon => AnyMap::Polygon(PolygonMap::from_patches(patches)?),
            Backend::BBox6d => AnyMap::BBox6d(BBox6dMap::from_patches(patches)?),
            Backend::Trimesh => AnyMap::Trimesh(TrimeshMap::from_patches(patches)?),
            #[cfg(feature = "rapier")]
            Backend::Rapier => AnyMap::Rapier(RapierMap::from_patches(patches)?),
            #[cfg(not(feature = "rapier"))]
            Backend::Rapier => return Err(AnyMapError::NotBuilt { backend }),
            Backend::PointCloud => {
                let spacing = point_spacing.ok_or(AnyMapError::NeedsSpacing)?;
                let points = sample_patch_points(&patches, spacing)?;
                AnyMap::PointCloud(PointCloudMap::from_points(&points)?)
            }
        })
    }

    /// The backend of the held map (its tag is [`MapFile::BACKEND`]).
    pub fn backend(&self) -> Backend {
        match self {
            AnyMap::Polygon(_) => PolygonMap::BACKEND,
            AnyMap::BBox6d(_) => BBox6dMap::BACKEND,
            AnyMap::PointCloud(_) => PointCloudMap::BACKEND,
            AnyMap::Trimesh(_) => TrimeshMap::BACKEND,
            #[cfg(feature = "rapier")]
            AnyMap::Rapier(_) => RapierMap::BACKEND,
        }
    }

    /// The heap bytes of the held map ([`MemoryUsage`]).
    pub fn memory_bytes(&self) -> usize {
        match self {
            AnyMap::Polygon(m) => m.memory_bytes(),
            AnyMap::BBox6d(m) => m.memory_bytes(),
            AnyMap::PointCloud(m) => MemoryUsage::memory_bytes(m),
            AnyMap::Trimesh(m) => m.memory_bytes(),
            #[cfg(feature = "rapier")]
            AnyMap::Rapier(m) => MemoryUsage::memory_bytes(m),
        }
    }

    /// What the held map holds ([`MapFile::counts`]).
    pub fn counts(&self) -> MapCounts {
        match self {
            AnyMap::Polygon(m) => m.counts(),
            AnyMap::BBox6d(m) => m.counts(),
            AnyMap::PointCloud(m) => m.counts(),
            AnyMap::Trimesh(m) => m.counts(),
            #[cfg(feature = "rapier")]
            AnyMap::Rapier(m) => m.counts(),
        }
    }

    /// Writes the held map with its own backend tag ([`MapFile::save`]).
    ///
    /// # Errors
    /// As [`MapFile::save`].
    pub fn save(&self, writer: impl Write) -> Result<u64, MapFileError> {
        match self {
            AnyMap::Polygon(m) => m.save(writer),
            AnyMap::BBox6d(m) => m.save(writer),
            AnyMap::PointCloud(m) => m.save(writer),
            AnyMap::Trimesh(m) => m.save(writer),
            #[cfg(feature = "rapier")]
            AnyMap::Rapier(m) => m.save(writer),
        }
    }

    /// The box of the held map's patches or points ([`Aabb::EMPTY`] for an empty map).
    pub fn bounds(&self) -> Aabb {
        match self {
            AnyMap::Polygon(m) => m.bounds(),
            AnyMap::BBox6d(m) => m.bounds(),
            AnyMap::PointCloud(m) => m.bounds(),
            AnyMap::Trimesh(m) => m.bounds(),
            #[cfg(feature = "rapier")]
            AnyMap::Rapier(m) => m.bounds(),
        }
    }

    /// The tolerance a patch map declares ([`PatchMap::tolerance`]); `None` for a point-cloud
    /// map, which approximates the patches by their points and has no such bound.
    pub fn tolerance(&self) -> Option<patch_core::Tolerance> {
        match self {
            AnyMap::Polygon(m) => Some(m.tolerance()),
            AnyMap::BBox6d(m) => Some(m.tolerance()),
            AnyMap::PointCloud(_) => None,
            AnyMap::Trimesh(m) => Some(m.tolerance()),
            #[cfg(feature = "rapier")]
            AnyMap::Rapier(m) => Some(m.tolerance()),
        }
    }

    /// Gives the patches of a patch map back, in id order, dropping the rest of the map (so
    /// one set of patches can be loaded into every backend in turn without a copy); `None` for
    /// a point-cloud map.
    pub fn into_patches(self) -> Option<Vec<Patch>> {
        match self {
            AnyMap::Polygon(m) => Some(m.into_patches()),
            AnyMap::BBox6d(m) => Some(m.into_patches()),
            AnyMap::PointCloud(_) => None,
            AnyMap::Trimesh(m) => Some(m.into_patches()),
            #[cfg(feature = "rapier")]
            AnyMap::Rapier(m) => Some(m.into_patches()),
        }
    }

    /// The patches of a patch map, in id order; `None` for a point-cloud map.
    pub fn patches(&self) -> Option<&[Patch]> {
        match self {
            AnyMap::Polygon(m) => Some(m.patches()),
            AnyMap::BBox6d(m) => Some(m.patches()),
            AnyMap::PointCloud(_) => None,
            AnyMap::Trimesh(m) => Some(m.patches()),
            #[cfg(feature = "rapier")]
            AnyMap::Rapier(m) => Some(m.patches()),
        }
    }
}

/// The four patch backends run the visitor (every capability of thesis Table 5.2); the
/// point-cloud map gives it back.
impl MaybePatchMap for AnyMap {
    fn with_patch_map<'m, V: PatchMapVisitor<'m>>(&'m self, visitor: V) -> Result<V::Output, V> {
        match self {
            AnyMap::Polygon(m) => Ok(visitor.visit(m)),
            AnyMap::BBox6d(m) => Ok(visitor.visit(m)),
            AnyMap::Trimesh(m) => Ok(visitor.visit(m)),
            #[cfg(feature = "rapier")]
            AnyMap::Rapier(m) => Ok(visitor.visit(m)),
            AnyMap::PointCloud(_) => Err(visitor),
        }
    }

    fn backend_name(&self) -> &'static str {
        self.backend().name()
    }
}

/// Every backend answers the unspecific capsule query (with its own tolerance: the point-cloud
/// map under its density assumption).
impl UnspecificStepIntersector for AnyMap {
    fn is_step_free(&self, step: &CapsuleStep) -> bool {
        match self {
            AnyMap::Polygon(m) => m.is_step_free(step),
            AnyMap::BBox6d(m) => m.is_step_free(step),
            AnyMap::PointCloud(m) => m.is_step_free(step),
            AnyMap::Trimesh(m) => m.is_step_free(step),
            #[cfg(feature = "rapier")]
            AnyMap::Rapier(m) => m.is_step_free(step),
        }
    }
}

/// Every backend answers the unspecific line query.
impl UnspecificStepIntersector<LineStep> for AnyMap {
    fn is_step_free(&self, step: &LineStep) -> bool {
        match self {
            AnyMap::Polygon(m) => m.is_step_free(step),
            AnyMap::BBox6d(m) => m.is_step_free(step),
            AnyMap::PointCloud(m) => m.is_step_free(step),
            AnyMap::Trimesh(m) => m.is_step_free(step),
            #[cfg(feature = "rapier")]
            AnyMap::Rapier(m) => m.is_step_free(step),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::load_any;
    use crate::mapfile::read_header;
    use patch_core::{Isometry3, PlanarPatch, Point2, Polygon};

    fn square() -> Vec<Patch> {
        let ring = vec![
            Point2::new(0.0, 0.0),
            Point2::new(1.0, 0.0),
            Point2::new(1.0, 1.0),
            Point2::new(0.0, 1.0),
        ];
        let polygon = Polygon::new(ring, Vec::new()).unwrap();
        vec![PlanarPatch::new(polygon, Isometry3::identity()).unwrap().into()]
    }

    #[test]
    fn every_backend_builds_and_its_files_carry_its_name() {
        for backend in Backend::ALL {
            if !backend.is_built() {
                let e = AnyMap::from_patches(backend, square(), Some(0.1)).unwrap_err();
                assert!(matches!(e, AnyMapError::NotBuilt { .. }), "{e}");
                assert!(e.to_string().contains("feature"), "{e}");
                continue;
            }
            let map = AnyMap::from_patches(backend, square(), Some(0.1)).unwrap();
            assert_eq!(map.backend(), backend);
            assert_eq!(map.backend_name(), backend.name());
            assert_eq!(map.patches().is_some(), backend.holds_patches(), "{backend}");
            assert_eq!(map.tolerance().is_some(), backend.holds_patches(), "{backend}");
            let b = map.bounds();
            assert!(b.min.x <= 0.0 && b.max.x >= 1.0 && b.max.y >= 1.0, "{backend}: {b:?}");
            let mut file = Vec::new();
            map.save(&mut file).unwrap();
            assert_eq!(read_header(&file[..]).unwrap().backend, backend.name());
            assert_eq!(load_any(&file[..]).unwrap().backend(), backend);
        }
    }

    #[test]
    fn the_point_cloud_backend_needs_a_good_spacing() {
        let e = AnyMap::from_patches(Backend::PointCloud, square(), None).unwrap_err();
        assert!(matches!(e, AnyMapError::NeedsSpacing));
        assert!(e.to_string().contains("pointcloud"), "{e}");
        let e = AnyMap::from_patches(Backend::PointCloud, square(), Some(-1.0)).unwrap_err();
        assert!(matches!(e, AnyMapError::Sampling(SamplingError::BadSpacing(_))), "{e}");
        // The patch backends need no spacing.
        assert!(AnyMap::from_patches(Backend::Trimesh, square(), None).is_ok());
    }
}
