//! The box of a few points, grown, inflated and tested.

use patch_math::{Aabb, Point3};

fn main() {
    let points = [Point3::new(0.0, 0.0, 0.0), Point3::new(2.0, 1.0, 0.5)];
    let mut b = Aabb::from_points(&points);
    b.grow(&Point3::new(-1.0, 0.5, 1.0));
    let padded = b.inflated(0.3);
    println!("box {:?} .. {:?}, extents {:?}", b.min, b.max, b.extents());
    println!(
        "padded by 0.3 m contains (2.2, 1.2, 0.0): {}",
        padded.contains(&Point3::new(2.2, 1.2, 0.0))
    );
}
