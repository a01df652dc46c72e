"""Stage 3 of the segmentation, skeleton: thinning the configuration space to one pixel.

:func:`thin` is Zhang-Suen thinning with a work list; :func:`reduce_blobs` then removes the
simple points left in 2x2 blobs so that the skeleton is one pixel wide under m-adjacency
(:func:`m_degree`). Pruning (:mod:`.prune`) reuses both after it removes spurs. The skeleton is
read as a graph in :mod:`.skeleton_graph`.
"""

from __future__ import annotations

import numpy as np
from numba import njit


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
def m_degree(f: np.ndarray, W: int, i: int) -> int:
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

    ``simple`` is row 2 of :func:`zhang_suen_tables` (simple point by neighbour code).
    """
    H, W = img.shape
    f = img.ravel()
    changed = True
    while changed:
        changed = False
        for k in range(px.size):
            i = px[k]
            if f[i] and m_degree(f, W, i) >= 3 and simple[_code(f, i, W)]:
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
def zhang_suen_tables() -> np.ndarray:
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
    tab = zhang_suen_tables()
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
