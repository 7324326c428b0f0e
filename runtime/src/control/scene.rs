//! Several arms in one scene, each through its own port (the thesis's §5.2: "both arms, a
//! kinematic constraint on each"), whose instruments' shafts must not touch inside the body.
//!
//! Each arm keeps its own [`Controller`]: its step holds its port, its joint limits (the rate box
//! of [`rate_box`], and with [`super::Method::Qp`] the dampers and the depth) and follows its task,
//! as it does alone. The scene's step then changes the arms' rates `θ̇*` so that every coupling
//! holds with the least change of the arms' task velocities, solving one QP over the `NS` rates
//! of all the arms:
//!
//! ```text
//! minimise    ½ Σ_k ‖D S_k J_k (θ̇_k − θ̇*_k)‖² + ½ ε² ‖θ̇ − θ̇*‖²                     (S1)
//! subject to  L_k θ̇_k = L_k θ̇*_k         each arm's port: the lateral velocity   (S2)
//!                                        of its shaft at the port, as its step
//!                                        commanded it
//!             lb_k ≤ θ̇_k ≤ ub_k          each arm's rate box (B1)–(B4)           (S3)
//!             row_w θ̇ ≥ −ξ (d − d_s)/(d_i − d_s)   each coupling, at each of its  (S4)
//!                                        distance's witnesses, within `d_i`
//! ```
//!
//! (S1) keeps each arm's task velocity `S_k J_k θ̇*_k` (its task rows of the end effector's body
//! Jacobian `J_k`, the angular rows weighted by [`Scene::orientation_weight`] in `D`: a tip's
//! place before its orientation), and with the weight [`Scene::rate_weight`] `ε` the rates
//! themselves. `L_k = H_v R_0rᵀ W_k`, `W_k` the velocity Jacobian of the shaft's point at the port (the rows
//! (Q2) of [`super::hard_limits`] in the base frame); the box holds `θ̇*_k` (widened to it where
//! the arm's own step let a lesser bound give way). (S4) is the velocity damper of the joint
//! ranges ([`Damper`], range `[0, ∞)`) on the distance `d` between two instruments inside the
//! body, the segments from their ports to their tips, with its rows `ḋ = row θ̇` from
//! [`crate::distance`] (both ends of a parallel overlap; the ports fixed, the tips moving with
//! their arms' end-effector Jacobians). Where no coupling is within its influence distance the
//! arms' rates are unchanged: a scene of one arm steps exactly as its controller does.
//!
//! The objective is positive definite (`ε > 0`), so the QP is solved by the dual active-set
//! method from the last step's working set, in a workspace the scene keeps ([`crate::qp::Dual`]):
//! a step whose working set is the optimum's costs one factorisation, a coupling coming in or a
//! joint leaving its bound one update of it each, and the second solve (S5) none. Where the dual method declines, the primal
//! active-set method solves it, started from the working set's coupling rows alone: the box's
//! rows a step held are the ones a changed problem leaves first (their multipliers change sign
//! as a coupling comes in or lets go), and the unconstrained minimiser, the arms' own rates, is
//! within the box.
//!
//! Over a sample time the shafts' motion curves their distance, which (S4) sees to first order
//! only: the step measures each coupling's distance at `q + dt θ̇` (forward kinematics) and,
//! where it fell short of `d + dt ḋ`, raises that coupling's bound by the shortfall over `dt` and
//! solves once more (S5), so that the distance keeps its safety to second order in `dt`.
//!
//! Arms that share a joint (a torso on which two arms are mounted) are two chains that both
//! hold it; the scene asks its rate to be the same in both (S6), `θ̇_a,j = θ̇_b,j'`
//! ([`SharedJoint`]), so the arms' own steps, each of which chose the torso's rate for its own
//! task, are reconciled by the least change, and each arm's other joints keep its port.
//!
//! On conflict the ports and the joint limits come first: if no rates keep every coupling
//! within the ports and the boxes, the solver relaxes the couplings' rows as little as it can
//! and [`SceneOutput::coupling_held`] is `false`. After the step every arm's controller takes
//! the scene's rates as its previous command ([`Controller::set_previous_rates`]), so its
//! acceleration and jerk bounds continue from what was commanded.

use super::hard_limits::{point_velocity_jacobian, rate_box, task_body_jacobian, Damper};
use super::{ConstrainedKinematics, ControlError, Controller, Rcm, Reference, StepOutput};
use crate::distance::{segment_distance, SegmentDistance};
use crate::linalg::SquareDim;
use crate::qp::{solve, ActiveSet, Dual, Problem, Settings, Side, Solution, Status};
use crate::se3::Se3;
use nalgebra::{Const, RealField, SMatrix, SVector, Vector3};

/// What a [`Coupling`] keeps apart.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Between {
    /// The instruments' shafts inside the body: the segments from their ports to their tips.
    #[default]
    Shafts,
    /// The instruments' tips (points).
    Tips,
}

/// A coupling between two arms of a scene: the distance between their instruments' shafts inside
/// the body (port to tip), or between their tips, kept at least `damper.safety` by the velocity
/// damper (S4).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coupling<T> {
    /// The two arms, by their index in the scene.
    pub arms: (usize, usize),
    /// Whether the shafts or the tips are kept apart.
    pub between: Between,
    /// `d_i` ([`Damper::influence`]), `d_s` ([`Damper::safety`], m) and `ξ` ([`Damper::gain`],
    /// m/s).
    pub damper: Damper<T>,
}

impl<T: RealField + Copy> Coupling<T> {
    /// Whether the damper is one a scene takes: safety `d_s ≥ 0`, gain `ξ ≥ 0` and influence
    /// `d_i > d_s`, all finite — or all three 0, a coupling switched off (it never acts).
    pub fn is_admissible(&self) -> bool {
        let Damper {
            influence,
            safety,
            gain,
        } = self.damper;
        let zero = T::zero();
        let finite = influence.is_finite() && safety.is_finite() && gain.is_finite();
        let off = influence == zero && safety == zero && gain == zero;
        finite && (off || (safety >= zero && gain >= zero && influence > safety))
    }
}

/// A joint two arms share (a torso, a column): its rate must be the same in both (S6).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SharedJoint {
    /// The two arms, by their index in the scene.
    pub arms: (usize, usize),
    /// The joint's index in each arm's chain.
    pub joints: (usize, usize),
}

/// A camera task for an endoscope arm through its port: its view axis, the line from its port
/// through its tip, kept on a point (the midpoint of the instruments' tips, say) with the tip at a
/// fixed depth below the port. It gives the arm's [`Reference`] at each step, so that the arm's
/// own step follows it as any task; the port constraint keeps the shaft through the port, so the
/// tip on the view axis is the whole of the task's position.
///
/// With `u = (t − p_r)/‖t − p_r‖` the unit vector from the port `p_r` to the point `t`:
///
/// ```text
/// dp = p_r + l u,   dṗ = l u̇,   u̇ = (I − u uᵀ) ṫ / ‖t − p_r‖
/// dR = R(u₀ → u) R₀,  dω = vee(Ṙ(u₀ → u) R(u₀ → u)ᵀ)
/// ```
///
/// `R(u₀ → u)` the least rotation taking the view axis at the start `u₀` to `u`, `R₀` the tip's
/// orientation at the start (so the roll about the shaft is the start's), `l` the depth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera<T: RealField + Copy> {
    /// The port (the arm's base frame).
    pub port: Vector3<T>,
    /// The tip's depth below the port along the view axis (m).
    pub depth: T,
    /// The view axis at the start (unit).
    pub start_axis: Vector3<T>,
    /// The tip's orientation at the start.
    pub start_rotation: nalgebra::Matrix3<T>,
}

impl<T: RealField + Copy> Camera<T> {
    /// The camera of an arm whose tip is at `tip` (its pose, the arm's base frame) and whose
    /// port is at `port`: the depth and the view axis are the start's. `None` when the tip is at
    /// the port (no view axis).
    pub fn at_start(port: Vector3<T>, tip: &Se3<T>) -> Option<Self> {
        let axis = tip.translation - port;
        let depth = axis.norm();
        (depth > T::zero() && depth.is_finite()).then(|| Camera {
            port,
            depth,
            start_axis: axis / depth,
            start_rotation: tip.rotation,
        })
    }

    /// The tip's reference that puts `point` on the view axis (`point` and its velocity
    /// `velocity` in the arm's base frame). `None` when the point is at the port, within about
    /// a millionth of a radian of opposite the start's view axis (no least rotation), or not
    /// finite.
    pub fn reference(&self, point: &Vector3<T>, velocity: &Vector3<T>) -> Option<Reference<T>> {
        let to = point - self.port;
        let distance = to.norm();
        if !(distance > T::zero() && distance.is_finite()) {
            return None;
        }
        let u = to / distance;
        let u_dot = (velocity - u * u.dot(velocity)) / distance;
        // The least rotation taking u₀ to u, `R = I + [v]× + [v]×² / (1 + c)` with `v = u₀ × u`,
        // `c = u₀ · u` (no arc cosine: exact as u nears u₀), and its rate from `v̇ = u₀ × u̇`,
        // `ċ = u₀ · u̇`; the angular velocity is `Ṙ Rᵀ`'s, roll about u included.
        let (v, c) = (self.start_axis.cross(&u), self.start_axis.dot(&u));
        let one_c = T::one() + c;
        let tiny: T = nalgebra::convert(1e-12);
        if !one_c.is_finite() || one_c <= tiny {
            return None;
        }
        let (v_dot, c_dot) = (self.start_axis.cross(&u_dot), self.start_axis.dot(&u_dot));
        let (vx, vx_dot) = (v.cross_matrix(), v_dot.cross_matrix());
        let turn = nalgebra::Matrix3::identity() + vx + vx * vx / one_c;
        let turn_dot =
            vx_dot + (vx_dot * vx + vx * vx_dot) / one_c - vx * vx * (c_dot / (one_c * one_c));
        let w = turn_dot * turn.transpose();
        let half: T = nalgebra::convert(0.5);
        let omega = Vector3::new(
            w[(2, 1)] - w[(1, 2)],
            w[(0, 2)] - w[(2, 0)],
            w[(1, 0)] - w[(0, 1)],
        ) * half;
        let out = Reference {
            position: self.port + u * self.depth,
            rotation: turn * self.start_rotation,
            velocity: u_dot * self.depth,
            angular_velocity: omega,
        };
        (out.rotation
            .iter()
            .chain(out.angular_velocity.iter())
            .all(|x| x.is_finite()))
        .then_some(out)
    }

    /// The angle (rad) between the view axis of a tip at `tip` and the direction from the port
    /// to `point`: how far the camera looks off its point.
    pub fn view_error(&self, tip: &Vector3<T>, point: &Vector3<T>) -> T {
        let a = tip - self.port;
        let b = point - self.port;
        a.cross(&b).norm().atan2(a.dot(&b))
    }
}

/// Why a scene step was refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SceneError {
    /// The scene's sizes do not add up: `NS` must be the arms' joints (`A·N`), `ES` their port
    /// rows and shared joints (`A·R + shared`), `C` two rows per coupling; or a coupling or a
    /// shared joint names an arm or a joint that is not there, or the same arm twice.
    Sizes,
    /// An arm's own step failed (the arm's index and its error).
    Arm(usize, ControlError),
    /// A NaN or infinity appeared in the scene's rows.
    NonFinite,
}

impl core::fmt::Display for SceneError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            SceneError::Sizes => f.write_str(
                "the scene's sizes do not add up (NS = arms × joints, ES = arms × port rows + \
                 shared joints, C = 2 × couplings, couplings and shared joints between two \
                 different arms of the scene)",
            ),
            SceneError::Arm(k, e) => write!(f, "arm {k}: {e}"),
            SceneError::NonFinite => f.write_str("a non-finite value appeared in the scene step"),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for SceneError {}

/// What one scene step commanded and measured.
#[derive(Clone, Copy, Debug)]
pub struct SceneOutput<
    T: RealField + Copy,
    const A: usize,
    const N: usize,
    const R: usize,
    const P: usize,
> {
    /// Each arm's rates, as the scene commands them.
    pub qd: [SVector<T, N>; A],
    /// Each arm's own step (its rates `θ̇*` before the couplings, its errors and statuses).
    pub arms: [StepOutput<T, N, R>; A],
    /// Each coupling's distance at the step (m).
    pub distances: [T; P],
    /// `false` where some coupling's row could not hold within the ports and the boxes.
    pub coupling_held: bool,
    /// Whether any coupling changed the arms' rates (some row active).
    pub coupling_active: bool,
    /// How the scene's QP ended.
    pub status: Status,
}

/// The scene's step: its couplings and the warm start of its QP. `A` arms of `N` joints and
/// `R` port rows each, `P` couplings; the QP has `NS = A·N` rates, `ES = A·R` equality rows and
/// `C = 2·P` coupling rows (the sizes are checked at each step: [`SceneError::Sizes`]).
#[derive(Clone, Debug)]
pub struct Scene<T: RealField + Copy, const P: usize, const NS: usize, const C: usize> {
    /// The couplings.
    pub couplings: [Coupling<T>; P],
    /// The QP solver's settings.
    pub settings: Settings,
    /// The weight of the tasks' angular rows against their linear ones in (S1) (0.1 by
    /// default: a tip's place before its orientation).
    pub orientation_weight: T,
    /// The weight `ε` of the change of the rates themselves in (S1) (1e-3 by default), which
    /// makes the objective definite where the tasks leave joints free.
    pub rate_weight: T,
    active: ActiveSet<NS, C>,
    /// The QP's workspace, kept from step to step.
    dual: Dual<T, NS>,
}

impl<T: RealField + Copy, const P: usize, const NS: usize, const C: usize> Scene<T, P, NS, C> {
    /// A scene with these couplings.
    pub fn new(couplings: [Coupling<T>; P]) -> Self {
        Scene {
            couplings,
            settings: Settings::DEFAULT,
            orientation_weight: nalgebra::convert(0.1),
            rate_weight: nalgebra::convert(1e-3),
            active: ActiveSet::EMPTY,
            dual: Dual::new(),
        }
    }

    /// Forgets the QP's warm start (the arms' controllers are reset on their own).
    pub fn reset(&mut self) {
        self.active = ActiveSet::EMPTY;
    }

    /// One step of the scene: each arm's own step, then (S1)–(S4). `kins[k]`, `q[k]`,
    /// `references[k]` and `rcms[k]` are arm `k`'s, in its own base frame, as for
    /// [`Controller::step`]; the ports are the `rcms`' trocars; `bases[k]` places arm `k`'s base
    /// in the scene's frame, where the distances are measured. Where no coupling is within its
    /// influence distance and no joint is shared (`shared`, (S6)) the QP is not solved: every
    /// arm's rates are its own step's, exactly.
    #[allow(clippy::too_many_arguments)]
    pub fn step<
        Kin: ConstrainedKinematics<T, N, I, R, K, M, Q>,
        const A: usize,
        const N: usize,
        const I: usize,
        const R: usize,
        const K: usize,
        const M: usize,
        const Q: usize,
        const ES: usize,
    >(
        &mut self,
        arms: &mut [Controller<T, N, I, R, K, M, Q>; A],
        kins: &[Kin; A],
        q: &[SVector<T, N>; A],
        references: &[Reference<T>; A],
        rcms: &[Rcm<T, R>; A],
        bases: &[Se3<T>; A],
        shared: &[SharedJoint],
        dt: T,
    ) -> Result<SceneOutput<T, A, N, R, P>, SceneError>
    where
        Const<R>: SquareDim,
        Const<I>: SquareDim,
        Const<M>: SquareDim,
        Const<Q>: SquareDim,
    {
        self.step_observed(
            arms,
            kins,
            q,
            references,
            rcms,
            bases,
            shared,
            dt,
            |_: &Problem<T, NS, ES, C>, _: &ActiveSet<NS, C>, _: &Solution<T, NS, ES, C>| {},
        )
    }

    /// [`Scene::step`], showing `observe` every QP it solves: the problem, the warm start it
    /// was solved from and its solution (a benchmark replays them with other solvers).
    #[allow(clippy::too_many_arguments)]
    pub fn step_observed<
        Kin: ConstrainedKinematics<T, N, I, R, K, M, Q>,
        const A: usize,
        const N: usize,
        const I: usize,
        const R: usize,
        const K: usize,
        const M: usize,
        const Q: usize,
        const ES: usize,
        F: FnMut(&Problem<T, NS, ES, C>, &ActiveSet<NS, C>, &Solution<T, NS, ES, C>),
    >(
        &mut self,
        arms: &mut [Controller<T, N, I, R, K, M, Q>; A],
        kins: &[Kin; A],
        q: &[SVector<T, N>; A],
        references: &[Reference<T>; A],
        rcms: &[Rcm<T, R>; A],
        bases: &[Se3<T>; A],
        shared: &[SharedJoint],
        dt: T,
        mut observe: F,
    ) -> Result<SceneOutput<T, A, N, R, P>, SceneError>
    where
        Const<R>: SquareDim,
        Const<I>: SquareDim,
        Const<M>: SquareDim,
        Const<Q>: SquareDim,
    {
        if A * N != NS
            || A * R + shared.len() != ES
            || 2 * P != C
            || shared.iter().any(|s| {
                s.arms.0 >= A
                    || s.arms.1 >= A
                    || s.arms.0 == s.arms.1
                    || s.joints.0 >= N
                    || s.joints.1 >= N
            })
            || !self.couplings_fit(A)
        {
            return Err(SceneError::Sizes);
        }
        let big = super::hard_limits::big::<T>();
        let mut problem = Problem::<T, NS, ES, C> {
            h: SMatrix::zeros(),
            f: SVector::zeros(),
            a_eq: SMatrix::zeros(),
            b_eq: SVector::zeros(),
            g: SMatrix::zeros(),
            lo: SVector::from_element(-big),
            hi: SVector::from_element(big),
            lb: SVector::zeros(),
            ub: SVector::zeros(),
        };
        let mut outputs: [Option<StepOutput<T, N, R>>; A] = [None; A];
        let mut tips = [Vector3::zeros(); A];
        let mut ports = [Vector3::zeros(); A];
        let mut tip_jacobians = [SMatrix::<T, 3, N>::zeros(); A];
        let mut previous = [SVector::<T, N>::zeros(); A];
        for k in 0..A {
            let before = *arms[k].previous_command();
            previous[k] = before.rates;
            let (out, s) = arms[k]
                .step_with_state(&kins[k], &q[k], &references[k], &rcms[k], dt)
                .map_err(|e| SceneError::Arm(k, e))?;
            let l_a = out.l_a;
            // (S2): the lateral velocity of the shaft's point at the port.
            let shaft = kins[k].shaft();
            let point = shaft.origin + shaft.direction * l_a;
            let w = point_velocity_jacobian(&s.g_0i.rotation, &s.jb0i, &point);
            let r_0r = s.g_0i.rotation * shaft.rotation;
            let directions = kins[k].h().fixed_columns::<3>(0).into_owned() * r_0r.transpose();
            let l = directions * w;
            for r in 0..R {
                for c in 0..I {
                    problem.a_eq[(k * R + r, k * N + c)] = l[(r, c)];
                }
                let mut b = T::zero();
                for c in 0..I {
                    b += l[(r, c)] * out.qd[c];
                }
                problem.b_eq[k * R + r] = b;
            }
            // (S3), and (S1)'s linear term: the box the arm's own step kept its rates within.
            let rates = match arms[k].last_rate_box() {
                Some(b) => *b,
                None => rate_box(
                    &q[k],
                    dt,
                    &arms[k].limits,
                    arms[k].config.max_joint_speed,
                    &before,
                ),
            };
            for c in 0..N {
                let x = out.qd[c];
                problem.lb[k * N + c] = rates.lower[c].min(x).max(-big);
                problem.ub[k * N + c] = rates.upper[c].max(x).min(big);
            }
            // The tip and its velocity Jacobian in the base frame, for (S4).
            let je = task_body_jacobian::<T, N, I, K, M, 6>(
                &SMatrix::identity(),
                true,
                &s.g_0e,
                &s.g_0i,
                &s.jb0i,
                &s.jr,
            );
            // (S1): the arm's task rows, the angular ones weighted.
            let mut weighted = je;
            for r in 3..6 {
                for c in 0..N {
                    weighted[(r, c)] *= self.orientation_weight;
                }
            }
            let task = kins[k].task_selection() * weighted;
            let mut h = task.tr_mul(&task);
            let eps2 = self.rate_weight * self.rate_weight;
            for c in 0..N {
                h[(c, c)] += eps2;
            }
            let f = -(h * out.qd);
            for r in 0..N {
                problem.f[k * N + r] = f[r];
                for c in 0..N {
                    problem.h[(k * N + r, k * N + c)] = h[(r, c)];
                }
            }
            tips[k] = bases[k].transform_point(&s.g_0e.translation);
            tip_jacobians[k] = bases[k].rotation * s.g_0e.rotation * je.fixed_rows::<3>(0);
            ports[k] = bases[k].transform_point(&rcms[k].trocar);
            outputs[k] = Some(out);
        }
        // (S4).
        let mut distances = [T::zero(); P];
        let mut rows_in = false;
        for (p, coupling) in self.couplings.iter().enumerate() {
            let (a, b) = coupling.arms;
            let d = coupling_distance(coupling.between, &ports, &tips, a, b);
            distances[p] = d.distance;
            let (lower, _) =
                coupling
                    .damper
                    .rate_bounds(d.distance, T::zero(), T::one() / T::zero(), big);
            if lower <= -big {
                continue;
            }
            let mut ja = SMatrix::<T, 3, NS>::zeros();
            let mut jb = SMatrix::<T, 3, NS>::zeros();
            for c in 0..N {
                ja.set_column(a * N + c, &tip_jacobians[a].column(c));
                jb.set_column(b * N + c, &tip_jacobians[b].column(c));
            }
            // The ports are still; a tip is both ends of its segment of no length.
            let zero = SMatrix::<T, 3, NS>::zeros();
            let ends = match coupling.between {
                Between::Shafts => [zero, ja, zero, jb],
                Between::Tips => [ja, ja, jb, jb],
            };
            // Touching shafts (or tips) without a normal have no row: the damper held them apart
            // before.
            if let Some(rows) = d.rate_row(&ends) {
                // One row per witness (a second, equal row would be a dependent one).
                for (w, row) in rows.iter().enumerate().take(d.count) {
                    problem.g.set_row(2 * p + w, row);
                    problem.lo[2 * p + w] = lower;
                }
                rows_in = true;
            }
        }
        // (S6): a shared joint's rate is the same in both arms.
        for (e, joint) in shared.iter().enumerate() {
            let row = A * R + e;
            problem.a_eq[(row, joint.arms.0 * N + joint.joints.0)] = T::one();
            problem.a_eq[(row, joint.arms.1 * N + joint.joints.1)] = -T::one();
            rows_in = true;
        }
        if !problem.is_finite() {
            return Err(SceneError::NonFinite);
        }
        let outputs = outputs.map(|o| o.expect("every arm stepped"));
        if !rows_in {
            return Ok(SceneOutput {
                qd: outputs.map(|o| o.qd),
                arms: outputs,
                distances,
                coupling_held: true,
                coupling_active: false,
                status: Status::Optimal,
            });
        }
        // The dual method's factors stay for the second solve (S5), whose problem differs in
        // its coupling rows' bounds only.
        let mut solution = solve_qp(&mut self.dual, &problem, &self.active, &self.settings);
        observe(&problem, &self.active, &solution);
        if solution.status == Status::NonFinite || solution.status == Status::InvalidBounds {
            return Err(SceneError::NonFinite);
        }
        // (S5): each coupling's distance after the step, measured at `q + dt θ̇`; where it fell
        // short of what its rows foresaw (the shafts' motion curves their distance), the rows
        // ask that much more and the QP is solved once more.
        let mut again = false;
        // Each arm's tip at `q + dt θ̇`, once for all its couplings.
        let mut next: [Option<Vector3<T>>; A] = [None; A];
        for (p, coupling) in self.couplings.iter().enumerate() {
            if problem.lo[2 * p] <= -big {
                continue;
            }
            let (a, b) = coupling.arms;
            for k in [a, b] {
                if next[k].is_none() {
                    let qk = SVector::<T, N>::from_fn(|c, _| q[k][c] + solution.x[k * N + c] * dt);
                    let g = kins[k].g_0e(&qk).map_err(|e| SceneError::Arm(k, e))?;
                    next[k] = Some(bases[k].transform_point(&g.translation));
                }
            }
            let moved = [a, b].map(|k| next[k].unwrap_or(tips[k]));
            let after = match coupling.between {
                Between::Shafts => {
                    segment_distance(&ports[a], &moved[0], &ports[b], &moved[1]).distance
                }
                Between::Tips => (moved[0] - moved[1]).norm(),
            };
            let rows = [2 * p, 2 * p + 1];
            let foreseen = rows
                .iter()
                .filter(|&&r| problem.lo[r] > -big)
                .map(|&r| (problem.g.row(r) * solution.x)[0])
                .fold(T::one() / T::zero(), |x, y| x.min(y));
            let shortfall = distances[p] + dt * foreseen - after;
            if shortfall > T::zero() && shortfall.is_finite() {
                for r in rows {
                    if problem.lo[r] > -big {
                        problem.lo[r] += shortfall / dt;
                    }
                }
                again = true;
            }
        }
        if again {
            let warm = solution.active;
            let second = match self.dual.resolve(&problem) {
                Some(second) => second,
                None => solve_qp(&mut self.dual, &problem, &warm, &self.settings),
            };
            observe(&problem, &warm, &second);
            if second.status == Status::NonFinite || second.status == Status::InvalidBounds {
                return Err(SceneError::NonFinite);
            }
            solution = second;
        }
        self.active = solution.active;
        let held = solution.status != Status::InequalitiesRelaxed;
        let coupling_active = solution.z_general.iter().any(|z| *z != T::zero());
        // The boxes hold whatever the rounding: clipped.
        let mut qd: [SVector<T, N>; A] = core::array::from_fn(|k| {
            SVector::from_fn(|c, _| {
                let i = k * N + c;
                solution.x[i].max(problem.lb[i]).min(problem.ub[i])
            })
        });
        // A shared joint is one joint: (S6) holds to rounding, and its rate is the first arm's
        // in both, within both arms' boxes; passes enough for a chain of shared joints.
        for _ in 0..shared.len() {
            for joint in shared {
                let (a, b) = (
                    joint.arms.0 * N + joint.joints.0,
                    joint.arms.1 * N + joint.joints.1,
                );
                let v = qd[joint.arms.0][joint.joints.0]
                    .max(problem.lb[a].max(problem.lb[b]))
                    .min(problem.ub[a].min(problem.ub[b]));
                qd[joint.arms.0][joint.joints.0] = v;
                qd[joint.arms.1][joint.joints.1] = v;
            }
        }
        for k in 0..A {
            let acceleration = (qd[k] - previous[k]) / dt;
            arms[k].set_previous_rates(qd[k], acceleration);
        }
        Ok(SceneOutput {
            qd,
            arms: outputs,
            distances,
            coupling_held: held,
            coupling_active,
            status: solution.status,
        })
    }
}

/// The scene's QP from the warm start `warm`: by the dual active-set method from its working
/// set in the workspace `dual` ([`Dual::solve`]; a scene keeps one from step to step), else by
/// the primal active-set method from its general (coupling) rows alone — the box's rows of a
/// warm start are the ones a changed problem releases (a coupling coming in: 18 iterations of
/// the primal method from the whole working set against 1 from its coupling row in
/// `three-ports`).
pub fn solve_qp<T: RealField + Copy, const N: usize, const E: usize, const C: usize>(
    dual: &mut Dual<T, N>,
    problem: &Problem<T, N, E, C>,
    warm: &ActiveSet<N, C>,
    settings: &Settings,
) -> Solution<T, N, E, C> {
    match dual.solve(problem, warm) {
        Some(solution) => solution,
        None => from_couplings(problem, warm, settings),
    }
}

/// The primal active-set method from the general (coupling) rows of `warm` alone: where the
/// dual method declines.
fn from_couplings<T: RealField + Copy, const N: usize, const E: usize, const C: usize>(
    problem: &Problem<T, N, E, C>,
    warm: &ActiveSet<N, C>,
    settings: &Settings,
) -> Solution<T, N, E, C> {
    let couplings = ActiveSet {
        general: warm.general,
        bounds: [Side::Inactive; N],
    };
    solve(problem, &couplings, settings)
}

impl<T: RealField + Copy, const P: usize, const NS: usize, const C: usize> Scene<T, P, NS, C> {
    /// Whether every coupling is between two different arms of a scene of `arms` arms.
    fn couplings_fit(&self, arms: usize) -> bool {
        self.couplings
            .iter()
            .all(|c| c.arms.0 < arms && c.arms.1 < arms && c.arms.0 != c.arms.1)
    }

    /// Each coupling's distance (m) at the arms' joints `q`, as [`Scene::step`] measures it
    /// (the shafts from their ports, the `rcms`' trocars, to their tips, or the tips alone, in
    /// the scene's frame), without stepping: what a loop monitors between steps.
    ///
    /// # Errors
    /// [`SceneError::Sizes`] for a coupling that names an arm not in the scene;
    /// [`SceneError::Arm`] where an arm's forward kinematics failed.
    pub fn distances<
        Kin: ConstrainedKinematics<T, N, I, R, K, M, Q>,
        const A: usize,
        const N: usize,
        const I: usize,
        const R: usize,
        const K: usize,
        const M: usize,
        const Q: usize,
    >(
        &self,
        kins: &[Kin; A],
        q: &[SVector<T, N>; A],
        rcms: &[Rcm<T, R>; A],
        bases: &[Se3<T>; A],
    ) -> Result<[T; P], SceneError> {
        if !self.couplings_fit(A) {
            return Err(SceneError::Sizes);
        }
        let mut tips = [Vector3::zeros(); A];
        for k in 0..A {
            let g = kins[k].g_0e(&q[k]).map_err(|e| SceneError::Arm(k, e))?;
            tips[k] = bases[k].transform_point(&g.translation);
        }
        let ports: [Vector3<T>; A] =
            core::array::from_fn(|k| bases[k].transform_point(&rcms[k].trocar));
        let mut out = [T::zero(); P];
        for (d, c) in out.iter_mut().zip(&self.couplings) {
            *d = coupling_distance(c.between, &ports, &tips, c.arms.0, c.arms.1).distance;
        }
        Ok(out)
    }
}

/// The point a [`Camera`] looks at: the mean of the tips of the arms `looks_at` (their forward
/// kinematics at `q`, placed by `bases` in the scene's frame), in the base frame of the arm
/// `camera` (where its camera's reference is taken).
///
/// # Errors
/// [`SceneError::Sizes`] where `looks_at` is empty or an index is not an arm of the scene;
/// [`SceneError::Arm`] where an arm's forward kinematics failed.
pub fn camera_point<
    T: RealField + Copy,
    Kin: ConstrainedKinematics<T, N, I, R, K, M, Q>,
    const A: usize,
    const N: usize,
    const I: usize,
    const R: usize,
    const K: usize,
    const M: usize,
    const Q: usize,
>(
    kins: &[Kin; A],
    q: &[SVector<T, N>; A],
    bases: &[Se3<T>; A],
    looks_at: &[usize],
    camera: usize,
) -> Result<Vector3<T>, SceneError> {
    if looks_at.is_empty() || camera >= A || looks_at.iter().any(|&k| k >= A) {
        return Err(SceneError::Sizes);
    }
    let mut sum = Vector3::zeros();
    for &k in looks_at {
        let g = kins[k].g_0e(&q[k]).map_err(|e| SceneError::Arm(k, e))?;
        sum += bases[k].transform_point(&g.translation);
    }
    let count: T = nalgebra::convert(looks_at.len() as f64);
    Ok(bases[camera].inverse().transform_point(&(sum / count)))
}

/// The distance of a coupling between arms `a` and `b` with its witnesses: the segments from
/// their ports to their tips ([`segment_distance`]), or their tips alone (the segments of no
/// length at the tips: one witness, its normal along `t_a − t_b`).
fn coupling_distance<T: RealField + Copy, const A: usize>(
    between: Between,
    ports: &[Vector3<T>; A],
    tips: &[Vector3<T>; A],
    a: usize,
    b: usize,
) -> SegmentDistance<T> {
    match between {
        Between::Shafts => segment_distance(&ports[a], &tips[a], &ports[b], &tips[b]),
        Between::Tips => segment_distance(&tips[a], &tips[a], &tips[b], &tips[b]),
    }
}
