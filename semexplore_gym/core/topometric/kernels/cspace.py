"""Stage 2 of the segmentation, configuration space: the clearance of every cell.

:func:`clearance_field` is an exact Euclidean distance transform (Felzenszwalb & Huttenlocher)
to the nearest non-free cell (outside the array counts as blocked). It also marks the
configuration space ``C`` (cells with at least the robot's clearance) and lists its cells.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from semexplore_gym.core.grid import FREE


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
        g[0, c] = 1.0 if work[0, c] == FREE else 0.0
    for r in range(1, H):
        for c in range(W):
            g[r, c] = g[r - 1, c] + 1.0 if work[r, c] == FREE else 0.0
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
        n_free += wf[i] == FREE
    n_c = 0
    f = np.empty(W + 2, np.float64)
    v = np.empty(W + 2, np.int64)
    z = np.empty(W + 3, np.float64)
    for r in range(H):
        row = work[r]
        grow = g[r]
        c = 0
        while c < W:
            if row[c] != FREE:
                grow[
                    c
                ] = -1.0  # no clearance test can accept a blocked cell, even with zero clearance
                c += 1
                continue
            a = c
            while c < W and row[c] == FREE:
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
