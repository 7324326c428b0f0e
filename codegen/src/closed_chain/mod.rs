//! Closed planar mechanisms (second source: Freitas, Leite & Lizarralde, CBA 2010): the reduced Jacobian in closed form.
//!
//! Equation numbers refer to G. M. Freitas, A. C. Leite, F. Lizarralde, *Controle de sistemas
//! robóticos com restrições cinemáticas*, CBA 2010. A mechanism is the symbolic model
//! [`trocar_model::closed_chain::MechanismModel`] (`runtime/model/robots/mechanisms/*.toml`): open
//! planar chains that all reach one common frame, joints split into active `θ_a` and passive `θ_p`.
//!
//! [`derive_mechanism`] carries the numeric construction of trocar-sim (`Mechanism::differential`)
//! out on symbols:
//!
//! 1. Each chain's pose: angles add, so the frame's rotation is `(cos Σθ, sin Σθ)` expanded into
//!    products of `s_k, c_k`; positions are sums of lengths times those (`l cos(Σθ)`,
//!    `l sin(Σθ)`); a prismatic joint adds `θ_k` times its direction.
//! 2. Chain Jacobians `S J_k` (15)–(16), (26)–(28): a revolute column is
//!    `(−(y_e − y_k), x_e − x_k, 1)`, a prismatic one `(R_k a, 0)`.
//! 3. `J_C = Ã J` (rows `J_1 − J_k`, `k = 2..m`) and `J_A = S_x A† J = S_x (1/m) Σ_k J_k`
//!    (17)–(19), (29)–(31), split into active/passive columns (5)–(6).
//! 4. With `J_Cp` square: `det J_Cp` and its adjugate (cofactors, exact), so that
//!    `J = (det(J_Cp) J_Aa − J_Ap adj(J_Cp) J_Ca) / det(J_Cp)` (8) and
//!    `θ̇_p = −adj(J_Cp) J_Ca θ̇_a / det(J_Cp)` (7): numerators and the denominator are
//!    polynomials, and the only division is by `det J_Cp`, which vanishes exactly at the
//!    parallel (actuator) singularities.
//!
//! Every function is a function of **all** joint values, active and passive: the caller solves the
//! passive joints (for the four-bar linkage with the closed form `FourBar::passive` of
//! trocar-sim, which needs `acos`, or with Newton's method, `Mechanism::solve_passive`). Off the
//! constraint manifold the results are those of the same formulas, as in the numeric reference.
//!
//! Lengths (`x`, `y` of `base`, `tip` and `origin`) may be expressions of the parameters (`+ − * /`,
//! parentheses, `pi`, parsed once by trocar-model into an
//! [`Expr`](trocar_model::expr::Expr), made a polynomial by [`Poly::from_expr`](crate::symbolic::Poly::from_expr)
//! as serial lengths are); they stay symbolic and
//! become fields of the generated `Params`. Fixed
//! angles must be constants (numbers and `pi`): their sines and cosines are exact for multiples
//! of `π/2`, and the `f64` values otherwise. Mechanisms whose `J_Cp` is not square (more
//! structural equations than passive joints, such as cooperating arms with point contacts) are
//! rejected with an error, as are contact models.
//!
//! Lowering (`lower::mechanism`) turns a [`MechanismDerivation`] into a module's programs and
//! the Rust backend (`emit::mechanism`) into its module.

mod derive;

pub use derive::{
    derive, derive_mechanism, length_poly, MechanismDerivation, MechanismError, MAX_LENGTH_TERMS,
    MAX_PASSIVE,
};
