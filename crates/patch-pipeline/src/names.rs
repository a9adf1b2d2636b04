//! The libraries' vocabularies by name, for command lines and configuration files: the
//! backends ([`Backend`]), the planners ([`PlannerKind`]) and this crate's enums, each parsed
//! by its own [`FromStr`]. [`NameParser`] accepts them, or a subset of them, and lists the
//! accepted names; a program wraps it in its argument parser's value parser.

use crate::experiment::extraction::RegionSource;
use crate::input::DepthConvention;
use crate::problem::Mode;
use crate::terrain::AxesChoice;
use crate::tof::Method;
use crate::{MapKind, MapSource, SensorPreset};
use patch_map::Backend;
use roadmap::PlannerKind;
use std::fmt;
use std::str::FromStr;

/// A library enum with a name and a description per value.
pub trait Named: Copy + PartialEq + FromStr + Send + Sync + 'static {
    /// Every value, in the order help texts list them.
    const ALL: &'static [Self];
    /// The name (what [`FromStr`] parses).
    fn name(self) -> &'static str;
    /// One line for help texts.
    fn description(self) -> &'static str;
}

impl Named for Backend {
    const ALL: &'static [Backend] = &Backend::ALL;

    fn name(self) -> &'static str {
        Backend::name(self)
    }

    fn description(self) -> &'static str {
        Backend::description(self)
    }
}

impl Named for MapKind {
    const ALL: &'static [MapKind] = &MapKind::ALL;

    fn name(self) -> &'static str {
        MapKind::name(self)
    }

    fn description(self) -> &'static str {
        MapKind::description(self)
    }
}

impl Named for MapSource {
    const ALL: &'static [MapSource] = &MapSource::ALL;

    fn name(self) -> &'static str {
        MapSource::name(self)
    }

    fn description(self) -> &'static str {
        MapSource::description(self)
    }
}

impl Named for DepthConvention {
    const ALL: &'static [DepthConvention] = &DepthConvention::ALL;

    fn name(self) -> &'static str {
        DepthConvention::name(self)
    }

    fn description(self) -> &'static str {
        DepthConvention::description(self)
    }
}

impl Named for SensorPreset {
    const ALL: &'static [SensorPreset] = &SensorPreset::ALL;

    fn name(self) -> &'static str {
        SensorPreset::name(self)
    }

    fn description(self) -> &'static str {
        SensorPreset::description(self)
    }
}

impl Named for RegionSource {
    const ALL: &'static [RegionSource] = &RegionSource::ALL;

    fn name(self) -> &'static str {
        RegionSource::name(self)
    }

    fn description(self) -> &'static str {
        RegionSource::description(self)
    }
}

impl Named for Mode {
    const ALL: &'static [Mode] = &Mode::ALL;

    fn name(self) -> &'static str {
        Mode::name(self)
    }

    fn description(self) -> &'static str {
        Mode::description(self)
    }
}

impl Named for AxesChoice {
    const ALL: &'static [AxesChoice] = &AxesChoice::ALL;

    fn name(self) -> &'static str {
        AxesChoice::name(self)
    }

    fn description(self) -> &'static str {
        AxesChoice::description(self)
    }
}

impl Named for Method {
    const ALL: &'static [Method] = &Method::ALL;

    fn name(self) -> &'static str {
        Method::name(self)
    }

    fn description(self) -> &'static str {
        Method::description(self)
    }
}

impl Named for PlannerKind {
    const ALL: &'static [PlannerKind] = &PlannerKind::ALL;

    fn name(self) -> &'static str {
        PlannerKind::name(self)
    }

    fn description(self) -> &'static str {
        PlannerKind::description(self)
    }
}

/// Accepts the names of the values of `T` that `accepts` lets through.
#[derive(Copy, Clone)]
pub struct NameParser<T: 'static> {
    accepts: fn(T) -> bool,
    /// Why the others are refused.
    refused: &'static str,
}

/// Every value of `T`.
pub fn all<T: Named>() -> NameParser<T> {
    NameParser { accepts: |_| true, refused: "" }
}

/// The values of `T` that `accepts` lets through; `refused` says why the others are not ("it
/// holds points, not patches").
pub fn only<T: Named>(accepts: fn(T) -> bool, refused: &'static str) -> NameParser<T> {
    NameParser { accepts, refused }
}

/// The backends that hold patches ([`Backend::holds_patches`]).
pub fn patch_backends() -> NameParser<Backend> {
    only(Backend::holds_patches, "it holds points, not patches")
}

/// A name refused by a [`NameParser`]: no value's, or one outside its subset.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum NameError {
    /// No value has this name.
    Unknown {
        /// The name given.
        given: String,
        /// The names accepted.
        choices: Vec<&'static str>,
    },
    /// The value exists but is outside the accepted subset.
    Refused {
        /// The value's name.
        given: &'static str,
        /// Why it is refused.
        refused: &'static str,
        /// The names accepted.
        choices: Vec<&'static str>,
    },
}

impl fmt::Display for NameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NameError::Unknown { given, choices } => {
                write!(f, "unknown value `{given}`; choose one of: {}", choices.join(", "))
            }
            NameError::Refused { given, refused, choices } => write!(
                f,
                "unknown value `{given}` here ({refused}); choose one of: {}",
                choices.join(", ")
            ),
        }
    }
}

impl std::error::Error for NameError {}

impl<T: Named> NameParser<T> {
    /// The accepted values, in [`Named::ALL`] order.
    pub fn values(&self) -> impl Iterator<Item = T> + '_ {
        T::ALL.iter().copied().filter(|&v| (self.accepts)(v))
    }

    /// The accepted names.
    pub fn names(&self) -> Vec<&'static str> {
        self.values().map(T::name).collect()
    }

    /// `text` as an accepted value.
    ///
    /// # Errors
    /// [`NameError::Unknown`] for no value's name, [`NameError::Refused`] for a value outside
    /// the subset.
    pub fn parse(&self, text: &str) -> Result<T, NameError> {
        match text.parse::<T>() {
            Ok(v) if (self.accepts)(v) => Ok(v),
            Ok(v) => Err(NameError::Refused {
                given: v.name(),
                refused: self.refused,
                choices: self.names(),
            }),
            Err(_) => Err(NameError::Unknown { given: text.to_owned(), choices: self.names() }),
        }
    }
}
