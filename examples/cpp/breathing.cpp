// The Panda laparoscope's port moving with breathing, followed from the wall's force, from C++
// at 1 kHz: the path of `trocar simulate panda-breathing --port estimated`, through the C++
// header's Controller (the QP with the URDF's limits) and PortFollower.
//
//   cmake -S examples/cpp -B build && cmake --build build && build/panda_breathing > breathing.csv
//
// The program is its own plant: the port rises and falls with breathing (8 mm at 0.25 Hz along the
// wall's normal, 45 degrees from the shaft) and the patient shifts 2 cm across between 8 and 12 s;
// the body wall pushes the shaft back toward the port as a spring-damper (4000 N/m, 40 N s/m);
// the follower moves the port's estimate along that force (closing in 30 ms, the wall's normal
// known) and the controller holds the shaft there, the estimate's rate fed forward, while the
// tip follows the anatomy. Writes t, the joints and rates, the true port, its estimate, the
// wall's force and the shaft's distance from the true port as CSV (17 significant digits).
#include <array>
#include <cmath>
#include <cstdio>

#include "panda_laparoscope.hpp"
#include "panda_qp.hpp"

namespace tp = trocar::panda_laparoscope;

namespace {

constexpr double kBreath = 0.008;         // m, peak to peak, along the wall's normal
constexpr double kBreathFrequency = 0.25;  // Hz
constexpr double kShift = 0.02;           // m, along the base's y
constexpr double kShiftStart = 8.0, kShiftEnd = 12.0;
constexpr double kStiffness = 4000.0, kDamping = 40.0;  // the wall
constexpr double kFollowerTimeConstant = 0.02, kFollowerMaxRate = 0.05;

// The wall's normal: 45 degrees from the shaft at the start, in the x z plane.
tp::Point wall_normal() {
    const double norm = std::sqrt(1.0 * 1.0 + 0.0 * 0.0 + 1.0 * 1.0);
    return {1.0 / norm, 0.0 / norm, 1.0 / norm};
}

// The port's displacement from its start at t and its velocity.
void port_motion(double t, tp::Point &displacement, tp::Point &velocity) {
    const double w = 2.0 * M_PI * kBreathFrequency;
    const tp::Point n = wall_normal();
    const double breath = kBreath * (1.0 - std::cos(w * t)) / 2.0;
    const double breath_rate = kBreath * w * std::sin(w * t) / 2.0;
    double s = (t - kShiftStart) / (kShiftEnd - kShiftStart);
    s = s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
    const double step = s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
    const double step_rate =
        (s > 0.0 && s < 1.0) ? 30.0 * s * s * (1.0 - s) * (1.0 - s) / (kShiftEnd - kShiftStart) : 0.0;
    const tp::Point y = {0.0, 1.0, 0.0};
    for (int i = 0; i < 3; ++i) {
        displacement[i] = n[i] * breath + y[i] * (kShift * step);
        velocity[i] = n[i] * breath_rate + y[i] * (kShift * step_rate);
    }
}

}  // namespace

int main() {
    tp::Joints q = {0.0, -M_PI / 4, 0.0, -3 * M_PI / 4, 0.0, M_PI / 2, M_PI / 4};
    const tp::Params &params = tp::kNominalParams;
    std::array<double, 12> g0e{}, g0i{}, gir{};
    if (panda_laparoscope_forward_kinematics(q.data(), params.data(), g0e.data()) != 0 ||
        panda_laparoscope_forward_kinematics_i(q.data(), params.data(), g0i.data()) != 0 ||
        panda_laparoscope_constraint_frame(q.data(), params.data(), gir.data()) != 0) {
        std::fprintf(stderr, "kinematics not finite at the start\n");
        return 1;
    }
    // The port at the start: the constraint frame's origin, g_0i(q0) g_ir.
    tp::Point port0{};
    for (int r = 0; r < 3; ++r) {
        port0[r] = g0i[9 + r];
        for (int c = 0; c < 3; ++c) port0[r] += g0i[3 * c + r] * gir[9 + c];
    }

    const tp::Config config = panda_qp_config();
    static tp::Controller controller;
    tp::PortFollower follower;
    const tp::Point normal = wall_normal();
    if (controller.init(config) != tp::Status::Held ||
        follower.init(port0, 1.0 / (kStiffness * kFollowerTimeConstant), kFollowerMaxRate,
                      &normal) != tp::Status::Held) {
        std::fprintf(stderr, "the configuration was refused\n");
        return 1;
    }

    const double dt = 0.001;
    const int steps = 16000;
    std::printf("t,q1,q2,q3,q4,q5,q6,q7,qd1,qd2,qd3,qd4,qd5,qd6,qd7,port_x,port_y,port_z,"
                "estimate_x,estimate_y,estimate_z,port_force,port_offset\n");
    tp::Point last_offset{};
    tp::Joints qd{};
    for (int k = 0; k < steps; ++k) {
        const double t = k * dt;
        tp::Point displacement{}, port_rate{}, port{};
        port_motion(t, displacement, port_rate);
        for (int i = 0; i < 3; ++i) port[i] = port0[i] + displacement[i];
        // The wall's force on the shaft, from the shaft's offset from the true port and its rate.
        tp::Point point{}, direction{};
        if (tp::shaft_line(q.data(), point, direction) != tp::Status::Held) {
            std::fprintf(stderr, "t = %.3f s: the shaft has no direction\n", t);
            return 1;
        }
        tp::Point v{}, offset{}, offset_rate{}, force{};
        for (int i = 0; i < 3; ++i) v[i] = point[i] - port[i];
        const double along = direction[0] * v[0] + direction[1] * v[1] + direction[2] * v[2];
        for (int i = 0; i < 3; ++i) {
            offset[i] = v[i] - direction[i] * along;
            offset_rate[i] = k == 0 ? 0.0 : (offset[i] - last_offset[i]) / dt;
            force[i] = -(offset[i] * kStiffness + offset_rate[i] * kDamping);
        }
        last_offset = offset;
        // The estimate follows the force; the controller holds the shaft there.
        if (follower.update(force, q.data(), dt) != tp::Status::Held) {
            std::fprintf(stderr, "t = %.3f s: the follower refused the step\n", t);
            return 1;
        }
        const tp::Point estimate = follower.estimate();
        const tp::Point estimate_rate = follower.rate();
        tp::Reference reference{};
        for (int i = 0; i < 3; ++i) {
            reference[i] = g0e[9 + i] + displacement[i];
            reference[12 + i] = port_rate[i];
        }
        for (int e = 0; e < 9; ++e) reference[3 + e] = g0e[e];
        const tp::Status status =
            controller.update(q, reference, estimate, dt, qd, nullptr, &estimate_rate);
        if (!tp::rates_usable(status)) {
            std::fprintf(stderr, "t = %.3f s: status %d\n", t, static_cast<int>(status));
            return 1;
        }
        const double force_norm = std::sqrt(force[0] * force[0] + force[1] * force[1] + force[2] * force[2]);
        const double offset_norm =
            std::sqrt(offset[0] * offset[0] + offset[1] * offset[1] + offset[2] * offset[2]);
        std::printf("%.17g", t);
        for (double x : q) std::printf(",%.17g", x);
        for (double x : qd) std::printf(",%.17g", x);
        for (double x : port) std::printf(",%.17g", x);
        for (double x : estimate) std::printf(",%.17g", x);
        std::printf(",%.17g,%.17g\n", force_norm, offset_norm);
        for (std::size_t j = 0; j < tp::kJoints; ++j) q[j] += dt * qd[j];
    }
    return 0;
}
