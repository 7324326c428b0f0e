"""What every front door refuses, refused from Python in the library's words (RELIABILITY.md's
findings F20 onwards): each case here was accepted, or aborted the interpreter, before."""

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
