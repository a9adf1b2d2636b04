//! Integration tests of `patchnav`, one binary (`cargo test -p patchnav --test it`).

mod bag;
mod cli;
mod common;
mod demo;
mod demo_report;
mod experiment_extraction;
mod experiment_lab;
mod experiment_office;
mod extract;
mod run_config;
mod terrain;
mod tof;
