//! Inverses of the Jacobians: pseudo-inverse, damped least squares with variable damping
//! (3.43)–(3.46), and the filtered inverse (3.47)–(3.50).
//!
//! Everything works on fixed-size `nalgebra` matrices of any shape and allocates nothing: the
//! linear systems are the Gram matrices `J Jᵀ + κ² I` (or `Jᵀ J + κ² I` when `J` has more rows
//! than columns), solved by Cholesky; a square `J` without damping is solved by its LU factors
//! (the factorisations, the pseudo-inverse and the damped solve are [`crate::linalg`]'s).
//!
//! A control step needs each inverse applied to one vector only: [`PreparedJacobian`] factors a
//! Jacobian once for its manipulability and `x = J†_κ v`, without forming `J†_κ`.

use crate::linalg::{as_square, damped_solve, gram_lower, Cholesky, Lu, SquareDim};
use crate::manipulability::manipulability;
use nalgebra::{Const, RealField, SMatrix, SVector};

/// Damping of the least-squares inverse `J†_κ = Jᵀ (J Jᵀ + κ² I)⁻¹` (3.43), (3.46).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Damping<T> {
    /// A constant `κ` (the thesis's Table 4.2, "κ = 0.05").
    Constant(T),
    /// Variable damping (3.44): `κ = 0` if `w ≥ w0`, else `α0 (1 − w/w0)²`, with `w` the
    /// manipulability of the matrix being inverted.
    Variable {
        /// Scale `α0` (the largest damping, reached at `w = 0`).
        alpha0: T,
        /// Threshold `w0` of manipulability under which damping starts.
        w0: T,
    },
}

impl<T: RealField + Copy> Damping<T> {
    /// The damping factor `κ` at manipulability `w`.
    pub fn kappa(&self, w: T) -> T {
        match *self {
            Damping::Constant(k) => k,
            Damping::Variable { alpha0, w0 } => {
                if w >= w0 {
                    T::zero()
                } else {
                    let s = T::one() - w / w0;
                    alpha0 * s * s
                }
            }
        }
    }
}

/// A Jacobian `J ∈ R^{R×C}` prepared for one control step: its manipulability `w` (3.36) and
/// `x = J†_κ v` at the damping chosen from `w` (3.44).
///
/// A square `J` is factored once by LU: `w = |det J|` and, without damping, `x = J⁻¹ v` come
/// from the same factors (and solving `J` itself is better conditioned than its Gram matrix).
/// With damping, or for a non-square `J`, `x` comes from [`damped_solve`].
#[derive(Clone, Debug)]
pub struct PreparedJacobian<'a, T: RealField + Copy, const R: usize, const C: usize>
where
    Const<R>: SquareDim,
{
    j: &'a SMatrix<T, R, C>,
    factors: Factors<T, R>,
    w: T,
}

/// The factors a [`PreparedJacobian`] keeps: one variant, so that the struct holds only the
/// one it uses (it is built and moved once per control step).
#[derive(Clone, Debug)]
enum Factors<T: RealField + Copy, const R: usize>
where
    Const<R>: SquareDim,
{
    /// LU of a square `J`.
    Lu(Lu<T, R>),
    /// Root-free Cholesky of `J Jᵀ` for a wide `J`.
    Gram(Cholesky<T, R>),
    /// None: a tall `J`, or a wide one whose `J Jᵀ` is not positive definite.
    None,
}

impl<'a, T: RealField + Copy, const R: usize, const C: usize> PreparedJacobian<'a, T, R, C>
where
    Const<R>: SquareDim,
    Const<C>: SquareDim,
{
    /// Factors `j` (LU when square, Cholesky of `J Jᵀ` when wide) and computes its
    /// manipulability.
    pub fn new(j: &'a SMatrix<T, R, C>) -> Self {
        if R == C {
            let lu = Lu::new(&as_square(j));
            let w = lu.determinant().abs();
            PreparedJacobian {
                j,
                factors: Factors::Lu(lu),
                w,
            }
        } else if R < C {
            // w = sqrt(det(J Jᵀ)) = Π L_kk of J Jᵀ = L Lᵀ; 0 when J Jᵀ is not positive definite.
            let gram = Cholesky::new(&gram_lower(j, T::zero()));
            let w = gram.as_ref().map_or(T::zero(), Cholesky::sqrt_determinant);
            PreparedJacobian {
                j,
                factors: gram.map_or(Factors::None, Factors::Gram),
                w,
            }
        } else {
            PreparedJacobian {
                j,
                factors: Factors::None,
                w: manipulability(j),
            }
        }
    }

    /// The manipulability `w = sqrt(|det(J Jᵀ)|)` (3.36), `|det J|` when square.
    pub fn manipulability(&self) -> T {
        self.w
    }

    /// The Jacobian.
    pub fn jacobian(&self) -> &SMatrix<T, R, C> {
        self.j
    }

    /// `x = J†_κ v`: the pseudo-inverse (the inverse when square) for `κ = 0`, damped least
    /// squares (3.43) otherwise — [`crate::linalg::pseudo_inverse_apply`] and
    /// [`crate::linalg::damped_solve`], from the factors already made. `None` if `J` is singular with `κ = 0`, or `x` is not finite.
    pub fn solve(&self, kappa: T, v: &SVector<T, R>) -> Option<SVector<T, C>> {
        match &self.factors {
            Factors::Lu(lu) if kappa == T::zero() => {
                lu.solve(v).map(|x| SVector::<T, C>::from_fn(|r, _| x[r]))
            }
            Factors::Gram(g) if kappa == T::zero() => {
                let x = self.j.tr_mul(&g.solve(v));
                x.iter().all(|v| v.is_finite()).then_some(x)
            }
            _ => damped_solve(self.j, kappa, v),
        }
    }
}

/// The filtered inverse (3.47)–(3.50): a state `Θ ∈ R^{C×R}` driven towards an inverse of
/// `J ∈ R^{R×C}` by `Θ̇ = −(Γ_r Jᵀ S_r + Γ_l S_l Jᵀ)`, `S_r = J Θ − I`, `S_l = Θ J − I`, and the
/// control `u = Θ Θᵀ Jᵀ dV`.
///
/// (3.49) writes one gain matrix `Γ`; the thesis's experiments give two scalars `Γ_r`, `Γ_l`
/// (Table 4.3), read here as the gains of the right- and left-inverse error terms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilteredInverse<T: RealField + Copy, const R: usize, const C: usize> {
    /// The state `Θ`.
    pub theta: SMatrix<T, C, R>,
}

impl<T: RealField + Copy, const R: usize, const C: usize> FilteredInverse<T, R, C> {
    /// Starts from a given `Θ(0)` (e.g. the pseudo-inverse of `J` at the initial configuration).
    pub fn new(theta: SMatrix<T, C, R>) -> Self {
        FilteredInverse { theta }
    }

    /// `Θ̇` of (3.49) at the current `J`.
    pub fn derivative(&self, j: &SMatrix<T, R, C>, gamma_r: T, gamma_l: T) -> SMatrix<T, C, R> {
        let s_r = j * self.theta - SMatrix::<T, R, R>::identity();
        let s_l = self.theta * j - SMatrix::<T, C, C>::identity();
        let jt = j.transpose();
        -(jt * s_r * gamma_r + s_l * jt * gamma_l)
    }

    /// Integrates (3.49) over `dt` with `J` held constant, by explicit Euler in `n` equal
    /// sub-steps, `n = ⌈2 dt max(Γ_r, Γ_l) ‖J‖²_F⌉` (at most 4096): the linear part of (3.49) has
    /// rates up to `(Γ_r + Γ_l) σ²_max ≤ 2 max(Γ) ‖J‖²_F`, so each sub-step is stable. Returns `n`.
    pub fn update(&mut self, j: &SMatrix<T, R, C>, gamma_r: T, gamma_l: T, dt: T) -> usize {
        let g = if gamma_r > gamma_l { gamma_r } else { gamma_l };
        let two: T = nalgebra::convert(2.0);
        let rate: f64 = (two * dt * g * j.norm_squared())
            .to_subset()
            .unwrap_or(f64::INFINITY);
        let n = if rate.is_finite() {
            (libm::ceil(rate) as usize).clamp(1, 4096)
        } else {
            4096
        };
        let h = dt / nalgebra::convert::<f64, T>(n as f64);
        for _ in 0..n {
            let d = self.derivative(j, gamma_r, gamma_l);
            self.theta += d * h;
        }
        n
    }

    /// The matrix `Θ Θᵀ Jᵀ` of (3.50) that maps `dV` to `u`.
    pub fn inverse(&self, j: &SMatrix<T, R, C>) -> SMatrix<T, C, R> {
        self.theta * (self.theta.transpose() * j.transpose())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix6, SMatrix};

    fn sample() -> SMatrix<f64, 6, 7> {
        SMatrix::<f64, 6, 7>::from_fn(|r, c| {
            ((r * 7 + c) as f64 * 0.731).sin() + if r == c { 2.0 } else { 0.0 }
        })
    }

    /// `J†_κ v` computed independently: nalgebra's SVD, `V diag(σ / (σ² + κ²)) Uᵀ v`.
    fn svd_damped<const R: usize, const C: usize>(
        j: &SMatrix<f64, R, C>,
        kappa: f64,
        v: &SVector<f64, R>,
    ) -> SVector<f64, C> {
        let svd = nalgebra::DMatrix::from_column_slice(R, C, j.as_slice()).svd(true, true);
        let (u, vt) = (svd.u.unwrap(), svd.v_t.unwrap());
        let mut out = SVector::<f64, C>::zeros();
        for (k, s) in svd.singular_values.iter().enumerate() {
            let coefficient = u
                .column(k)
                .dot(&nalgebra::DVector::from_column_slice(v.as_slice()));
            for c in 0..C {
                out[c] += vt[(k, c)] * coefficient * s / (s * s + kappa * kappa);
            }
        }
        out
    }

    #[test]
    fn prepared_jacobian_matches_the_separate_computations() {
        let v = nalgebra::Vector6::new(0.3, -1.2, 0.5, 2.0, -0.7, 0.1);
        // Square: LU for w and for κ = 0, the Gram matrix for κ > 0.
        let sq = Matrix6::from_fn(|r, c| {
            ((r * 6 + c) as f64 * 0.917).sin() + 0.5 * (r == c) as u8 as f64
        });
        let prep = PreparedJacobian::new(&sq);
        let svd_w: f64 = sq.svd(false, false).singular_values.iter().product();
        assert!((prep.manipulability() - svd_w).abs() < 1e-12 * svd_w);
        let x = prep.solve(0.0, &v).unwrap();
        assert!((sq * x - v).norm() < 1e-12);
        assert!((x - sq.try_inverse().unwrap() * v).norm() < 1e-10 * x.norm());
        let xd = prep.solve(0.2, &v).unwrap();
        assert!((xd - svd_damped(&sq, 0.2, &v)).norm() < 1e-12);
        // Wide: manipulability and pseudo-inverse from the Cholesky factors of the Gram matrix
        // (w = Π L_kk), equal to the LU determinant's and the SVD's to rounding.
        let j = sample();
        let prep = PreparedJacobian::new(&j);
        let w = manipulability(&j);
        assert!((prep.manipulability() - w).abs() < 1e-13 * w);
        let svd_w: f64 = j.svd(false, false).singular_values.iter().product();
        assert!((prep.manipulability() - svd_w).abs() < 1e-12 * svd_w);
        assert!((prep.solve(0.0, &v).unwrap() - svd_damped(&j, 0.0, &v)).norm() < 1e-12);
        // Wide and rank-deficient: w ≈ 0, and the solves stay finite (Jᵀ maps the Gram
        // matrix's near-null direction, null(Jᵀ), to zero).
        let mut jw = j;
        jw.set_row(4, &(jw.row(2) * 1.5));
        let prep = PreparedJacobian::new(&jw);
        // (Rounding leaves a pivot of order ε: w of order sqrt(ε), against w ≈ 1 when regular.)
        assert!(
            prep.manipulability() < 1e-5 * w,
            "{}",
            prep.manipulability()
        );
        assert!(prep
            .solve(0.0, &v)
            .is_none_or(|x| x.iter().all(|x| x.is_finite())));
        assert!(prep.solve(0.05, &v).unwrap().iter().all(|x| x.is_finite()));
        // Singular square: no inverse, w = 0, damping still solves.
        let mut s = sq;
        s.set_column(3, &(s.column(1) * 2.0));
        s.set_column(4, &(s.column(1) * -3.0));
        let prep = PreparedJacobian::new(&s);
        assert!(prep.manipulability() < 1e-14);
        assert!(prep.solve(0.0, &v).is_none_or(|x| x.norm() > 1e10));
        assert!(prep.solve(0.05, &v).unwrap().iter().all(|x| x.is_finite()));
        assert!(PreparedJacobian::new(&Matrix6::<f64>::zeros())
            .solve(0.0, &v)
            .is_none());
    }

    #[test]
    fn variable_damping_follows_3_44() {
        let d = Damping::Variable {
            alpha0: 0.05f64,
            w0: 0.2,
        };
        assert_eq!(d.kappa(0.3), 0.0);
        assert_eq!(d.kappa(0.2), 0.0);
        assert!((d.kappa(0.1) - 0.05 * 0.25).abs() < 1e-15);
        assert_eq!(d.kappa(0.0), 0.05);
        assert_eq!(Damping::Constant(0.01).kappa(7.0), 0.01);
    }

    #[test]
    fn manipulability_is_the_product_of_singular_values() {
        use crate::linalg::determinant;
        use crate::manipulability::manipulability;
        let j = sample();
        let svd = nalgebra::linalg::SVD::new(j, false, false);
        let prod: f64 = svd.singular_values.iter().product();
        assert!((manipulability(&j) - prod).abs() < 1e-10 * prod);
        assert!((manipulability(&j.transpose()) - prod).abs() < 1e-10 * prod);
        let m =
            Matrix6::from_fn(|r, c| (r as f64 + 1.0).powi(c as i32 % 3) + (r == c) as u8 as f64);
        assert!((determinant(&m) - m.determinant()).abs() < 1e-9 * m.determinant().abs());
    }

    #[test]
    fn filtered_inverse_converges_to_the_inverse() {
        let j = sample() * 0.5;
        let mut fi = FilteredInverse::new(SMatrix::<f64, 7, 6>::zeros());
        for _ in 0..20000 {
            fi.update(&j, 5.0, 5.0, 0.002);
        }
        assert!((j * fi.theta - Matrix6::identity()).norm() < 1e-6);
        // Θ Θᵀ Jᵀ then is a right inverse too.
        assert!((j * fi.inverse(&j) - Matrix6::identity()).norm() < 1e-5);
    }
}
