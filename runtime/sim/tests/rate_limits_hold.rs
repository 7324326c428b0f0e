//! Acceleration and jerk limits are limits of every control step, whatever it is asked.
//!
//! Random scenes on the Panda laparoscope's numeric kinematics, as `limits_hold.rs` makes them
//! (`q` within, at or beyond its ranges, the trocar on or off the shaft, speed limits, depth
//! bounds, gains up to their stable bound, every method), with acceleration and jerk limits (the
//! Panda's datasheet values scaled by 0.01–10, or none) and a previous command
//! ([`Controller::set_previous_rates`]: rest, slow, or up to twice the speed limits, with a
//! previous acceleration). Each step's rates are checked, joint by joint, against the bounds as
//! defined in `trocar::control::rate_box`:
//!
//! - (B1) the speed limit and the range over the sample time, always;
//! - (B2) `|θ̇ − θ̇⁻| ≤ a_max dt` wherever some rate meets it within (B1);
//! - (B3) the braking bound wherever some rate meets it within (B1)–(B2);
//! - (B4) `|θ̇ − θ̇⁻ − dt a⁻| ≤ j_max dt²` wherever some rate meets it within (B1)–(B3), unless
//!   the step says the jerk bound gave way (it also gives way to the trocar rows);
//!
//! and [`StepOutput::relaxed`] names at least the most important bound that had no rate in
//! common with those before it at some joint. A second property runs a few steps from rest and integrates
//! them: then the acceleration and braking bounds never give way. `TROCAR_LIMITS_CASES` sets the
//! number of cases (default 4000; the second runs a quarter as many).

// Joint by joint: the index names the joint in several arrays at once.
#![allow(clippy::needless_range_loop)]

use nalgebra::{SVector, Vector3};
use proptest::prelude::*;
use trocar::control::{
    braking_speed, gain_bound, ChainKinematics, Controller, ControllerConfig, Damping, HardLimits,
    Method, QpWeights, RateRelaxation, Rcm, Reference, StepOutput, StepStatus,
};
use trocar_model::description::RobotDescription;
use trocar_model::numeric::NumericModel;

type Kin = ChainKinematics<f64, 7, 2, 4>;

/// The Panda's datasheet: joint accelerations (rad/s²) and jerks (rad/s³).
const PANDA_ACCELERATION: [f64; 7] = [15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0];
const PANDA_JERK: [f64; 7] = [7500.0, 3750.0, 5000.0, 6250.0, 7500.0, 10000.0, 10000.0];

fn panda() -> (Kin, Vec<[f64; 2]>, Vec<f64>) {
    let d = RobotDescription::preset("panda-laparoscope").unwrap();
    let kin = NumericModel::<f64>::from_description(&d, &[])
        .unwrap()
        .to_kinematics::<7, 2, 4>()
        .unwrap();
    let ranges = d.joints.iter().map(|j| j.limits.unwrap()).collect();
    let speeds = d.joints.iter().map(|j| j.speed_limit.unwrap()).collect();
    (kin, ranges, speeds)
}

fn cases(default: u32) -> u32 {
    std::env::var("TROCAR_LIMITS_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

#[derive(Clone, Debug)]
struct Scene {
    place: [f64; 7],
    trocar_off: [f64; 3],
    l_a: f64,
    max_speed: Option<f64>,
    speed_scale: f64,
    depth: Option<(f64, f64)>,
    gains: [f64; 3],
    /// 0: QP, 1: DLS, 2: pseudo-inverse, 3: filtered inverse.
    method: usize,
    target: [f64; 3],
    velocity: [f64; 3],
    dv: [f64; 2],
    dt: f64,
    /// Scales of the Panda's acceleration and jerk limits, or none.
    acceleration: Option<f64>,
    jerk: Option<f64>,
    /// The previous command as fractions of the speed limits, and its acceleration as fractions
    /// of the acceleration limits.
    previous: [f64; 7],
    previous_acceleration: [f64; 7],
}

fn scene() -> impl Strategy<Value = Scene> {
    let place = prop_oneof![
        4 => 0.05..0.95f64,
        1 => Just(0.0),
        1 => Just(1.0),
        1 => -0.2..0.0f64,
        1 => 1.0..1.2f64,
        1 => prop_oneof![Just(1e-9), Just(1.0 - 1e-9), 1e-4..0.02f64, 0.98..0.9999f64],
    ];
    let off = prop_oneof![3 => Just(0.0), 2 => -1e-3..1e-3f64, 1 => -0.3..0.3f64];
    let gain = prop_oneof![2 => 0.0..0.5f64, 1 => Just(0.999_999), 1 => 0.9..0.999_999f64];
    let rate = prop_oneof![2 => Just(0.0), 2 => -0.1..0.1f64, 3 => -1.0..1.0f64, 1 => -2.0..2.0f64];
    let rate_acceleration = prop_oneof![2 => Just(0.0), 2 => -1.0..1.0f64, 1 => -3.0..3.0f64];
    (
        (prop::array::uniform7(place), prop::array::uniform3(off)),
        (
            0.1..0.35f64,
            prop::option::of(prop_oneof![1e-4..0.01f64, 0.01..3.0f64]),
            prop_oneof![Just(1.0), 1e-4..1.0f64],
            prop::option::of((-0.05..0.2f64, -0.05..0.2f64)),
        ),
        (prop::array::uniform3(gain), 0..4usize),
        (
            prop::array::uniform3(-0.05..0.05f64),
            prop::array::uniform3(-0.5..0.5f64),
            prop::array::uniform2(prop_oneof![3 => Just(0.0), 1 => -0.05..0.05f64]),
            prop_oneof![Just(0.002), Just(0.001), 1e-4..0.02f64],
        ),
        (
            prop::option::of(prop_oneof![Just(1.0), 0.01..10.0f64]),
            prop::option::of(prop_oneof![Just(1.0), 0.001..10.0f64]),
            prop::array::uniform7(rate),
            prop::array::uniform7(rate_acceleration),
        ),
    )
        .prop_map(
            |(
                (place, trocar_off),
                (l_a, max_speed, speed_scale, depth),
                (gains, method),
                (target, velocity, dv, dt),
                (acceleration, jerk, previous, previous_acceleration),
            )| Scene {
                place,
                trocar_off,
                l_a,
                max_speed,
                speed_scale,
                depth,
                gains,
                method,
                target,
                velocity,
                dv,
                dt,
                acceleration,
                jerk,
                previous,
                previous_acceleration,
            },
        )
}

struct Built {
    ctrl: Controller<f64, 7, 7, 2, 4, 4, 4>,
    q: SVector<f64, 7>,
    rcm: Rcm<f64, 2>,
    reference: Reference<f64>,
    limits: HardLimits<f64, 7>,
}

fn build(kin: &Kin, ranges: &[[f64; 2]], speeds: &[f64], s: &Scene, moving: bool) -> Built {
    let q = SVector::<f64, 7>::from_fn(|k, _| {
        let [lo, hi] = ranges[k];
        lo + s.place[k] * (hi - lo)
    });
    let g_0i = kin.chain.link_frame(7, &q);
    let trocar = kin.shaft.constraint_pose(&g_0i, s.l_a).translation + Vector3::from(s.trocar_off);
    let g_0e = kin.chain.forward_kinematics(&q);
    let bound = |name: &str, f: f64| f * gain_bound(name) / s.dt;
    let method = match s.method {
        0 => Method::Qp(QpWeights::with_kappa(0.01)),
        1 => Method::Dls(Damping::Variable {
            alpha0: 0.05,
            w0: 1e-3,
        }),
        2 => Method::Pinv,
        _ => Method::Fi {
            gamma_r: 5.0,
            gamma_l: 5.0,
        },
    };
    let config = ControllerConfig {
        kp: bound("kp", s.gains[0]),
        ko: bound("ko", s.gains[1]),
        method,
        jb0i_damping: (s.method != 0).then_some(Damping::Variable {
            alpha0: 0.05,
            w0: 0.01,
        }),
        kr: bound("kr", s.gains[2]),
        max_joint_speed: s.max_speed,
    };
    let inf = f64::INFINITY;
    let mut limits = HardLimits::none()
        .with_joint_limits(
            SVector::from_fn(|k, _| ranges[k][0]),
            SVector::from_fn(|k, _| ranges[k][1]),
        )
        .with_speed_limits(SVector::from_fn(|k, _| speeds[k] * s.speed_scale))
        .with_acceleration_limits(SVector::from_fn(|k, _| {
            s.acceleration.map_or(inf, |f| PANDA_ACCELERATION[k] * f)
        }))
        .with_jerk_limits(SVector::from_fn(|k, _| {
            s.jerk.map_or(inf, |f| PANDA_JERK[k] * f)
        }));
    if let Some((below, above)) = s.depth {
        limits = limits.with_depth(s.l_a - below, s.l_a + above.max(-below + 1e-3));
    }
    let mut ctrl = Controller::<f64, 7, 7, 2, 4, 4, 4>::new(config).with_limits(limits);
    if moving {
        ctrl.set_previous_rates(
            SVector::from_fn(|k, _| s.previous[k] * speeds[k]),
            SVector::from_fn(|k, _| s.previous_acceleration[k] * PANDA_ACCELERATION[k]),
        );
    }
    Built {
        ctrl,
        q,
        rcm: Rcm {
            trocar,
            dv: SVector::from(s.dv),
        },
        reference: Reference {
            position: g_0e.translation + Vector3::from(s.target),
            rotation: g_0e.rotation,
            velocity: Vector3::from(s.velocity),
            angular_velocity: Vector3::new(0.0, 0.0, 0.3),
        },
        limits,
    }
}

/// The intervals (B1)–(B4) of joint `k`, from their definitions.
fn intervals(
    b: &Built,
    k: usize,
    max_speed: Option<f64>,
    dt: f64,
    previous: (f64, f64),
) -> [(f64, f64); 4] {
    let inf = f64::INFINITY;
    let l = &b.limits;
    let q = b.q[k];
    let speed = max_speed.map_or(l.speed[k], |s| s.min(l.speed[k]));
    let b1 = (
        (-speed).max(((l.lower[k] - q) / dt).min(0.0)),
        speed.min(((l.upper[k] - q) / dt).max(0.0)),
    );
    let (rate, acceleration) = previous;
    let a = l.acceleration[k];
    let (b2, b3) = if a.is_finite() {
        (
            (rate - a * dt, rate + a * dt),
            (
                -braking_speed(q - l.lower[k], a, dt),
                braking_speed(l.upper[k] - q, a, dt),
            ),
        )
    } else {
        ((-inf, inf), (-inf, inf))
    };
    let j = l.jerk[k];
    let b4 = if j.is_finite() {
        let c = rate + dt * acceleration;
        (c - j * dt * dt, c + j * dt * dt)
    } else {
        (-inf, inf)
    };
    [b1, b2, b3, b4]
}

/// The rounding a bound is checked to: that of its ends, and of the positions over `dt` it is
/// computed from (as the step reports a bound as given way only beyond it).
fn slack(x: f64, q: f64, dt: f64) -> f64 {
    1e-12 * (1.0 + x.abs()) + 64.0 * f64::EPSILON * (4.0 + q.abs()) / dt
}

/// Checks one step's rates joint by joint against (B1)–(B4) and their priority, and the report.
fn check_step(
    b: &Built,
    s: &Scene,
    previous: &[(f64, f64); 7],
    out: &StepOutput<f64, 7, 2>,
) -> Result<(), TestCaseError> {
    let mut worst = RateRelaxation::Nothing;
    // Whether some joint's rate is outside (B4) where it is not empty.
    let mut past_jerk = false;
    let levels = [
        RateRelaxation::Acceleration,
        RateRelaxation::Braking,
        RateRelaxation::Jerk,
    ];
    for k in 0..7 {
        let v = out.qd[k];
        let q = b.q[k];
        prop_assert!(v.is_finite(), "joint {} rate {v}", k + 1);
        let sets = intervals(b, k, s.max_speed, s.dt, previous[k]);
        let tol = |x: f64| slack(x, q, s.dt);
        let inside = |(lo, hi): (f64, f64)| v >= lo - tol(lo) && v <= hi + tol(hi);
        // (B1), exactly as it is integrated.
        let (lo, hi) = (b.limits.lower[k], b.limits.upper[k]);
        let speed = s
            .max_speed
            .map_or(b.limits.speed[k], |m| m.min(b.limits.speed[k]));
        prop_assert!(v.abs() <= speed, "joint {}: |{v}| past {speed}", k + 1);
        let next = q + s.dt * v;
        if q >= lo {
            prop_assert!(next >= lo, "joint {} to {next} below {lo}", k + 1);
        } else {
            prop_assert!(v >= 0.0, "joint {} beyond {lo} moved out", k + 1);
        }
        if q <= hi {
            prop_assert!(next <= hi, "joint {} to {next} above {hi}", k + 1);
        } else {
            prop_assert!(v <= 0.0, "joint {} beyond {hi} moved out", k + 1);
        }
        let jerk_set = sets[3];
        if !inside(jerk_set) {
            past_jerk = true;
        }
        // (B2)–(B4): held wherever some rate meets them with those before.
        for level in 1..4 {
            if level == 3 && out.relaxed >= RateRelaxation::Jerk {
                // The jerk bound gave way, to (B1)–(B3) or to the trocar rows.
                break;
            }
            let (mut l, mut h) = sets[0];
            for set in &sets[1..=level] {
                l = l.max(set.0);
                h = h.min(set.1);
            }
            let gap = l - h;
            if gap <= 0.0 {
                prop_assert!(
                    inside(sets[level]),
                    "joint {}: {v} outside (B{}) {:?} though it meets those before ({:?}, {:?})",
                    k + 1,
                    level + 1,
                    sets[level],
                    out.relaxed,
                    sets
                );
            } else if gap > tol(l) + tol(h) {
                worst = worst.max(levels[level - 1]);
                break;
            } else {
                break;
            }
        }
    }
    // The report names at least the most important bound that certainly gave way, and never
    // one more important than any that could have.
    prop_assert!(
        out.relaxed >= worst,
        "{:?} reported, {:?} gave way",
        out.relaxed,
        worst
    );
    // A jerk bound reported as given way where every joint could keep it gave way to the trocar
    // rows: the rates are past it, or the trocar yielded even so.
    if out.relaxed == RateRelaxation::Jerk && worst < RateRelaxation::Jerk {
        prop_assert!(
            past_jerk || out.status == StepStatus::TrocarYielded,
            "the jerk bound reported as given way, but every rate keeps it"
        );
    }
    Ok(())
}

fn previous_of(ctrl: &Controller<f64, 7, 7, 2, 4, 4, 4>) -> [(f64, f64); 7] {
    let p = ctrl.previous_command();
    std::array::from_fn(|k| (p.rates[k], p.acceleration[k]))
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: cases(4000),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn every_method_keeps_the_rate_box(s in scene()) {
        let (kin, ranges, speeds) = panda();
        let mut b = build(&kin, &ranges, &speeds, &s, true);
        let previous = previous_of(&b.ctrl);
        let (reference, rcm) = (b.reference, b.rcm);
        match b.ctrl.step(&kin, &b.q, &reference, &rcm, s.dt) {
            Ok(out) => {
                check_step(&b, &s, &previous, &out)?;
                // The controller keeps the command as the next step's previous one.
                let next = b.ctrl.previous_command();
                prop_assert_eq!(next.rates, out.qd);
                for k in 0..7 {
                    let a = (out.qd[k] - previous[k].0) / s.dt;
                    prop_assert!((next.acceleration[k] - a).abs() <= 1e-9 * (1.0 + a.abs()));
                }
            }
            Err(e) => prop_assert!(
                !matches!(e, trocar::control::ControlError::Config(_)),
                "gains below their bound refused: {e}"
            ),
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: cases(4000) / 4,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// From rest within the ranges, a run of steps never needs the acceleration or braking bound
    /// to give way: braking (B3) keeps them compatible with the ranges.
    #[test]
    fn from_rest_only_the_jerk_bound_gives_way(s in scene(), steps in 3..12usize) {
        let s = Scene {
            place: s.place.map(|p| p.clamp(0.0, 1.0)),
            acceleration: Some(s.acceleration.unwrap_or(1.0)),
            ..s
        };
        let (kin, ranges, speeds) = panda();
        let mut b = build(&kin, &ranges, &speeds, &s, false);
        for k in 0..7 {
            b.q[k] = b.q[k].clamp(ranges[k][0], ranges[k][1]);
        }
        let (reference, rcm) = (b.reference, b.rcm);
        for _ in 0..steps {
            let previous = previous_of(&b.ctrl);
            let Ok(out) = b.ctrl.step(&kin, &b.q, &reference, &rcm, s.dt) else {
                break;
            };
            check_step(&b, &s, &previous, &out)?;
            prop_assert!(out.relaxed <= RateRelaxation::Jerk, "{:?}", out.relaxed);
            b.q += out.qd * s.dt;
        }
    }
}

/// A controller reset takes the arm to be at rest; a moving arm handed over keeps its motion.
#[test]
fn reset_is_rest_and_a_known_motion_is_continued() {
    let (kin, ranges, speeds) = panda();
    let s = Scene {
        place: [0.5; 7],
        trocar_off: [0.0; 3],
        l_a: 0.25,
        max_speed: None,
        speed_scale: 1.0,
        depth: None,
        gains: [0.1; 3],
        method: 1,
        target: [0.0, 0.0, 0.05],
        velocity: [0.0; 3],
        dv: [0.0; 2],
        dt: 0.002,
        acceleration: Some(1.0),
        jerk: None,
        previous: [0.0; 7],
        previous_acceleration: [0.0; 7],
    };
    let mut b = build(&kin, &ranges, &speeds, &s, false);
    let (reference, rcm) = (b.reference, b.rcm);
    let moving = SVector::<f64, 7>::from_fn(|k, _| if k == 0 { 1.0 } else { 0.0 });
    b.ctrl.set_previous_rates(moving, SVector::zeros());
    let out = b.ctrl.step(&kin, &b.q, &reference, &rcm, s.dt).unwrap();
    // Joint 1 was moving at 1 rad/s: it may slow by at most 15 rad/s² × 2 ms.
    assert!(
        (out.qd[0] - 1.0).abs() <= 15.0 * 0.002 * (1.0 + 1e-12),
        "{}",
        out.qd[0]
    );
    assert!(out.qd[0] > 0.9);
    b.ctrl.reset();
    assert_eq!(b.ctrl.previous_command().rates, SVector::<f64, 7>::zeros());
    let out = b.ctrl.step(&kin, &b.q, &reference, &rcm, s.dt).unwrap();
    for k in 0..7 {
        assert!(
            out.qd[k].abs() <= PANDA_ACCELERATION[k] * 0.002 * (1.0 + 1e-12),
            "joint {}: {} from rest",
            k + 1,
            out.qd[k]
        );
    }
}

/// A joint moving fast toward its range, handed over: it brakes at its acceleration limit
/// (the braking bound gives way, and says so), and does not pass its range.
#[test]
fn a_joint_too_fast_for_its_range_brakes_at_the_limit() {
    let (kin, ranges, speeds) = panda();
    let [lo, hi] = ranges[6];
    let s = Scene {
        place: [0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.985],
        trocar_off: [0.0; 3],
        l_a: 0.25,
        max_speed: None,
        speed_scale: 1.0,
        depth: None,
        gains: [0.1; 3],
        method: 0,
        target: [0.0; 3],
        velocity: [0.0; 3],
        dv: [0.0; 2],
        dt: 0.002,
        acceleration: Some(1.0),
        jerk: Some(1.0),
        previous: [0.0; 7],
        previous_acceleration: [0.0; 7],
    };
    let distance = 0.015 * (hi - lo);
    // 2.6 rad/s needs 2.6²/(2 × 20) = 0.17 rad to stop: more than the distance.
    assert!(2.6 * 2.6 / 40.0 > distance);
    for method in 0..4 {
        let s = Scene {
            method,
            ..s.clone()
        };
        let mut b = build(&kin, &ranges, &speeds, &s, false);
        let moving = SVector::<f64, 7>::from_fn(|k, _| if k == 6 { 2.6 } else { 0.0 });
        b.ctrl.set_previous_rates(moving, SVector::zeros());
        let (reference, rcm) = (b.reference, b.rcm);
        let mut relaxed = Vec::new();
        for _ in 0..200 {
            let previous = previous_of(&b.ctrl);
            let out = b.ctrl.step(&kin, &b.q, &reference, &rcm, s.dt).unwrap();
            check_step(&b, &s, &previous, &out).unwrap();
            relaxed.push(out.relaxed);
            b.q += out.qd * s.dt;
            assert!(b.q[6] <= hi, "method {method}: q7 = {} past {hi}", b.q[6]);
        }
        assert_eq!(relaxed[0], RateRelaxation::Braking, "method {method}");
        // The acceleration gave way only where the range left no choice: the last step to the
        // range and the stop there.
        let forced = relaxed
            .iter()
            .filter(|r| **r == RateRelaxation::Acceleration)
            .count();
        assert!(forced <= 2, "method {method}: {relaxed:?}");
    }
}
