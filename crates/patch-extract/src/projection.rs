//! Projecting a planar region's points into its plane (thesis §5.3.2, L4622–4752).
//!
//! A region's points scatter around the fitted plane; outlining works in 2D, so the points (or
//! an outline's vertices) are moved into the plane and expressed in a 2D frame on it. Two
//! independent choices (spec §2.2):
//!
//! * **When** ([`ProjectionTiming`]): *early* projects every point and outlines in 2D floats
//!   (α-shapes, convex hull: [`crate::alpha_shape`], [`crate::hull`]); *late* outlines on the
//!   pixel grid first and projects only the outline's vertices (the grid methods). Both call the
//!   same functions here ([`project_region`] for all points, [`project_indices`] for any subset
//!   in a given order, such as an outline's vertices).
//! * **How** ([`ProjectionMethod`]): *orthogonally* onto the plane, or *along the beam*: the
//!   sensor ray through the point, intersected with the plane. The sensor sits at the origin of
//!   the cloud's frame (clouds are in the sensor frame; [`pointcloud::PointCloud::to_world`]
//!   clouds lose that property, so project before moving a cloud to the world).
//!
//! The thesis concludes that **early orthogonal projection is the only problem-free choice**
//! (L4750–4752): orthogonal projection can reorder points, which with late projection makes
//! outlines self-intersect; projection along the beam blows regions up at grazing angles,
//! because the plane fit is orthogonal. [`ProjectionConfig::thesis`] is that choice.
//!
//! # Rays nearly parallel to the plane
//! Along the beam, a ray whose angle with the plane is tiny meets it far away (or never, or
//! behind the sensor). A ray is *grazing* when `|cos(ray, normal)| < min_beam_cos`, and
//! *backward* when the intersection lies behind the sensor (`t ≤ 0`). [`GrazingPolicy`] says
//! whether such a point is an error ([`ProjectionError::GrazingBeam`],
//! [`ProjectionError::PlaneBehindSensor`]) or is dropped (and counted).
//!
//! # The actuated-LRF fix (thesis App. A, L7710–7716)
//! Beams at ±90° lie on the ALRF's pitch axis and see the same line in every row, so the
//! column holding them folds late-projected outlines onto themselves (Fig. 5.5).
//! [`invalidate_alrf_side_columns`] invalidates that column before segmentation (optionally
//! keeping its centre pixel, as the thesis allows).

use patch_core::{Isometry3, Plane, Point2, Point3, Real, Vector3};
use pointcloud::{ActuatedLrfModel, PointCloud};

use crate::PlanarRegion;

/// When the points are projected relative to outlining (thesis L4634–4646).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum ProjectionTiming {
    /// Project all points, then outline in 2D floats (α-shape, hull). The thesis's choice.
    Early,
    /// Outline on the pixel grid, then project only the outline's vertices (grid methods).
    Late,
}

/// How a point is moved into the plane.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum ProjectionMethod {
    /// The foot of the perpendicular from the point to the plane. The thesis's choice.
    Orthogonal,
    /// The intersection of the sensor ray (from the cloud frame's origin through the point)
    /// with the plane.
    AlongBeam,
}

/// What to do with a point whose beam cannot be intersected with the plane usefully.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum GrazingPolicy {
    /// Fail with [`ProjectionError::GrazingBeam`] or [`ProjectionError::PlaneBehindSensor`].
    Error,
    /// Leave the point out and count it in [`Projected::dropped`].
    Drop,
}

/// How to project. No `Default`: start from [`ProjectionConfig::thesis`].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ProjectionConfig {
    /// Early or late (informational for the callers that choose the outline method; the
    /// functions here project whatever indices they are given).
    pub timing: ProjectionTiming,
    /// Orthogonal or along the beam.
    pub method: ProjectionMethod,
    /// Along the beam: the smallest `|cos|` of the angle between the ray and the plane normal
    /// that is still intersected (`0.05` ≈ rays within 2.9° of the plane are grazing).
    pub min_beam_cos: Real,
    /// Along the beam: what to do with grazing or backward rays.
    pub grazing: GrazingPolicy,
}

impl ProjectionConfig {
    /// Early orthogonal projection, the thesis's conclusion (L4750–4752). The beam fields are
    /// unused by it (set to `min_beam_cos = 0.05`, [`GrazingPolicy::Drop`]).
    pub fn thesis() -> ProjectionConfig {
        ProjectionConfig {
            timing: ProjectionTiming::Early,
            method: ProjectionMethod::Orthogonal,
            min_beam_cos: 0.05,
            grazing: GrazingPolicy::Drop,
        }
    }

    /// Early projection along the beam, dropping grazing rays (`|cos| < 0.05`).
    pub fn early_along_beam() -> ProjectionConfig {
        ProjectionConfig { method: ProjectionMethod::AlongBeam, ..ProjectionConfig::thesis() }
    }

    /// Late orthogonal projection (for grid-based outlines).
    pub fn late_orthogonal() -> ProjectionConfig {
        ProjectionConfig { timing: ProjectionTiming::Late, ..ProjectionConfig::thesis() }
    }
}

/// Why points could not be projected.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ProjectionError {
    /// A point index is not in the cloud.
    #[error("point index {index} is out of range for a cloud of {len} points")]
    IndexOutOfRange {
        /// The index.
        index: u32,
        /// The cloud's size.
        len: usize,
    },
    /// The plane is not finite or its normal is not unit length.
    #[error("the plane is invalid (non-finite or non-unit normal)")]
    InvalidPlane,
    /// Along the beam: the ray through this point is nearly parallel to the plane.
    #[error("the beam through point {index} is within the grazing limit (|cos| = {cos:.3e})")]
    GrazingBeam {
        /// The point index.
        index: u32,
        /// `|cos|` of the angle between the ray and the normal.
        cos: Real,
    },
    /// Along the beam: the ray through this point meets the plane behind the sensor (or the
    /// point is the sensor origin).
    #[error("the beam through point {index} meets the plane behind the sensor")]
    PlaneBehindSensor {
        /// The point index.
        index: u32,
    },
    /// The ALRF fix needs an organised cloud.
    #[error("the cloud has no pixel grid")]
    NotOrganised,
    /// `min_beam_cos` or the ALRF column tolerance is not finite and non-negative.
    #[error("invalid parameter {name} = {value}")]
    InvalidParameter {
        /// The parameter.
        name: &'static str,
        /// Its value.
        value: Real,
    },
}

/// Points projected into a plane frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Projected {
    /// The frame: its xy-plane is the plane, z its normal.
    pub world_from_plane: Isometry3,
    /// The projected points in the frame, in the order of [`Projected::indices`].
    pub points: Vec<Point2>,
    /// The cloud index of each projected point.
    pub indices: Vec<u32>,
    /// How many points [`GrazingPolicy::Drop`] left out.
    pub dropped: usize,
}

fn plane_is_valid(plane: &Plane) -> bool {
    let n = plane.normal.into_inner();
    n.iter().all(|c| c.is_finite())
        && plane.offset.is_finite()
        && (n.norm_squared() - 1.0).abs() < 1e-9
}

/// The patch frame of a plane: origin = `anchor` projected orthogonally onto the plane,
/// z = the plane normal, x = the world axis least aligned with the normal (first of x, y, z on
/// ties) made orthogonal to it, y = z × x.
///
/// This is [`patch_core::plane_frame`], the rule of every patch built from world coordinates,
/// so patches made by [`crate::polygonize`] have the same frames. With `anchor` = the region
/// centroid the origin is the centroid of the orthogonally projected points.
pub fn plane_frame(plane: &Plane, anchor: &Point3) -> Isometry3 {
    let normal: Vector3 = plane.normal.into_inner();
    let origin = anchor - normal * plane.signed_distance(anchor);
    patch_core::plane_frame(&normal, &origin)
}

/// Orthogonal projection of `p` into the frame's xy-plane (drops the frame z).
pub fn project_orthogonal(world_from_plane: &Isometry3, p: &Point3) -> Point2 {
    let q = world_from_plane.inverse_transform_point(p);
    Point2::new(q.x, q.y)
}

/// The intersection of the ray from the origin through `p` with `plane`, as a 3D point, or
/// why there is none: `Err(Some(cos))` for a grazing ray (`|cos| < min_beam_cos`), `Err(None)`
/// when the plane lies behind the sensor along the ray (or `p` is the origin).
pub fn beam_plane_intersection(
    plane: &Plane,
    p: &Point3,
    min_beam_cos: Real,
) -> Result<Point3, Option<Real>> {
    let len = p.coords.norm();
    if len == 0.0 || !len.is_finite() {
        return Err(None);
    }
    let dir = p.coords / len;
    let cos = plane.normal.dot(&dir);
    if cos.abs() < min_beam_cos || cos == 0.0 {
        return Err(Some(cos.abs()));
    }
    let t = plane.offset / cos;
    if t <= 0.0 || !t.is_finite() {
        return Err(None);
    }
    Ok(Point3::from(dir * t))
}

/// Projects the cloud points `indices` (in that order) into the frame `world_from_plane` on
/// `plane`. Early projection passes all of a region's points, late projection only an
/// outline's vertices.
///
/// # Errors
/// [`ProjectionError::IndexOutOfRange`], [`ProjectionError::InvalidPlane`],
/// [`ProjectionError::InvalidParameter`]; along the beam with [`GrazingPolicy::Error`] also
/// [`ProjectionError::GrazingBeam`] and [`ProjectionError::PlaneBehindSensor`].
///
/// # Complexity
/// O(n) for n indices.
pub fn project_indices(
    cloud: &PointCloud,
    plane: &Plane,
    world_from_plane: &Isometry3,
    indices: &[u32],
    config: &ProjectionConfig,
) -> Result<Projected, ProjectionError> {
    if !plane_is_valid(plane) {
        return Err(ProjectionError::InvalidPlane);
    }
    if !(config.min_beam_cos.is_finite() && config.min_beam_cos >= 0.0) {
        return Err(ProjectionError::InvalidParameter {
            name: "min_beam_cos",
            value: config.min_beam_cos,
        });
    }
    let positions = cloud.positions();
    let mut points = Vec::with_capacity(indices.len());
    let mut kept = Vec::with_capacity(indices.len());
    let mut dropped = 0;
    for &index in indices {
        let p = positions
            .get(index as usize)
            .ok_or(ProjectionError::IndexOutOfRange { index, len: positions.len() })?;
        let on_plane = match config.method {
            ProjectionMethod::Orthogonal => *p,
            ProjectionMethod::AlongBeam => {
                match beam_plane_intersection(plane, p, config.min_beam_cos) {
                    Ok(q) => q,
                    Err(why) => match config.grazing {
                        GrazingPolicy::Drop => {
                            dropped += 1;
                            continue;
                        }
                        GrazingPolicy::Error => {
                            return Err(match why {
                                Some(cos) => ProjectionError::GrazingBeam { index, cos },
                                None => ProjectionError::PlaneBehindSensor { index },
                            });
                        }
                    },
                }
            }
        };
        points.push(project_orthogonal(world_from_plane, &on_plane));
        kept.push(index);
    }
    Ok(Projected { world_from_plane: *world_from_plane, points, indices: kept, dropped })
}

/// Early projection of a whole region: all its points, into the frame
/// [`plane_frame`]`(&region.plane, &region.centroid)`.
///
/// # Errors
/// As [`project_indices`].
pub fn project_region(
    cloud: &PointCloud,
    region: &PlanarRegion,
    config: &ProjectionConfig,
) -> Result<Projected, ProjectionError> {
    let frame = plane_frame(&region.plane, &region.centroid);
    project_indices(cloud, &region.plane, &frame, &region.points, config)
}

/// Which pixels of an actuated-LRF scan [`invalidate_alrf_side_columns`] removes.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct AlrfSideColumns {
    /// A column is removed when its beam angle is within this many radians of ±90°. `None` =
    /// half the column spacing, i.e. the column(s) nearest to ±90°.
    pub tolerance: Option<Real>,
    /// Keep the pixel of the removed column in the row whose pitch is nearest to 0 (the
    /// thesis's "possible exception of the central pixel").
    pub keep_centre_pixel: bool,
}

impl AlrfSideColumns {
    /// The thesis's fix: the ±90° column(s), centre pixel kept.
    pub fn thesis() -> AlrfSideColumns {
        AlrfSideColumns { tolerance: None, keep_centre_pixel: true }
    }
}

/// The thesis's ALRF fix (App. A, L7710–7716): a copy of the organised `cloud` (made by an
/// actuated LRF with beam model `model`) with the ±90° column(s) invalidated, and the number of
/// points removed. All attributes follow the points; **point indices change**, so run this
/// before segmentation.
///
/// # Errors
/// [`ProjectionError::NotOrganised`] without a pixel grid;
/// [`ProjectionError::InvalidParameter`] for a negative or non-finite tolerance.
pub fn invalidate_alrf_side_columns(
    cloud: &PointCloud,
    model: &ActuatedLrfModel,
    which: &AlrfSideColumns,
) -> Result<(PointCloud, usize), ProjectionError> {
    let grid = cloud.grid().ok_or(ProjectionError::NotOrganised)?;
    let (w, h) = (grid.width(), grid.height());
    let lerp = |start: Real, end: Real, i: u32, n: u32| {
        if n <= 1 { start } else { start + (end - start) * i as Real / (n - 1) as Real }
    };
    let spacing =
        if w <= 1 { 0.0 } else { (model.beam_end - model.beam_start).abs() / (w - 1) as Real };
    let tolerance = which.tolerance.unwrap_or(0.5 * spacing + 1e-12);
    if !(tolerance.is_finite() && tolerance >= 0.0) {
        return Err(ProjectionError::InvalidParameter { name: "tolerance", value: tolerance });
    }
    let half_pi = std::f64::consts::FRAC_PI_2;
    let centre_row = (0..h)
        .min_by(|&a, &b| {
            let pa = lerp(model.pitch_top, model.pitch_bottom, a, h).abs();
            let pb = lerp(model.pitch_top, model.pitch_bottom, b, h).abs();
            pa.total_cmp(&pb)
        })
        .unwrap_or(0);
    let mut remove = vec![false; cloud.len()];
    let mut removed = 0;
    for col in 0..w {
        let theta = lerp(model.beam_start, model.beam_end, col, w);
        if (theta.abs() - half_pi).abs() > tolerance {
            continue;
        }
        for row in 0..h {
            if which.keep_centre_pixel && row == centre_row {
                continue;
            }
            if let Some(i) = grid.point_index(col, row) {
                remove[i] = true;
                removed += 1;
            }
        }
    }
    Ok((cloud.retain_indices(|i| !remove[i]), removed))
}
