"""Compiled kernels of Algorithm 1 (bit-identical to the Python/numpy forms they replace).

:func:`search_by_opening` is the search loop of
:func:`~semexplore_gym.core.planning.graph_search.search_frontier_paths` with one ``A_cost``
slot per opening (the default): the same stack order, pruning and float sums, with each path
kept as a record pointing at its parent instead of a tuple of nodes (on Willow Garage a replan
pushes hundreds of paths).

:func:`first_leg_offers` projects the robot onto every path of its area and measures the two
ways along each path, in one call instead of a dozen small numpy calls per path (on Willow
Garage an area holds ~40 paths per replan). Every value is the same floating-point expression
as :func:`~semexplore_gym.core.planning.polyline.project_onto_polyline` and
:func:`~semexplore_gym.core.planning.polyline.polyline_length` evaluate: the projection's products and sums in the same order, the
segment lengths as ``sqrt(dx * dx + dy * dy)``, and their sum by numpy's own pairwise
summation (:func:`pairwise_sum`), so the offers, and every plan built from them, do not change
in the last bit (tested against the numpy forms on random and degenerate polylines).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def _block_sum(a, lo, n):  # pragma: no cover - numba
    """numpy's sum of a run of at most 128 values: one by one below 8, else 8 partial sums."""
    if n < 8:
        res = 0.0
        for i in range(lo, lo + n):
            res += a[i]
        return res
    r0, r1, r2, r3 = a[lo], a[lo + 1], a[lo + 2], a[lo + 3]
    r4, r5, r6, r7 = a[lo + 4], a[lo + 5], a[lo + 6], a[lo + 7]
    i = 8
    m = n - n % 8
    while i < m:
        j = lo + i
        r0 += a[j]
        r1 += a[j + 1]
        r2 += a[j + 2]
        r3 += a[j + 3]
        r4 += a[j + 4]
        r5 += a[j + 5]
        r6 += a[j + 6]
        r7 += a[j + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        res += a[lo + i]
        i += 1
    return res


@njit(cache=True)
def pairwise_sum(a, lo, n):  # pragma: no cover - numba
    """``a[lo:lo + n].sum()`` with numpy's summation order (float64, contiguous), to the bit.

    numpy sums runs of up to 128 values directly (:func:`_block_sum`) and longer runs as the
    sum of two halves, the first a multiple of 8 long. The halving runs on an explicit stack
    (a recursive numba function does not survive numba's on-disk cache).
    """
    if n <= 128:
        return _block_sum(a, lo, n)
    # Tasks: (lo, n) to sum, or n == -1 for "add the two values on top of the value stack".
    task_lo = np.empty(128, np.int64)
    task_n = np.empty(128, np.int64)
    values = np.empty(64)
    n_tasks = 1
    n_values = 0
    task_lo[0] = lo
    task_n[0] = n
    while n_tasks > 0:
        n_tasks -= 1
        t_lo = task_lo[n_tasks]
        t_n = task_n[n_tasks]
        if t_n < 0:
            n_values -= 1
            values[n_values - 1] = values[n_values - 1] + values[n_values]
        elif t_n <= 128:
            values[n_values] = _block_sum(a, t_lo, t_n)
            n_values += 1
        else:
            n2 = t_n // 2
            n2 -= n2 % 8
            # Run order: the first half, then the second, then their sum.
            task_lo[n_tasks] = 0
            task_n[n_tasks] = -1
            task_lo[n_tasks + 1] = t_lo + n2
            task_n[n_tasks + 1] = t_n - n2
            task_lo[n_tasks + 2] = t_lo
            task_n[n_tasks + 2] = n2
            n_tasks += 3
    return values[0]


@njit(cache=True)
def first_leg_offers(pts, starts, px, py, seg_idx, q_xy, lengths):  # pragma: no cover - numba
    """Project ``(px, py)`` onto each polyline and measure the way to both of its ends.

    Polyline ``e`` is ``pts[starts[e]:starts[e + 1]]``. For each: ``seg_idx[e]`` the segment of
    the nearest point (the first of equals), ``q_xy[e]`` that point, ``lengths[e, 0]`` the
    distance to it plus the length from it back to the polyline's first vertex, and
    ``lengths[e, 1]`` plus the length on to its last vertex (a one-vertex polyline: the
    distance to the vertex, both ways).
    """
    n_lines = starts.shape[0] - 1
    buf = np.empty(pts.shape[0] + 1)
    for e in range(n_lines):
        lo = starts[e]
        n = starts[e + 1] - lo
        if n == 1:
            d = math.hypot(pts[lo, 0] - px, pts[lo, 1] - py)
            seg_idx[e] = 0
            q_xy[e, 0] = pts[lo, 0]
            q_xy[e, 1] = pts[lo, 1]
            lengths[e, 0] = d + 0.0
            lengths[e, 1] = d + 0.0
            continue
        best = np.inf
        bi = 0
        bqx = 0.0
        bqy = 0.0
        for s in range(n - 1):
            ax = pts[lo + s, 0]
            ay = pts[lo + s, 1]
            abx = pts[lo + s + 1, 0] - ax
            aby = pts[lo + s + 1, 1] - ay
            den = abx * abx + aby * aby
            t = 0.0
            if den > 0:
                t = ((px - ax) * abx + (py - ay) * aby) / den
                if t < 0.0:
                    t = 0.0
                elif t > 1.0:
                    t = 1.0
            qx = ax + t * abx
            qy = ay + t * aby
            d = math.hypot(qx - px, qy - py)
            if d < best:
                best = d
                bi = s
                bqx = qx
                bqy = qy
        seg_idx[e] = bi
        q_xy[e, 0] = bqx
        q_xy[e, 1] = bqy
        # Back to the first vertex: q, p_bi, p_bi-1, ..., p_0.
        dx = pts[lo + bi, 0] - bqx
        dy = pts[lo + bi, 1] - bqy
        buf[0] = math.sqrt(dx * dx + dy * dy)
        m = 1
        for k in range(bi - 1, -1, -1):
            dx = pts[lo + k, 0] - pts[lo + k + 1, 0]
            dy = pts[lo + k, 1] - pts[lo + k + 1, 1]
            buf[m] = math.sqrt(dx * dx + dy * dy)
            m += 1
        lengths[e, 0] = best + pairwise_sum(buf, 0, m)
        # On to the last vertex: q, p_bi+1, ..., p_n-1.
        dx = pts[lo + bi + 1, 0] - bqx
        dy = pts[lo + bi + 1, 1] - bqy
        buf[0] = math.sqrt(dx * dx + dy * dy)
        m = 1
        for k in range(bi + 1, n - 1):
            dx = pts[lo + k + 1, 0] - pts[lo + k, 0]
            dy = pts[lo + k + 1, 1] - pts[lo + k, 1]
            buf[m] = math.sqrt(dx * dx + dy * dy)
            m += 1
        lengths[e, 1] = best + pairwise_sum(buf, 0, m)


@njit(cache=True)
def _grow(a, n):  # pragma: no cover - numba
    out = np.empty(2 * a.shape[0], a.dtype)
    out[:n] = a[:n]
    return out


@njit(cache=True)
def search_by_opening(
    adj_ptr,
    adj_node,
    adj_edge,
    adj_len_m,
    is_frontier,
    a_cost,
    seed_node,
    seed_cost,
    seed_len_m,
    l_path,
):  # pragma: no cover - numba
    """Algorithm 1's search list with ``A_cost`` per opening, over dense node ids.

    The neighbours of node ``u`` are ``adj_node[adj_ptr[u]:adj_ptr[u + 1]]`` (in the order the
    Python search appends them) through edge ``adj_edge`` of length ``adj_len_m``. ``a_cost``
    holds the seeds' costs (inf elsewhere) and is updated in place; the seeds are pushed in
    order. Paths are records: node, edge (-1 for a seed), parent record (-1), cost, length.

    Returns ``(order, best_rec, rec_node, rec_edge, rec_parent, rec_cost, rec_len_m, n_pushed,
    n_popped, n_pruned)``: the frontier nodes in the order they were first reached and, per
    node, the record of its cheapest path (-1: not reached).
    """
    n_seeds = seed_node.shape[0]
    cap = max(64, 4 * n_seeds)
    rec_node = np.empty(cap, np.int64)
    rec_edge = np.empty(cap, np.int64)
    rec_parent = np.empty(cap, np.int64)
    rec_cost = np.empty(cap)
    rec_len = np.empty(cap)
    stack = np.empty(cap, np.int64)
    for s in range(n_seeds):
        rec_node[s] = seed_node[s]
        rec_edge[s] = -1
        rec_parent[s] = -1
        rec_cost[s] = seed_cost[s]
        rec_len[s] = seed_len_m[s]
        stack[s] = s
    n_rec = n_seeds
    top = n_seeds
    n_nodes = is_frontier.shape[0]
    best_rec = np.full(n_nodes, -1, np.int64)
    order = np.empty(n_nodes, np.int64)
    n_order = 0
    n_pushed = n_seeds
    n_popped = 0
    n_pruned = 0
    while top > 0:
        top -= 1
        r = stack[top]
        n_popped += 1
        last = rec_node[r]
        cost = rec_cost[r]
        if a_cost[last] < cost:
            n_pruned += 1  # reached more cheaply since it was pushed
            continue
        if is_frontier[last]:
            b = best_rec[last]
            if b < 0:
                order[n_order] = last
                n_order += 1
                best_rec[last] = r
            elif cost < rec_cost[b]:
                best_rec[last] = r
        for j in range(adj_ptr[last], adj_ptr[last + 1]):
            v = adj_node[j]
            q = r
            on_path = False
            while q >= 0:
                if rec_node[q] == v:
                    on_path = True
                    break
                q = rec_parent[q]
            if on_path:
                continue
            new_cost = cost + adj_len_m[j] / l_path
            if a_cost[v] <= new_cost:
                n_pruned += 1
                continue
            a_cost[v] = new_cost
            if n_rec == rec_node.shape[0]:
                rec_node = _grow(rec_node, n_rec)
                rec_edge = _grow(rec_edge, n_rec)
                rec_parent = _grow(rec_parent, n_rec)
                rec_cost = _grow(rec_cost, n_rec)
                rec_len = _grow(rec_len, n_rec)
                stack = _grow(stack, top)
            rec_node[n_rec] = v
            rec_edge[n_rec] = adj_edge[j]
            rec_parent[n_rec] = r
            rec_cost[n_rec] = new_cost
            rec_len[n_rec] = rec_len[r] + adj_len_m[j]
            stack[top] = n_rec
            top += 1
            n_rec += 1
            n_pushed += 1
    return (
        order[:n_order],
        best_rec,
        rec_node,
        rec_edge,
        rec_parent,
        rec_cost,
        rec_len,
        n_pushed,
        n_popped,
        n_pruned,
    )
