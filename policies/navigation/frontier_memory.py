"""What an exploring robot remembers about its goals: failed approaches, dropped and looked-at
frontiers (which come back when the map round them changes), and goals it recently abandoned.

The semantic expert uses it so that it never gives up on a frontier it could still reach:

* a goal whose approach failed is retried with another approach before it is dropped
  (:meth:`FrontierMemory.record_failure` says which attempt comes next);
* a dropped goal comes back when enough cells round it changed since it was dropped
  (:meth:`FrontierMemory.revive`), at most ``max_revivals`` times per place;
* a goal the robot switched away from stays "recently abandoned" for a while
  (:meth:`FrontierMemory.recently_abandoned`), so the goal choice can refuse to shuttle back.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from semexplore_gym.core.grid import UNKNOWN, GridGeometry

__all__ = ["DroppedGoal", "FrontierMemory"]


@dataclass
class DroppedGoal:
    """A goal given up on, and the state of the map round it at that time.

    Attributes:
        xy_m: The goal (metres, world frame).
        reason: ``"attempts"`` (approaches failed), ``"grid"`` (no grid path for the disc),
            ``"reached"`` (reached repeatedly, the frontier stayed) or ``"looked"`` (a look from
            close by did not open it).
        window_known: The known (non-UNKNOWN) cells of the map window round it when dropped.
        active: False once it came back.
        revivals: How often it came back.
    """

    xy_m: tuple[float, float]
    reason: str
    window_known: np.ndarray
    active: bool = True
    revivals: int = 0


class FrontierMemory:
    """Failed approaches, dropped goals with revival, and recently abandoned goals.

    Args:
        radius_m: Two goals closer than this are the same place.
        window_m: Radius of the map window watched round a dropped goal.
        min_changed_cells: Cells of that window that must change to bring a goal back.
        max_revivals: How often one place may come back.
        max_attempts: Failed approaches before a goal is dropped.
        drop_each_point: A goal dropped near an earlier drop (the same place) keeps a point of
            its own as well (see :meth:`drop`); False: only the earlier point is kept.
    """

    def __init__(
        self,
        radius_m: float,
        window_m: float,
        min_changed_cells: int,
        max_revivals: int,
        max_attempts: int,
        drop_each_point: bool = True,
    ) -> None:
        self.radius_m = float(radius_m)
        self.window_m = float(window_m)
        self.min_changed_cells = int(min_changed_cells)
        self.max_revivals = int(max_revivals)
        self.max_attempts = int(max_attempts)
        self.drop_each_point = bool(drop_each_point)
        self.dropped: list[DroppedGoal] = []
        self._failures: list[tuple[tuple[float, float], int, tuple[float, float]]] = []
        self._abandoned: list[tuple[tuple[float, float], float]] = []

    # ------------------------------------------------------------------ helpers
    def _near(self, a: tuple[float, float], b: tuple[float, float]) -> bool:
        return math.dist(a, b) <= self.radius_m

    def _window(
        self, grid: np.ndarray, geometry: GridGeometry, xy_m: tuple[float, float]
    ) -> np.ndarray:
        r = self.window_m
        r0, c0 = (int(v) for v in geometry.world_to_grid(xy_m[0] - r, xy_m[1] - r))
        r1, c1 = (int(v) for v in geometry.world_to_grid(xy_m[0] + r, xy_m[1] + r))
        r0, c0 = max(r0, 0), max(c0, 0)
        r1, c1 = min(r1, geometry.height - 1), min(c1, geometry.width - 1)
        if r1 < r0 or c1 < c0:
            return np.zeros((0, 0), dtype=bool)
        return grid[r0 : r1 + 1, c0 : c1 + 1] != UNKNOWN

    # ------------------------------------------------------------------ failures
    def record_failure(
        self, goal_xy_m: tuple[float, float], robot_xy_m: tuple[float, float]
    ) -> tuple[int, tuple[float, float]]:
        """Count a failed approach to ``goal_xy_m``; returns (failures so far, where the first
        failure happened)."""
        for i, (xy, n, where) in enumerate(self._failures):
            if self._near(xy, goal_xy_m):
                self._failures[i] = (xy, n + 1, where)
                return n + 1, where
        self._failures.append((goal_xy_m, 1, robot_xy_m))
        return 1, robot_xy_m

    def forget_failures(self, goal_xy_m: tuple[float, float]) -> None:
        """Start counting afresh for the place of ``goal_xy_m`` (it came back, or was cleared)."""
        self._failures = [f for f in self._failures if not self._near(f[0], goal_xy_m)]

    # ------------------------------------------------------------------ dropping
    def drop(
        self,
        goal_xy_m: tuple[float, float],
        reason: str,
        grid: np.ndarray,
        geometry: GridGeometry,
    ) -> None:
        """Give up on ``goal_xy_m`` until the map round it changes.

        A goal near one dropped before is the same place (it comes back at most
        ``max_revivals`` times in all); when it is not the very same point it is kept as a point
        of its own as well (with ``drop_each_point``), so that the frontier cells round *it* are
        excluded too: a search that excludes frontier cells near the dropped points would else
        find the same goal again, beyond the old point's radius, and drop it again, for ever."""
        window = self._window(grid, geometry, goal_xy_m)
        near = [d for d in self.dropped if self._near(d.xy_m, goal_xy_m)]
        own = next((d for d in near if d.xy_m == goal_xy_m), None) if self.drop_each_point else None
        for d in [own] if own is not None else near[:1]:
            d.active, d.reason, d.window_known = True, reason, window
        if not near or (self.drop_each_point and own is None):
            revivals = near[0].revivals if near else 0
            self.dropped.append(DroppedGoal(goal_xy_m, reason, window, revivals=revivals))

    def active_points(self, exclude: Sequence[str] = ()) -> list[tuple[float, float]]:
        """The goals dropped and not come back (but those dropped for a reason in
        ``exclude``)."""
        return [d.xy_m for d in self.dropped if d.active and d.reason not in exclude]

    def is_dropped(self, xy_m: tuple[float, float]) -> bool:
        """Whether ``xy_m`` lies within ``radius_m`` of an active dropped goal."""
        return any(d.active and self._near(d.xy_m, xy_m) for d in self.dropped)

    def count(self, reason: str | None = None) -> int:
        """Active dropped goals (of one reason, or all)."""
        return sum(d.active and (reason is None or d.reason == reason) for d in self.dropped)

    def revive(self, grid: np.ndarray, geometry: GridGeometry) -> list[tuple[float, float]]:
        """Bring back the dropped goals round which the map changed enough; returns them."""
        back = []
        for d in self.dropped:
            if not d.active or d.revivals >= self.max_revivals:
                continue
            now = self._window(grid, geometry, d.xy_m)
            if now.shape != d.window_known.shape:
                changed = self.min_changed_cells
            else:
                changed = int(np.count_nonzero(now != d.window_known))
            if changed >= self.min_changed_cells:
                d.active = False
                d.revivals += 1
                self.forget_failures(d.xy_m)
                back.append(d.xy_m)
        return back

    # ------------------------------------------------------------------ abandoning
    def abandon(self, goal_xy_m: tuple[float, float], time_s: float) -> None:
        """Note that the robot switched away from ``goal_xy_m`` at ``time_s``."""
        self._abandoned.append((goal_xy_m, time_s))

    def recently_abandoned(self, xy_m: tuple[float, float], time_s: float, window_s: float) -> bool:
        """Whether the robot switched away from a goal near ``xy_m`` within ``window_s``."""
        self._abandoned = [(g, t) for g, t in self._abandoned if time_s - t <= window_s]
        return any(self._near(g, xy_m) for g, _t in self._abandoned)
