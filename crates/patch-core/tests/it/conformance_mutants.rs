//! Deliberately wrong backends, each with one classic mistake: the conformance suite must
//! reject every one of them. If a suite stops catching its mutant, the `should_panic` test
//! fails (an expected failure that passes is a failure).

use patch_core::conformance::{SceneKind, SuiteConfig, suite};
use patch_core::{
    Aabb, BruteForceMap, CapsuleStep, FromPatches, MapError, Patch, PatchId, PatchMap, PlanarPatch,
    Point3, Polygon, Proximity, ProximityQuery, Real, SpecificStepIntersector, Step, StepHit,
    Tolerance, UnspecificStepIntersector,
};

/// The mistakes.
const IGNORES_RADIUS: u8 = 0;
const ENDPOINTS_ONLY: u8 = 1;
const CLOSEST_APPROACH_AS_FIRST_HIT: u8 = 2;
const UNFLIPPED_NORMAL: u8 = 3;
const BOX_PRUNE_WITHOUT_RADIUS: u8 = 4;
const IGNORES_HOLES: u8 = 5;
const SQUARED_DISTANCE: u8 = 6;
const WRONG_PATCH_ID: u8 = 7;

struct Mutant<const KIND: u8> {
    /// What the map claims to hold.
    reference: BruteForceMap,
    /// What it answers queries from (differs for `IGNORES_HOLES`).
    answers: BruteForceMap,
}

fn strip_holes(p: Patch) -> Patch {
    match p {
        Patch::Planar(q) if !q.polygon().holes().is_empty() => {
            let outer = q.polygon().outer().points().to_vec();
            let polygon = Polygon::new(outer, Vec::new()).unwrap();
            PlanarPatch::new(polygon, *q.world_from_patch()).unwrap().into()
        }
        other => other,
    }
}

impl<const KIND: u8> FromPatches for Mutant<KIND> {
    type Error = MapError;
    fn from_patches(patches: impl IntoIterator<Item = Patch>) -> Result<Self, MapError> {
        let patches: Vec<Patch> = patches.into_iter().collect();
        let answers = if KIND == IGNORES_HOLES {
            BruteForceMap::from_patches(patches.iter().cloned().map(strip_holes))?
        } else {
            BruteForceMap::from_patches(patches.clone())?
        };
        Ok(Mutant { reference: BruteForceMap::from_patches(patches)?, answers })
    }
}

impl<const KIND: u8> PatchMap for Mutant<KIND> {
    fn patches(&self) -> &[Patch] {
        self.reference.patches()
    }
    fn bounds(&self) -> Aabb {
        self.reference.bounds()
    }
    fn tolerance(&self) -> patch_core::Tolerance {
        patch_core::Tolerance::EXACT
    }
}

impl<const KIND: u8> ProximityQuery for Mutant<KIND> {
    fn closest_patch(&self, point: &Point3, max_dist: Real) -> Option<Proximity> {
        let mut p = self.answers.closest_patch(point, max_dist)?;
        if KIND == SQUARED_DISTANCE {
            p.distance *= p.distance;
        }
        Some(p)
    }
}

impl<const KIND: u8> UnspecificStepIntersector for Mutant<KIND> {
    fn is_step_free(&self, step: &CapsuleStep) -> bool {
        match KIND {
            IGNORES_RADIUS => self.answers.is_step_free(&step.line()),
            ENDPOINTS_ONLY => {
                let r = step.radius();
                self.answers.is_step_free(&CapsuleStep::sphere(step.start(), r).unwrap())
                    && self.answers.is_step_free(&CapsuleStep::sphere(step.end(), r).unwrap())
            }
            BOX_PRUNE_WITHOUT_RADIUS => {
                let b = Aabb::new(step.start(), step.end());
                self.answers
                    .patches()
                    .iter()
                    .filter(|p| p.bounds().intersects(&b))
                    .all(|p| !p.collides_with(step))
            }
            _ => self.answers.is_step_free(step),
        }
    }
}

impl<const KIND: u8> SpecificStepIntersector for Mutant<KIND> {
    fn first_hit(&self, step: &CapsuleStep) -> Option<StepHit> {
        let mut hit = self.answers.first_hit(step)?;
        match KIND {
            CLOSEST_APPROACH_AS_FIRST_HIT => {
                let d = self.answers.step_distance(step).unwrap();
                hit = StepHit { patch: d.patch, t: d.t, point: d.point, normal: hit.normal };
                if let Some(c) = self.answers.patches()[d.patch.index()].step_contact(step) {
                    hit.normal = c.normal;
                }
            }
            UNFLIPPED_NORMAL => {
                if let Patch::Planar(p) = &self.answers.patches()[hit.patch.index()] {
                    hit.normal = p.normal();
                }
            }
            WRONG_PATCH_ID => hit.patch = PatchId((hit.patch.0 + 1) % self.answers.len() as u32),
            _ => {}
        }
        Some(hit)
    }
}

fn config() -> SuiteConfig {
    SuiteConfig::from_env(Tolerance::EXACT, SceneKind::Mixed)
}

#[test]
#[should_panic(expected = "a colliding step was reported free")]
fn catches_ignoring_the_radius() {
    suite::capsule_unspecific::<Mutant<IGNORES_RADIUS>>(&config());
}

#[test]
#[should_panic(expected = "a colliding step was reported free")]
fn catches_checking_only_the_endpoints() {
    suite::capsule_unspecific::<Mutant<ENDPOINTS_ONLY>>(&config());
}

#[test]
#[should_panic(expected = "already collides before")]
fn catches_closest_approach_as_first_hit() {
    suite::capsule_specific::<Mutant<CLOSEST_APPROACH_AS_FIRST_HIT>>(&config());
}

#[test]
#[should_panic(expected = "faces away")]
fn catches_unflipped_normals() {
    suite::capsule_specific::<Mutant<UNFLIPPED_NORMAL>>(&config());
}

#[test]
#[should_panic(expected = "a colliding step was reported free")]
fn catches_a_broad_phase_without_the_radius() {
    suite::capsule_unspecific::<Mutant<BOX_PRUNE_WITHOUT_RADIUS>>(&config());
}

#[test]
#[should_panic(expected = "a free step was reported colliding")]
fn catches_ignored_holes() {
    suite::capsule_unspecific::<Mutant<IGNORES_HOLES>>(&config());
}

#[test]
#[should_panic(expected = "closest_patch distance")]
fn catches_squared_distances() {
    suite::proximity::<Mutant<SQUARED_DISTANCE>>(&config());
}

#[test]
#[should_panic(expected = "conformance suite `capsule_specific` failed")]
fn catches_wrong_patch_ids() {
    suite::capsule_specific::<Mutant<WRONG_PATCH_ID>>(&config());
}

#[test]
fn the_unmutated_map_passes() {
    suite::capsule_specific::<Mutant<255>>(&config());
    suite::proximity::<Mutant<255>>(&config());
}
