//! The host's instruction count of the QEMU run's sequences (`trocar_panda::sequence`), for
//! callgrind, beside the Cortex-M4F's (`examples/firmware/run-qemu.sh`):
//!
//! ```text
//! cargo run -q -p trocar-panda --example qemu_references -- target/qemu
//! cargo build --release -p trocar-panda --example panda_sequence_instructions
//! valgrind --tool=callgrind --toggle-collect='*measured_loop*' \
//!     target/release/examples/panda_sequence_instructions qp target/qemu
//! ```
//!
//! `panda_sequence_instructions dls|qp DIR` runs every step of the table (`panda-circle.bin` for
//! `dls`, `panda-limits.bin` for `qp`) inside `measured_loop`: the collected count divided by
//! the steps it prints is the mean instructions per step.

use std::hint::black_box;
use trocar_panda::sequence::{step, ReferenceTable};
use trocar_panda::{controller, qp_controller, Q0};

#[inline(never)]
fn measured_loop(n: usize, f: &mut dyn FnMut(usize)) {
    for k in 0..n {
        f(k);
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (mut ctrl, file) = match args.get(1).map(String::as_str) {
        Some("dls") => (controller(), "panda-circle.bin"),
        Some("qp") => (qp_controller(), "panda-limits.bin"),
        _ => {
            eprintln!("usage: panda_sequence_instructions dls|qp DIR");
            std::process::exit(2);
        }
    };
    let Some(dir) = args.get(2) else {
        eprintln!("usage: panda_sequence_instructions dls|qp DIR");
        std::process::exit(2);
    };
    let bytes = std::fs::read(std::path::Path::new(dir).join(file)).unwrap_or_else(|e| {
        eprintln!("error: {dir}/{file}: {e}");
        std::process::exit(1);
    });
    let Some(table) = ReferenceTable::parse(&bytes) else {
        eprintln!("error: {dir}/{file}: not a reference table");
        std::process::exit(1);
    };
    let references: Vec<_> = (0..table.steps()).map(|k| table.reference(k)).collect();
    let mut q = Q0;
    measured_loop(table.steps(), &mut |k| {
        let out = step(&mut ctrl, &mut q, &references[k], &table.trocar, table.dt);
        black_box(&out);
    });
    println!("{} steps, q = {:?}", table.steps(), black_box(q));
}
