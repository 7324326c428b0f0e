//! The controller driven by the generated closed forms (`trocar_tests_generated::control`) agrees
//! with the numeric runtime (`ChainKinematics`): the same `ConstrainedState`, the same joint
//! trajectory over a scenario, and no allocation per step — on the reference arm and on the
//! Panda laparoscope (`panda_laparoscope::Kinematics`, `step_kinematics`; the numeric side built
//! from the same description by `NumericModel::to_kinematics`: chain, constraint, shaft, task).

use trocar::constraint::Constraint;
use trocar::control::NullSpaceObjective;
use trocar::control::{ChainKinematics, ConstrainedKinematics, ConstrainedState, Controller, Rcm};
use trocar::nalgebra::SMatrix;
use trocar::nalgebra::{SVector, Vector3};
use trocar_counting_allocator::{allocations_during, Counting};
use trocar_model::description::RobotDescription;
use trocar_model::numeric::NumericModel;
use trocar_sim::simulation::PANDA_Q0;
use trocar_sim::simulation::{Method, Scenario, ScenarioConfig, L_A0, Q0};
use trocar_tests_generated::control::{Dia10LikeZx, Dia10LikeZy, GeneratedKinematics};
use trocar_tests_generated::control::{IiwaEndoscope, PandaLaparoscope};
use trocar_tests_generated::panda_laparoscope as panda;

#[global_allocator]
static ALLOCATOR: Counting = Counting;

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
        // The forward kinematics alone (the scene's step takes it after each step).
        let e_gen = gen.g_0e(&q).unwrap();
        let e_num = ConstrainedKinematics::<f64, 8, 6, 2, 4, 6>::g_0e(&num, &q).unwrap();
        assert!((e_gen.rotation - e_num.rotation).amax() <= 1e-12);
        assert!((e_gen.translation - e_num.translation).amax() <= 1e-12);
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
    let allocations = allocations_during(|| {
        for k in 1..1000 {
            let reference = config
                .scenario
                .reference(k as f64 * dt, dt, &s.g_0e, &axis7);
            q += ctrl.step(&kin, &q, &reference, &rcm, dt).unwrap().qd * dt;
        }
    });
    assert_eq!(allocations, 0, "allocations in 999 steps");
    // The counter counts: a Vec allocates.
    assert_eq!(
        allocations_during(|| drop(std::hint::black_box(vec![1u8; 16]))),
        1
    );
    assert!(q.iter().all(|x| x.is_finite()));
}

// The Panda laparoscope: constraint on the last link, task x y z rz, joint-limit objective.

fn panda_model() -> NumericModel<f64> {
    let d = RobotDescription::preset("panda-laparoscope").unwrap();
    NumericModel::from_description(&d, &[]).unwrap()
}

fn panda_numeric() -> ChainKinematics<f64, 7, 2, 4> {
    panda_model().to_kinematics::<7, 2, 4>().unwrap()
}

fn close_panda<const R: usize, const C: usize>(
    what: &str,
    a: &SMatrix<f64, R, C>,
    b: &SMatrix<f64, R, C>,
    tol: f64,
) {
    let d = (a - b).amax();
    assert!(
        d <= tol,
        "{what}: generated and numeric differ by {d:e}\n{a}{b}"
    );
}

#[test]
fn shaft_and_task_match_the_description() {
    let gen = PandaLaparoscope::<f64>::nominal();
    let num = panda_numeric();
    type Kin = dyn ConstrainedKinematics<f64, 7, 7, 2, 4, 4, 4>;
    let (gs, ns) = ((&gen as &Kin).shaft(), (&num as &Kin).shaft());
    // g_ir = (I, (0, 0, 0.107 + l_a)): the flange offset of panda_link8, the shaft along z.
    close_panda("R_ir", &gs.rotation, &ns.rotation, 1e-15);
    close_panda("o", &gs.origin, &ns.origin, 1e-12);
    close_panda("d", &gs.direction, &ns.direction, 1e-12);
    assert!((gs.origin.z - 0.107).abs() < 1e-15 && (gs.direction.z - 1.0).abs() < 1e-15);
    close_panda(
        "S",
        &(&gen as &Kin).task_selection(),
        &(&num as &Kin).task_selection(),
        0.0,
    );
}

#[test]
fn generated_step_kinematics_match_numeric_at_random_configurations() {
    let gen = PandaLaparoscope::<f64>::nominal();
    let num = panda_numeric();
    let mut rng = Rng(0x05ee_d0f7_a0da);
    for _ in 0..200 {
        let q = SVector::<f64, 7>::from_fn(|_, _| rng.uniform(-2.5, 2.5));
        // A trocar somewhere off the shaft: l_a is the nearest point, not a given value.
        let trocar = trocar::nalgebra::Vector3::new(
            rng.uniform(-0.6, 0.6),
            rng.uniform(-0.6, 0.6),
            rng.uniform(0.0, 1.0),
        );
        let la_g = states_agree(&gen, &num, &q, &trocar);

        // The plain step function fills the same, and S J^r.
        let (_, n) =
            ConstrainedKinematics::<f64, 7, 7, 2, 4, 4, 4>::evaluate_at_trocar(&num, &q, &trocar)
                .unwrap();
        let t = panda::JointTrig::new(&q.data.0[0]);
        let mut s = panda::StepKinematics::zeroed();
        assert!(panda::step_kinematics(
            &t,
            &trocar.data.0[0],
            &panda::Params::nominal(),
            &mut s
        ));
        assert_eq!(s.offset, la_g);
        let task = SMatrix::<f64, 4, 4>::from_data(trocar::nalgebra::ArrayStorage(s.task_jacobian));
        close_panda("S J^r", &task, &(num.task * n.jr), 1e-12);
    }
}

/// Generated and numeric kinematics agree at `q` with the trocar at `trocar`; returns `l_a`.
fn states_agree<G, Num>(
    gen: &G,
    num: &Num,
    q: &SVector<f64, 7>,
    trocar: &trocar::nalgebra::Vector3<f64>,
) -> f64
where
    G: ConstrainedKinematics<f64, 7, 7, 2, 4, 4, 4>,
    Num: ConstrainedKinematics<f64, 7, 7, 2, 4, 4, 4>,
{
    let (la_g, g) = gen.evaluate_at_trocar(q, trocar).unwrap();
    let (la_n, n) = num.evaluate_at_trocar(q, trocar).unwrap();
    assert!((la_g - la_n).abs() <= 1e-13, "l_a {la_g} vs {la_n}");
    close_panda("R_0e", &g.g_0e.rotation, &n.g_0e.rotation, 1e-13);
    close_panda("p_0e", &g.g_0e.translation, &n.g_0e.translation, 1e-13);
    close_panda("R_0i", &g.g_0i.rotation, &n.g_0i.rotation, 1e-13);
    close_panda("J^r", &g.jr, &n.jr, 1e-12);
    close_panda("J^B_0i", &g.jb0i, &n.jb0i, 1e-12);
    close_panda("J_c", &g.jc, &n.jc, 1e-12);
    close_panda("Λ#", &g.lambda_sharp, &n.lambda_sharp, 1e-12);
    close_panda("Λ†", &g.lambda_pinv, &n.lambda_pinv, 1e-12);
    close_panda("S", &gen.task_selection(), &num.task_selection(), 0.0);
    let (gs, ns) = (gen.shaft(), num.shaft());
    close_panda("R_ir", &gs.rotation, &ns.rotation, 1e-13);
    close_panda("o", &gs.origin, &ns.origin, 1e-12);
    close_panda("d", &gs.direction, &ns.direction, 1e-12);
    la_g
}

/// A second URDF robot with the constraint on its last link (the KUKA iiwa with an endoscope,
/// the flange frame folded from `iiwa_joint_ee`'s origin): the generated controller kinematics
/// equal the numeric ones built from its description too.
#[test]
fn iiwa_endoscope_controller_kinematics_match_numeric() {
    let d = RobotDescription::from_toml_file(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../runtime/model/robots/iiwa-endoscope.toml"),
    )
    .unwrap();
    let num = NumericModel::<f64>::from_description(&d, &[])
        .unwrap()
        .to_kinematics::<7, 2, 4>()
        .unwrap();
    let gen = IiwaEndoscope::<f64>::nominal();
    let mut rng = Rng(0x1ead_beef_cafe);
    for _ in 0..100 {
        let q = SVector::<f64, 7>::from_fn(|_, _| rng.uniform(-2.0, 2.0));
        let trocar = trocar::nalgebra::Vector3::new(
            rng.uniform(-0.6, 0.6),
            rng.uniform(-0.6, 0.6),
            rng.uniform(0.2, 1.2),
        );
        states_agree(&gen, &num, &q, &trocar);
    }
}

/// `steps` steps of the Panda scenario (explicit Euler, fixed trocar, joint-limit objective) with
/// kinematics `kin`; the joints after every step.
fn panda_run<Kin: ConstrainedKinematics<f64, 7, 7, 2, 4, 4, 4>>(
    kin: &Kin,
    steps: usize,
) -> Vec<SVector<f64, 7>> {
    let num = panda_numeric();
    let limits: Vec<[f64; 2]> = panda_model()
        .description()
        .joints
        .iter()
        .map(|j| j.limits.unwrap())
        .collect();
    let config = ScenarioConfig::new(Scenario::Panda).with_drift_correction(true);
    let mut ctrl = Controller::<f64, 7, 7, 2, 4, 4, 4>::new(config.controller_config())
        .with_objective(NullSpaceObjective::JointLimits {
            gain: config.null_space_gain,
            lower: SVector::from_fn(|k, _| limits[k][0]),
            upper: SVector::from_fn(|k, _| limits[k][1]),
        });
    let mut q = SVector::<f64, 7>::from(PANDA_Q0);
    let g0 = num.chain.forward_kinematics(&q);
    let trocar = num
        .shaft
        .constraint_pose(&num.chain.link_frame(7, &q), 0.25)
        .translation;
    let dt = config.dt;
    let mut out = Vec::with_capacity(steps);
    for k in 0..steps {
        let t = k as f64 * dt;
        let reference = config
            .scenario
            .reference(t, dt, &g0, &trocar::nalgebra::Vector3::zeros());
        let rcm = Rcm {
            trocar,
            dv: SVector::<f64, 2>::zeros(),
        };
        q += ctrl.step(kin, &q, &reference, &rcm, dt).unwrap().qd * dt;
        out.push(q);
    }
    out
}

#[test]
fn panda_trajectory_generated_equals_numeric() {
    let steps = 1500;
    let a = panda_run(&PandaLaparoscope::<f64>::nominal(), steps);
    let b = panda_run(&panda_numeric(), steps);
    let worst = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (x - y).amax())
        .fold(0.0, f64::max);
    let moved = (a[steps - 1] - SVector::<f64, 7>::from(PANDA_Q0)).amax();
    println!("{steps} steps: joints moved {moved:.3} rad, worst |q_gen − q_num| = {worst:.2e}");
    assert!(moved > 1e-2, "the trajectory goes somewhere");
    assert!(worst <= 1e-9, "trajectories differ by {worst:e}");
}

#[test]
fn generated_panda_step_allocates_nothing() {
    let kin = PandaLaparoscope::<f64>::nominal();
    let config = ScenarioConfig::new(Scenario::Panda).with_drift_correction(true);
    let mut ctrl = Controller::<f64, 7, 7, 2, 4, 4, 4>::new(config.controller_config())
        .with_objective(NullSpaceObjective::Manipulability { gain: 1.0 });
    let q0 = SVector::<f64, 7>::from(PANDA_Q0);
    let s = ConstrainedKinematics::<f64, 7, 7, 2, 4, 4, 4>::evaluate(&kin, &q0, 0.25).unwrap();
    let trocar = s
        .g_0i
        .transform_point(&trocar::nalgebra::Vector3::new(0.0, 0.0, 0.357));
    let g0 = s.g_0e;
    let dt = config.dt;
    let mut q = q0;
    let reference = config
        .scenario
        .reference(0.0, dt, &g0, &trocar::nalgebra::Vector3::zeros());
    let rcm = Rcm {
        trocar,
        dv: SVector::<f64, 2>::zeros(),
    };
    q += ctrl.step(&kin, &q, &reference, &rcm, dt).unwrap().qd * dt;
    let allocations = allocations_during(|| {
        for _ in 0..100 {
            q += ctrl.step(&kin, &q, &reference, &rcm, dt).unwrap().qd * dt;
        }
    });
    assert_eq!(allocations, 0, "a step allocated");
}
