//! Algorithm 3 on hand-built accumulators: every branch, its strict inequalities, `type(bin)`
//! and passability.

use hough_terrain::{
    Accumulator, Bin, ClassifierConfig, HoughSpace, Rule, TerrainClass, algorithm3, floor_bin,
};

const HEIGHT: f64 = 0.45;

fn setup() -> (Accumulator, Bin, ClassifierConfig) {
    let space = HoughSpace::thesis_degrees(15.0).unwrap();
    let floor = floor_bin(&space, HEIGHT).unwrap();
    assert_eq!(floor.id, 14);
    (Accumulator::new(space), floor, ClassifierConfig::thesis())
}

#[test]
fn floor_bin_rule_wins_even_against_a_higher_bin() {
    let (mut acc, floor, cfg) = setup();
    acc.set_points(300);
    acc.add(floor, 101); // > 300/3
    acc.add(Bin { ix: 0, iy: 0, id: 20 }, 250);
    let c = algorithm3(&acc, floor, &cfg).unwrap();
    assert_eq!((c.class, c.rule, c.drivable), (TerrainClass::Floor, Rule::FloorBin, true));
    assert_eq!((c.bin, c.votes, c.max_votes, c.floor_votes), (Some(floor), 101, 250, 101));
    assert!(c.plane.unwrap().rho_x.abs() < 1e-12);
    // Exactly t_h · #PC is not enough (strict): then bin_max decides: a ramp at −45°, −45°,
    // whose tilt (54.7°) is not passable.
    acc.set_points(303);
    let c = algorithm3(&acc, floor, &cfg).unwrap();
    assert_eq!((c.class, c.rule), (TerrainClass::Ramp, Rule::PeakedMaximum));
    assert!(!c.passable && !c.drivable);
    assert!((c.tilt.to_degrees() - 54.7356).abs() < 1e-3, "{}", c.tilt.to_degrees());
}

#[test]
fn peaked_maximum_types() {
    let (mut acc, floor, cfg) = setup();
    let cases = [
        // (bin, class, passable, step)
        (Bin { id: floor.id - 3, ..floor }, TerrainClass::Plateau, false, 0.3),
        (Bin { id: floor.id - 2, ..floor }, TerrainClass::Plateau, true, 0.2),
        (Bin { id: floor.id + 1, ..floor }, TerrainClass::Canyon, true, -0.1),
        (Bin { id: floor.id + 5, ..floor }, TerrainClass::Canyon, false, -0.5),
        (Bin { id: floor.id, ..floor }, TerrainClass::Floor, true, 0.0),
        // ρx = −30° (uphill ahead), ρy = 0: tilt 30° ≤ 35°.
        (Bin { ix: floor.ix - 2, ..floor }, TerrainClass::Ramp, true, 0.0),
        // ρx = −45°: too steep.
        (Bin { ix: floor.ix - 3, ..floor }, TerrainClass::Ramp, false, 0.0),
        // ρx = 15°, ρy = 30°: tilt atan √(tan²15 + tan²30) ≈ 32.1°.
        (Bin { ix: floor.ix + 1, iy: floor.iy + 2, id: 3 }, TerrainClass::Ramp, true, 0.0),
    ];
    for (bin, class, passable, step) in cases {
        acc.clear();
        acc.set_points(1000);
        acc.add(bin, 250); // > 1000/5, and only 1 high bin
        for k in 0..5 {
            acc.add(Bin { id: k, ..floor }, 100); // low bins (100 < 2/3 · 250)
        }
        let c = algorithm3(&acc, floor, &cfg).unwrap();
        assert_eq!(c.rule, Rule::PeakedMaximum);
        assert_eq!((c.class, c.passable, c.drivable), (class, passable, passable), "{bin:?}");
        assert!((c.step - step).abs() < 1e-9, "{bin:?}: {}", c.step);
        assert_eq!(c.bin, Some(bin));
        assert_eq!(c.high_bins, 1);
    }
}

#[test]
fn not_peaked_is_obstacle() {
    let (mut acc, floor, cfg) = setup();
    acc.set_points(1000);
    // t_n − 1 = 6 bins above 2/3 of the maximum: still peaked.
    for k in 0..6 {
        acc.add(Bin { id: k, ..floor }, 300 - k as u32);
    }
    let c = algorithm3(&acc, floor, &cfg).unwrap();
    assert_eq!((c.rule, c.high_bins), (Rule::PeakedMaximum, 6));
    // bin_max is the nearest distance bin at the floor's angles: a (high) plateau.
    assert_eq!((c.class, c.bin), (TerrainClass::Plateau, Some(Bin { id: 0, ..floor })));
    // The 7th makes it an obstacle.
    acc.add(Bin { id: 20, ..floor }, 201);
    let c = algorithm3(&acc, floor, &cfg).unwrap();
    assert_eq!(
        (c.class, c.rule, c.high_bins, c.drivable),
        (TerrainClass::Obstacle, Rule::NotPeaked, 7, false)
    );
    // A bin at exactly 2/3 of the maximum is not "high" (strict).
    acc.clear();
    acc.set_points(1000);
    acc.add(Bin { id: 0, ..floor }, 300);
    for k in 1..10 {
        acc.add(Bin { id: k, ..floor }, 200);
    }
    let c = algorithm3(&acc, floor, &cfg).unwrap();
    assert_eq!((c.rule, c.high_bins), (Rule::PeakedMaximum, 1));
}

#[test]
fn weak_maximum_and_no_votes_are_obstacles() {
    let (mut acc, floor, cfg) = setup();
    acc.set_points(1000);
    acc.add(Bin { id: 3, ..floor }, 200); // = t_p · #PC, not more
    let c = algorithm3(&acc, floor, &cfg).unwrap();
    assert_eq!((c.class, c.rule), (TerrainClass::Obstacle, Rule::WeakMaximum));
    assert_eq!(c.max_votes, 200);
    acc.add(Bin { id: 3, ..floor }, 1);
    assert_eq!(algorithm3(&acc, floor, &cfg).unwrap().class, TerrainClass::Plateau);
    acc.clear();
    acc.set_points(50);
    let c = algorithm3(&acc, floor, &cfg).unwrap();
    assert_eq!(
        (c.class, c.rule, c.plane, c.drivable),
        (TerrainClass::Obstacle, Rule::NoVotes, None, false)
    );
}

#[test]
fn floor_bin_outside_the_space_is_an_error() {
    let (acc, floor, cfg) = setup();
    assert!(algorithm3(&acc, Bin { id: 30, ..floor }, &cfg).is_err());
    assert!(algorithm3(&acc, Bin { ix: 5, ..floor }, &cfg).is_err());
}
