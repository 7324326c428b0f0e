"""Tests of the Python package against the command line, numpy finite differences and numpy's
own linear algebra (never against itself)."""

import json
import os
import pathlib
import shutil
import subprocess

import numpy as np
import pytest

import trocar

ROOT = pathlib.Path(__file__).resolve().parents[3]
Q8 = [0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3]


def trocar_binary():
    """The `trocar` command line: $TROCAR_BIN, or the workspace's build."""
    for candidate in (os.environ.get("TROCAR_BIN"), ROOT / "target" / "debug" / "trocar",
                      ROOT / "target" / "release" / "trocar", shutil.which("trocar")):
        if candidate and pathlib.Path(candidate).is_file():
            return str(candidate)
    return None


def cli(*args):
    binary = trocar_binary()
    if binary is None:
        pytest.skip("the trocar command line is not built (cargo build -p trocar-cli)")
    return subprocess.run([binary, *args], capture_output=True, text=True)


def q_arg(q):
    return "--q=" + ",".join(repr(float(x)) for x in q)


@pytest.mark.parametrize("what", ["jr", "manip", "jc", "jb0i", "jb0e", "fk"])
def test_eval_is_the_command_lines_answer(what):
    robot = trocar.Robot.load("bidirectional-zy")
    out = cli("eval", "bidirectional-zy", q_arg(Q8), "--what", what, "--json")
    assert out.returncode == 0, out.stderr
    expected = np.array(json.loads(out.stdout)["data"])
    got = robot.eval(Q8, what=what)
    assert isinstance(got, np.ndarray) and got.dtype == np.float64
    assert got.shape == expected.shape
    np.testing.assert_array_equal(got, expected)


def test_numeric_and_parameters_as_the_command_line():
    robot = trocar.Robot.load("bidirectional-zy")
    out = cli("eval", "bidirectional-zy", q_arg(Q8), "--what", "jr", "--numeric",
              "--param", "l_a=0.2", "--json")
    assert out.returncode == 0, out.stderr
    got = robot.eval(np.array(Q8), what="jr", params={"l_a": 0.2}, numeric=True)
    np.testing.assert_array_equal(got, np.array(json.loads(out.stdout)["data"]))
    # The parameter matters, and the generated closed form agrees with the numeric runtime.
    assert not np.allclose(got, robot.eval(Q8, what="jr", numeric=True))
    np.testing.assert_allclose(robot.eval(Q8, what="jr", params={"l_a": 0.2}), got, atol=1e-12)


def twist_of(g, dg):
    """(v, ω) of the body velocity g⁻¹ ġ (a 4 × 4 matrix [ω̂ v; 0 0])."""
    xi = np.linalg.solve(g, dg)
    return np.array([xi[0, 3], xi[1, 3], xi[2, 3], xi[2, 1], xi[0, 2], xi[1, 0]])


@pytest.mark.parametrize("name", ["bidirectional-zy", "dia10_like_zx", "panda-laparoscope"])
def test_body_jacobian_matches_numpy_finite_differences_of_fk(name):
    robot = trocar.Robot.load(name)
    rng = np.random.default_rng(7)
    h = 1e-6
    for _ in range(5):
        q = rng.uniform(-1.5, 1.5, robot.joints)
        g = robot.eval(q, what="fk")
        jb = robot.eval(q, what="jb0e")
        assert jb.shape == (6, robot.joints)
        for k in range(robot.joints):
            dq = np.zeros(robot.joints)
            dq[k] = h
            dg = (robot.eval(q + dq, what="fk") - robot.eval(q - dq, what="fk")) / (2 * h)
            np.testing.assert_allclose(jb[:, k], twist_of(g, dg), atol=1e-7)


def test_manipulability_is_numpys_determinant():
    robot = trocar.Robot.load("bidirectional-zy")
    rng = np.random.default_rng(3)
    for _ in range(20):
        q = rng.uniform(-2, 2, 8)
        jr = robot.eval(q, what="jr")
        w = robot.eval(q, what="manip")
        assert w.shape == (1, 1)
        assert w[0, 0] == pytest.approx(abs(np.linalg.det(jr)), rel=1e-10, abs=1e-12)


def test_a_task_robot_manipulability_is_that_of_the_task_jacobian():
    robot = trocar.Robot.load("panda-laparoscope")
    q = [0.1, -0.4, 0.2, -2.0, 0.1, 1.8, 0.7]
    task = robot.eval(q, what="task")
    w = robot.eval(q, what="manip")[0, 0]
    assert w == pytest.approx(np.sqrt(np.linalg.det(task @ task.T)), rel=1e-9)


def test_errors_are_value_errors_with_the_command_lines_message():
    """The command line's message, with the arguments named as Python's keywords (`q` for
    `--q`)."""
    robot = trocar.Robot.load("bidirectional-zy")
    out = cli("eval", "bidirectional-zy", "--q=0,1", "--what", "jr")
    with pytest.raises(ValueError) as e:
        robot.eval([0, 1], what="jr")
    assert out.returncode == 1
    assert out.stderr.strip() == f"error: --{e.value}"
    with pytest.raises(ValueError, match="unknown parameter `l_x`"):
        robot.eval(Q8, params={"l_x": 1.0})
    with pytest.raises(ValueError, match="not a quantity of the robot .* jr \\(constrained_jacobian\\)"):
        robot.eval(Q8, what="jacobian")
    with pytest.raises(ValueError, match="cannot read the file"):
        trocar.Robot.load("no-such-robot")


def test_a_description_file_error_names_the_line(tmp_path):
    text = trocar.Robot.load("unidirectional").generate  # a method: the robot loads
    assert callable(text)
    out = cli("preset", "unidirectional")
    assert out.returncode == 0
    bad = out.stdout.replace('type = "revolute"', 'type = "revolut"', 1)
    path = tmp_path / "bad.toml"
    path.write_text(bad)
    line = 1 + bad[: bad.index('"revolut"')].count("\n")
    with pytest.raises(ValueError) as e:
        trocar.Robot.load(path)
    assert f"bad.toml:{line}" in str(e.value)


def test_a_file_robot_loads_after_a_chdir(tmp_path, monkeypatch):
    out = cli("preset", "bidirectional-zx")
    path = tmp_path / "arm.toml"
    path.write_text(out.stdout)
    monkeypatch.chdir(tmp_path)
    robot = trocar.Robot.load("arm.toml")
    monkeypatch.chdir(ROOT)
    np.testing.assert_array_equal(
        robot.eval(Q8), trocar.Robot.load("bidirectional-zx").eval(Q8))


def test_verify_returns_the_table():
    report = trocar.Robot.load("dia10_like_zy").verify(samples=50, seed=3)
    assert report["passed"] is True and report["samples"] == 50
    jr = report["checks"]["jr: generated vs numeric"]
    assert jr["passed"] and jr["max_error"] < jr["tolerance"] == 1e-12
    assert jr["worst_q"].shape == (8,)
    assert any("finite differences" in name for name in report["checks"])


def test_generate_is_the_command_lines_module():
    out = cli("generate", "unidirectional", "--real", "f32")
    assert out.returncode == 0
    assert trocar.Robot.load("unidirectional").generate(real="f32") == out.stdout
    with pytest.raises(ValueError, match="expected"):
        trocar.Robot.load("unidirectional").generate(real="f16")


def test_simulate_returns_columns():
    trace = trocar.simulate("four-bar")
    assert list(trace)[0] == "t"
    t = trace["t"]
    assert t.ndim == 1 and len(t) > 100 and np.all(np.diff(t) > 0)
    assert all(len(v) == len(t) for v in trace.values())


def test_an_rcm_scenario_keeps_the_trocar():
    trace = trocar.simulate("4", method="dls")
    assert {"t", "rcm_drift", "w_r", "q8", "qd8"} <= set(trace)
    assert np.max(trace["rcm_drift"]) < 1e-4
    assert trace["t"][-1] == pytest.approx(200.0, abs=0.01)
    with pytest.raises(ValueError, match="method"):
        trocar.simulate("4", method="newton")
    with pytest.raises(ValueError, match="unknown scenario"):
        trocar.simulate("5")


def test_shipped_names_load():
    s = trocar.shipped()
    assert "bidirectional-zy" in s["robots"] and "four-bar" in s["mechanisms"]
    for name in s["robots"] + s["mechanisms"]:
        robot = trocar.Robot.load(name)
        assert robot.joints > 0
    assert trocar.Robot.load("four-bar").is_mechanism
    names = dict(trocar.quantities())
    assert names["constrained_jacobian"] == "jr" and names["passive_map"] == "passive"


PANDA_Q = np.array([0.1, -0.4, 0.2, -2.0, 0.1, 1.8, 0.7])


@pytest.mark.parametrize("short,name", [("jr", "constrained_jacobian"),
                                        ("jb0i", "partial_body_jacobian"),
                                        ("fk", "forward_kinematics"),
                                        ("jc", "constraint_jacobian_c"),
                                        ("task", "constrained_task_jacobian")])
def test_catalogue_names_and_short_names_are_one_quantity(short, name):
    robot = trocar.Robot.load("panda-laparoscope")
    np.testing.assert_array_equal(robot.eval(PANDA_Q, what=short), robot.eval(PANDA_Q, what=name))
    assert name in robot.quantities()


@pytest.mark.parametrize("what", ["fk", "jb0i", "jr", "task", "jc", "manip", "fk0i",
                                  "lambda_null_space"])
def test_eval_many_is_eval_at_every_row(what):
    robot = trocar.Robot.load("panda-laparoscope")
    rng = np.random.default_rng(11)
    lo, hi = np.array(robot.joint_limits).T
    # 1031 configurations: several lane groups on each core, and a partial last group.
    qs = rng.uniform(lo, hi, size=(1031, robot.joints))
    many = robot.eval_many(qs, what=what)
    assert many.shape[0] == len(qs)
    for k in [0, 1, 7, 8, 500, 1029, 1030]:
        np.testing.assert_array_equal(many[k], robot.eval(qs[k], what=what))
    # A non-contiguous array and other parameter values.
    strided = np.asfortranarray(qs[:20])
    np.testing.assert_array_equal(robot.eval_many(strided, what=what, params={"l_a": 0.2}),
                                  np.stack([robot.eval(q, what=what, params={"l_a": 0.2})
                                            for q in qs[:20]]))
    with pytest.raises(ValueError, match="columns"):
        robot.eval_many(qs[:, :3], what=what)
    bad = qs[:10].copy()
    bad[3, 2] = np.nan
    with pytest.raises(ValueError, match="configuration 3"):
        robot.eval_many(bad, what=what)


@pytest.mark.parametrize("what", [("fk0i", "jb0i"), ["jb0i", "fk", "jr", "manip"],
                                  ("forward_kinematics", "body_jacobian")])
def test_several_quantities_in_one_program(what):
    robot = trocar.Robot.load("panda-laparoscope")
    rng = np.random.default_rng(5)
    lo, hi = np.array(robot.joint_limits).T
    qs = rng.uniform(lo, hi, size=(600, robot.joints))
    for q in qs[:25]:
        got = robot.eval(q, what=what)
        assert isinstance(got, tuple) and len(got) == len(what)
        for name, value in zip(what, got):
            # Each as its own function gives it (another program: equal to rounding), and as
            # the numeric runtime does (it has no g_0i).
            alone = robot.eval(q, what=name)
            assert value.shape == alone.shape and value.flags["C_CONTIGUOUS"]
            np.testing.assert_allclose(value, alone, rtol=0, atol=1e-14)
            if name != "fk0i":
                np.testing.assert_allclose(value, robot.eval(q, what=name, numeric=True),
                                           rtol=0, atol=1e-12)
    # Many configurations (on both cores from 512): each row is that configuration's tuple.
    many = robot.eval_many(qs, what=what)
    assert isinstance(many, tuple) and len(many) == len(what)
    for k in [0, 9, 300, 599]:
        for value, one in zip(many, robot.eval(qs[k], what=what)):
            np.testing.assert_array_equal(value[k], one)
    # The numeric runtime and a mechanism give tuples too, each its own function's value.
    numeric = robot.eval(qs[0], what=("fk", "jb0i"), numeric=True)
    np.testing.assert_array_equal(numeric[1], robot.eval(qs[0], what="jb0i", numeric=True))
    four_bar = trocar.Robot.load("four-bar")
    qm = [0.5, 1.0, 0.3][:four_bar.joints] + [0.2] * max(0, four_bar.joints - 3)
    pair = four_bar.eval(qm, what=["jr", "det"])
    np.testing.assert_array_equal(pair[0], four_bar.eval(qm, what="jr"))
    np.testing.assert_array_equal(pair[1], four_bar.eval(qm, what="det"))
    qms = np.array([qm, [x + 0.01 for x in qm]])
    many_pair = four_bar.eval_many(qms, what=["jc", "ja"])
    for k in range(2):
        np.testing.assert_array_equal(many_pair[0][k], four_bar.eval(qms[k], what="jc"))
        np.testing.assert_array_equal(many_pair[1][k], four_bar.eval(qms[k], what="ja"))


def test_several_quantities_are_checked():
    robot = trocar.Robot.load("panda-laparoscope")
    with pytest.raises(ValueError, match="no quantity asked for"):
        robot.eval(PANDA_Q, what=())
    with pytest.raises(ValueError, match="`fk` asked for twice"):
        robot.eval(PANDA_Q, what=("fk", "forward_kinematics"))
    with pytest.raises(ValueError, match="not a quantity"):
        robot.eval(PANDA_Q, what=("fk", "nope"))
    with pytest.raises(TypeError, match="tuple or list of names"):
        robot.eval(PANDA_Q, what=("fk", 3))
    with pytest.raises(TypeError, match="tuple or list of names"):
        robot.eval_many(np.zeros((2, 7)), what=3)
    bad = np.zeros((4, 7))
    bad[2, 6] = np.inf
    with pytest.raises(ValueError, match="configuration 2"):
        robot.eval_many(bad, what=("fk", "jb0i"))


def test_shapes_names_labels_and_limits():
    robot = trocar.Robot.load("panda-laparoscope")
    assert robot.joint_names == [f"panda_joint{k}" for k in range(1, 8)]
    limits = np.array(robot.joint_limits)
    assert limits.shape == (7, 2) and np.all(limits[:, 0] < limits[:, 1])
    assert limits[3, 1] == pytest.approx(-0.0698)
    rows, cols = robot.labels("jb0i")
    assert rows == ["v_x", "v_y", "v_z", "w_x", "w_y", "w_z"]
    assert cols == [f"dq_panda_joint{k}" for k in range(1, 8)]
    assert robot.eval(PANDA_Q, what="jb0i").shape == (len(rows), len(cols))
    rows, cols = robot.labels("task")
    assert rows == ["v_x", "v_y", "v_z", "w_z"]
    assert robot.labels("fk") is None


def test_controller_step_is_the_rust_controllers_step():
    """Controller.step, replayed at the states of the Rust simulation of the Panda laparoscope
    scenario (DLS, drift correction, joint-limit objective), gives the joint rates the Rust
    controller gave there."""
    robot = trocar.Robot.load("panda-laparoscope")
    trace = trocar.simulate("panda-laparoscope", method="dls")
    q0 = np.array([trace[f"q{k}"][0] for k in range(1, 8)])
    # The trocar: the constraint frame's origin at q0, g_0i(q0) g_ir, from the closed forms.
    g0i = robot.eval(q0, what="fk0i")
    gir = robot.eval(q0, what="constraint_frame")
    trocar_point = (g0i @ gir)[:3, 3]
    ctrl = trocar.Controller(robot, method="dls")
    rates = lambda k: np.array([trace[f"qd{j}"][k] if k >= 0 else 0.0 for j in range(1, 8)])
    for k in [0, 1, 250, 2500, 7000, len(trace["t"]) - 1]:
        q = np.array([trace[f"q{j}"][k] for j in range(1, 8)])
        want = rates(k)
        # The acceleration and jerk limits are measured from the rows before.
        ctrl.set_previous_rates(rates(k - 1), (rates(k - 1) - rates(k - 2)) / 0.002)
        out = ctrl.step(q, trocar.panda_reference(trace["t"][k]), trocar_point, 0.002)
        np.testing.assert_allclose(out["qd"], want, rtol=1e-9, atol=1e-12)
        assert out["l_a"] == pytest.approx(trace["l_a"][k], abs=1e-12)
        assert out["w_r"] == pytest.approx(trace["w_r"][k], rel=1e-9)
    with pytest.raises(ValueError, match=r"rates: 6 values given, the robot has 7 joints"):
        ctrl.set_previous_rates(np.zeros(6))
    with pytest.raises(ValueError, match=r"acceleration\[2\] = NaN: must be finite"):
        ctrl.set_previous_rates(np.zeros(7), [0, 0, np.nan, 0, 0, 0, 0])
    with pytest.raises(ValueError, match="method"):
        trocar.Controller(robot, method="newton")
    with pytest.raises(ValueError, match="7 joints"):
        ctrl.step(q0[:3], [0.0, 0.0, 0.0], trocar_point, 0.002)
    with pytest.raises(ValueError, match="closed mechanism"):
        trocar.Controller(trocar.Robot.load("four-bar"))


def test_a_python_control_loop_keeps_the_trocar():
    """docs/python.md's loop: the tip moves 2 cm sideways while the shaft stays in the trocar."""
    robot = trocar.Robot.load("panda-laparoscope")
    q = np.array([0.0, -np.pi / 4, 0.0, -3 * np.pi / 4, 0.0, np.pi / 2, np.pi / 4])
    g0i = robot.eval(q, what="fk0i")
    trocar_point = (g0i @ robot.eval(q, what="constraint_frame"))[:3, 3]
    start = robot.eval(q, what="fk")[:3, 3]
    goal = start + np.array([0.02, 0.0, 0.0])
    ctrl = trocar.Controller(robot, method="dls")
    dt = 0.002
    for _ in range(1500):
        out = ctrl.step(q, {"position": goal}, trocar_point, dt)
        q = q + dt * out["qd"]
    assert np.linalg.norm(robot.eval(q, what="fk")[:3, 3] - goal) < 1e-4
    assert np.max(np.abs(out["lateral_error"])) < 1e-6


def test_the_readmes_python_example_runs():
    """The Python example of docs/python.md, as written there."""
    text = (ROOT / "docs" / "python.md").read_text()
    block = text.split("```python\n", 1)[1].split("```", 1)[0]
    scope = {}
    exec(compile(block, "docs/python.md", "exec"), scope)
    robot, q, goal = scope["robot"], scope["q"], scope["goal"]
    assert np.linalg.norm(robot.eval(q, what="fk")[:3, 3] - goal) < 1e-4
    assert np.max(np.abs(scope["out"]["lateral_error"])) < 1e-6
    assert scope["poses"].shape == (10_000, 4, 4)


def test_simulate_a_users_trajectory_as_the_command_line(tmp_path):
    """trocar.simulate(robot, trajectory=...) returns the command line's columns for the same
    robot, path and start."""
    robot = trocar.Robot.load("panda-laparoscope")
    q0 = np.array([0.0, -np.pi / 4, 0.0, -3 * np.pi / 4, 0.0, np.pi / 2, np.pi / 4])
    tip = robot.eval(q0, what="fk")[:3, 3]
    t = np.linspace(0.0, 2.0, 41)
    a = 2 * np.pi * t / 2.0
    path = tmp_path / "circle.csv"
    rows = ["t,x,y,z,roll"] + [
        f"{float(ti)!r},{float(tip[0] + 0.005 * (np.cos(ai) - 1))!r},"
        f"{float(tip[1] + 0.005 * np.sin(ai))!r},{float(tip[2])!r},0"
        for ti, ai in zip(t, a)]
    path.write_text("\n".join(rows) + "\n")
    trace = trocar.simulate(robot, trajectory=path, q0=q0)
    assert list(trace)[:6] == ["t", "ep_norm", "eo_norm", "vr_x", "vr_y", "rcm_drift"]
    assert np.max(trace["rcm_drift"]) < 1e-4
    out = tmp_path / "cli.csv"
    res = cli("simulate", "panda-laparoscope", "--trajectory", str(path),
              "--q0=" + ",".join(repr(float(x)) for x in q0), "--csv", str(out))
    assert res.returncode == 0, res.stderr
    data = np.genfromtxt(out, delimiter=",", names=True)
    np.testing.assert_allclose(data["rcm_drift"], trace["rcm_drift"], rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(data["q7"], trace["q7"], rtol=1e-12, atol=1e-15)
    with pytest.raises(ValueError, match="q0"):
        trocar.simulate(robot, trajectory=path)
    bad = tmp_path / "bad.csv"
    bad.write_text("t,x,y,z,roll\n0,0,0,0,0\n")
    with pytest.raises(ValueError, match="bad.csv:2: column `t`: 1 row;"):
        trocar.simulate("panda-laparoscope", trajectory=bad, q0=q0)


def test_the_ur5_example_follows_its_circle_as_the_command_line(tmp_path):
    """The UR5 example (a user's description: chain from its URDF, a 0.35 m shaft through a
    trocar on the last link) along its 10 s circle from Python: by its own [simulation] section
    and by the keywords, the trocar held within 0.1 mm, the tip within 1 mm after 2 s, every
    joint inside its URDF range (read here from the URDF), the same columns as the command line,
    which also writes the animation."""
    import xml.etree.ElementTree as ET

    desc = ROOT / "examples" / "robots" / "ur5_trocar.toml"
    circle = ROOT / "examples" / "trajectories" / "ur5-circle.csv"
    q0 = [0.0, -np.pi / 2, np.pi / 2, -np.pi / 2, -np.pi / 2, 0.0]
    own = trocar.simulate(str(desc))
    trace = trocar.simulate(str(desc), trajectory=circle, q0=q0, method="dls")
    np.testing.assert_allclose(trace["q4"], own["q4"], rtol=0, atol=1e-12)
    assert trace["t"][-1] == pytest.approx(10.0, abs=1e-9)
    assert np.max(trace["rcm_drift"]) <= 1e-4
    assert np.max(trace["ep_norm"][trace["t"] >= 2.0]) <= 1e-3
    urdf = ET.parse(ROOT / "examples" / "robots" / "urdf" / "ur5.urdf").getroot()
    limits = [(float(j.find("limit").get("lower")), float(j.find("limit").get("upper")))
              for j in urdf.iter("joint") if j.get("type") != "fixed"]
    assert len(limits) == 6
    for k, (lo, hi) in enumerate(limits, start=1):
        assert np.all(trace[f"q{k}"] >= lo) and np.all(trace[f"q{k}"] <= hi), f"q{k}"
    out, gif = tmp_path / "run.csv", tmp_path / "run.gif"
    res = cli("simulate", str(desc), "--trajectory", str(circle),
              "--q0=" + ",".join(repr(float(x)) for x in q0), "--csv", str(out),
              "--animate", str(gif))
    assert res.returncode == 0, res.stderr
    data = np.genfromtxt(out, delimiter=",", names=True)
    np.testing.assert_allclose(data["rcm_drift"], trace["rcm_drift"], rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(data["q6"], trace["q6"], rtol=1e-12, atol=1e-15)
    assert gif.read_bytes()[:6] == b"GIF89a"
    with pytest.raises(ValueError, match=r"^q0: 2 values given, `ur5_trocar` has 6 joints"):
        trocar.simulate(str(desc), q0=[0.0, 0.0])


def test_the_qp_controller_stops_at_the_depth_limit():
    """method="qp": asked to pull the tip 5 cm back along the shaft (l_a from 0.25 m to 0.30 m),
    the QP stops l_a at its bound l_max = 0.28 m while the DLS controller, which has no such
    bound, goes past it; both keep the trocar within 10 µm. l_a is computed here from the closed-form
    poses (the trocar's offset along the shaft from the flange), not taken from the step."""
    robot = trocar.Robot.load("panda-laparoscope")
    q0 = np.array([0.0, -np.pi / 4, 0.0, -3 * np.pi / 4, 0.0, np.pi / 2, np.pi / 4])
    g0i = robot.eval(q0, what="fk0i")
    trocar_point = (g0i @ robot.eval(q0, what="constraint_frame"))[:3, 3]
    fk = robot.eval(q0, what="fk")
    goal = {"position": fk[:3, 3] - 0.05 * fk[:3, 2], "rotation": fk[:3, :3]}
    shaft_origin = (g0i @ robot.eval(q0, what="constraint_frame"))[:3, 3] - 0.25 * g0i[:3, 2]
    offset = float(np.dot(shaft_origin - g0i[:3, 3], g0i[:3, 2]))  # the flange along z_i
    reached = {}
    for method in ["dls", "qp"]:
        ctrl = trocar.Controller(robot, method=method, depth_limits=(0.05, 0.28))
        q, top, lateral, resolved = q0.copy(), 0.0, 0.0, 0
        for _ in range(1500):
            out = ctrl.step(q, goal, trocar_point, 0.002)
            q = q + 0.002 * out["qd"]
            resolved += bool(out["qp_resolved"])
            g = robot.eval(q, what="fk0i")
            top = max(top, float(np.dot(trocar_point - g[:3, 3], g[:3, 2])) - offset)
            lateral = max(lateral, float(np.max(np.abs(out["lateral_error"]))))
        reached[method] = top
        assert lateral < 1e-5, (method, lateral)
        if method == "qp":
            assert out["qp_status"] == "Optimal"
            assert out["qp_active"] >= 1
            # The depth limit is met once, and the step after solves again (Q9): rarely.
            assert 1 <= resolved <= 10, resolved
        else:
            assert out["qp_status"] is None
            assert out["qp_resolved"] is None
    assert reached["dls"] > 0.29
    assert reached["qp"] <= 0.28


def test_simulate_the_limits_scenario_with_the_qp():
    """simulate("panda-laparoscope-limits"): the QP keeps l_a within [0.05, 0.30] m and every
    joint within the limits Robot.joint_limits reports; DLS goes past l_max."""
    limits = trocar.Robot.load("panda-laparoscope").joint_limits
    qp = trocar.simulate("panda-laparoscope-limits", method="qp")
    dls = trocar.simulate("panda-laparoscope-limits", method="dls")
    assert qp["l_a"].max() <= 0.30 and qp["l_a"].min() >= 0.05
    assert dls["l_a"].max() > 0.30
    for k, (lo, hi) in enumerate(limits, start=1):
        assert lo <= qp[f"q{k}"].min() and qp[f"q{k}"].max() <= hi


def test_the_three_ports_scene_keeps_the_shafts_apart():
    """trocar.simulate("three-ports"): two instruments and an endoscope, each through its own
    port; the columns of the command line's CSV, the shafts 10 mm apart at every row, every port
    held; a method other than the QP is refused."""
    trace = trocar.simulate("three-ports")
    assert "min_shaft_distance" in trace and "q21" in trace and "endoscope.rcm_drift" in trace
    assert np.min(trace["min_shaft_distance"]) >= 0.010 * (1 - 1e-6)
    for arm in ["left", "right", "endoscope"]:
        assert np.max(trace[f"{arm}.rcm_drift"]) <= 1e-4
    with pytest.raises(ValueError, match="is a scene of several arms"):
        trocar.simulate("three-ports", method="dls")


def test_a_scene_stepped_in_a_loop_of_ones_own_gives_the_shipped_run():
    """trocar.Scene("three-ports") stepped with Euler at its dt gives the joints of
    trocar.simulate's run row by row; its distances keep the safety distance; bad input is
    refused with the argument named."""
    trace = trocar.simulate("three-ports")
    scene = trocar.Scene("three-ports")
    assert scene.arms == ["left", "right", "endoscope"] and scene.joints == 21
    assert len(scene.couplings) == 3 and len(scene.ports) == 3
    q = scene.q0.copy()
    columns = [f"q{k + 1}" for k in range(21)]
    least = np.inf
    acted = False
    for row in range(len(trace["t"]) - 1):
        expected = np.array([trace[c][row] for c in columns])
        assert np.array_equal(q, expected), row
        out = scene.step(q, row * scene.dt)
        assert out["coupling_held"] and out["statuses"] == ["Held"] * 3
        least = min(least, np.min(out["distances"]))
        acted = acted or out["coupling_active"]
        q = q + out["qd"] * scene.dt
    # The whole run: the couplings acted, and the distances kept the safety distance.
    assert acted and least >= scene.safety * (1 - 1e-6)
    with pytest.raises(ValueError, match="q: 20 values given"):
        scene.step(q[:20], 0.0)
    with pytest.raises(ValueError, match="is not a scene that can be stepped"):
        trocar.Scene("four-bar")
    dual = trocar.Scene("dia10-dual")
    assert dual.arms == ["left", "right"] and dual.joints == 15 and len(dual.q0) == 15
    scene.reset()
    assert np.array_equal(scene.step(scene.q0, 0.0)["qd"], trocar.Scene("three-ports").step(scene.q0, 0.0)["qd"])


def test_register_port_is_the_command_lines_answer():
    path = ROOT / "examples" / "ports" / "panda-laparoscope-pivot.csv"
    rows = [line for line in path.read_text().splitlines() if line and not line.startswith("#")]
    joints = [[float(v) for v in line.split(",")] for line in rows[1:]]
    robot = trocar.Robot.load("panda-laparoscope")
    found = trocar.register_port(robot, joints)
    out = cli("register-port", "panda-laparoscope", "--joints", str(path), "--json")
    assert out.returncode == 0, out.stderr
    expected = json.loads(out.stdout)
    assert np.allclose(found["port"], expected["port"], rtol=0, atol=1e-15)
    assert found["lines"] == expected["lines"] == len(joints)
    assert found["spread"] == pytest.approx(expected["spread_deg"], rel=1e-12)
    # One pose again and again: no spread, refused with the reason.
    with pytest.raises(ValueError, match="nearly parallel"):
        trocar.register_port(robot, [joints[0]] * 5)
    with pytest.raises(ValueError, match="finite|joints"):
        trocar.register_port(robot, [[float("nan")] * 7, joints[1]])


def test_the_breathing_port_followed_from_the_force():
    fixed = trocar.simulate("panda-breathing", port="fixed")
    followed = trocar.simulate("panda-breathing", port="estimated")
    assert {"port_x", "estimate_x", "port_force", "port_offset"} <= set(followed)
    assert np.max(followed["port_force"]) <= 0.2 * np.max(fixed["port_force"])
    assert np.max(followed["port_offset"]) <= 5e-4
    with pytest.raises(ValueError, match="estimated"):
        trocar.simulate("panda-breathing", port="guessed")
    with pytest.raises(ValueError, match="known exactly"):
        trocar.simulate("panda-laparoscope", port="known")


def test_the_port_registered_from_a_pivot_without_force():
    found = trocar.simulate("panda-registration", port="registered")
    t = found["t"]
    after = t >= 2.0
    error = np.linalg.norm(
        np.stack([found[f"estimate_{a}"] - found[f"port_{a}"] for a in "xyz"]), axis=0
    )
    assert error[0] > 9e-3
    assert np.max(error[after]) <= 5e-4
    assert np.max(found["port_force"][after]) <= 1.0
    with pytest.raises(ValueError, match="--port estimated"):
        trocar.simulate("panda-breathing", port="registered")


def test_a_loop_of_ones_own_reproduces_simulate_along_a_trajectory():
    """Controller.step with the run's reference, stepped as trocar simulate steps (t = k dt, then
    q += dt qd), gives simulate(robot, trajectory=...)'s joints at every row of a 10 s path:
    exactly with RunSetup.reference, and to rounding with Trajectory.reference from the start
    pose robot.eval gives (its last bits differ from the run's own, and the roll's angular
    velocity, a central difference, carries them along)."""
    robot = trocar.Robot.load("panda-laparoscope")
    path = str(ROOT / "examples" / "trajectories" / "panda-circle.csv")
    q0 = [0.0, -np.pi / 4, 0.0, -3 * np.pi / 4, 0.0, np.pi / 2, np.pi / 4]
    trace = trocar.simulate(robot, trajectory=path, q0=q0)
    setup = trocar.RunSetup(robot, trajectory=path, q0=q0)
    path_reference = trocar.Trajectory.load(path)
    pose = robot.eval(q0, what="fk")
    r0, p0 = np.asarray(pose[:3, :3]), np.asarray(pose[:3, 3])
    t = trace["t"]
    dt = t[1] - t[0]
    rows = np.stack([trace[f"q{j + 1}"] for j in range(7)], axis=1)
    assert len(t) > 1000

    def replay(reference_at):
        controller = trocar.Controller(robot, **setup.controller)
        q = np.array(q0, dtype=float)
        worst = 0.0
        for k in range(len(t)):
            worst = max(worst, float(np.max(np.abs(q - rows[k]))))
            out = controller.step(q, reference_at(k * dt), setup.trocar, dt)
            assert out["status"] == "Held", (k, out["status"])
            q = q + np.asarray(out["qd"]) * dt
        return worst

    assert replay(setup.reference) == 0.0
    own = replay(lambda t: path_reference.reference(t, r0, p0, setup.trocar))
    assert own <= 1e-11, own
    for s in (0.0, 1.234, 9.99):
        a, b = setup.reference(s), path_reference.reference(s, r0, p0, setup.trocar)
        for key in ("position", "rotation", "velocity"):
            np.testing.assert_allclose(a[key], b[key], rtol=0, atol=1e-13)
        # A central difference of the roll's rotation: the start pose's last bits over its step.
        np.testing.assert_allclose(a["angular_velocity"], b["angular_velocity"], rtol=0, atol=1e-9)


def test_trajectory_reference_as_simulate_builds_it():
    path = str(ROOT / "examples" / "trajectories" / "panda-circle.csv")
    tr = trocar.Trajectory.load(path)
    rows = np.loadtxt(path, delimiter=",", comments="#", skiprows=3)
    robot = trocar.Robot.load("panda-laparoscope")
    q0 = [0.0, -np.pi / 4, 0.0, -3 * np.pi / 4, 0.0, np.pi / 2, np.pi / 4]
    pose = robot.eval(q0, what="fk")
    r0, p0 = np.asarray(pose[:3, :3]), np.asarray(pose[:3, 3])
    trocar_point = p0 - 0.15 * r0[:, 2]
    # At the start the tip is where the path starts: its orientation is the start's.
    start = tr.reference(rows[0, 0], r0, p0, trocar_point)
    assert np.allclose(start["rotation"], r0, atol=1e-12)
    # Between two rows: the position linear, the velocity the segment's slope.
    k = 7
    t = 0.25 * rows[k, 0] + 0.75 * rows[k + 1, 0]
    mid = tr.reference(t, r0, p0, trocar_point)
    assert np.allclose(mid["position"], 0.25 * rows[k, 1:4] + 0.75 * rows[k + 1, 1:4], atol=1e-15)
    slope = (rows[k + 1, 1:4] - rows[k, 1:4]) / (rows[k + 1, 0] - rows[k, 0])
    assert np.allclose(mid["velocity"], slope, atol=1e-12)
    # The rotation stays a rotation; past the end the velocities are zero.
    rot = np.asarray(mid["rotation"])
    assert np.allclose(rot.T @ rot, np.eye(3), atol=1e-12)
    after = tr.reference(rows[-1, 0] + 1.0, r0, p0, trocar_point)
    assert np.allclose(after["velocity"], 0.0) and np.allclose(after["angular_velocity"], 0.0)
    with pytest.raises(ValueError, match="finite"):
        tr.reference(float("nan"), r0, p0, trocar_point)
    with pytest.raises(ValueError):
        trocar.Trajectory.load(str(ROOT / "examples" / "ports" / "panda-laparoscope-pivot.csv"))
