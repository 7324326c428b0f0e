//! One full constrained control step (f64, DLS on the task Jacobian and on `J^B_0i`, drift
//! correction on), in one criterion run:
//!
//! - `dia10_like_zy` with the generated closed forms and with the numeric runtime;
//! - the Panda laparoscope (`panda-laparoscope`: constraint on the last link, task `x y z rz`,
//!   joint-limit objective on the arm's spare freedom) with the generated closed forms;
//! - for both generated robots, the **baseline**: the step of 2026-11-23 written out
//!   ([`baseline::step`]: nalgebra's `LU` for square matrices, nalgebra's `Cholesky` of the Gram
//!   matrix otherwise, as the runtime's `damped_solve` then did, the matrices copied entry by
//!   entry), so that a faster step is measured against it
//!   in one run (the target of the real-robot work: ≤ 0.57×). On `dia10_like` the baseline also
//!   evaluates the kinematics as the generated glue of that day did ([`baseline::ThenGlue`]: the
//!   module's functions one by one, `l_a` along `y_i`); the Panda had no glue then, so its
//!   baseline runs on today's `Kinematics`;
//! - `_16q`: the same pairs cycling through 16 configurations around `q0`, so that consecutive
//!   steps see different matrices (branch prediction of the pivoting no longer learns one).

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use trocar::constraint::Constraint;
use trocar::control::{
    ChainKinematics, ConstrainedKinematics, Controller, ControllerConfig, NullSpaceObjective, Rcm,
    Reference,
};
use trocar::nalgebra::{SVector, Vector3};
use trocar_model::description::RobotDescription;
use trocar_model::numeric::NumericModel;
use trocar_sim::simulation::{Method, Scenario, ScenarioConfig, L_A0, PANDA_Q0, Q0};
use trocar_tests_generated::control::{GeneratedKinematics, PandaLaparoscope};

/// The control step of 2026-11-23: the algorithm of `trocar::control::Controller::step`
/// (pseudo-inverse or damped least squares), with nalgebra's fixed-size `LU` for square matrices
/// and `from_iterator` copies.
mod baseline {
    use trocar::control::{trocar_offset, ConstrainedState, ControlError, Shaft};
    use trocar::control::{
        ConstrainedKinematics, ControllerConfig, Method, NullSpaceObjective, Quaternion, Rcm,
        Reference,
    };
    use trocar::nalgebra::{
        ArrayStorage, Cholesky, Const, DimMin, Matrix3, SMatrix, SVector, Vector3, Vector6,
    };
    use trocar::se3::Se3;
    use trocar_tests_generated::dia10_like_zy as dia10;

    /// The reference arm's kinematics evaluated as the generated glue of 2026-11-23 did: one
    /// `JointTrig`, `g_0i`, `l_a = (p_t − p_0i) · y_i`, then each function into the state.
    pub struct ThenGlue(pub dia10::Params<f64>);

    fn pose((r, p): ([[f64; 3]; 3], [f64; 3])) -> Se3<f64> {
        Se3 {
            rotation: Matrix3::from_data(ArrayStorage(r)),
            translation: Vector3::from_data(ArrayStorage([p])),
        }
    }

    impl ThenGlue {
        fn state(
            &self,
            t: &dia10::JointTrig<f64>,
            g_0i: Se3<f64>,
            l_a: f64,
        ) -> Result<ConstrainedState<f64, 6, 2, 4, 6>, ControlError> {
            if l_a == 0.0 || !l_a.is_finite() {
                return Err(ControlError::Kinematics);
            }
            let mut p = self.0;
            p.l_a = l_a;
            Ok(ConstrainedState {
                g_0e: pose(dia10::forward_kinematics_trig(t, &p)),
                g_0i,
                jr: SMatrix::from_data(ArrayStorage(dia10::constrained_jacobian_trig(t, &p))),
                jb0i: SMatrix::from_data(ArrayStorage(dia10::partial_body_jacobian_trig(t, &p))),
                jc: SMatrix::from_data(ArrayStorage(dia10::constraint_jacobian_c_trig(t, &p))),
                lambda_sharp: SMatrix::from_data(ArrayStorage(dia10::lambda_null_space(&p))),
                lambda_pinv: SMatrix::from_data(ArrayStorage(dia10::lambda_pinv(&p))),
            })
        }
    }

    impl ConstrainedKinematics<f64, 8, 6, 2, 4, 6> for ThenGlue {
        fn g_0i(&self, q: &SVector<f64, 8>) -> Se3<f64> {
            pose(dia10::forward_kinematics_i(&q.data.0[0], &self.0))
        }
        fn h(&self) -> SMatrix<f64, 2, 6> {
            SMatrix::from_data(ArrayStorage(dia10::constraint_selection(&self.0)))
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
        ) -> Result<ConstrainedState<f64, 6, 2, 4, 6>, ControlError> {
            let t = dia10::JointTrig::new(&q.data.0[0]);
            let g_0i = pose(dia10::forward_kinematics_i_trig(&t, &self.0));
            self.state(&t, g_0i, l_a)
        }
        fn evaluate_at_trocar(
            &self,
            q: &SVector<f64, 8>,
            trocar: &Vector3<f64>,
        ) -> Result<(f64, ConstrainedState<f64, 6, 2, 4, 6>), ControlError> {
            let t = dia10::JointTrig::new(&q.data.0[0]);
            let g_0i = pose(dia10::forward_kinematics_i_trig(&t, &self.0));
            let l_a = trocar_offset(&g_0i, trocar);
            Ok((l_a, self.state(&t, g_0i, l_a)?))
        }
    }

    /// `trocar::control::orientation_error` of that day: the product of the two rotations'
    /// quaternions (each extracted as today, by Shepperd's method).
    fn orientation_error(desired: &Matrix3<f64>, current: &Matrix3<f64>) -> Quaternion<f64> {
        let e =
            Quaternion::from_rotation(desired).mul(&Quaternion::from_rotation(current).inverse());
        if e.eta < 0.0 {
            Quaternion {
                eta: -e.eta,
                eps: -e.eps,
            }
        } else {
            e
        }
    }

    /// `trocar::control::damped_solve` of that day: nalgebra's `Cholesky` of the Gram matrix.
    fn damped_solve<const R: usize, const C: usize>(
        j: &SMatrix<f64, R, C>,
        kappa: f64,
        v: &SVector<f64, R>,
    ) -> Option<SVector<f64, C>> {
        let k2 = kappa * kappa;
        let x = if R <= C {
            let gram = j * j.transpose() + SMatrix::<f64, R, R>::identity() * k2;
            j.tr_mul(&Cholesky::new(gram)?.solve(v))
        } else {
            let gram = j.tr_mul(j) + SMatrix::<f64, C, C>::identity() * k2;
            Cholesky::new(gram)?.solve(&j.tr_mul(v))
        };
        x.iter().all(|v| v.is_finite()).then_some(x)
    }

    /// `trocar::control::resolve_with_null_space` of that day.
    fn resolve_with_null_space<const C: usize>(
        j: &SMatrix<f64, 6, C>,
        kappa: f64,
        v: &SVector<f64, 6>,
        u0: &SVector<f64, C>,
    ) -> Option<SVector<f64, C>> {
        Some(damped_solve(j, kappa, &(v - j * u0))? + u0)
    }

    fn prepared<const R: usize, const C: usize>(
        j: &SMatrix<f64, R, C>,
        kappa_of: impl Fn(f64) -> f64,
        v: &SVector<f64, R>,
    ) -> Option<(SVector<f64, C>, f64)>
    where
        Const<R>: DimMin<Const<R>, Output = Const<R>>,
    {
        if R == C {
            let square = SMatrix::<f64, R, R>::from_iterator(j.iter().copied());
            let lu = square.lu();
            let w = lu.determinant().abs();
            let kappa = kappa_of(w);
            if kappa == 0.0 {
                let x = lu.solve(v)?;
                return Some((SVector::<f64, C>::from_iterator(x.iter().copied()), w));
            }
            return Some((damped_solve(j, kappa, v)?, w));
        }
        let w = (j * j.transpose()).lu().determinant().abs().sqrt();
        Some((damped_solve(j, kappa_of(w), v)?, w))
    }

    /// One step; `None` where the controller would fail.
    #[allow(clippy::too_many_arguments)]
    pub fn step<
        Kin: ConstrainedKinematics<f64, N, I, R, K, M, P>,
        const N: usize,
        const I: usize,
        const R: usize,
        const K: usize,
        const M: usize,
        const P: usize,
    >(
        c: &ControllerConfig<f64>,
        objective: &NullSpaceObjective<f64, N>,
        kin: &Kin,
        q: &SVector<f64, N>,
        reference: &Reference<f64>,
        rcm: &Rcm<f64, R>,
    ) -> Option<SVector<f64, N>>
    where
        Const<I>: DimMin<Const<I>, Output = Const<I>>,
        Const<P>: DimMin<Const<P>, Output = Const<P>>,
    {
        let (l_a, s) = kin.evaluate_at_trocar(q, &rcm.trocar).ok()?;
        let h = kin.h();
        // `Shaft::trocar_in_frame` of that day: through `g_0r`.
        let g_0r = kin.shaft().constraint_pose(&s.g_0i, l_a);
        let e = g_0r.rotation.transpose() * (rcm.trocar - g_0r.translation);
        let lateral: SVector<f64, R> = h.fixed_columns::<3>(0) * e;
        let dv_0r = rcm.dv + lateral * c.kr;
        let rt = s.g_0e.rotation.transpose();
        let ep = rt * (reference.position - s.g_0e.translation);
        let eq = orientation_error(&reference.rotation, &s.g_0e.rotation);
        let uo = rt * (reference.angular_velocity + eq.eps * c.ko);
        let up: Vector3<f64> = rt * reference.velocity + ep * c.kp - uo.cross(&ep);
        let u = Vector6::new(up.x, up.y, up.z, uo.x, uo.y, uo.z);
        let sel = kin.task_selection();
        let rhs = u - s.jc * dv_0r;
        let (task_jr, dv_e): (SMatrix<f64, P, M>, SVector<f64, P>) =
            if P == 6 && sel == SMatrix::<f64, P, 6>::identity() {
                (
                    SMatrix::from_iterator(s.jr.iter().copied()),
                    SVector::from_iterator(rhs.iter().copied()),
                )
            } else {
                (sel * s.jr, sel * rhs)
            };
        let damping_r = match c.method {
            Method::Dls(d) => Some(d),
            _ => None,
        };
        let (x, _) = prepared(&task_jr, |w| damping_r.map_or(0.0, |d| d.kappa(w)), &dv_e)?;
        let v0i: SVector<f64, K> = x.fixed_rows::<K>(0).into_owned();
        let v_0i = s.lambda_sharp * v0i + s.lambda_pinv * dv_0r;
        let kappa_i = |w: f64| c.jb0i_damping.map_or(0.0, |d| d.kappa(w));
        let qd_i: SVector<f64, I> = if I > 6 && *objective != NullSpaceObjective::None {
            let w = (s.jb0i * s.jb0i.transpose())
                .lu()
                .determinant()
                .abs()
                .sqrt();
            let u0 = objective.gradient::<I>(q, &s.jb0i);
            resolve_with_null_space(&s.jb0i, kappa_i(w), &v_0i, &u0)?
        } else {
            prepared(&s.jb0i, kappa_i, &v_0i)?.0
        };
        let mut qd = SVector::<f64, N>::zeros();
        for k in 0..I {
            qd[k] = qd_i[k];
        }
        for k in I..N {
            qd[k] = x[K + k - I];
        }
        qd.iter().all(|v| v.is_finite()).then_some(qd)
    }
}

/// 16 configurations around `q0` (each joint `q0 + 0.01 + 0.15 u`, `u` uniform in [−1, 1] from
/// a fixed LCG): the `_16q` benches cycle through them, so that the steps do not all see the same
/// matrices (the emitted LU's pivot branches are predicted only as far as the pivots repeat).
fn configurations<const N: usize>(q0: &SVector<f64, N>) -> [SVector<f64, N>; 16] {
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    core::array::from_fn(|_| {
        q0 + SVector::<f64, N>::from_fn(|_, _| {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let u = (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0;
            0.01 + 0.15 * u
        })
    })
}

fn bench_step<Kin: ConstrainedKinematics<f64, 8, 6, 2, 4, 6>>(
    c: &mut Criterion,
    name: &str,
    kin: &Kin,
    reference: &Reference<f64>,
    rcm: &Rcm<f64, 2>,
    config: &ScenarioConfig,
) {
    let mut ctrl = Controller::<f64, 8, 6, 2, 4, 6>::new(config.controller_config());
    // A configuration off q0 so that the errors are not zero.
    let q = SVector::<f64, 8>::from(Q0) + SVector::<f64, 8>::from_element(0.01);
    c.bench_function(name, |b| {
        b.iter(|| {
            ctrl.step(
                black_box(kin),
                black_box(&q),
                black_box(reference),
                black_box(rcm),
                black_box(config.dt),
            )
            .unwrap()
        })
    });
}

fn dia10(c: &mut Criterion) {
    let d = RobotDescription::preset("dia10_like_zy").unwrap();
    let numeric = ChainKinematics::thesis(
        NumericModel::<f64>::from_description(&d, &[])
            .unwrap()
            .to_chain::<8>()
            .unwrap(),
        Constraint::<f64, 2>::thesis(6, L_A0).unwrap(),
    );
    let generated = GeneratedKinematics::<f64>::nominal();
    // No joint speed limit: the baseline has none (and this configuration's rates exceed the
    // default).
    let config = ScenarioConfig::new(Scenario::S2)
        .with_method(Method::Dls)
        .with_drift_correction(true)
        .with_max_joint_speed(None);
    let q0 = SVector::<f64, 8>::from(Q0);
    let g_0e0 = numeric.chain.forward_kinematics(&q0);
    let axis7 = numeric
        .chain
        .link_frame(7, &q0)
        .rotation
        .column(2)
        .into_owned();
    let g_0i0 = numeric.chain.link_frame(6, &q0);
    let reference = config.scenario.reference(1.0, config.dt, &g_0e0, &axis7);
    let rcm = Rcm {
        trocar: g_0i0.translation + g_0i0.rotation.column(1) * L_A0 + Vector3::new(1e-4, 0.0, 0.0),
        dv: SVector::<f64, 2>::new(0.001, -0.001),
    };
    bench_step(
        c,
        "control_step/generated",
        &generated,
        &reference,
        &rcm,
        &config,
    );
    let cfg: ControllerConfig<f64> = config.controller_config();
    let q = q0 + SVector::<f64, 8>::from_element(0.01);
    let none = NullSpaceObjective::None;
    // Same result as the controller's step (the baseline is the same algorithm).
    let mut ctrl = Controller::<f64, 8, 6, 2, 4, 6>::new(cfg);
    let now = ctrl
        .step(&generated, &q, &reference, &rcm, config.dt)
        .unwrap()
        .qd;
    let then_glue = baseline::ThenGlue(trocar_tests_generated::dia10_like_zy::Params::nominal());
    let then = baseline::step(&cfg, &none, &then_glue, &q, &reference, &rcm).unwrap();
    assert!((now - then).amax() < 1e-9, "baseline and step differ");
    c.bench_function("control_step/generated_baseline", |b| {
        b.iter(|| {
            baseline::step(
                &cfg,
                &none,
                black_box(&then_glue),
                black_box(&q),
                black_box(&reference),
                black_box(&rcm),
            )
            .unwrap()
        })
    });
    let qs = configurations(&q0);
    let mut k = 0usize;
    c.bench_function("control_step/generated_16q", |b| {
        b.iter(|| {
            k = (k + 1) % 16;
            ctrl.step(
                black_box(&generated),
                black_box(&qs[k]),
                black_box(&reference),
                black_box(&rcm),
                black_box(config.dt),
            )
            .unwrap()
        })
    });
    c.bench_function("control_step/generated_baseline_16q", |b| {
        b.iter(|| {
            k = (k + 1) % 16;
            baseline::step(
                &cfg,
                &none,
                black_box(&then_glue),
                black_box(&qs[k]),
                black_box(&reference),
                black_box(&rcm),
            )
            .unwrap()
        })
    });
    bench_step(
        c,
        "control_step/numeric",
        &numeric,
        &reference,
        &rcm,
        &config,
    );
    // The kinematics alone.
    let l_a = L_A0 + 0.001;
    c.bench_function("evaluate/generated", |b| {
        b.iter(|| black_box(&generated).evaluate(black_box(&q), black_box(l_a)))
    });
    c.bench_function("evaluate/numeric", |b| {
        b.iter(|| {
            ConstrainedKinematics::<f64, 8, 6, 2, 4, 6>::evaluate(
                black_box(&numeric),
                black_box(&q),
                black_box(l_a),
            )
        })
    });
}

fn panda(c: &mut Criterion) {
    let kin = PandaLaparoscope::<f64>::nominal();
    let config = ScenarioConfig::new(Scenario::Panda)
        .with_drift_correction(true)
        .with_max_joint_speed(None);
    let cfg = config.controller_config();
    let limits: Vec<[f64; 2]> = RobotDescription::preset("panda-laparoscope")
        .unwrap()
        .joints
        .iter()
        .map(|j| j.limits.unwrap())
        .collect();
    let objective = NullSpaceObjective::JointLimits {
        gain: config.null_space_gain,
        lower: SVector::from_fn(|k, _| limits[k][0]),
        upper: SVector::from_fn(|k, _| limits[k][1]),
    };
    let q0 = SVector::<f64, 7>::from(PANDA_Q0);
    let s = ConstrainedKinematics::<f64, 7, 7, 2, 4, 4, 4>::evaluate(&kin, &q0, 0.25).unwrap();
    let trocar = s.g_0i.transform_point(&Vector3::new(0.0, 0.0, 0.357));
    let reference = config
        .scenario
        .reference(1.0, config.dt, &s.g_0e, &Vector3::zeros());
    let rcm = Rcm {
        trocar: trocar + Vector3::new(1e-5, 0.0, 0.0),
        dv: SVector::<f64, 2>::zeros(),
    };
    let q = q0 + SVector::<f64, 7>::from_element(0.01);
    let mut ctrl = Controller::<f64, 7, 7, 2, 4, 4, 4>::new(cfg).with_objective(objective);
    let now = ctrl.step(&kin, &q, &reference, &rcm, config.dt).unwrap().qd;
    let then = baseline::step(&cfg, &objective, &kin, &q, &reference, &rcm).unwrap();
    assert!((now - then).amax() < 1e-9, "baseline and step differ");
    c.bench_function("panda_step/generated", |b| {
        b.iter(|| {
            ctrl.step(
                black_box(&kin),
                black_box(&q),
                black_box(&reference),
                black_box(&rcm),
                black_box(config.dt),
            )
            .unwrap()
        })
    });
    c.bench_function("panda_step/generated_baseline", |b| {
        b.iter(|| {
            baseline::step(
                &cfg,
                &objective,
                black_box(&kin),
                black_box(&q),
                black_box(&reference),
                black_box(&rcm),
            )
            .unwrap()
        })
    });
    let qs = configurations(&q0);
    let mut k = 0usize;
    c.bench_function("panda_step/generated_16q", |b| {
        b.iter(|| {
            k = (k + 1) % 16;
            ctrl.step(
                black_box(&kin),
                black_box(&qs[k]),
                black_box(&reference),
                black_box(&rcm),
                black_box(config.dt),
            )
            .unwrap()
        })
    });
    c.bench_function("panda_step/generated_baseline_16q", |b| {
        b.iter(|| {
            k = (k + 1) % 16;
            baseline::step(
                &cfg,
                &objective,
                black_box(&kin),
                black_box(&qs[k]),
                black_box(&reference),
                black_box(&rcm),
            )
            .unwrap()
        })
    });
}

criterion_group!(benches, dia10, panda);
criterion_main!(benches);
