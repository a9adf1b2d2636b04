//! Integration tests of `roadmap`, one binary (`cargo test -p patchnav-roadmap --test it`).

mod common;
mod connect;
mod evasion;
mod every_planner;
mod example_data;
mod lazy_prm;
mod medial;
mod planners;
mod prm_star;
mod prm_valid;
mod rrt_star;
mod smoothing;
mod volume;
