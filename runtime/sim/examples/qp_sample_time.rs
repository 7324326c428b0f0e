//! The trocar's largest lateral velocity and drift in `panda-laparoscope-limits` with the QP step
//! at sample times of 2, 1 and 0.5 ms, with the drift correction `K_r e_r` on (the scenario's
//! setting) and off. The second-order trocar rows (Q7) and the residual of the shaft's motion
//! across the trocar asked back (Q8) leave the change of the chord's third-order term over a
//! step, largest where the working set changes and the rates with it; there the step measures
//! its own chord and solves again (Q9), by default, or at every step, or never.
//!
//! `cargo run --release -p trocar-sim --example qp_sample_time`

use trocar::control::ChordCheck;
use trocar_sim::simulation::{run, Method, Scenario, ScenarioConfig};

fn main() -> Result<(), trocar_sim::simulation::SimulationError> {
    for (check, name) in [
        (
            ChordCheck::AfterChange,
            "after a working-set change (the default)",
        ),
        (ChordCheck::Always, "at every step"),
        (ChordCheck::Never, "never"),
    ] {
        println!("the step's own chord measured (Q9) {name}:");
        for drift_correction in [true, false] {
            println!(
                "  drift correction {}:",
                if drift_correction { "on" } else { "off" }
            );
            for dt in [0.002, 0.001, 0.0005] {
                let mut config = ScenarioConfig::new(Scenario::PandaLimits);
                config.method = Method::Qp;
                config.dt = dt;
                config.drift_correction = drift_correction;
                config.qp_chord_check = check;
                let trace = run(&config, |_| {})?;
                let (mut lateral, mut drift) = (0.0_f64, 0.0_f64);
                // The first step starts from rest with the drift correction's full pull.
                for row in trace.rows.iter().skip(1) {
                    lateral = lateral.max(row.vr[0].hypot(row.vr[1]));
                    drift = drift.max(row.rcm_drift);
                }
                println!(
                    "    dt = {:>3} ms: max lateral velocity {lateral:.2e} m/s, max drift {drift:.2e} m",
                    dt * 1e3
                );
            }
        }
    }
    Ok(())
}
