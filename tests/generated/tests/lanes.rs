//! The generated modules on lane types (`trocar::emitted::lanes::F64x4`, `F32x8`) against the same modules
//! on `f64` and `f32`, one configuration at a time: every straight-line function, at random
//! configurations (small and large angles, prismatic offsets) and at edge values (±0,
//! subnormals, multiples of π/2, the `sin_cos` fast path's limits and beyond), equal bit for bit
//! lane by lane.

use trocar::emitted::lanes::{F32x8, F64x4, Lanes};
use trocar_tests_generated as g;

/// The bit patterns of a generated function's value (NaN: any NaN, as one pattern).
trait Bits {
    fn bits(&self, out: &mut Vec<u64>);
}

impl Bits for f64 {
    fn bits(&self, out: &mut Vec<u64>) {
        out.push(if self.is_nan() {
            u64::MAX
        } else {
            self.to_bits()
        });
    }
}

impl Bits for f32 {
    fn bits(&self, out: &mut Vec<u64>) {
        out.push(if self.is_nan() {
            u64::MAX
        } else {
            u64::from(self.to_bits())
        });
    }
}

impl<B: Bits, const N: usize> Bits for [B; N] {
    fn bits(&self, out: &mut Vec<u64>) {
        self.iter().for_each(|b| b.bits(out));
    }
}

impl<A: Bits, B: Bits> Bits for (A, B) {
    fn bits(&self, out: &mut Vec<u64>) {
        self.0.bits(out);
        self.1.bits(out);
    }
}

impl<A: Bits, B: Bits, C: Bits, D: Bits> Bits for (A, B, C, D) {
    fn bits(&self, out: &mut Vec<u64>) {
        self.0.bits(out);
        self.1.bits(out);
        self.2.bits(out);
        self.3.bits(out);
    }
}

fn bits(b: &impl Bits) -> Vec<u64> {
    let mut v = Vec::new();
    b.bits(&mut v);
    v
}

/// A small deterministic generator (xorshift), so a failure names a reproducible sample.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next() >> 11) as f64 / (1u64 << 53) as f64)
    }
}

const EDGES: [f64; 22] = [
    0.0,
    -0.0,
    5e-324,
    -5e-324,
    2.2e-308,
    -1e-310,
    1e-300,
    core::f64::consts::FRAC_PI_4,
    -core::f64::consts::FRAC_PI_4,
    core::f64::consts::FRAC_PI_2,
    -core::f64::consts::PI,
    3.0 * core::f64::consts::FRAC_PI_2,
    1e3 * core::f64::consts::PI,
    1.0,
    -1.0,
    4096.0,
    -4097.0,
    1048576.0,
    -1048577.0,
    1e6,
    1e7,
    -1e12,
];

/// A joint value of sample `i`: a whole group at once of one kind (so most groups run the lanes'
/// `sin_cos` side by side), or edge values mixed into random ones.
fn joint(rng: &mut Rng, i: usize) -> f64 {
    match i % 5 {
        0 => rng.uniform(-core::f64::consts::PI, core::f64::consts::PI),
        1 => rng.uniform(-8.0, 8.0),
        2 => rng.uniform(-1000.0, 1000.0),
        3 => {
            if rng.next().is_multiple_of(3) {
                EDGES[(rng.next() % EDGES.len() as u64) as usize]
            } else {
                rng.uniform(-2.0, 2.0)
            }
        }
        _ => EDGES[(rng.next() % EDGES.len() as u64) as usize],
    }
}

macro_rules! check {
    ($module:ident, $rounds:expr, [$($f:ident),* $(,)?], [$($ft:ident),* $(,)?]) => {{
        use g::$module as m;
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15 ^ stringify!($module).len() as u64);
        let mut compared = 0usize;
        for i in 0..$rounds {
            // f64: four configurations on F64x4.
            let configs: [[f64; m::N]; 4] =
                core::array::from_fn(|_| core::array::from_fn(|_| joint(&mut rng, i)));
            let q = F64x4::gather(&configs);
            let (p, p1) = (m::Params::<F64x4>::nominal(), m::Params::<f64>::nominal());
            let t = m::JointTrig::new(&q);
            for (k, c) in configs.iter().enumerate() {
                let t1 = m::JointTrig::new(c);
                let what = |f: &str| format!("{} `{f}` f64 lane {k} at q = {c:?}", stringify!($module));
                assert_eq!(bits(&(t.sin.lane(k), t.cos.lane(k))), bits(&(t1.sin, t1.cos)), "{}", what("JointTrig::new"));
                $(
                    assert_eq!(bits(&m::$f(&q, &p).lane(k)), bits(&m::$f(c, &p1)), "{}", what(stringify!($f)));
                    compared += 1;
                )*
                $(
                    assert_eq!(bits(&m::$ft(&t, &p).lane(k)), bits(&m::$ft(&t1, &p1)), "{}", what(stringify!($ft)));
                    compared += 1;
                )*
            }
            // f32: eight configurations on F32x8.
            let configs: [[f32; m::N]; 8] =
                core::array::from_fn(|_| core::array::from_fn(|_| joint(&mut rng, i) as f32));
            let q = F32x8::gather(&configs);
            let (p, p1) = (m::Params::<F32x8>::nominal(), m::Params::<f32>::nominal());
            let t = m::JointTrig::new(&q);
            for (k, c) in configs.iter().enumerate() {
                let t1 = m::JointTrig::new(c);
                let what = |f: &str| format!("{} `{f}` f32 lane {k} at q = {c:?}", stringify!($module));
                assert_eq!(bits(&(t.sin.lane(k), t.cos.lane(k))), bits(&(t1.sin, t1.cos)), "{}", what("JointTrig::new"));
                $(
                    assert_eq!(bits(&m::$f(&q, &p).lane(k)), bits(&m::$f(c, &p1)), "{}", what(stringify!($f)));
                )*
                $(
                    assert_eq!(bits(&m::$ft(&t, &p).lane(k)), bits(&m::$ft(&t1, &p1)), "{}", what(stringify!($ft)));
                )*
            }
        }
        assert!(compared > 0);
    }};
}

#[test]
fn panda_on_lanes_is_the_scalar_code_bit_for_bit() {
    check!(
        panda_laparoscope,
        400,
        [
            forward_kinematics,
            forward_kinematics_i,
            body_jacobian,
            partial_body_jacobian,
            constrained_jacobian,
            constraint_jacobian_c,
            constrained_task_jacobian,
        ],
        [
            forward_kinematics_trig,
            forward_kinematics_i_trig,
            body_jacobian_trig,
            partial_body_jacobian_trig,
            constrained_jacobian_trig,
            constraint_jacobian_c_trig,
            constrained_task_jacobian_trig,
            pose_and_jacobians_trig,
        ]
    );
}

#[test]
fn reference_arm_presets_and_fixtures_on_lanes_are_the_scalar_code_bit_for_bit() {
    macro_rules! serial {
        ($($module:ident),*) => {$(
            check!(
                $module,
                150,
                [
                    forward_kinematics,
                    forward_kinematics_i,
                    body_jacobian,
                    partial_body_jacobian,
                    constrained_jacobian,
                    constraint_jacobian_c,
                ],
                [pose_and_jacobians_trig, constrained_jacobian_trig]
            );
        )*};
    }
    serial!(
        dia10_like_zy,
        bidirectional_zx,
        unidirectional,
        chain9_prismatic,
        rotated_rcm
    );
    check!(
        iiwa_endoscope,
        150,
        [forward_kinematics, constrained_task_jacobian],
        [pose_and_jacobians_trig]
    );
    check!(
        four_bar,
        150,
        [
            constraint_jacobian,
            task_jacobian,
            constraint_determinant,
            reduced_jacobian_numerator,
            passive_map_numerator,
        ],
        []
    );
}

/// `for_each_*` over a slice of the Panda's configurations (every length up to three groups, so
/// whole groups and every padded last group), with a fused function writing into its outputs
/// and a function returning its value: each result bit for bit the scalar code's.
#[test]
fn for_each_on_the_panda_is_the_scalar_code_bit_for_bit() {
    use g::panda_laparoscope as m;
    use trocar::emitted::lanes::{for_each_f32x8, for_each_f64x4};
    type Out<T> = (([[T; 3]; 3], [T; 3]), [[T; 6]; m::I]);
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    let all: Vec<[f64; m::N]> = (0..24)
        .map(|i| core::array::from_fn(|_| joint(&mut rng, i)))
        .collect();
    let (p, p1) = (m::Params::<F64x4>::nominal(), m::Params::<f64>::nominal());
    let (p8, p32) = (m::Params::<F32x8>::nominal(), m::Params::<f32>::nominal());
    for n in 0..=all.len() {
        let configs = &all[..n];
        let mut out = vec![Out::<f64>::default(); n];
        for_each_f64x4(
            configs,
            |q, o: &mut Out<F64x4>| m::link_pose_and_jacobian(q, &p, &mut o.0, &mut o.1),
            &mut out,
        );
        let mut jb = vec![[[f64::NAN; 6]; m::N]; n];
        for_each_f64x4(configs, |q, r| *r = m::body_jacobian(q, &p), &mut jb);
        for (i, c) in configs.iter().enumerate() {
            let mut o = Out::<f64>::default();
            m::link_pose_and_jacobian(c, &p1, &mut o.0, &mut o.1);
            assert_eq!(
                bits(&out[i]),
                bits(&o),
                "f64x4: {n} configurations, result {i}"
            );
            assert_eq!(
                bits(&jb[i]),
                bits(&m::body_jacobian(c, &p1)),
                "f64x4 body_jacobian: {n}, {i}"
            );
        }
        let configs: Vec<[f32; m::N]> = configs.iter().map(|c| c.map(|x| x as f32)).collect();
        let mut out = vec![Out::<f32>::default(); n];
        for_each_f32x8(
            &configs,
            |q, o: &mut Out<F32x8>| m::link_pose_and_jacobian(q, &p8, &mut o.0, &mut o.1),
            &mut out,
        );
        for (i, c) in configs.iter().enumerate() {
            let mut o = Out::<f32>::default();
            m::link_pose_and_jacobian(c, &p32, &mut o.0, &mut o.1);
            assert_eq!(
                bits(&out[i]),
                bits(&o),
                "f32x8: {n} configurations, result {i}"
            );
        }
    }
}
