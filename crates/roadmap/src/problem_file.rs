//! The planning problem file of the shared exchange format (JSON): a mesh, the robot radius,
//! the step, the bounds, a start, goals with one tolerance, an iteration budget and seeds.
//!
//! ```json
//! {"name": "floorplan", "mesh": "floorplan.obj", "robot_radius": 0.3, "max_step": 1.0,
//!  "bounds": {"min": [0, 0, 0], "max": [20, 15, 2.5]}, "start": [10, 7.5, 1.25],
//!  "goals": [[1.5, 1.5, 1.25], [18.5, 13.5, 1.25]], "goal_tolerance": 0.5,
//!  "iterations": 1000, "seeds": [0, 1, 2]}
//! ```
//!
//! `mesh` is relative to the file (or absolute); `name` defaults to `problem`, `seeds` to
//! `[0]`; unknown keys are ignored, as the format asks. The file is read as it is: whether the
//! numbers make a valid space is decided by [`ProblemFile::space`].
//!
//! ```
//! use roadmap::ProblemFile;
//! use std::path::Path;
//!
//! let text = r#"{"mesh": "m.obj", "robot_radius": 0.3, "max_step": 1,
//!     "bounds": {"min": [0, 0, 0], "max": [4, 4, 2]}, "start": [1, 1, 1],
//!     "goals": [[3, 3, 1]], "goal_tolerance": 0.5, "iterations": 500}"#;
//! let p = ProblemFile::parse(text, Path::new("bench"))?;
//! assert_eq!(p.mesh, Path::new("bench/m.obj"));
//! assert_eq!(p.query(&p.goals).goals[0].tolerance, 0.5);
//! assert!(p.space().is_ok());
//! # Ok::<(), roadmap::ProblemFileError>(())
//! ```

use std::path::{Path, PathBuf};

use patch_core::{Aabb, Point3, Real};
use serde_json::Value;

use crate::space::{Goal, PlanningSpace, Problem, SpaceError};

/// The largest iteration budget a file may ask for.
pub const MAX_ITERATIONS: u64 = 1_000_000_000;

/// A planning problem read from its JSON file.
#[derive(Clone, Debug, PartialEq)]
pub struct ProblemFile {
    /// The problem's name (`problem` when the file has none).
    pub name: String,
    /// The mesh, resolved against the file's folder.
    pub mesh: PathBuf,
    /// Radius of the spherical robot, metres.
    pub robot_radius: Real,
    /// Longest edge a tree planner adds, metres.
    pub max_step: Real,
    /// Where states may lie.
    pub bounds: Aabb,
    /// The start.
    pub start: Point3,
    /// The goal centres (regions of interest).
    pub goals: Vec<Point3>,
    /// A goal is reached by a vertex within this distance of its centre.
    pub goal_tolerance: Real,
    /// The iteration budget (at most [`MAX_ITERATIONS`]).
    pub iterations: u64,
    /// One run per seed.
    pub seeds: Vec<u64>,
}

/// Why a problem file could not be read. Every message names the file's key.
#[derive(Debug, thiserror::Error)]
pub enum ProblemFileError {
    /// The file could not be read.
    #[error("reading {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What failed.
        source: std::io::Error,
    },
    /// The text is not JSON.
    #[error("the problem is not JSON: {0}")]
    Json(#[from] serde_json::Error),
    /// A key is missing or has the wrong type or value.
    #[error("`{key}` {problem}")]
    Key {
        /// The key, with its path (`bounds.min`, `goals[2]`).
        key: String,
        /// What is wrong with it.
        problem: &'static str,
    },
}

fn key_error(key: impl Into<String>, problem: &'static str) -> ProblemFileError {
    ProblemFileError::Key { key: key.into(), problem }
}

fn point(v: Option<&Value>, key: &str) -> Result<Point3, ProblemFileError> {
    let a = v.ok_or_else(|| key_error(key, "is missing"))?;
    let a = a.as_array().ok_or_else(|| key_error(key, "is not an array"))?;
    let c: Option<Vec<Real>> = a.iter().map(Value::as_f64).collect();
    match c.as_deref() {
        Some(&[x, y, z]) if [x, y, z].iter().all(|c| c.is_finite()) => Ok(Point3::new(x, y, z)),
        _ => Err(key_error(key, "is not three finite numbers")),
    }
}

fn number(v: &Value, key: &str) -> Result<Real, ProblemFileError> {
    v.get(key).and_then(Value::as_f64).ok_or_else(|| key_error(key, "is missing or not a number"))
}

impl ProblemFile {
    /// Reads the file at `path`; the mesh is resolved against its folder.
    ///
    /// # Errors
    /// [`ProblemFileError`] naming the file, the JSON error or the key.
    pub fn read(path: &Path) -> Result<ProblemFile, ProblemFileError> {
        let text = std::fs::read_to_string(path)
            .map_err(|source| ProblemFileError::Io { path: path.to_owned(), source })?;
        ProblemFile::parse(&text, path.parent().unwrap_or(Path::new(".")))
    }

    /// Parses the JSON `text`; a relative mesh path is joined to `dir`.
    ///
    /// # Errors
    /// [`ProblemFileError::Json`] for text that is not JSON, [`ProblemFileError::Key`] for a
    /// missing key or a value of the wrong type (points must be three finite numbers, the
    /// iterations a whole number up to [`MAX_ITERATIONS`], seeds non-negative integers).
    pub fn parse(text: &str, dir: &Path) -> Result<ProblemFile, ProblemFileError> {
        let v: Value = serde_json::from_str(text)?;
        if !v.is_object() {
            return Err(key_error("(top level)", "is not an object"));
        }
        let mesh = v
            .get("mesh")
            .and_then(Value::as_str)
            .ok_or_else(|| key_error("mesh", "is missing or not a string"))?;
        let bounds = v.get("bounds").ok_or_else(|| key_error("bounds", "is missing"))?;
        let goals = v
            .get("goals")
            .and_then(Value::as_array)
            .ok_or_else(|| key_error("goals", "is missing or not an array"))?
            .iter()
            .enumerate()
            .map(|(i, g)| point(Some(g), &format!("goals[{i}]")))
            .collect::<Result<_, _>>()?;
        let seeds = match v.get("seeds") {
            None => vec![0],
            Some(s) => s
                .as_array()
                .ok_or_else(|| key_error("seeds", "is not an array"))?
                .iter()
                .map(|x| {
                    x.as_u64().ok_or_else(|| {
                        key_error("seeds", "holds a value that is not a non-negative integer")
                    })
                })
                .collect::<Result<_, _>>()?,
        };
        let iterations = number(&v, "iterations")?;
        if !(iterations >= 0.0 && iterations.fract() == 0.0 && iterations <= MAX_ITERATIONS as Real)
        {
            return Err(key_error("iterations", "must be a whole number from 0 to 10⁹"));
        }
        Ok(ProblemFile {
            name: v.get("name").and_then(Value::as_str).unwrap_or("problem").to_owned(),
            mesh: dir.join(mesh),
            robot_radius: number(&v, "robot_radius")?,
            max_step: number(&v, "max_step")?,
            bounds: Aabb::new(
                point(bounds.get("min"), "bounds.min")?,
                point(bounds.get("max"), "bounds.max")?,
            ),
            start: point(v.get("start"), "start")?,
            goals,
            goal_tolerance: number(&v, "goal_tolerance")?,
            iterations: iterations as u64,
            seeds,
        })
    }

    /// The planning space of the problem (its bounds, robot radius and step).
    ///
    /// # Errors
    /// [`SpaceError`] when they do not make a space (an empty box, a radius or step that is not
    /// positive and finite).
    pub fn space(&self) -> Result<PlanningSpace, SpaceError> {
        PlanningSpace::new(self.bounds, self.robot_radius, self.max_step)
    }

    /// The query from the start to `goals`, each a ball of the problem's tolerance.
    pub fn query(&self, goals: &[Point3]) -> Problem {
        Problem {
            start: self.start,
            goals: goals
                .iter()
                .map(|&center| Goal { center, tolerance: self.goal_tolerance })
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"{"name": "n", "mesh": "m.obj", "robot_radius": 0.3, "max_step": 1.0,
        "bounds": {"min": [0, 0, 0], "max": [20, 15, 2.5]}, "start": [10, 7.5, 1.25],
        "goals": [[1.5, 1.5, 1.25], [18.5, 1.5, 1.25]], "goal_tolerance": 0.5,
        "iterations": 1000, "seeds": [3, 4], "extra": {"ignored": true}}"#;

    fn with(key: &str, value: &str) -> String {
        let mut v: Value = serde_json::from_str(GOOD).unwrap();
        if value.is_empty() {
            v.as_object_mut().unwrap().remove(key);
        } else {
            v[key] = serde_json::from_str(value).unwrap();
        }
        v.to_string()
    }

    #[test]
    fn a_good_file_reads_with_defaults_and_unknown_keys_ignored() {
        let p = ProblemFile::parse(GOOD, Path::new("/b")).unwrap();
        assert_eq!(p.name, "n");
        assert_eq!(p.mesh, Path::new("/b/m.obj"));
        assert_eq!((p.goals.len(), p.iterations, p.seeds.clone()), (2, 1000, vec![3, 4]));
        assert_eq!(p.bounds.max, Point3::new(20.0, 15.0, 2.5));
        let q = p.query(&p.goals[1..]);
        assert_eq!((q.start, q.goals.len(), q.goals[0].tolerance), (p.start, 1, 0.5));
        let p = ProblemFile::parse(&with("seeds", ""), Path::new("b")).unwrap();
        assert_eq!(p.seeds, vec![0]);
        let abs = ProblemFile::parse(&with("mesh", r#""/abs/m.obj""#), Path::new("b")).unwrap();
        assert_eq!(abs.mesh, Path::new("/abs/m.obj"));
    }

    #[test]
    fn every_bad_value_names_its_key() {
        let cases = [
            ("mesh", "", "mesh"),
            ("start", "[1, 2]", "start"),
            ("start", r#"[1, 2, "x"]"#, "start"),
            ("goals", "[[1, 2, 3], [1, 2]]", "goals[1]"),
            ("goals", "7", "goals"),
            ("bounds", r#"{"min": [0, 0, 0]}"#, "bounds.max"),
            ("robot_radius", r#""big""#, "robot_radius"),
            ("iterations", "1.5", "iterations"),
            ("iterations", "-3", "iterations"),
            ("iterations", "1e12", "iterations"),
            ("seeds", "[1, -2]", "seeds"),
            ("goal_tolerance", "", "goal_tolerance"),
        ];
        for (key, value, named) in cases {
            let e = ProblemFile::parse(&with(key, value), Path::new(".")).unwrap_err();
            assert!(e.to_string().starts_with(&format!("`{named}`")), "{key} = {value}: {e}");
        }
        assert!(matches!(ProblemFile::parse("{", Path::new(".")), Err(ProblemFileError::Json(_))));
        assert!(ProblemFile::parse("[1]", Path::new(".")).is_err());
        let missing = ProblemFile::read(Path::new("/no/such/problem.json")).unwrap_err();
        assert!(missing.to_string().contains("/no/such/problem.json"));
    }

    #[test]
    fn a_file_that_reads_may_still_not_make_a_space() {
        let p = ProblemFile::parse(&with("robot_radius", "-1"), Path::new(".")).unwrap();
        assert!(p.space().is_err());
        let p = ProblemFile::parse(&with("max_step", "0"), Path::new(".")).unwrap();
        assert!(p.space().is_err());
    }
}
