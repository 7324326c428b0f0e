//! Kinematic control and redundancy resolution (§4.3, §5.5, (44)–(46)).
//!
//! `u = J†(ẋ_d + K e) + (I − J†J) u_0` (45), with `u_0 = K_0 ∂f/∂θ_a` (46) for an objective `f`:
//! manipulability `sqrt(det J Jᵀ)`, joint-limit distance
//! `−(1/2n) Σ ((θ_i − θ̄_i)/(θ_Mi − θ_mi))²` or obstacle distance `min ‖p(θ) − p_o‖`.
//! For a non-redundant mechanism (`J` square) this is `u = J⁻¹(ẋ_d + K e)`.
//!
//! When a mechanism has more constraints than passive joints (cooperating arms), admissible
//! active velocities also satisfy `Cᵀ J_Ca u = −k Cᵀ c` ([`super::Reduced::active_constraint`]);
//! these rows are stacked under `J` before the pseudo-inverse, so the null-space term moves the
//! arms only through admissible internal motions and never disturbs the task.
//!
//! `∂f/∂θ_a` is the total derivative through the constraint: with `θ̇_p = P θ̇_a` (7),
//! `∂f/∂θ_a = g_a + Pᵀ g_p` where `g = ∂f/∂θ`; then `ḟ = (∂f/∂θ_a)ᵀ u`, so the null-space term
//! raises `f` at the rate `K_0 ‖(I − J†J) ∂f/∂θ_a‖² ≥ 0`.

use super::error::{ClosedChainError, SingularityKind};
use super::mechanism::Mechanism;
use crate::linalg::{self, as_slice, stack_rows};
use faer::{Col, Mat};

/// Objective functions `f(θ_a)` of (46), to be increased in the null space.
#[derive(Clone, Debug, PartialEq)]
pub enum Objective {
    /// Manipulability `sqrt(det(J Jᵀ))` of the reduced Jacobian (8).
    Manipulability,
    /// Distance from the joint limits `−(1/2n) Σ ((θ_i − θ̄_i)/(θ_Mi − θ_mi))²` over the active
    /// joints with limits (`θ̄_i` the middle of the range; the source says "geometric mean").
    JointLimits,
    /// Distance `min ‖p(θ) − p_o‖` from a point obstacle `p_o` to the structure (segments between
    /// consecutive joint frames of every chain).
    ObstacleDistance {
        /// The obstacle point `p_o`.
        point: [f64; 2],
    },
}

impl Objective {
    /// Short name (`manipulability`, `joint-limits`, `obstacle`).
    pub fn name(&self) -> &'static str {
        match self {
            Objective::Manipulability => "manipulability",
            Objective::JointLimits => "joint-limits",
            Objective::ObstacleDistance { .. } => "obstacle",
        }
    }

    /// `f(θ)` at a configuration.
    pub fn value(&self, mech: &Mechanism, theta: &Col<f64>) -> Result<f64, ClosedChainError> {
        mech.check_theta(theta)?;
        let v = match self {
            Objective::Manipulability => manipulability(&mech.reduced(theta)?.jacobian),
            Objective::JointLimits => {
                let mut n = 0usize;
                let mut s = 0.0;
                for &i in mech.active_indices() {
                    let j = mech.joints().nth(i).expect("index in range");
                    if let Some([lo, hi]) = j.limits {
                        let mid = 0.5 * (lo + hi);
                        s += ((theta[i] - mid) / (hi - lo)).powi(2);
                        n += 1;
                    }
                }
                if n == 0 {
                    return Err(ClosedChainError::Option {
                        field: "objective".into(),
                        message: "joint-limit objective: no active joint has `limits`".into(),
                    });
                }
                -s / (2.0 * n as f64)
            }
            Objective::ObstacleDistance { point } => {
                let mut best = f64::INFINITY;
                for line in mech.polylines(theta) {
                    for w in line.windows(2) {
                        best = best.min(segment_distance(*point, w[0], w[1]));
                    }
                }
                best
            }
        };
        if !v.is_finite() {
            return Err(ClosedChainError::NonFinite {
                what: format!("objective `{}`", self.name()),
            });
        }
        Ok(v)
    }

    /// `∂f/∂θ_a` through the constraint (see the module docs): central differences of `f` in
    /// every joint (step `1e-6`), then `g_a + Pᵀ g_p` with `P = −J_Cp⁻¹ J_Ca` (7).
    pub fn gradient(
        &self,
        mech: &Mechanism,
        theta: &Col<f64>,
    ) -> Result<Col<f64>, ClosedChainError> {
        let n = mech.n_joints();
        let h = 1e-6;
        let mut g = Col::zeros(n);
        for i in 0..n {
            let mut tp = theta.clone();
            tp[i] += h;
            let mut tm = theta.clone();
            tm[i] -= h;
            g[i] = (self.value(mech, &tp)? - self.value(mech, &tm)?) / (2.0 * h);
        }
        let red = mech.reduced(theta)?;
        let (ga, gp) = mech.split(&g);
        Ok(ga + red.passive_map.transpose() * gp)
    }
}

/// Manipulability `w = sqrt(det(J Jᵀ))` = product of the singular values (46).
pub fn manipulability(j: &Mat<f64>) -> f64 {
    if j.nrows() == 0 {
        return 1.0;
    }
    if j.nrows() > j.ncols() {
        return 0.0;
    }
    linalg::singular_values(j.as_ref()).iter().product()
}

fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ((p[0] - a[0] - t * dx).powi(2) + (p[1] - a[1] - t * dy).powi(2)).sqrt()
}

/// The resolved rates of (44)–(45): `u = J_s† w + (I − J_s† J_s) u_0` with `J_s = [J; C]`,
/// `w = [ẋ_d + K e; c_rhs]`.
///
/// `task` is `ẋ_d + K e`; `constraint`/`constraint_rhs` are extra equality rows on `u` (may be
/// empty); `u0` the null-space velocity (`None` for zero). Errors with a serial singularity when
/// the stacked rows lose rank (the task cannot be followed), and on wrong sizes or non-finite
/// input.
pub fn resolve(
    j: &Mat<f64>,
    task: &Col<f64>,
    constraint: &Mat<f64>,
    constraint_rhs: &Col<f64>,
    u0: Option<&Col<f64>>,
) -> Result<Col<f64>, ClosedChainError> {
    let n = j.ncols();
    if task.nrows() != j.nrows() {
        return Err(ClosedChainError::Dimension {
            what: "task velocity ẋ_d + K e".into(),
            expected: j.nrows(),
            got: task.nrows(),
        });
    }
    if constraint.ncols() != n || constraint_rhs.nrows() != constraint.nrows() {
        return Err(ClosedChainError::Dimension {
            what: "constraint rows".into(),
            expected: n,
            got: constraint.ncols(),
        });
    }
    if let Some(u0) = u0 {
        if u0.nrows() != n {
            return Err(ClosedChainError::Dimension {
                what: "null-space velocity u0".into(),
                expected: n,
                got: u0.nrows(),
            });
        }
        if as_slice(u0).iter().any(|x| !x.is_finite()) {
            return Err(ClosedChainError::NonFinite {
                what: "null-space velocity u0".into(),
            });
        }
    }
    if as_slice(task)
        .iter()
        .chain(as_slice(constraint_rhs))
        .any(|x| !x.is_finite())
        || !linalg::all_finite(j.as_ref())
        || !linalg::all_finite(constraint.as_ref())
    {
        return Err(ClosedChainError::NonFinite {
            what: "task Jacobian or velocity".into(),
        });
    }
    let rows = j.nrows() + constraint.nrows();
    let js = stack_rows(j.as_ref(), constraint.as_ref());
    let w = Col::from_fn(rows, |k| {
        if k < j.nrows() {
            task[k]
        } else {
            constraint_rhs[k - j.nrows()]
        }
    });
    if linalg::rank(js.as_ref()) < rows {
        return Err(ClosedChainError::Singular {
            kind: SingularityKind::Serial,
            what: "task Jacobian J (with the admissibility rows)".into(),
            sigma_min: linalg::sigma_min(js.as_ref()),
        });
    }
    let pinv = linalg::pseudo_inverse(js.as_ref()).ok_or_else(|| ClosedChainError::NonFinite {
        what: "task Jacobian J (with the admissibility rows)".into(),
    })?;
    let mut u = &pinv * w;
    if let Some(u0) = u0 {
        let p = Mat::<f64>::identity(n, n) - &pinv * &js;
        u += p * u0;
    }
    Ok(u)
}

/// The null-space projector `I − J_s† J_s` of (44) for the stacked rows `J_s = [J; C]` (`NaN`
/// entries when `J_s` is not finite).
pub fn null_projector(j: &Mat<f64>, constraint: &Mat<f64>) -> Mat<f64> {
    let n = j.ncols();
    let js = stack_rows(j.as_ref(), constraint.as_ref());
    let pinv = linalg::pseudo_inverse(js.as_ref())
        .unwrap_or_else(|| Mat::from_fn(n, js.nrows(), |_, _| f64::NAN));
    Mat::<f64>::identity(n, n) - pinv * js
}
