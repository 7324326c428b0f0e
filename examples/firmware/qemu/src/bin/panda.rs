//! The Panda laparoscope's controller (generated kinematics, `f32`) on a Cortex-M4F: the DLS step
//! on the `panda-laparoscope` circle, then the QP step with hard limits on the
//! `panda-laparoscope-limits` path, from the reference tables `run-qemu.sh` writes. Every step
//! prints `step <dls|qp> k status instructions qd1..qd7` (the rates as `f32` bits), each run a
//! summary line.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use trocar_panda::sequence::{status_code, step, ReferenceTable};
use trocar_panda::{controller, panda, qp_controller, PandaController, Q0};
use trocar_qemu::{
    exit_success, fail, hprintln, median_mean_max, print_step, stack_pointer, InstructionCounter,
    StackGauge,
};

static CIRCLE: &[u8] = include_bytes!(concat!(env!("TROCAR_QEMU_REFERENCES"), "/panda-circle.bin"));
static LIMITS: &[u8] = include_bytes!(concat!(env!("TROCAR_QEMU_REFERENCES"), "/panda-limits.bin"));

/// The largest run (steps) whose counts are kept for the summary.
const MAX_STEPS: usize = 2000;

fn run(
    name: &str,
    mut ctrl: PandaController,
    table: &ReferenceTable,
    counter: &mut InstructionCounter,
    counts: &mut [u64; MAX_STEPS],
) {
    let steps = table.steps().min(MAX_STEPS);
    let mut q = Q0;
    let gauge = StackGauge::paint();
    let sp = stack_pointer();
    for (k, slot) in counts.iter_mut().enumerate().take(steps) {
        let reference = table.reference(k);
        let (count, out) =
            counter.count(|| step(&mut ctrl, &mut q, &reference, &table.trocar, table.dt));
        *slot = count;
        let qd = match &out {
            Ok(o) => o.qd.into(),
            Err(_) => [0.0f32; panda::N],
        };
        print_step(name, k, status_code(&out), count, &qd);
    }
    let depth = gauge.depth_below(sp);
    let (median, mean, max) = median_mean_max(&mut counts[..steps]);
    hprintln!(
        "summary {} steps {} instructions median {} mean {} max {} stack {} state {}",
        name,
        steps,
        median,
        mean,
        max,
        depth,
        core::mem::size_of::<PandaController>()
    );
}

#[entry]
fn main() -> ! {
    let mut counter = trocar_qemu::start();
    let (Some(circle), Some(limits)) =
        (ReferenceTable::parse(CIRCLE), ReferenceTable::parse(LIMITS))
    else {
        fail("a reference table is malformed");
    };
    static mut COUNTS: [u64; MAX_STEPS] = [0; MAX_STEPS];
    // SAFETY: the only reference to `COUNTS`, taken once in `main`, which never returns.
    let counts = unsafe { &mut *core::ptr::addr_of_mut!(COUNTS) };
    run("dls", controller(), &circle, &mut counter, counts);
    run("qp", qp_controller(), &limits, &mut counter, counts);
    exit_success()
}
