//! The module specification: what a generated module holds, whatever the output language.
//!
//! A [`ModuleSpec`] is what lowering (`lower`) builds from a derivation and what every backend reads
//! (Rust, the C ABI, the checks, the controller glue) and the evaluator runs: the module's
//! sizes ([`ConstItem`]), parameters, one [`EmittedFunction`] per catalogue output (its
//! [`Program`] and [`Layout`]), the fused functions ([`FusedFunction`]) and the data of the
//! control step ([`ControllerSpec`]).

use super::program::Program;
use trocar_model::catalogue;

/// The real type of generated code, as `Builder::real`, `ModuleOptions::real`, the command
/// line's `--real` and the attribute's `real = "..."` name it: generic over the runtime's
/// `trocar::Real`, or one of `f32`, `f64`.
#[derive(Clone, Copy, PartialEq, Eq, Debug, Default, Hash)]
pub enum Real {
    /// Generic over `T: ::trocar::emitted::Real` (works for `f32` and `f64`).
    #[default]
    Generic,
    /// Monomorphic `f32`.
    F32,
    /// Monomorphic `f64`.
    F64,
}

impl std::str::FromStr for Real {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "generic" | "T" => Ok(Real::Generic),
            "f32" => Ok(Real::F32),
            "f64" => Ok(Real::F64),
            other => Err(format!(
                "unknown real type `{other}` (expected f32, f64 or generic)"
            )),
        }
    }
}

/// The name [`FromStr`](std::str::FromStr) reads: `generic`, `f32` or `f64`.
impl std::fmt::Display for Real {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Real::Generic => "generic",
            Real::F32 => "f32",
            Real::F64 => "f64",
        })
    }
}

/// What a function returns; outputs of its program are in this layout.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Layout {
    /// One scalar.
    Scalar,
    /// A `rows × cols` matrix returned **column-major** as `[[T; rows]; cols]`; the program's
    /// outputs are in column-major order (output `c · rows + r` is entry `(r, c)`).
    Matrix {
        /// Rows.
        rows: usize,
        /// Columns.
        cols: usize,
    },
    /// A rigid transform `(R, p)` returned as `([[T; 3]; 3], [T; 3])`, `R` column-major; the
    /// outputs are the 9 entries of `R` column-major then the 3 of `p`.
    Transform,
}

impl Layout {
    /// Where each output goes in the result written row by row: an `rows × cols` matrix's
    /// entry `(r, c)` at `r · cols + c`, a transform as its 4 × 4 homogeneous matrix (whose
    /// constant last row no output fills).
    pub fn row_major_positions(&self) -> Vec<usize> {
        match *self {
            Layout::Scalar => vec![0],
            Layout::Matrix { rows, cols } => (0..rows * cols)
                .map(|k| (k % rows) * cols + k / rows)
                .collect(),
            Layout::Transform => (0..12)
                .map(|k| {
                    if k < 9 {
                        (k % 3) * 4 + k / 3
                    } else {
                        (k - 9) * 4 + 3
                    }
                })
                .collect(),
        }
    }

    /// Number of outputs.
    pub fn len(&self) -> usize {
        match *self {
            Layout::Scalar => 1,
            Layout::Matrix { rows, cols } => rows * cols,
            Layout::Transform => 12,
        }
    }

    /// `true` for an empty matrix.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// One function to emit.
#[derive(Clone, Debug)]
pub struct EmittedFunction {
    /// Rust name (the `_trig` variant gets the suffix `_trig`).
    pub name: String,
    /// First line of the doc comment, e.g. "The constrained Jacobian `J^r_0e`".
    pub summary: String,
    /// The thesis equation(s) it implements, e.g. "(3.15)".
    pub equation: String,
    /// More documentation (markdown paragraphs), may be empty.
    pub details: String,
    /// Output layout.
    pub layout: Layout,
    /// The program; its outputs match `layout`.
    pub program: Program,
    /// Names of the dimensions for the signature, e.g. `("6", "M")`; `None` uses numbers.
    pub dims: Option<(String, String)>,
    /// Whether the function takes the joints (`f(&q, &params)` and `f_trig(&trig, &params)`);
    /// otherwise it is `f(&params)` alone.
    pub takes_joints: bool,
    /// A scalar that returns 0 where its closed form is not finite (the manipulability: 0 means
    /// "singular" to a controller, `+∞` would mean the opposite).
    pub zero_when_not_finite: bool,
}

impl EmittedFunction {
    /// The function `entry` of the catalogue ([`trocar_model::catalogue`]): its name, equation
    /// (with the source's citation when it is not the thesis) and shape, the sizes of the module
    /// given by `size`; matrices name their dimensions in the signature (`[[T; 6]; M]`).
    pub fn catalogued(
        entry: catalogue::Function,
        summary: &str,
        details: &str,
        program: Program,
        size: impl Fn(catalogue::Size) -> usize,
    ) -> EmittedFunction {
        let (layout, dims) = match entry.shape() {
            catalogue::Shape::Scalar => (Layout::Scalar, None),
            catalogue::Shape::Transform => (Layout::Transform, None),
            catalogue::Shape::Matrix { rows, cols } => (
                Layout::Matrix {
                    rows: rows.value(&size),
                    cols: cols.value(&size),
                },
                Some((rows.to_string(), cols.to_string())),
            ),
            catalogue::Shape::Vector(len) => (
                Layout::Matrix {
                    rows: len.value(&size),
                    cols: 1,
                },
                Some((len.to_string(), "1".to_string())),
            ),
        };
        let citation = entry.source().citation();
        let equation = if citation.is_empty() {
            entry.equation().to_string()
        } else {
            format!("{} {citation}", entry.equation())
        };
        EmittedFunction {
            name: entry.name().into(),
            summary: summary.into(),
            equation,
            details: details.into(),
            layout,
            program,
            dims,
            takes_joints: entry.takes_joints(),
            zero_when_not_finite: matches!(
                entry,
                catalogue::Function::Manipulability | catalogue::Function::ManipulabilitySquared
            ),
        }
    }
}

/// One output of a [`FusedFunction`]: a catalogue function's result, written into the
/// out-parameter named by its short name.
#[derive(Clone, Debug)]
pub struct FusedOutput {
    /// The catalogue function whose value this is.
    pub function: catalogue::Function,
    /// Its layout (that of the function's own result).
    pub layout: Layout,
    /// Names of the dimensions for the signature, as [`EmittedFunction::dims`].
    pub dims: Option<(String, String)>,
    /// The manipulability's rule: 0 where the closed form is not finite.
    pub zero_when_not_finite: bool,
}

/// A function computing several catalogue outputs in one program ([`catalogue::Fused`]):
/// `name(q, p, out...)` and `name_trig(t, p, out...)`, each output written through a `&mut`
/// out-parameter.
#[derive(Clone, Debug)]
pub struct FusedFunction {
    /// Rust name.
    pub name: String,
    /// The outputs, in the order of the out-parameters.
    pub outputs: Vec<FusedOutput>,
    /// One program; its outputs are those of `outputs`, each in its layout, one after the other.
    pub program: Program,
    /// For `g_0i` and `J^B_0i` together, on a chain of right-angle joints: each joint's head
    /// `Trans(o) R_x(roll)`, base first, as `(roll, o)` with `roll` in quarter turns (0, 1 or −1).
    /// The function is then also written as the walk of `trocar::emitted::paired_rows`, which the
    /// default x86-64 target takes (chosen by lowering, `lower::paired_heads`).
    pub paired_heads: Option<Vec<(i8, [f64; 3])>>,
}

impl FusedFunction {
    /// The fused function `name` of `outputs` (each with the layout of its emitted function
    /// `functions`), computed by `program`.
    pub fn new(name: &str, outputs: &[&EmittedFunction], program: Program) -> FusedFunction {
        let outputs: Vec<FusedOutput> = outputs
            .iter()
            .map(|f| FusedOutput {
                function: catalogue::Function::from_name(&f.name)
                    .expect("a fused output is a catalogue function"),
                layout: f.layout,
                dims: f.dims.clone(),
                zero_when_not_finite: f.zero_when_not_finite,
            })
            .collect();
        debug_assert_eq!(
            program.outputs().len(),
            outputs.iter().map(|o| o.layout.len()).sum::<usize>()
        );
        FusedFunction {
            name: name.to_string(),
            outputs,
            program,
            paired_heads: None,
        }
    }

    /// The range of the program's outputs that holds output `k`.
    pub fn range(&self, k: usize) -> std::ops::Range<usize> {
        let start: usize = self.outputs[..k].iter().map(|o| o.layout.len()).sum();
        start..start + self.outputs[k].layout.len()
    }

    /// The catalogue functions computed, in order.
    pub fn functions(&self) -> Vec<catalogue::Function> {
        self.outputs.iter().map(|o| o.function).collect()
    }
}

/// A named `usize` constant of the module.
#[derive(Clone, Debug)]
pub struct ConstItem {
    /// Name (e.g. `N`).
    pub name: String,
    /// Value.
    pub value: usize,
    /// Doc comment.
    pub doc: String,
}

/// A robot module to emit.
#[derive(Clone, Debug)]
pub struct ModuleSpec {
    /// Module name (a Rust identifier).
    pub name: String,
    /// Module documentation (markdown).
    pub doc: String,
    /// Number of joints `n` (length of `q`).
    pub joints: usize,
    /// Named parameters and nominal values, in declaration order (the order of program
    /// parameter indices).
    pub params: Vec<(String, f64)>,
    /// `usize` constants (`N` must be among them; it types `q`).
    pub consts: Vec<ConstItem>,
    /// Functions.
    pub functions: Vec<EmittedFunction>,
    /// The control-step items of a constrained robot (`StepKinematics`, `step_kinematics` and,
    /// when the constraint frame slides along the link, `Kinematics`; see
    /// [`ControllerSpec`]).
    pub controller: Option<ControllerSpec>,
    /// Joint limits `[lower, upper]`, emitted as `JOINT_LIMITS` when every joint has them.
    pub joint_limits: Option<Vec<[f64; 2]>>,
    /// Each joint's limits, `None` for a joint without (a `continuous` one): emitted as
    /// `JOINT_RANGES` when some joint has limits and another has none.
    pub joint_ranges: Vec<Option<[f64; 2]>>,
    /// Each joint's speed limit (rad/s or m/s), `None` for a joint without: the C controller
    /// step keeps it (`emit::c_api`). Empty when no joint has one.
    pub joint_speed_limits: Vec<Option<f64>>,
    /// Each joint's acceleration limit, `None` for a joint without: the default of the C
    /// controller object's configuration (`emit::c_controller`). Empty for a mechanism.
    pub joint_acceleration_limits: Vec<Option<f64>>,
    /// Each joint's jerk limit, as [`Self::joint_acceleration_limits`].
    pub joint_jerk_limits: Vec<Option<f64>>,
    /// A constrained robot's `g_0e`, `J^B_0i`, `J^r_0e` and `J_c` as one program (outputs in that
    /// order), when it is smaller than their four functions: `pose_and_jacobians_trig` is then
    /// written from it, otherwise it calls the four.
    pub pose_and_jacobians: Option<Program>,
    /// Functions computing several catalogue outputs in one program ([`catalogue::Fused`]).
    pub fused: Vec<FusedFunction>,
    /// Also emit each fused function's `f64` entry points with FMA chosen at run time
    /// (`<name>_f64`, `<name>_trig_f64`, written by `fma_entry_points`); generic modules only.
    pub fma_at_run_time: bool,
}

impl ModuleSpec {
    /// The emitted function `f` of the catalogue, if the module has it.
    pub fn function(&self, f: catalogue::Function) -> Option<&EmittedFunction> {
        self.functions.iter().find(|x| x.name == f.name())
    }
}

/// What a constrained robot's step functions and controller glue are built from
/// (`step_kinematics`, `StepKinematics` and, when the constraint frame slides along the link,
/// `Kinematics`); lowering builds it from a derivation (`ControllerSpec::of`, in
/// `lower::controller`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ControllerSpec {
    /// The parameter that slides the constraint frame along the link (`lower::shaft_parameter`).
    pub offset: Option<String>,
    /// Whether the module has a task selection (`task_selection`, `constrained_task_jacobian`).
    pub task: bool,
    /// Rows of the task Jacobian `S J^r` (6 without a task).
    pub task_rows: usize,
    /// Columns `m` of `J^r`.
    pub m: usize,
    /// The constrained link `i` (columns of `J^B_0i`).
    pub link: usize,
}
