//! A scene's C ABI (`trocar generate SCENE --cmake DIR`, [`crate::Builder::scene`] with
//! [`crate::Builder::c_api`]): the scene's step as a C object, as the arms' controller objects
//! are ([`super::c_controller`]), so that a C or C++ loop steps several arms through their own
//! ports with the couplings between them — `trocar::control::scene::Scene::step` on the
//! generated kinematics — without allocation.
//!
//! - `<scene>_scene_config_default`, `_scene_init`, `_scene_reset`, `_scene_update`: the object
//!   in caller-provided storage (`<SCENE>_SCENE_SIZE` bytes aligned to `<SCENE>_SCENE_ALIGN`),
//!   configured by `<scene>_scene_config` — each arm's `<arm>_config` (every method, the QP
//!   included, its gains and hard limits), each coupling's damper, the weights of (S1);
//! - `<scene>_scene_start` (each arm's joints and port at the start), `<scene>_coupling_distances`
//!   (each coupling's distance at any joints, without stepping);
//! - with an endoscope, `<scene>_camera_point` and `<scene>_camera_reference`: the point its
//!   camera looks at and the camera arm's reference toward it.
//!
//! Every arm's module carries its own C ABI (`<arm>_...`) inside the scene's library. The
//! configuration is checked by the arms' rules (`<arm>_config` as the controller object checks
//! it) and the couplings' (`Coupling::is_admissible`), every number by the number rule.

use super::c_abi::{c_type, C_MAX_MAGNITUDE};
use crate::ir::Real;
use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};
use std::fmt::Write as _;

/// The storage's alignment (bytes, a power of two).
pub const ALIGN: usize = 16;

/// What the scene's C ABI is emitted from.
pub struct SceneC {
    /// The scene's module name (the prefix of its C symbols).
    pub name: String,
    /// Each arm's module (the same module for arms of one description).
    pub arm_modules: Vec<String>,
    /// The fields of the arms' `<arm>_config` (the same in every arm module of a scene).
    pub config_fields: Vec<&'static str>,
    /// A bound on one arm's controller object's state (bytes).
    pub arm_size: usize,
    /// The arms' joints `N`.
    pub joints: usize,
    /// The task rows of the arms' controllers, as a token (`TASK_ROWS` of the first module, or 6).
    pub task_rows: TokenStream,
    /// Each coupling's damper at the start: influence, safety, gain.
    pub couplings: Vec<[f64; 3]>,
    /// The weights of (S1): the tasks' angular rows, and the rates themselves.
    pub weights: [f64; 2],
    /// The camera's arm, if the scene has an endoscope.
    pub camera: Option<usize>,
}

impl SceneC {
    fn first(&self) -> &str {
        &self.arm_modules[0]
    }

    /// A bound on the state's size: the arms' controller objects, the configuration, and the
    /// scene's couplings and warm start (`ActiveSet` over `A·N` rates and `2P` coupling rows)
    /// and its QP's workspace.
    fn size_bound(&self) -> usize {
        let (a, p) = (self.arm_modules.len(), self.couplings.len());
        let (ns, c) = (a * self.joints, 2 * p);
        // The QP's workspace (`trocar::qp::Dual`): three `ns × ns` matrices of reals and a few
        // vectors and index arrays of `ns`.
        let workspace = 8 * (3 * ns * ns + 6 * ns) + 40 * ns + 64;
        let bytes = a * self.arm_size + 8 * (64 + 8 * p) + 16 * (ns + c) + 512 + workspace;
        bytes.div_ceil(ALIGN) * ALIGN
    }

    /// The C symbols the scene's module exports besides its arms'.
    pub fn symbols(&self) -> Vec<String> {
        let mut list: Vec<&str> = vec![
            "scene_config_default",
            "scene_init",
            "scene_reset",
            "scene_update",
            "scene_start",
            "coupling_distances",
        ];
        if self.camera.is_some() {
            list.extend(["camera_point", "camera_reference"]);
        }
        list.iter().map(|f| format!("{}_{f}", self.name)).collect()
    }

    /// The Rust items inside the scene's module.
    pub fn items(&self, real: Real, rt: &TokenStream) -> TokenStream {
        let (t, targs, fish) = match real {
            Real::F32 => (quote!(f32), quote!(), quote!()),
            Real::F64 => (quote!(f64), quote!(), quote!()),
            Real::Generic => (quote!(f64), quote!(<f64>), quote!(::<f64>)),
        };
        let first = format_ident!("{}", self.first());
        let name = &self.name;
        let f = |s: &str| format_ident!("{name}_{s}");
        let (f_default, f_init, f_reset, f_update, f_start, f_distances) = (
            f("scene_config_default"),
            f("scene_init"),
            f("scene_reset"),
            f("scene_update"),
            f("scene_start"),
            f("coupling_distances"),
        );
        let q_rows = &self.task_rows;
        let fields: Vec<_> = self
            .config_fields
            .iter()
            .map(|f| format_ident!("{f}"))
            .collect();
        let arm_defaults = self.arm_modules.iter().map(|m| {
            let m = format_ident!("{m}");
            if m == first {
                quote!(#first::CControllerConfig::DEFAULT)
            } else {
                let fields = &fields;
                quote!({
                    let d = #m::CControllerConfig::DEFAULT;
                    #first::CControllerConfig { #(#fields: d.#fields),* }
                })
            }
        });
        let column = |k: usize| {
            let v = self
                .couplings
                .iter()
                .map(move |c| Literal::f64_unsuffixed(c[k]));
            quote!([#(#v),*])
        };
        let (influence, safety, gain) = (column(0), column(1), column(2));
        let (wo, wr) = (
            Literal::f64_unsuffixed(self.weights[0]),
            Literal::f64_unsuffixed(self.weights[1]),
        );
        let size = Literal::usize_unsuffixed(self.size_bound());
        let align = Literal::usize_unsuffixed(ALIGN);
        let magic = Literal::u64_unsuffixed(super::c_controller::fnv1a(&format!("{name}.scene")));
        let camera = self.camera.map(|_| {
            let (f_point, f_reference) = (f("camera_point"), f("camera_reference"));
            quote! {
                /// C ABI: the point the endoscope's camera looks at (`CAMERA_LOOKS_AT`'s tips'
                /// mean) at the arms' joints `q` (`A·N` values, arm after arm), in the camera
                /// arm's base frame, into `point` (3). Returns 0, `C_INVALID_ARGUMENT` (a joint
                /// outside the number rule; nothing written), `C_CONTROL_ERROR`,
                /// `C_NULL_ARGUMENT`.
                ///
                /// # Safety
                /// `q` points to `A·N` values, `point` to room for 3 overlapping them.
                #[unsafe(no_mangle)]
                pub unsafe extern "C" fn #f_point(q: *const #t, point: *mut #t) -> i32 {
                    use #rt::emitted::nalgebra::SVector;
                    if q.is_null() || point.is_null() {
                        return C_NULL_ARGUMENT;
                    }
                    // SAFETY: non-null and, by the caller's contract, `A·N` values.
                    let q = unsafe { &*q.cast::<[[#t; N]; A]>() };
                    if !q.iter().flatten().all(|v| c_number_ok(*v)) {
                        return C_INVALID_ARGUMENT;
                    }
                    let q = q.map(SVector::from);
                    match #rt::emitted::camera_point::<#t, ArmKinematics #targs, A, N, I, R, K, M, #q_rows>(
                        &kinematics #fish (),
                        &q,
                        &bases #fish (),
                        &CAMERA_LOOKS_AT,
                        CAMERA_ARM,
                    ) {
                        Ok(p) if p.iter().all(|v| v.is_finite()) => {
                            // SAFETY: non-null, room for 3 values by the caller's contract.
                            unsafe { point.cast::<[#t; 3]>().write([p[0], p[1], p[2]]) };
                            0
                        }
                        _ => C_CONTROL_ERROR,
                    }
                }

                /// C ABI: the camera arm's reference (18 values: position, orientation
                /// column-major, velocity, angular velocity, its base frame) that puts `point`
                /// (3), moving at `velocity` (3), on its view axis (`Camera::reference`). Returns
                /// 0; `C_INVALID_ARGUMENT` for an input outside the number rule, a point at the
                /// port or opposite the start's view axis (nothing written); `C_NULL_ARGUMENT`.
                ///
                /// # Safety
                /// `point` and `velocity` point to 3 values, `reference` to room for 18
                /// overlapping them.
                #[unsafe(no_mangle)]
                pub unsafe extern "C" fn #f_reference(
                    point: *const #t,
                    velocity: *const #t,
                    reference: *mut #t,
                ) -> i32 {
                    use #rt::emitted::nalgebra::Vector3;
                    if point.is_null() || velocity.is_null() || reference.is_null() {
                        return C_NULL_ARGUMENT;
                    }
                    // SAFETY: non-null and, by the caller's contract, 3 values each.
                    let (p, v) = unsafe { (*point.cast::<[#t; 3]>(), *velocity.cast::<[#t; 3]>()) };
                    if !p.iter().chain(&v).all(|x| c_number_ok(*x)) {
                        return C_INVALID_ARGUMENT;
                    }
                    let Some(r) = camera #fish ().reference(&Vector3::from(p), &Vector3::from(v)) else {
                        return C_INVALID_ARGUMENT;
                    };
                    let mut out = [0.0; 18];
                    out[..3].copy_from_slice(r.position.as_slice());
                    out[3..12].copy_from_slice(r.rotation.as_slice());
                    out[12..15].copy_from_slice(r.velocity.as_slice());
                    out[15..].copy_from_slice(r.angular_velocity.as_slice());
                    if !out.iter().all(|x| x.is_finite()) {
                        return C_INVALID_ARGUMENT;
                    }
                    // SAFETY: non-null, room for 18 values by the caller's contract.
                    unsafe { reference.cast::<[#t; 18]>().write(out) };
                    0
                }
            }
        });
        quote! {
            use self::#first::{
                c_error_code, c_number_ok, c_object, c_reference, c_status_code, c_step_report,
                C_BAD_STORAGE, C_CONTROL_ERROR, C_COUPLING_YIELDED, C_INVALID_ARGUMENT,
                C_NULL_ARGUMENT,
            };

            /// The configuration of the scene's C object (`<scene>_scene_config` in the C
            /// header, the same layout): each arm's controller (`<arm>_config`), each
            /// coupling's damper (an influence, safety and gain of 0 switch it off), and the
            /// weights of (S1).
            #[repr(C)]
            #[derive(Clone, Copy, Debug, PartialEq)]
            pub struct CSceneConfig {
                /// Each arm's controller: method, gains, hard limits.
                pub arms: [#first::CControllerConfig; A],
                /// Each coupling's influence distance `d_i` (m).
                pub influence: [#t; P],
                /// Each coupling's safety distance `d_s` (m).
                pub safety: [#t; P],
                /// Each coupling's damper gain `ξ` (m/s).
                pub gain: [#t; P],
                /// The weight of the tasks' angular rows against their linear ones in (S1).
                pub orientation_weight: #t,
                /// The weight `ε` of the rates' change in (S1) (> 0).
                pub rate_weight: #t,
            }

            impl CSceneConfig {
                /// The defaults: each arm's controller defaults, the scene file's couplings and
                /// weights.
                pub const DEFAULT: Self = CSceneConfig {
                    arms: [#(#arm_defaults),*],
                    influence: #influence,
                    safety: #safety,
                    gain: #gain,
                    orientation_weight: #wo,
                    rate_weight: #wr,
                };

                /// The scene's step and its arms' controllers for this configuration, or the C
                /// return code that refuses it.
                fn build(&self) -> Result<(Scene #targs, [ArmController #targs; A]), i32> {
                    let mut arms = [self.arms[0].controller()?; A];
                    for (arm, config) in arms.iter_mut().zip(&self.arms).skip(1) {
                        *arm = config.controller()?;
                    }
                    let weights = [self.orientation_weight, self.rate_weight];
                    if !(self
                        .influence
                        .iter()
                        .chain(&self.safety)
                        .chain(&self.gain)
                        .chain(&weights)
                        .all(|v| c_number_ok(*v))
                        && self.orientation_weight >= 0.0
                        && self.rate_weight > 0.0)
                    {
                        return Err(C_INVALID_ARGUMENT);
                    }
                    let mut couplings = couplings #fish ();
                    for (p, c) in couplings.iter_mut().enumerate() {
                        c.damper = #rt::emitted::Damper {
                            influence: self.influence[p],
                            safety: self.safety[p],
                            gain: self.gain[p],
                        };
                        if !c.is_admissible() {
                            return Err(C_INVALID_ARGUMENT);
                        }
                    }
                    let mut scene = #rt::emitted::Scene::new(couplings);
                    scene.orientation_weight = self.orientation_weight;
                    scene.rate_weight = self.rate_weight;
                    Ok((scene, arms))
                }
            }

            /// What the C caller's storage holds after `init`: the scene's identity, the
            /// configuration (for `reset`), the scene's step and the arms' controllers.
            #[repr(C)]
            struct CSceneState {
                magic: u64,
                config: CSceneConfig,
                scene: Scene #targs,
                arms: [ArmController #targs; A],
            }

            /// The storage (bytes) a C caller provides for the scene object (the header's
            /// `SCENE_SIZE`): a bound from the scene's sizes, at least the state's size.
            pub const C_SCENE_SIZE: usize = #size;
            /// The storage's alignment (the header's `SCENE_ALIGN`).
            pub const C_SCENE_ALIGN: usize = #align;
            const C_SCENE_MAGIC: u64 = #magic;
            const _: () = assert!(
                ::core::mem::size_of::<CSceneState>() <= C_SCENE_SIZE
                    && ::core::mem::align_of::<CSceneState>() <= C_SCENE_ALIGN,
                "the scene's state outgrew the storage the C header gives it"
            );

            /// The scene object's state in `storage`, if `init` wrote it there.
            ///
            /// # Safety
            /// `storage` is null or points to `C_SCENE_SIZE` initialised bytes (written by
            /// `init`, or zeroed), aligned, that no other reference aliases.
            unsafe fn c_scene_state<'a>(storage: *mut ::core::ffi::c_void) -> Result<&'a mut CSceneState, i32> {
                // SAFETY: `CSceneState` is `#[repr(C)]` with its `magic: u64` first, at most
                // `C_SCENE_SIZE` bytes (asserted above); the rest is the caller's contract.
                unsafe { c_object(storage, C_SCENE_ALIGN, C_SCENE_MAGIC) }
            }

            /// C ABI: fills `config` with the defaults (`CSceneConfig::DEFAULT`). Returns 0,
            /// or `C_NULL_ARGUMENT`.
            ///
            /// # Safety
            /// `config` is null or points to room for a `CSceneConfig`.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn #f_default(config: *mut CSceneConfig) -> i32 {
                if config.is_null() {
                    return C_NULL_ARGUMENT;
                }
                // SAFETY: non-null and, by the caller's contract, room for the struct.
                unsafe { config.write(CSceneConfig::DEFAULT) };
                0
            }

            /// C ABI: writes the scene object into `storage` (`size` bytes, aligned to
            /// `C_SCENE_ALIGN`) from `config`. Returns 0; `C_INVALID_ARGUMENT` for a
            /// configuration the rules refuse; `C_BAD_STORAGE` for storage too small or not
            /// aligned; `C_NULL_ARGUMENT`. Nothing is written unless it returns 0.
            ///
            /// # Safety
            /// `storage` points to `size` writable bytes that nothing else uses while the object
            /// lives; `config` to a `CSceneConfig`.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn #f_init(
                storage: *mut ::core::ffi::c_void,
                size: usize,
                config: *const CSceneConfig,
            ) -> i32 {
                if storage.is_null() || config.is_null() {
                    return C_NULL_ARGUMENT;
                }
                if size < ::core::mem::size_of::<CSceneState>()
                    || (storage as usize) & (C_SCENE_ALIGN - 1) != 0
                {
                    return C_BAD_STORAGE;
                }
                // SAFETY: non-null and, by the caller's contract, a readable struct (every bit
                // pattern of its `i32`s and reals is a valid value).
                let config = unsafe { config.read() };
                let (scene, arms) = match config.build() {
                    Ok(built) => built,
                    Err(code) => return code,
                };
                // SAFETY: non-null, aligned and at least the state's size (checked above), and
                // the caller's to write.
                unsafe {
                    storage.cast::<CSceneState>().write(CSceneState {
                        magic: C_SCENE_MAGIC,
                        config,
                        scene,
                        arms,
                    })
                };
                0
            }

            /// C ABI: the scene as `init` left it (every arm's last command, the QP's warm
            /// starts forgotten), its configuration kept. Returns 0, `C_BAD_STORAGE`,
            /// `C_NULL_ARGUMENT`.
            ///
            /// # Safety
            /// `storage` is null or points to `C_SCENE_SIZE` aligned bytes that nothing else
            /// uses.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn #f_reset(storage: *mut ::core::ffi::c_void) -> i32 {
                // SAFETY: the caller's contract.
                let state = match unsafe { c_scene_state(storage) } {
                    Ok(s) => s,
                    Err(code) => return code,
                };
                match state.config.build() {
                    Ok((scene, arms)) => {
                        state.scene = scene;
                        state.arms = arms;
                        0
                    }
                    Err(code) => code,
                }
            }

            /// C ABI: one step of the scene (`Scene::step`): each arm's own step toward its
            /// reference, then the couplings and the shared joints. `q` the arms' joints (`A·N`
            /// values, arm after arm; a shared joint in each arm that holds it), `references`
            /// each arm's reference (18 values each, its base frame, as the controller object
            /// takes it), `ports` each arm's port (3 values each, its base frame; null: the
            /// scene's ports at the start), `dt` the sample time. Writes the `A·N` rates into
            /// `qd` and, where not null, each arm's status code into `status` (`A`), its 8
            /// report values into `report` (`A·8`, as the controller object's) and each
            /// coupling's distance at `q` into `distances` (`P`).
            ///
            /// Returns 0 (every port, limit and coupling held); `C_COUPLING_YIELDED` (a
            /// coupling gave way to the ports and the limits); else the first arm's code
            /// that is not 0 (`C_TROCAR_YIELDED`, `C_JOINT_OUTSIDE`, `C_DEPTH_OUTSIDE`) — the
            /// outputs written in each case; `C_INVALID_ARGUMENT` (an input outside the
            /// number rule, an orientation that is not a proper rotation, `dt ≤ 0`, `K dt`
            /// beyond its bound) or `C_CONTROL_ERROR`, both with `qd` zeros and nothing else
            /// written (the arms' controllers may have moved on: `reset`);
            /// `C_BAD_STORAGE`; `C_NULL_ARGUMENT` (nothing written).
            ///
            /// # Safety
            /// `storage` as for `reset`; `q` points to `A·N` values, `references` to `A·18`,
            /// `ports` to `A·3` or is null, `qd` to room for `A·N`, `status` to room for `A`
            /// or is null, `report` to room for `A·8` or is null, `distances` to room for `P`
            /// or is null; the outputs overlap no input and no other output.
            #[unsafe(no_mangle)]
            #[allow(clippy::too_many_arguments)]
            pub unsafe extern "C" fn #f_update(
                storage: *mut ::core::ffi::c_void,
                q: *const #t,
                references: *const #t,
                ports: *const #t,
                dt: #t,
                qd: *mut #t,
                status: *mut i32,
                report: *mut #t,
                distances: *mut #t,
            ) -> i32 {
                use #rt::emitted::nalgebra::SVector;
                if q.is_null() || references.is_null() || qd.is_null() {
                    return C_NULL_ARGUMENT;
                }
                // SAFETY: the caller's contract.
                let state = match unsafe { c_scene_state(storage) } {
                    Ok(s) => s,
                    Err(code) => return code,
                };
                // SAFETY: each pointer is non-null (checked above; `ports` where it is not null)
                // and, by the caller's contract, points to as many values as read here.
                let (q, references, ports) = unsafe {
                    (
                        &*q.cast::<[[#t; N]; A]>(),
                        &*references.cast::<[[#t; 18]; A]>(),
                        (!ports.is_null()).then(|| &*ports.cast::<[[#t; 3]; A]>()),
                    )
                };
                // SAFETY: non-null (checked above), room for `A·N` values overlapping no input.
                let qd: &mut [[#t; N]; A] = unsafe { &mut *qd.cast::<[[#t; N]; A]>() };
                let read_ok = q
                    .iter()
                    .flatten()
                    .chain(references.iter().flatten())
                    .chain(ports.iter().flat_map(|p| p.iter().flatten()))
                    .all(|v| c_number_ok(*v))
                    && c_number_ok(dt)
                    && dt > 0.0;
                let targets = references.map(|r| c_reference(&r));
                if !read_ok || !targets.iter().all(|r| #rt::emitted::is_rotation(&r.rotation)) {
                    *qd = [[0.0; N]; A];
                    return C_INVALID_ARGUMENT;
                }
                let rcms = c_rcms(ports);
                let q = q.map(SVector::from);
                let CSceneState { scene, arms, .. } = state;
                let result = scene.step::<ArmKinematics #targs, A, N, I, R, K, M, #q_rows, ES>(
                    arms,
                    &kinematics #fish (),
                    &q,
                    &targets,
                    &rcms,
                    &bases #fish (),
                    &SHARED,
                    dt,
                );
                let out = match result {
                    Ok(out) => out,
                    Err(e) => {
                        *qd = [[0.0; N]; A];
                        return match e {
                            #rt::emitted::SceneError::Arm(_, e) => c_error_code(e),
                            _ => C_CONTROL_ERROR,
                        };
                    }
                };
                let reports = out.arms.map(|o| c_step_report(&o));
                let finite = out.qd.iter().all(|x| x.iter().all(|v| v.is_finite()))
                    && reports.iter().flatten().all(|v| v.is_finite())
                    && out.distances.iter().all(|v| v.is_finite());
                if !finite {
                    *qd = [[0.0; N]; A];
                    return C_CONTROL_ERROR;
                }
                for (to, from) in qd.iter_mut().zip(&out.qd) {
                    to.copy_from_slice(from.as_slice());
                }
                let codes = out.arms.map(|o| c_status_code(o.status));
                // SAFETY: each output is null or, by the caller's contract, room for the values
                // written, overlapping nothing else.
                unsafe {
                    if !status.is_null() {
                        status.cast::<[i32; A]>().write(codes);
                    }
                    if !report.is_null() {
                        report.cast::<[[#t; 8]; A]>().write(reports);
                    }
                    if !distances.is_null() {
                        distances.cast::<[#t; P]>().write(out.distances);
                    }
                }
                if !out.coupling_held {
                    return C_COUPLING_YIELDED;
                }
                codes.into_iter().find(|c| *c != 0).unwrap_or(0)
            }

            /// C ABI: the scene at its start: each arm's joints into `q0` (`A·N`) and its port
            /// (its base frame) into `ports` (`A·3`), each where not null. Returns 0.
            ///
            /// # Safety
            /// `q0` is null or room for `A·N` values, `ports` null or room for `A·3`.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn #f_start(q0: *mut #t, ports: *mut #t) -> i32 {
                // SAFETY: each pointer is null or, by the caller's contract, room for the
                // values written.
                unsafe {
                    if !q0.is_null() {
                        q0.cast::<[[#t; N]; A]>().write(q0_values());
                    }
                    if !ports.is_null() {
                        ports.cast::<[[#t; 3]; A]>().write(rcms #fish ().map(|r| [r.trocar[0], r.trocar[1], r.trocar[2]]));
                    }
                }
                0
            }

            /// Each arm's joints at the start as arrays.
            fn q0_values() -> [[#t; N]; A] {
                let mut out = [[0.0; N]; A];
                for (to, from) in out.iter_mut().zip(q0 #fish ()) {
                    to.copy_from_slice(from.as_slice());
                }
                out
            }

            /// Each arm's port: the caller's (its base frame) where given, else the scene's.
            fn c_rcms(ports: Option<&[[#t; 3]; A]>) -> [#rt::emitted::Rcm<#t, R>; A] {
                let mut rcms = rcms #fish ();
                if let Some(ports) = ports {
                    for (rcm, port) in rcms.iter_mut().zip(ports) {
                        rcm.trocar = #rt::emitted::nalgebra::Vector3::from(*port);
                    }
                }
                rcms
            }

            /// C ABI: each coupling's distance (m) at the arms' joints `q` (`A·N`) with their
            /// ports `ports` (`A·3`, each arm's base frame; null: the scene's), as the step
            /// measures it, into `distances` (`P`). Returns 0; `C_INVALID_ARGUMENT` (an input
            /// outside the number rule; nothing written); `C_CONTROL_ERROR`;
            /// `C_NULL_ARGUMENT`.
            ///
            /// # Safety
            /// `q` points to `A·N` values, `ports` to `A·3` or is null, `distances` to room for
            /// `P` overlapping them.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn #f_distances(
                q: *const #t,
                ports: *const #t,
                distances: *mut #t,
            ) -> i32 {
                use #rt::emitted::nalgebra::SVector;
                if q.is_null() || distances.is_null() {
                    return C_NULL_ARGUMENT;
                }
                // SAFETY: non-null (`ports` where it is not null) and, by the caller's
                // contract, as many values as read here.
                let (q, ports) = unsafe {
                    (
                        &*q.cast::<[[#t; N]; A]>(),
                        (!ports.is_null()).then(|| &*ports.cast::<[[#t; 3]; A]>()),
                    )
                };
                if !q
                    .iter()
                    .flatten()
                    .chain(ports.iter().flat_map(|p| p.iter().flatten()))
                    .all(|v| c_number_ok(*v))
                {
                    return C_INVALID_ARGUMENT;
                }
                let rcms = c_rcms(ports);
                let q = q.map(SVector::from);
                match scene #fish ().distances::<ArmKinematics #targs, A, N, I, R, K, M, #q_rows>(
                    &kinematics #fish (),
                    &q,
                    &rcms,
                    &bases #fish (),
                ) {
                    Ok(d) if d.iter().all(|v| v.is_finite()) => {
                        // SAFETY: non-null, room for `P` values by the caller's contract.
                        unsafe { distances.cast::<[#t; P]>().write(d) };
                        0
                    }
                    _ => C_CONTROL_ERROR,
                }
            }

            #camera
        }
    }

    /// The C header of the scene's part (after its arms' headers, which it includes).
    pub fn header(&self, real: Real) -> String {
        let ct = c_type(real);
        let m = &self.name;
        let upper = m.to_uppercase();
        let first = self.first();
        let (a, p, n) = (self.arm_modules.len(), self.couplings.len(), self.joints);
        let mut distinct: Vec<&String> = Vec::new();
        for arm in &self.arm_modules {
            if !distinct.contains(&arm) {
                distinct.push(arm);
            }
        }
        let mut h = String::new();
        let _ = writeln!(
            h,
            "/* C ABI of the trocar-generated scene `{m}` (trocar generate {m} --cmake DIR): {a} arms,\n   \
             each through its own port, {p} couplings between their instruments. Each arm's module\n   \
             ({arms}) has its own C ABI in the same library (its header is included below).\n\n   \
             The scene object: trocar's scene step (each arm's constrained controller, then the\n   \
             couplings as hard inequalities by a QP over all the arms' rates, the ports and the\n   \
             joint limits first) with its state in storage the caller provides,\n   \
             {upper}_SCENE_SIZE bytes aligned to {upper}_SCENE_ALIGN. No call allocates. Arrays of\n   \
             all the arms hold arm 0's values first. */",
            arms = distinct
                .iter()
                .map(|s| s.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        );
        let guard = format!("TROCAR_{upper}_SCENE_H");
        let _ = writeln!(h, "#ifndef {guard}\n#define {guard}\n\n#include <stddef.h>");
        for arm in &distinct {
            let _ = writeln!(h, "#include \"{arm}.h\"");
        }
        let first_upper = first.to_uppercase();
        let _ = writeln!(
            h,
            "\n#define {upper}_ARMS {a} /* arms */\n\
             #define {upper}_JOINTS {n} /* joints of each arm */\n\
             #define {upper}_RATES {ns} /* the arms' joints together */\n\
             #define {upper}_COUPLINGS {p}\n\
             #define {upper}_SCENE_SIZE {size}\n\
             #define {upper}_SCENE_ALIGN {ALIGN}\n\
             /* The return codes are the arms' ({first_upper}_...); a coupling that gave way: */\n\
             #define {upper}_COUPLING_YIELDED {first_upper}_COUPLING_YIELDED",
            ns = a * n,
            size = self.size_bound(),
        );
        if let Some(k) = self.camera {
            let _ = writeln!(
                h,
                "#define {upper}_CAMERA_ARM {k} /* the endoscope's arm */"
            );
        }
        let _ = writeln!(
            h,
            "\n#ifdef __cplusplus\nextern \"C\" {{\n#endif\n\n\
             /* The scene's configuration: each arm's controller ({first}_config: method, gains,\n   \
             limits, as {first}_controller_init takes it), each coupling's damper (influence >\n   \
             safety >= 0, gain >= 0; all three 0 switch the coupling off), the weights of the\n   \
             tasks' angular rows (>= 0) and of the rates' change (> 0). Every number finite, not\n   \
             subnormal, within +-{max:e}. */\n\
             typedef struct {{\n    \
             {first}_config arms[{a}];\n    \
             {ct} influence[{p}]; /* m */\n    \
             {ct} safety[{p}]; /* m */\n    \
             {ct} gain[{p}]; /* m/s */\n    \
             {ct} orientation_weight;\n    \
             {ct} rate_weight;\n\
             }} {m}_scene_config;\n\n\
             /* Fills config with the defaults (each arm's controller defaults, the scene file's\n   \
             couplings and weights). Returns 0 or {first_upper}_NULL_ARGUMENT. */\n\
             int {m}_scene_config_default({m}_scene_config *config);\n\n\
             /* Writes the scene object into storage (size bytes, aligned to {upper}_SCENE_ALIGN).\n   \
             Returns 0; {first_upper}_INVALID_ARGUMENT for a configuration outside the rules;\n   \
             {first_upper}_BAD_STORAGE; {first_upper}_NULL_ARGUMENT. Nothing is written unless it\n   \
             returns 0. */\n\
             int {m}_scene_init(void *storage, size_t size, const {m}_scene_config *config);\n\n\
             /* The scene as init left it, its configuration kept. Returns 0,\n   \
             {first_upper}_BAD_STORAGE, {first_upper}_NULL_ARGUMENT. */\n\
             int {m}_scene_reset(void *storage);\n\n\
             /* One step. q[{ns}]: the arms' joints; references[{a} * 18]: each arm's reference as\n   \
             {first}_controller_update takes it (its base frame); ports[{a} * 3]: each arm's port\n   \
             (its base frame; NULL: the scene's own); dt > 0. qd[{ns}]: the rates, within every\n   \
             arm's limits; status[{a}] (or NULL): each arm's own code; report[{a} * 8] (or NULL):\n   \
             each arm's report as the controller object's; distances[{p}] (or NULL): each\n   \
             coupling's distance at q (m). Returns 0 when every port, limit and coupling held;\n   \
             {upper}_COUPLING_YIELDED; else the first arm's code that is not 0 (outputs written);\n   \
             {first_upper}_INVALID_ARGUMENT or {first_upper}_CONTROL_ERROR with qd zeros (reset\n   \
             before going on); {first_upper}_BAD_STORAGE; {first_upper}_NULL_ARGUMENT. */\n\
             int {m}_scene_update(void *storage, const {ct} *q, const {ct} *references,\n    \
             const {ct} *ports, {ct} dt, {ct} *qd, int *status, {ct} *report, {ct} *distances);\n\n\
             /* The scene at its start: q0[{ns}] each arm's joints, ports[{a} * 3] each arm's port\n   \
             (its base frame); either may be NULL. Returns 0. */\n\
             int {m}_scene_start({ct} *q0, {ct} *ports);\n\n\
             /* Each coupling's distance (m) at joints q[{ns}] with ports[{a} * 3] (NULL: the\n   \
             scene's), as the step measures it, into distances[{p}]. Returns 0,\n   \
             {first_upper}_INVALID_ARGUMENT, {first_upper}_CONTROL_ERROR, {first_upper}_NULL_ARGUMENT. */\n\
             int {m}_coupling_distances(const {ct} *q, const {ct} *ports, {ct} *distances);",
            ns = a * n,
            max = C_MAX_MAGNITUDE,
        );
        if self.camera.is_some() {
            let _ = writeln!(
                h,
                "\n/* The point the endoscope's camera looks at (the mean of the tips it follows) at\n   \
                 joints q[{ns}], in the camera arm's base frame, into point[3]. */\n\
                 int {m}_camera_point(const {ct} *q, {ct} *point);\n\n\
                 /* The camera arm's reference[18] that puts point[3], moving at velocity[3], on its\n   \
                 view axis. {first_upper}_INVALID_ARGUMENT for a point at the port or opposite the\n   \
                 start's view axis. */\n\
                 int {m}_camera_reference(const {ct} *point, const {ct} *velocity, {ct} *reference);",
                ns = a * n,
            );
        }
        let _ = writeln!(
            h,
            "\n#ifdef __cplusplus\n}}\n#endif\n\n#endif /* {guard} */"
        );
        h
    }

    /// The C++ header over the scene's C ABI: `trocar::<scene>::Scene` (RAII storage, as the
    /// arms' `Controller`), the sizes, `default_config()`, `start`, `coupling_distances` and
    /// the camera's functions.
    pub fn cpp_header(&self, real: Real) -> String {
        let ct = c_type(real);
        let m = &self.name;
        let upper = m.to_uppercase();
        let first = self.first();
        let (a, p, n) = (self.arm_modules.len(), self.couplings.len(), self.joints);
        let guard = format!("TROCAR_{upper}_SCENE_HPP");
        let mut h = String::new();
        let _ = writeln!(
            h,
            "// C++17 over the C ABI of the trocar-generated scene `{m}` (trocar generate {m} --cmake).\n\
             // Header-only; nothing throws or allocates: every call returns a Status (the arms').\n\
             #ifndef {guard}\n#define {guard}\n\n\
             #include <array>\n#include <cstddef>\n\n\
             #include \"{m}.h\"\n#include \"{first}.hpp\"\n\n\
             namespace trocar {{\nnamespace {m} {{\n\n\
             using Real = {ct};\n\
             using Status = ::trocar::{first}::Status;\n\
             using ArmConfig = ::trocar::{first}::Config;\n\
             using Config = {m}_scene_config;\n\
             constexpr std::size_t kArms = {a};\n\
             constexpr std::size_t kJoints = {n};\n\
             constexpr std::size_t kRates = {ns};\n\
             constexpr std::size_t kCouplings = {p};\n\
             /// The arms' joints (or rates) together, arm 0's first.\n\
             using Rates = std::array<Real, kRates>;\n\
             /// Each arm's reference (18 values each: position, orientation column-major,\n\
             /// velocity, angular velocity; its base frame).\n\
             using References = std::array<Real, kArms * 18>;\n\
             /// Each arm's port (3 values each, its base frame).\n\
             using Ports = std::array<Real, kArms * 3>;\n\
             using Distances = std::array<Real, kCouplings>;\n\
             using Statuses = std::array<int, kArms>;\n\
             using Reports = std::array<Real, kArms * 8>;\n\n\
             /// The defaults: each arm's controller defaults, the scene file's couplings and weights.\n\
             inline Config default_config() noexcept {{\n    \
             Config config{{}};\n    {m}_scene_config_default(&config);\n    return config;\n}}\n\n\
             /// Each arm's joints and port at the start.\n\
             inline void start(Rates &q0, Ports &ports) noexcept {{ {m}_scene_start(q0.data(), ports.data()); }}\n\n\
             /// Each coupling's distance at joints q (ports: the scene's unless given).\n\
             inline Status coupling_distances(const Rates &q, Distances &distances,\n                                  \
             const Ports *ports = nullptr) noexcept {{\n    \
             return static_cast<Status>({m}_coupling_distances(\n        \
             q.data(), ports != nullptr ? ports->data() : nullptr, distances.data()));\n}}\n",
            ns = a * n,
        );
        if self.camera.is_some() {
            let _ = writeln!(
                h,
                "/// The point the endoscope's camera looks at, at joints q (the camera arm's base frame).\n\
                 inline Status camera_point(const Rates &q, std::array<Real, 3> &point) noexcept {{\n    \
                 return static_cast<Status>({m}_camera_point(q.data(), point.data()));\n}}\n\n\
                 /// The camera arm's reference that puts point, moving at velocity, on its view axis.\n\
                 inline Status camera_reference(const std::array<Real, 3> &point,\n                               \
                 const std::array<Real, 3> &velocity, std::array<Real, 18> &reference) noexcept {{\n    \
                 return static_cast<Status>({m}_camera_reference(point.data(), velocity.data(), reference.data()));\n}}\n"
            );
        }
        let _ = writeln!(
            h,
            "/// The scene's step with its state (each arm's controller, the QP's warm start) in an\n\
             /// aligned member: no allocation, nothing to release. Not copyable; init before the\n\
             /// first update.\n\
             class Scene {{\npublic:\n    \
             Scene() noexcept = default;\n    \
             Scene(const Scene &) = delete;\n    \
             Scene &operator=(const Scene &) = delete;\n\n    \
             /// Configures the scene (and forgets any history). InvalidArgument for a\n    \
             /// configuration outside the rules; the scene is then left as it was.\n    \
             Status init(const Config &config) noexcept {{\n        \
             return static_cast<Status>({m}_scene_init(storage_, sizeof storage_, &config));\n    }}\n\n    \
             /// Forgets the history, keeping the configuration.\n    \
             Status reset() noexcept {{ return static_cast<Status>({m}_scene_reset(storage_)); }}\n\n    \
             /// One step: the rates into qd (and each arm's status and report, each coupling's\n    \
             /// distance), the status of the step (CouplingYielded, or the first arm's).\n    \
             Status update(const Rates &q, const References &references, Real dt, Rates &qd,\n                  \
             Statuses *status = nullptr, Reports *report = nullptr,\n                  \
             Distances *distances = nullptr, const Ports *ports = nullptr) noexcept {{\n        \
             return update(q.data(), references.data(), ports != nullptr ? ports->data() : nullptr,\n                      \
             dt, qd.data(), status != nullptr ? status->data() : nullptr,\n                      \
             report != nullptr ? report->data() : nullptr,\n                      \
             distances != nullptr ? distances->data() : nullptr);\n    }}\n\n    \
             /// The same on pointers (any may be null but q, references and qd).\n    \
             Status update(const Real *q, const Real *references, const Real *ports, Real dt,\n                  \
             Real *qd, int *status, Real *report, Real *distances) noexcept {{\n        \
             return static_cast<Status>({m}_scene_update(storage_, q, references, ports, dt, qd,\n                                                   \
             status, report, distances));\n    }}\n\n\
             private:\n    \
             alignas({upper}_SCENE_ALIGN) unsigned char storage_[{upper}_SCENE_SIZE] = {{}};\n\
             }};\n\n\
             }} // namespace {m}\n}} // namespace trocar\n\n#endif // {guard}"
        );
        h
    }
}
