//! A small exact symbolic engine over joint sines and cosines and named parameters.
//!
//! - [`number`]: exact rational coefficients and the policy for reading `f64` ("exact decimal",
//!   "snap unit").
//! - [`poly`]: the canonical polynomial normal form ([`Poly`]) with its named rules
//!   (`collect_like_terms`, `exponent_add`, `pythagorean`, `inverse_of_constant`,
//!   `inverse_of_monomial`, `inverse_normalise`, `inverse_cancel`), evaluation and a parser
//!   for hand-written reference expressions.
//! - [`matrix`]: matrices of polynomials, rigid transforms and adjoints (2.21), (2.43),
//!   determinants, maximal minors and inverses.
//!
//! ```
//! use trocar_codegen::symbolic::{Poly, Env};
//! let names = ["l_a"];
//! let x = Poly::parse("s7^2 + c7^2 + l_a/l_a", &names).unwrap();
//! assert_eq!(x, Poly::integer(2));
//! let y = Poly::parse("c8*(1 + l_a*c7)", &names).unwrap();
//! let q = [0.0; 8];
//! assert_eq!(y.eval(&Env { q: &q, params: &[0.5] }), 1.5);
//! ```

pub mod matrix;
pub mod number;
pub mod poly;

pub use matrix::{rational_null_space, Matrix, Transform};
pub use number::{NotFinite, Rational};
pub use poly::{inverse_denominator, node_definition, Atom, Env, Monomial, Poly, SymbolicError};
