//! A planar region to planar patches in one call: the thesis's Ch. 6 pipeline
//! (L5341–5343, L6580–6582): early orthogonal projection → α-shape with the optimal α for
//! one component → Douglas–Peucker → polygon in the plane frame → [`PlanarPatch`] (with the
//! fit's covariance). The final Delaunay triangulation for triangle-mesh backends is
//! `patch_core::triangulate::triangulate_polygon`; [`triangle_count`] wraps it for statistics.
//!
//! # The patch frame
//! The frame is [`plane_frame`](crate::projection::plane_frame) of the region's plane and
//! centroid: z = the region's fitted normal (pointing toward the sensor), origin = the
//! centroid projected onto the plane, x = the world axis least aligned with the normal made
//! orthogonal to it (patch-core's `from_world_polygon` rule). So the patch's plane is exactly
//! the region's fitted plane.

use patch_core::triangulate::{TriangulationError, triangulate_polygon};
use patch_core::{PatchError, PlanarPatch, Polygon, Real};
use pointcloud::PointCloud;

use crate::PlanarRegion;
use crate::alpha_shape::{AlphaShapeConfig, AlphaShapeError, ComponentPolicy, alpha_shape};
use crate::hull::{HullError, convex_hull_polygon};
use crate::offset::{OutlineOffset, grow_polygon};
use crate::projection::{ProjectionConfig, ProjectionError, ProjectionTiming, project_region};
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
        }
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
    if config.projection.timing != ProjectionTiming::Early {
        return Err(PolygonizeError::LateProjection);
    }
    let projected = project_region(cloud, region, &config.projection)?;
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
            let shape = alpha_shape(&projected.points, &c)?;
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
                let d = offset.distance(p.area(), projected.points.len(), region.mse);
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
        dropped_points: projected.dropped,
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
