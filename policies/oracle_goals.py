"""The oracle's goals: which rest of its tour to drive once some viewpoints are no longer needed,
a second look where a viewpoint's scan fell short, a shortcut to the coverage goal near the end,
and what to see once the tour is done (see :class:`~semexplore_gym.policies.oracle.OraclePolicy`).

All read only the oracle's privileged tour (:class:`~semexplore_gym.core.coverage_tour.CoverageTour`)
and its live map's unseen cells; each returns a candidate cell (or a route) or None.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from semexplore_gym.core.coverage_tour import CoverageTour, open_tour_order
from semexplore_gym.core.coverage_tour.refine import predicted_drive_m
from semexplore_gym.core.coverage_tour.tour import row_counts

Cell = tuple[int, int]


def best_rest_of_tour(
    tour: CoverageTour,
    here: Cell,
    dist: np.ndarray,
    routes: list[list[int]],
    unseen: np.ndarray,
    need: int,
) -> list[int]:
    """Of the candidate rests of the tour ``routes`` (viewpoint indices in driving order), the
    one the sensor model predicts to see ``need`` of the ``unseen`` cells after the shortest
    drive from the robot's cell ``here`` (``dist``: its geodesic distance field); the first on a
    tie; when none sees that many, the one that sees most. The tour's order was chosen with the
    scans along its legs counted: an order re-solved on distances alone can lose what those
    legs saw (:func:`~semexplore_gym.core.coverage_tour.refine.predicted_drive_m`)."""
    assert tour.legs is not None
    best: tuple[float, float, float] | None = None
    chosen = routes[0]
    for i, route in enumerate(routes):
        if route in routes[:i]:
            continue  # the same order again (LKH often keeps the tour's): same prediction
        cells = tour.viewpoints_rc[route].reshape(-1, 2)
        lengths = np.concatenate(
            [dist[cells[:1, 0], cells[:1, 1]], tour.distances_m[route[:-1], route[1:]]]
        )
        reached, drive_m, seen = predicted_drive_m(
            tour.legs, np.vstack([np.array([here]), cells]), lengths, unseen, need
        )
        key = (0.0, drive_m, 0.0) if reached else (1.0, -float(seen), drive_m)
        if best is None or key < best:
            best, chosen = key, route
    return list(chosen)


def open_order_from(
    tour: CoverageTour, dist: np.ndarray, vps: list[int], lkh_runs: int
) -> list[int]:
    """The viewpoints ``vps`` as an open LKH tour from the robot (``dist``: the geodesic
    distance field from its cell)."""
    if len(vps) <= 1:
        return list(vps)
    cells = tour.viewpoints_rc[vps]
    k = len(vps)
    m = np.zeros((k + 1, k + 1))
    m[0, 1:] = m[1:, 0] = dist[cells[:, 0], cells[:, 1]]
    m[1:, 1:] = tour.distances_m[np.ix_(vps, vps)]
    order = open_tour_order(m, lkh_runs)
    return [vps[i - 1] for i in order[1:]]


def repair_cell(
    tour: CoverageTour,
    unseen: np.ndarray,
    passed_vp: int,
    left: list[int],
    distances: Callable[[], np.ndarray],
    limits: tuple[int, float],
) -> Cell | None:
    """At viewpoint ``passed_vp`` just reached: the candidate within ``limits[1]`` metres of
    path (``distances()``: the field from the robot) that sees most of the cells its scan was
    counted on for and left unseen, which no viewpoint ``left`` sees; None when fewer than
    ``limits[0]`` such cells, or no candidate sees that many of them."""
    min_cells, radius_m = limits
    vis = tour.candidate_visible
    missed = np.zeros_like(unseen)
    own = tour.visible[passed_vp].indices
    missed[own] = unseen[own]
    if left:
        missed[tour.visible[left].indices] = False
    if vis is None or int(missed.sum()) < min_cells:
        return None
    dist = distances()
    cand = tour.candidates_rc
    near = np.flatnonzero(dist[cand[:, 0], cand[:, 1]] <= radius_m)
    if near.size == 0:
        return None
    sub = vis[near]
    gains = row_counts(missed, sub.indptr, sub.indices)
    k = int(np.argmax(gains))
    if gains[k] < min_cells:
        return None
    return int(cand[near[k], 0]), int(cand[near[k], 1])


def shortcut_cell(
    tour: CoverageTour,
    unseen: np.ndarray,
    need: int,
    left: list[int],
    distances: Callable[[], np.ndarray],
    slack: float,
) -> Cell | None:
    """The nearest candidate whose one scan would see ``slack`` times the ``need`` cells the
    goal still needs, when it is nearer (``distances()``: the field from the robot) than the
    rest of the tour: to the next viewpoint ``left``, then leg by leg; else None."""
    vis = tour.candidate_visible
    if vis is None or need <= 0:
        return None
    gains = row_counts(unseen, vis.indptr, vis.indices)
    ok = np.flatnonzero(gains >= slack * need)
    if ok.size == 0:
        return None
    cand = tour.candidates_rc[ok]
    dist = distances()
    d = dist[cand[:, 0], cand[:, 1]]
    k = int(np.argmin(d))
    rest = math.inf
    if left:
        r, c = (int(v) for v in tour.viewpoints_rc[left[0]])
        rest = float(dist[r, c] + tour.distances_m[left[:-1], left[1:]].sum())
    if not np.isfinite(d[k]) or d[k] >= rest - 0.1:
        return None
    return int(cand[k, 0]), int(cand[k, 1])


def fallback_cell(
    tour: CoverageTour,
    unseen: np.ndarray,
    need: int,
    tried: set[Cell],
    dist: np.ndarray,
    min_gain_cells: int,
) -> Cell | None:
    """After the tour: the nearest candidate (``dist``: the field from the robot), never one
    ``tried``, whose scan would see the ``need`` cells the goal still needs on its own, else
    the one that sees the most unseen cells per metre; None when none sees
    ``min_gain_cells``."""
    vis = tour.candidate_visible
    if vis is None:
        return None
    cand = tour.candidates_rc
    fresh = np.flatnonzero([(int(r), int(c)) not in tried for r, c in cand])
    if fresh.size == 0:
        return None
    sub = vis[fresh]
    gains = row_counts(unseen, sub.indptr, sub.indices)
    d = dist[cand[fresh, 0], cand[fresh, 1]]
    useful = (gains >= min_gain_cells) & np.isfinite(d)
    enough = useful & (gains >= need)
    score = np.where(enough, 1e9 - d, np.where(useful, gains / (d + 1.0), -1.0))
    k = int(np.argmax(score))
    if score[k] < 0:
        return None
    return int(cand[fresh[k], 0]), int(cand[fresh[k], 1])
