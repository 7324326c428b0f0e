//! The control step as a quadratic program with hard limits ([`super::Method::Qp`]): the trocar,
//! the joint position limits, the joint speed limits and the insertion depth held at once, by
//! the dense solver of [`crate::qp`] (no allocation, bounded time, warm-started from the previous
//! step's active set).
//!
//! # The problem of one step (`docs/CONTROL.md`, section "Hard limits: the QP step")
//!
//! In the joint rates `θ̇ ∈ Rⁿ`, with `J = S J^B_0e` the task rows of the end effector's body
//! Jacobian, `v_t = S u` the task command of the other inverses (`u` of (2.66), reference
//! velocity plus feedback, in the end-effector frame), `A = Λ J^B_0i [I 0]` the constrained
//! directions of the link's twist (3.30) and `l_a` the trocar's offset along the shaft:
//!
//! ```text
//! minimise    ½ ‖J θ̇ − v_t‖² + ½ κ² ‖θ̇‖² − γ u0ᵀ θ̇                          (Q1)
//! subject to  A θ̇ = dv_0r = dv_cmd + K_r e_r              the trocar, hard     (Q2)
//!             lb_k ≤ θ̇_k ≤ ub_k                           joints, hard         (Q3)
//!             l̇_lo ≤ g_lᵀ θ̇ ≤ l̇_hi                         insertion depth      (Q4)
//! ```
//!
//! - `u0 = K ∂f/∂θ` is the null-space objective's gradient ((44)–(46) of Freitas, Leite &
//!   Lizarralde 2010, [`super::NullSpaceObjective`]); with `γ = κ²` the motion (Q1) gives the
//!   spare freedom where nothing else acts is `u0`, as in the projected-gradient law (45).
//! - (Q3): `[lb_k, ub_k]` is the rate box (B1)–(B4) of [`rate_box`] (speed limit `θ̇max_k`,
//!   range over the sample time, acceleration, braking and jerk from the previous command)
//!   within which the velocity dampers of the joint position limits hold (influence distance
//!   `ρ_i`, safety distance `ρ_s`, gain `ξ`):
//!
//!   ```text
//!   d⁻_k = −ξ (θ_k − θ_min,k − ρ_s)/(ρ_i − ρ_s)   when θ_k − θ_min,k < ρ_i, else −∞     (Q5)
//!   d⁺_k =  ξ (θ_max,k − θ_k − ρ_s)/(ρ_i − ρ_s)   when θ_max,k − θ_k < ρ_i, else +∞
//!   ```
//!
//!   clipped so that `θ̇ = 0` satisfies them: `d⁻_k ≤ 0 ≤ d⁺_k`. Where the damper has no rate in
//!   common with the box (a joint too fast to slow down to the damper's rate at its
//!   acceleration limit), the box holds and the damper gives way: the braking bound (B3) still
//!   keeps the joint within its range. With the box, `θ̇ = 0` need not be within (Q3): the
//!   solver starts from any point ([`crate::qp`]'s phase 1). Integrated by explicit Euler
//!   over `dt`, `θ_k − θ_min,k − ρ_s` shrinks by at most the factor `1 − ξ dt/(ρ_i − ρ_s)` a
//!   step, so a joint that starts at least `ρ_s` inside its range stays there when
//!   `ξ dt ≤ ρ_i − ρ_s`.
//! - (Q4): with the shaft `o + l d` in `F_i` and `r = R_0iᵀ (p_t − p_0i)` the trocar in `F_i`,
//!   `l_a = (r − o)·d / |d|²` (fixed trocar), `ṙ = −v_i − ω_i × r` for the body twist
//!   `(v_i, ω_i) = J^B_0i θ̇_{1..i}` of the link, so
//!
//!   ```text
//!   l̇_a = g_lᵀ θ̇,   g_lᵀ = −[dᵀ, (r × d)ᵀ] J^B_0i [I 0] / |d|²                    (Q6)
//!   ```
//!
//!   and `l̇_lo`, `l̇_hi` are the dampers (Q5) of `l_min ≤ l_a ≤ l_max`, clipped the same way,
//!   and outside the influence distance `|l̇_a| ≤ ξ` toward a bound (Q4''): a shaft entering the
//!   damper faster than `ξ` would have to slow down in one step, which the joints' acceleration
//!   limits do not allow.
//!   Where no rate of the box (Q3) meets them (Q4'), the nearer of `Σ_k min(g_k lb_k, g_k ub_k)`
//!   and `Σ_k max(g_k lb_k, g_k ub_k)`, the range of `g_lᵀ θ̇` over the box, stands in for the
//!   bound it passes: the joint limits come first, and the inequalities always have a common
//!   point.
//!   (The insertion depth of an instrument of length `L` past the flange is `L − l_a`.)
//!
//! # Over a sample time (Q7)
//!
//! (Q2) holds for the rates at the start of a step; integrated over `dt` with the rates held,
//! the link's material point at the trocar, `m(q) = p_0i + R_0i s` (`s = o + l_a d` in `F_i`),
//! moves along a chord, and its lateral displacement is
//! `dt A θ̇ + ½ dt² H_v R_0rᵀ m̈ + O(dt³)`. At joint rates of radians per second that
//! second-order term is a lateral velocity of 1e-4–1e-3 m/s (the link leaves the trocar by
//! `½ l (|θ̇| dt)²` a step). The displacement is that of the point's velocity `ṁ = W(q) θ̇`,
//! `W = R_0i [I | −ŝ] J^B_0i [I 0]`, over the step, `dt (W θ̇ + ½ dt ∂W[θ̇] θ̇) + O(dt³)`. Since
//! `W = ∂m/∂q` and second derivatives are symmetric, `∂W[θ̇] θ̇ = ∂W[θ̇⁻] (2θ̇ − θ̇⁻)` to first
//! order in the change of rates `θ̇ − θ̇⁻` from the previous step, which stays linear in `θ̇`;
//! and `dt ∂W[θ̇⁻] ≈ E = W(q) − W(q⁻)` (the configuration moved by `dt θ̇⁻`). With
//! [`QpWeights::chord_correction`] the step asks, in place of (Q2),
//!
//! ```text
//! (A + H_v R_0rᵀ E) θ̇ = dv_0r + ½ H_v R_0rᵀ E θ̇⁻                                 (Q7)
//! ```
//!
//! so that the mean lateral velocity over the step is `dv_0r` to second order in `dt`, also
//! while the rates change fast, as when a joint meets its speed
//! limit and the others take over. The first step, and the first after
//! [`super::Controller::reset`], use (Q2) as it is. `H_v` is the linear part of
//! `H`; angular constrained directions are not corrected.
//!
//! What (Q7) leaves is the third-order term of the chord, `O(dt³)` a step: 1e-5 m/s of
//! lateral velocity where the Panda rolls its flange at 2–2.6 rad/s a joint. It changes little
//! from one step to the next, and the previous step's is known exactly once `q` is: the point
//! `s⁻` of the link that was at the trocar moved from `m⁻(q⁻)` to `m⁻(q) = p_0i(q) + R_0i(q) s⁻`,
//! and that chord less its part along the shaft's axis at `q` is how far the shaft's line moved
//! across the trocar's place ([`super::Shaft::moved_across`]). (The chord alone would also carry
//! the point's slide along a shaft that turns, `v ω dt²` for a shaft sliding at `v` while it
//! pivots at `ω`: asked back, that holds the point but walks the line off the trocar.) Its mean
//! lateral velocity `c⁻ = H_v R_0r(q⁻)ᵀ (moved across) / dt` is what the step made of
//! `dv_0r⁻` (plus its own correction `f⁻`). With [`QpWeights::chord_feedback`] the step asks
//! that residual back,
//!
//! ```text
//! b = (Q7)'s right-hand side + f,    f = −(c⁻ − dv_0r⁻ − f⁻)                        (Q8)
//! ```
//!
//! so that what is left is the change of the third-order term over one step, `O(dt⁴)`; it is
//! largest where the working set changes and the rates with it. It is
//! taken only when the sample time is the previous step's and the residual is within the
//! limit given (a larger one is not the chord's: the joints did not move by `dt θ̇⁻`, as after
//! a reset of the robot's own, and is left to the drift correction `K_r e_r`).
//!
//! Where the working set changes, the rates change regime, and the residual of the step before
//! does not foresee the step's own. With [`QpWeights::chord_check`] ([`ChordCheck`]) the step then
//! measures its own chord: with the rates `θ̇⁰` of the solve, the link's pose at `q + dt θ̇⁰`
//! (forward kinematics, [`super::ConstrainedKinematics::g_0i`]) gives the mean lateral velocity
//! `c⁰` over the step exactly ([`super::Shaft::moved_across`]), and the step solves once more
//! with
//!
//! ```text
//! (A + H_v R_0rᵀ E) θ̇ = (A + H_v R_0rᵀ E) θ̇⁰ + dv_0r − c⁰                           (Q9)
//! ```
//!
//! the chord linearised about `θ̇⁰`: what is left is the change of its nonlinear part between `θ̇⁰`
//! and `θ̇`, second order in `θ̇ − θ̇⁰`. The next step's (Q8) takes the first solve's residual
//! `c⁰ − dv_0r − f`. The change is small, and the second solve keeps the first's working set
//! (the KKT system of the change alone, `same_working_set`) unless that would cross a limit or
//! the depth row is active; then it is solved in full from the first's working set.
//! [`ChordCheck::AfterChange`] does so at the step after a working-set change (the default in
//! `f64`), [`ChordCheck::Always`] at every step (one more forward kinematics of the link and one
//! more solve). A step costs at most two solves.
//!
//! # On conflict
//!
//! The solver meets (Q2) first ([`crate::qp`]'s phase 0). If the trocar rows have no common
//! solution (`A` rank-deficient at a singularity of `J^B_0i`), they are met in least squares
//! ([`Status::EqualitiesInconsistent`]). If no rates keep the trocar within every limit (the
//! drift correction asks for motion a joint at its safety distance would need, a trocar off the
//! shaft, a speed limit too small for the motion commanded), the solver would exceed the limits
//! ([`Status::InequalitiesRelaxed`]); the step does not take those rates. Joint position and
//! speed limits are physical — the robot faults or breaks beyond them — so the limits hold and
//! the trocar gives way, after two lesser bounds have given way to it: the jerk bound (the rows
//! asked within the box without (B4)) and the dampers (Q5), (Q4) (the rows asked with both
//! dampers opened to their safety distance over one sample time (Q10),
//! `HardLimits::dampers_opened`: a damper is a way of approaching a bound, the safety distance
//! is the bound). Then: the rates within the limits nearest to the trocar rows, then the task
//! within both (`trocar_within_limits`), reported as [`Status::EqualitiesInconsistent`] in
//! [`super::StepOutput::qp`] and as [`super::StepStatus::TrocarYielded`] in
//! [`super::StepOutput::status`]. Whether the trocar held is judged from the rates commanded:
//! the rows asked of the step met to `√ε (1 + |b|)` (a relaxation the solver reports can be of
//! the order of its own tolerances, and a benign singularity meets the rows in least squares
//! exactly). Every step's rates are finally clipped to the box (Q3) and [`rate_box`] (whose
//! bounds step back where `q + dt θ̇` would round past a range), so that rounding cannot take a
//! joint past a limit either; they are always finite. After a step that gave way the next one
//! asks (Q2) afresh, without (Q7)–(Q8).

// `!(a < b)` is meant: a NaN takes the branch of a missing bound.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::{ControlError, NullSpaceObjective};
use crate::linalg::Cholesky;
use crate::qp::{self, ActiveSet, Problem, Settings, Status};
use crate::se3::Se3;
use nalgebra::{RealField, SMatrix, SVector, Vector3};

/// The weights of the QP step (Q1) ([`super::Method::Qp`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QpWeights<T> {
    /// `κ` of (Q1): the weight of the joint rates' norm (m/rad for a 6-D task's linear rows).
    /// It keeps the Hessian positive definite; `κ = 0` is allowed (the solver handles a
    /// singular Hessian exactly).
    pub kappa: T,
    /// `γ` of (Q1): the weight of the null-space objective's gradient `u0`; `γ = κ²` moves the
    /// spare freedom at `u0` where no limit acts, as (45) does.
    pub gamma: T,
    /// The damping rule of the task: with it, `κ` of a step is the larger of
    /// [`QpWeights::kappa`] and the rule's `κ(w_r)` at the task Jacobian's manipulability — the
    /// damping of [`super::Method::Dls`] (3.44) — and `γ` is scaled by `(κ / QpWeights::kappa)²`
    /// with it, so that the spare freedom still moves at `u0`. Away from singularities `κ` is
    /// then the small floor `kappa`, and with no limit active the step tracks the task as the
    /// DLS step does. `None`: `κ` is `kappa` at every step.
    pub damping: Option<super::Damping<T>>,
    /// The most working-set changes of one solve ([`Settings::max_iterations`]): it bounds the
    /// time of a step.
    pub max_iterations: usize,
    /// The second-order term (Q7) of the trocar rows: with it the link's point at the trocar
    /// keeps to the trocar over a sample time, not only at its start.
    pub chord_correction: bool,
    /// (Q8), with (Q7): the previous step's residual of the shaft's motion across the trocar,
    /// measured from the joints reached, asked back when its largest component is at most
    /// this (velocity units of `H`'s rows: m/s for lengths in metres). `None`: not used (the
    /// default in `f32`).
    pub chord_feedback: Option<T>,
    /// (Q9): when the step measures its own chord at the rates found and solves again.
    pub chord_check: ChordCheck,
}

/// When the QP step measures its own chord over the sample time and solves once more (Q9).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChordCheck {
    /// Never: the trocar rows are (Q7) with (Q8) (the default in `f32`, whose rounding of
    /// positions over a sample time is larger than what (Q9) corrects).
    Never,
    /// At the step after one whose working set changed, where the residual (Q8) of the step
    /// before does not foresee the step's own (the default in `f64`: one step in about 1,500 of
    /// `panda-laparoscope-limits`).
    AfterChange,
    /// At every step: one more forward kinematics of the link and one more solve a step, for a
    /// lateral velocity at the trocar of the order of the rounding.
    Always,
}

impl<T: RealField + Copy> QpWeights<T> {
    /// `κ`, `γ = κ²`, the solver's default iteration limit (100), (Q7), and in `f64` (Q8) with a
    /// residual of at most 1e-3 and (Q9) after a working-set change (neither in `f32`, whose
    /// rounding of positions over a sample time is as large as the residual).
    pub fn with_kappa(kappa: T) -> Self {
        QpWeights {
            kappa,
            gamma: kappa * kappa,
            damping: None,
            max_iterations: Settings::DEFAULT.max_iterations,
            chord_correction: true,
            // In f32 the rounding of the positions over a sample time (ε |p| / dt, 1.5e-5 m/s
            // for |p| = 0.5 m at 2 ms) is as large as the residual (Q8) would ask back.
            chord_feedback: (T::default_epsilon() < nalgebra::convert(1e-10))
                .then(|| nalgebra::convert(1e-3)),
            chord_check: if T::default_epsilon() < nalgebra::convert(1e-10) {
                ChordCheck::AfterChange
            } else {
                ChordCheck::Never
            },
        }
    }
}

/// A velocity damper (Q5) on a quantity with a range: influence distance `ρ_i`, safety
/// distance `ρ_s < ρ_i`, gain `ξ` (units of the quantity per second).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Damper<T> {
    /// `ρ_i`: the damper acts within this distance of a limit.
    pub influence: T,
    /// `ρ_s`: the distance from a limit that the quantity never crosses towards it.
    pub safety: T,
    /// `ξ`: the largest rate towards the limit at the influence distance.
    pub gain: T,
}

impl<T: RealField + Copy> Damper<T> {
    /// The rate bounds `(d⁻, d⁺)` of (Q5) for the value `x` in `[min, max]`, clipped so that
    /// `d⁻ ≤ 0 ≤ d⁺`; `±big` where the damper does not act. A damper with `ρ_i ≤ ρ_s` or a
    /// non-finite parameter bounds the rate away from a limit only where the quantity is at or
    /// beyond its safety distance (rate 0 towards it).
    pub fn rate_bounds(&self, x: T, min: T, max: T, big: T) -> (T, T) {
        let span = self.influence - self.safety;
        let bound = |distance: T| -> T {
            if !(distance < self.influence) {
                big
            } else if span > T::zero() && span.is_finite() && self.gain.is_finite() {
                (self.gain * (distance - self.safety) / span).max(T::zero())
            } else if distance > self.safety {
                big
            } else {
                T::zero()
            }
        };
        let lower = if min.is_finite() {
            -bound(x - min)
        } else {
            -big
        };
        let upper = if max.is_finite() { bound(max - x) } else { big };
        (
            lower.min(T::zero()).max(-big),
            upper.max(T::zero()).min(big),
        )
    }
}

/// The hard limits: joint ranges and joint speeds, which bound every inverse's rates
/// ([`rate_box`]), and, for the QP step, the dampers (Q5) of the ranges and the trocar's offset
/// `l_a` along the shaft (the insertion depth) (Q3)–(Q4).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HardLimits<T: RealField + Copy, const N: usize> {
    /// `θ_min` (rad, m for a prismatic joint); `−∞` for none.
    pub lower: SVector<T, N>,
    /// `θ_max`; `+∞` for none.
    pub upper: SVector<T, N>,
    /// `θ̇max_k > 0`; `+∞` for none ([`super::ControllerConfig::max_joint_speed`] applies as
    /// well, the smaller of the two).
    pub speed: SVector<T, N>,
    /// `a_max,k > 0` (rad/s², m/s² for a prismatic joint): the largest change of a joint's
    /// rate from one command to the next is `a_max,k dt` ([`rate_box`], (B2)), and the joint
    /// brakes in time for its range (B3); `+∞` for none.
    pub acceleration: SVector<T, N>,
    /// `j_max,k > 0` (rad/s³): the largest change of the commanded acceleration from one step
    /// to the next is `j_max,k dt` ([`rate_box`], (B4)); `+∞` for none.
    pub jerk: SVector<T, N>,
    /// The damper (Q5) of the joint position limits.
    pub joint_damper: Damper<T>,
    /// `[l_min, l_max]` of `l_a` (m); infinite entries for none.
    pub depth: [T; 2],
    /// The damper of the insertion depth.
    pub depth_damper: Damper<T>,
}

/// Why [`HardLimits::check`] refused a set of limits (joints counted from 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LimitsError {
    /// A joint's range is not `lower < upper` (or a bound is not a number).
    Range(usize),
    /// A joint's speed limit is not positive.
    Speed(usize),
    /// A joint's acceleration limit is not positive.
    Acceleration(usize),
    /// A joint's jerk limit is not positive.
    Jerk(usize),
    /// The insertion bounds are not `l_min < l_max`.
    Depth,
    /// A damper's influence distance is not above its safety distance, its safety distance is
    /// negative, or its gain is not a positive finite number.
    Damper,
}

impl core::fmt::Display for LimitsError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            LimitsError::Range(k) => write!(f, "joint {k}: its range needs lower < upper"),
            LimitsError::Speed(k) => write!(f, "joint {k}: its speed limit must be > 0"),
            LimitsError::Acceleration(k) => {
                write!(f, "joint {k}: its acceleration limit must be > 0")
            }
            LimitsError::Jerk(k) => write!(f, "joint {k}: its jerk limit must be > 0"),
            LimitsError::Depth => f.write_str("the insertion bounds need l_min < l_max"),
            LimitsError::Damper => {
                f.write_str("a damper needs influence > safety >= 0 and a finite gain > 0")
            }
        }
    }
}

impl<T: RealField + Copy, const N: usize> HardLimits<T, N> {
    /// Checks the limits: each joint's range `lower < upper` (a bound may be infinite: none),
    /// its speed, acceleration and jerk limits `> 0` (`+∞`: none), the insertion bounds
    /// `l_min < l_max`, and each damper's `ρ_i > ρ_s ≥ 0` (finite) with a finite `ξ > 0`.
    /// A NaN anywhere is refused.
    pub fn check(&self) -> Result<(), LimitsError> {
        for k in 0..N {
            let ordered = self.lower[k] < self.upper[k];
            if !ordered {
                return Err(LimitsError::Range(k + 1));
            }
            let positive = |v: T| v > T::zero();
            if !positive(self.speed[k]) {
                return Err(LimitsError::Speed(k + 1));
            }
            if !positive(self.acceleration[k]) {
                return Err(LimitsError::Acceleration(k + 1));
            }
            if !positive(self.jerk[k]) {
                return Err(LimitsError::Jerk(k + 1));
            }
        }
        let ordered = self.depth[0] < self.depth[1];
        if !ordered {
            return Err(LimitsError::Depth);
        }
        for d in [&self.joint_damper, &self.depth_damper] {
            let ok = d.influence.is_finite()
                && d.safety >= T::zero()
                && d.influence > d.safety
                && d.gain.is_finite()
                && d.gain > T::zero();
            if !ok {
                return Err(LimitsError::Damper);
            }
        }
        Ok(())
    }

    /// No limit at all (every bound infinite); the dampers `ρ_i = 0.2`, `ρ_s = 0.02`, `ξ = 3`
    /// (rad, rad/s) on the joints and `ρ_i = 0.02`, `ρ_s = 0.002` m, `ξ = 0.1` m/s on the
    /// depth, for when bounds are set: `ξ` above the speeds a joint (a Panda's: 2.175–2.61
    /// rad/s) or the shaft reaches, so that a damper takes over from the speed limit without a
    /// jump of the rates, and `ξ dt ≤ ρ_i − ρ_s` for sample times up to 60 ms (joints) and
    /// 180 ms (depth).
    pub fn none() -> Self {
        let c = |v: f64| nalgebra::convert::<f64, T>(v);
        HardLimits {
            lower: SVector::repeat(c(f64::NEG_INFINITY)),
            upper: SVector::repeat(c(f64::INFINITY)),
            speed: SVector::repeat(c(f64::INFINITY)),
            acceleration: SVector::repeat(c(f64::INFINITY)),
            jerk: SVector::repeat(c(f64::INFINITY)),
            joint_damper: Damper {
                influence: c(0.2),
                safety: c(0.02),
                gain: c(3.0),
            },
            depth: [c(f64::NEG_INFINITY), c(f64::INFINITY)],
            depth_damper: Damper {
                influence: c(0.02),
                safety: c(0.002),
                gain: c(0.1),
            },
        }
    }

    /// The same with joint ranges `[lower_k, upper_k]`.
    #[must_use]
    pub fn with_joint_limits(mut self, lower: SVector<T, N>, upper: SVector<T, N>) -> Self {
        self.lower = lower;
        self.upper = upper;
        self
    }

    /// The same with joint speed limits.
    #[must_use]
    pub fn with_speed_limits(mut self, speed: SVector<T, N>) -> Self {
        self.speed = speed;
        self
    }

    /// The same with joint acceleration limits `a_max,k` ((B2)–(B3) of [`rate_box`]).
    #[must_use]
    pub fn with_acceleration_limits(mut self, acceleration: SVector<T, N>) -> Self {
        self.acceleration = acceleration;
        self
    }

    /// The same with joint jerk limits `j_max,k` ((B4) of [`rate_box`]).
    #[must_use]
    pub fn with_jerk_limits(mut self, jerk: SVector<T, N>) -> Self {
        self.jerk = jerk;
        self
    }

    /// The same with `l_min ≤ l_a ≤ l_max`.
    #[must_use]
    pub fn with_depth(mut self, l_min: T, l_max: T) -> Self {
        self.depth = [l_min, l_max];
        self
    }

    /// These limits with both dampers (Q5) opened to the safety distance over one sample time
    /// (Q10): within `ρ_i` of a bound the rate toward it is at most `(distance − ρ_s)/dt` (the
    /// gain `(ρ_i − ρ_s)/dt` where that is larger). The step asks the trocar within these where
    /// it has no rates in common with the dampers: a damper is a way of approaching a bound, the
    /// safety distance is the bound.
    pub(super) fn dampers_opened(mut self, dt: T) -> Self {
        for damper in [&mut self.joint_damper, &mut self.depth_damper] {
            let span = damper.influence - damper.safety;
            if span > T::zero() && span.is_finite() && dt > T::zero() {
                let gain = span / dt;
                if gain > damper.gain {
                    damper.gain = gain;
                }
            }
        }
        self
    }
}

impl<T: RealField + Copy, const N: usize> Default for HardLimits<T, N> {
    fn default() -> Self {
        Self::none()
    }
}

/// What the QP step reports ([`super::StepOutput::qp`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct QpReport {
    /// How the solve ended. [`Status::EqualitiesInconsistent`] also where the trocar rows could
    /// not be met within the limits and were met in least squares within them (see "On
    /// conflict"); never [`Status::InequalitiesRelaxed`]: the step does not exceed a limit.
    pub status: Status,
    /// Working-set changes (0 when the warm start was right).
    pub iterations: usize,
    /// Inequality rows active at the solution (limits reached).
    pub active: usize,
    /// The step measured its own chord and solved again (Q9) ([`ChordCheck`]);
    /// `iterations` then counts the changes of both solves.
    pub resolved: bool,
}

/// The data of (Q1)–(Q6) the controller has at a step.
pub(super) struct QpInputs<'a, T: RealField + Copy, const N: usize, const I: usize, const R: usize>
{
    pub q: &'a SVector<T, N>,
    pub g_0i: &'a Se3<T>,
    pub jb0i: &'a SMatrix<T, 6, I>,
    /// `A = Λ J^B_0i` (R × I).
    pub a: &'a SMatrix<T, R, I>,
    /// The right-hand side of the trocar rows: `dv_0r`, with (Q7) when on.
    pub dv_0r: &'a SVector<T, R>,
    /// The shaft's direction `d` in `F_i` and the trocar point (base).
    pub shaft_direction: Vector3<T>,
    pub trocar: &'a Vector3<T>,
    pub l_a: T,
    /// The rates every method may command ([`rate_box`]): (Q3) within them.
    pub rate_box: &'a RateBox<T, N>,
}

/// What (Q7) keeps of the previous step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Previous<T: RealField + Copy, const N: usize, const I: usize, const R: usize> {
    /// `θ̇⁻`.
    pub qd: SVector<T, N>,
    /// `R_0i(q⁻)`.
    pub rotation: nalgebra::Matrix3<T>,
    /// `J^B_0i(q⁻)`.
    pub jb0i: SMatrix<T, 6, I>,
    /// The link's point at the trocar, in `F_i`: `s⁻ = o + l_a⁻ d`.
    pub point: Vector3<T>,
    /// Where that point was: `m⁻(q⁻) = p_0i(q⁻) + R_0i(q⁻) s⁻`.
    pub position: Vector3<T>,
    /// `H_v R_0r(q⁻)ᵀ`: the constrained directions the step was asked to keep.
    pub directions: SMatrix<T, R, 3>,
    /// The mean lateral velocity the step asked for, `dv_0r⁻` of (Q2).
    pub target: SVector<T, R>,
    /// `f⁻`: the correction (Q8) the step added to its right-hand side.
    pub feedback: SVector<T, R>,
    /// The step's sample time.
    pub dt: T,
    /// (Q9): the residual `c⁰ − dv_0r − f` of the step's first solve, from its own chord; the
    /// next step's (Q8) takes it in place of the one measured from the joints reached.
    pub residual: Option<SVector<T, R>>,
    /// The step's solves changed the working set.
    pub changed: bool,
}

/// `W = R [I | −ŝ] J^B_0i`: the Jacobian of the base-frame velocity `ṁ = R (v + ω × s)` of the
/// body point `s` of a link at rotation `R` whose body twist is `(v, ω) = J^B_0i θ̇`.
pub(super) fn point_velocity_jacobian<T: RealField + Copy, const I: usize>(
    rotation: &nalgebra::Matrix3<T>,
    jb0i: &SMatrix<T, 6, I>,
    s: &Vector3<T>,
) -> SMatrix<T, 3, I> {
    let body = SMatrix::<T, 3, I>::from_fn(|r, c| {
        let w = Vector3::new(jb0i[(3, c)], jb0i[(4, c)], jb0i[(5, c)]);
        jb0i[(r, c)] + w.cross(s)[r]
    });
    rotation * body
}

/// The bound the step gives the solver where there is none (rates, per second):
/// `min(1e6, 1e-6/ε)` — 1e6 in `f64`, 8.4 in `f32`. The solver's feasibility tolerance of a row
/// is relative to its bounds (`64 n ε (1 + max(|l|, |u|) + …)`, [`crate::qp`]), so a one-sided
/// row whose missing side is 1e6 would be met only to 53 units/s in `f32`; with 8.4 the insertion
/// depth's row is met to 5e-4 m/s. A joint without a speed limit is so bounded in `f32`.
pub(super) fn big<T: RealField + Copy>() -> T {
    let c = |v: f64| nalgebra::convert::<f64, T>(v);
    (c(1e-6) / T::default_epsilon()).min(c(1e6))
}

/// Builds (Q1)–(Q6). `task` is `J = S J^B_0e` (`P × N`), `v_t = S u`.
pub(super) fn step_problem<
    T: RealField + Copy,
    const N: usize,
    const I: usize,
    const R: usize,
    const P: usize,
>(
    inputs: &QpInputs<'_, T, N, I, R>,
    task: &SMatrix<T, P, N>,
    v_t: &SVector<T, P>,
    weights: &QpWeights<T>,
    objective: &NullSpaceObjective<T, N>,
    limits: &HardLimits<T, N>,
) -> Problem<T, N, R, 1> {
    let big = big::<T>();
    // (Q1): H = Jᵀ J + κ² I, f = −Jᵀ v_t − γ u0.
    let mut h = task.tr_mul(task);
    let k2 = weights.kappa * weights.kappa;
    for k in 0..N {
        h[(k, k)] += k2;
    }
    let mut f = -task.tr_mul(v_t);
    if I > 6 && *objective != NullSpaceObjective::None {
        let u0 = objective.gradient::<I>(inputs.q, inputs.jb0i);
        for k in 0..I {
            f[k] -= weights.gamma * u0[k];
        }
    }
    // (Q2): A [I 0] θ̇ = dv_0r.
    let a_eq = SMatrix::<T, R, N>::from_fn(|r, c| if c < I { inputs.a[(r, c)] } else { T::zero() });
    // (Q3), (Q5) within the box (B1)–(B4) of [`rate_box`]: where a damper has no rates in
    // common with the box, the box holds and the damper gives way.
    let rates = inputs.rate_box;
    let mut lb = SVector::<T, N>::zeros();
    let mut ub = SVector::<T, N>::zeros();
    for k in 0..N {
        let (lo, hi) =
            limits
                .joint_damper
                .rate_bounds(inputs.q[k], limits.lower[k], limits.upper[k], big);
        let (lo, hi, _) = restrict(rates.lower[k], rates.upper[k], lo, hi, T::zero(), false);
        lb[k] = lo.max(-big).min(big);
        ub[k] = hi.max(-big).min(big);
    }
    // (Q4), (Q6): l̇_a = g_lᵀ θ̇.
    let g_i = depth_rate_row(
        inputs.jb0i,
        inputs.g_0i,
        &inputs.shaft_direction,
        inputs.trocar,
    );
    let g = SMatrix::<T, 1, N>::from_fn(|_, c| if c < I { g_i[c] } else { T::zero() });
    let (mut lo, mut hi) =
        limits
            .depth_damper
            .rate_bounds(inputs.l_a, limits.depth[0], limits.depth[1], big);
    // Outside its influence distance the damper's rate `ξ` bounds the shaft's speed toward a
    // bound, so that the damper takes over without a jump of the rates: the joints' acceleration
    // limits could not slow a shaft that enters it faster (Q4'').
    let xi = limits.depth_damper.gain;
    if xi > T::zero() && xi.is_finite() {
        if limits.depth[1].is_finite() {
            hi = hi.min(xi);
        }
        if limits.depth[0].is_finite() {
            lo = lo.max(-xi);
        }
    }
    // The box first: `g_lᵀ θ̇` over the box spans `[Σ min(g_k lb_k, g_k ub_k), Σ max(…)]`; where
    // the depth's rows have no rate in common with it (a box away from 0: the shaft moving
    // too fast to be stopped in one step), they give way to its nearest end (Q4').
    let (mut reach_lo, mut reach_hi) = (T::zero(), T::zero());
    for k in 0..N {
        let (a, b) = (g[k] * lb[k], g[k] * ub[k]);
        reach_lo += a.min(b);
        reach_hi += a.max(b);
    }
    let (lo, hi) = if hi < reach_lo {
        (lo, reach_lo)
    } else if lo > reach_hi {
        (reach_hi, hi)
    } else {
        (lo, hi)
    };
    Problem {
        h,
        f,
        a_eq,
        b_eq: *inputs.dv_0r,
        g,
        lo: SVector::from_element(lo),
        hi: SVector::from_element(hi),
        lb,
        ub,
    }
}

/// The previous command of a [`super::Controller`]: the rates `θ̇⁻` it commanded last and the
/// acceleration `a⁻ = (θ̇⁻ − θ̇⁻⁻)/dt` of that command, from which the acceleration (B2) and jerk
/// (B4) bounds of [`rate_box`] are measured. [`PreviousCommand::rest`] after
/// [`super::Controller::reset`]; [`super::Controller::set_previous_rates`] to start from a known
/// motion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreviousCommand<T: RealField + Copy, const N: usize> {
    /// `θ̇⁻` (rad/s, m/s for a prismatic joint).
    pub rates: SVector<T, N>,
    /// `a⁻ = (θ̇⁻ − θ̇⁻⁻)/dt` (rad/s²).
    pub acceleration: SVector<T, N>,
}

impl<T: RealField + Copy, const N: usize> PreviousCommand<T, N> {
    /// At rest: `θ̇⁻ = 0`, `a⁻ = 0`.
    pub fn rest() -> Self {
        PreviousCommand {
            rates: SVector::zeros(),
            acceleration: SVector::zeros(),
        }
    }

    /// The command after this one, `θ̇` at the sample time `dt`: `θ̇⁻ ← θ̇`, `a⁻ ← (θ̇ − θ̇⁻)/dt`.
    #[must_use]
    pub fn then(&self, rates: &SVector<T, N>, dt: T) -> Self {
        PreviousCommand {
            rates: *rates,
            acceleration: (rates - self.rates) / dt,
        }
    }
}

impl<T: RealField + Copy, const N: usize> Default for PreviousCommand<T, N> {
    fn default() -> Self {
        Self::rest()
    }
}

/// Which bounds of the rate box (B1)–(B4) of [`rate_box`] gave way at some joint, the most
/// important first ([`super::StepOutput::relaxed`]). The order of the variants is that of their
/// priority: a later one gives way only where no rates meet it together with those before it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum RateRelaxation {
    /// Every bound held.
    #[default]
    Nothing,
    /// The jerk bound (B4) gave way to the speed, range, acceleration or braking bounds (a joint
    /// braking for its range, or starting from a motion given by
    /// [`super::Controller::set_previous_rates`], changes its acceleration faster than `j_max`),
    /// or to the trocar rows: a step whose trocar rows have no rates in common with the whole box
    /// asks them within the box without (B4), and reports this where its rates then pass (B4).
    Jerk,
    /// The braking bound (B3) gave way to the acceleration bound: the joint moves toward a bound
    /// of its range faster than it can stop at `a_max` (only from a motion that this
    /// controller did not command, or after the limits or the sample time changed); it
    /// decelerates at `a_max`.
    Braking,
    /// The acceleration bound (B2) gave way to the speed and range bounds (B1): no rate within
    /// them was within `a_max dt` of the previous command (a joint faster than its speed limit,
    /// or too close to its range to stop, when the motion was not commanded by this
    /// controller). The rate is the one within (B1) nearest to the acceleration bound.
    Acceleration,
}

/// The rates every method may command at one step ([`rate_box`]): `lower ≤ θ̇ ≤ upper`, and what
/// gave way to make it non-empty.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RateBox<T: RealField + Copy, const N: usize> {
    /// The lower bounds of the joint rates.
    pub lower: SVector<T, N>,
    /// The upper bounds (`lower ≤ upper`).
    pub upper: SVector<T, N>,
    /// The most important bound that gave way at some joint.
    pub relaxed: RateRelaxation,
}

/// The braking speed `b(d)` of (B3): the largest rate `v ≥ 0` toward a bound at distance `d` from
/// which a joint whose rate may change by at most `u = a dt` a step stops before the bound,
/// commanding `v, v − u, v − 2u, …` for a sample time `dt` each:
///
/// ```text
/// dt Σ_{k ≥ 0} max(0, v − k u) ≤ d   ⇔   v ≤ b(d) = (D + u n(n+1)/2) / (n + 1),            (B5)
/// ```
///
/// with `D = d/dt` and `n` the largest integer with `u n(n+1)/2 ≤ D` (the number of whole
/// decelerations the distance allows). `b` is exact in discrete time: the sum is `S(v)` and
/// `S(v) = v + S(v − u)`, so a rate `v ≤ b(d)` leaves `v − u ≤ b(d − v dt)` at the next step,
/// and braking at `a` is always allowed. (The continuous bound `−u/2 + sqrt(u²/4 + 2 a d)` is
/// `b` where `v` is a whole multiple of `u` and up to `u/8` above it in between, which overruns
/// the bound by up to `u dt/8`.) `0` for `d ≤ 0` or `a dt = 0`; `+∞` for no acceleration limit.
pub fn braking_speed<T: RealField + Copy>(d: T, a: T, dt: T) -> T {
    if !(d > T::zero()) {
        return T::zero();
    }
    if !(a < T::one() / T::zero()) {
        return T::one() / T::zero();
    }
    let u = a.abs() * dt;
    if !(u > T::zero()) {
        return T::zero();
    }
    let distance = d / dt;
    let two: T = nalgebra::convert(2.0);
    let eight: T = nalgebra::convert(8.0);
    let travel = |n: T| u * n * (n + T::one()) / two;
    let mut n = ((T::one() + eight * distance / u).sqrt() - T::one()) / two;
    if !(n.is_finite() && n < nalgebra::convert(1e12)) {
        // So many steps of braking that the discrete sum is its integral: the continuous bound,
        // less the largest step u/2 (safe by `(v + u/2)² / (2a) ≥ dt S(v)`).
        return ((two * a.abs() * d).sqrt() - u / two).max(T::zero());
    }
    n = n.floor().max(T::zero());
    // Rounding of the square root: the largest n with travel(n) ≤ D.
    for _ in 0..3 {
        if n > T::zero() && travel(n) > distance {
            n -= T::one();
        }
    }
    for _ in 0..3 {
        if travel(n + T::one()) <= distance {
            n += T::one();
        }
    }
    (distance + travel(n)) / (n + T::one())
}

/// Whether `v ≤ b(d)` ([`braking_speed`]) surely, without computing `b`: `v ≤ 0`, or `v` within
/// the integral bound of the sum of (B5), `dt S(v) ≤ dt (v + v²/(2u)) ≤ d` (each term
/// `max(0, v − k u)` past the first is at most the integral of `v − x u` over the step before
/// it), with a margin of `256 ε` of `d` for the rounding of both sides. A rate the box already
/// keeps below this is not bounded by (B3) on that side, so the box is the same bit for bit
/// without its square root and divisions (the usual case: a joint far from its range).
fn below_braking_speed<T: RealField + Copy>(v: T, d: T, a: T, dt: T) -> bool {
    if v <= T::zero() {
        return true;
    }
    let u = a.abs() * dt;
    let two: T = nalgebra::convert(2.0);
    let margin = T::one() - T::default_epsilon() * nalgebra::convert::<f64, T>(256.0);
    // (2 u v + v²) dt ≤ 2 u d (1 − margin), false for any NaN.
    u > T::zero() && (two * u * v + v * v) * dt <= two * u * d * margin
}

/// `[lo, hi] ∩ [lo2, hi2]` where it is not empty; else the point of `[lo, hi]` nearest to
/// `[lo2, hi2]` and `true` (the second set gave way) when the gap is beyond the rounding of the
/// bounds, `64 ε (1 + |ends|)`, plus `rounding` (that of the positions the bounds come from).
///
/// Within that rounding nothing gave way, and the point is the nearer end of `[lo2, hi2]` when
/// `second_within_rounding` (a bound from the joint's place, the braking bound: a joint riding
/// its braking curve that kept the acceleration bound's end instead would pass the curve by the
/// rounding at every step, and the next step's braking speed lower by that much again, a gap
/// that grows with the number of steps to the stop).
fn restrict<T: RealField + Copy>(
    lo: T,
    hi: T,
    lo2: T,
    hi2: T,
    rounding: T,
    second_within_rounding: bool,
) -> (T, T, bool) {
    let (l, h) = (lo.max(lo2), hi.min(hi2));
    if l <= h {
        return (l, h, false);
    }
    // The sets are disjoint, so the nearer end of the second is finite.
    let (point, near) = if hi2 < lo { (lo, hi2) } else { (hi, lo2) };
    let gap = (point - near).abs();
    let tolerance = T::default_epsilon()
        * nalgebra::convert::<f64, T>(64.0)
        * (T::one() + point.abs() + near.abs())
        + rounding;
    let gave_way = gap > tolerance;
    if second_within_rounding && !gave_way {
        (near, near, false)
    } else {
        (point, point, gave_way)
    }
}

/// A limit of [`HardLimits`] as a positive number: `|v|`, `+∞` for a NaN (taken as none:
/// [`super::ControllerConfig::check`] and the callers refuse them).
fn limit_of<T: RealField + Copy>(v: T) -> T {
    #[allow(clippy::eq_op)]
    let nan = v != v;
    if nan {
        T::one() / T::zero()
    } else {
        v.abs()
    }
}

/// The joint rates every method may command at `q` over the sample time `dt`, after the
/// command `previous`: for each joint the intersection of
///
/// ```text
/// (B1)  |θ̇| ≤ θ̇max,   θ_min ≤ q + dt θ̇ ≤ θ_max                speed, range over dt
/// (B2)  |θ̇ − θ̇⁻| ≤ a_max dt                                    acceleration
/// (B3)  −b(q − θ_min) ≤ θ̇ ≤ b(θ_max − q)                        braking (B5)
/// (B4)  |θ̇ − θ̇⁻ − dt a⁻| ≤ j_max dt²                            jerk
/// ```
///
/// `θ̇max` is the smaller of [`HardLimits::speed`] and
/// [`super::ControllerConfig::max_joint_speed`]; a joint already beyond a bound of its range may
/// only move back (its bound on that side of (B1) is 0), and `q + dt θ̇` is kept within the range
/// as the caller rounds it. (B1) always holds `θ̇ = 0`; with (B2)–(B4) the box may not: a joint
/// moving fast cannot stop in one step.
///
/// **Priority.** (B1) is physical and always holds; (B2) is applied within it, (B3) within both,
/// (B4) last. Where a bound has no rates in common with those before it, it gives way: the box
/// of that joint becomes the one rate of the box so far nearest to it, and
/// [`RateBox::relaxed`] names the most important bound that did so ([`RateRelaxation`]). So no
/// rate past a speed, range or acceleration limit is allowed when one within them exists, and
/// the jerk bound yields to braking. The controller puts the trocar rows between (B3) and (B4):
/// where no rates of the box meet them, it asks them within the box without (B4). Braking (B3)
/// keeps (B1) and (B2) compatible: from a command within (B1)–(B3) the joint can always brake at
/// `a_max` without passing its range, so with a constant `dt` and limits, and from rest or a
/// motion this controller commanded, only the jerk bound can give way (to the rounding of the
/// positions over `dt`, `16 ε (1 + |θ|)/dt`, within which a bound is not reported as given way).
///
/// Infinite where there is no limit; a joint without an acceleration limit has no braking
/// bound, and one without a jerk limit no (B4), so with neither the box is (B1) alone. A NaN
/// limit is taken as none.
pub fn rate_box<T: RealField + Copy, const N: usize>(
    q: &SVector<T, N>,
    dt: T,
    limits: &HardLimits<T, N>,
    max_joint_speed: Option<T>,
    previous: &PreviousCommand<T, N>,
) -> RateBox<T, N> {
    bounds(q, dt, limits, max_joint_speed, Some(previous), true)
}

/// [`rate_box`] without the jerk bound (B4): where the trocar rows have no rates in common with
/// the whole box, the step asks them within this one, and the jerk bound gives way to the trocar
/// ([`RateRelaxation::Jerk`]).
pub(super) fn rate_box_without_jerk<T: RealField + Copy, const N: usize>(
    q: &SVector<T, N>,
    dt: T,
    limits: &HardLimits<T, N>,
    max_joint_speed: Option<T>,
    previous: &PreviousCommand<T, N>,
) -> RateBox<T, N> {
    bounds(q, dt, limits, max_joint_speed, Some(previous), false)
}

/// The bounds (B1) and (B3) of [`rate_box`]: those of the joints' place (speed, range over the
/// sample time, braking), without the previous command's (B2), (B4). They always hold `θ̇ = 0`.
/// The inverses scale the task's share into them first ([`super::ControllerConfig::max_joint_speed`]).
pub(super) fn place_box<T: RealField + Copy, const N: usize>(
    q: &SVector<T, N>,
    dt: T,
    limits: &HardLimits<T, N>,
    max_joint_speed: Option<T>,
) -> (SVector<T, N>, SVector<T, N>) {
    let b = bounds(q, dt, limits, max_joint_speed, None, false);
    (b.lower, b.upper)
}

/// [`rate_box`], with (B2) and (B4) only when there is a previous command, and (B4) only with
/// `jerk`.
fn bounds<T: RealField + Copy, const N: usize>(
    q: &SVector<T, N>,
    dt: T,
    limits: &HardLimits<T, N>,
    max_joint_speed: Option<T>,
    previous: Option<&PreviousCommand<T, N>>,
    jerk: bool,
) -> RateBox<T, N> {
    let inf = T::one() / T::zero();
    let mut out = RateBox {
        lower: SVector::zeros(),
        upper: SVector::zeros(),
        relaxed: RateRelaxation::Nothing,
    };
    for k in 0..N {
        // (B1). `!(x > y)` is false for a NaN `y`: a NaN limit is taken as none.
        let mut speed = limit_of(limits.speed[k]);
        if let Some(s) = max_joint_speed {
            if s.abs() < speed {
                speed = s.abs();
            }
        }
        let (mut lo, mut hi) = (-speed, speed);
        if limits.lower[k].is_finite() {
            let back = ((limits.lower[k] - q[k]) / dt).min(T::zero());
            if back > lo {
                lo = back;
            }
        }
        if limits.upper[k].is_finite() {
            let ahead = ((limits.upper[k] - q[k]) / dt).max(T::zero());
            if ahead < hi {
                hi = ahead;
            }
        }
        // `q + dt ((max − q)/dt)` may round one ulp past `max`: step the bound back until the
        // joint's next position, as the caller integrates it, is within.
        for _ in 0..4 {
            if !(limits.upper[k].is_finite() && hi > T::zero() && q[k] + dt * hi > limits.upper[k])
            {
                break;
            }
            hi -= hi.abs() * T::default_epsilon();
        }
        for _ in 0..4 {
            if !(limits.lower[k].is_finite() && lo < T::zero() && q[k] + dt * lo < limits.lower[k])
            {
                break;
            }
            lo += lo.abs() * T::default_epsilon();
        }
        lo = lo.min(T::zero());
        hi = hi.max(T::zero());
        let mut relaxed = RateRelaxation::Nothing;
        // The bounds from the range are rates of `(θ − q)/dt`: a joint that rides its braking
        // curve (B3) to its range meets them to the rounding of the positions over `dt`, which is
        // not a bound giving way.
        let mut position = q[k].abs();
        for bound in [limits.lower[k], limits.upper[k]] {
            if bound.is_finite() {
                position = position.max(bound.abs());
            }
        }
        let rounding =
            T::default_epsilon() * nalgebra::convert::<f64, T>(16.0) * (T::one() + position) / dt;
        let (place_lo, place_hi) = (lo, hi);
        let mut apply = |lo: &mut T, hi: &mut T, lo2: T, hi2: T, what: RateRelaxation| {
            let (l, h, gave_way) = restrict(
                *lo,
                *hi,
                lo2,
                hi2,
                rounding,
                what == RateRelaxation::Braking,
            );
            *lo = l;
            *hi = h;
            if gave_way && what > relaxed {
                relaxed = what;
            }
        };
        let (rate, acceleration) = previous.map_or((inf, inf), |p| (p.rates[k], p.acceleration[k]));
        let a = limit_of(limits.acceleration[k]);
        if a < inf {
            if rate.is_finite() {
                // (B2).
                let change = a * dt;
                apply(
                    &mut lo,
                    &mut hi,
                    rate - change,
                    rate + change,
                    RateRelaxation::Acceleration,
                );
            }
            // (B3), (B5); a side the box is surely within leaves it as it is.
            let up = if limits.upper[k].is_finite()
                && !below_braking_speed(hi, limits.upper[k] - q[k], a, dt)
            {
                braking_speed(limits.upper[k] - q[k], a, dt)
            } else {
                inf
            };
            let down = if limits.lower[k].is_finite()
                && !below_braking_speed(-lo, q[k] - limits.lower[k], a, dt)
            {
                -braking_speed(q[k] - limits.lower[k], a, dt)
            } else {
                -inf
            };
            apply(&mut lo, &mut hi, down, up, RateRelaxation::Braking);
        }
        let j = limit_of(limits.jerk[k]);
        if jerk && j < inf && rate.is_finite() && acceleration.is_finite() {
            // (B4).
            let centre = rate + dt * acceleration;
            let change = j * dt * dt;
            apply(
                &mut lo,
                &mut hi,
                centre - change,
                centre + change,
                RateRelaxation::Jerk,
            );
        }
        // (B1) holds exactly, whatever the rounding of the bounds after it.
        out.lower[k] = lo.max(place_lo).min(place_hi);
        out.upper[k] = hi.min(place_hi).max(place_lo);
        if relaxed > out.relaxed {
            out.relaxed = relaxed;
        }
    }
    out
}

/// Whether the rates `x` meet the trocar rows `A x = b` of `problem` to `√ε (1 + |b|∞)`: the one
/// test of whether a step held the trocar (a relaxation the solver reports can be of the order
/// of its own tolerances, and a benign singularity meets the rows in least squares exactly). A
/// NaN residual does not meet them.
pub(super) fn trocar_rows_met<T: RealField + Copy, const N: usize, const R: usize>(
    problem: &Problem<T, N, R, 1>,
    x: &SVector<T, N>,
) -> bool {
    let tolerance = T::default_epsilon().sqrt() * (T::one() + problem.b_eq.amax());
    matches!(
        (problem.a_eq * x - problem.b_eq)
            .amax()
            .partial_cmp(&tolerance),
        Some(core::cmp::Ordering::Less | core::cmp::Ordering::Equal)
    )
}

/// `true` when some joint of `q` is beyond its range.
pub fn joint_outside<T: RealField + Copy, const N: usize>(
    q: &SVector<T, N>,
    limits: &HardLimits<T, N>,
) -> bool {
    (0..N).any(|k| q[k] < limits.lower[k] || q[k] > limits.upper[k])
}

/// When the trocar rows (Q2) and the limits have no common solution (the solver's
/// [`Status::InequalitiesRelaxed`]): the limits hold and the trocar gives way, in two solves.
/// First the rates within the inequalities that come nearest to the trocar rows,
/// `x₁ = argmin ½ ‖A x − b‖²` subject to (Q3)–(Q4); then the task (Q1) within the inequalities
/// with the trocar rows asked to do what `x₁` does, `A x = A x₁` (feasible: `x₁` meets it). The
/// second solve's rates when they meet the inequalities, else `x₁`. `None` when neither solve
/// gives finite rates.
pub(super) fn trocar_within_limits<T: RealField + Copy, const N: usize, const R: usize>(
    problem: &Problem<T, N, R, 1>,
    weights: &QpWeights<T>,
    warm: &mut ActiveSet<N, 1>,
) -> Option<(SVector<T, N>, QpReport)> {
    let settings = Settings {
        max_iterations: weights.max_iterations,
    };
    let a = problem.a_eq;
    let nearest = Problem::<T, N, 0, 1> {
        h: a.tr_mul(&a),
        f: -a.tr_mul(&problem.b_eq),
        a_eq: SMatrix::zeros(),
        b_eq: SVector::zeros(),
        g: problem.g,
        lo: problem.lo,
        hi: problem.hi,
        lb: problem.lb,
        ub: problem.ub,
    };
    let first = qp::solve(&nearest, &ActiveSet::EMPTY, &settings);
    if matches!(first.status, Status::NonFinite | Status::InvalidBounds)
        || !first.x.iter().all(|v| v.is_finite())
    {
        return None;
    }
    let mut task = *problem;
    task.b_eq = a * first.x;
    let second = qp::solve(&task, &first.active, &settings);
    let kept = matches!(
        second.status,
        Status::Optimal | Status::EqualitiesInconsistent | Status::IterationLimit
    ) && second.x.iter().all(|v| v.is_finite())
        && problem.meets_inequalities(&second.x);
    let (x, active, iterations) = if kept {
        (
            second.x,
            second.active,
            first.iterations + second.iterations,
        )
    } else {
        (first.x, first.active, first.iterations)
    };
    *warm = active;
    Some((
        x,
        QpReport {
            status: Status::EqualitiesInconsistent,
            iterations,
            active: active.len(),
            resolved: false,
        },
    ))
}

/// Solves a problem of [`step_problem`] from `warm` (the working set of the solve before),
/// leaving the solution's working set there.
pub(super) fn solve_problem<T: RealField + Copy, const N: usize, const R: usize>(
    problem: &Problem<T, N, R, 1>,
    weights: &QpWeights<T>,
    warm: &mut ActiveSet<N, 1>,
) -> Result<(SVector<T, N>, QpReport), ControlError> {
    let settings = Settings {
        max_iterations: weights.max_iterations,
    };
    let solution = qp::solve(problem, warm, &settings);
    match solution.status {
        Status::NonFinite | Status::InvalidBounds => {
            *warm = ActiveSet::EMPTY;
            Err(ControlError::NonFinite)
        }
        status => {
            *warm = solution.active;
            Ok((
                solution.x,
                QpReport {
                    status,
                    iterations: solution.iterations,
                    active: solution.active.len(),
                    resolved: false,
                },
            ))
        }
    }
}

/// (Q9)'s second solve: `problem` with the trocar rows' right-hand side set to `b_eq`, after a
/// first solve that gave `x` with `first` from the working set now in `active`. While that
/// working set holds, the KKT system of the change ([`same_working_set`]); else a full solve from
/// it. `None` when that gives no finite rates: the first solve's stand, and `active` with them.
pub(super) fn solve_again<T: RealField + Copy, const N: usize, const R: usize>(
    problem: &mut Problem<T, N, R, 1>,
    b_eq: SVector<T, R>,
    x: &SVector<T, N>,
    first: QpReport,
    weights: &QpWeights<T>,
    active: &mut ActiveSet<N, 1>,
) -> Option<(SVector<T, N>, QpReport)> {
    let db = b_eq - problem.b_eq;
    problem.b_eq = b_eq;
    if first.status == Status::Optimal {
        if let Some(kept) = same_working_set(problem, active, x, &db) {
            let report = QpReport {
                resolved: true,
                ..first
            };
            return Some((kept, report));
        }
    }
    let mut warm = *active;
    let (again, second) = solve_problem(problem, weights, &mut warm).ok()?;
    if second.status == Status::InequalitiesRelaxed || !again.iter().all(|v| v.is_finite()) {
        return None;
    }
    *active = warm;
    let report = QpReport {
        iterations: first.iterations + second.iterations,
        resolved: true,
        ..second
    };
    Some((again, report))
}

/// (Q9)'s second solve while the first's working set holds: the solution of (Q1)–(Q6) with the
/// right-hand side of (Q2) changed by `Δb` and every active limit kept where it is. The linear
/// term cancels against the first solution's stationarity, so
///
/// ```text
/// Δx = argmin ½ Δxᵀ H Δx   subject to   A Δx = Δb,   Δx_k = 0 at an active bound
///    = H'⁻¹ A'ᵀ (A' H'⁻¹ A'ᵀ)⁻¹ Δb
/// ```
///
/// with `H'` = `H` whose rows and columns of the bound variables are the identity's and `A'` = `A`
/// without their columns. `None` (the caller then solves in full) when the depth row is active,
/// `H'` or `A' H'⁻¹ A'ᵀ` is not positive definite, or `x + Δx` leaves a limit that was inactive.
pub(super) fn same_working_set<T: RealField + Copy, const N: usize, const R: usize>(
    problem: &Problem<T, N, R, 1>,
    active: &ActiveSet<N, 1>,
    x: &SVector<T, N>,
    db: &SVector<T, R>,
) -> Option<SVector<T, N>> {
    if active.general[0] != qp::Side::Inactive {
        return None;
    }
    let bound = |k: usize| active.bounds[k] != qp::Side::Inactive;
    let mut h = problem.h;
    let mut a = problem.a_eq;
    for k in (0..N).filter(|&k| bound(k)) {
        for j in 0..N {
            h[(k, j)] = T::zero();
            h[(j, k)] = T::zero();
        }
        h[(k, k)] = T::one();
        for r in 0..R {
            a[(r, k)] = T::zero();
        }
    }
    let u = Cholesky::new(&h)?.solve(&a.transpose());
    let schur = a * u;
    let dx = u * Cholesky::new(&schur)?.solve(db);
    let next = x + dx;
    (next.iter().all(|v| v.is_finite()) && problem.meets_inequalities(&next)).then_some(next)
}

/// `g_l` of (Q6): `l̇_a = g_lᵀ θ̇_{1..i}` for a fixed trocar, `g_lᵀ = −[dᵀ, (r × d)ᵀ] J^B_0i / |d|²`
/// with `d` the shaft's direction in `F_i` and `r = R_0iᵀ (p_t − p_0i)` the trocar in `F_i`.
/// Zero when `d = 0`.
pub fn depth_rate_row<T: RealField + Copy, const I: usize>(
    jb0i: &SMatrix<T, 6, I>,
    g_0i: &Se3<T>,
    direction: &Vector3<T>,
    trocar: &Vector3<T>,
) -> SVector<T, I> {
    let d = direction;
    let r_i = g_0i.rotation.transpose() * (trocar - g_0i.translation);
    let dd = d.norm_squared();
    let rd = r_i.cross(d);
    let mut g = SVector::<T, I>::zeros();
    if dd > T::zero() {
        for c in 0..I {
            let col = jb0i.column(c);
            let mut s = T::zero();
            for k in 0..3 {
                s += d[k] * col[k] + rd[k] * col[3 + k];
            }
            g[c] = -s / dd;
        }
    }
    g
}

/// `S J^B_0e` from the controller's kinematics: `J^B_0e = [Ad_{g_ei} J^B_0i | J^B_0e2]`, the
/// columns after the constrained link being those of `J^r_0e` after its `K` columns of
/// `Ad_{g_ei} Λ#` (3.15).
pub(super) fn task_body_jacobian<
    T: RealField + Copy,
    const N: usize,
    const I: usize,
    const K: usize,
    const M: usize,
    const P: usize,
>(
    sel: &SMatrix<T, P, 6>,
    whole: bool,
    g_0e: &Se3<T>,
    g_0i: &Se3<T>,
    jb0i: &SMatrix<T, 6, I>,
    jr: &SMatrix<T, 6, M>,
) -> SMatrix<T, P, N> {
    let g_ei = g_0e.inverse_compose(g_0i);
    let ad = g_ei.adjoint();
    let mut je = SMatrix::<T, 6, N>::zeros();
    for c in 0..I {
        let col = ad.apply(&jb0i.column(c).into_owned());
        je.set_column(c, &col);
    }
    for c in I..N {
        je.set_column(c, &jr.column(K + c - I));
    }
    if whole {
        SMatrix::from_fn(|r, c| je[(r, c)])
    } else {
        sel * je
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{SMatrix, SVector};
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 20_000, failure_persistence: None, ..ProptestConfig::default() })]

        /// The shortcut of the braking bound never claims a rate below `b(d)` that is not, in
        /// f64 and f32, from the far side of the range to the last step of braking.
        #[test]
        fn a_rate_surely_below_the_braking_speed_is_below_it(
            d in prop_oneof![0.0..1e-5f64, 0.0..1e-2f64, 0.0..6.0f64],
            a in 0.1..50.0f64,
            dt in prop_oneof![Just(1e-3f64), Just(2e-3f64), 1e-4..1e-1f64],
            fraction in 0.0..1.2f64,
        ) {
            let b = braking_speed(d, a, dt);
            let v = b * fraction;
            if below_braking_speed(v, d, a, dt) {
                prop_assert!(v <= b, "v {v} b {b}");
            }
            let (b32, v32) = (braking_speed(d as f32, a as f32, dt as f32), (b * fraction) as f32);
            if below_braking_speed(v32, d as f32, a as f32, dt as f32) {
                prop_assert!(v32 <= b32, "v {v32} b {b32}");
            }
        }
    }

    /// Far from the range the shortcut holds (it is what spares the square root), and near
    /// the braking speed it does not.
    #[test]
    fn the_braking_shortcut_is_taken_far_from_the_range_only() {
        let (a, dt) = (10.0, 1e-3);
        assert!(below_braking_speed(1.0, 1.0, a, dt));
        let b = braking_speed(1e-3, a, dt);
        assert!(!below_braking_speed(b, 1e-3, a, dt));
        assert!(!below_braking_speed(f64::NAN, 1.0, a, dt));
        assert!(!below_braking_speed(1.0, f64::NAN, a, dt));
    }

    /// A problem of the step's shape (7 rates, 2 trocar rows, the depth row) whose optimum
    /// holds some bounds: `H = JᵀJ + κ²I` from a fixed 4 × 7 `J`, and a linear term that pulls
    /// the first rates past their bounds.
    fn problem(depth: (f64, f64)) -> Problem<f64, 7, 2, 1> {
        let j = SMatrix::<f64, 4, 7>::from_fn(|r, c| ((r * 7 + c * 3) % 11) as f64 / 11.0 - 0.4);
        let mut h = j.tr_mul(&j);
        for k in 0..7 {
            h[(k, k)] += 1e-4;
        }
        Problem {
            h,
            f: SVector::from_fn(|k, _| if k < 2 { -3.0 } else { 0.1 * k as f64 }),
            a_eq: SMatrix::from_fn(|r, c| ((r * 5 + c * 2) % 7) as f64 / 7.0 - 0.5),
            b_eq: SVector::from_element(0.01),
            g: SMatrix::from_fn(|_, c| 0.1 * c as f64 - 0.2),
            lo: SVector::from_element(depth.0),
            hi: SVector::from_element(depth.1),
            lb: SVector::from_element(-1.0),
            ub: SVector::from_element(1.0),
        }
    }

    #[test]
    fn the_same_working_set_update_is_the_full_solve_of_the_changed_right_hand_side() {
        let p = problem((-10.0, 10.0));
        let first = qp::solve(&p, &ActiveSet::EMPTY, &Settings::DEFAULT);
        assert_eq!(first.status, Status::Optimal);
        assert!(
            !first.active.is_empty(),
            "no bound active: the test would not test them"
        );
        let db = SVector::<f64, 2>::new(3e-6, -2e-6);
        let kept = same_working_set(&p, &first.active, &first.x, &db).unwrap();
        let mut changed = p;
        changed.b_eq += db;
        let full = qp::solve(&changed, &first.active, &Settings::DEFAULT);
        assert_eq!(full.active, first.active);
        assert!((kept - full.x).amax() < 1e-12, "{}", (kept - full.x).amax());
        assert!((kept - first.x).amax() > 1e-7, "the change moved nothing");
    }

    #[test]
    fn the_same_working_set_update_declines_what_it_cannot_keep() {
        let p = problem((-10.0, 10.0));
        let first = qp::solve(&p, &ActiveSet::EMPTY, &Settings::DEFAULT);
        // A change large enough to push a free rate past its bound: the full solve must decide.
        let db = SVector::<f64, 2>::new(5.0, -5.0);
        assert!(same_working_set(&p, &first.active, &first.x, &db).is_none());
        // The depth row active: not handled here.
        let x = first.x;
        let gx = (p.g * x)[0];
        let held = problem((gx - 1.0, gx - 0.05));
        let at_depth = qp::solve(&held, &first.active, &Settings::DEFAULT);
        assert_eq!(at_depth.status, Status::Optimal);
        assert_eq!(at_depth.active.general[0], qp::Side::Upper);
        let db = SVector::<f64, 2>::new(1e-6, 0.0);
        assert!(same_working_set(&held, &at_depth.active, &at_depth.x, &db).is_none());
    }
}
