//! Fixed-size dense linear algebra of the core, one implementation of each: the LU factorisation
//! ([`Lu`], [`determinant`]), the root-free Cholesky factorisation of Gram matrices
//! ([`Cholesky`]), the Moore–Penrose pseudo-inverse of a full-rank matrix
//! ([`pseudo_inverse_apply`], [`pseudo_inverse`]), damped least squares (3.43), (3.46)
//! ([`damped_solve`]) and the null space of constraint rows ([`null_space_of_rows`]).
//!
//! Everything is allocation-free on `nalgebra` fixed-size matrices and builds without `std`. The
//! constraint (`Λ†`, `Λ#`), the manipulability, the controller's inverses and its null-space
//! objectives call these.

mod cholesky;
mod damped;
mod lu;
mod null_space;
mod pinv;

pub(crate) use cholesky::gram_lower;
pub use cholesky::Cholesky;
pub use damped::damped_solve;
pub(crate) use lu::as_square;
pub use lu::{determinant, Lu, SquareDim};
pub use null_space::{null_space_of_rows, RowsError};
pub use pinv::{pseudo_inverse, pseudo_inverse_apply};
