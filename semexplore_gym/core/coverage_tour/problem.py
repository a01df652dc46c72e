"""What a full-knowledge coverage planner is given: the true world and the env's sensor.

:class:`PrivilegedWorld` is the one channel through which the true world reaches a policy:
``SemanticExploreEnv(privileged=True)`` puts one in the ``info`` of ``reset`` under
:data:`PRIVILEGED_INFO_KEY` (never in the observation, never in a plain env's ``info``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.worlds.world import World

#: The ``info`` key of ``reset`` that holds the :class:`PrivilegedWorld` of a privileged env.
PRIVILEGED_INFO_KEY = "privileged_world"


@dataclass(frozen=True)
class SensorModel:
    """The env's LiDAR as a coverage planner models it (mount offset taken as zero).

    Attributes:
        n_beams: Beams per scan, evenly spaced over 360 degrees.
        max_range_m: Farthest return; free space is marked up to it.
        min_range_m: Returns closer than this are invalid (their beam marks nothing).
    """

    n_beams: int = 360
    max_range_m: float = 3.5
    min_range_m: float = 0.12

    def __post_init__(self) -> None:
        if not (isinstance(self.n_beams, int) and 4 <= self.n_beams <= 4096):
            raise ValueError(
                f"SensorModel.n_beams must be an integer in 4..4096, got {self.n_beams!r}"
            )
        if not (math.isfinite(self.max_range_m) and self.max_range_m > 0):
            raise ValueError(f"SensorModel.max_range_m must be positive, got {self.max_range_m!r}")
        if not 0 <= self.min_range_m < self.max_range_m:
            raise ValueError(
                f"SensorModel.min_range_m must be in [0, max_range_m), got {self.min_range_m!r}"
            )

    def beam_angles_rad(self) -> np.ndarray:
        return np.arange(self.n_beams, dtype=np.float64) * (2.0 * math.pi / self.n_beams)


@dataclass(frozen=True)
class PrivilegedWorld:
    """The ground truth of one episode, for privileged (oracle) planners only.

    Attributes:
        world: The true world (wall segments, free raster).
        geometry: The env's map frame (``info["map_geometry"]``).
        start_pose: The true start pose ``(x_m, y_m, yaw_rad)``.
        radius_m: Robot radius.
        clearance_m: The wall clearance that defines where the robot can stand in the
            reachable mask (``radius_m + episode.coverage_clearance_margin_m``, 0.01 m by
            default, as the env computes it).
        reachable_mask: ``geometry.shape`` bool: the env's coverage denominator (read-only).
        sensor: The env's LiDAR.
        max_linear_speed_mps: Top forward speed.
        coverage_goal: The env's ``episode.coverage_goal``.
    """

    world: World
    geometry: GridGeometry
    start_pose: tuple[float, float, float]
    radius_m: float
    clearance_m: float
    reachable_mask: np.ndarray
    sensor: SensorModel
    max_linear_speed_mps: float
    coverage_goal: float
