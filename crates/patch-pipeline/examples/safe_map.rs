//! Is a map built from scans safe? Scans the lab four times (simulated ALRF, 2° steps), builds
//! the hybrid map by patch extraction and the raw point-cloud map, and checks 20,000 random
//! capsule steps against the scene's exact surfaces: the colliding steps a map calls free
//! ("unsafe") and the free steps it calls colliding ("overcautious"). The pc map's unsafe rate
//! is what no scan saw, the floor for any map of these scans.
//!
//! ```sh
//! cargo run -p patch-pipeline --example safe_map
//! ```

use patch_map::{AnyMap, Attribution, Backend, PointCloudMap, StepSampling, compare_maps};
use patch_pipeline::MapKind;
use patch_pipeline::scene_map::{
    ScanSetup, extracted_patches, patch_map, pc_points, scan_clouds, truth_patches,
};

fn main() -> anyhow::Result<()> {
    let scene = scene_sim::lab(1)?;
    let setup = ScanSetup { scans: 4, height: 0.5, step_deg: Some(2.0), seed: 1, noise: 1.0 };
    let clouds = scan_clouds(&scene, &setup)?;
    let hybrid = extracted_patches(&clouds, MapKind::Hybrid)?.expect("a patch map");
    let hybrid = patch_map(hybrid, Backend::BBox6d)?;
    let points = pc_points(&clouds, &Default::default())?;
    let pc = AnyMap::PointCloud(PointCloudMap::from_points(&points)?);
    let truth = patch_map(truth_patches(&scene)?, Backend::BBox6d)?;
    let sampling = StepSampling {
        radius: 0.3,
        max_length: 1.0,
        samples: 20_000,
        seed: 1,
        bounds: truth.bounds(),
    };
    for (name, map) in [("hybrid", &hybrid), ("pc", &pc)] {
        let c = compare_maps(&truth, map, &sampling, Attribution::None)?;
        let (u, o) = (c.unsafe_rate(), c.overcautious_rate());
        println!(
            "{name:>6} map of 4 scans: unsafe {:5.2} % [{:.2}, {:.2}], overcautious {:5.2} % [{:.2}, {:.2}]",
            100.0 * u.value,
            100.0 * u.low,
            100.0 * u.high,
            100.0 * o.value,
            100.0 * o.low,
            100.0 * o.high
        );
    }
    Ok(())
}
