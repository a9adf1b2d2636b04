//! Integration tests of `patch-map`, one binary (`cargo test -p patch-map --test it`).

mod capabilities;
mod conformance;
mod floorplan;
mod mapfile;
