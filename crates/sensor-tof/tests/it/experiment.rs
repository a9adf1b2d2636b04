//! The Table 2.4 experiment on the simulated scenes: the facts the thesis states about its
//! methods, checked against the truth the simulator knows.

use sensor_tof::experiment::{Method, evaluate_scene, quality_table, table_2_4};
use sensor_tof::scenes::all_scenes;

#[test]
fn table_2_4_facts_hold_on_the_simulated_scenes() {
    let scenes = all_scenes().unwrap();
    let results: Vec<_> =
        scenes.iter().map(|s| evaluate_scene(s, &Method::all(), 7).unwrap()).collect();
    eprintln!("{}\n{}", table_2_4(&results), quality_table(&results));
    let get = |scene: &str, method: &str| {
        results.iter().find(|r| r.scene == scene).unwrap().get(method).unwrap().score
    };
    for r in &results {
        let aat = r.get("AAT").unwrap().score;
        let at160 = r.get("AT 160").unwrap().score;
        let at240 = r.get("AT 240").unwrap().score;
        // AT 240 is "high enough to exclude every wrapped around pixel" and discards most.
        assert!(at240.discarded_percent >= at160.discarded_percent, "{}", r.scene);
        assert!(at240.wrapped_kept_percent <= 0.5, "{}: {:?}", r.scene, at240);
        // The AAT keeps more correct pixels than the plain thresholds, and (almost) no wrapped ones.
        assert!(aat.correct_percent > at160.correct_percent, "{}", r.scene);
        assert!(aat.wrapped_kept_percent < 1.0, "{}: {:?}", r.scene, aat);
        // Every output pixel is either correct or counted wrong.
        for m in &r.results {
            assert!(m.score.discarded_percent >= 0.0 && m.score.discarded_percent <= 100.0);
        }
    }
    // AT 160 keeps wrapped pixels where the AAT does not (the rack-and-door caption).
    assert!(
        get("rack-and-door", "AT 160").wrapped_kept_percent
            > get("rack-and-door", "AAT").wrapped_kept_percent
    );
    // Unwrapping recovers most once-wrapped pixels where there are some.
    for scene in ["rack-and-door", "corner-window"] {
        let u = get(scene, "AAT+unwrap");
        assert!(u.unwrapped_correct_percent > 40.0, "{scene}: {u:?}");
        assert!(u.correct_percent > get(scene, "AAT").correct_percent, "{scene}");
        let two = get(scene, "two-freq");
        assert!(two.unwrapped_correct_percent > 40.0, "{scene}: {two:?}");
    }
    // The low AT before unwrapping removes wrong pixels (L2446–2452) in the sunlit scene.
    assert!(
        get("sun", "AAT+AT20+unwrap").wrong_kept_percent
            < get("sun", "AAT+unwrap").wrong_kept_percent / 2.0
    );
    // Region unwrapping (its preset was tuned on seed 1; this is seed 7) keeps the wrong output
    // under 1 % in every scene, where the AAT does not, and never yields more than the ceiling.
    for r in &results {
        let g = r.get("regions").unwrap().score;
        assert!(g.wrong_kept_percent <= 1.0, "{}: {g:?}", r.scene);
        assert!(g.yield_percent <= r.recoverable_any_percent + 1e-9, "{}: {g:?}", r.scene);
        assert!(r.get("AAT").unwrap().score.wrong_kept_percent > 1.0, "{}", r.scene);
    }
}
