"""Quick certain answers for :func:`.branch_kernels.coarse_region`'s visibility test.

That test keeps a block unless :func:`.lower_bound_kernels.box_blind` proves it blind to a
group's rectangle. Two shortcuts decide most blocks sooner, and neither changes the answer:

- **Umbras.** The blocks that one wall hides from the whole rectangle lie in that wall's umbra
  (beyond its line and inside the lines through its ends, shrunk by ``tol``, and each corner of
  the rectangle): a convex polygon. Each near wall's umbra is clipped to the search window and
  only the blocks inside its bounding box are tested against it (a few products per corner),
  so a block learns which wall to try instead of trying them all. The wall is then checked by
  the exact single-wall test that ``box_blind`` itself runs first, so a block is proven blind
  here only where ``box_blind`` would prove it.
- **Sight tables.** A segment within reach that meets no wall proves a block not blind (it is
  one of the segments every proof must block). For a point of the rectangle, a table of 1,024
  angular buckets holds a lower bound on the distance to any wall point in the bucket or its
  two neighbours; a block point nearer than that (less a margin) in its bucket sees the point
  along a clear segment. Walls within ``1 mm`` of the point bound every bucket; a wall whose
  line passes within ``1e-5 m`` of it zeroes the buckets along its direction (a segment along
  a wall's line counts as blocked by the exact test).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

SIGHT_BUCKETS = 1024
_NEAR_ALL_M = 1e-3  # a wall this close to the point bounds every bucket
_ON_LINE_M = 1e-5  # a wall's line this close to the point: its direction's buckets zeroed


@njit(cache=True)
def _clip(px, py, n, a, b, c, qx, qy):  # pragma: no cover - numba
    """The convex polygon ``px, py[:n]`` clipped to ``a x + b y + c >= 0``, written to
    ``qx, qy``; returns its vertex count."""
    k = 0
    for i in range(n):
        j = (i + 1) % n
        vi = a * px[i] + b * py[i] + c
        vj = a * px[j] + b * py[j] + c
        if vi >= 0.0:
            qx[k] = px[i]
            qy[k] = py[i]
            k += 1
        if (vi >= 0.0) != (vj >= 0.0):
            t = vi / (vi - vj)
            qx[k] = px[i] + t * (px[j] - px[i])
            qy[k] = py[i] + t * (py[j] - py[i])
            k += 1
    return k


@njit(cache=True)
def umbra_planes(walls, q, rect, tol, planes):  # pragma: no cover - numba
    """The 9 half-planes ``a x + b y + c > 0`` whose meet is wall ``q``'s umbra towards
    ``rect`` (``x0, y0, x1, y1``): beyond the wall's line by more than ``tol``, and for each
    wall end (``tol`` in from it) and rectangle corner, on the side of their line where the
    crossing lies inside the wall. Returns False (planes unset) when the wall is no longer than
    ``2 tol`` or its line does not leave the rectangle strictly on one side."""
    wx = walls[q, 0]
    wy = walls[q, 1]
    dx = walls[q, 2] - wx
    dy = walls[q, 3] - wy
    length = math.sqrt(dx * dx + dy * dy)
    if length <= 2.0 * tol:
        return False
    nx = -dy / length
    ny = dx / length
    lo = np.inf
    hi = -np.inf
    for i in range(4):
        cx = rect[0] if i == 0 or i == 3 else rect[2]
        cy = rect[1] if i < 2 else rect[3]
        f = (cx - wx) * nx + (cy - wy) * ny
        lo = min(lo, f)
        hi = max(hi, f)
    if lo > tol:
        sg = 1.0
    elif hi < -tol:
        sg = -1.0
    else:
        return False
    planes[0, 0] = -sg * nx
    planes[0, 1] = -sg * ny
    planes[0, 2] = sg * (nx * wx + ny * wy) - tol
    k = 1
    for e in range(2):
        s = tol if e == 0 else length - tol
        ex = wx + s * dx / length
        ey = wy + s * dy / length
        side = sg if e == 0 else -sg
        for i in range(4):
            cx = rect[0] if i == 0 or i == 3 else rect[2]
            cy = rect[1] if i < 2 else rect[3]
            vx = ex - cx
            vy = ey - cy
            planes[k, 0] = -side * vy
            planes[k, 1] = side * vx
            planes[k, 2] = side * (vy * cx - vx * cy)
            k += 1
    return True


@njit(cache=True)
def umbra_hints(walls, near, m, rect, tol, window, boxes, live, hint):  # pragma: no cover
    """For each live block (``boxes[i, j]``: ``x0, y0, x1, y1``) of the window (``x0, y0`` of
    its first block, the block side, rows, columns), the position in ``near[:m]`` of the first
    wall whose umbra towards ``rect`` holds all of the block's box (``hint``, -1 for none)."""
    planes = np.empty((9, 3))
    px = np.empty(16)
    py = np.empty(16)
    qx = np.empty(16)
    qy = np.empty(16)
    ox, oy, side = window[0], window[1], window[2]
    rows, cols = hint.shape
    for p in range(m):
        if not umbra_planes(walls, near[p], rect, tol, planes):
            continue
        px[0] = ox
        py[0] = oy
        px[1] = ox + cols * side
        py[1] = oy
        px[2] = ox + cols * side
        py[2] = oy + rows * side
        px[3] = ox
        py[3] = oy + rows * side
        n = 4
        for k in range(9):  # alternate buffers: the ninth clip leaves the polygon in qx, qy
            if k % 2 == 0:
                n = _clip(px, py, n, planes[k, 0], planes[k, 1], planes[k, 2], qx, qy)
            else:
                n = _clip(qx, qy, n, planes[k, 0], planes[k, 1], planes[k, 2], px, py)
            if n == 0:
                break
        if n == 0:
            continue
        x_lo = np.min(qx[:n])
        x_hi = np.max(qx[:n])
        y_lo = np.min(qy[:n])
        y_hi = np.max(qy[:n])
        # a box lies in its block widened a little: one block spare each side
        c_a = max(0, int(math.floor((x_lo - ox) / side)) - 1)
        c_b = min(cols - 1, int(math.floor((x_hi - ox) / side)) + 1)
        r_a = max(0, int(math.floor((y_lo - oy) / side)) - 1)
        r_b = min(rows - 1, int(math.floor((y_hi - oy) / side)) + 1)
        for i in range(r_a, r_b + 1):
            for j in range(c_a, c_b + 1):
                if not live[i, j] or hint[i, j] >= 0:
                    continue
                inside = True
                for k in range(9):
                    a = planes[k, 0]
                    b = planes[k, 1]
                    c = planes[k, 2]
                    if (
                        a * boxes[i, j, 0] + b * boxes[i, j, 1] + c <= 0.0
                        or a * boxes[i, j, 2] + b * boxes[i, j, 1] + c <= 0.0
                        or a * boxes[i, j, 2] + b * boxes[i, j, 3] + c <= 0.0
                        or a * boxes[i, j, 0] + b * boxes[i, j, 3] + c <= 0.0
                    ):
                        inside = False
                        break
                if inside:
                    hint[i, j] = p


@njit(cache=True)
def sight_table(walls, near, m, cx, cy, out):  # pragma: no cover - numba
    """``out[b]``: a lower bound on the distance from ``(cx, cy)`` to every point of the walls
    ``near[:m]`` whose direction lies in angular bucket ``b - 1``, ``b`` or ``b + 1`` (bucket
    ``b``: angles ``[b, b + 1) * 2 pi / out.size``, modulo ``2 pi``)."""
    nb = out.size
    two_pi = 2.0 * math.pi
    step = two_pi / nb
    d = np.full(nb, np.inf)
    for p in range(m):
        q = near[p]
        x0 = walls[q, 0]
        y0 = walls[q, 1]
        dx = walls[q, 2] - x0
        dy = walls[q, 3] - y0
        l2 = dx * dx + dy * dy
        if l2 <= 0.0:
            continue
        t = ((cx - x0) * dx + (cy - y0) * dy) / l2
        tc = min(1.0, max(0.0, t))
        gap = math.sqrt((x0 + tc * dx - cx) ** 2 + (y0 + tc * dy - cy) ** 2)
        if gap < _NEAR_ALL_M:
            for b in range(nb):
                d[b] = min(d[b], gap)
            continue
        fx = x0 + t * dx - cx
        fy = y0 + t * dy - cy
        h = math.sqrt(fx * fx + fy * fy)
        if h <= _ON_LINE_M:  # every point of the wall lies along its line's two directions
            for a in (math.atan2(dy, dx), math.atan2(-dy, -dx)):
                b0 = int(math.floor(a / step))
                for b in range(b0 - 2, b0 + 3):
                    d[b % nb] = 0.0
            continue
        # angles relative to the foot of the perpendicular, where the distance is h / cos
        foot = math.atan2(fy, fx)
        p1 = (math.atan2(y0 - cy, x0 - cx) - foot + math.pi) % two_pi - math.pi
        p2 = (math.atan2(y0 + dy - cy, x0 + dx - cx) - foot + math.pi) % two_pi - math.pi
        if p1 > p2:
            p1, p2 = p2, p1
        for b in range(
            int(math.floor((foot + p1) / step)), int(math.floor((foot + p2) / step)) + 1
        ):
            lo = max(b * step - foot, p1)
            hi = min((b + 1) * step - foot, p2)
            if lo > hi:  # rounding at a bucket's edge: the nearer end
                lo = hi = p1 if abs(p1 - (b * step - foot)) < abs(p2 - (b * step - foot)) else p2
            v = h if lo <= 0.0 <= hi else h / math.cos(lo if lo > 0.0 else hi)
            d[b % nb] = min(d[b % nb], v)
    for b in range(nb):
        out[b] = min(d[b], min(d[(b - 1) % nb], d[(b + 1) % nb]))


@njit(cache=True)
def sees_clearly(table, cx, cy, px, py, reach_m, margin):  # pragma: no cover - numba
    """Whether the segment from ``(cx, cy)`` (the table's point) to ``(px, py)`` is within
    ``reach_m`` and nearer than every wall point around its direction, less ``margin``."""
    d2 = (px - cx) ** 2 + (py - cy) ** 2
    if d2 > reach_m * reach_m:
        return False
    step = 2.0 * math.pi / table.size
    b = int(math.floor(math.atan2(py - cy, px - cx) / step)) % table.size
    return math.sqrt(d2) + margin < table[b]
