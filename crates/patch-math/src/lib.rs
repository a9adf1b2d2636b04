//! The math types every crate of the workspace shares: the scalar [`Real`], [`Point3`],
//! [`Vector3`], [`Isometry3`] and the axis-aligned box [`Aabb`].
//!
//! They sit below the file formats (`pointcloud`) and the patch types (`patch-core`), so a
//! planner can use them without compiling a PLY or JSON reader. All geometry is `f64` and uses
//! [`nalgebra`] types, re-exported as [`na`].
//!
//! ```
//! use patch_math::{Aabb, Point3};
//!
//! let b = Aabb::new(Point3::new(1.0, 0.0, 2.0), Point3::new(0.0, 1.0, 0.0));
//! assert!(b.contains(&Point3::new(0.5, 0.5, 1.0)));
//! ```

pub extern crate nalgebra as na;

mod aabb;

pub use aabb::Aabb;

/// The one scalar type of the workspace.
pub type Real = f64;
/// A point in 3D.
pub type Point3 = na::Point3<Real>;
/// A vector in 3D.
pub type Vector3 = na::Vector3<Real>;
/// A rigid transform in 3D.
pub type Isometry3 = na::Isometry3<Real>;
