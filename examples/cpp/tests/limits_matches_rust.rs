//! `limits.cpp` (the QP with every URDF limit at 1 kHz, through the C++ header's controller
//! object) against the same loop in Rust: the runtime's controller built from `trocar::control`
//! on the generated kinematics, the scenario's own reference path (`trocar_sim`). Every row's
//! joints and rates within 1e-12, every joint within its range, speed and acceleration limits,
//! the trocar held within 1e-4 m.
//!
//! Ignored by default: it needs the program's output. `.ci/run` runs it as
//!
//! ```text
//! build/panda_limits > limits.csv
//! TROCAR_CPP_LIMITS_OUTPUT=limits.csv cargo test -p trocar-cpp-example --test limits_matches_rust -- --ignored
//! ```

mod common;

use common::{rust_qp_controller, start, ACCELERATION, SPEED};
use trocar::control::Rcm;
use trocar::nalgebra::{SVector, Vector3};
use trocar_cpp_example::panda_laparoscope as m;
use trocar_cpp_example::Q0;
use trocar_sim::simulation::panda_limits_reference;

#[test]
#[ignore = "needs the C++ program's output: TROCAR_CPP_LIMITS_OUTPUT"]
fn cpp_limits_loop_matches_the_rust_loop() {
    let path = std::env::var("TROCAR_CPP_LIMITS_OUTPUT").expect("TROCAR_CPP_LIMITS_OUTPUT");
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (q1, qd1, drift) = (column("q1"), column("qd1"), column("rcm_drift"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 10_000, "1 kHz for 10 s");
    let (trocar, g0) = start();
    let kin = m::Kinematics::nominal();
    let mut rust = rust_qp_controller();
    let dt = 0.001;
    let mut q = SVector::from(Q0);
    let limits = m::JOINT_LIMITS;
    let (mut worst, mut largest_drift) = (0.0f64, 0.0f64);
    let mut previous = [0.0f64; 7];
    for (k, row) in rows.iter().enumerate() {
        let t = k as f64 * dt;
        assert!((row[0] - t).abs() < 1e-12, "row {k}: t = {}", row[0]);
        let out = rust
            .step(
                &kin,
                &q,
                &panda_limits_reference(t, &g0),
                &Rcm {
                    trocar: Vector3::from(trocar),
                    dv: SVector::zeros(),
                },
                dt,
            )
            .unwrap_or_else(|e| panic!("t = {t}: {e}"));
        for j in 0..7 {
            worst = worst
                .max((row[q1 + j] - q[j]).abs())
                .max((row[qd1 + j] - out.qd[j]).abs());
            let (qj, qdj) = (row[q1 + j], row[qd1 + j]);
            assert!(
                qj >= limits[j][0] && qj <= limits[j][1],
                "t = {t}: q{}",
                j + 1
            );
            assert!(qdj.abs() <= SPEED[j] * (1.0 + 1e-9), "t = {t}: qd{}", j + 1);
            assert!(
                (qdj - previous[j]).abs() <= ACCELERATION[j] * dt * (1.0 + 1e-6) + 1e-12,
                "t = {t}: joint {} accelerates past its limit",
                j + 1
            );
            previous[j] = qdj;
        }
        largest_drift = largest_drift.max(row[drift]);
        q += out.qd * dt;
    }
    println!(
        "C++ limits loop against Rust: {worst:.1e}; trocar drift at most {largest_drift:.1e} m"
    );
    assert!(
        worst <= 1e-12,
        "the C++ loop differs from the Rust loop by {worst}"
    );
    assert!(largest_drift <= 1e-4);
}
