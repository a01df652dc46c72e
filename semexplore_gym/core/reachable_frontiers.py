"""The nearest frontier a disc robot can drive to, by breadth-first search on the grid.

The semantic expert's fallback: GRID-FAST-style segmentations have no frontier pathway until
the map holds an intersection (a single corridor gives no areas at all), and they seal small
frontiers. While the topometric map offers no frontier, the expert drives to the nearest
frontier found here; and it stops only when neither source has one.

A frontier cell is a FREE cell with an UNKNOWN 4-neighbour; frontier cells are grouped
8-connected and groups smaller than ``min_frontier_cells`` are ignored. The robot may use FREE
cells at least ``clearance_m`` from every OCCUPIED cell (UNKNOWN cells do not count as
obstacles, so the free cells beside a frontier stay usable). The goal is the first such cell
met by an 8-connected BFS from the robot that lies within ``reach_m`` of a kept frontier cell.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from numba import njit
from scipy import ndimage

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry, validate_encoded_grid


@dataclass(frozen=True)
class ReachableFrontier:
    """The BFS-nearest reachable frontier.

    Attributes:
        goal_xy_m: Centre of the goal cell (a usable cell within ``reach_m`` of the frontier).
        path_m: ``(K, 2)`` polyline from the robot's position through cell centres to the goal.
        path_length_m: Length of ``path_m``.
        frontier_xy_m: Centroid of the frontier group the goal is next to.
        n_frontier_cells: Size of that group.
    """

    goal_xy_m: tuple[float, float]
    path_m: np.ndarray
    path_length_m: float
    frontier_xy_m: tuple[float, float]
    n_frontier_cells: int


def clearance_field_m(grid: npt.ArrayLike, resolution_m: float) -> np.ndarray:
    """Distance in metres from every cell centre to the nearest OCCUPIED cell centre (inf if none)."""
    g = validate_encoded_grid(grid)
    occupied = g == OCCUPIED
    if not occupied.any():
        return np.full(g.shape, np.inf)
    return ndimage.distance_transform_edt(~occupied) * float(resolution_m)


def frontier_groups(grid: np.ndarray, min_frontier_cells: int) -> tuple[np.ndarray, int]:
    """Label 8-connected groups of frontier cells (FREE with an UNKNOWN 4-neighbour) of at least
    ``min_frontier_cells`` cells. Returns ``(labels, n)``; label 0 is "not a kept frontier"."""
    free = grid == FREE
    unknown = grid == UNKNOWN
    near_unknown = np.zeros_like(free)
    near_unknown[1:, :] |= unknown[:-1, :]
    near_unknown[:-1, :] |= unknown[1:, :]
    near_unknown[:, 1:] |= unknown[:, :-1]
    near_unknown[:, :-1] |= unknown[:, 1:]
    cells = free & near_unknown
    labels, n = ndimage.label(cells, structure=np.ones((3, 3), dtype=bool))
    if n == 0:
        return labels, 0
    sizes = np.bincount(labels.ravel(), minlength=n + 1)
    keep = sizes >= max(1, int(min_frontier_cells))
    keep[0] = False
    remap = np.zeros(n + 1, dtype=labels.dtype)
    remap[keep] = np.arange(1, int(keep.sum()) + 1)
    return remap[labels], int(keep.sum())


def nearest_reachable_frontier(
    grid: npt.ArrayLike,
    geometry: GridGeometry,
    start_xy_m: tuple[float, float],
    clearance_m: float,
    min_frontier_cells: int = 3,
    reach_m: float = 0.3,
    excluded_xy_m: Sequence[tuple[float, float]] = (),
    excluded_radius_m: float = 0.5,
    clearance_field: np.ndarray | None = None,
) -> ReachableFrontier | None:
    """BFS from the robot to the nearest usable cell next to a frontier.

    Args:
        grid: Encoded occupancy grid (uint8).
        geometry: Frame of ``grid``.
        start_xy_m: Robot position. When its cell is not usable (too close to a wall), the
            search starts from the nearest usable cell within 0.5 m.
        clearance_m: Minimum distance from usable cells to OCCUPIED cells.
        min_frontier_cells: Smaller frontier groups are ignored.
        reach_m: A goal cell lies within this distance of a frontier cell.
        excluded_xy_m: Frontier cells within ``excluded_radius_m`` of these points are ignored
            (the expert's blacklist).
        excluded_radius_m: See ``excluded_xy_m``.
        clearance_field: A precomputed :func:`clearance_field_m` of ``grid`` (optional).

    Returns:
        The :class:`ReachableFrontier`, or None when no frontier can be reached.

    Raises:
        ValueError: on a malformed grid, a shape mismatch or negative distances.
    """
    g = validate_encoded_grid(grid)
    if g.shape != geometry.shape:
        raise ValueError(f"grid shape {g.shape} does not match geometry shape {geometry.shape}")
    for name, value in (
        ("clearance_m", clearance_m),
        ("reach_m", reach_m),
        ("excluded_radius_m", excluded_radius_m),
    ):
        if not (math.isfinite(value) and value >= 0.0):
            raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
    res = geometry.resolution_m
    labels, n = frontier_groups(g, min_frontier_cells)
    if n == 0:
        return None
    if len(excluded_xy_m):
        fr, fc = np.nonzero(labels)
        fx, fy = geometry.grid_to_world(fr, fc)
        drop = np.zeros(len(fr), dtype=bool)
        for ex, ey in excluded_xy_m:
            drop |= np.hypot(fx - ex, fy - ey) <= excluded_radius_m
        labels[fr[drop], fc[drop]] = 0
        if not labels.any():
            return None
    dist = clearance_field if clearance_field is not None else clearance_field_m(g, res)
    usable = (g == FREE) & (dist >= clearance_m - 1e-9)
    if reach_m > 0:
        near = ndimage.distance_transform_edt(labels == 0) * res <= reach_m + 1e-9
    else:
        near = labels > 0
    goal_mask = usable & near

    path = _search_path(g, geometry, usable, goal_mask, start_xy_m)
    if path is None:
        return None
    gr, gc = (int(v) for v in geometry.world_to_grid(path[-1, 0], path[-1, 1]))
    xs, ys = path[:, 0], path[:, 1]
    # The frontier group nearest the goal cell is the one it serves.
    fr, fc = np.nonzero(labels)
    j = int(np.argmin((fr - gr) ** 2 + (fc - gc) ** 2))
    grp = labels == labels[fr[j], fc[j]]
    gr_rows, gr_cols = np.nonzero(grp)
    cx, cy = geometry.grid_to_world(gr_rows.mean(), gr_cols.mean())
    return ReachableFrontier(
        goal_xy_m=(float(xs[-1]), float(ys[-1])),
        path_m=path,
        path_length_m=float(np.hypot(*np.diff(path, axis=0).T).sum()) if len(path) > 1 else 0.0,
        frontier_xy_m=(float(cx), float(cy)),
        n_frontier_cells=int(grp.sum()),
    )


def grid_path_to(
    grid: npt.ArrayLike,
    geometry: GridGeometry,
    start_xy_m: tuple[float, float],
    goal_xy_m: tuple[float, float],
    clearance_m: float,
    goal_radius_m: float = 0.15,
    clearance_field: np.ndarray | None = None,
) -> np.ndarray | None:
    """BFS path over usable cells (see the module docstring) from ``start_xy_m`` to a usable cell
    within ``goal_radius_m`` of ``goal_xy_m``; ``(K, 2)`` world polyline, or None if unreachable."""
    g = validate_encoded_grid(grid)
    if g.shape != geometry.shape:
        raise ValueError(f"grid shape {g.shape} does not match geometry shape {geometry.shape}")
    res = geometry.resolution_m
    dist = clearance_field if clearance_field is not None else clearance_field_m(g, res)
    usable = (g == FREE) & (dist >= clearance_m - 1e-9)
    h, w = g.shape
    gr, gc = (int(v) for v in geometry.world_to_grid(goal_xy_m[0], goal_xy_m[1]))
    rad = int(math.ceil(goal_radius_m / res))
    r0, r1 = max(gr - rad, 0), min(gr + rad + 1, h)
    c0, c1 = max(gc - rad, 0), min(gc + rad + 1, w)
    if r0 >= r1 or c0 >= c1:
        return None
    goal_mask = np.zeros((h, w), dtype=bool)
    rr, cc = np.mgrid[r0:r1, c0:c1]
    xs, ys = geometry.grid_to_world(rr, cc)
    goal_mask[r0:r1, c0:c1] = np.hypot(xs - goal_xy_m[0], ys - goal_xy_m[1]) <= max(
        goal_radius_m, 0.5 * res
    )
    goal_mask &= usable
    if not goal_mask.any():
        return None
    return _search_path(g, geometry, usable, goal_mask, start_xy_m)


def _search_path(
    g: np.ndarray,
    geometry: GridGeometry,
    usable: np.ndarray,
    goal_mask: np.ndarray,
    start_xy_m: tuple[float, float],
) -> np.ndarray | None:
    h, w = g.shape
    sr, sc = (int(v) for v in geometry.world_to_grid(start_xy_m[0], start_xy_m[1]))
    if not (0 <= sr < h and 0 <= sc < w):
        return None
    if not usable[sr, sc]:
        found = _nearest_usable(
            usable, g != OCCUPIED, sr, sc, int(math.ceil(0.5 / geometry.resolution_m))
        )
        if found[0] < 0:
            return None
        sr, sc = found
    goal, parent = _bfs(usable, goal_mask, sr, sc)
    if goal < 0:
        return None
    cells = []
    k = goal
    while k >= 0:
        cells.append(k)
        k = parent[k]
    cells.reverse()
    idx = np.asarray(cells)
    xs, ys = geometry.grid_to_world(idx // w, idx % w)
    return np.vstack([np.asarray(start_xy_m, dtype=np.float64)[None, :], np.column_stack([xs, ys])])


@njit(cache=True)
def _bfs(usable, goal_mask, sr, sc):  # pragma: no cover - numba
    h, w = usable.shape
    parent = np.full(h * w, -2, dtype=np.int64)
    queue = np.empty(h * w, dtype=np.int64)
    start = sr * w + sc
    parent[start] = -1
    queue[0] = start
    head = 0
    tail = 1
    drs = (-1, 1, 0, 0, -1, -1, 1, 1)
    dcs = (0, 0, -1, 1, -1, 1, -1, 1)
    while head < tail:
        k = queue[head]
        head += 1
        r = k // w
        c = k % w
        if goal_mask[r, c]:
            return k, parent
        for m in range(8):
            rr = r + drs[m]
            cc = c + dcs[m]
            if rr < 0 or rr >= h or cc < 0 or cc >= w or not usable[rr, cc]:
                continue
            # No cutting corners between two unusable cells.
            if m >= 4 and not (usable[r, cc] and usable[rr, c]):
                continue
            kk = rr * w + cc
            if parent[kk] != -2:
                continue
            parent[kk] = k
            queue[tail] = kk
            tail += 1
    return -1, parent


@njit(cache=True)
def _nearest_usable(usable, passable, sr, sc, max_cells):  # pragma: no cover - numba
    h, w = usable.shape
    seen = np.zeros((h, w), dtype=np.bool_)
    qr = np.empty(h * w, dtype=np.int64)
    qc = np.empty(h * w, dtype=np.int64)
    qr[0] = sr
    qc[0] = sc
    seen[sr, sc] = True
    head = 0
    tail = 1
    while head < tail:
        r = qr[head]
        c = qc[head]
        head += 1
        if usable[r, c]:
            return r, c
        for dr in range(-1, 2):
            for dc in range(-1, 2):
                rr = r + dr
                cc = c + dc
                if rr < 0 or rr >= h or cc < 0 or cc >= w or seen[rr, cc] or not passable[rr, cc]:
                    continue
                if abs(rr - sr) > max_cells or abs(cc - sc) > max_cells:
                    continue
                seen[rr, cc] = True
                qr[tail] = rr
                qc[tail] = cc
                tail += 1
    return -1, -1
