//! The generated closed forms driving the controller: [`trocar::control::ConstrainedKinematics`]
//! for `dia10_like_zy` and `dia10_like_zx` (`N = 8`, `I = 6`, `R = 2`, `K = 4`, `M = 6`).
//!
//! One [`ConstrainedKinematics::evaluate`] computes the joints' sines and cosines once
//! (`JointTrig::new`) and feeds every `_trig` function from them: `g_0e`, `g_0i`, `J^r_0e`,
//! `J^B_0i`, `J_c`. The generated code does not emit `Λ#` and `Λ†`; for the thesis's
//! bidirectional constraint (`H = (x_r, z_r)`, `g_ir = (I, (0, l_a, 0))`) they are closed forms
//! in `l_a`, written out here: `Λ#` is (3.27), and `Λ = H Ad_{g_ri}` has the orthogonal rows
//! `(1, 0, 0, 0, 0, −l_a)` and `(0, 0, 1, l_a, 0, 0)`, so `Λ† = Λᵀ / (1 + l_a²)`.
//! No allocation, no `std`.

use trocar::control::{trocar_offset, ConstrainedKinematics, ConstrainedState, ControlError};
use trocar::nalgebra::{ArrayStorage, Matrix3, RealField, SMatrix, SVector, Vector3};
use trocar::se3::Se3;
use trocar::Real;

/// `Λ#` (3.27) at `l_a`, from the runtime's [`trocar::constraint::thesis_null_space`].
fn lambda_sharp_bidirectional<T: RealField + Copy>(l_a: T) -> SMatrix<T, 6, 4> {
    let mut columns = [trocar::se3::Twist::<T>::zeros(); 4];
    trocar::constraint::thesis_null_space(l_a, &mut columns);
    SMatrix::from_columns(&columns)
}

/// `Λ† = Λᵀ (Λ Λᵀ)⁻¹ = Λᵀ / (1 + l_a²)` for `H = (x_r, z_r)`, `g_ir = (I, (0, l_a, 0))`.
fn lambda_pinv_bidirectional<T: RealField + Copy>(l_a: T) -> SMatrix<T, 6, 2> {
    let z = T::zero();
    let s = T::one() / (T::one() + l_a * l_a);
    SMatrix::from_data(ArrayStorage([
        [s, z, z, z, z, -l_a * s],
        [z, z, s, l_a * s, z, z],
    ]))
}

/// `H = (x_r, z_r)` (3.25).
fn h_bidirectional<T: RealField + Copy>() -> SMatrix<T, 2, 6> {
    let mut h = SMatrix::<T, 2, 6>::zeros();
    h[(0, 0)] = T::one();
    h[(1, 2)] = T::one();
    h
}

/// A pose from the generated `(R column-major, p)`.
fn se3<T: RealField + Copy>((r, p): ([[T; 3]; 3], [T; 3])) -> Se3<T> {
    Se3 {
        rotation: Matrix3::from_data(ArrayStorage(r)),
        translation: Vector3::from_data(ArrayStorage([p])),
    }
}

macro_rules! generated_kinematics {
    ($(#[$doc:meta])* $name:ident, $m:ident) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct $name<T: Real> {
            /// The robot's parameters; `l_a` is overwritten at every evaluation.
            pub params: crate::$m::Params<T>,
        }

        impl<T: Real> $name<T> {
            /// The nominal parameters of the description.
            pub fn nominal() -> Self {
                Self {
                    params: crate::$m::Params::nominal(),
                }
            }
        }

        impl<T: Real + RealField + Copy> ConstrainedKinematics<T, 8, 6, 2, 4, 6> for $name<T> {
            #[inline]
            fn g_0i(&self, q: &SVector<T, 8>) -> Se3<T> {
                se3(crate::$m::forward_kinematics_i(&q.data.0[0], &self.params))
            }

            #[inline]
            fn h(&self) -> SMatrix<T, 2, 6> {
                h_bidirectional()
            }

            #[inline]
            fn evaluate(
                &self,
                q: &SVector<T, 8>,
                l_a: T,
            ) -> Result<ConstrainedState<T, 6, 2, 4, 6>, ControlError> {
                let t = crate::$m::JointTrig::new(&q.data.0[0]);
                let g_0i = se3(crate::$m::forward_kinematics_i_trig(&t, &self.params));
                self.evaluate_trig(&t, g_0i, l_a)
            }

            /// One `JointTrig` for `g_0i`, `l_a` and everything else.
            #[inline]
            fn evaluate_at_trocar(
                &self,
                q: &SVector<T, 8>,
                trocar: &Vector3<T>,
            ) -> Result<(T, ConstrainedState<T, 6, 2, 4, 6>), ControlError> {
                let t = crate::$m::JointTrig::new(&q.data.0[0]);
                let g_0i = se3(crate::$m::forward_kinematics_i_trig(&t, &self.params));
                let l_a = trocar_offset(&g_0i, trocar);
                Ok((l_a, self.evaluate_trig(&t, g_0i, l_a)?))
            }
        }

        impl<T: Real + RealField + Copy> $name<T> {
            /// [`ConstrainedKinematics::evaluate`] from the joints' sines and cosines and `g_0i`
            /// (which does not depend on `l_a`).
            #[inline]
            fn evaluate_trig(
                &self,
                t: &crate::$m::JointTrig<T>,
                g_0i: Se3<T>,
                l_a: T,
            ) -> Result<ConstrainedState<T, 6, 2, 4, 6>, ControlError> {
                if l_a == T::zero() || !l_a.is_finite() {
                    return Err(ControlError::Kinematics);
                }
                let mut p = self.params;
                p.l_a = l_a;
                Ok(ConstrainedState {
                    g_0e: se3(crate::$m::forward_kinematics_trig(t, &p)),
                    g_0i,
                    jr: SMatrix::from_data(ArrayStorage(crate::$m::constrained_jacobian_trig(
                        t, &p,
                    ))),
                    jb0i: SMatrix::from_data(ArrayStorage(
                        crate::$m::partial_body_jacobian_trig(t, &p),
                    )),
                    jc: SMatrix::from_data(ArrayStorage(crate::$m::constraint_jacobian_c_trig(
                        t, &p,
                    ))),
                    lambda_sharp: lambda_sharp_bidirectional(l_a),
                    lambda_pinv: lambda_pinv_bidirectional(l_a),
                })
            }
        }
    };
}

generated_kinematics!(
    /// `dia10_like_zy` (zy wrist) through its generated closed forms.
    Dia10LikeZy,
    dia10_like_zy
);
generated_kinematics!(
    /// `dia10_like_zx` (zx wrist) through its generated closed forms.
    Dia10LikeZx,
    dia10_like_zx
);

/// The generated kinematics of the reference arm the thesis's scenarios use (`dia10_like_zy`).
pub type GeneratedKinematics<T> = Dia10LikeZy<T>;
