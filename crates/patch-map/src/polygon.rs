//! The native polygon map (thesis §5.4.2, `SimplePatchMap`): the patches in a list, no broad
//! phase, the exact narrow phase of `patch-core` on every patch.
//!
//! The thesis's SimplePatchMap (L5489–5499) loops over all planar patches, intersects a line
//! with each patch's plane and tests the hit point against the polygon in 2D. This map does the
//! same for every query of §5.4.1, with `patch-core`'s exact kernels
//! ([`Patch::segment_distance`], [`Patch::first_contact`], [`Patch::closest_point`]): lines and
//! capsules (the capsule–polygon distance of the project's spec §3.3, which the thesis leaves
//! undescribed) and proximity. It stores planar and triangle-mesh patches alike (hybrid maps,
//! spec §7.7), so it answers exactly what
//! [`BruteForceMap`](patch_core::BruteForceMap) answers.
//!
//! # No broad phase structure, one cheap rejection
//! There is no spatial index: every query visits every patch, O(P) for P patches. Inside the
//! loop, each patch's axis-aligned box (computed once, when the patch is added) is compared with
//! the query's box before the narrow phase runs: a rejection costs six comparisons instead of a
//! transform and an edge loop. The boxes are a per-patch cache, not a structure over patches,
//! and a rejected patch provably cannot touch the query: query boxes are grown by `1e-9`
//! relative to their coordinates (plus `1e-9` m), far more than the rounding of patch boxes and
//! kernel results (a few ulps), so the answers are those of the exact kernels.

use patch_core::{
    Aabb, FromPatches, MapError, Patch, PatchId, PatchMap, PatchMapMut, Point3, Proximity,
    ProximityQuery, Real, SpecificStepIntersector, Step, StepHit, UnspecificStepIntersector,
};

/// Relative slack added to query boxes, so that float rounding of patch boxes and of kernel
/// results can never make a box test reject a patch the exact kernel would report.
///
/// Patch boxes are the floating-point images of the vertices; kernel points are within a few
/// ulps (about `1e-16` relative) of the exact hull of those images. A slack of `1e-9` relative to
/// the magnitude of the coordinates (plus `1e-9` m absolute) exceeds that by seven orders of
/// magnitude and costs nothing measurable: it only lets a few more patches reach the narrow
/// phase, which decides exactly.
const BOX_SLACK: Real = 1e-9;

/// The slack for boxes whose coordinates are at most `scale` in magnitude.
pub(crate) fn slack_for(scale: Real) -> Real {
    BOX_SLACK * (1.0 + scale)
}

/// `b` grown by [`BOX_SLACK`] relative to its largest coordinate magnitude.
///
/// Every patch point within the exact box `b` lies in the grown box even after rounding, so a
/// patch whose box misses it cannot be touched by the query `b` bounds.
pub(crate) fn slackened(b: Aabb) -> Aabb {
    let scale = b.min.coords.amax().max(b.max.coords.amax());
    b.inflated(slack_for(scale))
}

/// The Euclidean distance from `p` to the closed box `b` (0 inside): a lower bound on the
/// distance to anything in the box.
pub(crate) fn box_distance(b: &Aabb, p: &Point3) -> Real {
    let mut sum = 0.0;
    for i in 0..3 {
        let d = (b.min[i] - p[i]).max(p[i] - b.max[i]).max(0.0);
        sum += d * d;
    }
    sum.sqrt()
}

/// The id the next patch of a map with `len` patches gets.
pub(crate) fn next_id(len: usize) -> Result<PatchId, MapError> {
    u32::try_from(len).ok().filter(|&i| i < u32::MAX).map(PatchId).ok_or(MapError::TooManyPatches)
}

/// Whether `point` is a valid proximity query with `max_dist` (the cases where the contract of
/// [`ProximityQuery::closest_patch`] says `None`).
pub(crate) fn valid_proximity_query(point: &Point3, max_dist: Real) -> bool {
    !(max_dist.is_nan() || max_dist < 0.0) && point.iter().all(|c| c.is_finite())
}

/// The earliest contact seen so far among visited patches, ordered by `(t, gap, id)`: the
/// first contact along the step, then the one nearest to the sphere's centre, then the lowest
/// id. This is the order of [`BruteForceMap`](patch_core::BruteForceMap) (which visits ids in
/// order and keeps the strictly earlier contact), made independent of the visiting order.
#[derive(Copy, Clone, Debug, Default)]
pub(crate) struct EarliestHit {
    best: Option<(StepHit, Real)>,
}

impl EarliestHit {
    /// Runs the narrow phase of `patch` against `step` and keeps the contact if it is earlier.
    /// Returns whether it was kept.
    pub(crate) fn offer<S: Step>(&mut self, id: PatchId, patch: &Patch, step: &S) -> bool {
        let Some(c) = patch.step_contact(step) else {
            return false;
        };
        let gap = (step.point_at(c.t) - c.point).norm_squared();
        let earlier = self.best.is_none_or(|(b, g)| {
            c.t < b.t || (c.t == b.t && (gap < g || (gap == g && id < b.patch)))
        });
        if earlier {
            let hit = StepHit { patch: id, t: c.t, point: c.point, normal: c.normal };
            self.best = Some((hit, gap));
        }
        earlier
    }

    /// The earliest contact kept.
    pub(crate) fn hit(&self) -> Option<StepHit> {
        self.best.map(|(hit, _)| hit)
    }
}

/// The nearest patch seen so far, ordered by `(distance, id)` (the lowest id among tied
/// distances, as [`BruteForceMap`](patch_core::BruteForceMap)).
#[derive(Copy, Clone, Debug, Default)]
pub(crate) struct Nearest {
    best: Option<Proximity>,
}

impl Nearest {
    /// Measures `patch` from `point` and keeps it if it is nearer.
    pub(crate) fn offer(&mut self, id: PatchId, patch: &Patch, point: &Point3) {
        let c = patch.closest_point(point);
        let nearer = self
            .best
            .is_none_or(|b| c.distance < b.distance || (c.distance == b.distance && id < b.patch));
        if nearer {
            self.best = Some(Proximity { patch: id, point: c.point, distance: c.distance });
        }
    }

    /// The distance of the nearest patch kept (infinite before any).
    pub(crate) fn distance(&self) -> Real {
        self.best.map_or(Real::INFINITY, |b| b.distance)
    }

    /// The nearest patch kept.
    pub(crate) fn get(&self) -> Option<Proximity> {
        self.best
    }
}

/// The thesis's SimplePatchMap (§5.4.2): a list of patches and the exact narrow phase on each,
/// without a broad phase. Planar and triangle-mesh patches (hybrid maps).
///
/// Implements every capability of §5.4.1 for line and capsule steps, exactly
/// ([`Tolerance::EXACT`](patch_core::Tolerance::EXACT)): its answers are those of
/// [`BruteForceMap`](patch_core::BruteForceMap), including which patch wins a tie.
///
/// # Complexity
/// With `P` patches of at most `n` edges or triangles each:
/// * [`add_patch`](PatchMapMut::add_patch): O(n) (the patch's box), amortised O(1) in the
///   number of patches (a push);
/// * [`is_step_free`](UnspecificStepIntersector::is_step_free): O(P) box tests plus O(n) per
///   patch whose box meets the step's, stopping at the first colliding patch;
/// * [`first_hit`](SpecificStepIntersector::first_hit): the same without the early exit; after
///   each contact the step's box shrinks to the part before it, so later patches are rejected
///   more often;
/// * [`closest_patch`](ProximityQuery::closest_patch): O(P) box distances plus O(n) per patch
///   whose box is nearer than the best distance so far (and than `max_dist`).
///
/// The any-hit loop ([`is_step_free`](UnspecificStepIntersector::is_step_free)) visits the
/// patches largest box first (by the sum of the box's edge lengths, then by id): a large
/// patch (a floor, a long wall) is the likeliest to stop a colliding step early. The answer
/// does not depend on the order.
///
/// Memory: the patches, one [`Aabb`] (48 bytes) per patch, and a copy of it with the patch's
/// id in visiting order (56 bytes).
#[derive(Clone, Debug)]
pub struct PolygonMap {
    patches: Vec<Patch>,
    /// `boxes[i] = patches[i].bounds()`.
    boxes: Vec<Aabb>,
    /// `(boxes[i], i)` for every patch, in the any-hit loop's order (see [`visit_before`]).
    visit: Vec<(Aabb, u32)>,
    bounds: Aabb,
}

/// The any-hit loop's order: larger boxes (sum of edge lengths) first, then lower ids.
fn visit_before(a: &(Aabb, u32), b: &(Aabb, u32)) -> std::cmp::Ordering {
    let size = |b: &Aabb| b.extents().sum();
    size(&b.0).total_cmp(&size(&a.0)).then(a.1.cmp(&b.1))
}

impl Default for PolygonMap {
    fn default() -> PolygonMap {
        PolygonMap::new()
    }
}

impl PolygonMap {
    /// The empty map.
    pub fn new() -> PolygonMap {
        PolygonMap {
            patches: Vec::new(),
            boxes: Vec::new(),
            visit: Vec::new(),
            bounds: Aabb::EMPTY,
        }
    }

    /// The empty map with room for `capacity` patches.
    pub fn with_capacity(capacity: usize) -> PolygonMap {
        PolygonMap {
            patches: Vec::with_capacity(capacity),
            boxes: Vec::with_capacity(capacity),
            visit: Vec::with_capacity(capacity),
            bounds: Aabb::EMPTY,
        }
    }

    /// Appends the patch and its box (not to the visiting order).
    fn push(&mut self, patch: Patch) -> Result<PatchId, MapError> {
        let id = next_id(self.patches.len())?;
        let b = patch.bounds();
        self.bounds = self.bounds.union(&b);
        self.patches.push(patch);
        self.boxes.push(b);
        Ok(id)
    }

    /// Gives the patches back, in id order.
    pub fn into_patches(self) -> Vec<Patch> {
        self.patches
    }

    /// The cached box of every patch, in id order.
    pub fn patch_boxes(&self) -> &[Aabb] {
        &self.boxes
    }

    /// The patches with their ids and boxes.
    fn entries(&self) -> impl Iterator<Item = (PatchId, &Patch, &Aabb)> + '_ {
        self.patches
            .iter()
            .zip(&self.boxes)
            .enumerate()
            .map(|(i, (p, b))| (PatchId(i as u32), p, b))
    }

    /// The heap bytes of the patch list and the box cache (see
    /// [`MemoryUsage`](crate::MemoryUsage)).
    pub(crate) fn heap_bytes(&self) -> usize {
        crate::persist::patches_memory_bytes(&self.patches)
            + self.boxes.capacity() * std::mem::size_of::<Aabb>()
            + self.visit.capacity() * std::mem::size_of::<(Aabb, u32)>()
    }
}

impl PatchMap for PolygonMap {
    fn patches(&self) -> &[Patch] {
        &self.patches
    }

    fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Exact: it runs the reference's kernels.
    fn tolerance(&self) -> patch_core::Tolerance {
        patch_core::Tolerance::EXACT
    }
}

impl PatchMapMut for PolygonMap {
    /// Appends the patch: O(n) for its box, O(1) amortised otherwise. Never refuses a patch
    /// kind.
    fn add_patch(&mut self, patch: Patch) -> Result<PatchId, MapError> {
        let id = self.push(patch)?;
        let entry = (self.boxes[id.0 as usize], id.0);
        let at = self.visit.partition_point(|e| visit_before(e, &entry).is_lt());
        self.visit.insert(at, entry);
        Ok(id)
    }
}

impl FromPatches for PolygonMap {
    type Error = MapError;

    /// Builds the map (never refuses a patch kind; fails only past `u32::MAX` patches).
    fn from_patches(patches: impl IntoIterator<Item = Patch>) -> Result<Self, Self::Error> {
        let patches = patches.into_iter();
        let mut map = PolygonMap::with_capacity(patches.size_hint().0);
        for patch in patches {
            map.push(patch)?;
        }
        // One sort instead of an insertion per patch. Ids fit in u32 (checked by `push`).
        map.visit = map.boxes.iter().enumerate().map(|(i, b)| (*b, i as u32)).collect();
        map.visit.sort_unstable_by(visit_before);
        Ok(map)
    }
}

impl ProximityQuery for PolygonMap {
    /// Exact; patches whose box is farther than the best distance so far (or than `max_dist`)
    /// are skipped without running the kernel.
    fn closest_patch(&self, point: &Point3, max_dist: Real) -> Option<Proximity> {
        if !valid_proximity_query(point, max_dist) {
            return None;
        }
        let mut nearest = Nearest::default();
        for (id, patch, b) in self.entries() {
            let scale = point.coords.amax().max(b.min.coords.amax()).max(b.max.coords.amax());
            let lower = box_distance(b, point) - slack_for(scale);
            if lower > max_dist.min(nearest.distance()) {
                continue;
            }
            nearest.offer(id, patch, point);
        }
        nearest.get().filter(|b| b.distance <= max_dist)
    }
}

impl<S: Step> UnspecificStepIntersector<S> for PolygonMap {
    /// Any-hit loop: stops at the first patch the step touches.
    fn is_step_free(&self, step: &S) -> bool {
        let query = slackened(step.bounds());
        !self
            .visit
            .iter()
            .any(|(b, i)| b.intersects(&query) && self.patches[*i as usize].collides_with(step))
    }
}

impl<S: Step> SpecificStepIntersector<S> for PolygonMap {
    /// The earliest contact over all patches; among contacts at the same `t`, the one nearest
    /// to the sphere's centre, then the lowest id.
    fn first_hit(&self, step: &S) -> Option<StepHit> {
        let mut query = slackened(step.bounds());
        let mut earliest = EarliestHit::default();
        for (id, patch, b) in self.entries() {
            if b.intersects(&query) && earliest.offer(id, patch, step) {
                // Only contacts up to this one can still win: shrink the box to that prefix.
                let t = earliest.hit().map_or(1.0, |h| h.t);
                let prefix = Aabb::new(step.start(), step.point_at(t)).inflated(step.radius());
                query = slackened(prefix);
            }
        }
        earliest.hit()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use patch_core::{
        BruteForceMap, CapsuleStep, Isometry3, LineStep, PlanarPatch, Point2, TrimeshPatch, Vector3,
    };

    fn floor_and_wall() -> Vec<Patch> {
        let floor = PlanarPatch::rectangle(
            Isometry3::identity(),
            Point2::new(0.0, 0.0),
            Point2::new(4.0, 3.0),
        )
        .unwrap();
        let wall = PlanarPatch::from_world_polygon(
            &[
                Point3::new(2.0, 0.0, 0.0),
                Point3::new(2.0, 0.0, 2.0),
                Point3::new(2.0, 3.0, 2.0),
                Point3::new(2.0, 3.0, 0.0),
            ],
            &[],
            1e-9,
        )
        .unwrap();
        let roof = TrimeshPatch::new(
            vec![
                Point3::new(0.0, 0.0, 3.0),
                Point3::new(4.0, 0.0, 3.0),
                Point3::new(0.0, 3.0, 3.0),
            ],
            vec![[0, 1, 2]],
        )
        .unwrap();
        vec![floor.into(), wall.into(), roof.into()]
    }

    #[test]
    fn answers_like_the_reference_on_a_small_scene() {
        let patches = floor_and_wall();
        let map = PolygonMap::from_patches(patches.clone()).unwrap();
        let reference = BruteForceMap::from_patches(patches).unwrap();
        assert_eq!(map.len(), 3);
        assert_eq!(map.bounds(), reference.bounds());
        let step =
            CapsuleStep::new(Point3::new(0.5, 1.5, 1.0), Point3::new(3.5, 1.5, 1.0), 0.25).unwrap();
        assert!(!map.is_step_free(&step));
        let hit = map.first_hit(&step).unwrap();
        assert_eq!(Some(hit), reference.first_hit(&step));
        assert_eq!(hit.patch, PatchId(1));
        assert!((hit.t - 1.25 / 3.0).abs() < 1e-12);
        assert!((hit.normal.into_inner() - Vector3::new(-1.0, 0.0, 0.0)).norm() < 1e-12);
        let free = LineStep::new(Point3::new(0.5, 1.5, 1.0), Point3::new(1.5, 1.5, 2.5)).unwrap();
        assert!(map.is_step_free(&free) && map.first_hit(&free).is_none());
        let p = Point3::new(1.0, 1.5, 0.5);
        assert_eq!(map.closest_patch(&p, 10.0), reference.closest_patch(&p, 10.0));
        assert!((map.clearance(&p, 10.0) - 0.5).abs() < 1e-12);
        assert!(map.closest_patch(&p, 0.25).is_none());
        assert!(map.closest_patch(&p, -1.0).is_none());
        assert!(map.closest_patch(&p, Real::NAN).is_none());
        assert!(map.closest_patch(&Point3::new(Real::NAN, 0.0, 0.0), 1.0).is_none());
        let far = Point3::new(0.5, 0.5, 2.75);
        assert_eq!(map.closest_patch(&far, Real::INFINITY).unwrap().patch, PatchId(2));
    }

    #[test]
    fn many_patches_answer_like_the_reference_and_are_visited_largest_first() {
        // 150 floor tiles of three sizes (exact in binary, so sizes tie exactly) in a 15 × 10
        // grid at four heights; every step is
        // tested against the reference.
        let tiles: Vec<Patch> = (0..150)
            .map(|i| {
                let (x, y) = (Real::from(i % 15), Real::from(i / 15));
                let size = [0.25, 0.75, 0.5][i as usize % 3];
                let pose = Isometry3::translation(0.0, 0.0, Real::from(i % 4) * 0.5);
                PlanarPatch::rectangle(pose, Point2::new(x, y), Point2::new(x + size, y + size))
                    .unwrap()
                    .into()
            })
            .collect();
        let map = PolygonMap::from_patches(tiles.clone()).unwrap();
        let reference = BruteForceMap::from_patches(tiles.clone()).unwrap();
        let mut hits = 0;
        for i in 0..400 {
            let t = Real::from(i);
            let a = Point3::new((t * 0.37) % 15.0, (t * 0.53) % 10.0, 1.2 + (t * 0.11) % 0.5);
            let b = Point3::new((t * 0.71) % 15.0, (t * 0.29) % 10.0, -0.3 + (t * 0.13) % 1.0);
            let step = CapsuleStep::new(a, b, 0.05 + (t * 0.07) % 0.2).unwrap();
            let free = reference.is_step_free(&step);
            assert_eq!(map.is_step_free(&step), free, "step {i}");
            hits += usize::from(!free);
        }
        assert!(hits > 50 && hits < 350, "{hits} hits");
        // Largest first, ties by id; adding one by one gives the order of `from_patches`.
        assert!(map.visit.windows(2).all(|w| visit_before(&w[0], &w[1]).is_lt()));
        assert_eq!(map.visit.len(), 150);
        assert_eq!((map.visit[0].1, map.visit[149].1), (1, 147));
        let mut grown = PolygonMap::new();
        for tile in tiles {
            grown.add_patch(tile).unwrap();
        }
        assert_eq!(grown.visit, map.visit);
    }

    #[test]
    fn empty_map_and_growth() {
        let mut map = PolygonMap::default();
        assert!(map.is_empty() && map.bounds().is_empty());
        let s = CapsuleStep::sphere(Point3::origin(), 1.0).unwrap();
        assert!(map.is_step_free(&s) && map.first_hit(&s).is_none());
        assert!(map.closest_patch(&Point3::origin(), Real::INFINITY).is_none());
        for (i, p) in floor_and_wall().into_iter().enumerate() {
            assert_eq!(map.add_patch(p), Ok(PatchId(i as u32)));
        }
        assert_eq!(map.patch_boxes().len(), 3);
        assert!(!map.is_step_free(&s));
        assert_eq!(map.clone().into_patches(), floor_and_wall());
    }

    #[test]
    fn ties_go_to_the_lowest_id() {
        // The same floor twice: every answer names patch 0.
        let floor: Patch = floor_and_wall().remove(0);
        let map = PolygonMap::from_patches([floor.clone(), floor]).unwrap();
        let down = LineStep::new(Point3::new(1.0, 1.0, 1.0), Point3::new(1.0, 1.0, -1.0)).unwrap();
        assert_eq!(map.first_hit(&down).unwrap().patch, PatchId(0));
        let p = Point3::new(1.0, 1.0, 1.0);
        assert_eq!(map.closest_patch(&p, Real::INFINITY).unwrap().patch, PatchId(0));
    }

    #[test]
    fn box_helpers() {
        let b = Aabb::new(Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 1.0, 1.0));
        assert_eq!(box_distance(&b, &Point3::new(0.5, 0.5, 0.5)), 0.0);
        assert_eq!(box_distance(&b, &Point3::new(4.0, 5.0, 0.5)), 5.0);
        let s = slackened(b);
        assert!(s.min.x < 0.0 && s.max.x > 1.0 && s.max.x - 1.0 < 1e-8);
        assert_eq!(next_id(0), Ok(PatchId(0)));
        assert_eq!(next_id(u32::MAX as usize), Err(MapError::TooManyPatches));
    }
}
