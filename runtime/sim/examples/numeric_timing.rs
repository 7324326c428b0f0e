//! Times the numeric runtime's `g_0i` and `J^B_0i` (3.13) of the Panda laparoscope
//! (`panda-laparoscope`, F_i = panda_link7, 7 joints) on the typed `Chain<f64, 7>`: the two calls
//! `link_frame` + `partial_body_jacobian` against the one sweep
//! `frame_and_partial_body_jacobian`.
//!
//! `cargo run --release -p trocar-sim --example numeric_timing`

use nalgebra::{SMatrix, SVector};
use std::hint::black_box;
use std::time::Instant;
use trocar::kinematics::Chain;
use trocar_model::description::RobotDescription;
use trocar_sim::robot::NumericRobot;

fn best_ns(calls: usize, mut f: impl FnMut(usize)) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..7 {
        let t = Instant::now();
        for k in 0..calls {
            f(k);
        }
        best = best.min(t.elapsed().as_secs_f64() / calls as f64);
    }
    best * 1e9
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let description = RobotDescription::preset("panda-laparoscope")?;
    let robot = NumericRobot::<f64>::from_description(&description, &[])?;
    let chain: Chain<f64, 7> = robot.to_chain()?;
    // 16 configurations cycled, so that nothing is folded.
    let qs: Vec<SVector<f64, 7>> = (0..16)
        .map(|k| SVector::from_fn(|j, _| ((k * 7 + j) as f64 * 0.37).sin() * 1.5))
        .collect();
    let calls = 400_000;
    let two = best_ns(calls, |k| {
        let q = black_box(&qs[k % 16]);
        black_box(chain.link_frame(7, q));
        black_box(chain.partial_body_jacobian::<7>(q));
    });
    let one = best_ns(calls, |k| {
        let q = black_box(&qs[k % 16]);
        black_box(chain.frame_and_partial_body_jacobian::<7>(q));
    });
    let mut worst: f64 = 0.0;
    for q in &qs {
        let (g, j): (_, SMatrix<f64, 6, 7>) = chain.frame_and_partial_body_jacobian::<7>(q);
        worst = worst.max((g.to_homogeneous() - chain.link_frame(7, q).to_homogeneous()).amax());
        worst = worst.max((j - chain.partial_body_jacobian::<7>(q)).amax());
    }
    println!("link_frame + partial_body_jacobian: {two:.1} ns");
    println!("frame_and_partial_body_jacobian:    {one:.1} ns  (largest difference {worst:.1e})");
    Ok(())
}
