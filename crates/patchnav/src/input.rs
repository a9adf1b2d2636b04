//! Reading the user's input files, with the choices the command line offers
//! ([`patch_pipeline::input`]).

use anyhow::Result;
use clap::Args;
use patch_pipeline::input::{CloudInput, DepthConvention};
use pointcloud::PointCloud;
use std::path::Path;

/// Options for reading an input cloud.
#[derive(Args, Debug, Clone, Copy)]
pub struct InputArgs {
    /// Drop NaN/infinite points of unorganised clouds instead of failing.
    #[arg(long)]
    pub skip_non_finite: bool,
    /// For a 16-bit PNG depth image: the camera convention, instead of a sidecar
    /// `<stem>_intrinsics*.json` next to the image (or OpenNI millimetres when there is none).
    #[arg(long, value_parser = crate::names::all::<DepthConvention>())]
    pub depth_camera: Option<DepthConvention>,
}

impl InputArgs {
    /// The library's reading options.
    pub fn input(&self) -> CloudInput {
        CloudInput { skip_non_finite: self.skip_non_finite, depth: self.depth_camera }
    }
}

/// Reads `path` as a point cloud with the user's options.
pub fn read_cloud(path: &Path, args: &InputArgs) -> Result<PointCloud> {
    patch_pipeline::input::read_cloud(path, &args.input())
}
