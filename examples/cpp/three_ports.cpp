// The scene `three-ports` from C++: two instrument arms and an endoscope arm (Franka Pandas on
// their own bases), each through its own port, their shafts kept 10 mm apart inside the body,
// through the scene object of the C++ header (three_ports.hpp) at 500 Hz.
//
//   cmake -S examples/cpp -B build && cmake --build build && build/three_ports > three_ports.csv
//
// The endoscope is first aimed at the midpoint of the instruments' tips by its arm's own
// controller object; then for 4 s the instruments' tips move 7 cm toward and past the centre
// (paths on which their shafts would meet) while the endoscope keeps their midpoint on its view
// axis: the run of `trocar simulate three-ports`. Each arm runs the QP step with its URDF's limits
// (the configuration's defaults). Writes `t`, the 21 joints, the 21 rates and the smallest
// distance between two shafts, one row a step, 17 significant digits, so that a test can compare
// it with the Rust run; prints the step's time (median, p99.9) and the allocations made by the
// updates (none) to stderr. Exits with 1 if a port or a coupling gave way.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

#include "counting_malloc.hpp"
#include "three_ports.hpp"

namespace scene = trocar::three_ports;
namespace arm = trocar::panda_laparoscope;

namespace {

constexpr double kDt = 0.002;
constexpr int kSteps = 2000;
constexpr std::size_t kN = scene::kJoints;

// The tip's reference of an instrument: from the start pose g0e (R column-major, p) by `shift`
// along a quintic smooth step over 2 s from 0.5 s.
arm::Reference instrument(const std::array<double, 12> &g0e, const std::array<double, 3> &shift,
                          double t) {
    const double s = std::clamp((t - 0.5) / 2.0, 0.0, 1.0);
    const double p = s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
    const double v = (s > 0.0 && s < 1.0) ? 30.0 * s * s * (1.0 - s) * (1.0 - s) / 2.0 : 0.0;
    arm::Reference r{};
    for (int i = 0; i < 3; ++i) {
        r[i] = g0e[9 + i] + shift[i] * p;
        r[12 + i] = shift[i] * v;
    }
    for (int e = 0; e < 9; ++e) r[3 + e] = g0e[e];
    return r;
}

// The endoscope's reference: the camera's point at q, moving at `velocity`, on its view axis.
bool camera(const scene::Rates &q, const std::array<double, 3> &velocity,
            std::array<double, 3> &point, arm::Reference &reference) {
    return scene::camera_point(q, point) == scene::Status::Held &&
           scene::camera_reference(point, velocity, reference) == scene::Status::Held;
}

}  // namespace

int main() {
    if (!counting_malloc_counts()) {
        std::fprintf(stderr, "the allocation counter does not count\n");
        return 1;
    }
    // Each arm: the QP (kappa 0.01) with K_p = K_o = K_r = 10 and its URDF's ranges, speeds,
    // accelerations and jerks (the defaults); no speed limit beyond the joints' own.
    arm::Config arm_config = arm::default_config();
    arm_config.method = PANDA_LAPAROSCOPE_METHOD_QP;
    arm_config.kp = 10.0;
    arm_config.ko = 10.0;
    arm_config.kr = 10.0;
    arm_config.qp_kappa = 0.01;
    arm_config.max_joint_speed = 0.0;
    arm_config.limit_gain = 0.0;
    scene::Config config = scene::default_config();  // the scene file's couplings
    for (auto &a : config.arms) a = arm_config;

    scene::Rates q{};
    scene::Ports ports{};
    scene::start(q, ports);
    std::array<double, 12> g0e{};
    if (panda_laparoscope_forward_kinematics(q.data(), arm::kNominalParams.data(), g0e.data()) != 0) {
        std::fprintf(stderr, "kinematics not finite at the start\n");
        return 1;
    }

    // The endoscope aimed at the instruments' midpoint, the instruments still.
    static arm::Controller aim;
    if (aim.init(arm_config) != arm::Status::Held) {
        std::fprintf(stderr, "the arm's configuration was refused\n");
        return 1;
    }
    const std::size_t e = scene::kArms - 1;  // the endoscope's arm (THREE_PORTS_CAMERA_ARM)
    for (int step = 0; step < 1500; ++step) {
        std::array<double, 3> point{};
        arm::Reference reference{};
        if (!camera(q, {0.0, 0.0, 0.0}, point, reference)) {
            std::fprintf(stderr, "aiming the endoscope: no camera reference\n");
            return 1;
        }
        arm::Joints qe{}, qd{};
        arm::Point port{};
        std::copy_n(q.begin() + e * kN, kN, qe.begin());
        std::copy_n(ports.begin() + e * 3, 3, port.begin());
        if (aim.update(qe, reference, port, kDt, qd) != arm::Status::Held) {
            std::fprintf(stderr, "aiming the endoscope: the step failed\n");
            return 1;
        }
        double norm = 0.0;
        for (double v : qd) norm += v * v;
        if (std::sqrt(norm) < 1e-9) break;
        for (std::size_t j = 0; j < kN; ++j) q[e * kN + j] += qd[j] * kDt;
    }

    static scene::Scene three;  // its storage: a member, no allocation
    if (three.init(config) != scene::Status::Held) {
        std::fprintf(stderr, "the scene's configuration was refused\n");
        return 1;
    }
    const std::array<std::array<double, 3>, 2> shifts = {{{0.07, 0.001, 0.0}, {0.07, 0.001, 0.0}}};
    bool have_last = false;
    double t_last = 0.0;
    std::array<double, 3> p_last{};
    double closest = INFINITY;
    std::vector<double> times;
    times.reserve(kSteps);
    unsigned long update_allocations = 0;

    std::printf("t");
    for (std::size_t k = 1; k <= scene::kRates; ++k) std::printf(",q%zu", k);
    for (std::size_t k = 1; k <= scene::kRates; ++k) std::printf(",qd%zu", k);
    std::printf(",min_shaft_distance\n");
    for (int step = 0; step <= kSteps; ++step) {
        const double t = step * kDt;
        scene::References references{};
        for (std::size_t k = 0; k < shifts.size(); ++k) {
            const arm::Reference r = instrument(g0e, shifts[k], t);
            std::copy(r.begin(), r.end(), references.begin() + 18 * k);
        }
        std::array<double, 3> point{};
        if (scene::camera_point(q, point) != scene::Status::Held) {
            std::fprintf(stderr, "t = %.3f s: no camera point\n", t);
            return 1;
        }
        std::array<double, 3> velocity{};
        if (have_last && t > t_last) {
            for (int i = 0; i < 3; ++i) velocity[i] = (point[i] - p_last[i]) / (t - t_last);
        }
        arm::Reference view{};
        if (scene::camera_reference(point, velocity, view) != scene::Status::Held) {
            std::fprintf(stderr, "t = %.3f s: no camera reference\n", t);
            return 1;
        }
        std::copy(view.begin(), view.end(), references.begin() + 18 * e);
        have_last = true;
        t_last = t;
        p_last = point;

        scene::Rates qd{};
        if (step < kSteps) {
            counting = true;
            const auto t0 = std::chrono::steady_clock::now();
            const scene::Status status = three.update(q, references, kDt, qd);
            const auto t1 = std::chrono::steady_clock::now();
            counting = false;
            update_allocations += allocations;
            allocations = 0;
            times.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
            if (status != scene::Status::Held && status != scene::Status::JointOutside) {
                std::fprintf(stderr, "t = %.3f s: the step gave way (status %d)\n", t,
                             static_cast<int>(status));
                return 1;
            }
        }
        scene::Distances distances{};
        if (scene::coupling_distances(q, distances) != scene::Status::Held) {
            std::fprintf(stderr, "t = %.3f s: no distances\n", t);
            return 1;
        }
        const double nearest = *std::min_element(distances.begin(), distances.end());
        closest = std::min(closest, nearest);
        std::printf("%.17g", t);
        for (double v : q) std::printf(",%.17g", v);
        for (double v : qd) std::printf(",%.17g", v);
        std::printf(",%.17g\n", nearest);
        for (std::size_t j = 0; j < scene::kRates; ++j) q[j] += qd[j] * kDt;
    }
    std::sort(times.begin(), times.end());
    const auto at = [&](double f) { return times[static_cast<std::size_t>(f * (times.size() - 1))]; };
    std::fprintf(stderr,
                 "three_ports: %d steps; closest shafts %.4f mm (safety 10 mm); step median %.1f us, "
                 "p99.9 %.1f us; allocations in update: %lu\n",
                 kSteps, closest * 1e3, at(0.5), at(0.999), update_allocations);
    if (update_allocations != 0) {
        std::fprintf(stderr, "the scene's update allocated\n");
        return 1;
    }
    return 0;
}
