//! The constraint: Λ = H Ad_gri (3.3), its null-space basis Λ# (3.23)/(3.27), Λ†, the constrained
//! Jacobian J^r_0e (3.15) and J_c (3.33).
//!
//! A point of link `i` carries the constraint frame `F_r`, `g_ir = (R_ir, p_ir)`; the constraint is
//! `H V^B_0r = 0` (3.1) with `H ∈ R^{r×6}`. Since `V^B_0r = Ad_{g_ri} V^B_0i` (3.2), the link's
//! body velocity must satisfy `Λ V^B_0i = 0` with `Λ = H Ad_{g_ri}` (3.3), i.e.
//! `V^B_0i = Λ# v0i` for any `v0i ∈ R^{6−r}` (3.6).
//!
//! [`Constraint<T, R>`] caches `Λ`, `Λ#` and `Λ†` and recomputes them when the constraint frame
//! moves ([`Constraint::set_offset`], a few dozen flops): in the thesis's setting the link slides
//! through a fixed trocar, so `l_a` changes every control step. Nothing here allocates.
//!
//! ```
//! use trocar::constraint::Constraint;
//! use trocar::kinematics::{Chain, Joint};
//! use trocar::nalgebra::{SMatrix, SVector, Vector3};
//! use trocar::se3::Se3;
//!
//! // The `bidirectional-zy` wrist after a 6-joint arm (here: six revolute joints about z, x, ...).
//! let (l_a, l_b, l_8) = (0.15, 0.18, 0.21);
//! let at = |x: f64, y: f64, z: f64| Se3::from_translation(Vector3::new(x, y, z));
//! let (x, y, z) = (Vector3::x(), Vector3::y(), Vector3::z());
//! let chain = Chain::new(
//!     [
//!         Joint::revolute(at(0.0, 0.0, 0.0), z),
//!         Joint::revolute(at(0.194, 0.0, 1.037), x),
//!         Joint::revolute(at(0.0, 0.38, 0.0), x),
//!         Joint::revolute(at(0.0, 0.0, 0.0), y),
//!         Joint::revolute(at(0.0, 0.39, 0.0), x),
//!         Joint::revolute(at(0.0, 0.0, 0.0), y),
//!         Joint::revolute(at(0.0, l_a + l_b, 0.0), z),
//!         Joint::revolute(at(0.0, 0.0, 0.0), y),
//!     ],
//!     at(0.0, l_8, 0.0),
//! );
//! // H = (x_r, z_r) at link 6, thesis basis (3.27).
//! let mut rcm = Constraint::<f64, 2>::thesis(6, l_a).unwrap();
//! let q = SVector::<f64, 8>::from([0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3]);
//!
//! // Every control step: move the constraint frame, then J^r (3.15) and J_c (3.33).
//! rcm.set_offset(0.16).unwrap();
//! let (jr, jc): (SMatrix<f64, 6, 6>, SMatrix<f64, 6, 2>) = rcm.constrained_jacobians(&chain, &q);
//! # let _ = jc;
//! // Given [v0i; θ̇_jn] from (J^r)† u, the joint rates before the constraint (3.10):
//! let v0i = SVector::<f64, 4>::new(0.01, 0.0, -0.02, 0.1);
//! let v_0i = rcm.link_velocity(&v0i, &SVector::zeros());
//! let th_1i: SVector<f64, 6> = rcm.joint_rates_before_constraint::<8, 6>(&chain, &q, &v_0i).unwrap();
//! // The constraint holds: Λ J^B_0i θ̇_{1..i} = 0.
//! let jb0i = chain.partial_body_jacobian::<6>(&q);
//! assert!((rcm.lambda() * jb0i * th_1i).amax() < 1e-12);
//! # let _ = jr;
//! ```

use crate::kinematics::{body_jacobian_columns, constrained_jacobian_columns, Chain};
use crate::linalg::{
    null_space_of_rows, pseudo_inverse, pseudo_inverse_apply, RowsError, SquareDim,
};
use crate::se3::{Adjoint, Se3, Twist};
use core::fmt;
use nalgebra::{convert, Const, RealField, SMatrix, SVector, Vector3};

/// Which basis of `null(Λ)` is used for `Λ#`. `J^r_0e` and its manipulability depend on the
/// choice (a different basis multiplies `J^r` on the right by an invertible matrix).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NullSpaceBasis {
    /// The thesis's (3.23), `r = 1`, `H = x_r`, `g_ir = (I, (0, l_a, 0))`: columns
    /// `v0i = (v_x, v_y, v_z, ω_x, ω_y)` with `ω_z = v_x / l_a`.
    Unidirectional,
    /// The thesis's (3.27), `r = 2`, `H = (x_r, z_r)`, `g_ir = (I, (0, l_a, 0))`: columns
    /// `v0i = (v_x, v_y, v_z, ω_y)` with `ω_x = −v_z / l_a`, `ω_z = v_x / l_a`.
    Bidirectional,
    /// `Λ# = Ad_{g_ir} N_H` (since `null(H Ad_{g_ri}) = Ad_{g_ir} null(H)`), where the columns of
    /// `N_H` are the null-space basis of `H` read off its reduced row echelon form
    /// ([`crate::linalg::null_space_of_rows`]): one column per free (non-pivot) coordinate `f`,
    /// with `x_f = 1`, the other free coordinates 0. For a selection `H` (rows of the identity)
    /// these are the unselected unit twists, in order.
    Computed,
}

impl NullSpaceBasis {
    /// The thesis's basis for `r` rows of `H`: (3.23) for `r = 1` (`H = x_r`), (3.27) for `r = 2`
    /// (`H = (x_r, z_r)`); `None` otherwise.
    pub const fn thesis(r: usize) -> Option<Self> {
        match r {
            1 => Some(Self::Unidirectional),
            2 => Some(Self::Bidirectional),
            _ => None,
        }
    }

    /// The number of rows of `H` a thesis basis is written for (1 for (3.23), 2 for (3.27));
    /// `None` for the computed basis, which fits any `H`.
    pub const fn thesis_rows(self) -> Option<usize> {
        match self {
            Self::Unidirectional => Some(1),
            Self::Bidirectional => Some(2),
            Self::Computed => None,
        }
    }

    /// Whether this basis can be used with `r` rows of `H`.
    pub const fn fits_rows(self, r: usize) -> bool {
        match self.thesis_rows() {
            Some(rows) => rows == r,
            None => true,
        }
    }
}

/// Why a constraint cannot be built or moved.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ConstraintError {
    /// `r` must be between 1 and 5.
    BadRowCount(usize),
    /// The rows of `H` are linearly dependent (or zero).
    DependentRows,
    /// A thesis basis was asked for, but `H` is not `x_r` (3.21) or `(x_r, z_r)` (3.25).
    NotThesisH,
    /// A thesis basis was asked for, but `g_ir` is not `(I, (0, l_a, 0))`.
    NotThesisFrame,
    /// A thesis basis with `l_a = 0` (it divides by `l_a`).
    ZeroOffset,
    /// A value is not finite.
    NotFinite,
}

impl fmt::Display for ConstraintError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadRowCount(r) => write!(f, "H has {r} rows; a constraint has 1 to 5"),
            Self::DependentRows => write!(f, "the rows of H are linearly dependent"),
            Self::NotThesisH => write!(
                f,
                "the thesis bases (3.23)/(3.27) need H = x_r or H = (x_r, z_r)"
            ),
            Self::NotThesisFrame => write!(
                f,
                "the thesis bases (3.23)/(3.27) need g_ir = (I, (0, l_a, 0))"
            ),
            Self::ZeroOffset => write!(f, "the thesis bases divide by l_a, which is 0"),
            Self::NotFinite => write!(f, "a value is not finite"),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for ConstraintError {}

impl From<RowsError> for ConstraintError {
    fn from(e: RowsError) -> Self {
        match e {
            RowsError::BadRowCount(r) => Self::BadRowCount(r),
            RowsError::DependentRows => Self::DependentRows,
            RowsError::NotFinite => Self::NotFinite,
        }
    }
}

/// The thesis's null-space bases, written into `out` as columns: (3.23) for `r = 1`
/// (`out.len() == 5`) and (3.27) for `r = 2` (`out.len() == 4`). Column order as the thesis's:
/// (3.23) `v0i = (v_x, v_y, v_z, ω_x, ω_y)`; (3.27) `v0i = (v_x, v_y, v_z, ω_y)`.
///
/// # Panics
/// If `out.len()` is not 4 or 5.
pub fn thesis_null_space<T: RealField + Copy>(l_a: T, out: &mut [Twist<T>]) {
    let z = T::zero();
    let o = T::one();
    let inv = o / l_a;
    match out.len() {
        5 => {
            // (3.23): rows e1, e2, e3, e4, e5, (1/l_a) e1.
            out[0] = Twist::new(o, z, z, z, z, inv);
            out[1] = Twist::new(z, o, z, z, z, z);
            out[2] = Twist::new(z, z, o, z, z, z);
            out[3] = Twist::new(z, z, z, o, z, z);
            out[4] = Twist::new(z, z, z, z, o, z);
        }
        4 => {
            // (3.27): rows e1, e2, e3, −(1/l_a) e3, e4, (1/l_a) e1.
            out[0] = Twist::new(o, z, z, z, z, inv);
            out[1] = Twist::new(z, o, z, z, z, z);
            out[2] = Twist::new(z, z, o, -inv, z, z);
            out[3] = Twist::new(z, z, z, z, o, z);
        }
        n => panic!("the thesis bases have 5 (r = 1) or 4 (r = 2) columns, not {n}"),
    }
}

/// A point constraint `H V^B_0r = 0` (3.1) with `R` rows, at the frame `F_r` fixed in link `i`
/// (`g_ir`), with cached `Λ = H Ad_{g_ri}` (3.3), `Λ#` (3.23)/(3.27)/computed and `Λ†`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Constraint<T: RealField + Copy, const R: usize> {
    link: usize,
    g_ir: Se3<T>,
    h: SMatrix<T, R, 6>,
    basis: NullSpaceBasis,
    /// Basis of null(H), first 6 − R entries (for the computed basis).
    null_h: [Twist<T>; 6],
    lambda: SMatrix<T, R, 6>,
    /// Columns of Λ#, first 6 − R entries.
    lambda_sharp: [Twist<T>; 6],
    lambda_pinv: SMatrix<T, 6, R>,
}

impl<T: RealField + Copy, const R: usize> Constraint<T, R>
where
    Const<R>: SquareDim,
{
    /// A constraint at link `link` (1-based `i`) with frame `g_ir` and selection `H`, using the
    /// computed basis ([`NullSpaceBasis::Computed`]).
    pub fn new(link: usize, g_ir: Se3<T>, h: SMatrix<T, R, 6>) -> Result<Self, ConstraintError> {
        Self::with_basis(link, g_ir, h, NullSpaceBasis::Computed)
    }

    /// The thesis's constraint at link `link` with `g_ir = (I, (0, l_a, 0))`: for `R = 1`,
    /// `H = x_r` (3.21) and the basis (3.23); for `R = 2`, `H = (x_r, z_r)` (3.25) and (3.27).
    pub fn thesis(link: usize, l_a: T) -> Result<Self, ConstraintError> {
        let basis = NullSpaceBasis::thesis(R).ok_or(ConstraintError::NotThesisH)?;
        let h = thesis_h::<T, R>();
        let g_ir = Se3::from_translation(Vector3::new(T::zero(), l_a, T::zero()));
        Self::with_basis(link, g_ir, h, basis)
    }

    /// A constraint with an explicit choice of basis. The thesis bases need
    /// `g_ir = (I, (0, l_a, 0))`, `l_a ≠ 0`, and `H = x_r` (`R = 1`) or `(x_r, z_r)` (`R = 2`).
    pub fn with_basis(
        link: usize,
        g_ir: Se3<T>,
        h: SMatrix<T, R, 6>,
        basis: NullSpaceBasis,
    ) -> Result<Self, ConstraintError> {
        if R == 0 || R > 5 {
            return Err(ConstraintError::BadRowCount(R));
        }
        let mut null_h = [Twist::zeros(); 6];
        let mut rows = [Twist::zeros(); 6];
        for (k, row) in rows.iter_mut().enumerate().take(R) {
            *row = h.row(k).transpose();
        }
        null_space_of_rows(&rows[..R], &mut null_h[..6 - R])?;
        if basis != NullSpaceBasis::Computed && (!basis.fits_rows(R) || h != thesis_h::<T, R>()) {
            return Err(ConstraintError::NotThesisH);
        }
        let mut c = Self {
            link,
            g_ir: Se3::identity(),
            h,
            basis,
            null_h,
            lambda: SMatrix::zeros(),
            lambda_sharp: [Twist::zeros(); 6],
            lambda_pinv: SMatrix::zeros(),
        };
        c.set_frame(g_ir)?;
        Ok(c)
    }

    /// Moves the constraint frame to `g_ir = (R_ir, (0, l_a, 0))` (keeping `R_ir`) — the trocar
    /// update of every control step — and recomputes `Λ`, `Λ#`, `Λ†`.
    pub fn set_offset(&mut self, l_a: T) -> Result<(), ConstraintError> {
        let g = Se3::new(self.g_ir.rotation, Vector3::new(T::zero(), l_a, T::zero()));
        self.set_frame(g)
    }

    /// Moves the constraint frame to `g_ir` and recomputes `Λ`, `Λ#`, `Λ†`. On error nothing
    /// changes.
    pub fn set_frame(&mut self, g_ir: Se3<T>) -> Result<(), ConstraintError> {
        if !(g_ir.rotation.iter().all(|x| x.is_finite())
            && g_ir.translation.iter().all(|x| x.is_finite()))
        {
            return Err(ConstraintError::NotFinite);
        }
        let k = 6 - R;
        let mut sharp = [Twist::zeros(); 6];
        match self.basis {
            NullSpaceBasis::Computed => {
                let ad = Adjoint(g_ir);
                for (s, n) in sharp.iter_mut().zip(&self.null_h).take(k) {
                    *s = ad.apply(n);
                }
            }
            NullSpaceBasis::Unidirectional | NullSpaceBasis::Bidirectional => {
                let tol: T = T::default_epsilon() * convert(16.0);
                let p = g_ir.translation;
                if (g_ir.rotation - nalgebra::Matrix3::identity()).amax() > tol
                    || p.x.abs() > tol
                    || p.z.abs() > tol
                {
                    return Err(ConstraintError::NotThesisFrame);
                }
                if p.y == T::zero() {
                    return Err(ConstraintError::ZeroOffset);
                }
                thesis_null_space(p.y, &mut sharp[..k]);
            }
        }
        // Λ = H Ad_{g_ri} = H Ad⁻¹_{g_ir} (3.3).
        let lambda = self.h * Adjoint(g_ir).inverse_matrix();
        let lambda_pinv =
            pseudo_inverse::<T, R, 6>(&lambda).ok_or(ConstraintError::DependentRows)?;
        self.g_ir = g_ir;
        self.lambda_sharp = sharp;
        self.lambda = lambda;
        self.lambda_pinv = lambda_pinv;
        Ok(())
    }
}

impl<T: RealField + Copy, const R: usize> Constraint<T, R> {
    /// The constrained link `i` (1-based).
    pub fn link(&self) -> usize {
        self.link
    }

    /// The constraint frame `g_ir`.
    pub fn frame(&self) -> &Se3<T> {
        &self.g_ir
    }

    /// The selection `H` (3.1).
    pub fn h(&self) -> &SMatrix<T, R, 6> {
        &self.h
    }

    /// The basis used for `Λ#`.
    pub fn basis(&self) -> NullSpaceBasis {
        self.basis
    }

    /// `Λ = H Ad_{g_ri}` (3.3), `R×6`; (3.22)/(3.26) for the thesis's frames.
    pub fn lambda(&self) -> &SMatrix<T, R, 6> {
        &self.lambda
    }

    /// `Λ# ∈ R^{6×(6−R)}`, a basis of `null(Λ)` ((3.23), (3.27) or computed). Checked at compile
    /// time: `K = 6 − R`.
    pub fn lambda_null_space<const K: usize>(&self) -> SMatrix<T, 6, K> {
        const { assert!(K + R == 6, "Λ# has 6 − r columns") };
        let mut m = SMatrix::<T, 6, K>::zeros();
        for c in 0..K {
            m.set_column(c, &self.lambda_sharp[c]);
        }
        m
    }

    /// The columns of `Λ#` (`6 − R` twists in `F_i`).
    pub fn lambda_null_space_columns(&self) -> &[Twist<T>] {
        &self.lambda_sharp[..6 - R]
    }

    /// `Λ† = Λᵀ (Λ Λᵀ)⁻¹` (Moore–Penrose, [`crate::linalg::pseudo_inverse`]), `6×R`, used by the
    /// moving RCM (3.31).
    pub fn lambda_pinv(&self) -> &SMatrix<T, 6, R> {
        &self.lambda_pinv
    }

    /// The link's body velocity `V^B_0i = Λ# v0i + Λ† dv_0r` (3.31); `dv_0r = 0` for a fixed RCM
    /// (3.6). Checked at compile time: `K = 6 − R`.
    pub fn link_velocity<const K: usize>(
        &self,
        v0i: &SVector<T, K>,
        dv_0r: &SVector<T, R>,
    ) -> Twist<T> {
        const { assert!(K + R == 6, "v0i has 6 − r entries") };
        let mut v = self.lambda_pinv * dv_0r;
        for c in 0..K {
            v += self.lambda_sharp[c] * v0i[c];
        }
        v
    }

    /// The constrained Jacobian (3.15) `J^r_0e = [Ad_{g_ei} Λ# | J^B_0e2(θ_j..θ_n)] ∈ R^{6×M}`.
    ///
    /// # Panics
    /// If `M ≠ 6 − R + N − i` or `i > N` (a programming error: the sizes are fixed by the robot).
    pub fn constrained_jacobian<const N: usize, const M: usize>(
        &self,
        chain: &Chain<T, N>,
        q: &SVector<T, N>,
    ) -> SMatrix<T, 6, M> {
        self.constrained_jacobians::<N, M>(chain, q).0
    }

    /// `J^r_0e` (3.15) and `J_c = Ad_{g_ei} Λ†` (3.33) in one sweep of the chain.
    ///
    /// # Panics
    /// If `M ≠ 6 − R + N − i` or `i > N`.
    pub fn constrained_jacobians<const N: usize, const M: usize>(
        &self,
        chain: &Chain<T, N>,
        q: &SVector<T, N>,
    ) -> (SMatrix<T, 6, M>, SMatrix<T, 6, R>) {
        let i = self.link;
        assert!(i <= N, "constrained link {i} beyond the chain's {N} joints");
        assert_eq!(M + i, 6 - R + N, "J^r has m = 6 − r + n − i columns");
        let mut cols = [Twist::zeros(); M];
        let g_ie = constrained_jacobian_columns(
            &chain.joints[i..],
            &q.as_slice()[i..],
            &chain.tool,
            &self.lambda_sharp[..6 - R],
            &mut cols,
        );
        let mut jr = SMatrix::<T, 6, M>::zeros();
        for (k, c) in cols.iter().enumerate() {
            jr.set_column(k, c);
        }
        let ad = Adjoint(g_ie);
        let mut jc = SMatrix::<T, 6, R>::zeros();
        for k in 0..R {
            jc.set_column(
                k,
                &ad.apply_inverse(&self.lambda_pinv.column(k).into_owned()),
            );
        }
        (jr, jc)
    }

    /// `J_c = Ad_{g_ei} Λ† ∈ R^{6×R}` (3.33), the end-effector velocity per unit RCM velocity.
    ///
    /// # Panics
    /// If `i > N`.
    pub fn constraint_jacobian_c<const N: usize>(
        &self,
        chain: &Chain<T, N>,
        q: &SVector<T, N>,
    ) -> SMatrix<T, 6, R> {
        let i = self.link;
        assert!(i <= N, "constrained link {i} beyond the chain's {N} joints");
        let g_ie = crate::kinematics::forward_kinematics(
            &chain.joints[i..],
            &q.as_slice()[i..],
            &chain.tool,
        );
        let ad = Adjoint(g_ie);
        let mut jc = SMatrix::<T, 6, R>::zeros();
        for k in 0..R {
            jc.set_column(
                k,
                &ad.apply_inverse(&self.lambda_pinv.column(k).into_owned()),
            );
        }
        jc
    }

    /// (3.10)/(3.7): the joint rates before the constraint, `θ̇_{1..i} = (J^B_0i)† V^B_0i`, for the
    /// link velocity `V^B_0i` (from [`Constraint::link_velocity`]). `None` if `J^B_0i` is
    /// rank-deficient (use damped least squares there).
    ///
    /// # Panics
    /// If `I ≠ i` or `I > N`.
    pub fn joint_rates_before_constraint<const N: usize, const I: usize>(
        &self,
        chain: &Chain<T, N>,
        q: &SVector<T, N>,
        v_0i: &Twist<T>,
    ) -> Option<SVector<T, I>> {
        assert_eq!(I, self.link, "θ̇_{{1..i}} has i entries");
        let mut cols = [Twist::zeros(); I];
        body_jacobian_columns(
            &chain.joints[..I],
            &q.as_slice()[..I],
            &Se3::identity(),
            &mut cols,
        );
        let j = crate::kinematics::matrix_from_columns(&cols);
        pseudo_inverse_apply::<T, 6, I, 1>(&j, v_0i)
    }
}

/// `H = x_r` (R = 1) or `(x_r, z_r)` (R = 2); zeros otherwise.
fn thesis_h<T: RealField + Copy, const R: usize>() -> SMatrix<T, R, 6> {
    let mut h = SMatrix::<T, R, 6>::zeros();
    if R >= 1 {
        h[(0, 0)] = T::one();
    }
    if R == 2 {
        h[(1, 2)] = T::one();
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix1x6, Matrix2x6, SMatrix};

    #[test]
    fn thesis_lambda_is_3_22_and_3_26() {
        let la = 0.2;
        let c = Constraint::<f64, 1>::thesis(6, la).unwrap();
        let expect = Matrix1x6::new(1.0, 0.0, 0.0, 0.0, 0.0, -la);
        assert!((c.lambda() - expect).norm() < 1e-15);
        let c = Constraint::<f64, 2>::thesis(6, la).unwrap();
        let expect = Matrix2x6::new(1.0, 0.0, 0.0, 0.0, 0.0, -la, 0.0, 0.0, 1.0, la, 0.0, 0.0);
        assert!((c.lambda() - expect).norm() < 1e-15);
        let s: SMatrix<f64, 6, 4> = c.lambda_null_space();
        assert!((c.lambda() * s).norm() < 1e-15);
        assert!((c.lambda() * c.lambda_pinv() - nalgebra::Matrix2::identity()).norm() < 1e-14);
    }

    #[test]
    fn computed_basis_spans_null_space_of_general_h() {
        let h = Matrix2x6::new(0.3, -1.0, 0.2, 0.0, 0.5, 0.1, 1.0, 0.4, 0.0, -0.7, 0.0, 0.2);
        let g = Se3::new(
            crate::se3::exp_so3(&Vector3::new(0.2, 0.4, -0.3)),
            Vector3::new(0.1, 0.3, -0.2),
        );
        let c = Constraint::<f64, 2>::new(3, g, h).unwrap();
        let s: SMatrix<f64, 6, 4> = c.lambda_null_space();
        assert!((c.lambda() * s).norm() < 1e-14);
        // Full column rank: [Λ#ᵀ Λ#] invertible.
        assert!((s.transpose() * s).determinant().abs() > 1e-6);
    }

    #[test]
    fn bad_constraints_are_errors() {
        let h = Matrix2x6::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        assert_eq!(
            Constraint::<f64, 2>::new(6, Se3::identity(), h).unwrap_err(),
            ConstraintError::DependentRows
        );
        assert_eq!(
            Constraint::<f64, 1>::thesis(6, 0.0).unwrap_err(),
            ConstraintError::ZeroOffset
        );
        let mut c = Constraint::<f64, 1>::thesis(6, 0.1).unwrap();
        let g = Se3::from_translation(Vector3::new(0.1, 0.2, 0.0));
        assert_eq!(c.set_frame(g), Err(ConstraintError::NotThesisFrame));
        assert_eq!(c.frame().translation.y, 0.1);
        c.set_offset(0.3).unwrap();
        assert_eq!(c.lambda()[(0, 5)], -0.3);
    }
}
