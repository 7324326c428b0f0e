//! The scene's C object under hostile input: every refused call writes nothing (the storage, the
//! outputs), a refused configuration leaves the object as it was, and `reset` starts the scene
//! again from rest.

mod common;

use common::{scene_config, Storage, DT};
use trocar_cpp_scene_example::three_ports as tp;
use trocar_cpp_scene_example::three_ports::panda_laparoscope::{
    C_BAD_STORAGE, C_INVALID_ARGUMENT, C_NULL_ARGUMENT,
};

const NS: usize = 21;
type Scene = Storage<{ tp::C_SCENE_SIZE }>;

fn init(storage: &mut Scene, config: &tp::CSceneConfig) -> i32 {
    // SAFETY: the storage's size and alignment as the header asks.
    unsafe { tp::three_ports_scene_init(storage.ptr(), tp::C_SCENE_SIZE, config) }
}

/// The start and the references that hold it (each tip where it is, no feed-forward).
fn start() -> ([f64; NS], [f64; 54]) {
    let mut q = [0.0; NS];
    // SAFETY: room for 21 values; no ports asked.
    assert_eq!(
        unsafe { tp::three_ports_scene_start(q.as_mut_ptr(), core::ptr::null_mut()) },
        0
    );
    let mut references = [0.0; 54];
    for k in 0..3 {
        let mut pose = [0.0; 12];
        // SAFETY: 7 joints, the one parameter, room for a pose.
        let code = unsafe {
            tp::panda_laparoscope::panda_laparoscope_forward_kinematics(
                q[7 * k..].as_ptr(),
                [0.25].as_ptr(),
                pose.as_mut_ptr(),
            )
        };
        assert_eq!(code, 0);
        references[18 * k..18 * k + 3].copy_from_slice(&pose[9..]);
        references[18 * k + 3..18 * k + 12].copy_from_slice(&pose[..9]);
    }
    (q, references)
}

/// One update with every output given, the outputs starting as sentinels.
fn update(
    storage: &mut Scene,
    q: &[f64; NS],
    references: &[f64; 54],
    ports: Option<&[f64; 9]>,
    dt: f64,
) -> (i32, [f64; NS], [i32; 3], [f64; 24], [f64; 3]) {
    let (mut qd, mut status, mut report, mut distances) = ([7.0; NS], [-7; 3], [7.0; 24], [7.0; 3]);
    // SAFETY: the sizes the header states.
    let code = unsafe {
        tp::three_ports_scene_update(
            storage.ptr(),
            q.as_ptr(),
            references.as_ptr(),
            ports.map_or(core::ptr::null(), |p| p.as_ptr()),
            dt,
            qd.as_mut_ptr(),
            status.as_mut_ptr(),
            report.as_mut_ptr(),
            distances.as_mut_ptr(),
        )
    };
    (code, qd, status, report, distances)
}

#[test]
fn a_still_scene_holds_and_reports_each_arm_and_coupling() {
    let mut s = Scene::new();
    assert_eq!(init(&mut s, &scene_config()), 0);
    let (q, references) = start();
    let (code, qd, status, report, distances) = update(&mut s, &q, &references, None, DT);
    assert_eq!(code, 0);
    assert_eq!(status, [0; 3]);
    assert!(qd.iter().all(|v| v.abs() < 1e-6), "{qd:?}");
    // The report's `l_a` (the trocar 0.25 m along each shaft) and `|e_p|`.
    for k in 0..3 {
        assert!((report[8 * k] - 0.25).abs() < 1e-9, "{report:?}");
        assert!(report[8 * k + 1] < 1e-9, "{report:?}");
    }
    // Each coupling's distance, as the stateless function measures it.
    let mut d = [0.0; 3];
    // SAFETY: the sizes the header states.
    let code = unsafe {
        tp::three_ports_coupling_distances(q.as_ptr(), core::ptr::null(), d.as_mut_ptr())
    };
    assert_eq!(code, 0);
    assert_eq!(d, distances);
    assert!(d.iter().all(|x| *x > 0.05 && *x < 0.08), "{d:?}");
}

#[test]
fn refused_configurations_write_nothing() {
    let mut s = Scene::new();
    let valid = scene_config();
    type Change = Box<dyn Fn(&mut tp::CSceneConfig)>;
    let bad: Vec<(&str, Change)> = vec![
        ("an arm's method", Box::new(|c| c.arms[1].method = 9)),
        ("a negative gain", Box::new(|c| c.arms[2].kp = -1.0)),
        (
            "an arm's range reversed",
            Box::new(|c| c.arms[0].lower[3] = 1.0),
        ),
        ("NaN safety", Box::new(|c| c.safety[0] = f64::NAN)),
        (
            "influence below safety",
            Box::new(|c| c.influence[1] = 0.005),
        ),
        ("negative safety", Box::new(|c| c.safety[2] = -0.01)),
        ("negative gain", Box::new(|c| c.gain[0] = -0.1)),
        ("1e300", Box::new(|c| c.influence[0] = 1e300)),
        ("subnormal", Box::new(|c| c.gain[0] = 1e-310)),
        ("no rate weight", Box::new(|c| c.rate_weight = 0.0)),
        (
            "negative orientation weight",
            Box::new(|c| c.orientation_weight = -1.0),
        ),
    ];
    for (what, change) in &bad {
        let mut config = valid;
        change(&mut config);
        assert_eq!(init(&mut s, &config), C_INVALID_ARGUMENT, "{what}");
        assert!(s.0.iter().all(|b| *b == 0), "{what}: storage written");
    }
    // A coupling switched off (all three 0) is a configuration.
    let mut off = valid;
    off.influence[0] = 0.0;
    off.safety[0] = 0.0;
    off.gain[0] = 0.0;
    assert_eq!(init(&mut s, &off), 0);
    // A refused configuration leaves the object as it was.
    let before = s.0;
    let mut config = valid;
    config.rate_weight = f64::NAN;
    assert_eq!(init(&mut s, &config), C_INVALID_ARGUMENT);
    assert!(s.0 == before);
}

#[test]
fn bad_storage_and_null_pointers_are_refused() {
    let config = scene_config();
    let mut s = Scene::new();
    // SAFETY: the storage is larger than the size given; a null storage or config is refused
    // before anything is read.
    unsafe {
        assert_eq!(
            tp::three_ports_scene_init(s.ptr(), 64, &config),
            C_BAD_STORAGE
        );
        assert_eq!(
            tp::three_ports_scene_init(
                s.ptr().cast::<u8>().add(8).cast(),
                tp::C_SCENE_SIZE - 8,
                &config
            ),
            C_BAD_STORAGE
        );
        assert_eq!(
            tp::three_ports_scene_init(core::ptr::null_mut(), tp::C_SCENE_SIZE, &config),
            C_NULL_ARGUMENT
        );
        assert_eq!(
            tp::three_ports_scene_init(s.ptr(), tp::C_SCENE_SIZE, core::ptr::null()),
            C_NULL_ARGUMENT
        );
        assert_eq!(tp::three_ports_scene_reset(s.ptr()), C_BAD_STORAGE);
        assert_eq!(
            tp::three_ports_scene_reset(core::ptr::null_mut()),
            C_NULL_ARGUMENT
        );
    }
    assert!(s.0.iter().all(|b| *b == 0));
    // Storage `init` did not write.
    let (q, references) = start();
    let (code, qd, ..) = update(&mut s, &q, &references, None, DT);
    assert_eq!(code, C_BAD_STORAGE);
    assert_eq!(qd, [7.0; NS]);
    assert_eq!(init(&mut s, &config), 0);
    let mut qd = [7.0; NS];
    // SAFETY: null inputs are refused before anything is read or written.
    unsafe {
        for (q, r, out) in [
            (core::ptr::null(), references.as_ptr(), qd.as_mut_ptr()),
            (q.as_ptr(), core::ptr::null(), qd.as_mut_ptr()),
            (q.as_ptr(), references.as_ptr(), core::ptr::null_mut()),
        ] {
            let code = tp::three_ports_scene_update(
                s.ptr(),
                q,
                r,
                core::ptr::null(),
                DT,
                out,
                core::ptr::null_mut(),
                core::ptr::null_mut(),
                core::ptr::null_mut(),
            );
            assert_eq!(code, C_NULL_ARGUMENT);
        }
    }
    assert_eq!(qd, [7.0; NS]);
}

#[test]
fn hostile_inputs_give_zero_rates_and_write_nothing_else() {
    let mut s = Scene::new();
    assert_eq!(init(&mut s, &scene_config()), 0);
    let (q, references) = start();
    let mut ports = [0.0; 9];
    // SAFETY: room for 9 values.
    assert_eq!(
        unsafe { tp::three_ports_scene_start(core::ptr::null_mut(), ports.as_mut_ptr()) },
        0
    );
    for bad in [f64::NAN, f64::INFINITY, -f64::INFINITY, 1e300, 1e-310] {
        for at in [0, 10, 20] {
            let mut q2 = q;
            q2[at] = bad;
            let (code, qd, status, report, distances) = update(&mut s, &q2, &references, None, DT);
            assert_eq!(code, C_INVALID_ARGUMENT, "q[{at}] = {bad}");
            assert_eq!(qd, [0.0; NS]);
            assert_eq!((status, report, distances), ([-7; 3], [7.0; 24], [7.0; 3]));
        }
        for at in [0, 5, 17, 40, 53] {
            let mut r = references;
            r[at] = bad;
            let (code, qd, ..) = update(&mut s, &q, &r, None, DT);
            assert_eq!(code, C_INVALID_ARGUMENT, "references[{at}] = {bad}");
            assert_eq!(qd, [0.0; NS]);
        }
        let mut p = ports;
        p[4] = bad;
        let (code, qd, ..) = update(&mut s, &q, &references, Some(&p), DT);
        assert_eq!(code, C_INVALID_ARGUMENT, "ports[4] = {bad}");
        assert_eq!(qd, [0.0; NS]);
        let (code, qd, ..) = update(&mut s, &q, &references, None, bad);
        assert_eq!(code, C_INVALID_ARGUMENT, "dt = {bad}");
        assert_eq!(qd, [0.0; NS]);
        let mut d = [7.0; 3];
        let mut q2 = q;
        q2[3] = bad;
        // SAFETY: the sizes the header states.
        let code = unsafe {
            tp::three_ports_coupling_distances(q2.as_ptr(), core::ptr::null(), d.as_mut_ptr())
        };
        assert_eq!((code, d), (C_INVALID_ARGUMENT, [7.0; 3]));
    }
    for dt in [0.0, -DT] {
        let (code, qd, ..) = update(&mut s, &q, &references, None, dt);
        assert_eq!((code, qd), (C_INVALID_ARGUMENT, [0.0; NS]), "dt = {dt}");
    }
    // `K dt` beyond its bound (K_p dt < 2 with K_p = 10).
    let (code, qd, ..) = update(&mut s, &q, &references, None, 0.5);
    assert_eq!((code, qd), (C_INVALID_ARGUMENT, [0.0; NS]));
    // A mirror image for an orientation: not a proper rotation.
    let mut r = references;
    for i in 3..6 {
        r[18 + i] = -r[18 + i];
    }
    let (code, qd, ..) = update(&mut s, &q, &r, None, DT);
    assert_eq!((code, qd), (C_INVALID_ARGUMENT, [0.0; NS]));
    // The camera: a point at the endoscope's port has no view axis.
    let mut reference = [7.0; 18];
    // SAFETY: 3, 3 and room for 18 values.
    let code = unsafe {
        tp::three_ports_camera_reference(
            ports[6..].as_ptr(),
            [0.0; 3].as_ptr(),
            reference.as_mut_ptr(),
        )
    };
    assert_eq!((code, reference), (C_INVALID_ARGUMENT, [7.0; 18]));
}

#[test]
fn reset_starts_the_scene_again_from_rest() {
    let mut s = Scene::new();
    assert_eq!(init(&mut s, &scene_config()), 0);
    let (q0, mut references) = start();
    // The instruments' tips asked 1 cm away: the arms accelerate within their limits.
    references[0] += 0.01;
    references[18] += 0.01;
    let run = |s: &mut Scene| {
        let mut q = q0;
        let mut rates = Vec::new();
        for _ in 0..20 {
            let (code, qd, ..) = update(s, &q, &references, None, DT);
            assert_eq!(code, 0);
            for (x, v) in q.iter_mut().zip(&qd) {
                *x += v * DT;
            }
            rates.push(qd);
        }
        rates
    };
    let first = run(&mut s);
    assert!(first[19].iter().any(|v| v.abs() > 1e-3));
    // Without a reset the acceleration limits continue from the last command: not the same.
    let again = run(&mut s);
    assert_ne!(first, again);
    // SAFETY: storage `init` wrote.
    assert_eq!(unsafe { tp::three_ports_scene_reset(s.ptr()) }, 0);
    assert_eq!(run(&mut s), first);
}
