//! The C++ header of a module's C ABI (`trocar generate --cpp-header`, `<module>.hpp` beside
//! `<module>.h` from [`crate::Builder::c_api`]): header-only, over the C functions alone.
//!
//! In `namespace trocar::<module>`: the sizes as `constexpr`, `std::array` aliases for the
//! joints, a reference, a point and the report, the return codes as `enum class Status`, the
//! nominal parameters, `default_config()`, `register_port(...)`, and `class Controller` — the
//! controller object of [`super::c_controller`] holding its storage as an aligned member
//! (constructed zeroed, nothing to release), with `init`, `reset` and `update` on `std::array`s
//! or on plain pointers (so an `Eigen::Map` or a `std::span`'s `data()` passes straight
//! through). Nothing throws and nothing allocates: every call returns a `Status`.

use super::c_abi::{c_type, has_controller};
use super::c_api::{
    C_BAD_STORAGE, C_CONTROL_ERROR, C_COUPLING_YIELDED, C_DEPTH_OUTSIDE, C_INVALID_ARGUMENT,
    C_JOINT_OUTSIDE, C_NEAR_PARALLEL, C_NOT_FINITE, C_NULL_ARGUMENT, C_TOO_FEW_LINES,
    C_TROCAR_YIELDED,
};
use crate::ir::{ModuleSpec, Real};
use std::fmt::Write as _;

/// The `Status` enumerators and their codes.
const STATUS: [(&str, i32, &str); 12] = [
    ("Held", 0, "every constraint held (or: the call succeeded)"),
    (
        "NotFinite",
        C_NOT_FINITE,
        "a value read or written is not finite",
    ),
    (
        "NullArgument",
        C_NULL_ARGUMENT,
        "a required pointer is null; nothing written",
    ),
    (
        "ControlError",
        C_CONTROL_ERROR,
        "no step could be computed; the rates are zeros",
    ),
    (
        "InvalidArgument",
        C_INVALID_ARGUMENT,
        "an input outside the rules; the rates are zeros",
    ),
    (
        "TrocarYielded",
        C_TROCAR_YIELDED,
        "the trocar gave way to the joints' limits; the rates are the best within them",
    ),
    (
        "JointOutside",
        C_JOINT_OUTSIDE,
        "a joint is beyond its range; the rates move it back",
    ),
    ("TooFewLines", C_TOO_FEW_LINES, "fewer than two poses"),
    (
        "NearParallel",
        C_NEAR_PARALLEL,
        "the shaft's lines spread too little; pivot further",
    ),
    (
        "DepthOutside",
        C_DEPTH_OUTSIDE,
        "the insertion depth left its bounds; the rates are the best within the limits",
    ),
    (
        "BadStorage",
        C_BAD_STORAGE,
        "the controller's storage is not one init wrote",
    ),
    (
        "CouplingYielded",
        C_COUPLING_YIELDED,
        "a scene's coupling could not hold within the ports and the limits",
    ),
];

/// The C++ header of `spec`'s C ABI, for a module with a controller; `None` for one without
/// (its C header alone serves).
pub fn header(spec: &ModuleSpec, real: Real) -> Option<String> {
    if !has_controller(spec) {
        return None;
    }
    let m = &spec.name;
    let upper = m.to_uppercase();
    let ct = c_type(real);
    let mut h = String::new();
    let guard = format!("TROCAR_{upper}_HPP");
    let _ = writeln!(
        h,
        "// C++ interface of the trocar-generated module `{m}` (trocar generate --cpp-header):\n\
         // header-only, over the C ABI of {m}.h. Nothing here throws or allocates; every call\n\
         // returns a Status. Arrays are std::array; every call also takes plain pointers, so an\n\
         // Eigen::Map or a span's data() passes straight through.\n\
         #ifndef {guard}\n#define {guard}\n\n\
         #include <array>\n#include <cstddef>\n\n#include \"{m}.h\"\n\n\
         namespace trocar {{\nnamespace {m} {{\n\n\
         using Real = {ct};\n\
         constexpr std::size_t kJoints = {n};\n\
         constexpr std::size_t kParams = {upper}_PARAMS;\n\
         constexpr std::size_t kReportLen = {upper}_REPORT_LEN;\n\
         constexpr std::size_t kRegisterPortLen = {upper}_REGISTER_PORT_LEN;\n\n\
         using Joints = std::array<Real, kJoints>;\n\
         using Params = std::array<Real, kParams>;\n\
         /// The tip's position (3), orientation column-major (9), linear and angular velocity (3 + 3).\n\
         using Reference = std::array<Real, 18>;\n\
         using Point = std::array<Real, 3>;\n\
         /// l_a, |e_p|, |eps|, |e_r|, w_r, w_i, kappa_r, kappa_i.\n\
         using Report = std::array<Real, kReportLen>;\n\
         /// The port (3), its covariance column-major (9), the residual, the lines' spread.\n\
         using PortEstimate = std::array<Real, kRegisterPortLen>;\n\
         using Config = {m}_config;\n",
        n = spec.joints,
    );
    let nominal: Vec<String> = spec.params.iter().map(|(_, v)| format!("{v:?}")).collect();
    let _ = writeln!(
        h,
        "/// The parameters' nominal values, in declaration order.\n\
         constexpr Params kNominalParams = {{{{{}}}}};\n",
        nominal.join(", ")
    );
    let _ = writeln!(
        h,
        "/// What a call returned (the C return codes).\nenum class Status : int {{"
    );
    for (name, code, what) in STATUS {
        let _ = writeln!(h, "    {name} = {code}, ///< {what}");
    }
    let _ = writeln!(
        h,
        "}};\n\n\
         /// Whether a step wrote usable rates: every constraint held, or one gave way and the\n\
         /// rates are the best within the limits.\n\
         constexpr bool rates_usable(Status s) noexcept {{\n    \
         return s == Status::Held || s == Status::TrocarYielded || s == Status::JointOutside ||\n           \
         s == Status::DepthOutside;\n}}\n\n\
         /// The defaults ({upper}_DEFAULT_*, the module's joint ranges and speed limits).\n\
         inline Config default_config() noexcept {{\n    \
         Config c{{}};\n    {m}_controller_config_default(&c);\n    return c;\n}}\n\n\
         /// The port from the shaft's lines at `poses` rows of kJoints joint values.\n\
         inline Status register_port(const Real *joints, std::size_t poses, Real least_spread,\n                            \
         Real forgetting, PortEstimate &out,\n                            \
         const Real *params = kNominalParams.data()) noexcept {{\n    \
         return static_cast<Status>(\n        \
         {m}_register_port(joints, poses, params, least_spread, forgetting, out.data()));\n}}\n\n\
         /// The shaft's line at the joints q: a point and its unit direction (base frame).\n\
         inline Status shaft_line(const Real *q, Point &point, Point &direction,\n                         \
         const Real *params = kNominalParams.data()) noexcept {{\n    \
         std::array<Real, 6> out{{}};\n    \
         const auto s = static_cast<Status>({m}_shaft_line(q, params, out.data()));\n    \
         if (s == Status::Held) {{\n        \
         point = {{out[0], out[1], out[2]}};\n        \
         direction = {{out[3], out[4], out[5]}};\n    }}\n    \
         return s;\n}}\n\n\
         /// The port's follower: the estimate moves along the wall's force across the shaft\n\
         /// (an admittance law), its rate the trocar's velocity to feed forward. Its state is a\n\
         /// plain member.\n\
         class PortFollower {{\npublic:\n    \
         /// Starts at estimate with the compliance (m/(N s)), the largest rate (m/s) and the\n    \
         /// wall's normal (null: unknown).\n    \
         Status init(const Point &estimate, Real compliance, Real max_rate,\n                \
         const Point *normal = nullptr) noexcept {{\n        \
         return static_cast<Status>({m}_port_follower_init(\n            \
         &state_, estimate.data(), compliance, max_rate, normal != nullptr ? normal->data() : nullptr));\n    }}\n    \
         /// One step over dt from the wall's force on the shaft at the joints q.\n    \
         Status update(const Point &force, const Real *q, Real dt,\n                  \
         const Real *params = kNominalParams.data()) noexcept {{\n        \
         return static_cast<Status>(\n            \
         {m}_port_follower_update(&state_, force.data(), q, params, dt, nullptr));\n    }}\n    \
         /// The port's estimate.\n    \
         Point estimate() const noexcept {{ return {{state_.estimate[0], state_.estimate[1], state_.estimate[2]}}; }}\n    \
         /// Its rate at the last update (the trocar's velocity to feed forward).\n    \
         Point rate() const noexcept {{ return {{state_.rate[0], state_.rate[1], state_.rate[2]}}; }}\n\n\
         private:\n    \
         {m}_port_follower state_{{}};\n\
         }};\n\n\
         /// The constrained controller with its state (the last command, the QP's warm start) in\n\
         /// an aligned member: no allocation, nothing to release. Not copyable (a copy would be a\n\
         /// second controller with the same history); init before the first update.\n\
         class Controller {{\npublic:\n    \
         Controller() noexcept = default;\n    \
         Controller(const Controller &) = delete;\n    \
         Controller &operator=(const Controller &) = delete;\n\n    \
         /// Configures the controller (and forgets any history). InvalidArgument for a\n    \
         /// configuration outside the rules; the controller is then left as it was.\n    \
         Status init(const Config &config) noexcept {{\n        \
         return static_cast<Status>({m}_controller_init(storage_, sizeof storage_, &config));\n    }}\n\n    \
         /// Forgets the history (a loop starting again from rest), keeping the configuration.\n    \
         Status reset() noexcept {{ return static_cast<Status>({m}_controller_reset(storage_)); }}\n\n    \
         /// One step: rates into qd (and the report), the status of the step.\n    \
         Status update(const Joints &q, const Reference &reference, const Point &trocar, Real dt,\n                  \
         Joints &qd, Report *report = nullptr, const Point *trocar_rate = nullptr,\n                  \
         const Params &params = kNominalParams) noexcept {{\n        \
         return update(q.data(), reference.data(), trocar.data(),\n                      \
         trocar_rate != nullptr ? trocar_rate->data() : nullptr, dt, qd.data(),\n                      \
         report != nullptr ? report->data() : nullptr, params.data());\n    }}\n\n    \
         /// The same on pointers: q and qd kJoints values, reference 18, trocar 3, trocar_rate 3\n    \
         /// or null (a still port), report kReportLen or null, params kParams.\n    \
         Status update(const Real *q, const Real *reference, const Real *trocar,\n                  \
         const Real *trocar_rate, Real dt, Real *qd, Real *report,\n                  \
         const Real *params = kNominalParams.data()) noexcept {{\n        \
         return static_cast<Status>({m}_controller_update(storage_, q, params, reference, trocar,\n                                                        \
         trocar_rate, dt, qd, report));\n    }}\n\n\
         private:\n    \
         alignas({upper}_CONTROLLER_ALIGN) unsigned char storage_[{upper}_CONTROLLER_SIZE] = {{}};\n\
         }};\n\n\
         }} // namespace {m}\n}} // namespace trocar\n\n#endif // {guard}"
    );
    Some(h)
}
