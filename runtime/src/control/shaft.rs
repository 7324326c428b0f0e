//! The line of the constrained link along which the trocar may sit: the constraint frame
//! `g_ir(l_a) = (R_ir, o + l_a d)` in the link's frame `F_i`, one parameter `l_a` moving `F_r`
//! along the direction `d` (the instrument's shaft).
//!
//! The thesis's arm has `R_ir = I`, `o = 0`, `d = y_i` ([`Shaft::along_y`]); a laparoscope on a
//! flange usually runs along the flange's `z` axis, past a fixed offset. With the trocar at a
//! point `p_t` of the base frame, every control step places `F_r` at the point of the line
//! nearest to `p_t` (the moving trocar of (3.30)–(3.34)): `l_a = ((p_t − p_0i − R_0i o) · R_0i d)
//! / |d|²`.

use crate::se3::Se3;
use nalgebra::{Matrix3, RealField, Vector3};

/// The constraint frame as a function of the trocar offset `l_a`:
/// `g_ir(l_a) = (rotation, origin + l_a direction)`, all in the constrained link's frame `F_i`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shaft<T: RealField + Copy> {
    /// `R_ir`, the orientation of `F_r` in `F_i` (independent of `l_a`).
    pub rotation: Matrix3<T>,
    /// `o`: the position of `F_r` at `l_a = 0`.
    pub origin: Vector3<T>,
    /// `d`: the direction in which `l_a` moves `F_r` (the shaft's axis; a unit vector when
    /// `l_a` is a length).
    pub direction: Vector3<T>,
}

impl<T: RealField + Copy> Shaft<T> {
    /// The thesis's convention: `g_ir = (I, (0, l_a, 0))`, the link runs along `y_i`.
    pub fn along_y() -> Self {
        Shaft {
            rotation: Matrix3::identity(),
            origin: Vector3::zeros(),
            direction: Vector3::y(),
        }
    }

    /// From the constraint frame at two offsets: `g_ir(0)` and `g_ir(1)` (a frame affine in
    /// `l_a`, as a generated module's `constraint_frame` is).
    pub fn from_frames(at_zero: &Se3<T>, at_one: &Se3<T>) -> Self {
        Shaft {
            rotation: at_zero.rotation,
            origin: at_zero.translation,
            direction: at_one.translation - at_zero.translation,
        }
    }

    /// `g_ir(l_a)`.
    pub fn frame(&self, l_a: T) -> Se3<T> {
        Se3::new(self.rotation, self.origin + self.direction * l_a)
    }

    /// The offset `l_a` of the point of the shaft nearest to `trocar` (base coordinates) with
    /// the link at `g_0i`: `((p_t − p_0i − R_0i o) · R_0i d) / |d|²`. Not finite when `d = 0`.
    pub fn offset(&self, g_0i: &Se3<T>, trocar: &Vector3<T>) -> T {
        let d = g_0i.rotation * self.direction;
        let rel = trocar - g_0i.translation - g_0i.rotation * self.origin;
        rel.dot(&d) / self.direction.norm_squared()
    }

    /// The shaft's line in the base frame with the link at `g_0i`: through `p_0i + R_0i o` along
    /// `R_0i d` (normalised), the line the port lies on ([`crate::port`]). `None` where `d = 0`
    /// or a number is not finite.
    pub fn line(&self, g_0i: &Se3<T>) -> Option<crate::port::Line<T>> {
        crate::port::Line::new(
            g_0i.transform_point(&self.origin),
            g_0i.rotation * self.direction,
        )
    }

    /// The lateral velocity `dv_0r` (3.30) that carries the constraint frame with a trocar moving
    /// at `velocity` (base frame), with the link at `g_0i`: `H_v R_0rᵀ v`, the trocar's motion in
    /// the constrained directions `H` of `F_r` — what the moving-RCM law (3.33)–(3.34) feeds
    /// forward for a port whose motion is known or estimated.
    pub fn trocar_rate<const R: usize>(
        &self,
        g_0i: &Se3<T>,
        h: &nalgebra::SMatrix<T, R, 6>,
        velocity: &Vector3<T>,
    ) -> nalgebra::SVector<T, R> {
        super::h_linear(h, &((g_0i.rotation * self.rotation).transpose() * velocity))
    }

    /// The pose `g_0r = g_0i g_ir(l_a)` of the constraint frame in the base.
    pub fn constraint_pose(&self, g_0i: &Se3<T>, l_a: T) -> Se3<T> {
        g_0i.compose(&self.frame(l_a))
    }

    /// The offset of `trocar` from the shaft, in `F_r`'s coordinates at `l_a`:
    /// `R_0rᵀ (p_t − p_0r)`. Its components along the constrained directions are the lateral
    /// error of the drift correction. Computed as `R_irᵀ (R_0iᵀ (p_t − p_0i) − o − l_a d)`,
    /// without forming `g_0r`.
    pub fn trocar_in_frame(&self, g_0i: &Se3<T>, l_a: T, trocar: &Vector3<T>) -> Vector3<T> {
        let in_link = g_0i.rotation.tr_mul(&(trocar - g_0i.translation));
        self.rotation
            .tr_mul(&(in_link - self.origin - self.direction * l_a))
    }

    /// How far the shaft's line moved across a place of the base frame: the link's point
    /// `point` (in `F_i`) was at `from`; with the link now at `g_0i` it is at `g_0i point`, and
    /// that chord less its part along the shaft's axis at `g_0i` is the vector from `from` to
    /// the nearest point of the line (base coordinates).
    ///
    /// With `from` at the trocar, it is the lateral motion of the shaft at the trocar over a
    /// step. The chord alone also carries the point's slide along a shaft that turns (a
    /// shaft sliding at `v` while pivoting at `ω` about the trocar moves the point that was
    /// there by `v ω dt²` across its first axis, though the line never leaves the trocar);
    /// this does not.
    pub fn moved_across(&self, g_0i: &Se3<T>, point: &Vector3<T>, from: &Vector3<T>) -> Vector3<T> {
        let chord = g_0i.transform_point(point) - from;
        let axis = (g_0i.rotation * self.direction).normalize();
        chord - axis * chord.dot(&axis)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::se3::rotation_from_rpy;

    #[test]
    fn offset_is_the_nearest_point_and_the_frame_follows_it() {
        let shaft = Shaft::<f64> {
            rotation: rotation_from_rpy(0.3, -0.2, 0.9),
            origin: Vector3::new(0.01, -0.02, 0.107),
            direction: Vector3::new(0.0, 0.0, 1.0),
        };
        let g_0i = Se3::new(
            rotation_from_rpy(0.4, 1.1, -0.7),
            Vector3::new(0.3, -0.1, 0.5),
        );
        let l: f64 = 0.25;
        let on_axis = g_0i.transform_point(&(shaft.origin + shaft.direction * l));
        // A trocar off the axis by a vector normal to it still gives l.
        let normal = g_0i.rotation * Vector3::new(0.003, -0.004, 0.0);
        let l_a = shaft.offset(&g_0i, &(on_axis + normal));
        assert!((l_a - l).abs() < 1e-14, "{l_a}");
        let g_0r = shaft.constraint_pose(&g_0i, l_a);
        assert!((g_0r.translation - on_axis).norm() < 1e-14);
        // In F_r the offset has no component along the shaft (F_r's z after R_ir).
        let e = shaft.trocar_in_frame(&g_0i, l_a, &(on_axis + normal));
        let along = shaft.rotation.transpose() * shaft.direction;
        assert!(e.dot(&along).abs() < 1e-14);
        assert!((e.norm() - 0.005).abs() < 1e-14);
    }

    #[test]
    fn a_shaft_sliding_while_it_pivots_about_a_place_does_not_move_across_it() {
        let shaft = Shaft::<f64> {
            rotation: Matrix3::identity(),
            origin: Vector3::new(0.0, 0.0, 0.107),
            direction: Vector3::z(),
        };
        let g_0i = Se3::new(
            rotation_from_rpy(0.4, 1.1, -0.7),
            Vector3::new(0.3, -0.1, 0.5),
        );
        let l_a = 0.25;
        let point = shaft.origin + shaft.direction * l_a;
        let trocar = g_0i.transform_point(&point);
        // Over dt = 2 ms: turn by ω dt = 2e-3 rad about an axis through the trocar, normal to
        // the shaft, and slide by v dt = 1e-4 m along the new axis.
        let normal = g_0i.rotation * Vector3::x();
        let turn =
            nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(normal), 2e-3)
                .into_inner();
        let turned = Se3::new(
            turn * g_0i.rotation,
            trocar + turn * (g_0i.translation - trocar),
        );
        let slide = turned.rotation * shaft.direction * 1e-4;
        let next = Se3::new(turned.rotation, turned.translation + slide);
        // The point that was at the trocar moved across the first axis by v ω dt² = 2e-7 m...
        let chord = next.transform_point(&point) - trocar;
        let first_axis = g_0i.rotation * shaft.direction;
        let across_first = chord - first_axis * chord.dot(&first_axis);
        assert!(
            (across_first.norm() - 2e-7).abs() < 1e-12,
            "{}",
            across_first.norm()
        );
        // ...but the line still passes through the trocar.
        assert!(shaft.moved_across(&next, &point, &trocar).norm() < 1e-16);
        // A lateral shift of the link is seen whole.
        let shift = g_0i.rotation * Vector3::new(3e-7, -4e-7, 0.0);
        let shifted = Se3::new(g_0i.rotation, g_0i.translation + shift);
        assert!((shaft.moved_across(&shifted, &point, &trocar) - shift).norm() < 1e-16);
    }

    #[test]
    fn along_y_is_the_thesis_convention() {
        let g_0i = Se3::new(
            rotation_from_rpy(0.1, 0.2, 0.3),
            Vector3::new(1.0, 2.0, 3.0),
        );
        let trocar = g_0i.transform_point(&Vector3::new(0.0, 0.15, 0.0));
        let s = Shaft::<f64>::along_y();
        assert!((s.offset(&g_0i, &trocar) - 0.15).abs() < 1e-14);
        let f = Shaft::from_frames(&s.frame(0.0), &s.frame(1.0));
        assert_eq!(f, s);
    }
}
