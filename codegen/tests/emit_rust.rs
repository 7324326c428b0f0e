//! Emission of a small hand-built module: token/string snapshot and operation counts in docs.

use trocar_codegen::emit::{format_file, module_tokens};
use trocar_codegen::ir::{
    ConstItem, EmittedFunction, Factor, Layout, ModuleSpec, Program, Real, Term,
};

fn params() -> Vec<String> {
    vec!["l_a".into(), "l_b".into(), "l_8".into()]
}

/// Three entries of (3.24) and a scalar, on joints 7 and 8 of an 8-joint robot.
fn small_module() -> ModuleSpec {
    let mut j = Program::new(params());
    // Column 1 of (3.24): α1, lb s7/la, α2, −s8/la, 0, c8/la.
    let col1 = [
        vec![
            Term::new(
                -1.0,
                [
                    (Factor::Cos(7), 1),
                    (Factor::Param(2), 1),
                    (Factor::Param(0), -1),
                ],
            ),
            Term::new(
                -1.0,
                [
                    (Factor::Cos(6), 1),
                    (Factor::Cos(7), 1),
                    (Factor::Param(1), 1),
                    (Factor::Param(0), -1),
                ],
            ),
        ],
        vec![Term::new(
            1.0,
            [
                (Factor::Param(1), 1),
                (Factor::Sin(6), 1),
                (Factor::Param(0), -1),
            ],
        )],
        vec![
            Term::new(
                -1.0,
                [
                    (Factor::Sin(7), 1),
                    (Factor::Param(2), 1),
                    (Factor::Param(0), -1),
                ],
            ),
            Term::new(
                -1.0,
                [
                    (Factor::Cos(6), 1),
                    (Factor::Sin(7), 1),
                    (Factor::Param(1), 1),
                    (Factor::Param(0), -1),
                ],
            ),
        ],
        vec![Term::new(
            -1.0,
            [(Factor::Sin(7), 1), (Factor::Param(0), -1)],
        )],
        vec![],
        vec![Term::new(
            1.0,
            [(Factor::Cos(7), 1), (Factor::Param(0), -1)],
        )],
    ];
    // Column 2: c8 s7, c7, s7 s8, 0, 0, 0.
    let col2 = [
        vec![Term::new(1.0, [(Factor::Cos(7), 1), (Factor::Sin(6), 1)])],
        vec![Term::new(1.0, [(Factor::Cos(6), 1)])],
        vec![Term::new(1.0, [(Factor::Sin(6), 1), (Factor::Sin(7), 1)])],
        vec![],
        vec![],
        vec![],
    ];
    let outs: Vec<_> = col1
        .iter()
        .chain(col2.iter())
        .map(|t| j.sum_of_monomials(t))
        .collect();
    j.set_outputs(outs);
    let mut w = Program::new(params());
    // (3.42): w = lb² |s7| / la².
    let t = Term::new(
        1.0,
        [
            (Factor::Param(1), 2),
            (Factor::Sin(6), 1),
            (Factor::Param(0), -2),
        ],
    );
    let v = w.sum_of_monomials(&[t]);
    let a = w.abs(v);
    w.set_outputs(vec![a]);
    ModuleSpec {
        name: "small".into(),
        doc: "A hand-built module for the emitter's tests.".into(),
        joints: 8,
        params: vec![
            ("l_a".into(), 0.15),
            ("l_b".into(), 0.18),
            ("l_8".into(), 0.21),
        ],
        consts: vec![ConstItem {
            name: "N".into(),
            value: 8,
            doc: "Number of joints.".into(),
        }],
        functions: vec![
            EmittedFunction {
                name: "two_columns".into(),
                summary: "The first two columns of `J^r_0e`".into(),
                equation: "(3.24)".into(),
                details: String::new(),
                layout: Layout::Matrix { rows: 6, cols: 2 },
                program: j,
                dims: None,
                takes_joints: true,
                zero_when_not_finite: false,
            },
            EmittedFunction {
                name: "manipulability".into(),
                summary: "Manipulability".into(),
                equation: "(3.42)".into(),
                details: String::new(),
                layout: Layout::Scalar,
                program: w,
                dims: None,
                takes_joints: true,
                zero_when_not_finite: false,
            },
        ],
        controller: None,
        joint_limits: None,
        joint_ranges: Vec::new(),
        joint_speed_limits: Vec::new(),
        joint_acceleration_limits: Vec::new(),
        joint_jerk_limits: Vec::new(),
        pose_and_jacobians: None,
        fused: Vec::new(),
        fma_at_run_time: false,
    }
}

/// prost-style golden file: the test rewrites it and fails when it changed, so updating is one
/// `cargo test` and the change is reviewed in the diff.
pub fn check_golden(path: &str, actual: &str) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(path);
    let old = std::fs::read_to_string(&path).unwrap_or_default();
    if old != actual {
        std::fs::write(&path, actual).expect("write golden file");
        panic!(
            "{} changed; it has been rewritten — review the diff and re-run",
            path.display()
        );
    }
}

#[test]
fn small_module_snapshot() {
    let spec = small_module();
    let text = format_file(module_tokens(&spec, Real::Generic)).unwrap();
    assert!(text.starts_with("// This file is @generated by trocar-codegen. Do not edit."));
    // The lines as prettyplease wraps them, joined by single spaces.
    let flat = text.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(flat.contains(
        "pub fn two_columns<T: ::trocar::emitted::Arith>( q: &[T; N], p: &Params<T>, ) -> [[T; 6]; 2]"
    ));
    assert!(flat.contains(
        "let ([s7, s8], [c7, c8]) = <T as ::trocar::emitted::Arith>::sin_cos_array( &[q[6], q[7]], );"
    ));
    // Only what a function uses is bound.
    assert!(
        text.contains("let ([s7], [_]) = <T as ::trocar::emitted::Arith>::sin_cos_array(&[q[6]]);")
    );
    check_golden("tests/snapshots/emit_small.rs", &text);
}

#[test]
fn monomorphic_f32_literals_are_suffixed() {
    let spec = small_module();
    let text = format_file(module_tokens(&spec, Real::F32)).unwrap();
    assert!(text.contains("l_a: 0.15_f32"), "{text}");
    assert!(text.contains("pub fn manipulability(q: &[f32; N], p: &Params) -> f32"));
    assert!(!text.contains("<T"), "{text}");
}

#[test]
fn op_counts_are_documented() {
    let spec = small_module();
    let counts = spec.functions[1].program.op_counts();
    // lb² |s7| / la²: inverse once, squares, products.
    assert_eq!((counts.div, counts.abs, counts.trig), (1, 1, 1), "{counts}");
    let text = format_file(module_tokens(&spec, Real::Generic)).unwrap();
    assert!(
        text.contains(&format!("/// Operations: {counts}.")),
        "{text}"
    );
}
