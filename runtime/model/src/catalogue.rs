//! The catalogue of emitted functions: every function trocar-codegen writes into a generated
//! module, with its Rust name, the equation it implements, the shape of its result and what it
//! computes.
//!
//! The generator names the functions it emits from here, its evaluator finds them from here, the
//! command line maps `trocar eval --what` onto them and the numeric verification
//! (`trocar_check::verify`) asks a `Candidate` for them by [`Function`]: renaming a
//! function is one edit here, and removing one is a compile error wherever it is used.
//!
//! Serial robots (thesis numbering) get [`Function::SERIAL`]; those without a constraint only
//! [`Function::ForwardKinematics`] and [`Function::BodyJacobian`]. Closed planar mechanisms
//! (numbering of Freitas, Leite & Lizarralde, CBA 2010) get [`Function::MECHANISM`].
//!
//! Every generated function `f` also has a variant `f_trig` ([`Function::trig_name`]) taking the
//! joints' sines and cosines instead of `q`. Matrices are returned column-major.

use std::fmt;

/// A size of a generated module, emitted as a `usize` constant of that module.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Size {
    /// `N`: number of joints `n` (length of `q`).
    N,
    /// `I`: the constrained link `i` (1-based) of a serial robot.
    I,
    /// `R`: rows of `H` (constrained directions, serial robots) or structural equations
    /// `3(m − 1)` (mechanisms).
    R,
    /// `M`: columns of `J^r_0e`, `m = 6 − r + n − i` (3.15).
    M,
    /// `K`: columns of `Λ#`, `6 − r` (3.6).
    K,
    /// `TASK_ROWS`: rows of the task selection `S` (a `[task]` section).
    TaskRows,
    /// `N_ACTIVE`: active joints `n_a` of a mechanism.
    NActive,
    /// `N_PASSIVE`: passive joints `n_p` of a mechanism.
    NPassive,
    /// `N_OUTPUTS`: task outputs `m_x` of a mechanism.
    NOutputs,
}

impl Size {
    /// The name of the module constant, e.g. `N_ACTIVE`.
    pub const fn const_name(self) -> &'static str {
        match self {
            Size::N => "N",
            Size::I => "I",
            Size::R => "R",
            Size::M => "M",
            Size::K => "K",
            Size::TaskRows => "TASK_ROWS",
            Size::NActive => "N_ACTIVE",
            Size::NPassive => "N_PASSIVE",
            Size::NOutputs => "N_OUTPUTS",
        }
    }
}

/// One dimension of a result: a number or an expression of the module's sizes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Dim {
    /// A fixed number (`6` rows of a twist).
    Fixed(usize),
    /// A size of the module.
    Size(Size),
    /// `1 + size` (a row holding `det J_Cp` above the numerator rows).
    OnePlus(Size),
}

impl Dim {
    /// The value for a module whose sizes are given by `size`.
    pub fn value(self, size: impl Fn(Size) -> usize) -> usize {
        match self {
            Dim::Fixed(k) => k,
            Dim::Size(s) => size(s),
            Dim::OnePlus(s) => 1 + size(s),
        }
    }
}

/// As written in a generated signature: `6`, `N`, `1 + N_OUTPUTS`.
impl fmt::Display for Dim {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Dim::Fixed(k) => write!(f, "{k}"),
            Dim::Size(s) => f.write_str(s.const_name()),
            Dim::OnePlus(s) => write!(f, "1 + {}", s.const_name()),
        }
    }
}

/// What a generated function returns.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Shape {
    /// One scalar.
    Scalar,
    /// A vector `[T; len]`.
    Vector(Dim),
    /// A `rows × cols` matrix, column-major `[[T; rows]; cols]`.
    Matrix {
        /// Rows.
        rows: Dim,
        /// Columns.
        cols: Dim,
    },
    /// A rigid transform `(R, p)` as `([[T; 3]; 3], [T; 3])`, `R` column-major; evaluated
    /// numerically as a 4 × 4 homogeneous matrix.
    Transform,
}

/// Whose equation numbers a function cites.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Source {
    /// The thesis (serial robots).
    Thesis,
    /// G. M. Freitas, A. C. Leite, F. Lizarralde, *Controle de sistemas robóticos com restrições
    /// cinemáticas*, CBA 2010 (closed mechanisms).
    FreitasLeiteLizarralde2010,
}

impl Source {
    /// How generated documentation cites it after an equation number (empty for the thesis).
    pub const fn citation(self) -> &'static str {
        match self {
            Source::Thesis => "",
            Source::FreitasLeiteLizarralde2010 => "of Freitas, Leite & Lizarralde (2010)",
        }
    }
}

/// A function of a generated module.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Function {
    /// `forward_kinematics`: `g_0e(q)` of the end effector (2.21).
    ForwardKinematics,
    /// `body_jacobian`: `J^B_0e(q)`, 6 × N (2.53)–(2.55).
    BodyJacobian,
    /// `constrained_jacobian`: `J^r_0e = [Ad_{g_ei} Λ# | J^B_0e2]`, 6 × M (3.15).
    ConstrainedJacobian,
    /// `constraint_jacobian_c`: `J_c = Ad_{g_ei} Λ†`, 6 × R (3.33).
    ConstraintJacobianC,
    /// `partial_body_jacobian`: `J^B_0i(q_1..q_i)`, 6 × I (3.13).
    PartialBodyJacobian,
    /// `forward_kinematics_i`: `g_0i(q_1..q_i)` of the constrained link's frame (2.21).
    ConstrainedLinkKinematics,
    /// `manipulability`: `w = sqrt(det(J^r J^rᵀ))` (3.36)–(3.39); with a `[task]`, that of
    /// `S J^r_0e`.
    Manipulability,
    /// `manipulability_squared`: `w² = det(J^r J^rᵀ)` (3.36); with a `[task]`, that of `S J^r_0e`.
    ManipulabilitySquared,
    /// `constraint_selection`: `H`, R × 6 (3.1); depends on no joint.
    ConstraintSelection,
    /// `lambda_null_space`: the null-space basis `Λ#` of `Λ = H Ad_{g_ri}`, 6 × K (3.6),
    /// (3.23)/(3.27) for the thesis's wrists; depends only on the parameters.
    LambdaNullSpace,
    /// `lambda_pinv`: `Λ† = Λᵀ (Λ Λᵀ)⁻¹`, 6 × R (3.31); depends only on the parameters.
    LambdaPinv,
    /// `constraint_frame`: `g_ir`, the constraint frame `F_r` in the constrained link's frame
    /// (3.3); depends only on the parameters.
    ConstraintFrame,
    /// `task_selection`: the task's selection `S`, TASK_ROWS × 6, rows of the end-effector body
    /// twist (components in `F_e`); only with a `[task]`; depends on no joint.
    TaskSelection,
    /// `constrained_task_jacobian`: `S J^r_0e`, TASK_ROWS × M, what the task commands; only with a
    /// `[task]`.
    ConstrainedTaskJacobian,
    /// `constraint_jacobian` (mechanisms): `J_C = ∂c/∂θ`, R × N (3), (19), (31).
    ConstraintJacobian,
    /// `task_jacobian` (mechanisms): `J_A = S_x A† J`, N_OUTPUTS × N (4), (19), (31).
    TaskJacobian,
    /// `constraint_determinant` (mechanisms): `det J_Cp` (7).
    ConstraintDeterminant,
    /// `reduced_jacobian_numerator` (mechanisms): `det J_Cp` above `det(J_Cp) · J`,
    /// (1 + N_OUTPUTS) × N_ACTIVE (8).
    ReducedJacobianNumerator,
    /// `passive_map_numerator` (mechanisms): `det J_Cp` above `−adj(J_Cp) J_Ca`,
    /// (1 + N_PASSIVE) × N_ACTIVE (7).
    PassiveMapNumerator,
    /// `reduced_jacobian` (mechanisms): `J = J_Aa − J_Ap J_Cp⁻¹ J_Ca`, N_OUTPUTS × N_ACTIVE, `None`
    /// at a parallel singularity (8).
    ReducedJacobian,
    /// `passive_map` (mechanisms): `−J_Cp⁻¹ J_Ca`, N_PASSIVE × N_ACTIVE, `None` at a parallel
    /// singularity (7).
    PassiveMap,
    /// `passive_velocities` (mechanisms): `θ̇_p = −J_Cp⁻¹ J_Ca θ̇_a`, `None` at a parallel
    /// singularity (7).
    PassiveVelocities,
}

use Dim::{Fixed, OnePlus};
use Size::{NActive, NOutputs, NPassive, TaskRows, I, K, M, N, R};

impl Function {
    /// The functions of a serial robot's module, in emission order (all but the first two only
    /// with a constraint, the last two only with a task).
    pub const SERIAL: [Function; 14] = [
        Function::ForwardKinematics,
        Function::BodyJacobian,
        Function::ConstrainedJacobian,
        Function::ConstraintJacobianC,
        Function::PartialBodyJacobian,
        Function::ConstrainedLinkKinematics,
        Function::Manipulability,
        Function::ManipulabilitySquared,
        Function::ConstraintSelection,
        Function::LambdaNullSpace,
        Function::LambdaPinv,
        Function::ConstraintFrame,
        Function::TaskSelection,
        Function::ConstrainedTaskJacobian,
    ];

    /// The functions of a closed mechanism's module, in emission order: the polynomial ones, then
    /// the ones that divide by `det J_Cp`.
    pub const MECHANISM: [Function; 8] = [
        Function::ConstraintJacobian,
        Function::TaskJacobian,
        Function::ConstraintDeterminant,
        Function::ReducedJacobianNumerator,
        Function::PassiveMapNumerator,
        Function::ReducedJacobian,
        Function::PassiveMap,
        Function::PassiveVelocities,
    ];

    /// The Rust name of the generated function.
    pub const fn name(self) -> &'static str {
        match self {
            Function::ForwardKinematics => "forward_kinematics",
            Function::BodyJacobian => "body_jacobian",
            Function::ConstrainedJacobian => "constrained_jacobian",
            Function::ConstraintJacobianC => "constraint_jacobian_c",
            Function::PartialBodyJacobian => "partial_body_jacobian",
            Function::ConstrainedLinkKinematics => "forward_kinematics_i",
            Function::Manipulability => "manipulability",
            Function::ManipulabilitySquared => "manipulability_squared",
            Function::ConstraintSelection => "constraint_selection",
            Function::LambdaNullSpace => "lambda_null_space",
            Function::LambdaPinv => "lambda_pinv",
            Function::ConstraintFrame => "constraint_frame",
            Function::TaskSelection => "task_selection",
            Function::ConstrainedTaskJacobian => "constrained_task_jacobian",
            Function::ConstraintJacobian => "constraint_jacobian",
            Function::TaskJacobian => "task_jacobian",
            Function::ConstraintDeterminant => "constraint_determinant",
            Function::ReducedJacobianNumerator => "reduced_jacobian_numerator",
            Function::PassiveMapNumerator => "passive_map_numerator",
            Function::ReducedJacobian => "reduced_jacobian",
            Function::PassiveMap => "passive_map",
            Function::PassiveVelocities => "passive_velocities",
        }
    }

    /// The Rust name of the variant taking the joints' sines and cosines (`JointTrig`).
    pub fn trig_name(self) -> String {
        format!("{}_trig", self.name())
    }

    /// The function called `name` (the Rust name, without `_trig`), if there is one.
    pub fn from_name(name: &str) -> Option<Function> {
        Function::SERIAL
            .into_iter()
            .chain(Function::MECHANISM)
            .find(|f| f.name() == name)
    }

    /// The function of a serial robot (`mechanism` false) or of a closed mechanism that `name`
    /// names: its Rust name (`constrained_jacobian`) or its short name (`jr`,
    /// [`Function::short_name`]), the names `trocar eval --what` and Python's `what=` take. The
    /// short names `jr` and `jc` name `J^r_0e` and `J_c` of a serial robot, the reduced Jacobian
    /// and `J_C` of a mechanism.
    pub fn resolve(name: &str, mechanism: bool) -> Option<Function> {
        let list: &[Function] = if mechanism {
            &Function::MECHANISM
        } else {
            &Function::SERIAL
        };
        list.iter()
            .copied()
            .find(|f| f.name() == name || f.short_name() == name)
    }

    /// The short name of the quantity (`trocar eval --what`, the lines of a verification report):
    /// `jr`, `jc`, `jb0i`, `jb0e`, `fk`, `fk0i`, `manip`, `manip2`, `h`, `lambda_sharp`,
    /// `lambda_pinv`, `gir`, `s`, `task`; for mechanisms `jc`, `ja`,
    /// `det`, `jr_num`, `passive_num`, `jr`, `passive`, `passive_vel`.
    pub const fn short_name(self) -> &'static str {
        match self {
            Function::ForwardKinematics => "fk",
            Function::BodyJacobian => "jb0e",
            Function::ConstrainedJacobian => "jr",
            Function::ConstraintJacobianC => "jc",
            Function::PartialBodyJacobian => "jb0i",
            Function::ConstrainedLinkKinematics => "fk0i",
            Function::Manipulability => "manip",
            Function::ManipulabilitySquared => "manip2",
            Function::ConstraintSelection => "h",
            Function::LambdaNullSpace => "lambda_sharp",
            Function::LambdaPinv => "lambda_pinv",
            Function::ConstraintFrame => "constraint_frame",
            Function::TaskSelection => "s",
            Function::ConstrainedTaskJacobian => "task",
            Function::ConstraintJacobian => "jc",
            Function::TaskJacobian => "ja",
            Function::ConstraintDeterminant => "det",
            Function::ReducedJacobianNumerator => "jr_num",
            Function::PassiveMapNumerator => "passive_num",
            Function::ReducedJacobian => "jr",
            Function::PassiveMap => "passive",
            Function::PassiveVelocities => "passive_vel",
        }
    }

    /// The quantity computed, as a formula: `J^r_0e`, `det J_Cp`, ...
    pub const fn quantity(self) -> &'static str {
        match self {
            Function::ForwardKinematics => "g_0e",
            Function::BodyJacobian => "J^B_0e",
            Function::ConstrainedJacobian => "J^r_0e",
            Function::ConstraintJacobianC => "J_c = Ad_{g_ei} Λ†",
            Function::PartialBodyJacobian => "J^B_0i",
            Function::ConstrainedLinkKinematics => "g_0i",
            Function::Manipulability => "w = sqrt(det(J^r J^rᵀ))",
            Function::ManipulabilitySquared => "w² = det(J^r J^rᵀ)",
            Function::ConstraintSelection => "H",
            Function::LambdaNullSpace => "Λ#",
            Function::LambdaPinv => "Λ† = Λᵀ (Λ Λᵀ)⁻¹",
            Function::ConstraintFrame => "g_ir",
            Function::TaskSelection => "S",
            Function::ConstrainedTaskJacobian => "S J^r_0e",
            Function::ConstraintJacobian => "J_C",
            Function::TaskJacobian => "J_A",
            Function::ConstraintDeterminant => "det J_Cp",
            Function::ReducedJacobianNumerator => "det(J_Cp) · J",
            Function::PassiveMapNumerator => "−adj(J_Cp) J_Ca",
            Function::ReducedJacobian => "J = J_Aa − J_Ap J_Cp⁻¹ J_Ca",
            Function::PassiveMap => "−J_Cp⁻¹ J_Ca",
            Function::PassiveVelocities => "θ̇_p = −J_Cp⁻¹ J_Ca θ̇_a",
        }
    }

    /// Whether the function belongs to closed mechanisms (rather than serial robots).
    pub const fn is_mechanism(self) -> bool {
        matches!(self.source(), Source::FreitasLeiteLizarralde2010)
    }

    /// Whose equation numbers [`Function::equation`] gives.
    pub const fn source(self) -> Source {
        match self {
            Function::ForwardKinematics
            | Function::BodyJacobian
            | Function::ConstrainedJacobian
            | Function::ConstraintJacobianC
            | Function::PartialBodyJacobian
            | Function::ConstrainedLinkKinematics
            | Function::Manipulability
            | Function::ManipulabilitySquared
            | Function::ConstraintSelection
            | Function::LambdaNullSpace
            | Function::LambdaPinv
            | Function::ConstraintFrame
            | Function::TaskSelection
            | Function::ConstrainedTaskJacobian => Source::Thesis,
            _ => Source::FreitasLeiteLizarralde2010,
        }
    }

    /// The equation(s) implemented, as cited in the generated documentation, e.g. `(3.15)`.
    pub const fn equation(self) -> &'static str {
        match self {
            Function::ForwardKinematics | Function::ConstrainedLinkKinematics => "(2.21)",
            Function::BodyJacobian => "(2.53)–(2.55)",
            Function::ConstrainedJacobian => "(3.15) (presets: (3.24), (3.28), (3.29))",
            Function::ConstraintJacobianC => "(3.33)",
            Function::PartialBodyJacobian => "(3.13)",
            Function::Manipulability => "(3.36)–(3.39) (presets: (3.40)–(3.42))",
            Function::ManipulabilitySquared => "(3.36)",
            Function::ConstraintSelection => "(3.1)",
            Function::LambdaNullSpace => "(3.6) (presets: (3.23), (3.27))",
            Function::LambdaPinv => "(3.31)",
            Function::ConstraintFrame => "(3.3)",
            Function::TaskSelection | Function::ConstrainedTaskJacobian => "(3.15)",
            Function::ConstraintJacobian => "(3), (19), (31)",
            Function::TaskJacobian => "(4), (19), (31)",
            Function::ConstraintDeterminant => "(7), §4.5",
            Function::ReducedJacobianNumerator | Function::ReducedJacobian => "(8)",
            Function::PassiveMapNumerator | Function::PassiveMap | Function::PassiveVelocities => {
                "(7)"
            }
        }
    }

    /// The shape of the result.
    pub const fn shape(self) -> Shape {
        use Shape::{Matrix, Scalar, Transform, Vector};
        match self {
            Function::ForwardKinematics
            | Function::ConstrainedLinkKinematics
            | Function::ConstraintFrame => Transform,
            Function::BodyJacobian => Matrix {
                rows: Fixed(6),
                cols: Dim::Size(N),
            },
            Function::ConstrainedJacobian => Matrix {
                rows: Fixed(6),
                cols: Dim::Size(M),
            },
            Function::ConstraintJacobianC => Matrix {
                rows: Fixed(6),
                cols: Dim::Size(R),
            },
            Function::PartialBodyJacobian => Matrix {
                rows: Fixed(6),
                cols: Dim::Size(I),
            },
            Function::ConstraintSelection => Matrix {
                rows: Dim::Size(R),
                cols: Fixed(6),
            },
            Function::LambdaNullSpace => Matrix {
                rows: Fixed(6),
                cols: Dim::Size(K),
            },
            Function::LambdaPinv => Matrix {
                rows: Fixed(6),
                cols: Dim::Size(R),
            },
            Function::TaskSelection => Matrix {
                rows: Dim::Size(TaskRows),
                cols: Fixed(6),
            },
            Function::ConstrainedTaskJacobian => Matrix {
                rows: Dim::Size(TaskRows),
                cols: Dim::Size(M),
            },
            Function::Manipulability
            | Function::ManipulabilitySquared
            | Function::ConstraintDeterminant => Scalar,
            Function::ConstraintJacobian => Matrix {
                rows: Dim::Size(R),
                cols: Dim::Size(N),
            },
            Function::TaskJacobian => Matrix {
                rows: Dim::Size(NOutputs),
                cols: Dim::Size(N),
            },
            Function::ReducedJacobianNumerator => Matrix {
                rows: OnePlus(NOutputs),
                cols: Dim::Size(NActive),
            },
            Function::PassiveMapNumerator => Matrix {
                rows: OnePlus(NPassive),
                cols: Dim::Size(NActive),
            },
            Function::ReducedJacobian => Matrix {
                rows: Dim::Size(NOutputs),
                cols: Dim::Size(NActive),
            },
            Function::PassiveMap => Matrix {
                rows: Dim::Size(NPassive),
                cols: Dim::Size(NActive),
            },
            Function::PassiveVelocities => Vector(Dim::Size(NPassive)),
        }
    }

    /// Whether the result is an `Option`, `None` where it is not defined (a zero `det J_Cp`).
    pub const fn is_fallible(self) -> bool {
        matches!(
            self,
            Function::ReducedJacobian | Function::PassiveMap | Function::PassiveVelocities
        )
    }

    /// Whether the function takes the joints: `false` for the constraint's own matrices (`H`,
    /// `Λ#`, `Λ†`, `g_ir`) and the task's `S`, which depend only on the parameters and are emitted as `f(&params)` without
    /// a `_trig` variant.
    pub const fn takes_joints(self) -> bool {
        !matches!(
            self,
            Function::ConstraintSelection
                | Function::LambdaNullSpace
                | Function::LambdaPinv
                | Function::ConstraintFrame
                | Function::TaskSelection
        )
    }

    /// Whether the result is an expanded polynomial program (with CSE and Horner factoring),
    /// as opposed to a fixed wrapper around such programs (the quotients by `det J_Cp`).
    pub const fn is_program(self) -> bool {
        !self.is_fallible()
    }
}

/// A fused function of a serial robot's module: one emitted function `name` (and `name_trig`)
/// computing several catalogue outputs ([`Fused::outputs`]) in one straight-line program that
/// shares every common value, writing each into an out-parameter named by its short name
/// ([`Function::short_name`]).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Fused {
    /// The Rust name of the function (its variant taking `JointTrig` adds `_trig`).
    pub name: String,
    /// The outputs, in the order of the out-parameters.
    pub outputs: Vec<Function>,
}

impl Fused {
    /// The fused function `name` of `outputs`.
    pub fn new(name: impl Into<String>, outputs: impl IntoIterator<Item = Function>) -> Self {
        Fused {
            name: name.into(),
            outputs: outputs.into_iter().collect(),
        }
    }

    /// The fused functions every serial module gets: `pose_and_jacobian` (`g_0e` and `J^B_0e`)
    /// and, with a constraint, `link_pose_and_jacobian` (`g_0i` and `J^B_0i`, the constrained
    /// link's pose and partial body Jacobian).
    pub fn defaults(constrained: bool) -> Vec<Fused> {
        let mut out = vec![Fused::new(
            "pose_and_jacobian",
            [Function::ForwardKinematics, Function::BodyJacobian],
        )];
        if constrained {
            out.push(Fused::new(
                "link_pose_and_jacobian",
                [
                    Function::ConstrainedLinkKinematics,
                    Function::PartialBodyJacobian,
                ],
            ));
        }
        out
    }

    /// Parses `name=output,output,...` (the command line's `--function`): each output by its
    /// Rust name or short name ([`Function::resolve`], serial functions). The error names the
    /// part that is wrong.
    pub fn parse(text: &str) -> Result<Fused, String> {
        let (name, list) = text.split_once('=').ok_or_else(|| {
            format!("`{text}`: expected NAME=OUTPUT,OUTPUT,... (e.g. pose_and_jacobian=fk,jb0e)")
        })?;
        let name = name.trim();
        let mut outputs = Vec::new();
        for part in list.split(',').map(str::trim) {
            let f = Function::resolve(part, false).ok_or_else(|| {
                format!(
                    "function `{name}`: unknown output `{part}` (expected one of: {})",
                    Function::SERIAL
                        .iter()
                        .map(|f| format!("{} ({})", f.name(), f.short_name()))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            })?;
            outputs.push(f);
        }
        Ok(Fused::new(name, outputs))
    }

    /// Whether `name` is free for a fused function: a snake_case identifier that is not a
    /// keyword, does not end in `_trig`, and is not the name of a catalogue function or of
    /// another item a serial module holds. `Err` says why not.
    pub fn check_name(name: &str) -> Result<(), String> {
        let identifier = name.chars().next().is_some_and(|c| c.is_ascii_lowercase())
            && name
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
        if !identifier || RUST_KEYWORDS.contains(&name) {
            return Err(format!(
                "`{name}` is not a function name (a snake_case identifier such as \
                 `pose_and_jacobian`, not a keyword)"
            ));
        }
        if name.ends_with("_trig") {
            return Err(format!(
                "`{name}` ends in `_trig`, the suffix of the variant taking `JointTrig`"
            ));
        }
        if let Some(suffix) = ["_f64", "_fma", "_avx512"]
            .into_iter()
            .find(|s| name.ends_with(s))
        {
            return Err(format!(
                "`{name}` ends in `{suffix}`, a suffix of the `f64` entry points that \
                 `fma_at_run_time` adds to each fused function"
            ));
        }
        let taken = Function::SERIAL
            .iter()
            .chain(&Function::MECHANISM)
            .any(|f| f.name() == name)
            || RESERVED_ITEMS.contains(&name)
            || name.starts_with("lu_solve_")
            || name.starts_with("min_norm_solve_");
        if taken {
            return Err(format!(
                "`{name}` is already the name of a function of the generated module"
            ));
        }
        Ok(())
    }
}

/// Functions a serial module may hold besides the catalogue's (`controller_step`: the C ABI's
/// `<module>_controller_step`, beside each fused function's `<module>_<name>`).
const RESERVED_ITEMS: [&str; 5] = [
    "controller_step",
    "pose_and_jacobians",
    "step_kinematics",
    "trocar_offset",
    "zeroed",
];

/// Rust's keywords (strict and reserved) that are snake_case words.
const RUST_KEYWORDS: [&str; 50] = [
    "as", "break", "const", "continue", "crate", "else", "enum", "extern", "false", "fn", "for",
    "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut", "pub", "ref", "return",
    "self", "static", "struct", "super", "trait", "true", "type", "unsafe", "use", "where",
    "while", "async", "await", "dyn", "abstract", "become", "box", "do", "final", "macro",
    "override", "priv", "typeof", "unsized", "virtual", "yield", "try",
];

/// The Rust name.
impl fmt::Display for Function {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_round_trip() {
        let all: Vec<Function> = Function::SERIAL
            .into_iter()
            .chain(Function::MECHANISM)
            .collect();
        for (k, a) in all.iter().enumerate() {
            assert_eq!(Function::from_name(a.name()), Some(*a));
            assert_eq!(a.trig_name(), format!("{}_trig", a.name()));
            for b in &all[k + 1..] {
                assert_ne!(a.name(), b.name());
            }
        }
        assert!(all
            .iter()
            .all(|f| f.is_mechanism() == Function::MECHANISM.contains(f)));
    }

    #[test]
    fn names_resolve_by_kind() {
        for f in Function::SERIAL {
            assert_eq!(Function::resolve(f.name(), false), Some(f));
            assert_eq!(Function::resolve(f.short_name(), false), Some(f));
        }
        for f in Function::MECHANISM {
            assert_eq!(Function::resolve(f.name(), true), Some(f));
            assert_eq!(Function::resolve(f.short_name(), true), Some(f));
        }
        assert_eq!(
            Function::resolve("jr", true),
            Some(Function::ReducedJacobian)
        );
        assert_eq!(
            Function::resolve("jr", false),
            Some(Function::ConstrainedJacobian)
        );
        assert_eq!(Function::resolve("reduced_jacobian", false), None);
        assert_eq!(Function::resolve("nonsense", false), None);
    }

    #[test]
    fn fused_functions_parse_and_names_are_checked() {
        let f = Fused::parse("pose_and_jacobian=fk, body_jacobian").unwrap();
        assert_eq!(f.name, "pose_and_jacobian");
        assert_eq!(
            f.outputs,
            [Function::ForwardKinematics, Function::BodyJacobian]
        );
        let e = Fused::parse("step=fk,jb").unwrap_err();
        assert!(e.contains("function `step`: unknown output `jb`"), "{e}");
        assert!(Fused::parse("step").unwrap_err().contains("NAME=OUTPUT"));
        assert!(Fused::check_name("pose_and_jacobian").is_ok());
        for bad in [
            "Pose",
            "2x",
            "fn",
            "x_trig",
            "x_f64",
            "x_fma",
            "x_avx512",
            "body_jacobian",
            "step_kinematics",
            "",
        ] {
            assert!(Fused::check_name(bad).is_err(), "{bad}");
        }
        for f in Fused::defaults(true) {
            assert!(Fused::check_name(&f.name).is_ok());
        }
        let e = Fused::check_name("step_f64").unwrap_err();
        assert!(
            e.contains("ends in `_f64`, a suffix of the `f64` entry points"),
            "{e}"
        );
        let e = Fused::check_name("step_trig_avx512").unwrap_err();
        assert!(e.contains("ends in `_avx512`"), "{e}");
    }

    #[test]
    fn dimensions_print_as_in_signatures() {
        let size = |s: Size| match s {
            Size::NOutputs => 2,
            Size::NActive => 1,
            _ => 7,
        };
        match Function::ReducedJacobianNumerator.shape() {
            Shape::Matrix { rows, cols } => {
                assert_eq!(rows.to_string(), "1 + N_OUTPUTS");
                assert_eq!(cols.to_string(), "N_ACTIVE");
                assert_eq!((rows.value(size), cols.value(size)), (3, 1));
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(Dim::Fixed(6).to_string(), "6");
    }
}
