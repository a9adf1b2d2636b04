//! A bounding volume hierarchy over primitive boxes: binned surface-area-heuristic build,
//! flattened depth-first node array, allocation-free closest-hit traversal with a fixed stack.

use pointcloud::{Aabb, Point3, Real, Vector3};

/// Deeper subtrees become leaves, so the traversal stack cannot overflow.
const MAX_DEPTH: usize = 48;
const STACK: usize = 64;
const BINS: usize = 16;
/// Ranges this small always become leaves.
const MIN_LEAF: usize = 2;
/// Ranges larger than this are always split (if their centroids differ at all).
const MAX_LEAF: usize = 8;
/// Primitive boxes are grown by this (metres), so flat boxes of axis-aligned polygons have a
/// thickness and the slab test is robust.
const MARGIN: Real = 1e-6;

#[derive(Copy, Clone, Debug)]
struct Node {
    min: [Real; 3],
    max: [Real; 3],
    /// Leaf: first entry in `indices`; interior: index of the right child (the left child is
    /// the next node).
    first: u32,
    /// Leaf: number of primitives (> 0); interior: 0.
    count: u32,
}

/// The hierarchy: nodes in depth-first order, leaves refer to ranges of `indices`.
#[derive(Clone, Debug)]
pub(crate) struct Bvh {
    nodes: Vec<Node>,
    indices: Vec<u32>,
}

fn area(b: &Aabb) -> Real {
    let e = b.extents();
    2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
}

struct Builder<'a> {
    boxes: &'a [Aabb],
    centroids: Vec<Point3>,
    indices: Vec<u32>,
    nodes: Vec<Node>,
}

impl Builder<'_> {
    fn bounds(&self, range: std::ops::Range<usize>) -> (Aabb, Aabb) {
        let mut b = Aabb::EMPTY;
        let mut c = Aabb::EMPTY;
        for &i in &self.indices[range] {
            b = b.union(&self.boxes[i as usize]);
            c.grow(&self.centroids[i as usize]);
        }
        (b, c)
    }

    fn build(&mut self, start: usize, end: usize, depth: usize) {
        let (bounds, cbounds) = self.bounds(start..end);
        let me = self.nodes.len();
        self.nodes.push(Node {
            min: bounds.min.coords.into(),
            max: bounds.max.coords.into(),
            first: start as u32,
            count: (end - start) as u32,
        });
        let n = end - start;
        if n <= MIN_LEAF || depth >= MAX_DEPTH {
            return;
        }
        let Some(mid) = self.split(start, end, &bounds, &cbounds) else {
            return;
        };
        self.build(start, mid, depth + 1);
        let right = self.nodes.len() as u32;
        self.build(mid, end, depth + 1);
        self.nodes[me].first = right;
        self.nodes[me].count = 0;
    }

    /// Partitions `indices[start..end]` by the best binned SAH plane; `None` means "make a leaf".
    fn split(&mut self, start: usize, end: usize, bounds: &Aabb, cb: &Aabb) -> Option<usize> {
        let n = end - start;
        let ext = cb.extents();
        let mut best: Option<(Real, usize, usize)> = None; // (cost, axis, bin boundary)
        for axis in 0..3 {
            if ext[axis].is_nan() || ext[axis] <= 0.0 {
                continue;
            }
            let mut bins = [(Aabb::EMPTY, 0usize); BINS];
            let scale = BINS as Real / ext[axis];
            for &i in &self.indices[start..end] {
                let k = (((self.centroids[i as usize][axis] - cb.min[axis]) * scale) as usize)
                    .min(BINS - 1);
                bins[k].0 = bins[k].0.union(&self.boxes[i as usize]);
                bins[k].1 += 1;
            }
            // Sweep from the right to get suffix areas and counts.
            let mut right_area = [0.0; BINS];
            let mut right_count = [0usize; BINS];
            let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
            for k in (1..BINS).rev() {
                acc = acc.union(&bins[k].0);
                cnt += bins[k].1;
                right_area[k] = area(&acc);
                right_count[k] = cnt;
            }
            let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
            for k in 1..BINS {
                acc = acc.union(&bins[k - 1].0);
                cnt += bins[k - 1].1;
                if cnt == 0 || right_count[k] == 0 {
                    continue;
                }
                let cost = area(&acc) * cnt as Real + right_area[k] * right_count[k] as Real;
                if best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, axis, k));
                }
            }
        }
        let (cost, axis, k) = best?;
        let leaf_cost = area(bounds) * n as Real;
        // Traversal cost ≈ one primitive test per unit of area.
        if cost + area(bounds) >= leaf_cost && n <= MAX_LEAF {
            return None;
        }
        let scale = BINS as Real / ext[axis];
        let (cmin, centroids) = (cb.min[axis], &self.centroids);
        let slice = &mut self.indices[start..end];
        let mut left = 0;
        for j in 0..slice.len() {
            let bin =
                (((centroids[slice[j] as usize][axis] - cmin) * scale) as usize).min(BINS - 1);
            if bin < k {
                slice.swap(left, j);
                left += 1;
            }
        }
        (left > 0 && left < n).then_some(start + left)
    }
}

impl Bvh {
    /// Builds the hierarchy over the given primitive boxes (primitive `i` has box `boxes[i]`).
    pub(crate) fn new(boxes: &[Aabb]) -> Bvh {
        let boxes: Vec<Aabb> = boxes.iter().map(|b| b.inflated(MARGIN)).collect();
        let mut b = Builder {
            centroids: boxes.iter().map(|b| b.center()).collect(),
            boxes: &boxes,
            indices: (0..boxes.len() as u32).collect(),
            nodes: Vec::with_capacity(2 * boxes.len()),
        };
        if !boxes.is_empty() {
            b.build(0, boxes.len(), 0);
        }
        Bvh { nodes: b.nodes, indices: b.indices }
    }

    /// The number of nodes (for diagnostics).
    #[allow(dead_code)]
    pub(crate) fn num_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Entry distance of the ray into node `n` if it enters before `t_max`.
    #[inline(always)]
    fn enter(&self, n: usize, o: &[Real; 3], inv: &[Real; 3], t_max: Real) -> Option<Real> {
        let node = &self.nodes[n];
        let mut t0: Real = 0.0;
        let mut t1 = t_max;
        for i in 0..3 {
            let a = (node.min[i] - o[i]) * inv[i];
            let b = (node.max[i] - o[i]) * inv[i];
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
        (t0 <= t1).then_some(t0)
    }

    /// Visits the primitives whose boxes the ray `origin + t·dir`, `t ∈ [0, t_max]`, passes,
    /// nearest boxes first. `test(primitive, t_max)` returns the distance of a hit closer than
    /// `t_max`, which then shrinks the search. Returns the final `t_max`.
    #[inline]
    pub(crate) fn closest(
        &self,
        origin: &Point3,
        dir: &Vector3,
        mut t_max: Real,
        mut test: impl FnMut(usize, Real) -> Option<Real>,
    ) -> Real {
        if self.nodes.is_empty() {
            return t_max;
        }
        let o = [origin.x, origin.y, origin.z];
        // A zero direction component gets a huge but finite inverse: no 0·∞ = NaN.
        let inv = [0, 1, 2].map(|i| {
            let d = dir[i];
            if d.abs() < 1e-300 { 1e300_f64.copysign(d) } else { 1.0 / d }
        });
        let mut stack = [(0u32, 0.0 as Real); STACK];
        let mut sp = 0usize;
        let mut node = 0usize;
        if self.enter(0, &o, &inv, t_max).is_none() {
            return t_max;
        }
        loop {
            let nd = self.nodes[node];
            let mut next = None;
            if nd.count > 0 {
                let s = nd.first as usize;
                for &p in &self.indices[s..s + nd.count as usize] {
                    if let Some(t) = test(p as usize, t_max) {
                        t_max = t_max.min(t);
                    }
                }
            } else {
                let (l, r) = (node + 1, nd.first as usize);
                match (self.enter(l, &o, &inv, t_max), self.enter(r, &o, &inv, t_max)) {
                    (Some(tl), Some(tr)) => {
                        let (near, far, tf) = if tl <= tr { (l, r, tr) } else { (r, l, tl) };
                        if sp < STACK {
                            stack[sp] = (far as u32, tf);
                            sp += 1;
                            next = Some(near);
                        } else {
                            // Unreachable with MAX_DEPTH < STACK; stay correct anyway.
                            let t = self.closest_from(far, t_max, &mut test);
                            t_max = t_max.min(t);
                            next = Some(near);
                        }
                    }
                    (Some(_), None) => next = Some(l),
                    (None, Some(_)) => next = Some(r),
                    (None, None) => {}
                }
            }
            match next {
                Some(n) => node = n,
                None => loop {
                    if sp == 0 {
                        return t_max;
                    }
                    sp -= 1;
                    let (n, t_enter) = stack[sp];
                    if t_enter <= t_max {
                        node = n as usize;
                        break;
                    }
                },
            }
        }
    }

    /// Brute-force fallback over a subtree's primitives (used only if the stack were full).
    #[cold]
    fn closest_from(
        &self,
        node: usize,
        mut t_max: Real,
        test: &mut impl FnMut(usize, Real) -> Option<Real>,
    ) -> Real {
        let mut todo = vec![node];
        while let Some(n) = todo.pop() {
            let nd = self.nodes[n];
            if nd.count > 0 {
                let s = nd.first as usize;
                for &p in &self.indices[s..s + nd.count as usize] {
                    if let Some(t) = test(p as usize, t_max) {
                        t_max = t_max.min(t);
                    }
                }
            } else {
                todo.push(n + 1);
                todo.push(nd.first as usize);
            }
        }
        t_max
    }
}
