//! Roadmap planners on patch maps: the RRT and the PRM of the thesis (Poppinga 2010,
//! "Towards Autonomous Navigation for Robots with 3D Sensors", §5.5 and §6.1, Algorithms 13
//! and 14), generic over the collision capabilities of `patch-core` and never over a backend.
//!
//! # Design (OMPL's separation)
//! * [`PlanningSpace`]: the sampling box, the robot's sphere radius, the RRT step (validated;
//!   OMPL's `SpaceInformation` without the map).
//! * [`Problem`]: a start and any number of [`Goal`] balls (`ProblemDefinition`).
//! * [`Termination`]: asked before every iteration — [`MaxIterations`], [`Deadline`],
//!   [`GoalReached`], [`AnyOf`] (`PlannerTerminationCondition`).
//! * [`Planner`]: the object-safe face, `solve` → [`PlannerStatus`] (an outcome, not an
//!   error), the [`Roadmap`] (a petgraph graph, edge weight = length), paths and
//!   [`PlannerCounters`] (samples, vertices, edges, collision checks and their time).
//! * [`Rrt`] and [`Prm`] are generic over `M: UnspecificStepIntersector<CapsuleStep>`, the one
//!   capability they need (thesis Table 5.2); configs ([`RrtConfig`], [`PrmConfig`]) have no
//!   `Default` but named constructors with the thesis's choices.
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
//!   the goal centre (§7.17), optional ([`RrtConfig::direct_goal_step`],
//!   [`PrmConfig::direct_goal_step`]).
//! * Goal-directed sampling: `σ = sqrt(d_far[mm]·factor)` mm per axis, redrawn outside the
//!   box (§7.9; [`Sampler::GoalGaussian`]).
//! * PRM components by union–find; no vertex validity check, no edge-length limit by default
//!   (spec §4); `N` is a parameter, 6 in [`PrmConfig::thesis`] (§7.4).
//! * The sampling box is the caller's (§7.10, §7.18: the thesis uses the box of all patches).
//!
//! # Not yet here
//! Evasion RRT (Algorithm 11), the medial-axis planners (MA RRT, MA PRM, Algorithm 12),
//! RRT-Connect, RRT*, PRM*, lazy PRM, path smoothing, path and roadmap metrics, the explored
//! volume, the thesis's experiments, benchmarks, and a choice of nearest-neighbour structure
//! per planner (both use [`KdNeighbors`]; the thesis used an octree for RRT and a CGAL
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

mod evasion;
pub mod metrics;
mod nn;
mod planner;
mod prm;
mod rrt;
mod space;
mod termination;

pub use evasion::{EvasionRrt, EvasionRrtConfig};
pub use metrics::PathMetrics;
pub use nn::{KdNeighbors, LinearNeighbors, NearestNeighbors, Neighbor};
pub use planner::{Planner, PlannerCounters, PlannerStatus, Roadmap};
pub use prm::{Prm, PrmConfig};
pub use rrt::{Rrt, RrtConfig, Sampler};
pub use space::{Goal, PlanningSpace, Problem, SpaceError};
pub use termination::{AnyOf, Deadline, GoalReached, MaxIterations, Progress, Termination};
