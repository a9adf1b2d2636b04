//! Outline merging across scans (thesis §5.1, "outline merging"): planar patches from several
//! registered scans that lie on the same plane and overlap become one polygon, so a map built
//! from many scans of one room keeps one patch per wall instead of one per scan.
//!
//! # Method
//! 1. **Candidates.** Two patches are merge candidates when their boxes, grown by
//!    [`MergeConfig::max_distance`] + [`MergeConfig::gap`], overlap (a sweep over the boxes'
//!    lower x bounds, `O(P log P + K)` for `K` box overlaps).
//! 2. **Same plane.** Their normals differ by at most [`MergeConfig::max_angle`] (either
//!    sign: a wall seen from both sides is one plane) and every outer vertex of each lies
//!    within [`MergeConfig::max_distance`] of the other's plane.
//! 3. **Overlap.** In the first patch's frame, the other's outline (orthogonally projected)
//!    intersects its outline or comes closer than [`MergeConfig::gap`].
//! 4. **Groups** are the connected components of "candidate, same plane and overlapping"
//!    (union–find), so merging is transitive: a chain of overlapping scans of one long wall
//!    becomes one patch.
//! 5. **Union.** A group of two or more patches gets one frame ([`patch_core::plane_frame`]):
//!    the area-weighted mean normal (signs aligned with the group's largest patch) through the
//!    area-weighted mean of the patches' centroids. Every ring is projected orthogonally into
//!    that frame and the polygons are united with `geo`'s boolean operations
//!    (`unary_union`); each polygon of the union becomes a [`PlanarPatch`]. If patch
//!    validation refuses a union polygon (rings touching at a vertex, which the overlay can
//!    produce), the group's patches are kept unmerged and counted in
//!    [`MergeStats::kept_unmerged`]: merging never loses surface.
//!
//! Merged patches carry no plane covariance: the covariances of the parts describe different
//! fits and combining them needs the point sets, which patches do not keep. Patches that are
//! merged with nothing are returned unchanged (covariance included). Output order: the groups
//! in the order of their first input patch.

use geo::{Distance, Euclidean, Intersects, LineString, MultiPolygon, Polygon as GeoPolygon};
use patch_core::{Aabb, PlanarPatch, Point2, Point3, Polygon, Real, Vector3, plane_frame};

/// Parameters of [`merge_coplanar`]. No `Default`: the tolerances depend on the sensor's noise
/// and the registration's accuracy.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct MergeConfig {
    /// Largest angle between the normals of two patches of one plane, radians.
    pub max_angle: Real,
    /// Largest distance of a patch's outer vertices from the other patch's plane, metres.
    pub max_distance: Real,
    /// Patches of one plane whose outlines are at most this far apart are merged (the gap is
    /// not filled: the union of two disjoint outlines stays two polygons), metres. 0: only
    /// outlines that touch or overlap.
    pub gap: Real,
}

impl MergeConfig {
    /// For patches of registered ALRF scans (noise of 1–3 cm, registration error of a few
    /// centimetres): 3°, 5 cm, no gap. The thesis gives no values.
    pub fn alrf() -> MergeConfig {
        MergeConfig { max_angle: 3f64.to_radians(), max_distance: 0.05, gap: 0.0 }
    }

    /// For exact geometry (synthetic scenes, CAD): 0.1°, 1 mm, no gap.
    pub fn exact() -> MergeConfig {
        MergeConfig { max_angle: 0.1f64.to_radians(), max_distance: 1e-3, gap: 0.0 }
    }

    fn validate(&self) -> Result<(), MergeError> {
        let ok = |v: Real, max: Real| v.is_finite() && (0.0..=max).contains(&v);
        if !ok(self.max_angle, std::f64::consts::FRAC_PI_2) {
            return Err(MergeError::InvalidParameter { name: "max_angle", value: self.max_angle });
        }
        if !ok(self.max_distance, Real::MAX) {
            return Err(MergeError::InvalidParameter {
                name: "max_distance",
                value: self.max_distance,
            });
        }
        if !ok(self.gap, Real::MAX) {
            return Err(MergeError::InvalidParameter { name: "gap", value: self.gap });
        }
        Ok(())
    }
}

/// Why [`merge_coplanar`] refused its input.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MergeError {
    /// A parameter is NaN, negative or out of range.
    #[error("merge parameter `{name}` = {value} is out of range")]
    InvalidParameter {
        /// The field of [`MergeConfig`].
        name: &'static str,
        /// Its value.
        value: Real,
    },
}

/// What [`merge_coplanar`] did.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct MergeStats {
    /// Patches given.
    pub input: usize,
    /// Patches returned.
    pub output: usize,
    /// Groups of two or more patches that were united.
    pub groups_merged: usize,
    /// Patches of groups whose union patch validation refused, returned unmerged.
    pub kept_unmerged: usize,
}

/// Merges the patches of `patches` that lie on one plane and overlap (see the module docs).
///
/// # Errors
/// [`MergeError::InvalidParameter`] for a NaN, negative or out-of-range parameter.
pub fn merge_coplanar(
    patches: &[PlanarPatch],
    config: &MergeConfig,
) -> Result<(Vec<PlanarPatch>, MergeStats), MergeError> {
    config.validate()?;
    let n = patches.len();
    let mut sets = UnionFind::new(n);
    let grow = config.max_distance + config.gap;
    let boxes: Vec<Aabb> = patches.iter().map(|p| inflate(&p.bounds(), grow)).collect();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| boxes[a].min.x.total_cmp(&boxes[b].min.x));
    for (k, &i) in order.iter().enumerate() {
        for &j in &order[k + 1..] {
            if boxes[j].min.x > boxes[i].max.x {
                break;
            }
            if sets.find(i) != sets.find(j)
                && boxes_overlap(&boxes[i], &boxes[j])
                && same_plane(&patches[i], &patches[j], config)
                && outlines_meet(&patches[i], &patches[j], config.gap)
            {
                sets.union(i, j);
            }
        }
    }
    let mut groups: Vec<Vec<usize>> = Vec::new();
    let mut group_of_root = vec![usize::MAX; n];
    for i in 0..n {
        let root = sets.find(i);
        if group_of_root[root] == usize::MAX {
            group_of_root[root] = groups.len();
            groups.push(Vec::new());
        }
        groups[group_of_root[root]].push(i);
    }
    let mut stats = MergeStats { input: n, ..MergeStats::default() };
    let mut out = Vec::with_capacity(groups.len());
    for group in &groups {
        if let [only] = group[..] {
            out.push(patches[only].clone());
            continue;
        }
        match unite(group.iter().map(|&i| &patches[i])) {
            Some(merged) => {
                stats.groups_merged += 1;
                out.extend(merged);
            }
            None => {
                stats.kept_unmerged += group.len();
                out.extend(group.iter().map(|&i| patches[i].clone()));
            }
        }
    }
    stats.output = out.len();
    Ok((out, stats))
}

fn inflate(b: &Aabb, by: Real) -> Aabb {
    let d = Vector3::repeat(by);
    Aabb::new(b.min - d, b.max + d)
}

fn boxes_overlap(a: &Aabb, b: &Aabb) -> bool {
    (0..3).all(|k| a.min[k] <= b.max[k] && b.min[k] <= a.max[k])
}

/// Normals within the angle (either sign) and each outline within the distance of the other's
/// plane.
fn same_plane(a: &PlanarPatch, b: &PlanarPatch, config: &MergeConfig) -> bool {
    if a.normal().dot(&b.normal()).abs() < config.max_angle.cos() {
        return false;
    }
    let near = |p: &PlanarPatch, q: &PlanarPatch| {
        let plane = q.plane();
        p.polygon()
            .outer()
            .points()
            .iter()
            .all(|v| plane.signed_distance(&p.to_world(v)).abs() <= config.max_distance)
    };
    near(a, b) && near(b, a)
}

/// Whether the outlines of `a` and `b`, both in `a`'s frame, intersect or come within `gap`.
fn outlines_meet(a: &PlanarPatch, b: &PlanarPatch, gap: Real) -> bool {
    let pa = to_geo(a.polygon());
    let pb = to_geo(&project(b, a));
    if pa.intersects(&pb) {
        return true;
    }
    gap > 0.0 && Euclidean.distance(&pa, &pb) <= gap
}

/// `patch`'s polygon in the frame of `frame` (orthogonal projection), or the unprojected
/// polygon if projecting made it invalid (only possible for nearly perpendicular planes, which
/// [`same_plane`] has excluded).
fn project(patch: &PlanarPatch, frame: &PlanarPatch) -> Polygon {
    let rings = project_rings(patch, |p| {
        let q = frame.to_local(&p);
        Point2::new(q.x, q.y)
    });
    let mut rings = rings.into_iter();
    let outer = rings.next().unwrap_or_default();
    Polygon::new(outer, rings.collect()).unwrap_or_else(|_| patch.polygon().clone())
}

/// The rings of `patch` (outer first) mapped through `local` from world coordinates, outer
/// counter-clockwise and holes clockwise.
fn project_rings(patch: &PlanarPatch, local: impl Fn(Point3) -> Point2) -> Vec<Vec<Point2>> {
    patch
        .polygon()
        .rings()
        .enumerate()
        .map(|(k, ring)| {
            let mut pts: Vec<Point2> =
                ring.points().iter().map(|v| local(patch.to_world(v))).collect();
            let ccw = signed_area(&pts) > 0.0;
            if ccw != (k == 0) {
                pts.reverse();
            }
            pts
        })
        .collect()
}

fn signed_area(pts: &[Point2]) -> Real {
    let n = pts.len();
    (0..n).map(|i| pts[i].x * pts[(i + 1) % n].y - pts[(i + 1) % n].x * pts[i].y).sum::<Real>()
        / 2.0
}

fn ring_to_geo(pts: &[Point2]) -> LineString<Real> {
    LineString::from(pts.iter().map(|p| (p.x, p.y)).collect::<Vec<_>>())
}

/// A patch-core polygon as a `geo` polygon.
pub(crate) fn to_geo(polygon: &Polygon) -> GeoPolygon<Real> {
    GeoPolygon::new(
        ring_to_geo(polygon.outer().points()),
        polygon.holes().iter().map(|h| ring_to_geo(h.points())).collect(),
    )
}

fn ring_from_geo(ring: &LineString<Real>) -> Vec<Point2> {
    let mut pts: Vec<Point2> = ring.coords().map(|c| Point2::new(c.x, c.y)).collect();
    if pts.len() > 1 && pts.first() == pts.last() {
        pts.pop();
    }
    pts
}

/// The union of a group's patches in one common frame, or `None` if a union polygon is not a
/// valid patch polygon.
fn unite<'a>(group: impl Iterator<Item = &'a PlanarPatch> + Clone) -> Option<Vec<PlanarPatch>> {
    let largest = group.clone().max_by(|a, b| a.area().total_cmp(&b.area()))?;
    let reference = largest.normal().into_inner();
    let mut normal = Vector3::zeros();
    let mut centre = Vector3::zeros();
    let mut total = 0.0;
    for p in group.clone() {
        let area = p.area();
        let n = p.normal().into_inner();
        normal += if n.dot(&reference) < 0.0 { -n * area } else { n * area };
        centre += centroid(p).coords * area;
        total += area;
    }
    if total.is_nan() || total <= 0.0 || normal.norm() == 0.0 {
        return None;
    }
    let frame = plane_frame(&normal, &Point3::from(centre / total));
    let polygons: Vec<GeoPolygon<Real>> = group
        .map(|p| {
            let mut rings = project_rings(p, |w| {
                let q = frame.inverse_transform_point(&w);
                Point2::new(q.x, q.y)
            })
            .into_iter();
            let outer = ring_to_geo(&rings.next().unwrap_or_default());
            GeoPolygon::new(outer, rings.map(|r| ring_to_geo(&r)).collect())
        })
        .collect();
    let union: MultiPolygon<Real> = geo::unary_union(&polygons);
    union
        .0
        .iter()
        .map(|poly| {
            let outer = ring_from_geo(poly.exterior());
            let holes: Vec<Vec<Point2>> = poly.interiors().iter().map(ring_from_geo).collect();
            let polygon = Polygon::new(outer.clone(), holes.clone()).or_else(|_| {
                let mut rings: Vec<Vec<Point2>> = std::iter::once(outer).chain(holes).collect();
                separate_pinches(&mut rings);
                let outer = rings.remove(0);
                Polygon::new(outer, rings)
            });
            PlanarPatch::new(polygon.ok()?, frame).ok()
        })
        .collect()
}

/// Moves every repeated occurrence of a vertex (a ring touching itself or another ring at a
/// point, which a union can produce and patch polygons refuse) by a nanometre-scale step
/// toward the midpoint of its two ring neighbours, so the rings no longer touch. The area
/// changes by about the square of the step; no point farther than the step from the boundary
/// changes side.
fn separate_pinches(rings: &mut [Vec<Point2>]) {
    let scale =
        rings.iter().flatten().fold(0.0, |m: Real, p| m.max(p.x.abs()).max(p.y.abs())).max(1.0);
    let step = 1e-9 * scale;
    let mut seen: Vec<Point2> = Vec::new();
    for ring in rings.iter_mut() {
        let n = ring.len();
        for i in 0..n {
            let v = ring[i];
            if seen.contains(&v) {
                let mid =
                    Point2::from((ring[(i + n - 1) % n].coords + ring[(i + 1) % n].coords) / 2.0);
                let d = mid - v;
                let len = d.norm();
                if len > 0.0 {
                    ring[i] = v + d * (step / len);
                }
            } else {
                seen.push(v);
            }
        }
    }
}

/// The area centroid of a patch's outer ring, in world coordinates.
fn centroid(p: &PlanarPatch) -> Point3 {
    let pts = p.polygon().outer().points();
    let (mut cx, mut cy, mut a2) = (0.0, 0.0, 0.0);
    for i in 0..pts.len() {
        let (u, v) = (pts[i], pts[(i + 1) % pts.len()]);
        let cross = u.x * v.y - v.x * u.y;
        cx += (u.x + v.x) * cross;
        cy += (u.y + v.y) * cross;
        a2 += cross;
    }
    if a2 == 0.0 {
        return p.to_world(&pts[0]);
    }
    p.to_world(&Point2::new(cx / (3.0 * a2), cy / (3.0 * a2)))
}

/// Union–find with path halving and union by size.
struct UnionFind {
    parent: Vec<usize>,
    size: Vec<usize>,
}

impl UnionFind {
    fn new(n: usize) -> UnionFind {
        UnionFind { parent: (0..n).collect(), size: vec![1; n] }
    }

    fn find(&mut self, mut i: usize) -> usize {
        while self.parent[i] != i {
            self.parent[i] = self.parent[self.parent[i]];
            i = self.parent[i];
        }
        i
    }

    fn union(&mut self, a: usize, b: usize) {
        let (mut a, mut b) = (self.find(a), self.find(b));
        if a == b {
            return;
        }
        if self.size[a] < self.size[b] {
            std::mem::swap(&mut a, &mut b);
        }
        self.parent[b] = a;
        self.size[a] += self.size[b];
    }
}
