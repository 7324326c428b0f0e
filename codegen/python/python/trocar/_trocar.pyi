"""Type stubs of the native module ``trocar._trocar`` (re-exported by ``trocar``)."""

import os
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union, overload

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
    @property
    def joint_names(self) -> List[str]:
        """The joints' names, base first."""
    @property
    def joint_limits(self) -> List[Tuple[float, float]]:
        """Each joint's (lower, upper) limits; (-inf, inf) where the description has none."""
    def quantities(self) -> List[str]:
        """The quantities ``eval`` takes for this robot, by their catalogue names."""
    @overload
    def eval_many(
        self,
        q: npt.ArrayLike,
        what: str = ...,
        params: Optional[Mapping[str, float]] = None,
    ) -> npt.NDArray[np.float64]:
        """``what`` at every row of the ``(N, joints)`` array ``q`` (``float64``, or anything
        ``numpy.asarray`` converts to it, such as integers): an ``(N, rows, cols)`` array equal
        to N calls of ``eval``, evaluated on every core without the GIL. Raises ``MemoryError``
        when the result cannot be allocated."""
    @overload
    def eval_many(
        self,
        q: npt.ArrayLike,
        what: Union[Tuple[str, ...], List[str]],
        params: Optional[Mapping[str, float]] = None,
    ) -> Tuple[npt.NDArray[np.float64], ...]:
        """Several quantities at every row of ``q``: one ``(N, rows, cols)`` array per name,
        computed by one program (as ``eval`` with a sequence of names)."""
    def labels(self, what: str) -> Optional[Tuple[List[str], List[str]]]:
        """Row and column labels of ``what``'s matrix, or ``None`` for a pose or a scalar."""
    @overload
    def eval(
        self,
        q: Union[Sequence[float], npt.NDArray[np.float64]],
        what: str = ...,
        params: Optional[Mapping[str, float]] = None,
        numeric: bool = False,
    ) -> npt.NDArray[np.float64]:
        """``trocar eval``: the quantity ``what`` at joint values ``q`` as a row-major 2-D array.

        ``what``: a catalogue name (``constrained_jacobian``, ``partial_body_jacobian``, ...) or
        a short name: ``jr`` (J^r_0e, thesis (3.15)), ``manip`` ((3.36), 1 × 1), ``task`` (S J^r),
        ``jc`` ((3.33)), ``jb0i`` ((3.13)), ``jb0e`` ((2.55)), ``fk`` (4 × 4), ``fk0i`` (g_0i,
        4 × 4); for closed mechanisms ``jr``, ``jc``, ``passive``, ``det``. ``params`` overrides
        parameter values by name; ``numeric`` evaluates with the numeric runtime instead of the
        generated closed forms.
        """
    @overload
    def eval(
        self,
        q: Union[Sequence[float], npt.NDArray[np.float64]],
        what: Union[Tuple[str, ...], List[str]],
        params: Optional[Mapping[str, float]] = None,
        numeric: bool = False,
    ) -> Tuple[npt.NDArray[np.float64], ...]:
        """Several quantities at ``q``, e.g. ``g, j = robot.eval(q, what=("fk0i", "jb0i"))``: a
        tuple of arrays, one per name, computed by one program that shares every value they have
        in common (the pose and the Jacobian share the walk along the chain). The first call with
        a new set of names builds its program (milliseconds); later calls reuse it.
        """
    def verify(self, samples: int = 1000, seed: int = 1) -> Dict[str, Any]:
        """``trocar verify``: ``{"robot", "samples", "passed", "checks": {name: {"max_error",
        "tolerance", "passed", "count", "worst_q"}}}``."""
    def generate(self, real: str = "f64") -> str:
        """``trocar generate``: the Rust module (``real`` is ``"f64"``, ``"f32"`` or ``"generic"``)."""

def simulate(
    scenario: Union[str, "os.PathLike[str]", Robot],
    method: Optional[str] = None,
    drift_correction: bool = True,
    max_joint_speed: Optional[float] = ...,
    trajectory: Optional[Union[str, "os.PathLike[str]"]] = None,
    q0: Optional[Sequence[float]] = None,
    trocar: Optional[Sequence[float]] = None,
    port: Optional[str] = None,
) -> Dict[str, npt.NDArray[np.float64]]:
    """``trocar simulate``: the trace of a scenario, or of a robot along its own trajectory, as
    named columns (``t`` first), the command line's CSV.

    ``method`` is ``"pinv"``, ``"dls"``, ``"fi"`` or ``"qp"`` (default: the scenario's);
    ``max_joint_speed`` in rad/s, ``None`` for no limit (default: the simulations' limit).
    With ``trajectory`` (a CSV: ``t,x,y,z`` and ``roll`` or ``qw,qx,qy,qz``), or when the first
    argument is a ``Robot`` or a description file, the robot is driven along that tip path from
    ``q0``, the trocar at ``trocar``; what is not given comes from the description's
    ``[simulation]`` section (``trajectory``, ``q0``, ``trocar``, ``method``, gains).
    ``port`` (``"fixed"``, ``"known"``, ``"estimated"``; default ``"estimated"``;
    ``"registered"`` for ``"panda-registration"``: from the shaft's lines during a pivot, no
    force) is how the moving-port scenarios' controller knows its port.
    """

def register_port(
    robot: Robot,
    joints: Sequence[Sequence[float]],
    least_spread: float = 2.0,
    forgetting: Optional[float] = None,
) -> Dict[str, Any]:
    """``trocar register-port``: the port located from joint positions of the instrument pivoting
    about it, one row per pose: ``port`` (m, base frame), ``covariance`` (m²), ``residual`` (m),
    ``spread`` (degrees), ``lines``. Refused (``ValueError``) where the shaft's lines spread less
    than ``least_spread`` degrees.
    """

class Controller:
    """The constrained kinematic controller on a robot (task selection, drift correction, the
    joint-limit objective); defaults are the Panda laparoscope scenario's gains."""

    def __init__(
        self,
        robot: Robot,
        method: str = "dls",
        kp: Optional[float] = None,
        ko: Optional[float] = None,
        kr: Optional[float] = None,
        max_joint_speed: Optional[float] = ...,
        null_space_gain: Optional[float] = None,
        dls_alpha0: Optional[float] = None,
        fi_gamma: Optional[float] = None,
        qp_kappa: Optional[float] = None,
        depth_limits: Optional[Tuple[float, float]] = None,
        max_joint_acceleration: Optional[float] = None,
    ) -> None: ...
    def step(
        self,
        q: Union[Sequence[float], npt.NDArray[np.float64]],
        reference: Union[Sequence[float], Mapping[str, Any]],
        trocar: Sequence[float],
        dt: float,
        dv: Optional[Sequence[float]] = None,
    ) -> Dict[str, Any]:
        """One step: ``{"qd", "l_a", "position_error", "orientation_error", "lateral_error",
        "dv_0r", "w_r", "w_i", "kappa_r", "kappa_i", "status", "qp_status", "qp_iterations",
        "qp_active", "qp_resolved"}`` (the last four ``None`` unless ``method="qp"``).
        ``status`` is ``"Held"``, or what gave way: ``"TrocarYielded"`` (the trocar could not be
        held within the joint limits, which every step keeps), ``"JointOutside"``,
        ``"DepthOutside"``.

        A ``reference`` dict has the keys ``"position"``, ``"rotation"``, ``"velocity"`` and
        ``"angular_velocity"`` only (another key raises ``ValueError``); its rotation must be a
        proper rotation matrix (``|RᵀR − I| ≤ 1e-6`` entry by entry, ``det R > 0``)."""
    def trocar_rate(
        self, q: Union[Sequence[float], npt.NDArray[np.float64]], velocity: Sequence[float]
    ) -> List[float]:
        """The ``dv`` of ``step`` that carries the constraint frame with a trocar moving at
        ``velocity`` (base frame, m/s) at joints ``q``."""
    def reset(self) -> None:
        """Restarts the filtered inverse and the QP's warm start."""

class RunSetup:
    """What a control loop of one's own needs to replay a run: a shipped Panda scenario's
    (``RunSetup("panda-laparoscope")``) or a robot's along its own trajectory
    (``RunSetup(robot_or_path, trajectory=..., q0=..., trocar=..., method=...)``, what is not
    given taken from its description's ``[simulation]`` section)."""

    def __init__(
        self,
        scenario: Union[str, "Robot"],
        trajectory: Optional[str] = None,
        q0: Optional[Sequence[float]] = None,
        trocar: Optional[Sequence[float]] = None,
        method: Optional[str] = None,
    ) -> None: ...
    @property
    def robot(self) -> "Robot":
        """The robot."""
    @property
    def q0(self) -> List[float]:
        """The start configuration."""
    @property
    def trocar(self) -> Tuple[float, float, float]:
        """The trocar (m, base frame)."""
    @property
    def duration(self) -> float:
        """How long the run lasts (s)."""
    @property
    def controller(self) -> Dict[str, Any]:
        """The keyword arguments of :class:`Controller` the run uses."""
    def reference(self, t: float) -> Dict[str, Any]:
        """The reference at time ``t`` (s), as :meth:`Controller.step` takes it."""
    def port(self, t: float) -> Optional[Tuple[Tuple[float, float, float], Tuple[float, float, float]]]:
        """The true port at ``t`` and its velocity where the port moves, else ``None``."""
    @property
    def wall_normal(self) -> Optional[Tuple[float, float, float]]:
        """The wall's normal where the port moves along it, else ``None``."""
    @property
    def follower(self) -> Optional[Tuple[float, float]]:
        """``(time_constant, max_rate)`` of the run's :class:`PortFollower`, where the port moves."""

class Trajectory:
    """A tip trajectory read from a CSV (``t,x,y,z`` and ``roll`` or ``qw,qx,qy,qz``), for a loop
    of one's own that follows it as ``trocar simulate ROBOT --trajectory F.csv`` does."""

    @staticmethod
    def load(path: str) -> "Trajectory":
        """Reads and checks the CSV (errors name the file, the line and the column)."""
    def reference(
        self,
        t: float,
        start_rotation: Sequence[Sequence[float]],
        start_position: Sequence[float],
        trocar: Sequence[float],
    ) -> Dict[str, Any]:
        """The controller's reference at ``t`` (s) as ``trocar simulate`` builds it: the position
        linear between rows and its slope fed forward; a roll turned through the trocar, its
        angular velocity by a central difference; quaternions by slerp. ``start_rotation``
        (3 × 3) and ``start_position``: the tip's pose at the start. A dict for
        :meth:`Controller.step` (``rotation`` is ``None`` for positions only)."""

class PortFollower:
    """A port followed from the wall's force on the shaft (an admittance law): the estimate moves
    along the force across the shaft, ``compliance`` m/(N s), its rate at most ``max_rate`` m/s;
    with the wall's ``normal``, the part along the shaft too."""

    def __init__(
        self,
        estimate: Sequence[float],
        compliance: float,
        max_rate: float,
        normal: Optional[Sequence[float]] = None,
    ) -> None: ...
    def update(
        self, force: Sequence[float], direction: Sequence[float], dt: float
    ) -> Tuple[float, float, float]:
        """One step over ``dt`` from the wall's force on a shaft of ``direction``: moves the
        estimate and returns its rate."""
    @property
    def estimate(self) -> Tuple[float, float, float]: ...
    @property
    def rate(self) -> Tuple[float, float, float]: ...

def panda_reference(t: float) -> Dict[str, npt.NDArray[np.float64]]:
    """The reference of the ``panda-laparoscope`` scenario at time ``t``, as ``Controller.step``
    takes it."""

def shipped() -> Dict[str, List[str]]:
    """The shipped ``robots``, ``mechanisms`` and ``scenarios``, as ``trocar list`` prints them."""

def quantities() -> List[Tuple[str, str]]:
    """``(name, short name)`` of every quantity ``Robot.eval`` accepts as ``what``."""

class Scene:
    """A shipped scene of several arms, each through its own port, stepped by a loop of one's own:
    ``"three-ports"`` (three Pandas; the instruments' shafts kept ``safety`` apart, the
    endoscope's view axis on the instruments' midpoint) or ``"dia10-dual"`` (the reference arm
    and its mirror image on one torso)."""

    def __init__(self, name: str, coupled: bool = True) -> None: ...
    @property
    def name(self) -> str: ...
    @property
    def arms(self) -> List[str]: ...
    @property
    def couplings(self) -> List[Tuple[str, str]]: ...
    @property
    def joints(self) -> int: ...
    @property
    def dt(self) -> float: ...
    @property
    def safety(self) -> float: ...
    @property
    def q0(self) -> npt.NDArray[np.float64]: ...
    @property
    def ports(self) -> List[Tuple[float, float, float]]: ...
    def reset(self) -> None: ...
    def step(
        self, q: Union[Sequence[float], npt.NDArray[np.float64]], t: float
    ) -> Dict[str, Any]:
        """One step: ``{"qd", "distances", "coupling_held", "coupling_active", "statuses"}``."""
        ...
