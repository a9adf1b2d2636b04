//! Sensor presets: the extraction thresholds and trimesh growing that suit a sensor.

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
