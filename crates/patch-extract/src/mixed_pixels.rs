//! Mixed-pixel (veil-point) filter for organised range scans.
//!
//! A beam whose footprint straddles a depth edge reports a range between the foreground and the
//! background: a phantom point in mid-air, on the beam, between the two surfaces (a "mixed
//! pixel", "veil point" or "shadow point"). The simulated actuated laser range finder of
//! `scene-sim` produces them at edges deeper than 5 cm with probability 0.5; a point-cloud map
//! built from such scans blocks free space along every silhouette, and the phantoms disturb plane
//! segmentation. [`mixed_pixels`] flags them, [`remove_mixed_pixels`] drops them.
//!
//! # The rule
//! The cloud must be organised ([`PointCloud::grid`]) and in the sensor frame (sensor at the
//! origin, as `scene_sim`'s `SimulatedScan::to_cloud` gives it), so that the beam through a
//! point `p` is the ray from the origin through `p`, and its range is `r_p = |p|`. Neighbours
//! are grid neighbours; invalid pixels and pixels outside the grid are missing.
//!
//! * **Veil edge.** The line from `p` to a neighbour `q` is a veil edge when the range jumps
//!   above the noise floor, `|r_q − r_p| > min_jump`, **and** the line `p → q` makes an angle
//!   below `θ = max_veil_angle` with the beam through `p` (`|cos∠(p, q − p)| > cos θ`). On a
//!   surface seen head-on the line to a neighbour is perpendicular to the beam; across a depth
//!   edge, and along a veil of phantoms, it is almost parallel to it.
//! * **Line support.** Along each of the four grid lines through `p` (row, column, both
//!   diagonals), a side supports `p` when its adjacent pixel `q₁` is valid and not a veil edge;
//!   or, reaching one pixel further, when the pixel `q₂` two steps away is valid and not a veil
//!   edge and `q₁` is missing or sticks out *behind* both (`r_q₁ > r_p` and
//!   `r_q₁ > r_q₂ + min_jump`: a hole or a phantom behind `p`, as next to the silhouette of a
//!   one- or two-pixel-wide post). A line supports `p` when both of its sides do. (The two
//!   end pixels of a one-pixel-wide object have no line along it; the foreground guard keeps
//!   them.)
//! * **Plane support** (`plane_tolerance = Some(t)`). Each of the four 3 × 3 quadrant blocks
//!   that have `p` at a corner, `{(c + i·s_c, r + j·s_r) : 0 ≤ i, j ≤ 2}` without `p`, with at
//!   least 6 valid pixels, is fitted with the plane `{x : m·x = 1}` that minimises
//!   `Σ r_q² (m·q − 1)²`: to first order the squared residuals *along the beams*, the direction
//!   of the range noise (the beam through `q` meets the plane at range `r_q / (m·q)`). The block
//!   supports `p` when the plane is not seen edge-on from the sensor
//!   (`|m·p| ≥ 0.02 · |m| · r_p`, about 1.1°: near the ±90° columns of an actuated LRF, where
//!   the rows nearly coincide, a window's points lie on a plane through the sensor, which is no
//!   surface) and `p` and every block pixel lie within `t` of it along their beams. This keeps a
//!   smooth surface seen at grazing incidence, where every grid line is a veil edge (the floor far
//!   from a scanner 0.5 m above it, in the backward-looking half of an actuated LRF's grid), also
//!   next to a wall or an object (a quadrant away from them is all floor), and refuses a phantom,
//!   which is more than `t` off both surfaces of its edge.
//! * **Foreground guard** (`keep_foreground`, on in the presets). `p` is kept unless some
//!   veil edge leads to a *nearer* neighbour: a phantom lies between a foreground and a
//!   background, a thin obstacle's silhouette in front of everything.
//! * **Background guard** (`keep_background`, off in the presets). `p` is kept unless some
//!   veil edge leads to a *farther* neighbour: a phantom also has its background beside it,
//!   while a surface seen past an occluder's silhouette (a wall through the gaps of a rack)
//!   has only nearer neighbours across its veil edges.
//! * **Verdict.** `p` is a mixed pixel iff it has a veil edge to at least one of its 8 neighbours
//!   (with the guards: to a nearer one, to a farther one) and neither a line nor a quadrant
//!   plane supports it. A point at the origin (no beam) is
//!   never flagged. One pass over the grid; a 3 × 3 minimum and maximum of the ranges skips the
//!   pixels without any jump above `min_jump`, and planes are fitted only for the points the
//!   lines leave undecided.
//!
//! # What it is, and how it differs from PCL
//! The veil edge is the classic shadow test on the angle between the viewing ray and the line
//! to a neighbour: ROS `laser_filters`' `ScanShadowsFilter` applies it within 2D scan lines (a
//! point goes when a neighbour within a window is seen at an angle below `min_angle`, often
//! 10°); PCL's `RangeImageBorderExtractor` labels the points between an obstacle border and its
//! shadow border "veil points", and PCL's `ShadowPoints` filter removes points whose normal is
//! nearly perpendicular to the viewing direction (`|n · p| < threshold`, normals computed
//! beforehand). Ours differs in four ways:
//! 1. it works on the organised grid along rows, columns and diagonals, without normals (normals
//!    at a veil are themselves estimated from the phantoms);
//! 2. range jumps within the noise floor `min_jump` are never veil edges (near the ±90° columns
//!    of an actuated LRF neighbouring beams nearly coincide, and noise alone would give any
//!    angle);
//! 3. a veil edge alone does not remove a point: the point must also lack support on every grid
//!    line and on every quadrant plane, so real edge points (supported along the edge), thin
//!    posts (supported along their axis) and grazing surfaces (supported by a plane) stay;
//! 4. θ can therefore be larger than the usual 10° (the presets use 30°), which also removes
//!    phantoms that lie close to a surface.
//!
//! # Removing or snapping
//! [`remove_mixed_pixels`] drops the mixed pixels. [`snap_mixed_pixels`] instead moves each
//! along its beam to its *foreground range*, the least range across its veil edges to nearer
//! neighbours: the beam's footprint partly hit the foreground, so the point goes to the
//! foreground's silhouette (at most one beam spacing past its edge) rather than away.
//! [`fix_mixed_pixels`] does either, as [`MixedPixelFix`] says.
//!
//! Unorganised clouds are refused ([`MixedPixelError::NotOrganised`]); there is no k-NN
//! fallback: in 3D a phantom's nearest neighbours are the other phantoms of its veil, and which
//! points were neighbouring beams cannot be recovered from positions.
//!
//! # Measured effect
//! The table below was measured without the foreground guard. With it (the presets), the lab's
//! phantom recall (> 20 cm) is 95 % instead of 99.9 % and thin obstacles lose 3.1 % (seed 7,
//! 2 scans); a pc map of the lab (scene seed 1, 8 scans) checked against the exact scene
//! (`patchnav map compare`, 100,000 steps, seed 2) calls 0.57 % of colliding steps free
//! (0.69 % without the guard, 0.14 % unfiltered) and 6.4 % of free steps colliding (5.2 %
//! without the guard, 30.1 % unfiltered): the filter still costs safety, so it is off by
//! default in the pipeline and the pc maps.
//!
//! Simulated SICK S300 scans (σ = 3 cm, mixed pixels with probability 0.5 at edges above 5 cm)
//! at full resolution (541 × 361 beams at 0.5°) and at 1° (271 × 181), the ±90° columns
//! dropped as the project does, [`MixedPixelConfig::alrf`], 4 scan poses at 0.5 m height for
//! each of the seeds 1, 2 and 3 of each scene; truth from the simulator (`tests/it/mixed_pixels.rs`,
//! `report_full_resolution`; the time is the best of 5 runs per scan, release build, on a
//! shared 2-core machine):
//!
//! | scan | points | removed | recall: all mixed | > 3σ (n) | phantoms > 9 cm (n) | > 20 cm (n) | clean points lost | thin obstacles lost (n) | far floor lost (n; interior) | time/scan |
//! |---|---|---|---|---|---|---|---|---|---|---|
//! | lab, 0.5° | 2,286,025 | 9,219 (0.4 %) | 65.3 % | 86.3 % (5,264) | 95.5 % (4,061) | 99.9 % (3,077) | 0.20 % | 2.7 % (30,715) | 0.76 % (28,549; 0.13 %) | 8.2 ms |
//! | office, 0.5° | 2,331,747 | 3,468 (0.1 %) | 58.5 % | 86.1 % (2,179) | 95.0 % (1,726) | 99.8 % (1,238) | 0.07 % | 2.0 % (503) | 0.35 % (20,184; 0.07 %) | 7.2 ms |
//! | lab, 1° | 571,996 | 3,797 (0.7 %) | 61.8 % | 80.3 % (1,297) | 93.1 % (933) | 99.7 % (674) | 0.47 % | 7.0 % (7,685) | 2.27 % (7,174; 0.23 %) | 2.4 ms |
//! | office, 1° | 583,439 | 1,309 (0.2 %) | 60.6 % | 86.5 % (565) | 95.2 % (461) | 100.0 % (316) | 0.14 % | 9.8 % (112) | 1.18 % (5,072; 0.00 %) | 1.6 ms |
//!
//! "All mixed" counts every pixel the simulator blended; most of the ones kept have a weight
//! near 0 or 1 and lie within the noise of a real surface. "> 3σ": mixed pixels more than 9 cm
//! from their own surface's true range. "Phantoms": mixed pixels more than 9 cm (20 cm) from the
//! true range of every pixel of their 3 × 3 window, i.e. in mid-air rather than near either
//! surface of the edge; the phantoms kept are nearly all within 10–20 cm of a surface, inside
//! the noise band that `min_jump` leaves alone. "Clean points": all points that are not mixed
//! pixels. Thin obstacles: the lab's table legs (cylinders of radius 2.5 cm) and rack posts
//! (8 cm square), the office's desk legs (5 cm square); what they lose is mostly posts 6–11 m
//! away (about one pixel wide, most of their pixels mixed) and legs seen by the backward beams
//! (in one scan pair of the lab with seed 7, 12 % of their points). Far floor: the floor more
//! than 4 m from the scanner; "interior": its pixels whose whole 5 × 5 window is floor, none
//! of it mixed.
//!
//! Without plane support (`plane_tolerance: None`, seeds 1 and 2) the grazing floor goes: 14 %
//! (lab) and 11 % (office) of the far floor at 0.5°, 36–40 % at 1°, and the clean loss is
//! 0.95 % and 0.41 %; phantom recall (> 9 cm) is 1–1.5 points higher. At 1° the grid is twice
//! as coarse as the beam footprint and a phantom twice as far from its neighbours' lines, so
//! recall drops a little and thin obstacles (one pixel wide from 3–5 m on) lose more.

use nalgebra::Matrix3;
use patch_core::{Point3, Real, Vector3};
use pointcloud::{INVALID_PIXEL, PointCloud};

/// Why the filter refused its input.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MixedPixelError {
    /// The cloud has no pixel grid.
    #[error("the cloud has no pixel grid (the mixed-pixel filter needs an organised scan)")]
    NotOrganised,
    /// A parameter is outside its allowed range.
    #[error("mixed-pixel parameter {name} = {value} is outside {allowed}")]
    BadParameter {
        /// The parameter name.
        name: &'static str,
        /// Its value.
        value: Real,
        /// The allowed range.
        allowed: &'static str,
    },
    /// The corrected cloud could not be built (a non-finite position).
    #[error("the corrected cloud is invalid: {0}")]
    Cloud(#[from] pointcloud::AttributeError),
}

/// Parameters of [`mixed_pixels`] (see the module docs for the rule). No `Default`: start from
/// a preset.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct MixedPixelConfig {
    /// `θ`: a line to a neighbour within this angle of the beam is a veil edge, radians, in
    /// (0, π/2).
    pub max_veil_angle: Real,
    /// Range jumps up to this many metres are noise and never veil edges, in [0, 100].
    pub min_jump: Real,
    /// Plane support: the largest residual, along each point's beam, of `p` and of a quadrant
    /// block to their plane, metres, in (0, 100]; `None` disables plane support (surfaces seen
    /// at grazing incidence then lose points).
    pub plane_tolerance: Option<Real>,
    /// Foreground guard: a point none of whose veil edges leads to a *nearer* neighbour is
    /// kept. A mixed pixel lies between a foreground and a background, so it always has a
    /// nearer neighbour across a veil edge; a thin obstacle's silhouette (a board's front
    /// edge, a post one pixel wide) has only farther ones. Trades a few phantoms next to the
    /// foreground (within the mixture's spread of it) for never eating an obstacle's edge.
    pub keep_foreground: bool,
    /// Background guard: a point none of whose veil edges leads to a *farther* neighbour is
    /// kept. A mixed pixel lies between a foreground and a background, so it also has a
    /// farther neighbour across a veil edge; a background surface seen past an occluder's
    /// silhouette (a wall between a rack's boards) has only nearer ones. Off in the presets:
    /// on the lab (seed 7, 2 scans) it keeps 90 % of the phantoms more than 20 cm off every
    /// surface instead of 95 %, and it saves maps little (`docs/map-safety.md`).
    pub keep_background: bool,
}

impl MixedPixelConfig {
    /// The preset for a sensor with Gaussian range noise of `sigma` metres: `θ = 30°`,
    /// `min_jump = 4σ`, `plane_tolerance = 3σ`.
    ///
    /// Measured on the lab at 0.5° (seeds 1 and 2, 4 scans each; phantom recall = mixed pixels
    /// more than 9 cm off every surface around them, module docs), with this preset's 95.1 %
    /// recall and 0.18 % clean points lost as the reference:
    /// * `min_jump = 4σ`: the difference of two noisy ranges has standard deviation `σ√2`, so
    ///   `4σ` is 2.8 of those. `3σ`: 96.2 % / 0.28 % (noise alone starts making veil edges);
    ///   `5σ`: 93.1 % / 0.14 %.
    /// * `plane_tolerance = 3σ`: a phantom within `3σ` of a surface is indistinguishable from
    ///   noise on it. `2σ`: 96.4 % / 0.35 %, and 2.9 % of the far floor lost instead of 0.8 %;
    ///   `4σ`: 91.1 % / 0.12 %.
    /// * `θ = 30°`: once a point must also lack support, θ hardly costs real points: `20°`
    ///   gives 93.9 % / 0.17 %. The 10° of 2D shadow filters keeps the phantoms that lie close
    ///   to a surface.
    ///
    /// # Errors
    /// [`MixedPixelError::BadParameter`] unless `sigma` is in (0, 1] metres.
    pub fn for_range_noise(sigma: Real) -> Result<MixedPixelConfig, MixedPixelError> {
        if !(sigma.is_finite() && sigma > 0.0 && sigma <= 1.0) {
            return Err(MixedPixelError::BadParameter {
                name: "sigma",
                value: sigma,
                allowed: "(0, 1] m",
            });
        }
        Ok(MixedPixelConfig {
            max_veil_angle: 30f64.to_radians(),
            min_jump: 4.0 * sigma,
            plane_tolerance: Some(3.0 * sigma),
            keep_foreground: true,
            keep_background: false,
        })
    }

    /// For the simulated SICK S300 actuated laser range finder (σ = 3 cm): `θ = 30°`,
    /// `min_jump = 0.12 m`, plane tolerance 0.09 m ([`MixedPixelConfig::for_range_noise`]
    /// with σ = 0.03). Measured in the module docs.
    pub fn alrf() -> MixedPixelConfig {
        MixedPixelConfig {
            max_veil_angle: 30f64.to_radians(),
            min_jump: 0.12,
            plane_tolerance: Some(0.09),
            keep_foreground: true,
            keep_background: false,
        }
    }

    /// For range cameras (SwissRanger SR-3000 class, σ = 1 cm): `θ = 30°`, `min_jump =
    /// 0.04 m`, plane tolerance 0.03 m ([`MixedPixelConfig::for_range_noise`] with σ = 0.01).
    /// Not measured: the simulated range camera makes no mixed pixels.
    pub fn range_camera() -> MixedPixelConfig {
        MixedPixelConfig {
            max_veil_angle: 30f64.to_radians(),
            min_jump: 0.04,
            plane_tolerance: Some(0.03),
            keep_foreground: true,
            keep_background: false,
        }
    }

    /// Checks the fields (for configurations built as struct literals).
    ///
    /// # Errors
    /// [`MixedPixelError::BadParameter`] for an angle outside (0, π/2), a `min_jump` outside
    /// [0, 100] m, or a plane tolerance outside (0, 100] m (NaN and infinities included).
    pub fn validate(&self) -> Result<(), MixedPixelError> {
        let bad =
            |name, value, allowed| Err(MixedPixelError::BadParameter { name, value, allowed });
        let a = self.max_veil_angle;
        if !(a > 0.0 && a < std::f64::consts::FRAC_PI_2) {
            return bad("max_veil_angle", a, "(0, π/2) rad");
        }
        let j = self.min_jump;
        if !(0.0..=100.0).contains(&j) {
            return bad("min_jump", j, "[0, 100] m");
        }
        if let Some(t) = self.plane_tolerance
            && !(t > 0.0 && t <= 100.0)
        {
            return bad("plane_tolerance", t, "(0, 100] m");
        }
        Ok(())
    }
}

/// Fewest valid pixels of a quadrant block (besides `p`) a plane is fitted to.
const MIN_BLOCK_POINTS: usize = 6;
/// Planes seen more edge-on than this (|cos(beam, normal)|, about 1.1°) support nothing, and
/// the floor of that cosine when a normal residual is turned into one along a beam.
const MIN_BEAM_COS: Real = 0.02;

/// A valid pixel: its point and range.
#[derive(Copy, Clone)]
struct Px {
    p: Point3,
    r: Real,
}

/// The four grid lines through a pixel, as one step `(dc, dr)`.
const LINES: [(isize, isize); 4] = [(1, 0), (0, 1), (1, 1), (1, -1)];
/// The four quadrant blocks, as the signs of their steps.
const QUADRANTS: [(isize, isize); 4] = [(1, 1), (1, -1), (-1, 1), (-1, -1)];

struct Image<'a> {
    w: usize,
    h: usize,
    /// Per pixel the point's range, NaN for missing pixels.
    range: Vec<Real>,
    pixels: &'a [u32],
    positions: &'a [Point3],
    cos2: Real,
    config: &'a MixedPixelConfig,
}

impl Image<'_> {
    fn at(&self, c: isize, r: isize) -> Option<Px> {
        if c < 0 || r < 0 || c as usize >= self.w || r as usize >= self.h {
            return None;
        }
        let k = r as usize * self.w + c as usize;
        let i = self.pixels[k];
        (i != INVALID_PIXEL).then(|| Px { p: self.positions[i as usize], r: self.range[k] })
    }

    /// Whether `p → q` is a veil edge (module docs).
    fn veil(&self, p: &Px, q: &Px) -> bool {
        if (q.r - p.r).abs() <= self.config.min_jump {
            return false;
        }
        let v = q.p - p.p;
        let d = p.p.coords.dot(&v);
        d * d > self.cos2 * p.r * p.r * v.norm_squared()
    }

    /// Whether pixel (`c`, `r`) holding `p` is a mixed pixel (module docs): `None` if not,
    /// else `Some` of its foreground range (the least range across its veil edges to nearer
    /// neighbours; `None` when it has none, possible only without the foreground guard).
    fn mixed(&self, c: isize, r: isize, p: &Px) -> Option<Option<Real>> {
        if p.r <= 0.0 {
            return None;
        }
        // Shortcut: a line whose two neighbours are within `min_jump` supports `p`.
        let close = |dc: isize, dr: isize| {
            let (c, r) = (c + dc, r + dr);
            c >= 0
                && r >= 0
                && (c as usize) < self.w
                && (r as usize) < self.h
                && (self.range[r as usize * self.w + c as usize] - p.r).abs()
                    <= self.config.min_jump
        };
        if LINES.iter().any(|&(dc, dr)| close(dc, dr) && close(-dc, -dr)) {
            return None;
        }
        // Veil state of the 8 neighbours, indexed (dr + 1) * 3 + (dc + 1).
        let mut near: [Option<bool>; 9] = [None; 9];
        let mut any_veil = false;
        let mut foreground: Option<Real> = None;
        let mut farther_veil = false;
        for dr in -1..=1 {
            for dc in -1..=1 {
                if (dc, dr) != (0, 0)
                    && let Some(q) = self.at(c + dc, r + dr)
                {
                    let v = self.veil(p, &q);
                    any_veil |= v;
                    if v && q.r < p.r {
                        foreground = Some(foreground.map_or(q.r, |f| f.min(q.r)));
                    }
                    farther_veil |= v && q.r > p.r;
                    near[((dr + 1) * 3 + dc + 1) as usize] = Some(v);
                }
            }
        }
        if !any_veil
            || (self.config.keep_foreground && foreground.is_none())
            || (self.config.keep_background && !farther_veil)
        {
            return None;
        }
        let side = |dc: isize, dr: isize| {
            let q1 = match near[((dr + 1) * 3 + dc + 1) as usize] {
                Some(false) => return true,
                Some(true) => self.at(c + dc, r + dr),
                None => None,
            };
            let Some(q2) = self.at(c + 2 * dc, r + 2 * dr) else { return false };
            q1.is_none_or(|q1| q1.r > p.r && q1.r > q2.r + self.config.min_jump)
                && !self.veil(p, &q2)
        };
        if LINES.iter().any(|&(dc, dr)| side(dc, dr) && side(-dc, -dr)) {
            return None;
        }
        if let Some(tol) = self.config.plane_tolerance
            && QUADRANTS.iter().any(|&(sc, sr)| self.on_block_plane(c, r, sc, sr, p, tol))
        {
            return None;
        }
        Some(foreground)
    }

    /// Plane support by the quadrant block `{(c + i·sc, r + j·sr) : 0 ≤ i, j ≤ 2} \ {p}`
    /// (module docs, "plane support").
    fn on_block_plane(&self, c: isize, r: isize, sc: isize, sr: isize, p: &Px, tol: Real) -> bool {
        // Normal equations of min Σ r_q² (q·m − 1)² over the block.
        let mut a = Matrix3::<Real>::zeros();
        let mut b = Vector3::zeros();
        let mut block = [None; 8];
        let mut n = 0;
        for j in 0..=2 {
            for i in 0..=2 {
                if (i, j) != (0, 0)
                    && let Some(q) = self.at(c + i * sc, r + j * sr)
                {
                    let w = q.r * q.r;
                    a += (q.p.coords * w) * q.p.coords.transpose();
                    b += q.p.coords * w;
                    block[n] = Some(q);
                    n += 1;
                }
            }
        }
        if n < MIN_BLOCK_POINTS {
            return false;
        }
        let Some(m) = a.cholesky().map(|ch| ch.solve(&b)) else { return false };
        // The plane is {x : m·x = 1}; the beam through q meets it at range r_q / (m·q).
        let along_beam = |q: &Px| {
            let t = m.dot(&q.p.coords);
            if t > 0.0 { (q.r - q.r / t).abs() } else { Real::INFINITY }
        };
        m.dot(&p.p.coords).abs() >= MIN_BEAM_COS * p.r * m.norm()
            && along_beam(p) <= tol
            && block[..n].iter().flatten().all(|q| along_beam(q) <= tol)
    }
}

/// One flag per point of `cloud` (point order): whether it is a mixed pixel (module docs).
///
/// `cloud` must be organised and in the sensor frame (the sensor at the origin), as
/// `scene_sim`'s `SimulatedScan::to_cloud` gives it; a cloud moved to the world frame gives
/// wrong flags (the filter cannot tell). A cloud without points gives no flags.
///
/// # Errors
/// [`MixedPixelError::NotOrganised`] without a pixel grid; [`MixedPixelError::BadParameter`]
/// for a bad `config`.
pub fn mixed_pixels(
    cloud: &PointCloud,
    config: &MixedPixelConfig,
) -> Result<Vec<bool>, MixedPixelError> {
    Ok(verdicts(cloud, config)?.into_iter().map(|v| v.is_some()).collect())
}

/// Per point `None`, or `Some` of a mixed pixel's foreground range (see `Image::mixed`).
fn verdicts(
    cloud: &PointCloud,
    config: &MixedPixelConfig,
) -> Result<Vec<Option<Option<Real>>>, MixedPixelError> {
    config.validate()?;
    let grid = cloud.grid().ok_or(MixedPixelError::NotOrganised)?;
    let positions = cloud.positions();
    let pixels = grid.pixels();
    let (w, h) = (grid.width() as usize, grid.height() as usize);
    let range = pixels
        .iter()
        .map(|&i| if i == INVALID_PIXEL { Real::NAN } else { positions[i as usize].coords.norm() })
        .collect();
    let cos2 = config.max_veil_angle.cos().powi(2);
    let image = Image { w, h, range, pixels, positions, cos2, config };
    let range = &image.range;
    let jump = config.min_jump;
    let mut flags = vec![None; cloud.len()];
    // Quick test: without a jump above `min_jump` to a neighbour there is no veil edge. Per
    // pixel the smallest and largest range of its 3 × 3 window (missing pixels are NaN, which
    // `min` and `max` skip), as a row pass and a column pass.
    let (mut lo, mut hi) = (range.clone(), range.clone());
    for row in 0..h {
        let line = &range[row * w..(row + 1) * w];
        for col in 0..w {
            let (a, b) = (col.saturating_sub(1), (col + 2).min(w));
            let (mut l, mut u) = (Real::NAN, Real::NAN);
            for &x in &line[a..b] {
                l = l.min(x);
                u = u.max(x);
            }
            lo[row * w + col] = l;
            hi[row * w + col] = u;
        }
    }
    for row in 0..h {
        let (a, b) = (row.saturating_sub(1), (row + 2).min(h));
        for col in 0..w {
            let k = row * w + col;
            let rp = range[k];
            if rp.is_nan() {
                continue;
            }
            let (mut l, mut u) = (rp, rp);
            for rr in a..b {
                l = l.min(lo[rr * w + col]);
                u = u.max(hi[rr * w + col]);
            }
            if (u - rp > jump || rp - l > jump)
                && let Some(p) = image.at(col as isize, row as isize)
                && let Some(v) = image.mixed(col as isize, row as isize, &p)
            {
                flags[pixels[k] as usize] = Some(v);
            }
        }
    }
    Ok(flags)
}

/// `cloud` without its mixed pixels ([`mixed_pixels`]), and how many were removed. The grid is
/// kept: the removed points' pixels become invalid; all attributes follow the points, so
/// **point indices change**.
///
/// # Errors
/// As [`mixed_pixels`].
pub fn remove_mixed_pixels(
    cloud: &PointCloud,
    config: &MixedPixelConfig,
) -> Result<(PointCloud, usize), MixedPixelError> {
    let flags = mixed_pixels(cloud, config)?;
    let removed = flags.iter().filter(|&&f| f).count();
    Ok((cloud.retain_indices(|i| !flags[i]), removed))
}

/// What to do with the mixed pixels [`mixed_pixels`] finds.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Default)]
pub enum MixedPixelFix {
    /// Drop them ([`remove_mixed_pixels`]).
    Remove,
    /// Move each onto its foreground along its beam ([`snap_mixed_pixels`]): the foreground
    /// keeps its silhouette, the free space behind it is cleared. The safer choice for maps
    /// (measured in `docs/map-safety.md`).
    #[default]
    SnapToForeground,
}

impl MixedPixelFix {
    /// Every fix, in declaration order.
    pub const ALL: [MixedPixelFix; 2] = [MixedPixelFix::Remove, MixedPixelFix::SnapToForeground];

    /// Its name: `remove` or `snap`.
    pub fn name(self) -> &'static str {
        match self {
            MixedPixelFix::Remove => "remove",
            MixedPixelFix::SnapToForeground => "snap",
        }
    }
}

impl std::fmt::Display for MixedPixelFix {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for MixedPixelFix {
    type Err = String;

    /// Parses [`MixedPixelFix::name`].
    fn from_str(s: &str) -> Result<MixedPixelFix, String> {
        MixedPixelFix::ALL
            .into_iter()
            .find(|f| f.name() == s)
            .ok_or_else(|| format!("unknown mixed-pixel fix `{s}` (expected `remove` or `snap`)"))
    }
}

/// `cloud` with its mixed pixels removed or snapped, as `fix` says, and how many there were.
///
/// # Errors
/// As [`mixed_pixels`].
pub fn fix_mixed_pixels(
    cloud: &PointCloud,
    config: &MixedPixelConfig,
    fix: MixedPixelFix,
) -> Result<(PointCloud, usize), MixedPixelError> {
    match fix {
        MixedPixelFix::Remove => remove_mixed_pixels(cloud, config),
        MixedPixelFix::SnapToForeground => {
            let s = snap_mixed_pixels(cloud, config)?;
            Ok((s.cloud, s.snapped + s.removed))
        }
    }
}

/// What [`snap_mixed_pixels`] did.
#[derive(Clone, Debug)]
pub struct SnappedMixedPixels {
    /// The cloud with its mixed pixels moved (or removed); the grid is kept.
    pub cloud: PointCloud,
    /// Mixed pixels moved onto their foreground.
    pub snapped: usize,
    /// Mixed pixels without a nearer neighbour across a veil edge, removed (only without the
    /// foreground guard).
    pub removed: usize,
}

/// `cloud` with each mixed pixel ([`mixed_pixels`]) moved along its beam to its
/// **foreground range**: the least range among its neighbours across veil edges that are
/// nearer than it. A beam whose footprint straddles a depth edge partly hit the foreground,
/// so the snapped point lies on the foreground's silhouette, at most one beam spacing past
/// its edge: unlike removal, the obstacle side of the edge keeps a point, and the free space
/// between the surfaces is cleared. Mixed pixels without such a neighbour (possible only with
/// `keep_foreground` off) are removed. Point order and attributes are kept, except for the
/// removed points.
///
/// # Errors
/// As [`mixed_pixels`].
pub fn snap_mixed_pixels(
    cloud: &PointCloud,
    config: &MixedPixelConfig,
) -> Result<SnappedMixedPixels, MixedPixelError> {
    let verdicts = verdicts(cloud, config)?;
    let mut snapped = 0;
    let positions = cloud
        .positions()
        .iter()
        .zip(&verdicts)
        .map(|(p, v)| match v {
            Some(Some(fg)) => {
                snapped += 1;
                Point3::from(p.coords * (fg / p.coords.norm()))
            }
            _ => *p,
        })
        .collect();
    let moved = cloud.with_positions(positions)?;
    let removed = verdicts.iter().filter(|v| matches!(v, Some(None))).count();
    let cloud = if removed == 0 {
        moved
    } else {
        moved.retain_indices(|i| !matches!(verdicts[i], Some(None)))
    };
    Ok(SnappedMixedPixels { cloud, snapped, removed })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use patch_core::Vector3;

    /// An organised cloud of `w × h` beams 0.5° apart around +x, with the range of each pixel
    /// from `range(col, row)` (`None`: no measurement).
    pub(crate) fn scan(w: u32, h: u32, range: impl Fn(u32, u32) -> Option<Real>) -> PointCloud {
        let step = 0.5f64.to_radians();
        let pixels = (0..h).flat_map(|row| (0..w).map(move |col| (col, row))).map(|(col, row)| {
            let yaw = (col as Real - w as Real / 2.0) * step;
            let pitch = (row as Real - h as Real / 2.0) * step;
            let dir = Vector3::new(yaw.cos() * pitch.cos(), yaw.sin() * pitch.cos(), pitch.sin());
            range(col, row).map(|r| Point3::from(dir * r))
        });
        PointCloud::from_pixels(w, h, pixels.collect::<Vec<_>>()).unwrap()
    }

    fn flagged(cloud: &PointCloud, config: &MixedPixelConfig) -> Vec<(u32, u32)> {
        let flags = mixed_pixels(cloud, config).unwrap();
        let grid = cloud.grid().unwrap();
        let w = grid.width();
        grid.pixels()
            .iter()
            .enumerate()
            .filter(|&(_, &i)| i != INVALID_PIXEL && flags[i as usize])
            .map(|(k, _)| (k as u32 % w, k as u32 / w))
            .collect()
    }

    #[test]
    fn a_veil_between_two_walls_goes_and_the_walls_stay() {
        // Foreground at 3 m left of column 10, background at 6 m right of it, and a column of
        // phantoms at 3.5–5.5 m on the edge.
        let cloud = scan(20, 12, |col, row| {
            Some(match col {
                0..10 => 3.0,
                10 => 3.5 + 2.0 * (row as Real / 11.0),
                _ => 6.0,
            })
        });
        let flags = flagged(&cloud, &MixedPixelConfig::alrf());
        let expected: Vec<(u32, u32)> = (0..12).map(|row| (10, row)).collect();
        assert_eq!(flags, expected);
    }

    #[test]
    fn a_one_pixel_post_keeps_its_points_across_phantoms_behind_it() {
        // A post one pixel wide at 3 m (rows 2–12) before a wall at 6 m; rows 4, 7 and 10 of the
        // post are phantoms at 4.5 m. The phantoms go; the post stays, its two end pixels too
        // (no line along the post passes through them, but they are foreground: the guard),
        // and the wall stays.
        let cloud = scan(9, 15, |col, row| {
            Some(match (col, row) {
                (4, 4 | 7 | 10) => 4.5,
                (4, 2..=12) => 3.0,
                _ => 6.0,
            })
        });
        let flags = flagged(&cloud, &MixedPixelConfig::alrf());
        assert_eq!(flags, [(4, 4), (4, 7), (4, 10)]);
        let unguarded = MixedPixelConfig { keep_foreground: false, ..MixedPixelConfig::alrf() };
        assert_eq!(flagged(&cloud, &unguarded), [(4, 2), (4, 4), (4, 7), (4, 10), (4, 12)]);
    }

    #[test]
    fn a_wall_seen_between_two_boards_keeps_its_points() {
        // Boards at 2 m in rows 0–4 and 7–12, a wall at 5 m seen between them in rows 5–6, and
        // a post at 2 m in columns 9–10 that cuts the wall's rows. Next to the post, the wall's
        // pixels have no line support (every line meets a board or the post), but no farther
        // neighbour either: the background guard keeps them.
        let cloud = scan(20, 13, |col, row| {
            Some(match (col, row) {
                (9..=10, _) => 2.0,
                (_, 5..=6) => 5.0,
                _ => 2.0,
            })
        });
        let guarded = MixedPixelConfig { keep_background: true, ..MixedPixelConfig::alrf() };
        assert!(flagged(&cloud, &guarded).is_empty());
        assert!(flagged(&cloud, &MixedPixelConfig::alrf()).contains(&(8, 5)));
    }

    #[test]
    fn snapping_moves_a_veil_onto_its_foreground() {
        // As in the first test: a column of phantoms at 3.5–5.5 m between walls at 3 and 6 m.
        let cloud = scan(20, 12, |col, row| {
            Some(match col {
                0..10 => 3.0,
                10 => 3.5 + 2.0 * (row as Real / 11.0),
                _ => 6.0,
            })
        });
        let snapped = snap_mixed_pixels(&cloud, &MixedPixelConfig::alrf()).unwrap();
        assert_eq!((snapped.snapped, snapped.removed), (12, 0));
        assert_eq!(snapped.cloud.len(), cloud.len());
        let grid = snapped.cloud.grid().unwrap();
        for row in 0..12 {
            let i = grid.point_index(10, row).unwrap();
            let r = snapped.cloud.positions()[i].coords.norm();
            assert!((r - 3.0).abs() < 1e-9, "row {row}: {r}");
            let j = grid.point_index(11, row).unwrap();
            assert!((snapped.cloud.positions()[j].coords.norm() - 6.0).abs() < 1e-9);
        }
        let (removed, n) =
            fix_mixed_pixels(&cloud, &MixedPixelConfig::alrf(), MixedPixelFix::Remove).unwrap();
        assert_eq!((removed.len(), n), (cloud.len() - 12, 12));
    }

    #[test]
    fn noise_below_min_jump_is_no_edge_and_holes_are_no_edges() {
        // Ranges 5.00, 5.05 or 5.10 m in a scrambled pattern (jumps up to 10 cm, below 0.12 m),
        // and a hole.
        let cloud = scan(12, 12, |col, row| {
            let r = 5.0 + 0.05 * ((col * 7 + row * 13 + col * row) % 3) as Real;
            if (col, row) == (5, 5) { None } else { Some(r) }
        });
        assert!(flagged(&cloud, &MixedPixelConfig::alrf()).is_empty());
        // Without the noise floor and the plane, the same jumps make veil edges.
        let strict =
            MixedPixelConfig { min_jump: 0.0, plane_tolerance: None, ..MixedPixelConfig::alrf() };
        assert!(!flagged(&cloud, &strict).is_empty());
    }

    #[test]
    fn presets_are_valid_and_derive_from_the_noise() {
        for c in [MixedPixelConfig::alrf(), MixedPixelConfig::range_camera()] {
            c.validate().unwrap();
        }
        assert_eq!(MixedPixelConfig::for_range_noise(0.03), Ok(MixedPixelConfig::alrf()));
        assert_eq!(MixedPixelConfig::for_range_noise(0.01), Ok(MixedPixelConfig::range_camera()));
        let err = MixedPixelConfig { max_veil_angle: -1.0, ..MixedPixelConfig::alrf() }.validate();
        assert_eq!(
            err,
            Err(MixedPixelError::BadParameter {
                name: "max_veil_angle",
                value: -1.0,
                allowed: "(0, π/2) rad"
            })
        );
    }
}
