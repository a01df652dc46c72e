"""Where a robot can stand to see into a frontier: a reachable cell with a line of sight to the
unknown side of it.

A frontier the robot reached without its unknown side becoming known is not yet a dead end: the
unknown cells may lie round a bend of a narrow passage, behind a wall end, or inside the
LiDAR's minimum range from the spot the planner led to. :func:`find_view_pose` looks for a cell
the robot can reach (FREE, at least ``clearance_m`` from every OCCUPIED cell, connected to the
robot) from which straight lines over known FREE cells reach those unknown cells at a distance
the LiDAR resolves, away from the places already tried, and the path there.

The unknown side of a frontier near a point is its *rim*: the UNKNOWN cells within a box of
half-size ``rim_radius_m`` round the point that have a FREE 8-neighbour (unknown cells walled
in by OCCUPIED ones, such as the inside of a wall, are no rim: no scan reaches them).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from numba import njit

from semexplore_gym.core.frontiers.reachable import clearance_field_m, grid_path_to_mask
from semexplore_gym.core.grid import FREE, UNKNOWN, GridGeometry
from semexplore_gym.core.planning.grid_scan import checked_encoded_grid

__all__ = ["ViewPose", "ViewSearch", "find_view_pose", "unknown_extent_cells", "unknown_rim"]


@dataclass(frozen=True)
class ViewPose:
    """A place to look into a frontier from.

    Attributes:
        goal_xy_m: Centre of the chosen cell.
        path_m: ``(K, 2)`` polyline from the robot to it over usable cells.
        n_visible: Rim cells in line of sight from it.
        n_rim: Rim cells in all.
    """

    goal_xy_m: tuple[float, float]
    path_m: np.ndarray
    n_visible: int
    n_rim: int


def unknown_rim(
    grid: np.ndarray, geometry: GridGeometry, xy_m: tuple[float, float], rim_radius_m: float
) -> tuple[np.ndarray, np.ndarray]:
    """``(rows, cols)`` of the rim round ``xy_m`` (see the module docstring)."""
    g = geometry
    r0, c0 = (int(v) for v in g.world_to_grid(xy_m[0] - rim_radius_m, xy_m[1] - rim_radius_m))
    r1, c1 = (int(v) for v in g.world_to_grid(xy_m[0] + rim_radius_m, xy_m[1] + rim_radius_m))
    r0, c0 = max(r0, 0), max(c0, 0)
    r1, c1 = min(r1, g.height - 1), min(c1, g.width - 1)
    if r1 < r0 or c1 < c0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    # One cell of margin so that the 8-neighbours of the box's edge cells are read.
    a0, b0 = max(r0 - 1, 0), max(c0 - 1, 0)
    win = grid[a0 : min(r1 + 2, g.height), b0 : min(c1 + 2, g.width)]
    free = np.pad(win == FREE, 1)
    near_free = np.zeros(win.shape, dtype=bool)
    for dr in (-1, 0, 1):
        for dc in (-1, 0, 1):
            near_free |= free[1 + dr : 1 + dr + win.shape[0], 1 + dc : 1 + dc + win.shape[1]]
    rim = (win == UNKNOWN) & near_free
    rows, cols = np.nonzero(rim)
    rows, cols = rows + a0, cols + b0
    inside = (rows >= r0) & (rows <= r1) & (cols >= c0) & (cols <= c1)
    return rows[inside].astype(np.int64), cols[inside].astype(np.int64)


def unknown_extent_cells(
    grid: np.ndarray, rim_rows: np.ndarray, rim_cols: np.ndarray, limit: int
) -> int:
    """How many UNKNOWN cells are 4-connected to the rim, counted up to ``limit``.

    What a view into a frontier can gain at most: a sliver of unknown behind a wall end is a
    few cells, a room not yet entered is thousands. A region that touches the map's edge goes
    on beyond it, so it counts ``limit``.
    """
    h, w = grid.shape
    seen = {(int(r), int(c)) for r, c in zip(rim_rows, rim_cols, strict=True)}
    todo = list(seen)
    while todo and len(seen) < limit:
        r, c = todo.pop()
        for rr, cc in ((r + 1, c), (r - 1, c), (r, c + 1), (r, c - 1)):
            if not (0 <= rr < h and 0 <= cc < w):
                return limit
            if (rr, cc) not in seen and grid[rr, cc] == UNKNOWN:
                seen.add((rr, cc))
                todo.append((rr, cc))
    return min(len(seen), limit)


@dataclass(frozen=True)
class ViewSearch:
    """What counts as a view into a frontier (see :func:`find_view_pose`).

    Attributes:
        range_m: ``(nearest, farthest)`` distance at which a rim cell counts as seen (the
            LiDAR's minimum range plus a margin; a share of its maximum range, where beams
            still lie closer together than a cell).
        rim_radius_m: Half-size of the box round the frontier's point holding the rim.
        excluded_xy_m: Places already looked from (no view place lies near them).
        excluded_radius_m: See ``excluded_xy_m``.
    """

    range_m: tuple[float, float] = (0.27, 2.45)
    rim_radius_m: float = 0.5
    excluded_xy_m: Sequence[tuple[float, float]] = ()
    excluded_radius_m: float = 0.25

    def __post_init__(self) -> None:
        near_m, far_m = (float(v) for v in self.range_m)
        if not (math.isfinite(far_m) and 0.0 <= near_m < far_m):
            raise ValueError(f"need 0 <= range_m[0] < range_m[1], got {self.range_m!r}")


def find_view_pose(
    grid: npt.ArrayLike,
    geometry: GridGeometry,
    start_xy_m: tuple[float, float],
    frontier_xy_m: tuple[float, float],
    clearance_m: float,
    view: ViewSearch = ViewSearch(),
    clearance_field: np.ndarray | None = None,
) -> ViewPose | None:
    """The nearest reachable cell (by path cost) that sees into the frontier at ``frontier_xy_m``.

    A cell sees a rim cell when the straight line between their centres crosses only FREE
    cells and their distance lies within ``view.range_m``. Among the usable cells not near
    ``view.excluded_xy_m`` (where the robot already looked from), those that see at least half
    as many rim cells as the best one are goals.

    Args:
        grid: Encoded occupancy grid (uint8).
        geometry: Frame of ``grid``.
        start_xy_m: Robot position.
        frontier_xy_m: The frontier's point (its rim lies round it).
        clearance_m: Minimum distance from usable cells to OCCUPIED cells.
        view: What counts as a view (ranges, rim, excluded places).
        clearance_field: A precomputed :func:`clearance_field_m` of ``grid`` (optional).

    Returns:
        The :class:`ViewPose`, or None when no reachable cell sees the rim (or it is empty).
    """
    g = checked_encoded_grid(grid)
    if g.shape != geometry.shape:
        raise ValueError(f"grid shape {g.shape} does not match geometry shape {geometry.shape}")
    near_m, far_m = (float(v) for v in view.range_m)
    excluded_xy_m, excluded_radius_m = view.excluded_xy_m, view.excluded_radius_m
    res = geometry.resolution_m
    rim_r, rim_c = unknown_rim(g, geometry, frontier_xy_m, view.rim_radius_m)
    if len(rim_r) == 0:
        return None
    dist = clearance_field if clearance_field is not None else clearance_field_m(g, res)
    # Candidate cells: usable ones in the box within reach of the rim's farthest view.
    k = int(math.ceil(far_m / res)) + 1
    r0, r1 = max(int(rim_r.min()) - k, 0), min(int(rim_r.max()) + k + 1, g.shape[0])
    c0, c1 = max(int(rim_c.min()) - k, 0), min(int(rim_c.max()) + k + 1, g.shape[1])
    cand = np.zeros(g.shape, dtype=bool)
    cand[r0:r1, c0:c1] = (g[r0:r1, c0:c1] == FREE) & (dist[r0:r1, c0:c1] >= clearance_m - 1e-9)
    if len(excluded_xy_m):
        rr, cc = np.mgrid[r0:r1, c0:c1]
        xs, ys = geometry.grid_to_world(rr, cc)
        for ex, ey in excluded_xy_m:
            cand[r0:r1, c0:c1] &= np.hypot(xs - ex, ys - ey) > excluded_radius_m
    if not cand.any():
        return None
    counts = np.zeros(g.shape, dtype=np.int32)
    _count_visible(g, cand, rim_r, rim_c, near_m / res, far_m / res, FREE, counts)
    best = int(counts.max())
    if best == 0:
        return None
    goals = counts >= max(1, (best + 1) // 2)
    path = grid_path_to_mask(g, geometry, start_xy_m, goals, clearance_m, clearance_field=dist)
    if path is None:
        return None
    gr, gc = (int(v) for v in geometry.world_to_grid(path[-1, 0], path[-1, 1]))
    return ViewPose(
        goal_xy_m=(float(path[-1, 0]), float(path[-1, 1])),
        path_m=path,
        n_visible=int(counts[gr, gc]),
        n_rim=len(rim_r),
    )


@njit(cache=True)
def _count_visible(g, cand, rim_r, rim_c, near_cells, far_cells, free, counts):  # pragma: no cover
    # For every candidate cell: rim cells within [near, far] cells whose connecting line,
    # sampled at a quarter cell, crosses only FREE cells (besides the rim cell itself).
    h, w = g.shape
    for r in range(h):
        for c in range(w):
            if not cand[r, c]:
                continue
            n = 0
            for i in range(rim_r.shape[0]):
                tr = rim_r[i]
                tc = rim_c[i]
                dr = tr - r
                dc = tc - c
                d = math.sqrt(dr * dr + dc * dc)
                if d < near_cells or d > far_cells:
                    continue
                steps = int(math.ceil(d * 4.0))
                clear = True
                for s in range(1, steps):
                    t = s / steps
                    # Cell centres sit at integer indices: round to the nearest.
                    rr = int(math.floor(r + dr * t + 0.5))
                    cc = int(math.floor(c + dc * t + 0.5))
                    if rr == tr and cc == tc:
                        break
                    if g[rr, cc] != free:
                        clear = False
                        break
                if clear:
                    n += 1
            counts[r, c] = n
