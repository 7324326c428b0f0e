//! The tip's reference along a path given as rows — time, position and, optionally, an
//! orientation (a roll about the tip's `z` axis, or a unit quaternion) — at any time: the one rule
//! by which `trocar simulate ROBOT --trajectory F.csv` turns a path into the controller's
//! reference, so that a user's own loop (Rust, Python, C) reproduces it to rounding.
//!
//! - **Position**: linear between rows; the velocity fed forward is the segment's slope (zero
//!   outside the path's time span; the position is held at its ends).
//! - **Roll** `φ`: `R_0e(q0) Rz(φ)` interpolated linearly, then turned by the smallest rotation that
//!   takes the direction from the trocar to the start tip onto the direction from the trocar to
//!   the desired tip: the task commands the roll, and the tilt that the trocar imposes leaves no
//!   orientation error. Its angular velocity is the central difference of that orientation
//!   (`h = 1e-6` s), `ω̂ = (R(t + h) − R(t − h)) Rᵀ / 2h`.
//! - **Quaternion** `(w, x, y, z)`, base frame: interpolated by slerp; the angular velocity is the
//!   segment's rotation as an axis times its angle over its duration.
//! - **Position only**: the orientation is the tip's current one (no orientation error), which the
//!   caller supplies ([`PathRows::reference`] takes it).
//!
//! Allocation-free and `no_std`; the rows are read through [`PathRows`], so a table in any
//! layout (the command line's columns, a C caller's flat array) serves without a copy.

use crate::control::Reference;
use crate::se3::Se3;
use nalgebra::{Matrix3, Quaternion, RealField, Rotation3, Unit, UnitQuaternion, Vector3};

/// How the rows give the tip's orientation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OrientationKind {
    /// None: position only.
    None,
    /// A roll about the tip's `z` axis (rad), relative to its orientation at the start.
    Roll,
    /// Unit quaternions `(w, x, y, z)`, base frame.
    Quaternion,
}

/// A path's rows: at least two, times strictly increasing (the caller checks; see
/// [`PathRows::check`]).
pub trait PathRows<T: RealField + Copy> {
    /// The number of rows.
    fn rows(&self) -> usize;
    /// The time of row `k` (s).
    fn time(&self, k: usize) -> T;
    /// The tip's position at row `k` (m, base frame).
    fn position(&self, k: usize) -> [T; 3];
    /// How the rows give the orientation.
    fn orientation(&self) -> OrientationKind;
    /// The roll at row `k` (rad) when [`OrientationKind::Roll`].
    fn roll(&self, k: usize) -> T;
    /// The quaternion `(w, x, y, z)` at row `k` when [`OrientationKind::Quaternion`].
    fn quaternion(&self, k: usize) -> [T; 4];

    /// Whether the rows can be read as a path: two or more, every value finite, times strictly
    /// increasing, quaternions of nonzero length.
    fn check(&self) -> bool {
        let n = self.rows();
        if n < 2 {
            return false;
        }
        (0..n).all(|k| {
            let finite = self.time(k).is_finite()
                && self.position(k).iter().all(|v| v.is_finite())
                && match self.orientation() {
                    OrientationKind::None => true,
                    OrientationKind::Roll => self.roll(k).is_finite(),
                    OrientationKind::Quaternion => {
                        let q = self.quaternion(k);
                        q.iter().all(|v| v.is_finite())
                            && q.iter().map(|v| *v * *v).fold(T::zero(), |a, b| a + b) > T::zero()
                    }
                };
            finite && (k == 0 || self.time(k) > self.time(k - 1))
        })
    }

    /// The segment `[k, k + 1]` holding `t` and the fraction along it (clamped to the ends).
    fn segment(&self, t: T) -> (usize, T) {
        let n = self.rows();
        if t <= self.time(0) {
            return (0, T::zero());
        }
        if t >= self.time(n - 1) {
            return (n - 2, T::one());
        }
        // The last row at or before `t` (binary search), at most `n − 2`.
        let (mut lo, mut hi) = (0, n - 1);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if self.time(mid) <= t {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        (
            lo,
            (t - self.time(lo)) / (self.time(lo + 1) - self.time(lo)),
        )
    }

    /// The path at `t` as the rows give it: the position, the orientation (from the start
    /// orientation `r0` for a roll; `None` for position only), the velocity and the angular
    /// velocity, before the roll is turned through the trocar ([`PathRows::reference`]).
    fn at(
        &self,
        t: T,
        r0: &Matrix3<T>,
    ) -> (Vector3<T>, Option<Matrix3<T>>, Vector3<T>, Vector3<T>) {
        let (k, s) = self.segment(t);
        let inside = t > self.time(0) && t < self.time(self.rows() - 1);
        let span = self.time(k + 1) - self.time(k);
        let (a, b) = (self.position(k), self.position(k + 1));
        let position = Vector3::from_fn(|i, _| a[i] + s * (b[i] - a[i]));
        let velocity = Vector3::from_fn(|i, _| {
            if inside {
                (b[i] - a[i]) / span
            } else {
                T::zero()
            }
        });
        let (rotation, angular_velocity) = match self.orientation() {
            OrientationKind::None => (None, Vector3::zeros()),
            OrientationKind::Roll => {
                let (ra, rb) = (self.roll(k), self.roll(k + 1));
                let roll = ra + s * (rb - ra);
                let rate = if inside { (rb - ra) / span } else { T::zero() };
                let rot = r0 * Rotation3::from_axis_angle(&Vector3::z_axis(), roll).into_inner();
                let w = rot.column(2) * rate;
                (Some(rot), w)
            }
            OrientationKind::Quaternion => {
                let qa = unit_quaternion(self.quaternion(k));
                let qb = unit_quaternion(self.quaternion(k + 1));
                let q = qa.slerp(&qb, s);
                // ω = axis · angle / span, in the base frame.
                let w = if inside {
                    (qb * qa.inverse()).scaled_axis() / span
                } else {
                    Vector3::zeros()
                };
                (Some(q.to_rotation_matrix().into_inner()), w)
            }
        };
        (position, rotation, velocity, angular_velocity)
    }

    /// The controller's reference at `t` (see the [module](self)): the tip at `g0` at the start
    /// and the trocar at `trocar`; `current` is the tip's orientation now, taken where the rows
    /// give none.
    fn reference(
        &self,
        t: T,
        g0: &Se3<T>,
        trocar: &Vector3<T>,
        current: &Matrix3<T>,
    ) -> Reference<T> {
        let (position, rotation, velocity, angular_velocity) = self.at(t, &g0.rotation);
        match self.orientation() {
            OrientationKind::Roll => {
                let rolled = |t: T| {
                    let (position, rotation, _, _) = self.at(t, &g0.rotation);
                    turned_through(&position, rotation, g0, trocar)
                };
                let r = turned_through(&position, rotation, g0, trocar);
                let h: T = nalgebra::convert(1e-6);
                let two: T = nalgebra::convert(2.0);
                let half: T = nalgebra::convert(0.5);
                let omega = (rolled(t + h) - rolled(t - h)) / (two * h) * r.transpose();
                Reference {
                    position,
                    rotation: r,
                    velocity,
                    angular_velocity: Vector3::new(
                        half * (omega[(2, 1)] - omega[(1, 2)]),
                        half * (omega[(0, 2)] - omega[(2, 0)]),
                        half * (omega[(1, 0)] - omega[(0, 1)]),
                    ),
                }
            }
            _ => Reference {
                position,
                rotation: rotation.unwrap_or(*current),
                velocity,
                angular_velocity,
            },
        }
    }
}

/// The unit quaternion of `(w, x, y, z)` (normalised).
pub fn unit_quaternion<T: RealField + Copy>(q: [T; 4]) -> UnitQuaternion<T> {
    UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]))
}

/// A rolled orientation `rotation` (the start's where `None`) at the desired tip `position`,
/// turned by the smallest rotation that takes the direction from the trocar to the start tip
/// onto the direction from the trocar to `position` (see the [module](self)).
fn turned_through<T: RealField + Copy>(
    position: &Vector3<T>,
    rotation: Option<Matrix3<T>>,
    g0: &Se3<T>,
    trocar: &Vector3<T>,
) -> Matrix3<T> {
    let r = rotation.unwrap_or(g0.rotation);
    let tiny: T = nalgebra::convert(1e-12);
    let (Some(a), Some(b)) = (
        (g0.translation - trocar).try_normalize(tiny),
        (position - trocar).try_normalize(tiny),
    ) else {
        return r;
    };
    let axis = a.cross(&b);
    let sin = axis.norm();
    if sin == T::zero() {
        return r;
    }
    let align = Rotation3::from_axis_angle(&Unit::new_unchecked(axis / sin), sin.atan2(a.dot(&b)));
    align.matrix() * r
}

/// A path as one flat table, row after row (a C caller's array, a CSV's numbers): `t, x, y, z`,
/// then `roll` ([`OrientationKind::Roll`]) or `qw, qx, qy, qz` ([`OrientationKind::Quaternion`]).
#[derive(Clone, Copy, Debug)]
pub struct FlatPath<'a, T> {
    values: &'a [T],
    orientation: OrientationKind,
}

impl<'a, T: RealField + Copy> FlatPath<'a, T> {
    /// The values per row for an orientation kind: 4, 5 or 8.
    pub const fn columns(orientation: OrientationKind) -> usize {
        match orientation {
            OrientationKind::None => 4,
            OrientationKind::Roll => 5,
            OrientationKind::Quaternion => 8,
        }
    }

    /// The path of `values` (a whole number of rows of [`Self::columns`] values); `None` where
    /// the length is not, or the rows fail [`PathRows::check`].
    pub fn new(values: &'a [T], orientation: OrientationKind) -> Option<Self> {
        let c = Self::columns(orientation);
        if values.len() % c != 0 {
            return None;
        }
        let path = FlatPath {
            values,
            orientation,
        };
        path.check().then_some(path)
    }

    fn value(&self, k: usize, column: usize) -> T {
        self.values[k * Self::columns(self.orientation) + column]
    }
}

impl<T: RealField + Copy> PathRows<T> for FlatPath<'_, T> {
    fn rows(&self) -> usize {
        self.values.len() / Self::columns(self.orientation)
    }
    fn time(&self, k: usize) -> T {
        self.value(k, 0)
    }
    fn position(&self, k: usize) -> [T; 3] {
        [self.value(k, 1), self.value(k, 2), self.value(k, 3)]
    }
    fn orientation(&self) -> OrientationKind {
        self.orientation
    }
    fn roll(&self, k: usize) -> T {
        self.value(k, 4)
    }
    fn quaternion(&self, k: usize) -> [T; 4] {
        [
            self.value(k, 4),
            self.value(k, 5),
            self.value(k, 6),
            self.value(k, 7),
        ]
    }
}
