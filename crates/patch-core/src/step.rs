//! Steps: the motions a step intersector checks (thesis §5.4.1, "Step").
//!
//! A step is a sphere of radius `r` swept along the segment from `start` to `end`: the robot's
//! workspace bounding sphere moving along one roadmap edge (§6.1). With `r = 0` it is a line
//! step (the thesis's line intersectors, "only an approximation" because they ignore the
//! robot's size); with `start = end` it is a sphere at one point.

use std::fmt::Debug;

use serde::{Deserialize, Serialize};

use crate::{Aabb, Point3, Real, StepError, Vector3};

/// A straight motion of a sphere: `start → end` with radius `radius() ≥ 0`.
///
/// Implementors guarantee finite points and a finite non-negative radius (the provided types
/// check this in their constructors).
pub trait Step: Copy + Debug {
    /// Where the motion starts (`t = 0`).
    fn start(&self) -> Point3;
    /// Where the motion ends (`t = 1`).
    fn end(&self) -> Point3;
    /// The radius of the swept sphere (0 for a line step).
    fn radius(&self) -> Real;

    /// The sphere's centre at parameter `t`: `start` at 0, `end` at 1 (exactly), linear in
    /// between.
    fn point_at(&self, t: Real) -> Point3 {
        let (s, e) = (self.start(), self.end());
        if t == 0.0 {
            s
        } else if t == 1.0 {
            e
        } else {
            s + (e - s) * t
        }
    }

    /// The motion vector `end − start`.
    fn delta(&self) -> Vector3 {
        self.end() - self.start()
    }

    /// The length of the motion (0 for a sphere test).
    fn length(&self) -> Real {
        self.delta().norm()
    }

    /// The axis-aligned box of the swept sphere (the box of the core segment grown by the
    /// radius on every side). Every point the step can touch lies in it.
    fn bounds(&self) -> Aabb {
        Aabb::new(self.start(), self.end()).inflated(self.radius())
    }
}

#[inline]
fn check_point(p: &Point3, which: &'static str) -> Result<(), StepError> {
    if p.iter().all(|c| c.is_finite()) { Ok(()) } else { Err(StepError::NonFinitePoint { which }) }
}

/// A line segment `start → end` (a step of radius 0).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawLineStep", into = "RawLineStep")]
pub struct LineStep {
    start: Point3,
    end: Point3,
}

#[derive(Serialize, Deserialize)]
struct RawLineStep {
    start: Point3,
    end: Point3,
}

impl TryFrom<RawLineStep> for LineStep {
    type Error = StepError;
    fn try_from(raw: RawLineStep) -> Result<Self, Self::Error> {
        LineStep::new(raw.start, raw.end)
    }
}

impl From<LineStep> for RawLineStep {
    fn from(s: LineStep) -> Self {
        RawLineStep { start: s.start, end: s.end }
    }
}

impl LineStep {
    /// The segment from `start` to `end` (they may coincide).
    ///
    /// # Errors
    /// [`StepError::NonFinitePoint`] if a coordinate is NaN or infinite.
    pub fn new(start: Point3, end: Point3) -> Result<LineStep, StepError> {
        check_point(&start, "start")?;
        check_point(&end, "end")?;
        Ok(LineStep { start, end })
    }

    /// This segment as a capsule step of the given radius.
    ///
    /// # Errors
    /// [`StepError::InvalidRadius`] for a negative, NaN or infinite radius.
    pub fn with_radius(&self, radius: Real) -> Result<CapsuleStep, StepError> {
        CapsuleStep::new(self.start, self.end, radius)
    }

    /// The same segment run backwards.
    pub fn reversed(&self) -> LineStep {
        LineStep { start: self.end, end: self.start }
    }
}

impl Step for LineStep {
    fn start(&self) -> Point3 {
        self.start
    }
    fn end(&self) -> Point3 {
        self.end
    }
    fn radius(&self) -> Real {
        0.0
    }
}

/// A capsule step: a sphere of radius `radius` swept from `start` to `end` (thesis §5.4.1:
/// "the convex hull of two spheres of equal radius").
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawCapsuleStep", into = "RawCapsuleStep")]
pub struct CapsuleStep {
    start: Point3,
    end: Point3,
    radius: Real,
}

#[derive(Serialize, Deserialize)]
struct RawCapsuleStep {
    start: Point3,
    end: Point3,
    radius: Real,
}

impl TryFrom<RawCapsuleStep> for CapsuleStep {
    type Error = StepError;
    fn try_from(raw: RawCapsuleStep) -> Result<Self, Self::Error> {
        CapsuleStep::new(raw.start, raw.end, raw.radius)
    }
}

impl From<CapsuleStep> for RawCapsuleStep {
    fn from(s: CapsuleStep) -> Self {
        RawCapsuleStep { start: s.start, end: s.end, radius: s.radius }
    }
}

impl CapsuleStep {
    /// The sphere of radius `radius` swept from `start` to `end` (they may coincide; the radius
    /// may be 0).
    ///
    /// # Errors
    /// [`StepError::NonFinitePoint`] for a NaN or infinite coordinate,
    /// [`StepError::InvalidRadius`] for a negative, NaN or infinite radius.
    #[inline]
    pub fn new(start: Point3, end: Point3, radius: Real) -> Result<CapsuleStep, StepError> {
        check_point(&start, "start")?;
        check_point(&end, "end")?;
        if !(radius >= 0.0 && radius.is_finite()) {
            return Err(StepError::InvalidRadius { radius });
        }
        Ok(CapsuleStep { start, end, radius })
    }

    /// A sphere of radius `radius` at `center` (a zero-length step).
    ///
    /// # Errors
    /// As [`CapsuleStep::new`].
    pub fn sphere(center: Point3, radius: Real) -> Result<CapsuleStep, StepError> {
        CapsuleStep::new(center, center, radius)
    }

    /// The core segment, without the radius.
    pub fn line(&self) -> LineStep {
        LineStep { start: self.start, end: self.end }
    }

    /// The same step run backwards.
    pub fn reversed(&self) -> CapsuleStep {
        CapsuleStep { start: self.end, end: self.start, radius: self.radius }
    }
}

impl From<LineStep> for CapsuleStep {
    fn from(line: LineStep) -> Self {
        CapsuleStep { start: line.start, end: line.end, radius: 0.0 }
    }
}

impl Step for CapsuleStep {
    fn start(&self) -> Point3 {
        self.start
    }
    fn end(&self) -> Point3 {
        self.end
    }
    fn radius(&self) -> Real {
        self.radius
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::na;

    #[test]
    fn constructors_validate() {
        let o = Point3::origin();
        let x = Point3::new(1.0, 0.0, 0.0);
        assert!(LineStep::new(o, x).is_ok());
        assert!(LineStep::new(o, o).is_ok());
        assert_eq!(
            LineStep::new(Point3::new(Real::NAN, 0.0, 0.0), x),
            Err(StepError::NonFinitePoint { which: "start" })
        );
        assert_eq!(
            LineStep::new(o, Point3::new(0.0, Real::INFINITY, 0.0)),
            Err(StepError::NonFinitePoint { which: "end" })
        );
        assert!(CapsuleStep::new(o, x, 0.0).is_ok());
        assert!(matches!(CapsuleStep::new(o, x, -1e-300), Err(StepError::InvalidRadius { .. })));
        assert!(matches!(CapsuleStep::new(o, x, Real::NAN), Err(StepError::InvalidRadius { .. })));
        assert!(matches!(
            CapsuleStep::new(o, x, Real::INFINITY),
            Err(StepError::InvalidRadius { .. })
        ));
    }

    #[test]
    fn defaults_interpolate_and_bound() {
        let s =
            CapsuleStep::new(Point3::new(0.1, 0.2, 0.3), Point3::new(1.7, -0.9, 2.3), 0.5).unwrap();
        assert_eq!(s.point_at(0.0), s.start());
        assert_eq!(s.point_at(1.0), s.end());
        assert!((s.point_at(0.5) - na::center(&s.start(), &s.end())).norm() < 1e-15);
        assert!((s.length() - s.delta().norm()).abs() == 0.0);
        let b = s.bounds();
        assert_eq!(b.min, Point3::new(-0.4, -1.4, -0.2));
        assert_eq!(b.max, Point3::new(2.2, 0.7, 2.8));
        assert_eq!(s.reversed().start(), s.end());
        assert_eq!(s.line().radius(), 0.0);
        assert_eq!(CapsuleStep::from(s.line()).radius(), 0.0);
        assert_eq!(s.line().with_radius(0.5).unwrap(), s);
        assert_eq!(CapsuleStep::sphere(s.start(), 0.5).unwrap().length(), 0.0);
    }

    #[test]
    fn serde_round_trip_and_rejection() {
        let s =
            CapsuleStep::new(Point3::new(0.1, 0.2, 0.3), Point3::new(1.0, 2.0, 3.0), 0.25).unwrap();
        let json = serde_json::to_string(&s).unwrap();
        assert_eq!(serde_json::from_str::<CapsuleStep>(&json).unwrap(), s);
        let bad = json.replace("0.25", "-0.25");
        assert!(serde_json::from_str::<CapsuleStep>(&bad).is_err());
        let l = s.line();
        let json = serde_json::to_string(&l).unwrap();
        assert_eq!(serde_json::from_str::<LineStep>(&json).unwrap(), l);
        assert!(
            serde_json::from_str::<LineStep>(r#"{"start":[0,0,0],"end":[0,0,1e999]}"#).is_err()
        );
    }
}
