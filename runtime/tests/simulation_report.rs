//! Generates `runtime/CONTROL.md` (the method comparison and drift tables) and the figures.
//! Not part of the normal test run (it takes ~30 s in release); regenerate with
//!
//! ```text
//! cargo test --release -p trocar --test simulation_report -- --ignored
//! ```
//! Figures go to `target/figures/` (`TROCAR_FIGURES` overrides).

use std::fmt::Write as _;
use trocar::simulation::{run, Method, Scenario, ScenarioConfig, Summary, Trace};

fn go(cfg: ScenarioConfig) -> (Result<Trace, String>, f64) {
    let t0 = std::time::Instant::now();
    let r = run(&cfg, |_| {}).map_err(|e| e.to_string());
    (r, t0.elapsed().as_secs_f64())
}

fn row(label: &str, s: &Summary) -> String {
    format!(
        "| {label} | {:.3e} | {:.3e} | {:.3e} | {:.3e} | {:.3e} | {:.3e} | {:.3e} |\n",
        s.peak_qd, s.max_ep, s.max_eo, s.max_rcm_velocity_error, s.max_drift, s.min_w_r, s.min_w_i
    )
}

const HEADER: &str = "| run | peak \\|θ̇\\| (rad/s) | max ‖dp − p‖ (m) | max ‖ε̃‖ | max \\|vr − dv\\| (m/s) | max drift (m) | min w_r | min w_i |\n|---|---|---|---|---|---|---|---|\n";

#[test]
#[ignore]
fn write_control_md() {
    let figures = std::env::var("TROCAR_FIGURES")
        .unwrap_or_else(|_| concat!(env!("CARGO_MANIFEST_DIR"), "/../target/figures").to_string());
    std::fs::create_dir_all(&figures).unwrap();
    let mut md = String::new();
    md.push_str(HEAD);

    // Method comparison, scenario 3 and experiment 4.2.1.
    for scenario in [Scenario::S3, Scenario::Exp421] {
        writeln!(md, "\n### {}\n", scenario.title()).unwrap();
        md.push_str(HEADER);
        for dc in [false, true] {
            for m in [Method::Pinv, Method::Dls, Method::Fi] {
                let cfg = ScenarioConfig::new(scenario)
                    .with_method(m)
                    .with_drift_correction(dc);
                let label = format!(
                    "{} (correction {})",
                    m.name(),
                    if dc { "on" } else { "off" }
                );
                match go(cfg) {
                    (Ok(tr), _) => {
                        md.push_str(&row(&label, &tr.summary()));
                        let f = format!("{figures}/{}_{}_{}", scenario.name(), m.name(), dc as u8);
                        trocar::plot::write_figure(&tr, format!("{f}.svg")).unwrap();
                        trocar::plot::write_figure(&tr, format!("{f}.png")).unwrap();
                    }
                    (Err(e), _) => writeln!(md, "| {label} | failed: {e} | | | | | | |").unwrap(),
                }
            }
        }
    }

    // Drift with and without the correction, scenarios 1, 2, 4 (pseudo-inverse).
    md.push_str(
        "\n## RCM drift with and without the correction (pseudo-inverse, 2 ms explicit Euler)\n\n",
    );
    md.push_str(HEADER);
    for (scenario, duration) in [
        (Scenario::S1, 200.0),
        (Scenario::S2, 200.0),
        (Scenario::S4, 20.0),
        (Scenario::S4, 200.0),
    ] {
        for dc in [false, true] {
            let mut cfg = ScenarioConfig::new(scenario).with_drift_correction(dc);
            cfg.duration = duration;
            let label = format!(
                "scenario {} ({duration} s, correction {})",
                scenario.name(),
                if dc { "on" } else { "off" }
            );
            match go(cfg) {
                (Ok(tr), secs) => {
                    md.push_str(&row(&label, &tr.summary()));
                    eprintln!("{label}: {secs:.2} s");
                    if duration == scenario.duration() {
                        let f = format!("{figures}/{}_pinv_{}", scenario.name(), dc as u8);
                        trocar::plot::write_figure(&tr, format!("{f}.svg")).unwrap();
                        trocar::plot::write_figure(&tr, format!("{f}.png")).unwrap();
                    }
                }
                (Err(e), _) => writeln!(md, "| {label} | failed: {e} | | | | | | |").unwrap(),
            }
        }
    }
    md.push_str(TAIL);
    let out = concat!(env!("CARGO_MANIFEST_DIR"), "/CONTROL.md");
    std::fs::write(out, md).unwrap();
}

const HEAD: &str = "# head\n";
const TAIL: &str = "\n# tail\n";
