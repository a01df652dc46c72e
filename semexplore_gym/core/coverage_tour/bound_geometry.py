"""Geometry the certified bounds share: walls merged into maximal segments, the corners where
two of them meet, and the mask's cells grouped by the blocks of a lattice."""

from __future__ import annotations

import numpy as np

from semexplore_gym.core.grid import GridGeometry


def merge_walls(segments_m: np.ndarray, tol_m: float = 1e-9) -> np.ndarray:
    """Collinear walls that touch or overlap, merged into maximal segments ``(M, 4)``."""
    seg = np.asarray(segments_m, dtype=np.float64).reshape(-1, 4)
    d = seg[:, 2:] - seg[:, :2]
    length = np.hypot(d[:, 0], d[:, 1])
    keep = length > 0
    seg, d, length = seg[keep], d[keep], length[keep]
    u = d / length[:, None]
    flip = (u[:, 0] < -1e-12) | ((np.abs(u[:, 0]) <= 1e-12) & (u[:, 1] < 0))
    u[flip] *= -1.0
    offset = seg[:, 0] * -u[:, 1] + seg[:, 1] * u[:, 0]
    key = np.round(np.column_stack([u[:, 0], u[:, 1], offset]) * 1e9).astype(np.int64)
    out: list[np.ndarray] = []
    _, inverse = np.unique(key, axis=0, return_inverse=True)
    for g in np.unique(inverse):
        idx = np.flatnonzero(inverse == g)
        ug = u[idx[0]]
        base = seg[idx[0], :2]
        s0 = (seg[idx, :2] - base) @ ug
        s1 = (seg[idx, 2:] - base) @ ug
        lo, hi = np.minimum(s0, s1), np.maximum(s0, s1)
        order = np.argsort(lo)
        cur_lo, cur_hi = lo[order[0]], hi[order[0]]
        for i in order[1:]:
            if lo[i] <= cur_hi + tol_m:
                cur_hi = max(cur_hi, hi[i])
            else:
                out.append(np.concatenate([base + cur_lo * ug, base + cur_hi * ug]))
                cur_lo, cur_hi = lo[i], hi[i]
        out.append(np.concatenate([base + cur_lo * ug, base + cur_hi * ug]))
    return np.array(out, dtype=np.float64).reshape(-1, 4)


def wall_corners(segments_m: np.ndarray, walls: np.ndarray, tol_m: float = 1e-9) -> np.ndarray:
    """Where two merged ``walls`` (:func:`merge_walls` of ``segments_m``) that are not collinear
    both end at one point that ends two of the env's own segments exactly (the same floats:
    its ray cast then counts a beam through the point as a hit on one of them). One row per
    pair: ``vx, vy``, then for each wall its unit direction from the point and its length
    ``(K, 8)``."""
    seg = np.asarray(segments_m, dtype=np.float64).reshape(-1, 4)
    ends = np.concatenate([seg[:, :2], seg[:, 2:]])
    points, counts = np.unique(ends, axis=0, return_counts=True)
    shared = points[counts >= 2]
    w = np.asarray(walls, dtype=np.float64).reshape(-1, 4)
    rows: list[list[float]] = []
    for vx, vy in shared:
        legs = []
        for a, b in ((w[:, :2], w[:, 2:]), (w[:, 2:], w[:, :2])):
            at = np.flatnonzero(np.hypot(a[:, 0] - vx, a[:, 1] - vy) <= tol_m)
            for i in at:
                d = b[i] - (vx, vy)
                length = float(np.hypot(*d))
                if length > 0:
                    legs.append((*(d / length), length))
        for i in range(len(legs)):
            for j in range(i + 1, len(legs)):
                (ax, ay, la), (bx, by, lb) = legs[i], legs[j]
                if abs(ax * by - ay * bx) > 1e-9:
                    rows.append([vx, vy, ax, ay, la, bx, by, lb])
    return np.array(rows, dtype=np.float64).reshape(-1, 8)


def mask_groups(
    mask: np.ndarray, geometry: GridGeometry, block_cells: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The mask cells of each ``block_cells`` lattice block: ``(rects, cells, centres)``:
    the bounding rectangle ``x0, y0, x1, y1`` of each non-empty group, its cell count and the
    centre of its block."""
    b = max(1, int(block_cells))
    rows, cols = np.nonzero(mask)
    block = (rows // b) * (-(-mask.shape[1] // b)) + cols // b
    ids, inverse, cells = np.unique(block, return_inverse=True, return_counts=True)
    n = ids.size
    rmin = np.full(n, np.iinfo(np.int64).max)
    rmax = np.full(n, -1)
    cmin = np.full(n, np.iinfo(np.int64).max)
    cmax = np.full(n, -1)
    np.minimum.at(rmin, inverse, rows)
    np.maximum.at(rmax, inverse, rows)
    np.minimum.at(cmin, inverse, cols)
    np.maximum.at(cmax, inverse, cols)
    h, x0, y0 = geometry.resolution_m, geometry.origin_x_m, geometry.origin_y_m
    rects = np.column_stack(
        [x0 + cmin * h, y0 + rmin * h, x0 + (cmax + 1) * h, y0 + (rmax + 1) * h]
    )
    nb = -(-mask.shape[1] // b)
    br, bc = ids // nb, ids % nb
    centres = np.column_stack([x0 + (bc + 0.5) * b * h, y0 + (br + 0.5) * b * h])
    return rects.astype(np.float64), cells.astype(np.int64), centres


def group_parents(mask: np.ndarray, block_cells: int) -> np.ndarray:
    """For each group of :func:`mask_groups` with ``block_cells``, the index of the group of
    ``2 * block_cells`` blocks that holds it (the lattices nest: a block lies in one block of
    twice the side, and so do its mask cells)."""
    b = max(1, int(block_cells))
    rows, cols = np.nonzero(mask)
    small = (rows // b) * (-(-mask.shape[1] // b)) + cols // b
    big = (rows // (2 * b)) * (-(-mask.shape[1] // (2 * b))) + cols // (2 * b)
    _, first = np.unique(small, return_index=True)
    return np.searchsorted(np.unique(big), big[first]).astype(np.int64)
