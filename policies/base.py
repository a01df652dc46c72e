"""The interface every policy implements: scripted expert, baselines and learned agents."""

from __future__ import annotations

import abc
import functools
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from semexplore_gym.core.grid import GridGeometry


@dataclass
class StepStats:
    """Compute time a policy spent on one ``act`` call, by stage, in milliseconds.

    ``map_generation_ms`` covers building the policy's map representation (the semantic
    topometric map, or frontier detection for the frontier baselines); ``global_planning_ms``
    covers goal selection and the global path search; ``local_planning_ms`` the local planner.
    A stage that did not run in this step reports 0.
    """

    map_generation_ms: float = 0.0
    global_planning_ms: float = 0.0
    local_planning_ms: float = 0.0
    replanned: bool = False
    extra: dict[str, Any] = field(default_factory=dict)


#: Modes (:attr:`DriveIntent.mode`) whose driving is a look drive or a recovery, not a drive
#: toward the goal (the semantic expert's ``ExpertMode`` values of the same names).
LOOK_RECOVERY_MODES: frozenset[str] = frozenset({"look", "recovery"})


@dataclass(frozen=True)
class DriveIntent:
    """What a policy says it drives toward in the step it just chose (see
    :meth:`Policy.drive_intent`; read by the benchmark's path decomposition).

    Attributes:
        goal_xy_m: The goal the robot drives toward (metres, world frame); None: no goal now.
        mode: A short label of what it does. ``"look"`` and ``"recovery"``
            (:data:`LOOK_RECOVERY_MODES`) count as look drives and recoveries; any other label
            (``"goal"``, the expert's ``"semantic"``, ``"fallback"``, ...) with a goal counts as
            driving toward that goal.
    """

    goal_xy_m: tuple[float, float] | None = None
    mode: str = "goal"


@dataclass(frozen=True)
class EnvFacts:
    """The static facts of the env's ``info`` a policy may read (see :func:`read_env_facts`).

    Attributes:
        geometry: The map observation's frame (``info["map_geometry"]``).
        radius_m: Robot radius.
        max_linear_speed_mps: Top forward speed (action ``v = 1``).
        max_angular_speed_radps: Top turn rate (action ``omega = 1``).
        max_range_m: LiDAR maximum range.
        min_range_m: LiDAR minimum range (0 when ``info`` does not say).
        dt_s: Control period.
    """

    geometry: GridGeometry
    radius_m: float
    max_linear_speed_mps: float
    max_angular_speed_radps: float
    max_range_m: float
    min_range_m: float
    dt_s: float


def read_env_facts(info: dict[str, Any], policy_name: str) -> EnvFacts:
    """Read ``map_geometry``, ``robot``, ``lidar`` and ``dt_s`` from the env's ``info``.

    Args:
        info: The ``info`` dict of ``env.reset``.
        policy_name: Who reads (for the error message).

    Raises:
        ValueError: an entry is missing or malformed.
    """
    try:
        robot = info["robot"]
        lidar = info["lidar"]
        return EnvFacts(
            geometry=GridGeometry.from_dict(info["map_geometry"]),
            radius_m=float(robot["radius_m"]),
            max_linear_speed_mps=float(robot["max_linear_speed_mps"]),
            max_angular_speed_radps=float(robot["max_angular_speed_radps"]),
            max_range_m=float(lidar["max_range_m"]),
            min_range_m=float(lidar.get("min_range_m", 0.0)),
            dt_s=float(info["dt_s"]),
        )
    except (KeyError, TypeError) as e:
        raise ValueError(
            f"{policy_name}.reset needs info with map_geometry, robot, lidar and dt_s: {e!r}"
        ) from None


class PolicyNotResetError(RuntimeError):
    """``act`` was called before the policy's first ``reset``: a policy needs the episode's
    first observation and ``info`` (the map frame, the robot's limits) before it can act."""


#: The flag a policy instance carries once its ``reset`` has run to the end.
RESET_DONE_ATTR = "_reset_done"

#: How a stop reason starts when the observed pose lies off the map's grid (a SLAM back end
#: that diverged): no frontier search and no path can start there.
OFF_MAP_REASON = "pose estimate outside the map"


def on_map(geometry: GridGeometry, xy_m: Any) -> bool:
    """Whether the position ``xy_m`` (an observed pose's x, y) lies on a cell of the grid."""
    x, y = float(xy_m[0]), float(xy_m[1])
    if not (np.isfinite(x) and np.isfinite(y)):
        return False
    row, col = geometry.world_to_grid(x, y)
    return bool(geometry.contains(int(row), int(col)))


def off_map_msg(geometry: GridGeometry, xy_m: Any, reason: str = "") -> str:
    """``reason`` as it is on the map; off it, :data:`OFF_MAP_REASON` at ``xy_m`` first."""
    if on_map(geometry, xy_m):
        return reason
    note = f"{OFF_MAP_REASON} at ({float(xy_m[0]):.2f}, {float(xy_m[1]):.2f}) m"
    return f"{note}; {reason}" if reason else note


def require_reset_before_act(cls: type) -> None:
    """Make ``cls``'s own ``act`` raise :class:`PolicyNotResetError` until ``reset`` has run.

    Wraps the ``reset`` and ``act`` that ``cls`` itself defines (not inherited ones, which are
    wrapped where they are defined): ``reset`` marks the instance as reset when it returns,
    whether or not it calls ``super().reset``; ``act`` checks the mark first. :class:`Policy`
    and :class:`~semexplore_gym.policies.team.base.TeamPolicy` call it for every subclass.
    """
    for name, wrap in (("reset", _marking_reset), ("act", _checked_act)):
        method = vars(cls).get(name)
        if callable(method) and not getattr(method, "__isabstractmethod__", False):
            setattr(cls, name, wrap(method))


def _marking_reset(reset: Callable[..., Any]) -> Callable[..., Any]:
    @functools.wraps(reset)
    def marking_reset(self: Any, *args: Any, **kwargs: Any) -> Any:
        setattr(self, RESET_DONE_ATTR, False)
        try:
            out = reset(self, *args, **kwargs)
        except BaseException:
            # A reset that fails part-way (after super().reset) leaves the policy unusable.
            setattr(self, RESET_DONE_ATTR, False)
            raise
        setattr(self, RESET_DONE_ATTR, True)
        return out

    return marking_reset


def _checked_act(act: Callable[..., Any]) -> Callable[..., Any]:
    @functools.wraps(act)
    def checked_act(self: Any, *args: Any, **kwargs: Any) -> Any:
        if not getattr(self, RESET_DONE_ATTR, False):
            raise PolicyNotResetError(
                f"{type(self).__name__}.act: call reset(obs, info, seed=...) first, with the "
                "observation and info of env.reset"
            )
        return act(self, *args, **kwargs)

    return checked_act


class Policy(abc.ABC):
    """A controller from observations to actions.

    A policy sees what a robot sees: the observation dict and the ``info`` dict the env returns
    (including ``info["map_geometry"]`` and the robot limits), never the simulator.

    Lifecycle: ``reset(obs, info, seed=...)`` at the start of an episode, then
    ``act(obs, info)`` each step (before the first ``reset``, ``act`` raises
    :class:`PolicyNotResetError`). ``done`` turns True when the policy considers the mission
    over (``stop_reason`` says why); ``last_stats`` holds the compute times of the last step.
    """

    name: str = "policy"
    #: True when the policy reads ``obs["map"]`` only while ``reset``/``act`` runs and keeps
    #: no reference to it (nor to a view of it) for later steps. The mission runners then
    #: make the env with ``map_observation="shared"`` (a read-only live view of the env's map
    #: instead of a fresh copy per step: 1.3 MB per step on Willow Garage). Leave it False
    #: unless a test shows the policy's missions identical with ``"copy"`` and ``"shared"``.
    reads_map_in_step_only: bool = False

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        require_reset_before_act(cls)

    def __init__(self) -> None:
        self.done: bool = False
        self.stop_reason: str = ""
        self.last_stats: StepStats = StepStats()
        self.rng: np.random.Generator = np.random.default_rng()
        self._reset_done = False

    def reset(
        self, obs: dict[str, np.ndarray], info: dict[str, Any], seed: int | None = None
    ) -> None:
        """Start a new episode. All randomness of the policy flows from ``seed``."""
        self.done = False
        self.stop_reason = ""
        self.last_stats = StepStats()
        self.rng = np.random.default_rng(seed)

    @abc.abstractmethod
    def act(self, obs: dict[str, np.ndarray], info: dict[str, Any]) -> np.ndarray:
        """Return the action for this step: float32 ``(2,)`` in ``[-1, 1]`` (scaled v, omega)."""

    def mission_metrics(self) -> dict[str, Any]:
        """Extra per-mission figures for benchmark rows, read once when a mission ends.

        Name -> int, float, str or None; a policy returns the same names in every mission.
        The benchmark harness writes the names it has columns for (for the semantic expert:
        ``scored_replans`` and ``semantic_share``). Empty by default.
        """
        return {}

    def drive_intent(self) -> DriveIntent | None:
        """The goal and mode of the step ``act`` just chose, read once per step after ``act``.

        The default reads the policy's ``goal_xy_m`` and ``mode`` read-outs when it has them
        (the semantic expert does), else returns None: the policy does not say, and its whole
        path counts as driven without a goal. Override it to report more cheaply or exactly.
        """
        goal = getattr(self, "goal_xy_m", None)
        mode = getattr(self, "mode", None)
        if goal is None and mode is None:
            return None
        return DriveIntent(goal, str(mode) if mode is not None else "goal")

    def overlay(self) -> dict[str, Any]:
        """Drawing hints for the renderer (see :mod:`semexplore_gym.rendering`); empty by default."""
        return {}


require_reset_before_act(Policy)  # its own reset marks too (subclasses that do not override it)
