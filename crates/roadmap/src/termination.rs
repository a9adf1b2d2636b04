//! When a planner stops: OMPL's `PlannerTerminationCondition`.
//!
//! A planner asks its [`Termination`] before every iteration; it never stops on its own, so
//! a run with [`MaxIterations`] keeps growing the roadmap after the goals are reached (the
//! thesis's roadmap runs use a fixed number of iterations, §6.1); combine with
//! [`GoalReached`] through [`AnyOf`] to stop at the first solution.

use std::time::{Duration, Instant};

/// What a planner has done so far, shown to its [`Termination`] before each iteration.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Progress {
    /// Iterations completed (samples drawn).
    pub iterations: u64,
    /// Vertices in the roadmap.
    pub vertices: usize,
    /// Goals connected to the start.
    pub goals_reached: usize,
    /// Goals of the problem.
    pub goals_total: usize,
    /// When `solve` began.
    pub started: Instant,
}

impl Progress {
    /// Time since `solve` began (read from the clock only when asked: most conditions
    /// never ask, and a clock read costs as much as a small map's collision check).
    pub fn elapsed(&self) -> Duration {
        self.started.elapsed()
    }
}

/// Decides whether a planner stops before its next iteration.
pub trait Termination {
    /// `true` to stop now.
    fn should_stop(&mut self, progress: &Progress) -> bool;

    /// The most iterations this condition lets a planner run, if it bounds them (`None`:
    /// unknown). Only a hint for reserving room up front; stopping is still decided by
    /// [`should_stop`](Termination::should_stop).
    fn iteration_budget(&self) -> Option<u64> {
        None
    }
}

impl<T: Termination + ?Sized> Termination for &mut T {
    fn should_stop(&mut self, progress: &Progress) -> bool {
        (**self).should_stop(progress)
    }

    fn iteration_budget(&self) -> Option<u64> {
        (**self).iteration_budget()
    }
}

/// Stops after exactly this many iterations.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct MaxIterations(pub u64);

impl Termination for MaxIterations {
    fn should_stop(&mut self, progress: &Progress) -> bool {
        progress.iterations >= self.0
    }

    fn iteration_budget(&self) -> Option<u64> {
        Some(self.0)
    }
}

/// Stops at the first check at or after this instant (an iteration in progress finishes).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct Deadline(pub Instant);

impl Termination for Deadline {
    fn should_stop(&mut self, _progress: &Progress) -> bool {
        Instant::now() >= self.0
    }
}

/// Stops once every goal is connected to the start (at once for a problem without goals).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct GoalReached;

impl Termination for GoalReached {
    fn should_stop(&mut self, progress: &Progress) -> bool {
        progress.goals_reached >= progress.goals_total
    }
}

/// Stops when either condition says so. Both are asked every time (no short circuit), so
/// stateful conditions see every iteration.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct AnyOf<A, B>(pub A, pub B);

impl<A: Termination, B: Termination> Termination for AnyOf<A, B> {
    fn should_stop(&mut self, progress: &Progress) -> bool {
        self.0.should_stop(progress) | self.1.should_stop(progress)
    }

    /// The smaller budget of the two (either one stops the run).
    fn iteration_budget(&self) -> Option<u64> {
        match (self.0.iteration_budget(), self.1.iteration_budget()) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn progress(iterations: u64, goals_reached: usize) -> Progress {
        Progress { iterations, vertices: 1, goals_reached, goals_total: 2, started: Instant::now() }
    }

    #[test]
    fn conditions() {
        assert!(!MaxIterations(3).should_stop(&progress(2, 0)));
        assert!(MaxIterations(3).should_stop(&progress(3, 0)));
        assert!(MaxIterations(0).should_stop(&progress(0, 0)));
        assert!(!GoalReached.should_stop(&progress(9, 1)));
        assert!(GoalReached.should_stop(&progress(9, 2)));
        assert!(Deadline(Instant::now()).should_stop(&progress(0, 0)));
        let far = Instant::now() + Duration::from_secs(3600);
        assert!(!Deadline(far).should_stop(&progress(0, 0)));
        let mut any = AnyOf(MaxIterations(5), GoalReached);
        assert!(!any.should_stop(&progress(4, 1)));
        assert!(any.should_stop(&progress(5, 1)));
        assert!(any.should_stop(&progress(1, 2)));
        let dynamic: &mut dyn Termination = &mut any;
        assert!(dynamic.should_stop(&progress(7, 0)));
    }

    #[test]
    fn iteration_budgets() {
        assert_eq!(MaxIterations(7).iteration_budget(), Some(7));
        assert_eq!(GoalReached.iteration_budget(), None);
        assert_eq!(Deadline(Instant::now()).iteration_budget(), None);
        assert_eq!(AnyOf(MaxIterations(5), GoalReached).iteration_budget(), Some(5));
        assert_eq!(AnyOf(GoalReached, MaxIterations(5)).iteration_budget(), Some(5));
        assert_eq!(AnyOf(MaxIterations(9), MaxIterations(4)).iteration_budget(), Some(4));
        assert_eq!(AnyOf(GoalReached, GoalReached).iteration_budget(), None);
        // Through the forwarding impl for `&mut T`.
        let mut max = MaxIterations(3);
        let forwarded: &mut dyn Termination = &mut max;
        assert_eq!(Termination::iteration_budget(&forwarded), Some(3));
    }
}
