"""The oracle explorer: a full-knowledge coverage tour, driven by the expert's navigation stack.

**Privileged.** Unlike every other policy, the oracle reads the true world: the
:class:`~semexplore_gym.core.coverage_tour.problem.PrivilegedWorld` that an env made with
``privileged=True`` puts in the ``info`` of ``reset`` (``info["privileged_world"]``; the mission
runners ask for it through :func:`semexplore_gym.evaluation.rollout.map_observation_for`, which
reads :attr:`OraclePolicy.privileged`). Any other env makes :meth:`OraclePolicy.reset` raise, so
the oracle cannot slip into learning code: ``make_expert`` refuses it unless a training run
sets ``expert.privileged_teacher=true`` by name, and then only the teacher's env is privileged
(the learner's env never is). It is a yardstick, not an explorer: its times are what a robot
that knew the building could do with this sensor and this navigation stack.

At ``reset`` it plans the static tour of :func:`~semexplore_gym.core.coverage_tour.plan_coverage_tour`
(viewpoints whose scans, with the scans along the legs between them, see 99.3 % of the reachable
mask; an open LKH tour from the start, viewpoints dropped and moved while the tour shortens; the
legs are the paths it drives, so the tour's path cost is the oracle's own). While it drives:

* every ``check_period_s`` it counts, for each viewpoint left, the cells of its visible set the
  live map (``obs["map"]``) has not mapped FREE yet. When some viewpoint is no longer needed, it
  reruns the greedy cover on what is still unseen and drives the rest of the tour the sensor
  model predicts to see what the tour's target needs soonest, the scans along its legs counted
  (:func:`~semexplore_gym.policies.oracle_goals.best_rest_of_tour`);
* it drives to each viewpoint along a shortest path on the true standing mask that keeps off
  the walls, followed by the semantic expert's modified potential field
  (:func:`~semexplore_gym.core.planning.potential_field.potential_field_command`, the expert's
  parameters) with the expert's stuck recovery (:class:`~semexplore_gym.policies.navigation.BackoffRecovery`,
  :class:`~semexplore_gym.policies.navigation.ProgressWatch`); a viewpoint not reached within
  its time budget is dropped;
* near the end (fewer than ``finish_max_share`` of the cells still to see) it takes a
  shortcut when one exists: the nearest candidate whose one scan would see what the goal still
  needs, with ``finish_slack`` to spare, when it is nearer than the rest of the tour;
* when the tour runs out below the goal it drives to the nearest standing cell near a cell
  still unseen; it stops once ``info["coverage"]`` reaches the env's coverage goal, or nothing
  is left to see.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace
from typing import Any

import numpy as np
from semexplore_gym.policies.base import DriveIntent, Policy, StepStats, read_env_facts
from semexplore_gym.policies.navigation import BackoffRecovery, ProgressWatch
from semexplore_gym.policies.oracle_goals import (
    best_rest_of_tour,
    fallback_cell,
    open_order_from,
    repair_cell,
    shortcut_cell,
)
from semexplore_gym.policies.oracle_params import OracleParams

from semexplore_gym.core.coverage_tour import (
    PRIVILEGED_INFO_KEY,
    CoverageTour,
    PrivilegedWorld,
    TourParams,
    greedy_cover,
    plan_coverage_tour,
)
from semexplore_gym.core.coverage_tour.tour import row_counts
from semexplore_gym.core.coverage_tour.viewpoints import (
    nearest_allowed_cell,
    wall_clearance_m,
)
from semexplore_gym.core.grid import FREE
from semexplore_gym.core.planning.grid_scan import known_cell_count
from semexplore_gym.core.planning.grid_search import distance_field, shortest_path_cells
from semexplore_gym.core.planning.path_tracking import (
    TightTracking,
    path_clearance_ahead_m,
    tight_tracking_command,
)
from semexplore_gym.core.planning.potential_field import (
    RobotLimits,
    beam_angles_rad,
    potential_field_command,
    resample_polyline,
)

__all__ = ["OracleParams", "OraclePolicy", "PrivilegedPolicyError", "refuse_privileged"]

_NOT_PRIVILEGED = (
    "the oracle is a privileged policy: it needs the true world, which only an env made with "
    "privileged=True hands out (info['privileged_world'] at reset); the mission runners "
    "(semexplore explore/benchmark) do that for it, learning code only with "
    "expert.privileged_teacher=true"
)


class PrivilegedPolicyError(ValueError):
    """A privileged policy was used where only honest policies belong."""


def refuse_privileged(policy: Any, where: str, hint: str = "") -> None:
    """Raise :class:`PrivilegedPolicyError` when ``policy`` reads ground truth (learning code).

    ``hint`` (optional) ends the message: how the caller lets it in when asked explicitly.
    """
    if getattr(policy, "privileged", False):
        raise PrivilegedPolicyError(
            f"{where}: policy {getattr(policy, 'name', policy)!r} is privileged (reads the true "
            "world) and cannot be used here" + (f"; {hint}" if hint else "")
        )


class OraclePolicy(Policy):
    """PRIVILEGED full-knowledge explorer (see the module docstring): reads the true world from
    ``info["privileged_world"]`` of a ``privileged=True`` env and drives a precomputed coverage
    tour with the expert's navigation stack. A benchmark yardstick, never a learner's teacher.

    Args:
        params: Parameters (default :class:`OracleParams`).
    """

    name = "oracle"
    #: Reads ground truth: runners make its env with ``privileged=True``; learning code refuses it
    #: unless asked (``expert.privileged_teacher``).
    privileged = True
    reads_map_in_step_only = True

    def __init__(self, params: OracleParams | None = None) -> None:
        super().__init__()
        self.params = params if params is not None else OracleParams()
        self.tour: CoverageTour | None = None
        self.counters: dict[str, int] = {}

    # ------------------------------------------------------------------ lifecycle
    def reset(
        self, obs: dict[str, np.ndarray], info: dict[str, Any], seed: int | None = None
    ) -> None:
        super().reset(obs, info, seed=seed)
        facts = info.get(PRIVILEGED_INFO_KEY)
        if not isinstance(facts, PrivilegedWorld):
            raise PrivilegedPolicyError(_NOT_PRIVILEGED)
        env = read_env_facts(info, type(self).__name__)
        prm = self.params
        self.facts = facts
        self.geometry = env.geometry
        self.dt_s = env.dt_s
        self.limits = RobotLimits(
            radius_m=env.radius_m,
            max_linear_speed_mps=env.max_linear_speed_mps,
            max_angular_speed_radps=env.max_angular_speed_radps,
            max_range_m=env.max_range_m,
        )
        t0 = time.perf_counter()
        tour_params = replace(
            prm.tour,
            leg_prefer_clearance_m=prm.path_prefer_clearance_m,
            leg_wall_cost=prm.path_wall_cost,
        )
        self.tour = tour = self.plan_tour(facts, tour_params)
        self.planning_s = time.perf_counter() - t0
        res = self.geometry.resolution_m
        clearance = wall_clearance_m(facts.world, self.geometry, prm.path_prefer_clearance_m)
        self._clearance_m = clearance
        self._tight_below_m = env.radius_m + prm.tight_margin_m
        self._tracking = TightTracking(
            lookahead_m=prm.tight_track_lookahead_m,
            speed_mps=min(prm.tight_speed_mps, env.max_linear_speed_mps),
            max_omega_radps=env.max_angular_speed_radps,
            turn_in_place_rad=prm.tight_turn_in_place_rad,
        )
        pref = np.clip(1.0 - clearance / prm.path_prefer_clearance_m, 0.0, 1.0)
        self._drive_cost = np.where(tour.standing, res * (1.0 + prm.path_wall_cost * pref), np.inf)
        self._geo_cost = np.where(tour.standing, res, np.inf)
        self._left: list[int] = list(range(tour.n_viewpoints))
        self._tried: set[tuple[int, int]] = set()
        self._kept_useless: frozenset[int] = frozenset()
        self._goal_xy: tuple[float, float] | None = None
        self._goal_rc: tuple[int, int] | None = None
        self._goal_kind = ""
        # The cell the tour's prediction drives the next tour leg from (None: from the robot).
        self._leg_from: tuple[int, int] | None = self._robot_cell(
            (float(obs["pose"][0]), float(obs["pose"][1]), float(obs["pose"][2]))
        )
        self._path: np.ndarray | None = None
        self._progress = 0
        self._time_s = 0.0
        self._next_check_s = 0.0
        self._goal_since_s = 0.0
        self._goal_budget_s = math.inf
        self._angles: np.ndarray | None = None
        self._n_mask = max(1, tour.mask_flat.size)
        self.counters = {
            "viewpoints": tour.n_viewpoints,
            "reached": 0,
            "skipped": 0,
            "timeouts": 0,
            "reorders": 0,
            "recoveries": 0,
            "fallback_goals": 0,
            "tight_steps": 0,
            "shortcuts": 0,
            "repairs": 0,
        }
        self._backoff = BackoffRecovery(prm.backoff_duration_s, prm.backoff_speed_fraction)
        self._watch = ProgressWatch(
            prm.stuck_timeout_s, radius_m=prm.stuck_radius_m, min_new_cells=20
        )
        self._watch.reset(
            0.0, (float(obs["pose"][0]), float(obs["pose"][1])), known_cell_count(obs["map"])
        )

    def plan_tour(self, facts: PrivilegedWorld, tour_params: TourParams) -> CoverageTour:
        """The tour :meth:`reset` drives: the static coverage tour of ``facts`` (the team
        oracle's members drive their share of the team's instead)."""
        return plan_coverage_tour(facts, tour_params)

    def mission_metrics(self) -> dict[str, Any]:
        t = self.tour
        return {
            "oracle_tour_m": None if t is None else round(t.length_m, 3),
            "oracle_viewpoints": None if t is None else t.n_viewpoints,
        }

    def drive_intent(self) -> DriveIntent:
        """The viewpoint (or fallback cell) driven to; mode ``"recovery"`` while backing off."""
        # act has advanced the clock: the step it chose began one period earlier.
        backing_off = self._backoff.active(self._time_s - self.dt_s)
        return DriveIntent(self._goal_xy, "recovery" if backing_off else "goal")

    # ------------------------------------------------------------------ stepping
    def act(self, obs: dict[str, np.ndarray], info: dict[str, Any]) -> np.ndarray:
        t_start = time.perf_counter()
        stats = StepStats()
        self.last_stats = stats
        if self.done:
            return np.zeros(2, dtype=np.float32)
        grid = obs["map"]
        p = obs["pose"]
        pose = (float(p[0]), float(p[1]), float(p[2]))
        scan = np.asarray(obs["scan"], dtype=np.float64)
        if self._angles is None or len(self._angles) != len(scan):
            self._angles = beam_angles_rad(len(scan))
        if float(info.get("coverage", 0.0)) >= self.facts.coverage_goal:
            return self._stop("coverage_goal")
        if self._backoff.active(self._time_s):
            v, w = self._backoff_command(grid, pose, scan)
        else:
            if self._backoff.finish():
                self._path = None  # replan the way to the goal from here
            t_plan = time.perf_counter()
            self._update_goal(grid, pose)
            stats.global_planning_ms = (time.perf_counter() - t_plan) * 1e3
            if self.done:
                return np.zeros(2, dtype=np.float32)
            v, w = self._follow(grid, pose, scan)
            self._watch_progress(grid, pose)
            if self._backoff.active(self._time_s):
                v, w = self._backoff_command(grid, pose, scan)
        self._time_s += self.dt_s
        stats.local_planning_ms = max(
            0.0, (time.perf_counter() - t_start) * 1e3 - stats.global_planning_ms
        )
        lim = self.limits
        return np.array(
            [
                np.clip(v / lim.max_linear_speed_mps, -1, 1),
                np.clip(w / lim.max_angular_speed_radps, -1, 1),
            ],
            dtype=np.float32,
        )

    def _stop(self, reason: str) -> np.ndarray:
        self.done = True
        self.stop_reason = reason
        return np.zeros(2, dtype=np.float32)

    # ------------------------------------------------------------------ goals
    def _unseen(self, grid: np.ndarray) -> np.ndarray:
        """Per reachable-mask cell (``tour.mask_flat`` order): not yet mapped FREE."""
        assert self.tour is not None
        return np.asarray(grid).reshape(-1)[self.tour.mask_flat] != FREE

    def _update_goal(self, grid: np.ndarray, pose: tuple[float, float, float]) -> None:
        prm = self.params
        if self._goal_xy is not None:
            d = math.hypot(pose[0] - self._goal_xy[0], pose[1] - self._goal_xy[1])
            if d <= prm.goal_reached_radius_m:
                self.counters["reached"] += 1
                passed = self._left[0] if self._goal_kind == "tour" and self._left else None
                self._leg_from = self._goal_rc if passed is not None else None
                self._drop_goal()
                if passed is not None:
                    self._repair(grid, pose, passed)
            elif self._time_s - self._goal_since_s > self._goal_budget_s:
                self.counters["timeouts"] += 1
                self._leg_from = None
                self._drop_goal()
        if self._goal_xy is None or self._time_s >= self._next_check_s - 1e-9:
            self._next_check_s = self._time_s + prm.check_period_s
            self._prune(grid, pose)
            if self._goal_kind not in ("finish", "repair"):
                self._shortcut(grid, pose)
        if self._goal_xy is None:
            self._next_goal(grid, pose)

    def _drop_goal(self) -> None:
        if self._goal_kind == "tour" and self._left:
            self._left.pop(0)
        self._goal_xy = self._goal_rc = None
        self._path = None

    def _prune(self, grid: np.ndarray, pose: tuple[float, float, float]) -> None:
        """Drop the viewpoints the live map has made unnecessary; reorder the rest."""
        tour = self.tour
        if tour is None or not self._left:
            return
        unseen = self._unseen(grid)
        sub = tour.visible[self._left]
        gains = row_counts(unseen, sub.indptr, sub.indices)
        useless = frozenset(np.asarray(self._left)[gains < self.params.min_gain_cells].tolist())
        if not useless or useless == self._kept_useless:
            return  # none to drop, or the same ones the last check chose to keep
        # Drop only what the others make redundant: the live map lags the static prediction
        # (the robot passes near a viewpoint, not on it), so no margin is given away here.
        coverable = ~unseen
        coverable[sub.indices] = True
        kept = [self._left[i] for i in sorted(greedy_cover(sub, int(coverable.sum()), ~unseen))]
        here = self._robot_cell(pose)
        dist, _ = distance_field(self._geo_cost, here)
        routes = [kept, open_order_from(tour, dist, kept, self.params.tour.lkh_runs), self._left]
        chosen = self._best_route(here, dist, routes, unseen)
        self.counters["skipped"] += len(self._left) - len(chosen)
        self._left = chosen
        self._kept_useless = useless & frozenset(chosen)
        self.counters["reorders"] += 1
        if self._goal_kind == "tour" and (not chosen or self._goal_rc != self._rc(chosen[0])):
            self._goal_xy = self._goal_rc = None
            self._path = None
        if self._goal_xy is None:
            self._leg_from = here  # the chosen rest was judged from here

    def _repair(self, grid: np.ndarray, pose: tuple[float, float, float], vp: int) -> None:
        """At a viewpoint just reached: look again from nearby where its scan fell short."""
        assert self.tour is not None
        prm = self.params
        rc = repair_cell(
            self.tour,
            self._unseen(grid),
            vp,
            self._left,
            lambda: distance_field(self._geo_cost, self._robot_cell(pose))[0],
            (prm.repair_min_cells, prm.repair_radius_m),
        )
        if rc is not None and rc not in self._tried:
            self._tried.add(rc)
            if self._set_goal(rc, "repair", pose):
                self.counters["repairs"] += 1

    def _shortcut(self, grid: np.ndarray, pose: tuple[float, float, float]) -> None:
        """Near the end, a shortcut to the goal when one is nearer than the rest of the tour."""
        assert self.tour is not None
        unseen = self._unseen(grid)
        need = math.ceil(self.facts.coverage_goal * self._n_mask) - int((~unseen).sum())
        if need > self.params.finish_max_share * self._n_mask:
            return
        rc = shortcut_cell(
            self.tour,
            unseen,
            need,
            self._left,
            lambda: distance_field(self._geo_cost, self._robot_cell(pose))[0],
            self.params.finish_slack,
        )
        if rc is not None and rc not in self._tried:
            self._tried.add(rc)
            if self._set_goal(rc, "finish", pose):
                self.counters["shortcuts"] += 1

    def _rc(self, vp: int) -> tuple[int, int]:
        assert self.tour is not None
        r, c = self.tour.viewpoints_rc[vp]
        return int(r), int(c)

    def _best_route(
        self, here: tuple[int, int], dist: np.ndarray, routes: list[list[int]], unseen: np.ndarray
    ) -> list[int]:
        """The rest of the tour to drive (:func:`~.oracle_goals.best_rest_of_tour`)."""
        assert self.tour is not None
        need = math.ceil(self.params.tour.coverage_target * self._n_mask) - int((~unseen).sum())
        return best_rest_of_tour(self.tour, here, dist, routes, unseen, need)

    def _robot_cell(self, pose: tuple[float, float, float]) -> tuple[int, int]:
        assert self.tour is not None
        try:
            return nearest_allowed_cell(self.tour.standing, self.geometry, pose[:2])
        except ValueError:
            r, c = (int(v) for v in self.geometry.world_to_grid(pose[0], pose[1]))
            return r, c

    def _next_goal(self, grid: np.ndarray, pose: tuple[float, float, float]) -> None:
        tour = self.tour
        assert tour is not None
        while self._left:
            rc = self._rc(self._left[0])
            if self._set_goal(rc, "tour", pose):
                return
            self._left.pop(0)
            self.counters["skipped"] += 1
        rc_fb = self._fallback_cell(grid, pose)
        if rc_fb is None or not self._set_goal(rc_fb, "fallback", pose):
            self._stop("nothing_left_to_see")
            return
        self.counters["fallback_goals"] += 1

    def _fallback_cell(
        self, grid: np.ndarray, pose: tuple[float, float, float]
    ) -> tuple[int, int] | None:
        """The candidate viewpoint that would see the most still-unseen reachable cells per
        metre of path (never one tried before), or None when none would see any."""
        tour = self.tour
        assert tour is not None
        unseen = self._unseen(grid)
        if not unseen.any() or self.counters["fallback_goals"] >= self.params.max_fallback_goals:
            return None
        rc = fallback_cell(
            tour,
            unseen,
            math.ceil(self.facts.coverage_goal * self._n_mask) - int((~unseen).sum()),
            self._tried,
            distance_field(self._geo_cost, self._robot_cell(pose))[0],
            self.params.min_gain_cells,
        )
        if rc is not None:
            self._tried.add(rc)
        return rc

    def _set_goal(self, rc: tuple[int, int], kind: str, pose: tuple[float, float, float]) -> bool:
        leg_from, self._leg_from = self._leg_from, None
        path = None
        if kind == "tour" and leg_from is not None and self.params.drive_planned_legs:
            path = self._planned_leg(leg_from, rc, pose)
        if path is None:
            path = self._plan_path(rc, pose)
        if path is None:
            return False
        x, y = self.geometry.grid_to_world(rc[0], rc[1])
        self._goal_xy, self._goal_rc, self._goal_kind = (float(x), float(y)), rc, kind
        self._goal_since_s = self._time_s
        length = float(np.hypot(*np.diff(path, axis=0).T).sum()) if len(path) > 1 else 0.0
        self._goal_budget_s = max(
            self.params.min_goal_time_s,
            self.params.goal_time_factor * length / self.limits.max_linear_speed_mps,
        )
        return True

    def _planned_leg(
        self, leg_from: tuple[int, int], rc: tuple[int, int], pose: tuple[float, float, float]
    ) -> np.ndarray | None:
        """The tour's leg from ``leg_from`` to ``rc`` (the cells its scans were counted on),
        from the robot's pose; None when the robot is not at ``leg_from``'s cell or beside it."""
        tour = self.tour
        assert tour is not None and tour.legs is not None
        here = self._robot_cell(pose)
        reach = self.params.goal_reached_radius_m / self.geometry.resolution_m + 1.0
        if math.hypot(here[0] - leg_from[0], here[1] - leg_from[1]) > reach:
            return None
        cells = tour.legs.path(leg_from, rc)
        if cells is None:
            return None
        return self._drive_along(cells, pose)

    def _plan_path(
        self, rc: tuple[int, int], pose: tuple[float, float, float]
    ) -> np.ndarray | None:
        here = self._robot_cell(pose)
        found = shortest_path_cells(self._drive_cost, here, rc)
        if found is None:
            return None
        cells, _ = found
        return self._drive_along(cells, pose)

    def _drive_along(self, cells: np.ndarray, pose: tuple[float, float, float]) -> np.ndarray:
        """Follow the path through ``cells`` from the robot's pose, from its start."""
        xs, ys = self.geometry.grid_to_world(cells[:, 0], cells[:, 1])
        pts = np.vstack([[pose[0], pose[1]], np.column_stack([xs, ys])])
        self._path = resample_polyline(pts, self.geometry.resolution_m)
        self._progress = 0
        return self._path

    # ------------------------------------------------------------------ driving
    def _follow(
        self, grid: np.ndarray, pose: tuple[float, float, float], scan: np.ndarray
    ) -> tuple[float, float]:
        if self._path is None:
            assert self._goal_rc is not None
            if self._plan_path(self._goal_rc, pose) is None:
                self._drop_goal()
                return 0.0, 0.0
        path = self._path
        assert path is not None
        if self._in_tight_passage(pose, path):
            self.counters["tight_steps"] += 1
            v, w = tight_tracking_command(pose, path, self._progress, self._tracking)
            self._advance_progress(pose)
            return v, w
        cmd = potential_field_command(
            scan,
            pose,
            path,
            grid,
            self.geometry,
            self.limits,
            self.params.potential_field,
            start_index=self._progress,
        )
        self._advance_progress(pose)
        return cmd.v_mps, cmd.omega_radps

    def _in_tight_passage(self, pose: tuple[float, float, float], path: np.ndarray) -> bool:
        """The true clearance at the robot or along the next stretch of path is tight."""
        geo = self.geometry
        n = int(math.ceil(self.params.tight_lookahead_m / geo.resolution_m)) + 1
        stretch = np.vstack([[pose[0], pose[1]], path[self._progress : self._progress + n]])
        rows, cols = geo.world_to_grid(stretch[:, 0], stretch[:, 1])
        h, w = geo.shape
        ok = (rows >= 0) & (rows < h) & (cols >= 0) & (cols < w)
        ahead = path_clearance_ahead_m(self._clearance_m, rows[ok], cols[ok])
        return ahead < self._tight_below_m

    def _advance_progress(self, pose: tuple[float, float, float]) -> None:
        path = self._path
        assert path is not None
        lo = self._progress
        hi = min(len(path), lo + int(math.ceil(1.5 / self.geometry.resolution_m)) + 1)
        d = np.hypot(path[lo:hi, 0] - pose[0], path[lo:hi, 1] - pose[1])
        i = int(np.argmin(d))
        if d[i] <= 0.5:
            self._progress = lo + i
        else:
            self._path = None  # far off the path: plan again from here next step

    def _watch_progress(self, grid: np.ndarray, pose: tuple[float, float, float]) -> None:
        if self._watch.update(self._time_s, (pose[0], pose[1]), known_cell_count(grid)):
            self.counters["recoveries"] += 1
            self._backoff.start(self._time_s, self.rng)
            self._watch.hold(self._time_s + self.params.backoff_duration_s, known_cell_count(grid))

    def _backoff_command(
        self, grid: np.ndarray, pose: tuple[float, float, float], scan: np.ndarray
    ) -> tuple[float, float]:
        assert self._angles is not None
        return self._backoff.command(
            grid, self.geometry, pose, scan, self._angles, self.limits, self.params.potential_field
        )

    def overlay(self) -> dict[str, Any]:
        out: dict[str, Any] = {"text": f"oracle (privileged): {len(self._left)} viewpoint(s) left"}
        if self._goal_xy is not None:
            out["goal_m"] = self._goal_xy
        if self._path is not None:
            out["paths_m"] = [self._path]
        if self.tour is not None and self._left:
            out["frontiers_m"] = [tuple(self.tour.viewpoints_xy_m[i]) for i in self._left]
        return out
