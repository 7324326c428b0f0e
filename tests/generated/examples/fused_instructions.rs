//! Instruction count of the Panda laparoscope's fused functions (`f64`), for callgrind:
//!
//! ```text
//! cargo build --release -p trocar-tests-generated --example fused_instructions
//! valgrind --tool=callgrind --toggle-collect='*measured_loop*' \
//!     target/release/examples/fused_instructions link_pose_and_jacobian 10000
//! ```
//!
//! `fused_instructions FUNCTION N` evaluates one function N times inside `measured_loop`,
//! cycling through 16 configurations (the index through `black_box`), so the collected count
//! divided by N is instructions per evaluation (the loop's few instructions included).
//! FUNCTION: `pose_and_jacobian`, `pose_and_jacobian_trig`, `link_pose_and_jacobian`,
//! `link_pose_and_jacobian_trig` (the generic module at `f64`), `link_pose_and_jacobian_f64`,
//! `link_pose_and_jacobian_trig_f64` (`fma_at_run_time`: fused multiply-adds chosen at run time).

use std::hint::black_box;
use trocar_tests_generated::{panda_fma, panda_laparoscope as panda};

#[inline(never)]
fn measured_loop(n: usize, f: &mut dyn FnMut(usize)) {
    for k in 0..n {
        f(black_box(k % 16));
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (which, n) = match args.as_slice() {
        [_, which, n] => match n.parse::<usize>() {
            Ok(n) => (which.clone(), n),
            Err(e) => {
                eprintln!("error: N: {e}");
                std::process::exit(2);
            }
        },
        _ => {
            eprintln!("usage: fused_instructions FUNCTION N");
            std::process::exit(2);
        }
    };
    // 16 configurations spread over the joints' ranges (a fixed, simple sequence).
    let configs: Vec<[f64; 7]> = (0..16)
        .map(|k| core::array::from_fn(|j| ((k * 7 + j * 3) % 11) as f64 * 0.25 - 1.25))
        .collect();
    let trigs: Vec<panda::JointTrig<f64>> = configs.iter().map(panda::JointTrig::new).collect();
    let fma_trigs: Vec<panda_fma::JointTrig<f64>> =
        configs.iter().map(panda_fma::JointTrig::new).collect();
    let p = panda::Params::<f64>::nominal();
    let pf = panda_fma::Params::<f64>::nominal();
    let mut fk = ([[0.0; 3]; 3], [0.0; 3]);
    let mut je = [[0.0; 6]; panda::N];
    let mut ji = [[0.0; 6]; panda::I];
    let mut f: Box<dyn FnMut(usize)> = match which.as_str() {
        "pose_and_jacobian" => {
            Box::new(|k| panda::pose_and_jacobian(&configs[k], &p, &mut fk, &mut je))
        }
        "pose_and_jacobian_trig" => {
            Box::new(|k| panda::pose_and_jacobian_trig(&trigs[k], &p, &mut fk, &mut je))
        }
        "link_pose_and_jacobian" => {
            Box::new(|k| panda::link_pose_and_jacobian(&configs[k], &p, &mut fk, &mut ji))
        }
        "link_pose_and_jacobian_trig" => {
            Box::new(|k| panda::link_pose_and_jacobian_trig(&trigs[k], &p, &mut fk, &mut ji))
        }
        "link_pose_and_jacobian_f64" => {
            Box::new(|k| panda_fma::link_pose_and_jacobian_f64(&configs[k], &pf, &mut fk, &mut ji))
        }
        "link_pose_and_jacobian_trig_f64" => Box::new(|k| {
            panda_fma::link_pose_and_jacobian_trig_f64(&fma_trigs[k], &pf, &mut fk, &mut ji)
        }),
        other => {
            eprintln!("error: unknown function `{other}`");
            std::process::exit(2);
        }
    };
    measured_loop(n, &mut *f);
    drop(f);
    println!("{which}: {:?} {:?}", black_box(fk).1, black_box(ji)[0]);
}
