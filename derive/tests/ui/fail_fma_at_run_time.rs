//! `fma_at_run_time` needs a generic module, and takes no value.
use trocar_derive::constrained_robot;

#[constrained_robot(preset = "bidirectional-zy", real = "f64", fma_at_run_time)]
struct Mono;

#[constrained_robot(preset = "bidirectional-zy", fma_at_run_time = true)]
struct Valued;

fn main() {}
