//! K-dimensional trees with orthogonal range queries: the broad phase of the 6D bounding-box map
//! (thesis §5.4.2, `BoundingBox6DPatchMap`, after Baraff's sweep and prune).
//!
//! Each patch's axis-aligned box `(min, max)` is one point in 6D. A step's box `B` overlaps a
//! patch box exactly when the patch point lies in the orthogonal range
//! `(−∞, B.max] × (−∞, B.max] × (−∞, B.max] × [B.min, ∞) × [B.min, ∞) × [B.min, ∞)`
//! (the thesis's "min_Q[4−6] = ∞" is a typo for max_Q). `kiddo` offers no box query, so the
//! tree is written here:
//!
//! * [`StaticKdTree`]: built once by median splits on cycling axes in an implicit layout (the
//!   median of a range sits in the middle of it; no node structs, no pointers), queried with
//!   closed intervals per dimension (`±∞` allowed). Each inner node also keeps the bounding
//!   box of the points below it, and a query skips a subtree whose box misses the range. For
//!   6D box points that box is the union of the patches' boxes below the node, so the tree is
//!   also a bounding-volume hierarchy over the patches: without it, a map of tens of
//!   thousands of patches of mixed sizes visited thousands of nodes per query (the
//!   `O(n^(1 − 1/k))` worst case of a 6D range query). Build `O(n log n)`, query
//!   `O(n^(1 − 1/k) + m)` for `m` results at worst, memory: the points, item ids and one box
//!   per inner node.
//! * [`KdForest`]: the same, growable by the logarithmic method (Bentley and Saxe 1980): static
//!   trees of sizes that are distinct powers of two, merged like a binary counter. An insertion
//!   costs amortised `O(log² n)`; a query visits at most `log₂ n + 1` trees.
//!
//! Both are checked against a linear scan on random inputs.

use std::ops::ControlFlow;

/// Ranges of at most this many points are scanned linearly instead of split further.
const LEAF_SIZE: usize = 8;

/// A closed box in `K` dimensions: `min[i] ≤ x[i] ≤ max[i]` for every `i`; bounds may be infinite.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct RangeQuery<const K: usize> {
    /// Lower bounds (use `f64::NEG_INFINITY` for none).
    pub min: [f64; K],
    /// Upper bounds (use `f64::INFINITY` for none).
    pub max: [f64; K],
}

impl<const K: usize> RangeQuery<K> {
    /// Whether `p` lies in the closed range. NaN coordinates never do.
    #[inline]
    pub fn contains(&self, p: &[f64; K]) -> bool {
        (0..K).all(|i| self.min[i] <= p[i] && p[i] <= self.max[i])
    }
}

/// The bounding box `(min, max)` of some points; empty (`min > max`) if there are none or
/// all are NaN on an axis.
type Cell<const K: usize> = ([f64; K], [f64; K]);

fn empty_cell<const K: usize>() -> Cell<K> {
    ([f64::INFINITY; K], [f64::NEG_INFINITY; K])
}

/// Grows `cell` by `p` (NaN coordinates are ignored: such points are never returned).
fn grow<const K: usize>(cell: &mut Cell<K>, p: &[f64; K]) {
    for (i, &x) in p.iter().enumerate() {
        cell.0[i] = cell.0[i].min(x);
        cell.1[i] = cell.1[i].max(x);
    }
}

/// Whether some point of `cell` may lie in `query`.
#[inline]
fn meets<const K: usize>(cell: &Cell<K>, query: &RangeQuery<K>) -> bool {
    (0..K).all(|i| cell.0[i] <= query.max[i] && query.min[i] <= cell.1[i])
}

/// A balanced k-d tree over `K`-dimensional points, each carrying a `u32` item id, with the
/// bounding box of the points below each inner node.
///
/// # Complexity
/// Build `O(n log n)`; a range query `O(n^(1 − 1/K) + m)` at worst; memory
/// `n · (8K + 4)` bytes plus `16K` bytes per inner node (about `n / 4` of them).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StaticKdTree<const K: usize> {
    /// Points in tree order.
    points: Vec<[f64; K]>,
    /// The item id of each point, same order.
    items: Vec<u32>,
    /// The box of the points of each inner node's range (longer than a leaf), by node
    /// number: the root is 0, the children of `n` are `2n + 1` and `2n + 2`.
    cells: Vec<Cell<K>>,
}

impl<const K: usize> StaticKdTree<K> {
    /// Builds the tree. Points with a NaN coordinate are never returned by a query (they are
    /// kept, so `len` counts them, but fail every comparison).
    pub fn build(entries: Vec<([f64; K], u32)>) -> StaticKdTree<K> {
        let mut entries = entries;
        build_range(&mut entries, 0);
        let (points, items): (Vec<[f64; K]>, Vec<u32>) = entries.into_iter().unzip();
        let mut cells = Vec::new();
        cell_of_range(&points, 0, points.len(), 0, &mut cells);
        StaticKdTree { points, items, cells }
    }

    /// The number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether the tree is empty.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Calls `f(item)` for every point in the closed range `query`, in no particular order.
    pub fn for_each_in_range(&self, query: &RangeQuery<K>, f: &mut impl FnMut(u32)) {
        self.visit(0, self.points.len(), 0, 0, query, f);
    }

    /// The items of every point in the range, in no particular order.
    pub fn items_in_range(&self, query: &RangeQuery<K>) -> Vec<u32> {
        let mut out = Vec::new();
        self.for_each_in_range(query, &mut |i| out.push(i));
        out
    }

    /// Calls `f(item)` for points in the closed range until `f` breaks; returns the break
    /// value, or `Continue` after every point in the range was visited (an any-hit query:
    /// the traversal stops at the first break).
    pub fn try_for_each_in_range<B>(
        &self,
        query: &RangeQuery<K>,
        f: &mut impl FnMut(u32) -> ControlFlow<B>,
    ) -> ControlFlow<B> {
        self.try_visit(0, self.points.len(), 0, 0, query, f)
    }

    /// The bytes this tree owns (points, item ids and node boxes; not the struct itself).
    pub fn memory_bytes(&self) -> usize {
        self.points.capacity() * std::mem::size_of::<[f64; K]>()
            + self.items.capacity() * std::mem::size_of::<u32>()
            + self.cells.capacity() * std::mem::size_of::<Cell<K>>()
    }

    fn visit(
        &self,
        lo: usize,
        hi: usize,
        depth: usize,
        node: usize,
        query: &RangeQuery<K>,
        f: &mut impl FnMut(u32),
    ) {
        if hi - lo <= LEAF_SIZE {
            for i in lo..hi {
                if query.contains(&self.points[i]) {
                    f(self.items[i]);
                }
            }
            return;
        }
        if !meets(&self.cells[node], query) {
            return;
        }
        let mid = lo + (hi - lo) / 2;
        let axis = depth % K;
        let split = self.points[mid][axis];
        if query.contains(&self.points[mid]) {
            f(self.items[mid]);
        }
        // Left of `mid` every coordinate on `axis` is ≤ split, right of it ≥ split (in
        // `total_cmp` order). A NaN split is incomparable and visits both sides.
        use std::cmp::Ordering::{Greater, Less};
        if query.min[axis].partial_cmp(&split) != Some(Greater) {
            self.visit(lo, mid, depth + 1, 2 * node + 1, query, f);
        }
        if query.max[axis].partial_cmp(&split) != Some(Less) {
            self.visit(mid + 1, hi, depth + 1, 2 * node + 2, query, f);
        }
    }

    /// [`visit`](Self::visit) with early exit.
    fn try_visit<B>(
        &self,
        lo: usize,
        hi: usize,
        depth: usize,
        node: usize,
        query: &RangeQuery<K>,
        f: &mut impl FnMut(u32) -> ControlFlow<B>,
    ) -> ControlFlow<B> {
        if hi - lo <= LEAF_SIZE {
            for i in lo..hi {
                if query.contains(&self.points[i]) {
                    f(self.items[i])?;
                }
            }
            return ControlFlow::Continue(());
        }
        if !meets(&self.cells[node], query) {
            return ControlFlow::Continue(());
        }
        let mid = lo + (hi - lo) / 2;
        let axis = depth % K;
        let split = self.points[mid][axis];
        if query.contains(&self.points[mid]) {
            f(self.items[mid])?;
        }
        use std::cmp::Ordering::{Greater, Less};
        if query.min[axis].partial_cmp(&split) != Some(Greater) {
            self.try_visit(lo, mid, depth + 1, 2 * node + 1, query, f)?;
        }
        if query.max[axis].partial_cmp(&split) != Some(Less) {
            self.try_visit(mid + 1, hi, depth + 1, 2 * node + 2, query, f)?;
        }
        ControlFlow::Continue(())
    }

    fn into_entries(self) -> impl Iterator<Item = ([f64; K], u32)> {
        self.points.into_iter().zip(self.items)
    }
}

/// The box of `points[lo..hi]` (in tree order), storing that of every inner node in
/// `cells[node]` on the way.
fn cell_of_range<const K: usize>(
    points: &[[f64; K]],
    lo: usize,
    hi: usize,
    node: usize,
    cells: &mut Vec<Cell<K>>,
) -> Cell<K> {
    if hi - lo <= LEAF_SIZE {
        let mut cell = empty_cell();
        points[lo..hi].iter().for_each(|p| grow(&mut cell, p));
        return cell;
    }
    let mid = lo + (hi - lo) / 2;
    let mut cell = cell_of_range(points, lo, mid, 2 * node + 1, cells);
    let right = cell_of_range(points, mid + 1, hi, 2 * node + 2, cells);
    for i in 0..K {
        cell.0[i] = cell.0[i].min(right.0[i]);
        cell.1[i] = cell.1[i].max(right.1[i]);
    }
    grow(&mut cell, &points[mid]);
    if cells.len() <= node {
        cells.resize(node + 1, empty_cell());
    }
    cells[node] = cell;
    cell
}

/// Orders `entries` into the implicit tree layout: the median on the cycling axis in the middle,
/// smaller-or-equal values left of it, greater-or-equal right of it, recursively.
fn build_range<const K: usize>(entries: &mut [([f64; K], u32)], depth: usize) {
    if entries.len() <= LEAF_SIZE {
        return;
    }
    let mid = entries.len() / 2;
    let axis = depth % K;
    entries.select_nth_unstable_by(mid, |a, b| a.0[axis].total_cmp(&b.0[axis]));
    let (left, rest) = entries.split_at_mut(mid);
    build_range(left, depth + 1);
    build_range(&mut rest[1..], depth + 1);
}

/// A growable set of k-d trees (the logarithmic method): insertion amortised `O(log² n)`, a
/// range query visits at most `log₂ n + 1` static trees.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct KdForest<const K: usize> {
    /// `levels[i]` holds either nothing or a tree of exactly `2^i` points.
    levels: Vec<Option<StaticKdTree<K>>>,
    len: usize,
}

impl<const K: usize> KdForest<K> {
    /// An empty forest.
    pub fn new() -> KdForest<K> {
        KdForest { levels: Vec::new(), len: 0 }
    }

    /// A forest holding `entries`, built as balanced trees directly (`O(n log n)`).
    pub fn from_entries(entries: Vec<([f64; K], u32)>) -> KdForest<K> {
        let mut forest = KdForest::new();
        let mut rest = entries;
        // One tree per set bit of n, largest first, so the layout equals n insertions'.
        let n = rest.len();
        forest.len = n;
        let bits = usize::BITS - n.leading_zeros();
        forest.levels = vec![None; bits as usize];
        for level in (0..bits as usize).rev() {
            if n & (1 << level) != 0 {
                let tail = rest.split_off(rest.len() - (1 << level));
                forest.levels[level] = Some(StaticKdTree::build(tail));
            }
        }
        forest
    }

    /// Adds a point. Amortised `O(log² n)`: the new point and every full level below the first
    /// empty one are rebuilt into one tree at that level.
    pub fn insert(&mut self, point: [f64; K], item: u32) {
        let mut carry = vec![(point, item)];
        let mut level = 0;
        loop {
            if level == self.levels.len() {
                self.levels.push(None);
            }
            match self.levels[level].take() {
                Some(tree) => {
                    carry.extend(tree.into_entries());
                    level += 1;
                }
                None => {
                    self.levels[level] = Some(StaticKdTree::build(carry));
                    break;
                }
            }
        }
        self.len += 1;
    }

    /// The number of points.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the forest is empty.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Calls `f(item)` for every point in the closed range, in no particular order.
    pub fn for_each_in_range(&self, query: &RangeQuery<K>, f: &mut impl FnMut(u32)) {
        for tree in self.levels.iter().flatten() {
            tree.for_each_in_range(query, f);
        }
    }

    /// The items of every point in the range, in no particular order.
    pub fn items_in_range(&self, query: &RangeQuery<K>) -> Vec<u32> {
        let mut out = Vec::new();
        self.for_each_in_range(query, &mut |i| out.push(i));
        out
    }

    /// Calls `f(item)` for points in the closed range until `f` breaks (see
    /// [`StaticKdTree::try_for_each_in_range`]).
    pub fn try_for_each_in_range<B>(
        &self,
        query: &RangeQuery<K>,
        f: &mut impl FnMut(u32) -> ControlFlow<B>,
    ) -> ControlFlow<B> {
        for tree in self.levels.iter().flatten() {
            tree.try_for_each_in_range(query, f)?;
        }
        ControlFlow::Continue(())
    }

    /// The bytes the trees own.
    pub fn memory_bytes(&self) -> usize {
        self.levels.capacity() * std::mem::size_of::<Option<StaticKdTree<K>>>()
            + self.levels.iter().flatten().map(StaticKdTree::memory_bytes).sum::<usize>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn linear(entries: &[([f64; 3], u32)], q: &RangeQuery<3>) -> Vec<u32> {
        let mut v: Vec<u32> = entries.iter().filter(|e| q.contains(&e.0)).map(|e| e.1).collect();
        v.sort_unstable();
        v
    }

    fn sorted(mut v: Vec<u32>) -> Vec<u32> {
        v.sort_unstable();
        v
    }

    /// Coordinates from a small grid, so many points share a split value (flat walls).
    fn coord() -> impl Strategy<Value = f64> {
        prop_oneof![(-5i32..5).prop_map(|i| i as f64 * 0.5), -3.0f64..3.0]
    }

    fn bound() -> impl Strategy<Value = f64> {
        prop_oneof![Just(f64::NEG_INFINITY), Just(f64::INFINITY), coord()]
    }

    prop_compose! {
        fn entries()(pts in prop::collection::vec([coord(), coord(), coord()], 0..200)) -> Vec<([f64; 3], u32)> {
            pts.into_iter().enumerate().map(|(i, p)| (p, i as u32)).collect()
        }
    }

    prop_compose! {
        fn query()(a in [bound(), bound(), bound()], b in [bound(), bound(), bound()]) -> RangeQuery<3> {
            RangeQuery { min: a, max: b }
        }
    }

    proptest! {
        #[test]
        fn static_tree_matches_linear_scan(e in entries(), qs in prop::collection::vec(query(), 1..20)) {
            let tree = StaticKdTree::build(e.clone());
            prop_assert_eq!(tree.len(), e.len());
            for q in &qs {
                prop_assert_eq!(sorted(tree.items_in_range(q)), linear(&e, q));
            }
        }

        #[test]
        fn forest_matches_linear_scan_while_growing(e in entries(), qs in prop::collection::vec(query(), 1..8)) {
            let mut forest = KdForest::new();
            for (k, &(p, i)) in e.iter().enumerate() {
                forest.insert(p, i);
                prop_assert_eq!(forest.len(), k + 1);
                if k % 17 == 0 {
                    for q in &qs {
                        prop_assert_eq!(sorted(forest.items_in_range(q)), linear(&e[..=k], q));
                    }
                }
            }
            let bulk = KdForest::from_entries(e.clone());
            for q in &qs {
                prop_assert_eq!(sorted(forest.items_in_range(q)), linear(&e, q));
                prop_assert_eq!(sorted(bulk.items_in_range(q)), linear(&e, q));
                // Early exit: visiting everything agrees with the plain query, and breaking
                // at the first item visits exactly one item iff the range is not empty.
                let mut all = Vec::new();
                let flow = forest.try_for_each_in_range(q, &mut |i| {
                    all.push(i);
                    ControlFlow::<()>::Continue(())
                });
                prop_assert!(flow.is_continue());
                prop_assert_eq!(sorted(all), linear(&e, q));
                let mut visited = 0;
                let flow = forest.try_for_each_in_range(q, &mut |i| {
                    visited += 1;
                    ControlFlow::Break(i)
                });
                prop_assert_eq!(visited, usize::from(!linear(&e, q).is_empty()));
                prop_assert_eq!(flow.break_value().is_some(), visited == 1);
            }
        }
    }

    #[test]
    fn many_equal_coordinates_do_not_break_the_tree() {
        // 1000 points on one plane x = 1 (a wall): every split on x sees ties.
        let e: Vec<([f64; 3], u32)> =
            (0..1000).map(|i| ([1.0, (i % 37) as f64, (i / 37) as f64], i as u32)).collect();
        let tree = StaticKdTree::build(e.clone());
        let q = RangeQuery { min: [1.0, 3.0, 2.0], max: [1.0, 5.0, 2.0] };
        assert_eq!(sorted(tree.items_in_range(&q)), linear(&e, &q));
        assert_eq!(tree.items_in_range(&q).len(), 3);
    }

    #[test]
    fn six_d_box_overlap_query() {
        // Boxes as 6D points (min, max); the overlap query of a step box.
        let boxes = [([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]), ([2.0, 2.0, 2.0], [3.0, 3.0, 3.0])];
        let e: Vec<([f64; 6], u32)> = boxes
            .iter()
            .enumerate()
            .map(|(i, (lo, hi))| ([lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]], i as u32))
            .collect();
        let tree = StaticKdTree::build(e);
        let overlap = |lo: [f64; 3], hi: [f64; 3]| {
            let inf = f64::INFINITY;
            let q = RangeQuery {
                min: [-inf, -inf, -inf, lo[0], lo[1], lo[2]],
                max: [hi[0], hi[1], hi[2], inf, inf, inf],
            };
            sorted(tree.items_in_range(&q))
        };
        assert_eq!(overlap([0.5, 0.5, 0.5], [2.5, 2.5, 2.5]), vec![0, 1]);
        assert_eq!(overlap([1.5, 1.5, 1.5], [1.8, 1.8, 1.8]), Vec::<u32>::new());
        assert_eq!(overlap([1.0, 1.0, 1.0], [1.0, 1.0, 1.0]), vec![0], "touching counts");
    }

    #[test]
    fn nan_points_are_never_returned_and_hide_nothing() {
        // Mostly NaN, so NaN values become split values.
        let mut e: Vec<([f64; 3], u32)> = (0..40).map(|i| ([f64::NAN, 0.0, 0.0], i)).collect();
        e.extend((40..60).map(|i| ([i as f64, 0.0, 0.0], i)));
        let tree = StaticKdTree::build(e);
        let all = RangeQuery { min: [f64::NEG_INFINITY; 3], max: [f64::INFINITY; 3] };
        assert_eq!(sorted(tree.items_in_range(&all)), (40..60).collect::<Vec<_>>());
    }
}
