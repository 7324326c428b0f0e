//! `breathing.cpp` (the port moving with breathing, followed from the wall's force through the C++
//! header's `PortFollower` and `Controller`) against the same loop in Rust — the runtime's
//! controller from `trocar::control`, `trocar::port`'s wall and follower, the scenario's own port
//! motion (`trocar_sim::breathing`) — every row within 1e-12; and what the loop must show: the
//! wall's peak force under a fifth of a fixed port's (the same loop holding the start), the shaft
//! within 0.5 mm of the true port throughout, the estimate within 1 mm after the first breath.
//!
//! Ignored by default: it needs the program's output (`.ci/run`:
//! `TROCAR_CPP_BREATHING_OUTPUT=breathing.csv cargo test -p trocar-cpp-example --test
//! breathing_matches_rust -- --ignored`).

mod common;

use common::rust_qp_controller;
use trocar::control::{ConstrainedKinematics, Rcm, Reference};
use trocar::nalgebra::{SVector, Vector3};
use trocar::port::{PortFollower, Wall};
use trocar_cpp_example::panda_laparoscope as m;
use trocar_cpp_example::Q0;
use trocar_sim::breathing::{
    port_motion, wall_normal, BREATH_FREQUENCY, FOLLOWER_MAX_RATE, FOLLOWER_TIME_CONSTANT,
};

/// One row of the loop: the joints, the rates, the true port, the port held, the force's and the
/// offset's sizes.
type Row = Vec<f64>;

/// The loop in Rust, the port followed (`follow`) or held at its start.
fn rust_loop(follow: bool, steps: usize) -> Vec<Row> {
    let kin = m::Kinematics::nominal();
    let shaft = kin.shaft();
    let h = kin.h();
    let p = m::Params::nominal();
    let (re, te) = m::forward_kinematics(&Q0, &p);
    let (ri, ti) = m::forward_kinematics_i(&Q0, &p);
    let (_, tir) = m::constraint_frame(&p);
    let port0 = Vector3::from_fn(|r, _| ti[r] + (0..3).map(|c| ri[c][r] * tir[c]).sum::<f64>());
    let wall = Wall::<f64>::abdominal();
    let mut follower = PortFollower::new(
        port0,
        1.0 / (wall.stiffness * FOLLOWER_TIME_CONSTANT),
        FOLLOWER_MAX_RATE,
    )
    .and_then(|f| f.with_normal(wall_normal()))
    .unwrap();
    let mut ctrl = rust_qp_controller();
    let dt = 0.001;
    let mut q = SVector::from(Q0);
    let mut last_offset: Option<Vector3<f64>> = None;
    let mut rows = Vec::with_capacity(steps);
    for k in 0..steps {
        let t = k as f64 * dt;
        let (displacement, port_rate) = port_motion(t);
        let port = port0 + displacement;
        let line = shaft.line(&kin.g_0i(&q)).unwrap();
        let offset = line.offset_from(&port);
        let offset_rate = last_offset.map_or_else(Vector3::zeros, |e| (offset - e) / dt);
        last_offset = Some(offset);
        let force = wall.force(&offset, &offset_rate);
        let (trocar, trocar_rate) = if follow {
            let rate = follower.update(&force, &line.direction, dt).unwrap();
            (follower.estimate, rate)
        } else {
            (port0, Vector3::zeros())
        };
        let dv = shaft.trocar_rate(&kin.g_0i(&q), &h, &trocar_rate);
        let reference = Reference {
            position: Vector3::from(te) + displacement,
            rotation: trocar::nalgebra::Matrix3::from_fn(|i, j| re[j][i]),
            velocity: port_rate,
            angular_velocity: Vector3::zeros(),
        };
        let out = ctrl
            .step(&kin, &q, &reference, &Rcm { trocar, dv }, dt)
            .unwrap_or_else(|e| panic!("t = {t}: {e}"));
        let mut row = vec![t];
        row.extend(q.iter());
        row.extend(out.qd.iter());
        row.extend(port.iter());
        row.extend(trocar.iter());
        row.push(force.norm());
        row.push(offset.norm());
        rows.push(row);
        q += out.qd * dt;
    }
    rows
}

#[test]
#[ignore = "needs the C++ program's output: TROCAR_CPP_BREATHING_OUTPUT"]
fn cpp_breathing_loop_matches_the_rust_loop() {
    let path = std::env::var("TROCAR_CPP_BREATHING_OUTPUT").expect("TROCAR_CPP_BREATHING_OUTPUT");
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().expect("a header");
    assert!(header.starts_with("t,q1,") && header.ends_with("port_force,port_offset"));
    let cpp: Vec<Row> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(cpp.len(), 16_000, "1 kHz for 16 s");
    let rust = rust_loop(true, cpp.len());
    let mut worst = 0.0f64;
    for (a, b) in cpp.iter().zip(&rust) {
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(b) {
            worst = worst.max((x - y).abs());
        }
    }
    let fixed = rust_loop(false, cpp.len());
    let peak = |rows: &[Row], c: usize| rows.iter().map(|r| r[c]).fold(0.0, f64::max);
    let (force, offset) = (21, 22);
    let first_breath = (1.0 / BREATH_FREQUENCY / 0.001) as usize;
    let estimate_error = cpp[first_breath..]
        .iter()
        .map(|r| {
            (0..3)
                .map(|i| (r[18 + i] - r[15 + i]).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .fold(0.0, f64::max);
    println!(
        "C++ breathing loop against Rust: {worst:.1e}; peak force {:.3} N (held at the start: \
         {:.2} N), the shaft at most {:.3} mm from the port, the estimate {:.3} mm after the \
         first breath",
        peak(&cpp, force),
        peak(&fixed, force),
        peak(&cpp, offset) * 1e3,
        estimate_error * 1e3
    );
    assert!(
        worst <= 1e-12,
        "the C++ loop differs from the Rust loop by {worst}"
    );
    assert!(peak(&cpp, force) <= 0.2 * peak(&fixed, force));
    assert!(peak(&cpp, offset) <= 5e-4);
    assert!(estimate_error <= 1e-3);
}
