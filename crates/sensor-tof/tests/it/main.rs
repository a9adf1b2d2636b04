//! Integration tests of `sensor-tof`, one binary (`cargo test -p sensor-tof --test it`).

mod calibrate;
mod experiment;
mod io;
mod saturation;
mod scenes;
mod sim;
mod spatial;
mod two_freq;
