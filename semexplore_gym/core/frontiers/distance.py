"""Path length from every cell to the nearest frontier cell, as one numba kernel.

The ``frontier_distance`` channel of :mod:`semexplore_gym.core.features.egocentric` needs this field at
every step. Composed from general tools (a scipy dilation for the wall clearance, then the
heap-based Dijkstra of :func:`semexplore_gym.core.grid_search.distance_field`) it cost most of
an encode. The kernel here fuses the frontier test, the clearance mask and the search, and
replaces the binary heap by three FIFO queues: the search has only two edge weights (a side
step ``res`` and a diagonal step ``sqrt(2) * res``) and the sources are taken in order of
their keys, so the keys pushed through each weight leave in the order they were pushed and the
smallest of the three queue heads is the global minimum (Dijkstra's settle order without a
heap). Between steps a map changes in a few cells: :class:`FrontierDistanceField` keeps the
field and its buffers and repairs only what the change invalidated.

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
    the last map. An update with an unchanged map costs one comparison pass; one whose map
    changed in a few cells (a scan's worth) repairs the field instead of recomputing it:

    1. the cells whose search state (blocked, passable, frontier) changed are found in the
       changed cells' bounding box, grown by the clearance;
    2. those cells, their 8 neighbours and, transitively, every cell whose distance was
       reached through an invalidated one (``d[v] == d[u] + w(u, v)``) are invalidated;
    3. a Dijkstra seeded with the invalidated cells' best values from the valid cells round
       them (0 for frontier cells) settles them again, lowering any other cell it improves.

    Every distance that survives step 2 is still realised by a path of the new map, so the
    repair reaches the same unique fixed point ``d[v] = min_u fl(d[u] + w(u, v))`` as a search
    from scratch: the field is bit-identical to :func:`frontier_distance_m` of the same map.
    The distances live in :attr:`dist_padded`, a flat array over the grid with a one-cell border
    of ``inf`` (cell ``(r, c)`` at ``(r + 1) * (W + 2) + c + 1``), which kernels read in place.

    Args:
        shape: ``(H, W)`` of the grids to come.
        resolution_m: Cell side in metres.
        clearance_m: Minimum distance of a path cell from walls.
        incremental: Repair after small changes (False: recompute from scratch every time).
    """

    def __init__(
        self,
        shape: tuple[int, int],
        resolution_m: float,
        clearance_m: float,
        incremental: bool = True,
    ) -> None:
        if not (math.isfinite(resolution_m) and resolution_m > 0):
            raise ValueError(f"resolution_m must be a positive number, got {resolution_m!r}")
        if not (math.isfinite(clearance_m) and clearance_m >= 0):
            raise ValueError(f"clearance_m must be a finite number >= 0, got {clearance_m!r}")
        h, w = (int(v) for v in shape)
        self.shape = (h, w)
        self.row_stride = w + 2
        self.incremental = bool(incremental)
        n = (h + 2) * (w + 2)
        self.off_r, self.off_c = clearance_offsets(resolution_m, clearance_m)
        # The same products as the general Dijkstra's step costs (side, diagonal).
        self._w_side = 1.0 * float(resolution_m)
        self._w_diag = math.sqrt(2.0) * float(resolution_m)
        self.dist_padded = np.full(n, np.inf)
        # 0 blocked, 1 passable, 2 frontier (passable); the border stays 0.
        self._state = np.zeros(n, np.uint8)
        self._inv = np.zeros(n, np.uint8)
        self._cells = np.empty(n, np.int32)  # invalidated cells, then sources
        self._seed_node = np.empty(n, np.int32)
        self._seed_key = np.empty(n, np.float64)
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
            True when the field changed or was rebuilt, False when ``grid`` equals the last map.

        Raises:
            ValueError: ``grid`` holds a value other than UNKNOWN, FREE or OCCUPIED.
        """
        full = not (self._valid and self.incremental)
        self._valid = False
        status = _update_kernel(
            grid, self._last_map, full, self.off_r, self.off_c, self._w_side, self._w_diag,
            self.dist_padded, self._state, self._inv, self._cells,
            self._seed_node, self._seed_key, self._q1_node, self._q1_key, self._q2_node,
            self._q2_key,
        )  # fmt: skip
        if status < 0:
            self._inv[:] = 0
            validate_encoded_grid(grid)  # a value outside UNKNOWN/FREE/OCCUPIED: raises naming it
        self._valid = True
        return status > 0

    def distance_m(self) -> np.ndarray:
        """``(H, W)`` float64 copy of the distances (``inf`` where no frontier is reachable)."""
        h, w = self.shape
        return self.dist_padded.reshape(h + 2, w + 2)[1:-1, 1:-1].copy()


@njit(cache=True, inline="always")
def _cell_state(grid, r, c, off_r, off_c):  # pragma: no cover - numba
    """Search state of cell ``(r, c)``: 0 blocked, 1 passable, 2 frontier; 255: bad value."""
    h, w = grid.shape
    v = grid[r, c]
    if v == FREE:
        if (
            (r > 0 and grid[r - 1, c] == UNKNOWN)
            or (r < h - 1 and grid[r + 1, c] == UNKNOWN)
            or (c > 0 and grid[r, c - 1] == UNKNOWN)
            or (c < w - 1 and grid[r, c + 1] == UNKNOWN)
        ):
            return 2
        # The offsets are symmetric: a wall within the clearance of this cell blocks it.
        for k in range(off_r.shape[0]):
            rr = r + off_r[k]
            cc = c + off_c[k]
            if 0 <= rr < h and 0 <= cc < w and grid[rr, cc] == OCCUPIED:
                return 0
        return 1
    if v != UNKNOWN and v != OCCUPIED:
        return 255
    return 0


@njit(cache=True)
def _update_kernel(
    grid,
    last,
    full,
    off_r,
    off_c,
    w_side,
    w_diag,
    dp,
    state,
    inv,
    cells,
    seed_node,
    seed_key,
    q1_node,
    q1_key,
    q2_node,
    q2_key,
):  # pragma: no cover - numba
    """Update the padded flat field ``dp`` to ``grid``; 0 unchanged, 1 updated, -1 bad value.

    ``full``: recompute every cell (the first map, or no incremental repair); otherwise
    compare ``grid`` with ``last`` (the previous map) and repair (see
    :class:`FrontierDistanceField`). ``last`` receives ``grid`` in both cases.
    """
    h, w = grid.shape
    wp = w + 2
    # Bounding box of the changed cells.
    r0, r1, c0, c1 = h, -1, w, -1
    if full:
        r0, r1, c0, c1 = 0, h - 1, 0, w - 1
    else:
        # Compare 8 cells at a time, then the cells of the words that differ.
        a = grid.ravel()
        b = last.ravel()
        n = a.shape[0]
        n8 = n - n % 8
        a8 = a[:n8].view(np.uint64)
        b8 = b[:n8].view(np.uint64)
        for q in range(n8 // 8):
            if a8[q] != b8[q]:
                for i in range(8 * q, 8 * q + 8):
                    if a[i] != b[i]:
                        r, c = i // w, i % w
                        r0, r1, c0, c1 = min(r0, r), max(r1, r), min(c0, c), max(c1, c)
        for i in range(n8, n):
            if a[i] != b[i]:
                r, c = i // w, i % w
                r0, r1, c0, c1 = min(r0, r), max(r1, r), min(c0, c), max(c1, c)
        if r1 < 0:
            return 0
        if 4 * (r1 - r0 + 1) * (c1 - c0 + 1) > h * w:
            # A new map rather than a scan's worth of changes: a fresh search is cheaper.
            full = True
            r0, r1, c0, c1 = 0, h - 1, 0, w - 1
    for r in range(r0, r1 + 1):
        for c in range(c0, c1 + 1):
            last[r, c] = grid[r, c]
    # A cell's state depends on the map within max(1, clearance reach) of it.
    reach = 1
    for k in range(off_r.shape[0]):
        reach = max(reach, abs(off_r[k]), abs(off_c[k]))
    r0, r1 = max(0, r0 - reach), min(h - 1, r1 + reach)
    c0, c1 = max(0, c0 - reach), min(w - 1, c1 + reach)
    n_seed = 0
    if full:
        for r in range(h):
            base = (r + 1) * wp + 1
            for c in range(w):
                s = _cell_state(grid, r, c, off_r, off_c)
                if s == 255:
                    return -1
                i = base + c
                state[i] = s
                if s == 2:
                    dp[i] = 0.0
                    seed_node[n_seed] = i
                    seed_key[n_seed] = 0.0
                    n_seed += 1
                else:
                    dp[i] = np.inf
    else:
        # Changed states: invalidate them and their 8 neighbours (a diagonal step through
        # their corner may have opened or closed).
        n_inv = 0
        for r in range(r0, r1 + 1):
            for c in range(c0, c1 + 1):
                s = _cell_state(grid, r, c, off_r, off_c)
                if s == 255:
                    return -1
                i = (r + 1) * wp + c + 1
                if s != state[i]:
                    state[i] = s
                    for dr in range(-wp, wp + 1, wp):
                        for dc in range(-1, 2):
                            j = i + dr + dc
                            if inv[j] == 0:
                                inv[j] = 1
                                cells[n_inv] = j
                                n_inv += 1
        if n_inv == 0:
            return 1
        # Every cell whose distance came through an invalidated cell is invalid too. (Border
        # cells hold inf and are never reached: an inf cell does not propagate.)
        k = 0
        while k < n_inv:
            u = cells[k]
            k += 1
            du = dp[u]
            if not du < np.inf:
                continue
            nd = du + w_side
            for v in (u + 1, u - 1, u + wp, u - wp):
                if inv[v] == 0 and dp[v] == nd:
                    inv[v] = 1
                    cells[n_inv] = v
                    n_inv += 1
            nd = du + w_diag
            for v in (u + wp + 1, u + wp - 1, u - wp + 1, u - wp - 1):
                if inv[v] == 0 and dp[v] == nd:
                    inv[v] = 1
                    cells[n_inv] = v
                    n_inv += 1
        for k in range(n_inv):
            dp[cells[k]] = np.inf
        # Seeds: each invalidated passable cell at its best value from the valid cells round
        # it (invalid ones hold inf), frontier cells at 0.
        for k in range(n_inv):
            v = cells[k]
            inv[v] = 0
            s = state[v]
            if s == 0:
                continue
            if s == 2:
                best = 0.0
            else:
                best = np.inf
                for u in (v + 1, v - 1, v + wp, v - wp):
                    nd = dp[u] + w_side
                    if nd < best:
                        best = nd
                up, dn, rt, lf = (
                    state[v + wp] != 0,
                    state[v - wp] != 0,
                    state[v + 1] != 0,
                    state[v - 1] != 0,
                )
                if up and rt:
                    nd = dp[v + wp + 1] + w_diag
                    if nd < best:
                        best = nd
                if up and lf:
                    nd = dp[v + wp - 1] + w_diag
                    if nd < best:
                        best = nd
                if dn and rt:
                    nd = dp[v - wp + 1] + w_diag
                    if nd < best:
                        best = nd
                if dn and lf:
                    nd = dp[v - wp - 1] + w_diag
                    if nd < best:
                        best = nd
                if not best < np.inf:
                    continue
            seed_key[n_seed] = best
            seed_node[n_seed] = v
            n_seed += 1
        # Settle order needs the seeds by key.
        order = np.argsort(seed_key[:n_seed], kind="mergesort")
        for k in range(n_seed):
            cells[k] = seed_node[order[k]]
        for k in range(n_seed):
            seed_node[k] = cells[k]
            dp[cells[k]] = seed_key[order[k]]
        for k in range(n_seed):
            seed_key[k] = dp[seed_node[k]]
    _settle(state, dp, seed_node, seed_key, n_seed, wp, w_side, w_diag,
            q1_node, q1_key, q2_node, q2_key)  # fmt: skip
    return 1


@njit(cache=True, inline="always")
def _relax(state, dp, v, nd, q_node, q_key, t):  # pragma: no cover - numba
    """Lower ``dp[v]`` to ``nd`` and queue ``v`` when that is shorter; returns the new tail.

    A settled cell is never lowered (every later key is larger), so it needs no test here.
    """
    if state[v] != 0:
        if nd < dp[v]:
            dp[v] = nd
            q_node[t] = v
            q_key[t] = nd
            return t + 1
    return t


@njit(cache=True)
def _settle(
    state,
    dp,
    q0_node,
    q0_key,
    n0,
    wp,
    w_side,
    w_diag,
    q1_node,
    q1_key,
    q2_node,
    q2_key,
):  # pragma: no cover - numba
    """Dijkstra over the padded flat grid from the ``n0`` seeds (sorted by key) in ``q0``.

    ``w_side`` and ``w_diag`` are the same products (step times cell cost) as the general
    Dijkstra's. Pops come from three queues whose keys never decrease: the seeds, the cells
    reached by a side step and those reached by a diagonal step. Every push lowers its
    cell's distance, so the one entry whose key still equals it settles the cell and the
    others are stale.
    """
    h0, h1, t1, h2, t2 = 0, 0, 0, 0, 0
    inf = np.inf
    while True:
        k0 = q0_key[h0] if h0 < n0 else inf
        k1 = q1_key[h1] if h1 < t1 else inf
        k2 = q2_key[h2] if h2 < t2 else inf
        if h0 < n0 and k0 <= k1 and k0 <= k2:
            u, du = q0_node[h0], k0
            h0 += 1
        elif h1 < t1 and k1 <= k2:
            u, du = q1_node[h1], k1
            h1 += 1
        elif h2 < t2:
            u, du = q2_node[h2], k2
            h2 += 1
        else:
            break
        if du != dp[u]:
            continue  # a stale entry: the cell was lowered since (and settled from there)
        nd = du + w_side
        t1 = _relax(state, dp, u + 1, nd, q1_node, q1_key, t1)
        t1 = _relax(state, dp, u - 1, nd, q1_node, q1_key, t1)
        t1 = _relax(state, dp, u + wp, nd, q1_node, q1_key, t1)
        t1 = _relax(state, dp, u - wp, nd, q1_node, q1_key, t1)
        # No corner cutting: both side cells of a diagonal step must be passable.
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
