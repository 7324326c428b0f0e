//! Planar mechanisms made of open chains joined by structural equations (source §3–§4).
//!
//! A [`Mechanism`] is a list of open [`PlanarChain`]s that all end at the same frame (the end
//! effector `E_e`, the platform `E_s` or the object `E_c`). The structural equations (9)–(10),
//! (23)–(24), (32)–(33) say that every chain reaches the same pose; with the joint vector
//! `θ = (θ_chain1, θ_chain2, …)` they read `c(θ) = 0` (2), `c_k = pose_1(θ) − pose_k(θ)` for
//! `k = 2, …, m` (angles wrapped to `(−π, π]`).
//!
//! Differential kinematics stacks the chain Jacobians `S J_k` (`S` of (14) keeps `(v_x, v_y, ω_z)`):
//! `J θ̇ = A v` (17), (29), (37)–(39), `A = [I; …; I]`, and
//! `J_C = Ã J`, `J_A = A† J` (19), (31), (40)–(41). Joints are partitioned into active `θ_a` and
//! passive `θ_p`; `J_C = [J_Ca J_Cp]`, `J_A = [J_Aa J_Ap]` (5)–(6); passive velocities
//! `θ̇_p = −J_Cp⁻¹ J_Ca θ̇_a` (7) and the reduced Jacobian `J = J_Aa − J_Ap J_Cp⁻¹ J_Ca` (8).
//!
//! When there are more constraints than passive joints (`r > n_p`, cooperating arms: "the
//! number of constraints is not equal to the number of passive joints", §5.1) `J_Cp⁻¹` becomes
//! the left inverse `J_Cp†` and the active velocities must in addition satisfy
//! `Cᵀ J_Ca θ̇_a = 0`, `C` a basis of `R(J_Cp)^⊥` ([`Reduced::active_constraint`]).
//!
//! Angles are not wrapped in `θ` or in the outputs: an orientation is the sum of the joint angles
//! of chain 1 (plus fixed offsets), so it is continuous along a motion, as in the source's figures
//! (`φ ∈ [5.88, 7.89]` rad for the four-bar linkage).

use super::error::{ClosedChainError, SingularityKind};
use crate::linalg::{self, as_slice, select_columns, stack_rows};
use faer::{Col, Mat};
use std::f64::consts::PI;
pub use trocar_model::closed_chain::Output;
use trocar_model::closed_chain::{ContactJoint, MechanismModel};

/// A planar pose `(x, y, angle)`: the transform `Trans(x, y) · Rot_z(angle)`.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Pose2 {
    /// x coordinate.
    pub x: f64,
    /// y coordinate.
    pub y: f64,
    /// Rotation about z (rad), not wrapped.
    pub angle: f64,
}

impl Pose2 {
    /// The identity transform.
    pub const IDENTITY: Pose2 = Pose2 {
        x: 0.0,
        y: 0.0,
        angle: 0.0,
    };

    /// A pose from its coordinates.
    pub const fn new(x: f64, y: f64, angle: f64) -> Self {
        Pose2 { x, y, angle }
    }

    /// Composition `self · other` (other expressed in self's frame).
    pub fn compose(&self, other: &Pose2) -> Pose2 {
        let (s, c) = self.angle.sin_cos();
        Pose2 {
            x: self.x + c * other.x - s * other.y,
            y: self.y + s * other.x + c * other.y,
            angle: self.angle + other.angle,
        }
    }

    /// The inverse transform.
    pub fn inverse(&self) -> Pose2 {
        let (s, c) = self.angle.sin_cos();
        Pose2 {
            x: -(c * self.x + s * self.y),
            y: -(-s * self.x + c * self.y),
            angle: -self.angle,
        }
    }

    /// `(x, y, angle)` as an array.
    pub fn to_vector(&self) -> [f64; 3] {
        [self.x, self.y, self.angle]
    }

    /// `true` when every coordinate is finite.
    pub fn is_finite(&self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.angle.is_finite()
    }
}

/// Wraps an angle to `(−π, π]`.
pub fn wrap_angle(a: f64) -> f64 {
    let w = (a + PI).rem_euclid(2.0 * PI) - PI;
    if w <= -PI {
        w + 2.0 * PI
    } else {
        w
    }
}

/// What a planar joint does.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum JointType {
    /// Rotation about z through the joint frame's origin.
    Revolute,
    /// Translation along a unit `axis` of the joint frame.
    Prismatic {
        /// Unit direction in the joint frame.
        axis: [f64; 2],
    },
}

/// One joint of a planar chain: the joint frame is `origin` from the previous frame; the joint
/// then moves the next link by `Rot_z(θ)` or `Trans(θ · axis)`.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanarJoint {
    /// Unique name in the mechanism.
    pub name: String,
    /// Revolute or prismatic.
    pub kind: JointType,
    /// Fixed transform from the previous frame (chain base or previous joint) to the joint frame.
    pub origin: Pose2,
    /// Active (actuated, `θ_a`) or passive (`θ_p`).
    pub active: bool,
    /// Optional limits `[θ_min, θ_max]` (used by the joint-limit objective of (46)).
    pub limits: Option<[f64; 2]>,
}

/// An open planar chain from the ground to the common frame.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanarChain {
    /// Name (for messages).
    pub name: String,
    /// Pose of the chain's base in the world frame `E_0`.
    pub base: Pose2,
    /// Joints, base first.
    pub joints: Vec<PlanarJoint>,
    /// Fixed transform from the last joint's moving frame to the common frame.
    pub tip: Pose2,
}

/// A closed planar mechanism: chains joined at a common frame, joints split into active/passive.
///
/// Built from a [`MechanismModel`] at parameter values ([`Mechanism::from_model`]); the model's
/// admission rules are the only ones.
#[derive(Clone, Debug, PartialEq)]
pub struct Mechanism {
    /// Name.
    pub name: String,
    /// The open chains; all end at the common frame.
    pub chains: Vec<PlanarChain>,
    /// The task components `x ⊂ (x, y, φ)`, in order.
    pub outputs: Vec<Output>,
    /// Named parameters the mechanism was built from (kept for the example modules).
    pub parameters: Vec<(String, f64)>,
    /// A configuration near an assembly (optional, all joints), used as a start for Newton.
    pub initial: Option<Vec<f64>>,
    offsets: Vec<usize>,
    active: Vec<usize>,
    passive: Vec<usize>,
}

/// Jacobians of a mechanism at a configuration ((17)–(19), (29)–(31), (40)–(41)).
#[derive(Clone, Debug, PartialEq)]
pub struct Differential {
    /// Stacked chain Jacobians `J = blockdiag(S J_1, …, S J_m)` (`3m × n`).
    pub j: Mat<f64>,
    /// `A = [I; …; I]` (`3m × 3`).
    pub a: Mat<f64>,
    /// Constraint Jacobian `J_C = Ã J` (`3(m−1) × n`), with `Ã` the difference annihilator
    /// (`Ã = [[I, −I, 0, …], [I, 0, −I, …], …]`), so `J_C = ∂c/∂θ` exactly.
    pub j_c: Mat<f64>,
    /// Analytic Jacobian of the task `J_A = S_x A† J` (`m_x × n`), `A† = (1/m)[I … I]`.
    pub j_a: Mat<f64>,
    /// Active columns of `J_C`.
    pub j_ca: Mat<f64>,
    /// Passive columns of `J_C`.
    pub j_cp: Mat<f64>,
    /// Active columns of `J_A`.
    pub j_aa: Mat<f64>,
    /// Passive columns of `J_A`.
    pub j_ap: Mat<f64>,
}

/// The reduced differential kinematics in the active joints ((7), (8)).
#[derive(Clone, Debug, PartialEq)]
pub struct Reduced {
    /// `J = J_Aa − J_Ap J_Cp⁻¹ J_Ca` (8), `m_x × n_a`.
    pub jacobian: Mat<f64>,
    /// `−J_Cp⁻¹ J_Ca` (7), `n_p × n_a`: `θ̇_p = passive_map · θ̇_a`.
    pub passive_map: Mat<f64>,
    /// `J_Cp⁻¹` (or the left inverse `J_Cp†` when `r > n_p`), `n_p × r`.
    pub j_cp_inverse: Mat<f64>,
    /// Orthonormal basis `C` of `R(J_Cp)^⊥` (`r × (r − n_p)`; empty for parallel mechanisms).
    pub complement: Mat<f64>,
    /// `Cᵀ J_Ca` (`(r − n_p) × n_a`): admissible active velocities satisfy `Cᵀ J_Ca θ̇_a = 0`.
    pub active_constraint: Mat<f64>,
}

/// Result of the singularity classification of §4.3/§4.5 at a configuration.
#[derive(Clone, Debug, PartialEq)]
pub struct SingularityReport {
    /// `rank(J_Cp)`.
    pub rank_j_cp: usize,
    /// Number of passive joints `n_p`.
    pub n_passive: usize,
    /// Smallest singular value of `J_Cp` (0 without passive joints).
    pub sigma_min_j_cp: f64,
    /// Dimension of the feasible task velocities `rank([J_C; J_A]) − rank(J_C)`; equals `rank(J)`
    /// of (8) when `J_Cp` is invertible.
    pub task_rank: usize,
    /// Task dimension `m_x`.
    pub task_dim: usize,
    /// `None` at a regular configuration.
    pub kind: Option<SingularityKind>,
}

impl Mechanism {
    /// The mechanism `model` at parameter values `values` (one per model parameter, in
    /// declaration order): every length evaluated, prismatic axes normalised, contacts turned
    /// into passive joints (one per row of `H`, (36)–(42)). Errors: the model's admission rules
    /// ([`MechanismModel::validate`], [`MechanismModel::check_values`]) at these values.
    pub fn from_model(model: &MechanismModel, values: &[f64]) -> Result<Self, ClosedChainError> {
        if values.len() != model.parameters.len() {
            return Err(ClosedChainError::Dimension {
                what: "parameter values".into(),
                expected: model.parameters.len(),
                got: values.len(),
            });
        }
        model.validate()?;
        model.check_values(values)?;
        let lookup = model.lookup(values);
        let lookup: &trocar_model::closed_chain::Lookup = &lookup;
        let pose = |p: &trocar_model::closed_chain::PoseExpr, field: &str| {
            p.eval(lookup, field).map(|[x, y, a]| Pose2::new(x, y, a))
        };
        let mut chains = Vec::with_capacity(model.chains.len());
        let mut initial = Vec::new();
        let mut any_initial = false;
        for (ci, ch) in model.chains.iter().enumerate() {
            let path = format!("chains[{ci}]");
            let mut joints = Vec::with_capacity(ch.n_joints());
            for (ji, j) in ch.joints.iter().enumerate() {
                let jp = format!("{path}.joints[{ji}]");
                let kind = match j.kind.unit_axis(lookup, &format!("{jp}.axis"))? {
                    None => JointType::Revolute,
                    Some(axis) => JointType::Prismatic { axis },
                };
                match &j.initial {
                    None => initial.push(0.0),
                    Some(e) => {
                        any_initial = true;
                        initial.push(trocar_model::closed_chain::eval(
                            e,
                            lookup,
                            &format!("{jp}.initial"),
                        )?);
                    }
                }
                joints.push(PlanarJoint {
                    name: j.name.clone(),
                    kind,
                    origin: pose(&j.origin, &format!("{jp}.origin"))?,
                    active: j.active,
                    limits: trocar_model::closed_chain::joint_limits(j, lookup, &jp)?,
                });
            }
            let mut tip = pose(&ch.tip, &format!("{path}.tip"))?;
            if let Some(c) = &ch.contact {
                // The free directions of the contact become passive joints at the contact frame,
                // then the chain continues to the object frame (see [`super::cooperative`]).
                let cp = format!("{path}.contact");
                let object = pose(&c.object, &format!("{cp}.object"))?;
                let names = ch.joint_names();
                let mut origin = tip;
                for (i, cj) in c.joints(lookup, &cp)?.into_iter().enumerate() {
                    joints.push(PlanarJoint {
                        name: names[ch.joints.len() + i].clone(),
                        kind: match cj {
                            ContactJoint::Revolute => JointType::Revolute,
                            ContactJoint::Prismatic(axis) => JointType::Prismatic { axis },
                        },
                        origin,
                        active: false,
                        limits: None,
                    });
                    initial.push(0.0);
                    origin = Pose2::IDENTITY;
                }
                tip = if c.h.is_empty() {
                    tip.compose(&object)
                } else {
                    object
                };
            }
            chains.push(PlanarChain {
                name: ch.name.clone(),
                base: pose(&ch.base, &format!("{path}.base"))?,
                joints,
                tip,
            });
        }
        let (active, passive) = model.partition();
        let mut offsets = Vec::with_capacity(chains.len() + 1);
        let mut k = 0;
        for ch in &chains {
            offsets.push(k);
            k += ch.joints.len();
        }
        offsets.push(k);
        Ok(Mechanism {
            name: model.name.clone(),
            chains,
            outputs: model.outputs.clone(),
            parameters: model
                .parameters
                .iter()
                .zip(values)
                .map(|(p, v)| (p.name.clone(), *v))
                .collect(),
            initial: any_initial.then_some(initial),
            offsets,
            active,
            passive,
        })
    }

    /// The mechanism `model` at its nominal parameter values.
    pub fn nominal(model: &MechanismModel) -> Result<Self, ClosedChainError> {
        Self::from_model(model, &model.nominal_values())
    }

    /// Total number of joints `n`.
    pub fn n_joints(&self) -> usize {
        *self.offsets.last().unwrap_or(&0)
    }

    /// Number of structural equations `r = 3(m − 1)`.
    pub fn n_constraints(&self) -> usize {
        3 * (self.chains.len() - 1)
    }

    /// Indices (in `θ`) of the active joints.
    pub fn active_indices(&self) -> &[usize] {
        &self.active
    }

    /// Indices (in `θ`) of the passive joints.
    pub fn passive_indices(&self) -> &[usize] {
        &self.passive
    }

    /// Effective degrees of freedom `n_e = n − r` (Grübler count, Definition 3).
    pub fn effective_dof(&self) -> isize {
        self.n_joints() as isize - self.n_constraints() as isize
    }

    /// Joint names in `θ` order.
    pub fn joint_names(&self) -> Vec<&str> {
        self.chains
            .iter()
            .flat_map(|c| c.joints.iter().map(|j| j.name.as_str()))
            .collect()
    }

    /// All joints in `θ` order.
    pub fn joints(&self) -> impl Iterator<Item = &PlanarJoint> {
        self.chains.iter().flat_map(|c| c.joints.iter())
    }

    /// Index of the joint named `name`.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joint_names().iter().position(|n| *n == name)
    }

    /// A named parameter.
    pub fn parameter(&self, name: &str) -> Option<f64> {
        self.parameters
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| *v)
    }

    /// Range of chain `k`'s joints in `θ`.
    pub fn chain_range(&self, k: usize) -> std::ops::Range<usize> {
        self.offsets[k]..self.offsets[k + 1]
    }

    /// Splits `θ` into `(θ_a, θ_p)`.
    pub fn split(&self, theta: &Col<f64>) -> (Col<f64>, Col<f64>) {
        (
            Col::from_fn(self.active.len(), |k| theta[self.active[k]]),
            Col::from_fn(self.passive.len(), |k| theta[self.passive[k]]),
        )
    }

    /// Joins `(θ_a, θ_p)` into `θ`.
    pub fn join(&self, active: &Col<f64>, passive: &Col<f64>) -> Col<f64> {
        let mut t = Col::zeros(self.n_joints());
        for (k, &i) in self.active.iter().enumerate() {
            t[i] = active[k];
        }
        for (k, &i) in self.passive.iter().enumerate() {
            t[i] = passive[k];
        }
        t
    }

    /// Checks that `theta` holds one finite value per joint.
    pub fn check_theta(&self, theta: &Col<f64>) -> Result<(), ClosedChainError> {
        if theta.nrows() != self.n_joints() {
            return Err(ClosedChainError::Dimension {
                what: "joint vector θ".into(),
                expected: self.n_joints(),
                got: theta.nrows(),
            });
        }
        if let Some(i) = as_slice(theta).iter().position(|x| !x.is_finite()) {
            return Err(ClosedChainError::NonFinite {
                what: format!("joint `{}`", self.joint_names()[i]),
            });
        }
        Ok(())
    }

    /// Frames along chain `k` at joint values `q` (the chain's slice of `θ`): the pose of each joint
    /// frame (before its motion), then the common frame reached by the chain.
    pub fn chain_frames(&self, k: usize, q: &[f64]) -> (Vec<Pose2>, Pose2) {
        let ch = &self.chains[k];
        let mut g = ch.base;
        let mut frames = Vec::with_capacity(ch.joints.len());
        for (j, &qj) in ch.joints.iter().zip(q) {
            g = g.compose(&j.origin);
            frames.push(g);
            let motion = match j.kind {
                JointType::Revolute => Pose2::new(0.0, 0.0, qj),
                JointType::Prismatic { axis } => Pose2::new(qj * axis[0], qj * axis[1], 0.0),
            };
            g = g.compose(&motion);
        }
        (frames, g.compose(&ch.tip))
    }

    /// Pose of the common frame reached through chain `k` (forward kinematics of one open chain,
    /// (11), (12), (23)).
    pub fn chain_pose(&self, k: usize, theta: &Col<f64>) -> Pose2 {
        let r = self.chain_range(k);
        self.chain_frames(k, &as_slice(theta)[r]).1
    }

    /// `S J_k` of chain `k` (`3 × n_k`, rows `(v_x, v_y, ω_z)` in the world frame): the planar
    /// geometric Jacobians (15)–(16), (26)–(28), (38).
    pub fn chain_jacobian(&self, k: usize, theta: &Col<f64>) -> Mat<f64> {
        let r = self.chain_range(k);
        let q = &as_slice(theta)[r];
        let (frames, end) = self.chain_frames(k, q);
        let ch = &self.chains[k];
        let mut jk = Mat::zeros(3, q.len());
        for (c, (j, f)) in ch.joints.iter().zip(&frames).enumerate() {
            match j.kind {
                JointType::Revolute => {
                    jk[(0, c)] = -(end.y - f.y);
                    jk[(1, c)] = end.x - f.x;
                    jk[(2, c)] = 1.0;
                }
                JointType::Prismatic { axis } => {
                    let (s, co) = f.angle.sin_cos();
                    jk[(0, c)] = co * axis[0] - s * axis[1];
                    jk[(1, c)] = s * axis[0] + co * axis[1];
                }
            }
        }
        jk
    }

    /// The structural equations `c(θ)` (2): `pose_1 − pose_k`, `k = 2..m`, angles wrapped.
    pub fn structural(&self, theta: &Col<f64>) -> Col<f64> {
        let m = self.chains.len();
        let p1 = self.chain_pose(0, theta);
        let mut c = Col::zeros(3 * (m - 1));
        for k in 1..m {
            let pk = self.chain_pose(k, theta);
            c[3 * (k - 1)] = p1.x - pk.x;
            c[3 * (k - 1) + 1] = p1.y - pk.y;
            c[3 * (k - 1) + 2] = wrap_angle(p1.angle - pk.angle);
        }
        c
    }

    /// The pose of the common frame, `A† (pose_1, …, pose_m)` (chain angles unwrapped next to
    /// chain 1's), as `(x, y, φ)`.
    pub fn common_pose(&self, theta: &Col<f64>) -> Pose2 {
        let m = self.chains.len() as f64;
        let p1 = self.chain_pose(0, theta);
        let (mut x, mut y, mut a) = (0.0, 0.0, 0.0);
        for k in 0..self.chains.len() {
            let pk = self.chain_pose(k, theta);
            x += pk.x;
            y += pk.y;
            a += p1.angle + wrap_angle(pk.angle - p1.angle);
        }
        Pose2::new(x / m, y / m, a / m)
    }

    /// The task vector `x = h(θ)` (1): the selected outputs of [`Mechanism::common_pose`].
    pub fn task(&self, theta: &Col<f64>) -> Col<f64> {
        let p = self.common_pose(theta).to_vector();
        Col::from_fn(self.outputs.len(), |k| p[self.outputs[k].index()])
    }

    /// Stacked Jacobian `J` and `A` of `J θ̇ = A v` ((17), (29), (39)).
    pub fn stacked(&self, theta: &Col<f64>) -> (Mat<f64>, Mat<f64>) {
        let m = self.chains.len();
        let n = self.n_joints();
        let mut j = Mat::zeros(3 * m, n);
        let a = Mat::from_fn(3 * m, 3, |r, c| if r % 3 == c { 1.0 } else { 0.0 });
        for k in 0..m {
            let r = self.chain_range(k);
            let jk = self.chain_jacobian(k, theta);
            j.as_mut()
                .submatrix_mut(3 * k, r.start, 3, r.len())
                .copy_from(&jk);
        }
        (j, a)
    }

    /// The difference annihilator `Ã = [[I, −I, 0, …], [I, 0, −I, …], …]` (`3(m−1) × 3m`), `Ã A = 0`.
    pub fn difference_annihilator(&self) -> Mat<f64> {
        let m = self.chains.len();
        Mat::from_fn(3 * (m - 1), 3 * m, |r, c| {
            let k = r / 3 + 1;
            if c == r % 3 {
                1.0
            } else if c == 3 * k + r % 3 {
                -1.0
            } else {
                0.0
            }
        })
    }

    /// Task selection `S_x` (`m_x × 3`).
    pub fn output_selection(&self) -> Mat<f64> {
        let mut s = Mat::zeros(self.outputs.len(), 3);
        for (i, o) in self.outputs.iter().enumerate() {
            s[(i, o.index())] = 1.0;
        }
        s
    }

    /// `J_C = Ã J`, `J_A = S_x A† J` and their active/passive blocks ((19), (31), (41), (5)–(6)).
    pub fn differential(&self, theta: &Col<f64>) -> Result<Differential, ClosedChainError> {
        self.check_theta(theta)?;
        let (j, a) = self.stacked(theta);
        let at = self.difference_annihilator();
        // `A` stacks one 3 × 3 identity per chain, so `Aᵀ A = m I` and `A† = Aᵀ / m` exactly.
        let a_dag = a.transpose() * faer::Scale(1.0 / self.chains.len() as f64);
        let j_c = &at * &j;
        let j_a = self.output_selection() * a_dag * &j;
        let j_ca = select_columns(j_c.as_ref(), &self.active);
        let j_cp = select_columns(j_c.as_ref(), &self.passive);
        let j_aa = select_columns(j_a.as_ref(), &self.active);
        let j_ap = select_columns(j_a.as_ref(), &self.passive);
        Ok(Differential {
            j,
            a,
            j_c,
            j_a,
            j_ca,
            j_cp,
            j_aa,
            j_ap,
        })
    }

    /// The reduced kinematics (7)–(8) at `θ`.
    ///
    /// Errors with [`ClosedChainError::Singular`] (kind [`SingularityKind::Parallel`]) when `J_Cp`
    /// loses rank: the passive joints can then move with the active joints locked.
    pub fn reduced(&self, theta: &Col<f64>) -> Result<Reduced, ClosedChainError> {
        let d = self.differential(theta)?;
        reduce(&d)
    }

    /// Passive velocities `θ̇_p = −J_Cp⁻¹ J_Ca θ̇_a` (7).
    pub fn passive_velocities(
        &self,
        theta: &Col<f64>,
        active_velocities: &Col<f64>,
    ) -> Result<Col<f64>, ClosedChainError> {
        if active_velocities.nrows() != self.active.len() {
            return Err(ClosedChainError::Dimension {
                what: "active velocities θ̇_a".into(),
                expected: self.active.len(),
                got: active_velocities.nrows(),
            });
        }
        Ok(self.reduced(theta)?.passive_map * active_velocities)
    }

    /// Forward kinematics of the closed chain: the passive joints for given active joints, by
    /// Newton's method on the structural equations `c(θ_a, θ_p) = 0` from `passive_guess`.
    ///
    /// Errors: singular `J_Cp` on the way ([`ClosedChainError::Singular`]), no convergence
    /// ([`ClosedChainError::NoConvergence`]: e.g. active joints outside the workspace), and, for
    /// `r > n_p`, active joints inconsistent with the constraints.
    pub fn solve_passive(
        &self,
        active: &Col<f64>,
        passive_guess: &Col<f64>,
    ) -> Result<Col<f64>, ClosedChainError> {
        if active.nrows() != self.active.len() {
            return Err(ClosedChainError::Dimension {
                what: "active joints θ_a".into(),
                expected: self.active.len(),
                got: active.nrows(),
            });
        }
        if passive_guess.nrows() != self.passive.len() {
            return Err(ClosedChainError::Dimension {
                what: "passive guess θ_p".into(),
                expected: self.passive.len(),
                got: passive_guess.nrows(),
            });
        }
        let mut theta = self.join(active, passive_guess);
        self.check_theta(&theta)?;
        let mut res = self.structural(&theta).norm_l2();
        for _ in 0..100 {
            if res < 1e-13 {
                return Ok(self.split(&theta).1);
            }
            let d = self.differential(&theta)?;
            let smin = linalg::sigma_min(d.j_cp.as_ref());
            if linalg::rank(d.j_cp.as_ref()) < self.passive.len() {
                return Err(ClosedChainError::Singular {
                    kind: SingularityKind::Parallel,
                    what: "J_Cp while solving the structural equations".into(),
                    sigma_min: smin,
                });
            }
            let c = self.structural(&theta);
            let step = -(not_finite(linalg::pseudo_inverse(d.j_cp.as_ref()), "J_Cp")? * &c);
            // Damped Newton: halve the step until the residual decreases.
            let mut t = 1.0;
            let mut accepted = false;
            for _ in 0..30 {
                let mut trial = theta.clone();
                for (k, &i) in self.passive.iter().enumerate() {
                    trial[i] += t * step[k];
                }
                let r = self.structural(&trial).norm_l2();
                if r.is_finite() && r < res {
                    theta = trial;
                    res = r;
                    accepted = true;
                    break;
                }
                t *= 0.5;
            }
            if !accepted {
                break;
            }
        }
        if res < 1e-10 {
            return Ok(self.split(&theta).1);
        }
        Err(ClosedChainError::NoConvergence {
            what: "structural equations c(θ_a, θ_p) = 0 (active joints may be outside the workspace or inconsistent)".into(),
            residual: res,
        })
    }

    /// Assembles a configuration: Gauss–Newton with minimum-norm steps on all joints for
    /// `c(θ) = 0` and, when given, `task(θ) = target`, starting from `guess`.
    pub fn assemble(
        &self,
        guess: &Col<f64>,
        target: Option<&Col<f64>>,
    ) -> Result<Col<f64>, ClosedChainError> {
        self.check_theta(guess)?;
        if let Some(t) = target {
            if t.nrows() != self.outputs.len() {
                return Err(ClosedChainError::Dimension {
                    what: "task target".into(),
                    expected: self.outputs.len(),
                    got: t.nrows(),
                });
            }
        }
        let resid = |th: &Col<f64>| -> Col<f64> {
            let c = self.structural(th);
            match target {
                None => c,
                Some(t) => {
                    let e = self.task(th) - t;
                    Col::from_fn(c.nrows() + e.nrows(), |k| {
                        if k < c.nrows() {
                            c[k]
                        } else {
                            e[k - c.nrows()]
                        }
                    })
                }
            }
        };
        let mut theta = guess.clone();
        let mut r = resid(&theta);
        for _ in 0..200 {
            let rn = r.norm_l2();
            if rn < 1e-13 {
                return Ok(theta);
            }
            let d = self.differential(&theta)?;
            let jm = match target {
                None => d.j_c.clone(),
                Some(_) => stack_rows(d.j_c.as_ref(), d.j_a.as_ref()),
            };
            let step =
                -(not_finite(linalg::pseudo_inverse(jm.as_ref()), "the assembly Jacobian")? * &r);
            let mut t = 1.0;
            let mut accepted = false;
            for _ in 0..30 {
                let trial = &theta + faer::Scale(t) * &step;
                let rt = resid(&trial);
                if rt.norm_l2().is_finite() && rt.norm_l2() < rn {
                    theta = trial;
                    r = rt;
                    accepted = true;
                    break;
                }
                t *= 0.5;
            }
            if !accepted {
                break;
            }
        }
        if r.norm_l2() < 1e-10 {
            return Ok(theta);
        }
        Err(ClosedChainError::NoConvergence {
            what: "assembly of the mechanism (structural equations and task target)".into(),
            residual: r.norm_l2(),
        })
    }

    /// Singularity classification (§4.5): parallel (actuator) when `rank(J_Cp) < n_p`, serial
    /// (end-effector) when the feasible task velocities lose dimension
    /// (`rank([J_C; J_A]) − rank(J_C) < m_x`, i.e. `rank J < m_x` for (8)), structural when both.
    pub fn classify(&self, theta: &Col<f64>) -> Result<SingularityReport, ClosedChainError> {
        let d = self.differential(theta)?;
        let rank_j_cp = linalg::rank(d.j_cp.as_ref());
        let stacked = stack_rows(d.j_c.as_ref(), d.j_a.as_ref());
        let task_rank = linalg::rank(stacked.as_ref()).saturating_sub(linalg::rank(d.j_c.as_ref()));
        let parallel = rank_j_cp < self.passive.len();
        let serial = task_rank < self.outputs.len();
        let kind = match (serial, parallel) {
            (false, false) => None,
            (true, false) => Some(SingularityKind::Serial),
            (false, true) => Some(SingularityKind::Parallel),
            (true, true) => Some(SingularityKind::Structural),
        };
        Ok(SingularityReport {
            rank_j_cp,
            n_passive: self.passive.len(),
            sigma_min_j_cp: linalg::sigma_min(d.j_cp.as_ref()),
            task_rank,
            task_dim: self.outputs.len(),
            kind,
        })
    }

    /// The SVD analysis of §5.4 applied to the reduced Jacobian `J` of (8) at `θ`.
    pub fn svd_analysis(&self, theta: &Col<f64>) -> Result<linalg::SvdAnalysis, ClosedChainError> {
        Ok(linalg::svd_analysis(self.reduced(theta)?.jacobian.as_ref()))
    }

    /// Points along the structure (joint frames and the common frame of every chain), as
    /// polylines, for obstacle distances and drawings.
    pub fn polylines(&self, theta: &Col<f64>) -> Vec<Vec<[f64; 2]>> {
        (0..self.chains.len())
            .map(|k| {
                let r = self.chain_range(k);
                let (frames, end) = self.chain_frames(k, &as_slice(theta)[r]);
                let mut pts = vec![[self.chains[k].base.x, self.chains[k].base.y]];
                pts.extend(frames.iter().map(|f| [f.x, f.y]));
                pts.push([end.x, end.y]);
                pts
            })
            .collect()
    }
}

/// The reduced kinematics from the Jacobian blocks ((7), (8)); see [`Mechanism::reduced`].
pub fn reduce(d: &Differential) -> Result<Reduced, ClosedChainError> {
    let n_p = d.j_cp.ncols();
    let r = d.j_cp.nrows();
    let rank_cp = linalg::rank(d.j_cp.as_ref());
    if rank_cp < n_p {
        return Err(ClosedChainError::Singular {
            kind: SingularityKind::Parallel,
            what: "J_Cp (passive joints move with the active joints locked)".into(),
            sigma_min: linalg::sigma_min(d.j_cp.as_ref()),
        });
    }
    let j_cp_inverse = if n_p == r {
        linalg::inverse(d.j_cp.as_ref()).ok_or(ClosedChainError::Singular {
            kind: SingularityKind::Parallel,
            what: "J_Cp".into(),
            sigma_min: 0.0,
        })?
    } else {
        not_finite(linalg::pseudo_inverse(d.j_cp.as_ref()), "J_Cp")?
    };
    let passive_map = -(&j_cp_inverse * &d.j_ca);
    let jacobian = &d.j_aa + &d.j_ap * &passive_map;
    let complement = if n_p == r {
        Mat::zeros(r, 0)
    } else if n_p == 0 {
        Mat::identity(r, r)
    } else {
        linalg::null_space(d.j_cp.transpose())
    };
    let active_constraint = complement.transpose() * &d.j_ca;
    for (m, what) in [
        (&jacobian, "reduced Jacobian J"),
        (&passive_map, "passive map −J_Cp⁻¹J_Ca"),
    ] {
        if !linalg::all_finite(m.as_ref()) {
            return Err(ClosedChainError::NonFinite { what: what.into() });
        }
    }
    Ok(Reduced {
        jacobian,
        passive_map,
        j_cp_inverse,
        complement,
        active_constraint,
    })
}

/// `J_C = Ã J` and `J_A = A† J` for any stacked `J` and full-column-rank `A` ((19), (31), (41)),
/// with `Ã` from [`linalg::annihilator`] (orthonormal rows). Returns `(J_C, J_A)`.
pub fn constraint_and_analytic(
    j: &Mat<f64>,
    a: &Mat<f64>,
) -> Result<(Mat<f64>, Mat<f64>), ClosedChainError> {
    if j.nrows() != a.nrows() {
        return Err(ClosedChainError::Dimension {
            what: "rows of A (must match the stacked Jacobian J)".into(),
            expected: j.nrows(),
            got: a.nrows(),
        });
    }
    let a_dag = linalg::left_pseudo_inverse(a.as_ref())
        .ok_or_else(|| ClosedChainError::invalid("A", "A must have full column rank (A† A = I)"))?;
    let at = linalg::annihilator(a.as_ref());
    Ok((at * j, a_dag * j))
}

/// Splits `(J_C, J_A)` by active/passive columns and reduces them ((5)–(8)).
pub fn reduce_blocks(
    j_c: &Mat<f64>,
    j_a: &Mat<f64>,
    active: &[usize],
    passive: &[usize],
) -> Result<Reduced, ClosedChainError> {
    let d = Differential {
        j: Mat::zeros(0, 0),
        a: Mat::zeros(0, 0),
        j_ca: select_columns(j_c.as_ref(), active),
        j_cp: select_columns(j_c.as_ref(), passive),
        j_aa: select_columns(j_a.as_ref(), active),
        j_ap: select_columns(j_a.as_ref(), passive),
        j_c: j_c.clone(),
        j_a: j_a.clone(),
    };
    reduce(&d)
}

/// A pseudo-inverse, or the error that the matrix it was asked of is not finite (its SVD did not
/// converge).
fn not_finite(pinv: Option<Mat<f64>>, what: &str) -> Result<Mat<f64>, ClosedChainError> {
    pinv.ok_or_else(|| ClosedChainError::NonFinite { what: what.into() })
}
