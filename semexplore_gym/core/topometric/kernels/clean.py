"""Stage 1 of the segmentation, crop and clean: the free cells' bounding box, the noise filter.

:func:`scan_grid` checks the encoding and finds the free cells' bounding box (the crop);
:func:`filter_small_blobs` erases occupied specks in free space and closes small unknown holes,
and collects the free cells next to unknown space (the frontier candidates of stage 7).
"""

from __future__ import annotations

import numpy as np
from numba import njit, uint64

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN

_LOW7 = 0x7F7F7F7F7F7F7F7F
_HIGH = 0x8080808080808080


@njit(cache=True, error_model="numpy", boundscheck=False)
def scan_grid(enc: np.ndarray) -> tuple[int, int, int, int, int]:
    """One pass: index of the first value outside the encoding (-1 if none) and the free bbox.

    Returns ``(bad_flat_index, rmin, rmax, cmin, cmax)``; ``rmin == -1`` when there is no free cell.

    Each row is read eight cells at a time (64-bit words, bytes tested with word arithmetic:
    a large map is mostly unknown, and this pass reads all of it); the few cells of a row
    outside whole words, and grids whose data are not word-aligned, are read cell by cell
    (:func:`scan_grid_cells`, the same result).
    """
    H, W = enc.shape
    flat = enc.ravel()
    if flat.ctypes.data % 8 or W < 16:
        return scan_grid_cells(enc)
    words = flat[: (flat.size // 8) * 8].view(np.uint64)
    low7 = uint64(_LOW7)
    high = uint64(_HIGH)
    rmin = -1
    rmax = -1
    cmin = W
    cmax = -1
    for r in range(H):
        s = r * W
        e = s + W
        a = (s + 7) // 8
        b = e // 8
        free_w = uint64(0)
        bad_w = uint64(0)
        for k in range(a, b):
            x = words[k]
            nx = ~x
            y = x ^ high
            # high bit of each byte set where that byte is non-zero (exact: no carries)
            nz_nx = (((nx & low7) + low7) | nx) & high  # byte != FREE (255)
            nz_x = (((x & low7) + low7) | x) & high  # byte != OCCUPIED (0)
            nz_y = (((y & low7) + low7) | y) & high  # byte != UNKNOWN (128)
            free_w |= (~nz_nx) & high
            bad_w |= nz_x & nz_y & nz_nx
        n_free = free_w != 0
        n_bad = bad_w != 0
        for k in range(s, 8 * a):
            v = flat[k]
            n_free |= v == FREE
            n_bad |= (v != FREE) & (v != UNKNOWN) & (v != OCCUPIED)
        for k in range(8 * b, e):
            v = flat[k]
            n_free |= v == FREE
            n_bad |= (v != FREE) & (v != UNKNOWN) & (v != OCCUPIED)
        if n_bad:
            for c in range(W):
                v = flat[s + c]
                if v != FREE and v != UNKNOWN and v != OCCUPIED:
                    return s + c, -1, -1, -1, -1
        if n_free:
            if rmin < 0:
                rmin = r
            rmax = r
            c = 0
            while flat[s + c] != FREE:
                c += 1
            cmin = min(cmin, c)
            c = W - 1
            while flat[s + c] != FREE:
                c -= 1
            cmax = max(cmax, c)
    return -1, rmin, rmax, cmin, cmax


@njit(cache=True, error_model="numpy")
def scan_grid_cells(enc: np.ndarray) -> tuple[int, int, int, int, int]:
    """:func:`scan_grid` read cell by cell (any layout)."""
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
            n_free += v == FREE
            n_bad += (v != FREE) & (v != UNKNOWN) & (v != OCCUPIED)
        if n_bad:
            for c in range(W):
                v = row[c]
                if v != FREE and v != UNKNOWN and v != OCCUPIED:
                    return r * W + c, -1, -1, -1, -1
        if n_free:
            if rmin < 0:
                rmin = r
            rmax = r
            c = 0
            while row[c] != FREE:
                c += 1
            cmin = min(cmin, c)
            c = W - 1
            while row[c] != FREE:
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
    limit = max_speck_cells if v == OCCUPIED else max_hole_cells
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
                if state[q + er * W + ec] != 2 and work[qr + er, qc + ec] != FREE:
                    all_free = False
    new_v = -1
    if all_free:
        new_v = FREE
    elif v == UNKNOWN:
        new_v = OCCUPIED
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
            xf = row[c] == FREE
            flag[c] = (xf ^ (row[c + 1] == FREE)) | (xf ^ (above[c] == FREE))
        for c in range(1, W - 1):
            if not flag[c]:
                continue
            i = base + c
            x = wf[i]
            xf = x == FREE
            for t in range(3):
                if t == 0:
                    if xf:
                        continue
                    j = i
                    nb = wf[i + 1] if wf[i + 1] == FREE else wf[i + W]
                elif t == 1:
                    if xf == (wf[i + 1] == FREE):
                        continue
                    j = i + 1 if xf else i
                    nb = wf[i + 1]
                else:
                    if xf == (wf[i + W] == FREE):
                        continue
                    j = i + W if xf else i
                    nb = wf[i + W]
                # frontier candidate: the free cell of a free/unknown pair
                if t > 0 and (x == UNKNOWN or nb == UNKNOWN):
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
                if wf[j] == OCCUPIED:
                    if max_speck_cells <= 0:
                        continue
                    # a speck of at most k cells leaves each of its cells >= 9 - k free neighbours
                    nf = 0
                    for dr in range(-1, 2):
                        for dc in range(-1, 2):
                            if wf[j + dr * W + dc] == FREE:
                                nf += 1
                    if nf < 9 - max_speck_cells:
                        state[j] = 1  # then no blob through j is small enough
                        continue
                elif max_hole_cells <= 0:
                    continue
                changed += _try_blob(work, state, stack, blob, j, max_speck_cells, max_hole_cells)
    return changed, np.unique(fcand[:n_f])
