//! Pixel filters and unwrapping (thesis §2.5.5, spec §2, §6.1–6.5).
//!
//! - The standard **amplitude threshold** (AT): a pixel is valid iff its amplitude exceeds a
//!   constant (L1851–1883).
//! - The **adaptive amplitude threshold** (AAT, Eq 2.4): pixel `p` is valid iff
//!   `a_p > aw_p · AAT / r_p²`, where `aw_p` is the amplitude the pixel would see on a white wall
//!   at 1 m ([`Illumination`]: the parabola of Eq 2.5 or a per-pixel white-wall table) and `r_p`
//!   the reported range. `a_p · r_p² / aw_p` is the apparent reflectivity relative to a white
//!   wall: AAT = 0.2 rejects pixels that look darker than 20 %, and a pixel wrapped once from
//!   `R + 7.5 m` to `R` looks `((R + 7.5)/R)²` times darker than it is.
//! - **Unwrapping** (L2404–2458): every AAT-invalid pixel is moved one non-ambiguity range
//!   further along its beam, `p' = p · (|p| + R_amb) / |p|` (spec §6.5; the depth does not grow
//!   by R_amb). An optional low plain AT drops the very dark, multiply wrapped pixels first
//!   (L2446–2452). Pixels without a measurement (range 0) are never unwrapped.
//!
//! Every pixel gets a [`PixelOutcome`]: kept, unwrapped or dropped, so a user can take the dense
//! output (kept + unwrapped) or the safe one (kept only), the trade-off of L2456–2458.
//!
//! [`TofFilter`] precomputes the per-pixel limit `aw_p · AAT` and the ray tables once per camera;
//! [`TofFilter::apply`] then runs without trigonometry, division or allocation per frame.

use crate::{TofCamera, TofError, TofFrame};
use pointcloud::{FieldData, PointCloud, RangeKind, Real, ScalarField};
use serde::{Deserialize, Serialize};

/// What became of a pixel. The numeric values are those written to files (`outcome` field).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[repr(u8)]
pub enum PixelOutcome {
    /// Valid as measured.
    Kept = 0,
    /// Judged wrapped around and moved one (or more) non-ambiguity ranges further.
    Unwrapped = 1,
    /// Discarded (no measurement, or judged invalid and not unwrapped).
    Dropped = 2,
}

impl PixelOutcome {
    /// Whether the pixel is in the output (kept or unwrapped).
    pub fn is_output(self) -> bool {
        self != PixelOutcome::Dropped
    }
}

/// The illumination parabola of Eq 2.5, generalised by a curvature `k`:
/// `aw(x, y) = Â − k · ((x − δx)² + (y − δy)²)` (the thesis has `k = 1`). `x` is the column,
/// `y` the row, pixel (0, 0) top left (spec §6.3).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Parabola {
    /// Â: the white-wall amplitude at 1 m in the brightest pixel.
    pub a_hat: Real,
    /// δx: the column of the brightest pixel.
    pub delta_x: Real,
    /// δy: the row of the brightest pixel.
    pub delta_y: Real,
    /// k: how fast the illumination falls off (1 in Eq 2.5).
    pub curvature: Real,
}

impl Parabola {
    /// The SR-3000 of the thesis: Â = 12,000, δ = (88, 61) (L2364–2372): the brightness centre
    /// is shifted upward.
    pub fn sr3000() -> Parabola {
        Parabola { a_hat: 12_000.0, delta_x: 88.0, delta_y: 61.0, curvature: 1.0 }
    }

    /// The SR-3100: brightest at the image centre (L2370), δ = (88, 72) (inferred, spec §6.3),
    /// Â = 12,000.
    pub fn sr3100() -> Parabola {
        Parabola { a_hat: 12_000.0, delta_x: 88.0, delta_y: 72.0, curvature: 1.0 }
    }

    /// `aw` at pixel (`x`, `y`).
    pub fn eval(&self, x: Real, y: Real) -> Real {
        let (dx, dy) = (x - self.delta_x, y - self.delta_y);
        self.a_hat - self.curvature * (dx * dx + dy * dy)
    }

    fn validate(&self) -> Result<(), TofError> {
        let ok =
            [self.a_hat, self.delta_x, self.delta_y, self.curvature].iter().all(|v| v.is_finite())
                && self.a_hat > 0.0
                && self.curvature >= 0.0;
        if ok {
            Ok(())
        } else {
            Err(TofError::BadParameter {
                what: "illumination parabola",
                why: format!("{self:?} (want finite values, Â > 0, k ≥ 0)"),
            })
        }
    }
}

/// The white-wall amplitude at 1 m of every pixel (the look-up table the thesis mentions as the
/// alternative to Eq 2.5, L2344–2348), row-major.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WhiteWallTable {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// `aw` per pixel.
    pub values: Vec<f32>,
}

/// `aw_p`, the white-wall amplitude at 1 m of each pixel.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Illumination {
    /// Eq 2.5.
    Parabola(Parabola),
    /// A per-pixel table.
    Table(WhiteWallTable),
}

/// What to do where the illumination model gives `aw_p ≤ 0` (with the SR-3000 parabola the far
/// corners reach −2,468: spec §2, §6.2).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum NegativeIllumination {
    /// Eq 2.4 literally: the limit `aw_p · AAT / r²` is ≤ 0, so every pixel there passes (the
    /// thesis's behaviour, default).
    Literal,
    /// Clamp `aw_p` to at least this value (> 0), so the corners are tested too.
    Clamp(Real),
}

/// Which range `r_p` enters Eq 2.4.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum AatRange {
    /// The distance to the image plane, as the thesis (L2316–2317) (default).
    Depth,
    /// The distance along the beam (physically cleaner, spec §6.1).
    Radial,
}

/// The adaptive amplitude threshold (Eq 2.4).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AatConfig {
    /// `aw_p`.
    pub illumination: Illumination,
    /// AAT: the apparent-reflectivity threshold (0.2 in the thesis, L2370–2372).
    pub threshold: Real,
    /// Which `r_p`.
    pub range: AatRange,
    /// The corner case `aw_p ≤ 0`.
    pub negative: NegativeIllumination,
}

impl AatConfig {
    /// The thesis's parameters for the SR-3000: Eq 2.5 with Â = 12,000, δ = (88, 61),
    /// AAT = 0.2, depth range, corners literal.
    pub fn sr3000() -> AatConfig {
        AatConfig {
            illumination: Illumination::Parabola(Parabola::sr3000()),
            threshold: 0.2,
            range: AatRange::Depth,
            negative: NegativeIllumination::Literal,
        }
    }

    /// The same for the SR-3100 (δ = (88, 72)).
    pub fn sr3100() -> AatConfig {
        AatConfig {
            illumination: Illumination::Parabola(Parabola::sr3100()),
            ..AatConfig::sr3000()
        }
    }
}

/// Which pixels a filter judges invalid.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Detector {
    /// Every measured pixel is valid.
    None,
    /// The plain amplitude threshold: valid iff amplitude > the value.
    At(Real),
    /// The adaptive amplitude threshold.
    Aat(AatConfig),
}

/// What to do with the pixels an AAT judges invalid.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct UnwrapConfig {
    /// A low plain AT applied to the flagged pixels first: darker ones are taken for multiply
    /// wrapped (or simply dark) and dropped instead (L2446–2452). `None`: unwrap them all.
    pub low_at: Option<Real>,
}

/// A filter: a detector and, for the AAT, optional unwrapping.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FilterConfig {
    /// Which pixels are invalid.
    pub detector: Detector,
    /// Unwrap the invalid ones instead of dropping them (AAT only).
    pub unwrap: Option<UnwrapConfig>,
}

impl FilterConfig {
    /// The plain AT.
    pub fn at(threshold: Real) -> FilterConfig {
        FilterConfig { detector: Detector::At(threshold), unwrap: None }
    }

    /// The AAT without unwrapping.
    pub fn aat(config: AatConfig) -> FilterConfig {
        FilterConfig { detector: Detector::Aat(config), unwrap: None }
    }

    /// The AAT with unwrapping.
    pub fn aat_unwrap(config: AatConfig, low_at: Option<Real>) -> FilterConfig {
        FilterConfig { detector: Detector::Aat(config), unwrap: Some(UnwrapConfig { low_at }) }
    }
}

/// Per pixel the outcome and the output range (radial, metres; the reported one for kept
/// pixels, the unwrapped one for unwrapped pixels, 0 for dropped ones), and the counts.
///
/// Reused across frames by [`TofFilter::apply`]: its buffers are only reallocated when the
/// image size changes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FilterOutput {
    /// Outcome per pixel, row-major.
    pub outcomes: Vec<PixelOutcome>,
    /// Output radial range per pixel, metres (0 when dropped).
    pub radial: Vec<f32>,
    /// How many pixels were kept, unwrapped, dropped.
    pub counts: OutcomeCounts,
}

/// How many pixels ended in each [`PixelOutcome`].
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct OutcomeCounts {
    /// Kept as measured.
    pub kept: usize,
    /// Unwrapped.
    pub unwrapped: usize,
    /// Dropped (including pixels without a measurement).
    pub dropped: usize,
}

impl OutcomeCounts {
    /// All pixels.
    pub fn total(&self) -> usize {
        self.kept + self.unwrapped + self.dropped
    }

    /// The thesis's metric: the percentage of discarded pixels ("d. p.", Table 2.4).
    pub fn discarded_percent(&self) -> Real {
        if self.total() == 0 { 0.0 } else { 100.0 * self.dropped as Real / self.total() as Real }
    }

    /// Counts `outcomes`.
    pub fn of(outcomes: &[PixelOutcome]) -> OutcomeCounts {
        let mut c = OutcomeCounts::default();
        for o in outcomes {
            match o {
                PixelOutcome::Kept => c.kept += 1,
                PixelOutcome::Unwrapped => c.unwrapped += 1,
                PixelOutcome::Dropped => c.dropped += 1,
            }
        }
        c
    }
}

impl FilterOutput {
    /// Reset for `n` pixels (keeps the allocations).
    pub fn reset(&mut self, n: usize) {
        self.outcomes.clear();
        self.outcomes.resize(n, PixelOutcome::Dropped);
        self.radial.clear();
        self.radial.resize(n, 0.0);
        self.counts = OutcomeCounts::default();
    }

    /// Recounts [`FilterOutput::counts`] from the outcomes (after editing them by hand).
    pub fn recount(&mut self) {
        self.counts = OutcomeCounts::of(&self.outcomes);
    }

    /// Appends the output point of every non-dropped pixel (camera optical frame) to `points`,
    /// with its pixel index to `pixels`. No allocation if the vectors have room.
    pub fn points_into(
        &self,
        tables: &RayTables,
        points: &mut Vec<[f32; 3]>,
        pixels: &mut Vec<u32>,
    ) {
        let n = self.outcomes.len().min(tables.unit.len());
        let (p0, q0) = (points.len(), pixels.len());
        points.resize(p0 + n, [0.0; 3]);
        pixels.resize(q0 + n, 0);
        let (pts, pix) = (&mut points[p0..], &mut pixels[q0..]);
        // Write every pixel, advance only past output ones (no unpredictable branch).
        let mut j = 0;
        for i in 0..n {
            let (d, r) = (tables.unit[i], self.radial[i]);
            pts[j] = [d[0] * r, d[1] * r, d[2] * r];
            pix[j] = i as u32;
            j += self.outcomes[i].is_output() as usize;
        }
        points.truncate(p0 + j);
        pixels.truncate(q0 + j);
    }

    /// The point cloud of the output: every non-dropped pixel (or every measured pixel when
    /// `include_dropped`, dropped ones at their reported range), organised on the camera's
    /// grid, with the fields `outcome` (u8: 0 kept, 1 unwrapped, 2 dropped) and `pixel` (u32,
    /// row-major index), and the amplitude as intensity.
    pub fn to_cloud(&self, frame: &TofFrame, include_dropped: bool) -> PointCloud {
        let camera = frame.camera();
        let tables = RayTables::new(camera);
        let n = camera.num_pixels();
        let mut chosen = Vec::new();
        let pixels = (0..n).map(|i| {
            let r = match self.outcomes[i] {
                PixelOutcome::Dropped if include_dropped && frame.range()[i] > 0.0 => {
                    frame.radial(i) as f32
                }
                PixelOutcome::Dropped => return None,
                _ => self.radial[i],
            };
            chosen.push(i);
            let d = tables.unit[i];
            Some(pointcloud::Point3::new(
                (d[0] * r) as Real,
                (d[1] * r) as Real,
                (d[2] * r) as Real,
            ))
        });
        let mut cloud =
            PointCloud::from_pixels(camera.width, camera.height, pixels.collect::<Vec<_>>())
                .expect("finite points, consistent grid");
        let amplitude = chosen.iter().map(|&i| frame.amplitude()[i]).collect();
        cloud.set_intensity(Some(amplitude)).expect("one value per point");
        let outcome = FieldData::U8(chosen.iter().map(|&i| self.outcomes[i] as u8).collect());
        cloud
            .push_extra_field(ScalarField { name: "outcome".into(), data: outcome })
            .expect("one per point");
        let pixel = FieldData::U32(chosen.iter().map(|&i| i as u32).collect());
        cloud
            .push_extra_field(ScalarField { name: "pixel".into(), data: pixel })
            .expect("one per point");
        cloud
    }
}

/// Per-pixel ray tables of a camera, in `f32` for the per-frame loops: the unit beam direction
/// and the factor `radial / depth`.
#[derive(Clone, Debug, PartialEq)]
pub struct RayTables {
    /// Unit direction per pixel (optical frame).
    pub unit: Vec<[f32; 3]>,
    /// `|ray|` with the ray scaled to z = 1: radial = depth × this.
    pub radial_per_depth: Vec<f32>,
}

impl RayTables {
    /// The tables of `camera`.
    pub fn new(camera: &TofCamera) -> RayTables {
        let n = camera.num_pixels();
        let mut unit = Vec::with_capacity(n);
        let mut radial_per_depth = Vec::with_capacity(n);
        for row in 0..camera.height {
            for col in 0..camera.width {
                let ray = camera.ray(col, row);
                let norm = ray.norm();
                unit.push([(ray.x / norm) as f32, (ray.y / norm) as f32, (1.0 / norm) as f32]);
                radial_per_depth.push(norm as f32);
            }
        }
        RayTables { unit, radial_per_depth }
    }
}

/// Fails with [`TofError::Mismatch`] unless `frame` has the size of `camera` and range `kind`
/// that `what` (a filter, an unwrapper) was prepared for.
pub(crate) fn check_prepared(
    frame: &TofFrame,
    camera: &TofCamera,
    kind: RangeKind,
    what: &str,
) -> Result<(), TofError> {
    let c = frame.camera();
    if (c.width, c.height) != (camera.width, camera.height) || frame.kind() != kind {
        return Err(TofError::Mismatch {
            why: format!(
                "frame {} × {} {:?}, {what} prepared for {} × {} {:?}",
                c.width,
                c.height,
                frame.kind(),
                camera.width,
                camera.height,
                kind
            ),
        });
    }
    Ok(())
}

/// A filter prepared for one camera and range kind: per-pixel limits and ray tables computed
/// once, then [`TofFilter::apply`] per frame.
#[derive(Clone, Debug)]
pub struct TofFilter {
    camera: TofCamera,
    kind: RangeKind,
    config: FilterConfig,
    tables: RayTables,
    /// Per pixel the AAT limit `aw_p · AAT` (for the AT: the threshold, constant).
    limit: Vec<f32>,
    /// AAT with the radial range (else depth, else the AT / none).
    mode: Mode,
    non_ambiguity: f32,
    /// A table of ones (radial input needs no conversion).
    ones: Vec<f32>,
}

#[derive(Copy, Clone, Debug, PartialEq)]
enum Mode {
    None,
    At,
    AatDepth,
    AatRadial,
}

impl TofFilter {
    /// Prepares `config` for frames of `camera` whose ranges are of `kind`. Fails on absurd
    /// parameters (negative or non-finite thresholds, a table of the wrong size, a clamp ≤ 0,
    /// unwrapping without an AAT).
    pub fn new(
        camera: &TofCamera,
        kind: RangeKind,
        config: &FilterConfig,
    ) -> Result<TofFilter, TofError> {
        camera.validate()?;
        let bad = |what: &'static str, why: String| Err(TofError::BadParameter { what, why });
        let n = camera.num_pixels();
        let (mode, limit) = match &config.detector {
            Detector::None => (Mode::None, vec![0.0; n]),
            Detector::At(t) => {
                if !(t.is_finite() && *t >= 0.0) {
                    return bad("amplitude threshold", format!("{t} (want finite ≥ 0)"));
                }
                (Mode::At, vec![*t as f32; n])
            }
            Detector::Aat(aat) => {
                if !(aat.threshold.is_finite() && aat.threshold >= 0.0) {
                    return bad("AAT", format!("{} (want finite ≥ 0)", aat.threshold));
                }
                if let NegativeIllumination::Clamp(m) = aat.negative
                    && !(m.is_finite() && m > 0.0)
                {
                    return bad("illumination clamp", format!("{m} (want finite > 0)"));
                }
                let aw = illumination_table(&aat.illumination, camera)?;
                let limit = aw
                    .iter()
                    .map(|&a| {
                        let a = match aat.negative {
                            NegativeIllumination::Literal => a,
                            NegativeIllumination::Clamp(m) => a.max(m),
                        };
                        (a * aat.threshold) as f32
                    })
                    .collect();
                let mode = match aat.range {
                    AatRange::Depth => Mode::AatDepth,
                    AatRange::Radial => Mode::AatRadial,
                };
                (mode, limit)
            }
        };
        if let Some(u) = &config.unwrap {
            if !matches!(mode, Mode::AatDepth | Mode::AatRadial) {
                return bad(
                    "unwrap",
                    "unwrapping needs the AAT: a plain AT flags dark pixels at any range".into(),
                );
            }
            if let Some(t) = u.low_at
                && !(t.is_finite() && t >= 0.0)
            {
                return bad("low amplitude threshold", format!("{t} (want finite ≥ 0)"));
            }
        }
        Ok(TofFilter {
            camera: *camera,
            kind,
            config: config.clone(),
            tables: RayTables::new(camera),
            limit,
            mode,
            non_ambiguity: camera.non_ambiguity_range() as f32,
            ones: vec![1.0; n],
        })
    }

    /// The camera.
    pub fn camera(&self) -> &TofCamera {
        &self.camera
    }

    /// The configuration.
    pub fn config(&self) -> &FilterConfig {
        &self.config
    }

    /// The ray tables.
    pub fn tables(&self) -> &RayTables {
        &self.tables
    }

    /// Filters `frame` into `out` (buffers reused). Fails if the frame is of another camera
    /// size or range kind than the filter was prepared for.
    pub fn apply(&self, frame: &TofFrame, out: &mut FilterOutput) -> Result<(), TofError> {
        check_prepared(frame, &self.camera, self.kind, "filter")?;
        let n = self.camera.num_pixels();
        out.reset(n);
        // No unwrapping: no flagged pixel passes `a > +∞`; unwrapping without a low AT: all do.
        let low = self
            .config
            .unwrap
            .map_or(f32::INFINITY, |u| u.low_at.map_or(f32::NEG_INFINITY, |t| t as f32));
        let (range, amplitude) = (frame.range(), frame.amplitude());
        let limit = &self.limit[..n];
        // One branch-free loop per test, so the per-pixel decision compiles to selects.
        let counts = match (self.mode, self.kind) {
            (Mode::None, _) => self.decide(range, amplitude, low, out, |_, _, _| true),
            (Mode::At, _) => self.decide(range, amplitude, low, out, |i, a, _| a > limit[i]),
            (Mode::AatDepth, RangeKind::Depth) => {
                self.decide(range, amplitude, low, out, |i, a, r| a * r * r > limit[i])
            }
            (Mode::AatRadial, RangeKind::Radial) => {
                self.decide(range, amplitude, low, out, |i, a, r| a * r * r > limit[i])
            }
            // The test wants the other kind of range than the frame holds: convert per pixel.
            (Mode::AatDepth, RangeKind::Radial) => {
                let k = &self.tables.radial_per_depth[..n];
                self.decide(range, amplitude, low, out, |i, a, r| {
                    let z = r / k[i];
                    a * z * z > limit[i]
                })
            }
            (Mode::AatRadial, RangeKind::Depth) => {
                let k = &self.tables.radial_per_depth[..n];
                self.decide(range, amplitude, low, out, |i, a, r| {
                    let q = r * k[i];
                    a * q * q > limit[i]
                })
            }
        };
        out.counts = counts;
        Ok(())
    }

    /// The per-pixel loop: `valid(i, amplitude, reported range)` is the detector. Writes the
    /// outcome and output radial range of every pixel and returns the counts.
    #[inline(always)]
    fn decide(
        &self,
        range: &[f32],
        amplitude: &[f32],
        low: f32,
        out: &mut FilterOutput,
        valid: impl Fn(usize, f32, f32) -> bool,
    ) -> OutcomeCounts {
        let n = range.len();
        let to_radial = if self.kind == RangeKind::Depth {
            &self.tables.radial_per_depth[..n]
        } else {
            &self.ones[..n]
        };
        let (outcomes, radial_out) = (&mut out.outcomes[..n], &mut out.radial[..n]);
        let amplitude = &amplitude[..n];
        let (mut kept, mut unwrapped) = (0u32, 0u32);
        for i in 0..n {
            let (r, a) = (range[i], amplitude[i]);
            // Integer arithmetic instead of branches: the decisions are data-dependent.
            let measured = (r > 0.0) as u8;
            let ok = valid(i, a, r) as u8;
            let keep = measured & ok;
            let unwrap = measured & (1 - ok) & ((a > low) as u8);
            let radial =
                (r * to_radial[i] + self.non_ambiguity * unwrap as f32) * ((keep | unwrap) as f32);
            radial_out[i] = radial;
            outcomes[i] = match 2 - 2 * keep - unwrap {
                0 => PixelOutcome::Kept,
                1 => PixelOutcome::Unwrapped,
                _ => PixelOutcome::Dropped,
            };
            kept += keep as u32;
            unwrapped += unwrap as u32;
        }
        let (kept, unwrapped) = (kept as usize, unwrapped as usize);
        OutcomeCounts { kept, unwrapped, dropped: n - kept - unwrapped }
    }

    /// [`TofFilter::apply`] into a new output.
    pub fn run(&self, frame: &TofFrame) -> Result<FilterOutput, TofError> {
        let mut out = FilterOutput::default();
        self.apply(frame, &mut out)?;
        Ok(out)
    }
}

/// `aw_p` of every pixel of `camera` (row-major).
pub fn illumination_table(
    illumination: &Illumination,
    camera: &TofCamera,
) -> Result<Vec<Real>, TofError> {
    match illumination {
        Illumination::Parabola(p) => {
            p.validate()?;
            let mut v = Vec::with_capacity(camera.num_pixels());
            for row in 0..camera.height {
                for col in 0..camera.width {
                    v.push(p.eval(col as Real, row as Real));
                }
            }
            Ok(v)
        }
        Illumination::Table(t) => {
            if (t.width, t.height) != (camera.width, camera.height)
                || t.values.len() != camera.num_pixels()
            {
                return Err(TofError::BadParameter {
                    what: "white-wall table",
                    why: format!(
                        "{} × {} with {} values for a {} × {} camera",
                        t.width,
                        t.height,
                        t.values.len(),
                        camera.width,
                        camera.height
                    ),
                });
            }
            if let Some(i) = t.values.iter().position(|v| !v.is_finite()) {
                return Err(TofError::BadParameter {
                    what: "white-wall table",
                    why: format!("pixel {i} holds {}", t.values[i]),
                });
            }
            Ok(t.values.iter().map(|&v| v as Real).collect())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pointcloud::PinholeIntrinsics;

    fn camera() -> TofCamera {
        TofCamera::sr3000()
    }

    /// A frame where every pixel sees a surface of reflectivity `rho` (relative to the white
    /// wall) at true radial distance `true_r`, with the SR-3000 parabola as illumination.
    fn flat_frame(rho: Real, true_r: Real) -> TofFrame {
        let c = camera();
        let amb = c.non_ambiguity_range();
        let p = Parabola::sr3000();
        let mut range = Vec::new();
        let mut amp = Vec::new();
        for row in 0..c.height {
            for col in 0..c.width {
                let k = c.ray(col, row).norm();
                range.push((true_r.rem_euclid(amb) / k) as f32); // depth
                // Amplitude falls with the true depth squared (the thesis's model).
                let z = true_r / k;
                amp.push((rho * p.eval(col as Real, row as Real).max(0.0) / (z * z)) as f32);
            }
        }
        TofFrame::new(c, RangeKind::Depth, range, amp).unwrap()
    }

    #[test]
    fn aat_keeps_bright_near_pixels_and_drops_wrapped_ones() {
        let f =
            TofFilter::new(&camera(), RangeKind::Depth, &FilterConfig::aat(AatConfig::sr3000()))
                .unwrap();
        // A wall of 50 % reflectivity at 3 m: apparent reflectivity 0.5 > 0.2 everywhere.
        let out = f.run(&flat_frame(0.5, 3.0)).unwrap();
        assert_eq!(out.counts.kept, camera().num_pixels());
        // The same wall at 9 m wraps to 1.5 m: apparent reflectivity 0.5·(1.5/9)² ≈ 0.014.
        let out = f.run(&flat_frame(0.5, 9.0)).unwrap();
        // Only the corners where aw_p < 0 pass (Eq 2.4 taken literally).
        let aw =
            illumination_table(&Illumination::Parabola(Parabola::sr3000()), &camera()).unwrap();
        let negative = aw.iter().filter(|&&a| a <= 0.0).count();
        assert!(negative > 0);
        assert_eq!(out.counts.kept, negative);
        // Clamping aw_p tests the corners too: nothing wrapped survives.
        let mut cfg = AatConfig::sr3000();
        cfg.negative = NegativeIllumination::Clamp(1.0);
        let f = TofFilter::new(&camera(), RangeKind::Depth, &FilterConfig::aat(cfg)).unwrap();
        assert_eq!(f.run(&flat_frame(0.5, 9.0)).unwrap().counts.kept, 0);
    }

    #[test]
    fn unwrapping_restores_the_true_range() {
        let mut cfg = AatConfig::sr3000();
        cfg.negative = NegativeIllumination::Clamp(1.0);
        let f = TofFilter::new(&camera(), RangeKind::Depth, &FilterConfig::aat_unwrap(cfg, None))
            .unwrap();
        let out = f.run(&flat_frame(0.5, 9.0)).unwrap();
        assert_eq!(out.counts.unwrapped, camera().num_pixels());
        for &r in &out.radial {
            assert!((r - 9.0).abs() < 1e-3, "{r}");
        }
        // The low AT drops the darkest flagged pixels instead (the dim corners).
        let mut cfg = AatConfig::sr3000();
        cfg.negative = NegativeIllumination::Clamp(1.0);
        let f =
            TofFilter::new(&camera(), RangeKind::Depth, &FilterConfig::aat_unwrap(cfg, Some(60.0)))
                .unwrap();
        let out = f.run(&flat_frame(0.5, 9.0)).unwrap();
        assert!(out.counts.dropped > 0 && out.counts.unwrapped > 0, "{:?}", out.counts);
        assert_eq!(out.counts.total(), camera().num_pixels());
    }

    #[test]
    fn plain_at_and_outputs() {
        let f = TofFilter::new(&camera(), RangeKind::Depth, &FilterConfig::at(160.0)).unwrap();
        let frame = flat_frame(0.5, 3.0);
        let out = f.run(&frame).unwrap();
        let expect = frame.amplitude().iter().filter(|&&a| a > 160.0).count();
        assert_eq!(out.counts.kept, expect);
        assert!(out.counts.dropped > 0, "the dim edges fall below AT 160");
        let cloud = out.to_cloud(&frame, false);
        assert_eq!(cloud.len(), expect);
        assert!(cloud.extra_field("outcome").is_some() && cloud.extra_field("pixel").is_some());
        let all = out.to_cloud(&frame, true);
        assert_eq!(all.len(), frame.num_measured());
        let (mut pts, mut px) = (Vec::new(), Vec::new());
        out.points_into(f.tables(), &mut pts, &mut px);
        assert_eq!(pts.len(), expect);
        for (p, q) in pts.iter().zip(cloud.positions()) {
            assert!((p[2] as Real - q.z).abs() < 1e-4);
        }
    }

    #[test]
    fn absurd_filters_are_refused() {
        let c = camera();
        assert!(TofFilter::new(&c, RangeKind::Depth, &FilterConfig::at(Real::NAN)).is_err());
        let mut cfg = FilterConfig::at(100.0);
        cfg.unwrap = Some(UnwrapConfig { low_at: None });
        assert!(TofFilter::new(&c, RangeKind::Depth, &cfg).is_err());
        let mut aat = AatConfig::sr3000();
        aat.threshold = -1.0;
        assert!(TofFilter::new(&c, RangeKind::Depth, &FilterConfig::aat(aat)).is_err());
        let mut aat = AatConfig::sr3000();
        aat.illumination =
            Illumination::Table(WhiteWallTable { width: 3, height: 3, values: vec![1.0; 9] });
        assert!(TofFilter::new(&c, RangeKind::Depth, &FilterConfig::aat(aat)).is_err());
        let mut aat = AatConfig::sr3000();
        aat.negative = NegativeIllumination::Clamp(0.0);
        assert!(TofFilter::new(&c, RangeKind::Depth, &FilterConfig::aat(aat)).is_err());
        // A frame of another kind than prepared for.
        let f = TofFilter::new(&c, RangeKind::Radial, &FilterConfig::at(1.0)).unwrap();
        assert!(f.run(&flat_frame(0.5, 3.0)).is_err());
    }

    #[test]
    fn radial_and_depth_inputs_give_the_same_output() {
        let frame = flat_frame(0.3, 5.0);
        let radial = frame.converted(RangeKind::Radial);
        let cfg = FilterConfig::aat_unwrap(AatConfig::sr3000(), None);
        let a = TofFilter::new(&camera(), RangeKind::Depth, &cfg).unwrap().run(&frame).unwrap();
        let b = TofFilter::new(&camera(), RangeKind::Radial, &cfg).unwrap().run(&radial).unwrap();
        assert_eq!(a.outcomes, b.outcomes);
        for (x, y) in a.radial.iter().zip(&b.radial) {
            assert!((x - y).abs() < 1e-4);
        }
    }

    /// Eq 2.4 and the unwrapping rule evaluated literally in f64, pixel by pixel: the oracle of
    /// the branch-free loop.
    fn reference(frame: &TofFrame, cfg: &FilterConfig) -> Vec<(PixelOutcome, Real)> {
        let c = frame.camera();
        let aw = match &cfg.detector {
            Detector::Aat(a) => illumination_table(&a.illumination, c).unwrap(),
            _ => vec![0.0; c.num_pixels()],
        };
        (0..c.num_pixels())
            .map(|i| {
                let a = frame.amplitude()[i] as Real;
                if frame.range()[i] <= 0.0 {
                    return (PixelOutcome::Dropped, 0.0);
                }
                let valid = match &cfg.detector {
                    Detector::None => true,
                    Detector::At(t) => a > *t,
                    Detector::Aat(x) => {
                        let r = match x.range {
                            AatRange::Depth => frame.depth(i),
                            AatRange::Radial => frame.radial(i),
                        };
                        let w = match x.negative {
                            NegativeIllumination::Literal => aw[i],
                            NegativeIllumination::Clamp(m) => aw[i].max(m),
                        };
                        a > w * x.threshold / (r * r)
                    }
                };
                if valid {
                    (PixelOutcome::Kept, frame.radial(i))
                } else if let Some(u) = cfg.unwrap
                    && u.low_at.is_none_or(|t| a > t)
                {
                    (PixelOutcome::Unwrapped, frame.radial(i) + c.non_ambiguity_range())
                } else {
                    (PixelOutcome::Dropped, 0.0)
                }
            })
            .collect()
    }

    proptest::proptest! {
        #[test]
        fn fast_filter_matches_the_literal_rule(
            seed in 0u64..1000,
            radial_input in proptest::bool::ANY,
            radial_test in proptest::bool::ANY,
            clamp in proptest::bool::ANY,
            unwrap in 0u8..3,
            at in proptest::option::of(0.0..400.0f64),
        ) {
            use rand::{Rng, SeedableRng};
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
            let c = TofCamera::pinhole(17, 13, PinholeIntrinsics { fx: 8.0, fy: 8.0, cx: 8.0, cy: 6.0 }, 20e6).unwrap();
            let n = c.num_pixels();
            let range: Vec<f32> =
                (0..n).map(|_| if rng.random_bool(0.1) { 0.0 } else { rng.random_range(0.05..7.5f32) }).collect();
            let amp: Vec<f32> = (0..n).map(|_| rng.random_range(0.0..3000.0f32)).collect();
            let kind = if radial_input { RangeKind::Radial } else { RangeKind::Depth };
            let frame = TofFrame::new(c, kind, range, amp).unwrap();
            let cfg = match at {
                Some(t) => FilterConfig::at(t),
                None => {
                    let mut a = AatConfig::sr3000();
                    a.illumination = Illumination::Parabola(Parabola { a_hat: 150.0, delta_x: 8.0, delta_y: 4.0, curvature: 1.0 });
                    a.range = if radial_test { AatRange::Radial } else { AatRange::Depth };
                    if clamp { a.negative = NegativeIllumination::Clamp(5.0) }
                    let low = match unwrap { 0 => None, 1 => Some(None), _ => Some(Some(100.0)) };
                    FilterConfig { detector: Detector::Aat(a), unwrap: low.map(|low_at| UnwrapConfig { low_at }) }
                }
            };
            let out = TofFilter::new(&c, kind, &cfg).unwrap().run(&frame).unwrap();
            let want = reference(&frame, &cfg);
            let mut differ = 0;
            for (i, (o, r)) in want.iter().enumerate() {
                if out.outcomes[i] != *o {
                    differ += 1; // a tie within f32 rounding may go either way
                } else {
                    proptest::prop_assert!((out.radial[i] as Real - r).abs() < 1e-4 * (1.0 + r), "pixel {}", i);
                }
            }
            proptest::prop_assert!(differ <= 1, "{} of {} outcomes differ", differ, n);
            proptest::prop_assert_eq!(out.counts, OutcomeCounts::of(&out.outcomes));
        }
    }
}
