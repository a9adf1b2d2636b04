//! Reading the user's input files, with the choices the command line offers.

use anyhow::Result;
use clap::{Args, ValueEnum};
use pointcloud::PointCloud;
use pointcloud::io::depth_png::DepthCamera;
use pointcloud::io::{self, Format, ReadOptions};
use std::path::Path;

/// Depth-image conventions selectable on the command line.
#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum DepthCameraChoice {
    /// TUM RGB-D: fx = fy = 525, cx = 319.5, cy = 239.5, depth = value / 5000 m.
    Tum,
    /// OpenNI / PCL: fx = fy = 525, cx = 320, cy = 240, depth in millimetres.
    Openni,
}

/// Options for reading an input cloud.
#[derive(Args, Debug, Clone, Copy)]
pub struct InputArgs {
    /// Drop NaN/infinite points of unorganised clouds instead of failing.
    #[arg(long)]
    pub skip_non_finite: bool,
    /// For a 16-bit PNG depth image: the camera convention, instead of a sidecar
    /// `<stem>_intrinsics*.json` next to the image (or OpenNI millimetres when there is none).
    #[arg(long, value_enum)]
    pub depth_camera: Option<DepthCameraChoice>,
}

/// Reads `path` as a point cloud with the user's options.
pub fn read_cloud(path: &Path, args: &InputArgs) -> Result<PointCloud> {
    let options = ReadOptions { skip_non_finite: args.skip_non_finite };
    let is_png = Format::from_path(path) == Some(Format::DepthPng);
    Ok(match args.depth_camera {
        Some(choice) if is_png => {
            let camera = match choice {
                DepthCameraChoice::Tum => DepthCamera::tum_kinect(),
                DepthCameraChoice::Openni => DepthCamera::openni_mm(),
            };
            let image = io::read_range_image(path, Some(&camera))?;
            image.to_cloud().map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?
        }
        Some(_) => anyhow::bail!("--depth-camera applies only to .png depth images"),
        None => io::read_cloud(path, &options)?,
    })
}
