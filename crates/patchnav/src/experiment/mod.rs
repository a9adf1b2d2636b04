//! `patchnav experiment ...`: the thesis's planning experiments, run on our maps and printed
//! beside the thesis's numbers.
//!
//! * `office`: the preliminary experiment of §5.5.3 (Tables 5.3–5.11);
//! * `lab-timing`: RRT time against iterations on the lab's planes, hybrid, trimesh and
//!   point-cloud maps (§6.1.3, Fig 6.4), as CSV and SVG;
//! * `lab-volume`: explored volume and its congruence tables (§6.1.1, Tables 6.2 and 6.4);
//! * `map-safety`: maps built from scans checked against the exact scene (unsafe and
//!   overcautious steps, sizes, extraction time, roadmap edges re-checked);
//! * `map-coverage`: the share of each real scan's points its planes and hybrid maps hold;
//! * `extraction`: patch extraction quality, the outlining survey and patch sizes (§5.3,
//!   Figs 5.12–5.14, Table 5.1).

use crate::progress::Progress;
use anyhow::Result;
use clap::Subcommand;

mod extraction;
pub(crate) mod lab;
mod map_coverage;
mod map_safety;
mod office;
mod tof;

/// The experiments.
#[derive(Subcommand, Debug)]
pub enum ExperimentCommand {
    /// Thesis §5.5.3: every planner on every backend, reach four regions of interest from the
    /// centre of the office floor plan (`--seeds` runs each, capped at `--max-iterations`);
    /// prints Tables 5.3–5.11 beside the thesis's numbers and checks the thesis's claims.
    Office(office::OfficeArgs),
    /// Thesis Fig 6.4: RRT time against iterations on the lab's four map types (CSV and SVG).
    LabTiming(lab::LabTimingArgs),
    /// Thesis Tables 6.2 and 6.4: explored volume of RRT and PRM on the lab's four map types
    /// and the congruence table between them.
    LabVolume(lab::LabVolumeArgs),
    /// Thesis §5.3: segmentation quality (SegComp), the outlining survey (Figs 5.12–5.14),
    /// outline fidelity and patch sizes (Table 5.1) on simulated and real scans.
    Extraction(extraction::ExtractionArgs),
    /// Is a map built from scans safe? Planes, hybrid, trimesh and pc maps of the lab and the
    /// office at three noise levels and two scan counts, checked against the exact scene:
    /// unsafe and overcautious step rates, sizes, extraction time, roadmap edges re-checked.
    MapSafety(map_safety::MapSafetyArgs),
    /// How much of each real scan (`--real-dir`) its planes and hybrid maps hold: the share of
    /// points within 3σ(r) of a patch, and the maps' sizes against the scan's.
    MapCoverage(map_coverage::MapCoverageArgs),
    /// Thesis Table 2.4: the adaptive amplitude threshold against amplitude thresholds, with
    /// unwrapping, two-frequency unwrapping and the spatial check, on six simulated scenes
    /// (and a real frame folded at a chosen non-ambiguity range with `--real`).
    Tof(tof::TofArgs),
}

/// Runs `patchnav experiment ...`.
pub fn run(command: &ExperimentCommand, progress: &Progress) -> Result<()> {
    match command {
        ExperimentCommand::Office(args) => office::run(args, progress),
        ExperimentCommand::LabTiming(args) => lab::run_timing(args, progress),
        ExperimentCommand::LabVolume(args) => lab::run_volume(args, progress),
        ExperimentCommand::Extraction(args) => extraction::run(args, progress),
        ExperimentCommand::Tof(args) => tof::run(args, progress),
        ExperimentCommand::MapSafety(args) => map_safety::run(args, progress),
        ExperimentCommand::MapCoverage(args) => map_coverage::run(args, progress),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser, Debug)]
    struct Cli {
        #[command(subcommand)]
        experiment: ExperimentCommand,
    }

    fn parse(name: &str) -> ExperimentCommand {
        Cli::try_parse_from(["cli", name]).unwrap().experiment
    }

    /// The command line's defaults are the library's, so a library user gets the figures the
    /// docs print with the bare command.
    #[test]
    fn every_experiment_defaults_to_the_library_defaults() {
        use patch_pipeline::experiment::{extraction, map_coverage, map_safety, office, tof};
        let ExperimentCommand::Office(a) = parse("office") else { panic!() };
        assert_eq!(a.setup(), office::OfficeSetup::default());
        let ExperimentCommand::LabTiming(a) = parse("lab-timing") else { panic!() };
        assert_eq!(a.lab.setup(), patch_pipeline::experiment::lab::LabSetup::default());
        assert_eq!((a.seeds, a.checkpoints, a.out.clone()), (24, 20, None));
        let ExperimentCommand::Extraction(a) = parse("extraction") else { panic!() };
        assert_eq!(a.setup(), extraction::ExtractionSetup::default());
        let ExperimentCommand::MapSafety(a) = parse("map-safety") else { panic!() };
        assert_eq!(a.setup(), map_safety::MapSafetySetup::default());
        let ExperimentCommand::MapCoverage(a) = parse("map-coverage") else { panic!() };
        assert_eq!(a.setup(), map_coverage::MapCoverageSetup::default());
        let ExperimentCommand::Tof(a) = parse("tof") else { panic!() };
        assert_eq!(a.setup(), tof::TofSetup::default());
    }
}
