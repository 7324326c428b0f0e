//! Kinematics of a serial arm read from a [`RobotDescription`], implementing
//! [`ConstrainedKinematics`] for the simulations.
//!
//! Frames are chained link by link (`g_0k = g_0,k−1 · origin_k · exp(ξ_k θ_k)`); the body Jacobian
//! column of joint `k` in frame `F_b` is `Ad_{g_kb}⁻¹ ξ_k`. `Λ#` is the thesis's basis (3.23)
//! (one constrained direction, `x_r`) or (3.27) (`x_r`, `z_r`).

use nalgebra::{Matrix3, Matrix6, Rotation3, SMatrix, SVector, Unit, Vector3};
use trocar::control::{ConstrainedKinematics, ConstrainedState, ControlError};
use trocar::se3::Se3;
use trocar_model::description::{JointKind, RobotDescription, Rotation};

/// One joint: fixed origin from the parent frame and the axis in the joint frame.
#[derive(Clone, Copy, Debug)]
struct JointData {
    origin: Se3<f64>,
    axis: Vector3<f64>,
    prismatic: bool,
}

/// A serial arm of `N` joints with the RCM on link `I` and `R` constrained directions
/// (`R = 1`: `H = x_r`; `R = 2`: `H = (x_r, z_r)`).
#[derive(Clone, Debug)]
pub struct Arm<const N: usize, const I: usize, const R: usize> {
    joints: [JointData; N],
    tool: Se3<f64>,
}

fn compose(a: &Se3<f64>, b: &Se3<f64>) -> Se3<f64> {
    Se3 {
        rotation: a.rotation * b.rotation,
        translation: a.translation + a.rotation * b.translation,
    }
}

fn inverse(a: &Se3<f64>) -> Se3<f64> {
    let rt = a.rotation.transpose();
    Se3 {
        rotation: rt,
        translation: -(rt * a.translation),
    }
}

/// `Ad_g = [[R, p̂R], [0, R]]` (2.43).
pub(crate) fn adjoint(g: &Se3<f64>) -> Matrix6<f64> {
    let mut m = Matrix6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&g.rotation);
    m.fixed_view_mut::<3, 3>(3, 3).copy_from(&g.rotation);
    m.fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&(g.translation.cross_matrix() * g.rotation));
    m
}

impl<const N: usize, const I: usize, const R: usize> Arm<N, I, R> {
    /// Builds the arm from a description (numbers only in joint and tool origins; parameters take
    /// their nominal values). `Err` if the description does not have `N` joints.
    pub fn from_description(d: &RobotDescription) -> Result<Self, String> {
        if d.joints.len() != N {
            return Err(format!(
                "{}: expected {N} joints, found {}",
                d.name,
                d.joints.len()
            ));
        }
        let lookup = |n: &str| d.parameter(n);
        let origin = |o: &trocar_model::description::Origin| -> Result<Se3<f64>, String> {
            let mut t = Vector3::zeros();
            for k in 0..3 {
                t[k] = o.xyz[k]
                    .eval(lookup)
                    .map_err(|p| format!("{}: unknown parameter {p}", d.name))?;
            }
            let rotation = match &o.rotation {
                Rotation::Rpy([r, p, y]) => Rotation3::from_euler_angles(*r, *p, *y).into_inner(),
                Rotation::Matrix(m) => Matrix3::from_fn(|r, c| m[r][c]),
            };
            Ok(Se3 {
                rotation,
                translation: t,
            })
        };
        let mut joints = [JointData {
            origin: Se3 {
                rotation: Matrix3::identity(),
                translation: Vector3::zeros(),
            },
            axis: Vector3::z(),
            prismatic: false,
        }; N];
        for (k, j) in d.joints.iter().enumerate() {
            let (axis, prismatic) = match &j.kind {
                JointKind::Revolute { axis } => (Vector3::from(*axis), false),
                JointKind::Prismatic { axis } => (Vector3::from(*axis), true),
                JointKind::Twist { .. } => {
                    return Err(format!("{}: raw twists are not supported here", d.name))
                }
            };
            joints[k] = JointData {
                origin: origin(&j.origin)?,
                axis: axis.normalize(),
                prismatic,
            };
        }
        Ok(Arm {
            joints,
            tool: origin(&d.end_effector.origin)?,
        })
    }

    /// Frames `g_01 … g_0N` and the tool `g_0e` at `q`.
    pub fn frames(&self, q: &SVector<f64, N>) -> ([Se3<f64>; N], Se3<f64>) {
        let mut out = [self.tool; N];
        let mut g = Se3 {
            rotation: Matrix3::identity(),
            translation: Vector3::zeros(),
        };
        for (k, j) in self.joints.iter().enumerate() {
            g = compose(&g, &j.origin);
            let motion = if j.prismatic {
                Se3 {
                    rotation: Matrix3::identity(),
                    translation: j.axis * q[k],
                }
            } else {
                Se3 {
                    rotation: Rotation3::from_axis_angle(&Unit::new_unchecked(j.axis), q[k])
                        .into_inner(),
                    translation: Vector3::zeros(),
                }
            };
            g = compose(&g, &motion);
            out[k] = g;
        }
        let e = compose(&g, &self.tool);
        (out, e)
    }

    /// The body twist of joint `k` (frame `g_0k`) expressed in frame `g_0b`: `Ad_{g_kb}⁻¹ ξ_k`.
    fn column(&self, k: usize, g_0k: &Se3<f64>, g_0b: &Se3<f64>) -> SVector<f64, 6> {
        let g_kb = compose(&inverse(g_0k), g_0b);
        let rt = g_kb.rotation.transpose();
        let a = self.joints[k].axis;
        let (v, w) = if self.joints[k].prismatic {
            (rt * a, Vector3::zeros())
        } else {
            (rt * a.cross(&g_kb.translation), rt * a)
        };
        SVector::<f64, 6>::new(v.x, v.y, v.z, w.x, w.y, w.z)
    }

    /// The position of the point of link `I` at `l_a` along `y_i`: `p_0i + l_a y_i`.
    pub fn link_point(&self, q: &SVector<f64, N>, l_a: f64) -> Vector3<f64> {
        let g = self.frames(q).0[I - 1];
        g.translation + g.rotation.column(1) * l_a
    }

    /// `Λ = H Ad_{g_ri}` with `g_ri = (I, (0, −l_a, 0))` (3.3).
    pub fn lambda(&self, l_a: f64) -> SMatrix<f64, R, 6> {
        let g_ri = Se3 {
            rotation: Matrix3::identity(),
            translation: Vector3::new(0.0, -l_a, 0.0),
        };
        <Self as ConstrainedKinematics<f64, N, I, R, 6, 6>>::h(self) * adjoint(&g_ri)
    }
}

/// `Λ#` of (3.23) (`R = 1`) or (3.27) (`R = 2`), `K = 6 − R` columns.
fn lambda_sharp<const R: usize, const K: usize>(l_a: f64) -> SMatrix<f64, 6, K> {
    let mut s = SMatrix::<f64, 6, K>::zeros();
    if R == 1 {
        for k in 0..5 {
            s[(k, k)] = 1.0;
        }
        s[(5, 0)] = 1.0 / l_a;
    } else {
        s[(0, 0)] = 1.0;
        s[(1, 1)] = 1.0;
        s[(2, 2)] = 1.0;
        s[(3, 2)] = -1.0 / l_a;
        s[(4, 3)] = 1.0;
        s[(5, 0)] = 1.0 / l_a;
    }
    s
}

impl<const N: usize, const I: usize, const R: usize, const K: usize, const M: usize>
    ConstrainedKinematics<f64, N, I, R, K, M> for Arm<N, I, R>
{
    fn g_0i(&self, q: &SVector<f64, N>) -> Se3<f64> {
        self.frames(q).0[I - 1]
    }

    fn h(&self) -> SMatrix<f64, R, 6> {
        let mut h = SMatrix::<f64, R, 6>::zeros();
        h[(0, 0)] = 1.0;
        if R == 2 {
            h[(1, 2)] = 1.0;
        }
        h
    }

    fn evaluate(
        &self,
        q: &SVector<f64, N>,
        l_a: f64,
    ) -> Result<ConstrainedState<f64, I, R, K, M>, ControlError> {
        assert!(R <= 2 && K + R == 6 && M == K + N - I);
        let (frames, g_0e) = self.frames(q);
        let g_0i = frames[I - 1];
        let mut jb0i = SMatrix::<f64, 6, I>::zeros();
        for (k, f) in frames.iter().enumerate().take(I) {
            jb0i.set_column(k, &self.column(k, f, &g_0i));
        }
        let ad_ei = adjoint(&compose(&inverse(&g_0e), &g_0i));
        let ls = lambda_sharp::<R, K>(l_a);
        let lambda = self.lambda(l_a);
        let lambda_pinv = lambda.transpose()
            * (lambda * lambda.transpose())
                .try_inverse()
                .expect("Λ has full row rank");
        let mut jr = SMatrix::<f64, 6, M>::zeros();
        jr.fixed_columns_mut::<K>(0).copy_from(&(ad_ei * ls));
        for (k, f) in frames.iter().enumerate().skip(I) {
            jr.set_column(K + k - I, &self.column(k, f, &g_0e));
        }
        Ok(ConstrainedState {
            g_0e,
            g_0i,
            jr,
            jb0i,
            jc: ad_ei * lambda_pinv,
            lambda_sharp: ls,
            lambda_pinv,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn q0() -> SVector<f64, 8> {
        SVector::from([0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3])
    }

    #[test]
    fn zero_configuration_matches_spec_table() {
        let arm =
            Arm::<8, 6, 2>::from_description(&RobotDescription::preset("dia10_like_zy").unwrap())
                .unwrap();
        let (f, e) = arm.frames(&SVector::zeros());
        assert!((f[5].translation - Vector3::new(0.194, 0.77, 1.037)).norm() < 1e-12);
        assert!((f[6].translation - Vector3::new(0.194, 1.10, 1.037)).norm() < 1e-12);
        assert!((e.translation - Vector3::new(0.194, 1.31, 1.037)).norm() < 1e-12);
    }

    /// The body Jacobian columns and J^r agree with finite differences of the frames, and
    /// Λ Λ# = 0, J^r reproduces (3.24) at q0 and w_r is (3.42).
    #[test]
    fn jacobians_match_finite_differences_and_thesis() {
        let arm =
            Arm::<8, 6, 2>::from_description(&RobotDescription::preset("dia10_like_zy").unwrap())
                .unwrap();
        let q = q0();
        let la = 0.15;
        let s: ConstrainedState<f64, 6, 2, 4, 6> = arm.evaluate(&q, la).unwrap();
        assert!((arm.lambda(la) * s.lambda_sharp).norm() < 1e-14);
        let h = 1e-7;
        for k in 0..6 {
            let mut qp = q;
            qp[k] += h;
            let mut qm = q;
            qm[k] -= h;
            let gp = arm.frames(&qp).0[5];
            let gm = arm.frames(&qm).0[5];
            let rt = s.g_0i.rotation.transpose();
            let v = rt * (gp.translation - gm.translation) / (2.0 * h);
            let wh = rt * (gp.rotation - gm.rotation) / (2.0 * h);
            let w = Vector3::new(wh[(2, 1)], wh[(0, 2)], wh[(1, 0)]);
            let col = s.jb0i.column(k);
            assert!((col.fixed_rows::<3>(0) - v).norm() < 1e-6, "v col {k}");
            assert!((col.fixed_rows::<3>(3) - w).norm() < 1e-6, "w col {k}");
        }
        let (lb, l8) = (0.33 - la, 0.21);
        let (s7, c7, s8, c8) = (q[6].sin(), q[6].cos(), q[7].sin(), q[7].cos());
        // Check the unidirectional J^r (3.24), which SPEC states is exact for this geometry.
        let arm1 =
            Arm::<8, 6, 1>::from_description(&RobotDescription::preset("dia10_like_zy").unwrap())
                .unwrap();
        let s1: ConstrainedState<f64, 6, 1, 5, 7> = arm1.evaluate(&q, la).unwrap();
        let a1 = -c8 * (l8 + lb * c7) / la;
        let a2 = -s8 * (l8 + lb * c7) / la;
        let a3 = -s8 * (la + lb + l8 * c7);
        let a4 = c8 * (la + lb + l8 * c7);
        #[rustfmt::skip]
        let expect = SMatrix::<f64, 6, 7>::from_row_slice(&[
            a1, c8 * s7, -s8, a3, -l8 * s7 * s8, -l8 * c8, 0.0,
            lb * s7 / la, c7, 0.0, 0.0, 0.0, 0.0, 0.0,
            a2, s7 * s8, c8, a4, l8 * c8 * s7, -l8 * s8, 0.0,
            -s8 / la, 0.0, 0.0, c7 * c8, c8 * s7, -s8, 0.0,
            0.0, 0.0, 0.0, -s7, c7, 0.0, 1.0,
            c8 / la, 0.0, 0.0, c7 * s8, s7 * s8, c8, 0.0,
        ]);
        assert!((s1.jr - expect).norm() < 1e-12, "{}", s1.jr - expect);
        // Manipulability claim (3.42) for zy: w_r = lb² |sin θ7| / la².
        let w = trocar::control::manipulability(&s.jr);
        assert!((w - lb * lb * s7.abs() / (la * la)).abs() < 1e-9, "{w}");
    }
}
