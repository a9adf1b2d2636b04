//! What the project measures itself against and how it summarises what it measured: the
//! thesis's published tables ([`thesis`]) and the statistics every experiment, report and
//! comparison prints ([`stats`]), the benchmarks page `cargo xtask docs` writes
//! ([`benchmarks`]) and the OMPL benchmark logs of the planning matrix ([`ompl_log`]). Not
//! published: it serves the pipeline's experiments, the
//! benchmark matrix and the docs and comparison generators of `xtask`.
//!
//! ```
//! use evaluation::stats::{median, quantile};
//!
//! assert_eq!(median([3.0, 1.0, 2.0, f64::NAN]), Some(2.0));
//! assert_eq!(quantile(&[1.0, 2.0, 3.0, 4.0], 0.75), Some(3.25));
//! assert_eq!(evaluation::thesis::TABLE_6_1.len(), 4);
//! ```

pub mod benchmarks;
pub mod ompl_log;
pub mod stats;
pub mod thesis;
