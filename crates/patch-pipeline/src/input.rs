//! Reading a user's cloud with the choices the programs offer: skipping non-finite points of
//! unorganised clouds, and the depth-image convention of a 16-bit PNG.

use anyhow::Result;
use pointcloud::PointCloud;
use pointcloud::io::depth_png::DepthCamera;
use pointcloud::io::{self, Format, ReadOptions};
use std::path::Path;

use crate::names::named_enum;

named_enum! {
    /// The depth-image conventions a 16-bit PNG may follow.
    pub enum DepthConvention ("depth convention") {
        /// TUM RGB-D: fx = fy = 525, cx = 319.5, cy = 239.5, depth = value / 5000 m.
        Tum = "tum", "TUM RGB-D: fx = fy = 525, cx = 319.5, cy = 239.5, depth = value / 5000 m";
        /// OpenNI / PCL: fx = fy = 525, cx = 320, cy = 240, depth in millimetres.
        Openni = "openni", "OpenNI / PCL: fx = fy = 525, cx = 320, cy = 240, depth in millimetres";
    }
}

impl DepthConvention {
    /// The camera model.
    pub fn camera(self) -> DepthCamera {
        match self {
            DepthConvention::Tum => DepthCamera::tum_kinect(),
            DepthConvention::Openni => DepthCamera::openni_mm(),
        }
    }
}

/// How to read an input cloud.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct CloudInput {
    /// Drop NaN or infinite points of unorganised clouds instead of failing.
    pub skip_non_finite: bool,
    /// For a 16-bit PNG depth image: its convention, instead of a sidecar
    /// `<stem>_intrinsics*.json` next to the image (or OpenNI millimetres when there is none).
    pub depth: Option<DepthConvention>,
}

/// Reads `path` as a point cloud as `input` says.
///
/// # Errors
/// The file's own ([`io::Error`]), or a depth convention given for a file that is no PNG
/// depth image.
pub fn read_cloud(path: &Path, input: &CloudInput) -> Result<PointCloud> {
    let options = ReadOptions { skip_non_finite: input.skip_non_finite };
    let is_png = Format::from_path(path) == Some(Format::DepthPng);
    Ok(match input.depth {
        Some(convention) if is_png => {
            let image = io::read_range_image(path, Some(&convention.camera()))?;
            image.to_cloud().map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?
        }
        Some(_) => anyhow::bail!("--depth-camera applies only to .png depth images"),
        None => io::read_cloud(path, &options)?,
    })
}
