//! Is the map safe? Every map type the demo built is compared with the lab's exact surfaces
//! over seeded random capsule steps of the robot's radius ([`patch_map::compare`]): the
//! colliding steps a map calls free (unsafe) and the free steps it blocks (overcautious),
//! and where the unsafe ones first touch the true scene, for the report's picture. The same
//! measurement as `patchnav map compare` and `patchnav experiment map-safety`.

use super::maps::{Built, drawing};
use super::{MAX_DRAWN, RADIUS, Settings, decimate, p3mm};
use crate::results::{MapSafety, SafetySection};
use crate::scene_map::{MapKind, patch_map, truth_patches};
use anyhow::Result;
use patch_map::{Attribution, Backend, StepSampling, compare_maps};
use scene_sim::Scene;

/// Longest random step, metres.
const MAX_LENGTH: f64 = 1.0;

/// Compares every map of `built` with `scene`'s exact surfaces (its hybrid map).
///
/// # Errors
/// The scene's surfaces cannot be made into patches, or a bad sampling box.
pub fn check(
    scene: &Scene,
    built: &Built,
    seed: u64,
    settings: &Settings,
) -> Result<SafetySection> {
    let truth_patches = truth_patches(scene)?;
    let truth_drawing = drawing(MapKind::Planes, &truth_patches);
    let truth = patch_map(truth_patches, Backend::BBox6d)?;
    let sampling = StepSampling {
        radius: RADIUS,
        max_length: MAX_LENGTH,
        samples: settings.safety_samples,
        seed,
        bounds: truth.bounds(),
    };
    let mut rows = Vec::with_capacity(built.maps.len());
    for m in &built.maps {
        let c = compare_maps(&truth, &m.map, &sampling, Attribution::FirstContact)?;
        let pct = |r: patch_map::Rate| [100.0 * r.value, 100.0 * r.low, 100.0 * r.high];
        let hits: Vec<[f64; 3]> = c.unsafe_contacts.iter().map(|u| p3mm(&u.point)).collect();
        rows.push(MapSafety {
            map: m.kind.name().to_owned(),
            unsafe_pct: pct(c.unsafe_rate()),
            overcautious_pct: pct(c.overcautious_rate()),
            unsafe_steps: [c.unsafe_steps, c.truly_colliding()],
            unsafe_hits: decimate(&hits, MAX_DRAWN),
        });
    }
    Ok(SafetySection {
        samples: settings.safety_samples as u64,
        radius: RADIUS,
        max_length: MAX_LENGTH,
        truth: truth_drawing,
        rows,
    })
}
