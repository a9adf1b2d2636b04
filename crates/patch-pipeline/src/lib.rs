//! The pipeline from range scans to patch maps a robot can plan on, and the results the
//! programs report (thesis Ch. 6).
//!
//! * [`scene_map`]: maps of each kind ([`MapKind`]: planes, hybrid, trimesh, pc) of a synthetic
//!   scene in any backend, from its exact geometry or from simulated ALRF scans by patch
//!   extraction ([`MapSource`]); the scans themselves; the pc map's cleaning; the truth map that
//!   maps from scans are compared with.
//! * [`results`]: what the demo and `run` measured ([`DemoResults`]), as written to
//!   `results.json`.
//! * [`demo`]: the demo's stages on the lab (sensors, maps, safety, planning, explored
//!   volume), the pieces `patchnav run` reuses on the user's data.
//! * [`files`]: scan poses and map files.
//! * [`input`]: reading a user's cloud (depth-image conventions, non-finite points).
//! * [`preset`]: sensor presets ([`SensorPreset`]) of the extraction thresholds.
//! * [`problem`]: the runs of a planning problem of the shared exchange format and their
//!   result rows.
//! * [`terrain`]: a frame's terrain class and drivability by the plane Hough transform.
//! * [`tof`]: reading and filtering a time-of-flight frame (AAT, unwrapping, two frequencies).
//! * [`names`]: every vocabulary by name ([`names::Named`], [`names::NameParser`]).
//! * [`run_config`]: `patchnav run`, the demo's job on the user's data from a TOML file.
//! * [`parallel`]: independent runs on all cores, results in input order.
//! * [`plan`]: one planning run on a map ([`plan::plan_on_map`]), as `patchnav plan` and the
//!   Python package run it.
//! * [`polylines`]: roadmaps and paths as OBJ polylines.
//! * [`viewer`]: maps, roadmaps, paths and clouds as ROS 2 markers and clouds in an MCAP file
//!   that Foxglove and RViz replay.
//! * [`experiment`]: the thesis's experiments beside its numbers (the lab's §6.1 in
//!   [`experiment::lab`]).
//! * [`report`]: the self-contained HTML page drawn from those results.
//! * [`progress`]: how long steps say how far they got ([`Progress`]; [`Silent`] says nothing).
//!
//! The programs (`patchnav`, `bench-matrix`) parse arguments, show progress and print; the
//! logic they share lives here. No command-line type crosses into this crate: its enums parse
//! by [`FromStr`](std::str::FromStr) and list themselves with `ALL`, `name` and
//! `description`.
//!
//! Errors are [`anyhow::Error`]s with a context chain: a pipeline step joins the typed errors
//! of several libraries (files, extraction, maps, planners), and its callers print them.
//!
//! ```
//! use patch_pipeline::MapKind;
//!
//! let kind: MapKind = "hybrid".parse()?;
//! assert_eq!(kind, MapKind::Hybrid);
//! assert_eq!(kind.to_string(), "hybrid");
//! assert!("voxels".parse::<MapKind>().unwrap_err().to_string().contains("planes, hybrid"));
//! # Ok::<(), patch_pipeline::UnknownName>(())
//! ```

pub mod demo;
pub mod experiment;
pub mod files;
pub mod input;
pub mod names;
pub mod parallel;
pub mod plan;
pub mod polylines;
pub mod preset;
pub mod problem;
pub mod progress;
pub mod report;
pub mod results;
pub mod run_config;
pub mod scene_map;
pub mod terrain;
pub mod tof;
pub mod viewer;

pub use preset::SensorPreset;
pub use progress::{Progress, Silent, Ticker};
pub use results::DemoResults;
pub use scene_map::{MapKind, MapSource};

/// A name that is none of an enum's values (the [`FromStr`](std::str::FromStr) of this crate's
/// enums).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown {what} `{name}`; known: {known}")]
pub struct UnknownName {
    /// What was named (`map kind`, `map source`, `scale`).
    pub what: &'static str,
    /// The name given.
    pub name: String,
    /// The known names, comma-separated.
    pub known: String,
}

impl UnknownName {
    /// The value of `all` whose `name` is `given`, or the error that lists them.
    pub(crate) fn find<T: Copy>(
        what: &'static str,
        all: &[T],
        name: fn(T) -> &'static str,
        given: &str,
    ) -> Result<T, UnknownName> {
        all.iter().copied().find(|&v| name(v) == given).ok_or_else(|| UnknownName {
            what,
            name: given.to_owned(),
            known: all.iter().map(|&v| name(v)).collect::<Vec<_>>().join(", "),
        })
    }
}
