//! The rate box of every control step (`trocar::control::rate_box`, (B1)–(B5)), checked from its
//! definition on random joints, limits and previous commands:
//!
//! - every rate of the box keeps the speed limit and the range over the sample time (B1), always;
//! - it keeps the acceleration (B2), braking (B3) and jerk (B4) bounds unless the box says that
//!   bound gave way, and a bound gives way only where it has no rate in common with those
//!   before it (checked from the bounds themselves, joint by joint);
//! - the braking speed (B5) is exact: braking at the acceleration limit from it stops within the
//!   distance, and from a little more does not;
//! - a joint driven as hard as the box allows toward its range, from rest, never passes it and
//!   never exceeds its acceleration, and only the jerk bound gives way.

use nalgebra::SVector;
use proptest::prelude::*;
use trocar::control::{braking_speed, rate_box, HardLimits, PreviousCommand, RateRelaxation};

/// The distance travelled braking at `u = a dt` a step from `v`: `dt Σ max(0, v − k u)`.
fn braking_distance(v: f64, a: f64, dt: f64) -> f64 {
    let u = a * dt;
    let mut s = 0.0;
    let mut w = v;
    while w > 0.0 {
        s += w * dt;
        w -= u;
    }
    s
}

#[test]
fn the_braking_speed_is_the_discrete_one() {
    let (a, dt) = (15.0, 0.002);
    let u = a * dt;
    // At a whole number of decelerations the continuous bound is exact; between them it is
    // larger than the discrete one and overruns.
    for d in [0.0, 1e-6, 1e-4, 0.01, 0.0123, 0.1, 0.5, 3.0] {
        let b = braking_speed(d, a, dt);
        assert!(
            braking_distance(b, a, dt) <= d * (1.0 + 1e-12) + 1e-15,
            "d = {d}"
        );
        if d > 0.0 {
            assert!(
                braking_distance(b * (1.0 + 1e-9) + 1e-15, a, dt) > d,
                "d = {d}"
            );
        }
        let continuous = -u / 2.0 + ((u / 2.0) * (u / 2.0) + 2.0 * a * d).sqrt();
        assert!(b <= continuous + 1e-12, "d = {d}: {b} > {continuous}");
    }
    assert_eq!(braking_speed(0.0, a, dt), 0.0);
    assert_eq!(braking_speed(-1.0, a, dt), 0.0);
    assert_eq!(braking_speed(0.1, f64::INFINITY, dt), f64::INFINITY);
    // A distance for 2.5 decelerations: the continuous bound would overrun it.
    let d = dt * u * 2.5 * 3.5 / 2.0;
    let continuous = -u / 2.0 + ((u / 2.0) * (u / 2.0) + 2.0 * a * d).sqrt();
    assert!(braking_distance(continuous, a, dt) > d);
    assert!(braking_distance(braking_speed(d, a, dt), a, dt) <= d * (1.0 + 1e-12));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 4000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn braking_from_the_braking_speed_stops_in_time(
        d in prop_oneof![0.0..1e-3f64, 0.0..0.5f64, 0.0..50.0f64],
        a in prop_oneof![0.1..30.0f64, 1e3..1e5f64],
        dt in prop_oneof![Just(0.001), Just(0.002), 1e-4..0.05f64],
        fraction in 0.0..1.0f64,
    ) {
        let b = braking_speed(d, a, dt);
        prop_assert!(b.is_finite() && b >= 0.0);
        prop_assert!(braking_distance(b, a, dt) <= d * (1.0 + 1e-10) + 1e-14);
        // Invariance: a rate within the bound leaves the next step's bound room to brake.
        let v = fraction * b;
        let u = a * dt;
        if v > u {
            let next = braking_speed(d - v * dt, a, dt);
            prop_assert!(v - u <= next * (1.0 + 1e-10) + 1e-12, "{} > {}", v - u, next);
        }
    }
}

/// One joint's limits and state.
#[derive(Clone, Debug)]
struct Joint {
    range: [f64; 2],
    /// Where in its range (outside 0..1 beyond it).
    place: f64,
    speed: f64,
    max_speed: Option<f64>,
    acceleration: Option<f64>,
    jerk: Option<f64>,
    rate: f64,
    previous_acceleration: f64,
    dt: f64,
}

fn joint() -> impl Strategy<Value = Joint> {
    (
        (
            -3.0..-0.1f64,
            0.1..3.0f64,
            prop_oneof![4 => 0.0..1.0f64, 1 => Just(0.0), 1 => Just(1.0), 1 => -0.1..1.1f64, 1 => prop_oneof![Just(1e-6), Just(1.0 - 1e-6)]],
        ),
        (
            0.1..3.0f64,
            prop::option::of(0.05..3.0f64),
            prop::option::of(prop_oneof![0.5..30.0f64, 100.0..1e4f64]),
            prop::option::of(prop_oneof![10.0..1e4f64, 1e4..1e6f64]),
        ),
        (
            prop_oneof![2 => -3.0..3.0f64, 1 => Just(0.0), 1 => -0.05..0.05f64],
            prop_oneof![2 => -30.0..30.0f64, 1 => Just(0.0)],
            prop_oneof![Just(0.001), Just(0.002), 1e-4..0.02f64],
        ),
    )
        .prop_map(
            |((lo, hi, place), (speed, max_speed, acceleration, jerk), (rate, pa, dt))| Joint {
                range: [lo, hi],
                place,
                speed,
                max_speed,
                acceleration,
                jerk,
                rate,
                previous_acceleration: pa,
                dt,
            },
        )
}

fn limits_of(j: &Joint) -> HardLimits<f64, 1> {
    let inf = f64::INFINITY;
    HardLimits::none()
        .with_joint_limits(SVector::from([j.range[0]]), SVector::from([j.range[1]]))
        .with_speed_limits(SVector::from([j.speed]))
        .with_acceleration_limits(SVector::from([j.acceleration.unwrap_or(inf)]))
        .with_jerk_limits(SVector::from([j.jerk.unwrap_or(inf)]))
}

/// The bounds (B1)–(B4) of one joint as intervals, from their definitions.
fn intervals(j: &Joint, q: f64) -> [(f64, f64); 4] {
    let inf = f64::INFINITY;
    let speed = j.max_speed.map_or(j.speed, |s| s.min(j.speed));
    let [lo, hi] = j.range;
    let b1 = (
        (-speed).max(((lo - q) / j.dt).min(0.0)),
        speed.min(((hi - q) / j.dt).max(0.0)),
    );
    let (b2, b3) = match j.acceleration {
        Some(a) => (
            (j.rate - a * j.dt, j.rate + a * j.dt),
            (
                -braking_speed(q - lo, a, j.dt),
                braking_speed(hi - q, a, j.dt),
            ),
        ),
        None => ((-inf, inf), (-inf, inf)),
    };
    let b4 = match j.jerk {
        Some(jerk) => {
            let c = j.rate + j.dt * j.previous_acceleration;
            let w = jerk * j.dt * j.dt;
            (c - w, c + w)
        }
        None => (-inf, inf),
    };
    [b1, b2, b3, b4]
}

fn slack(x: f64) -> f64 {
    1e-12 * (1.0 + x.abs())
}

fn within(x: f64, (lo, hi): (f64, f64)) -> bool {
    x >= lo - slack(lo) && x <= hi + slack(hi)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 20_000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn the_box_keeps_each_bound_unless_it_says_it_gave_way(j in joint()) {
        let q = j.range[0] + j.place * (j.range[1] - j.range[0]);
        let limits = limits_of(&j);
        let previous = PreviousCommand {
            rates: SVector::from([j.rate]),
            acceleration: SVector::from([j.previous_acceleration]),
        };
        let b = rate_box(&SVector::from([q]), j.dt, &limits, j.max_speed, &previous);
        let (lb, ub) = (b.lower[0], b.upper[0]);
        prop_assert!(lb <= ub && lb.is_finite() && ub.is_finite(), "[{lb}, {ub}]");
        let bounds = intervals(&j, q);
        for x in [lb, ub, 0.5 * (lb + ub)] {
            // (B1), exactly as the caller integrates: speed, and the range over dt (a joint
            // beyond its range does not move further out).
            let speed = j.max_speed.map_or(j.speed, |s| s.min(j.speed));
            prop_assert!(x.abs() <= speed, "{x} past the speed {speed}");
            let next = q + j.dt * x;
            if q >= j.range[0] {
                prop_assert!(next >= j.range[0], "{q} + dt {x} below {}", j.range[0]);
            } else {
                prop_assert!(x >= 0.0);
            }
            if q <= j.range[1] {
                prop_assert!(next <= j.range[1], "{q} + dt {x} above {}", j.range[1]);
            } else {
                prop_assert!(x <= 0.0);
            }
            if b.relaxed < RateRelaxation::Acceleration {
                prop_assert!(within(x, bounds[1]), "{x} outside (B2) {:?}", bounds[1]);
            }
            if b.relaxed < RateRelaxation::Braking {
                prop_assert!(within(x, bounds[2]), "{x} outside (B3) {:?}", bounds[2]);
            }
            if b.relaxed < RateRelaxation::Jerk {
                prop_assert!(within(x, bounds[3]), "{x} outside (B4) {:?}", bounds[3]);
            }
        }
        // A bound gives way only where it has no rate in common with those before it.
        let meet = |sets: &[(f64, f64)]| {
            let lo = sets.iter().map(|s| s.0).fold(f64::NEG_INFINITY, f64::max);
            let hi = sets.iter().map(|s| s.1).fold(f64::INFINITY, f64::min);
            (lo, hi)
        };
        let empty = |(lo, hi): (f64, f64)| lo > hi + slack(lo) + slack(hi);
        match b.relaxed {
            RateRelaxation::Nothing => {}
            RateRelaxation::Acceleration => {
                prop_assert!(empty(meet(&bounds[..2])), "(B2) gave way but meets (B1)");
            }
            RateRelaxation::Braking => {
                prop_assert!(!empty(meet(&bounds[..2])));
                prop_assert!(empty(meet(&bounds[..3])), "(B3) gave way but meets (B1)-(B2)");
            }
            RateRelaxation::Jerk => {
                prop_assert!(!empty(meet(&bounds[..3])));
                prop_assert!(empty(meet(&bounds)), "(B4) gave way but meets (B1)-(B3)");
            }
        }
    }

    /// A joint driven toward its bound as hard as the box allows, from rest at a random place,
    /// then reversed: it stops within its range, its rate changes by at most `a_max dt` a step,
    /// and only the jerk bound gives way.
    #[test]
    fn a_joint_driven_into_its_range_brakes_in_time(
        j in joint(),
        toward_upper in any::<bool>(),
        steps in 50..400usize,
    ) {
        let Some(a) = j.acceleration else { return Ok(()); };
        let place = j.place.clamp(0.0, 1.0);
        let mut q = (j.range[0] + place * (j.range[1] - j.range[0])).clamp(j.range[0], j.range[1]);
        let limits = limits_of(&j);
        let mut previous = PreviousCommand::<f64, 1>::rest();
        for k in 0..steps {
            let b = rate_box(&SVector::from([q]), j.dt, &limits, j.max_speed, &previous);
            prop_assert!(
                b.relaxed <= RateRelaxation::Jerk,
                "step {k}: {:?} at q = {q}, rate {}",
                b.relaxed,
                previous.rates[0]
            );
            // Push against the bound for three quarters of the run, then back.
            let up = toward_upper == (k < 3 * steps / 4);
            let v = if up { b.upper[0] } else { b.lower[0] };
            let change = (v - previous.rates[0]).abs();
            // To the rounding of `θ̇⁻ ± a dt` and of the positions over `dt` (a joint riding its
            // braking curve to its range meets (B1) there to that rounding).
            let position = 1.0 + j.range[0].abs().max(j.range[1].abs());
            let rounding = 4.0 * f64::EPSILON * (1.0 + previous.rates[0].abs())
                + 32.0 * f64::EPSILON * position / j.dt;
            prop_assert!(change <= a * j.dt + rounding, "step {k}: Δθ̇ = {change}");
            q += j.dt * v;
            prop_assert!(q >= j.range[0] && q <= j.range[1], "step {k}: q = {q}");
            previous = previous.then(&SVector::from([v]), j.dt);
        }
    }
}
