//! The 6D bounding-box map (thesis §5.4.2, `BoundingBox6DPatchMap`, L5501–5554, Fig. 5.17): a
//! broad phase of patch boxes as points in a 6D k-d tree, then the exact narrow phase of
//! `patch-core` on the candidates only.
//!
//! # The broad phase (a variant of sweep and prune)
//! Each patch's axis-aligned box `(min, max)` is one point `(min_x, min_y, min_z, max_x, max_y,
//! max_z)` in 6D. A query box `B` overlaps a patch box exactly when that point lies in the
//! orthogonal range
//!
//! ```text
//! (−∞, B.max_x] × (−∞, B.max_y] × (−∞, B.max_z] × [B.min_x, ∞) × [B.min_y, ∞) × [B.min_z, ∞)
//! ```
//!
//! (in 1D: boxes become points `(x_min, x_max)` and the query a quadrant; the thesis's
//! "min_Q[4–6] = ∞" is a typo for max_Q). For a step, `B` is the box of its segment inflated by
//! its radius (spec §7.6) and by a relative slack of `1e-9` for rounding, so a candidate set
//! always holds every patch the exact kernel would report. One insertion per patch, one range
//! query per check (L5552–5554).
//!
//! The points live in a [`KdForest<6>`]: static k-d trees of power-of-two sizes (the
//! logarithmic method), so adding a patch is amortised O(log² P). Each inner node of a tree
//! also keeps the union of the patch boxes below it, and a query skips a subtree whose union
//! misses the step's box: the same candidates, but on maps of tens of thousands of patches of
//! mixed sizes 4× faster than the 6D range pruning alone (docs/performance.md).
//!
//! # Proximity
//! With a finite `max_dist`, the candidates are the patches whose boxes meet the cube of half
//! edge `max_dist` around the query point; every patch within `max_dist` is among them. With an
//! infinite (or very large) `max_dist` that cube would hold every patch, so the search grows
//! instead: it starts with a cube of half edge `r₀` (the distance to the map's box plus an
//! estimate of the patch spacing, `diagonal / ∛P / 2`), doubles `r` until some candidate turns
//! up, takes the nearest candidate's distance `d`, and, if `d > r`, queries once more with
//! `d`, which holds every patch at distance `≤ d`. The answer is exact: every patch nearer than
//! the one returned had its box inside the last cube. The growth stops at the distance of the
//! map box's farthest corner, which every patch lies within.

use std::ops::ControlFlow;

use patch_core::{
    Aabb, FromPatches, MapError, Patch, PatchId, PatchMap, PatchMapMut, Point3, Proximity,
    ProximityQuery, Real, SpecificStepIntersector, Step, StepHit, UnspecificStepIntersector,
};

use crate::kdtree::{KdForest, RangeQuery};
use crate::polygon::{
    EarliestHit, Nearest, box_distance, next_id, slackened, valid_proximity_query,
};

/// A patch box as a 6D point `(min, max)`.
fn box_point(b: &Aabb) -> [Real; 6] {
    [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z]
}

/// The range of 6D box points whose boxes meet the closed box `b`.
fn overlap_query(b: &Aabb) -> RangeQuery<6> {
    let inf = Real::INFINITY;
    RangeQuery {
        min: [-inf, -inf, -inf, b.min.x, b.min.y, b.min.z],
        max: [b.max.x, b.max.y, b.max.z, inf, inf, inf],
    }
}

/// The thesis's BoundingBox6DPatchMap (§5.4.2): patch boxes as 6D points in a k-d forest as the
/// broad phase, `patch-core`'s exact kernels as the narrow phase. Planar and triangle-mesh
/// patches (hybrid maps).
///
/// Implements every capability of §5.4.1 for line and capsule steps, exactly
/// ([`Tolerance::EXACT`](patch_core::Tolerance::EXACT)): its answers are those of
/// [`BruteForceMap`](patch_core::BruteForceMap), including which patch wins a tie (ties are
/// broken by id, independent of the order the forest reports candidates in).
///
/// # Complexity
/// With `P` patches of at most `n` edges or triangles each, and `m` candidates (patches whose
/// boxes meet the query box):
/// * [`add_patch`](PatchMapMut::add_patch): O(n) for the box, amortised O(log² P) for the
///   forest; [`from_patches`](FromPatches::from_patches) builds balanced trees in O(P log P);
/// * [`is_step_free`](UnspecificStepIntersector::is_step_free): one range query,
///   O(log P · P^(5/6) + m) in the worst case, plus O(n) per candidate until the first collision
///   (the traversal stops there);
/// * [`first_hit`](SpecificStepIntersector::first_hit): the same over all candidates;
/// * [`closest_patch`](ProximityQuery::closest_patch): one range query for a finite
///   `max_dist`, a few (logarithmically many in the ratio of the map size to the answer
///   distance) for an infinite one.
///
/// A patch's box covers the whole patch, so a large or slanted patch (or a whole triangle mesh
/// in one patch) is a candidate for every query near its box; split such patches for a sharper
/// broad phase.
///
/// Memory: the patches plus 52 bytes per patch in the forest (six coordinates and an id).
#[derive(Clone, Debug)]
pub struct BBox6dMap {
    patches: Vec<Patch>,
    forest: KdForest<6>,
    bounds: Aabb,
}

impl Default for BBox6dMap {
    fn default() -> BBox6dMap {
        BBox6dMap::new()
    }
}

impl BBox6dMap {
    /// The empty map.
    pub fn new() -> BBox6dMap {
        BBox6dMap { patches: Vec::new(), forest: KdForest::new(), bounds: Aabb::EMPTY }
    }

    /// Gives the patches back, in id order.
    pub fn into_patches(self) -> Vec<Patch> {
        self.patches
    }

    /// The ids of the patches whose boxes meet `b` (the broad phase alone), in no particular
    /// order. `b` is used as given, without slack.
    pub fn candidates(&self, b: &Aabb) -> Vec<PatchId> {
        self.forest.items_in_range(&overlap_query(b)).into_iter().map(PatchId).collect()
    }

    fn patch_at(&self, item: u32) -> (PatchId, &Patch) {
        (PatchId(item), &self.patches[item as usize])
    }

    /// The nearest of the patches whose boxes meet the cube of half edge `radius` around
    /// `point` (grown by the rounding slack), whatever its distance.
    fn nearest_in_cube(&self, point: &Point3, radius: Real) -> Option<Proximity> {
        let cube = slackened(Aabb::new(*point, *point).inflated(radius));
        let mut nearest = Nearest::default();
        self.forest.for_each_in_range(&overlap_query(&cube), &mut |item| {
            let (id, patch) = self.patch_at(item);
            nearest.offer(id, patch, point);
        });
        nearest.get()
    }

    /// The heap bytes of the patch list and the forest (see
    /// [`MemoryUsage`](crate::MemoryUsage)).
    pub(crate) fn heap_bytes(&self) -> usize {
        crate::persist::patches_memory_bytes(&self.patches) + self.forest.memory_bytes()
    }
}

impl PatchMap for BBox6dMap {
    fn patches(&self) -> &[Patch] {
        &self.patches
    }

    fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Exact: its broad phase returns a superset of the patches the kernels report, and the narrow phase is the reference's.
    fn tolerance(&self) -> patch_core::Tolerance {
        patch_core::Tolerance::EXACT
    }
}

impl PatchMapMut for BBox6dMap {
    /// Appends the patch and inserts its box into the forest: O(n) for the box, amortised
    /// O(log² P) for the forest. Never refuses a patch kind.
    fn add_patch(&mut self, patch: Patch) -> Result<PatchId, MapError> {
        let id = next_id(self.patches.len())?;
        let b = patch.bounds();
        self.bounds = self.bounds.union(&b);
        self.forest.insert(box_point(&b), id.0);
        self.patches.push(patch);
        Ok(id)
    }
}

impl FromPatches for BBox6dMap {
    type Error = MapError;

    /// Builds the forest in one go (balanced trees, O(P log P)); never refuses a patch kind,
    /// fails only past `u32::MAX` patches.
    fn from_patches(patches: impl IntoIterator<Item = Patch>) -> Result<Self, Self::Error> {
        let patches: Vec<Patch> = patches.into_iter().collect();
        next_id(patches.len())?;
        let mut bounds = Aabb::EMPTY;
        let entries = patches
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let b = p.bounds();
                bounds = bounds.union(&b);
                (box_point(&b), i as u32)
            })
            .collect();
        Ok(BBox6dMap { forest: KdForest::from_entries(entries), patches, bounds })
    }
}

impl ProximityQuery for BBox6dMap {
    /// Exact. One range query for `max_dist` below the initial search radius, else the growing
    /// search of the [module docs](self).
    fn closest_patch(&self, point: &Point3, max_dist: Real) -> Option<Proximity> {
        if !valid_proximity_query(point, max_dist) || self.patches.is_empty() {
            return None;
        }
        // Every patch lies within `far` of the point (the farthest corner of the map's box).
        let far = (point - self.bounds.min).abs().sup(&(point - self.bounds.max).abs()).norm();
        let cap = max_dist.min(far);
        let diagonal = self.bounds.extents().norm();
        let spacing = 0.5 * diagonal / (self.patches.len() as Real).cbrt();
        let start = box_distance(&self.bounds, point) + spacing.max(1e-6);
        let mut radius = start.min(cap);
        loop {
            if let Some(found) = self.nearest_in_cube(point, radius) {
                let best = if found.distance <= radius {
                    found
                } else {
                    // Patches nearer than `found` have boxes within its distance.
                    self.nearest_in_cube(point, found.distance.min(cap)).unwrap_or(found)
                };
                return Some(best).filter(|b| b.distance <= max_dist);
            }
            if radius >= cap {
                return None;
            }
            radius = (2.0 * radius).min(cap);
        }
    }
}

impl<S: Step> UnspecificStepIntersector<S> for BBox6dMap {
    /// One range query; the traversal stops at the first candidate the step touches.
    fn is_step_free(&self, step: &S) -> bool {
        let query = overlap_query(&slackened(step.bounds()));
        let flow = self.forest.try_for_each_in_range(&query, &mut |item| {
            let (_, patch) = self.patch_at(item);
            if patch.collides_with(step) {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        });
        flow.is_continue()
    }
}

impl<S: Step> SpecificStepIntersector<S> for BBox6dMap {
    /// The earliest contact among the candidates; among contacts at the same `t`, the one
    /// nearest to the sphere's centre, then the lowest id.
    fn first_hit(&self, step: &S) -> Option<StepHit> {
        let query = overlap_query(&slackened(step.bounds()));
        let mut earliest = EarliestHit::default();
        self.forest.for_each_in_range(&query, &mut |item| {
            let (id, patch) = self.patch_at(item);
            earliest.offer(id, patch, step);
        });
        earliest.hit()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use patch_core::{BruteForceMap, CapsuleStep, Isometry3, LineStep, PlanarPatch, Point2};

    /// A row of unit floor tiles at x = 2i, i < n.
    fn tiles(n: usize) -> Vec<Patch> {
        (0..n)
            .map(|i| {
                let x = 2.0 * i as Real;
                PlanarPatch::rectangle(
                    Isometry3::identity(),
                    Point2::new(x, 0.0),
                    Point2::new(x + 1.0, 1.0),
                )
                .unwrap()
                .into()
            })
            .collect()
    }

    #[test]
    fn broad_phase_selects_overlapping_boxes_only() {
        let map = BBox6dMap::from_patches(tiles(10)).unwrap();
        let b = Aabb::new(Point3::new(2.5, 0.5, -0.1), Point3::new(4.0, 0.6, 0.1));
        let mut c = map.candidates(&b);
        c.sort();
        assert_eq!(c, vec![PatchId(1), PatchId(2)], "touching at x = 4 counts");
    }

    #[test]
    fn incremental_and_bulk_maps_agree_with_the_reference() {
        let patches = tiles(37);
        let bulk = BBox6dMap::from_patches(patches.clone()).unwrap();
        let mut grown = BBox6dMap::new();
        for (i, p) in patches.iter().enumerate() {
            assert_eq!(grown.add_patch(p.clone()), Ok(PatchId(i as u32)));
        }
        let reference = BruteForceMap::from_patches(patches).unwrap();
        assert_eq!(grown.bounds(), reference.bounds());
        assert_eq!(bulk.bounds(), reference.bounds());
        for k in 0..40 {
            let x = k as Real * 1.9 - 1.0;
            let line =
                LineStep::new(Point3::new(x, 0.5, 1.0), Point3::new(x + 0.7, 0.5, -1.0)).unwrap();
            let capsule = CapsuleStep::new(
                Point3::new(x, 0.5, 0.6),
                Point3::new(x + 3.0, 0.5, 0.6),
                0.1 * (k % 7) as Real,
            )
            .unwrap();
            for map in [&bulk, &grown] {
                assert_eq!(map.is_step_free(&line), reference.is_step_free(&line));
                assert_eq!(map.first_hit(&line), reference.first_hit(&line));
                assert_eq!(map.is_step_free(&capsule), reference.is_step_free(&capsule));
                assert_eq!(map.first_hit(&capsule), reference.first_hit(&capsule));
                for max_dist in [0.0, 0.3, 2.0, 1e300, Real::INFINITY] {
                    let p = Point3::new(x, 3.0 - 0.1 * k as Real, 0.2 * k as Real - 4.0);
                    assert_eq!(
                        map.closest_patch(&p, max_dist),
                        reference.closest_patch(&p, max_dist),
                        "{p} {max_dist}"
                    );
                }
            }
        }
    }

    #[test]
    fn proximity_far_away_and_degenerate_queries() {
        let map = BBox6dMap::from_patches(tiles(3)).unwrap();
        let far = Point3::new(1e6, -2e6, 3e5);
        let reference = BruteForceMap::from_patches(tiles(3)).unwrap();
        assert_eq!(
            map.closest_patch(&far, Real::INFINITY),
            reference.closest_patch(&far, Real::INFINITY)
        );
        assert!(map.closest_patch(&far, 10.0).is_none());
        assert!(map.closest_patch(&far, -1.0).is_none());
        assert!(map.closest_patch(&Point3::new(0.0, Real::INFINITY, 0.0), 1.0).is_none());
        assert!(BBox6dMap::new().closest_patch(&far, Real::INFINITY).is_none());
        let s = CapsuleStep::sphere(far, 1.0).unwrap();
        assert!(BBox6dMap::default().is_step_free(&s));
        assert!(BBox6dMap::default().first_hit(&s).is_none());
        assert_eq!(map.clone().into_patches(), tiles(3));
    }
}
