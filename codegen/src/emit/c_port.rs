//! The moving port in a module's C ABI: `<module>_shaft_line` (the shaft's line at the joints,
//! where the port lies) and the port's follower `<module>_port_follower_init` / `_update`
//! (`trocar::port::PortFollower`, the admittance law (R2) that moves the port's estimate along
//! the wall's lateral force), its state a plain struct `<module>_port_follower` the caller owns.

use super::c_abi::{c_type, has_controller};
use crate::ir::{ModuleSpec, Real};
use proc_macro2::TokenStream;
use quote::{format_ident, quote};
use std::fmt::Write as _;

/// The C symbols of the moving port.
pub fn symbols(spec: &ModuleSpec) -> Vec<String> {
    if !has_controller(spec) {
        return Vec::new();
    }
    ["shaft_line", "port_follower_init", "port_follower_update"]
        .iter()
        .map(|f| format!("{}_{f}", spec.name))
        .collect()
}

/// The Rust items.
pub fn items(spec: &ModuleSpec, t: &TokenStream, rt: &TokenStream) -> TokenStream {
    let name = &spec.name;
    let f_line = format_ident!("{name}_shaft_line");
    let f_init = format_ident!("{name}_port_follower_init");
    let f_update = format_ident!("{name}_port_follower_update");
    quote! {
        /// The port's follower of the C ABI (`<module>_port_follower` in the C header, the same
        /// layout): its estimate and rate, and its settings. Written by `port_follower_init`,
        /// moved by `port_follower_update`.
        #[repr(C)]
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct CPortFollower {
            /// The port's estimate (base frame, m).
            pub estimate: [#t; 3],
            /// Its rate at the last update (m/s).
            pub rate: [#t; 3],
            /// The compliance `C` (m/(N s)).
            pub compliance: #t,
            /// The largest rate of the estimate (m/s).
            pub max_rate: #t,
            /// Whether the wall's normal is known (1) or not (0).
            pub has_normal: i32,
            /// The wall's normal (base frame; any length, the follower normalises it) when
            /// known.
            pub normal: [#t; 3],
        }

        impl CPortFollower {
            /// The runtime's follower for this state, if its numbers hold the rules.
            fn follower(&self) -> Option<#rt::emitted::PortFollower<#t>> {
                use #rt::emitted::nalgebra::Vector3;
                let numbers = self
                    .estimate
                    .iter()
                    .chain(&self.rate)
                    .chain(&self.normal)
                    .chain([&self.compliance, &self.max_rate])
                    .all(|v| c_number_ok(*v));
                if !numbers {
                    return None;
                }
                let mut f = #rt::emitted::PortFollower::new(
                    Vector3::from(self.estimate),
                    self.compliance,
                    self.max_rate,
                )
                .ok()?;
                f = match self.has_normal {
                    0 => f,
                    1 => f.with_normal(Vector3::from(self.normal)).ok()?,
                    _ => return None,
                };
                f.rate = Vector3::from(self.rate);
                Some(f)
            }
        }

        /// C ABI: the shaft's line at the joints `q` — a point (3) and its unit direction (3),
        /// base frame — the line the port lies on (`trocar::control::Shaft::line`). Returns 0,
        /// `C_INVALID_ARGUMENT` (a value outside the number rule; nothing written),
        /// `C_CONTROL_ERROR` (the shaft has no direction), `C_NULL_ARGUMENT`.
        ///
        /// # Safety
        /// `q` points to `N` values, `params` to `PARAMS` (null when there are none), `out` to
        /// room for 6.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn #f_line(q: *const #t, params: *const #t, out: *mut #t) -> i32 {
            use #rt::emitted::nalgebra::SVector;
            use #rt::emitted::ConstrainedKinematics;
            if q.is_null() || out.is_null() {
                return C_NULL_ARGUMENT;
            }
            // SAFETY: the caller's contract for `params`.
            let Some((p, p_values)) = (unsafe { c_params(params) }) else {
                return C_NULL_ARGUMENT;
            };
            // SAFETY: non-null (checked above), `N` values by the caller's contract.
            let q: &[#t; N] = unsafe { &*q.cast::<[#t; N]>() };
            if !q.iter().chain(p_values.iter()).all(|v| c_number_ok(*v)) {
                return C_INVALID_ARGUMENT;
            }
            let kin = Kinematics { params: p };
            let Some(line) = kin.shaft().line(&kin.g_0i(&SVector::from(*q))) else {
                return C_CONTROL_ERROR;
            };
            // SAFETY: non-null (checked above), room for 6 values by the caller's contract.
            let out: &mut [#t; 6] = unsafe { &mut *out.cast::<[#t; 6]>() };
            out[..3].copy_from_slice(line.point.as_slice());
            out[3..].copy_from_slice(line.direction.as_slice());
            0
        }

        /// C ABI: writes a follower into `follower`, its estimate at `estimate` (3), the
        /// compliance `compliance` (m/(N s), ≥ 0: `1/(k τ)` closes on a wall of stiffness `k`
        /// with the time constant `τ`), the largest rate `max_rate` (m/s, > 0), the wall's
        /// normal `normal` (3, or null where it is not known). Returns 0,
        /// `C_INVALID_ARGUMENT` (nothing written), `C_NULL_ARGUMENT`.
        ///
        /// # Safety
        /// `follower` points to room for a `CPortFollower`, `estimate` to 3 values, `normal` to
        /// 3 or is null.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn #f_init(
            follower: *mut CPortFollower,
            estimate: *const #t,
            compliance: #t,
            max_rate: #t,
            normal: *const #t,
        ) -> i32 {
            if follower.is_null() || estimate.is_null() {
                return C_NULL_ARGUMENT;
            }
            // SAFETY: non-null (checked above; `normal` where it is not null), 3 values each by
            // the caller's contract.
            let (estimate, normal) = unsafe {
                (
                    *estimate.cast::<[#t; 3]>(),
                    (!normal.is_null()).then(|| *normal.cast::<[#t; 3]>()),
                )
            };
            let state = CPortFollower {
                estimate,
                rate: [0.0; 3],
                compliance,
                max_rate,
                has_normal: i32::from(normal.is_some()),
                normal: normal.unwrap_or([0.0; 3]),
            };
            if state.follower().is_none() {
                return C_INVALID_ARGUMENT;
            }
            // SAFETY: non-null, room for the struct by the caller's contract.
            unsafe { follower.write(state) };
            0
        }

        /// C ABI: one step of the follower (R2) over `dt` from the wall's force `force` (3, N,
        /// base frame) on the shaft at the joints `q`: the estimate moves; its rate (the
        /// trocar's velocity to feed forward) is written into `rate` (3, or null). Returns 0,
        /// `C_INVALID_ARGUMENT` (a value outside the number rule, `dt < 0`, a state `init` did
        /// not write; the follower unchanged), `C_CONTROL_ERROR` (the shaft has no direction),
        /// `C_NULL_ARGUMENT`.
        ///
        /// # Safety
        /// `follower` points to a `CPortFollower`, `force` to 3 values, `q` to `N`, `params`
        /// to `PARAMS` (null when there are none), `rate` to room for 3 or is null.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn #f_update(
            follower: *mut CPortFollower,
            force: *const #t,
            q: *const #t,
            params: *const #t,
            dt: #t,
            rate: *mut #t,
        ) -> i32 {
            use #rt::emitted::nalgebra::{SVector, Vector3};
            use #rt::emitted::ConstrainedKinematics;
            if follower.is_null() || force.is_null() || q.is_null() {
                return C_NULL_ARGUMENT;
            }
            // SAFETY: the caller's contract for `params`.
            let Some((p, p_values)) = (unsafe { c_params(params) }) else {
                return C_NULL_ARGUMENT;
            };
            // SAFETY: non-null (checked above); a `CPortFollower` (any bits are valid numbers),
            // 3 and `N` values by the caller's contract.
            let (state, force, q) = unsafe {
                (
                    &mut *follower,
                    &*force.cast::<[#t; 3]>(),
                    &*q.cast::<[#t; N]>(),
                )
            };
            let read_ok = force
                .iter()
                .chain(q)
                .chain(p_values.iter())
                .all(|v| c_number_ok(*v))
                && c_number_ok(dt)
                && dt >= 0.0;
            let Some(mut f) = state.follower().filter(|_| read_ok) else {
                return C_INVALID_ARGUMENT;
            };
            let kin = Kinematics { params: p };
            let Some(line) = kin.shaft().line(&kin.g_0i(&SVector::from(*q))) else {
                return C_CONTROL_ERROR;
            };
            let Ok(v) = f.update(&Vector3::from(*force), &line.direction, dt) else {
                return C_INVALID_ARGUMENT;
            };
            state.estimate = f.estimate.into();
            state.rate = v.into();
            if !rate.is_null() {
                // SAFETY: non-null, room for 3 values by the caller's contract.
                unsafe { rate.cast::<[#t; 3]>().write(v.into()) };
            }
            0
        }
    }
}

/// The header's part for the moving port.
pub fn header(spec: &ModuleSpec, real: Real) -> String {
    if !has_controller(spec) {
        return String::new();
    }
    let ct = c_type(real);
    let m = &spec.name;
    let upper = m.to_uppercase();
    let mut h = String::new();
    let _ = writeln!(
        h,
        "/* The shaft's line at the joints q: a point (3) and its unit direction (3), base frame,\n   \
         the line the port lies on. Returns 0, {upper}_INVALID_ARGUMENT, {upper}_CONTROL_ERROR (no\n   \
         direction), {upper}_NULL_ARGUMENT. */\n\
         int {m}_shaft_line(const {ct} *q, const {ct} *params, {ct} *out);\n\n\
         /* The port's follower (an admittance law): the estimate moves along the wall's force\n   \
         across the shaft, rate = C (I - d d^T) F (+ the part along the shaft the wall's normal\n   \
         decides), at most max_rate. Its state is this struct, the caller's. */\n\
         typedef struct {{\n    \
         {ct} estimate[3]; /* the port's estimate (base frame, m) */\n    \
         {ct} rate[3]; /* its rate at the last update (m/s): the trocar's velocity to feed forward */\n    \
         {ct} compliance; /* C (m/(N s)); 1/(k tau) closes on a wall of stiffness k in tau */\n    \
         {ct} max_rate; /* m/s */\n    \
         int has_normal; /* 1 when the wall's normal is known */\n    \
         {ct} normal[3]; /* base frame (any length: normalised at each update) */\n\
         }} {m}_port_follower;\n\n\
         /* Writes a follower: estimate[3], compliance >= 0, max_rate > 0, normal[3] or NULL.\n   \
         Returns 0, {upper}_INVALID_ARGUMENT (nothing written), {upper}_NULL_ARGUMENT. */\n\
         int {m}_port_follower_init({m}_port_follower *follower, const {ct} *estimate,\n    \
         {ct} compliance, {ct} max_rate, const {ct} *normal);\n\n\
         /* One step over dt >= 0 from the wall's force[3] (N, base frame) on the shaft at the\n   \
         joints q: the estimate moves, its rate written into rate[3] (or NULL). Returns 0,\n   \
         {upper}_INVALID_ARGUMENT (the follower unchanged), {upper}_CONTROL_ERROR,\n   \
         {upper}_NULL_ARGUMENT. */\n\
         int {m}_port_follower_update({m}_port_follower *follower, const {ct} *force,\n    \
         const {ct} *q, const {ct} *params, {ct} dt, {ct} *rate);\n"
    );
    h
}
