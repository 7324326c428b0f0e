//! A straight-line program compiled for fast evaluation in `f64`: what `trocar eval`, the
//! library's `Robot::eval` and Python's `Robot.eval` / `eval_many` run.
//!
//! The program is the one the emitter writes as Rust, and it is evaluated operation for
//! operation as the compiled module evaluates it: the sines and cosines come from
//! [`trocar::Real::sin_cos`] (as `sin_cos_array` in generated code, which is exactly `sin_cos` of
//! each element), and the products the emitter writes as `Real::mul_add` (rule
//! `fuse_when_it_pays`, [`Program::fused_products`]) are evaluated by `Real::mul_add` too, so the
//! results are bit for bit those of the generated `f64` code built for the same target.
//!
//! Compilation numbers the live operations in order and gives each a register; a register is
//! reused once its value has no use left (linear scan over the straight line), so the register
//! file stays small (the Panda's largest program needs about a hundred) and sits in the first
//! level of cache. Literals, parameters, joint values, sines and cosines have registers of their
//! own, filled before the operations run.
//!
//! [`Compiled::eval_batch`] evaluates many configurations at once, [`LANES`] side by side: every
//! register then holds one value per configuration and every operation is a loop over the lanes,
//! which the compiler vectorises; the sines and cosines of the lanes come from one
//! `sin_cos_array` call per joint. Each lane's results are those of [`Compiled::eval`] bit for bit.

use crate::ir::{Op, Program, ValueId};
use trocar::emitted::fast;
use trocar::Real;

/// Configurations evaluated side by side by [`Compiled::eval_batch`].
pub const LANES: usize = 8;

/// Register files of at most this many registers are indexed by `u8` into a fixed-size array,
/// so that every access is in bounds by its type and the evaluation loop has no bounds checks
/// (the Panda's programs use 6–51 registers); larger programs index a slice.
pub const SMALL_REGISTERS: usize = 256;

/// A register index: `u8` into `[_; SMALL_REGISTERS]`, `u32` into a slice.
trait Reg: Copy + std::fmt::Debug + PartialEq {
    fn at(self) -> usize;
}

impl Reg for u8 {
    #[inline(always)]
    fn at(self) -> usize {
        self as usize
    }
}

impl Reg for u32 {
    #[inline(always)]
    fn at(self) -> usize {
        self as usize
    }
}

/// How a [`Step`] computes: `kind` below [`DIV`] is `(±x)·y + (±c)` with the signs
/// [`NEG_X`] and [`NEG_C`]; otherwise one of [`DIV`] (`x / y`), [`SQRT`] and [`ABS`] of `x`.
const NEG_X: u8 = 1;
/// See [`NEG_X`].
const NEG_C: u8 = 2;
/// See [`NEG_X`].
const DIV: u8 = 4;
/// See [`NEG_X`].
const SQRT: u8 = 8;
/// See [`NEG_X`].
const ABS: u8 = 16;

/// One operation in the evaluator's single form: `d = Real::mul_add(±x, y, ±c)` for every
/// addition, subtraction, product, negation and fused product (with a register holding 1 or
/// −0 where the operation has no such operand), a division, square root or absolute value
/// otherwise. Every operation of the program then runs the same few machine instructions, so
/// the evaluation has no jump that depends on the operation (in a `match` over ten kinds
/// most of the time went into mispredicted jumps); the results are bit for bit the
/// operations' own:
///
/// - `a + b` is `a · 1 + b` (`a · 1` is exact, one rounding of the sum), `a − b` is
///   `a · 1 + (−b)` (IEEE 754 defines subtraction so);
/// - `a · b` is `a · b + (−0)` (adding −0 leaves every value, +0 and −0 included, as it is);
/// - `−a` is `(−a) · 1 + (−0)`;
/// - the fused products are `Real::mul_add` already, with the sign flips exact.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Step<R> {
    d: R,
    x: R,
    y: R,
    c: R,
    kind: u8,
}

impl Step<u32> {
    /// The same step with `u8` registers (all indices below [`SMALL_REGISTERS`]).
    fn narrow(self) -> Step<u8> {
        let n = |r: u32| r as u8;
        Step {
            d: n(self.d),
            x: n(self.x),
            y: n(self.y),
            c: n(self.c),
            kind: self.kind,
        }
    }
}

/// The operations, with the narrowest registers that hold the program.
#[derive(Clone, Debug)]
enum Code {
    Small(Vec<Step<u8>>),
    Large(Vec<Step<u32>>),
}

/// Input registers, filled before the operations run.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Input {
    /// A parameter's value.
    Param(u32, usize),
    /// `q[k]`.
    Joint(u32, usize),
    /// `sin q[k]` and `cos q[k]` from one `sin_cos`, into the registers that use them.
    Trig {
        joint: usize,
        sin: Option<u32>,
        cos: Option<u32>,
    },
}

/// A program ready to evaluate: its live operations on reused registers, evaluated as the
/// generated `f64` code evaluates them (see `trocar_codegen::evaluate`).
#[derive(Clone, Debug)]
pub struct Compiled {
    /// Register file with the literals in place; the other input registers and the operation
    /// registers are overwritten on every evaluation.
    template: Vec<f64>,
    /// The other inputs.
    inputs: Vec<Input>,
    /// Registers below this hold inputs and literals; the operations' registers follow.
    inputs_end: usize,
    code: Code,
    /// Number of operations.
    operations: usize,
    outputs: Vec<u32>,
    joints: usize,
    params: usize,
}

impl Compiled {
    /// Compiles the live part of `program`, a function of `joints` joint values and
    /// `program.params().len()` parameters.
    pub fn new(program: &Program, joints: usize) -> Self {
        let ops = program.ops();
        let live = program.live();
        let fused = program.fused_products();
        let outputs = program.outputs();
        // The operations in order of their depth (the longest chain of operations from the
        // inputs to them), program order within a depth: the operations next to each other are
        // then independent, and the processor overlaps them instead of waiting for one result
        // after another. Each result is the same whichever order they run in.
        let mut depth = vec![0usize; ops.len()];
        for (i, op) in ops.iter().enumerate() {
            if live[i] {
                let below = op.operands().map(|a| depth[a.index()]).max();
                depth[i] = below.map_or(0, |d| d + usize::from(!fused[i]));
            }
        }
        let mut order: Vec<usize> = (0..ops.len()).collect();
        order.sort_by_key(|&i| depth[i]);
        // Last position (in that order, outputs after every op) where each value is read.
        let end = ops.len();
        let mut last_use = vec![0usize; ops.len()];
        for (at, &i) in order.iter().enumerate() {
            if !live[i] || fused[i] {
                continue;
            }
            for a in operands_as_evaluated(program, &fused, &ops[i]) {
                last_use[a.index()] = last_use[a.index()].max(at);
            }
        }
        for o in outputs {
            last_use[o.index()] = end;
        }

        let mut reg = vec![u32::MAX; ops.len()];
        let mut template = Vec::new();
        let mut inputs: Vec<Input> = Vec::new();
        // Inputs first: literals (kept in the template), then parameters, joints and trig.
        for (i, op) in ops.iter().enumerate() {
            if !live[i] {
                continue;
            }
            let r = template.len() as u32;
            match *op {
                Op::Const(c) => template.push(c.value()),
                Op::Param(p) => {
                    inputs.push(Input::Param(r, p));
                    template.push(0.0);
                }
                Op::Joint(k) => {
                    inputs.push(Input::Joint(r, k));
                    template.push(0.0);
                }
                Op::Sin(k) | Op::Cos(k) => {
                    let at = inputs
                        .iter()
                        .position(|x| matches!(x, Input::Trig { joint, .. } if *joint == k))
                        .unwrap_or_else(|| {
                            inputs.push(Input::Trig {
                                joint: k,
                                sin: None,
                                cos: None,
                            });
                            inputs.len() - 1
                        });
                    if let Input::Trig { sin, cos, .. } = &mut inputs[at] {
                        if matches!(op, Op::Sin(_)) {
                            *sin = Some(r);
                        } else {
                            *cos = Some(r);
                        }
                    }
                    template.push(0.0);
                }
                _ => continue,
            }
            reg[i] = r;
        }
        // The 1 and −0 that additions, subtractions, products and negations are written with
        // (see `Step`).
        let one = template.len() as u32;
        template.push(1.0);
        let neg_zero = template.len() as u32;
        template.push(-0.0);
        let first_free = template.len();

        // Operations: a register freed after its value's last use is reused.
        let mut free: Vec<u32> = Vec::new();
        let mut registers = first_free;
        let mut steps = Vec::new();
        // Values whose last use is at position `at` of the order, to free after it.
        let mut dies_at: Vec<Vec<usize>> = vec![Vec::new(); ops.len() + 1];
        for (v, &l) in last_use.iter().enumerate() {
            if live[v] && !fused[v] && l < end && reg[v] == u32::MAX {
                dies_at[l].push(v);
            }
        }
        for (at, &i) in order.iter().enumerate() {
            let op = &ops[i];
            if !live[i] || fused[i] || reg[i] != u32::MAX {
                continue;
            }
            let r = |v: ValueId| reg[v.index()];
            let product = |v: ValueId| match *program.op(v) {
                Op::Mul(x, y) if fused[v.index()] => Some((x, y)),
                _ => None,
            };
            // Operands are read before the destination is chosen, so the destination may
            // reuse an operand's register that dies here.
            // As a `Step`: fused products `x · y ± c` (`c − x · y` with `−x`), sums and
            // differences against 1, products and negations with −0 added.
            let make = |d: u32| {
                let s = |x: u32, y: u32, c: u32, kind: u8| Step { d, x, y, c, kind };
                match *op {
                    Op::Add(a, b) => match (product(a), product(b)) {
                        (Some((x, y)), _) => s(r(x), r(y), r(b), 0),
                        (None, Some((x, y))) => s(r(x), r(y), r(a), 0),
                        (None, None) => s(r(a), one, r(b), 0),
                    },
                    Op::Sub(a, b) => match (product(a), product(b)) {
                        (Some((x, y)), _) => s(r(x), r(y), r(b), NEG_C),
                        (None, Some((x, y))) => s(r(x), r(y), r(a), NEG_X),
                        (None, None) => s(r(a), one, r(b), NEG_C),
                    },
                    Op::Mul(a, b) => s(r(a), r(b), neg_zero, 0),
                    Op::Neg(a) => s(r(a), one, neg_zero, NEG_X),
                    Op::Div(a, b) => s(r(a), r(b), r(a), DIV),
                    Op::Sqrt(a) => s(r(a), r(a), r(a), SQRT),
                    Op::Abs(a) => s(r(a), r(a), r(a), ABS),
                    _ => unreachable!("inputs have registers already"),
                }
            };
            for &v in &dies_at[at] {
                free.push(reg[v]);
            }
            let d = free.pop().unwrap_or_else(|| {
                registers += 1;
                (registers - 1) as u32
            });
            steps.push(make(d));
            reg[i] = d;
        }
        template.resize(registers, 0.0);
        let operations = steps.len();
        let code = if registers <= SMALL_REGISTERS {
            Code::Small(steps.into_iter().map(Step::narrow).collect())
        } else {
            Code::Large(steps)
        };
        Compiled {
            template,
            inputs,
            inputs_end: first_free,
            code,
            operations,
            outputs: outputs.iter().map(|o| reg[o.index()]).collect(),
            joints,
            params: program.params().len(),
        }
    }

    /// Number of outputs.
    pub fn outputs(&self) -> usize {
        self.outputs.len()
    }

    /// Number of registers (the size of the scratch space of one evaluation).
    pub fn registers(&self) -> usize {
        self.template.len()
    }

    /// Number of arithmetic operations evaluated per configuration.
    pub fn operations(&self) -> usize {
        self.operations
    }

    /// Evaluates at joint values `q` (`joints` of them) and parameter values `params` into `out`
    /// (one entry per output, in the program's order), with `scratch` as register file (resized
    /// as needed: a caller that evaluates often keeps it and nothing is allocated).
    ///
    /// # Panics
    /// If `q`, `params` or `out` has the wrong length.
    pub fn eval_into(&self, q: &[f64], params: &[f64], scratch: &mut Vec<f64>, out: &mut [f64]) {
        assert_eq!(out.len(), self.outputs.len(), "one entry per output");
        self.eval_into_at(q, params, scratch, out, None);
    }

    /// [`Compiled::eval_into`] with output `j` written at `out[at[j]]` (a caller's layout, such
    /// as a row-major matrix, without a second copy; entries no output goes to are left as
    /// they are), or in order when `at` is `None`. Returns whether every output is finite.
    ///
    /// # Panics
    /// If `q` or `params` has the wrong length, `at` does not have one entry per output, or an
    /// entry is beyond `out`.
    pub fn eval_into_at(
        &self,
        q: &[f64],
        params: &[f64],
        scratch: &mut Vec<f64>,
        out: &mut [f64],
        at: Option<&[usize]>,
    ) -> bool {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx512f") {
                // SAFETY: the one requirement of calling a function compiled with
                // `target_feature(enable = "avx512f")` is that the CPU has AVX-512F, detected
                // just above.
                return unsafe { self.single_avx512(q, params, scratch, out, at) };
            }
        }
        self.single(q, params, scratch, out, at)
    }

    /// [`Compiled::single`] compiled for AVX-512F: the joints' sines and cosines in one vector
    /// register ([`Compiled::batch_avx512`] says why the results do not change).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    fn single_avx512(
        &self,
        q: &[f64],
        params: &[f64],
        scratch: &mut Vec<f64>,
        out: &mut [f64],
        at: Option<&[usize]>,
    ) -> bool {
        self.single(q, params, scratch, out, at)
    }

    /// The body of [`Compiled::eval_into_at`], inlined into each instruction-set variant.
    #[inline(always)]
    fn single(
        &self,
        q: &[f64],
        params: &[f64],
        scratch: &mut Vec<f64>,
        out: &mut [f64],
        at: Option<&[usize]>,
    ) -> bool {
        assert_eq!(q.len(), self.joints, "one value per joint");
        assert_eq!(params.len(), self.params, "one value per parameter");
        // Every register an operation writes is written before it is read (the program is in
        // order), so only the inputs' part with its literals is copied in; the rest of the file
        // is reused as it is.
        let size = match self.code {
            Code::Small(_) => SMALL_REGISTERS,
            Code::Large(_) => self.template.len(),
        };
        if scratch.len() < size {
            scratch.resize(size, 0.0);
        }
        scratch[..self.inputs_end].copy_from_slice(&self.template[..self.inputs_end]);
        let regs = scratch.as_mut_slice();
        // The sines and cosines, LANES joints side by side (each bit for bit `sin_cos`).
        let mut group = [0.0; LANES];
        let mut targets = [(None, None); LANES];
        let mut filled = 0;
        // Inlined, so that the lanes run on the variant's vector registers.
        #[inline(always)]
        fn flush(
            group: &[f64; LANES],
            targets: &[(Option<u32>, Option<u32>); LANES],
            filled: usize,
            regs: &mut [f64],
        ) {
            let (s, c) = fast::sin_cos_f64_lanes(group);
            for (k, &(rs, rc)) in targets.iter().enumerate().take(filled) {
                if let Some(r) = rs {
                    regs[r as usize] = s[k];
                }
                if let Some(r) = rc {
                    regs[r as usize] = c[k];
                }
            }
        }
        for &input in &self.inputs {
            match input {
                Input::Param(r, p) => regs[r as usize] = params[p],
                Input::Joint(r, k) => regs[r as usize] = q[k],
                Input::Trig { joint, sin, cos } => {
                    group[filled] = q[joint];
                    targets[filled] = (sin, cos);
                    filled += 1;
                    if filled == LANES {
                        flush(&group, &targets, filled, regs);
                        filled = 0;
                    }
                }
            }
        }
        if filled > 0 {
            // Padding repeats the last joint (any finite value would do).
            let last = group[filled - 1];
            group[filled..].fill(last);
            flush(&group, &targets, filled, regs);
        }
        match &self.code {
            Code::Small(code) => {
                let regs: &mut [f64; SMALL_REGISTERS] = (&mut regs[..SMALL_REGISTERS])
                    .try_into()
                    .expect("resized to SMALL_REGISTERS above");
                run(code, regs);
            }
            Code::Large(code) => run(code, regs),
        }
        let mut finite = true;
        match at {
            None => {
                for (o, &r) in out.iter_mut().zip(&self.outputs) {
                    *o = regs[r as usize];
                    finite &= o.is_finite();
                }
            }
            Some(at) => {
                assert_eq!(at.len(), self.outputs.len(), "one position per output");
                for (&k, &r) in at.iter().zip(&self.outputs) {
                    out[k] = regs[r as usize];
                    finite &= out[k].is_finite();
                }
            }
        }
        finite
    }

    /// [`Compiled::eval_into`] returning a new vector.
    pub fn eval(&self, q: &[f64], params: &[f64]) -> Vec<f64> {
        thread_local! {
            /// The registers of the last evaluation on this thread, reused (every register is
            /// written before it is read).
            static SCRATCH: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
        }
        let mut out = vec![0.0; self.outputs.len()];
        SCRATCH.with(|scratch| match scratch.try_borrow_mut() {
            Ok(mut scratch) => self.eval_into(q, params, &mut scratch, &mut out),
            Err(_) => self.eval_into(q, params, &mut Vec::new(), &mut out),
        });
        out
    }

    /// Evaluates at `q.len() / joints` configurations, `q` holding them one after the other
    /// (row-major `count × joints`), with the same parameter values; `out` receives the outputs of
    /// each configuration one after the other (`count × outputs`). [`LANES`] configurations are
    /// evaluated side by side; each one's outputs equal [`Compiled::eval`]'s bit for bit.
    ///
    /// # Panics
    /// If the lengths do not match.
    pub fn eval_batch(&self, q: &[f64], params: &[f64], out: &mut [f64]) {
        let order: Vec<usize> = (0..self.outputs.len()).collect();
        self.eval_batch_ordered(q, params, out, self.outputs.len(), &order);
    }

    /// [`Compiled::eval_batch`] into blocks of `stride` entries per configuration, output `j`
    /// written at position `order[j]` of its configuration's block (a caller's layout, such as a
    /// row-major matrix or a homogeneous transform, without a second copy; positions no output
    /// goes to are left as they are). Returns whether every output is finite.
    ///
    /// # Panics
    /// If the lengths do not match, or two outputs share a position, or one is beyond `stride`.
    pub fn eval_batch_ordered(
        &self,
        q: &[f64],
        params: &[f64],
        out: &mut [f64],
        stride: usize,
        order: &[usize],
    ) -> bool {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx512f") {
                // SAFETY: the one requirement of calling a function compiled with
                // `target_feature(enable = "avx512f")` is that the CPU has AVX-512F, detected
                // just above.
                return unsafe { self.batch_avx512(q, params, out, stride, order) };
            }
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: as above, for AVX2, detected just above.
                return unsafe { self.batch_avx2(q, params, out, stride, order) };
            }
        }
        self.batch(q, params, out, stride, order)
    }

    /// [`Compiled::batch`] compiled for AVX-512F: the lanes in one vector register. No fused
    /// multiply-add is formed (Rust does not contract `x * y + z`), so every lane rounds as
    /// [`Compiled::eval`] does.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    fn batch_avx512(
        &self,
        q: &[f64],
        params: &[f64],
        out: &mut [f64],
        stride: usize,
        order: &[usize],
    ) -> bool {
        self.batch(q, params, out, stride, order)
    }

    /// [`Compiled::batch`] compiled for AVX2 (two vector registers a lane group).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn batch_avx2(
        &self,
        q: &[f64],
        params: &[f64],
        out: &mut [f64],
        stride: usize,
        order: &[usize],
    ) -> bool {
        self.batch(q, params, out, stride, order)
    }

    /// The body of [`Compiled::eval_batch_ordered`], inlined into each instruction-set variant.
    #[inline(always)]
    fn batch(
        &self,
        q: &[f64],
        params: &[f64],
        out: &mut [f64],
        stride: usize,
        order: &[usize],
    ) -> bool {
        assert_eq!(order.len(), self.outputs.len(), "one position per output");
        // Registers read for each position of a block (`None`: left as it is).
        let mut source: Vec<Option<u32>> = vec![None; stride];
        for (j, &o) in order.iter().enumerate() {
            assert!(
                source[o].replace(self.outputs[j]).is_none(),
                "one output a position"
            );
        }
        // (position in the block, register), by position.
        let placed: Vec<(usize, u32)> = source
            .iter()
            .enumerate()
            .filter_map(|(at, r)| Some((at, (*r)?)))
            .collect();
        let mut finite = true;
        let n = self.joints;
        let m = stride;
        let count = match (n, m) {
            (0, 0) => 0,
            (0, _) => out.len() / m,
            _ => q.len() / n,
        };
        assert_eq!(q.len(), count * n, "whole configurations");
        assert_eq!(
            out.len(),
            count * m,
            "one block of outputs per configuration"
        );
        assert_eq!(params.len(), self.params, "one value per parameter");
        let mut regs: Vec<[f64; LANES]> = self.template.iter().map(|&c| [c; LANES]).collect();
        if let Code::Small(_) = self.code {
            regs.resize(SMALL_REGISTERS, [0.0; LANES]);
        }
        for &input in &self.inputs {
            if let Input::Param(r, p) = input {
                regs[r as usize] = [params[p]; LANES];
            }
        }
        let mut first = 0;
        while first < count {
            let lanes = LANES.min(count - first);
            // Joint values of the lanes; an incomplete last block repeats its last configuration.
            let joint = |k: usize| -> [f64; LANES] {
                core::array::from_fn(|l| q[(first + l.min(lanes - 1)) * n + k])
            };
            for &input in &self.inputs {
                match input {
                    Input::Param(..) => {}
                    Input::Joint(r, k) => regs[r as usize] = joint(k),
                    Input::Trig { joint: k, sin, cos } => {
                        let (s, c) = fast::sin_cos_f64_lanes(&joint(k));
                        if let Some(r) = sin {
                            regs[r as usize] = s;
                        }
                        if let Some(r) = cos {
                            regs[r as usize] = c;
                        }
                    }
                }
            }
            match &self.code {
                Code::Small(code) => {
                    let small: &mut [[f64; LANES]; SMALL_REGISTERS] = (&mut regs
                        [..SMALL_REGISTERS])
                        .try_into()
                        .expect("resized to SMALL_REGISTERS above");
                    run_lanes(code, small);
                }
                Code::Large(code) => run_lanes(code, &mut regs),
            }
            // Output by output, all lanes at once (the lanes beyond `lanes` repeat the last
            // configuration, so they are finite when it is).
            let block = &mut out[first * m..(first + lanes) * m];
            for &(at, r) in &placed {
                let v = &regs[r as usize];
                finite &= v.iter().fold(true, |all, x| all & x.is_finite());
                for (l, x) in v.iter().enumerate().take(lanes) {
                    block[l * m + at] = *x;
                }
            }
            first += lanes;
        }
        finite
    }
}

/// The values `op` reads when evaluated as compiled: a fused product's factors in place of the
/// product.
fn operands_as_evaluated(program: &Program, fused: &[bool], op: &Op) -> Vec<ValueId> {
    let mut out = Vec::with_capacity(4);
    for a in op.operands() {
        match *program.op(a) {
            Op::Mul(x, y) if fused[a.index()] => {
                out.push(x);
                out.push(y);
            }
            _ => out.push(a),
        }
    }
    out
}

/// The sign bit of an `f64` when `flag` (one bit) is set in `kind`.
#[inline(always)]
fn sign(kind: u8, flag: u8) -> u64 {
    ((kind & flag) as u64) << (63 - flag.trailing_zeros())
}

/// One [`Step`] on its operands' values.
#[inline(always)]
fn apply(kind: u8, x: f64, y: f64, c: f64) -> f64 {
    if kind < DIV {
        Real::mul_add(
            f64::from_bits(x.to_bits() ^ sign(kind, NEG_X)),
            y,
            f64::from_bits(c.to_bits() ^ sign(kind, NEG_C)),
        )
    } else if kind == DIV {
        x / y
    } else if kind == SQRT {
        Real::sqrt(x)
    } else {
        Real::abs(x)
    }
}

/// Runs the operations on one register file (`V` a fixed-size array for `u8` registers, where
/// no access needs a bounds check, or a slice).
#[inline(always)]
fn run<R: Reg, V: std::ops::IndexMut<usize, Output = f64> + ?Sized>(steps: &[Step<R>], v: &mut V) {
    for s in steps {
        v[s.d.at()] = apply(s.kind, v[s.x.at()], v[s.y.at()], v[s.c.at()]);
    }
}

/// Runs the operations on [`LANES`] register files side by side (inlined into each
/// instruction-set variant of the batch evaluation); the lanes of a step are one vector
/// operation, the same in every lane.
#[inline(always)]
fn run_lanes<R: Reg, V: std::ops::IndexMut<usize, Output = [f64; LANES]> + ?Sized>(
    steps: &[Step<R>],
    v: &mut V,
) {
    for s in steps {
        let (x, y, c) = (v[s.x.at()], v[s.y.at()], v[s.c.at()]);
        v[s.d.at()] = if s.kind < DIV {
            let (sx, sc) = (sign(s.kind, NEG_X), sign(s.kind, NEG_C));
            core::array::from_fn(|l| {
                Real::mul_add(
                    f64::from_bits(x[l].to_bits() ^ sx),
                    y[l],
                    f64::from_bits(c[l].to_bits() ^ sc),
                )
            })
        } else {
            core::array::from_fn(|l| apply(s.kind, x[l], y[l], c[l]))
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `(s0 c1 + q0 p0)·(s0 c1 + q0 p0) − 3 / q1` with a shared subexpression, a literal and a
    /// parameter: compiled and batch results against the same expression written in Rust.
    #[test]
    fn compiled_matches_written_out() {
        let mut p = Program::new(vec!["p0".into()]);
        let s0 = p.sin(0);
        let c1 = p.cos(1);
        let q0 = p.joint(0);
        let q1 = p.joint(1);
        let p0 = p.param(0);
        let a = p.mul(s0, c1);
        let b = p.mul(q0, p0);
        let x = p.add(a, b);
        let sq = p.mul(x, x);
        let three = p.constant(3.0);
        let d = p.div(three, q1);
        let y = p.sub(sq, d);
        let r = p.sqrt(sq);
        p.set_outputs(vec![y, r, x]);
        let c = Compiled::new(&p, 2);
        let expect = |q: [f64; 2], k: f64| {
            let (s0, _) = Real::sin_cos(q[0]);
            let (_, c1) = Real::sin_cos(q[1]);
            let x: f64 = s0 * c1 + q[0] * k;
            [x * x - 3.0 / q[1], (x * x).sqrt(), x]
        };
        let qs: Vec<[f64; 2]> = (0..19)
            .map(|i| [0.3 * i as f64 - 2.0, 0.7 + 0.11 * i as f64])
            .collect();
        for q in &qs {
            let got = c.eval(q, &[0.25]);
            assert_eq!(got, expect(*q, 0.25).to_vec());
        }
        let flat: Vec<f64> = qs.iter().flatten().copied().collect();
        let mut out = vec![0.0; qs.len() * 3];
        c.eval_batch(&flat, &[0.25], &mut out);
        for (k, q) in qs.iter().enumerate() {
            let want = expect(*q, 0.25);
            for j in 0..3 {
                assert_eq!(out[k * 3 + j].to_bits(), want[j].to_bits());
            }
        }
    }

    /// Every operation, written as one `Real::mul_add` with 1 or −0 (see `Step`), gives the
    /// bits of the operation itself, signed zeros, infinities and subnormals included, one
    /// configuration at a time and in lanes.
    #[test]
    fn single_form_keeps_every_bit() {
        let mut p = Program::new(vec![]);
        let (a, b, c) = (p.joint(0), p.joint(1), p.joint(2));
        let outs = vec![
            p.add(a, b),
            p.sub(a, b),
            p.mul(a, b),
            p.neg(a),
            p.div(a, b),
            p.abs(a),
        ];
        let ab = p.mul(a, b);
        let fused = [p.add(ab, c), p.sub(ab, c)];
        let ab2 = p.mul(a, b);
        let sub_mul = p.sub(c, ab2);
        let mut all = outs.clone();
        all.extend(fused);
        all.push(sub_mul);
        p.set_outputs(all);
        let compiled = Compiled::new(&p, 3);
        let specials = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            f64::MIN_POSITIVE / 8.0,
            -f64::MIN_POSITIVE / 8.0,
            f64::MAX,
            f64::INFINITY,
            f64::NEG_INFINITY,
            0.3,
        ];
        let mut qs = Vec::new();
        for &x in &specials {
            for &y in &specials {
                for &z in &[0.0, -0.0, 2.5] {
                    qs.push([x, y, z]);
                }
            }
        }
        let flat: Vec<f64> = qs.iter().flatten().copied().collect();
        let m = compiled.outputs();
        let mut batch = vec![0.0; qs.len() * m];
        compiled.eval_batch(&flat, &[], &mut batch);
        for (k, &[x, y, z]) in qs.iter().enumerate() {
            let want = [
                x + y,
                x - y,
                x * y,
                -x,
                x / y,
                x.abs(),
                Real::mul_add(x, y, z),
                Real::mul_add(x, y, -z),
                Real::mul_add(-x, y, z),
            ];
            let got = compiled.eval(&[x, y, z], &[]);
            for j in 0..m {
                let same =
                    |v: f64| v.to_bits() == want[j].to_bits() || (v.is_nan() && want[j].is_nan());
                assert!(
                    same(got[j]),
                    "output {j} at {:?}: {} != {}",
                    [x, y, z],
                    got[j],
                    want[j]
                );
                assert!(
                    same(batch[k * m + j]),
                    "lanes, output {j} at {:?}",
                    [x, y, z]
                );
            }
        }
    }

    /// Registers are reused: a long chain of sums needs a handful, not one per operation.
    #[test]
    fn registers_are_reused() {
        let mut p = Program::new(vec![]);
        let mut acc = p.joint(0);
        for k in 0..200 {
            let c = p.constant(1.0 + k as f64);
            let m = p.mul(acc, c);
            acc = p.add(m, acc);
        }
        p.set_outputs(vec![acc]);
        let c = Compiled::new(&p, 1);
        assert!(c.registers() < 210 + 8, "{} registers", c.registers());
        assert!(c.operations() >= 200);
        let mut x = 0.5_f64;
        for k in 0..200 {
            x = Real::mul_add(x, 1.0 + k as f64, x);
        }
        assert_eq!(c.eval(&[0.5], &[]), vec![x]);
    }
}
