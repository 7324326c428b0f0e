//! The stateful controller of a module's C ABI: `<module>_controller_init`, `_update`, `_reset`
//! over caller-provided storage, configured by a `<module>_config` struct (every method, the QP
//! included, its gains and the hard limits), so that a C or C++ loop gets what
//! `trocar::control::Controller` gives a Rust one — the warm-started QP, the acceleration and
//! jerk limits from one command to the next, the status of each step — without allocation.
//!
//! The storage is sized and aligned by the header's `<MODULE>_CONTROLLER_SIZE` and
//! `<MODULE>_CONTROLLER_ALIGN`: a bound computed from the module's sizes at generation time,
//! which the module checks against the state's real size when it is compiled (a constant
//! assertion), and `init` checks the storage it is given against both. The configuration is
//! checked by the runtime's own rules (`ControllerConfig::check` for the gains,
//! `HardLimits::check` for the limits) and every number by the number rule.

use super::c_abi::{c_type, has_controller, C_MAX_MAGNITUDE};
use crate::ir::{ModuleSpec, Real};
use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};
use std::fmt::Write as _;

/// The alignment of the storage (bytes, a power of two): the state's alignment is at most
/// this (checked when the module compiles).
pub const ALIGN: usize = 16;

/// The method codes of `<module>_config.method`, as the header `#define`s them.
pub const METHODS: [(&str, i32); 4] = [("PINV", 0), ("DLS", 1), ("FI", 2), ("QP", 3)];

/// The number of values `_update` writes into `report`.
pub const REPORT_LEN: usize = 8;

/// The defaults of `<module>_config` (those of the thesis's scenarios and the Panda's):
/// `(field, value, what)`, in the order of the struct's scalar fields.
fn defaults(spec: &ModuleSpec, real: Real) -> Vec<(&'static str, f64, &'static str)> {
    let limits = spec.joint_limits.is_some();
    vec![
        ("kp", 5.0, "position gain K_p (1/s)"),
        ("ko", 10.0, "orientation gain K_o (1/s)"),
        (
            "kr",
            20.0,
            "drift correction gain K_r (1/s); 0 for the thesis's controller",
        ),
        (
            "dls_alpha0",
            0.05,
            "variable damping (3.44): the largest damping alpha0",
        ),
        (
            "dls_w0_task",
            1e-3,
            "variable damping: w0 of the task Jacobian",
        ),
        ("dls_w0_jb0i", 0.01, "variable damping: w0 of J^B_0i"),
        (
            "fi_gamma",
            5.0,
            "filtered inverse (3.47)-(3.50): Gamma_r = Gamma_l",
        ),
        (
            "qp_kappa",
            // In `f32` a floor of 1e-3 is below the solver's curvature tolerance relative to
            // `JᵀJ`: the `f32` examples take 0.01.
            if matches!(real, Real::F32) {
                0.01
            } else {
                1e-3
            },
            "QP: the weight kappa of the rates' norm (gamma = kappa^2)",
        ),
        (
            "max_joint_speed",
            2.0,
            "joint speed limit on every joint (rad/s); 0: none but the joints' own",
        ),
        (
            "limit_gain",
            if limits { 10.0 } else { 0.0 },
            "gain of the joint-limit objective on J^B_0i's spare freedom (1/s); 0: none",
        ),
    ]
}

/// A bound on the state's size (bytes) from the module's sizes: its real numbers, counted
/// generously (the controller's matrices are at most `P × M`, `R × I`, `N × N` and vectors of
/// `N`), and its flags and indices.
pub(crate) fn size_bound(spec: &ModuleSpec, real: Real) -> usize {
    let c = spec
        .controller
        .as_ref()
        .expect("a module with a controller");
    let bytes = match real {
        Real::F32 => 4,
        Real::F64 | Real::Generic => 8,
    };
    let (n, i, m, p) = (spec.joints, c.link, c.m, c.task_rows);
    let reals = 256 + 48 * n + 4 * n * n + 8 * p * m + 8 * 3 * i + 2 * p * p;
    let words = 64 + 8 * n;
    let total = reals * bytes + words * 8;
    total.div_ceil(ALIGN) * ALIGN
}

/// The fields of `<module>_config` (`CControllerConfig`), in their order.
pub(crate) fn config_fields(spec: &ModuleSpec) -> Vec<&'static str> {
    let mut fields = vec!["method"];
    fields.extend(defaults(spec, Real::F64).iter().map(|(f, _, _)| *f));
    fields.extend([
        "lower",
        "upper",
        "speed",
        "acceleration",
        "jerk",
        "depth_limits",
        "depth",
    ]);
    fields
}

/// An identity of the module for its storage (FNV-1a of its name): `update` refuses storage
/// that this module's `init` did not write.
fn magic(spec: &ModuleSpec) -> u64 {
    fnv1a(&spec.name)
}

/// FNV-1a of `name`: the identity a C object's storage carries.
pub(crate) fn fnv1a(name: &str) -> u64 {
    name.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The C symbols of the controller object.
pub fn symbols(spec: &ModuleSpec) -> Vec<String> {
    if !has_controller(spec) {
        return Vec::new();
    }
    [
        "controller_config_default",
        "controller_init",
        "controller_update",
        "controller_reset",
    ]
    .iter()
    .map(|f| format!("{}_{f}", spec.name))
    .collect()
}

/// The macros the header defines for the controller object, with what each stands for.
pub fn macros(spec: &ModuleSpec) -> Vec<(String, String)> {
    if !has_controller(spec) {
        return Vec::new();
    }
    let upper = spec.name.to_uppercase();
    let mut list = vec![
        (
            format!("{upper}_CONTROLLER_SIZE"),
            "the controller's storage size".to_string(),
        ),
        (
            format!("{upper}_CONTROLLER_ALIGN"),
            "the controller's storage alignment".to_string(),
        ),
        (
            format!("{upper}_REPORT_LEN"),
            "the controller's report".to_string(),
        ),
    ];
    for (name, _) in METHODS {
        list.push((format!("{upper}_METHOD_{name}"), "a method".to_string()));
    }
    // The names do not depend on the real type (the values do).
    for (field, _, _) in defaults(spec, Real::F64) {
        list.push((
            format!("{upper}_DEFAULT_{}", field.to_uppercase()),
            format!("the default of `{field}`"),
        ));
    }
    list
}

/// The Rust items: the configuration struct, the state, and the four functions.
pub fn items(spec: &ModuleSpec, t: &TokenStream, rt: &TokenStream, real: Real) -> TokenStream {
    let rows = if spec.controller.as_ref().is_some_and(|c| c.task) {
        quote!(TASK_ROWS)
    } else {
        quote!(6)
    };
    let name = &spec.name;
    let config_ty = format_ident!("CControllerConfig");
    let f_default = format_ident!("{name}_controller_config_default");
    let f_init = format_ident!("{name}_controller_init");
    let f_update = format_ident!("{name}_controller_update");
    let f_reset = format_ident!("{name}_controller_reset");
    let size = Literal::usize_unsuffixed(size_bound(spec, real));
    let align = Literal::usize_unsuffixed(ALIGN);
    let magic = Literal::u64_unsuffixed(magic(spec));
    let defaults = defaults(spec, real);
    let scalar_fields: Vec<_> = defaults
        .iter()
        .map(|(f, _, _)| format_ident!("{f}"))
        .collect();
    let scalar_docs: Vec<_> = defaults
        .iter()
        .map(|(_, _, what)| format!(" {what}."))
        .collect();
    let default_values: Vec<_> = defaults
        .iter()
        .map(|(_, v, _)| Literal::f64_unsuffixed(*v))
        .collect();
    let range = |k: usize, side: usize| -> TokenStream {
        match &spec.joint_limits {
            Some(l) => {
                let v = Literal::f64_unsuffixed(l[k][side]);
                quote!(#v)
            }
            None => {
                let v = Literal::f64_unsuffixed(if side == 0 {
                    -C_MAX_MAGNITUDE
                } else {
                    C_MAX_MAGNITUDE
                });
                quote!(#v)
            }
        }
    };
    let lower: Vec<_> = (0..spec.joints).map(|k| range(k, 0)).collect();
    let upper: Vec<_> = (0..spec.joints).map(|k| range(k, 1)).collect();
    // Each joint's limit from the description, 0 (none) where it has none.
    let per_joint = |limits: &[Option<f64>]| -> Vec<Literal> {
        (0..spec.joints)
            .map(|k| Literal::f64_unsuffixed(limits.get(k).copied().flatten().unwrap_or(0.0)))
            .collect()
    };
    let speeds = per_joint(&spec.joint_speed_limits);
    let accelerations = per_joint(&spec.joint_acceleration_limits);
    let jerks = per_joint(&spec.joint_jerk_limits);
    let methods = METHODS.map(|(_, code)| Literal::i32_unsuffixed(code));
    let [pinv, dls, fi, qp] = methods;
    quote! {
        /// The runtime's controller on this module's kinematics, in the C ABI's real type.
        type CController = #rt::emitted::Controller<#t, N, I, R, K, M, #rows>;

        /// The configuration of the C ABI's controller object (`<module>_config` in the C
        /// header, the same layout): the method (`METHOD_*` of the header: 0 pseudo-inverse,
        /// 1 DLS, 2 filtered inverse, 3 QP), its gains, and the hard limits. A limit of 0 is
        /// none; ranges of ±1e6 are none.
        #[repr(C)]
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct #config_ty {
            /// The method: 0 pseudo-inverse, 1 DLS, 2 filtered inverse, 3 QP.
            pub method: i32,
            #(
                #[doc = #scalar_docs]
                pub #scalar_fields: #t,
            )*
            /// Each joint's range: lower bounds (rad, m for a prismatic joint).
            pub lower: [#t; N],
            /// Each joint's range: upper bounds.
            pub upper: [#t; N],
            /// Each joint's own speed limit (rad/s); 0: none.
            pub speed: [#t; N],
            /// Each joint's acceleration limit (rad/s²); 0: none.
            pub acceleration: [#t; N],
            /// Each joint's jerk limit (rad/s³); 0: none.
            pub jerk: [#t; N],
            /// Whether the insertion bounds apply (1) or not (0).
            pub depth_limits: i32,
            /// The insertion bounds `[l_min, l_max]` of the trocar's offset along the shaft (m).
            pub depth: [#t; 2],
        }

        impl #config_ty {
            /// The defaults: DLS, the gains of the header's `DEFAULT_*`, the module's joint
            /// ranges and its joints' speed, acceleration and jerk limits (0, none, where the
            /// description has none), no insertion limits.
            pub const DEFAULT: Self = #config_ty {
                method: #dls,
                #( #scalar_fields: #default_values, )*
                lower: [#(#lower),*],
                upper: [#(#upper),*],
                speed: [#(#speeds),*],
                acceleration: [#(#accelerations),*],
                jerk: [#(#jerks),*],
                depth_limits: 0,
                depth: [0.0; 2],
            };

            /// The runtime's controller for this configuration, or the C return code that
            /// refuses it: every number by the number rule, the method by its code, the gains
            /// by `ControllerConfig::check`, the limits by `HardLimits::check`.
            pub(crate) fn controller(&self) -> Result<CController, i32> {
                use #rt::emitted::{Gains, HardLimits, MethodKind, NullSpaceObjective};
                use #rt::emitted::nalgebra::SVector;
                let scalars = [#(self.#scalar_fields),*];
                let arrays = self
                    .lower
                    .iter()
                    .chain(&self.upper)
                    .chain(&self.speed)
                    .chain(&self.acceleration)
                    .chain(&self.jerk)
                    .chain(&self.depth);
                if !(scalars.iter().chain(arrays).all(|v| c_number_ok(*v))) {
                    return Err(C_INVALID_ARGUMENT);
                }
                let method = match self.method {
                    #pinv => MethodKind::Pinv,
                    #dls => MethodKind::Dls,
                    #fi => MethodKind::Fi,
                    #qp => MethodKind::Qp,
                    _ => return Err(C_INVALID_ARGUMENT),
                };
                // A limit of 0 is none; a negative one is refused (by `HardLimits::check`).
                let limit = |v: #t| if v == 0.0 { #t::INFINITY } else { v };
                let gains = Gains {
                    kp: self.kp,
                    ko: self.ko,
                    kr: self.kr,
                    dls_alpha0: self.dls_alpha0,
                    dls_w0_task: self.dls_w0_task,
                    dls_w0_jb0i: self.dls_w0_jb0i,
                    fi_gamma: self.fi_gamma,
                    qp_kappa: self.qp_kappa,
                    max_joint_speed: (self.max_joint_speed != 0.0).then_some(self.max_joint_speed),
                };
                let config = gains.config(method);
                // The gains' signs and finiteness (`K dt` is checked against each step's `dt`):
                // at a sample time of one rounding unit every bound on `K dt` holds.
                if config.check(#t::EPSILON).is_err() || self.limit_gain < 0.0 {
                    return Err(C_INVALID_ARGUMENT);
                }
                let lower = SVector::<#t, N>::from(self.lower);
                let upper = SVector::<#t, N>::from(self.upper);
                let mut limits = HardLimits::none()
                    .with_joint_limits(lower, upper)
                    .with_speed_limits(SVector::from(self.speed.map(limit)))
                    .with_acceleration_limits(SVector::from(self.acceleration.map(limit)))
                    .with_jerk_limits(SVector::from(self.jerk.map(limit)));
                match self.depth_limits {
                    0 => {}
                    1 => limits = limits.with_depth(self.depth[0], self.depth[1]),
                    _ => return Err(C_INVALID_ARGUMENT),
                }
                if limits.check().is_err() {
                    return Err(C_INVALID_ARGUMENT);
                }
                let ctrl = CController::new(config).with_limits(limits);
                Ok(if self.limit_gain > 0.0 {
                    ctrl.with_objective(NullSpaceObjective::JointLimits {
                        gain: self.limit_gain,
                        lower,
                        upper,
                    })
                } else {
                    ctrl
                })
            }
        }

        /// What the C caller's storage holds after `init`: this module's identity, the
        /// configuration (for `reset`) and the controller.
        #[repr(C)]
        struct CControllerState {
            magic: u64,
            config: #config_ty,
            controller: CController,
        }

        /// The storage (bytes) a C caller provides for the controller object (the header's
        /// `CONTROLLER_SIZE`): a bound from the module's sizes, at least the state's size.
        pub const C_CONTROLLER_SIZE: usize = #size;
        /// The storage's alignment (the header's `CONTROLLER_ALIGN`).
        pub const C_CONTROLLER_ALIGN: usize = #align;
        const C_CONTROLLER_MAGIC: u64 = #magic;
        const _: () = assert!(
            ::core::mem::size_of::<CControllerState>() <= C_CONTROLLER_SIZE
                && ::core::mem::align_of::<CControllerState>() <= C_CONTROLLER_ALIGN,
            "the controller's state outgrew the storage the C header gives it"
        );

        /// The controller object's state in `storage`, if `init` wrote it there.
        ///
        /// # Safety
        /// `storage` is null or points to `C_CONTROLLER_SIZE` initialised bytes (written by
        /// `init`, or zeroed), aligned, that no other reference aliases.
        unsafe fn c_state<'a>(storage: *mut ::core::ffi::c_void) -> Result<&'a mut CControllerState, i32> {
            // SAFETY: `CControllerState` is `#[repr(C)]` with its `magic: u64` first, at most
            // `C_CONTROLLER_SIZE` bytes (asserted above); the rest is the caller's contract.
            unsafe { c_object(storage, C_CONTROLLER_ALIGN, C_CONTROLLER_MAGIC) }
        }

        /// C ABI: fills `config` with the defaults (`CControllerConfig::DEFAULT`). Returns 0,
        /// or `C_NULL_ARGUMENT` for a null pointer.
        ///
        /// # Safety
        /// `config` is null or points to room for a `CControllerConfig`.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn #f_default(config: *mut #config_ty) -> i32 {
            if config.is_null() {
                return C_NULL_ARGUMENT;
            }
            // SAFETY: non-null and, by the caller's contract, room for the struct.
            unsafe { config.write(#config_ty::DEFAULT) };
            0
        }

        /// C ABI: writes the controller object into `storage` (`size` bytes, aligned to
        /// `C_CONTROLLER_ALIGN`) from `config`. Returns 0; `C_INVALID_ARGUMENT` for a
        /// configuration the rules refuse; `C_BAD_STORAGE` for storage too small or not
        /// aligned; `C_NULL_ARGUMENT`. Nothing is written unless it returns 0.
        ///
        /// # Safety
        /// `storage` points to `size` writable bytes that nothing else uses while the object
        /// lives; `config` to a `CControllerConfig`.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn #f_init(
            storage: *mut ::core::ffi::c_void,
            size: usize,
            config: *const #config_ty,
        ) -> i32 {
            if storage.is_null() || config.is_null() {
                return C_NULL_ARGUMENT;
            }
            if size < ::core::mem::size_of::<CControllerState>()
                || (storage as usize) & (C_CONTROLLER_ALIGN - 1) != 0
            {
                return C_BAD_STORAGE;
            }
            // SAFETY: non-null and, by the caller's contract, a readable struct (every bit
            // pattern of its `i32`s and reals is a valid value).
            let config = unsafe { config.read() };
            let controller = match config.controller() {
                Ok(c) => c,
                Err(code) => return code,
            };
            // SAFETY: non-null, aligned and at least the state's size (checked above), and the
            // caller's to write.
            unsafe {
                storage.cast::<CControllerState>().write(CControllerState {
                    magic: C_CONTROLLER_MAGIC,
                    config,
                    controller,
                })
            };
            0
        }

        /// C ABI: the controller as `init` left it — the last command, the QP's working set
        /// and the filtered inverse's state forgotten — with the same configuration (for a
        /// loop that starts again from rest). Returns 0, `C_BAD_STORAGE` for storage `init`
        /// did not write, `C_NULL_ARGUMENT`.
        ///
        /// # Safety
        /// `storage` is null or points to `C_CONTROLLER_SIZE` aligned bytes that nothing else
        /// uses.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn #f_reset(storage: *mut ::core::ffi::c_void) -> i32 {
            // SAFETY: the caller's contract.
            let state = match unsafe { c_state(storage) } {
                Ok(s) => s,
                Err(code) => return code,
            };
            match state.config.controller() {
                Ok(c) => {
                    state.controller = c;
                    0
                }
                Err(code) => code,
            }
        }

        /// C ABI: one step of the controller object. `q` the `N` joint values, `params` the
        /// module's parameters (null when there are none), `reference` 18 values (the tip's
        /// position, orientation column-major, linear and angular feed-forward velocities,
        /// base frame), `trocar` the port (3), `trocar_rate` its velocity (3; null for a still
        /// port; fed forward by (3.33)–(3.34)), `dt` the sample time. Writes the `N` rates into
        /// `qd` and, when `report` is not null, 8 values (`l_a`, `|e_p|`, `|ε̃|`, `|e_r|`,
        /// `w_r`, `w_i`, `κ_r`, `κ_i`).
        ///
        /// Returns 0 (every constraint held); `C_TROCAR_YIELDED`, `C_JOINT_OUTSIDE`,
        /// `C_DEPTH_OUTSIDE` (the constraint that gave way; rates and report written);
        /// `C_INVALID_ARGUMENT` (an input outside the number rule, an orientation that is not a
        /// proper rotation to 1e-6, `dt ≤ 0`, `K dt` beyond its bound) or `C_CONTROL_ERROR` (no step could be computed), both with `qd` zeros and
        /// the report not written; `C_BAD_STORAGE`; `C_NULL_ARGUMENT` (nothing written).
        ///
        /// # Safety
        /// `storage` as for `reset`; `q` points to `N` values, `params` to `PARAMS` (or is
        /// null when there are none), `reference` to 18, `trocar` to 3, `trocar_rate` to 3 or
        /// is null, `qd` to room for `N`, `report` to room for 8 or is null; the outputs
        /// overlap no input.
        #[unsafe(no_mangle)]
        #[allow(clippy::too_many_arguments)]
        pub unsafe extern "C" fn #f_update(
            storage: *mut ::core::ffi::c_void,
            q: *const #t,
            params: *const #t,
            reference: *const #t,
            trocar: *const #t,
            trocar_rate: *const #t,
            dt: #t,
            qd: *mut #t,
            report: *mut #t,
        ) -> i32 {
            use #rt::emitted::nalgebra::{SVector, Vector3};
            use #rt::emitted::{ConstrainedKinematics, Rcm};
            if q.is_null() || reference.is_null() || trocar.is_null() || qd.is_null() {
                return C_NULL_ARGUMENT;
            }
            // SAFETY: the caller's contract.
            let state = match unsafe { c_state(storage) } {
                Ok(s) => s,
                Err(code) => return code,
            };
            // SAFETY: the caller's contract for `params`.
            let Some((p, p_values)) = (unsafe { c_params(params) }) else {
                return C_NULL_ARGUMENT;
            };
            // SAFETY: each pointer is non-null (checked above; `trocar_rate` where it is not
            // null) and, by the caller's contract, points to as many values as read here.
            let (q, reference, trocar, rate) = unsafe {
                (
                    &*q.cast::<[#t; N]>(),
                    &*reference.cast::<[#t; 18]>(),
                    &*trocar.cast::<[#t; 3]>(),
                    (!trocar_rate.is_null()).then(|| *trocar_rate.cast::<[#t; 3]>()),
                )
            };
            // SAFETY: non-null (checked above), room for `N` values overlapping no input.
            let qd: &mut [#t; N] = unsafe { &mut *qd.cast::<[#t; N]>() };
            let read_ok = q
                .iter()
                .chain(p_values.iter())
                .chain(reference.iter())
                .chain(trocar.iter())
                .chain(rate.iter().flatten())
                .all(|v| c_number_ok(*v))
                && c_number_ok(dt)
                && dt > 0.0;
            if !read_ok {
                *qd = [0.0; N];
                return C_INVALID_ARGUMENT;
            }
            // The desired orientation must be a proper rotation (the runtime's rule, the command
            // line's and Python's).
            let target = c_reference(reference);
            if !#rt::emitted::is_rotation(&target.rotation) {
                *qd = [0.0; N];
                return C_INVALID_ARGUMENT;
            }
            let kin = Kinematics { params: p };
            let q = SVector::from(*q);
            let dv = match rate {
                Some(v) => kin.shaft().trocar_rate(&kin.g_0i(&q), &kin.h(), &Vector3::from(v)),
                None => SVector::zeros(),
            };
            let rcm = Rcm {
                trocar: Vector3::from(*trocar),
                dv,
            };
            let ctrl: &mut CController = &mut state.controller;
            let result = ctrl.step(&kin, &q, &target, &rcm, dt);
            // SAFETY: `report` is null or, by the caller's contract, room for 8 values.
            unsafe { c_write_step(result, qd, report) }
        }
    }
}

/// The header's part for the controller object.
pub fn header(spec: &ModuleSpec, real: Real) -> String {
    if !has_controller(spec) {
        return String::new();
    }
    let ct = c_type(real);
    let m = &spec.name;
    let upper = m.to_uppercase();
    let n = spec.joints;
    let mut h = String::new();
    let _ = writeln!(
        h,
        "/* The controller object: trocar's constrained controller with its state (the last\n   \
         command for the acceleration and jerk limits, the QP's warm start) in storage the\n   \
         caller provides, {upper}_CONTROLLER_SIZE bytes aligned to {upper}_CONTROLLER_ALIGN\n   \
         (e.g. a static or stack array declared with alignas). No call allocates. */\n\
         #define {upper}_CONTROLLER_SIZE {size}\n\
         #define {upper}_CONTROLLER_ALIGN {ALIGN}\n\
         #define {upper}_REPORT_LEN {REPORT_LEN}",
        size = size_bound(spec, real),
    );
    for (name, code) in METHODS {
        let _ = writeln!(h, "#define {upper}_METHOD_{name} {code}");
    }
    let _ = writeln!(
        h,
        "/* The defaults of {m}_config ({m}_controller_config_default). */"
    );
    for (field, value, what) in defaults(spec, real) {
        let _ = writeln!(
            h,
            "#define {upper}_DEFAULT_{} {value:?} /* {what} */",
            field.to_uppercase()
        );
    }
    let _ = writeln!(
        h,
        "\n/* The controller's configuration. Every number finite, not subnormal, within +-{max:e};\n   \
         gains >= 0; a limit of 0 is none; ranges lower < upper (+-1e6 for none).\n   \
         method: {upper}_METHOD_PINV, _DLS, _FI or _QP. */\n\
         typedef struct {{\n    int method;",
        max = C_MAX_MAGNITUDE,
    );
    for (field, _, what) in defaults(spec, real) {
        let _ = writeln!(h, "    {ct} {field}; /* {what} */");
    }
    let _ = writeln!(
        h,
        "    {ct} lower[{n}]; /* each joint's range, lower bound (default: the description's) */\n    \
         {ct} upper[{n}]; /* upper bound */\n    \
         {ct} speed[{n}]; /* each joint's own speed limit (rad/s; 0: none; default: the description's) */\n    \
         {ct} acceleration[{n}]; /* acceleration limit (rad/s^2; 0: none; default: the description's) */\n    \
         {ct} jerk[{n}]; /* jerk limit (rad/s^3; 0: none; default: the description's) */\n    \
         int depth_limits; /* 1: the insertion bounds below apply */\n    \
         {ct} depth[2]; /* [l_min, l_max] of the trocar's offset along the shaft (m) */\n\
         }} {m}_config;\n\n\
         /* Fills config with the defaults. Returns 0 or {upper}_NULL_ARGUMENT. */\n\
         int {m}_controller_config_default({m}_config *config);\n\n\
         /* Writes the controller into storage (size bytes, aligned to {upper}_CONTROLLER_ALIGN).\n   \
         Returns 0; {upper}_INVALID_ARGUMENT for a configuration outside the rules above;\n   \
         {upper}_BAD_STORAGE for storage too small or misaligned; {upper}_NULL_ARGUMENT.\n   \
         Nothing is written unless it returns 0. */\n\
         int {m}_controller_init(void *storage, size_t size, const {m}_config *config);\n\n\
         /* The controller as init left it, its configuration kept (a loop starting again from\n   \
         rest). Returns 0, {upper}_BAD_STORAGE (storage init did not write), {upper}_NULL_ARGUMENT. */\n\
         int {m}_controller_reset(void *storage);\n\n\
         /* One step. q[{n}]; params (NULL when there are none); reference[18]: tip position (3),\n   \
         orientation R column-major (9), velocity (3), angular velocity (3), base frame;\n   \
         trocar[3]: the port; trocar_rate[3]: its velocity, fed forward (NULL: still); dt > 0.\n   \
         qd[{n}]: the rates, always within the limits; report[{upper}_REPORT_LEN] (or NULL):\n   \
         l_a, |e_p|, |eps|, |e_r|, w_r, w_i, kappa_r, kappa_i.\n   \
         Returns 0 when every constraint held; {upper}_TROCAR_YIELDED, {upper}_JOINT_OUTSIDE or\n   \
         {upper}_DEPTH_OUTSIDE naming the one that gave way (qd and report written);\n   \
         {upper}_INVALID_ARGUMENT (an input outside the number rule, an orientation that is not a\n   \
         proper rotation to 1e-6, dt <= 0, a gain times dt beyond its bound: K_p dt < 2,\n   \
         K_r dt < 2, K_o dt < 4) or {upper}_CONTROL_ERROR (no step\n   \
         could be computed), both with qd set to zeros; {upper}_BAD_STORAGE; {upper}_NULL_ARGUMENT\n   \
         (nothing written). */\n\
         int {m}_controller_update(void *storage, const {ct} *q, const {ct} *params,\n    \
         const {ct} *reference, const {ct} *trocar, const {ct} *trocar_rate, {ct} dt, {ct} *qd,\n    \
         {ct} *report);\n"
    );
    h
}
