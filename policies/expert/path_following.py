"""The semantic expert's path following: potential field, progress, escapes, stuck recovery.

:class:`PathFollower` is a part the expert owns. Each step it drives along the current
:class:`~semexplore_gym.policies.expert.plan.Plan` with the modified potential field (section II
of the paper), moves the plan's progress along the path, lowers the repulsion for a while when
the field holds the robot still (local-minimum escape), and watches progress: when the robot
is stuck, its path stopped shrinking or its goal's time budget ran out, it backs off (the
expert then retries or drops the goal). Its parameters are
:class:`~semexplore_gym.policies.expert.params.PathFollowingParams`.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from semexplore_gym.policies.expert.counters import ExpertCounters
from semexplore_gym.policies.expert.params import PathFollowingParams
from semexplore_gym.policies.expert.plan import Plan
from semexplore_gym.policies.navigation import BackoffRecovery, ProgressWatch

from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.planning.path_tracking import (
    TightTracking,
    path_heading_rad,
    safe_forward_speed_mps,
    scan_centring_offset_m,
    tight_tracking_command,
)
from semexplore_gym.core.planning.potential_field import (
    PotentialFieldCommand,
    PotentialFieldFollower,
    RobotLimits,
    beam_angles_rad,
)

__all__ = [
    "PATH_PROGRESS_MARGIN_M",
    "PROGRESS_SNAP_M",
    "PROGRESS_WINDOW_M",
    "STILL_SPEED_FRACTION",
    "PathFollower",
]

#: The rest of the path must shrink by more than this to count as progress.
PATH_PROGRESS_MARGIN_M = 0.1

#: How far ahead along the path (metres) the robot's nearest path point is looked for: the
#: part behind is done, and a look this short cannot skip a loop of the path.
PROGRESS_WINDOW_M = 1.5

#: The nearest path point in that window counts as reached only within this distance (metres)
#: of the robot; farther (pushed off the path), the progress stays where it was.
PROGRESS_SNAP_M = 0.5

#: A forward command below this fraction of the top speed counts as standing still.
STILL_SPEED_FRACTION = 0.1

#: A narrow plan is tracked exactly where its path is tight this far ahead of the robot (m).
TIGHT_LOOKAHEAD_M = 0.5

#: In a tight passage no forward step brings the body nearer a scan return than this (m).
TIGHT_MIN_SPARE_M = 0.003


class PathFollower:
    """Drives along a plan and says when the robot is stuck.

    Args:
        params: The path follower's parameters.
        counts: The expert's counters (``escapes``, ``recoveries``, ``goal_timeouts``).
        log: Records an event ``(name, detail)`` in the expert's event log.

    Attributes (after :meth:`reset`): ``last_command`` the potential field's last command,
    ``goal_since_s`` and ``goal_budget_s`` the current goal's start and time budget.
    """

    def __init__(
        self,
        params: PathFollowingParams,
        counts: ExpertCounters,
        log: Callable[[str, str], None],
    ) -> None:
        self.params = params
        self.counts = counts
        self.log = log
        self.last_command: PotentialFieldCommand | None = None

    def reset(
        self,
        geometry: GridGeometry,
        limits: RobotLimits,
        dt_s: float,
        xy_m: tuple[float, float],
        known_cells: int,
        params: PathFollowingParams | None = None,
        min_range_m: float = 0.0,
    ) -> None:
        """Start a mission with the robot at ``xy_m`` on a map with ``known_cells`` known (with
        ``params``, if given, from now on; ``min_range_m``: the LiDAR's, which invalid returns
        (0) are read as)."""
        if params is not None:
            self.params = params
        self.min_range_m = min_range_m
        prm = self.params
        self._tracking = TightTracking(
            lookahead_m=prm.tight_track_lookahead_m,
            speed_mps=min(prm.tight_speed_mps, limits.max_linear_speed_mps),
            max_omega_radps=limits.max_angular_speed_radps,
            turn_in_place_rad=prm.tight_turn_in_place_rad,
        )
        self.geometry = geometry
        self.limits = limits
        self.dt_s = dt_s
        self.last_command = None
        self.goal_since_s = 0.0
        self.goal_budget_s = math.inf
        self._angles: np.ndarray | None = None
        self._still_s = 0.0
        self._escape_until_s = -1.0
        self._backoff = BackoffRecovery(prm.backoff_duration_s, prm.backoff_speed_fraction)
        # Stuck: the robot stayed near one point while the map hardly grew ...
        self._motion_watch = ProgressWatch(
            prm.stuck_timeout_s,
            radius_m=prm.stuck_radius_m,
            min_new_cells=prm.progress_min_new_cells,
        )
        self._motion_watch.reset(0.0, xy_m, known_cells)
        # ... or neither its path to the goal shrank nor the map grew, for longer.
        self._path_watch = ProgressWatch(
            prm.progress_timeout_s,
            min_new_cells=prm.progress_min_new_cells,
            path_margin_m=PATH_PROGRESS_MARGIN_M,
        )
        self._path_watch.reset(0.0, None, known_cells)

    # ------------------------------------------------------------------ goals
    def start_goal(self, plan: Plan, now_s: float) -> None:
        """A new goal: its time budget is a few times its path's duration at full speed."""
        self.goal_since_s = now_s
        self.goal_budget_s = max(
            self.params.min_goal_time_s,
            self.params.goal_time_factor * plan.remaining_m / self.limits.max_linear_speed_mps,
        )

    def track(self, plan: Plan) -> None:
        """Measure path progress along ``plan`` from its start (the robot's position): a
        replanned route may be longer than the rest of the old one without anything wrong."""
        self._path_watch.track_path(plan.remaining_m)

    # ------------------------------------------------------------------ following
    def follow(
        self,
        plan: Plan,
        grid: np.ndarray,
        pose: tuple[float, float, float],
        scan: np.ndarray,
        now_s: float,
    ) -> tuple[float, float, bool]:
        """One step along ``plan``: ``(v_mps, omega_radps, escaping)``."""
        prm = self.params
        if self.tight(plan):
            self.counts.tight_steps += 1
            v, w = self._tight_command(plan, pose, scan)
            self.last_command = None
            self.advance_progress(plan, pose)
            self._still_s = 0.0
            return v, w, False
        escaping = now_s < self._escape_until_s
        cmd = PotentialFieldFollower(self.limits, prm.potential_field).command(
            scan,
            pose,
            plan.path_m,
            grid,
            self.geometry,
            start_index=plan.progress,
            repulsion_scale=prm.escape_repulsion_scale if escaping else 1.0,
        )
        self.last_command = cmd
        self.advance_progress(plan, pose)
        if not escaping:
            if cmd.v_mps < STILL_SPEED_FRACTION * self.limits.max_linear_speed_mps:
                self._still_s += self.dt_s
            else:
                self._still_s = 0.0
            if prm.local_min_escape and self._still_s >= prm.local_min_timeout_s:
                self._still_s = 0.0
                self._escape_until_s = now_s + prm.escape_duration_s
                self.counts.escapes += 1
                self.log("escape", f"goal={plan.goal_xy_m}")
        return cmd.v_mps, cmd.omega_radps, escaping

    def tight(self, plan: Plan) -> bool:
        """A narrow plan (``narrow_passages``, ``room_beyond_gap``: one that carries its path's
        clearance) whose next stretch has less than the planners' clearance on the map (the
        expert then holds its periodic replans: a plan from inside the passage would hand the
        robot back to the potential field)."""
        along = plan.path_clearance_m
        if along is None:
            return False
        n = int(math.ceil(TIGHT_LOOKAHEAD_M / self.geometry.resolution_m)) + 1
        ahead = along[plan.progress : plan.progress + n]
        planners_m = self.limits.radius_m + self.params.clearance_margin_m
        return ahead.size > 0 and float(ahead.min()) < planners_m - 1e-9

    def _tight_command(
        self, plan: Plan, pose: tuple[float, float, float], scan: np.ndarray
    ) -> tuple[float, float]:
        """Slow, exact tracking of ``plan``, centred between the walls the scan measures."""
        prm = self.params
        if self._angles is None or len(self._angles) != len(scan):
            self._angles = beam_angles_rad(len(scan))
        heading = path_heading_rad(plan.path_m, plan.progress + 1)
        shift = scan_centring_offset_m(
            scan,
            self._angles,
            min_range_m=self.min_range_m,
            reach_m=prm.tight_centring_range_m,
            left_rad=heading - pose[2] + 0.5 * math.pi,
        )
        # The scan corrects the map's placement of the walls (a wall hit on a cell border may
        # mark the free cell beside it), by a cell at most.
        cell_m = self.geometry.resolution_m
        shift = float(np.clip(shift, -cell_m, cell_m))
        v, w = tight_tracking_command(pose, plan.path_m, plan.progress, self._tracking, shift)
        # No step forward that would bring the body within a few millimetres of a return.
        v = min(
            v,
            safe_forward_speed_mps(
                scan,
                self._angles,
                radius_m=self.limits.radius_m,
                dt_s=self.dt_s,
                spare_m=TIGHT_MIN_SPARE_M,
            ),
        )
        return v, w

    def advance_progress(self, plan: Plan, pose: tuple[float, float, float]) -> None:
        """Move ``plan.progress`` to the nearest path point a short window ahead."""
        lo = plan.progress
        ahead = int(math.ceil(PROGRESS_WINDOW_M / self.geometry.resolution_m)) + 1
        hi = min(len(plan.path_m), lo + ahead)
        seg = plan.path_m[lo:hi]
        d = np.hypot(seg[:, 0] - pose[0], seg[:, 1] - pose[1])
        i = int(np.argmin(d))
        if d[i] <= PROGRESS_SNAP_M:
            plan.progress = lo + i

    # ------------------------------------------------------------------ stuck handling
    def watch(
        self,
        plan: Plan,
        pose: tuple[float, float, float],
        now_s: float,
        known_cells: int,
        rng: np.random.Generator,
    ) -> bool:
        """Watch progress towards ``plan``'s goal (with ``stuck_recovery``); True when stuck,
        and a back-off recovery has started."""
        if not self.params.stuck_recovery:
            return False
        stuck = self._motion_watch.update(now_s, (pose[0], pose[1]), known_cells)
        self._path_watch.update(now_s, known_cells=known_cells, remaining_m=plan.remaining_m)
        overdue = now_s - self.goal_since_s > self.goal_budget_s
        if overdue:
            # Moving, but not getting there (a limit cycle round clutter, a path that keeps
            # changing): treat it as a failed approach, so the goal is retried another way.
            self.counts.goal_timeouts += 1
            self.log("goal_timeout", f"goal={plan.goal_xy_m}")
        if not (stuck or self._path_watch.stalled(now_s) or overdue):
            return False
        self.goal_since_s, self.goal_budget_s = now_s, math.inf
        self.counts.recoveries += 1
        self.log("recovery", f"goal={plan.goal_xy_m}")
        self._backoff.start(now_s, rng)
        until_s = now_s + self.params.backoff_duration_s
        self._motion_watch.hold(until_s, known_cells)
        self._path_watch.hold(until_s, known_cells)
        self._still_s = 0.0
        return True

    def recovering(self, now_s: float) -> bool:
        """A back-off recovery is under way."""
        return self._backoff.active(now_s)

    def recovery_ended(self) -> bool:
        """True once, at the first call after a recovery ended."""
        return self._backoff.finish()

    def recovery_command(
        self, grid: np.ndarray, pose: tuple[float, float, float], scan: np.ndarray
    ) -> tuple[float, float]:
        """The back-off's ``(v_mps, omega_radps)`` for this step."""
        if self._angles is None or len(self._angles) != len(scan):
            self._angles = beam_angles_rad(len(scan))
        return self._backoff.command(
            grid,
            self.geometry,
            pose,
            scan,
            self._angles,
            self.limits,
            self.params.potential_field,
        )
