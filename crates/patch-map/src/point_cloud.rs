//! The point-cloud map (thesis §5.4.2, `PointCloudMap`): the scan points themselves are the map,
//! and a capsule step is checked by the thesis's Algorithm 10 on a k-d tree.
//!
//! # Algorithm 10 (sphere marching along the spine)
//! ```text
//! if NN(start) ≤ r or NN(end) ≤ r: collision
//! s = (end − start)/|end − start|;  q = start
//! while q is before end:
//!     D = distance from q to its nearest point;  if D ≤ r: collision
//!     q = q + s · sqrt(D² − r²)
//! free
//! ```
//! Why it is exact for point obstacles: the ball of radius D around q holds no point. A point
//! within r of the spine piece from q to q' = q + s·sqrt(D² − r²) whose closest spine point is
//! interior lies within `sqrt(a² + ρ²) < sqrt(D² − r² + r²) = D` of q (a = its offset along the
//! spine, ρ < r its distance from it), so inside the empty ball; one closest to q or to q' is
//! caught by the nearest-neighbour test at q or at q' (the next iteration, or the end test).
//!
//! # Density assumption
//! The map knows only points: a sphere can pass between samples of a surface. The test is a
//! correct collision check against the *surface* only where the points are denser than the robot:
//! neighbouring samples closer than about `2r`. Check the density of your scans against the robot
//! radius before relying on it; the thesis scopes this backend to the unspecific capsule test and
//! so does this crate.
//!
//! # Grazing steps
//! Near a point at distance just above r the march advances by tiny amounts (the thesis notes
//! that such steps are slow). An advance below [`PointCloudMap::MIN_ADVANCE`] reports the step as
//! colliding: a conservative answer (a free step may be called colliding when it passes within
//! about `MIN_ADVANCE² / (2r)` of touching), never the opposite, and never a hang.
//!
//! # Growing the map
//! Points are held in k-d trees of distinct power-of-two sizes (the logarithmic method), each a
//! `kiddo` immutable tree (its mutable tree fails when more than 32 points share a split
//! coordinate, which planar walls produce). Adding points costs amortised `O(log² n)` per point;
//! a nearest-neighbour query asks at most `log₂ n + 1` trees.

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use patch_core::{CapsuleStep, LineStep, Step, UnspecificStepIntersector};
use pointcloud::{Aabb, Point3, Real};

/// One static level: the points and their tree (items are indices into `points`).
struct Level {
    points: Vec<[Real; 3]>,
    tree: ImmutableKdTree<Real, 3>,
}

impl Level {
    fn build(points: Vec<[Real; 3]>) -> Level {
        // Construction fails only for trees larger than the item type can index (u32).
        let tree = ImmutableKdTree::new_from_slice(&points)
            .unwrap_or_else(|e| panic!("k-d tree over {} points: {e:?}", points.len()));
        Level { points, tree }
    }
}

impl std::fmt::Debug for Level {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Level").field("points", &self.points.len()).finish()
    }
}

/// Why points were refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PointCloudMapError {
    /// A coordinate is NaN or infinite.
    #[error("point {index} is not finite")]
    NonFinite {
        /// Its index in the input.
        index: usize,
    },
    /// More points than a map can index.
    #[error("a point-cloud map holds at most {max} points")]
    TooMany {
        /// The limit.
        max: usize,
    },
}

/// A map made of points, answering the unspecific capsule query by Algorithm 10.
#[derive(Debug)]
pub struct PointCloudMap {
    /// `levels[i]`: nothing, or exactly `2^i` points.
    levels: Vec<Option<Level>>,
    len: usize,
    bounds: Aabb,
}

impl Default for PointCloudMap {
    fn default() -> PointCloudMap {
        PointCloudMap::new()
    }
}

impl PointCloudMap {
    /// The smallest advance of the march, metres; below it a step counts as colliding.
    pub const MIN_ADVANCE: Real = 1e-6;
    /// The most points one map holds (the item type of the trees is `u32`).
    pub const MAX_POINTS: usize = u32::MAX as usize;

    /// An empty map (every step is free).
    pub fn new() -> PointCloudMap {
        PointCloudMap { levels: Vec::new(), len: 0, bounds: Aabb::EMPTY }
    }

    /// A map of `points`, which must be finite.
    pub fn from_points(points: &[Point3]) -> Result<PointCloudMap, PointCloudMapError> {
        let mut map = PointCloudMap::new();
        map.add_points(points)?;
        Ok(map)
    }

    /// A map of `points`, which must be finite: the same map as
    /// [`from_points`](Self::from_points), built from the vector's end. Each level takes its
    /// points off the end and the vector is shrunk, so the points are held about once while
    /// the map is built, not twice.
    pub fn from_point_vec(mut points: Vec<Point3>) -> Result<PointCloudMap, PointCloudMapError> {
        let mut map = PointCloudMap::new();
        map.admit(&points)?;
        let len = points.len();
        map.levels.resize_with((usize::BITS - len.leading_zeros()) as usize, || None);
        for level in (0..map.levels.len()).rev() {
            let size = 1usize << level;
            if len & size != 0 {
                let start = points.len() - size;
                let tail: Vec<[Real; 3]> =
                    points[start..].iter().map(|p| [p.x, p.y, p.z]).collect();
                points.truncate(start);
                points.shrink_to_fit();
                map.levels[level] = Some(Level::build(tail));
            }
        }
        map.len = len;
        Ok(map)
    }

    /// Checks that `points` may join the map (all finite, not too many) and grows the bounds
    /// by them.
    fn admit(&mut self, points: &[Point3]) -> Result<(), PointCloudMapError> {
        if let Some(index) = points.iter().position(|p| !p.coords.iter().all(|v| v.is_finite())) {
            return Err(PointCloudMapError::NonFinite { index });
        }
        if self.len + points.len() > Self::MAX_POINTS {
            return Err(PointCloudMapError::TooMany { max: Self::MAX_POINTS });
        }
        for p in points {
            self.bounds.grow(p);
        }
        Ok(())
    }

    /// Adds points (all or none: a non-finite point refuses the whole batch).
    ///
    /// # Complexity
    /// Amortised `O(m log² n)` for `m` points.
    pub fn add_points(&mut self, points: &[Point3]) -> Result<(), PointCloudMapError> {
        self.admit(points)?;
        // Binary-counter merge, one level per set bit of the new length: the new points and
        // every level whose bit carries are rebuilt into the level where the carry stops. The
        // points flow from the input and the old levels straight into the new levels (each
        // level takes the last points of "new points, then the old levels' points"), so the
        // merge holds one copy of them, not three.
        let new_len = self.len + points.len();
        let bits = (usize::BITS - new_len.leading_zeros()) as usize;
        self.levels.resize_with(bits.max(self.levels.len()), || None);
        let old: Vec<Vec<[Real; 3]>> =
            self.levels.iter_mut().filter_map(|l| l.take().map(|l| l.points)).collect();
        let mut pending = points.iter().map(|p| [p.x, p.y, p.z]).chain(old.into_iter().flatten());
        for level in (0..self.levels.len()).rev() {
            let size = 1usize << level;
            if new_len & size != 0 {
                let mut tail: Vec<[Real; 3]> = pending.by_ref().rev().take(size).collect();
                tail.reverse();
                self.levels[level] = Some(Level::build(tail));
            }
        }
        debug_assert!(pending.next().is_none());
        self.len = new_len;
        Ok(())
    }

    /// The number of points.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the map has no point.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The bounding box of the points.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The nearest map point to `q` and its distance, or `None` for an empty map.
    pub fn nearest(&self, q: &Point3) -> Option<(Point3, Real)> {
        let query = [q.x, q.y, q.z];
        let mut best: Option<([Real; 3], Real)> = None;
        for level in self.levels.iter().flatten() {
            let nn = level.tree.query(&query).nearest_one::<SquaredEuclidean<Real>>().execute();
            if best.is_none_or(|(_, d2)| nn.distance < d2) {
                best = Some((level.points[nn.item as usize], nn.distance));
            }
        }
        best.map(|(p, d2)| (Point3::new(p[0], p[1], p[2]), d2.sqrt()))
    }

    /// Whether the capsule of radius `r` around the segment `start → end` holds no map point
    /// (Algorithm 10; see the module docs for the exactness argument and the conservative
    /// handling of grazing steps). `r` must be finite and non-negative, the points finite;
    /// anything else is reported as colliding.
    pub fn capsule_is_free(&self, start: &Point3, end: &Point3, r: Real) -> bool {
        let finite = |p: &Point3| p.coords.iter().all(|v| v.is_finite());
        if !(r.is_finite() && r >= 0.0 && finite(start) && finite(end)) {
            return false;
        }
        if self.is_empty() {
            return true;
        }
        let clear = |q: &Point3| self.nearest(q).map_or(Real::INFINITY, |(_, d)| d);
        if clear(start) <= r || clear(end) <= r {
            return false;
        }
        let delta = end - start;
        let length = delta.norm();
        if length == 0.0 {
            return true;
        }
        let s = delta / length;
        let mut along = 0.0;
        while along < length {
            let d = clear(&(start + s * along));
            if d <= r {
                return false;
            }
            let advance = ((d - r) * (d + r)).sqrt();
            if advance < Self::MIN_ADVANCE {
                return false;
            }
            along += advance;
        }
        true
    }

    /// The bytes of point storage (the points are stored twice: in the level's array and in the
    /// tree's leaves) plus the item ids. The trees' stems, a few bytes per leaf of 32 points, are
    /// not counted.
    pub fn memory_bytes(&self) -> usize {
        let per_point = 2 * std::mem::size_of::<[Real; 3]>() + std::mem::size_of::<u32>();
        self.len * per_point
    }

    /// Every point, level by level (the order is not the insertion order).
    pub fn points(&self) -> impl Iterator<Item = Point3> + '_ {
        self.levels
            .iter()
            .flatten()
            .flat_map(|l| l.points.iter().map(|p| Point3::new(p[0], p[1], p[2])))
    }
}

/// Thesis §5.4.2: the point-cloud map is an Unspecific*Capsule*Intersector only (no proximity,
/// no specific queries, not a patch map). [`PointCloudMap::capsule_is_free`] with the step's
/// radius; exact against the points, conservative by at most about
/// `MIN_ADVANCE² / (2r)` for grazing steps, and a check against the sampled *surface* only
/// under the density assumption of the [module docs](self).
impl UnspecificStepIntersector for PointCloudMap {
    fn is_step_free(&self, step: &CapsuleStep) -> bool {
        self.capsule_is_free(&step.start(), &step.end(), step.radius())
    }
}

/// The line variant: [`PointCloudMap::capsule_is_free`] with radius 0. A segment almost never
/// meets a sample exactly, so against a sampled surface this answer is meaningful only as the
/// thesis's "approximation"; prefer capsule steps of the robot's radius.
impl UnspecificStepIntersector<LineStep> for PointCloudMap {
    fn is_step_free(&self, step: &LineStep) -> bool {
        self.capsule_is_free(&step.start(), &step.end(), 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The oracle: the capsule holds a point iff the point's distance to the segment is ≤ r.
    fn segment_distance(p: &Point3, a: &Point3, b: &Point3) -> Real {
        let ab = b - a;
        let len2 = ab.norm_squared();
        let t = if len2 == 0.0 { 0.0 } else { ((p - a).dot(&ab) / len2).clamp(0.0, 1.0) };
        (p - (a + ab * t)).norm()
    }

    fn oracle_min_distance(points: &[Point3], a: &Point3, b: &Point3) -> Real {
        points.iter().map(|p| segment_distance(p, a, b)).fold(Real::INFINITY, Real::min)
    }

    fn point() -> impl Strategy<Value = Point3> {
        (-5.0f64..5.0, -5.0f64..5.0, -2.0f64..2.0).prop_map(|(x, y, z)| Point3::new(x, y, z))
    }

    proptest! {
        #[test]
        fn capsule_test_agrees_with_brute_force(
            pts in prop::collection::vec(point(), 1..120),
            a in point(), b in point(), r in 0.0f64..1.5,
        ) {
            let map = PointCloudMap::from_points(&pts).unwrap();
            let free = map.capsule_is_free(&a, &b, r);
            let d = oracle_min_distance(&pts, &a, &b);
            if free {
                prop_assert!(d > r, "reported free, but a point is {d} ≤ {r} from the spine");
            } else {
                // Conservative only within the grazing tolerance.
                prop_assert!(d <= r + 1e-6, "reported colliding, but the nearest point is {d} > {r}");
            }
        }

        /// Built from a vector, the map has the same levels, holding the same points in the
        /// same order, as built from a slice.
        #[test]
        fn from_point_vec_builds_the_same_map(pts in prop::collection::vec(point(), 0..300), q in point()) {
            let a = PointCloudMap::from_points(&pts).unwrap();
            let b = PointCloudMap::from_point_vec(pts.clone()).unwrap();
            prop_assert_eq!(a.len(), b.len());
            prop_assert_eq!(a.bounds(), b.bounds());
            let level_sizes = |m: &PointCloudMap| {
                m.levels.iter().map(|l| l.as_ref().map(|l| l.points.len())).collect::<Vec<_>>()
            };
            prop_assert_eq!(level_sizes(&a), level_sizes(&b));
            prop_assert!(a.points().eq(b.points()));
            prop_assert_eq!(a.nearest(&q), b.nearest(&q));
        }

        #[test]
        fn nearest_agrees_with_brute_force_while_growing(
            batches in prop::collection::vec(prop::collection::vec(point(), 0..40), 1..6),
            q in point(),
        ) {
            let mut map = PointCloudMap::new();
            let mut all = Vec::new();
            for batch in &batches {
                map.add_points(batch).unwrap();
                all.extend_from_slice(batch);
                prop_assert_eq!(map.len(), all.len());
                let expected = all.iter().map(|p| (p - q).norm()).fold(Real::INFINITY, Real::min);
                match map.nearest(&q) {
                    None => prop_assert!(all.is_empty()),
                    Some((p, d)) => {
                        prop_assert!((d - expected).abs() < 1e-9);
                        prop_assert!(((p - q).norm() - d).abs() < 1e-9);
                    }
                }
            }
            prop_assert_eq!(map.points().count(), all.len());
        }
    }

    #[test]
    fn a_flat_wall_of_many_equal_coordinates_works() {
        // 40 × 40 points on the plane x = 2, 0.25 m apart (exact in binary): far more than 32
        // points share the coordinate x = 2.
        let wall: Vec<Point3> = (0..1600)
            .map(|i| Point3::new(2.0, (i % 40) as f64 * 0.25, (i / 40) as f64 * 0.25))
            .collect();
        let map = PointCloudMap::from_points(&wall).unwrap();
        let from = Point3::new(0.0, 1.0, 1.0);
        let to = |x: f64| Point3::new(x, 1.0, 1.0);
        assert!(!map.capsule_is_free(&from, &to(4.0), 0.1), "through the wall");
        assert!(map.capsule_is_free(&from, &to(1.25), 0.5), "stops 0.25 m short of touching");
        assert!(!map.capsule_is_free(&from, &to(1.5), 0.5), "touching exactly counts");
        assert!(!map.capsule_is_free(&from, &to(1.75), 0.5), "overlapping");
    }

    #[test]
    fn many_identical_points_build_and_answer() {
        // Duplicate returns are common in scans; far more than a k-d bucket holds.
        let pts = vec![Point3::new(1.0, 2.0, 3.0); 1000];
        let map = PointCloudMap::from_points(&pts).unwrap();
        assert_eq!(map.len(), 1000);
        let (p, d) = map.nearest(&Point3::origin()).unwrap();
        assert_eq!(p, pts[0]);
        assert!((d - 14f64.sqrt()).abs() < 1e-12);
        assert!(!map.capsule_is_free(&Point3::origin(), &Point3::new(2.0, 4.0, 6.0), 0.1));
    }

    #[test]
    fn degenerate_inputs() {
        let empty = PointCloudMap::new();
        let o = Point3::origin();
        assert!(empty.capsule_is_free(&o, &Point3::new(1.0, 0.0, 0.0), 1.0));
        assert!(empty.nearest(&o).is_none());
        let map = PointCloudMap::from_points(&[Point3::new(1.0, 0.0, 0.0)]).unwrap();
        assert!(map.capsule_is_free(&o, &o, 0.5), "zero-length step away from points");
        assert!(!map.capsule_is_free(&o, &o, 1.0), "zero-length step touching a point");
        assert!(
            !map.capsule_is_free(&o, &Point3::new(2.0, 0.0, 0.0), 0.0),
            "r = 0 through a point"
        );
        assert!(!map.capsule_is_free(&o, &Point3::new(f64::NAN, 0.0, 0.0), 0.1));
        assert!(!map.capsule_is_free(&o, &o, -1.0));
        assert_eq!(
            PointCloudMap::from_points(&[o, Point3::new(0.0, f64::INFINITY, 0.0)]).unwrap_err(),
            PointCloudMapError::NonFinite { index: 1 }
        );
    }
}
