"""What every front door refuses, refused from Python in the library's words (docs/RELIABILITY.md's
findings F18 onwards): each case here was accepted, or aborted the interpreter, before."""

import math
import os
import pathlib

import numpy as np
import pytest

import trocar

ROOT = pathlib.Path(__file__).resolve().parents[3]
Q0 = [0.0, -math.pi / 4, 0.0, -3 * math.pi / 4, 0.0, math.pi / 2, math.pi / 4]


@pytest.mark.parametrize("speed", [float("nan"), 0.0, -1.0, float("inf")])
def test_simulate_refuses_a_speed_limit_that_is_not_positive(speed):
    """max_joint_speed NaN dropped the limit and 0 or -1 held the arm still in a shipped
    scenario; the controller and a robot's own trajectory refused them. Now all three refuse
    with the one message."""
    with pytest.raises(ValueError) as scenario:
        trocar.simulate("panda-laparoscope", max_joint_speed=speed)
    with pytest.raises(ValueError) as controller:
        trocar.Controller(trocar.Robot.load("panda-laparoscope"), max_joint_speed=speed)
    assert str(scenario.value) == str(controller.value)
    assert "max_joint_speed" in str(scenario.value)
    desc = ROOT / "examples" / "robots" / "ur5_trocar.toml"
    with pytest.raises(ValueError) as own:
        trocar.simulate(str(desc), max_joint_speed=speed)
    assert str(own.value) == str(controller.value)


def test_eval_many_of_too_many_configurations_raises_memory_error():
    """eval_many of 10¹² configurations (a broadcast view: no memory of its own) ended the
    interpreter with SIGABRT on a failed allocation; it raises MemoryError, as numpy does, and
    the interpreter goes on."""
    robot = trocar.Robot.load("bidirectional-zy")
    q = np.broadcast_to(np.zeros(robot.joints), (10**12, robot.joints))
    with pytest.raises(MemoryError):
        robot.eval_many(q, what="jr")
    with pytest.raises(MemoryError):
        robot.eval_many(q, what=("jr", "fk"))
    c = np.ascontiguousarray(np.broadcast_to(np.zeros(robot.joints), (3, robot.joints)))
    assert robot.eval_many(c, what="jr").shape[0] == 3


def test_eval_many_takes_integers_as_eval_does():
    """eval takes a list or an array of integers; eval_many refused an integer array (a
    TypeError on the dtype). Both take them now, with the same answers as floats."""
    robot = trocar.Robot.load("bidirectional-zy")
    qi = np.array([[0, 1, 0, 0, 1, 0, 0, 0], [1, 0, 0, 1, 0, 0, 1, 0]], dtype=np.int64)
    many = robot.eval_many(qi, what="jr")
    for k in range(2):
        np.testing.assert_array_equal(many[k], robot.eval(qi[k], what="jr"))
        np.testing.assert_array_equal(many[k], robot.eval(qi[k].astype(float), what="jr"))
    np.testing.assert_array_equal(robot.eval_many(qi.tolist(), what="jr"), many)
    with pytest.raises(ValueError, match="Q: a 2-D array"):
        robot.eval_many(qi[0], what="jr")


def controller_and_reference():
    robot = trocar.Robot.load("panda-laparoscope")
    q = np.array(Q0)
    g0i = robot.eval(q, what="fk0i")
    point = (g0i @ robot.eval(q, what="constraint_frame"))[:3, 3]
    fk = robot.eval(q, what="fk")
    return trocar.Controller(robot), q, point, fk


def test_a_reference_with_an_unknown_key_is_refused():
    """{"rotaton": ...} was ignored (the step held the current orientation): an unknown key is
    named."""
    ctrl, q, point, fk = controller_and_reference()
    with pytest.raises(ValueError, match="unknown key 'rotaton'.*\"rotation\""):
        ctrl.step(q, {"position": fk[:3, 3], "rotaton": fk[:3, :3]}, point, 0.002)
    out = ctrl.step(q, {"position": fk[:3, 3], "rotation": fk[:3, :3]}, point, 0.002)
    assert np.all(np.isfinite(out["qd"]))


@pytest.mark.parametrize("rotation", [
    np.zeros((3, 3)),
    np.diag([1.0, 1.0, -1.0]),              # a reflection
    2.0 * np.eye(3),
    np.eye(3) + 1e-3,
    np.full((3, 3), np.nan),
])
def test_a_reference_rotation_must_be_a_rotation(rotation):
    """A zero matrix was taken as an orientation; a reference rotation must satisfy
    |RᵀR − I| ≤ 1e-6 and det R > 0."""
    ctrl, q, point, fk = controller_and_reference()
    with pytest.raises(ValueError, match=r'reference\["rotation"\]'):
        ctrl.step(q, {"position": fk[:3, 3], "rotation": rotation}, point, 0.002)
    # Within the tolerance: accepted.
    near = fk[:3, :3] + 1e-9
    ctrl.step(q, {"position": fk[:3, 3], "rotation": near}, point, 0.002)


def test_simulate_takes_a_path_like(tmp_path):
    """simulate(pathlib.Path(...)) raised TypeError though the stub takes os.PathLike; a
    description's path and a trajectory's path may be either."""
    desc = ROOT / "examples" / "robots" / "ur5_trocar.toml"
    by_path = trocar.simulate(desc)
    by_str = trocar.simulate(str(desc))
    np.testing.assert_array_equal(by_path["q4"], by_str["q4"])

    class Fs(os.PathLike):
        def __fspath__(self):
            return str(desc)

    np.testing.assert_array_equal(trocar.simulate(Fs())["q4"], by_str["q4"])
    with pytest.raises(TypeError, match="os.PathLike"):
        trocar.simulate(3.5)


def test_messages_name_the_arguments_not_the_command_lines_flags():
    """The library's messages named the command line's flags (`--q has 2 values`, `--param
    l_a=inf`, `--what ...`); Python's name its arguments."""
    robot = trocar.Robot.load("bidirectional-zy")
    with pytest.raises(ValueError) as e:
        robot.eval([0, 1], what="jr")
    assert str(e.value).startswith("q: 2 values given, `bidirectional_zy` has 8 joints"), e.value
    with pytest.raises(ValueError) as e:
        robot.eval([0.0] * 8, params={"l_a": float("inf")})
    assert str(e.value).startswith("params: l_a=inf:"), e.value
    with pytest.raises(ValueError) as e:
        robot.eval([0.0] * 8, what="jacobian")
    assert str(e.value).startswith("what: `jacobian` is not a quantity"), e.value
    for message in (str(e.value),):
        assert "--" not in message


def test_a_step_says_when_the_trocar_gave_way_and_keeps_the_limits():
    """The QP step with the trocar 0.2 m off the shaft exceeded joint 6's speed limit (9.6 rad/s
    against 2.61) and said nothing but its solver's status (docs/RELIABILITY.md F10): the rates now
    keep every URDF speed limit and the step's status says the trocar gave way."""
    robot = trocar.Robot.load("panda-laparoscope")
    ctrl, q, point, fk = controller_and_reference()
    held = ctrl.step(q, {"position": fk[:3, 3], "rotation": fk[:3, :3]}, point, 0.002)
    assert held["status"] == "Held"
    qp = trocar.Controller(robot, method="qp")
    off = point + np.array([0.2, 0.0, 0.0])
    out = qp.step(q, {"position": fk[:3, 3], "rotation": fk[:3, :3]}, off, 0.002)
    assert out["status"] == "TrocarYielded"
    speeds = [2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61]  # the Panda URDF's velocity limits
    assert all(abs(v) <= s for v, s in zip(out["qd"], speeds)), out["qd"]


def test_a_gain_the_sample_time_makes_unstable_is_refused():
    """kr = 2000 /s at 2 ms (kr dt = 4) was run, and diverged (F11): the step refuses it with
    the bound; the same gain at 0.5 ms (kr dt = 1) is taken."""
    robot = trocar.Robot.load("panda-laparoscope")
    ctrl = trocar.Controller(robot, kr=2000.0)
    _, q, point, fk = controller_and_reference()
    reference = {"position": fk[:3, 3], "rotation": fk[:3, :3]}
    with pytest.raises(ValueError, match=r"kr \* dt must be below 2"):
        ctrl.step(q, reference, point, 0.002)
    ctrl.step(q, reference, point, 0.0005)
