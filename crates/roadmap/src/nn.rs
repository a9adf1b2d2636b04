//! Nearest-neighbour search over the roadmap's vertices.

use std::num::NonZeroUsize;

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use patch_core::{Point3, Real};

/// A growing set of points answering nearest-neighbour queries; points are numbered by
/// insertion order from 0 (the planners keep this equal to the roadmap's node index).
///
/// Ties in distance go to the smaller index, so answers (and with them the planners) are
/// deterministic.
pub trait NearestNeighbors {
    /// Adds a point; its index is the previous [`len`](NearestNeighbors::len).
    fn add(&mut self, point: Point3);

    /// The number of points.
    fn len(&self) -> usize;

    /// Whether there is no point.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Removes all points.
    fn clear(&mut self);

    /// The up to `k` points nearest to `query` with distance at most `max_dist`, as
    /// `(index, distance)` sorted by increasing distance, then index.
    fn k_nearest(&self, query: &Point3, k: usize, max_dist: Real) -> Vec<Neighbor>;

    /// The nearest point, if any.
    fn nearest(&self, query: &Point3) -> Option<Neighbor> {
        self.k_nearest(query, 1, Real::INFINITY).into_iter().next()
    }
}

/// One answer of a [`NearestNeighbors`] query.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Neighbor {
    /// The point's insertion index.
    pub index: usize,
    /// Its Euclidean distance to the query.
    pub distance: Real,
}

/// The reference implementation: a linear scan, O(n) per query (O(n log k) for `k`).
///
/// Exact and simple: the oracle [`KdNeighbors`] is checked against.
#[derive(Clone, Debug, Default)]
pub struct LinearNeighbors {
    points: Vec<Point3>,
}

impl LinearNeighbors {
    /// An empty set.
    pub fn new() -> LinearNeighbors {
        LinearNeighbors::default()
    }
}

impl NearestNeighbors for LinearNeighbors {
    fn add(&mut self, point: Point3) {
        self.points.push(point);
    }

    fn len(&self) -> usize {
        self.points.len()
    }

    fn clear(&mut self) {
        self.points.clear();
    }

    fn k_nearest(&self, query: &Point3, k: usize, max_dist: Real) -> Vec<Neighbor> {
        if k == 0 {
            return Vec::new();
        }
        let mut out: Vec<Neighbor> = self
            .points
            .iter()
            .enumerate()
            .map(|(index, p)| Neighbor { index, distance: (p - query).norm() })
            .filter(|n| n.distance <= max_dist)
            .collect();
        let by_distance = |a: &Neighbor, b: &Neighbor| {
            a.distance.total_cmp(&b.distance).then(a.index.cmp(&b.index))
        };
        if out.len() > k {
            out.select_nth_unstable_by(k - 1, by_distance);
            out.truncate(k);
        }
        out.sort_by(by_distance);
        out
    }
}

/// Points below this count stay in a linear buffer; trees hold multiples of it.
const BUFFER: usize = 32;

/// One static level of a [`KdNeighbors`]: points, their global indices, their tree.
struct Level {
    points: Vec<[Real; 3]>,
    indices: Vec<usize>,
    /// `None` only if `kiddo` refused to build (more points than its `u32` items index);
    /// the level is then scanned linearly.
    tree: Option<ImmutableKdTree<Real, 3>>,
}

impl Level {
    fn build(points: Vec<[Real; 3]>, indices: Vec<usize>) -> Level {
        let tree = ImmutableKdTree::new_from_slice(&points).ok();
        Level { points, indices, tree }
    }
}

/// Exact nearest neighbours in `kiddo` immutable k-d trees grown by the logarithmic method:
/// the newest points (fewer than 32) are scanned linearly, the rest sit in trees of
/// `32 · 2^i` points, rebuilt by binary-counter merging (`kiddo`'s mutable tree fails when
/// more than 32 points share a split coordinate, which planar scenes produce).
///
/// Answers equal [`LinearNeighbors`]'s (checked by property tests) except that among points
/// at exactly equal distance at the `k`-th place a tree may keep another one; answers are
/// still deterministic.
///
/// # Complexity
/// Adding is amortised `O(log² n)`; a query asks at most `log₂(n/32) + 1` trees and the
/// buffer.
#[derive(Default)]
pub struct KdNeighbors {
    buffer: Vec<(usize, Point3)>,
    /// `levels[i]`: nothing, or exactly `BUFFER · 2^i` points.
    levels: Vec<Option<Level>>,
    len: usize,
}

impl std::fmt::Debug for KdNeighbors {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let sizes: Vec<usize> = self.levels.iter().flatten().map(|l| l.points.len()).collect();
        f.debug_struct("KdNeighbors")
            .field("len", &self.len)
            .field("buffer", &self.buffer.len())
            .field("levels", &sizes)
            .finish()
    }
}

impl KdNeighbors {
    /// An empty set.
    pub fn new() -> KdNeighbors {
        KdNeighbors::default()
    }

    fn flush(&mut self) {
        let (mut indices, mut points): (Vec<usize>, Vec<[Real; 3]>) =
            self.buffer.drain(..).map(|(i, p)| (i, [p.x, p.y, p.z])).unzip();
        for slot in self.levels.iter_mut() {
            match slot.take() {
                None => {
                    *slot = Some(Level::build(points, indices));
                    return;
                }
                Some(level) => {
                    points.extend(level.points);
                    indices.extend(level.indices);
                }
            }
        }
        self.levels.push(Some(Level::build(points, indices)));
    }
}

impl NearestNeighbors for KdNeighbors {
    fn add(&mut self, point: Point3) {
        self.buffer.push((self.len, point));
        self.len += 1;
        if self.buffer.len() >= BUFFER {
            self.flush();
        }
    }

    fn len(&self) -> usize {
        self.len
    }

    fn clear(&mut self) {
        *self = KdNeighbors::default();
    }

    fn k_nearest(&self, query: &Point3, k: usize, max_dist: Real) -> Vec<Neighbor> {
        let Some(qty) = NonZeroUsize::new(k) else {
            return Vec::new();
        };
        let neighbor = |index: usize, p: &Point3| Neighbor { index, distance: (p - query).norm() };
        let mut out: Vec<Neighbor> = self.buffer.iter().map(|(i, p)| neighbor(*i, p)).collect();
        let q = [query.x, query.y, query.z];
        for level in self.levels.iter().flatten() {
            let at = |item: usize| neighbor(level.indices[item], &Point3::from(level.points[item]));
            match &level.tree {
                Some(tree) => out.extend(
                    tree.query(&q)
                        .nearest_n::<SquaredEuclidean<Real>>(qty)
                        .execute()
                        .into_iter()
                        .map(|r| at(r.item as usize)),
                ),
                None => out.extend((0..level.points.len()).map(at)),
            }
        }
        out.retain(|n| n.distance <= max_dist);
        out.sort_by(|a, b| a.distance.total_cmp(&b.distance).then(a.index.cmp(&b.index)));
        out.truncate(k);
        out
    }

    /// [`k_nearest`](NearestNeighbors::k_nearest) with `k = 1`, without allocating: one
    /// exact nearest-one query per tree (RRT's hot path).
    fn nearest(&self, query: &Point3) -> Option<Neighbor> {
        let mut best: Option<Neighbor> = None;
        let mut consider = |index: usize, p: &Point3| {
            let n = Neighbor { index, distance: (p - query).norm() };
            let closer = |b: &Neighbor| {
                n.distance.total_cmp(&b.distance).then(n.index.cmp(&b.index)).is_lt()
            };
            if best.as_ref().is_none_or(closer) {
                best = Some(n);
            }
        };
        for (i, p) in &self.buffer {
            consider(*i, p);
        }
        let q = [query.x, query.y, query.z];
        for level in self.levels.iter().flatten() {
            let mut at =
                |item: usize| consider(level.indices[item], &Point3::from(level.points[item]));
            match &level.tree {
                Some(tree) => {
                    at(tree.query(&q).nearest_one::<SquaredEuclidean<Real>>().execute().item
                        as usize)
                }
                None => (0..level.points.len()).for_each(at),
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ties_and_limits() {
        let mut nn = LinearNeighbors::new();
        assert!(nn.is_empty() && nn.nearest(&Point3::origin()).is_none());
        for p in [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0.5, 0.0, 0.0]] {
            nn.add(Point3::from(p));
        }
        let q = Point3::origin();
        assert_eq!(nn.nearest(&q).unwrap().index, 3);
        let idx: Vec<usize> = nn.k_nearest(&q, 3, Real::INFINITY).iter().map(|n| n.index).collect();
        assert_eq!(idx, [3, 0, 1]);
        assert_eq!(nn.k_nearest(&q, 10, 1.0).len(), 3);
        assert!(nn.k_nearest(&q, 0, 1.0).is_empty());
        nn.clear();
        assert_eq!(nn.len(), 0);
    }
}

#[cfg(test)]
mod proptests {
    use super::*;
    use proptest::prelude::*;

    fn point() -> impl Strategy<Value = Point3> {
        // A coarse grid half of the time, so equal coordinates and exact ties occur.
        prop_oneof![
            (-50.0..50.0, -50.0..50.0, -5.0..5.0).prop_map(|(x, y, z)| Point3::new(x, y, z)),
            (-4i32..4, -4i32..4, 0i32..2).prop_map(|(x, y, z)| Point3::new(
                x.into(),
                y.into(),
                z.into()
            )),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

        #[test]
        fn kd_agrees_with_linear_while_growing(
            points in proptest::collection::vec(point(), 0..300),
            queries in proptest::collection::vec(point(), 1..8),
            k in 0usize..10,
            max_dist in prop_oneof![Just(Real::INFINITY), 0.0..30.0],
        ) {
            let (mut kd, mut linear) = (KdNeighbors::new(), LinearNeighbors::new());
            for (n, p) in points.iter().enumerate() {
                kd.add(*p);
                linear.add(*p);
                if n % 37 != 0 && n + 1 != points.len() {
                    continue;
                }
                prop_assert_eq!(kd.len(), linear.len());
                for q in &queries {
                    let a = kd.k_nearest(q, k, max_dist);
                    let b = linear.k_nearest(q, k, max_dist);
                    let da: Vec<Real> = a.iter().map(|n| n.distance).collect();
                    let db: Vec<Real> = b.iter().map(|n| n.distance).collect();
                    prop_assert_eq!(da, db);
                    for n in &a {
                        prop_assert_eq!((points[n.index] - q).norm(), n.distance);
                    }
                    let one = kd.nearest(q);
                    prop_assert_eq!(one.map(|n| n.distance), linear.nearest(q).map(|n| n.distance));
                    if let Some(n) = one {
                        prop_assert_eq!((points[n.index] - q).norm(), n.distance);
                    }
                }
            }
            kd.clear();
            prop_assert!(kd.is_empty() && kd.nearest(&Point3::origin()).is_none());
        }
    }

    #[test]
    fn many_equal_coordinates() {
        // A planar wall of points: far more than 32 share x.
        let mut kd = KdNeighbors::new();
        for i in 0..2000 {
            kd.add(Point3::new(1.0, Real::from(i % 50), Real::from(i / 50)));
        }
        let n = kd.k_nearest(&Point3::new(0.0, 10.2, 3.0), 3, Real::INFINITY);
        assert_eq!(n.len(), 3);
        assert_eq!(n[0].index, 3 * 50 + 10);
        assert!(format!("{kd:?}").contains("len: 2000"));
    }
}
