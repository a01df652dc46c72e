"""Raster <-> wall geometry.

:func:`raster_to_segments` turns a free-space raster into wall segments: a wall runs along every
cell edge between a free cell and a non-free one (occupied *or unknown*, and everything outside
the raster counts as non-free), so a map always comes out closed. Unit edges on one grid line
are merged into maximal axis-aligned segments. A wall one pixel thick yields a segment on each
of its faces, so it stays a wall however thin it is.

:func:`rasterize_free` goes the other way: the ground-truth free mask of a world on any grid.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from numba import njit

from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.worlds.geometry import (
    as_segments,
    crossed_links,
    flood_fill_links,
    segment_distance_field,
)
from semexplore_gym.core.worlds.world import World

# A cell centre exactly on half a cell from a wall (the wall lies on the cell's edge, as for
# every raster-derived wall) must count as free despite rounding.
_HALF_CELL_TOLERANCE = 1e-5


def remove_small_free_components(free_mask: np.ndarray, min_free_cells: int) -> np.ndarray:
    """Drop 4-connected free components smaller than ``min_free_cells`` cells.

    Such specks (isolated free pixels in SLAM maps, anti-aliasing dots) are too small for a
    robot and would only add tiny closed walls.
    """
    free = np.array(free_mask, dtype=np.bool_)
    if free.ndim != 2:
        raise ValueError(f"free_mask must be 2-D, got shape {free.shape}")
    if min_free_cells > 1 and free.any():
        _drop_small_components_kernel(free, int(min_free_cells))
    return free


@njit(cache=True)
def _drop_small_components_kernel(free: np.ndarray, min_cells: int) -> None:
    # A search from each unvisited free cell stops as soon as it has seen min_cells cells or a
    # cell already known to be in a big component; only a search that runs out of cells first
    # has found a whole small component. Every cell is explored once: O(H * W), and no labels.
    h, w = free.shape
    state = np.zeros((h, w), dtype=np.uint8)  # 0 unseen, 1 big, 2 small
    queue = np.empty(min_cells + 4, dtype=np.int64)
    for r0 in range(h):
        for c0 in range(w):
            if not free[r0, c0] or state[r0, c0] != 0:
                continue
            state[r0, c0] = 3  # in the current search
            queue[0] = r0 * w + c0
            n = 1
            head = 0
            big = False
            while head < n and not big:
                s = queue[head]
                head += 1
                r = s // w
                c = s % w
                for dr, dc in ((1, 0), (-1, 0), (0, 1), (0, -1)):
                    rr = r + dr
                    cc = c + dc
                    if rr < 0 or rr >= h or cc < 0 or cc >= w or not free[rr, cc]:
                        continue
                    if state[rr, cc] == 1:
                        big = True
                        break
                    if state[rr, cc] == 0:
                        state[rr, cc] = 3
                        queue[n] = rr * w + cc
                        n += 1
                        if n >= min_cells:
                            big = True
                            break
            mark = 1 if big else 2
            for k in range(n):
                state[queue[k] // w, queue[k] % w] = mark
                if not big:
                    free[queue[k] // w, queue[k] % w] = False


def raster_to_segments(free_mask: npt.ArrayLike, geometry: GridGeometry) -> np.ndarray:
    """Wall segments along the boundary between free and non-free cells.

    Args:
        free_mask: ``(H, W)`` bool, True = free. Cells outside the raster count as non-free.
        geometry: Frame of ``free_mask``.

    Returns:
        ``(N, 4)`` float64 segments ``x0, y0, x1, y1`` in metres, axis-aligned and maximal:
        collinear touching unit edges are merged (a straight 10-cell wall face is one segment).
        Horizontal segments come first, ordered by y then x; then vertical ones, ordered by
        the row where they end, then x.
    """
    free = np.asarray(free_mask, dtype=bool)
    if free.shape != geometry.shape:
        raise ValueError(f"free_mask shape {free.shape} != geometry shape {geometry.shape}")
    h, w = free.shape
    padded = np.zeros((h + 2, w + 2), dtype=np.bool_)
    padded[1:-1, 1:-1] = free
    runs = np.empty(
        (_edge_runs_kernel(padded, np.empty((0, 4), dtype=np.int64), False), 4), dtype=np.int64
    )
    _edge_runs_kernel(padded, runs, True)
    res = float(geometry.resolution_m)
    out = np.empty((runs.shape[0], 4), dtype=np.float64)
    horizontal = runs[:, 0] == 0
    line, a, b = runs[:, 1], runs[:, 2], runs[:, 3]
    # Horizontal run on grid line y = oy + line*res from x = ox + a*res to ox + b*res.
    out[:, 0] = np.where(horizontal, a, line)
    out[:, 1] = np.where(horizontal, line, a)
    out[:, 2] = np.where(horizontal, b, line)
    out[:, 3] = np.where(horizontal, line, b)
    out *= res
    out[:, [0, 2]] += geometry.origin_x_m
    out[:, [1, 3]] += geometry.origin_y_m
    return out


@njit(cache=True)
def _edge_runs_kernel(padded: np.ndarray, out: np.ndarray, fill: bool) -> int:
    """Maximal runs of boundary edges of a zero-padded mask; returns their number and, when
    ``fill``, writes them to ``out`` as rows ``(kind, line, first, end)`` (kind 0 = along x).

    Called twice (count, then fill) because growing a buffer inside the loop is several
    times slower.
    """
    h = padded.shape[0] - 2
    w = padded.shape[1] - 2
    n = 0
    # Along x: grid line k lies between padded rows k and k + 1.
    for k in range(h + 1):
        start = -1
        for c in range(w):
            if padded[k, c + 1] != padded[k + 1, c + 1]:
                if start < 0:
                    start = c
            elif start >= 0:
                if fill:
                    out[n, 0] = 0
                    out[n, 1] = k
                    out[n, 2] = start
                    out[n, 3] = c
                n += 1
                start = -1
        if start >= 0:
            if fill:
                out[n, 0] = 0
                out[n, 1] = k
                out[n, 2] = start
                out[n, 3] = w
            n += 1
    # Along y: grid line k lies between padded columns k and k + 1; walk rows in the outer loop
    # for memory order, keeping one open run per line.
    open_start = np.full(w + 1, -1, dtype=np.int64)
    for r in range(h):
        for k in range(w + 1):
            if padded[r + 1, k] != padded[r + 1, k + 1]:
                if open_start[k] < 0:
                    open_start[k] = r
            elif open_start[k] >= 0:
                if fill:
                    out[n, 0] = 1
                    out[n, 1] = k
                    out[n, 2] = open_start[k]
                    out[n, 3] = r
                n += 1
                open_start[k] = -1
    for k in range(w + 1):
        if open_start[k] >= 0:
            if fill:
                out[n, 0] = 1
                out[n, 1] = k
                out[n, 2] = open_start[k]
                out[n, 3] = h
            n += 1
    return n


def cells_near_walls(segments_m: npt.ArrayLike, geometry: GridGeometry) -> np.ndarray:
    """Cells whose centre lies strictly within half a cell of some wall (a wall on the cell's
    edge does not count)."""
    half = 0.5 * geometry.resolution_m
    dist = segment_distance_field(segments_m, geometry, max_distance_m=2.0 * half)
    return dist < half * (1.0 - _HALF_CELL_TOLERANCE)


def sample_mask(
    mask: np.ndarray, mask_geometry: GridGeometry, geometry: GridGeometry
) -> np.ndarray:
    """Nearest-cell resampling: the value of ``mask`` at each cell centre of ``geometry``.

    Centres outside ``mask_geometry`` read False.
    """
    h, w = geometry.shape
    xs, _ = geometry.grid_to_world(0, np.arange(w))
    _, ys = geometry.grid_to_world(np.arange(h), 0)
    _, cols = mask_geometry.world_to_grid(xs, 0.0)
    rows, _ = mask_geometry.world_to_grid(0.0, ys)
    col_ok = (cols >= 0) & (cols < mask_geometry.width)
    row_ok = (rows >= 0) & (rows < mask_geometry.height)
    out = np.zeros((h, w), dtype=bool)
    if col_ok.any() and row_ok.any():
        sub = mask[np.ix_(rows[row_ok], cols[col_ok])]
        out[np.ix_(row_ok, col_ok)] = sub
    return out


def rasterize_free(
    world_or_segments: World | npt.ArrayLike,
    geometry: GridGeometry,
    *,
    interior_points_m: npt.ArrayLike | None = None,
) -> np.ndarray:
    """Ground-truth free mask of a world on any grid.

    A cell is free when its centre lies inside the world's free space and no wall passes
    within half a cell of that centre. A wall lying exactly on the edge between two cells
    (half a cell from both centres) marks just one of them, the one on the +x / +y side as
    :meth:`GridGeometry.world_to_grid` would, so a thin wall always shows as a line one cell
    thick and never disappears, while a raster world resampled on its own grid gives back
    exactly its mask (there every wall already has a non-free cell on one side).

    "Inside" is decided by the world's ``free_space_source``:

    - ``"raster"``: the world's exact ``free_mask`` is read at the cell centre.
    - ``"vector"``: a 4-connected flood fill over cells no wall passes within half a cell of,
      never crossing a wall between two cell centres, seeded from cells whose centre lies
      inside the world's ``free_mask`` and more than a native cell from any wall (so a seed
      cannot sit on the wrong side of a wall).

    Args:
        world_or_segments: A :class:`World`, or bare ``(N, 4)`` wall segments; then
            ``interior_points_m`` must say where the inside is.
        geometry: The target grid.
        interior_points_m: ``(K, 2)`` points inside free space, the flood-fill seeds for bare
            segments (ignored for a world).

    Returns:
        ``geometry.shape`` bool mask, True = free.
    """
    if isinstance(world_or_segments, World):
        world = world_or_segments
        segments = world.segments_m
        blocked = cells_near_walls(segments, geometry)
        cut_x, cut_y = crossed_links(segments, geometry)
        inside = sample_mask(world.free_mask, world.free_geometry, geometry)
        if world.free_space_source == "vector":
            seed_margin_m = max(world.free_geometry.resolution_m, geometry.resolution_m)
            dist = segment_distance_field(segments, geometry, max_distance_m=2.0 * seed_margin_m)
            seeds = inside & (dist > seed_margin_m)
            if not seeds.any():
                # The grid is too coarse for deep seeds: accept any unblocked inside cell.
                seeds = inside & ~blocked
            inside = flood_fill_links(~blocked, cut_x, cut_y, seeds)
        return mark_walls(inside & ~blocked, cut_x, cut_y)

    segments = as_segments(world_or_segments)
    if interior_points_m is None:
        raise ValueError(
            "rasterize_free needs interior_points_m when given bare segments (where is the inside?)"
        )
    pts = np.atleast_2d(np.asarray(interior_points_m, dtype=np.float64))
    if pts.ndim != 2 or pts.shape[1] != 2 or not np.isfinite(pts).all():
        raise ValueError(f"interior_points_m must be finite (K, 2) points, got shape {pts.shape}")
    blocked = cells_near_walls(segments, geometry)
    cut_x, cut_y = crossed_links(segments, geometry)
    seeds = np.zeros(geometry.shape, dtype=bool)
    rows, cols = geometry.world_to_grid(pts[:, 0], pts[:, 1])
    ok = geometry.contains(rows, cols)
    seeds[rows[ok], cols[ok]] = True
    inside = flood_fill_links(~blocked, cut_x, cut_y, seeds)
    return mark_walls(inside, cut_x, cut_y)


def mark_walls(free: np.ndarray, cut_x: np.ndarray, cut_y: np.ndarray) -> np.ndarray:
    """Make every wall visible: where a wall crosses the link between two free cells, the cell
    on the +x (or +y) side becomes non-free.

    Args:
        free: ``(H, W)`` bool free cells (already without cells within half a cell of a wall).
        cut_x: ``(H, W-1)`` crossed links along x from
            :func:`~semexplore_gym.core.worlds.geometry.crossed_links`.
        cut_y: ``(H-1, W)`` crossed links along y.
    """
    out = free.copy()
    out[:, 1:] &= ~(cut_x & free[:, :-1] & free[:, 1:])
    out[1:, :] &= ~(cut_y & free[:-1, :] & free[1:, :])
    return out
