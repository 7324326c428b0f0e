//! The distance between two instruments' shafts and how fast it changes: the coupling
//! constraint of several arms through their own ports (the thesis's §5.2, "both arms, a
//! constraint on each"), where the shafts converge inside the body and must not touch.
//!
//! A shaft inside the body is the segment from its port to its tip, `a(s) = a₀ + s (a₁ − a₀)`,
//! `s ∈ [0, 1]`, and the other `b(t) = b₀ + t (b₁ − b₀)`. Their distance is
//!
//! ```text
//! d = min_{s,t ∈ [0,1]} |a(s) − b(t)|                                              (D1)
//! ```
//!
//! attained at the witnesses `(s*, t*)` ([`segment_distance`]). Where they are unique `d` is
//! differentiable, and with the endpoints moving at `ȧ₀, ȧ₁, ḃ₀, ḃ₁` (the witnesses' own motion
//! along the segments does not change `d` to first order: the gradient in `s, t` is normal to the
//! box `[0, 1]²` or zero at the minimum),
//!
//! ```text
//! ḋ = nᵀ (ȧ(s*) − ḃ(t*)),   n = (a(s*) − b(t*)) / d,                                 (D2)
//! ȧ(s) = (1 − s) ȧ₀ + s ȧ₁,  ḃ(t) = (1 − t) ḃ₀ + t ḃ₁
//! ```
//!
//! and with each endpoint's velocity `J_p θ̇` (its point-velocity Jacobian) the row of the
//! joint rates is `nᵀ ((1 − s*) J_a₀ + s* J_a₁ − (1 − t*) J_b₀ − t* J_b₁)`
//! ([`SegmentDistance::rate_row`]).
//!
//! Two cases break the formula that is usually written for lines:
//!
//! - **Parallel shafts** whose projections overlap have a whole interval of witnesses, and `d`
//!   is not differentiable: rotating either shaft changes `d` at a rate that depends on where
//!   along the overlap one looks. Its one-sided derivative is the smallest of (D2) over the
//!   witnesses (Danskin's theorem), and (D2) is affine in `s`, so its smallest value is at an end
//!   of the overlap: [`SegmentDistance::witnesses`] holds both ends, and a constraint `ḋ ≥ …`
//!   holds for the shafts' distance when it holds at both. (A line-to-line distance Jacobian
//!   divides by `|u × v|` there.)
//! - **Touching or crossing shafts** (`d = 0`) have no `a − b` to normalise: `n` is the common
//!   normal `u × v / |u × v|` of crossing shafts, whose distance grows at `|nᵀ (ȧ − ḃ)|` as they
//!   separate, so `nᵀ (ȧ − ḃ)` is a lower bound of the rate; touching parallel shafts have no
//!   normal ([`SegmentDistance::normal`] is `None`). The square `d²` has the rate
//!   `2 (a − b)ᵀ (ȧ − ḃ)` everywhere, zero there ([`SegmentDistance::squared_rate`]).

use nalgebra::{RealField, SMatrix, Vector3};

/// The distance between two segments and where it is attained ((D1)–(D2) of this module).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentDistance<T: RealField + Copy> {
    /// `d ≥ 0`.
    pub distance: T,
    /// The witnesses `(s*, t*)`: one pair, or, for parallel segments whose projections overlap,
    /// both ends of the overlap (`count == 2`).
    pub witnesses: [(T, T); 2],
    /// How many of [`SegmentDistance::witnesses`] there are: 1 or 2.
    pub count: usize,
    /// The unit normal `n` of (D2): `(a(s*) − b(t*)) / d`, or for touching or crossing segments
    /// the unit `u × v`; `None` where neither exists (touching parallel segments, or a segment of
    /// zero length at distance zero).
    pub normal: Option<Vector3<T>>,
    /// The segments' endpoints as given (`a₀, a₁, b₀, b₁`).
    pub ends: [Vector3<T>; 4],
}

/// `(1 − s) p₀ + s p₁`.
fn along<T: RealField + Copy>(p0: &Vector3<T>, p1: &Vector3<T>, s: T) -> Vector3<T> {
    p0 * (T::one() - s) + p1 * s
}

fn clamp01<T: RealField + Copy>(x: T) -> T {
    x.max(T::zero()).min(T::one())
}

/// The distance (D1) between the segments `[a0, a1]` and `[b0, b1]` and its witnesses. A segment
/// of zero length is a point. Every input finite gives a finite result.
pub fn segment_distance<T: RealField + Copy>(
    a0: &Vector3<T>,
    a1: &Vector3<T>,
    b0: &Vector3<T>,
    b1: &Vector3<T>,
) -> SegmentDistance<T> {
    let u = a1 - a0;
    let v = b1 - b0;
    let r = a0 - b0;
    let (aa, bb, ee) = (u.dot(&u), u.dot(&v), v.dot(&v));
    let (c, f) = (u.dot(&r), v.dot(&r));
    let eps = T::default_epsilon();
    let zero = T::zero();
    let one = T::one();
    // A length below the rounding of the endpoints' coordinates is none.
    let scale = a0.amax().max(a1.amax()).max(b0.amax()).max(b1.amax()) + one;
    let tiny = (eps * nalgebra::convert::<f64, T>(16.0) * scale).powi(2);
    let mut witnesses = [(zero, zero); 2];
    let mut count = 1;
    if aa <= tiny && ee <= tiny {
        // Two points.
    } else if aa <= tiny {
        witnesses[0] = (zero, clamp01(f / ee));
    } else if ee <= tiny {
        witnesses[0] = (clamp01(-c / aa), zero);
    } else {
        let denom = aa * ee - bb * bb;
        // Parallel to the rounding of `u × v`.
        let parallel = denom <= eps * nalgebra::convert::<f64, T>(64.0) * aa * ee;
        if parallel {
            // The projections of b₀, b₁ on a's line, in a's parameter.
            let (p0, p1) = (-c / aa, (bb - c) / aa);
            let (lo, hi) = (clamp01(p0.min(p1)), clamp01(p0.max(p1)));
            // b's parameter of a point of a's line (the segments' lines coincide up to an
            // offset), clamped: outside the overlap the nearest end of b.
            let t_of = |s: T| clamp01((bb * s + f) / ee);
            let s_of = |t: T| clamp01((bb * t - c) / aa);
            if hi > lo {
                // The nearer end of the overlap first: segments parallel only to the rounding
                // are closest at one of them.
                let ends = [(lo, t_of(lo)), (hi, t_of(hi))];
                let gap = |(s, t): (T, T)| (along(a0, a1, s) - along(b0, b1, t)).norm_squared();
                witnesses = if gap(ends[1]) < gap(ends[0]) {
                    [ends[1], ends[0]]
                } else {
                    ends
                };
                count = 2;
            } else {
                // No overlap: the nearer ends.
                let t = t_of(lo);
                witnesses[0] = (s_of(t), t);
            }
        } else {
            let mut s = clamp01((bb * f - c * ee) / denom);
            let mut t = (bb * s + f) / ee;
            if t < zero {
                t = zero;
                s = clamp01(-c / aa);
            } else if t > one {
                t = one;
                s = clamp01((bb - c) / aa);
            }
            witnesses[0] = (s, t);
        }
    }
    let (s, t) = witnesses[0];
    let gap = along(a0, a1, s) - along(b0, b1, t);
    let distance = gap.norm();
    // Apart beyond the rounding of the endpoints (else touching: the gap has no direction).
    let normal = if distance * distance > tiny {
        Some(gap / distance)
    } else {
        let cross = u.cross(&v);
        let n = cross.norm();
        (n > zero && n * n > tiny * (aa + ee)).then(|| cross / n)
    };
    SegmentDistance {
        distance,
        witnesses,
        count,
        normal,
        ends: [*a0, *a1, *b0, *b1],
    }
}

impl<T: RealField + Copy> SegmentDistance<T> {
    /// The witnesses in use: one, or both ends of a parallel overlap.
    pub fn witnesses(&self) -> &[(T, T)] {
        &self.witnesses[..self.count]
    }

    /// The points `(a(s*), b(t*))` of the first witness.
    pub fn closest_points(&self) -> (Vector3<T>, Vector3<T>) {
        let [a0, a1, b0, b1] = &self.ends;
        let (s, t) = self.witnesses[0];
        (along(a0, a1, s), along(b0, b1, t))
    }

    /// `ḋ` (D2) with the endpoints moving at `velocities = [ȧ₀, ȧ₁, ḃ₀, ḃ₁]`: the smallest over
    /// the witnesses, which is the one-sided derivative for parallel segments. `None` without a
    /// normal ([`SegmentDistance::normal`]).
    pub fn rate(&self, velocities: &[Vector3<T>; 4]) -> Option<T> {
        let n = self.normal?;
        let [va0, va1, vb0, vb1] = velocities;
        self.witnesses()
            .iter()
            .map(|&(s, t)| n.dot(&(along(va0, va1, s) - along(vb0, vb1, t))))
            .reduce(|x, y| x.min(y))
    }

    /// `d(d²)/dt = 2 (a(s*) − b(t*))ᵀ (ȧ(s*) − ḃ(t*))` at the first witness: defined everywhere,
    /// zero where the segments touch. For parallel segments the other witnesses give the same
    /// value where the gap is normal to both, to first order.
    pub fn squared_rate(&self, velocities: &[Vector3<T>; 4]) -> T {
        let (pa, pb) = self.closest_points();
        let [va0, va1, vb0, vb1] = velocities;
        let (s, t) = self.witnesses[0];
        (pa - pb).dot(&(along(va0, va1, s) - along(vb0, vb1, t))) * nalgebra::convert(2.0)
    }

    /// The rows `ḋ = row θ̇` of (D2), one per witness (`count` of them), from the endpoints'
    /// point-velocity Jacobians `[J_a₀, J_a₁, J_b₀, J_b₁]` (3 × N each, in the frame of the
    /// endpoints): `ḋ ≥ c` holds for the segments where `row_k θ̇ ≥ c` holds for every row.
    /// `None` without a normal.
    pub fn rate_row<const N: usize>(
        &self,
        jacobians: &[SMatrix<T, 3, N>; 4],
    ) -> Option<[SMatrix<T, 1, N>; 2]> {
        let n = self.normal?;
        let [ja0, ja1, jb0, jb1] = jacobians;
        let mut rows = [SMatrix::<T, 1, N>::zeros(); 2];
        for (row, &(s, t)) in rows.iter_mut().zip(self.witnesses()) {
            let one = T::one();
            let j = ja0 * (one - s) + ja1 * s - jb0 * (one - t) - jb1 * t;
            *row = n.transpose() * j;
        }
        if self.count == 1 {
            rows[1] = rows[0];
        }
        Some(rows)
    }
}
