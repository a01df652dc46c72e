"""Path length from every cell to the nearest frontier cell, as one numba kernel.

The ``frontier_distance`` channel of :mod:`semexplore_gym.core.features.egocentric` needs this field at
every step. Composed from general tools (a scipy dilation for the wall clearance, then the
heap-based Dijkstra of :func:`semexplore_gym.core.grid_search.distance_field`) it cost most of
an encode. The kernel here fuses the frontier test, the clearance mask and the search, and
replaces the binary heap by three FIFO queues: the search has only two edge weights (a side
step ``res`` and a diagonal step ``sqrt(2) * res``) and every source starts at 0, so the keys
pushed through each weight leave in the order they were pushed and the smallest of the three
queue heads is the global minimum (Dijkstra's settle order without a heap).

Every distance is the same floating-point sum as the general Dijkstra's (``d[u] + step * res``
with the same two step values): both settle cells in non-decreasing order, so both reach the
unique fixed point ``d[v] = min over neighbours u of fl(d[u] + w(u, v))`` and agree bit for bit.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, validate_encoded_grid


def clearance_offsets(resolution_m: float, clearance_m: float) -> tuple[np.ndarray, np.ndarray]:
    """``(d_row, d_col)`` int64 offsets of the cells nearer than ``clearance_m`` to a cell centre.

    A FREE cell at one of these offsets from an OCCUPIED cell is too near the wall for a path.
    Empty when ``clearance_m`` is below one cell's reach (no cell is blocked).
    """
    r = int(math.ceil(clearance_m / resolution_m))
    if r <= 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    dr, dc = np.mgrid[-r : r + 1, -r : r + 1]
    # The 1e-9 keeps cells exactly at the clearance usable (a wall-hugging corridor of the
    # clearance's width stays open).
    near = np.hypot(dr, dc) * resolution_m < clearance_m - 1e-9
    return dr[near].astype(np.int64), dc[near].astype(np.int64)


def frontier_distance_m(grid: np.ndarray, resolution_m: float, clearance_m: float) -> np.ndarray:
    """Path length in metres from every cell to the nearest frontier cell, through free space.

    A frontier cell is a FREE cell with an UNKNOWN 4-neighbour. Paths run 8-connected (no
    corner cutting) over FREE cells whose centre is at least ``clearance_m`` from every OCCUPIED
    cell centre (frontier cells themselves always count).

    Args:
        grid: ``(H, W)`` uint8 encoded occupancy grid.
        resolution_m: Cell side in metres.
        clearance_m: Minimum distance of a path cell from walls.

    Returns:
        ``(H, W)`` float64 distances, ``inf`` where no frontier can be reached (or none exists).

    Raises:
        ValueError, TypeError: ``grid`` is not a valid encoded grid, or the resolution is not
            positive.
    """
    a = np.asarray(grid)
    if a.ndim != 2 or a.dtype != np.uint8 or a.size == 0:
        validate_encoded_grid(a)  # raises with the reason
    if not (math.isfinite(resolution_m) and resolution_m > 0):
        raise ValueError(f"resolution_m must be a positive number, got {resolution_m!r}")
    if not (math.isfinite(clearance_m) and clearance_m >= 0):
        raise ValueError(f"clearance_m must be a finite number >= 0, got {clearance_m!r}")
    field = FrontierDistanceField(a.shape, resolution_m, clearance_m)
    field.update(np.ascontiguousarray(a))
    return field.distance_m()


class FrontierDistanceField:
    """The frontier distance of one grid shape, kept up to date as the map changes.

    Holds the search's buffers (allocated once, reused by every :meth:`update`) and a copy of
    the last map: an update with an unchanged map costs one comparison pass. The distances
    live in :attr:`dist_padded`, a flat array over the grid with a one-cell border of ``inf``
    (cell ``(r, c)`` at ``(r + 1) * (W + 2) + c + 1``), which kernels read without copying.

    Args:
        shape: ``(H, W)`` of the grids to come.
        resolution_m: Cell side in metres.
        clearance_m: Minimum distance of a path cell from walls.
    """

    def __init__(self, shape: tuple[int, int], resolution_m: float, clearance_m: float) -> None:
        if not (math.isfinite(resolution_m) and resolution_m > 0):
            raise ValueError(f"resolution_m must be a positive number, got {resolution_m!r}")
        if not (math.isfinite(clearance_m) and clearance_m >= 0):
            raise ValueError(f"clearance_m must be a finite number >= 0, got {clearance_m!r}")
        h, w = (int(v) for v in shape)
        self.shape = (h, w)
        self.row_stride = w + 2
        n = (h + 2) * (w + 2)
        self.off_r, self.off_c = clearance_offsets(resolution_m, clearance_m)
        # The same products as the general Dijkstra's step costs (side, diagonal).
        self._w_side = 1.0 * float(resolution_m)
        self._w_diag = math.sqrt(2.0) * float(resolution_m)
        self.dist_padded = np.full(n, np.inf)
        self._state = np.zeros(n, np.uint8)
        self._queue0 = np.empty(h * w, np.int32)
        # A cell enters each step queue at most 4 times (once per neighbour of that kind).
        self._q1_node = np.empty(4 * n, np.int32)
        self._q1_key = np.empty(4 * n, np.float64)
        self._q2_node = np.empty(4 * n, np.int32)
        self._q2_key = np.empty(4 * n, np.float64)
        self._last_map = np.zeros((h, w), np.uint8)
        self._valid = False

    def update(self, grid: np.ndarray) -> bool:
        """Bring the distances up to date with ``grid`` (C-contiguous uint8 of :attr:`shape`).

        Returns:
            True when the field was recomputed, False when ``grid`` equals the last map.

        Raises:
            ValueError: ``grid`` holds a value other than UNKNOWN, FREE or OCCUPIED.
        """
        if self._valid:
            if not _copy_if_changed(grid, self._last_map):
                return False
            self._valid = False
        else:
            self._last_map[...] = grid
        if not _frontier_distance_kernel(
            grid, self.off_r, self.off_c, self._w_side, self._w_diag, self.dist_padded,
            self._state, self._queue0, self._q1_node, self._q1_key, self._q2_node, self._q2_key,
        ):  # fmt: skip
            validate_encoded_grid(grid)  # a value outside UNKNOWN/FREE/OCCUPIED: raises naming it
        self._valid = True
        return True

    def distance_m(self) -> np.ndarray:
        """``(H, W)`` float64 copy of the distances (``inf`` where no frontier is reachable)."""
        h, w = self.shape
        return self.dist_padded.reshape(h + 2, w + 2)[1:-1, 1:-1].copy()


@njit(cache=True)
def _copy_if_changed(src, dst):  # pragma: no cover - numba
    """Copy ``src`` into ``dst`` (same shape); False, copying nothing, when they are equal."""
    a = src.ravel()
    b = dst.ravel()
    n = a.shape[0]
    i = 0
    while i < n and a[i] == b[i]:
        i += 1
    if i == n:
        return False
    b[i:] = a[i:]
    return True


def relative_distance_image(
    dist: np.ndarray, row: int, col: int, distance_scale_per_m: float
) -> np.ndarray:
    """``(H, W)`` uint8 ``frontier_distance`` layer: distances relative to the robot's cell.

    ``128 + distance_scale_per_m * (d - d_robot)`` rounded half to even and clipped to
    [0, 254]; 255 where ``d`` is infinite. ``d_robot`` is the distance at ``(row, col)``, or
    the smallest finite distance in the 5 x 5 window round it when that cell is unreachable
    (the robot may stand too near a wall for the search), or 0 when the window has none.
    """
    h, w = dist.shape
    if 0 <= row < h and 0 <= col < w and math.isfinite(dist[row, col]):
        d_robot = float(dist[row, col])
    else:
        win = dist[max(0, row - 2) : max(0, row + 3), max(0, col - 2) : max(0, col + 3)]
        finite = win[np.isfinite(win)]
        d_robot = float(finite.min()) if finite.size else 0.0
    out = np.empty(dist.shape, np.uint8)
    _relative_kernel(np.ascontiguousarray(dist), d_robot, float(distance_scale_per_m), out)
    return out


@njit(cache=True)
def _frontier_distance_kernel(
    grid, off_r, off_c, w_side, w_diag, dp, state, queue0, q1_node, q1_key, q2_node, q2_key
):  # pragma: no cover - numba
    """Fill the padded flat ``dp`` with the frontier distance; False if ``grid`` has a bad value.

    ``dp`` and ``state`` carry a one-cell blocked border (``inf`` and 0, never written here), so
    neighbours need no bounds checks; every interior cell is rewritten.
    """
    h, w = grid.shape
    wp = w + 2
    # state: 0 blocked, 1 passable, 2 frontier (passable, never blocked), 3 settled.
    n_src = 0
    for r in range(h):
        base = (r + 1) * wp + 1
        for c in range(w):
            v = grid[r, c]
            i = base + c
            dp[i] = np.inf
            state[i] = 0
            if v == FREE:
                if (
                    (r > 0 and grid[r - 1, c] == UNKNOWN)
                    or (r < h - 1 and grid[r + 1, c] == UNKNOWN)
                    or (c > 0 and grid[r, c - 1] == UNKNOWN)
                    or (c < w - 1 and grid[r, c + 1] == UNKNOWN)
                ):
                    state[i] = 2
                    dp[i] = 0.0
                    queue0[n_src] = i
                    n_src += 1
                else:
                    state[i] = 1
            elif v != UNKNOWN and v != OCCUPIED:
                return False
    if n_src > 0:
        n_off = off_r.shape[0]
        if n_off > 0:
            for r in range(h):
                for c in range(w):
                    if grid[r, c] == OCCUPIED:
                        for k in range(n_off):
                            rr = r + off_r[k]
                            cc = c + off_c[k]
                            if 0 <= rr < h and 0 <= cc < w:
                                i = (rr + 1) * wp + cc + 1
                                if state[i] == 1:
                                    state[i] = 0
        for i in range(n_src):
            state[queue0[i]] = 1
        _settle(state, dp, queue0, n_src, wp, w_side, w_diag, q1_node, q1_key, q2_node, q2_key)
    return True


@njit(cache=True, inline="always")
def _relax(state, dp, v, nd, q_node, q_key, t):  # pragma: no cover - numba
    """Lower ``dp[v]`` to ``nd`` and queue ``v`` when that is shorter; returns the new tail."""
    if state[v] == 1:
        if nd < dp[v]:
            dp[v] = nd
            q_node[t] = v
            q_key[t] = nd
            return t + 1
    return t


@njit(cache=True)
def _settle(
    state, dp, queue0, n_src, wp, w_side, w_diag, q1_node, q1_key, q2_node, q2_key
):  # pragma: no cover - numba
    """Multi-source Dijkstra over the padded flat grid from the ``n_src`` sources at distance 0.

    ``w_side`` and ``w_diag`` are the same products (step times cell cost) as the general
    Dijkstra's. Pops come from three queues whose keys never decrease: the sources, the cells
    reached by a side step and those reached by a diagonal step.
    """
    h0, h1, t1, h2, t2 = 0, 0, 0, 0, 0
    while True:
        if h0 < n_src:
            u = queue0[h0]
            h0 += 1
        elif h1 < t1 and (h2 >= t2 or q1_key[h1] <= q2_key[h2]):
            u = q1_node[h1]
            h1 += 1
        elif h2 < t2:
            u = q2_node[h2]
            h2 += 1
        else:
            break
        if state[u] == 3:
            continue  # a stale entry: the cell was settled from a smaller key
        state[u] = 3
        du = dp[u]
        nd = du + w_side
        t1 = _relax(state, dp, u + 1, nd, q1_node, q1_key, t1)
        t1 = _relax(state, dp, u - 1, nd, q1_node, q1_key, t1)
        t1 = _relax(state, dp, u + wp, nd, q1_node, q1_key, t1)
        t1 = _relax(state, dp, u - wp, nd, q1_node, q1_key, t1)
        # No corner cutting: both side cells of a diagonal step must be passable (or settled).
        nd = du + w_diag
        up, dn, rt, lf = (
            state[u + wp] != 0,
            state[u - wp] != 0,
            state[u + 1] != 0,
            state[u - 1] != 0,
        )
        if up and rt:
            t2 = _relax(state, dp, u + wp + 1, nd, q2_node, q2_key, t2)
        if up and lf:
            t2 = _relax(state, dp, u + wp - 1, nd, q2_node, q2_key, t2)
        if dn and rt:
            t2 = _relax(state, dp, u - wp + 1, nd, q2_node, q2_key, t2)
        if dn and lf:
            t2 = _relax(state, dp, u - wp - 1, nd, q2_node, q2_key, t2)


@njit(cache=True)
def _relative_kernel(dist, d_robot, scale, out):  # pragma: no cover - numba
    h, w = dist.shape
    for r in range(h):
        for c in range(w):
            d = dist[r, c]
            if d < np.inf:
                v = np.rint(128.0 + scale * (d - d_robot))
                out[r, c] = np.uint8(min(max(v, 0.0), 254.0))
            else:
                out[r, c] = 255
