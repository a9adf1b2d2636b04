//! Saturated pixels (beyond the thesis): a pixel whose brightest sample reaches the sensor's
//! full well has lost its modulation, so its range is random.
//!
//! Sunlight (L2009–2017: the SR-3000 suppresses background light only up to 400 W/m²/µm) and a
//! bright surface closer than the minimum range (L2259–2269) fill the well. The thesis found
//! its sunlit snapshots "significantly distorted but not automatically recognizable" (§4.4,
//! L3928–3931). With the intensity image (Eq 2.3) they are: of the four samples
//! `τk = B − A cos(φ − k·90°)` the brightest is at most `B + A`, so a pixel with
//! `B + A ≥ fraction · full well` may have clipped. Cameras that flag saturation themselves
//! (ifm's confidence bit 1) do the same test on the raw samples.
//!
//! ```
//! use sensor_tof::Saturation;
//! let s = Saturation::new(65_535.0, 0.9).unwrap();
//! assert!(s.is_saturated(60_000.0, 200.0));
//! assert!(!s.is_saturated(5_000.0, 1_500.0));
//! ```

use crate::{TofError, TofFrame};
use pointcloud::Real;
use serde::{Deserialize, Serialize};

/// The saturation test: a pixel is saturated when `intensity + amplitude ≥ fraction ·
/// full_well`.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Saturation {
    /// The level at which a sample clips, in the amplitude units of the frame (> 0; 65,535
    /// for a 16-bit sample, the simulator's [`SimConfig::saturation`](crate::sim::SimConfig)).
    pub full_well: Real,
    /// The share of the full well that already counts as saturated, in `(0, 1]`: the
    /// demodulated `B + A` of a clipped pixel falls below the full well by the clipped part
    /// and the noise. 0.9 by default.
    pub fraction: Real,
}

impl Saturation {
    /// A checked test.
    pub fn new(full_well: Real, fraction: Real) -> Result<Saturation, TofError> {
        if !(full_well.is_finite() && full_well > 0.0) {
            return Err(TofError::BadParameter {
                what: "full well",
                why: format!("{full_well} (want finite and > 0)"),
            });
        }
        if !(fraction > 0.0 && fraction <= 1.0) {
            return Err(TofError::BadParameter {
                what: "saturation fraction",
                why: format!("{fraction} (want (0, 1])"),
            });
        }
        Ok(Saturation { full_well, fraction })
    }

    /// The simulated SR-3000's 16-bit samples ([`SimConfig::sr3000`](crate::sim::SimConfig::sr3000)),
    /// at 0.9 of the full well.
    pub fn sr3000() -> Saturation {
        Saturation { full_well: 65_535.0, fraction: 0.9 }
    }

    /// Whether a pixel of this `intensity` and `amplitude` may have clipped.
    pub fn is_saturated(&self, intensity: f32, amplitude: f32) -> bool {
        Real::from(intensity) + Real::from(amplitude) >= self.fraction * self.full_well
    }

    /// One flag per pixel of `frame`. Fails if the frame has no intensity image.
    pub fn mask(&self, frame: &TofFrame) -> Result<Vec<bool>, TofError> {
        let intensity = frame.intensity().ok_or_else(|| TofError::BadImage {
            what: "intensity",
            why: "the frame has none; the saturation test needs it (Eq 2.3)".into(),
        })?;
        Ok(intensity
            .iter()
            .zip(frame.amplitude())
            .map(|(&b, &a)| self.is_saturated(b, a))
            .collect())
    }
}
