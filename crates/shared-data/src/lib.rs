//! Where tests and benchmarks find the project's shared data, and what they do when it is
//! missing. A dev-dependency only: no library or program depends on it.
//!
//! The shared folder sits next to the checkout (`../shared` from the workspace root): real
//! scans and frames in `data/real` (each with a `SOURCE.md`; never committed, for their
//! licences) and the benchmark floor plan in `bench`. An environment variable points
//! elsewhere: [`REAL_DATA_VAR`] for `data/real`, [`BENCH_VAR`] for `bench`.
//!
//! A folder that is missing is a skip outside CI: a `SKIPPED: …` line on the uncaptured
//! stderr, so it shows in every test run's output, and `None`. Where [`REQUIRE_VAR`] is set
//! (`.ci/run` sets it: CI has the shared folder), a missing folder panics instead, so a data
//! test can never pass without its data there.
//!
//! # Example
//! ```
//! if let Some(dir) = shared_data::real_data("ifm_o3r_tof_frame") {
//!     assert!(dir.is_dir());
//! }
//! ```

use std::path::{Path, PathBuf};

/// Overrides the real-data folder (`shared/data/real`).
pub const REAL_DATA_VAR: &str = "PATCHNAV_REAL_DATA";
/// Overrides the benchmark folder (`shared/bench`).
pub const BENCH_VAR: &str = "PATCHNAV_BENCH";
/// When set (to anything), a missing folder panics instead of skipping.
pub const REQUIRE_VAR: &str = "PATCHNAV_REQUIRE_DATA";

/// The shared folder next to the checkout.
fn shared_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared")
}

/// `name` inside the real-data folder (`$PATCHNAV_REAL_DATA` or `shared/data/real`; `""`:
/// the folder itself), or `None` after a `SKIPPED` line if it is missing (a panic where
/// [`REQUIRE_VAR`] is set).
pub fn real_data(name: &str) -> Option<PathBuf> {
    located(REAL_DATA_VAR, "data/real", name)
}

/// `name` inside the benchmark folder (`$PATCHNAV_BENCH` or `shared/bench`; `""`: the folder
/// itself), as [`real_data`].
pub fn bench(name: &str) -> Option<PathBuf> {
    located(BENCH_VAR, "bench", name)
}

fn located(var: &str, relative: &str, name: &str) -> Option<PathBuf> {
    let folder = std::env::var_os(var).map_or_else(|| shared_root().join(relative), PathBuf::from);
    let path = if name.is_empty() { folder } else { folder.join(name) };
    if path.exists() {
        return Some(path);
    }
    let message = format!("{} not found (set {var} to its folder)", path.display());
    if std::env::var_os(REQUIRE_VAR).is_some() {
        panic!("{message}; {REQUIRE_VAR} is set, so the data must be there");
    }
    // Straight to the stderr handle, not `eprintln!`: the harness captures that, and a skipped
    // check must show in every run's output.
    use std::io::Write as _;
    let _ = writeln!(std::io::stderr(), "SKIPPED: {message}");
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_name_is_none_and_an_existing_folder_is_found() {
        if std::env::var_os(REQUIRE_VAR).is_some() {
            return; // a missing name panics there by design
        }
        assert_eq!(real_data("no such folder, surely"), None);
        // An absolute name replaces the folder: this crate's own folder exists.
        let here = env!("CARGO_MANIFEST_DIR");
        assert_eq!(located("SHARED_DATA_TEST_UNSET", "", here), Some(PathBuf::from(here)));
    }
}
