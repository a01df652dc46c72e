"""Line of sight on an encoded occupancy grid, with an optional clearance around the line.

Used by the local planners to decide whether a point of the global path can be aimed at
directly: the straight segment from the robot to the point must not cross an obstacle cell
(and, with ``clearance_m > 0``, no obstacle cell may lie within ``clearance_m`` of it).
Cells outside the grid count as unknown.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
from numba import njit

from semexplore_gym.core.grid import OCCUPIED, UNKNOWN, GridGeometry
from semexplore_gym.core.planning.grid_scan import checked_encoded_grid


def segment_is_clear(
    grid: npt.ArrayLike,
    geometry: GridGeometry,
    start_xy_m: tuple[float, float],
    end_xy_m: tuple[float, float],
    clearance_m: float = 0.0,
    unknown_blocks: bool = False,
) -> bool:
    """Whether the segment between two world points is free of obstacle cells.

    Args:
        grid: ``(H, W)`` uint8 encoded grid (see :mod:`semexplore_gym.core.grid`).
        geometry: Frame of ``grid``.
        start_xy_m: Segment start ``(x, y)``.
        end_xy_m: Segment end ``(x, y)``.
        clearance_m: Cells whose centre lies within this distance of the segment are checked
            too; 0 checks only the cells the segment passes through.
        unknown_blocks: Count UNKNOWN cells (and cells off the grid) as obstacles.

    Returns:
        True if no checked cell is OCCUPIED (or UNKNOWN when ``unknown_blocks``).

    Raises:
        ValueError: on a malformed grid, a grid whose shape differs from ``geometry``, or a
            negative / non-finite clearance.
    """
    g = checked_encoded_grid(grid)
    if g.shape != geometry.shape:
        raise ValueError(f"grid shape {g.shape} does not match geometry shape {geometry.shape}")
    if not (np.isfinite(clearance_m) and clearance_m >= 0.0):
        raise ValueError(f"clearance_m must be a finite number >= 0, got {clearance_m!r}")
    pts = np.asarray([start_xy_m, end_xy_m], dtype=np.float64)
    if pts.shape != (2, 2) or not np.isfinite(pts).all():
        raise ValueError(f"start/end must be finite (x, y) pairs, got {start_xy_m!r}, {end_xy_m!r}")
    return bool(
        _segment_clear(
            g,
            geometry.origin_x_m,
            geometry.origin_y_m,
            geometry.resolution_m,
            pts[0, 0],
            pts[0, 1],
            pts[1, 0],
            pts[1, 1],
            float(clearance_m),
            bool(unknown_blocks),
        )
    )


def farthest_visible_index(
    grid: np.ndarray,
    geometry: GridGeometry,
    origin_xy_m: tuple[float, float],
    points_m: np.ndarray,
    candidate_mask: np.ndarray,
    clearance_m: float = 0.0,
    unknown_blocks: bool = False,
) -> int:
    """Largest index ``i`` with ``candidate_mask[i]`` whose point is in line of sight, or -1.

    The caller has validated ``grid`` (uint8, matching ``geometry``); this is the inner loop
    of the lookahead selection and is called every control step.
    """
    pts = np.ascontiguousarray(points_m, dtype=np.float64)
    mask = np.ascontiguousarray(candidate_mask, dtype=np.bool_)
    if pts.ndim != 2 or pts.shape[1] != 2 or mask.shape != (pts.shape[0],):
        raise ValueError(
            f"points_m must be (K, 2) with a (K,) mask, got {pts.shape} and {mask.shape}"
        )
    return int(
        _farthest_visible(
            grid,
            geometry.origin_x_m,
            geometry.origin_y_m,
            geometry.resolution_m,
            float(origin_xy_m[0]),
            float(origin_xy_m[1]),
            pts,
            mask,
            float(clearance_m),
            bool(unknown_blocks),
        )
    )


@njit(cache=True)
def _blocked_cell(grid, r, c, unknown_blocks):  # pragma: no cover - numba
    h, w = grid.shape
    if r < 0 or r >= h or c < 0 or c >= w:
        return unknown_blocks
    v = grid[r, c]
    if v == OCCUPIED:
        return True
    return unknown_blocks and v == UNKNOWN


@njit(cache=True)
def _segment_clear(
    grid, ox, oy, res, x0, y0, x1, y1, clearance_m, unknown_blocks
):  # pragma: no cover - numba
    # Sample at a quarter cell so that no crossed cell is skipped; with a clearance, check
    # the disk of cells whose centres lie within it of every sample.
    length = math.hypot(x1 - x0, y1 - y0)
    n = int(math.ceil(length / (0.25 * res))) + 1
    rad_cells = int(math.ceil(clearance_m / res))
    clr2 = (clearance_m / res) ** 2
    last_r = -(1 << 30)
    last_c = -(1 << 30)
    for k in range(n + 1):
        t = k / n if n > 0 else 0.0
        fx = (x0 + t * (x1 - x0) - ox) / res
        fy = (y0 + t * (y1 - y0) - oy) / res
        c = int(math.floor(fx))
        r = int(math.floor(fy))
        if rad_cells == 0:
            if r == last_r and c == last_c:
                continue
            if _blocked_cell(grid, r, c, unknown_blocks):
                return False
            # A diagonal step may slip between two cells that share only a corner (a
            # rasterised diagonal wall); both of them must be free.
            if k > 0 and r != last_r and c != last_c:
                if _blocked_cell(grid, last_r, c, unknown_blocks) or _blocked_cell(
                    grid, r, last_c, unknown_blocks
                ):
                    return False
            last_r = r
            last_c = c
            continue
        for dr in range(-rad_cells, rad_cells + 1):
            for dc in range(-rad_cells, rad_cells + 1):
                # Distance from the sample to the neighbour cell's centre, in cells.
                ddx = (c + dc + 0.5) - fx
                ddy = (r + dr + 0.5) - fy
                if dr == 0 and dc == 0 or ddx * ddx + ddy * ddy <= clr2:
                    if _blocked_cell(grid, r + dr, c + dc, unknown_blocks):
                        return False
    return True


@njit(cache=True)
def _farthest_visible(
    grid, ox, oy, res, x0, y0, pts, mask, clearance_m, unknown_blocks
):  # pragma: no cover - numba
    for i in range(pts.shape[0] - 1, -1, -1):
        if not mask[i]:
            continue
        if _segment_clear(
            grid, ox, oy, res, x0, y0, pts[i, 0], pts[i, 1], clearance_m, unknown_blocks
        ):
            return i
    return -1
