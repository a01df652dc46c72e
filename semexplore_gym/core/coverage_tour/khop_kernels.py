"""The certified bound's K-hop distance field (:mod:`.lower_bound`, step 2): the moves between
blocks of allowed cells, the search from a set of sources over them (numba), and the
breadth-first balls that many searches on one grid can share.
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
def _ball(flat_moves, h, w, a, k, stamp, queue, depth, sid):  # pragma: no cover - numba
    """Breadth-first search from cell ``a`` along moves inside its Chebyshev ball of radius
    ``k``, expanding only cells strictly inside it: fills ``queue`` (ball offsets ``i * side +
    j``, cell ``(ar + i - k, ac + j - k)``) and ``depth`` (moves from ``a``) in the order
    reached, and returns how many (``stamp`` marks them with ``sid``)."""
    side = 2 * k + 1
    ar = a // w
    ac = a - ar * w
    centre = k * side + k
    stamp[centre] = sid
    queue[0] = centre
    depth[0] = 0
    head = 0
    tail = 1
    while head < tail:
        loc = queue[head]
        dl = depth[head]
        head += 1
        li = loc // side
        lj = loc - li * side
        if abs(li - k) == k or abs(lj - k) == k:
            continue
        bits = flat_moves[(ar + li - k) * w + (ac + lj - k)]
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
                depth[tail] = dl + 1
                tail += 1
    return tail


@njit(cache=True)
def khop_balls(moves, k):  # pragma: no cover - numba
    """Every allowed cell's breadth-first ball (:func:`_ball`) for :func:`khop_distances`:
    ``(start, offset, depth)``, cell ``a``'s entries ``start[a]:start[a + 1]`` in the order
    reached (int16: ``k`` <= 64)."""
    h, w = moves.shape
    flat_moves = moves.reshape(h * w)
    side = 2 * k + 1
    stamp = np.zeros(side * side, dtype=np.int64)
    queue = np.empty(side * side, dtype=np.int64)
    depth = np.zeros(side * side, dtype=np.int64)
    start = np.zeros(h * w + 1, dtype=np.int64)
    cap = 1024
    offset = np.empty(cap, dtype=np.int16)
    moves_to = np.empty(cap, dtype=np.int16)
    n = 0
    sid = 0
    for a in range(h * w):
        start[a] = n
        if not (flat_moves[a] >> 4) & 1:
            continue
        sid += 1
        size = _ball(flat_moves, h, w, a, k, stamp, queue, depth, sid)
        while n + size > cap:
            cap *= 2
            grown = np.empty(cap, dtype=np.int16)
            grown[:n] = offset[:n]
            offset = grown
            grown = np.empty(cap, dtype=np.int16)
            grown[:n] = moves_to[:n]
            moves_to = grown
        for q in range(size):
            offset[n + q] = queue[q]
            moves_to[n + q] = depth[q]
        n += size
    start[h * w] = n
    return start, offset[:n].copy(), moves_to[:n].copy()


@njit(cache=True, nogil=True)
def khop_distances(
    moves, sources, k, res, target_of, n_targets, limit=np.inf, depth_step=0.0, balls=None
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

    ``balls``: :func:`khop_balls` of ``moves`` and ``k`` (the searches' breadth-first balls,
    computed once for many searches; None: each search computes them). The same distances,
    bit for bit.

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
        # The cached ball's loop repeats the search's own below, written out: numba does not
        # inline a helper for it (a helper for the rim cells cost 15-25 % of the cached search).
        if balls is not None:
            for q in range(balls[0][a], balls[0][a + 1]):
                loc = np.int64(balls[1][q])
                li = loc // side
                lj = loc - li * side
                g = (ar + li - k) * w + (ac + lj - k)
                e = d + max(cost[face, loc], (np.int64(balls[2][q]) - 1) * depth_step)
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


def coarse_moves(allowed: np.ndarray, factor: int) -> np.ndarray:
    """The moves between ``factor`` x ``factor`` blocks of ``allowed`` (uint16 bit masks, see
    :func:`khop_distances`): block A passes to its neighbour B when an
    allowed cell of A is 8-adjacent to one of B (bit 4: A holds an allowed cell). A path's
    blocks thus step along moves, and blocks never join across a wall the cells do not."""
    f = int(factor)
    h, w = allowed.shape
    hc, wc = -(-h // f), -(-w // f)
    out = np.zeros(hc * wc, dtype=np.uint16)  # 9 bits: the move by (+1, +1) is bit 8
    rows, cols = np.nonzero(allowed)
    own = (rows // f) * wc + cols // f
    np.bitwise_or.at(out, own, np.uint16(1 << 4))
    for dr in (-1, 0, 1):
        for dc in (-1, 0, 1):
            r2, c2 = rows + dr, cols + dc
            ok = (r2 >= 0) & (r2 < h) & (c2 >= 0) & (c2 < w)
            ok[ok] &= allowed[r2[ok], c2[ok]]
            br, bc = rows[ok] // f, cols[ok] // f
            sr, sc = r2[ok] // f - br, c2[ok] // f - bc
            step = (sr != 0) | (sc != 0)
            bit = (3 * (sr[step] + 1) + sc[step] + 1).astype(np.uint16)
            np.bitwise_or.at(out, br[step] * wc + bc[step], np.left_shift(np.uint16(1), bit))
    return out.reshape(hc, wc)
