//! Errors of this crate: one enum per boundary (patches, steps, maps).

use thiserror::Error;

use crate::{PatchKind, Real, RingId};

/// Why a patch (polygon, planar patch, covariance or triangle mesh) was rejected.
///
/// Every variant names where the problem is: ring and vertex, edge, triangle, or matrix entry.
/// Ring, vertex and edge indices refer to the input as given (edge `i` runs from vertex `i` to
/// vertex `i + 1`, the last edge closes the ring).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PatchError {
    /// A ring has fewer than 3 vertices.
    #[error("{ring} has {count} vertices, at least 3 are needed")]
    TooFewVertices {
        /// The ring.
        ring: RingId,
        /// Its number of vertices.
        count: usize,
    },
    /// A ring vertex has a NaN or infinite coordinate.
    #[error("vertex {vertex} of the {ring} is not finite")]
    NonFiniteVertex {
        /// The ring.
        ring: RingId,
        /// The vertex index in that ring.
        vertex: usize,
    },
    /// Two consecutive vertices of a ring are equal (the closing pair last → first included).
    #[error("vertex {vertex} of the {ring} equals the next vertex")]
    RepeatedVertex {
        /// The ring.
        ring: RingId,
        /// The first of the two equal vertices.
        vertex: usize,
    },
    /// All vertices of a ring lie on one line.
    #[error("the {ring} has zero area")]
    ZeroArea {
        /// The ring.
        ring: RingId,
    },
    /// Two edges touch or cross: a self-intersecting ring, a hole touching or crossing the
    /// outer ring, or two holes touching. Adjacent edges of one ring may only share their
    /// common vertex.
    #[error("edge {edge_a} of the {ring_a} meets edge {edge_b} of the {ring_b}")]
    EdgesIntersect {
        /// The ring of the first edge.
        ring_a: RingId,
        /// The first edge.
        edge_a: usize,
        /// The ring of the second edge (may equal `ring_a`).
        ring_b: RingId,
        /// The second edge.
        edge_b: usize,
    },
    /// A hole lies outside the outer ring.
    #[error("hole {hole} lies outside the outer ring")]
    HoleOutside {
        /// The hole index.
        hole: usize,
    },
    /// A hole lies inside another hole.
    #[error("hole {inner_hole} lies inside hole {outer_hole}")]
    NestedHoles {
        /// The enclosing hole.
        outer_hole: usize,
        /// The enclosed hole.
        inner_hole: usize,
    },
    /// The `world_from_patch` transform is not finite or its rotation is not a unit quaternion
    /// (norm off by more than 1e-6).
    #[error("the patch transform is not a finite rigid transform")]
    InvalidTransform,
    /// A vertex given in world coordinates is farther than the tolerance from the fitted plane.
    #[error(
        "vertex {vertex} of the {ring} is {distance} m from the fitted plane (tolerance {tolerance} m)"
    )]
    NotPlanar {
        /// The ring.
        ring: RingId,
        /// The vertex index in that ring.
        vertex: usize,
        /// Its distance from the plane.
        distance: Real,
        /// The tolerance that was exceeded.
        tolerance: Real,
    },
    /// A tolerance parameter is negative or not finite.
    #[error("tolerance {tolerance} is not a finite non-negative number")]
    InvalidTolerance {
        /// The value given.
        tolerance: Real,
    },
    /// A covariance entry is NaN or infinite.
    #[error("covariance entry ({row}, {col}) is not finite")]
    NonFiniteCovariance {
        /// Row index.
        row: usize,
        /// Column index.
        col: usize,
    },
    /// A covariance matrix is not symmetric (relative difference above 1e-9).
    #[error("covariance entries ({row}, {col}) and ({col}, {row}) differ")]
    AsymmetricCovariance {
        /// Row index.
        row: usize,
        /// Column index.
        col: usize,
    },
    /// A covariance diagonal entry (a variance) is negative.
    #[error("covariance diagonal entry {index} is negative")]
    NegativeVariance {
        /// The diagonal index.
        index: usize,
    },
    /// A triangle mesh has no triangles.
    #[error("the triangle mesh has no triangles")]
    NoTriangles,
    /// A mesh vertex has a NaN or infinite coordinate.
    #[error("mesh vertex {vertex} is not finite")]
    NonFiniteMeshVertex {
        /// The vertex index.
        vertex: usize,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error("triangle {triangle} refers to vertex {index}, but there are {num_vertices} vertices")]
    IndexOutOfRange {
        /// The triangle index.
        triangle: usize,
        /// The offending vertex index.
        index: u32,
        /// The number of vertices.
        num_vertices: usize,
    },
    /// A triangle's area is below [`MIN_TRIANGLE_AREA`](crate::MIN_TRIANGLE_AREA).
    #[error("triangle {triangle} has area {area} m², below the minimum")]
    DegenerateTriangle {
        /// The triangle index.
        triangle: usize,
        /// Its area.
        area: Real,
    },
}

/// Why a step was rejected.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum StepError {
    /// The start or end point has a NaN or infinite coordinate.
    #[error("the step's {which} point is not finite")]
    NonFinitePoint {
        /// `"start"` or `"end"`.
        which: &'static str,
    },
    /// The radius is negative, NaN or infinite.
    #[error("step radius {radius} is not a finite non-negative number")]
    InvalidRadius {
        /// The value given.
        radius: Real,
    },
}

/// Why a map refused a patch.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum MapError {
    /// The backend does not store this kind of patch.
    ///
    /// # How to handle this error
    /// Build the map from patches of the kinds the backend takes (its docs say which); for
    /// example, a planar-only backend can hold a triangle mesh as one planar patch per triangle
    /// ([`PlanarPatch::from_world_polygon`](crate::PlanarPatch::from_world_polygon) with the
    /// triangle's three corners).
    #[error("this map does not store {kind} patches")]
    Unsupported {
        /// The refused kind.
        kind: PatchKind,
    },
    /// The map already holds `u32::MAX` patches; [`PatchId`](crate::PatchId) cannot count
    /// further.
    #[error("the map is full ({} patches)", u32::MAX)]
    TooManyPatches,
}
