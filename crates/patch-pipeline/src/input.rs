//! Reading a user's cloud with the choices the programs offer: skipping non-finite points of
//! unorganised clouds, and the depth-image convention of a 16-bit PNG.

use anyhow::Result;
use pointcloud::PointCloud;
use pointcloud::io::depth_png::DepthCamera;
use pointcloud::io::{self, Format, ReadOptions};
use std::fmt;
use std::path::Path;
use std::str::FromStr;

use crate::UnknownName;

/// The depth-image conventions a 16-bit PNG may follow.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum DepthConvention {
    /// TUM RGB-D: fx = fy = 525, cx = 319.5, cy = 239.5, depth = value / 5000 m.
    Tum,
    /// OpenNI / PCL: fx = fy = 525, cx = 320, cy = 240, depth in millimetres.
    Openni,
}

impl DepthConvention {
    /// Both.
    pub const ALL: [DepthConvention; 2] = [DepthConvention::Tum, DepthConvention::Openni];

    /// The lower-case name (`tum`, `openni`).
    pub fn name(self) -> &'static str {
        match self {
            DepthConvention::Tum => "tum",
            DepthConvention::Openni => "openni",
        }
    }

    /// One line for help texts.
    pub fn description(self) -> &'static str {
        match self {
            DepthConvention::Tum => {
                "TUM RGB-D: fx = fy = 525, cx = 319.5, cy = 239.5, depth = value / 5000 m"
            }
            DepthConvention::Openni => {
                "OpenNI / PCL: fx = fy = 525, cx = 320, cy = 240, depth in millimetres"
            }
        }
    }

    /// The camera model.
    pub fn camera(self) -> DepthCamera {
        match self {
            DepthConvention::Tum => DepthCamera::tum_kinect(),
            DepthConvention::Openni => DepthCamera::openni_mm(),
        }
    }
}

impl fmt::Display for DepthConvention {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for DepthConvention {
    type Err = UnknownName;

    fn from_str(name: &str) -> Result<DepthConvention, UnknownName> {
        UnknownName::find("depth convention", &DepthConvention::ALL, DepthConvention::name, name)
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
