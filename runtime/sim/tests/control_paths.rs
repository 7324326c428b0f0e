//! Both kinematics paths behind `ConstrainedKinematics` agree: the typed runtime
//! (`ChainKinematics`: kinematics + `Constraint::thesis`) and the dynamic-size numeric robot built
//! from the description (`trocar_sim::robot::NumericRobot`, on faer, its `l_a` parameter moved to
//! each `l_a`), and what the simulations measure with the typed chain.

use faer::Mat;
use rand::{rngs::StdRng, Rng, SeedableRng};
use trocar::constraint::Constraint;
use trocar::control::{
    ChainKinematics, ConstrainedKinematics, ConstrainedState, ControlError, Controller,
    ControllerConfig, Damping, Method, Rcm, Reference, Shaft,
};
use trocar::kinematics::Chain;
use trocar::linalg::SquareDim;
use trocar::nalgebra::{Const, SMatrix, SVector, Vector3};
use trocar::se3::Se3;
use trocar_model::description::RobotDescription;
use trocar_model::numeric::NumericModel;
use trocar_sim::robot::NumericRobot;

/// The description-built dynamic robot behind `ConstrainedKinematics`: every quantity from the
/// faer [`NumericRobot`] with `l_a` set, copied into the fixed sizes.
struct Described<const R: usize> {
    robot: NumericRobot<f64>,
}

impl<const R: usize> Described<R> {
    /// The robot of `name` with its constraint cut to the first `R` rows of `H` (one row, `x_r`,
    /// is the unidirectional wrist).
    fn new(name: &str) -> Self {
        let mut d = RobotDescription::preset(name).unwrap();
        let c = d.constraint.as_mut().unwrap();
        c.h.truncate(R);
        if R == 1 {
            c.wrist = Some(trocar_model::description::Wrist::Unidirectional);
        }
        Described {
            robot: NumericRobot::from_description(&d, &[]).unwrap(),
        }
    }

    /// Forward kinematics `(link frames g_01 … g_08, g_0e)`.
    fn frames(&self, q: &SVector<f64, 8>) -> ([Se3<f64>; 8], Se3<f64>) {
        let f = std::array::from_fn(|k| self.robot.link_frame(k + 1, q.as_slice()).unwrap());
        (f, self.robot.forward_kinematics(q.as_slice()).unwrap())
    }

    /// The point of link 6 at `l_a` along `y_6`.
    fn link_point(&self, q: &SVector<f64, 8>, l_a: f64) -> Vector3<f64> {
        let g = self.frames(q).0[5];
        g.translation + g.rotation.column(1) * l_a
    }
}

fn fixed<const C: usize>(m: &Mat<f64>) -> SMatrix<f64, 6, C> {
    assert_eq!(m.shape(), (6, C));
    SMatrix::from_fn(|r, c| m[(r, c)])
}

impl<const R: usize, const K: usize, const M: usize> ConstrainedKinematics<f64, 8, 6, R, K, M>
    for Described<R>
{
    fn g_0i(&self, q: &SVector<f64, 8>) -> Se3<f64> {
        self.robot.link_frame(6, q.as_slice()).unwrap()
    }

    fn h(&self) -> SMatrix<f64, R, 6> {
        let h = &self.robot.description().constraint.as_ref().unwrap().h;
        SMatrix::from_fn(|r, c| h[r][c])
    }

    fn shaft(&self) -> Shaft<f64> {
        Shaft::along_y()
    }

    fn task_selection(&self) -> SMatrix<f64, 6, 6> {
        SMatrix::identity()
    }

    fn evaluate(
        &self,
        q: &SVector<f64, 8>,
        l_a: f64,
    ) -> Result<ConstrainedState<f64, 6, R, K, M>, ControlError> {
        let mut robot = self.robot.clone();
        robot
            .set_parameter("l_a", l_a)
            .map_err(|_| ControlError::Kinematics)?;
        let q = q.as_slice();
        Ok(ConstrainedState {
            g_0e: robot.forward_kinematics(q).unwrap(),
            g_0i: robot.link_frame(6, q).unwrap(),
            jr: fixed(&robot.constrained_jacobian(q).unwrap()),
            jb0i: fixed(&robot.partial_body_jacobian(q).unwrap()),
            jc: fixed(&robot.constraint_jacobian_c(q).unwrap()),
            lambda_sharp: fixed(&robot.lambda_null_space().unwrap()),
            lambda_pinv: fixed(&robot.lambda_pinv().unwrap()),
        })
    }
}

fn chain(name: &str) -> Chain<f64, 8> {
    NumericModel::<f64>::from_description(&RobotDescription::preset(name).unwrap(), &[])
        .unwrap()
        .to_chain::<8>()
        .unwrap()
}

fn close<const I: usize, const R: usize, const K: usize, const M: usize>(
    a: &ConstrainedState<f64, I, R, K, M>,
    b: &ConstrainedState<f64, I, R, K, M>,
) {
    let tol = 1e-11;
    assert!((a.g_0e.rotation - b.g_0e.rotation).norm() < tol);
    assert!((a.g_0e.translation - b.g_0e.translation).norm() < tol);
    assert!((a.g_0i.translation - b.g_0i.translation).norm() < tol);
    assert!((a.jr - b.jr).norm() < tol, "{}", a.jr - b.jr);
    assert!((a.jb0i - b.jb0i).norm() < tol);
    assert!((a.jc - b.jc).norm() < tol);
    assert!((a.lambda_sharp - b.lambda_sharp).norm() < tol);
    assert!((a.lambda_pinv - b.lambda_pinv).norm() < tol);
}

fn check<const R: usize, const K: usize, const M: usize>(name: &str)
where
    Described<R>: ConstrainedKinematics<f64, 8, 6, R, K, M>,
    Const<R>: SquareDim,
    Const<M>: SquareDim,
{
    let arm = Described::<R>::new(name);
    let kin = ChainKinematics::thesis(chain(name), Constraint::<f64, R>::thesis(6, 0.15).unwrap());
    let mut rng = StdRng::seed_from_u64(5);
    for _ in 0..50 {
        let q = SVector::<f64, 8>::from_fn(|_, _| rng.gen_range(-1.5..1.5));
        let l_a = rng.gen_range(0.05..0.3);
        let a: ConstrainedState<f64, 6, R, K, M> = arm.evaluate(&q, l_a).unwrap();
        let b: ConstrainedState<f64, 6, R, K, M> = kin.evaluate(&q, l_a).unwrap();
        close(&a, &b);
        // The same controller step through both paths.
        let g = a.g_0e;
        let trocar = a.g_0i.translation + a.g_0i.rotation.column(1) * l_a;
        let reference = Reference {
            position: g.translation + Vector3::new(0.01, -0.02, 0.005),
            rotation: g.rotation,
            velocity: Vector3::new(0.001, 0.0, 0.0),
            angular_velocity: Vector3::new(0.0, 0.01, 0.0),
        };
        let rcm = Rcm {
            trocar: trocar + a.g_0i.rotation.column(0) * 1e-4,
            dv: SVector::<f64, R>::from_element(0.002),
        };
        let config = ControllerConfig {
            kp: 5.0,
            ko: 10.0,
            method: Method::Dls(Damping::Variable {
                alpha0: 0.05,
                w0: 0.1,
            }),
            jb0i_damping: Some(Damping::Variable {
                alpha0: 0.05,
                w0: 0.01,
            }),
            kr: 20.0,
            max_joint_speed: None,
        };
        let mut c1 = Controller::<f64, 8, 6, R, K, M>::new(config);
        let mut c2 = c1;
        let o1 = c1.step(&arm, &q, &reference, &rcm, 0.002).unwrap();
        let o2 = c2.step(&kin, &q, &reference, &rcm, 0.002).unwrap();
        assert!((o1.qd - o2.qd).norm() < 1e-8 * (1.0 + o1.qd.norm()));
        assert!((o1.l_a - l_a).abs() < 1e-12);
    }
}

#[test]
fn numeric_runtime_and_description_robot_agree() {
    check::<2, 4, 6>("dia10_like_zy");
    check::<2, 4, 6>("dia10_like_zx");
    check::<1, 5, 7>("dia10_like_zy");
}

/// The step solves what it claims: with the pseudo-inverse, the commanded end-effector twist is
/// `J^r x + J_c dv_0r = u` and the link velocity satisfies `H V^B_0r = dv_0r` exactly.
#[test]
fn step_realises_the_cartesian_command_and_the_rcm_velocity() {
    let arm = Described::<2>::new("dia10_like_zy");
    let q = SVector::<f64, 8>::from([0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3]);
    let l_a = 0.15;
    let s: ConstrainedState<f64, 6, 2, 4, 6> = arm.evaluate(&q, l_a).unwrap();
    let trocar = s.g_0i.translation + s.g_0i.rotation.column(1) * l_a;
    let reference = Reference {
        position: s.g_0e.translation + Vector3::new(0.003, 0.0, -0.002),
        rotation: s.g_0e.rotation,
        velocity: Vector3::new(0.0, 0.004, 0.0),
        angular_velocity: Vector3::new(0.02, 0.0, 0.0),
    };
    let dv = SVector::<f64, 2>::new(0.003, -0.001);
    let mut c = Controller::<f64, 8, 6, 2, 4, 6>::new(ControllerConfig {
        kp: 5.0,
        ko: 10.0,
        method: Method::Pinv,
        jb0i_damping: None,
        kr: 0.0,
        max_joint_speed: None,
    });
    let out = c
        .step(&arm, &q, &reference, &Rcm { trocar, dv }, 0.002)
        .unwrap();
    // End-effector body twist from the full body Jacobian by finite differences of FK.
    let h = 1e-7;
    let (_, gp) = arm.frames(&(q + out.qd * h));
    let (_, gm) = arm.frames(&(q - out.qd * h));
    let rt = s.g_0e.rotation.transpose();
    let v = rt * (gp.translation - gm.translation) / (2.0 * h);
    let w = rt * (gp.rotation - gm.rotation) / (2.0 * h);
    let w = Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
    assert!(
        (v - out.u.fixed_rows::<3>(0)).norm() < 1e-7,
        "{v} {}",
        out.u
    );
    assert!((w - out.u.fixed_rows::<3>(3)).norm() < 1e-7);
    // Lateral velocity of the link point at the trocar.
    let pp = arm.link_point(&(q + out.qd * h), l_a);
    let pm = arm.link_point(&(q - out.qd * h), l_a);
    let vr = s.g_0i.rotation.transpose() * (pp - pm) / (2.0 * h);
    assert!(
        (vr.x - dv[0]).abs() < 1e-8 && (vr.z - dv[1]).abs() < 1e-8,
        "{vr}"
    );
    // Under a joint speed limit at half that step's peak: the task's share is scaled, the
    // constraint's kept. The link still moves at `dv` across the trocar (finite differences of
    // the chain, not the controller's own Jacobians), and no joint exceeds the limit.
    let limit = 0.5 * out.qd.amax();
    c.config.max_joint_speed = Some(limit);
    let slow = c
        .step(&arm, &q, &reference, &Rcm { trocar, dv }, 0.002)
        .unwrap();
    assert!(
        (slow.qd.amax() - limit).abs() <= 1e-12 * limit,
        "{}",
        slow.qd
    );
    let pp = arm.link_point(&(q + slow.qd * h), l_a);
    let pm = arm.link_point(&(q - slow.qd * h), l_a);
    let vr = s.g_0i.rotation.transpose() * (pp - pm) / (2.0 * h);
    assert!(
        (vr.x - dv[0]).abs() < 1e-8 && (vr.z - dv[1]).abs() < 1e-8,
        "{vr}"
    );
    // Scaling the whole θ̇ instead would move the link at half `dv`.
    let halved = out.qd * (limit / out.qd.amax());
    let pp = arm.link_point(&(q + halved * h), l_a);
    let pm = arm.link_point(&(q - halved * h), l_a);
    let vr_halved = s.g_0i.rotation.transpose() * (pp - pm) / (2.0 * h);
    assert!((vr_halved.x - dv[0]).abs() > 1e-4, "{vr_halved}");
}

/// The controller runs in f32 (embedded users) and stays close to the f64 run over 5 s of
/// scenario-2-like tracking with the numeric runtime.
#[test]
fn f32_controller_tracks_like_f64() {
    let d = RobotDescription::preset("dia10_like_zy").unwrap();
    let k64 = ChainKinematics::thesis(
        chain("dia10_like_zy"),
        Constraint::<f64, 2>::thesis(6, 0.15).unwrap(),
    );
    let k32 = ChainKinematics::thesis(
        NumericModel::<f32>::from_description(&d, &[])
            .unwrap()
            .to_chain::<8>()
            .unwrap(),
        Constraint::<f32, 2>::thesis(6, 0.15).unwrap(),
    );
    let cfg64 = ControllerConfig {
        kp: 5.0,
        ko: 10.0,
        method: Method::Dls(Damping::Variable {
            alpha0: 0.05,
            w0: 0.1,
        }),
        jb0i_damping: None,
        kr: 20.0,
        max_joint_speed: None,
    };
    let cfg32 = ControllerConfig {
        kp: 5.0f32,
        ko: 10.0,
        method: Method::Dls(Damping::Variable {
            alpha0: 0.05,
            w0: 0.1,
        }),
        jb0i_damping: None,
        kr: 20.0,
        max_joint_speed: None,
    };
    let mut c64 = Controller::<f64, 8, 6, 2, 4, 6>::new(cfg64);
    let mut c32 = Controller::<f32, 8, 6, 2, 4, 6>::new(cfg32);
    let mut q64 = SVector::<f64, 8>::from([0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3]);
    let mut q32: SVector<f32, 8> = q64.cast();
    let g0 = k64.chain.forward_kinematics(&q64);
    let gi = k64.chain.link_frame(6, &q64);
    let trocar = gi.translation + gi.rotation.column(1) * 0.15;
    let dt = 0.002;
    for k in 0..2500 {
        let t = k as f64 * dt;
        let w = 0.1;
        let r64 = Reference {
            position: g0.translation + Vector3::new(0.02 * (w * t).sin(), 0.0, 0.0),
            rotation: g0.rotation,
            velocity: Vector3::new(0.02 * w * (w * t).cos(), 0.0, 0.0),
            angular_velocity: Vector3::zeros(),
        };
        let r32 = Reference {
            position: r64.position.cast(),
            rotation: r64.rotation.cast(),
            velocity: r64.velocity.cast(),
            angular_velocity: r64.angular_velocity.cast(),
        };
        let o64 = c64
            .step(
                &k64,
                &q64,
                &r64,
                &Rcm {
                    trocar,
                    dv: SVector::zeros(),
                },
                dt,
            )
            .unwrap();
        let o32 = c32
            .step(
                &k32,
                &q32,
                &r32,
                &Rcm {
                    trocar: trocar.cast(),
                    dv: SVector::zeros(),
                },
                dt as f32,
            )
            .unwrap();
        q64 += o64.qd * dt;
        q32 += o32.qd * dt as f32;
    }
    let diff = (q32.cast::<f64>() - q64).amax();
    assert!(diff < 1e-3, "f32 and f64 joints differ by {diff}");
}

/// The simulations' measurements come from the typed chain: its frames at the zero
/// configuration are `docs/reference-robots.md`'s table.
#[test]
fn zero_configuration_matches_spec_table() {
    let chain = chain("dia10_like_zy");
    let q = SVector::<f64, 8>::zeros();
    let f = chain.link_frames(&q);
    let e = chain.forward_kinematics(&q);
    assert!((f[5].translation - Vector3::new(0.194, 0.77, 1.037)).norm() < 1e-12);
    assert!((f[6].translation - Vector3::new(0.194, 1.10, 1.037)).norm() < 1e-12);
    assert!((e.translation - Vector3::new(0.194, 1.31, 1.037)).norm() < 1e-12);
}

/// The body Jacobian columns agree with finite differences of the chain's frames, and
/// Λ Λ# = 0, J^r reproduces (3.24) at q0 and w_r is (3.42), through `ChainKinematics`.
#[test]
fn jacobians_match_finite_differences_and_thesis() {
    let kin2 = ChainKinematics::thesis(
        chain("dia10_like_zy"),
        Constraint::<f64, 2>::thesis(6, 0.15).unwrap(),
    );
    let q = SVector::<f64, 8>::from([0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3]);
    let la = 0.15;
    let s: ConstrainedState<f64, 6, 2, 4, 6> = kin2.evaluate(&q, la).unwrap();
    let mut c = kin2.constraint;
    c.set_offset(la).unwrap();
    assert!((c.lambda() * s.lambda_sharp).norm() < 1e-14);
    let h = 1e-7;
    for k in 0..6 {
        let mut qp = q;
        qp[k] += h;
        let mut qm = q;
        qm[k] -= h;
        let gp = kin2.chain.link_frame(6, &qp);
        let gm = kin2.chain.link_frame(6, &qm);
        let rt = s.g_0i.rotation.transpose();
        let v = rt * (gp.translation - gm.translation) / (2.0 * h);
        let wh = rt * (gp.rotation - gm.rotation) / (2.0 * h);
        let w = Vector3::new(wh[(2, 1)], wh[(0, 2)], wh[(1, 0)]);
        let col = s.jb0i.column(k);
        assert!((col.fixed_rows::<3>(0) - v).norm() < 1e-6, "v col {k}");
        assert!((col.fixed_rows::<3>(3) - w).norm() < 1e-6, "w col {k}");
    }
    let (lb, l8) = (0.33 - la, 0.21);
    let (s7, c7, s8, c8) = (q[6].sin(), q[6].cos(), q[7].sin(), q[7].cos());
    // Check the unidirectional J^r (3.24), which is exact as printed for this geometry (`docs/ERRATA.md`).
    let kin1 = ChainKinematics::thesis(kin2.chain, Constraint::<f64, 1>::thesis(6, la).unwrap());
    let s1: ConstrainedState<f64, 6, 1, 5, 7> = kin1.evaluate(&q, la).unwrap();
    let a1 = -c8 * (l8 + lb * c7) / la;
    let a2 = -s8 * (l8 + lb * c7) / la;
    let a3 = -s8 * (la + lb + l8 * c7);
    let a4 = c8 * (la + lb + l8 * c7);
    #[rustfmt::skip]
    let expect = SMatrix::<f64, 6, 7>::from_row_slice(&[
        a1, c8 * s7, -s8, a3, -l8 * s7 * s8, -l8 * c8, 0.0,
        lb * s7 / la, c7, 0.0, 0.0, 0.0, 0.0, 0.0,
        a2, s7 * s8, c8, a4, l8 * c8 * s7, -l8 * s8, 0.0,
        -s8 / la, 0.0, 0.0, c7 * c8, c8 * s7, -s8, 0.0,
        0.0, 0.0, 0.0, -s7, c7, 0.0, 1.0,
        c8 / la, 0.0, 0.0, c7 * s8, s7 * s8, c8, 0.0,
    ]);
    assert!((s1.jr - expect).norm() < 1e-12, "{}", s1.jr - expect);
    // Manipulability claim (3.42) for zy: w_r = lb² |sin θ7| / la².
    let w = trocar::control::manipulability(&s.jr);
    assert!((w - lb * lb * s7.abs() / (la * la)).abs() < 1e-9, "{w}");
}
