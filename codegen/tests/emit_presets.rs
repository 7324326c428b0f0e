//! Emission of the shipped descriptions: every module formats, op counts are printed, and the
//! interpreted programs agree with the derivation's expanded polynomials. How long generation
//! takes is measured by `cargo bench -p trocar-codegen --bench generation`.

use trocar_codegen::catalogue::Function;
use trocar_codegen::derivation::derive;
use trocar_codegen::lower::module_spec;
use trocar_codegen::{generate_module_string, ModuleOptions};
use trocar_model::description::{preset_names, RobotDescription};

#[test]
fn presets_generate_and_print_op_counts() {
    for name in preset_names() {
        let desc = RobotDescription::preset(name).unwrap();
        let text = generate_module_string(&desc, &ModuleOptions::default()).unwrap();
        assert!(text.len() > 1000, "{name}");
        println!("{name}: {} lines", text.lines().count());
        let d = derive(&desc).unwrap();
        let spec = module_spec(&d, "m");
        for f in &spec.functions {
            println!("  {:<24} {}", f.name, f.program.op_counts());
        }
    }
}

/// The programs built from the derivation (Horner factoring, CSE, product-form FK) evaluate to
/// the derivation's expanded polynomials.
#[test]
fn programs_agree_with_expanded_polynomials() {
    use trocar_codegen::evaluate::Compiled;
    use trocar_codegen::lower::{manipulability_from_jr, matrix_program};
    use trocar_codegen::symbolic::Env;
    for name in preset_names() {
        let desc = RobotDescription::preset(name).unwrap();
        let d = derive(&desc).unwrap();
        let c = d.constraint.as_ref().unwrap();
        let spec = module_spec(&d, "m");
        // The fallback used when the derivation has no closed-form manipulability (of S J^r
        // with a task).
        let commanded = c.task.as_ref().map_or(&c.jr, |t| &t.jacobian);
        let fallback = manipulability_from_jr(&d, commanded);
        let by_name = |f: Function| &spec.function(f).unwrap().program;
        let mut seed = 0x1234_5678_9abc_def1u64;
        for _ in 0..200 {
            let mut rnd = || {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                (seed >> 11) as f64 / (1u64 << 53) as f64
            };
            let q: Vec<f64> = (0..d.n).map(|_| rnd() * 6.0 - 3.0).collect();
            let params: Vec<f64> = d
                .param_values
                .iter()
                .map(|v| v * (0.7 + 0.6 * rnd()))
                .collect();
            let env = Env {
                q: &q,
                params: &params,
            };
            let col_major = |m: &trocar_codegen::symbolic::Matrix| {
                let rows = m.eval(&env);
                let mut v = Vec::new();
                for j in 0..m.cols() {
                    for row in &rows {
                        v.push(row[j]);
                    }
                }
                v
            };
            let fk_e = d.fk_e.as_ref().unwrap();
            let mut fk = col_major(&fk_e.rot);
            fk.extend(col_major(&fk_e.pos));
            for (prog, expected) in [
                (by_name(Function::ConstrainedJacobian), col_major(&c.jr)),
                (by_name(Function::ConstraintJacobianC), col_major(&c.jc)),
                (
                    by_name(Function::PartialBodyJacobian),
                    col_major(&c.body_jacobian_i),
                ),
                (
                    by_name(Function::BodyJacobian),
                    col_major(d.body_jacobian_e.as_ref().unwrap()),
                ),
                (by_name(Function::ForwardKinematics), fk),
                (
                    by_name(Function::ManipulabilitySquared),
                    vec![c.manipulability.as_ref().unwrap().squared.eval(&env)],
                ),
                (
                    &fallback.1,
                    vec![c.manipulability.as_ref().unwrap().squared.eval(&env)],
                ),
                (&matrix_program(&d, &c.jr), col_major(&c.jr)),
            ] {
                let got = Compiled::new(prog, q.len()).eval(&q, &params);
                let scale = expected.iter().fold(1.0f64, |a, x| a.max(x.abs()));
                for (g, e) in got.iter().zip(&expected) {
                    assert!((g - e).abs() <= 1e-12 * scale, "{name}: {g} vs {e}");
                }
            }
        }
    }
}

/// Every constrained preset gets `pose_and_jacobians_trig` from one program (smaller than its
/// four functions'); without that program the function calls the four, and the module still
/// formats (its types are those of the four functions).
#[test]
fn pose_and_jacobians_is_one_program_or_the_four_functions() {
    use trocar_codegen::emit::{format_file, module_tokens};
    use trocar_codegen::Real;
    for name in preset_names() {
        let desc = RobotDescription::preset(name).unwrap();
        let d = derive(&desc).unwrap();
        let mut spec = module_spec(&d, "m");
        let fused = spec.pose_and_jacobians.as_ref().expect("one program");
        let separate: usize = [
            Function::ForwardKinematics,
            Function::PartialBodyJacobian,
            Function::ConstrainedJacobian,
            Function::ConstraintJacobianC,
        ]
        .iter()
        .map(|&f| spec.function(f).unwrap().program.live_len())
        .sum();
        assert!(fused.live_len() < separate, "{name}");
        let c = d.constraint.as_ref().unwrap();
        assert_eq!(
            fused.outputs().len(),
            12 + 6 * (c.link + c.m + c.r),
            "{name}"
        );
        spec.pose_and_jacobians = None;
        let text = format_file(module_tokens(&spec, Real::Generic)).unwrap();
        let body = &text[text.find("pub fn pose_and_jacobians_trig").unwrap()..];
        let body = &body[..body.find("\n    }\n").unwrap()];
        for f in [
            "forward_kinematics_trig(t, p)",
            "partial_body_jacobian_trig(t, p)",
            "constrained_jacobian_trig(t, p)",
            "constraint_jacobian_c_trig(t, p)",
        ] {
            assert!(body.contains(f), "{name}: {f} in\n{body}");
        }
    }
}
