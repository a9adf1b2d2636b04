//! The libraries' vocabularies on the command line ([`patch_pipeline::names`]): clap value
//! parsers that accept a vocabulary's names, or a subset of them, and list them with their
//! descriptions in `--help`.

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use patch_pipeline::names::{NameParser, Named};
use std::ffi::OsStr;

/// A library [`NameParser`] as a clap value parser.
#[derive(Copy, Clone)]
pub(crate) struct ClapNames<T: 'static>(pub(crate) NameParser<T>);

/// Every value of `T`.
pub(crate) fn all<T: Named>() -> ClapNames<T> {
    ClapNames(patch_pipeline::names::all())
}

/// The backends that hold patches ([`patch_map::Backend::holds_patches`]).
pub(crate) fn patch_backends() -> ClapNames<patch_map::Backend> {
    ClapNames(patch_pipeline::names::patch_backends())
}

impl<T: Named> ClapNames<T> {
    fn possible(&self) -> impl Iterator<Item = PossibleValue> + '_ {
        self.0.values().map(|v| PossibleValue::new(v.name()).help(v.description()))
    }
}

impl<T: Named> TypedValueParser for ClapNames<T> {
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
        self.0.parse(&name).map_err(|e| cmd.clone().error(clap::error::ErrorKind::InvalidValue, e))
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(self.possible()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;
    use patch_map::Backend;
    use patch_pipeline::names::NameError;
    use roadmap::PlannerKind;

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
        let p = patch_backends().0;
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
