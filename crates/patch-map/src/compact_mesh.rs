//! A triangle mesh with a compact bounding volume hierarchy: the storage of
//! [`TrimeshMap`](crate::TrimeshMap) (thesis §5.4.2, the OPCODE role: a BVH over the
//! triangles of Delaunay-triangulated patches).
//!
//! parry's `TriMesh` keeps one BVH leaf per triangle with `f64` boxes, about 136 bytes of
//! hierarchy per triangle. [`CompactMesh`] keeps
//! * the vertices (`f64`, as given: the narrow phase is exact on them) and one `[u32; 3]` per
//!   triangle, reordered so the triangles of each leaf are contiguous;
//! * a binary tree of 32-byte nodes whose boxes are `f32`, rounded outwards (so they still
//!   contain their triangles), with up to [`LEAF_SIZE`] triangles per leaf.
//!
//! Leaves test each triangle's own `f64` box (computed from its vertices) before the exact
//! test, so pruning is as tight as with one triangle per leaf. The tree is built top-down by
//! the surface area heuristic over binned centroids; below depth [`SAH_DEPTH`] it splits at the
//! median, so every tree is at most about 70 levels deep and the walks need no heap. The splits
//! see each triangle's box on a 16-bit grid over the mesh's box (12 bytes per triangle while
//! building); the nodes' boxes are then computed bottom-up from the vertices, so they are as
//! tight as the `f32` rounding allows.
//!
//! The mesh is also a parry [`Shape`] (of type [`ShapeType::Custom`]): the rapier map's
//! colliders hold it, so both maps store triangles the same compact way and answer through
//! the same walks ([`CompactMesh::any_triangle`], [`CompactMesh::find_best`]) with one narrow
//! phase.

use parry3d_f64::bounding_volume::{Aabb as BoxAabb, BoundingSphere};
use parry3d_f64::mass_properties::MassProperties;
use parry3d_f64::math::{Isometry, Vector};
use parry3d_f64::partitioning::BvhLeafCost;
use parry3d_f64::query::{PointProjection, PointQuery, Ray, RayCast, RayIntersection};
use parry3d_f64::shape::{FeatureId, Shape, ShapeType, Triangle, TypedShape};
use patch_core::{Point3, Real};

/// The most triangles in one leaf.
pub(crate) const LEAF_SIZE: usize = 4;

/// Below this depth the tree is split by the surface area heuristic, from it on at the median
/// (which bounds the depth by `SAH_DEPTH + log₂(n)`).
pub(crate) const SAH_DEPTH: usize = 40;

/// Centroid bins of the surface area heuristic.
const BINS: usize = 16;

/// The walks' stack: deeper than any tree [`CompactMesh::build`] makes (at most
/// `SAH_DEPTH + 32` levels for `u32` triangle indices).
const STACK: usize = 96;

/// A node: an `f32` box rounded outwards; a leaf holds triangles `first..first + count`, an
/// inner node (`count == 0`) has its children at `first` and `first + 1`.
#[derive(Clone, Copy, Debug)]
struct Node {
    min: [f32; 3],
    max: [f32; 3],
    first: u32,
    count: u32,
}

impl Node {
    fn aabb(&self) -> BoxAabb {
        BoxAabb::new(self.min.map(Real::from).into(), self.max.map(Real::from).into())
    }
}

/// The largest `f32` not above `x`.
fn down(x: Real) -> f32 {
    let f = x as f32;
    if Real::from(f) > x { f.next_down() } else { f }
}

/// The smallest `f32` not below `x`.
fn up(x: Real) -> f32 {
    let f = x as f32;
    if Real::from(f) < x { f.next_up() } else { f }
}

/// Triangles (by index into `f64` vertices) and a compact BVH over them; see the
/// [module docs](self).
#[derive(Clone, Debug)]
pub(crate) struct CompactMesh {
    vertices: Vec<Point3>,
    indices: Vec<[u32; 3]>,
    nodes: Vec<Node>,
}

/// A triangle's box during the build, in [`Items::STEPS`] steps across the mesh's box along
/// each axis: it only steers the splits (the nodes' boxes are computed from the vertices once
/// the tree stands), so 12 bytes per triangle suffice.
#[derive(Clone, Copy)]
struct Item {
    min: [u16; 3],
    max: [u16; 3],
}

/// The triangles' [`Item`]s and the grid they are measured on.
struct Items {
    items: Vec<Item>,
    origin: [Real; 3],
    /// Metres per step along each axis (0 for an axis the mesh is flat in).
    step: [Real; 3],
}

impl Items {
    /// Steps across the mesh's box.
    const STEPS: Real = u16::MAX as Real;

    /// The items of `indices` into `vertices` (a mesh of at least one triangle).
    fn new(vertices: &[Point3], indices: &[[u32; 3]]) -> Items {
        let mut bounds = Bounds::EMPTY;
        for p in vertices {
            bounds.add_point(&[p.x, p.y, p.z]);
        }
        let origin = bounds.min;
        let extent = [0, 1, 2].map(|k| bounds.max[k] - bounds.min[k]);
        let step = extent.map(|e| if e > 0.0 { e / Self::STEPS } else { 0.0 });
        let scale = step.map(|s| if s > 0.0 { 1.0 / s } else { 0.0 });
        // Rounded outwards and clamped; `as` saturates, so rounding error cannot wrap.
        let at = |x: Real, k: usize| (x - origin[k]) * scale[k];
        let items = indices
            .iter()
            .map(|t| {
                let mut b = Bounds::EMPTY;
                b.add_triangle(vertices, t);
                Item {
                    min: [0, 1, 2].map(|k| at(b.min[k], k).floor() as u16),
                    max: [0, 1, 2].map(|k| at(b.max[k], k).ceil() as u16),
                }
            })
            .collect();
        Items { items, origin, step }
    }

    /// The centre of triangle `i`'s box along `axis` (its "centroid" for binning), metres.
    fn centroid(&self, i: u32, axis: usize) -> Real {
        let item = &self.items[i as usize];
        let steps = 0.5 * (Real::from(item.min[axis]) + Real::from(item.max[axis]));
        self.origin[axis] + steps * self.step[axis]
    }

    /// Grows `bounds` by triangle `i`'s box.
    fn add_to(&self, bounds: &mut Bounds, i: u32) {
        let item = &self.items[i as usize];
        let at = |s: [u16; 3]| [0, 1, 2].map(|k| self.origin[k] + Real::from(s[k]) * self.step[k]);
        bounds.add_point(&at(item.min));
        bounds.add_point(&at(item.max));
    }
}

/// A box under construction.
#[derive(Clone, Copy)]
struct Bounds {
    min: [Real; 3],
    max: [Real; 3],
}

impl Bounds {
    const EMPTY: Bounds = Bounds { min: [Real::INFINITY; 3], max: [Real::NEG_INFINITY; 3] };

    fn add_box(&mut self, min: &[f32; 3], max: &[f32; 3]) {
        // Plain comparisons (the coordinates are finite): faster than `f64::min`.
        for k in 0..3 {
            let (lo, hi) = (Real::from(min[k]), Real::from(max[k]));
            if lo < self.min[k] {
                self.min[k] = lo;
            }
            if hi > self.max[k] {
                self.max[k] = hi;
            }
        }
    }

    fn add_point(&mut self, p: &[Real; 3]) {
        for (k, &x) in p.iter().enumerate() {
            if x < self.min[k] {
                self.min[k] = x;
            }
            if x > self.max[k] {
                self.max[k] = x;
            }
        }
    }

    /// Grows the box by the triangle `t` of `vertices`.
    fn add_triangle(&mut self, vertices: &[Point3], t: &[u32; 3]) {
        for &i in t {
            let p = &vertices[i as usize];
            self.add_point(&[p.x, p.y, p.z]);
        }
    }

    fn add_bounds(&mut self, b: &Bounds) {
        self.add_point(&b.min);
        self.add_point(&b.max);
    }

    /// Half the surface area (the heuristic's measure); 0 when empty.
    fn half_area(&self) -> Real {
        let d = [0, 1, 2].map(|k| (self.max[k] - self.min[k]).max(0.0));
        d[0] * d[1] + d[1] * d[2] + d[2] * d[0]
    }
}

impl CompactMesh {
    /// The mesh of `indices` into `vertices`, with `tags[i]` belonging to triangle `i`; the
    /// triangles (and the tags with them) are reordered by the tree. `None` if there are no
    /// triangles. Every index must be below `vertices.len()`.
    pub(crate) fn build<T: Copy>(
        vertices: Vec<Point3>,
        indices: Vec<[u32; 3]>,
        tags: Vec<T>,
    ) -> Option<(CompactMesh, Vec<T>)> {
        debug_assert_eq!(indices.len(), tags.len());
        if indices.is_empty() {
            return None;
        }
        let items = Items::new(&vertices, &indices);
        let mut order: Vec<u32> = (0..indices.len() as u32).collect();
        let mut nodes = Vec::with_capacity(2 * indices.len().div_ceil(LEAF_SIZE));
        nodes.push(Node { min: [0.0; 3], max: [0.0; 3], first: 0, count: 0 });
        // The tree's shape, top-down (its boxes come last, from the vertices).
        // (node, range of `order`, depth)
        let mut work = vec![(0usize, 0usize, indices.len(), 0usize)];
        while let Some((node, start, end, depth)) = work.pop() {
            let count = end - start;
            if count <= LEAF_SIZE {
                nodes[node].first = start as u32;
                nodes[node].count = count as u32;
                continue;
            }
            let mid = split(&items, &mut order[start..end], depth) + start;
            let child = nodes.len();
            nodes[node].first = child as u32;
            nodes[node].count = 0;
            nodes.push(Node { min: [0.0; 3], max: [0.0; 3], first: 0, count: 0 });
            nodes.push(Node { min: [0.0; 3], max: [0.0; 3], first: 0, count: 0 });
            work.push((child, start, mid, depth + 1));
            work.push((child + 1, mid, end, depth + 1));
        }
        nodes.shrink_to_fit();
        drop(items);
        // Triangles in leaf order, and vertices in the order the triangles first use them, so
        // a walk reads both nearly sequentially (unused vertices are dropped). The vertices
        // are permuted in place: a copy would double the largest array for a moment.
        let mut new_index = vec![u32::MAX; vertices.len()];
        let mut used = 0u32;
        for &i in &order {
            for v in indices[i as usize] {
                let slot = &mut new_index[v as usize];
                if *slot == u32::MAX {
                    *slot = used;
                    used += 1;
                }
            }
        }
        let tags = order.iter().map(|&i| tags[i as usize]).collect();
        // The triangles into leaf order in place (consuming `order`), then renumbered.
        let mut indices = indices;
        permute_in_place(&mut indices, &mut order);
        for t in &mut indices {
            *t = t.map(|v| new_index[v as usize]);
        }
        for (next, slot) in (used..).zip(new_index.iter_mut().filter(|s| **s == u32::MAX)) {
            *slot = next;
        }
        let mut vertices = vertices;
        for i in 0..vertices.len() {
            // Move the vertex at `i` to its place until the one that belongs at `i` arrives.
            while new_index[i] as usize != i {
                let j = new_index[i] as usize;
                vertices.swap(i, j);
                new_index.swap(i, j);
            }
        }
        drop(new_index);
        vertices.truncate(used as usize);
        vertices.shrink_to_fit();
        // The boxes bottom-up (children come after their parent): a leaf's from its
        // triangles' vertices, an inner node's around its children's, rounded outwards.
        for n in (0..nodes.len()).rev() {
            let Node { first, count, .. } = nodes[n];
            let (first, count) = (first as usize, count as usize);
            let mut bounds = Bounds::EMPTY;
            if count > 0 {
                for t in &indices[first..first + count] {
                    bounds.add_triangle(&vertices, t);
                }
            } else {
                for child in &nodes[first..first + 2] {
                    bounds.add_box(&child.min, &child.max);
                }
            }
            nodes[n].min = bounds.min.map(down);
            nodes[n].max = bounds.max.map(up);
        }
        Some((CompactMesh { vertices, indices, nodes }, tags))
    }

    /// The vertices.
    pub(crate) fn vertices(&self) -> &[Point3] {
        &self.vertices
    }

    /// The triangles, as indices into [`vertices`](Self::vertices), in tree order.
    pub(crate) fn indices(&self) -> &[[u32; 3]] {
        &self.indices
    }

    /// The heap bytes (by capacity).
    pub(crate) fn heap_bytes(&self) -> usize {
        self.vertices.capacity() * size_of::<Point3>()
            + self.indices.capacity() * size_of::<[u32; 3]>()
            + self.nodes.capacity() * size_of::<Node>()
    }

    /// The number of triangles.
    #[cfg(test)]
    pub(crate) fn num_triangles(&self) -> usize {
        self.indices.len()
    }

    /// A box around every triangle (the root's, rounded outwards).
    pub(crate) fn local_aabb(&self) -> BoxAabb {
        self.nodes[0].aabb()
    }

    /// The projection of `pt` on the nearest triangle, and that triangle.
    fn project(&self, pt: &Point3, solid: bool) -> (PointProjection, u32) {
        let project = |i: u32| {
            let p = self.triangle(i).project_local_point(pt, solid);
            ((p.point - pt).norm(), p)
        };
        self.find_best(
            Real::MAX,
            |aabb, _| aabb.distance_to_local_point(pt, true),
            |i, _| Some(project(i)),
        )
        // Only a point with a NaN coordinate finds nothing.
        .map_or_else(|| (project(0).1, 0), |(i, (_, p))| (p, i))
    }

    /// The `f64` box of triangle `i`.
    fn triangle_aabb(&self, i: u32) -> BoxAabb {
        let [a, b, c] = self.indices[i as usize].map(|v| self.vertices[v as usize]);
        BoxAabb::new(a.inf(&b).inf(&c), a.sup(&b).sup(&c))
    }
}

/// Reorders `data` so that `data[k]` becomes the old `data[order[k]]`, without a second copy;
/// `order` (a permutation) is used up.
fn permute_in_place<T: Copy>(data: &mut [T], order: &mut [u32]) {
    for start in 0..data.len() {
        if order[start] == u32::MAX {
            continue;
        }
        let first = data[start];
        let mut k = start;
        loop {
            let from = order[k] as usize;
            order[k] = u32::MAX;
            if from == start {
                data[k] = first;
                break;
            }
            data[k] = data[from];
            k = from;
        }
    }
}

/// Splits `order` (at least two triangles) in place and returns the size of the first part
/// (never 0 or all): the best of [`BINS`] centroid bins along the longest centroid axis by the
/// surface area heuristic, or the median below depth [`SAH_DEPTH`] and where the heuristic
/// finds no split.
fn split(items: &Items, order: &mut [u32], depth: usize) -> usize {
    let mut cb = Bounds::EMPTY;
    for &i in order.iter() {
        cb.add_point(&[0, 1, 2].map(|k| items.centroid(i, k)));
    }
    let extent = [0, 1, 2].map(|k| cb.max[k] - cb.min[k]);
    let axis = (0..3).fold(0, |a, k| if extent[k] > extent[a] { k } else { a });
    let median = |order: &mut [u32]| {
        let mid = order.len() / 2;
        order.select_nth_unstable_by(mid, |&x, &y| {
            items.centroid(x, axis).total_cmp(&items.centroid(y, axis))
        });
        mid
    };
    // `extent` is 0 (or NaN, never for finite vertices) when all centroids coincide.
    if depth >= SAH_DEPTH || extent[axis].partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return median(order);
    }
    let scale = BINS as Real / extent[axis];
    let bin = |i: u32| {
        let b = ((items.centroid(i, axis) - cb.min[axis]) * scale) as usize;
        b.min(BINS - 1)
    };
    let mut boxes = [Bounds::EMPTY; BINS];
    let mut counts = [0usize; BINS];
    for &i in order.iter() {
        let b = bin(i);
        items.add_to(&mut boxes[b], i);
        counts[b] += 1;
    }
    // Cost of splitting after bin `k`: area × count on each side.
    let mut right_cost = [0.0; BINS];
    let (mut acc, mut n) = (Bounds::EMPTY, 0);
    for k in (1..BINS).rev() {
        acc.add_bounds(&boxes[k]);
        n += counts[k];
        right_cost[k - 1] = acc.half_area() * n as Real;
    }
    let (mut acc, mut n) = (Bounds::EMPTY, 0);
    let mut best: Option<(Real, usize)> = None;
    for k in 0..BINS - 1 {
        acc.add_bounds(&boxes[k]);
        n += counts[k];
        if n == 0 || n == order.len() {
            continue;
        }
        let cost = acc.half_area() * n as Real + right_cost[k];
        if best.is_none_or(|(c, _)| cost < c) {
            best = Some((cost, k));
        }
    }
    let Some((_, k)) = best else {
        return median(order);
    };
    // Partition: bins 0..=k first.
    let mut left = 0;
    for j in 0..order.len() {
        if bin(order[j]) <= k {
            order.swap(left, j);
            left += 1;
        }
    }
    left
}

impl CompactMesh {
    /// Triangle `i`.
    pub(crate) fn triangle(&self, i: u32) -> Triangle {
        let [a, b, c] = self.indices[i as usize].map(|v| self.vertices[v as usize]);
        Triangle::new(a, b, c)
    }

    /// Whether `hit` holds for a triangle whose boxes all pass `visit` (a conservative test: a
    /// box that fails it holds no triangle `hit` accepts).
    pub(crate) fn any_triangle(
        &self,
        visit: impl Fn(&BoxAabb) -> bool,
        mut hit: impl FnMut(u32) -> bool,
    ) -> bool {
        let mut stack = [0u32; STACK];
        let mut len = 1;
        while len > 0 {
            len -= 1;
            let node = &self.nodes[stack[len] as usize];
            if !visit(&node.aabb()) {
                continue;
            }
            if node.count == 0 {
                stack[len] = node.first;
                stack[len + 1] = node.first + 1;
                len += 2;
            } else {
                for i in node.first..node.first + node.count {
                    if visit(&self.triangle_aabb(i)) && hit(i) {
                        return true;
                    }
                }
            }
        }
        false
    }

    /// The triangle of least cost below `max_cost`: `aabb_cost(box, best)` is a lower bound of
    /// the cost of every triangle in the box (`Real::MAX` if none can beat `best`),
    /// `leaf_cost(triangle, best)` its cost if below `best`.
    pub(crate) fn find_best<L: BvhLeafCost>(
        &self,
        max_cost: Real,
        aabb_cost: impl Fn(&BoxAabb, Real) -> Real,
        leaf_cost: impl Fn(u32, Real) -> Option<L>,
    ) -> Option<(u32, L)> {
        let mut best: Option<(u32, L)> = None;
        let mut best_cost = max_cost;
        let root = aabb_cost(&self.nodes[0].aabb(), best_cost);
        let mut stack = [(0u32, 0.0); STACK];
        stack[0] = (0, root);
        let mut len = usize::from(root < best_cost);
        while len > 0 {
            len -= 1;
            let (id, cost) = stack[len];
            if cost >= best_cost {
                continue;
            }
            let node = &self.nodes[id as usize];
            if node.count == 0 {
                let (l, r) = (node.first, node.first + 1);
                let cl = aabb_cost(&self.nodes[l as usize].aabb(), best_cost);
                let cr = aabb_cost(&self.nodes[r as usize].aabb(), best_cost);
                // The nearer child is popped first.
                let (near, far) = if cl <= cr { ((l, cl), (r, cr)) } else { ((r, cr), (l, cl)) };
                for (child, c) in [far, near] {
                    if c < best_cost {
                        stack[len] = (child, c);
                        len += 1;
                    }
                }
            } else {
                for i in node.first..node.first + node.count {
                    if aabb_cost(&self.triangle_aabb(i), best_cost) >= best_cost {
                        continue;
                    }
                    if let Some(val) = leaf_cost(i, best_cost) {
                        let c = val.cost();
                        if c < best_cost {
                            best_cost = c;
                            best = Some((i, val));
                        }
                    }
                }
            }
        }
        best
    }
}

impl PointQuery for CompactMesh {
    fn project_local_point(&self, pt: &Point3, solid: bool) -> PointProjection {
        self.project(pt, solid).0
    }

    fn project_local_point_and_get_feature(&self, pt: &Point3) -> (PointProjection, FeatureId) {
        let (p, i) = self.project(pt, false);
        (p, FeatureId::Face(i))
    }
}

impl RayCast for CompactMesh {
    fn cast_local_ray_and_get_normal(
        &self,
        ray: &Ray,
        max_time_of_impact: Real,
        solid: bool,
    ) -> Option<RayIntersection> {
        let (i, (_, mut hit)) = self.find_best(
            max_time_of_impact.next_up(),
            |aabb, best| aabb.cast_local_ray(ray, best, true).unwrap_or(Real::MAX),
            |i, best| {
                let hit = self.triangle(i).cast_local_ray_and_get_normal(ray, best, solid)?;
                Some((hit.time_of_impact, hit))
            },
        )?;
        hit.feature = FeatureId::Face(i);
        Some(hit)
    }
}

/// A custom parry shape, so a rapier collider can hold the mesh.
impl Shape for CompactMesh {
    fn compute_local_aabb(&self) -> BoxAabb {
        self.local_aabb()
    }

    fn compute_local_bounding_sphere(&self) -> BoundingSphere {
        self.local_aabb().bounding_sphere()
    }

    fn clone_dyn(&self) -> Box<dyn Shape> {
        Box::new(self.clone())
    }

    /// Not supported (the maps never scale their colliders).
    fn scale_dyn(&self, _scale: &Vector<Real>, _num_subdivisions: u32) -> Option<Box<dyn Shape>> {
        None
    }

    fn mass_properties(&self, density: Real) -> MassProperties {
        MassProperties::from_trimesh(density, &self.vertices, &self.indices)
    }

    fn shape_type(&self) -> ShapeType {
        ShapeType::Custom
    }

    fn as_typed_shape(&self) -> TypedShape<'_> {
        TypedShape::Custom(self)
    }

    /// As parry's triangle mesh: no thickness.
    fn ccd_thickness(&self) -> Real {
        0.0
    }

    /// As parry's triangle mesh.
    fn ccd_angular_thickness(&self) -> Real {
        std::f64::consts::FRAC_PI_4
    }

    fn compute_aabb(&self, position: &Isometry<Real>) -> BoxAabb {
        self.local_aabb().transform_by(position)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn mesh(points: &[[Real; 9]]) -> CompactMesh {
        let vertices = points
            .iter()
            .flat_map(|t| [0, 3, 6].map(|k| Point3::new(t[k], t[k + 1], t[k + 2])))
            .collect();
        let indices = (0..points.len() as u32).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
        let tags = (0..points.len()).collect();
        let (mesh, tags) = CompactMesh::build(vertices, indices, tags).unwrap();
        // The tags follow their triangles.
        for (i, &t) in tags.iter().enumerate() {
            let tri = mesh.triangle(i as u32);
            assert_eq!(tri.a, Point3::new(points[t][0], points[t][1], points[t][2]));
        }
        mesh
    }

    fn depth(mesh: &CompactMesh, node: u32) -> usize {
        let n = &mesh.nodes[node as usize];
        if n.count > 0 { 1 } else { 1 + depth(mesh, n.first).max(depth(mesh, n.first + 1)) }
    }

    #[test]
    fn outward_rounding_contains_the_value() {
        for x in [0.1, -0.1, 1e-40, -1e-40, 1e39, -1e39, 3.0, 16_777_217.0, -16_777_217.0] {
            assert!(Real::from(down(x)) <= x && x <= Real::from(up(x)), "{x}");
        }
    }

    #[test]
    fn identical_triangles_make_a_shallow_tree() {
        let mesh = mesh(&vec![[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]; 10_000]);
        assert!(depth(&mesh, 0) <= 14);
    }

    fn triangles() -> impl Strategy<Value = Vec<[Real; 9]>> {
        // Clusters of very different sizes, so the tree has to mix them.
        prop::collection::vec(
            (prop::array::uniform3(-50.0..50.0), 0.001..20.0, prop::array::uniform9(0.0..1.0)),
            1..300,
        )
        .prop_map(|v| {
            v.into_iter()
                .map(|(c, s, u): ([Real; 3], Real, [Real; 9])| {
                    std::array::from_fn(|k| c[k % 3] + s * u[k])
                })
                .collect()
        })
    }

    /// The box of the triangles under `node`, rounded outwards to `f32`.
    fn tight_box(mesh: &CompactMesh, node: u32) -> ([f32; 3], [f32; 3]) {
        let n = &mesh.nodes[node as usize];
        let mut b = Bounds::EMPTY;
        if n.count > 0 {
            for i in n.first..n.first + n.count {
                let t = mesh.triangle_aabb(i);
                b.add_point(&[t.mins.x, t.mins.y, t.mins.z]);
                b.add_point(&[t.maxs.x, t.maxs.y, t.maxs.z]);
            }
            (b.min.map(down), b.max.map(up))
        } else {
            let (l, r) = (tight_box(mesh, n.first), tight_box(mesh, n.first + 1));
            (
                std::array::from_fn(|k| l.0[k].min(r.0[k])),
                std::array::from_fn(|k| l.1[k].max(r.1[k])),
            )
        }
    }

    /// Every node's box is the tightest `f32` box of its triangles.
    fn assert_tight(mesh: &CompactMesh) {
        for node in 0..mesh.nodes.len() as u32 {
            let n = &mesh.nodes[node as usize];
            assert_eq!((n.min, n.max), tight_box(mesh, node), "node {node}");
        }
    }

    #[test]
    fn a_flat_grid_makes_tight_boxes() {
        // 2 × 40 × 40 triangles in the plane z = 1.5: the build's grid has no extent in z.
        let tris: Vec<[Real; 9]> = (0..40 * 40)
            .flat_map(|k| {
                let (x, y) = (Real::from(k % 40) * 0.1, Real::from(k / 40) * 0.1);
                [
                    [x, y, 1.5, x + 0.1, y, 1.5, x, y + 0.1, 1.5],
                    [x + 0.1, y, 1.5, x + 0.1, y + 0.1, 1.5, x, y + 0.1, 1.5],
                ]
            })
            .collect();
        assert_tight(&mesh(&tris));
    }

    proptest! {
        /// Every node's box holds the boxes below it and is the tightest `f32` box of its
        /// triangles, and every triangle is in one leaf.
        #[test]
        fn boxes_hold_their_triangles(tris in triangles()) {
            let mesh = mesh(&tris);
            assert_tight(&mesh);
            let mut seen = vec![0; tris.len()];
            let mut stack = vec![(0u32, None::<BoxAabb>)];
            while let Some((id, parent)) = stack.pop() {
                let node = &mesh.nodes[id as usize];
                let b = node.aabb();
                if let Some(p) = parent {
                    prop_assert!(p.mins <= b.mins && b.maxs <= p.maxs);
                }
                if node.count == 0 {
                    stack.push((node.first, Some(b)));
                    stack.push((node.first + 1, Some(b)));
                } else {
                    prop_assert!(node.count as usize <= LEAF_SIZE);
                    for i in node.first..node.first + node.count {
                        let t = mesh.triangle_aabb(i);
                        prop_assert!(b.mins <= t.mins && t.maxs <= b.maxs);
                        seen[i as usize] += 1;
                    }
                }
            }
            prop_assert!(seen.iter().all(|&s| s == 1));
        }

        /// The walks answer like a scan of all triangles: nearest centroid below a bound, and
        /// whether any triangle's box holds a point.
        #[test]
        fn walks_answer_like_a_scan(tris in triangles(), q in prop::array::uniform3(-60.0..60.0), bound in 0.0..200.0) {
            let mesh = mesh(&tris);
            let q = Point3::from(q);
            let cost = |i: u32| {
                let t = mesh.triangle(i);
                (((t.a.coords + t.b.coords + t.c.coords) / 3.0) - q.coords).norm()
            };
            let found = mesh.find_best(
                bound,
                |b, _| b.distance_to_local_point(&q, true),
                |i, best| Some(cost(i)).filter(|&c| c < best),
            );
            let scan = (0..tris.len() as u32).map(cost).filter(|&c| c < bound).min_by(Real::total_cmp);
            prop_assert_eq!(found.map(|f| f.1), scan);
            let inside = |b: &BoxAabb| b.contains_local_point(&q);
            let any = mesh.any_triangle(inside, |_| true);
            let scan = (0..tris.len() as u32).any(|i| inside(&mesh.triangle_aabb(i)));
            prop_assert_eq!(any, scan);
        }

        /// As a parry shape: point projections and ray casts answer like a scan.
        #[test]
        fn shape_queries_answer_like_a_scan(tris in triangles(), q in prop::array::uniform3(-60.0..60.0), d in prop::array::uniform3(-1.0..1.0)) {
            let mesh = mesh(&tris);
            let q = Point3::from(q);
            let all = || (0..tris.len() as u32).map(|i| mesh.triangle(i));
            let nearest = all()
                .map(|t| (t.project_local_point(&q, false).point - q).norm())
                .min_by(Real::total_cmp)
                .unwrap();
            let (p, feature) = mesh.project_local_point_and_get_feature(&q);
            prop_assert_eq!((p.point - q).norm(), nearest);
            let FeatureId::Face(i) = feature else { panic!("{feature:?}") };
            prop_assert_eq!((mesh.triangle(i).project_local_point(&q, false).point - q).norm(), nearest);
            let ray = Ray::new(q, Vector::from(d) * 100.0);
            let first = all().filter_map(|t| t.cast_local_ray(&ray, 1.0, true)).min_by(Real::total_cmp);
            prop_assert_eq!(mesh.cast_local_ray(&ray, 1.0, true), first);
        }
    }
}
