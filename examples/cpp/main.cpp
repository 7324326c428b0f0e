// The Panda laparoscope's control loop from C++, through trocar's C ABI.
//
//   cmake -S examples/cpp -B build && cmake --build build && build/panda_loop
//
// From the Panda scenario's start configuration, the laparoscope's tip moves 1 cm along the
// start frame's x axis in 1 s (2 ms steps) while the shaft stays in the trocar (the shaft's point
// at l_a = 0.25 m at the start). Prints, every 0.1 s and at the end, the time, the tip error, the
// trocar's lateral offset from the shaft and the joint values (17 significant digits), so that a
// test can compare the run with the same loop in Rust.
#include <array>
#include <cmath>
#include <cstdio>

#include "panda_laparoscope.h"

int main() {
    constexpr int n = PANDA_LAPAROSCOPE_N;
    std::array<double, n> q = {0.0, -M_PI / 4, 0.0, -3 * M_PI / 4, 0.0, M_PI / 2, M_PI / 4};
    const std::array<double, PANDA_LAPAROSCOPE_PARAMS> params = {0.25};
    // The trocar: the constraint frame's origin at the start, g_0i(q0) g_ir.
    std::array<double, 12> g0i{}, gir{}, g0e{};
    if (panda_laparoscope_forward_kinematics_i(q.data(), params.data(), g0i.data()) != 0 ||
        panda_laparoscope_constraint_frame(q.data(), params.data(), gir.data()) != 0 ||
        panda_laparoscope_forward_kinematics(q.data(), params.data(), g0e.data()) != 0) {
        std::fprintf(stderr, "kinematics not finite at the start\n");
        return 1;
    }
    // g_0i and J^B_0i from one program (the fused function), one after the other in one array:
    // the same g_0i to rounding.
    std::array<double, PANDA_LAPAROSCOPE_LINK_POSE_AND_JACOBIAN_LEN> fused{};
    if (panda_laparoscope_link_pose_and_jacobian(q.data(), params.data(), fused.data()) != 0) {
        std::fprintf(stderr, "fused kinematics not finite at the start\n");
        return 1;
    }
    for (int e = 0; e < 12; ++e) {
        const double g = fused[PANDA_LAPAROSCOPE_LINK_POSE_AND_JACOBIAN_FK0I_OFFSET + e];
        if (std::fabs(g - g0i[e]) > 1e-12) {
            std::fprintf(stderr, "fused g_0i[%d] = %.17g, forward_kinematics_i %.17g\n", e, g,
                         g0i[e]);
            return 1;
        }
    }
    std::array<double, 3> trocar{};
    for (int r = 0; r < 3; ++r) {  // p_0r = R_0i p_ir + p_0i (R column-major, then p)
        trocar[r] = g0i[9 + r];
        for (int c = 0; c < 3; ++c) trocar[r] += g0i[3 * c + r] * gir[9 + c];
    }
    // K_p, K_o, K_r, DLS alpha0, w0 of S J^r, w0 of J^B_0i, speed limit, joint-limit gain.
    const std::array<double, 8> gains = {5.0, 10.0, 20.0, 0.05, 1e-3, 0.01, 2.0, 10.0};
    const double dt = 0.002, speed = 0.01;
    std::array<double, 18> target{};
    std::array<double, n> qd{};
    std::array<double, 8> report{};
    // What the step refuses gets the header's codes: a sample time that is not a number and a
    // negative gain (qd then zeros); a trocar 0.2 m off the shaft cannot be held within the
    // speed limit (gains[6]): the rates keep it, and the step says the trocar yielded.
    {
        std::array<double, 18> start{};
        for (int r = 0; r < 3; ++r) start[r] = g0e[9 + r];
        for (int e = 0; e < 9; ++e) start[3 + e] = g0e[e];
        std::array<double, 8> negative = gains;
        negative[2] = -gains[2];
        std::array<double, 3> off = trocar;
        off[0] += 0.2;
        const int nan_dt = panda_laparoscope_controller_step(
            q.data(), params.data(), start.data(), trocar.data(), std::nan(""), gains.data(),
            qd.data(), nullptr);
        const int negative_kr = panda_laparoscope_controller_step(
            q.data(), params.data(), start.data(), trocar.data(), dt, negative.data(), qd.data(),
            nullptr);
        if (nan_dt != PANDA_LAPAROSCOPE_INVALID_ARGUMENT ||
            negative_kr != PANDA_LAPAROSCOPE_INVALID_ARGUMENT) {
            std::fprintf(stderr, "dt NaN: status %d, K_r < 0: status %d\n", nan_dt, negative_kr);
            return 1;
        }
        const int yielded = panda_laparoscope_controller_step(
            q.data(), params.data(), start.data(), off.data(), dt, gains.data(), qd.data(),
            report.data());
        if (yielded != PANDA_LAPAROSCOPE_TROCAR_YIELDED) {
            std::fprintf(stderr, "trocar off the shaft: status %d\n", yielded);
            return 1;
        }
        for (double v : qd) {
            if (!(std::fabs(v) <= gains[6])) {
                std::fprintf(stderr, "trocar off the shaft: |qd| = %g > %g\n", v, gains[6]);
                return 1;
            }
        }
    }
    const int steps = 500;
    for (int k = 0; k <= steps; ++k) {
        const double t = k * dt;
        for (int r = 0; r < 3; ++r) {
            target[r] = g0e[9 + r] + g0e[r] * speed * t;  // along the start frame's x axis
            target[12 + r] = g0e[r] * speed;              // its velocity
            target[15 + r] = 0.0;
        }
        for (int e = 0; e < 9; ++e) target[3 + e] = g0e[e];  // the start orientation
        const int status = panda_laparoscope_controller_step(
            q.data(), params.data(), target.data(), trocar.data(), dt, gains.data(), qd.data(),
            report.data());
        if (status != 0) {
            std::fprintf(stderr, "controller step failed at t = %g: status %d\n", t, status);
            return 1;
        }
        if (k % 50 == 0) {
            std::printf("t %.17g tip_error %.17g drift %.17g q", t, report[1], report[3]);
            for (double v : q) std::printf(" %.17g", v);
            std::printf("\n");
        }
        for (int j = 0; j < n; ++j) q[j] += dt * qd[j];
    }
    return 0;
}
