//! Integration tests of `scene-sim`, one binary (`cargo test -p scene-sim --test it`).

mod scenes;
mod sensors;
