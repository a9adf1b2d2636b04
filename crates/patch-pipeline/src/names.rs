//! The libraries' vocabularies by name, for command lines and configuration files: the
//! backends ([`Backend`]), the planners ([`PlannerKind`]) and this crate's enums, each parsed
//! by its own [`FromStr`]. [`NameParser`] accepts them, or a subset of them, and lists the
//! accepted names; a program wraps it in its argument parser's value parser.

use patch_map::Backend;
use roadmap::PlannerKind;
use std::fmt;
use std::str::FromStr;

/// Defines an enum whose values have a name and a one-line description, with `ALL`, `name`,
/// `description`, [`Display`](fmt::Display), [`FromStr`] (the error lists the names) and
/// [`Named`]: one table per vocabulary.
macro_rules! named_enum {
    (
        $(#[$meta:meta])*
        pub enum $Enum:ident ($what:literal) {
            $( $(#[$vmeta:meta])* $Variant:ident = $name:literal, $description:literal; )+
        }
    ) => {
        $(#[$meta])*
        #[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum $Enum {
            $( $(#[$vmeta])* $Variant, )+
        }

        impl $Enum {
            /// Every value, in the order help texts list them.
            pub const ALL: [$Enum; [$(stringify!($Variant)),+].len()] = [$($Enum::$Variant),+];

            /// The name on command lines and in configuration files.
            pub const fn name(self) -> &'static str {
                match self {
                    $( $Enum::$Variant => $name, )+
                }
            }

            /// One line for help texts.
            pub const fn description(self) -> &'static str {
                match self {
                    $( $Enum::$Variant => $description, )+
                }
            }
        }

        impl std::fmt::Display for $Enum {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.name())
            }
        }

        impl std::str::FromStr for $Enum {
            type Err = $crate::UnknownName;

            fn from_str(name: &str) -> Result<$Enum, $crate::UnknownName> {
                $crate::UnknownName::find($what, &$Enum::ALL, $Enum::name, name)
            }
        }

        impl $crate::names::Named for $Enum {
            const ALL: &'static [$Enum] = &$Enum::ALL;

            fn name(self) -> &'static str {
                $Enum::name(self)
            }

            fn description(self) -> &'static str {
                $Enum::description(self)
            }
        }
    };
}
pub(crate) use named_enum;

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

impl Named for hough_terrain::Method {
    const ALL: &'static [hough_terrain::Method] = &hough_terrain::Method::ALL;

    fn name(self) -> &'static str {
        hough_terrain::Method::name(self)
    }

    fn description(self) -> &'static str {
        hough_terrain::Method::description(self)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::extraction::RegionSource;
    use crate::input::DepthConvention;
    use crate::problem::Mode;
    use crate::terrain::AxesChoice;
    use crate::tof::Method;
    use crate::{MapKind, MapSource, SensorPreset};

    fn round_trips<T: Named + fmt::Display + fmt::Debug>()
    where
        <T as FromStr>::Err: fmt::Display,
    {
        let mut names: Vec<&str> = T::ALL.iter().map(|v| v.name()).collect();
        for &v in T::ALL {
            assert_eq!(v.name().parse::<T>().ok(), Some(v));
            assert_eq!(v.to_string(), v.name());
            assert!(!v.description().is_empty());
        }
        let e = match "no-such-name".parse::<T>() {
            Err(e) => e.to_string(),
            Ok(v) => panic!("parsed {v:?}"),
        };
        assert!(e.contains(&names.join(", ")), "{e}");
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), T::ALL.len(), "one name per value");
    }

    #[test]
    fn every_vocabulary_parses_its_names_and_lists_them_when_it_cannot() {
        round_trips::<Backend>();
        round_trips::<PlannerKind>();
        round_trips::<MapKind>();
        round_trips::<MapSource>();
        round_trips::<SensorPreset>();
        round_trips::<DepthConvention>();
        round_trips::<RegionSource>();
        round_trips::<Mode>();
        round_trips::<AxesChoice>();
        round_trips::<Method>();
    }

    #[test]
    fn a_subset_names_why_it_refuses_the_others() {
        let p = patch_backends();
        assert_eq!(p.parse("trimesh"), Ok(Backend::Trimesh));
        assert!(matches!(p.parse("pointcloud"), Err(NameError::Refused { .. })));
        assert!(matches!(p.parse("octree"), Err(NameError::Unknown { .. })));
        assert!(!p.names().contains(&"pointcloud"));
    }
}
