//! The conformance suite every backend runs against [`BruteForceMap`](crate::BruteForceMap)
//! (feature `conformance`; after OMPL's `PlannerTest` and nalgebra's proptest support).
//!
//! Three layers, use whichever fits:
//!
//! * [`strategies`]: proptest free-function strategies over bounded domains: polygons,
//!   patches (random orientations, and axis-aligned walls and floors on a 0.25 m grid as in a
//!   building), scenes, and steps of every kind (random, zero length, very short, crossing the
//!   scene, grazing a face, edge or vertex at `r ± tiny`, running along a plane in it or at
//!   height `r`, radius 0).
//! * [`checks`]: one function per capability comparing one answer of a backend with the
//!   reference under a [`Tolerance`] (the statements of [`capability`](crate::capability)),
//!   returning a [`TestCaseError`](proptest::test_runner::TestCaseError) for use in a
//!   backend's own `proptest!`.
//! * [`suite`] and the [`conformance_tests!`](crate::conformance_tests) macro: whole suites per
//!   capability for any `M: FromPatches`, with the case count from the environment.
//!
//! # Running the suite in a backend crate
//! ```toml
//! [dev-dependencies]
//! patch-core = { workspace = true, features = ["conformance"] }
//! ```
//! ```text
//! // tests/conformance.rs
//! use patch_core::Tolerance;
//! use patch_core::conformance::{SceneKind, SuiteConfig};
//!
//! mod polygon_map {
//!     use super::*;
//!     patch_core::conformance_tests!(
//!         patch_map::PolygonMap,
//!         SuiteConfig::from_env(Tolerance::EXACT, SceneKind::Mixed);
//!         map, map_mut, proximity, line_unspecific, line_specific,
//!         capsule_unspecific, capsule_specific, clearance_vs_capsule,
//!     );
//! }
//! ```
//! Each name becomes one `#[test]` calling [`suite`]`::<name>::<Backend>`. List only the
//! capabilities the backend implements (a point-cloud map lists `capsule_unspecific`), and
//! pick [`SceneKind::PlanarOnly`] for a backend that refuses trimesh patches.
//!
//! # Environment
//! * `PATCHNAV_CONFORMANCE_CASES`: cases per suite (default [`DEFAULT_CASES`]; set thousands
//!   for a thorough run).
//! * `PATCHNAV_CONFORMANCE_SEED`: the RNG seed (default fixed, so CI is reproducible; a
//!   failure message names the seed it ran with).

pub mod checks;
pub mod strategies;
pub mod suite;

use crate::Tolerance;

/// Cases per suite when `PATCHNAV_CONFORMANCE_CASES` is not set.
pub const DEFAULT_CASES: u32 = 256;
/// The environment variable overriding the number of cases.
pub const CASES_ENV: &str = "PATCHNAV_CONFORMANCE_CASES";
/// The environment variable overriding the RNG seed.
pub const SEED_ENV: &str = "PATCHNAV_CONFORMANCE_SEED";
/// The seed used when `PATCHNAV_CONFORMANCE_SEED` is not set.
pub const DEFAULT_SEED: u64 = 0x5eed_2010;

/// Which patches the generated scenes contain.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum SceneKind {
    /// Planar and trimesh patches.
    Mixed,
    /// Planar patches only (backends that store only polygons).
    PlanarOnly,
    /// Trimesh patches only.
    TrimeshOnly,
}

/// How a suite runs: the backend's tolerance, the scenes, the number of cases, the seed.
/// There is no `Default`: a backend states its tolerance.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct SuiteConfig {
    /// The backend's declared tolerance.
    pub tolerance: Tolerance,
    /// The patch kinds in generated scenes.
    pub scenes: SceneKind,
    /// Proptest cases per suite.
    pub cases: u32,
    /// The RNG seed.
    pub seed: u64,
}

impl SuiteConfig {
    /// The configuration with cases and seed from the environment (see the module docs).
    ///
    /// # Panics
    /// If an environment variable is set but is not a number.
    pub fn from_env(tolerance: Tolerance, scenes: SceneKind) -> SuiteConfig {
        let parse = |name: &str| {
            std::env::var(name).ok().map(|v| {
                v.trim().parse::<u64>().unwrap_or_else(|_| panic!("{name}={v} is not a number"))
            })
        };
        let cases =
            parse(CASES_ENV).map_or(DEFAULT_CASES, |c| c.clamp(1, u64::from(u32::MAX)) as u32);
        let seed = parse(SEED_ENV).unwrap_or(DEFAULT_SEED);
        SuiteConfig { tolerance, scenes, cases, seed }
    }
}

/// Generates one `#[test]` per named suite of [`suite`] for a backend type.
///
/// ```
/// use patch_core::conformance::{SceneKind, SuiteConfig};
/// use patch_core::{BruteForceMap, Tolerance};
///
/// patch_core::conformance_tests!(
///     BruteForceMap,
///     SuiteConfig::from_env(Tolerance::EXACT, SceneKind::Mixed);
///     map, proximity, capsule_specific,
/// );
/// # fn main() {}
/// ```
/// expands to `#[test] fn map() { patch_core::conformance::suite::map::<MyMap>(&config) }`
/// and so on. Put it in its own module per backend so the test names do not clash.
#[macro_export]
macro_rules! conformance_tests {
    ($map:ty, $config:expr; $($suite:ident),+ $(,)?) => {
        $(
            #[test]
            fn $suite() {
                $crate::conformance::suite::$suite::<$map>(&$config);
            }
        )+
    };
}
