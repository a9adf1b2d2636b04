//! `patchnav info FILE|BAG`.

use crate::input::InputArgs;
use anyhow::Result;
use pointcloud::io::{self, Format};
use pointcloud::{Aabb, PointCloud};
use ros_bag::{Bag, BagInfo};
use std::fmt::Write as _;
use std::path::Path;

/// Prints what `file` holds.
pub fn run(file: &Path, input: &InputArgs) -> Result<()> {
    print!("{}", describe(file, input)?);
    Ok(())
}

/// The text `info` prints for `file`.
pub fn describe(file: &Path, input: &InputArgs) -> Result<String> {
    if crate::extract::is_bag(file) {
        return describe_bag(file);
    }
    let format = Format::from_path(file)
        .ok_or_else(|| anyhow::anyhow!("{}: unknown file extension", file.display()))?;
    let mut out = String::new();
    writeln!(out, "file:       {}", file.display())?;
    writeln!(out, "format:     {format}")?;
    if format == Format::Obj {
        let mesh = io::read_mesh(file)?;
        writeln!(out, "vertices:   {}", mesh.vertices().len())?;
        writeln!(out, "faces:      {} ({} triangles)", mesh.faces().len(), mesh.num_triangles())?;
        write_bounds(&mut out, &mesh.bounds())?;
        return Ok(out);
    }
    let cloud = crate::input::read_cloud(file, input)?;
    describe_cloud(&mut out, &cloud)?;
    Ok(out)
}

/// Seconds since the epoch, to the millisecond.
fn seconds(ns: u64) -> String {
    format!("{}.{:03}", ns / 1_000_000_000, ns % 1_000_000_000 / 1_000_000)
}

/// The text `info` prints for a bag: its topics, types, counts, time span and frames.
fn describe_bag(path: &Path) -> Result<String> {
    let bag = Bag::open(path)?;
    let info = BagInfo::of(&bag)?;
    let mut out = String::new();
    writeln!(out, "bag:        {}", path.display())?;
    writeln!(out, "format:     {}", bag.format().name())?;
    if bag.files().len() > 1 {
        writeln!(out, "files:      {}", bag.files().len())?;
    }
    writeln!(out, "messages:   {}", info.messages)?;
    if info.messages > 0 {
        let span = (info.end_ns - info.start_ns) as f64 * 1e-9;
        let (start, end) = (seconds(info.start_ns), seconds(info.end_ns));
        writeln!(out, "time:       {start} .. {end} s ({span:.3} s)")?;
    }
    let join = |v: Vec<&str>| if v.is_empty() { "none".to_owned() } else { v.join(", ") };
    writeln!(out, "frames:     {}", join(info.frames.iter().map(String::as_str).collect()))?;
    let tf: Vec<String> = info.transforms.iter().map(|(p, c)| format!("{p} -> {c}")).collect();
    writeln!(out, "transforms: {}", join(tf.iter().map(String::as_str).collect()))?;
    writeln!(out, "topics:     {}", info.topics.len())?;
    let width = info.topics.iter().map(|t| t.topic.len()).max().unwrap_or(0);
    let type_width = info.topics.iter().map(|t| t.type_name.len()).max().unwrap_or(0);
    for t in &info.topics {
        let frames = join(t.frames.iter().map(String::as_str).collect());
        writeln!(
            out,
            "  {:<width$}  {:<type_width$}  {:>6} msgs  {} .. {} s  frames {frames}",
            t.topic,
            t.type_name,
            t.count,
            seconds(t.first_ns),
            seconds(t.last_ns),
        )?;
    }
    Ok(out)
}

fn describe_cloud(out: &mut String, cloud: &PointCloud) -> Result<()> {
    writeln!(out, "points:     {}", cloud.len())?;
    match cloud.grid() {
        Some(g) => writeln!(
            out,
            "organised:  {} × {} ({} pixels, {} valid)",
            g.width(),
            g.height(),
            g.num_pixels(),
            g.num_valid()
        )?,
        None => writeln!(out, "organised:  no")?,
    }
    write_bounds(out, &cloud.bounds())?;
    let mut attrs: Vec<String> = Vec::new();
    if cloud.intensity().is_some() {
        attrs.push("intensity".into());
    }
    if cloud.normals().is_some() {
        attrs.push("normals".into());
    }
    if cloud.labels().is_some() {
        attrs.push("labels".into());
    }
    if cloud.rings().is_some() {
        attrs.push("rings".into());
    }
    attrs.extend(cloud.extra_fields().iter().map(|f| f.name.clone()));
    let attrs = if attrs.is_empty() { "none".to_owned() } else { attrs.join(", ") };
    writeln!(out, "attributes: {attrs}")?;
    if let Some(pose) = cloud.sensor_pose() {
        let t = pose.world_from_sensor.translation.vector;
        let (r, p, y) = pose.world_from_sensor.rotation.euler_angles();
        writeln!(
            out,
            "sensor:     at ({:.3}, {:.3}, {:.3}) m, roll {:.1}° pitch {:.1}° yaw {:.1}° (points in the sensor frame)",
            t.x,
            t.y,
            t.z,
            r.to_degrees(),
            p.to_degrees(),
            y.to_degrees()
        )?;
    }
    Ok(())
}

fn write_bounds(out: &mut String, b: &Aabb) -> Result<()> {
    if b.is_empty() {
        writeln!(out, "bounds:     empty")?;
    } else {
        let e = b.extents();
        writeln!(
            out,
            "bounds:     ({:.3}, {:.3}, {:.3}) .. ({:.3}, {:.3}, {:.3}) m, size {:.3} × {:.3} × {:.3} m",
            b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z, e.x, e.y, e.z
        )?;
    }
    Ok(())
}
