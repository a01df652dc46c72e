"""Stage 6 of the segmentation, regions: the skeleton cut at the openings, grown over free space.

:func:`build_regions` cuts the skeleton graph at the openings (union-find over nodes and edge
pieces) and labels its pixels; :func:`region_centres` picks each region's centre;
:func:`grow_regions` grows the regions from the skeleton over ``C`` and then over the rest of
free space within the cover depth, never across an opening chord, and builds one shortest-path
tree per region. :func:`window_labels` writes the final area ids of the work grid's window of the map.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from semexplore_gym.core.grid import FREE


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
            while b > 0 and wrow[b - 1] != FREE:
                b -= 1
            if b == 0:
                break
            a = b - 1
            while a > 0 and wrow[a - 1] == FREE:
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
            if lab[j] == -1 and w_flat[j] == FREE:
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
def window_labels(lab, lut, W, ra, rb, ca, cb):
    """Final area ids of the work-grid window rows ``ra:rb``, columns ``ca:cb``:
    ``lut[lab[r * W + c]]`` for labelled cells, -1 elsewhere, as an ``(rb - ra, cb - ca)`` int32
    array (the part of the map's raster that is not all -1)."""
    out = np.empty((max(rb - ra, 0), max(cb - ca, 0)), dtype=np.int32)
    for r in range(ra, rb):
        orow = out[r - ra]
        base = r * W
        for c in range(ca, cb):
            g = lab[base + c]
            orow[c - ca] = lut[g] if g >= 0 else -1
    return out
