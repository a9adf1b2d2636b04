//! Plans on a triangle mesh: the faces of an OBJ file become planar patches of a 6D bounding-box
//! map (`patch-map`), and a seeded RRT looks for a path of a 0.3 m sphere from start to goal.
//! Run `cargo run -p patchnav-roadmap --example plan_on_mesh` (the room of `examples/data/room.obj`), or
//! pass a mesh (metres, z up), start and goal: `-- floorplan.obj 10,7.5,1.25 1.5,1.5,1.25`.
use patch_map::{BBox6dMap, map_from_obj};
use roadmap::{AnyOf, Goal, GoalReached, MaxIterations, PatchMap, Planner, PlanningSpace, Point3};
use roadmap::{Problem, Rrt, RrtConfig, metrics::path_length};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let room = [concat!(env!("CARGO_MANIFEST_DIR"), "/examples/data/room.obj"), "1,1,1", "7,5,1"];
    let arg = |i: usize| std::env::args().nth(i + 1).unwrap_or_else(|| room[i].into());
    let point = |i| -> Result<Point3, Box<dyn std::error::Error>> {
        let v: Vec<f64> = arg(i).split(',').map(str::parse).collect::<Result<_, _>>()?;
        (v.len() == 3).then(|| Point3::from_slice(&v)).ok_or_else(|| "a point is x,y,z".into())
    };
    let map: BBox6dMap = map_from_obj(arg(0))?;
    let space = PlanningSpace::new(map.bounds(), 0.3, 0.5)?;
    let goals = vec![Goal { center: point(2)?, tolerance: 0.3 }];
    let mut rrt = Rrt::new(&map, space, RrtConfig::thesis(), 7);
    let stop = &mut AnyOf(GoalReached, MaxIterations(20_000));
    let status = rrt.solve(&Problem { start: point(1)?, goals }, stop);
    let found = rrt.path_to(0).map(|path| format!("a path of {:.2} m", path_length(&path)));
    println!("{} patches, {status:?}: {}", map.len(), found.as_deref().unwrap_or("no path"));
    Ok(())
}
