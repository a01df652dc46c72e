"""Numba kernels of :mod:`.lower_bound`: the K-hop distance field, visibility regions of cell
groups (one wall at a time), and the Held-Karp route over groups with a skip budget.

Grid cell ``(r, c)`` is the square ``[gx0 + c*res, gx0 + (c+1)*res] x [gy0 + r*res, ...]``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def _heap_push(keys, vals, n, key, val):  # pragma: no cover - numba
    if n == keys.shape[0]:
        bigger_k = np.empty(2 * n, dtype=np.float64)
        bigger_v = np.empty(2 * n, dtype=np.int64)
        bigger_k[:n] = keys[:n]
        bigger_v[:n] = vals[:n]
        keys = bigger_k
        vals = bigger_v
    i = n
    keys[i] = key
    vals[i] = val
    while i > 0:
        p = (i - 1) // 2
        if keys[p] <= keys[i]:
            break
        keys[p], keys[i] = keys[i], keys[p]
        vals[p], vals[i] = vals[i], vals[p]
        i = p
    return keys, vals, n + 1


@njit(cache=True)
def _heap_pop(keys, vals, n):  # pragma: no cover - numba
    key = keys[0]
    val = vals[0]
    n -= 1
    keys[0] = keys[n]
    vals[0] = vals[n]
    i = 0
    while True:
        a = 2 * i + 1
        if a >= n:
            break
        b = a + 1
        m = a if (b >= n or keys[a] <= keys[b]) else b
        if keys[i] <= keys[m]:
            break
        keys[m], keys[i] = keys[i], keys[m]
        vals[m], vals[i] = vals[i], vals[m]
        i = m
    return key, val, n


@njit(cache=True)
def _interval_gap(lo, hi, t0, t1):  # pragma: no cover - numba
    """Gap between the intervals ``[lo, hi]`` and ``[t0, t1]`` (0 when they meet)."""
    if t0 > hi:
        return t0 - hi
    if t1 < lo:
        return lo - t1
    return 0.0


@njit(cache=True)
def _face_costs(k, res):  # pragma: no cover - numba
    """``cost[f, i * side + j]``: the distance from face ``f`` of a cell's square (0: the whole
    square; 1, 2: its low and high row side; 3, 4: its low and high column side) to the square
    of the cell at offset ``(i - k, j - k)``."""
    side = 2 * k + 1
    cost = np.empty((5, side * side), dtype=np.float64)
    for f in range(5):
        r0, r1, c0, c1 = -0.5, 0.5, -0.5, 0.5
        if f == 1:
            r1 = -0.5
        elif f == 2:
            r0 = 0.5
        elif f == 3:
            c1 = -0.5
        elif f == 4:
            c0 = 0.5
        for i in range(side):
            for j in range(side):
                dr = _interval_gap(r0, r1, i - k - 0.5, i - k + 0.5)
                dc = _interval_gap(c0, c1, j - k - 0.5, j - k + 0.5)
                cost[f, i * side + j] = res * math.sqrt(dr * dr + dc * dc)
    return cost


@njit(cache=True, nogil=True)
def khop_distances(
    moves, sources, k, res, target_of, n_targets, limit=np.inf, depth_step=0.0
):  # pragma: no cover - numba
    """K-hop lower-bound distances from ``sources`` (flat cell indices) over the cells' moves.

    ``moves[r, c]``: bit ``3 * (dr + 1) + (dc + 1)`` set when the robot can pass from cell
    ``(r, c)`` to ``(r + dr, c + dc)`` (bit 4: the cell itself is allowed). A checkpoint is a
    cell and the face of its square the path is on: a source anywhere in its square, a later
    checkpoint on the side toward the one before (a path first reaches Chebyshev distance
    ``k`` from a checkpoint by crossing that side; a ring corner at its inner corner, which
    lies on its row side too). A settled checkpoint ``a`` reaches, by a breadth-first search
    along moves inside its Chebyshev ball of radius ``k`` that expands only cells strictly
    inside the ball, every cell ``b`` a path can reach before first leaving the ball's
    interior; the edge costs the distance from ``a``'s face to ``b``'s square (a straight
    chain of hops thus measures ``k`` cells a hop), or ``(D - 1) * depth_step`` where that is
    more, ``D`` the number of moves the search took from ``a`` to ``b`` (``depth_step``: the
    least distance between two map cells whose cells share no move; 0: not used). A path
    that first enters a cell of depth ``m`` does so from one of depth ``m - 1``, and a cell
    of depth ``m - 1`` and one of depth ``m + 1`` share no move, so the path drives at least
    ``depth_step`` between its first entries at depths ``m`` and ``m + 1``: round a corner
    the breadth-first depth grows while the straight gap cuts through the wall. Cells on the
    ball's rim are the next
    checkpoints (heap); every reached cell also records ``d(a) + cost`` as a last hop. A face
    is not pushed when another face of the same cell is known at least one cell size lower
    (its distances are never above this one's).

    With ``n_targets`` > 0 it stops once each target set (``target_of[cell]``, -1 for none)
    holds its final least distance: every later value is at least the popped one. It also stops
    once the popped value reaches ``limit`` and returns ``limit`` wherever its value is larger
    (every value not yet final is at least the popped one): a lower bound still.

    Returns:
        ``moves.shape`` float64 distances (inf where unreached, or not needed for the targets).
    """
    h, w = moves.shape
    flat_moves = moves.reshape(h * w)
    side = 2 * k + 1
    cost = _face_costs(k, res)
    chain = np.full(h * w * 5, np.inf)
    best = np.full(h * w, np.inf)
    settled = np.zeros(h * w * 5, dtype=np.bool_)
    keys = np.empty(1024, dtype=np.float64)
    vals = np.empty(1024, dtype=np.int64)
    n = 0
    for s in sources:
        if (flat_moves[s] >> 4) & 1 and chain[5 * s] > 0.0:
            chain[5 * s] = 0.0
            best[s] = 0.0
            keys, vals, n = _heap_push(keys, vals, n, 0.0, 5 * s)
    stamp = np.zeros(side * side, dtype=np.int64)
    queue = np.empty(side * side, dtype=np.int64)
    depth = np.zeros(side * side, dtype=np.int64)
    sid = 0
    flat_target = target_of.reshape(h * w)
    tbest = np.full(max(n_targets, 1), np.inf)
    for s in sources:
        if flat_target[s] >= 0 and best[s] < tbest[flat_target[s]]:
            tbest[flat_target[s]] = best[s]
    while n > 0:
        d, state, n = _heap_pop(keys, vals, n)
        if settled[state] or d > chain[state]:
            continue
        if n_targets > 0 and d >= tbest.max():
            break
        if d >= limit:
            break
        settled[state] = True
        a = state // 5
        face = state - 5 * a
        ar = a // w
        ac = a - ar * w
        sid += 1
        centre = k * side + k
        stamp[centre] = sid
        queue[0] = centre
        depth[centre] = 0
        head = 0
        tail = 1
        while head < tail:
            loc = queue[head]
            head += 1
            li = loc // side
            lj = loc - li * side
            g = (ar + li - k) * w + (ac + lj - k)
            e = d + max(cost[face, loc], (depth[loc] - 1) * depth_step)
            if e < best[g]:
                best[g] = e
                t = flat_target[g]
                if t >= 0 and e < tbest[t]:
                    tbest[t] = e
            if abs(li - k) == k or abs(lj - k) == k:
                if abs(li - k) == k:
                    nf = 1 if li > k else 2
                else:
                    nf = 3 if lj > k else 4
                low = chain[5 * g]
                for f2 in range(1, 5):
                    if f2 != nf and chain[5 * g + f2] + res < low:
                        low = chain[5 * g + f2] + res
                if e < chain[5 * g + nf] and e < low and not settled[5 * g + nf]:
                    chain[5 * g + nf] = e
                    keys, vals, n = _heap_push(keys, vals, n, e, 5 * g + nf)
                continue
            bits = flat_moves[g]
            for di in range(-1, 2):
                for dj in range(-1, 2):
                    if not (bits >> (3 * (di + 1) + dj + 1)) & 1 or (di == 0 and dj == 0):
                        continue
                    ni = li + di
                    nj = lj + dj
                    gr = ar + ni - k
                    gc = ac + nj - k
                    if gr < 0 or gc < 0 or gr >= h or gc >= w:
                        continue
                    nl = ni * side + nj
                    if stamp[nl] == sid:
                        continue
                    stamp[nl] = sid
                    queue[tail] = nl
                    depth[nl] = depth[loc] + 1
                    tail += 1
    if limit < np.inf:
        for i in range(h * w):
            if best[i] > limit:
                best[i] = limit
    return best.reshape(h, w)


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
