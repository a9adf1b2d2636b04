//! Constrained Delaunay triangulation of polygons with holes (spade), the step that turns planar
//! patches into triangles for triangle-mesh backends (thesis §5.4.2: "planar patches are
//! Delaunay-triangulated into trimeshes").
//!
//! The rings' edges are inserted as constraints with spade's non-panicking
//! `can_add_constraint`/`try_add_constraint`, so crossing rings give an error instead of a panic.
//! A triangle of the triangulation is kept when its centroid lies inside the polygon (inside the
//! outer ring and outside every hole, by the crossing rule): every triangle lies wholly inside or
//! wholly outside, because the polygon's boundary consists of constraint edges.

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
    let mut triangles = Vec::new();
    for face in cdt.inner_faces() {
        let [a, b, c] = face.vertices();
        let (pa, pb, pc) = (a.position(), b.position(), c.position());
        let centroid = [(pa.x + pb.x + pc.x) / 3.0, (pa.y + pb.y + pc.y) / 3.0];
        if inside(rings, centroid) {
            triangles.push([
                a.fix().index() as u32,
                b.fix().index() as u32,
                c.fix().index() as u32,
            ]);
        }
    }
    Ok(Triangulated { vertices, triangles })
}

/// Crossing-number test over all rings: inside the outer ring and outside every hole.
fn inside(rings: &[Vec<[f64; 2]>], p: [f64; 2]) -> bool {
    let mut odd = false;
    for ring in rings {
        let n = ring.len();
        for i in 0..n {
            let (a, b) = (ring[i], ring[(i + 1) % n]);
            if (a[1] > p[1]) != (b[1] > p[1]) {
                let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
                if p[0] < x {
                    odd = !odd;
                }
            }
        }
    }
    odd
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
