//! `panda_laparoscope_controller_step` on hostile inputs, through its C ABI: every value outside
//! the number rule, a bad sample time, gains the controller refuses and null pointers get their
//! return code (with `qd` set to zeros, or nothing written for a null pointer), the report never
//! holds a NaN, and a positive joint speed limit (and the joint ranges over `dt`) always hold,
//! the trocar yielding with its own code when it cannot be held within them (docs/RELIABILITY.md
//! F27).

use trocar_cpp_example::panda_laparoscope as m;
use trocar_cpp_example::Q0;

/// The inputs of one step, as a C caller holds them.
#[derive(Clone, Copy)]
struct Inputs {
    q: [f64; 7],
    params: [f64; 1],
    target: [f64; 18],
    trocar: [f64; 3],
    dt: f64,
    gains: [f64; 8],
}

/// What a step wrote: the return code, `qd` and `report` (which start as `SENTINEL`).
struct Outputs {
    status: i32,
    qd: [f64; 7],
    report: [f64; 8],
}

/// The value `qd` and `report` hold before a step: a step that writes them overwrites it.
const SENTINEL: f64 = -123.25;

/// The loop of `main.cpp` at its start: the Panda at `Q0`, the trocar at the constraint frame,
/// the target at the tip's pose, `main.cpp`'s gains (speed limit 2 rad/s) and 2 ms.
fn inputs() -> Inputs {
    let p = m::Params::nominal();
    let (ri, ti) = m::forward_kinematics_i(&Q0, &p);
    let (_, tir) = m::constraint_frame(&p);
    let (re, te) = m::forward_kinematics(&Q0, &p);
    let mut trocar = [0.0; 3];
    for r in 0..3 {
        trocar[r] = ti[r];
        for c in 0..3 {
            trocar[r] += ri[c][r] * tir[c];
        }
    }
    let mut target = [0.0; 18];
    target[..3].copy_from_slice(&te);
    target[3..12].copy_from_slice(re.as_flattened());
    Inputs {
        q: Q0,
        params: [p.l_a],
        target,
        trocar,
        dt: 0.002,
        gains: [5.0, 10.0, 20.0, 0.05, 1e-3, 0.01, 2.0, 10.0],
    }
}

fn step(i: &Inputs) -> Outputs {
    let mut o = Outputs {
        status: -1,
        qd: [SENTINEL; 7],
        report: [SENTINEL; 8],
    };
    // SAFETY: every array has the length the function reads or writes (N = 7, PARAMS = 1,
    // 18, 3, 8, N, 8); the outputs are distinct locals.
    o.status = unsafe {
        m::panda_laparoscope_controller_step(
            i.q.as_ptr(),
            i.params.as_ptr(),
            i.target.as_ptr(),
            i.trocar.as_ptr(),
            i.dt,
            i.gains.as_ptr(),
            o.qd.as_mut_ptr(),
            o.report.as_mut_ptr(),
        )
    };
    o
}

/// A refused step: the code, `qd` all zeros (the joints stop), the report not written.
fn assert_refused(o: &Outputs, code: i32, what: &str) {
    assert_eq!(o.status, code, "{what}");
    assert_eq!(o.qd, [0.0; 7], "{what}: qd");
    assert_eq!(o.report, [SENTINEL; 8], "{what}: report");
}

/// A step that wrote its rates: finite, within the speed limit `gains[6]` (where positive) and,
/// over `dt`, within the joint ranges; the report finite.
fn assert_within_limits(i: &Inputs, o: &Outputs, what: &str) {
    assert!(o.qd.iter().all(|v| v.is_finite()), "{what}: qd {:?}", o.qd);
    assert!(
        o.report.iter().all(|v| v.is_finite()),
        "{what}: report {:?}",
        o.report
    );
    if i.gains[6] > 0.0 {
        // The rate box is computed in floating point: a few ulps.
        let limit = i.gains[6] * (1.0 + 1e-12);
        assert!(
            o.qd.iter().all(|v| v.abs() <= limit),
            "{what}: qd {:?} beyond the speed limit {}",
            o.qd,
            i.gains[6]
        );
    }
    for k in 0..7 {
        let [lo, hi] = m::JOINT_LIMITS[k];
        let next = i.q[k] + i.dt * o.qd[k];
        let tol = 1e-12 * (1.0 + next.abs());
        if (lo..=hi).contains(&i.q[k]) {
            assert!(
                next >= lo - tol && next <= hi + tol,
                "{what}: joint {k} to {next} beyond [{lo}, {hi}]"
            );
        } else {
            // Beyond its range: it may only move back.
            assert!(
                (i.q[k] > hi && o.qd[k] <= 0.0) || (i.q[k] < lo && o.qd[k] >= 0.0),
                "{what}: joint {k} at {} beyond [{lo}, {hi}] moves further ({})",
                i.q[k],
                o.qd[k]
            );
        }
    }
}

/// The values outside the number rule (finite, not subnormal, within ±1e6).
const HOSTILE: [f64; 8] = [
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    1e300,
    -1e300,
    1.000_001e6,
    -2e6,
    1e-310,
];

#[test]
fn the_unchanged_start_holds() {
    let i = inputs();
    let o = step(&i);
    assert_eq!(o.status, 0);
    assert_within_limits(&i, &o, "start");
    // A null report is allowed.
    let mut qd = [SENTINEL; 7];
    // SAFETY: as in `step`, the report null.
    let status = unsafe {
        m::panda_laparoscope_controller_step(
            i.q.as_ptr(),
            i.params.as_ptr(),
            i.target.as_ptr(),
            i.trocar.as_ptr(),
            i.dt,
            i.gains.as_ptr(),
            qd.as_mut_ptr(),
            std::ptr::null_mut(),
        )
    };
    assert_eq!(status, 0);
    assert_eq!(qd, o.qd);
}

/// The trocar at 1e300 gave rates of 2e301 with status 0: every input of each array, set to
/// each value outside the number rule, is refused.
#[test]
fn values_outside_the_number_rule_are_refused() {
    for bad in HOSTILE {
        for k in 0..7 {
            let mut i = inputs();
            i.q[k] = bad;
            assert_refused(
                &step(&i),
                m::C_INVALID_ARGUMENT,
                &format!("q[{k}] = {bad:e}"),
            );
        }
        let mut i = inputs();
        i.params[0] = bad;
        assert_refused(&step(&i), m::C_INVALID_ARGUMENT, &format!("l_a = {bad:e}"));
        for k in 0..18 {
            let mut i = inputs();
            i.target[k] = bad;
            assert_refused(
                &step(&i),
                m::C_INVALID_ARGUMENT,
                &format!("target[{k}] = {bad:e}"),
            );
        }
        for k in 0..3 {
            let mut i = inputs();
            i.trocar[k] = bad;
            assert_refused(
                &step(&i),
                m::C_INVALID_ARGUMENT,
                &format!("trocar[{k}] = {bad:e}"),
            );
        }
        // Every gain, the speed limit and the objective's gain included (`w0 = NaN` gave a NaN
        // report with status 0; `K_r = ±1e300` status 0).
        for k in 0..8 {
            let mut i = inputs();
            i.gains[k] = bad;
            assert_refused(
                &step(&i),
                m::C_INVALID_ARGUMENT,
                &format!("gains[{k}] = {bad:e}"),
            );
        }
        let mut i = inputs();
        i.dt = bad;
        assert_refused(&step(&i), m::C_INVALID_ARGUMENT, &format!("dt = {bad:e}"));
    }
}

/// `dt` NaN, 0, −0, −0.002 and ∞ returned 0.
#[test]
fn a_sample_time_that_is_not_positive_is_refused() {
    for dt in [
        f64::NAN,
        0.0,
        -0.0,
        -0.002,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ] {
        let mut i = inputs();
        i.dt = dt;
        assert_refused(&step(&i), m::C_INVALID_ARGUMENT, &format!("dt = {dt}"));
    }
}

/// Negative gains (which Rust and Python refuse) returned 0, and `K dt` at or beyond the stable
/// bound (`K_p dt`, `K_r dt` < 2, `K_o dt` < 4) is refused; just below it is not.
#[test]
fn gains_the_controller_refuses_are_refused() {
    for k in 0..6 {
        let mut i = inputs();
        i.gains[k] = -1.0;
        assert_refused(
            &step(&i),
            m::C_INVALID_ARGUMENT,
            &format!("gains[{k}] = -1"),
        );
    }
    // K dt at the bound (dt = 2 ms): K_p 1000, K_o 2000, K_r 1000.
    for (k, at) in [(0, 1000.0), (1, 2000.0), (2, 1000.0)] {
        let mut i = inputs();
        i.gains[k] = at;
        assert_refused(
            &step(&i),
            m::C_INVALID_ARGUMENT,
            &format!("gains[{k}] = {at}"),
        );
        i.gains[k] = at * 0.99;
        let o = step(&i);
        assert!(
            [0, m::C_TROCAR_YIELDED].contains(&o.status),
            "gains[{k}] = {}: {}",
            i.gains[k],
            o.status
        );
        assert_within_limits(&i, &o, &format!("gains[{k}] = {}", i.gains[k]));
    }
    // The speed limit and the objective's gain: ≤ 0 is "none", as documented.
    for k in [6, 7] {
        for v in [0.0, -1.0] {
            let mut i = inputs();
            i.gains[k] = v;
            let o = step(&i);
            assert_eq!(o.status, 0, "gains[{k}] = {v}");
            assert_within_limits(&i, &o, &format!("gains[{k}] = {v}"));
        }
    }
}

/// A null pointer other than `report` writes nothing.
#[test]
fn null_pointers_are_refused_and_nothing_is_written() {
    let i = inputs();
    for k in 0..6 {
        let mut qd = [SENTINEL; 7];
        let mut report = [SENTINEL; 8];
        let null = |j: usize, p: *const f64| if j == k { std::ptr::null() } else { p };
        let qd_ptr = if k == 5 {
            std::ptr::null_mut()
        } else {
            qd.as_mut_ptr()
        };
        // SAFETY: as in `step`; the pointer `k` is null, which the function checks first.
        let status = unsafe {
            m::panda_laparoscope_controller_step(
                null(0, i.q.as_ptr()),
                null(1, i.params.as_ptr()),
                null(2, i.target.as_ptr()),
                null(3, i.trocar.as_ptr()),
                i.dt,
                null(4, i.gains.as_ptr()),
                qd_ptr,
                report.as_mut_ptr(),
            )
        };
        assert_eq!(status, m::C_NULL_ARGUMENT, "pointer {k}");
        assert_eq!(qd, [SENTINEL; 7], "pointer {k}");
        assert_eq!(report, [SENTINEL; 8], "pointer {k}");
    }
}

/// A trocar 0.2 m off the shaft with the speed limit 2 rad/s gave |qd| = 7 rad/s and status 0:
/// each step of 200 keeps every |qd| ≤ 2 and the joints within their ranges, and the steps
/// that cannot hold the trocar say so.
#[test]
fn a_trocar_off_the_shaft_keeps_the_speed_limit_and_yields() {
    let mut i = inputs();
    i.trocar[0] += 0.2;
    let mut yielded = 0;
    for k in 0..200 {
        let o = step(&i);
        assert!(
            [0, m::C_TROCAR_YIELDED].contains(&o.status),
            "step {k}: {}",
            o.status
        );
        assert_within_limits(&i, &o, &format!("step {k}"));
        if o.status == m::C_TROCAR_YIELDED {
            yielded += 1;
        }
        for j in 0..7 {
            i.q[j] += i.dt * o.qd[j];
        }
    }
    assert!(yielded > 0, "the first steps ask for more than 2 rad/s");
    // The first step asks the most: it yields.
    let mut first = inputs();
    first.trocar[0] += 0.2;
    assert_eq!(step(&first).status, m::C_TROCAR_YIELDED);
}

/// A joint beyond its range: the step says so and only moves it back; at a bound the rates do
/// not take it past over `dt`.
#[test]
fn joints_keep_their_ranges() {
    let [lo3, hi3] = m::JOINT_LIMITS[3];
    let mut i = inputs();
    i.q[3] = hi3 + 0.05;
    let o = step(&i);
    assert!(
        [m::C_JOINT_OUTSIDE, m::C_TROCAR_YIELDED].contains(&o.status),
        "{}",
        o.status
    );
    assert_within_limits(&i, &o, "joint 4 beyond its upper limit");
    // At the lower bound, with the tip asked to go where joint 4 would pass it.
    let mut i = inputs();
    i.q[3] = lo3;
    i.target[2] -= 0.3;
    i.target[14] = -1.0;
    let o = step(&i);
    assert!([0, m::C_TROCAR_YIELDED].contains(&o.status), "{}", o.status);
    assert_within_limits(&i, &o, "joint 4 at its lower limit");
}

/// A deterministic sweep of inputs within the rules (gains up to their bound, targets far off,
/// trocars off the shaft, speed limits from 1e-3 to none, `q` near and beyond the limits): the
/// rates always keep the limits, the report is finite, and the code is one of the documented
/// ones.
#[test]
fn any_accepted_step_keeps_the_limits() {
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut uniform = |lo: f64, hi: f64| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        lo + (hi - lo) * ((state >> 11) as f64 / (1u64 << 53) as f64)
    };
    let mut codes = [0usize; 7];
    for case in 0..2000 {
        let mut i = inputs();
        for k in 0..7 {
            let [lo, hi] = m::JOINT_LIMITS[k];
            i.q[k] = uniform(lo - 0.1, hi + 0.1);
        }
        for k in 0..3 {
            i.target[k] += uniform(-0.5, 0.5);
            i.trocar[k] += uniform(-0.3, 0.3);
        }
        for k in 12..18 {
            i.target[k] = uniform(-2.0, 2.0);
        }
        let bound = 2.0 / i.dt;
        i.gains[0] = uniform(0.0, 0.999 * bound);
        i.gains[1] = uniform(0.0, 1.999 * bound);
        i.gains[2] = uniform(0.0, 0.999 * bound);
        i.gains[6] = [1e-3, 0.5, 2.0, 100.0, -1.0][case % 5];
        i.gains[7] = uniform(-1.0, 20.0);
        let o = step(&i);
        let what = format!("case {case}");
        match o.status {
            0 => {
                assert_within_limits(&i, &o, &what);
                assert!(i
                    .q
                    .iter()
                    .zip(&m::JOINT_LIMITS)
                    .all(|(q, [lo, hi])| q >= lo && q <= hi));
            }
            m::C_TROCAR_YIELDED | m::C_JOINT_OUTSIDE => assert_within_limits(&i, &o, &what),
            m::C_CONTROL_ERROR => assert_refused(&o, m::C_CONTROL_ERROR, &what),
            other => panic!("{what}: code {other}"),
        }
        codes[o.status as usize] += 1;
    }
    assert!(
        codes[m::C_TROCAR_YIELDED as usize] > 0 && codes[0] > 0,
        "{codes:?}"
    );
}

/// The Panda's URDF velocities (`<limit velocity>` of joints 1–4 and 5–7, rad/s).
const URDF_VELOCITY: [f64; 7] = [2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61];

/// With no speed limit in `gains[6]` (0) or one above the joints' own (3 rad/s), a trocar
/// 0.2 m off the shaft gave |qd| of 7 rad/s: beyond the URDF's 2.175 rad/s, with a success
/// code. Every step of 200 keeps each joint's own speed limit.
#[test]
fn the_joints_own_speed_limits_hold_without_a_speed_limit() {
    for speed in [0.0, 3.0] {
        let mut i = inputs();
        i.trocar[0] += 0.2;
        i.gains[6] = speed;
        let mut fastest = 0.0_f64;
        for k in 0..200 {
            let o = step(&i);
            assert!(
                [0, m::C_TROCAR_YIELDED].contains(&o.status),
                "gains[6] = {speed}, step {k}: {}",
                o.status
            );
            assert_within_limits(&i, &o, &format!("gains[6] = {speed}, step {k}"));
            for (j, velocity) in URDF_VELOCITY.into_iter().enumerate() {
                assert!(
                    o.qd[j].abs() <= velocity * (1.0 + 1e-12),
                    "gains[6] = {speed}, step {k}: joint {j} at {} rad/s",
                    o.qd[j]
                );
                fastest = fastest.max(o.qd[j].abs() / velocity);
                i.q[j] += i.dt * o.qd[j];
            }
        }
        // The first steps ask for more than the joints can give: a joint is at its limit.
        assert!(fastest > 0.99, "gains[6] = {speed}: {fastest}");
    }
}
