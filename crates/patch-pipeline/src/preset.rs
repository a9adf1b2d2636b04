//! Sensor presets: the extraction thresholds and trimesh growing that suit a sensor.

use patch_extract::visibility::VisibilityConfig;
use patch_extract::{PipelineConfig, TrimeshGrowConfig};

use crate::names::named_enum;

named_enum! {
    /// Sensor presets of the pipeline's thresholds.
    pub enum SensorPreset ("sensor preset") {
        /// Actuated laser range finder (S300-like, 1–3 cm noise).
        Alrf = "alrf", "Actuated laser range finder (S300-like, 1–3 cm noise)";
        /// The same sensor through the thesis's pipeline verbatim: no grazing planes, outlines
        /// as the α-shape gives them (`PipelineConfig::alrf_thesis`).
        AlrfThesis = "alrf-thesis",
            "The same sensor through the thesis's pipeline verbatim: no grazing planes, \
             outlines as the α-shape gives them";
        /// Time-of-flight range camera (SR-3000-like).
        RangeCamera = "range-camera", "Time-of-flight range camera (SR-3000-like)";
        /// Structured-light depth camera (Kinect-like): noise growing with the square of the
        /// range.
        StructuredLight = "structured-light",
            "Structured-light depth camera (Kinect-like): noise growing with the square of \
             the range";
        /// Noise-free synthetic scans.
        Exact = "exact", "Noise-free synthetic scans";
    }
}

impl SensorPreset {
    /// The extraction pipeline's thresholds and the trimesh growing of the remainder for this
    /// sensor.
    pub fn configs(self) -> (PipelineConfig, TrimeshGrowConfig) {
        match self {
            SensorPreset::Alrf => (PipelineConfig::alrf(), TrimeshGrowConfig::alrf()),
            SensorPreset::AlrfThesis => (PipelineConfig::alrf_thesis(), TrimeshGrowConfig::alrf()),
            SensorPreset::RangeCamera => {
                (PipelineConfig::range_camera(), TrimeshGrowConfig::range_camera())
            }
            SensorPreset::StructuredLight => {
                (PipelineConfig::structured_light(), TrimeshGrowConfig::range_camera())
            }
            SensorPreset::Exact => (PipelineConfig::exact(), TrimeshGrowConfig::range_camera()),
        }
    }
}

/// The extraction choices the programs offer on top of a sensor preset (`patchnav extract`'s
/// flags, the Python package's `extract` keywords).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ExtractChoices {
    /// The preset of the thresholds.
    pub sensor: SensorPreset,
    /// Also grow trimesh patches on the points in no plane (the thesis's hybrid map).
    pub hybrid: bool,
    /// Merge coplanar overlapping patches across scans.
    pub merge: bool,
    /// Segment the points in no plane a second time (as the preset says; `false` turns it
    /// off).
    pub second_pass: bool,
    /// With `hybrid`: drop the remainder triangles another scan saw through (the ALRF's
    /// thresholds).
    pub carve: bool,
    /// The back faces' distance behind each planar patch, metres (`None`: the preset's;
    /// `Some(0.0)`: bare surfaces).
    pub slab_thickness: Option<f64>,
}

impl ExtractChoices {
    /// The preset as it is: planes only, merged, the preset's second pass and slabs.
    pub fn new(sensor: SensorPreset) -> ExtractChoices {
        ExtractChoices {
            sensor,
            hybrid: false,
            merge: true,
            second_pass: true,
            carve: false,
            slab_thickness: None,
        }
    }

    /// The extraction pipeline's configuration.
    pub fn config(&self) -> PipelineConfig {
        let (mut config, grow) = self.sensor.configs();
        if self.hybrid {
            config.remainder = Some(grow);
        }
        if !self.merge {
            config.merge = None;
        }
        if !self.second_pass {
            config.second_pass = None;
        }
        if self.carve && self.hybrid {
            config.carve = Some(VisibilityConfig::alrf());
        }
        if let Some(t) = self.slab_thickness {
            config.slab_thickness = (t != 0.0).then_some(t);
        }
        config
    }
}
