//! Algorithm 3 (thesis §4.1.3, L3468–3520): floor, ramp, canyon, plateau or obstacle from the
//! accumulator, passability from the robot's limits (L3453–3460), and the preprocessing test
//! (L3601–3605, spec §6.10–6.11).

use crate::accumulator::Accumulator;
use crate::error::{HoughError, Result};
use crate::space::{Bin, HoughSpace, Plane};
use serde::{Deserialize, Serialize};

/// The five classes of the thesis (L3439–3452).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum TerrainClass {
    /// Flat ground at the robot's level.
    Floor,
    /// Inclined ground.
    Ramp,
    /// Even ground below the robot's level (a step down).
    Canyon,
    /// Even ground above the robot's level (a step up).
    Plateau,
    /// No single dominant plane.
    Obstacle,
}

/// Algorithm 3's thresholds (L3520; "quite uncritical", L3514–3516).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Thresholds {
    /// `t_m`: a bin is "high" if it has more than `t_m · #bin_max` votes. Thesis 2/3.
    pub t_m: f64,
    /// `t_h`: floor if the floor bin has more than `t_h · #PC` votes. Thesis 1/3.
    pub t_h: f64,
    /// `t_n`: the distribution is peaked if fewer than `t_n` bins are high. Thesis 7.
    pub t_n: usize,
    /// `t_p`: `bin_max` must have more than `t_p · #PC` votes. Thesis 1/5.
    pub t_p: f64,
}

impl Thresholds {
    /// The thesis's values: `t_m = 2/3, t_h = 1/3, t_n = 7, t_p = 1/5`.
    pub fn thesis() -> Thresholds {
        Thresholds { t_m: 2.0 / 3.0, t_h: 1.0 / 3.0, t_n: 7, t_p: 1.0 / 5.0 }
    }
}

/// What the robot can drive over (L3453–3460, Rugbot).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RobotLimits {
    /// Largest passable step up or down, metres. Rugbot: 0.2.
    pub max_step: f64,
    /// Largest passable combined ramp angle (normal vs. vertical), radians. Rugbot: 35°.
    pub max_slope: f64,
}

impl RobotLimits {
    /// Rugbot's limits: steps up to 0.2 m, ramps up to 35°.
    pub fn rugbot() -> RobotLimits {
        RobotLimits { max_step: 0.2, max_slope: 35f64.to_radians() }
    }
}

/// The preprocessing test: "sufficiently many meaningful data-points" (L3603–3605; the rule is
/// not given, spec §6.11). A frame is accepted if its valid points (finite, not the all-zero
/// "no measurement" point) are at least `min_points` and at least `min_valid_fraction` of the
/// frame's pixels.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Preprocessing {
    /// Least share of valid pixels, in [0, 1]. Default 0.1: with the valid ratios of Table 3.1
    /// this keeps SR-3000 frames (0.60–0.98) and excludes most stereo frames (0.04–0.14), like
    /// Table 4.2.
    pub min_valid_fraction: f64,
    /// Least number of valid points. Default 100.
    pub min_points: usize,
}

impl Preprocessing {
    /// `min_valid_fraction = 0.1`, `min_points = 100`.
    pub fn recommended() -> Preprocessing {
        Preprocessing { min_valid_fraction: 0.1, min_points: 100 }
    }

    /// Whether a frame with `valid` of `frame` pixels valid passes.
    pub fn accepts(&self, valid: usize, frame: usize) -> bool {
        valid >= self.min_points.max(1) && valid as f64 >= self.min_valid_fraction * frame as f64
    }
}

/// Everything Algorithm 3 and the passability decision need.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ClassifierConfig {
    /// Algorithm 3's thresholds.
    pub thresholds: Thresholds,
    /// The robot's limits.
    pub limits: RobotLimits,
    /// The preprocessing test.
    pub preprocessing: Preprocessing,
}

impl ClassifierConfig {
    /// The thesis's thresholds, Rugbot's limits, the recommended preprocessing.
    pub fn thesis() -> ClassifierConfig {
        ClassifierConfig {
            thresholds: Thresholds::thesis(),
            limits: RobotLimits::rugbot(),
            preprocessing: Preprocessing::recommended(),
        }
    }

    /// Checks every field: `t_m, t_h, t_p` in [0, 1], `t_n ≥ 1`, `max_step ≥ 0`,
    /// `max_slope` in [0, 90°], `min_valid_fraction` in [0, 1].
    pub fn validate(&self) -> Result<()> {
        let unit = |what, v: f64| {
            if (0.0..=1.0).contains(&v) {
                Ok(())
            } else {
                Err(HoughError::BadParameter { what, value: v, allowed: "[0, 1]" })
            }
        };
        unit("t_m", self.thresholds.t_m)?;
        unit("t_h", self.thresholds.t_h)?;
        unit("t_p", self.thresholds.t_p)?;
        unit("min_valid_fraction", self.preprocessing.min_valid_fraction)?;
        if self.thresholds.t_n == 0 {
            return Err(HoughError::BadParameter { what: "t_n", value: 0.0, allowed: "≥ 1" });
        }
        let step = self.limits.max_step;
        if !(step.is_finite() && step >= 0.0) {
            return Err(HoughError::BadParameter {
                what: "max_step",
                value: step,
                allowed: "≥ 0 m",
            });
        }
        let slope = self.limits.max_slope;
        if !(0.0..=std::f64::consts::FRAC_PI_2).contains(&slope) {
            return Err(HoughError::BadParameter {
                what: "max_slope",
                value: slope,
                allowed: "[0, 90°]",
            });
        }
        Ok(())
    }
}

/// Which branch of Algorithm 3 decided.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Rule {
    /// `#bin_floor > t_h · #PC`: floor.
    FloorBin,
    /// Peaked (`#{high bins} < t_n`) and `#bin_max > t_p · #PC`: `type(bin_max)`.
    PeakedMaximum,
    /// Too many high bins (`≥ t_n`): obstacle.
    NotPeaked,
    /// Peaked but `#bin_max ≤ t_p · #PC`: obstacle.
    WeakMaximum,
    /// No vote landed in range (spec §6.10): obstacle.
    NoVotes,
    /// The preprocessing test failed: not classified, reported as a non-drivable obstacle.
    Rejected,
    /// Ground-ahead rule ([`crate::ahead`]): nothing stands and no other surface lies ahead:
    /// floor.
    AheadFloor,
    /// Ground-ahead rule: a surface other than the floor lies ahead and decides (ramp, plateau,
    /// canyon, or floor for a step the robot can take).
    AheadSurface,
    /// Ground-ahead rule: something higher than the robot's step stands ahead: obstacle.
    AheadObstacle,
    /// Ground-ahead rule: a face higher than the robot's step spans the view with a level top
    /// edge: plateau.
    AheadLedge,
    /// Ground-ahead rule: too few points ahead to tell: obstacle.
    AheadTooFew,
    /// Ground-ahead rule: the ground ends ahead and what lies beyond is out of a step's reach:
    /// canyon.
    AheadDrop,
}

/// The result of classifying one frame (or one sector).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Classification {
    /// The class (obstacle when rejected by preprocessing).
    pub class: TerrainClass,
    /// Whether the robot's limits allow the class's plane: floor yes, obstacle no, plateau and
    /// canyon if the step is at most `max_step`, ramp if its tilt is at most `max_slope`.
    pub passable: bool,
    /// The binary drivability of Table 4.3: floor, or a passable ramp / plateau / canyon
    /// (spec §6.9).
    pub drivable: bool,
    /// Which branch of Algorithm 3 decided.
    pub rule: Rule,
    /// The winning plane: the floor bin's under [`Rule::FloorBin`], `bin_max`'s otherwise
    /// (also for obstacles, as information); `None` without votes.
    pub plane: Option<Plane>,
    /// The winning bin.
    pub bin: Option<Bin>,
    /// Votes of the winning bin.
    pub votes: u32,
    /// Votes of `bin_max`.
    pub max_votes: u32,
    /// Votes of the floor bin.
    pub floor_votes: u32,
    /// Peakedness: `#{bin | #bin > t_m · #bin_max}` (the white bins of Fig 4.3; thesis: 14
    /// for a random step field, 35 for a ramp, L3735).
    pub high_bins: usize,
    /// `#PC`: points after preprocessing.
    pub points: usize,
    /// Step height of a plateau or canyon relative to the floor bin, metres (quantised to the
    /// distance resolution; positive for plateaus); 0 otherwise.
    pub step: f64,
    /// The winning plane's combined angle (radians); 0 without a plane.
    pub tilt: f64,
    /// Whether the preprocessing test passed.
    pub accepted: bool,
    /// Valid points / frame pixels.
    pub valid_fraction: f64,
}

/// The floor bin (spec §6.9): ρx = ρy = 0 and the distance bin of the sensor height `height`
/// (levelled frame, z down: the floor is `d = +height`). Fails if 0° is not a sample of both
/// angle axes or the height is outside the distance range.
pub fn floor_bin(space: &HoughSpace, height: f64) -> Result<Bin> {
    let ix = HoughSpace::zero_index(space.rho_x_axis(), space.nx())
        .ok_or_else(|| HoughError::NoFloorBin { why: "ρx = 0 is not sampled".into() })?;
    let iy = HoughSpace::zero_index(space.rho_y_axis(), space.ny())
        .ok_or_else(|| HoughError::NoFloorBin { why: "ρy = 0 is not sampled".into() })?;
    let id = space.d_bin(height).ok_or_else(|| HoughError::NoFloorBin {
        why: format!("sensor height {height} m is outside the distance range"),
    })?;
    Ok(Bin { ix, iy, id })
}

/// What `type(bin)` says about a bin.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BinType {
    /// Floor, ramp, canyon or plateau.
    pub class: TerrainClass,
    /// Whether the robot's limits allow it.
    pub passable: bool,
    /// Step relative to the floor bin, metres (plateau positive, canyon negative; 0 for ramps).
    pub step: f64,
    /// Combined angle of the bin's plane, radians.
    pub tilt: f64,
}

/// `type(bin)` of Algorithm 3 (not given in the thesis; spec §6.9) with its passability: same
/// angles as the floor and same distance bin → floor; same angles, larger d (farther below the
/// sensor) → canyon; same angles, smaller d → plateau; other angles → ramp. Steps are
/// `|id − id_floor| · d_res` (passable up to `max_step`), ramps pass up to `max_slope`.
pub fn bin_type(space: &HoughSpace, bin: Bin, floor: Bin, limits: &RobotLimits) -> BinType {
    let tilt = space.plane(bin).tilt();
    if bin.ix != floor.ix || bin.iy != floor.iy {
        let passable = tilt <= limits.max_slope + 1e-12;
        return BinType { class: TerrainClass::Ramp, passable, step: 0.0, tilt };
    }
    let step = (floor.id as f64 - bin.id as f64) * space.d_axis().resolution;
    let passable = step.abs() <= limits.max_step + 1e-9;
    let class = match bin.id.cmp(&floor.id) {
        std::cmp::Ordering::Equal => TerrainClass::Floor,
        std::cmp::Ordering::Greater => TerrainClass::Canyon,
        std::cmp::Ordering::Less => TerrainClass::Plateau,
    };
    BinType { class, passable, step, tilt }
}

/// Algorithm 3 on an accumulator, with `#PC = acc.points()`:
///
/// ```text
/// if #bin_floor > t_h·#PC                                  → floor
/// elif #{bin | #bin > t_m·#bin_max} < t_n and #bin_max > t_p·#PC → type(bin_max)
/// else                                                      → obstacle
/// ```
///
/// No votes at all gives obstacle ([`Rule::NoVotes`]). The result has `accepted = true` and
/// `valid_fraction = 1`; [`crate::HoughClassifier`] fills in the preprocessing. Fails if
/// `floor` is not a bin of the accumulator's space.
pub fn algorithm3(
    acc: &Accumulator,
    floor: Bin,
    config: &ClassifierConfig,
) -> Result<Classification> {
    let space = acc.space();
    if floor.ix >= space.nx() || floor.iy >= space.ny() || floor.id >= space.nd() {
        return Err(HoughError::Mismatch {
            why: format!("floor bin {floor:?} outside the Hough space"),
        });
    }
    let t = &config.thresholds;
    let pc = acc.points() as f64;
    let floor_votes = acc.count(floor);
    let mut out = Classification {
        class: TerrainClass::Obstacle,
        passable: false,
        drivable: false,
        rule: Rule::NoVotes,
        plane: None,
        bin: None,
        votes: 0,
        max_votes: 0,
        floor_votes,
        high_bins: 0,
        points: acc.points(),
        step: 0.0,
        tilt: 0.0,
        accepted: true,
        valid_fraction: 1.0,
    };
    let Some((max_bin, max_votes)) = acc.max_bin() else { return Ok(out) };
    out.max_votes = max_votes;
    out.high_bins = acc.bins_above(t.t_m * max_votes as f64);
    let (winner, rule) = if floor_votes as f64 > t.t_h * pc {
        (floor, Rule::FloorBin)
    } else if out.high_bins < t.t_n && max_votes as f64 > t.t_p * pc {
        (max_bin, Rule::PeakedMaximum)
    } else if out.high_bins >= t.t_n {
        (max_bin, Rule::NotPeaked)
    } else {
        (max_bin, Rule::WeakMaximum)
    };
    out.rule = rule;
    out.bin = Some(winner);
    out.plane = Some(space.plane(winner));
    out.votes = acc.count(winner);
    let BinType { class, passable, step, tilt } = bin_type(space, winner, floor, &config.limits);
    out.tilt = tilt;
    match rule {
        Rule::FloorBin => {
            out.class = TerrainClass::Floor;
            out.passable = true;
        }
        Rule::PeakedMaximum => {
            out.class = class;
            out.passable = passable;
            out.step = step;
        }
        _ => {}
    }
    out.drivable = out.class != TerrainClass::Obstacle && out.passable;
    Ok(out)
}

/// The result for a frame the preprocessing test rejected.
pub(crate) fn rejected(points: usize, valid_fraction: f64) -> Classification {
    Classification { accepted: false, valid_fraction, ..not_drivable(Rule::Rejected, points, None) }
}

/// A not-drivable obstacle decided by `rule`, with nothing counted.
pub(crate) fn not_drivable(rule: Rule, points: usize, plane: Option<Plane>) -> Classification {
    Classification {
        class: TerrainClass::Obstacle,
        passable: false,
        drivable: false,
        rule,
        plane,
        bin: None,
        votes: 0,
        max_votes: 0,
        floor_votes: 0,
        high_bins: 0,
        points,
        step: 0.0,
        tilt: 0.0,
        accepted: true,
        valid_fraction: 1.0,
    }
}
