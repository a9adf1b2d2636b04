//! `patchnav`: the command-line face of the workspace.
//!
//! ```text
//! patchnav info FILE|BAG                  what a file or a ROS bag holds
//! patchnav convert IN OUT                 between PLY, PCD, OBJ, XYZ, KITTI .bin, 3DTK .3d
//! patchnav simulate SCENE --sensor alrf|tof|stereo --poses N --out DIR
//! patchnav extract SCANS...|BAG --out MAP [--topic T] [--sensor alrf|range-camera|structured-light|exact] [--hybrid] [--export F.obj|F.ply]
//! patchnav map build INPUT --backend polygon|bbox6d|trimesh|rapier|pointcloud --out MAP
//! patchnav map info MAP
//! patchnav map export MAP --mcap OUT.mcap [--cloud CLOUD] [--frame-id map]
//! patchnav plan MAP --start x,y,z --goal x,y,z --radius R [--planner ...] [--seed K] [--mcap OUT.mcap]
//! patchnav plan --problem P.json --backend B --planner X --mode explore|solve|roi
//! patchnav experiment office|lab-timing|lab-volume ...
//! ```
//!
//! Errors are printed as one line on standard error and the exit code is 1 (2 for usage errors,
//! as clap reports them).

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

use patch_pipeline::scene_map;

mod convert;
mod demo;
mod experiment;
mod extract;
mod info;
mod input;
mod map;
mod names;
mod plan;
mod problem;
mod progress;
mod run_config;
mod simulate;
mod terrain;
mod tof;
mod tof_sim;

/// Turns 3D range data into maps a robot can plan on.
#[derive(Parser, Debug)]
#[command(name = "patchnav", version, about, long_about = None)]
struct Cli {
    /// Print nothing but errors (no progress bars, no summaries).
    #[arg(long, short, global = true)]
    quiet: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Print a file's format, point count, organised size, bounds and attributes; or a ROS
    /// bag's topics, types, message counts, time span and frames.
    Info {
        /// A cloud, mesh or depth image (.ply .pcd .obj .xyz .txt .bin .3d .png), or a ROS bag
        /// (.mcap, a rosbag2 folder, a ROS 1 .bag).
        file: PathBuf,
        #[command(flatten)]
        input: input::InputArgs,
    },
    /// Convert a cloud or mesh between formats (chosen by the file extensions).
    Convert {
        /// Input file.
        input: PathBuf,
        /// Output file (.ply .pcd .obj .xyz .bin .3d).
        output: PathBuf,
        #[command(flatten)]
        options: input::InputArgs,
    },
    /// The main job on the built-in example: simulate the lab, filter a ToF frame, classify
    /// terrain, extract patches, build every map, plan on each, and write an HTML report.
    Demo(demo::DemoArgs),
    /// The demo's job on your own data (scans + poses, a mesh, or a map file) described by a
    /// TOML file.
    Run(run_config::RunArgs),
    /// Scan a synthetic scene with a simulated sensor from several poses.
    Simulate(simulate::SimulateArgs),
    /// Planar (and trimesh) patches from range scans, merged across scans, as a map file.
    Extract(extract::ExtractArgs),
    /// Build and inspect map files.
    #[command(subcommand)]
    Map(map::MapCommand),
    /// Plan on a map file with RRT or PRM.
    Plan(plan::PlanArgs),
    /// Run the thesis's planning experiments and print our numbers beside the thesis's.
    #[command(subcommand)]
    Experiment(experiment::ExperimentCommand),
    /// Time-of-flight frames: filter wrap-around (AAT), unwrap, calibrate, simulate.
    #[command(subcommand)]
    Tof(tof::TofCommand),
    /// Classify the terrain ahead in a range frame (plane Hough transform, thesis Ch. 4).
    Terrain(terrain::TerrainArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let progress = progress::Progress::new(cli.quiet);
    let result = match cli.command {
        Command::Info { file, input } => info::run(&file, &input),
        Command::Convert { input, output, options } => {
            convert::run(&input, &output, &options, &progress)
        }
        Command::Demo(args) => demo::run(&args, &progress),
        Command::Run(args) => run_config::run(&args, &progress),
        Command::Simulate(args) => simulate::run(&args, &progress),
        Command::Extract(args) => extract::run(&args, &progress),
        Command::Map(command) => map::run(&command, &progress),
        Command::Plan(args) => plan::run(&args, &progress),
        Command::Experiment(command) => experiment::run(&command, &progress),
        Command::Tof(command) => tof::run(&command, &progress),
        Command::Terrain(args) => terrain::run(&args, &progress),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
