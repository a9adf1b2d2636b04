//! The spatial consistency check on synthetic frames (walls and objects at known distances,
//! amplitude `a = ρ·aw_p / z²` with the SR-3000 parabola, reported range = true mod R_amb)
//! and against a brute-force implementation on random small frames.

use pointcloud::{PinholeIntrinsics, RangeKind, Real};
use proptest::prelude::*;
use sensor_tof::spatial::{
    FlagPolicy, RangeTolerance, SpatialConfig, SpatialScratch, SpatialStats, reconsider,
    reconsider_with,
};
use sensor_tof::{
    AatConfig, FilterConfig, FilterOutput, NegativeIllumination, Parabola, PixelOutcome, RayTables,
    TofCamera, TofError, TofFilter, TofFrame,
};

/// An SR-3000 depth frame: pixel (col, row) sees a surface at true depth `depth(col, row)`
/// with reflectivity `rho(col, row)`.
fn scene(depth: impl Fn(u32, u32) -> Real, rho: impl Fn(u32, u32) -> Real) -> TofFrame {
    let c = TofCamera::sr3000();
    let amb = c.non_ambiguity_range();
    let p = Parabola::sr3000();
    let (mut range, mut amplitude) = (Vec::new(), Vec::new());
    for row in 0..c.height {
        for col in 0..c.width {
            let k = c.ray(col, row).norm();
            let z = depth(col, row);
            range.push(((z * k).rem_euclid(amb) / k) as f32);
            let aw = p.eval(col as Real, row as Real).max(0.0);
            amplitude.push((rho(col, row) * aw / (z * z)) as f32);
        }
    }
    TofFrame::new(c, RangeKind::Depth, range, amplitude).unwrap()
}

fn index(col: u32, row: u32) -> usize {
    row as usize * TofCamera::sr3000().width as usize + col as usize
}

fn filter(unwrap: bool, negative: NegativeIllumination) -> (TofFilter, FilterConfig) {
    let aat = AatConfig { negative, ..AatConfig::sr3000() };
    let config = if unwrap { FilterConfig::aat_unwrap(aat, None) } else { FilterConfig::aat(aat) };
    (TofFilter::new(&TofCamera::sr3000(), RangeKind::Depth, &config).unwrap(), config)
}

fn in_spot(col: u32, row: u32) -> bool {
    (100..102).contains(&col) && (70..72).contains(&row) || (col, row) == (40, 40)
}

#[test]
fn a_dark_spot_on_a_near_wall_is_restored() {
    // A wall at 2 m of 60 % reflectivity with a 2 × 2 and a 1-pixel spot of 1 %.
    let frame = scene(|_, _| 2.0, |c, r| if in_spot(c, r) { 0.01 } else { 0.6 });
    for unwrap in [false, true] {
        let (f, config) = filter(unwrap, NegativeIllumination::Literal);
        let mut out = f.run(&frame).unwrap();
        // The AAT flags the spots (apparent reflectivity 1 % < 20 %) and nothing else.
        let flagged = if unwrap { PixelOutcome::Unwrapped } else { PixelOutcome::Dropped };
        for (i, &o) in out.outcomes.iter().enumerate() {
            let (c, r) = frame.col_row(i);
            assert_eq!(o == flagged, in_spot(c, r), "pixel ({c}, {r}) {o:?}");
        }
        let stats =
            reconsider(&frame, &mut out, &SpatialConfig::for_filter(&config), f.tables()).unwrap();
        let expect = if unwrap {
            SpatialStats { unwrapped_to_kept: 5, ..SpatialStats::default() }
        } else {
            SpatialStats { dropped_to_kept: 5, ..SpatialStats::default() }
        };
        assert_eq!(stats, expect);
        assert_eq!(out.counts.kept, frame.range().len());
        let i = index(100, 70);
        assert!((out.radial[i] as Real - frame.radial(i)).abs() < 1e-4);
    }
}

#[test]
fn passes_restore_a_dark_patch_from_its_corners_inwards() {
    // A 3 × 3 dark patch on a near wall: one pass restores its corners (5 kept neighbours
    // against 3 flagged), the next its edges, the third the centre. A 4 × 4 patch stops after
    // the corners: its edge pixels then see as many flagged neighbours as kept ones.
    for (size, expect) in [(3, [4, 8, 9, 9]), (4, [4, 4, 4, 4])] {
        let dark = |c: u32, r: u32| (80..80 + size).contains(&c) && (60..60 + size).contains(&r);
        let frame = scene(|_, _| 2.5, |c, r| if dark(c, r) { 0.02 } else { 0.6 });
        let (f, config) = filter(false, NegativeIllumination::Literal);
        let out = f.run(&frame).unwrap();
        assert_eq!(out.counts.dropped, (size * size) as usize);
        let mut restored = [0; 4];
        for (passes, slot) in (1..=4).zip(&mut restored) {
            let spatial = SpatialConfig { passes, ..SpatialConfig::for_filter(&config) };
            let mut o = out.clone();
            *slot = reconsider(&frame, &mut o, &spatial, f.tables()).unwrap().dropped_to_kept;
        }
        assert_eq!(restored, expect, "{size} × {size}");
    }
}

#[test]
fn a_wrapped_patch_with_one_passing_pixel_is_fixed() {
    // A wall at 9 m (wraps to ≈ 1.5 m) with one retro-reflecting pixel that passes the AAT.
    let spot = (88, 72);
    let frame = scene(|_, _| 9.0, |c, r| if (c, r) == spot { 40.0 } else { 0.5 });
    let i = index(spot.0, spot.1);
    let true_radial = 9.0 * TofCamera::sr3000().ray(spot.0, spot.1).norm();
    // Clamped illumination: every other pixel is flagged.
    for unwrap in [true, false] {
        let (f, config) = filter(unwrap, NegativeIllumination::Clamp(1.0));
        let mut out = f.run(&frame).unwrap();
        assert_eq!(out.counts.kept, 1);
        assert_eq!(out.outcomes[i], PixelOutcome::Kept);
        let stats =
            reconsider(&frame, &mut out, &SpatialConfig::for_filter(&config), f.tables()).unwrap();
        if unwrap {
            assert_eq!(stats, SpatialStats { kept_to_unwrapped: 1, ..SpatialStats::default() });
            assert_eq!(out.counts.unwrapped, frame.range().len());
            assert!((out.radial[i] as Real - true_radial).abs() < 1e-3, "{}", out.radial[i]);
        } else {
            assert_eq!(stats, SpatialStats { kept_to_dropped: 1, ..SpatialStats::default() });
            assert_eq!(out.counts.dropped, frame.range().len());
        }
    }
    // The thesis's literal corners (aw_p < 0) pass as whole regions: those are consistent among
    // themselves and stay; only the single pixel is fixed.
    let (f, config) = filter(true, NegativeIllumination::Literal);
    let mut out = f.run(&frame).unwrap();
    let corners = out.counts.kept - 1;
    assert!(corners > 100, "{corners}");
    let stats =
        reconsider(&frame, &mut out, &SpatialConfig::for_filter(&config), f.tables()).unwrap();
    assert_eq!(out.outcomes[i], PixelOutcome::Unwrapped);
    assert!(stats.kept_to_unwrapped >= 1);
    assert!(out.counts.kept >= corners * 9 / 10, "{} of {corners}", out.counts.kept);
}

#[test]
fn a_separate_small_near_object_is_not_erased() {
    // A wrapped wall at 9 m; a near object of exactly `min_support` pixels (an L of 3) and a
    // single near pixel at 2 m; another single pixel exactly one non-ambiguity range in front of
    // the wall, which no neighbourhood can tell from a wrapped pixel that passed.
    let c = TofCamera::sr3000();
    let amb = c.non_ambiguity_range();
    let object = |c: u32, r: u32| matches!((c, r), (60, 50) | (61, 50) | (60, 51));
    let near = |c: u32, r: u32| object(c, r) || (c, r) == (120, 90);
    let alias = (30, 100);
    let alias_depth = 9.0 - amb / c.ray(alias.0, alias.1).norm();
    let frame = scene(
        |c, r| {
            if near(c, r) {
                2.0
            } else if (c, r) == alias {
                alias_depth
            } else {
                9.0
            }
        },
        |_, _| 0.5,
    );
    for unwrap in [true, false] {
        let (f, config) = filter(unwrap, NegativeIllumination::Clamp(1.0));
        let mut out = f.run(&frame).unwrap();
        assert_eq!(out.counts.kept, 5);
        let spatial = SpatialConfig::for_filter(&config);
        assert_eq!(spatial.min_support, 3);
        let stats = reconsider(&frame, &mut out, &spatial, f.tables()).unwrap();
        for (c, r) in [(60, 50), (61, 50), (60, 51), (120, 90)] {
            assert_eq!(out.outcomes[index(c, r)], PixelOutcome::Kept);
        }
        assert_ne!(out.outcomes[index(alias.0, alias.1)], PixelOutcome::Kept);
        assert_eq!(stats.changed(), 1);
    }
}

#[test]
fn isolated_pixels_are_dropped_on_request() {
    // Every pixel at its own distance (a staircase of 1 m steps): nothing agrees.
    let frame = scene(|c, r| 1.0 + ((c + 2 * r) % 4) as Real, |_, _| 0.5);
    let (f, config) = filter(false, NegativeIllumination::Literal);
    let mut out = f.run(&frame).unwrap();
    let kept = out.counts.kept;
    assert!(kept > frame.range().len() / 2);
    let mut spatial = SpatialConfig::for_filter(&config);
    let keep = reconsider(&frame, &mut out.clone(), &spatial, f.tables()).unwrap();
    assert_eq!(keep.changed(), 0);
    spatial.isolation_support = 1;
    let stats = reconsider(&frame, &mut out, &spatial, f.tables()).unwrap();
    // (c + 2r) mod 4 repeats only at offsets (±4, 0) and (∓2, ±1), outside the 3 × 3 window:
    // every kept pixel is isolated.
    assert_eq!(stats.isolated_dropped, kept);
    assert_eq!(out.counts.dropped, frame.range().len());

    // A horizontal line of near pixels before a far wall: each line pixel has two agreeing
    // neighbours (one at the ends), so support 2 keeps its inside, support 3 drops it all.
    let line = |c: u32, r: u32| r == 70 && (50..60).contains(&c);
    let frame = scene(|c, r| if line(c, r) { 1.0 } else { 4.0 }, |_, _| 0.5);
    let out = f.run(&frame).unwrap();
    for (support, dropped) in [(1, 0), (2, 2), (3, 10)] {
        let spatial =
            SpatialConfig { isolation_support: support, ..SpatialConfig::for_filter(&config) };
        let mut o = out.clone();
        let stats = reconsider(&frame, &mut o, &spatial, f.tables()).unwrap();
        let line_dropped = (50..60).filter(|&c| o.outcomes[index(c, 70)] == PixelOutcome::Dropped);
        assert_eq!(line_dropped.count(), dropped, "support {support}");
        assert_eq!(stats.isolated_dropped, dropped, "the wall is untouched");
    }
}

#[test]
fn bad_input_is_refused() {
    let frame = scene(|_, _| 2.0, |_, _| 0.5);
    let (f, config) = filter(false, NegativeIllumination::Literal);
    let out = f.run(&frame).unwrap();
    let ok = SpatialConfig::for_filter(&config);
    let tables = f.tables();
    let bad = |c: SpatialConfig| {
        matches!(c.validate(), Err(TofError::BadParameter { .. }))
            && reconsider(&frame, &mut out.clone(), &c, tables).is_err()
    };
    assert!(bad(SpatialConfig { radius: 0, ..ok }));
    assert!(bad(SpatialConfig { radius: 100, ..ok }));
    assert!(bad(SpatialConfig { min_support: 0, ..ok }));
    assert!(bad(SpatialConfig { min_support: 9, ..ok }));
    assert!(bad(SpatialConfig { passes: 0, ..ok }));
    assert!(bad(SpatialConfig { isolation_support: 9, ..ok }));
    assert!(bad(SpatialConfig { passes: u32::MAX, ..ok }));
    assert!(SpatialConfig { min_support: 9, radius: 2, ..ok }.validate().is_ok());
    let tol = |absolute_m, relative| SpatialConfig {
        tolerance: RangeTolerance { absolute_m, relative },
        ..ok
    };
    assert!(bad(tol(Real::NAN, 0.0)));
    assert!(bad(tol(-1.0, 0.0)));
    assert!(bad(tol(0.1, 1.0)));
    assert!(bad(tol(0.1, Real::INFINITY)));
    // Sizes that do not match.
    let mut short = out.clone();
    short.outcomes.pop();
    assert!(matches!(reconsider(&frame, &mut short, &ok, tables), Err(TofError::Mismatch { .. })));
    let small =
        TofCamera::pinhole(4, 4, PinholeIntrinsics::from_fov(4, 4, 0.5, 0.5), 20e6).unwrap();
    assert!(matches!(
        reconsider(&frame, &mut out.clone(), &ok, &RayTables::new(&small)),
        Err(TofError::Mismatch { .. })
    ));
}

// ---- random small frames against a brute-force implementation ----

const LEVELS: [f32; 6] = [0.0, 1.0, 1.03, 1.5, 3.0, 6.0];

/// A random radial frame and a filter output consistent with it (kept at the reported range,
/// unwrapped one R_amb further, unmeasured pixels dropped).
fn random_case() -> impl Strategy<Value = (TofFrame, FilterOutput)> {
    (1u32..9, 1u32..9).prop_flat_map(|(w, h)| {
        let n = (w * h) as usize;
        (
            Just((w, h)),
            prop::collection::vec(0usize..LEVELS.len(), n),
            prop::collection::vec(0u8..3, n),
            prop::collection::vec(-0.02..0.02f32, n),
        )
            .prop_map(|((w, h), level, outcome, jitter)| {
                let k = PinholeIntrinsics::from_fov(w, h, 0.8, 0.7);
                let camera = TofCamera::pinhole(w, h, k, 20e6).unwrap();
                let amb = camera.non_ambiguity_range() as f32;
                let range: Vec<f32> = level
                    .iter()
                    .zip(&jitter)
                    .map(|(&l, &j)| if l == 0 { 0.0 } else { LEVELS[l] + j })
                    .collect();
                let n = range.len();
                let frame =
                    TofFrame::new(camera, RangeKind::Radial, range.clone(), vec![1.0; n]).unwrap();
                let mut out = FilterOutput::default();
                out.reset(n);
                for i in 0..n {
                    let o = match outcome[i] {
                        _ if range[i] == 0.0 => PixelOutcome::Dropped,
                        0 => PixelOutcome::Kept,
                        1 => PixelOutcome::Unwrapped,
                        _ => PixelOutcome::Dropped,
                    };
                    out.outcomes[i] = o;
                    out.radial[i] = match o {
                        PixelOutcome::Kept => range[i],
                        PixelOutcome::Unwrapped => range[i] + amb,
                        PixelOutcome::Dropped => 0.0,
                    };
                }
                out.recount();
                (frame, out)
            })
    })
}

fn random_config() -> impl Strategy<Value = SpatialConfig> {
    let sizes = (1u32..3, 1u32..9, 1u32..4, 0u32..4);
    let flags = (prop::bool::ANY, prop::bool::ANY, prop::bool::ANY);
    (sizes, flags).prop_map(|((radius, min_support, passes, iso), (tight, relative, unwrap))| {
        SpatialConfig {
            radius,
            min_support,
            tolerance: RangeTolerance {
                absolute_m: if tight { 0.01 } else { 0.05 },
                relative: if relative { 0.03 } else { 0.0 },
            },
            policy: if unwrap { FlagPolicy::Unwrap } else { FlagPolicy::Drop },
            isolation_support: iso,
            passes,
        }
    })
}

/// The check written the obvious way: `passes` times, for every pixel look at every offset of
/// the window, count, decide by the table of the module doc, write into a fresh output.
fn brute_force(frame: &TofFrame, before: &FilterOutput, cfg: &SpatialConfig) -> FilterOutput {
    let mut out = before.clone();
    for _ in 0..cfg.passes {
        out = brute_force_pass(frame, &out, cfg);
    }
    out
}

fn brute_force_pass(frame: &TofFrame, before: &FilterOutput, cfg: &SpatialConfig) -> FilterOutput {
    let (w, h) = (frame.camera().width as i64, frame.camera().height as i64);
    let amb = frame.camera().non_ambiguity_range();
    let t = cfg.tolerance;
    let agree = |x: Real, y: Real| (x - y).abs() <= t.absolute_m + t.relative * x.max(y);
    let s = cfg.min_support as usize;
    let r = cfg.radius as i64;
    let mut after = before.clone();
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let mine = frame.radial(i);
            if mine <= 0.0 {
                continue;
            }
            let o = before.outcomes[i];
            let (mut k, mut wr, mut iso) = (0, 0, 0);
            for dy in -r..=r {
                for dx in -r..=r {
                    let (xx, yy) = (x + dx, y + dy);
                    if (dx, dy) == (0, 0) || xx < 0 || yy < 0 || xx >= w || yy >= h {
                        continue;
                    }
                    let j = (yy * w + xx) as usize;
                    let oj = before.outcomes[j];
                    let out_j = before.radial[j] as Real;
                    if oj == PixelOutcome::Kept && agree(mine, out_j) {
                        k += 1;
                    }
                    let wrapped_support = match cfg.policy {
                        FlagPolicy::Unwrap => {
                            oj == PixelOutcome::Unwrapped && agree(mine + amb, out_j)
                        }
                        FlagPolicy::Drop => {
                            oj == PixelOutcome::Dropped
                                && frame.radial(j) > 0.0
                                && agree(mine + amb, frame.radial(j) + amb)
                        }
                    };
                    if wrapped_support {
                        wr += 1;
                    }
                    if o.is_output() && oj.is_output() && agree(before.radial[i] as Real, out_j) {
                        iso += 1;
                    }
                }
            }
            let isolated = iso < cfg.isolation_support;
            let (new, radial) = match o {
                PixelOutcome::Kept if k == 0 && wr >= s => match cfg.policy {
                    FlagPolicy::Unwrap => (PixelOutcome::Unwrapped, mine + amb),
                    FlagPolicy::Drop => (PixelOutcome::Dropped, 0.0),
                },
                PixelOutcome::Unwrapped | PixelOutcome::Dropped if k >= s && k > wr => {
                    (PixelOutcome::Kept, mine)
                }
                PixelOutcome::Dropped if cfg.policy == FlagPolicy::Unwrap && wr >= s && wr > k => {
                    (PixelOutcome::Unwrapped, mine + amb)
                }
                PixelOutcome::Kept | PixelOutcome::Unwrapped if isolated => {
                    (PixelOutcome::Dropped, 0.0)
                }
                _ => continue,
            };
            after.outcomes[i] = new;
            after.radial[i] = radial as f32;
        }
    }
    after.recount();
    after
}

/// The frame and output turned by 180° (pixel `i` ↦ `n − 1 − i`): the scan meets the pixels
/// in the opposite order.
fn turned(frame: &TofFrame, out: &FilterOutput) -> (TofFrame, FilterOutput) {
    let rev = |v: &[f32]| v.iter().rev().copied().collect::<Vec<f32>>();
    let f =
        TofFrame::new(*frame.camera(), frame.kind(), rev(frame.range()), rev(frame.amplitude()))
            .unwrap();
    let mut o = out.clone();
    o.outcomes.reverse();
    o.radial.reverse();
    (f, o)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn matches_brute_force_and_ignores_scan_order(
        (frame, out) in random_case(), config in random_config(),
    ) {
        prop_assume!(config.validate().is_ok());
        let tables = RayTables::new(frame.camera());
        let mut fast = out.clone();
        let mut scratch = SpatialScratch::default();
        let stats = reconsider_with(&frame, &mut fast, &config, &tables, &mut scratch).unwrap();
        let slow = brute_force(&frame, &out, &config);
        prop_assert_eq!(&fast.outcomes, &slow.outcomes);
        for (a, b) in fast.radial.iter().zip(&slow.radial) {
            prop_assert!((a - b).abs() < 1e-5, "{} vs {}", a, b);
        }
        prop_assert_eq!(fast.counts, slow.counts);
        let changed = out.outcomes.iter().zip(&fast.outcomes).filter(|(a, b)| a != b).count();
        prop_assert_eq!(stats.changed(), changed);
        // Scan order: the turned frame gives the turned result (scratch reused).
        let (tf, tout) = turned(&frame, &out);
        let mut tfast = tout.clone();
        reconsider_with(&tf, &mut tfast, &config, &RayTables::new(tf.camera()), &mut scratch)
            .unwrap();
        let back: Vec<PixelOutcome> = tfast.outcomes.iter().rev().copied().collect();
        prop_assert_eq!(back, fast.outcomes);
    }
}
