"""trocar: constrained kinematics of robots with a remote centre of motion (a trocar).

The same library as the ``trocar`` command line: :class:`Robot` loads a shipped description or a
TOML file and evaluates, verifies and generates its closed-form constrained kinematics;
:func:`simulate` runs the constrained controller's scenarios. Errors raise :class:`ValueError`
with the command line's message.
"""

from ._trocar import Robot, __version__, quantities, shipped, simulate

__all__ = ["Robot", "simulate", "shipped", "quantities", "__version__"]
