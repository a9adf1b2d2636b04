//! The fast Algorithm 2 ([`NormalTable`]) against its literal transcription ([`vote_literal`]):
//! equal bin for bin on random clouds, spaces and normal kinds, serial and parallel.

use hough_terrain::{
    Accumulator, AngleAxis, DistanceAxis, HoughSpace, NormalKind, NormalTable, vote_literal,
};
use nalgebra::Point3;
use proptest::prelude::*;

fn angle_axis() -> impl Strategy<Value = AngleAxis> {
    (-89.0f64..60.0, 0.5f64..1.0, 2.0f64..90.0).prop_map(|(min, f, res)| {
        let max = min + (90.0 - min) * f;
        AngleAxis::degrees(min, max.max(min + 0.5), res)
    })
}

fn distance_axis() -> impl Strategy<Value = DistanceAxis> {
    (-3.0f64..1.0, 0.05f64..5.0, 0.01f64..1.0).prop_map(|(min, span, res)| DistanceAxis {
        min,
        max: min + span,
        resolution: res,
    })
}

fn space() -> impl Strategy<Value = HoughSpace> {
    (angle_axis(), angle_axis(), distance_axis(), any::<bool>()).prop_map(|(x, y, d, unit)| {
        let kind = if unit { NormalKind::Unit } else { NormalKind::Thesis };
        HoughSpace::new(x, y, d, kind).unwrap()
    })
}

fn cloud() -> impl Strategy<Value = Vec<Point3<f64>>> {
    prop::collection::vec(
        prop_oneof![
            // Anywhere.
            (-5.0f64..5.0, -5.0f64..5.0, -3.0f64..3.0).prop_map(|(x, y, z)| Point3::new(x, y, z)),
            // On a decimetre grid: distances land on bin edges.
            (-30i32..30, -30i32..30, -10i32..20).prop_map(|(x, y, z)| Point3::new(
                x as f64 * 0.1,
                y as f64 * 0.1,
                z as f64 * 0.1
            )),
        ],
        0..300,
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn fast_equals_literal(space in space(), points in cloud(), threads in 1usize..4) {
        let literal = vote_literal(&space, &points).unwrap();
        let table = NormalTable::new(&space);
        let mut fast = Accumulator::new(space);
        table.vote(&points, &mut fast).unwrap();
        prop_assert_eq!(fast.counts(), literal.counts());
        prop_assert_eq!(fast.points(), literal.points());
        let mut par = Accumulator::new(space);
        let mut partials = Vec::new();
        table.vote_parallel(&points, &mut par, &mut partials, threads).unwrap();
        prop_assert_eq!(par.counts(), literal.counts());
        prop_assert_eq!(par.points(), points.len());
    }
}

#[test]
fn thesis_resolutions_on_a_big_cloud() {
    // Many blocks and both normal kinds at the thesis's three resolutions.
    let points: Vec<_> = (0..3000)
        .map(|i| {
            let f = i as f64;
            Point3::new(
                0.5 + (f * 0.013).fract() * 5.0,
                (f * 0.71).sin() * 2.0,
                0.45 + (f * 0.3).cos() * 0.6,
            )
        })
        .collect();
    for res in [45.0, 15.0, 9.0, 5.0] {
        for kind in [NormalKind::Thesis, NormalKind::Unit] {
            let space = HoughSpace::thesis_degrees(res).unwrap().with_normal(kind);
            let literal = vote_literal(&space, &points).unwrap();
            let mut fast = Accumulator::new(space);
            NormalTable::new(&space).vote(&points, &mut fast).unwrap();
            assert_eq!(fast, literal, "{res}° {kind:?}");
            assert!(literal.total_votes() > 0);
        }
    }
}

#[test]
fn many_distance_bins_use_the_direct_kernel() {
    // 300 distance bins (≥ 256): the general kernel; still equal to the literal one.
    let space = HoughSpace::new(
        AngleAxis::degrees(-45.0, 18.0, 9.0),
        AngleAxis::degrees(-45.0, 45.0, 9.0),
        DistanceAxis { min: -1.0, max: 2.0, resolution: 0.01 },
        NormalKind::Thesis,
    )
    .unwrap();
    assert_eq!(space.nd(), 300);
    let points: Vec<_> = (0..2000)
        .map(|i| {
            let f = i as f64;
            Point3::new((f * 0.37).sin() * 3.0, (f * 0.11).cos() * 2.0, (f * 0.05).sin())
        })
        .collect();
    let literal = vote_literal(&space, &points).unwrap();
    let mut fast = Accumulator::new(space);
    NormalTable::new(&space).vote(&points, &mut fast).unwrap();
    assert_eq!(fast, literal);
    assert!(literal.total_votes() > 0);
}
