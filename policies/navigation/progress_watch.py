"""When the robot has made no progress for a while: :class:`ProgressWatch`.

The move_base-like :class:`~semexplore_gym.policies.navigation.navigator.Navigator` of the frontier
baselines and the semantic expert's path follower use the same class, each parametrised to its
own rules (see :mod:`semexplore_gym.policies.navigation`).
"""

from __future__ import annotations

import math

__all__ = ["ProgressWatch"]


class ProgressWatch:
    """Says when the robot has made no progress for ``timeout_s``.

    Progress is any of the enabled criteria: the robot moved ``radius_m`` away from the point
    where progress was last seen (the anchor), the map gained ``min_new_cells`` known cells, or
    the rest of the path shrank by more than ``path_margin_m`` below its best so far. Each
    progress moves the anchor, the known-cell count and the clock to the present.

    Args:
        timeout_s: Time without progress after which :meth:`stalled` is True (> 0).
        radius_m: Motion criterion; None disables it.
        radius_inclusive: Moving exactly ``radius_m`` counts as progress (move_base's
            oscillation check); otherwise the robot must move farther.
        min_new_cells: Map-growth criterion; None disables it.
        path_margin_m: Path criterion; None disables it.

    Attributes:
        anchor_xy_m: Where progress was last seen (None: anywhere counts as progress).
        since_s: When progress was last seen (or the watch was held until).
        best_remaining_m: The shortest rest of the path seen since the last reset.
    """

    def __init__(
        self,
        timeout_s: float,
        *,
        radius_m: float | None = None,
        radius_inclusive: bool = False,
        min_new_cells: int | None = None,
        path_margin_m: float | None = None,
    ) -> None:
        self.timeout_s = float(timeout_s)
        self.radius_m = radius_m
        self.radius_inclusive = radius_inclusive
        self.min_new_cells = min_new_cells
        self.path_margin_m = path_margin_m
        self.anchor_xy_m: tuple[float, float] | None = None
        self.since_s = 0.0
        self.known_cells = 0
        self.best_remaining_m = math.inf

    def reset(
        self, now_s: float, xy_m: tuple[float, float] | None = None, known_cells: int = 0
    ) -> None:
        """Start watching at ``now_s`` from ``xy_m`` (None: the next position is the anchor)."""
        self.anchor_xy_m = xy_m
        self.since_s = now_s
        self.known_cells = known_cells
        self.best_remaining_m = math.inf

    def hold(self, until_s: float, known_cells: int) -> None:
        """Count no time before ``until_s`` (a recovery manoeuvre runs), keeping the anchor."""
        self.since_s = until_s
        self.known_cells = known_cells
        self.best_remaining_m = math.inf

    def track_path(self, remaining_m: float) -> None:
        """Measure path progress against a new path whose rest is ``remaining_m`` long."""
        self.best_remaining_m = remaining_m

    def update(
        self,
        now_s: float,
        xy_m: tuple[float, float] | None = None,
        known_cells: int = 0,
        remaining_m: float | None = None,
    ) -> bool:
        """Record the robot's state at ``now_s``; returns :meth:`stalled`.

        Args:
            now_s: Policy time.
            xy_m: Robot position (motion criterion).
            known_cells: Known cells of the map (map-growth criterion).
            remaining_m: Length of the rest of the path (path criterion).
        """
        if self._progressed(xy_m, known_cells, remaining_m):
            if remaining_m is not None:
                self.best_remaining_m = min(remaining_m, self.best_remaining_m)
            self.anchor_xy_m = xy_m if self.radius_m is not None else self.anchor_xy_m
            self.since_s = now_s
            self.known_cells = known_cells
        return self.stalled(now_s)

    def stalled(self, now_s: float) -> bool:
        """No progress for ``timeout_s`` up to ``now_s``."""
        return now_s - self.since_s >= self.timeout_s

    def _progressed(
        self, xy_m: tuple[float, float] | None, known_cells: int, remaining_m: float | None
    ) -> bool:
        if self.radius_m is not None and xy_m is not None:
            if self.anchor_xy_m is None:
                return True
            moved_m = math.dist(xy_m, self.anchor_xy_m)
            if moved_m >= self.radius_m if self.radius_inclusive else moved_m > self.radius_m:
                return True
        if self.path_margin_m is not None and remaining_m is not None:
            if remaining_m < self.best_remaining_m - self.path_margin_m:
                return True
        return self.min_new_cells is not None and (
            known_cells - self.known_cells >= self.min_new_cells
        )
