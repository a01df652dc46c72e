"""Candidate viewpoints on the true map and what the env's LiDAR sees from each.

* :func:`standing_mask`: the cells the robot's centre can occupy: free cells at least the
  clearance from every wall, 4-connected to the start (the core of the env's reachable mask,
  :func:`~semexplore_gym.core.worlds.start.reachable_free_mask`, before its dilation).
* :func:`candidate_viewpoints`: one cell per ``spacing`` x ``spacing`` block of the standing
  mask, the one farthest from the walls (easy to drive to, and it sees the most).
* :func:`visible_sets`: for each viewpoint, the cells of a count mask that one scan from there
  maps FREE: rays cast against the true wall segments (the env's ray caster), fused into a fresh
  occupancy grid by the env's own update rule (beam count, min and max range, end cells
  occupied). The heading is 0; the robot turns while it drives, so this is what it sees at
  least (beams are 1 degree apart: cells far out between two beams need another pose).
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
from numba import njit
from scipy import ndimage, sparse

from semexplore_gym.core.coverage_tour.problem import SensorModel
from semexplore_gym.core.grid import FREE, UNKNOWN, GridGeometry
from semexplore_gym.core.mapping.occupancy_grid import MappingParams, integrate_dirs
from semexplore_gym.core.mapping.raycast import SegmentIndex, cast_scan
from semexplore_gym.core.worlds.geometry import segment_distance_field
from semexplore_gym.core.worlds.raster import rasterize_free
from semexplore_gym.core.worlds.world import World

_FOUR = ndimage.generate_binary_structure(2, 1)


def wall_clearance_m(world: World, geometry: GridGeometry, cap_m: float) -> np.ndarray:
    """Distance from each cell centre to the nearest true wall segment, clipped at ``cap_m``."""
    return segment_distance_field(world.segments_m, geometry, cap_m)


def standing_mask(
    world: World,
    geometry: GridGeometry,
    start_xy_m: npt.ArrayLike,
    clearance_m: float,
    clearance: np.ndarray | None = None,
) -> np.ndarray:
    """Free cells at least ``clearance_m`` from every wall, 4-connected to the start.

    The start joins the nearest such cell within 1.5 cells (as the env's reachable mask does).
    With ``clearance_m`` above half a cell no two allowed cells face each other across a wall,
    so plain 4-connectivity is exact.

    Raises:
        ValueError: ``clearance_m`` not above half a cell, or no allowed cell near the start.
    """
    res = geometry.resolution_m
    if not clearance_m > 0.5 * res:
        raise ValueError(
            f"clearance_m must exceed half a cell ({0.5 * res:g} m), got {clearance_m!r}"
        )
    if clearance is None:
        clearance = wall_clearance_m(world, geometry, clearance_m + res)
    allowed = rasterize_free(world, geometry) & (clearance >= clearance_m)
    start_rc = nearest_allowed_cell(allowed, geometry, start_xy_m)
    labels, _ = ndimage.label(allowed, structure=_FOUR)
    return labels == labels[start_rc]


def nearest_allowed_cell(
    allowed: np.ndarray, geometry: GridGeometry, xy_m: npt.ArrayLike
) -> tuple[int, int]:
    """The cell of ``allowed`` nearest ``xy_m`` within 1.5 cells (its own cell first).

    Raises:
        ValueError: no allowed cell that close.
    """
    x, y = (float(v) for v in np.asarray(xy_m, dtype=np.float64).ravel()[:2])
    h, w = allowed.shape
    row, col = (int(v) for v in geometry.world_to_grid(x, y))
    if 0 <= row < h and 0 <= col < w and allowed[row, col]:
        return row, col
    best: tuple[float, int, int] | None = None
    for r in range(max(0, row - 2), min(h, row + 3)):
        for c in range(max(0, col - 2), min(w, col + 3)):
            if allowed[r, c]:
                cx, cy = geometry.grid_to_world(r, c)
                d = math.hypot(float(cx) - x, float(cy) - y)
                if d <= 1.5 * geometry.resolution_m and (best is None or d < best[0]):
                    best = (d, r, c)
    if best is None:
        raise ValueError(
            f"start ({x:g}, {y:g}) is not reachable: no cell with the robot's wall clearance within "
            "1.5 cells"
        )
    return best[1], best[2]


def candidate_viewpoints(
    standing: np.ndarray, clearance: np.ndarray, spacing_cells: int
) -> np.ndarray:
    """One standing cell per ``spacing_cells`` block: the one farthest from the walls.

    Returns:
        ``(N, 2)`` int64 ``(row, col)`` cells, in row-major block order (ties: the first cell).
    """
    s = max(1, int(spacing_cells))
    h, w = standing.shape
    hp, wp = -(-h // s) * s, -(-w // s) * s
    score = np.full((hp, wp), -1.0, dtype=np.float64)
    score[:h, :w] = np.where(standing, clearance, -1.0)
    blocks = (
        score.reshape(hp // s, s, wp // s, s).transpose(0, 2, 1, 3).reshape(hp // s, wp // s, s * s)
    )
    k = blocks.argmax(axis=2)
    best = np.take_along_axis(blocks, k[..., None], axis=2)[..., 0]
    br, bc = np.nonzero(best >= 0.0)
    kk = k[br, bc]
    return np.column_stack([br * s + kk // s, bc * s + kk % s]).astype(np.int64)


def row_counts(
    flags: np.ndarray, indptr: np.ndarray, indices: np.ndarray, rows: np.ndarray | None = None
) -> np.ndarray:
    """Per CSR row (or per row of ``rows`` only), how many of its columns are set in ``flags``
    (one pass over the rows' entries: no sparse product, no copies of the matrix)."""
    picked = np.arange(indptr.size - 1) if rows is None else np.asarray(rows, dtype=np.int64)
    return count_set_columns(np.asarray(flags, dtype=np.bool_), indptr, indices, picked)


@njit(cache=True)
def count_set_columns(flags, indptr, indices, rows):  # pragma: no cover - numba
    """``out[j]``: how many columns of CSR row ``rows[j]`` are set in ``flags``."""
    out = np.zeros(rows.size, dtype=np.int64)
    for j in range(rows.size):
        i = rows[j]
        total = 0
        for p in range(indptr[i], indptr[i + 1]):
            if flags[indices[p]]:
                total += 1
        out[j] = total
    return out


def visible_sets(
    world: World,
    geometry: GridGeometry,
    cells_rc: np.ndarray,
    sensor: SensorModel,
    count_mask: np.ndarray,
    index: SegmentIndex | None = None,
) -> sparse.csr_matrix:
    """Which cells of ``count_mask`` one scan from each cell centre maps FREE.

    Args:
        world: The true world.
        geometry: Grid of ``count_mask``.
        cells_rc: ``(N, 2)`` viewpoint cells.
        sensor: The LiDAR.
        count_mask: ``geometry.shape`` bool; its True cells, in ``np.flatnonzero`` order, are
            the matrix's columns.
        index: The world's :class:`SegmentIndex` if already built.

    Returns:
        ``(N, count_mask.sum())`` bool CSR matrix.
    """
    index = index if index is not None else SegmentIndex(world.segments_m)
    res = geometry.resolution_m
    h, w = geometry.shape
    column = np.full(h * w, -1, dtype=np.int64)
    flat = np.flatnonzero(count_mask)
    column[flat] = np.arange(flat.size)
    cells = np.asarray(cells_rc, dtype=np.int64).reshape(-1, 2)
    angles = sensor.beam_angles_rad()
    n = cells.shape[0]
    ranges = np.empty((n, angles.size), dtype=np.float64)
    xs, ys = geometry.grid_to_world(cells[:, 0], cells[:, 1])
    xs = np.asarray(xs, dtype=np.float64).reshape(-1)
    ys = np.asarray(ys, dtype=np.float64).reshape(-1)
    for i in range(n):
        cast_scan(index, float(xs[i]), float(ys[i]), 0.0, angles, sensor.max_range_m, out=ranges[i])
    np.minimum(ranges, sensor.max_range_m, out=ranges)
    ranges[ranges < sensor.min_range_m] = 0.0
    half = int(math.ceil(sensor.max_range_m / res)) + 2
    mp = MappingParams(resolution_m=res)
    consts = np.array(
        [
            mp.log_odds_free,
            mp.log_odds_occupied,
            mp.log_odds_min,
            mp.log_odds_max,
            mp.free_threshold,
            mp.occupied_threshold,
        ],
        dtype=np.float32,
    )
    indptr, indices = _visible_kernel(
        cells,
        xs,
        ys,
        np.cos(angles),
        np.sin(angles),
        ranges,
        sensor.max_range_m,
        geometry.origin_x_m,
        geometry.origin_y_m,
        res,
        h,
        w,
        column,
        half,
        consts,
    )
    small = np.int32 if flat.size < 2**31 and indices.size < 2**31 else np.int64
    return sparse.csr_matrix(
        (np.ones(indices.size, dtype=bool), indices.astype(small), indptr.astype(small)),
        shape=(n, flat.size),
    )


@njit(cache=True)
def _visible_kernel(
    cells, xs, ys, cos_b, sin_b, ranges, max_range, gx0, gy0, res, h, w, column, half, consts
):  # pragma: no cover - numba
    """Per viewpoint: fuse its scan into a fresh window grid (the env's update, ``integrate_dirs``)
    and list the columns of the cells that came out FREE. Returns CSR ``(indptr, indices)``."""
    n = cells.shape[0]
    side = 2 * half + 1
    log_odds = np.zeros((side, side), dtype=np.float32)
    encoded = np.full((side, side), UNKNOWN, dtype=np.uint8)
    stamp = np.zeros((side, side), dtype=np.uint8)
    mask = np.zeros((side, side), dtype=np.bool_)
    indptr = np.zeros(n + 1, dtype=np.int64)
    cap = max(1024, n * 64)
    out = np.empty(cap, dtype=np.int64)
    k = 0
    for i in range(n):
        r0 = cells[i, 0] - half
        c0 = cells[i, 1] - half
        log_odds[:] = 0.0
        encoded[:] = UNKNOWN
        stamp[:] = 0
        integrate_dirs(
            log_odds,
            encoded,
            stamp,
            mask,
            1,
            xs[i],
            ys[i],
            cos_b,
            sin_b,
            ranges[i],
            max_range,
            gx0 + c0 * res,
            gy0 + r0 * res,
            res,
            consts,
        )
        for a in range(side):
            gr = r0 + a
            if gr < 0 or gr >= h:
                continue
            for b in range(side):
                gc = c0 + b
                if gc < 0 or gc >= w or encoded[a, b] != FREE:
                    continue
                col = column[gr * w + gc]
                if col < 0:
                    continue
                if k == cap:
                    cap *= 2
                    bigger = np.empty(cap, dtype=np.int64)
                    bigger[:k] = out[:k]
                    out = bigger
                out[k] = col
                k += 1
        indptr[i + 1] = k
    return indptr, out[:k].copy()
