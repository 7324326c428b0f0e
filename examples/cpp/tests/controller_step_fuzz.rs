//! A fuzzer of `panda_laparoscope_controller_step` through its C ABI: random steps mixing
//! ordinary inputs near the Panda's working pose (joints near `Q0`, anywhere in, at or beyond
//! their ranges; the trocar on, near or far off the shaft; targets near the tip; gains from 0 to
//! beyond their stable bound; `dt` from 1 µs to 0.1 s) with hostile values in random slots (NaN,
//! ±∞, ±1e300, subnormals, −0, ±1e6 and just beyond) and, now and then, a null pointer; the
//! target's orientation the tip's, turned a little (a rotation), or any nine numbers (refused:
//! not a proper rotation).
//!
//! The property, for every case: the function returns (a panic across `extern "C"` would abort
//! the test), the code is the one the inputs call for — `NULL_ARGUMENT` with nothing written,
//! `INVALID_ARGUMENT` with `qd` zeros and the report not written, else 0, `TROCAR_YIELDED`,
//! `JOINT_OUTSIDE` or `CONTROL_ERROR` — and what is written obeys the header: after a step the
//! rates and the report are finite, every `|qd_k|` is within the speed limit `gains[6]` (when
//! positive) and the joint's URDF velocity, every joint stays within its URDF range over `dt`
//! (or, beyond it, does not move further out), 0 comes only with every joint in range and the
//! trocar rows met, `JOINT_OUTSIDE` only with a joint out of range and the rows met.
//!
//! The limits are parsed from the Panda's URDF here, not taken from the generated module. The
//! number of cases is `TROCAR_C_FUZZ_CASES` (20 000 by default); `c_controller_step_fuzz_long`
//! (ignored) runs 10⁵. docs/RELIABILITY.md, "The C ABI's controller step", has the figures of a run.

use proptest::prelude::*;
use proptest::test_runner::{Config, TestCaseError, TestRunner};
use std::cell::RefCell;
use std::path::Path;
use trocar_cpp_example::panda_laparoscope as m;
use trocar_cpp_example::Q0;

/// The value `qd` and `report` hold before a step: a step that writes them overwrites it.
const SENTINEL: f64 = -123.25;

/// The number rule's bound on every value the step reads.
const MAX: f64 = 1e6;

/// The next value after 1e6: just beyond the number rule.
const BEYOND: f64 = f64::from_bits(MAX.to_bits() + 1);

/// Number of value slots a case can poison: `q` (7), `params` (1), `target` (18), `trocar`
/// (3), `gains` (8) and `dt`.
const SLOTS: usize = 7 + 1 + 18 + 3 + 8 + 1;

/// The return codes of the header, by value (checked against the module's constants below).
const CODES: [(i32, &str); 7] = [
    (0, "0 (held)"),
    (1, "NOT_FINITE"),
    (2, "NULL_ARGUMENT"),
    (3, "CONTROL_ERROR"),
    (4, "INVALID_ARGUMENT"),
    (5, "TROCAR_YIELDED"),
    (6, "JOINT_OUTSIDE"),
];

/// `(lower, upper, velocity)` of the Panda's seven joints, parsed from the shipped URDF.
fn urdf_limits() -> [(f64, f64, f64); 7] {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../runtime/model/robots/urdf/panda.urdf");
    let text = std::fs::read_to_string(&path).expect("the Panda URDF is readable");
    let attr = |tag: &str, name: &str| -> f64 {
        let key = format!("{name}=\"");
        let start = tag.find(&key).unwrap_or_else(|| panic!("{name} in {tag}")) + key.len();
        let end = start + tag[start..].find('"').unwrap();
        tag[start..end].parse().unwrap()
    };
    let limits: Vec<_> = text
        .lines()
        .filter(|l| l.trim_start().starts_with("<limit "))
        .map(|l| (attr(l, "lower"), attr(l, "upper"), attr(l, "velocity")))
        .collect();
    limits
        .try_into()
        .expect("seven revolute joints with limits")
}

/// One call: the inputs as a C caller holds them, and which pointer (if any) is null: 0 `q`,
/// 1 `params`, 2 `target`, 3 `trocar`, 4 `gains`, 5 `qd`, 6 `report`.
#[derive(Clone, Debug)]
struct Case {
    q: [f64; 7],
    params: [f64; 1],
    target: [f64; 18],
    trocar: [f64; 3],
    dt: f64,
    gains: [f64; 8],
    null: Option<usize>,
}

impl Case {
    /// The value slot `k` of [`SLOTS`].
    fn slot(&mut self, k: usize) -> &mut f64 {
        match k {
            0..7 => &mut self.q[k],
            7 => &mut self.params[0],
            8..26 => &mut self.target[k - 8],
            26..29 => &mut self.trocar[k - 26],
            29..37 => &mut self.gains[k - 29],
            _ => &mut self.dt,
        }
    }
}

/// What a step wrote: the return code, `qd` and `report` (which start as [`SENTINEL`]).
struct Outputs {
    status: i32,
    qd: [f64; 7],
    report: [f64; 8],
}

fn step(c: &Case) -> Outputs {
    let mut o = Outputs {
        status: -1,
        qd: [SENTINEL; 7],
        report: [SENTINEL; 8],
    };
    let input = |k: usize, p: *const f64| {
        if c.null == Some(k) {
            std::ptr::null()
        } else {
            p
        }
    };
    let output = |k: usize, p: *mut f64| {
        if c.null == Some(k) {
            std::ptr::null_mut()
        } else {
            p
        }
    };
    // SAFETY: every array has the length the function reads or writes (N = 7, PARAMS = 1, 18,
    // 3, 8, N, 8); the outputs are distinct locals; a null pointer is one the function checks
    // before reading (any input, `qd`) or allows (`report`).
    o.status = unsafe {
        m::panda_laparoscope_controller_step(
            input(0, c.q.as_ptr()),
            input(1, c.params.as_ptr()),
            input(2, c.target.as_ptr()),
            input(3, c.trocar.as_ptr()),
            c.dt,
            input(4, c.gains.as_ptr()),
            output(5, o.qd.as_mut_ptr()),
            output(6, o.report.as_mut_ptr()),
        )
    };
    o
}

/// The number rule: finite, not subnormal, within ±1e6.
fn rule(v: f64) -> bool {
    v.is_finite() && v.abs() <= MAX && (v == 0.0 || v.abs() >= f64::MIN_POSITIVE)
}

/// Whether the header's rules accept the values of `c`: every value read follows the number
/// rule, `dt > 0`, `K_p`, `K_o`, `K_r`, `α0` and both `w0` non-negative, `K_p dt < 2`,
/// `K_r dt < 2`, `K_o dt < 4`.
fn accepted(c: &Case) -> bool {
    let g = &c.gains;
    c.q.iter()
        .chain(&c.params)
        .chain(&c.target)
        .chain(&c.trocar)
        .chain(g)
        .chain([&c.dt])
        .all(|&v| rule(v))
        && c.dt > 0.0
        && g[..6].iter().all(|&k| k >= 0.0)
        && g[0] * c.dt < 2.0
        && g[1] * c.dt < 4.0
        && g[2] * c.dt < 2.0
        && proper_rotation(&c.target[3..12])
}

/// Whether the target's orientation (column-major) is a proper rotation to 1e-6: every entry of
/// `RᵀR − I` within 1e-6 and `det R > 0` (the header's rule, computed here on its own).
fn proper_rotation(r: &[f64]) -> bool {
    let column = |c: usize| [r[3 * c], r[3 * c + 1], r[3 * c + 2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let orthonormal = (0..3).all(|i| {
        (0..3).all(|j| {
            let target = if i == j { 1.0 } else { 0.0 };
            (dot(column(i), column(j)) - target).abs() <= 1e-6
        })
    });
    let (x, y, z) = (column(0), column(1), column(2));
    let cross = [
        y[1] * z[2] - y[2] * z[1],
        y[2] * z[0] - y[0] * z[2],
        y[0] * z[1] - y[1] * z[0],
    ];
    orthonormal && dot(x, cross) > 0.0
}

/// The point of the link at `l_a` along the shaft (the constraint frame's origin) and the
/// frame's rotation (`R_r`, columns), at `q`.
fn constraint_point(q: &[f64; 7], l_a: f64) -> ([f64; 3], [[f64; 3]; 3]) {
    let p = m::Params { l_a };
    let (ri, ti) = m::forward_kinematics_i(q, &p);
    let (rir, tir) = m::constraint_frame(&p);
    let mut point = ti;
    let mut rr = [[0.0; 3]; 3];
    for r in 0..3 {
        for c in 0..3 {
            point[r] += ri[c][r] * tir[c];
            for k in 0..3 {
                rr[c][r] += ri[k][r] * rir[c][k];
            }
        }
    }
    (point, rr)
}

/// The residual of the trocar rows `Λ J^B_0i θ̇ = K_r e_r` (the link's point at `l_a` moves
/// sideways, in the constraint frame, at `K_r` times the trocar's lateral offset from it),
/// with the point's velocity by central differences of the forward kinematics; and the scale
/// of the terms.
fn trocar_rows(c: &Case, qd: &[f64; 7], l_a: f64) -> (f64, f64) {
    let (point, rr) = constraint_point(&c.q, l_a);
    let speed = qd.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
    // A joint displacement of 1e-5 rad along qd.
    let h = if speed > 0.0 { 1e-5 / speed } else { 1.0 };
    // The joints turned back by whole turns, so that the step along qd is not lost in the
    // rounding of a large joint value (q = 1e6 is within the number rule).
    let turn = std::f64::consts::TAU;
    let q0: [f64; 7] = std::array::from_fn(|k| c.q[k] - turn * (c.q[k] / turn).round());
    let at = |s: f64| {
        let q: [f64; 7] = std::array::from_fn(|k| q0[k] + s * h * qd[k]);
        constraint_point(&q, l_a).0
    };
    let (ahead, back) = (at(1.0), at(-1.0));
    let mut residual = 0.0_f64;
    // The point's speed is up to the joints' times its distance from the base.
    let reach = point.iter().fold(1.0_f64, |a, v| a.max(v.abs()));
    let mut scale = speed * reach;
    // The lateral axes: the constraint frame's x and y.
    for axis in &rr[..2] {
        let along = |v: [f64; 3]| (0..3).map(|r| axis[r] * v[r]).sum::<f64>();
        let velocity = along(std::array::from_fn(|r| (ahead[r] - back[r]) / (2.0 * h)));
        let offset = along(std::array::from_fn(|r| c.trocar[r] - point[r]));
        residual = residual.max((velocity - c.gains[2] * offset).abs());
        scale = scale.max((c.gains[2] * offset).abs());
    }
    (residual, scale)
}

/// Checks one case against the header's contract; the code returned is counted by the caller.
fn check(c: &Case, o: &Outputs, limits: &[(f64, f64, f64); 7]) -> Result<(), TestCaseError> {
    let untouched = |o: &Outputs| o.qd == [SENTINEL; 7] && o.report == [SENTINEL; 8];
    if matches!(c.null, Some(0..=5)) {
        prop_assert_eq!(o.status, m::C_NULL_ARGUMENT);
        prop_assert!(
            untouched(o),
            "a null pointer, yet written: {:?} {:?}",
            o.qd,
            o.report
        );
        return Ok(());
    }
    let report_null = c.null == Some(6);
    if !accepted(c) {
        prop_assert_eq!(o.status, m::C_INVALID_ARGUMENT);
        prop_assert_eq!(o.qd, [0.0; 7]);
        prop_assert_eq!(o.report, [SENTINEL; 8]);
        return Ok(());
    }
    let outside = |k: usize| !(limits[k].0..=limits[k].1).contains(&c.q[k]);
    match o.status {
        0 | m::C_TROCAR_YIELDED | m::C_JOINT_OUTSIDE => {}
        m::C_CONTROL_ERROR => {
            prop_assert_eq!(o.qd, [0.0; 7]);
            prop_assert_eq!(o.report, [SENTINEL; 8]);
            return Ok(());
        }
        other => return Err(TestCaseError::fail(format!("code {other}"))),
    }
    prop_assert!(o.qd.iter().all(|v| v.is_finite()), "qd {:?}", o.qd);
    if report_null {
        prop_assert_eq!(o.report, [SENTINEL; 8]);
    } else {
        prop_assert!(
            o.report.iter().all(|v| v.is_finite() && *v != SENTINEL),
            "report {:?}",
            o.report
        );
    }
    // The rate box is computed in floating point: a few ulps.
    let ulps = 1.0 + 1e-12;
    for (k, &(lo, hi, velocity)) in limits.iter().enumerate() {
        let v = o.qd[k];
        if c.gains[6] > 0.0 {
            prop_assert!(
                v.abs() <= c.gains[6] * ulps,
                "joint {}: |qd| = {} beyond the speed limit {}",
                k,
                v.abs(),
                c.gains[6]
            );
        }
        prop_assert!(
            v.abs() <= velocity * ulps,
            "joint {}: |qd| = {} beyond the URDF velocity {}",
            k,
            v.abs(),
            velocity
        );
        if outside(k) {
            prop_assert!(
                (c.q[k] > hi && v <= 0.0) || (c.q[k] < lo && v >= 0.0),
                "joint {} at {} beyond [{}, {}] moves further ({})",
                k,
                c.q[k],
                lo,
                hi,
                v
            );
        } else {
            let next = c.q[k] + c.dt * v;
            let tol = 1e-12 * (1.0 + next.abs());
            prop_assert!(
                next >= lo - tol && next <= hi + tol,
                "joint {} from {} to {} beyond [{}, {}] over dt {}",
                k,
                c.q[k],
                next,
                lo,
                hi,
                c.dt
            );
        }
    }
    let any_outside = (0..7).any(outside);
    if o.status == 0 {
        prop_assert!(!any_outside, "0 with a joint beyond its range: {:?}", c.q);
    }
    if o.status == m::C_JOINT_OUTSIDE {
        prop_assert!(any_outside, "JOINT_OUTSIDE with every joint in range");
    }
    // 0 and JOINT_OUTSIDE: the trocar rows were met (the report's `l_a` is where).
    if (o.status == 0 || o.status == m::C_JOINT_OUTSIDE) && !report_null {
        let (residual, scale) = trocar_rows(c, &o.qd, o.report[0]);
        prop_assert!(
            residual <= 1e-6 * (1.0 + scale),
            "code {}: the trocar rows are off by {} (scale {})",
            o.status,
            residual,
            scale
        );
    }
    Ok(())
}

/// Values outside the number rule or at its edges.
fn hostile() -> impl Strategy<Value = f64> {
    prop::sample::select(vec![
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        1e300,
        -1e300,
        1e-310,
        -1e-310,
        f64::MIN_POSITIVE / 2.0,
        f64::MIN_POSITIVE,
        -0.0,
        MAX,
        -MAX,
        BEYOND,
        -BEYOND,
        1.000_001e6,
        -2e6,
    ])
}

/// One joint value: near `Q0`, in its range, at a bound, just or far beyond.
fn joint(k: usize, (lo, hi, _): (f64, f64, f64)) -> BoxedStrategy<f64> {
    prop_oneof![
        4 => (-0.3..0.3).prop_map(move |d: f64| Q0[k] + d),
        3 => lo..=hi,
        1 => prop::sample::select(vec![lo, hi]),
        1 => (0.0..0.5).prop_map(move |d: f64| lo - d),
        1 => (0.0..0.5).prop_map(move |d: f64| hi + d),
        1 => -10.0..10.0,
    ]
    .boxed()
}

/// A gain as a fraction of its stable bound `bound / dt`: within it, 0, at or just beyond it,
/// or negative.
fn fraction() -> impl Strategy<Value = f64> {
    prop_oneof![
        24 => 0.0..0.999,
        2 => Just(0.0),
        1 => prop::sample::select(vec![0.999_999, 1.0, 1.000_001]),
        1 => 0.999..1.5,
        1 => -1.0..0.0,
    ]
}

/// A damping parameter (`α0`, `w0`).
fn damping() -> impl Strategy<Value = f64> {
    prop_oneof![
        8 => 0.0..0.1,
        4 => 0.0..10.0,
        2 => Just(0.0),
        1 => -1.0..0.0,
    ]
}

/// The random cases.
fn strategy(limits: [(f64, f64, f64); 7]) -> impl Strategy<Value = Case> {
    let per_joint: Vec<_> = (0..7).map(|k| joint(k, limits[k])).collect();
    let q = prop_oneof![
        3 => prop::array::uniform7(-0.3..0.3).prop_map(|d: [f64; 7]| {
            std::array::from_fn(|k| Q0[k] + d[k])
        }),
        2 => prop::array::uniform7(0.0..=1.0).prop_map(move |u: [f64; 7]| {
            std::array::from_fn(|k| limits[k].0 + u[k] * (limits[k].1 - limits[k].0))
        }),
        2 => per_joint.prop_map(|v| <[f64; 7]>::try_from(v).unwrap()),
    ];
    // The shaft's l_a, and the parameter passed (the same, or another).
    let l_a = prop_oneof![4 => 0.1..0.4, 1 => -1.0..1.0, 1 => Just(0.0)];
    let param = prop_oneof![4 => Just(None), 1 => (-1.0..1.0).prop_map(Some)];
    // The trocar's offset from the shaft's point at l_a.
    let trocar = prop_oneof![
        3 => Just([0.0; 3]),
        2 => prop::array::uniform3(-0.01..0.01),
        1 => prop::array::uniform3(-0.3..0.3),
        1 => prop::array::uniform3(-5.0..5.0),
    ];
    // The target: the tip's offset, its rotation (the tip's, perturbed, or any entries) and
    // the feed-forward velocities.
    let position = prop_oneof![
        3 => prop::array::uniform3(-0.01..0.01),
        2 => prop::array::uniform3(-0.1..0.1),
        1 => prop::array::uniform3(-1.0..1.0),
    ];
    // The target's orientation: the tip's, the tip's turned by up to 0.1 rad about any axis (a
    // rotation), or any entries (almost never a rotation: refused).
    let rotation = prop_oneof![
        3 => Just(None),
        1 => prop::array::uniform3(-0.05..0.05).prop_map(|w| Some((turn(w), false))),
        1 => prop::array::uniform9(-2.0..2.0).prop_map(|d| Some((d, true))),
    ];
    let velocity = prop_oneof![
        3 => Just([0.0; 6]),
        2 => prop::array::uniform6(-0.1..0.1),
        1 => prop::array::uniform6(-10.0..10.0),
    ];
    let dt = prop_oneof![
        16 => (1e-6_f64.ln()..0.1_f64.ln()).prop_map(f64::exp),
        2 => prop::sample::select(vec![0.002, 0.001, 0.01, 0.1, 1e-6, 0.5, 10.0]),
        1 => prop::sample::select(vec![
            0.0,
            -0.0,
            -0.002,
            1e-310,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            1e300,
            BEYOND,
        ]),
    ];
    let speed = prop_oneof![
        1 => Just(-1.0),
        1 => Just(0.0),
        1 => Just(1e-3),
        2 => 0.0..3.0,
        1 => Just(2.0),
        1 => 3.0..100.0,
    ];
    let gains = (
        prop::array::uniform3(fraction()),
        prop::array::uniform3(damping()),
        speed,
        prop_oneof![1 => Just(0.0), 3 => -1.0..20.0],
    );
    let poison = prop_oneof![
        3 => Just(vec![]),
        1 => prop::collection::vec((0..SLOTS, hostile()), 1..=3),
    ];
    let null = prop_oneof![30 => Just(None), 1 => (0..7usize).prop_map(Some)];
    (
        (q, l_a, param, trocar),
        (position, rotation, velocity),
        (dt, gains),
        (poison, null),
    )
        .prop_map(
            |(
                (q, l_a, param, offset),
                (position, rotation, velocity),
                (dt, (fractions, damping, speed, objective)),
                (poison, null),
            )| {
                let (point, _) = constraint_point(&q, l_a);
                let trocar = std::array::from_fn(|r| point[r] + offset[r]);
                let p = m::Params { l_a };
                let (re, te) = m::forward_kinematics(&q, &p);
                let mut target = [0.0; 18];
                for r in 0..3 {
                    target[r] = te[r] + position[r];
                }
                target[3..12].copy_from_slice(re.as_flattened());
                match rotation {
                    Some((d, true)) => target[3..12].copy_from_slice(&d),
                    Some((turned, false)) => {
                        // `R_e · turn`, column-major.
                        let re = re.as_flattened();
                        for c in 0..3 {
                            for r in 0..3 {
                                target[3 + 3 * c + r] =
                                    (0..3).map(|k| re[3 * k + r] * turned[3 * c + k]).sum();
                            }
                        }
                    }
                    None => {}
                }
                target[12..].copy_from_slice(&velocity);
                // The gains' bounds at dt (at 2 ms when dt is not a usable sample time).
                let at = if dt.is_finite() && dt > 0.0 {
                    dt
                } else {
                    0.002
                };
                let bounds = [2.0 / at, 4.0 / at, 2.0 / at];
                let mut gains = [0.0; 8];
                for k in 0..3 {
                    gains[k] = fractions[k] * bounds[k];
                    gains[3 + k] = damping[k];
                }
                gains[6] = speed;
                gains[7] = objective;
                let mut c = Case {
                    q,
                    params: [param.unwrap_or(l_a)],
                    target,
                    trocar,
                    dt,
                    gains,
                    null,
                };
                for (k, v) in poison {
                    *c.slot(k) = v;
                }
                c
            },
        )
}

/// The rotation `exp([w]×)` (Rodrigues), column-major.
fn turn(w: [f64; 3]) -> [f64; 9] {
    let angle = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
    let (s, c) = angle.sin_cos();
    let (a, b) = if angle > 0.0 {
        (s / angle, (1.0 - c) / (angle * angle))
    } else {
        (1.0, 0.5)
    };
    let k = [[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]];
    let mut out = [0.0; 9];
    for col in 0..3 {
        for row in 0..3 {
            let k2: f64 = (0..3).map(|m| k[row][m] * k[m][col]).sum();
            let identity = if row == col { 1.0 } else { 0.0 };
            out[3 * col + row] = identity + a * k[row][col] + b * k2;
        }
    }
    out
}

/// Runs `cases` random cases; the count of each return code.
fn fuzz(cases: u32) -> [u64; 7] {
    assert_eq!(
        [
            m::C_NOT_FINITE,
            m::C_NULL_ARGUMENT,
            m::C_CONTROL_ERROR,
            m::C_INVALID_ARGUMENT,
            m::C_TROCAR_YIELDED,
            m::C_JOINT_OUTSIDE
        ],
        [1, 2, 3, 4, 5, 6],
        "the header's codes"
    );
    let limits = urdf_limits();
    let counts = RefCell::new([0u64; 7]);
    let mut runner = TestRunner::new(Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    });
    let result = runner.run(&strategy(limits), |c| {
        let o = step(&c);
        check(&c, &o, &limits)?;
        counts.borrow_mut()[o.status as usize] += 1;
        Ok(())
    });
    if let Err(e) = result {
        panic!("{e}");
    }
    let counts = counts.into_inner();
    let summary: Vec<String> = CODES
        .iter()
        .map(|(code, name)| format!("{name}: {}", counts[*code as usize]))
        .collect();
    eprintln!("{cases} cases; {}", summary.join(", "));
    counts
}

/// The number of cases: `TROCAR_C_FUZZ_CASES`, else `default`.
fn case_count(default: u32) -> u32 {
    match std::env::var("TROCAR_C_FUZZ_CASES") {
        Ok(v) => v
            .parse()
            .unwrap_or_else(|_| panic!("TROCAR_C_FUZZ_CASES = {v:?} is not a count")),
        Err(_) => default,
    }
}

/// The fuzz run of CI: every case keeps the contract, and the cases reach every code a caller
/// can get but `CONTROL_ERROR` (which needs a degenerate pose).
#[test]
fn c_controller_step_fuzz() {
    let counts = fuzz(case_count(20_000));
    for code in [
        0,
        m::C_NULL_ARGUMENT,
        m::C_INVALID_ARGUMENT,
        m::C_TROCAR_YIELDED,
        m::C_JOINT_OUTSIDE,
    ] {
        assert!(counts[code as usize] > 0, "no case gave {code}: {counts:?}");
    }
}

/// The long run of docs/RELIABILITY.md: 10⁵ cases (or `TROCAR_C_FUZZ_CASES`).
#[test]
#[ignore = "the long run: 1e5 cases"]
fn c_controller_step_fuzz_long() {
    fuzz(case_count(100_000));
}
