//! What the project measures itself against and how it summarises what it measured: the
//! thesis's published tables ([`thesis`]) and the statistics every experiment, report and
//! comparison prints ([`stats`]), the benchmarks page `cargo xtask docs` writes
//! ([`benchmarks`]), the OMPL benchmark logs of the planning matrix ([`ompl_log`]), and the
//! generators of the comparisons with established systems ([`compare`], [`peers`]): they run
//! both sides on the same inputs, score them against ground truth and tabulate the ratios. Not
//! published: it serves the pipeline's experiments, the benchmark matrix and `xtask`, which
//! keeps argument parsing, cargo calls and provenance.
//!
//! ```
//! use evaluation::stats::{median, quantile};
//!
//! assert_eq!(median([3.0, 1.0, 2.0, f64::NAN]), Some(2.0));
//! assert_eq!(quantile(&[1.0, 2.0, 3.0, 4.0], 0.75), Some(3.25));
//! assert_eq!(evaluation::thesis::TABLE_6_1.len(), 4);
//! ```

pub mod benchmarks;
pub mod compare;
pub mod ompl_log;
pub mod peers;
pub mod stats;
pub mod thesis;
