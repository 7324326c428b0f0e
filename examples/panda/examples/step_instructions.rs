//! Instruction count of one control step of the Panda example (f32, generated kinematics), for
//! callgrind:
//!
//! ```text
//! cargo build --release -p trocar-panda --example step_instructions
//! valgrind --tool=callgrind --toggle-collect='*measured_loop*' \
//!     target/release/examples/step_instructions qp 10000
//! ```
//!
//! `step_instructions dls|qp N` runs N steps inside `measured_loop` from the same state (the
//! Panda's start, the reference 5 mm off the tip, the tip pulled 8 cm toward the trocar for the
//! QP so that its depth bound is active), so the collected count divided by N is instructions
//! per step. Prints the last step's rates so nothing is optimised away.

use std::hint::black_box;
use trocar::control::Reference;
use trocar::nalgebra::{Matrix3, Vector3};
use trocar_panda::{control_step, controller, panda, qp_controller, PandaController, Q0};

#[inline(never)]
fn measured_loop(n: usize, f: &mut dyn FnMut()) {
    for _ in 0..n {
        f();
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (which, n) = match args.as_slice() {
        [_, which, n] => match n.parse::<usize>() {
            Ok(n) => (which.as_str(), n),
            Err(e) => {
                eprintln!("error: N: {e}");
                std::process::exit(2);
            }
        },
        _ => {
            eprintln!("usage: step_instructions dls|qp N");
            std::process::exit(2);
        }
    };
    let params = panda::Params::nominal();
    let (r, p) = panda::forward_kinematics(&Q0, &params);
    let (ri, pi) = panda::forward_kinematics_i(&Q0, &params);
    let trocar = [0, 1, 2].map(|k| pi[k] + 0.357 * ri[2][k]);
    let z = Vector3::new(r[2][0], r[2][1], r[2][2]);
    let (mut ctrl, offset): (PandaController, Vector3<f32>) = match which {
        "dls" => (controller(), Vector3::new(0.005, 0.0, 0.0)),
        "qp" => (qp_controller(), -z * 0.08),
        other => {
            eprintln!("error: unknown step `{other}` (dls | qp)");
            std::process::exit(2);
        }
    };
    let reference = Reference {
        position: Vector3::from(p) + offset,
        rotation: Matrix3::from_data(trocar::nalgebra::ArrayStorage(r)),
        velocity: Vector3::zeros(),
        angular_velocity: Vector3::zeros(),
    };
    let mut last = [0.0f32; panda::N];
    let mut failed = false;
    measured_loop(n, &mut || match control_step(
        &mut ctrl,
        black_box(&Q0),
        &reference,
        &trocar,
        0.002,
    ) {
        Ok(out) => last = out.qd.into(),
        Err(_) => failed = true,
    });
    if failed {
        eprintln!("error: a step failed");
        std::process::exit(1);
    }
    println!("{which}: {last:?}");
}
