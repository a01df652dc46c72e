"""Shortest paths at a clearance: the yardstick a driven path is compared with.

:func:`clear_cells` marks where the robot's centre may go on an encoded grid (observed FREE
cells farther than the clearance from every OCCUPIED cell); :func:`shortest_clear_path_m`
measures the shortest path between two points through those cells. The search is the
8-connected A* of :mod:`~semexplore_gym.core.planning.grid_search` followed by string pulling
(each point of the cell path is skipped while the straight segment past it stays on clear
cells), so a straight line at any angle measures its Euclidean length rather than the up to 8 %
longer 8-connected one.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
from scipy.ndimage import distance_transform_edt

from semexplore_gym.core.grid import FREE, OCCUPIED, GridGeometry
from semexplore_gym.core.planning.grid_search_kernels import backtrack_cells, search_cells
from semexplore_gym.core.planning.line_of_sight import farthest_visible_index

__all__ = ["clear_cells", "shortest_clear_path_m"]


def clear_cells(grid: npt.ArrayLike, geometry: GridGeometry, clearance_m: float) -> np.ndarray:
    """FREE cells whose centre lies farther than ``clearance_m`` from every OCCUPIED cell centre.

    Half a cell of slack keeps passages open whose width the grid rounds down.

    Args:
        grid: ``(H, W)`` encoded occupancy grid.
        geometry: Frame of ``grid``.
        clearance_m: The clearance (the robot radius, for where its centre may go).

    Returns:
        ``(H, W)`` bool.
    """
    g = np.asarray(grid)
    if g.shape != geometry.shape:
        raise ValueError(f"grid shape {g.shape} does not match geometry shape {geometry.shape}")
    if not (math.isfinite(clearance_m) and clearance_m >= 0):
        raise ValueError(f"clearance_m must be a finite number >= 0, got {clearance_m!r}")
    free = g == FREE
    occupied = g == OCCUPIED
    if not occupied.any():
        return free
    res = geometry.resolution_m
    dist_m = distance_transform_edt(~occupied) * res
    return free & (dist_m > clearance_m - 0.5 * res)


def shortest_clear_path_m(
    traversable: npt.ArrayLike,
    geometry: GridGeometry,
    start_xy_m: tuple[float, float],
    end_xy_m: tuple[float, float],
    snap_m: float,
) -> float | None:
    """Length of the shortest path from ``start_xy_m`` to ``end_xy_m`` through ``traversable``.

    The robot may stand a little off the clear cells (closer to a wall than the clearance, or
    in a cell the map has since marked otherwise): the path may join them within ``snap_m`` of
    either end, the way in and out counted as straight segments.

    Args:
        traversable: ``(H, W)`` bool (:func:`clear_cells`).
        geometry: Frame of the mask.
        start_xy_m: Start ``(x, y)`` in metres.
        end_xy_m: End ``(x, y)`` in metres.
        snap_m: How far from either end the path may join the traversable cells.

    Returns:
        The length in metres, or None when either end lies off the grid, no traversable cell
        lies within ``snap_m`` of the end, or no path joins them.
    """
    mask = np.asarray(traversable, dtype=bool)
    if mask.shape != geometry.shape:
        raise ValueError(f"traversable shape {mask.shape} does not match {geometry.shape}")
    h, w = mask.shape
    sources = _cells_near(mask, geometry, start_xy_m, snap_m, include_own=True)
    ends = _cells_near(mask, geometry, end_xy_m, snap_m, include_own=False)
    if sources is None or ends is None or not len(ends[0]):
        return None
    goal = int(ends[0][int(np.argmin(ends[1]))])
    res = geometry.resolution_m
    cost = np.where(mask, res, np.inf)
    dist = np.full(h * w, np.inf)
    dist[sources[0]] = sources[1]
    parent = np.full(h * w, -1, dtype=np.int64)
    search_cells(cost, sources[0], goal, res, dist, parent)
    if not math.isfinite(dist[goal]):
        return None
    cells = backtrack_cells(parent, goal)
    xs, ys = geometry.grid_to_world(cells // w, cells % w)
    pts = np.vstack([start_xy_m, np.column_stack([xs, ys]), end_xy_m]).astype(np.float64)
    sight = np.full(mask.shape, OCCUPIED, dtype=np.uint8)
    sight[mask] = FREE
    sight.ravel()[cells] = FREE
    return _pulled_length(sight, geometry, pts)


def _cells_near(
    mask: np.ndarray,
    geometry: GridGeometry,
    xy_m: tuple[float, float],
    radius_m: float,
    include_own: bool,
) -> tuple[np.ndarray, np.ndarray] | None:
    """Flat indices of the traversable cells within ``radius_m`` of ``xy_m`` and their distances
    (with the point's own cell when ``include_own``); None when the point is off the grid."""
    r_a, c_a = geometry.world_to_grid(xy_m[0], xy_m[1])
    r, c = int(r_a), int(c_a)
    if not geometry.contains(r, c):
        return None
    h, w = mask.shape
    k = int(math.ceil(radius_m / geometry.resolution_m))
    r0, r1, c0, c1 = max(r - k, 0), min(r + k + 1, h), max(c - k, 0), min(c + k + 1, w)
    rr, cc = np.mgrid[r0:r1, c0:c1]
    xs, ys = geometry.grid_to_world(rr, cc)
    d = np.hypot(np.asarray(xs) - xy_m[0], np.asarray(ys) - xy_m[1])
    keep = mask[r0:r1, c0:c1] & (d <= radius_m)
    if include_own:
        keep |= (rr == r) & (cc == c)
    return (rr[keep] * w + cc[keep]).astype(np.int64), d[keep].astype(np.float64)


def _pulled_length(sight: np.ndarray, geometry: GridGeometry, pts: np.ndarray) -> float:
    """Length of ``pts`` after string pulling: from each kept point, on to the farthest later
    point in straight sight on ``sight`` (the next point when none is)."""
    n = len(pts)
    total, i = 0.0, 0
    later = np.zeros(n, dtype=bool)
    while i < n - 1:
        later[: i + 1] = False
        later[i + 1 :] = True
        j = farthest_visible_index(sight, geometry, (pts[i, 0], pts[i, 1]), pts, later)
        j = max(j, i + 1)
        total += float(math.hypot(pts[j, 0] - pts[i, 0], pts[j, 1] - pts[i, 1]))
        i = j
    return total
