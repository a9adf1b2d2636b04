//! Nearest-neighbour search over the roadmap's vertices.

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

/// Points a leaf holds before it splits.
const LEAF: usize = 24;

/// One point of a [`KdNeighbors`] leaf.
#[derive(Copy, Clone, Debug)]
struct Entry {
    p: [Real; 3],
    index: usize,
}

/// A node of a [`KdNeighbors`] tree, in its arena.
#[derive(Debug)]
enum Node {
    /// Points with `p[dim] < split` are in `children[0]`, the others in `children[1]`.
    Inner {
        split: Real,
        children: [u32; 2],
        /// Points below this node (saturating: it only steers rebalancing).
        size: u32,
        /// `size` when this node was last built; it is rebuilt only after doubling.
        built: u32,
        dim: u8,
    },
    Leaf(Vec<Entry>),
}

impl Node {
    fn size(&self) -> u32 {
        match self {
            Node::Inner { size, .. } => *size,
            Node::Leaf(entries) => u32::try_from(entries.len()).unwrap_or(u32::MAX),
        }
    }
}

/// The best answers so far of a `k`-nearest query, sorted by squared distance, then index.
struct Best {
    k: usize,
    /// Only points with squared distance at most this are wanted.
    limit: Real,
    /// (squared distance, index, point)
    found: Vec<(Real, usize, [Real; 3])>,
}

impl Best {
    /// The squared distance a point must not exceed to enter.
    fn bound(&self) -> Real {
        if self.found.len() < self.k { self.limit } else { self.found[self.k - 1].0 }
    }

    fn offer(&mut self, d2: Real, e: &Entry) {
        if d2.is_nan() || d2 > self.bound() {
            return;
        }
        let at = self.found.partition_point(|&(d, i, _)| (d, i) < (d2, e.index));
        if at < self.k {
            self.found.insert(at, (d2, e.index, e.p));
            self.found.truncate(self.k);
        }
    }
}

/// Exact nearest neighbours in one k-d tree grown by insertion: leaves of up to 24 points
/// split at the median of their widest coordinate, and a subtree whose larger child holds
/// more than ¾ of its points is rebuilt balanced (the scapegoat rule), once it has doubled
/// since it was last built. Splits put equal coordinates on one side and choose the widest
/// spread, so planar scenes, where many points share a coordinate, stay balanced.
///
/// Answers equal [`LinearNeighbors`]'s (checked by property tests) except that among points
/// at exactly equal distance at the `k`-th place the tree may keep another one; answers are
/// still deterministic. [`nearest`](NearestNeighbors::nearest) breaks ties by the smaller
/// index, as the linear scan does, and allocates nothing.
///
/// # Complexity
/// Adding is amortised `O(log² n)`; a query descends one path of `O(log n)` nodes and
/// visits the few others its best distance so far does not rule out.
#[derive(Default)]
pub struct KdNeighbors {
    /// The tree's nodes; `nodes[0]` is the root (once there is a point).
    nodes: Vec<Node>,
    /// Unused slots of `nodes`, after rebuilds.
    free: Vec<u32>,
    len: usize,
    /// Scratch: the path of the last insertion.
    path: Vec<u32>,
    /// Scratch of rebuilds: the subtree's entries, and emptied leaves to reuse.
    entries: Vec<Entry>,
    spare: Vec<Vec<Entry>>,
    /// Scratch of builds: (slot, range of `entries`) still to build.
    todo: Vec<(u32, usize, usize)>,
}

impl std::fmt::Debug for KdNeighbors {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("KdNeighbors")
            .field("len", &self.len)
            .field("nodes", &(self.nodes.len() - self.free.len()))
            .field("depth", &self.depth())
            .finish()
    }
}

impl KdNeighbors {
    /// An empty set.
    pub fn new() -> KdNeighbors {
        KdNeighbors::default()
    }

    /// The number of nodes on the longest path from the root to a leaf (0 when empty).
    pub fn depth(&self) -> usize {
        let mut deepest = 0;
        let mut stack = Vec::new();
        if !self.nodes.is_empty() {
            stack.push((0u32, 1usize));
        }
        while let Some((n, d)) = stack.pop() {
            deepest = deepest.max(d);
            if let Node::Inner { children, .. } = &self.nodes[n as usize] {
                stack.extend(children.iter().map(|&c| (c, d + 1)));
            }
        }
        deepest
    }

    fn alloc(&mut self) -> u32 {
        match self.free.pop() {
            Some(n) => n,
            None => {
                self.nodes.push(Node::Leaf(Vec::new()));
                u32::try_from(self.nodes.len() - 1).expect("fewer than 2^32 k-d nodes")
            }
        }
    }

    /// Rebuilds the subtree at `root` balanced from its points.
    fn rebuild(&mut self, root: u32) {
        let mut entries = std::mem::take(&mut self.entries);
        entries.clear();
        // `path` is free again once the insertion chose its scapegoat.
        let mut stack = std::mem::take(&mut self.path);
        stack.clear();
        stack.push(root);
        while let Some(n) = stack.pop() {
            match std::mem::replace(&mut self.nodes[n as usize], Node::Leaf(Vec::new())) {
                Node::Inner { children, .. } => stack.extend(children),
                Node::Leaf(mut leaf) => {
                    entries.append(&mut leaf);
                    self.spare.push(leaf);
                }
            }
            if n != root {
                self.free.push(n);
            }
        }
        self.path = stack;
        self.build(root, &mut entries);
        self.entries = entries;
    }

    /// Builds a balanced subtree at slot `root` holding `entries` (no recursion, so
    /// degenerate inputs cannot exhaust the stack).
    fn build(&mut self, root: u32, entries: &mut [Entry]) {
        let mut todo = std::mem::take(&mut self.todo);
        todo.push((root, 0, entries.len()));
        while let Some((slot, lo, hi)) = todo.pop() {
            let part = &mut entries[lo..hi];
            let Some((dim, split, left)) = split_of(part) else {
                let mut leaf = self.spare.pop().unwrap_or_default();
                leaf.reserve(LEAF + 1);
                leaf.extend_from_slice(part);
                self.nodes[slot as usize] = Node::Leaf(leaf);
                continue;
            };
            let children = [self.alloc(), self.alloc()];
            let size = u32::try_from(hi - lo).unwrap_or(u32::MAX);
            let dim = dim as u8; // 0, 1 or 2
            self.nodes[slot as usize] = Node::Inner { dim, split, children, size, built: size };
            todo.push((children[0], lo, lo + left));
            todo.push((children[1], lo + left, hi));
        }
        self.todo = todo;
    }

    /// The nearest point to `q` below `n` that beats `best` (squared distance, entry).
    /// `offsets[d]` is how far `q` lies outside `n`'s cell along axis `d` (0 inside), and
    /// `rd` the sum of their squares: a lower bound of the squared distance to every point
    /// below `n` (Arya and Mount's incremental distance), so a far child is skipped unless its
    /// cell comes within the best distance.
    fn nearest_below(
        &self,
        n: u32,
        q: &[Real; 3],
        rd: Real,
        offsets: &mut [Real; 3],
        best: &mut (Real, Entry),
    ) {
        match &self.nodes[n as usize] {
            Node::Leaf(entries) => {
                for e in entries {
                    let d2 = squared_distance(&e.p, q);
                    if d2 < best.0 || (d2 == best.0 && e.index < best.1.index) {
                        *best = (d2, *e);
                    }
                }
            }
            Node::Inner { dim, split, children, .. } => {
                let dim = usize::from(*dim);
                let diff = q[dim] - split;
                let (near, far) = if diff < 0.0 { (0, 1) } else { (1, 0) };
                self.nearest_below(children[near], q, rd, offsets, best);
                let old = offsets[dim];
                let far_rd = rd - old * old + diff * diff;
                // The slack covers the rounding of `far_rd`, so ties are never pruned.
                if far_rd <= best.0 * (1.0 + 1e-12) {
                    offsets[dim] = diff;
                    self.nearest_below(children[far], q, far_rd, offsets, best);
                    offsets[dim] = old;
                }
            }
        }
    }

    /// Offers every point below `n` that can enter `best`.
    fn k_nearest_below(&self, n: u32, q: &[Real; 3], best: &mut Best) {
        match &self.nodes[n as usize] {
            Node::Leaf(entries) => {
                for e in entries {
                    best.offer(squared_distance(&e.p, q), e);
                }
            }
            Node::Inner { dim, split, children, .. } => {
                let dim = usize::from(*dim);
                let diff = q[dim] - split;
                let (near, far) = if diff < 0.0 { (0, 1) } else { (1, 0) };
                self.k_nearest_below(children[near], q, best);
                if diff * diff <= best.bound() {
                    self.k_nearest_below(children[far], q, best);
                }
            }
        }
    }
}

fn squared_distance(a: &[Real; 3], b: &[Real; 3]) -> Real {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
}

/// How to split `entries` (more than a leaf's worth): the coordinate of widest spread, the
/// median as split value (or, if the median is the minimum, the next larger value), with
/// `entries` reordered so the first `left` are below the split. `None` if they must stay one
/// leaf: few enough, or all at one place (or NaN).
fn split_of(entries: &mut [Entry]) -> Option<(usize, Real, usize)> {
    if entries.len() <= LEAF {
        return None;
    }
    let spread = |d: usize| {
        let (lo, hi) = entries.iter().fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), e| {
            (lo.min(e.p[d]), hi.max(e.p[d]))
        });
        hi - lo
    };
    let spreads = [spread(0), spread(1), spread(2)];
    let dim = (0..3)
        .filter(|&d| spreads[d] > 0.0)
        .max_by(|&a, &b| spreads[a].total_cmp(&spreads[b]).then(b.cmp(&a)))?;
    let mid = entries.len() / 2;
    entries.select_nth_unstable_by(mid, |a, b| a.p[dim].total_cmp(&b.p[dim]));
    let mut split = entries[mid].p[dim];
    let mut left = partition(entries, |e| e.p[dim] < split);
    if left == 0 {
        split = entries
            .iter()
            .map(|e| e.p[dim])
            .filter(|&c| c > split)
            .min_by(|a, b| a.total_cmp(b))?;
        left = partition(entries, |e| e.p[dim] < split);
    }
    (left > 0 && left < entries.len()).then_some((dim, split, left))
}

/// Moves the entries satisfying `below` to the front; returns their count.
fn partition(entries: &mut [Entry], below: impl Fn(&Entry) -> bool) -> usize {
    let mut k = 0;
    for i in 0..entries.len() {
        if below(&entries[i]) {
            entries.swap(i, k);
            k += 1;
        }
    }
    k
}

impl NearestNeighbors for KdNeighbors {
    fn add(&mut self, point: Point3) {
        let e = Entry { p: [point.x, point.y, point.z], index: self.len };
        self.len += 1;
        if self.nodes.is_empty() {
            self.nodes.push(Node::Leaf(Vec::with_capacity(LEAF + 1)));
        }
        self.path.clear();
        let mut at = 0u32;
        let leaf_len = loop {
            match &mut self.nodes[at as usize] {
                Node::Inner { dim, split, children, size, .. } => {
                    *size = size.saturating_add(1);
                    self.path.push(at);
                    at = children[usize::from(e.p[usize::from(*dim)] >= *split)];
                }
                Node::Leaf(entries) => {
                    entries.push(e);
                    break entries.len();
                }
            }
        };
        if leaf_len <= LEAF {
            return;
        }
        // The highest node the scapegoat rule asks to rebuild, else the full leaf. (Balance is
        // looked at only when a leaf splits: a few insertions late at most.)
        let scapegoat = self.path.iter().copied().find(|&n| match &self.nodes[n as usize] {
            Node::Inner { children, size, built, .. } => {
                let heavier = children.iter().map(|&c| self.nodes[c as usize].size()).max();
                let (size, built) = (u64::from(*size), u64::from(*built));
                size >= 2 * built && u64::from(heavier.unwrap_or(0)) * 4 > size * 3
            }
            Node::Leaf(_) => false,
        });
        self.rebuild(scapegoat.unwrap_or(at));
    }

    fn len(&self) -> usize {
        self.len
    }

    fn clear(&mut self) {
        *self = KdNeighbors::default();
    }

    fn k_nearest(&self, query: &Point3, k: usize, max_dist: Real) -> Vec<Neighbor> {
        if k == 0 || self.nodes.is_empty() || max_dist.is_nan() || max_dist < 0.0 {
            return Vec::new();
        }
        // Slightly wider than `max_dist²`, so rounding never prunes a point the exact test
        // below keeps.
        let limit = max_dist * max_dist * (1.0 + 1e-9);
        let mut best = Best { k, limit, found: Vec::with_capacity(k.min(self.len)) };
        self.k_nearest_below(0, &[query.x, query.y, query.z], &mut best);
        let mut out: Vec<Neighbor> = best
            .found
            .into_iter()
            .map(|(_, index, p)| Neighbor { index, distance: (Point3::from(p) - query).norm() })
            .filter(|n| n.distance <= max_dist)
            .collect();
        out.sort_by(|a, b| a.distance.total_cmp(&b.distance).then(a.index.cmp(&b.index)));
        out
    }

    /// [`k_nearest`](NearestNeighbors::k_nearest) with `k = 1`, without allocating (RRT's
    /// hot path). `None` if there is no point, or no point at a comparable distance (a NaN
    /// query).
    fn nearest(&self, query: &Point3) -> Option<Neighbor> {
        if self.nodes.is_empty() {
            return None;
        }
        let none = Entry { p: [Real::NAN; 3], index: usize::MAX };
        let mut best = (Real::INFINITY, none);
        self.nearest_below(0, &[query.x, query.y, query.z], 0.0, &mut [0.0; 3], &mut best);
        let e = best.1;
        (e.index != usize::MAX)
            .then(|| Neighbor { index: e.index, distance: (Point3::from(e.p) - query).norm() })
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
    fn depth_stays_logarithmic_for_ordered_and_flat_inputs() {
        // A corridor explored from one end (points in increasing x), a flat floor (every z
        // equal), and many copies of one point.
        let corridor = (0..20_000).map(|i| Point3::new(Real::from(i) * 0.01, 0.3, 0.5));
        let floor = (0..20_000).map(|i| Point3::new(Real::from(i % 141), Real::from(i / 141), 0.0));
        let same = (0..5_000).map(|_| Point3::new(1.0, 2.0, 3.0));
        for (name, points) in [
            ("corridor", corridor.collect::<Vec<_>>()),
            ("floor", floor.collect()),
            ("same", same.collect()),
        ] {
            let mut kd = KdNeighbors::new();
            for p in &points {
                kd.add(*p);
            }
            // A balanced tree of 24-point leaves has depth about log2(n / 24) + 1 ≈ 11;
            // the scapegoat rule allows a constant factor.
            assert!(kd.depth() <= 40, "{name}: depth {}", kd.depth());
            let q = points[points.len() / 3] + patch_core::Vector3::new(0.001, 0.0, 0.0);
            let n = kd.nearest(&q).unwrap();
            assert!((n.distance - 0.001).abs() < 1e-9, "{name}: {n:?}");
        }
    }

    #[test]
    fn nan_queries_and_points_do_not_panic() {
        let mut kd = KdNeighbors::new();
        for i in 0..100 {
            kd.add(Point3::new(Real::from(i), 0.0, 0.0));
        }
        kd.add(Point3::new(Real::NAN, 0.0, 0.0));
        for i in 0..100 {
            kd.add(Point3::new(0.0, Real::from(i), 0.0));
        }
        let nan = Point3::new(Real::NAN, 1.0, 1.0);
        assert!(kd.nearest(&nan).is_none());
        assert!(kd.k_nearest(&nan, 3, Real::INFINITY).is_empty());
        assert!(kd.k_nearest(&Point3::origin(), 3, Real::NAN).is_empty());
        assert_eq!(kd.nearest(&Point3::new(50.2, 0.0, 0.0)).unwrap().index, 50);
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
