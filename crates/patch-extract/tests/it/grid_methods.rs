//! Naive triangulation, scan-line polygons and chain-code outlines on hand-made regions and
//! random pixel blobs.

use std::collections::HashSet;

use geo::{Area as _, BooleanOps as _};
use patch_core::Point3;
use patch_extract::chain_code::{chain_code_outlines, outline_mask};
use patch_extract::grid_mesh::{GridError, GridMesh, RegionMask, naive_triangulation};
use patch_extract::scanline::{ScanLineVersion, scan_line};
use pointcloud::PointCloud;
use proptest::prelude::*;

/// A flat organised cloud whose point of pixel `(c, r)` is `(c, r, 5)`, so 3D areas equal pixel
/// areas.
fn flat_cloud(w: u32, h: u32) -> PointCloud {
    PointCloud::from_pixels(
        w,
        h,
        (0..h).flat_map(|r| (0..w).map(move |c| Some(Point3::new(c as f64, r as f64, 5.0)))),
    )
    .unwrap()
}

fn mask_from_rows(rows: &[&str]) -> RegionMask {
    let h = rows.len() as u32;
    let w = rows[0].len() as u32;
    let flags = rows.iter().flat_map(|r| r.chars().map(|ch| ch == 'X')).collect();
    RegionMask::new(w, h, flags).unwrap()
}

fn tri_polygon(mesh: &GridMesh, t: &[u32; 3]) -> geo::Polygon<f64> {
    let pts: Vec<(f64, f64)> = t
        .iter()
        .map(|&i| (mesh.pixels[i as usize][0] as f64, mesh.pixels[i as usize][1] as f64))
        .collect();
    let mut pts = pts;
    let twice = (pts[1].0 - pts[0].0) * (pts[2].1 - pts[0].1)
        - (pts[1].1 - pts[0].1) * (pts[2].0 - pts[0].0);
    if twice < 0.0 {
        pts.reverse();
    }
    geo::Polygon::new(geo::LineString::from(pts), vec![])
}

fn union(mesh: &GridMesh) -> geo::MultiPolygon<f64> {
    let polys: Vec<geo::Polygon<f64>> =
        mesh.triangles.iter().map(|t| tri_polygon(mesh, t)).collect();
    geo::unary_union(&polys)
}

#[test]
fn naive_full_region_has_two_triangles_per_quad() {
    for (w, h) in [(2, 2), (5, 3), (17, 9)] {
        let cloud = flat_cloud(w, h);
        let mesh =
            naive_triangulation(&cloud, &RegionMask::all_valid(cloud.grid().unwrap())).unwrap();
        assert_eq!(mesh.triangles.len(), 2 * (w as usize - 1) * (h as usize - 1));
        assert_eq!(mesh.stats.triangles, mesh.triangles.len());
        assert_eq!(mesh.stats.vertices, (w * h) as usize);
        assert!((mesh.pixel_area() - ((w - 1) * (h - 1)) as f64).abs() < 1e-9);
        assert!((mesh.stats.spikyness_mean - std::f64::consts::PI.powi(2) / 24.0).abs() < 1e-9);
    }
}

#[test]
fn naive_three_valid_pixels_give_one_triangle() {
    let mesh = naive_triangulation(&flat_cloud(2, 2), &mask_from_rows(&["XX", ".X"])).unwrap();
    assert_eq!(mesh.triangles.len(), 1);
    assert!((mesh.pixel_area() - 0.5).abs() < 1e-12);
}

#[test]
fn bad_inputs_are_typed_errors() {
    let cloud = flat_cloud(3, 3);
    let wrong = RegionMask::new(2, 2, vec![true; 4]).unwrap();
    assert!(matches!(naive_triangulation(&cloud, &wrong), Err(GridError::MaskSize { .. })));
    assert!(matches!(
        scan_line(&cloud, &wrong, ScanLineVersion::V1),
        Err(GridError::MaskSize { .. })
    ));
    let unorganised = PointCloud::from_positions(vec![Point3::origin()]).unwrap();
    let m = RegionMask::new(3, 3, vec![true; 9]).unwrap();
    assert_eq!(naive_triangulation(&unorganised, &m), Err(GridError::NoGrid));
    assert_eq!(chain_code_outlines(&unorganised, &m), Err(GridError::NoGrid));
    assert!(matches!(RegionMask::new(3, 3, vec![true; 8]), Err(GridError::MaskSize { .. })));
}

#[test]
fn scanline_rectangle_is_one_polygon_of_two_triangles() {
    let cloud = flat_cloud(12, 8);
    let mask = mask_from_rows(&[
        "............",
        "..XXXXXXX...",
        "..XXXXXXX...",
        "..XXXXXXX...",
        "..XXXXXXX...",
        "............",
        "............",
        "............",
    ]);
    for v in [ScanLineVersion::V1, ScanLineVersion::V2] {
        let s = scan_line(&cloud, &mask, v).unwrap();
        assert_eq!(s.polygons.len(), 1, "{v:?}");
        assert_eq!(s.mesh.triangles.len(), 2, "{v:?}");
        assert_eq!(s.mesh.stats.polygons, 1);
        assert!((s.mesh.pixel_area() - 18.0).abs() < 1e-12);
    }
}

#[test]
fn scanline_l_shape_needs_few_polygons() {
    let cloud = flat_cloud(10, 8);
    let mask = mask_from_rows(&[
        "XXX.......",
        "XXX.......",
        "XXX.......",
        "XXXXXXXXX.",
        "XXXXXXXXX.",
        "..........",
        "..........",
        "..........",
    ]);
    let naive = naive_triangulation(&cloud, &mask).unwrap();
    for v in [ScanLineVersion::V1, ScanLineVersion::V2] {
        let s = scan_line(&cloud, &mask, v).unwrap();
        assert!(s.polygons.len() <= 3, "{v:?}: {:?}", s.polygons);
        assert!(s.mesh.triangles.len() <= 8, "{v:?}: {}", s.mesh.triangles.len());
        if v == ScanLineVersion::V1 {
            assert!((s.mesh.pixel_area() - naive.pixel_area()).abs() < 1e-9);
        } else {
            assert!(s.mesh.pixel_area() > naive.pixel_area());
        }
    }
}

#[test]
fn scanline_v2_needs_fewer_triangles_on_a_staircase() {
    // Fig 5.10: a steep diagonal outline; V1 follows the staircase, V2 cuts across it.
    let rows = ["XXXXXXXXXX", "XXXXXXX...", "XXXX......", "X........."];
    let cloud = flat_cloud(10, 4);
    let mask = mask_from_rows(&rows);
    let v1 = scan_line(&cloud, &mask, ScanLineVersion::V1).unwrap();
    let v2 = scan_line(&cloud, &mask, ScanLineVersion::V2).unwrap();
    assert!(
        v2.mesh.triangles.len() < v1.mesh.triangles.len(),
        "{} {}",
        v1.mesh.triangles.len(),
        v2.mesh.triangles.len()
    );
    assert_eq!(v2.polygons.len(), 1);
    let naive = naive_triangulation(&cloud, &mask).unwrap();
    assert!((v1.mesh.pixel_area() - naive.pixel_area()).abs() < 1e-9);
    assert!(v2.mesh.pixel_area() > naive.pixel_area());
}

#[test]
fn chain_code_of_a_square_with_a_hole() {
    let mask = mask_from_rows(&["XXXX", "X..X", "XXXX"]);
    let outlines = outline_mask(&mask);
    assert_eq!(outlines.len(), 1);
    let o = &outlines[0];
    assert_eq!(o.outer.vertices.len(), 4);
    assert_eq!(o.outer.signed_area, 12.0);
    assert_eq!(o.holes.len(), 1);
    assert_eq!(o.holes[0].signed_area, -2.0);
    assert_eq!(o.pixels, 10);
    assert_eq!(o.outer.code.len(), 14);
    assert_eq!(o.outer.vertices[0], [-0.5, -0.5]);
}

#[test]
fn chain_code_splits_pinches() {
    // Diagonal neighbours are separate components; a component touching itself at a corner
    // gets a hole that touches its outer ring.
    let outlines = outline_mask(&mask_from_rows(&["X.", ".X"]));
    assert_eq!(outlines.len(), 2);
    let outlines = outline_mask(&mask_from_rows(&["XX.", "X.X", "XXX"]));
    assert_eq!(outlines.len(), 1);
    assert_eq!(outlines[0].holes.len(), 1);
    assert_eq!(outlines[0].outer.signed_area + outlines[0].holes[0].signed_area, 7.0);
    for r in std::iter::once(&outlines[0].outer).chain(&outlines[0].holes) {
        assert_ring_simple(&r.vertices);
    }
}

/// No repeated vertex and no two non-adjacent edges meeting (axis-parallel rings).
fn assert_ring_simple(ring: &[[f64; 2]]) {
    let n = ring.len();
    assert!(n >= 4);
    let set: HashSet<(i64, i64)> =
        ring.iter().map(|p| ((p[0] * 2.0) as i64, (p[1] * 2.0) as i64)).collect();
    assert_eq!(set.len(), n, "repeated vertex in {ring:?}");
    let ls = geo::LineString::from(ring.iter().map(|p| (p[0], p[1])).collect::<Vec<_>>());
    let poly = geo::Polygon::new(ls, vec![]);
    use geo::Validation as _;
    assert!(poly.is_valid(), "{ring:?}");
}

fn blob_strategy() -> impl Strategy<Value = (u32, u32, Vec<bool>)> {
    (2u32..14, 2u32..12).prop_flat_map(|(w, h)| {
        (
            Just(w),
            Just(h),
            proptest::collection::vec(proptest::bool::weighted(0.7), (w * h) as usize),
        )
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn scanline_covers_the_naive_area_without_overlap((w, h, flags) in blob_strategy()) {
        let cloud = flat_cloud(w, h);
        let mask = RegionMask::new(w, h, flags).unwrap();
        let naive = naive_triangulation(&cloud, &mask).unwrap();
        let naive_union = union(&naive);
        for v in [ScanLineVersion::V1, ScanLineVersion::V2] {
            let s = scan_line(&cloud, &mask, v).unwrap();
            let sum = s.mesh.pixel_area();
            let u = union(&s.mesh);
            // No overlaps: the triangles' areas add up to their union's.
            prop_assert!((u.unsigned_area() - sum).abs() < 1e-6, "{v:?} overlap: {} vs {}", u.unsigned_area(), sum);
            // Every triangle is non-degenerate.
            prop_assert!(s.mesh.triangles.iter().all(|t| tri_polygon(&s.mesh, t).unsigned_area() > 1e-9));
            if v == ScanLineVersion::V1 {
                prop_assert!(u.xor(&naive_union).unsigned_area() < 1e-6, "V1 coverage differs");
            } else {
                // V2 covers the naive area and possibly more.
                prop_assert!(naive_union.difference(&u).unsigned_area() < 1e-6, "V2 misses naive area");
            }
            prop_assert!(s.polygons.len() <= naive.triangles.len());
        }
    }

    #[test]
    fn scanline_mesh_has_no_t_junctions((w, h, flags) in blob_strategy()) {
        let cloud = flat_cloud(w, h);
        let mask = RegionMask::new(w, h, flags).unwrap();
        for v in [ScanLineVersion::V1, ScanLineVersion::V2] {
            let s = scan_line(&cloud, &mask, v).unwrap();
            let verts: Vec<(i64, i64)> = s.mesh.pixels.iter().map(|p| (p[0] as i64, p[1] as i64)).collect();
            let used: HashSet<u32> = s.mesh.triangles.iter().flatten().copied().collect();
            for t in &s.mesh.triangles {
                for k in 0..3 {
                    let (a, b) = (verts[t[k] as usize], verts[t[(k + 1) % 3] as usize]);
                    for &vi in &used {
                        let p = verts[vi as usize];
                        if p == a || p == b { continue; }
                        let cross = (b.0 - a.0) * (p.1 - a.1) - (b.1 - a.1) * (p.0 - a.0);
                        let within = (p.0 - a.0) * (p.0 - b.0) <= 0 && (p.1 - a.1) * (p.1 - b.1) <= 0;
                        prop_assert!(!(cross == 0 && within), "{v:?}: vertex {p:?} inside edge {a:?}-{b:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn chain_code_rings_are_simple_and_add_up((w, h, flags) in blob_strategy()) {
        let mask = RegionMask::new(w, h, flags).unwrap();
        let outlines = outline_mask(&mask);
        let mut total = 0.0;
        for o in &outlines {
            let sum: f64 = o.outer.signed_area + o.holes.iter().map(|r| r.signed_area).sum::<f64>();
            prop_assert_eq!(sum, o.pixels as f64);
            prop_assert!(o.outer.signed_area > 0.0);
            prop_assert!(o.holes.iter().all(|h| h.signed_area < 0.0));
            assert_ring_simple(&o.outer.vertices);
            for hole in &o.holes {
                assert_ring_simple(&hole.vertices);
            }
            // The vertex shoelace agrees with the crack-code area.
            let shoelace = |r: &[[f64; 2]]| -> f64 {
                (0..r.len()).map(|k| { let (p, q) = (r[k], r[(k + 1) % r.len()]); p[0] * q[1] - q[0] * p[1] }).sum::<f64>() / 2.0
            };
            prop_assert!((shoelace(&o.outer.vertices) - o.outer.signed_area).abs() < 1e-9);
            // The polygon is a valid polygon with holes (holes may touch the outer ring in a
            // vertex).
            let poly = geo::Polygon::new(
                geo::LineString::from(o.outer.vertices.iter().map(|p| (p[0], p[1])).collect::<Vec<_>>()),
                o.holes.iter().map(|h| geo::LineString::from(h.vertices.iter().map(|p| (p[0], p[1])).collect::<Vec<_>>())).collect(),
            );
            prop_assert!((poly.unsigned_area() - o.pixels as f64).abs() < 1e-9);
            total += o.pixels as f64;
        }
        prop_assert_eq!(total as usize, mask.count());
    }
}

/// The survey benchmark (thesis Figs 5.12–5.14) on simulated scans of the lab: per method the
/// time, polygon and triangle counts and mean spikyness, with scene-sim surface labels as the
/// regions (regions of at least 30 pixels). Run with
/// `cargo test --release -p patch-extract --test it grid_methods::survey_benchmark -- --ignored --nocapture`.
#[test]
#[ignore = "benchmark; run in release with --nocapture"]
fn survey_benchmark() {
    use patch_extract::quality::{MeshStats, spikyness_2d};
    use patch_extract::trimesh_grow::{TrimeshGrowConfig, grow_trimeshes};
    use scene_sim::{Alrf, AlrfConfig, RangeCamera, RangeSensor};
    use std::time::Instant;

    let scene = scene_sim::scene_by_name("lab", 1).unwrap();
    let alrf = Alrf::new(AlrfConfig::sick_s300_with_step(1f64.to_radians()).unwrap()).unwrap();
    let alrf_full = Alrf::sick_s300();
    let camera = RangeCamera::swissranger_sr3000();
    let sensors: [(&str, &dyn RangeSensor, f64, TrimeshGrowConfig); 3] = [
        ("ALRF 1° (271×181)", &alrf, 0.5, TrimeshGrowConfig::alrf()),
        ("ALRF 0.5° (541×361)", &alrf_full, 0.5, TrimeshGrowConfig::alrf()),
        ("SR-3000 (176×144)", &camera, 1.0, TrimeshGrowConfig::range_camera()),
    ];
    for (name, sensor, height, grow_config) in sensors {
        let poses = scene.scan_poses(3, height, 11);
        let mut rows: Vec<(&str, f64, MeshStats, usize)> = Vec::new();
        let mut add = |method: &'static str, secs: f64, stats: MeshStats, failures: usize| {
            if let Some(r) = rows.iter_mut().find(|r| r.0 == method) {
                r.1 += secs;
                r.2 = r.2.combine(&stats);
                r.3 += failures;
            } else {
                rows.push((method, secs, stats, failures));
            }
        };
        let mut regions_total = 0;
        let mut pixels_total = 0;
        for (k, body) in poses.iter().enumerate() {
            let scan = sensor.scan(&scene, &sensor.mount(body), 100 + k as u64);
            let cloud = scan.to_cloud().unwrap();
            let grid = cloud.grid().unwrap();
            let labels = cloud.labels().unwrap();
            let mut ids: Vec<u32> = labels.to_vec();
            ids.sort_unstable();
            ids.dedup();
            let masks: Vec<RegionMask> = ids
                .iter()
                .filter(|&&l| l != u32::MAX)
                .map(|&l| RegionMask::from_label(&cloud, grid, l))
                .filter(|m| m.count() >= 30)
                .collect();
            regions_total += masks.len();
            pixels_total += masks.iter().map(RegionMask::count).sum::<usize>();

            let t = Instant::now();
            let naive: Vec<_> =
                masks.iter().map(|m| naive_triangulation(&cloud, m).unwrap()).collect();
            let secs = t.elapsed().as_secs_f64();
            add(
                "naive",
                secs,
                naive.iter().fold(MeshStats::default(), |s, m| s.combine(&m.stats)),
                0,
            );
            for (label, v) in
                [("scanLineV1", ScanLineVersion::V1), ("scanLineV2", ScanLineVersion::V2)]
            {
                let t = Instant::now();
                let out: Vec<_> = masks.iter().map(|m| scan_line(&cloud, m, v).unwrap()).collect();
                let secs = t.elapsed().as_secs_f64();
                add(
                    label,
                    secs,
                    out.iter().fold(MeshStats::default(), |s, m| s.combine(&m.mesh.stats)),
                    0,
                );
            }
            // Chain code, then CDT of its rings in pixel space (no projection here).
            let t = Instant::now();
            let mut stats = MeshStats::default();
            let mut failures = 0;
            for m in &masks {
                for o in outline_mask(m) {
                    match patch_core::triangulate::triangulate_polygon(&o.rings()) {
                        Ok(tri) => {
                            let s: f64 = tri
                                .triangles
                                .iter()
                                .map(|t| {
                                    let [a, b, c] = t.map(|i| tri.vertices[i as usize]);
                                    spikyness_2d(a, b, c)
                                })
                                .sum();
                            stats = stats.combine(&MeshStats::from_parts(
                                tri.triangles.len(),
                                1,
                                tri.vertices.len(),
                                s,
                            ));
                        }
                        Err(_) => {
                            failures += 1;
                            stats =
                                stats.combine(&MeshStats::from_parts(0, 1, o.num_vertices(), 0.0));
                        }
                    }
                }
            }
            add("chain code + CDT (pixel space)", t.elapsed().as_secs_f64(), stats, failures);
            let t = Instant::now();
            let grown = grow_trimeshes(&cloud, &grow_config).unwrap();
            let secs = t.elapsed().as_secs_f64();
            let phase1: Vec<MeshStats> = grown
                .meshes
                .iter()
                .filter(|m| m.phase == patch_extract::trimesh_grow::GrowPhase::Similarity)
                .map(|m| MeshStats::from_triangles(m.patch.vertices(), m.patch.triangles(), 1))
                .collect();
            let p1 = phase1.iter().fold(MeshStats::default(), |s, m| s.combine(m));
            add("trimesh growing (whole cloud)", secs, grown.stats, 0);
            add("  of which phase 1", 0.0, p1, 0);
        }
        println!(
            "\n{name}: lab, {} scans, {regions_total} regions, {pixels_total} region pixels",
            poses.len()
        );
        println!(
            "| method | time [ms/scan] | polygons | triangles | vertices | mean spikyness | CDT failures |"
        );
        println!("|---|---|---|---|---|---|---|");
        for (method, secs, s, failures) in &rows {
            println!(
                "| {method} | {:.2} | {} | {} | {} | {:.3} | {failures} |",
                1e3 * secs / poses.len() as f64,
                s.polygons,
                s.triangles,
                s.vertices,
                s.spikyness_mean
            );
        }
    }
}
