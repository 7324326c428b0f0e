//! Planar Gough–Stewart platform (source §4.4): forward kinematics by Newton's method on the
//! structural equations, the reduced Jacobian (8) and passive velocities (7) against finite
//! differences of that map, and parallel singularities detected by the rank of J_Cp.

use faer::{Col, ColRef, Scale};
use trocar_sim::closed_chain::{
    description, stewart, ClosedChainError, Mechanism, Pose2, SingularityKind,
};

fn mech() -> Mechanism {
    description::shipped("planar-stewart").unwrap()
}

const POSES: [(f64, f64, f64); 5] = [
    (14.0, 14.0, 0.0),
    (12.0, 15.5, 0.3),
    (16.5, 12.0, -0.25),
    (13.0, 12.5, -0.5),
    (15.0, 16.0, 0.1),
];

#[test]
fn layout_and_partition() {
    let m = mech();
    assert_eq!(m.n_joints(), 9);
    assert_eq!(m.n_constraints(), 6);
    assert_eq!(m.effective_dof(), 3); // Grübler (22)
    let names = m.joint_names();
    let act: Vec<&str> = m.active_indices().iter().map(|&i| names[i]).collect();
    assert_eq!(act, ["d2", "d5", "d8"]);
    let th = stewart::inverse_kinematics(&m, Pose2::new(14.0, 14.0, 0.0)).unwrap();
    let d = m.differential(&th).unwrap();
    assert_eq!(d.j_c.shape(), (6, 9)); // J_C ∈ R^{6×9} (31)
    assert_eq!(d.j_a.shape(), (3, 9)); // J_A ∈ R^{3×9} (31)
    assert_eq!(d.j.shape(), (9, 9)); // blockdiag(S J1, S J2, S J3) (29)
}

#[test]
fn newton_forward_kinematics_recovers_the_pose() {
    let m = mech();
    for &(x, y, phi) in &POSES {
        let th = stewart::inverse_kinematics(&m, Pose2::new(x, y, phi)).unwrap();
        assert!(m.structural(&th).norm_l2() < 1e-12);
        let (d, _) = m.split(&th);
        // Start Newton from a pose 0.5 m / 0.1 rad away.
        let (pose, th2) =
            stewart::forward_kinematics(&m, &d, Pose2::new(x + 0.5, y - 0.4, phi + 0.1)).unwrap();
        assert!((pose.x - x).abs() < 1e-10 && (pose.y - y).abs() < 1e-10);
        assert!((pose.angle - phi).abs() < 1e-10);
        assert!(m.structural(&th2).norm_l2() < 1e-12);
    }
}

fn d4(f: impl Fn(f64) -> Col<f64>, h: f64) -> Col<f64> {
    Scale(1.0 / (12.0 * h)) * (-f(2.0 * h) + Scale(8.0) * f(h) - Scale(8.0) * f(-h) + f(-2.0 * h))
}

#[test]
fn reduced_jacobian_and_passive_velocities_equal_finite_differences() {
    let m = mech();
    for &(x, y, phi) in &POSES {
        let th = stewart::inverse_kinematics(&m, Pose2::new(x, y, phi)).unwrap();
        let red = m.reduced(&th).unwrap();
        let (d0, p0) = m.split(&th);
        for k in 0..3 {
            let fk = |s: f64| {
                let mut d = d0.clone();
                d[k] += s;
                let p = m.solve_passive(&d, &p0).unwrap();
                let th = m.join(&d, &p);
                let x = m.task(&th);
                Col::from_fn(9, |i| if i < 3 { x[i] } else { p[i - 3] })
            };
            let fd = d4(fk, 1e-3);
            for r in 0..3 {
                let e = (red.jacobian[(r, k)] - fd[r]).abs();
                assert!(e < 1e-8, "J[{r},{k}] {} vs {}", red.jacobian[(r, k)], fd[r]);
            }
            for r in 0..6 {
                let e = (red.passive_map[(r, k)] - fd[3 + r]).abs();
                assert!(e < 1e-8, "θ̇_p[{r}] per d[{k}]: {e}");
            }
        }
        assert_eq!(m.classify(&th).unwrap().kind, None);
        let svd = m.svd_analysis(&th).unwrap();
        assert!(svd.full_rank && svd.null_space.ncols() == 0);
    }
}

/// Fermat point of the base triangle (Weiszfeld's iteration): the three base joints are seen
/// from it 120° apart, so with the spokes pointing at them all three legs are radial.
fn fermat(p: &[[f64; 2]; 3]) -> [f64; 2] {
    let mut c = [
        (p[0][0] + p[1][0] + p[2][0]) / 3.0,
        (p[0][1] + p[1][1] + p[2][1]) / 3.0,
    ];
    for _ in 0..2000 {
        let (mut sx, mut sy, mut sw) = (0.0, 0.0, 0.0);
        for q in p {
            let d = ((q[0] - c[0]).powi(2) + (q[1] - c[1]).powi(2)).sqrt();
            sx += q[0] / d;
            sy += q[1] / d;
            sw += 1.0 / d;
        }
        c = [sx / sw, sy / sw];
    }
    c
}

#[test]
fn concurrent_legs_are_a_parallel_singularity_and_an_error() {
    let m = mech();
    let b: Vec<[f64; 2]> = m.chains.iter().map(|c| [c.base.x, c.base.y]).collect();
    let c = fermat(&[b[0], b[1], b[2]]);
    // Spoke 1 points from the centre to attachment 1 at angle φ + π: aim it at base joint 1.
    let beta = (b[0][1] - c[1]).atan2(b[0][0] - c[0]);
    let pose = Pose2::new(c[0], c[1], beta - std::f64::consts::PI);
    let th = stewart::inverse_kinematics(&m, pose).unwrap();
    assert!(m.structural(&th).norm_l2() < 1e-12);
    let rep = m.classify(&th).unwrap();
    assert!(rep.rank_j_cp < 6, "σ_min(J_Cp) = {}", rep.sigma_min_j_cp);
    assert!(matches!(
        rep.kind,
        Some(SingularityKind::Parallel) | Some(SingularityKind::Structural)
    ));
    match m.reduced(&th) {
        Err(ClosedChainError::Singular {
            kind: SingularityKind::Parallel,
            sigma_min,
            ..
        }) => {
            assert!(sigma_min.is_finite() && sigma_min < 1e-9)
        }
        other => panic!("expected a parallel singularity, got {other:?}"),
    }
    assert!(m
        .passive_velocities(&th, &Col::from_fn(3, |_| 1.0))
        .is_err());
    // A regular pose nearby is fine and its Jacobian finite.
    let th = stewart::inverse_kinematics(&m, Pose2::new(c[0], c[1], beta - 2.5)).unwrap();
    let red = m.reduced(&th).unwrap();
    assert!(trocar_sim::linalg::all_finite(red.jacobian.as_ref()));
}

#[test]
fn bad_inputs_are_errors_not_nan() {
    let m = mech();
    assert!(stewart::inverse_kinematics(&m, Pose2::new(f64::NAN, 0.0, 0.0)).is_err());
    let th = stewart::inverse_kinematics(&m, Pose2::new(14.0, 14.0, 0.0)).unwrap();
    let mut bad = th.clone();
    bad[1] = f64::INFINITY;
    assert!(matches!(
        m.reduced(&bad),
        Err(ClosedChainError::NonFinite { .. })
    ));
    assert!(matches!(
        m.reduced(&Col::zeros(4)),
        Err(ClosedChainError::Dimension {
            expected: 9,
            got: 4,
            ..
        })
    ));
    // Leg lengths the platform cannot reach: Newton fails with an error.
    let (_, p0) = m.split(&th);
    let r = m.solve_passive(&col(&[1.0, 1.0, 1.0]), &p0);
    assert!(r.is_err(), "{r:?}");
}

fn col(values: &[f64]) -> Col<f64> {
    ColRef::from_slice(values).to_owned()
}
