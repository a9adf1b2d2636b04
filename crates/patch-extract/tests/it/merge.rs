//! Outline merging across scans: unions on one plane, nothing else.

use patch_core::{PlanarPatch, Point2, Point3, Polygon, Real, Vector3, plane_frame};
use patch_extract::merge::{MergeConfig, MergeError, merge_coplanar};
use proptest::prelude::*;

/// An axis-aligned rectangle `[x0, x1] × [y0, y1]` on the plane z = `z`, in a frame whose
/// origin is shifted by `shift` along the plane (as patches of different scans are).
fn rect(x0: Real, y0: Real, x1: Real, y1: Real, z: Real, shift: Real) -> PlanarPatch {
    let origin = Point3::new(shift, -shift, z);
    let frame = plane_frame(&Vector3::z(), &origin);
    let local = |x: Real, y: Real| {
        let q = frame.inverse_transform_point(&Point3::new(x, y, z));
        Point2::new(q.x, q.y)
    };
    let outer = vec![local(x0, y0), local(x1, y0), local(x1, y1), local(x0, y1)];
    PlanarPatch::new(Polygon::new(outer, vec![]).unwrap(), frame).unwrap()
}

fn total_area(patches: &[PlanarPatch]) -> Real {
    patches.iter().map(PlanarPatch::area).sum()
}

#[test]
fn overlapping_patches_of_one_plane_become_one() {
    let a = rect(0.0, 0.0, 2.0, 1.0, 1.0, 0.0);
    let b = rect(1.5, 0.0, 3.0, 1.0, 1.01, 0.7); // 1 cm off, another frame origin
    let (out, stats) = merge_coplanar(&[a, b], &MergeConfig::alrf()).unwrap();
    assert_eq!(out.len(), 1);
    assert_eq!((stats.input, stats.output, stats.groups_merged, stats.kept_unmerged), (2, 1, 1, 0));
    assert!((out[0].area() - 3.0).abs() < 1e-3, "{}", out[0].area());
    assert!(out[0].polygon().num_vertices() <= 8);
    assert!(out[0].covariance().is_none());
}

#[test]
fn apart_tilted_or_offset_patches_stay_apart() {
    let a = rect(0.0, 0.0, 1.0, 1.0, 0.0, 0.0);
    let config = MergeConfig::alrf();
    // Same plane, 10 cm apart.
    let (out, _) =
        merge_coplanar(&[a.clone(), rect(1.1, 0.0, 2.0, 1.0, 0.0, 0.0)], &config).unwrap();
    assert_eq!(out.len(), 2);
    // ... unless the gap allows it: still two polygons (the gap is not filled), one group.
    let with_gap = MergeConfig { gap: 0.2, ..config };
    let (out, stats) =
        merge_coplanar(&[a.clone(), rect(1.1, 0.0, 2.0, 1.0, 0.0, 0.0)], &with_gap).unwrap();
    assert_eq!((out.len(), stats.groups_merged), (2, 1));
    assert!((total_area(&out) - 1.9).abs() < 1e-9);
    // Overlapping in x and y, but 20 cm apart along the normal.
    let (out, _) =
        merge_coplanar(&[a.clone(), rect(0.5, 0.0, 2.0, 1.0, 0.2, 0.0)], &config).unwrap();
    assert_eq!(out.len(), 2);
    // Crossing at 10°.
    let tilted = {
        let r = patch_core::na::Rotation3::from_axis_angle(&Vector3::y_axis(), 10f64.to_radians());
        let frame = patch_core::Isometry3::from_parts(
            patch_core::na::Translation3::new(0.5, 0.0, 0.0),
            patch_core::na::UnitQuaternion::from_rotation_matrix(&r),
        );
        PlanarPatch::new(
            Polygon::rectangle(Point2::new(0.0, 0.0), Point2::new(1.0, 1.0)).unwrap(),
            frame,
        )
        .unwrap()
    };
    let (out, _) = merge_coplanar(&[a, tilted], &config).unwrap();
    assert_eq!(out.len(), 2);
}

#[test]
fn a_ring_of_scans_around_a_square_keeps_the_hole() {
    let parts = [
        rect(0.0, 0.0, 3.0, 1.0, 0.0, 0.0),
        rect(2.0, 0.0, 3.0, 3.0, 0.0, 0.3),
        rect(0.0, 2.0, 3.0, 3.0, 0.0, -0.4),
        rect(0.0, 0.0, 1.0, 3.0, 0.0, 0.1),
    ];
    let (out, stats) = merge_coplanar(&parts, &MergeConfig::exact()).unwrap();
    assert_eq!(stats.groups_merged, 1);
    assert_eq!(out.len(), 1);
    assert_eq!(out[0].polygon().holes().len(), 1);
    assert!((out[0].area() - 8.0).abs() < 1e-9, "{}", out[0].area());
}

#[test]
fn both_sides_of_a_wall_and_chains_merge() {
    // The same wall seen from both sides: opposite normals.
    let front = rect(0.0, 0.0, 2.0, 1.0, 0.0, 0.0);
    let back = {
        let r =
            patch_core::na::Rotation3::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI);
        let frame = patch_core::Isometry3::from_parts(
            patch_core::na::Translation3::new(1.0, 1.0, 0.0),
            patch_core::na::UnitQuaternion::from_rotation_matrix(&r),
        );
        // x ∈ [1, 3] in the world, y ∈ [0, 1] (the frame flips y).
        PlanarPatch::new(
            Polygon::rectangle(Point2::new(0.0, 0.0), Point2::new(2.0, 1.0)).unwrap(),
            frame,
        )
        .unwrap()
    };
    let (out, _) = merge_coplanar(&[front, back], &MergeConfig::exact()).unwrap();
    assert_eq!(out.len(), 1);
    assert!((out[0].area() - 3.0).abs() < 1e-9);
    // A chain: a–b overlap, b–c overlap, a–c do not.
    let chain = [
        rect(0.0, 0.0, 1.0, 1.0, 0.0, 0.0),
        rect(0.9, 0.0, 2.0, 1.0, 0.0, 0.0),
        rect(1.9, 0.0, 3.0, 1.0, 0.0, 0.0),
    ];
    let (out, _) = merge_coplanar(&chain, &MergeConfig::exact()).unwrap();
    assert_eq!(out.len(), 1);
    assert!((out[0].area() - 3.0).abs() < 1e-9);
}

#[test]
fn bad_parameters_and_empty_input() {
    let (out, stats) = merge_coplanar(&[], &MergeConfig::alrf()).unwrap();
    assert!(out.is_empty() && stats.output == 0);
    for config in [
        MergeConfig { max_angle: Real::NAN, ..MergeConfig::alrf() },
        MergeConfig { max_angle: 2.0, ..MergeConfig::alrf() },
        MergeConfig { max_distance: -1.0, ..MergeConfig::alrf() },
        MergeConfig { gap: Real::INFINITY, ..MergeConfig::alrf() },
    ] {
        assert!(matches!(merge_coplanar(&[], &config), Err(MergeError::InvalidParameter { .. })));
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// Random rectangles with integer corners on one plane: the merged patches cover exactly
    /// the union (counted on the unit cells), and no two output patches overlap.
    #[test]
    fn merged_area_is_the_union_area(
        rects in proptest::collection::vec((0..8i32, 0..8i32, 1..4i32, 1..4i32, -1.0..1.0f64), 1..7),
    ) {
        let patches: Vec<PlanarPatch> = rects
            .iter()
            .map(|&(x, y, w, h, shift)| {
                rect(x as Real, y as Real, (x + w) as Real, (y + h) as Real, 0.5, shift)
            })
            .collect();
        let mut cells = std::collections::HashSet::new();
        for &(x, y, w, h, _) in &rects {
            for i in x..x + w {
                for j in y..y + h {
                    cells.insert((i, j));
                }
            }
        }
        let (out, stats) = merge_coplanar(&patches, &MergeConfig::exact()).unwrap();
        prop_assert_eq!(stats.output, out.len());
        prop_assert!((total_area(&out) - cells.len() as Real).abs() < 1e-6,
            "{} vs {}", total_area(&out), cells.len());
        // Every unit cell centre is inside exactly one output patch.
        for &(i, j) in &cells {
            let c = Point3::new(i as Real + 0.5, j as Real + 0.5, 0.5);
            let inside = out
                .iter()
                .filter(|p| {
                    let q = p.to_local(&c);
                    p.polygon().contains(&Point2::new(q.x, q.y))
                })
                .count();
            prop_assert_eq!(inside, 1);
        }
    }
}

/// Four rectangles around a unit cell whose union has a hole touching the outline at one
/// vertex (a case a random search found): merged without overlap, with the exact area.
#[test]
fn a_hole_pinched_to_the_outline_is_separated() {
    let cells = [(0, 4, 2, 3), (3, 5, 1, 2), (1, 6, 2, 1), (1, 3, 2, 2)];
    let patches: Vec<PlanarPatch> = cells
        .iter()
        .map(|&(x, y, w, h)| rect(x as Real, y as Real, (x + w) as Real, (y + h) as Real, 0.5, 0.0))
        .collect();
    let (out, stats) = merge_coplanar(&patches, &MergeConfig::exact()).unwrap();
    assert_eq!(stats.kept_unmerged, 0, "{stats:?}");
    assert_eq!(out.len(), 1);
    assert_eq!(out[0].polygon().holes().len(), 1, "the enclosed cell stays a hole");
    assert!((total_area(&out) - 12.0).abs() < 1e-6, "{}", total_area(&out));
}
