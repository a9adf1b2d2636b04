//! Planar patches as thin slabs: each patch and a copy of it moved behind its seen side.
//!
//! A planar patch extracted from scans is the surface the sensor saw, and its normal points
//! toward the sensor (regions are fitted with the viewpoint, [`crate::region`]; merged patches
//! keep the orientation of their largest part, [`crate::merge`]). Behind a seen surface is
//! the solid it bounds, unseen. For a wall that makes no difference, but a board or table top
//! seen only from below is a slab of a few centimetres whose top no scan saw: a step that
//! grazes the top face from above stops short of the underside patch and is called free. A
//! copy of each patch moved `thickness` along its normal, away from the sensor, closes that
//! gap: the two patches bound the slab from both sides.
//!
//! This is not in the thesis (its patches have no thickness). It doubles a map's planar
//! patches; what it costs in blocked free steps is measured in `docs/map-safety.md`. The
//! pipeline keeps the back faces apart from the surfaces ([`crate::Extraction::back_faces`]):
//! maps take both ([`crate::Extraction::into_map_patches`]), a comparison of extracted
//! surfaces takes the surfaces alone.

use patch_core::{Isometry3, PlanarPatch, Real};

/// Why [`back_faces`] refused its input.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SlabError {
    /// The thickness is not a finite length in (0, 1] m.
    #[error("slab thickness must be in (0, 1] m, got {0}")]
    BadThickness(Real),
}

/// The back face of each of `patches`: the same outline moved `thickness` metres along the
/// patch's normal, away from the side it was seen from (module docs). Together with
/// `patches` they bound slabs.
///
/// # Errors
/// [`SlabError::BadThickness`] unless `thickness` is in (0, 1] m.
pub fn back_faces(patches: &[PlanarPatch], thickness: Real) -> Result<Vec<PlanarPatch>, SlabError> {
    if !(thickness.is_finite() && thickness > 0.0 && thickness <= 1.0) {
        return Err(SlabError::BadThickness(thickness));
    }
    Ok(patches
        .iter()
        .map(|p| {
            let back = p.normal().into_inner() * -thickness;
            p.transformed(&Isometry3::translation(back.x, back.y, back.z))
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use patch_core::{Point2, Point3};

    #[test]
    fn the_back_face_lies_behind_the_seen_side() {
        // A board's underside at z = 0.71, seen from below: its normal points down.
        let under = PlanarPatch::rectangle(
            Isometry3::translation(0.0, 0.0, 0.71)
                * Isometry3::rotation(patch_core::Vector3::x() * std::f64::consts::PI),
            Point2::new(-1.0, -1.0),
            Point2::new(1.0, 1.0),
        )
        .unwrap();
        assert!(under.normal().z < -0.99);
        let back = back_faces(std::slice::from_ref(&under), 0.04).unwrap();
        assert_eq!(back.len(), 1);
        let top = back[0].plane().signed_distance(&Point3::new(0.0, 0.0, 0.75));
        assert!(top.abs() < 1e-12, "{top}");
        assert!((back[0].area() - under.area()).abs() < 1e-12);
    }

    #[test]
    fn bad_thickness_is_an_error() {
        for t in [0.0, -0.1, 2.0, Real::NAN, Real::INFINITY] {
            assert!(matches!(back_faces(&[], t), Err(SlabError::BadThickness(_))));
        }
    }
}
