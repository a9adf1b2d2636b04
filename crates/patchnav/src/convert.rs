//! `patchnav convert IN OUT`.

use crate::input::InputArgs;
use crate::progress::Progress;
use anyhow::{Result, bail};
use pointcloud::io::{self, Format};
use std::path::Path;

/// Converts `input` to `output`, formats chosen by extension. A mesh stays a mesh when both
/// sides are OBJ; otherwise the data travel as a point cloud (an OBJ input gives its vertices).
pub fn run(input: &Path, output: &Path, options: &InputArgs, progress: &Progress) -> Result<()> {
    let in_format = Format::from_path(input)
        .ok_or_else(|| anyhow::anyhow!("{}: unknown input extension", input.display()))?;
    let out_format = Format::from_path(output)
        .ok_or_else(|| anyhow::anyhow!("{}: unknown output extension", output.display()))?;
    let spinner = progress.spinner("converting");
    if out_format == Format::Obj {
        if in_format != Format::Obj {
            bail!("{}: an OBJ is written only from an OBJ mesh", output.display());
        }
        let mesh = io::read_mesh(input)?;
        io::write_mesh(output, &mesh)?;
        spinner.finish_and_clear();
        progress.say(format!(
            "wrote {} ({} vertices, {} faces)",
            output.display(),
            mesh.vertices().len(),
            mesh.faces().len()
        ));
        return Ok(());
    }
    let cloud = crate::input::read_cloud(input, options)?;
    io::write_cloud(output, &cloud)?;
    spinner.finish_and_clear();
    progress.say(format!("wrote {} ({} points, {out_format})", output.display(), cloud.len()));
    Ok(())
}
