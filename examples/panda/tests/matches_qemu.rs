//! The Cortex-M4F run of the Panda's controller under QEMU (`examples/firmware/run-qemu.sh`)
//! against the host: every step's rates against the host's `f32` run of the same code (the
//! same reference tables, `trocar_panda::sequence`), and the joints against the `f64` numeric
//! runtime's run of the same scenarios (`trocar_sim`).
//!
//! Ignored by default: it needs QEMU's output. `run-qemu.sh` runs it as
//!
//! ```text
//! TROCAR_QEMU_PANDA_OUTPUT=target/qemu/panda.txt TROCAR_QEMU_REFERENCES=target/qemu \
//!     cargo test -p trocar-panda --test matches_qemu -- --ignored --nocapture
//! ```

use trocar_panda::sequence::{status_code, step, ReferenceTable};
use trocar_panda::{controller, qp_controller, PandaController, Q0};
use trocar_sim::simulation::{run, Method, Scenario, ScenarioConfig};

/// One step of QEMU's log: status, instructions, rates.
struct Logged {
    status: u32,
    instructions: u64,
    qd: [f32; 7],
}

fn parse(text: &str, name: &str) -> Vec<Logged> {
    let mut steps = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let fields: Vec<&str> = line.split_whitespace().collect();
        if fields.first() != Some(&"step") || fields.get(1) != Some(&name) {
            continue;
        }
        assert_eq!(fields.len(), 12, "line {}: {line}", n + 1);
        let k: usize = fields[2].parse().unwrap();
        assert_eq!(k, steps.len(), "line {}: steps out of order", n + 1);
        let bits = |s: &str| f32::from_bits(u32::from_str_radix(s, 16).unwrap());
        steps.push(Logged {
            status: fields[3].parse().unwrap(),
            instructions: fields[4].parse().unwrap(),
            qd: std::array::from_fn(|j| bits(fields[5 + j])),
        });
    }
    steps
}

/// Compares one run; returns (steps, steps bit for bit equal, largest rate difference, largest
/// joint difference from the f64 run).
fn compare(
    name: &str,
    logged: &[Logged],
    table: &ReferenceTable,
    mut ctrl: PandaController,
    f64_joints: &[[f64; 7]],
) -> (usize, usize, f32, f64) {
    assert_eq!(logged.len(), table.steps(), "{name}: steps logged");
    let (mut q_host, mut q_qemu) = (Q0, Q0);
    let (mut equal, mut rate_diff, mut joint_diff) = (0, 0.0f32, 0.0f64);
    for (k, log) in logged.iter().enumerate() {
        // The joints of both runs at step k, before it, against the f64 run's.
        for j in 0..7 {
            joint_diff = joint_diff.max((f64::from(q_qemu[j]) - f64_joints[k][j]).abs());
        }
        let out = step(
            &mut ctrl,
            &mut q_host,
            &table.reference(k),
            &table.trocar,
            table.dt,
        );
        assert_eq!(status_code(&out), log.status, "{name} step {k}: status");
        let qd: [f32; 7] = out.expect("a step the log says held").qd.into();
        if qd
            .iter()
            .zip(&log.qd)
            .all(|(a, b)| a.to_bits() == b.to_bits())
        {
            equal += 1;
        }
        for j in 0..7 {
            rate_diff = rate_diff.max((qd[j] - log.qd[j]).abs());
            q_qemu[j] += table.dt * log.qd[j];
        }
    }
    (logged.len(), equal, rate_diff, joint_diff)
}

#[test]
#[ignore = "needs QEMU's output: examples/firmware/run-qemu.sh"]
fn qemu_run_matches_the_host() {
    let output = std::env::var("TROCAR_QEMU_PANDA_OUTPUT")
        .expect("TROCAR_QEMU_PANDA_OUTPUT: QEMU's log of the Panda");
    let dir = std::env::var("TROCAR_QEMU_REFERENCES").expect("TROCAR_QEMU_REFERENCES");
    let text = std::fs::read_to_string(&output).unwrap();
    let read = |file: &str| std::fs::read(std::path::Path::new(&dir).join(file)).unwrap();
    let (circle, limits) = (read("panda-circle.bin"), read("panda-limits.bin"));
    let circle = ReferenceTable::parse(&circle).expect("the circle's table");
    let limits = ReferenceTable::parse(&limits).expect("the limits' table");
    let mut qp_config = ScenarioConfig::new(Scenario::PandaLimits)
        .with_method(Method::Qp)
        .with_drift_correction(true);
    // The f32 controller's `κ` (as in `matches_runtime.rs`).
    qp_config.qp_kappa = 0.01;
    let joints = |config: &ScenarioConfig| -> Vec<[f64; 7]> {
        run(config, |_| {})
            .unwrap()
            .rows
            .iter()
            .map(|r| std::array::from_fn(|j| r.q[j]))
            .collect()
    };
    let dls_config = ScenarioConfig::new(Scenario::Panda).with_drift_correction(true);
    let runs = [
        ("dls", &circle, controller(), joints(&dls_config)),
        ("qp", &limits, qp_controller(), joints(&qp_config)),
    ];
    for (name, table, ctrl, f64_joints) in runs {
        let logged = parse(&text, name);
        let (steps, equal, rate_diff, joint_diff) =
            compare(name, &logged, table, ctrl, &f64_joints);
        let mut counts: Vec<u64> = logged.iter().map(|l| l.instructions).collect();
        counts.sort_unstable();
        println!(
            "panda {name}: {steps} steps, {equal} bit for bit equal to the host's f32 run, \
             largest rate difference {rate_diff:.3e} rad/s; joints within {joint_diff:.3e} rad \
             of the f64 run; instructions per step median {} max {}",
            counts[counts.len() / 2],
            counts[counts.len() - 1]
        );
        assert!(
            joint_diff < 1e-4,
            "{name}: joints {joint_diff} rad from the f64 run"
        );
        // The same operations in the same order on both (no fused multiply-adds on either:
        // the generated code fuses only where the target has FMA, and the host's baseline
        // x86-64 has none; the runtime's own `sin_cos`; `sqrt` correctly rounded on both).
        assert_eq!(
            equal, steps,
            "{name}: steps whose rates differ from the host's in a bit"
        );
        assert_eq!(rate_diff, 0.0);
    }
}
