// Pinocchio (C++) on the Franka Panda, as a Panda user calls it: the model is read from the URDF
// once (pinocchio::urdf::buildModel), then per control step the LOCAL Jacobian of a frame (the
// flange `panda_link8`, or `panda_link7` = panda-laparoscope's F_i: its body Jacobian, twist order
// (v, w) as trocar's) and the frame's placement.
//
// Built by the harness's build.rs (feature `pinocchio`) with g++ -O3 -DNDEBUG at the DEFAULT
// x86-64 ISA: the pip wheel's libpinocchio is built for the default ISA, and this file built with
// -march=native segfaults on this AVX-512 machine in Model's destructor (most likely Eigen's
// EIGEN_MAX_ALIGN_BYTES, 64 instead of 16, changes the layout of Eigen members). The compile
// definitions are those the CMake target pinocchio::pinocchio exports (explicit template
// instantiation on, so computeFrameJacobian etc. are the library's compiled instances).
#include <cstring>
#include <exception>
#include <iostream>
#include <string>

#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/multibody.hpp>
#include <pinocchio/parsers/urdf.hpp>

namespace {
struct PinPanda {
  pinocchio::Model model;
  pinocchio::Data data;
  pinocchio::FrameIndex frame;
  Eigen::VectorXd q;              // the configuration, as a user holds it (dim model.nq)
  pinocchio::Data::Matrix6x J;    // the caller's Jacobian (6 x nv), zeroed once

  PinPanda(pinocchio::Model m, pinocchio::FrameIndex f)
      : model(std::move(m)), data(model), frame(f), q(Eigen::VectorXd::Zero(model.nq)),
        J(pinocchio::Data::Matrix6x::Zero(6, model.nv)) {}
};

void put_se3(const pinocchio::SE3 &m, double *out) {
  // R column-major, then p (the layout of trocar's ([[T; 3]; 3], [T; 3]) and of the peers' FK).
  Eigen::Map<Eigen::Matrix3d> r(out);
  Eigen::Map<Eigen::Vector3d> t(out + 9);
  r = m.rotation();
  t = m.translation();
}
}  // namespace

extern "C" {

// Reads the URDF and prepares Model, Data, q and J; null on failure (message on stderr).
void *pin_panda_new(const char *urdf, const char *frame) {
  try {
    pinocchio::Model model;
    pinocchio::urdf::buildModel(std::string(urdf), model);
    if (!model.existFrame(frame, pinocchio::BODY)) {
      std::cerr << "pinocchio: no body frame " << frame << " in " << urdf << "\n";
      return nullptr;
    }
    const pinocchio::FrameIndex f = model.getFrameId(frame, pinocchio::BODY);
    return new PinPanda(std::move(model), f);
  } catch (const std::exception &e) {
    std::cerr << "pinocchio: " << e.what() << "\n";
    return nullptr;
  }
}

void pin_panda_free(void *p) { delete static_cast<PinPanda *>(p); }

int pin_panda_nq(const void *p) { return static_cast<const PinPanda *>(p)->model.nq; }
int pin_panda_nv(const void *p) { return static_cast<const PinPanda *>(p)->model.nv; }

// Timed: computeFrameJacobian(model, data, q, frame, LOCAL, J). Its backward pass composes the
// placements from the frame down to joint 0, so on return data.iMf[0] is the frame's placement
// in the world (read by pin_panda_placement(p, 0)); nothing else is computed.
void pin_panda_frame_jacobian(void *p, const double *q) {
  PinPanda &s = *static_cast<PinPanda *>(p);
  s.q = Eigen::Map<const Eigen::VectorXd>(q, s.model.nq);
  pinocchio::computeFrameJacobian(s.model, s.data, s.q, s.frame, pinocchio::LOCAL, s.J);
}

// Timed: the documented route to both: forwardKinematics + updateFramePlacement (data.oMf[frame])
// + computeFrameJacobian(LOCAL).
void pin_panda_fk_frame_jacobian(void *p, const double *q) {
  PinPanda &s = *static_cast<PinPanda *>(p);
  s.q = Eigen::Map<const Eigen::VectorXd>(q, s.model.nq);
  pinocchio::forwardKinematics(s.model, s.data, s.q);
  pinocchio::updateFramePlacement(s.model, s.data, s.frame);
  pinocchio::computeFrameJacobian(s.model, s.data, s.q, s.frame, pinocchio::LOCAL, s.J);
}

// The last results: which = 0: data.iMf[0] (left by computeFrameJacobian LOCAL), 1:
// data.oMf[frame] (updateFramePlacement). out: R column-major (9), p (3).
void pin_panda_placement(const void *p, int which, double *out) {
  const PinPanda &s = *static_cast<const PinPanda *>(p);
  put_se3(which == 0 ? s.data.iMf[0] : s.data.oMf[s.frame], out);
}

// The last Jacobian, column-major 6 x nv.
void pin_panda_jacobian(const void *p, double *out) {
  const PinPanda &s = *static_cast<const PinPanda *>(p);
  std::memcpy(out, s.J.data(), sizeof(double) * 6 * s.model.nv);
}

}  // extern "C"
