"""The semantic expert's plan record (:class:`Plan`, where it comes from: :class:`PlanKind`) and
what the expert is doing (:class:`ExpertMode`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum

import numpy as np

from semexplore_gym.core.planning.graph_search import FrontierCandidate

__all__ = ["ExpertMode", "Plan", "PlanKind", "StrValueEnum"]


class StrValueEnum(str, Enum):
    """A string enum that prints as its value (``f"{PlanKind.LOOK}" == "look"``)."""

    def __str__(self) -> str:
        return str(self.value)

    def __format__(self, format_spec: str) -> str:
        return format(str(self.value), format_spec)


class PlanKind(StrValueEnum):
    """Where a plan's goal comes from (equal to its value: ``PlanKind.SEMANTIC == "semantic"``)."""

    #: A frontier of the semantic topometric map, chosen by Algorithm 1.
    SEMANTIC = "semantic"
    #: A frontier the grid fallback found.
    FALLBACK = "fallback"
    #: Another approach to a goal whose approach failed.
    RETRY = "retry"
    #: A look at a frontier too narrow to reach.
    LOOK = "look"
    #: A goal commanded from outside (:meth:`SemanticExpertPolicy.drive_to`).
    COMMANDED = "commanded"
    #: A place that sees into a frontier reached without clearing it.
    VIEW = "view"
    #: A frontier a learned chooser picked among every reachable one
    #: (:class:`~semexplore_gym.policies.frontier_student.FrontierStudentPolicy`).
    LEARNED = "learned"


@dataclass
class Plan:
    """Where the robot drives, and along which path.

    Attributes:
        kind: Where the goal comes from.
        goal_xy_m: The goal (metres, world frame); reached within ``goal_reached_radius_m``.
        path_m: ``(K, 2)`` polyline from the robot's position when planned to the goal.
        candidate: The scored frontier (semantic plans only).
        frontier_xy_m: The frontier served when the goal lies beside it (retry, look, view).
        reached_within_m: The goal counts as reached within this distance (None: the expert's
            ``goal_reached_radius_m``).
        path_clearance_m: For a plan through passages narrower than the planners' clearance
            (``narrow_passages``): the map's wall clearance at each path point, else None.
        progress: Index of the path point the robot has reached.
        arc_m: Arc length of the path at each point (computed).
    """

    kind: PlanKind
    goal_xy_m: tuple[float, float]
    path_m: np.ndarray
    candidate: FrontierCandidate | None = None
    frontier_xy_m: tuple[float, float] | None = None
    reached_within_m: float | None = None
    path_clearance_m: np.ndarray | None = None
    progress: int = 0
    arc_m: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        seg = np.hypot(*np.diff(self.path_m, axis=0).T) if len(self.path_m) > 1 else np.zeros(0)
        self.arc_m = np.concatenate(([0.0], np.cumsum(seg)))

    @property
    def remaining_m(self) -> float:
        """Length of the path from :attr:`progress` to its end."""
        return float(self.arc_m[-1] - self.arc_m[self.progress])


class ExpertMode(StrValueEnum):
    """What the expert is doing (equal to and printed as its value)."""

    IDLE = "idle"
    SEMANTIC = "semantic"
    FALLBACK = "fallback"
    RETRY = "retry"
    LOOK = "look"
    COMMANDED = "commanded"
    VIEW = "view"
    LEARNED = "learned"
    ESCAPE = "escape"
    RECOVERY = "recovery"
    WAITING = "waiting"
    DONE = "done"
