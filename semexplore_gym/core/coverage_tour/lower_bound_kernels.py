"""Numba kernels of :mod:`.lower_bound`: visibility regions of cell groups (one wall at a time)
and the Held-Karp route over groups with a skip budget (the K-hop distance field is in
:mod:`.khop_kernels`).

Grid cell ``(r, c)`` is the square ``[gx0 + c*res, gx0 + (c+1)*res] x [gy0 + r*res, ...]``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def unpack_frame(frame):  # pragma: no cover - numba
    """A visibility test's ``frame``: ``gx0, gy0, res, reach_m, widen_m, tol`` (floats), then
    the quartering depth and a last integer (the caller's: a stride, a wall cap)."""
    return frame[0], frame[1], frame[2], frame[3], frame[4], frame[5], int(frame[6]), int(frame[7])


@njit(cache=True, inline="always")
def box_corners(x0, y0, x1, y1, xs, ys):  # pragma: no cover - numba
    """The corners of the box ``x0, y0, x1, y1`` into ``xs, ys`` (counter-clockwise from
    ``x0, y0``), as the blocking tests take a rectangle."""
    xs[0] = x0
    xs[1] = x1
    xs[2] = x1
    xs[3] = x0
    ys[0] = y0
    ys[1] = y0
    ys[2] = y1
    ys[3] = y1


@njit(cache=True)
def wall_blocks(walls, q, ax, ay, ux, uy, tol, fa, fu):  # pragma: no cover - numba
    """Whether ``wall`` meets every segment between the rectangles with corners ``(ax, ay)``
    and ``(ux, uy)``: its line separates them strictly and all 16 corner-pair segments cross
    the line inside the wall (the union of the segments is the convex hull of the two)."""
    x0 = walls[q, 0]
    y0 = walls[q, 1]
    dx = walls[q, 2] - x0
    dy = walls[q, 3] - y0
    length = math.sqrt(dx * dx + dy * dy)
    if length <= 2.0 * tol:
        return False
    nx = -dy / length
    ny = dx / length
    for i in range(4):
        fa[i] = (ax[i] - x0) * nx + (ay[i] - y0) * ny
        fu[i] = (ux[i] - x0) * nx + (uy[i] - y0) * ny
    a_lo = min(min(fa[0], fa[1]), min(fa[2], fa[3]))
    a_hi = max(max(fa[0], fa[1]), max(fa[2], fa[3]))
    u_lo = min(min(fu[0], fu[1]), min(fu[2], fu[3]))
    u_hi = max(max(fu[0], fu[1]), max(fu[2], fu[3]))
    if not ((a_lo > tol and u_hi < -tol) or (a_hi < -tol and u_lo > tol)):
        return False
    for i in range(4):
        for j in range(4):
            t = fa[i] / (fa[i] - fu[j])
            px = ax[i] + t * (ux[j] - ax[i])
            py = ay[i] + t * (uy[j] - ay[i])
            s = ((px - x0) * dx + (py - y0) * dy) / length
            if s < tol or s > length - tol:
                return False
    return True


@njit(cache=True)
def _corner_reach(vx, vy, dx, dy, px, py):  # pragma: no cover - numba
    """How far along the ray from ``v`` in unit direction ``d`` the convex hull of the 8 points
    ``px, py`` reaches (its crossings of the ray's line, every pair of points on opposite sides;
    -inf when it does not meet the line)."""
    far = -np.inf
    for i in range(8):
        fi = (px[i] - vx) * -dy + (py[i] - vy) * dx
        if fi == 0.0:
            far = max(far, (px[i] - vx) * dx + (py[i] - vy) * dy)
            continue
        if fi < 0.0:
            continue
        for j in range(8):
            fj = (px[j] - vx) * -dy + (py[j] - vy) * dx
            if fj > 0.0:
                continue
            t = fi / (fi - fj)
            x = px[i] + t * (px[j] - px[i])
            y = py[i] + t * (py[j] - py[i])
            far = max(far, (x - vx) * dx + (y - vy) * dy)
    return far


@njit(cache=True)
def corner_blocks(corners, k, ax, ay, ux, uy, tol, px, py):  # pragma: no cover - numba
    """Whether corner ``k`` (two walls that meet at an end: ``vx, vy``, then each wall's unit
    direction from there and its length) meets every segment between the rectangles with
    corners ``(ax, ay)`` and ``(ux, uy)``: one lies inside the sector between the two walls (the
    one under half a turn) and the other beyond one of its two sides, each by more than
    ``tol``, so every segment leaves the sector across one of the two rays; and where the convex
    hull of both meets a ray it stays ``tol`` short of that wall's far end, so the crossing is on
    a wall or at the corner, where the env's ray cast counts a hit (a beam through the shared
    end has one wall's ends on either side). ``px, py``: 8 scratch floats."""
    vx = corners[k, 0]
    vy = corners[k, 1]
    adx = corners[k, 2]
    ady = corners[k, 3]
    bdx = corners[k, 5]
    bdy = corners[k, 6]
    turn = adx * bdy - ady * bdx
    if abs(turn) < 1e-9:
        return False
    sg = 1.0 if turn > 0.0 else -1.0
    a_in = True
    u_in = True
    a_out_a = True
    a_out_b = True
    u_out_a = True
    u_out_b = True
    for i in range(4):
        for side in range(2):
            x = ax[i] if side == 0 else ux[i]
            y = ay[i] if side == 0 else uy[i]
            fa = sg * (adx * (y - vy) - ady * (x - vx))
            fb = sg * ((x - vx) * bdy - (y - vy) * bdx)
            inside = fa > tol and fb > tol
            if side == 0:
                a_in = a_in and inside
                a_out_a = a_out_a and fa < -tol
                a_out_b = a_out_b and fb < -tol
            else:
                u_in = u_in and inside
                u_out_a = u_out_a and fa < -tol
                u_out_b = u_out_b and fb < -tol
            px[4 * side + i] = x
            py[4 * side + i] = y
    if not ((a_in and (u_out_a or u_out_b)) or (u_in and (a_out_a or a_out_b))):
        return False
    if _corner_reach(vx, vy, adx, ady, px, py) > corners[k, 4] - tol:
        return False
    return _corner_reach(vx, vy, bdx, bdy, px, py) <= corners[k, 7] - tol


@njit(cache=True)
def corners_near(corners, rect, pad):  # pragma: no cover - numba
    """The corners (rows of ``corners``) within ``pad`` of ``rect`` in each axis."""
    keep = np.zeros(corners.shape[0], dtype=np.bool_)
    for k in range(corners.shape[0]):
        keep[k] = (
            rect[0] - pad <= corners[k, 0] <= rect[2] + pad
            and rect[1] - pad <= corners[k, 1] <= rect[3] + pad
        )
    return corners[keep]


@njit(cache=True)
def _blocking_wall(walls, near, m, last, ax, ay, ux, uy, tol, fa, fu):  # pragma: no cover
    """Position in ``near[:m]`` of a wall that meets every segment between the two rectangles
    (tried first: ``last``), or -1 for none."""
    if m > 0 and wall_blocks(walls, near[last], ax, ay, ux, uy, tol, fa, fu):
        return last
    for p in range(m):
        if p != last and wall_blocks(walls, near[p], ax, ay, ux, uy, tol, fa, fu):
            return p
    return -1


@njit(cache=True)
def rect_blind(
    walls, near, m, last, rect, ux, uy, reach_m, depth, tol, work, corners
):  # pragma: no cover - numba
    """Whether every segment between ``rect`` and the square ``ux, uy`` (corners 0 and 2) no
    longer than ``reach_m`` meets a wall: one wall blocks all of them, the two are farther
    apart than ``reach_m``, one of ``corners`` blocks all of them (:func:`corner_blocks`), or
    (up to ``depth`` times) each quarter of ``rect`` is blind in turn (the segments from a
    rectangle are those from its quarters). Returns ``(blind, last)``."""
    ax = work[0]
    ay = work[1]
    fa = work[2]
    fu = work[3]
    px = np.empty(8)
    py = np.empty(8)
    stack = np.empty((4 * depth + 1, 5))
    stack[0, 0] = rect[0]
    stack[0, 1] = rect[1]
    stack[0, 2] = rect[2]
    stack[0, 3] = rect[3]
    stack[0, 4] = 0.0
    n = 1
    while n > 0:
        n -= 1
        x0 = stack[n, 0]
        y0 = stack[n, 1]
        x1 = stack[n, 2]
        y1 = stack[n, 3]
        d = int(stack[n, 4])
        gap_x = max(0.0, max(x0 - ux[2], ux[0] - x1))
        gap_y = max(0.0, max(y0 - uy[2], uy[0] - y1))
        if gap_x * gap_x + gap_y * gap_y > reach_m * reach_m:
            continue
        box_corners(x0, y0, x1, y1, ax, ay)
        p = _blocking_wall(walls, near, m, last, ax, ay, ux, uy, tol, fa, fu)
        if p >= 0:
            last = p
            continue
        cornered = False
        for k in range(corners.shape[0]):
            if corner_blocks(corners, k, ax, ay, ux, uy, tol, px, py):
                cornered = True
                break
        if cornered:
            continue
        if d >= depth:
            return False, last
        xm = 0.5 * (x0 + x1)
        ym = 0.5 * (y0 + y1)
        for q in range(4):
            stack[n, 0] = x0 if q % 2 == 0 else xm
            stack[n, 2] = xm if q % 2 == 0 else x1
            stack[n, 1] = y0 if q < 2 else ym
            stack[n, 3] = ym if q < 2 else y1
            stack[n, 4] = d + 1
            n += 1
    return True, last


@njit(cache=True)
def box_blind(
    walls, near, m, last, rect, box, reach_m, depth, tol, work, corners
):  # pragma: no cover - numba
    """:func:`rect_blind` for the square ``box`` (``x0, y0, x1, y1``); ``work``: 6 x 4 scratch
    (its last two rows take the box's corners). Returns ``(blind, last)``."""
    ux = work[4]
    uy = work[5]
    box_corners(box[0], box[1], box[2], box[3], ux, uy)
    return rect_blind(walls, near, m, last, rect, ux, uy, reach_m, depth, tol, work[:4], corners)


@njit(cache=True)
def cells_within(rect, pad, gx0, gy0, res, h, w):  # pragma: no cover - numba
    """Column and row ranges ``c_lo, c_hi, r_lo, r_hi`` of the ``res`` cells of an ``h`` x
    ``w`` grid (origin ``gx0, gy0``) that may lie within ``pad`` of ``rect`` (one cell spare)."""
    c_lo = max(0, int(math.floor((rect[0] - pad - gx0) / res)) - 1)
    c_hi = min(w - 1, int(math.floor((rect[2] + pad - gx0) / res)) + 1)
    r_lo = max(0, int(math.floor((rect[1] - pad - gy0) / res)) - 1)
    r_hi = min(h - 1, int(math.floor((rect[3] + pad - gy0) / res)) + 1)
    return c_lo, c_hi, r_lo, r_hi


@njit(cache=True)
def walls_near(walls, rect, pad):  # pragma: no cover - numba
    """Indices of the walls whose bounding box meets ``rect`` grown by ``pad``, and their
    count: ``(near, m)``, the first ``m`` entries of ``near``."""
    near = np.empty(walls.shape[0], dtype=np.int64)
    m = 0
    bx0 = rect[0] - pad
    bx1 = rect[2] + pad
    by0 = rect[1] - pad
    by1 = rect[3] + pad
    for q in range(walls.shape[0]):
        wx0 = min(walls[q, 0], walls[q, 2])
        wx1 = max(walls[q, 0], walls[q, 2])
        wy0 = min(walls[q, 1], walls[q, 3])
        wy1 = max(walls[q, 1], walls[q, 3])
        if wx1 >= bx0 and wx0 <= bx1 and wy1 >= by0 and wy0 <= by1:
            near[m] = q
            m += 1
    return near, m


@njit(cache=True, nogil=True)
def group_region(allowed, rect, walls, frame, corners):  # pragma: no cover - numba
    """Flat indices of the ``allowed`` cells not certainly blind to the rectangle ``rect``
    (``x0, y0, x1, y1``): the cell's square widened by ``widen_m`` is within ``reach_m`` of the
    rectangle and the walls (and ``corners``) do not meet every segment between the two
    (:func:`rect_blind`, quarters down to ``depth`` levels). ``frame``: ``gx0, gy0, res, reach_m, widen_m, tol, depth,
    stride``; a ``stride`` above 1 tests only every stride-th row and column (a sample, for
    ranking groups, never for the bound)."""
    gx0, gy0, res, reach_m, widen_m, tol, depth, stride = unpack_frame(frame)
    h, w = allowed.shape
    c_lo, c_hi, r_lo, r_hi = cells_within(rect, reach_m + widen_m, gx0, gy0, res, h, w)
    near, m = walls_near(walls, rect, reach_m + widen_m)
    close = corners_near(corners, rect, reach_m + widen_m)
    work = np.empty((6, 4))
    out = np.empty((r_hi - r_lo + 1) * (c_hi - c_lo + 1), dtype=np.int64)
    count = 0
    last = 0
    for r in range(r_lo, r_hi + 1, stride):
        y0 = gy0 + r * res - widen_m
        y1 = gy0 + (r + 1) * res + widen_m
        gap_y = max(0.0, max(rect[1] - y1, y0 - rect[3]))
        for c in range(c_lo, c_hi + 1, stride):
            if not allowed[r, c]:
                continue
            x0 = gx0 + c * res - widen_m
            x1 = gx0 + (c + 1) * res + widen_m
            gap_x = max(0.0, max(rect[0] - x1, x0 - rect[2]))
            if gap_x * gap_x + gap_y * gap_y > reach_m * reach_m:
                continue
            box = (x0, y0, x1, y1)
            blind, last = box_blind(
                walls, near, m, last, rect, box, reach_m, depth, tol, work, close
            )
            if not blind:
                out[count] = r * w + c
                count += 1
    return out[:count].copy()


def held_karp_route(first, legs, cells, budget):
    """Shortest route from the start through a subset S of the groups, over every S whose
    unvisited groups hold at most ``budget`` cells. ``first[i]``: start to group i; ``legs[i, j]``:
    group i to group j. Returns ``(length, order)`` (inf and an empty order if none is finite)."""
    return held_karp_entries(
        first, legs, np.arange(len(first)), cells, budget
    )  # each group entered at one place: its own node


@njit(cache=True)
def held_karp_entries(first, legs, group_of, cells, budget):  # pragma: no cover - numba
    """:func:`held_karp_route` over entry pieces: node ``v`` is where the route first enters
    the region of group ``group_of[v]``; ``first[v]``: start to node v; ``legs[v, w]``: node v to
    node w. A route visits one node of each group of a subset S, and S leaves at most ``budget``
    cells unvisited. Returns ``(length, group order)`` (inf and an empty order if none)."""
    m = cells.shape[0]
    nn = first.shape[0]
    full = 1 << m
    dp = np.full((full, max(nn, 1)), np.inf)
    parent = np.full((full, max(nn, 1)), -1, dtype=np.int64)
    held = np.zeros(full, dtype=np.int64)
    total = 0
    for i in range(m):
        total += cells[i]
    for v in range(nn):
        s = 1 << group_of[v]
        if first[v] < dp[s, v]:
            dp[s, v] = first[v]
    best = np.inf
    best_set = -1
    best_end = -1
    if total <= budget:
        best = 0.0
        best_set = 0
    for s in range(1, full):
        low = s & (-s)
        b = 0
        while (1 << b) != low:
            b += 1
        held[s] = held[s ^ low] + cells[b]
        ok = total - held[s] <= budget
        for v in range(nn):
            val = dp[s, v]
            if not ((s >> group_of[v]) & 1) or val == np.inf:
                continue
            if ok and val < best:
                best = val
                best_set = s
                best_end = v
            if val >= best:
                continue
            for u in range(nn):
                if (s >> group_of[u]) & 1:
                    continue
                t = s | (1 << group_of[u])
                nv = val + legs[v, u]
                if nv < dp[t, u]:
                    dp[t, u] = nv
                    parent[t, u] = v
    order = np.empty(m, dtype=np.int64)
    n = 0
    s = best_set
    e = best_end
    while e >= 0:
        order[n] = group_of[e]
        n += 1
        p = parent[s, e]
        s = s ^ (1 << group_of[e])
        e = p
    return best, order[:n][::-1].copy()
