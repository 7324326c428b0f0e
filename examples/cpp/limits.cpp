// The Panda laparoscope's limits scenario from C++ at 1 kHz: the QP step with every limit of the
// Panda's URDF (joint ranges, speeds, libfranka's accelerations and jerks) and the insertion
// bounds, through the controller object of the C++ header (panda_laparoscope.hpp).
//
//   cmake -S examples/cpp -B build && cmake --build build && build/panda_limits > limits.csv
//
// From the Panda scenario's start configuration, the tip withdraws 8 cm along the shaft toward the
// trocar between 1 and 3 s (into the insertion bound), the instrument rolls 2.6 rad about the
// shaft between 4 and 5 s (into joint 7's speed limit) and back between 6 and 8 s, and the tip
// returns between 8 and 10 s: the path of `trocar simulate panda-laparoscope-limits`. Writes a CSV
// with the command line's columns (those the controller's report carries) to stdout, one row a
// step, 17 significant digits, so that a test can compare it with the same loop in Rust.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "panda_laparoscope.hpp"
#include "counting_malloc.hpp"
#include "panda_qp.hpp"

namespace tp = trocar::panda_laparoscope;

namespace {

// The quintic smooth step from 0 at a to 1 at b, and its derivative at t.
void smooth_step(double t, double a, double b, double &s, double &ds) {
    const double span = b - a;
    double tau = (t - a) / span;
    tau = tau < 0.0 ? 0.0 : (tau > 1.0 ? 1.0 : tau);
    s = tau * tau * tau * (10.0 + tau * (-15.0 + 6.0 * tau));
    ds = (t > a && t < b) ? 30.0 * tau * tau * (1.0 - tau) * (1.0 - tau) / span : 0.0;
}

constexpr double kTipDepth = 0.15;    // the tip below the trocar at the start (m)
constexpr double kWithdrawal = 0.08;  // m
constexpr double kRoll = 2.6;         // rad

// The reference at t from the start pose (R0 column-major, p0).
tp::Reference reference(double t, const std::array<double, 9> &r0, const std::array<double, 3> &p0) {
    double w1, dw1, w2, dw2, r1, dr1, r2, dr2;
    smooth_step(t, 1.0, 3.0, w1, dw1);
    smooth_step(t, 8.0, 10.0, w2, dw2);
    smooth_step(t, 4.0, 5.0, r1, dr1);
    smooth_step(t, 6.0, 8.0, r2, dr2);
    const double depth = kTipDepth - kWithdrawal * (w1 - w2);
    const double ddepth = -kWithdrawal * (dw1 - dw2);
    const double roll = kRoll * (r1 - r2);
    const double droll = kRoll * (dr1 - dr2);
    const double c = std::cos(roll), s = std::sin(roll);
    tp::Reference ref{};
    for (int i = 0; i < 3; ++i) {
        const double z = r0[6 + i];  // the shaft: the tip frame's z at the start
        const double trocar = p0[i] - z * kTipDepth;
        ref[i] = trocar + z * depth;
        // R0 Rz(roll), column-major: columns R0 (c, s, 0), R0 (-s, c, 0), R0 (0, 0, 1).
        ref[3 + i] = r0[i] * c + r0[3 + i] * s + r0[6 + i] * 0.0;
        ref[6 + i] = r0[i] * -s + r0[3 + i] * c + r0[6 + i] * 0.0;
        ref[9 + i] = r0[i] * 0.0 + r0[3 + i] * 0.0 + r0[6 + i] * 1.0;
        ref[12 + i] = z * ddepth;
        ref[15 + i] = z * droll;
    }
    return ref;
}

}  // namespace

int main() {
    if (!counting_malloc_counts()) {
        std::fprintf(stderr, "the allocation counter does not count\n");
        return 1;
    }
    tp::Joints q = {0.0, -M_PI / 4, 0.0, -3 * M_PI / 4, 0.0, M_PI / 2, M_PI / 4};
    std::array<double, 12> g0e{};
    if (panda_laparoscope_forward_kinematics(q.data(), tp::kNominalParams.data(), g0e.data()) != 0) {
        std::fprintf(stderr, "kinematics not finite at the start\n");
        return 1;
    }
    std::array<double, 9> r0{};
    std::array<double, 3> p0{};
    for (int e = 0; e < 9; ++e) r0[e] = g0e[e];
    for (int e = 0; e < 3; ++e) p0[e] = g0e[9 + e];
    tp::Point trocar{};
    for (int i = 0; i < 3; ++i) trocar[i] = p0[i] - r0[6 + i] * kTipDepth;

    // The QP with the URDF's limits (panda_qp.hpp).
    const tp::Config config = panda_qp_config();
    static tp::Controller controller;  // its storage: a member, no allocation
    if (controller.init(config) != tp::Status::Held) {
        std::fprintf(stderr, "the configuration was refused\n");
        return 1;
    }

    const double dt = 0.001;
    const int steps = 10000;
    std::printf("t,ep_norm,eo_norm,rcm_drift,w_r,w_i,l_a,q1,q2,q3,q4,q5,q6,q7,qd1,qd2,qd3,qd4,qd5,qd6,qd7\n");
    tp::Joints qd{};
    tp::Report report{};
    std::vector<double> micros(steps);
    for (int k = 0; k < steps; ++k) {
        const double t = k * dt;
        const tp::Reference ref = reference(t, r0, p0);
        counting = true;
        const auto start = std::chrono::steady_clock::now();
        const tp::Status status = controller.update(q, ref, trocar, dt, qd, &report);
        const auto end = std::chrono::steady_clock::now();
        counting = false;
        micros[k] = std::chrono::duration<double, std::micro>(end - start).count();
        if (status != tp::Status::Held) {
            std::fprintf(stderr, "t = %.3f s: status %d\n", t, static_cast<int>(status));
            return 1;
        }
        std::printf("%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", t, report[1], report[2], report[3],
                    report[4], report[5], report[0]);
        for (double v : q) std::printf(",%.17g", v);
        for (double v : qd) std::printf(",%.17g", v);
        std::printf("\n");
        for (std::size_t j = 0; j < tp::kJoints; ++j) q[j] += dt * qd[j];
    }
    // The step's own time (the clock read around update alone): median and 99.9th percentile.
    std::sort(micros.begin(), micros.end());
    std::fprintf(stderr, "panda_limits: %d steps, allocations during update %lu, update median %.2f us, p99.9 %.2f us, max %.2f us\n",
                 steps, allocations, micros[steps / 2], micros[steps * 999 / 1000], micros[steps - 1]);
    return allocations == 0 ? 0 : 1;
}
