//! A transform tree from `/tf` and `/tf_static`, looked up at a time with interpolation.

use crate::msgs::TransformStamped;
use pointcloud::Isometry3;
use std::collections::HashMap;

/// Why a transform could not be looked up.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum TfError {
    /// No chain of transforms joins the two frames.
    #[error(
        "no transform chain from `{from}` to `{to}` (the chain stops at `{from_root}` and `{to_root}`)"
    )]
    NoPath {
        /// The source frame.
        from: String,
        /// The target frame.
        to: String,
        /// The farthest ancestor of `from`.
        from_root: String,
        /// The farthest ancestor of `to`.
        to_root: String,
    },
    /// The time lies outside the samples of a dynamic transform (no extrapolation).
    #[error(
        "`{parent}` -> `{child}` is known from {first_ns} to {last_ns} ns, not at {stamp_ns} ns"
    )]
    OutOfRange {
        /// The parent frame.
        parent: String,
        /// The child frame.
        child: String,
        /// The time asked for.
        stamp_ns: i64,
        /// The first sample.
        first_ns: i64,
        /// The last sample.
        last_ns: i64,
    },
}

#[derive(Clone, Debug, Default)]
struct Edge {
    parent: String,
    /// `None` for a static transform.
    samples: Vec<(i64, Isometry3)>,
    fixed: Option<Isometry3>,
}

/// Every transform of a bag: each child frame has one parent, with a static transform or
/// time-stamped samples.
///
/// [`TfTree::lookup`] interpolates between the two samples around the time (linearly in the
/// translation, spherically in the rotation; where that is ambiguous it takes the nearer
/// sample), returns a sample exactly at its own stamp, and does not extrapolate. A later parent for a child replaces the earlier one (as tf does).
#[derive(Clone, Debug, Default)]
pub struct TfTree {
    edges: HashMap<String, Edge>,
    sorted: bool,
}

impl TfTree {
    /// An empty tree.
    pub fn new() -> TfTree {
        TfTree::default()
    }

    /// Adds transforms of `/tf_static` (`is_static`) or `/tf`.
    pub fn insert(&mut self, transforms: &[TransformStamped], is_static: bool) {
        for t in transforms {
            let edge = self.edges.entry(t.child_frame_id.clone()).or_default();
            if edge.parent != t.header.frame_id {
                *edge = Edge { parent: t.header.frame_id.clone(), ..Edge::default() };
            }
            if is_static {
                edge.fixed = Some(t.parent_from_child);
            } else {
                edge.samples.push((t.header.stamp_ns, t.parent_from_child));
                self.sorted = false;
            }
        }
    }

    fn sort(&mut self) {
        if !self.sorted {
            for e in self.edges.values_mut() {
                e.samples.sort_by_key(|s| s.0);
            }
            self.sorted = true;
        }
    }

    /// The farthest ancestor of `frame` (`frame` itself if it has no parent).
    pub fn root(&self, frame: &str) -> String {
        self.chain(frame).pop().unwrap_or_default()
    }

    /// The frames from `frame` up to its root, `frame` first.
    fn chain(&self, frame: &str) -> Vec<String> {
        let mut out = vec![frame.to_owned()];
        while let Some(e) = self.edges.get(out.last().map(String::as_str).unwrap_or_default()) {
            if out.contains(&e.parent) || out.len() > self.edges.len() {
                break; // a loop: stop rather than spin
            }
            out.push(e.parent.clone());
        }
        out
    }

    fn parent_from_child(&self, child: &str, stamp_ns: i64) -> Result<Isometry3, TfError> {
        let e = &self.edges[child];
        if let Some(m) = e.fixed {
            return Ok(m);
        }
        let s = &e.samples;
        let out_of_range = || TfError::OutOfRange {
            parent: e.parent.clone(),
            child: child.to_owned(),
            stamp_ns,
            first_ns: s.first().map_or(0, |x| x.0),
            last_ns: s.last().map_or(0, |x| x.0),
        };
        let i = s.partition_point(|x| x.0 < stamp_ns);
        match (s.get(i), i.checked_sub(1).and_then(|j| s.get(j))) {
            (Some(&(t, m)), _) if t == stamp_ns => Ok(m),
            (Some(&(t1, m1)), Some(&(t0, m0))) => {
                let a = (stamp_ns - t0) as f64 / (t1 - t0) as f64;
                // Where slerp is ambiguous (opposite quaternions), take the nearer sample.
                Ok(m0.try_lerp_slerp(&m1, a, 1e-12).unwrap_or(if a < 0.5 { m0 } else { m1 }))
            }
            _ => Err(out_of_range()),
        }
    }

    /// `target_from_source` at `stamp_ns`: takes points in `source` to `target`.
    ///
    /// # Errors
    /// [`TfError::NoPath`] when no chain joins the frames, [`TfError::OutOfRange`] when a
    /// dynamic transform on the chain has no samples around the time.
    pub fn lookup(
        &mut self,
        target: &str,
        source: &str,
        stamp_ns: i64,
    ) -> Result<Isometry3, TfError> {
        self.sort();
        let up_source = self.chain(source);
        let up_target = self.chain(target);
        let Some((i, j)) = up_source
            .iter()
            .enumerate()
            .find_map(|(i, f)| up_target.iter().position(|g| g == f).map(|j| (i, j)))
        else {
            return Err(TfError::NoPath {
                from: source.to_owned(),
                to: target.to_owned(),
                from_root: up_source.last().cloned().unwrap_or_default(),
                to_root: up_target.last().cloned().unwrap_or_default(),
            });
        };
        // common_from_source = p(up_source[i-1]) * … * p(up_source[0]), composed from the top.
        let mut common_from_source = Isometry3::identity();
        for child in up_source[..i].iter().rev() {
            common_from_source *= self.parent_from_child(child, stamp_ns)?;
        }
        let mut common_from_target = Isometry3::identity();
        for child in up_target[..j].iter().rev() {
            common_from_target *= self.parent_from_child(child, stamp_ns)?;
        }
        Ok(if j == 0 {
            common_from_source
        } else {
            common_from_target.inverse() * common_from_source
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msgs::Header;
    use pointcloud::na::{UnitQuaternion, Vector3};

    fn t(stamp_ns: i64, parent: &str, child: &str, m: Isometry3) -> TransformStamped {
        TransformStamped {
            header: Header { stamp_ns, frame_id: parent.into() },
            child_frame_id: child.into(),
            parent_from_child: m,
        }
    }

    #[test]
    fn chains_compose_and_interpolate() {
        let mut tree = TfTree::new();
        let mount = Isometry3::translation(0.1, 0.0, 0.5);
        tree.insert(&[t(0, "base_link", "sensor", mount)], true);
        let turn = Isometry3::from_parts(
            Vector3::new(2.0, 0.0, 0.0).into(),
            UnitQuaternion::from_euler_angles(0.0, 0.0, 1.0),
        );
        tree.insert(
            &[
                t(100, "odom", "base_link", Isometry3::identity()),
                t(200, "odom", "base_link", turn),
            ],
            false,
        );
        assert_eq!(tree.lookup("odom", "sensor", 100).unwrap(), mount);
        assert_eq!(tree.lookup("odom", "sensor", 200).unwrap(), turn * mount);
        let mid = tree.lookup("odom", "base_link", 150).unwrap();
        assert!((mid.translation.vector - Vector3::new(1.0, 0.0, 0.0)).norm() < 1e-12);
        assert!((mid.rotation.angle() - 0.5).abs() < 1e-12);
        let back = tree.lookup("sensor", "odom", 200).unwrap();
        assert!(
            ((back * turn * mount).to_homogeneous() - Isometry3::identity().to_homogeneous())
                .abs()
                .max()
                < 1e-12
        );
        assert_eq!(tree.lookup("sensor", "sensor", 7).unwrap(), Isometry3::identity());
        assert!(matches!(tree.lookup("odom", "sensor", 250), Err(TfError::OutOfRange { .. })));
        assert!(matches!(tree.lookup("map", "sensor", 150), Err(TfError::NoPath { .. })));
    }

    #[test]
    fn half_turns_and_negated_quaternions_interpolate_without_panic() {
        let mut tree = TfTree::new();
        let half = Isometry3::rotation(Vector3::z() * std::f64::consts::PI);
        let samples = [t(0, "odom", "base", Isometry3::identity()), t(10, "odom", "base", half)];
        tree.insert(&samples, false);
        let yaw = tree.lookup("odom", "base", 4).unwrap().rotation.euler_angles().2;
        assert!((yaw.abs() - 0.4 * std::f64::consts::PI).abs() < 1e-9, "{yaw}");
        // The same rotation with the quaternion's sign flipped.
        let negated = UnitQuaternion::new_unchecked(-*UnitQuaternion::identity().quaternion());
        let flipped = Isometry3::from_parts(Vector3::zeros().into(), negated);
        let samples = [t(20, "odom", "b2", Isometry3::identity()), t(30, "odom", "b2", flipped)];
        tree.insert(&samples, false);
        let mid = tree.lookup("odom", "b2", 25).unwrap();
        assert!(mid.rotation.angle() < 1e-9, "{mid}");
    }

    #[test]
    fn a_loop_in_the_tree_ends_the_walk() {
        let mut tree = TfTree::new();
        let m = Isometry3::translation(1.0, 0.0, 0.0);
        tree.insert(&[t(0, "a", "b", m), t(0, "b", "a", m)], true);
        assert!(matches!(tree.lookup("c", "a", 0), Err(TfError::NoPath { .. })));
        assert!(tree.lookup("b", "a", 0).is_ok());
    }
}
