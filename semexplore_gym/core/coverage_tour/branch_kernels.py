"""Compiled parts of :mod:`.branch_bound`: the merge tree of the distance's superlevel sets and
the level at which a set of cells first lies in one of its branches."""

from __future__ import annotations

import numpy as np
from numba import njit

from semexplore_gym.core.coverage_tour.lower_bound_kernels import (
    box_blind,
    box_corners,
    cells_within,
    corners_near,
    unpack_frame,
    wall_blocks,
    walls_near,
)
from semexplore_gym.core.coverage_tour.sight_kernels import (
    SIGHT_BUCKETS,
    sees_clearly,
    sight_table,
    umbra_hints,
)


@njit(cache=True)
def _find(parent, v):  # pragma: no cover - numba
    root = v
    while parent[root] != root:
        root = parent[root]
    while parent[v] != root:
        nxt = parent[v]
        parent[v] = root
        v = nxt
    return root


@njit(cache=True)
def merge_tree(moves, level):  # pragma: no cover - numba
    """The merge tree of the superlevel sets ``{level >= t}`` over the cells of ``moves``.

    ``moves``: the coarse grid's move bits (bit ``3 * (dr + 1) + dc + 1`` for a move by
    ``(dr, dc)``, bit 4 for a cell that holds an allowed cell); ``level``: each cell's value
    (flat; inf where unreachable, never part of the tree). Cells are added from the highest
    value down; a cell joins the components of its neighbours already added. Leaves ``0..n-1``
    are the cells in ``cells`` order; each join adds a node at the level of the cell that made
    it. Returns ``(cells, node_of_cell, parent, node_level)``; a root's parent is itself.
    """
    hc, wc = moves.shape
    flat_moves = moves.reshape(-1)
    total = hc * wc
    take = np.zeros(total, dtype=np.bool_)
    n = 0
    for i in range(total):
        if (flat_moves[i] >> 4) & 1 and np.isfinite(level[i]):
            take[i] = True
            n += 1
    cells = np.empty(n, dtype=np.int64)
    k = 0
    for i in range(total):
        if take[i]:
            cells[k] = i
            k += 1
    order = np.argsort(-level[cells], kind="mergesort")
    node_of_cell = np.full(total, -1, dtype=np.int64)
    for j in range(n):
        node_of_cell[cells[j]] = j
    size = max(1, 2 * n - 1)
    parent = np.arange(size)
    node_level = np.empty(size)
    for j in range(n):
        node_level[j] = level[cells[j]]
    uf = np.arange(size)  # union-find over tree nodes: each set's representative is its top
    added = np.zeros(total, dtype=np.bool_)
    nxt = n
    for oi in range(n):
        j = order[oi]
        v = cells[j]
        lv = level[v]
        added[v] = True
        r, c = divmod(v, wc)
        bits = flat_moves[v]
        for dr in range(-1, 2):
            for dc in range(-1, 2):
                if dr == 0 and dc == 0:
                    continue
                if not (bits >> (3 * (dr + 1) + dc + 1)) & 1:
                    continue
                r2 = r + dr
                c2 = c + dc
                if r2 < 0 or r2 >= hc or c2 < 0 or c2 >= wc:
                    continue
                u = r2 * wc + c2
                if not added[u]:
                    continue
                a = _find(uf, node_of_cell[u])
                b = _find(uf, j)
                if a == b:
                    continue
                parent[a] = nxt
                parent[b] = nxt
                node_level[nxt] = lv
                uf[a] = nxt
                uf[b] = nxt
                nxt += 1
    return cells, node_of_cell, parent[:nxt], node_level[:nxt]


@njit(cache=True)
def preorder(parent):  # pragma: no cover - numba
    """Each node's number in a depth-first preorder of the forest and its subtree's size: ``u``
    is an ancestor of ``v`` (or ``v`` itself) iff ``tin[u] <= tin[v] < tin[u] + size[u]``.
    A parent's index is above its children's (as :func:`merge_tree` builds them)."""
    m = parent.size
    size = np.ones(m, dtype=np.int64)
    for v in range(m):  # children before parents
        if parent[v] != v:
            size[parent[v]] += size[v]
    tin = np.empty(m, dtype=np.int64)
    nxt = np.empty(m, dtype=np.int64)
    offset = 0
    for v in range(m - 1, -1, -1):  # parents before children
        p = parent[v]
        if p == v:
            tin[v] = offset
            offset += size[v]
        else:
            tin[v] = nxt[p]
            nxt[p] += size[v]
        nxt[v] = tin[v] + 1
    return tin, size


@njit(cache=True)
def set_levels(parent, node_level, region_nodes, region_start):  # pragma: no cover - numba
    """For each set of leaves (``region_nodes[region_start[g]:region_start[g + 1]]``; negative
    entries, cells outside the tree, are passed over), the lowest common ancestor of its leaves
    and that node's level: the highest ``t`` at which all of them lie in one component of
    ``{level >= t}``; ``-1`` and ``-inf`` for an empty set or leaves in different trees.

    The common ancestor of a set is that of its first and last leaf in preorder, found by
    binary lifting; a set costs one pass over its leaves and one pair's ancestor search."""
    m = parent.size
    tin, size = preorder(parent)
    levels = 1
    while (1 << levels) < m + 1:
        levels += 1
    up = np.empty((levels, m), dtype=np.int64)
    for v in range(m):
        up[0, v] = parent[v]
    for k in range(1, levels):
        for v in range(m):
            up[k, v] = up[k - 1, up[k - 1, v]]
    n_sets = region_start.size - 1
    lca = np.full(n_sets, -1, dtype=np.int64)
    out = np.full(n_sets, -np.inf)
    for g in range(n_sets):
        lo = -1
        hi = -1
        for i in range(region_start[g], region_start[g + 1]):
            b = region_nodes[i]
            if b < 0:
                continue
            if lo < 0 or tin[b] < tin[lo]:
                lo = b
            if hi < 0 or tin[b] > tin[hi]:
                hi = b
        if lo < 0:
            continue
        x = lo
        if not (tin[x] <= tin[hi] < tin[x] + size[x]):
            for k in range(levels - 1, -1, -1):
                y = up[k, x]
                if not (tin[y] <= tin[hi] < tin[y] + size[y]):
                    x = y
            x = parent[x]
            if not (tin[x] <= tin[hi] < tin[x] + size[x]):  # different trees
                continue
        lca[g] = x
        out[g] = node_level[x]
    return lca, out


@njit(cache=True)
def region_extremes(blocks, block_start, factor, allowed, node_of, tin):  # pragma: no cover
    """Each region (the coarse blocks ``blocks[block_start[g]:block_start[g + 1]]``, each
    ``factor`` x ``factor`` cells of ``allowed``) as the cells the robot's centre may be in:
    their count, whether one lies outside the tree (``node_of`` negative), and its first and
    last tree node in preorder (``tin``; -1 when it has none)."""
    height, width = allowed.shape
    wide = -(-width // factor)
    n = block_start.size - 1
    count = np.zeros(n, dtype=np.int64)
    bad = np.zeros(n, dtype=np.bool_)
    ends = np.full(2 * n, -1, dtype=np.int64)
    for g in range(n):
        lo = -1
        hi = -1
        for i in range(block_start[g], block_start[g + 1]):
            br, bc = divmod(blocks[i], wide)
            for r in range(br * factor, min(br * factor + factor, height)):
                for c in range(bc * factor, min(bc * factor + factor, width)):
                    if not allowed[r, c]:
                        continue
                    count[g] += 1
                    v = node_of[r * width + c]
                    if v < 0:
                        bad[g] = True
                        continue
                    if lo < 0 or tin[v] < tin[lo]:
                        lo = v
                    if hi < 0 or tin[v] > tin[hi]:
                        hi = v
        ends[2 * g] = lo
        ends[2 * g + 1] = hi
    return count, bad, ends


@njit(cache=True, nogil=True)
def coarse_region(allowed, factor, rect, walls, frame, corners):  # pragma: no cover - numba
    """Flat indices of the coarse cells (``factor`` x ``factor`` blocks of ``allowed``) not
    certainly blind to ``rect`` (``x0, y0, x1, y1``), in increasing order: the bounding box of
    the block's allowed map cells, widened by ``widen_m``, tested as
    :func:`.lower_bound_kernels.group_region` tests one map cell's square (so a superset of the
    coarse cells of that region): within reach, and not proven blind by
    :func:`.lower_bound_kernels.box_blind`. Umbras and sight tables
    (:mod:`.sight_kernels`) decide most blocks sooner with the same answer. With more than
    ``max_walls`` walls near ``rect`` (a map traced from a raster), every block within reach is
    in, untested (a superset; the tests would cost walls x blocks). ``frame``: ``gx0, gy0, res
    (map), reach_m, widen_m, tol, depth, max_walls``."""
    gx0, gy0, res, reach_m, widen_m, _, _, _ = unpack_frame(frame)
    f = factor
    h = -(-allowed.shape[0] // f)
    w = -(-allowed.shape[1] // f)
    c_lo, c_hi, r_lo, r_hi = cells_within(rect, reach_m + widen_m, gx0, gy0, res * f, h, w)
    candidates = np.empty((r_hi - r_lo + 1) * (c_hi - c_lo + 1), dtype=np.int64)
    k = 0
    for r in range(r_lo, r_hi + 1):
        for c in range(c_lo, c_hi + 1):
            candidates[k] = r * w + c
            k += 1
    return coarse_region_among(allowed, factor, rect, walls, frame, candidates[:k], corners)


@njit(cache=True, nogil=True)
def coarse_region_among(
    allowed, factor, rect, walls, frame, candidates, corners
):  # pragma: no cover - numba
    """:func:`coarse_region`'s test of the coarse cells ``candidates`` (flat indices) only: the
    region within a known superset of it (a larger rectangle's region holds a smaller one's:
    every segment to the smaller is one to the larger)."""
    gx0, gy0, res, reach_m, widen_m, tol, depth, max_walls = unpack_frame(frame)
    f = factor
    hm, wm = allowed.shape
    h = -(-hm // f)
    w = -(-wm // f)
    c_lo, c_hi, r_lo, r_hi = cells_within(rect, reach_m + widen_m, gx0, gy0, res * f, h, w)
    rows = r_hi - r_lo + 1
    cols = c_hi - c_lo + 1
    near, m = walls_near(walls, rect, reach_m + widen_m)
    close = corners_near(corners, rect, reach_m + widen_m)
    cell = (res * f) / f  # the map cell, rounded as the coarse side divided (as before)
    # the window's blocks: the candidates among them with allowed cells within reach
    live = np.zeros((rows, cols), dtype=np.bool_)
    boxes = np.empty((rows, cols, 4))
    for flat in candidates:
        r, c = divmod(flat, w)
        if r < r_lo or r > r_hi or c < c_lo or c > c_hi:
            continue  # beyond reach (the window holds every block within it)
        r0 = r * f
        c0 = c * f
        lo_r = f
        hi_r = -1
        lo_c = f
        hi_c = -1
        for i in range(f):
            for j in range(f):
                if r0 + i < hm and c0 + j < wm and allowed[r0 + i, c0 + j]:
                    lo_r = min(lo_r, i)
                    hi_r = max(hi_r, i)
                    lo_c = min(lo_c, j)
                    hi_c = max(hi_c, j)
        if hi_r < 0:
            continue
        y0 = gy0 + (r0 + lo_r) * cell - widen_m
        y1 = gy0 + (r0 + hi_r + 1) * cell + widen_m
        gap_y = max(0.0, max(rect[1] - y1, y0 - rect[3]))
        x0 = gx0 + (c0 + lo_c) * cell - widen_m
        x1 = gx0 + (c0 + hi_c + 1) * cell + widen_m
        gap_x = max(0.0, max(rect[0] - x1, x0 - rect[2]))
        if gap_x * gap_x + gap_y * gap_y > reach_m * reach_m:
            continue
        i = r - r_lo
        j = c - c_lo
        live[i, j] = True
        boxes[i, j, 0] = x0
        boxes[i, j, 1] = y0
        boxes[i, j, 2] = x1
        boxes[i, j, 3] = y1
    out = np.empty(rows * cols, dtype=np.int64)
    count = 0
    if m > max_walls:
        for i in range(rows):
            for j in range(cols):
                if live[i, j]:
                    out[count] = (r_lo + i) * w + c_lo + j
                    count += 1
        return out[:count].copy()
    hint = np.full((rows, cols), -1, dtype=np.int64)
    window = np.array([gx0 + c_lo * res * f, gy0 + r_lo * res * f, res * f])
    umbra_hints(walls, near, m, rect, tol, window, boxes, live, hint)
    # sight tables from the rectangle's centre and (lazily) its corners, 2 mm in
    inset = min(2e-3, 0.25 * min(rect[2] - rect[0], rect[3] - rect[1]))
    sx = np.array([0.5 * (rect[0] + rect[2]), rect[0] + inset, rect[2] - inset])
    sy = np.array([0.5 * (rect[1] + rect[3]), rect[1] + inset, rect[3] - inset])
    tables = np.empty((5, SIGHT_BUCKETS))
    built = np.zeros(5, dtype=np.bool_)
    sight_table(walls, near, m, sx[0], sy[0], tables[0])
    built[0] = True
    margin = 4.0 * tol
    work = np.empty((6, 4))
    fa = np.empty(4)
    fu = np.empty(4)
    ux = np.empty(4)
    uy = np.empty(4)
    ax = np.empty(4)
    ay = np.empty(4)
    box_corners(rect[0], rect[1], rect[2], rect[3], ax, ay)
    last = 0
    for i in range(rows):
        for j in range(cols):
            if not live[i, j]:
                continue
            x0 = boxes[i, j, 0]
            y0 = boxes[i, j, 1]
            x1 = boxes[i, j, 2]
            y1 = boxes[i, j, 3]
            p = hint[i, j]
            if p >= 0:  # box_blind's own first proof, with the wall it would find
                box_corners(x0, y0, x1, y1, ux, uy)
                if wall_blocks(walls, near[p], ax, ay, ux, uy, tol, fa, fu):
                    continue
            px = 0.5 * (x0 + x1)
            py = 0.5 * (y0 + y1)
            seen = sees_clearly(tables[0], sx[0], sy[0], px, py, reach_m, margin)
            for k in range(1, 5):  # the corners' tables, from the box's centre and corners
                if seen:
                    break
                kx = sx[1] if k == 1 or k == 4 else sx[2]
                ky = sy[1] if k <= 2 else sy[2]
                if not built[k]:
                    sight_table(walls, near, m, kx, ky, tables[k])
                    built[k] = True
                for e in range(5):
                    ex = px if e == 0 else (x0 + inset if e == 1 or e == 4 else x1 - inset)
                    ey = py if e == 0 else (y0 + inset if e <= 2 else y1 - inset)
                    if sees_clearly(tables[k], kx, ky, ex, ey, reach_m, margin):
                        seen = True
                        break
            if not seen:
                box = (x0, y0, x1, y1)
                blind, last = box_blind(
                    walls, near, m, last, rect, box, reach_m, depth, tol, work, close
                )
                seen = not blind
            if seen:
                out[count] = (r_lo + i) * w + c_lo + j
                count += 1
    return out[:count].copy()


@njit(cache=True)
def _merge_min_plus(f, g, out):  # pragma: no cover - numba
    """``out[b] = min over b1 <= b of f[b1] + g[b - b1]`` (both non-increasing in ``b``)."""
    n = f.size
    for b in range(n):
        best = np.inf
        for b1 in range(b + 1):
            v = f[b1] + g[b - b1]
            if v < best:
                best = v
        out[b] = best


@njit(cache=True)
def branch_route(parent, edge_m, skip_weight, budget, leaf_m=0.0):  # pragma: no cover - numba
    """The least ``2 * sum(edge_m[E]) - sum(edge_m[end path]) - leaf_m * (leaves(E) - 1)`` over
    the node sets ``E`` a walk from the root can enter (closed under parents, the root always
    in) whose skipped subtrees (the nodes out of ``E`` whose parent is in it) weigh at most
    ``budget`` in all (``skip_weight[w]``: the weight of ``w``'s subtree), the walk ending in
    one node of ``E``; ``leaves(E)``: the nodes of ``E`` but the root with no child in ``E``
    (0 when ``E`` is the root alone: no allowance then).

    ``parent``: each node's parent, above its own index (the last node the root, its own
    parent). Exact (a knapsack over the tree, min-plus merges of each child's table)."""
    m = parent.size
    nb = budget + 1
    skip = np.full((m, nb), np.inf)  # this subtree skipped
    dp0 = np.full((m, nb), np.inf)  # entered, the walk ends outside it
    dp1 = np.full((m, nb), np.inf)  # entered, the walk ends inside it
    a0 = np.zeros((m, nb))  # the children merged so far, all skipped
    x0 = np.full((m, nb), np.inf)  # ... one entered at least, all ending outside
    x1 = np.full((m, nb), np.inf)  # ... one of them holding the end
    t = np.empty((5, nb))
    for w in range(m):
        e = edge_m[w]
        for b in range(nb):
            if a0[w, b] < np.inf:  # every child skipped: a leaf of E
                leaf = a0[w, b] - leaf_m
            else:
                leaf = np.inf
            dp0[w, b] = 2.0 * e + min(x0[w, b], leaf)
            dp1[w, b] = e + min(x0[w, b], x1[w, b], leaf)
            if b >= skip_weight[w]:
                skip[w, b] = 0.0
        p = parent[w]
        if p == w:
            continue
        out0 = np.minimum(skip[w], dp0[w])  # the child skipped or entered, the end elsewhere
        _merge_min_plus(a0[p], skip[w], t[0])
        _merge_min_plus(x0[p], out0, t[1])
        _merge_min_plus(a0[p], dp0[w], t[2])
        _merge_min_plus(x1[p], out0, t[3])
        _merge_min_plus(np.minimum(a0[p], x0[p]), dp1[w], t[4])
        for b in range(nb):
            a0[p, b] = t[0, b]
            x0[p, b] = min(t[1, b], t[2, b])
            x1[p, b] = min(t[3, b], t[4, b])
    root = m - 1
    # every set but the root alone has a leaf, whose allowance is given back (the first is free)
    return min(a0[root, budget], min(x0[root, budget], x1[root, budget]) + leaf_m)
