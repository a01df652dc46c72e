"""Dynamic Window Approach local planner, after ROS ``dwa_local_planner``.

Each control period the planner samples velocity pairs ``(v, omega)`` reachable within one
period from the current velocity (the dynamic window, clipped to the robot's limits), rolls
each pair forward at constant velocity for ``sim_time_s`` and scores the trajectory like ROS:

``cost = path_distance_bias * 0.5 * (d_path(end) + d_path(front))``
``     + goal_distance_bias * 0.5 * (d_goal(end) + d_goal(front))``
``     + occdist_scale * max inflation cost along the trajectory``

``d_path`` is the distance to the local part of the global path, ``d_goal`` the distance to the
local goal (the last path point inside the local window), both flood-filled over the local
window round obstacles as ROS's ``MapGrid`` does; ``end`` is the trajectory end point and
``front`` the point ``forward_point_distance_m`` ahead of it (the ROS "alignment" and "goal
front" terms, which turn the robot towards the path; the nose aims at a point beyond the local
goal and alignment is dropped near the final goal, as in ROS). Distances are in metres where
ROS counts cells (``scale = bias * resolution * 0.5``, so the weights carry over). A trajectory
is invalid if the robot would come within ``robot_radius_m + clearance_margin_m`` of an
obstacle, which come from the occupied cells of the map window around the robot plus the
current LiDAR returns; a robot that is already closer than that may still rotate or move away
(it may not get closer), in place of ROS's recovery behaviours. Unknown cells count as free, as
in the TurtleBot3 local costmap (``track_unknown_space: false``). The oscillation and twirling
terms are not modelled; ROS's minimum-velocity filter is (``min_trans_speed_mps``).

Settling: within ``min_trans_speed_mps * sim_time_s`` of the final goal every admissible
trajectory would overshoot it, so there the filter and the nose and obstacle terms are dropped
and a trajectory is scored by where the robot will be after one control period (its distance
to the goal); the collision test still applies. Without this the robot parks a few centimetres
short of goals near walls (ROS then oscillates until a recovery).

The chosen command is always within ``[min_linear_speed_mps, max_linear_speed_mps]`` and
``[-max_angular_speed_radps, max_angular_speed_radps]``; with no valid trajectory it is (0, 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.planning.dwa_fields import distance_maps, local_clearance
from semexplore_gym.core.planning.dwa_kernels import evaluate_trajectories

__all__ = ["DWACommand", "DWAParams", "DWAPlanner", "scan_points_m"]


@dataclass(frozen=True)
class DWAParams:
    """DWA parameters; defaults are the TurtleBot3 Burger ``dwa_local_planner`` settings.

    Attributes:
        max_linear_speed_mps: Highest forward speed (TB3 ``max_vel_x`` 0.22).
        min_linear_speed_mps: Lowest linear speed; 0 = no reversing (TB3 allows -0.22; a
            circular robot can always turn in place, so we keep it forward-only by default).
        max_angular_speed_radps: Highest |omega| (TB3 ``max_rot_vel`` 2.75).
        linear_accel_mps2: Linear acceleration limit (``acc_lim_x`` 2.5).
        angular_accel_radps2: Angular acceleration limit (``acc_lim_theta`` 3.2).
        control_period_s: Time one command is held; sets the size of the dynamic window.
        sim_time_s: Forward simulation horizon (``sim_time`` 1.5).
        sim_step_s: Integration step of the rollouts.
        min_trans_speed_mps: With ``min_rot_speed_radps``, ROS's minimum-velocity filter: a
            sample slower than this in v *and* slower than ``min_rot_speed_radps`` in omega is
            not considered, so the robot never creeps or stands still (TB3 ``min_trans_vel``
            0.11; 0 disables the filter). Unlike ROS, where a robot at rest cannot reach
            ``min_rot_vel`` within one period and so cannot turn in place, turning at the
            fastest reachable rate is allowed, and the filter is lifted within
            ``min_trans_speed_mps * sim_time_s`` of the final goal so the robot can settle on it.
        min_rot_speed_radps: See ``min_trans_speed_mps`` (TB3 ``min_rot_vel`` 1.37).
        linear_samples: Number of v samples (``vx_samples`` 20).
        angular_samples: Number of omega samples (``vth_samples`` 40).
        path_distance_bias: Weight of staying on the global path (32).
        goal_distance_bias: Weight of approaching the local goal (20).
        occdist_scale: Weight of the obstacle cost (0.02).
        forward_point_distance_m: Look-ahead of the alignment point (0.325).
        robot_radius_m: Robot radius.
        clearance_margin_m: Added to the radius in the collision test. Obstacle distances are
            measured to occupied cell centres, which may lie up to half a cell diagonal (0.035 m
            at 0.05 m cells) off the wall surface; 0.04 m covers that and the rollout sampling.
        inflation_radius_m: Reach of the obstacle cost.
        cost_scaling_factor: Decay rate of the obstacle cost, 1/m.
        local_window_m: Side of the square local costmap around the robot (TB3: 3 m).
        xy_goal_tolerance_m: Distance to the final goal that counts as arrived (0.05).
    """

    max_linear_speed_mps: float = 0.22
    min_linear_speed_mps: float = 0.0
    max_angular_speed_radps: float = 2.75
    linear_accel_mps2: float = 2.5
    angular_accel_radps2: float = 3.2
    control_period_s: float = 0.2
    sim_time_s: float = 1.5
    sim_step_s: float = 0.1
    min_trans_speed_mps: float = 0.11
    min_rot_speed_radps: float = 1.37
    linear_samples: int = 20
    angular_samples: int = 40
    path_distance_bias: float = 32.0
    goal_distance_bias: float = 20.0
    occdist_scale: float = 0.02
    forward_point_distance_m: float = 0.325
    robot_radius_m: float = 0.105
    clearance_margin_m: float = 0.04
    inflation_radius_m: float = 0.2
    cost_scaling_factor: float = 10.0
    local_window_m: float = 3.0
    xy_goal_tolerance_m: float = 0.05

    def __post_init__(self) -> None:
        positive = (
            "max_linear_speed_mps",
            "max_angular_speed_radps",
            "linear_accel_mps2",
            "angular_accel_radps2",
            "control_period_s",
            "sim_time_s",
            "sim_step_s",
            "local_window_m",
        )
        for name in positive:
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ValueError(f"DWAParams.{name} must be a positive number, got {v!r}")
        non_negative = (
            "path_distance_bias",
            "goal_distance_bias",
            "occdist_scale",
            "forward_point_distance_m",
            "robot_radius_m",
            "clearance_margin_m",
            "inflation_radius_m",
            "cost_scaling_factor",
            "xy_goal_tolerance_m",
            "min_trans_speed_mps",
            "min_rot_speed_radps",
        )
        for name in non_negative:
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0):
                raise ValueError(f"DWAParams.{name} must be a number >= 0, got {v!r}")
        if not self.min_linear_speed_mps <= self.max_linear_speed_mps:
            raise ValueError(
                f"min_linear_speed_mps ({self.min_linear_speed_mps}) must be <= max_linear_speed_mps ({self.max_linear_speed_mps})"
            )
        for name in ("linear_samples", "angular_samples"):
            v = getattr(self, name)
            if not (isinstance(v, int) and v >= 2):
                raise ValueError(f"DWAParams.{name} must be an integer >= 2, got {v!r}")


@dataclass(frozen=True)
class DWACommand:
    """Result of one DWA step.

    Attributes:
        v_mps: Linear velocity command.
        omega_radps: Angular velocity command.
        valid: False when no sampled trajectory was collision-free (the command is then 0, 0).
        goal_reached: True when the robot is within ``xy_goal_tolerance_m`` of the path's end.
        cost: Score of the chosen trajectory (``inf`` if none was valid).
        trajectory_m: ``(T, 2)`` the chosen rollout (for drawing).
    """

    v_mps: float
    omega_radps: float
    valid: bool
    goal_reached: bool
    cost: float
    trajectory_m: np.ndarray


def scan_points_m(
    pose: npt.ArrayLike, ranges_m: npt.ArrayLike, max_range_m: float, min_range_m: float = 0.0
) -> np.ndarray:
    """World ``(N, 2)`` points of the valid returns of a 360-degree scan.

    Beam ``i`` points at ``yaw + i * 2*pi / n``. Ranges of 0 (invalid), below ``min_range_m``,
    at or beyond ``max_range_m`` (no return) or not finite are dropped.
    """
    p = np.asarray(pose, dtype=np.float64).ravel()
    r = np.asarray(ranges_m, dtype=np.float64).ravel()
    if p.shape[0] < 3 or not np.isfinite(p[:3]).all():
        raise ValueError(f"pose must be a finite (x, y, yaw), got {pose!r}")
    n = r.shape[0]
    ok = np.isfinite(r) & (r > 0.0) & (r >= min_range_m) & (r < max_range_m)
    ang = p[2] + np.arange(n) * (2.0 * np.pi / max(n, 1))
    return np.column_stack([p[0] + r[ok] * np.cos(ang[ok]), p[1] + r[ok] * np.sin(ang[ok])])


class DWAPlanner:
    """Follows a global path with DWA. Holds the path and the progress along it."""

    def __init__(self, params: DWAParams = DWAParams()) -> None:
        if not isinstance(params, DWAParams):
            raise TypeError(f"params must be DWAParams, got {type(params).__name__}")
        self.params = params
        self._path = np.zeros((0, 2))
        self._progress = 0

    @property
    def path_m(self) -> np.ndarray:
        return self._path

    @property
    def progress_index(self) -> int:
        """Index of the path point the robot was last nearest to (the path behind is done)."""
        return self._progress

    def set_path(self, path_m: npt.ArrayLike) -> None:
        """Track a new global path ``(K, 2)`` (K >= 1) in world metres."""
        p = np.asarray(path_m, dtype=np.float64)
        if p.ndim != 2 or p.shape[1] != 2 or p.shape[0] < 1 or not np.isfinite(p).all():
            raise ValueError(
                f"path_m must be a finite (K, 2) array with K >= 1, got shape {p.shape}"
            )
        self._path = np.ascontiguousarray(p)
        self._progress = 0

    def clear(self) -> None:
        self._path = np.zeros((0, 2))
        self._progress = 0

    def compute(
        self,
        pose: npt.ArrayLike,
        velocity: tuple[float, float],
        grid: np.ndarray,
        geometry: GridGeometry,
        obstacle_points_m: npt.ArrayLike | None = None,
        limits: tuple[float, float] | None = None,
    ) -> DWACommand:
        """Choose the velocity command for this control period.

        Args:
            pose: Robot ``(x_m, y_m, yaw_rad)``.
            velocity: Current ``(v_mps, omega_radps)`` (the last command).
            grid: Encoded occupancy grid; its OCCUPIED cells are obstacles.
            geometry: Frame of ``grid``.
            obstacle_points_m: ``(N, 2)`` extra obstacle points (the current LiDAR returns).
            limits: Optional tighter ``(max_linear_speed_mps, max_angular_speed_radps)``, e.g.
                the env's limits.

        Returns:
            The command; ``goal_reached`` when within tolerance of the path end.
        """
        prm = self.params
        x0, y0, yaw0 = _checked_pose(pose, velocity, grid, geometry)
        if self._path.shape[0] == 0:
            return DWACommand(0.0, 0.0, True, True, 0.0, np.array([[x0, y0]]))
        goal = self._path[-1]
        if math.hypot(goal[0] - x0, goal[1] - y0) <= prm.xy_goal_tolerance_m:
            return DWACommand(0.0, 0.0, True, True, 0.0, np.array([[x0, y0]]))

        max_v, max_w = prm.max_linear_speed_mps, prm.max_angular_speed_radps
        if limits is not None:
            max_v = min(max_v, float(limits[0]))
            max_w = min(max_w, float(limits[1]))
        min_v = min(prm.min_linear_speed_mps, max_v)
        vs, ws = self._dynamic_window(velocity, min_v, max_v, max_w)

        res = geometry.resolution_m
        near, clear, wx0, wy0 = local_clearance(
            grid, geometry, x0, y0, prm.local_window_m, obstacle_points_m
        )
        local_path, local_goal = self._local_path(x0, y0, wx0, wy0, prm.local_window_m)
        to_goal = math.hypot(goal[0] - x0, goal[1] - y0)
        near_goal = to_goal <= prm.forward_point_distance_m
        # Within one horizon at the minimum speed of the final goal the filter is lifted, or every
        # admissible trajectory would overshoot a goal the robot can no longer settle on.
        settling = to_goal <= prm.min_trans_speed_mps * prm.sim_time_s
        fields = distance_maps(
            clear,
            wx0,
            wy0,
            res,
            local_path,
            (x0, y0),
            prm.robot_radius_m,
            prm.forward_point_distance_m,
        )
        n_steps = max(1, int(round(prm.sim_time_s / prm.sim_step_s)))
        # 2: alignment and goal-front terms; 1: goal front only (near the goal, as ROS);
        # 0: settling, score the position after one control period (a nose aimed beyond a
        # goal by a wall, or a horizon end beyond it, would pin the robot short of it).
        front_mode = 0 if settling else (1 if near_goal else 2)
        best_i, best_j, best_cost = self._evaluate(
            (x0, y0, yaw0), vs, ws, n_steps, near, fields, (wx0, wy0, res), local_goal, front_mode
        )
        if best_i < 0:
            return DWACommand(0.0, 0.0, False, False, math.inf, np.array([[x0, y0]]))
        v = float(np.clip(vs[best_i], min_v, max_v))
        w = float(np.clip(ws[best_j], -max_w, max_w))
        traj = _rollout(x0, y0, yaw0, v, w, n_steps, prm.sim_time_s / n_steps)
        return DWACommand(v, w, True, False, float(best_cost), traj)

    def _dynamic_window(
        self, velocity: tuple[float, float], min_v: float, max_v: float, max_w: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """The linear and angular speeds reachable within one control period, sampled."""
        prm = self.params
        v_now, w_now = float(velocity[0]), float(velocity[1])
        vs = _samples(
            v_now, prm.linear_accel_mps2 * prm.control_period_s, min_v, max_v, prm.linear_samples
        )
        ws = _samples(
            w_now,
            prm.angular_accel_radps2 * prm.control_period_s,
            -max_w,
            max_w,
            prm.angular_samples,
        )
        return vs, ws

    def _evaluate(
        self,
        pose: tuple[float, float, float],
        vs: np.ndarray,
        ws: np.ndarray,
        n_steps: int,
        near: np.ndarray,
        fields: tuple[np.ndarray, np.ndarray, np.ndarray],
        window: tuple[float, float, float],
        local_goal: np.ndarray,
        front_mode: int,
    ) -> tuple[int, int, float]:
        """The best sample ``(i, j)`` of ``vs x ws`` and its cost (``i < 0``: none is valid).

        ``fields`` are the path, goal and nose distance fields of the local window whose corner
        and resolution are ``window``; ``front_mode`` is 2 (alignment and goal front), 1 (goal
        front only) or 0 (settling).
        """
        prm = self.params
        path_field, goal_field, front_field = fields
        wx0, wy0, res = window
        settling = front_mode == 0
        return evaluate_trajectories(
            pose[0],
            pose[1],
            pose[2],
            vs,
            ws,
            n_steps,
            prm.sim_time_s / n_steps,
            near,
            path_field,
            goal_field,
            front_field,
            wx0,
            wy0,
            res,
            prm.forward_point_distance_m,
            front_mode,
            max(1, int(round(prm.control_period_s / (prm.sim_time_s / n_steps)))),
            float(local_goal[0]),
            float(local_goal[1]),
            prm.robot_radius_m + prm.clearance_margin_m,
            prm.path_distance_bias,
            prm.goal_distance_bias,
            prm.occdist_scale,
            prm.robot_radius_m,
            prm.inflation_radius_m,
            prm.cost_scaling_factor,
            0.0 if settling else prm.min_trans_speed_mps,
            0.0 if settling else prm.min_rot_speed_radps,
            # A robot too slow to reach min_rot_speed within one period may still turn in place
            # at the fastest rate it can reach (ROS would declare failure and run a recovery).
            min(prm.min_rot_speed_radps, float(np.abs(ws).max())),
        )

    def _local_path(
        self, x0: float, y0: float, wx0: float, wy0: float, window_m: float
    ) -> tuple[np.ndarray, np.ndarray]:
        path = self._path
        # Progress only moves forward (ROS prunes the plan behind the robot); search a stretch
        # ahead of it so a path that loops near itself does not make the robot jump along it.
        ahead = path[self._progress :]
        d = np.hypot(ahead[:, 0] - x0, ahead[:, 1] - y0)
        horizon = min(len(d), 200)
        self._progress += int(np.argmin(d[:horizon]))
        rest = path[self._progress :]
        margin = 1e-9
        inside = (
            (rest[:, 0] >= wx0 + margin)
            & (rest[:, 0] <= wx0 + window_m - margin)
            & (rest[:, 1] >= wy0 + margin)
            & (rest[:, 1] <= wy0 + window_m - margin)
        )
        n_in = int(np.argmin(inside)) if not inside.all() else len(inside)
        n_in = max(n_in, 1)
        local = np.ascontiguousarray(rest[:n_in])
        return local, local[-1]


def _checked_pose(
    pose: npt.ArrayLike, velocity: tuple[float, float], grid: np.ndarray, geometry: GridGeometry
) -> tuple[float, float, float]:
    """``(x, y, yaw)`` of a finite pose; raises on a bad pose, grid shape or velocity."""
    p = np.asarray(pose, dtype=np.float64).ravel()
    if p.shape[0] < 3 or not np.isfinite(p[:3]).all():
        raise ValueError(f"pose must be a finite (x, y, yaw), got {pose!r}")
    if np.shape(grid) != geometry.shape:
        raise ValueError(f"grid shape {np.shape(grid)} does not match geometry {geometry.shape}")
    if not all(math.isfinite(float(v)) for v in velocity[:2]):
        raise ValueError(f"velocity must be a finite (v, omega), got {velocity!r}")
    return float(p[0]), float(p[1]), float(p[2])


def _samples(now: float, reach: float, lo: float, hi: float, n: int) -> np.ndarray:
    a = max(lo, now - reach)
    b = min(hi, now + reach)
    if a > b:
        # The current velocity is outside the limits (e.g. limits just tightened): go to the nearest.
        a = b = min(max(now, lo), hi)
    s = np.linspace(a, b, n)
    extra = [v for v in (0.0,) if a <= v <= b]
    return np.unique(np.concatenate([s, np.asarray(extra, dtype=np.float64)]))


def _rollout(x, y, yaw, v, w, n_steps, dt) -> np.ndarray:
    out = np.empty((n_steps + 1, 2))
    out[0] = (x, y)
    for k in range(1, n_steps + 1):
        x += v * math.cos(yaw) * dt
        y += v * math.sin(yaw) * dt
        yaw += w * dt
        out[k] = (x, y)
    return out
