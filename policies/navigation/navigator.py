"""A move_base-like navigator: Navfn global plan, DWA local control, patience and recoveries.

:class:`Navigator` drives the frontier baselines (:mod:`semexplore_gym.policies.frontier_baselines`) to their goals as
ROS move_base does (:class:`MoveBaseParams`): a Navfn-like global planner on an inflated
costmap (:mod:`semexplore_gym.core.planning.grid_search`) and a DWA local planner
(:mod:`semexplore_gym.core.planning.dwa`), with move_base's failure handling:

* a new goal is planned once (``planner_frequency_hz = 0``, the TurtleBot3 setting); the path is
  replanned when the local planner fails (no admissible trajectory, or it can only stand still);
* while planning fails the robot stands still; after ``planner_patience_s`` (5 s), or when
  the local planner has failed for ``controller_patience_s`` (15 s), or the robot has not
  moved ``oscillation_distance_m`` (0.2 m) for ``oscillation_timeout_s`` (10 s), a recovery
  runs: rotate in place once round (``recovery_rotation_rad`` at
  ``recovery_angular_speed_radps``; move_base's ``rotate_recovery``), then plan again;
* after ``max_recoveries`` (2, the two rotations of move_base's default recovery list) the
  goal is **aborted**;
* the goal counts as reached within the local planner's ``xy_goal_tolerance`` (TurtleBot3
  ``dwa_local_planner``: 0.05 m; the planner's own default is 0.10 m);
* the local planner **fails when its local goal cannot be reached** (``local_goal_check``, on
  for FE):
  ROS's DWA scores every trajectory by a distance flood from the local goal (the last point of
  the global path inside the local window) that does not enter lethal or inscribed cells, so
  once that point is mapped as (next to) a wall every trajectory is invalid. move_base then
  replans; a goal in a wall cannot be planned to, so planner patience, the recoveries and the
  abort follow. Without this rule a goal that turned out to be a wall kept the emulated DWA
  circling 0.3-0.7 m from it for the rest of the mission (an FE run on maze1 circled for
  ~1,100 s). move_base's oscillation check does not catch that case (in ROS neither): it
  measures displacement from the last reset point, and a circle wider than
  ``oscillation_distance_m`` keeps resetting it.

The oscillation check is a :class:`~semexplore_gym.policies.navigation.progress_watch.ProgressWatch`, the same
progress watch the semantic expert uses for its stuck detection.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from semexplore_gym.policies.base import DriveIntent, StepStats
from semexplore_gym.policies.navigation.progress_watch import ProgressWatch
from semexplore_gym.policies.navigation.recovery import RotateRecovery

from semexplore_gym.core.frontiers.detection import detect_frontiers
from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry
from semexplore_gym.core.planning.dwa import DWAParams, DWAPlanner
from semexplore_gym.core.planning.grid_search import (
    CostmapParams,
    GridPath,
    NavfnParams,
    cells_near_occupied,
    geodesic_distance_m,
    inflate_costmap,
    plan_path,
)

__all__ = [
    "MoveBaseParams",
    "NavStatus",
    "Navigator",
    "check_int_at_least",
    "check_positive",
    "warm_up_navigation_kernels",
]


def check_positive(obj: Any, names: tuple[str, ...], allow_zero: bool = False) -> None:
    """Raise a ValueError naming the first field of ``obj`` in ``names`` that is not a finite
    number ``> 0`` (``>= 0`` with ``allow_zero``)."""
    for name in names:
        v = getattr(obj, name)
        ok = isinstance(v, (int, float)) and math.isfinite(v) and (v >= 0 if allow_zero else v > 0)
        if not ok:
            bound = ">= 0" if allow_zero else "> 0"
            raise ValueError(
                f"{type(obj).__name__}.{name} must be a finite number {bound}, got {v!r}"
            )


def check_int_at_least(obj: Any, name: str, minimum: int) -> None:
    """Raise a ValueError unless the field ``name`` of ``obj`` is an integer ``>= minimum``."""
    v = getattr(obj, name)
    if not (isinstance(v, int) and not isinstance(v, bool) and v >= minimum):
        raise ValueError(f"{type(obj).__name__}.{name} must be an integer >= {minimum}, got {v!r}")


@dataclass(frozen=True)
class MoveBaseParams:
    """The move_base-like navigator shared by both baselines.

    Attributes:
        costmap: Global costmap (TurtleBot3 burger: inflation 0.2 m; ``track_unknown_space``).
            Its ``inscribed_radius_m`` is replaced by the robot radius from ``info``.
        navfn: Global planner cost model. ``escape_radius_m`` lets a robot that touched the
            inscribed band plan out of it (ROS relies on recoveries for that).
        dwa: Local planner (TurtleBot3 DWA settings). Speed limits are capped by the env's,
            ``control_period_s`` and ``robot_radius_m`` are taken from ``info``.
        planner_frequency_hz: Periodic global replanning; 0 = only for a new goal or after a
            local-planner failure (TurtleBot3 ``planner_frequency: 0.0``).
        planner_patience_s: How long planning may fail before a recovery.
        controller_patience_s: How long the local planner may fail before a recovery.
        oscillation_timeout_s: Time without moving ``oscillation_distance_m`` before a recovery.
        oscillation_distance_m: See ``oscillation_timeout_s``.
        recovery_rotation_rad: Angle of one in-place rotation recovery.
        recovery_angular_speed_radps: Its angular speed (``rotate_recovery`` default 1.0).
        max_recoveries: Recoveries per goal before the goal is aborted.
        stand_still_speed_mps: A local-planner command slower than this in both v and
            ``stand_still_speed_mps / radius`` in omega counts as a failure (ROS DWA never
            samples such commands: TurtleBot3 ``min_trans_vel`` 0.11, ``min_rot_vel`` 1.37).
        replan_on_blocked_path: Replan as soon as the rest of the path passes within the robot
            radius of a newly mapped obstacle (move_base only replans when the local planner
            fails, with ``planner_frequency`` 0, so a stale path through a wall first costs an
            oscillation timeout and a recovery).
        local_goal_check: The local planner fails when every cell round its local goal lies
            within the robot radius of an obstacle (ROS DWA's goal-distance flood cannot leave
            it); see the module docstring. On for FE (``frontier``); off here so that the
            ``nearest`` baseline keeps its pinned behaviour (``nearest[navigation.
            local_goal_check=true]`` turns it on). The goal tolerance is
            ``dwa.xy_goal_tolerance_m``.
    """

    costmap: CostmapParams = field(default_factory=CostmapParams)
    navfn: NavfnParams = field(default_factory=lambda: NavfnParams(escape_radius_m=0.15))
    dwa: DWAParams = field(default_factory=DWAParams)
    planner_frequency_hz: float = 0.0
    planner_patience_s: float = 5.0
    controller_patience_s: float = 15.0
    oscillation_timeout_s: float = 10.0
    oscillation_distance_m: float = 0.2
    recovery_rotation_rad: float = 2.0 * math.pi
    recovery_angular_speed_radps: float = 1.0
    max_recoveries: int = 2
    stand_still_speed_mps: float = 0.005
    replan_on_blocked_path: bool = False
    local_goal_check: bool = False

    def __post_init__(self) -> None:
        check_positive(
            self,
            (
                "planner_patience_s",
                "controller_patience_s",
                "oscillation_timeout_s",
                "recovery_angular_speed_radps",
            ),
        )
        check_positive(
            self,
            (
                "planner_frequency_hz",
                "oscillation_distance_m",
                "recovery_rotation_rad",
                "stand_still_speed_mps",
            ),
            allow_zero=True,
        )
        if not (isinstance(self.max_recoveries, int) and self.max_recoveries >= 0):
            raise ValueError(
                f"MoveBaseParams.max_recoveries must be an integer >= 0, got {self.max_recoveries!r}"
            )


class NavStatus:
    """Navigator states (strings, so they show up readably in stats)."""

    IDLE = "idle"
    ACTIVE = "active"
    RECOVERING = "recovering"
    SUCCEEDED = "succeeded"
    ABORTED = "aborted"


class Navigator:
    """move_base emulation: Navfn global plan, DWA local control, patience and recoveries."""

    def __init__(
        self,
        params: MoveBaseParams,
        robot_radius_m: float,
        limits: tuple[float, float],
        dt_s: float,
    ) -> None:
        radius = float(robot_radius_m)
        cm = params.costmap
        self.costmap_params = dataclasses.replace(
            cm, inscribed_radius_m=radius, inflation_radius_m=max(cm.inflation_radius_m, radius)
        )
        dwa = dataclasses.replace(
            params.dwa,
            robot_radius_m=radius,
            control_period_s=dt_s,
            inflation_radius_m=max(params.dwa.inflation_radius_m, radius),
        )
        self.params = params
        self.dwa = DWAPlanner(dwa)
        self.limits = (float(limits[0]), float(limits[1]))
        self.dt_s = float(dt_s)
        self.radius_m = radius
        self.status = NavStatus.IDLE
        self.goal_xy_m: tuple[float, float] | None = None
        self.path: GridPath | None = None
        self.velocity = (0.0, 0.0)
        self.trajectory_m = np.zeros((0, 2))
        self.counters = {
            "plans": 0,
            "plan_failures": 0,
            "recoveries": 0,
            "aborts": 0,
            "successes": 0,
            "unreachable_local_goal": 0,
        }
        self.last_plan_failed = False
        # Set by a policy to force replan_on_blocked_path (FE's check_reachability).
        self.check_blocked = False
        # move_base's oscillation check: no progress until the robot moves that far.
        self._oscillation = ProgressWatch(
            params.oscillation_timeout_s,
            radius_m=params.oscillation_distance_m,
            radius_inclusive=True,
        )
        self._rotation = RotateRecovery(
            params.recovery_rotation_rad, params.recovery_angular_speed_radps
        )
        self._reset_goal_state(0.0)

    def _reset_goal_state(self, now_s: float) -> None:
        self._need_plan = True
        self._plan_fail_since: float | None = None
        self._ctrl_fail_since: float | None = None
        self._last_plan_s = -math.inf
        self._oscillation.reset(now_s)
        self._recoveries = 0
        self._rotation.stop()

    def set_goal(self, goal_xy_m: tuple[float, float], now_s: float) -> None:
        """Start navigating to a new goal (move_base ``sendGoal``)."""
        self.goal_xy_m = (float(goal_xy_m[0]), float(goal_xy_m[1]))
        self.status = NavStatus.ACTIVE
        self.path = None
        self.dwa.clear()
        self._reset_goal_state(now_s)

    def abort(self) -> None:
        """Give up the current goal now (status ABORTED), without patience or recoveries."""
        if self.goal_xy_m is not None:
            self.status = NavStatus.ABORTED
            self.counters["aborts"] += 1
            self.path = None
            self.dwa.clear()

    def drive_intent(self) -> DriveIntent:
        """The goal while navigating to it (mode ``"recovery"`` during a recovery, else
        ``"goal"``); no goal once it has succeeded, been aborted or cancelled."""
        if self.status == NavStatus.RECOVERING:
            return DriveIntent(self.goal_xy_m, "recovery")
        return DriveIntent(self.goal_xy_m if self.status == NavStatus.ACTIVE else None, "goal")

    def cancel(self) -> None:
        self.goal_xy_m = None
        self.path = None
        self.dwa.clear()
        self.status = NavStatus.IDLE

    def step(
        self,
        now_s: float,
        pose: np.ndarray,
        grid: np.ndarray,
        geometry: GridGeometry,
        scan_pts: np.ndarray | None,
        stats: StepStats,
    ) -> tuple[float, float]:
        """One control period; returns ``(v_mps, omega_radps)`` and updates ``status``."""
        if self.status not in (NavStatus.ACTIVE, NavStatus.RECOVERING) or self.goal_xy_m is None:
            return self._command(0.0, 0.0)
        prm = self.params
        self.last_plan_failed = False
        if self.status == NavStatus.RECOVERING:
            if self._rotation.active:
                return self._command(0.0, self._rotation.turn(self.limits[1], self.dt_s))
            self._end_recovery(now_s)

        if (
            prm.planner_frequency_hz > 0
            and now_s - self._last_plan_s >= 1.0 / prm.planner_frequency_hz
        ):
            self._need_plan = True
        blocked = (prm.replan_on_blocked_path or self.check_blocked) and self._path_blocked(
            pose, grid, geometry
        )
        if self._need_plan or blocked:
            waiting = self._global_plan(now_s, pose, grid, geometry, stats)
            if waiting is not None:
                return waiting

        if self._oscillation.update(now_s, (float(pose[0]), float(pose[1]))):
            return self._recover(now_s)
        return self._local_control(now_s, pose, grid, geometry, scan_pts, stats)

    def _end_recovery(self, now_s: float) -> None:
        """Recovery over: plan again (move_base goes back to PLANNING)."""
        self.status = NavStatus.ACTIVE
        self._need_plan = True
        self._plan_fail_since = None
        self._ctrl_fail_since = None
        self._oscillation.reset(now_s)

    def _global_plan(
        self,
        now_s: float,
        pose: np.ndarray,
        grid: np.ndarray,
        geometry: GridGeometry,
        stats: StepStats,
    ) -> tuple[float, float] | None:
        """Plan the global path; the command to give instead of following it (None: follow)."""
        prm = self.params
        t0 = time.perf_counter()
        path = self._plan(pose, grid, geometry)
        stats.global_planning_ms += (time.perf_counter() - t0) * 1e3
        stats.replanned = True
        self._last_plan_s = now_s
        self.counters["plans"] += 1
        if path is None:
            self.last_plan_failed = True
            self.counters["plan_failures"] += 1
            self._need_plan = True
            if self._plan_fail_since is None:
                self._plan_fail_since = now_s
            if now_s - self._plan_fail_since >= prm.planner_patience_s:
                return self._recover(now_s)
            return self._command(0.0, 0.0)
        self.path = path
        self.dwa.set_path(path.points_m)
        self._need_plan = False
        self._plan_fail_since = None
        return None

    def _local_control(
        self,
        now_s: float,
        pose: np.ndarray,
        grid: np.ndarray,
        geometry: GridGeometry,
        scan_pts: np.ndarray | None,
        stats: StepStats,
    ) -> tuple[float, float]:
        """Follow the global path with DWA (local planner failures lead to a recovery)."""
        prm = self.params
        t0 = time.perf_counter()
        cmd = self.dwa.compute(
            pose, self.velocity, grid, geometry, obstacle_points_m=scan_pts, limits=self.limits
        )
        unreachable = (
            prm.local_goal_check
            and not cmd.goal_reached
            and self._local_goal_unreachable(pose, grid, geometry)
        )
        stats.local_planning_ms += (time.perf_counter() - t0) * 1e3
        self.trajectory_m = cmd.trajectory_m
        if cmd.goal_reached:
            self.status = NavStatus.SUCCEEDED
            self.counters["successes"] += 1
            return self._command(0.0, 0.0)
        still = (
            abs(cmd.v_mps) < prm.stand_still_speed_mps
            and abs(cmd.omega_radps) * self.radius_m < prm.stand_still_speed_mps
        )
        if unreachable:
            self.counters["unreachable_local_goal"] += 1
        if not cmd.valid or still or unreachable:
            # Local planner failure: replan next step; recover after controller patience.
            if self._ctrl_fail_since is None:
                self._ctrl_fail_since = now_s
            self._need_plan = True
            if now_s - self._ctrl_fail_since >= prm.controller_patience_s:
                return self._recover(now_s)
            return self._command(0.0, 0.0)
        self._ctrl_fail_since = None
        return self._command(cmd.v_mps, cmd.omega_radps)

    def _path_blocked(self, pose: np.ndarray, grid: np.ndarray, geometry: GridGeometry) -> bool:
        if self.path is None:
            return False
        rest = self.path.cells[self.dwa.progress_index + 1 :]
        if len(rest) == 0:
            return False
        # Cells round the robot may be in the inscribed band on purpose (the planner's escape
        # radius); only the path ahead of them counts.
        x, y = geometry.grid_to_world(rest[:, 0], rest[:, 1])
        skip = max(self.params.navfn.escape_radius_m, self.radius_m)
        ahead = rest[np.hypot(x - pose[0], y - pose[1]) > skip]
        if len(ahead) == 0:
            return False
        return bool(cells_near_occupied(grid, ahead, self.radius_m, geometry.resolution_m).any())

    def _local_goal_unreachable(
        self, pose: np.ndarray, grid: np.ndarray, geometry: GridGeometry
    ) -> bool:
        """Whether ROS DWA's goal-distance flood could not leave the local goal's cell.

        The local goal is the last point of the first run of path points (from the robot's
        progress on) inside the square local window. The flood leaves its cell through any of
        the 8 neighbours that is neither lethal nor inscribed; cells the robot covers count as
        passable (ROS's ``within_robot``), so a goal next to the robot never fails here.
        """
        points = self.dwa.path_m[self.dwa.progress_index :]
        if len(points) == 0:
            return False
        half = 0.5 * self.dwa.params.local_window_m
        inside = (np.abs(points[:, 0] - pose[0]) <= half) & (np.abs(points[:, 1] - pose[1]) <= half)
        if not inside[0]:
            return False
        n_in = len(inside) if inside.all() else int(np.argmin(inside))
        gx, gy = points[n_in - 1]
        res = geometry.resolution_m
        if math.hypot(gx - pose[0], gy - pose[1]) <= self.radius_m + 1.5 * res:
            return False
        r_a, c_a = geometry.world_to_grid(gx, gy)
        r, c = int(r_a), int(c_a)
        rr, cc = np.mgrid[r - 1 : r + 2, c - 1 : c + 2]
        cells = np.column_stack([rr.ravel(), cc.ravel()])
        cells = cells[(cells[:, 0] >= 0) & (cells[:, 0] < grid.shape[0])]
        cells = cells[(cells[:, 1] >= 0) & (cells[:, 1] < grid.shape[1])]
        if len(cells) == 0:
            return False
        return bool(cells_near_occupied(grid, cells, self.radius_m, res).all())

    def _plan(self, pose: np.ndarray, grid: np.ndarray, geometry: GridGeometry) -> GridPath | None:
        costmap = inflate_costmap(grid, geometry.resolution_m, self.costmap_params)
        assert self.goal_xy_m is not None
        return plan_path(costmap, geometry, pose[:2], self.goal_xy_m, self.params.navfn)

    def _recover(self, now_s: float) -> tuple[float, float]:
        if self._recoveries >= self.params.max_recoveries:
            self.abort()
            return self._command(0.0, 0.0)
        self._recoveries += 1
        self.counters["recoveries"] += 1
        self.status = NavStatus.RECOVERING
        self._rotation.start()
        self._oscillation.reset(now_s)
        if not self._rotation.active:
            return self._command(0.0, 0.0)
        return self._command(0.0, self._rotation.turn(self.limits[1], self.dt_s))

    def _command(self, v: float, w: float) -> tuple[float, float]:
        self.velocity = (float(v), float(w))
        return self.velocity


def warm_up_navigation_kernels() -> None:
    """Run every numba kernel once on a tiny map, so that loading or compiling them lands in
    ``reset`` and not in the timing statistics of the first steps."""
    grid = np.full((12, 12), FREE, dtype=np.uint8)
    grid[:, 8:] = UNKNOWN
    grid[0, :8] = OCCUPIED
    geo = GridGeometry(0.05, 0.0, 0.0, 12, 12)
    detect_frontiers(grid, geo, (0.1, 0.2))
    costmap = inflate_costmap(grid, 0.05, CostmapParams())
    plan_path(costmap, geo, (0.1, 0.3), (0.35, 0.35))
    geodesic_distance_m(grid == FREE, geo, (0.1, 0.3))
    dwa = DWAPlanner(DWAParams())
    dwa.set_path(np.array([[0.1, 0.3], [0.35, 0.35]]))
    dwa.compute((0.1, 0.3, 0.0), (0.0, 0.0), grid, geo, obstacle_points_m=np.array([[0.3, 0.5]]))
