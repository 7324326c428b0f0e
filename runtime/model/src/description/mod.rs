//! Robot descriptions, shared by the generator and the runtime.
//!
//! A description is link by link, URDF-style (`docs/reference-robots.md`, conventions): each joint has a fixed origin from its
//! parent frame, an axis in its own frame and a type, or a raw twist `(v, ω)`. Link frame `k` is
//! joint `k`'s frame. Lengths may be numbers or **named parameters** (linear combinations such as
//! `"l_a + l_b"`), which stay symbolic in generated code and become runtime inputs.
//!
//! Descriptions are read from TOML ([`RobotDescription::from_toml_str`],
//! [`RobotDescription::from_toml_file`], [`RobotDescription::preset`]) or imported from URDF
//! ([`RobotDescription::from_urdf_file`], [`RobotDescription::from_urdf_str`]), and written back
//! with [`RobotDescription::to_toml_string`]. Every error is a [`DescriptionError`] naming file,
//! line, column and field (`` robot.toml:61:1: field `joints[7].axis`: ... ``); field paths follow the
//! TOML (`constraint.h[1]`, `parameters.l_a`, `end_effector.xyz[1]`; joint indices 0-based).
//!
//! Reading validates (see [`validate`](RobotDescription::validate) for the rules: unit axes,
//! rotations, declared parameters, unique names, `H` of full rank with at most 5 rows, the
//! constrained link, `n − r ≥ 6`, wrist presets consistent with `H`, `g_ir` and the wrist joints).
//!
//! ```
//! use trocar_model::description::RobotDescription;
//!
//! let d = RobotDescription::preset("bidirectional-zy").unwrap();
//! assert_eq!(d.joints.len(), 8);
//! let text = d.to_toml_string();
//! let bad = text.replace("h = [\"x\", \"z\"]", "h = [\"x\", \"x\"]");
//! let e = RobotDescription::from_toml_str(&bad, None).unwrap_err();
//! assert_eq!(e.field, "constraint.h[1]");
//! assert!(e.line.is_some());
//! ```

mod error;
pub(crate) mod locate;
pub(crate) mod parse;
mod presets;
mod serialize;
mod simulation;
mod urdf;
mod validate;

pub use crate::expr::Linear;

/// The most joints a robot (a serial description, its URDF chain included) or a closed
/// mechanism (all chains together) may have: 64. A larger one is refused where it is written.
pub const MAX_JOINTS: usize = 64;
pub use error::{DescriptionError, MAX_FILE_BYTES};
pub use presets::{preset, preset_names, PRESETS};
pub use simulation::{SimulationDesc, SIMULATION_METHODS};
pub use trocar::constraint::NullSpaceBasis;
pub use validate::{
    admission_problems, admission_rank_problem, admit, shaft_not_toward_tip, trocar_beyond_tip,
    AdmissionError, RANK_CONFIGURATIONS,
};

impl RobotDescription {
    /// The number `t` of task rows: those of the `[task]` selection, or 6 (the whole twist).
    pub fn task_rows(&self) -> usize {
        self.task.as_ref().map_or(6, |t| t.select.len())
    }
}

/// Orientation of a frame relative to its parent.
#[derive(Clone, Debug, PartialEq)]
pub enum Rotation {
    /// Roll, pitch, yaw about fixed x, y, z (URDF convention: `R = Rz(yaw) Ry(pitch) Rx(roll)`).
    Rpy([f64; 3]),
    /// A rotation matrix, row-major.
    Matrix([[f64; 3]; 3]),
}

/// A fixed transform from a parent frame: translation `xyz` and a rotation.
#[derive(Clone, Debug, PartialEq)]
pub struct Origin {
    /// Translation; components may be parameters.
    pub xyz: [Linear; 3],
    /// Rotation.
    pub rotation: Rotation,
}

/// What a joint does in its own frame.
#[derive(Clone, Debug, PartialEq)]
pub enum JointKind {
    /// Rotation about `axis` (unit) through the joint frame's origin: `ξ = (0, axis)`.
    Revolute {
        /// Unit axis in the joint frame.
        axis: [f64; 3],
    },
    /// Translation along `axis` (unit): `ξ = (axis, 0)`.
    Prismatic {
        /// Unit axis in the joint frame.
        axis: [f64; 3],
    },
    /// A raw twist `ξ = (v, ω)` in the joint frame: `‖ω‖ = 1`, or `ω = 0` and `‖v‖ = 1`.
    Twist {
        /// Linear part; components may be parameters (e.g. `v = −ω × q` with `q` a parameter).
        v: [Linear; 3],
        /// Angular part.
        w: [f64; 3],
    },
}

/// Where an item was written: 1-based line and column in its source file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Location {
    /// 1-based line.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
}

/// One joint (and the link frame it carries).
#[derive(Clone, Debug, PartialEq)]
pub struct JointDesc {
    /// Unique name.
    pub name: String,
    /// Fixed transform from the parent frame (the previous joint's frame, or the base).
    pub origin: Origin,
    /// Type and axis or twist.
    pub kind: JointKind,
    /// Lower and upper limit of `q` (rad or m), when known (`limits = [lo, hi]` in TOML, the
    /// `<limit>` of a URDF joint); the simulation keeps the joints inside them.
    pub limits: Option<[f64; 2]>,
    /// The joint's speed limit `|q̇| ≤ v` (rad/s or m/s), when known: `speed_limit = v` in TOML,
    /// the `velocity` of a URDF joint's `<limit>`; the QP control step keeps it.
    pub speed_limit: Option<f64>,
    /// The joint's acceleration limit `|q̈| ≤ a` (rad/s² or m/s²), when known:
    /// `acceleration_limit = a` in TOML, the `acceleration` of a URDF 1.2 joint's `<limit>`; the
    /// control step keeps its commands' changes within it.
    pub acceleration_limit: Option<f64>,
    /// The joint's jerk limit `|q⃛| ≤ j` (rad/s³ or m/s³), when known: `jerk_limit = j` in TOML,
    /// the `jerk` of a URDF 1.2 joint's `<limit>`.
    pub jerk_limit: Option<f64>,
    /// What a physics plant needs of the joint and of the link it moves (effort limit,
    /// damping, friction, mass properties); empty for a purely kinematic description.
    pub dynamics: JointDynamics,
    /// Where the joint was written (its `[[joints]]` header, or its `<joint>` element in a URDF),
    /// when read from text; [`RobotDescription::validate`] uses it for joint errors.
    pub location: Option<Location>,
}

/// The mass properties of a rigid body: its mass, its centre of mass and its inertia tensor
/// about the centre of mass, both in the frame of the link the body is fixed in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inertia {
    /// Mass (kg).
    pub mass: f64,
    /// Centre of mass in the link's frame (m).
    pub com: [f64; 3],
    /// Inertia tensor about the centre of mass, in the axes of the link's frame (kg m²):
    /// `[ixx, iyy, izz, ixy, ixz, iyz]`.
    pub inertia: [f64; 6],
}

impl Inertia {
    /// The tensor as a symmetric 3 × 3 matrix (row-major).
    pub fn matrix(&self) -> [[f64; 3]; 3] {
        let [xx, yy, zz, xy, xz, yz] = self.inertia;
        [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]
    }

    /// The same body seen from a frame in which the link's frame sits at rotation `r` (row-major)
    /// and translation `p`: centre of mass `p + R c`, tensor `R I Rᵀ`.
    pub fn transformed(&self, r: &[[f64; 3]; 3], p: &[f64; 3]) -> Inertia {
        let i = self.matrix();
        let com = [0, 1, 2].map(|a| p[a] + (0..3).map(|k| r[a][k] * self.com[k]).sum::<f64>());
        let ri: [[f64; 3]; 3] =
            [0, 1, 2].map(|a| [0, 1, 2].map(|b| (0..3).map(|k| r[a][k] * i[k][b]).sum()));
        let m: [[f64; 3]; 3] =
            [0, 1, 2].map(|a| [0, 1, 2].map(|b| (0..3).map(|k| ri[a][k] * r[b][k]).sum()));
        Inertia {
            mass: self.mass,
            com,
            inertia: [m[0][0], m[1][1], m[2][2], m[0][1], m[0][2], m[1][2]],
        }
    }

    /// Two bodies in the same frame as one (masses added, the tensors moved to the common centre
    /// of mass by the parallel-axis theorem). Massless bodies add nothing.
    pub fn combined(&self, other: &Inertia) -> Inertia {
        if other.mass <= 0.0 {
            return *self;
        }
        if self.mass <= 0.0 {
            return *other;
        }
        let mass = self.mass + other.mass;
        let com = [0, 1, 2].map(|a| (self.mass * self.com[a] + other.mass * other.com[a]) / mass);
        let mut out = [0.0; 6];
        for body in [self, other] {
            let d = [0, 1, 2].map(|a| body.com[a] - com[a]);
            let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            let shift = [
                dd - d[0] * d[0],
                dd - d[1] * d[1],
                dd - d[2] * d[2],
                -d[0] * d[1],
                -d[0] * d[2],
                -d[1] * d[2],
            ];
            for k in 0..6 {
                out[k] += body.inertia[k] + body.mass * shift[k];
            }
        }
        Inertia {
            mass,
            com,
            inertia: out,
        }
    }
}

/// What a physics plant needs of a joint beyond its kinematics: its torque (force) limit, its
/// viscous damping and dry friction, and the mass properties of the link it moves (every link
/// that fixed joints attach to it folded in). Every entry is `None` where the description does
/// not give it.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct JointDynamics {
    /// Torque (N m) or force (N) limit: `effort_limit` in TOML, a URDF `<limit effort>`.
    pub effort_limit: Option<f64>,
    /// Viscous damping (N m s/rad): `damping` in TOML, a URDF `<dynamics damping>`.
    pub damping: Option<f64>,
    /// Dry (Coulomb) friction (N m): `friction` in TOML, a URDF `<dynamics friction>`.
    pub friction: Option<f64>,
    /// Mass properties of the link the joint moves, in the joint's frame: `mass`, `com` and
    /// `inertia = [ixx, iyy, izz, ixy, ixz, iyz]` in TOML, the URDF `<inertial>` of the link
    /// and of every link fixed to it on the path to the tip.
    pub inertia: Option<Inertia>,
}

/// The instrument the robot holds: a straight rigid shaft from the tip link's frame to the end
/// effector's, for a physics plant (`[instrument]` in TOML).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instrument {
    /// The shaft's mass (kg), spread evenly along it.
    pub mass: f64,
    /// The shaft's radius (m).
    pub radius: f64,
}

/// The end-effector frame `F_e`, fixed in the last link.
#[derive(Clone, Debug, PartialEq)]
pub struct EndEffector {
    /// Name of the frame.
    pub name: String,
    /// Transform from the last joint's frame to `F_e`.
    pub origin: Origin,
}

/// The thesis's wrist presets, which fix the null-space basis `Λ#` to (3.23) or (3.27).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrist {
    /// `H = x_r`, basis (3.23); J^r is (3.24).
    Unidirectional,
    /// `H = (x_r, z_r)`, last joints about z then y, basis (3.27); J^r is (3.28).
    Zy,
    /// `H = (x_r, z_r)`, last joints about z then x, basis (3.27); J^r is (3.29).
    Zx,
}

impl Wrist {
    /// The null-space basis `Λ#` this preset selects: (3.23) for `unidirectional`, (3.27) for
    /// `zy` and `zx` (which differ in `J^r`: (3.28), (3.29)).
    pub const fn basis(self) -> NullSpaceBasis {
        match self {
            Wrist::Unidirectional => NullSpaceBasis::Unidirectional,
            Wrist::Zy | Wrist::Zx => NullSpaceBasis::Bidirectional,
        }
    }
}

impl ConstraintDesc {
    /// Which basis of `null(Λ)` this constraint uses for `Λ#` — the one rule every consumer
    /// (validation, the generator's derivation, the numeric robot) follows: the wrist preset's
    /// thesis basis ([`Wrist::basis`]) when one is given, otherwise
    /// [`NullSpaceBasis::Computed`]. Whether the thesis basis fits `H` and `g_ir` is checked by
    /// validation (and again by whoever builds `Λ#`): see [`NullSpaceBasis::fits_rows`].
    pub const fn basis(&self) -> NullSpaceBasis {
        match self.wrist {
            Some(w) => w.basis(),
            None => NullSpaceBasis::Computed,
        }
    }
}

/// The constraint `H V^B_0r = 0` at the frame `F_r` fixed in link `i` (3.1).
#[derive(Clone, Debug, PartialEq)]
pub struct ConstraintDesc {
    /// The constrained link `i`, 1-based (link `i` is joint `i`'s frame, carried by joint `i`);
    /// valid descriptions have `1 ≤ i ≤ n` (`i = n`: the constraint is on the last link, no joint
    /// after it, and `J^r_0e = Ad_{g_ei} Λ#`).
    pub link: usize,
    /// `g_ir`: the constraint frame relative to `F_i`; the thesis takes `(I, (0, l_a, 0))`.
    pub origin: Origin,
    /// Rows of `H ∈ R^{r×6}` (twist order `(v, ω)`); valid descriptions have `1 ≤ r ≤ 5`
    /// independent rows and `n − r ≥ t` (`t` task rows, see [`RobotDescription::task_rows`]).
    pub h: Vec<[f64; 6]>,
    /// Wrist preset: when given, `Λ#` is the thesis's basis; otherwise a derived basis (see
    /// [`ConstraintDesc::basis`]).
    pub wrist: Option<Wrist>,
}

/// The task: which rows of the end-effector twist the task commands, `S ∈ R^{t×6}`; the task
/// Jacobian is `S J^r_0e`.
///
/// `J^r_0e` maps to the body twist `V^B_0e = (v, ω)` of the end-effector frame `F_e`, so the rows
/// select components **in `F_e`**: `"x"` is the tip's velocity along `x_e`, `"rz"` the rotation
/// rate about `z_e` (the roll about a shaft that runs along `z_e`).
#[derive(Clone, Debug, PartialEq)]
pub struct TaskDesc {
    /// Rows of `S` (twist order `(v, ω)`), 1 to 6, linearly independent.
    pub select: Vec<[f64; 6]>,
}

/// A named parameter and its nominal value (used by numeric evaluation unless overridden).
#[derive(Clone, Debug, PartialEq)]
pub struct Parameter {
    /// Name, a Rust identifier.
    pub name: String,
    /// Nominal value.
    pub value: f64,
}

/// A serial manipulator with an optional point constraint.
#[derive(Clone, Debug, PartialEq)]
pub struct RobotDescription {
    /// Robot name (a Rust identifier once snake-cased; used for generated module names).
    pub name: String,
    /// Named parameters, in declaration order.
    pub parameters: Vec<Parameter>,
    /// Joints, base first.
    pub joints: Vec<JointDesc>,
    /// End-effector frame.
    pub end_effector: EndEffector,
    /// The RCM constraint, if any.
    pub constraint: Option<ConstraintDesc>,
    /// The task selection, if any (default: all six rows of the twist).
    pub task: Option<TaskDesc>,
    /// The instrument's mass and radius, if given (`[instrument]`; used by a physics plant).
    pub instrument: Option<Instrument>,
    /// The file the description was read from, if any (for error messages).
    pub source: Option<std::path::PathBuf>,
}
