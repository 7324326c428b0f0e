"""Type stubs of the native module ``trocar._trocar`` (re-exported by ``trocar``)."""

import os
from typing import Any, Dict, List, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

class Robot:
    """A robot description: a shipped name or a TOML file (its chain may come from a URDF)."""

    @staticmethod
    def load(name_or_path: Union[str, "os.PathLike[str]"]) -> "Robot":
        """Loads a shipped description by name or a TOML description file.

        Raises ``ValueError`` with the file, line and field when the description is invalid.
        """
    @property
    def name(self) -> str:
        """The robot's name (``[robot] name``)."""
    @property
    def joints(self) -> int:
        """Number of joint values ``eval`` takes."""
    @property
    def is_mechanism(self) -> bool:
        """Whether this is a closed mechanism."""
    @property
    def params(self) -> Dict[str, float]:
        """The parameters and their nominal values."""
    def eval(
        self,
        q: Union[Sequence[float], npt.NDArray[np.float64]],
        what: str = "jr",
        params: Optional[Mapping[str, float]] = None,
        numeric: bool = False,
    ) -> npt.NDArray[np.float64]:
        """``trocar eval``: the quantity ``what`` at joint values ``q`` as a row-major 2-D array.

        ``what``: ``jr`` (J^r_0e, thesis (3.15)), ``manip`` ((3.36), 1 × 1), ``task`` (S J^r),
        ``jc`` ((3.33)), ``jb0i`` ((3.13)), ``jb0e`` ((2.55)), ``fk`` (4 × 4); for closed
        mechanisms ``jr``, ``jc``, ``passive``, ``det``. ``params`` overrides parameter values by
        name; ``numeric`` evaluates with the numeric runtime instead of the generated closed forms.
        """
    def verify(self, samples: int = 1000, seed: int = 1) -> Dict[str, Any]:
        """``trocar verify``: ``{"robot", "samples", "passed", "checks": {name: {"max_error",
        "tolerance", "passed", "count", "worst_q"}}}``."""
    def generate(self, real: str = "f64") -> str:
        """``trocar generate``: the Rust module (``real`` is ``"f64"``, ``"f32"`` or ``"generic"``)."""

def simulate(
    scenario: str,
    method: Optional[str] = None,
    drift_correction: bool = True,
    max_joint_speed: Optional[float] = ...,
) -> Dict[str, npt.NDArray[np.float64]]:
    """``trocar simulate``: the trace of a scenario as named columns (``t`` first).

    ``method`` is ``"pinv"``, ``"dls"`` or ``"fi"`` (default: the scenario's);
    ``max_joint_speed`` in rad/s, ``None`` for no limit (default: the simulations' limit).
    """

def shipped() -> Dict[str, List[str]]:
    """The shipped ``robots``, ``mechanisms`` and ``scenarios``, as ``trocar list`` prints them."""

def quantities() -> List[str]:
    """The values ``Robot.eval`` accepts as ``what``."""
