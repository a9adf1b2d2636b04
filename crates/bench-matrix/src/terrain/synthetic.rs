//! Simulated snapshots with ground truth for Tables 4.3, 4.6 and 4.7 (thesis §4.4, spec §3).
//!
//! Every parameter set is a scene-sim terrain scene (or a ramp with clutter on it) seen by the
//! SR-3000 time-of-flight simulator (amplitude-dependent noise and wrap-around; once in the dark
//! and once with sunlight on the whole scene, which raises the noise) and by the
//! simulated STOC stereo camera, from a Rugbot-like pose: the camera 0.45 m above the floor,
//! level. Snapshots of a set differ in the obstacle layout (scene seed), the sensor noise and
//! the feature's distance (spread evenly over ±0.25 m around the nominal one).

use anyhow::{Context, Result};
use hough_terrain::{HoughClassifier, HoughConfig, Method, SensorAxes, SensorMount, TerrainClass};
use nalgebra::Point3;
use scene_sim::{HoughClass, RangeSensor, Scene, SceneBuilder, StereoCamera, TerrainSpec, terrain};
use sensor_tof::Saturation;
use sensor_tof::sim::{SimConfig, SunRegion, TofSimulator};
use std::time::Instant;

/// Camera height above the floor, metres (mid d-bin [0.4, 0.5), so noise does not split the
/// floor's votes).
pub(crate) const HEIGHT: f64 = 0.45;
/// Camera pitch, degrees down: level (pitched down 20°, the floor right in front holds more than
/// `t_h · #PC` points in every scene and Algorithm 3 says "floor" everywhere).
pub(crate) const PITCH_DEG: f64 = 0.0;
/// The resolutions of Tables 4.3 (45°) and 4.6/4.7 (45°, 15°, 9°).
pub(crate) const RESOLUTIONS: [f64; 3] = [45.0, 15.0, 9.0];

/// The simulated sensors.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(crate) enum Sensor {
    /// SR-3000 simulator, no ambient light but the simulator's base level.
    Tof,
    /// SR-3000 simulator with sunlight on the whole scene.
    TofSun,
    /// [`Sensor::TofSun`]'s frames with the saturated pixels left out
    /// ([`sensor_tof::Saturation`]), as a camera that flags saturation gives them.
    TofSunMasked,
    /// STOC stereo camera.
    Stereo,
}

impl Sensor {
    /// Every simulated sensor, in table order.
    pub(crate) const ALL: [Sensor; 4] =
        [Sensor::Tof, Sensor::TofSun, Sensor::TofSunMasked, Sensor::Stereo];

    /// The short name used in tables and JSON rows.
    pub(crate) fn name(self) -> &'static str {
        match self {
            Sensor::Tof => "tof",
            Sensor::TofSun => "tof-sun",
            Sensor::TofSunMasked => "tof-sun-masked",
            Sensor::Stereo => "stereo",
        }
    }
}

/// What a scene shows: how to build it and its truth.
#[derive(Clone, Debug)]
pub(crate) struct Case {
    /// A short name (`ramp-p30-r0`, `plateau-0.30@1.5`, ...).
    pub name: String,
    /// The main feature.
    pub spec: TerrainSpec,
    /// Clutter added on top (the sloped-and-cluttered mixes).
    pub clutter: Option<TerrainSpec>,
    /// The label the thesis's evaluation would give.
    pub label: TerrainClass,
    /// Whether Rugbot could pass.
    pub passable: bool,
}

fn label_of(c: HoughClass) -> TerrainClass {
    match c {
        HoughClass::Floor => TerrainClass::Floor,
        HoughClass::Ramp => TerrainClass::Ramp,
        HoughClass::Canyon => TerrainClass::Canyon,
        HoughClass::Plateau => TerrainClass::Plateau,
        HoughClass::Obstacle => TerrainClass::Obstacle,
    }
}

fn case(name: String, spec: TerrainSpec) -> Case {
    let t = spec.truth();
    Case { name, spec, clutter: None, label: label_of(t.label), passable: t.passable }
}

/// The parameter sets: floor; ramps of pitch 10–45° and roll 15–45° (and both); a downhill ramp;
/// steps up and down of 0.05–0.5 m at 1.5 m and 3 m; walls at 1, 2, 3 m; clutter; rubble; ramps
/// with clutter on them.
pub(crate) fn cases() -> Vec<Case> {
    let rad = f64::to_radians;
    let mut v = vec![case("floor".into(), TerrainSpec::Floor)];
    for (p, r) in
        [(10.0, 0.0), (20.0, 0.0), (30.0, 0.0), (40.0, 0.0), (45.0, 0.0), (0.0, 15.0), (0.0, 30.0)]
            .into_iter()
            .chain([(0.0, 45.0), (20.0, 20.0), (30.0, 30.0), (-15.0, 0.0)])
    {
        let spec = TerrainSpec::Ramp { pitch: rad(p), roll: rad(r), distance: 1.5 };
        v.push(case(format!("ramp-p{p}-r{r}"), spec));
    }
    for distance in [1.5, 3.0] {
        for h in [0.05, 0.1, 0.2, 0.3, 0.5] {
            v.push(case(
                format!("plateau-{h:.2}@{distance}"),
                TerrainSpec::Plateau { height: h, distance },
            ));
        }
        for h in [0.05, 0.1, 0.2, 0.3, 0.5] {
            v.push(case(
                format!("canyon-{h:.2}@{distance}"),
                TerrainSpec::Canyon { depth: h, distance },
            ));
        }
    }
    for distance in [1.0, 2.0, 3.0] {
        v.push(case(format!("wall@{distance}"), TerrainSpec::Wall { distance, height: 2.0 }));
    }
    for count in [10, 25] {
        v.push(case(format!("clutter-{count}"), TerrainSpec::Obstacles { count, distance: 1.5 }));
    }
    for max_size in [0.1, 0.4] {
        v.push(case(
            format!("rubble-{max_size}"),
            TerrainSpec::Rubble { count: 300, max_size, distance: 1.0 },
        ));
    }
    for p in [15.0, 30.0] {
        v.push(Case {
            name: format!("ramp-p{p}+clutter"),
            spec: TerrainSpec::Ramp { pitch: rad(p), roll: 0.0, distance: 2.0 },
            clutter: Some(TerrainSpec::Obstacles { count: 8, distance: 1.5 }),
            label: TerrainClass::Obstacle,
            passable: false,
        });
    }
    v
}

/// `spec` with its feature moved by `shift` metres.
fn shifted(spec: TerrainSpec, shift: f64) -> TerrainSpec {
    match spec {
        TerrainSpec::Ramp { pitch, roll, distance } => {
            TerrainSpec::Ramp { pitch, roll, distance: distance + shift }
        }
        TerrainSpec::Plateau { height, distance } => {
            TerrainSpec::Plateau { height, distance: distance + shift }
        }
        TerrainSpec::Canyon { depth, distance } => {
            TerrainSpec::Canyon { depth, distance: distance + shift }
        }
        TerrainSpec::Wall { distance, height } => {
            TerrainSpec::Wall { distance: distance + shift, height }
        }
        TerrainSpec::Obstacles { count, distance } => {
            TerrainSpec::Obstacles { count, distance: distance + shift }
        }
        TerrainSpec::Rubble { count, max_size, distance } => {
            TerrainSpec::Rubble { count, max_size, distance: distance + shift }
        }
        TerrainSpec::Floor => TerrainSpec::Floor,
    }
}

/// Snapshot `k` of `n` of a case: the scene (feature distance spread over ±0.25 m).
pub(crate) fn scene(case: &Case, k: usize, n: usize, seed: u64) -> Result<Scene> {
    let shift = if n > 1 { 0.5 * k as f64 / (n - 1) as f64 - 0.25 } else { 0.0 };
    let scene_seed = seed.wrapping_mul(1_000_003).wrapping_add(k as u64);
    let main = terrain(&shifted(case.spec, shift), scene_seed)?;
    let Some(clutter) = case.clutter else { return Ok(main) };
    let extra = terrain(&shifted(clutter, shift), scene_seed)?;
    let mut b = SceneBuilder::new(case.name.clone());
    for p in main.primitives() {
        b.add(p.name.clone(), p.shape.clone(), p.material)?;
    }
    // The clutter scene's own floor (its first primitives) is the same plane: add only its boxes
    // and cylinders.
    for p in
        extra.primitives().iter().filter(|p| !main.primitives().iter().any(|m| m.name == p.name))
    {
        b.add(p.name.clone(), p.shape.clone(), p.material)?;
    }
    Ok(b.build()?)
}

/// The body pose of the robot and the mount the classifier is given.
pub(crate) fn body_pose() -> pointcloud::SensorPose {
    pointcloud::SensorPose::from_position_rpy(
        Point3::new(0.0, 0.0, HEIGHT),
        0.0,
        PITCH_DEG.to_radians(),
        0.0,
    )
}

/// The mount matching [`body_pose`] for a camera (optical axes).
pub(crate) fn mount() -> Result<SensorMount> {
    Ok(SensorMount::looking_ahead(HEIGHT, PITCH_DEG.to_radians(), 0.0, SensorAxes::Optical)?)
}

/// Makes frames of one sensor: points in the optical frame and the frame's pixel count.
///
/// The range camera's points are its measured pixels that see a surface, unfiltered, as the
/// thesis's snapshots (Table 3.1: 93–98 % of the pixels valid): pixels that see nothing (only
/// noise) are left out, as the camera flags them; no amplitude threshold is applied (the AAT of
/// Chapter 2 would drop most of the floor, seen at grazing incidence from a level camera).
pub(crate) struct FrameMaker {
    sensor: Sensor,
    tof: Option<TofSimulator>,
    /// The saturation test whose pixels are left out ([`Sensor::TofSunMasked`]).
    saturation: Option<Saturation>,
    stereo: StereoCamera,
}

impl FrameMaker {
    /// Prepares the simulator of `sensor`.
    pub(crate) fn new(sensor: Sensor) -> Result<FrameMaker> {
        let tof = match sensor {
            Sensor::Stereo => None,
            Sensor::Tof | Sensor::TofSun | Sensor::TofSunMasked => {
                let mut cfg = SimConfig::sr3000();
                if sensor != Sensor::Tof {
                    cfg.sun = vec![SunRegion {
                        min: Point3::new(-4.0, -7.0, -6.0),
                        max: Point3::new(13.0, 7.0, 6.0),
                        irradiance: sensor_tof::scenes::SUN_IRRADIANCE,
                    }];
                }
                Some(TofSimulator::new(cfg)?)
            }
        };
        let saturation = (sensor == Sensor::TofSunMasked).then(Saturation::sr3000);
        Ok(FrameMaker { sensor, tof, saturation, stereo: StereoCamera::stoc() })
    }

    /// One frame of `scene`: the valid points (optical frame) into `points`; returns the pixel
    /// count.
    pub(crate) fn frame(
        &mut self,
        scene: &Scene,
        seed: u64,
        points: &mut Vec<Point3<f64>>,
    ) -> Result<usize> {
        self.frame_from(scene, &body_pose(), seed, points)
    }

    /// [`FrameMaker::frame`] from another body pose.
    pub(crate) fn frame_from(
        &mut self,
        scene: &Scene,
        body: &pointcloud::SensorPose,
        seed: u64,
        points: &mut Vec<Point3<f64>>,
    ) -> Result<usize> {
        points.clear();
        let pixels: Result<usize> = match &mut self.tof {
            Some(sim) => {
                let pose = scene_sim::RangeCamera::swissranger_sr3000().mount(body);
                let sim_frame = sim.simulate(scene, &pose, seed)?;
                let frame = &sim_frame.frame;
                let saturated = match self.saturation {
                    Some(s) => s.mask(frame)?,
                    None => Vec::new(),
                };
                for (i, truth) in sim_frame.truth.radial.iter().enumerate() {
                    let range = frame.range()[i];
                    if truth.is_some() && range > 0.0 && !saturated.get(i).is_some_and(|s| *s) {
                        let (col, row) = frame.col_row(i);
                        points.push(frame.camera().point(col, row, f64::from(range), frame.kind()));
                    }
                }
                let n = frame.range().len();
                Ok(n)
            }
            None => {
                let pose = self.stereo.mount(body);
                let cloud = self.stereo.scan(scene, &pose, seed).to_cloud()?;
                points.extend_from_slice(cloud.positions());
                Ok(cloud.grid().map_or(cloud.len(), |g| g.num_pixels()))
            }
        };
        pixels.with_context(|| format!("{} frame", self.sensor.name()))
    }
}

/// The outcome of one snapshot at one resolution.
#[derive(Copy, Clone, Debug)]
pub(crate) struct Outcome {
    /// The class Algorithm 3 gave.
    pub class: TerrainClass,
    /// Whether it was judged drivable.
    pub drivable: bool,
    /// Whether the preprocessing accepted the frame.
    pub accepted: bool,
    /// `#PC`.
    pub points: usize,
    /// Time of the classification call, seconds.
    pub seconds: f64,
}

/// Per method × sensor × case: outcomes per resolution, one per snapshot.
pub(crate) struct CaseResult {
    /// The classification method.
    pub method: &'static str,
    /// The sensor.
    pub sensor: Sensor,
    /// The parameter set.
    pub case: Case,
    /// Outcomes at 45°, 15°, 9°.
    pub outcomes: [Vec<Outcome>; 3],
}

/// The methods compared: the ground-ahead rule (recommended) and the thesis's Algorithm 3.
pub(crate) const METHODS: [&str; 2] = ["ground-ahead", "thesis"];

/// Runs every case for every sensor with `n` snapshots each, classified by every method of
/// [`METHODS`] at every resolution. With `PATCHNAV_TERRAIN_DEBUG` set, the ground-ahead rule's
/// wrong drivability calls at 45° are printed with what it saw.
pub(crate) fn run_all(n: usize, seed: u64) -> Result<Vec<CaseResult>> {
    let mount = mount()?;
    let debug = std::env::var_os("PATCHNAV_TERRAIN_DEBUG");
    let all = debug.as_deref() == Some(std::ffi::OsStr::new("all"));
    let debug = debug.is_some();
    let mut methods = METHODS
        .iter()
        .map(|name| {
            let method: Method = name.parse()?;
            let cls = RESOLUTIONS
                .iter()
                .map(|r| {
                    let config =
                        HoughConfig { method, ..HoughConfig::thesis(r.to_radians(), mount)? };
                    Ok(HoughClassifier::new(config)?)
                })
                .collect::<Result<Vec<_>>>()?;
            Ok((*name, cls))
        })
        .collect::<Result<Vec<_>>>()?;
    let cases = cases();
    let mut results = Vec::new();
    let mut points = Vec::new();
    for sensor in Sensor::ALL {
        let mut maker = FrameMaker::new(sensor)?;
        let n_sensor = if sensor == Sensor::Stereo { n.div_ceil(2) } else { n };
        for case in &cases {
            let mut outcomes: Vec<[Vec<Outcome>; 3]> = vec![Default::default(); methods.len()];
            for k in 0..n_sensor {
                let scene = scene(case, k, n_sensor, seed)?;
                let pixels =
                    maker.frame(&scene, seed.wrapping_add(k as u64 * 7919), &mut points)?;
                for ((name, cls), per_method) in methods.iter_mut().zip(outcomes.iter_mut()) {
                    for (i, (c, out)) in cls.iter_mut().zip(per_method.iter_mut()).enumerate() {
                        let t = Instant::now();
                        let r = c.classify_frame(&points, pixels)?;
                        let seconds = t.elapsed().as_secs_f64();
                        if debug
                            && i == 0
                            && *name == "ground-ahead"
                            && (all || r.drivable != case.passable)
                        {
                            eprintln!(
                                "{} {} #{k}: {:?} {:?} step {:.2} tilt {:.1}° {:?}",
                                sensor.name(),
                                case.name,
                                r.class,
                                r.rule,
                                r.step,
                                r.tilt.to_degrees(),
                                c.ahead_facts()
                            );
                        }
                        out.push(Outcome {
                            class: r.class,
                            drivable: r.drivable,
                            accepted: r.accepted,
                            points: r.points,
                            seconds,
                        });
                    }
                }
            }
            for ((name, _), outcomes) in methods.iter().zip(outcomes) {
                results.push(CaseResult { method: name, sensor, case: case.clone(), outcomes });
            }
        }
    }
    Ok(results)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mixes_hold_the_ramp_and_the_clutter_once() {
        let mix = cases().into_iter().find(|c| c.clutter.is_some()).unwrap();
        let combined = scene(&mix, 0, 1, 0).unwrap();
        let ramp = terrain(&mix.spec, 0).unwrap();
        let clutter = terrain(&mix.clutter.unwrap(), 0).unwrap();
        let (n, r, c) =
            (combined.primitives().len(), ramp.primitives().len(), clutter.primitives().len());
        assert!(n > r, "{n} primitives, the ramp alone has {r}");
        assert!(
            n < r + c,
            "{n} primitives: the clutter's floor must not be added twice ({r} + {c})"
        );
        assert!(!mix.passable && mix.label == TerrainClass::Obstacle);
    }
}
