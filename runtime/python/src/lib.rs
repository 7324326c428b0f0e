//! The Python module `trocar._trocar`, re-exported by the package `trocar` (`python/trocar`).
//!
//! Every function is the command line's own (the library `trocar_cli`): the same descriptions,
//! the same answers and the same error messages, raised as `ValueError`. Matrices are returned as
//! 2-D `numpy.ndarray`s of `float64`, row-major as the command line prints them.

use numpy::{PyArray1, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use trocar_cli::{CliError, MatrixOut, Method, OnOff, RcmOptions, RealArg, SpeedLimit, What};

fn value_error(e: CliError) -> PyErr {
    PyValueError::new_err(e.0)
}

/// The name of a `--what` value, as the command line spells it.
fn what_names() -> Vec<String> {
    use clap::ValueEnum;
    What::value_variants()
        .iter()
        .filter_map(|w| w.to_possible_value())
        .map(|v| v.get_name().to_owned())
        .collect()
}

fn parse_what(what: &str) -> PyResult<What> {
    use clap::ValueEnum;
    What::from_str(what, false).map_err(|_| {
        PyValueError::new_err(format!(
            "what={what:?}: expected one of {}",
            what_names().join(", ")
        ))
    })
}

fn matrix<'py>(py: Python<'py>, m: &MatrixOut) -> PyResult<Bound<'py, PyArray2<f64>>> {
    PyArray2::from_vec2(py, &m.data).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// A robot description: a shipped name (`bidirectional-zy`, `panda-laparoscope`, `four-bar`, …)
/// or a TOML file (its chain may come from a URDF).
#[pyclass(module = "trocar", frozen)]
struct Robot {
    /// What the command line is given: the shipped name, or the file's absolute path.
    source: String,
    name: String,
    mechanism: bool,
    joints: usize,
    params: Vec<(String, f64)>,
}

#[pymethods]
impl Robot {
    /// Loads a robot: a shipped description's name or the path of a TOML description.
    /// Raises `ValueError` with the command line's message (file, line and field) when the
    /// description is invalid.
    #[staticmethod]
    fn load(name_or_path: PathBuf) -> PyResult<Self> {
        let given = name_or_path.to_string_lossy().into_owned();
        // A file is kept by its absolute path, so that the robot still loads after a chdir.
        let source = if name_or_path.is_file() {
            name_or_path
                .canonicalize()
                .map_or(given.clone(), |p| p.to_string_lossy().into_owned())
        } else {
            given
        };
        let description = trocar_cli::robot_info(&source).map_err(value_error)?;
        Ok(Robot {
            source,
            name: description.name,
            mechanism: description.mechanism,
            joints: description.joints,
            params: description.params,
        })
    }

    /// The robot's name (`[robot] name`).
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }

    /// Number of joint values `eval` takes (all joints of a closed mechanism).
    #[getter]
    fn joints(&self) -> usize {
        self.joints
    }

    /// Whether this is a closed mechanism (`eval` then takes `what` in jr, jc, passive, det).
    #[getter]
    fn is_mechanism(&self) -> bool {
        self.mechanism
    }

    /// The parameters and their nominal values.
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in &self.params {
            d.set_item(k, v)?;
        }
        Ok(d)
    }

    /// `trocar eval`: the quantity `what` at the joint values `q`, as a 2-D array (a scalar such
    /// as the manipulability is 1 × 1). `params` overrides parameter values by name; `numeric`
    /// uses the numeric runtime instead of the generated closed forms.
    #[pyo3(signature = (q, what = "jr", params = None, numeric = false))]
    fn eval<'py>(
        &self,
        py: Python<'py>,
        q: Vec<f64>,
        what: &str,
        params: Option<std::collections::BTreeMap<String, f64>>,
        numeric: bool,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let what = parse_what(what)?;
        let params: Vec<(String, f64)> = params.unwrap_or_default().into_iter().collect();
        let source = self.source.clone();
        let m = py
            .detach(move || trocar_cli::eval(&source, &q, &params, what, numeric))
            .map_err(value_error)?;
        matrix(py, &m)
    }

    /// `trocar verify`: the generated closed forms against the numeric runtime and finite
    /// differences at `samples` random configurations. Returns `{"robot", "samples", "passed",
    /// "checks": {name: {"max_error", "tolerance", "passed", "count", "worst_q"}}}`.
    #[pyo3(signature = (samples = 1000, seed = 1))]
    fn verify<'py>(
        &self,
        py: Python<'py>,
        samples: usize,
        seed: u64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let source = self.source.clone();
        let report = py
            .detach(move || trocar_cli::verify(&source, samples, seed, |_| {}))
            .map_err(value_error)?;
        let out = PyDict::new(py);
        out.set_item("robot", &report.robot)?;
        out.set_item("samples", report.samples)?;
        out.set_item("passed", report.passed())?;
        let checks = PyDict::new(py);
        for c in &report.checks {
            let row = PyDict::new(py);
            row.set_item("max_error", c.max_error)?;
            row.set_item("tolerance", c.tolerance)?;
            row.set_item("passed", c.passed())?;
            row.set_item("count", c.count)?;
            row.set_item("worst_q", PyArray1::from_slice(py, &c.worst_q))?;
            checks.set_item(&c.name, row)?;
        }
        out.set_item("checks", checks)?;
        Ok(out)
    }

    /// `trocar generate`: the Rust module of the closed forms, generic over the scalar
    /// (`real="generic"`) or for `"f64"` / `"f32"`.
    #[pyo3(signature = (real = "f64"))]
    fn generate(&self, py: Python<'_>, real: &str) -> PyResult<String> {
        let real = match real {
            "f64" => RealArg::F64,
            "f32" => RealArg::F32,
            "generic" => RealArg::Generic,
            other => {
                return Err(PyValueError::new_err(format!(
                    "real={other:?}: expected \"f64\", \"f32\" or \"generic\""
                )))
            }
        };
        let source = self.source.clone();
        py.detach(move || trocar_cli::generate(&source, real))
            .map_err(value_error)
    }

    fn __repr__(&self) -> String {
        format!("trocar.Robot.load({:?})", self.source)
    }
}

/// `trocar simulate`: runs a scenario (`"1"`–`"4"`, `"exp421"`, `"panda-laparoscope"`, or a
/// closed-chain scenario such as `"four-bar"`) and returns its trace as named columns (`t`
/// first), the columns of the command line's CSV. `method` (`"pinv"`, `"dls"`, `"fi"`; default:
/// the scenario's), `drift_correction` and `max_joint_speed` (rad/s; `None` for no limit; default:
/// the simulations' limit) apply to the RCM scenarios.
#[pyfunction]
#[pyo3(signature = (scenario, method = None, drift_correction = true, max_joint_speed = MaxJointSpeed::Default))]
fn simulate<'py>(
    py: Python<'py>,
    scenario: &str,
    method: Option<&str>,
    drift_correction: bool,
    max_joint_speed: MaxJointSpeed,
) -> PyResult<Bound<'py, PyDict>> {
    let method = match method {
        None => None,
        Some("pinv") => Some(Method::Pinv),
        Some("dls") => Some(Method::Dls),
        Some("fi") => Some(Method::Fi),
        Some(other) => {
            return Err(PyValueError::new_err(format!(
                "method={other:?}: expected \"pinv\", \"dls\" or \"fi\""
            )))
        }
    };
    let options = RcmOptions {
        method,
        drift_correction: if drift_correction {
            OnOff::On
        } else {
            OnOff::Off
        },
        max_joint_speed: match max_joint_speed {
            MaxJointSpeed::Default => None,
            MaxJointSpeed::Unlimited => Some(SpeedLimit::None),
            MaxJointSpeed::At(v) => Some(SpeedLimit::At(v)),
        },
    };
    let scenario = scenario.to_owned();
    let run = py
        .detach(move || trocar_cli::run_simulation(&scenario, &options))
        .map_err(value_error)?;
    let out = PyDict::new(py);
    for (name, values) in run.columns() {
        out.set_item(name, PyArray1::from_vec(py, values))?;
    }
    Ok(out)
}

/// `max_joint_speed` of [`simulate`]: omitted, `None` or a number.
#[derive(Clone, Copy, Debug)]
enum MaxJointSpeed {
    Default,
    Unlimited,
    At(f64),
}

impl<'a, 'py> FromPyObject<'a, 'py> for MaxJointSpeed {
    type Error = PyErr;

    fn extract(ob: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if ob.is_none() {
            Ok(MaxJointSpeed::Unlimited)
        } else {
            Ok(MaxJointSpeed::At(ob.extract::<f64>()?))
        }
    }
}

/// The names of the shipped robots, mechanisms and simulation scenarios, as `trocar list`
/// prints them: `{"robots": [...], "mechanisms": [...], "scenarios": [...]}`.
#[pyfunction]
fn shipped<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
    let s = trocar_cli::shipped();
    let out = PyDict::new(py);
    out.set_item("robots", s.robots)?;
    out.set_item("mechanisms", s.mechanisms)?;
    out.set_item("scenarios", s.scenarios)?;
    Ok(out)
}

/// The quantities `Robot.eval` takes as `what`.
#[pyfunction]
fn quantities() -> Vec<String> {
    what_names()
}

/// trocar: constrained kinematics of robots with a remote centre of motion.
#[pymodule]
fn _trocar(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Robot>()?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(shipped, m)?)?;
    m.add_function(wrap_pyfunction!(quantities, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
