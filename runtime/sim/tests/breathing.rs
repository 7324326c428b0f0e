//! `panda-breathing`: the port moves with breathing and a patient shift. Against the fixed
//! port, the port followed from the wall's force keeps the peak force to a fifth or less, its
//! estimate within 1 mm of the true port after the first breath and the shaft within 0.5 mm of
//! it throughout; the known port within 0.1 mm; no joint past its URDF range or speed.

use trocar_sim::breathing::{simulate, PortMode, BREATH_FREQUENCY};
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
    let fixed = simulate(PortMode::Fixed, |_| {}).unwrap();
    let known = simulate(PortMode::Known, |_| {}).unwrap();
    let estimated = simulate(PortMode::Estimated, |_| {}).unwrap();
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
