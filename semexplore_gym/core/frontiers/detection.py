"""Wavefront frontier detection (WFD) on an encoded occupancy grid.

This follows the search of ROS ``frontier_exploration`` (``FrontierSearch::searchFrom``), which
is the WFD of Keidar & Kaminka:

1. Start at the robot's cell; if it is not free, start at the nearest free cell (8-connected BFS
   over all cells, as FE's ``nearestCell``). No free cell at all means no frontier.
2. An outer BFS visits free cells 4-connected to the start. Frontiers are therefore only found
   where the robot can get to (through known free space): a frontier behind a wall is ignored.
3. Each unvisited frontier cell met by the outer BFS seeds an inner BFS over 8-connected frontier
   cells; that group is one frontier.

**Frontier-cell convention.** By default (``cell_convention="unknown"``) a frontier cell is an
*unknown* cell with at least one *free* 4-neighbour. That is FE's ``isNewFrontierCell`` (and
explore_lite's): the frontier lies on the unknown side of the boundary, so a travel point is a
cell that is not yet seen and the planner must be allowed into unknown space to reach it (Navfn
does, ``allow_unknown``). ``cell_convention="free"`` gives the other textbook definition (a *free*
cell with an unknown 4-neighbour, Yamauchi's), whose cells are always on known free ground.

Per frontier, :class:`GridFrontier` records what FE's ``Frontier`` message records (size,
centroid, first-contact cell, Euclidean-nearest cell and its distance) plus the cell list and a
"middle" cell (the frontier cell nearest to the centroid, which unlike the centroid always lies
on the frontier). FE's names differ: FE's travel point ``"closest"`` is the *first-contact* cell
(``initial_cell`` here, the first cell the wavefront reached, i.e. roughly the nearest by path)
and FE's ``middle`` field actually holds the *Euclidean-nearest* cell (``nearest_cell``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
import numpy.typing as npt
from numba import njit

from semexplore_gym.core.grid import FREE, UNKNOWN, GridGeometry
from semexplore_gym.core.planning.grid_scan import checked_encoded_grid

__all__ = ["GridFrontier", "detect_frontiers", "frontier_cell_mask"]


@dataclass(frozen=True)
class GridFrontier:
    """One frontier: a connected group of frontier cells reachable from the robot.

    Attributes:
        cells: ``(K, 2)`` int64 ``(row, col)`` of the frontier cells, in inner-BFS order
            (``cells[0]`` is ``initial_cell``).
        size: ``K``, the number of cells.
        centroid_m: Mean world ``(x, y)`` of the cell centres (may lie off the frontier).
        initial_cell: ``(row, col)`` of the first cell the wavefront met (FE's ``"closest"``
            travel point).
        nearest_cell: ``(row, col)`` of the cell with the smallest Euclidean distance to the
            robot (what FE stores in its ``middle`` field).
        middle_cell: ``(row, col)`` of the frontier cell nearest to the centroid.
        min_distance_m: Euclidean distance from the robot to ``nearest_cell`` (FE's
            ``min_distance``), cell centre to the robot position.
        discovery_index: Rank in the order the outer BFS discovered the frontiers (0 first;
            counted before the size filter).
    """

    cells: np.ndarray
    size: int
    centroid_m: tuple[float, float]
    initial_cell: tuple[int, int]
    nearest_cell: tuple[int, int]
    middle_cell: tuple[int, int]
    min_distance_m: float
    discovery_index: int

    def cell_xy_m(self, geometry: GridGeometry, which: str) -> tuple[float, float]:
        """World ``(x, y)`` of ``"initial"``, ``"nearest"`` or ``"middle"`` cell centre."""
        cells = {
            "initial": self.initial_cell,
            "nearest": self.nearest_cell,
            "middle": self.middle_cell,
        }
        if which not in cells:
            raise ValueError(f"which must be one of {sorted(cells)}, got {which!r}")
        r, c = cells[which]
        x, y = geometry.grid_to_world(r, c)
        return (float(x), float(y))


def frontier_cell_mask(
    grid: npt.ArrayLike, cell_convention: Literal["unknown", "free"] = "unknown"
) -> np.ndarray:
    """All frontier cells of a grid, reachable or not (boolean ``(H, W)``).

    Useful for drawing and for tests; :func:`detect_frontiers` adds reachability and grouping.
    """
    a = checked_encoded_grid(grid)
    conv = _convention_code(cell_convention)
    target = a == (UNKNOWN if conv == 0 else FREE)
    other = a == (FREE if conv == 0 else UNKNOWN)
    nbr = np.zeros_like(other)
    nbr[1:, :] |= other[:-1, :]
    nbr[:-1, :] |= other[1:, :]
    nbr[:, 1:] |= other[:, :-1]
    nbr[:, :-1] |= other[:, 1:]
    return target & nbr


def detect_frontiers(
    grid: npt.ArrayLike,
    geometry: GridGeometry,
    robot_xy_m: tuple[float, float] | npt.ArrayLike,
    min_frontier_cells: int = 2,
    cell_convention: Literal["unknown", "free"] = "unknown",
) -> list[GridFrontier]:
    """Find the frontiers reachable from the robot with a wavefront BFS.

    Args:
        grid: Encoded occupancy grid ``(H, W)`` uint8 (UNKNOWN / FREE / OCCUPIED).
        geometry: Frame of ``grid``; its shape must match.
        robot_xy_m: Robot position ``(x, y)`` in metres. It must lie inside the grid.
        min_frontier_cells: Frontiers with fewer cells are dropped (FE hard-codes "more than
            one cell", i.e. 2; its melodic version calls it ``min_frontier_size``).
        cell_convention: ``"unknown"`` (FE: unknown cell next to free) or ``"free"`` (free
            cell next to unknown); see the module docstring.

    Returns:
        The frontiers in BFS discovery order (nearest by wavefront first), each at least
        ``min_frontier_cells`` large. Empty if none, or if the map has no free cell.

    Raises:
        ValueError: Bad grid values or shape, ``min_frontier_cells < 1``, unknown convention or
            a robot outside the grid.
    """
    a = checked_encoded_grid(grid)
    if a.shape != geometry.shape:
        raise ValueError(f"grid shape {a.shape} does not match geometry shape {geometry.shape}")
    if int(min_frontier_cells) < 1:
        raise ValueError(f"min_frontier_cells must be >= 1, got {min_frontier_cells!r}")
    conv = _convention_code(cell_convention)
    rx, ry = _xy(robot_xy_m)
    row_a, col_a = geometry.world_to_grid(rx, ry)
    row, col = int(row_a), int(col_a)
    if not geometry.contains(row, col):
        raise ValueError(
            f"robot position ({rx:.3f}, {ry:.3f}) m is outside the grid (cell ({row}, {col}) of shape {a.shape})"
        )
    cells, starts, n = _wfd_kernel(np.ascontiguousarray(a), row, col, conv)
    stats = _frontier_stats(
        cells, starts, geometry.origin_x_m, geometry.origin_y_m, geometry.resolution_m, rx, ry
    )
    frontiers: list[GridFrontier] = []
    for k in range(n):
        s0, s1 = int(starts[k]), int(starts[k + 1])
        if s1 - s0 < min_frontier_cells:
            continue
        fc = cells[s0:s1]
        cx, cy, i_near, i_mid, d_near = stats[k]
        i_near, i_mid = s0 + int(i_near), s0 + int(i_mid)
        frontiers.append(
            GridFrontier(
                cells=fc,
                size=s1 - s0,
                centroid_m=(float(cx), float(cy)),
                initial_cell=(int(fc[0, 0]), int(fc[0, 1])),
                nearest_cell=(int(cells[i_near, 0]), int(cells[i_near, 1])),
                middle_cell=(int(cells[i_mid, 0]), int(cells[i_mid, 1])),
                min_distance_m=float(d_near),
                discovery_index=k,
            )
        )
    return frontiers


def _convention_code(cell_convention: str) -> int:
    if cell_convention == "unknown":
        return 0
    if cell_convention == "free":
        return 1
    raise ValueError(f"cell_convention must be 'unknown' or 'free', got {cell_convention!r}")


def _xy(p: tuple[float, float] | npt.ArrayLike) -> tuple[float, float]:
    arr = np.asarray(p, dtype=np.float64).ravel()
    if arr.shape[0] < 2 or not np.isfinite(arr[:2]).all():
        raise ValueError(f"robot_xy_m must be a finite (x, y), got {p!r}")
    return float(arr[0]), float(arr[1])


@njit(cache=True)
def _is_frontier_cell(grid, r, c, conv):  # pragma: no cover - numba
    h, w = grid.shape
    own = UNKNOWN if conv == 0 else FREE
    other = FREE if conv == 0 else UNKNOWN
    if grid[r, c] != own:
        return False
    if r > 0 and grid[r - 1, c] == other:
        return True
    if r < h - 1 and grid[r + 1, c] == other:
        return True
    if c > 0 and grid[r, c - 1] == other:
        return True
    if c < w - 1 and grid[r, c + 1] == other:
        return True
    return False


@njit(cache=True)
def _wfd_kernel(grid, row, col, conv):  # pragma: no cover - numba
    """Outer 4-connected BFS over free cells, inner 8-connected BFS per frontier.

    Returns (cells (N, 2), starts (n+1,), n): frontier k is cells[starts[k]:starts[k+1]].
    """
    h, w = grid.shape
    d4r = np.array([1, -1, 0, 0])
    d4c = np.array([0, 0, 1, -1])
    d8r = np.array([1, -1, 0, 0, 1, 1, -1, -1])
    d8c = np.array([0, 0, 1, -1, 1, -1, 1, -1])
    n_cells = h * w
    cells = np.empty((0, 2), dtype=np.int64)
    starts = np.zeros(1, dtype=np.int64)

    # Start cell: the robot's, or the nearest free cell by an 8-connected BFS over all cells.
    seen = np.zeros((h, w), dtype=np.uint8)
    queue = np.empty(n_cells, dtype=np.int64)
    start = -1
    qh = 0
    qt = 0
    queue[qt] = row * w + col
    qt += 1
    seen[row, col] = 1
    while qh < qt:
        idx = queue[qh]
        qh += 1
        r = idx // w
        c = idx - r * w
        if grid[r, c] == FREE:
            start = idx
            break
        for k in range(8):
            nr = r + d8r[k]
            nc = c + d8c[k]
            if nr < 0 or nr >= h or nc < 0 or nc >= w or seen[nr, nc]:
                continue
            seen[nr, nc] = 1
            queue[qt] = nr * w + nc
            qt += 1
    if start < 0:
        return cells, starts, 0

    # visited: 1 = visited by the outer BFS; flag: 1 = already assigned to a frontier.
    visited = np.zeros((h, w), dtype=np.uint8)
    flag = np.zeros((h, w), dtype=np.uint8)
    out = np.empty((n_cells, 2), dtype=np.int64)
    n_out = 0
    starts_buf = np.empty(n_cells + 1, dtype=np.int64)
    starts_buf[0] = 0
    n_front = 0
    inner = np.empty(n_cells, dtype=np.int64)

    qh = 0
    qt = 0
    queue[qt] = start
    qt += 1
    sr = start // w
    visited[sr, start - sr * w] = 1
    while qh < qt:
        idx = queue[qh]
        qh += 1
        r = idx // w
        c = idx - r * w
        # With the "free" convention the frontier cells are the free cells the outer BFS visits.
        if conv == 1 and not flag[r, c] and _is_frontier_cell(grid, r, c, conv):
            n_out = _grow(grid, r, c, conv, flag, out, n_out, inner, d8r, d8c)
            n_front += 1
            starts_buf[n_front] = n_out
        for k in range(4):
            nr = r + d4r[k]
            nc = c + d4c[k]
            if nr < 0 or nr >= h or nc < 0 or nc >= w:
                continue
            if grid[nr, nc] == FREE:
                if not visited[nr, nc]:
                    visited[nr, nc] = 1
                    queue[qt] = nr * w + nc
                    qt += 1
            elif conv == 0 and not flag[nr, nc] and _is_frontier_cell(grid, nr, nc, conv):
                # Grow this frontier right away, as FE does, so discovery order is BFS order.
                n_out = _grow(grid, nr, nc, conv, flag, out, n_out, inner, d8r, d8c)
                n_front += 1
                starts_buf[n_front] = n_out
    return out[:n_out].copy(), starts_buf[: n_front + 1].copy(), n_front


@njit(cache=True)
def _grow(grid, r0, c0, conv, flag, out, n_out, inner, d8r, d8c):  # pragma: no cover - numba
    h, w = grid.shape
    flag[r0, c0] = 1
    out[n_out, 0] = r0
    out[n_out, 1] = c0
    n_out += 1
    ih = 0
    it = 0
    inner[it] = r0 * w + c0
    it += 1
    while ih < it:
        idx = inner[ih]
        ih += 1
        r = idx // w
        c = idx - r * w
        for k in range(8):
            nr = r + d8r[k]
            nc = c + d8c[k]
            if nr < 0 or nr >= h or nc < 0 or nc >= w or flag[nr, nc]:
                continue
            if _is_frontier_cell(grid, nr, nc, conv):
                flag[nr, nc] = 1
                out[n_out, 0] = nr
                out[n_out, 1] = nc
                n_out += 1
                inner[it] = nr * w + nc
                it += 1
    return n_out


@njit(cache=True)
def _frontier_stats(cells, starts, ox, oy, res, rx, ry):  # pragma: no cover - numba
    """Per frontier: centroid x, y, offsets of the robot-nearest and centroid-nearest cells, and
    the robot distance of the nearest one."""
    n = starts.shape[0] - 1
    out = np.empty((n, 5))
    for k in range(n):
        s0 = starts[k]
        s1 = starts[k + 1]
        sx = 0.0
        sy = 0.0
        best_d = np.inf
        best_i = 0
        for i in range(s0, s1):
            x = ox + (cells[i, 1] + 0.5) * res
            y = oy + (cells[i, 0] + 0.5) * res
            sx += x
            sy += y
            d = math.hypot(x - rx, y - ry)
            if d < best_d:
                best_d = d
                best_i = i - s0
        cx = sx / (s1 - s0)
        cy = sy / (s1 - s0)
        mid_d = np.inf
        mid_i = 0
        for i in range(s0, s1):
            x = ox + (cells[i, 1] + 0.5) * res
            y = oy + (cells[i, 0] + 0.5) * res
            d = math.hypot(x - cx, y - cy)
            if d < mid_d:
                mid_d = d
                mid_i = i - s0
        out[k, 0] = cx
        out[k, 1] = cy
        out[k, 2] = best_i
        out[k, 3] = mid_i
        out[k, 4] = best_d
    return out
