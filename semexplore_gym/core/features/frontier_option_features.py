"""Features of every reachable frontier, for a learned frontier chooser (pure numpy).

The frontier student (:class:`semexplore_gym.policies.frontier_student.FrontierStudentPolicy`)
scores each option of :func:`~semexplore_gym.core.frontiers.options.reachable_frontier_options`
by a learned function of the columns below (:data:`OPTION_FEATURE_NAMES`), all read from the
observation (the map and the pose) and the student's own current goal:

====================  ==================================================================
``path_m``            path cost from the robot to the option's goal (metres)
``extra_path_m``      ``path_m`` minus the nearest option's
``log_path``          ``log(0.5 + path_m)``: a metre matters more near the robot
``straight_m``        straight distance robot-goal
``detour``            ``path_m / max(straight_m, 0.1) - 1``, at most 10
``turn_rad``          the turn from the robot's heading to the goal's bearing, in [0, pi]
``frontier_m``        the frontier's length (its cells times the cell size)
``unknown_near``      share of UNKNOWN cells within 1 m of the frontier's centroid
``unknown_far``       the same within 3.5 m (the LiDAR's range): the area still to see
``isolation_m``       straight distance to the nearest other frontier (10 when alone or
                      farther): a lone frontier left now costs a trip back later
``crowd``             other frontiers within 3 m of this one
``away_m``            distance from this frontier to the centroid of the others, minus the
                      robot's: positive when it lies away from the rest (0 when alone)
``current``           1 for the option within ``commitment_radius_m`` of the current goal
``nearest``           1 for the nearest option
``tour_m``            ``path_m`` plus a short open path from this option's goal through the
                      other options' goals (path costs between goals; nearest neighbour then
                      2-opt): the student's own estimate of what the oracle prices, a tour
                      of the building that starts here (the ``TOUR_OPTIONS`` nearest options;
                      a farther one gets ``path_m`` plus the longest of their open paths)
``tour_extra_m``      ``tour_m`` minus the smallest
====================  ==================================================================
"""

from __future__ import annotations

import math

import numpy as np

from semexplore_gym.core.features.frontier_features import unknown_fraction_near
from semexplore_gym.core.frontiers.options import FrontierOptions
from semexplore_gym.core.grid import GridGeometry

__all__ = ["OPTION_FEATURE_NAMES", "frontier_option_features"]

#: The feature columns, in order.
OPTION_FEATURE_NAMES: tuple[str, ...] = (
    "path_m",
    "extra_path_m",
    "log_path",
    "straight_m",
    "detour",
    "turn_rad",
    "frontier_m",
    "unknown_near",
    "unknown_far",
    "isolation_m",
    "crowd",
    "away_m",
    "current",
    "nearest",
    "tour_m",
    "tour_extra_m",
)

#: Options (nearest first) whose goals the tour features connect.
TOUR_OPTIONS = 16

#: The isolation of a frontier with no other within this distance (metres).
ISOLATION_CAP_M = 10.0


def frontier_option_features(
    grid: np.ndarray,
    geometry: GridGeometry,
    pose: tuple[float, float, float],
    options: FrontierOptions,
    current_goal_xy_m: tuple[float, float] | None = None,
    commitment_radius_m: float = 0.5,
) -> np.ndarray:
    """``(F, len(OPTION_FEATURE_NAMES))`` features of ``options`` seen from ``pose``."""
    n = len(options)
    out = np.zeros((n, len(OPTION_FEATURE_NAMES)))
    if n == 0:
        return out
    x, y, yaw = (float(v) for v in pose)
    d = options.path_cost_m
    goal = options.goal_xy_m
    centre = options.frontier_xy_m
    straight = np.hypot(goal[:, 0] - x, goal[:, 1] - y)
    bearing = np.arctan2(goal[:, 1] - y, goal[:, 0] - x)
    turn = np.abs((bearing - yaw + math.pi) % (2.0 * math.pi) - math.pi)
    res = geometry.resolution_m
    near = [unknown_fraction_near(grid, geometry, (cx, cy), 1.0) for cx, cy in centre]
    far = [unknown_fraction_near(grid, geometry, (cx, cy), 3.5) for cx, cy in centre]
    gap = np.hypot(centre[:, None, 0] - centre[None, :, 0], centre[:, None, 1] - centre[None, :, 1])
    np.fill_diagonal(gap, np.inf)
    isolation = np.minimum(gap.min(axis=1), ISOLATION_CAP_M)
    crowd = (gap <= 3.0).sum(axis=1)
    away = np.zeros(n)
    if n > 1:
        total = centre.sum(axis=0)
        others = (total[None, :] - centre) / (n - 1)
        away = np.hypot(*(centre - others).T) - np.hypot(others[:, 0] - x, others[:, 1] - y)
    current = np.zeros(n)
    if current_goal_xy_m is not None:
        to_cur = np.hypot(goal[:, 0] - current_goal_xy_m[0], goal[:, 1] - current_goal_xy_m[1])
        j = int(np.argmin(to_cur))
        current[j] = float(to_cur[j] <= commitment_radius_m)
    out[:, 0] = d
    out[:, 1] = d - d.min()
    out[:, 2] = np.log(0.5 + d)
    out[:, 3] = straight
    out[:, 4] = np.minimum(d / np.maximum(straight, 0.1) - 1.0, 10.0)
    out[:, 5] = turn
    out[:, 6] = [len(c) * res for c in options.frontier_cells]
    out[:, 7] = near
    out[:, 8] = far
    out[:, 9] = isolation
    out[:, 10] = crowd
    out[:, 11] = away
    out[:, 12] = current
    out[:, 13] = (np.arange(n) == int(np.argmin(d))).astype(float)
    rest = _open_paths_m(options.pairwise_path_cost_m(TOUR_OPTIONS))
    m = len(rest)
    tour = d + np.concatenate([rest, np.full(n - m, rest.max())])
    out[:, 14] = tour
    out[:, 15] = tour - tour.min()
    return out


def _open_paths_m(dist: np.ndarray) -> np.ndarray:
    """For each node, the length of a short open path from it through every other node
    (nearest neighbour, then 2-opt); unreachable legs count as the largest finite cost."""
    n = len(dist)
    finite = dist[np.isfinite(dist)]
    d = np.where(np.isfinite(dist), dist, (finite.max() if len(finite) else 0.0) * 2.0 + 1.0)
    out = np.zeros(n)
    for s in range(n):
        order = [s]
        left = set(range(n)) - {s}
        while left:
            nxt = min(left, key=lambda j: (d[order[-1], j], j))
            order.append(nxt)
            left.remove(nxt)
        out[s] = _two_opt_open(d, order)
    return out


def _two_opt_open(d: np.ndarray, order: list[int]) -> float:
    """Improve an open path (first node fixed) by 2-opt moves; its length."""
    path = list(order)
    improved = True
    while improved:
        improved = False
        for i in range(1, len(path) - 1):
            for j in range(i + 1, len(path)):
                a, b = path[i - 1], path[i]
                c = path[j]
                nxt = path[j + 1] if j + 1 < len(path) else None
                before = d[a, b] + (d[c, nxt] if nxt is not None else 0.0)
                after = d[a, c] + (d[b, nxt] if nxt is not None else 0.0)
                if after < before - 1e-9:
                    path[i : j + 1] = path[i : j + 1][::-1]
                    improved = True
    return float(sum(d[a, b] for a, b in zip(path[:-1], path[1:], strict=False)))
