//! The `[simulation]` section of a description: the scenario a description carries for its own
//! robot (`trocar simulate my_arm.toml`), read with the location of every field.
//!
//! ```toml
//! [simulation]
//! trajectory = "circle.csv"    # the tip's reference path, relative to the description's file
//! q0 = [0, -1.5708, 1.5708, -1.5708, -1.5708, 0]   # start configuration, all joints (rad, m)
//! trocar = [0.49, 0.11, 0.23]  # the trocar point (m, base frame); default: F_r's origin at q0
//! method = "dls"               # pinv | dls | fi | qp
//! kp = 5.0                     # position gain (1/s)
//! ko = 10.0                    # orientation gain (1/s)
//! kr = 20.0                    # drift correction gain on the trocar (1/s; 0: off)
//! dls_alpha0 = 0.05            # largest damping of the damped least squares
//! null_space_gain = 10.0       # joint-limit objective on the spare freedom (1/s)
//! max_joint_speed = 2.0        # joint speed limit (rad/s)
//! ```
//!
//! Every number follows the project's number rule ([`crate::validity`]: finite, not subnormal,
//! `|x| ≤ 1e6`); gains are `≥ 0`, the speed limit `> 0`, `q0` has one value per joint. Every
//! error is a [`DescriptionError`] naming the file, line, column and field
//! (`simulation.q0[2]`).

use super::locate::Locator;
use super::parse::{toml_error_of, Ctx};
use super::DescriptionError;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The methods a `[simulation]` section may name.
pub const SIMULATION_METHODS: [&str; 4] = ["pinv", "dls", "fi", "qp"];

/// A description's own simulation: every entry optional, each overridden by what the caller
/// gives (the command line's `--q0`, `--trocar`, `--method`, `--trajectory`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SimulationDesc {
    /// The tip's reference path (a trajectory CSV), resolved against the description's
    /// directory.
    pub trajectory: Option<PathBuf>,
    /// The start configuration, one value per joint.
    pub q0: Option<Vec<f64>>,
    /// The trocar point (m, base frame).
    pub trocar: Option<[f64; 3]>,
    /// The inverse of the task Jacobian: one of [`SIMULATION_METHODS`].
    pub method: Option<String>,
    /// Position gain `K_p` (1/s).
    pub kp: Option<f64>,
    /// Orientation gain `K_o` (1/s).
    pub ko: Option<f64>,
    /// Drift-correction gain `K_r` (1/s); 0 turns the correction off.
    pub kr: Option<f64>,
    /// Largest damping `α0` of the damped least squares (3.44).
    pub dls_alpha0: Option<f64>,
    /// Gain of the joint-limit objective (46) on the spare freedom (1/s).
    pub null_space_gain: Option<f64>,
    /// Joint speed limit (rad/s).
    pub max_joint_speed: Option<f64>,
}

#[derive(Deserialize)]
struct RawDocument {
    simulation: Option<RawSimulation>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSimulation {
    trajectory: Option<String>,
    q0: Option<Vec<f64>>,
    trocar: Option<[f64; 3]>,
    method: Option<String>,
    kp: Option<f64>,
    ko: Option<f64>,
    kr: Option<f64>,
    dls_alpha0: Option<f64>,
    null_space_gain: Option<f64>,
    max_joint_speed: Option<f64>,
}

impl SimulationDesc {
    /// Reads the `[simulation]` section of a description's TOML text (`None` when it has
    /// none) for a robot of `joints` joints; `file` names the description in messages and is
    /// the directory a relative `trajectory` is resolved against.
    pub fn from_toml_str(
        text: &str,
        file: Option<&Path>,
        joints: usize,
    ) -> Result<Option<Self>, DescriptionError> {
        let locator = Locator::new(text);
        let ctx = Ctx {
            file,
            locator: &locator,
        };
        let raw: RawDocument = toml::from_str(text).map_err(|e| toml_error_of(&ctx, text, &e))?;
        let Some(raw) = raw.simulation else {
            return Ok(None);
        };
        let number = |field: String, v: f64| -> Result<f64, DescriptionError> {
            crate::validity::check(v)
                .map(|()| v)
                .map_err(|problem| ctx.err(&field, format!("{v:e} {problem}")))
        };
        let q0 = match raw.q0 {
            None => None,
            Some(q) => {
                if q.len() != joints {
                    return Err(ctx.err(
                        "simulation.q0",
                        format!(
                            "{} values; the robot has {joints} joints (give all joint values, base first)",
                            q.len()
                        ),
                    ));
                }
                for (k, v) in q.iter().enumerate() {
                    number(format!("simulation.q0[{k}]"), *v)?;
                }
                Some(q)
            }
        };
        let trocar = match raw.trocar {
            None => None,
            Some(p) => {
                for (k, v) in p.iter().enumerate() {
                    number(format!("simulation.trocar[{k}]"), *v)?;
                }
                Some(p)
            }
        };
        if let Some(m) = &raw.method {
            if !SIMULATION_METHODS.contains(&m.as_str()) {
                return Err(ctx.err(
                    "simulation.method",
                    format!(
                        "unknown method `{m}` (expected one of: {})",
                        SIMULATION_METHODS.join(", ")
                    ),
                ));
            }
        }
        let gain = |name: &str, v: Option<f64>| -> Result<Option<f64>, DescriptionError> {
            let Some(v) = v else { return Ok(None) };
            let field = format!("simulation.{name}");
            number(field.clone(), v)?;
            if v < 0.0 {
                return Err(ctx.err(&field, format!("{v}: a gain must be ≥ 0")));
            }
            Ok(Some(v))
        };
        let max_joint_speed = match raw.max_joint_speed {
            None => None,
            Some(v) => {
                number("simulation.max_joint_speed".into(), v)?;
                if v <= 0.0 {
                    return Err(ctx.err(
                        "simulation.max_joint_speed",
                        format!("{v}: a speed limit must be positive (rad/s)"),
                    ));
                }
                Some(v)
            }
        };
        let trajectory = match raw.trajectory {
            None => None,
            Some(t) if t.trim().is_empty() => {
                return Err(ctx.err(
                    "simulation.trajectory",
                    "an empty path (give the trajectory CSV, relative to this file)",
                ))
            }
            Some(t) => Some(match file.and_then(Path::parent) {
                Some(dir) if Path::new(&t).is_relative() => lexically_joined(dir, &t),
                _ => PathBuf::from(&t),
            }),
        };
        Ok(Some(SimulationDesc {
            trajectory,
            q0,
            trocar,
            method: raw.method,
            kp: gain("kp", raw.kp)?,
            ko: gain("ko", raw.ko)?,
            kr: gain("kr", raw.kr)?,
            dls_alpha0: gain("dls_alpha0", raw.dls_alpha0)?,
            null_space_gain: gain("null_space_gain", raw.null_space_gain)?,
            max_joint_speed,
        }))
    }

    /// Reads the `[simulation]` section of a description file ([`SimulationDesc::from_toml_str`]).
    pub fn from_toml_file(path: &Path, joints: usize) -> Result<Option<Self>, DescriptionError> {
        let text = DescriptionError::read_file(path)?;
        Self::from_toml_str(&text, Some(path), joints)
    }
}

/// `dir` joined with the relative path `rel`, each `..` taking off the directory before it
/// where there is one (`robots/../paths/c.csv` is `paths/c.csv`): the path as messages show it.
fn lexically_joined(dir: &Path, rel: &str) -> PathBuf {
    use std::path::Component;
    let mut out = PathBuf::new();
    for c in dir.join(rel).components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir
                if matches!(out.components().next_back(), Some(Component::Normal(_))) =>
            {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(body: &str) -> Result<Option<SimulationDesc>, DescriptionError> {
        let text = format!("[robot]\nname = \"arm\"\n\n[simulation]\n{body}");
        SimulationDesc::from_toml_str(&text, Some(Path::new("/robots/arm.toml")), 3)
    }

    #[test]
    fn a_section_is_read_and_its_path_resolved_against_the_file() {
        let s = read("trajectory = \"paths/c.csv\"\nq0 = [0, 0.5, -1]\nmethod = \"qp\"\nkp = 4\n")
            .unwrap()
            .unwrap();
        assert_eq!(s.trajectory, Some(PathBuf::from("/robots/paths/c.csv")));
        let up = read("trajectory = \"../paths/./c.csv\"\n")
            .unwrap()
            .unwrap();
        assert_eq!(up.trajectory, Some(PathBuf::from("/paths/c.csv")));
        assert_eq!(s.q0, Some(vec![0.0, 0.5, -1.0]));
        assert_eq!(s.method.as_deref(), Some("qp"));
        assert_eq!(s.kp, Some(4.0));
        assert_eq!(s.ko, None);
        let none = SimulationDesc::from_toml_str("[robot]\nname = \"a\"\n", None, 3).unwrap();
        assert_eq!(none, None);
    }

    #[test]
    fn bad_values_name_the_file_line_and_field() {
        // (body, field, line, words of the message)
        let cases = [
            (
                "q0 = [0, 1]\n",
                "simulation.q0",
                5,
                "2 values; the robot has 3 joints",
            ),
            ("q0 = [0, 1, 2e7]\n", "simulation.q0[2]", 5, "beyond"),
            (
                "trocar = [0, 1e-320, 0]\n",
                "simulation.trocar[1]",
                5,
                "subnormal",
            ),
            ("kp = 5\nko = -1\n", "simulation.ko", 6, "must be ≥ 0"),
            (
                "method = \"newton\"\n",
                "simulation.method",
                5,
                "unknown method `newton`",
            ),
            (
                "max_joint_speed = 0\n",
                "simulation.max_joint_speed",
                5,
                "must be positive",
            ),
            ("gain = 3\n", "simulation.gain", 5, "unknown key `gain`"),
            ("kp = \"fast\"\n", "simulation.kp", 5, ""),
            (
                "trajectory = \"\"\n",
                "simulation.trajectory",
                5,
                "empty path",
            ),
        ];
        for (body, field, line, words) in cases {
            let e = read(body).unwrap_err();
            assert_eq!(e.field, field, "{body}: {e}");
            assert_eq!(e.line, Some(line), "{body}: {e}");
            assert_eq!(e.file.as_deref(), Some(Path::new("/robots/arm.toml")));
            assert!(e.to_string().contains(words), "{body}: {e}");
        }
    }
}
