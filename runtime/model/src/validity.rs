//! One rule for every number trocar takes from a user: the numbers of a description (positions,
//! angles, axes, matrices, parameter values), `--param` values and joint values alike.
//!
//! A number is accepted when it is finite, not subnormal (a nonzero below `f64::MIN_POSITIVE`
//! ≈ 2.2e-308 is rounding debris, and dividing by one overflows), and within ±[`MAX_MAGNITUDE`]
//! (SI units: metres, radians). Beyond that no kinematic quantity is meaningful — at 1e6 the
//! spacing of `f64` is already 1.2e-10 — and squares of such numbers overflow on the way to a
//! Jacobian or a manipulability (a joint value of 1.4e154 made the numeric forward kinematics
//! NaN).

use std::fmt;

/// The largest magnitude accepted for any number (SI units).
pub const MAX_MAGNITUDE: f64 = 1e6;

/// Why a number is refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NumberProblem {
    /// NaN or ±∞.
    NotFinite,
    /// Nonzero and below `f64::MIN_POSITIVE` in magnitude.
    Subnormal,
    /// Beyond ±[`MAX_MAGNITUDE`].
    TooLarge,
}

impl fmt::Display for NumberProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NumberProblem::NotFinite => f.write_str("is not finite (inf or nan)"),
            NumberProblem::Subnormal => f.write_str(
                "is subnormal (nonzero below 2.2e-308: rounding debris; write 0 or a normal number)",
            ),
            NumberProblem::TooLarge => {
                write!(f, "is beyond ±{MAX_MAGNITUDE:e} (metres, radians)")
            }
        }
    }
}

/// Checks one number against the rule of this module.
pub fn check(v: f64) -> Result<(), NumberProblem> {
    if !v.is_finite() {
        Err(NumberProblem::NotFinite)
    } else if v != 0.0 && v.abs() < f64::MIN_POSITIVE {
        Err(NumberProblem::Subnormal)
    } else if v.abs() > MAX_MAGNITUDE {
        Err(NumberProblem::TooLarge)
    } else {
        Ok(())
    }
}

/// The first refused number of `values`: its index and why.
pub fn check_all(values: &[f64]) -> Result<(), (usize, NumberProblem)> {
    values
        .iter()
        .enumerate()
        .try_for_each(|(k, &v)| check(v).map_err(|p| (k, p)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rule() {
        for ok in [0.0, -0.0, 1.0, -3.5, 1e-300, f64::MIN_POSITIVE, 1e6, -1e6] {
            assert_eq!(check(ok), Ok(()), "{ok:e}");
        }
        assert_eq!(check(f64::NAN), Err(NumberProblem::NotFinite));
        assert_eq!(check(f64::NEG_INFINITY), Err(NumberProblem::NotFinite));
        assert_eq!(check(1e-320), Err(NumberProblem::Subnormal));
        assert_eq!(check(-5e-324), Err(NumberProblem::Subnormal));
        assert_eq!(check(1.0000001e6), Err(NumberProblem::TooLarge));
        assert_eq!(check(1e308), Err(NumberProblem::TooLarge));
        assert_eq!(
            check_all(&[0.1, 2.0, 1e155, f64::NAN]),
            Err((2, NumberProblem::TooLarge))
        );
        // The messages say what is wrong, with the bound.
        assert!(NumberProblem::TooLarge.to_string().contains("1e6"));
    }
}
