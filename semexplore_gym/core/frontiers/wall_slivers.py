"""Wall slivers: strips of UNKNOWN too thin to hide anything, lying along walls.

A map built by SLAM from keyframe scans draws walls one cell thin in places and leaves gaps in
their faces where a beam from a pose a centimetre off ran past the wall's edge. The inside of
a wall then shows as a strip of UNKNOWN next to FREE cells, a frontier that no scan will ever
clear, and where the strip reaches the unknown outside of the building through a corner of the
outer wall it even passes a test for deep unknown space behind it (an explorer drives there,
looks, and drives on, after the floor is done).

:func:`wall_sliver_mask` finds those cells: UNKNOWN cells that no disc of diameter
``max_width_cells`` of UNKNOWN cells covers (the complement of the morphological opening of
the UNKNOWN cells by that disc; space beyond the grid's edge counts as UNKNOWN) and that lie
within ``wall_gap_cells`` (Chebyshev distance) of an OCCUPIED cell. Unknown space an explorer
could still map (a room behind a door, a corridor seen along a narrow fan) is wider than the
robot and stays UNKNOWN; thin unknown strips between LiDAR rays, far from any wall, stay too.
:func:`fill_wall_slivers` returns the grid with those cells OCCUPIED. Whether a cell is a sliver
depends only on the cells within :func:`sliver_context_cells` of it, so after a local change of
the grid :func:`wall_sliver_mask_box` computes the mask again over the changed box alone.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
from scipy import ndimage

from semexplore_gym.core.frontiers.wall_distance import wall_distance_m
from semexplore_gym.core.grid import OCCUPIED, UNKNOWN
from semexplore_gym.core.planning.grid_scan import checked_encoded_grid

__all__ = [
    "fill_wall_slivers",
    "sliver_context_cells",
    "wall_sliver_mask",
    "wall_sliver_mask_box",
]


def _within_sq(marked: np.ndarray, r2: float) -> np.ndarray:
    """Cells whose squared distance (cells) to the nearest OCCUPIED-marked cell is at most
    ``r2`` (exact: the squared distances are integers)."""
    # The distances are square roots of integers: none lies within float rounding of sqrt(r2).
    return wall_distance_m(marked, 1.0) <= math.sqrt(r2)


def wall_sliver_mask(
    grid: npt.ArrayLike, max_width_cells: float, wall_gap_cells: int = 2
) -> np.ndarray:
    """Boolean mask of the UNKNOWN cells in strips narrower than ``max_width_cells`` that lie
    within ``wall_gap_cells`` of an OCCUPIED cell (see the module docstring).

    The disc is the cells ``(dy, dx)`` with ``dx^2 + dy^2 <= (max_width_cells / 2)^2``; the
    opening is computed with two exact distance transforms (:func:`wall_distance_m`) over the
    known part of the grid and its margin, the same cells as ``scipy.ndimage.binary_opening``
    with that disc on the grid padded with UNKNOWN (tested).

    Args:
        grid: Encoded occupancy grid (FREE / OCCUPIED / UNKNOWN).
        max_width_cells: A strip narrower than a disc of this diameter (cells) is a sliver.
        wall_gap_cells: How near (Chebyshev distance, cells) a sliver cell lies to a wall.

    Raises:
        ValueError: a grid that is not encoded, a non-positive or non-finite width or a
            negative gap (the message names the value).
    """
    g = checked_encoded_grid(grid)
    if not (math.isfinite(max_width_cells) and max_width_cells > 0):
        raise ValueError(f"max_width_cells must be a positive number, got {max_width_cells!r}")
    if int(wall_gap_cells) != wall_gap_cells or wall_gap_cells < 0:
        raise ValueError(f"wall_gap_cells must be an integer >= 0, got {wall_gap_cells!r}")
    mask = np.zeros(g.shape, dtype=bool)
    known = g != UNKNOWN
    rows, cols = np.flatnonzero(known.any(axis=1)), np.flatnonzero(known.any(axis=0))
    if rows.size == 0:
        return mask
    r2 = (float(max_width_cells) / 2.0) ** 2 + 1e-9
    # Far from every known cell UNKNOWN is wide: work on the known cells' box and a margin.
    m = math.ceil(float(max_width_cells) / 2.0) + int(wall_gap_cells) + 2
    r0, r1 = max(0, rows[0] - m), min(g.shape[0], rows[-1] + m + 1)
    c0, c1 = max(0, cols[0] - m), min(g.shape[1], cols[-1] + m + 1)
    pad = math.ceil(float(max_width_cells) / 2.0) + 1
    w = np.pad(g[r0:r1, c0:c1], pad, constant_values=UNKNOWN)
    unknown = w == UNKNOWN
    # Centres of discs that fit inside UNKNOWN: farther than the radius from every known cell.
    fits = ~_within_sq(np.where(unknown, np.uint8(UNKNOWN), np.uint8(OCCUPIED)), r2)
    # The opening: cells inside such a disc.
    opened = _within_sq(np.where(fits, np.uint8(OCCUPIED), np.uint8(UNKNOWN)), r2)
    thin = unknown & ~opened
    if thin.any():
        side = 2 * int(wall_gap_cells) + 1
        near_wall = (w == OCCUPIED).view(np.uint8)
        for axis in (0, 1):
            near_wall = ndimage.maximum_filter1d(near_wall, side, axis=axis, mode="constant")
        near_wall = near_wall.view(bool)
        mask[r0:r1, c0:c1] = (thin & near_wall)[pad:-pad, pad:-pad]
    return mask


def sliver_context_cells(max_width_cells: float, wall_gap_cells: int = 2) -> int:
    """How far (cells, in rows and columns) a cell's sliver status reaches into the grid: a disc
    that covers it has its centre within the radius, and that centre's fit looks another radius
    on; the wall nearby lies within ``wall_gap_cells``."""
    return 2 * math.ceil(float(max_width_cells) / 2.0) + int(wall_gap_cells) + 1


def wall_sliver_mask_box(
    grid: npt.ArrayLike,
    rows: tuple[int, int],
    cols: tuple[int, int],
    max_width_cells: float,
    wall_gap_cells: int = 2,
) -> np.ndarray:
    """``wall_sliver_mask(grid, ...)[r0:r1, c0:c1]`` for ``rows = (r0, r1)`` and ``cols =
    (c0, c1)``, computed from that box and its :func:`sliver_context_cells` around it only
    (the same cells, tested)."""
    g = checked_encoded_grid(grid)
    (r0, r1), (c0, c1) = rows, cols
    if not (0 <= r0 <= r1 <= g.shape[0] and 0 <= c0 <= c1 <= g.shape[1]):
        raise ValueError(f"box rows {rows!r}, cols {cols!r} outside the grid's {g.shape}")
    d = sliver_context_cells(max_width_cells, wall_gap_cells)
    w0, w1 = max(0, r0 - d), min(g.shape[0], r1 + d)
    v0, v1 = max(0, c0 - d), min(g.shape[1], c1 + d)
    mask = wall_sliver_mask(g[w0:w1, v0:v1], max_width_cells, wall_gap_cells)
    return mask[r0 - w0 : r1 - w0, c0 - v0 : c1 - v0]


def fill_wall_slivers(
    grid: npt.ArrayLike, max_width_m: float, resolution_m: float, wall_gap_cells: int = 2
) -> np.ndarray:
    """``grid`` with its wall slivers (:func:`wall_sliver_mask`, strips narrower than
    ``max_width_m``) marked OCCUPIED: a new array when any was found, else ``grid`` itself.

    Raises:
        ValueError: as :func:`wall_sliver_mask`, or a non-positive resolution.
    """
    if not (math.isfinite(resolution_m) and resolution_m > 0):
        raise ValueError(f"resolution_m must be a positive number, got {resolution_m!r}")
    g = checked_encoded_grid(grid)
    mask = wall_sliver_mask(g, max_width_m / resolution_m, wall_gap_cells)
    if not mask.any():
        return g
    out = g.copy()
    out[mask] = OCCUPIED
    return out
