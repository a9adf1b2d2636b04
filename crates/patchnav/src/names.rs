//! The libraries' vocabularies on the command line and in configuration files: the backends
//! ([`Backend`]) and the planners ([`PlannerKind`]) by their names, parsed by their own
//! [`FromStr`]. [`NameParser`] is the clap value parser that accepts them, or a subset of
//! them, and lists them with their descriptions in `--help`.

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use patch_map::Backend;
use patch_pipeline::experiment::extraction::RegionSource;
use patch_pipeline::input::DepthConvention;
use patch_pipeline::problem::Mode;
use patch_pipeline::terrain::AxesChoice;
use patch_pipeline::tof::Method;
use patch_pipeline::{MapKind, MapSource, SensorPreset};
use roadmap::PlannerKind;
use std::ffi::OsStr;
use std::fmt;
use std::str::FromStr;

/// A library enum with a name and a description per value.
pub(crate) trait Named: Copy + PartialEq + FromStr + Send + Sync + 'static {
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
pub(crate) struct NameParser<T: 'static> {
    accepts: fn(T) -> bool,
    /// Why the others are refused.
    refused: &'static str,
}

/// Every value of `T`.
pub(crate) fn all<T: Named>() -> NameParser<T> {
    NameParser { accepts: |_| true, refused: "" }
}

/// The values of `T` that `accepts` lets through; `refused` says why the others are not ("it
/// holds points, not patches").
pub(crate) fn only<T: Named>(accepts: fn(T) -> bool, refused: &'static str) -> NameParser<T> {
    NameParser { accepts, refused }
}

/// The backends that hold patches ([`Backend::holds_patches`]).
pub(crate) fn patch_backends() -> NameParser<Backend> {
    only(Backend::holds_patches, "it holds points, not patches")
}

/// A name refused by a [`NameParser`]: no value's, or one outside its subset.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum NameError {
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
    pub(crate) fn values(&self) -> impl Iterator<Item = T> + '_ {
        T::ALL.iter().copied().filter(|&v| (self.accepts)(v))
    }

    /// The accepted names.
    pub(crate) fn names(&self) -> Vec<&'static str> {
        self.values().map(T::name).collect()
    }

    /// `text` as an accepted value.
    ///
    /// # Errors
    /// [`NameError::Unknown`] for no value's name, [`NameError::Refused`] for a value outside
    /// the subset.
    pub(crate) fn parse(&self, text: &str) -> Result<T, NameError> {
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

    fn possible(&self) -> impl Iterator<Item = PossibleValue> + '_ {
        self.values().map(|v| PossibleValue::new(v.name()).help(v.description()))
    }
}

impl<T: Named> TypedValueParser for NameParser<T> {
    type Value = T;

    /// Clap's own check against the accepted names first, so a wrong name gets clap's message
    /// (the possible values, a similar one); then the library's parser.
    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &OsStr,
    ) -> Result<T, clap::Error> {
        let name = PossibleValuesParser::new(self.possible()).parse_ref(cmd, arg, value)?;
        self.parse(&name).map_err(|e| cmd.clone().error(clap::error::ErrorKind::InvalidValue, e))
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(self.possible()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser, Debug)]
    struct Cli {
        #[arg(long, value_parser = all::<Backend>(), default_value_t = Backend::BBox6d)]
        backend: Backend,
        #[arg(long, value_parser = patch_backends())]
        patches: Option<Backend>,
        #[arg(long, value_parser = all::<PlannerKind>(), value_delimiter = ',')]
        planners: Vec<PlannerKind>,
    }

    fn cli(args: &[&str]) -> Result<Cli, clap::Error> {
        Cli::try_parse_from([&["cli"], args].concat())
    }

    #[test]
    fn every_name_parses_and_others_get_the_list() {
        assert_eq!(cli(&[]).unwrap().backend, Backend::BBox6d);
        for b in Backend::ALL {
            assert_eq!(cli(&["--backend", b.name()]).unwrap().backend, b);
        }
        let names: Vec<&str> = PlannerKind::ALL.iter().map(|k| k.name()).collect();
        assert_eq!(cli(&["--planners", &names.join(",")]).unwrap().planners, PlannerKind::ALL);
        let e = cli(&["--backend", "octree"]).unwrap_err().to_string();
        assert!(Backend::ALL.iter().all(|b| e.contains(b.name())), "{e}");
        let e = cli(&["--planners", "rrt,astar"]).unwrap_err().to_string();
        assert!(e.contains("astar") && e.contains("lazy-prm"), "{e}");
    }

    #[test]
    fn a_subset_refuses_the_others_by_name() {
        assert_eq!(cli(&["--patches", "rapier"]).unwrap().patches, Some(Backend::Rapier));
        let e = cli(&["--patches", "pointcloud"]).unwrap_err().to_string();
        assert!(e.contains("pointcloud") && e.contains("polygon, bbox6d, trimesh, rapier"), "{e}");
        let p = patch_backends();
        assert_eq!(p.parse("trimesh"), Ok(Backend::Trimesh));
        assert_eq!(
            p.parse("pointcloud").unwrap_err().to_string(),
            "unknown value `pointcloud` here (it holds points, not patches); choose one of: \
             polygon, bbox6d, trimesh, rapier"
        );
        assert!(matches!(p.parse("bullet"), Err(NameError::Unknown { .. })));
    }

    #[test]
    fn help_lists_every_name_with_its_description() {
        use clap::CommandFactory;
        let help = Cli::command().render_long_help().to_string();
        for b in Backend::ALL {
            assert!(help.contains(&format!("{}:", b.name())), "{help}");
            assert!(help.contains(b.description()), "{help}");
        }
        for k in PlannerKind::ALL {
            assert!(help.contains(&format!("{}:", k.name())), "{help}");
        }
    }
}
