//! The Python module `trocar._trocar`, re-exported by the package `trocar` (`python/trocar`).
//!
//! A shell over the library `trocar_api`, as the command line is: the same descriptions, the same
//! answers and the same error messages, raised as `ValueError`. A `Robot` is loaded and derived
//! once and keeps its compiled programs; matrices are returned as `numpy.ndarray`s of `float64`,
//! row-major as the command line prints them.

use numpy::ndarray::{Array1, Array2};
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2,
};
use pyo3::exceptions::{PyMemoryError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString, PyTuple};
use std::collections::BTreeMap;
use std::path::PathBuf;
use trocar_api::{ControllerOptions, Function, Method, RcmOptions, SpeedLimit, Target};

/// The library's error as a `ValueError`: its message names the arguments as the library does,
/// which are this module's keyword arguments (`q`, `params`, `what`, `q0`, `trocar`, ...).
fn value_error(e: trocar_api::Error) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// Most joint values [`with_joints`] holds on the stack (more are copied to the heap).
const STACK_JOINTS: usize = 64;

/// Calls `f` with the joint values `q`; a contiguous 1-D `float64` array of at most
/// [`STACK_JOINTS`] values is copied to the stack at once, anything else goes through
/// [`joints`].
fn with_joints<R>(q: &Bound<'_, PyAny>, f: impl FnOnce(&[f64]) -> PyResult<R>) -> PyResult<R> {
    if let Ok(a) = q.cast::<PyArray1<f64>>() {
        // SAFETY: `as_slice` requires that nothing writes the array's data while the slice
        // lives. The slice lives for the one copy below, during which this thread holds the GIL
        // (through `q`) and runs no Python code, so no Python code can write the array; nothing
        // in this module writes an array it did not create. (It returns an error instead of a
        // slice for a non-contiguous array, which then goes through `joints`.)
        if let Ok(s) = unsafe { a.as_slice() } {
            if s.len() <= STACK_JOINTS {
                let mut buf = [0.0; STACK_JOINTS];
                buf[..s.len()].copy_from_slice(s);
                return f(&buf[..s.len()]);
            }
        }
    }
    f(&joints(q)?)
}

/// Joint values: a 1-D numpy array of `float64` (read in place) or any sequence of numbers.
fn joints(q: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    if let Ok(a) = q.cast::<PyArray1<f64>>() {
        // A contiguous array is copied at once; a strided one goes through the sequence path.
        if let Ok(v) = a.to_vec() {
            return Ok(v);
        }
    }
    if let Ok(a) = q.extract::<PyReadonlyArray1<'_, f64>>() {
        return Ok(a.as_array().to_vec());
    }
    q.extract::<Vec<f64>>()
}

fn method(name: &str) -> PyResult<Method> {
    match name {
        "pinv" => Ok(Method::Pinv),
        "dls" => Ok(Method::Dls),
        "fi" => Ok(Method::Fi),
        "qp" => Ok(Method::Qp),
        other => Err(PyValueError::new_err(format!(
            "method={other:?}: expected \"pinv\", \"dls\", \"fi\" or \"qp\""
        ))),
    }
}

/// `trocar register-port`: the port located from joint positions of the instrument pivoting
/// about it (one row of `robot.joints` values per pose): the point nearest to the shaft's lines
/// (`trocar::port`), refused where the lines spread less than `least_spread` degrees. Returns
/// a dict: `port` (3, base frame, m), `covariance` (3 × 3, m²), `residual` (m, the lines'
/// root-mean-square distance from it), `spread` (degrees), `lines`. `forgetting` (in (0, 1])
/// weighs each pose `1/λ` times the one before.
#[pyfunction]
#[pyo3(signature = (robot, joints, least_spread = 2.0, forgetting = None))]
fn register_port<'py>(
    py: Python<'py>,
    robot: &Robot,
    joints: Vec<Vec<f64>>,
    least_spread: f64,
    forgetting: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let rows = trocar_api::JointRows {
        lines: (1..=joints.len()).collect(),
        rows: joints,
    };
    let e = trocar_api::register_port(&robot.inner, &rows, least_spread.to_radians(), forgetting)
        .map_err(value_error)?;
    let out = PyDict::new(py);
    out.set_item("port", [e.point.x, e.point.y, e.point.z])?;
    let covariance: Vec<[f64; 3]> = (0..3)
        .map(|r| {
            [
                e.covariance[(r, 0)],
                e.covariance[(r, 1)],
                e.covariance[(r, 2)],
            ]
        })
        .collect();
    out.set_item("covariance", covariance)?;
    out.set_item("residual", e.residual)?;
    out.set_item("spread", e.spread.to_degrees())?;
    out.set_item("lines", e.lines)?;
    Ok(out)
}

/// A reference as the dict `Controller.step` takes: `position`, `rotation` (3 × 3 or `None`),
/// `velocity`, `angular_velocity` (base frame).
fn target_dict<'py>(py: Python<'py>, r: &trocar_api::Target) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("position", PyArray1::from_slice(py, &r.position))?;
    match r.rotation {
        Some(rot) => {
            let rot = Array2::from_shape_fn((3, 3), |(i, j)| rot[i][j]);
            out.set_item("rotation", rot.into_pyarray(py))?;
        }
        None => out.set_item("rotation", py.None())?,
    }
    out.set_item("velocity", PyArray1::from_slice(py, &r.velocity))?;
    out.set_item(
        "angular_velocity",
        PyArray1::from_slice(py, &r.angular_velocity),
    )?;
    Ok(out)
}

/// A tip trajectory read from a CSV (`t,x,y,z` and `roll` or `qw,qx,qy,qz`), for a loop of
/// one's own that follows it as `trocar simulate ROBOT --trajectory F.csv` does.
#[pyclass(module = "trocar", frozen)]
struct Trajectory {
    inner: trocar_api::Trajectory,
}

#[pymethods]
impl Trajectory {
    /// Reads and checks the CSV at `path` (errors name the file, the line and the column).
    #[staticmethod]
    fn load(path: std::path::PathBuf) -> PyResult<Self> {
        let inner = trocar_api::Trajectory::from_csv(&path).map_err(value_error)?;
        let name = path.display().to_string();
        inner.check(&name).map_err(value_error)?;
        Ok(Trajectory { inner })
    }

    /// The controller's reference at time `t` (s), as `trocar simulate ROBOT --trajectory`
    /// builds it: the position linear between rows and its slope fed forward; a roll turned
    /// through the trocar with its angular velocity by a central difference; quaternions by
    /// slerp. `start_rotation` (3 × 3) and `start_position` are the tip's pose at the start,
    /// `trocar` the trocar point. A dict for `Controller.step`: `position`, `rotation` (`None`
    /// for a path of positions only: the tip keeps its orientation), `velocity`,
    /// `angular_velocity`.
    fn reference<'py>(
        &self,
        py: Python<'py>,
        t: f64,
        start_rotation: [[f64; 3]; 3],
        start_position: [f64; 3],
        trocar: [f64; 3],
    ) -> PyResult<Bound<'py, PyDict>> {
        let finite = t.is_finite()
            && start_rotation.iter().flatten().all(|v| v.is_finite())
            && start_position.iter().chain(&trocar).all(|v| v.is_finite());
        if !finite {
            return Err(PyValueError::new_err(
                "reference: t, start_rotation, start_position and trocar must be finite numbers",
            ));
        }
        check_rotation(&start_rotation)?;
        let r = self
            .inner
            .reference_from(t, &start_rotation, &start_position, &trocar);
        target_dict(py, &r)
    }
}

/// The port's mode of `simulate("panda-breathing", port=...)`.
fn port_mode(name: &str) -> PyResult<trocar_api::PortMode> {
    trocar_api::PortMode::from_name(name).ok_or_else(|| {
        PyValueError::new_err(format!(
            "port={name:?}: expected \"fixed\", \"known\", \"estimated\" or \"registered\""
        ))
    })
}

/// What `eval` and `eval_many` are asked for: one quantity, or several in one program.
enum What {
    One(Function),
    Several(Vec<Function>),
}

/// A new `rows × cols` array holding `data` row by row.
fn matrix<'py>(
    py: Python<'py>,
    rows: usize,
    cols: usize,
    data: &[f64],
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    if data.len() != rows * cols {
        return Err(PyValueError::new_err(format!(
            "{} values for a {rows} × {cols} matrix",
            data.len()
        )));
    }
    // SAFETY: `new` leaves the data uninitialised; every entry is written just below (the
    // lengths were checked above) before the array is handed to Python.
    let out = unsafe { PyArray2::<f64>::new(py, [rows, cols], false) };
    // SAFETY: `out` was created just above as a new, C-contiguous array and has not been handed
    // to Python or borrowed yet, so this is the only reference to its data while the slice
    // lives (for the one copy).
    unsafe { out.as_slice_mut() }
        .map_err(|e| PyValueError::new_err(e.to_string()))?
        .copy_from_slice(data);
    Ok(out)
}

/// A new, uninitialised, C-ordered `count × rows × cols` array of `float64`, made by
/// `numpy.empty`: an array that cannot be allocated raises `MemoryError` with numpy's message (its
/// size and shape) instead of ending the interpreter.
///
/// # Safety
///
/// The caller writes every entry before the array is handed to Python, as with
/// [`PyArray3::new`].
unsafe fn empty3<'py>(
    py: Python<'py>,
    count: usize,
    rows: usize,
    cols: usize,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let array = py
        .import("numpy")?
        .getattr("empty")?
        .call1(((count, rows, cols), "float64"))?;
    Ok(array.cast_into::<PyArray3<f64>>()?)
}

/// The configurations `Q` of `eval_many`: a 2-D `float64` array read in place, or anything numpy
/// converts to one (`numpy.asarray(Q, dtype="float64")`: integer arrays, nested lists), as `eval`
/// takes integers.
fn configurations<'py>(
    py: Python<'py>,
    q: &Bound<'py, PyAny>,
) -> PyResult<PyReadonlyArray2<'py, f64>> {
    if let Ok(a) = q.extract::<PyReadonlyArray2<'py, f64>>() {
        return Ok(a);
    }
    let converted = py
        .import("numpy")?
        .getattr("asarray")?
        .call1((q, "float64"))?;
    let ndim: usize = converted.getattr("ndim")?.extract()?;
    if ndim != 2 {
        return Err(PyValueError::new_err(format!(
            "Q: a 2-D array of joint values, one row per configuration (N, joints); got {ndim} dimension{}",
            if ndim == 1 { "" } else { "s" }
        )));
    }
    converted.extract::<PyReadonlyArray2<'py, f64>>()
}

thread_local! {
    /// The result of a fused evaluation before it is copied to its arrays, kept per thread.
    static RESULT: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// A robot or closed mechanism: a shipped name (`bidirectional-zy`, `panda-laparoscope`,
/// `four-bar`, …) or a TOML file (its chain may come from a URDF). Loaded, derived and compiled
/// once; every evaluation after that runs the compiled closed forms.
#[pyclass(module = "trocar", frozen)]
struct Robot {
    inner: trocar_api::Robot,
    nominal: Vec<f64>,
    /// Every name `what` may take for this robot (catalogue and short names), resolved once,
    /// sorted by name.
    names: Vec<(String, Function)>,
}

impl Robot {
    /// A loaded robot with its nominal parameters and the names of its quantities.
    fn wrap(inner: trocar_api::Robot) -> PyResult<Self> {
        let nominal = inner.params().into_iter().map(|(_, v)| v).collect();
        let mut names: Vec<(String, Function)> = inner
            .quantities()
            .into_iter()
            .flat_map(|f| [(f.name().to_string(), f), (f.short_name().to_string(), f)])
            .collect();
        names.sort();
        names.dedup();
        Ok(Robot {
            inner,
            nominal,
            names,
        })
    }

    fn values(&self, params: Option<BTreeMap<String, f64>>) -> PyResult<Vec<f64>> {
        match params {
            None => Ok(self.nominal.clone()),
            Some(p) => {
                let p: Vec<(String, f64)> = p.into_iter().collect();
                self.inner.param_values(&p).map_err(value_error)
            }
        }
    }

    /// `what` as `eval` takes it: `None` for `"jr"`, one name, or a tuple or list of names.
    fn what(&self, what: Option<&Bound<'_, PyAny>>) -> PyResult<What> {
        let Some(what) = what else {
            return Ok(What::One(self.function("jr")?));
        };
        if let Ok(name) = what.cast::<PyString>() {
            return Ok(What::One(self.function(name.to_str()?)?));
        }
        let not_names = || {
            PyTypeError::new_err(format!(
                "what: a quantity's name (\"jr\", \"jb0i\", ...) or a tuple or list of names \
                 (strings), not {}",
                what.repr()
                    .map_or_else(|_| "this value".to_string(), |r| r.to_string())
            ))
        };
        let mut functions = Vec::with_capacity(4);
        let mut add = |name: Bound<'_, PyAny>| -> PyResult<()> {
            let name = name.cast_into::<PyString>().map_err(|_| not_names())?;
            let function = self.function(name.to_str()?)?;
            functions.push(function);
            Ok(())
        };
        if let Ok(tuple) = what.cast::<PyTuple>() {
            tuple.iter().try_for_each(&mut add)?;
        } else if let Ok(list) = what.cast::<PyList>() {
            list.iter().try_for_each(&mut add)?;
        } else {
            return Err(not_names());
        }
        trocar_api::Robot::check_outputs(&functions).map_err(value_error)?;
        Ok(What::Several(functions))
    }

    /// `function` at the `count` configurations `flat` (one after the other), as `eval_many`
    /// of one name returns it.
    fn many<'py>(
        &self,
        py: Python<'py>,
        function: Function,
        flat: &[f64],
        count: usize,
        values: &[f64],
    ) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let e = self.inner.evaluator(function).map_err(value_error)?;
        let (rows, cols) = (e.rows(), e.cols());
        // SAFETY: `empty3` leaves the data uninitialised; the array is handed to Python only
        // after `eval_many` has written every entry of every configuration (each output at its
        // own row-major position, they cover the matrix, and a transform's constant last row),
        // and is dropped unread otherwise.
        let out = unsafe { empty3(py, count, rows, cols) }?;
        {
            // SAFETY: `out` was created just above as a new, C-contiguous array and has not
            // been handed to Python or borrowed yet, so this is the only reference to its data
            // while the slice lives (it ends with this block). Python code that runs while the
            // GIL is released below cannot reach `out`, which no Python object refers to yet.
            let data =
                unsafe { out.as_slice_mut() }.map_err(|e| PyValueError::new_err(e.to_string()))?;
            py.detach(|| e.eval_many(flat, values, data))
                .map_err(value_error)?;
        }
        Ok(out)
    }

    /// `function` at `q` as a new array, from the numeric runtime (`numeric`) or from the
    /// library's checked evaluation (a closed mechanism's closed forms): `eval`'s path where no
    /// compiled program of a serial robot is run.
    fn evaluated<'py>(
        &self,
        py: Python<'py>,
        function: Function,
        q: &[f64],
        params: &[(String, f64)],
        numeric: bool,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let m = if numeric {
            self.inner.eval_numeric(function, q, params)
        } else {
            self.inner.eval(function, q, params)
        }
        .map_err(value_error)?;
        matrix(py, m.rows, m.cols, &m.data)
    }

    /// [`Robot::eval`] of one function.
    fn eval_one<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        function: Function,
        params: Option<BTreeMap<String, f64>>,
        numeric: bool,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        with_joints(q, |q| {
            if numeric || self.inner.is_mechanism() {
                let p: Vec<(String, f64)> = params.unwrap_or_default().into_iter().collect();
                return self.evaluated(py, function, q, &p, numeric);
            }
            self.inner.check_q(q).map_err(value_error)?;
            let e = self.inner.evaluator(function).map_err(value_error)?;
            // SAFETY: `new` leaves the data uninitialised; the array is handed to Python only
            // after `eval_into` has written every entry (each output at its own row-major
            // position, they cover the matrix, and a transform's constant last row), and is
            // dropped unread otherwise.
            let out = unsafe { PyArray2::<f64>::new(py, [e.rows(), e.cols()], false) };
            let written = {
                // SAFETY: `out` was created just above as a new, C-contiguous array of
                // `rows × cols` values and has not been handed to Python or borrowed yet, so
                // this is the only reference to its data while the slice lives (it ends with
                // this block).
                let data = unsafe { out.as_slice_mut() }
                    .map_err(|e| PyValueError::new_err(e.to_string()))?;
                match params {
                    None => e.eval_into(q, &self.nominal, data),
                    Some(p) => e.eval_into(q, &self.values(Some(p))?, data),
                }
            };
            written.map_err(value_error)?;
            Ok(out)
        })
    }

    fn function(&self, what: &str) -> PyResult<Function> {
        match self.names.binary_search_by(|(n, _)| n.as_str().cmp(what)) {
            Ok(k) => Ok(self.names[k].1),
            Err(_) => self.inner.function(what).map_err(value_error),
        }
    }
}

#[pymethods]
impl Robot {
    /// Loads a robot (a shipped description's name or the path of a TOML description) and
    /// derives and compiles its closed forms once. Raises `ValueError` with the message of the command line (file,
    /// line and field) when the description is invalid.
    #[staticmethod]
    fn load(py: Python<'_>, name_or_path: PathBuf) -> PyResult<Self> {
        let inner = py
            .detach(move || {
                let r = trocar_api::Robot::load(&name_or_path)?;
                // Derived now, once; a description whose closed forms cannot be derived (a
                // mechanism with a non-square J_Cp) still loads, and the calls that need them
                // say why they cannot.
                let _ = r.derive();
                Ok::<_, trocar_api::Error>(r)
            })
            .map_err(value_error)?;
        Robot::wrap(inner)
    }

    /// The robot's name (`[robot] name`).
    #[getter]
    fn name(&self) -> &str {
        self.inner.name()
    }

    /// Number of joint values `eval` takes (all joints of a closed mechanism).
    #[getter]
    fn joints(&self) -> usize {
        self.inner.dof()
    }

    /// The joints' names, base first.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.inner.joint_names()
    }

    /// Each joint's `(lower, upper)` position limits (rad or m); `(-inf, inf)` where the
    /// description has none.
    #[getter]
    fn joint_limits(&self) -> Vec<(f64, f64)> {
        self.inner
            .joint_limits()
            .into_iter()
            .map(|l| l.map_or((f64::NEG_INFINITY, f64::INFINITY), |[a, b]| (a, b)))
            .collect()
    }

    /// Each joint's speed limit (rad/s or m/s; `None` where the description has none).
    #[getter]
    fn speed_limits(&self) -> Vec<Option<f64>> {
        self.inner.description().map_or_else(Vec::new, |d| {
            d.joints.iter().map(|j| j.speed_limit).collect()
        })
    }

    /// Each joint's acceleration limit (rad/s² or m/s²; `None` where the description has none:
    /// a URDF 1.2 `<limit acceleration>` or `acceleration_limit` in TOML).
    #[getter]
    fn acceleration_limits(&self) -> Vec<Option<f64>> {
        self.inner.description().map_or_else(Vec::new, |d| {
            d.joints.iter().map(|j| j.acceleration_limit).collect()
        })
    }

    /// Whether this is a closed mechanism (`eval` then takes `what` in jr, jc, passive, det).
    #[getter]
    fn is_mechanism(&self) -> bool {
        self.inner.is_mechanism()
    }

    /// The parameters and their nominal values.
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in self.inner.params() {
            d.set_item(k, v)?;
        }
        Ok(d)
    }

    /// The quantities `eval` takes for this robot, by their catalogue names.
    fn quantities(&self) -> Vec<&'static str> {
        self.inner
            .quantities()
            .into_iter()
            .map(Function::name)
            .collect()
    }

    /// The quantity `what` (a catalogue name such as `"constrained_jacobian"` or a short name
    /// such as `"jr"`) at the joint values `q`, as a 2-D array, row-major (a scalar such as the
    /// manipulability is 1 × 1, a pose 4 × 4). `what` may also be a tuple or list of names: a
    /// tuple of arrays then comes back, one per name, computed by one program that shares every
    /// value they have in common (a serial robot's closed forms). `params` overrides parameter
    /// values by name; `numeric` uses the numeric runtime instead of the generated closed forms.
    #[pyo3(signature = (q, what = None, params = None, numeric = false))]
    fn eval<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        what: Option<&Bound<'py, PyAny>>,
        params: Option<BTreeMap<String, f64>>,
        numeric: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let functions = match self.what(what)? {
            What::One(function) => {
                return Ok(self.eval_one(py, q, function, params, numeric)?.into_any());
            }
            What::Several(functions) => functions,
        };
        with_joints(q, |q| {
            if numeric || self.inner.is_mechanism() {
                let p: Vec<(String, f64)> = params.unwrap_or_default().into_iter().collect();
                let arrays = functions
                    .iter()
                    .map(|&f| self.evaluated(py, f, q, &p, numeric))
                    .collect::<PyResult<Vec<_>>>()?;
                return Ok(PyTuple::new(py, arrays)?.into_any());
            }
            self.inner.check_q(q).map_err(value_error)?;
            let e = self
                .inner
                .fused_evaluator(&functions)
                .map_err(value_error)?;
            let values = match params {
                None => None,
                Some(p) => Some(self.values(Some(p))?),
            };
            let values = values.as_deref().unwrap_or(&self.nominal);
            // Taken out of the thread's slot while in use: creating the arrays may run Python
            // code (a collection's finalisers), which may evaluate again on this thread.
            let mut out = RESULT.with(|slot| slot.take());
            out.resize(e.len(), 0.0);
            let arrays = e
                .eval_into(q, values, &mut out)
                .map_err(value_error)
                .and_then(|()| {
                    e.dims()
                        .iter()
                        .enumerate()
                        .map(|(k, &(rows, cols))| matrix(py, rows, cols, &out[e.range(k)]))
                        .collect::<PyResult<Vec<_>>>()
                });
            RESULT.with(|slot| slot.replace(out));
            Ok(PyTuple::new(py, arrays?)?.into_any())
        })
    }

    /// `what` at every row of `Q` (an `(N, joints)` array, `float64` or anything numpy converts
    /// to it), as an `(N, rows, cols)` array equal to N calls of `eval` (`MemoryError` when it
    /// cannot be allocated); the configurations are evaluated side by side on every core,
    /// without the GIL. With a tuple or list of names, a tuple of such arrays, one per name,
    /// computed by one program (as `eval`).
    #[pyo3(signature = (q, what = None, params = None))]
    fn eval_many<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        what: Option<&Bound<'py, PyAny>>,
        params: Option<BTreeMap<String, f64>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let q = configurations(py, q)?;
        let what = self.what(what)?;
        let values = self.values(params)?;
        let (count, n) = q.as_array().dim();
        if n != self.inner.dof() {
            return Err(PyValueError::new_err(format!(
                "Q has {n} columns but `{}` has {} joints (one row per configuration)",
                self.inner.name(),
                self.inner.dof()
            )));
        }
        // Row-major (C-ordered) arrays are read in place; any other layout is copied row by row.
        let view = q.as_array();
        let owned;
        let flat: &[f64] = match view.as_slice() {
            Some(s) => s,
            None => {
                // A copy that cannot be allocated (a broadcast view of many rows) raises
                // `MemoryError` instead of ending the interpreter.
                let mut copy = Vec::new();
                copy.try_reserve_exact(view.len()).map_err(|_| {
                    PyMemoryError::new_err(format!(
                        "Unable to allocate {} bytes for a copy of Q, shape ({count}, {n}), to read it row by row",
                        view.len().saturating_mul(std::mem::size_of::<f64>())
                    ))
                })?;
                copy.extend(view.iter().copied());
                owned = copy;
                &owned
            }
        };
        let functions = match what {
            What::One(function) => {
                return Ok(self.many(py, function, flat, count, &values)?.into_any());
            }
            // A mechanism's functions one by one.
            What::Several(functions) if self.inner.is_mechanism() => {
                let arrays = functions
                    .iter()
                    .map(|&f| self.many(py, f, flat, count, &values))
                    .collect::<PyResult<Vec<_>>>()?;
                return Ok(PyTuple::new(py, arrays)?.into_any());
            }
            What::Several(functions) => functions,
        };
        // Without the GIL: the first call with a set builds its program (milliseconds).
        let e = py
            .detach(|| self.inner.fused_evaluator(&functions))
            .map_err(value_error)?;
        // SAFETY: `empty3` leaves the data uninitialised; the arrays are handed to Python only
        // after `eval_many_each` has written every entry of every configuration (each
        // function's matrix row by row, a transform with its constant last row), and are
        // dropped unread otherwise.
        let arrays: Vec<Bound<'py, PyArray3<f64>>> = e
            .dims()
            .iter()
            .map(|&(rows, cols)| unsafe { empty3(py, count, rows, cols) })
            .collect::<PyResult<_>>()?;
        {
            // SAFETY: each array was created just above as a new, C-contiguous array and has
            // not been handed to Python or borrowed yet, so these are the only references to
            // their data while the slices live (they end with this block). Python code that
            // runs while the GIL is released below cannot reach them, which no Python object
            // refers to yet.
            let mut outs = arrays
                .iter()
                .map(|a| unsafe { a.as_slice_mut() })
                .collect::<Result<Vec<&mut [f64]>, _>>()
                .map_err(|e| PyValueError::new_err(e.to_string()))?;
            py.detach(|| e.eval_many_each(flat, &values, &mut outs))
                .map_err(value_error)?;
        }
        Ok(PyTuple::new(py, arrays)?.into_any())
    }

    /// Row and column labels of `what`'s matrix (`(rows, cols)`, e.g. `v_x … w_z` by `dq_joint1
    /// …`), or `None` for a pose or a scalar.
    fn labels(&self, what: &str) -> PyResult<Option<(Vec<String>, Vec<String>)>> {
        Ok(self.inner.labels(self.function(what)?))
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
        let report = py
            .detach(|| self.inner.verify(samples, seed, |_| {}))
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
        let real: trocar_api::Real = real.parse().map_err(PyValueError::new_err)?;
        let options = trocar_api::ModuleOptions {
            real,
            ..Default::default()
        };
        py.detach(|| self.inner.generate(&options))
            .map_err(value_error)
    }

    /// The robot as a physics plant: MuJoCo's XML (MJCF) with the links' mass properties,
    /// joint damping and friction, torque limits, gravity compensated by the actuators, one
    /// velocity actuator per joint and the instrument's shaft with a `wrist` force/torque sensor
    /// (`trocar_api::plant`). `params` overrides parameters' nominal values. Raises
    /// `ValueError` when a link has no mass properties.
    #[pyo3(signature = (params = None))]
    fn mjcf(&self, params: Option<BTreeMap<String, f64>>) -> PyResult<String> {
        let params: Vec<(String, f64)> = params.unwrap_or_default().into_iter().collect();
        trocar_api::plant::mjcf(&self.inner, &params).map_err(value_error)
    }

    /// The instrument as the plant places it, in the last link's frame: a dict with `start`
    /// (the shaft's origin, m), `direction` (unit, toward the tip), `length` (m), `radius` (m)
    /// and `mass` (kg); `None` without `[instrument]`.
    fn shaft<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(d) = self.inner.description() else {
            return Ok(None);
        };
        let Some(s) = trocar_api::plant::shaft(d, &self.inner.params()).map_err(value_error)?
        else {
            return Ok(None);
        };
        let out = PyDict::new(py);
        out.set_item("start", s.start.to_vec())?;
        out.set_item("direction", s.direction.to_vec())?;
        out.set_item("length", s.length)?;
        out.set_item("radius", s.radius)?;
        out.set_item("mass", s.mass)?;
        Ok(Some(out))
    }

    fn __repr__(&self) -> String {
        format!("trocar.Robot.load({:?})", self.inner.source())
    }
}

/// The constrained kinematic controller on a robot (the Rust runtime's `Controller`: task
/// selection, drift correction on the trocar, the null-space objective keeping the joints from
/// their limits). Defaults are the Panda laparoscope scenario's gains.
#[pyclass(module = "trocar")]
struct Controller {
    inner: trocar_api::RobotController,
}

#[pymethods]
impl Controller {
    /// A controller for `robot` (a serial robot with a `[constraint]`). `method` is `"dls"`,
    /// `"pinv"`, `"fi"` or `"qp"` (one quadratic program per step: the trocar, the robot's joint
    /// ranges and speed limits and `depth_limits` held as hard limits); `kp`, `ko` (1/s) the
    /// position and orientation gains, `kr` (1/s) the drift correction on the trocar (0: none),
    /// `max_joint_speed` (rad/s, `None`: none), `null_space_gain` (1/s) the joint-limit
    /// objective's gain on a redundant arm, `qp_kappa` the QP's weight on the joint rates,
    /// `depth_limits` `(l_min, l_max)` (m) of the trocar's offset along the shaft (QP only),
    /// `max_joint_acceleration` (rad/s²) a limit on every joint's acceleration, the smaller with
    /// the robot's own (URDF `<limit acceleration=...>`, `acceleration_limit`; `None`, the
    /// default: the robot's alone): each step's rates then change by at most `a_max dt` from the
    /// last step's, starting from rest, and brake in time for the joint ranges.
    #[new]
    #[pyo3(signature = (robot, method = "dls", kp = None, ko = None, kr = None, max_joint_speed = MaybeLimit::Default, null_space_gain = None, dls_alpha0 = None, fi_gamma = None, qp_kappa = None, depth_limits = None, max_joint_acceleration = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        robot: &Robot,
        method: &str,
        kp: Option<f64>,
        ko: Option<f64>,
        kr: Option<f64>,
        max_joint_speed: MaybeLimit,
        null_space_gain: Option<f64>,
        dls_alpha0: Option<f64>,
        fi_gamma: Option<f64>,
        qp_kappa: Option<f64>,
        depth_limits: Option<[f64; 2]>,
        max_joint_acceleration: Option<f64>,
    ) -> PyResult<Self> {
        let d = ControllerOptions::default();
        let options = ControllerOptions {
            method: self::method(method)?,
            kp: kp.unwrap_or(d.kp),
            ko: ko.unwrap_or(d.ko),
            kr: kr.unwrap_or(d.kr),
            max_joint_speed: match max_joint_speed {
                MaybeLimit::Default => d.max_joint_speed,
                MaybeLimit::Unlimited => None,
                MaybeLimit::At(v) => Some(v),
            },
            null_space_gain: null_space_gain.unwrap_or(d.null_space_gain),
            dls_alpha0: dls_alpha0.unwrap_or(d.dls_alpha0),
            fi_gamma: fi_gamma.unwrap_or(d.fi_gamma),
            qp_kappa: qp_kappa.unwrap_or(d.qp_kappa),
            depth_limits,
            max_joint_acceleration,
            ..d
        };
        let inner = trocar_api::RobotController::new(&robot.inner, options).map_err(value_error)?;
        Ok(Controller { inner })
    }

    /// One control step at joints `q` toward `reference` — the desired tip position (3 numbers)
    /// or a dict with `"position"` and optionally `"rotation"` (3 × 3, base frame), `"velocity"`
    /// and `"angular_velocity"` (feed-forward, base frame) — with the trocar at `trocar` (base
    /// frame, m), moving laterally at `dv` (default: fixed). Returns a dict: `qd` (joint rates),
    /// `l_a`, `position_error`, `orientation_error`, `lateral_error`, `dv_0r`, `w_r`, `w_i`,
    /// `kappa_r`, `kappa_i`, `status` (`"Held"`; `"TrocarYielded"` when the trocar could not be
    /// held within the joint limits, which hold in every step; `"JointOutside"`,
    /// `"DepthOutside"`), `relaxed` (`"Nothing"`; `"Jerk"`, `"Braking"` or `"Acceleration"`: the
    /// most important of those rate limits that could not be met with the ones before it at some
    /// joint), and with `method="qp"` `qp_status` (`"Optimal"`,
    /// `"EqualitiesInconsistent"` when the trocar rows were met in least squares, ...),
    /// `qp_iterations`, `qp_active` (the number of limits reached) and `qp_resolved` (the step
    /// measured its own chord over `dt` and solved again); `None` otherwise. A dict with another
    /// key, or a rotation that is not a proper rotation matrix, raises `ValueError`.
    #[pyo3(signature = (q, reference, trocar, dt, dv = None))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        reference: &Bound<'py, PyAny>,
        trocar: [f64; 3],
        dt: f64,
        dv: Option<Vec<f64>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let q = joints(q)?;
        let target = if let Ok(d) = reference.cast::<PyDict>() {
            for key in d.keys() {
                let known = key
                    .cast::<PyString>()
                    .ok()
                    .and_then(|k| k.to_str().ok())
                    .is_some_and(|k| REFERENCE_KEYS.contains(&k));
                if !known {
                    return Err(PyValueError::new_err(format!(
                        "reference: unknown key {} (the keys are \"{}\")",
                        key.repr()?,
                        REFERENCE_KEYS.join("\", \"")
                    )));
                }
            }
            let get3 = |k: &str| -> PyResult<[f64; 3]> {
                match d.get_item(k)? {
                    Some(v) => v.extract::<[f64; 3]>(),
                    None => Ok([0.0; 3]),
                }
            };
            let position = match d.get_item("position")? {
                Some(v) => v.extract::<[f64; 3]>()?,
                None => {
                    return Err(PyValueError::new_err(
                        "reference: a dict with \"position\" (and optionally \"rotation\", \"velocity\", \"angular_velocity\")",
                    ))
                }
            };
            let rotation = match d.get_item("rotation")? {
                Some(v) if !v.is_none() => {
                    if let Ok(a) = v.extract::<PyReadonlyArray2<'_, f64>>() {
                        let a = a.as_array();
                        if a.shape() != [3, 3] {
                            return Err(PyValueError::new_err(
                                "reference[\"rotation\"]: a 3 × 3 matrix",
                            ));
                        }
                        Some(std::array::from_fn(|i| std::array::from_fn(|j| a[(i, j)])))
                    } else {
                        Some(v.extract::<[[f64; 3]; 3]>()?)
                    }
                }
                _ => None,
            };
            if let Some(r) = &rotation {
                check_rotation(r)?;
            }
            Target {
                position,
                rotation,
                velocity: get3("velocity")?,
                angular_velocity: get3("angular_velocity")?,
            }
        } else {
            Target {
                position: reference.extract::<[f64; 3]>()?,
                rotation: None,
                velocity: [0.0; 3],
                angular_velocity: [0.0; 3],
            }
        };
        let dv = dv.unwrap_or_else(|| vec![0.0; self.inner.constrained_directions()]);
        let s = self
            .inner
            .step(&q, &target, &trocar, &dv, dt)
            .map_err(value_error)?;
        let out = PyDict::new(py);
        out.set_item("qd", Array1::from(s.qd).into_pyarray(py))?;
        out.set_item("l_a", s.l_a)?;
        out.set_item(
            "position_error",
            PyArray1::from_slice(py, &s.position_error),
        )?;
        out.set_item(
            "orientation_error",
            PyArray1::from_slice(py, &s.orientation_error),
        )?;
        out.set_item("lateral_error", PyArray1::from_vec(py, s.lateral_error))?;
        out.set_item("dv_0r", PyArray1::from_vec(py, s.dv_0r))?;
        out.set_item("w_r", s.w_r)?;
        out.set_item("w_i", s.w_i)?;
        out.set_item("kappa_r", s.kappa_r)?;
        out.set_item("kappa_i", s.kappa_i)?;
        out.set_item("status", format!("{:?}", s.status))?;
        out.set_item("relaxed", format!("{:?}", s.relaxed))?;
        out.set_item("qp_status", s.qp.map(|r| format!("{:?}", r.status)))?;
        out.set_item("qp_iterations", s.qp.map(|r| r.iterations))?;
        out.set_item("qp_active", s.qp.map(|r| r.active))?;
        out.set_item("qp_resolved", s.qp.map(|r| r.resolved))?;
        Ok(out)
    }

    /// The lateral velocity `dv` of `step` that carries the constraint frame with a trocar moving
    /// at `velocity` (base frame, m/s) at joints `q`: its motion across the shaft in the
    /// constrained directions, for a port whose motion is known or estimated.
    fn trocar_rate(&self, q: &Bound<'_, PyAny>, velocity: [f64; 3]) -> PyResult<Vec<f64>> {
        let q = joints(q)?;
        self.inner.trocar_rate(&q, &velocity).map_err(value_error)
    }

    /// Restarts the filtered inverse and the QP's warm start, and takes the arm to be at rest
    /// (with acceleration limits the next rates start from zero).
    fn reset(&mut self) {
        self.inner.reset();
    }

    /// Continues from a known motion: the previous command was `rates` (rad/s) with the
    /// acceleration `acceleration` (rad/s², `(θ̇⁻ − θ̇⁻⁻)/dt`; zeros when not given). The next
    /// step's acceleration and jerk bounds are measured from them, as if this controller had
    /// commanded them: a controller taking over a moving arm, or replaying a run from its rows.
    #[pyo3(signature = (rates, acceleration=None))]
    fn set_previous_rates(
        &mut self,
        rates: &Bound<'_, PyAny>,
        acceleration: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let rates = joints(rates)?;
        let acceleration = match acceleration {
            Some(a) => joints(a)?,
            None => vec![0.0; rates.len()],
        };
        self.inner
            .set_previous_rates(&rates, &acceleration)
            .map_err(value_error)
    }
}

/// What a control loop of one's own needs to replay a run (`trocar_api::plant::RunSetup`): a
/// shipped Panda scenario's (`RunSetup("panda-laparoscope")`) or a robot's along its own
/// trajectory (`RunSetup(robot_or_path, trajectory=..., q0=..., trocar=..., method=...)`, what is
/// not given taken from its description's `[simulation]` section). Attributes: `robot`, `q0`,
/// `trocar` (m, base frame), `duration` (s), `controller` (the keyword arguments of
/// `Controller`); `reference(t)` is the reference at time `t` as `Controller.step` takes it.
#[pyclass(module = "trocar", frozen)]
struct RunSetup {
    inner: trocar_api::plant::RunSetup,
    robot: Py<Robot>,
}

#[pymethods]
impl RunSetup {
    #[new]
    #[pyo3(signature = (scenario, trajectory = None, q0 = None, trocar = None, method = None))]
    fn new(
        py: Python<'_>,
        scenario: &Bound<'_, PyAny>,
        trajectory: Option<PathBuf>,
        q0: Option<Vec<f64>>,
        trocar: Option<[f64; 3]>,
        method: Option<&str>,
    ) -> PyResult<Self> {
        let given: Option<Py<Robot>> = scenario.cast::<Robot>().ok().map(|r| r.clone().unbind());
        let name: Option<PathBuf> = match given {
            Some(_) => None,
            None => Some(scenario.extract().map_err(|_| {
                PyTypeError::new_err(
                    "scenario: a Panda scenario's name, a Robot, or a description's path",
                )
            })?),
        };
        let scenario_name = name
            .as_deref()
            .and_then(std::path::Path::to_str)
            .filter(|n| trocar_api::simulate::scenario_names().contains(n));
        let (robot, mut inner) = match (scenario_name, &given) {
            (Some(n), None) if trajectory.is_none() => {
                if q0.is_some() || trocar.is_some() {
                    return Err(PyValueError::new_err(
                        "q0 and trocar apply to a robot's own trajectory, not to a shipped scenario",
                    ));
                }
                let (robot, setup) =
                    trocar_api::plant::RunSetup::scenario(n).map_err(value_error)?;
                (Py::new(py, Robot::wrap(robot)?)?, setup)
            }
            _ => {
                let robot: Py<Robot> = match given {
                    Some(r) => r,
                    None => {
                        let path = name.as_deref().unwrap_or(std::path::Path::new(""));
                        Py::new(py, Robot::load(py, path.to_path_buf())?)?
                    }
                };
                let request = trocar_api::RunRequest {
                    trajectory,
                    q0,
                    trocar,
                    ..Default::default()
                };
                let setup = trocar_api::plant::RunSetup::trajectory(&robot.get().inner, &request)
                    .map_err(value_error)?;
                (robot, setup)
            }
        };
        if let Some(m) = method {
            inner.controller.method = self::method(m)?;
        }
        Ok(RunSetup { inner, robot })
    }

    /// The robot.
    #[getter]
    fn robot(&self, py: Python<'_>) -> Py<Robot> {
        self.robot.clone_ref(py)
    }

    /// The start configuration.
    #[getter]
    fn q0(&self) -> Vec<f64> {
        self.inner.q0.clone()
    }

    /// The trocar (m, base frame).
    #[getter]
    fn trocar(&self) -> [f64; 3] {
        self.inner.trocar
    }

    /// How long the run lasts (s).
    #[getter]
    fn duration(&self) -> f64 {
        self.inner.duration
    }

    /// The keyword arguments of `Controller` the run uses.
    #[getter]
    fn controller<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let c = &self.inner.controller;
        let out = PyDict::new(py);
        out.set_item("method", c.method.name())?;
        out.set_item("kp", c.kp)?;
        out.set_item("ko", c.ko)?;
        out.set_item("kr", c.kr)?;
        out.set_item("max_joint_speed", c.max_joint_speed)?;
        out.set_item("null_space_gain", c.null_space_gain)?;
        out.set_item("dls_alpha0", c.dls_alpha0)?;
        out.set_item("fi_gamma", c.fi_gamma)?;
        out.set_item("qp_kappa", c.qp_kappa)?;
        out.set_item("depth_limits", c.depth_limits.map(|d| d.to_vec()))?;
        Ok(out)
    }

    /// The reference at time `t` (s): `position`, `rotation` (3 × 3 or `None`), `velocity`,
    /// `angular_velocity` (base frame), as `Controller.step` takes it.
    fn reference<'py>(&self, py: Python<'py>, t: f64) -> PyResult<Bound<'py, PyDict>> {
        let r = self.inner.reference(t).map_err(value_error)?;
        target_dict(py, &r)
    }

    /// The true port at time `t` (s) and its velocity, `(position, velocity)` (base frame), in a
    /// scenario whose port moves (`"panda-breathing"`, `"panda-registration"`, where `trocar` is
    /// where the controller starts from); `None` where the port is `trocar`.
    fn port(&self, t: f64) -> PyResult<Option<([f64; 3], [f64; 3])>> {
        if !t.is_finite() {
            return Err(PyValueError::new_err(format!("t = {t}: must be finite")));
        }
        Ok(self.inner.port(t))
    }

    /// The wall's normal where the port moves along it (the moving-port scenarios), else `None`.
    #[getter]
    fn wall_normal(&self) -> Option<[f64; 3]> {
        self.inner.wall_normal()
    }

    /// How the kinematic run follows a moving port from the wall's force: `(time_constant,
    /// max_rate)` (s, m/s) of its `PortFollower`; `None` where the port does not move.
    #[getter]
    fn follower(&self) -> Option<(f64, f64)> {
        self.inner.follower()
    }
}

/// A port followed from the wall's force on the shaft (`trocar_api::PortFollower`): an
/// admittance law that moves the estimate along the force across the shaft, `compliance` m/(N s)
/// (`1/(k τ)` follows a wall of stiffness `k` with the time constant `τ`), its rate at most
/// `max_rate` m/s; with the wall's `normal`, the part along the shaft too.
#[pyclass(module = "trocar")]
struct PortFollower {
    inner: trocar_api::PortFollower<f64>,
}

#[pymethods]
impl PortFollower {
    #[new]
    #[pyo3(signature = (estimate, compliance, max_rate, normal = None))]
    fn new(
        estimate: [f64; 3],
        compliance: f64,
        max_rate: f64,
        normal: Option<[f64; 3]>,
    ) -> PyResult<Self> {
        let refused = |_| {
            PyValueError::new_err(
                "PortFollower: a finite estimate, compliance ≥ 0, max_rate > 0 and a normal of some length",
            )
        };
        let mut inner = trocar_api::PortFollower::new(estimate.into(), compliance, max_rate)
            .map_err(refused)?;
        if let Some(n) = normal {
            inner = inner.with_normal(n.into()).map_err(refused)?;
        }
        Ok(PortFollower { inner })
    }

    /// One step over `dt` (s) from the wall's force on the shaft `force` (N, base frame) and
    /// the shaft's `direction`: moves the estimate and returns its rate (m/s).
    fn update(&mut self, force: [f64; 3], direction: [f64; 3], dt: f64) -> PyResult<[f64; 3]> {
        self.inner
            .update(&force.into(), &direction.into(), dt)
            .map(Into::into)
            .map_err(|e| PyValueError::new_err(format!("PortFollower.update: {e}")))
    }

    /// The port's estimate (base frame, m).
    #[getter]
    fn estimate(&self) -> [f64; 3] {
        self.inner.estimate.into()
    }

    /// Its rate at the last update (m/s).
    #[getter]
    fn rate(&self) -> [f64; 3] {
        self.inner.rate.into()
    }
}

/// The keys a reference dict of `Controller.step` may have.
const REFERENCE_KEYS: [&str; 4] = ["position", "rotation", "velocity", "angular_velocity"];

/// Refuses a reference rotation that is not a proper rotation ([`trocar_api::proper_rotation`],
/// the rule the library's controller applies too).
fn check_rotation(r: &[[f64; 3]; 3]) -> PyResult<()> {
    trocar_api::proper_rotation(r)
        .map_err(|reason| PyValueError::new_err(format!("reference[\"rotation\"]: {reason}")))
}

/// `trocar simulate`: runs a scenario (`"1"`–`"4"`, `"exp421"`, `"panda-laparoscope"`,
/// `"panda-laparoscope-limits"`, a closed-chain scenario such as `"four-bar"`, or the scene of
/// several arms `"three-ports"`) and returns its
/// trace as named columns (`t` first), the columns of the command line's CSV. `method`
/// (`"pinv"`, `"dls"`, `"fi"`, `"qp"`; default:
/// the scenario's), `drift_correction` and `max_joint_speed` (rad/s; `None` for no limit; default:
/// the simulations' limit) apply to the RCM scenarios. With `trajectory` (a CSV: `t,x,y,z` and
/// `roll` or `qw,qx,qy,qz`), or when the first argument is a `Robot` or a description file, the
/// robot is driven along that tip path from `q0`, the trocar at `trocar` (default: the
/// constraint frame's origin at `q0`); what is not given comes from the description's
/// `[simulation]` section (`trocar_api::simulate_robot`). `port` (`"fixed"`, `"known"`,
/// `"estimated"`; default `"estimated"`; `"registered"` for `"panda-registration"`: from the
/// shaft's lines during a pivot, no force) is how the moving-port scenarios' controller knows
/// its port.
#[pyfunction]
#[pyo3(signature = (scenario, method = None, drift_correction = true, max_joint_speed = MaybeLimit::Default, trajectory = None, q0 = None, trocar = None, port = None))]
#[allow(clippy::too_many_arguments)]
fn simulate<'py>(
    py: Python<'py>,
    scenario: &Bound<'py, PyAny>,
    method: Option<&str>,
    drift_correction: bool,
    max_joint_speed: MaybeLimit,
    trajectory: Option<PathBuf>,
    q0: Option<Vec<f64>>,
    trocar: Option<[f64; 3]>,
    port: Option<&str>,
) -> PyResult<Bound<'py, PyDict>> {
    // A scenario's name, a robot's name or a description file: a `str` or any `os.PathLike`.
    let named: Option<PathBuf> = match scenario.cast::<Robot>() {
        Ok(_) => None,
        Err(_) => Some(scenario.extract().map_err(|_| {
            PyTypeError::new_err(
                "scenario: a scenario's name, a Robot, or a description's path (str or os.PathLike)",
            )
        })?),
    };
    // A robot's own trajectory: given, or named by its description's [simulation] section
    // (a `Robot`, or a description file that is not a scenario's name).
    let own = trajectory.is_some()
        || named.as_ref().is_none_or(|name| {
            trocar_api::simulate::scenario_names()
                .iter()
                .all(|s| Some(*s) != name.to_str())
                && name.is_file()
        });
    if own && port.is_some() {
        return Err(PyValueError::new_err(
            "port applies to the scenario \"panda-breathing\" (a port that moves), not to a robot's own trajectory",
        ));
    }
    let columns = if !own {
        if q0.is_some() || trocar.is_some() {
            return Err(PyValueError::new_err(
                "q0 and trocar apply to a robot's own trajectory (trajectory=, or a description with a [simulation] section)",
            ));
        }
        let scenario = named
            .as_deref()
            .and_then(std::path::Path::to_str)
            .unwrap_or_default()
            .to_string();
        let options = RcmOptions {
            method: method.map(self::method).transpose()?,
            drift_correction,
            max_joint_speed: match max_joint_speed {
                MaybeLimit::Default => None,
                MaybeLimit::Unlimited => Some(SpeedLimit::Unlimited),
                MaybeLimit::At(v) => Some(SpeedLimit::At(v)),
            },
            port: port.map(port_mode).transpose()?,
        };
        py.detach(|| trocar_api::simulate(&scenario, &options, &mut |_| {}))
            .map_err(value_error)?
            .columns()
    } else {
        // A robot: a loaded `Robot`, a shipped name or a description file.
        let loaded;
        let robot: &trocar_api::Robot = match scenario.cast::<Robot>() {
            Ok(r) => &r.get().inner,
            Err(_) => {
                let name = named.as_deref().unwrap_or(std::path::Path::new(""));
                loaded = trocar_api::Robot::load(name).map_err(value_error)?;
                &loaded
            }
        };
        let request = trocar_api::RunRequest {
            trajectory,
            q0,
            trocar,
            method: method.map(self::method).transpose()?,
            drift_correction: (!drift_correction).then_some(false),
            max_joint_speed: match max_joint_speed {
                MaybeLimit::Default => None,
                MaybeLimit::Unlimited => Some(SpeedLimit::Unlimited),
                MaybeLimit::At(v) => Some(SpeedLimit::At(v)),
            },
        };
        py.detach(|| trocar_api::simulate_robot(robot, &request, &mut |_| {}))
            .map_err(value_error)?
            .columns()
    };
    let out = PyDict::new(py);
    for (name, values) in columns {
        out.set_item(name, PyArray1::from_vec(py, values))?;
    }
    Ok(out)
}

/// The reference the `panda-laparoscope` scenario tracks at time `t` (s), as the dict
/// `Controller.step` takes: `position`, `rotation` (3 × 3), `velocity`, `angular_velocity`
/// (base frame).
#[pyfunction]
fn panda_reference<'py>(py: Python<'py>, t: f64) -> PyResult<Bound<'py, PyDict>> {
    let mut r = trocar_api::simulate::panda_target(t).map_err(value_error)?;
    r.rotation
        .get_or_insert([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
    target_dict(py, &r)
}

/// A speed limit argument: omitted, `None` or a number.
#[derive(Clone, Copy, Debug)]
enum MaybeLimit {
    Default,
    Unlimited,
    At(f64),
}

impl<'a, 'py> FromPyObject<'a, 'py> for MaybeLimit {
    type Error = PyErr;

    fn extract(ob: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if ob.is_none() {
            Ok(MaybeLimit::Unlimited)
        } else {
            Ok(MaybeLimit::At(ob.extract::<f64>()?))
        }
    }
}

/// Writes a figure of panels of lines over time (SVG or PNG by the extension of `path`), two
/// panels a row under `title`: `panels` is a list of dicts with `title`, `y_label`, `lines` (a
/// list of `(legend, t, y)`) and optionally `non_negative` (the y axis from 0). The figures of
/// `trocar.physics` are drawn with it.
#[pyfunction]
fn write_figure(path: PathBuf, title: &str, panels: &Bound<'_, PyAny>) -> PyResult<()> {
    let mut out = Vec::new();
    for p in panels.try_iter()? {
        let p = p?;
        let d = p
            .cast::<PyDict>()
            .map_err(|_| PyTypeError::new_err("panels: a list of dicts"))?;
        let get = |k: &str| -> PyResult<Bound<'_, PyAny>> {
            d.get_item(k)?
                .ok_or_else(|| PyValueError::new_err(format!("panels: a panel without \"{k}\"")))
        };
        let mut lines = Vec::new();
        for line in get("lines")?.try_iter()? {
            let (label, t, y): (String, Vec<f64>, Vec<f64>) = line?.extract()?;
            lines.push((label, t, y));
        }
        out.push(trocar_api::TimePanel {
            title: get("title")?.extract()?,
            y_label: get("y_label")?.extract()?,
            lines,
            non_negative: match d.get_item("non_negative")? {
                Some(v) => v.extract()?,
                None => false,
            },
        });
    }
    trocar_api::write_time_panels(&path, title, &out)
        .map_err(|e| PyValueError::new_err(format!("{}: {e}", path.display())))
}

/// The names of the shipped robots, mechanisms and simulation scenarios, as `trocar list`
/// prints them: `{"robots": [...], "mechanisms": [...], "scenarios": [...]}`.
#[pyfunction]
fn shipped<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
    let s = trocar_api::shipped();
    let out = PyDict::new(py);
    out.set_item("robots", s.robots)?;
    out.set_item("mechanisms", s.mechanisms)?;
    out.set_item("scenarios", s.scenarios)?;
    Ok(out)
}

/// The quantities `Robot.eval` takes as `what`: `(name, short name)` of every function of a
/// serial robot's module, then of a closed mechanism's.
#[pyfunction]
fn quantities() -> Vec<(&'static str, &'static str)> {
    Function::SERIAL
        .into_iter()
        .chain(Function::MECHANISM)
        .map(|f| (f.name(), f.short_name()))
        .collect()
}

/// A shipped scene of several arms, each through its own port, stepped by a loop of one's own
/// (a physics plant, a robot): `three-ports`, three Pandas whose instruments' shafts are kept
/// `safety` apart and whose endoscope's view axis follows the instruments' midpoint (21 joints);
/// `dia10-dual`, the reference arm and its mirror image on one torso, the left tip held while the
/// right one cuts (15 joints: the torso once). Each step runs every arm's own QP step (its port,
/// its limits, its path), then the scene's QP over all the rates (the couplings between the
/// shafts, the shared torso).
#[pyclass(module = "trocar")]
struct Scene {
    inner: trocar_api::SceneStepper,
}

#[pymethods]
impl Scene {
    /// The scene `name` (`"three-ports"` or `"dia10-dual"`) at its start, with its couplings
    /// (`coupled=True`) or without them (`three-ports` only: to see what they prevent).
    #[new]
    #[pyo3(signature = (name, coupled = true))]
    fn new(name: &str, coupled: bool) -> PyResult<Self> {
        Ok(Scene {
            inner: trocar_api::SceneStepper::new(name, coupled).map_err(value_error)?,
        })
    }

    /// The scene's name.
    #[getter]
    fn name(&self) -> String {
        self.inner.name().to_string()
    }

    /// The arms' names, in the scene's order (its joints are theirs in this order).
    #[getter]
    fn arms(&self) -> Vec<String> {
        self.inner.arms()
    }

    /// The couplings, as pairs of arms' names (the order of a step's `distances`).
    #[getter]
    fn couplings(&self) -> Vec<(String, String)> {
        self.inner.couplings()
    }

    /// The number of the scene's joints.
    #[getter]
    fn joints(&self) -> usize {
        self.inner.joints()
    }

    /// The sample time (s) the scene's limits are for.
    #[getter]
    fn dt(&self) -> f64 {
        self.inner.dt()
    }

    /// The shafts' safety distance (m).
    #[getter]
    fn safety(&self) -> f64 {
        self.inner.safety()
    }

    /// The scene's joints at its start.
    #[getter]
    fn q0<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.q0().into_pyarray(py)
    }

    /// Every arm's port in the scene's frame (m), one row per arm.
    #[getter]
    fn ports(&self) -> Vec<[f64; 3]> {
        self.inner.ports()
    }

    /// Back to the start: the controllers at rest, the warm starts forgotten.
    fn reset(&mut self) {
        self.inner.reset()
    }

    /// One step at the scene's joints `q` (all arms, in order) and time `t` (s; once per
    /// sample, `t` increasing by `dt`). Returns a dict: `qd` (every joint's rate, rad/s),
    /// `distances` (each coupling's distance between two shafts, m), `coupling_held` (`False`
    /// where a coupling could not hold within the ports and the joint limits),
    /// `coupling_active` (a coupling changed the rates) and `statuses` (each arm's step:
    /// `"Held"`, or what gave way). A `q` of the wrong length or with a NaN, or a time that is
    /// not finite, raises `ValueError`.
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        t: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let q = joints(q)?;
        let s = self.inner.step(&q, t).map_err(value_error)?;
        let out = PyDict::new(py);
        out.set_item("qd", s.qd.into_pyarray(py))?;
        out.set_item("distances", s.distances.into_pyarray(py))?;
        out.set_item("coupling_held", s.coupling_held)?;
        out.set_item("coupling_active", s.coupling_active)?;
        out.set_item(
            "statuses",
            s.statuses
                .iter()
                .map(|s| format!("{s:?}"))
                .collect::<Vec<_>>(),
        )?;
        Ok(out)
    }

    fn __repr__(&self) -> String {
        format!("trocar.Scene({:?})", self.inner.name())
    }
}

/// trocar: constrained kinematics of robots with a remote centre of motion.
#[pymodule]
fn _trocar(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Robot>()?;
    m.add_class::<Controller>()?;
    m.add_class::<RunSetup>()?;
    m.add_class::<Scene>()?;
    m.add_function(wrap_pyfunction!(write_figure, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(register_port, m)?)?;
    m.add_class::<Trajectory>()?;
    m.add_class::<PortFollower>()?;
    m.add_function(wrap_pyfunction!(shipped, m)?)?;
    m.add_function(wrap_pyfunction!(quantities, m)?)?;
    m.add_function(wrap_pyfunction!(panda_reference, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
