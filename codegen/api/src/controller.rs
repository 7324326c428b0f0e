//! The constrained kinematic controller ([`trocar::control::Controller`]) on a robot loaded at
//! run time: the same step the Rust crate runs on fixed sizes (task selection `S`, drift
//! correction on the trocar, the null-space objective (44)–(46) keeping the joints from their
//! limits), chosen for the robot's sizes when it is built.
//!
//! With [`Method::Qp`] the step is the quadratic program of `trocar::control::hard_limits`:
//! the trocar as equality rows, the description's joint ranges and speed limits (the URDF's
//! `<limit lower upper velocity>`) and [`ControllerOptions::depth_limits`] as hard limits.
//! Every method keeps the description's acceleration and jerk limits (a URDF 1.2 `<limit
//! acceleration jerk>`, `acceleration_limit` and `jerk_limit` in TOML) and
//! [`ControllerOptions::max_joint_acceleration`] from one step's rates to the next
//! (`trocar::control::rate_box`).
//!
//! The kinematics are the numeric runtime's ([`trocar::control::ChainKinematics`]). The sizes
//! the controller is instantiated for are listed in [`SUPPORTED`]: `n` joints 6–8, the
//! constraint on link `i ≥ 6`, `r` = 1–3 constrained directions, 3–6 task rows. Another robot
//! uses `trocar::control::Controller` with its generated module.

use crate::error::{Error, Result};
use crate::robot::Robot;
use nalgebra::{Const, Matrix3, SVector, Vector3};
use trocar::control::{
    self, ChainKinematics, Controller as Typed, HardLimits, NullSpaceObjective, QpReport,
    RateRelaxation, Rcm, Reference, StepStatus,
};
use trocar::linalg::SquareDim;
use trocar_model::numeric::NumericModel;
use trocar_sim::simulation::{Method, Scenario, ScenarioConfig};

/// Gains and methods of a [`RobotController`]; [`ControllerOptions::default`] is the Panda
/// laparoscope scenario's (Table 4.2's `K_p = 5`, `K_o = 10`, DLS `α0 = 0.05`, drift correction
/// `K_r = 20 /s`, joint speed limit 2 rad/s, null-space gain 10 /s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControllerOptions {
    /// Inverse of the task Jacobian `S J^r_0e` (Table 4.1).
    pub method: Method,
    /// Position gain `K_p` (1/s).
    pub kp: f64,
    /// Orientation gain `K_o` (1/s).
    pub ko: f64,
    /// Gain `K_r` (1/s) of the drift correction on the trocar; 0 for the thesis's controller.
    pub kr: f64,
    /// DLS: largest damping `α0` (3.44).
    pub dls_alpha0: f64,
    /// DLS: manipulability threshold `w0` of the task Jacobian.
    pub dls_w0_task: f64,
    /// DLS: manipulability threshold `w0` of `J^B_0i`.
    pub dls_w0_jb0i: f64,
    /// Filtered inverse gains `Γ_r = Γ_l` (3.47)–(3.50).
    pub fi_gamma: f64,
    /// Joint speed limit (rad/s), `None` for none.
    pub max_joint_speed: Option<f64>,
    /// Joint acceleration limit (rad/s²) on every joint, with the description's own
    /// (`acceleration_limit`, a URDF 1.2 `<limit acceleration=...>`) the smaller of the two;
    /// `None`: the description's alone. With either, each step's rates change by at most
    /// `a_max dt` from the last step's and brake in time for the joint ranges
    /// (`trocar::control::rate_box`); the controller starts from rest
    /// ([`RobotController::reset`]).
    pub max_joint_acceleration: Option<f64>,
    /// Gain `K` (1/s) of the joint-limit objective (46) on the spare freedom of `J^B_0i` when
    /// the robot has joint limits and `i > 6`; 0 for none.
    pub null_space_gain: f64,
    /// QP ([`Method::Qp`]): the weight `κ` of the joint rates' norm (`γ = κ²` for the
    /// objective).
    pub qp_kappa: f64,
    /// QP: bounds `[l_min, l_max]` (m) of the trocar's offset `l_a` along the shaft (the
    /// insertion depth), `None` for none.
    pub depth_limits: Option<[f64; 2]>,
}

impl Default for ControllerOptions {
    fn default() -> Self {
        let s = ScenarioConfig::new(Scenario::Panda);
        ControllerOptions {
            method: s.method,
            kp: s.kp,
            ko: s.ko,
            kr: s.kr,
            dls_alpha0: s.dls_alpha0,
            dls_w0_task: s.dls_w0_r,
            dls_w0_jb0i: s.dls_w0_i,
            fi_gamma: s.fi_gamma,
            max_joint_speed: s.max_joint_speed,
            max_joint_acceleration: None,
            null_space_gain: s.null_space_gain,
            qp_kappa: s.qp_kappa,
            depth_limits: None,
        }
    }
}

impl ControllerOptions {
    /// The core's configuration, through the simulations' one mapping
    /// ([`ScenarioConfig::controller_config`]).
    fn config(&self) -> control::ControllerConfig<f64> {
        let mut s = ScenarioConfig::new(Scenario::Panda).with_method(self.method);
        s.kp = self.kp;
        s.ko = self.ko;
        s.kr = self.kr;
        s.drift_correction = self.kr != 0.0;
        s.dls_alpha0 = self.dls_alpha0;
        s.dls_w0_r = self.dls_w0_task;
        s.dls_w0_i = self.dls_w0_jb0i;
        s.fi_gamma = self.fi_gamma;
        s.max_joint_speed = self.max_joint_speed;
        s.qp_kappa = self.qp_kappa;
        s.controller_config()
    }

    /// Checks the gains against the sample time `dt` (s): `dt` finite and positive, and each
    /// proportional gain below its stable bound (`kp dt`, `kr dt < 2`, `ko dt < 4`:
    /// [`trocar::control::gain_bound`]), with the bound in the message.
    pub fn check_sample_time(&self, dt: f64) -> Result<()> {
        self.check()?;
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::Input(format!(
                "dt = {dt}: must be a positive time (s)"
            )));
        }
        for (name, k) in [("kp", self.kp), ("ko", self.ko), ("kr", self.kr)] {
            check_gain_times_dt(name, k, dt)?;
        }
        Ok(())
    }

    pub(crate) fn check(&self) -> Result<()> {
        let named = [
            ("kp", self.kp),
            ("ko", self.ko),
            ("kr", self.kr),
            ("dls_alpha0", self.dls_alpha0),
            ("dls_w0_task", self.dls_w0_task),
            ("dls_w0_jb0i", self.dls_w0_jb0i),
            ("fi_gamma", self.fi_gamma),
            ("null_space_gain", self.null_space_gain),
            ("qp_kappa", self.qp_kappa),
        ];
        for (name, v) in named {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::Input(format!(
                    "{name} = {v}: must be a finite number ≥ 0"
                )));
            }
        }
        if let Some(v) = self.max_joint_speed {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::Input(format!(
                    "max_joint_speed = {v}: must be a positive number (or none)"
                )));
            }
        }
        if let Some(v) = self.max_joint_acceleration {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::Input(format!(
                    "max_joint_acceleration = {v}: must be a positive number (rad/s², or none)"
                )));
            }
        }
        if let Some([lo, hi]) = self.depth_limits {
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(Error::Input(format!(
                    "depth_limits = [{lo}, {hi}]: need finite l_min < l_max (m)"
                )));
            }
        }
        Ok(())
    }
}

/// Refuses the proportional gain `name` (`"kp"`, `"ko"` or `"kr"`) of value `k` (1/s) when
/// `k dt` is not below its stable bound ([`trocar::control::gain_bound`]), with the bound.
pub(crate) fn check_gain_times_dt(name: &str, k: f64, dt: f64) -> Result<()> {
    let bound = control::gain_bound(name);
    if k * dt >= bound {
        return Err(Error::Input(format!(
            "{name} = {k} /s at dt = {dt} s: {name} · dt = {:.4} is not below {bound}, where the \
             discrete loop stops converging; at this sample time {name} < {} /s",
            k * dt,
            bound / dt
        )));
    }
    Ok(())
}

/// How far a target's rotation matrix may be from orthonormal: the largest entry of `RᵀR − I`
/// (the runtime's rule, `trocar::se3::ROTATION_TOLERANCE`, the C ABI's too).
pub const ROTATION_TOLERANCE: f64 = trocar::se3::ROTATION_TOLERANCE;

/// Whether `r` (row by row) is a proper rotation: finite, `|RᵀR − I| ≤` [`ROTATION_TOLERANCE`]
/// entry by entry and `det R > 0` (a zero matrix or a reflection would be read as some other
/// orientation). The reason when it is not. [`RobotController::step`] refuses a target whose
/// rotation is not.
pub fn proper_rotation(r: &[[f64; 3]; 3]) -> std::result::Result<(), String> {
    if let Some(v) = r.iter().flatten().find(|v| !v.is_finite()) {
        return Err(format!("{v} is not a finite number"));
    }
    let m = nalgebra::Matrix3::from_fn(|i, j| r[i][j]);
    if trocar::se3::is_rotation(&m) {
        return Ok(());
    }
    let (worst, det) = trocar::se3::rotation_defect(&m).unwrap_or((f64::NAN, f64::NAN));
    Err(format!(
        "not a rotation matrix (RᵀR differs from I by {worst:.3e}, tolerance {ROTATION_TOLERANCE:e}; det R = {det:.6})"
    ))
}

/// The desired end-effector motion at one instant, in base coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Target {
    /// Desired position `dp_0e` (m).
    pub position: [f64; 3],
    /// Desired orientation `dR_0e`, row by row; `None` keeps the current orientation (no
    /// orientation error).
    pub rotation: Option<[[f64; 3]; 3]>,
    /// Feed-forward linear velocity (m/s).
    pub velocity: [f64; 3],
    /// Feed-forward angular velocity (rad/s, base coordinates).
    pub angular_velocity: [f64; 3],
}

/// What one step computed.
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    /// Joint rates `θ̇` (rad/s or m/s), one per joint.
    pub qd: Vec<f64>,
    /// The trocar's offset `l_a` along the shaft at this step.
    pub l_a: f64,
    /// Position error `e_p = R_0eᵀ(dp − p)` (end-effector frame, m).
    pub position_error: [f64; 3],
    /// Vector part `ε̃` of the orientation error quaternion.
    pub orientation_error: [f64; 3],
    /// Lateral offset of the trocar from the link in the constrained directions of `F_r` (m).
    pub lateral_error: Vec<f64>,
    /// The RCM velocity used, `dv_0r = dv_cmd + K_r e_r`.
    pub dv_0r: Vec<f64>,
    /// Manipulability of the task Jacobian `S J^r_0e`.
    pub w_r: f64,
    /// Manipulability of `J^B_0i`.
    pub w_i: f64,
    /// Damping applied to the task Jacobian (0 unless DLS).
    pub kappa_r: f64,
    /// Damping applied to `J^B_0i`.
    pub kappa_i: f64,
    /// The QP's outcome with [`Method::Qp`]: its status (`"Optimal"`,
    /// `"EqualitiesInconsistent"`: the trocar rows met in least squares within the limits, ...),
    /// working-set changes and active limits; `None` for the other methods.
    pub qp: Option<QpReport>,
    /// Whether every constraint held, or which gave way: the joint limits never do (every
    /// method's rates keep each joint within its speed limit and, over `dt`, its range).
    pub status: StepStatus,
    /// Which of the rate limits that depend on the previous step (acceleration, braking, jerk)
    /// gave way at some joint, because no rates met it with the more important ones
    /// ([`RateRelaxation`]: `Nothing` when all held).
    pub relaxed: RateRelaxation,
}

/// One instantiation of the typed controller, behind the sizes known at run time.
trait Stepper: Send + Sync + std::fmt::Debug {
    fn step(
        &mut self,
        q: &[f64],
        target: &Target,
        trocar: &[f64; 3],
        dv: &[f64],
        dt: f64,
    ) -> std::result::Result<Step, control::ControlError>;
    fn reset(&mut self);
    fn set_previous_rates(&mut self, rates: &[f64], acceleration: &[f64]);
    fn trocar_rate(&self, q: &[f64], velocity: &[f64; 3]) -> Vec<f64>;
}

#[derive(Debug)]
struct Sized<
    const N: usize,
    const I: usize,
    const R: usize,
    const K: usize,
    const M: usize,
    const P: usize,
> {
    kin: ChainKinematics<f64, N, R, P>,
    ctrl: Typed<f64, N, I, R, K, M, P>,
}

impl<
        const N: usize,
        const I: usize,
        const R: usize,
        const K: usize,
        const M: usize,
        const P: usize,
    > Stepper for Sized<N, I, R, K, M, P>
where
    Const<R>: SquareDim,
    Const<I>: SquareDim,
    Const<M>: SquareDim,
    Const<P>: SquareDim,
{
    fn trocar_rate(&self, q: &[f64], velocity: &[f64; 3]) -> Vec<f64> {
        type Kinematics<const N: usize, const R: usize, const P: usize> =
            ChainKinematics<f64, N, R, P>;
        let q = SVector::<f64, N>::from_column_slice(q);
        let g_0i =
            <Kinematics<N, R, P> as control::ConstrainedKinematics<f64, N, I, R, K, M, P>>::g_0i(
                &self.kin, &q,
            );
        let h = <Kinematics<N, R, P> as control::ConstrainedKinematics<f64, N, I, R, K, M, P>>::h(
            &self.kin,
        );
        self.kin
            .shaft
            .trocar_rate(&g_0i, &h, &Vector3::from(*velocity))
            .as_slice()
            .to_vec()
    }

    fn step(
        &mut self,
        q: &[f64],
        target: &Target,
        trocar: &[f64; 3],
        dv: &[f64],
        dt: f64,
    ) -> std::result::Result<Step, control::ControlError> {
        let q = SVector::<f64, N>::from_column_slice(q);
        let rotation = match target.rotation {
            Some(r) => Matrix3::from_fn(|i, j| r[i][j]),
            None => self.kin.chain.forward_kinematics(&q).rotation,
        };
        let reference = Reference {
            position: Vector3::from(target.position),
            rotation,
            velocity: Vector3::from(target.velocity),
            angular_velocity: Vector3::from(target.angular_velocity),
        };
        let rcm = Rcm {
            trocar: Vector3::from(*trocar),
            dv: SVector::<f64, R>::from_column_slice(dv),
        };
        let out = self.ctrl.step(&self.kin, &q, &reference, &rcm, dt)?;
        Ok(Step {
            qd: out.qd.as_slice().to_vec(),
            l_a: out.l_a,
            position_error: out.ep.into(),
            orientation_error: out.eq.eps.into(),
            lateral_error: out.lateral_error.as_slice().to_vec(),
            dv_0r: out.dv_0r.as_slice().to_vec(),
            w_r: out.w_r,
            w_i: out.w_i,
            kappa_r: out.kappa_r,
            kappa_i: out.kappa_i,
            qp: out.qp,
            status: out.status,
            relaxed: out.relaxed,
        })
    }

    fn set_previous_rates(&mut self, rates: &[f64], acceleration: &[f64]) {
        self.ctrl.set_previous_rates(
            SVector::from_column_slice(rates),
            SVector::from_column_slice(acceleration),
        );
    }

    fn reset(&mut self) {
        self.ctrl.reset();
    }
}

/// Builds the typed controller for `(N, I, R, P)` from the list of supported sizes.
macro_rules! dispatch {
    ($model:expr, $config:expr, $objective:expr, $hard:expr, $sizes:expr; $(($n:literal, $i:literal, $r:literal, $p:literal)),* $(,)?) => {{
        let model: &NumericModel<f64> = $model;
        let sizes: (usize, usize, usize, usize) = $sizes;
        let boxed: Option<std::result::Result<Box<dyn Stepper>, String>> = match sizes {
            $(
                ($n, $i, $r, $p) => Some((|| {
                    let kin = model
                        .to_kinematics::<$n, $r, $p>()
                        .map_err(|e| e.to_string())?;
                    let objective: Option<(f64, Vec<[f64; 2]>)> = $objective;
                    let mut ctrl = Typed::<f64, $n, $i, $r, { 6 - $r }, { 6 - $r + $n - $i }, $p>::new($config);
                    let hard: &Hard = $hard;
                    ctrl = ctrl.with_limits(hard.limits::<$n>());
                    if let Some((gain, limits)) = objective {
                        ctrl = ctrl.with_objective(NullSpaceObjective::JointLimits {
                            gain,
                            lower: SVector::from_fn(|k, _| limits[k][0]),
                            upper: SVector::from_fn(|k, _| limits[k][1]),
                        });
                    }
                    Ok(Box::new(Sized { kin, ctrl }) as Box<dyn Stepper>)
                })()),
            )*
            _ => None,
        };
        boxed
    }};
}

/// The hard limits, sized at run time: each joint's range, speed, acceleration and jerk limit
/// (infinite where the description has none) and the depth bounds (the QP's).
struct Hard {
    ranges: Vec<[f64; 2]>,
    speeds: Vec<f64>,
    accelerations: Vec<f64>,
    jerks: Vec<f64>,
    depth: Option<[f64; 2]>,
}

impl Hard {
    fn limits<const N: usize>(&self) -> HardLimits<f64, N> {
        let mut h = HardLimits::none()
            .with_joint_limits(
                SVector::from_fn(|k, _| self.ranges[k][0]),
                SVector::from_fn(|k, _| self.ranges[k][1]),
            )
            .with_speed_limits(SVector::from_fn(|k, _| self.speeds[k]))
            .with_acceleration_limits(SVector::from_fn(|k, _| self.accelerations[k]))
            .with_jerk_limits(SVector::from_fn(|k, _| self.jerks[k]));
        if let Some([lo, hi]) = self.depth {
            h = h.with_depth(lo, hi);
        }
        h
    }
}

/// Calls `$callback!($($args)*; (n, i, r, task rows), ...)` with the sizes the controller is
/// instantiated for: one list for [`SUPPORTED`] and for the dispatch in
/// [`RobotController::new`].
macro_rules! with_supported_sizes {
    ($callback:ident!($($args:tt)*)) => {
        $callback!($($args)*;
            (6, 6, 1, 3), (6, 6, 1, 4), (6, 6, 1, 5), (6, 6, 2, 3),
            (6, 6, 2, 4), (6, 6, 3, 3), (7, 6, 1, 3), (7, 6, 1, 4),
            (7, 6, 1, 5), (7, 6, 1, 6), (7, 6, 2, 3), (7, 6, 2, 4),
            (7, 6, 2, 5), (7, 6, 3, 3), (7, 6, 3, 4), (7, 7, 1, 3),
            (7, 7, 1, 4), (7, 7, 1, 5), (7, 7, 2, 3), (7, 7, 2, 4),
            (7, 7, 3, 3), (8, 6, 1, 4), (8, 6, 1, 6), (8, 6, 2, 4),
            (8, 6, 2, 6), (8, 6, 3, 4), (8, 6, 3, 5), (8, 7, 1, 4),
            (8, 7, 1, 6), (8, 7, 2, 4), (8, 7, 2, 5), (8, 7, 3, 4),
            (8, 8, 1, 4), (8, 8, 1, 5), (8, 8, 2, 4), (8, 8, 3, 3),
        )
    };
}

/// The list of sizes as a slice.
macro_rules! size_list {
    (; $(($n:literal, $i:literal, $r:literal, $p:literal)),* $(,)?) => {
        &[$(($n, $i, $r, $p)),*]
    };
}

/// The sizes `(n, i, r, task rows)` the controller is instantiated for.
pub const SUPPORTED: &[(usize, usize, usize, usize)] = with_supported_sizes!(size_list!());

/// The constrained kinematic controller on a [`Robot`], with the sizes of its description.
///
/// ```no_run
/// use trocar_api::{RobotController, ControllerOptions, Robot, Target};
/// let robot = Robot::load("panda-laparoscope")?;
/// let mut ctrl = RobotController::new(&robot, ControllerOptions::default())?;
/// let q = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785];
/// let target = Target { position: [0.3, 0.0, 0.2], rotation: None, velocity: [0.0; 3], angular_velocity: [0.0; 3] };
/// let step = ctrl.step(&q, &target, &[0.3, 0.0, 0.45], &[0.0, 0.0], 0.002)?;
/// assert_eq!(step.qd.len(), 7);
/// # Ok::<(), trocar_api::Error>(())
/// ```
#[derive(Debug)]
pub struct RobotController {
    inner: Box<dyn Stepper>,
    dof: usize,
    rows: usize,
}

impl RobotController {
    /// A controller for `robot` (a serial robot with a `[constraint]`) with `options`.
    pub fn new(robot: &Robot, options: ControllerOptions) -> Result<Self> {
        options.check()?;
        let desc = robot.description().ok_or_else(|| {
            Error::Unsupported(format!(
                "`{}` is a closed mechanism: the constrained controller runs serial robots",
                robot.name()
            ))
        })?;
        let constraint = desc.constraint.as_ref().ok_or_else(|| {
            Error::Unsupported(format!(
                "`{}` has no [constraint]: the constrained controller needs one",
                desc.name
            ))
        })?;
        let n = desc.joints.len();
        let (i, r) = (constraint.link, constraint.h.len());
        let p = desc.task.as_ref().map_or(6, |t| t.select.len());
        let model = robot.numeric()?.model();
        let limits: Option<Vec<[f64; 2]>> = desc.joints.iter().map(|j| j.limits).collect();
        let objective = match limits {
            Some(l) if i > 6 && options.null_space_gain > 0.0 => Some((options.null_space_gain, l)),
            _ => None,
        };
        let config = options.config();
        let hard = Hard {
            ranges: desc
                .joints
                .iter()
                .map(|j| j.limits.unwrap_or([f64::NEG_INFINITY, f64::INFINITY]))
                .collect(),
            speeds: desc
                .joints
                .iter()
                .map(|j| j.speed_limit.unwrap_or(f64::INFINITY))
                .collect(),
            accelerations: desc
                .joints
                .iter()
                .map(|j| {
                    let own = j.acceleration_limit.unwrap_or(f64::INFINITY);
                    options.max_joint_acceleration.map_or(own, |v| v.min(own))
                })
                .collect(),
            jerks: desc
                .joints
                .iter()
                .map(|j| j.jerk_limit.unwrap_or(f64::INFINITY))
                .collect(),
            depth: options.depth_limits,
        };
        let built = with_supported_sizes!(dispatch!(
            model,
            config,
            objective.clone(),
            &hard,
            (n, i, r, p)
        ));
        match built {
            Some(Ok(inner)) => Ok(RobotController {
                inner,
                dof: n,
                rows: r,
            }),
            Some(Err(e)) => Err(Error::Robot {
                file: desc.source.clone(),
                message: e,
            }),
            None => Err(Error::Unsupported(format!(
                "`{}`: n = {n} joints, constraint on link i = {i}, r = {r} constrained \
                 directions and {p} task rows: the run-time controller is built for (n, i, r, \
                 task rows) in {}; use trocar::control::Controller with the generated module",
                desc.name,
                SUPPORTED
                    .iter()
                    .map(|(n, i, r, p)| format!("({n}, {i}, {r}, {p})"))
                    .collect::<Vec<_>>()
                    .join(" ")
            ))),
        }
    }

    /// One control step at joints `q` toward `target`, with the trocar at `trocar` (base
    /// coordinates) commanded to move laterally at `dv` (one value per constrained direction;
    /// zeros for a fixed trocar); `dt` is the sample time (the filtered inverse uses it).
    pub fn step(
        &mut self,
        q: &[f64],
        target: &Target,
        trocar: &[f64; 3],
        dv: &[f64],
        dt: f64,
    ) -> Result<Step> {
        if q.len() != self.dof {
            return Err(Error::Input(format!(
                "q has {} values, the robot has {} joints",
                q.len(),
                self.dof
            )));
        }
        if dv.len() != self.rows {
            return Err(Error::Input(format!(
                "dv has {} values, the constraint has {} constrained directions",
                dv.len(),
                self.rows
            )));
        }
        let finite = q
            .iter()
            .chain(&target.position)
            .chain(&target.velocity)
            .chain(&target.angular_velocity)
            .chain(trocar)
            .chain(dv)
            .chain(target.rotation.iter().flatten().flatten())
            .all(|v| v.is_finite());
        if !finite {
            return Err(Error::Input(
                "q, the target, the trocar and dv must be finite".into(),
            ));
        }
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::Input(format!(
                "dt = {dt}: must be a positive time (s)"
            )));
        }
        if let Some(r) = &target.rotation {
            proper_rotation(r)
                .map_err(|reason| Error::Input(format!("target.rotation: {reason}")))?;
        }
        self.inner
            .step(q, target, trocar, dv, dt)
            .map_err(|e| match e {
                control::ControlError::Config(c) => {
                    Error::Input(format!("control step at dt = {dt} s: {c}"))
                }
                e => Error::NotFinite(format!("control step: {e}")),
            })
    }

    /// The lateral velocity `dv` ([`RobotController::step`]) that carries the constraint frame
    /// with a trocar moving at `velocity` (base frame, m/s) at joints `q`: its motion across the
    /// shaft in the constrained directions (`trocar::control::Shaft::trocar_rate`), for a port
    /// whose motion is known or estimated.
    pub fn trocar_rate(&self, q: &[f64], velocity: &[f64; 3]) -> Result<Vec<f64>> {
        if q.len() != self.dof {
            return Err(Error::Input(format!(
                "q has {} values, the robot has {} joints",
                q.len(),
                self.dof
            )));
        }
        if !q.iter().chain(velocity).all(|v| v.is_finite()) {
            return Err(Error::Input(
                "q and the trocar's velocity must be finite".into(),
            ));
        }
        Ok(self.inner.trocar_rate(q, velocity))
    }

    /// Restarts the filtered inverse (it re-initialises on the next step) and the QP's warm
    /// start, and takes the arm to be at rest: with acceleration limits the next rates start
    /// from zero (`trocar::control::Controller::reset`).
    pub fn reset(&mut self) {
        self.inner.reset();
    }

    /// Continues from a known motion: the previous command was `rates` (rad/s, m/s) with the
    /// acceleration `acceleration` (`(θ̇⁻ − θ̇⁻⁻)/dt`, zeros for a steady motion); the next step's
    /// acceleration and jerk bounds are measured from them
    /// (`trocar::control::Controller::set_previous_rates`). Refused unless both have
    /// [`RobotController::dof`] finite values.
    pub fn set_previous_rates(&mut self, rates: &[f64], acceleration: &[f64]) -> Result<()> {
        for (name, v) in [("rates", rates), ("acceleration", acceleration)] {
            if v.len() != self.dof {
                return Err(Error::Input(format!(
                    "{name}: {} values given, the robot has {} joints",
                    v.len(),
                    self.dof
                )));
            }
            if let Some(k) = v.iter().position(|x| !x.is_finite()) {
                return Err(Error::Input(format!(
                    "{name}[{k}] = {}: must be finite",
                    v[k]
                )));
            }
        }
        self.inner.set_previous_rates(rates, acceleration);
        Ok(())
    }

    /// Number of joints.
    pub fn dof(&self) -> usize {
        self.dof
    }

    /// Number of constrained directions (`dv`'s length).
    pub fn constrained_directions(&self) -> usize {
        self.rows
    }
}
