//! Writes the reference tables of the QEMU run (`examples/firmware/run-qemu.sh`): the Panda
//! scenario's circle (`panda-circle.bin`, the DLS steps) and the limits scenario's withdrawal and
//! roll (`panda-limits.bin`, the QP steps), from the scenarios' own reference paths
//! (`trocar_sim::simulation`), cast to `f32` (`trocar_panda::sequence`).
//!
//! ```text
//! cargo run -p trocar-panda --example qemu_references -- DIR
//! ```

use trocar::control::Reference;
use trocar_model::description::RobotDescription;
use trocar_model::numeric::NumericModel;
use trocar_panda::sequence::{reference_to_f32, write_table};
use trocar_panda::Q0;
use trocar_sim::simulation::{panda_limits_reference, panda_reference, PANDA_TIP_DEPTH};

/// Steps of the DLS run on the circle (2 s) and of the QP run on the limits path (4 s: the
/// withdrawal to the depth bound and the start of the roll).
pub const DLS_STEPS: usize = 1000;
/// See [`DLS_STEPS`].
pub const QP_STEPS: usize = 2000;
/// The sample time (s).
pub const DT: f64 = 0.002;

/// A scenario's reference path: the reference at `t` from the start pose `g_0e`.
type Path = fn(f64, &trocar::se3::Se3<f64>) -> Reference<f64>;

fn main() {
    let Some(dir) = std::env::args_os().nth(1) else {
        eprintln!("usage: qemu_references DIR");
        std::process::exit(2);
    };
    let dir = std::path::PathBuf::from(dir);
    let d = RobotDescription::preset("panda-laparoscope").expect("a shipped robot");
    let chain = NumericModel::<f64>::from_description(&d, &[])
        .and_then(|m| m.to_chain::<7>())
        .expect("the Panda's chain");
    let q0 = trocar::nalgebra::SVector::<f64, 7>::from_fn(|k, _| f64::from(Q0[k]));
    let g0 = chain.forward_kinematics(&q0);
    let trocar = g0.translation - g0.rotation.column(2) * PANDA_TIP_DEPTH;
    let trocar32 = [trocar.x as f32, trocar.y as f32, trocar.z as f32];
    let tables: [(&str, usize, Path); 2] = [
        ("panda-circle.bin", DLS_STEPS, panda_reference),
        ("panda-limits.bin", QP_STEPS, panda_limits_reference),
    ];
    for (name, steps, path) in tables {
        let mut bytes = Vec::new();
        let references = (0..steps).map(|k| reference_to_f32(&path(k as f64 * DT, &g0)));
        write_table(&trocar32, DT as f32, references, &mut bytes);
        let file = dir.join(name);
        if let Err(e) = std::fs::write(&file, &bytes) {
            eprintln!("error: {}: {e}", file.display());
            std::process::exit(1);
        }
        println!("{}: {steps} references", file.display());
    }
}
