"""The env's SLAM mapping mode (``slam.enabled``): the observed map and pose come from SLAM.

:class:`SlamMode` runs :class:`~semexplore_gym.core.slam.backend.ScanSlam` on the env's drifting
odometry pose and the LiDAR scans; the env's own grid, fused at the true pose, stays for
coverage and rewards. It also keeps the true pose of each keyframe for the trajectory error.

Faults are reported, never silent: ``info["slam_lost"]`` (now), ``slam_lost_events`` (how often
the back end became lost) and ``slam_degenerate_matches`` (matches that pinned the pose only
across one direction, as in a featureless corridor), and the same in the mission record.

Kidnapping: ``env.reset(options={"kidnap_to": (x_m, y_m, yaw_rad)})`` after a first reset
carries the robot to that pose without telling SLAM (:func:`kidnap_start`). The episode starts
again there (time, path, coverage on the truth), the odometry reads on from there, but the
back end keeps its map, its keyframes and its estimate (the last keyframe's pose): it must
notice from its scans. Not allowed without the SLAM mode, before the first reset, or together
with ``start_pose``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from semexplore_gym.core.grid import UNKNOWN, GridGeometry
from semexplore_gym.core.mapping.occupancy_grid import OccupancyGrid
from semexplore_gym.core.slam.backend import ScanSlam
from semexplore_gym.core.slam.false_stop import stop_artefact
from semexplore_gym.core.slam.pose_graph import require_gtsam
from semexplore_gym.core.slam.trajectory_error import relative_pose_error_m
from semexplore_gym.envs.env_config import EnvConfig

Pose = tuple[float, float, float]

#: The per-step ``info`` keys of the SLAM mode.
SLAM_INFO_KEYS = (
    "slam_pose",
    "slam_pose_error_m",
    "loop_closures",
    "slam_lost",
    "slam_lost_events",
    "slam_degenerate_matches",
)

#: The reset option that kidnaps the robot (see the module docstring).
KIDNAP_OPTION = "kidnap_to"


def kidnap_start(options: dict[str, Any] | None, slam: SlamMode | None) -> dict[str, Any] | None:
    """The reset ``options`` with a kidnap's target as the start pose (see the module
    docstring); other options unchanged.

    Raises:
        ValueError: ``kidnap_to`` without the SLAM mode, before the first reset, or with
            ``start_pose``.
    """
    if not options or options.get(KIDNAP_OPTION) is None:
        return options
    if slam is None:
        raise ValueError("reset option kidnap_to needs the SLAM mode (slam.enabled: true)")
    if not slam.started:
        raise ValueError("reset option kidnap_to needs a first reset: there is no map to lose")
    if options.get("start_pose") is not None:
        raise ValueError("reset options kidnap_to and start_pose exclude each other")
    return {**options, "start_pose": options[KIDNAP_OPTION]}


def slam_reset(
    slam: SlamMode | None,
    grid: OccupancyGrid,
    pose: Pose,
    scan: np.ndarray,
    options: dict[str, Any] | None,
) -> tuple[OccupancyGrid, Pose]:
    """The observed map and pose after a reset to the true ``pose``: the env's ``grid`` and
    ``pose`` without SLAM; SLAM's after :meth:`SlamMode.reset` (a kidnap with ``kidnap_to``)."""
    if slam is None:
        return grid, pose
    if options and options.get(KIDNAP_OPTION) is not None:
        slam.kidnap(pose)
    else:
        slam.reset(pose, scan)
    return slam.grid, slam.backend.estimate


class SlamMode:
    """One robot's SLAM in the env (see the module docstring).

    Args:
        config: The env config (its ``slam``, ``mapping`` and ``lidar`` sections).
        geometry: The env's map frame.
        beam_angles_rad: The LiDAR's beam angles.

    Raises:
        ImportError: one line naming the extra when gtsam is missing.
    """

    def __init__(
        self, config: EnvConfig, geometry: GridGeometry, beam_angles_rad: np.ndarray
    ) -> None:
        require_gtsam()
        lidar = config.lidar
        self.backend = ScanSlam(
            config.slam,
            geometry,
            config.mapping,
            beam_angles_rad,
            lidar.max_range_m,
            (lidar.mount_x_m, lidar.mount_y_m),
        )
        self._truth_at_keyframes: list[Pose] = []
        self._odom_at_keyframes: list[Pose] = []
        self.started = False

    @classmethod
    def create(
        cls, config: EnvConfig, geometry: GridGeometry, beam_angles_rad: np.ndarray
    ) -> SlamMode | None:
        """The SLAM mode when ``config.slam.enabled``, else None."""
        return cls(config, geometry, beam_angles_rad) if config.slam.enabled else None

    @property
    def grid(self) -> OccupancyGrid:
        """The SLAM map (what the policies see)."""
        return self.backend.grid

    def reset(self, pose: Pose, scan: np.ndarray) -> OccupancyGrid:
        """A new episode at the (shared) start ``pose``; returns the SLAM map."""
        self.backend.reset(pose, scan)
        self._truth_at_keyframes = [tuple(float(v) for v in pose)]  # type: ignore[list-item]
        self._odom_at_keyframes = list(self._truth_at_keyframes)
        self.started = True
        return self.backend.grid

    def kidnap(self, pose: Pose) -> None:
        """The robot now stands at ``pose`` (where the odometry reads on from); the back end
        is not told (:meth:`~semexplore_gym.core.slam.backend.ScanSlam.kidnap`)."""
        self.backend.kidnap(pose)

    def update(self, odom_pose: Any, scan: np.ndarray, true_pose: Pose) -> Pose:
        """One step on the odometry pose and the scan; returns the SLAM estimate. At each new
        keyframe the true and the odometry pose are kept beside it (:meth:`ate_m`,
        :meth:`odom_ate_m`)."""
        odom: Pose = tuple(float(v) for v in odom_pose)  # type: ignore[assignment]
        estimate = self.backend.update(odom, scan)
        if len(self.backend.keyframe_poses) > len(self._truth_at_keyframes):
            self._truth_at_keyframes.append(true_pose)
            self._odom_at_keyframes.append(odom)
        return estimate

    def info(self, true_pose: Pose) -> dict[str, Any]:
        """The per-step ``info`` entries (:data:`SLAM_INFO_KEYS`)."""
        est = self.backend.estimate
        return {
            "slam_pose": est,
            "slam_pose_error_m": math.hypot(est[0] - true_pose[0], est[1] - true_pose[1]),
            "loop_closures": self.backend.loop_closures,
            "slam_lost": self.backend.lost,
            "slam_lost_events": self.backend.lost_events,
            "slam_degenerate_matches": self.backend.degenerate_matches,
        }

    def ate_m(self) -> float:
        """Absolute trajectory error: RMSE of the keyframe positions against the true poses
        there, without alignment (SLAM starts at the true start pose, a shared frame)."""
        return _position_rmse_m(self.backend.keyframe_poses, self._truth_at_keyframes)

    def odom_ate_m(self) -> float:
        """The same error for the raw odometry at the same keyframes: what the map would
        have been built on without SLAM (the baseline :meth:`ate_m` is judged against)."""
        return _position_rmse_m(self._odom_at_keyframes, self._truth_at_keyframes)

    def rpe_m(self) -> float | None:
        """Relative pose error over 1 m of true travel between keyframes (translation RMSE;
        :func:`~semexplore_gym.core.slam.trajectory_error.relative_pose_error_m`); None when
        the robot travelled less than 1 m."""
        est = np.asarray(self.backend.keyframe_poses, dtype=np.float64)
        return relative_pose_error_m(est, np.asarray(self._truth_at_keyframes), delta_m=1.0)

    def map_error(self, truth_grid: OccupancyGrid) -> float:
        """Share of the SLAM map's known cells whose class (free, occupied) differs from the
        map the same scans build at the true poses (``truth_grid``; unknown there counts as a
        difference: ghost space)."""
        slam = self.backend.grid.encoded
        known = slam != UNKNOWN
        n_known = int(np.count_nonzero(known))
        if n_known == 0:
            return 0.0
        return float(np.count_nonzero(known & (slam != truth_grid.encoded)) / n_known)

    def metrics(self, truth_grid: OccupancyGrid, stopped_short: bool = False) -> dict[str, Any]:
        """The mission's SLAM figures: ``ate_m``, ``odom_ate_m``, ``rpe_m``, ``map_error``,
        ``loop_closures``, ``slam_lost`` (at the end), ``slam_lost_events``,
        ``slam_degenerate_matches``, and for a policy that ``stopped_short`` (self-stop below
        the coverage goal) whether a SLAM artefact explains it: ``slam_false_stop`` and
        ``slam_stop_artefact`` (:func:`~semexplore_gym.core.slam.false_stop.stop_artefact`;
        None when it did not stop short or the maps agree on the frontiers)."""
        rpe = self.rpe_m()
        artefact = None
        if stopped_short:
            artefact = stop_artefact(
                self.backend.grid.encoded, truth_grid.encoded, truth_grid.count_mask
            )
        return {
            "ate_m": round(self.ate_m(), 5),
            "odom_ate_m": round(self.odom_ate_m(), 5),
            "rpe_m": None if rpe is None else round(rpe, 5),
            "map_error": round(self.map_error(truth_grid), 5),
            "loop_closures": int(self.backend.loop_closures),
            "slam_lost": bool(self.backend.lost),
            "slam_lost_events": int(self.backend.lost_events),
            "slam_degenerate_matches": int(self.backend.degenerate_matches),
            "slam_false_stop": artefact is not None,
            "slam_stop_artefact": artefact,
        }


def draw_beside_truth(renderer: Any, snap: Any, truth_grid: OccupancyGrid, slam: SlamMode) -> Any:
    """One frame of the SLAM mode for people: left the SLAM map the policy sees, with the
    robot at SLAM's estimate and SLAM's keyframe trail; right the map the same scans build at
    the true poses, with the true robot, scan and trail. The true walls (faint blue) lie under
    both, so drift and doubled walls show as map off the walls.

    Args:
        renderer: A :class:`~semexplore_gym.rendering.renderer.Renderer` of the env's map frame.
        snap: The env's :class:`~semexplore_gym.rendering.renderer.RenderSnapshot` (its map is
            the SLAM map, its pose the true pose).
        truth_grid: The map fused at the true poses.
        slam: The env's SLAM mode.

    Returns:
        The ``(H, 2 W + gap, 3)`` uint8 frame.
    """
    from dataclasses import replace

    keyframes = np.asarray(slam.backend.keyframe_poses, dtype=np.float64)[:, :2]
    left = renderer.draw(
        replace(
            snap,
            pose=slam.backend.estimate,
            scan=None,
            trajectory_m=keyframes,
            text=f"SLAM map (the policy's)  ATE {slam.ate_m():.3f} m",
        )
    )
    right = renderer.draw(
        replace(
            snap,
            map=truth_grid.encoded.copy(),
            overlay={},
            text=f"{snap.text}  (truth: the same scans at the true poses)",
        )
    )
    gap = np.full((left.shape[0], 6, 3), 255, dtype=np.uint8)
    return np.concatenate([left, gap, right], axis=1)


def _position_rmse_m(estimate: list[Pose], truth: list[Pose]) -> float:
    """RMSE of the positions of ``estimate`` against ``truth`` (same instants, no alignment)."""
    est = np.asarray(estimate, dtype=np.float64)[:, :2]
    true = np.asarray(truth, dtype=np.float64)[:, :2]
    return float(np.sqrt(np.mean(np.sum((est - true) ** 2, axis=1))))
