//! Sensor presets: the extraction thresholds and trimesh growing that suit a sensor.

use patch_extract::{PipelineConfig, TrimeshGrowConfig};
use std::fmt;
use std::str::FromStr;

use crate::UnknownName;

/// Sensor presets of the pipeline's thresholds.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum SensorPreset {
    /// Actuated laser range finder (S300-like, 1–3 cm noise).
    Alrf,
    /// The same sensor through the thesis's pipeline verbatim: no grazing planes, outlines as
    /// the α-shape gives them (`PipelineConfig::alrf_thesis`).
    AlrfThesis,
    /// Time-of-flight range camera (SR-3000-like).
    RangeCamera,
    /// Structured-light depth camera (Kinect-like): noise growing with the square of the range.
    StructuredLight,
    /// Noise-free synthetic scans.
    Exact,
}

impl SensorPreset {
    /// Every preset.
    pub const ALL: [SensorPreset; 5] = [
        SensorPreset::Alrf,
        SensorPreset::AlrfThesis,
        SensorPreset::RangeCamera,
        SensorPreset::StructuredLight,
        SensorPreset::Exact,
    ];

    /// The name on command lines and in configuration files (`alrf`, `alrf-thesis`,
    /// `range-camera`, `structured-light`, `exact`).
    pub fn name(self) -> &'static str {
        match self {
            SensorPreset::Alrf => "alrf",
            SensorPreset::AlrfThesis => "alrf-thesis",
            SensorPreset::RangeCamera => "range-camera",
            SensorPreset::StructuredLight => "structured-light",
            SensorPreset::Exact => "exact",
        }
    }

    /// One line for help texts.
    pub fn description(self) -> &'static str {
        match self {
            SensorPreset::Alrf => "Actuated laser range finder (S300-like, 1–3 cm noise)",
            SensorPreset::AlrfThesis => {
                "The same sensor through the thesis's pipeline verbatim: no grazing planes, \
                 outlines as the α-shape gives them"
            }
            SensorPreset::RangeCamera => "Time-of-flight range camera (SR-3000-like)",
            SensorPreset::StructuredLight => {
                "Structured-light depth camera (Kinect-like): noise growing with the square of \
                 the range"
            }
            SensorPreset::Exact => "Noise-free synthetic scans",
        }
    }

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

impl fmt::Display for SensorPreset {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for SensorPreset {
    type Err = UnknownName;

    fn from_str(name: &str) -> Result<SensorPreset, UnknownName> {
        UnknownName::find("sensor preset", &SensorPreset::ALL, SensorPreset::name, name)
    }
}
