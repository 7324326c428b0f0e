//! The planar four-bar linkage of the source's §4 (Figure 1), with its closed-form passive joints.
//!
//! Geometry (see `robots/mechanisms/four-bar.toml`): ground joints 1 at `(−l0/2, 0)` and 2 at
//! `(l0/2, 0)`; crank `l1` (joint 1 → 3), rocker `l2` (joint 2 → 4), coupler `l3` (joint 3 → 4)
//! extended by `l4` to the end effector. Joint angles are relative; `φ = θ1 + θ3 = θ2 + θ4` (10).
//! The passive joints in closed form (source §4.1), with `l_d² = l0² + l1² − 2 l0 l1 cos θ1`:
//!
//! ```text
//! θ2 = π − acos((l0² − l1² + l_d²)/(2 l0 l_d)) − acos((l2² − l3² + l_d²)/(2 l2 l_d))
//! θ3 = π + acos((l1² − l0² + l_d²)/(2 l1 l_d)) + acos((l3² − l2² + l_d²)/(2 l3 l_d))
//! θ4 = 2π − acos((l2² + l3² − l_d²)/(2 l2 l3))
//! ```
//!
//! (the extracted source lost the `=`, `π` and sign glyphs; these are the signs of the assembly
//! branch with joint 4 above the diagonal joint 3 → joint 2, for `0 < θ1 < π`). They give the
//! source's orientation range: `φ ∈ [5.81, 7.98]` rad over `θ1 ∈ [0.7227, 2.2784]` rad.

use super::error::ClosedChainError;
use super::mechanism::Mechanism;
use faer::{Col, ColRef};
use std::f64::consts::PI;

/// Link lengths of the four-bar linkage (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FourBar {
    /// Ground link (joint 1 → joint 2).
    pub l0: f64,
    /// Crank (joint 1 → joint 3), driven by the active joint θ1.
    pub l1: f64,
    /// Rocker (joint 2 → joint 4).
    pub l2: f64,
    /// Coupler (joint 3 → joint 4).
    pub l3: f64,
    /// Coupler extension (joint 4 → end effector).
    pub l4: f64,
}

impl FourBar {
    /// The source's lengths: `l0 = 1, l1 = 1.2, l2 = 1.4, l3 = 0.6, l4 = 1.4` m.
    pub const SOURCE: FourBar = FourBar {
        l0: 1.0,
        l1: 1.2,
        l2: 1.4,
        l3: 0.6,
        l4: 1.4,
    };

    /// Reads `l0`…`l4` from a mechanism's parameters (errors name the missing parameter).
    pub fn from_mechanism(m: &Mechanism) -> Result<Self, ClosedChainError> {
        let get = |n: &str| {
            m.parameter(n).ok_or_else(|| {
                ClosedChainError::invalid(
                    format!("parameters.{n}"),
                    "the four-bar linkage needs parameters l0, l1, l2, l3, l4",
                )
            })
        };
        let fb = FourBar {
            l0: get("l0")?,
            l1: get("l1")?,
            l2: get("l2")?,
            l3: get("l3")?,
            l4: get("l4")?,
        };
        for (n, v) in [
            ("l0", fb.l0),
            ("l1", fb.l1),
            ("l2", fb.l2),
            ("l3", fb.l3),
            ("l4", fb.l4),
        ] {
            if v.is_nan() || v <= 0.0 {
                return Err(ClosedChainError::invalid(
                    format!("parameters.{n}"),
                    "link lengths must be positive",
                ));
            }
        }
        if m.n_joints() != 4 || m.active_indices() != [0] {
            return Err(ClosedChainError::invalid(
                "chains",
                "expected the four-bar layout: chain1 (theta1 active, theta3), chain2 (theta2, theta4)",
            ));
        }
        Ok(fb)
    }

    /// `l_d = |joint 3 − joint 2|`, `l_d² = l0² + l1² − 2 l0 l1 cos θ1`.
    pub fn diagonal(&self, theta1: f64) -> f64 {
        (self.l0 * self.l0 + self.l1 * self.l1 - 2.0 * self.l0 * self.l1 * theta1.cos())
            .max(0.0)
            .sqrt()
    }

    /// The range of θ1 in `(0, π)` where the loop closes (`|l2 − l3| ≤ l_d ≤ l2 + l3`); at its
    /// ends joints 2, 3, 4 align and `J_Cp` is singular.
    pub fn workspace(&self) -> (f64, f64) {
        let c = |ld: f64| {
            ((self.l0 * self.l0 + self.l1 * self.l1 - ld * ld) / (2.0 * self.l0 * self.l1))
                .clamp(-1.0, 1.0)
                .acos()
        };
        let lo = c((self.l2 - self.l3).abs().max((self.l0 - self.l1).abs()));
        let hi = c((self.l2 + self.l3).min(self.l0 + self.l1));
        (lo, hi)
    }

    /// The passive joints `(θ2, θ3, θ4)` in closed form (source §4.1). Errors outside the
    /// workspace (the loop does not close) or for θ1 outside `(0, π)`.
    pub fn passive(&self, theta1: f64) -> Result<[f64; 3], ClosedChainError> {
        if !theta1.is_finite() {
            return Err(ClosedChainError::NonFinite {
                what: "theta1".into(),
            });
        }
        let (lo, hi) = self.workspace();
        let ld = self.diagonal(theta1);
        let acos = |x: f64| -> Option<f64> {
            if (-1.0..=1.0).contains(&x) {
                Some(x.acos())
            } else {
                None
            }
        };
        let (l0, l1, l2, l3) = (self.l0, self.l1, self.l2, self.l3);
        let out = || ClosedChainError::NoConvergence {
            what: format!(
                "four-bar loop closure: θ1 = {theta1} is outside the workspace [{lo:.4}, {hi:.4}]"
            ),
            residual: f64::INFINITY,
        };
        if !(theta1 > 0.0 && theta1 < PI) || ld <= 0.0 {
            return Err(out());
        }
        let a = acos((l0 * l0 - l1 * l1 + ld * ld) / (2.0 * l0 * ld)).ok_or_else(out)?;
        let b = acos((l2 * l2 - l3 * l3 + ld * ld) / (2.0 * l2 * ld)).ok_or_else(out)?;
        let c = acos((l1 * l1 - l0 * l0 + ld * ld) / (2.0 * l1 * ld)).ok_or_else(out)?;
        let d = acos((l3 * l3 - l2 * l2 + ld * ld) / (2.0 * l3 * ld)).ok_or_else(out)?;
        let e = acos((l2 * l2 + l3 * l3 - ld * ld) / (2.0 * l2 * l3)).ok_or_else(out)?;
        Ok([PI - a - b, PI + c + d, 2.0 * PI - e])
    }

    /// The output orientation `φ = θ1 + θ3` (10), closed form.
    pub fn orientation(&self, theta1: f64) -> Result<f64, ClosedChainError> {
        Ok(theta1 + self.passive(theta1)?[1])
    }

    /// The end-effector position `p_e` through chain 1 (11).
    pub fn position(&self, theta1: f64) -> Result<[f64; 2], ClosedChainError> {
        let phi = self.orientation(theta1)?;
        Ok([
            -self.l0 / 2.0 + self.l1 * theta1.cos() + (self.l3 + self.l4) * phi.cos(),
            self.l1 * theta1.sin() + (self.l3 + self.l4) * phi.sin(),
        ])
    }

    /// The full joint vector in the mechanism's order `θ = (θ1, θ3, θ2, θ4)`.
    pub fn configuration(&self, theta1: f64) -> Result<Col<f64>, ClosedChainError> {
        let [t2, t3, t4] = self.passive(theta1)?;
        Ok(ColRef::from_slice(&[theta1, t3, t2, t4]).to_owned())
    }

    /// The active joint θ1 giving orientation `φ` (bisection on the monotone closed form).
    pub fn inverse(&self, phi: f64) -> Result<f64, ClosedChainError> {
        let (lo, hi) = self.workspace();
        let (mut a, mut b) = (lo + 1e-12, hi - 1e-12);
        let (fa, fb) = (self.orientation(a)? - phi, self.orientation(b)? - phi);
        if fa * fb > 0.0 {
            return Err(ClosedChainError::NoConvergence {
                what: format!("four-bar inverse kinematics: φ = {phi} is not reachable"),
                residual: fa.abs().min(fb.abs()),
            });
        }
        for _ in 0..200 {
            let m = 0.5 * (a + b);
            let fm = self.orientation(m)? - phi;
            if (fm > 0.0) == (fa > 0.0) {
                a = m;
            } else {
                b = m;
            }
        }
        Ok(0.5 * (a + b))
    }
}
