//! Trimesh growing on organised clouds (thesis §5.3.1: Alg 4 L4513–4580, Alg 5 L4582–4620,
//! prose L4484–4498).
//!
//! The grid induces a triangulation: each 2×2 pixel quad with top-left pixel `(c, r)` holds the
//! triangles `T₀ = ((c,r),(c,r+1),(c+1,r))` (the seed triangle of Alg 4, line 11) and
//! `T₁ = ((c+1,r),(c,r+1),(c+1,r+1))`; a triangle exists when its three pixels are input pixels
//! (valid and in the mask). Two triangles are neighbours (`N(T)`) when they share an edge.
//!
//! * **Phase 1** (Alg 4). Per input pixel, over the input pixels of its 3×3 neighbourhood:
//!   `p_c` = their mean, `A = Σ (p_c − p)(p_c − p)ᵀ`, `n` = the eigenvector of `A`'s smallest
//!   eigenvalue, `d = n · p_c`, flipped so that `d ≥ 0` (at least 3 points are needed; pixels
//!   with fewer have no plane, and their triangles are not growable). A triangle is *growable*
//!   iff over its vertex pairs the largest normal angle is below `θ_ang` and the largest `|Δd|`
//!   below `θ_d`. From every quad, in raster order, a breadth-first search starting at its `T₀`
//!   and then at its `T₁` (both triangles seed, as the spec recommends) collects unused
//!   growable triangles; each search gives one mesh, empty ones are skipped.
//! * **Phase 2** (Alg 5). The same search over the triangles phase 1 did not use, accepting a
//!   triangle iff both of its pixel-axis-aligned sides are shorter than `θ_s` metres.
//!
//! The thesis gives no values for `θ_ang`, `θ_d`, `θ_s`; [`TrimeshGrowConfig`]'s named
//! constructors document the ones chosen here. Additions of this implementation: meshes with
//! fewer than `min_triangles` triangles are dropped (phase-1 ones are released to phase 2
//! first), triangles that are degenerate in 3D are never accepted (a [`TrimeshPatch`] refuses
//! them), and meshes above `max_triangles` are cut into consecutive runs of their
//! breadth-first order (spatially compact pieces; the thesis's Lab dataset averaged about 324
//! triangles per trimesh patch), and optionally side limits that grow with range
//! ([`TrimeshGrowConfig::side_per_range`]).
//!
//! `d ≥ 0` orients normals towards the origin, so run this on clouds in the sensor frame (as
//! scanned), where the origin is the sensor.
//!
//! # Complexity
//! `O(w · h)` for the planes and the triangles; the searches revisit rejected triangles at most
//! once per neighbouring accepted triangle.

use std::collections::VecDeque;

use crate::grid_mesh::{GridError, RegionMask};
use crate::quality::MeshStats;
use patch_core::geometry::TriangleFrame;
use patch_core::{MIN_TRIANGLE_AREA, Point3, Real, TrimeshPatch, Vector3, na};
use pointcloud::PointCloud;

/// Why trimesh growing refused its input.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TrimeshGrowError {
    /// A threshold is not a positive finite number (or an angle is above π).
    #[error("threshold {name} = {value} must be positive and finite{}", if *name == "max_normal_angle" { " and at most π" } else { "" })]
    BadThreshold {
        /// The parameter name.
        name: &'static str,
        /// Its value.
        value: Real,
    },
    /// The triangle limits are inconsistent (`1 ≤ min_triangles ≤ max_triangles` is needed).
    #[error("triangle limits min {min} / max {max}: need 1 ≤ min ≤ max")]
    TriangleLimits {
        /// `min_triangles`.
        min: usize,
        /// `max_triangles`.
        max: usize,
    },
    /// The cloud or mask does not fit.
    #[error(transparent)]
    Grid(#[from] GridError),
}

/// Parameters of trimesh growing. No `Default`: start from a named constructor.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct TrimeshGrowConfig {
    /// `θ_ang`: largest angle between the per-pixel normals of a growable triangle, radians.
    pub max_normal_angle: Real,
    /// `θ_d`: largest difference of the per-pixel plane offsets of a growable triangle, metres.
    pub max_offset_diff: Real,
    /// `θ_s`: phase 2 accepts a triangle iff both pixel-axis-aligned sides are shorter, metres.
    pub max_side: Real,
    /// Addition to Alg 4: when set, phase 1 also rejects triangles with a pixel-axis-aligned
    /// side of at least this length, metres. At a depth jump the 3×3 neighbourhoods of the
    /// pixels on both sides contain points of both surfaces, so their fitted planes agree and
    /// Alg 4 alone would bridge the jump. `None` is Alg 4 as printed.
    pub phase1_max_side: Option<Real>,
    /// Addition for sparse scans (spinning lidars, whose neighbouring beams are `r · Δ`
    /// apart): when set to `k`, both side limits (`θ_s` and `phase1_max_side`) are multiplied
    /// by `max(1, k · r / θ_s)`, `r` the distance of the side's nearer end from the origin
    /// (the sensor, for clouds in the sensor frame): phase 2 accepts a side below
    /// `max(θ_s, k · r)`. `None` (the named constructors) keeps the fixed limits.
    /// [`crate::spherical_grid::SphericalGridConfig::max_side_steps`] sets it from the grid's
    /// angular step for unorganised scans.
    pub side_per_range: Option<Real>,
    /// Addition against veils (PCL's shadow-point test, on triangles): when set, a triangle
    /// whose plane makes less than this angle with the beam to its centroid, radians, is
    /// not grown. A triangle that bridges a depth jump contains its beams and is seen
    /// edge-on; a real surface is seen at that angle only far away or at grazing incidence.
    /// The sensor sits at the cloud's origin (clouds in the sensor frame). `None` (the named
    /// constructors) grows triangles at any angle, as Alg 4/5. On the lab's trimesh map
    /// (8 ALRF scans, held out) 5° trades unsafe 0.43 → 0.77 % for overcautious 4.27 →
    /// 3.26 %, 10° gives 3.34 / 2.61 %: real surfaces seen at grazing angles (board
    /// undersides) go with the veils (`docs/map-safety.md`, item 13).
    pub min_view_angle: Option<Real>,
    /// Meshes with fewer triangles are dropped.
    pub min_triangles: usize,
    /// Meshes with more triangles are cut into pieces of at most this many.
    pub max_triangles: usize,
}

impl TrimeshGrowConfig {
    /// A validated configuration (with fixed side limits: `side_per_range` `None`).
    ///
    /// # Errors
    /// [`TrimeshGrowError::BadThreshold`], [`TrimeshGrowError::TriangleLimits`].
    pub fn new(
        max_normal_angle: Real,
        max_offset_diff: Real,
        max_side: Real,
        phase1_max_side: Option<Real>,
        min_triangles: usize,
        max_triangles: usize,
    ) -> Result<TrimeshGrowConfig, TrimeshGrowError> {
        let config = TrimeshGrowConfig {
            max_normal_angle,
            max_offset_diff,
            max_side,
            phase1_max_side,
            side_per_range: None,
            min_view_angle: None,
            min_triangles,
            max_triangles,
        };
        config.validate()?;
        Ok(config)
    }

    /// Checks the fields (for configurations built as struct literals).
    ///
    /// # Errors
    /// As [`TrimeshGrowConfig::new`].
    pub fn validate(&self) -> Result<(), TrimeshGrowError> {
        let checks = [
            ("max_normal_angle", self.max_normal_angle),
            ("max_offset_diff", self.max_offset_diff),
            ("max_side", self.max_side),
            ("phase1_max_side", self.phase1_max_side.unwrap_or(1.0)),
            ("side_per_range", self.side_per_range.unwrap_or(1.0)),
            ("min_view_angle", self.min_view_angle.unwrap_or(1.0)),
        ];
        for (name, value) in checks {
            let too_big = (name == "max_normal_angle" && value > std::f64::consts::PI)
                || (name == "min_view_angle" && value >= std::f64::consts::FRAC_PI_2);
            if !(value.is_finite() && value > 0.0) || too_big {
                return Err(TrimeshGrowError::BadThreshold { name, value });
            }
        }
        if self.min_triangles == 0 || self.min_triangles > self.max_triangles {
            return Err(TrimeshGrowError::TriangleLimits {
                min: self.min_triangles,
                max: self.max_triangles,
            });
        }
        Ok(())
    }

    /// For range cameras (SwissRanger SR-3000, σ = 1 cm at 0.6–7.5 m, about 0.27° per pixel):
    /// `θ_ang = 30°`, `θ_d = 0.30 m`, `θ_s = 0.10 m`, phase-1 sides below 0.20 m, at least 4
    /// and at most 1000 triangles.
    ///
    /// Normals from 3×3 neighbourhoods a few centimetres across are noisy at σ = 1 cm, and `d`
    /// moves by range × normal error (3 m × 0.1 rad = 0.3 m), so `θ_d` is the binding
    /// threshold: on a simulated floor seen at 2–5 m, `θ_d` = 0.1 m fragments the floor into
    /// meshes of a few hundred triangles, 0.3 m grows one mesh of ~16,000 of its ~21,000
    /// triangles. `θ_s` is a few pixel spacings at 4 m, so phase 2 bridges small gaps but not
    /// depth jumps.
    pub fn range_camera() -> TrimeshGrowConfig {
        TrimeshGrowConfig {
            max_normal_angle: 30f64.to_radians(),
            max_offset_diff: 0.30,
            max_side: 0.10,
            phase1_max_side: Some(0.20),
            side_per_range: None,
            min_view_angle: None,
            min_triangles: 4,
            max_triangles: 1000,
        }
    }

    /// For actuated laser range finders (SICK S300, σ = 3 cm, 0.5°–1° steps, 0–20 m):
    /// `θ_ang = 35°`, `θ_d = 0.50 m`, `θ_s = 0.30 m`, phase-1 sides below 0.60 m, at least 4
    /// and at most 1000 triangles.
    ///
    /// The range noise is three times the camera's and the beams are sparser, so all three
    /// thresholds are wider (0.3 m is the pixel spacing at about 17 m with 1° steps).
    pub fn alrf() -> TrimeshGrowConfig {
        TrimeshGrowConfig {
            max_normal_angle: 35f64.to_radians(),
            max_offset_diff: 0.50,
            max_side: 0.30,
            phase1_max_side: Some(0.60),
            side_per_range: None,
            min_view_angle: None,
            min_triangles: 4,
            max_triangles: 1000,
        }
    }
}

/// Which phase grew a mesh.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum GrowPhase {
    /// Alg 4: similar per-pixel planes.
    Similarity,
    /// Alg 5: short sides.
    Proximity,
}

/// One grown mesh (or a piece of one cut at `max_triangles`).
#[derive(Clone, Debug, PartialEq)]
pub struct GrownMesh {
    /// The mesh on the cloud's points.
    pub patch: TrimeshPatch,
    /// The phase that grew it.
    pub phase: GrowPhase,
}

/// The result of [`grow_trimeshes`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GrownTrimeshes {
    /// The meshes, phase 1 first, each in seed order.
    pub meshes: Vec<GrownMesh>,
    /// Triangles and spikyness over all meshes; `polygons` = the number of meshes.
    pub stats: MeshStats,
    /// Input pixels whose neighbourhood had fewer than 3 points (no plane).
    pub pixels_without_plane: usize,
}

impl GrownTrimeshes {
    /// The patches alone.
    pub fn into_patches(self) -> Vec<TrimeshPatch> {
        self.meshes.into_iter().map(|m| m.patch).collect()
    }
}

/// Grows trimeshes over every valid pixel of the organised cloud.
///
/// # Errors
/// [`TrimeshGrowError`] for a bad configuration or an unorganised cloud.
pub fn grow_trimeshes(
    cloud: &PointCloud,
    config: &TrimeshGrowConfig,
) -> Result<GrownTrimeshes, TrimeshGrowError> {
    let grid = cloud.grid().ok_or(GridError::NoGrid)?;
    grow_trimeshes_in(cloud, &RegionMask::all_valid(grid), config)
}

/// Grows trimeshes over the valid pixels of `mask`, e.g. the remainder of a plane segmentation
/// ([`RegionMask::from_points`]) for hybrid maps.
///
/// # Errors
/// [`TrimeshGrowError`] for a bad configuration, an unorganised cloud or a mask of the wrong
/// size.
pub fn grow_trimeshes_in(
    cloud: &PointCloud,
    mask: &RegionMask,
    config: &TrimeshGrowConfig,
) -> Result<GrownTrimeshes, TrimeshGrowError> {
    config.validate()?;
    let grid = cloud.grid().ok_or(GridError::NoGrid)?;
    let region = mask.restricted_to(grid)?;
    let (w, h) = (grid.width() as usize, grid.height() as usize);
    let positions = cloud.positions();
    let point_at = |c: usize, r: usize| -> Option<Point3> {
        if region.flags()[r * w + c] {
            grid.point_index(c as u32, r as u32).map(|i| positions[i])
        } else {
            None
        }
    };

    // Phase 1 planes.
    let mut planes: Vec<Option<(Vector3, Real)>> = vec![None; w * h];
    let mut pixels_without_plane = 0;
    for r in 0..h {
        for c in 0..w {
            if !region.flags()[r * w + c] {
                continue;
            }
            let mut pts = [Point3::origin(); 9];
            let mut k = 0;
            for rr in r.saturating_sub(1)..(r + 2).min(h) {
                for cc in c.saturating_sub(1)..(c + 2).min(w) {
                    if let Some(p) = point_at(cc, rr) {
                        pts[k] = p;
                        k += 1;
                    }
                }
            }
            planes[r * w + c] = local_plane(&pts[..k]);
            if planes[r * w + c].is_none() {
                pixels_without_plane += 1;
            }
        }
    }

    if w < 2 || h < 2 {
        return Ok(GrownTrimeshes { pixels_without_plane, ..GrownTrimeshes::default() });
    }
    let qw = w - 1;
    let num_tris = 2 * qw * (h - 1);
    let tri_pixels = |t: usize| -> [(usize, usize); 3] {
        let (q, k) = (t / 2, t % 2);
        let (c, r) = (q % qw, q / qw);
        if k == 0 {
            [(c, r), (c, r + 1), (c + 1, r)]
        } else {
            [(c + 1, r), (c, r + 1), (c + 1, r + 1)]
        }
    };
    let tri_points = |t: usize| -> Option<[Point3; 3]> {
        let [a, b, c] = tri_pixels(t);
        Some([point_at(a.0, a.1)?, point_at(b.0, b.1)?, point_at(c.0, c.1)?])
    };
    // Triangles that exist, are not degenerate in 3D and are not seen edge-on.
    let min_view_sin = config.min_view_angle.map(Real::sin);
    let exists: Vec<bool> = (0..num_tris)
        .map(|t| {
            tri_points(t).is_some_and(|p| {
                let normal = (p[1] - p[0]).cross(&(p[2] - p[0]));
                0.5 * normal.norm() >= MIN_TRIANGLE_AREA
                    && TriangleFrame::new(&p).is_some()
                    && min_view_sin.is_none_or(|min_sin| {
                        let beam = (p[0].coords + p[1].coords + p[2].coords) / 3.0;
                        normal.dot(&beam).abs() >= min_sin * normal.norm() * beam.norm()
                    })
            })
        })
        .collect();
    let neighbours = |t: usize| -> [Option<usize>; 3] {
        let (q, k) = (t / 2, t % 2);
        let (c, r) = (q % qw, q / qw);
        let quad = |c: usize, r: usize, k: usize| 2 * (r * qw + c) + k;
        if k == 0 {
            [
                Some(quad(c, r, 1)),
                (c > 0).then(|| quad(c - 1, r, 1)),
                (r > 0).then(|| quad(c, r - 1, 1)),
            ]
        } else {
            [
                Some(quad(c, r, 0)),
                (c + 1 < qw).then(|| quad(c + 1, r, 0)),
                (r + 2 < h).then(|| quad(c, r + 1, 0)),
            ]
        }
    };

    let growable = |t: usize| -> bool {
        let px = tri_pixels(t);
        let pl: Vec<(Vector3, Real)> = px.iter().filter_map(|&(c, r)| planes[r * w + c]).collect();
        if pl.len() < 3 {
            return false;
        }
        for i in 0..3 {
            for j in i + 1..3 {
                let angle = pl[i].0.dot(&pl[j].0).clamp(-1.0, 1.0).acos();
                if angle >= config.max_normal_angle
                    || (pl[i].1 - pl[j].1).abs() >= config.max_offset_diff
                {
                    return false;
                }
            }
        }
        true
    };
    // τ₀, τ₁ of Alg 5: the pixel-axis-aligned sides. T₀: (0,1) vertical, (0,2) horizontal;
    // T₁: (0,2) vertical, (1,2) horizontal.
    let sides_below = |t: usize, limit: Real| -> bool {
        let Some(p) = tri_points(t) else { return false };
        let (s0, s1) = if t.is_multiple_of(2) { ((0, 1), (0, 2)) } else { ((0, 2), (1, 2)) };
        let below = |(a, b): (usize, usize)| {
            let scale = config.side_per_range.map_or(1.0, |k| {
                (k * p[a].coords.norm().min(p[b].coords.norm()) / config.max_side).max(1.0)
            });
            (p[a] - p[b]).norm() < limit * scale
        };
        below(s0) && below(s1)
    };
    let short_sides = |t: usize| sides_below(t, config.max_side);

    let mut used = vec![false; num_tris];
    let mut queued = vec![u32::MAX; num_tris];
    let mut epoch = 0u32;
    let mut grow = |accept: &dyn Fn(usize) -> bool, used: &mut Vec<bool>| -> Vec<Vec<usize>> {
        let mut meshes = Vec::new();
        let mut queue = VecDeque::new();
        for seed in 0..num_tris {
            if used[seed] || !exists[seed] {
                continue;
            }
            epoch += 1;
            let mut mesh = Vec::new();
            queue.push_back(seed);
            queued[seed] = epoch;
            while let Some(t) = queue.pop_front() {
                if used[t] || !accept(t) {
                    continue;
                }
                used[t] = true;
                mesh.push(t);
                for n in neighbours(t).into_iter().flatten() {
                    if exists[n] && !used[n] && queued[n] != epoch {
                        queued[n] = epoch;
                        queue.push_back(n);
                    }
                }
            }
            if !mesh.is_empty() {
                meshes.push(mesh);
            }
        }
        meshes
    };

    let cache: Vec<bool> = (0..num_tris)
        .map(|t| {
            exists[t]
                && config.phase1_max_side.is_none_or(|limit| sides_below(t, limit))
                && growable(t)
        })
        .collect();
    let mut phase1 = grow(&|t| cache[t], &mut used);
    phase1.retain(|m| {
        let keep = m.len() >= config.min_triangles;
        if !keep {
            for &t in m {
                used[t] = false;
            }
        }
        keep
    });
    let phase2 = grow(&short_sides, &mut used);

    let mut out = GrownTrimeshes { pixels_without_plane, ..GrownTrimeshes::default() };
    let mut stats = MeshStats::default();
    for (phase, meshes) in [(GrowPhase::Similarity, phase1), (GrowPhase::Proximity, phase2)] {
        for mesh in meshes.iter().filter(|m| m.len() >= config.min_triangles) {
            for chunk in mesh.chunks(config.max_triangles) {
                let mut index = std::collections::HashMap::new();
                let mut vertices = Vec::new();
                let triangles: Vec<[u32; 3]> = chunk
                    .iter()
                    .map(|&t| {
                        tri_pixels(t).map(|(c, r)| {
                            *index.entry((c, r)).or_insert_with(|| {
                                vertices.push(point_at(c, r).expect("mesh pixels are input"));
                                (vertices.len() - 1) as u32
                            })
                        })
                    })
                    .collect();
                stats = stats.combine(&MeshStats::from_triangles(&vertices, &triangles, 1));
                let patch = TrimeshPatch::new(vertices, triangles)
                    .expect("accepted triangles are non-degenerate");
                out.meshes.push(GrownMesh { patch, phase });
            }
        }
    }
    out.stats = stats;
    Ok(out)
}

/// The plane `(n, d)` of Alg 4 lines 2–8 through `pts` (at least 3), or `None`.
fn local_plane(pts: &[Point3]) -> Option<(Vector3, Real)> {
    if pts.len() < 3 {
        return None;
    }
    let centroid = pts.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / pts.len() as Real;
    let mut a = na::Matrix3::<Real>::zeros();
    for p in pts {
        let v = centroid - p.coords;
        a += v * v.transpose();
    }
    let eig = na::SymmetricEigen::new(a);
    let (imin, _) = eig
        .eigenvalues
        .iter()
        .enumerate()
        .min_by(|x, y| x.1.total_cmp(y.1))
        .expect("three eigenvalues");
    let mut n: Vector3 = eig.eigenvectors.column(imin).into_owned();
    let norm = n.norm();
    if norm <= 0.0 || !norm.is_finite() {
        return None;
    }
    n /= norm;
    let mut d = n.dot(&centroid);
    if d < 0.0 {
        d = -d;
        n = -n;
    }
    Some((n, d))
}
