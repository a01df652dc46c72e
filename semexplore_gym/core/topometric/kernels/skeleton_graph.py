"""Stage 3 of the segmentation, continued: the skeleton read as a graph.

Nodes are junction blobs and end points, edges the pixel chains between them under
m-adjacency (:func:`extract_graph`); nodes of degree 2 are spliced into their edges
(:func:`splice_pass_nodes`). :func:`skeleton_graph` does both and is called by every pruning
round and once more for the final skeleton.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from semexplore_gym.core.topometric.kernels.skeleton import m_degree


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
        st[px[k]] = -2 if m_degree(skf, W, px[k]) == 2 else -4
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
