//! Filters a simulated time-of-flight frame: the `rack-and-door` scene of the thesis's
//! Table 2.4 (surfaces beyond the SR-3100's 7.5 m non-ambiguity range wrap around to near
//! ranges) seen by the simulated camera, then the plain amplitude threshold (AT 160) and the
//! adaptive amplitude threshold (AAT 0.2), alone and with unwrapping. Prints per filter the
//! pixels kept, unwrapped and removed, and how many truly wrapped pixels it kept unchanged.
//!
//! ```sh
//! cargo run -p sensor-tof --example filter_frame
//! ```

use sensor_tof::scenes::tof_scene;
use sensor_tof::{AatConfig, FilterConfig, PixelOutcome, TofFilter, TofSimulator};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let scene = tof_scene("rack-and-door")?;
    let sim = TofSimulator::new(scene.sim.clone())?;
    let shot = sim.simulate(&scene.scene, &scene.pose, 1)?;
    let frame = &shot.frame;
    let wrapped = shot.truth.wraps.iter().filter(|&&w| w > 0).count();
    println!(
        "{}: {} × {} pixels, {wrapped} of them wrapped around",
        scene.name,
        frame.camera().width,
        frame.camera().height
    );

    let filters = [
        ("AT 160", FilterConfig::at(160.0)),
        ("AAT 0.2", FilterConfig::aat(AatConfig::sr3100())),
        ("AAT 0.2 + unwrapping", FilterConfig::aat_unwrap(AatConfig::sr3100(), None)),
    ];
    for (name, config) in filters {
        let out = TofFilter::new(frame.camera(), frame.kind(), &config)?.run(frame)?;
        let wrapped_kept = out
            .outcomes
            .iter()
            .zip(&shot.truth.wraps)
            .filter(|&(&o, &w)| o == PixelOutcome::Kept && w > 0)
            .count();
        let c = out.counts;
        println!(
            "{name:>20}: kept {}, unwrapped {}, removed {} ({:.1} %); wrapped but kept {wrapped_kept}",
            c.kept,
            c.unwrapped,
            c.dropped,
            c.discarded_percent()
        );
    }
    Ok(())
}
