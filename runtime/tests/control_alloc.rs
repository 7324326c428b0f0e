//! The control step allocates nothing: a counting global allocator (this test binary only).

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use trocar::control::{Controller, ControllerConfig, Damping, Method, Rcm, Reference};
use trocar::description::RobotDescription;
use trocar::nalgebra::{SVector, Vector2, Vector3};
use trocar::simulation::{Arm, Q0};

struct Counting;
static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        System.alloc(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        System.realloc(ptr, layout, new_size)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn control_step_allocates_nothing() {
    let arm = Arm::<8, 6, 2>::from_description(&RobotDescription::preset("dia10_like_zy").unwrap())
        .unwrap();
    let q0 = SVector::<f64, 8>::from(Q0);
    let (frames, g0) = arm.frames(&q0);
    let trocar = frames[5].translation + frames[5].rotation.column(1) * 0.15;
    let methods = [
        Method::Pinv,
        Method::Dls(Damping::Variable {
            alpha0: 0.05,
            w0: 0.1,
        }),
        Method::Fi {
            gamma_r: 5.0,
            gamma_l: 5.0,
        },
    ];
    let mut steps = 0;
    let before = ALLOCATIONS.load(Ordering::SeqCst);
    for method in methods {
        let mut ctrl = Controller::<f64, 8, 6, 2, 4, 6>::new(ControllerConfig {
            kp: 5.0,
            ko: 10.0,
            method,
            jb0i_damping: Some(Damping::Variable {
                alpha0: 0.05,
                w0: 0.01,
            }),
            kr: 20.0,
        });
        let mut q = q0;
        for k in 0..3000 {
            let t = k as f64 * 0.002;
            let reference = Reference {
                position: g0.translation + Vector3::new(0.01 * t.sin(), 0.0, 0.0),
                rotation: g0.rotation,
                velocity: Vector3::new(0.01 * t.cos(), 0.0, 0.0),
                angular_velocity: Vector3::zeros(),
            };
            let rcm = Rcm {
                trocar,
                dv: Vector2::new(0.001, 0.0),
            };
            let out = ctrl.step(&arm, &q, &reference, &rcm, 0.002).unwrap();
            q += out.qd * 0.002;
            steps += 1;
        }
    }
    let after = ALLOCATIONS.load(Ordering::SeqCst);
    assert_eq!(steps, 9000);
    assert_eq!(
        after - before,
        0,
        "{} allocations in {steps} steps",
        after - before
    );
}
