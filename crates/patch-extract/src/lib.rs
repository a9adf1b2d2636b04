//! Planar patches from range data (thesis §5.3, spec §2): plane segmentation of organised and
//! unorganised scans, projection of the regions onto their planes, outlines and
//! triangulations of the thesis's survey, outline simplification, trimesh growing for the
//! non-planar remainder (of unorganised scans too, through a spherical grid), and outline
//! merging across scans; [`pipeline::extract`] runs them all.
//!
//! | stage | module | thesis |
//! |---|---|---|
//! | mixed pixels (veil points) at depth edges, before segmentation | [`mod@mixed_pixels`] | — (ours: the shadow/veil test of PCL and ROS with line and plane support, measured in the module) |
//! | incremental least-squares plane fit | [`plane_fit`] | §5.3.2 (orthogonal LSQ, L4624–4628) |
//! | region growing segmentation | [`mod@segment`] | Poppinga et al. 2008, undescribed in the thesis: our method is documented in the module |
//! | a second pass over the remainder with smaller seed windows and regions | [`segment_remainder`] | — (ours) |
//! | segmentation quality (SegComp, Hoover et al. 1996) | [`evaluate`] | — |
//! | projection: early/late, orthogonal/along the beam; ALRF ±90° columns | [`projection`] | §5.3.2, App. A |
//! | α-shapes with the optimal α for one component (ours: a robust α, an α limit) | [`alpha_shape`] | Alg 6, L4839–4909 |
//! | convex hull | [`hull`] | survey, L4811 |
//! | naive range-image triangulation | [`grid_mesh`] | L4913–4915 |
//! | convex grid polygons (scanLine V1, V2) | [`scanline`] | Alg 7, Alg 8, L4911–5146 |
//! | chain-code outlines | [`chain_code`] | survey, L4831–4837 |
//! | Douglas–Peucker | [`simplify`] | §5.3.4, L5249–5353 |
//! | region → planar patch (projection, α-shape, DP) | [`polygonize`] | Ch.6 pipeline, L5341–5343 |
//! | spikyness, mesh statistics, outline fidelity | [`quality`] | L5148–5154 |
//! | trimesh growing (Alg 4 and 5) | [`trimesh_grow`] | L4484–4620 |
//! | spherical range-image grids, so unorganised scans' remainders are meshed too | [`spherical_grid`] | — (ours: the thesis's hybrid maps mesh organised scans only, §6.1) |
//! | outline merging across scans | [`merge`] | §5.1 |
//! | range denoising along the beams (trimesh, hybrid and point-cloud maps) | [`denoise`] | — (ours) |
//! | conservative outline offset | [`offset`] | — (ours) |
//! | holes of upward-facing patches filled, after merging | [`fill`] | — (ours) |
//! | slabs: a back face behind each planar patch, for maps | [`slab`] | — (ours) |
//! | free-space carving: points and veil triangles another scan saw through | [`visibility`] | — (ours) |
//! | all of it, timed per stage | [`pipeline`] | §5.3, §6.1 |
//!
//! Every parameter the thesis leaves open (segmentation thresholds, α rule details, DP ε,
//! θ_ang, θ_d, θ_s, merging tolerances) is a field of a config struct with named presets and
//! the choice documented where it is made. Bad input (empty clouds, degenerate regions, absurd
//! parameters) gives typed errors, never panics.
//!
//! Extraction produces `patch-core` patches and never names a map backend: any `patch-map`
//! backend takes its output.

pub mod alpha_shape;
pub mod chain_code;
pub mod denoise;
pub mod evaluate;
pub mod fill;
pub mod grid_mesh;
pub mod hull;
pub mod merge;
pub mod mixed_pixels;
pub mod offset;
pub mod pipeline;
pub mod plane_fit;
pub mod polygonize;
pub mod projection;
pub mod quality;
pub mod region;
pub mod scanline;
pub mod segment;
pub mod simplify;
pub mod slab;
pub mod spherical_grid;
pub mod trimesh_grow;
pub mod visibility;

pub use merge::{MergeConfig, merge_coplanar};
pub use mixed_pixels::{
    MixedPixelConfig, MixedPixelFix, fix_mixed_pixels, mixed_pixels, remove_mixed_pixels,
    snap_mixed_pixels,
};
pub use pipeline::{ExtractError, Extraction, PipelineConfig, extract, extract_with_threads};
pub use polygonize::{PolygonizeConfig, region_to_patch};
pub use region::{PlanarRegion, Segmentation};
pub use segment::{GrazingPlanes, SegmentConfig, segment, segment_remainder, segment_with_threads};
pub use spherical_grid::{SphericalGrid, SphericalGridConfig};
pub use trimesh_grow::{TrimeshGrowConfig, grow_trimeshes};
pub use visibility::{FreeSpace, VisibilityConfig};
