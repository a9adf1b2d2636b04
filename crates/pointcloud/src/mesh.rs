//! Polygon meshes: vertices and faces that index them.

use crate::{Aabb, Point3};

/// Why a mesh was refused.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum MeshError {
    /// A vertex has a NaN or infinite coordinate.
    #[error("vertex {index} is not finite")]
    NonFiniteVertex {
        /// The vertex index (0-based).
        index: usize,
    },
    /// A face names a vertex that does not exist.
    #[error("face {face} names vertex {index}, but the mesh has {num_vertices} vertices")]
    IndexOutOfRange {
        /// The face index (0-based).
        face: usize,
        /// The vertex index named (0-based).
        index: u32,
        /// The number of vertices.
        num_vertices: usize,
    },
    /// A face has fewer than three corners.
    #[error("face {face} has {corners} corners; a face needs at least 3")]
    TooFewCorners {
        /// The face index (0-based).
        face: usize,
        /// Its number of corners.
        corners: usize,
    },
    /// More vertices or face corners than 32-bit indices can address.
    #[error("the mesh is too large for 32-bit indices")]
    TooLarge,
}

/// A polygon mesh: finite vertices, and faces given as polygons of 0-based vertex indices.
///
/// Faces keep all their corners (a quad stays a quad); [`PolygonMesh::triangulated`] and
/// [`PolygonMesh::triangles`] split them as fans (`a b c d` → `a b c`, `a c d`). Faces need not be
/// planar, convex or consistently oriented, and repeated corners (degenerate faces) are kept.
///
/// # Invariants
/// Every vertex is finite, every face has at least three corners, and every corner indexes an
/// existing vertex. The fields are private so that every mesh a function receives upholds them.
#[derive(Clone, Debug, PartialEq)]
pub struct PolygonMesh {
    vertices: Vec<Point3>,
    /// Face `i` is `corners[offsets[i]..offsets[i + 1]]`; `offsets` starts with 0.
    offsets: Vec<u32>,
    corners: Vec<u32>,
}

impl Default for PolygonMesh {
    /// The empty mesh.
    fn default() -> PolygonMesh {
        PolygonMesh { vertices: Vec::new(), offsets: vec![0], corners: Vec::new() }
    }
}

impl PolygonMesh {
    /// A mesh from vertices and polygonal faces (0-based vertex indices). Fails on a non-finite
    /// vertex, a face with fewer than three corners or a corner naming a missing vertex.
    pub fn new(vertices: Vec<Point3>, faces: Vec<Vec<u32>>) -> Result<PolygonMesh, MeshError> {
        let mut offsets = Vec::with_capacity(faces.len() + 1);
        offsets.push(0u32);
        let mut corners = Vec::with_capacity(faces.iter().map(Vec::len).sum());
        for face in &faces {
            corners.extend_from_slice(face);
            offsets.push(u32::try_from(corners.len()).map_err(|_| MeshError::TooLarge)?);
        }
        PolygonMesh::from_parts(vertices, offsets, corners)
    }

    /// A mesh of triangles (0-based vertex indices), validated as by [`PolygonMesh::new`].
    pub fn from_triangles(
        vertices: Vec<Point3>,
        triangles: &[[u32; 3]],
    ) -> Result<PolygonMesh, MeshError> {
        let n = u32::try_from(triangles.len().checked_mul(3).ok_or(MeshError::TooLarge)?)
            .map_err(|_| MeshError::TooLarge)?;
        let offsets = (0..=n).step_by(3).collect();
        let corners = triangles.iter().flatten().copied().collect();
        PolygonMesh::from_parts(vertices, offsets, corners)
    }

    /// A mesh from its packed face table: face `i` is `corners[offsets[i]..offsets[i + 1]]`;
    /// `offsets` starts with 0, never decreases and ends with `corners.len()`.
    pub(crate) fn from_parts(
        vertices: Vec<Point3>,
        offsets: Vec<u32>,
        corners: Vec<u32>,
    ) -> Result<PolygonMesh, MeshError> {
        if u32::try_from(vertices.len()).is_err() {
            return Err(MeshError::TooLarge);
        }
        if let Some(index) = vertices.iter().position(|p| !p.coords.iter().all(|v| v.is_finite())) {
            return Err(MeshError::NonFiniteVertex { index });
        }
        debug_assert_eq!(offsets.first(), Some(&0));
        debug_assert_eq!(offsets.last().map(|&o| o as usize), Some(corners.len()));
        for (face, w) in offsets.windows(2).enumerate() {
            let n = w[1].saturating_sub(w[0]) as usize;
            if n < 3 {
                return Err(MeshError::TooFewCorners { face, corners: n });
            }
            let polygon = &corners[w[0] as usize..w[1] as usize];
            if let Some(&index) = polygon.iter().find(|&&i| i as usize >= vertices.len()) {
                return Err(MeshError::IndexOutOfRange {
                    face,
                    index,
                    num_vertices: vertices.len(),
                });
            }
        }
        Ok(PolygonMesh { vertices, offsets, corners })
    }

    /// The vertices.
    pub fn vertices(&self) -> &[Point3] {
        &self.vertices
    }

    /// The number of vertices.
    pub fn num_vertices(&self) -> usize {
        self.vertices.len()
    }

    /// The number of faces (polygons, not triangles).
    pub fn num_faces(&self) -> usize {
        self.offsets.len() - 1
    }

    /// The corners of face `i` (0-based vertex indices), or `None` past the last face.
    pub fn face(&self, i: usize) -> Option<&[u32]> {
        let start = *self.offsets.get(i)? as usize;
        let end = *self.offsets.get(i + 1)? as usize;
        Some(&self.corners[start..end])
    }

    /// The faces, each as its corners (0-based vertex indices).
    pub fn faces(&self) -> impl ExactSizeIterator<Item = &[u32]> + '_ {
        self.offsets.windows(2).map(|w| &self.corners[w[0] as usize..w[1] as usize])
    }

    /// Whether every face is a triangle.
    pub fn is_triangle_mesh(&self) -> bool {
        self.offsets.windows(2).all(|w| w[1] - w[0] == 3)
    }

    /// The number of triangles of the fan triangulation: `corners − 2` per face.
    pub fn num_triangles(&self) -> usize {
        self.corners.len() - 2 * self.num_faces()
    }

    /// The triangles of the fan triangulation of every face, in face order
    /// (`a b c d` → `[a, b, c]`, `[a, c, d]`).
    pub fn triangles(&self) -> impl Iterator<Item = [u32; 3]> + '_ {
        self.faces().flat_map(|f| f.windows(2).skip(1).map(move |w| [f[0], w[0], w[1]]))
    }

    /// The same mesh with every face split into a fan of triangles. Vertices are shared, not
    /// copied per triangle.
    pub fn triangulated(&self) -> PolygonMesh {
        let corners: Vec<u32> = self.triangles().flatten().collect();
        // The triangulation has fewer corners than the polygons, so the offsets fit in u32.
        let offsets = (0..=corners.len() as u32).step_by(3).collect();
        PolygonMesh { vertices: self.vertices.clone(), offsets, corners }
    }

    /// The bounding box of the vertices ([`Aabb::EMPTY`] without vertices). Vertices no face
    /// uses count too.
    pub fn bounds(&self) -> Aabb {
        Aabb::from_points(&self.vertices)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Vec<Point3> {
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(1.0, 1.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ]
    }

    #[test]
    fn quads_are_kept_and_fan_triangulated() {
        let m = PolygonMesh::new(square(), vec![vec![0, 1, 2, 3]]).unwrap();
        assert_eq!(m.num_faces(), 1);
        assert_eq!(m.face(0), Some(&[0, 1, 2, 3][..]));
        assert_eq!(m.face(1), None);
        assert!(!m.is_triangle_mesh());
        assert_eq!(m.num_triangles(), 2);
        let t = m.triangulated();
        assert!(t.is_triangle_mesh());
        assert_eq!(t.faces().collect::<Vec<_>>(), vec![&[0, 1, 2][..], &[0, 2, 3][..]]);
        assert_eq!(t.num_triangles(), 2);
        assert_eq!(m.bounds().extents(), crate::Vector3::new(1.0, 1.0, 0.0));
    }

    #[test]
    fn bad_meshes_are_refused() {
        assert_eq!(
            PolygonMesh::new(square(), vec![vec![0, 1]]),
            Err(MeshError::TooFewCorners { face: 0, corners: 2 })
        );
        assert_eq!(
            PolygonMesh::from_triangles(square(), &[[0, 1, 2], [0, 4, 1]]),
            Err(MeshError::IndexOutOfRange { face: 1, index: 4, num_vertices: 4 })
        );
        let mut v = square();
        v[2].y = f64::NAN;
        assert_eq!(PolygonMesh::new(v, vec![]), Err(MeshError::NonFiniteVertex { index: 2 }));
    }

    #[test]
    fn empty_mesh_is_fine() {
        let m = PolygonMesh::default();
        assert_eq!(m.num_faces(), 0);
        assert_eq!(m.num_triangles(), 0);
        assert!(m.bounds().is_empty());
        let m = PolygonMesh::new(square(), vec![]).unwrap();
        assert_eq!(m.num_faces(), 0);
        assert_eq!(m.triangulated(), m);
    }
}
