//! The six scenes of Table 2.4: each builds, shows its effect in the truth, and the filters
//! behave as the thesis reports qualitatively. `cargo test -p sensor-tof --test it scenes:: --
//! --nocapture` prints the % discarded pixels beside the thesis's.

use pointcloud::{RangeKind, Real};
use scene_sim::SurfaceId;
use sensor_tof::scenes::{SCENE_NAMES, TofScene, all_scenes, tof_scene};
use sensor_tof::sim::{SimulatedFrame, TofSimulator};
use sensor_tof::{
    AatConfig, FilterConfig, FilterOutput, FrameTruth, PixelOutcome, TofFilter, score,
};

/// What the truth of a frame shows, as fractions of all pixels.
#[derive(Debug)]
struct Effects {
    wrapped: Real,
    nothing: Real,
    dark: Real,
    sunlit: Real,
    near: Real,
}

fn effects(s: &TofScene, f: &SimulatedFrame) -> Effects {
    let n = f.truth.radial.len() as Real;
    let cam = f.frame.camera();
    let (mut wrapped, mut nothing, mut dark, mut sunlit, mut near) = (0, 0, 0, 0, 0);
    for i in 0..f.truth.radial.len() {
        let Some(r) = f.truth.radial[i] else {
            nothing += 1;
            continue;
        };
        if f.truth.wraps[i] > 0 {
            wrapped += 1;
        }
        if r < 1.3 {
            near += 1;
        }
        let surface = s.scene.surface(SurfaceId(f.surface[i].unwrap())).unwrap();
        if surface.material.reflectivity < 0.06 {
            dark += 1;
        }
        let (col, row) = f.frame.col_row(i);
        let p = s.pose.world_from_sensor
            * pointcloud::Point3::from(cam.ray(col, row).normalize() * r as Real);
        if s.sim.sun.iter().any(|region| region.contains(&p)) {
            sunlit += 1;
        }
    }
    let pct = |k: usize| k as Real / n;
    Effects {
        wrapped: pct(wrapped),
        nothing: pct(nothing),
        dark: pct(dark),
        sunlit: pct(sunlit),
        near: pct(near),
    }
}

/// Mean reported minus true radial range over the pixels `pick` selects.
fn mean_error(f: &SimulatedFrame, pick: impl Fn(usize) -> bool) -> Real {
    let e: Vec<Real> = (0..f.truth.radial.len())
        .filter(|&i| pick(i))
        .map(|i| f.frame.radial(i) - f.truth.radial[i].unwrap() as Real)
        .collect();
    e.iter().sum::<Real>() / e.len() as Real
}

fn simulate(s: &TofScene) -> SimulatedFrame {
    TofSimulator::new(s.sim.clone()).unwrap().simulate(&s.scene, &s.pose, 2010).unwrap()
}

#[test]
fn every_scene_builds_and_shows_its_effect() {
    assert_eq!(all_scenes().unwrap().len(), 6);
    assert!(tof_scene("no-such-scene").is_err());
    for name in SCENE_NAMES {
        let s = tof_scene(name).unwrap();
        assert_eq!(s.name, name);
        assert!(!s.description.is_empty());
        assert_eq!((s.sim.camera.width, s.sim.camera.height), (176, 144));
        let f = simulate(&s);
        assert_eq!(f.frame.range().len(), 176 * 144);
        assert_eq!(f.frame.kind(), RangeKind::Depth);
        let e = effects(&s, &f);
        println!("{name:14} {e:?}");
        match name {
            "rack-and-door" => assert!(e.wrapped >= 0.10, "{e:?}"),
            "corner-window" => assert!(e.wrapped >= 0.10 && e.sunlit > 0.02, "{e:?}"),
            "gates" => assert!(e.wrapped >= 0.50 && e.sunlit > 0.01, "{e:?}"),
            "close-boxes" => assert!(e.near >= 0.15 && e.wrapped == 0.0, "{e:?}"),
            "dark-material" => assert!(e.dark >= 0.05 && e.wrapped == 0.0, "{e:?}"),
            "sun" => assert!(e.sunlit >= 0.10, "{e:?}"),
            _ => unreachable!(),
        }
        // The scattering and the amplitude-related error show in the reported ranges.
        if name == "close-boxes" {
            let bias = mean_error(&f, |i| f.truth.radial[i].is_some_and(|t| t > 2.5));
            assert!(bias < -0.05, "background reads {bias} m off");
        }
        if name == "dark-material" {
            let dark = |i: usize| {
                let id = SurfaceId(f.surface[i].unwrap());
                s.scene.surface(id).unwrap().material.reflectivity < 0.06
            };
            let bias = mean_error(&f, dark);
            assert!(bias < -0.03, "dark pixels read {bias} m off");
        }
        // Every scene is closed: (almost) every beam meets a surface within the cast range.
        assert!(e.nothing < 0.01, "{name}: {e:?}");
    }
}

fn run(filter: &FilterConfig, f: &SimulatedFrame) -> FilterOutput {
    TofFilter::new(f.frame.camera(), RangeKind::Depth, filter).unwrap().run(&f.frame).unwrap()
}

/// % of the pixels whose truth wrapped that `out` keeps (at the wrapped range).
fn wrapped_kept(out: &FilterOutput, truth: &FrameTruth) -> Real {
    let n = truth.wraps.len() as Real;
    let k = (0..truth.wraps.len())
        .filter(|&i| truth.wraps[i] > 0 && out.outcomes[i] == PixelOutcome::Kept)
        .count();
    100.0 * k as Real / n
}

/// % of all pixels that are correct (within 5 cm of a truth that did not wrap) but dropped.
fn correct_dropped(out: &FilterOutput, f: &SimulatedFrame) -> Real {
    let n = f.truth.wraps.len();
    let k = (0..n)
        .filter(|&i| {
            let ok =
                f.truth.radial[i].is_some_and(|t| (f.frame.radial(i) - t as Real).abs() < 0.05);
            ok && out.outcomes[i] == PixelOutcome::Dropped
        })
        .count();
    100.0 * k as Real / n as Real
}

#[test]
fn table_2_4_beside_the_thesis() {
    let aat = FilterConfig::aat(AatConfig::sr3100());
    let at160 = FilterConfig::at(160.0);
    let at240 = FilterConfig::at(240.0);
    println!(
        concat!(
            "{:14} | {:>13} | {:>13} | {:>13} | wrapped kept % AAT/160/240 ",
            "| correct dropped % AAT/160/240 | wrong kept % AAT/160 | AAT Lambert | sim ms"
        ),
        "scene", "AAT (thesis)", "AT160 (th.)", "AT240 (th.)"
    );
    for s in all_scenes().unwrap() {
        let start = std::time::Instant::now();
        let f = simulate(&s);
        let millis = start.elapsed().as_secs_f64() * 1e3;
        let outs = [run(&aat, &f), run(&at160, &f), run(&at240, &f)];
        let d: Vec<Real> = outs.iter().map(|o| o.counts.discarded_percent()).collect();
        let wk: Vec<Real> = outs.iter().map(|o| wrapped_kept(o, &f.truth)).collect();
        let cd: Vec<Real> = outs.iter().map(|o| correct_dropped(o, &f)).collect();
        let measured: Vec<bool> = f.frame.range().iter().map(|&r| r > 0.0).collect();
        let wrong: Vec<Real> = outs[..2]
            .iter()
            .map(|o| score(o, &measured, &f.truth, 0.05).unwrap().wrong_kept_percent)
            .collect();
        // The same frame with Lambertian surfaces, to show what the roughness choice does.
        let mut lambert = s.sim.clone();
        lambert.roughness = 0.0;
        let fl = TofSimulator::new(lambert).unwrap().simulate(&s.scene, &s.pose, 2010).unwrap();
        let d_lambert = run(&aat, &fl).counts.discarded_percent();
        let t = s.thesis;
        println!(
            concat!(
                "{:14} | {:5.1} ({:5.1}) | {:5.1} ({:5.1}) | {:5.1} ({:>5}) ",
                "| {:5.1} {:5.1} {:5.1} | {:5.1} {:5.1} {:5.1} | {:5.1} {:5.1} | {:5.1} | {:4.0}"
            ),
            s.name,
            d[0],
            t.aat,
            d[1],
            t.at160,
            d[2],
            t.at240.map_or("–".to_string(), |v| format!("{v:.1}")),
            wk[0],
            wk[1],
            wk[2],
            cd[0],
            cd[1],
            cd[2],
            wrong[0],
            wrong[1],
            d_lambert,
            millis,
        );
        // The AAT drops fewer correct pixels than AT 160 (Fig 2.17g, h: "correct ones are
        // discarded").
        assert!(cd[0] < cd[1], "{}: correct pixels dropped {cd:?}", s.name);
        // A higher plain threshold drops at least as much (amplitudes are the same).
        assert!(d[2] >= d[1], "{}: {d:?}", s.name);
        // The AAT keeps few wrapped pixels (those it keeps are sunlit noise whose random range
        // happens to fit its amplitude, L2382–2385).
        assert!(wk[0] < 5.0, "{}: AAT keeps {:.1} % wrapped pixels", s.name, wk[0]);
        if s.name == "rack-and-door" {
            assert!(wk[0] < 1.0, "{}: AAT keeps {:.1} % wrapped pixels", s.name, wk[0]);
            // AT 160 keeps some wrapped pixels, AT 240 drops more of the image than the AAT.
            assert!(wk[1] > wk[0], "{wk:?}");
            assert!(d[2] > d[0], "{d:?}");
        }
    }
}
