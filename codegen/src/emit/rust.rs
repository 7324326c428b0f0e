//! Rust tokens for a robot module: `Params`, `JointTrig`, constants and one function (plus its
//! `_trig` variant) per [`EmittedFunction`].

use super::program::{Op, Program, ValueId};
use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::{format_ident, quote};
use std::fmt::Write as _;
use trocar_model::catalogue;

/// The scalar type of generated code.
#[derive(Clone, Copy, PartialEq, Eq, Debug, Default, Hash)]
pub enum Scalar {
    /// Generic over `T: ::trocar::emitted::Real` (works for `f32` and `f64`).
    #[default]
    Generic,
    /// Monomorphic `f32`.
    F32,
    /// Monomorphic `f64`.
    F64,
}

impl std::str::FromStr for Scalar {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "generic" | "T" => Ok(Scalar::Generic),
            "f32" => Ok(Scalar::F32),
            "f64" => Ok(Scalar::F64),
            other => Err(format!(
                "unknown real type `{other}` (expected f32, f64 or generic)"
            )),
        }
    }
}

/// The name [`FromStr`](std::str::FromStr) reads: `generic`, `f32` or `f64`.
impl std::fmt::Display for Scalar {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Scalar::Generic => "generic",
            Scalar::F32 => "f32",
            Scalar::F64 => "f64",
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
    /// default x86-64 target takes ([`paired_heads`](super::bridge::paired_heads)).
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
    /// [`super::controller`]).
    pub controller: Option<super::controller::ControllerSpec>,
    /// Joint limits `[lower, upper]`, emitted as `JOINT_LIMITS` when every joint has them.
    pub joint_limits: Option<Vec<[f64; 2]>>,
    /// Each joint's limits, `None` for a joint without (a `continuous` one): emitted as
    /// `JOINT_RANGES` when some joint has limits and another has none.
    pub joint_ranges: Vec<Option<[f64; 2]>>,
    /// Each joint's speed limit (rad/s or m/s), `None` for a joint without: the C controller
    /// step keeps it ([`super::c_api`]). Empty when no joint has one.
    pub joint_speed_limits: Vec<Option<f64>>,
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

/// The default path of the runtime crate in emitted code ([`Runtime`]).
pub const DEFAULT_RUNTIME_PATH: &str = "::trocar";

/// The path through which emitted code names the runtime crate `trocar`
/// (`<T: ::trocar::emitted::Real>`), `::trocar` by default; another path (e.g.
/// `::my_reexport::trocar`) serves a crate that reaches `trocar` through a re-export
/// (prost-build's `prost_path`).
#[derive(Clone, Debug)]
pub struct Runtime {
    path: String,
    tokens: TokenStream,
}

impl Runtime {
    /// The runtime at `path`; `None` when `path` is not a Rust path.
    pub fn new(path: &str) -> Option<Self> {
        let parsed: syn::Path = syn::parse_str(path).ok()?;
        Some(Runtime {
            path: path.to_string(),
            tokens: quote!(#parsed),
        })
    }

    /// The path as given.
    pub fn path(&self) -> &str {
        &self.path
    }

    /// The path as tokens.
    pub fn tokens(&self) -> &TokenStream {
        &self.tokens
    }
}

/// Equal when the paths are written alike.
impl PartialEq for Runtime {
    fn eq(&self, other: &Self) -> bool {
        self.path == other.path
    }
}

impl Eq for Runtime {}

impl Default for Runtime {
    fn default() -> Self {
        Runtime::new(DEFAULT_RUNTIME_PATH).expect("a valid path")
    }
}

/// The scalar type and the runtime path of emitted code, with the token fragments built from
/// them.
pub(crate) struct Ty {
    pub(crate) real: Scalar,
    runtime: TokenStream,
}

impl Ty {
    pub(crate) fn new(real: Scalar, runtime: &Runtime) -> Self {
        Ty {
            real,
            runtime: runtime.tokens.clone(),
        }
    }

    /// The runtime crate's path, e.g. `::trocar`.
    pub(crate) fn runtime(&self) -> &TokenStream {
        &self.runtime
    }

    pub(crate) fn t(&self) -> TokenStream {
        match self.real {
            Scalar::Generic => quote!(T),
            Scalar::F32 => quote!(f32),
            Scalar::F64 => quote!(f64),
        }
    }
    /// The generic parameter of a straight-line function: `<T: Arith>` (the part of `Real` that
    /// runs lane by lane, `trocar::emitted::lanes`).
    pub(crate) fn generics(&self) -> TokenStream {
        let rt = &self.runtime;
        match self.real {
            Scalar::Generic => quote!(<T: #rt::emitted::Arith>),
            _ => quote!(),
        }
    }
    /// The generic parameter of a function that compares or tests a value (`is_finite`):
    /// `<T: Real>`.
    pub(crate) fn real_generics(&self) -> TokenStream {
        let rt = &self.runtime;
        match self.real {
            Scalar::Generic => quote!(<T: #rt::emitted::Real>),
            _ => quote!(),
        }
    }
    pub(crate) fn args(&self) -> TokenStream {
        match self.real {
            Scalar::Generic => quote!(<T>),
            _ => quote!(),
        }
    }
    /// The path of the arithmetic functions: `<T as Arith>` in a generic module, `<f64 as Real>`
    /// (or `f32`) in a monomorphic one.
    pub(crate) fn real_path(&self) -> TokenStream {
        let t = self.t();
        let rt = &self.runtime;
        match self.real {
            Scalar::Generic => quote!(<#t as #rt::emitted::Arith>),
            Scalar::F32 | Scalar::F64 => quote!(<#t as #rt::emitted::Real>),
        }
    }
    /// The path of `Real`'s own functions (`is_finite`, `to_f64`): `<T as Real>`.
    pub(crate) fn real_trait_path(&self) -> TokenStream {
        let t = self.t();
        let rt = &self.runtime;
        quote!(<#t as #rt::emitted::Real>)
    }
    fn lit(&self, x: f64) -> TokenStream {
        let r = self.real_path();
        if x == 0.0 {
            return quote!(#r::ZERO);
        }
        if x == 1.0 {
            return quote!(#r::ONE);
        }
        match self.real {
            Scalar::Generic => {
                let l = Literal::f64_unsuffixed(x);
                quote!(#r::lit(#l))
            }
            Scalar::F32 | Scalar::F64 => {
                // The f64's shortest round-trip decimal with the target suffix: rustc rounds the
                // decimal directly to the target type (correct rounding for f32).
                let mut s = format!("{x:?}");
                if !s.contains('.') && !s.contains('e') {
                    s.push_str(".0");
                }
                s.push_str(if self.real == Scalar::F32 {
                    "_f32"
                } else {
                    "_f64"
                });
                match s.parse::<Literal>() {
                    Ok(l) => quote!(#l),
                    Err(_) => {
                        let l = Literal::f64_unsuffixed(x);
                        quote!(#r::lit(#l))
                    }
                }
            }
        }
    }
}

const PREC_SUM: u8 = 1;
const PREC_PROD: u8 = 2;
const PREC_NEG: u8 = 3;
const PREC_ATOM: u8 = 4;

/// How joint and parameter values are reached in a function body.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Access {
    /// `q: &[T; N]`, trig computed in the body.
    Q,
    /// `t: &JointTrig<T>`.
    Trig,
}

struct BodyWriter<'a> {
    prog: &'a Program,
    ty: &'a Ty,
    access: Access,
    /// Name of a let-bound value.
    bound: Vec<Option<Ident>>,
    inline: Vec<bool>,
    /// The products written into their one addition as `Real::mul_add`
    /// ([`Program::fused_products`]).
    fused: Vec<bool>,
}

impl BodyWriter<'_> {
    fn expr(&self, v: ValueId) -> (TokenStream, u8) {
        if let Some(id) = &self.bound[v.index()] {
            return (quote!(#id), PREC_ATOM);
        }
        let r = self.ty.real_path();
        let op = self.prog.op(v);
        match *op {
            Op::Const(c) => {
                let x = c.value();
                if x < 0.0 {
                    let l = self.ty.lit(-x);
                    (quote!(-#l), PREC_NEG)
                } else {
                    (self.ty.lit(x), PREC_ATOM)
                }
            }
            Op::Param(p) => {
                let name = format_ident!("{}", self.prog.params()[p]);
                (quote!(p.#name), PREC_ATOM)
            }
            Op::Joint(k) => {
                let k = Literal::usize_unsuffixed(k);
                match self.access {
                    Access::Q => (quote!(q[#k]), PREC_ATOM),
                    Access::Trig => (quote!(t.q[#k]), PREC_ATOM),
                }
            }
            Op::Sin(k) | Op::Cos(k) => {
                let sin = matches!(op, Op::Sin(_));
                match self.access {
                    Access::Q => {
                        let id = format_ident!("{}{}", if sin { "s" } else { "c" }, k + 1);
                        (quote!(#id), PREC_ATOM)
                    }
                    Access::Trig => {
                        let k = Literal::usize_unsuffixed(k);
                        if sin {
                            (quote!(t.sin[#k]), PREC_ATOM)
                        } else {
                            (quote!(t.cos[#k]), PREC_ATOM)
                        }
                    }
                }
            }
            Op::Add(a, b) => match (self.product(a), self.product(b)) {
                (Some((x, y)), _) => self.mul_add(x, y, self.expr(b).0),
                (None, Some((x, y))) => self.mul_add(x, y, self.expr(a).0),
                (None, None) => self.binary(a, b, quote!(+), PREC_SUM),
            },
            Op::Sub(a, b) => match (self.product(a), self.product(b)) {
                // x y − b = fma(x, y, −b); a − x y = fma(−x, y, a).
                (Some((x, y)), _) => {
                    let nb = self.operand(b, PREC_NEG);
                    self.mul_add(x, y, quote!(-#nb))
                }
                (None, Some((x, y))) => {
                    let nx = self.operand(x, PREC_NEG);
                    let y = self.expr(y).0;
                    let a = self.expr(a).0;
                    (quote!(#r::mul_add(-#nx, #y, #a)), PREC_ATOM)
                }
                (None, None) => self.binary(a, b, quote!(-), PREC_SUM),
            },
            Op::Mul(a, b) => self.binary(a, b, quote!(*), PREC_PROD),
            Op::Div(a, b) => self.binary(a, b, quote!(/), PREC_PROD),
            Op::Neg(a) => {
                let x = self.operand(a, PREC_NEG);
                (quote!(-#x), PREC_NEG)
            }
            Op::Sqrt(a) => {
                let (x, _) = self.expr(a);
                (quote!(#r::sqrt(#x)), PREC_ATOM)
            }
            Op::Abs(a) => {
                let (x, _) = self.expr(a);
                (quote!(#r::abs(#x)), PREC_ATOM)
            }
        }
    }

    /// The factors of `v` when it is a product written in place (not a `let`-bound value): an
    /// addition of it is then one fused multiply-add (`Real::mul_add`).
    fn product(&self, v: ValueId) -> Option<(ValueId, ValueId)> {
        if !self.fused[v.index()] {
            return None;
        }
        match *self.prog.op(v) {
            Op::Mul(x, y) => Some((x, y)),
            _ => None,
        }
    }

    /// `x · y + c` as `Real::mul_add(x, y, c)`.
    fn mul_add(&self, x: ValueId, y: ValueId, c: TokenStream) -> (TokenStream, u8) {
        let r = self.ty.real_path();
        let (x, _) = self.expr(x);
        let (y, _) = self.expr(y);
        (quote!(#r::mul_add(#x, #y, #c)), PREC_ATOM)
    }

    /// `v` as an operand that needs precedence at least `min`.
    fn operand(&self, v: ValueId, min: u8) -> TokenStream {
        let (x, p) = self.expr(v);
        if p < min {
            quote!((#x))
        } else {
            x
        }
    }

    fn binary(&self, a: ValueId, b: ValueId, op: TokenStream, prec: u8) -> (TokenStream, u8) {
        // Left-associative: the right operand must bind tighter to keep the evaluation order.
        let x = self.operand(a, prec);
        let y = self.operand(b, prec + 1);
        (quote!(#x #op #y), prec)
    }
}

/// A program written as Rust: the statements (trig prelude and `let` bindings) and the output
/// expressions.
struct Body {
    stmts: Vec<TokenStream>,
    outs: Vec<TokenStream>,
    /// For each output, how many of `stmts` must precede it: the position just after the last
    /// statement its expression reads (0 when it reads none, e.g. a constant).
    ready: Vec<usize>,
}

impl Body {
    /// `stmts` with each of `stores` (one per output, in output order) placed right after the
    /// last statement its value reads, stores that become ready together in their own order.
    ///
    /// Written at the end instead, every output value stays live (in a register, or spilled)
    /// from its computation to the end of the function; placed early, its register is free for
    /// the rest of the walk. On SSE2's two-operand instructions this removes register copies and
    /// spills: the Panda's `link_pose_and_jacobian_trig` compiles to 333 instructions instead of
    /// 388 at the default x86-64 target, and runs in 0.87× the time with AVX-512
    /// (BENCHMARKS.md, "Stores where their values are ready").
    fn interleaved(self, stores: Vec<TokenStream>) -> Vec<TokenStream> {
        debug_assert_eq!(stores.len(), self.ready.len());
        let mut after: Vec<Vec<TokenStream>> = vec![Vec::new(); self.stmts.len() + 1];
        for (store, &r) in stores.into_iter().zip(&self.ready) {
            after[r].push(store);
        }
        let mut after = after.into_iter();
        let mut out: Vec<TokenStream> = after.next().unwrap_or_default();
        for (stmt, group) in self.stmts.into_iter().zip(after) {
            out.push(stmt);
            out.extend(group);
        }
        out
    }
}

/// A program written as Rust ([`Body`]).
fn body(prog: &Program, ty: &Ty, access: Access) -> Body {
    let live = prog.live();
    let n = prog.ops().len();
    let uses = prog.use_counts();
    let mut w = BodyWriter {
        prog,
        ty,
        access,
        bound: vec![None; n],
        inline: vec![false; n],
        fused: prog.fused_products(),
    };
    let mut stmts = Vec::new();
    if access == Access::Q {
        let r = ty.real_path();
        let mut used_sin = std::collections::BTreeSet::new();
        let mut used_cos = std::collections::BTreeSet::new();
        for (i, op) in prog.ops().iter().enumerate() {
            if live[i] {
                match *op {
                    Op::Sin(k) => {
                        used_sin.insert(k);
                    }
                    Op::Cos(k) => {
                        used_cos.insert(k);
                    }
                    _ => {}
                }
            }
        }
        stmts.extend(trig_statement(
            &r,
            &prog.trig_joints(),
            |k| used_sin.contains(&k),
            |k| used_cos.contains(&k),
        ));
    }
    // How many statements precede the point where each value can be written: the trig prelude
    // for a joint's sine, cosine or value read from `q`, a value's own `let`, or the latest of
    // its operands' for a value written in place.
    let prelude = stmts.len();
    let mut ready = vec![0usize; n];
    let mut counter = 0usize;
    for (i, op) in prog.ops().iter().enumerate() {
        if !live[i] {
            continue;
        }
        ready[i] = match op {
            Op::Joint(_) | Op::Sin(_) | Op::Cos(_) => prelude,
            _ => op.operands().map(|a| ready[a.index()]).max().unwrap_or(0),
        };
        let atom = matches!(
            op,
            Op::Const(_) | Op::Param(_) | Op::Joint(_) | Op::Sin(_) | Op::Cos(_)
        );
        if atom || uses[i] <= 1 {
            w.inline[i] = true;
            continue;
        }
        let (e, _) = w.expr(ValueId(i as u32));
        let id = format_ident!("x{}", counter);
        counter += 1;
        stmts.push(quote!(let #id = #e;));
        w.bound[i] = Some(id);
        ready[i] = stmts.len();
    }
    let outs = prog.outputs().iter().map(|&o| w.expr(o).0).collect();
    let ready = prog.outputs().iter().map(|o| ready[o.index()]).collect();
    Body { stmts, outs, ready }
}

fn layout_tokens(layout: Layout, ty: &Ty, outs: &[TokenStream]) -> (TokenStream, TokenStream) {
    let t = ty.t();
    match layout {
        Layout::Scalar => (quote!(#t), outs[0].clone()),
        Layout::Matrix { rows, cols } => {
            let r = Literal::usize_unsuffixed(rows);
            let c = Literal::usize_unsuffixed(cols);
            let columns = outs.chunks(rows.max(1)).map(|col| quote!([#(#col),*]));
            (quote!([[#t; #r]; #c]), quote!([#(#columns),*]))
        }
        Layout::Transform => {
            let columns = outs[..9].chunks(3).map(|col| quote!([#(#col),*]));
            let p = &outs[9..12];
            (
                quote!(([[#t; 3]; 3], [#t; 3])),
                quote!(([#(#columns),*], [#(#p),*])),
            )
        }
    }
}

fn dims_tokens(f: &EmittedFunction, ty: &Ty) -> Option<TokenStream> {
    let (r, c) = f.dims.as_ref()?;
    let t = ty.t();
    let r: TokenStream = r.parse().ok()?;
    let c: TokenStream = c.parse().ok()?;
    Some(match f.layout {
        Layout::Matrix { .. } => quote!([[#t; #r]; #c]),
        _ => return None,
    })
}

fn layout_doc(layout: Layout, dims: Option<&(String, String)>, t: &str) -> String {
    match layout {
        Layout::Scalar => String::new(),
        Layout::Matrix { rows, cols } => {
            let (r, c) = dims
                .cloned()
                .unwrap_or_else(|| (rows.to_string(), cols.to_string()));
            format!(
                "Returns the {rows} × {cols} matrix **column-major**: `[[{t}; {r}]; {c}]` holds {c} \
                 columns of {r} entries, `a[col][row]`. The conversion to nalgebra is free: \
                 `SMatrix::<{t}, {rows}, {cols}>::from_data(ArrayStorage(a))`."
            )
        }
        Layout::Transform => "Returns `(R, p)`: the rotation **column-major** (`r[col][row]`, \
             nalgebra: `Matrix3::from_data(ArrayStorage(r))`) and the position."
            .to_string(),
    }
}

fn doc_attrs(text: &str) -> TokenStream {
    let lines = text.lines().map(|l| {
        let l = if l.is_empty() {
            String::new()
        } else {
            format!(" {l}")
        };
        quote!(#[doc = #l])
    });
    quote!(#(#lines)*)
}

/// The parameters `prog` divides by, as "`a`, `b`" (empty when none).
fn divisors(prog: &Program) -> String {
    prog.divisor_params()
        .iter()
        .map(|p| format!("`{p}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The documentation's note on the parameters a function divides by ([`divisors`]).
fn divides_by(divisors: &str) -> String {
    format!(
        "Divides by {divisors}: the result is not finite where that is 0 (nor, in general, with a \
         NaN or infinite input); test it with `is_finite` where that can happen."
    )
}

fn function_tokens(f: &EmittedFunction, ty: &Ty, n: usize) -> TokenStream {
    let t = ty.t();
    let counts = f.program.op_counts();
    let name = format_ident!("{}", f.name);
    let name_trig = format_ident!("{}_trig", f.name);
    let mut doc = String::new();
    let _ = writeln!(doc, "{}, thesis {}.", f.summary, f.equation);
    if !f.details.is_empty() {
        let _ = writeln!(doc, "\n{}", f.details);
    }
    let layout = layout_doc(f.layout, f.dims.as_ref(), &t.to_string());
    if !layout.is_empty() {
        let _ = writeln!(doc, "\n{layout}");
    }
    let guard = f.zero_when_not_finite && f.layout == Layout::Scalar;
    // A function that tests its value needs `Real`; a straight-line one runs on lanes (`Arith`).
    let generics = if guard {
        ty.real_generics()
    } else {
        ty.generics()
    };
    let args = ty.args();
    let divisors = divisors(&f.program);
    let not_finite = if guard {
        let by = if divisors.is_empty() {
            String::new()
        } else {
            format!(" at a parameter it divides by equal to 0 ({divisors}), or")
        };
        format!(
            "Returns 0 where the closed form is not finite:{by} where a NaN or infinite input makes it so. \
             0 reads as singular to a controller that damps when the manipulability is small; \
             `+∞` would read as far from singular."
        )
    } else {
        String::new()
    };
    if guard {
        let _ = writeln!(doc, "\n{not_finite}");
    } else if !divisors.is_empty() {
        let _ = writeln!(doc, "\n{}", divides_by(&divisors));
    }
    let _ = writeln!(doc, "\nOperations: {counts}.");
    let doc_q = doc_attrs(&doc);
    let doc_t = doc_attrs(&format!(
        "[`{}`] from precomputed joint sines and cosines ([`JointTrig`]), thesis {}.\n\n{}{}\
         Operations: {} (the `sin_cos` calls are done once in [`JointTrig::new`]).",
        f.name,
        f.equation,
        if layout.is_empty() {
            String::new()
        } else {
            format!("{layout}\n\n")
        },
        if guard {
            format!("{not_finite}\n\n")
        } else {
            String::new()
        },
        super::program::OpCounts { trig: 0, ..counts }
    ));
    let Body {
        stmts: stmts_q,
        outs: outs_q,
        ..
    } = body(&f.program, ty, Access::Q);
    let Body {
        stmts: stmts_t,
        outs: outs_t,
        ..
    } = body(&f.program, ty, Access::Trig);
    let (ret, value_q) = layout_tokens(f.layout, ty, &outs_q);
    let ret = dims_tokens(f, ty).unwrap_or(ret);
    let (_, value_t) = layout_tokens(f.layout, ty, &outs_t);
    let (value_q, value_t) = if guard {
        let r = ty.real_trait_path();
        let wrap = |v: TokenStream| {
            quote! {{
                let w = #v;
                if #r::is_finite(w) { w } else { #r::ZERO }
            }}
        };
        (wrap(value_q), wrap(value_t))
    } else {
        (value_q, value_t)
    };
    let uses_q = uses(&f.program, |op| {
        matches!(op, Op::Joint(_) | Op::Sin(_) | Op::Cos(_))
    });
    let uses_p = uses(&f.program, |op| matches!(op, Op::Param(_)));
    let q = if uses_q { quote!(q) } else { quote!(_q) };
    let tt = if uses_q { quote!(t) } else { quote!(_t) };
    let p = if uses_p { quote!(p) } else { quote!(_p) };
    let n_ty = if n > 0 { quote!(N) } else { quote!(0) };
    if !f.takes_joints {
        assert!(
            !uses_q,
            "`{}` is catalogued as independent of the joints",
            f.name
        );
        return quote! {
            #doc_q
            #[inline]
            #[must_use]
            pub fn #name #generics (#p: &Params #args) -> #ret {
                #(#stmts_q)*
                #value_q
            }
        };
    }
    quote! {
        #doc_q
        #[inline]
        #[must_use]
        pub fn #name #generics (#q: &[#t; #n_ty], #p: &Params #args) -> #ret {
            #(#stmts_q)*
            #value_q
        }

        #doc_t
        #[inline]
        #[must_use]
        pub fn #name_trig #generics (#tt: &JointTrig #args, #p: &Params #args) -> #ret {
            #(#stmts_t)*
            #value_t
        }
    }
}

/// Whether a live operation of `prog` matches `f` (joint values, parameters ...).
fn uses(prog: &Program, f: impl Fn(&Op) -> bool) -> bool {
    prog.ops().iter().zip(prog.live()).any(|(op, l)| l && f(op))
}

/// The statements that write a program's output values `outs` (in `layout`) through the
/// out-parameter `out`: entry by entry, so that each value is stored where the caller wants it
/// (no temporary of the whole result and no copy).
fn store_tokens(
    layout: Layout,
    out: &Ident,
    outs: &[TokenStream],
    guard: Option<&TokenStream>,
) -> Vec<TokenStream> {
    match layout {
        Layout::Scalar => {
            let v = &outs[0];
            match guard {
                Some(r) => vec![quote! {
                    let w = #v;
                    *#out = if #r::is_finite(w) { w } else { #r::ZERO };
                }],
                None => vec![quote!(*#out = #v;)],
            }
        }
        Layout::Matrix { rows, .. } => outs
            .iter()
            .enumerate()
            .map(|(k, v)| {
                let c = Literal::usize_unsuffixed(k / rows);
                let r = Literal::usize_unsuffixed(k % rows);
                quote!(#out[#c][#r] = #v;)
            })
            .collect(),
        Layout::Transform => outs
            .iter()
            .enumerate()
            .map(|(k, v)| {
                if k < 9 {
                    let c = Literal::usize_unsuffixed(k / 3);
                    let r = Literal::usize_unsuffixed(k % 3);
                    quote!(#out.0[#c][#r] = #v;)
                } else {
                    let r = Literal::usize_unsuffixed(k - 9);
                    quote!(#out.1[#r] = #v;)
                }
            })
            .collect(),
    }
}

/// The type of a fused output's out-parameter (without `&mut`).
fn out_type(o: &FusedOutput, ty: &Ty) -> TokenStream {
    let t = ty.t();
    match o.layout {
        Layout::Scalar => quote!(#t),
        Layout::Transform => quote!(([[#t; 3]; 3], [#t; 3])),
        Layout::Matrix { rows, cols } => match &o.dims {
            Some((r, c)) => {
                let r: TokenStream = r.parse().expect("a dimension");
                let c: TokenStream = c.parse().expect("a dimension");
                quote!([[#t; #r]; #c])
            }
            None => {
                let r = Literal::usize_unsuffixed(rows);
                let c = Literal::usize_unsuffixed(cols);
                quote!([[#t; #r]; #c])
            }
        },
    }
}

/// A fused function's out-parameters: their names (the outputs' short names) and `name: &mut type`.
fn out_params(f: &FusedFunction, ty: &Ty) -> (Vec<Ident>, Vec<TokenStream>) {
    let outs: Vec<Ident> = f
        .outputs
        .iter()
        .map(|o| format_ident!("{}", o.function.short_name()))
        .collect();
    let params = f
        .outputs
        .iter()
        .zip(&outs)
        .map(|(o, id)| {
            let t = out_type(o, ty);
            quote!(#id: &mut #t)
        })
        .collect();
    (outs, params)
}

/// A fused function ([`FusedFunction`]) and its `_trig` variant, writing into out-parameters.
///
/// With `fma_at_run_time` both are `#[inline(always)]`, so that the entry points of
/// [`fma_entry_points`] compile their whole program for AVX2 and FMA.
fn fused_tokens(f: &FusedFunction, ty: &Ty, n: usize, fma_at_run_time: bool) -> TokenStream {
    let guarded = |o: &FusedOutput| o.zero_when_not_finite && o.layout == Layout::Scalar;
    // An output that is tested (`is_finite`) needs `Real`; otherwise the program runs on lanes.
    let generics = if f.outputs.iter().any(guarded) {
        ty.real_generics()
    } else {
        ty.generics()
    };
    let args = ty.args();
    let t_str = ty.t().to_string();
    let name = format_ident!("{}", f.name);
    let name_trig = format_ident!("{}_trig", f.name);
    let functions: Vec<catalogue::Function> = f.functions();
    let links = functions
        .iter()
        .map(|g| format!("[`{}`]", g.name()))
        .collect::<Vec<_>>();
    let links = match links.len() {
        1 => links[0].clone(),
        k => format!("{} and {}", links[..k - 1].join(", "), links[k - 1]),
    };
    let quantities = functions
        .iter()
        .map(|g| format!("`{}`", g.quantity()))
        .collect::<Vec<_>>()
        .join(", ");
    let mut equations: Vec<&str> = functions.iter().map(|g| g.equation()).collect();
    equations.dedup();
    let mut doc = format!(
        "{quantities} in one program: the values of {links}, thesis {}, computed together so \
         that they share every common value.\n\n",
        equations.join(", ")
    );
    for o in &f.outputs {
        let what = match o.layout {
            Layout::Scalar => String::new(),
            Layout::Transform => " as `(R, p)`, `R` column-major (`r[col][row]`)".to_string(),
            Layout::Matrix { rows, cols } => {
                let (r, c) = o
                    .dims
                    .clone()
                    .unwrap_or_else(|| (rows.to_string(), cols.to_string()));
                format!(", {r} × {c}, column-major (`[[{t_str}; {r}]; {c}]`, `a[col][row]`)")
            }
        };
        let zero = if o.zero_when_not_finite {
            " (0 where the closed form is not finite)"
        } else {
            ""
        };
        let _ = writeln!(
            doc,
            "- `{}`: `{}`{what}{zero}",
            o.function.short_name(),
            o.function.quantity()
        );
    }
    let divisors = divisors(&f.program);
    if !divisors.is_empty() {
        let _ = writeln!(doc, "\n{}", divides_by(&divisors));
    }
    let counts = f.program.op_counts();
    let doc_q = doc_attrs(&format!("{doc}\nOperations: {counts}."));
    let doc_t = doc_attrs(&format!(
        "[`{}`] from precomputed joint sines and cosines ([`JointTrig`]).\n\nOperations: {} \
         (the `sin_cos` calls are done once in [`JointTrig::new`]).",
        f.name,
        super::program::OpCounts { trig: 0, ..counts }
    ));
    let r = ty.real_trait_path();
    let (outs, params) = out_params(f, ty);
    let stores = |values: &[TokenStream]| -> Vec<TokenStream> {
        f.outputs
            .iter()
            .enumerate()
            .flat_map(|(k, o)| {
                let guard = guarded(o).then_some(&r);
                store_tokens(o.layout, &outs[k], &values[f.range(k)], guard)
            })
            .collect()
    };
    let body_q = body(&f.program, ty, Access::Q);
    let body_t = body(&f.program, ty, Access::Trig);
    let stores_q = stores(&body_q.outs);
    let stores_t = stores(&body_t.outs);
    let mut stmts_q = body_q.interleaved(stores_q);
    let mut stmts_t = body_t.interleaved(stores_t);
    let mut doc_q = doc_q;
    let mut doc_t = doc_t;
    if let (Some(heads), false) = (&f.paired_heads, fma_at_run_time) {
        let walk_doc = doc_attrs(&format!(
            "\nOn x86-64 with SSE2 and without AVX (the default target), the chain is walked \
             instead with the rows of the homogeneous transform as pairs \
             (`{}::emitted::paired_rows`): one SSE2 register per pair for `f64` and `f32`, one operation \
             per lane for the lane types (so that they stay, lane by lane, the scalar walk); \
             the same values to rounding. The operation counts above are the program's.",
            ty.runtime().to_string().replace(' ', "")
        ));
        doc_q.extend(walk_doc.clone());
        doc_t.extend(walk_doc);
        let at = |g: catalogue::Function| {
            let k = f
                .outputs
                .iter()
                .position(|o| o.function == g)
                .expect("paired heads are set for g_0i and J^B_0i");
            outs[k].clone()
        };
        let (g, jb) = (
            at(catalogue::Function::ConstrainedLinkKinematics),
            at(catalogue::Function::PartialBodyJacobian),
        );
        for (stmts, access) in [(&mut stmts_q, Access::Q), (&mut stmts_t, Access::Trig)] {
            let walk = paired_walk(heads, ty, access, &g, &jb);
            let program = std::mem::take(stmts);
            stmts.push(quote! {
                if cfg!(all(
                    target_arch = "x86_64",
                    target_feature = "sse2",
                    not(target_feature = "avx")
                )) {
                    #(#walk)*
                } else {
                    #(#program)*
                }
            });
        }
    }
    let uses_q = uses(&f.program, |op| {
        matches!(op, Op::Joint(_) | Op::Sin(_) | Op::Cos(_))
    });
    let uses_p = uses(&f.program, |op| matches!(op, Op::Param(_)));
    let q = if uses_q { quote!(q) } else { quote!(_q) };
    let tt = if uses_q { quote!(t) } else { quote!(_t) };
    let p = if uses_p { quote!(p) } else { quote!(_p) };
    let t = ty.t();
    let n_ty = if n > 0 { quote!(N) } else { quote!(0) };
    let inline = if fma_at_run_time {
        quote!(#[inline(always)] #[allow(clippy::inline_always)])
    } else {
        quote!(#[inline])
    };
    quote! {
        #doc_q
        #inline
        pub fn #name #generics (#q: &[#t; #n_ty], #p: &Params #args, #(#params),*) {
            #(#stmts_q)*
        }

        #doc_t
        #inline
        pub fn #name_trig #generics (#tt: &JointTrig #args, #p: &Params #args, #(#params),*) {
            #(#stmts_t)*
        }
    }
}

/// The statements of `g_0i` and `J^B_0i` written into `g` and `jb` by the walk of
/// `trocar::emitted::paired_rows` over the joints with heads `heads` (base first,
/// [`FusedFunction::paired_heads`]): from link `i` towards the base, each joint's column of
/// `J^B_0i` from the rows reached before it (2.45), `g_0i` at the end.
fn paired_walk(
    heads: &[(i8, [f64; 3])],
    ty: &Ty,
    access: Access,
    g: &Ident,
    jb: &Ident,
) -> Vec<TokenStream> {
    let rt = ty.runtime();
    let r = ty.real_path();
    let i = heads.len();
    let mut stmts = Vec::new();
    let joints: Vec<usize> = (0..i).collect();
    let trig = |k: usize| match access {
        Access::Q => {
            let (s, c) = (format_ident!("s{}", k + 1), format_ident!("c{}", k + 1));
            (quote!(#s), quote!(#c))
        }
        Access::Trig => {
            let k = Literal::usize_unsuffixed(k);
            (quote!(t.sin[#k]), quote!(t.cos[#k]))
        }
    };
    if access == Access::Q {
        stmts.extend(trig_statement(&r, &joints, |_| true, |_| true));
    }
    let last = Literal::usize_unsuffixed(i - 1);
    stmts.push(quote!(#jb[#last] = [#r::ZERO, #r::ZERO, #r::ZERO, #r::ZERO, #r::ZERO, #r::ONE];));
    for k in (0..i).rev() {
        let (roll, o) = heads[k];
        let roll = match roll {
            0 => quote!(#rt::emitted::paired_rows::Roll::Zero),
            1 => quote!(#rt::emitted::paired_rows::Roll::Quarter),
            _ => quote!(#rt::emitted::paired_rows::Roll::MinusQuarter),
        };
        let o = o.map(|x| {
            let l = Literal::f64_unsuffixed(x.abs());
            if x < 0.0 {
                quote!(-#l)
            } else {
                quote!(#l)
            }
        });
        let (s, c) = trig(k);
        stmts.push(if k == i - 1 {
            quote!(let rows = #rt::emitted::paired_rows::Rows::first(#s, #c, #roll, [#(#o),*]);)
        } else {
            quote!(let rows = rows.joint(#s, #c, #roll, [#(#o),*]);)
        });
        stmts.push(if k == 0 {
            quote!(rows.pose(#g);)
        } else {
            let col = Literal::usize_unsuffixed(k - 1);
            quote!(rows.column(&mut #jb[#col]);)
        });
    }
    stmts
}

/// The `f64` entry points of a fused function with FMA chosen at run time (`trocar::emitted::fma`):
/// `<name>_f64` and `<name>_trig_f64`, each taking the private `<name>_fma` /
/// `<name>_trig_fma` (the fused function on `FusedF64`, compiled for AVX2 and FMA) where
/// `trocar::emitted::fma::available()` holds, and `<name>::<f64>` otherwise; `<name>_trig_f64` takes
/// `<name>_trig_avx512` (the same, compiled for AVX-512F and AVX-512VL too) instead where
/// `trocar::emitted::fma::path()` is `Avx512`. From `q` the AVX2 function stays: compiled for
/// AVX-512 it was slower there (BENCHMARKS.md, "The fused functions on AVX-512, given the sines
/// and cosines").
fn fma_entry_points(f: &FusedFunction, spec: &ModuleSpec, ty: &Ty) -> TokenStream {
    let rt = ty.runtime();
    let f64_ty = Ty {
        real: Scalar::F64,
        runtime: rt.clone(),
    };
    let n_ty = if spec.joints > 0 {
        quote!(N)
    } else {
        quote!(0)
    };
    let (outs, params) = out_params(f, &f64_ty);
    // Each output seen as `FusedF64` storage: matrices and scalars in place, the pose through a
    // local (a tuple's layout is not guaranteed to follow its fields' types), copied out after.
    let mut locals = Vec::new();
    let mut copies = Vec::new();
    let views: Vec<TokenStream> = f
        .outputs
        .iter()
        .zip(&outs)
        .map(|(o, id)| match o.layout {
            Layout::Scalar => quote!(#rt::emitted::fma::FusedF64::scalar_mut(#id)),
            Layout::Matrix { .. } => quote!(#rt::emitted::fma::FusedF64::matrix_mut(#id)),
            Layout::Transform => {
                let local = format_ident!("{}_fused", id);
                locals.push(quote! {
                    let mut #local = ([[F(0.0); 3]; 3], [F(0.0); 3]);
                });
                copies.push(quote! {
                    *#id = (#local.0.map(|c| c.map(|v| v.0)), #local.1.map(|v| v.0));
                });
                quote!(&mut #local)
            }
        })
        .collect();
    // The casts are sound (the `_fma` function's doc, which the generated code carries, says
    // why): `Params` and `JointTrig` are `#[repr(C)]` ([`repr_c`]) over `T` fields only.
    let params_fused =
        quote!(unsafe { &*::core::ptr::from_ref::<Params<f64>>(p).cast::<Params<F>>() });
    // The functions are called through `self::`: the entry points' parameters (`q`, `t`, `p`,
    // the outputs' short names) and locals (`fk_fused`) would shadow a function named like one.
    let mut items = TokenStream::new();
    for trig in [false, true] {
        let base = if trig {
            format!("{}_trig", f.name)
        } else {
            f.name.clone()
        };
        let name = format_ident!("{}", base);
        let name_f64 = format_ident!("{}_f64", base);
        let name_fma = format_ident!("{}_fma", base);
        let (input, input_fused, arg) = if trig {
            (
                quote!(t: &JointTrig<f64>),
                quote!(unsafe {
                    &*::core::ptr::from_ref::<JointTrig<f64>>(t).cast::<JointTrig<F>>()
                }),
                quote!(t),
            )
        } else {
            (quote!(q: &[f64; #n_ty]), quote!(F::array(q)), quote!(q))
        };
        let doc = doc_attrs(&format!(
            "[`{base}`] in `f64` with fused multiply-adds chosen at run time (`{rt}::emitted::fma`): \
             on an x86-64 CPU with AVX2 and FMA, in a build with `trocar`'s `std` feature \
             whose target lacks FMA, [`{base}`] compiled for them{avx512}, every `mul_add` \
             rounded once (bit for bit [`{base}`] built with FMA); [`{base}`]`::<f64>` \
             otherwise (without `std`, always). The last bits of the results therefore depend \
             on the CPU: call [`{base}`] where they must not. Fast when optimised: at \
             opt-level 0 each `mul_add` is a call.",
            rt = rt.to_string().replace(' ', ""),
            avx512 = if trig {
                " (and for AVX-512F and AVX-512VL too where the CPU has them, with the same bits)"
            } else {
                ""
            }
        ));
        let doc_fma = doc_attrs(&format!(
            "[`{base}_f64`] on a CPU with AVX2 and FMA: [`{base}`] on `FusedF64`, compiled for \
             them (it is `#[inline(always)]`, so its whole program is).\n\n# Safety\n\nThe CPU \
             must have AVX2 and FMA: [`{base}_f64`] calls this function only when \
             `fma::path()` is `Fma` or `Avx512`, which it is only on such a CPU.\n\nThe views \
             of the arguments as `FusedF64` are sound: `Params` and `JointTrig` are \
             `#[repr(C)]` with fields `f64`, `[f64; N]` (or one `PhantomData`) only, and \
             `FusedF64` is `#[repr(transparent)]` over `f64`, so `Params<f64>` and \
             `Params<FusedF64>` (and the same for `JointTrig`) have one layout and every value \
             of one is a value of the other; the views borrow the arguments for no longer than \
             the call."
        ));
        let body = quote! {
            use #rt::emitted::fma::FusedF64 as F;
            #(#locals)*
            self::#name::<F>(#input_fused, #params_fused, #(#views),*);
            #(#copies)*
        };
        // Given the sines and cosines, the AVX-512 function where the CPU has it (one load of
        // the kept answer either way).
        let (dispatch, avx512_fn) = if trig {
            let name_avx512 = format_ident!("{}_avx512", base);
            let doc_avx512 = doc_attrs(&format!(
                "[`{base}_fma`] compiled for AVX-512F and AVX-512VL too (thirty-two vector \
                 registers): the same operations, so the same bits.\n\n# Safety\n\nThe CPU \
                 must have AVX2, FMA, AVX-512F and AVX-512VL: [`{base}_f64`] calls this \
                 function only when `fma::path()` is `Avx512`, which it is only on such a CPU. \
                 The views of the arguments are sound as in [`{base}_fma`]."
            ));
            (
                quote! {
                    #[cfg(target_arch = "x86_64")]
                    match #rt::emitted::fma::path() {
                        #rt::emitted::fma::Path::Avx512 => {
                            unsafe { self::#name_avx512(#arg, p, #(#outs),*) };
                            return;
                        }
                        #rt::emitted::fma::Path::Fma => {
                            unsafe { self::#name_fma(#arg, p, #(#outs),*) };
                            return;
                        }
                        _ => {}
                    }
                },
                quote! {
                    #doc_avx512
                    #[cfg(target_arch = "x86_64")]
                    #[target_feature(enable = "avx2,fma,avx512f,avx512vl")]
                    unsafe fn #name_avx512(#input, p: &Params<f64>, #(#params),*) {
                        #body
                    }
                },
            )
        } else {
            (
                quote! {
                    #[cfg(target_arch = "x86_64")]
                    if #rt::emitted::fma::available() {
                        unsafe { self::#name_fma(#arg, p, #(#outs),*) };
                        return;
                    }
                },
                TokenStream::new(),
            )
        };
        // `#[inline]`, not `always`: `name` is `#[inline(always)]` here, so `always` would copy
        // the fallback `name::<f64>` into every caller, and with `path()` one load the entry
        // points inline where they pay anyway (BENCHMARKS.md, "The fused functions on AVX-512,
        // …": the same instruction counts either way).
        items.extend(quote! {
            #doc
            #[inline]
            pub fn #name_f64(#input, p: &Params<f64>, #(#params),*) {
                #dispatch
                self::#name::<f64>(#arg, p, #(#outs),*);
            }

            #doc_fma
            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx2,fma")]
            unsafe fn #name_fma(#input, p: &Params<f64>, #(#params),*) {
                #body
            }

            #avx512_fn
        });
    }
    items
}

/// `pose_and_jacobians_trig` of a constrained robot: `g_0e`, `J^B_0i`, `J^r_0e` and `J_c` from one
/// [`JointTrig`], written from [`ModuleSpec::pose_and_jacobians`] when there is one (the chain
/// walked once), from the four `_trig` functions otherwise.
fn pose_and_jacobians_tokens(spec: &ModuleSpec, ty: &Ty) -> Option<TokenStream> {
    spec.function(catalogue::Function::ConstrainedJacobian)?;
    let size = |name: &str| {
        spec.consts
            .iter()
            .find(|c| c.name == name)
            .map(|c| c.value)
            .unwrap_or_else(|| panic!("a constrained module has the constant {name}"))
    };
    let (i, m, r) = (size("I"), size("M"), size("R"));
    let t = ty.t();
    let generics = ty.generics();
    let args = ty.args();
    let tuple = quote!((([[#t; 3]; 3], [#t; 3]), [[#t; 6]; I], [[#t; 6]; M], [[#t; 6]; R]));
    let ret = quote!(PoseAndJacobians #args);
    let mut doc = String::from(
        "`(g_0e, J^B_0i, J^r_0e, J_c)` from one [`JointTrig`]: the values of \
         [`forward_kinematics_trig`], [`partial_body_jacobian_trig`], \
         [`constrained_jacobian_trig`] and [`constraint_jacobian_c_trig`], what a control step \
         needs, thesis (2.21), (3.13), (3.15) and (3.33).\n\n",
    );
    let (p, value) = match &spec.pose_and_jacobians {
        Some(prog) => {
            let Body { stmts, outs, .. } = body(prog, ty, Access::Trig);
            let (_, g) = layout_tokens(Layout::Transform, ty, &outs[..12]);
            let mat = |range: std::ops::Range<usize>, cols: usize| {
                layout_tokens(Layout::Matrix { rows: 6, cols }, ty, &outs[range]).1
            };
            let jbi = mat(12..12 + 6 * i, i);
            let jr = mat(12 + 6 * i..12 + 6 * (i + m), m);
            let jc = mat(12 + 6 * (i + m)..12 + 6 * (i + m + r), r);
            let _ = writeln!(
                doc,
                "One pass along the chain: the walk that builds `J^B_0i` ends with `g_0i`, so \
                 `g_0e = g_0i g_ie` costs one product more, and the four share their common \
                 values.\n"
            );
            let divisors = divisors(prog);
            if !divisors.is_empty() {
                let _ = writeln!(doc, "{}\n", divides_by(&divisors));
            }
            let _ = write!(
                doc,
                "Operations: {} (the `sin_cos` calls are done once in [`JointTrig::new`]).",
                super::program::OpCounts {
                    trig: 0,
                    ..prog.op_counts()
                }
            );
            let p = if uses(prog, |op| matches!(op, Op::Param(_))) {
                quote!(p)
            } else {
                quote!(_p)
            };
            (p, quote! { #(#stmts)* (#g, #jbi, #jr, #jc) })
        }
        None => {
            doc.push_str(
                "The four functions called in turn (one program for all four is no smaller).",
            );
            (
                quote!(p),
                quote! {
                    (
                        forward_kinematics_trig(t, p),
                        partial_body_jacobian_trig(t, p),
                        constrained_jacobian_trig(t, p),
                        constraint_jacobian_c_trig(t, p),
                    )
                },
            )
        }
    };
    let doc = doc_attrs(&doc);
    // Always inlined: called once per step, its four results then go straight into the caller's
    // storage instead of through a returned copy (measured: dia10_like 93 ns out of line, see
    // BENCHMARKS.md).
    Some(quote! {
        /// `(g_0e, J^B_0i, J^r_0e, J_c)` as [`pose_and_jacobians_trig`] returns them: `(R, p)` with
        /// `R` column-major, then the three matrices column-major.
        pub type PoseAndJacobians #args = #tuple;

        #doc
        #[inline(always)]
        #[must_use]
        pub fn pose_and_jacobians_trig #generics (t: &JointTrig #args, #p: &Params #args) -> #ret {
            #value
        }
    })
}

fn params_tokens(spec: &ModuleSpec, ty: &Ty) -> TokenStream {
    let t = ty.t();
    let generics = ty.generics();
    let args = ty.args();
    let doc_struct = doc_attrs(&format!(
        "The named parameters of `{}`: runtime inputs of every function.",
        spec.name
    ));
    let rt = ty.runtime();
    let repr = repr_c(spec);
    if spec.params.is_empty() {
        return match ty.real {
            Scalar::Generic => quote! {
                #doc_struct
                #[derive(Clone, Copy, Debug, Default, PartialEq)]
                #repr
                pub struct Params<T>(::core::marker::PhantomData<T>);

                impl<T: #rt::emitted::Arith> Params<T> {
                    /// The description's nominal values (this robot has no parameters).
                    #[inline]
                    #[must_use]
                    pub fn nominal() -> Self {
                        Params(::core::marker::PhantomData)
                    }
                }
            },
            _ => quote! {
                #doc_struct
                #[derive(Clone, Copy, Debug, Default, PartialEq)]
                pub struct Params;

                impl Params {
                    /// The description's nominal values (this robot has no parameters).
                    #[inline]
                    #[must_use]
                    pub fn nominal() -> Self {
                        Params
                    }
                }
            },
        };
    }
    let fields = spec.params.iter().map(|(name, value)| {
        let id = format_ident!("{}", name);
        let d = format!(" `{name}` (nominal value {value:?}).");
        quote!(#[doc = #d] pub #id: #t,)
    });
    let inits = spec.params.iter().map(|(name, value)| {
        let id = format_ident!("{}", name);
        let v = ty.lit(*value);
        quote!(#id: #v,)
    });
    quote! {
        #doc_struct
        #[derive(Clone, Copy, Debug, Default, PartialEq)]
        #repr
        pub struct Params #generics {
            #(#fields)*
        }

        impl #generics Params #args {
            /// The description's nominal values.
            #[inline]
            #[must_use]
            pub fn nominal() -> Self {
                Params { #(#inits)* }
            }
        }
    }
}

/// `#[repr(C)]` for `Params` and `JointTrig` in a module with `fma_at_run_time`: their fields are
/// all `T` (or arrays of `T`), so with a fixed field order `Params<f64>` and `JointTrig<f64>` have
/// the layout of `Params<FusedF64>` and `JointTrig<FusedF64>`, and the `_fma` functions read the
/// caller's values in place ([`fma_entry_points`]).
fn repr_c(spec: &ModuleSpec) -> Option<TokenStream> {
    spec.fma_at_run_time.then(|| quote!(#[repr(C)]))
}

fn trig_tokens(spec: &ModuleSpec, ty: &Ty) -> TokenStream {
    let t = ty.t();
    let r = ty.real_path();
    let generics = ty.generics();
    let args = ty.args();
    let n = spec.joints;
    let mut used = vec![false; n];
    for f in &spec.functions {
        for k in f.program.trig_joints() {
            if k < n {
                used[k] = true;
            }
        }
    }
    let joints: Vec<usize> = (0..n).filter(|&k| used[k]).collect();
    let stmts = trig_statement(&r, &joints, |_| true, |_| true);
    let mut sins = Vec::new();
    let mut coss = Vec::new();
    for (k, &u) in used.iter().enumerate() {
        if u {
            let s = format_ident!("s{}", k + 1);
            let c = format_ident!("c{}", k + 1);
            sins.push(quote!(#s));
            coss.push(quote!(#c));
        } else {
            sins.push(quote!(#r::ZERO));
            coss.push(quote!(#r::ONE));
        }
    }
    let joints_doc = used
        .iter()
        .enumerate()
        .filter(|(_, &u)| u)
        .map(|(k, _)| (k + 1).to_string())
        .collect::<Vec<_>>()
        .join(", ");
    let doc = doc_attrs(&format!(
        "Joint values with the sine and cosine of every joint the functions use (joints \
         {joints_doc}, 1-based), computed once per control step and shared by the `_trig` \
         functions.\n\nUnused entries hold `sin = 0`, `cos = 1`."
    ));
    let q = if n > 0 { quote!(q) } else { quote!(_q) };
    let repr = repr_c(spec);
    quote! {
        #doc
        #[derive(Clone, Copy, Debug, PartialEq)]
        #repr
        pub struct JointTrig #generics {
            /// The joint values `q`, base first.
            pub q: [#t; N],
            /// `sin q[k]`.
            pub sin: [#t; N],
            /// `cos q[k]`.
            pub cos: [#t; N],
        }

        impl #generics JointTrig #args {
            /// The sines and cosines of the used joints, in one `sin_cos_array` call.
            // Always inlined: out of line (merged with every identical `new` of the program)
            // its sines and cosines went to the caller through memory (the Panda with an RCM:
            // 65 ns a step instead of 56, BENCHMARKS.md).
            #[inline(always)]
            #[must_use]
            pub fn new(#q: &[#t; N]) -> Self {
                #stmts
                JointTrig { q: *#q, sin: [#(#sins),*], cos: [#(#coss),*] }
            }
        }
    }
}

/// `let ([s.., ..], [c.., ..]) = R::sin_cos_array(&[q[k], ..]);`: the sines and cosines of the
/// joints `ks` (0-based, ascending) in one call (rule `one_trig`: one `sin_cos` per joint, batched
/// so that the runtime can compute them side by side), binding `s{k+1}` and `c{k+1}` where
/// `bind_sin(k)` and `bind_cos(k)` hold and `_` elsewhere. Nothing when `ks` is empty.
fn trig_statement(
    r: &TokenStream,
    ks: &[usize],
    bind_sin: impl Fn(usize) -> bool,
    bind_cos: impl Fn(usize) -> bool,
) -> Option<TokenStream> {
    if ks.is_empty() {
        return None;
    }
    let bind = |k: usize, yes: bool, letter: &str| {
        if yes {
            let id = format_ident!("{}{}", letter, k + 1);
            quote!(#id)
        } else {
            quote!(_)
        }
    };
    let sins = ks.iter().map(|&k| bind(k, bind_sin(k), "s"));
    let coss = ks.iter().map(|&k| bind(k, bind_cos(k), "c"));
    let args = ks.iter().map(|&k| {
        let kk = Literal::usize_unsuffixed(k);
        quote!(q[#kk])
    });
    Some(quote!(let ([#(#sins),*], [#(#coss),*]) = #r::sin_cos_array(&[#(#args),*]);))
}

/// The items of a robot module (without the `mod` wrapper), naming the runtime `::trocar`.
pub fn module_items(spec: &ModuleSpec, real: Scalar) -> TokenStream {
    module_items_in(spec, real, &Runtime::default())
}

/// The items of a robot module (without the `mod` wrapper), naming the runtime by `runtime`.
pub fn module_items_in(spec: &ModuleSpec, real: Scalar, runtime: &Runtime) -> TokenStream {
    let ty = Ty::new(real, runtime);
    let consts = spec.consts.iter().map(|c| {
        let id = format_ident!("{}", c.name);
        let v = Literal::usize_unsuffixed(c.value);
        let d = doc_attrs(&c.doc);
        quote!(#d pub const #id: usize = #v;)
    });
    let params = params_tokens(spec, &ty);
    let limits = spec.joint_limits.as_ref().map(|limits| {
        let rows = limits.iter().map(|[lo, hi]| quote!([#lo, #hi]));
        quote! {
            /// Joint limits `[lower, upper]` (rad for revolute joints, m for prismatic ones),
            /// base first, from the description (its URDF's `<limit>` or `limits = [lo, hi]`).
            pub const JOINT_LIMITS: [[f64; 2]; N] = [#(#rows),*];
        }
    });
    // A robot whose joints have limits except some (`continuous` ones): each joint's bounds,
    // typed, instead of no constant at all.
    let partial = spec.joint_ranges.iter().any(Option::is_some)
        && spec.joint_ranges.iter().any(Option::is_none);
    let ranges = partial.then(|| {
        let rows = spec.joint_ranges.iter().map(|r| match r {
            Some([lo, hi]) => quote!(Some([#lo, #hi])),
            None => quote!(None),
        });
        quote! {
            /// Each joint's limits `[lower, upper]` (rad for revolute joints, m for prismatic
            /// ones), base first, from the description; `None` for a joint without (a URDF
            /// `continuous` joint): its range is unbounded, `(−∞, ∞)`. Emitted when some
            /// joints have limits and others do not; `JOINT_LIMITS` when all have them.
            pub const JOINT_RANGES: [Option<[f64; 2]>; N] = [#(#rows),*];
        }
    });
    let trig = trig_tokens(spec, &ty);
    let fns = spec
        .functions
        .iter()
        .map(|f| function_tokens(f, &ty, spec.joints));
    let fused = spec.fused.iter().map(|f| {
        let mut items = fused_tokens(f, &ty, spec.joints, spec.fma_at_run_time);
        if spec.fma_at_run_time {
            items.extend(fma_entry_points(f, spec, &ty));
        }
        items
    });
    let step = pose_and_jacobians_tokens(spec, &ty);
    let controller = spec
        .controller
        .as_ref()
        .map(|c| super::controller::tokens(ty.runtime(), real, c));
    quote! {
        #(#consts)*
        #limits
        #ranges
        #params
        #trig
        #(#fns)*
        #(#fused)*
        #step
        #controller
    }
}

/// The whole module `pub mod <name> { ... }`, with its documentation and lint attributes, naming
/// the runtime `::trocar`.
pub fn module_tokens(spec: &ModuleSpec, real: Scalar) -> TokenStream {
    module_tokens_in(spec, real, &Runtime::default())
}

/// The whole module `pub mod <name> { ... }`, naming the runtime by `runtime`.
pub fn module_tokens_in(spec: &ModuleSpec, real: Scalar, runtime: &Runtime) -> TokenStream {
    wrap_module(&spec.name, &spec.doc, module_items_in(spec, real, runtime))
}

/// The module wrapper of every generated module, serial or mechanism: `pub mod <name> { ... }`
/// with `doc` (markdown, one `#![doc]` a line) and the lint attributes, around `items`.
pub fn wrap_module(name: &str, doc: &str, items: TokenStream) -> TokenStream {
    let name = Ident::new(name, Span::call_site());
    let doc = doc.lines().map(|l| {
        let l = if l.is_empty() {
            String::new()
        } else {
            format!(" {l}")
        };
        quote!(#![doc = #l])
    });
    quote! {
        pub mod #name {
            #(#doc)*
            // Literals are the description's values written in full: they may look like
            // well-known constants (e.g. 1/√2) or carry more digits than f32 holds; rustc rounds
            // them correctly.
            #![allow(
                clippy::approx_constant,
                clippy::excessive_precision,
                clippy::unreadable_literal,
                clippy::too_many_lines,
                clippy::doc_markdown
            )]
            #items
        }
    }
}

/// Formats tokens of a file with prettyplease, headed by the `@generated` line.
pub fn format_file(tokens: TokenStream) -> Result<String, syn::Error> {
    let file: syn::File = syn::parse2(tokens)?;
    Ok(format!(
        "// This file is @generated by trocar-codegen. Do not edit.\n\n{}",
        prettyplease::unparse(&file)
    ))
}
