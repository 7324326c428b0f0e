//! `trocar-firmware`'s DLS step (generated `dia10_like_zy` kinematics, `f32`) on a Cortex-M4F:
//! the fixed sequence of `trocar_firmware::sequence`. Every step prints `step firmware k status
//! instructions qd1..qd8` (the rates as `f32` bits, status 0 for a step taken), then a summary.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use trocar_firmware::sequence::{step, trocar, Q0, STEPS};
use trocar_firmware::{Tuning, N};
use trocar_qemu::{exit_success, hprintln, median_mean_max, print_step, stack_pointer, StackGauge};

#[entry]
fn main() -> ! {
    let mut counter = trocar_qemu::start();
    let trocar = trocar();
    let tuning = Tuning::default();
    let mut q = Q0;
    let mut counts = [0u64; STEPS];
    let gauge = StackGauge::paint();
    let sp = stack_pointer();
    for (k, count) in counts.iter_mut().enumerate() {
        let (n, out) = counter.count(|| step(&mut q, &trocar, &tuning));
        *count = n;
        let (status, qd) = match out {
            Ok(s) => (0, s.qdot),
            Err(_) => (10, [0.0f32; N]),
        };
        print_step("firmware", k, status, n, &qd);
    }
    let depth = gauge.depth_below(sp);
    let (median, mean, max) = median_mean_max(&mut counts);
    hprintln!(
        "summary firmware steps {} instructions median {} mean {} max {} stack {} state {}",
        STEPS,
        median,
        mean,
        max,
        depth,
        0
    );
    exit_success()
}
