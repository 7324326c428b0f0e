//! Where the port is: the point nearest to the instrument's shaft lines.
//!
//! The thesis takes the trocar as known — a fixed point, or one that moves as given ((3.33)–
//! (3.34)) — and names an incision point that must be found and followed as its next step
//! (§5.2). After insertion the port's place in the robot's frame is known only roughly; the
//! shaft, though, passes through it in every pose. So the poses of an instrument pivoting about
//! its port (moved by hand, or by a short pivoting motion) locate it: the port is the point
//! nearest to all the shaft's lines in the least-squares sense,
//!
//! ```text
//! p̂ = argmin_x Σ_k w_k ‖P_k (x − a_k)‖²,   P_k = I − d_k d_kᵀ,
//! (Σ_k w_k P_k) p̂ = Σ_k w_k P_k a_k                                            (R1)
//! ```
//!
//! for lines through `a_k` along the unit `d_k` (each line's [`Shaft::line`] at its pose).
//! [`PortRegistration`] keeps the sums of (R1), so it takes one line at a time — a control loop
//! adds the shaft's line every step — and with a forgetting factor `λ` (`w_k = λ^(n−k)`) it
//! follows a port that moves. [`PortRegistration::estimate`] solves (R1) and says how well:
//!
//! - the lines' **spread** `s = sqrt(μ_min(A)/W)`, `A = Σ w_k P_k`, `W = Σ w_k`: the root mean
//!   square of the sines of the angles between the lines and the direction they share most (for
//!   a unit `u`, `uᵀ A u = Σ w_k sin²∠(u, d_k)`). Lines that are nearly parallel locate the
//!   port across them but not along them; below a least spread the estimate is refused
//!   ([`PortError::NearParallel`]);
//! - the **residual** `ρ = sqrt(Σ w_k ‖P_k (p̂ − a_k)‖² / W)`, the lines' root-mean-square
//!   distance from the estimate;
//! - the **covariance** `σ² A⁻¹` with `σ² = Σ w_k ‖P_k (p̂ − a_k)‖² / (2W − 3)`: each line
//!   measures the port in the two directions across it, with independent errors of variance
//!   `σ²` (the least-squares estimate of that variance from the residual). Exact for equal
//!   weights; with forgetting it is `σ² A⁻¹ (Σ w_k² P_k) A⁻¹` instead, which this overstates by
//!   up to `1 + λ` — a bound, not the figure.
//!
//! Allocation-free and `no_std`, like the controller.
//!
//! [`Shaft::line`]: crate::control::Shaft::line

use nalgebra::{Matrix3, RealField, Vector3};

/// The largest least spread (rad) that lines can reach: lines spread evenly in every direction
/// have `μ_min(A)/W = 2/3`, so no set of lines spreads by more than `asin √(2/3)` ≈ 54.7°.
pub const LARGEST_SPREAD: f64 = 0.955_316_618_124_509_3;

/// Whether `least_spread` (rad) may be asked of [`PortRegistration::estimate`] by a user: an
/// angle from 0 to [`LARGEST_SPREAD`] (a larger one could never be met).
pub fn least_spread_admitted(least_spread: f64) -> bool {
    least_spread.is_finite() && (0.0..=LARGEST_SPREAD).contains(&least_spread)
}

/// A line of the base frame: the points `point + t direction`, `direction` a unit vector.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line<T: RealField + Copy> {
    /// A point of the line.
    pub point: Vector3<T>,
    /// Its direction (unit length).
    pub direction: Vector3<T>,
}

impl<T: RealField + Copy> Line<T> {
    /// The line through `point` along `direction` (normalised here). `None` when a number is not
    /// finite or `direction` has no length.
    pub fn new(point: Vector3<T>, direction: Vector3<T>) -> Option<Self> {
        let norm = direction.norm();
        let finite = point.iter().chain(direction.iter()).all(|v| v.is_finite());
        if !finite || !norm.is_finite() || norm <= T::zero() {
            return None;
        }
        Some(Line {
            point,
            direction: direction / norm,
        })
    }

    /// The distance of `x` from the line, `‖(I − d dᵀ)(x − a)‖`.
    pub fn distance(&self, x: &Vector3<T>) -> T {
        let v = x - self.point;
        (v - self.direction * self.direction.dot(&v)).norm()
    }
}

/// Why the port could not be located, or a line not taken.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PortError {
    /// Fewer lines than two (or, with forgetting, less weight than two lines').
    TooFewLines {
        /// The lines taken so far.
        lines: usize,
    },
    /// The lines are nearly parallel: their spread (radians, the root mean square of the sines
    /// of their angles from their common direction, taken as an angle) is below the least asked.
    NearParallel {
        /// The lines' spread (rad).
        spread: f64,
        /// The least spread asked for (rad).
        least: f64,
    },
    /// A line or a setting with a number that is not finite, a direction of no length, a
    /// forgetting factor outside `(0.5, 1]`, or a step whose result would not be finite.
    Invalid,
}

impl core::fmt::Display for PortError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            PortError::TooFewLines { lines } => write!(
                f,
                "{lines} shaft line(s): the port is where two or more lines meet; take more poses"
            ),
            PortError::NearParallel { spread, least } => write!(
                f,
                "the shaft's lines are nearly parallel: their directions spread by {:.3}° (root \
                 mean square), and at least {:.3}° is needed to place the port along the shaft; \
                 pivot the instrument further about the port",
                spread.to_degrees(),
                least.to_degrees()
            ),
            PortError::Invalid => write!(
                f,
                "a shaft line with a number that is not finite or a direction of no length, or a \
                 forgetting factor outside (0.5, 1], or a step whose result would not be finite"
            ),
        }
    }
}

/// The port located from the shaft's lines ([`PortRegistration::estimate`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PortEstimate<T: RealField + Copy> {
    /// The point nearest to the lines (R1), base frame.
    pub point: Vector3<T>,
    /// Its covariance `σ² A⁻¹` (m²).
    pub covariance: Matrix3<T>,
    /// The lines' root-mean-square distance from [`PortEstimate::point`] (m).
    pub residual: T,
    /// The lines' spread (rad): the root mean square of the sines of their angles from their
    /// common direction, as an angle.
    pub spread: T,
    /// The lines taken.
    pub lines: usize,
}

impl<T: RealField + Copy> PortEstimate<T> {
    /// The standard deviation of the estimate along its least certain direction,
    /// `sqrt(λ_max(covariance))` (m): for lines pivoting little, along the shaft.
    pub fn largest_deviation(&self) -> T {
        let e = self.covariance.symmetric_eigenvalues();
        e.max().max(T::zero()).sqrt()
    }
}

/// The sums of (R1) over the shaft's lines so far, one line at a time: see the [module](self).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PortRegistration<T: RealField + Copy> {
    // The sums are kept about the first line's point `r` (each line's point taken as its point
    // nearest to `r`), so that `c` is the sum of the lines' squared distances from `r` — of the
    // size of the lines' spread about the port times its distance from `r` — and not of the
    // points' distances from the base's origin: the residual loses only that to cancellation.
    origin: Option<Vector3<T>>,
    a: Matrix3<T>,
    b: Vector3<T>,
    c: T,
    weight: T,
    lines: usize,
    forgetting: T,
}

impl<T: RealField + Copy> Default for PortRegistration<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: RealField + Copy> PortRegistration<T> {
    /// No line yet; every line weighs the same.
    pub fn new() -> Self {
        PortRegistration {
            origin: None,
            a: Matrix3::zeros(),
            b: Vector3::zeros(),
            c: T::zero(),
            weight: T::zero(),
            lines: 0,
            forgetting: T::one(),
        }
    }

    /// No line yet; each new line weighs `1/λ` times the one before (`w_k = λ^(n−k)`), so the
    /// estimate follows a port that moves, over about `1/(1 − λ)` lines. `λ` in `(0.5, 1]`: the
    /// weight of all the lines tends to `1/(1 − λ)`, which must pass two lines' for an estimate.
    pub fn with_forgetting(lambda: T) -> Result<Self, PortError> {
        let half: T = nalgebra::convert(0.5);
        if !(lambda > half && lambda <= T::one()) {
            return Err(PortError::Invalid);
        }
        Ok(PortRegistration {
            forgetting: lambda,
            ..Self::new()
        })
    }

    /// Takes one more line. A line with a number that is not finite is refused
    /// ([`PortError::Invalid`]) and changes nothing.
    pub fn add(&mut self, line: &Line<T>) -> Result<(), PortError> {
        let Some(line) = Line::new(line.point, line.direction) else {
            return Err(PortError::Invalid);
        };
        let d = line.direction;
        let origin = *self.origin.get_or_insert(line.point);
        let p = Matrix3::identity() - d * d.transpose();
        // The line's point nearest to the origin, relative to it: `P (a − r)`.
        let pa = p * (line.point - origin);
        let l = self.forgetting;
        self.a = self.a * l + p;
        self.b = self.b * l + pa;
        self.c = self.c * l + pa.norm_squared();
        self.weight = self.weight * l + T::one();
        self.lines += 1;
        Ok(())
    }

    /// The lines taken so far.
    pub fn lines(&self) -> usize {
        self.lines
    }

    /// Forgets every line.
    pub fn reset(&mut self) {
        *self = PortRegistration {
            forgetting: self.forgetting,
            ..Self::new()
        };
    }

    /// The port (R1) with its residual, spread and covariance; refused below two lines' weight
    /// ([`PortError::TooFewLines`]) or where the lines' spread is below `least_spread` (rad,
    /// [`PortError::NearParallel`]; it is never taken below `√ε`, where (R1) is singular to
    /// rounding).
    pub fn estimate(&self, least_spread: T) -> Result<PortEstimate<T>, PortError> {
        let two: T = nalgebra::convert(2.0);
        if !least_spread.is_finite() {
            return Err(PortError::Invalid);
        }
        if self.lines < 2 || self.weight < two * (T::one() - T::default_epsilon().sqrt()) {
            return Err(PortError::TooFewLines { lines: self.lines });
        }
        let a = (self.a + self.a.transpose()) * nalgebra::convert::<f64, T>(0.5);
        let eigen = a.symmetric_eigenvalues();
        let spread_sine = (eigen.min().max(T::zero()) / self.weight).sqrt();
        let spread = spread_sine.min(T::one()).asin();
        let least = least_spread.max(T::default_epsilon().sqrt());
        let to_f64 = |v: T| v.to_subset().unwrap_or(f64::NAN);
        if !spread.is_finite() || spread < least {
            return Err(PortError::NearParallel {
                spread: to_f64(spread),
                least: to_f64(least),
            });
        }
        let inverse = a.try_inverse().ok_or(PortError::NearParallel {
            spread: to_f64(spread),
            least: to_f64(least),
        })?;
        let relative = inverse * self.b;
        let point = relative + self.origin.unwrap_or_else(Vector3::zeros);
        // Σ w ‖P (x − a)‖² = yᵀ A y − 2 bᵀ y + c at `y = x − r`, never below 0 but for rounding
        // (of `√ε` times the lines' root-mean-square distance from `r`, in the residual).
        let sum =
            (relative.dot(&(a * relative)) - two * self.b.dot(&relative) + self.c).max(T::zero());
        let freedom = two * self.weight - nalgebra::convert::<f64, T>(3.0);
        let variance = if freedom > T::zero() {
            sum / freedom
        } else {
            T::zero()
        };
        let estimate = PortEstimate {
            point,
            covariance: inverse * variance,
            residual: (sum / self.weight).sqrt(),
            spread,
            lines: self.lines,
        };
        let finite = estimate
            .point
            .iter()
            .chain(estimate.covariance.iter())
            .all(|v| v.is_finite());
        if !finite {
            return Err(PortError::Invalid);
        }
        Ok(estimate)
    }
}

impl<T: RealField + Copy> Line<T> {
    /// The offset of the line from `p`: from `p` to the line's point nearest to it,
    /// `(I − d dᵀ)(a − p)`, across the line.
    pub fn offset_from(&self, p: &Vector3<T>) -> Vector3<T> {
        let v = self.point - p;
        v - self.direction * self.direction.dot(&v)
    }
}

/// The body wall at the port, acting on the shaft where it crosses the port: a spring-damper
/// across the shaft, `F = −k e − c ė`, with `e` the offset of the shaft's line from the port
/// ([`Line::offset_from`]) and `ė` its rate. The physics plant's lateral model of the wall, for
/// the kinematic simulation (the plant adds friction along the shaft, which this leaves out).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wall<T: RealField + Copy> {
    /// The lateral stiffness `k` (N/m): 4000 N/m for a shaft in 3 cm of insufflated abdominal
    /// wall (Young's modulus 42.5 kPa, `k ≈ π E h`).
    pub stiffness: T,
    /// The damping `c` (N s/m): `k τ` with a relaxation time of 10 ms, 40 N s/m.
    pub damping: T,
}

impl<T: RealField + Copy> Wall<T> {
    /// The wall of the physics plant's defaults: 4000 N/m, 40 N s/m.
    pub fn abdominal() -> Self {
        Wall {
            stiffness: nalgebra::convert(4000.0),
            damping: nalgebra::convert(40.0),
        }
    }

    /// The wall's force on the shaft (N, base frame) for the offset `e` of the shaft from the
    /// port and its rate `ė`: `−k e − c ė`.
    pub fn force(&self, offset: &Vector3<T>, offset_rate: &Vector3<T>) -> Vector3<T> {
        -(offset * self.stiffness + offset_rate * self.damping)
    }
}

/// A port that moves, followed from the wall's force on the shaft: an admittance law that moves
/// the estimate (where the controller holds the shaft) toward where the wall pushes it,
///
/// ```text
/// ṗ̂ = C (I − d dᵀ) F + α d,   ‖ṗ̂‖ ≤ v_max                                    (R2)
/// ```
///
/// with `F` the wall's force on the shaft (a wrist force/torque sensor's, or the plant's), `d`
/// the shaft's direction and `C` the compliance (m/(N s)): at rest the force across the shaft
/// is zero, the estimate on the port's line. The force says nothing of the port's place along
/// the shaft; where the wall's normal `n` is known (breathing moves the wall along it), `α`
/// takes, of the motions that explain the force, the one that moves least across `n`:
/// `α = −((I − n nᵀ) d)·((I − n nᵀ) C F⊥) / ‖(I − n nᵀ) d‖²`, so a port moving along `n` is
/// followed along the shaft too (where the shaft is at least 10° from `n`). With the shaft held
/// at the estimate, a wall `F = −k e − c ė` makes the estimate close on a still port with the time
/// constant `1/(C k) + c/k`: `C = 1/(k τ)` follows with `τ + c/k`. The estimate's rate `ṗ̂` is the
/// trocar's velocity the controller feeds forward ((3.33)–(3.34)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PortFollower<T: RealField + Copy> {
    /// The port's estimate (base frame).
    pub estimate: Vector3<T>,
    /// Its rate at the last update (m/s).
    pub rate: Vector3<T>,
    compliance: T,
    max_rate: T,
    normal: Option<Vector3<T>>,
}

impl<T: RealField + Copy> PortFollower<T> {
    /// Starts at `estimate` with the compliance `C` (m/(N s), ≥ 0) and the largest rate `v_max`
    /// (m/s, > 0); [`PortError::Invalid`] otherwise.
    pub fn new(estimate: Vector3<T>, compliance: T, max_rate: T) -> Result<Self, PortError> {
        let finite = estimate.iter().all(|v| v.is_finite());
        if !finite
            || !compliance.is_finite()
            || compliance < T::zero()
            || !max_rate.is_finite()
            || max_rate <= T::zero()
        {
            return Err(PortError::Invalid);
        }
        Ok(PortFollower {
            estimate,
            rate: Vector3::zeros(),
            compliance,
            max_rate,
            normal: None,
        })
    }

    /// The same follower, with the wall's normal `n` (any length but 0) for the part along the
    /// shaft (R2).
    pub fn with_normal(mut self, normal: Vector3<T>) -> Result<Self, PortError> {
        let norm = normal.norm();
        if !norm.is_finite() || norm <= T::zero() {
            return Err(PortError::Invalid);
        }
        self.normal = Some(normal / norm);
        Ok(self)
    }

    /// One step of (R2) over `dt` (s) from the wall's force `force` (N) on a shaft of direction
    /// `direction`: the estimate moves, and its rate is returned (and kept in
    /// [`PortFollower::rate`]). A force, direction or `dt` that is not finite (or `dt < 0`, or
    /// a direction of no length) is refused and changes nothing.
    pub fn update(
        &mut self,
        force: &Vector3<T>,
        direction: &Vector3<T>,
        dt: T,
    ) -> Result<Vector3<T>, PortError> {
        let norm = direction.norm();
        let finite = force.iter().chain(direction.iter()).all(|v| v.is_finite());
        if !finite || !norm.is_finite() || norm <= T::zero() || !dt.is_finite() || dt < T::zero() {
            return Err(PortError::Invalid);
        }
        let d = direction / norm;
        let across = force - d * d.dot(force);
        let mut rate = across * self.compliance;
        if let Some(n) = self.normal {
            // Only where the shaft is at least 10° from the normal: nearer, the part along the
            // shaft that explains a lateral motion grows as 1/sin of that angle, and a shaft
            // square to the wall is followed across only.
            let in_plane = |v: &Vector3<T>| v - n * n.dot(v);
            let pd = in_plane(&d);
            let scale = pd.norm_squared();
            let least: T = nalgebra::convert(0.030_153_689_607_045_8); // sin²(10°)
            if scale >= least {
                rate -= d * (pd.dot(&in_plane(&rate)) / scale);
            }
        }
        let speed = rate.norm();
        if speed > self.max_rate {
            rate *= self.max_rate / speed;
        }
        let estimate = self.estimate + rate * dt;
        if !rate.iter().chain(estimate.iter()).all(|v| v.is_finite()) {
            return Err(PortError::Invalid);
        }
        self.estimate = estimate;
        self.rate = rate;
        Ok(rate)
    }
}
