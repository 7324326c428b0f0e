"""The physics plant (trocar.physics on MuJoCo): its geometry against trocar's closed forms and
against Pinocchio, a short closed-loop run with noise and latency, and its refusals."""

import math
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import trocar

if os.environ.get("TROCAR_REQUIRE_PHYSICS"):
    # CI installs the physics extra: a missing MuJoCo is a failure there, not a skip.
    import mujoco
    import pinocchio  # noqa: F401
    from trocar import physics
else:
    mujoco = pytest.importorskip("mujoco")
    physics = pytest.importorskip("trocar.physics")

ROOT = pathlib.Path(__file__).resolve().parents[3]
PANDA_URDF = ROOT / "runtime" / "model" / "robots" / "urdf" / "panda.urdf"
UR5 = ROOT / "examples" / "robots" / "ur5_trocar.toml"


def tip_in_mujoco(robot, q):
    model = mujoco.MjModel.from_xml_string(robot.mjcf())
    data = mujoco.MjData(model)
    data.qpos[: len(q)] = q
    mujoco.mj_forward(model, data)
    return data.site_xpos[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "tip")].copy()


@pytest.mark.parametrize("name", ["panda-laparoscope", str(UR5)])
def test_the_plant_places_the_tip_where_the_closed_forms_do(name):
    robot = trocar.Robot.load(name)
    rng = np.random.default_rng(1)
    for _ in range(20):
        q = [rng.uniform(max(lo, -2.5), min(hi, 2.5)) for lo, hi in robot.joint_limits]
        g = np.asarray(robot.eval(q, "fk"))
        assert np.max(np.abs(tip_in_mujoco(robot, q) - g[:3, 3])) < 1e-12


def test_the_plant_carries_the_descriptions_masses_and_limits():
    robot = trocar.Robot.load("panda-laparoscope")
    model = mujoco.MjModel.from_xml_string(robot.mjcf())
    masses = [model.body_mass[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f"link{k}")]
              for k in range(1, 8)]
    assert masses == pytest.approx([2.7907, 2.542, 2.2513, 2.2037, 2.2855, 1.353, 0.35973], abs=1e-12)
    shaft = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "instrument")
    assert model.body_mass[shaft] == pytest.approx(0.25)
    assert list(model.jnt_actfrcrange[:, 1]) == [87.0] * 4 + [12.0] * 3
    assert list(model.dof_frictionloss[:7]) == [0.2] * 7


def test_a_robot_without_mass_properties_is_refused_by_name():
    robot = trocar.Robot.load("bidirectional-zy")
    with pytest.raises(ValueError, match=r"mass properties.*joints\[0\]"):
        robot.mjcf()


def test_run_setup_replays_the_scenario_reference():
    setup = trocar.RunSetup("panda-laparoscope")
    assert setup.q0 == pytest.approx([0.0, -math.pi / 4, 0.0, -3 * math.pi / 4, 0.0, math.pi / 2, math.pi / 4])
    for t in (0.0, 0.7, 5.3):
        a, b = setup.reference(t), trocar.panda_reference(t)
        for key in ("position", "rotation", "velocity", "angular_velocity"):
            assert np.array_equal(np.asarray(a[key]), np.asarray(b[key])), key
    with pytest.raises(ValueError, match="q0 and trocar"):
        trocar.RunSetup("panda-laparoscope", q0=[0.0] * 7)


def pinocchio_drift(columns):
    """The distance from the port to the shaft's line, the shaft computed by Pinocchio from the
    URDF and the run's joint columns (panda_link8's origin along its z axis)."""
    pin = pytest.importorskip("pinocchio")
    model = pin.buildModelFromUrdf(str(PANDA_URDF))
    data = model.createData()
    frame = model.getFrameId("panda_link8")
    port = np.array([columns["port_x"][0], columns["port_y"][0], columns["port_z"][0]])
    out = []
    for k in range(len(columns["t"])):
        q = np.array([columns[f"q{j + 1}"][k] for j in range(7)])
        pin.forwardKinematics(model, data, q)
        pin.updateFramePlacements(model, data)
        m = data.oMf[frame]
        s, d = m.translation, m.rotation[:, 2]
        r = port - s
        out.append(np.linalg.norm(r - (r @ d) * d))
    return np.array(out)


def test_drift_agrees_with_pinocchio_from_the_joint_columns():
    # Without encoder noise the q columns are the plant's joint positions.
    c = physics.simulate("panda-laparoscope", method="qp", noise=0.0, duration=0.5)
    assert np.max(np.abs(pinocchio_drift(c) - c["rcm_drift"])) <= 1e-6
    assert np.max(c["rcm_drift"]) > 1e-6  # the plant does drift: the comparison says something


def test_a_short_run_with_noise_and_latency_holds_the_port_and_the_limits():
    robot = trocar.Robot.load("panda-laparoscope")
    c = physics.simulate("panda-laparoscope", method="qp", noise=1e-5, latency=1, duration=2.0)
    s = c["summary"]
    assert s["max_drift"] <= 5e-4
    assert s["yielded_steps"] == 0 and np.all(c["status"] == 1.0)
    q = np.stack([c[f"q{k + 1}"] for k in range(7)], axis=1)
    qd = np.stack([c[f"qd{k + 1}"] for k in range(7)], axis=1)
    lo, hi = np.array(robot.joint_limits).T
    assert np.all(q >= lo) and np.all(q <= hi)
    assert np.all(np.abs(qd) <= np.array(robot.speed_limits))
    # Every command a Panda accepts: its changes within the acceleration limits.
    accel = np.abs(np.diff(qd, axis=0)) / 1e-3
    assert np.all(accel <= np.array(robot.acceleration_limits) * (1 + 1e-9))
    # The plant's own motion too (it follows the commands through its servo and the wall).
    assert s["measured_speed_excess"] <= 0.0
    assert s["measured_acceleration_excess"] <= 0.0
    assert s["peak_port_force"] > 0.0
    assert s["real_time_factor"] > 0.0
    # The drift correction is what keeps the shaft at the port: without it the drift grows.
    off = physics.simulate("panda-laparoscope", method="qp", noise=1e-5, latency=1, duration=2.0,
                           drift_correction=False)
    assert off["summary"]["max_drift"] > 2 * s["max_drift"]


def test_the_breathing_port_followed_from_the_force_on_the_plant():
    # The same breathing scenario as the kinematic run, on MuJoCo's arm: the port followed from
    # the wall's lateral force holds the peak force within 2x of the kinematic run's figure, and
    # far below the fixed port's.
    kinematic = trocar.simulate("panda-breathing", port="estimated")
    plant = physics.simulate("panda-breathing")
    fixed = physics.simulate("panda-breathing", follow="fixed", duration=4.0)
    peak_kinematic = float(np.max(kinematic["port_force"]))
    peak_plant = plant["summary"]["peak_port_force"]
    print(f"peak port force: kinematic {peak_kinematic:.3f} N, MuJoCo {peak_plant:.3f} N, "
          f"MuJoCo with the port fixed (first breath) {fixed['summary']['peak_port_force']:.2f} N")
    assert peak_plant <= 2.0 * peak_kinematic
    assert peak_plant <= 0.2 * fixed["summary"]["peak_port_force"]
    assert plant["summary"]["yielded_steps"] == 0
    assert plant["summary"]["position_limit_excess"] <= 0.0
    assert plant["summary"]["speed_limit_excess"] <= 0.0
    # The estimate stays on the true port.
    error = np.sqrt(sum((plant[f"estimate_{a}"] - plant[f"port_{a}"]) ** 2 for a in "xyz"))
    assert np.max(error[plant["t"] >= 4.0]) <= 1e-3
    with pytest.raises(ValueError, match="does not move"):
        physics.simulate("panda-laparoscope", follow="known", duration=0.1)


def test_bad_arguments_are_refused():
    for kwargs, words in [
        (dict(noise=-1.0), "noise"),
        (dict(noise=float("nan")), "noise"),
        (dict(latency=-1), "latency"),
        (dict(latency=1.5), "latency"),
        (dict(port="soft"), "port"),
        (dict(port=physics.Wall(stiffness=float("inf"))), "port.stiffness"),
        (dict(duration=0.0), "duration"),
        (dict(servo_time_constant=0.0), "servo_time_constant"),
        (dict(method="fast"), "method"),
    ]:
        with pytest.raises(ValueError, match=words):
            physics.simulate("panda-laparoscope", duration=kwargs.pop("duration", 0.01), **kwargs)
    with pytest.raises(ValueError):
        physics.simulate("no-such-robot", duration=0.01)


def test_the_command_line_writes_its_columns_and_refuses_bad_input(tmp_path):
    out = tmp_path / "run.csv"
    plot = tmp_path / "run.png"
    r = subprocess.run(
        [sys.executable, "-m", "trocar.physics", "panda-laparoscope", "--method", "dls",
         "--duration", "0.2", "--csv", str(out), "--plot", str(plot), "--quiet"],
        capture_output=True, text=True, check=False,
    )
    assert r.returncode == 0, r.stderr
    header = out.read_text().splitlines()[0].split(",")
    assert header[:5] == ["t", "ep_norm", "eo_norm", "rcm_drift", "l_a"]
    for name in ["q7", "qd7", "port_x", "port_y", "port_z", "port_force", "tau1", "tau7"]:
        assert name in header
    assert len(out.read_text().splitlines()) == 202
    assert plot.stat().st_size > 10_000
    bad = subprocess.run(
        [sys.executable, "-m", "trocar.physics", "panda-laparoscope", "--noise", "-1",
         "--csv", str(tmp_path / "bad.csv")],
        capture_output=True, text=True, check=False,
    )
    assert bad.returncode == 1 and "noise" in bad.stderr and "Traceback" not in bad.stderr
    assert not (tmp_path / "bad.csv").exists()
