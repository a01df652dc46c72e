"""Other ways to a goal after the first approach failed: a grid route, or another side.

Used by the semantic expert before it drops a goal: its own path follows the topometric map,
so the first retry plans a clearance-aware route on the current grid; the second comes at the
frontier from a standable point round it that lies away from where the robot got stuck.
"""

from __future__ import annotations

import math

import numpy as np

from semexplore_gym.core.frontiers.reachable import grid_path_to
from semexplore_gym.core.grid import FREE, GridGeometry

__all__ = ["side_approach"]

#: Radii (metres) of the rings of candidate approach points round the goal.
_RING_RADII_M = (0.45, 0.8)
_RING_POINTS = 16
#: Grid searches tried at most (the farthest candidates from the failure first).
_MAX_SEARCHES = 4


def side_approach(
    grid: np.ndarray,
    geometry: GridGeometry,
    start_xy_m: tuple[float, float],
    goal_xy_m: tuple[float, float],
    failed_at_xy_m: tuple[float, float],
    clearance_m: float,
    clearance_field: np.ndarray,
) -> tuple[tuple[float, float], np.ndarray] | None:
    """A standable point round ``goal_xy_m``, away from ``failed_at_xy_m``, and a path to it.

    Candidates lie on rings round the goal, on FREE cells at least ``clearance_m`` from walls;
    those farthest from where the first approach failed are tried first.

    Returns:
        ``(target_xy_m, path_m)``, or None when no candidate can be reached.
    """
    angles = np.linspace(0.0, 2.0 * math.pi, _RING_POINTS, endpoint=False)
    cands = []
    for r in _RING_RADII_M:
        xs = goal_xy_m[0] + r * np.cos(angles)
        ys = goal_xy_m[1] + r * np.sin(angles)
        rows, cols = geometry.world_to_grid(xs, ys)
        for x, y, row, col in zip(xs, ys, rows, cols, strict=True):
            if not (0 <= row < geometry.height and 0 <= col < geometry.width):
                continue
            if grid[row, col] != FREE or clearance_field[row, col] < clearance_m:
                continue
            cands.append((math.dist((x, y), failed_at_xy_m), (float(x), float(y))))
    cands.sort(key=lambda c: -c[0])
    for _d, target in cands[:_MAX_SEARCHES]:
        path = grid_path_to(
            grid, geometry, start_xy_m, target, clearance_m, clearance_field=clearance_field
        )
        if path is not None:
            return target, path
    return None
