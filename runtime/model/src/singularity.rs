//! When a matrix counts as singular: one rule for every place that reports a singularity — the
//! closed forms and the numeric runtime behind `trocar eval` (the constrained Jacobian `J^r`,
//! the task Jacobian `S J^r`, `J^B_0i`), and the closed-chain solvers (`J_Cp`, the reduced
//! Jacobian).
//!
//! A matrix with singular values `σ_1 ≥ … ≥ σ_k` has the numerical rank
//! `#{σ_i > RELATIVE_TOLERANCE · max(σ_1, 1)}`, and is singular when that is below `k`. The
//! tolerance is relative to the largest singular value, and to 1 when all of them are smaller
//! (so that a matrix of rounding noise, all of whose entries are 1e-17, is singular too). With
//! `RELATIVE_TOLERANCE = 1e-9` a closed form evaluated in `f64` (rounding of order 1e-16
//! relative) is well clear of it at a regular configuration, and a singular one is reported
//! whether the closed form's rounding leaves `det` at exactly 0, at 1e-16, or at −1e-16.

/// The relative tolerance on singular values (see the module documentation).
pub const RELATIVE_TOLERANCE: f64 = 1e-9;

/// The numerical rank of a matrix from its singular values (in any order):
/// `#{σ_i > RELATIVE_TOLERANCE · max(σ_max, 1)}`. A NaN singular value does not count.
pub fn rank(singular_values: &[f64]) -> usize {
    let tol = threshold(singular_values);
    singular_values.iter().filter(|&&s| s > tol).count()
}

/// The bound a singular value must exceed to count: `RELATIVE_TOLERANCE · max(σ_max, 1)`.
pub fn threshold(singular_values: &[f64]) -> f64 {
    let max = singular_values.iter().copied().fold(0.0_f64, f64::max);
    RELATIVE_TOLERANCE * max.max(1.0)
}

/// Whether a matrix whose `full` = min(rows, cols) singular values are `singular_values` is
/// singular (rank-deficient) by [`rank`].
pub fn is_singular(singular_values: &[f64], full: usize) -> bool {
    rank(singular_values) < full
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rank_is_relative_to_the_largest_singular_value() {
        assert_eq!(rank(&[2.0, 1.0, 1e-8]), 3);
        assert_eq!(rank(&[2.0, 1.0, 1.9e-9]), 2);
        assert_eq!(rank(&[1e3, 1e-5]), 2);
        assert_eq!(rank(&[1e3, 0.9e-6]), 1);
        // Below 1, the bound is absolute.
        assert_eq!(rank(&[1e-12, 1e-13]), 0);
        assert_eq!(rank(&[f64::NAN, 1.0]), 1);
        assert!(is_singular(&[1.0, 1.763e-16], 2));
        assert!(!is_singular(&[1.0, 0.1], 2));
        assert!(is_singular(&[], 1));
    }
}
