"""The compiled kernels of :mod:`semexplore_gym.core.frontiers.reachable`'s searches.

The step cost near walls, an 8-connected Dijkstra that stops at the first goal cell (a step
costs the mean of its two cells' costs times its length; the grid planners of
:mod:`semexplore_gym.core.planning.grid_search_kernels` charge the entered cell's), a disc
dilation, the start's nearest usable cell (moved here unchanged from ``reachable.py``), and a
disc test at a few cells (:func:`near_marked`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["dijkstra", "dilate", "near_marked", "nearest_usable", "step_cost_kernel"]


@njit(cache=True)
def step_cost_kernel(dist, usable, pref, wall_cost, out):  # pragma: no cover - numba
    """``out`` = ``1 + wall_cost * clip(1 - min(dist, 1e9) / pref, 0, 1)`` on usable cells, inf
    elsewhere (1 when ``pref`` or ``wall_cost`` is 0): numpy's expression, one pass, same floats."""
    d = dist.ravel()
    u = usable.ravel()
    o = out.ravel()
    weigh = pref > 0.0 and wall_cost > 0.0
    for i in range(d.shape[0]):
        if not u[i]:
            o[i] = np.inf
        elif weigh:
            p = 1.0 - min(d[i], 1e9) / pref
            p = min(max(p, 0.0), 1.0)
            o[i] = 1.0 + wall_cost * p
        else:
            o[i] = 1.0


@njit(cache=True)
def dijkstra(cost, goal_mask, sr, sc):  # pragma: no cover - numba
    # 8-connected Dijkstra on cell costs (inf = blocked); stops at the first goal cell settled.
    h, w = cost.shape
    n = h * w
    dist = np.full(n, np.inf)
    parent = np.full(n, -2, dtype=np.int64)
    done = np.zeros(n, dtype=np.bool_)
    heap_k = np.empty(n // 4 + 16, dtype=np.float64)
    heap_v = np.empty(n // 4 + 16, dtype=np.int64)
    start = sr * w + sc
    dist[start] = 0.0
    parent[start] = -1
    heap_k[0] = 0.0
    heap_v[0] = start
    size = 1
    drs = (-1, 1, 0, 0, -1, -1, 1, 1)
    dcs = (0, 0, -1, 1, -1, 1, -1, 1)
    diag = math.sqrt(2.0)
    while size > 0:
        d = heap_k[0]
        k = heap_v[0]
        size -= 1
        if size > 0:
            # Pop: move the last item to the root and sift down.
            lk = heap_k[size]
            lv = heap_v[size]
            i = 0
            while True:
                j = 2 * i + 1
                if j >= size:
                    break
                if j + 1 < size and heap_k[j + 1] < heap_k[j]:
                    j += 1
                if heap_k[j] >= lk:
                    break
                heap_k[i] = heap_k[j]
                heap_v[i] = heap_v[j]
                i = j
            heap_k[i] = lk
            heap_v[i] = lv
        if done[k]:
            continue
        done[k] = True
        r = k // w
        c = k % w
        if goal_mask[r, c]:
            return k, parent
        for m in range(8):
            rr = r + drs[m]
            cc = c + dcs[m]
            if rr < 0 or rr >= h or cc < 0 or cc >= w:
                continue
            cn = cost[rr, cc]
            if not math.isfinite(cn):
                continue
            step = 1.0
            if m >= 4:
                # No cutting corners between two blocked cells.
                if not (math.isfinite(cost[r, cc]) and math.isfinite(cost[rr, c])):
                    continue
                step = diag
            kk = rr * w + cc
            nd = d + step * 0.5 * (cost[r, c] + cn)
            if nd < dist[kk]:
                dist[kk] = nd
                parent[kk] = k
                # Push (growing the heap when full) and sift up.
                if size == len(heap_k):
                    grown_k = np.empty(2 * size, dtype=np.float64)
                    grown_v = np.empty(2 * size, dtype=np.int64)
                    grown_k[:size] = heap_k
                    grown_v[:size] = heap_v
                    heap_k = grown_k
                    heap_v = grown_v
                i = size
                size += 1
                while i > 0:
                    p = (i - 1) // 2
                    if heap_k[p] <= nd:
                        break
                    heap_k[i] = heap_k[p]
                    heap_v[i] = heap_v[p]
                    i = p
                heap_k[i] = nd
                heap_v[i] = kk
    return -1, parent


@njit(cache=True)
def dilate(mask, radius_cells):  # pragma: no cover - numba
    # Cells whose centre is within radius_cells of a True cell's centre.
    h, w = mask.shape
    out = mask.copy()
    k = int(math.floor(radius_cells + 1e-9))
    r2 = radius_cells * radius_cells + 1e-9
    for r in range(h):
        for c in range(w):
            if not mask[r, c]:
                continue
            for dr in range(-k, k + 1):
                rr = r + dr
                if rr < 0 or rr >= h:
                    continue
                for dc in range(-k, k + 1):
                    cc = c + dc
                    if cc < 0 or cc >= w or dr * dr + dc * dc > r2:
                        continue
                    out[rr, cc] = True
    return out


@njit(cache=True)
def nearest_usable(usable, passable, sr, sc, max_cells):  # pragma: no cover - numba
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


@njit(cache=True)
def near_marked(mask, rows, cols, limit):  # pragma: no cover - numba
    """Whether a True cell of ``mask`` lies within ``limit`` cells of each ``(rows[i], cols[i])``:
    ``sqrt(dr^2 + dc^2) <= limit`` for some marked cell, the very test of a distance transform
    to the marked cells thresholded at ``limit`` (same floats), at those cells only."""
    h, w = mask.shape
    k = int(math.floor(limit))
    out = np.zeros(rows.shape[0], np.bool_)
    for i in range(rows.shape[0]):
        r = rows[i]
        c = cols[i]
        found = False
        for dr in range(-k, k + 1):
            rr = r + dr
            if rr < 0 or rr >= h:
                continue
            for dc in range(-k, k + 1):
                cc = c + dc
                if cc < 0 or cc >= w or not mask[rr, cc]:
                    continue
                if math.sqrt(float(dr * dr + dc * dc)) <= limit:
                    found = True
                    break
            if found:
                break
        out[i] = found
    return out
