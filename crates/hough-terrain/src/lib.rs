//! Plane Hough transform for terrain classification (thesis Ch. 4, spec `tof-hough.md` §3,
//! §5, §6 items 6–13): from one range frame to *floor, ramp, canyon, plateau* or *obstacle*,
//! a drivable yes/no and the winning plane, in well under a millisecond per frame at 45°.
//!
//! # User guide
//!
//! Describe where the sensor sits ([`SensorMount`]), pick a Hough space (the thesis's at 45°
//! for drivability, 15° or 9° for classes: [`HoughConfig::thesis`]), prepare a
//! [`HoughClassifier`] once, and call [`HoughClassifier::classify`] (or
//! [`HoughClassifier::classify_cloud`] with a [`pointcloud::PointCloud`]) per frame; buffers
//! are reused, so the serial path allocates nothing per frame.
//!
//! ```
//! use hough_terrain::{
//!     HistogramStyle, HoughClassifier, HoughConfig, SensorAxes, SensorMount, TerrainClass,
//!     hough_png,
//! };
//! use nalgebra::Point3;
//!
//! // A level laser scanner (x forward, y left, z up) 0.45 m above a flat floor.
//! let mount = SensorMount::looking_ahead(0.45, 0.0, 0.0, SensorAxes::Body)?;
//! let mut classifier = HoughClassifier::new(HoughConfig::thesis(15f64.to_radians(), mount)?)?;
//! let floor: Vec<Point3<f64>> = (0..2000)
//!     .map(|i| Point3::new(1.0 + (i % 50) as f64 * 0.05, (i / 50) as f64 * 0.05 - 1.0, -0.45))
//!     .collect();
//! let result = classifier.classify(&floor)?;
//! assert_eq!(result.class, TerrainClass::Floor);
//! assert!(result.drivable);
//! let plane = result.plane.unwrap(); // ρx = ρy = 0, d in the bin of +0.45 m
//! assert_eq!((plane.rho_x, plane.rho_y), (0.0, 0.0));
//! assert!((plane.d - 0.45).abs() <= 0.05);
//!
//! // A ramp climbing 30° from 1 m ahead: negative ρx (uphill) in the levelled frame.
//! let ramp: Vec<Point3<f64>> = (0..2000)
//!     .map(|i| {
//!         let (x, y) = (1.0 + (i % 50) as f64 * 0.05, (i / 50) as f64 * 0.05 - 1.0);
//!         Point3::new(x, y, -0.45 + (x - 1.0) * 30f64.to_radians().tan())
//!     })
//!     .collect();
//! let result = classifier.classify(&ramp)?;
//! assert_eq!(result.class, TerrainClass::Ramp);
//! assert!((result.plane.unwrap().rho_x.to_degrees() + 30.0).abs() < 1e-9);
//! assert!(result.drivable); // 30° ≤ Rugbot's 35°
//!
//! // The Hough space as a picture like Fig 4.3.
//! let mut png = Vec::new();
//! hough_png(classifier.accumulator(), &HistogramStyle::thesis(Some(classifier.floor_bin())), &mut png)?;
//! # Ok::<(), hough_terrain::HoughError>(())
//! ```
//!
//! # What implements which part of Chapter 4
//!
//! | thesis | here |
//! |---|---|
//! | plane parameters ρx, ρy, d (§4.1.2, L3352–3410, Fig 4.1) | [`Plane`], [`HoughSpace`] |
//! | Algorithm 2, plane Hough transform (L3330–3350) | [`vote_literal`] (reference), [`NormalTable`] (fast, optionally parallel), [`Accumulator`] |
//! | ranges and resolutions (L3522–3542) | [`HoughSpace::thesis`], [`AngleAxis`], [`DistanceAxis`] |
//! | walls excluded by dropping out-of-range votes (L3429–3437) | [`NormalTable::vote`] |
//! | floor bin from the sensor pose (L3417–3419) | [`SensorMount`], [`floor_bin`] |
//! | classes and Rugbot's limits (L3439–3460) | [`TerrainClass`], [`RobotLimits`], [`bin_type`] |
//! | Algorithm 3 with t_m, t_h, t_n, t_p (L3468–3520) | [`algorithm3`], [`Thresholds`], [`Classification`] |
//! | preprocessing "enough meaningful points" (L3601–3605) | [`Preprocessing`] |
//! | drivability (Table 4.3, L3908–3922) | [`Classification::drivable`] |
//! | histogram pictures (Fig 4.3, L3689–3705) | [`hough_png`], [`hough_image`] |
//! | timing (Fig 4.4, 5–50 ms per frame) | `benches/hough.rs` |
//! | beyond: the ground-ahead rule (what stands on the ground or lies ahead, within the robot's limits) | [`Method::GroundAhead`], [`GroundAhead`], [`classify_ahead`] |
//! | beyond: per-sector classification | [`SectorClassifier`], [`SectorGrid`] |
//! | beyond: equal-area ball accumulator (Borrmann et al. 2011) | [`BallAccumulator`], [`refine_plane`] |
//! | beyond: mount self-calibration (height, pitch, roll from the ground plane; one frame or a running window) | [`estimate_mount`], [`MountSearch`], [`MountWindow`] |
//! | beyond: per-point ground segmentation (local planes on a polar grid, Rugbot's step and slope limits) | [`GroundSegmenter`], [`GroundSettings`] |
//!
//! # Conventions
//!
//! * **Frame.** Algorithm 2 runs in the *levelled frame*: origin at the sensor, x forward
//!   (horizontal, the robot's heading), y right, **z down** along gravity. [`SensorMount`]
//!   gives the rotation from the sensor's own frame (body axes or camera optical axes) and the
//!   sensor height `h` above the floor. The thesis does not state its frame (spec §6.8); this
//!   is the only one in which its statements hold together: positive ρx is downhill ahead
//!   (L3524–3526) and the floor, `ρx = ρy = 0, d = +h`, lies inside d ∈ [−1, 2] m.
//! * **Sign.** `n = (−sin ρx cos ρy, −cos ρx sin ρy, cos ρx cos ρy)`, `d = n·p`, so the plane is
//!   `z = tan ρx · x + tan ρy · y + d/(cos ρx cos ρy)`: **a ramp climbing ahead has ρx < 0**,
//!   one falling to the right has ρy > 0, and `d > 0` for planes crossing the vertical below the
//!   sensor. A plateau (ground above the robot's) has a smaller `d` than the floor, a canyon a
//!   larger one. [`Plane::to_z_up`] gives `(−ρx, ρy, −d)` in a z-up frame (x forward, y left).
//! * **Normal.** The thesis's non-unit normal by default (`|n|² = sin²ρx cos²ρy + cos²ρx`, so
//!   `d` is the distance times `|n|`); [`NormalKind::Unit`] normalises it.
//! * **Angle sampling** (spec §6.6): `ρ_k = min + k·res` for `k = 0 .. ⌈(max − min)/res⌉ − 1`
//!   (ranges half open): 2 × 2 angle pairs at 45° (ρ ∈ {−45°, 0°}), 5 × 6 at 15°, 7 × 10 at 9°;
//!   0° is sampled, so the floor bin exists (a space without it is an error).
//! * **Distance binning:** bin `⌊(d − d_min)/d_res⌋` if in `0..nd`, otherwise the vote is
//!   dropped; 30 bins of 0.1 m on [−1, 2) m.
//! * **Accumulator layout:** one flat `Vec<u32>`, index `(iy·nx + ix)·nd + id`: ρy outer, ρx
//!   inner (Fig 4.3's column order), distance innermost.
//! * **#PC** is the number of valid points that voted (finite, not the all-zero "no
//!   measurement" point), including points whose every vote was dropped (spec §6.10); no votes
//!   at all is an obstacle. Ties for `bin_max` go to the first bin in storage order.
//! * **`type(bin)`** (not given in the thesis; spec §6.9): the floor's angles and distance bin
//!   → floor; the floor's angles, larger d → canyon, smaller d → plateau; any other angles →
//!   ramp. Plateaus and canyons are passable if the step `|id − id_floor| · d_res` is at most
//!   0.2 m, ramps if their combined angle `atan √(tan²ρx + tan²ρy)` is at most 35°.
//!   Drivable = floor or a passable ramp, plateau or canyon.
//! * **Preprocessing** (rule not given; spec §6.11): a frame is classified only if it has at
//!   least `min_points` (100) valid points and at least `min_valid_fraction` (10 %) of its
//!   pixels valid; otherwise the result is a non-drivable obstacle with `accepted = false`.
//!
//! Input points must be finite ([`HoughError::NonFinitePoint`]); an empty frame, absurd
//! ranges or resolutions (0, above 90°, empty ranges, too many bins), thresholds outside
//! [0, 1] or a floor without a bin are typed errors ([`HoughError`]).

pub mod accumulator;
pub mod ahead;
pub mod ball;
pub mod calibrate;
pub mod classifier;
pub mod classify;
pub mod error;
pub mod ground;
pub mod histogram;
pub mod mount;
pub mod sectors;
pub mod space;

pub use accumulator::{Accumulator, NormalTable, vote_literal};
pub use ahead::{AheadFacts, GroundAhead, classify_ahead};
pub use ball::{BallAccumulator, BallConfig, BallPlane, refine_plane};
pub use calibrate::{MountEstimate, MountSearch, MountWindow, estimate_mount};
pub use classifier::{HoughClassifier, HoughConfig, Method};
pub use classify::{
    BinType, Classification, ClassifierConfig, Preprocessing, RobotLimits, Rule, TerrainClass,
    Thresholds, algorithm3, bin_type, floor_bin,
};
pub use error::{HoughError, Result};
pub use ground::{GroundSegmenter, GroundSettings, GroundSummary};
pub use histogram::{HistogramStyle, hough_image, hough_png, hough_png_file};
pub use mount::{SensorAxes, SensorMount};
pub use sectors::{Sector, SectorClassifier, SectorGrid};
pub use space::{AngleAxis, Bin, DistanceAxis, HoughSpace, MAX_BINS, NormalKind, Plane};
