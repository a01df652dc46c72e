"""Features of a learned frontier value (pure numpy, no gymnasium).

The learned-value agent (:class:`semexplore_gym.policies.learned_frontier_value.FrontierValuePolicy`) ranks the
frontier candidates of Algorithm 1 by ``C' = C + sum_k w_k * phi_k``: the paper's cost ``C``
plus a linear value over the features below, whose weights ``w_k`` were fitted by black-box
optimisation over missions on training worlds
(:mod:`semexplore_gym.training.frontier_value_search`).

Per candidate (rows of :func:`frontier_value_features`, columns in :data:`FEATURE_NAMES`):

==================  ======================================================================
``path_m``          path length ``d`` to the frontier (metres, unnormalised: the paper
                    divides it by ``L_path``, which changes as the map grows)
``unknown_frac``    share of UNKNOWN cells in a disc of ``unknown_radius_m`` round the goal
                    (the area still to see behind the frontier, cut at the map's edge)
``isolation_m``     straight distance from the goal to the nearest other candidate's goal
                    (a lone frontier left behind costs a trip back later); 0 if alone
``spread_m``        straight distance from the goal to the centroid of the other goals; 0
                    if alone
``detour``          ``d`` over the straight distance robot-goal, minus 1 (0: straight)
==================  ======================================================================
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from semexplore_gym.core.grid import UNKNOWN, GridGeometry

__all__ = ["FEATURE_NAMES", "frontier_value_features", "unknown_fraction_near"]

#: The feature columns, in order.
FEATURE_NAMES: tuple[str, ...] = ("path_m", "unknown_frac", "isolation_m", "spread_m", "detour")


def unknown_fraction_near(
    grid: np.ndarray, geometry: GridGeometry, xy_m: tuple[float, float], radius_m: float
) -> float:
    """The share of UNKNOWN cells in the disc of ``radius_m`` round ``xy_m``.

    Cells of the disc outside the map count as unknown (beyond the map's edge nothing is
    known). ``radius_m`` below one cell looks at the goal's own cell.
    """
    res = geometry.resolution_m
    r_cells = max(0, int(math.ceil(radius_m / res)))
    row, col = geometry.world_to_grid(xy_m[0], xy_m[1])
    r0, c0 = int(row), int(col)
    dr, dc = np.mgrid[-r_cells : r_cells + 1, -r_cells : r_cells + 1]
    in_disc = dr * dr + dc * dc <= r_cells * r_cells
    rows = (r0 + dr)[in_disc]
    cols = (c0 + dc)[in_disc]
    inside = (rows >= 0) & (rows < grid.shape[0]) & (cols >= 0) & (cols < grid.shape[1])
    unknown = np.count_nonzero(grid[rows[inside], cols[inside]] == UNKNOWN)
    unknown += int(np.count_nonzero(~inside))
    return float(unknown) / float(len(rows))


def frontier_value_features(
    grid: np.ndarray,
    geometry: GridGeometry,
    robot_xy_m: tuple[float, float],
    goals_xy_m: Sequence[tuple[float, float]],
    path_lengths_m: Sequence[float],
    unknown_radius_m: float = 1.5,
) -> np.ndarray:
    """The ``(N, len(FEATURE_NAMES))`` feature rows of ``N`` frontier candidates.

    Args:
        grid: The encoded occupancy grid the candidates were found on.
        geometry: Its geometry.
        robot_xy_m: The robot's position (metres, world frame).
        goals_xy_m: Each candidate's goal (the frontier opening's midpoint).
        path_lengths_m: Each candidate's path length ``d`` (metres).
        unknown_radius_m: Radius of the disc ``unknown_frac`` looks at.

    Raises:
        ValueError: ``goals_xy_m`` and ``path_lengths_m`` differ in length.
    """
    n = len(goals_xy_m)
    if len(path_lengths_m) != n:
        raise ValueError(f"{n} goals but {len(path_lengths_m)} path lengths")
    out = np.zeros((n, len(FEATURE_NAMES)), dtype=np.float64)
    if n == 0:
        return out
    goals = np.asarray(goals_xy_m, dtype=np.float64).reshape(n, 2)
    d = np.asarray(path_lengths_m, dtype=np.float64)
    out[:, 0] = d
    for i in range(n):
        out[i, 1] = unknown_fraction_near(
            grid, geometry, (goals[i, 0], goals[i, 1]), unknown_radius_m
        )
    if n > 1:
        diff = goals[:, None, :] - goals[None, :, :]
        dist = np.hypot(diff[..., 0], diff[..., 1])
        np.fill_diagonal(dist, np.inf)
        out[:, 2] = dist.min(axis=1)
        others_sum = goals.sum(axis=0)[None, :] - goals
        centroid = others_sum / float(n - 1)
        out[:, 3] = np.hypot(*(goals - centroid).T)
    straight = np.hypot(goals[:, 0] - robot_xy_m[0], goals[:, 1] - robot_xy_m[1])
    out[:, 4] = np.where(straight > 1e-6, d / np.maximum(straight, 1e-6) - 1.0, 0.0)
    out[:, 4] = np.clip(out[:, 4], 0.0, 10.0)
    return out
