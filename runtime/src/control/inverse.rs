//! Inverses of the Jacobians: pseudo-inverse, damped least squares with variable damping
//! (3.43)–(3.46), and the filtered inverse (3.47)–(3.50).
//!
//! Everything works on fixed-size `nalgebra` matrices of any shape and allocates nothing: the
//! linear systems are the Gram matrices `J Jᵀ + κ² I` (or `Jᵀ J + κ² I` when `J` has more rows
//! than columns), solved by Cholesky; a square `J` without damping is solved by its LU factors.
//!
//! A control step needs each inverse applied to one vector only: [`PreparedJacobian`] factors a
//! Jacobian once for its manipulability and `x = J†_κ v`, without forming `J†_κ`.

use crate::manipulability::{manipulability, SquareDim, SquareLu};
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

/// The root-free Cholesky factorisation `A = L D Lᵀ` (`L` unit lower triangular, `D` diagonal)
/// of a symmetric positive definite `A` of fixed size `D`, with forward and back substitution
/// for `A x = b`: the Gram matrices of the least-squares inverses.
///
/// Root-free because each square root of `A = L Lᵀ` lies on the chain of dependent operations
/// that bounds a control step's latency; `sqrt(det A)` takes one at the end. Written out over the
/// fixed size (the compiler unrolls it for a 6 × 6 Gram matrix) rather than through
/// `nalgebra::Cholesky`, whose loops over matrix views dominated a control step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GramCholesky<T: RealField + Copy, const D: usize> {
    /// `L` below the diagonal, row by row (`l[i][k]`, `k < i`; the rest is not used).
    l: [[T; D]; D],
    /// `1 / D_kk`.
    inv_d: [T; D],
    /// `sqrt(Π D_kk)`.
    sqrt_det: T,
}

impl<T: RealField + Copy, const D: usize> GramCholesky<T, D> {
    /// Factors `a` (only its lower triangle is read). `None` unless `a` is positive definite to
    /// working precision: every pivot finite and `D_jj > D ε A_jj` (`ε` the machine epsilon of
    /// `T`). `D_jj / A_jj` is the squared sine of the angle between row `j` of `J` and the span
    /// of the rows before it when `A = J Jᵀ`; below `D ε` it is rounding noise, and so would be
    /// the solution.
    pub fn new(a: &SMatrix<T, D, D>) -> Option<Self> {
        let tol = T::default_epsilon() * nalgebra::convert::<f64, T>(D as f64);
        let mut l = [[T::zero(); D]; D];
        for (i, row) in l.iter_mut().enumerate() {
            for (k, v) in row.iter_mut().enumerate().take(i + 1) {
                *v = a[(i, k)];
            }
        }
        let mut inv_d = [T::zero(); D];
        let mut det = T::one();
        // Tested once at the end: the loop stays free of branches.
        let mut positive = true;
        for j in 0..D {
            let (above, rest) = l.split_at_mut(j);
            let row = &mut rest[0];
            // Row j of W = L D left of the diagonal, from the rows above (already L).
            for k in 0..j {
                let mut w = row[k];
                for m in 0..k {
                    w -= row[m] * above[k][m];
                }
                row[k] = w;
            }
            let ajj = row[j];
            let mut dj = ajj;
            for k in 0..j {
                let ljk = row[k] * inv_d[k];
                dj -= ljk * row[k];
                row[k] = ljk;
            }
            // A NaN pivot fails the comparison too.
            positive &= dj > tol * ajj && dj.is_finite() && ajj.is_finite();
            det *= dj;
            inv_d[j] = T::one() / dj;
        }
        positive.then(|| GramCholesky {
            l,
            inv_d,
            sqrt_det: det.sqrt(),
        })
    }

    /// `sqrt(det A) = sqrt(Π D_kk)`.
    pub fn sqrt_determinant(&self) -> T {
        self.sqrt_det
    }

    /// `x = A⁻¹ b` by `L y = b`, `D z = y`, `Lᵀ x = z`, for each of the `K` columns of `b`.
    pub fn solve<const K: usize>(&self, b: &SMatrix<T, D, K>) -> SMatrix<T, D, K> {
        let mut out = *b;
        for c in 0..K {
            let mut x = [T::zero(); D];
            for (i, v) in x.iter_mut().enumerate() {
                *v = b[(i, c)];
            }
            for i in 0..D {
                let (done, rest) = x.split_at_mut(i);
                let row = &self.l[i];
                rest[0] = done
                    .iter()
                    .zip(row)
                    .fold(rest[0], |v, (xk, lik)| v - *lik * *xk);
            }
            for i in (0..D).rev() {
                let (head, done) = x.split_at_mut(i + 1);
                head[i] = done
                    .iter()
                    .zip(&self.l[i + 1..])
                    .fold(head[i] * self.inv_d[i], |v, (xk, lk)| v - lk[i] * *xk);
            }
            for (i, v) in x.iter().enumerate() {
                out[(i, c)] = *v;
            }
        }
        out
    }
}

/// The lower triangle of the Gram matrix `J Jᵀ + κ² I` (the upper triangle is left zero: only
/// [`GramCholesky`] reads it).
fn gram_lower<T: RealField + Copy, const R: usize, const C: usize>(
    j: &SMatrix<T, R, C>,
    k2: T,
) -> SMatrix<T, R, R> {
    let mut a = SMatrix::<T, R, R>::zeros();
    for c in 0..C {
        for k in 0..R {
            let x = j[(k, c)];
            for i in k..R {
                a[(i, k)] += j[(i, c)] * x;
            }
        }
    }
    for i in 0..R {
        a[(i, i)] += k2;
    }
    a
}

/// The damped least-squares inverse `Jᵀ (J Jᵀ + κ² I)⁻¹` (3.43), (3.46), computed as
/// `(Jᵀ J + κ² I)⁻¹ Jᵀ` when `J` is tall (the same matrix for `κ > 0`): [`damped_solve`] of the
/// identity. With `κ = 0` it is the Moore–Penrose pseudo-inverse of a full-rank `J`. `None` if the
/// Gram matrix is not positive definite (a singular `J` with `κ = 0`).
pub fn damped_pinv<T: RealField + Copy, const R: usize, const C: usize>(
    j: &SMatrix<T, R, C>,
    kappa: T,
) -> Option<SMatrix<T, C, R>> {
    damped_solve(j, kappa, &SMatrix::<T, R, R>::identity())
}

/// `X = J†_κ V = Jᵀ (J Jᵀ + κ² I)⁻¹ V` (3.43), (3.46) (`(Jᵀ J + κ² I)⁻¹ Jᵀ V` when `J` is tall)
/// for `K` right-hand sides, without forming `J†_κ` (a control step has one, `V = v`): one
/// Cholesky factorisation of the Gram matrix. `None` if the Gram matrix is not positive definite
/// or `X` is not finite.
pub fn damped_solve<T: RealField + Copy, const R: usize, const C: usize, const K: usize>(
    j: &SMatrix<T, R, C>,
    kappa: T,
    v: &SMatrix<T, R, K>,
) -> Option<SMatrix<T, C, K>> {
    let k2 = kappa * kappa;
    let x = if R <= C {
        j.tr_mul(&GramCholesky::new(&gram_lower(j, k2))?.solve(v))
    } else {
        GramCholesky::new(&gram_lower(&j.transpose(), k2))?.solve(&j.tr_mul(v))
    };
    x.iter().all(|v| v.is_finite()).then_some(x)
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
    Lu(SquareLu<T, R>),
    /// Root-free Cholesky of `J Jᵀ` for a wide `J`.
    Gram(GramCholesky<T, R>),
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
            let square = SMatrix::<T, R, R>::from_fn(|r, c| j[(r, c)]);
            let lu = SquareLu::new(&square);
            let w = lu.determinant().abs();
            PreparedJacobian {
                j,
                factors: Factors::Lu(lu),
                w,
            }
        } else if R < C {
            // w = sqrt(det(J Jᵀ)) = Π L_kk of J Jᵀ = L Lᵀ; 0 when J Jᵀ is not positive definite.
            let gram = GramCholesky::new(&gram_lower(j, T::zero()));
            let w = gram
                .as_ref()
                .map_or(T::zero(), GramCholesky::sqrt_determinant);
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
    /// squares (3.43) otherwise. `None` if `J` is singular with `κ = 0`, or `x` is not finite.
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

/// The pseudo-inverse of a full-rank `J` (`damped_pinv` with `κ = 0`).
pub fn pinv<T: RealField + Copy, const R: usize, const C: usize>(
    j: &SMatrix<T, R, C>,
) -> Option<SMatrix<T, C, R>> {
    damped_pinv(j, T::zero())
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

    #[test]
    fn pinv_is_a_right_inverse_and_matches_svd() {
        let j = sample();
        let p = pinv(&j).unwrap();
        assert!((j * p - Matrix6::identity()).norm() < 1e-12);
        let svd = nalgebra::linalg::SVD::new(j, true, true);
        let reference = svd.pseudo_inverse(1e-14).unwrap();
        assert!((p - reference).norm() < 1e-10);
        let tall = j.transpose();
        let pt = pinv(&tall).unwrap();
        assert!((pt * tall - Matrix6::identity()).norm() < 1e-12);
    }

    #[test]
    fn damped_inverse_forms_agree_and_singular_pinv_fails() {
        let j = sample();
        let a = damped_pinv(&j, 0.3).unwrap();
        let b = damped_pinv(&j.transpose(), 0.3).unwrap().transpose();
        assert!((a - b).norm() < 1e-12);
        let mut s = j;
        s.set_row(5, &(s.row(0) * 2.0));
        assert!(
            pinv(&s).is_none(),
            "a rank-deficient J has no pseudo-inverse by the Gram matrix"
        );
        assert!(damped_pinv(&s, 0.05).unwrap().norm() < 1e3);
    }

    #[test]
    fn damped_solve_applies_the_damped_inverse_to_one_vector() {
        let j = sample();
        let v = nalgebra::Vector6::new(0.3, -1.2, 0.5, 2.0, -0.7, 0.1);
        for kappa in [0.0, 0.05, 0.3] {
            let x = damped_solve(&j, kappa, &v).unwrap();
            assert!((x - damped_pinv(&j, kappa).unwrap() * v).norm() < 1e-12);
            let tall = j.transpose();
            let w = SMatrix::<f64, 7, 1>::from_fn(|r, _| (r as f64 * 0.4).cos());
            let y = damped_solve(&tall, kappa, &w).unwrap();
            assert!((y - damped_pinv(&tall, kappa).unwrap() * w).norm() < 1e-12);
        }
        let mut s = j;
        s.set_row(5, &(s.row(0) * 2.0));
        assert!(damped_solve(&s, 0.0, &v).is_none());
        assert!(damped_solve(&s, 0.05, &v).unwrap().norm() < 1e3);
    }

    #[test]
    fn prepared_jacobian_matches_the_separate_computations() {
        use crate::manipulability::manipulability;
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
        assert!((xd - damped_pinv(&sq, 0.2).unwrap() * v).norm() < 1e-12);
        // Wide: manipulability and pseudo-inverse from the Cholesky factors of the Gram matrix
        // (w = Π L_kk), equal to the LU determinant's and the SVD's to rounding.
        let j = sample();
        let prep = PreparedJacobian::new(&j);
        let w = manipulability(&j);
        assert!((prep.manipulability() - w).abs() < 1e-13 * w);
        let svd_w: f64 = j.svd(false, false).singular_values.iter().product();
        assert!((prep.manipulability() - svd_w).abs() < 1e-12 * svd_w);
        assert!((prep.solve(0.0, &v).unwrap() - pinv(&j).unwrap() * v).norm() < 1e-12);
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
        use crate::manipulability::{determinant, manipulability};
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

    /// The fixed-size Cholesky factor agrees with nalgebra's (factor, `sqrt(det)`, solve) and
    /// refuses matrices that are not positive definite, or not finite.
    #[test]
    fn gram_cholesky_matches_nalgebra_and_refuses_indefinite() {
        let j = sample();
        let a = j * j.transpose();
        let ours = GramCholesky::new(&a).expect("positive definite");
        let theirs = nalgebra::Cholesky::new(a).unwrap();
        let b = SMatrix::<f64, 6, 2>::from_fn(|i, c| (i as f64 - 2.0) * (c as f64 + 0.5));
        assert!((ours.solve(&b) - theirs.solve(&b)).norm() < 1e-12);
        assert!((a * ours.solve(&b) - b).norm() < 1e-12);
        assert!((ours.sqrt_determinant() - a.determinant().sqrt()).abs() < 1e-12);
        let mut indefinite = a;
        indefinite[(3, 3)] = -1.0;
        assert!(GramCholesky::new(&indefinite).is_none());
        let mut nan = a;
        nan[(5, 5)] = f64::NAN;
        assert!(GramCholesky::new(&nan).is_none());
        let mut inf = a;
        inf[(0, 0)] = f64::INFINITY;
        assert!(GramCholesky::new(&inf).is_none());
        assert!(GramCholesky::new(&SMatrix::<f64, 3, 3>::zeros()).is_none());
    }
}
