//! Constrained kinematic control (3.17)–(3.18), the moving RCM (3.30)–(3.34), and the inverses of
//! the Jacobians near singularities (3.43)–(3.50): pseudo-inverse, damped least squares with
//! variable damping, filtered inverse (the thesis's Table 4.1).
//!
//! One [`Controller::step`] computes joint velocities from
//! - the desired pose and its velocity feed-forward ([`Reference`]),
//! - the current joints `q`,
//! - the RCM state ([`Rcm`]): the trocar point (fixed in space, or moving with a commanded lateral
//!   velocity `dv_0r`), and the gain `K_r` of the drift correction.
//!
//! The kinematics come through the [`ConstrainedKinematics`] trait, so the numeric runtime and
//! generated closed forms can both drive the same controller. The step allocates nothing and
//! builds without `std`.
//!
//! # The step
//! 1. `l_a = (p_trocar − p_0i) · y_i`: the constraint frame `F_r = (R_0i, p_0i + l_a y_i)` is the
//!    point of link `i` at the trocar (`R_ir = I`, the link runs along `y_i`, SPEC §3.2).
//! 2. Drift correction (beyond the thesis): `e_r = H_v R_0iᵀ (p_trocar − p_0r)`, the lateral
//!    offset of the trocar from the link in `F_r`'s constrained directions, and
//!    `dv_0r = dv_cmd + K_r e_r`. With `K_r = 0` this is the thesis's controller.
//! 3. Cartesian law (2.66)/Table 4.1: `e_p = R_0eᵀ(dp − p)`, `e_q = Q_d ⊗ Q⁻¹ = {η̃, ε̃}`,
//!    `u_o = R_0eᵀ(dω + K_o ε̃)`, `u_p = R_0eᵀ dv + K_p e_p − û_o e_p`. The desired velocities
//!    `dv`, `dω` are given in base coordinates and brought to the end-effector frame; `ε̃` is in
//!    base coordinates (it belongs to `R_Δ = dR Rᵀ`) and is brought to the end-effector frame too,
//!    which makes `ε̃̇ = −½ K_o η̃ ε̃` exactly (the thesis adds the body `dω` to the base `ε̃`; the
//!    two agree at zero error). The `−û_o e_p` term uses the commanded angular velocity `u_o`,
//!    which makes `ė_p = −K_p e_p` exactly.
//! 4. `[v0i; θ̇_jn] = J_inv (u − J_c dv_0r)` (3.34) with `J_inv` the pseudo-inverse, the damped
//!    inverse or the filtered inverse of `J^r_0e`.
//! 5. `V^B_0i = Λ# v0i + Λ† dv_0r` (3.33), `θ̇_{1..i} = J^B_0i^{inv} V^B_0i` (3.18), with the
//!    pseudo-inverse or the damped inverse of `J^B_0i`.

mod inverse;
mod quaternion;

pub use crate::manipulability::{determinant, manipulability};
pub use inverse::{damped_pinv, damped_solve, pinv, Damping, FilteredInverse, PreparedJacobian};
pub use quaternion::{orientation_error, Quaternion};

use crate::constraint::Constraint;
use crate::kinematics::Chain;
use crate::manipulability::SquareDim;
use crate::se3::Se3;
use nalgebra::{Const, Matrix3, RealField, SMatrix, SVector, Vector3, Vector6};

/// Everything the controller needs from the kinematics at `(q, l_a)`.
///
/// Sizes: `I` joints up to the constrained link, `R` constrained directions, `K = 6 − R` columns
/// of `Λ#`, `M = K + n − I` columns of `J^r_0e`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConstrainedState<
    T: RealField + Copy,
    const I: usize,
    const R: usize,
    const K: usize,
    const M: usize,
> {
    /// Pose of the end effector `g_0e`.
    pub g_0e: Se3<T>,
    /// Pose of the constrained link's frame `g_0i`.
    pub g_0i: Se3<T>,
    /// The constrained Jacobian `J^r_0e = [Ad_{g_ei} Λ# | J^B_0e2]` (3.15).
    pub jr: SMatrix<T, 6, M>,
    /// The partial body Jacobian `J^B_0i` (3.13).
    pub jb0i: SMatrix<T, 6, I>,
    /// `J_c = Ad_{g_ei} Λ†` (3.33).
    pub jc: SMatrix<T, 6, R>,
    /// The null-space basis `Λ#` (3.23)/(3.27).
    pub lambda_sharp: SMatrix<T, 6, K>,
    /// `Λ† = Λᵀ (Λ Λᵀ)⁻¹`.
    pub lambda_pinv: SMatrix<T, 6, R>,
}

/// Constrained kinematics of an `N`-joint arm with the RCM on link `I`, `R` constrained
/// directions (see [`ConstrainedState`] for `K`, `M`).
///
/// Convention (the thesis's and SPEC §3): `F_r` is `F_i` translated by `l_a` along `y_i`
/// (`g_ir = (I, (0, l_a, 0))`), and the rows of `H` select directions of `F_r`.
pub trait ConstrainedKinematics<
    T: RealField + Copy,
    const N: usize,
    const I: usize,
    const R: usize,
    const K: usize,
    const M: usize,
>
{
    /// The pose `g_0i(q)` of the constrained link's frame.
    fn g_0i(&self, q: &SVector<T, N>) -> Se3<T>;
    /// The selection `H ∈ R^{R×6}` of the constrained directions (3.1).
    fn h(&self) -> SMatrix<T, R, 6>;
    /// Poses and Jacobians at joints `q` with the constraint at `l_a`.
    fn evaluate(
        &self,
        q: &SVector<T, N>,
        l_a: T,
    ) -> Result<ConstrainedState<T, I, R, K, M>, ControlError>;

    /// `l_a = (p_trocar − p_0i) · y_i` at joints `q` (SPEC §3.2) and [`Self::evaluate`] there:
    /// what a control step asks of the kinematics. The default calls [`Self::g_0i`], then
    /// [`Self::evaluate`]; an implementation that can share work between the two (one set of
    /// joint sines and cosines) overrides it.
    fn evaluate_at_trocar(
        &self,
        q: &SVector<T, N>,
        trocar: &Vector3<T>,
    ) -> Result<(T, ConstrainedState<T, I, R, K, M>), ControlError> {
        let l_a = trocar_offset(&self.g_0i(q), trocar);
        Ok((l_a, self.evaluate(q, l_a)?))
    }
}

/// `l_a = (p_trocar − p_0i) · y_i` (SPEC §3.2): the position of the trocar along the constrained
/// link, whose frame `F_i` is `g_0i` (the link runs along `y_i`).
pub fn trocar_offset<T: RealField + Copy>(g_0i: &Se3<T>, trocar: &Vector3<T>) -> T {
    (trocar - g_0i.translation).dot(&g_0i.rotation.column(1).into_owned())
}

/// The numeric runtime behind [`ConstrainedKinematics`]: a [`Chain`] and the thesis's
/// [`Constraint`] (whose offset is moved to `l_a` at every evaluation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChainKinematics<T: RealField + Copy, const N: usize, const R: usize> {
    /// The serial chain.
    pub chain: Chain<T, N>,
    /// The constraint (its frame `g_ir = (I, (0, l_a, 0))` is reset to each `l_a`).
    pub constraint: Constraint<T, R>,
}

impl<
        T: RealField + Copy,
        const N: usize,
        const I: usize,
        const R: usize,
        const K: usize,
        const M: usize,
    > ConstrainedKinematics<T, N, I, R, K, M> for ChainKinematics<T, N, R>
where
    Const<R>: SquareDim,
{
    fn g_0i(&self, q: &SVector<T, N>) -> Se3<T> {
        self.chain.link_frame(I, q)
    }

    fn h(&self) -> SMatrix<T, R, 6> {
        *self.constraint.h()
    }

    fn evaluate(
        &self,
        q: &SVector<T, N>,
        l_a: T,
    ) -> Result<ConstrainedState<T, I, R, K, M>, ControlError> {
        assert_eq!(self.constraint.link(), I, "the constraint is on link I");
        let mut c = self.constraint;
        c.set_offset(l_a).map_err(|_| ControlError::Kinematics)?;
        let (jr, jc) = c.constrained_jacobians::<N, M>(&self.chain, q);
        Ok(ConstrainedState {
            g_0e: self.chain.forward_kinematics(q),
            g_0i: self.chain.link_frame(I, q),
            jr,
            jb0i: self.chain.partial_body_jacobian::<I>(q),
            jc,
            lambda_sharp: c.lambda_null_space::<K>(),
            lambda_pinv: *c.lambda_pinv(),
        })
    }
}

/// How `J^r_0e` is inverted (Table 4.1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method<T> {
    /// The pseudo-inverse `(J^r)† = J^rᵀ (J^r J^rᵀ)⁻¹` (the inverse when square).
    Pinv,
    /// Damped least squares (3.46) on `J^r`.
    Dls(Damping<T>),
    /// The filtered inverse (3.47)–(3.50) with gains `Γ_r`, `Γ_l`.
    Fi {
        /// Gain of the right-inverse error `S_r`.
        gamma_r: T,
        /// Gain of the left-inverse error `S_l`.
        gamma_l: T,
    },
}

/// Gains and methods of the controller.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControllerConfig<T> {
    /// Position gain `K_p` (1/s).
    pub kp: T,
    /// Orientation gain `K_o` (1/s).
    pub ko: T,
    /// Inverse of `J^r_0e`.
    pub method: Method<T>,
    /// Damping of the inverse of `J^B_0i`; `None` for the pseudo-inverse.
    pub jb0i_damping: Option<Damping<T>>,
    /// Gain `K_r` (1/s) of the RCM drift correction; `0` reproduces the thesis.
    pub kr: T,
}

/// The desired end-effector motion at one instant, in base coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reference<T: RealField + Copy> {
    /// Desired position `dp_0e`.
    pub position: Vector3<T>,
    /// Desired orientation `dR_0e`.
    pub rotation: Matrix3<T>,
    /// Feed-forward linear velocity `d ṗ_0e`.
    pub velocity: Vector3<T>,
    /// Feed-forward angular velocity `dω` (spatial, `dṘ dRᵀ = dω̂`).
    pub angular_velocity: Vector3<T>,
}

/// The RCM at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rcm<T: RealField + Copy, const R: usize> {
    /// The trocar point in base coordinates.
    pub trocar: Vector3<T>,
    /// Commanded lateral velocity of the link at the trocar, `H V^B_0r = dv_0r` (3.30); zero
    /// for a fixed trocar.
    pub dv: SVector<T, R>,
}

/// What one step computed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepOutput<T: RealField + Copy, const N: usize, const R: usize> {
    /// Joint velocities `θ̇`.
    pub qd: SVector<T, N>,
    /// `l_a` at this step.
    pub l_a: T,
    /// Position error `e_p = R_0eᵀ(dp − p)` (end-effector frame).
    pub ep: Vector3<T>,
    /// Orientation error `e_q = {η̃, ε̃}`.
    pub eq: Quaternion<T>,
    /// The Cartesian control `u = (u_p, u_o)` (2.66).
    pub u: Vector6<T>,
    /// Lateral offset `e_r` of the trocar from the link in the constrained directions of `F_r`.
    pub lateral_error: SVector<T, R>,
    /// The RCM velocity used, `dv_0r = dv_cmd + K_r e_r`.
    pub dv_0r: SVector<T, R>,
    /// Manipulability of `J^r_0e`.
    pub w_r: T,
    /// Manipulability of `J^B_0i`.
    pub w_i: T,
    /// Damping applied to `J^r_0e` (0 unless DLS).
    pub kappa_r: T,
    /// Damping applied to `J^B_0i`.
    pub kappa_i: T,
}

/// Why a step failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ControlError {
    /// `J^r_0e` could not be pseudo-inverted (singular with no damping).
    SingularJr,
    /// `J^B_0i` could not be pseudo-inverted (singular with no damping).
    SingularJb0i,
    /// A NaN or infinity appeared.
    NonFinite,
    /// The kinematics could not be evaluated (e.g. `l_a = 0`: the trocar at `F_i`).
    Kinematics,
}

impl core::fmt::Display for ControlError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            ControlError::SingularJr => "the constrained Jacobian J^r_0e is singular",
            ControlError::SingularJb0i => "the partial Jacobian J^B_0i is singular",
            ControlError::NonFinite => "a non-finite value appeared in the control step",
            ControlError::Kinematics => {
                "the constrained kinematics could not be evaluated (trocar at F_i?)"
            }
        })
    }
}

#[cfg(feature = "std")]
impl std::error::Error for ControlError {}

/// The constrained kinematic controller (Table 4.1 with the moving RCM and drift correction).
///
/// Holds the filtered-inverse state `Θ` (unused by the other methods). Generic over the sizes
/// of [`ConstrainedKinematics`]; `K = 6 − R` and `M = K + N − I` are checked at compile time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Controller<
    T: RealField + Copy,
    const N: usize,
    const I: usize,
    const R: usize,
    const K: usize,
    const M: usize,
> {
    /// Gains and methods.
    pub config: ControllerConfig<T>,
    fi: FilteredInverse<T, 6, M>,
    fi_started: bool,
}

/// Splits `e` on `H`'s linear part: `H_v e`.
fn h_linear<T: RealField + Copy, const R: usize>(
    h: &SMatrix<T, R, 6>,
    e: &Vector3<T>,
) -> SVector<T, R> {
    h.fixed_columns::<3>(0) * e
}

impl<
        T: RealField + Copy,
        const N: usize,
        const I: usize,
        const R: usize,
        const K: usize,
        const M: usize,
    > Controller<T, N, I, R, K, M>
{
    const SIZES_OK: () = assert!(K + R == 6 && M == K + N - I && I <= N && R >= 1);

    /// A controller; with [`Method::Fi`], `Θ` starts at `(J^r_0e)†` on the first step.
    pub fn new(config: ControllerConfig<T>) -> Self {
        #[allow(clippy::let_unit_value)]
        let () = Self::SIZES_OK;
        Controller {
            config,
            fi: FilteredInverse::new(SMatrix::zeros()),
            fi_started: false,
        }
    }

    /// The filtered-inverse state `Θ`.
    pub fn theta(&self) -> &SMatrix<T, M, 6> {
        &self.fi.theta
    }

    /// Restarts the filtered inverse (it re-initialises on the next step).
    pub fn reset(&mut self) {
        self.fi_started = false;
    }

    /// One control step at joints `q`; `dt` is the sample time (used by the filtered inverse).
    pub fn step<Kin: ConstrainedKinematics<T, N, I, R, K, M>>(
        &mut self,
        kin: &Kin,
        q: &SVector<T, N>,
        reference: &Reference<T>,
        rcm: &Rcm<T, R>,
        dt: T,
    ) -> Result<StepOutput<T, N, R>, ControlError>
    where
        Const<R>: SquareDim,
        Const<I>: SquareDim,
        Const<M>: SquareDim,
    {
        let c = self.config;
        // 1. l_a from the trocar point, and the kinematics there.
        let (l_a, s) = kin.evaluate_at_trocar(q, &rcm.trocar)?;
        let h = kin.h();

        // 2. Lateral offset of the trocar from the link, in F_r (R_ir = I), and drift correction.
        let p_0r = s.g_0i.translation + s.g_0i.rotation.column(1) * l_a;
        let lateral_error = h_linear(&h, &(s.g_0i.rotation.transpose() * (rcm.trocar - p_0r)));
        let dv_0r = rcm.dv + lateral_error * c.kr;

        // 3. Cartesian law (2.66) with the quaternion error (2.62)–(2.65).
        let r_0e = s.g_0e.rotation;
        let rt = r_0e.transpose();
        let ep = rt * (reference.position - s.g_0e.translation);
        let eq = orientation_error(&reference.rotation, &r_0e);
        let uo = rt * (reference.angular_velocity + eq.eps * c.ko);
        let up = rt * reference.velocity + ep * c.kp - uo.cross(&ep);
        let u = Vector6::new(up.x, up.y, up.z, uo.x, uo.y, uo.z);

        // 4. [v0i; θ̇_jn] = J_inv (u − J_c dv_0r) (3.34).
        let dv_e = u - s.jc * dv_0r;
        let jr = PreparedJacobian::new(&s.jr);
        let jb0i = PreparedJacobian::new(&s.jb0i);
        let w_r = jr.manipulability();
        let w_i = jb0i.manipulability();
        let mut kappa_r = T::zero();
        let x: SVector<T, M> = match c.method {
            Method::Pinv => jr.solve(T::zero(), &dv_e).ok_or(ControlError::SingularJr)?,
            Method::Dls(d) => {
                kappa_r = d.kappa(w_r);
                jr.solve(kappa_r, &dv_e).ok_or(ControlError::SingularJr)?
            }
            Method::Fi { gamma_r, gamma_l } => {
                if !self.fi_started {
                    self.fi = FilteredInverse::new(pinv(&s.jr).ok_or(ControlError::SingularJr)?);
                    self.fi_started = true;
                }
                let x = self.fi.inverse(&s.jr) * dv_e;
                self.fi.update(&s.jr, gamma_r, gamma_l, dt);
                x
            }
        };

        // 5. V^B_0i = Λ# v0i + Λ† dv_0r (3.33); θ̇_1..i = J^B_0i^inv V^B_0i (3.18).
        let v0i: SVector<T, K> = x.fixed_rows::<K>(0).into_owned();
        let v_0i = s.lambda_sharp * v0i + s.lambda_pinv * dv_0r;
        let kappa_i = c.jb0i_damping.map_or(T::zero(), |d| d.kappa(w_i));
        let qd_i = jb0i
            .solve(kappa_i, &v_0i)
            .ok_or(ControlError::SingularJb0i)?;

        let mut qd = SVector::<T, N>::zeros();
        for k in 0..I {
            qd[k] = qd_i[k];
        }
        for k in I..N {
            qd[k] = x[K + k - I];
        }
        if !qd.iter().all(|v| v.is_finite()) {
            return Err(ControlError::NonFinite);
        }
        Ok(StepOutput {
            qd,
            l_a,
            ep,
            eq,
            u,
            lateral_error,
            dv_0r,
            w_r,
            w_i,
            kappa_r,
            kappa_i,
        })
    }
}
