//! The constrained Jacobian on the shipped robots: Λ Λ# = 0, the constraint holds for θ̇ from
//! (3.10), J^B_0e θ̇ = J^r_0e [v0i; θ̇_jn] (3.9)–(3.11), the printed (3.24), the manipulability
//! claims (3.41)/(3.42), the typed API against the dynamic one, f32 against f64, and errors.

use faer::{Col, Mat};
use rand::{rngs::StdRng, Rng, SeedableRng};
use trocar::constraint::Constraint;
use trocar::linalg::SquareDim;
use trocar::nalgebra::{Const, SMatrix, SVector, Vector3};
use trocar::se3::{rotation_from_rpy, Adjoint, Se3};
use trocar_model::description::{AdmissionError, Linear, RobotDescription};
use trocar_sim::robot::{NumericRobot, RobotError};

const ALL: [&str; 5] = [
    "unidirectional",
    "bidirectional-zy",
    "bidirectional-zx",
    "dia10_like_zy",
    "dia10_like_zx",
];

/// A robot with random lengths: l_a in [0.05, 0.3] (and l_b, l_8 for the presets).
fn random_robot(name: &str, rng: &mut StdRng) -> NumericRobot<f64> {
    let d = RobotDescription::preset(name).unwrap();
    let overrides: Vec<(String, f64)> = d
        .parameters
        .iter()
        .map(|p| (p.name.clone(), rng.gen_range(0.05..0.3)))
        .collect();
    NumericRobot::from_description(&d, &overrides).unwrap()
}

fn random_q(rng: &mut StdRng, n: usize) -> Vec<f64> {
    (0..n).map(|_| rng.gen_range(-3.1..3.1)).collect()
}

/// `H Ad_{g_ri}` straight from the description (not from `NumericRobot::lambda`).
fn h_ad_gri(robot: &NumericRobot<f64>) -> Mat<f64> {
    let c = robot.description().constraint.clone().unwrap();
    let look = |n: &str| {
        robot
            .parameters()
            .iter()
            .find(|(p, _)| p == n)
            .map(|(_, v)| *v)
    };
    let ev = |s: &Linear| s.eval(look).unwrap();
    let p = Vector3::new(
        ev(&c.origin.xyz[0]),
        ev(&c.origin.xyz[1]),
        ev(&c.origin.xyz[2]),
    );
    let r = match c.origin.rotation {
        trocar_model::description::Rotation::Rpy([a, b, g]) => rotation_from_rpy(a, b, g),
        trocar_model::description::Rotation::Matrix(m) => {
            trocar::nalgebra::Matrix3::from_fn(|i, j| m[i][j])
        }
    };
    let ad_gri = Adjoint(Se3::new(r, p)).inverse_matrix();
    let h = Mat::from_fn(c.h.len(), 6, |i, j| c.h[i][j]);
    let ad = dense(ad_gri.as_slice(), 6, 6);
    h * ad
}

fn max_abs(m: &Mat<f64>) -> f64 {
    m.norm_max()
}

/// A faer matrix from column-major entries.
fn dense(m: &[f64], rows: usize, cols: usize) -> Mat<f64> {
    Mat::from_fn(rows, cols, |r, c| m[c * rows + r])
}

/// Singular values by faer's SVD, decreasing.
fn singular_values(m: &Mat<f64>) -> Vec<f64> {
    m.singular_values().expect("SVD converges")
}

fn min(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::INFINITY, f64::min)
}

fn max(v: &[f64]) -> f64 {
    v.iter().copied().fold(0.0, f64::max)
}

/// Numerical rank: singular values above `eps`.
fn rank(m: &Mat<f64>, eps: f64) -> usize {
    singular_values(m).iter().filter(|&&s| s > eps).count()
}

#[test]
fn lambda_times_null_space_is_zero() {
    let mut rng = StdRng::seed_from_u64(1);
    for name in ALL {
        for _ in 0..50 {
            let robot = random_robot(name, &mut rng);
            let l = robot.lambda().unwrap();
            assert!(
                max_abs(&(&l - h_ad_gri(&robot))) < 1e-15,
                "{name}: Λ = H Ad_gri"
            );
            let s = robot.lambda_null_space().unwrap();
            let r = robot.constraint_rows().unwrap();
            assert_eq!(s.shape(), (6, 6 - r));
            assert!(max_abs(&(&l * &s)) < 1e-12, "{name}: Λ Λ# = {:?}", &l * &s);
            assert_eq!(rank(&s, 1e-9), 6 - r, "{name}: Λ# has full column rank");
            let p = robot.lambda_pinv().unwrap();
            assert!(max_abs(&(&l * &p - Mat::<f64>::identity(r, r))) < 1e-12);
        }
    }
}

/// (3.10) keeps the constraint, and (3.9)–(3.11): J^B_0e θ̇ = J^r_0e [v0i; θ̇_jn].
#[test]
fn constrained_jacobian_reproduces_the_body_velocity() {
    let mut rng = StdRng::seed_from_u64(2);
    for name in ALL {
        let mut checked = 0;
        while checked < 100 {
            let robot = random_robot(name, &mut rng);
            let n = robot.dof();
            let i = robot.constrained_link().unwrap();
            let r = robot.constraint_rows().unwrap();
            let q = random_q(&mut rng, n);
            let jb0i = robot.partial_body_jacobian(&q).unwrap();
            // Stay away from singular J^B_0i (3.10 needs its inverse).
            let sv = singular_values(&jb0i);
            if min(&sv) < 1e-2 {
                continue;
            }
            checked += 1;
            let v0i: Vec<f64> = (0..6 - r).map(|_| rng.gen_range(-1.0..1.0)).collect();
            let th_jn: Vec<f64> = (0..n - i).map(|_| rng.gen_range(-1.0..1.0)).collect();
            let th_1i = robot.joint_rates_before_constraint(&q, &v0i, &[]).unwrap();
            // The constraint: H Ad_gri J^B_0i θ̇_{1..i} = 0.
            let c = h_ad_gri(&robot) * &jb0i * &th_1i;
            assert!(c.norm_max() < 1e-12, "{name}: constraint violated by {c:?}");
            // (3.9)–(3.11).
            let th_all: Vec<f64> = th_1i.iter().copied().chain(th_jn.iter().copied()).collect();
            let th = Col::from_fn(n, |k| th_all[k]);
            let lhs = robot.body_jacobian(&q).unwrap() * th;
            let vv_all: Vec<f64> = v0i.iter().copied().chain(th_jn.iter().copied()).collect();
            let vv = Col::from_fn(6 - r + n - i, |k| vv_all[k]);
            let jr = robot.constrained_jacobian(&q).unwrap();
            assert_eq!(jr.shape(), (6, 6 - r + n - i));
            let rhs = &jr * vv;
            assert!(
                (&lhs - &rhs).norm_max() < 1e-12,
                "{name}: {lhs:?} vs {rhs:?}"
            );
            // The split (3.12): J^B_0e1 = Ad_{g_ei} J^B_0i.
            let (j1, j2) = robot.body_jacobian_split(&q).unwrap();
            let g_ie = robot
                .link_frame(i, &q)
                .unwrap()
                .inverse()
                .compose(&robot.forward_kinematics(&q).unwrap());
            let ad = Adjoint(g_ie).inverse_matrix();
            let ad = dense(ad.as_slice(), 6, 6);
            assert!((j1 - ad * &jb0i).norm_max() < 1e-12);
            assert!((j2 - jr.as_ref().subcols(6 - r, n - i)).norm_max() == 0.0);
        }
    }
}

/// (3.24) as printed (presets' geometry: `docs/reference-robots.md`), transcribed by hand.
fn printed_3_24(t7: f64, t8: f64, la: f64, lb: f64, l8: f64) -> SMatrix<f64, 6, 7> {
    let (s7, c7) = t7.sin_cos();
    let (s8, c8) = t8.sin_cos();
    let a1 = -c8 * (l8 + lb * c7) / la;
    let a2 = -s8 * (l8 + lb * c7) / la;
    let a3 = -s8 * (la + lb + l8 * c7);
    let a4 = c8 * (la + lb + l8 * c7);
    SMatrix::<f64, 6, 7>::from_row_slice(&[
        a1,
        c8 * s7,
        -s8,
        a3,
        -l8 * s7 * s8,
        -l8 * c8,
        0.0, //
        lb * s7 / la,
        c7,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0, //
        a2,
        s7 * s8,
        c8,
        a4,
        l8 * c8 * s7,
        -l8 * s8,
        0.0, //
        -s8 / la,
        0.0,
        0.0,
        c7 * c8,
        c8 * s7,
        -s8,
        0.0, //
        0.0,
        0.0,
        0.0,
        -s7,
        c7,
        0.0,
        1.0, //
        c8 / la,
        0.0,
        0.0,
        c7 * s8,
        s7 * s8,
        c8,
        0.0, //
    ])
}

#[test]
fn unidirectional_preset_is_the_printed_3_24() {
    let d = RobotDescription::preset("unidirectional").unwrap();
    let mut rng = StdRng::seed_from_u64(3);
    for _ in 0..200 {
        let (la, lb, l8) = (
            rng.gen_range(0.02..0.5),
            rng.gen_range(0.02..0.5),
            rng.gen_range(0.02..0.5),
        );
        let robot = NumericRobot::<f64>::from_description(
            &d,
            &[("l_a".into(), la), ("l_b".into(), lb), ("l_8".into(), l8)],
        )
        .unwrap();
        let q = random_q(&mut rng, 8);
        let jr = robot.constrained_jacobian(&q).unwrap();
        let printed = printed_3_24(q[6], q[7], la, lb, l8);
        let diff = (jr - dense(printed.as_slice(), 6, 7)).norm_max();
        assert!(diff < 1e-12, "differs by {diff:e} at q = {q:?}");
    }
}

/// (3.41) zx: w_r = l_b² |cos θ7| / l_a²; (3.42) zy: w_r = l_b² |sin θ7| / l_a².
#[test]
fn bidirectional_manipulability_claims() {
    let mut rng = StdRng::seed_from_u64(4);
    for (name, f) in [
        ("bidirectional-zy", f64::sin as fn(f64) -> f64),
        ("bidirectional-zx", f64::cos),
    ] {
        for _ in 0..100 {
            let robot = random_robot(name, &mut rng);
            let p = |n: &str| robot.parameters().iter().find(|(m, _)| m == n).unwrap().1;
            let (la, lb) = (p("l_a"), p("l_b"));
            let q = random_q(&mut rng, 8);
            let w = robot.manipulability(&q).unwrap();
            let claim = lb * lb * f(q[6]).abs() / (la * la);
            assert!(
                (w - claim).abs() < 1e-10 * (1.0 + claim),
                "{name}: {w} vs {claim}"
            );
        }
    }
}

/// The allocation-free typed API agrees with the dynamic front end.
#[test]
fn typed_api_matches_dynamic() {
    let mut rng = StdRng::seed_from_u64(5);
    fn check<const R: usize, const K: usize, const M: usize>(robot: &NumericRobot<f64>, q: &[f64])
    where
        Const<R>: SquareDim,
        Const<M>: SquareDim,
    {
        let chain = robot.to_chain::<8>().unwrap();
        let c: Constraint<f64, R> = robot.to_constraint().unwrap();
        let qv = SVector::<f64, 8>::from_column_slice(q);
        let (jr, jc) = c.constrained_jacobians::<8, M>(&chain, &qv);
        let d = dense;
        assert_eq!(
            d(jr.as_slice(), 6, M),
            robot.constrained_jacobian(q).unwrap()
        );
        assert!(
            (d(jc.as_slice(), 6, R) - robot.constraint_jacobian_c(q).unwrap()).norm_max() < 1e-15
        );
        assert_eq!(
            d(chain.body_jacobian(&qv).as_slice(), 6, 8),
            robot.body_jacobian(q).unwrap()
        );
        assert_eq!(
            d(chain.spatial_jacobian(&qv).as_slice(), 6, 8),
            robot.spatial_jacobian(q).unwrap()
        );
        let jb0i = chain.partial_body_jacobian::<6>(&qv);
        assert_eq!(
            d(jb0i.as_slice(), 6, 6),
            robot.partial_body_jacobian(q).unwrap()
        );
        let s: SMatrix<f64, 6, K> = c.lambda_null_space();
        assert_eq!(d(s.as_slice(), 6, K), robot.lambda_null_space().unwrap());
        // (3.10) with the typed kernel, against the SVD pseudo-inverse.
        let v0i = SVector::<f64, K>::from_fn(|k, _| 0.1 * k as f64 - 0.2);
        let v = c.link_velocity(&v0i, &SVector::<f64, R>::zeros());
        let th: SVector<f64, 6> = c
            .joint_rates_before_constraint::<8, 6>(&chain, &qv, &v)
            .unwrap();
        let th_dyn = robot
            .joint_rates_before_constraint(q, v0i.as_slice(), &[])
            .unwrap();
        assert!((Col::from_fn(6, |k| th[k]) - th_dyn).norm_max() < 1e-9);
        // Manipulability (3.36).
        let w = trocar::manipulability::manipulability::<f64, 6, M>(&jr);
        assert!((w - robot.manipulability(q).unwrap()).abs() < 1e-12 * (1.0 + w));
    }
    for _ in 0..20 {
        let q = random_q(&mut rng, 8);
        check::<1, 5, 7>(&random_robot("unidirectional", &mut rng), &q);
        check::<2, 4, 6>(&random_robot("bidirectional-zy", &mut rng), &q);
        check::<2, 4, 6>(&random_robot("dia10_like_zx", &mut rng), &q);
    }
}

/// The f32 path: the same kernels in f32 agree with f64 to single precision.
#[test]
fn f32_agrees_with_f64() {
    let mut rng = StdRng::seed_from_u64(6);
    for name in ALL {
        let r64 = random_robot(name, &mut rng);
        let r32 =
            NumericRobot::<f32>::from_description(r64.description(), r64.parameters()).unwrap();
        let q: Vec<f64> = random_q(&mut rng, 8);
        let q32: Vec<f32> = q.iter().map(|&x| x as f32).collect();
        let a = r64.constrained_jacobian(&q).unwrap();
        let b32 = r32.constrained_jacobian(&q32).unwrap();
        let b = Mat::from_fn(b32.nrows(), b32.ncols(), |r, c| b32[(r, c)] as f64);
        assert!(
            (&a - &b).norm_max() < 1e-4 * (1.0 + a.norm_max()),
            "{name}: {a:?} vs {b:?}"
        );
        // Typed f32 chain from the f64 one.
        let chain64 = r64.to_chain::<8>().unwrap();
        let chain32 = trocar::kinematics::Chain::<f32, 8>::from_f64(&chain64);
        let qv = SVector::<f32, 8>::from_column_slice(&q32);
        let jb32 = chain32.body_jacobian(&qv).map(|x| x as f64);
        let jb64 = r64.body_jacobian(&q).unwrap();
        let jb32 = dense(jb32.as_slice(), 6, 8);
        assert!((&jb64 - &jb32).norm_max() < 1e-4 * (1.0 + jb64.norm_max()));
        // Finite differences in f32 with the f32 step.
        let fd = trocar::finite_diff::body_jacobian(
            &chain32,
            &qv,
            trocar::finite_diff::default_step::<f32>(),
        )
        .map(|x| x as f64);
        let fd = dense(fd.as_slice(), 6, 8);
        assert!(
            (&jb64 - &fd).norm_max() < 2e-2,
            "{name}: f32 finite differences"
        );
    }
}

#[test]
fn user_errors_are_results() {
    let d = RobotDescription::preset("bidirectional-zy").unwrap();
    let r = NumericRobot::<f64>::from_description(&d, &[("l_q".into(), 1.0)]);
    assert_eq!(r.unwrap_err(), RobotError::UnknownOverride("l_q".into()));
    let robot = NumericRobot::<f64>::from_description(&d, &[]).unwrap();
    assert_eq!(
        robot.constrained_jacobian(&[0.0; 7]).unwrap_err(),
        RobotError::WrongJointCount {
            expected: 8,
            got: 7
        }
    );
    let mut robot2 = robot.clone();
    assert!(robot2.set_parameter("l_a", 0.0).is_err());
    assert_eq!(robot2, robot);
    robot2.set_parameter("l_a", 0.25).unwrap();
    assert_eq!(robot2.lambda().unwrap()[(0, 5)], -0.25);

    let mut bad = d.clone();
    bad.joints.pop();
    let e = NumericRobot::<f64>::from_description(&bad, &[]).unwrap_err();
    assert_eq!(
        e,
        RobotError::NotAdmitted(AdmissionError::TooFewJoints { n: 7, r: 2, t: 6 })
    );
    assert!(e.to_string().contains("n − r ≥ t") && e.to_string().contains("n = 7, r = 2, t = 6"));

    let mut bad = d.clone();
    bad.constraint.as_mut().unwrap().link = 9;
    assert_eq!(
        NumericRobot::<f64>::from_description(&bad, &[]).unwrap_err(),
        RobotError::LinkOutOfRange { link: 9, joints: 8 }
    );

    let mut bad = d.clone();
    bad.joints[2].origin.xyz[1] = Linear::param("l_z");
    let e = NumericRobot::<f64>::from_description(&bad, &[]).unwrap_err();
    assert!(e.to_string().contains("joints[2].xyz[1]") && e.to_string().contains("l_z"));

    let mut bad = d.clone();
    bad.joints[3].kind = trocar_model::description::JointKind::Revolute { axis: [0.0; 3] };
    assert!(matches!(
        NumericRobot::<f64>::from_description(&bad, &[]).unwrap_err(),
        RobotError::BadAxis { field } if field == "joints[3].axis"
    ));

    let mut bad = d.clone();
    bad.constraint.as_mut().unwrap().h[1] = [2.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    assert!(matches!(
        NumericRobot::<f64>::from_description(&bad, &[]).unwrap_err(),
        RobotError::Constraint(_)
    ));

    // No constraint: kinematics work, constrained quantities are errors.
    let mut free = d.clone();
    free.constraint = None;
    let robot = NumericRobot::<f64>::from_description(&free, &[]).unwrap();
    assert!(robot.body_jacobian(&[0.1; 8]).is_ok());
    assert_eq!(
        robot.constrained_jacobian(&[0.1; 8]).unwrap_err(),
        RobotError::NoConstraint
    );

    // A general H without a wrist preset gets the computed basis.
    let mut general = d.clone();
    let c = general.constraint.as_mut().unwrap();
    c.wrist = None;
    c.h = vec![[0.2, 1.0, 0.0, 0.3, 0.0, 0.0]];
    let robot = NumericRobot::<f64>::from_description(&general, &[]).unwrap();
    let l = robot.lambda().unwrap();
    assert!((l * robot.lambda_null_space().unwrap()).norm_max() < 1e-14);
}

/// `docs/reference-robots.md`: both Jacobians (J^B_0i and J^r) are regular at the start configuration q0.
#[test]
fn dia10_like_start_configuration_is_regular() {
    let q0 = [0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3];
    for name in ["dia10_like_zy", "dia10_like_zx"] {
        let robot =
            NumericRobot::<f64>::from_description(&RobotDescription::preset(name).unwrap(), &[])
                .unwrap();
        let s0i = singular_values(&robot.partial_body_jacobian(&q0).unwrap());
        let sr = singular_values(&robot.constrained_jacobian(&q0).unwrap());
        println!(
            "{name}: σ(J^B_0i) ∈ [{:.3e}, {:.3e}], σ(J^r) ∈ [{:.3e}, {:.3e}], w_r = {:.4e}",
            min(&s0i),
            max(&s0i),
            min(&sr),
            max(&sr),
            robot.manipulability(&q0).unwrap()
        );
        assert!(min(&s0i) > 1e-2 && min(&sr) > 1e-2, "{name}");
    }
}
