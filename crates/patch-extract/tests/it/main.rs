//! Integration tests of `patch-extract`, one binary (`cargo test -p patch-extract --test it`).

mod evaluate;
mod grid_methods;
mod lab_coverage;
mod merge;
mod mixed_pixels;
mod outline;
mod pipeline;
mod segment;
mod segment_bending;
mod trimesh_grow;
