//! Constrained kinematic control (3.17)–(3.18), the moving RCM (3.30)–(3.34), and the inverses of
//! the Jacobians near singularities (3.43)–(3.50): pseudo-inverse, damped least squares with
//! variable damping, filtered inverse (the thesis's Table 4.1).
//!
//! One [`Controller::step`] computes joint velocities from
//! - the desired pose and its velocity feed-forward ([`Reference`]),
//! - the current joints `q`,
//! - the RCM state ([`Rcm`]): the trocar point (fixed in space, or moving with a commanded lateral
//!   velocity `dv_0r`), and the gain `K_r` of the drift correction.
//!
//! The kinematics come through the [`ConstrainedKinematics`] trait, so the numeric runtime and
//! generated closed forms can both drive the same controller. The step allocates nothing and
//! builds without `std`.
//!
//! # The step
//! 1. `l_a` places the constraint frame at the trocar: `g_ir(l_a) = (R_ir, o + l_a d)` moves
//!    along the link's [`Shaft`] (the thesis's arm: `R_ir = I`, `o = 0`, `d = y_i`), and `l_a`
//!    is the offset of the point of the shaft nearest to the trocar.
//! 2. Drift correction (beyond the thesis): `e_r = H_v R_0rᵀ (p_trocar − p_0r)`, the lateral
//!    offset of the trocar from the link in `F_r`'s constrained directions, and
//!    `dv_0r = dv_cmd + K_r e_r`. With `K_r = 0` this is the thesis's controller.
//! 3. Cartesian law (2.66)/Table 4.1: `e_p = R_0eᵀ(dp − p)`, `e_q = Q_d ⊗ Q⁻¹ = {η̃, ε̃}`,
//!    `u_o = R_0eᵀ(dω + K_o ε̃)`, `u_p = R_0eᵀ dv + K_p e_p − û_o e_p`. The desired velocities
//!    `dv`, `dω` are given in base coordinates and brought to the end-effector frame; `ε̃` is in
//!    base coordinates (it belongs to `R_Δ = dR Rᵀ`) and is brought to the end-effector frame too,
//!    which makes `ε̃̇ = −½ K_o η̃ ε̃` exactly (the thesis adds the body `dω` to the base `ε̃`; the
//!    two agree at zero error). The `−û_o e_p` term uses the commanded angular velocity `u_o`,
//!    which makes `ė_p = −K_p e_p` exactly.
//! 4. `[v0i; θ̇_jn] = J_inv S (u − J_c dv_0r)` (3.34) with `J_inv` the pseudo-inverse, the damped
//!    inverse or the filtered inverse of the task Jacobian `S J^r_0e`. `S` selects the rows of
//!    the end-effector body twist that the task commands (`S = I`, `P = 6`, for a full 6-D task
//!    as in the thesis; a trocar leaves an instrument on the last link `6 − r` freedoms, so a
//!    laparoscope commands the tip's position and its roll, `P = 4`).
//! 5. `V^B_0i = Λ# v0i + Λ† dv_0r` (3.33), `θ̇_{1..i} = J^B_0i^{inv} V^B_0i` (3.18), with the
//!    pseudo-inverse or the damped inverse of `J^B_0i`. When `J^B_0i` is wide (`i > 6`, e.g. a
//!    7-DOF arm with the constraint on its last link), the spare freedom follows an objective
//!    ([`NullSpaceObjective`], (44)–(46) of Freitas, Leite & Lizarralde 2010):
//!    `θ̇_{1..i} = u0 + J^B_0i^{inv} (V^B_0i − J^B_0i u0)`.
//!
//! With [`Method::Qp`] steps 4–5 are one quadratic program instead ([`hard_limits`]): the
//! task `S u` tracked in least squares, the trocar `Λ J^B_0i θ̇ = dv_0r` as equality rows, the
//! joint position limits (velocity dampers), the joint speed limits and the insertion depth
//! ([`HardLimits`], [`Controller::with_limits`]) as hard inequalities, solved by [`crate::qp`]
//! from the previous step's active set.
//!
//! Every method's rates stay within the rate box of [`rate_box`] ((B1)–(B5)): the speed limits,
//! the ranges over the sample time and, from the previous command that the controller keeps
//! ([`Controller::set_previous_rates`], [`Controller::reset`]), the acceleration, braking and
//! jerk limits, which give way in that order only where they cannot all hold
//! ([`StepOutput::relaxed`]).
//!
//! With the constraint on the last link (`i = n`) there are no joints after it: `J^r_0e =
//! Ad_{g_ei} Λ#` does not depend on `q`, so the arm's closeness to a singularity is that of
//! `J^B_0i` (`w_i` of [`StepOutput`]), and the damping of [`ControllerConfig::jb0i_damping`] is
//! the one that matters.

pub mod hard_limits;
mod inverse;
mod quaternion;
mod redundancy;
pub mod scene;
mod shaft;

pub use crate::linalg::determinant;
pub use crate::manipulability::manipulability;
pub use hard_limits::{
    braking_speed, rate_box, ChordCheck, Damper, HardLimits, LimitsError, PreviousCommand,
    QpReport, QpWeights, RateBox, RateRelaxation,
};
pub use inverse::{Damping, FilteredInverse, PreparedJacobian};
pub use quaternion::{orientation_error, Quaternion};
pub use redundancy::{
    lie_bracket, manipulability_gradient, resolve_with_null_space, NullSpaceObjective,
};
pub use shaft::Shaft;

use crate::constraint::Constraint;
use crate::kinematics::Chain;
use crate::linalg::{damped_solve, pseudo_inverse, Cholesky, SquareDim};
use crate::se3::Se3;
use nalgebra::{Const, Matrix3, RealField, SMatrix, SVector, Vector3, Vector6};

/// Everything the controller needs from the kinematics at `(q, l_a)`.
///
/// Sizes: `I` joints up to the constrained link, `R` constrained directions, `K = 6 − R` columns
/// of `Λ#`, `M = K + n − I` columns of `J^r_0e`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConstrainedState<
    T: RealField + Copy,
    const I: usize,
    const R: usize,
    const K: usize,
    const M: usize,
> {
    /// Pose of the end effector `g_0e`.
    pub g_0e: Se3<T>,
    /// Pose of the constrained link's frame `g_0i`.
    pub g_0i: Se3<T>,
    /// The constrained Jacobian `J^r_0e = [Ad_{g_ei} Λ# | J^B_0e2]` (3.15).
    pub jr: SMatrix<T, 6, M>,
    /// The partial body Jacobian `J^B_0i` (3.13).
    pub jb0i: SMatrix<T, 6, I>,
    /// `J_c = Ad_{g_ei} Λ†` (3.33).
    pub jc: SMatrix<T, 6, R>,
    /// The null-space basis `Λ#` (3.23)/(3.27).
    pub lambda_sharp: SMatrix<T, 6, K>,
    /// `Λ† = Λᵀ (Λ Λᵀ)⁻¹`.
    pub lambda_pinv: SMatrix<T, 6, R>,
}

/// Constrained kinematics of an `N`-joint arm with the RCM on link `I`, `R` constrained
/// directions and `P` task rows (see [`ConstrainedState`] for `K`, `M`).
///
/// The constraint frame moves along the link's [`Shaft`] with the trocar offset `l_a`, and the
/// rows of `H` select directions of `F_r`; the task selection `S` selects rows of the
/// end-effector body twist.
pub trait ConstrainedKinematics<
    T: RealField + Copy,
    const N: usize,
    const I: usize,
    const R: usize,
    const K: usize,
    const M: usize,
    const P: usize = 6,
>
{
    /// The pose `g_0i(q)` of the constrained link's frame.
    fn g_0i(&self, q: &SVector<T, N>) -> Se3<T>;
    /// The selection `H ∈ R^{R×6}` of the constrained directions (3.1).
    fn h(&self) -> SMatrix<T, R, 6>;
    /// The line of the constrained link along which `l_a` moves the constraint frame.
    fn shaft(&self) -> Shaft<T>;
    /// The task selection `S ∈ R^{P×6}`: rows of the end-effector body twist that the task
    /// commands (the identity for a full 6-D task).
    fn task_selection(&self) -> SMatrix<T, P, 6>;
    /// Poses and Jacobians at joints `q` with the constraint at `l_a`.
    fn evaluate(
        &self,
        q: &SVector<T, N>,
        l_a: T,
    ) -> Result<ConstrainedState<T, I, R, K, M>, ControlError>;

    /// `J x = b` for the task Jacobian `J = S J^r_0e` when it is square (`P = M`), by a solve
    /// specialised for this robot (generated modules emit a straight-line elimination for their
    /// size): `Some((x, det J))`, `x` meaningful only when `det J` is finite and not 0. `None`
    /// (the default) lets the controller factor `J` itself.
    fn solve_task(&self, j: &SMatrix<T, P, M>, b: &SVector<T, P>) -> Option<(SVector<T, M>, T)> {
        let _ = (j, b);
        None
    }

    /// `J x = b` for `J = J^B_0i` by a solve specialised for this robot, as
    /// [`Self::solve_task`]: when it is square (`I = 6`), `Some((x, det J))`; with one redundant
    /// joint (`I = 7`), the minimum-norm solution `x = J⁺ b` and `w = sqrt(det(J Jᵀ))` (3.36)
    /// in place of the determinant. `x` is meaningful only when the second value is finite and
    /// not 0; otherwise (and by default, `None`) the controller factors `J` itself.
    fn solve_jb0i(&self, j: &SMatrix<T, 6, I>, b: &SVector<T, 6>) -> Option<(SVector<T, I>, T)> {
        let _ = (j, b);
        None
    }

    /// The pose `g_0e(q)` of the end effector (2.21). The default takes it from
    /// [`Self::evaluate`]; an implementation with the forward kinematics alone overrides it.
    fn g_0e(&self, q: &SVector<T, N>) -> Result<Se3<T>, ControlError> {
        self.evaluate(q, T::zero()).map(|s| s.g_0e)
    }

    /// `l_a` of the point of the shaft nearest to the trocar at joints `q`
    /// ([`Shaft::offset`]) and [`Self::evaluate`] there: what a control step asks of the
    /// kinematics. The default calls [`Self::g_0i`], then [`Self::evaluate`]; an implementation
    /// that can share work between the two (one set of joint sines and cosines) overrides it.
    fn evaluate_at_trocar(
        &self,
        q: &SVector<T, N>,
        trocar: &Vector3<T>,
    ) -> Result<(T, ConstrainedState<T, I, R, K, M>), ControlError> {
        let l_a = self.shaft().offset(&self.g_0i(q), trocar);
        Ok((l_a, self.evaluate(q, l_a)?))
    }
}

/// `l_a = (p_trocar − p_0i) · y_i`: the position of the trocar along a link that runs along
/// `y_i` (the thesis's convention, [`Shaft::along_y`]); [`Shaft::offset`] in general.
pub fn trocar_offset<T: RealField + Copy>(g_0i: &Se3<T>, trocar: &Vector3<T>) -> T {
    Shaft::along_y().offset(g_0i, trocar)
}

/// The numeric runtime behind [`ConstrainedKinematics`]: a [`Chain`], a [`Constraint`] whose
/// frame is moved along `shaft` to `l_a` at every evaluation, and the task selection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChainKinematics<T: RealField + Copy, const N: usize, const R: usize, const P: usize = 6>
{
    /// The serial chain.
    pub chain: Chain<T, N>,
    /// The constraint (its frame is reset to `shaft.frame(l_a)` at each evaluation).
    pub constraint: Constraint<T, R>,
    /// The line along which the constraint frame moves.
    pub shaft: Shaft<T>,
    /// The task selection `S`.
    pub task: SMatrix<T, P, 6>,
}

impl<T: RealField + Copy, const N: usize, const R: usize> ChainKinematics<T, N, R, 6> {
    /// The thesis's setting: the constraint frame moves along `y_i` ([`Shaft::along_y`]) and
    /// the task is the whole end-effector twist (`S = I`).
    pub fn thesis(chain: Chain<T, N>, constraint: Constraint<T, R>) -> Self {
        ChainKinematics {
            chain,
            constraint,
            shaft: Shaft::along_y(),
            task: SMatrix::identity(),
        }
    }
}

impl<
        T: RealField + Copy,
        const N: usize,
        const I: usize,
        const R: usize,
        const K: usize,
        const M: usize,
        const P: usize,
    > ConstrainedKinematics<T, N, I, R, K, M, P> for ChainKinematics<T, N, R, P>
where
    Const<R>: SquareDim,
{
    fn g_0i(&self, q: &SVector<T, N>) -> Se3<T> {
        self.chain.link_frame(I, q)
    }

    fn g_0e(&self, q: &SVector<T, N>) -> Result<Se3<T>, ControlError> {
        Ok(self.chain.forward_kinematics(q))
    }

    fn h(&self) -> SMatrix<T, R, 6> {
        *self.constraint.h()
    }

    fn shaft(&self) -> Shaft<T> {
        self.shaft
    }

    fn task_selection(&self) -> SMatrix<T, P, 6> {
        self.task
    }

    fn evaluate(
        &self,
        q: &SVector<T, N>,
        l_a: T,
    ) -> Result<ConstrainedState<T, I, R, K, M>, ControlError> {
        assert_eq!(self.constraint.link(), I, "the constraint is on link I");
        let mut c = self.constraint;
        c.set_frame(self.shaft.frame(l_a))
            .map_err(|_| ControlError::Kinematics)?;
        let (jr, jc) = c.constrained_jacobians::<N, M>(&self.chain, q);
        let (g_0i, jb0i) = self.chain.frame_and_partial_body_jacobian::<I>(q);
        Ok(ConstrainedState {
            g_0e: self.chain.forward_kinematics(q),
            g_0i,
            jr,
            jb0i,
            jc,
            lambda_sharp: c.lambda_null_space::<K>(),
            lambda_pinv: *c.lambda_pinv(),
        })
    }
}

/// The method of a control step with its parameters: how the task Jacobian `S J^r_0e`
/// (`J^r_0e` for a 6-D task) is inverted (Table 4.1), or the quadratic program that replaces the
/// inverse.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method<T> {
    /// The pseudo-inverse `(J^r)† = J^rᵀ (J^r J^rᵀ)⁻¹` (the inverse when square).
    Pinv,
    /// Damped least squares (3.46) on `J^r`.
    Dls(Damping<T>),
    /// The filtered inverse (3.47)–(3.50) with gains `Γ_r`, `Γ_l`.
    Fi {
        /// Gain of the right-inverse error `S_r`.
        gamma_r: T,
        /// Gain of the left-inverse error `S_l`.
        gamma_l: T,
    },
    /// No inverse: the step is the quadratic program (Q1)–(Q7) of [`hard_limits`] — the task
    /// `S u` in least squares with weights `κ`, `γ`, the trocar as equality rows, the
    /// [`HardLimits`] of [`Controller::with_limits`] (and
    /// [`ControllerConfig::max_joint_speed`]) as hard inequalities. `J^B_0i` is not inverted:
    /// [`ControllerConfig::jb0i_damping`] is unused.
    Qp(QpWeights<T>),
}

/// The controller's method by name, without its parameters: the [`Method`] that [`Gains::config`]
/// makes of it with the damping, the filtered inverse's gains or the QP's weights of a
/// [`Gains`] (the simulations, the command line, Python and the C ABI name methods so).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MethodKind {
    /// No inverse: one quadratic program per step with the trocar, the joint limits, the joint
    /// speed limits and the insertion depth as hard constraints ([`Method::Qp`]).
    Qp,
    /// Pseudo-inverses of `J^r_0e` and `J^B_0i`.
    Pinv,
    /// Damped least squares with variable damping (3.44) on `J^r_0e` and `J^B_0i`.
    Dls,
    /// Filtered inverse of `J^r_0e` (3.47)–(3.50); damped least squares (3.44) on `J^B_0i`.
    Fi,
}

impl MethodKind {
    /// Every method, in the order of the comparison figure.
    pub const ALL: [MethodKind; 4] = [
        MethodKind::Pinv,
        MethodKind::Dls,
        MethodKind::Fi,
        MethodKind::Qp,
    ];

    /// `"pinv"`, `"dls"`, `"fi"` or `"qp"`.
    pub fn name(self) -> &'static str {
        match self {
            MethodKind::Qp => "qp",
            MethodKind::Pinv => "pinv",
            MethodKind::Dls => "dls",
            MethodKind::Fi => "fi",
        }
    }

    /// What the method does, in one line (the command line's help).
    pub fn summary(self) -> &'static str {
        match self {
            MethodKind::Qp => {
                "one quadratic program per step: the trocar, the joint limits, the joint speed \
                 limits and the insertion depth held as hard constraints"
            }
            MethodKind::Pinv => "Moore–Penrose pseudo-inverse",
            MethodKind::Dls => "damped least squares with variable damping (3.44)–(3.46)",
            MethodKind::Fi => "filtered inverse (3.47)–(3.50)",
        }
    }

    /// Parses `"pinv"`, `"dls"`, `"fi"` or `"qp"`.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "qp" => Some(MethodKind::Qp),
            "pinv" => Some(MethodKind::Pinv),
            "dls" => Some(MethodKind::Dls),
            "fi" => Some(MethodKind::Fi),
            _ => None,
        }
    }
}

/// The parameters of every method, flat (as a scenario, a command line or a C caller gives
/// them): [`Gains::config`] is the one mapping of a [`MethodKind`] and its gains onto a
/// [`ControllerConfig`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gains<T> {
    /// Position gain `K_p` (1/s).
    pub kp: T,
    /// Orientation gain `K_o` (1/s).
    pub ko: T,
    /// Drift correction gain `K_r` (1/s); 0 for the thesis's controller.
    pub kr: T,
    /// Variable damping (3.44): the largest damping `α0`, on the task Jacobian and on `J^B_0i`.
    pub dls_alpha0: T,
    /// Variable damping: the manipulability threshold `w0` of the task Jacobian.
    pub dls_w0_task: T,
    /// Variable damping: the manipulability threshold `w0` of `J^B_0i`.
    pub dls_w0_jb0i: T,
    /// The filtered inverse's gains `Γ_r = Γ_l` (3.47)–(3.50).
    pub fi_gamma: T,
    /// The QP's weight `κ` of the rates' norm (`γ = κ²`); the task's damping (3.44) as its floor.
    pub qp_kappa: T,
    /// The joint speed limit (rad/s), `None` for none.
    pub max_joint_speed: Option<T>,
}

impl<T: RealField + Copy> Gains<T> {
    /// The controller's configuration for `method`: DLS with variable damping on the task
    /// Jacobian and on `J^B_0i`; the pseudo-inverses; the filtered inverse with DLS on
    /// `J^B_0i`; the QP with `κ` ([`QpWeights::with_kappa`]) and the task's damping.
    pub fn config(&self, method: MethodKind) -> ControllerConfig<T> {
        let task = Damping::Variable {
            alpha0: self.dls_alpha0,
            w0: self.dls_w0_task,
        };
        let jb0i = Damping::Variable {
            alpha0: self.dls_alpha0,
            w0: self.dls_w0_jb0i,
        };
        let (method, jb0i_damping) = match method {
            MethodKind::Pinv => (Method::Pinv, None),
            MethodKind::Qp => (
                Method::Qp(QpWeights {
                    damping: Some(task),
                    ..QpWeights::with_kappa(self.qp_kappa)
                }),
                None,
            ),
            MethodKind::Dls => (Method::Dls(task), Some(jb0i)),
            MethodKind::Fi => (
                Method::Fi {
                    gamma_r: self.fi_gamma,
                    gamma_l: self.fi_gamma,
                },
                Some(jb0i),
            ),
        };
        ControllerConfig {
            kp: self.kp,
            ko: self.ko,
            method,
            jb0i_damping,
            kr: self.kr,
            max_joint_speed: self.max_joint_speed,
        }
    }
}

/// Gains and inverses of the controller.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControllerConfig<T> {
    /// Position gain `K_p` (1/s).
    pub kp: T,
    /// Orientation gain `K_o` (1/s).
    pub ko: T,
    /// The method: the inverse of the task Jacobian `S J^r_0e`, or the QP.
    pub method: Method<T>,
    /// Damping of the inverse of `J^B_0i`; `None` for the pseudo-inverse.
    pub jb0i_damping: Option<Damping<T>>,
    /// Gain `K_r` (1/s) of the RCM drift correction; `0` reproduces the thesis.
    pub kr: T,
    /// Joint speed limit (rad/s, m/s for a prismatic joint), `None` for none; with
    /// [`HardLimits::speed`] the smaller of the two holds. For the inverses other than the QP,
    /// where `θ̇` leaves the limits ([`rate_box`]: this speed, and each joint's range over the
    /// sample time), the task's share of `θ̇` is scaled down and the constraint's is kept:
    /// `θ̇ = θ̇_c + α (θ̇ − θ̇_c)` with `θ̇_c = A† dv_0r` (`A = Λ J^B_0i`) and the largest
    /// `α ∈ [0, 1]` within the limits, so `Λ J^B_0i θ̇ = dv_0r` still holds and the link keeps
    /// to the trocar while the end effector slows down; where `θ̇_c` alone leaves them, the rates
    /// nearest to `θ̇` that meet the trocar rows within them, and where none do the step reports
    /// [`StepStatus::TrocarYielded`]. With acceleration or jerk limits
    /// ([`HardLimits::acceleration`], [`HardLimits::jerk`]) these are the limits of the joints'
    /// place (speed, range, braking), and the rates then move from the previous command `θ̇⁻`
    /// toward them, `θ̇⁻ + β (θ̇* − θ̇⁻)` with the largest `β ∈ [0, 1]` within the whole box of
    /// [`rate_box`]: every joint changes its rate in the same proportion, so the end effector
    /// keeps its path and lags behind, and where the task stops the joints slow down together.
    /// Over a sample time
    /// `dt` the joints move along a straight line, which leaves the link off the trocar by a
    /// second-order term (≈ ½ l (|θ̇| dt)² per step for a lever `l`); bounding `|θ̇|` bounds that
    /// drift.
    pub max_joint_speed: Option<T>,
}

/// The desired end-effector motion at one instant, in base coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reference<T: RealField + Copy> {
    /// Desired position `dp_0e`.
    pub position: Vector3<T>,
    /// Desired orientation `dR_0e`.
    pub rotation: Matrix3<T>,
    /// Feed-forward linear velocity `d ṗ_0e`.
    pub velocity: Vector3<T>,
    /// Feed-forward angular velocity `dω` (spatial, `dṘ dRᵀ = dω̂`).
    pub angular_velocity: Vector3<T>,
}

/// The RCM at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rcm<T: RealField + Copy, const R: usize> {
    /// The trocar point in base coordinates.
    pub trocar: Vector3<T>,
    /// Commanded lateral velocity of the link at the trocar, `H V^B_0r = dv_0r` (3.30); zero
    /// for a fixed trocar.
    pub dv: SVector<T, R>,
}

/// What one step computed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepOutput<T: RealField + Copy, const N: usize, const R: usize> {
    /// Joint velocities `θ̇`.
    pub qd: SVector<T, N>,
    /// `l_a` at this step.
    pub l_a: T,
    /// Position error `e_p = R_0eᵀ(dp − p)` (end-effector frame).
    pub ep: Vector3<T>,
    /// Orientation error `e_q = {η̃, ε̃}`.
    pub eq: Quaternion<T>,
    /// The Cartesian control `u = (u_p, u_o)` (2.66).
    pub u: Vector6<T>,
    /// Lateral offset `e_r` of the trocar from the link in the constrained directions of `F_r`.
    pub lateral_error: SVector<T, R>,
    /// The RCM velocity used, `dv_0r = dv_cmd + K_r e_r`.
    pub dv_0r: SVector<T, R>,
    /// Manipulability of the task Jacobian `S J^r_0e` (of `J^r_0e` for a 6-D task); constant
    /// when the constraint is on the last link.
    pub w_r: T,
    /// Manipulability of `J^B_0i`.
    pub w_i: T,
    /// Damping applied to `J^r_0e` (0 unless DLS).
    pub kappa_r: T,
    /// Damping applied to `J^B_0i`.
    pub kappa_i: T,
    /// The QP's outcome with [`Method::Qp`] (`None` for the other inverses).
    pub qp: Option<QpReport>,
    /// Whether the step held every constraint, or which gave way ([`StepStatus`]).
    pub status: StepStatus,
    /// Which bound of the rate box (B1)–(B4) gave way at some joint ([`rate_box`],
    /// [`RateRelaxation`]): [`RateRelaxation::Nothing`] when the rates keep every speed, range,
    /// acceleration, braking and jerk bound.
    pub relaxed: RateRelaxation,
}

/// Whether a step held the trocar and every limit. The joint limits never give way: the rates
/// of every step keep each joint within its speed limit and, over the sample time, within its
/// range ([`HardLimits`]); what gives way when they cannot all hold is the trocar.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StepStatus {
    /// The trocar rows `Λ J^B_0i θ̇ = dv_0r` are met and every limit is kept.
    Held,
    /// No joint rates within the joint limits meet the trocar rows (the drift correction or the
    /// commanded motion of the trocar asks for more than the joints at their limits allow, or
    /// `Λ J^B_0i` is rank-deficient): the rates are the best within the limits — the trocar rows
    /// in least squares (QP), the constraint's own rates scaled into the limits (the other
    /// inverses) — and the link leaves the trocar.
    TrocarYielded,
    /// A joint is beyond its range at `q` (it can only move back); everything else held.
    JointOutside,
    /// The trocar's offset `l_a` is outside the insertion-depth bounds of [`HardLimits`] (the
    /// QP keeps it from going further); everything else held.
    DepthOutside,
}

impl StepStatus {
    /// `true` for [`StepStatus::Held`].
    pub fn held(&self) -> bool {
        *self == StepStatus::Held
    }
}

impl core::fmt::Display for StepStatus {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            StepStatus::Held => "every constraint held",
            StepStatus::TrocarYielded => {
                "the trocar could not be held within the joint limits: the rates are the best \
                 within them and the link leaves the trocar"
            }
            StepStatus::JointOutside => "a joint is beyond its range",
            StepStatus::DepthOutside => {
                "the instrument's insertion (l_a) is outside its depth bounds"
            }
        })
    }
}

/// The bound on `K dt` of a proportional gain `K` at the sample time `dt`: the discrete error of
/// the position loop and of the drift correction, `e ← (1 − K dt) e`, converges only for
/// `0 ≤ K dt < 2` (without overshoot up to 1). The orientation loop's quaternion error moves at
/// half the rate, `ε̇ = −½ K_o η ε`, so its bound is `K_o dt < 4`. [`ControllerConfig::check`]
/// refuses gains at or beyond these bounds ([`gain_bound`]).
pub const MAX_GAIN_TIMES_DT: f64 = 2.0;

/// The bound of `K dt` for the gain named `"kp"`, `"kr"` ([`MAX_GAIN_TIMES_DT`]) or `"ko"`
/// (twice that): a gain is accepted when `K dt` is below it.
pub fn gain_bound(name: &str) -> f64 {
    if name == "ko" {
        2.0 * MAX_GAIN_TIMES_DT
    } else {
        MAX_GAIN_TIMES_DT
    }
}

/// A gain or setting of [`ControllerConfig`] that [`ControllerConfig::check`] refuses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConfigError {
    /// The sample time is not finite and positive.
    SampleTime,
    /// A gain (`"kp"`, `"ko"`, `"kr"`, a damping or filter gain) is negative or not finite.
    Gain(&'static str),
    /// A proportional gain times the sample time exceeds [`MAX_GAIN_TIMES_DT`].
    GainTimesDt(&'static str),
    /// [`ControllerConfig::max_joint_speed`] is not a finite positive speed.
    MaxJointSpeed,
}

impl core::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ConfigError::SampleTime => f.write_str("the sample time dt must be finite and > 0"),
            ConfigError::Gain(name) => write!(f, "{name} must be a finite number >= 0"),
            ConfigError::GainTimesDt(name) => write!(
                f,
                "{name} * dt must be below {} (the discrete loop diverges beyond)",
                gain_bound(name)
            ),
            ConfigError::MaxJointSpeed => {
                f.write_str("max_joint_speed must be a finite speed > 0 (or none)")
            }
        }
    }
}

impl<T: RealField + Copy> ControllerConfig<T> {
    /// Checks the gains against the sample time `dt`: `dt` finite and positive; every gain
    /// finite and `≥ 0`; `K_p dt < 2`, `K_r dt < 2`, `K_o dt < 4` ([`MAX_GAIN_TIMES_DT`]); the joint
    /// speed limit, if any, finite and positive. [`Controller::step`] refuses a step whose
    /// configuration fails it.
    pub fn check(&self, dt: T) -> Result<(), ConfigError> {
        if !(dt.is_finite() && dt > T::zero()) {
            return Err(ConfigError::SampleTime);
        }
        let finite = |v: T| v.is_finite() && v >= T::zero();
        for (name, k) in [("kp", self.kp), ("ko", self.ko), ("kr", self.kr)] {
            if !finite(k) {
                return Err(ConfigError::Gain(name));
            }
            if k * dt >= nalgebra::convert(gain_bound(name)) {
                return Err(ConfigError::GainTimesDt(name));
            }
        }
        let damping = |d: &Damping<T>, name: &'static str| match *d {
            Damping::Constant(k) if !finite(k) => Err(ConfigError::Gain(name)),
            Damping::Variable { alpha0, w0 } if !(finite(alpha0) && finite(w0)) => {
                Err(ConfigError::Gain(name))
            }
            _ => Ok(()),
        };
        match self.method {
            Method::Dls(d) => damping(&d, "the damping of J^r")?,
            Method::Fi { gamma_r, gamma_l } => {
                if !(finite(gamma_r) && finite(gamma_l)) {
                    return Err(ConfigError::Gain("the filtered inverse's gain"));
                }
            }
            Method::Qp(w) => {
                if !(finite(w.kappa) && finite(w.gamma)) {
                    return Err(ConfigError::Gain("the QP weight kappa"));
                }
                if let Some(d) = &w.damping {
                    damping(d, "the QP's damping rule")?;
                }
                if w.chord_feedback.is_some_and(|f| !finite(f)) || w.max_iterations == 0 {
                    return Err(ConfigError::Gain(
                        "the QP's chord feedback or iteration limit",
                    ));
                }
            }
            Method::Pinv => {}
        }
        if let Some(d) = &self.jb0i_damping {
            damping(d, "the damping of J^B_0i")?;
        }
        if let Some(s) = self.max_joint_speed {
            if !(s.is_finite() && s > T::zero()) {
                return Err(ConfigError::MaxJointSpeed);
            }
        }
        Ok(())
    }
}

/// Why a step failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ControlError {
    /// `J^r_0e` could not be pseudo-inverted (singular with no damping).
    SingularJr,
    /// `J^B_0i` could not be pseudo-inverted (singular with no damping).
    SingularJb0i,
    /// A NaN or infinity appeared.
    NonFinite,
    /// The kinematics could not be evaluated (e.g. `l_a = 0`: the trocar at `F_i`).
    Kinematics,
    /// The configuration or the sample time was refused ([`ControllerConfig::check`]).
    Config(ConfigError),
}

impl core::fmt::Display for ControlError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            ControlError::SingularJr => "the constrained Jacobian J^r_0e is singular",
            ControlError::SingularJb0i => "the partial Jacobian J^B_0i is singular",
            ControlError::NonFinite => "a non-finite value appeared in the control step",
            ControlError::Kinematics => {
                "the constrained kinematics could not be evaluated (trocar at F_i?)"
            }
            ControlError::Config(e) => return write!(f, "{e}"),
        })
    }
}

#[cfg(feature = "std")]
impl std::error::Error for ControlError {}

/// The constrained kinematic controller (Table 4.1 with the moving RCM and drift correction).
///
/// Holds the filtered-inverse state `Θ` (unused by the other inverses) and the objective of the
/// spare freedom of `J^B_0i`. Generic over the sizes of [`ConstrainedKinematics`];
/// `K = 6 − R`, `M = K + N − I` and `P ≤ M` are checked at compile time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Controller<
    T: RealField + Copy,
    const N: usize,
    const I: usize,
    const R: usize,
    const K: usize,
    const M: usize,
    const P: usize = 6,
> {
    /// Gains and inverses.
    pub config: ControllerConfig<T>,
    /// What the spare freedom of the joints before the constraint does when `J^B_0i` is wide
    /// (`I > 6`); [`NullSpaceObjective::None`] by default.
    pub objective: NullSpaceObjective<T, N>,
    /// The hard limits ([`HardLimits::none`] by default): the joint ranges and speeds bound
    /// every inverse's rates ([`rate_box`]); the dampers and the insertion depth are the QP's
    /// ([`Method::Qp`]).
    pub limits: HardLimits<T, N>,
    fi: FilteredInverse<T, P, M>,
    fi_started: bool,
    qp_active: crate::qp::ActiveSet<N, 1>,
    qp_previous: Option<hard_limits::Previous<T, N, I, R>>,
    previous: PreviousCommand<T, N>,
    last_box: Option<RateBox<T, N>>,
}

/// `A = Λ J^B_0i`, the constrained directions of the link's twist as functions of `θ̇_{1..i}`,
/// with `Λ = (Λ†ᵀ Λ†)⁻¹ Λ†ᵀ` recovered from `Λ†` (its left inverse). `None` if `Λ†` has not
/// full column rank.
fn constrained_rows<T: RealField + Copy, const I: usize, const R: usize>(
    j: &SMatrix<T, 6, I>,
    lambda_pinv: &SMatrix<T, 6, R>,
) -> Option<SMatrix<T, R, I>> {
    let lambda: SMatrix<T, R, 6> =
        Cholesky::new(&lambda_pinv.tr_mul(lambda_pinv))?.solve(&lambda_pinv.transpose());
    Some(lambda * j)
}

/// `θ̇_c + α (θ̇ − θ̇_c)` within the joint limits' box `[lb, ub]` (the speed, range and braking
/// bounds (B1), (B3) of [`hard_limits::rate_box`], which hold `0`): `θ̇_c = A† dv_0r` on the
/// joints up to the constrained link (zero after it), `A = Λ J^B_0i`, and the largest
/// `α ∈ [0, 1]` that keeps every entry within the box, so `Λ J^B_0i θ̇ = dv_0r` still holds and
/// the link keeps to the trocar while the end effector slows down. When `θ̇_c` alone leaves the
/// box, the rates nearest to `θ̇` that meet the rows within it (a small QP); where none do, the
/// rates within the limits nearest to the rows, and `true` (the trocar yields). `None` if
/// `A Aᵀ` is singular.
fn within_box<T: RealField + Copy, const N: usize, const I: usize, const R: usize>(
    qd: &SVector<T, N>,
    a: &SMatrix<T, R, I>,
    dv_0r: &SVector<T, R>,
    lb: &SVector<T, N>,
    ub: &SVector<T, N>,
) -> Option<(SVector<T, N>, bool)> {
    let c_i: SVector<T, I> = a.tr_mul(&Cholesky::new(&(a * a.transpose()))?.solve(dv_0r));
    let c = SVector::<T, N>::from_fn(|k, _| if k < I { c_i[k] } else { T::zero() });
    if !c.iter().all(|v| v.is_finite()) {
        return None;
    }
    if within(&c, lb, ub) {
        let alpha = largest_step_within(&c, &(qd - c), lb, ub);
        return Some((c + (qd - c) * alpha, false));
    }
    // `θ̇_c` leaves the box, but other rates `θ̇_c + null(A)` may meet the rows within it: the
    // rates nearest to `θ̇` that do; where none do, the limits hold and the trocar gives way.
    Some(nearest_meeting_rows(qd, a, dv_0r, lb, ub).unwrap_or_else(|| (clipped(&c, lb, ub), true)))
}

/// The rates within `[lb, ub]` nearest to `r` that meet the trocar rows `A x = dv_0r`,
/// `argmin ½ ‖x − r‖²` (a small QP), and `false`; where no rates within the box meet them, the
/// rates within it nearest to the rows ([`hard_limits::trocar_within_limits`]) and `true` (the
/// trocar yields). `None` when the solver gives no finite rates.
fn nearest_meeting_rows<T: RealField + Copy, const N: usize, const I: usize, const R: usize>(
    r: &SVector<T, N>,
    a: &SMatrix<T, R, I>,
    dv_0r: &SVector<T, R>,
    lb: &SVector<T, N>,
    ub: &SVector<T, N>,
) -> Option<(SVector<T, N>, bool)> {
    let big = hard_limits::big::<T>();
    let problem = crate::qp::Problem::<T, N, R, 1> {
        h: SMatrix::identity(),
        f: -r,
        a_eq: SMatrix::from_fn(|row, k| if k < I { a[(row, k)] } else { T::zero() }),
        b_eq: *dv_0r,
        g: SMatrix::zeros(),
        lo: SVector::from_element(-T::one()),
        hi: SVector::from_element(T::one()),
        lb: lb.map(|v| v.max(-big).min(big)),
        ub: ub.map(|v| v.max(-big).min(big)),
    };
    let settings = crate::qp::Settings::DEFAULT;
    let solution = crate::qp::solve(&problem, &crate::qp::ActiveSet::EMPTY, &settings);
    // Whether rates give way: the rows' residual, not the solver's word alone.
    let gives_way = |x: &SVector<T, N>| !hard_limits::trocar_rows_met(&problem, x);
    match solution.status {
        crate::qp::Status::Optimal => {
            let x = clipped(&solution.x, lb, ub);
            Some((x, gives_way(&x)))
        }
        crate::qp::Status::NonFinite | crate::qp::Status::InvalidBounds => None,
        _ => {
            let weights = QpWeights::with_kappa(T::zero());
            let mut warm = crate::qp::ActiveSet::EMPTY;
            let (x, _) = hard_limits::trocar_within_limits(&problem, &weights, &mut warm)?;
            let x = clipped(&x, lb, ub);
            Some((x, gives_way(&x)))
        }
    }
}

/// The second stage of the rate limits of the inverses: from the previous command toward
/// `target` (the rates the speed, range and braking bounds allow, [`within_box`]) within the whole
/// box `[lb, ub]` of [`hard_limits::rate_box`] (with the acceleration and jerk bounds). From
/// `x⁻`, the previous command `θ̇⁻` where it is within the box and meets the trocar rows, else the
/// rates that do nearest to it, the rates `x⁻ + β (target − x⁻)` with the largest `β ∈ [0, 1]`
/// within the box: every joint's rate moves toward the target in the same proportion, so the
/// joints keep their coordination (the end effector keeps its path and lags) and, where the
/// target stops the task, they slow down together. Both ends meet the rows, so the rates between
/// them do. Where no rates within the box meet the rows, those within it nearest to them and
/// `true` (the trocar yields). `None` when no finite rates are found.
fn toward_within_box<T: RealField + Copy, const N: usize, const I: usize, const R: usize>(
    target: &SVector<T, N>,
    previous: &SVector<T, N>,
    a: &SMatrix<T, R, I>,
    dv_0r: &SVector<T, R>,
    lb: &SVector<T, N>,
    ub: &SVector<T, N>,
) -> Option<(SVector<T, N>, bool)> {
    let a_n = SMatrix::<T, R, N>::from_fn(|row, k| if k < I { a[(row, k)] } else { T::zero() });
    let tolerance = T::default_epsilon().sqrt() * (T::one() + dv_0r.amax());
    let meets = |x: &SVector<T, N>| (a_n * x - dv_0r).amax() <= tolerance;
    let start = if within(previous, lb, ub) && meets(previous) {
        *previous
    } else {
        let (x, yielded) = nearest_meeting_rows(previous, a, dv_0r, lb, ub)?;
        if yielded {
            return Some((x, true));
        }
        x
    };
    let beta = largest_step_within(&start, &(target - start), lb, ub);
    let x = clipped(&(start + (target - start) * beta), lb, ub);
    Some((x, !meets(&x)))
}

/// `true` when some rate of `x` is outside `rates` beyond the rounding of its bounds: where the
/// step took the rates within the box without the jerk bound (the trocar before (B4)), whether
/// the jerk bound gave way.
fn past<T: RealField + Copy, const N: usize>(x: &SVector<T, N>, rates: &RateBox<T, N>) -> bool {
    let slack =
        |b: T| T::default_epsilon() * nalgebra::convert::<f64, T>(64.0) * (T::one() + b.abs());
    (0..N).any(|k| {
        x[k] < rates.lower[k] - slack(rates.lower[k])
            || x[k] > rates.upper[k] + slack(rates.upper[k])
    })
}

/// `true` when every entry of `x` is within `[lb, ub]` (false for a NaN).
fn within<T: RealField + Copy, const N: usize>(
    x: &SVector<T, N>,
    lb: &SVector<T, N>,
    ub: &SVector<T, N>,
) -> bool {
    (0..N).all(|k| x[k] >= lb[k] && x[k] <= ub[k])
}

/// The largest `s ∈ [0, 1]` with `lb ≤ x + s d ≤ ub`, for `x` within the box.
fn largest_step_within<T: RealField + Copy, const N: usize>(
    x: &SVector<T, N>,
    d: &SVector<T, N>,
    lb: &SVector<T, N>,
    ub: &SVector<T, N>,
) -> T {
    (0..N)
        .filter(|&k| d[k] != T::zero())
        .map(|k| {
            let room = if d[k] > T::zero() {
                ub[k] - x[k]
            } else {
                x[k] - lb[k]
            };
            room / d[k].abs()
        })
        .fold(T::one(), |a, b| a.min(b))
        .max(T::zero())
}

/// `x` clipped to `[lb, ub]` entry by entry.
fn clipped<T: RealField + Copy, const N: usize>(
    x: &SVector<T, N>,
    lb: &SVector<T, N>,
    ub: &SVector<T, N>,
) -> SVector<T, N> {
    SVector::from_fn(|k, _| x[k].max(lb[k]).min(ub[k]))
}

/// `θ̇` with the constraint first, for a damped `J = J^B_0i`: with `A = Λ J` (the constrained
/// directions of the link's twist, `Λ = (Λ†ᵀ Λ†)⁻¹ Λ†ᵀ` recovered from `Λ†`) and
/// `P = I − A† A`,
/// `θ̇ = A† dv_0r + P u0 + (J P)†_κ (V − J (A† dv_0r + P u0))`, so `A θ̇ = dv_0r` holds exactly
/// and only the rest of `V` is damped (3.46), with the objective's `u0` ((44)–(46)) in the same
/// null space when there is one; where `A A^T` is singular, `A†` is damped by the same `κ`.
/// `None` if a Gram matrix is singular even so.
fn constraint_first<T: RealField + Copy, const I: usize, const R: usize>(
    j: &SMatrix<T, 6, I>,
    lambda_pinv: &SMatrix<T, 6, R>,
    kappa: T,
    v: &SVector<T, 6>,
    dv_0r: &SVector<T, R>,
    u0: Option<&SVector<T, I>>,
) -> Option<SVector<T, I>> {
    let a = constrained_rows(j, lambda_pinv)?;
    let aat = a * a.transpose();
    // Where `J` cannot move the link in a constrained direction (`A A^T` singular), that
    // stage is damped too: the constraint then holds as well as the arm allows.
    let aat = Cholesky::new(&aat)
        .or_else(|| Cholesky::new(&(aat + SMatrix::<T, R, R>::identity() * (kappa * kappa))))?;
    let first: SVector<T, I> = a.tr_mul(&aat.solve(dv_0r));
    // P = I − Aᵀ (A Aᵀ)⁻¹ A.
    let p = SMatrix::<T, I, I>::identity() - a.tr_mul(&aat.solve(&a));
    let base = first + u0.map_or_else(SVector::zeros, |u| p * u);
    let jp = j * p;
    // `J P` has rank ≤ I − R: its Gram matrix is positive definite only through `κ²`. A `κ`
    // just above 0 (variable damping (3.44) as `w` crosses `w0`) would leave it singular to
    // working precision, so `κ` is at least 1e-6 of the largest entry of `J` here.
    let floor = j.amax() * nalgebra::convert::<f64, T>(1e-6);
    let rest = damped_solve(&jp, kappa.abs().max(floor), &(v - j * base))?;
    Some(base + rest)
}

/// A direct solve `(x, det J)` when `J` is regular (`det J` finite and not 0).
fn regular<T: RealField + Copy, const C: usize>(
    solved: Option<(SVector<T, C>, T)>,
) -> Option<(SVector<T, C>, T)> {
    solved.filter(|(_, det)| *det != T::zero() && det.is_finite())
}

/// Splits `e` on `H`'s linear part: `H_v e`.
pub(crate) fn h_linear<T: RealField + Copy, const R: usize>(
    h: &SMatrix<T, R, 6>,
    e: &Vector3<T>,
) -> SVector<T, R> {
    h.fixed_columns::<3>(0) * e
}

impl<
        T: RealField + Copy,
        const N: usize,
        const I: usize,
        const R: usize,
        const K: usize,
        const M: usize,
        const P: usize,
    > Controller<T, N, I, R, K, M, P>
{
    const SIZES_OK: () =
        assert!(K + R == 6 && M == K + N - I && I <= N && R >= 1 && P >= 1 && P <= M);

    /// A controller; with [`Method::Fi`], `Θ` starts at `(S J^r_0e)†` on the first step.
    pub fn new(config: ControllerConfig<T>) -> Self {
        #[allow(clippy::let_unit_value)]
        let () = Self::SIZES_OK;
        Controller {
            config,
            objective: NullSpaceObjective::None,
            limits: HardLimits::none(),
            fi: FilteredInverse::new(SMatrix::zeros()),
            fi_started: false,
            qp_active: crate::qp::ActiveSet::EMPTY,
            qp_previous: None,
            previous: PreviousCommand::rest(),
            last_box: None,
        }
    }

    /// The same controller with hard limits: the joint ranges and speeds for every inverse,
    /// the dampers and the insertion depth for [`Method::Qp`].
    #[must_use]
    pub fn with_limits(mut self, limits: HardLimits<T, N>) -> Self {
        self.limits = limits;
        self
    }

    /// The QP's active set of the last step: the next step's warm start ([`Method::Qp`]).
    pub fn qp_active_set(&self) -> &crate::qp::ActiveSet<N, 1> {
        &self.qp_active
    }

    /// The same controller with the objective of the spare freedom of `J^B_0i`.
    #[must_use]
    pub fn with_objective(mut self, objective: NullSpaceObjective<T, N>) -> Self {
        self.objective = objective;
        self
    }

    /// The filtered-inverse state `Θ`.
    pub fn theta(&self) -> &SMatrix<T, M, P> {
        &self.fi.theta
    }

    /// Restarts the filtered inverse (it re-initialises on the next step) and the QP's warm
    /// start (the next solve starts from the empty active set), and takes the arm to be at rest:
    /// the previous command is `θ̇⁻ = 0` with `a⁻ = 0` ([`PreviousCommand::rest`]), so with
    /// acceleration limits ([`HardLimits::acceleration`]) the next rates start from zero. A
    /// controller taking over a moving arm says how it moves with
    /// [`Controller::set_previous_rates`] after the reset.
    pub fn reset(&mut self) {
        self.fi_started = false;
        self.qp_active = crate::qp::ActiveSet::EMPTY;
        self.qp_previous = None;
        self.previous = PreviousCommand::rest();
        self.last_box = None;
    }

    /// Starts from a known motion: the previous command was `rates` (`θ̇⁻`) with the acceleration
    /// `acceleration` (`a⁻ = (θ̇⁻ − θ̇⁻⁻)/dt`, zero for a steady motion). The next step's
    /// acceleration (B2) and jerk (B4) bounds ([`rate_box`]) are measured from them, so a
    /// controller that takes over an arm already moving (another controller's last command, or
    /// the robot's own state) continues from that motion instead of from rest. Every step sets
    /// them to its own command; [`Controller::reset`] sets them to rest.
    pub fn set_previous_rates(&mut self, rates: SVector<T, N>, acceleration: SVector<T, N>) {
        self.previous = PreviousCommand {
            rates,
            acceleration,
        };
        self.last_box = None;
    }

    /// The rate box ([`rate_box`]) the last step's rates were kept within, from the command
    /// before it: what a caller building on the step (a scene's QP, [`scene`]) bounds the same
    /// joints by without computing it again. `None` before the first step and after
    /// [`Controller::reset`] or [`Controller::set_previous_rates`].
    pub fn last_rate_box(&self) -> Option<&RateBox<T, N>> {
        self.last_box.as_ref()
    }

    /// The previous command: the rates of the last step and their acceleration
    /// ([`Controller::set_previous_rates`]).
    pub fn previous_command(&self) -> &PreviousCommand<T, N> {
        &self.previous
    }

    /// One control step at joints `q`; `dt` is the sample time (the filtered inverse integrates
    /// over it, the joint ranges bound the rates over it). The configuration is checked first
    /// ([`ControllerConfig::check`]: a refused one is [`ControlError::Config`]). The rates never
    /// leave the joint limits ([`rate_box`]); [`StepOutput::status`] says whether the trocar and
    /// every limit held, or what gave way.
    pub fn step<Kin: ConstrainedKinematics<T, N, I, R, K, M, P>>(
        &mut self,
        kin: &Kin,
        q: &SVector<T, N>,
        reference: &Reference<T>,
        rcm: &Rcm<T, R>,
        dt: T,
    ) -> Result<StepOutput<T, N, R>, ControlError>
    where
        Const<R>: SquareDim,
        Const<I>: SquareDim,
        Const<M>: SquareDim,
        Const<P>: SquareDim,
    {
        self.step_with_state(kin, q, reference, rcm, dt)
            .map(|(out, _)| out)
    }

    /// [`Controller::step`], and the kinematics it evaluated at the trocar (`l_a` is
    /// [`StepOutput::l_a`]): what a caller that builds on the step (a scene of several arms,
    /// [`scene`]) needs without evaluating them again.
    pub fn step_with_state<Kin: ConstrainedKinematics<T, N, I, R, K, M, P>>(
        &mut self,
        kin: &Kin,
        q: &SVector<T, N>,
        reference: &Reference<T>,
        rcm: &Rcm<T, R>,
        dt: T,
    ) -> Result<(StepOutput<T, N, R>, ConstrainedState<T, I, R, K, M>), ControlError>
    where
        Const<R>: SquareDim,
        Const<I>: SquareDim,
        Const<M>: SquareDim,
        Const<P>: SquareDim,
    {
        let c = self.config;
        c.check(dt).map_err(ControlError::Config)?;
        // 1. l_a from the trocar point, and the kinematics there.
        let (l_a, s) = kin.evaluate_at_trocar(q, &rcm.trocar)?;
        self.step_from(kin, q, reference, rcm, dt, l_a, &s)
            .map(|out| (out, s))
    }

    /// Steps 2–5 of [`Controller::step`] from the kinematics at the trocar.
    #[allow(clippy::too_many_arguments)]
    fn step_from<Kin: ConstrainedKinematics<T, N, I, R, K, M, P>>(
        &mut self,
        kin: &Kin,
        q: &SVector<T, N>,
        reference: &Reference<T>,
        rcm: &Rcm<T, R>,
        dt: T,
        l_a: T,
        s: &ConstrainedState<T, I, R, K, M>,
    ) -> Result<StepOutput<T, N, R>, ControlError>
    where
        Const<R>: SquareDim,
        Const<I>: SquareDim,
        Const<M>: SquareDim,
        Const<P>: SquareDim,
    {
        let c = self.config;
        let h = kin.h();
        let shaft = kin.shaft();

        // 2. Lateral offset of the trocar from the link, in F_r, and drift correction.
        let lateral_error = h_linear(&h, &shaft.trocar_in_frame(&s.g_0i, l_a, &rcm.trocar));
        let dv_0r = rcm.dv + lateral_error * c.kr;

        // 3. Cartesian law (2.66) with the quaternion error (2.62)–(2.65).
        let r_0e = s.g_0e.rotation;
        let rt = r_0e.transpose();
        let ep = rt * (reference.position - s.g_0e.translation);
        let eq = orientation_error(&reference.rotation, &r_0e);
        let uo = rt * (reference.angular_velocity + eq.eps * c.ko);
        let up = rt * reference.velocity + ep * c.kp - uo.cross(&ep);
        let u = Vector6::new(up.x, up.y, up.z, uo.x, uo.y, uo.z);

        // 4. [v0i; θ̇_jn] = J_inv S (u − J_c dv_0r) (3.34), J = S J^r.
        let sel = kin.task_selection();
        let rhs = u - s.jc * dv_0r;
        // A whole 6-D task (S = I) needs no product.
        let whole = P == 6
            && (0..P)
                .all(|r| (0..6).all(|c| sel[(r, c)] == if r == c { T::one() } else { T::zero() }));
        if let Method::Qp(weights) = c.method {
            return self.qp_step(
                kin,
                q,
                rcm,
                s,
                l_a,
                &sel,
                whole,
                &u,
                lateral_error,
                dv_0r,
                ep,
                eq,
                &weights,
                dt,
            );
        }
        let (task_jr, dv_e): (SMatrix<T, P, M>, SVector<T, P>) = if whole {
            (
                SMatrix::from_fn(|r, c| s.jr[(r, c)]),
                SVector::from_fn(|r, _| rhs[r]),
            )
        } else {
            (sel * s.jr, sel * rhs)
        };
        // The robot's own square solves when it has them.
        let direct_r = match c.method {
            Method::Fi { .. } => None,
            _ => regular(kin.solve_task(&task_jr, &dv_e)),
        };
        let jr = match direct_r {
            Some(_) => None,
            None => Some(PreparedJacobian::new(&task_jr)),
        };
        let w_r = direct_r.map_or_else(
            || jr.as_ref().map_or(T::zero(), |j| j.manipulability()),
            |(_, d)| d.abs(),
        );
        let mut kappa_r = T::zero();
        let solve_r = |kappa: T| -> Option<SVector<T, M>> {
            match (&direct_r, &jr) {
                (Some((x, _)), _) if kappa == T::zero() => Some(*x),
                (_, Some(j)) => j.solve(kappa, &dv_e),
                _ => damped_solve(&task_jr, kappa, &dv_e),
            }
        };
        let x: SVector<T, M> = match c.method {
            // `Method::Qp` returned above.
            Method::Pinv | Method::Qp(_) => solve_r(T::zero()).ok_or(ControlError::SingularJr)?,
            Method::Dls(d) => {
                kappa_r = d.kappa(w_r);
                solve_r(kappa_r).ok_or(ControlError::SingularJr)?
            }
            Method::Fi { gamma_r, gamma_l } => {
                if !self.fi_started {
                    self.fi = FilteredInverse::new(
                        pseudo_inverse(&task_jr).ok_or(ControlError::SingularJr)?,
                    );
                    self.fi_started = true;
                }
                let x = self.fi.inverse(&task_jr) * dv_e;
                self.fi.update(&task_jr, gamma_r, gamma_l, dt);
                x
            }
        };

        // 5. V^B_0i = Λ# v0i + Λ† dv_0r (3.33); θ̇_1..i = J^B_0i^inv V^B_0i (3.18), plus the
        //    objective's motion in the null space of J^B_0i when it is wide ((44)–(46)).
        let v0i: SVector<T, K> = x.fixed_rows::<K>(0).into_owned();
        let v_0i = s.lambda_sharp * v0i + s.lambda_pinv * dv_0r;
        //    With an objective, u0 + J⁺ (V^B_0i − J^B_0i u0) ((44)–(45)): the right-hand side
        //    is known before J^B_0i is factored, so one solve gives both.
        let objective = I > 6 && self.objective != NullSpaceObjective::None;
        let u0 = objective.then(|| self.objective.gradient::<I>(q, &s.jb0i));
        let rhs_i = match &u0 {
            Some(u0) => v_0i - s.jb0i * u0,
            None => v_0i,
        };
        let direct_i = regular(kin.solve_jb0i(&s.jb0i, &rhs_i));
        let jb0i = match direct_i {
            Some(_) => None,
            None => Some(PreparedJacobian::new(&s.jb0i)),
        };
        let w_i = direct_i.map_or_else(
            || jb0i.as_ref().map_or(T::zero(), |j| j.manipulability()),
            |(_, d)| d.abs(),
        );
        let kappa_i = c.jb0i_damping.map_or(T::zero(), |d| d.kappa(w_i));
        let qd_i = if kappa_i != T::zero() {
            // Damped: the constraint first. `Λ J^B_0i θ̇ = dv_0r` exactly, the rest of `V^B_0i`
            // damped in its null space (`constraint_first`); damping all of `V^B_0i` let the
            // link leave the trocar by 0.5 mm where DLS crosses a singularity.
            constraint_first(&s.jb0i, &s.lambda_pinv, kappa_i, &v_0i, &dv_0r, u0.as_ref())
        } else {
            match (&direct_i, &jb0i) {
                (Some((x, _)), _) => Some(*x),
                (_, Some(j)) => j.solve(kappa_i, &rhs_i),
                _ => damped_solve(&s.jb0i, kappa_i, &rhs_i),
            }
            .map(|x| match &u0 {
                Some(u0) => x + u0,
                None => x,
            })
        }
        .ok_or(ControlError::SingularJb0i)?;

        let mut qd = SVector::<T, N>::zeros();
        for k in 0..I {
            qd[k] = qd_i[k];
        }
        for k in I..N {
            qd[k] = x[K + k - I];
        }
        if !qd.iter().all(|v| v.is_finite()) {
            return Err(ControlError::NonFinite);
        }
        // The joint limits: speed, range over the sample time, acceleration, braking, jerk.
        let rates = hard_limits::rate_box(q, dt, &self.limits, c.max_joint_speed, &self.previous);
        self.last_box = Some(rates);
        let mut relaxed_rates = rates.relaxed;
        let mut status = StepStatus::Held;
        if !within(&qd, &rates.lower, &rates.upper) {
            let a = constrained_rows(&s.jb0i, &s.lambda_pinv).ok_or(ControlError::SingularJb0i)?;
            // First the task's share scaled into the bounds of the joints' place (speed, range,
            // braking: the box without the previous command's, which holds `0`)...
            let (lb, ub) = hard_limits::place_box(q, dt, &self.limits, c.max_joint_speed);
            let (target, yielded) = if within(&qd, &lb, &ub) {
                (qd, false)
            } else {
                let (x, yielded) =
                    within_box(&qd, &a, &dv_0r, &lb, &ub).ok_or(ControlError::SingularJb0i)?;
                (clipped(&x, &lb, &ub), yielded)
            };
            // ... then, with acceleration or jerk bounds, from the previous command toward it.
            let (mut lb, mut ub) = (rates.lower, rates.upper);
            let (within_all, yielded) = if within(&target, &lb, &ub) {
                (target, yielded)
            } else {
                let toward = |lb: &SVector<T, N>, ub: &SVector<T, N>| {
                    toward_within_box(&target, &self.previous.rates, &a, &dv_0r, lb, ub)
                        .ok_or(ControlError::NonFinite)
                };
                let (mut x, mut gave_way) = toward(&lb, &ub)?;
                if gave_way && !yielded {
                    // The trocar before the jerk bound: the box without (B4).
                    let loose = hard_limits::rate_box_without_jerk(
                        q,
                        dt,
                        &self.limits,
                        c.max_joint_speed,
                        &self.previous,
                    );
                    if loose != rates {
                        let (y, still) = toward(&loose.lower, &loose.upper)?;
                        if !still {
                            (x, gave_way) = (y, false);
                            (lb, ub) = (loose.lower, loose.upper);
                        }
                    }
                }
                (x, yielded || gave_way)
            };
            qd = clipped(&within_all, &lb, &ub);
            if past(&qd, &rates) {
                relaxed_rates = relaxed_rates.max(RateRelaxation::Jerk);
            }
            if yielded {
                status = StepStatus::TrocarYielded;
            }
        }
        if status.held() && hard_limits::joint_outside(q, &self.limits) {
            status = StepStatus::JointOutside;
        }
        self.previous = self.previous.then(&qd, dt);
        Ok(StepOutput {
            qd,
            l_a,
            ep,
            eq,
            u,
            lateral_error,
            dv_0r,
            w_r,
            w_i,
            kappa_r,
            kappa_i,
            qp: None,
            status,
            relaxed: relaxed_rates,
        })
    }

    /// Steps 4–5 as the QP (Q1)–(Q7) of [`hard_limits`].
    #[allow(clippy::too_many_arguments)]
    fn qp_step<Kin: ConstrainedKinematics<T, N, I, R, K, M, P>>(
        &mut self,
        kin: &Kin,
        q: &SVector<T, N>,
        rcm: &Rcm<T, R>,
        s: &ConstrainedState<T, I, R, K, M>,
        l_a: T,
        sel: &SMatrix<T, P, 6>,
        whole: bool,
        u: &Vector6<T>,
        lateral_error: SVector<T, R>,
        dv_0r: SVector<T, R>,
        ep: Vector3<T>,
        eq: Quaternion<T>,
        weights: &QpWeights<T>,
        dt: T,
    ) -> Result<StepOutput<T, N, R>, ControlError>
    where
        Const<R>: SquareDim,
        Const<I>: SquareDim,
        Const<M>: SquareDim,
        Const<P>: SquareDim,
    {
        let task = hard_limits::task_body_jacobian::<T, N, I, K, M, P>(
            sel, whole, &s.g_0e, &s.g_0i, &s.jb0i, &s.jr,
        );
        let v_t: SVector<T, P> = if whole {
            SVector::from_fn(|r, _| u[r])
        } else {
            sel * u
        };
        let mut a = constrained_rows(&s.jb0i, &s.lambda_pinv).ok_or(ControlError::SingularJb0i)?;
        let shaft = kin.shaft();
        let rates = hard_limits::rate_box(
            q,
            dt,
            &self.limits,
            self.config.max_joint_speed,
            &self.previous,
        );
        self.last_box = Some(rates);
        // (Q7): the trocar rows over the whole sample time, to second order.
        let point = shaft.origin + shaft.direction * l_a;
        let r_0r = s.g_0i.rotation * shaft.rotation;
        let directions = kin.h().fixed_columns::<3>(0).into_owned() * r_0r.transpose();
        let mut b = dv_0r;
        let mut feedback = SVector::<T, R>::zeros();
        if let (true, Some(prev)) = (weights.chord_correction, &self.qp_previous) {
            // (Q7) with W the point velocity Jacobian: E = W(q) − W(q⁻).
            let e = hard_limits::point_velocity_jacobian(&s.g_0i.rotation, &s.jb0i, &point)
                - hard_limits::point_velocity_jacobian(&prev.rotation, &prev.jb0i, &point);
            // H_v R_0rᵀ E.
            let e = directions * e;
            let qd_prev = SVector::<T, I>::from_fn(|k, _| prev.qd[k]);
            let half = nalgebra::convert::<f64, T>(0.5);
            a += e;
            b += e * qd_prev * half;
            // (Q8): what the previous step's rows left over its sample time, asked back.
            if let (Some(limit), true) =
                (weights.chord_feedback, prev.dt > T::zero() && prev.dt == dt)
            {
                let residual = prev.residual.unwrap_or_else(|| {
                    let across = shaft.moved_across(&s.g_0i, &prev.point, &prev.position);
                    prev.directions * across / prev.dt - prev.target - prev.feedback
                });
                if residual.iter().all(|v| v.is_finite() && v.abs() <= limit) {
                    feedback = -residual;
                    b += feedback;
                }
            }
        }
        let mut inputs = hard_limits::QpInputs {
            q,
            g_0i: &s.g_0i,
            jb0i: &s.jb0i,
            a: &a,
            dv_0r: &b,
            shaft_direction: shaft.direction,
            trocar: &rcm.trocar,
            l_a,
            rate_box: &rates,
        };
        let task_jr: SMatrix<T, P, M> = if whole {
            SMatrix::from_fn(|r, c| s.jr[(r, c)])
        } else {
            sel * s.jr
        };
        let w_r = PreparedJacobian::new(&task_jr).manipulability();
        // One damping rule: the task's (3.44) where the weights carry it, `kappa` the floor.
        let mut weights = *weights;
        if let Some(d) = weights.damping {
            let kappa = d.kappa(w_r);
            if kappa > weights.kappa {
                if weights.kappa > T::zero() {
                    let scale = kappa / weights.kappa;
                    weights.gamma *= scale * scale;
                } else if weights.gamma > T::zero() {
                    // A floor of 0: γ/κ² is taken as 1, the spare freedom moving at `u0`.
                    weights.gamma = kappa * kappa;
                }
                weights.kappa = kappa;
            }
        }
        let weights = &weights;
        let mut problem =
            hard_limits::step_problem(&inputs, &task, &v_t, weights, &self.objective, &self.limits);
        let (mut qd, mut report) =
            hard_limits::solve_problem(&problem, weights, &mut self.qp_active)?;
        let infeasible =
            |problem: &crate::qp::Problem<T, N, R, 1>, qd: &SVector<T, N>, report: &QpReport| {
                report.status == crate::qp::Status::InequalitiesRelaxed
                    || (report.status == crate::qp::Status::IterationLimit
                        && !problem.meets_inequalities(qd))
            };
        let mut relaxed_rates = rates.relaxed;
        // Only where the rows do not hold within the whole box: the box without (B4).
        let loose = infeasible(&problem, &qd, &report).then(|| {
            hard_limits::rate_box_without_jerk(
                q,
                dt,
                &self.limits,
                self.config.max_joint_speed,
                &self.previous,
            )
        });
        if let Some(loose) = loose.as_ref().filter(|loose| **loose != rates) {
            // The trocar before the jerk bound: the rows within the box without (B4).
            inputs.rate_box = loose;
            let without = hard_limits::step_problem(
                &inputs,
                &task,
                &v_t,
                weights,
                &self.objective,
                &self.limits,
            );
            let mut warm = self.qp_active;
            let (x, r) = hard_limits::solve_problem(&without, weights, &mut warm)?;
            self.qp_active = warm;
            (problem, qd, report) = (without, x, r);
        }
        if infeasible(&problem, &qd, &report) {
            // The trocar before the dampers (Q10): a shaft or a joint approaching a bound faster
            // than its acceleration limits let it slow to the damper's rate comes as close as
            // the safety distance over this step.
            let opened = self.limits.dampers_opened(dt);
            if opened != self.limits {
                let wide = hard_limits::step_problem(
                    &inputs,
                    &task,
                    &v_t,
                    weights,
                    &self.objective,
                    &opened,
                );
                let mut warm = self.qp_active;
                let (x, r) = hard_limits::solve_problem(&wide, weights, &mut warm)?;
                if !infeasible(&wide, &x, &r) {
                    self.qp_active = warm;
                    (problem, qd, report) = (wide, x, r);
                }
            }
        }
        let mut yielded = false;
        if infeasible(&problem, &qd, &report) {
            // The limits hold; the trocar gives way ("On conflict" in [`hard_limits`]).
            (qd, report) =
                hard_limits::trocar_within_limits(&problem, weights, &mut self.qp_active)
                    .ok_or(ControlError::NonFinite)?;
            yielded = true;
        }
        if !qd.iter().all(|v| v.is_finite()) {
            return Err(ControlError::NonFinite);
        }
        // (Q9): the step's own chord at the rates found, and one more solve.
        let check = !yielded
            && match weights.chord_check {
                ChordCheck::Never => false,
                ChordCheck::AfterChange => self.qp_previous.as_ref().is_some_and(|p| p.changed),
                ChordCheck::Always => true,
            };
        let position = s.g_0i.transform_point(&point);
        let mut first_residual = None;
        if check {
            let reached = kin.g_0i(&(q + qd * dt));
            let chord = directions * shaft.moved_across(&reached, &point, &position) / dt;
            if chord.iter().all(|v| v.is_finite()) {
                let asked = a * SVector::<T, I>::from_fn(|k, _| qd[k]);
                if let Some(again) = hard_limits::solve_again(
                    &mut problem,
                    asked + dv_0r - chord,
                    &qd,
                    report,
                    weights,
                    &mut self.qp_active,
                ) {
                    (qd, report) = again;
                    first_residual = Some(chord - dv_0r - feedback);
                }
            }
        }
        // Rounding must not take a joint past a limit either.
        let qd = clipped(&qd, &problem.lb, &problem.ub);
        if past(&qd, &rates) {
            relaxed_rates = relaxed_rates.max(RateRelaxation::Jerk);
        }
        self.previous = self.previous.then(&qd, dt);
        // Whether the trocar held: the rows asked of the step ((Q2), with (Q7)–(Q9) when on) met
        // by the rates commanded, to a tolerance of the rounding's order.
        yielded = !hard_limits::trocar_rows_met(&problem, &qd);
        self.qp_previous = Some(hard_limits::Previous {
            qd,
            rotation: s.g_0i.rotation,
            jb0i: s.jb0i,
            point,
            position,
            directions,
            target: dv_0r,
            feedback,
            dt,
            residual: first_residual,
            changed: report.iterations > 0,
        });
        if yielded {
            // The next step asks the trocar rows afresh: the shortfall of this one is not a chord
            // residual for (Q8) to ask back (the drift correction `K_r e_r` sees it).
            self.qp_previous = None;
        }
        let status = if yielded {
            StepStatus::TrocarYielded
        } else if hard_limits::joint_outside(q, &self.limits) {
            StepStatus::JointOutside
        } else if l_a < self.limits.depth[0] || l_a > self.limits.depth[1] {
            StepStatus::DepthOutside
        } else {
            StepStatus::Held
        };
        Ok(StepOutput {
            qd,
            l_a,
            ep,
            eq,
            u: *u,
            lateral_error,
            dv_0r,
            w_r,
            w_i: PreparedJacobian::new(&s.jb0i).manipulability(),
            kappa_r: weights.kappa,
            kappa_i: T::zero(),
            qp: Some(report),
            status,
            relaxed: relaxed_rates,
        })
    }
}
