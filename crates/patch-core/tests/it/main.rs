//! Integration tests of `patch-core`, one binary (`cargo test -p patch-core --test it`).

mod conformance_mutants;
mod conformance_reference;
mod oracle;
mod serde;
