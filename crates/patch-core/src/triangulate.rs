//! Constrained Delaunay triangulation of polygons with holes (spade), the step that turns planar
//! patches into triangles for triangle-mesh backends (thesis §5.4.2: "planar patches are
//! Delaunay-triangulated into trimeshes").
//!
//! The rings' edges are inserted as constraints with spade's non-panicking
//! `can_add_constraint`/`try_add_constraint`, so crossing rings give an error instead of a panic.
//! A triangle of the triangulation is kept when it lies inside the polygon: every triangle lies
//! wholly inside or wholly outside, because the polygon's boundary consists of constraint
//! edges, and a walk from the outer face to it crosses an odd number of them exactly when it
//! is inside (inside the outer ring and outside every hole). The parity is found by a
//! breadth-first walk over the triangles, without coordinate arithmetic: a sliver triangle
//! between nearly collinear vertices, whose centroid rounding could put on either side, is
//! classified exactly.

use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

/// Why a polygon could not be triangulated.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TriangulationError {
    /// A coordinate is NaN, infinite or too large for exact predicates.
    #[error("ring {ring}, vertex {vertex}: coordinate cannot be triangulated ({reason})")]
    BadCoordinate {
        /// Ring index (0 = outer).
        ring: usize,
        /// Vertex index in the ring.
        vertex: usize,
        /// Spade's reason.
        reason: String,
    },
    /// Two ring edges cross.
    #[error("ring {ring}, edge {edge} crosses another edge")]
    CrossingEdges {
        /// Ring index (0 = outer).
        ring: usize,
        /// Edge index in the ring (from vertex `edge` to `edge + 1`).
        edge: usize,
    },
    /// A ring has fewer than three vertices.
    #[error("ring {ring} has {len} vertices, at least 3 are needed")]
    TooFewVertices {
        /// Ring index.
        ring: usize,
        /// Its vertex count.
        len: usize,
    },
}

/// A triangulated polygon: vertices (the rings' vertices, duplicates merged) and
/// counter-clockwise triangles as vertex indices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Triangulated {
    /// The vertices.
    pub vertices: Vec<[f64; 2]>,
    /// Counter-clockwise triangles.
    pub triangles: Vec<[u32; 3]>,
}

/// Coordinates closer to zero than spade accepts are snapped to zero (they are below any
/// meaningful length in metres).
fn snap(v: f64) -> f64 {
    if v.abs() < 1e-30 { 0.0 } else { v }
}

/// Triangulates the polygon whose outer ring is `rings[0]` and whose holes are `rings[1..]`
/// (rings need not be closed, orientation does not matter).
///
/// # Complexity
/// `O(n log n)` expected for `n` vertices (constraint insertion can be worse on adversarial
/// input).
pub fn triangulate_polygon(rings: &[Vec<[f64; 2]>]) -> Result<Triangulated, TriangulationError> {
    let mut cdt: ConstrainedDelaunayTriangulation<Point2<f64>> =
        ConstrainedDelaunayTriangulation::new();
    let mut handles = Vec::with_capacity(rings.len());
    for (ring, points) in rings.iter().enumerate() {
        if points.len() < 3 {
            return Err(TriangulationError::TooFewVertices { ring, len: points.len() });
        }
        let mut ring_handles = Vec::with_capacity(points.len());
        for (vertex, p) in points.iter().enumerate() {
            let h = cdt.insert(Point2::new(snap(p[0]), snap(p[1]))).map_err(|e| {
                TriangulationError::BadCoordinate { ring, vertex, reason: format!("{e:?}") }
            })?;
            ring_handles.push(h);
        }
        handles.push(ring_handles);
    }
    for (ring, ring_handles) in handles.iter().enumerate() {
        for edge in 0..ring_handles.len() {
            let (a, b) = (ring_handles[edge], ring_handles[(edge + 1) % ring_handles.len()]);
            if a == b {
                continue; // a repeated vertex (e.g. a closed ring's last point)
            }
            if !cdt.can_add_constraint(a, b) || cdt.try_add_constraint(a, b).is_empty() {
                // `try_add_constraint` returns nothing when the edge exists already as a
                // constraint, which a valid polygon never repeats.
                return Err(TriangulationError::CrossingEdges { ring, edge });
            }
        }
    }
    let vertices: Vec<[f64; 2]> =
        cdt.vertices().map(|v| [v.position().x, v.position().y]).collect();
    let inside = inside_faces(&cdt);
    let mut triangles = Vec::new();
    for face in cdt.inner_faces() {
        let [a, b, c] = face.vertices();
        if inside[face.fix().index()] {
            triangles.push([
                a.fix().index() as u32,
                b.fix().index() as u32,
                c.fix().index() as u32,
            ]);
        }
    }
    Ok(Triangulated { vertices, triangles })
}

/// Per face of `cdt` (by index): whether it lies inside the polygon whose rings are its
/// constraint edges, i.e. whether walks from the outer face to it cross an odd number of
/// constraint edges (the parity is the same along every walk, the rings being closed).
fn inside_faces(cdt: &ConstrainedDelaunayTriangulation<Point2<f64>>) -> Vec<bool> {
    let crossings = |e: spade::handles::DirectedEdgeHandle<'_, _, _, _, _>| {
        u32::from(cdt.is_constraint_edge(e.as_undirected().fix()))
    };
    let mut depth: Vec<Option<u32>> = vec![None; cdt.num_all_faces()];
    let mut queue = std::collections::VecDeque::new();
    for face in cdt.inner_faces() {
        for e in face.adjacent_edges() {
            let slot = &mut depth[face.fix().index()];
            if slot.is_none() && e.rev().face().is_outer() {
                *slot = Some(crossings(e));
                queue.push_back(face.fix());
            }
        }
    }
    while let Some(fixed) = queue.pop_front() {
        let face = cdt.face(fixed);
        let d = depth[fixed.index()].unwrap_or(0);
        for e in face.adjacent_edges() {
            if let Some(next) = e.rev().face().as_inner() {
                let slot = &mut depth[next.fix().index()];
                if slot.is_none() {
                    *slot = Some(d + crossings(e));
                    queue.push_back(next.fix());
                }
            }
        }
    }
    depth.into_iter().map(|d| d.is_some_and(|d| d % 2 == 1)).collect()
}

/// The world triangles of a patch: a planar patch's polygon triangulated by
/// [`triangulate_polygon`] and mapped to the world, or a mesh's own triangles.
///
/// # Errors
/// [`TriangulationError`] if the polygon cannot be triangulated (only for coordinates beyond
/// the exact predicates' range: validated polygons have no crossing rings).
pub fn patch_triangles(
    patch: &crate::Patch,
) -> Result<Vec<[crate::Point3; 3]>, TriangulationError> {
    match patch {
        crate::Patch::Planar(p) => {
            let rings: Vec<Vec<[f64; 2]>> = p
                .polygon()
                .rings()
                .map(|r| r.points().iter().map(|q| [q.x, q.y]).collect())
                .collect();
            let t = triangulate_polygon(&rings)?;
            let world = |k: u32| {
                let [x, y] = t.vertices[k as usize];
                p.to_world(&crate::Point2::new(x, y))
            };
            Ok(t.triangles.iter().map(|tri| tri.map(world)).collect())
        }
        crate::Patch::Trimesh(m) => Ok((0..m.num_triangles()).map(|i| m.triangle(i)).collect()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn ring_area(r: &[[f64; 2]]) -> f64 {
        let n = r.len();
        (0..n).map(|i| r[i][0] * r[(i + 1) % n][1] - r[(i + 1) % n][0] * r[i][1]).sum::<f64>() / 2.0
    }

    fn tri_area(v: &[[f64; 2]], t: &[u32; 3]) -> f64 {
        let (a, b, c) = (v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]);
        ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])) / 2.0
    }

    fn square(c: [f64; 2], h: f64) -> Vec<[f64; 2]> {
        vec![[c[0] - h, c[1] - h], [c[0] + h, c[1] - h], [c[0] + h, c[1] + h], [c[0] - h, c[1] + h]]
    }

    #[test]
    fn square_with_a_hole() {
        let rings = vec![square([0.0, 0.0], 2.0), square([0.0, 0.0], 1.0)];
        let t = triangulate_polygon(&rings).unwrap();
        let area: f64 = t.triangles.iter().map(|tr| tri_area(&t.vertices, tr)).sum();
        assert!((area - 12.0).abs() < 1e-12, "{area}");
        assert_eq!(t.triangles.len(), 8);
        assert!(t.triangles.iter().all(|tr| tri_area(&t.vertices, tr) > 0.0), "CCW");
    }

    #[test]
    fn concave_polygon_keeps_only_inner_triangles() {
        // An L shape: area 3.
        let l = vec![vec![[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 1.0], [1.0, 2.0], [0.0, 2.0]]];
        let t = triangulate_polygon(&l).unwrap();
        let area: f64 = t.triangles.iter().map(|tr| tri_area(&t.vertices, tr)).sum();
        assert!((area - 3.0).abs() < 1e-12);
    }

    /// A patch outline from a lab scan with two vertices 1e-9 m apart on a nearly straight
    /// edge: the sliver outside it, between them and the next vertex, has a centroid that
    /// rounding put inside the ring. The walk over the triangles classifies it exactly.
    #[test]
    #[allow(clippy::excessive_precision)] // the outline's coordinates as the map holds them
    fn a_sliver_outside_a_nearly_straight_edge_is_not_kept() {
        let ring = vec![
            [-0.30394544619192254, 0.02893516701273442],
            [-0.31121996211876046, 0.01958966255746604],
            [-0.30956240817029845, 0.00786321610770942],
            [-0.30261096338798177, -0.04131513460911988],
            [-0.30010012983401191, -0.05907815414853572],
            [-0.29288629795481336, -0.06534400861151694],
            [-0.27494670151789558, -0.06534400954283952],
            [-0.05990722942222726, -0.06534401513077497],
            [-0.02054624053706300, -0.06534401699342011],
            [-0.02054623960574042, -0.06534401699342011],
            [0.34054160789529908, -0.06534402071871041],
            [0.35848120433221686, -0.06534402071871041],
            [0.37266946976016391, -0.02902428712137221],
            [0.35948032439629662, -0.01686387694813489],
            [0.35131616258005727, -0.00933650880493402],
            [0.36304131262879002, 0.02127330843917848],
            [0.36945842971037257, 0.03802591283432961],
            [0.33553717491160262, 0.06444016192667008],
            [0.32086784970889914, 0.05411349703185082],
            [0.30578751974682439, 0.04349750001542092],
            [0.29757144228498567, 0.05789001659117461],
            [0.28072860670219291, 0.05732692406140090],
            [0.19856507723162997, 0.05458001699857236],
            [0.18621365838627446, 0.08708036598376752],
            [0.16829099991302121, 0.08630097751132966],
            [-0.26137126310785186, 0.06761658657900811],
            [-0.27427264004071128, 0.06705555413476945],
            [-0.28220473769177568, 0.05686525907926084],
        ];
        let t = triangulate_polygon(std::slice::from_ref(&ring)).unwrap();
        assert_eq!(t.triangles.len(), ring.len() - 2);
        assert!(t.triangles.iter().all(|tr| tri_area(&t.vertices, tr) > 0.0), "CCW");
        let area: f64 = t.triangles.iter().map(|tr| tri_area(&t.vertices, tr)).sum();
        assert!((area - ring_area(&ring).abs()).abs() < 1e-12, "{area}");
    }

    #[test]
    fn bad_input_is_an_error_not_a_panic() {
        let bow_tie = vec![vec![[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]]];
        assert!(matches!(
            triangulate_polygon(&bow_tie),
            Err(TriangulationError::CrossingEdges { .. })
        ));
        let crossing_hole = vec![square([0.0, 0.0], 1.0), square([1.0, 0.0], 0.5)];
        assert!(matches!(
            triangulate_polygon(&crossing_hole),
            Err(TriangulationError::CrossingEdges { .. })
        ));
        let nan = vec![vec![[0.0, 0.0], [f64::NAN, 0.0], [0.0, 1.0]]];
        assert!(matches!(
            triangulate_polygon(&nan),
            Err(TriangulationError::BadCoordinate { ring: 0, vertex: 1, .. })
        ));
        assert!(matches!(
            triangulate_polygon(&[vec![[0.0, 0.0], [1.0, 0.0]]]),
            Err(TriangulationError::TooFewVertices { ring: 0, len: 2 })
        ));
    }

    prop_compose! {
        /// A star-shaped polygon around the origin (radii 1..3 at sorted angles, at least 8 so
        /// consecutive vertices are less than 90° apart and every edge stays 0.7 from the origin)
        /// and, maybe, a square hole of half-size 0.2 at the origin.
        fn star_polygon()(
            radii in prop::collection::vec(1.0f64..3.0, 8..40),
            jitter in prop::collection::vec(0.0f64..0.9, 40),
            hole in any::<bool>(),
        ) -> Vec<Vec<[f64; 2]>> {
            let n = radii.len();
            let outer = (0..n).map(|i| {
                let a = (i as f64 + jitter[i]) / n as f64 * std::f64::consts::TAU;
                [radii[i] * a.cos(), radii[i] * a.sin()]
            }).collect();
            let mut rings = vec![outer];
            if hole {
                rings.push(square([0.0, 0.0], 0.2));
            }
            rings
        }
    }

    proptest! {
        #[test]
        fn triangles_tile_the_polygon(rings in star_polygon()) {
            let expected = ring_area(&rings[0]).abs()
                - rings[1..].iter().map(|r| ring_area(r).abs()).sum::<f64>();
            let t = triangulate_polygon(&rings).unwrap();
            let areas: Vec<f64> = t.triangles.iter().map(|tr| tri_area(&t.vertices, tr)).collect();
            prop_assert!(areas.iter().all(|&a| a > 0.0));
            let total: f64 = areas.iter().sum();
            prop_assert!((total - expected).abs() < 1e-9 * expected.max(1.0), "{total} vs {expected}");
            // n vertices, h holes: a triangulation of a polygon with holes has n + 2h − 2 triangles.
            let n: usize = rings.iter().map(Vec::len).sum();
            prop_assert_eq!(t.triangles.len(), n + 2 * (rings.len() - 1) - 2);
        }
    }
}
