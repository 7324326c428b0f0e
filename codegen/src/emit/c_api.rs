//! The C ABI of a generated module ([`crate::Builder::c_api`], `trocar generate --c-api`) and its
//! C header (`trocar generate --c-header`).
//!
//! Every function `f` of the module gets, inside the module,
//!
//! ```c
//! int <module>_<f>(const double *q, const double *params, double *out);
//! ```
//!
//! (`float` for an `f32` module; a generic module's C ABI is `double`): `q` the `N` joint values,
//! `params` the parameters in declaration order, `out` room for the result in the layout of the
//! Rust function — matrices **column-major** (`out[c · rows + r]` is entry `(r, c)`), a pose as
//! `R` column-major then `p` (12 values). The return code is `0` when every value read (`q`,
//! `params`) and written is finite, [`C_NOT_FINITE`] when one is not (the values are written all
//! the same), and [`C_NULL_ARGUMENT`] when a pointer is null (nothing is written). Nothing
//! allocates; the functions are straight-line arithmetic and cannot panic.
//!
//! Every fused function `name` of the module (`pose_and_jacobian`, `link_pose_and_jacobian`, those
//! of [`crate::Builder::function`]) gets the same signature, `out` receiving its outputs one after
//! the other, each in its own layout (the header `#define`s each one's offset and the total). In a
//! generic module generated with [`crate::Builder::fma_at_run_time`] it calls `name_f64`, so C and
//! C++ callers get the fused multiply-adds chosen at run time too.
//!
//! A constrained module whose constraint frame slides along its link (it has `Kinematics`) also
//! gets `<module>_controller_step`: one step of the runtime's constrained controller
//! (`trocar::control::Controller`, damped least squares, drift correction, the joint-limit
//! objective and the joint ranges where the module has `JOINT_LIMITS`) on the generated
//! kinematics. Every number it reads follows the number rule (finite, not subnormal, within
//! ±[`C_MAX_MAGNITUDE`]) and the gains the controller's own check
//! (`trocar::control::ControllerConfig::check`: non-negative, `K dt` within its stable bound),
//! else it returns [`C_INVALID_ARGUMENT`]; its rates always keep the joint speed limit `gains[6]`,
//! each joint's own speed limit from the description (a URDF joint's `velocity`) and the joint
//! ranges over `dt`, and [`C_TROCAR_YIELDED`] says when the trocar could not be held
//! within them.
//!
//! The header's macros are the module's name in upper case followed by a name of the module
//! (a parameter's, a function's): [`check_names`] refuses a module in which two of them would
//! be the same macro (parameters `l_b` and `L_B`).

use crate::ir::{FusedFunction, Layout, ModuleSpec, Real};
use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};
use std::fmt::Write as _;

/// Return code of a C function: a value written is not finite.
pub const C_NOT_FINITE: i32 = 1;
/// Return code of a C function: a required pointer is null; nothing is written.
pub const C_NULL_ARGUMENT: i32 = 2;
/// Return code of `<module>_controller_step`: the controller could not compute a step (a
/// singular Jacobian without damping, a non-finite value, the trocar at the link's frame).
pub const C_CONTROL_ERROR: i32 = 3;
/// Return code of `<module>_controller_step`: an input is outside the number rule (not finite,
/// subnormal, beyond ±[`C_MAX_MAGNITUDE`]), `dt` is not positive, or a gain is refused by
/// `trocar::control::ControllerConfig::check` (negative, `K dt` at or beyond its stable bound).
pub const C_INVALID_ARGUMENT: i32 = 4;
/// Return code of `<module>_controller_step`: the trocar could not be held within the joint
/// speed limit and ranges (`trocar::control::StepStatus::TrocarYielded`); `qd` holds the best
/// rates within them.
pub const C_TROCAR_YIELDED: i32 = 5;
/// Return code of `<module>_controller_step`: a joint of `q` is beyond its range
/// (`trocar::control::StepStatus::JointOutside`); `qd` moves it back only.
pub const C_JOINT_OUTSIDE: i32 = 6;
/// Return code of `<module>_register_port`: fewer than two poses (with forgetting, less weight
/// than two poses'); nothing is written.
pub const C_TOO_FEW_LINES: i32 = 7;
/// Return code of `<module>_register_port`: the shaft's lines are nearly parallel (their spread
/// below the least asked); only the spread is written.
pub const C_NEAR_PARALLEL: i32 = 8;
/// Return code of the controller object's update: the insertion depth left its bounds
/// (`trocar::control::StepStatus::DepthOutside`); rates and report written.
pub const C_DEPTH_OUTSIDE: i32 = 9;
/// Return code of the controller object: its storage is too small, misaligned, or was not
/// written by this module's `init`.
pub const C_BAD_STORAGE: i32 = 10;
/// Return code of a scene's update (`<scene>_scene_update`): a coupling between two arms could
/// not hold within the ports and the joint limits; the rates written keep the ports and the
/// limits, the couplings relaxed as little as they could be.
pub const C_COUPLING_YIELDED: i32 = 11;
/// The number of values `<module>_register_port` writes: the port (3), its covariance
/// column-major (9), the residual, the lines' spread.
pub const C_REGISTER_PORT_LEN: usize = 14;
pub use super::c_abi::C_MAX_MAGNITUDE;
use super::c_abi::{c_type, has_controller};

/// A pose `(R, p)` (the expression `pose`) into `out` from `offset`: `R` column-major, then `p`;
/// literal ranges, the layout every C function writes a pose in.
fn pose_into(pose: &TokenStream, offset: usize) -> TokenStream {
    let range = |from: usize| {
        let (a, b) = (
            Literal::usize_unsuffixed(offset + from),
            Literal::usize_unsuffixed(offset + from + 3),
        );
        quote!(#a..#b)
    };
    let (r0, r1, r2, rp) = (range(0), range(3), range(6), range(9));
    quote! {
        out[#r0].copy_from_slice(&#pose.0[0]);
        out[#r1].copy_from_slice(&#pose.0[1]);
        out[#r2].copy_from_slice(&#pose.0[2]);
        out[#rp].copy_from_slice(&#pose.1);
    }
}

/// The C prefix of a module's symbols: its name.
fn prefix(spec: &ModuleSpec) -> String {
    spec.name.clone()
}

/// The C symbol of the module's function `f`: `<module>_<f>`.
fn symbol(spec: &ModuleSpec, f: &str) -> String {
    format!("{}_{f}", prefix(spec))
}

/// Every C symbol the module exports (its functions, fused functions and controller step), for
/// the check that two modules of one build do not export the same one.
pub fn symbols(spec: &ModuleSpec) -> Vec<String> {
    let functions = spec.functions.iter().map(|f| f.name.as_str());
    let fused = spec.fused.iter().map(|f| f.name.as_str());
    let controller = has_controller(spec)
        .then_some(["controller_step", "register_port", "trajectory_reference"])
        .into_iter()
        .flatten();
    functions
        .chain(fused)
        .chain(controller)
        .map(|f| symbol(spec, f))
        .chain(super::c_controller::symbols(spec))
        .chain(super::c_port::symbols(spec))
        .collect()
}

/// The `extern "C"` items inside the module, for the real type `real`.
pub fn items(spec: &ModuleSpec, real: Real, rt: &TokenStream) -> TokenStream {
    let t = match real {
        Real::F32 => quote!(f32),
        Real::F64 | Real::Generic => quote!(f64),
    };
    let p_count = spec.params.len();
    let params_init = if spec.params.is_empty() {
        quote!(Params::nominal())
    } else {
        let fields = spec.params.iter().enumerate().map(|(k, (name, _))| {
            let id = format_ident!("{}", name);
            let k = Literal::usize_unsuffixed(k);
            quote!(#id: p[#k],)
        });
        quote!(Params { #(#fields)* })
    };
    let p_len = Literal::usize_unsuffixed(p_count);
    let params_ty = match real {
        Real::Generic => quote!(Params<f64>),
        _ => quote!(Params),
    };
    let read_params = quote! {
        /// The parameters from a C array (`PARAMS` values, declaration order), and the values
        /// read; `None` for a null pointer where there are parameters.
        ///
        /// # Safety
        /// `params` points to `PARAMS` readable values (it may be null when there are none).
        #[inline]
        unsafe fn c_params(params: *const #t) -> Option<(#params_ty, [#t; #p_len])> {
            if #p_len > 0 && params.is_null() {
                return None;
            }
            let mut p: [#t; #p_len] = [0.0; #p_len];
            if #p_len > 0 {
                // SAFETY: non-null (checked above) and, by the caller's contract, pointing to
                // `PARAMS` readable values.
                p.copy_from_slice(unsafe { ::core::slice::from_raw_parts(params, #p_len) });
            }
            Some((#params_init, p))
        }
    };
    let fns = spec.functions.iter().map(|f| {
        let name = format_ident!("{}", f.name);
        let c_name = format_ident!("{}", symbol(spec, &f.name));
        let n = Literal::usize_unsuffixed(f.layout.len());
        // Through `self::`, so that no local of the wrapper can shadow the function.
        let call = if f.takes_joints {
            quote!(self::#name(q, &p))
        } else {
            quote!(self::#name(&p))
        };
        let flatten = match f.layout {
            Layout::Scalar => quote!(out[0] = value;),
            // A single row: one value a column (`c * 1` is clippy's `identity_op`).
            Layout::Matrix { rows: 1, .. } => quote! {
                for (c, column) in value.iter().enumerate() {
                    out[c] = column[0];
                }
            },
            Layout::Matrix { rows, .. } => {
                let rows = Literal::usize_unsuffixed(rows);
                quote! {
                    for (c, column) in value.iter().enumerate() {
                        out[c * #rows..(c + 1) * #rows].copy_from_slice(column);
                    }
                }
            }
            Layout::Transform => pose_into(&quote!(value), 0),
        };
        let doc = format!(
            " C ABI of [`{name}`]: `int {c_name}(const {ct} *q, const {ct} *params, {ct} *out)`; \
             `out` receives {n} values (column-major). Returns 0, `C_NOT_FINITE` (1: a value \
             read or written is not finite) or `C_NULL_ARGUMENT` (2); see the C header \
             (`trocar generate --c-header`).",
            name = f.name,
            ct = c_type(real),
            n = f.layout.len(),
        );
        let q_check = if f.takes_joints {
            quote!(q.is_null() ||)
        } else {
            quote!()
        };
        let q_read = if f.takes_joints {
            quote! {
                // SAFETY: non-null (checked above) and, by the caller's contract, pointing to
                // `N` readable values.
                let q: &[#t; N] = unsafe { &*q.cast::<[#t; N]>() };
                let read_finite = read_finite && q.iter().all(|v| v.is_finite());
            }
        } else {
            quote!(let _ = q;)
        };
        quote! {
            #[doc = #doc]
            ///
            /// # Safety
            /// `q` points to `N` readable values (it may be null for a function of the
            /// parameters alone), `params` to the parameters (`PARAMS` values, declaration
            /// order; null when there are none), `out` to room for the result, and `out`
            /// overlaps neither.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn #c_name(q: *const #t, params: *const #t, out: *mut #t) -> i32 {
                if #q_check out.is_null() {
                    return C_NULL_ARGUMENT;
                }
                // SAFETY: the caller's contract for `params`.
                let Some((p, p_values)) = (unsafe { c_params(params) }) else {
                    return C_NULL_ARGUMENT;
                };
                // A value read that is not finite is reported even where the result is finite
                // (a manipulability is 0 where its value is not finite).
                let read_finite = p_values.iter().all(|v| v.is_finite());
                #q_read
                let value = #call;
                // SAFETY: non-null (checked above) and, by the caller's contract, room for the
                // result's values, not overlapping the inputs.
                let out: &mut [#t; #n] = unsafe { &mut *out.cast::<[#t; #n]>() };
                #flatten
                if read_finite && out.iter().all(|v| v.is_finite()) { 0 } else { C_NOT_FINITE }
            }
        }
    });
    let fused = spec.fused.iter().map(|f| fused_c(spec, f, real, &t));
    let controller = has_controller(spec).then(|| controller_step(spec, &t, rt));
    let register = has_controller(spec).then(|| register_port(spec, &t, rt));
    let path_reference = has_controller(spec).then(|| trajectory_reference(spec, &t, rt));
    let object = has_controller(spec).then(|| super::c_controller::items(spec, &t, rt, real));
    let port = has_controller(spec).then(|| super::c_port::items(spec, &t, rt));
    let max = Literal::f64_unsuffixed(C_MAX_MAGNITUDE);
    let number_rule = has_controller(spec).then(|| {
        quote! {
            /// The number rule of every number trocar takes from a C caller: finite, not
            /// subnormal, within ±1e6.
            #[inline]
            pub(crate) fn c_number_ok(v: #t) -> bool {
                v.is_finite() && v.abs() <= #max && (v == 0.0 || v.abs() >= #t::MIN_POSITIVE)
            }

            /// A control step's outcome for a C caller: the rates into `qd` and, where `report`
            /// is not null, its 8 values (`l_a`, `|e_p|`, `|ε̃|`, `|e_r|`, `w_r`, `w_i`, `κ_r`,
            /// `κ_i`); the return code of its status. Where the step failed or a value is not
            /// finite, `qd` is set to zeros, the report is not written, and the code is
            /// `C_INVALID_ARGUMENT` (the configuration refused at this `dt`) or
            /// `C_CONTROL_ERROR`.
            ///
            /// # Safety
            /// `report` is null or points to room for 8 values that overlap nothing else.
            pub(crate) unsafe fn c_write_step(
                result: Result<#rt::emitted::StepOutput<#t, N, R>, #rt::emitted::ControlError>,
                qd: &mut [#t; N],
                report: *mut #t,
            ) -> i32 {
                let out = match result {
                    Ok(out) => out,
                    Err(e) => {
                        *qd = [0.0; N];
                        return c_error_code(e);
                    }
                };
                let values = c_step_report(&out);
                if !(out.qd.iter().all(|v| v.is_finite()) && values.iter().all(|v| v.is_finite())) {
                    *qd = [0.0; N];
                    return C_CONTROL_ERROR;
                }
                qd.copy_from_slice(out.qd.as_slice());
                if !report.is_null() {
                    // SAFETY: non-null, room for 8 values by the caller's contract.
                    unsafe { report.cast::<[#t; 8]>().write(values) };
                }
                c_status_code(out.status)
            }

            /// The C return code of a step that failed: `C_INVALID_ARGUMENT` for a configuration
            /// refused at this `dt` (negative gains, `K dt` at or beyond its stable bound),
            /// `C_CONTROL_ERROR` otherwise.
            pub(crate) fn c_error_code(e: #rt::emitted::ControlError) -> i32 {
                match e {
                    #rt::emitted::ControlError::Config(_) => C_INVALID_ARGUMENT,
                    _ => C_CONTROL_ERROR,
                }
            }

            /// The 8 values of a step's report: `l_a`, `|e_p|`, `|ε̃|`, `|e_r|`, `w_r`, `w_i`,
            /// `κ_r`, `κ_i`.
            pub(crate) fn c_step_report(out: &#rt::emitted::StepOutput<#t, N, R>) -> [#t; 8] {
                [
                    out.l_a,
                    out.ep.norm(),
                    out.eq.eps.norm(),
                    out.lateral_error.norm(),
                    out.w_r,
                    out.w_i,
                    out.kappa_r,
                    out.kappa_i,
                ]
            }

            /// The C return code of a step's status: 0 when every constraint held, else the one
            /// that gave way.
            pub(crate) fn c_status_code(status: #rt::emitted::StepStatus) -> i32 {
                use #rt::emitted::StepStatus;
                match status {
                    StepStatus::Held => 0,
                    StepStatus::TrocarYielded => C_TROCAR_YIELDED,
                    StepStatus::JointOutside => C_JOINT_OUTSIDE,
                    StepStatus::DepthOutside => C_DEPTH_OUTSIDE,
                }
            }

            /// A C object's state in the caller's `storage` (a controller's, a scene's), if its
            /// `init` wrote it there: non-null, aligned to `align`, and starting with the
            /// object's identity `magic` (the state is `#[repr(C)]` with its `magic: u64` first).
            ///
            /// # Safety
            /// `S` is `#[repr(C)]` with a `u64` first; `storage` is null or points to at least
            /// `size_of::<S>()` initialised bytes (written by `init`, or zeroed) that no other
            /// reference aliases.
            pub(crate) unsafe fn c_object<'a, S>(
                storage: *mut ::core::ffi::c_void,
                align: usize,
                magic: u64,
            ) -> Result<&'a mut S, i32> {
                if storage.is_null() {
                    return Err(C_NULL_ARGUMENT);
                }
                if (storage as usize) & (align - 1) != 0 || align < ::core::mem::align_of::<S>() {
                    return Err(C_BAD_STORAGE);
                }
                // SAFETY: non-null, aligned for `S` (checked above) and, by the caller's
                // contract, at least `size_of::<S>()` bytes; the identity, the first field at
                // offset 0, is read as plain bytes (any value is a valid `u64`) before the rest
                // is trusted.
                let found = unsafe { storage.cast::<u64>().read() };
                if found != magic {
                    return Err(C_BAD_STORAGE);
                }
                // SAFETY: the identity says `init` wrote a whole `S` here; the caller's
                // contract excludes aliasing.
                Ok(unsafe { &mut *storage.cast::<S>() })
            }

            /// The reference of a C caller's 18 values: the tip's position, orientation
            /// column-major, linear and angular feed-forward velocities.
            pub(crate) fn c_reference(v: &[#t; 18]) -> #rt::emitted::Reference<#t> {
                use #rt::emitted::nalgebra::{Matrix3, Vector3};
                #rt::emitted::Reference {
                    position: Vector3::new(v[0], v[1], v[2]),
                    rotation: Matrix3::from_column_slice(&v[3..12]),
                    velocity: Vector3::new(v[12], v[13], v[14]),
                    angular_velocity: Vector3::new(v[15], v[16], v[17]),
                }
            }
        }
    });
    let p_const = Literal::usize_unsuffixed(p_count);
    quote! {
        /// Number of parameters the C functions read from `params`.
        pub const PARAMS: usize = #p_const;
        /// C return code: a value written is not finite.
        pub const C_NOT_FINITE: i32 = 1;
        /// C return code: a required pointer is null; nothing is written.
        pub const C_NULL_ARGUMENT: i32 = 2;
        /// C return code of the controller step: no step could be computed.
        pub const C_CONTROL_ERROR: i32 = 3;
        /// C return code of the controller step: an input is outside the number rule (not
        /// finite, subnormal, beyond ±1e6), `dt` is not positive, or a gain is refused
        /// (negative, `K dt` at or beyond its stable bound).
        pub const C_INVALID_ARGUMENT: i32 = 4;
        /// C return code of the controller step: the trocar could not be held within the joint
        /// limits; the rates written are the best within them.
        pub const C_TROCAR_YIELDED: i32 = 5;
        /// C return code of the controller step: a joint is beyond its range; the rates
        /// written move it back only.
        pub const C_JOINT_OUTSIDE: i32 = 6;
        /// C return code of the port's registration: fewer than two poses; nothing written.
        pub const C_TOO_FEW_LINES: i32 = 7;
        /// C return code of the port's registration: the shaft's lines are nearly parallel;
        /// only their spread is written.
        pub const C_NEAR_PARALLEL: i32 = 8;
        /// C return code of the controller object's update: the insertion depth left its
        /// bounds; the rates written are the best within the limits.
        pub const C_DEPTH_OUTSIDE: i32 = 9;
        /// C return code of the controller object: its storage is too small, misaligned, or
        /// not written by this module's `init`.
        pub const C_BAD_STORAGE: i32 = 10;
        /// C return code of a scene's update: a coupling between two arms could not hold within
        /// the ports and the joint limits.
        pub const C_COUPLING_YIELDED: i32 = 11;
        #read_params
        #number_rule
        #(#fns)*
        #(#fused)*
        #controller
        #register
        #path_reference
        #object
        #port
    }
}

/// The offset of each output of a fused function in its C `out`, and the total.
fn fused_offsets(f: &FusedFunction) -> (Vec<usize>, usize) {
    let mut offsets = Vec::new();
    let mut total = 0;
    for o in &f.outputs {
        offsets.push(total);
        total += o.layout.len();
    }
    (offsets, total)
}

/// `<module>_<name>` of a fused function: its outputs one after the other in `out`, matrices in
/// place, a pose and a scalar through locals; `name_f64` where the module has
/// `fma_at_run_time`.
fn fused_c(spec: &ModuleSpec, f: &FusedFunction, real: Real, t: &TokenStream) -> TokenStream {
    let c_name = format_ident!("{}", symbol(spec, &f.name));
    // `fma_at_run_time` holds for generic modules only (the builder refuses the others). Called
    // through `self::`: the wrapper's own names (`q`, `p`, `out`, `o0`, ...) would shadow a
    // function named like them.
    let target = if spec.fma_at_run_time {
        format_ident!("{}_f64", f.name)
    } else {
        format_ident!("{}", f.name)
    };
    let (offsets, total) = fused_offsets(f);
    let mut views = Vec::new();
    let mut args = Vec::new();
    let mut copies = Vec::new();
    for (k, (o, &offset)) in f.outputs.iter().zip(&offsets).enumerate() {
        let id = format_ident!("o{k}");
        let at = Literal::usize_unsuffixed(offset);
        match o.layout {
            Layout::Scalar => {
                views.push(quote!(let mut #id: #t = 0.0;));
                args.push(quote!(&mut #id));
                copies.push(quote!(out[#at] = #id;));
            }
            Layout::Transform => {
                views.push(
                    quote!(let mut #id: ([[#t; 3]; 3], [#t; 3]) = ([[0.0; 3]; 3], [0.0; 3]);),
                );
                args.push(quote!(&mut #id));
                copies.push(pose_into(&quote!(#id), offset));
            }
            Layout::Matrix { rows, cols } => {
                let (r, c) = (
                    Literal::usize_unsuffixed(rows),
                    Literal::usize_unsuffixed(cols),
                );
                let start = if offset == 0 {
                    quote!(out)
                } else {
                    quote!(out.add(#at))
                };
                views.push(quote! {
                    // SAFETY: `out` has room for every output (the caller's contract); this
                    // one's `rows × cols` values start at its offset, apart from the others'.
                    let #id: &mut [[#t; #r]; #c] = unsafe { &mut *#start.cast::<[[#t; #r]; #c]>() };
                });
                args.push(quote!(#id));
            }
        }
    }
    let total_lit = Literal::usize_unsuffixed(total);
    let ct = c_type(real);
    let outputs = f
        .outputs
        .iter()
        .zip(&offsets)
        .map(|(o, off)| format!("`{}` at {off}", o.function.short_name()))
        .collect::<Vec<_>>()
        .join(", ");
    let doc = format!(
        " C ABI of [`{name}`]: `int {c_name}(const {ct} *q, const {ct} *params, {ct} *out)`; \
         `out` receives {total} values, the outputs one after the other ({outputs}), each \
         column-major. Returns 0, `C_NOT_FINITE` (1: a value read or written is not finite) or \
         `C_NULL_ARGUMENT` (2).{fma}",
        name = target,
        fma = if spec.fma_at_run_time {
            " Fused multiply-adds are chosen at run time (`trocar::emitted::fma`, with `std`)."
        } else {
            ""
        },
    );
    quote! {
        #[doc = #doc]
        ///
        /// # Safety
        /// `q` points to `N` readable values, `params` to the parameters (`PARAMS` values,
        /// declaration order; null when there are none), `out` to room for all the outputs'
        /// values, and `out` overlaps neither.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn #c_name(q: *const #t, params: *const #t, out: *mut #t) -> i32 {
            if q.is_null() || out.is_null() {
                return C_NULL_ARGUMENT;
            }
            // SAFETY: the caller's contract for `params`.
            let Some((p, p_values)) = (unsafe { c_params(params) }) else {
                return C_NULL_ARGUMENT;
            };
            // SAFETY: non-null (checked above) and, by the caller's contract, pointing to `N`
            // readable values.
            let q: &[#t; N] = unsafe { &*q.cast::<[#t; N]>() };
            let read_finite =
                p_values.iter().all(|v| v.is_finite()) && q.iter().all(|v| v.is_finite());
            #(#views)*
            self::#target(q, &p, #(#args),*);
            // SAFETY: non-null, room for all the outputs (the caller's contract); the views
            // above are no longer used.
            let out: &mut [#t; #total_lit] = unsafe { &mut *out.cast::<[#t; #total_lit]>() };
            #(#copies)*
            if read_finite && out.iter().all(|v| v.is_finite()) { 0 } else { C_NOT_FINITE }
        }
    }
}

/// `<module>_controller_step`: one step of the runtime controller on `Kinematics`.
fn controller_step(spec: &ModuleSpec, t: &TokenStream, rt: &TokenStream) -> TokenStream {
    let c_name = format_ident!("{}", symbol(spec, "controller_step"));
    let rows = if spec.controller.as_ref().is_some_and(|c| c.task) {
        quote!(TASK_ROWS)
    } else {
        quote!(6)
    };
    let limits = spec.joint_limits.is_some();
    // `JOINT_LIMITS` is `f64`: cast for an `f32` module only.
    let cast = if t.to_string() == "f32" {
        quote!(as f32)
    } else {
        quote!()
    };
    // Each joint's own speed limit (a URDF joint's `velocity`), infinite for none: the rates
    // keep it as well as `gains[6]` (`trocar::control::rate_box` takes the smaller).
    let speeds =
        (0..spec.joints).map(
            |k| match spec.joint_speed_limits.get(k).copied().flatten() {
                Some(v) => {
                    let v = Literal::f64_unsuffixed(v);
                    quote!(#v)
                }
                None => quote!(#t::INFINITY),
            },
        );
    let speed = quote!(let speed = SVector::<#t, N>::from([#(#speeds),*]););
    // With `JOINT_LIMITS`, the joint-limit objective (gain > 0) and, always, the joint ranges:
    // the rates keep every joint within its range over `dt` (`trocar::control::rate_box`).
    let objective = if limits {
        quote! {
            let lower = SVector::from_fn(|k, _| JOINT_LIMITS[k][0] #cast);
            let upper = SVector::from_fn(|k, _| JOINT_LIMITS[k][1] #cast);
            let ctrl = ctrl.with_limits(#rt::emitted::HardLimits {
                lower,
                upper,
                speed,
                ..#rt::emitted::HardLimits::none()
            });
            let ctrl = if gains[7] > 0.0 {
                ctrl.with_objective(#rt::emitted::NullSpaceObjective::JointLimits {
                    gain: gains[7],
                    lower,
                    upper,
                })
            } else {
                ctrl
            };
        }
    } else {
        quote! {
            let ctrl = ctrl.with_limits(#rt::emitted::HardLimits {
                speed,
                ..#rt::emitted::HardLimits::none()
            });
        }
    };
    let ranges = if limits {
        " and, over `dt`, within the joint ranges (`JOINT_LIMITS`)"
    } else {
        ""
    };
    let doc = format!(
        " C ABI of one step of the runtime's constrained controller (`trocar::control::Controller`, \
         damped least squares) on this module's `Kinematics`: `int {c_name}(const T *q, const T \
         *params, const T *target, const T *trocar, T dt, const T *gains, T *qd, T *report)`. \
         `target` holds 18 values: the tip's desired position (3), orientation `R` column-major \
         (9), linear and angular feed-forward velocities (3 + 3), all in the base frame; `trocar` \
         the trocar point (3); `gains` 8 values: `K_p`, `K_o`, `K_r` (drift correction), DLS `α0`, \
         `w0` of the task Jacobian and of `J^B_0i`, the joint speed limit (≤ 0: none but the \
         joints' own), the joint-limit objective's gain (≤ 0: none; used where the module has `JOINT_LIMITS`). \
         `qd` receives the `N` joint rates, within the speed limit and each joint's own (the \
         description's `speed_limit`, a URDF joint's `velocity`){ranges}; `report` (may be \
         null) 8 values: `l_a`, `|e_p|`, `|ε̃|`, the lateral offset of the trocar from the link \
         `|e_r|`, `w_r`, `w_i`, `κ_r`, `κ_i`.\n\n\
         Every value read follows the number rule (finite, not subnormal, within ±1e6), `dt > 0`, \
         the orientation is a proper rotation (`|RᵀR − I| ≤ 1e-6` entrywise, `det R > 0`), \
         and the gains pass `ControllerConfig::check` (`K_p`, `K_o`, `K_r`, `α0`, `w0` \
         non-negative, `K_p dt < 2`, `K_r dt < 2`, `K_o dt < 4`). Returns 0 (every constraint \
         held), `C_TROCAR_YIELDED` (5: the trocar could not be held within the joint limits; \
         `qd` and `report` written, the rates the best within the limits), `C_JOINT_OUTSIDE` \
         (6: a joint of `q` is beyond its range; written, the rates move it back only), \
         `C_NULL_ARGUMENT` (2: nothing written), `C_INVALID_ARGUMENT` (4) or \
         `C_CONTROL_ERROR` (3: no step could be computed); with 4 and 3, `qd` is set to zeros \
         (the joints stop) and `report` is not written."
    );
    quote! {
        #[doc = #doc]
        ///
        /// # Safety
        /// `q` points to `N` values, `params` to `PARAMS` values (null when there are none),
        /// `target` to 18, `trocar` to 3, `gains` to 8, `qd` to room for `N` values and
        /// `report` to room for 8 or is null; the outputs overlap no input.
        #[unsafe(no_mangle)]
        #[allow(clippy::too_many_arguments)]
        pub unsafe extern "C" fn #c_name(
            q: *const #t,
            params: *const #t,
            target: *const #t,
            trocar: *const #t,
            dt: #t,
            gains: *const #t,
            qd: *mut #t,
            report: *mut #t,
        ) -> i32 {
            use #rt::emitted::{Controller, ControllerConfig, Damping, Method, Rcm};
            use #rt::emitted::nalgebra::{SVector, Vector3};
            if q.is_null() || target.is_null() || trocar.is_null() || gains.is_null() || qd.is_null() {
                return C_NULL_ARGUMENT;
            }
            // SAFETY: the caller's contract for `params`.
            let Some((p, p_values)) = (unsafe { c_params(params) }) else {
                return C_NULL_ARGUMENT;
            };
            // SAFETY: each pointer is non-null (checked above) and, by the caller's contract,
            // points to as many readable values as read here.
            let (q, target, trocar, gains) = unsafe {
                (
                    &*q.cast::<[#t; N]>(),
                    &*target.cast::<[#t; 18]>(),
                    &*trocar.cast::<[#t; 3]>(),
                    &*gains.cast::<[#t; 8]>(),
                )
            };
            // SAFETY: non-null (checked above) and, by the caller's contract, room for `N` values
            // that overlap no input.
            let qd: &mut [#t; N] = unsafe { &mut *qd.cast::<[#t; N]>() };
            // The number rule of every number trocar takes from a user: finite, not subnormal
            // (rounding debris), within ±1e6 (a trocar at 1e300 gave rates of 2e301).
            let rule = |v: &#t| c_number_ok(*v);
            let read_ok = q.iter().all(rule)
                && p_values.iter().all(rule)
                && target.iter().all(rule)
                && trocar.iter().all(rule)
                && gains.iter().all(rule)
                && rule(&dt)
                && dt > 0.0;
            if !read_ok {
                *qd = [0.0; N];
                return C_INVALID_ARGUMENT;
            }
            let config = ControllerConfig {
                kp: gains[0],
                ko: gains[1],
                method: Method::Dls(Damping::Variable { alpha0: gains[3], w0: gains[4] }),
                jb0i_damping: Some(Damping::Variable { alpha0: gains[3], w0: gains[5] }),
                kr: gains[2],
                max_joint_speed: if gains[6] > 0.0 { Some(gains[6]) } else { None },
            };
            let ctrl = Controller::<#t, N, I, R, K, M, #rows>::new(config);
            #speed
            #objective
            let mut ctrl = ctrl;
            let reference = c_reference(target);
            // The desired orientation must be a proper rotation (the runtime's rule, the
            // controller object's, the command line's and Python's).
            if !#rt::emitted::is_rotation(&reference.rotation) {
                *qd = [0.0; N];
                return C_INVALID_ARGUMENT;
            }
            let rcm = Rcm {
                trocar: Vector3::new(trocar[0], trocar[1], trocar[2]),
                dv: SVector::<#t, R>::zeros(),
            };
            let kin = Kinematics { params: p };
            let result = ctrl.step(&kin, &SVector::from(*q), &reference, &rcm, dt);
            // SAFETY: `report` is null or, by the caller's contract, room for 8 values.
            unsafe { c_write_step(result, qd, report) }
        }
    }
}

/// `<module>_register_port`: the port from the shaft's lines at measured joint positions
/// (`trocar::port::PortRegistration`, the least-squares point nearest to them).
fn register_port(spec: &ModuleSpec, t: &TokenStream, rt: &TokenStream) -> TokenStream {
    let c_name = format_ident!("{}", symbol(spec, "register_port"));
    let len = Literal::usize_unsuffixed(C_REGISTER_PORT_LEN);
    // The spreads are `f64` in the runtime: cast for an `f32` module only.
    let (to_f64, from_f64) = if t.to_string() == "f32" {
        (quote!(as f64), quote!(as f32))
    } else {
        (quote!(), quote!())
    };
    let doc = format!(
        " C ABI of the port's registration from the shaft's lines (`trocar::port`, the point \
         nearest to every line in the least-squares sense): `int {c_name}(const T *joints, \
         size_t poses, const T *params, T least_spread, T forgetting, T *out)`. `joints` holds \
         `poses` rows of `N` joint values (row after row), one pose of the instrument pivoting \
         about its port each; `least_spread` (rad, 0 to `trocar::port::LARGEST_SPREAD`) the \
         least spread of the lines' directions to accept; `forgetting` in `(0.5, 1]` weighs each \
         row `1/forgetting` times the one before (1: all the same). `out` receives \
         {C_REGISTER_PORT_LEN} values: the port (3, base frame), its covariance column-major \
         (9, m²), the lines' root-mean-square distance from it (m), their spread (rad).\n\n\
         Returns 0; `C_TOO_FEW_LINES` (7: fewer than two poses, nothing written); \
         `C_NEAR_PARALLEL` (8: the lines spread less than `least_spread`; only the spread, \
         `out[13]`, is written); `C_INVALID_ARGUMENT` (4: a value read outside the number rule \
         — finite, not subnormal, within ±1e6 —, `least_spread` or `forgetting` out of range; \
         nothing written); `C_CONTROL_ERROR` (3: a shaft line could not be formed; nothing \
         written); `C_NULL_ARGUMENT` (2: nothing written)."
    );
    quote! {
        #[doc = #doc]
        ///
        /// # Safety
        /// `joints` points to `poses · N` readable values, `params` to `PARAMS` values (null
        /// when there are none), `out` to room for 14 values overlapping no input.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn #c_name(
            joints: *const #t,
            poses: usize,
            params: *const #t,
            least_spread: #t,
            forgetting: #t,
            out: *mut #t,
        ) -> i32 {
            use #rt::emitted::nalgebra::SVector;
            use #rt::emitted::{ConstrainedKinematics, PortError, PortRegistration};
            if joints.is_null() || out.is_null() {
                return C_NULL_ARGUMENT;
            }
            // SAFETY: the caller's contract for `params`.
            let Some((p, p_values)) = (unsafe { c_params(params) }) else {
                return C_NULL_ARGUMENT;
            };
            let rule = |v: &#t| c_number_ok(*v);
            let settings_ok = p_values.iter().all(rule)
                && rule(&least_spread)
                && rule(&forgetting)
                && #rt::emitted::least_spread_admitted(least_spread #to_f64);
            let Ok(mut registration) = PortRegistration::<#t>::with_forgetting(forgetting) else {
                return C_INVALID_ARGUMENT;
            };
            // A slice of `poses · N` values must not pass `isize::MAX` bytes.
            let count = poses.checked_mul(N).filter(|c| {
                c.checked_mul(::core::mem::size_of::<#t>())
                    .is_some_and(|bytes| bytes <= isize::MAX as usize)
            });
            let Some(count) = count.filter(|_| settings_ok) else {
                return C_INVALID_ARGUMENT;
            };
            // SAFETY: non-null (checked above); by the caller's contract `poses · N` readable
            // values, `count` of them, whose size is within `isize::MAX` (checked above).
            let joints = unsafe { ::core::slice::from_raw_parts(joints, count) };
            if !joints.iter().all(rule) {
                return C_INVALID_ARGUMENT;
            }
            let kin = Kinematics { params: p };
            let shaft = kin.shaft();
            for q in joints.chunks_exact(N) {
                let g_0i = kin.g_0i(&SVector::<#t, N>::from_column_slice(q));
                let added = shaft.line(&g_0i).map(|line| registration.add(&line));
                if !matches!(added, Some(Ok(()))) {
                    return C_CONTROL_ERROR;
                }
            }
            // SAFETY: non-null (checked above) and, by the caller's contract, room for 14
            // values that overlap no input.
            let out: &mut [#t; #len] = unsafe { &mut *out.cast::<[#t; #len]>() };
            match registration.estimate(least_spread) {
                Ok(e) => {
                    out[0..3].copy_from_slice(e.point.as_slice());
                    out[3..12].copy_from_slice(e.covariance.as_slice());
                    out[12] = e.residual;
                    out[13] = e.spread;
                    0
                }
                Err(PortError::TooFewLines { .. }) => C_TOO_FEW_LINES,
                Err(PortError::NearParallel { spread, .. }) => {
                    out[13] = spread #from_f64;
                    C_NEAR_PARALLEL
                }
                Err(PortError::Invalid) => C_CONTROL_ERROR,
            }
        }
    }
}

/// `<module>_trajectory_reference`: the controller's reference along a path of rows at any
/// time, as `trocar simulate ROBOT --trajectory` builds it (`trocar::trajectory`).
fn trajectory_reference(spec: &ModuleSpec, t: &TokenStream, rt: &TokenStream) -> TokenStream {
    let c_name = format_ident!("{}", symbol(spec, "trajectory_reference"));
    let doc = format!(
        " C ABI of the reference along a path (`trocar::trajectory`): `int {c_name}(const T \
         *rows, size_t count, int orientation, T t, const T *q0, const T *q, const T *params, \
         const T *trocar, T *out)`. `rows` holds `count` rows, each `t, x, y, z` (orientation 0), \
         then `roll` (1) or `qw, qx, qy, qz` (2); `q0` the joints at the start (the start pose \
         and, for a roll, its orientation), `q` the joints now (position only: the tip's current \
         orientation), `trocar` the trocar point. `out` receives 18 values: the reference's \
         position, orientation column-major, linear and angular velocity — what the controller \
         step and update take. Returns 0, `C_INVALID_ARGUMENT` (a value outside the number \
         rule, an orientation code other than 0–2, fewer than two rows, times not increasing, a \
         quaternion of no length; nothing written), `C_NOT_FINITE` (a value written is not \
         finite) or `C_NULL_ARGUMENT`."
    );
    quote! {
        #[doc = #doc]
        ///
        /// # Safety
        /// `rows` points to `count` rows of 4, 5 or 8 values (by `orientation`), `q0` and `q` to
        /// `N` values, `params` to `PARAMS` (null when there are none), `trocar` to 3, `out` to
        /// room for 18 overlapping no input.
        #[unsafe(no_mangle)]
        #[allow(clippy::too_many_arguments)]
        pub unsafe extern "C" fn #c_name(
            rows: *const #t,
            count: usize,
            orientation: i32,
            time: #t,
            q0: *const #t,
            q: *const #t,
            params: *const #t,
            trocar: *const #t,
            out: *mut #t,
        ) -> i32 {
            use #rt::emitted::nalgebra::{SVector, Vector3};
            use #rt::emitted::{ConstrainedKinematics, FlatPath, OrientationKind, PathRows};
            if rows.is_null() || q0.is_null() || q.is_null() || trocar.is_null() || out.is_null() {
                return C_NULL_ARGUMENT;
            }
            // SAFETY: the caller's contract for `params`.
            let Some((p, p_values)) = (unsafe { c_params(params) }) else {
                return C_NULL_ARGUMENT;
            };
            let kind = match orientation {
                0 => OrientationKind::None,
                1 => OrientationKind::Roll,
                2 => OrientationKind::Quaternion,
                _ => return C_INVALID_ARGUMENT,
            };
            // The values of `count` rows must fit in memory (`isize::MAX` bytes).
            let columns = FlatPath::<#t>::columns(kind);
            let Some(len) = count.checked_mul(columns).filter(|n| {
                n.checked_mul(::core::mem::size_of::<#t>())
                    .is_some_and(|bytes| bytes <= isize::MAX as usize)
            }) else {
                return C_INVALID_ARGUMENT;
            };
            // SAFETY: non-null (checked above) and, by the caller's contract, `count` rows of
            // `columns` values, `len` in all, within `isize::MAX` bytes (checked above); `q0`,
            // `q` and `trocar` point to `N`, `N` and 3 values.
            let (values, q0, q, trocar) = unsafe {
                (
                    ::core::slice::from_raw_parts(rows, len),
                    &*q0.cast::<[#t; N]>(),
                    &*q.cast::<[#t; N]>(),
                    &*trocar.cast::<[#t; 3]>(),
                )
            };
            let read_ok = values
                .iter()
                .chain(q0)
                .chain(q)
                .chain(trocar)
                .chain(p_values.iter())
                .all(|v| c_number_ok(*v))
                && c_number_ok(time);
            if !read_ok {
                return C_INVALID_ARGUMENT;
            }
            let Some(path) = FlatPath::new(values, kind) else {
                return C_INVALID_ARGUMENT;
            };
            let kin = Kinematics { params: p };
            let (Ok(g0), Ok(now)) = (
                kin.g_0e(&SVector::from(*q0)),
                kin.g_0e(&SVector::from(*q)),
            ) else {
                return C_NOT_FINITE;
            };
            let r = path.reference(time, &g0, &Vector3::from(*trocar), &now.rotation);
            // SAFETY: non-null (checked above), room for 18 values overlapping no input.
            let out: &mut [#t; 18] = unsafe { &mut *out.cast::<[#t; 18]>() };
            out[0..3].copy_from_slice(r.position.as_slice());
            out[3..12].copy_from_slice(r.rotation.as_slice());
            out[12..15].copy_from_slice(r.velocity.as_slice());
            out[15..18].copy_from_slice(r.angular_velocity.as_slice());
            if out.iter().all(|v| v.is_finite()) { 0 } else { C_NOT_FINITE }
        }
    }
}

/// The return codes the header `#define`s, after the module's name in upper case.
const CODES: [(&str, i32); 11] = [
    ("NOT_FINITE", C_NOT_FINITE),
    ("NULL_ARGUMENT", C_NULL_ARGUMENT),
    ("CONTROL_ERROR", C_CONTROL_ERROR),
    ("INVALID_ARGUMENT", C_INVALID_ARGUMENT),
    ("TROCAR_YIELDED", C_TROCAR_YIELDED),
    ("JOINT_OUTSIDE", C_JOINT_OUTSIDE),
    ("TOO_FEW_LINES", C_TOO_FEW_LINES),
    ("NEAR_PARALLEL", C_NEAR_PARALLEL),
    ("DEPTH_OUTSIDE", C_DEPTH_OUTSIDE),
    ("BAD_STORAGE", C_BAD_STORAGE),
    ("COUPLING_YIELDED", C_COUPLING_YIELDED),
];

/// The header's include guard.
fn guard(upper: &str) -> String {
    format!("TROCAR_{upper}_H")
}

/// The macro of a parameter's index.
fn param_macro(upper: &str, name: &str) -> String {
    format!("{upper}_PARAM_{}", name.to_uppercase())
}

/// The macro of a function's number of values.
fn len_macro(upper: &str, function: &str) -> String {
    format!("{upper}_{}_LEN", function.to_uppercase())
}

/// The macro of the offset of a fused function's output in its `out`.
fn offset_macro(upper: &str, function: &str, output: &str) -> String {
    format!(
        "{upper}_{}_{}_OFFSET",
        function.to_uppercase(),
        output.to_uppercase()
    )
}

/// Every macro the header of `spec` defines ([`header`]), in its order, each with what it
/// stands for (`"the parameter `l_b`"`).
pub fn macros(spec: &ModuleSpec) -> Vec<(String, String)> {
    let upper = prefix(spec).to_uppercase();
    let mut list = vec![(guard(&upper), "the include guard".to_string())];
    for c in &spec.consts {
        list.push((
            format!("{upper}_{}", c.name),
            format!("the constant `{}`", c.name),
        ));
    }
    list.push((
        format!("{upper}_PARAMS"),
        "the number of parameters".to_string(),
    ));
    for (name, _) in &spec.params {
        list.push((param_macro(&upper, name), format!("the parameter `{name}`")));
    }
    for (code, _) in CODES {
        list.push((format!("{upper}_{code}"), "a return code".to_string()));
    }
    if spec.joint_limits.is_some() {
        list.push((
            format!("{upper}_JOINT_LIMITS"),
            "the joint limits".to_string(),
        ));
    }
    for f in &spec.functions {
        list.push((
            len_macro(&upper, &f.name),
            format!("the function `{}`", f.name),
        ));
    }
    if has_controller(spec) {
        list.push((
            len_macro(&upper, "register_port"),
            "the port's registration".to_string(),
        ));
    }
    list.extend(super::c_controller::macros(spec));
    for f in &spec.fused {
        list.push((
            len_macro(&upper, &f.name),
            format!("the function `{}`", f.name),
        ));
        for o in &f.outputs {
            let short = o.function.short_name();
            list.push((
                offset_macro(&upper, &f.name, short),
                format!("the output `{short}` of the function `{}`", f.name),
            ));
        }
    }
    list
}

/// Refuses a module whose header would define one macro twice ([`macros`]): C macros are the
/// names in upper case, so the parameters `l_b` and `L_B` would both be `<MODULE>_PARAM_L_B` (the
/// compiler warns of the redefinition and a C caller writes `l_b` into `L_B`'s slot), and a
/// parameter `x_len` and a function `param_x` would both give `<MODULE>_PARAM_X_LEN`.
pub fn check_names(spec: &ModuleSpec) -> Result<(), crate::error::Error> {
    let list = macros(spec);
    for (k, (name, what)) in list.iter().enumerate() {
        if let Some((_, first)) = list[..k].iter().find(|(n, _)| n == name) {
            return Err(crate::error::Error::CMacroClash {
                name: name.clone(),
                first: first.clone(),
                second: what.clone(),
            });
        }
    }
    Ok(())
}

/// The C header of a module's C ABI ([`items`]), with its sizes as `#define`s (the macros of
/// [`macros`]; [`check_names`] refuses a module in which two of them are the same).
pub fn header(spec: &ModuleSpec, real: Real) -> String {
    let ct = c_type(real);
    let m = prefix(spec);
    let upper = m.to_uppercase();
    let mut h = String::new();
    let _ = writeln!(
        h,
        "/* C ABI of the trocar-generated module `{m}` (trocar generate --c-header).\n\
         \n\
         Every function: int {m}_<name>(const {ct} *q, const {ct} *params, {ct} *out).\n\
         q: the {n} joint values, base first; params: the {p} parameters in declaration order\n\
         (see {upper}_PARAM_<NAME>; may be NULL when there are none); out: room for the result.\n\
         Matrices are written COLUMN-MAJOR (out[c * rows + r] is entry (r, c)), as the Rust\n\
         functions return them; a pose is R column-major (9) then p (3).\n\
         Returns 0, {upper}_NOT_FINITE when a value read (q, params) or written is not finite\n\
         (the values are written all the same), {upper}_NULL_ARGUMENT when a pointer is NULL\n\
         (nothing written). No function allocates or fails otherwise.\n\
         A function of several outputs (computed in one program) writes them one after the other:\n\
         {upper}_<NAME>_<OUTPUT>_OFFSET is where each starts, {upper}_<NAME>_LEN their total. */",
        n = spec.joints,
        p = spec.params.len(),
    );
    let guard = guard(&upper);
    let _ = writeln!(
        h,
        "#ifndef {guard}\n#define {guard}\n\n#include <stddef.h>\n"
    );
    for c in &spec.consts {
        let _ = writeln!(h, "#define {upper}_{} {}", c.name, c.value);
    }
    let _ = writeln!(h, "#define {upper}_PARAMS {}", spec.params.len());
    for (k, (name, value)) in spec.params.iter().enumerate() {
        let _ = writeln!(
            h,
            "#define {} {k} /* nominal {value:?} */",
            param_macro(&upper, name)
        );
    }
    for (code, value) in CODES {
        let _ = writeln!(h, "#define {upper}_{code} {value}");
    }
    if let Some(limits) = &spec.joint_limits {
        let _ = writeln!(h, "/* Joint limits {{lower, upper}}, base first. */");
        let _ = write!(h, "#define {upper}_JOINT_LIMITS {{");
        for (k, [lo, hi]) in limits.iter().enumerate() {
            let _ = write!(h, "{}{{{lo:?}, {hi:?}}}", if k > 0 { ", " } else { "" });
        }
        let _ = writeln!(h, "}}");
    }
    let _ = writeln!(h, "\n#ifdef __cplusplus\nextern \"C\" {{\n#endif\n");
    for f in &spec.functions {
        let shape = match f.layout {
            Layout::Scalar => "a scalar".to_string(),
            Layout::Matrix { rows, cols } => format!("{rows} x {cols}, column-major"),
            Layout::Transform => "a pose: R column-major, then p".to_string(),
        };
        let _ = writeln!(
            h,
            "/* {} {} ({shape}). */\n#define {} {}\nint {m}_{}(const {ct} *q, const {ct} *params, {ct} *out);\n",
            f.summary,
            f.equation,
            len_macro(&upper, &f.name),
            f.layout.len(),
            f.name
        );
    }
    for f in &spec.fused {
        let (offsets, total) = fused_offsets(f);
        let list = f
            .outputs
            .iter()
            .map(|o| o.function.short_name())
            .collect::<Vec<_>>()
            .join(", ");
        let fma = if spec.fma_at_run_time {
            " Fused multiply-adds are chosen at run time (on a CPU with AVX2 and FMA), so the\n   last bits of the results depend on the CPU."
        } else {
            ""
        };
        let _ = writeln!(
            h,
            "/* {list} in one program, one after the other in out (each column-major, a pose as R\n   then p).{fma} */\n#define {} {total}",
            len_macro(&upper, &f.name)
        );
        for (o, off) in f.outputs.iter().zip(&offsets) {
            let _ = writeln!(
                h,
                "#define {} {off}",
                offset_macro(&upper, &f.name, o.function.short_name())
            );
        }
        let _ = writeln!(
            h,
            "int {m}_{}(const {ct} *q, const {ct} *params, {ct} *out);\n",
            f.name
        );
    }
    if has_controller(spec) {
        let ranges = if spec.joint_limits.is_some() {
            format!(" and, over dt, within the joint\n   ranges ({upper}_JOINT_LIMITS)")
        } else {
            String::new()
        };
        let _ = writeln!(
            h,
            "/* One step of trocar's constrained controller (damped least squares, drift correction,\n   \
             the joint-limit objective) on this module's kinematics.\n   \
             target[18]: tip position (3), orientation R column-major (9), velocity (3), angular\n   \
             velocity (3), base frame. trocar[3]: the trocar point. gains[8]: K_p, K_o, K_r, DLS\n   \
             alpha0, w0 of the task Jacobian, w0 of J^B_0i, joint speed limit (<= 0: none\n   \
             but the joints' own), joint-limit objective gain (<= 0: none).\n   \
             qd[{n}]: the joint rates, always within the speed limit and each joint's own (the\n   \
             URDF's velocity){ranges}.\n   \
             report[8] (or NULL): l_a, |e_p|, |eps|, |e_r| (trocar's lateral offset from the\n   \
             link), w_r, w_i, kappa_r, kappa_i.\n   \
             Every value read must be finite, not subnormal and within +-{max:e}; dt > 0; R a\n   \
             proper rotation to 1e-6 (|R^T R - I| entrywise, det R > 0); K_p, K_o, K_r, alpha0\n   \
             and the w0 >= 0; K_p dt < 2, K_r dt < 2, K_o dt < 4.\n   \
             Returns 0 when every constraint held;\n   \
             {upper}_TROCAR_YIELDED when the trocar could not be held within the joint limits\n     \
             (qd and report written: the best rates within the limits; the link leaves the\n     \
             trocar);\n   \
             {upper}_JOINT_OUTSIDE when a joint of q is beyond its range (qd and report written;\n     \
             qd moves it back only);\n   \
             {upper}_INVALID_ARGUMENT when an input breaks the rules above;\n   \
             {upper}_CONTROL_ERROR when no step could be computed (with this code and the one\n     \
             above qd is set to zeros and report is not written);\n   \
             {upper}_NULL_ARGUMENT when a pointer other than report is NULL (nothing written). */\n\
             int {m}_controller_step(const {ct} *q, const {ct} *params, const {ct} *target,\n    const {ct} *trocar, {ct} dt, const {ct} *gains, {ct} *qd, {ct} *report);\n",
            n = spec.joints,
            max = C_MAX_MAGNITUDE,
        );
        let _ = writeln!(
            h,
            "/* The port located from the shaft's lines: the point nearest to them all (least\n   \
             squares), one line per pose of the instrument pivoting about its port.\n   \
             joints[poses * {n}]: the measured joint values, pose after pose. least_spread (rad,\n   \
             0 to {largest:.4}): the least spread of the lines' directions to accept.\n   \
             forgetting in (0.5, 1]: each pose weighs 1/forgetting times the one before (1: all\n   \
             the same).\n   \
             out[{len_macro}]: the port (3, base frame), its covariance column-major\n   \
             (9, m^2), the lines' root-mean-square distance from it (m), their spread (rad).\n   \
             Returns 0;\n   \
             {upper}_TOO_FEW_LINES when there are fewer than two poses (nothing written);\n   \
             {upper}_NEAR_PARALLEL when the lines spread less than least_spread (only the spread,\n     \
             out[13], is written: pivot the instrument further);\n   \
             {upper}_INVALID_ARGUMENT when a value read is not finite, subnormal or beyond\n     \
             +-{max:e}, or least_spread or forgetting is out of range (nothing written);\n   \
             {upper}_CONTROL_ERROR when a shaft line cannot be formed (nothing written);\n   \
             {upper}_NULL_ARGUMENT when joints or out is NULL (nothing written). */\n\
             #define {len_macro} {len}\n\
             int {m}_register_port(const {ct} *joints, size_t poses, const {ct} *params,\n    \
             {ct} least_spread, {ct} forgetting, {ct} *out);\n",
            n = spec.joints,
            max = C_MAX_MAGNITUDE,
            largest = trocar::port::LARGEST_SPREAD,
            len = C_REGISTER_PORT_LEN,
            len_macro = len_macro(&upper, "register_port"),
        );
    }
    if has_controller(spec) {
        let _ = writeln!(
            h,
            "/* The reference along a path at time t, as `trocar simulate ROBOT --trajectory F.csv`\n   \
             builds it: rows[count] of t, x, y, z (orientation 0), then roll (1: about the tip's z,\n   \
             from its start orientation, turned through the trocar) or qw, qx, qy, qz (2: base\n   \
             frame); the position linear between rows, the velocity the segment's slope.\n   \
             q0: the joints at the start; q: the joints now (position only: the tip's current\n   \
             orientation); trocar[3]. out[18]: position, orientation column-major, velocity,\n   \
             angular velocity: the reference of {m}_controller_step and _update.\n   \
             Returns 0; {upper}_INVALID_ARGUMENT (a value not finite, subnormal or beyond\n   \
             +-{max:e}, an orientation code other than 0-2, fewer than two rows, times not\n   \
             increasing, a quaternion of no length; nothing written); {upper}_NOT_FINITE;\n   \
             {upper}_NULL_ARGUMENT. */\n\
             int {m}_trajectory_reference(const {ct} *rows, size_t count, int orientation, {ct} t,\n    \
             const {ct} *q0, const {ct} *q, const {ct} *params, const {ct} *trocar, {ct} *out);\n",
            max = C_MAX_MAGNITUDE,
        );
    }
    h.push_str(&super::c_controller::header(spec, real));
    h.push_str(&super::c_port::header(spec, real));
    let _ = writeln!(h, "#ifdef __cplusplus\n}}\n#endif\n\n#endif /* {guard} */");
    h
}
