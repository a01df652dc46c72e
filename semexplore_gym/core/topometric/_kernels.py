"""Numba kernels of the topometric segmentation (single-threaded, ``cache=True``).

All kernels work on a *work grid*: a crop of the input grid whose free cells are at least two
cells away from its edge, so neighbour look-ups of free cells never leave the array. Cells are
addressed by flat index ``i = row * W + col``. Distances are in cells.
"""

from __future__ import annotations

import numpy as np
from numba import njit

FREE_V = 255
UNKNOWN_V = 128
OCCUPIED_V = 0


# ----------------------------------------------------------------------------------------------
# Noise filter: small blobs of one value
# ----------------------------------------------------------------------------------------------


@njit(cache=True, error_model="numpy")
def scan_grid(enc: np.ndarray) -> tuple[int, int, int, int, int]:
    """One pass: index of the first value outside the encoding (-1 if none) and the free bbox.

    Returns ``(bad_flat_index, rmin, rmax, cmin, cmax)``; ``rmin == -1`` when there is no free cell.
    """
    H, W = enc.shape
    rmin = -1
    rmax = -1
    cmin = W
    cmax = -1
    for r in range(H):
        row = enc[r]
        n_bad = 0
        n_free = 0
        for c in range(W):  # branch-free counts: numba vectorises them (3x faster than if/elif)
            v = row[c]
            n_free += v == FREE_V
            n_bad += (v != FREE_V) & (v != UNKNOWN_V) & (v != OCCUPIED_V)
        if n_bad:
            for c in range(W):
                v = row[c]
                if v != FREE_V and v != UNKNOWN_V and v != OCCUPIED_V:
                    return r * W + c, -1, -1, -1, -1
        if n_free:
            if rmin < 0:
                rmin = r
            rmax = r
            c = 0
            while row[c] != FREE_V:
                c += 1
            cmin = min(cmin, c)
            c = W - 1
            while row[c] != FREE_V:
                c -= 1
            cmax = max(cmax, c)
    return -1, rmin, rmax, cmin, cmax


@njit(cache=True, error_model="numpy")
def _flood_blob(work, state, stack, blob, start, value, max_cells):
    """Collect the 8-connected blob of ``value`` at ``start``; returns its size or -1 if too big."""
    H, W = work.shape
    n_blob = 0
    top = 0
    stack[top] = start
    top += 1
    state[start] = 2
    big = False
    while top > 0:
        top -= 1
        j = stack[top]
        if n_blob >= max_cells:
            big = True
            state[j] = 1
            break
        blob[n_blob] = j
        n_blob += 1
        jr = j // W
        jc = j - jr * W
        if jr == 0 or jc == 0 or jr == H - 1 or jc == W - 1:
            big = True
            break
        for dr in range(-1, 2):
            for dc in range(-1, 2):
                k = j + dr * W + dc
                if state[k] == 0 and work[jr + dr, jc + dc] == value:
                    state[k] = 2
                    stack[top] = k
                    top += 1
    if big:
        # every cell reached belongs to the same big blob: never start from them again
        for t in range(n_blob):
            state[blob[t]] = 1
        for t in range(top):
            state[stack[t]] = 1
        return -1
    return n_blob


@njit(cache=True, error_model="numpy")
def _try_blob(work, state, stack, blob, j, max_speck_cells, max_hole_cells) -> int:
    """Examine the blob at non-free cell ``j`` (next to free space); rewrite it if it is small."""
    H, W = work.shape
    wf = work.ravel()
    v = wf[j]
    limit = max_speck_cells if v == OCCUPIED_V else max_hole_cells
    if limit <= 0:
        state[j] = 1
        return 0
    n_blob = _flood_blob(work, state, stack, blob, j, v, limit)
    if n_blob < 0:
        return 0
    all_free = True
    for t in range(n_blob):
        q = blob[t]
        qr = q // W
        qc = q - qr * W
        for er in range(-1, 2):
            for ec in range(-1, 2):
                if state[q + er * W + ec] != 2 and work[qr + er, qc + ec] != FREE_V:
                    all_free = False
    new_v = -1
    if all_free:
        new_v = FREE_V
    elif v == UNKNOWN_V:
        new_v = OCCUPIED_V
    changed = 0
    for t in range(n_blob):
        q = blob[t]
        state[q] = 1
        if new_v >= 0:
            wf[q] = new_v
            changed += 1
    return changed


@njit(cache=True, error_model="numpy")
def filter_small_blobs(
    work: np.ndarray, max_speck_cells: int, max_hole_cells: int, state: np.ndarray
) -> tuple[int, np.ndarray]:
    """Erase occupied specks and close unknown holes next to free cells, in place.

    An 8-connected OCCUPIED blob of at most ``max_speck_cells`` not touching the array edge whose
    neighbours are all FREE becomes FREE. An UNKNOWN blob of at most ``max_hole_cells`` not
    touching the edge becomes FREE when its neighbours are all FREE, OCCUPIED otherwise. Blobs
    are found from their cells that are 4-adjacent to a free cell.

    ``state`` is uint8 scratch of ``H * W`` zeros.

    Returns the number of cells changed and the free cells that had an UNKNOWN 4-neighbour
    before filtering (frontier candidates, to be re-checked).
    """
    H, W = work.shape
    # state: 1 = big/edge blob or handled, 2 = current blob
    mx = max(max_speck_cells, max_hole_cells, 1)
    stack = np.empty(8 * (mx + 2), np.int64)
    blob = np.empty(mx + 1, np.int64)
    changed = 0
    wf = work.ravel()
    flag = np.empty(W, np.uint8)
    fcand = np.empty(1024, np.int64)
    n_f = 0
    for r in range(1, H - 1):
        base = r * W
        # stage 1 (branch-free; on row slices numba vectorises it, ~10x faster than flat
        # indexing): where does free-ness change to the right or above?
        row = wf[base : base + W]
        above = wf[base + W : base + 2 * W]
        for c in range(W - 1):
            xf = row[c] == FREE_V
            flag[c] = (xf ^ (row[c + 1] == FREE_V)) | (xf ^ (above[c] == FREE_V))
        for c in range(1, W - 1):
            if not flag[c]:
                continue
            i = base + c
            x = wf[i]
            xf = x == FREE_V
            for t in range(3):
                if t == 0:
                    if xf:
                        continue
                    j = i
                    nb = wf[i + 1] if wf[i + 1] == FREE_V else wf[i + W]
                elif t == 1:
                    if xf == (wf[i + 1] == FREE_V):
                        continue
                    j = i + 1 if xf else i
                    nb = wf[i + 1]
                else:
                    if xf == (wf[i + W] == FREE_V):
                        continue
                    j = i + W if xf else i
                    nb = wf[i + W]
                # frontier candidate: the free cell of a free/unknown pair
                if t > 0 and (x == UNKNOWN_V or nb == UNKNOWN_V):
                    fc = i if xf else (i + 1 if t == 1 else i + W)
                    if n_f >= fcand.size:
                        grown = np.empty(2 * fcand.size, np.int64)
                        grown[:n_f] = fcand[:n_f]
                        fcand = grown
                    fcand[n_f] = fc
                    n_f += 1
                if t > 0 and not xf:
                    continue  # the non-free cell of this pair is i itself, handled by t == 0
                if state[j] != 0:
                    continue
                if wf[j] == OCCUPIED_V:
                    if max_speck_cells <= 0:
                        continue
                    # a speck of at most k cells leaves each of its cells >= 9 - k free neighbours
                    nf = 0
                    for dr in range(-1, 2):
                        for dc in range(-1, 2):
                            if wf[j + dr * W + dc] == FREE_V:
                                nf += 1
                    if nf < 9 - max_speck_cells:
                        state[j] = 1  # then no blob through j is small enough
                        continue
                elif max_hole_cells <= 0:
                    continue
                changed += _try_blob(work, state, stack, blob, j, max_speck_cells, max_hole_cells)
    return changed, np.unique(fcand[:n_f])


# ----------------------------------------------------------------------------------------------
# Euclidean distance transform (Felzenszwalb & Huttenlocher), outside the array counts as blocked
# ----------------------------------------------------------------------------------------------


@njit(cache=True, error_model="numpy")
def _fh_run(grow, a, b, f, v, z, crow, min_clear_cells, base, clist, n_c):
    """Lower envelope of parabolas over the free run [a, b) of one row (blocked at a-1 and b).

    Reads the column distances of the run from ``grow`` and overwrites them with the clearance.
    """
    n = b - a + 2  # positions 0..n-1 are columns a-1..b
    f[0] = 0.0
    f[n - 1] = 0.0
    for j in range(a, b):
        gj = float(grow[j])
        f[j - a + 1] = gj * gj
    k = 0
    v[0] = 0
    z[0] = -1e300
    z[1] = 1e300
    for q in range(1, n):
        fq = f[q] + q * q
        p = v[k]
        s = (fq - (f[p] + p * p)) / (2.0 * (q - p))
        while s <= z[k]:
            k -= 1
            p = v[k]
            s = (fq - (f[p] + p * p)) / (2.0 * (q - p))
        k += 1
        v[k] = q
        z[k] = s
        z[k + 1] = 1e300
    k = 0
    for q in range(1, n - 1):
        while z[k + 1] < q:
            k += 1
        p = v[k]
        d = np.sqrt((q - p) * (q - p) + f[p]) - 0.5
        grow[a + q - 1] = d
        if d >= min_clear_cells:
            crow[a + q - 1] = 1
            clist[n_c] = base + a + q - 1
            n_c += 1
    return n_c


@njit(cache=True, error_model="numpy")
def _column_distances(work: np.ndarray, g: np.ndarray) -> None:
    """Per column, cells to the nearest non-free cell (outside the array counts as non-free).

    Written into ``g`` (float32, the shape of ``work``).
    """
    H, W = work.shape
    for c in range(W):
        g[0, c] = 1.0 if work[0, c] == FREE_V else 0.0
    for r in range(1, H):
        for c in range(W):
            g[r, c] = g[r - 1, c] + 1.0 if work[r, c] == FREE_V else 0.0
    for c in range(W):
        if g[H - 1, c] > 1.0:
            g[H - 1, c] = 1.0
    for r in range(H - 2, -1, -1):
        for c in range(W):
            up = g[r + 1, c] + 1.0
            if up < g[r, c]:
                g[r, c] = up


@njit(cache=True, error_model="numpy")
def _row_envelopes(
    work: np.ndarray, g: np.ndarray, min_clear_cells: float, cspace: np.ndarray, clist: np.ndarray
) -> tuple[np.ndarray, int]:
    H, W = work.shape
    n_free = 0
    wf = work.ravel()
    for i in range(H * W):
        n_free += wf[i] == FREE_V
    n_c = 0
    f = np.empty(W + 2, np.float64)
    v = np.empty(W + 2, np.int64)
    z = np.empty(W + 3, np.float64)
    for r in range(H):
        row = work[r]
        grow = g[r]
        c = 0
        while c < W:
            if row[c] != FREE_V:
                grow[
                    c
                ] = -1.0  # no clearance test can accept a blocked cell, even with zero clearance
                c += 1
                continue
            a = c
            while c < W and row[c] == FREE_V:
                c += 1
            n_c = _fh_run(grow, a, c, f, v, z, cspace[r], min_clear_cells, r * W, clist, n_c)
    return clist[:n_c], n_free


def clearance_field(
    work: np.ndarray,
    min_clear_cells: float,
    dcell: np.ndarray,
    cspace: np.ndarray,
    clist: np.ndarray,
) -> tuple[np.ndarray, int]:
    """Exact Euclidean clearance of the free cells of an encoded grid and the configuration space.

    ``dcell`` (float32) is the distance from a cell centre to the nearest non-free cell centre
    minus half a cell (the distance to that cell's edge; outside the array counts as non-free;
    -1 on non-free cells). ``cspace`` (uint8) is ``free & dcell >= min_clear_cells``; its cells are
    also listed (sorted flat indices), with the number of free cells. The row pass
    of Felzenszwalb and Huttenlocher's transform runs over free runs only: the blocked cell
    ending a run is closer than any column beyond it. (Two kernels: one kernel holding both
    passes compiles to a much slower column pass.)

    ``dcell`` (float32) and ``cspace`` (uint8, all zeros on entry), both of the shape of
    ``work``, are written in place; ``clist`` is int32 scratch of at least ``work.size + 1`` cells. Returns the C-space
    cell list (a view of ``clist``) and the number of free cells.
    """
    _column_distances(work, dcell)
    return _row_envelopes(work, dcell, float(min_clear_cells), cspace, clist)


# ----------------------------------------------------------------------------------------------
# Thinning
# ----------------------------------------------------------------------------------------------


@njit(cache=True, error_model="numpy")
def _zs_ok(img: np.ndarray, r: int, c: int, sub: int) -> bool:
    p2 = int(img[r - 1, c])
    p3 = int(img[r - 1, c + 1])
    p4 = int(img[r, c + 1])
    p5 = int(img[r + 1, c + 1])
    p6 = int(img[r + 1, c])
    p7 = int(img[r + 1, c - 1])
    p8 = int(img[r, c - 1])
    p9 = int(img[r - 1, c - 1])
    b = p2 + p3 + p4 + p5 + p6 + p7 + p8 + p9
    if b < 2 or b > 6:
        return False
    a = 0
    if p2 == 0 and p3 == 1:
        a += 1
    if p3 == 0 and p4 == 1:
        a += 1
    if p4 == 0 and p5 == 1:
        a += 1
    if p5 == 0 and p6 == 1:
        a += 1
    if p6 == 0 and p7 == 1:
        a += 1
    if p7 == 0 and p8 == 1:
        a += 1
    if p8 == 0 and p9 == 1:
        a += 1
    if p9 == 0 and p2 == 1:
        a += 1
    if a != 1:
        return False
    if sub == 0:
        return p2 * p4 * p6 == 0 and p4 * p6 * p8 == 0
    if sub == 1:
        return p2 * p4 * p8 == 0 and p2 * p6 * p8 == 0
    return True


@njit(cache=True, error_model="numpy")
def _mdeg(f: np.ndarray, W: int, i: int) -> int:
    """Degree of flat pixel ``i`` under m-adjacency (diagonals count only without a shared
    4-neighbour). Flat indexing: no division per pixel."""
    up = f[i + W] != 0
    dn = f[i - W] != 0
    rt = f[i + 1] != 0
    lf = f[i - 1] != 0
    n = int(up) + int(dn) + int(rt) + int(lf)
    if f[i + W + 1] != 0 and not up and not rt:
        n += 1
    if f[i + W - 1] != 0 and not up and not lf:
        n += 1
    if f[i - W + 1] != 0 and not dn and not rt:
        n += 1
    if f[i - W - 1] != 0 and not dn and not lf:
        n += 1
    return n


@njit(cache=True, error_model="numpy")
def reduce_blobs(img: np.ndarray, px: np.ndarray, simple: np.ndarray) -> np.ndarray:
    """Remove simple pixels of m-degree >= 3 (junction blobs) in place; returns the kept pixels.

    ``simple`` is row 2 of :func:`_zs_tables` (simple point by neighbour code).
    """
    H, W = img.shape
    f = img.ravel()
    changed = True
    while changed:
        changed = False
        for k in range(px.size):
            i = px[k]
            if f[i] and _mdeg(f, W, i) >= 3 and simple[_code(f, i, W)]:
                f[i] = 0
                changed = True
    return _still_set(f, px)


@njit(cache=True, error_model="numpy")
def _still_set(f: np.ndarray, px: np.ndarray) -> np.ndarray:
    """The entries of ``px`` whose pixel in the flat image ``f`` is still set (order kept)."""
    n = 0
    for k in range(px.size):
        if f[px[k]]:
            n += 1
    out = np.empty(n, np.int64)
    n = 0
    for k in range(px.size):
        if f[px[k]]:
            out[n] = px[k]
            n += 1
    return out


@njit(cache=True, error_model="numpy")
def _zs_tables() -> np.ndarray:
    """Deletability of a pixel by its 8-neighbour code (bit k = P(k+2), P2 = row-1), per mode.

    Mode 0/1: the two Zhang-Suen sub-iterations; mode 2: simple point with 2..6 neighbours.
    """
    t = np.zeros((3, 256), np.uint8)
    img = np.zeros((3, 3), np.uint8)
    rr = (0, 0, 1, 2, 2, 2, 1, 0)
    cc = (1, 2, 2, 2, 1, 0, 0, 0)
    for code in range(256):
        for k in range(8):
            img[rr[k], cc[k]] = (code >> k) & 1
        img[1, 1] = 1
        for mode in range(3):
            t[mode, code] = 1 if _zs_ok(img, 1, 1, mode) else 0
    return t


@njit(cache=True, error_model="numpy")
def _code(f: np.ndarray, i: int, W: int) -> int:
    return (
        (int(f[i - W]) & 1)
        | ((int(f[i - W + 1]) & 1) << 1)
        | ((int(f[i + 1]) & 1) << 2)
        | ((int(f[i + W + 1]) & 1) << 3)
        | ((int(f[i + W]) & 1) << 4)
        | ((int(f[i + W - 1]) & 1) << 5)
        | ((int(f[i - 1]) & 1) << 6)
        | ((int(f[i - W - 1]) & 1) << 7)
    )


@njit(cache=True, error_model="numpy")
def thin(img: np.ndarray, allfg: np.ndarray, scratch: np.ndarray) -> np.ndarray:
    """Zhang-Suen thinning in place, with a work list and a sequential re-check.

    ``img`` is uint8 0/1 with an empty border; it becomes the skeleton. The re-check keeps 2x2
    blocks connected. ``allfg`` lists its foreground pixels (sorted). Junction blobs are reduced
    afterwards (:func:`reduce_blobs`). ``scratch`` is int32 of at least ``3 * (allfg.size + 1)``
    cells. Returns the sorted flat indices of the skeleton pixels.
    """
    H, W = img.shape
    f = img.ravel()
    tab = _zs_tables()
    n_fg = allfg.size
    cand = scratch[: n_fg + 1]
    nxt = scratch[n_fg + 1 : 2 * n_fg + 2]
    marked = scratch[2 * n_fg + 2 : 3 * n_fg + 3]
    n = 0
    for k in range(n_fg):
        i = allfg[k]
        if _code(f, i, W) != 255:
            cand[n] = i
            n += 1
    while n > 0:
        nn = 0
        for sub in range(2):
            m = 0
            for k in range(n):
                i = cand[k]
                if f[i] & 1 and tab[sub, _code(f, i, W)]:
                    marked[m] = i
                    m += 1
            if sub == 1:
                for k in range(nn):
                    i = nxt[k]
                    if f[i] & 1 and tab[sub, _code(f, i, W)]:
                        marked[m] = i
                        m += 1
            for k in range(m):
                i = marked[k]
                if f[i] & 1 and tab[sub, _code(f, i, W)]:
                    f[i] = 0
                    for dr in range(-1, 2):
                        for dc in range(-1, 2):
                            j = i + dr * W + dc
                            if f[j] == 1:  # foreground, not yet queued (bit 2 marks queued)
                                f[j] = 3
                                nxt[nn] = j
                                nn += 1
        for k in range(nn):
            f[nxt[k]] &= 1
            cand[k] = nxt[k]
        n = nn
    return reduce_blobs(img, _still_set(f, allfg), tab[2])


# ----------------------------------------------------------------------------------------------
# Skeleton graph
# ----------------------------------------------------------------------------------------------


@njit(cache=True, error_model="numpy")
def _mnbrs(f: np.ndarray, W: int, i: int, out: np.ndarray) -> int:
    """m-adjacent neighbours of flat pixel ``i`` of the flat skeleton ``f`` into ``out``."""
    n = 0
    up = f[i + W] != 0
    dn = f[i - W] != 0
    rt = f[i + 1] != 0
    lf = f[i - 1] != 0
    if up:
        out[n] = i + W
        n += 1
    if dn:
        out[n] = i - W
        n += 1
    if rt:
        out[n] = i + 1
        n += 1
    if lf:
        out[n] = i - 1
        n += 1
    if f[i + W + 1] != 0 and not up and not rt:
        out[n] = i + W + 1
        n += 1
    if f[i + W - 1] != 0 and not up and not lf:
        out[n] = i + W - 1
        n += 1
    if f[i - W + 1] != 0 and not dn and not rt:
        out[n] = i - W + 1
        n += 1
    if f[i - W - 1] != 0 and not dn and not lf:
        out[n] = i - W - 1
        n += 1
    return n


@njit(cache=True, error_model="numpy")
def extract_graph(sk: np.ndarray, px: np.ndarray, dcell: np.ndarray, st: np.ndarray):
    """Nodes (clusters of pixels whose m-degree is not 2) and edges (chains of degree-2 pixels).

    ``st`` is a flat int32 scratch array of the grid size filled with -1; it is restored.
    Returns node arrays (rep pixel, radius, degree, pixel CSR) and edge arrays (a, b, pixel CSR
    ordered from a to b). Pure cycles get one of their pixels as a node with a self-loop.
    """
    H, W = sk.shape
    skf = sk.ravel()
    n = px.size
    nb = np.empty(8, np.int64)
    nb2 = np.empty(8, np.int64)
    for k in range(n):
        st[px[k]] = -2 if _mdeg(skf, W, px[k]) == 2 else -4
    # cluster node pixels
    node_of = np.full(n, -1, np.int64)  # node id per px entry (only node pixels)
    stack = np.empty(n + 1, np.int64)
    n_nodes = 0
    for k in range(n):
        i = px[k]
        if st[i] != -4:
            continue
        st[i] = n_nodes
        top = 0
        stack[top] = i
        top += 1
        while top > 0:
            top -= 1
            j = stack[top]
            cnt = _mnbrs(skf, W, j, nb)
            for t in range(cnt):
                q = nb[t]
                if st[q] == -4:
                    st[q] = n_nodes
                    stack[top] = q
                    top += 1
        n_nodes += 1
    # trace edges from node pixels
    edge_a = np.empty(n + 1, np.int64)
    edge_b = np.empty(n + 1, np.int64)
    edge_off = np.zeros(n + 2, np.int64)
    edge_px = np.empty(n + 1, np.int64)
    ne = 0
    ep = 0
    for pass_ in range(2):
        for k in range(n):
            u = px[k]
            if pass_ == 1:
                if st[u] != -2:
                    continue
                # an untouched cycle of degree-2 pixels: make this pixel a node
                st[u] = n_nodes
                n_nodes += 1
            if st[u] < 0:
                continue
            a = st[u]
            cnt = _mnbrs(skf, W, u, nb)
            for t in range(cnt):
                v = nb[t]
                if st[v] != -2:
                    continue
                prev = u
                cur = v
                b = a
                while True:
                    st[cur] = -3
                    edge_px[ep] = cur
                    ep += 1
                    c2 = _mnbrs(skf, W, cur, nb2)
                    w = -1
                    for s in range(c2):
                        if nb2[s] != prev:
                            w = nb2[s]
                            break
                    if w < 0:
                        break
                    if st[w] >= 0:
                        b = st[w]
                        break
                    if st[w] == -3:
                        break
                    prev = cur
                    cur = w
                edge_a[ne] = a
                edge_b[ne] = b
                ne += 1
                edge_off[ne] = ep
    # node pixel lists, representative (largest clearance) and degree
    node_cnt = np.zeros(n_nodes + 1, np.int64)
    for k in range(n):
        s = st[px[k]]
        if s >= 0:
            node_of[k] = s
            node_cnt[s + 1] += 1
    node_off = np.cumsum(node_cnt)
    node_px = np.empty(node_off[-1], np.int64)
    fill = node_off[:-1].copy()
    node_rep = np.full(n_nodes, -1, np.int64)
    node_r = np.full(n_nodes, -1.0, np.float64)
    dflat = dcell.ravel()
    for k in range(n):
        s = node_of[k]
        if s >= 0:
            i = px[k]
            node_px[fill[s]] = i
            fill[s] += 1
            d = dflat[i]
            if d > node_r[s]:
                node_r[s] = d
                node_rep[s] = i
    node_deg = np.zeros(n_nodes, np.int64)
    for e in range(ne):
        node_deg[edge_a[e]] += 1
        node_deg[edge_b[e]] += 1
    for k in range(n):
        st[px[k]] = -1
    return (
        n_nodes,
        node_rep,
        node_r,
        node_deg,
        node_off,
        node_px,
        ne,
        edge_a[:ne].copy(),
        edge_b[:ne].copy(),
        edge_off[: ne + 1].copy(),
        edge_px[:ep].copy(),
    )


@njit(cache=True, error_model="numpy")
def splice_pass_nodes(n_nodes, node_deg, node_off, node_px, ne, edge_a, edge_b, edge_off, edge_px):
    """Join the two edges of every degree-2 node (a junction blob with only two exits) into one.

    Returns new edge arrays and a per-node ``alive`` flag; a dissolved node's pixels are put into
    the joined edge. A cycle made only of such nodes keeps its first node as a self-loop anchor.
    """
    inc_cnt = np.zeros(n_nodes + 1, np.int64)
    for e in range(ne):
        inc_cnt[edge_a[e] + 1] += 1
        inc_cnt[edge_b[e] + 1] += 1
    inc_off = np.cumsum(inc_cnt)
    inc = np.empty(inc_off[-1], np.int64)
    fill = inc_off[:-1].copy()
    for e in range(ne):
        inc[fill[edge_a[e]]] = 2 * e
        fill[edge_a[e]] += 1
        inc[fill[edge_b[e]]] = 2 * e + 1
        fill[edge_b[e]] += 1
    splice = np.zeros(n_nodes, np.bool_)
    for v in range(n_nodes):
        if node_deg[v] == 2:
            e0 = inc[inc_off[v]] // 2
            e1 = inc[inc_off[v] + 1] // 2
            if e0 != e1:
                splice[v] = True
    alive = np.ones(n_nodes, np.bool_)
    used = np.zeros(ne, np.bool_)
    new_a = np.empty(ne + 1, np.int64)
    new_b = np.empty(ne + 1, np.int64)
    new_off = np.zeros(ne + 2, np.int64)
    new_px = np.empty(edge_px.size + node_px.size + 1, np.int64)
    nn = 0
    p = 0
    for e0 in range(ne):
        if used[e0]:
            continue
        # walk backwards from the a-end of e0 to the start of its chain
        e = e0
        end = 0  # we leave edge e through its end `end` (0 = a, 1 = b) when walking backwards
        cyc = False
        while True:
            v = edge_a[e] if end == 0 else edge_b[e]
            if not splice[v]:
                break
            s0 = inc[inc_off[v]]
            s1 = inc[inc_off[v] + 1]
            nxt = s1 if s0 // 2 == e else s0
            e = nxt // 2
            # we arrive at edge e through its end nxt % 2; continue through the other end
            end = 1 - (nxt % 2)
            if e == e0:
                cyc = True
                break
        # e is the first edge; it starts at its end `end`
        start_e = e
        start_end = end
        if cyc:
            # anchor the cycle at the splice node we started from
            start_e = e0
            start_end = 0
        first_node = edge_a[start_e] if start_end == 0 else edge_b[start_e]
        e = start_e
        from_end = start_end
        while True:
            used[e] = True
            lo = edge_off[e]
            hi = edge_off[e + 1]
            if from_end == 0:
                for t in range(lo, hi):
                    new_px[p] = edge_px[t]
                    p += 1
                v = edge_b[e]
            else:
                for t in range(hi - 1, lo - 1, -1):
                    new_px[p] = edge_px[t]
                    p += 1
                v = edge_a[e]
            if not splice[v] or (cyc and v == first_node):
                last_node = v
                break
            alive[v] = False
            for t in range(node_off[v], node_off[v + 1]):
                new_px[p] = node_px[t]
                p += 1
            s0 = inc[inc_off[v]]
            s1 = inc[inc_off[v] + 1]
            # leave v through the incidence that is not the one we came in by
            came = 2 * e + (1 if from_end == 0 else 0)
            nxt = s1 if s0 == came else s0
            e = nxt // 2
            from_end = nxt % 2
        if cyc:
            alive[first_node] = True
        new_a[nn] = first_node
        new_b[nn] = last_node
        nn += 1
        new_off[nn] = p
    return (
        alive,
        nn,
        new_a[:nn].copy(),
        new_b[:nn].copy(),
        new_off[: nn + 1].copy(),
        new_px[:p].copy(),
    )


@njit(cache=True, error_model="numpy")
def _has_plateau(edge_px, first, n, step, dflat, W, lim, min_len):
    """Whether a branch (walked from ``first`` by ``step`` for ``n`` pixels) has a corridor stretch.

    A corridor stretch keeps its clearance within [0.75 m, m] with ``m <= lim`` over a length of at
    least ``min_len + 0.5 m``: a dead-end corridor or closet has one, a room corner (a wedge
    whose clearance changes steadily along the branch) has none. Two pointers with monotonic
    deques of the window's maximum and minimum.
    """
    if n < 2:
        return False
    dq_max = np.empty(n, np.int64)
    dq_min = np.empty(n, np.int64)
    h_max = 0
    t_max = 0
    h_min = 0
    t_min = 0
    cum = np.empty(n, np.float64)
    cum[0] = 0.0
    i = 0
    for k in range(n):
        q = edge_px[first + k * step]
        if k > 0:
            p = edge_px[first + (k - 1) * step]
            dr = abs(q // W - p // W)
            dc = abs(q % W - p % W)
            cum[k] = cum[k - 1] + (1.4142135623730951 if dr + dc == 2 else float(dr + dc))
        dk = dflat[q]
        while t_max > h_max and dflat[edge_px[first + dq_max[t_max - 1] * step]] <= dk:
            t_max -= 1
        dq_max[t_max] = k
        t_max += 1
        while t_min > h_min and dflat[edge_px[first + dq_min[t_min - 1] * step]] >= dk:
            t_min -= 1
        dq_min[t_min] = k
        t_min += 1
        while True:
            mx = dflat[edge_px[first + dq_max[h_max] * step]]
            mn = dflat[edge_px[first + dq_min[h_min] * step]]
            if mn >= 0.75 * mx or i >= k:
                break
            i += 1
            if dq_max[h_max] < i:
                h_max += 1
            if dq_min[h_min] < i:
                h_min += 1
        mx = dflat[edge_px[first + dq_max[h_max] * step]]
        if mx <= lim and cum[k] - cum[i] + 1.0 >= min_len + 0.5 * mx:
            return True
    return False


@njit(cache=True, error_model="numpy")
def skeleton_graph(sk, px, dcell, st):
    """:func:`extract_graph`, then :func:`splice_pass_nodes` when a node has degree 2.

    Returns ``(n, rep, r, deg, noff, npx, ne, ea, eb, eoff, epx, alive)``; ``deg`` counts the
    spliced edges.
    """
    (n, rep, r, deg, noff, npx, ne, ea, eb, eoff, epx) = extract_graph(sk, px, dcell, st)
    alive = np.ones(n, np.bool_)
    has_pass = False
    for v in range(n):
        if deg[v] == 2:
            has_pass = True
            break
    if ne > 0 and has_pass:
        alive, ne, ea, eb, eoff, epx = splice_pass_nodes(n, deg, noff, npx, ne, ea, eb, eoff, epx)
        deg = np.zeros(n, np.int64)
        for e in range(ea.size):
            deg[ea[e]] += 1
            deg[eb[e]] += 1
    return n, rep, r, deg, noff, npx, ne, ea, eb, eoff, epx, alive


@njit(cache=True, error_model="numpy")
def remove_pixels(sk, px, gone):
    """Clear the pixels ``gone`` of the skeleton ``sk`` and reduce junction blobs again;
    returns the remaining skeleton pixels (sorted, as ``px``)."""
    f = sk.ravel()
    for k in range(gone.size):
        f[gone[k]] = 0
    return reduce_blobs(sk, px, _zs_tables()[2])  # skips and drops the cleared pixels


@njit(cache=True, error_model="numpy")
def spur_pixels(
    W,
    node_rep,
    node_r,
    node_deg,
    node_off,
    node_px,
    ne,
    edge_a,
    edge_b,
    edge_off,
    edge_px,
    dcell,
    spur_ratio,
    min_depth_cells,
    neck_ratio,
):
    """Pixels of the branches to prune: junction-to-end edges that barely leave the junction disk.

    A branch protrudes ``|E - J| + d(E) - r_J`` beyond the junction's inscribed disk (E the end
    node, J the junction, d the clearance); it is pruned when that is below
    ``spur_ratio * r_J + min_depth_cells`` *and* it has no corridor stretch narrower than
    ``neck_ratio * r_J`` (see :func:`_has_plateau`): a dead-end corridor or closet leaving a big
    room is kept however big the room, a room corner is not. When pruning would leave a junction with fewer than
    two branches, its most protruding branch is kept: the junction then dissolves and that
    branch is judged again, as part of the longer branch it continues, in the next round
    (otherwise a dead end broken by a noise junction is eaten piece by piece).
    """
    dflat = dcell.ravel()
    n_nodes = node_rep.size
    protr = np.full(ne, -1e300)
    below = np.zeros(n_nodes, np.int64)
    keep = np.full(n_nodes, -1, np.int64)
    for e in range(ne):
        a = edge_a[e]
        b = edge_b[e]
        if node_deg[a] >= 3 and node_deg[b] == 1:
            j = a
            t = b
        elif node_deg[b] >= 3 and node_deg[a] == 1:
            j = b
            t = a
        else:
            continue
        rj = node_rep[j] // W
        cj = node_rep[j] - rj * W
        rt = node_rep[t] // W
        ct = node_rep[t] - rt * W
        pr = np.sqrt((rj - rt) ** 2 + (cj - ct) ** 2) + dflat[node_rep[t]] - node_r[j]
        if pr < spur_ratio * node_r[j] + min_depth_cells:
            step = -1 if t == b else 1
            first = edge_off[e + 1] - 1 if t == b else edge_off[e]
            if _has_plateau(
                edge_px,
                first,
                edge_off[e + 1] - edge_off[e],
                step,
                dflat,
                W,
                neck_ratio * node_r[j],
                min_depth_cells,
            ):
                continue
            protr[e] = pr
            below[j] += 1
            if keep[j] < 0 or pr > protr[keep[j]]:
                keep[j] = e
    out = np.empty(edge_px.size + node_px.size + 1, np.int64)
    n = 0
    for e in range(ne):
        if protr[e] == -1e300:
            continue
        a = edge_a[e]
        j = a if node_deg[a] >= 3 else edge_b[e]
        t = edge_b[e] if j == a else a
        if node_deg[j] - below[j] <= 1 and keep[j] == e:
            continue
        for k in range(edge_off[e], edge_off[e + 1]):
            out[n] = edge_px[k]
            n += 1
        for k in range(node_off[t], node_off[t + 1]):
            out[n] = node_px[k]
            n += 1
    return out[:n].copy()


# ----------------------------------------------------------------------------------------------
# Openings on skeleton edges, merging of junctions, regions
# ----------------------------------------------------------------------------------------------


@njit(cache=True, error_model="numpy")
def _uf_find(parent: np.ndarray, x: int) -> int:
    while parent[x] != x:
        parent[x] = parent[parent[x]]
        x = parent[x]
    return x


@njit(cache=True, error_model="numpy")
def _uf_union(parent: np.ndarray, a: int, b: int) -> None:
    ra = _uf_find(parent, a)
    rb = _uf_find(parent, b)
    if ra != rb:
        if ra < rb:
            parent[rb] = ra
        else:
            parent[ra] = rb


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
        if r < 0 or c < 0 or r >= H or c >= W or work[r, c] != FREE_V:
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
def build_regions(
    n_nodes,
    alive,
    node_off,
    node_px,
    ne,
    edge_a,
    edge_b,
    edge_off,
    edge_px,
    internal,
    open_a,
    open_b,
    lab,
):
    """Union-find over nodes and edge middles; writes region labels of skeleton pixels into ``lab``.

    Returns ``(n_regions, node_region, mid_region)`` and the opening table
    ``(op_px, op_edge, op_idx, op_core, op_far)``. Opening pixels are left unlabelled (-1).
    """
    n_el = n_nodes + ne
    parent = np.arange(n_el)
    for e in range(ne):
        a = edge_a[e]
        b = edge_b[e]
        m = n_nodes + e
        if internal[e]:
            _uf_union(parent, a, b)
            _uf_union(parent, m, a)
        else:
            if open_a[e] < 0:
                _uf_union(parent, m, a)
            if open_b[e] < 0:
                _uf_union(parent, m, b)
    root_id = np.full(n_el, -1, np.int64)
    region = np.empty(n_el, np.int64)
    n_reg = 0
    for x in range(n_el):
        if x < n_nodes and not alive[x]:
            region[x] = -1
            continue
        rt = _uf_find(parent, x)
        if root_id[rt] < 0:
            root_id[rt] = n_reg
            n_reg += 1
        region[x] = root_id[rt]
    for v in range(n_nodes):
        if not alive[v]:
            continue
        for t in range(node_off[v], node_off[v + 1]):
            lab[node_px[t]] = region[v]
    n_op = 0
    for e in range(ne):
        if open_a[e] >= 0:
            n_op += 1
        if open_b[e] >= 0:
            n_op += 1
    op_px = np.empty(n_op, np.int64)
    op_edge = np.empty(n_op, np.int64)
    op_idx = np.empty(n_op, np.int64)
    op_core = np.empty(n_op, np.int64)
    op_far = np.empty(n_op, np.int64)
    k = 0
    for e in range(ne):
        lo = edge_off[e]
        L = edge_off[e + 1] - lo
        ra = region[edge_a[e]]
        rb = region[edge_b[e]]
        rm = region[n_nodes + e]
        oa = open_a[e]
        ob = open_b[e] if open_b[e] >= 0 else L
        for i in range(L):
            q = edge_px[lo + i]
            if i == oa or i == ob:
                lab[q] = -1
            elif i < oa:
                lab[q] = ra
            elif i > ob:
                lab[q] = rb
            else:
                lab[q] = rm
        if open_a[e] >= 0:
            op_px[k] = edge_px[lo + oa]
            op_edge[k] = e
            op_idx[k] = oa
            op_core[k] = ra
            op_far[k] = rm
            k += 1
        if open_b[e] >= 0:
            op_px[k] = edge_px[lo + ob]
            op_edge[k] = e
            op_idx[k] = ob
            op_core[k] = rb
            op_far[k] = rm
            k += 1
    return (
        n_reg,
        region[:n_nodes].copy(),
        region[n_nodes:].copy(),
        op_px,
        op_edge,
        op_idx,
        op_core,
        op_far,
    )


# ----------------------------------------------------------------------------------------------
# Opening chords
# ----------------------------------------------------------------------------------------------


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
            if rr >= 0 and cc >= 0 and rr < H and cc < W and work[rr, cc] == FREE_V:
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


# ----------------------------------------------------------------------------------------------
# Region trees: skeleton BFS from region centres, then C-space, then the rest of free space
# ----------------------------------------------------------------------------------------------


@njit(cache=True, error_model="numpy")
def region_centres(px, lab, dcell, n_reg, W):
    """Per region, a central skeleton pixel far from walls (-1 if the region has none).

    Maximises ``d(p) - 0.5 |p - m|`` over the region's skeleton pixels, with ``m`` their mean:
    the most open point, pulled towards the middle of large areas.
    """
    dflat = dcell.ravel()
    sr = np.zeros(n_reg, np.float64)
    sc = np.zeros(n_reg, np.float64)
    cnt = np.zeros(n_reg, np.float64)
    for k in range(px.size):
        i = px[k]
        g = lab[i]
        if g >= 0:
            sr[g] += i // W
            sc[g] += i % W
            cnt[g] += 1.0
    for g in range(n_reg):
        if cnt[g] > 0:
            sr[g] /= cnt[g]
            sc[g] /= cnt[g]
    best = np.full(n_reg, -1, np.int64)
    bs = np.full(n_reg, -1e300, np.float64)
    for k in range(px.size):
        i = px[k]
        g = lab[i]
        if g >= 0:
            score = dflat[i] - 0.5 * np.sqrt((i // W - sr[g]) ** 2 + (i % W - sc[g]) ** 2)
            if score > bs[g]:
                bs[g] = score
                best[g] = i
    return best


@njit(cache=True, error_model="numpy")
def _row_sweep(W, H, lab, st, w_flat, q, tail, max_d, left, rest, counts):
    """Give unlabelled free cells the label of the nearest labelled cell in their row.

    Sources are cells labelled before the sweep, at most ``max_d`` cells away through free
    cells that are not chords; a cell's parent (``st``) is its source. Free unlabelled cells
    left over are appended to ``rest`` (grown as needed); returns ``(tail, rest, n_rest)``.
    Each row is handled run of free cells by run, from the right (so cells are visited in
    descending column order), skipping walls and unknown space.
    """
    n_rest = 0
    for line in range(1, H - 1):
        base = line * W
        wrow = w_flat[base : base + W]
        lrow = lab[base : base + W]
        b = W
        while b > 0:
            while b > 0 and wrow[b - 1] != FREE_V:
                b -= 1
            if b == 0:
                break
            a = b - 1
            while a > 0 and wrow[a - 1] == FREE_V:
                a -= 1
            # free run [a, b): nearest source at or before k; branch-free (selects)
            src = -1
            for k in range(a, b):
                g = lrow[k]
                src = k if g >= 0 else (src if g == -1 else -1)
                left[k] = src
            # nearest source after k; cells labelled here are not sources
            src = -1
            for k in range(b - 1, a - 1, -1):
                g = lrow[k]
                if g != -1:
                    src = k if g >= 0 else -1
                    continue
                best = -1
                bd = max_d + 1
                lk = left[k]
                if lk >= 0 and k - lk < bd:
                    best = lk
                    bd = k - lk
                if src >= 0 and src - k < bd:
                    best = src
                i = base + k
                if best >= 0:
                    j = base + best
                    g = lab[j]
                    lab[i] = g
                    counts[g] += 1
                    st[i] = j
                    q[tail] = i
                    tail += 1
                else:
                    if n_rest >= rest.size:
                        grown = np.empty(2 * rest.size, np.int32)
                        grown[:n_rest] = rest[:n_rest]
                        rest = grown
                    rest[n_rest] = i
                    n_rest += 1
            b = a
    return tail, rest, n_rest


@njit(cache=True, error_model="numpy")
def _skeleton_bfs(qs, head, tail, px, st, lab_sk, sk_dep, sk_par, W):
    """Breadth-first search over same-label skeleton pixels (8-neighbours) from the queue
    entries ``qs[head:tail]``; returns the new tail."""
    while head < tail:
        k = qs[head]
        head += 1
        i = px[k]
        g = lab_sk[k]
        for dr in range(-1, 2):
            for dc in range(-1, 2):
                kj = st[i + dr * W + dc]
                if kj >= 0 and lab_sk[kj] == g and sk_dep[kj] < 0:
                    sk_dep[kj] = sk_dep[k] + 1
                    sk_par[kj] = k
                    qs[tail] = kj
                    tail += 1
    return tail


@njit(cache=True, error_model="numpy")
def grow_regions(
    W,
    sk,
    px,
    st,
    roots,
    lab,
    dcell,
    min_clear,
    work,
    max_out_depth,
    chord_cells,
    op_core,
    n_reg,
    n_free,
    q,
):
    """Label every reachable free cell with a region and build one shortest-path tree per region.

    1. BFS over each region's skeleton pixels (8-neighbours, same label) from its root: the
       skeleton tree, kept compactly by skeleton index (``sk_par``, ``sk_dep``).
    2. BFS from all skeleton pixels over C-space cells (4-neighbours), never into barriers.
    3. A row sweep gives the other free cells the label of the nearest labelled cell in their
       row (at most ``max_out_depth`` cells away, not across walls or chords); a layered BFS
       over the cells still unlabelled finishes (room corners, cells beside the C-space ends).
    Chord cells then take the label of their opening's core region when they touch a labelled
    cell. On return ``st`` holds, for skeleton pixels, their skeleton index and, for other
    labelled cells, the parent cell towards the skeleton (-1 for chord cells).

    ``q`` is int32 scratch of at least ``n_free + 1`` cells.

    Returns ``(sk_par, sk_dep, counts)``: the skeleton tree and the cells per region.
    """
    H = sk.shape[0]
    n_px = px.size
    sk_flat = sk.ravel()
    d_flat = dcell.ravel()
    w_flat = work.ravel()
    # skeleton pixels are exactly the cells with st >= 0 here; their labels are copied into a
    # compact array so the tree search touches one grid-sized array (st), not three
    lab_sk = np.empty(n_px, np.int32)
    for k in range(n_px):
        st[px[k]] = k
        lab_sk[k] = lab[px[k]]
    sk_par = np.full(n_px, -1, np.int32)
    sk_dep = np.full(n_px, -1, np.int32)
    qs = np.empty(n_px + 1, np.int32)
    # One region at a time (regions never share skeleton pixels, so each tree is the same as
    # in a joint BFS): the search stays inside one region's memory instead of hopping between
    # thousands of regions, which on large maps costs a cache miss per pixel.
    tail = 0
    for g in range(roots.size):
        rt = roots[g]
        if rt >= 0:
            k = st[rt]
            sk_dep[k] = 0
            qs[tail] = k
            tail = _skeleton_bfs(qs, tail, tail + 1, px, st, lab_sk, sk_dep, sk_par, W)
    # skeleton pixels not reached from their root (not expected) start trees of their own
    for k in range(n_px):
        if sk_dep[k] < 0 and lab[px[k]] >= 0:
            sk_dep[k] = 0
            qs[tail] = k
            tail = _skeleton_bfs(qs, tail, tail + 1, px, st, lab_sk, sk_dep, sk_par, W)
    counts = np.zeros(n_reg, np.int64)
    tail = 0
    for k in range(n_px):
        g = lab[px[k]]
        if g >= 0:
            q[tail] = px[k]
            tail += 1
            counts[g] += 1
    head = 0
    while head < tail:
        i = q[head]
        head += 1
        g = lab[i]
        for t in range(4):
            j = i + (W if t == 0 else (-W if t == 1 else (1 if t == 2 else -1)))
            if lab[j] == -1 and d_flat[j] >= min_clear and sk_flat[j] == 0:
                lab[j] = g
                counts[g] += 1
                st[j] = i
                q[tail] = j
                tail += 1
    # 3. the rest of free space: nearest labelled C-space cell along the row, then the column,
    # within max_out_depth cells and without crossing walls or chords. Each such cell's parent
    # (st) is that C-space cell, so the robot's anchor for it is one step away.
    left = np.empty(W, np.int64)
    tail, rest, n_rest = _row_sweep(
        W, H, lab, st, w_flat, q, tail, max_out_depth, left, np.empty(4096, np.int32), counts
    )
    # what the rows did not reach (room corners, cells above or below the C-space): a layered
    # BFS over those cells only, from their labelled 4-neighbours
    head = tail
    for t in range(n_rest):
        i = rest[t]
        if lab[i] != -1:
            continue
        for u in range(4):
            j = i + (W if u == 0 else (-W if u == 1 else (1 if u == 2 else -1)))
            if lab[j] >= 0:
                lab[i] = lab[j]
                counts[lab[j]] += 1
                st[i] = j
                q[tail] = i
                tail += 1
                break
    layer_end = tail
    layer = 1
    while head < tail and layer < max_out_depth:
        i = q[head]
        head += 1
        for u in range(4):
            j = i + (W if u == 0 else (-W if u == 1 else (1 if u == 2 else -1)))
            if lab[j] == -1 and w_flat[j] == FREE_V:
                lab[j] = lab[i]
                counts[lab[i]] += 1
                st[j] = i
                q[tail] = j
                tail += 1
        if head == layer_end:
            layer += 1
            layer_end = tail
    # chord cells join the core side of their opening where they touch labelled cells
    extra_cells = np.empty(chord_cells.size, np.int32)
    touching = np.zeros(chord_cells.size, np.bool_)
    n_extra = 0
    for t in range(chord_cells.size):
        i = chord_cells[t]
        if lab[i] > -2:
            continue
        ok = False
        for u in range(4):
            j = i + (W if u == 0 else (-W if u == 1 else (1 if u == 2 else -1)))
            if lab[j] >= 0:
                ok = True
        extra_cells[n_extra] = i
        touching[n_extra] = ok
        n_extra += 1
    for t in range(n_extra):
        i = extra_cells[t]
        if not touching[t]:
            lab[i] = -1
            continue
        g = op_core[-lab[i] - 2]
        lab[i] = g
        if sk_flat[i] == 0:
            st[i] = -1
        counts[g] += 1
    return sk_par, sk_dep, counts


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
            and wf[i] == FREE_V
            and (
                wf[i + W] == UNKNOWN_V
                or wf[i - W] == UNKNOWN_V
                or wf[i + 1] == UNKNOWN_V
                or wf[i - 1] == UNKNOWN_V
            )
        ):
            fc[n] = i
            n += 1
    fc = fc[:n]
    orow = np.zeros(n, np.int64)
    ocol = np.zeros(n, np.int64)
    for k in range(n):
        i = fc[k]
        if wf[i + W] == UNKNOWN_V:
            orow[k] += 1
        if wf[i - W] == UNKNOWN_V:
            orow[k] -= 1
        if wf[i + 1] == UNKNOWN_V:
            ocol[k] += 1
        if wf[i - 1] == UNKNOWN_V:
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
def scatter_labels(out, lab, lut, W, r0, c0):
    """Fill ``out`` (contents undefined on entry): ``out[r + r0, c + c0] = lut[lab[r * W + c]]``
    for labelled work-grid cells, -1 everywhere else (one pass over ``out``)."""
    H0, W0 = out.shape
    Hw = lab.size // W
    ra = max(0, -r0)
    rb = min(Hw, H0 - r0)
    ca = max(0, -c0)
    cb = min(W, W0 - c0)
    for ro in range(H0):
        orow = out[ro]
        r = ro - r0
        if r < ra or r >= rb:
            orow[:] = -1
            continue
        orow[: ca + c0] = -1
        orow[cb + c0 :] = -1
        base = r * W - c0
        for co in range(ca + c0, cb + c0):
            g = lab[base + co]
            orow[co] = lut[g] if g >= 0 else -1


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
        if v == OCCUPIED_V:
            return False
        if v == UNKNOWN_V:
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


# ----------------------------------------------------------------------------------------------
# Paths
# ----------------------------------------------------------------------------------------------


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
