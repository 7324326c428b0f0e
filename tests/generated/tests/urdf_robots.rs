//! Robots whose chain comes from a URDF, constrained on the last link (`panda-laparoscope`,
//! `iiwa-endoscope`) and on a middle link (`iiwa-link6`): the compiled generated modules against
//! the numeric runtime at random configurations (property tests), and their forward kinematics and
//! `J^B_0i` against the URDF chain computed independently here (nalgebra isometries built from the
//! URDF's `<origin>`/`<axis>` elements, finite differences for the Jacobian).

use nalgebra::{Isometry3, Matrix3, Translation3, Unit, UnitQuaternion, Vector3};
use proptest::prelude::*;
use trocar_model::description::RobotDescription;
use trocar_sim::robot::NumericRobot;

fn robots() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../runtime/model/robots")
}

fn description(name: &str) -> RobotDescription {
    RobotDescription::from_toml_file(robots().join(format!("{name}.toml"))).unwrap()
}

fn max_diff(a: impl IntoIterator<Item = f64>, b: impl IntoIterator<Item = f64>) -> f64 {
    a.into_iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Column-major `[[f64; R]; C]` against a faer matrix.
fn against<const R: usize, const C: usize>(got: &[[f64; R]; C], want: &faer::Mat<f64>) -> f64 {
    assert_eq!((want.nrows(), want.ncols()), (R, C));
    let mut worst: f64 = 0.0;
    for (c, col) in got.iter().enumerate() {
        for (r, x) in col.iter().enumerate() {
            worst = worst.max((x - want[(r, c)]).abs());
        }
    }
    worst
}

macro_rules! generated_vs_numeric {
    ($test:ident, $m:ident, $file:literal, task: $task:tt) => {
        proptest! {
            #![proptest_config(ProptestConfig::with_cases(200))]
            #[test]
            fn $test(q in proptest::array::uniform7(-2.8f64..2.8), l_a in 0.05f64..0.3) {
                use trocar_tests_generated::$m as g;
                let mut p = g::Params::<f64>::nominal();
                p.l_a = l_a;
                let robot = NumericRobot::<f64>::from_description(
                    &description($file),
                    &[("l_a".to_string(), l_a)],
                )
                .unwrap();
                let (r, t) = g::forward_kinematics(&q, &p);
                let fk = robot.forward_kinematics(&q).unwrap();
                prop_assert!(max_diff(r.iter().flatten().copied(), fk.rotation.iter().copied()) < 1e-12);
                prop_assert!(max_diff(t, fk.translation.iter().copied()) < 1e-12);
                let (ri, ti) = g::forward_kinematics_i(&q, &p);
                let fki = robot.link_frame(g::I, &q).unwrap();
                prop_assert!(max_diff(ri.iter().flatten().copied(), fki.rotation.iter().copied()) < 1e-12);
                prop_assert!(max_diff(ti, fki.translation.iter().copied()) < 1e-12);
                prop_assert!(against(&g::partial_body_jacobian(&q, &p), &robot.partial_body_jacobian(&q).unwrap()) < 1e-12);
                prop_assert!(against(&g::constrained_jacobian(&q, &p), &robot.constrained_jacobian(&q).unwrap()) < 1e-12);
                // The step's outputs from one pass along the chain.
                let (g0e, jbi, jr, jc) = g::pose_and_jacobians_trig(&g::JointTrig::new(&q), &p);
                prop_assert!(max_diff(g0e.0.iter().flatten().copied(), fk.rotation.iter().copied()) < 1e-12);
                prop_assert!(max_diff(g0e.1, fk.translation.iter().copied()) < 1e-12);
                prop_assert!(against(&jbi, &robot.partial_body_jacobian(&q).unwrap()) < 1e-12);
                prop_assert!(against(&jr, &robot.constrained_jacobian(&q).unwrap()) < 1e-12);
                prop_assert!(against(&jc, &robot.constraint_jacobian_c(&q).unwrap()) < 1e-12);
                // The fused g_0i and J^B_0i, from q and given the sines and cosines (the
                // Panda's walk with rows as pairs where the target is x86-64 without AVX).
                let jbi_n = robot.partial_body_jacobian(&q).unwrap();
                let (mut gi, mut jb) = (([[0.0; 3]; 3], [0.0; 3]), [[0.0; 6]; g::I]);
                g::link_pose_and_jacobian(&q, &p, &mut gi, &mut jb);
                let (mut gi_t, mut jb_t) = (([[0.0; 3]; 3], [0.0; 3]), [[0.0; 6]; g::I]);
                g::link_pose_and_jacobian_trig(&g::JointTrig::new(&q), &p, &mut gi_t, &mut jb_t);
                for (gi, jb) in [(gi, jb), (gi_t, jb_t)] {
                    prop_assert!(max_diff(gi.0.iter().flatten().copied(), fki.rotation.iter().copied()) < 1e-12);
                    prop_assert!(max_diff(gi.1, fki.translation.iter().copied()) < 1e-12);
                    prop_assert!(against(&jb, &jbi_n) < 1e-12);
                }
                // The same in f32 (one operation per lane where f64 takes SSE2 pairs), against
                // the f64 numeric robot at the f32-rounded joint values.
                let q32 = q.map(|x| x as f32);
                let mut p32 = g::Params::<f32>::nominal();
                p32.l_a = l_a as f32;
                let q32_64 = q32.map(f64::from);
                let fki32 = robot.link_frame(g::I, &q32_64).unwrap();
                let jbi32_n = robot.partial_body_jacobian(&q32_64).unwrap();
                let (mut gi, mut jb) = (([[0.0f32; 3]; 3], [0.0f32; 3]), [[0.0f32; 6]; g::I]);
                g::link_pose_and_jacobian_trig(&g::JointTrig::new(&q32), &p32, &mut gi, &mut jb);
                let jb64 = jb.map(|c| c.map(f64::from));
                prop_assert!(max_diff(gi.0.iter().flatten().map(|&x| f64::from(x)), fki32.rotation.iter().copied()) < 1e-5);
                prop_assert!(max_diff(gi.1.map(f64::from), fki32.translation.iter().copied()) < 1e-5);
                prop_assert!(against(&jb64, &jbi32_n) < 1e-5);
                generated_vs_numeric!(@task $task, g, q, p, robot);
                let w = g::manipulability(&q, &p);
                let wn = robot.manipulability(&q).unwrap();
                prop_assert!((w - wn).abs() < 1e-12 * (1.0 + wn), "{} vs {}", w, wn);
            }
        }
    };
    (@task true, $g:ident, $q:ident, $p:ident, $robot:ident) => {
        prop_assert!(
            against(
                &$g::constrained_task_jacobian(&$q, &$p),
                &$robot.constrained_task_jacobian(&$q).unwrap()
            ) < 1e-12
        );
    };
    (@task false, $g:ident, $q:ident, $p:ident, $robot:ident) => {};
}

generated_vs_numeric!(panda_generated_vs_numeric, panda_laparoscope, "panda-laparoscope", task: true);
generated_vs_numeric!(iiwa_endoscope_generated_vs_numeric, iiwa_endoscope, "iiwa-endoscope", task: true);
generated_vs_numeric!(iiwa_link6_generated_vs_numeric, iiwa_link6, "iiwa-link6", task: false);

/// The pose of `link` at joints `q` (one value per moving joint on the path, base first), from
/// the URDF's elements directly: `origin · Rot(axis, q)` per joint, `R = Rz(yaw) Ry(pitch) Rx(roll)`.
fn urdf_pose(urdf: &urdf_rs::Robot, link: &str, q: &[f64]) -> Isometry3<f64> {
    let mut path = Vec::new();
    let mut current = link.to_string();
    while let Some(j) = urdf.joints.iter().find(|j| j.child.link == current) {
        path.push(j);
        current = j.parent.link.clone();
    }
    path.reverse();
    let mut g = Isometry3::identity();
    let mut k = 0;
    for j in path {
        let [x, y, z] = j.origin.xyz.0;
        let [roll, pitch, yaw] = j.origin.rpy.0;
        g *= Isometry3::from_parts(
            Translation3::new(x, y, z),
            UnitQuaternion::from_euler_angles(roll, pitch, yaw),
        );
        if j.joint_type != urdf_rs::JointType::Fixed {
            let axis = Unit::new_normalize(Vector3::from(j.axis.xyz.0));
            g *= UnitQuaternion::from_axis_angle(&axis, q[k]);
            k += 1;
        }
    }
    g
}

/// Body Jacobian of the frame `pose(q)` by central differences: column `k` is
/// `(Rᵀ ∂p/∂q_k, vee(Rᵀ ∂R/∂q_k))`.
fn body_jacobian_fd(pose: impl Fn(&[f64]) -> Isometry3<f64>, q: &[f64]) -> Vec<[f64; 6]> {
    let h = 1e-6;
    let g = pose(q);
    let rt = g.rotation.to_rotation_matrix().matrix().transpose();
    (0..q.len())
        .map(|k| {
            let mut a = q.to_vec();
            let mut b = q.to_vec();
            a[k] += h;
            b[k] -= h;
            let (ga, gb) = (pose(&a), pose(&b));
            let dp = (ga.translation.vector - gb.translation.vector) / (2.0 * h);
            let dr: Matrix3<f64> = (ga.rotation.to_rotation_matrix().matrix()
                - gb.rotation.to_rotation_matrix().matrix())
                / (2.0 * h);
            let v = rt * dp;
            let w = rt * dr;
            [v.x, v.y, v.z, w[(2, 1)], w[(0, 2)], w[(1, 0)]]
        })
        .collect()
}

macro_rules! urdf_independent {
    ($test:ident, $m:ident, $urdf:literal, $link_i:literal, $tip:literal, $tool:expr) => {
        #[test]
        fn $test() {
            use trocar_tests_generated::$m as g;
            let urdf = urdf_rs::read_file(robots().join($urdf)).unwrap();
            let p = g::Params::<f64>::nominal();
            let mut seed = 0x2545_f491_4f6c_dd1du64;
            for _ in 0..50 {
                let q: [f64; 7] = std::array::from_fn(|_| {
                    seed ^= seed << 13;
                    seed ^= seed >> 7;
                    seed ^= seed << 17;
                    (seed >> 11) as f64 / (1u64 << 53) as f64 * 5.0 - 2.5
                });
                // The constrained link's frame F_i and J^B_0i.
                let gi = urdf_pose(&urdf, $link_i, &q[..g::I]);
                let (ri, ti) = g::forward_kinematics_i(&q, &p);
                let want = gi.rotation.to_rotation_matrix();
                assert!(
                    max_diff(ri.iter().flatten().copied(), want.matrix().iter().copied()) < 1e-12
                );
                assert!(max_diff(ti, gi.translation.vector.iter().copied()) < 1e-12);
                let fd = body_jacobian_fd(|qq| urdf_pose(&urdf, $link_i, qq), &q[..g::I]);
                let jb = g::partial_body_jacobian(&q, &p);
                assert!(
                    max_diff(jb.iter().flatten().copied(), fd.iter().flatten().copied()) < 1e-8
                );
                // The end effector: the tip link's frame, then the tool offset along its z.
                let ge = urdf_pose(&urdf, $tip, &q) * Translation3::new(0.0, 0.0, $tool);
                let (re, te) = g::forward_kinematics(&q, &p);
                let want = ge.rotation.to_rotation_matrix();
                assert!(
                    max_diff(re.iter().flatten().copied(), want.matrix().iter().copied()) < 1e-12
                );
                assert!(max_diff(te, ge.translation.vector.iter().copied()) < 1e-12);
            }
        }
    };
}

urdf_independent!(
    panda_agrees_with_its_urdf,
    panda_laparoscope,
    "urdf/panda.urdf",
    "panda_link7",
    "panda_link8",
    0.40
);
urdf_independent!(
    iiwa_endoscope_agrees_with_its_urdf,
    iiwa_endoscope,
    "urdf/iiwa14.urdf",
    // The constraint names iiwa_link_ee (fixed 0.045 m beyond iiwa_link_7): F_i is its frame.
    "iiwa_link_ee",
    "iiwa_link_ee",
    0.30
);
urdf_independent!(
    iiwa_link6_agrees_with_its_urdf,
    iiwa_link6,
    "urdf/iiwa14.urdf",
    "iiwa_link_6",
    "iiwa_link_ee",
    0.0
);
