//! The controller driven by the generated closed forms (`trocar_tests_generated::control`) agrees
//! with the numeric runtime (`ChainKinematics`): the same `ConstrainedState`, the same joint
//! trajectory over a scenario, and no allocation per step.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use trocar::constraint::Constraint;
use trocar::control::{ChainKinematics, ConstrainedKinematics, ConstrainedState, Controller, Rcm};
use trocar::nalgebra::{SVector, Vector3};
use trocar_model::description::RobotDescription;
use trocar_model::numeric::NumericModel;
use trocar_sim::simulation::{Method, Scenario, ScenarioConfig, L_A0, Q0};
use trocar_tests_generated::control::{Dia10LikeZx, Dia10LikeZy, GeneratedKinematics};

/// Counts the allocations of the current thread (tests run in parallel threads).
struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        System.alloc(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        System.realloc(ptr, layout, new_size)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations() -> usize {
    ALLOCATIONS.with(|c| c.get())
}

/// xorshift64*, uniform in `[lo, hi)`.
struct Rng(u64);

impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let u = (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * u
    }
}

/// The numeric runtime for a shipped robot, with the thesis's bidirectional constraint on link 6.
fn numeric(name: &str) -> ChainKinematics<f64, 8, 2> {
    let d = RobotDescription::preset(name).unwrap();
    ChainKinematics::thesis(
        NumericModel::<f64>::from_description(&d, &[])
            .unwrap()
            .to_chain::<8>()
            .unwrap(),
        Constraint::<f64, 2>::thesis(6, L_A0).unwrap(),
    )
}

fn assert_states_agree(
    a: &ConstrainedState<f64, 6, 2, 4, 6>,
    b: &ConstrainedState<f64, 6, 2, 4, 6>,
    tol: f64,
) {
    let pairs = [
        ("R_0e", (a.g_0e.rotation - b.g_0e.rotation).amax()),
        ("p_0e", (a.g_0e.translation - b.g_0e.translation).amax()),
        ("R_0i", (a.g_0i.rotation - b.g_0i.rotation).amax()),
        ("p_0i", (a.g_0i.translation - b.g_0i.translation).amax()),
        ("J^r", (a.jr - b.jr).amax()),
        ("J^B_0i", (a.jb0i - b.jb0i).amax()),
        ("J_c", (a.jc - b.jc).amax()),
        ("Λ#", (a.lambda_sharp - b.lambda_sharp).amax()),
        ("Λ†", (a.lambda_pinv - b.lambda_pinv).amax()),
    ];
    for (what, e) in pairs {
        assert!(e <= tol, "{what}: generated and numeric differ by {e:e}");
    }
}

fn check_states<G: ConstrainedKinematics<f64, 8, 6, 2, 4, 6>>(gen: &G, name: &str, seed: u64) {
    let num = numeric(name);
    assert_eq!(
        ConstrainedKinematics::<f64, 8, 6, 2, 4, 6>::h(&num),
        gen.h()
    );
    let mut rng = Rng(seed);
    let mut worst = 0.0f64;
    for _ in 0..500 {
        let q = SVector::<f64, 8>::from_fn(|_, _| rng.uniform(-3.1, 3.1));
        let l_a = if rng.uniform(0.0, 1.0) < 0.5 {
            rng.uniform(0.02, 0.4)
        } else {
            -rng.uniform(0.02, 0.4)
        };
        let a = gen.evaluate(&q, l_a).unwrap();
        let b: ConstrainedState<f64, 6, 2, 4, 6> = num.evaluate(&q, l_a).unwrap();
        assert_states_agree(&a, &b, 1e-12);
        let g_gen = gen.g_0i(&q);
        let g_num = ConstrainedKinematics::<f64, 8, 6, 2, 4, 6>::g_0i(&num, &q);
        assert!((g_gen.rotation - g_num.rotation).amax() <= 1e-12);
        assert!((g_gen.translation - g_num.translation).amax() <= 1e-12);
        worst = worst.max((a.jr - b.jr).amax());
    }
    println!("{name}: worst |J^r generated − numeric| = {worst:.2e}");
    // l_a = 0 (trocar at F_i) is refused by both.
    let q = SVector::<f64, 8>::from(Q0);
    assert!(gen.evaluate(&q, 0.0).is_err());
    assert!(ConstrainedKinematics::<f64, 8, 6, 2, 4, 6>::evaluate(&num, &q, 0.0).is_err());
}

#[test]
fn generated_state_matches_numeric_zy() {
    check_states(
        &Dia10LikeZy::<f64>::nominal(),
        "dia10_like_zy",
        0x1234_5678_9abc_def1,
    );
}

#[test]
fn generated_state_matches_numeric_zx() {
    check_states(
        &Dia10LikeZx::<f64>::nominal(),
        "dia10_like_zx",
        0x0fed_cba9_8765_4321,
    );
}

/// Runs `steps` steps of a scenario (explicit Euler as `trocar_sim::simulation`, trocar moved by the
/// commanded RCM velocity) with kinematics `kin`; returns the joints after every step.
fn run<Kin: ConstrainedKinematics<f64, 8, 6, 2, 4, 6>>(
    kin: &Kin,
    config: &ScenarioConfig,
    steps: usize,
) -> Vec<SVector<f64, 8>> {
    // Initial pose and axis of joint 7 from the numeric runtime (the same for both paths).
    let num = numeric(config.scenario.robot());
    let q0 = SVector::<f64, 8>::from(Q0);
    let g_0e0 = num.chain.forward_kinematics(&q0);
    let axis7 = num.chain.link_frame(7, &q0).rotation.column(2).into_owned();
    let g_0i0 = num.chain.link_frame(6, &q0);
    let mut trocar = g_0i0.translation + g_0i0.rotation.column(1) * L_A0;
    let dt = config.dt;
    let mut ctrl = Controller::<f64, 8, 6, 2, 4, 6>::new(config.controller_config());
    let mut q = q0;
    let mut out = Vec::with_capacity(steps);
    for k in 0..steps {
        let t = k as f64 * dt;
        let reference = config.scenario.reference(t, dt, &g_0e0, &axis7);
        let dv_all = config.rcm_velocity(t);
        let dv = SVector::<f64, 2>::new(dv_all[0], dv_all[1]);
        let step = ctrl
            .step(kin, &q, &reference, &Rcm { trocar, dv }, dt)
            .unwrap();
        let r_0i = num.chain.link_frame(6, &q).rotation;
        trocar += r_0i * Vector3::new(dv_all[0], 0.0, dv_all[1]) * dt;
        q += step.qd * dt;
        out.push(q);
    }
    out
}

fn check_trajectory(config: ScenarioConfig, steps: usize) {
    let a = run(&GeneratedKinematics::<f64>::nominal(), &config, steps);
    let b = run(&numeric("dia10_like_zy"), &config, steps);
    let worst = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (x - y).amax())
        .fold(0.0, f64::max);
    let moved = (a[steps - 1] - SVector::<f64, 8>::from(Q0)).amax();
    println!(
        "scenario {} {:?} (K_r {}): {steps} steps, joints moved {moved:.3} rad, worst |q_gen − q_num| = {worst:.2e}",
        config.scenario.name(),
        config.method,
        config.controller_config().kr
    );
    assert!(moved > 1e-3, "the trajectory goes somewhere");
    assert!(worst <= 1e-9, "trajectories differ by {worst:e}");
}

#[test]
fn scenario2_trajectory_generated_equals_numeric() {
    // 10 s of the 200 s scenario at 2 ms, with each inverse.
    for method in [Method::Pinv, Method::Dls, Method::Fi] {
        check_trajectory(ScenarioConfig::new(Scenario::S2).with_method(method), 5000);
    }
    check_trajectory(
        ScenarioConfig::new(Scenario::S2)
            .with_method(Method::Dls)
            .with_drift_correction(true),
        5000,
    );
}

#[test]
fn scenario4_moving_rcm_generated_equals_numeric() {
    check_trajectory(
        ScenarioConfig::new(Scenario::S4).with_drift_correction(true),
        5000,
    );
}

#[test]
fn generated_step_allocates_nothing() {
    let kin = GeneratedKinematics::<f64>::nominal();
    let config = ScenarioConfig::new(Scenario::S2).with_method(Method::Dls);
    let mut ctrl = Controller::<f64, 8, 6, 2, 4, 6>::new(config.controller_config());
    let q0 = SVector::<f64, 8>::from(Q0);
    let s = kin.evaluate(&q0, L_A0).unwrap();
    let axis7 = numeric("dia10_like_zy")
        .chain
        .link_frame(7, &q0)
        .rotation
        .column(2)
        .into_owned();
    let trocar = s.g_0i.translation + s.g_0i.rotation.column(1) * L_A0;
    let dt = config.dt;
    // Warm up (lazy initialisation anywhere in the process is not the step's).
    let mut q = q0;
    let reference = config.scenario.reference(0.0, dt, &s.g_0e, &axis7);
    let rcm = Rcm {
        trocar,
        dv: SVector::zeros(),
    };
    q += ctrl.step(&kin, &q, &reference, &rcm, dt).unwrap().qd * dt;
    let before = allocations();
    for k in 1..1000 {
        let reference = config
            .scenario
            .reference(k as f64 * dt, dt, &s.g_0e, &axis7);
        q += ctrl.step(&kin, &q, &reference, &rcm, dt).unwrap().qd * dt;
    }
    let after = allocations();
    assert_eq!(after - before, 0, "allocations in 999 steps");
    // The counter counts: a Vec allocates.
    let v = std::hint::black_box(vec![1u8; 16]);
    assert_eq!(allocations() - after, 1);
    drop(v);
    assert!(q.iter().all(|x| x.is_finite()));
}
