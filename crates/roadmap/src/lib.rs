//! Roadmap planners on patch maps: the RRT, the PRM, the Evasion RRT and the medial-axis
//! planners of the thesis (Poppinga 2010, "Towards Autonomous Navigation for Robots with 3D
//! Sensors", §5.5 and §6.1, Algorithms 13, 14, 11 and 12), RRT-Connect as a baseline from the
//! literature, PRM* (Karaman & Frazzoli 2011) as an option of the PRM, RRT* (Karaman &
//! Frazzoli 2011) and the lazy PRM (Bohlin & Kavraki 2000), the path metrics of the thesis's
//! benchmark ([`metrics`]) and path shortcutting as a post-process ([`smoothing`]);
//! generic over the collision capabilities of `patch-core` and never over a backend.
//!
//! # Planners and the capabilities they need (thesis Table 5.2)
//!
//! | planner | capability of the map | here |
//! |---|---|---|
//! | RRT (Alg. 13) | [`UnspecificStepIntersector`] | [`Rrt`] |
//! | PRM (Alg. 14) | [`UnspecificStepIntersector`] | [`Prm`] |
//! | PRM* (not in the thesis) | [`UnspecificStepIntersector`] | [`Prm`] with [`PrmConfig::star()`] |
//! | lazy PRM (not in the thesis) | [`UnspecificStepIntersector`] | [`LazyPrm`] (any [`PrmConfig`]) |
//! | RRT* (not in the thesis) | [`UnspecificStepIntersector`] | [`RrtStar`] |
//! | Evasion RRT (Alg. 11) | [`SpecificStepIntersector`] | [`EvasionRrt`] |
//! | MA PRM (Alg. 12) | [`ProximityQuery`] + [`UnspecificStepIntersector`] | [`MaPrm`] |
//! | MA RRT (§5.5.2, no pseudo-code) | [`ProximityQuery`] + [`UnspecificStepIntersector`] | [`MaRrt`] |
//! | RRT-Connect (not in the thesis) | [`UnspecificStepIntersector`] | [`RrtConnect`] |
//! | path shortcutting (post-process, not in the thesis) | [`UnspecificStepIntersector`] | [`shortcut_path`] |
//!
//! A planner states its capability as a trait bound, so a map without it is rejected at
//! compile time: the point-cloud map (`PointCloudMap` of `patch-map`), which answers no
//! closest-patch queries, runs the RRT, PRM, RRT*, lazy PRM and RRT-Connect (and path
//! shortcutting) but not the medial-axis planners (thesis Table 5.2).
//!
//! [`UnspecificStepIntersector`]: patch_core::UnspecificStepIntersector
//! [`SpecificStepIntersector`]: patch_core::SpecificStepIntersector
//! [`ProximityQuery`]: patch_core::ProximityQuery
//!
//! # Design (OMPL's separation)
//! * [`PlanningSpace`]: the sampling box, the robot's sphere radius, the RRT step (validated;
//!   OMPL's `SpaceInformation` without the map).
//! * [`Problem`]: a start and any number of [`Goal`] balls (`ProblemDefinition`).
//! * [`Termination`]: asked before every iteration — [`MaxIterations`], [`Deadline`],
//!   [`GoalReached`], [`AnyOf`] (`PlannerTerminationCondition`).
//! * [`Planner`]: the object-safe face, `solve` → [`PlannerStatus`] (an outcome, not an
//!   error), the [`Roadmap`] (a petgraph graph, edge weight = length), paths and
//!   [`PlannerCounters`] (samples, vertices, edges, collision checks, closest-patch queries and
//!   their times).
//! * Each planner is generic over the capabilities it needs (table above); configs
//!   ([`RrtConfig`], [`PrmConfig`], [`RrtStarConfig`], [`EvasionRrtConfig`], [`MaPrmConfig`],
//!   [`MaRrtConfig`], and [`ShortcutConfig`] for the post-process) have no `Default` but named constructors
//!   with the thesis's choices, or documented ones where the thesis gives none.
//!
//! Runs are deterministic: a planner takes a seed (ChaCha8), every `solve` starts from it,
//! and nearest-neighbour queries ([`KdNeighbors`], checked against the linear scan
//! [`LinearNeighbors`]) are deterministic, so the same seed on the same map gives the same
//! roadmap.
//!
//! # Where the thesis is repaired or completed (spec §4, §7)
//! * RRT step: `x_new = x_near + min(max_step, |x − x_near|)·unit` (§7.8; the thesis says both
//!   "fixed distance" and "maximum length").
//! * Direct goal test of the Lesum variants: one capsule of any length from the new vertex to
//!   the goal centre (§7.17), optional ([`GoalStep::Direct`] in
//!   [`RrtConfig::goal_step`] and [`PrmConfig::goal_step`]).
//! * Goal-directed sampling: `σ = sqrt(d_far[mm]·factor)` mm per axis, redrawn outside the
//!   box (§7.9; [`Sampler::GoalGaussian`]).
//! * PRM components by union–find; no vertex validity check, no edge-length limit by default
//!   (spec §4); `N` is a parameter, 6 in [`PrmConfig::thesis`] (§7.4).
//! * The sampling box is the caller's (§7.10, §7.18: the thesis uses the box of all patches).
//! * Evasion RRT: the printed Algorithm 11 is broken (§7.14); [`EvasionRrt`] implements the
//!   spec's repair (shift `x_new` by `l_ev · unit(u × n_p)` while the hit patch stays the same
//!   planar patch, at most `E` times, add only if free). The thesis gives neither `l_ev` nor
//!   `E`; [`EvasionRrtConfig::for_space`] documents this crate's values.
//! * Medial axis (§5.5.2): [`retract_to_medial_axis`] moves a sample away from its closest
//!   patch along the ray from the closest point through the sample, brackets (doubling, inside
//!   the box) and bisects the change of the closest patch, and drops the sample if there is
//!   none inside the box or the sample lies on a patch (the spec's recommendation, §4). The
//!   thesis gives neither the solver, its tolerance nor `N`; [`MaPrmConfig::for_space`] and
//!   [`MaRrtConfig::for_space`] document this crate's values. The MA RRT has no pseudo-code
//!   in the thesis; [`MaRrt`] retracts each sample, then takes one RRT step toward it (the
//!   spec's recommendation, §4). Their closest-patch queries are counted in
//!   [`PlannerCounters::proximity_queries`] (and timed in [`PlannerCounters::proximity_time`]),
//!   apart from the collision checks.
//! * Path metrics (§5.5.4, Tables 5.5–5.11): the thesis does not define its quartile; see
//!   [`metrics`] for the method used and the treatment of straight and repeated vertices.
//! * PRM* (Karaman & Frazzoli 2011, k-nearest variant; [`PrmConnections::Star`]): the PRM loop
//!   with `k(n) = ⌈e·(1 + 1/3)·ln n⌉` neighbours for the `n`-th vertex
//!   ([`PrmConfig::neighbours_for`]) and without the component test, so its roadmap has
//!   cycles; paths of every planner are shortest by length in the roadmap (Dijkstra), which
//!   in the forests of the other planners is the unique path.
//! * RRT* (Karaman & Frazzoli 2011, Algorithm 6, k-nearest variant; [`RrtStar`]): the RRT's
//!   sampling and step, then choose-parent and rewiring among the `k(n) = ⌈2e·ln n⌉` nearest
//!   vertices ([`RrtStarConfig::standard`], [`RrtStarConfig::neighbours_for`]; optionally
//!   within [`RrtStarConfig::rewire_radius`]); a capsule is checked only if it would lower a
//!   cost, and once per pair. Rewiring removes the old parent edge, so the roadmap stays a
//!   tree, and recomputes the subtree's costs. A goal's path is the tree path to its cheapest
//!   vertex within tolerance; it never grows during a run.
//! * Lazy PRM (Bohlin & Kavraki 2000; [`LazyPrm`]): edges to the `N` (or PRM*'s `k(n)`)
//!   nearest vertices without a check and without the component test; after each iteration a
//!   query per unreached goal searches the shortest path over edges not known to collide,
//!   checks its unknown edges from the start, deletes the first colliding one and repeats. A
//!   goal is reached only through edges checked free; a union–find of the optimistic graph
//!   (rebuilt after deletions) decides when a query is worth running. The roadmap holds only
//!   the edges checked free.
//! * Path shortcutting ([`smoothing`]): the thesis reports unsmoothed paths; [`shortcut_path`]
//!   is a greedy pass plus random shortcuts ([`ShortcutConfig::standard`] documents this
//!   crate's values). It never lengthens a path and adds only segments the map reported free.
//!
//! # Explored volume ([`volume`], thesis §6.1.1)
//! Roadmaps are rasterised into a sparse voxel grid ([`volume::VoxelGrid`], 1024³ cells over
//! the common bounds by default): a voxel counts iff its centre lies within the robot radius of
//! a vertex or an edge, decided exactly ([`volume::capsule_contains_point`]); unions over runs
//! and the thesis's congruence table "explored on A but not on B, in % of A"
//! ([`volume::CongruenceTable`], Tables 6.2–6.5). The experiments that use it are in the
//! `patchnav experiment` command.
//!
//! # Not yet here
//! Path smoothing other than shortcutting (e.g. splines), a choice of nearest-neighbour
//! structure per planner (all use [`KdNeighbors`]; the thesis used an octree for RRT and a CGAL
//! k-d tree for PRM, §6.1).
//!
//! # Example
//! ```
//! use patch_core::{Aabb, BruteForceMap, Point3};
//! use roadmap::{
//!     AnyOf, Goal, GoalReached, MaxIterations, Planner, PlannerStatus, PlanningSpace,
//!     Problem, Rrt, RrtConfig,
//! };
//!
//! let map = BruteForceMap::new(); // no obstacles
//! let bounds = Aabb::new(Point3::origin(), Point3::new(4.0, 4.0, 2.0));
//! let space = PlanningSpace::new(bounds, 0.2, 0.5)?;
//! let problem = Problem {
//!     start: Point3::new(0.5, 0.5, 1.0),
//!     goals: vec![Goal { center: Point3::new(3.5, 3.5, 1.0), tolerance: 0.3 }],
//! };
//! let mut rrt = Rrt::new(&map, space, RrtConfig::thesis(), 7);
//! let status = rrt.solve(&problem, &mut AnyOf(GoalReached, MaxIterations(5_000)));
//! assert_eq!(status, PlannerStatus::Exact);
//! let path = rrt.path_to(0).unwrap();
//! assert_eq!(path[0], problem.start);
//! assert!((path.last().unwrap() - problem.goals[0].center).norm() <= 0.3);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! The points, boxes and map trait of these signatures ([`Point3`], [`Aabb`], [`Real`],
//! [`PatchMap`]) are `patch-core`'s, re-exported here. `examples/plan_on_mesh.rs` plans on an
//! OBJ mesh in a `patch-map` backend (`cargo run -p patchnav-roadmap --example plan_on_mesh`).
//!
//! # Features
//! `problem-file` (off by default) adds `ProblemFile`, the planning problem file of the shared
//! exchange format (JSON). Without it the crate reads and writes no file, and compiles no
//! file-format crate.

mod connect;
mod evasion;
mod medial;
pub mod metrics;
mod named;
mod nn;
mod planner;
mod prm;
#[cfg(feature = "problem-file")]
mod problem_file;
mod rrt;
mod rrt_star;
pub mod smoothing;
mod space;
mod termination;
pub mod volume;

pub use connect::RrtConnect;
pub use evasion::{EvasionRrt, EvasionRrtConfig};
pub use medial::{MaPrm, MaPrmConfig, MaRrt, MaRrtConfig, retract_to_medial_axis};
pub use metrics::PathMetrics;
pub use named::{
    MapCapability, NamedPlannerError, PlannerKind, named_patch_planner, named_planner,
    named_planner_on,
};
pub use nn::{KdNeighbors, LinearNeighbors, NearestNeighbors, Neighbor};
pub use planner::{GoalStep, Planner, PlannerCounters, PlannerStatus, Roadmap};
pub use prm::{LazyPrm, Prm, PrmConfig, PrmConnections, PrmEdges, PrmSamples};
#[cfg(feature = "problem-file")]
pub use problem_file::{MAX_ITERATIONS, ProblemFile, ProblemFileError};
pub use rrt::{Rrt, RrtConfig, Sampler};
pub use rrt_star::{RrtStar, RrtStarConfig};
pub use smoothing::{ShortcutConfig, shortcut_path};
pub use space::{Goal, PlanningSpace, Problem, SpaceError};
pub use termination::{AnyOf, Deadline, GoalReached, MaxIterations, Progress, Termination};

// The `patch-core` vocabulary of this crate's signatures (points and boxes of the space and the
// problem; the map trait whose `bounds` is the usual sampling box), so a program that plans on a
// map built elsewhere needs no direct `patch-core` dependency for them.
pub use patch_core::{Aabb, PatchMap, Point3, Real};
