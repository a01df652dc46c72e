"""The semantic expert's goal persistence: retries, dropped goals that come back, looks at
narrow frontiers, and the stop rule (issue #13: never give up on a reachable frontier).

:class:`GoalPersistence` is a mixin of :class:`~semexplore_gym.policies.semantic_expert.SemanticExpertPolicy`:
it holds the methods that decide what happens when the approach to a goal fails, when a goal is
reached without clearing its frontier, and when no frontier is left. The parameters are
documented in :mod:`semexplore_gym.policies.semantic_expert_params`.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
from semexplore_gym.policies.navigation.approaches import side_approach
from semexplore_gym.policies.navigation.frontier_memory import FrontierMemory

from semexplore_gym.core.frontiers.reachable import (
    FrontierFilter,
    clearance_field_m,
    grid_path_to,
    nearest_reachable_frontier,
    pocket_exit_path,
)
from semexplore_gym.core.planning.potential_field import resample_polyline

if TYPE_CHECKING:
    from semexplore_gym.policies.semantic_expert import _Plan

__all__ = ["GoalPersistence"]

#: Lattice of the robot's trail (metres per cell).
TRAIL_CELL_M = 0.25

#: Narrow frontiers checked against the trail before one is worth driving to.
_MAX_LOOK_CANDIDATES = 8


class GoalPersistence:
    """Mixin: failed approaches are retried, dropped goals come back, narrow frontiers get a
    look, and the mission stops only when the grid check finds nothing reachable."""

    # Provided by the policy class this is mixed into.
    params: Any
    geometry: Any
    clearance_m: float
    limits: Any
    counters: dict[str, int]
    memory: FrontierMemory
    blacklist: Any
    _plan: Any
    _retry: tuple[tuple[float, float], int, tuple[float, float]] | None
    _reaches: list[tuple[float, float, int]]
    _trail: set[tuple[int, int]]

    if TYPE_CHECKING:

        def _log(self, event: str, detail: str = "") -> None: ...
        def request_replan(self) -> None: ...
        def _fallback_search_kwargs(self) -> dict[str, Any]: ...
        def _unknown_near(
            self, grid: np.ndarray, xy: tuple[float, float], radius_m: float
        ) -> bool: ...

    def _new_memory(self) -> FrontierMemory:
        prm = self.params
        return FrontierMemory(
            prm.blacklist_radius_m,
            prm.revive_window_m,
            prm.revive_min_changed_cells,
            prm.max_revivals,
            prm.max_goal_attempts,
        )

    def _drop(self, grid: np.ndarray, xy_m: tuple[float, float], reason: str) -> None:
        """Give up on the goal at ``xy_m`` until the map round it changes."""
        self.memory.drop(xy_m, reason, grid, self.geometry)
        self.blacklist.points_m[:] = self.memory.active_points()
        self.counters["blacklisted"] += 1
        self._log("blacklist", f"{reason}: {xy_m}")

    def _goal_failed(self, grid: np.ndarray, pose: tuple[float, float, float]) -> None:
        """A stuck recovery ended: retry the goal by another approach, or drop it."""
        plan = self._plan
        self._plan = None
        self.request_replan()
        if plan is None:
            return
        # A retry's target may be a point beside the goal: the goal itself is what failed.
        goal = (
            plan.frontier_xy_m if plan.source == "retry" and plan.frontier_xy_m else plan.goal_xy_m
        )
        n, failed_at = self.memory.record_failure(goal, (pose[0], pose[1]))
        if n >= self.params.max_goal_attempts or plan.source == "look":
            self._retry = None
            self._drop(grid, goal, "attempts")
            return
        self._retry = (goal, n, failed_at)
        self.counters["retries"] += 1
        self._log("retry", f"attempt {n + 1} at {goal}")

    def _on_goal_reached(self, grid: np.ndarray, plan: _Plan) -> None:
        if plan.source == "retry":
            self._retry = None
        if plan.source == "look" and plan.frontier_xy_m is not None:
            # Looked from close by and the frontier is still there: the gap stays closed.
            self.counters["looks"] += 1
            self._drop(grid, plan.frontier_xy_m, "looked")
        elif self.params.reach_blacklist:
            self._register_reach(grid, plan.goal_xy_m)

    def _register_reach(self, grid: np.ndarray, goal: tuple[float, float]) -> None:
        r = self.params.blacklist_radius_m
        for i, (x, y, n) in enumerate(self._reaches):
            if math.hypot(goal[0] - x, goal[1] - y) <= r:
                self._reaches[i] = (x, y, n + 1)
                if n + 1 >= self.params.max_goal_reaches:
                    self._reaches[i] = (x, y, 0)
                    self._drop(grid, (x, y), "reached")
                return
        self._reaches.append((goal[0], goal[1], 1))
        if self.params.max_goal_reaches <= 1:
            self._drop(grid, goal, "reached")

    def _revive_dropped(self, grid: np.ndarray) -> None:
        back = self.memory.revive(grid, self.geometry)
        if back:
            self.blacklist.points_m[:] = self.memory.active_points()
            self.counters["revived"] += len(back)
            for xy in back:
                self._log("revive", f"map changed round {xy}")

    def _retry_plan(
        self, grid: np.ndarray, pose: tuple[float, float, float]
    ) -> tuple[_Plan | None, np.ndarray | None]:
        """The next approach to a failed goal: a grid route, then another side (or drop it)."""
        assert self._retry is not None
        goal, n, failed_at = self._retry
        res_m = self.geometry.resolution_m
        if not self._unknown_near(grid, goal, self.params.goal_check_radius_m):
            self._retry = None  # its frontier got mapped meanwhile
            return None, None
        clearance = clearance_field_m(grid, res_m)
        target, path = goal, None
        if n == 1:
            path = grid_path_to(
                grid, self.geometry, pose[:2], goal, self.clearance_m, clearance_field=clearance
            )
        else:
            found = side_approach(
                grid, self.geometry, pose[:2], goal, failed_at, self.clearance_m, clearance
            )
            if found is not None:
                target, path = found
        if path is None:
            # The grid planner finds no way for the robot's disc: the goal is unreachable now.
            self._retry = None
            self._drop(grid, goal, "grid")
            return None, clearance
        from semexplore_gym.policies.semantic_expert import _Plan

        plan = _Plan("retry", target, resample_polyline(path, res_m), None, frontier_xy_m=goal)
        return plan, clearance

    def _look_plan(
        self, grid: np.ndarray, pose: tuple[float, float, float], clearance: np.ndarray
    ) -> _Plan | None:
        """Before stopping: drive towards a frontier too narrow to reach, to look again.

        The grid fallback already found no frontier the robot's disc can reach. A frontier that
        a thinner robot (``look_clearance_fraction`` of the clearance) could reach is a gap
        narrower than the robot *at first sight* (a door seen at a grazing angle, a passage
        seen through a narrow slot); leaks through rasterised walls, one or two cells wide, are
        not. The robot follows the thin robot's path as far as its own clearance allows, and
        looks from there, once per place; if the robot already passed within
        ``look_seen_radius_m`` of the frontier it had its look, and the frontier is dropped.
        """
        prm = self.params
        res_m = self.geometry.resolution_m
        if self.counters["look_drives"] >= prm.max_look_drives:
            return None
        for _ in range(_MAX_LOOK_CANDIDATES):
            found = nearest_reachable_frontier(
                grid,
                self.geometry,
                pose[:2],
                self.clearance_m * prm.look_clearance_fraction,
                FrontierFilter(
                    min_frontier_cells=max(1, math.ceil(prm.look_min_frontier_m / res_m - 1e-9)),
                    min_unknown_depth_cells=prm.look_min_unknown_depth_m / res_m,
                    reach_m=prm.fallback_reach_m,
                    excluded_xy_m=self.memory.active_points(),
                    excluded_radius_m=prm.blacklist_radius_m,
                ),
                clearance_field=clearance,
            )
            if found is None:
                return None
            path = self._standable_prefix(found.path_m, clearance)
            near = math.dist(tuple(path[-1]), found.frontier_xy_m) <= prm.look_reach_m
            if (
                len(path) >= 2
                and near
                and not self._been_near(found.frontier_xy_m, prm.look_seen_radius_m)
            ):
                from semexplore_gym.policies.semantic_expert import _Plan

                plan = _Plan("look", (float(path[-1, 0]), float(path[-1, 1])), path, None)
                plan.frontier_xy_m = found.frontier_xy_m
                self.counters["look_drives"] += 1
                return plan
            self.counters["looks"] += 1
            self._drop(grid, found.frontier_xy_m, "looked")
        return None

    def _pocket_escape_plan(
        self, grid: np.ndarray, pose: tuple[float, float, float], clearance: np.ndarray
    ) -> _Plan | None:
        """The grid check found nothing: if the robot stands in a pocket, check from outside it.

        The potential field may leave the robot nearer a wall than the planner's clearance, in a
        spot that a gap narrower than the clearance cuts off from the rest of the usable map;
        the check, which starts where the robot stands, then sees only that pocket. The robot
        fits where it stands, so it leaves over cells with the clearance of its radius plus
        ``pocket_clearance_margin_m`` to the nearest region that is not a pocket, and the check
        runs again from there with the full clearance (see
        :mod:`semexplore_gym.policies.semantic_expert_params`). The plan is both legs; none when the check
        from outside finds nothing either.
        """
        prm = self.params
        thin_m = self.limits.radius_m + prm.pocket_clearance_margin_m
        exit_path = pocket_exit_path(
            grid,
            self.geometry,
            pose[:2],
            self.clearance_m,
            min(thin_m, self.clearance_m),
            prm.pocket_max_share,
            clearance_field=clearance,
        )
        if exit_path is None:
            return None
        outside = (float(exit_path[-1, 0]), float(exit_path[-1, 1]))
        found = nearest_reachable_frontier(
            grid,
            self.geometry,
            outside,
            self.clearance_m,
            frontiers=FrontierFilter(**self._fallback_search_kwargs()),
            clearance_field=clearance,
        )
        if found is None:
            return None
        from semexplore_gym.policies.semantic_expert import _Plan

        self.counters["pocket_escapes"] += 1
        self._log(
            "pocket",
            f"out at {tuple(round(v, 2) for v in outside)}, then to the frontier at "
            f"{tuple(round(v, 2) for v in found.frontier_xy_m)}",
        )
        path = np.vstack([exit_path, found.path_m[1:]])
        return _Plan(
            "fallback", found.goal_xy_m, resample_polyline(path, self.geometry.resolution_m), None
        )

    def _standable_prefix(self, path_m: np.ndarray, clearance: np.ndarray) -> np.ndarray:
        """The part of ``path_m`` from its start on which the robot's own clearance holds."""
        res_m = self.geometry.resolution_m
        dense = resample_polyline(path_m, res_m)
        rows, cols = self.geometry.world_to_grid(dense[:, 0], dense[:, 1])
        ok = clearance[rows, cols] >= self.clearance_m - 1e-9
        # The robot may start closer to a wall than its clearance: skip that first stretch.
        first = int(np.argmax(ok)) if ok.any() else len(ok)
        bad = np.flatnonzero(~ok[first:])
        return dense if len(bad) == 0 else dense[: first + int(bad[0])]

    def _been_near(self, xy_m: tuple[float, float], radius_m: float) -> bool:
        """Whether the robot's trail passed within ``radius_m`` of ``xy_m``."""
        c = TRAIL_CELL_M
        k = int(math.ceil(radius_m / c))
        ix, iy = int(xy_m[0] // c), int(xy_m[1] // c)
        for i in range(ix - k, ix + k + 1):
            for j in range(iy - k, iy + k + 1):
                if (i, j) in self._trail and math.dist(((i + 0.5) * c, (j + 0.5) * c), xy_m) <= (
                    radius_m
                ):
                    return True
        return False

    def _stop_reason(self) -> str:
        """Which rule ended the mission, and what was left behind."""
        if not self.params.grid_fallback:
            n = self.memory.count()
            return "no semantic frontier left" + (f" ({n} frontier(s) dropped)" if n else "")
        parts = []
        for reason, text in (
            ("attempts", f"failed {self.params.max_goal_attempts} approaches"),
            ("grid", "no grid path"),
            ("reached", f"reached {self.params.max_goal_reaches} times, not cleared"),
            ("looked", "looked at, gap closed"),
        ):
            n = self.memory.count(reason)
            if n:
                parts.append(f"{n} {text}")
        tail = f"; dropped: {', '.join(parts)}" if parts else ""
        return f"no frontier left (grid check: none reachable{tail})"
