//! The scenarios of the thesis's sections 4.1–4.2.1 (`docs/reference-robots.md`) and their configuration.

use core::f64::consts::PI;
use nalgebra::{Matrix3, Rotation3, Vector3};
use trocar::control::{self, ChordCheck, ControlError, ControllerConfig, Reference};
use trocar::se3::Se3;

/// A simulation scenario.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scenario {
    /// Simulation 1: unidirectional constraint (`H = x_r` on the zy arm), trajectory (4.1).
    S1,
    /// Simulation 2: bidirectional, zy wrist, trajectory (4.2).
    S2,
    /// Simulation 3: bidirectional zy, through singularities, (4.3)–(4.4).
    S3,
    /// Simulation 4: moving RCM, trajectory (4.5) = (4.2) and the RCM velocity of (4.6) with the
    /// amplitude [`ScenarioConfig::s4_rcm_amplitude`] ([`S4_RCM_AMPLITUDE`], −1 mm/s, on this
    /// arm; (4.6) as printed has +5 mm/s and is not feasible here).
    S4,
    /// Experiment 4.2.1 in kinematic simulation: pinv vs DLS vs FI near the `J^r` singularity.
    Exp421,
    /// A Franka Panda holding a 0.40 m laparoscope through a trocar (`panda-laparoscope`: the
    /// constraint on the last link, task `x y z rz`): the tip draws a circle of radius
    /// [`PANDA_CIRCLE_RADIUS`] in the plane normal to the shaft at `t = 0`, centred on the start
    /// tip position, once in [`PANDA_DURATION`], while the shaft rolls
    /// `(π/6) sin(2πt/20)`, both reached from rest in [`PANDA_RAMP`]; joint limits from the URDF, with the spare freedom of the arm kept
    /// away from them ((44)–(46) of Freitas, Leite & Lizarralde 2010).
    Panda,
    /// The Panda laparoscope against its hard limits (`panda-laparoscope-limits`): over
    /// [`PANDA_LIMITS_DURATION`] the tip is asked to withdraw along the shaft past the
    /// insertion limit ([`PANDA_DEPTH_LIMITS`]), then to roll the shaft by
    /// [`PANDA_LIMITS_ROLL`] — past joint 7's URDF limit, faster than its URDF speed limit —
    /// and back; see [`panda_limits_reference`]. No joint speed limit of the controller's own
    /// (the URDF's bind with [`control::Method::Qp`]).
    PandaLimits,
}

/// Duration of the `panda-laparoscope-limits` scenario (s).
pub const PANDA_LIMITS_DURATION: f64 = 12.0;
/// The roll about the shaft that `panda-laparoscope-limits` asks for (rad): from `q7 = π/4`
/// it would take joint 7 to 3.39 rad, past its URDF limit 2.8973.
pub const PANDA_LIMITS_ROLL: f64 = 2.6;
/// How far `panda-laparoscope-limits` asks the tip to withdraw along the shaft (m): from a depth
/// of 0.15 m to 0.07 m below the trocar, `l_a` from 0.25 m to 0.33 m, past `l_max`.
pub const PANDA_LIMITS_WITHDRAWAL: f64 = 0.08;
/// The insertion limits `[l_min, l_max]` of `l_a` in `panda-laparoscope-limits` (m): the tip
/// stays between 0.10 m and 0.35 m below the trocar (the tool is 0.40 m long).
pub const PANDA_DEPTH_LIMITS: [f64; 2] = [0.05, 0.30];

/// Radius of the Panda scenario's circle (m).
pub const PANDA_CIRCLE_RADIUS: f64 = 0.01;
/// Duration of the Panda scenario (s): one circle.
pub const PANDA_DURATION: f64 = 20.0;
/// Time (s) in which the Panda scenario's reference spirals out from the start tip position
/// onto its circle, and its roll grows to full amplitude (see [`panda_reference`]).
pub const PANDA_RAMP: f64 = 2.0;
/// Amplitude of the Panda scenario's roll about the shaft (rad).
pub const PANDA_ROLL_AMPLITUDE: f64 = PI / 6.0;
/// Depth of the laparoscope's tip below the trocar at the start (m): the tool length 0.40 m
/// minus the nominal `l_a` = 0.25 m.
pub const PANDA_TIP_DEPTH: f64 = 0.15;
/// The Panda's start configuration `(0, −π/4, 0, −3π/4, 0, π/2, π/4)` (rad).
pub const PANDA_Q0: [f64; 7] = [
    0.0,
    -PI / 4.0,
    0.0,
    -3.0 * PI / 4.0,
    0.0,
    PI / 2.0,
    PI / 4.0,
];

/// The controller's method by name: the [`control::Method`] a scenario runs, whose parameters
/// (damping, gains of the filtered inverse, the QP's weights) come from its
/// [`ScenarioConfig`] ([`ScenarioConfig::controller_config`]); the core's
/// [`control::MethodKind`].
pub use trocar::control::MethodKind as Method;

/// Why a simulation failed.
#[derive(Clone, Debug, PartialEq)]
pub enum SimulationError {
    /// Unknown scenario name.
    UnknownScenario(String),
    /// The robot description could not be used.
    Description(String),
    /// The controller failed at time `t`.
    Control {
        /// Time (s).
        t: f64,
        /// The failure.
        error: ControlError,
    },
    /// A step could not hold every constraint at time `t` (the trocar gave way to the joint
    /// limits, a joint or the insertion was outside its bounds): the run stops there.
    Yielded {
        /// Time (s).
        t: f64,
        /// What gave way.
        status: trocar::control::StepStatus,
    },
}

impl core::fmt::Display for SimulationError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            SimulationError::UnknownScenario(s) => write!(
                f,
                "unknown scenario `{s}` (expected one of: 1, 2, 3, 4, exp421, panda-laparoscope, panda-laparoscope-limits)"
            ),
            SimulationError::Description(s) => write!(f, "robot description: {s}"),
            SimulationError::Control { t, error } => write!(f, "at t = {t:.3} s: {error}"),
            SimulationError::Yielded { t, status } => write!(f, "at t = {t:.3} s: {status}"),
        }
    }
}

impl std::error::Error for SimulationError {}

/// Amplitude `A` of the simulations (m).
pub const A: f64 = 0.03;
/// Frequency `ω` of the simulations (rad/s).
pub const OMEGA: f64 = 2.0 * PI / 200.0;
/// Half-range of the experiment's rotation about the joint-7 axis at `q0` (rad), `7π/72`: the
/// rotation `(7π/72)(cos ωk − 1) ∈ [−0.61, 0]` replaces the thesis's `(π/18)(cos ωk − 1)` about
/// the end-effector x axis, which leaves this arm's `q7 ≥ 0.5`. With it `q7` sweeps
/// `[0.06, 0.8]` and `J^B_0i` passes near a singularity (see `docs/CONTROL.md`).
pub const EXP421_AMPLITUDE: f64 = 7.0 * PI / 72.0;
/// Frequency of experiment 4.2.1 per iteration (`2π/7000` rad per 2 ms step).
pub const OMEGA_K_421: f64 = 2.0 * PI / 7000.0;
/// Amplitude `a` (m/s) of the thesis's RCM velocity (4.6), `dv_0r = a (sin 3ωt, −sin 3ωt)`:
/// 5 mm/s, which moves the trocar by up to `2a/(3ω)` = 10.6 cm along `x_r` and `z_r`.
pub const S4_RCM_AMPLITUDE_THESIS: f64 = 0.005;
/// Amplitude `a` (m/s) of scenario 4's RCM velocity on the reference arm: −1 mm/s, i.e. (4.6)
/// scaled by −1/5 (trocar excursion up to 2.1 cm along `x_r` and `z_r`).
///
/// With (4.6) as printed ([`S4_RCM_AMPLITUDE_THESIS`]) the joint trajectory is unique while both
/// Jacobians are regular, and it reaches `q7 = 0` (`J^r_0e` singular) at t ≈ 24.6 s: on this arm,
/// from `q0` (`q7 = 0.5`), motion of the trocar along `+x_r` turns link 6 onto the tool axis.
/// There `z_r`, which rotates with the link about the tool axis, turns at
/// `|dv_z| / (l_b |sin q7|)` rad/s, so following the command exactly needs unbounded `q6`, `q8`
/// rates; afterwards the elbow stretches (`q3 → 0`, `J^B_0i` singular) and the link leaves the
/// trocar. With the sign reversed the trocar first moves the link away from the tool axis, and at
/// 1 mm/s the run stays regular (`|q7| ≥ 0.39`, `w_r ≥ 0.033`, `w_i ≥ 0.038`); at 1.5 mm/s the
/// elbow stretches out (`q3 → 0`) at t ≈ 162 s. See `docs/CONTROL.md`.
pub const S4_RCM_AMPLITUDE: f64 = -0.001;

impl Scenario {
    /// All scenarios, in order.
    pub const ALL: [Scenario; 7] = [
        Scenario::S1,
        Scenario::S2,
        Scenario::S3,
        Scenario::S4,
        Scenario::Exp421,
        Scenario::Panda,
        Scenario::PandaLimits,
    ];

    /// `true` for the scenarios on the Panda.
    pub fn is_panda(self) -> bool {
        matches!(self, Scenario::Panda | Scenario::PandaLimits)
    }

    /// Parses `"1"`, `"2"`, `"3"`, `"4"`, `"exp421"`, `"panda-laparoscope"` or
    /// `"panda-laparoscope-limits"`.
    pub fn from_name(name: &str) -> Result<Self, SimulationError> {
        match name {
            "1" => Ok(Scenario::S1),
            "2" => Ok(Scenario::S2),
            "3" => Ok(Scenario::S3),
            "4" => Ok(Scenario::S4),
            "exp421" => Ok(Scenario::Exp421),
            "panda-laparoscope" => Ok(Scenario::Panda),
            "panda-laparoscope-limits" => Ok(Scenario::PandaLimits),
            other => Err(SimulationError::UnknownScenario(other.to_string())),
        }
    }

    /// The name [`Scenario::from_name`] accepts.
    pub fn name(self) -> &'static str {
        match self {
            Scenario::S1 => "1",
            Scenario::S2 => "2",
            Scenario::S3 => "3",
            Scenario::S4 => "4",
            Scenario::Exp421 => "exp421",
            Scenario::Panda => "panda-laparoscope",
            Scenario::PandaLimits => "panda-laparoscope-limits",
        }
    }

    /// A one-line description (used as plot title).
    pub fn title(self) -> &'static str {
        match self {
            Scenario::S1 => "Simulation 1: unidirectional constraint (x_r), trajectory (4.1)",
            Scenario::S2 => "Simulation 2: bidirectional constraint, zy wrist, trajectory (4.2)",
            Scenario::S3 => "Simulation 3: bidirectional zy through singularities (4.3)-(4.4)",
            Scenario::S4 => "Simulation 4: moving RCM (4.5)-(4.6)",
            Scenario::Exp421 => "Experiment 4.2.1 (kinematic simulation)",
            Scenario::Panda => {
                "Panda laparoscope: 1 cm circle of the tip with a +-30 deg roll through a trocar"
            }
            Scenario::PandaLimits => {
                "Panda laparoscope against its limits: withdrawal past l_max, roll past q7's range"
            }
        }
    }

    /// The shipped robot description used.
    pub fn robot(self) -> &'static str {
        match self {
            Scenario::Panda | Scenario::PandaLimits => "panda-laparoscope",
            _ => "dia10_like_zy",
        }
    }

    /// `1` (`H = x_r`) for scenario 1, `2` otherwise (`(x_r, z_r)` on the reference arm,
    /// `(x_r, y_r)` on the Panda).
    pub fn constrained_directions(self) -> usize {
        if self == Scenario::S1 {
            1
        } else {
            2
        }
    }

    /// The thesis's method for the scenario: DLS for simulation 3 and the Panda, the filtered
    /// inverse for the experiment, the pseudo-inverse otherwise; the QP for the Panda's limits.
    pub fn default_method(self) -> Method {
        match self {
            Scenario::PandaLimits => Method::Qp,
            Scenario::S3 | Scenario::Panda => Method::Dls,
            Scenario::Exp421 => Method::Fi,
            _ => Method::Pinv,
        }
    }

    /// Duration (s): one period `2π/ω = 200 s` for the simulations, 5000 steps of 2 ms for the
    /// experiment.
    pub fn duration(self) -> f64 {
        match self {
            Scenario::Exp421 => 10.0,
            Scenario::Panda => PANDA_DURATION,
            Scenario::PandaLimits => PANDA_LIMITS_DURATION,
            _ => 200.0,
        }
    }

    /// The desired pose and velocity at time `t`, from the initial end-effector pose `g0` and
    /// the axis of joint 7 at `q0` (`axis7`, base coordinates).
    /// Offsets of (4.1)–(4.5) are in base coordinates. The rotation (4.4),
    /// `φ = −(π/8) sin ωt`, is applied about `axis7` (about base x, as printed, this arm's `q7`
    /// stays in `[0.48, 0.91]`, far from the `J^r` singularity `q7 = 0` the scenario is meant to
    /// cross). Experiment 4.2.1 moves along the initial end-effector x axis and rotates about
    /// `axis7` (see [`EXP421_AMPLITUDE`]). The Panda scenario ignores `axis7`: see
    /// [`panda_reference`].
    pub fn reference(self, t: f64, dt: f64, g0: &Se3<f64>, axis7: &Vector3<f64>) -> Reference<f64> {
        if self == Scenario::Panda {
            return panda_reference(t, g0);
        }
        if self == Scenario::PandaLimits {
            return panda_limits_reference(t, g0);
        }
        let axis7 = *axis7;
        let w = OMEGA;
        let (s, c) = (f64::sin, f64::cos);
        let (offset, velocity, rotation, angular_velocity) = match self {
            Scenario::S1 => (
                Vector3::new(
                    0.5 * A * s(w * t),
                    2.2 * A * c(2.0 * w * t) - 2.2 * A,
                    A * s(2.0 * w * t),
                ),
                Vector3::new(
                    0.5 * A * w * c(w * t),
                    -4.4 * A * w * s(2.0 * w * t),
                    2.0 * A * w * c(2.0 * w * t),
                ),
                g0.rotation,
                Vector3::zeros(),
            ),
            Scenario::S2 | Scenario::S4 => (
                Vector3::new(
                    0.5 * A * s(w * t),
                    -2.0 * A * s(3.0 * w * t - PI / 2.0) - 2.0 * A,
                    0.5 * A * s(2.0 * w * t),
                ),
                Vector3::new(
                    0.5 * A * w * c(w * t),
                    -6.0 * A * w * c(3.0 * w * t - PI / 2.0),
                    A * w * c(2.0 * w * t),
                ),
                g0.rotation,
                Vector3::zeros(),
            ),
            Scenario::S3 => {
                let amp = PI / 8.0;
                let phi = -amp * s(w * t);
                let phid = -amp * w * c(w * t);
                (
                    Vector3::new(0.0, 0.9 * A * s(w * t - PI / 2.0) + 0.9 * A, 0.0),
                    Vector3::new(0.0, 0.9 * A * w * c(w * t - PI / 2.0), 0.0),
                    axis_angle(axis7, phi) * g0.rotation,
                    axis7 * phid,
                )
            }
            Scenario::Exp421 => {
                let amp = EXP421_AMPLITUDE;
                let wt = OMEGA_K_421 / dt;
                let x0 = g0.rotation.column(0).into_owned();
                let ro = amp * (c(wt * t) - 1.0);
                let rod = -amp * wt * s(wt * t);
                (
                    x0 * 0.03 * s(wt * t),
                    x0 * 0.03 * wt * c(wt * t),
                    axis_angle(axis7, ro) * g0.rotation,
                    axis7 * rod,
                )
            }
            Scenario::Panda | Scenario::PandaLimits => unreachable!("returned above"),
        };
        Reference {
            position: g0.translation + offset,
            rotation,
            velocity,
            angular_velocity,
        }
    }

    /// How the scenario departs from the thesis on the reference arm (one line, for the
    /// command-line output), if it does; `docs/CONTROL.md` gives the reasons and numbers.
    pub fn deviation(self) -> Option<&'static str> {
        match self {
            Scenario::S3 => Some(
                "the rotation (4.4) is applied about the joint-7 axis at q0 \
                 (about base x this arm's q7 stays in [0.48, 0.91])",
            ),
            Scenario::S4 => Some(
                "dv_0r = -1 (sin 3wt, -sin 3wt) mm/s, (4.6) scaled by -1/5: as printed \
                 (+5 mm/s) the trocar turns link 6 onto the tool axis (q7 = 0 at t = 24.6 s, \
                 unbounded roll rates), then out of the arm's reach",
            ),
            Scenario::Exp421 => Some(
                "rotation (7pi/72)(cos wk - 1) about the joint-7 axis at q0 \
                 (the thesis's (pi/18)(cos wk - 1) about x_e leaves q7 >= 0.5)",
            ),
            Scenario::S1 | Scenario::S2 | Scenario::Panda | Scenario::PandaLimits => None,
        }
    }
}

/// The Panda scenario's desired tip pose at `t` from the start pose `g0` of the tip frame (the
/// shaft along its `z`, the trocar [`PANDA_TIP_DEPTH`] behind the tip).
///
/// - Position: `p0 + ρ s(t) (x0 cos ωt + y0 sin ωt)` with `ρ` = [`PANDA_CIRCLE_RADIUS`],
///   `ω = 2π/20` rad/s, `x0`, `y0` the start tip frame's axes, and `s` the quintic smooth step
///   `10τ³ − 15τ⁴ + 6τ⁵`, `τ = t /` [`PANDA_RAMP`] clamped to `[0, 1]`: the reference starts at
///   the tip, at rest, and spirals out onto the circle in the first [`PANDA_RAMP`] seconds
///   (a step onto the circle would ask the arm for a 1 cm jump at `t = 0`).
/// - Orientation: the one the trocar allows there, rolled: the shaft through the trocar and the
///   desired tip (`z_d ∥ p_d − p_trocar`, the smallest rotation from `z0`), times a roll
///   `φ = (π/6) s(t) sin ωt` about the shaft. So the whole reference is feasible and `eo_norm`
///   stays with the position error; the task commands only the roll of it (`rz`).
/// - Velocities: `ṗ_d` exactly; `ω_d` from central differences of the desired rotation
///   (`h = 1e-6` s).
pub fn panda_reference(t: f64, g0: &Se3<f64>) -> Reference<f64> {
    let w = 2.0 * PI / PANDA_DURATION;
    let x0 = g0.rotation.column(0).into_owned();
    let y0 = g0.rotation.column(1).into_owned();
    let z0 = g0.rotation.column(2).into_owned();
    let trocar = g0.translation - z0 * PANDA_TIP_DEPTH;
    let position = |t: f64| {
        g0.translation
            + (x0 * (w * t).cos() + y0 * (w * t).sin()) * (PANDA_CIRCLE_RADIUS * smooth_step(t).0)
    };
    let rotation = |t: f64| {
        let z = (position(t) - trocar).normalize();
        // The smallest rotation taking z0 to z (Rodrigues about z0 × z); computed here because
        // nalgebra's `rotation_between` returns NaN when the two are within ~1e-8 rad.
        let axis = z0.cross(&z);
        let sin = axis.norm();
        let align = if sin > 0.0 {
            axis_angle(axis / sin, sin.atan2(z0.dot(&z)))
        } else {
            Matrix3::identity()
        };
        let roll = PANDA_ROLL_AMPLITUDE * smooth_step(t).0 * (w * t).sin();
        align * g0.rotation * Rotation3::from_axis_angle(&Vector3::z_axis(), roll).into_inner()
    };
    let h = 1e-6;
    let r = rotation(t);
    let rdot = (rotation(t + h) - rotation(t - h)) / (2.0 * h);
    let omega = rdot * r.transpose();
    Reference {
        position: position(t),
        rotation: r,
        velocity: {
            let (s, ds) = smooth_step(t);
            let (sin, cos) = (w * t).sin_cos();
            ((y0 * cos - x0 * sin) * (s * w) + (x0 * cos + y0 * sin) * ds) * PANDA_CIRCLE_RADIUS
        },
        angular_velocity: Vector3::new(
            0.5 * (omega[(2, 1)] - omega[(1, 2)]),
            0.5 * (omega[(0, 2)] - omega[(2, 0)]),
            0.5 * (omega[(1, 0)] - omega[(0, 1)]),
        ),
    }
}

/// The `panda-laparoscope-limits` reference from the start pose `g0` of the tip frame (shaft
/// along its `z`, trocar [`PANDA_TIP_DEPTH`] behind the tip): the shaft keeps its direction
/// `z0`, the tip moves along it and the shaft rolls about it,
///
/// - depth below the trocar `δ(t) = 0.15 − w (σ(t; 1, 3) − σ(t; 8, 10))` m, `w` =
///   [`PANDA_LIMITS_WITHDRAWAL`]: withdrawn to 0.07 m between 1 s and 3 s (past `l_max`, which
///   stops it at 0.10 m) and pushed back in between 8 s and 10 s;
/// - roll `φ(t) = Φ (σ(t; 4, 5) − σ(t; 6, 8))`, `Φ` = [`PANDA_LIMITS_ROLL`]: up in 1 s (peak
///   rate `1.875 Φ` = 4.9 rad/s, above joint 7's 2.61 rad/s) and back in 2 s;
///
/// with `σ(t; a, b)` the quintic smooth step from 0 at `a` to 1 at `b`. Position
/// `p_t + δ z0`, rotation `Rz(φ)` after `g0`'s, velocities exact (`δ̇ z0`, `φ̇ z0`).
pub fn panda_limits_reference(t: f64, g0: &Se3<f64>) -> Reference<f64> {
    let z0 = g0.rotation.column(2).into_owned();
    let trocar = g0.translation - z0 * PANDA_TIP_DEPTH;
    let sigma = |a: f64, b: f64| smooth_step_between(t, a, b);
    let (w1, dw1) = sigma(1.0, 3.0);
    let (w2, dw2) = sigma(8.0, 10.0);
    let (r1, dr1) = sigma(4.0, 5.0);
    let (r2, dr2) = sigma(6.0, 8.0);
    let depth = PANDA_TIP_DEPTH - PANDA_LIMITS_WITHDRAWAL * (w1 - w2);
    let ddepth = -PANDA_LIMITS_WITHDRAWAL * (dw1 - dw2);
    let roll = PANDA_LIMITS_ROLL * (r1 - r2);
    let droll = PANDA_LIMITS_ROLL * (dr1 - dr2);
    Reference {
        position: trocar + z0 * depth,
        rotation: g0.rotation * Rotation3::from_axis_angle(&Vector3::z_axis(), roll).into_inner(),
        velocity: z0 * ddepth,
        angular_velocity: z0 * droll,
    }
}

/// The quintic smooth step from 0 at `a` to 1 at `b` (`a < b`) and its derivative at `t`.
fn smooth_step_between(t: f64, a: f64, b: f64) -> (f64, f64) {
    let span = b - a;
    let tau = ((t - a) / span).clamp(0.0, 1.0);
    let s = tau * tau * tau * (10.0 + tau * (-15.0 + 6.0 * tau));
    let ds = if t > a && t < b {
        30.0 * tau * tau * (1.0 - tau) * (1.0 - tau) / span
    } else {
        0.0
    };
    (s, ds)
}

/// The Panda scenario's start ramp `s(t)` and its derivative: the quintic smooth step
/// `10τ³ − 15τ⁴ + 6τ⁵` in `τ = t /` [`PANDA_RAMP`], 0 before the start and 1 after the ramp;
/// `s`, `ṡ` and `s̈` are continuous, zero at the start.
fn smooth_step(t: f64) -> (f64, f64) {
    let tau = (t / PANDA_RAMP).clamp(0.0, 1.0);
    let s = tau * tau * tau * (10.0 + tau * (-15.0 + 6.0 * tau));
    let ds = if t > 0.0 && t < PANDA_RAMP {
        30.0 * tau * tau * (1.0 - tau) * (1.0 - tau) / PANDA_RAMP
    } else {
        0.0
    };
    (s, ds)
}

fn axis_angle(axis: Vector3<f64>, a: f64) -> Matrix3<f64> {
    Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), a).into_inner()
}

/// The default joint speed limit of the simulated controller (rad/s): above the peak joint
/// speed of every scenario away from singularities (scenario 3 with DLS peaks at 0.8 rad/s, the
/// Panda at 0.26 rad/s) and below the Franka Panda's own limits (2.175–2.61 rad/s). Through a
/// singularity the task slows down instead of the joints moving so far within one 2 ms step that
/// the link leaves the trocar (see [`ControllerConfig::max_joint_speed`]).
pub const MAX_JOINT_SPEED: f64 = 2.0;

/// What to simulate and how.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScenarioConfig {
    /// The scenario.
    pub scenario: Scenario,
    /// Inverse of the Jacobians.
    pub method: Method,
    /// Close the RCM loop: `dv_0r = dv_cmd + K_r e_r` (beyond the thesis).
    pub drift_correction: bool,
    /// Gain `K_r` (1/s) of the drift correction when on.
    pub kr: f64,
    /// Joint speed limit (rad/s) of the controller ([`ControllerConfig::max_joint_speed`]):
    /// [`MAX_JOINT_SPEED`] by default, `None` for the thesis's controller, which has none.
    pub max_joint_speed: Option<f64>,
    /// Sample time (s).
    pub dt: f64,
    /// Duration (s).
    pub duration: f64,
    /// Position gain `K_p`.
    pub kp: f64,
    /// Orientation gain `K_o`.
    pub ko: f64,
    /// DLS: largest damping `α0` (the thesis's `κ`).
    pub dls_alpha0: f64,
    /// DLS: manipulability threshold `w0` of `J^r_0e`.
    pub dls_w0_r: f64,
    /// DLS: manipulability threshold `w0` of `J^B_0i`.
    pub dls_w0_i: f64,
    /// Filtered inverse gains `Γ_r = Γ_l`.
    pub fi_gamma: f64,
    /// Gain `K` (1/s) of the null-space objective (46) (joint-limit distance) on a redundant
    /// arm (the Panda); unused on the reference arm, which has none.
    pub null_space_gain: f64,
    /// The floor of `κ` of the QP step ([`Method::Qp`], (Q1) of `trocar::control::hard_limits`;
    /// `γ = κ²`): a step's `κ` is the larger of it and the DLS damping of the task Jacobian
    /// (3.44) at its manipulability, so that with no limit active the QP tracks the task as
    /// DLS does. 1e-3 by default: it keeps the Hessian regular on a redundant arm and damps the
    /// task by `κ²` relative to its gains' squared singular values (1e-6 of a unit one).
    pub qp_kappa: f64,
    /// When the QP step measures its own chord and solves again ((Q9) of
    /// `trocar::control::hard_limits`): after a working-set change by default.
    pub qp_chord_check: ChordCheck,
    /// Amplitude `a` (m/s) of scenario 4's RCM velocity `dv_0r = a (sin 3ωt, −sin 3ωt)`:
    /// [`S4_RCM_AMPLITUDE`] by default, [`S4_RCM_AMPLITUDE_THESIS`] for (4.6) as printed.
    /// Unused by the other scenarios.
    pub s4_rcm_amplitude: f64,
}

impl ScenarioConfig {
    /// The thesis's settings for a scenario: gains of Table 4.2 (`K_p = 5`, `K_o = 10`,
    /// `κ = 0.05`) or Table 4.3 for the experiment (`K_p = 270`, `K_o = 1500`, `κ = 0.01`,
    /// `Γ_r = Γ_l = 5`), 2 ms, its default method, drift correction off (`K_r = 20 /s` when on).
    ///
    /// The Panda: the same gains, and variable damping starting below `w0 = 1e-3` for the task
    /// Jacobian `S J^r` (constant there, `w_r` = trocar–tip distance², 0.0225 m² at the start,
    /// so the damping only acts when the tip comes within 3.2 cm of the trocar), `0.01` for
    /// `J^B_0i`; null-space gain 10 /s.
    pub fn new(scenario: Scenario) -> Self {
        let exp = scenario == Scenario::Exp421;
        let panda = scenario.is_panda();
        ScenarioConfig {
            scenario,
            method: scenario.default_method(),
            drift_correction: false,
            kr: 20.0,
            max_joint_speed: if scenario == Scenario::PandaLimits {
                None
            } else {
                Some(MAX_JOINT_SPEED)
            },
            dt: 0.002,
            duration: scenario.duration(),
            kp: if exp { 270.0 } else { 5.0 },
            ko: if exp { 1500.0 } else { 10.0 },
            dls_alpha0: if exp { 0.01 } else { 0.05 },
            dls_w0_r: if panda { 1e-3 } else { 0.1 },
            dls_w0_i: 0.01,
            fi_gamma: 5.0,
            null_space_gain: 10.0,
            qp_kappa: 1e-3,
            qp_chord_check: ChordCheck::AfterChange,
            s4_rcm_amplitude: S4_RCM_AMPLITUDE,
        }
    }

    /// The same with another joint speed limit (`None`: none, as in the thesis).
    pub fn with_max_joint_speed(mut self, limit: Option<f64>) -> Self {
        self.max_joint_speed = limit;
        self
    }

    /// The same with another method.
    pub fn with_method(mut self, method: Method) -> Self {
        self.method = method;
        self
    }

    /// The commanded RCM velocity `dv_0r` on `(x_r, z_r)` (m/s) at time `t`:
    /// `a (sin 3ωt, −sin 3ωt)` with `a` = [`ScenarioConfig::s4_rcm_amplitude`] for scenario 4
    /// ((4.6) has `a` = 5 mm/s), `sin(8 ω k)` cm/s on `x_r` for the experiment, zero otherwise.
    pub fn rcm_velocity(&self, t: f64) -> [f64; 2] {
        match self.scenario {
            Scenario::S4 => {
                let v = self.s4_rcm_amplitude * (3.0 * OMEGA * t).sin();
                [v, -v]
            }
            Scenario::Exp421 => [0.01 * (8.0 * OMEGA_K_421 / self.dt * t).sin(), 0.0],
            _ => [0.0, 0.0],
        }
    }

    /// The same with the drift correction on or off.
    pub fn with_drift_correction(mut self, on: bool) -> Self {
        self.drift_correction = on;
        self
    }

    /// The controller's configuration.
    pub fn controller_config(&self) -> ControllerConfig<f64> {
        let gains = control::Gains {
            kp: self.kp,
            ko: self.ko,
            kr: if self.drift_correction { self.kr } else { 0.0 },
            dls_alpha0: self.dls_alpha0,
            dls_w0_task: self.dls_w0_r,
            dls_w0_jb0i: self.dls_w0_i,
            fi_gamma: self.fi_gamma,
            qp_kappa: self.qp_kappa,
            max_joint_speed: self.max_joint_speed,
        };
        let mut config = gains.config(self.method);
        if let control::Method::Qp(weights) = &mut config.method {
            weights.chord_check = self.qp_chord_check;
        }
        config
    }
}
