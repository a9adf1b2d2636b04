//! The viewer file (`patch_pipeline::viewer`) read back with the `mcap` crate: schemas,
//! topics, message counts, and the markers' triangles against the map's.

use patch_core::{Isometry3, Patch, PlanarPatch, Point3, TrimeshPatch, na};
use patch_map::{AnyMap, Backend};
use patch_pipeline::viewer::{
    CLOUD_TOPIC, MAP_POINTS_TOPIC, MAP_TOPIC, PATH_COLOUR, PATH_TOPIC, PLANAR_COLOUR,
    ROADMAP_TOPIC, TRIMESH_COLOUR, ViewerContent, viewer_header, viewer_mcap, write_viewer_mcap,
};
use pointcloud::PointCloud;
use ros_bag::msgs::PointCloud2Msg;
use ros_bag::msgs::markers::{LINE_LIST, LINE_STRIP, MarkerArray, TRIANGLE_LIST};
use ros_bag::wire::Encoding;
use std::collections::BTreeMap;

/// A floor with a square hole (8 vertices, one hole: 8 triangles), a wall (2 triangles) and a
/// small mesh (3 triangles).
fn patches() -> Vec<Patch> {
    let square = |c: f64, h: f64| {
        vec![
            Point3::new(c - h, c - h, 0.0),
            Point3::new(c + h, c - h, 0.0),
            Point3::new(c + h, c + h, 0.0),
            Point3::new(c - h, c + h, 0.0),
        ]
    };
    let floor = PlanarPatch::from_world_polygon(&square(5.0, 5.0), &[square(5.0, 1.0)], 1e-9);
    let wall = PlanarPatch::rectangle(
        Isometry3::new(
            na::Vector3::new(0.0, 10.0, 0.0),
            na::Vector3::x() * std::f64::consts::FRAC_PI_2,
        ),
        na::Point2::new(0.0, 0.0),
        na::Point2::new(10.0, 2.0),
    );
    let mesh = TrimeshPatch::new(
        vec![
            Point3::new(2.0, 2.0, 0.5),
            Point3::new(3.0, 2.0, 0.5),
            Point3::new(2.5, 3.0, 0.5),
            Point3::new(2.5, 2.5, 1.5),
        ],
        vec![[0, 1, 3], [1, 2, 3], [2, 0, 3]],
    );
    vec![floor.unwrap().into(), wall.unwrap().into(), mesh.unwrap().into()]
}

/// Per topic: (schema name, schema encoding, message encoding, the messages' bytes).
type Topics = BTreeMap<String, (String, String, String, Vec<Vec<u8>>)>;

fn read_topics(bytes: &[u8]) -> Topics {
    let mut topics = Topics::new();
    for message in mcap::MessageStream::new(bytes).unwrap() {
        let message = message.unwrap();
        let c = &message.channel;
        let schema = c.schema.as_ref().expect("every channel has a schema");
        assert!(!schema.data.is_empty(), "{}: empty schema", c.topic);
        let entry = topics.entry(c.topic.clone()).or_insert_with(|| {
            (schema.name.clone(), schema.encoding.clone(), c.message_encoding.clone(), Vec::new())
        });
        entry.3.push(message.data.into_owned());
    }
    topics
}

#[test]
fn a_plan_file_holds_the_map_roadmap_paths_and_cloud() {
    let map = AnyMap::from_patches(Backend::Trimesh, patches(), None).unwrap();
    let map_triangles = map.counts().triangles as usize;
    assert_eq!(map_triangles, 8 + 2 + 3);
    let mut graph = roadmap::Roadmap::new_undirected();
    let a = graph.add_node(Point3::new(1.0, 1.0, 0.5));
    let b = graph.add_node(Point3::new(2.0, 1.0, 0.5));
    let c = graph.add_node(Point3::new(2.0, 4.0, 0.5));
    graph.add_edge(a, b, 1.0);
    graph.add_edge(b, c, 3.0);
    let paths = vec![vec![graph[a], graph[b], graph[c]], vec![]];
    let cloud = PointCloud::from_positions(vec![Point3::new(1.0, 2.0, 3.0); 5]).unwrap();
    let content = ViewerContent {
        map: Some(&map),
        roadmap: Some(&graph),
        paths: Some(&paths),
        cloud: Some(&cloud),
    };
    let header = viewer_header(Some("world"));
    let (bytes, summary) = viewer_mcap(&content, &header).unwrap();
    assert_eq!(
        summary.to_string(),
        "/patchnav/map 1 MarkerArray (2 markers, 13 triangles); \
         /patchnav/roadmap 1 MarkerArray (1 markers, 2 segments); \
         /patchnav/path 1 MarkerArray (1 markers, 2 segments); \
         /patchnav/cloud 1 PointCloud2 (5 points)"
    );

    let topics = read_topics(&bytes);
    let names: Vec<&str> = topics.keys().map(String::as_str).collect();
    assert_eq!(names, [CLOUD_TOPIC, MAP_TOPIC, PATH_TOPIC, ROADMAP_TOPIC]);
    for (topic, (schema, schema_encoding, encoding, messages)) in &topics {
        let expected = if topic == CLOUD_TOPIC {
            "sensor_msgs/msg/PointCloud2"
        } else {
            "visualization_msgs/msg/MarkerArray"
        };
        assert_eq!(schema, expected, "{topic}");
        assert_eq!((schema_encoding.as_str(), encoding.as_str()), ("ros2msg", "cdr"), "{topic}");
        assert_eq!(messages.len(), 1, "{topic}");
    }

    let markers = |topic: &str| MarkerArray::decode(&topics[topic].3[0]).unwrap().markers;
    let map_markers = markers(MAP_TOPIC);
    let triangles: usize = map_markers.iter().map(|m| m.points.len() / 3).sum();
    assert_eq!(triangles, map_triangles);
    let kinds: Vec<_> =
        map_markers.iter().map(|m| (m.ns.as_str(), m.id, m.kind, m.color)).collect();
    assert_eq!(
        kinds,
        [
            ("planar", 0, TRIANGLE_LIST, PLANAR_COLOUR),
            ("trimesh", 1, TRIANGLE_LIST, TRIMESH_COLOUR)
        ]
    );
    assert_eq!(map_markers.iter().map(|m| m.points.len()).collect::<Vec<_>>(), [30, 9]);
    for m in &map_markers {
        assert_eq!(m.header, header);
        // The planar triangles lie on the floor or the wall; the mesh keeps its vertices.
        assert!(
            m.points.iter().all(|p| p.z.abs() < 1e-9 || (p.y - 10.0).abs() < 1e-9 || m.id == 1)
        );
    }
    let roadmap = markers(ROADMAP_TOPIC);
    assert_eq!((roadmap.len(), roadmap[0].kind, roadmap[0].points.len()), (1, LINE_LIST, 4));
    let path = markers(PATH_TOPIC);
    assert_eq!(
        (path.len(), path[0].kind, path[0].id, path[0].color),
        (1, LINE_STRIP, 0, PATH_COLOUR)
    );
    assert_eq!(path[0].points, paths[0]);
    let cloud_msg = PointCloud2Msg::decode(&topics[CLOUD_TOPIC].3[0], Encoding::Cdr).unwrap();
    assert_eq!(cloud_msg.header, header);
    let decoded = pointcloud::io::pointcloud2::decode(&cloud_msg.cloud).unwrap();
    assert_eq!(decoded.len(), 5);
    assert!((decoded.positions()[0] - Point3::new(1.0, 2.0, 3.0)).norm() < 1e-6);
}

#[test]
fn every_patch_backend_gives_the_same_triangles_and_a_pc_map_gives_points() {
    let header = viewer_header(None);
    assert_eq!(header.frame_id, "map");
    let hint: usize = patches().iter().map(Patch::num_triangles_hint).sum();
    for backend in [Backend::Polygon, Backend::BBox6d, Backend::Trimesh] {
        let map = AnyMap::from_patches(backend, patches(), None).unwrap();
        let content = ViewerContent { map: Some(&map), ..Default::default() };
        let (bytes, summary) = viewer_mcap(&content, &header).unwrap();
        assert_eq!(summary.topic(MAP_TOPIC).unwrap().elements, hint, "{backend}");
        let topics = read_topics(&bytes);
        assert_eq!(topics.len(), 1, "{backend}");
        let markers = MarkerArray::decode(&topics[MAP_TOPIC].3[0]).unwrap().markers;
        assert_eq!(markers.iter().map(|m| m.points.len()).sum::<usize>(), 3 * hint);
    }
    let pc = AnyMap::from_patches(Backend::PointCloud, patches(), Some(0.5)).unwrap();
    let points = pc.counts().points as usize;
    assert!(points > 100, "{points}");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("pc.mcap");
    let content = ViewerContent { map: Some(&pc), ..Default::default() };
    let summary = write_viewer_mcap(&path, &content, &header).unwrap();
    assert_eq!(
        summary.to_string(),
        format!("/patchnav/map_points 1 PointCloud2 ({points} points)")
    );
    let topics = read_topics(&std::fs::read(&path).unwrap());
    let (schema, _, _, messages) = &topics[MAP_POINTS_TOPIC];
    assert_eq!((schema.as_str(), messages.len()), ("sensor_msgs/msg/PointCloud2", 1));
    let msg = PointCloud2Msg::decode(&messages[0], Encoding::Cdr).unwrap();
    assert_eq!(msg.cloud.width as usize * msg.cloud.height as usize, points);
}

#[test]
fn empty_maps_roadmaps_and_paths_give_empty_marker_arrays() {
    let header = viewer_header(None);
    let map = AnyMap::from_patches(Backend::Polygon, Vec::new(), None).unwrap();
    let graph = roadmap::Roadmap::new_undirected();
    let paths: Vec<Vec<Point3>> = vec![vec![], vec![Point3::origin()]];
    let content =
        ViewerContent { map: Some(&map), roadmap: Some(&graph), paths: Some(&paths), cloud: None };
    let (bytes, summary) = viewer_mcap(&content, &header).unwrap();
    assert!(summary.topics.iter().all(|t| t.messages == 1 && t.markers == 0), "{summary}");
    let topics = read_topics(&bytes);
    assert_eq!(topics.len(), 3);
    for (topic, (_, _, _, messages)) in &topics {
        assert!(MarkerArray::decode(&messages[0]).unwrap().markers.is_empty(), "{topic}");
    }
    // Nothing at all: a valid MCAP without messages.
    let (bytes, summary) = viewer_mcap(&ViewerContent::default(), &header).unwrap();
    assert!(summary.topics.is_empty());
    assert!(read_topics(&bytes).is_empty());
    // An unwritable path is an error naming it, not a panic.
    let e = write_viewer_mcap(std::path::Path::new("/nonexistent/dir/x.mcap"), &content, &header);
    assert!(format!("{:#}", e.unwrap_err()).contains("/nonexistent/dir/x.mcap"));
}
