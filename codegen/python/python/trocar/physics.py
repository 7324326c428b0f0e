"""The constrained controller on a robot with dynamics: trocar's controller in the loop with a
MuJoCo plant.

The kinematic simulations (:func:`trocar.simulate`) integrate ``q += dt θ̇``: a robot that
moves exactly as commanded. Here the same controller runs at 1 kHz on a physics plant built from
the robot's description (:meth:`trocar.Robot.mjcf`):

- **the arm**: the links' inertias, joint damping and friction, gravity (compensated by the
  servos, as arms with a joint-velocity interface do), torque limits;
- **the command interface**: a joint-velocity servo per joint (libfranka's velocity interface,
  the dVRK's ``servo_jv``): torque ``kv (θ̇_cmd − θ̇)`` within the torque limit, with ``kv`` set
  so that each joint follows a step of the command with the time constant ``servo_time_constant``
  (5 ms by default; ``kv_k = M_kk(q0) / τ``, ``M`` the joint-space inertia at the start);
- **the measurement**: joint positions with Gaussian encoder noise (``noise``, rad), read one
  sample before the command they produce is applied (``latency`` samples, 1 by default);
- **the body wall** (:class:`Wall`): the port as tissue, a spring-damper on the shaft's offset
  from the port centre and friction along the shaft, applied to the shaft where it crosses the
  port and measured there (``port_force``) and at the wrist (a force/torque sensor).

``rcm_drift`` is measured from MuJoCo's own geometry: the distance from the port centre to the
shaft's axis as the plant places it, not from trocar's kinematics.

Run it from the command line::

    python -m trocar.physics panda-laparoscope --method qp --csv run.csv --plot run.png

or from Python with :func:`simulate`. Needs MuJoCo (``pip install "trocar[physics]"``).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import time
from dataclasses import dataclass, field

import numpy as np

from . import _trocar

__all__ = ["Wall", "simulate", "summary", "main", "DEFAULT_NOISE", "DEFAULT_SERVO_TIME_CONSTANT"]

#: Encoder noise (standard deviation, rad) by default: about ten counts of a 20-bit encoder
#: (2π / 2²⁰ ≈ 6e-6 rad), a conservative figure for the joint encoders of collaborative arms.
DEFAULT_NOISE = 1e-5

#: The velocity servo's time constant by default (s).
DEFAULT_SERVO_TIME_CONSTANT = 0.005

#: The motors' inertia reflected through their gears (kg m², added to every joint) by default:
#: 0.1, the value of MuJoCo Menagerie's Panda model (franka_emika_panda/panda.xml); a
#: description does not carry it.
DEFAULT_ARMATURE = 0.1

#: Control period (s): 1 kHz, libfranka's and the dVRK's rate.
CONTROL_PERIOD = 0.001


@dataclass(frozen=True)
class Wall:
    """The body wall at the port, acting on the shaft where it crosses the port.

    Lateral: a spring-damper on the offset ``e`` of the shaft's axis from the port centre
    (``F = −k e − c ė``, normal to the shaft). Along the shaft: friction opposing the shaft's
    sliding, ``F = −f tanh(v / v_s)`` (Coulomb, smoothed below ``v_s``).

    Sources of the defaults:

    - ``stiffness``: the in-vivo Young's modulus of the insufflated abdominal wall, 42.5 ± 9.0 kPa
      transverse and 22.5 ± 2.6 kPa sagittal (Song, Alijani, Frank, Hanna, Cuschieri, "Mechanical
      properties of the human abdominal wall measured in vivo during insufflation for
      laparoscopic surgery", Surgical Endoscopy 20(6), 2006), turned into the lateral stiffness
      of a rigid shaft in a layer of thickness ``h`` as ``k ≈ π E h``; with E = 42.5 kPa and
      h = 3 cm, k ≈ 4000 N/m (4 N/mm). An order of magnitude, not a measurement of one patient:
      give your own.
    - ``damping``: ``c = k τ`` with a tissue relaxation time τ = 10 ms, 40 N s/m (an assumption:
      no cited value).
    - ``axial_friction``: 1 N, within the 0.25–8 N resistance measured for instruments sliding in
      12 mm trocars (Alazmani, Roshan, Jayne, Neville, Culmer, "Friction characteristics of
      trocars in laparoscopic surgery", Proc. IMechE H 229(4), 2015); ``sliding_speed`` 5 mm/s.
    """

    stiffness: float = 4000.0
    damping: float = 40.0
    axial_friction: float = 1.0
    sliding_speed: float = 0.005

    def check(self) -> None:
        for name in ("stiffness", "damping", "axial_friction", "sliding_speed"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0.0):
                raise ValueError(f"port.{name}: a finite number ≥ 0, not {v!r}")
        if self.sliding_speed <= 0.0:
            raise ValueError("port.sliding_speed: must be positive")


def _mujoco():
    try:
        import mujoco  # noqa: PLC0415
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError(
            'trocar.physics needs MuJoCo: pip install "trocar[physics]" (or pip install mujoco)'
        ) from e
    return mujoco


@dataclass
class _Plant:
    """The MuJoCo model and data of a robot, with the ids the loop uses."""

    model: object
    data: object
    n: int
    instrument: int
    wrist_force: int
    wrist_torque: int
    start: np.ndarray
    direction: np.ndarray
    kv: np.ndarray = field(default_factory=lambda: np.zeros(0))


def _plant(robot, q0, servo_time_constant, armature) -> _Plant:
    mujoco = _mujoco()
    shaft = robot.shaft()
    if shaft is None:
        raise ValueError(
            f"{robot.name}: a physics run needs the instrument ([instrument] mass and radius in the description)"
        )
    model = mujoco.MjModel.from_xml_string(robot.mjcf())
    n = robot.joints
    model.dof_armature[:n] = armature
    data = mujoco.MjData(model)
    data.qpos[:n] = q0
    mujoco.mj_forward(model, data)
    # The servo gains: kv_k = M_kk(q0) / τ (M with the armature).
    full = np.zeros((model.nv, model.nv))
    if hasattr(data, "qM"):
        mujoco.mj_fullM(model, full, data.qM)
    else:  # MuJoCo 4: mj_fullM(m, d, dst)
        mujoco.mj_fullM(model, data, full)
    kv = np.diag(full)[:n] / servo_time_constant
    for k in range(n):
        model.actuator_gainprm[k, 0] = kv[k]
        model.actuator_biasprm[k, 2] = -kv[k]
    return _Plant(
        model=model,
        data=data,
        n=n,
        instrument=mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "instrument"),
        wrist_force=model.sensor_adr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, "wrist_force")],
        wrist_torque=model.sensor_adr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, "wrist_torque")],
        start=np.array(shaft["start"]),
        direction=np.array(shaft["direction"]),
        kv=kv,
    )


def _shaft_line(plant: _Plant):
    """The shaft's start and unit direction in the world, from MuJoCo's pose of the instrument."""
    d = plant.data
    r = d.xmat[plant.instrument].reshape(3, 3)
    p = d.xpos[plant.instrument]
    return p + r @ plant.start, r @ plant.direction


def _wall_force(plant: _Plant, port: np.ndarray, wall: Wall | None, port_velocity=None):
    """The wall's force on the shaft where it crosses the port, that point, and the offset; the
    damping and the friction act on the shaft's motion relative to the port (which moves with the
    tissue at ``port_velocity``, still by default)."""
    mujoco = _mujoco()
    s, d = _shaft_line(plant)
    along = float((port - s) @ d)
    c = s + along * d
    offset = c - port
    if wall is None:
        return np.zeros(3), c, offset, along
    # The velocity of the shaft's material point at c.
    jacp = np.zeros((3, plant.model.nv))
    mujoco.mj_jac(plant.model, plant.data, jacp, None, c, plant.instrument)
    v = jacp @ plant.data.qvel
    if port_velocity is not None:
        v = v - port_velocity
    v_axial = float(v @ d)
    v_lateral = v - v_axial * d
    force = -wall.stiffness * offset - wall.damping * v_lateral
    force -= wall.axial_friction * math.tanh(v_axial / wall.sliding_speed) * d
    return force, c, offset, along


def _apply(plant: _Plant, force: np.ndarray, at: np.ndarray) -> None:
    d = plant.data
    torque = np.cross(at - d.xipos[plant.instrument], force)
    d.xfrc_applied[plant.instrument, :3] = force
    d.xfrc_applied[plant.instrument, 3:] = torque


def _setup(robot, trajectory, q0, trocar, method):
    if isinstance(robot, _trocar.RunSetup):
        return robot
    return _trocar.RunSetup(robot, trajectory=trajectory, q0=q0, trocar=trocar, method=method)


def simulate(
    robot,
    scenario_or_trajectory=None,
    method=None,
    noise=DEFAULT_NOISE,
    latency=1,
    port=None,
    *,
    follow=None,
    drift_correction=True,
    duration=None,
    servo_time_constant=DEFAULT_SERVO_TIME_CONSTANT,
    armature=DEFAULT_ARMATURE,
    seed=0,
    q0=None,
    trocar=None,
    progress=None,
    frames=None,
):
    """Runs trocar's controller at 1 kHz on the MuJoCo plant of a robot and returns the run's
    columns (numpy arrays, ``t`` first) and, under ``"summary"``, its figures (:func:`summary`).

    ``robot``: a shipped Panda scenario's name (``"panda-laparoscope"``,
    ``"panda-laparoscope-limits"``), a :class:`trocar.Robot` or a description's path (run along
    its own trajectory, its ``[simulation]`` section completing what is not given), or a
    :class:`trocar.RunSetup`. ``scenario_or_trajectory``: a trajectory CSV for a robot.
    ``method``: ``"pinv"``, ``"dls"``, ``"fi"`` or ``"qp"`` (default: the run's). ``noise``: the
    encoder noise's standard deviation (rad; 0 for none). ``latency``: samples between a
    measurement and the command it produces taking effect (≥ 0; 1 by default). ``port``: the
    body wall (:class:`Wall`; ``None`` for the default wall, ``False`` for none).
    ``follow``: in a scenario whose port moves (``"panda-breathing"``, ``"panda-registration"``),
    how the controller knows it: ``"fixed"`` (where it was at the start), ``"known"`` (its
    trajectory fed forward) or ``"estimated"`` (the default: followed from the wall's lateral force
    on the shaft by :class:`trocar.PortFollower`, as the kinematic run follows it).
    ``drift_correction``: the controller's correction toward the trocar (``K_r``).
    ``duration``: seconds to run (default: the run's). ``servo_time_constant`` (s) and
    ``armature`` (kg m², the motors' reflected inertia added to every joint) shape the servo.
    ``frames``: when a list, the joint
    positions of every 20th step are appended to it (for pictures).

    Columns: ``t, ep_norm, eo_norm, rcm_drift, l_a, q1..qn`` (as measured), ``qd1..qdn`` (the
    commands sent), ``port_x, port_y, port_z`` (the port's true centre), ``estimate_x, estimate_y,
    estimate_z`` (where the controller holds it), ``port_force`` (N, the
    wall's lateral reaction on the shaft), ``port_offset`` (m, the shaft's axis from the port's
    true centre; ``rcm_drift`` is from the port held, the same where the port does not move),
    ``wrist_force`` (N, the wrist sensor's force),
    ``tau1..taun`` (N m, the servos' torques), ``status`` (1 where the step held the trocar, 0
    where it gave way within the limits).
    """
    mujoco = _mujoco()
    trajectory = scenario_or_trajectory
    setup = _setup(robot, trajectory, q0, trocar, method)
    if isinstance(robot, _trocar.RunSetup) and method is not None:
        raise ValueError("method: give it when the RunSetup is made")
    wall = Wall() if port is None else (None if port is False else port)
    if wall is not None:
        if not isinstance(wall, Wall):
            raise ValueError("port: a trocar.physics.Wall, None (the default wall) or False (none)")
        wall.check()
    if not (isinstance(latency, int) and 0 <= latency <= 1000):
        raise ValueError(f"latency: a whole number of samples in [0, 1000], not {latency!r}")
    if not (math.isfinite(noise) and 0.0 <= noise <= 0.1):
        raise ValueError(f"noise: a standard deviation in [0, 0.1] rad, not {noise!r}")
    if not (math.isfinite(servo_time_constant) and 1e-4 <= servo_time_constant <= 1.0):
        raise ValueError(
            f"servo_time_constant: in [1e-4, 1] s, not {servo_time_constant!r}"
        )
    total = setup.duration if duration is None else duration
    if not (math.isfinite(total) and 0.0 < total <= 3600.0):
        raise ValueError(f"duration: in (0, 3600] s, not {total!r}")
    bot = setup.robot
    options = dict(setup.controller)
    if not drift_correction:
        options["kr"] = 0.0
    ctrl = _trocar.Controller(bot, **options)
    if not (math.isfinite(armature) and 0.0 <= armature <= 100.0):
        raise ValueError(f"armature: in [0, 100] kg m², not {armature!r}")
    plant = _plant(bot, np.array(setup.q0, dtype=float), servo_time_constant, armature)
    model, data, n = plant.model, plant.data, plant.n
    port_centre = np.array(setup.trocar, dtype=float)
    moving = setup.port(0.0) is not None
    if follow is not None and not moving:
        raise ValueError(
            "follow: the port of this run does not move (panda-breathing and panda-registration have one that does)"
        )
    mode = (follow or "estimated") if moving else "fixed"
    if mode not in ("fixed", "known", "estimated"):
        raise ValueError(f'follow: "fixed", "known" or "estimated", not {follow!r}')
    follower = None
    if mode == "estimated":
        if wall is None:
            raise ValueError(
                'follow="estimated": the port is followed from the wall\'s force; there is no wall (port=False)'
            )
        time_constant, max_rate = setup.follower
        follower = _trocar.PortFollower(
            list(port_centre), 1.0 / (wall.stiffness * time_constant), max_rate, setup.wall_normal
        )

    def true_port(t):
        if not moving:
            return port_centre, np.zeros(3)
        position, velocity = setup.port(t)
        return np.array(position), np.array(velocity)

    substeps = round(CONTROL_PERIOD / model.opt.timestep)
    rng = np.random.default_rng(seed)
    steps = int(round(total / CONTROL_PERIOD))
    queue = [np.zeros(n)] * latency
    rows = []
    yielded = 0
    start = time.perf_counter()
    report = max(steps // 100, 1)
    force = np.zeros(3)
    # The measured motion's joint speeds and accelerations (the plant's, per control period).
    speed_peak = np.zeros(n)
    accel_peak = np.zeros(n)
    previous_velocity = data.qvel[:n].copy()
    for k in range(steps + 1):
        t = k * CONTROL_PERIOD
        q_true = data.qpos[:n].copy()
        q_meas = q_true + (rng.normal(0.0, noise, n) if noise > 0.0 else 0.0)
        port_now, port_rate = true_port(t)
        if mode == "known":
            held, held_rate = port_now, port_rate
        elif mode == "estimated":
            direction = _shaft_line(plant)[1]
            lateral = force - (force @ direction) * direction
            rate = follower.update(list(lateral), list(direction), CONTROL_PERIOD)
            held, held_rate = np.array(follower.estimate), np.array(rate)
        else:
            held, held_rate = port_centre, np.zeros(3)
        dv = ctrl.trocar_rate(q_meas, list(held_rate)) if mode != "fixed" else None
        out = ctrl.step(q_meas, setup.reference(t), list(held), CONTROL_PERIOD, dv=dv)
        if out["status"] != "Held":
            yielded += 1
        queue.append(np.array(out["qd"]))
        command = queue.pop(0)
        _, _, offset, along = _wall_force(plant, port_now, wall)
        held_offset = _wall_force(plant, held, None)[2]
        wrist = data.sensordata[plant.wrist_force : plant.wrist_force + 3]
        rows.append(
            [
                t,
                float(np.linalg.norm(out["position_error"])),
                float(np.linalg.norm(out["orientation_error"])),
                float(np.linalg.norm(held_offset)),
                along,
                *q_meas,
                *command,
                *port_now,
                *held,
                float(np.linalg.norm(force - (force @ _shaft_line(plant)[1]) * _shaft_line(plant)[1])),
                float(np.linalg.norm(offset)),
                float(np.linalg.norm(wrist)),
                *data.actuator_force[:n],
                1.0 if out["status"] == "Held" else 0.0,
            ]
        )
        if frames is not None and k % 20 == 0:
            frames.append(q_true)
        if k == steps:
            break
        data.ctrl[:n] = command
        for j in range(substeps):
            at_time = true_port(t + j * model.opt.timestep)
            force, at, _, _ = _wall_force(plant, at_time[0], wall, at_time[1])
            _apply(plant, force, at)
            mujoco.mj_step(model, data)
            if not np.all(np.isfinite(data.qpos)):
                raise RuntimeError(f"the plant diverged at t = {t:.3f} s (non-finite joint positions)")
        velocity = data.qvel[:n].copy()
        speed_peak = np.maximum(speed_peak, np.abs(velocity))
        accel_peak = np.maximum(accel_peak, np.abs(velocity - previous_velocity) / CONTROL_PERIOD)
        previous_velocity = velocity
        if progress is not None and k % report == 0:
            progress(k / steps)
    elapsed = time.perf_counter() - start
    names = (
        ["t", "ep_norm", "eo_norm", "rcm_drift", "l_a"]
        + [f"q{k + 1}" for k in range(n)]
        + [f"qd{k + 1}" for k in range(n)]
        + ["port_x", "port_y", "port_z", "estimate_x", "estimate_y", "estimate_z", "port_force", "port_offset", "wrist_force"]
        + [f"tau{k + 1}" for k in range(n)]
        + ["status"]
    )
    table = np.array(rows)
    columns = {name: table[:, j] for j, name in enumerate(names)}
    columns["summary"] = summary(
        columns,
        bot,
        simulated=total,
        elapsed=elapsed,
        yielded=yielded,
        kv=plant.kv,
        method=options["method"],
        measured=(speed_peak, accel_peak),
    )
    return columns


def summary(columns, robot, simulated, elapsed, yielded, kv, method, measured=None):
    """The figures of a run: drift (max, RMS), port force (peak, RMS), tip error (max, final),
    the limits (the largest excess over each of the commands, and of the plant's own motion
    where ``measured`` gives its peak joint speeds and accelerations: position, speed, and
    acceleration where the robot has acceleration limits; negative: the margin), the real-time
    factor (simulated time over the wall-clock time of the loop) and the servo gains."""
    n = robot.joints
    t = columns["t"]
    q = np.stack([columns[f"q{k + 1}"] for k in range(n)], axis=1)
    qd = np.stack([columns[f"qd{k + 1}"] for k in range(n)], axis=1)
    limits = robot.joint_limits
    position_excess = 0.0
    for k, (lo, hi) in enumerate(limits):
        if math.isfinite(lo):
            position_excess = max(position_excess, float(np.max(lo - q[:, k])))
        if math.isfinite(hi):
            position_excess = max(position_excess, float(np.max(q[:, k] - hi)))
    speed = robot.speed_limits
    accel = robot.acceleration_limits
    dt = t[1] - t[0] if len(t) > 1 else CONTROL_PERIOD
    command_accel = np.abs(np.diff(qd, axis=0)) / dt if len(t) > 1 else np.zeros((1, n))
    speed_excess = max(
        (float(np.max(np.abs(qd[:, k]) - s)) for k, s in enumerate(speed) if s is not None),
        default=float("-inf"),
    )
    accel_excess = max(
        (float(np.max(command_accel[:, k] - a)) for k, a in enumerate(accel) if a is not None),
        default=float("-inf"),
    )
    drift = columns["rcm_drift"]
    force = columns["port_force"]
    measured_speed_excess = measured_accel_excess = float("nan")
    if measured is not None:
        peak_speed, peak_accel = measured
        measured_speed_excess = max(
            (float(peak_speed[k] - v) for k, v in enumerate(speed) if v is not None),
            default=float("-inf"),
        )
        measured_accel_excess = max(
            (float(peak_accel[k] - a) for k, a in enumerate(accel) if a is not None),
            default=float("-inf"),
        )
    return {
        "measured_speed_excess": measured_speed_excess,
        "measured_acceleration_excess": measured_accel_excess,
        "method": method,
        "max_drift": float(np.max(drift)),
        "rms_drift": float(np.sqrt(np.mean(drift**2))),
        "peak_port_force": float(np.max(force)),
        "rms_port_force": float(np.sqrt(np.mean(force**2))),
        "max_tip_error": float(np.max(columns["ep_norm"])),
        "final_tip_error": float(columns["ep_norm"][-1]),
        "position_limit_excess": position_excess,
        "speed_limit_excess": speed_excess,
        "acceleration_limit_excess": accel_excess,
        "yielded_steps": int(yielded),
        "simulated_s": float(simulated),
        "elapsed_s": float(elapsed),
        "real_time_factor": float(simulated / elapsed) if elapsed > 0 else float("inf"),
        "servo_kv": [float(x) for x in kv],
    }


def _write_csv(path, columns):
    names = [k for k in columns if k != "summary"]
    table = np.stack([columns[k] for k in names], axis=1)
    directory = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=directory, prefix=".trocar-", suffix=".csv")
    try:
        with os.fdopen(fd, "w") as f:
            f.write(",".join(names) + "\n")
            for row in table:
                f.write(",".join(repr(float(x)) for x in row) + "\n")
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def figure(path, runs, title):
    """Writes the figure of one or several runs (``{label: columns}``): drift, port force, tip
    error and the largest joint rate over time. Drift and force are drawn from their first sample
    above 1e-4 of their largest: the shaft starts on the port exactly, and a logarithmic axis
    would otherwise reach down to the rounding of the first milliseconds."""

    def rise(c, key):
        values = np.asarray(c[key])
        above = np.nonzero(values >= 1e-4 * np.max(values))[0]
        return int(above[0]) if above.size else 0

    panels = [
        ("distance port centre - shaft axis (rcm_drift)", "drift (mm)", "rcm_drift", 1e3),
        ("the wall's lateral force on the shaft (port_force)", "force (N)", "port_force", 1.0),
        ("tip position error |dp - p|", "error (mm)", "ep_norm", 1e3),
    ]
    spec = []
    for panel_title, label, key, scale in panels:
        spec.append(
            {
                "title": panel_title,
                "y_label": label,
                "non_negative": True,
                "lines": [
                    (name, list(c["t"][start:]), list(c[key][start:] * scale))
                    for name, c in runs.items()
                    for start in [rise(c, key) if key != "ep_norm" else 0]
                ],
            }
        )
    lines = []
    for name, c in runs.items():
        n = sum(1 for k in c if k.startswith("qd"))
        peak = np.max(np.abs(np.stack([c[f"qd{k + 1}"] for k in range(n)], axis=1)), axis=1)
        lines.append((name, list(c["t"]), list(peak)))
    spec.append(
        {
            "title": "largest joint rate commanded max_k |qd_k|",
            "y_label": "rate (rad/s)",
            "non_negative": True,
            "lines": lines,
        }
    )
    _trocar.write_figure(str(path), title, spec)


def _animate(path, robot, frames, port):
    """An animated GIF of the arm (MuJoCo's renderer, off screen)."""
    mujoco = _mujoco()
    model = mujoco.MjModel.from_xml_string(robot.mjcf())
    model.site_pos[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "port")] = port
    data = mujoco.MjData(model)
    try:
        renderer = mujoco.Renderer(model, 480, 640)
    except Exception as e:  # no OpenGL context on this machine
        raise RuntimeError(
            f"--animate: MuJoCo cannot render off screen here ({e}); set MUJOCO_GL=egl or osmesa where available"
        ) from e
    images = []
    camera = mujoco.MjvCamera()
    camera.lookat[:] = [0.5 * port[0], 0.5 * port[1], 0.5 * port[2] + 0.15]
    camera.distance = 1.8
    camera.azimuth = 135
    camera.elevation = -20
    for q in frames[:: max(len(frames) // 100, 1)]:
        data.qpos[: len(q)] = q
        mujoco.mj_forward(model, data)
        renderer.update_scene(data, camera)
        images.append(renderer.render().copy())
    _write_gif(path, images)


def _write_gif(path, images):
    try:
        from PIL import Image  # noqa: PLC0415
    except ImportError as e:
        raise RuntimeError("--animate: writing a GIF needs Pillow (pip install pillow)") from e
    first, *rest = [Image.fromarray(im) for im in images]
    first.save(path, save_all=True, append_images=rest, duration=60, loop=0)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m trocar.physics",
        description="Run trocar's constrained controller at 1 kHz on a MuJoCo plant of the robot "
        "(inertia, gravity, velocity servos with torque limits, encoder noise, latency, the body "
        "wall at the port). ROBOT is a shipped Panda scenario (panda-laparoscope, "
        "panda-laparoscope-limits, panda-breathing, panda-registration) or a description with a "
        "[simulation] section.",
    )
    parser.add_argument("robot", metavar="ROBOT|SCENARIO")
    parser.add_argument("--trajectory", help="a trajectory CSV (t,x,y,z and roll or qw,qx,qy,qz)")
    parser.add_argument("--method", choices=["pinv", "dls", "fi", "qp"])
    parser.add_argument("--noise", type=float, default=DEFAULT_NOISE, help="encoder noise, rad (default 1e-5; 0: none)")
    parser.add_argument("--latency", type=int, default=1, help="command latency in samples (default 1)")
    parser.add_argument("--no-wall", action="store_true", help="no body wall at the port")
    parser.add_argument("--wall-stiffness", type=float, default=Wall.stiffness, help="N/m (default 4000)")
    parser.add_argument("--wall-damping", type=float, default=Wall.damping, help="N s/m (default 40)")
    parser.add_argument(
        "--follow",
        choices=["fixed", "known", "estimated"],
        help="a moving port (panda-breathing, panda-registration): held where it was, its "
        "trajectory fed forward, or followed from the wall's force (the default)",
    )
    parser.add_argument("--drift-correction", choices=["on", "off"], default="on")
    parser.add_argument("--duration", type=float, help="seconds (default: the run's)")
    parser.add_argument("--servo-time-constant", type=float, default=DEFAULT_SERVO_TIME_CONSTANT)
    parser.add_argument("--armature", type=float, default=DEFAULT_ARMATURE, help="motor inertia per joint, kg m² (default 0.1)")
    parser.add_argument("--seed", type=int, default=0, help="of the encoder noise")
    parser.add_argument("--csv", help="write the columns to this CSV file")
    parser.add_argument("--plot", help="write the figure (.png or .svg)")
    parser.add_argument("--animate", help="write an animated GIF of the arm (needs an OpenGL context)")
    parser.add_argument("--quiet", action="store_true", help="no progress")
    args = parser.parse_args(argv)
    if args.animate and "mujoco" not in sys.modules:
        # MuJoCo picks its OpenGL platform when first imported: EGL renders without a display.
        os.environ.setdefault("MUJOCO_GL", "egl")
    wall = False if args.no_wall else Wall(stiffness=args.wall_stiffness, damping=args.wall_damping)
    frames = [] if args.animate else None

    def progress(fraction):
        if not args.quiet:
            print(f"\r{100 * fraction:5.1f} %", end="", file=sys.stderr, flush=True)

    try:
        columns = simulate(
            args.robot,
            args.trajectory,
            method=args.method,
            noise=args.noise,
            latency=args.latency,
            port=wall,
            follow=args.follow,
            drift_correction=args.drift_correction == "on",
            duration=args.duration,
            servo_time_constant=args.servo_time_constant,
            armature=args.armature,
            seed=args.seed,
            progress=progress,
            frames=frames,
        )
        if not args.quiet:
            print("\r", end="", file=sys.stderr)
        s = columns["summary"]
        if args.csv:
            _write_csv(args.csv, columns)
        if args.plot:
            figure(args.plot, {s["method"]: columns}, f"{args.robot} on a MuJoCo plant")
        if args.animate:
            _animate(args.animate, _setup(args.robot, args.trajectory, None, None, None).robot, frames, [columns["port_x"][0], columns["port_y"][0], columns["port_z"][0]])
    except (ValueError, RuntimeError, ImportError, OSError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    print(
        f"{args.robot}, {s['method']}, noise {args.noise:g} rad, latency {args.latency}: "
        f"drift max {s['max_drift']:.3e} m rms {s['rms_drift']:.3e} m; "
        f"port force peak {s['peak_port_force']:.3f} N rms {s['rms_port_force']:.3f} N; "
        f"tip error max {s['max_tip_error']:.3e} m final {s['final_tip_error']:.3e} m; "
        f"limit excess: position {s['position_limit_excess']:.2e} rad, speed {s['speed_limit_excess']:.2e} rad/s, "
        f"acceleration {s['acceleration_limit_excess']:.2e} rad/s² (commands), "
        f"speed {s['measured_speed_excess']:.2e} rad/s and acceleration "
        f"{s['measured_acceleration_excess']:.2e} rad/s² (the plant's motion); "
        f"real-time factor {s['real_time_factor']:.1f}"
    )
    if s["yielded_steps"]:
        print(f"error: the trocar gave way in {s['yielded_steps']} steps", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
