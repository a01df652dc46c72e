"""Stage 9 of the segmentation, paths: cell paths along the region trees, simplified.

:func:`tree_paths` follows the regions' shortest-path trees (skeleton and configuration space)
between the requested cells; :func:`smooth_paths` simplifies them (Douglas-Peucker) keeping every
segment inside the area's ``C``; :func:`join_legs` joins two legs at an intersection's centre
into one graph-edge path. :func:`far_skeleton_pixels` finds a dead end's far end.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, error_model="numpy")
def far_skeleton_pixels(W, sk, px, st, lab, starts):
    """For each start cell, the skeleton pixel of its region farthest from it (BFS steps).

    A start that is not a skeleton pixel is first followed down its parent chain.
    """
    sk_flat = sk.ravel()
    n_px = px.size
    stamp = np.full(n_px, -1, np.int32)
    q = np.empty(n_px + 1, np.int32)
    out = np.empty(starts.size, np.int64)
    for s in range(starts.size):
        i = starts[s]
        guard = 0
        while not sk_flat[i] and guard < 1000000:
            i = st[i]
            guard += 1
            if i < 0:
                break
        if i < 0:
            out[s] = starts[s]
            continue
        g = lab[i]
        k0 = st[i]
        head = 0
        tail = 0
        q[tail] = k0
        tail += 1
        stamp[k0] = s
        far = i
        while head < tail:
            k = q[head]
            head += 1
            c = px[k]
            far = c
            for dr in range(-1, 2):
                for dc in range(-1, 2):
                    j = c + dr * W + dc
                    if sk_flat[j] and lab[j] == g:
                        kj = st[j]
                        if stamp[kj] != s:
                            stamp[kj] = s
                            q[tail] = kj
                            tail += 1
        out[s] = far
    return out


@njit(cache=True, error_model="numpy")
def _down_to_skeleton(st, sk_flat, cell, buf):
    """Cells from ``cell`` along parents down to its skeleton pixel (inclusive) into ``buf``."""
    n = 0
    i = cell
    while i >= 0:
        if n >= buf.size:
            return -1
        buf[n] = i
        n += 1
        if sk_flat[i]:
            return n
        i = st[i]
    return -1


@njit(cache=True, error_model="numpy")
def tree_paths(sk, px, st, sk_par, sk_dep, starts, ends, pre, post):
    """Path from ``starts[k]`` to ``ends[k]`` through their region's tree.

    Each end climbs its parent chain to the skeleton; the two skeleton pixels are joined through
    their lowest common ancestor in the skeleton tree. ``pre[k]`` / ``post[k]`` (>= 0) are cells
    prepended / appended. Returns flat cells and offsets.
    """
    sk_flat = sk.ravel()
    n = starts.size
    off = np.zeros(n + 1, np.int64)
    cap = 1024
    out = np.empty(cap, np.int64)
    bufa = np.empty(4096, np.int64)
    bufb = np.empty(4096, np.int64)
    tmp = np.empty(1024, np.int64)
    p = 0
    for k in range(n):
        na = _down_to_skeleton(st, sk_flat, starts[k], bufa)
        nb = _down_to_skeleton(st, sk_flat, ends[k], bufb)
        # worst case length of this path
        if na < 0 or nb < 0:
            need = 4
        else:
            ka = st[bufa[na - 1]]
            kb = st[bufb[nb - 1]]
            need = na + nb + sk_dep[ka] + sk_dep[kb] + 4
        if p + need > cap:
            while p + need > cap:
                cap *= 2
            grown = np.empty(cap, np.int64)
            grown[:p] = out[:p]
            out = grown
        if pre[k] >= 0:
            out[p] = pre[k]
            p += 1
        if na < 0 or nb < 0:
            out[p] = starts[k]
            p += 1
            out[p] = ends[k]
            p += 1
        else:
            for t in range(na - 1):
                out[p] = bufa[t]
                p += 1
            a = ka
            b = kb
            da = sk_dep[a]
            db = sk_dep[b]
            while da > db:
                out[p] = px[a]
                p += 1
                a = sk_par[a]
                da -= 1
            m = 0
            if tmp.size < db + 2:
                tmp = np.empty(2 * db + 4, np.int64)
            while db > da:
                tmp[m] = px[b]
                m += 1
                b = sk_par[b]
                db -= 1
            while a != b and a >= 0 and b >= 0:
                out[p] = px[a]
                p += 1
                if tmp.size < m + 2:
                    grown = np.empty(2 * tmp.size, np.int64)
                    grown[:m] = tmp[:m]
                    tmp = grown
                tmp[m] = px[b]
                m += 1
                a = sk_par[a]
                b = sk_par[b]
            if a == b and a >= 0:
                out[p] = px[a]
                p += 1
            for t in range(m - 1, -1, -1):
                out[p] = tmp[t]
                p += 1
            for t in range(nb - 2, -1, -1):
                out[p] = bufb[t]
                p += 1
        if post[k] >= 0:
            out[p] = post[k]
            p += 1
        off[k + 1] = p
    return out[:p].copy(), off


@njit(cache=True, error_model="numpy")
def _line_ok(W, r0, c0, r1, c1, d_flat, min_clear, lab, region, first, last):
    dr = r1 - r0
    dc = c1 - c0
    n = max(abs(dr), abs(dc)) * 2
    if n == 0:
        return True
    for s in range(n + 1):
        rr = int(np.floor(r0 + 0.5 + dr * s / n))
        cc = int(np.floor(c0 + 0.5 + dc * s / n))
        i = rr * W + cc
        if i == first or i == last:
            continue
        if d_flat[i] < min_clear or lab[i] != region:
            return False
    return True


@njit(cache=True, error_model="numpy")
def smooth_paths(W, cells, off, regions, dcell, min_clear, lab, tol_cells, res_m):
    """Simplify each tree path (Douglas-Peucker, ``tol_cells``) keeping every segment in C-space.

    A segment that would leave the path's region or the configuration space is split at its
    farthest point, whatever the tolerance. Returns vertex cells (flat), offsets and lengths in
    metres; a path of one cell is doubled.
    """
    d_flat = dcell.ravel()
    n = off.size - 1
    out = np.empty(cells.size + 2 * n, np.int64)
    ooff = np.zeros(n + 1, np.int64)
    lengths = np.zeros(n, np.float64)
    keep = np.zeros(cells.size, np.uint8)
    stack = np.empty(2 * cells.size + 2, np.int64)
    p = 0
    tol2 = tol_cells * tol_cells
    for k in range(n):
        lo = off[k]
        hi = off[k + 1]
        m = hi - lo
        if m == 0:
            ooff[k + 1] = p
            continue
        if m == 1:
            out[p] = cells[lo]
            out[p + 1] = cells[lo]
            p += 2
            ooff[k + 1] = p
            continue
        g = regions[k]
        first = cells[lo]
        last = cells[hi - 1]
        keep[lo] = 1
        keep[hi - 1] = 1
        top = 0
        stack[top] = lo
        stack[top + 1] = hi - 1
        top += 2
        while top > 0:
            top -= 2
            i0 = stack[top]
            i1 = stack[top + 1]
            if i1 - i0 < 2:
                continue
            a = cells[i0]
            b = cells[i1]
            ar = a // W
            ac = a - ar * W
            br = b // W
            bc = b - br * W
            dr = float(br - ar)
            dc = float(bc - ac)
            den = dr * dr + dc * dc
            worst = -1.0
            wi = i0 + 1
            for i in range(i0 + 1, i1):
                q = cells[i]
                qr = q // W
                qc = q - qr * W
                if den > 0:
                    cr = (qr - ar) * dc - (qc - ac) * dr
                    dist2 = cr * cr / den
                else:
                    dist2 = float((qr - ar) ** 2 + (qc - ac) ** 2)
                if dist2 > worst:
                    worst = dist2
                    wi = i
            if worst > tol2 or not _line_ok(
                W, ar, ac, br, bc, d_flat, min_clear, lab, g, first, last
            ):
                keep[wi] = 1
                stack[top] = i0
                stack[top + 1] = wi
                stack[top + 2] = wi
                stack[top + 3] = i1
                top += 4
        length = 0.0
        prev = -1
        for i in range(lo, hi):
            if keep[i]:
                keep[i] = 0
                c = cells[i]
                if prev >= 0:
                    pr = prev // W
                    pc = prev - pr * W
                    cr = c // W
                    length += np.sqrt((cr - pr) ** 2 + (c - cr * W - pc) ** 2)
                out[p] = c
                p += 1
                prev = c
        lengths[k] = length * res_m
        ooff[k + 1] = p
    return out[:p].copy(), ooff, lengths


@njit(cache=True, error_model="numpy")
def join_legs(xy, off, legs_a, legs_b):
    """Concatenate leg ``a`` with the reverse of leg ``b`` (minus its last point) per pair.

    Legs are slices ``xy[off[i]:off[i + 1]]`` ending at a shared point (an intersection centre).
    Returns flat points and offsets.
    """
    n = legs_a.size
    total = 0
    for k in range(n):
        a = legs_a[k]
        b = legs_b[k]
        total += (off[a + 1] - off[a]) + (off[b + 1] - off[b]) - 1
    out = np.empty((max(total, 0), 2), np.float64)
    ooff = np.zeros(n + 1, np.int64)
    p = 0
    for k in range(n):
        a = legs_a[k]
        b = legs_b[k]
        for i in range(off[a], off[a + 1]):
            out[p, 0] = xy[i, 0]
            out[p, 1] = xy[i, 1]
            p += 1
        for i in range(off[b + 1] - 2, off[b] - 1, -1):
            out[p, 0] = xy[i, 0]
            out[p, 1] = xy[i, 1]
            p += 1
        ooff[k + 1] = p
    return out, ooff
