//! Exact rational coefficients and the policy for reading `f64` numbers from descriptions.
//!
//! Coefficients are arbitrary-precision rationals ([`num_rational::BigRational`]): arithmetic is
//! exact and cannot overflow, so nothing ever wraps or panics silently.
//!
//! **Reading `f64` (rule [`Rational::from_f64_decimal`], "exact decimal").** A number from a
//! description is read as the shortest decimal string that round-trips to the same `f64` (Rust's
//! `{:e}` formatting), and that decimal is taken exactly: `0.194 → 97/500`, `0.33 → 33/100`.
//! Numbers written as decimals in a file are therefore exactly what the author meant.
//! Numbers that are not small rationals (sines of rpy angles, `1/√2` axes, random test chains)
//! cannot be exact: they become the rational value of that shortest decimal, which differs from
//! the `f64` by less than half an ulp. Results then agree with `f64` kinematics to rounding
//! (≈1e-15 relative), well inside the 1e-12 contract, but identities such as `R Rᵀ = I` hold only
//! to that accuracy, not symbolically.
//!
//! **Bounded exactness (rule [`Rational::bounded`], "float stays float").** A result of
//! arithmetic whose numerator and denominator together need more than [`EXACT_BITS`] bits is
//! rounded to the nearest `f64` (kept as the exact dyadic rational of that `f64`). Small
//! rationals — the thesis's robots, decimals such as `0.194`, `1/2`, `l_a⁻¹` — are never that
//! long and stay exact, so their symbolic identities still hold exactly; a calibrated robot's
//! float geometry (17-digit axes and offsets) stays floating instead of growing into fractions
//! of hundreds of digits along the chain.
//!
//! **Snapping (rule [`Rational::from_f64_snapped`], "snap unit").** Rotation entries within
//! `1e-15` of `0`, `1` or `−1` are taken as exactly that value, so that `rpy = (0, 0, π/2)` gives
//! an exact permutation matrix.

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{One, Signed, ToPrimitive, Zero};
use std::fmt;
use std::ops::{Add, Mul, Neg, Sub};

/// Longest exact coefficient, in bits of numerator plus denominator (rule "float stays float",
/// [`Rational::bounded`]). A 17-digit decimal needs about 114.
pub const EXACT_BITS: u64 = 128;

/// Tolerance of the "snap unit" rule.
pub const SNAP_TOLERANCE: f64 = 1e-15;

/// An exact rational number (normalised, positive denominator).
#[derive(Clone, PartialEq, Eq, PartialOrd, Ord, Hash, Debug)]
pub struct Rational(BigRational);

/// A number that cannot be read (NaN or infinite).
#[derive(Clone, Debug, PartialEq)]
pub struct NotFinite(pub f64);

impl fmt::Display for NotFinite {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "number {} is not finite", self.0)
    }
}

impl std::error::Error for NotFinite {}

impl Rational {
    /// Zero.
    pub fn zero() -> Self {
        Rational(BigRational::zero())
    }

    /// One.
    pub fn one() -> Self {
        Rational(BigRational::one())
    }

    /// An integer.
    pub fn integer(i: i64) -> Self {
        Rational(BigRational::from_integer(BigInt::from(i)))
    }

    /// `num / den`, or `None` when `den == 0`.
    pub fn new(num: i64, den: i64) -> Option<Self> {
        if den == 0 {
            None
        } else {
            Some(Rational(BigRational::new(
                BigInt::from(num),
                BigInt::from(den),
            )))
        }
    }

    /// Rule "exact decimal": the exact value of the shortest round-trip decimal of `x`.
    ///
    /// `0.194 → 97/500`; `1e-3 → 1/1000`; `-2.5 → -5/2`.
    pub fn from_f64_decimal(x: f64) -> Result<Self, NotFinite> {
        if !x.is_finite() {
            return Err(NotFinite(x));
        }
        if x == 0.0 {
            return Ok(Self::zero());
        }
        // `{:e}` prints the shortest round-trip digits: "-1.94e-1".
        let s = format!("{x:e}");
        let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
        let exponent: i64 = exponent.parse().unwrap_or(0);
        let (negative, mantissa) = match mantissa.strip_prefix('-') {
            Some(m) => (true, m),
            None => (false, mantissa),
        };
        let (int_part, frac_part) = mantissa.split_once('.').unwrap_or((mantissa, ""));
        let digits = format!("{int_part}{frac_part}");
        let mut num: BigInt = digits.parse().unwrap_or_else(|_| BigInt::zero());
        if negative {
            num = -num;
        }
        let scale = exponent - frac_part.len() as i64;
        let ten = BigInt::from(10u32);
        let pow = num_traits::pow(ten, scale.unsigned_abs() as usize);
        Ok(if scale >= 0 {
            Rational(BigRational::from_integer(num * pow))
        } else {
            Rational(BigRational::new(num, pow))
        })
    }

    /// Rule "snap unit": `0`, `1`, `−1` when `x` is within [`SNAP_TOLERANCE`] of one of them,
    /// otherwise [`Rational::from_f64_decimal`].
    pub fn from_f64_snapped(x: f64) -> Result<Self, NotFinite> {
        for target in [0.0, 1.0, -1.0] {
            if (x - target).abs() <= SNAP_TOLERANCE {
                return Ok(Self::integer(target as i64));
            }
        }
        Self::from_f64_decimal(x)
    }

    /// Is this zero?
    pub fn is_zero(&self) -> bool {
        self.0.is_zero()
    }

    /// Is this one?
    pub fn is_one(&self) -> bool {
        self.0.is_one()
    }

    /// Is this negative?
    pub fn is_negative(&self) -> bool {
        self.0.is_negative()
    }

    /// Is this an integer?
    pub fn is_integer(&self) -> bool {
        self.0.is_integer()
    }

    /// Absolute value.
    pub fn abs(&self) -> Self {
        Rational(self.0.abs())
    }

    /// `1/x`, or `None` for zero.
    pub fn checked_recip(&self) -> Option<Self> {
        if self.is_zero() {
            None
        } else {
            Some(Rational(self.0.recip()))
        }
    }

    /// Rule "float stays float": `self` when its numerator and denominator together fit in
    /// [`EXACT_BITS`] bits, otherwise the nearest `f64` as an exact rational (unless that is
    /// not finite: then `self`).
    pub fn bounded(self) -> Self {
        if self.0.numer().bits() + self.0.denom().bits() <= EXACT_BITS {
            return self;
        }
        match self.0.to_f64().and_then(BigRational::from_float) {
            Some(r)
                if r.numer().bits() + r.denom().bits()
                    < self.0.numer().bits() + self.0.denom().bits() =>
            {
                Rational(r)
            }
            _ => self,
        }
    }

    /// Bits of the numerator plus bits of the denominator: how long the coefficient is.
    pub fn bits(&self) -> u64 {
        self.0.numer().bits() + self.0.denom().bits()
    }

    /// The nearest `f64` (correctly rounded by `num-rational`; `±inf` beyond range).
    pub fn to_f64(&self) -> f64 {
        self.0.to_f64().unwrap_or(f64::NAN)
    }

    /// Numerator and denominator (denominator positive), as decimal strings, for emitters that
    /// want to print exact literals.
    pub fn to_parts(&self) -> (String, String) {
        (self.0.numer().to_string(), self.0.denom().to_string())
    }

    /// The underlying big rational.
    pub fn as_big(&self) -> &BigRational {
        &self.0
    }
}

impl fmt::Display for Rational {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0.is_integer() {
            write!(f, "{}", self.0.numer())
        } else {
            write!(f, "{}/{}", self.0.numer(), self.0.denom())
        }
    }
}

impl Add for &Rational {
    type Output = Rational;
    fn add(self, rhs: &Rational) -> Rational {
        Rational(&self.0 + &rhs.0).bounded()
    }
}

impl Sub for &Rational {
    type Output = Rational;
    fn sub(self, rhs: &Rational) -> Rational {
        Rational(&self.0 - &rhs.0).bounded()
    }
}

impl Mul for &Rational {
    type Output = Rational;
    fn mul(self, rhs: &Rational) -> Rational {
        Rational(&self.0 * &rhs.0).bounded()
    }
}

impl Neg for &Rational {
    type Output = Rational;
    fn neg(self) -> Rational {
        Rational(-&self.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rule_exact_decimal() {
        assert_eq!(
            Rational::from_f64_decimal(0.194).unwrap(),
            Rational::new(97, 500).unwrap()
        );
        assert_eq!(
            Rational::from_f64_decimal(-2.5).unwrap(),
            Rational::new(-5, 2).unwrap()
        );
        assert_eq!(
            Rational::from_f64_decimal(1e-3).unwrap(),
            Rational::new(1, 1000).unwrap()
        );
        assert_eq!(
            Rational::from_f64_decimal(1.037e3).unwrap(),
            Rational::integer(1037)
        );
        assert_eq!(Rational::from_f64_decimal(0.0).unwrap(), Rational::zero());
        assert!(Rational::from_f64_decimal(f64::NAN).is_err());
        // Irrational constants: within half an ulp of the f64.
        let x = 0.3f64.sin();
        assert_eq!(Rational::from_f64_decimal(x).unwrap().to_f64(), x);
        let tiny = 1e-300;
        assert_eq!(Rational::from_f64_decimal(tiny).unwrap().to_f64(), tiny);
    }

    #[test]
    fn rule_float_stays_float() {
        // Small rationals stay exact through arithmetic.
        let a = Rational::new(97, 500).unwrap();
        let b = Rational::new(1, 3).unwrap();
        assert_eq!(&(&a * &b) * &Rational::integer(3), a);
        // A product of long decimals is rounded to the nearest f64, not kept as a long fraction.
        let x = Rational::from_f64_decimal(0.3f64.sin()).unwrap();
        let y = Rational::from_f64_decimal(0.7f64.cos()).unwrap();
        let p = &x * &y;
        let (n, d) = (p.as_big().numer().bits(), p.as_big().denom().bits());
        assert!(n + d <= 2 * 64, "{n} + {d} bits");
        let exact = BigRational::from_float(0.3f64.sin()).unwrap()
            * BigRational::from_float(0.7f64.cos()).unwrap();
        let err = ((p.as_big() - &exact) / &exact).to_f64().unwrap().abs();
        assert!(err < 2e-16, "{err}");
        // Far beyond f64's range it stays exact rather than becoming infinite.
        let big = Rational(BigRational::from_integer(num_traits::pow(
            BigInt::from(3u32),
            700,
        )));
        assert!((&big * &Rational::new(1, 7).unwrap())
            .to_f64()
            .is_infinite());
    }

    #[test]
    fn rule_snap_unit() {
        let half_pi = std::f64::consts::FRAC_PI_2;
        assert_eq!(
            Rational::from_f64_snapped(half_pi.cos()).unwrap(),
            Rational::zero()
        );
        assert_eq!(
            Rational::from_f64_snapped(1.0 - 1e-16).unwrap(),
            Rational::one()
        );
        assert_eq!(
            Rational::from_f64_snapped(-1.0 + 4e-16).unwrap(),
            Rational::integer(-1)
        );
        assert_eq!(
            Rational::from_f64_snapped(0.5).unwrap(),
            Rational::new(1, 2).unwrap()
        );
        assert!(!Rational::from_f64_snapped(1e-10).unwrap().is_zero());
    }
}
