//! The distance between two Pandas' instruments inside the body, each through its own port, as
//! a function of the 14 joints: the row of `trocar::distance::SegmentDistance::rate_row` (the
//! tips' point-velocity Jacobians from the arms' body Jacobians, the ports fixed) against central
//! differences of the distance computed from forward kinematics alone; and the velocity damper of
//! the joint limits (`HardLimits`'s `Damper`) as the coupling's bound `ḋ ≥ −ξ (d − d_s)/(d_i − d_s)`.

use nalgebra::{SMatrix, SVector, Vector3};
use proptest::prelude::*;
use trocar::distance::segment_distance;
use trocar::kinematics::Chain;
use trocar::se3::Se3;
use trocar_model::description::RobotDescription;
use trocar_model::numeric::NumericModel;

/// The instrument's tip is the description's end effector; the ports are on the shafts 0.25 m
/// above the tips at `Q0`.
const Q0: [f64; 7] = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785];

struct Arm {
    chain: Chain<f64, 7>,
    base: Se3<f64>,
    port: Vector3<f64>,
}

impl Arm {
    fn new(base: Se3<f64>) -> Self {
        let d = RobotDescription::preset("panda-laparoscope").unwrap();
        let chain = NumericModel::<f64>::from_description(&d, &[])
            .unwrap()
            .to_chain::<7>()
            .unwrap();
        let g = base * chain.forward_kinematics(&SVector::from(Q0));
        let port = g.translation - g.rotation.column(2) * 0.25;
        Arm { chain, base, port }
    }

    fn tip(&self, q: &SVector<f64, 7>) -> Vector3<f64> {
        (self.base * self.chain.forward_kinematics(q)).translation
    }

    /// `ṗ_tip = R_0b R_be v_b`: the linear rows of the body Jacobian, in the world frame.
    fn tip_jacobian(&self, q: &SVector<f64, 7>) -> SMatrix<f64, 3, 7> {
        let g = self.base * self.chain.forward_kinematics(q);
        let jb = self.chain.body_jacobian(q);
        g.rotation * jb.fixed_rows::<3>(0)
    }
}

fn arms() -> (Arm, Arm) {
    // Two arms facing each other 1 m apart, both reaching toward the middle.
    let a = Arm::new(Se3::identity());
    let turn = nalgebra::Matrix3::new(-1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 1.0);
    let b = Arm::new(Se3::new(turn, Vector3::new(1.0, 0.05, 0.0)));
    (a, b)
}

fn distance(a: &Arm, b: &Arm, q: &SVector<f64, 14>) -> f64 {
    let qa = q.fixed_rows::<7>(0).into_owned();
    let qb = q.fixed_rows::<7>(7).into_owned();
    segment_distance(&a.port, &a.tip(&qa), &b.port, &b.tip(&qb)).distance
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, failure_persistence: None, ..ProptestConfig::default() })]

    /// The row of the 14 joint rates is the derivative of the distance along any joint motion.
    #[test]
    fn the_row_is_the_derivative_of_the_distance_through_both_arms(
        dq in prop::array::uniform14(-0.6f64..0.6),
        qd in prop::array::uniform14(-1.0f64..1.0),
    ) {
        let (a, b) = arms();
        let q = SVector::<f64, 14>::from_fn(|k, _| Q0[k % 7] + dq[k]);
        let qd = SVector::<f64, 14>::from(qd);
        let (qa, qb) = (q.fixed_rows::<7>(0).into_owned(), q.fixed_rows::<7>(7).into_owned());
        let d = segment_distance(&a.port, &a.tip(&qa), &b.port, &b.tip(&qb));
        prop_assume!(d.distance > 1e-3 && d.normal.is_some());
        // The endpoints' Jacobians over the 14 joints: the ports fixed, each tip its arm's.
        let zero = SMatrix::<f64, 3, 14>::zeros();
        let mut ja = zero;
        ja.fixed_columns_mut::<7>(0).copy_from(&a.tip_jacobian(&qa));
        let mut jb = zero;
        jb.fixed_columns_mut::<7>(7).copy_from(&b.tip_jacobian(&qb));
        let rows = d.rate_row(&[zero, ja, zero, jb]).unwrap();
        let rate = rows[..d.count].iter().map(|r| (r * qd)[0]).fold(f64::INFINITY, f64::min);
        let h = 1e-6;
        let fd = (distance(&a, &b, &(q + qd * h)) - distance(&a, &b, &(q - qd * h))) / (2.0 * h);
        prop_assert!((rate - fd).abs() <= 1e-6 * (1.0 + 1e-3 / d.distance), "{rate} vs {fd} at d = {}", d.distance);
    }
}

/// The coupling's bound is the joint limits' damper with the distance's range `[0, ∞)`: no
/// bound beyond the influence distance, `−ξ (d − d_s)/(d_i − d_s)` within it, 0 at the safety
/// distance and closer.
#[test]
fn the_coupling_bound_is_the_velocity_damper() {
    let damper = trocar::control::Damper {
        influence: 0.02,
        safety: 0.005,
        gain: 0.1,
    };
    let big = 1e6;
    let lower = |d: f64| damper.rate_bounds(d, 0.0, f64::INFINITY, big).0;
    assert_eq!(lower(0.03), -big);
    assert!((lower(0.0125) + 0.1 * 0.0075 / 0.015).abs() < 1e-15);
    assert_eq!(lower(0.005), 0.0);
    assert_eq!(lower(0.001), 0.0);
}
