//! Four-bar linkage (source §4.1–§4.3): passive velocities (7) and the reduced Jacobian (8)
//! against finite differences of independent position-level solutions.

use faer::{Col, ColRef};
use trocar_sim::closed_chain::ClosedChainError;
use trocar_sim::closed_chain::{description, four_bar::FourBar, Mechanism, SingularityKind};
use trocar_sim::linalg;

fn setup() -> (Mechanism, FourBar) {
    let m = description::shipped("four-bar").unwrap();
    let fb = FourBar::from_mechanism(&m).unwrap();
    (m, fb)
}

/// Fourth-order central difference (error O(h⁴)).
fn d4(f: impl Fn(f64) -> f64, x: f64, h: f64) -> f64 {
    (-f(x + 2.0 * h) + 8.0 * f(x + h) - 8.0 * f(x - h) + f(x - 2.0 * h)) / (12.0 * h)
}

#[test]
fn closed_form_satisfies_the_structural_equations() {
    let (m, fb) = setup();
    assert_eq!(fb, FourBar::SOURCE);
    for i in 0..=20 {
        let t1 = 0.75 + 1.5 * i as f64 / 20.0;
        let th = fb.configuration(t1).unwrap();
        assert!(m.structural(&th).norm_l2() < 1e-12, "θ1 = {t1}");
        // φ = θ1 + θ3 = θ2 + θ4 (10), not only modulo 2π.
        assert!((th[0] + th[1] - th[2] - th[3]).abs() < 1e-12);
        let p = fb.position(t1).unwrap();
        let pose = m.chain_pose(1, &th);
        assert!((pose.x - p[0]).abs() < 1e-12 && (pose.y - p[1]).abs() < 1e-12);
    }
    // The orientation range quoted by the source (φ ∈ [5.88, 7.89] rad) up to the end points.
    let (lo, hi) = fb.workspace();
    assert!((lo - 0.7227).abs() < 1e-3 && (hi - 2.2784).abs() < 1e-3);
    let a = fb.orientation(lo + 1e-9).unwrap();
    let b = fb.orientation(hi - 1e-9).unwrap();
    assert!(
        (a - 7.98).abs() < 0.01 && (b - 5.81).abs() < 0.01,
        "{a} {b}"
    );
}

#[test]
fn passive_velocities_7_equal_finite_differences_of_the_closed_form() {
    let (m, fb) = setup();
    for i in 0..=12 {
        let t1 = 0.8 + 1.4 * i as f64 / 12.0;
        let th = fb.configuration(t1).unwrap();
        let pd = m
            .passive_velocities(&th, &Col::from_fn(1, |_| 1.0))
            .unwrap();
        // θ_p order in the mechanism: (θ3, θ2, θ4).
        let h = 1e-4;
        let fd3 = d4(|x| fb.passive(x).unwrap()[1], t1, h);
        let fd2 = d4(|x| fb.passive(x).unwrap()[0], t1, h);
        let fd4 = d4(|x| fb.passive(x).unwrap()[2], t1, h);
        for (a, b) in [(pd[0], fd3), (pd[1], fd2), (pd[2], fd4)] {
            assert!((a - b).abs() < 1e-8, "θ1 = {t1}: (7) {a} vs FD {b}");
        }
    }
}

#[test]
fn reduced_jacobian_8_equals_finite_differences_through_the_constraint() {
    let (m, fb) = setup();
    for i in 0..=12 {
        let t1 = 0.8 + 1.4 * i as f64 / 12.0;
        let th = fb.configuration(t1).unwrap();
        let j = m.reduced(&th).unwrap().jacobian[(0, 0)];
        // End-effector map through the constraint: Newton on c(θ) = 0 (not the closed form).
        let (_, p0) = m.split(&th);
        let phi = |x: f64| {
            let p = m.solve_passive(&Col::from_fn(1, |_| x), &p0).unwrap();
            m.task(&m.join(&Col::from_fn(1, |_| x), &p))[0]
        };
        let fd = d4(phi, t1, 1e-4);
        assert!((j - fd).abs() < 1e-8, "θ1 = {t1}: J = {j}, FD = {fd}");
        // and against the closed form of φ.
        let fd_closed = d4(|x| fb.orientation(x).unwrap(), t1, 1e-4);
        assert!((j - fd_closed).abs() < 1e-8);
    }
}

#[test]
fn any_annihilator_gives_the_same_reduced_jacobian() {
    let (m, fb) = setup();
    let th = fb.configuration(1.3).unwrap();
    let (j, a) = m.stacked(&th);
    let (jc, ja) = trocar_sim::closed_chain::mechanism::constraint_and_analytic(&j, &a).unwrap();
    // J_A here is the full pose; select φ.
    let ja_phi = ja.subrows(2, 1).to_owned();
    let red = trocar_sim::closed_chain::mechanism::reduce_blocks(
        &jc,
        &ja_phi,
        m.active_indices(),
        m.passive_indices(),
    )
    .unwrap();
    let direct = m.reduced(&th).unwrap();
    assert!((red.jacobian - direct.jacobian).norm_l2() < 1e-12);
    assert!((red.passive_map - direct.passive_map).norm_l2() < 1e-12);
    assert_eq!(jc.shape(), (3, 4));
    assert!((linalg::annihilator(a.as_ref()) * &a).norm_l2() < 1e-12);
}

#[test]
fn singularities_at_the_workspace_ends_and_outside() {
    let (m, fb) = setup();
    let (lo, _) = fb.workspace();
    // At the end of the workspace joints 2, 3, 4 align: J_Cp loses rank (parallel singularity).
    // Build that configuration geometrically: joint 4 on the ray from joint 2 through joint 3.
    let p3 = [-0.5 + 1.2 * lo.cos(), 1.2 * lo.sin()];
    let u = [p3[0] - 0.5, p3[1]];
    let t2 = u[1].atan2(u[0]);
    let th = col(&[
        lo,
        t2 - lo + 2.0 * std::f64::consts::PI,
        t2,
        2.0 * std::f64::consts::PI,
    ]);
    assert!(m.structural(&th).norm_l2() < 1e-9);
    let rep = m.classify(&th).unwrap();
    assert_eq!(rep.rank_j_cp, 2);
    assert!(matches!(
        rep.kind,
        Some(SingularityKind::Parallel) | Some(SingularityKind::Structural)
    ));
    match m.reduced(&th) {
        Err(ClosedChainError::Singular { kind, .. }) => assert_eq!(kind, SingularityKind::Parallel),
        other => panic!("expected a singular J_Cp error, got {other:?}"),
    }
    // A regular configuration.
    let th = fb.configuration(1.3).unwrap();
    assert_eq!(m.classify(&th).unwrap().kind, None);
    assert!(m.svd_analysis(&th).unwrap().full_rank);
    // Outside the workspace: an error, never NaN.
    assert!(fb.passive(0.5).is_err());
    assert!(fb.passive(f64::NAN).is_err());
    let r = m.solve_passive(&Col::from_fn(1, |_| 0.3), &m.split(&th).1);
    assert!(r.is_err(), "{r:?}");
}

#[test]
fn no_serial_singularity_inside_the_workspace() {
    // dφ/dθ1 would vanish where crank and rocker are parallel; for the source's lengths this does
    // not happen between the two parallel singularities: φ decreases monotonically (7.98 → 5.81
    // rad), and every interior configuration is regular with J = dφ/dθ1 < 0.
    let (m, fb) = setup();
    let (lo, hi) = fb.workspace();
    let n = 400;
    for i in 1..n {
        let t1 = lo + (hi - lo) * i as f64 / n as f64;
        let th = fb.configuration(t1).unwrap();
        assert_eq!(m.classify(&th).unwrap().kind, None, "θ1 = {t1}");
        assert!(m.reduced(&th).unwrap().jacobian[(0, 0)] < 0.0);
    }
}

fn col(values: &[f64]) -> Col<f64> {
    ColRef::from_slice(values).to_owned()
}
