//! The loop of `three_ports.cpp` through the scene's C ABI, in Rust: the endoscope aimed at the
//! instruments' midpoint by its arm's own controller object, then 4 s of the scene's step at
//! 500 Hz, the instruments' tips 7 cm along their paths, the endoscope following their midpoint.
#![allow(dead_code)]

use trocar_cpp_scene_example::three_ports as tp;
use trocar_cpp_scene_example::three_ports::panda_laparoscope as arm;

/// The sample time and the number of steps of the run (those of `trocar simulate three-ports`).
pub const DT: f64 = 0.002;
pub const STEPS: usize = 2000;
const N: usize = 7;
const A: usize = 3;

/// The storage of a C object: 16-byte aligned, as the headers ask.
#[repr(C, align(16))]
pub struct Storage<const S: usize>(pub [u8; S]);

impl<const S: usize> Storage<S> {
    pub fn new() -> Box<Self> {
        Box::new(Storage([0; S]))
    }
    pub fn ptr(&mut self) -> *mut core::ffi::c_void {
        self.0.as_mut_ptr().cast()
    }
}

/// Each arm's controller in the scene: the QP (`κ = 0.01`) with `K_p = K_o = K_r = 10`, the
/// Panda's URDF limits (the defaults), no speed limit beyond the joints' own, no joint-limit
/// objective.
pub fn arm_config() -> arm::CControllerConfig {
    let mut c = arm::CControllerConfig::DEFAULT;
    c.method = 3; // METHOD_QP
    c.kp = 10.0;
    c.ko = 10.0;
    c.kr = 10.0;
    c.qp_kappa = 0.01;
    c.max_joint_speed = 0.0;
    c.limit_gain = 0.0;
    c
}

/// The scene's configuration: every arm's [`arm_config`], the scene file's couplings.
pub fn scene_config() -> tp::CSceneConfig {
    let mut c = tp::CSceneConfig::DEFAULT;
    c.arms = [arm_config(); A];
    c
}

/// The tip's reference of an instrument: from `start` by `shift` along a smooth step over 2 s
/// from 0.5 s (18 values).
pub fn instrument_reference(start: &[f64; 12], shift: [f64; 3], t: f64) -> [f64; 18] {
    let s = ((t - 0.5) / 2.0).clamp(0.0, 1.0);
    let p = s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
    let v = if s > 0.0 && s < 1.0 {
        30.0 * s * s * (1.0 - s) * (1.0 - s) / 2.0
    } else {
        0.0
    };
    let mut r = [0.0; 18];
    for i in 0..3 {
        r[i] = start[9 + i] + shift[i] * p;
        r[12 + i] = shift[i] * v;
    }
    r[3..12].copy_from_slice(&start[..9]);
    r
}

/// The run: `t`, the 21 joints, the 21 rates, the smallest distance between two shafts, a row
/// a step (the rates of the last row zeros), as `three_ports.cpp` writes it.
pub fn c_run() -> Vec<Vec<f64>> {
    let params = [0.25];
    let mut q = [0.0; A * N];
    let mut ports = [0.0; A * 3];
    // SAFETY: room for A·N and A·3 values.
    assert_eq!(
        unsafe { tp::three_ports_scene_start(q.as_mut_ptr(), ports.as_mut_ptr()) },
        0
    );
    let mut start = [0.0; 12];
    // SAFETY: 7 joints, 1 parameter, room for a pose.
    let code = unsafe {
        arm::panda_laparoscope_forward_kinematics(q.as_ptr(), params.as_ptr(), start.as_mut_ptr())
    };
    assert_eq!(code, 0);
    let config = scene_config();
    // The endoscope aimed by its own controller object, the instruments still.
    let mut aim = Storage::<{ arm::C_CONTROLLER_SIZE }>::new();
    // SAFETY: storage of the size and alignment asked; a valid config.
    let code = unsafe {
        arm::panda_laparoscope_controller_init(aim.ptr(), arm::C_CONTROLLER_SIZE, &config.arms[2])
    };
    assert_eq!(code, 0);
    for _ in 0..1500 {
        let reference = camera_reference(camera_point(&q), [0.0; 3]);
        let mut qd = [0.0; N];
        // SAFETY: sizes as the header states; a null trocar rate and report.
        let code = unsafe {
            arm::panda_laparoscope_controller_update(
                aim.ptr(),
                q[2 * N..].as_ptr(),
                params.as_ptr(),
                reference.as_ptr(),
                ports[6..].as_ptr(),
                core::ptr::null(),
                DT,
                qd.as_mut_ptr(),
                core::ptr::null_mut(),
            )
        };
        assert_eq!(code, 0, "aiming the endoscope");
        if qd.iter().map(|v| v * v).sum::<f64>().sqrt() < 1e-9 {
            break;
        }
        for (j, v) in qd.iter().enumerate() {
            q[2 * N + j] += v * DT;
        }
    }
    // The scene.
    let mut scene = Storage::<{ tp::C_SCENE_SIZE }>::new();
    // SAFETY: as above.
    assert_eq!(
        unsafe { tp::three_ports_scene_init(scene.ptr(), tp::C_SCENE_SIZE, &config) },
        0
    );
    let shifts = [[0.07, 0.001, 0.0], [0.07, 0.001, 0.0]];
    let mut last: Option<(f64, [f64; 3])> = None;
    let mut rows = Vec::with_capacity(STEPS + 1);
    for step in 0..=STEPS {
        let t = step as f64 * DT;
        let mut references = [0.0; A * 18];
        for (k, shift) in shifts.iter().enumerate() {
            references[k * 18..(k + 1) * 18]
                .copy_from_slice(&instrument_reference(&start, *shift, t));
        }
        let point = camera_point(&q);
        let velocity = match last {
            Some((t0, p0)) if t > t0 => core::array::from_fn(|i| (point[i] - p0[i]) / (t - t0)),
            _ => [0.0; 3],
        };
        references[36..].copy_from_slice(&camera_reference(point, velocity));
        last = Some((t, point));
        let mut row = vec![t];
        row.extend_from_slice(&q);
        let mut qd = [0.0; A * N];
        if step < STEPS {
            // SAFETY: sizes as the header states; the scene's own ports.
            let code = unsafe {
                tp::three_ports_scene_update(
                    scene.ptr(),
                    q.as_ptr(),
                    references.as_ptr(),
                    core::ptr::null(),
                    DT,
                    qd.as_mut_ptr(),
                    core::ptr::null_mut(),
                    core::ptr::null_mut(),
                    core::ptr::null_mut(),
                )
            };
            assert!(
                code == 0 || code == tp::panda_laparoscope::C_JOINT_OUTSIDE,
                "t = {t}: {code}"
            );
        }
        row.extend_from_slice(&qd);
        let mut distances = [0.0; 3];
        // SAFETY: sizes as the header states.
        let code = unsafe {
            tp::three_ports_coupling_distances(
                q.as_ptr(),
                core::ptr::null(),
                distances.as_mut_ptr(),
            )
        };
        assert_eq!(code, 0);
        row.push(distances.iter().copied().fold(f64::INFINITY, f64::min));
        rows.push(row);
        for (x, v) in q.iter_mut().zip(&qd) {
            *x += v * DT;
        }
    }
    rows
}

/// The camera's point at `q`.
fn camera_point(q: &[f64; A * N]) -> [f64; 3] {
    let mut point = [0.0; 3];
    // SAFETY: A·N joints, room for 3.
    assert_eq!(
        unsafe { tp::three_ports_camera_point(q.as_ptr(), point.as_mut_ptr()) },
        0
    );
    point
}

/// The endoscope's reference toward `point`, the point moving at `velocity`.
fn camera_reference(point: [f64; 3], velocity: [f64; 3]) -> [f64; 18] {
    let mut reference = [0.0; 18];
    // SAFETY: 3, 3 and room for 18.
    let code = unsafe {
        tp::three_ports_camera_reference(point.as_ptr(), velocity.as_ptr(), reference.as_mut_ptr())
    };
    assert_eq!(code, 0);
    reference
}

/// The columns of the run, by name, as the command line names them.
pub fn columns() -> Vec<String> {
    let mut c = vec!["t".to_string()];
    c.extend((1..=21).map(|k| format!("q{k}")));
    c.extend((1..=21).map(|k| format!("qd{k}")));
    c.push("min_shaft_distance".into());
    c
}

/// The Rust run of the scene (`trocar simulate three-ports`), its columns [`columns`].
pub fn rust_run() -> Vec<Vec<f64>> {
    let trace = trocar_sim::scene::simulate("three-ports", true, |_| {}).expect("the Rust run");
    let index: Vec<usize> = columns()
        .iter()
        .map(|c| {
            trace
                .columns
                .iter()
                .position(|x| x == c)
                .unwrap_or_else(|| panic!("no column {c}"))
        })
        .collect();
    trace
        .rows
        .iter()
        .map(|row| index.iter().map(|&i| row[i]).collect())
        .collect()
}

/// The largest difference between two runs, and where: `(difference, row, column)`.
pub fn largest_difference(a: &[Vec<f64>], b: &[Vec<f64>]) -> (f64, usize, usize) {
    assert_eq!(a.len(), b.len(), "the runs have different numbers of rows");
    let mut worst = (0.0, 0, 0);
    for (r, (x, y)) in a.iter().zip(b).enumerate() {
        assert_eq!(x.len(), y.len(), "row {r}: different numbers of columns");
        for (c, (u, v)) in x.iter().zip(y).enumerate() {
            let d = (u - v).abs();
            // A NaN counts as the largest difference.
            if d.is_nan() || d > worst.0 {
                worst = (d, r, c);
            }
        }
    }
    worst
}
