//! The streaming classifier: prepared once, then one call per frame reusing every buffer.

use crate::accumulator::{Accumulator, NormalTable};
use crate::ahead::{AheadScratch, GroundAhead, classify_ahead};
use crate::classify::{Classification, ClassifierConfig, algorithm3, floor_bin, rejected};
use crate::error::{HoughError, Result};
use crate::mount::SensorMount;
use crate::space::{Bin, HoughSpace};
use nalgebra::Point3;
use pointcloud::PointCloud;
use serde::{Deserialize, Serialize};

/// Everything a [`HoughClassifier`] needs.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HoughConfig {
    /// The discretised parameter space.
    pub space: HoughSpace,
    /// The sensor's mounting (levelling rotation and height, which fixes the floor bin).
    pub mount: SensorMount,
    /// Algorithm 3, limits, preprocessing.
    pub classifier: ClassifierConfig,
    /// Voting threads: 1 votes on the caller's thread without allocating; more splits the
    /// points over scoped threads.
    pub threads: usize,
    /// Which rule turns the frame into a class.
    pub method: Method,
    /// The ground-ahead rule's parameters (used by [`Method::GroundAhead`]).
    pub ahead: GroundAhead,
}

impl HoughConfig {
    /// The thesis's space at `resolution` (radians), the thesis's classifier (Algorithm 3),
    /// one thread: the thesis's tables.
    pub fn thesis(resolution: f64, mount: SensorMount) -> Result<HoughConfig> {
        Ok(HoughConfig {
            space: HoughSpace::thesis(resolution)?,
            mount,
            classifier: ClassifierConfig::thesis(),
            threads: 1,
            method: Method::Thesis,
            ahead: GroundAhead::recommended(),
        })
    }

    /// [`HoughConfig::thesis`] with the ground-ahead rule ([`crate::ahead`]) deciding: the
    /// recommended configuration.
    pub fn recommended(resolution: f64, mount: SensorMount) -> Result<HoughConfig> {
        Ok(HoughConfig { method: Method::GroundAhead, ..HoughConfig::thesis(resolution, mount)? })
    }
}

/// Which rule turns a frame into a class.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Method {
    /// The ground-ahead rule ([`crate::ahead`]), beyond the thesis; the recommended one.
    GroundAhead,
    /// Algorithm 3 verbatim (§4.1.3, L3468–3520): the thesis's tables.
    Thesis,
}

impl Method {
    /// Every method, the recommended first.
    pub const ALL: [Method; 2] = [Method::GroundAhead, Method::Thesis];

    /// The method's name (what [`std::str::FromStr`] parses).
    pub fn name(self) -> &'static str {
        match self {
            Method::GroundAhead => "ground-ahead",
            Method::Thesis => "thesis",
        }
    }

    /// One line on what the method is, for help texts.
    pub fn description(self) -> &'static str {
        match self {
            Method::GroundAhead => {
                "what stands on the ground, the surface ahead and where the ground drops away, \
                 within the robot's step and slope limits"
            }
            Method::Thesis => "Algorithm 3 of the thesis, verbatim (its tables)",
        }
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Method {
    type Err = HoughError;

    fn from_str(s: &str) -> Result<Method> {
        Method::ALL.into_iter().find(|m| m.name() == s).ok_or_else(|| HoughError::UnknownName {
            what: "terrain method",
            name: s.to_owned(),
            allowed: Method::ALL.map(Method::name).join(", "),
        })
    }
}

/// Algorithm 2 + Algorithm 3 on a stream of frames. Prepared once ([`HoughClassifier::new`]:
/// normal table, floor bin, buffers); [`HoughClassifier::classify`] then allocates nothing
/// once its point buffer has grown to the largest frame seen (single-threaded voting; the
/// parallel path reuses its per-thread accumulators but the OS allocates thread stacks).
#[derive(Clone, Debug)]
pub struct HoughClassifier {
    config: HoughConfig,
    table: NormalTable,
    floor: Bin,
    acc: Accumulator,
    partials: Vec<Accumulator>,
    levelled: Vec<Point3<f64>>,
    ahead: AheadScratch,
}

impl HoughClassifier {
    /// Validates the configuration and prepares the tables. Fails on bad thresholds or limits,
    /// on 0 threads, or if the floor has no bin ([`floor_bin`]).
    pub fn new(config: HoughConfig) -> Result<HoughClassifier> {
        config.classifier.validate()?;
        if config.method == Method::GroundAhead {
            config.ahead.validate()?;
        }
        if config.threads == 0 || config.threads > 1024 {
            return Err(HoughError::BadParameter {
                what: "threads",
                value: config.threads as f64,
                allowed: "1..=1024",
            });
        }
        let floor = floor_bin(&config.space, config.mount.height())?;
        Ok(HoughClassifier {
            table: NormalTable::new(&config.space),
            acc: Accumulator::new(config.space),
            partials: Vec::new(),
            levelled: Vec::new(),
            ahead: AheadScratch::default(),
            floor,
            config,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &HoughConfig {
        &self.config
    }

    /// The floor bin.
    pub fn floor_bin(&self) -> Bin {
        self.floor
    }

    /// The accumulator of the last frame (empty if it was rejected, or under the ground-ahead
    /// rule without [`GroundAhead::hough`]).
    pub fn accumulator(&self) -> &Accumulator {
        &self.acc
    }

    /// The last frame's valid points in the levelled frame.
    pub fn levelled_points(&self) -> &[Point3<f64>] {
        &self.levelled
    }

    /// Heap bytes held by the buffers (constant from frame to frame once warmed up).
    pub fn capacity_bytes(&self) -> usize {
        self.acc.capacity_bytes()
            + self.partials.iter().map(Accumulator::capacity_bytes).sum::<usize>()
            + self.levelled.capacity() * std::mem::size_of::<Point3<f64>>()
            + self.ahead.capacity_bytes()
    }

    /// What the ground-ahead rule saw in the last frame (all zero under [`Method::Thesis`] and
    /// for a frame the preprocessing rejected).
    pub fn ahead_facts(&self) -> crate::ahead::AheadFacts {
        self.ahead.facts
    }

    /// Classifies a frame of sensor-frame points; the frame size for the preprocessing test is
    /// `points.len()` (points at exactly the origin count as pixels without a measurement).
    /// Fails on an empty slice or a non-finite point.
    pub fn classify(&mut self, points: &[Point3<f64>]) -> Result<Classification> {
        self.classify_frame(points, points.len())
    }

    /// Classifies a point cloud: an organised cloud's frame size is its grid's pixel count
    /// (its points are the valid pixels), otherwise the number of points.
    pub fn classify_cloud(&mut self, cloud: &PointCloud) -> Result<Classification> {
        let frame = cloud.grid().map_or(cloud.len(), |g| g.num_pixels());
        self.classify_frame(cloud.positions(), frame)
    }

    /// Classifies `points` taken from a frame of `frame_pixels` pixels (≥ `points.len()`).
    pub fn classify_frame(
        &mut self,
        points: &[Point3<f64>],
        frame_pixels: usize,
    ) -> Result<Classification> {
        self.ahead.facts = crate::ahead::AheadFacts::default();
        self.level(points, frame_pixels)?;
        self.acc.clear();
        let valid = self.levelled.len();
        let fraction = valid as f64 / frame_pixels as f64;
        if !self.config.classifier.preprocessing.accepts(valid, frame_pixels) {
            return Ok(rejected(valid, fraction));
        }
        // The ground-ahead rule alone leaves the Hough space empty.
        let vote = self.config.method == Method::Thesis || self.config.ahead.hough;
        if vote && self.config.threads > 1 {
            self.table.vote_parallel(
                &self.levelled,
                &mut self.acc,
                &mut self.partials,
                self.config.threads,
            )?;
        } else if vote {
            self.table.vote(&self.levelled, &mut self.acc)?;
        }
        let mut c = match self.config.method {
            Method::Thesis => algorithm3(&self.acc, self.floor, &self.config.classifier)?,
            Method::GroundAhead => {
                let mut c = classify_ahead(
                    &self.levelled,
                    self.config.mount.height(),
                    &self.config.classifier.limits,
                    &self.config.ahead,
                    &mut self.ahead,
                )?;
                c.floor_votes = self.acc.count(self.floor);
                c.points = valid;
                c
            }
        };
        c.valid_fraction = fraction;
        Ok(c)
    }

    /// Checks and levels the points into the reused buffer, dropping all-zero points.
    fn level(&mut self, points: &[Point3<f64>], frame_pixels: usize) -> Result<()> {
        if frame_pixels == 0 {
            return Err(HoughError::EmptyCloud);
        }
        if frame_pixels < points.len() {
            return Err(HoughError::Mismatch {
                why: format!("{} points in a frame of {frame_pixels} pixels", points.len()),
            });
        }
        self.levelled.clear();
        self.levelled.reserve(points.len());
        let mount = &self.config.mount;
        for (index, p) in points.iter().enumerate() {
            if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
                self.levelled.clear();
                return Err(HoughError::NonFinitePoint { index });
            }
            if p.x == 0.0 && p.y == 0.0 && p.z == 0.0 {
                continue;
            }
            self.levelled.push(mount.to_levelled(p));
        }
        Ok(())
    }
}
