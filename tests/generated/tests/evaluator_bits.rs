//! The compiled evaluator (`trocar_codegen::evaluate::Compiled`, what `trocar eval`, the
//! library's `Robot::eval` and Python's `Robot.eval`/`eval_many` run) against the compiled
//! generated modules of the same descriptions: every function, at random configurations and
//! parameter values, equal bit for bit — one value at a time and in batches.

use trocar_codegen::catalogue::Function;
use trocar_codegen::evaluate::Generated;
use trocar_model::description::RobotDescription;

fn description(path: &str) -> RobotDescription {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(path);
    RobotDescription::from_toml_file(&p).unwrap_or_else(|e| panic!("{e}"))
}

/// A small deterministic generator (xorshift), so a failure names a reproducible sample.
struct Rng(u64);

impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// The outputs of a generated function in the emitted layout: matrices column by column, a
/// transform as `R` column by column then `p`.
trait Flat {
    fn flat(&self) -> Vec<f64>;
}

impl Flat for f64 {
    fn flat(&self) -> Vec<f64> {
        vec![*self]
    }
}

impl<const R: usize, const C: usize> Flat for [[f64; R]; C] {
    fn flat(&self) -> Vec<f64> {
        self.iter().flatten().copied().collect()
    }
}

impl Flat for ([[f64; 3]; 3], [f64; 3]) {
    fn flat(&self) -> Vec<f64> {
        self.0.iter().flatten().chain(&self.1).copied().collect()
    }
}

fn assert_bits(robot: &str, f: Function, q: &[f64], got: &[f64], want: &[f64]) {
    assert_eq!(got.len(), want.len(), "{robot}: `{f}` output count");
    for (k, (a, b)) in got.iter().zip(want).enumerate() {
        assert!(
            a.to_bits() == b.to_bits(),
            "{robot}: `{f}` output {k} at q = {q:?}: evaluator {a:e}, generated code {b:e}"
        );
    }
}

/// Checks the functions `$f => $call` of module `$m` (generic modules, instantiated in `f64`)
/// against `Generated` of the description at `$path`, one configuration at a time and as one
/// batch of 37 (four full lane groups and a partial one).
macro_rules! bit_identical {
    ($test:ident, $m:ident, $path:literal, params: [$($p:ident),*], [$($f:ident => $call:ident),* $(,)?]) => {
        #[test]
        fn $test() {
            use trocar_tests_generated::$m as g;
            let desc = description($path);
            let generated = Generated::new(&desc).unwrap();
            let nominal = generated.nominal_params();
            let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
            let mut batch_q: Vec<f64> = Vec::new();
            let mut batch_want: Vec<Vec<Vec<f64>>> = Vec::new();
            // One configuration at a time, parameters at 0.7–1.3 × nominal.
            for _ in 0..200 {
                let q: [f64; g::N] = core::array::from_fn(|_| rng.uniform(-3.0, 3.0));
                let mut p = g::Params::<f64>::nominal();
                let mut values = nominal.clone();
                let mut k = 0;
                $(
                    p.$p *= rng.uniform(0.7, 1.3);
                    values[k] = p.$p;
                    k += 1;
                )*
                assert_eq!(k, values.len(), "every parameter listed, in declaration order");
                $(
                    let want = g::$call(&q, &p).flat();
                    let got = generated.outputs(Function::$f, &q, &values).unwrap();
                    assert_bits(stringify!($m), Function::$f, &q, &got, &want);
                )*
            }
            // A batch at the nominal parameters.
            let p = g::Params::<f64>::nominal();
            for _ in 0..37 {
                let q: [f64; g::N] = core::array::from_fn(|_| rng.uniform(-3.0, 3.0));
                batch_q.extend_from_slice(&q);
                batch_want.push(vec![$(g::$call(&q, &p).flat()),*]);
            }
            let mut which = 0;
            $(
                let c = generated.compiled(Function::$f).unwrap();
                let m = c.outputs();
                let mut out = vec![0.0; 37 * m];
                c.eval_batch(&batch_q, &nominal, &mut out);
                for s in 0..37 {
                    assert_bits(
                        stringify!($m),
                        Function::$f,
                        &batch_q[s * g::N..(s + 1) * g::N],
                        &out[s * m..(s + 1) * m],
                        &batch_want[s][which],
                    );
                }
                which += 1;
            )*
            let _ = which;
        }
    };
}

bit_identical!(
    panda_laparoscope,
    panda_laparoscope,
    "../../runtime/model/robots/panda-laparoscope.toml",
    params: [l_a],
    [
        ForwardKinematics => forward_kinematics,
        BodyJacobian => body_jacobian,
        ConstrainedJacobian => constrained_jacobian,
        ConstraintJacobianC => constraint_jacobian_c,
        PartialBodyJacobian => partial_body_jacobian,
        ConstrainedLinkKinematics => forward_kinematics_i,
        ManipulabilitySquared => manipulability_squared,
        ConstrainedTaskJacobian => constrained_task_jacobian,
    ]
);

bit_identical!(
    dia10_like_zy,
    dia10_like_zy,
    "../../runtime/model/robots/dia10_like_zy.toml",
    params: [l_a],
    [
        ForwardKinematics => forward_kinematics,
        BodyJacobian => body_jacobian,
        ConstrainedJacobian => constrained_jacobian,
        ConstraintJacobianC => constraint_jacobian_c,
        PartialBodyJacobian => partial_body_jacobian,
        ConstrainedLinkKinematics => forward_kinematics_i,
        ManipulabilitySquared => manipulability_squared,
    ]
);

bit_identical!(
    chain9_prismatic,
    chain9_prismatic,
    "robots/chain9_prismatic.toml",
    params: [l_a, d_1],
    [
        ForwardKinematics => forward_kinematics,
        BodyJacobian => body_jacobian,
        ConstrainedJacobian => constrained_jacobian,
        PartialBodyJacobian => partial_body_jacobian,
        ManipulabilitySquared => manipulability_squared,
    ]
);

bit_identical!(
    iiwa_link6,
    iiwa_link6,
    "../../runtime/model/robots/iiwa-link6.toml",
    params: [l_a],
    [
        ForwardKinematics => forward_kinematics,
        ConstrainedJacobian => constrained_jacobian,
        PartialBodyJacobian => partial_body_jacobian,
        ConstraintJacobianC => constraint_jacobian_c,
    ]
);
