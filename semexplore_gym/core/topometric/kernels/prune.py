"""Stage 4 of the segmentation, pruning: spurs off the skeleton graph.

:func:`spur_pixels` finds the branches from a junction to an end that protrude too little
beyond the junction's inscribed circle and have no corridor stretch (:func:`_has_plateau`);
:func:`remove_pixels` deletes them and re-thins the skeleton where they met it.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from semexplore_gym.core.topometric.kernels.skeleton import reduce_blobs, zhang_suen_tables


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


@njit(cache=True, error_model="numpy")
def remove_pixels(sk, px, gone):
    """Clear the pixels ``gone`` of the skeleton ``sk`` and reduce junction blobs again;
    returns the remaining skeleton pixels (sorted, as ``px``)."""
    f = sk.ravel()
    for k in range(gone.size):
        f[gone[k]] = 0
    return reduce_blobs(sk, px, zhang_suen_tables()[2])  # skips and drops the cleared pixels
