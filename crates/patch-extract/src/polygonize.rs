//! A planar region to planar patches in one call: the thesis's Ch. 6 pipeline
//! (L5341–5343, L6580–6582): early orthogonal projection → α-shape with the optimal α for
//! one component → Douglas–Peucker → polygon in the plane frame → [`PlanarPatch`] (with the
//! fit's covariance). The final Delaunay triangulation for triangle-mesh backends is
//! `patch_core::triangulate::triangulate_polygon`; [`triangle_count`] wraps it for statistics.
//!
//! # The patch frame
//! The frame is [`plane_frame`] of the region's plane and
//! centroid: z = the region's fitted normal (pointing toward the sensor), origin = the
//! centroid projected onto the plane, x = the world axis least aligned with the normal made
//! orthogonal to it (patch-core's `from_world_polygon` rule). So the patch's plane is exactly
//! the region's fitted plane.

use patch_core::triangulate::{TriangulationError, triangulate_polygon};
use patch_core::{PatchError, PlanarPatch, Polygon, Real};
use pointcloud::{Grid, INVALID_PIXEL, PointCloud};

use crate::PlanarRegion;
use crate::alpha_shape::{AlphaShapeConfig, AlphaShapeError, ComponentPolicy, alpha_shape_filled};
use crate::hull::{HullError, convex_hull_polygon};
use crate::offset::{OutlineOffset, grow_polygon};
use crate::projection::{
    ProjectionConfig, ProjectionError, ProjectionTiming, plane_frame, project_indices,
};
use crate::simplify::{SimplifyError, simplify_polygon, simplify_polygon_valid};

/// Which float-based ("indirect", early-projection) outliner to use.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum OutlineMethod {
    /// α-shape (thesis Alg. 6, the thesis's choice).
    AlphaShape(AlphaShapeConfig),
    /// Convex hull (coarse but fastest).
    ConvexHull,
}

/// Outline simplification.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Simplification {
    /// Keep the outline as found.
    None,
    /// Douglas–Peucker per ring with this ε (metres); an invalid result is an error
    /// ([`crate::simplify::simplify_polygon`]).
    DouglasPeucker {
        /// Tolerance, metres.
        epsilon: Real,
    },
    /// Douglas–Peucker per ring, falling back to smaller ε or the original when the result
    /// would be invalid ([`crate::simplify::simplify_polygon_valid`]).
    DouglasPeuckerValid {
        /// Tolerance, metres.
        epsilon: Real,
    },
}

/// Parameters of [`region_to_patch`]. No `Default`: start from a named constructor.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PolygonizeConfig {
    /// The projection; its timing must be [`ProjectionTiming::Early`] (the outliners here work
    /// on all projected points).
    pub projection: ProjectionConfig,
    /// The outliner.
    pub outline: OutlineMethod,
    /// The simplification.
    pub simplification: Simplification,
    /// A conservative outward offset of the simplified outline ([`crate::offset`]); `None`:
    /// the outline as found (the thesis).
    pub offset: Option<OutlineOffset>,
    /// For α-shape outlines of steep regions (normal more than 45° from the world's up, taken
    /// from the cloud's sensor pose: walls), the largest α, metres
    /// ([`AlphaShapeConfig::max_alpha`], every component kept); `None`: no limit. A wall seen
    /// sparsely, far along a corridor, otherwise gets an α of half a metre that closes its
    /// doorways. Floors and boards keep their α: seen at grazing incidence their rows lie
    /// further apart than any doorway's half-width.
    pub wall_max_alpha: Option<Real>,
    /// For α-shape outlines of regions of organised clouds: the points thinned on the pixel
    /// grid first ([`GridThinning`], not in the thesis); `None`: every point (the thesis).
    pub thinning: Option<GridThinning>,
}

/// A region of an organised cloud thinned on its pixel grid before its α-shape (not in the
/// thesis): the points of the pixels near the region's pixel outline are kept, and of the
/// pixels further inside only a sparse lattice, as fill points
/// ([`crate::alpha_shape::alpha_shape_filled`]: their triangles are interior and never decide
/// α). The α-shape's outline, and so its α, come from the points along the region's edges,
/// which the band keeps at full density; inside, the shape is solid either way (sampling holes
/// there are filled by the thesis's hole filter). The Delaunay triangulation, which dominates
/// the outline's cost, then grows with the outline's length rather than the region's area.
///
/// A pixel belongs to the band iff some pixel within `band` pixels along rows and columns
/// (Chebyshev distance) is outside the region or the grid; a fill pixel is any other region
/// pixel whose column and row are multiples of `stride`. With `stride ≤ band / 2` a fill
/// point's Delaunay triangles (circumradius about `stride` pixel spacings on a regular grid)
/// stay inside the region.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct GridThinning {
    /// Width of the band of pixels kept along the region's pixel outline, pixels (≥ 1).
    pub band: u32,
    /// Lattice spacing of the fill pixels inside the band, pixels (≥ 1).
    pub stride: u32,
    /// Regions with fewer points are not thinned.
    pub min_points: usize,
}

impl GridThinning {
    /// A band 6 pixels wide, fill points every 3 pixels, regions of at least 1,000 points:
    /// the region's points fall to the band along its outline and a ninth of the inside.
    /// Measured with `cargo xtask compare segmentation` (floor plan, 6 lab frames, Kinect
    /// office; outlines' time, polygon vertices): all points 0.35 s / 181 on the floor plan,
    /// 0.30–0.36 s / 849 on the Kinect frame; band 4, stride 2: 0.15 s / 182, 0.15 s / 936;
    /// band 6, stride 3: 0.09–0.11 s / 179, 0.11–0.13 s / 1206. True planes found, planes off
    /// truth and vertices on the surface did not change. On the Kinect frame the α-shapes are
    /// tighter (the thinned-out inner points, sparse where disparity steps spread them, no
    /// longer raise α), hence the extra vertices.
    pub fn standard() -> GridThinning {
        GridThinning { band: 6, stride: 3, min_points: 1000 }
    }

    /// The points of `region` (indices into a cloud with `grid`; `pixel_of` maps each point to
    /// its pixel) split into the band and the fill points, each in the region's order; `None`
    /// when the region is not thinned (too small, invalid parameters).
    ///
    /// # Complexity
    /// O(n + a) for n points whose pixels span a rectangle of a pixels.
    pub fn split(
        &self,
        grid: &Grid,
        pixel_of: &[u32],
        region: &[u32],
    ) -> Option<(Vec<u32>, Vec<u32>)> {
        if region.len() < self.min_points || self.band == 0 || self.stride == 0 {
            return None;
        }
        let w = grid.width() as usize;
        let pixel = |p: u32| pixel_of.get(p as usize).copied().filter(|&x| x != INVALID_PIXEL);
        let (mut c0, mut r0, mut c1, mut r1) = (usize::MAX, usize::MAX, 0, 0);
        for &p in region {
            let x = pixel(p)? as usize;
            let (c, r) = (x % w, x / w);
            (c0, r0, c1, r1) = (c0.min(c), r0.min(r), c1.max(c), r1.max(r));
        }
        // A local mask padded by `band` pixels (outside the region) on every side.
        let b = self.band as usize;
        let (lw, lh) = (c1 - c0 + 1 + 2 * b, r1 - r0 + 1 + 2 * b);
        let local = |x: u32| {
            let (c, r) = (x as usize % w, x as usize / w);
            (r - r0 + b) * lw + (c - c0 + b)
        };
        let mut inside = vec![false; lw * lh];
        for &p in region {
            inside[local(pixel(p)?)] = true;
        }
        // Per pixel: an outside pixel within `b` along its row, then within `b` of that along
        // its column (a Chebyshev ball is a square), from running counts.
        let mut near_row = vec![false; lw * lh];
        for r in 0..lh {
            let row = &inside[r * lw..(r + 1) * lw];
            let mut prefix = vec![0u32; lw + 1];
            for (c, &i) in row.iter().enumerate() {
                prefix[c + 1] = prefix[c] + u32::from(!i);
            }
            for c in 0..lw {
                let (lo, hi) = (c.saturating_sub(b), (c + b + 1).min(lw));
                near_row[r * lw + c] = prefix[hi] > prefix[lo];
            }
        }
        let mut near = vec![false; lw * lh];
        let mut prefix = vec![0u32; lh + 1];
        for c in 0..lw {
            for r in 0..lh {
                prefix[r + 1] = prefix[r] + u32::from(near_row[r * lw + c]);
            }
            for r in 0..lh {
                let (lo, hi) = (r.saturating_sub(b), (r + b + 1).min(lh));
                near[r * lw + c] = prefix[hi] > prefix[lo];
            }
        }
        let s = self.stride as usize;
        let (mut band, mut fill) = (Vec::new(), Vec::new());
        for &p in region {
            let x = pixel(p)?;
            if near[local(x)] {
                band.push(p);
            } else if (x as usize % w).is_multiple_of(s) && (x as usize / w).is_multiple_of(s) {
                fill.push(p);
            }
        }
        Some((band, fill))
    }
}

/// Per point of an organised cloud: its pixel (row-major index), [`INVALID_PIXEL`] for none.
pub fn pixels_of_points(grid: &Grid, num_points: usize) -> Vec<u32> {
    let mut pixel_of = vec![INVALID_PIXEL; num_points];
    for (pixel, &p) in grid.pixels().iter().enumerate() {
        if let Some(slot) = pixel_of.get_mut(p as usize) {
            *slot = pixel as u32;
        }
    }
    pixel_of
}

/// [`PolygonizeConfig::conservative`]'s largest α for walls, metres: openings wider than
/// 0.4 m stay open (doorways are 0.7 m and wider). Measured on the office (29 scans, scene
/// seed 0, step seed 1; unsafe / overcautious %): no limit: planes 1.16 / 1.91, hybrid
/// 1.09 / 2.25 (the doorways of walls seen far along the corridors closed); 0.3 m: hybrid
/// 1.09 / 2.05; 0.2 m: planes 1.17 / 1.60, hybrid 1.09 / 1.98. The same limit for every
/// region lost sparsely seen floor (hybrid 1.18 / 1.95). The lab's maps do not change.
pub const WALL_MAX_ALPHA: Real = 0.2;

/// The Douglas–Peucker ε of [`PolygonizeConfig::thesis`], metres. The thesis gives none; 2 cm
/// is about twice the range noise of the SICK S300 ALRF and the SR-3000 (σ ≈ 1 cm), so noise
/// wiggles go and corners of furniture-sized objects stay.
pub const THESIS_DP_EPSILON: Real = 0.02;

impl PolygonizeConfig {
    /// The thesis's pipeline: early orthogonal projection, α-shape with the optimal α for one
    /// component (largest component kept), Douglas–Peucker with
    /// ε = [`THESIS_DP_EPSILON`] = 2 cm in its validity-preserving form (our patches must be
    /// valid polygons; the thesis's CGAL pipeline did not check).
    pub fn thesis() -> PolygonizeConfig {
        PolygonizeConfig {
            projection: ProjectionConfig::thesis(),
            outline: OutlineMethod::AlphaShape(AlphaShapeConfig::thesis()),
            simplification: Simplification::DouglasPeuckerValid { epsilon: THESIS_DP_EPSILON },
            offset: None,
            wall_max_alpha: None,
            thinning: None,
        }
    }

    /// [`PolygonizeConfig::thesis`] with the regions of organised clouds thinned on the pixel
    /// grid first ([`GridThinning::standard`]): the same α-shape pipeline on the points along
    /// each region's pixel outline (the range-camera and structured-light presets). Unorganised
    /// clouds are outlined from all points.
    pub fn thinned() -> PolygonizeConfig {
        PolygonizeConfig { thinning: Some(GridThinning::standard()), ..PolygonizeConfig::thesis() }
    }

    /// [`PolygonizeConfig::thesis`] with outlines grown by [`OutlineOffset::alrf`], so patches
    /// cover the surface between and beyond their outermost points, the robust α
    /// ([`AlphaShapeConfig::robust`]), so a few stray points do not stretch them across gaps,
    /// and walls' α at most [`WALL_MAX_ALPHA`], so doorways stay open (none is in the thesis).
    pub fn conservative() -> PolygonizeConfig {
        PolygonizeConfig {
            outline: OutlineMethod::AlphaShape(AlphaShapeConfig::robust()),
            offset: Some(OutlineOffset::alrf()),
            wall_max_alpha: Some(WALL_MAX_ALPHA),
            ..PolygonizeConfig::thesis()
        }
    }

    /// The thesis's pipeline with a different Douglas–Peucker ε (e.g. 3 cm for noisier
    /// ALRF data).
    pub fn thesis_with_epsilon(epsilon: Real) -> PolygonizeConfig {
        PolygonizeConfig {
            simplification: Simplification::DouglasPeuckerValid { epsilon },
            ..PolygonizeConfig::thesis()
        }
    }

    /// Early orthogonal projection, convex hull, no simplification (a hull has few vertices).
    pub fn convex_hull() -> PolygonizeConfig {
        PolygonizeConfig {
            projection: ProjectionConfig::thesis(),
            outline: OutlineMethod::ConvexHull,
            simplification: Simplification::None,
            offset: None,
            wall_max_alpha: None,
            thinning: None,
        }
    }
}

/// Why a region gave no patch.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PolygonizeError {
    /// Late projection was requested; the outliners here need early projection.
    #[error("late projection needs a grid-based outliner; use early projection here")]
    LateProjection,
    /// Projection failed.
    #[error(transparent)]
    Projection(#[from] ProjectionError),
    /// The α-shape failed (degenerate points, bad α).
    #[error(transparent)]
    AlphaShape(#[from] AlphaShapeError),
    /// The hull failed (degenerate points).
    #[error(transparent)]
    Hull(#[from] HullError),
    /// Simplification failed.
    #[error(transparent)]
    Simplify(#[from] SimplifyError),
    /// The patch could not be built.
    #[error(transparent)]
    Patch(#[from] PatchError),
    /// An outline offset parameter is negative or not finite.
    #[error("outline offset parameters must be finite and ≥ 0")]
    BadOffset,
}

/// [`polygonize_region`]'s result: the patches and what happened on the way.
#[derive(Clone, Debug, PartialEq)]
pub struct Polygonized {
    /// The patches, largest first.
    pub patches: Vec<PlanarPatch>,
    /// The α used, when the outliner was an α-shape.
    pub alpha: Option<Real>,
    /// The number of α-shape components at that α (1 for the hull).
    pub num_components: usize,
    /// Points left out by the projection (grazing beams).
    pub dropped_points: usize,
    /// Outline vertex count (all patches, all rings) before simplification.
    pub vertices_before: usize,
    /// Outline vertex count after simplification.
    pub vertices_after: usize,
}

/// The region's patches with the pipeline's statistics; see the module docs.
///
/// # Errors
/// [`PolygonizeError::LateProjection`], or the first failing step's error.
///
/// # Complexity
/// O(n log n) in the region's point count (projection O(n), Delaunay triangulation and sorting
/// O(n log n)), plus simplification and polygon validation of the outline.
pub fn polygonize_region(
    cloud: &PointCloud,
    region: &PlanarRegion,
    config: &PolygonizeConfig,
) -> Result<Polygonized, PolygonizeError> {
    let pixel_of = match (config.thinning, cloud.grid()) {
        (Some(_), Some(grid)) => Some(pixels_of_points(grid, cloud.len())),
        _ => None,
    };
    polygonize_region_with(cloud, region, config, pixel_of.as_deref())
}

/// [`polygonize_region`] with the cloud's point-to-pixel table ([`pixels_of_points`]) when
/// [`PolygonizeConfig::thinning`] may need it (so the regions of one cloud share it).
///
/// # Errors
/// As [`polygonize_region`].
pub fn polygonize_region_with(
    cloud: &PointCloud,
    region: &PlanarRegion,
    config: &PolygonizeConfig,
    pixel_of: Option<&[u32]>,
) -> Result<Polygonized, PolygonizeError> {
    if config.projection.timing != ProjectionTiming::Early {
        return Err(PolygonizeError::LateProjection);
    }
    let frame = plane_frame(&region.plane, &region.centroid);
    let thinned = match (&config.outline, config.thinning, cloud.grid(), pixel_of) {
        (OutlineMethod::AlphaShape(_), Some(t), Some(grid), Some(pixel_of)) => {
            t.split(grid, pixel_of, &region.points)
        }
        _ => None,
    };
    let (projected, fill) = match &thinned {
        Some((band, fill)) => (
            project_indices(cloud, &region.plane, &frame, band, &config.projection)?,
            project_indices(cloud, &region.plane, &frame, fill, &config.projection)?,
        ),
        None => (
            project_indices(cloud, &region.plane, &frame, &region.points, &config.projection)?,
            project_indices(cloud, &region.plane, &frame, &[], &config.projection)?,
        ),
    };
    // The points the outline stands for (the thinned-out ones included).
    let num_points = region.points.len() - projected.dropped - fill.dropped;
    let (polygons, alpha, num_components) = match &config.outline {
        OutlineMethod::AlphaShape(c) => {
            let up = crate::segment::up(cloud);
            let steep = region.plane.normal.dot(&up).abs() < std::f64::consts::FRAC_1_SQRT_2;
            let c = match config.wall_max_alpha {
                Some(m) if steep => {
                    AlphaShapeConfig { max_alpha: Some(m), components: ComponentPolicy::All, ..*c }
                }
                _ => *c,
            };
            let shape = alpha_shape_filled(&projected.points, &fill.points, &c)?;
            (shape.polygons, Some(shape.alpha), shape.num_components)
        }
        OutlineMethod::ConvexHull => (vec![convex_hull_polygon(&projected.points)?], None, 1),
    };
    let vertices_before = polygons.iter().map(Polygon::num_vertices).sum();
    let simplified: Vec<Polygon> = polygons
        .into_iter()
        .map(|p| match config.simplification {
            Simplification::None => Ok(p),
            Simplification::DouglasPeucker { epsilon } => simplify_polygon(&p, epsilon),
            Simplification::DouglasPeuckerValid { epsilon } => {
                simplify_polygon_valid(&p, epsilon).map(|s| s.polygon)
            }
        })
        .collect::<Result<_, _>>()?;
    let simplified: Vec<Polygon> = match config.offset {
        Some(offset) if offset.is_valid() => simplified
            .into_iter()
            .map(|p| {
                let d = offset.distance(p.area(), num_points, region.mse);
                grow_polygon(&p, d).unwrap_or(p)
            })
            .collect(),
        Some(_) => return Err(PolygonizeError::BadOffset),
        None => simplified,
    };
    let vertices_after = simplified.iter().map(Polygon::num_vertices).sum();
    let mut patches = Vec::with_capacity(simplified.len());
    for polygon in simplified {
        let mut patch = PlanarPatch::new(polygon, projected.world_from_plane)?;
        if let Some(cov) = region.covariance {
            patch = patch.with_covariance(cov);
        }
        patches.push(patch);
    }
    patches.sort_by(|a, b| b.area().total_cmp(&a.area()));
    Ok(Polygonized {
        patches,
        alpha,
        num_components,
        dropped_points: projected.dropped + fill.dropped,
        vertices_before,
        vertices_after,
    })
}

/// A planar region of `cloud` as planar patches (one with the thesis's configuration; several
/// only with [`crate::alpha_shape::ComponentPolicy::All`] and a given α).
///
/// # Errors
/// As [`polygonize_region`].
pub fn region_to_patch(
    cloud: &PointCloud,
    region: &PlanarRegion,
    config: &PolygonizeConfig,
) -> Result<Vec<PlanarPatch>, PolygonizeError> {
    Ok(polygonize_region(cloud, region, config)?.patches)
}

/// The number of triangles of the constrained Delaunay triangulation of the patch's polygon
/// (the thesis's last step, for Bullet; L5341–5343).
///
/// # Errors
/// As `triangulate_polygon` (not expected for a valid polygon).
pub fn triangle_count(patch: &PlanarPatch) -> Result<usize, TriangulationError> {
    let rings: Vec<Vec<[f64; 2]>> =
        patch.polygon().rings().map(|r| r.points().iter().map(|p| [p.x, p.y]).collect()).collect();
    Ok(triangulate_polygon(&rings)?.triangles.len())
}
