//! The trocar's largest lateral velocity and drift in `panda-laparoscope-limits` with the QP step
//! (drift correction on) at sample times of 2, 1 and 0.5 ms: what is left after the second-order
//! trocar rows (Q7) is the third-order term of the chord the link follows over a step, which
//! falls with the square of the sample time.
//!
//! `cargo run --release -p trocar-sim --example qp_sample_time`

use trocar_sim::simulation::{run, Method, Scenario, ScenarioConfig};

fn main() -> Result<(), trocar_sim::simulation::SimulationError> {
    for dt in [0.002, 0.001, 0.0005] {
        let mut config = ScenarioConfig::new(Scenario::PandaLimits);
        config.method = Method::Qp;
        config.dt = dt;
        config.drift_correction = true;
        let trace = run(&config, |_| {})?;
        let (mut lateral, mut drift) = (0.0_f64, 0.0_f64);
        // The first step starts from rest with the drift correction's full pull.
        for row in trace.rows.iter().skip(1) {
            lateral = lateral.max(row.vr[0].hypot(row.vr[1]));
            drift = drift.max(row.rcm_drift);
        }
        println!(
            "dt = {:>3} ms: max lateral velocity {lateral:.2e} m/s, max drift {drift:.2e} m",
            dt * 1e3
        );
    }
    Ok(())
}
