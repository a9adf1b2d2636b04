//! Explored volume (thesis §6.1.1): the rasteriser against a brute force that tests every
//! cell centre with the same predicate, set operations against sets, roadmaps, the congruence
//! table of Tables 6.2–6.5, and the errors.

use std::collections::BTreeSet;

use patch_core::{Aabb, Point3, Real, Vector3};
use petgraph::graph::UnGraph;
use proptest::prelude::*;
use roadmap::Roadmap;
use roadmap::volume::{CongruenceTable, VolumeError, VoxelGrid, capsule_contains_point};

type Cell = (u32, u32, u32);
type Capsule = (Point3, Point3, Real);

/// Every cell whose centre is inside one of the capsules: the definition, voxel by voxel.
fn brute(grid: &VoxelGrid, capsules: &[Capsule]) -> BTreeSet<Cell> {
    let n = grid.cells_per_axis();
    let mut set = BTreeSet::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let c = grid.cell_center(i, j, k);
                if capsules.iter().any(|(a, b, r)| capsule_contains_point(&c, a, b, *r)) {
                    set.insert((i, j, k));
                }
            }
        }
    }
    set
}

/// The grid's cells, checked for consistency of `iter`, `contains` and `count`.
fn cells(grid: &VoxelGrid) -> BTreeSet<Cell> {
    let set: BTreeSet<Cell> = grid.iter().collect();
    assert_eq!(set.len() as u64, grid.count(), "iter and count agree");
    assert_eq!(grid.iter().count() as u64, grid.count(), "iter yields each cell once");
    assert!(set.iter().all(|&(i, j, k)| grid.contains(i, j, k)), "contains what iter yields");
    set
}

/// A capsule described relative to the grid, so that special positions are reachable.
#[derive(Clone, Debug)]
struct Spec {
    /// Start: 0 anywhere around the grid, 1 on a cell centre.
    a_mode: u8,
    a_frac: [Real; 3],
    a_cell: [u32; 3],
    /// End: 0 anywhere, 1 equal to the start, 2 axis-aligned from the start, 3 on a centre.
    b_mode: u8,
    b_frac: [Real; 3],
    b_cell: [u32; 3],
    axis: usize,
    /// Axis-aligned length: a fraction of the side, or whole cells if `len_cells`.
    len: Real,
    len_cells: i32,
    /// Radius: 0 zero, 1 tiny, 2 whole cells, 3 general, 4 huge.
    r_mode: u8,
    r_frac: Real,
    r_cells: u32,
}

fn spec() -> impl Strategy<Value = Spec> {
    let frac = || prop::array::uniform3(-0.3..1.3f64);
    let cell = || prop::array::uniform3(0u32..64);
    (
        (0u8..2, frac(), cell()),
        (0u8..4, frac(), cell(), 0usize..3, -1.0..1.0f64, -12i32..12),
        (0u8..5, 0.0..1.0f64, 0u32..8),
    )
        .prop_map(|((a_mode, a_frac, a_cell), b, (r_mode, r_frac, r_cells))| Spec {
            a_mode,
            a_frac,
            a_cell,
            b_mode: b.0,
            b_frac: b.1,
            b_cell: b.2,
            axis: b.3,
            len: b.4,
            len_cells: b.5,
            r_mode,
            r_frac,
            r_cells,
        })
}

impl Spec {
    fn capsule(&self, grid: &VoxelGrid) -> Capsule {
        let n = grid.cells_per_axis();
        let h = grid.cell_size();
        let side = h * Real::from(n);
        let anywhere = |f: [Real; 3]| grid.min() + Vector3::from(f) * side;
        let centre = |c: [u32; 3]| grid.cell_center(c[0] % n, c[1] % n, c[2] % n);
        let a = if self.a_mode == 0 { anywhere(self.a_frac) } else { centre(self.a_cell) };
        let b = match self.b_mode {
            0 => anywhere(self.b_frac),
            1 => a,
            2 => {
                let mut b = a;
                b[self.axis] += if self.len_cells % 2 == 0 {
                    self.len * side
                } else {
                    Real::from(self.len_cells) * h
                };
                b
            }
            _ => centre(self.b_cell),
        };
        let r = match self.r_mode {
            0 => 0.0,
            1 => self.r_frac * 0.5 * h,
            2 => Real::from(self.r_cells) * h,
            3 => self.r_frac * 0.5 * side,
            _ => (1.0 + 2.0 * self.r_frac) * side,
        };
        (a, b, r)
    }
}

/// A grid over a random box (one axis possibly flat), `N` in `4..=max_n`.
fn grid(max_n: u32) -> impl Strategy<Value = VoxelGrid> {
    (
        prop::array::uniform3(-5.0..5.0f64),
        prop::array::uniform3(0.0..3.0f64),
        0usize..4,
        4u32..=max_n,
    )
        .prop_map(|(min, ext, flat, n)| {
            let mut ext = Vector3::from(ext).add_scalar(0.05);
            if flat < 3 {
                ext[flat] = 0.0;
            }
            let min = Point3::from(min);
            VoxelGrid::new(min, min + ext, n).unwrap()
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// Each capsule alone, and all of them added to one grid, give exactly the brute-force
    /// voxels.
    #[test]
    fn capsules_match_brute_force(grid in grid(32), specs in prop::collection::vec(spec(), 1..4)) {
        let capsules: Vec<Capsule> = specs.iter().map(|s| s.capsule(&grid)).collect();
        let mut all = grid.empty_like();
        for c in &capsules {
            let mut one = grid.empty_like();
            one.add_capsule(c.0, c.1, c.2).unwrap();
            prop_assert_eq!(cells(&one), brute(&grid, std::slice::from_ref(c)), "capsule {:?}", c);
            all.add_capsule(c.0, c.1, c.2).unwrap();
        }
        prop_assert_eq!(cells(&all), brute(&grid, &capsules));
    }

    /// `union_with` and `count_not_in` agree with set union and set difference; the volume is
    /// count · cell³.
    #[test]
    fn set_operations_match_sets(
        grid in grid(24),
        specs_a in prop::collection::vec(spec(), 0..3),
        specs_b in prop::collection::vec(spec(), 0..3),
    ) {
        let mut a = grid.empty_like();
        let mut b = grid.empty_like();
        for s in &specs_a {
            let (p, q, r) = s.capsule(&grid);
            a.add_capsule(p, q, r).unwrap();
        }
        for s in &specs_b {
            let (p, q, r) = s.capsule(&grid);
            b.add_capsule(p, q, r).unwrap();
        }
        let (sa, sb) = (cells(&a), cells(&b));
        prop_assert_eq!(a.count_not_in(&b).unwrap(), sa.difference(&sb).count() as u64);
        prop_assert_eq!(b.count_not_in(&a).unwrap(), sb.difference(&sa).count() as u64);
        prop_assert_eq!(a.count_not_in(&a).unwrap(), 0);
        let h3 = grid.cell_size().powi(3);
        prop_assert_eq!(a.volume(), sa.len() as Real * h3);
        let mut u = a.clone();
        u.union_with(&b).unwrap();
        prop_assert_eq!(cells(&u), sa.union(&sb).copied().collect::<BTreeSet<_>>());
        prop_assert_eq!(u.count_not_in(&a).unwrap(), sb.difference(&sa).count() as u64);
    }

    /// A roadmap is the union of its edges' capsules and its vertices' spheres, isolated
    /// vertices included.
    #[test]
    fn roadmap_is_union_of_edges_and_vertices(
        grid in grid(16),
        points in prop::collection::vec(prop::array::uniform3(-0.2..1.2f64), 1..8),
        edges in prop::collection::vec((0usize..8, 0usize..8), 0..8),
        r_frac in 0.0..0.2f64,
    ) {
        let side = grid.cell_size() * Real::from(grid.cells_per_axis());
        let r = r_frac * side;
        let mut roadmap = Roadmap::default();
        let nodes: Vec<_> = points
            .iter()
            .map(|f| roadmap.add_node(grid.min() + Vector3::from(*f) * side))
            .collect();
        for (u, v) in edges {
            let (u, v) = (nodes[u % nodes.len()], nodes[v % nodes.len()]);
            let length = (roadmap[u] - roadmap[v]).norm();
            roadmap.add_edge(u, v, length);
        }
        let mut shapes: Vec<Capsule> = roadmap.node_weights().map(|p| (*p, *p, r)).collect();
        shapes.extend(roadmap.edge_indices().map(|e| {
            let (u, v) = roadmap.edge_endpoints(e).unwrap();
            (roadmap[u], roadmap[v], r)
        }));
        let mut g = grid.empty_like();
        g.add_roadmap(&roadmap, r).unwrap();
        prop_assert_eq!(cells(&g), brute(&grid, &shapes));
    }
}

/// Axis-aligned segments whose ends lie on cell centres, radii of whole cells: every centre
/// at distance exactly `r` from the axis is a tie.
#[test]
fn axis_aligned_segments_on_centres_match_brute_force() {
    let grid = VoxelGrid::new(Point3::new(-1.0, 0.5, 2.0), Point3::new(1.4, 2.9, 4.4), 24).unwrap();
    let h = grid.cell_size();
    for axis in 0..3 {
        for cells_r in 0..5 {
            let a = grid.cell_center(5, 7, 9);
            let mut b = a;
            b[axis] += 9.0 * h;
            let r = Real::from(cells_r) * h;
            let mut g = grid.empty_like();
            g.add_capsule(a, b, r).unwrap();
            assert_eq!(cells(&g), brute(&grid, &[(a, b, r)]), "axis {axis}, r = {cells_r} cells");
        }
    }
}

/// A radius-0 segment between two centres of one row holds exactly the centres between them:
/// every one is a tie that only an exact predicate decides consistently.
#[test]
fn zero_radius_segment_through_centres_is_exact() {
    let grid =
        VoxelGrid::new(Point3::new(1.844, 0.0, -0.3), Point3::new(2.9, 0.7, 0.1), 20).unwrap();
    let (a, b) = (grid.cell_center(3, 11, 4), grid.cell_center(15, 11, 4));
    let mut g = grid.empty_like();
    g.add_capsule(a, b, 0.0).unwrap();
    let expected: BTreeSet<Cell> = (3..=15).map(|i| (i, 11, 4)).collect();
    assert_eq!(cells(&g), expected);
    assert_eq!(brute(&grid, &[(a, b, 0.0)]), expected);
    // Reversed ends, and a capsule whose radius reaches the neighbouring rows exactly.
    let mut r = grid.empty_like();
    r.add_capsule(b, a, 0.0).unwrap();
    assert_eq!(cells(&r), expected);
    let h = grid.cell_size();
    let mut w = grid.empty_like();
    w.add_capsule(a, b, h).unwrap();
    assert_eq!(cells(&w), brute(&grid, &[(a, b, h)]));
}

/// Found by `capsules_match_brute_force` (before the predicate was exact): a radius-0 segment
/// along a row, partly left of the grid, lost one centre to rounding of `t`.
#[test]
fn regression_zero_radius_row_partly_outside() {
    let min = Point3::new(1.844531113801734, 0.0, 0.0);
    let grid = VoxelGrid::new(min, min + Vector3::new(0.0, 0.05, 0.05), 27).unwrap();
    let a = grid.cell_center(3, 0, 0);
    let b = a - Vector3::new(5.0 * grid.cell_size(), 0.0, 0.0);
    let mut g = grid.empty_like();
    g.add_capsule(a, b, 0.0).unwrap();
    assert_eq!(cells(&g), (0..=3).map(|i| (i, 0, 0)).collect::<BTreeSet<Cell>>());
    assert_eq!(cells(&g), brute(&grid, &[(a, b, 0.0)]));
}

/// The predicate decides ties for the exact values of its floating-point inputs, where a
/// floating-point evaluation rounds to a tie.
#[test]
fn predicate_is_exact_on_ties() {
    let o = Point3::origin();
    let b = Point3::new(1.0, 3.0, 0.0);
    // 0.1 · 3 rounds to 0.30000000000000004, so the cross product rounds to 0, but the point is
    // off the line; (0.5, 1.5, 0) is on it.
    assert!(!capsule_contains_point(&Point3::new(0.1, 0.1 * 3.0, 0.0), &o, &b, 0.0));
    assert!(capsule_contains_point(&Point3::new(0.5, 1.5, 0.0), &o, &b, 0.0));
    // 0.3² + 0.4² exceeds 0.25 by 1.1e-17 for the doubles nearest 0.3 and 0.4.
    assert!(!capsule_contains_point(&Point3::new(0.3, 0.4, 0.0), &o, &o, 0.5));
    assert!(capsule_contains_point(&Point3::new(0.0, 0.5, 0.0), &o, &o, 0.5));
    assert!(capsule_contains_point(&Point3::new(0.5, 0.0, 0.0), &o, &b, 0.5));
    // Ends of the parameter range are covered by the end spheres, not the cylinder.
    assert!(capsule_contains_point(&b, &o, &b, 0.0));
    assert!(!capsule_contains_point(&Point3::new(2.0, 6.0, 0.0), &o, &b, 0.0));
}

/// Far from the origin (UTM-like coordinates), with shapes snapped to centres and not.
#[test]
fn offset_grid_matches_brute_force() {
    let min = Point3::new(512_345.678, 5_123_456.789, 42.0);
    let grid = VoxelGrid::new(min, min + Vector3::new(0.32, 0.2, 0.1), 32).unwrap();
    let h = grid.cell_size();
    let capsules = [
        (grid.cell_center(3, 4, 5), grid.cell_center(20, 4, 5), 3.0 * h),
        (min + Vector3::new(0.05, 0.11, 0.02), min + Vector3::new(0.29, 0.03, 0.3), 0.04),
        (grid.cell_center(10, 10, 10), grid.cell_center(10, 10, 10), 5.0 * h),
        (grid.cell_center(1, 2, 3), grid.cell_center(25, 20, 15), 0.0),
    ];
    for c in capsules {
        let mut g = grid.empty_like();
        g.add_capsule(c.0, c.1, c.2).unwrap();
        assert_eq!(cells(&g), brute(&grid, &[c]), "{c:?}");
    }
}

/// A zero radius on a centre is exactly that voxel; a sphere and a capsule approximate their
/// volumes.
#[test]
fn single_voxels_and_volumes() {
    let grid =
        VoxelGrid::new(Point3::new(-2.0, -2.0, -2.0), Point3::new(2.0, 2.0, 2.0), 64).unwrap();
    let mut g = grid.empty_like();
    g.add_sphere(grid.cell_center(3, 60, 17), 0.0).unwrap();
    assert_eq!(cells(&g), BTreeSet::from([(3, 60, 17)]));

    let mut s = grid.empty_like();
    s.add_sphere(Point3::new(0.1, -0.2, 0.05), 1.0).unwrap();
    let sphere = 4.0 / 3.0 * std::f64::consts::PI;
    assert!((s.volume() / sphere - 1.0).abs() < 0.02, "sphere {} vs {sphere}", s.volume());

    let mut c = grid.empty_like();
    c.add_capsule(Point3::new(-1.0, -0.5, 0.0), Point3::new(1.0, 0.5, 0.3), 0.5).unwrap();
    let (r, l) = (0.5, Vector3::new(2.0, 1.0, 0.3).norm());
    let capsule = std::f64::consts::PI * r * r * l + 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    assert!((c.volume() / capsule - 1.0).abs() < 0.02, "capsule {} vs {capsule}", c.volume());
}

/// Shapes outside the grid add nothing; cells outside are never reported.
#[test]
fn shapes_are_clipped_to_the_grid() {
    let grid = VoxelGrid::new(Point3::origin(), Point3::new(1.0, 1.0, 1.0), 16).unwrap();
    let mut g = grid.empty_like();
    g.add_capsule(Point3::new(3.0, 3.0, 3.0), Point3::new(5.0, 3.0, 3.0), 1.0).unwrap();
    assert!(g.is_empty());
    assert_eq!(g.count(), 0);
    g.add_sphere(Point3::new(1.0, 1.0, 1.0), 0.3).unwrap();
    assert_eq!(
        cells(&g),
        brute(&grid, &[(Point3::new(1.0, 1.0, 1.0), Point3::new(1.0, 1.0, 1.0), 0.3)])
    );
    assert!(!g.contains(16, 15, 15));
    // A radius covering everything fills the grid.
    g.add_sphere(Point3::new(0.5, 0.5, 0.5), 10.0).unwrap();
    assert_eq!(g.count(), 16 * 16 * 16);
}

/// The largest grid is sparse: a sphere in 65536³ cells costs kilobytes.
#[test]
fn huge_grid_is_sparse() {
    let mut g = VoxelGrid::new(Point3::origin(), Point3::new(655.36, 1.0, 1.0), 65536).unwrap();
    assert!((g.cell_size() - 0.01).abs() < 1e-12);
    g.add_sphere(Point3::new(300.0, 0.5, 0.5), 0.1).unwrap();
    assert!(g.count() > 4000);
    assert!(g.memory_bytes() < 1 << 20, "{} bytes", g.memory_bytes());
}

#[test]
fn covering_lattice_and_empty_like() {
    let boxes = [
        Aabb::new(Point3::new(0.0, 0.0, 0.0), Point3::new(2.0, 1.0, 1.0)),
        Aabb::new(Point3::new(-1.0, 0.5, 0.0), Point3::new(1.0, 3.0, 0.5)),
    ];
    let g = VoxelGrid::covering(boxes, 30).unwrap();
    assert_eq!(g.min(), Point3::new(-1.0, 0.0, 0.0));
    assert_eq!(g.cell_size(), 0.1);
    assert_eq!(g.cells_per_axis(), 30);
    assert_eq!(g.bounds().max, Point3::new(2.0, 3.0, 3.0));
    assert!(g.same_lattice(&g.empty_like()));
    let other = VoxelGrid::covering(boxes, 31).unwrap();
    assert!(!g.same_lattice(&other));
    let shifted =
        VoxelGrid::new(Point3::new(-1.0, 0.0, 1e-9), Point3::new(2.0, 3.0, 3.0), 30).unwrap();
    assert!(!g.same_lattice(&shifted));
}

#[test]
fn errors() {
    let o = Point3::origin();
    let one = Point3::new(1.0, 1.0, 1.0);
    let bad_bounds = [
        (o, Point3::new(Real::NAN, 1.0, 1.0)),
        (o, Point3::new(Real::INFINITY, 1.0, 1.0)),
        (Point3::new(0.0, 2.0, 0.0), one),
        (one, one),
    ];
    for (min, max) in bad_bounds {
        assert_eq!(
            VoxelGrid::new(min, max, 8).unwrap_err(),
            VolumeError::InvalidBounds,
            "{min} {max}"
        );
    }
    assert!(VoxelGrid::new(o, Point3::new(1.0, 0.0, 0.0), 8).is_ok(), "flat boxes are fine");
    assert_eq!(VoxelGrid::covering([], 8).unwrap_err(), VolumeError::InvalidBounds);
    assert_eq!(VoxelGrid::covering([Aabb::EMPTY], 8).unwrap_err(), VolumeError::InvalidBounds);
    for n in [0, VoxelGrid::MAX_CELLS_PER_AXIS + 1] {
        assert_eq!(
            VoxelGrid::new(o, one, n).unwrap_err(),
            VolumeError::InvalidCellsPerAxis { cells_per_axis: n }
        );
    }

    let mut g = VoxelGrid::new(o, one, 8).unwrap();
    g.add_sphere(Point3::new(0.5, 0.5, 0.5), 0.2).unwrap();
    let before = cells(&g);
    for r in [-0.1, Real::NAN, Real::INFINITY, 1e200] {
        assert!(matches!(g.add_capsule(o, one, r), Err(VolumeError::InvalidRadius { .. })), "{r}");
    }
    let nan = Point3::new(Real::NAN, 0.0, 0.0);
    assert_eq!(g.add_capsule(o, nan, 0.1), Err(VolumeError::InvalidPoint));
    assert_eq!(g.add_sphere(nan, 0.1), Err(VolumeError::InvalidPoint));
    let far = Point3::new(2e30, 0.0, 0.0);
    assert_eq!(g.add_capsule(o, far, 0.1), Err(VolumeError::InvalidPoint));

    let mut roadmap: Roadmap = UnGraph::default();
    let u = roadmap.add_node(Point3::new(0.5, 0.5, 0.5));
    let v = roadmap.add_node(nan);
    roadmap.add_edge(u, v, 1.0);
    assert_eq!(g.add_roadmap(&roadmap, 0.1), Err(VolumeError::InvalidPoint));
    assert!(matches!(
        g.add_roadmap(&Roadmap::default(), -1.0),
        Err(VolumeError::InvalidRadius { .. })
    ));
    assert_eq!(cells(&g), before, "unchanged after errors");

    let other = VoxelGrid::new(o, one, 9).unwrap();
    assert_eq!(g.union_with(&other), Err(VolumeError::LatticeMismatch));
    assert_eq!(g.count_not_in(&other), Err(VolumeError::LatticeMismatch));
    assert_eq!(
        CongruenceTable::new([("a", &g), ("b", &other)]).unwrap_err(),
        VolumeError::LatticeMismatch
    );
    assert_eq!(cells(&g), before, "unchanged after errors");
}

/// Hand-made maps with known percentages: each voxel is a zero-radius sphere on its centre.
#[test]
fn congruence_table_of_known_maps() {
    let grid = VoxelGrid::new(Point3::origin(), Point3::new(2.0, 2.0, 2.0), 8).unwrap();
    let with = |cells: &[Cell]| {
        let mut g = grid.empty_like();
        for &(i, j, k) in cells {
            g.add_sphere(grid.cell_center(i, j, k), 0.0).unwrap();
        }
        g
    };
    // planes: 4 voxels; hybrid: 8 voxels, 3 of them planes'; empty: none.
    let planes = with(&[(0, 0, 0), (1, 0, 0), (2, 0, 0), (7, 7, 7)]);
    let hybrid = with(&[
        (0, 0, 0),
        (1, 0, 0),
        (2, 0, 0),
        (0, 1, 0),
        (0, 2, 0),
        (0, 3, 0),
        (5, 5, 5),
        (6, 6, 6),
    ]);
    let empty = grid.empty_like();
    let table = CongruenceTable::new([("planes", &planes), ("hybrid", &hybrid), ("empty", &empty)])
        .unwrap();
    assert_eq!(table.len(), 3);
    assert_eq!(table.names(), ["planes", "hybrid", "empty"]);
    assert_eq!(table.count(0), 4);
    assert_eq!(table.volume(1), 8.0 * 0.25f64.powi(3));
    assert_eq!(table.count_not_in(0, 1), 1);
    assert_eq!(table.percent_not_in(0, 1), Some(25.0));
    assert_eq!(table.percent_not_in(1, 0), Some(62.5));
    assert_eq!(table.percent_not_in(0, 2), Some(100.0));
    assert_eq!(table.percent_not_in(2, 0), None, "nothing explored: undefined");
    assert_eq!(table.percent_not_in(1, 1), None, "diagonal");
    let expected = "\
| Map    | Volume [m³] | planes | hybrid | empty   |
| ------ | ----------- | ------ | ------ | ------- |
| planes | 0.062       | –      | 25.000 | 100.000 |
| hybrid | 0.125       | 62.500 | –      | 100.000 |
| empty  | 0.000       | n/a    | n/a    | –       |
";
    assert_eq!(table.to_string(), expected);
    assert!(format!("{table:.4}").contains("| 0.0625      | –       | 25.0000 | 100.0000 |"));
}

/// The lab-scale measurement of the issue: 10,000 random 1 m capsules of radius 0.3 m in a
/// 1024³ grid over a 12 × 9 × 4 m box. Run with
/// `cargo test --release -p patchnav-roadmap --test it volume:: -- --ignored --nocapture rasterise_lab`.
#[test]
#[ignore = "timing; run in release"]
fn rasterise_lab_scale_timing() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let mut grid = VoxelGrid::new(Point3::origin(), Point3::new(12.0, 9.0, 4.0), 1024).unwrap();
    let capsules: Vec<(Point3, Point3)> = (0..10_000)
        .map(|_| {
            let a = Point3::new(
                rng.random_range(0.0..12.0),
                rng.random_range(0.0..9.0),
                rng.random_range(0.0..4.0),
            );
            let dir = loop {
                let v = Vector3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                );
                if (1e-3..=1.0).contains(&v.norm()) {
                    break v.normalize();
                }
            };
            (a, a + dir)
        })
        .collect();
    let start = std::time::Instant::now();
    for (a, b) in &capsules {
        grid.add_capsule(*a, *b, 0.3).unwrap();
    }
    let elapsed = start.elapsed();
    let count_start = std::time::Instant::now();
    let count = grid.count();
    let count_time = count_start.elapsed();
    let other = grid.clone();
    let diff_start = std::time::Instant::now();
    assert_eq!(grid.count_not_in(&other).unwrap(), 0);
    let diff_time = diff_start.elapsed();
    println!(
        "10,000 capsules (1 m, r = 0.3 m), 1024³ over 12 × 9 × 4 m (cell {:.2} mm): {:.3} s \
         ({:.1} µs/capsule); {} voxels = {:.3} m³; {} bricks, {:.1} MiB; count {:.1} ms, \
         count_not_in {:.1} ms",
        grid.cell_size() * 1e3,
        elapsed.as_secs_f64(),
        elapsed.as_secs_f64() * 1e6 / 1e4,
        count,
        grid.volume(),
        grid.brick_count(),
        grid.memory_bytes() as f64 / (1 << 20) as f64,
        count_time.as_secs_f64() * 1e3,
        diff_time.as_secs_f64() * 1e3,
    );
}
