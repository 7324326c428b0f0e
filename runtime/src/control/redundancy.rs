//! Redundancy resolution of Freitas, Leite & Lizarralde (CBA 2010), (44)–(46), on the joints
//! before the constraint: `θ̇_{1..i} = J†(V^B_0i) + (I − J†J) u0` with `J = J^B_0i` and
//! `u0 = K ∂f/∂θ` the gradient of an objective `f` to increase.
//!
//! With the damped inverse `J†_κ = Jᵀ(JJᵀ + κ²I)⁻¹` the step computes
//! `θ̇ = u0 + J†_κ (V − J u0)`, which is (44)–(45) exactly when `κ = 0` and needs one solve.
//! The arm of a 7-DOF robot holding an instrument through a trocar by its last link has one such
//! spare freedom (`J^B_0i` is 6 × 7).
//!
//! Objectives (46):
//! - joint-limit distance `f = −(1/2i) Σ_k ((θ_k − θ̄_k)/(θ_Mk − θ_mk))²`, with `θ̄` the middle
//!   of the range: `∂f/∂θ_k = −(1/i)(θ_k − θ̄_k)/(θ_Mk − θ_mk)²`;
//! - manipulability `f = w = sqrt(det(J Jᵀ))` of `J^B_0i`, whose gradient comes from the
//!   Jacobian itself ([`manipulability_gradient`]).

use crate::linalg::{damped_solve, Cholesky};
use crate::se3::Twist;
use nalgebra::{RealField, SMatrix, SVector, Vector3};

/// The objective whose gradient drives the spare freedom of the joints before the constraint
/// (46): `u0 = gain · ∂f/∂θ`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NullSpaceObjective<T: RealField + Copy, const N: usize> {
    /// No secondary motion: `u0 = 0` (the minimum-norm joint rates).
    None,
    /// Keep the joints away from their limits: `f = −(1/2i) Σ ((θ_k − θ̄_k)/(θ_Mk − θ_mk))²`
    /// over the joints `1..=i`; joints whose range is not positive are left out.
    JointLimits {
        /// `K` of (46) (1/s).
        gain: T,
        /// Lower limits `θ_m` of all `N` joints.
        lower: SVector<T, N>,
        /// Upper limits `θ_M` of all `N` joints.
        upper: SVector<T, N>,
    },
    /// Increase the manipulability `w` of `J^B_0i`, away from the arm's singularities.
    Manipulability {
        /// `K` of (46).
        gain: T,
    },
}

impl<T: RealField + Copy, const N: usize> NullSpaceObjective<T, N> {
    /// `u0 = K ∂f/∂θ_{1..i}` at joints `q` (the first `I` entries are used) with `J^B_0i = jb0i`.
    pub fn gradient<const I: usize>(
        &self,
        q: &SVector<T, N>,
        jb0i: &SMatrix<T, 6, I>,
    ) -> SVector<T, I> {
        match *self {
            NullSpaceObjective::None => SVector::zeros(),
            NullSpaceObjective::JointLimits { gain, lower, upper } => {
                let n = T::from_usize(I).unwrap_or_else(T::one);
                let two = T::one() + T::one();
                SVector::from_fn(|k, _| {
                    let range = upper[k] - lower[k];
                    if range > T::zero() && range.is_finite() {
                        let mid = (upper[k] + lower[k]) / two;
                        -gain * (q[k] - mid) / (range * range * n)
                    } else {
                        T::zero()
                    }
                })
            }
            NullSpaceObjective::Manipulability { gain } => {
                manipulability_gradient(jb0i).map_or(SVector::zeros(), |g| g * gain)
            }
        }
    }
}

/// The Lie bracket `[a, b] = ad_a b = (ω_a × v_b − ω_b × v_a, ω_a × ω_b)` of twists `(v, ω)`.
pub fn lie_bracket<T: RealField + Copy>(a: &Twist<T>, b: &Twist<T>) -> Twist<T> {
    let (va, wa) = (
        Vector3::new(a[0], a[1], a[2]),
        Vector3::new(a[3], a[4], a[5]),
    );
    let (vb, wb) = (
        Vector3::new(b[0], b[1], b[2]),
        Vector3::new(b[3], b[4], b[5]),
    );
    let v = wa.cross(&vb) - wb.cross(&va);
    let w = wa.cross(&wb);
    Twist::new(v.x, v.y, v.z, w.x, w.y, w.z)
}

/// `∂w/∂θ_k` of the manipulability `w = sqrt(det(J Jᵀ))` of a body Jacobian `J` (6 × C, C ≥ 6),
/// from `J` alone.
///
/// The columns of a body Jacobian satisfy `∂J_j/∂θ_k = [J_j, J_k]` for `j < k` and `0` for
/// `j ≥ k` (each column is `Ad⁻¹` of the transform after its joint), and
/// `∂w/∂θ_k = w tr(J† ∂J/∂θ_k)` with `J† = Jᵀ(JJᵀ)⁻¹`. `None` if `J Jᵀ` is singular.
pub fn manipulability_gradient<T: RealField + Copy, const C: usize>(
    j: &SMatrix<T, 6, C>,
) -> Option<SVector<T, C>> {
    let chol = Cholesky::new(&(j * j.transpose()))?;
    // A = (JJᵀ)⁻¹ J: row j of J† is column j of A.
    let a = chol.solve(j);
    let w = chol.sqrt_determinant();
    let g = SVector::<T, C>::from_fn(|k, _| {
        let jk: Twist<T> = j.column(k).into_owned();
        let mut tr = T::zero();
        for c in 0..k {
            let jc: Twist<T> = j.column(c).into_owned();
            tr += a.column(c).dot(&lie_bracket(&jc, &jk));
        }
        w * tr
    });
    g.iter().all(|x| x.is_finite()).then_some(g)
}

/// `θ̇ = u0 + J†_κ (v − J u0)` ((44)–(45) with the damped inverse of (3.46)): the joint rates
/// that give the twist `v` (least squares when damped) plus the part of `u0` that `J` does not
/// see. `None` if the Gram matrix is singular.
pub fn resolve_with_null_space<T: RealField + Copy, const C: usize>(
    j: &SMatrix<T, 6, C>,
    kappa: T,
    v: &SVector<T, 6>,
    u0: &SVector<T, C>,
) -> Option<SVector<T, C>> {
    let x = damped_solve(j, kappa, &(v - j * u0))?;
    Some(x + u0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::{Chain, Joint};
    use crate::manipulability::manipulability;
    use crate::se3::{rotation_from_rpy, Se3};

    /// A Panda-like 7-joint arm (Franka's joint origins, rpy of ±π/2).
    fn arm() -> Chain<f64, 7> {
        const H: f64 = core::f64::consts::FRAC_PI_2;
        let axes = [
            (Vector3::z(), [0.0, 0.0, 0.333], [0.0, 0.0, 0.0]),
            (Vector3::z(), [0.0, 0.0, 0.0], [-H, 0.0, 0.0]),
            (Vector3::z(), [0.0, -0.316, 0.0], [H, 0.0, 0.0]),
            (Vector3::z(), [0.0825, 0.0, 0.0], [H, 0.0, 0.0]),
            (Vector3::z(), [-0.0825, 0.384, 0.0], [-H, 0.0, 0.0]),
            (Vector3::z(), [0.0, 0.0, 0.0], [H, 0.0, 0.0]),
            (Vector3::z(), [0.088, 0.0, 0.0], [H, 0.0, 0.0]),
        ];
        let joints = axes.map(|(a, xyz, rpy)| {
            Joint::revolute(
                Se3::new(
                    rotation_from_rpy(rpy[0], rpy[1], rpy[2]),
                    Vector3::new(xyz[0], xyz[1], xyz[2]),
                ),
                a,
            )
        });
        Chain::new(joints, Se3::from_translation(Vector3::new(0.0, 0.0, 0.107)))
    }

    #[test]
    fn manipulability_gradient_matches_central_differences() {
        let chain = arm();
        for q in [
            [0.1, -0.7, 0.2, -2.3, 0.3, 1.5, 0.8],
            [-0.4, 0.3, -0.9, -1.2, 1.1, 2.2, -0.5],
        ] {
            let q = SVector::<f64, 7>::from(q);
            let j = chain.body_jacobian(&q);
            let g = manipulability_gradient(&j).unwrap();
            let h = 1e-6;
            for k in 0..7 {
                let mut a = q;
                let mut b = q;
                a[k] += h;
                b[k] -= h;
                let fd = (manipulability(&chain.body_jacobian(&a))
                    - manipulability(&chain.body_jacobian(&b)))
                    / (2.0 * h);
                assert!((g[k] - fd).abs() < 1e-8, "joint {k}: {} vs {fd}", g[k]);
            }
        }
    }

    #[test]
    fn joint_limit_gradient_points_to_the_middle() {
        let obj = NullSpaceObjective::<f64, 3>::JointLimits {
            gain: 2.0,
            lower: SVector::from([-1.0, 0.0, 1.0]),
            upper: SVector::from([1.0, 2.0, 1.0]),
        };
        let g = obj.gradient::<3>(&SVector::from([0.5, 0.5, 1.0]), &SMatrix::zeros());
        // −K (θ − θ̄)/(range² i): (−2·0.5/(4·3), −2·(−0.5)/(4·3), 0 for an empty range).
        assert!((g[0] + 1.0 / 12.0).abs() < 1e-15 && (g[1] - 1.0 / 12.0).abs() < 1e-15);
        assert_eq!(g[2], 0.0);
    }

    #[test]
    fn null_space_motion_keeps_the_twist() {
        let chain = arm();
        let q = SVector::<f64, 7>::from([0.1, -0.7, 0.2, -2.3, 0.3, 1.5, 0.8]);
        let j = chain.body_jacobian(&q);
        let v = SVector::<f64, 6>::new(0.01, -0.02, 0.03, 0.1, 0.0, -0.2);
        let u0 = SVector::<f64, 7>::from([0.3, -0.1, 0.2, 0.0, 0.5, -0.4, 0.1]);
        let qd = resolve_with_null_space(&j, 0.0, &v, &u0).unwrap();
        assert!((j * qd - v).norm() < 1e-12);
        let plain = resolve_with_null_space(&j, 0.0, &v, &SVector::zeros()).unwrap();
        // The difference is u0's component in null(J): orthogonal to the row space.
        let d = qd - plain;
        assert!((j * d).norm() < 1e-12 && d.norm() > 1e-3);
    }
}
