//! Integration tests of `ros-bag`, one binary (`cargo test -p patchnav-ros-bag --test it`).

mod depth_image;
mod fixture;
mod hostile;
mod laser_scan;
mod official_reader;
mod round_trip;
