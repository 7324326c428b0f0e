//! Where generation time goes for dia10_like (derivation, programs, tokens, formatting).
//! `cargo test -p trocar-codegen --release --test emit_timing_breakdown -- --nocapture`.

use std::time::Instant;
use trocar_codegen::derivation::derive;
use trocar_codegen::emit::{format_file, module_tokens};
use trocar_codegen::lower::module_spec;
use trocar_codegen::Scalar;
use trocar_model::description::RobotDescription;

#[test]
fn dia10_like_breakdown() {
    let desc = RobotDescription::preset("dia10_like_zy").unwrap();
    let t0 = Instant::now();
    let d = derive(&desc).unwrap();
    let t1 = Instant::now();
    let spec = module_spec(&d, "dia10_like_zy");
    let t2 = Instant::now();
    let tokens = module_tokens(&spec, Scalar::Generic);
    let t3 = Instant::now();
    let text = format_file(tokens).unwrap();
    let t4 = Instant::now();
    println!(
        "derive {:?}, programs {:?}, tokens {:?}, format {:?} ({} bytes)",
        t1 - t0,
        t2 - t1,
        t3 - t2,
        t4 - t3,
        text.len()
    );
}
