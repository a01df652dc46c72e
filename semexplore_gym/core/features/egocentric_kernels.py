"""Numba kernels of the egocentric observation (:class:`~.egocentric.EgocentricEncoder`).

Every kernel samples the map rotated heading-up round the robot on the same lattice: crop row
0 lies farthest ahead of the robot, crop column 0 farthest to its left, and the robot sits at
the centre of the crop.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from semexplore_gym.core.grid import FREE, UNKNOWN


@njit(cache=True)
def crop_kernel(
    grid, x_cells, y_cells, cos_y, sin_y, cells_per_crop_cell, k, out, fill
):  # pragma: no cover
    """Fill ``out`` (c, c) with the min over k x k samples per crop cell of the rotated map.

    Crop row 0 lies farthest ahead of the robot and crop column 0 farthest to its left; the
    robot sits at the centre of the crop. Samples outside the map read as ``fill``.
    """
    c = out.shape[0]
    n = c * k
    h, w = grid.shape
    step = cells_per_crop_cell / k
    centre = (n - 1) / 2.0
    # Fine sample (u, v) sits centre-u steps ahead and centre-v steps left of the robot; walk
    # the lattice by increments instead of recomputing the rotation per sample.
    du_x, du_y = -step * cos_y, -step * sin_y
    dv_x, dv_y = step * sin_y, -step * cos_y
    x00 = x_cells + centre * step * cos_y - centre * step * sin_y
    y00 = y_cells + centre * step * sin_y + centre * step * cos_y
    out[:, :] = 255
    for u in range(n):
        xs = x00 + u * du_x
        ys = y00 + u * du_y
        i = u // k
        for v in range(n):
            xf = xs + v * dv_x
            yf = ys + v * dv_y
            if xf >= 0.0 and yf >= 0.0 and xf < w and yf < h:
                val = grid[int(yf), int(xf)]
            else:
                val = fill
            j = v // k
            if val < out[i, j]:
                out[i, j] = val


@njit(cache=True)
def stamp_disc(trail, r0, c0, radius_cells):  # pragma: no cover - numba
    h, w = trail.shape
    rad = int(math.ceil(radius_cells))
    for dr in range(-rad, rad + 1):
        for dc in range(-rad, rad + 1):
            if dr * dr + dc * dc <= radius_cells * radius_cells + 1e-9:
                r, c = r0 + dr, c0 + dc
                if 0 <= r < h and 0 <= c < w:
                    trail[r, c] = 0


@njit(cache=True)
def robot_distance(dp, wp, h, w, row, col):  # pragma: no cover - numba
    """Frontier distance of the robot's cell ``(row, col)`` in the padded flat field ``dp``.

    The cell's own when in the map and finite, else the smallest finite one in the 5 x 5 window
    round it (clipped to the map), else 0: as :func:`relative_distance_image`.
    """
    if 0 <= row < h and 0 <= col < w:
        d = dp[(row + 1) * wp + col + 1]
        if d < np.inf:
            return d
    best = np.inf
    for r in range(max(0, row - 2), min(h, max(0, row + 3))):
        for c in range(max(0, col - 2), min(w, max(0, col + 3))):
            d = dp[(r + 1) * wp + c + 1]
            if d < best:
                best = d
    return best if best < np.inf else 0.0


@njit(cache=True)
def encode_kernel(
    grid,
    dp,
    wp,
    trail,
    x_cells,
    y_cells,
    cos_y,
    sin_y,
    cells_per_crop_cell,
    k,
    ch_occ,
    ch_fd,
    ch_trail,
    trail_radius_cells,
    scale,
    scan,
    max_range,
    shift,
    image,
    pooled,
    features,
):  # pragma: no cover - numba
    """One egocentric observation: stamp the trail, crop every channel, pool the scan.

    The crops sample the rotated map exactly as :func:`crop_kernel` does (same lattice, same
    floating-point operations, min over ``k`` x ``k`` samples per crop cell), reading the map,
    the frontier field ``dp`` (padded flat, row stride ``wp``) and the trail at each sample
    once. The frontier channel takes the minimum *distance* per crop cell and maps it to grey
    levels afterwards: the mapping is non-decreasing (255 for ``inf`` above every finite level),
    so this equals the minimum of the mapped map-frame layer. A channel index < 0 skips it.
    """
    h, w = grid.shape
    row = int(math.floor(y_cells))
    col = int(math.floor(x_cells))
    if ch_trail >= 0:
        stamp_disc(trail, row, col, trail_radius_cells)
    d_robot = robot_distance(dp, wp, h, w, row, col) if ch_fd >= 0 else 0.0
    c = image.shape[1]
    n = c * k
    step = cells_per_crop_cell / k
    centre = (n - 1) / 2.0
    du_x, du_y = -step * cos_y, -step * sin_y
    dv_x, dv_y = step * sin_y, -step * cos_y
    x00 = x_cells + centre * step * cos_y - centre * step * sin_y
    y00 = y_cells + centre * step * sin_y + centre * step * cos_y
    unknown = np.uint8(UNKNOWN)
    n_known = 0
    n_free = 0
    for i in range(c):
        for j in range(c):
            occ = np.uint8(255)
            tr = np.uint8(255)
            dmin = np.inf
            for a in range(k):
                u = i * k + a
                xs = x00 + u * du_x
                ys = y00 + u * du_y
                for b in range(k):
                    v = j * k + b
                    xf = xs + v * dv_x
                    yf = ys + v * dv_y
                    if xf >= 0.0 and yf >= 0.0 and xf < w and yf < h:
                        r = int(yf)
                        cc = int(xf)
                        g = grid[r, cc]
                        if g < occ:
                            occ = g
                        if ch_fd >= 0:
                            d = dp[(r + 1) * wp + cc + 1]
                            if d < dmin:
                                dmin = d
                        if ch_trail >= 0:
                            t = trail[r, cc]
                            if t < tr:
                                tr = t
                    elif unknown < occ:
                        occ = unknown  # outside the map: unknown (and 255 for the others)
            if occ != UNKNOWN:
                n_known += 1
                if occ == FREE:
                    n_free += 1
            if ch_occ >= 0:
                image[ch_occ, i, j] = occ
            if ch_trail >= 0:
                image[ch_trail, i, j] = tr
            if ch_fd >= 0:
                if dmin < np.inf:
                    lv = np.rint(128.0 + scale * (dmin - d_robot))
                    image[ch_fd, i, j] = np.uint8(min(max(lv, 0.0), 254.0))
                else:
                    image[ch_fd, i, j] = 255
    # The scan: invalid returns (0: too close or dropout) read as max range; bin b pools beams
    # b * per - shift .. (b + 1) * per - shift - 1 (np.roll by shift, then consecutive beams).
    n_beams = scan.shape[0]
    n_bins = pooled.shape[0]
    per = n_beams // n_bins
    mr = np.float32(max_range)
    n_open = 0
    for b in range(n_bins):
        m = np.float32(np.inf)
        for q in range(b * per, (b + 1) * per):
            x = scan[(q - shift) % n_beams]
            if not x > 0.0:
                x = mr
            if x < m:
                m = x
        p = np.float32(m / mr)
        p = min(max(p, np.float32(0.0)), np.float32(1.0))
        pooled[b] = p
        if p >= 1.0:
            n_open += 1
    n_cells = c * c
    features[0] = n_known / n_cells
    features[1] = n_free / n_cells
    features[2] = n_open / n_bins


@njit(cache=True)
def min_pool(grid, f, out):  # pragma: no cover - numba
    """``out[r, c]`` = min of ``grid[f r : f r + f, f c : f c + f]``; cells beyond the map read
    UNKNOWN (OCCUPIED < UNKNOWN < FREE: a wall anywhere in the block wins)."""
    h, w = grid.shape
    ho, wo = out.shape
    hf, wf = h // f, w // f  # whole blocks
    out[:, :] = 255
    # Row by row, then column blocks: each map row read once, in order.
    for r in range(hf * f):
        src = grid[r]
        dst = out[r // f]
        if f == 2:  # the common case (0.1 m crops of a 0.05 m map), in a loop that vectorises
            for co in range(wf):
                dst[co] = min(dst[co], min(src[2 * co], src[2 * co + 1]))
        else:
            for co in range(wf):
                m = dst[co]
                for k in range(f):
                    m = min(m, src[co * f + k])
                dst[co] = m
        for c in range(wf * f, w):  # a partial block at the right edge
            dst[wf] = min(dst[wf], src[c])
    for r in range(hf * f, h):  # a partial block row at the top
        src = grid[r]
        dst = out[hf]
        for c in range(w):
            dst[c // f] = min(dst[c // f], src[c])
    unknown = np.uint8(UNKNOWN)
    if w % f:
        for ro in range(ho):
            out[ro, wo - 1] = min(out[ro, wo - 1], unknown)
    if h % f:
        for co in range(wo):
            out[ho - 1, co] = min(out[ho - 1, co], unknown)
