//! Proptest strategies over bounded domains (free functions, as nalgebra's `proptest`
//! module: constrained values and invariant-preserving shrinking, which `Arbitrary` cannot
//! express).
//!
//! Scenes live in the cube `[-SCENE_EXTENT, SCENE_EXTENT]³` ([`scene_bounds`]); random steps
//! are drawn from a slightly larger box ([`step_bounds`]) so some start outside the scene.
//! Building-like patches (floors, walls with doors and windows) use coordinates on a 0.25 m
//! grid and rotations with exact quaternions (multiples of 90° about the axes and 120° about
//! the diagonals), so exact touching and coplanar configurations occur.

use std::f64::consts::{PI, TAU};
use std::sync::Arc;

use proptest::collection::{SizeRange, vec};
use proptest::prelude::*;
use proptest::sample::{Index, select};

use crate::geometry::TriangleFrame;
use crate::{
    Aabb, CapsuleStep, Isometry3, LineStep, Patch, PlanarPatch, Point2, Point3, Polygon, Real,
    Step, TrimeshPatch, Vector3, na,
};

use super::SceneKind;

/// Half the edge of the cube scenes are generated in.
pub const SCENE_EXTENT: Real = 5.0;

/// The cube scenes are generated in.
pub fn scene_bounds() -> Aabb {
    Aabb::new(
        Point3::new(-1.0, -1.0, -1.0) * SCENE_EXTENT,
        Point3::new(1.0, 1.0, 1.0) * SCENE_EXTENT,
    )
}

/// The box random steps and query points are drawn from: the scene cube grown by 1.5 m.
pub fn step_bounds() -> Aabb {
    scene_bounds().inflated(1.5)
}

/// A point uniformly in `bounds` (which must not be empty).
pub fn point3(bounds: Aabb) -> BoxedStrategy<Point3> {
    let (lo, hi) = (bounds.min, bounds.max);
    (lo.x..=hi.x, lo.y..=hi.y, lo.z..=hi.z).prop_map(|(x, y, z)| Point3::new(x, y, z)).boxed()
}

fn quarter(lo: i32, hi: i32) -> impl Strategy<Value = Real> + Clone {
    (lo..=hi).prop_map(|k| Real::from(k) * 0.25)
}

/// The 12 rotations whose unit quaternions have only the entries 0, ±½ and ±1 (the
/// tetrahedral group: 180° about the axes, 120° about the diagonals). They map the z axis to
/// every ±axis, so they place floors, ceilings and walls facing every axis direction, and they
/// transform coordinates on a dyadic grid without rounding.
pub fn exact_rotations() -> Vec<na::UnitQuaternion<Real>> {
    let q = |w, i, j, k| na::UnitQuaternion::new_unchecked(na::Quaternion::new(w, i, j, k));
    let mut out = vec![
        q(1.0, 0.0, 0.0, 0.0),
        q(0.0, 1.0, 0.0, 0.0),
        q(0.0, 0.0, 1.0, 0.0),
        q(0.0, 0.0, 0.0, 1.0),
    ];
    for signs in 0..8 {
        let s = |bit: i32| if signs >> bit & 1 == 1 { -0.5 } else { 0.5 };
        out.push(q(0.5, s(0), s(1), s(2)));
    }
    out
}

/// A rotation: uniformly random axis and angle, or one of [`exact_rotations`].
pub fn rotation() -> BoxedStrategy<na::UnitQuaternion<Real>> {
    prop_oneof![
        3 => (-1.0..=1.0, -1.0..=1.0, -1.0..=1.0)
            .prop_map(|(x, y, z)| na::UnitQuaternion::from_scaled_axis(Vector3::new(x, y, z) * PI)),
        2 => select(exact_rotations()),
    ]
    .boxed()
}

/// A pose: a random rotation and translation within 4 m of the origin, or (building-like) an
/// exact rotation and a translation on the 0.25 m grid.
pub fn isometry() -> BoxedStrategy<Isometry3> {
    let random = (rotation(), -4.0..=4.0, -4.0..=4.0, -4.0..=4.0)
        .prop_map(|(r, x, y, z)| Isometry3::from_parts(na::Translation3::new(x, y, z), r));
    let building =
        (select(exact_rotations()), quarter(-16, 16), quarter(-16, 16), quarter(-16, 16))
            .prop_map(|(r, x, y, z)| Isometry3::from_parts(na::Translation3::new(x, y, z), r));
    prop_oneof![random, building].boxed()
}

/// A polygon: rectangles, star-shaped polygons with up to two holes, walls with a door
/// (concave) and walls with windows (holes). All fit in a 6 m × 6 m square around the origin.
pub fn polygon() -> BoxedStrategy<Polygon> {
    prop_oneof![
        2 => rectangle_polygon(),
        3 => star_polygon(),
        1 => door_wall_polygon(),
        1 => window_wall_polygon(),
    ]
    .boxed()
}

/// An axis-aligned rectangle on the 0.25 m grid, from 0.25 m to 3 m per side.
pub fn rectangle_polygon() -> BoxedStrategy<Polygon> {
    (quarter(-8, 0), quarter(-8, 0), quarter(1, 12), quarter(1, 12))
        .prop_map(|(x, y, w, h)| {
            Polygon::rectangle(Point2::new(x, y), Point2::new(x + w, y + h))
                .expect("positive sides")
        })
        .boxed()
}

fn star_ring(center: Point2, params: &[(Real, Real)], scale: Real, phase: Real) -> Vec<Point2> {
    let n = params.len() as Real;
    params
        .iter()
        .enumerate()
        .map(|(k, &(jitter, radius))| {
            let angle = phase + (k as Real + jitter) * TAU / n;
            center + na::Vector2::new(angle.cos(), angle.sin()) * (radius * scale)
        })
        .collect()
}

/// A star-shaped polygon around the origin (3 to 10 vertices at radii 0.3–3 m, angular gaps
/// below π so the origin sees every edge), with up to two star-shaped holes placed in the disk
/// the outer ring leaves free around the origin.
pub fn star_polygon() -> BoxedStrategy<Polygon> {
    let ring = |n: std::ops::RangeInclusive<usize>, r: std::ops::Range<Real>| {
        (n).prop_flat_map(move |n| vec((0.0..0.45, r.clone()), n))
    };
    (ring(3..=10, 0.3..3.0), vec(ring(3..=6, 0.3..1.0), 0..=2), 0.0..TAU)
        .prop_filter_map("star polygon rejected by validation", |(outer, holes, phase)| {
            let outer = star_ring(Point2::origin(), &outer, 1.0, 0.0);
            let n = outer.len();
            let inner_radius = (0..n)
                .map(|i| {
                    let q = crate::polygon::closest_point_on_segment2(
                        &Point2::origin(),
                        &outer[i],
                        &outer[(i + 1) % n],
                    );
                    q.coords.norm()
                })
                .fold(Real::INFINITY, Real::min);
            let holes: Vec<Vec<Point2>> = if inner_radius < 0.05 {
                Vec::new()
            } else {
                holes
                    .iter()
                    .enumerate()
                    .map(|(i, params)| {
                        let angle = phase + i as Real * PI;
                        let center = Point2::new(angle.cos(), angle.sin()) * (0.5 * inner_radius);
                        star_ring(center, params, 0.3 * inner_radius, phase)
                    })
                    .collect()
            };
            Polygon::new(outer, holes).ok()
        })
        .boxed()
}

/// A wall `[0, W] × [0, H]` with a door cut out of its bottom edge (a concave polygon), on the
/// 0.25 m grid: W 2–5 m, H 2–3 m.
pub fn door_wall_polygon() -> BoxedStrategy<Polygon> {
    (8i32..=20, 8i32..=12, 2i32..=4, 0.0..1.0, 0.0..1.0)
        .prop_map(|(w, h, door, u, v)| {
            let q = |k: i32| Real::from(k) * 0.25;
            let x0 = 1 + ((w - door - 2) as Real * u) as i32;
            let top = 2 + ((h - 3) as Real * v) as i32;
            let ring = [
                (0, 0),
                (x0, 0),
                (x0, top),
                (x0 + door, top),
                (x0 + door, 0),
                (w, 0),
                (w, h),
                (0, h),
            ]
            .iter()
            .map(|&(x, y)| Point2::new(q(x), q(y)))
            .collect();
            Polygon::new(ring, Vec::new()).expect("door walls are simple")
        })
        .boxed()
}

/// A wall `[0, W] × [0, H]` with one or two rectangular windows (holes), on the 0.25 m grid.
pub fn window_wall_polygon() -> BoxedStrategy<Polygon> {
    (8i32..=20, 8i32..=12, 1usize..=2, proptest::array::uniform4(1i32..=2))
        .prop_map(|(w, h, count, m)| {
            let q = |k: i32| Real::from(k) * 0.25;
            let (width, height) = (q(w), q(h));
            let slot = width / count as Real;
            let holes = (0..count)
                .map(|i| {
                    // Slots are at least 1 m wide; x margins of 0.125 or 0.25 m keep every window
                    // at least 0.5 m wide and 0.25 m from its neighbour.
                    let x0 = i as Real * slot + 0.5 * q(m[0]);
                    let x1 = (i + 1) as Real * slot - 0.5 * q(m[1]);
                    let (y0, y1) = (q(m[2]), height - q(m[3]));
                    vec![
                        Point2::new(x0, y0),
                        Point2::new(x1, y0),
                        Point2::new(x1, y1),
                        Point2::new(x0, y1),
                    ]
                })
                .collect();
            let outer = vec![
                Point2::new(0.0, 0.0),
                Point2::new(width, 0.0),
                Point2::new(width, height),
                Point2::new(0.0, height),
            ];
            Polygon::new(outer, holes).expect("window walls are valid")
        })
        .boxed()
}

/// A planar patch: a [`polygon`] placed by an [`isometry`].
pub fn planar_patch() -> BoxedStrategy<PlanarPatch> {
    (polygon(), isometry())
        .prop_map(|(p, iso)| PlanarPatch::new(p, iso).expect("strategy poses are rigid"))
        .boxed()
}

/// A triangle mesh: a small height field (2×2 to 4×4 vertices, 0.25–1 m spacing, heights
/// ±0.5 m) placed by an [`isometry`], or a soup of 1–5 random triangles in a 2 m cube.
pub fn trimesh_patch() -> BoxedStrategy<TrimeshPatch> {
    let field = (2usize..=4, 2usize..=4, 0.25..1.0, vec(-0.5..0.5, 16), isometry())
        .prop_filter_map("degenerate height field", |(nx, ny, spacing, heights, iso)| {
            let mut vertices = Vec::new();
            for j in 0..ny {
                for i in 0..nx {
                    let local =
                        Point3::new(i as Real * spacing, j as Real * spacing, heights[j * 4 + i]);
                    vertices.push(iso * local);
                }
            }
            let mut triangles = Vec::new();
            for j in 0..ny - 1 {
                for i in 0..nx - 1 {
                    let v = |i: usize, j: usize| (j * nx + i) as u32;
                    triangles.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
                    triangles.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
                }
            }
            TrimeshPatch::new(vertices, triangles).ok()
        });
    let unit = Aabb::new(Point3::new(-1.0, -1.0, -1.0), Point3::new(1.0, 1.0, 1.0));
    let soup = (
        point3(scene_bounds().inflated(-2.0)),
        vec([point3(unit), point3(unit), point3(unit)], 1..=5),
    )
        .prop_filter_map("degenerate triangle soup", |(center, tris)| {
            let mut vertices = Vec::new();
            let mut triangles = Vec::new();
            for tri in tris {
                let base = vertices.len() as u32;
                vertices.extend(tri.iter().map(|p| center + p.coords));
                triangles.push([base, base + 1, base + 2]);
            }
            TrimeshPatch::new(vertices, triangles).ok()
        });
    prop_oneof![2 => field, 1 => soup].boxed()
}

/// A patch of the given kinds.
pub fn patch(kind: SceneKind) -> BoxedStrategy<Patch> {
    match kind {
        SceneKind::Mixed => prop_oneof![
            3 => planar_patch().prop_map(Patch::from),
            1 => trimesh_patch().prop_map(Patch::from),
        ]
        .boxed(),
        SceneKind::PlanarOnly => planar_patch().prop_map(Patch::from).boxed(),
        SceneKind::TrimeshOnly => trimesh_patch().prop_map(Patch::from).boxed(),
    }
}

/// A scene: a list of patches (the list may be empty if `size` allows it).
pub fn scene(kind: SceneKind, size: impl Into<SizeRange>) -> BoxedStrategy<Vec<Patch>> {
    vec(patch(kind), size).boxed()
}

/// A step radius: 0 (one case in six), small (1 mm – 5 cm) or robot-sized (5 cm – 1 m).
pub fn radius() -> BoxedStrategy<Real> {
    prop_oneof![1 => Just(0.0), 2 => 0.001..0.05, 3 => 0.05..1.0].boxed()
}

/// A capsule step in `bounds` with a radius from `radius`: random segments, zero-length steps
/// (sphere tests) and very short steps (below 1 mm).
pub fn capsule_step_with(bounds: Aabb, radius: BoxedStrategy<Real>) -> BoxedStrategy<CapsuleStep> {
    let tiny = (-1e-3..1e-3, -1e-3..1e-3, -1e-3..1e-3).prop_map(|(x, y, z)| Vector3::new(x, y, z));
    prop_oneof![
        3 => (point3(bounds), point3(bounds), radius.clone())
            .prop_map(|(a, b, r)| CapsuleStep::new(a, b, r).expect("finite")),
        1 => (point3(bounds), radius.clone())
            .prop_map(|(a, r)| CapsuleStep::sphere(a, r).expect("finite")),
        1 => (point3(bounds), tiny, radius)
            .prop_map(|(a, d, r)| CapsuleStep::new(a, a + d, r).expect("finite")),
    ]
    .boxed()
}

/// A capsule step in `bounds` with a [`radius`].
pub fn capsule_step(bounds: Aabb) -> BoxedStrategy<CapsuleStep> {
    capsule_step_with(bounds, radius())
}

/// A line step in `bounds` (random, zero-length and very short segments).
pub fn line_step(bounds: Aabb) -> BoxedStrategy<LineStep> {
    capsule_step_with(bounds, Just(0.0).boxed()).prop_map(|s| s.line()).boxed()
}

/// Signed offsets from the exact contact distance used by [`probe_step`]: exact, within
/// rounding, and clearly on either side of the numeric tolerance.
pub const PROBE_OFFSETS: [Real; 11] =
    [0.0, 1e-13, -1e-13, 1e-10, -1e-10, 1e-7, -1e-7, 1e-4, -1e-4, 0.05, -0.05];

/// A planar piece of a patch with a local frame: a planar patch, or one triangle of a mesh.
enum Facet<'a> {
    Polygon(&'a PlanarPatch),
    Triangle(TriangleFrame),
}

impl Facet<'_> {
    fn of(patch: &Patch, u: Real) -> Facet<'_> {
        match patch {
            Patch::Planar(p) => Facet::Polygon(p),
            Patch::Trimesh(m) => {
                let i = ((u * m.num_triangles() as Real) as usize).min(m.num_triangles() - 1);
                Facet::Triangle(TriangleFrame::new(&m.triangle(i)).expect("validated triangle"))
            }
        }
    }

    /// The rings in the local frame; the region is to the left of every edge.
    fn rings(&self) -> Vec<Vec<Point2>> {
        match self {
            Facet::Polygon(p) => p.polygon().rings().map(|r| r.points().to_vec()).collect(),
            Facet::Triangle(f) => vec![f.triangle().vertices().to_vec()],
        }
    }

    fn contains(&self, p: &Point2) -> bool {
        match self {
            Facet::Polygon(patch) => patch.polygon().contains(p),
            Facet::Triangle(f) => crate::geometry::PlanarRegion::contains(f.triangle(), p),
        }
    }

    fn to_world(&self, p: &Point3) -> Point3 {
        match self {
            Facet::Polygon(patch) => patch.world_from_patch() * p,
            Facet::Triangle(f) => f.to_world(p),
        }
    }
}

fn outward(a: &Point2, b: &Point2) -> Vector3 {
    let e = b - a;
    Vector3::new(e.y, -e.x, 0.0).normalize()
}

fn pick<T>(items: &[T], u: Real) -> &T {
    &items[((u * items.len() as Real) as usize).min(items.len() - 1)]
}

/// A unit vector perpendicular to the unit vector `m`, at angle `beta` in its normal plane.
fn perpendicular(m: &Vector3, beta: Real) -> Vector3 {
    let helper = if m.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() };
    let e1 = m.cross(&helper).normalize();
    let e2 = m.cross(&e1);
    e1 * beta.cos() + e2 * beta.sin()
}

/// The parameters of a probe step (see [`probe_step`]).
#[derive(Clone, Debug)]
struct Probe {
    patch: Index,
    feature: u8,
    u: [Real; 6],
    offset: Real,
    lengths: (Real, Real),
    radius: Real,
}

fn build_probe(scene: &[Patch], probe: &Probe) -> CapsuleStep {
    let Probe { u, offset, lengths: (l1, l2), radius, .. } = *probe;
    if scene.is_empty() {
        let c = Point3::new(u[0], u[1], u[2]) * 2.0 * SCENE_EXTENT - Vector3::repeat(SCENE_EXTENT);
        return CapsuleStep::new(c, c + Vector3::new(l1, l2, 0.0), radius).expect("finite");
    }
    let facet = Facet::of(probe.patch.get(scene), u[5]);
    let rings = facet.rings();
    let rho = (radius + offset).max(0.0);
    let z = Vector3::z();
    let side = if u[2] < 0.5 { 1.0 } else { -1.0 };
    let edge_ring = pick(&rings, u[4]);
    let k = ((u[0] * edge_ring.len() as Real) as usize).min(edge_ring.len() - 1);
    let (e0, e1) = (edge_ring[k], edge_ring[(k + 1) % edge_ring.len()]);
    let interior = || {
        let lo = rings[0].iter().fold(rings[0][0], |m, p| m.inf(p));
        let hi = rings[0].iter().fold(rings[0][0], |m, p| m.sup(p));
        let p = Point2::new(lo.x + (hi.x - lo.x) * u[0], lo.y + (hi.y - lo.y) * u[1]);
        if facet.contains(&p) {
            return p;
        }
        let mid = na::center(&e0, &e1);
        let left = mid - outward(&e0, &e1).xy() * (1e-3 * (e1 - e0).norm());
        if facet.contains(&left) { left } else { mid }
    };
    let (start, end) = match probe.feature {
        // Passing a face parallel to it at height rho.
        0 => {
            let q = interior();
            let c = Point3::new(q.x, q.y, side * rho);
            let dir = Vector3::new((TAU * u[3]).cos(), (TAU * u[3]).sin(), 0.0);
            (c - dir * l1, c + dir * l2)
        }
        // Approaching a face along its normal and stopping at height rho (or leaving it).
        1 => {
            let q = interior();
            let c = Point3::new(q.x, q.y, side * rho);
            let far = c + z * (side * (l1 + l2));
            if u[3] < 0.5 { (far, c) } else { (c, far) }
        }
        // Passing an edge at distance rho.
        2 => {
            let q = e0 + (e1 - e0) * u[1];
            let alpha = (u[3] - 0.5) * PI;
            let m = outward(&e0, &e1) * alpha.cos() + z * alpha.sin();
            let c = Point3::new(q.x, q.y, 0.0) + m * rho;
            let along = Vector3::new(e1.x - e0.x, e1.y - e0.y, 0.0).normalize();
            let w = m.cross(&along);
            let beta = TAU * u[2];
            let dir = along * beta.cos() + w * beta.sin();
            (c - dir * l1, c + dir * l2)
        }
        // Passing a vertex at distance rho.
        3 => {
            let n = edge_ring.len();
            let prev = edge_ring[(k + n - 1) % n];
            let bisector = outward(&prev, &e0) + outward(&e0, &e1);
            let bisector = bisector.try_normalize(1e-9).unwrap_or_else(|| outward(&e0, &e1));
            let alpha = (u[3] - 0.5) * PI;
            let m = bisector * alpha.cos() + z * alpha.sin();
            let c = Point3::new(e0.x, e0.y, 0.0) + m * rho;
            let dir = perpendicular(&m, TAU * u[2]);
            (c - dir * l1, c + dir * l2)
        }
        // Running along the plane: in it, or at height ±rho.
        _ => {
            let lo = rings[0].iter().fold(rings[0][0], |m, p| m.inf(p));
            let hi = rings[0].iter().fold(rings[0][0], |m, p| m.sup(p));
            let ext = hi - lo;
            let at = |a: Real, b: Real| {
                lo - ext * 0.5 + ext.component_mul(&na::Vector2::new(a, b)) * 2.0
            };
            let h = match (u[4] * 3.0) as usize {
                0 => 0.0,
                1 => rho,
                _ => -rho,
            };
            let (p, q) = (at(u[0], u[1]), at(u[2], u[3]));
            (Point3::new(p.x, p.y, h), Point3::new(q.x, q.y, h))
        }
    };
    CapsuleStep::new(facet.to_world(&start), facet.to_world(&end), radius).expect("finite")
}

/// A step built to be a near-critical case for a patch of `scene`: it passes a face
/// (parallel, at height `r + offset`), approaches a face along its normal and stops at that
/// height (or leaves from there), passes an edge or a vertex at distance `r + offset`, or runs
/// along a patch's plane (in it, or at height `±(r + offset)`), where `offset` is one of
/// [`PROBE_OFFSETS`]. The motion before and after the critical point is 0–2 m (zero in one
/// case of five). With an empty scene, a short random step.
pub fn probe_step(scene: Arc<[Patch]>, radius: BoxedStrategy<Real>) -> BoxedStrategy<CapsuleStep> {
    let length = || prop_oneof![1 => Just(0.0), 4 => 0.0..2.0];
    (
        any::<Index>(),
        0u8..5,
        proptest::array::uniform6(0.0..1.0),
        select(PROBE_OFFSETS.to_vec()),
        (length(), length()),
        radius,
    )
        .prop_map(move |(patch, feature, u, offset, lengths, radius)| {
            build_probe(&scene, &Probe { patch, feature, u, offset, lengths, radius })
        })
        .boxed()
}

/// A scene with capsule steps: random steps ([`capsule_step`] in [`step_bounds`]) and probe
/// steps ([`probe_step`]) against its patches.
pub fn scene_with_capsule_steps(
    kind: SceneKind,
    patches: impl Into<SizeRange>,
    steps: impl Into<SizeRange>,
) -> BoxedStrategy<(Vec<Patch>, Vec<CapsuleStep>)> {
    let steps = steps.into();
    scene(kind, patches)
        .prop_flat_map(move |scene| {
            let shared: Arc<[Patch]> = scene.clone().into();
            let step = prop_oneof![
                2 => capsule_step(step_bounds()),
                3 => probe_step(shared, radius()),
            ];
            (Just(scene), vec(step, steps.clone()))
        })
        .boxed()
}

/// A scene with line steps (random and probe steps, radius 0).
pub fn scene_with_line_steps(
    kind: SceneKind,
    patches: impl Into<SizeRange>,
    steps: impl Into<SizeRange>,
) -> BoxedStrategy<(Vec<Patch>, Vec<LineStep>)> {
    let steps = steps.into();
    scene(kind, patches)
        .prop_flat_map(move |scene| {
            let shared: Arc<[Patch]> = scene.clone().into();
            let step = prop_oneof![
                2 => line_step(step_bounds()),
                3 => probe_step(shared, Just(0.0).boxed()).prop_map(|s| s.line()),
            ];
            (Just(scene), vec(step, steps.clone()))
        })
        .boxed()
}

/// A scene with query points: random points in [`step_bounds`], and points near, on or at
/// `r ± tiny` from its patches (the starts of probe steps).
pub fn scene_with_points(
    kind: SceneKind,
    patches: impl Into<SizeRange>,
    points: impl Into<SizeRange>,
) -> BoxedStrategy<(Vec<Patch>, Vec<Point3>)> {
    let points = points.into();
    scene(kind, patches)
        .prop_flat_map(move |scene| {
            let shared: Arc<[Patch]> = scene.clone().into();
            let point = prop_oneof![
                1 => point3(step_bounds()),
                2 => probe_step(shared, radius()).prop_map(|s| s.start()),
            ];
            (Just(scene), vec(point, points.clone()))
        })
        .boxed()
}
