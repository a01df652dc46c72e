"""The team env's SLAM mode: each robot its own SLAM, the team map merged from their maps.

With ``slam.enabled`` ``SemanticExploreMulti-v0`` gives every robot a
:class:`~semexplore_gym.envs.slam_mode.SlamMode` of its own (its own drifting odometry, scan
matcher, keyframes, loop closures and pose graph), fed with its scans (teammates left out of
them unless ``team.map_teammates``, as the team map does). The team map the robots observe is
the merge of their SLAM maps, each in the frame its own estimate built it in, by the rule the
team env merges maps with (:func:`~semexplore_gym.core.mapping.map_merge.merged_log_odds`:
per cell, the most certain robot). Each robot's observed pose is its own SLAM estimate.
Coverage, rewards and scoring stay on the map fused at the true poses.

Only ``team.map_sharing: team`` (one team map) has a SLAM mode; ``range`` (maps merged within
a communication range) fails in one line.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from semexplore_gym.core.grid import UNKNOWN, GridGeometry
from semexplore_gym.core.mapping.map_merge import merged_log_odds
from semexplore_gym.core.mapping.occupancy_grid import OccupancyGrid
from semexplore_gym.envs.env_config import EnvConfig
from semexplore_gym.envs.slam_mode import SlamMode

Pose = tuple[float, float, float]


class TeamSlam:
    """Every robot's SLAM and the merged team map (see the module docstring).

    Args:
        config: The env config (its ``slam``, ``mapping`` and ``lidar`` sections).
        geometry: The team's map frame.
        beam_angles_rad: The LiDAR's beam angles.
        n_robots: Team size.
    """

    def __init__(
        self, config: EnvConfig, geometry: GridGeometry, beam_angles_rad: np.ndarray, n_robots: int
    ) -> None:
        self.robots = [SlamMode(config, geometry, beam_angles_rad) for _ in range(n_robots)]
        self.grid = OccupancyGrid(geometry, config.mapping)

    @classmethod
    def create(
        cls,
        config: EnvConfig,
        geometry: GridGeometry,
        beam_angles_rad: np.ndarray,
        n_robots: int,
        map_sharing: str,
    ) -> TeamSlam | None:
        """The team's SLAM when ``config.slam.enabled``, else None.

        Raises:
            ValueError: with ``map_sharing`` other than ``"team"``.
        """
        if not config.slam.enabled:
            return None
        if map_sharing != "team":
            raise ValueError(
                f"slam.enabled needs team.map_sharing=team (one merged team map), got {map_sharing!r}"
            )
        return cls(config, geometry, beam_angles_rad, n_robots)

    def reset(self, poses: list[Pose], ranges: list[np.ndarray], count_mask: np.ndarray) -> None:
        """A new episode: each robot's SLAM at its (known) start pose with its first scan."""
        for slam, pose, scan in zip(self.robots, poses, ranges, strict=True):
            slam.reset(pose, scan)
        self.grid = OccupancyGrid(self.grid.geometry, self.grid.params, count_mask=count_mask)
        self.merge()

    def update(self, i: int, odom_pose: Any, ranges: np.ndarray, true_pose: Pose) -> Pose:
        """Robot ``i``'s step on its odometry pose and scan; returns its SLAM estimate."""
        return self.robots[i].update(odom_pose, ranges, true_pose)

    def merge(self) -> None:
        """The team map from the robots' SLAM maps (after every robot's step)."""
        self.grid.load_log_odds(merged_log_odds([s.grid for s in self.robots]))

    def info(self, i: int, true_pose: Pose) -> dict[str, Any]:
        """Robot ``i``'s per-step SLAM ``info`` entries (as ``SemanticExplore-v0``'s)."""
        return self.robots[i].info(true_pose)

    def metrics(self, truth_grid: OccupancyGrid) -> dict[str, Any]:
        """The team mission's SLAM figures (the ``runs.csv`` columns of ``benchmark --robots``,
        :data:`~semexplore_gym.evaluation.team_benchmark.SLAM_COLUMNS`): the robots' mean ATE
        and odometry ATE, the merged map's error against ``truth_grid`` (the map fused at the
        true poses), the loop closures and lost events of all robots together."""
        each = [s.metrics(truth_grid) for s in self.robots]
        known = self.grid.encoded != UNKNOWN
        n_known = int(np.count_nonzero(known))
        wrong = int(np.count_nonzero(known & (self.grid.encoded != truth_grid.encoded)))
        return {
            "ate_m": round(float(np.mean([m["ate_m"] for m in each])), 5),
            "odom_ate_m": round(float(np.mean([m["odom_ate_m"] for m in each])), 5),
            "map_error": round(wrong / n_known, 5) if n_known else 0.0,
            "loop_closures": int(sum(m["loop_closures"] for m in each)),
            "slam_lost_events": int(sum(m["slam_lost_events"] for m in each)),
        }
