//! The host's instruction count of the QEMU run's sequence (`trocar_firmware::sequence`), for
//! callgrind, beside the Cortex-M4F's (`examples/firmware/run-qemu.sh`):
//!
//! ```text
//! cargo build --release -p trocar-firmware --example firmware_sequence_instructions
//! valgrind --tool=callgrind --toggle-collect='*measured_loop*' \
//!     target/release/examples/firmware_sequence_instructions
//! ```
//!
//! The collected count divided by `STEPS` (500) is the mean instructions per step.

use std::hint::black_box;
use trocar_firmware::sequence::{step, trocar, Q0, STEPS};
use trocar_firmware::Tuning;

#[inline(never)]
fn measured_loop(n: usize, f: &mut dyn FnMut()) {
    for _ in 0..n {
        f();
    }
}

fn main() {
    let (trocar, tuning) = (trocar(), Tuning::default());
    let mut q = Q0;
    measured_loop(STEPS, &mut || {
        let out = step(&mut q, &trocar, &tuning);
        black_box(&out);
    });
    println!("{STEPS} steps, q = {:?}", black_box(q));
}
