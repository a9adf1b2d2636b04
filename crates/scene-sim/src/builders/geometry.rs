//! Small constructors the builders share.

use crate::shapes::Point2;
use crate::{PlanarPolygon, SceneError};
use pointcloud::{Isometry3, Point3, Real, Vector3};

/// The frame of a vertical patch through `origin` whose normal is the horizontal unit vector
/// `normal`: local x is `z × normal` (horizontal), local y is up, local z is `normal`.
pub(crate) fn vertical_frame(origin: Point3, normal: Vector3) -> Isometry3 {
    let z = Vector3::z();
    let x = z.cross(&normal);
    let r = nalgebra::Rotation3::from_basis_unchecked(&[x, z, normal]);
    Isometry3::from_parts(origin.coords.into(), nalgebra::UnitQuaternion::from_rotation_matrix(&r))
}

/// A horizontal rectangle `[min, max]` (world x, y) at height `z`, normal up or down.
pub(crate) fn horizontal_rect(
    min: Point2,
    max: Point2,
    z: Real,
    up: bool,
    holes: &[(Point2, Point2)],
) -> Result<PlanarPolygon, SceneError> {
    if up {
        PlanarPolygon::rectangle(Isometry3::translation(0.0, 0.0, z), min, max, holes)
    } else {
        // Rotation by π about x: local (x, y) is world (x, −y).
        let m = Isometry3::new(Vector3::new(0.0, 0.0, z), Vector3::x() * std::f64::consts::PI);
        let flip = |a: Point2, b: Point2| (Point2::new(a.x, -b.y), Point2::new(b.x, -a.y));
        let (lo, hi) = flip(min, max);
        let holes: Vec<_> = holes.iter().map(|&(a, b)| flip(a, b)).collect();
        PlanarPolygon::rectangle(m, lo, hi, &holes)
    }
}

/// A vertical rectangle in the plane through `origin` with horizontal unit `normal`:
/// horizontally from `origin + a0·t` to `origin + a1·t` with `t = z × normal`, vertically from
/// `z0` to `z1` (world heights), with rectangular holes given the same way
/// (`(a0, a1, z0, z1)`).
pub(crate) fn vertical_rect(
    origin: Point3,
    normal: Vector3,
    a: (Real, Real),
    z: (Real, Real),
    holes: &[(Real, Real, Real, Real)],
) -> Result<PlanarPolygon, SceneError> {
    let frame = vertical_frame(Point3::new(origin.x, origin.y, 0.0), normal);
    let r = |a0: Real, a1: Real, z0: Real, z1: Real| {
        (Point2::new(a0.min(a1), z0.min(z1)), Point2::new(a0.max(a1), z0.max(z1)))
    };
    let (lo, hi) = r(a.0, a.1, z.0, z.1);
    let holes: Vec<_> = holes.iter().map(|&(a0, a1, z0, z1)| r(a0, a1, z0, z1)).collect();
    PlanarPolygon::rectangle(frame, lo, hi, &holes)
}
