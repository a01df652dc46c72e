"""Stages 8 and 9 of the segmentation: area types and the topometric graph.

These kernels run after the grid kernels and work on small per-region and per-opening arrays:
area types from the opening counts (:func:`area_types`, stage 8), path requests
(:func:`plan_paths`), graph edges, the frontiers' nearest intersections and the lengths behind
``L_path`` (:func:`graph_summary`), and world coordinates (:func:`world_coordinates`). Python
then only builds the output records.

Indices are *provisional*: regions ``0..n_reg-1``, then one zero-area frontier pathway per
frontier that lies on an intersection's wall (``n_reg..n_prov-1``). Openings are the chords
``0..n_op-1``, then per frontier (in frontier order) a twin opening (the mouth of its zero-area
frontier pathway, only for frontiers on an intersection) and the frontier opening itself.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from semexplore_gym.core.topometric.kernels.paths import far_skeleton_pixels
from semexplore_gym.core.topometric.types import AreaType

# compile-time constants for the kernels
INTER = int(AreaType.INTERSECTION)
PATH = int(AreaType.PATHWAY)
DEAD = int(AreaType.DEAD_END)
FRONT = int(AreaType.FRONTIER_PATHWAY)


@njit(cache=True, error_model="numpy")
def area_types(n_reg, op_core, op_far, f_reg):
    """GRID-FAST's rule with frontiers counting as openings: >= 3 intersection, 2 pathway
    (frontier pathway with a frontier), 1 dead end (frontier pathway when it is a frontier)."""
    n_regular = np.zeros(n_reg, np.int64)
    n_front = np.zeros(n_reg, np.int64)
    for k in range(op_core.size):
        n_regular[op_core[k]] += 1
        n_regular[op_far[k]] += 1
    for f in range(f_reg.size):
        n_front[f_reg[f]] += 1
    rtype = np.full(n_reg, DEAD, np.int64)
    for g in range(n_reg):
        total = n_regular[g] + n_front[g]
        if total >= 3:
            rtype[g] = INTER
        elif total == 2:
            rtype[g] = FRONT if n_front[g] >= 1 else PATH
        elif total == 1 and n_front[g] == 1:
            rtype[g] = FRONT
    return rtype


@njit(cache=True, error_model="numpy")
def opening_sides(op_edge, op_idx, open_a, eoff, epx, ea, eb, rep):
    """Skeleton pixels on either side of each opening pixel: ``(side_core, side_far)``.

    The core side is the previous pixel of the edge when the opening is at its ``a`` end (the
    end node's representative when the opening is the edge's first pixel), the next one at its
    ``b`` end; the far side is the other neighbour along the edge.
    """
    n = op_edge.size
    side_core = np.empty(n, np.int64)
    side_far = np.empty(n, np.int64)
    last = epx.size - 1
    for k in range(n):
        e = op_edge[k]
        idx = op_idx[k]
        pos = eoff[e] + idx
        prev_px = epx[max(pos - 1, 0)]
        next_px = epx[min(pos + 1, last)]
        if open_a[e] == idx:
            side_core[k] = prev_px if idx >= 1 else rep[ea[e]]
            side_far[k] = next_px
        else:
            side_core[k] = next_px if pos + 1 < eoff[e + 1] else rep[eb[e]]
            side_far[k] = prev_px
    return side_core, side_far


@njit(cache=True, error_model="numpy")
def world_coordinates(
    vcells,
    op_anchor,
    centres,
    zf_fo,
    f_mid,
    fidx,
    ends,
    f_ends,
    widths,
    f_width,
    W,
    r0,
    c0,
    origin_x,
    origin_y,
    res,
):
    """World coordinates (metres) of everything the records need, in one pass.

    Cells are converted at their centres, fractional (row, col) points as they are:
    ``x = origin_x + (col + c0) * res``, ``y = origin_y + (row + r0) * res``.

    Returns ``(vxy, anchor_xy, centre_xy, ends_xy, mids, widths_m)``: the path vertices, the
    openings' anchors, the provisional areas' centres (regions, then zero-area frontier
    pathways at their frontier's anchor), the openings' endpoints ``(n, 2, 2)``, midpoints and
    widths (chords, then frontier openings).
    """
    n_op = ends.shape[0]
    n_fe = fidx.size
    n_all = n_op + n_fe
    vxy = np.empty((vcells.size, 2))
    for k in range(vcells.size):
        _cell_xy(vxy, k, vcells[k], W, r0, c0, origin_x, origin_y, res)
    anchor_xy = np.empty((op_anchor.size, 2))
    for k in range(op_anchor.size):
        _cell_xy(anchor_xy, k, op_anchor[k], W, r0, c0, origin_x, origin_y, res)
    n_reg = centres.size
    centre_xy = np.empty((n_reg + zf_fo.size, 2))
    for k in range(n_reg):
        _cell_xy(centre_xy, k, centres[k], W, r0, c0, origin_x, origin_y, res)
    for k in range(zf_fo.size):
        _cell_xy(centre_xy, n_reg + k, op_anchor[zf_fo[k]], W, r0, c0, origin_x, origin_y, res)
    ends_xy = np.empty((n_all, 2, 2))
    mids = np.empty((n_all, 2))
    widths_m = np.empty(n_all)
    for k in range(n_op):
        for s in range(2):
            ends_xy[k, s, 0] = origin_x + (ends[k, 2 * s + 1] + c0) * res
            ends_xy[k, s, 1] = origin_y + (ends[k, 2 * s] + r0) * res
        mids[k, 0] = (ends_xy[k, 0, 0] + ends_xy[k, 1, 0]) * 0.5
        mids[k, 1] = (ends_xy[k, 0, 1] + ends_xy[k, 1, 1]) * 0.5
        widths_m[k] = widths[k] * res
    for t in range(n_fe):
        k = n_op + t
        f = fidx[t]
        for s in range(2):
            ends_xy[k, s, 0] = origin_x + ((f_ends[f, 2 * s + 1] + 0.5) + c0) * res
            ends_xy[k, s, 1] = origin_y + ((f_ends[f, 2 * s] + 0.5) + r0) * res
        _cell_xy(mids, k, f_mid[f], W, r0, c0, origin_x, origin_y, res)
        widths_m[k] = f_width[f] * res
    return vxy, anchor_xy, centre_xy, ends_xy, mids, widths_m


@njit(cache=True, error_model="numpy", inline="always")
def _cell_xy(out, k, cell, W, r0, c0, origin_x, origin_y, res):
    r = cell // W
    c = cell - r * W
    out[k, 0] = origin_x + ((c + 0.5) + c0) * res
    out[k, 1] = origin_y + ((r + 0.5) + r0) * res


@njit(cache=True, error_model="numpy", inline="always")
def _request(req, n, area, op, s, e, pre, post):
    req[0, n] = area
    req[1, n] = op
    req[2, n] = s
    req[3, n] = e
    req[4, n] = pre
    req[5, n] = post


@njit(cache=True, error_model="numpy")
def plan_paths(
    rtype, op_core, op_far, f_reg, centres, side_core, side_far, op_px, f_anchor, W, sk, px, st, lab
):
    """Openings, the openings of every area, and one path request per (area, opening).

    Requests, in this order: per region (by index) its legs (opening -> centre for
    intersections, opening -> opening both ways for pathways and frontier pathways), then the
    legs from the only opening of dead ends and of one-frontier areas to the skeleton pixel
    farthest from it. A request runs from ``s`` to ``e`` with ``pre`` / ``post`` cells (>= 0)
    added before / after.

    Returns ``(op_a0, op_a1, op_front, op_anchor, aoff, aops, zf_twin, zf_fo, req)``:
    per opening its areas (``op_a1 == -1`` for frontier openings), its frontier index (-1 for
    chords) and anchor cell; the openings of area ``a`` are ``aops[aoff[a]:aoff[a + 1]]`` (its
    chords and twins in id order, then its frontier openings); the twin and frontier openings of
    the zero-area frontier pathways;
    and ``req`` (6, n): rows area, opening, s, e, pre, post.
    """
    n_reg = rtype.size
    n_op = op_core.size
    n_f = f_reg.size
    n_zf = 0
    for f in range(n_f):
        if rtype[f_reg[f]] == INTER:
            n_zf += 1
    n_all = n_op + n_f + n_zf
    n_prov = n_reg + n_zf
    op_a0 = np.empty(n_all, np.int64)
    op_a1 = np.empty(n_all, np.int64)
    op_front = np.full(n_all, -1, np.int64)
    op_anchor = np.empty(n_all, np.int64)
    zf_host = np.empty(n_zf, np.int64)
    zf_twin = np.empty(n_zf, np.int64)
    zf_fo = np.empty(n_zf, np.int64)
    n_ops = np.zeros(n_prov, np.int64)  # chords and twins per area
    n_frs = np.zeros(n_prov, np.int64)  # frontier openings per area
    for k in range(n_op):
        op_a0[k] = op_core[k]
        op_a1[k] = op_far[k]
        op_anchor[k] = op_px[k]
        n_ops[op_core[k]] += 1
        n_ops[op_far[k]] += 1
    nxt = n_op
    z = 0
    for f in range(n_f):
        g = f_reg[f]
        if rtype[g] == INTER:
            za = n_reg + z
            op_a0[nxt] = g
            op_a1[nxt] = za
            op_a0[nxt + 1] = za
            op_a1[nxt + 1] = -1
            op_front[nxt] = f
            op_front[nxt + 1] = f
            op_anchor[nxt] = f_anchor[f]
            op_anchor[nxt + 1] = f_anchor[f]
            n_ops[g] += 1
            n_ops[za] += 2
            zf_host[z] = g
            zf_twin[z] = nxt
            zf_fo[z] = nxt + 1
            z += 1
            nxt += 2
        else:
            op_a0[nxt] = g
            op_a1[nxt] = -1
            op_front[nxt] = f
            op_anchor[nxt] = f_anchor[f]
            n_frs[g] += 1
            nxt += 1
    aoff = np.zeros(n_prov + 1, np.int64)
    for a in range(n_prov):
        aoff[a + 1] = aoff[a] + n_ops[a] + n_frs[a]
    aops = np.empty(aoff[n_prov], np.int64)
    cur = aoff[:n_prov].copy()
    for k in range(n_op):
        aops[cur[op_core[k]]] = k
        cur[op_core[k]] += 1
        aops[cur[op_far[k]]] = k
        cur[op_far[k]] += 1
    for z in range(n_zf):
        g = zf_host[z]
        aops[cur[g]] = zf_twin[z]
        cur[g] += 1
        za = n_reg + z
        aops[cur[za]] = zf_twin[z]
        aops[cur[za] + 1] = zf_fo[z]
        cur[za] += 2
    for k in range(n_op, n_all):
        if op_a1[k] == -1 and op_a0[k] < n_reg:
            g = op_a0[k]
            aops[cur[g]] = k
            cur[g] += 1

    req = np.empty((6, 2 * aoff[n_prov] + 2 * n_reg + 2), np.int64)
    n = 0
    far_area = np.empty(n_reg, np.int64)
    far_op = np.empty(n_reg, np.int64)
    far_start = np.empty(n_reg, np.int64)
    n_far = 0
    for g in range(n_reg):
        t = rtype[g]
        lo = aoff[g]
        no = n_ops[g]
        if t == INTER:
            root = centres[g]
            for q in range(lo, lo + no):
                k = aops[q]
                if k < n_op:
                    s = side_core[k] if op_core[k] == g else side_far[k]
                    pre = op_px[k]
                else:
                    s = op_anchor[k]
                    pre = -1
                _request(req, n, g, k, s, root, pre, -1)
                n += 1
        elif t == PATH:
            k1 = aops[lo]
            k2 = aops[lo + 1]
            s1 = side_core[k1] if op_core[k1] == g else side_far[k1]
            s2 = side_core[k2] if op_core[k2] == g else side_far[k2]
            _request(req, n, g, k1, s1, s2, op_px[k1], op_px[k2])
            _request(req, n + 1, g, k2, s2, s1, op_px[k2], op_px[k1])
            n += 2
        elif t == FRONT:
            if no > 0:
                k = aops[lo]
                fo = aops[lo + no]
                s1 = side_core[k] if op_core[k] == g else side_far[k]
                _request(req, n, g, k, s1, op_anchor[fo], op_px[k], -1)
                _request(req, n + 1, g, fo, op_anchor[fo], s1, -1, op_px[k])
                n += 2
            elif n_frs[g] == 2:
                fo1 = aops[lo]
                fo2 = aops[lo + 1]
                _request(req, n, g, fo1, op_anchor[fo1], op_anchor[fo2], -1, -1)
                _request(req, n + 1, g, fo2, op_anchor[fo2], op_anchor[fo1], -1, -1)
                n += 2
            else:
                fo = aops[lo]
                far_area[n_far] = g
                far_op[n_far] = fo
                far_start[n_far] = op_anchor[fo]
                n_far += 1
        elif no > 0:
            k = aops[lo]
            far_area[n_far] = g
            far_op[n_far] = k
            far_start[n_far] = side_core[k] if op_core[k] == g else side_far[k]
            n_far += 1
    if n_far:
        far = far_skeleton_pixels(W, sk, px, st, lab, far_start[:n_far])
        for q in range(n_far):
            k = far_op[q]
            _request(req, n, far_area[q], k, far_start[q], far[q], op_px[k] if k < n_op else -1, -1)
            n += 1
    return op_a0, op_a1, op_front, op_anchor, aoff, aops, zf_twin, zf_fo, req[:, :n].copy()


@njit(cache=True, error_model="numpy")
def graph_summary(ptype, aoff, aops, op_a0, op_a1, req, vlen, zf_twin, zf_fo, n_reg):
    """Edges, the frontiers' nearest intersections and the intersection-to-intersection lengths.

    Returns:
        ``(edges2, pairs, plen, fronts, fronts_len, lpath)``. ``edges2`` (n, 4): opening a,
        opening b, area, request (-1 for zero-area pathways) of every non-intersection area
        with two openings, in area order; ``pairs``
        (5, n): request a, request b, opening a, opening b, area for every pair of an
        intersection's legs (areas in order, pairs as ``itertools.combinations``) and ``plen``
        their lengths; ``fronts`` (n, 3) area, frontier opening, nearest intersection (-1 if
        none) with ``fronts_len`` (p_l); ``lpath``: the lengths that ``L_path`` averages.
    """
    n_prov = ptype.size
    n_all = op_a0.size
    n_req = req.shape[1]
    area_lens = np.full((n_all, 2), np.nan)
    req_of = np.full((n_all, 2), -1, np.int64)
    for j in range(n_req):
        a = req[0, j]
        k = req[1, j]
        s = 0 if op_a0[k] == a else 1
        area_lens[k, s] = vlen[j]
        req_of[k, s] = j
    for z in range(zf_twin.size):
        area_lens[zf_twin[z], 1] = 0.0
        area_lens[zf_fo[z], 0] = 0.0

    # graph edges and the links of the chains through non-intersection areas
    n_pairs = 0
    for a in range(n_prov):
        if ptype[a] == INTER:
            m = aoff[a + 1] - aoff[a]
            n_pairs += m * (m - 1) // 2
    pairs = np.empty((5, n_pairs), np.int64)
    plen = np.empty(n_pairs, np.float64)
    edges2 = np.empty((n_prov, 4), np.int64)
    link = np.full((n_all, 2), -1, np.int64)
    link_w = np.zeros((n_all, 2), np.float64)
    ne = 0
    npair = 0
    for a in range(n_prov):
        lo = aoff[a]
        hi = aoff[a + 1]
        if ptype[a] == INTER:
            for x in range(lo, hi):
                kx = aops[x]
                jx = req_of[kx, 0 if op_a0[kx] == a else 1]
                for y in range(x + 1, hi):
                    ky = aops[y]
                    jy = req_of[ky, 0 if op_a0[ky] == a else 1]
                    pairs[0, npair] = jx
                    pairs[1, npair] = jy
                    pairs[2, npair] = kx
                    pairs[3, npair] = ky
                    pairs[4, npair] = a
                    plen[npair] = vlen[jx] + vlen[jy]
                    npair += 1
        elif hi - lo == 2:
            o1 = aops[lo]
            o2 = aops[lo + 1]
            s1 = 0 if op_a0[o1] == a else 1
            if a < n_reg and req_of[o1, s1] < 0:
                continue
            edges2[ne, 0] = o1
            edges2[ne, 1] = o2
            edges2[ne, 2] = a
            edges2[ne, 3] = req_of[o1, s1] if a < n_reg else -1
            ne += 1
            if o1 != o2:
                w = area_lens[o1, s1]
                for o, other in ((o1, o2), (o2, o1)):
                    slot = 0 if link[o, 0] < 0 else 1
                    link[o, slot] = other
                    link_w[o, slot] = w

    # frontiers: walk the chain from the frontier opening to the first intersection opening
    # (at most two links per opening, one for a frontier opening: the shortest path is the walk)
    n_items = 0
    for a in range(n_prov):
        for q in range(aoff[a], aoff[a + 1]):
            if op_a1[aops[q]] == -1:
                n_items += 1
    fronts = np.empty((n_items, 3), np.int64)
    fronts_len = np.empty(n_items, np.float64)
    seen = np.full(n_all, -1, np.int64)
    t = 0
    for a in range(n_prov):  # regions, then zero-area frontier pathways, as in the output
        for q in range(aoff[a], aoff[a + 1]):
            fo = aops[q]
            if op_a1[fo] != -1:
                continue
            u = fo
            came = -1
            d = 0.0
            found = -1
            seen[fo] = t
            while True:
                if ptype[op_a0[u]] == INTER:
                    found = op_a0[u]
                    break
                if op_a1[u] >= 0 and ptype[op_a1[u]] == INTER:
                    found = op_a1[u]
                    break
                nxt = -1
                w = 0.0
                for slot in range(2):
                    v = link[u, slot]
                    if v >= 0 and v != came and seen[v] != t:
                        nxt = v
                        w = link_w[u, slot]
                        break
                if nxt < 0:
                    break
                came = u
                u = nxt
                d += w
                seen[u] = t
            fronts[t, 0] = a
            fronts[t, 1] = fo
            fronts[t, 2] = found
            if found >= 0:
                fronts_len[t] = d
            else:
                own = area_lens[fo, 0]
                fronts_len[t] = 0.0 if np.isnan(own) else own
            t += 1

    # L_path: intersection - pathway - intersection (areas in order), then openings shared by
    # two intersections (openings in order)
    lpath = np.empty(n_prov + n_all, np.float64)
    nl = 0
    for a in range(n_prov):
        if ptype[a] != PATH or aoff[a + 1] - aoff[a] != 2:
            continue
        o1 = aops[aoff[a]]
        o2 = aops[aoff[a] + 1]
        s1 = 0 if op_a0[o1] == a else 1
        s2 = 0 if op_a0[o2] == a else 1
        i1 = op_a1[o1] if s1 == 0 else op_a0[o1]
        i2 = op_a1[o2] if s2 == 0 else op_a0[o2]
        if i1 < 0 or i1 == a or ptype[i1] != INTER or i2 < 0 or i2 == a or ptype[i2] != INTER:
            continue
        lpath[nl] = area_lens[o1, 1 - s1] + area_lens[o1, s1] + area_lens[o2, 1 - s2]
        nl += 1
    for k in range(n_all):
        a0 = op_a0[k]
        a1 = op_a1[k]
        if a1 >= 0 and a0 != a1 and ptype[a0] == INTER and ptype[a1] == INTER:
            lpath[nl] = area_lens[k, 0] + area_lens[k, 1]
            nl += 1
    return (
        edges2[:ne].copy(),
        pairs,
        plen,
        fronts,
        fronts_len,
        lpath[:nl].copy(),
    )
