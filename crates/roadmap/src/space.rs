//! The planning space and the problem: OMPL's `SpaceInformation` (minus the map) and
//! `ProblemDefinition`.

use patch_core::{Aabb, Point3, Real};

/// Why a [`PlanningSpace`] could not be built.
#[derive(Copy, Clone, Debug, PartialEq, thiserror::Error)]
pub enum SpaceError {
    /// The bounds are empty or have a non-finite coordinate.
    #[error("the planning bounds are empty or not finite")]
    InvalidBounds,
    /// The robot radius is not a finite positive number.
    #[error("robot radius {radius} is not a finite positive number")]
    InvalidRadius {
        /// The value given.
        radius: Real,
    },
    /// The maximum step is not a finite positive number.
    #[error("maximum step {max_step} is not a finite positive number")]
    InvalidMaxStep {
        /// The value given.
        max_step: Real,
    },
}

/// Where the robot may be and how it moves: the sampling box, the radius of the sphere that
/// stands for the robot, and the longest edge an RRT adds in one extension.
///
/// The thesis samples in the axis-aligned box of all patches (thesis §6.1; spec §7.10 and
/// §7.18); the caller chooses the box, for example the map's [`bounds`] grown a little.
///
/// [`bounds`]: patch_core::PatchMap::bounds
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PlanningSpace {
    bounds: Aabb,
    robot_radius: Real,
    max_step: Real,
}

impl PlanningSpace {
    /// A validated space.
    ///
    /// # Errors
    /// [`SpaceError::InvalidBounds`] for an empty box or a non-finite corner (a box flat along
    /// some axis is allowed); [`SpaceError::InvalidRadius`] / [`SpaceError::InvalidMaxStep`]
    /// unless the value is finite and positive.
    pub fn new(
        bounds: Aabb,
        robot_radius: Real,
        max_step: Real,
    ) -> Result<PlanningSpace, SpaceError> {
        let finite = bounds.min.iter().chain(bounds.max.iter()).all(|c| c.is_finite());
        if !finite || bounds.is_empty() {
            return Err(SpaceError::InvalidBounds);
        }
        if !(robot_radius.is_finite() && robot_radius > 0.0) {
            return Err(SpaceError::InvalidRadius { radius: robot_radius });
        }
        if !(max_step.is_finite() && max_step > 0.0) {
            return Err(SpaceError::InvalidMaxStep { max_step });
        }
        Ok(PlanningSpace { bounds, robot_radius, max_step })
    }

    /// The sampling box; vertices never leave it.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The radius of the robot's sphere (every edge is checked as a capsule of this radius).
    pub fn robot_radius(&self) -> Real {
        self.robot_radius
    }

    /// The longest edge one RRT extension adds (the thesis's step length).
    pub fn max_step(&self) -> Real {
        self.max_step
    }
}

/// A goal region: a ball around `center`.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Goal {
    /// The goal position.
    pub center: Point3,
    /// A vertex within this distance of `center` reaches the goal (0: only the centre itself,
    /// which only a direct goal step adds).
    pub tolerance: Real,
}

/// A planning query: one start and any number of goals (OMPL's `ProblemDefinition`).
#[derive(Clone, Debug, PartialEq)]
pub struct Problem {
    /// Where the robot is.
    pub start: Point3,
    /// Where it should get; [`PlannerStatus::Exact`](crate::PlannerStatus::Exact) means all of them are connected to the start.
    pub goals: Vec<Goal>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation() {
        let b = Aabb::new(Point3::origin(), Point3::new(1.0, 1.0, 0.0));
        assert!(PlanningSpace::new(b, 0.1, 0.5).is_ok());
        assert_eq!(PlanningSpace::new(Aabb::EMPTY, 0.1, 0.5), Err(SpaceError::InvalidBounds));
        let inf = Aabb::new(Point3::origin(), Point3::new(Real::INFINITY, 1.0, 1.0));
        assert_eq!(PlanningSpace::new(inf, 0.1, 0.5), Err(SpaceError::InvalidBounds));
        assert!(matches!(PlanningSpace::new(b, 0.0, 0.5), Err(SpaceError::InvalidRadius { .. })));
        assert!(matches!(
            PlanningSpace::new(b, Real::NAN, 0.5),
            Err(SpaceError::InvalidRadius { .. })
        ));
        assert!(matches!(PlanningSpace::new(b, 0.1, -1.0), Err(SpaceError::InvalidMaxStep { .. })));
        assert!(matches!(
            PlanningSpace::new(b, 0.1, Real::INFINITY),
            Err(SpaceError::InvalidMaxStep { .. })
        ));
        let s = PlanningSpace::new(b, 0.1, 0.5).unwrap();
        assert_eq!((s.bounds(), s.robot_radius(), s.max_step()), (b, 0.1, 0.5));
    }
}
