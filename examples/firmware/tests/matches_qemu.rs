//! The Cortex-M4F run of the firmware's DLS step under QEMU (`examples/firmware/run-qemu.sh`)
//! against the host: every step's rates against the host's `f32` run of the same code
//! (`trocar_firmware::sequence`), and the joints against the same law in `f64` on the numeric
//! runtime, integrated alongside.
//!
//! Ignored by default: it needs QEMU's output. `run-qemu.sh` runs it as
//!
//! ```text
//! TROCAR_QEMU_FIRMWARE_OUTPUT=target/qemu/firmware.txt \
//!     cargo test -p trocar-firmware --test matches_qemu -- --ignored --nocapture
//! ```

mod common;

use trocar_firmware::sequence::{step, trocar, DT, L_A0, Q0, STEPS, TWIST};
use trocar_firmware::Tuning;

#[test]
#[ignore = "needs QEMU's output: examples/firmware/run-qemu.sh"]
fn qemu_run_matches_the_host() {
    let output = std::env::var("TROCAR_QEMU_FIRMWARE_OUTPUT")
        .expect("TROCAR_QEMU_FIRMWARE_OUTPUT: QEMU's log of the firmware");
    let text = std::fs::read_to_string(&output).unwrap();
    let mut logged = Vec::new();
    for line in text.lines() {
        let fields: Vec<&str> = line.split_whitespace().collect();
        if fields.first() != Some(&"step") || fields.get(1) != Some(&"firmware") {
            continue;
        }
        assert_eq!(fields.len(), 13, "{line}");
        assert_eq!(fields[2].parse::<usize>().unwrap(), logged.len(), "{line}");
        assert_eq!(fields[3], "0", "a step refused on the target: {line}");
        let qd: [f32; 8] = std::array::from_fn(|j| {
            f32::from_bits(u32::from_str_radix(fields[5 + j], 16).unwrap())
        });
        logged.push((fields[4].parse::<u64>().unwrap(), qd));
    }
    assert_eq!(logged.len(), STEPS, "steps logged");
    let trocar32 = trocar();
    let trocar64 = trocar32.map(f64::from);
    let tuning = Tuning::default();
    let twist = TWIST.map(f64::from);
    let (mut q_host, mut q_qemu) = (Q0, Q0);
    let mut q64 = Q0.map(f64::from);
    assert!((common::trocar_offset(&q64, &trocar64) - f64::from(L_A0)).abs() < 1e-6);
    let (mut equal, mut rate_diff, mut joint_diff) = (0, 0.0f32, 0.0f64);
    for (k, (_, qd_qemu)) in logged.iter().enumerate() {
        for j in 0..8 {
            joint_diff = joint_diff.max((f64::from(q_qemu[j]) - q64[j]).abs());
        }
        let host = step(&mut q_host, &trocar32, &tuning).unwrap_or_else(|e| panic!("{k}: {e:?}"));
        if host
            .qdot
            .iter()
            .zip(qd_qemu)
            .all(|(a, b)| a.to_bits() == b.to_bits())
        {
            equal += 1;
        }
        for j in 0..8 {
            rate_diff = rate_diff.max((host.qdot[j] - qd_qemu[j]).abs());
            q_qemu[j] += DT * qd_qemu[j];
        }
        let l_a = common::trocar_offset(&q64, &trocar64);
        let (rates, _) = common::numeric_rates(&q64, l_a, &twist, &tuning);
        for j in 0..8 {
            q64[j] += f64::from(DT) * rates[j];
        }
    }
    let mut counts: Vec<u64> = logged.iter().map(|(n, _)| *n).collect();
    counts.sort_unstable();
    println!(
        "firmware dls: {STEPS} steps, {equal} bit for bit equal to the host's f32 run, largest \
         rate difference {rate_diff:.3e} rad/s; joints within {joint_diff:.3e} rad of the f64 \
         run; instructions per step median {} max {}",
        counts[counts.len() / 2],
        counts[counts.len() - 1]
    );
    assert_eq!(
        equal, STEPS,
        "steps whose rates differ from the host's in a bit"
    );
    assert!(
        joint_diff < 1e-4,
        "joints {joint_diff} rad from the f64 run"
    );
}
