//! The Panda laparoscope's generated controller kinematics (`panda_laparoscope::Kinematics`,
//! `step_kinematics`) agree with the numeric runtime built from the same description
//! (`NumericModel::to_kinematics`: chain, constraint, shaft, task), the controller follows the
//! same trajectory on both over the first seconds of the Panda scenario, and a generated step
//! allocates nothing.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use trocar::control::{
    ChainKinematics, ConstrainedKinematics, Controller, NullSpaceObjective, Rcm,
};
use trocar::nalgebra::{SMatrix, SVector};
use trocar_model::description::RobotDescription;
use trocar_model::numeric::NumericModel;
use trocar_sim::simulation::{Scenario, ScenarioConfig, PANDA_Q0};
use trocar_tests_generated::control::PandaLaparoscope;
use trocar_tests_generated::panda_laparoscope as panda;

struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

// SAFETY: every call forwards to `System` with the caller's arguments unchanged; the counter is a
// thread-local `Cell` touched through `try_with`, which neither allocates nor panics.
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

fn model() -> NumericModel<f64> {
    let d = RobotDescription::preset("panda-laparoscope").unwrap();
    NumericModel::from_description(&d, &[]).unwrap()
}

fn numeric() -> ChainKinematics<f64, 7, 2, 4> {
    model().to_kinematics::<7, 2, 4>().unwrap()
}

fn close<const R: usize, const C: usize>(
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
    let num = numeric();
    type Kin = dyn ConstrainedKinematics<f64, 7, 7, 2, 4, 4, 4>;
    let (gs, ns) = ((&gen as &Kin).shaft(), (&num as &Kin).shaft());
    // g_ir = (I, (0, 0, 0.107 + l_a)): the flange offset of panda_link8, the shaft along z.
    close("R_ir", &gs.rotation, &ns.rotation, 1e-15);
    close("o", &gs.origin, &ns.origin, 1e-12);
    close("d", &gs.direction, &ns.direction, 1e-12);
    assert!((gs.origin.z - 0.107).abs() < 1e-15 && (gs.direction.z - 1.0).abs() < 1e-15);
    close(
        "S",
        &(&gen as &Kin).task_selection(),
        &(&num as &Kin).task_selection(),
        0.0,
    );
}

#[test]
fn generated_step_kinematics_match_numeric_at_random_configurations() {
    let gen = PandaLaparoscope::<f64>::nominal();
    let num = numeric();
    let mut rng = Rng(0x05ee_d0f7_a0da);
    for _ in 0..200 {
        let q = SVector::<f64, 7>::from_fn(|_, _| rng.uniform(-2.5, 2.5));
        // A trocar somewhere off the shaft: l_a is the nearest point, not a given value.
        let trocar = trocar::nalgebra::Vector3::new(
            rng.uniform(-0.6, 0.6),
            rng.uniform(-0.6, 0.6),
            rng.uniform(0.0, 1.0),
        );
        let (la_g, g) =
            ConstrainedKinematics::<f64, 7, 7, 2, 4, 4, 4>::evaluate_at_trocar(&gen, &q, &trocar)
                .unwrap();
        let (la_n, n) =
            ConstrainedKinematics::<f64, 7, 7, 2, 4, 4, 4>::evaluate_at_trocar(&num, &q, &trocar)
                .unwrap();
        assert!((la_g - la_n).abs() <= 1e-13, "l_a {la_g} vs {la_n}");
        close("R_0e", &g.g_0e.rotation, &n.g_0e.rotation, 1e-13);
        close("p_0e", &g.g_0e.translation, &n.g_0e.translation, 1e-13);
        close("R_0i", &g.g_0i.rotation, &n.g_0i.rotation, 1e-13);
        close("J^r", &g.jr, &n.jr, 1e-12);
        close("J^B_0i", &g.jb0i, &n.jb0i, 1e-12);
        close("J_c", &g.jc, &n.jc, 1e-12);
        close("Λ#", &g.lambda_sharp, &n.lambda_sharp, 1e-12);
        close("Λ†", &g.lambda_pinv, &n.lambda_pinv, 1e-12);

        // The plain step function fills the same, and S J^r.
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
        close("S J^r", &task, &(num.task * n.jr), 1e-12);
    }
}

/// `steps` steps of the Panda scenario (explicit Euler, fixed trocar, joint-limit objective) with
/// kinematics `kin`; the joints after every step.
fn run<Kin: ConstrainedKinematics<f64, 7, 7, 2, 4, 4, 4>>(
    kin: &Kin,
    steps: usize,
) -> Vec<SVector<f64, 7>> {
    let num = numeric();
    let limits: Vec<[f64; 2]> = model()
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
    let a = run(&PandaLaparoscope::<f64>::nominal(), steps);
    let b = run(&numeric(), steps);
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
    let before = allocations();
    for _ in 0..100 {
        q += ctrl.step(&kin, &q, &reference, &rcm, dt).unwrap().qd * dt;
    }
    assert_eq!(allocations() - before, 0, "a step allocated");
}
