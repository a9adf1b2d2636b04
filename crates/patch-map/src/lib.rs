//! Patch map backends (thesis §5.4.2).
//!
//! This crate is being built up; it currently holds the spatial index of the 6D bounding-box
//! backend ([`kdtree`]), the point-cloud map ([`point_cloud`], the thesis's Algorithm 10), the
//! triangulation of planar patches ([`triangulate`]) and the map file container ([`mapfile`]).

pub mod kdtree;
pub mod mapfile;
pub mod point_cloud;
pub mod triangulate;

pub use point_cloud::{PointCloudMap, PointCloudMapError};
