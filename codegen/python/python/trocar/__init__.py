"""trocar: constrained kinematics of robots with a remote centre of motion (a trocar).

The same library as the ``trocar`` command line: :class:`Robot` loads a shipped description or a
TOML file and evaluates, verifies and generates its closed-form constrained kinematics;
:class:`Controller` runs the constrained controller on a robot, step by step;
:func:`simulate` runs the shipped scenarios. Errors raise :class:`ValueError`
with the command line's message.
"""

from ._trocar import (
    Controller,
    Robot,
    __version__,
    panda_reference,
    quantities,
    shipped,
    simulate,
)

__all__ = [
    "Robot",
    "Controller",
    "simulate",
    "panda_reference",
    "shipped",
    "quantities",
    "__version__",
]
