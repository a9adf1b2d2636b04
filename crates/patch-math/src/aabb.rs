//! Axis-aligned bounding boxes.

use crate::{Point3, Real, Vector3};
use serde::{Deserialize, Serialize};

/// An axis-aligned box `[min, max]` (closed on both sides).
///
/// The empty box has `min = +∞` and `max = −∞`, so [`Aabb::grow`] works from it without a
/// special case; [`Aabb::is_empty`] tells it apart.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Aabb {
    /// The corner with the smallest coordinates.
    pub min: Point3,
    /// The corner with the largest coordinates.
    pub max: Point3,
}

impl Aabb {
    /// The empty box: contains nothing, and growing it by a point gives that point's box.
    pub const EMPTY: Aabb = Aabb {
        min: Point3::new(Real::INFINITY, Real::INFINITY, Real::INFINITY),
        max: Point3::new(Real::NEG_INFINITY, Real::NEG_INFINITY, Real::NEG_INFINITY),
    };

    /// The box with the given corners. The corners are sorted per axis, so any two opposite
    /// corners work.
    #[inline]
    pub fn new(a: Point3, b: Point3) -> Aabb {
        Aabb { min: a.inf(&b), max: a.sup(&b) }
    }

    /// The smallest box holding all `points` ([`Aabb::EMPTY`] for none).
    pub fn from_points<'a>(points: impl IntoIterator<Item = &'a Point3>) -> Aabb {
        let mut aabb = Aabb::EMPTY;
        for p in points {
            aabb.grow(p);
        }
        aabb
    }

    /// Whether the box holds no point at all.
    #[inline]
    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y && self.min.z <= self.max.z)
    }

    /// Grows the box to hold `p`.
    #[inline]
    pub fn grow(&mut self, p: &Point3) {
        self.min = self.min.inf(p);
        self.max = self.max.sup(p);
    }

    /// The smallest box holding both boxes.
    #[inline]
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb { min: self.min.inf(&other.min), max: self.max.sup(&other.max) }
    }

    /// The box grown by `margin` on every side (shrunk for a negative margin).
    #[inline]
    pub fn inflated(&self, margin: Real) -> Aabb {
        let m = Vector3::repeat(margin);
        Aabb { min: self.min - m, max: self.max + m }
    }

    /// Whether `p` lies in the closed box.
    #[inline]
    pub fn contains(&self, p: &Point3) -> bool {
        (0..3).all(|i| self.min[i] <= p[i] && p[i] <= self.max[i])
    }

    /// Whether the two closed boxes share at least one point.
    #[inline]
    pub fn intersects(&self, other: &Aabb) -> bool {
        // Without short-circuits: six comparisons and one branch at the caller, which runs
        // this over many boxes in a row (the polygon map's loop over its patches).
        (self.min.x <= other.max.x)
            & (other.min.x <= self.max.x)
            & (self.min.y <= other.max.y)
            & (other.min.y <= self.max.y)
            & (self.min.z <= other.max.z)
            & (other.min.z <= self.max.z)
    }

    /// The centre of the box.
    #[inline]
    pub fn center(&self) -> Point3 {
        na::center(&self.min, &self.max)
    }

    /// The edge lengths of the box (zero for an empty box).
    #[inline]
    pub fn extents(&self) -> Vector3 {
        if self.is_empty() { Vector3::zeros() } else { self.max - self.min }
    }

    /// The volume of the box (zero for an empty box).
    pub fn volume(&self) -> Real {
        let e = self.extents();
        e.x * e.y * e.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_box_grows_to_its_points() {
        let mut b = Aabb::EMPTY;
        assert!(b.is_empty());
        assert_eq!(b.volume(), 0.0);
        b.grow(&Point3::new(1.0, 2.0, 3.0));
        assert!(!b.is_empty());
        assert_eq!(b.min, b.max);
        b.grow(&Point3::new(-1.0, 4.0, 3.0));
        assert_eq!(b, Aabb::new(Point3::new(1.0, 4.0, 3.0), Point3::new(-1.0, 2.0, 3.0)));
        assert!(b.contains(&Point3::new(0.0, 3.0, 3.0)));
        assert!(!b.contains(&Point3::new(0.0, 3.0, 3.1)));
    }

    #[test]
    fn intersection_is_closed() {
        let a = Aabb::new(Point3::origin(), Point3::new(1.0, 1.0, 1.0));
        let b = Aabb::new(Point3::new(1.0, 0.0, 0.0), Point3::new(2.0, 1.0, 1.0));
        let c = Aabb::new(Point3::new(1.1, 0.0, 0.0), Point3::new(2.0, 1.0, 1.0));
        assert!(a.intersects(&b));
        assert!(!a.intersects(&c));
        assert!(!a.intersects(&Aabb::EMPTY));
        assert_eq!(a.union(&c).extents(), Vector3::new(2.0, 1.0, 1.0));
        assert_eq!(a.inflated(0.5).volume(), 8.0);
    }
}
