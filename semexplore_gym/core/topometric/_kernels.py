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


@njit(cache=True)
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
        row_free = False
        for c in range(W):
            v = enc[r, c]
            if v == FREE_V:
                row_free = True
                if c < cmin:
                    cmin = c
                if c > cmax:
                    cmax = c
            elif v != UNKNOWN_V and v != OCCUPIED_V:
                return r * W + c, -1, -1, -1, -1
        if row_free:
            if rmin < 0:
                rmin = r
            rmax = r
    return -1, rmin, rmax, cmin, cmax


@njit(cache=True)
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


@njit(cache=True)
def filter_small_blobs(work: np.ndarray, max_speck_cells: int, max_hole_cells: int) -> int:
    """Erase occupied specks and close unknown holes next to free cells, in place.

    An 8-connected OCCUPIED blob of at most ``max_speck_cells`` not touching the array edge whose
    neighbours are all FREE becomes FREE. An UNKNOWN blob of at most ``max_hole_cells`` not
    touching the edge becomes FREE when its neighbours are all FREE, OCCUPIED otherwise.
    Returns the number of cells changed.
    """
    H, W = work.shape
    if max_speck_cells <= 0 and max_hole_cells <= 0:
        return 0
    state = np.zeros(H * W, np.uint8)  # 1 = big/edge blob or handled, 2 = current blob
    mx = max(max_speck_cells, max_hole_cells)
    stack = np.empty(8 * (mx + 2), np.int64)
    blob = np.empty(mx + 1, np.int64)
    changed = 0
    wf = work.ravel()
    for r in range(1, H - 1):
        for c in range(1, W - 1):
            if work[r, c] != FREE_V:
                continue
            i = r * W + c
            for dr in range(-1, 2):
                for dc in range(-1, 2):
                    j = i + dr * W + dc
                    v = wf[j]
                    if v == FREE_V or state[j] != 0:
                        continue
                    limit = max_speck_cells if v == OCCUPIED_V else max_hole_cells
                    if limit <= 0:
                        state[j] = 1
                        continue
                    n_blob = _flood_blob(work, state, stack, blob, j, v, limit)
                    if n_blob < 0:
                        continue
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
                    for t in range(n_blob):
                        q = blob[t]
                        state[q] = 1
                        if new_v >= 0:
                            wf[q] = new_v
                            changed += 1
    return changed


# ----------------------------------------------------------------------------------------------
# Euclidean distance transform (Felzenszwalb & Huttenlocher), outside the array counts as blocked
# ----------------------------------------------------------------------------------------------


@njit(cache=True)
def _fh_run(grow, a, b, f, v, z, drow, crow, min_clear_cells):
    """Lower envelope of parabolas over the free run [a, b) of one row (blocked at a-1 and b)."""
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
        drow[a + q - 1] = d
        if d >= min_clear_cells:
            crow[a + q - 1] = 1


@njit(cache=True)
def clearance_field(free: np.ndarray, min_clear_cells: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact Euclidean clearance of free cells and the configuration space.

    ``dcell`` is the distance from a cell centre to the nearest non-free cell centre minus half
    a cell (the distance to that cell's edge; outside the array counts as non-free; 0 on non-free
    cells). ``cspace`` is ``free & dcell >= min_clear_cells``. The row pass of Felzenszwalb and
    Huttenlocher's transform runs over free runs only: the blocked cell ending a run is closer
    than any column beyond it.
    """
    H, W = free.shape
    g = np.empty((H, W), np.int32)
    for c in range(W):
        g[0, c] = 1 if free[0, c] else 0
    for r in range(1, H):
        for c in range(W):
            g[r, c] = g[r - 1, c] + 1 if free[r, c] else 0
    for c in range(W):
        if g[H - 1, c] > 1:
            g[H - 1, c] = 1
    for r in range(H - 2, -1, -1):
        for c in range(W):
            up = g[r + 1, c] + 1
            if up < g[r, c]:
                g[r, c] = up
    dcell = np.zeros((H, W), np.float32)
    cspace = np.zeros((H, W), np.uint8)
    f = np.empty(W + 2, np.float64)
    v = np.empty(W + 2, np.int64)
    z = np.empty(W + 3, np.float64)
    for r in range(H):
        row = free[r]
        c = 0
        while c < W:
            if not row[c]:
                c += 1
                continue
            a = c
            while c < W and row[c]:
                c += 1
            _fh_run(g[r], a, c, f, v, z, dcell[r], cspace[r], min_clear_cells)
    return dcell, cspace


# ----------------------------------------------------------------------------------------------
# Thinning
# ----------------------------------------------------------------------------------------------


@njit(cache=True)
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


@njit(cache=True)
def _mdeg(img: np.ndarray, r: int, c: int) -> int:
    """Degree of a pixel under m-adjacency (diagonals count only without a shared 4-neighbour)."""
    up = img[r + 1, c] != 0
    dn = img[r - 1, c] != 0
    rt = img[r, c + 1] != 0
    lf = img[r, c - 1] != 0
    n = int(up) + int(dn) + int(rt) + int(lf)
    if img[r + 1, c + 1] != 0 and not up and not rt:
        n += 1
    if img[r + 1, c - 1] != 0 and not up and not lf:
        n += 1
    if img[r - 1, c + 1] != 0 and not dn and not rt:
        n += 1
    if img[r - 1, c - 1] != 0 and not dn and not lf:
        n += 1
    return n


@njit(cache=True)
def reduce_blobs(img: np.ndarray, px: np.ndarray) -> np.ndarray:
    """Remove simple pixels of m-degree >= 3 (junction blobs) in place; returns the kept pixels."""
    H, W = img.shape
    changed = True
    while changed:
        changed = False
        for k in range(px.size):
            i = px[k]
            r = i // W
            c = i - r * W
            if img[r, c] and _mdeg(img, r, c) >= 3 and _zs_ok(img, r, c, 2):
                img[r, c] = 0
                changed = True
    f = img.ravel()
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


@njit(cache=True)
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


@njit(cache=True)
def _code(f: np.ndarray, i: int, W: int) -> int:
    return (
        int(f[i - W])
        | (int(f[i - W + 1]) << 1)
        | (int(f[i + 1]) << 2)
        | (int(f[i + W + 1]) << 3)
        | (int(f[i + W]) << 4)
        | (int(f[i + W - 1]) << 5)
        | (int(f[i - 1]) << 6)
        | (int(f[i - W - 1]) << 7)
    )


@njit(cache=True)
def thin(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Zhang-Suen thinning with a work list and a sequential re-check (keeps 2x2 blocks connected).

    ``mask`` is uint8 0/1 with an empty border. Returns the skeleton image (uint8 0/1) and the
    flat indices of its pixels. Junction blobs are reduced afterwards (see :func:`reduce_blobs`).
    """
    img = mask.copy()
    H, W = img.shape
    f = img.ravel()
    tab = _zs_tables()
    n_fg = 0
    for i in range(H * W):
        if f[i]:
            n_fg += 1
    cand = np.empty(n_fg + 1, np.int64)
    nxt = np.empty(n_fg + 1, np.int64)
    marked = np.empty(n_fg + 1, np.int64)
    flag = np.zeros(H * W, np.uint8)
    n = 0
    for i in range(W, H * W - W):
        if f[i] and _code(f, i, W) != 255:
            cand[n] = i
            n += 1
    while n > 0:
        nn = 0
        for sub in range(2):
            m = 0
            for k in range(n):
                i = cand[k]
                if f[i] and tab[sub, _code(f, i, W)]:
                    marked[m] = i
                    m += 1
            if sub == 1:
                for k in range(nn):
                    i = nxt[k]
                    if f[i] and tab[sub, _code(f, i, W)]:
                        marked[m] = i
                        m += 1
            for k in range(m):
                i = marked[k]
                if f[i] and tab[sub, _code(f, i, W)]:
                    f[i] = 0
                    for dr in range(-1, 2):
                        for dc in range(-1, 2):
                            j = i + dr * W + dc
                            if f[j] and flag[j] == 0:
                                flag[j] = 1
                                nxt[nn] = j
                                nn += 1
        for k in range(nn):
            flag[nxt[k]] = 0
            cand[k] = nxt[k]
        n = nn
    cnt = 0
    for i in range(H * W):
        if f[i]:
            cnt += 1
    px = np.empty(cnt, np.int64)
    cnt = 0
    for i in range(H * W):
        if f[i]:
            px[cnt] = i
            cnt += 1
    px = reduce_blobs(img, px)
    return img, px


# ----------------------------------------------------------------------------------------------
# Skeleton graph
# ----------------------------------------------------------------------------------------------


@njit(cache=True)
def _mnbrs(sk: np.ndarray, W: int, i: int, out: np.ndarray) -> int:
    r = i // W
    c = i - r * W
    n = 0
    up = sk[r + 1, c] != 0
    dn = sk[r - 1, c] != 0
    rt = sk[r, c + 1] != 0
    lf = sk[r, c - 1] != 0
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
    if sk[r + 1, c + 1] != 0 and not up and not rt:
        out[n] = i + W + 1
        n += 1
    if sk[r + 1, c - 1] != 0 and not up and not lf:
        out[n] = i + W - 1
        n += 1
    if sk[r - 1, c + 1] != 0 and not dn and not rt:
        out[n] = i - W + 1
        n += 1
    if sk[r - 1, c - 1] != 0 and not dn and not lf:
        out[n] = i - W - 1
        n += 1
    return n


@njit(cache=True)
def extract_graph(sk: np.ndarray, px: np.ndarray, dcell: np.ndarray, st: np.ndarray):
    """Nodes (clusters of pixels whose m-degree is not 2) and edges (chains of degree-2 pixels).

    ``st`` is a flat int32 scratch array of the grid size filled with -1; it is restored.
    Returns node arrays (rep pixel, radius, degree, pixel CSR) and edge arrays (a, b, pixel CSR
    ordered from a to b). Pure cycles get one of their pixels as a node with a self-loop.
    """
    H, W = sk.shape
    n = px.size
    nb = np.empty(8, np.int64)
    nb2 = np.empty(8, np.int64)
    for k in range(n):
        i = px[k]
        r = i // W
        c = i - r * W
        st[i] = -2 if _mdeg(sk, r, c) == 2 else -4
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
            cnt = _mnbrs(sk, W, j, nb)
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
            cnt = _mnbrs(sk, W, u, nb)
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
                    c2 = _mnbrs(sk, W, cur, nb2)
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


@njit(cache=True)
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
    return alive, nn, new_a[:nn].copy(), new_b[:nn].copy(), new_off[: nn + 1].copy(), new_px[:p].copy()


@njit(cache=True)
def spur_pixels(W, node_rep, node_r, node_deg, node_off, node_px, ne, edge_a, edge_b, edge_off, edge_px, dcell, spur_ratio, min_depth_cells):
    """Pixels of the branches to prune: junction-to-endpoint edges that barely leave the junction disk.

    A branch protrudes ``|E - J| + d(E) - r_J`` beyond the junction's inscribed disk (E the end
    node, J the junction, d the clearance); it is pruned when that is below
    ``spur_ratio * r_J + min_depth_cells``.
    """
    dflat = dcell.ravel()
    out = np.empty(edge_px.size + node_px.size + 1, np.int64)
    n = 0
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
        dist = np.sqrt((rj - rt) ** 2 + (cj - ct) ** 2)
        protr = dist + dflat[node_rep[t]] - node_r[j]
        if protr < spur_ratio * node_r[j] + min_depth_cells:
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


@njit(cache=True)
def _uf_find(parent: np.ndarray, x: int) -> int:
    while parent[x] != x:
        parent[x] = parent[parent[x]]
        x = parent[x]
    return x


@njit(cache=True)
def _uf_union(parent: np.ndarray, a: int, b: int) -> None:
    ra = _uf_find(parent, a)
    rb = _uf_find(parent, b)
    if ra != rb:
        if ra < rb:
            parent[rb] = ra
        else:
            parent[ra] = rb


@njit(cache=True)
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


@njit(cache=True)
def _march(free, r0, c0, ur, uc, max_t, step):
    """Distance along (ur, uc) from point (r0, c0) to the first non-free sample (max_t + 1 if none)."""
    H, W = free.shape
    t = step
    while t <= max_t:
        r = int(np.floor(r0 + t * ur))
        c = int(np.floor(c0 + t * uc))
        if r < 0 or c < 0 or r >= H or c >= W or not free[r, c]:
            return t
        t += step
    return max_t + 1.0


@njit(cache=True)
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


@njit(cache=True)
def _chord(free, r, c, base, n_angles, max_angle, max_t, step):
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
        t1 = _march(free, pr, pc, ur, uc, max_t, step)
        if t1 >= best:
            continue
        t2 = _march(free, pr, pc, -ur, -uc, max_t, step)
        tot = t1 + t2
        if tot < best - 1e-9:
            best = tot
            bur = ur
            buc = uc
            bt1 = t1
            bt2 = t2
    return best, bur, buc, bt1, bt2


@njit(cache=True)
def _refine_opening(free, dflat, edge_px, lo, L, i0, lo_lim, hi_lim, W, max_angle, weight):
    """Index near ``i0`` in [lo_lim, hi_lim] minimising chord length + weight * offset."""
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
        ln = _chord(free, r, c, base, 2, max_angle, 4.0 * dflat[q] + 6.0, 0.5)[0]
        cost = ln + weight * abs(i - i0)
        if cost < best_cost - 1e-9:
            best_cost = cost
            best = i
    return best


@njit(cache=True)
def place_openings(W, n_nodes, node_rep, node_r, node_deg, ne, edge_a, edge_b, edge_off, edge_px, dcell, free, mouth_ratio, weight, min_path_px, max_angle):
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
            oa = _refine_opening(free, dflat, edge_px, lo, L, oa, exit_a, min(mid, ob - 2), W, max_angle, 0.25)
            ob = _refine_opening(free, dflat, edge_px, lo, L, ob, max(mid + 1, oa + 2), exit_b, W, max_angle, 0.25)
            open_a[e] = oa
            open_b[e] = ob
        elif ja:
            limit = L - 2
            if exit_a > limit:
                internal[e] = True
                continue
            oa = _best_opening(edge_px, lo, exit_a, limit, 1, dflat, W, weight)
            open_a[e] = _refine_opening(free, dflat, edge_px, lo, L, oa, exit_a, limit, W, max_angle, 0.25)
        elif jb:
            limit = 1
            if exit_b < limit:
                internal[e] = True
                continue
            ob = _best_opening(edge_px, lo, exit_b, limit, -1, dflat, W, weight)
            open_b[e] = _refine_opening(free, dflat, edge_px, lo, L, ob, limit, exit_b, W, max_angle, 0.25)
    return internal, open_a, open_b


@njit(cache=True)
def build_regions(n_nodes, alive, node_off, node_px, ne, edge_a, edge_b, edge_off, edge_px, internal, open_a, open_b, lab):
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
    return n_reg, region[:n_nodes].copy(), region[n_nodes:].copy(), op_px, op_edge, op_idx, op_core, op_far


# ----------------------------------------------------------------------------------------------
# Opening chords
# ----------------------------------------------------------------------------------------------


@njit(cache=True)
def opening_chords(free, dcell, op_px, op_edge, op_idx, edge_off, edge_px, barrier, n_angles, max_angle_rad):
    """Shortest wall-to-wall chord through each opening pixel, roughly across its edge.

    Marks the chord's free cells in ``barrier`` (value = opening index + 1) and returns the
    endpoints ``(n, 4)`` as (row0, col0, row1, col1) in fractional cell units (cell centre at
    +0.5) and the widths in cells.
    """
    H, W = free.shape
    n = op_px.size
    ends = np.empty((n, 4), np.float64)
    width = np.empty(n, np.float64)
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
        best, bur, buc, bt1, bt2 = _chord(free, r, c, base, n_angles, max_angle_rad, max_t, step)
        e1 = min(bt1, max_t) - step * 0.5
        e2 = min(bt2, max_t) - step * 0.5
        ends[k, 0] = pr + e1 * bur
        ends[k, 1] = pc + e1 * buc
        ends[k, 2] = pr - e2 * bur
        ends[k, 3] = pc - e2 * buc
        width[k] = e1 + e2
        t = -e2
        while t <= e1:
            rr = int(np.floor(pr + t * bur))
            cc = int(np.floor(pc + t * buc))
            if rr >= 0 and cc >= 0 and rr < H and cc < W and free[rr, cc]:
                barrier[rr * W + cc] = k + 1
            t += step
        barrier[i] = k + 1
    return ends, width


# ----------------------------------------------------------------------------------------------
# Region trees: skeleton BFS from region centres, then C-space, then the rest of free space
# ----------------------------------------------------------------------------------------------


@njit(cache=True)
def region_centres(px, lab, dcell, n_reg):
    """Per region, the skeleton pixel with the largest clearance (-1 if the region has none)."""
    dflat = dcell.ravel()
    best = np.full(n_reg, -1, np.int64)
    bd = np.full(n_reg, -1.0, np.float64)
    for k in range(px.size):
        i = px[k]
        g = lab[i]
        if g >= 0 and dflat[i] > bd[g]:
            bd[g] = dflat[i]
            best[g] = i
    return best


@njit(cache=True)
def grow_regions(W, sk, px, roots, lab, cspace, free, barrier, op_core, max_out_depth, parent, depth):
    """Label every reachable free cell with a region and build one shortest-path tree per region.

    1. BFS over each region's skeleton pixels (8-neighbours, same label) from its root.
    2. BFS from all skeleton pixels over C-space cells (4-neighbours), never crossing a chord.
    3. BFS from C-space over the other free cells, at most ``max_out_depth`` steps.
    Chord cells get the label of the opening's core region. ``parent``/``depth`` describe the
    trees (parent -1 at roots). Returns the number of labelled cells.
    """
    H = sk.shape[0]
    N = H * W
    n_free = 0
    for r in range(H):
        for c in range(W):
            if free[r, c]:
                n_free += 1
    q = np.empty(n_free + px.size + 1, np.int64)
    sk_flat = sk.ravel()
    cs_flat = cspace.ravel()
    fr_flat = free.ravel()
    head = 0
    tail = 0
    for g in range(roots.size):
        rt = roots[g]
        if rt >= 0:
            parent[rt] = -1
            depth[rt] = 0
            q[tail] = rt
            tail += 1
    # 1. skeleton trees (skeleton pixels carry their labels already; -1 marks opening pixels)
    seen = np.zeros(N, np.uint8)
    for t in range(tail):
        seen[q[t]] = 1
    while head < tail:
        i = q[head]
        head += 1
        g = lab[i]
        for dr in range(-1, 2):
            for dc in range(-1, 2):
                j = i + dr * W + dc
                if sk_flat[j] and seen[j] == 0 and lab[j] == g:
                    seen[j] = 1
                    parent[j] = i
                    depth[j] = depth[i] + 1
                    q[tail] = j
                    tail += 1
    # skeleton pixels not reached from a root (should not happen) become roots themselves
    for k in range(px.size):
        i = px[k]
        if lab[i] >= 0 and seen[i] == 0:
            seen[i] = 1
            parent[i] = -1
            depth[i] = 0
            q[tail] = i
            tail += 1
    # 2. C-space, seeded by all skeleton pixels
    head = 0
    n_lab = tail
    while head < tail:
        i = q[head]
        head += 1
        g = lab[i]
        for t in range(4):
            j = i + (W if t == 0 else (-W if t == 1 else (1 if t == 2 else -1)))
            if cs_flat[j] and lab[j] < 0 and barrier[j] == 0 and sk_flat[j] == 0:
                lab[j] = g
                parent[j] = i
                depth[j] = depth[i] + 1
                q[tail] = j
                tail += 1
    # 3. the rest of free space, depth-limited from C-space
    out_d = np.zeros(N, np.int32)
    head = 0
    while head < tail:
        i = q[head]
        head += 1
        g = lab[i]
        if out_d[i] >= max_out_depth:
            continue
        for t in range(4):
            j = i + (W if t == 0 else (-W if t == 1 else (1 if t == 2 else -1)))
            if fr_flat[j] and lab[j] < 0 and barrier[j] == 0:
                lab[j] = g
                parent[j] = i
                depth[j] = depth[i] + 1
                out_d[j] = out_d[i] + 1
                q[tail] = j
                tail += 1
    n_lab = tail
    # chord cells: the side of the opening's core region (only where the chord touches that region)
    for r in range(1, H - 1):
        for c in range(1, W - 1):
            i = r * W + c
            b = barrier[i]
            if b > 0 and fr_flat[i] and lab[i] < 0:
                g = op_core[b - 1]
                ok = False
                for t in range(4):
                    j = i + (W if t == 0 else (-W if t == 1 else (1 if t == 2 else -1)))
                    if lab[j] >= 0 and barrier[j] == 0:
                        ok = True
                if ok:
                    lab[i] = g
                    parent[i] = -1
                    depth[i] = 0
                    n_lab += 1
    return n_lab


@njit(cache=True)
def frontier_cells(W, work, lab):
    """Labelled free cells with an UNKNOWN 4-neighbour, clustered 8-connectedly.

    Returns (cells, cluster id per cell, outward row/col offset sums per cell).
    """
    H = work.shape[0]
    wf = work.ravel()
    n = 0
    for r in range(1, H - 1):
        for c in range(1, W - 1):
            i = r * W + c
            if lab[i] >= 0 and wf[i] == FREE_V:
                if wf[i + W] == UNKNOWN_V or wf[i - W] == UNKNOWN_V or wf[i + 1] == UNKNOWN_V or wf[i - 1] == UNKNOWN_V:
                    n += 1
    cells = np.empty(n, np.int64)
    orow = np.zeros(n, np.int64)
    ocol = np.zeros(n, np.int64)
    mark = np.full(H * W, -1, np.int32)
    n = 0
    for r in range(1, H - 1):
        for c in range(1, W - 1):
            i = r * W + c
            if lab[i] >= 0 and wf[i] == FREE_V:
                dr = 0
                dc = 0
                if wf[i + W] == UNKNOWN_V:
                    dr += 1
                if wf[i - W] == UNKNOWN_V:
                    dr -= 1
                if wf[i + 1] == UNKNOWN_V:
                    dc += 1
                if wf[i - 1] == UNKNOWN_V:
                    dc -= 1
                if wf[i + W] == UNKNOWN_V or wf[i - W] == UNKNOWN_V or wf[i + 1] == UNKNOWN_V or wf[i - 1] == UNKNOWN_V:
                    cells[n] = i
                    orow[n] = dr
                    ocol[n] = dc
                    mark[i] = n
                    n += 1
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
            i = cells[m]
            for dr in range(-1, 2):
                for dc in range(-1, 2):
                    j = i + dr * W + dc
                    mm = mark[j]
                    if mm >= 0 and cluster[mm] < 0:
                        cluster[mm] = n_cl
                        stack[top] = mm
                        top += 1
        n_cl += 1
    return cells, cluster, orow, ocol, n_cl


@njit(cache=True)
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


@njit(cache=True)
def chain_to_tree(parent, cspace_flat, cell, max_len):
    """Follow parents from ``cell`` until the first C-space cell; returns (anchor, ok)."""
    i = cell
    for _ in range(max_len):
        if cspace_flat[i]:
            return i, True
        p = parent[i]
        if p < 0:
            return i, bool(cspace_flat[i])
        i = p
    return i, False


@njit(cache=True)
def far_skeleton_pixel(W, sk, lab, start, label):
    """The skeleton pixel of region ``label`` farthest (in BFS steps) from ``start``."""
    H = sk.shape[0]
    sk_flat = sk.ravel()
    # small local BFS with a hash-free visited set: use a dictionary-free array over the bbox
    q = [start]
    seen = {start: 0}
    head = 0
    far = start
    while head < len(q):
        i = q[head]
        head += 1
        far = i
        for dr in range(-1, 2):
            for dc in range(-1, 2):
                j = i + dr * W + dc
                if j >= 0 and j < H * W and sk_flat[j] and lab[j] == label and j not in seen:
                    seen[j] = 1
                    q.append(j)
    return far


# ----------------------------------------------------------------------------------------------
# Paths
# ----------------------------------------------------------------------------------------------


@njit(cache=True)
def tree_paths(parent, depth, starts, ends, pre, post):
    """Tree path from ``starts[k]`` to ``ends[k]`` (through their lowest common ancestor).

    ``pre[k]`` / ``post[k]`` (>= 0) are cells prepended / appended. Returns flat cells + offsets;
    an empty path (different trees) yields just the end points.
    """
    n = starts.size
    off = np.zeros(n + 1, np.int64)
    total = 0
    for k in range(n):
        a = starts[k]
        b = ends[k]
        da = depth[a]
        db = depth[b]
        ln = 0
        while da > db:
            a = parent[a]
            da -= 1
            ln += 1
        while db > da:
            b = parent[b]
            db -= 1
            ln += 1
        while a != b and a >= 0 and b >= 0:
            a = parent[a]
            b = parent[b]
            ln += 2
        total += ln + 3
    out = np.empty(total, np.int64)
    tmp = np.empty(0, np.int64)
    p = 0
    for k in range(n):
        if pre[k] >= 0:
            out[p] = pre[k]
            p += 1
        a = starts[k]
        b = ends[k]
        da = depth[a]
        db = depth[b]
        # climb a to the LCA writing forward, climb b collecting backwards
        la = 0
        aa = a
        bb = b
        dda = da
        ddb = db
        while dda > ddb:
            aa = parent[aa]
            dda -= 1
        while ddb > dda:
            bb = parent[bb]
            ddb -= 1
        while aa != bb and aa >= 0 and bb >= 0:
            aa = parent[aa]
            bb = parent[bb]
        lca = aa if aa == bb else -1
        x = a
        while x != lca and x >= 0:
            out[p] = x
            p += 1
            la += 1
            x = parent[x]
        if lca >= 0:
            out[p] = lca
            p += 1
        # b side
        cnt = 0
        x = b
        while x != lca and x >= 0:
            cnt += 1
            x = parent[x]
        if tmp.size < cnt:
            tmp = np.empty(cnt * 2 + 4, np.int64)
        x = b
        m = 0
        while x != lca and x >= 0:
            tmp[m] = x
            m += 1
            x = parent[x]
        for t in range(m - 1, -1, -1):
            out[p] = tmp[t]
            p += 1
        if post[k] >= 0:
            out[p] = post[k]
            p += 1
        off[k + 1] = p
    return out[:p].copy(), off


@njit(cache=True)
def _line_ok(W, r0, c0, r1, c1, cs_flat, lab, barrier, region):
    dr = r1 - r0
    dc = c1 - c0
    n = max(abs(dr), abs(dc)) * 2
    if n == 0:
        return True
    for s in range(n + 1):
        rr = int(np.floor(r0 + 0.5 + dr * s / n))
        cc = int(np.floor(c0 + 0.5 + dc * s / n))
        i = rr * W + cc
        if not cs_flat[i]:
            return False
        if lab[i] != region and barrier[i] == 0:
            return False
    return True


@njit(cache=True)
def smooth_paths(W, cells, off, regions, cs_flat, lab, barrier, max_seg_cells, res_m):
    """Greedy line-of-sight shortcuts inside each path's region and C-space.

    Returns vertex cells (flat), offsets and lengths in metres. A path of one cell is doubled.
    """
    n = off.size - 1
    out = np.empty(cells.size + 2 * n, np.int64)
    ooff = np.zeros(n + 1, np.int64)
    lengths = np.zeros(n, np.float64)
    p = 0
    for k in range(n):
        lo = off[k]
        hi = off[k + 1]
        m = hi - lo
        if m == 0:
            ooff[k + 1] = p
            continue
        g = regions[k]
        out[p] = cells[lo]
        p += 1
        if m == 1:
            out[p] = cells[lo]
            p += 1
            ooff[k + 1] = p
            continue
        i = 0
        length = 0.0
        while i < m - 1:
            a = cells[lo + i]
            ar = a // W
            ac = a - ar * W
            j = i + 1
            while j + 1 < m:
                b = cells[lo + j + 1]
                br = b // W
                bc = b - br * W
                if max_seg_cells > 0 and (br - ar) ** 2 + (bc - ac) ** 2 > max_seg_cells * max_seg_cells:
                    break
                if not _line_ok(W, ar, ac, br, bc, cs_flat, lab, barrier, g):
                    break
                j += 1
            b = cells[lo + j]
            br = b // W
            bc = b - br * W
            length += np.sqrt((br - ar) ** 2 + (bc - ac) ** 2)
            out[p] = b
            p += 1
            i = j
        lengths[k] = length * res_m
        ooff[k + 1] = p
    return out[:p].copy(), ooff, lengths
