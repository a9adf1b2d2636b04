//! Maps, roadmaps, paths and clouds as ROS 2 messages in an MCAP file that a robot viewer
//! replays: Foxglove opens it directly, RViz through `ros2 bag play`.
//!
//! Every topic holds one message, stamped and recorded at the header's stamp, in the header's
//! frame (`map` by default, [`DEFAULT_FRAME_ID`]):
//!
//! | topic | type | what |
//! |---|---|---|
//! | [`MAP_TOPIC`] `/patchnav/map` | `visualization_msgs/MarkerArray` | a patch map: one `TRIANGLE_LIST` marker per patch kind present (planar, trimesh), its namespace the kind's name, its colour [`kind_colour`] |
//! | [`MAP_POINTS_TOPIC`] `/patchnav/map_points` | `sensor_msgs/PointCloud2` | a point-cloud map's points (it has no patches) |
//! | [`ROADMAP_TOPIC`] `/patchnav/roadmap` | `visualization_msgs/MarkerArray` | one `LINE_LIST` marker (namespace `roadmap`), a segment per edge |
//! | [`PATH_TOPIC`] `/patchnav/path` | `visualization_msgs/MarkerArray` | one `LINE_STRIP` marker per path (namespace `path`, id = the goal's index) |
//! | [`CLOUD_TOPIC`] `/patchnav/cloud` | `sensor_msgs/PointCloud2` | an input cloud |
//!
//! The patch kinds are `patch_core`'s [`PatchKind`]s: planar polygons (triangulated by
//! [`patch_core::triangulate::patch_triangles`], the constrained Delaunay triangulation the
//! mesh backends use) and triangle meshes (their own triangles). Paths and the roadmap are
//! MarkerArrays too, so that one display type draws every marker topic and several paths
//! (one per goal) fit one message. A marker without enough points to draw (an empty roadmap,
//! a path of one vertex, a kind without triangles) is left out; the topic's message is
//! written all the same, so every file of one command has the same topics and counts.
//!
//! Triangles keep the winding of their source (counter-clockwise about a planar patch's
//! normal); viewers that cull back faces show a surface from one side only.

use anyhow::{Context, Result, bail};
use patch_core::triangulate::patch_triangles;
use patch_core::{Patch, PatchKind, Point3};
use patch_map::AnyMap;
use pointcloud::PointCloud;
use pointcloud::io::pointcloud2::{self, Pc2Layout, PointCloud2};
use ros_bag::msgs::markers::{
    ColorRgba, LINE_LIST, LINE_STRIP, Marker, MarkerArray, TRIANGLE_LIST,
};
use ros_bag::msgs::{MARKER_ARRAY, POINT_CLOUD2};
use ros_bag::{BagFormat, BagWriter, Header};
use std::fmt;
use std::path::Path;

/// The frame the messages are in unless the caller names another.
pub const DEFAULT_FRAME_ID: &str = "map";
/// A patch map's triangles (`visualization_msgs/MarkerArray`).
pub const MAP_TOPIC: &str = "/patchnav/map";
/// A point-cloud map's points (`sensor_msgs/PointCloud2`).
pub const MAP_POINTS_TOPIC: &str = "/patchnav/map_points";
/// A roadmap's edges (`visualization_msgs/MarkerArray`).
pub const ROADMAP_TOPIC: &str = "/patchnav/roadmap";
/// Paths (`visualization_msgs/MarkerArray`).
pub const PATH_TOPIC: &str = "/patchnav/path";
/// An input cloud (`sensor_msgs/PointCloud2`).
pub const CLOUD_TOPIC: &str = "/patchnav/cloud";

/// The colour of planar patches: light blue.
pub const PLANAR_COLOUR: ColorRgba = ColorRgba::new(0.40, 0.65, 0.90, 1.0);
/// The colour of triangle-mesh patches: orange.
pub const TRIMESH_COLOUR: ColorRgba = ColorRgba::new(0.95, 0.60, 0.20, 1.0);
/// The colour of the roadmap: grey, a little transparent.
pub const ROADMAP_COLOUR: ColorRgba = ColorRgba::new(0.55, 0.55, 0.55, 0.8);
/// The colour of paths: green.
pub const PATH_COLOUR: ColorRgba = ColorRgba::new(0.10, 0.80, 0.25, 1.0);
/// The roadmap's line width, metres.
pub const ROADMAP_LINE_WIDTH: f64 = 0.02;
/// A path's line width, metres.
pub const PATH_LINE_WIDTH: f64 = 0.06;

/// The colour of a patch kind's marker.
pub fn kind_colour(kind: PatchKind) -> ColorRgba {
    match kind {
        PatchKind::Planar => PLANAR_COLOUR,
        PatchKind::Trimesh => TRIMESH_COLOUR,
    }
}

/// The patch kinds in marker order (the marker's id is the index).
const KINDS: [PatchKind; 2] = [PatchKind::Planar, PatchKind::Trimesh];

/// A patch map as markers: per [`PatchKind`] with triangles, one `TRIANGLE_LIST` marker
/// (namespace the kind's name, id its index in planar, trimesh; colour [`kind_colour`];
/// identity pose, scale 1), three points per triangle, in `header`'s frame.
///
/// # Errors
/// A planar patch whose polygon cannot be triangulated (named by its index).
pub fn patch_markers(patches: &[Patch], header: &Header) -> Result<MarkerArray> {
    let mut points: [Vec<Point3>; 2] = Default::default();
    for (i, patch) in patches.iter().enumerate() {
        let triangles = patch_triangles(patch)
            .with_context(|| format!("triangulating patch {i} ({})", patch.kind()))?;
        let k = KINDS.iter().position(|&k| k == patch.kind()).unwrap_or(0);
        points[k].extend(triangles.into_iter().flatten());
    }
    let markers = KINDS
        .iter()
        .zip(points)
        .enumerate()
        .filter(|(_, (_, points))| !points.is_empty())
        .map(|(id, (&kind, points))| {
            let mut m = Marker::new(header.clone(), kind.to_string(), id as i32);
            m.kind = TRIANGLE_LIST;
            m.color = kind_colour(kind);
            m.points = points;
            m
        })
        .collect();
    Ok(MarkerArray { markers })
}

/// A roadmap as one `LINE_LIST` marker (namespace `roadmap`, id 0, [`ROADMAP_COLOUR`],
/// [`ROADMAP_LINE_WIDTH`]), two points per edge; no marker for a roadmap without edges.
pub fn roadmap_markers(graph: &roadmap::Roadmap, header: &Header) -> MarkerArray {
    let points: Vec<Point3> = graph
        .edge_indices()
        .filter_map(|e| graph.edge_endpoints(e))
        .flat_map(|(a, b)| [graph[a], graph[b]])
        .collect();
    let markers = (!points.is_empty())
        .then(|| line_marker(header, "roadmap", 0, LINE_LIST, points))
        .map(|mut m| {
            m.color = ROADMAP_COLOUR;
            m.scale.x = ROADMAP_LINE_WIDTH;
            m
        });
    MarkerArray { markers: markers.into_iter().collect() }
}

/// Paths as `LINE_STRIP` markers (namespace `path`, id = the path's index, [`PATH_COLOUR`],
/// [`PATH_LINE_WIDTH`]); paths of fewer than two points (a goal not reached) get none.
pub fn path_markers(paths: &[Vec<Point3>], header: &Header) -> MarkerArray {
    let markers = paths
        .iter()
        .enumerate()
        .filter(|(_, p)| p.len() >= 2)
        .map(|(i, p)| {
            let mut m = line_marker(header, "path", i as i32, LINE_STRIP, p.clone());
            m.color = PATH_COLOUR;
            m.scale.x = PATH_LINE_WIDTH;
            m
        })
        .collect();
    MarkerArray { markers }
}

fn line_marker(header: &Header, ns: &str, id: i32, kind: i32, points: Vec<Point3>) -> Marker {
    let mut m = Marker::new(header.clone(), ns, id);
    m.kind = kind;
    m.points = points;
    m.scale.y = 0.0;
    m.scale.z = 0.0;
    m
}

/// A cloud as a `PointCloud2` (float32 x, y, z first, then its attributes; organised clouds
/// keep their image, [`pointcloud2::encode`]).
///
/// # Errors
/// A cloud too large for the message's `u32` sizes.
pub fn cloud_message(cloud: &PointCloud) -> Result<PointCloud2> {
    pointcloud2::encode(cloud, &Pc2Layout::default()).context("encoding a PointCloud2")
}

/// What goes into a viewer file; every part is optional.
#[derive(Clone, Copy, Debug, Default)]
pub struct ViewerContent<'a> {
    /// A map: a patch map's triangles on [`MAP_TOPIC`], a point-cloud map's points on
    /// [`MAP_POINTS_TOPIC`].
    pub map: Option<&'a AnyMap>,
    /// A planner's roadmap, on [`ROADMAP_TOPIC`].
    pub roadmap: Option<&'a roadmap::Roadmap>,
    /// Paths, on [`PATH_TOPIC`] when given (`Some`, even empty).
    pub paths: Option<&'a [Vec<Point3>]>,
    /// A cloud in the map's frame, on [`CLOUD_TOPIC`].
    pub cloud: Option<&'a PointCloud>,
}

/// One topic of a viewer file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TopicSummary {
    /// The topic.
    pub topic: &'static str,
    /// Its message type (`visualization_msgs/MarkerArray`, `sensor_msgs/PointCloud2`).
    pub type_name: &'static str,
    /// Messages written.
    pub messages: usize,
    /// Markers in them (0 for clouds).
    pub markers: usize,
    /// What the markers or clouds hold: triangles, segments or points.
    pub elements: usize,
    /// The elements' name (`triangles`, `segments`, `points`).
    pub unit: &'static str,
}

impl fmt::Display for TopicSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let ty = self.type_name.rsplit('/').next().unwrap_or(self.type_name);
        write!(f, "{} {} {ty}", self.topic, self.messages)?;
        if self.type_name == MARKER_ARRAY {
            write!(f, " ({} markers, {} {})", self.markers, self.elements, self.unit)
        } else {
            write!(f, " ({} {})", self.elements, self.unit)
        }
    }
}

/// What a viewer file holds, per topic in writing order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ViewerSummary {
    /// The topics.
    pub topics: Vec<TopicSummary>,
}

impl ViewerSummary {
    /// The topic's summary, if it was written.
    pub fn topic(&self, topic: &str) -> Option<&TopicSummary> {
        self.topics.iter().find(|t| t.topic == topic)
    }
}

impl fmt::Display for ViewerSummary {
    /// One line: `TOPIC N TYPE (...)` per topic, separated by `; `.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, t) in self.topics.iter().enumerate() {
            if i > 0 {
                f.write_str("; ")?;
            }
            write!(f, "{t}")?;
        }
        Ok(())
    }
}

/// The MCAP file's bytes (ROS 2 profile, `ros2msg` schemas, CDR messages) and what it holds.
///
/// # Errors
/// A patch that cannot be triangulated, a cloud too large for a `PointCloud2`, a map of a
/// backend with neither patches nor points, or the MCAP writer's error.
pub fn viewer_mcap(
    content: &ViewerContent<'_>,
    header: &Header,
) -> Result<(Vec<u8>, ViewerSummary)> {
    let mut bag = BagWriter::new(BagFormat::Mcap)?;
    let mut summary = ViewerSummary::default();
    let log_time = header.stamp_ns.max(0) as u64;
    let mut markers = |bag: &mut BagWriter, topic, array: MarkerArray, unit| {
        let id = bag.add_topic(topic, MARKER_ARRAY)?;
        bag.write_markers(id, log_time, &array)?;
        let per_marker = |m: &Marker| match m.kind {
            TRIANGLE_LIST => m.points.len() / 3,
            LINE_LIST => m.points.len() / 2,
            _ => m.points.len().saturating_sub(1),
        };
        summary.topics.push(TopicSummary {
            topic,
            type_name: MARKER_ARRAY,
            messages: 1,
            markers: array.markers.len(),
            elements: array.markers.iter().map(per_marker).sum(),
            unit,
        });
        anyhow::Ok(())
    };
    let mut clouds = Vec::new();
    if let Some(map) = content.map {
        match (map.patches(), map) {
            (Some(patches), _) => {
                markers(&mut bag, MAP_TOPIC, patch_markers(patches, header)?, "triangles")?;
            }
            (None, AnyMap::PointCloud(m)) => {
                let cloud = PointCloud::from_positions(m.points().collect())
                    .context("the point-cloud map's points")?;
                clouds.push((MAP_POINTS_TOPIC, cloud));
            }
            (None, other) => bail!("a `{}` map has neither patches nor points", other.backend()),
        }
    }
    if let Some(graph) = content.roadmap {
        markers(&mut bag, ROADMAP_TOPIC, roadmap_markers(graph, header), "segments")?;
    }
    if let Some(paths) = content.paths {
        markers(&mut bag, PATH_TOPIC, path_markers(paths, header), "segments")?;
    }
    let mut write_cloud = |topic, cloud: &PointCloud| -> Result<()> {
        let id = bag.add_topic(topic, POINT_CLOUD2)?;
        bag.write_cloud(id, header, &cloud_message(cloud)?)?;
        summary.topics.push(TopicSummary {
            topic,
            type_name: POINT_CLOUD2,
            messages: 1,
            markers: 0,
            elements: cloud.len(),
            unit: "points",
        });
        Ok(())
    };
    for (topic, cloud) in &clouds {
        write_cloud(topic, cloud)?;
    }
    if let Some(cloud) = content.cloud {
        write_cloud(CLOUD_TOPIC, cloud)?;
    }
    Ok((bag.finish()?, summary))
}

/// Writes [`viewer_mcap`]'s file to `path` (atomically, through
/// [`pointcloud::io::write_bytes_atomically`]).
///
/// # Errors
/// As [`viewer_mcap`], or the file could not be written.
pub fn write_viewer_mcap(
    path: &Path,
    content: &ViewerContent<'_>,
    header: &Header,
) -> Result<ViewerSummary> {
    let (bytes, summary) = viewer_mcap(content, header)?;
    // The writer's error names the file.
    pointcloud::io::write_bytes_atomically(path, bytes)?;
    Ok(summary)
}

/// The header of a viewer file's messages: `frame_id` (or [`DEFAULT_FRAME_ID`]) at time 0.
pub fn viewer_header(frame_id: Option<&str>) -> Header {
    Header { stamp_ns: 0, frame_id: frame_id.unwrap_or(DEFAULT_FRAME_ID).to_owned() }
}
