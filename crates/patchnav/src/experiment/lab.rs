//! The command line of `patchnav experiment lab-timing` and `lab-volume`: arguments that
//! become [`patch_pipeline::experiment::lab`]'s settings; the experiments themselves live there.

use anyhow::Result;
use clap::Args;
use patch_core::Real;
use patch_extract::MixedPixelFix;
use patch_map::Backend;
use patch_pipeline::experiment::lab::{self, LabSetup, LabTimingSetup, LabVolumeSetup};
use patch_pipeline::{MapKind, MapSource};
use std::path::PathBuf;

use crate::progress::Progress;

/// How the lab and its maps are made (shared by both experiments).
#[derive(Args, Debug)]
pub struct LabMapArgs {
    /// Seed of the lab's furniture (scene-sim's `lab`).
    #[arg(long, default_value_t = 0)]
    pub scene_seed: u64,
    /// Simulated ALRF scans in the pc map (the thesis's Lab has 29).
    #[arg(long, default_value_t = 8)]
    pub scans: usize,
    /// Angular step of the simulated ALRF in degrees (default: the S300's 0.5°).
    #[arg(long)]
    pub scan_step_deg: Option<Real>,
    /// Height of the scanner above the floor, metres.
    #[arg(long, default_value_t = 0.5)]
    pub scan_height: Real,
    /// Longest edge when tessellating curved surfaces (hybrid and trimesh maps), metres.
    #[arg(long, default_value_t = 0.1)]
    pub curved_edge: Real,
    /// Longest triangle edge of the trimesh map, metres.
    #[arg(long, default_value_t = 0.1)]
    pub mesh_edge: Real,
    /// Most triangles per trimesh patch of the trimesh map (the thesis's average: 324).
    #[arg(long, default_value_t = 324)]
    pub max_patch_triangles: usize,
    /// Where the planes, hybrid and trimesh maps come from: the scene's exact geometry, or
    /// patch extraction from the simulated scans (as the thesis built its maps).
    #[arg(long, value_parser = crate::names::all::<MapSource>(), default_value_t = MapSource::Scans)]
    pub source: MapSource,
    /// Backend of the planes, hybrid and trimesh maps (the pc map is always a point-cloud map).
    #[arg(long, value_parser = crate::names::patch_backends(), default_value_t = Backend::Trimesh)]
    pub backend: Backend,
    /// The map types to run, comma-separated.
    #[arg(long, value_parser = crate::names::all::<MapKind>(), value_delimiter = ',', default_values_t = MapKind::ALL)]
    pub maps: Vec<MapKind>,
    /// Robot radius (the capsule of every step), metres (not given in the thesis for the Lab).
    #[arg(long, default_value_t = 0.3)]
    pub radius: Real,
    /// Longest RRT edge, metres (not given in the thesis for the Lab).
    #[arg(long, default_value_t = 1.0)]
    pub step: Real,
    /// Starts near the room corners (1–4).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u64).range(1..=4))]
    pub starts: u64,
    /// Iterations of every run (K).
    #[arg(long, default_value_t = 1000)]
    pub max_iterations: u64,
    /// Clean the pc map's scans of mixed pixels first (`snap` onto their foreground, or
    /// `remove`); without it the pc map is the raw scans, as the thesis's.
    #[arg(long)]
    pub pc_mixed_pixels: Option<MixedPixelFix>,
    /// Denoise the pc map's scans along their beams (after --pc-mixed-pixels).
    #[arg(long)]
    pub pc_denoise: bool,
    /// Sample every map in the box common to all maps (their intersection) instead of each
    /// map's own box (the thesis's choice, L6460; the pc map's box is larger by the sensor
    /// noise).
    #[arg(long)]
    pub common_box: bool,
}

/// Arguments of `patchnav experiment lab-timing`.
#[derive(Args, Debug)]
pub struct LabTimingArgs {
    #[command(flatten)]
    pub lab: LabMapArgs,
    /// RRT seeds per start (seeds 1..=N).
    #[arg(long, default_value_t = 24)]
    pub seeds: u64,
    /// Checkpoints per run: the time is recorded every K/N iterations (and at 100, 500, 1000).
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u64).range(1..=10_000))]
    pub checkpoints: u64,
    /// Directory for `lab-timing.csv` and `lab-timing.svg`.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Arguments of `patchnav experiment lab-volume`.
#[derive(Args, Debug)]
pub struct LabVolumeArgs {
    #[command(flatten)]
    pub lab: LabMapArgs,
    /// RRT seeds per start (the thesis: 120, so 480 RRTs per map).
    #[arg(long, default_value_t = 24)]
    pub seeds: u64,
    /// PRM seeds (the thesis does not say; spec §7.11 suggests 120).
    #[arg(long, default_value_t = 24)]
    pub prm_seeds: u64,
    /// PRM iterations (default: --max-iterations).
    #[arg(long)]
    pub prm_iterations: Option<u64>,
    /// Voxels per axis of the common grid (the thesis: 1024 cells of 38.684 mm; 320 gives
    /// about that cell size on the lab).
    #[arg(long, default_value_t = 320, value_parser = clap::value_parser!(u32).range(1..=65_536))]
    pub cells: u32,
}

impl LabMapArgs {
    /// The library's settings.
    pub fn setup(&self) -> LabSetup {
        LabSetup {
            scene_seed: self.scene_seed,
            scans: self.scans,
            scan_step_deg: self.scan_step_deg,
            scan_height: self.scan_height,
            curved_edge: self.curved_edge,
            mesh_edge: self.mesh_edge,
            max_patch_triangles: self.max_patch_triangles,
            source: self.source,
            backend: self.backend,
            maps: self.maps.clone(),
            radius: self.radius,
            step: self.step,
            starts: self.starts,
            max_iterations: self.max_iterations,
            pc_mixed_pixels: self.pc_mixed_pixels,
            pc_denoise: self.pc_denoise,
            common_box: self.common_box,
        }
    }
}

/// Runs `patchnav experiment lab-timing`.
pub fn run_timing(args: &LabTimingArgs, progress: &Progress) -> Result<()> {
    let setup = LabTimingSetup {
        lab: args.lab.setup(),
        seeds: args.seeds,
        checkpoints: args.checkpoints,
        out: args.out.clone(),
    };
    lab::run_timing(&setup, progress)
}

/// Runs `patchnav experiment lab-volume`.
pub fn run_volume(args: &LabVolumeArgs, progress: &Progress) -> Result<()> {
    let setup = LabVolumeSetup {
        lab: args.lab.setup(),
        seeds: args.seeds,
        prm_seeds: args.prm_seeds,
        prm_iterations: args.prm_iterations,
        cells: args.cells,
    };
    lab::run_volume(&setup, progress)
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser, Debug)]
    struct Cli {
        #[command(flatten)]
        lab: LabMapArgs,
    }

    #[test]
    fn the_command_line_defaults_are_the_library_defaults() {
        let cli = Cli::try_parse_from(["cli"]).unwrap();
        assert_eq!(cli.lab.setup(), LabSetup::default());
        let timing = LabTimingSetup::default();
        let volume = LabVolumeSetup::default();
        assert_eq!((timing.seeds, timing.checkpoints), (24, 20));
        assert_eq!((volume.seeds, volume.prm_seeds, volume.cells), (24, 24, 320));
    }
}
