//! Integration tests of `hough-terrain`, one binary (`cargo test -p hough-terrain --test it`).

mod ahead;
mod algorithm3;
mod ball;
mod common;
mod literal;
mod scenes;
mod sectors;
mod streaming;
