"""Numba kernels of the grid planners (:mod:`.grid_search`): a binary-heap Dijkstra / A* over
a cell-cost array, the backtrack of its parent array, and the costmap's inflation stamp.

Cells are flat indices ``row * W + col`` of the cost array; an 8-connected move costs the
entered cell's cost times the step length (1 or sqrt 2), and never cuts a blocked corner.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def _sift_up(heap, hkey, pos, i, item, key):  # pragma: no cover - numba
    # Keys live beside the items in the heap array (no indirection), for cache locality.
    while i > 0:
        p = (i - 1) >> 1
        if hkey[p] <= key:
            break
        heap[i] = heap[p]
        hkey[i] = hkey[p]
        pos[heap[i]] = i
        i = p
    heap[i] = item
    hkey[i] = key
    pos[item] = i


@njit(cache=True)
def _sift_down(heap, hkey, pos, size, i, item, key):  # pragma: no cover - numba
    while True:
        child = 2 * i + 1
        if child >= size:
            break
        if child + 1 < size and hkey[child + 1] < hkey[child]:
            child += 1
        if key <= hkey[child]:
            break
        heap[i] = heap[child]
        hkey[i] = hkey[child]
        pos[heap[i]] = i
        i = child
    heap[i] = item
    hkey[i] = key
    pos[item] = i


@njit(cache=True)
def search_cells(cost, starts, goal, h_weight, dist, parent):  # pragma: no cover - numba
    """Dijkstra (h_weight = 0) or A* (octile heuristic * h_weight) on an indexed binary heap.

    ``starts`` are flat source indices, at the distance preset in ``dist`` if finite, else 0.
    Fills dist/parent (flat) in place;
    stops when ``goal`` (flat index, -1 = none) is settled. Each cell is in the heap at most
    once (decrease-key through ``pos``), so memory stays O(cells).
    """
    h, w = cost.shape
    n = h * w
    sqrt2 = math.sqrt(2.0)
    dr = np.array([1, -1, 0, 0, 1, 1, -1, -1])
    dc = np.array([0, 0, 1, -1, 1, -1, 1, -1])
    step = np.array([1.0, 1.0, 1.0, 1.0, sqrt2, sqrt2, sqrt2, sqrt2])
    gr = goal // w if goal >= 0 else 0
    gc = goal - gr * w if goal >= 0 else 0
    # pos: -1 never queued, -2 settled, else index in the heap.
    pos = np.full(n, -1, dtype=np.int64)
    heap = np.empty(n, dtype=np.int64)
    hkey = np.empty(n, dtype=np.float64)
    size = 0
    for i in range(starts.shape[0]):
        st = starts[i]
        if pos[st] == -1:
            # A source keeps a finite distance the caller preset (a sub-cell offset), else 0.
            if not dist[st] < np.inf:
                dist[st] = 0.0
            size += 1
            _sift_up(heap, hkey, pos, size - 1, st, dist[st])
    while size > 0:
        u = heap[0]
        size -= 1
        pos[u] = -2
        if size > 0:
            _sift_down(heap, hkey, pos, size, 0, heap[size], hkey[size])
        if u == goal:
            break
        ur = u // w
        uc = u - ur * w
        du = dist[u]
        for k in range(8):
            nr = ur + dr[k]
            nc = uc + dc[k]
            if nr < 0 or nr >= h or nc < 0 or nc >= w:
                continue
            cv = cost[nr, nc]
            if not cv < np.inf:
                continue
            if k >= 4:
                # No corner cutting: both orthogonal cells of a diagonal step must be passable.
                if not (cost[ur, nc] < np.inf and cost[nr, uc] < np.inf):
                    continue
            v = nr * w + nc
            pv = pos[v]
            if pv == -2:
                continue
            nd = du + step[k] * cv
            if nd < dist[v]:
                dist[v] = nd
                parent[v] = u
                pri = nd
                if h_weight > 0.0:
                    ddr = abs(nr - gr)
                    ddc = abs(nc - gc)
                    lo = min(ddr, ddc)
                    hi = max(ddr, ddc)
                    pri = nd + h_weight * ((hi - lo) + sqrt2 * lo)
                if pv == -1:
                    size += 1
                    _sift_up(heap, hkey, pos, size - 1, v, pri)
                else:
                    _sift_up(heap, hkey, pos, pv, v, pri)


@njit(cache=True)
def backtrack_cells(parent, goal):  # pragma: no cover - numba
    n = 0
    v = goal
    while v >= 0:
        n += 1
        v = parent[v]
    out = np.empty(n, dtype=np.int64)
    v = goal
    for i in range(n - 1, -1, -1):
        out[i] = v
        v = parent[v]
    return out


@njit(cache=True)
def stamp_costs(h, w, occ_r, occ_c, offsets, stamp_cost):  # pragma: no cover - numba
    """Max over occupied cells of the cost stamped at each disc offset (uint8, 0 elsewhere)."""
    out = np.zeros((h, w), dtype=np.uint8)
    n_off = offsets.shape[0]
    for i in range(occ_r.shape[0]):
        r0 = occ_r[i]
        c0 = occ_c[i]
        for j in range(n_off):
            r = r0 + offsets[j, 0]
            c = c0 + offsets[j, 1]
            if 0 <= r < h and 0 <= c < w and stamp_cost[j] > out[r, c]:
                out[r, c] = stamp_cost[j]
    return out
