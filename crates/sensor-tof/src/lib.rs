//! Time-of-flight cameras (thesis §2.3 and §2.5, spec `tof-hough.md` §1, §2, §6): the camera
//! model, frames, the simulator, wrap-around detection by the adaptive amplitude threshold,
//! unwrapping, and what goes beyond the thesis (two-frequency unwrapping, a spatial consistency
//! check, region unwrapping).
//!
//! | what | module | thesis |
//! |---|---|---|
//! | camera presets, non-ambiguity range, four-sample demodulation, depth vs radial range | [`camera`] | §2.3, Eqs 2.1–2.3, Table 2.1 |
//! | a frame: range + amplitude (+ intensity, + confidence) | [`frame`] | §2.3.2 |
//! | amplitude threshold, adaptive amplitude threshold, unwrapping, per-pixel outcomes | [`filter`] | §2.5.5, Eqs 2.4, 2.5 |
//! | white-wall calibration (parabola fit or raw table) | [`calibrate`] | L2338–2348 |
//! | two-frequency unwrapping | [`two_freq`] | beyond the thesis |
//! | spatial consistency of the flags | [`spatial`] | beyond the thesis |
//! | region unwrapping: unwrap only where a smooth region agrees | [`regions`] | beyond the thesis |
//! | saturated pixels, from the intensity image | [`saturation`] | beyond the thesis (L2009–2017) |
//! | simulator on `scene-sim`'s range camera | [`sim`] | §2.5.4 error types, Table 2.3 |
//! | the six test scenes of Table 2.4 | [`scenes`] | §2.5.6 |
//! | scoring against the truth | [`eval`] | Table 2.4 (+ our metrics) |
//! | the Table 2.4 experiment, folded real frames | [`experiment`] | §2.5.6 |
//! | 16-bit PNG range/amplitude pairs with a JSON sidecar | [`io`] | — |
//!
//! Where the thesis is ambiguous this crate follows the spec's resolutions: `r_p` of Eq 2.4 is
//! the depth (radial optional), the corners where the Eq 2.5 parabola goes negative pass
//! (clamping optional), unwrapping moves points along the beam, phase is `atan2` mod 2π.

pub mod calibrate;
pub mod camera;
pub mod error;
pub mod eval;
pub mod experiment;
pub mod filter;
pub mod frame;
pub mod io;
pub mod regions;
pub mod saturation;
pub mod scenes;
pub mod sim;
pub mod spatial;
pub mod two_freq;

pub use calibrate::Calibration;
pub use camera::{
    Demodulated, SPEED_OF_LIGHT, TofCamera, demodulate, modulate, non_ambiguity_range,
};
pub use error::TofError;
pub use eval::{FrameTruth, Score, score};
pub use filter::{
    AatConfig, AatRange, Detector, FilterConfig, FilterOutput, Illumination, NegativeIllumination,
    OutcomeCounts, Parabola, PixelOutcome, RayTables, TofFilter, UnwrapConfig, WhiteWallTable,
};
pub use frame::TofFrame;
pub use io::FrameMeta;
pub use regions::{RegionConfig, RegionUnwrapper, ScatterGate};
pub use saturation::Saturation;
pub use sim::{SimConfig, SimulatedFrame, TofSimulator};
pub use spatial::SpatialConfig;
pub use two_freq::{TwoFreqConfig, TwoFreqUnwrapper};
