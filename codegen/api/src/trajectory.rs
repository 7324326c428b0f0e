//! A user's reference path for the tip, read from CSV, and the simulation of any serial robot
//! along it with the constrained controller ([`simulate_trajectory`]).
//!
//! The CSV has a header; column `t` (s, increasing) and the tip's reference in the base frame:
//! `x, y, z` (m) and, for a task that commands orientation, either `roll` (rad, about the tip's
//! `z` axis, relative to its orientation at `q0`) or a unit quaternion `qw, qx, qy, qz`. Rows are
//! interpolated linearly (orientation by slerp); the reference velocity is the interpolant's
//! derivative; before the first row the reference holds the first row, after the last the last.

use crate::controller::{ControllerOptions, RobotController, Target};
use crate::error::{Error, Result};
use crate::robot::Robot;
use crate::simulate::SimulationRun;
use nalgebra::{Matrix3, Vector3};
use std::path::{Path, PathBuf};
use trocar::trajectory::{unit_quaternion, OrientationKind, PathRows};
use trocar_model::description::SimulationDesc;
use trocar_sim::simulation::{ArmModel, Method, StepRecord, Trace};

/// The largest trajectory read (bytes, 64 MiB): a path of 10⁵ rows fits many times over. The
/// bytes read are counted, not the size the file system reports, so a device or a pipe
/// (`/dev/zero`) is refused after this many bytes too.
pub const MAX_TRAJECTORY_BYTES: u64 = 64 << 20;

/// The fastest a trajectory may move the tip between two rows (m/s): far above what an
/// instrument through a trocar is moved at (cm/s), far below the feed-forward that a jump
/// between rows close in time would command (a 5 cm step over 1 ns is 5e7 m/s).
pub const MAX_REFERENCE_SPEED: f64 = 2.0;

/// The fastest a trajectory may turn the tip between two rows (rad/s).
pub const MAX_REFERENCE_ANGULAR_SPEED: f64 = 20.0;

/// The most control steps a run along a trajectory takes (10⁶: 2000 s at the 2 ms sample time).
/// Every step keeps a row of the trace, about 0.35 kB for a seven-joint arm, so the trace stays
/// below about 0.4 GB (and its CSV below about 0.5 GB); a longer path is refused before the run.
pub const MAX_TRAJECTORY_STEPS: usize = 1_000_000;

/// How a trajectory gives the tip's orientation.
#[derive(Clone, Debug, PartialEq)]
pub enum Orientation {
    /// None: the task commands position only.
    None,
    /// A roll about the tip's `z` axis (rad), relative to its orientation at `q0`.
    Roll(Vec<f64>),
    /// Unit quaternions `(w, x, y, z)`, base frame.
    Quaternion(Vec<[f64; 4]>),
}

/// A tip reference path: times, positions and (optionally) orientations.
#[derive(Clone, Debug, PartialEq)]
pub struct Trajectory {
    /// The file it was read from, for messages.
    pub source: Option<PathBuf>,
    /// Times (s), increasing.
    pub t: Vec<f64>,
    /// Tip positions (m, base frame).
    pub position: Vec<[f64; 3]>,
    /// Tip orientations.
    pub orientation: Orientation,
    /// The line of the file each row was read from (1-based, the header's is the first line
    /// that is not blank or a `#` comment), for messages; empty when not read from text.
    pub lines: Vec<usize>,
    /// The line of the header (1-based; after any blank or `#` comment lines), for messages
    /// about columns.
    pub header_line: usize,
}

/// The lines of CSV text that hold something, with their 1-based line numbers: a byte-order
/// mark before the first (as some spreadsheets write UTF-8) skipped, blank lines and `#`
/// comments left out.
pub(crate) fn csv_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.strip_prefix('\u{feff}')
        .unwrap_or(text)
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .map(|(i, l)| (i + 1, l))
}

/// A user's text file read whole, at most `limit` bytes: errors name the file and `what` it
/// was read as (`cannot read the trajectory: …`, too large, not UTF-8 with the first bad byte).
/// At most one byte more than the limit is read, whatever the file is (a device or a pipe
/// reports no size): one more says it is too large.
pub(crate) fn read_text(path: &Path, what: &str, limit: u64) -> Result<String> {
    use std::io::Read;
    let shown = path.display();
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(limit + 1).read_to_end(&mut bytes))
        .map_err(|e| Error::Input(format!("{shown}: cannot read {what}: {e}")))?;
    if bytes.len() as u64 > limit {
        return Err(Error::Input(format!(
            "{shown}: {what} is larger than the {limit} bytes ({} MiB) read",
            limit >> 20
        )));
    }
    String::from_utf8(bytes).map_err(|e| {
        Error::Input(format!(
            "{shown}: cannot read {what}: not UTF-8 text (byte {})",
            e.utf8_error().valid_up_to() + 1
        ))
    })
}

impl Trajectory {
    /// Reads a trajectory CSV. Errors name the file, the row (1-based, the header is row 1) and
    /// the column: missing columns, a value that is not a finite number, times that do not
    /// increase, fewer than two rows, a quaternion that is not of unit length.
    pub fn from_csv(path: &Path) -> Result<Self> {
        let shown = path.display();
        let text = read_text(path, "the trajectory", MAX_TRAJECTORY_BYTES)?;
        let mut t = Self::parse(&text, &shown.to_string())?;
        t.source = Some(path.to_path_buf());
        Ok(t)
    }

    /// Parses CSV text (`name` for messages). A byte-order mark before the header (as some
    /// spreadsheets write UTF-8) is skipped. Text whose header has no column `t` is not quoted in
    /// the error (it may be any file): the message says how many fields the line has.
    pub fn parse(text: &str, name: &str) -> Result<Self> {
        let mut lines = csv_lines(text);
        let Some((header_line, header)) = lines.next() else {
            return Err(Error::Input(format!(
                "{name}: empty trajectory (a header `t,x,y,z` and at least two rows)"
            )));
        };
        let columns: Vec<String> = header.split(',').map(|c| c.trim().to_string()).collect();
        let find = |c: &str| columns.iter().position(|x| x == c);
        if find("t").is_none() {
            let n = columns.len();
            return Err(Error::Input(format!(
                "{name}:{header_line}: no column `t`: this line, the first that is not blank or a `#` comment, has {n} comma-separated field{} and none is `t` (a trajectory's header names t, x, y, z and optionally roll or qw, qx, qy, qz)",
                if n == 1 { "" } else { "s" }
            )));
        }
        for (k, c) in columns.iter().enumerate() {
            if columns[..k].contains(c) {
                return Err(Error::Input(format!(
                    "{name}:{header_line}: column `{c}` appears twice"
                )));
            }
        }
        let mut index = [0usize; 4];
        for (k, c) in ["t", "x", "y", "z"].iter().enumerate() {
            index[k] = find(c).ok_or_else(|| {
                Error::Input(format!(
                    "{name}:{header_line}: no column `{c}` (the header names t, x, y, z and optionally roll or qw, qx, qy, qz; it has: {})",
                    columns.join(", ")
                ))
            })?;
        }
        let roll = find("roll");
        let quat: Vec<Option<usize>> = ["qw", "qx", "qy", "qz"].iter().map(|c| find(c)).collect();
        let quat = match (quat.iter().filter(|q| q.is_some()).count(), roll) {
            (0, _) => None,
            (4, None) => Some([
                quat[0].unwrap_or(0),
                quat[1].unwrap_or(0),
                quat[2].unwrap_or(0),
                quat[3].unwrap_or(0),
            ]),
            (4, Some(_)) => {
                return Err(Error::Input(format!(
                    "{name}:{header_line}: give the orientation as `roll` or as `qw, qx, qy, qz`, not both"
                )))
            }
            _ => {
                return Err(Error::Input(format!(
                    "{name}:{header_line}: a quaternion needs all four columns qw, qx, qy, qz"
                )))
            }
        };
        let mut out = Trajectory {
            source: None,
            t: Vec::new(),
            position: Vec::new(),
            lines: Vec::new(),
            header_line,
            orientation: match (roll, quat) {
                (Some(_), _) => Orientation::Roll(Vec::new()),
                (None, Some(_)) => Orientation::Quaternion(Vec::new()),
                (None, None) => Orientation::None,
            },
        };
        for (row_no, row) in lines {
            let cells: Vec<&str> = row.split(',').map(str::trim).collect();
            let value = |k: usize| -> Result<f64> {
                let c = &columns[k];
                let cell = cells.get(k).copied().unwrap_or("");
                let v: f64 = cell.parse().map_err(|_| {
                    Error::Input(format!(
                        "{name}:{row_no}: column `{c}`: `{cell}` is not a number"
                    ))
                })?;
                if let Err(problem) = trocar_model::validity::check(v) {
                    return Err(Error::Input(format!(
                        "{name}:{row_no}: column `{c}`: {v:e} {problem}"
                    )));
                }
                Ok(v)
            };
            if cells.len() != columns.len() {
                let which = match columns.get(cells.len()) {
                    Some(c) => format!(" (no value for column `{c}`)"),
                    None => " (more values than columns)".to_string(),
                };
                return Err(Error::Input(format!(
                    "{name}:{row_no}: {} values, the header names {} columns{which}",
                    cells.len(),
                    columns.len()
                )));
            }
            let t = value(index[0])?;
            if let Some(&last) = out.t.last() {
                if t <= last {
                    return Err(Error::Input(format!(
                        "{name}:{row_no}: column `t`: {t} does not increase (the row before has {last})"
                    )));
                }
            }
            out.t.push(t);
            out.lines.push(row_no);
            out.position
                .push([value(index[1])?, value(index[2])?, value(index[3])?]);
            match &mut out.orientation {
                Orientation::None => {}
                Orientation::Roll(r) => r.push(value(roll.unwrap_or(0))?),
                Orientation::Quaternion(qs) => {
                    let k = quat.unwrap_or([0; 4]);
                    let q = [value(k[0])?, value(k[1])?, value(k[2])?, value(k[3])?];
                    let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
                    if (norm - 1.0).abs() > 1e-6 {
                        return Err(Error::Input(format!(
                            "{name}:{row_no}: columns qw, qx, qy, qz: the quaternion has length {norm}, not 1"
                        )));
                    }
                    qs.push(q);
                }
            }
        }
        if out.t.len() < 2 {
            let line = out.lines.last().map_or(header_line, |l| *l);
            return Err(Error::Input(format!(
                "{name}:{line}: column `t`: {} row{}; a trajectory needs at least two (a time span)",
                out.t.len(),
                if out.t.len() == 1 { "" } else { "s" }
            )));
        }
        Ok(out)
    }

    /// Checks a trajectory built by hand as [`Trajectory::parse`] checks one it reads: at
    /// least two rows, one position (and orientation, when given) per time, increasing times,
    /// every value within the number rule, unit quaternions, and between two rows a speed of
    /// at most [`MAX_REFERENCE_SPEED`] and a turn rate of at most
    /// [`MAX_REFERENCE_ANGULAR_SPEED`] (the feed-forward the controller is given).
    pub fn check(&self, name: &str) -> Result<()> {
        let n = self.t.len();
        let orientations = match &self.orientation {
            Orientation::None => n,
            Orientation::Roll(r) => r.len(),
            Orientation::Quaternion(q) => q.len(),
        };
        if n < 2 || self.position.len() != n || orientations != n {
            return Err(Error::Input(format!(
                "{name}: {n} times, {} positions and {orientations} orientations; a trajectory needs at least two rows, each with all of them",
                self.position.len()
            )));
        }
        let mut values: Vec<f64> = self
            .t
            .iter()
            .copied()
            .chain(self.position.iter().flatten().copied())
            .collect();
        match &self.orientation {
            Orientation::None => {}
            Orientation::Roll(r) => values.extend(r),
            Orientation::Quaternion(q) => {
                values.extend(q.iter().flatten());
                if let Some(k) = q
                    .iter()
                    .position(|q| (q.iter().map(|v| v * v).sum::<f64>().sqrt() - 1.0).abs() > 1e-6)
                {
                    return Err(Error::Input(format!(
                        "{name}: row {}: the quaternion is not of unit length",
                        k + 1
                    )));
                }
            }
        }
        if let Err((k, problem)) = trocar_model::validity::check_all(&values) {
            return Err(Error::Input(format!("{name}: value {} {problem}", k + 1)));
        }
        if let Some(k) = self.t.windows(2).position(|w| w[1] <= w[0]) {
            return Err(Error::Input(format!(
                "{name}: row {}: t = {} does not increase (the row before has {})",
                k + 2,
                self.t[k + 1],
                self.t[k]
            )));
        }
        let line = |k: usize| self.lines.get(k).copied().unwrap_or(k + 2);
        for k in 0..n - 1 {
            let span = self.t[k + 1] - self.t[k];
            let (a, b) = (self.position[k], self.position[k + 1]);
            let speed = (0..3).map(|i| (b[i] - a[i]).powi(2)).sum::<f64>().sqrt() / span;
            if speed.is_nan() || speed > MAX_REFERENCE_SPEED {
                return Err(Error::Input(format!(
                    "{name}:{}: columns x, y, z: the tip would move at {speed:.4e} m/s from the row before (t = {} to {} s); at most {MAX_REFERENCE_SPEED} m/s",
                    line(k + 1),
                    self.t[k],
                    self.t[k + 1]
                )));
            }
            let turn = match &self.orientation {
                Orientation::None => 0.0,
                Orientation::Roll(r) => (r[k + 1] - r[k]).abs(),
                Orientation::Quaternion(q) => {
                    unit_quaternion(q[k + 1]).angle_to(&unit_quaternion(q[k]))
                }
            } / span;
            if turn.is_nan() || turn > MAX_REFERENCE_ANGULAR_SPEED {
                return Err(Error::Input(format!(
                    "{name}:{}: the tip would turn at {turn:.4e} rad/s from the row before (t = {} to {} s); at most {MAX_REFERENCE_ANGULAR_SPEED} rad/s",
                    line(k + 1),
                    self.t[k],
                    self.t[k + 1]
                )));
            }
        }
        Ok(())
    }

    /// The control steps of `dt` (s) a run along the trajectory takes, from `t = 0` to its last
    /// row; refused beyond [`MAX_TRAJECTORY_STEPS`] (the trace's memory), naming the last row's
    /// line of `name`.
    pub fn steps(&self, dt: f64, name: &str) -> Result<usize> {
        let t_end = self.t.last().copied().unwrap_or(0.0).max(0.0);
        let steps = (t_end / dt).ceil();
        if steps.is_nan() || steps > MAX_TRAJECTORY_STEPS as f64 {
            let line = self
                .lines
                .last()
                .map_or_else(String::new, |l| format!(":{l}"));
            return Err(Error::Input(format!(
                "{name}{line}: column `t`: the path ends at t = {t_end} s, {steps:.0} control steps of {dt} s; a run takes at most {MAX_TRAJECTORY_STEPS} steps ({} s), which bounds the trace's memory",
                MAX_TRAJECTORY_STEPS as f64 * dt
            )));
        }
        Ok(steps as usize)
    }

    /// Whether the trajectory gives an orientation.
    pub fn has_orientation(&self) -> bool {
        !matches!(self.orientation, Orientation::None)
    }

    /// The reference at time `t`: position, orientation (from the start orientation `r0` for a
    /// roll), velocity and angular velocity (zero outside the path's time span), as the rows give
    /// it ([`trocar::trajectory::PathRows::at`]).
    ///
    /// # Panics
    /// With fewer than two rows, which [`Trajectory::parse`] and [`Trajectory::check`] refuse.
    pub fn at(&self, t: f64, r0: &Matrix3<f64>) -> Target {
        let (position, rotation, velocity, angular_velocity) = PathRows::at(self, t, r0);
        Target {
            position: position.into(),
            rotation: rotation.map(|r| std::array::from_fn(|i| std::array::from_fn(|j| r[(i, j)]))),
            velocity: velocity.into(),
            angular_velocity: angular_velocity.into(),
        }
    }

    /// The controller's reference at time `t` as `trocar simulate ROBOT --trajectory` builds it
    /// ([`trocar::trajectory`]): with a roll, the orientation turned through the trocar and its
    /// angular velocity by a central difference; `g0` the tip's pose at the start, `trocar` the
    /// trocar point. Position only: no orientation (the controller keeps the tip's current one).
    ///
    /// # Panics
    /// With fewer than two rows, which [`Trajectory::parse`] and [`Trajectory::check`] refuse.
    pub fn reference(&self, t: f64, g0: &trocar::se3::Se3<f64>, trocar: &Vector3<f64>) -> Target {
        match self.orientation {
            Orientation::None => self.at(t, &g0.rotation),
            _ => {
                let r = PathRows::reference(self, t, g0, trocar, &g0.rotation);
                Target {
                    position: r.position.into(),
                    rotation: Some(std::array::from_fn(|i| {
                        std::array::from_fn(|j| r.rotation[(i, j)])
                    })),
                    velocity: r.velocity.into(),
                    angular_velocity: r.angular_velocity.into(),
                }
            }
        }
    }
}

impl Trajectory {
    /// [`Trajectory::reference`] with plain arrays: the tip's start orientation (row by row)
    /// and position, and the trocar point (for the Python and other front doors).
    pub fn reference_from(
        &self,
        t: f64,
        start_rotation: &[[f64; 3]; 3],
        start_position: &[f64; 3],
        trocar: &[f64; 3],
    ) -> Target {
        let g0 = trocar::se3::Se3::new(
            Matrix3::from_fn(|i, j| start_rotation[i][j]),
            Vector3::from(*start_position),
        );
        self.reference(t, &g0, &Vector3::from(*trocar))
    }
}

/// The rows of a trajectory read from a CSV, for the runtime's one rule of the reference.
impl PathRows<f64> for Trajectory {
    fn rows(&self) -> usize {
        self.t.len()
    }
    fn time(&self, k: usize) -> f64 {
        self.t[k]
    }
    fn position(&self, k: usize) -> [f64; 3] {
        self.position[k]
    }
    fn orientation(&self) -> OrientationKind {
        match self.orientation {
            Orientation::None => OrientationKind::None,
            Orientation::Roll(_) => OrientationKind::Roll,
            Orientation::Quaternion(_) => OrientationKind::Quaternion,
        }
    }
    fn roll(&self, k: usize) -> f64 {
        match &self.orientation {
            Orientation::Roll(r) => r[k],
            _ => 0.0,
        }
    }
    fn quaternion(&self, k: usize) -> [f64; 4] {
        match &self.orientation {
            Orientation::Quaternion(q) => q[k],
            _ => [1.0, 0.0, 0.0, 0.0],
        }
    }
}

/// How a user's simulation runs.
#[derive(Clone, Debug, PartialEq)]
pub struct TrajectoryOptions {
    /// The start configuration (one value per joint).
    pub q0: Vec<f64>,
    /// The trocar point (base frame, m); default: the constraint frame's origin at `q0`.
    pub trocar: Option<[f64; 3]>,
    /// The controller's gains and method.
    pub controller: ControllerOptions,
    /// Sample time (s).
    pub dt: f64,
}

/// The result of a user's simulation: the same run, trace, CSV, figures and views of the arm as
/// a shipped scenario's ([`SimulationRun`]).
pub type TrajectoryRun = SimulationRun;

/// The distance (m) from the tip at `q0` to the trajectory's first point above which a path that
/// starts at `t = 0` is refused (the controller would be asked for a jump).
pub const START_TOLERANCE: f64 = 1e-3;

/// The largest distance (m) of a given trocar point from the shaft's line at `q0`. A run starts
/// with the shaft through the trocar: the drift correction would otherwise pull the shaft across
/// the body wall at `K_r` times the offset in its first steps (8.5 mm at `K_r = 20 /s` is
/// 0.17 m/s). Beyond this a run is refused.
pub const TROCAR_TOLERANCE: f64 = 1e-3;

/// Runs `robot`'s constrained controller along `trajectory` from `options.q0` for the
/// trajectory's duration, measuring everything from the numeric forward kinematics (not the
/// controller's Jacobians, [`ArmModel::measure`], as the shipped scenarios): the columns `t,
/// ep_norm, eo_norm, vr_<a>, vr_<b>, rcm_drift, w_r, w_i, l_a, q1..qn, qd1..qdn`, where
/// `vr_<a>`, `vr_<b>` are the lateral velocity components of the shaft at the trocar (its line's
/// motion across the trocar's place, [`trocar::control::Shaft::moved_across`]) along the
/// constraint frame's two axes normal to the shaft. The run draws the same figures and
/// views of the arm as a scenario's ([`SimulationRun::write_plot`],
/// [`SimulationRun::write_animation`], [`SimulationRun::write_snapshot`]).
pub fn simulate_trajectory(
    robot: &Robot,
    trajectory: &Trajectory,
    options: &TrajectoryOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<TrajectoryRun> {
    let desc = robot.description().ok_or_else(|| {
        Error::Unsupported(format!(
            "`{}` is a closed mechanism: a trajectory drives a serial robot's tip",
            robot.name()
        ))
    })?;
    let source = trajectory
        .source
        .as_ref()
        .map_or_else(|| "the trajectory".to_string(), |p| p.display().to_string());
    trajectory.check(&source)?;
    let n = desc.joints.len();
    robot.check_joints("q0", &options.q0)?;
    if !(options.dt.is_finite() && options.dt > 0.0 && options.dt <= 0.1) {
        return Err(Error::Input(format!(
            "dt = {}: must be in (0, 0.1] s",
            options.dt
        )));
    }
    // Task rows the CSV must provide: an orientation row needs an orientation column.
    if let Some(task) = &desc.task {
        let rotational = task
            .select
            .iter()
            .any(|row| row[3..].iter().any(|v| *v != 0.0));
        if rotational && !trajectory.has_orientation() {
            return Err(Error::Input(format!(
                "{source}:{}: the task of `{}` commands a rotation and the header has no column `roll` (rad about the tip's z) or `qw, qx, qy, qz`",
                trajectory.header_line,
                desc.name
            )));
        }
    } else if !trajectory.has_orientation() {
        return Err(Error::Input(format!(
            "{source}:{}: `{}` has no [task]: the whole tip pose is commanded and the header has no column `roll` or `qw, qx, qy, qz`",
            trajectory.header_line,
            desc.name
        )));
    }
    let numeric = robot.numeric()?;
    let model = numeric.model();
    let constraint = desc.constraint.as_ref().ok_or_else(|| {
        Error::Unsupported(format!(
            "`{}` has no [constraint]: nothing holds a trocar",
            desc.name
        ))
    })?;
    let arm = ArmModel::from_model(model).map_err(|message| Error::Robot {
        file: desc.source.clone(),
        message,
    })?;
    let shaft = *arm.shaft();
    let q0 = &options.q0;
    let g0e = arm.tip(q0);
    let g0i = arm.link_frame(q0);
    // The constraint frame's origin at q0 with the nominal parameters, g_0i(q0) g_ir.
    let g_ir = model
        .constraint()
        .map(|c| c.frame())
        .ok_or_else(|| Error::Unsupported(format!("`{}` has no [constraint]", desc.name)))?;
    let trocar = options
        .trocar
        .map_or_else(|| g0i.transform_point(&g_ir.translation), Vector3::from);
    // The joints start within their ranges.
    for (k, (v, l)) in q0.iter().zip(robot.joint_limits()).enumerate() {
        if let Some([lo, hi]) = l {
            if !(lo <= *v && *v <= hi) {
                return Err(Error::Input(format!(
                    "q0: joint {} = {v} is outside its range [{lo}, {hi}]; start the run within every joint's limits",
                    k + 1
                )));
            }
        }
    }
    // The shaft passes through the trocar at q0, between the link and the tip: `l_a` within
    // `(0, l_tip)`, `l_tip` the tip's offset along the shaft (the instrument's length).
    let l_a0 = shaft.offset(&g0i, &trocar);
    let off = (shaft.constraint_pose(&g0i, l_a0).translation - trocar).norm();
    if off.is_nan() || off > TROCAR_TOLERANCE {
        return Err(Error::Input(format!(
            "trocar: the point ({}, {}, {}) is {off:.4e} m off the shaft's line at q0, more than {TROCAR_TOLERANCE} m; give the trocar on the shaft (the default is the constraint frame's origin at q0)",
            trocar.x, trocar.y, trocar.z
        )));
    }
    // An instrument on the last link only: with the constraint on a middle link the tip moves
    // with the joints beyond it, and the link's length bounds nothing here.
    let on_last_link = constraint.link == n;
    let l_tip = shaft.offset(&g0i, &g0e.translation);
    let insertion = if on_last_link {
        [l_tip.min(0.0), l_tip.max(0.0)]
    } else {
        [f64::NEG_INFINITY, f64::INFINITY]
    };
    if !(insertion[0] < l_a0 && l_a0 < insertion[1]) {
        return Err(Error::Input(format!(
            "trocar: at q0 the trocar is at l_a = {l_a0:.4} along the shaft, outside the instrument (l_a in ({:.4}, {:.4}) from the link to the tip)",
            insertion[0], insertion[1]
        )));
    }

    // A path that starts at t = 0 must start at the tip.
    let start = Vector3::from(trajectory.position[0]);
    let distance = (start - g0e.translation).norm();
    if trajectory.t[0] <= 0.0 && distance > START_TOLERANCE {
        return Err(Error::Input(format!(
            "{source}:{}: columns x, y, z: the first point is {distance:.4} m from the tip at q0 ({:.4}, {:.4}, {:.4}); start the path at the tip, or at t > 0 to let the controller converge from q0",
            trajectory.lines.first().copied().unwrap_or(2),
            g0e.translation.x,
            g0e.translation.y,
            g0e.translation.z
        )));
    }
    // The tip cannot be farther from the trocar than the instrument is long: the distance from
    // the shaft's origin on the link (l_a = 0) to the tip. An instrument on the last link only:
    // with the constraint on a middle link the tip moves with the joints beyond it.
    let reach = (g0e.translation - shaft.constraint_pose(&g0i, 0.0).translation).norm();
    for (k, p) in trajectory
        .position
        .iter()
        .enumerate()
        .filter(|_| on_last_link)
    {
        let d = (Vector3::from(*p) - trocar).norm();
        if d > reach {
            return Err(Error::Input(format!(
                "{source}:{}: columns x, y, z: the point is {d:.4} m from the trocar, farther than the instrument reaches ({reach:.4} m from the trocar at most)",
                trajectory.lines.get(k).copied().unwrap_or(k + 2)
            )));
        }
        // Every point of the path is beyond the trocar, on the side the tip enters at q0.
        if (Vector3::from(*p) - trocar).dot(&(g0e.translation - trocar)) <= 0.0 {
            return Err(Error::Input(format!(
                "{source}:{}: columns x, y, z: the point is behind the trocar (on the robot's side of the plane through the trocar across the instrument at q0): the instrument would be pulled out through the trocar",
                trajectory.lines.get(k).copied().unwrap_or(k + 2)
            )));
        }
    }
    options.controller.check_sample_time(options.dt)?;
    // The instrument's length bounds `l_a` in every run: the QP holds it as its depth bounds
    // (intersected with the caller's), the other methods stop where it is left.
    let mut controller = options.controller;
    let depth = match controller.depth_limits {
        Some([lo, hi]) => [lo.max(insertion[0]), hi.min(insertion[1])],
        None => insertion,
    };
    if !(depth[0] < depth[1] && depth[0] <= l_a0 && l_a0 <= depth[1]) {
        return Err(Error::Input(format!(
            "depth_limits: l_a = {l_a0:.4} at q0 is outside [{:.4}, {:.4}] (the bounds given, within the instrument's ({:.4}, {:.4}))",
            depth[0], depth[1], insertion[0], insertion[1]
        )));
    }
    if depth.iter().all(|v| v.is_finite()) {
        controller.depth_limits = Some(depth);
    }
    let mut ctrl = RobotController::new(robot, controller)?;
    let axes = arm.lateral_axes();
    const NAMES: [&str; 3] = ["x_r", "y_r", "z_r"];
    let steps = trajectory.steps(options.dt, &source)?;
    let limits = robot.joint_limits();
    let mut rows = Vec::with_capacity(steps + 1);
    let mut q = q0.clone();
    let dv = vec![0.0; constraint.h.len()];
    let report = (steps / 100).max(1);
    for k in 0..=steps {
        let t = k as f64 * options.dt;
        let target = trajectory.reference(t, &g0e, &trocar);
        let step = ctrl
            .step(
                &q,
                &target,
                &[trocar.x, trocar.y, trocar.z],
                &dv,
                options.dt,
            )
            .map_err(|e| Error::Simulation(format!("t = {t:.3} s: {e}")))?;
        if !(depth[0] <= step.l_a && step.l_a <= depth[1]) && step.status.held() {
            return Err(Error::Simulation(format!(
                "t = {t:.3} s: l_a = {:.4} left [{:.4}, {:.4}] (the instrument between the link and its tip, and the depth bounds given): the run stops",
                step.l_a, depth[0], depth[1]
            )));
        }
        if !step.status.held() {
            return Err(Error::Simulation(format!(
                "t = {t:.3} s: {} (lateral error {:.3e} m); the run stops at the first step \
                 that does not hold every constraint",
                step.status,
                step.lateral_error
                    .iter()
                    .fold(0.0f64, |m, v| m.max(v.abs()))
            )));
        }
        let rotation = target.rotation.map(|r| Matrix3::from_fn(|i, j| r[i][j]));
        rows.push(arm.measure(&StepRecord {
            t,
            q: &q,
            qd: &step.qd,
            dt: options.dt,
            trocar: &trocar,
            position: &Vector3::from(target.position),
            rotation: rotation.as_ref(),
            w_r: step.w_r,
            w_i: step.w_i,
            kappa_r: step.kappa_r,
            dv_cmd: [0.0, 0.0],
        }));
        for (a, b) in q.iter_mut().zip(&step.qd) {
            *a += b * options.dt;
        }
        if let Some(k) = q
            .iter()
            .chain(&step.qd)
            .position(|v| trocar_model::validity::check(*v).is_err())
        {
            let (what, j) = if k < n { ("q", k) } else { ("qd", k - n) };
            return Err(Error::Simulation(format!(
                "t = {t:.3} s: {what}{} = {:e} is beyond the numbers a run writes (finite, within ±{:e})",
                j + 1,
                if k < n { q[j] } else { step.qd[j] },
                trocar_model::validity::MAX_MAGNITUDE
            )));
        }
        if k % report == 0 {
            progress(k as f64 / steps.max(1) as f64);
        }
    }
    progress(1.0);
    let joint_limits: Option<Vec<[f64; 2]>> = limits.iter().copied().collect();
    let speeds: Option<Vec<f64>> = desc.joints.iter().map(|j| j.speed_limit).collect();
    let trace = Trace {
        scenario: None,
        title: format!("{} along {}", desc.name, file_name(&source)),
        arm,
        method: options.controller.method,
        drift_correction: options.controller.kr != 0.0,
        constrained_directions: constraint.h.len(),
        dt: options.dt,
        joints: n,
        lateral_axes: [NAMES[axes[0]], NAMES[axes[1]]],
        joint_limits,
        speed_limits: speeds.filter(|_| options.controller.method == Method::Qp),
        depth_limits: options
            .controller
            .depth_limits
            .filter(|_| options.controller.method == Method::Qp),
        rows,
    };
    let s = trace.summary();
    // The closest approach over the joints that have limits (all or some of them).
    let margin = limits
        .iter()
        .enumerate()
        .filter_map(|(k, l)| {
            let [lo, hi] = (*l)?;
            Some(
                trace
                    .rows
                    .iter()
                    .map(|r| (r.q[k] - lo).min(hi - r.q[k]))
                    .fold(f64::INFINITY, f64::min),
            )
        })
        .fold(f64::INFINITY, f64::min);
    let max_lateral = trace
        .rows
        .iter()
        .map(|r| r.vr[0].abs().max(r.vr[1].abs()))
        .fold(0.0, f64::max);
    let after_1s = if trajectory.t[trajectory.t.len() - 1] > 1.0 {
        format!(", after the first second {:.3e} m", s.max_ep_after_1s)
    } else {
        String::new()
    };
    let summary = format!(
        "`{}` along {source} ({:?}, {} steps of {} s): max tip error {:.3e} m{after_1s}, max orientation error {:.3e}, max drift {:.3e} m, max lateral velocity {:.3e} m/s, peak joint rate {:.3e}{}",
        desc.name,
        options.controller.method,
        steps,
        options.dt,
        s.max_ep,
        s.max_eo,
        s.max_drift,
        max_lateral,
        s.peak_qd,
        if margin.is_finite() {
            format!(
                ", closest approach to a joint limit {margin:.4} rad{}",
                if margin < 0.0 { " (BEYOND A LIMIT)" } else { "" }
            )
        } else {
            String::new()
        }
    );
    Ok(SimulationRun::from_trace(trace, summary))
}

/// The last component of a path as written, for titles.
fn file_name(path: &str) -> &str {
    path.rsplit(['/', '\\']).next().unwrap_or(path)
}

/// What the caller of [`simulate_robot`] gives (the command line's `--trajectory`, `--q0`,
/// `--trocar`, `--method`, `--drift-correction off`, `--max-joint-speed`); each entry left
/// `None` is taken from the description's `[simulation]` section
/// ([`trocar_model::description::SimulationDesc`]), else from the defaults
/// ([`ControllerOptions::default`], the trocar at the constraint frame's origin at `q0`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunRequest {
    /// The trajectory CSV.
    pub trajectory: Option<PathBuf>,
    /// The start configuration.
    pub q0: Option<Vec<f64>>,
    /// The trocar point (m, base frame).
    pub trocar: Option<[f64; 3]>,
    /// The inverse of the task Jacobian.
    pub method: Option<Method>,
    /// `Some(false)` turns the drift correction off (`K_r = 0`); `Some(true)` keeps it on (the
    /// section's `kr`, else the default, when the section's is 0).
    pub drift_correction: Option<bool>,
    /// The joint speed limit.
    pub max_joint_speed: Option<crate::SpeedLimit>,
}

impl Robot {
    /// The `[simulation]` section of the robot's description, when it has one: read from the
    /// file it was loaded from, or from the shipped text for a shipped name. Errors name the
    /// file, the line and the field.
    pub fn simulation_section(&self) -> Result<Option<SimulationDesc>> {
        let Some(desc) = self.description() else {
            return Ok(None);
        };
        let n = desc.joints.len();
        let file = Path::new(self.source());
        if file.is_file() {
            return Ok(SimulationDesc::from_toml_file(file, n)?);
        }
        match trocar_model::description::preset(self.source()) {
            Some(text) => Ok(SimulationDesc::from_toml_str(
                text,
                Some(Path::new(&format!("<preset {}>", self.source()))),
                n,
            )?),
            None => Ok(None),
        }
    }
}

/// Runs `robot` along a user's trajectory with what the caller gives, completed from the
/// description's `[simulation]` section ([`RunRequest`]): `trocar simulate my_arm.toml` runs
/// the description's own scenario, and every flag overrides its entry. Errors say how to give
/// what is missing (a trajectory, `q0`).
pub fn simulate_robot(
    robot: &Robot,
    request: &RunRequest,
    progress: &mut dyn FnMut(f64),
) -> Result<SimulationRun> {
    let section = robot.simulation_section()?.unwrap_or_default();
    let (trajectory, options) = request.resolve(robot, &section)?;
    let trajectory = Trajectory::from_csv(&trajectory)?;
    simulate_trajectory(robot, &trajectory, &options, progress)
}

impl RunRequest {
    /// The trajectory file and the options of a run of `robot`: this request's values, else
    /// those of `section` (the description's, [`Robot::simulation_section`]), else the
    /// defaults.
    pub fn resolve(
        &self,
        robot: &Robot,
        section: &SimulationDesc,
    ) -> Result<(PathBuf, TrajectoryOptions)> {
        resolve(robot, self, section)
    }
}

fn resolve(
    robot: &Robot,
    request: &RunRequest,
    section: &SimulationDesc,
) -> Result<(PathBuf, TrajectoryOptions)> {
    let where_ = |key: &str| {
        format!(
            "`{key} = ...` in the [simulation] section of {}",
            robot
                .description()
                .and_then(|d| d.source.as_ref())
                .map_or_else(
                    || "the description".to_string(),
                    |p| p.display().to_string()
                )
        )
    };
    let trajectory = request
        .trajectory
        .clone()
        .or_else(|| section.trajectory.clone())
        .ok_or_else(|| {
            Error::argument(
                "trajectory",
                format!(
                    "`{}` runs along a trajectory: give one (a CSV file) or set it as {}",
                    robot.name(),
                    where_("trajectory")
                ),
            )
        })?;
    let q0 = request
        .q0
        .clone()
        .or_else(|| section.q0.clone())
        .ok_or_else(|| {
            Error::argument(
                "q0",
                format!(
                    "the start configuration of the trajectory is missing: give q1,...,q{} (all joints of `{}`, base first) or set it as {}",
                    robot.dof(),
                    robot.name(),
                    where_("q0")
                ),
            )
        })?;
    let mut controller = ControllerOptions::default();
    if let Some(m) = section.method.as_deref() {
        controller.method = Method::from_name(m).unwrap_or(controller.method);
    }
    let set = |slot: &mut f64, v: Option<f64>| {
        if let Some(v) = v {
            *slot = v;
        }
    };
    set(&mut controller.kp, section.kp);
    set(&mut controller.ko, section.ko);
    set(&mut controller.kr, section.kr);
    set(&mut controller.dls_alpha0, section.dls_alpha0);
    set(&mut controller.null_space_gain, section.null_space_gain);
    if let Some(v) = section.max_joint_speed {
        controller.max_joint_speed = Some(v);
    }
    if let Some(m) = request.method {
        controller.method = m;
    }
    match request.drift_correction {
        Some(false) => controller.kr = 0.0,
        Some(true) if controller.kr == 0.0 => controller.kr = ControllerOptions::default().kr,
        _ => {}
    }
    match request.max_joint_speed {
        Some(crate::SpeedLimit::Unlimited) => controller.max_joint_speed = None,
        Some(crate::SpeedLimit::At(v)) => controller.max_joint_speed = Some(v),
        None => {}
    }
    let dt = 0.002;
    // The section's gains against the sample time, located at their entry.
    for (key, given, value) in [
        ("kp", section.kp, controller.kp),
        ("ko", section.ko, controller.ko),
        ("kr", section.kr, controller.kr),
    ] {
        if given.is_some() {
            crate::controller::check_gain_times_dt(key, value, dt)
                .map_err(|e| Error::Input(format!("{}: {e}", where_(key))))?;
        }
    }
    Ok((
        trajectory,
        TrajectoryOptions {
            q0,
            trocar: request.trocar.or(section.trocar),
            controller,
            dt,
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_rows() -> Trajectory {
        Trajectory {
            source: None,
            t: vec![0.0, 1.0],
            position: vec![[0.0; 3], [0.1, 0.0, 0.0]],
            orientation: Orientation::Roll(vec![0.0, 0.5]),
            lines: Vec::new(),
            header_line: 1,
        }
    }

    /// A trajectory built by hand is checked as one read from a file.
    #[test]
    fn a_hand_built_trajectory_is_checked() {
        assert!(two_rows().check("p").is_ok());
        let mut short = two_rows();
        short.position.pop();
        assert!(short
            .check("p")
            .unwrap_err()
            .to_string()
            .contains("1 positions"));
        let mut back = two_rows();
        back.t[1] = 0.0;
        assert!(back
            .check("p")
            .unwrap_err()
            .to_string()
            .contains("row 2: t = 0"));
        let mut nan = two_rows();
        nan.position[1][2] = f64::NAN;
        assert!(nan
            .check("p")
            .unwrap_err()
            .to_string()
            .contains("not finite"));
        let mut quat = two_rows();
        quat.orientation =
            Orientation::Quaternion(vec![[1.0, 0.0, 0.0, 0.0], [2.0, 0.0, 0.0, 0.0]]);
        assert!(quat
            .check("p")
            .unwrap_err()
            .to_string()
            .contains("row 2: the quaternion"));
        let robot = Robot::load("panda-laparoscope").unwrap();
        let options = TrajectoryOptions {
            q0: vec![0.0; 7],
            trocar: None,
            controller: ControllerOptions::default(),
            dt: 0.002,
        };
        let e = simulate_trajectory(&robot, &short, &options, &mut |_| {}).unwrap_err();
        assert!(e.to_string().contains("at least two rows"), "{e}");
    }
}
