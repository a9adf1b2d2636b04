//! Planar patches from range data (thesis §5.3).

pub mod alpha_shape;
pub mod chain_code;
pub mod evaluate;
pub mod grid_mesh;
pub mod hull;
pub mod merge;
pub mod pipeline;
pub mod plane_fit;
pub mod polygonize;
pub mod projection;
pub mod quality;
pub mod region;
pub mod scanline;
pub mod segment;
pub mod simplify;
pub mod trimesh_grow;

pub use region::{PlanarRegion, Segmentation};
