//! `panda-breathing`: the port moves with breathing and a patient shift. Against the fixed
//! port, the port followed from the wall's force keeps the peak force to a fifth or less, its
//! estimate within 1 mm of the true port after the first breath and the shaft within 0.5 mm of
//! it throughout; the known port within 0.1 mm; no joint past its URDF range or speed.

use trocar_sim::breathing::{simulate, PortMode, BREATH_FREQUENCY, NAME, REGISTRATION};
use trocar_sim::closed_chain::MechanismTrace;

fn peak(trace: &MechanismTrace, column: &str, from: f64) -> f64 {
    let t = trace.column("t").unwrap();
    trace
        .column(column)
        .unwrap()
        .iter()
        .zip(&t)
        .filter(|(_, t)| **t >= from)
        .map(|(v, _)| *v)
        .fold(0.0, f64::max)
}

fn estimate_error(trace: &MechanismTrace, from: f64) -> f64 {
    let c = |n: &str| trace.column(n).unwrap();
    let (t, px, py, pz, ex, ey, ez) = (
        c("t"),
        c("port_x"),
        c("port_y"),
        c("port_z"),
        c("estimate_x"),
        c("estimate_y"),
        c("estimate_z"),
    );
    (0..t.len())
        .filter(|&k| t[k] >= from)
        .map(|k| {
            ((px[k] - ex[k]).powi(2) + (py[k] - ey[k]).powi(2) + (pz[k] - ez[k]).powi(2)).sqrt()
        })
        .fold(0.0, f64::max)
}

#[test]
fn the_followed_port_holds_the_force_down() {
    let fixed = simulate(NAME, PortMode::Fixed, |_| {}).unwrap();
    let known = simulate(NAME, PortMode::Known, |_| {}).unwrap();
    let estimated = simulate(NAME, PortMode::Estimated, |_| {}).unwrap();
    let after_first_breath = 1.0 / BREATH_FREQUENCY;
    let f_fixed = peak(&fixed, "port_force", 0.0);
    let f_known = peak(&known, "port_force", 0.0);
    let f_estimated = peak(&estimated, "port_force", 0.0);
    println!(
        "peak port force: fixed {f_fixed:.2} N, known {f_known:.3} N, estimated {f_estimated:.3} N ({:.3}x)",
        f_estimated / f_fixed
    );
    println!(
        "shaft from the true port: fixed {:.3} mm, known {:.4} mm, estimated {:.4} mm; estimate from the port after the first breath {:.4} mm",
        peak(&fixed, "port_offset", 0.0) * 1e3,
        peak(&known, "port_offset", 0.0) * 1e3,
        peak(&estimated, "port_offset", 0.0) * 1e3,
        estimate_error(&estimated, after_first_breath) * 1e3
    );
    assert!(f_fixed > 10.0, "the scenario moves the port: {f_fixed} N");
    assert!(f_estimated <= 0.2 * f_fixed);
    assert!(estimate_error(&estimated, after_first_breath) <= 1e-3);
    assert!(peak(&estimated, "port_offset", 0.0) <= 5e-4);
    assert!(peak(&known, "port_offset", 0.0) <= 1e-4);
    // Every joint within its URDF range and speed, in every mode.
    let (_, limits) = trocar_sim::scene::panda().unwrap();
    for trace in [&fixed, &known, &estimated] {
        for k in 0..7 {
            let q = trace.column(&format!("q{}", k + 1)).unwrap();
            let qd = trace.column(&format!("qd{}", k + 1)).unwrap();
            assert!(q
                .iter()
                .all(|v| *v >= limits.lower[k] && *v <= limits.upper[k]));
            assert!(qd.iter().all(|v| v.abs() <= limits.speed[k]));
        }
    }
}

/// The port registered 10 mm off: held there, the wall pushes the shaft with 40 N for as long as
/// the run lasts; followed from the wall's force, within 1 s (the slower of the follower's 30 ms
/// and the drift correction's 0.1 s) the shaft passes within 0.01 mm of the port, the force is
/// below 0.1 N, its peak under a fifth of the misregistered port's, and the port held is within
/// 0.2 mm of the true one (what remains lies along the shaft, where the force does not see it).
#[test]
fn a_port_registered_10_mm_off_is_found_from_the_force() {
    let fixed = simulate(REGISTRATION, PortMode::Fixed, |_| {}).unwrap();
    let found = simulate(REGISTRATION, PortMode::Estimated, |_| {}).unwrap();
    let t = found.column("t").unwrap();
    let error = found.column("estimate_error").unwrap();
    let force = found.column("port_force").unwrap();
    assert!(
        (error[0] - 0.01).abs() < 1e-12,
        "starts 10 mm off: {}",
        error[0]
    );
    let settled = t.iter().position(|t| *t >= 1.0).unwrap();
    let late_error = error[settled..].iter().copied().fold(0.0, f64::max);
    let late_force = force[settled..].iter().copied().fold(0.0, f64::max);
    println!(
        "registration: peak force {:.2} N (held off: {:.2} N at the end), after 1 s the port within {:.4} mm, force {:.4} N",
        peak(&found, "port_force", 0.0),
        fixed.column("port_force").unwrap().last().unwrap(),
        late_error * 1e3,
        late_force
    );
    let offset = found.column("port_offset").unwrap();
    assert!(offset[settled..].iter().all(|e| *e <= 1e-5));
    assert!(late_error <= 2e-4);
    assert!(late_force <= 0.1);
    assert!(*fixed.column("port_force").unwrap().last().unwrap() >= 39.0);
    assert!(peak(&found, "port_force", 0.0) <= 0.2 * peak(&fixed, "port_force", 0.0));
}
