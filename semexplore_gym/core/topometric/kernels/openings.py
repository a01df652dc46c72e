"""Stage 5 of the segmentation, intersections and openings.

:func:`place_openings` merges junctions whose cores overlap along an edge and otherwise places
an opening on the edge just outside the core, slid to the narrowest point and, at a mouth, to
the shortest chord (:func:`_refine_opening`). :func:`opening_chords` then gives each opening its
wall-to-wall chord (:func:`_chord`), once the regions of :mod:`.regions` are labelled.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from semexplore_gym.core.grid import FREE


@njit(cache=True, error_model="numpy")
def _best_opening(edge_px, lo, i0, i1, step, dflat, W, weight):
    """Index in [i0, i1] (walking by ``step``) minimising 2*d + weight*distance from i0."""
    best = i0
    best_cost = 1e300
    i = i0
    s = 0.0
    prev = edge_px[lo + i0]
    while True:
        cur = edge_px[lo + i]
        if i != i0:
            pr = prev // W
            cr = cur // W
            dr = abs(pr - cr)
            dc = abs((prev - pr * W) - (cur - cr * W))
            s += 1.4142135623730951 if (dr + dc) == 2 else 1.0
        cost = 2.0 * dflat[cur] + weight * s
        if cost < best_cost - 1e-9:
            best_cost = cost
            best = i
        prev = cur
        if i == i1:
            break
        i += step
    return best


@njit(cache=True, error_model="numpy")
def _march(work, r0, c0, ur, uc, max_t, step):
    """Distance along (ur, uc) from point (r0, c0) to the first non-free sample (max_t + 1 if none)."""
    H, W = work.shape
    t = step
    while t <= max_t:
        r = int(np.floor(r0 + t * ur))
        c = int(np.floor(c0 + t * uc))
        if r < 0 or c < 0 or r >= H or c >= W or work[r, c] != FREE:
            return t
        t += step
    return max_t + 1.0


@njit(cache=True, error_model="numpy")
def _edge_normal(edge_px, lo, L, idx, W):
    """Angle (radians, in (row, col) space) of the normal to an edge at pixel ``idx``."""
    i0 = max(idx - 3, 0)
    i1 = min(idx + 3, L - 1)
    p0 = edge_px[lo + i0]
    p1 = edge_px[lo + i1]
    tr = float(p1 // W - p0 // W)
    tc = float((p1 % W) - (p0 % W))
    if tr == 0.0 and tc == 0.0:
        tc = 1.0
    return np.arctan2(tr, tc) + np.pi / 2.0


@njit(cache=True, error_model="numpy")
def _chord(work, r, c, base, n_angles, max_angle, max_t, step):
    """Shortest chord through cell (r, c) within ``max_angle`` of ``base``: (length, ur, uc, t1, t2)."""
    pr = r + 0.5
    pc = c + 0.5
    best = 1e300
    bur = 0.0
    buc = 0.0
    bt1 = 0.0
    bt2 = 0.0
    for a in range(-n_angles, n_angles + 1):
        ang = base + max_angle * a / max(n_angles, 1)
        ur = np.sin(ang)
        uc = np.cos(ang)
        # Each march stops as soon as its chord can no longer beat the best one: a sample
        # sequence cut at ``cap`` returns the same hit when there is one before ``cap`` and
        # ``cap + 1`` (a sure reject) otherwise, so the chosen chord is unchanged.
        t1 = _march(work, pr, pc, ur, uc, min(max_t, best), step)
        if t1 >= best:
            continue
        t2 = _march(work, pr, pc, -ur, -uc, min(max_t, best - 1e-9 - t1), step)
        tot = t1 + t2
        if tot < best - 1e-9:
            best = tot
            bur = ur
            buc = uc
            bt1 = t1
            bt2 = t2
    return best, bur, buc, bt1, bt2


@njit(cache=True, error_model="numpy")
def _refine_opening(work, dflat, edge_px, lo, L, i0, lo_lim, hi_lim, W, max_angle, weight):
    """Index near ``i0`` in [lo_lim, hi_lim] minimising chord length + weight * offset."""
    q0 = edge_px[lo + i0]
    r0 = q0 // W
    ln0 = _chord(
        work,
        r0,
        q0 - r0 * W,
        _edge_normal(edge_px, lo, L, i0, W),
        2,
        max_angle,
        4.0 * dflat[q0] + 6.0,
        0.5,
    )[0]
    if ln0 <= 2.0 * dflat[q0] + 3.0:
        return i0  # the chord is as short as the inscribed circle allows: not at a mouth
    best = i0
    best_cost = 1e300
    k = int(3 + 0.5 * dflat[edge_px[lo + i0]])
    a = max(lo_lim, i0 - k)
    b = min(hi_lim, i0 + k)
    for i in range(a, b + 1):
        q = edge_px[lo + i]
        r = q // W
        c = q - r * W
        base = _edge_normal(edge_px, lo, L, i, W)
        ln = _chord(work, r, c, base, 2, max_angle, 4.0 * dflat[q] + 6.0, 0.5)[0]
        cost = ln + weight * abs(i - i0)
        if cost < best_cost - 1e-9:
            best_cost = cost
            best = i
    return best


@njit(cache=True, error_model="numpy")
def place_openings(
    W,
    n_nodes,
    node_rep,
    node_r,
    node_deg,
    ne,
    edge_a,
    edge_b,
    edge_off,
    edge_px,
    dcell,
    work,
    mouth_ratio,
    weight,
    min_path_px,
    max_angle,
):
    """Decide, per edge, whether it is inside an intersection core or where its openings lie.

    Returns ``(internal, open_a, open_b)``: ``open_a[e]`` is the index in the edge's pixel list
    of the opening next to junction ``a`` (-1 if none), ``open_b[e]`` likewise for ``b``.
    """
    dflat = dcell.ravel()
    internal = np.zeros(ne, np.bool_)
    open_a = np.full(ne, -1, np.int64)
    open_b = np.full(ne, -1, np.int64)
    for e in range(ne):
        a = edge_a[e]
        b = edge_b[e]
        lo = edge_off[e]
        L = edge_off[e + 1] - lo
        ja = node_deg[a] >= 3
        jb = node_deg[b] >= 3
        if L == 0:
            if ja or jb:
                internal[e] = True
            continue
        exit_a = L
        exit_b = -1
        if ja:
            ra = node_rep[a] // W
            ca = node_rep[a] - ra * W
            lim = mouth_ratio * node_r[a]
            for i in range(L):
                q = edge_px[lo + i]
                qr = q // W
                qc = q - qr * W
                if (qr - ra) ** 2 + (qc - ca) ** 2 >= lim * lim:
                    exit_a = i
                    break
        if jb:
            rb = node_rep[b] // W
            cb = node_rep[b] - rb * W
            lim = mouth_ratio * node_r[b]
            for i in range(L - 1, -1, -1):
                q = edge_px[lo + i]
                qr = q // W
                qc = q - qr * W
                if (qr - rb) ** 2 + (qc - cb) ** 2 >= lim * lim:
                    exit_b = i
                    break
        if ja and jb:
            if exit_b - exit_a < min_path_px:
                internal[e] = True
                continue
            mid = (exit_a + exit_b) // 2
            oa = _best_opening(edge_px, lo, exit_a, mid, 1, dflat, W, weight)
            ob = _best_opening(edge_px, lo, exit_b, mid + 1, -1, dflat, W, weight)
            if ob - oa < 2:
                if ob < exit_b:
                    ob += 1
                elif oa > exit_a:
                    oa -= 1
            if ob - oa < 2:
                internal[e] = True
                continue
            oa = _refine_opening(
                work, dflat, edge_px, lo, L, oa, exit_a, min(mid, ob - 2), W, max_angle, 0.25
            )
            ob = _refine_opening(
                work, dflat, edge_px, lo, L, ob, max(mid + 1, oa + 2), exit_b, W, max_angle, 0.25
            )
            open_a[e] = oa
            open_b[e] = ob
        elif ja:
            limit = L - 2
            if exit_a > limit:
                internal[e] = True
                continue
            oa = _best_opening(edge_px, lo, exit_a, limit, 1, dflat, W, weight)
            open_a[e] = _refine_opening(
                work, dflat, edge_px, lo, L, oa, exit_a, limit, W, max_angle, 0.25
            )
        elif jb:
            limit = 1
            if exit_b < limit:
                internal[e] = True
                continue
            ob = _best_opening(edge_px, lo, exit_b, limit, -1, dflat, W, weight)
            open_b[e] = _refine_opening(
                work, dflat, edge_px, lo, L, ob, limit, exit_b, W, max_angle, 0.25
            )
    return internal, open_a, open_b


@njit(cache=True, error_model="numpy")
def opening_chords(
    work, dcell, op_px, op_edge, op_idx, edge_off, edge_px, lab, n_angles, max_angle_rad
):
    """Shortest wall-to-wall chord through each opening pixel, roughly across its edge.

    Marks the chord's unlabelled free cells in ``lab`` with ``-(2 + opening index)`` (a barrier
    for region growing) and returns the endpoints ``(n, 4)`` as (row0, col0, row1, col1) in
    fractional cell units (cell centre at +0.5), the widths in cells and the marked cells.
    """
    H, W = work.shape
    n = op_px.size
    ends = np.empty((n, 4), np.float64)
    width = np.empty(n, np.float64)
    marked = np.empty(64 + 8 * n, np.int64)
    n_marked = 0
    step = 0.25
    for k in range(n):
        i = op_px[k]
        r = i // W
        c = i - r * W
        e = op_edge[k]
        lo = edge_off[e]
        L = edge_off[e + 1] - lo
        base = _edge_normal(edge_px, lo, L, op_idx[k], W)
        max_t = 4.0 * dcell[r, c] + 6.0
        pr = r + 0.5
        pc = c + 0.5
        best, bur, buc, bt1, bt2 = _chord(work, r, c, base, n_angles, max_angle_rad, max_t, step)
        e1 = min(bt1, max_t) - step * 0.5
        e2 = min(bt2, max_t) - step * 0.5
        ends[k, 0] = pr + e1 * bur
        ends[k, 1] = pc + e1 * buc
        ends[k, 2] = pr - e2 * bur
        ends[k, 3] = pc - e2 * buc
        width[k] = e1 + e2
        code = -(2 + k)
        t = -e2
        while t <= e1 + 1e-9:
            rr = int(np.floor(pr + t * bur))
            cc = int(np.floor(pc + t * buc))
            if rr >= 0 and cc >= 0 and rr < H and cc < W and work[rr, cc] == FREE:
                j = rr * W + cc
                if lab[j] == -1:
                    lab[j] = code
                    if n_marked >= marked.size:
                        grown = np.empty(marked.size * 2, np.int64)
                        grown[:n_marked] = marked[:n_marked]
                        marked = grown
                    marked[n_marked] = j
                    n_marked += 1
            t += step
    return ends, width, marked[:n_marked].copy()
