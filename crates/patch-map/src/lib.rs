//! Patch map backends (thesis §5.4.2).
//!
//! This crate is being built up; it currently holds the spatial index of the 6D bounding-box
//! backend ([`kdtree`]) and the map file container ([`mapfile`]).

pub mod kdtree;
pub mod mapfile;
