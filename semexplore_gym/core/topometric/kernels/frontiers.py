"""Stage 7 of the segmentation, frontiers: clusters of free cells next to unknown space.

:func:`frontier_cells` clusters the labelled free cells with an unknown 4-neighbour;
:func:`frontier_groups` splits the clusters by region, keeps those wide enough and with enough
unknown space behind them (:func:`unknown_depth_ok`), and gives each a target cell in the
configuration space (:func:`anchor_of`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN


@njit(cache=True, error_model="numpy")
def _bsearch(a, x):
    lo = 0
    hi = a.size
    while lo < hi:
        mid = (lo + hi) >> 1
        if a[mid] < x:
            lo = mid + 1
        else:
            hi = mid
    if lo < a.size and a[lo] == x:
        return lo
    return -1


@njit(cache=True, error_model="numpy")
def frontier_cells(W, work, lab, cand):
    """Labelled free cells with an UNKNOWN 4-neighbour, clustered 8-connectedly.

    ``cand`` (sorted) are candidates from the filter pass; they are re-checked here.
    Returns (sorted frontier cells, cluster id per cell, outward row/col offset sums, n clusters).
    """
    wf = work.ravel()
    n = 0
    fc = np.empty(cand.size, np.int64)
    for t in range(cand.size):
        i = cand[t]
        if (
            lab[i] >= 0
            and wf[i] == FREE
            and (
                wf[i + W] == UNKNOWN
                or wf[i - W] == UNKNOWN
                or wf[i + 1] == UNKNOWN
                or wf[i - 1] == UNKNOWN
            )
        ):
            fc[n] = i
            n += 1
    fc = fc[:n]
    orow = np.zeros(n, np.int64)
    ocol = np.zeros(n, np.int64)
    for k in range(n):
        i = fc[k]
        if wf[i + W] == UNKNOWN:
            orow[k] += 1
        if wf[i - W] == UNKNOWN:
            orow[k] -= 1
        if wf[i + 1] == UNKNOWN:
            ocol[k] += 1
        if wf[i - 1] == UNKNOWN:
            ocol[k] -= 1
    cluster = np.full(n, -1, np.int64)
    stack = np.empty(n + 1, np.int64)
    n_cl = 0
    for k in range(n):
        if cluster[k] >= 0:
            continue
        cluster[k] = n_cl
        top = 0
        stack[top] = k
        top += 1
        while top > 0:
            top -= 1
            m = stack[top]
            i = fc[m]
            for dr in range(-1, 2):
                for dc in range(-1, 2):
                    mm = _bsearch(fc, i + dr * W + dc)
                    if mm >= 0 and cluster[mm] < 0:
                        cluster[mm] = n_cl
                        stack[top] = mm
                        top += 1
        n_cl += 1
    return fc, cluster, orow, ocol, n_cl


@njit(cache=True, error_model="numpy")
def _group_width(fc, sel, W):
    """Extent (cells) of frontier cells ``fc[sel]`` along their principal axis, and its data."""
    m = sel.size
    mr = 0.0
    mc = 0.0
    for t in range(m):
        i = fc[sel[t]]
        mr += i // W
        mc += i % W
    mr /= m
    mc /= m
    srr = 0.0
    scc = 0.0
    src = 0.0
    for t in range(m):
        i = fc[sel[t]]
        dr = i // W - mr
        dc = i % W - mc
        srr += dr * dr
        scc += dc * dc
        src += dr * dc
    theta = 0.5 * np.arctan2(2.0 * src, scc - srr)
    ct = np.cos(theta)
    sn = np.sin(theta)
    proj = np.empty(m, np.float64)
    t0 = 0
    t1 = 0
    for t in range(m):
        i = fc[sel[t]]
        proj[t] = (i % W - mc) * ct + (i // W - mr) * sn
        if proj[t] < proj[t0]:
            t0 = t
        if proj[t] > proj[t1]:
            t1 = t
    return proj[t1] - proj[t0] + 1.0, t0, t1, mr, mc, proj


@njit(cache=True, error_model="numpy")
def frontier_groups(
    W, work, lab, st, sk, dcell, min_clear, fc, cluster, orow, ocol, n_cl, min_w, depth_cells, n_reg
):
    """Frontiers from clustered frontier cells: split by area when each part is wide enough.

    A cluster seen from several areas is split into its per-area parts when every kept part is
    at least ``min_w`` cells wide; if no part is, the whole cluster goes to the area holding
    most of it. A group is a frontier when it is ``min_w`` wide, a C-space target is reachable
    from one of its cells nearest its centroid, and ``depth_cells`` of unknown space lie behind it.

    Returns per frontier: region, width (cells), end cells (r0, c0, r1, c1), middle cell, target.
    """
    n = fc.size
    key = cluster * (n_reg + 1) + lab[fc]
    order = np.argsort(key, kind="mergesort")
    out_reg = np.empty(n + 1, np.int64)
    out_w = np.empty(n + 1, np.float64)
    out_end = np.empty((n + 1, 4), np.float64)
    out_mid = np.empty(n + 1, np.int64)
    out_anchor = np.empty(n + 1, np.int64)
    n_out = 0
    start = 0
    while start < n:
        k = cluster[order[start]]
        stop = start
        while stop < n and cluster[order[stop]] == k:
            stop += 1
        # parts by region inside [start, stop)
        part_lo = np.empty(stop - start + 1, np.int64)
        part_hi = np.empty(stop - start + 1, np.int64)
        n_part = 0
        t = start
        while t < stop:
            g = lab[fc[order[t]]]
            u = t
            while u < stop and lab[fc[order[u]]] == g:
                u += 1
            part_lo[n_part] = t
            part_hi[n_part] = u
            n_part += 1
            t = u
        groups_lo = np.empty(n_part, np.int64)
        groups_hi = np.empty(n_part, np.int64)
        groups_reg = np.empty(n_part, np.int64)
        n_g = 0
        if n_part == 1:
            groups_lo[0] = start
            groups_hi[0] = stop
            groups_reg[0] = lab[fc[order[start]]]
            n_g = 1
        else:
            biggest = 0
            for pp in range(n_part):
                if part_hi[pp] - part_lo[pp] > part_hi[biggest] - part_lo[biggest]:
                    biggest = pp
                wdt = _group_width(fc, order[part_lo[pp] : part_hi[pp]], W)[0]
                if wdt + 1e-9 >= min_w:
                    groups_lo[n_g] = part_lo[pp]
                    groups_hi[n_g] = part_hi[pp]
                    groups_reg[n_g] = lab[fc[order[part_lo[pp]]]]
                    n_g += 1
            if n_g == 0:
                groups_lo[0] = start
                groups_hi[0] = stop
                groups_reg[0] = lab[fc[order[part_lo[biggest]]]]
                n_g = 1
        for gg in range(n_g):
            sel = order[groups_lo[gg] : groups_hi[gg]]
            region = groups_reg[gg]
            wdt, t0, t1, mr, mc, proj = _group_width(fc, sel, W)
            if wdt + 1e-9 < min_w:
                continue
            m = sel.size
            dist = np.empty(m, np.float64)
            for t in range(m):
                i = fc[sel[t]]
                dist[t] = (i // W - mr) ** 2 + (i % W - mc) ** 2
            by_centre = np.argsort(dist)
            anchor = -1
            mid = -1
            for t in range(min(m, 32)):
                cell = fc[sel[by_centre[t]]]
                a = anchor_of(st, sk, dcell, min_clear, cell, 64)
                if a >= 0 and lab[a] == region:
                    anchor = a
                    mid = cell
                    break
            if anchor < 0:
                continue
            vr = 0.0
            vc = 0.0
            for t in range(m):
                vr += orow[sel[t]]
                vc += ocol[sel[t]]
            nrm = np.sqrt(vr * vr + vc * vc)
            if nrm == 0.0:
                vr = float(mid // W - anchor // W)
                vc = float(mid % W - anchor % W)
                nrm = np.sqrt(vr * vr + vc * vc)
            if nrm > 0.0:
                ur = vr / nrm
                uc = vc / nrm
                sp = np.sort(proj)
                ok = False
                for qq in range(3):
                    if qq == 0:
                        cell = mid
                    else:
                        target = sp[(m * qq) // 4] if qq == 1 else sp[(3 * m) // 4]
                        bt = 0
                        for t in range(m):
                            if abs(proj[t] - target) < abs(proj[bt] - target):
                                bt = t
                        cell = fc[sel[bt]]
                    if unknown_depth_ok(work, cell // W, cell % W, ur, uc, depth_cells):
                        ok = True
                        break
                if not ok:
                    continue
            e0 = fc[sel[t0]]
            e1 = fc[sel[t1]]
            out_reg[n_out] = region
            out_w[n_out] = wdt
            out_end[n_out, 0] = e0 // W
            out_end[n_out, 1] = e0 % W
            out_end[n_out, 2] = e1 // W
            out_end[n_out, 3] = e1 % W
            out_mid[n_out] = mid
            out_anchor[n_out] = anchor
            n_out += 1
        start = stop
    return (
        out_reg[:n_out].copy(),
        out_w[:n_out].copy(),
        out_end[:n_out].copy(),
        out_mid[:n_out].copy(),
        out_anchor[:n_out].copy(),
    )


@njit(cache=True, error_model="numpy")
def unknown_depth_ok(work, r, c, ur, uc, depth_cells):
    """True if marching from cell (r, c) along (ur, uc) crosses ``depth_cells`` of unknown space."""
    H, W = work.shape
    t = 0.5
    seen_unknown = 0.0
    while t <= depth_cells + 1.5:
        rr = int(np.floor(r + 0.5 + t * ur))
        cc = int(np.floor(c + 0.5 + t * uc))
        if rr < 0 or cc < 0 or rr >= H or cc >= W:
            return True
        v = work[rr, cc]
        if v == OCCUPIED:
            return False
        if v == UNKNOWN:
            seen_unknown = t
            if seen_unknown >= depth_cells:
                return True
        elif seen_unknown > 0.0:
            return False
        t += 0.5
    return seen_unknown >= depth_cells


@njit(cache=True, error_model="numpy")
def anchor_of(st, sk, dcell, min_clear, cell, max_len):
    """First C-space cell on the parent chain of ``cell`` (-1 if the chain breaks first)."""
    sk_flat = sk.ravel()
    d_flat = dcell.ravel()
    i = cell
    for _ in range(max_len):
        if d_flat[i] >= min_clear or sk_flat[i]:
            return i
        p = st[i]
        if p < 0:
            return -1
        i = p
    return -1
