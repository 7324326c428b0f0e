"""Per-call time of trocar's Python evaluation against Pinocchio's, in one interpreter.

    pip install ./codegen/python pin
    python codegen/python/bench/eval_vs_pinocchio.py

On the Franka Panda (shipped ``panda-laparoscope``; Pinocchio reads the same URDF), times:

- ``robot.eval(q, what=...)`` per call, for the partial body Jacobian ``jb0i`` (J^B_0i in
  panda_link7's frame, 6 x 7), the pose ``fk`` and ``jr``, against ``pinocchio.computeFrameJacobian(model,
  data, q, frame, LOCAL)`` (the same J^B, panda_link7) per call;
- ``robot.eval(q, what=("fk0i", "jb0i"))`` (the pose of panda_link7 and J^B_0i from one
  program) against Pinocchio's faster way to both (``computeJointJacobians`` +
  ``updateFramePlacement`` + ``getFrameJacobian``, or ``computeFrameJacobian`` +
  ``forwardKinematics`` + ``updateFramePlacement``), and against two trocar calls;
- ``robot.eval_many(Q, what="jb0i")`` for N = 10^4 configurations, per configuration;
- ``trocar.Controller(robot, method="dls").step(...)`` per step.

Each figure is the minimum over repetitions of the mean time of a block of calls (the least
disturbed block on a shared machine). Prints the ratios the front-door issue sets as targets:
eval / Pinocchio <= 1 and eval_many per configuration / Pinocchio <= 0.1; step <= 20 us.
"""

import pathlib
import platform
import timeit

import numpy as np
import pinocchio as pin

import trocar
from machine import cpu

ROOT = pathlib.Path(__file__).resolve().parents[3]
URDF = ROOT / "runtime" / "model" / "robots" / "urdf" / "panda.urdf"


def per_call(fn, number, repeat=7):
    return min(timeit.repeat(fn, number=number, repeat=repeat)) / number


def main():
    robot = trocar.Robot.load("panda-laparoscope")
    model = pin.buildModelFromUrdf(str(URDF))
    data = model.createData()
    # trocar's J^B_0i is in the frame of the joint that carries the constrained link
    # (panda_joint7's, which is panda_link7's; panda_link8 is fixed 0.107 m further out).
    frame = model.getFrameId("panda_link7")
    rng = np.random.default_rng(1)
    lo, hi = np.array(robot.joint_limits).T
    q = rng.uniform(lo, hi)
    qp = np.zeros(model.nq)
    qp[:7] = q

    # The two agree: Pinocchio's LOCAL Jacobian of panda_link7 is trocar's J^B_0i.
    jp = pin.computeFrameJacobian(model, data, qp, frame, pin.ReferenceFrame.LOCAL)[:, :7]
    jt = robot.eval(q, what="jb0i")
    print(f"CPU: {cpu()}; Python {platform.python_version()}; pinocchio {pin.__version__}")
    print(f"max |J^B_0i trocar - Pinocchio| = {np.max(np.abs(jt - jp)):.1e}")

    n = 20000
    t_pin = per_call(lambda: pin.computeFrameJacobian(model, data, qp, frame,
                                                      pin.ReferenceFrame.LOCAL), n)
    print(f"pinocchio computeFrameJacobian (LOCAL)  {t_pin * 1e6:8.3f} us per call")
    worst = 0.0
    for what in ["jb0i", "fk", "jr", "task"]:
        t = per_call(lambda: robot.eval(q, what=what), n)
        worst = max(worst, t / t_pin)
        print(f"trocar robot.eval(q, what={what!r:7})     {t * 1e6:8.3f} us per call"
              f"  {t / t_pin:6.3f}x Pinocchio")

    # The pose and the Jacobian together. `computeFrameJacobian` leaves `data.oMf` as it was
    # (checked below), so Pinocchio needs a second step for the placement: two ways, the faster
    # one taken. trocar: one call with a tuple of names (one program), and two calls.
    def pin_joint_jacobians():
        pin.computeJointJacobians(model, data, qp)
        g = pin.updateFramePlacement(model, data, frame).homogeneous
        return g, pin.getFrameJacobian(model, data, frame, pin.ReferenceFrame.LOCAL)

    def pin_frame_jacobian():
        j = pin.computeFrameJacobian(model, data, qp, frame, pin.ReferenceFrame.LOCAL)
        pin.forwardKinematics(model, data, qp)
        return pin.updateFramePlacement(model, data, frame).homogeneous, j

    g_t, j_t = robot.eval(q, what=("fk0i", "jb0i"))
    pin.framesForwardKinematics(model, data, np.zeros(model.nq))
    before = data.oMf[frame].homogeneous.copy()
    pin.computeFrameJacobian(model, data, qp, frame, pin.ReferenceFrame.LOCAL)
    print("computeFrameJacobian leaves data.oMf[frame] as it was: "
          f"{np.array_equal(data.oMf[frame].homogeneous, before)}"
          f" (then {np.max(np.abs(data.oMf[frame].homogeneous - g_t)):.1e} from the pose)")
    for way in (pin_joint_jacobians, pin_frame_jacobian):
        g_p, j_p = way()
        print(f"{way.__name__}: max |g_0i trocar - Pinocchio| = {np.max(np.abs(g_t - g_p)):.1e},"
              f" max |J^B_0i trocar - Pinocchio| = {np.max(np.abs(j_t - j_p[:, :7])):.1e}")
    t_pin2 = min(per_call(pin_joint_jacobians, n), per_call(pin_frame_jacobian, n))
    t_both = per_call(lambda: robot.eval(q, what=("fk0i", "jb0i")), n)
    t_two = per_call(lambda: (robot.eval(q, what="fk0i"), robot.eval(q, what="jb0i")), n)
    print(f"pinocchio pose + J^B (the faster way)   {t_pin2 * 1e6:8.3f} us per call")
    print(f"trocar robot.eval(q, what=('fk0i', 'jb0i')) {t_both * 1e6:8.3f} us per call"
          f"  {t_both / t_pin2:6.3f}x Pinocchio")
    print(f"trocar eval 'fk0i' then 'jb0i'         {t_two * 1e6:8.3f} us per pair"
          f"  {t_two / t_pin2:6.3f}x Pinocchio")

    qs = rng.uniform(lo, hi, size=(10_000, 7))
    t_many = per_call(lambda: robot.eval_many(qs, what="jb0i"), 5) / len(qs)
    t_many2 = per_call(lambda: robot.eval_many(qs, what=("fk0i", "jb0i")), 5) / len(qs)
    print(f"trocar robot.eval_many(Q, ('fk0i', 'jb0i')) {t_many2 * 1e9:8.1f} ns per configuration"
          f"  {t_many2 / t_pin2:6.3f}x Pinocchio's pose + J^B")
    print(f"trocar robot.eval_many(Q, 'jb0i'), N=1e4 {t_many * 1e9:8.1f} ns per configuration"
          f"  {t_many / t_pin:6.3f}x Pinocchio's call")

    ctrl = trocar.Controller(robot, method="dls")
    g = robot.eval(q, what="fk0i") @ robot.eval(q, what="constraint_frame")
    point = g[:3, 3]
    ref = trocar.panda_reference(1.0)
    t_step = per_call(lambda: ctrl.step(q, ref, point, 0.002), 5000)
    print(f"trocar Controller.step (Panda, DLS)    {t_step * 1e6:8.3f} us per step")

    print(f"ratio eval / Pinocchio (worst of the four): {worst:.3f} (target <= 1)")
    print(f"ratio eval_many per configuration / Pinocchio: {t_many / t_pin:.3f} (target <= 0.1)")
    print(f"Controller.step: {t_step * 1e6:.2f} us (target <= 20 us)")
    print(f"ratio pose and Jacobian in one call / Pinocchio's: {t_both / t_pin2:.3f}")


if __name__ == "__main__":
    main()
