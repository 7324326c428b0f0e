//! The generated closed-mechanism modules against independent computations: the runtime's numeric
//! reduced kinematics (7)–(8) (SVD-based, `trocar_sim::closed_chain`), finite differences of the
//! closed-form passive solution of the four-bar linkage and of the closed-form inverse kinematics
//! of the planar Gough–Stewart platform, and the runtime's singularity classification.
// Entries are compared by (row, column) index against faer matrices.
#![allow(clippy::needless_range_loop)]

use faer::{Col, ColRef, Mat, Scale};
use trocar_sim::closed_chain::four_bar::FourBar;
use trocar_sim::closed_chain::{description, stewart, Mechanism, Pose2, SingularityKind};
use trocar_tests_generated::{four_bar, four_bar_f32, planar_stewart};

fn four_bar_mechanism() -> (Mechanism, FourBar) {
    let m = description::shipped("four-bar").unwrap();
    let fb = FourBar::from_mechanism(&m).unwrap();
    (m, fb)
}

/// θ1 over the open workspace, `n` points, `margin` away from its ends.
fn theta1_grid(fb: &FourBar, n: usize, margin: f64) -> Vec<f64> {
    let (lo, hi) = fb.workspace();
    (0..n)
        .map(|i| lo + margin + (hi - lo - 2.0 * margin) * i as f64 / (n - 1) as f64)
        .collect()
}

fn q_of(theta: &Col<f64>) -> [f64; 4] {
    [theta[0], theta[1], theta[2], theta[3]]
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1.0)
}

#[test]
fn four_bar_layout() {
    assert_eq!(four_bar::N, 4);
    assert_eq!(four_bar::N_ACTIVE, 1);
    assert_eq!(four_bar::N_PASSIVE, 3);
    assert_eq!(four_bar::N_OUTPUTS, 1);
    let (m, _) = four_bar_mechanism();
    assert_eq!(four_bar::ACTIVE.as_slice(), m.active_indices());
    assert_eq!(four_bar::PASSIVE.as_slice(), m.passive_indices());
    let p = four_bar::Params::<f64>::nominal();
    assert_eq!(
        [p.l0, p.l1, p.l2, p.l3, p.l4],
        [1.0, 1.2, 1.4, 0.6, 1.4],
        "nominal parameters from the description"
    );
}

/// (a) Generated (8) and (7) equal the runtime's numeric `reduced` / `passive_velocities` on the
/// constraint manifold (passive joints from the closed form), to 1e-12 relative.
#[test]
fn four_bar_matches_runtime_on_the_manifold() {
    let (m, fb) = four_bar_mechanism();
    let p = four_bar::Params::nominal();
    let mut worst = 0.0f64;
    for theta1 in theta1_grid(&fb, 400, 1e-3) {
        let theta = fb.configuration(theta1).unwrap();
        let q = q_of(&theta);
        let red = m.reduced(&theta).unwrap();
        let j = four_bar::reduced_jacobian(&q, &p).unwrap();
        worst = worst.max(rel(j[0][0], red.jacobian[(0, 0)]));
        let t = four_bar::JointTrig::new(&q);
        assert_eq!(four_bar::reduced_jacobian_trig(&t, &p), Some(j));
        let map = four_bar::passive_map(&q, &p).unwrap();
        assert_eq!(four_bar::passive_map_trig(&t, &p), Some(map));
        for qd in [1.0, -0.37, 2.5] {
            let num = m
                .passive_velocities(&theta, &Col::from_fn(1, |_| qd))
                .unwrap();
            let gen = four_bar::passive_velocities(&q, &[qd], &p).unwrap();
            for k in 0..3 {
                worst = worst.max(rel(gen[k], num[k]));
                worst = worst.max(rel(map[0][k] * qd, num[k]));
            }
        }
        // J_C and J_A themselves.
        let d = m.differential(&theta).unwrap();
        let jc = four_bar::constraint_jacobian(&q, &p);
        let ja = four_bar::task_jacobian(&q, &p);
        for c in 0..4 {
            for r in 0..3 {
                worst = worst.max(rel(jc[c][r], d.j_c[(r, c)]));
            }
            worst = worst.max(rel(ja[c][0], d.j_a[(0, c)]));
        }
        let det = four_bar::constraint_determinant(&q, &p);
        worst = worst.max(rel(det, d.j_cp.clone().determinant()));
    }
    assert!(worst <= 1e-12, "worst relative difference {worst:e}");
}

/// Fourth-order central difference `(−f(x+2h) + 8f(x+h) − 8f(x−h) + f(x−2h)) / 12h`.
fn derivative<const K: usize>(f: impl Fn(f64) -> [f64; K], x: f64, h: f64) -> [f64; K] {
    let (a, b, c, d) = (f(x + 2.0 * h), f(x + h), f(x - h), f(x - 2.0 * h));
    core::array::from_fn(|k| (-a[k] + 8.0 * b[k] - 8.0 * c[k] + d[k]) / (12.0 * h))
}

/// (b) The reduced Jacobian is `dφ/dθ1` of the closed-form output map `φ(θ1) = θ1 + θ3(θ1)`, and
/// the passive velocities are the derivatives of the closed-form passive joints (fourth-order
/// central differences, h = 1e-4), to 1e-8.
#[test]
fn four_bar_matches_finite_differences_of_the_closed_form() {
    let (_, fb) = four_bar_mechanism();
    let p = four_bar::Params::nominal();
    let h = 1e-4;
    let mut worst = 0.0f64;
    for theta1 in theta1_grid(&fb, 200, 0.02) {
        let q = q_of(&fb.configuration(theta1).unwrap());
        let j = four_bar::reduced_jacobian(&q, &p).unwrap();
        let [fd] = derivative(|x| [fb.orientation(x).unwrap()], theta1, h);
        worst = worst.max(rel(j[0][0], fd));
        let v = four_bar::passive_velocities(&q, &[1.0], &p).unwrap();
        // PASSIVE order is (θ3, θ2, θ4); `FourBar::passive` returns (θ2, θ3, θ4).
        let fd_p = derivative(
            |x| {
                let [t2, t3, t4] = fb.passive(x).unwrap();
                [t3, t2, t4]
            },
            theta1,
            h,
        );
        for k in 0..3 {
            worst = worst.max(rel(v[k], fd_p[k]));
        }
    }
    assert!(worst <= 1e-8, "worst relative difference {worst:e}");
}

/// (c) The same in `f32`: the generic module at `T = f32` and the monomorphic `f32` module agree
/// with the `f64` runtime to 1e-4 relative (away from the singular ends of the workspace, where
/// `det J_Cp → 0` amplifies rounding).
#[test]
fn four_bar_in_f32() {
    let (m, fb) = four_bar_mechanism();
    let p32 = four_bar::Params::<f32>::nominal();
    let pm = four_bar_f32::Params::nominal();
    let mut worst = 0.0f64;
    for theta1 in theta1_grid(&fb, 200, 0.05) {
        let theta = fb.configuration(theta1).unwrap();
        let q32 = q_of(&theta).map(|x| x as f32);
        let red = m.reduced(&theta).unwrap();
        let a = four_bar::reduced_jacobian(&q32, &p32).unwrap();
        let b = four_bar_f32::reduced_jacobian(&q32, &pm).unwrap();
        worst = worst.max(rel(f64::from(a[0][0]), red.jacobian[(0, 0)]));
        worst = worst.max(rel(f64::from(b[0][0]), red.jacobian[(0, 0)]));
        let v = four_bar_f32::passive_velocities(&q32, &[1.0], &pm).unwrap();
        for k in 0..3 {
            worst = worst.max(rel(f64::from(v[k]), red.passive_map[(k, 0)]));
        }
    }
    assert!(worst <= 1e-4, "worst relative difference {worst:e}");
}

/// `det J_Cp` vanishes exactly where the runtime's `classify` reports a parallel singularity:
/// at the ends of the workspace of θ1 (joints 2, 3, 4 aligned); inside, it keeps one sign and
/// stays away from zero, and `classify` reports a regular configuration.
#[test]
fn four_bar_determinant_vanishes_at_parallel_singularities() {
    let (m, fb) = four_bar_mechanism();
    let p = four_bar::Params::nominal();
    let (lo, hi) = fb.workspace();
    let mut interior_min = f64::INFINITY;
    let mut sign = 0.0f64;
    for theta1 in theta1_grid(&fb, 300, 0.01) {
        let theta = fb.configuration(theta1).unwrap();
        let det = four_bar::constraint_determinant(&q_of(&theta), &p);
        let report = m.classify(&theta).unwrap();
        assert_eq!(report.kind, None, "θ1 = {theta1}");
        if sign == 0.0 {
            sign = det.signum();
        }
        assert_eq!(
            det.signum(),
            sign,
            "det J_Cp changes sign inside, θ1 = {theta1}"
        );
        interior_min = interior_min.min(det.abs());
    }
    assert!(interior_min > 1e-2, "{interior_min}");
    // At the ends joints 2, 3 and 4 are aligned: at θ1 = lo the diagonal is l2 − l3 (joint 3
    // between joints 2 and 4), at θ1 = hi it is l2 + l3 (joint 4 between joints 2 and 3). The
    // configurations built from that geometry, on the branch of the closed form next to them:
    for (end, inside, beyond) in [(lo, lo + 1e-3, true), (hi, hi - 1e-3, false)] {
        let near = fb.configuration(inside).unwrap();
        let j3 = [-fb.l0 / 2.0 + fb.l1 * end.cos(), fb.l1 * end.sin()];
        let u = (j3[1]).atan2(j3[0] - fb.l0 / 2.0); // direction joint 2 → joint 3
        let rocker = u; // joint 2 → joint 4
        let coupler = if beyond { u } else { u + std::f64::consts::PI }; // joint 3 → joint 4
        let unwrap = |a: f64, like: f64| {
            let tau = 2.0 * std::f64::consts::PI;
            a + tau * ((like - a) / tau).round()
        };
        let theta = ColRef::from_slice(&[
            end,
            unwrap(coupler - end, near[1]),
            unwrap(rocker, near[2]),
            unwrap(coupler - rocker, near[3]),
        ])
        .to_owned();
        assert!(
            m.structural(&theta).norm_l2() < 1e-12,
            "θ1 = {end}: {:?}",
            m.structural(&theta)
        );
        let q = q_of(&theta);
        let det = four_bar::constraint_determinant(&q, &p);
        let report = m.classify(&theta).unwrap();
        assert!(
            matches!(
                report.kind,
                Some(SingularityKind::Parallel | SingularityKind::Structural)
            ),
            "classify at θ1 = {end}: {report:?}"
        );
        assert!(
            det.abs() < 1e-4 * interior_min,
            "det J_Cp = {det:e} at θ1 = {end}"
        );
    }
    // Exactly singular (every link along x): det is exactly 0 and the divisions give `None`.
    let zero = [0.0; 4];
    assert_eq!(four_bar::constraint_determinant(&zero, &p), 0.0);
    assert_eq!(four_bar::reduced_jacobian(&zero, &p), None);
    assert_eq!(four_bar::passive_velocities(&zero, &[1.0], &p), None);
    let report = m.classify(&ColRef::from_slice(&zero).to_owned()).unwrap();
    assert!(matches!(
        report.kind,
        Some(SingularityKind::Parallel | SingularityKind::Structural)
    ));
    // Not finite input: `None`, never NaN.
    let nan = [f64::NAN, 5.57, 1.595, 5.175];
    assert_eq!(four_bar::reduced_jacobian(&nan, &p), None);
    assert_eq!(four_bar::passive_map(&nan, &p), None);
    let q = q_of(&fb.configuration(1.2).unwrap());
    assert_eq!(four_bar::passive_velocities(&q, &[f64::INFINITY], &p), None);
}

/// Parameters are runtime inputs: other link lengths give the runtime's values for the
/// mechanism described with those lengths.
#[test]
fn four_bar_parameters_are_runtime_inputs() {
    let text = description::FOUR_BAR_TOML
        .replace("l1 = 1.2", "l1 = 1.1")
        .replace("l4 = 1.4", "l4 = 0.9");
    let m = description::from_toml_str(&text).unwrap();
    let fb = FourBar::from_mechanism(&m).unwrap();
    let p = four_bar::Params {
        l1: 1.1,
        l4: 0.9,
        ..four_bar::Params::nominal()
    };
    for theta1 in theta1_grid(&fb, 50, 0.01) {
        let theta = fb.configuration(theta1).unwrap();
        let red = m.reduced(&theta).unwrap();
        let j = four_bar::reduced_jacobian(&q_of(&theta), &p).unwrap();
        assert!(rel(j[0][0], red.jacobian[(0, 0)]) <= 1e-12);
        let v = four_bar::passive_map(&q_of(&theta), &p).unwrap();
        for k in 0..3 {
            assert!(rel(v[0][k], red.passive_map[(k, 0)]) <= 1e-12);
        }
    }
}

fn stewart_poses() -> Vec<Pose2> {
    let mut v = Vec::new();
    for i in 0..5 {
        for j in 0..5 {
            for k in 0..3 {
                v.push(Pose2::new(
                    10.5 + 1.8 * i as f64,
                    11.5 + 1.3 * j as f64,
                    -0.3 + 0.3 * k as f64,
                ));
            }
        }
    }
    v
}

fn to_array<const N: usize>(v: &Col<f64>) -> [f64; N] {
    core::array::from_fn(|k| v[k])
}

/// Planar Gough–Stewart platform: generated (8) and (7) equal the runtime's at configurations
/// from the closed-form inverse kinematics, to 1e-12 relative; `J` is the inverse of the
/// derivative of the inverse kinematics (central differences of leg lengths over the pose), to
/// 1e-8.
#[test]
fn planar_stewart_matches_runtime_and_inverse_kinematics() {
    let m = description::shipped("planar-stewart").unwrap();
    let p = planar_stewart::Params::nominal();
    assert_eq!(planar_stewart::ACTIVE.as_slice(), m.active_indices());
    let (mut worst, mut worst_fd) = (0.0f64, 0.0f64);
    let h = 1e-5;
    for pose in stewart_poses() {
        let theta = stewart::inverse_kinematics(&m, pose).unwrap();
        let q: [f64; 9] = to_array(&theta);
        let red = m.reduced(&theta).unwrap();
        let j = planar_stewart::reduced_jacobian(&q, &p).unwrap();
        let map = planar_stewart::passive_map(&q, &p).unwrap();
        let scale_j = red.jacobian.norm_max().max(1.0);
        let scale_p = red.passive_map.norm_max().max(1.0);
        for c in 0..3 {
            for r in 0..3 {
                worst = worst.max((j[c][r] - red.jacobian[(r, c)]).abs() / scale_j);
            }
            for r in 0..6 {
                worst = worst.max((map[c][r] - red.passive_map[(r, c)]).abs() / scale_p);
            }
        }
        // ∂d/∂pose by central differences of the inverse kinematics; J · ∂d/∂pose = I.
        let active = |pose: Pose2| -> Col<f64> {
            let t = stewart::inverse_kinematics(&m, pose).unwrap();
            m.split(&t).0
        };
        let mut dd = Mat::<f64>::zeros(3, 3);
        for axis in 0..3 {
            let mut a = pose;
            let mut b = pose;
            match axis {
                0 => {
                    a.x += h;
                    b.x -= h;
                }
                1 => {
                    a.y += h;
                    b.y -= h;
                }
                _ => {
                    a.angle += h;
                    b.angle -= h;
                }
            }
            let col = Scale(1.0 / (2.0 * h)) * (active(a) - active(b));
            dd.col_mut(axis).copy_from(&col);
        }
        let jm = Mat::from_fn(3, 3, |r, c| j[c][r]);
        let prod = &jm * &dd;
        worst_fd = worst_fd.max((prod - Mat::<f64>::identity(3, 3)).norm_max());
    }
    assert!(worst <= 1e-12, "worst relative difference {worst:e}");
    assert!(worst_fd <= 1e-8, "worst |J ∂d/∂pose − I| {worst_fd:e}");
}

/// The symbolic J_C and J_A of the four-bar linkage equal the numeric reference's.
#[test]
fn four_bar_matches_runtime_differential() {
    use trocar_codegen::symbolic::Env;
    use trocar_model::closed_chain::MechanismModel;
    let model = MechanismModel::shipped("four-bar").unwrap();
    let d = trocar_codegen::closed_chain::derive(&model).unwrap();
    let q = [1.1, 5.3, 1.7, 4.9];
    let num = Mechanism::nominal(&model)
        .unwrap()
        .differential(&ColRef::from_slice(&q).to_owned())
        .unwrap();
    let env = Env {
        q: &q,
        params: &d.param_values,
    };
    let jc = d.j_c.eval(&env);
    let ja = d.j_a.eval(&env);
    for (i, row) in jc.iter().enumerate() {
        for (j, x) in row.iter().enumerate() {
            assert!((x - num.j_c[(i, j)]).abs() < 1e-13, "J_C[{i}][{j}]");
        }
    }
    for (j, x) in ja[0].iter().enumerate() {
        assert!((x - num.j_a[(0, j)]).abs() < 1e-13);
    }
    let det = d.det_j_cp.eval(&env);
    assert!((det - trocar_sim::linalg::determinant(num.j_cp.as_ref())).abs() < 1e-12);
}
