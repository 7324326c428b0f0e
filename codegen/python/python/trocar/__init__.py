"""trocar: constrained kinematics of robots with a remote centre of motion (a trocar).

The same library as the ``trocar`` command line: :class:`Robot` loads a shipped description or a
TOML file and evaluates, verifies and generates its closed-form constrained kinematics;
:class:`Controller` runs the constrained controller on a robot, step by step;
:func:`simulate` runs the shipped scenarios (``"panda-breathing"``'s port fixed, known or followed
from the wall's force); :func:`register_port` locates a port from joint positions; :class:`RunSetup` gives what a loop of one's own
needs to replay one; :class:`Trajectory` gives the reference along a CSV path as ``trocar simulate``
builds it; :class:`Scene` steps a shipped scene of several arms in a loop of one's
own; :mod:`trocar.physics` runs the controller on a robot with dynamics (MuJoCo,
``pip install trocar[physics]``). Errors raise :class:`ValueError`
with the command line's message.
"""

from ._trocar import (
    Controller,
    PortFollower,
    Robot,
    RunSetup,
    Scene,
    Trajectory,
    __version__,
    panda_reference,
    quantities,
    register_port,
    shipped,
    simulate,
    write_figure,
)

__all__ = [
    "Robot",
    "Controller",
    "RunSetup",
    "Scene",
    "PortFollower",
    "Trajectory",
    "write_figure",
    "simulate",
    "register_port",
    "panda_reference",
    "shipped",
    "quantities",
    "__version__",
]
