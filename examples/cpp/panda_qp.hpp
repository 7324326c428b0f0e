// The configuration the examples run the Panda laparoscope's controller with: the QP step with
// the URDF's joint ranges and speeds (the configuration's defaults, from the description),
// libfranka's acceleration and jerk limits, and insertion bounds of 5-30 cm; no speed limit
// besides the joints' own.
#ifndef TROCAR_EXAMPLES_PANDA_QP_HPP
#define TROCAR_EXAMPLES_PANDA_QP_HPP

#include "panda_laparoscope.hpp"

inline trocar::panda_laparoscope::Config panda_qp_config() {
    trocar::panda_laparoscope::Config config = trocar::panda_laparoscope::default_config();
    config.method = PANDA_LAPAROSCOPE_METHOD_QP;
    config.max_joint_speed = 0.0;
    const double acceleration[7] = {15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0};
    const double jerk[7] = {7500.0, 3750.0, 5000.0, 6250.0, 7500.0, 10000.0, 10000.0};
    for (int k = 0; k < 7; ++k) {
        config.acceleration[k] = acceleration[k];
        config.jerk[k] = jerk[k];
    }
    config.depth_limits = 1;
    config.depth[0] = 0.05;
    config.depth[1] = 0.30;
    return config;
}

#endif  // TROCAR_EXAMPLES_PANDA_QP_HPP
