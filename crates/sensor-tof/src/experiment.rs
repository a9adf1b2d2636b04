//! The thesis's evaluation of the AAT (§2.5.6, Table 2.4) on our simulated scenes, with the
//! metrics the thesis could not compute (it had no ground truth, spec §2): for every method
//! the % discarded pixels, the % wrong pixels among those kept, the % wrapped pixels correctly
//! unwrapped, and the RMSE of the output; plus the same detection on a real frame whose
//! distances we fold at a chosen non-ambiguity range ([`fold_frame`]).
//!
//! `cargo xtask bench tof` runs it and prints [`table_2_4`] and [`quality_table`].

use crate::regions::{RegionConfig, RegionUnwrapper, ScatterGate};
use crate::scenes::TofScene;
use crate::sim::{SimulatedFrame, TofSimulator};
use crate::spatial::{SpatialConfig, reconsider};
use crate::two_freq::{TwoFreqConfig, TwoFreqUnwrapper};
use crate::{
    AatConfig, FilterConfig, FilterOutput, FrameTruth, Illumination, Score, TofCamera, TofError,
    TofFilter, TofFrame, eval::recoverable_percent, score,
};
use pointcloud::{RangeKind, Real};
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// A pixel is correct iff output within this many metres of the truth (the 5 cm).
pub const TOLERANCE_M: Real = 0.05;

/// One method of the comparison.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Method {
    /// The SwissRanger's plain amplitude threshold.
    At(Real),
    /// The AAT with the thesis's parameters (AAT 0.2, the camera's illumination), dropping.
    Aat,
    /// The AAT with `aw_p` clamped to at least the given value (spec §6.2: the corners where the
    /// parabola is negative are tested too) and/or the radial range in Eq 2.4 (spec §6.1).
    AatVariant {
        /// [`crate::NegativeIllumination::Clamp`] value, if any.
        clamp: Option<Real>,
        /// Use the radial distance instead of the depth.
        radial: bool,
    },
    /// The AAT with unwrapping (no low AT).
    AatUnwrap,
    /// The AAT with unwrapping after a low plain AT of the given value (L2446–2452): darker
    /// flagged pixels are dropped instead of unwrapped.
    AatUnwrapLowAt(Real),
    /// The AAT with unwrapping (after an optional low AT), then the spatial consistency check
    /// ([`crate::spatial`]) with the given isolation support (0: off).
    AatUnwrapSpatial {
        /// The low plain AT before unwrapping.
        low_at: Option<Real>,
        /// [`SpatialConfig::isolation_support`].
        isolation_support: u32,
    },
    /// Two-frequency unwrapping (the frame and a second one at the configured frequency).
    TwoFreq,
    /// Region unwrapping ([`crate::regions`]) with these parameters; its `aat` is replaced by
    /// the experiment's AAT (the camera's illumination, or the tuned flat one of a real frame).
    Regions(Box<RegionConfig>),
}

impl Method {
    /// The methods of the issue, in table order: AT 160, AT 240, AAT (literal, clamped,
    /// radial), AAT + unwrap (without and with a low AT), two-frequency, AAT + unwrap + spatial
    /// check, region unwrapping.
    pub fn all() -> Vec<Method> {
        vec![
            Method::At(160.0),
            Method::At(240.0),
            Method::Aat,
            Method::AatVariant { clamp: Some(480.0), radial: false },
            Method::AatVariant { clamp: None, radial: true },
            Method::AatUnwrap,
            Method::AatUnwrapLowAt(20.0),
            Method::TwoFreq,
            Method::AatUnwrapSpatial { low_at: Some(20.0), isolation_support: 3 },
            Method::regions(),
        ]
    }

    /// Region unwrapping with the parameters of [`RegionConfig::simulated_sr3000`] (the
    /// demo's).
    pub fn regions() -> Method {
        Method::Regions(Box::new(RegionConfig::simulated_sr3000(AatConfig::sr3000())))
    }

    /// A short column name.
    pub fn name(&self) -> String {
        match self {
            Method::At(t) => format!("AT {t:.0}"),
            Method::Aat => "AAT".into(),
            Method::AatVariant { clamp, radial } => format!(
                "AAT({})",
                [clamp.map(|c| format!("aw>={c}")), radial.then(|| "radial".to_string())]
                    .into_iter()
                    .flatten()
                    .collect::<Vec<_>>()
                    .join(",")
            ),
            Method::AatUnwrap => "AAT+unwrap".into(),
            Method::AatUnwrapLowAt(t) => format!("AAT+AT{t:.0}+unwrap"),
            Method::AatUnwrapSpatial { low_at, isolation_support } => format!(
                "AAT+{}unwrap+spatial{}",
                low_at.map_or(String::new(), |t| format!("AT{t:.0}+")),
                if *isolation_support > 0 {
                    format!("(i{isolation_support})")
                } else {
                    String::new()
                }
            ),
            Method::TwoFreq => "two-freq".into(),
            Method::Regions(_) => "regions".into(),
        }
    }
}

/// One method's result on one frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MethodResult {
    /// [`Method::name`].
    pub method: String,
    /// The scores.
    pub score: Score,
    /// Time of the method on this frame, milliseconds (filtering only).
    pub millis: Real,
}

/// The thesis's % discarded pixels of one scene (Table 2.4).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ThesisDiscarded {
    /// AAT.
    pub aat: Real,
    /// AT 160.
    pub at160: Real,
    /// AT 240 (not given for close boxes).
    pub at240: Option<Real>,
}

/// All methods on one scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SceneResult {
    /// Scene name.
    pub scene: String,
    /// % of pixels whose true surface lies beyond the non-ambiguity range.
    pub wrapped_percent: Real,
    /// The thesis's figures.
    pub thesis: ThesisDiscarded,
    /// The ceiling of any single-frame unwrapping that unwraps at most once: % of the measured
    /// pixels that some wrap count 0 or 1 puts within [`TOLERANCE_M`] of the truth
    /// ([`crate::eval::recoverable_percent`]).
    #[serde(default)]
    pub recoverable_percent: Real,
    /// The same with any wrap count.
    #[serde(default)]
    pub recoverable_any_percent: Real,
    /// One entry per method, in the order asked.
    pub results: Vec<MethodResult>,
}

impl SceneResult {
    /// The result of the method called `name`.
    pub fn get(&self, name: &str) -> Option<&MethodResult> {
        self.results.iter().find(|r| r.method == name)
    }
}

/// The AAT configuration matching a simulator: the thesis's threshold 0.2 with the camera's
/// illumination pattern as a calibration would find it (the simulator's `aw_p`).
pub fn aat_for(simulator: &TofSimulator) -> AatConfig {
    let c = simulator.config();
    let illumination = match &c.illumination {
        Illumination::Parabola(p) => {
            let mut p = *p;
            p.a_hat *= c.amplitude_scale;
            p.curvature *= c.amplitude_scale;
            Illumination::Parabola(p)
        }
        Illumination::Table(t) => {
            let mut t = t.clone();
            t.values.iter_mut().for_each(|v| *v *= c.amplitude_scale as f32);
            Illumination::Table(t)
        }
    };
    AatConfig { illumination, ..AatConfig::sr3000() }
}

fn measured(frame: &TofFrame) -> Vec<bool> {
    frame.range().iter().map(|&r| r > 0.0).collect()
}

/// Runs `methods` on one simulated scene (noise from `seed`) and scores them.
pub fn evaluate_scene(
    scene: &TofScene,
    methods: &[Method],
    seed: u64,
) -> Result<SceneResult, TofError> {
    let simulator = TofSimulator::new(scene.sim.clone())?;
    let two = TwoFreqConfig::sr3000();
    let needs_pair = methods.contains(&Method::TwoFreq);
    let (a, b): (SimulatedFrame, Option<SimulatedFrame>) = if needs_pair {
        let (a, b) = simulator.simulate_two_frequencies(
            &scene.scene,
            &scene.pose,
            two.frequency_b_hz,
            seed,
        )?;
        (a, Some(b))
    } else {
        (simulator.simulate(&scene.scene, &scene.pose, seed)?, None)
    };
    if needs_pair && (a.frame.camera().modulation_hz - two.frequency_a_hz).abs() > 1.0 {
        return Err(TofError::Mismatch {
            why: format!(
                "scene camera at {} Hz, two-frequency preset at {} Hz",
                a.frame.camera().modulation_hz,
                two.frequency_a_hz
            ),
        });
    }
    let aat = aat_for(&simulator);
    let results = methods
        .iter()
        .map(|m| run_method(m, &a.frame, b.as_ref().map(|b| &b.frame), &aat, &two, &a.truth))
        .collect::<Result<Vec<_>, _>>()?;
    let wrapped = a.truth.wraps.iter().filter(|&&w| w > 0).count();
    let (recoverable_percent, recoverable_any_percent) = ceilings(&a.frame, &a.truth);
    Ok(SceneResult {
        recoverable_percent,
        recoverable_any_percent,
        scene: scene.name.to_string(),
        wrapped_percent: 100.0 * wrapped as Real / a.truth.wraps.len().max(1) as Real,
        thesis: ThesisDiscarded {
            aat: scene.thesis.aat,
            at160: scene.thesis.at160,
            at240: scene.thesis.at240,
        },
        results,
    })
}

/// The goal for wrong output, % of the output (the 1 %).
pub const WRONG_LIMIT_PERCENT: Real = 1.0;

/// The wrong-output limit [`tune_regions`] tunes for on the training frames, % of the output:
/// half the goal, a margin for what changes between the training and the scored frames.
pub const TUNING_WRONG_LIMIT_PERCENT: Real = 0.5;

/// The parameter values [`tune_regions`] tries (every combination), each field a list of
/// values of the [`RegionConfig`] field of the same name.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RegionGrid {
    /// [`RegionConfig::max_brightness`].
    pub max_brightness: Vec<Real>,
    /// [`RegionConfig::max_amplitude_ratio`].
    pub max_amplitude_ratio: Vec<Real>,
    /// [`RegionConfig::min_margin`].
    pub min_margin: Vec<Real>,
    /// [`RegionConfig::max_wraps`].
    pub max_wraps: Vec<u8>,
    /// [`RegionConfig::low_at`].
    pub low_at: Vec<Option<Real>>,
    /// [`RegionConfig::max_noise_m`].
    pub max_noise_m: Vec<Option<Real>>,
    /// [`RegionConfig::join_curvature_m`].
    pub join_curvature_m: Vec<Option<Real>>,
    /// [`RegionConfig::min_brightness`].
    pub min_brightness: Vec<Real>,
    /// [`RegionConfig::absorb_passes`].
    pub absorb_passes: Vec<u32>,
    /// [`RegionConfig::min_region_pixels`].
    pub min_region_pixels: Vec<usize>,
    /// [`RegionConfig::scattering`].
    pub scattering: Vec<Option<ScatterGate>>,
}

impl RegionGrid {
    /// The grid for the simulated SR-3000/3100 scenes (amplitudes in the simulator's units;
    /// the scattering gate with the simulator's scattering, as a calibration would find it).
    pub fn simulated() -> RegionGrid {
        RegionGrid {
            max_brightness: vec![6.0, 10.0],
            max_amplitude_ratio: vec![2.0, 3.0],
            min_margin: vec![0.2],
            max_wraps: vec![1],
            low_at: vec![None, Some(100.0), Some(200.0)],
            max_noise_m: vec![None, Some(0.02)],
            join_curvature_m: vec![None],
            min_brightness: vec![1.0],
            absorb_passes: vec![0, 3],
            min_region_pixels: vec![20],
            scattering: vec![None, Some(ScatterGate::sr3000())],
        }
    }

    /// The grid for a real frame folded at a short non-ambiguity range (ranges of a few
    /// non-ambiguity ranges, millimetre noise: no amplitude floor or noise gate).
    pub fn folded() -> RegionGrid {
        RegionGrid {
            max_brightness: vec![6.0, 10.0, 16.0],
            max_amplitude_ratio: vec![1.5, 3.0],
            min_margin: vec![0.2, 0.5],
            max_wraps: vec![1, 3],
            low_at: vec![None],
            max_noise_m: vec![None],
            join_curvature_m: vec![Some(0.005), Some(0.02)],
            min_brightness: vec![1.0, 0.5],
            absorb_passes: vec![0, 3],
            min_region_pixels: vec![20, 60, 150],
            scattering: vec![None],
        }
    }

    /// Every combination, each on a copy of `base`.
    pub fn configs(&self, base: &RegionConfig) -> Vec<RegionConfig> {
        let mut v = Vec::new();
        for &scattering in &self.scattering {
            for &size in &self.min_region_pixels {
                for &b in &self.max_brightness {
                    for &r in &self.max_amplitude_ratio {
                        for &m in &self.min_margin {
                            for &k in &self.max_wraps {
                                for &l in &self.low_at {
                                    for (&n, &c, &mb, &ab) in
                                        self.max_noise_m.iter().flat_map(|n| {
                                            self.join_curvature_m.iter().flat_map(move |c| {
                                                self.min_brightness.iter().flat_map(move |mb| {
                                                    self.absorb_passes
                                                        .iter()
                                                        .map(move |ab| (n, c, mb, ab))
                                                })
                                            })
                                        })
                                    {
                                        v.push(RegionConfig {
                                            join_curvature_m: c,
                                            min_brightness: mb,
                                            absorb_passes: ab,
                                            min_region_pixels: size,
                                            scattering,
                                            max_brightness: b,
                                            max_amplitude_ratio: r,
                                            min_margin: m,
                                            max_wraps: k,
                                            low_at: l,
                                            max_noise_m: n,
                                            ..base.clone()
                                        });
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
        v
    }
}

/// What [`tune_regions`] chose and how it did on the training frames.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TunedRegions {
    /// The chosen parameters (`aat` as in the base).
    pub config: RegionConfig,
    /// Mean yield over the training frames, %.
    pub train_yield_percent: Real,
    /// Largest wrong % of output over the training frames.
    pub train_max_wrong_percent: Real,
    /// Whether some combination kept every training frame at or below
    /// [`TUNING_WRONG_LIMIT_PERCENT`].
    pub within_limit: bool,
}

/// One training frame of [`tune_regions`]: the frame, its truth and its AAT.
pub type TrainingFrame = (TofFrame, FrameTruth, AatConfig);

/// Chooses region-unwrapping parameters on training frames: among the combinations of `grid`
/// (on `base`) that keep the wrong output of every frame at or below
/// [`TUNING_WRONG_LIMIT_PERCENT`],
/// the one with the highest mean yield; if none does, the one with the smallest largest wrong
/// share (ties: higher yield).
pub fn tune_regions(
    frames: &[TrainingFrame],
    base: &RegionConfig,
    grid: &RegionGrid,
) -> Result<TunedRegions, TofError> {
    let mut best: Option<TunedRegions> = None;
    for config in grid.configs(base) {
        let (mut yield_sum, mut worst) = (0.0, 0.0 as Real);
        for (frame, truth, aat) in frames {
            let c = RegionConfig { aat: aat.clone(), ..config.clone() };
            let out = RegionUnwrapper::new(frame.camera(), frame.kind(), &c)?.run(frame)?;
            let s = score(&out, &measured(frame), truth, TOLERANCE_M)?;
            yield_sum += s.yield_percent;
            worst = worst.max(s.wrong_kept_percent);
        }
        let cand = TunedRegions {
            config,
            train_yield_percent: yield_sum / frames.len().max(1) as Real,
            train_max_wrong_percent: worst,
            within_limit: worst <= TUNING_WRONG_LIMIT_PERCENT,
        };
        let better = match &best {
            None => true,
            Some(b) => match (cand.within_limit, b.within_limit) {
                (true, false) => true,
                (false, true) => false,
                (true, true) => cand.train_yield_percent > b.train_yield_percent,
                (false, false) => {
                    (cand.train_max_wrong_percent, -cand.train_yield_percent)
                        < (b.train_max_wrong_percent, -b.train_yield_percent)
                }
            },
        };
        if better {
            best = Some(cand);
        }
    }
    best.ok_or_else(|| TofError::BadParameter { what: "region grid", why: "empty".into() })
}

/// A simulated scene's frame (noise from `seed`), its truth and the AAT matching the
/// simulator ([`aat_for`]): a training frame for [`tune_regions`].
pub fn training_frame(scene: &TofScene, seed: u64) -> Result<TrainingFrame, TofError> {
    let simulator = TofSimulator::new(scene.sim.clone())?;
    let shot = simulator.simulate(&scene.scene, &scene.pose, seed)?;
    Ok((shot.frame, shot.truth, aat_for(&simulator)))
}

/// Region unwrapping tuned on the six simulated scenes of Table 2.4 with the noise of
/// `tune_seed` ([`tune_regions`] over [`RegionGrid::simulated`] on [`RegionConfig::new`]; each
/// scene's AAT from its simulator): the parameters to score on another seed.
pub fn tune_on_scenes(tune_seed: u64) -> Result<TunedRegions, TofError> {
    let frames = crate::scenes::all_scenes()?
        .iter()
        .map(|s| training_frame(s, tune_seed))
        .collect::<Result<Vec<_>, _>>()?;
    tune_regions(&frames, &RegionConfig::new(AatConfig::sr3000()), &RegionGrid::simulated())
}

/// [`SceneResult::recoverable_percent`] and [`SceneResult::recoverable_any_percent`].
fn ceilings(frame: &TofFrame, truth: &FrameTruth) -> (Real, Real) {
    let radial = frame.converted(RangeKind::Radial);
    let amb = frame.camera().non_ambiguity_range();
    let r = |k| recoverable_percent(radial.range(), truth, amb, k, TOLERANCE_M);
    (r(1), r(u8::MAX))
}

/// Runs one method on a frame (and the second-frequency frame for [`Method::TwoFreq`]) and
/// scores it against `truth`.
pub fn run_method(
    method: &Method,
    frame: &TofFrame,
    second: Option<&TofFrame>,
    aat: &AatConfig,
    two: &TwoFreqConfig,
    truth: &FrameTruth,
) -> Result<MethodResult, TofError> {
    let camera = frame.camera();
    let kind = frame.kind();
    let mut out = FilterOutput::default();
    // Prepare (tables, illumination) outside the timed part: `millis` is the per-frame work.
    let unwrap = match method {
        Method::AatUnwrap => Some(None),
        Method::AatUnwrapSpatial { low_at, .. } => Some(*low_at),
        Method::AatUnwrapLowAt(t) => Some(Some(*t)),
        _ => None,
    };
    let config = match (method, unwrap) {
        (Method::At(t), _) => Some(FilterConfig::at(*t)),
        (Method::Aat, _) => Some(FilterConfig::aat(aat.clone())),
        (Method::AatVariant { clamp, radial }, _) => {
            let mut a = aat.clone();
            if let Some(c) = clamp {
                a.negative = crate::NegativeIllumination::Clamp(*c);
            }
            if *radial {
                a.range = crate::AatRange::Radial;
            }
            Some(FilterConfig::aat(a))
        }
        (_, Some(low)) => Some(FilterConfig::aat_unwrap(aat.clone(), low)),
        _ => None,
    };
    let filter = config.as_ref().map(|c| TofFilter::new(camera, kind, c)).transpose()?;
    let spatial = match (method, &config) {
        (Method::AatUnwrapSpatial { isolation_support, .. }, Some(c)) => Some(SpatialConfig {
            isolation_support: *isolation_support,
            ..SpatialConfig::for_filter(c)
        }),
        _ => None,
    };
    let pair = match method {
        Method::TwoFreq => Some((
            second.ok_or_else(|| TofError::Mismatch {
                why: "two-frequency unwrapping needs a second frame".into(),
            })?,
            TwoFreqUnwrapper::new(camera, kind, two)?,
        )),
        _ => None,
    };
    let regions = match method {
        Method::Regions(r) => Some(RegionUnwrapper::new(
            camera,
            kind,
            &RegionConfig { aat: aat.clone(), ..(**r).clone() },
        )?),
        _ => None,
    };
    let t0 = Instant::now();
    if let Some(r) = &regions {
        r.apply(frame, &mut out)?;
    }
    if let Some(f) = &filter {
        f.apply(frame, &mut out)?;
        if let Some(sc) = &spatial {
            reconsider(frame, &mut out, sc, f.tables())?;
        }
    }
    if let Some((second, u)) = &pair {
        u.apply(frame, second, &mut out)?;
    }
    let millis = t0.elapsed().as_secs_f64() * 1e3;
    let score = score(&out, &measured(frame), truth, TOLERANCE_M)?;
    Ok(MethodResult { method: method.name(), score, millis })
}

/// A real frame's distances folded at `non_ambiguity_m` (what a single-frequency camera
/// modulated at `c / (2 R)` would report), its real amplitude kept: the folded frame (radial,
/// on a camera with that modulation frequency) and the truth (the original distances, wrap
/// counts). Pixels without a distance stay without one (truth `None`).
pub fn fold_frame(
    frame: &TofFrame,
    non_ambiguity_m: Real,
) -> Result<(TofFrame, FrameTruth), TofError> {
    if !(non_ambiguity_m.is_finite() && non_ambiguity_m > 0.0) {
        return Err(TofError::BadParameter {
            what: "non-ambiguity range",
            why: format!("{non_ambiguity_m} m (want finite > 0)"),
        });
    }
    let radial = frame.converted(RangeKind::Radial);
    let mut camera: TofCamera = *frame.camera();
    camera.modulation_hz = crate::SPEED_OF_LIGHT / (2.0 * non_ambiguity_m);
    camera.validate()?;
    let mut truth = FrameTruth::default();
    let mut range = Vec::with_capacity(radial.range().len());
    for &r in radial.range() {
        if r > 0.0 {
            let r = r as Real;
            truth.radial.push(Some(r as f32));
            truth.wraps.push((r / non_ambiguity_m).floor().min(255.0) as u8);
            // A folded value of exactly 0 would read as "no measurement".
            range.push((r.rem_euclid(non_ambiguity_m) as f32).max(1e-6));
        } else {
            truth.radial.push(None);
            truth.wraps.push(0);
            range.push(0.0);
        }
    }
    let folded = TofFrame::new(camera, RangeKind::Radial, range, radial.amplitude().to_vec())?;
    Ok((folded, truth))
}

/// How the methods did on a real frame folded at a chosen non-ambiguity range
/// ([`evaluate_folded`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FoldedResult {
    /// The non-ambiguity range the distances were folded at, metres.
    pub fold_m: Real,
    /// The second frame's fold, metres (two-frequency unwrapping).
    pub second_fold_m: Real,
    /// Measured pixels of the frame.
    pub measured: usize,
    /// % of the measured pixels that wrapped.
    pub wrapped_percent: Real,
    /// Thresholds tuned on the even rows: (method, threshold).
    pub thresholds: Vec<(String, Real)>,
    /// The region-unwrapping parameters tuned on the even rows ([`RegionGrid::folded`]).
    pub regions: TunedRegions,
    /// % of the measured pixels of the odd rows some wrap count 0 or 1 puts within
    /// [`TOLERANCE_M`] of the truth (the ceiling of unwrapping at most once).
    pub recoverable_percent: Real,
    /// The same with any wrap count.
    pub recoverable_any_percent: Real,
    /// Every method scored on the odd rows.
    pub results: Vec<MethodResult>,
}

/// The rows of `frame` with the given parity (0 even, 1 odd), as a frame of their own (for
/// tuning on one half and scoring on the other). The camera keeps its columns; rows are
/// halved (geometry is not used by the scores, which compare radial ranges).
fn rows_of(
    frame: &TofFrame,
    truth: &FrameTruth,
    parity: u32,
) -> Result<(TofFrame, FrameTruth), TofError> {
    let c = frame.camera();
    let w = c.width as usize;
    let rows: Vec<usize> = (0..c.height as usize).filter(|r| *r as u32 % 2 == parity).collect();
    let pick = |v: &[f32]| {
        rows.iter().flat_map(|&r| v[r * w..(r + 1) * w].iter().copied()).collect::<Vec<f32>>()
    };
    let mut camera = *c;
    camera.height = rows.len() as u32;
    camera.intrinsics.fy /= 2.0;
    camera.intrinsics.cy /= 2.0;
    let sub = TofFrame::new(camera, frame.kind(), pick(frame.range()), pick(frame.amplitude()))?;
    let t = FrameTruth {
        radial: rows
            .iter()
            .flat_map(|&r| truth.radial[r * w..(r + 1) * w].iter().copied())
            .collect(),
        wraps: rows.iter().flat_map(|&r| truth.wraps[r * w..(r + 1) * w].iter().copied()).collect(),
    };
    Ok((sub, t))
}

/// The threshold on `feature` (flag a pixel iff its feature is below the threshold) that
/// maximises Youden's J = true-positive rate − false-positive rate of flagging the wrapped
/// among the measured pixels. `None` if either class is empty.
fn best_threshold(feature: &[Real], wrapped: &[bool]) -> Option<Real> {
    let pos = wrapped.iter().filter(|&&w| w).count();
    let neg = wrapped.len() - pos;
    if pos == 0 || neg == 0 {
        return None;
    }
    let mut order: Vec<usize> = (0..feature.len()).collect();
    order.sort_by(|&a, &b| feature[a].total_cmp(&feature[b]));
    // Threshold just above order[k]: flags order[..=k].
    let (mut tp, mut fp, mut best, mut best_j) = (0usize, 0usize, None, 0.0);
    for (k, &i) in order.iter().enumerate() {
        if wrapped[i] {
            tp += 1
        } else {
            fp += 1
        }
        let next = order.get(k + 1).map(|&j| feature[j]);
        if next == Some(feature[i]) {
            continue; // ties flag together
        }
        let j = tp as Real / pos as Real - fp as Real / neg as Real;
        if j > best_j {
            best_j = j;
            best = Some(match next {
                Some(n) => (feature[i] + n) / 2.0,
                None => feature[i] * (1.0 + 1e-9) + 1e-12,
            });
        }
    }
    best
}

/// The detection experiment on a real frame whose distances are already unwrapped (the ifm
/// O3R frame of the real-data folder): fold the distances at `fold_m` ([`fold_frame`]), keep
/// the real amplitude, and run the AT, the AAT (a flat illumination model, since the camera has
/// no white-wall calibration: the test is `a · r² > T`), the AAT with unwrapping, with the
/// spatial check, and two-frequency unwrapping (a second fold at `second_fold_m`, both folds
/// with Gaussian noise of the frame's own per-pixel σ from `noise`, seeded). The AT and AAT
/// thresholds are tuned on the even rows (best Youden J for flagging wrapped pixels) and every
/// method is scored on the odd rows.
pub fn evaluate_folded(
    frame: &TofFrame,
    noise: Option<&[f32]>,
    fold_m: Real,
    second_fold_m: Real,
    seed: u64,
) -> Result<FoldedResult, TofError> {
    use rand::SeedableRng as _;
    use rand_distr::Distribution as _;
    let n = frame.range().len();
    if let Some(s) = noise
        && s.len() != n
    {
        return Err(TofError::Mismatch { why: format!("{} noise values for {n} pixels", s.len()) });
    }
    // Noisy copies of the true distances, one per fold.
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let radial = frame.converted(RangeKind::Radial);
    let mut noisy = |r: &TofFrame| -> Result<TofFrame, TofError> {
        let range = r
            .range()
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                let sigma = noise.map_or(0.0, |s| s[i] as Real);
                if v <= 0.0 || sigma <= 0.0 {
                    return v;
                }
                let e = rand_distr::Normal::new(0.0, sigma).map_or(0.0, |d| d.sample(&mut rng));
                ((v as Real + e).max(1e-4)) as f32
            })
            .collect();
        TofFrame::new(*r.camera(), RangeKind::Radial, range, r.amplitude().to_vec())
    };
    let (folded, truth) = fold_frame(&noisy(&radial)?, fold_m)?;
    let (second, _) = fold_frame(&noisy(&radial)?, second_fold_m)?;
    // The truth is the noise-free distance.
    let truth = FrameTruth { radial: fold_frame(&radial, fold_m)?.1.radial, wraps: truth.wraps };
    let (train, train_truth) = rows_of(&folded, &truth, 0)?;
    let (test, test_truth) = rows_of(&folded, &truth, 1)?;
    let (test2, _) = rows_of(&second, &truth, 1)?;
    let measured_train: Vec<usize> =
        (0..train.range().len()).filter(|&i| train.range()[i] > 0.0).collect();
    let wrapped: Vec<bool> = measured_train.iter().map(|&i| train_truth.wraps[i] > 0).collect();
    let feat_at: Vec<Real> = measured_train.iter().map(|&i| train.amplitude()[i] as Real).collect();
    let feat_aat: Vec<Real> = measured_train
        .iter()
        .map(|&i| {
            let r = train.range()[i] as Real;
            train.amplitude()[i] as Real * r * r
        })
        .collect();
    let at = best_threshold(&feat_at, &wrapped).unwrap_or(0.0);
    let t_aat = best_threshold(&feat_aat, &wrapped).unwrap_or(0.0);
    let flat = crate::Parabola { a_hat: 1.0, delta_x: 0.0, delta_y: 0.0, curvature: 0.0 };
    let aat = AatConfig {
        illumination: Illumination::Parabola(flat),
        threshold: t_aat,
        range: crate::AatRange::Radial,
        ..AatConfig::sr3000()
    };
    // The pair's phase noise from the frame's median σ at the shorter fold.
    let sigma = noise.map_or(0.0, |s| {
        let mut v: Vec<f32> =
            (0..n).filter(|&i| frame.range()[i] > 0.0 && s[i] > 0.0).map(|i| s[i]).collect();
        v.sort_by(f32::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(0.0) as Real
    });
    let phase_noise = std::f64::consts::TAU * sigma / fold_m.min(second_fold_m);
    let max_range = 2.0 * fold_m.max(second_fold_m);
    let two = TwoFreqConfig::for_pair(
        crate::SPEED_OF_LIGHT / (2.0 * fold_m),
        crate::SPEED_OF_LIGHT / (2.0 * second_fold_m),
        max_range,
        phase_noise,
    )?;
    let tuned = tune_regions(
        &[(train.clone(), train_truth.clone(), aat.clone())],
        &RegionConfig::new(aat.clone()),
        &RegionGrid::folded(),
    )?;
    let methods = [
        Method::At(at),
        Method::Aat,
        Method::AatUnwrap,
        Method::AatUnwrapSpatial { low_at: None, isolation_support: 0 },
        Method::AatUnwrapSpatial { low_at: None, isolation_support: 3 },
        Method::TwoFreq,
        Method::Regions(Box::new(tuned.config.clone())),
    ];
    let (recoverable_percent, recoverable_any_percent) = ceilings(&test, &test_truth);
    let results = methods
        .iter()
        .map(|m| run_method(m, &test, Some(&test2), &aat, &two, &test_truth))
        .collect::<Result<Vec<_>, _>>()?;
    let measured = folded.num_measured();
    let wrapped_n = (0..n).filter(|&i| folded.range()[i] > 0.0 && truth.wraps[i] > 0).count();
    Ok(FoldedResult {
        fold_m,
        second_fold_m,
        measured,
        wrapped_percent: 100.0 * wrapped_n as Real / measured.max(1) as Real,
        thresholds: vec![("AT".into(), at), ("AAT (a·r²)".into(), t_aat)],
        regions: tuned,
        recoverable_percent,
        recoverable_any_percent,
        results,
    })
}

fn mean_median(values: &[Real]) -> (Real, Real) {
    if values.is_empty() {
        return (Real::NAN, Real::NAN);
    }
    let mut v = values.to_vec();
    v.sort_by(|a, b| a.total_cmp(b));
    let mean = v.iter().sum::<Real>() / v.len() as Real;
    let m = v.len() / 2;
    let median = if v.len() % 2 == 1 { v[m] } else { (v[m - 1] + v[m]) / 2.0 };
    (mean, median)
}

/// Table 2.4 (% discarded pixels) in the thesis's layout, the thesis's three columns beside
/// ours for every method. The mean and median rows are computed (the thesis's printed medians
/// of AAT and AT 160 are swapped, spec §2; its AT 240 mean is over five scenes, as here).
pub fn table_2_4(results: &[SceneResult]) -> String {
    use std::fmt::Write as _;
    let methods: Vec<String> = results
        .first()
        .map(|r| r.results.iter().map(|m| m.method.clone()).collect())
        .unwrap_or_default();
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Table 2.4: discarded pixels [%] (thesis: SR-3100 lab snapshots; ours: simulated scenes, truth known)"
    );
    let _ =
        write!(s, "{:<14} {:>6} | {:>6} {:>6} {:>6} |", "scene", "wrap%", "AAT", "AT160", "AT240");
    for m in &methods {
        let _ = write!(s, " {:>w$}", m, w = m.len().max(6));
    }
    s.push('\n');
    let fmt_opt = |v: Option<Real>| v.map_or("–".to_string(), |v| format!("{v:.1}"));
    for r in results {
        let _ = write!(
            s,
            "{:<14} {:>6.1} | {:>6.1} {:>6.1} {:>6} |",
            r.scene,
            r.wrapped_percent,
            r.thesis.aat,
            r.thesis.at160,
            fmt_opt(r.thesis.at240)
        );
        for m in &methods {
            let v = r.get(m).map(|x| x.score.discarded_percent);
            let _ = write!(s, " {:>w$}", fmt_opt(v), w = m.len().max(6));
        }
        s.push('\n');
    }
    for (label, pick) in [("mean", 0usize), ("median", 1)] {
        let col = |f: &dyn Fn(&SceneResult) -> Option<Real>| {
            let v: Vec<Real> = results.iter().filter_map(f).collect();
            let (mean, median) = mean_median(&v);
            if pick == 0 { mean } else { median }
        };
        let _ = write!(
            s,
            "{:<14} {:>6.1} | {:>6.1} {:>6.1} {:>6.1} |",
            label,
            col(&|r| Some(r.wrapped_percent)),
            col(&|r| Some(r.thesis.aat)),
            col(&|r| Some(r.thesis.at160)),
            col(&|r| r.thesis.at240)
        );
        for m in &methods {
            let v = col(&|r| r.get(m).map(|x| x.score.discarded_percent));
            let _ = write!(s, " {:>w$.1}", v, w = m.len().max(6));
        }
        s.push('\n');
    }
    s
}

/// The view: per scene (or fold) and method the discarded %, the wrong % of output and
/// the yield (correct output pixels, % of the measured pixels), beside the scene's ceiling
/// (% of measured pixels any unwrapping by at most one non-ambiguity range could output
/// correctly; in brackets, with any number). Methods meeting both goals (wrong ≤ 1 %,
/// yield ≥ 80 %) are marked `*`.
pub fn yield_table(results: &[SceneResult]) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<18} {:>15} {:<28} {:>8} {:>8} {:>8}",
        "scene", "ceiling% (any)", "method", "disc.%", "wrong%", "yield%"
    );
    for r in results {
        for m in &r.results {
            let q = &m.score;
            let ok = q.wrong_kept_percent <= WRONG_LIMIT_PERCENT && q.yield_percent >= 80.0;
            let _ = writeln!(
                s,
                "{:<18} {:>6.1} ({:>6.1}) {:<28} {:>8.1} {:>8.2} {:>7.1}{}",
                r.scene,
                r.recoverable_percent,
                r.recoverable_any_percent,
                m.method,
                q.discarded_percent,
                q.wrong_kept_percent,
                q.yield_percent,
                if ok { "*" } else { "" }
            );
        }
    }
    s
}

impl FoldedResult {
    /// As a [`SceneResult`] named `real-folded-<fold>m`, for [`yield_table`] and
    /// [`quality_table`].
    pub fn as_scene(&self) -> SceneResult {
        SceneResult {
            scene: format!("real-folded-{}m", self.fold_m),
            wrapped_percent: self.wrapped_percent,
            thesis: ThesisDiscarded { aat: Real::NAN, at160: Real::NAN, at240: None },
            recoverable_percent: self.recoverable_percent,
            recoverable_any_percent: self.recoverable_any_percent,
            results: self.results.clone(),
        }
    }
}

/// What the thesis could not measure: per scene and method the % wrong pixels among those
/// output (and of those the gross errors, more than 1 m off), the % wrapped pixels correctly
/// unwrapped, the % of measurable pixels output
/// correctly, and the RMSE of the correct output (cm).
pub fn quality_table(results: &[SceneResult]) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<14} {:<28} {:>8} {:>8} {:>8} {:>10} {:>9} {:>9} {:>9} {:>8}",
        "scene",
        "method",
        "disc.%",
        "wrong%",
        "gross%",
        "wrapkept%",
        "unwrap%",
        "correct%",
        "rmse cm",
        "ms"
    );
    for r in results {
        for m in &r.results {
            let q = &m.score;
            let _ = writeln!(
                s,
                "{:<14} {:<28} {:>8.1} {:>8.2} {:>8.2} {:>10.2} {:>9.1} {:>9.1} {:>9.2} {:>8.3}",
                r.scene,
                m.method,
                q.discarded_percent,
                q.wrong_kept_percent,
                q.gross_percent,
                q.wrapped_kept_percent,
                q.unwrapped_correct_percent,
                q.correct_percent,
                100.0 * q.rmse_correct,
                m.millis
            );
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folding_keeps_the_truth() {
        let c = TofCamera::sr3000();
        let n = c.num_pixels();
        let range: Vec<f32> =
            (0..n).map(|i| if i % 7 == 0 { 0.0 } else { 0.3 + (i % 200) as f32 * 0.01 }).collect();
        let frame = TofFrame::new(c, RangeKind::Radial, range.clone(), vec![100.0; n]).unwrap();
        let (folded, truth) = fold_frame(&frame, 1.0).unwrap();
        assert!((folded.camera().non_ambiguity_range() - 1.0).abs() < 1e-9);
        for (i, &r) in range.iter().enumerate() {
            if r > 0.0 {
                let t = truth.radial[i].unwrap();
                assert_eq!(truth.wraps[i] as f32, t.floor());
                assert!((folded.range()[i] + truth.wraps[i] as f32 - t).abs() < 1e-5);
            } else {
                assert!(truth.radial[i].is_none() && folded.range()[i] == 0.0);
            }
        }
        assert!(fold_frame(&frame, 0.0).is_err());
    }

    #[test]
    fn medians_are_medians() {
        // The thesis's Table 2.4 AAT column: median 29.9, not the printed 44.8 (spec §2).
        let (mean, median) = mean_median(&[16.7, 21.7, 56.3, 38.1, 13.1, 44.9]);
        assert!((mean - 31.8).abs() < 0.05 && (median - 29.9).abs() < 1e-9);
    }
}
