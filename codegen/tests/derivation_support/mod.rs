//! Shared helpers of the `derivation_*` tests: the preset descriptions built programmatically
//! (geometry of `runtime/model/robots/*.toml` and `docs/reference-robots.md`) and an independent, plain-`f64`
//! numeric implementation of the kinematics (4×4 products and adjoints), written without the
//! symbolic engine.
#![allow(dead_code)]

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use trocar_model::description::{
    ConstraintDesc, EndEffector, JointDesc, JointKind, Linear, Origin, Parameter, RobotDescription,
    Rotation, Wrist,
};

pub fn num(x: f64) -> Linear {
    Linear {
        constant: x,
        terms: vec![],
    }
}

pub fn par(terms: &[(f64, &str)]) -> Linear {
    Linear {
        constant: 0.0,
        terms: terms.iter().map(|(c, n)| (*c, n.to_string())).collect(),
    }
}

pub fn origin(xyz: [Linear; 3]) -> Origin {
    Origin {
        xyz,
        rotation: Rotation::Rpy([0.0; 3]),
    }
}

pub fn revolute(name: &str, xyz: [Linear; 3], axis: [f64; 3]) -> JointDesc {
    JointDesc {
        name: name.into(),
        origin: origin(xyz),
        kind: JointKind::Revolute { axis },
        limits: None,
        speed_limit: None,
        acceleration_limit: None,
        jerk_limit: None,
        dynamics: Default::default(),
        location: None,
    }
}

const X: [f64; 3] = [1.0, 0.0, 0.0];
const Y: [f64; 3] = [0.0, 1.0, 0.0];
const Z: [f64; 3] = [0.0, 0.0, 1.0];

/// Joints 1–6 of dia10_like (`docs/reference-robots.md`), as in `runtime/model/robots/*.toml`.
pub fn dia10_first_six() -> Vec<JointDesc> {
    vec![
        revolute("torso", [num(0.0), num(0.0), num(0.0)], Z),
        revolute("shoulder_pitch", [num(0.194), num(0.0), num(1.037)], X),
        revolute("elbow_pitch", [num(0.0), num(0.38), num(0.0)], X),
        revolute("forearm_roll", [num(0.0), num(0.0), num(0.0)], Y),
        revolute("wrist_pitch", [num(0.0), num(0.39), num(0.0)], X),
        revolute("wrist_roll", [num(0.0), num(0.0), num(0.0)], Y),
    ]
}

fn robot(
    name: &str,
    params: &[(&str, f64)],
    shaft: Linear,
    last_axis: [f64; 3],
    l8: Linear,
    h: Vec<[f64; 6]>,
    wrist: Option<Wrist>,
) -> RobotDescription {
    let mut joints = dia10_first_six();
    joints.push(revolute("shaft_7", [num(0.0), shaft, num(0.0)], Z));
    joints.push(revolute(
        "shaft_8",
        [num(0.0), num(0.0), num(0.0)],
        last_axis,
    ));
    RobotDescription {
        name: name.into(),
        parameters: params
            .iter()
            .map(|(n, v)| Parameter {
                name: n.to_string(),
                value: *v,
            })
            .collect(),
        joints,
        end_effector: EndEffector {
            name: "tool".into(),
            origin: origin([num(0.0), l8, num(0.0)]),
        },
        constraint: Some(ConstraintDesc {
            link: 6,
            origin: origin([num(0.0), par(&[(1.0, "l_a")]), num(0.0)]),
            h,
            wrist,
        }),
        task: None,
        instrument: None,
        source: None,
    }
}

pub const HX: [f64; 6] = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
pub const HZ: [f64; 6] = [0.0, 0.0, 1.0, 0.0, 0.0, 0.0];

/// Parameter order of the presets: `l_a, l_b, l_8`.
pub const PRESET_PARAMS: [&str; 3] = ["l_a", "l_b", "l_8"];

/// One of the thesis presets `unidirectional`, `bidirectional-zy`, `bidirectional-zx`.
pub fn preset(name: &str) -> RobotDescription {
    let params = [("l_a", 0.15), ("l_b", 0.18), ("l_8", 0.21)];
    let shaft = par(&[(1.0, "l_a"), (1.0, "l_b")]);
    let l8 = par(&[(1.0, "l_8")]);
    match name {
        "unidirectional" => robot(
            name,
            &params,
            shaft,
            Y,
            l8,
            vec![HX],
            Some(Wrist::Unidirectional),
        ),
        "bidirectional-zy" => robot(name, &params, shaft, Y, l8, vec![HX, HZ], Some(Wrist::Zy)),
        "bidirectional-zx" => robot(name, &params, shaft, X, l8, vec![HX, HZ], Some(Wrist::Zx)),
        _ => panic!("unknown preset {name}"),
    }
}

/// dia10_like with a zy or zx wrist (`docs/reference-robots.md`): only `l_a` is a parameter.
pub fn dia10_like(zx: bool) -> RobotDescription {
    let (name, axis, wrist) = if zx {
        ("dia10_like_zx", X, Wrist::Zx)
    } else {
        ("dia10_like_zy", Y, Wrist::Zy)
    };
    robot(
        name,
        &[("l_a", 0.15)],
        num(0.33),
        axis,
        num(0.21),
        vec![HX, HZ],
        Some(wrist),
    )
}

// ---------------------------------------------------------------------------------------------
// Independent numeric kinematics: plain f64, 4×4 homogeneous matrices, 6×6 adjoints.

pub type M4 = [[f64; 4]; 4];
pub type M6 = [[f64; 6]; 6];

pub fn m4_mul(a: &M4, b: &M4) -> M4 {
    let mut c = [[0.0; 4]; 4];
    for i in 0..4 {
        for j in 0..4 {
            for k in 0..4 {
                c[i][j] += a[i][k] * b[k][j];
            }
        }
    }
    c
}

pub fn m4_identity() -> M4 {
    let mut m = [[0.0; 4]; 4];
    for (i, row) in m.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    m
}

pub fn m4_inv(g: &M4) -> M4 {
    let mut r = m4_identity();
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = g[j][i];
        }
    }
    for i in 0..3 {
        r[i][3] = -(0..3).map(|k| g[k][i] * g[k][3]).sum::<f64>();
    }
    r
}

pub fn scalar_value(s: &Linear, params: &[(&str, f64)]) -> f64 {
    s.constant
        + s.terms
            .iter()
            .map(|(c, n)| c * params.iter().find(|(m, _)| m == n).expect("param").1)
            .sum::<f64>()
}

pub fn origin_matrix(o: &Origin, params: &[(&str, f64)]) -> M4 {
    let r = match &o.rotation {
        Rotation::Matrix(m) => *m,
        Rotation::Rpy([a, b, c]) => {
            let rx = [
                [1.0, 0.0, 0.0],
                [0.0, a.cos(), -a.sin()],
                [0.0, a.sin(), a.cos()],
            ];
            let ry = [
                [b.cos(), 0.0, b.sin()],
                [0.0, 1.0, 0.0],
                [-b.sin(), 0.0, b.cos()],
            ];
            let rz = [
                [c.cos(), -c.sin(), 0.0],
                [c.sin(), c.cos(), 0.0],
                [0.0, 0.0, 1.0],
            ];
            let mul = |a: [[f64; 3]; 3], b: [[f64; 3]; 3]| {
                let mut m = [[0.0; 3]; 3];
                for i in 0..3 {
                    for j in 0..3 {
                        for k in 0..3 {
                            m[i][j] += a[i][k] * b[k][j];
                        }
                    }
                }
                m
            };
            mul(mul(rz, ry), rx)
        }
    };
    let mut g = m4_identity();
    for i in 0..3 {
        for j in 0..3 {
            g[i][j] = r[i][j];
        }
        g[i][3] = scalar_value(&o.xyz[i], params);
    }
    g
}

/// Joint twist `(v, ω)` in its own frame.
pub fn twist(j: &JointDesc, params: &[(&str, f64)]) -> [f64; 6] {
    match &j.kind {
        JointKind::Revolute { axis } => [0.0, 0.0, 0.0, axis[0], axis[1], axis[2]],
        JointKind::Prismatic { axis } => [axis[0], axis[1], axis[2], 0.0, 0.0, 0.0],
        JointKind::Twist { v, w } => [
            scalar_value(&v[0], params),
            scalar_value(&v[1], params),
            scalar_value(&v[2], params),
            w[0],
            w[1],
            w[2],
        ],
    }
}

/// `exp(ξ̂ θ)` by the 4×4 matrix exponential series (independent of Rodrigues).
pub fn twist_exp(xi: &[f64; 6], theta: f64) -> M4 {
    let mut a = [[0.0; 4]; 4];
    let (v, w) = (&xi[0..3], &xi[3..6]);
    a[0][1] = -w[2] * theta;
    a[0][2] = w[1] * theta;
    a[1][0] = w[2] * theta;
    a[1][2] = -w[0] * theta;
    a[2][0] = -w[1] * theta;
    a[2][1] = w[0] * theta;
    for i in 0..3 {
        a[i][3] = v[i] * theta;
    }
    // scaling and squaring
    let mut s = 0;
    let norm: f64 = a.iter().flatten().map(|x| x.abs()).sum();
    let mut scale = 1.0;
    while norm * scale > 0.5 {
        scale /= 2.0;
        s += 1;
    }
    let mut b = a;
    for row in b.iter_mut() {
        for x in row.iter_mut() {
            *x *= scale;
        }
    }
    let mut result = m4_identity();
    let mut term = m4_identity();
    for k in 1..30 {
        term = m4_mul(&term, &b);
        for row in term.iter_mut() {
            for x in row.iter_mut() {
                *x /= k as f64;
            }
        }
        for i in 0..4 {
            for j in 0..4 {
                result[i][j] += term[i][j];
            }
        }
    }
    for _ in 0..s {
        result = m4_mul(&result, &result);
    }
    result
}

pub fn adjoint(g: &M4) -> M6 {
    let mut ad = [[0.0; 6]; 6];
    let p = [g[0][3], g[1][3], g[2][3]];
    let ph = [[0.0, -p[2], p[1]], [p[2], 0.0, -p[0]], [-p[1], p[0], 0.0]];
    for i in 0..3 {
        for j in 0..3 {
            ad[i][j] = g[i][j];
            ad[i + 3][j + 3] = g[i][j];
            ad[i][j + 3] = (0..3).map(|k| ph[i][k] * g[k][j]).sum();
        }
    }
    ad
}

pub fn mat_mul(a: &[Vec<f64>], b: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let (n, k, m) = (a.len(), b.len(), b[0].len());
    (0..n)
        .map(|i| {
            (0..m)
                .map(|j| (0..k).map(|l| a[i][l] * b[l][j]).sum())
                .collect()
        })
        .collect()
}

pub fn m6_vec(a: &M6) -> Vec<Vec<f64>> {
    a.iter().map(|r| r.to_vec()).collect()
}

/// Numeric kinematics of a description at `q`.
pub struct Numeric {
    /// T_k = origin_k exp(ξ_k q_k)
    pub t: Vec<M4>,
    pub xi: Vec<[f64; 6]>,
    pub ee: M4,
}

impl Numeric {
    pub fn new(d: &RobotDescription, q: &[f64], params: &[(&str, f64)]) -> Self {
        let mut t = Vec::new();
        let mut xi = Vec::new();
        for (k, j) in d.joints.iter().enumerate() {
            let x = twist(j, params);
            t.push(m4_mul(
                &origin_matrix(&j.origin, params),
                &twist_exp(&x, q[k]),
            ));
            xi.push(x);
        }
        Numeric {
            t,
            xi,
            ee: origin_matrix(&d.end_effector.origin, params),
        }
    }

    /// g_0k (k joints) then optionally the end effector.
    pub fn fk(&self, k: usize, with_ee: bool) -> M4 {
        let mut g = m4_identity();
        for t in &self.t[..k] {
            g = m4_mul(&g, t);
        }
        if with_ee {
            g = m4_mul(&g, &self.ee);
        }
        g
    }

    /// Body Jacobian of the chain cut at frame `upto` (all joints + ee when `with_ee`):
    /// column k = Ad(g_ke)^{-1} ξ_k, g_ke = T_{k+1} ⋯ T_upto (· ee).
    pub fn body_jacobian(&self, upto: usize, with_ee: bool) -> Vec<Vec<f64>> {
        let mut cols = Vec::new();
        for k in 0..upto {
            let mut g = m4_identity();
            for t in &self.t[k + 1..upto] {
                g = m4_mul(&g, t);
            }
            if with_ee {
                g = m4_mul(&g, &self.ee);
            }
            let ad = adjoint(&m4_inv(&g));
            cols.push(
                (0..6)
                    .map(|i| (0..6).map(|l| ad[i][l] * self.xi[k][l]).sum::<f64>())
                    .collect::<Vec<f64>>(),
            );
        }
        (0..6)
            .map(|i| cols.iter().map(|c| c[i]).collect())
            .collect()
    }
}

pub fn max_abs_diff(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| {
            assert_eq!(x.len(), y.len());
            x.iter().zip(y).map(|(u, v)| (u - v).abs())
        })
        .fold(0.0, f64::max)
}

pub fn norm(a: &[Vec<f64>]) -> f64 {
    a.iter().flatten().map(|x| x * x).sum::<f64>().sqrt()
}

pub fn m4_vec(g: &M4) -> Vec<Vec<f64>> {
    g.iter().map(|r| r.to_vec()).collect()
}

// ---------------------------------------------------------------------------------------------
// A random chain (the numeric tests and the derivation benchmark).

pub fn rand_scalar(rng: &mut StdRng, lo: f64, hi: f64) -> Linear {
    num((rng.gen_range(lo..hi) * 1000.0_f64).round() / 1000.0)
}

/// A random 9-joint chain: Pythagorean-triple axes (exact unit vectors) in random orientations
/// (rpy, irrational entries), random offsets, one prismatic joint, one screw joint with pitch
/// (`Twist` with `ωᵀv ≠ 0`), parameters in an offset and in the constraint; the constraint at
/// link 6 with a random 3-row `H` and a non-identity `R_ir`.
pub fn random_chain(seed: u64) -> RobotDescription {
    let mut rng = StdRng::seed_from_u64(seed);
    let axes: [[f64; 3]; 6] = [
        [0.6, 0.8, 0.0],
        [0.0, 0.28, 0.96],
        [0.36, 0.48, 0.8],
        [0.0, 0.0, 1.0],
        [-0.8, 0.0, 0.6],
        [1.0, 0.0, 0.0],
    ];
    let mut joints = Vec::new();
    for k in 0..9 {
        let axis = axes[rng.gen_range(0..axes.len())];
        let kind = match k {
            3 => JointKind::Prismatic { axis },
            6 => JointKind::Twist {
                v: [num(0.1), par(&[(0.5, "l_p")]), num(-0.2)],
                w: axis,
            },
            _ => JointKind::Revolute { axis },
        };
        let xyz = if k == 2 {
            [
                rand_scalar(&mut rng, -0.3, 0.3),
                par(&[(1.0, "l_p")]),
                num(0.05),
            ]
        } else {
            [
                rand_scalar(&mut rng, -0.3, 0.3),
                rand_scalar(&mut rng, -0.3, 0.3),
                rand_scalar(&mut rng, -0.3, 0.3),
            ]
        };
        let rotation = if k % 3 == 1 && k < 6 {
            Rotation::Rpy([
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
            ])
        } else {
            Rotation::Rpy([0.0, 0.0, 0.0])
        };
        joints.push(JointDesc {
            name: format!("j{k}"),
            origin: Origin { xyz, rotation },
            kind,
            limits: None,
            speed_limit: None,
            acceleration_limit: None,
            jerk_limit: None,
            dynamics: Default::default(),
            location: None,
        });
    }
    let h: Vec<[f64; 6]> = (0..3)
        .map(|_| {
            let mut r = [0.0; 6];
            for x in r.iter_mut() {
                *x = (rng.gen_range(-1.0..1.0_f64) * 10.0).round() / 10.0;
            }
            r
        })
        .collect();
    RobotDescription {
        name: "random_chain".into(),
        parameters: vec![
            Parameter {
                name: "l_p".into(),
                value: 0.2,
            },
            Parameter {
                name: "l_a".into(),
                value: 0.15,
            },
        ],
        joints,
        end_effector: EndEffector {
            name: "tool".into(),
            origin: Origin {
                xyz: [num(0.01), num(0.1), num(0.02)],
                rotation: Rotation::Matrix([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
            },
        },
        constraint: Some(ConstraintDesc {
            link: 6,
            origin: Origin {
                xyz: [num(0.02), par(&[(1.0, "l_a")]), num(-0.01)],
                rotation: Rotation::Rpy([0.3, -0.2, 0.7]),
            },
            h,
            wrist: None,
        }),
        task: None,
        instrument: None,
        source: None,
    }
}
